"""The affine hull of the admissible forces P (verify.statics.model): its implicit equalities
and its dimension (the method is described in verify.statics.forceset's docstring).

An implicit equality is an inequality of P that holds with equality on all of P (R = 0,
S = mu R or S = -mu R on the whole set); substituting them leaves the unknowns on which P is
full-dimensional, and dim P = (their number) - rank of the balance equations on them.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

from .implicit import proved_rows
from .model import LP_TOL, StaticProblem, interior_point

#: A slack or a force below this times the largest disk weight is zero.
ZERO = 1e-9
#: Largest number of unknowns whose rank is computed (dense SVD).
DENSE_RANK_LIMIT = 8000


def implicit_equalities(prob: StaticProblem, x: np.ndarray | None = None) -> list[str]:
    """Per contact: "R=0", "S=+muR", "S=-muR" or "" (module docstring). x: a point of P
    near its relative interior, if one is known (else one is computed)."""
    c = prob.c
    # inequality rows: -R <= 0 (c), then S - mu R <= 0 and -S - mu R <= 0 (k each)
    Gi = sp.vstack([-sp.eye(c, prob.n), prob.G], format="csr")
    m = Gi.shape[0]
    T = prob.scale
    undecided = np.ones(m, dtype=bool)
    # One interior point settles most rows at once: a row with a clear positive slack at a
    # point of P is not an implicit equality; the slack LPs then decide only the rest.
    if x is None:
        x = interior_point(prob, 1e3 * float(np.sum(prob.system.masses)) * prob.system.g)[1]
    witness = None
    if x is not None:
        weight = float(np.sum(prob.system.masses)) * prob.system.g
        eq, viol = prob.residuals(x)
        if eq <= 1e-9 * weight and viol <= 1e-9 * weight:
            undecided &= ~(-(Gi @ x) > 1e-6 * T)
            witness = x if prob.admissible(x) else None
    # the rows left, when few: exactly checked local certificates that they vanish on all of
    # P (verify.statics.implicit: a few small LPs each, where the slack LP below solves P
    # whole); the rows none proves go to the slack LPs
    proved = proved_rows(prob, undecided) if witness is not None else np.zeros(m, dtype=bool)
    undecided &= ~proved
    while undecided.any():
        cost = np.r_[np.zeros(prob.n), -undecided.astype(float)]
        A_ub = sp.hstack([Gi, sp.eye(m)], format="csr")
        A_eq = sp.hstack([prob.A, sp.csr_matrix((prob.A.shape[0], m))], format="csr")
        bounds = list(zip(prob.lb, prob.ub)) + [(0, T if u else 0) for u in undecided]
        bounds = [(None if not np.isfinite(lo) else lo, None if not np.isfinite(hi) else hi)
                  for lo, hi in bounds]
        res = linprog(cost, A_ub=A_ub, b_ub=np.zeros(m), A_eq=A_eq, b_eq=prob.b,
                      bounds=bounds, method="highs",
                      options={"primal_feasibility_tolerance": LP_TOL})
        if res.status != 0:
            raise RuntimeError(f"slack LP failed: {res.message}")
        t = np.maximum(res.x[prob.n:], -(Gi @ res.x[:prob.n]))  # the rows' actual slacks
        new = undecided & (t > ZERO * T)
        if not new.any():
            break
        undecided &= ~new
    return labels(prob, undecided | proved, witness)


def labels(prob: StaticProblem, undecided: np.ndarray,
           witness: np.ndarray | None = None) -> list[str]:
    """Per contact, the strongest implicit equality among the rows left `undecided` (no slack
    found: -R <= 0 for the c contacts, then S - mu R <= 0 and -S - mu R <= 0 for the k
    frictional ones): "R=0" (implies S = +-mu R = 0), "S=+muR", "S=-muR" or "". witness: a
    point of P (checked by the caller, `StaticProblem.admissible`) whose R > ZERO x scale
    there stands for `_positive_R`'s LP."""
    c, k = prob.c, prob.fric.size
    out = [""] * c
    for a in range(c):
        if undecided[a]:
            out[a] = "R=0"
    for n, a in enumerate(prob.fric):
        if out[a]:
            continue
        plus, minus = undecided[c + n], undecided[c + k + n]
        # S = mu R and S = -mu R both on all of P give 2 mu R = 0: R = 0 (which implies both)
        if not (plus or minus):
            continue
        positive = (witness is not None and witness[a] > ZERO * prob.scale) or (
            _positive_R(prob, a))
        if (plus and minus) or not positive:
            out[a] = "R=0"
        else:
            out[a] = "S=+muR" if plus else "S=-muR"
    return out


