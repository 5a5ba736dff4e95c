"""The event loop of the exact event-driven evolution (Sec. II C, Sec. IV): one loop, two backends.

Between two events the contact states, hence the forces and accelerations, are constant and every
angular velocity is linear in time (the geometry does not change: no particle displacement).
The next event is the earliest time at which a sliding contact's tangential velocity reaches
zero, t_k = t + |v_t| / |a_t| for the contacts with sgn(a_t) = -sgn(v_t): computed exactly, with
no time step. At the event that contact becomes a non-sliding candidate and the event's LCP
decides every contact's state anew.

`run_events` owns the stop rules; a backend (`Backend`: models/engine/dense.py or sparse.py)
only solves the event problem of a state and returns an `Outcome`. The run stops:

* "steady": no future event (every a_t has the sign of its v_t, or both are zero, Sec. IV A);
* "time_limit" / "event_limit": the limits given;
* "detachment": a contact would open (a_n > 0), or a disk would translate with its contacts
  closed (a mechanism of a packing): the no-displacement regime of the paper ends;
* "no_solution": the solver ends without a solution (e.g. a Lemke ray), contacts named;
* "zeno": events accumulate (more than `zeno_events` within `zeno_time`);
* "solver_failed": a solution whose residual exceeds `check_tol` (times the problem's scale).
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.event import State, acceleration_tol
from rigidlcp.models.observables import dissipation_rate, global_friction
from rigidlcp.models.system import System

from .records import EventRecord, Run


@dataclass(frozen=True)
class Limits:
    """The stop rules' parameters (see the module doc)."""

    t_max: float = np.inf
    max_events: int = 100_000
    check_tol: float = 1e-8
    zeno_events: int = 200
    zeno_time: float = 1e-6


@dataclass
class Outcome:
    """One event as a backend solved it, or why it could not (status other than "solved").

    R, S: the contact forces; omega_dot: angular accelerations; a_n, a_t: relative accelerations
    of every contact; residual: max|min(z, w)| of the event LCP, accepted when <= check_tol x
    scale; n_lcp: the LCP's size c + 2 k; fallback: solved by the fallback method.
    """

    status: str
    method: str
    message: str = ""
    contacts: list[int] = field(default_factory=list)
    R: np.ndarray | None = None
    S: np.ndarray | None = None
    omega_dot: np.ndarray | None = None
    a_n: np.ndarray | None = None
    a_t: np.ndarray | None = None
    residual: float = np.nan
    scale: float = 1.0
    iterations: int = 0
    n_lcp: int = 0
    fallback: bool = False
    note: str = ""  # the closed-solution search's verdict when it ran (models/engine/closed.py)


class Backend(Protocol):
    """Solves the event problem of a state (models/engine/dense.py, models/engine/sparse.py)."""

    method: str
    dyn: Dynamics
    info: dict | None  # counters kept over the run (Run.sparse_info), or None

    def solve(self, state: State) -> Outcome: ...


def run_events(system: System, state: State, backend: Backend, limits: Limits = Limits(),
               progress: Callable[[Run], None] | None = None, records: str = "full") -> Run:
    """Evolve `state` event by event with `backend` until a stop rule holds (module doc).

    records: "full", or "light" to keep only the scalars of each record but the last (long runs
    of large arrays)."""
    if records not in ("full", "light"):
        raise ValueError(f"records must be 'full' or 'light', got {records!r}")
    run = Run(system, method=backend.method, sparse_info=backend.info)
    clock = _Clock(system, backend.dyn, state, limits)
    state, last = state.copy(), None
    start = _time.perf_counter()
    while True:
        out = backend.solve(state)
        if _failed(run, state, out, limits.check_tol):
            break
        last = _record(system, backend.dyn, state, out, clock.tol_a)
        run.records.append(last if records == "full" else _light(last))
        if _detached(run, state, out, clock.tol_a) or _translating(run, state, out, backend.dyn,
                                                                 clock.tol_a):
            break
        state = clock.advance(run, state, last)
        if run.status != "running":
            break
        if progress:
            progress(run)
    if records == "light" and last is not None:
        run.records[-1] = last
    run.final = state
    run.wall_time = _time.perf_counter() - start
    return run


