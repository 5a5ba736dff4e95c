"""Ranges of linear observables over the whole solution set of an event's LCP (Sec. II C).

The LCP w = M z + q, 0 <= z perp w >= 0 (models.event) has for solution set the union, over
complementary patterns y (y_i = 1: w_i = 0; y_i = 0: z_i = 0), of the polyhedra
P_y = {z >= 0 : z_i = 0 (y_i = 0), w_i = 0 (y_i = 1), w >= 0}. For an observable L z:

* over the face of a given solution z* (its contact states, verify.certificates.faces): linear
  programs over the two convex faces F_D and F_0 through z*;
* over every pattern: a MILP (scipy.optimize.milp, HiGHS) in 0 <= z <= U with binaries y,
  z_i <= U y_i, w_i <= w_max,i (1 - y_i), w_max,i = max(0, q_i + U sum_j max(M_ij, 0)): exact
  consequences of the box. The box is *proved* to hold every solution when
  verify.certificates.bounds.no_solution_beyond shows that no solution has |z|_1 >= U. When it
  does not (LCP(M, 0) has a nonzero solution: the set may be unbounded, and the MILP's box is
  an assumption), each end is proved without a box by verify.ranges.pattern_search (branch
  and bound over the patterns, an LP per node; the MILP's witness its first bound): "optimal"
  over every solution, "unbounded" with a ray of a nonempty piece checked at two t, or
  "time limit" / "unproved" with the reason (the best value met is then not a bound); the
  scope says which.

Each end: the MILP's pattern is fixed and the extreme recomputed by an LP on P_y without the
box (the witness, never the MILP's own point), re-checked by the independent residual of
verify.certificates.stages (w in extended precision) <= 1e-8; an LP that is unbounded gives a
ray d (d >= 0 on the pattern's cone, L d of the right sign) checked by the residual of z + t d
at a large t. A MILP stopped by its time limit gives the status "time limit" (its best point
is reported as met, never as a bound).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import Bounds, LinearConstraint, linprog, milp

from rigidlcp.lcp import Solution
from rigidlcp.lcp.errors import InvalidInput
from rigidlcp.models.event import EventProblem
from rigidlcp.verify.certificates.bounds import no_solution_beyond
from rigidlcp.verify.certificates.faces import FaceLP
from rigidlcp.verify.certificates.stages import independent_residual
from rigidlcp.verify.certificates.uniqueness import (
    BOUND_FACTOR,
    quiet_highs,
    scales,
    sign_pattern,
)

from .milp import seconds
from .observables import (
    BadObservable,
    alpha_rows,
    check_observable,
    mu_g_vector,
    user_observables,
)
from .pattern_search import check_ray, extreme
from .result import INFEASIBLE, OPTIMAL, TIME_LIMIT, UNBOUNDED, End, Range

#: A witness is accepted when its independent residual is at most this.
WITNESS_TOL = 1e-8
_MILP = {"mip_feasibility_tolerance": 1e-9, "primal_feasibility_tolerance": 1e-9,
         "mip_rel_gap": 0.0}
_LP = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


@dataclass
class EventRanges:
    """face[name]: the range over the given solution's face (None without a solution);
    every[name]: over every solution (scope says whether the box is proved, or the ends by the
    pattern search without it); selected: the given solution's values; U, bound_proved: the box
    of the MILP and its proof; searched: whether the ends were (also) sought by
    verify.ranges.pattern_search, the box not being proved; proved: every end of every[...]
    proved (optimal, unbounded or infeasible, by the proved box or by the search)."""

    every: dict[str, Range]
    face: dict[str, Range | None]
    selected: dict[str, float]
    U: float
    bound_proved: bool
    bound_message: str
    seconds: float
    notes: list[str] = field(default_factory=list)
    searched: bool = False

    @property
    def proved(self) -> bool:
        return (self.bound_proved or self.searched) and all(
            e.status in (OPTIMAL, UNBOUNDED, INFEASIBLE)
            for r in self.every.values() for e in (r.lo, r.hi))

    def __repr__(self) -> str:
        def cell(e: End | None) -> str:
            if e is None:
                return "-"
            return f"{e.value:.8g}" if e.status == OPTIMAL else e.status

        head = (f"EventRanges: box |z| <= {self.U:.3g} "
                f"{'(proved: no solution beyond)' if self.bound_proved else '(NOT proved)'}, "
                f"{self.seconds:.2f} s")
        if self.searched:
            head += ("; every end proved without the box (pattern search)" if self.proved
                     else "; NOT every end proved (pattern search: see each end)")
        lines = [head, f"{'observable':<14} {'face min':>14} {'face max':>14} {'all min':>14} "
                       f"{'all max':>14} {'selected':>12}  other states at"]
        for name, r in self.every.items():
            f = self.face.get(name)
            sel = self.selected.get(name)
            other = [side for side, e in (("min", r.lo), ("max", r.hi))
                     if e.status == OPTIMAL and "other" in e.note]
            lines.append(f"{name:<14} {cell(f.lo if f else None):>14} "
                         f"{cell(f.hi if f else None):>14} {cell(r.lo):>14} {cell(r.hi):>14} "
                         f"{'' if sel is None else f'{sel:.8g}':>12}  {','.join(other)}")
        return "\n".join(lines)


def event_observables(ep: EventProblem, observables=None, over: str = "forces",
                      vt: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """{name: L over z}. Default: mu_g and every angular acceleration alpha[i]; with vt (the
    tangential velocities at the event) also D = -S . v_t; observables: "all" adds every R
    and S, or a dict {name: vector} / a matrix (rows "user[k]") over `over` = "forces"
    (x = [R; S], 2c entries) or "z" (the LCP's unknowns, n entries)."""
    system, G = ep.system, np.asarray(ep.G, dtype=float)
    c = system.c
    out = {"mu_g": mu_g_vector(system) @ G}
    for i, row in enumerate(alpha_rows(system, ep.dyn)):
        out[f"alpha[{i}]"] = row @ G
    if vt is not None:
        L = np.zeros(2 * c)
        L[c:] = -check_observable("vt", vt, c)
        out["D"] = L @ G
    if isinstance(observables, str):
        if observables != "all":
            raise BadObservable(f"observables must be 'all', a dict or a matrix, got "
                                f"{observables!r}")
        for a in range(c):
            out[f"R[{a}]"], out[f"S[{a}]"] = G[a], G[c + a]
        return out
    if observables is None:
        return out
    if over not in ("forces", "z"):
        raise ValueError(f"over must be 'forces' or 'z', got {over!r}")
    size = 2 * c if over == "forces" else ep.lcp.n
    for name, v in user_observables(observables, size).items():
        out[name] = v @ G if over == "forces" else v
    return out


def event_ranges(ep: EventProblem, solution=None, observables=None, *, over: str = "forces",
                 vt: np.ndarray | None = None, time_limit: float = 30.0,
                 bound: float | None = None, prove_bound: bool = True) -> EventRanges:
    """Ranges of the observables (see `event_observables`) over every solution of the
    event's LCP, and over the face of `solution` (an lcp.Solution or z) when given.

    time_limit: seconds per MILP, and CPU seconds per end of the pattern search (run when
    the box is not proved); bound: the box U (default 1e3 z_s); prove_bound: try to prove that
    no solution lies outside the box (verify.certificates.bounds)."""
    t0 = time.perf_counter()
    if not isinstance(ep, EventProblem):
        raise InvalidInput(f"event_ranges takes a models.EventProblem (models.event_problem("
                           f"system, state): its observables need the event's mechanics), got "
                           f"{type(ep).__name__}")
    time_limit = seconds(time_limit)
    M, q = np.asarray(ep.lcp.M, dtype=float), np.asarray(ep.lcp.q, dtype=float)
    obs = event_observables(ep, observables, over, vt)
    z_star = None
    if solution is not None:
        z_star = np.asarray(solution.z if isinstance(solution, Solution) else solution, float)
        if z_star.size != q.size:
            raise BadObservable(f"solution has {z_star.size} entries, the event's LCP {q.size}")
        res = independent_residual(M, q, z_star)
        if not res <= WITNESS_TOL:
            raise InvalidInput(f"the given z is not a solution of the event's LCP (independent "
                             f"residual {res:.2e})")
    zs, _ = scales(M, q, z_star if z_star is not None else np.zeros_like(q))
    U = float(bound) if bound is not None else BOUND_FACTOR * zs
    proved, message = False, "not tried"
    if prove_bound:
        nb = no_solution_beyond(M, q, U, time_limit=time_limit)
        proved, message = nb.proved is True, nb.message
    scope = ("every solution" if proved
             else f"every solution with z <= {U:.3g} (no bound proved: "
                  f"{message.removeprefix('no bound proved: ')})")
    face_lps = _face_lps(M, q, z_star) if z_star is not None else None
    pat_star = _pattern(M, q, z_star) if z_star is not None else None
    every, face, selected = {}, {}, {}
    for name, L in obs.items():
        every[name] = Range(name, _milp_end(M, q, L, +1, U, time_limit, pat_star),
                            _milp_end(M, q, L, -1, U, time_limit, pat_star), scope)
        if not proved:
            every[name] = _searched(M, q, L, every[name], U, message, time_limit, pat_star)
        face[name] = None
        if z_star is not None:
            selected[name] = every[name].selected = float(L @ z_star)
            face[name] = Range(name, _face_end(M, q, face_lps, L, +1),
                               _face_end(M, q, face_lps, L, -1), "the face of the solution",
                               selected[name])
    return EventRanges(every, face, selected, U, proved, message, time.perf_counter() - t0,
                       searched=not proved)


def _searched(M, q, L, box: Range, U, message, time_limit, pat_star) -> Range:
    """The MILP's in-box ends replaced by the pattern search's (verify.ranges.pattern_search),
    proved without the box: an in-box "unbounded" whose ray passes check_ray (two t) is kept,
    an in-box witness is the search's first bound."""
    ends = []
    for sense, e in ((+1, box.lo), (-1, box.hi)):
        if (e.status == UNBOUNDED and e.ray is not None
                and check_ray(M, q, np.asarray(e.witness), e.ray)[2] <= WITNESS_TOL):
            ends.append(e)
            continue
        z0 = e.witness if e.status in (OPTIMAL, TIME_LIMIT) else None
        end, _ = extreme(M, q, L, sense, incumbent=z0, time_limit=time_limit)
        ends.append(_states_note(M, q, end, pat_star))
    open_ = [side for side, e in zip(("min", "max"), ends)
             if e.status not in (OPTIMAL, UNBOUNDED, INFEASIBLE)]
    why = message.removeprefix("no bound proved: ")
    scope = (f"every solution (proved without a box by the pattern search; the box z <= "
             f"{U:.3g} has no bound proved: {why})" if not open_ else
             f"every solution, NOT proved at the {' and '.join(open_)} (pattern search: "
             f"{', '.join(e.status for e in ends)}; the box z <= {U:.3g} has no bound "
             f"proved: {why})")
    return Range(box.name, ends[0], ends[1], scope)


def _states_note(M, q, end: End, pat_star) -> End:
    """end.note told whether its witness has the given solution's contact states."""
    if end.witness is not None and pat_star is not None:
        same = np.array_equal(_pattern(M, q, np.asarray(end.witness)) == 1, pat_star == 1)
        end.note = (end.note + "; " if end.note else "") + (
            "same contact states as the solution" if same else "other contact states")
    return end


def _pattern(M, q, z) -> np.ndarray:
    zs, ws = scales(M, q, z)
    return sign_pattern(z, M @ z + q, zs, ws, 1e-9)


def _face_lps(M, q, z_star):
    pat = _pattern(M, q, z_star)
    P, D = pat == 1, pat == 0
    return [FaceLP(M, q, P, D, "z"), FaceLP(M, q, P, D, "w")], P, D


def _face_end(M, q, face_lps, L, sense) -> End:
    """The extreme of L over F_D u F_0 (verify.certificates.faces)."""
    lps, P, D = face_lps
    best = None
    for side, lp in zip(("z", "w"), lps):
        status, z = lp.solve(sense * L)
        if status == "unbounded":
            zero_z = ~P & ~D if side == "z" else ~P
            zero_w = P | D if side == "z" else P
            return _ray_end(M, q, L, sense, zero_z, zero_w, "the face")
        if status == "optimal" and (best is None or sense * (L @ z) < sense * (L @ best)):
            best = z
    if best is None:
        return End("failed", note="the face LPs found no point")
    res = independent_residual(M, q, best)
    if res > WITNESS_TOL:
        return End("failed", note=f"face witness rejected (residual {res:.1e})")
    return End(OPTIMAL, float(L @ best), best, residual=res)


def _pattern_lp(M, q, L, sense, y):
    """LP of sense * L z over P_y (no box)."""
    n = q.size
    eq, ub = np.flatnonzero(y), np.flatnonzero(~y)
    bounds = [(0, None) if y[i] else (0, 0) for i in range(n)]
    return linprog(sense * L, A_ub=-M[ub] if ub.size else None,
                   b_ub=q[ub] if ub.size else None, A_eq=M[eq] if eq.size else None,
                   b_eq=-q[eq] if eq.size else None, bounds=bounds, method="highs",
                   options=_LP)


def _ray_end(M, q, L, sense, zero_z, zero_w, where: str, z0=None) -> End:
    """End "unbounded" with a checked ray d of {z_i = 0 (zero_z), (M d)_i = 0 (zero_w),
    M d >= 0, d >= 0, sum d <= 1} with sense * L d < 0; "failed" if none passes."""
    n = q.size
    others = ~zero_w
    A_ub = np.vstack([-M[others], np.ones((1, n))])
    b_ub = np.r_[np.zeros(int(others.sum())), 1.0]
    bounds = [(0, 0) if zero_z[i] else (0, None) for i in range(n)]
    r = linprog(sense * L, A_ub=A_ub, b_ub=b_ub, A_eq=M[zero_w] if zero_w.any() else None,
                b_eq=np.zeros(int(zero_w.sum())) if zero_w.any() else None, bounds=bounds,
                method="highs", options=_LP)
    if r.status != 0 or not r.fun < 0:
        return End("failed", note=f"unbounded on {where} but no improving ray found")
    d = np.maximum(r.x, 0.0)
    if z0 is None:
        p = linprog(np.zeros(n), A_ub=-M[others] if others.any() else None,
                    b_ub=q[others] if others.any() else None,
                    A_eq=M[zero_w] if zero_w.any() else None,
                    b_eq=-q[zero_w] if zero_w.any() else None, bounds=bounds, method="highs",
                    options=_LP)
        z0 = p.x if p.status == 0 else None
    if z0 is None:
        return End("failed", note=f"unbounded on {where} but no point found for the ray")
    t = 1e3 * max(1.0, float(np.max(np.abs(z0))))
    res = independent_residual(M, q, z0 + t * d)
    if res > WITNESS_TOL:
        return End("failed", note=f"ray rejected: residual {res:.1e} at z + {t:.3g} d")
    return End(UNBOUNDED, -sense * np.inf, z0, ray=d, residual=res,
               note=f"ray checked on {where}: z + {t:.3g} d is a solution")


def _milp_end(M, q, L, sense, U, time_limit, pat_star) -> End:
    """The extreme of L over every solution in the box (module docstring)."""
    t0 = time.perf_counter()
    n = q.size
    wmax = np.maximum(q + U * np.sum(np.maximum(M, 0.0), axis=1), 0.0)
    Z = sp.csr_matrix((n, n))
    A = sp.vstack([sp.hstack([sp.csr_matrix(M), Z]),  # w = M z + q >= 0
                   sp.hstack([sp.eye(n), -U * sp.eye(n)]),  # z_i <= U y_i
                   sp.hstack([sp.csr_matrix(M), sp.diags(wmax)])]).tocsr()  # w <= wmax (1-y)
    lo = np.r_[-q, np.full(n, -np.inf), np.full(n, -np.inf)]
    hi = np.r_[np.full(n, np.inf), np.zeros(n), wmax - q]
    with quiet_highs():
        out = milp(np.r_[sense * L, np.zeros(n)], integrality=np.r_[np.zeros(n), np.ones(n)],
                   constraints=LinearConstraint(A, lo, hi),
                   bounds=Bounds(np.zeros(2 * n), np.r_[np.full(n, U), np.ones(n)]),
                   options={"time_limit": float(time_limit), **_MILP})
    secs = time.perf_counter() - t0
    if out.status == 2:
        return End(INFEASIBLE, seconds=secs, note="no solution in the box")
    if out.x is None:
        return End(TIME_LIMIT if out.status == 1 else "failed", seconds=secs,
                   note=str(out.message))
    y = out.x[n:] > 0.5
    r = _pattern_lp(M, q, L, sense, y)
    if r.status == 3:
        end = _ray_end(M, q, L, sense, ~y, y, "the MILP's pattern")
    elif r.status != 0:
        return End("failed", seconds=secs, note="the MILP's pattern holds no solution "
                                                "(rounding)")
    else:
        z = np.maximum(r.x, 0.0)
        res = independent_residual(M, q, z)
        if res > WITNESS_TOL:
            return End("failed", seconds=secs, note=f"witness rejected (residual {res:.1e})")
        end = End(OPTIMAL, float(L @ z), z, residual=res)
    end.seconds = time.perf_counter() - t0
    if out.status == 1 and end.status == OPTIMAL:
        end.status, end.best, end.value = TIME_LIMIT, end.value, None
    return _states_note(M, q, end, pat_star)
