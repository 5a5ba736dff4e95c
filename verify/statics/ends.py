"""One end of a range LP (min cost . lambda over P), settled with its check or reported unknown
with the evidence (issue 22: an end whose check fails is never a number).

`settle` takes the warm LP's answer and checks it (verify.statics.model): an optimum must lie
in P (balance backward error and laws' violation <= BALANCE_TOL) and be certified by the
LP's dual y (weak duality, DUAL_TOL); "unbounded" must come with a checked primal ray. When
the check fails it tries, in order:

1. the same basis, solved again: w_B = K_B^-1 b and y = K_B^-T c_B by one sparse LU of the
   optimal basis. A warm-started simplex updates its values (the point w and the certificate
   y) from one LP to the next, and they drift from those of its basis: after optima a million
   times larger (a pair between walls near mu = 1) the point carried a balance error of 9e-8
   of the weights (n 3, seed 304, mu 0.99999), and elsewhere y fell 2e-8 short of the end
   (n 15, seed 28, mu 1.03125; docs/packings.md); the basis itself was right, and its values
   recomputed from scratch are accurate to the rounding of one LU;
2. after an "unbounded" whose ray fails its check, a ray from an LP of our own (`ray_lp`);
3. a cold LP: a new ForceLP (primal simplex from the slack basis), its answer checked the same
   way (and its basis re-solved if needed); HiGHS's warm primal simplex has answered
   "unbounded" with a ray that fails its check (cost . r = -5.5e-9 of |r| = 2e3) on a bounded
   LP (n 5, seed 5, mu 1.0);
4. for a range LP, a cold dual simplex (DualForceLP): warm and cold, the primal simplex
   answered "unbounded" for max R of contact 2 (n 9, seed 342, mu 0.99999, the primal's
   chunk) with rays whose descent, 9e-12 and 4e-11 of their size, fails its check; the cold
   dual finds the end 835822.16, certified exactly (linprog: 835822.16);
5. on P of at most exact_lp.MAX_ROWS balance rows, the LP solved in rational arithmetic
   (verify.statics.exact_lp: an optimum with its dual certificate, a ray, or a Farkas
   certificate of an empty face, each checked exactly): on the symmetric degenerate optima of
   equal disks between walls the float certificates cannot be made exact (n 3, seed 1,
   mu 1.001953125: max S of contact 3 is +inf by an exact ray where the float LP stopped at
   0.50098; n 2, seed 1, mu 0.99999: the face S = mu R of contact 0 is empty).

An optimum's dual certificate must also hold beyond the simplex's tolerance (`_dual_exact`:
exactly on small piles, else to rounding), and a sliding LP's "infeasible" needs a checked
Farkas certificate for its face (`_infeasible`).

Else the end is unknown: `Unknown` names the failed check and its measure against its
tolerance, for the JSON and the summary.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from . import exact, exact_lp
from .model import (
    BALANCE_TOL,
    DUAL_TOL,
    LP_TOL,
    DualForceLP,
    ForceLP,
    StaticProblem,
    dual_defects,
    ray_defect,
)

#: The tolerance of the primal ray's check (ForceLP.ray_checked's default).
RAY_TOL = 1e-9
#: A dual certificate not checked exactly (`_dual_exact`) must have its reduced costs
#: >= -ROUND_TOL max(1, |y|): rounding, not the simplex's tolerance (DUAL_TOL).
ROUND_TOL = 1e-12


@dataclass(frozen=True)
class Evidence:
    """Why an answer is refused: the check ("balance", "laws", "dual feasibility", "dual gap",
    "ray sign", "ray fixed", "ray balance", "ray descent", "no ray" or "LP status"), its
    measure (relative, as the check defines it; NaN for "no ray" and "LP status") and the
    tolerance it had to meet; `status`: the LP's answer ("optimal", "unbounded", ...)."""

    check: str
    value: float
    tol: float
    status: str

    def text(self) -> str:
        if self.check == "LP status":
            return f"LP {self.status}"
        if self.check == "no ray":
            return "LP unbounded without a primal ray"
        # the ray must descend by more than tol (relative); every other measure must stay below it
        cmp = "<=" if self.check == "ray descent" else ">"
        return f"{self.check} {self.value:.3g} {cmp} tol {self.tol:.0e} ({self.status})"