def blas_limit(threads: int | None) -> AbstractContextManager:
    """BLAS limited to `threads` threads while the context is open (None: left alone); used by
    both backends' entry points (simulate.py, sparse.py), hence here, below both."""
    if threads is None:
        return nullcontext()
    from threadpoolctl import threadpool_limits

    return threadpool_limits(threads)


def states_after(s_in: np.ndarray, mu: np.ndarray, a_t: np.ndarray, tol_a: float) -> np.ndarray:
    """Tangential states after an event (Eq. 2.7): sliding contacts keep sgn(v_t); a candidate
    (s = 0, mu > 0) slides with sgn(a_t) when |a_t| > tol_a, else stays non-sliding."""
    s = np.where(mu == 0, 0, np.asarray(s_in, dtype=int))
    cand = (s == 0) & (mu > 0)
    s[cand] = np.where(a_t[cand] > tol_a, 1, np.where(a_t[cand] < -tol_a, -1, 0))
    return s


def _failed(run: Run, state: State, out: Outcome, check_tol: float) -> bool:
    """Stop when the backend found no solution, or one whose residual is not accepted."""
    if out.status != "solved":
        run.status, run.contacts = out.status, list(out.contacts)
        run.message = f"t = {state.t:.6g}: {out.message}"
        return True
    if out.residual > check_tol * out.scale:
        run.status = "solver_failed"
        run.message = (f"t = {state.t:.6g}: {out.method} returned residual {out.residual:.3g} "
                       f"> {check_tol:g} x scale {out.scale:.3g}")
        return True
    return False


def _detached(run: Run, state: State, out: Outcome, tol_a: float) -> bool:
    """A contact would open (a_n > 0): the paper's no-displacement regime ends."""
    opening = np.flatnonzero(out.a_n > max(tol_a, 10 * out.residual))
    if not opening.size:
        return False
    run.status, run.contacts = "detachment", opening.tolist()
    names = "; ".join(f"{run.system.lattice.label(a)} (a_n = {out.a_n[a]:.3g})"
                      for a in opening[:5])
    run.message = (f"t = {state.t:.6g}: contact(s) would open, the no-displacement regime "
                   f"ends: {names}" + (f"; {out.note}" if out.note else ""))
    return True


#: A disk translates when its acceleration exceeds this many times the acceleration tolerance
#: (the arrays' runs keep |v'| below 1e-11 g: their contacts block every translation).
TRANSLATION_FACTOR = 100.0


def regime_left(system: System, a_n: np.ndarray, trans_acc: np.ndarray, residual: float
                ) -> bool:
    """Whether a solution with these a_n and translational accelerations (vx, vy rows) would
    stop the run (`_detached`, `_translating`, same thresholds): a contact opens, or a disk
    translates. Both backends' closed-solution searches start from it."""
    tol_a = acceleration_tol(system)
    if np.any(a_n > max(tol_a, 10 * residual)):
        return True
    size = np.hypot(*np.asarray(trans_acc).reshape(2, system.p))
    return bool(np.any(size > max(TRANSLATION_FACTOR * tol_a, 10 * residual)))


def _translating(run: Run, state: State, out: Outcome, dyn: Dynamics, tol_a: float) -> bool:
    """Every contact stays closed but a disk would translate (v' != 0): a mechanism of the
    packing (a disk or a cluster free to slide, e.g. a pile touching no wall pushed along the
    plane), which the arrays of the paper never have; the no-displacement regime ends too."""
    p = run.system.p
    v_dot = dyn.accelerations(np.concatenate([out.R, out.S]))[:2 * p].reshape(2, p)
    size = np.hypot(v_dot[0], v_dot[1])
    moving = np.flatnonzero(size > max(TRANSLATION_FACTOR * tol_a, 10 * out.residual))
    if not moving.size:
        return False
    run.status, run.contacts = "detachment", []
    names = "; ".join(f"disk {k} (|v'| = {size[k]:.3g})" for k in moving[:5])
    run.message = (f"t = {state.t:.6g}: disk(s) would translate with every contact closed, the "
                   f"no-displacement regime ends: {names}" + (f"; {out.note}" if out.note else ""))
    return True


