"""The admissible contact forces of a packing at rest under gravity, as linear constraints.

A packing (models.Lattice) with friction coefficients per contact (models.System) is at rest,
so its accelerations vanish: Newton-Euler (models.dynamics) with nu' = 0 reads

    H^T lambda + f = 0,      lambda = [R (c); S (c)],   f = (0, -m_i g, 0) per disk,

(force and torque balance of every disk: 3p equations) together with the contact laws at rest,
Signorini R >= 0 and Coulomb |S| <= mu R (Eqs. 2.5-2.7 with every v = 0; S = 0 where mu = 0).
These are linear: the admissible set P = {lambda : H^T lambda = -f, R >= 0, S - mu R <= 0,
-S - mu R <= 0} is a convex polyhedron (McNamara & Herrmann, PRE 70, 061303, 2004).

`ForceLP` holds P once in HiGHS (highspy) and re-solves it for one objective after another,
warm-started from the previous basis (the ranges of every R and S are 4c such LPs);
`DualForceLP` solves the same LPs through their dual, about twice as fast on deposited piles.
Every optimum is checked against P in floating point (`admissible`: the balance's
componentwise backward error and the laws' violation), and its value against the dual bound
(`certified`), not taken on the solver's word (verify.statics.ends: what is done when a check
fails).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from rigidlcp import models
from rigidlcp.lcp.errors import InvalidInput
from rigidlcp.lcp.quiet import new_highs

#: HiGHS's primal and dual feasibility tolerances (relative to O(1) data: rows are scaled).
LP_TOL = 1e-10
#: The dual certificate's tolerance (`ForceLP.certified`), relative like `admissible`'s 1e-8:
#: HiGHS applies LP_TOL to its scaled LP, and the unscaled reduced costs of the primal simplex
#: reached -2.3e-9 (|y| = 1.1) on one of 143 range LPs of the 1000-disk pile.
DUAL_TOL = 1e-8
#: Acceptance of a point of P (`StaticProblem.admissible`): the balance's componentwise
#: backward error and the laws' relative violation at most this, lcp.acceptance.residual's TOL
#: (the one tolerance of "solved" for an LCP): the point is then an exact equilibrium of the
#: packing with every balance coefficient and weight changed by at most 1e-8 of its size.
BALANCE_TOL = 1e-8


class StaticProblem:
    """P for a system (its gamma must be 0: a packing at rest under gravity only).

    A (3p x 2c, sparse) = H^T, b = -f; frictional contacts `fric` (mu > 0) carry the cone rows;
    `scale` is the largest disk weight m_i g (zero tests are relative to it).
    """

    def __init__(self, system: models.System):
        if system.gamma != 0:
            raise InvalidInput("a static analysis needs gamma = 0 (a packing at rest)")
        dyn = models.Dynamics(system)
        self.system, self.c, self.p = system, system.c, system.p
        self.mu = np.asarray(system.mu, dtype=float)
        self.A = sp.csr_matrix(dyn.H.T)
        self.b = -dyn.f
        self.fric = np.flatnonzero(self.mu > 0)
        self.scale = float(np.max(system.masses)) * max(system.g, 1e-300)
        c = self.c
        k = self.fric.size
        rows = np.r_[np.arange(k), np.arange(k), k + np.arange(k), k + np.arange(k)]
        cols = np.r_[c + self.fric, self.fric, c + self.fric, self.fric]
        vals = np.r_[np.ones(k), -self.mu[self.fric], -np.ones(k), -self.mu[self.fric]]
        #: cone rows G lambda <= 0: rows 0..k-1 are S - mu R, rows k..2k-1 are -S - mu R
        self.G = sp.csr_matrix((vals, (rows, cols)), shape=(2 * k, 2 * c))
        self.lb = np.r_[np.zeros(c), np.where(self.mu > 0, -np.inf, 0.0)]
        self.ub = np.r_[np.full(c, np.inf), np.where(self.mu > 0, np.inf, 0.0)]
        self._absA = None  # |A|, for backward_error

    @property
    def n(self) -> int:
        return 2 * self.c

    def residuals(self, lam: np.ndarray) -> tuple[float, float]:
        """(max |H^T lambda + f|, largest violation of R >= 0, |S| <= mu R and S = 0 where
        mu = 0), in units of force."""
        lam = np.asarray(lam, dtype=float)
        eq = float(np.max(np.abs(self.A @ lam - self.b), initial=0.0))
        viol = max(float(np.max(self.G @ lam, initial=0.0)),
                   float(np.max(self.lb - lam, initial=0.0)),
                   float(np.max(lam - self.ub, initial=0.0)))
        return eq, viol

    def backward_error(self, lam: np.ndarray) -> float:
        """Componentwise (Oettli-Prager) backward error of the balance A lambda = b:
        max_i |A lambda - b|_i / max((|A| |lambda| + |b|)_i, scale). lambda balances exactly
        the forces of a packing whose balance coefficients (normals, tangents, lever arms) and
        weights are each changed by at most this fraction of their own size (of the largest
        weight on a row whose terms are smaller), as lcp.acceptance.accuracy's backward_error
        for an LCP; its own rounding is below 8 eps (at most 6 terms a row)."""
        lam = np.asarray(lam, dtype=float)
        if self._absA is None:
            self._absA = abs(self.A)
        r = np.abs(self.A @ lam - self.b)
        s = np.maximum(self._absA @ np.abs(lam) + np.abs(self.b), self.scale)
        return float(np.max(r / s, initial=0.0))

    def law_error(self, lam: np.ndarray) -> float:
        """The largest violation of R >= 0, |S| <= mu R, S = 0 where mu = 0, relative to the
        force scale (the largest weight, or |lambda|_inf when larger)."""
        viol = self.residuals(lam)[1]
        return viol / max(self.scale, float(np.max(np.abs(lam), initial=0.0)))

    def admissible(self, lam: np.ndarray, tol: float = BALANCE_TOL) -> bool:
        """lambda in P: its balance's backward error (`backward_error`) and its laws' violation
        (`law_error`) both <= tol."""
        return self.backward_error(lam) <= tol and self.law_error(lam) <= tol


class ForceLP:
    """min cost . lambda over P by HiGHS's simplex, warm-started between objectives.

    P is passed in cone coordinates: at a frictional contact u = mu R - S >= 0 and
    v = mu R + S >= 0 (R = (u + v) / 2 mu, S = (v - u) / 2), at a frictionless one R >= 0 (S = 0).
    The cone rows become bounds on the columns, so the LP has only the 3p balance rows: a
    smaller basis, and about 3x faster per range LP than the rows-and-columns form on deposited
    piles (docs/packings.md, Scale). Its optima are mapped back, lambda = T w, and checked
    against P by the callers."""

    def __init__(self, prob: StaticProblem):
        import highspy

        self.prob, self.hs = prob, highspy
        lp, self.T, k = cone_lp(prob)
        nw = lp.num_col_
        self.u_col, self.v_col = np.arange(k), k + np.arange(k)
        # primal simplex: a new objective leaves the last basis primal feasible, so each
        # range LP restarts from the previous optimum (3.5x faster than the default here)
        h = new_highs(presolve="off", simplex_strategy=4, primal_feasibility_tolerance=LP_TOL,
                      dual_feasibility_tolerance=LP_TOL)
        h.passModel(lp)
        self.h, self.nw = h, nw
        self.cols = np.arange(nw, dtype=np.int32)
        self.TT = sp.csr_matrix(self.T.T)
        self.KT = sp.csr_matrix((prob.A @ self.T).T)  # the balance rows' transpose, in w
        self._K: sp.csc_matrix | None = None

    @property
    def K(self) -> sp.csc_matrix:
        """The balance rows in cone coordinates, K = A T, by columns (built once): the
        bases' columns are cut from it (verify.statics.ends)."""
        if self._K is None:
            self._K = sp.csc_matrix(self.KT.T)
        return self._K

    def solve(self, cost: np.ndarray) -> tuple[str, np.ndarray | None]:
        """("optimal", lambda) | ("unbounded", None) | ("infeasible", None) | ("failed", None)."""
        h, st = self.h, self.hs.HighsModelStatus
        h.changeColsCost(self.nw, self.cols, self.TT @ np.asarray(cost, dtype=float))
        h.run()
        status = h.getModelStatus()
        if status == st.kOptimal:
            return "optimal", self.T @ np.asarray(h.getSolution().col_value, dtype=float)
        if status in (st.kUnbounded, st.kUnboundedOrInfeasible):
            return "unbounded", None
        if status == st.kInfeasible:
            return "infeasible", None
        return "failed", None

    def certified(self, cost: np.ndarray, lam: np.ndarray, tol: float = DUAL_TOL,
                  fixed: tuple[int, ...] = ()) -> bool:
        """Whether the row duals y of the last optimum (lam) certify its value by weak
        duality: y is dual feasible, its reduced costs d = T^T cost - K^T y >= -tol max(1, |y|)
        on the columns w >= 0 (K = A T: balance in cone coordinates; `fixed`: columns fixed at
        0 by `set_cone_row`, whose d may have any sign), and the gap cost . lam - b . y is
        within tol of the force scale (of the objective, of |b| . |y| and of the largest
        weight). Then cost . lambda >= b . y on all of P (on its face with the fixed columns
        at 0), to that tolerance."""
        y = np.asarray(self.h.getSolution().row_dual, dtype=float)
        return dual_bound_holds(self, cost, lam, y, tol, fixed)

    def ray_checked(self, cost: np.ndarray, tol: float = 1e-9,
                    fixed: tuple[int, ...] = ()) -> bool:
        """Whether HiGHS's primal ray r (cone coordinates) after an "unbounded" proves it: r >= 0
        (0 on the `fixed` columns), K r = 0 and cost . T r < 0, each to tol of the ray's own
        terms; then lambda + t T r stays in P for every t >= 0 and cost . lambda -> -inf."""
        _, has_ray, values = self.h.getPrimalRay()
        if not has_ray:
            return False
        return ray_defect(self, np.asarray(values, dtype=float), cost, tol, fixed) is None

    def set_cone_row(self, row: int, equality: bool) -> int:
        """Make cone row `row` (0..2k-1: S - mu R <= 0 for the k frictional contacts, then
        -S - mu R <= 0) an equality (S = +-mu R: u = 0 or v = 0) or restore it; returns the
        column (u or v) whose bounds changed."""
        k = self.prob.fric.size
        col = int(self.u_col[row] if row < k else self.v_col[row - k])
        self.h.changeColBounds(col, 0.0, 0.0 if equality else self.hs.kHighsInf)
        return col


