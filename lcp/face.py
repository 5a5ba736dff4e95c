"""A canonical solution on the face of an LCP solution (for problems whose solution is not unique).

Let z solve w = M z + q, 0 <= z perp w >= 0, and let A = {i : w_i = 0} (the indices where z may
be positive). The face of z,

    F(z) = { y : y_A >= 0, y_{A^c} = 0, (M y + q)_A = 0, (M y + q)_{A^c} >= 0 },

is a convex polyhedron of solutions that share z's complementary pattern (every y in F(z) is a
solution). When M_AA is nonsingular F(z) = {z}. Otherwise two methods can return two different
points of the same face; `face_minimum_norm` returns a point of F(z) that depends only on the
face, not on the point a method found: lexicographically, first the minimum of a linear
functional c'y when `c` is given (a linear program), then, among those minimizers, the unique
minimizer of |G y|^2 + eps |y|^2 (G: a linear map, e.g. from LCP unknowns to contact forces).
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
    c: np.ndarray | None = None,
    tol: float | None = None,
    eps: float = 1e-10,
    max_walk: int = 20,
) -> FaceResult:
    """The point of the face of z minimizing c'y, then |G y| (see the module docstring).

    With `c`, the linear stage walks from face to face: a minimizer of c'y on the face of z is
    again a solution, whose own face (its degenerate indices, z_i = w_i = 0, may now go either
    way) can hold a lower c'y; the walk stops when c'y no longer decreases (at most max_walk
    linear programs), so it reaches a local minimum of c'y over the solution set.
    """
    M, q = problem.M, problem.q
    z0 = np.asarray(z, dtype=float)
    scale = max(np.abs(q).max(initial=0.0), np.abs(z0).max(initial=0.0), 1e-300)
    tol = 1e-9 * scale if tol is None else tol
    z = z0
    face = _Face(M, q, z, tol)
    if face.nullity == 0:
        return FaceResult(z0, 0, 0.0, "unique")
    bound = None
    if c is not None:  # stage 1: descend c'y over faces, then keep c'y at its minimum
        c = np.asarray(c, dtype=float)
        slack = 1e-9 * max(abs(c @ z), scale)
        for _ in range(max_walk):
            best = None
            for f in (face, _Face(M, q, z, tol, degenerate_in_A=False)):
                if f.nullity == 0:
                    continue
                x1, status = _lp(c[f.A] @ f.N, f.Aineq, f.bineq)
                if x1 is None:
                    return FaceResult(z0, f.nullity, 0.0, f"failed (linear stage): {status}")
                z1 = f.point(x1)
                if best is None or c @ z1 < c @ best:
                    best = z1
            if best is None or c @ best >= c @ z - slack:
                break
            z = best
            face = _Face(M, q, z, tol)
            if face.nullity == 0:
                break
        bound = c @ z + slack
    if face.nullity == 0:
        return FaceResult(z, 0, float(np.abs(z - z0).max()), "selected")
    GA = (np.eye(q.size) if G is None else np.asarray(G))[:, face.A]
    GN = GA @ face.N
    # min 1/2 |G_A (z_A + N x)|^2 + eps/2 |N x|^2  s.t.  the face's inequalities (and c'y bound)
    P = GN.T @ GN + eps * np.eye(face.nullity)
    Aineq, bineq = face.Aineq, face.bineq
    if bound is not None:
        cN = c[face.A] @ face.N
        Aineq = np.vstack([Aineq, cN[None, :]])
        bineq = np.append(bineq, max(bound - c @ z, 0.0))
    x, status = _qp(P, GN.T @ (GA @ z[face.A]), Aineq, bineq)
    if x is None:
        return FaceResult(z0, face.nullity, 0.0, f"failed: {status}")
    y = face.point(x)
    return FaceResult(y, face.nullity, float(np.abs(y - z0).max()), "selected")


class _Face:
    """F(z) parametrized as y_A = z_A + N x (N: null space of M_AA), y_Ac = 0, Aineq x <= bineq.

    A = {i : w_i = 0}, the largest face; with degenerate_in_A=False the indices where both
    z_i = w_i = 0 go to the other side (z_i = 0 kept, w_i >= 0 free): the face that lets the
    degenerate pairs open the other way.
    """

    def __init__(self, M: np.ndarray, q: np.ndarray, z: np.ndarray, tol: float,
                 degenerate_in_A: bool = True):
        w = M @ z + q
        self.z = z
        in_A = w <= tol
        if not degenerate_in_A:
            in_A &= z > tol
        self.A = np.flatnonzero(in_A)
        Ac = np.setdiff1d(np.arange(q.size), self.A)
        if self.A.size == 0:
            self.nullity = 0
            return
        MAA = M[np.ix_(self.A, self.A)]
        _, sig, Vt = np.linalg.svd(MAA)
        rank_tol = max(MAA.shape) * np.finfo(float).eps * max(sig.max(initial=0.0), 1.0) * 1e3
        rank = int(np.sum(sig > rank_tol))
        self.nullity = self.A.size - rank
        self.N = Vt[rank:].T
        # y_A = z_A + N x >= 0 and w_Ac + M_{Ac,A} N x >= 0 (w_Ac > tol > 0; z_A clipped at 0)
        self.Aineq = np.vstack([-self.N, -(M[np.ix_(Ac, self.A)] @ self.N)])
        self.bineq = np.concatenate([np.maximum(z[self.A], 0.0), np.maximum(w[Ac], 0.0)])

    def point(self, x: np.ndarray) -> np.ndarray:
        y = self.z.copy()
        y[self.A] = np.maximum(self.z[self.A] + self.N @ x, 0.0)
        return y


def _lp(c: np.ndarray, Aineq: np.ndarray, bineq: np.ndarray):
    """min c'x s.t. Aineq x <= bineq (x free), by HiGHS."""
    from scipy.optimize import linprog

    res = linprog(c, A_ub=Aineq, b_ub=bineq, bounds=(None, None), method="highs")
    if res.status != 0:
        return None, res.message
    return res.x, "optimal"


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