@dataclass(frozen=True)
class Settled:
    """An end: status "optimal" (lam: a checked optimum), "unbounded" (a checked ray) or
    "unknown" (evidence: the last try's failed check); lps: LPs solved; how: the try that
    settled it ("warm", "basis", "ray LP", "cold", "cold basis", "cold dual", "exact LP"; ""
    when unknown; "vertex": a kept basis, `at_basis`; "kept start": the LP again from a kept
    basis, verify.statics.range_ends); first: the warm answer's evidence when a retry was
    needed."""

    status: str
    lam: np.ndarray | None
    lps: int
    evidence: Evidence | None = None
    how: str = "warm"
    first: Evidence | None = None

    @property
    def retried(self) -> bool:
        """The warm LP's answer failed its check and a retry settled the end."""
        return self.how not in ("warm", "")


@dataclass(frozen=True)
class Unknown:
    """A range end reported unknown: index k in [R; S] (k < c: R of contact k, else S of
    contact k - c), side "min" or "max", and the evidence of its last try."""

    k: int
    side: str
    evidence: Evidence

    def to_dict(self, c: int, i: np.ndarray, j: np.ndarray) -> dict:
        a, value = int(self.k) % c, float(self.evidence.value)
        return {"contact": a, "i": int(i[a]), "j": int(j[a]),
                "force": "R" if self.k < c else "S", "end": self.side,
                "check": self.evidence.check, "value": value if np.isfinite(value) else None,
                "tol": float(self.evidence.tol), "lp_status": self.evidence.status}


def settle(prob: StaticProblem, lp: DualForceLP | ForceLP, cost: np.ndarray,
           fixed: tuple[int, ...] = (),
           cold: Callable[[], ForceLP] | None = None,
           as_is: tuple[str, ...] = ()) -> Settled:
    """min cost . lambda over P (on the face with the `fixed` cone columns at 0) by lp, checked,
    with the retries of the module docstring; cold() builds the cold LP (default: a new
    ForceLP of prob); as_is: the statuses taken as answers besides "optimal" and "unbounded"
    (the sliding LPs' "infeasible": that face of P is empty), each with its check (an
    "infeasible" by a Farkas certificate: `_infeasible`)."""
    status, lam = lp.solve(cost)
    lps = 1
    ev = _infeasible(prob, lp, fixed) if status in as_is else judge(prob, lp, cost, status,
                                                                     lam, fixed)
    if ev is None:
        return Settled(status, lam, lps)
    if status == "optimal":
        got = _rebasis(prob, lp, cost, fixed)
        if got is not None:
            return Settled(status, got, lps, how="basis", first=ev)
    if status == "unbounded":
        lps += 1
        if ray_lp(prob, _primal(lp), cost, fixed) is not None:
            return Settled(status, None, lps, how="ray LP", first=ev)
    fresh = cold() if cold is not None else ForceLP(prob)
    status, lam = fresh.solve(cost)
    lps += 1
    ev2 = _infeasible(prob, fresh, fixed) if status in as_is else judge(prob, fresh, cost,
                                                                         status, lam, fixed)
    if ev2 is None:
        return Settled(status, lam, lps, how="cold", first=ev)
    if status == "optimal":
        got = _rebasis(prob, fresh, cost, fixed)
        if got is not None:
            return Settled(status, got, lps, how="cold basis", first=ev)
    if cold is None and not fixed:  # 4. a cold dual simplex (the range LPs)
        dual = DualForceLP(prob, ForceLP(prob))
        status, lam = dual.solve(cost)
        lps += 1
        ev3 = judge(prob, dual, cost, status, lam)
        if ev3 is None:
            return Settled(status, lam, lps, how="cold dual", first=ev)
        ev2 = ev3
    # 5. on small piles, the LP solved exactly (verify.statics.exact_lp), its answer with
    # its certificate checked in rationals
    got = exact_lp.solve(prob, cost, fixed)
    if got is not None and (got.status != "infeasible" or "infeasible" in as_is):
        return Settled(got.status, got.lam, lps + 1, how="exact LP", first=ev)
    return Settled("unknown", None, lps, evidence=ev2, how="", first=ev)