def dual_bound_holds(lp: ForceLP, cost: np.ndarray, lam: np.ndarray, y: np.ndarray,
                     tol: float = DUAL_TOL, fixed: tuple[int, ...] = ()) -> bool:
    """ForceLP.certified's test of y (one entry per balance row) for min cost . lambda = cost .
    lam over P in lp's cone coordinates."""
    infeasible, gap = dual_defects(lp, cost, lam, y, fixed)
    return infeasible <= tol and gap <= tol


def dual_defects(lp: ForceLP, cost: np.ndarray, lam: np.ndarray, y: np.ndarray,
                 fixed: tuple[int, ...] = ()) -> tuple[float, float]:
    """(dual infeasibility -min d / max(1, |y|_inf), gap |cost . lam - b . y| / the force
    scale of ForceLP.certified): y certifies lam's value when both are <= its tol."""
    cost = np.asarray(cost, dtype=float)
    d = lp.TT @ cost - lp.KT @ y
    d[list(fixed)] = 0.0
    obj, dual = float(cost @ lam), float(lp.prob.b @ y)
    big = max(lp.prob.scale, abs(obj), float(np.abs(lp.prob.b) @ np.abs(y)))
    infeasible = -float(np.min(d, initial=0.0)) / max(1.0, float(np.max(np.abs(y), initial=0.0)))
    return infeasible, abs(obj - dual) / big


