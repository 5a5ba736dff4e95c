"""Cross-checks of the report's steady states: by the independent integrator and by certificate.

**Kept by the toolkit's time-stepper** (issue 16.5; renamed in issue 21.4 from "confirmed by
time-stepping", for what it checks): a SELF-CONSISTENCY check, not an independent confirmation.
The time-stepper shares this toolkit's solvers (lemke, warm pivoting) and follows their points
where a step's solution is not unique, so agreement shows that the two integrators of one code
agree; integrators that select otherwise reach other valid steady states (`rigidlcp
compare-integrators --ensemble`, docs/integrators.md). Full Moreau-Jean runs of a 10x4 array take
minutes, so the report does not integrate from the initial state: it starts the time-stepper
(`models.timestepping.moreau_jean`, h = TS_H, theta = 1) FROM the event-driven steady state
(its time, angular velocities, box velocity and contact states) and runs it until the
time-stepper's own steady test holds (contact states and omega' unchanged for 20 consecutive
steps, no sliding contact decelerating) or for at most TS_STEPS steps. The steady state is
**kept** when that run ends "steady" (no step failed: every step's Coulomb residual is
checked by the integrator) and at its last step

* every contact has the event-driven state (T/NT and NS/S+/S-, `verify.integrators.state_labels`);
* max |omega'_TS - omega'_ED| <= TOL_ALPHA g / r and |mu_g,TS - mu_g,ED| <= TOL_MU,

i.e. the event-driven steady state is (to rounding) a steady state of the independent
integrator. Otherwise "NOT kept", with the drift. Transient state changes on the way
(e.g. a degenerate non-sliding contact sliding at O(h) velocity for one step) are reported,
not judged. Each check also says whether the event-driven state satisfies the time-stepper's
step laws (`verify.integrators.step_check`): where it does and the run still moves away, the
step's solution is not unique and the time-stepper's solver picks another one. The tolerances
are those of the seed-independence claims (experiments.seed_claim): both are exact solutions
of linear systems.

**Certified determinacy** (issue 17.4): the staged certificate
(`verify.certificates.stages.certify_stages` through `certify_event`) of the last event of the
run: for accelerations, forces and contact states, unique / another solution exists / unknown,
the stage that decided and the witness's size.
"""

from __future__ import annotations

import time
import traceback
from dataclasses import dataclass, field

import numpy as np

from rigidlcp import models
from rigidlcp.models.engine.records import Run
from rigidlcp.models.event import State
from rigidlcp.models.modes import RowModes, row_modes

TS_H = 2e-3
TS_STEPS = 200
TS_STEADY = 20
TOL_ALPHA = 1e-8
TOL_MU = 1e-9

TS_DEFINITION = (
    f"Moreau-Jean (h = {TS_H:g}, theta = 1) started from the event-driven steady state, run "
    f"until its own steady test ({TS_STEADY} steps with unchanged states and omega') or "
    f"{TS_STEPS} steps; kept when it ends steady with every step's Coulomb residual "
    f"checked and, at its last step, the same contact state at every contact (T/NT, "
    f"NS/S+/S-), max|d omega'| <= {TOL_ALPHA:g} g/r and |d mu_g| <= {TOL_MU:g}")


@dataclass
class TSCheck:
    """The time-stepper's self-consistency check of one steady state (module docstring;
    `confirmed`: the state was kept)."""

    label: str
    confirmed: bool = False
    status: str = ""
    steps: int = 0
    d_alpha: float = float("nan")
    d_mu_g: float = float("nan")
    d_force: float = float("nan")
    states_differing: int = -1  # at the last step
    transient: int = 0  # recorded steps (state changes) whose states differ from ED's
    ed_in_step: float = float("nan")  # step_check residual of the ED state (<= 1e-8: valid)
    mu_g_ts: float = float("nan")
    modes_ed: str = ""
    modes_ts: str = ""
    row_ts: RowModes | None = None  # first-row modes of the time-stepper's last step
    ts_valid_event: bool | None = None  # the TS's last step in the exact event problem
    seconds: float = 0.0
    error: str = ""

    def text(self) -> str:
        if self.error:
            return f"{self.label}: FAIL (evaluation error: {self.error.splitlines()[0]})"
        head = "kept" if self.confirmed else "NOT kept"
        return (f"{self.label}: {head} ({self.status} after {self.steps} steps; "
                f"max|d omega'| {self.d_alpha:.1e}, |d mu_g| {self.d_mu_g:.1e}, "
                f"{self.states_differing} contact state(s) differ at the end"
                + (f", {self.transient} transient step(s) with other states" if self.transient
                   else "") + ")")


