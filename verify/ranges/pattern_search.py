"""The extreme of a linear observable over every solution of LCP(M, q), with no box on z
(issue 21 point 1: the "every pattern" range proved when LCP(M, 0) has a nonzero solution).

The solution set is the union of the pieces P_y = {z >= 0, w = M z + q >= 0, z_i = 0 (y_i = 0),
w_i = 0 (y_i = 1)} over the 2^n complementary patterns y. Each piece is a polyhedron in
z >= 0 (pointed), with recession cone C_y = {d >= 0, M d >= 0, d_i = 0 (y_i = 0),
(M d)_i = 0 (y_i = 1)}, a part of SOL(M, 0). So, for f = c . z (c = sense L; the minimum is
sought):

* f is unbounded below on the set iff some *nonempty* piece has a d in C_y with c . d < 0
  (then z + t d lies in P_y for every t >= 0);
* otherwise the minimum over each nonempty piece is attained (at a vertex), and the minimum
  over the set is the least of the pieces' minima.

No bound on |z| is needed to decide either, so none is assumed: the patterns are searched by
branch and bound (Murty, Linear Complementarity, Linear and Nonlinear Programming, 1988,
Sec. 11.4: enumeration of complementary cones). A node fixes z_i = 0 on a set Z and w_i = 0 on
a set W (disjoint); its relaxation is the LP min c . z over {z >= 0, w >= 0, z_Z = 0, w_W = 0},
a polyhedron holding every piece whose pattern agrees with the node. The LP's verdict
(HiGHS; "infeasible" only when HiGHS says it again without presolve: with presolve, scipy
1.17's HiGHS called min -z_3 over {z >= 0, -z2 + z3 - z4 >= 0, z2 - z3 + z4 + 1 >= 0} infeasible,
though z = 0 is feasible and the LP unbounded; test_pattern_search):

* infeasible: no piece of the node is nonempty (pruned);
* optimal at z with z complementary (the independent residual of
  verify.certificates.stages <= WITNESS_TOL): z is a solution and the node's minimum (pruned,
  a candidate); optimal at a value >= the best solution met (less a tolerance of
  PRUNE_TOL relative): pruned by the bound; otherwise split on the free index i where z_i and
  w_i are both largest (children z_i = 0 and w_i = 0);
* unbounded: a point z0 of the relaxation and a direction d of its recession cone with
  c . d < 0 (two LPs, sum d <= 1); if z0 + t d passes the independent residual at two values of
  t, its pattern's piece is nonempty and holds that ray: f is unbounded below (the answer);
  else split on the index where z0 + t d is least complementary. At a leaf (every index fixed)
  the relaxation *is* a piece, and an unbounded LP there is the criterion above.

Every node ends pruned or split into two children that partition its patterns, so the pruned
nodes partition {0, 1}^n: checked in code at the end (sum over pruned nodes of 2^free equals
2^n, in integers). The verdicts are HiGHS's LP verdicts at each node (an LP not said optimal
or unbounded is asked again without presolve, then at HiGHS's default, looser, tolerances:
a relaxation whose verdict "infeasible" or bound holds for the tighter one); the values,
witnesses and rays are checked.
A search stopped by its time limit (CPU seconds) reports "time limit" with the best solution
met (not a bound) and, when every open node's parent LP was bounded, the least of their
bounds, which is a proved bound on the end.
"""

from __future__ import annotations

import heapq
import time
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog

from rigidlcp.lcp.acceptance.residual import scales
from rigidlcp.verify.certificates.stages import independent_residual

from .result import INFEASIBLE, OPTIMAL, TIME_LIMIT, UNBOUNDED, UNPROVED, End

#: A witness (or a point of a ray) is accepted when its independent residual is at most this.
WITNESS_TOL = 1e-8
#: A node whose LP bound is within PRUNE_TOL max(1, |best|) of the best value met is pruned.
PRUNE_TOL = 1e-9
_LP = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


@dataclass
class SearchStats:
    """nodes: LPs of nodes solved; infeasible, bound, solutions: nodes pruned empty, by the
    bound, at a solution; covered: the patterns the pruned nodes hold (2^n when the search
    finished; set to 2^n when a checked ray ends it, whatever the other patterns hold)."""

    nodes: int = 0
    infeasible: int = 0
    bound: int = 0
    solutions: int = 0
    covered: int = 0

    def text(self, n: int) -> str:
        return (f"{self.nodes} node LPs; pruned {self.infeasible} empty, {self.bound} by the "
                f"bound, {self.solutions} at a solution; they cover {self.covered} of 2^{n} "
                f"patterns")


