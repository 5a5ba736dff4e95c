"""Numerical rank by SVD and localized (sparse) bases of null spaces. Generic: no mechanics.

* `svd_rank`: the SVD (Eq. 3.1 of the paper) and the numerical rank with the standard tolerance
  tol = max(shape) * eps * w_max: a singular value below it is indistinguishable from the
  backward error of the SVD itself (||dM|| ~ eps ||M||, and ||M||_2 = w_max).
* `localized_basis`: a basis of ker M whose vectors have small supports -- candidates from
  column patches (null vectors of M supported in a patch) and from L1 minimization (the
  L1-smallest null vector with x_k = 1 is, at an optimal vertex, a *circuit*: a null vector of
  minimal support), polished to exact circuits, then the matroid greedy algorithm (sparsest
  first while independent) and a normalization that forces independence for what is missing.
  Not a certified sparsest basis (that problem is NP-hard); docs/verification.md.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog
from threadpoolctl import threadpool_limits

from rigidlcp.lcp.errors import InvalidProblem

EPS = np.finfo(float).eps
#: A row of an orthonormal null basis with a norm below this is zero (Eq. 3.2).
SUPPORT_TOL = float(np.sqrt(EPS))
#: Relative size below which an entry of a (max-normalized) localized vector is zero.
ENTRY_TOL = 1e-9
#: A candidate is independent of the chosen vectors when the relative norm of its part outside
#: their span exceeds this.
INDEPENDENCE_TOL = 1e-8


def svd_rank(M: np.ndarray, tol: float | None = None) -> tuple[np.ndarray, np.ndarray, float, int]:
    """SVD of M (Eq. 3.1): (singular values w, descending; V; tol; numerical rank).

    tol defaults to max(M.shape) * eps * w_max (see the module docstring).
    """
    M = np.asarray(M, dtype=float)
    if M.ndim != 2 or not np.all(np.isfinite(M)):
        raise InvalidProblem("M must be a finite 2-D array")
    if M.size == 0:
        return np.zeros(0), np.eye(M.shape[1]), 0.0, 0
    # V must be complete (all of R^n): full_matrices only matters when M has fewer rows.
    _, w, Vt = np.linalg.svd(M, full_matrices=M.shape[0] < M.shape[1])
    if tol is None:
        tol = max(M.shape) * EPS * (w[0] if w.size else 0.0)
    rank = int(np.sum(w > tol))
    return w, Vt.T, float(tol), rank


def _l1_smallest(V: np.ndarray, a: np.ndarray) -> np.ndarray | None:
    """argmin ||V y||_1 subject to a . y = 1, returned as x = V y (a linear program).

    Variables (y, u), u >= 0 bounding |V y| from above; the dual simplex returns a vertex, i.e.
    a null vector of minimal support (a circuit) in the generic case.
    """
    n, d = V.shape
    Vs = sp.csr_matrix(V)
    eye = sp.identity(n, format="csr")
    A_ub = sp.vstack([sp.hstack([Vs, -eye]), sp.hstack([-Vs, -eye])], format="csr")
    res = linprog(
        np.r_[np.zeros(d), np.ones(n)], A_ub=A_ub, b_ub=np.zeros(2 * n),
        A_eq=np.r_[a, np.zeros(n)][None, :], b_eq=[1.0],
        bounds=[(None, None)] * d + [(0, None)] * n, method="highs-ds",
    )
    if res.status != 0:
        return None
    return V @ res.x[:d]


def _polish(M: np.ndarray, x: np.ndarray, tol: float) -> np.ndarray:
    """Zero the negligible entries of x; when its support carries exactly one null direction of
    M (a circuit), return that direction computed from M restricted to the support."""
    x = x / np.abs(x).max()
    supp = np.flatnonzero(np.abs(x) > ENTRY_TOL)
    w, V, _, rank = svd_rank(M[:, supp], tol)
    if supp.size - rank == 1:
        y = V[:, -1]
        y = y if y @ x[supp] > 0 else -y
        x = np.zeros_like(x)
        x[supp] = y
    else:
        x[np.abs(x) <= ENTRY_TOL] = 0.0
    k = np.argmax(np.abs(x))
    x = x / x[k]
    x[np.abs(x) <= ENTRY_TOL] = 0.0
    return x + 0.0  # no negative zeros


def _n_contacts(x: np.ndarray, contact_count: int | None) -> int:
    nz = x != 0
    if contact_count is None:
        return int(nz.sum())
    c = contact_count
    return int(np.sum(nz[:c] | nz[c:]))


def localized_basis(
    M: np.ndarray,
    basis: np.ndarray,
    contact_count: int | None = None,
    patches: list[np.ndarray] = (),
    exhaustive: bool | None = None,
    seed: int = 0,
) -> np.ndarray:
    """A basis of ker M (given by an orthonormal `basis`) whose vectors have small supports.

    Candidates: (1) for each column set in `patches`, the null vectors of M supported there
    (ker M[:, patch], embedded), localized by L1 inside the patch -- these are genuine null
    vectors of M and catch local structures such as the hexagons of Fig. 5(a), which a global
    L1 minimum may trade for a longer but lighter vector; (2) for the coordinates of the support
    not yet covered (all of them when `exhaustive`, the default when there are no patches and
    2c <= 400), the global L1-smallest null vector with x_k = 1. Then the matroid greedy
    algorithm keeps the sparsest independent ones, and a normalization orthogonal to the kept
    span fills any missing dimension.

    contact_count c: coordinates k and c + k belong to the same contact (x = [R; S] of Eq.
    2.15); supports are then measured in contacts. Vectors are scaled so that their largest
    entry is +1 and sorted by support size.
    """
    n, d = basis.shape
    if d == 0:
        return np.zeros((n, 0))
    with threadpool_limits(1):  # small dense matrices: one BLAS thread is fastest (and much
        return _localized_basis(M, basis, contact_count, patches, exhaustive, seed)  # faster
        # on a loaded machine)


def _localize_within(M: np.ndarray, V: np.ndarray, tol: float) -> list[np.ndarray]:
    """L1 circuits of the span of V (orthonormal columns), one LP per support coordinate."""
    if V.shape[1] == 1:
        return [_polish(M, V[:, 0], tol)]
    out = []
    for k in np.flatnonzero(np.linalg.norm(V, axis=1) > SUPPORT_TOL):
        x = _l1_smallest(V, V[k])
        if x is not None:
            out.append(_polish(M, x, tol))
    return out


def _representatives(basis: np.ndarray, contact_count: int | None) -> np.ndarray:
    """One coordinate per contact of the support (its R, else its S): supports are counted in
    contacts, so one L1 problem per contact suffices."""
    nonzero = np.linalg.norm(basis, axis=1) > SUPPORT_TOL
    if contact_count is None:
        return np.flatnonzero(nonzero)
    c = contact_count
    a = np.flatnonzero(nonzero[:c] | nonzero[c:])
    return np.where(nonzero[a], a, a + c)


def _localized_basis(M: np.ndarray, basis: np.ndarray, contact_count: int | None,
                     patches, exhaustive: bool | None, seed: int) -> np.ndarray:
    n, d = basis.shape
    tol = max(M.shape) * EPS * np.linalg.norm(M, 2)
    found: list[np.ndarray] = []
    covered = np.zeros(n, dtype=bool)
    seen: set[tuple[int, ...]] = set()
    for cols in patches:
        _, V, _, rank = svd_rank(M[:, cols], tol)
        if V.shape[1] - rank == 0 or tuple(cols) in seen:
            continue
        seen.add(tuple(cols))
        for y in _localize_within(M[:, cols], V[:, rank:], tol):
            x = np.zeros(n)
            x[cols] = y
            covered |= x != 0
            found.append(x)
    if exhaustive is None:
        exhaustive = n <= 400
    for k in _representatives(basis, contact_count):
        if not exhaustive and covered[k]:
            continue
        x = _l1_smallest(basis, basis[k])
        if x is None:
            continue
        x = _polish(M, x, tol)
        covered |= x != 0
        found.append(x)

    def key(x: np.ndarray) -> tuple:
        nz = np.flatnonzero(x)
        return (_n_contacts(x, contact_count), nz.size, tuple(nz))

    chosen: list[np.ndarray] = []
    Q = np.zeros((n, 0))
    for x in sorted(found, key=key):
        r = x - Q @ (Q.T @ x)
        if np.linalg.norm(r) > INDEPENDENCE_TOL * np.linalg.norm(x):
            chosen.append(x)
            Q = np.column_stack([Q, r / np.linalg.norm(r)])
        if len(chosen) == d:
            break
    rng = np.random.default_rng(seed)
    while len(chosen) < d:  # a normalization orthogonal to the chosen span forces independence
        g = basis @ rng.standard_normal(d)
        g -= Q @ (Q.T @ g)
        x = _l1_smallest(basis, basis.T @ g)
        x = basis @ (basis.T @ g) if x is None else _polish(M, x, tol)
        r = x - Q @ (Q.T @ x)
        chosen.append(x)
        Q = np.column_stack([Q, r / np.linalg.norm(r)])
    return np.column_stack(sorted(chosen, key=key))
