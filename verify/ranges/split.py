"""A certified lower bound of an observable over the valid steady states by a case split on the
contact states, plane contacts first (`split_bound`), for ends the MILP leaves open.

Each case fixes the states of some frictional contacts (their binaries y+, y- of
verify.ranges.steady: sliding +, sliding -, non-sliding); its bound is the certified
Lagrangian bound of the linear relaxation with those binaries fixed (verify.ranges.milp,
`lagrangian_bound`, evaluated in numpy with the fixed columns' bounds), and an infeasible case
is closed only by a checked Farkas certificate (multipliers y with a Lagrangian bound > 0 for
the zero cost). Why the plane first: mu_g weighs only the plane's S, and a plane contact's
state fixes its S (sliding: S = -s mu R) or its kinematics (non-sliding: u_i = -V and a_t = 0,
so at most the disks of one velocity roll on the plane); the relaxation with free binaries
lets the plane's S cancel, which is why its bound is 0 on Fig. 9's system.

The cases are split best-first (the case of least bound first); the contact split is the
plane contact whose relaxed binaries are most fractional, else any frictional contact. The
result is proved whatever the time limit: the least bound over the cases still open (and the
closed ones' bounds) is a lower bound over every valid steady state, since the cases cover all
state sets. When every case is closed at `target` (the best value met), the end is decided.
"""

from __future__ import annotations

import heapq
import time
from dataclasses import dataclass

import numpy as np

from rigidlcp.models.lattice import PLANE
from rigidlcp.verify.certificates.uniqueness import quiet_highs

from .milp import MilpModel, certified_result


@dataclass
class SplitBound:
    """bound: a proved lower bound of cost . x over the valid steady states (of sense * L for
    an observable); closed: every case closed at target (so bound >= target - tol: the end is
    decided when a state attains target); cases: the cases bounded; open: those left."""

    bound: float
    closed: bool
    cases: int
    open: int
    infeasible: int
    seconds: float


def _fixed_bounds(model: MilpModel, fix: dict[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Column bounds with the binaries of the contacts in fix (k -> state +1, -1, 0) fixed."""
    lb, ub = model.form.lb.copy(), model.form.ub.copy()
    for k, st in fix.items():
        yp, ym = model.base + k, model.base + model.F + k
        lb[yp] = ub[yp] = float(st > 0)
        lb[ym] = ub[ym] = float(st < 0)
    return lb, ub


def case_bound(model: MilpModel, cost: np.ndarray, fix: dict[int, int]
               ) -> tuple[float, np.ndarray | None]:
    """(certified lower bound of cost . x over the MILP's points with the states fix, the
    relaxation's point or None): +inf when a Farkas certificate proves the case empty, -inf
    when the LP gives no usable multipliers."""
    h, hs, f = model.lp, model.hs, model.form
    lb, ub = _fixed_bounds(model, fix)
    idx = np.arange(model.n, dtype=np.int32)
    h.changeColsBounds(model.n, idx, lb, ub)
    h.changeColsCost(model.n, idx, cost)
    try:
        with quiet_highs():
            h.run()
        return certified_result(h, hs, cost, model.A, f.lo, f.hi, lb, ub)
    finally:
        h.changeColsBounds(model.n, idx, f.lb, f.ub)
        h.clearSolver()


def _split_contact(model: MilpModel, x: np.ndarray, fix: dict[int, int],
                   plane: set[int]) -> int | None:
    """The unfixed contact (index k among the frictional ones) to split: a plane contact
    first, the most fractional (least max of y+, y-, y0) among them."""
    best, key = None, None
    for k in range(model.F):
        if k in fix:
            continue
        yp, ym = x[model.base + k], x[model.base + model.F + k]
        frac = max(yp, ym, 1.0 - yp - ym)
        cand = (k not in plane, frac)
        if key is None or cand < key:
            best, key = k, cand
    return best


def split_bound(model: MilpModel, cost: np.ndarray, target: float, time_limit: float,
                tol: float = 1e-9) -> SplitBound:
    """A proved lower bound of cost . x over the MILP of `model` (module docstring): cases are
    split until each is bounded at >= target - tol, is empty, or the time limit is reached."""
    if model.proportional:  # its HiGHS columns are not the Formulation's
        raise ValueError("split_bound needs a MilpModel with the velocity columns ('lazy' or "
                         "'big-M'), not 'proportional'")
    t0 = time.perf_counter()
    lat = model.form.system.lattice
    plane = {k for k, a in enumerate(model.form.fric) if int(lat.j[a]) == PLANE}
    goal = target - tol * max(1.0, abs(target))
    b, x = case_bound(model, cost, {})
    heap: list[tuple[float, int, dict[int, int], np.ndarray | None]] = []
    cases, infeasible, tick, closed_min = 1, 0, 0, np.inf
    if b == np.inf:
        infeasible += 1
    elif b >= goal:
        closed_min = b
    else:
        heap.append((b, tick, {}, x))
    while heap and time.perf_counter() - t0 < time_limit:
        b, _, fix, x = heapq.heappop(heap)
        k = None if x is None else _split_contact(model, x, fix, plane)
        if k is None:  # nothing left to split (every state fixed) or no point: stays open
            heapq.heappush(heap, (b, -1, fix, x))
            break
        for st in (1, -1, 0):
            child = {**fix, k: st}
            cb, cx = case_bound(model, cost, child)
            cases += 1
            if cb == np.inf:
                infeasible += 1
            elif cb >= goal:
                closed_min = min(closed_min, cb)
            else:
                tick += 1
                heapq.heappush(heap, (max(cb, b), tick, child, cx))
    bound = min([e[0] for e in heap] + [closed_min])
    return SplitBound(float(bound), not heap, cases, len(heap), infeasible,
                      time.perf_counter() - t0)
