"""The P-matrix test of verify.certificates.uniqueness (split out: one job per module).

M is a P-matrix (every principal minor positive) iff the LCP w = M z + q, 0 <= z perp w >= 0
has exactly one solution for every q (Samelson, Thrall & Wesler 1958; Cottle, Pang & Stone
1992, Thm 3.3.7).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

#: Largest n for the principal-minor test (2^n - 1 determinants).
P_MINORS_MAX_N = 12
#: A principal submatrix with sigma_min <= RCOND * sigma_max is treated as numerically singular.
RCOND = 1e-10


@dataclass
class PMatrixTest:
    """is_p: True (proved, to the stated conditioning margin), False (a principal minor is
    <= 0), None (undecided: near-singular minors, or n too large for the minors)."""

    is_p: bool | None
    how: str
    witness: tuple[int, ...] | None = None
    minors_checked: int = 0
    message: str = ""


def p_matrix_test(M: np.ndarray, max_n: int = P_MINORS_MAX_N, rcond: float = RCOND) -> PMatrixTest:
    """Is M a P-matrix? (every principal minor det M_aa > 0).

    1 x 1 minors (the diagonal) are data and are compared with 0 exactly. A larger minor counts
    as positive when its LU determinant is positive and its submatrix is well conditioned
    (sigma_min > rcond sigma_max), so that the sign is not an artefact of rounding; a negative
    determinant of a well-conditioned submatrix proves M is not P; a near-singular submatrix
    leaves the question undecided. For n > max_n only the sufficient test runs: the symmetric
    part (M + M^T)/2 positive definite (smallest eigenvalue > rcond times the largest |.|)
    implies P; for symmetric M a negative eigenvalue disproves it.
    """
    M = np.asarray(M, dtype=float)
    n = M.shape[0]
    diag = np.diagonal(M)
    if np.any(diag <= 0):
        i = int(np.flatnonzero(diag <= 0)[0])
        return PMatrixTest(False, "principal minors", (i,), i + 1,
                           f"diagonal entry M[{i},{i}] = {diag[i]:.3g} <= 0: not a P-matrix")
    Hs = 0.5 * (M + M.T)
    eig = np.linalg.eigvalsh(Hs)
    big = max(float(np.max(np.abs(eig))), 1e-300)
    symmetric = bool(np.max(np.abs(M - M.T)) <= 1e-14 * max(float(np.max(np.abs(M))), 1e-300))
    if eig[0] > rcond * big:
        return PMatrixTest(True, "symmetric part positive definite", None, 0,
                           f"lambda_min((M + M^T)/2) = {eig[0]:.3g} > 0 implies P")
    if symmetric and eig[0] < -rcond * big:
        return PMatrixTest(False, "symmetric: eigenvalues", None, 0,
                           f"M symmetric with eigenvalue {eig[0]:.3g} < 0: not P")
    if n > max_n:
        return PMatrixTest(None, "none", None, 0,
                           f"n = {n} > {max_n}: principal minors not enumerated, and the "
                           "sufficient test (symmetric part positive definite) fails")
    checked = n
    undecided: tuple[int, ...] | None = None
    for k in range(2, n + 1):
        idx = np.array(list(itertools.combinations(range(n), k)), dtype=np.intp)
        subs = M[idx[:, :, None], idx[:, None, :]]
        sign, _ = np.linalg.slogdet(subs)
        sv = np.linalg.svd(subs, compute_uv=False)
        well = sv[:, -1] > rcond * sv[:, 0]
        checked += idx.shape[0]
        bad = np.flatnonzero(well & (sign <= 0))
        if bad.size:
            a = tuple(int(j) for j in idx[bad[0]])
            return PMatrixTest(False, "principal minors", a, checked,
                               f"principal minor on {list(a)} is negative: not a P-matrix")
        if undecided is None and not np.all(well):
            undecided = tuple(int(j) for j in idx[np.flatnonzero(~well)[0]])
    if undecided is not None:
        return PMatrixTest(None, "principal minors", undecided, checked,
                           f"principal submatrix on {list(undecided)} is singular to rounding "
                           f"(sigma_min <= {rcond:g} sigma_max): P-property undecided")
    return PMatrixTest(True, "principal minors", None, checked,
                       f"all {checked} principal minors positive (well conditioned)")