def ray_defect(lp: ForceLP, r: np.ndarray, cost: np.ndarray, tol: float = 1e-9,
               fixed: tuple[int, ...] = ()) -> tuple[str, float] | None:
    """None when r (cone coordinates) proves min cost . lambda unbounded (ForceLP.ray_checked),
    else (the first part that fails: "sign", "fixed", "balance" or "descent", its measure
    relative to the ray's own terms, to compare with tol)."""
    big = float(np.max(np.abs(r), initial=0.0))
    if not big > 0.0:
        return "sign", 0.0
    lam = lp.T @ r
    drop = -float(np.asarray(lp.TT @ np.asarray(cost, dtype=float)) @ r)
    terms = np.maximum(abs(lp.KT.T) @ np.abs(r), big)
    parts = (("sign", -float(np.min(r, initial=0.0)) / big),
             ("fixed", max((abs(r[j]) for j in fixed), default=0.0) / big),
             ("balance", float(np.max(np.abs(lp.KT.T @ r) / terms, initial=0.0))))
    for name, value in parts:
        if not value <= tol:
            return name, value
    size = float(np.max(np.abs(lam), initial=0.0))
    if not drop > tol * size:
        return "descent", drop / size if size > 0 else 0.0
    return None


class DualForceLP:
    """The range LPs min cost . lambda over P through their dual, max b . y subject to
    K^T y <= T^T cost (K = A T: the balance rows in ForceLP's cone coordinates; y free, one
    column per balance row, one row per cone coordinate), by HiGHS's dual simplex.

    A new cost changes only the rows' upper bounds, so the last basis stays dual feasible and
    each LP restarts from the previous optimum: about half the pivots of ForceLP's primal
    simplex on deposited piles, 1.8x faster at 1000 disks (docs/packings.md, Scale). The row
    duals of its optimum are the cone coordinates w >= 0 of an optimum of the range LP
    (lambda = T w, checked in P by the callers) and its y is the dual certificate
    (`certified`). When the dual is infeasible (the range LP unbounded) or its run fails, the
    range LP is solved by `primal` (a ForceLP), whose ray is checked (`ray_checked`)."""

    def __init__(self, prob: StaticProblem, primal: ForceLP):
        import highspy

        self.prob, self.hs, self.primal = prob, highspy, primal
        K = sp.csr_matrix(primal.KT.T)
        m, nw = K.shape
        lp = highspy.HighsLp()
        lp.num_col_, lp.num_row_ = m, nw
        lp.col_cost_ = -np.asarray(prob.b, dtype=float)
        lp.col_lower_ = np.full(m, -highspy.kHighsInf)
        lp.col_upper_ = np.full(m, highspy.kHighsInf)
        lp.row_lower_ = np.full(nw, -highspy.kHighsInf)
        lp.row_upper_ = np.zeros(nw)
        A = sp.csc_matrix(primal.KT)
        lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
        lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (A.indptr, A.indices,
                                                                         A.data)
        h = new_highs(presolve="off", simplex_strategy=1, primal_feasibility_tolerance=LP_TOL,
                      dual_feasibility_tolerance=LP_TOL)
        h.passModel(lp)
        self.h, self.nw = h, nw
        self.rows = np.arange(nw, dtype=np.int32)
        self.lower = np.full(nw, -highspy.kHighsInf)
        self.upper = np.zeros(nw)  # the rows' upper bounds as passed (row_upper_ above)
        self.last = self  # which LP gave the last answer

    def solve(self, cost: np.ndarray) -> tuple[str, np.ndarray | None]:
        """As ForceLP.solve."""
        h, st = self.h, self.hs.HighsModelStatus
        upper = self.primal.TT @ np.asarray(cost, dtype=float)
        if hasattr(h, "changeRowsBounds"):
            h.changeRowsBounds(self.nw, self.rows, self.lower, upper)
        else:  # highspy 1.10 (the lowest pyproject allows): one row at a time, changed rows only
            for i in np.flatnonzero(upper != self.upper):
                h.changeRowBounds(int(i), -self.hs.kHighsInf, float(upper[i]))
        self.upper = upper
        h.run()
        if h.getModelStatus() == st.kOptimal:
            self.last = self
            w = -np.asarray(h.getSolution().row_dual, dtype=float)
            return "optimal", self.primal.T @ w
        self.last = self.primal
        return self.primal.solve(cost)

    def set_basis(self, cols: np.ndarray) -> None:
        """Start the next solve from the basis of a vertex of P: `cols`, its basic cone columns
        (one per balance row), are the dual LP's tight rows (nonbasic at their upper bound),
        every y basic. Any vertex of P is a dual feasible start for every cost."""
        st = self.hs.HighsBasisStatus
        basis = self.hs.HighsBasis()
        rows = [st.kBasic] * self.nw
        for j in np.asarray(cols, dtype=int):
            rows[j] = st.kUpper
        basis.col_status = [st.kBasic] * self.prob.A.shape[0]
        basis.row_status = rows
        basis.valid = True
        self.h.setBasis(basis)

    def certified(self, cost: np.ndarray, lam: np.ndarray, tol: float = DUAL_TOL) -> bool:
        """ForceLP.certified, with y the dual LP's optimum."""
        if self.last is not self:
            return self.primal.certified(cost, lam, tol)
        y = np.asarray(self.h.getSolution().col_value, dtype=float)
        return dual_bound_holds(self.primal, cost, lam, y, tol)

    def ray_checked(self, cost: np.ndarray, tol: float = 1e-9) -> bool:
        """ForceLP.ray_checked (an unbounded range LP is always the primal's answer)."""
        return self.last is self.primal and self.primal.ray_checked(cost, tol)