def _positive_R(prob: StaticProblem, a: int) -> bool:
    """Is R_a > 0 somewhere on P? One LP, max R_a, its optimum checked against P. The slack
    LPs decide R_a >= 0 from points within the LP's tolerance of P, where R_a ~ 1e-9 can be
    rounding on a set with R_a = 0 throughout (a 2-disk pile at mu 0.988 was labelled
    "S=+muR" so); a contact labelled S = +-mu R must have a checked witness of R > 0."""
    bounds = [(None if not np.isfinite(lo) else lo, None if not np.isfinite(hi) else hi)
              for lo, hi in zip(prob.lb, prob.ub)]
    cost = np.zeros(prob.n)
    cost[a] = -1.0
    res = linprog(cost, A_ub=prob.G, b_ub=np.zeros(prob.G.shape[0]), A_eq=prob.A, b_eq=prob.b,
                  bounds=bounds, method="highs")
    if res.status == 3:  # unbounded: R_a takes every large value on P
        return True
    return bool(res.status == 0 and prob.admissible(res.x) and res.x[a] > ZERO * prob.scale)


def reduced_balance(prob: StaticProblem, implicit: list[str]) -> sp.csc_matrix:
    """The balance matrix on the unknowns left once the implicit equalities are substituted:
    per contact none (R = 0), one column A_R +- mu A_S (S = +-mu R; or A_R when mu = 0), or
    two (A_R, A_S)."""
    c, mu = prob.c, prob.mu
    kind = np.asarray(implicit, dtype=object)
    keep = kind != "R=0"
    two = keep & (kind == "") & (mu != 0)  # both R and S stay
    ncol = keep.astype(int) + two  # columns per contact, in contact order
    first = np.cumsum(ncol) - ncol
    a = np.flatnonzero(keep)  # the column of R (or of R with S = +-mu R substituted)
    sign = np.where(kind[a] == "S=+muR", 1.0, np.where(kind[a] == "S=-muR", -1.0, 0.0))
    sign[mu[a] == 0] = 0.0  # S = 0 there: the column is A_R
    tied = np.flatnonzero(sign != 0)
    s2 = np.flatnonzero(two)
    rows = np.r_[a, c + a[tied], c + s2]
    cols = np.r_[first[a], first[a[tied]], first[s2] + 1]
    vals = np.r_[np.ones(a.size), sign[tied] * mu[a[tied]], np.ones(s2.size)]
    Z = sp.csc_matrix((vals, (rows, cols)), shape=(prob.n, int(ncol.sum())))
    return sp.csc_matrix(prob.A @ Z)


def dimension(prob: StaticProblem, implicit: list[str]
              ) -> tuple[int | None, tuple[float | None, float | None]]:
    """(dim P, (smallest singular value kept, largest dropped)); None when the rank is not
    settled (rank deficient above the dense limit)."""
    B = reduced_balance(prob, implicit)
    keep = np.diff(B.tocsr().indptr) > 0  # rows that are exactly zero: rank 0
    keep &= ~locally_dependent(B, prob.p)
    B = B[np.flatnonzero(keep)]
    if B.shape[1] == 0 or B.shape[0] == 0:
        return B.shape[1], (None, None)
    full = _full_row_rank(B)
    if full is not None:
        return B.shape[1] - B.shape[0], (full, None)
    if B.shape[1] > DENSE_RANK_LIMIT:
        return None, (None, None)
    w = np.linalg.svd(B.toarray(), compute_uv=False)
    tol = max(B.shape) * np.finfo(float).eps * float(w[0])
    rank = int(np.sum(w > tol))
    kept = float(w[rank - 1]) if rank else None
    dropped = float(w[rank]) if rank < w.size else None
    return B.shape[1] - rank, (kept, dropped)


