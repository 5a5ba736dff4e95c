"""`steady_ranges`: the range of mu_g (and of each angular acceleration, R, S, or a user's
observable) over every valid steady state of a system (verify.ranges.steady), each end with a
witness state checked against the laws by verify.ranges.witness.steady_check.

An end is found by the MILP of verify.ranges.steady (by default without velocities:
verify.ranges.proportional); its states are then fixed and the extreme recomputed by a linear
program over the forces of those states, without the force box (the witness), which moves at
(omega, V) = (alpha, gamma) t (where that reduction is not exact: velocities by a second linear
program). The MILP's own point is never the witness.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.system import System

from .cap_split import bound_open_ends
from .kinematics import realizable
from .milp import MilpModel, seconds
from .milp import clock as milp_clock
from .observables import steady_observables, user_observables
from .proportional import exact as proportional_exact
from .proportional import velocities as proportional_velocities
from .proportional import velocity_scale
from .result import (
    INFEASIBLE,
    OPTIMAL,
    TIME_LIMIT,
    UNBOUNDED,
    End,
    Range,
    end_cell,
    width_text,
    witness_tolerance,
)
from .seeds import seed_starts, seed_states
from .steady import (
    Formulation,
    NotSteady,
    formulate,
    state_extreme,
    state_velocities,
    states_of,
)
from .witness import WITNESS_TOL, make_witness, steady_check

#: A witness attains a certified bound when within this (relative to max(1, |bound|)).
ATTAIN_TOL = 1e-9


@dataclass
class SteadyRanges:
    """Ranges over the valid steady states of `system`. box_proved: the force bounds (R <= U,
    per contact in verify.ranges.bounds) are proved, for every observable of S and of the
    bounded R (each Range's scope says whether it is covered; else the range is over the
    states with R <= U); V_mode: how V was treated
    (docs/mechanics.md). When a run was given: run_values, its own values, and own, the
    ranges over the valid steady states with the run's own contact states (linear programs,
    no force box: unbounded ends are reported so)."""

    system: System
    ranges: dict[str, Range]
    U: float
    box_proved: bool
    V_mode: str
    seconds: float
    run_values: dict[str, float] = field(default_factory=dict)
    own: dict[str, Range] = field(default_factory=dict)

    @property
    def mu_g(self) -> Range:
        return self.ranges["mu_g"]

    def to_dict(self) -> dict:
        """The JSON of `rigidlcp ranges` (issue 21): {"steady": {"mu_g": [lo, hi],
        "witnesses": {"min": W, "max": W}, ...}}; an end that is not a number (unbounded, time
        limit) is null, its status says which."""
        def num(e: End):
            return float(e.value) if e.status == OPTIMAL else None

        mg = self.mu_g
        out = {"mu_g": [num(mg.lo), num(mg.hi)],
               "witnesses": {k: (e.witness.to_dict() if e.witness is not None else None)
                             for k, e in (("min", mg.lo), ("max", mg.hi))},
               "status": {"mu_g": [mg.lo.status, mg.hi.status]},
               "scope": mg.scope, "force_bound": {"U": self.U, "proved": self.box_proved},
               "V": self.V_mode, "seconds": round(self.seconds, 3)}
        bounds: dict[str, list] = {}
        for name, r in self.ranges.items():  # [lower bound of min, upper bound of max]
            pair = [num(e) if e.status == OPTIMAL else e.bound for e in (r.lo, r.hi)]
            if name == "mu_g":
                bounds["mu_g"] = pair
            else:
                bounds.setdefault(name.split("[")[0], []).append(pair)
        out["bounds"] = bounds
        if "mu_g" in self.run_values:
            out["run"] = {"mu_g": self.run_values["mu_g"]}
        if "mu_g" in self.own:
            o = self.own["mu_g"]
            out["own_states"] = {"mu_g": [num(o.lo), num(o.hi)],
                                 "status": [o.lo.status, o.hi.status]}
        groups: dict[str, list] = {}
        for name, r in self.ranges.items():
            if name == "mu_g":
                continue
            base = name.split("[")[0]
            groups.setdefault(base, []).append([num(r.lo), num(r.hi)])
            out["status"].setdefault(base, []).append([r.lo.status, r.hi.status])
        out.update(groups)
        return {"steady": out}

    def table(self) -> str:
        lines = [f"valid steady states of {self.system.lattice!r} (gamma {self.system.gamma:g}, "
                 f"mu {self.system.mu_pp:g}/{self.system.mu_plane:g}/{self.system.mu_wall:g}); "
                 f"V {self.V_mode}; force bound R <= {self.U:.4g} "
                 f"{'(proved)' if self.box_proved else '(a box: not proved)'}; "
                 f"{self.seconds:.2f} s",
                 f"{'observable':<12} {'min':>16} {'max':>16} {'width':>11} {'run':>13}"]
        cell, width = end_cell, width_text
        for name, r in self.ranges.items():
            run = self.run_values.get(name)
            lines.append(f"{name:<12} {cell(r.lo, -1):>16} {cell(r.hi, 1):>16} "
                         f"{width(r):>11} {'' if run is None else f'{run:.8g}':>13}")
            if name in self.own:
                o = self.own[name]
                lines.append(f"{'  own states':<12} {cell(o.lo, -1):>16} {cell(o.hi, 1):>16} "
                             f"{width(o):>11}")
        for name, r in self.ranges.items():
            for e in (r.lo, r.hi):
                if e.note and not e.note.startswith(("proved by", "optimal by")):
                    lines.append(f"note ({name}): {e.note}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return self.table()


def _alpha(system: System, R: np.ndarray, S: np.ndarray) -> np.ndarray:
    """Angular accelerations of the forces (R, S): the rotational part of nu'."""
    return Dynamics(system).accelerations(np.concatenate([R, S]))[2 * system.p:]