def ray_lp(prob: StaticProblem, primal: ForceLP, cost: np.ndarray,
           fixed: tuple[int, ...] = ()) -> np.ndarray | None:
    """A ray of P in cone coordinates along which cost . lambda decreases, from an LP of our
    own: min (T^T cost) . r subject to K r = 0 and 0 <= r <= 1 (0 on the `fixed` columns), a
    vertex, whose basic entries are solved from exact 0 and 1 bounds. It is returned when it
    passes ray_defect (the range LP is then unbounded), else None (also when the optimum is
    0: no such ray). HiGHS's own ray after "unbounded" can miss the sign check by 7e-8 of its
    size on a truly unbounded LP (deep profile: n 17, seed 17, mu 1.015625)."""
    import highspy

    from rigidlcp.lcp.quiet import new_highs

    K = sp.csc_matrix(primal.KT.T)
    m, nw = K.shape
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = nw, m
    lp.col_cost_ = np.asarray(primal.TT @ np.asarray(cost, dtype=float), dtype=float)
    upper = np.ones(nw)
    upper[list(fixed)] = 0.0
    lp.col_lower_, lp.col_upper_ = np.zeros(nw), upper
    lp.row_lower_ = lp.row_upper_ = np.zeros(m)
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (K.indptr, K.indices, K.data)
    h = new_highs(presolve="off", primal_feasibility_tolerance=LP_TOL,
                  dual_feasibility_tolerance=LP_TOL)
    h.passModel(lp)
    h.run()
    if h.getModelStatus() != highspy.HighsModelStatus.kOptimal:
        return None
    r = np.asarray(h.getSolution().col_value, dtype=float)
    return r if ray_defect(primal, r, cost, RAY_TOL, fixed) is None else None


def judge(prob: StaticProblem, lp: DualForceLP | ForceLP, cost: np.ndarray, status: str,
          lam: np.ndarray | None, fixed: tuple[int, ...] = (),
          y: np.ndarray | None = None, basis: np.ndarray | None = None) -> Evidence | None:
    """None when lp's last answer passes its check (module docstring), else the evidence; y:
    the dual certificate to read (default: the LP's own); basis: the basic cone columns that
    gave lam and y (default: the LP's last basis), for the exact dual check."""
    if status == "optimal":
        checks = [("balance", prob.backward_error(lam), BALANCE_TOL),
                  ("laws", prob.law_error(lam), BALANCE_TOL)]
        infeasible, gap = dual_defects(_primal(lp), cost, lam,
                                       _dual_y(lp) if y is None else y, fixed)
        checks += [("dual feasibility", infeasible, DUAL_TOL), ("dual gap", gap, DUAL_TOL)]
        for name, value, tol in checks:
            if not value <= tol:
                return Evidence(name, value, tol, status)
        return _dual_exact(prob, lp, cost, lam, fixed, infeasible, basis)
    if status == "unbounded":
        last = _last(lp)
        if not isinstance(last, ForceLP):
            return Evidence("no ray", np.nan, RAY_TOL, status)
        _, has_ray, values = last.h.getPrimalRay()
        if not has_ray:
            return Evidence("no ray", np.nan, RAY_TOL, status)
        bad = ray_defect(last, np.asarray(values, dtype=float), cost, RAY_TOL, fixed)
        return None if bad is None else Evidence("ray " + bad[0], bad[1], RAY_TOL, status)
    return Evidence("LP status", np.nan, 0.0, status)


def _last(lp: DualForceLP | ForceLP):
    """The HiGHS LP that gave lp's last answer (a DualForceLP may have handed it to its
    primal)."""
    return lp.last if isinstance(lp, DualForceLP) else lp


