"""An ensemble over selection rules: the spread of the steady states reachable from one start.

Where an event's (or a step's) solution set has more than one point, the run follows the point
of a selection rule (models/selection.py). `selection_ensemble` runs the event engine, and the
Moreau-Jean time-stepper when a step h is given, once per rule from the same initial angular
velocities, checks each final state against the exact event laws at its configuration
(`verify.integrators.event_check`: residual, sliding law, and the steady-state definition of
verify.steadiness: a_n = 0, non-sliding a_t = 0, no sliding contact decelerating) and
reports the spread of mu_g over the runs that end in a valid steady state, and how many distinct
vectors of contact states (T/NT, NS/S+/S-) they reach. A spread of 0 does not prove the steady
state unique (only these rules were tried); a spread > 0 proves it is not (each end is a checked
steady state).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from rigidlcp import models
from rigidlcp.models.engine.records import Run
from rigidlcp.models.modes import row_modes
from rigidlcp.models.selection import Selection
from rigidlcp.models.timestepping import moreau_jean

from .integrators import LawCheck, event_check, state_labels

#: The default ensemble: both ends of the sum-R range, two random points, the solver's vertex.
RULES = ("face-min-norm", "max-sum-R", "random:1", "random:2", "none")


@dataclass
class EnsembleRow:
    rule: str
    integrator: str  # "event-driven" or "moreau-jean h=..."
    run: Run
    check: LawCheck
    states: np.ndarray  # state_labels of the last record
    seconds: float

    @property
    def valid_steady(self) -> bool:
        return self.run.status == "steady" and self.check.valid and bool(self.check.steady)

    @property
    def mu_g(self) -> float:
        return float(self.run.last.mu_g)


@dataclass
class Ensemble:
    system: models.System
    seed: int | None
    rows: list[EnsembleRow] = field(default_factory=list)

    def steady_rows(self) -> list[EnsembleRow]:
        return [r for r in self.rows if r.valid_steady]

    @property
    def mu_g_range(self) -> tuple[float, float] | None:
        mus = [r.mu_g for r in self.steady_rows()]
        return (min(mus), max(mus)) if mus else None

    @property
    def distinct_states(self) -> int:
        return len({r.states.tobytes() for r in self.steady_rows()})


def selection_ensemble(system: models.System, seed: int | None = 1,
                       rules: tuple[str, ...] = RULES, h: float | None = None,
                       t_max: float = 60.0, max_events: int = 100_000,
                       step_rules: tuple[str, ...] | None = None) -> Ensemble:
    """Run every rule from the initial state of `seed` (see the module docstring).

    rules: the event engine's selection rules; h: also the Moreau-Jean time-stepper with this
    step, over step_rules (default: the rules other than "global"); t_max: bound on each run.
    Bad rules raise models.selection.InvalidSelection before anything runs.
    """
    parsed = [str(Selection.parse(r)) for r in rules]
    step_parsed = [str(Selection.parse(r)) for r in (step_rules if step_rules is not None
                                                      else rules)]
    step_parsed = [r for r in step_parsed if r != "global"] if h is not None else []
    ens = Ensemble(system, seed)
    start = models.initial_state(system, seed=seed)
    jobs = [(r, "event-driven") for r in parsed] + [(r, f"moreau-jean h={h:g}")
                                                     for r in step_parsed]
    for rule, integrator in jobs:
        t0 = time.perf_counter()
        if integrator == "event-driven":
            run = models.simulate(system, start.copy(), selection=rule, t_max=t_max,
                                  max_events=max_events)
        else:
            run = moreau_jean(system, start.copy(), h=h, selection=rule, t_max=t_max)
        rec = run.last
        ens.rows.append(EnsembleRow(rule, integrator, run, event_check(system, rec),
                                    state_labels(system, rec), time.perf_counter() - t0))
    return ens


def format_ensemble(ens: Ensemble) -> str:
    """The ensemble as a table and its spread (what `rigidlcp compare-integrators --ensemble`
    prints)."""
    sysm, lat = ens.system, ens.system.lattice
    lines = [f"{lat.title()}, mu_pp {sysm.mu_pp:g}, mu_plane {sysm.mu_plane:g}, "
             f"mu_wall {sysm.mu_wall:g}, gamma {sysm.gamma:g}, V0 {sysm.V0:g}, seed {ens.seed}: "
             "one start, every selection rule",
             f"{'rule':<16} {'integrator':<20} {'status':<11} {'t_end':>8} {'mu_g':>11} "
             f"{'modes':>12} {'sum R':>10} {'dstates':>7} {'event laws':>14} {'s':>6}"]
    ref = ens.steady_rows()[0].states if ens.steady_rows() else None
    for r in ens.rows:
        rec = r.run.last
        modes = row_modes(sysm, rec).text()
        d = "-" if ref is None else str(int(np.sum(r.states != ref)))
        law = (f"{'valid' if r.check.valid else 'INVALID'}"
               f"{', steady' if r.check.steady else ', unsteady'} {r.check.residual:.0e}")
        lines.append(f"{r.rule:<16} {r.integrator:<20} {r.run.status:<11} {rec.t:8.4g} "
                     f"{r.mu_g:11.7f} {modes:>12} {float(np.sum(rec.R)):10.4f} {d:>7} "
                     f"{law:>14} {r.seconds:6.1f}")
    rng = ens.mu_g_range
    if rng is None:
        lines.append("no run ended in a valid steady state: no spread to report")
    else:
        n = len(ens.steady_rows())
        lines.append(f"valid steady states: {n} of {len(ens.rows)} runs; mu_g in "
                     f"[{rng[0]:.7f}, {rng[1]:.7f}], spread {rng[1] - rng[0]:.3g}; "
                     f"{ens.distinct_states} distinct contact-state vectors "
                     "(dstates: contacts whose state differs from the first steady row)")
    return "\n".join(lines)


__all__ = ["RULES", "Ensemble", "EnsembleRow", "format_ensemble", "selection_ensemble"]