def cone_lp(prob: StaticProblem):
    """(HiGHS LP of P in cone coordinates w >= 0 (columns u (k), v (k), then R of the
    frictionless contacts; only the 3p balance rows), T with lambda = T w, k)."""
    import highspy

    c, mu, fric = prob.c, prob.mu, prob.fric
    k = fric.size
    plain = np.flatnonzero(mu == 0)
    nw = 2 * k + plain.size
    rows = np.r_[fric, c + fric, fric, c + fric, plain]
    cols = np.r_[np.arange(k), np.arange(k), k + np.arange(k), k + np.arange(k),
                 2 * k + np.arange(plain.size)]
    vals = np.r_[0.5 / mu[fric], -0.5 * np.ones(k), 0.5 / mu[fric], 0.5 * np.ones(k),
                 np.ones(plain.size)]
    T = sp.csr_matrix((vals, (rows, cols)), shape=(prob.n, nw))
    K = sp.csc_matrix(prob.A @ T)
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = nw, prob.A.shape[0]
    lp.col_cost_ = np.zeros(nw)
    lp.col_lower_ = np.zeros(nw)
    lp.col_upper_ = np.full(nw, highspy.kHighsInf)
    lp.row_lower_ = lp.row_upper_ = np.asarray(prob.b, dtype=float)
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (K.indptr, K.indices, K.data)
    return lp, T, k


def interior_point(prob: StaticProblem, bound: float) -> tuple[str, np.ndarray | None]:
    """A point of P with every cone coordinate (u = mu R - S, v = mu R + S; R where mu = 0)
    in [0, bound], from HiGHS's interior-point method without crossover (zero objective: near
    the analytic centre), so that every inequality of P that is not an implicit equality has a
    clearly positive slack there: ("optimal", lambda), ("infeasible", None) when HiGHS finds
    none in the box, else ("failed", None). In cone coordinates the LP has only the 3p
    balance rows: about 4x faster than with the cone rows (docs/packings.md, Scale)."""
    import highspy

    lp, T, _ = cone_lp(prob)
    lp.col_upper_ = np.full(lp.num_col_, bound)
    h = new_highs(solver="ipm", run_crossover="off", presolve="off")
    h.passModel(lp)
    h.run()
    status = h.getModelStatus()
    if status == highspy.HighsModelStatus.kOptimal:
        return "optimal", T @ np.asarray(h.getSolution().col_value, dtype=float)
    if status == highspy.HighsModelStatus.kInfeasible:
        return "infeasible", None
    return "failed", None