def _primal(lp: DualForceLP | ForceLP) -> ForceLP:
    return lp.primal if isinstance(lp, DualForceLP) else lp


def _dual_y(lp: DualForceLP | ForceLP) -> np.ndarray:
    """The dual certificate y of lp's last optimum, as its `certified` reads it."""
    last = _last(lp)
    sol = last.h.getSolution()
    return np.asarray(sol.col_value if isinstance(last, DualForceLP) else sol.row_dual,
                      dtype=float)


def _rebasis(prob: StaticProblem, lp: DualForceLP | ForceLP, cost: np.ndarray,
             fixed: tuple[int, ...]) -> np.ndarray | None:
    """The last optimal basis solved again (module docstring, 1.): lambda when it passes the
    check with its own y, else None (also when the basis is not square or is singular)."""
    basis = _basis_columns(prob, lp)
    if basis is None or basis[1].size:
        return None
    got = _solve_basis(prob, _primal(lp), basis[0], cost)
    if got is None:
        return None
    lam, y = got
    return lam if judge(prob, _primal(lp), cost, "optimal", lam, fixed, y,
                        basis[0]) is None else None


def at_basis(prob: StaticProblem, lp: DualForceLP | ForceLP, cols: np.ndarray,
             cost: np.ndarray) -> Settled | None:
    """min cost . lambda over P settled without an LP at a basis kept from an earlier optimum
    (cols: its basic cone columns, `basis_of`): its vertex w_B = K_B^-1 b and y = K_B^-T c_B by
    one sparse LU, the same check as an LP's answer (`judge`: in P, dual feasible, no gap,
    and the exact or rounding-level dual check on this basis). A Settled "optimal" with
    lps 0 and how "vertex" when it passes, else None (the basis is not optimal for cost)."""
    got = _solve_basis(prob, _primal(lp), cols, cost)
    if got is None:
        return None
    lam, y = got
    primal = _primal(lp)
    d = np.asarray(primal.TT @ np.asarray(cost, dtype=float)) - primal.KT @ y
    if float(np.min(d, initial=0.0)) < -ROUND_TOL * max(1.0, float(np.max(np.abs(y)))):
        return None  # a reduced cost < 0: not optimal (cheaply, before the full check)
    if judge(prob, primal, cost, "optimal", lam, (), y, cols) is not None:
        return None
    return Settled("optimal", lam, 0, how="vertex")


def basis_of(prob: StaticProblem, lp: DualForceLP | ForceLP) -> np.ndarray | None:
    """The basic cone columns of lp's last optimum when they form a square basis of the
    balance rows (for `at_basis`), else None."""
    basis = _basis_columns(prob, lp)
    return None if basis is None or basis[1].size else basis[0]


def _solve_basis(prob: StaticProblem, primal: ForceLP, cols: np.ndarray, cost: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray] | None:
    """(lambda = T w with w_B = K_B^-1 b, y = K_B^-T c_B) of the basis `cols` by one sparse
    LU, or None when K_B is singular or the values are not finite."""
    from scipy.sparse.linalg import splu

    KB = primal.K[:, cols]
    try:
        lu = splu(sp.csc_matrix(KB))
    except RuntimeError:  # singular
        return None
    c = np.asarray(primal.TT @ np.asarray(cost, dtype=float))
    w = np.zeros(primal.nw)
    w[cols] = lu.solve(np.asarray(prob.b, dtype=float))
    y = lu.solve(c[cols], trans="T")
    if not (np.all(np.isfinite(w)) and np.all(np.isfinite(y))):
        return None
    return primal.T @ w, y


