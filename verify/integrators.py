"""Two integrators on one system: event-driven (models.simulate) against Moreau-Jean
time-stepping (models.timestepping), and each steady state checked against the other's laws.

* `event_check(system, record)`: is a record's (R, S, states) a solution of the exact event
  problem (models.event_problem, Eqs. 2.5-2.10 at acceleration level) at that record's
  configuration and states? The forces are mapped to the event LCP's z = [R, tau, a_minus]
  (tau = mu R + S, a_minus = max(-a_t, 0) for the candidates), the substituted sliding law
  S = -s mu R is checked, and `verify.certify` measures the residual. Also: is it steady
  (verify.steadiness's definition, docs/mechanics.md: a_n = 0, a non-sliding contact keeps
  a_t = 0, no sliding contact decelerating, Sec. IV A)?
* `step_check(system, record, h)`: the converse, for an event-driven record: are its forces
  times h, with u^{k+1} = u^k + h a, a solution of the velocity-level step laws of
  models.timestepping (Signorini and Coulomb on u^{k+1}, natural-map residual)?
* `compare_integrators(system, seed, hs)`: both integrators, then per h: the time-stepper's
  steady mu_g, states and first-row modes, their differences to the event-driven steady state,
  max |delta alpha| (angular accelerations), the error of the angular velocities at a common
  time T, each steady state's check against the other's problem, and the observed orders
  log2(e(h) / e(h / 2)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rigidlcp import models
from rigidlcp.lcp.errors import InvalidInput, NotApplicable
from rigidlcp.models.engine.records import EventRecord, Run
from rigidlcp.models.event import State, acceleration_tol, event_problem
from rigidlcp.models.modes import row_modes
from rigidlcp.models.timestepping import coulomb_residual, moreau_jean

from .certificates.certify import certify
from .steadiness import KINEMATICS, steadiness


@dataclass
class LawCheck:
    """Whether a record satisfies a set of exact laws at its configuration."""

    valid: bool
    residual: float  # scaled residual of the laws (see the function that made it)
    sliding_law: float = 0.0  # max |S + s mu R| over the sliding contacts, / force scale
    steady: bool | None = None  # verify.steadiness's kinematic conditions hold
    omega_dot_gap: float = 0.0  # |omega' of the forces - the record's omega'|
    note: str = ""


def event_check(system: models.System, record: EventRecord, tol: float = 1e-8) -> LawCheck:
    """Check a record against the exact event problem at its configuration (see module doc)."""
    c = system.c
    s = np.where(system.mu > 0, np.asarray(record.s, int), 0)
    ep = event_problem(system, State(record.t, np.asarray(record.omega, float), record.V, s))
    R, S = np.asarray(record.R, float), np.asarray(record.S, float)
    scale = max(float(np.abs(np.concatenate([R, S])).max(initial=0.0)),
                system.mass * max(system.g, abs(system.gamma)))
    a = ep.dyn.relative_accelerations(np.concatenate([R, S]))
    cand = ep.candidates
    tau = system.mu[cand] * R[cand] + S[cand]
    a_minus = np.maximum(-a[c:][cand], 0.0)
    z = np.concatenate([R, tau, a_minus])
    sliding = (s != 0)
    slide_gap = float(np.abs(S[sliding] + s[sliding] * system.mu[sliding] * R[sliding])
                      .max(initial=0.0)) / scale
    free = system.mu == 0
    slide_gap = max(slide_gap, float(np.abs(S[free]).max(initial=0.0)) / scale)
    cert = certify(ep, z, tol=tol, uniqueness="none")
    es = ep.unpack(z)
    gap = float(np.abs(es.omega_dot - np.asarray(record.omega_dot)).max(initial=0.0))
    # steady: the kinematic conditions of verify.steadiness's definition (docs/mechanics.md)
    # at the record's states, accelerations to 1e-9 of the driving scale (acceleration_tol)
    st = steadiness(system, R, S, s, es.a_n, es.a_t, f_scale=scale,
                    a_scale=acceleration_tol(system) / 1e-9, trans=es.trans_acc)
    ok = cert.accepted and slide_gap <= tol
    return LawCheck(valid=bool(ok), residual=cert.scaled_residual, sliding_law=slide_gap,
                    steady=st.steady(1e-9, KINEMATICS), omega_dot_gap=gap,
                    note="" if st.steady(1e-9, KINEMATICS) else st.reason(1e-9, KINEMATICS))


def step_check(system: models.System, record: EventRecord, h: float,
               tol: float = 1e-8) -> LawCheck:
    """Check an event-driven record against the velocity-level laws of one Moreau-Jean step of
    size h from its velocities: P = h [R; S], u^{k+1} = u^k + h a (a = W lambda + q)."""
    dyn = models.Dynamics(system)
    lam = np.concatenate([record.R, record.S])
    u0 = dyn.velocities(np.asarray(record.omega, float), record.V)
    u1 = u0 + h * dyn.relative_accelerations(lam)
    u1[:system.c] = np.where(np.abs(u1[:system.c]) < 1e-14, 0.0, u1[:system.c])
    P = h * lam
    P_scale = max(float(np.abs(P).max(initial=0.0)),
                  h * system.mass * max(system.g, abs(system.gamma)))
    u_scale = max(float(np.abs(u0).max(initial=0.0)), system.g * h)
    res = coulomb_residual(system, P, u1, P_scale, u_scale)
    return LawCheck(valid=bool(res <= tol), residual=res)


@dataclass
class StepRow:
    """One time-step size of a comparison."""

    h: float
    run: Run
    mu_g: float
    modes: str
    d_mu_g: float  # |mu_g(time-stepping) - mu_g(event-driven)|, steady states
    d_alpha: float  # max |delta omega'| between the steady states
    d_states: int  # contacts whose (T/NT, tangential state) differ
    d_omega_T: float  # max |omega_ts(T) - omega_ed(T)| at the common time T
    d_omega_max: float  # max over the steps t_k of max |omega_ts(t_k) - omega_ed(t_k)|
    ts_in_event: LawCheck | None  # the time-stepper's steady state in the exact event problem
    ed_in_step: LawCheck | None  # the event-driven steady state in this h's step laws


@dataclass
class Comparison:
    system: models.System
    seed: int | None
    event_run: Run
    modes: str
    T: float
    rows: list[StepRow] = field(default_factory=list)

    def orders(self, name: str) -> list[float]:
        """Observed orders log2(e(h_k) / e(h_{k+1})) of a StepRow error field (halving h)."""
        out = []
        for a, b in zip(self.rows, self.rows[1:]):
            ea, eb = getattr(a, name), getattr(b, name)
            ratio = a.h / b.h
            out.append(math.log(ea / eb) / math.log(ratio) if ea > 0 and eb > 0 else math.nan)
        return out

    def order_text(self, name: str, floor: float = 1e-10) -> str:
        """The orders as text; 'exact' where both errors are at rounding (<= floor)."""
        out = []
        for a, b, o in zip(self.rows, self.rows[1:], self.orders(name)):
            if getattr(a, name) <= floor and getattr(b, name) <= floor:
                out.append("exact")
            else:
                out.append("nan" if math.isnan(o) else f"{o:.2f}")
        return ", ".join(out)


def omega_at(run: Run, T: float) -> np.ndarray:
    """Angular velocities of an event-driven run at time T (linear between events)."""
    t = run.array("t")
    k = int(np.searchsorted(t, T, side="right")) - 1
    if k < 0:
        raise InvalidInput(f"T = {T} is before the run's first event")
    rec = run.records[k]
    return rec.omega + rec.omega_dot * (T - rec.t)


def state_labels(system: models.System, record: EventRecord) -> np.ndarray:
    """Per contact: 0 NT, then 1 + (s + 1) for transmitting contacts (s = -1, 0, +1)."""
    tol = 1e-9 * system.mass * max(system.g, abs(system.gamma), 1e-12)
    s = np.where(system.mu > 0, np.asarray(record.s, int), 0)
    return np.where(np.asarray(record.R) > tol, 2 + s, 0)


def compare_integrators(system: models.System, seed: int | None = 1,
                        hs: tuple[float, ...] = (1e-3, 5e-4, 2.5e-4), T: float | None = None,
                        t_max: float = 60.0, event_options: dict | None = None,
                        step_options: dict | None = None, progress=None,
                        phases: int = 1) -> Comparison:
    """Run both integrators from the same initial angular velocities and compare (module doc).

    T: the common time at which the angular velocities are compared (default: half the
    event-driven run's last event time, i.e. inside the transient). t_max bounds both runs.
    phases: the sup error over the steps, d_omega_max, is averaged over this many runs whose
    grids are shifted by j h / phases (each started from the exact event-driven state at that
    time). An event falls at a random place in its step, and the error it leaves is
    (t_{k+1} - t_event) |jump of omega'|: <= h |jump|, but its size under one halving of h
    depends on that phase; averaging over phases shows the first order cleanly.
    """
    if not (isinstance(phases, int) and phases >= 1):
        raise InvalidInput(f"phases must be an integer >= 1, got {phases!r}")
    if len(hs) < 2 or any(not (h > 0) for h in hs):
        raise InvalidInput(f"hs must hold at least two step sizes > 0, got {hs!r}")
    ed = models.simulate(system, seed=seed, t_max=t_max, **(event_options or {}))
    if not ed.records:
        raise NotApplicable(f"the event-driven run has no event ({ed.status}: {ed.message})")
    last = ed.last
    T = 0.5 * last.t if T is None else float(T)
    cmp = Comparison(system, seed, ed, row_modes(system, last).text(), T)
    labels_ed = state_labels(system, last)
    t_ed, om_ed, od_ed = ed.array("t"), ed.array("omega"), ed.array("omega_dot")

    def ed_omega(t: float) -> np.ndarray:
        k = max(int(np.searchsorted(t_ed, t, side="right")) - 1, 0)
        return om_ed[k] + od_ed[k] * (t - t_ed[k])

    for h in hs:
        snap: dict[str, np.ndarray] = {"max": np.zeros(1)}

        def capture(run, t, omega, h=h, snap=snap):
            if "omega" not in snap and t >= T - 0.5 * h:
                snap["omega"] = omega.copy()
                snap["t"] = np.array(t)
            gap = float(np.abs(omega - ed_omega(t)).max(initial=0.0))
            snap["max"][0] = max(snap["max"][0], gap)

        ts = moreau_jean(system, seed=seed, h=h, t_max=t_max, progress=capture,
                         **(step_options or {}))
        if not ts.records:
            raise NotApplicable(f"the time-stepping run (h = {h:g}) has no record ({ts.status})")
        sups = [float(snap["max"][0])]
        for j in range(1, phases):
            t0 = j * h / phases
            k0 = max(int(np.searchsorted(t_ed, t0, side="right")) - 1, 0)
            start = State(t0, ed_omega(t0), system.V0 + system.gamma * t0,
                          np.asarray(ed.records[k0].s, int).copy())
            other: dict[str, np.ndarray] = {"max": np.zeros(1)}
            moreau_jean(system, start, h=h, t_max=t_max,
                        progress=lambda run, t, om, other=other: other["max"].__setitem__(
                            0, max(other["max"][0], float(np.abs(om - ed_omega(t)).max()))),
                        **(step_options or {}))
            sups.append(float(other["max"][0]))
        rec = ts.last
        steady_pair = ed.status == "steady" and ts.status == "steady"
        d_omega = (float(np.abs(snap["omega"] - omega_at(ed, float(snap["t"]))).max())
                   if "omega" in snap else math.nan)
        cmp.rows.append(StepRow(
            h=h, run=ts, mu_g=rec.mu_g, modes=row_modes(system, rec).text(),
            d_mu_g=abs(rec.mu_g - last.mu_g),
            d_alpha=float(np.abs(rec.omega_dot - last.omega_dot).max()),
            d_states=int(np.sum(state_labels(system, rec) != labels_ed)),
            d_omega_T=d_omega, d_omega_max=float(np.mean(sups)),
            ts_in_event=event_check(system, rec) if steady_pair else None,
            ed_in_step=step_check(system, last, h) if steady_pair else None))
        if progress is not None:
            progress(cmp.rows[-1])
    return cmp


def format_comparison(cmp: Comparison) -> str:
    """The comparison as a text table (what `rigidlcp compare-integrators` prints)."""
    ed, sysm = cmp.event_run, cmp.system
    lat = sysm.lattice
    head = (f"{lat.title()}, mu_pp {sysm.mu_pp:g}, mu_plane {sysm.mu_plane:g}, "
            f"mu_wall {sysm.mu_wall:g}, gamma {sysm.gamma:g}, V0 {sysm.V0:g}, seed {cmp.seed}")
    lines = [head,
             f"event-driven: {ed.status} at t = {ed.last.t:.6g} after {ed.n_events} events; "
             f"mu_g = {ed.last.mu_g:.6f}" + (f"; first-row modes {cmp.modes}" if cmp.modes
                                               else ""),
             f"time-stepping (Moreau-Jean); omega compared at T = {cmp.T:.6g}",
             f"{'h':>9} {'status':>8} {'t_end':>9} {'mu_g':>10} {'modes':>12} "
             f"{'|dmu_g|':>9} {'max|dalpha|':>11} {'dstates':>7} {'|domega(T)|':>11} "
             f"{'sup|domega|':>11} {'TS in event':>12} {'ED in step':>11}"]
    for r in cmp.rows:
        def verdict(chk):
            if chk is None:
                return "-"
            return f"{'ok' if chk.valid else 'NO'} {chk.residual:.0e}"
        lines.append(f"{r.h:9.3g} {r.run.status[:8]:>8} {r.run.last.t:9.4g} {r.mu_g:10.6f} "
                     f"{r.modes:>12} {r.d_mu_g:9.2e} {r.d_alpha:11.3e} {r.d_states:7d} "
                     f"{r.d_omega_T:11.3e} {r.d_omega_max:11.3e} {verdict(r.ts_in_event):>12} "
                     f"{verdict(r.ed_in_step):>11}")
    for name, label in (("d_omega_max", "sup|domega|"), ("d_omega_T", "|domega(T)|"),
                        ("d_mu_g", "|dmu_g|"), ("d_alpha", "max|dalpha|")):
        lines.append(f"observed order of {label} (h halving): {cmp.order_text(name)}")
    return "\n".join(lines)


@dataclass
class SteadyPair:
    """Two steady states of one system (event-driven `ed`, time-stepping `ts`) examined as
    solutions of one event problem (see `examine_steady_states`)."""

    d_mu_g: float
    d_alpha: float
    differing: list[int]  # contacts whose T/NT or NS/S+/S- differ
    ts_in_event: LawCheck
    ed_in_step: LawCheck
    sum_R: tuple[float, float]  # (ed, ts)
    norm2: tuple[float, float]  # |lambda|^2 (ed, ts)
    raw_vs_ts: float  # max |dalpha| between lemke's own solution at ts's state and ts
    selected_vs_ed: float  # max |dalpha| between face-min-norm at ts's state and ed
    selected_mu_g: float
    ed_from_ts: Run  # the event-driven run restarted from ts's steady state
    ts_from_ed: Run  # the time-stepper restarted from ed's final state (t_max + 5)


def examine_steady_states(system: models.System, ed: Run, ts: Run, h: float) -> SteadyPair:
    """Is the disagreement of two steady states a matter of selection? At the time-stepper's
    steady configuration and states, the event LCP is solved by lemke (the solver's own
    vertex, select="none") and moved by the event-driven rule (`lcp.face.face_minimum_norm`:
    least sum R, then least |lambda|); each integrator is also restarted from the other's
    steady state."""
    from rigidlcp import lcp
    from rigidlcp.lcp.faces.face import face_minimum_norm
    from rigidlcp.models.observables import global_friction_coefficient

    E, T = ed.last, ts.last
    c = system.c
    state = State(T.t, np.asarray(T.omega, float).copy(), T.V,
                  np.where(system.mu > 0, np.asarray(T.s, int), 0))
    ep = event_problem(system, state)
    sol = lcp.solve(ep.lcp, "lemke")
    if sol.status != "solved":
        raise ValueError(f"lemke failed at the time-stepper's steady state: {sol.message}")
    least = np.zeros(ep.lcp.n)
    least[:c] = 1.0
    side = np.zeros(ep.lcp.n, bool)
    side[:c + ep.k] = True
    face = face_minimum_norm(ep.lcp, sol.z, ep.G, c=least, z_side=side)
    raw, sel = ep.unpack(sol.z), ep.unpack(face.z)
    ed_from_ts = models.simulate(system, state.copy(), t_max=T.t + 40.0)
    fin = ed.final if ed.final is not None else State(E.t, E.omega, E.V, E.s)
    ts_from_ed = moreau_jean(system, State(fin.t, fin.omega.copy(), fin.V, fin.s.copy()), h=h,
                             t_max=fin.t + 5.0)
    return SteadyPair(
        d_mu_g=abs(E.mu_g - T.mu_g), d_alpha=float(np.abs(E.omega_dot - T.omega_dot).max()),
        differing=np.flatnonzero(state_labels(system, E) != state_labels(system, T)).tolist(),
        ts_in_event=event_check(system, T), ed_in_step=step_check(system, E, h),
        sum_R=(float(E.R.sum()), float(T.R.sum())),
        norm2=(float(np.sum(E.R**2 + E.S**2)), float(np.sum(T.R**2 + T.S**2))),
        raw_vs_ts=float(np.abs(raw.omega_dot - T.omega_dot).max()),
        selected_vs_ed=float(np.abs(sel.omega_dot - E.omega_dot).max()),
        selected_mu_g=global_friction_coefficient(system, sel.S),
        ed_from_ts=ed_from_ts, ts_from_ed=ts_from_ed)


__all__ = ["LawCheck", "event_check", "step_check", "StepRow", "Comparison", "SteadyPair",
           "examine_steady_states",
           "compare_integrators", "format_comparison", "omega_at", "state_labels"]
