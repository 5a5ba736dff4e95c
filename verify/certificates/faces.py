"""The face of an LCP solution: its null directions, and linear programs over it.

For a solution z* of w = M z + q, 0 <= z perp w >= 0, the sign pattern (verify.uniqueness.
sign_pattern) splits the pairs into P (z*_i > 0, w*_i = 0), W (w*_i > 0, z*_i = 0) and D
(degenerate: z*_i = w*_i = 0). Every solution with the same contact states, degenerate pairs
free, lies in the affine set

    A(z*) = { z : z_W = 0, (M z + q)_P = 0 },

and those solutions are the union, over S in D, of the polyhedra
F_S = { z in A : z_S >= 0, w_S = 0, z_{D-S} = 0, w_{D-S} >= 0, z_P >= 0, w_W >= 0 }.
Two of them are convex faces of the solution set through z*: F_D (degenerate pairs on the
z side) and F_0 (on the w side); with D empty they coincide (*the* face).

* `null_directions`: an orthonormal basis N of the directions of A (the null space of
  M[P, P u D], by SVD with the standard rank tolerance), with the spectral gap that justifies
  the rank. If L N = 0, the quantity L z is the same on all of A, hence on every F_S: unique
  among the solutions with these contact states (stage (b) of verify.certificates.stages).
* `FaceLP`: min / max of linear functions over F_D or F_0 (HiGHS through its own API, one
  model re-solved with new costs, so each range costs a few simplex iterations).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rigidlcp.lcp.quiet import new_highs

#: HiGHS tolerances for the face LPs (its defaults are 1e-7).
_TOL = 1e-10


@dataclass
class NullDirections:
    """N: orthonormal basis (columns, in the coordinates `cols` = P u D) of the directions of
    A(z*); smallest kept and largest dropped singular value of M[P, P u D] and the tolerance."""

    cols: np.ndarray
    N: np.ndarray
    kept_min: float
    dropped_max: float
    rank_tol: float

    @property
    def dim(self) -> int:
        return self.N.shape[1]

    @property
    def gap_ok(self) -> bool:
        """The rank decision is clear: kept singular values >= 1e3 times the tolerance."""
        return self.kept_min >= 1e3 * self.rank_tol

    def moves(self, L: np.ndarray, zs: float) -> np.ndarray:
        """Per row of L, the largest |L_j d| over unit directions d of A, relative to
        |L_j|_1 (0 when L_j z is constant on A); shape (rows of L,)."""
        if self.dim == 0:
            return np.zeros(L.shape[0])
        LN = L[:, self.cols] @ self.N
        return np.linalg.norm(LN, axis=1) / np.maximum(np.sum(np.abs(L), axis=1), 1e-300)


def null_directions(M: np.ndarray, P: np.ndarray, D: np.ndarray) -> NullDirections:
    """The directions of A(z*) (module docstring): null space of M[P, P u D] by SVD."""
    cols = np.flatnonzero(P | D)
    rows = np.flatnonzero(P)
    if cols.size == 0:
        return NullDirections(cols, np.zeros((0, 0)), np.inf, 0.0, 0.0)
    if rows.size == 0:
        return NullDirections(cols, np.eye(cols.size), np.inf, 0.0, 0.0)
    K = M[np.ix_(rows, cols)]
    _, sig, Vt = np.linalg.svd(K)
    rank_tol = max(K.shape) * np.finfo(float).eps * max(float(sig.max(initial=0.0)), 1e-300)
    rank = int(np.sum(sig > rank_tol))
    return NullDirections(cols, Vt[rank:].T.copy(),
                          float(sig[:rank].min(initial=np.inf)),
                          float(sig[rank:].max(initial=0.0)), rank_tol)


class FaceLP:
    """min c'z over F_S (S = D: `side="z"`, S = empty: `side="w"`), by HiGHS's simplex.

    z_i = 0 on W (and on D for side "w"); w_i = (M z + q)_i = 0 on P (and on D for side
    "z"), >= 0 elsewhere; z >= 0. `bound` (optional) adds z <= bound (a box for witnesses
    along unbounded directions).
    """

    def __init__(self, M: np.ndarray, q: np.ndarray, P: np.ndarray, D: np.ndarray, side: str,
                 bound: float | None = None):
        import highspy

        n = q.size
        zero_z = ~P & ~D if side == "z" else ~P
        zero_w = P | D if side == "z" else P
        inf = highspy.kHighsInf
        K = sp.csc_matrix(M)
        lp = highspy.HighsLp()
        lp.num_col_, lp.num_row_ = n, n
        lp.col_cost_ = np.zeros(n)
        ub = inf if bound is None else float(bound)
        lp.col_lower_ = np.zeros(n)
        lp.col_upper_ = np.where(zero_z, 0.0, ub)
        lp.row_lower_ = -q
        lp.row_upper_ = np.where(zero_w, -q, inf)
        lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
        lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (
            K.indptr, K.indices, K.data)
        h = new_highs(presolve="off", primal_feasibility_tolerance=_TOL,
                      dual_feasibility_tolerance=_TOL)
        h.passModel(lp)
        self._h, self._hs, self.n = h, highspy, n

    def solve(self, c: np.ndarray) -> tuple[str, np.ndarray | None]:
        """("optimal", z) | ("unbounded", None) | ("infeasible", None) | ("failed", None)."""
        h, hs = self._h, self._hs
        h.changeColsCost(self.n, np.arange(self.n, dtype=np.int32), np.asarray(c, dtype=float))
        h.run()
        st = h.getModelStatus()
        if st == hs.HighsModelStatus.kOptimal:
            return "optimal", np.maximum(np.asarray(h.getSolution().col_value), 0.0)
        if st in (hs.HighsModelStatus.kUnbounded, hs.HighsModelStatus.kUnboundedOrInfeasible):
            return "unbounded", None
        if st == hs.HighsModelStatus.kInfeasible:
            return "infeasible", None
        return "failed", None