def _run_system(target) -> tuple[System, dict[str, np.ndarray] | None]:
    if isinstance(target, System):
        return target, None
    if hasattr(target, "records") and hasattr(target, "system"):
        if target.status != "steady":
            raise NotSteady(f"the run ended {target.status!r}, not in a steady state: steady "
                            "ranges need a run that reached one (or pass its system)")
        last = target.records[-1]
        return target.system, {"R": np.asarray(last.R, float), "S": np.asarray(last.S, float)}
    raise TypeError(f"expected a models.System or a steady Run, got {type(target).__name__}")


def steady_ranges(target, observables: dict | None = None, *, which: str = "mu_g",
                  time_limit: float = 60.0, box: float | None = None,
                  V_mode: str | None = None, kinematics: str = "auto", split: bool | float = True,
                  progress: Callable[[int, int, str], None] | None = None,
                  clock: str = "cpu") -> SteadyRanges:
    """Range of each observable over all valid steady states of `target` (a System, or a Run
    that ended steady: its last state's values are reported beside the ranges and must lie
    in them). observables: {name: L over x = [R; S]}, or a matrix whose rows are named
    "user[k]", added to `which` ("mu_g", "alpha": also every angular acceleration, "all":
    also every R and S; another object is BadObservable). time_limit: seconds per end.
    box: the force box when no bound is proved. kinematics: "auto" ("proportional" where
    verify.ranges.proportional.exact holds, else "lazy"), "proportional" (no velocities in
    the MILP; witnesses move at (alpha, gamma) t, t = 1 or the run's V / gamma), "lazy"
    (velocities checked on each optimum, verify.ranges.milp) or "big-M" (in the MILP).
    split: an end left at the time limit gets a proved bound by verify.ranges.cap_split where
    it applies (a number s: also disk_split's, s seconds per end). progress(done, total,
    name): called after each end's search (total: 2 per observable). clock: time_limit and
    the disk split's seconds counted as this process's CPU time ("cpu", the default, as
    `rigidlcp ranges` and verify.certify: the same work whatever the machine's load;
    verify.ranges.milp.MilpModel) or on the wall clock ("wall").
    Raises NotSteady (none valid, run not steady)."""
    milp_clock(clock)  # a wrong clock refused before any work (InvalidInput)
    time_limit = seconds(time_limit)
    t0 = time.perf_counter()
    system, last = _run_system(target)
    start = None
    if last is not None:
        # The run's state one time unit after its last event (a steady state stays one; a
        # contact that starts to slide there has v_t = 0 at the event itself).
        fin = target.final
        alpha = _alpha(system, last["R"], last["S"])
        omega, V = fin.omega + alpha, fin.V + system.gamma
        v_scale = max(float(np.sqrt(system.g * system.lattice.radius)), abs(V))
        res, s_run = steady_check(system, omega, V, last["R"], last["S"], v_scale=v_scale)
        if res <= WITNESS_TOL:
            start = (last["R"], last["S"], omega, V, s_run)
    form = formulate(system, box, V_mode)
    obs = steady_observables(system, which, form.dyn)
    obs.update(user_observables(observables, 2 * system.c))
    unproved = f"all valid steady states with every R <= {form.U:.4g} (no bound proved)"
    ranges, run_values, own = {}, {}, {}
    if kinematics == "auto":
        kinematics = "proportional" if proportional_exact(form) else "lazy"
    elif kinematics == "proportional" and not proportional_exact(form):
        raise ValueError(f"kinematics 'proportional' is not exact here (gamma "
                         f"{system.gamma:g}, V {form.V_mode}): use 'lazy' or 'big-M'")
    model = MilpModel(form, kinematics, clock)
    model.V_ref = None if start is None else float(start[3])
    if start is not None:
        model.starts.append(form.start(*start))
        model.add_seed(start[4])
    for s_seed in seed_states(form):
        model.add_seed(s_seed)
    for k, (name, L) in enumerate(obs.items()):
        lo = _end(form, model, L, +1, time_limit)
        if progress is not None:
            progress(2 * k + 1, 2 * len(obs), name)
        hi = _end(form, model, L, -1, time_limit)
        if progress is not None:
            progress(2 * k + 2, 2 * len(obs), name)
        scope = "all valid steady states" if form.proved_for(L) else unproved
        ranges[name] = Range(name, lo, hi, scope)
    # The ends left at their time limit, again against the states met since (a later end's
    # witness may attain an earlier end's certified bound): no new search.
    for name, L in obs.items():
        for side, sense in (("lo", +1), ("hi", -1)):
            old = getattr(ranges[name], side)
            if old.status == TIME_LIMIT:
                new = _end(form, model, L, sense, 0.0, seeds=False)
                if new.status == OPTIMAL:
                    new.seconds += old.seconds
                    setattr(ranges[name], side, new)
    if split:  # a proved bound on each end still open (verify.ranges.cap_split)
        bound_open_ends(form, ranges, obs, 0.0 if split is True else float(split), clock)
    for name, L in obs.items():
        if last is not None:
            run_values[name] = float(L @ np.concatenate([last["R"], last["S"]]))
            ranges[name].selected = run_values[name]
            if start is not None:
                own[name] = Range(name, _own_end(form, start, L, +1),
                                  _own_end(form, start, L, -1), "the run's own contact states",
                                  run_values[name])
    return SteadyRanges(system, ranges, form.U, form.box_proved, form.V_mode,
                        time.perf_counter() - t0, run_values, own)