def _record(system: System, dyn: Dynamics, state: State, out: Outcome,
            tol_a: float) -> EventRecord:
    c = system.c
    vt = dyn.velocities(state.omega, state.V)[c:]
    return EventRecord(
        t=state.t, V=state.V, omega=state.omega.copy(), omega_dot=out.omega_dot.copy(),
        R=out.R.copy(), S=out.S.copy(), s=states_after(state.s, system.mu, out.a_t, tol_a),
        s_in=np.asarray(state.s).copy(), vt=vt, at=out.a_t.copy(),
        mu_g=global_friction(system, out.S) / (system.total_mass * system.g or 1.0),
        dissipation=dissipation_rate(out.S, vt), iterations=int(out.iterations),
        residual=float(out.residual), n_lcp=int(out.n_lcp), method=out.method,
        fallback=out.fallback)


class _Clock:
    """The time stepping between events: next event time, limits, Zeno guard."""

    def __init__(self, system: System, dyn: Dynamics, state: State, limits: Limits):
        self.system, self.dyn, self.limits = system, dyn, limits
        self.tol_a = acceleration_tol(system)
        self.scale_v = max(np.abs(dyn.velocities(state.omega, state.V)).max(initial=0.0),
                           1e-300)
        self.zeno = ZenoGuard(limits.zeno_events, limits.zeno_time)

    def advance(self, run: Run, state: State, rec: EventRecord) -> State:
        """The state at the next event, or (with run.status set) the state the run ends in."""
        s, at, vt = rec.s, rec.at, rec.vt
        closing = (s != 0) & (s * at < -self.tol_a)  # a sliding contact driven to v_t = 0
        dt_all = np.full(s.size, np.inf)
        dt_all[closing] = np.abs(vt[closing]) / np.abs(at[closing])
        dt = dt_all.min(initial=np.inf)
        if not np.isfinite(dt):
            run.status, run.message = "steady", f"steady state at t = {state.t:.6g}"
            return state
        t_max = self.limits.t_max
        if state.t + dt > t_max:
            run.status, run.message = "time_limit", f"t_max = {t_max:g} reached"
            return _advance(state, rec, t_max - state.t, self.system)
        if run.n_events >= self.limits.max_events:
            run.status, run.message = "event_limit", f"{self.limits.max_events} events"
            return state
        new = _advance(state, rec, dt, self.system)
        vt_new = self.dyn.velocities(new.omega, new.V)[self.system.c:]
        new.s = np.where(reaching_zero(closing, dt_all, dt, vt_new, self.scale_v), 0, s)
        message = self.zeno.add(new.t)
        if message:
            run.status, run.message = "zeno", message
            return state
        return new


def _advance(state: State, rec: EventRecord, dt: float, system: System) -> State:
    """Angular velocities are linear in time between events; so is V."""
    return State(state.t + dt, state.omega + rec.omega_dot * dt, state.V + system.gamma * dt,
                 rec.s.copy())


def reaching_zero(closing: np.ndarray, dt_all: np.ndarray, dt: float, vt_new: np.ndarray,
                  scale_v: float) -> np.ndarray:
    """The closing contacts whose v_t reaches zero at the event (within rounding): they become
    non-sliding candidates together."""
    return closing & ((dt_all <= dt * (1 + 1e-9)) | (np.abs(vt_new) <= 1e-12 * scale_v))


class ZenoGuard:
    """Events accumulate when more than `events` of them fall within `window` time units."""

    def __init__(self, events: int, window: float):
        self.events, self.window, self.recent = events, window, []

    def add(self, t: float) -> str:
        """Record an event time; a message when events accumulate, else ''."""
        self.recent = [s for s in self.recent if t - s <= self.window] + [t]
        if len(self.recent) > self.events:
            return (f"{len(self.recent)} events within {self.window:g} time units before t = "
                    f"{t:.6g}: events accumulate")
        return ""


def _light(rec: EventRecord) -> EventRecord:
    empty = np.zeros(0)
    return EventRecord(t=rec.t, V=rec.V, omega=empty, omega_dot=empty, R=empty, S=empty,
                       s=np.zeros(0, dtype=int), s_in=np.zeros(0, dtype=int), vt=empty,
                       at=empty, mu_g=rec.mu_g, dissipation=rec.dissipation,
                       iterations=rec.iterations, residual=rec.residual, n_lcp=rec.n_lcp,
                       method=rec.method, fallback=rec.fallback)
