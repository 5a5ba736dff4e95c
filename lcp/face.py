"""A canonical solution on the face of an LCP solution (for problems whose solution is not unique).

Let z solve w = M z + q, 0 <= z perp w >= 0, and let A = {i : w_i = 0} (the indices where z may
be positive). The face of z,

    F(z) = { y : y_A >= 0, y_{A^c} = 0, (M y + q)_A = 0, (M y + q)_{A^c} >= 0 },

is a convex polyhedron of solutions that share z's complementary pattern (every y in F(z) is a
solution). When M_AA is nonsingular F(z) = {z}. Otherwise two methods can return two different
vertices of the same face; `face_minimum_norm` returns the unique minimizer of |G y|^2 + eps |y|^2
over F(z) (G: a linear map, e.g. from LCP unknowns to contact forces), which does not depend on
which point of the face a method found.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .problem import LCP


@dataclass
class FaceResult:
    z: np.ndarray
    nullity: int  # dimension of the null space of M_AA (0: the face is one point)
    moved: float  # max |z_new - z|
    status: str  # "unique", "selected", or "failed: ..." (then z is the input)


def face_minimum_norm(
    problem: LCP,
    z: np.ndarray,
    G: np.ndarray | None = None,
    *,
    tol: float | None = None,
    eps: float = 1e-10,
) -> FaceResult:
    """The minimum-|G y| point of the face of the solution z (see the module docstring)."""
    M, q = problem.M, problem.q
    z = np.asarray(z, dtype=float)
    w = M @ z + q
    scale = max(np.abs(q).max(initial=0.0), np.abs(z).max(initial=0.0), 1e-300)
    tol = 1e-9 * scale if tol is None else tol
    A = np.flatnonzero(w <= tol)
    if A.size == 0:
        return FaceResult(z, 0, 0.0, "unique")
    MAA = M[np.ix_(A, A)]
    U, sig, Vt = np.linalg.svd(MAA)
    rank_tol = max(MAA.shape) * np.finfo(float).eps * max(sig.max(initial=0.0), 1.0) * 1e3
    rank = int(np.sum(sig > rank_tol))
    nullity = A.size - rank
    if nullity == 0:
        return FaceResult(z, 0, 0.0, "unique")
    N = Vt[rank:].T  # null space of M_AA: y_A = z_A + N x keeps (M y + q)_A = 0
    Ac = np.setdiff1d(np.arange(q.size), A)
    GA = (np.eye(q.size) if G is None else np.asarray(G))[:, A]
    GN = GA @ N
    # min 1/2 |G_A (z_A + N x)|^2 + eps/2 |N x|^2  s.t.  z_A + N x >= 0,  w_Ac + M_{Ac,A} N x >= 0
    P = GN.T @ GN + eps * np.eye(nullity)
    c = GN.T @ (GA @ z[A])
    Aineq = np.vstack([-N, -(M[np.ix_(Ac, A)] @ N)])
    bineq = np.concatenate([z[A], w[Ac]])
    x, status = _qp(P, c, Aineq, bineq)
    if x is None:
        return FaceResult(z, nullity, 0.0, f"failed: {status}")
    y = z.copy()
    y[A] = np.maximum(z[A] + N @ x, 0.0)
    return FaceResult(y, nullity, float(np.abs(y - z).max()), "selected")


def _qp(P: np.ndarray, c: np.ndarray, Aineq: np.ndarray, bineq: np.ndarray):
    """min 1/2 x'Px + c'x s.t. Aineq x <= bineq, by Clarabel (interior point)."""
    import clarabel

    n = c.size
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = 1e-12
    settings.tol_feas = 1e-12
    Pu = sp.triu(sp.csc_matrix((P + P.T) / 2), format="csc")
    solver = clarabel.DefaultSolver(
        Pu, c, sp.csc_matrix(Aineq), bineq, [clarabel.NonnegativeConeT(bineq.size)], settings
    )
    sol = solver.solve()
    status = str(sol.status)
    if "Solved" not in status:
        return None, status
    return np.array(sol.x).reshape(n), status
