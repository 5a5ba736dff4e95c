"""The MILP of verify.ranges.steady in HiGHS, re-solved with new costs, and its linear
relaxation with a *certified* lower bound (used by verify.ranges.valid_steady to decide an end
without branching when a checked valid steady state attains the relaxation's bound).

Certificate. The MILP is min c.x over lo <= A x <= hi, lb <= x <= ub, binaries. For any row
multipliers y (here HiGHS's duals of the relaxation, either sign convention), weak duality of
the Lagrangian gives, for every x of the box with lo <= A x <= hi (so for every point of the
MILP),

    c.x = (c - A^T y).x + y.(A x) >= sum_j min(d_j lb_j, d_j ub_j) + sum_i min(y_i lo_i, y_i hi_i),

d = c - A^T y, each term taken on the finite side (a multiplier whose side is infinite is set
to 0 first, which keeps the inequality). Every column of the formulation is boxed (forces by
the proved bounds, r alpha by the rotation cap, velocities by the velocity box, binaries in
[0, 1]), so the bound is finite; it is evaluated here in numpy, independently of HiGHS's claim
of optimality, and lowered by a rounding margin.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from rigidlcp.lcp.errors import InvalidInput
from rigidlcp.lcp.quiet import new_highs
from rigidlcp.verify.certificates.clocked import (  # noqa: F401  (clock: re-exported)
    BACKSTOP_FACTOR,
    BACKSTOP_S,
    clock,
    start_cpu_interrupt,
)
from rigidlcp.verify.certificates.uniqueness import quiet_highs

from .kinematics import realizable
from .proportional import exact
from .result import INFEASIBLE, OPTIMAL, TIME_LIMIT
from .steady import Formulation, states_of, velocity_box

#: Contact-state sets kept as seeds (MilpModel.add_seed).
MAX_SEEDS = 10
#: "lazy-a_t": a_t counts as 0 within this times max(|gamma|, g) (a larger set of contacts
#: asked only makes the check stricter; its cuts stay valid).
AT_ZERO = 1e-7


def seconds(value, name: str = "time_limit") -> float:
    """A time limit as a float > 0, else InvalidInput naming `name` (a NaN, 0 or negative
    limit used to be taken and left every end at "time limit" without a search)."""
    number = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, bool)
    v = float(value) if number else float("nan")
    if not v > 0:
        raise InvalidInput(f"{name} must be a number of seconds > 0, got {value!r}")
    return v


def lagrangian_bound(c: np.ndarray, A: sp.csr_matrix, lo: np.ndarray, hi: np.ndarray,
                     lb: np.ndarray, ub: np.ndarray, y: np.ndarray) -> float:
    """The certified lower bound of the module docstring for the multipliers y (-inf if a
    needed column bound is infinite)."""
    y = np.where(((y > 0) & ~np.isfinite(lo)) | ((y < 0) & ~np.isfinite(hi)), 0.0, y)
    row = np.where(y > 0, y * np.where(np.isfinite(lo), lo, 0.0),
                   y * np.where(np.isfinite(hi), hi, 0.0))
    d = c - A.T @ y
    need = np.where(d > 0, lb, ub)
    if np.any((d != 0) & ~np.isfinite(need)):
        return -np.inf
    col = np.where(d != 0, d * np.where(np.isfinite(need), need, 0.0), 0.0)
    total = float(np.sum(row) + np.sum(col))
    margin = 1e-12 * float(np.sum(np.abs(row)) + np.sum(np.abs(col))) + 1e-15
    return total - margin


def certified_result(h, hs, cost: np.ndarray, A: sp.csr_matrix, lo: np.ndarray,
                     hi: np.ndarray, lb: np.ndarray, ub: np.ndarray
                     ) -> tuple[float, np.ndarray | None]:
    """(a certified lower bound of cost.x over lo <= A x <= hi, lb <= x <= ub, the LP's point
    or None) from a HiGHS instance `h` just run on that LP: the Lagrangian bound of its duals
    (either sign); +inf when infeasible and its dual ray, checked, proves it (a Lagrangian
    bound > 0 for the zero cost); -inf when neither is available."""
    st = h.getModelStatus()
    if st == hs.HighsModelStatus.kOptimal:
        y = np.asarray(h.getSolution().row_dual, float)
        b = max(lagrangian_bound(cost, A, lo, hi, lb, ub, y),
                lagrangian_bound(cost, A, lo, hi, lb, ub, -y))
        return b, np.asarray(h.getSolution().col_value, float)
    if st == hs.HighsModelStatus.kInfeasible:
        _, has, ray = h.getDualRay()
        if has:
            ray, zero = np.asarray(ray, float), np.zeros(A.shape[1])
            if max(lagrangian_bound(zero, A, lo, hi, lb, ub, ray),
                   lagrangian_bound(zero, A, lo, hi, lb, ub, -ray)) > 0:
                return np.inf, None
    return -np.inf, None


class MilpModel:
    """The MILP of a Formulation in one HiGHS instance, and its relaxation in another.

    kinematics "lazy" (default): the MILP drops the velocities' big-M rows (a relaxation) and
    each optimum's contact states are checked by verify.ranges.kinematics; a set the
    velocities do not admit is cut off (the states of its negative cycle cannot all hold) and
    the MILP solved again, until the optimum's states are admitted: then it is the optimum
    over every valid steady state. "big-M": the velocity rows stay (module steady).
    "lazy-a_t": as "lazy", but a point's states are checked only on the contacts with a_t =
    0 there, V free (exact where proportional.exact holds and gamma != 0: with (omega, V) =
    (alpha, gamma) t + (omega', V') and t large, a contact with a_t != 0 slides the way it
    accelerates whatever (omega', V'), which need only give the states with a_t = 0;
    docs/mechanics.md). "proportional": no velocity column and no velocity row
    (verify.ranges.proportional: where `proportional.exact` holds, the forces of this MILP
    are those of every valid steady state, a point's velocities are (alpha, gamma) t, so no
    cut is needed); columns and points keep the Formulation's layout outside (the velocity
    entries 0).

    clock: how `solve`'s time limit is counted, "wall" (HiGHS's own time_limit) or "cpu"
    (this process's CPU seconds, time.process_time, checked in HiGHS's MIP interrupt
    callback, with HiGHS's wall-clock limit kept as a backstop at BACKSTOP_FACTOR times the
    limit plus BACKSTOP_S): either way a search stopped by it is a time limit, never a
    bound."""

    def __init__(self, form: Formulation, kinematics: str = "lazy", clock_name: str = "wall"):
        import highspy

        self.now = clock(clock_name)
        self.clock = clock_name
        self._deadline = [np.inf]  # a box the callback reads (no reference back to self)

        if kinematics not in ("lazy", "lazy-a_t", "big-M", "proportional"):
            raise ValueError("kinematics must be 'lazy', 'lazy-a_t', 'big-M' or "
                             f"'proportional', got {kinematics!r}")
        self.at_only = kinematics == "lazy-a_t"
        if self.at_only and not (form.system.gamma != 0 and exact(form)):
            raise ValueError("kinematics 'lazy-a_t' needs gamma != 0 and V = gamma t admitted")
        kinematics = "lazy" if self.at_only else kinematics
        c, p = form.system.c, form.system.p
        self.proportional = kinematics == "proportional"
        self.n = form.A.shape[1]  # the Formulation's layout (costs, points, starts)
        keep_rows = np.ones(form.A.shape[0], dtype=bool)
        self.keep = np.ones(self.n, dtype=bool)
        if self.proportional:  # drop u = r omega, V and the rows of v_t
            keep_rows[form.v_rows[0]:form.v_rows[1]] = False
            self.keep[2 * c + p:2 * c + 2 * p + 1] = False
        A = sp.csc_matrix(form.A[np.flatnonzero(keep_rows)][:, np.flatnonzero(self.keep)])
        self.lo, self.hi = form.lo[keep_rows], form.hi[keep_rows]
        self.lb, self.ub = form.lb[self.keep], form.ub[self.keep]
        integrality = form.integrality[self.keep]
        self.A, self.form, self.lazy = sp.csr_matrix(A), form, kinematics == "lazy"
        self.hs = highspy
        self.cuts = 0
        F = form.fric.size
        self.base = 2 * form.system.c + 2 * form.system.p + 1  # y+ at base + k, y- base + F + k
        self.fpos = {int(a): k for k, a in enumerate(form.fric)}
        self.F = F

        def model(integer: bool):
            lp = highspy.HighsLp()
            lp.num_col_, lp.num_row_ = A.shape[1], A.shape[0]
            lp.col_cost_ = np.zeros(A.shape[1])
            lp.col_lower_, lp.col_upper_ = self.lb, self.ub
            lo = np.array(self.lo, float)
            if integer and self.lazy:
                lo[form.v_rows[0]:form.v_rows[1]] = -np.inf
            lp.row_lower_, lp.row_upper_ = lo, self.hi
            lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
            lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (
                A.indptr, A.indices, A.data)
            if integer:
                lp.integrality_ = [highspy.HighsVarType.kInteger if v else
                                   highspy.HighsVarType.kContinuous for v in integrality]
            h = new_highs(mip_rel_gap=0.0, mip_abs_gap=1e-13, mip_feasibility_tolerance=1e-9,
                          primal_feasibility_tolerance=1e-9, dual_feasibility_tolerance=1e-9)
            h.passModel(lp)
            return h

        self.h, self.lp = model(True), model(False)
        if clock_name == "cpu":
            start_cpu_interrupt(self.h, highspy, self._deadline)
        self.starts: list[np.ndarray] = []
        self.seeds: list[np.ndarray] = []  # contact-state sets tried first at every end
        self.V_ref: float | None = None  # proportional witnesses' V (if of gamma's sign)

    def add_seed(self, s: np.ndarray) -> None:
        """Keep s among the (at most MAX_SEEDS, newest kept) seed state sets."""
        s = np.asarray(s, dtype=int)
        self.seeds = [t for t in self.seeds if not np.array_equal(t, s)] + [s]
        del self.seeds[:-MAX_SEEDS]

    def relaxation_bound(self, cost: np.ndarray) -> float:
        """A certified lower bound of cost.x over the MILP (module docstring); -inf if the
        relaxation fails."""
        h, hs = self.lp, self.hs
        cost = np.asarray(cost, float)[self.keep]
        m = cost.size
        h.changeColsCost(m, np.arange(m, dtype=np.int32), cost)
        with quiet_highs():
            h.run()
        if h.getModelStatus() != hs.HighsModelStatus.kOptimal:
            h.clearSolver()
            with quiet_highs():
                h.run()
            if h.getModelStatus() != hs.HighsModelStatus.kOptimal:
                return -np.inf
        y = np.asarray(h.getSolution().row_dual, float)
        return max(lagrangian_bound(cost, self.A, self.lo, self.hi, self.lb, self.ub, y),
                   lagrangian_bound(cost, self.A, self.lo, self.hi, self.lb, self.ub, -y))

    def _full(self, x: np.ndarray) -> np.ndarray:
        """A point of the model in the Formulation's layout (dropped columns 0)."""
        out = np.zeros(self.n)
        out[self.keep] = x
        return out

    def cut(self, s: np.ndarray, contacts: list[int]) -> None:
        """Forbid the states s on `contacts` together: sum of their indicators <= |C| - 1
        (indicator of +1: y+, of -1: y-, of 0: 1 - y+ - y-)."""
        idx, val, rhs = [], [], len(contacts) - 1.0
        for a in contacts:
            k = self.fpos[int(a)]
            if s[a] > 0:
                idx, val = idx + [self.base + k], val + [1.0]
            elif s[a] < 0:
                idx, val = idx + [self.base + self.F + k], val + [1.0]
            else:
                idx, val = idx + [self.base + k, self.base + self.F + k], val + [-1.0, -1.0]
                rhs -= 1.0
        self.h.addRow(-np.inf, rhs, len(idx), np.array(idx, dtype=np.int32),
                      np.array(val, float))
        self.cuts += 1

    def solve(self, cost: np.ndarray, time_limit: float, extra: list[np.ndarray] = ()
              ) -> tuple[str, np.ndarray | None]:
        """("optimal" | "time limit" | "infeasible" | "failed", the MILP's point or None);
        extra: MIP starts for this objective only. Lazy: the point's contact states are
        admitted by the velocities (else it is None)."""
        if not self.lazy:  # big-M: the velocities are in; proportional: none needed
            return self._solve(cost, time_limit, extra)
        t0 = self.now()
        while True:
            left = time_limit - (self.now() - t0)
            if left <= 0:
                return TIME_LIMIT, None
            st, x = self._solve(cost, left, extra)
            if x is None:
                return st, None
            s = states_of(self.form, x)
            ok, info = realizable(self.form, s, *self._asked(x))
            if ok:
                return st, x
            self.cut(s, info)
            if st != OPTIMAL:
                return st, None

    def _asked(self, x: np.ndarray) -> tuple[np.ndarray | None, bool]:
        """(contacts whose states the velocities must give, V free) at the point x: all and
        V as the formulation's, or ("lazy-a_t") those with |a_t| <= AT_ZERO max(|gamma|, g),
        V free."""
        if not self.at_only:
            return None, False
        f = self.form
        c, p = f.system.c, f.system.p
        T_u, T_V, _ = velocity_box(f.dyn)
        at = T_u @ x[2 * c:2 * c + p] + T_V * f.system.gamma
        return np.abs(at) <= AT_ZERO * max(abs(f.system.gamma), f.system.g), True

    def _solve(self, cost: np.ndarray, time_limit: float, extra: list[np.ndarray] = ()
               ) -> tuple[str, np.ndarray | None]:
        h, hs = self.h, self.hs
        h.clearSolver()
        cost = np.asarray(cost, float)[self.keep]
        h.changeColsCost(cost.size, np.arange(cost.size, dtype=np.int32), cost)
        if self.clock == "cpu":
            self._deadline[0] = time.process_time() + float(time_limit)
            h.setOptionValue("time_limit", BACKSTOP_FACTOR * float(time_limit) + BACKSTOP_S)
        else:
            h.setOptionValue("time_limit", float(time_limit))
        starts = [*self.starts, *extra]
        # the best valid state as the MIP start (a later setSolution replaces an earlier one)
        for x in sorted(starts, key=lambda x: float(cost @ x[self.keep]))[:1]:
            sol = hs.HighsSolution()
            sol.col_value = list(x[self.keep])
            sol.value_valid = True
            h.setSolution(sol)
        t0 = self.now()
        with quiet_highs():
            h.run()
        st = h.getModelStatus()
        left = float(time_limit) - (self.now() - t0)
        if st == hs.HighsModelStatus.kInfeasible and left > 0:
            # "infeasible" only when HiGHS says so twice, the second time without presolve:
            # its presolve declared a feasible MILP infeasible (rect 3x2 at mu_pp ~ 1.2e-7,
            # tests/verify/ranges/test_milp_recheck.py); a claim not re-checked in time stays
            # a time limit
            h.clearSolver()
            h.setOptionValue("presolve", "off")
            if self.clock == "wall":
                h.setOptionValue("time_limit", left)
            try:
                with quiet_highs():
                    h.run()
            finally:
                h.setOptionValue("presolve", "choose")
            st = h.getModelStatus()
        elif st == hs.HighsModelStatus.kInfeasible:
            return TIME_LIMIT, None
        has_x = h.getInfo().primal_solution_status == 2
        x = self._full(np.asarray(h.getSolution().col_value)) if has_x else None
        if st == hs.HighsModelStatus.kOptimal:
            return OPTIMAL, x
        if st == hs.HighsModelStatus.kInfeasible:
            return INFEASIBLE, None
        if st in (hs.HighsModelStatus.kTimeLimit, hs.HighsModelStatus.kInterrupt):
            return TIME_LIMIT, x
        return "failed", x