def locally_dependent(B: sp.spmatrix, p: int) -> np.ndarray:
    """Rows of B (3p: the u, v, w balance rows of the p disks) that are exact linear
    combinations of other rows of the same disk, one mask entry per row: at a disk whose
    nonzero rows touch fewer columns than their number (e.g. a disk left with one contact
    once the implicit equalities R = 0 are substituted: 2 columns, 3 rows), the disk's rows
    are 0 outside those columns, so a row that is a combination of the disk's other rows on
    them is one in B, and rank B is unchanged without it. The disk's rows are kept in order
    while they raise the exact rank (python-flint, on the stored doubles) of the kept ones.
    Dropping them lets the sparse full-row-rank test settle the rank above the dense SVD's
    limit."""
    from flint import fmpq_mat

    from .farkas import rational

    B = sp.csr_matrix(B)
    out = np.zeros(B.shape[0], dtype=bool)
    nz = (abs(B) > 0).astype(float)
    disk_of = np.tile(np.arange(p), 3)
    M = sp.csr_matrix((np.ones(3 * p), (disk_of, np.arange(3 * p))), shape=(p, 3 * p))
    ncols = np.diff((M @ nz).tocsr().indptr)  # distinct columns touching each disk's rows
    nrows = np.asarray(M @ (np.diff(B.indptr) > 0).astype(float)).ravel()
    for d in np.flatnonzero(ncols < nrows):
        rows = [r for r in (d, p + d, 2 * p + d) if B.indptr[r + 1] > B.indptr[r]]
        block = B[rows]
        cols = np.unique(block.indices)
        dense = block[:, cols].toarray()
        kept: list[int] = []
        for n, r in enumerate(rows):
            trial = kept + [n]
            A = fmpq_mat(len(trial), cols.size, [rational(v) for i in trial for v in dense[i]])
            if A.rank() == len(trial):
                kept = trial
            else:
                out[r] = True
    return out


def _full_row_rank(B: sp.csr_matrix) -> float | None:
    """sigma_min(B) when B (rows <= columns) has full row rank beyond doubt, else None.

    The extreme eigenvalues of C = B B^T give sigma_min and sigma_max; rank = rows by the SVD's
    own rule (sigma_min > max(shape) eps sigma_max) is accepted only with a wide margin,
    sigma_min > 1e-6 sigma_max, since the eigenvalues of C carry an absolute error
    ~ eps sigma_max^2 (else the dense SVD, or None, decides). The smallest eigenvalue is found
    by Lanczos on C^-1 (shift-invert at 0, C factored once by SuperLU in a minimum-degree
    order of its symmetric pattern); the largest is first bounded above by Gershgorin's
    theorem (the largest absolute row sum of C, within 2x of it on the arrays and piles),
    which can only make the test stricter, and computed by Lanczos only when that bound does
    not settle it (docs/packings.md, Scale: 0.5-0.8 against 5-6 CPU s at 10^4 disks)."""
    from scipy.sparse.linalg import ArpackError, ArpackNoConvergence, LinearOperator, eigsh, splu

    rows, cols = B.shape
    if rows > cols:
        return None
    C = (B @ B.T).tocsc()
    if rows < 3:
        ev = np.linalg.eigvalsh(C.toarray())
        lo, hi = float(ev[0]), float(ev[-1])
    else:
        try:
            lu = splu(C, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                      options={"SymmetricMode": True})
            inv = LinearOperator(C.shape, matvec=lu.solve, dtype=float)
            lo = float(eigsh(C, k=1, sigma=0.0, which="LM", OPinv=inv,
                             return_eigenvectors=False, tol=1e-6)[0])
            hi = float(np.max(abs(C).sum(axis=1)))  # >= the largest eigenvalue
            if not (lo > 0 and np.sqrt(lo) > 1e-6 * np.sqrt(hi)):
                hi = float(eigsh(C, k=1, which="LA", return_eigenvectors=False, tol=1e-6)[0])
        except (ArpackError, ArpackNoConvergence, RuntimeError, ValueError):
            return None  # e.g. C exactly singular: the factorization at sigma = 0 fails
    if hi <= 0 or lo <= 0:
        return None
    smin, smax = np.sqrt(lo), np.sqrt(hi)
    return float(smin) if smin > 1e-6 * smax else None