def _own_end(form: Formulation, start: tuple, L: np.ndarray, sense: int) -> End:
    """An end over the valid steady states with the run's contact states (its velocities)."""
    R, S, omega, V, s = start
    status, x, ray = state_extreme(form, s, L, sense)
    if x is None:
        return End("failed", note="the run's contact states admit no force (rounding)")
    system = form.system
    v_scale = max(float(np.sqrt(system.g * system.lattice.radius)), abs(V))
    wit = make_witness(system, omega, V, x[:system.c], x[system.c:], form.dyn, v_scale)
    end = End(OPTIMAL, float(L @ x), wit, residual=wit.residual,
              tol=witness_tolerance(system, L, x, wit.residual))
    if wit.residual > WITNESS_TOL:
        end.status, end.value = "failed", None
        end.note = f"witness rejected by the independent check (residual {wit.residual:.1e})"
    elif status == UNBOUNDED:
        end = _check_ray(form, end, wit, ray, L, sense, v_scale)
    return end


def _end(form: Formulation, model: MilpModel, L: np.ndarray, sense: int, time_limit: float,
         seeds: bool = True) -> End:
    """min (sense +1) or max (sense -1) of L . x over the valid steady states; seeds: also
    the seed states' extremes (linear programs) before the search."""
    t0 = time.perf_counter()
    c, p = form.system.c, form.system.p
    cost = np.zeros(model.n)
    cost[:2 * c] = sense * L
    # A checked valid steady state that attains the relaxation's certified bound is an
    # extreme: no branching (verify.ranges.milp). First the states met so far, then the seeds.
    bound = model.relaxation_bound(cost)
    tol = ATTAIN_TOL * max(1.0, abs(bound)) if np.isfinite(bound) else 0.0
    xm, mstat, how = None, None, ""
    pools = [lambda: model.starts, lambda: seed_starts(form, model, L, sense)]
    found: list[np.ndarray] = []
    for k, pool in enumerate(pools[:2 if seeds else 1]):
        cands = pool()
        if k:
            found = cands
        best = min(cands, key=lambda x: float(cost @ x), default=None)
        if best is not None and float(cost @ best) <= bound + tol:
            xm, mstat = best, OPTIMAL
            how = (f"proved by the relaxation's certified bound {sense * bound:.12g} "
                   "(no branching)")
            break
    if xm is None:
        mstat, xm = (model.solve(cost, time_limit, found) if time_limit > 0
                     else (TIME_LIMIT, None))
        if xm is None and mstat == TIME_LIMIT:  # the best checked state met, not a bound
            xm = min([*model.starts, *found], key=lambda x: float(cost @ x), default=None)
    if mstat == INFEASIBLE and form.box_proved:
        raise NotSteady("no valid steady state: every contact-state set the kinematics admit "
                        "violates a law (MILP infeasible)")
    if mstat == INFEASIBLE:  # only the box was searched: not a proof that none exists
        return End("failed", seconds=time.perf_counter() - t0,
                   note=f"no valid steady state with every R <= {form.U:.4g} (MILP infeasible "
                   "in the force box, which no proved bound covers: states with larger "
                   "forces, e.g. R ~ 1/mu at a tiny mu, not searched)")
    if xm is None:
        return End(TIME_LIMIT if mstat == TIME_LIMIT else "failed",
                   seconds=time.perf_counter() - t0, note=f"HiGHS: {mstat}, no point")
    s = states_of(form, xm)
    status, x, ray = state_extreme(form, s, L, sense)
    if x is None:
        x = xm[:2 * c]
    v_scale = 0.0
    if model.proportional:  # (omega, V) = (alpha, gamma) t (verify.ranges.proportional)
        vel = proportional_velocities(form, x[:c], x[c:], model.V_ref)
        v_scale = velocity_scale(form, vel[1])
    else:
        vel = state_velocities(form, s)
    if vel is None:  # the LP disagrees: the shortest-path velocities, else the MILP's
        r = form.system.lattice.radii
        ok, xv = realizable(form, s)
        xv = xv if ok else xm[2 * c + p:2 * c + 2 * p + 1]
        vel = (np.asarray(xv[:p]) / r, float(xv[p]))
    wit = make_witness(form.system, vel[0], vel[1], x[:c], x[c:], form.dyn, v_scale)
    if wit.residual > WITNESS_TOL and model.proportional:
        # (alpha, gamma) t carries alpha's rounding, ~ eps max|lambda| / m: with R ~ 1/mu
        # (mu_pp ~ 1e-8) a rolling contact's v_t reads as sliding. The velocities of the
        # states s themselves (v_t = 0 where non-sliding), if the kinematics admit them:
        vel_s = state_velocities(form, s)
        if vel_s is not None:
            wit_s = make_witness(form.system, vel_s[0], vel_s[1], x[:c], x[c:], form.dyn)
            if wit_s.residual <= WITNESS_TOL:
                wit = wit_s
                how = (how + "; " if how else "") + ("velocities of its contact states (the "
                                                     "proportional ones misread by rounding)")
    end = End(OPTIMAL, float(L @ x), wit, residual=wit.residual,
              seconds=time.perf_counter() - t0, note=how,
              tol=witness_tolerance(form.system, L, x, wit.residual))
    if wit.residual > WITNESS_TOL:
        end.status, end.value = "failed", None
        end.note = f"witness rejected by the independent check (residual {wit.residual:.1e})"
        return end
    if mstat != OPTIMAL:  # time limit with an incumbent: a value met, not a bound
        end.status, end.best, end.value = TIME_LIMIT, float(L @ x), None
        return end
    if status == UNBOUNDED:
        end = _check_ray(form, end, wit, ray, L, sense, moving=model.proportional)
    elif status == INFEASIBLE:
        # the state LP (tolerance 1e-10) refused the MILP's own states, whose point passed the
        # independent check above (x is the MILP's): that point is the witness, its value
        # the MILP's optimum
        end.note = ("the state LP failed on the MILP's contact states (rounding at forces up "
                    f"to {float(np.max(np.abs(x))):.3g}); the MILP's own point is the witness: "
                    "optimal by HiGHS's branch and bound (gap closed; bound not re-checked)")
    elif sense * (end.value - float(L @ xm[:2 * c])) < -1e-9 * max(1.0, abs(end.value)):
        end.note = "the extreme of these contact states lies beyond the force box"
    elif not how and sense * end.value <= bound + tol:  # the search's optimum, certified too
        end.note = (f"proved by the relaxation's certified bound {sense * bound:.12g} "
                    "(attained by the search's witness)")
    elif not how:
        end.note = "optimal by HiGHS's branch and bound (gap closed; bound not re-checked)"
    if end.status == OPTIMAL:
        model.starts.append(form.start(wit.R, wit.S, wit.omega, wit.V, wit.s))
    if end.status in (OPTIMAL, TIME_LIMIT):
        model.add_seed(wit.s)
    return end


