"""Uniqueness of LCP solutions: P-matrix test, enumeration verdicts, and a MILP search.

The LCP is w = M z + q, 0 <= z perp w >= 0. Its solution set is the union, over complementary
bases alpha, of the polyhedra P_alpha = {z : z_b = 0, z_a >= 0, w_a = 0, w_b >= 0} (beta the
complement of alpha); every P_alpha lies in the orthant z >= 0, so it is pointed.

Three tools, from cheapest to most general:

* ``p_matrix_test`` (verify/certificates/pmatrix.py, re-exported here): M is a P-matrix
  (every principal minor positive) iff the LCP has exactly one
  solution for every q (Samelson, Thrall & Wesler 1958; Cottle, Pang & Stone 1992, Thm 3.3.7).
  Checked by all 2^n - 1 principal minors for small n, and for any n by the sufficient condition
  that the symmetric part (M + M^T)/2 be positive definite (necessary too when M is symmetric).
* ``lcp.enumerate_solutions`` (used by verify.certify): every complementary basis, small n.
* ``milp_search``: a mixed-integer program (HiGHS, verify/certificates/clocked.py: its time
  limit in CPU or wall seconds) for a solution other
  than a given z*, with binary variables y for the complementarity and big-M bounds; each basis
  it proposes is polished into an exact solution by LP (verify/certificates/polish.py; HiGHS's
  options and quiet context: verify/certificates/highs.py).

Scales (lcp.residual, shared with lcp.solve and verify.certify): z_s = max(|z*|_inf, |q|_inf /
|M|_max) is the size of a solution and w_s = |q|_inf + ||M||_inf z_s bounds the size of the
terms of w = M z + q.
Every margin below is relative to these scales.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import Bounds, LinearConstraint

from rigidlcp.lcp.acceptance.residual import scaled_residual, scales
from rigidlcp.lcp.errors import InvalidInput

from .clocked import UNITS, clock, solve_milp
from .highs import HIGHS_MILP, quiet_highs
from .pmatrix import P_MINORS_MAX_N, RCOND, PMatrixTest, p_matrix_test
from .polish import polish_basis

__all__ = ["P_MINORS_MAX_N", "RCOND", "PMatrixTest", "Search", "milp_search", "p_matrix_test",
           "quiet_highs", "scaled_residual", "scales", "sign_pattern"]

#: Default box for the MILP: 0 <= z <= BOUND_FACTOR * z_s.
BOUND_FACTOR = 1e3


# --------------------------------------------------------------------------------------------
# scales and residuals
# --------------------------------------------------------------------------------------------

def sign_pattern(z: np.ndarray, w: np.ndarray, zs: float, ws: float, delta: float) -> np.ndarray:
    """+1 where z_i > delta z_s, -1 where w_i > delta w_s, 0 where both are ~0 (degenerate).

    (If both exceed the margin the pair is not complementary; the larger relative one wins.)
    """
    zr, wr = z / zs, w / ws
    out = np.zeros(z.size, dtype=int)
    out[(zr > delta) & (zr >= wr)] = 1
    out[(wr > delta) & (wr > zr)] = -1
    return out


# --------------------------------------------------------------------------------------------
# MILP search for another solution
# --------------------------------------------------------------------------------------------

@dataclass
class Search:
    """Result of `milp_search`.

    status: "found" (another solution, verified), "none" (no other solution in the box, to the
    margins), "unknown" (time limit, or a MILP point that did not survive verification).
    """

    status: str
    target: str
    other: np.ndarray | None = None
    deviation: float = 0.0  # the found solution's max relative difference in the target
    bound: float = np.inf
    delta: float = 0.0
    seconds: float = 0.0
    message: str = ""
    info: dict = field(default_factory=dict)


def milp_search(
    M: np.ndarray, q: np.ndarray, z_star: np.ndarray, target: str = "pattern",
    L: np.ndarray | None = None, *, delta: float = 1e-4, bound: float | None = None,
    time_limit: float = 10.0, objective: str = "none", retries: int = 5, clock_name: str = "cpu",
) -> Search:
    """Search for an LCP solution other than z_star, as a MILP (HiGHS, verify.certificates.clocked).

    Formulation, in the scaled unknowns zeta = z / U (U the box bound, so 0 <= zeta <= 1), with
    w = U M zeta + q, binaries y (y_i = 1: z_i may be positive and w_i = 0; y_i = 0: z_i = 0):

        w >= 0,   zeta_i <= y_i,   w_i <= w_max,i (1 - y_i),

    w_max,i = max(0, q_i + U sum_j max(M_ij, 0)) being the largest w_i over the box: these
    big-M constants are exact consequences of 0 <= z <= U, so within the box no solution is cut
    off. The verdict is therefore *relative to the box*: another solution with some z_i > U is
    not seen (the solution set of an LCP can be unbounded, and no a-priori bound holds for
    floating-point data). Default U = 1e3 z_s.

    target "pattern": another solution with a different sign pattern (+: z_i > 0, -: w_i > 0,
      0: both 0). Where z*_i > delta z_s, y_i = 0 (so z_i = 0); or where w*_i > delta w_s,
      y_i = 1 (so w_i = 0); or, at a degenerate i of z*, z_i / z_s + w_i / w_s >= delta
      (binary d_i). At least one of these must hold. Since the P_alpha are pointed, the sign
      pattern is unique iff z is: this answers "is z unique" (up to delta at degenerate pairs).
    target "values": another solution with |(L (z - z*))_j| >= delta s_L for some row j
      (binaries e_j+, e_j-; s_L = max(||L||_inf z_s, |L z*|_inf)). L = M asks for another w,
      L = I another z, L = an acceleration map another set of accelerations.

    Margin: delta is relative (to z_s, w_s, s_L) and is raised, if smaller, to 100 times the
    MILP's leakage 1e-9 U / z_s (HiGHS treats y within 1e-9 of 0 as 0, which lets z_i reach
    1e-9 U); with the default box this floor is 1e-4, the default delta. The margin used is
    reported in `Search.delta`.

    A MILP point is never trusted: its basis (y) is fixed and the solution on it recomputed by
    an LP with the target's inequality (tolerance 1e-10), then checked (scaled residual <= 1e-8
    and the difference present). objective "min-sum" asks for the other solution of least sum z
    (HiGHS must then prove optimality; a feasible point at the time limit is still used);
    "none" (default) stops at the first feasible point. A basis that fails verification is cut
    off (a no-good cut on y) and the MILP asked again, at most `retries` times; the total time
    is bounded by `time_limit` seconds on the clock `clock_name` ("cpu": this process's CPU
    seconds, the default, so that the verdict does not depend on the machine's load; "wall";
    a search stopped by it is "unknown", never "none"). Every way of differing is tried on
    that basis (the MILP's binaries may pick one that rounding made look satisfied); the cut
    is *proved* only if all their LPs are infeasible, and an infeasible MILP after an
    unproved cut answers "unknown", never "none" (a false "unique" is the worst answer a
    verifier can give).
    "none" rests on HiGHS's "infeasible", given twice, at two tolerances (`confirmed_milp`):
    the MILP solver's verdict, not a certificate this module checks. `seconds`: wall seconds.
    """
    now = clock(clock_name)  # a wrong clock refused before any work
    t0, w0 = now(), time.perf_counter()
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    z_star = np.asarray(z_star, dtype=float)
    if target not in ("pattern", "values"):
        raise InvalidInput(f"target must be 'pattern' or 'values', got {target!r}")
    if target == "values" and L is None:
        raise InvalidInput("target 'values' needs the matrix L")
    if objective not in ("none", "min-sum"):
        raise InvalidInput(f"objective must be 'min-sum' or 'none', got {objective!r}")
    zs, ws = scales(M, q, z_star)
    U = float(bound) if bound is not None else BOUND_FACTOR * zs
    # HiGHS accepts y within 1e-9 of an integer, so z_i <= 1e-9 U "vanishes": a margin below
    # ~100 times this leakage would let rounding pass for a difference. Raise delta to it.
    floor = 100.0 * HIGHS_MILP["mip_feasibility_tolerance"] * U / zs
    delta = max(float(delta), floor)
    res = Search("unknown", target, bound=U, delta=delta)
    model = _MilpModel(M, q, z_star, U, delta, zs, ws)
    if target == "pattern":
        model.differ_in_pattern()
    elif not model.differ_in_values(np.atleast_2d(np.asarray(L, dtype=float))):
        res.status, res.seconds = "none", time.perf_counter() - w0
        res.message = f"no row of L can move by {delta:g} s_L inside the box z <= {U:.3g}"
        return res
    _solve_and_verify(model, res, objective, time_limit, retries, t0, clock_name)
    res.seconds = time.perf_counter() - w0
    used = now() - t0
    res.message += (f" [{res.seconds:.2f} s]" if clock_name == "wall" else
                    f" [{used:.2f} s CPU, {res.seconds:.2f} s wall]")
    return res


class _MilpModel:
    """The rows of milp_search's program (columns: zeta (n) | y (n) | extra binaries), built
    in two steps: the complementarity of every pair (__init__), then the target's way of
    differing from z* (differ_in_pattern / differ_in_values)."""

    def __init__(self, M, q, z_star, U: float, delta: float, zs: float, ws: float):
        self.M, self.q, self.z_star, self.U, self.delta = M, q, z_star, U, delta
        self.zs, self.ws, self.n = zs, ws, q.size
        self.rows: list[np.ndarray] = []
        self.lo: list[float] = []
        self.hi: list[float] = []
        self.pat: np.ndarray | None = None  # "pattern": z*'s sign pattern
        self.L: np.ndarray | None = None  # "values": the observable, its scale s_L
        self.sL = 1.0
        self.extra: list[tuple] = []  # "values": (row j, sign) of each extra binary
        self.wmax = np.maximum(q + U * np.sum(np.maximum(M, 0.0), axis=1), 0.0)
        self._pairs: list[tuple] = []  # the complementarity rows, added once N is known

    @property
    def N(self) -> int:
        return 2 * self.n + (len(self.extra) if self.L is not None else
                             int(np.sum(self.pat == 0)))

    def add(self, row: np.ndarray, lb: float, ub: float) -> None:
        s = float(np.max(np.abs(row))) or 1.0  # normalize each row to max |coefficient| 1
        self.rows.append(row / s)
        self.lo.append(lb / s)
        self.hi.append(ub / s)

    def complementarity(self) -> None:
        """w >= 0, zeta_i <= y_i, w_i <= wmax_i (1 - y_i), for every pair i."""
        n, N, UM, q, wmax = self.n, self.N, self.U * self.M, self.q, self.wmax
        for i in range(n):
            r = np.zeros(N)
            r[:n] = UM[i]
            self.add(r, -q[i], np.inf)  # w_i >= 0
            r = np.zeros(N)
            r[i], r[n + i] = 1.0, -1.0
            self.add(r, -np.inf, 0.0)  # zeta_i <= y_i
            r = np.zeros(N)
            r[:n] = UM[i]
            r[n + i] = wmax[i]
            self.add(r, -np.inf, wmax[i] - q[i])  # w_i <= wmax_i (1 - y_i)

    def differ_in_pattern(self) -> None:
        """Target "pattern": y_i = 0 where z*_i > 0, or y_i = 1 where w*_i > 0, or a degenerate
        pair of z* leaves 0 (z_i / z_s + w_i / w_s >= delta d_i): at least one."""
        n, U, zs, ws, M, q = self.n, self.U, self.zs, self.ws, self.M, self.q
        self.pat = pat = sign_pattern(self.z_star, M @ self.z_star + q, zs, ws, self.delta)
        self.complementarity()
        N = self.N
        plus, minus, deg = (np.flatnonzero(pat == v) for v in (1, -1, 0))
        cut = np.zeros(N)
        cut[n + plus] = -1.0
        cut[n + minus] = 1.0
        cut[2 * n:] = 1.0
        self.add(cut, 1.0 - plus.size, np.inf)
        for k, i in enumerate(deg):  # z_i/zs + w_i/ws >= delta d_i
            r = np.zeros(N)
            r[i] = U / zs
            r[:n] += U * M[i] / ws
            r[2 * n + k] = -self.delta
            self.add(r, -q[i] / ws, np.inf)

    def differ_in_values(self, L: np.ndarray) -> bool:
        """Target "values": |(L (z - z*))_j| >= delta s_L for some row j and sign (binaries
        e_j+-), only those reachable inside the box; False when none is."""
        n, U, z_star = self.n, self.U, self.z_star
        self.L = L
        v_star = L @ z_star
        self.sL = max(float(np.max(np.sum(np.abs(L), axis=1))) * self.zs,
                      float(np.max(np.abs(v_star))), 1e-300)
        dL = self.delta * self.sL
        for j in range(L.shape[0]):
            for sgn in (1.0, -1.0):
                best = U * float(np.sum(np.maximum(sgn * L[j], 0.0))) - sgn * v_star[j]
                if best >= dL:  # the deviation is reachable inside the box
                    self.extra.append((j, sgn))
        if not self.extra:
            return False
        self.complementarity()
        N = self.N
        for k, (j, sgn) in enumerate(self.extra):
            gain = sgn * L[j]
            big = dL + sgn * v_star[j] - U * float(np.sum(np.minimum(gain, 0.0)))
            r = np.zeros(N)
            r[:n] = U * gain
            r[2 * n + k] = -big
            self.add(r, dL - big + sgn * v_star[j], np.inf)
        cut = np.zeros(N)
        cut[2 * n:] = 1.0
        self.add(cut, 1.0, np.inf)
        return True

    def deviation(self, other: np.ndarray) -> float:
        if self.L is None:
            return float(np.max(np.abs(other - self.z_star))) / self.zs
        return float(np.max(np.abs(self.L @ (other - self.z_star)))) / self.sL


def _solve_and_verify(model: _MilpModel, res: Search, objective: str, time_limit: float,
                      retries: int, t0: float, clock_name: str = "cpu") -> None:
    """Ask HiGHS; polish its basis into an exact solution (`polish_basis`, in polish.py) or
    cut the basis off and ask again (at most `retries` times); fill `res` (see milp_search's
    docstring)."""
    n, N = model.n, model.N
    c = np.zeros(N)
    if objective == "min-sum":
        c[:n] = 1.0
    integrality = np.r_[np.zeros(n), np.ones(N - n)]
    rejected = unproved = 0
    now = clock(clock_name)
    for _attempt in range(retries + 1):
        left = time_limit - (now() - t0)
        if left <= 0:
            res.message = f"time limit {time_limit:g} {UNITS[clock_name]} reached"
            break
        A = sp.csr_matrix(np.array(model.rows))
        cons = LinearConstraint(A, np.array(model.lo), np.array(model.hi))
        out, runs = confirmed_milp(c, integrality, cons, left, clock_name=clock_name)
        res.info = {"milp_status": int(out.status), "milp_message": str(out.message),
                    "binaries": N - n, "rejected_bases": rejected, "milp_runs": runs}
        if out.x is None:
            if out.status == 2 and runs < 2:
                res.message = ("MILP infeasible at tolerance 1e-9; no time left to confirm "
                               "it at 1e-8: unknown")
            elif out.status == 2 and unproved:  # a cut that was not proved may hide a solution
                res.message = (f"MILP infeasible after {rejected} bases were cut, {unproved} of "
                               "them without proof that they hold no other solution: unknown")
            elif out.status == 2:  # proved infeasible, every cut proved
                res.status = "none"
                res.message = (f"no other solution with z <= {model.U:.3g} (MILP infeasible"
                               + (f" after {rejected} bases, each proved empty by LP, were cut"
                                  if rejected else "") + ")")
            else:
                res.message = f"MILP stopped without a point: {out.message}"
            break
        y = out.x[n:2 * n] > 0.5
        chosen = out.x[2 * n:] > 0.5
        other, proved = polish_basis(model.M, model.q, model.z_star, y, res.target, chosen,
                                     model.L, model.delta, model.zs, model.ws, model.pat,
                                     model.extra)
        if other is not None:
            res.status, res.other = "found", other
            res.deviation = model.deviation(other)
            res.message = ("another solution (max relative difference "
                           f"{res.deviation:.3g}) found"
                           + ("" if out.status == 0 else " (time limit hit)"))
            break
        # The basis proposed carries no exact solution with the target (rounding in the MILP):
        # cut it off (no-good cut on y) and ask again. The cut is sound only if every way the
        # target can differ was proved infeasible on this basis (`proved`); else a "none" at the
        # end would rest on it, and becomes "unknown".
        rejected += 1
        unproved += not proved
        r = np.zeros(N)
        r[n:2 * n] = np.where(y, -1.0, 1.0)
        model.add(r, 1.0 - float(np.sum(y)), np.inf)
    else:
        res.message = (f"{rejected} bases proposed by the MILP carried no exact solution with "
                       "the target's difference (rounding): verdict unknown")
    res.info["rejected_bases"] = rejected
    res.info["unproved_cuts"] = unproved


def confirmed_milp(c, integrality, constraints: LinearConstraint, seconds: float,
                   bounds: Bounds | None = None, options: dict | None = None,
                   clock_name: str = "cpu"):
    """(HiGHS's answer, a verify.certificates.clocked.MilpAnswer, runs). "Infeasible" is
    asked again without presolve at 10 times the mip_feasibility_tolerance (a relaxation; its
    points are polished), and stands only if that run agrees (runs = 2): at 1e-9 HiGHS called
    test_uniqueness.PRESOLVE_M infeasible (HiGHS through scipy 1.15.0 and 1.17.1, with
    presolve; 1e-8 finds the point; 1e-6 lets in spurious points; since clock21 HiGHS is
    called through highspy, verify.certificates.clocked). seconds: the limit of both runs
    together, on the clock `clock_name` ("cpu" or "wall")."""
    now = clock(clock_name)
    t0 = now()
    runs = 0
    bounds = Bounds(0.0, 1.0) if bounds is None else bounds
    for tight in (True, False):
        left = seconds - (now() - t0)
        if runs and left <= 0:
            break
        opts = dict(HIGHS_MILP if options is None else options)
        if not tight:
            opts.update(presolve=False, mip_feasibility_tolerance=1e-8)
        out = solve_milp(c, integrality, constraints.A, constraints.lb, constraints.ub,
                         bounds.lb, bounds.ub, time_limit=max(left, 0.0), options=opts,
                         clock_name=clock_name)
        runs += 1
        if out.status != 2:
            break
    return out, runs