def _solve(c, M, q, fixz, fixw, extra_ub=None):
    """linprog of c . z over the node's relaxation {z >= 0, w >= 0, z_Z = 0, w_W = 0}
    (extra_ub: one more row a . z <= b); an LP not said optimal or unbounded is asked again
    without presolve, then at HiGHS's default tolerances (dual simplex, then interior
    point)."""
    free_w = ~fixw
    A_ub, b_ub = -M[free_w], q[free_w]
    if extra_ub is not None:
        A_ub, b_ub = np.vstack([A_ub, extra_ub[0]]), np.r_[b_ub, extra_ub[1]]
    kw = dict(A_ub=A_ub if A_ub.shape[0] else None, b_ub=b_ub if A_ub.shape[0] else None,
              A_eq=M[fixw] if fixw.any() else None, b_eq=-q[fixw] if fixw.any() else None,
              bounds=[(0, 0) if fixz[i] else (0, None) for i in range(q.size)],
              method="highs")
    r = linprog(c, options=_LP, **kw)
    if r.status not in (0, 3):  # HiGHS's presolve has called a feasible LP infeasible
        r = linprog(c, options={**_LP, "presolve": False}, **kw)
    for method in ("highs-ds", "highs-ipm"):  # HiGHS's status 15 "unknown" at 1e-10 (a node
        if r.status in (0, 2, 3):  # of rect 4x2's event from rest): its default tolerances
            break  # (1e-7), looser, so a verdict "infeasible" or a bound still holds
        r = linprog(c, options={"presolve": False}, **{**kw, "method": method})
    return r


def _terms(M, q, z) -> np.ndarray:
    """Per index, the independent residual's term |min(z_i / z_s, w_i / w_s)|."""
    zs, ws = scales(M, q, z)
    w = M.astype(np.longdouble) @ z.astype(np.longdouble) + q.astype(np.longdouble)
    return np.abs(np.minimum(z / zs, np.asarray(w / ws, dtype=float)))


def check_ray(M, q, z0, d) -> tuple[float, float, float]:
    """(t1, t2, worst residual): z0 + t d checked by the independent residual at
    t1 = max(1, |z0|) / |d| and t2 = 1e3 t1 (z0's part and d's part of the pattern)."""
    t1 = max(1.0, float(np.max(np.abs(z0), initial=0.0))) / float(np.max(d))
    t2 = 1e3 * t1
    return t1, t2, max(independent_residual(M, q, z0 + t1 * d),
                       independent_residual(M, q, z0 + t2 * d))


def _ray(c, M, q, fixz, fixw):
    """(z0, d) of the node's relaxation: a point and a direction of its recession cone with
    c . d < 0, sum d <= 1 (the most decreasing one); None where an LP fails."""
    n = q.size
    p = _solve(np.zeros(n), M, q, fixz, fixw)
    r = _solve(c, M, np.zeros(n), fixz, fixw, extra_ub=(np.ones((1, n)), 1.0))
    if p.status != 0 or r.status != 0 or not r.fun < 0:
        return None
    return np.maximum(p.x, 0.0), np.maximum(r.x, 0.0)