def _check_ray(form: Formulation, end: End, wit, ray, L: np.ndarray, sense: int,
               v_scale: float = 0.0, moving: bool = False) -> End:
    """End "unbounded" if x + t d stays a valid steady state for a large t and L d has the
    right sign; otherwise "failed" with the reason. moving: the velocities are those of
    x + t d (verify.ranges.proportional), else the witness's."""
    c = form.system.c
    if ray is None or not sense * float(L @ ray) < 0:
        end.status, end.value = "failed", None
        end.note = "the LP was unbounded but no improving ray was found"
        return end
    x = np.concatenate([wit.R, wit.S])
    t = 1e3 * max(1.0, float(np.max(np.abs(x))))
    y = x + t * ray
    omega, V = wit.omega, wit.V
    if moving:
        omega, V = proportional_velocities(form, y[:c], y[c:], wit.V)
        v_scale = velocity_scale(form, V)
    res, _ = steady_check(form.system, omega, V, y[:c], y[c:], form.dyn, v_scale)
    if res > WITNESS_TOL:
        end.status, end.value = "failed", None
        end.note = f"the ray did not pass the check (residual {res:.1e} at t = {t:.3g})"
        return end
    end.status, end.value, end.ray = UNBOUNDED, -sense * np.inf, ray
    end.note = f"ray checked: x + {t:.3g} d is a valid steady state"
    return end