@dataclass
class Determinacy:
    """The staged certificate of a steady state, per question (verdict, stage, witness)."""

    label: str
    n: int = 0
    accepted: bool = False
    verdicts: dict[str, dict] = field(default_factory=dict)
    seconds: float = 0.0
    error: str = ""

    def text(self) -> str:
        if self.error:
            return f"{self.label}: FAIL (evaluation error: {self.error.splitlines()[0]})"
        if not self.accepted:
            return f"{self.label}: the recorded solution is not accepted by certify (n {self.n})"
        parts = []
        for name in ("accelerations", "forces"):
            v = self.verdicts[name]
            s = f"{name} {_short(v['verdict'])} [{v['stage']}"
            w = v.get("witness")
            if w:
                s += (f"; witness |dz|/z_s {w['distance']:.2g}, d{name[0]} {w['difference']:.2g}"
                      f", {'same' if w['same_states'] else 'other'} contact states")
            parts.append(s + "]")
        return f"{self.label} (n {self.n}, {self.seconds:.1f} s): " + "; ".join(parts)


    def short(self) -> str:
        """One line for the claims table."""
        if self.error or not self.accepted:
            return self.text()
        v = self.verdicts
        return (f"{self.label}: accelerations {_short(v['accelerations']['verdict'])} "
                f"[{v['accelerations']['stage']}], forces {_short(v['forces']['verdict'])} "
                f"[{v['forces']['stage']}]")


def _short(verdict: str) -> str:
    return {"another solution exists": "NOT unique"}.get(verdict, verdict)


def confirm_by_timestepping(run: Run, label: str = "", h: float = TS_H,
                            steps: int = TS_STEPS) -> TSCheck:
    """Start Moreau-Jean from the steady state of `run` (event-driven) and judge whether it
    stays there (module docstring). Never raises: an error is returned in TSCheck.error."""
    from rigidlcp.models.timestepping import moreau_jean
    from rigidlcp.verify.integrators import event_check, state_labels, step_check

    out = TSCheck(label)
    t0 = time.perf_counter()
    try:
        if not run.steady or run.final is None:
            raise ValueError(f"the event-driven run is not steady ({run.status})")
        system, E, fin = run.system, run.last, run.final
        ts = moreau_jean(system, State(fin.t, fin.omega.copy(), fin.V, fin.s.copy()), h=h,
                         max_steps=steps, steady_steps=TS_STEADY)
        T = ts.last
        ref = state_labels(system, E)
        out.status = ts.status
        out.steps = int(round((T.t - fin.t) / h))
        out.states_differing = int(np.sum(state_labels(system, T) != ref))
        out.transient = sum(bool(np.any(state_labels(system, r) != ref)) for r in ts.records[:-1])
        out.ed_in_step = float(step_check(system, E, h).residual)
        out.d_alpha = float(np.abs(T.omega_dot - E.omega_dot).max(initial=0.0))
        out.d_mu_g = abs(float(T.mu_g) - float(E.mu_g))
        out.d_force = float(np.abs(np.r_[T.R - E.R, T.S - E.S]).max(initial=0.0))
        out.mu_g_ts = float(T.mu_g)
        out.row_ts = row_modes(system, T)
        out.modes_ed, out.modes_ts = row_modes(system, E).text(), out.row_ts.text()
        out.ts_valid_event = bool(event_check(system, T).valid)
        out.confirmed = bool(ts.status == "steady" and out.states_differing == 0
                             and out.d_alpha <= TOL_ALPHA * _acc(system)
                             and out.d_mu_g <= TOL_MU)
    except Exception as exc:  # reported as FAIL with the evidence, never dropped
        out.error = f"{type(exc).__name__}: {exc}\n{traceback.format_exc(limit=3)}"
    out.seconds = time.perf_counter() - t0
    return out


def _acc(system: models.System) -> float:
    """g / r (the unit of angular acceleration of the tolerances)."""
    return system.g / system.lattice.radius


def certify_steady(run: Run, label: str = "") -> Determinacy:
    """The staged certificate of the last event of `run` (accelerations, forces, states).
    Never raises: an error is returned in Determinacy.error."""
    from rigidlcp.verify.certificates.run import certify_event

    from .valid_steady import SEARCH_CLOCK

    out = Determinacy(label)
    t0 = time.perf_counter()
    try:
        row = certify_event(run, run.n_events - 1, ranges=False, clock=SEARCH_CLOCK)
        cert = row["certificate"]
        out.n, out.accepted = int(row["n"]), bool(row["accepted"])
        out.verdicts = {k: {kk: v[kk] for kk in ("verdict", "stage", "reason", "witness")}
                        for k, v in cert["verdicts"].items()}
    except Exception as exc:
        out.error = f"{type(exc).__name__}: {exc}\n{traceback.format_exc(limit=3)}"
    out.seconds = time.perf_counter() - t0
    return out


def check_job(job: tuple):
    """The cross-check jobs: ("ts", label, run) / ("cert", label, run), or ("sweep-ts", label,
    system, seed) for a sweep point (the run is made here: sweeps keep no runs)."""
    kind, label = job[0], job[1]
    if kind == "ts":
        return confirm_by_timestepping(job[2], label)
    if kind == "cert":
        return certify_steady(job[2], label)
    if kind == "sweep-ts":
        try:
            run = models.simulate(job[2], seed=job[3])
        except Exception as exc:
            return TSCheck(label, error=f"{type(exc).__name__}: {exc}")
        return confirm_by_timestepping(run, label)
    raise ValueError(f"unknown check job {job!r}")


__all__ = ["TSCheck", "Determinacy", "confirm_by_timestepping", "certify_steady", "check_job",
           "TS_H", "TS_STEPS", "TS_STEADY", "TOL_ALPHA", "TOL_MU", "TS_DEFINITION"]