def extreme(M, q, L, sense: int, *, incumbent: np.ndarray | None = None,
            time_limit: float = 30.0) -> tuple[End, SearchStats]:
    """min sense * L . z over every solution of LCP(M, q) (module docstring): the End (value
    L . z of its witness; "unbounded" with a checked ray; "infeasible": no solution; "time
    limit"; "unproved" with the reason where a check failed) and the search's counts.

    incumbent: a solution met before (checked here), the first bound; time_limit: CPU
    seconds (time.process_time) for the whole search."""
    t0 = time.process_time()
    M, q = np.asarray(M, dtype=float), np.asarray(q, dtype=float)
    L = np.asarray(L, dtype=float)
    n = q.size
    c = sense * L
    stats = SearchStats()
    best_z, best = None, np.inf
    if incumbent is not None:
        z = np.maximum(np.asarray(incumbent, dtype=float), 0.0)
        if independent_residual(M, q, z) <= WITNESS_TOL:
            best_z, best = z, float(c @ z)
    heap: list = [(-np.inf, 0, 0, np.zeros(n, bool), np.zeros(n, bool))]
    count = 1

    def secs() -> float:
        return time.process_time() - t0

    def beaten(v: float) -> bool:  # v no better than the best met (less the tolerance)
        return bool(np.isfinite(best) and v >= best - PRUNE_TOL * max(1.0, abs(best)))

    def end(status: str, note: str) -> tuple[End, SearchStats]:
        text = f"{note}; pattern search: {stats.text(n)}, {secs():.2f} CPU s"
        if status == OPTIMAL:
            res = independent_residual(M, q, best_z)
            return End(OPTIMAL, float(L @ best_z), best_z, residual=res, seconds=secs(),
                       note=text), stats
        met = None if best_z is None else float(L @ best_z)
        return End(status, witness=best_z, best=met, seconds=secs(), note=text,
                   residual=(np.nan if best_z is None
                             else independent_residual(M, q, best_z))), stats

    def prune(kind: str, fixz, fixw) -> None:
        setattr(stats, kind, getattr(stats, kind) + 1)
        stats.covered += 1 << int(n - fixz.sum() - fixw.sum())

    def split(bound, fixz, fixw, terms) -> None:
        nonlocal count
        free = ~(fixz | fixw)
        i = int(np.flatnonzero(free)[np.argmax(terms[free])])
        for fz in (True, False):
            cz, cw = fixz.copy(), fixw.copy()
            (cz if fz else cw)[i] = True
            heapq.heappush(heap, (bound, -int(cz.sum() + cw.sum()), count, cz, cw))
            count += 1

    while heap:
        if secs() > time_limit:
            bounds = [b for b, *_ in heap]
            lo = min(bounds)
            out, st = end(TIME_LIMIT, f"time limit ({time_limit:g} CPU s) with {len(heap)} "
                                      f"open node(s)")
            if np.isfinite(lo):
                out.bound = float(sense * min(lo, best))
            return out, st
        bound, _, _, fixz, fixw = heapq.heappop(heap)
        if beaten(bound):
            prune("bound", fixz, fixw)
            continue
        leaf = not (~(fixz | fixw)).any()
        r = _solve(c, M, q, fixz, fixw)
        stats.nodes += 1
        if r.status == 2:
            prune("infeasible", fixz, fixw)
        elif r.status == 3:
            zd = _ray(c, M, q, fixz, fixw)
            if zd is None:
                return end(UNPROVED, "a node LP was unbounded but no point and improving ray "
                                     "of it were found")
            z0, d = zd
            t1, t2, res = check_ray(M, q, z0, d)
            if res <= WITNESS_TOL:
                stats.covered = 1 << n  # the answer holds whatever the other patterns say
                out, st = end(UNBOUNDED, f"ray checked: z + t d is a solution at t = {t1:.3g} "
                                         f"and {t2:.3g} (residual {res:.1e}), c . d = "
                                         f"{float(L @ d):.3g}")
                out.value, out.witness, out.ray, out.residual = -sense * np.inf, z0, d, res
                return out, st
            if leaf:
                return end(UNPROVED, f"a piece's LP is unbounded but its ray fails the residual "
                                     f"check ({res:.1e})")
            split(-np.inf, fixz, fixw, _terms(M, q, z0 + t2 * d))
        elif r.status == 0:
            z = np.maximum(r.x, 0.0)
            v = float(r.fun)
            if beaten(v):
                prune("bound", fixz, fixw)
            elif independent_residual(M, q, z) <= WITNESS_TOL:
                best_z, best = z, float(c @ z)
                prune("solutions", fixz, fixw)
            elif leaf:
                return end(UNPROVED, "a piece's LP optimum fails the residual check")
            else:
                split(v, fixz, fixw, _terms(M, q, z))
        else:
            return end(UNPROVED, f"a node LP ended '{r.message}' (HiGHS)")
    if stats.covered != 1 << n:  # the tree's invariant: the pruned nodes partition {0,1}^n
        return end(UNPROVED, f"the pruned nodes cover {stats.covered} patterns, not 2^{n}")
    if best_z is None:
        return end(INFEASIBLE, "no piece is nonempty: the LCP has no solution")
    return end(OPTIMAL, f"proved over every pattern without a box (to {PRUNE_TOL:g} "
                        f"relative)")
