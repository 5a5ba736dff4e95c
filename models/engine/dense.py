"""Exact event-driven evolution (Sec. II C, Sec. IV).

Between two events the contact states, hence the forces and accelerations, are constant and every
angular velocity is linear in time (the geometry does not change: no particle displacement).
The next event is the earliest time at which a sliding contact's tangential velocity reaches
zero, t_k = t + |v_t| / |a_t| for the contacts with sgn(a_t) = -sgn(v_t): computed exactly, with
no time step. At the event that contact becomes a non-sliding candidate and the LCP of
models.event decides every contact's state anew. The run stops:

* "steady": no future event (every a_t has the sign of its v_t, or both are zero, Sec. IV A);
* "time_limit" / "event_limit": the limits given;
* "detachment": a contact would open (a_n > 0): the no-displacement regime of the paper ends;
* "no_solution": the solver ends without a solution (e.g. a Lemke ray), contacts named;
* "zeno": events accumulate (more than `zeno_events` within `zeno_time`);
* "solver_failed": a solution whose residual exceeds `check_tol`.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from rigidlcp import lcp
from rigidlcp.lcp.face import face_minimum_norm, global_minimum_norm
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.event import (
    EventProblem,
    EventSolution,
    State,
    acceleration_tol,
    event_problem,
    initial_state,
)
from rigidlcp.models.system import System

#: How an event's particular solution is chosen when it is not unique (see `simulate`).
SELECT = ("face-min-norm", "global", "none")

STOP_REASONS = ("steady", "time_limit", "event_limit", "detachment", "no_solution", "zeno",
                "solver_failed")


@dataclass
class EventRecord:
    """What is recorded at each event (values right after the event's LCP is solved)."""

    t: float
    V: float
    omega: np.ndarray
    omega_dot: np.ndarray
    R: np.ndarray
    S: np.ndarray
    s: np.ndarray  # tangential states after the event: +1/-1 sliding, 0 non-sliding
    s_in: np.ndarray  # the states the event started from (0: candidates), see Run.state_at
    vt: np.ndarray
    at: np.ndarray
    mu_g: float
    dissipation: float
    iterations: int
    residual: float
    n_lcp: int
    method: str
    fallback: bool = False


@dataclass
class Run:
    """A simulation: the system, one record per event, and why it stopped."""

    system: System
    records: list[EventRecord] = field(default_factory=list)
    status: str = "running"
    message: str = ""
    contacts: list[int] = field(default_factory=list)  # contacts named by the stop report
    wall_time: float = 0.0
    method: str = "lemke"
    final: State | None = None

    @property
    def steady(self) -> bool:
        return self.status == "steady"

    @property
    def n_events(self) -> int:
        return len(self.records)

    def array(self, name: str) -> np.ndarray:
        """Stack a record field over events, e.g. run.array('mu_g') or run.array('omega')."""
        return np.array([getattr(r, name) for r in self.records])

    def state_at(self, k: int) -> State:
        """The state from which event k was solved (to re-solve it with another method)."""
        rec = self.records[k]
        return State(rec.t, rec.omega.copy(), rec.V, rec.s_in.copy())

    @property
    def last(self) -> EventRecord:
        if not self.records:
            raise ValueError("the run has no event")
        return self.records[-1]

    def summary(self) -> dict:
        from rigidlcp.models.observables import state_counts

        out = {"status": self.status, "message": self.message, "events": self.n_events,
               "wall_time_s": round(self.wall_time, 4), "method": self.method}
        if self.records:
            last = self.last
            out.update(t=last.t, mu_g=last.mu_g, F_g=last.mu_g * self.system.total_mass
                       * self.system.g, dissipation=last.dissipation,
                       **state_counts(self.system, last))
        return out


def simulate(
    system: System,
    state: State | None = None,
    *,
    method: str = "lemke",
    omega: np.ndarray | None = None,
    seed: int | None = None,
    t_max: float = np.inf,
    max_events: int = 100_000,
    check_tol: float = 1e-8,
    warm_start: bool = True,
    zeno_events: int = 200,
    zeno_time: float = 1e-6,
    progress: Callable[[Run], None] | None = None,
    dump_dir: str | None = None,
    select: str = "face-min-norm",
    fallback: str | None = "lemke",
    blas_threads: int | None = 1,
) -> Run:
    """Evolve `system` from `state` (or from omega / a seed) event by event.

    method: any `lcp` method; "pivoting" is warm-started from the previous event's contact states
    when warm_start is true. Every solution's residual max|min(z, w)| must be <= check_tol (in
    units of the problem's scale), or the run stops with "solver_failed".

    select: "face-min-norm" (default) replaces the solver's solution by a canonical point of its
    face (`lcp.face.face_minimum_norm`): the least total normal force sum R, and among those the
    least |lambda|. When the event's solution is not unique (hyperstatic rows, loops of
    non-sliding contacts, Sec. III) this makes the result independent of which point a method
    happened to return (see docs/theory.md, "Non-unique events"). The face walk is local:
    "global" minimizes sum R over every solution of the event (a mixed-integer program, slower),
    which makes the run independent of the method and of the order of the unknowns.
    "none" keeps the solver's solution.

    fallback: when `method` fails at an event (no solution, cycling, iteration limit), that
    event is solved again by this method (None: stop); each use is counted in the record.
    blas_threads: BLAS threads during the run (the event problems are small dense matrices, for
    which one thread is fastest, and much faster on a loaded machine); None leaves BLAS alone.
    """
    if method == "sparse-pivoting":  # the sparse warm-started path (rigidlcp.models.engine.sparse)
        if select != "none":
            raise ValueError("method 'sparse-pivoting' keeps the pivoting's own solution: "
                             "use select='none'")
        if dump_dir is not None:
            raise ValueError("method 'sparse-pivoting' does not dump problems (dump_dir)")
        from .sparse import simulate_sparse

        return simulate_sparse(system, state, omega=omega, seed=seed, t_max=t_max,
                               max_events=max_events, check_tol=check_tol,
                               warm_start=warm_start, zeno_events=zeno_events,
                               zeno_time=zeno_time, progress=progress, fallback=fallback,
                               blas_threads=blas_threads)
    from contextlib import nullcontext

    from threadpoolctl import threadpool_limits

    with nullcontext() if blas_threads is None else threadpool_limits(blas_threads):
        return _simulate(system, state, method=method, omega=omega, seed=seed, t_max=t_max,
                         max_events=max_events, check_tol=check_tol, warm_start=warm_start,
                         zeno_events=zeno_events, zeno_time=zeno_time, progress=progress,
                         dump_dir=dump_dir, select=select, fallback=fallback)


def _simulate(system, state, *, method, omega, seed, t_max, max_events, check_tol, warm_start,
              zeno_events, zeno_time, progress, dump_dir, select, fallback) -> Run:
    if select not in SELECT:
        raise ValueError(f"select must be one of {SELECT}, got {select!r}")
    for name in (method, fallback):
        if name is not None:
            lcp.get_method(name)  # raises InvalidProblem naming the available methods
    dyn = Dynamics(system)
    if state is None:
        state = initial_state(system, omega=omega, seed=seed)
    state = state.copy()
    run = Run(system, method=method)
    c = system.c
    tol_a = acceleration_tol(system)
    scale_v = max(np.abs(dyn.velocities(state.omega, state.V)).max(initial=0.0), 1e-300)
    zeno = ZenoGuard(zeno_events, zeno_time)
    least_force = None
    prev: EventSolution | None = None
    start = _time.perf_counter()
    while True:
        ep = event_problem(system, state, dyn)
        if least_force is None or least_force.size != ep.lcp.n:
            least_force = np.zeros(ep.lcp.n)
            least_force[:c] = 1.0  # sum of R over the contacts: z = [R, tau, a_minus]
        # Degenerate pairs open the way that keeps contacts closed and candidates non-sliding:
        # R (a_n = 0), tau (a_plus = 0, S inside the cone), but not a_minus (a_minus = 0).
        stick_side = np.zeros(ep.lcp.n, bool)
        stick_side[: c + ep.k] = True
        options = {}
        if method == "pivoting" and warm_start and prev is not None:
            options["active"] = warm_active_set(ep, prev, state)
        sol = lcp.solve(ep.lcp, method=method, **options)
        fell_back = False
        if sol.status != "solved" and fallback is not None and fallback != method:
            first = sol
            sol = lcp.solve(ep.lcp, method=fallback)
            fell_back = True
            if sol.status != "solved":
                sol.message = f"{method}: {first.status}; {fallback}: {sol.message}"
        if dump_dir is not None:
            ep.lcp.save(f"{dump_dir}/event_{run.n_events:06d}.npz")
        scale = max(np.abs(ep.lcp.q).max(initial=0.0), system.mass * system.g, 1e-300)
        if sol.status != "solved":
            run.status = "no_solution" if sol.status in ("ray", "infeasible") else "solver_failed"
            run.contacts = contacts_of_ray(ep, sol)
            run.message = (
                f"t = {state.t:.6g}: {method} ended with status {sol.status!r} "
                f"({sol.message or 'no message'}); contacts involved: {run.contacts}"
            )
            break
        if sol.residual > check_tol * scale:
            run.status = "solver_failed"
            run.message = (
                f"t = {state.t:.6g}: {method} returned residual {sol.residual:.3g} > "
                f"{check_tol:g} x scale {scale:.3g}"
            )
            break
        z = sol.z
        if select != "none":
            face = (global_selection(ep, z, least_force) if select == "global" else None)
            if face is None or face.status.startswith("failed"):
                face = face_minimum_norm(ep.lcp, z, ep.G, c=least_force, z_side=stick_side)
            if face.status.startswith("selected"):
                z = face.z
                sol.residual = lcp.complementarity_residual(z, ep.lcp.M @ z + ep.lcp.q)
                if sol.residual > check_tol * scale:
                    run.status = "solver_failed"
                    run.message = (f"t = {state.t:.6g}: the face selection left residual "
                                   f"{sol.residual:.3g}")
                    break
        es = ep.unpack(z)
        vt = dyn.velocities(state.omega, state.V)[c:]
        run.records.append(_record(system, state, es, vt, sol, fell_back))
        opening = np.flatnonzero(es.a_n > max(tol_a, 10 * sol.residual))
        if opening.size:
            run.status = "detachment"
            run.contacts = opening.tolist()
            names = "; ".join(f"{system.lattice.label(a)} (a_n = {es.a_n[a]:.3g})"
                              for a in opening[:5])
            run.message = (
                f"t = {state.t:.6g}: contact(s) would open, the no-displacement regime ends: "
                f"{names}"
            )
            break
        prev = es
        # The next event: a sliding contact whose v_t is driven to zero.
        s = es.s
        vt_signed = np.where(s != 0, np.abs(vt), np.inf)
        closing = (s != 0) & (s * es.a_t < -tol_a)
        dt_all = np.full(c, np.inf)
        dt_all[closing] = vt_signed[closing] / np.abs(es.a_t[closing])
        dt = dt_all.min(initial=np.inf)
        if not np.isfinite(dt):
            run.status, run.message = "steady", f"steady state at t = {state.t:.6g}"
            break
        if state.t + dt > t_max:
            state = _advance(state, es, t_max - state.t, system)
            run.status, run.message = "time_limit", f"t_max = {t_max:g} reached"
            break
        if run.n_events >= max_events:
            run.status, run.message = "event_limit", f"{max_events} events"
            break
        new_state = _advance(state, es, dt, system)
        vt_new = dyn.velocities(new_state.omega, new_state.V)[c:]
        new_state.s = np.where(reaching_zero(closing, dt_all, dt, vt_new, scale_v), 0, s)
        message = zeno.add(new_state.t)
        if message:
            run.status, run.message = "zeno", message
            break
        state = new_state
        if progress is not None:
            progress(run)
    run.final = state
    run.wall_time = _time.perf_counter() - start
    return run


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


def _advance(state: State, es: EventSolution, dt: float, system: System) -> State:
    """Angular velocities are linear in time between events; so is V."""
    return State(state.t + dt, state.omega + es.omega_dot * dt, state.V + system.gamma * dt,
                 es.s.copy())


def _record(
    system: System, state: State, es: EventSolution, vt: np.ndarray, sol, fell_back: bool
) -> EventRecord:
    from rigidlcp.models.observables import dissipation_rate, global_friction

    return EventRecord(
        t=state.t, V=state.V, omega=state.omega.copy(), omega_dot=es.omega_dot.copy(),
        R=es.R.copy(), S=es.S.copy(), s=es.s.copy(), s_in=np.asarray(state.s).copy(),
        vt=vt.copy(), at=es.a_t.copy(),
        mu_g=global_friction(system, es.S) / (system.total_mass * system.g or 1.0),
        dissipation=dissipation_rate(es.S, vt), iterations=int(sol.iterations),
        residual=float(sol.residual), n_lcp=int(sol.z.size), method=sol.method,
        fallback=fell_back,
    )


def warm_active_set(ep: EventProblem, prev: EventSolution, state: State) -> np.ndarray:
    """Warm start for `pivoting` from the previous event's contact states.

    In z = [R, tau, a_minus]: R is basic on transmitting contacts; for a candidate tau is basic
    unless it slides with a_t > 0 (tau = 0), and a_minus is basic when it slides with a_t < 0.
    A contact that has just stopped is guessed non-sliding (tau basic).
    """
    c, k = ep.system.c, ep.k
    active = list(np.flatnonzero(prev.R > 0))
    for pos, alpha in enumerate(ep.candidates):
        was = prev.s[alpha] if state.s[alpha] == 0 else 0
        if was <= 0:
            active.append(c + pos)
        if was < 0:
            active.append(c + k + pos)
    return np.array(sorted(active), dtype=int)


def global_selection(ep: EventProblem, z: np.ndarray, least_force: np.ndarray):
    """`lcp.face.global_minimum_norm` with big-M bounds derived from the mechanics.

    With B = sum R of the solver's solution, the minimizer has every R <= B and
    |S| <= mu_max B, so tau <= 2 mu B, and |a_t| <= |q_t| + max_j |W_tj| (1 + mu_max) B.
    a_n = 0 is imposed on every contact (a solution with a_n > 0 is a detachment, which stops
    the run before selection matters); returns None when the solver's solution has a_n > 0.
    """
    system, dyn = ep.system, ep.dyn
    c = system.c
    w = ep.lcp.M @ z + ep.lcp.q
    if np.any(w[:c] > acceleration_tol(system)):
        return None
    B = max(float(z[:c].sum()), 1e-12)
    mu = system.mu[ep.candidates]
    mu_max = float(system.mu.max(initial=0.0))
    Wt = dyn.W[c:][ep.candidates]
    amax = np.abs(dyn.q[c:][ep.candidates]) + np.abs(Wt).max(axis=1, initial=0.0) * (
        1 + mu_max) * B
    amax = 2.0 * amax + 1e-12
    z_upper = np.concatenate([np.full(c, 2.0 * B), 4.0 * mu * B + 1e-12, amax])
    w_upper = np.concatenate([np.ones(c), 2.0 * amax, 4.0 * mu * B + 1e-12])
    return global_minimum_norm(ep.lcp, ep.G, least_force, z_upper, w_upper,
                               w_zero=np.arange(c))


def contacts_of_ray(ep: EventProblem, sol: lcp.Solution) -> list[int]:
    """Contacts whose variables carry the ray (or the last iterate) of a failed solve."""
    vec = sol.info.get("ray")
    vec = np.asarray(vec if vec is not None else sol.z, dtype=float).reshape(-1)[: ep.lcp.n]
    if vec.size < ep.lcp.n:
        return []
    c, k = ep.system.c, ep.k
    support = np.abs(vec) > 1e-12 * max(np.abs(vec).max(initial=0.0), 1e-300)
    alphas = set(np.flatnonzero(support[:c]).tolist())
    alphas |= set(ep.candidates[np.flatnonzero(support[c:c + k] | support[c + k:])].tolist())
    return sorted(int(a) for a in alphas)
