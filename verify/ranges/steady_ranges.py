"""`steady_ranges`: the range of mu_g (and of each angular acceleration, R, S, or a user's
observable) over every valid steady state of a system (verify.ranges.steady), each end with a
witness state checked against the laws by verify.ranges.witness.steady_check.

An end is found by the MILP of verify.ranges.steady; its contact states are then fixed and the
extreme recomputed by a linear program over the forces of those states, without the force box
(the witness), and the velocities by a second one. The MILP's own point is never the witness.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import Bounds, LinearConstraint, milp

from rigidlcp.models.system import System
from rigidlcp.verify.certificates.uniqueness import quiet_highs

from .observables import check_observable, steady_observables
from .result import INFEASIBLE, OPTIMAL, TIME_LIMIT, UNBOUNDED, End, Range
from .steady import _MILP, Formulation, NotSteady, formulate, state_extreme, state_velocities, \
    states_of
from .witness import make_witness, steady_check

#: A witness is accepted when its independent residual is at most this.
WITNESS_TOL = 1e-8


@dataclass
class SteadyRanges:
    """Ranges over the valid steady states of `system`. box_proved: every valid steady state
    has R <= U (else the ranges are over those with R <= U); V_mode: how V was treated
    (docs/mechanics.md); selected: the run's own values, when a run was given."""

    system: System
    ranges: dict[str, Range]
    U: float
    box_proved: bool
    V_mode: str
    seconds: float
    run_values: dict[str, float] = field(default_factory=dict)

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
        if "mu_g" in self.run_values:
            out["run"] = {"mu_g": self.run_values["mu_g"]}
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
        for name, r in self.ranges.items():
            def cell(e: End) -> str:
                return f"{e.value:.10g}" if e.status == OPTIMAL else e.status
            run = self.run_values.get(name)
            lines.append(f"{name:<12} {cell(r.lo):>16} {cell(r.hi):>16} {r.width:>11.4g} "
                         f"{'' if run is None else f'{run:.8g}':>13}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return self.table()


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
                  V_mode: str | None = None) -> SteadyRanges:
    """Range of each observable over all valid steady states of `target` (a System, or a Run
    that ended steady: its last state's values are reported beside the ranges and must lie
    in them). observables: {name: L over x = [R; S]} added to `which` ("mu_g", "alpha":
    also every angular acceleration, "all": also every R and S). time_limit: seconds per end.
    box: the force box when no bound is proved. Raises NotSteady when no valid steady state
    exists or the run is not steady."""
    t0 = time.perf_counter()
    system, last = _run_system(target)
    form = formulate(system, box, V_mode)
    obs = steady_observables(system, which, form.dyn)
    for name, L in (observables or {}).items():
        obs[str(name)] = check_observable(str(name), L, 2 * system.c)
    scope = "all valid steady states" + ("" if form.box_proved else
                                         f" with every R <= {form.U:.4g} (no bound proved)")
    ranges, run_values = {}, {}
    for name, L in obs.items():
        lo = _end(form, L, +1, time_limit)
        hi = _end(form, L, -1, time_limit)
        ranges[name] = Range(name, lo, hi, scope)
        if last is not None:
            run_values[name] = float(L @ np.concatenate([last["R"], last["S"]]))
            ranges[name].selected = run_values[name]
    return SteadyRanges(system, ranges, form.U, form.box_proved, form.V_mode,
                        time.perf_counter() - t0, run_values)


def _end(form: Formulation, L: np.ndarray, sense: int, time_limit: float) -> End:
    """min (sense +1) or max (sense -1) of L . x over the valid steady states."""
    t0 = time.perf_counter()
    c, p = form.system.c, form.system.p
    cost = np.zeros(form.A.shape[1])
    cost[:2 * c] = sense * L
    with quiet_highs():
        out = milp(cost, integrality=form.integrality,
                   constraints=LinearConstraint(form.A, form.lo, form.hi),
                   bounds=Bounds(form.lb, form.ub),
                   options={"time_limit": float(time_limit), **_MILP})
    if out.status == 2:
        raise NotSteady("no valid steady state: every contact-state set the kinematics admit "
                        "violates a law (MILP infeasible)")
    if out.x is None:
        return End(TIME_LIMIT if out.status == 1 else "failed",
                   seconds=time.perf_counter() - t0, note=str(out.message))
    s = states_of(form, out.x)
    status, x, ray = state_extreme(form, s, L, sense)
    vel = state_velocities(form, s)
    if vel is None:  # the LP disagrees with the MILP's kinematics: keep the MILP's velocities
        vel = (out.x[2 * c:2 * c + p] / form.system.lattice.radius, float(out.x[2 * c + p]))
    if x is None:
        x = out.x[:2 * c]
    wit = make_witness(form.system, vel[0], vel[1], x[:c], x[c:], form.dyn)
    end = End(OPTIMAL, float(L @ x), wit, residual=wit.residual,
              seconds=time.perf_counter() - t0)
    if wit.residual > WITNESS_TOL:
        end.status, end.value = "failed", None
        end.note = f"witness rejected by the independent check (residual {wit.residual:.1e})"
        return end
    if out.status == 1:  # time limit with an incumbent: a value met, not a bound
        end.status, end.best, end.value = TIME_LIMIT, float(L @ x), None
        return end
    if status == UNBOUNDED:
        end = _check_ray(form, end, wit, ray, L, sense)
    elif status == INFEASIBLE:
        end.status, end.value = "failed", None
        end.note = "the contact states of the MILP's point admit no force (rounding)"
    elif sense * (end.value - sense * out.fun * sense) < -1e-9 * max(1.0, abs(end.value)):
        end.note = "the extreme of these contact states lies beyond the force box"
    return end


def _check_ray(form: Formulation, end: End, wit, ray, L: np.ndarray, sense: int) -> End:
    """End "unbounded" if x + t d stays a valid steady state for a large t and L d has the
    right sign; otherwise "failed" with the reason."""
    c = form.system.c
    if ray is None or not sense * float(L @ ray) < 0:
        end.status, end.value = "failed", None
        end.note = "the LP was unbounded but no improving ray was found"
        return end
    x = np.concatenate([wit.R, wit.S])
    t = 1e3 * max(1.0, float(np.max(np.abs(x))))
    y = x + t * ray
    res, _ = steady_check(form.system, wit.omega, wit.V, y[:c], y[c:], form.dyn)
    if res > WITNESS_TOL:
        end.status, end.value = "failed", None
        end.note = f"the ray did not pass the check (residual {res:.1e} at t = {t:.3g})"
        return end
    end.status, end.value, end.ray = UNBOUNDED, -sense * np.inf, ray
    end.note = f"ray checked: x + {t:.3g} d is a valid steady state"
    return end