def _basis_columns(prob: StaticProblem, lp: DualForceLP | ForceLP
                   ) -> tuple[np.ndarray, np.ndarray] | None:
    """The last optimal basis as (its cone-coordinate columns, the balance rows whose y is 0):
    ForceLP: its basic columns and its basic rows (a redundant balance row's slack); DualForceLP:
    its nonbasic rows and its nonbasic columns (a free y at 0). None unless they add up to one
    equation per balance row."""
    last = _last(lp)
    basic = last.hs.HighsBasisStatus.kBasic
    basis = last.h.getBasis()
    if isinstance(last, DualForceLP):  # its rows are the cone coordinates: active = nonbasic
        zero = np.array([n for n, s in enumerate(basis.col_status) if s != basic], dtype=int)
        cols = np.array([n for n, s in enumerate(basis.row_status) if s != basic], dtype=int)
    else:  # the balance rows are equalities: a basic row is a rank defect
        zero = np.array([n for n, s in enumerate(basis.row_status) if s == basic], dtype=int)
        cols = np.array([n for n, s in enumerate(basis.col_status) if s == basic], dtype=int)
    return (cols, zero) if cols.size + zero.size == prob.A.shape[0] else None


def _dual_exact(prob: StaticProblem, lp: DualForceLP | ForceLP, cost: np.ndarray,
                lam: np.ndarray, fixed: tuple[int, ...], infeasible: float,
                cols: np.ndarray | None = None) -> Evidence | None:
    """The dual check of an optimum whose float checks passed, beyond DUAL_TOL: None when

    * exactly: verify.statics.exact's dual_bound (the basis' y solved in rationals, every
      reduced cost >= 0 exactly, after at most exact.MAX_PIVOTS pivots) gives a bound b . y
      within DUAL_TOL of the force scale of the value (P of at most exact.EXACT_MAX_ROWS
      balance rows), or else
    * in floats, y's dual infeasibility (dual_defects: -min d / max(1, |y|)) is at most
      ROUND_TOL: then every ray r >= 0 of P (K r = 0) has cost . T r >= -ROUND_TOL max(1, |y|)
      sum r, to the rounding of d; a ray shallower than that is not excluded
      (docs/packings.md, "Still open"). DUAL_TOL alone let a slope of 4e-6 through where the
      exact check finds none: n 13, seed 592, mu 1.078125.

    Else the evidence "dual exact" (its value: the exact bound's gap, NaN when there is
    none). cols: the basis of lam (default: lp's last basis)."""
    gap = np.nan
    if prob.A.shape[0] <= exact.EXACT_MAX_ROWS:
        basis = _basis_columns(prob, lp) if cols is None else (cols, np.zeros(0, dtype=int))
        bound = None if basis is None else exact.dual_bound(prob, cost, *basis, fixed)
        if bound is not None:
            obj = float(np.asarray(cost, dtype=float) @ lam)
            gap = abs(obj - float(bound)) / max(prob.scale, abs(obj))
            if gap <= DUAL_TOL:
                return None
    if infeasible <= ROUND_TOL:
        return None
    return Evidence("dual exact", gap, DUAL_TOL, "optimal")


def _infeasible(prob: StaticProblem, lp: DualForceLP | ForceLP,
                fixed: tuple[int, ...]) -> Evidence | None:
    """None when the LP's "infeasible" for the face of P with the `fixed` cone columns at 0
    carries a checked Farkas certificate (HiGHS's dual ray, verify.statics.exact's
    face_empty), else the evidence "farkas" (also when the LP's status is another)."""
    last = _last(lp)
    if not isinstance(last, ForceLP) or last.h.getModelStatus() != \
            last.hs.HighsModelStatus.kInfeasible:
        return Evidence("LP status", np.nan, 0.0, "infeasible")
    _, has_ray, values = last.h.getDualRay()
    k = prob.fric.size
    rows = tuple(int(prob.fric[j]) if j < k else prob.c + j - k if j < 2 * k else int(
        np.flatnonzero(prob.mu == 0)[j - 2 * k]) for j in fixed)
    if has_ray and exact.face_empty(prob, np.asarray(values, dtype=float), rows):
        return None
    # no ray, or one that fails: Farkas LPs of our own
    if any(exact.face_empty(prob, y, rows) for y in exact.face_farkas_lp(prob, rows)):
        return None
    return Evidence("farkas", np.nan, 0.0, "infeasible")
