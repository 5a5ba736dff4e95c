"""Event-driven evolution on the sparse path (issue 6): `simulate_sparse`.

The same evolution as models.engine.dense.simulate (Sec. II C, IV: exact event times, contact
states decided at every event, the same stop reasons and records), with each event solved by
models.sparse_event: warm-started pivoting on contact states with one sparse LU reused, by
row updates, across pivots and events. Nothing dense of size c is formed, so arrays of 10^4
disks fit.

Differences from the dense path, on purpose:

* no selection among the solutions of a non-unique event (the dense default is
  select="face-min-norm", a dense optimization): the pivoting returns a vertex of the solution
  set, as the dense path does with select="none". When an event's accelerations are unique
  (the usual case: hyperstatic rows make *forces* indeterminate, not accelerations) the
  trajectory does not depend on that choice; the forces may.
* when the pivoting fails at an event (a cycle, or no nonsingular flip), that event is solved
  by the dense `fallback` method when the event LCP has at most `fallback_max_n` unknowns;
  otherwise the run stops with "solver_failed".
* records="light" keeps only the scalars of each record (the array fields are empty) except
  for the last event, so that long runs of large arrays do not hold c-sized arrays per event.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable

import numpy as np

from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.event import State, acceleration_tol, initial_state
from rigidlcp.models.observables import dissipation_rate, global_friction
from rigidlcp.models.sparse_event import (
    NS,
    ActiveSystem,
    SingularSystem,
    StateFactor,
    sparse_delassus,
)
from rigidlcp.models.system import System

from .dense import EventRecord, Run, ZenoGuard, reaching_zero
from .sparse_pivoting import StateSolution, lcp_residual, solve_states

METHOD = "sparse-pivoting"
#: The pivoting's counters summed over a run in run.sparse_info.
COUNTERS = ("block_steps", "independent", "partial_blocks", "single_flips", "fallback_flips",
            "rescues", "factorizations")


def simulate_sparse(
    system: System,
    state: State | None = None,
    *,
    omega: np.ndarray | None = None,
    seed: int | None = None,
    t_max: float = np.inf,
    max_events: int = 100_000,
    check_tol: float = 1e-8,
    warm_start: bool = True,
    zeno_events: int = 200,
    zeno_time: float = 1e-6,
    progress: Callable[[Run], None] | None = None,
    records: str = "full",
    tol: float = 1e-10,
    max_updates: int = 400,
    fallback: str | None = "lemke",
    fallback_max_n: int = 3000,
    blas_threads: int | None = 1,
    event_hook: Callable[[int, float, StateSolution, ActiveSystem], None] | None = None,
) -> Run:
    """Evolve `system` event by event on the sparse path (see the module doc).

    Arguments as models.simulate, plus: records "full" or "light"; tol, max_updates: of the
    pivoting (models.sparse_event); fallback / fallback_max_n: the dense method for an event
    the pivoting fails on, and the largest LCP it is used for; event_hook(k, seconds, solution,
    active_system): called after event k, outside its timing (benchmarks use it to time a
    factorization of the event's final active system). The run's `sparse_info` holds the
    seconds of every event and the pivoting's counters.
    """
    kwargs = dict(locals())
    if records not in ("full", "light"):
        raise ValueError(f"records must be 'full' or 'light', got {records!r}")
    if blas_threads is None:
        return _simulate(**kwargs)
    from threadpoolctl import threadpool_limits

    with threadpool_limits(blas_threads):
        return _simulate(**kwargs)


def _simulate(system, state, *, omega, seed, t_max, max_events, check_tol, warm_start,
              zeno_events, zeno_time, progress, records, tol, max_updates, fallback,
              fallback_max_n, blas_threads, event_hook) -> Run:
    del blas_threads
    dyn = Dynamics(system)
    if state is None:
        state = initial_state(system, omega=omega, seed=seed)
    state = state.copy()
    c, mu = system.c, system.mu
    asys = ActiveSystem(sparse_delassus(dyn), dyn.q, mu)
    run = Run(system, method=METHOD)
    info = {"seconds": [], "iterations": [], "fallbacks": 0, **dict.fromkeys(COUNTERS, 0)}
    run.sparse_info = info
    tol_a = acceleration_tol(system)
    scale_v = max(np.abs(dyn.velocities(state.omega, state.V)).max(initial=0.0), 1e-300)
    zeno = ZenoGuard(zeno_events, zeno_time)
    factor: StateFactor | None = None
    prev_cand = np.zeros(c, dtype=bool)
    last_full: EventRecord | None = None
    start = _time.perf_counter()
    while True:
        t0 = _time.perf_counter()
        s_in = np.where(mu == 0, 0, np.asarray(state.s, dtype=int))
        cand = (s_in == 0) & (mu > 0)
        if factor is None:
            factor = StateFactor(asys, np.zeros(c, dtype=bool),
                                 np.where(cand, 1, s_in).astype(np.int8), max_updates)
            normal0, tang0 = cold_start(asys, s_in, cand)
        elif warm_start:
            # the previous event's final states; a contact that has just stopped is guessed
            # non-sliding (NS), a candidate that stays one keeps its state
            normal0 = factor.normal.copy()
            tang0 = np.where(cand, np.where(prev_cand, factor.tang, NS), s_in).astype(np.int8)
        else:
            normal0, tang0 = cold_start(asys, s_in, cand)
        sol = solve_states(factor, cand, normal0, tang0, tol=tol)
        for key in COUNTERS:
            info[key] += sol.info.get(key, 0)
        fell_back = False
        n_lcp = c + 2 * int(cand.sum())
        if sol.status != "solved" and fallback is not None and n_lcp <= fallback_max_n:
            sol = _dense_fallback(system, state, dyn, asys, cand, fallback, sol)
            fell_back = True
            info["fallbacks"] += 1
            if sol.status == "solved":
                try:  # the next event starts from the fallback's states when it can
                    factor.set_states(sol.normal, sol.tang)
                except SingularSystem:
                    pass
        prev_cand = cand
        q_lcp = np.concatenate([asys.q[:c], asys.q[c:][cand]])
        scale = max(float(np.abs(q_lcp).max(initial=0.0)), system.mass * system.g, 1e-300)
        if sol.status != "solved":
            run.status = "solver_failed"
            run.message = (f"t = {state.t:.6g}: {METHOD} ended with status {sol.status!r} "
                           f"({sol.message or 'no message'})")
            break
        if sol.residual > check_tol * scale:
            run.status = "solver_failed"
            run.message = (f"t = {state.t:.6g}: {METHOD} returned residual "
                           f"{sol.residual:.3g} > {check_tol:g} x scale {scale:.3g}")
            break
        lam = np.concatenate([sol.R, sol.S])
        nu_dot = dyn.accelerations(lam)
        a = dyn.H @ nu_dot + dyn.u_obs_dot
        at, an = a[c:], a[:c]
        new_s = s_in.copy()
        new_s[cand] = np.where(at[cand] > tol_a, 1, np.where(at[cand] < -tol_a, -1, 0))
        vt = dyn.velocities(state.omega, state.V)[c:]
        rec = EventRecord(
            t=state.t, V=state.V, omega=state.omega.copy(), omega_dot=nu_dot[2 * system.p:],
            R=sol.R, S=sol.S, s=new_s, s_in=s_in, vt=vt, at=at.copy(),
            mu_g=global_friction(system, sol.S) / (system.total_mass * system.g or 1.0),
            dissipation=dissipation_rate(sol.S, vt), iterations=int(sol.iterations),
            residual=float(sol.residual), n_lcp=n_lcp, method=METHOD, fallback=fell_back)
        last_full = rec
        run.records.append(rec if records == "full" else _light(rec))
        elapsed = _time.perf_counter() - t0
        info["seconds"].append(elapsed)
        info["iterations"].append(int(sol.iterations))
        if event_hook is not None:
            event_hook(run.n_events - 1, elapsed, sol, asys)
        opening = np.flatnonzero(an > max(tol_a, 10 * sol.residual))
        if opening.size:
            run.status = "detachment"
            run.contacts = opening.tolist()
            names = "; ".join(f"{system.lattice.label(k)} (a_n = {an[k]:.3g})"
                              for k in opening[:5])
            run.message = (f"t = {state.t:.6g}: contact(s) would open, the no-displacement "
                           f"regime ends: {names}")
            break
        closing = (new_s != 0) & (new_s * at < -tol_a)
        dt_all = np.full(c, np.inf)
        dt_all[closing] = np.abs(vt[closing]) / np.abs(at[closing])
        dt = dt_all.min(initial=np.inf)
        if not np.isfinite(dt):
            run.status, run.message = "steady", f"steady state at t = {state.t:.6g}"
            break
        omega_dot = nu_dot[2 * system.p:]
        if state.t + dt > t_max:
            state = _advance(state, omega_dot, new_s, t_max - state.t, system)
            run.status, run.message = "time_limit", f"t_max = {t_max:g} reached"
            break
        if run.n_events >= max_events:
            run.status, run.message = "event_limit", f"{max_events} events"
            break
        new_state = _advance(state, omega_dot, new_s, dt, system)
        vt_new = dyn.velocities(new_state.omega, new_state.V)[c:]
        new_state.s = np.where(reaching_zero(closing, dt_all, dt, vt_new, scale_v), 0, new_s)
        message = zeno.add(new_state.t)
        if message:
            run.status, run.message = "zeno", message
            break
        state = new_state
        if progress is not None:
            progress(run)
    if records == "light" and run.records and last_full is not None:
        run.records[-1] = last_full
    run.final = state
    run.wall_time = _time.perf_counter() - start
    return run


def cold_start(asys: ActiveSystem, s_in: np.ndarray, cand: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """States to start an event from without a previous event: T wherever the free relative
    acceleration does not separate the contact (q_n <= 0: gravity closes the vertical and
    horizontal contacts alike), and candidates sliding the way they are driven (sgn q_t; NS
    everywhere would over-constrain the rotations)."""
    c = asys.c
    scale = float(np.abs(asys.q).max(initial=0.0)) or 1.0
    normal = asys.q[:c] <= 1e-12 * scale
    tang = np.where(cand, np.where(asys.q[c:] < 0, -1, 1), s_in).astype(np.int8)
    return normal, tang


def _advance(state: State, omega_dot: np.ndarray, s: np.ndarray, dt: float,
             system: System) -> State:
    return State(state.t + dt, state.omega + omega_dot * dt, state.V + system.gamma * dt,
                 s.copy())


def _light(rec: EventRecord) -> EventRecord:
    empty = np.zeros(0)
    return EventRecord(t=rec.t, V=rec.V, omega=empty, omega_dot=empty, R=empty, S=empty,
                       s=np.zeros(0, dtype=int), s_in=np.zeros(0, dtype=int), vt=empty,
                       at=empty, mu_g=rec.mu_g, dissipation=rec.dissipation,
                       iterations=rec.iterations, residual=rec.residual, n_lcp=rec.n_lcp,
                       method=rec.method, fallback=rec.fallback)


def _dense_fallback(system, state, dyn, asys, cand, method, failed) -> StateSolution:
    """Solve the event's dense LCP by `method`; the states are read off the solution."""
    from rigidlcp import lcp
    from rigidlcp.models.event import event_problem

    ep = event_problem(system, State(state.t, state.omega, state.V,
                                     np.where(cand, 0, state.s)), dyn)
    sol = lcp.solve(ep.lcp, method=method)
    if sol.status != "solved":
        failed.message += f"; dense {method}: {sol.status} ({sol.message})"
        return failed
    c = system.c
    lam = ep.G @ sol.z
    a = asys.W @ lam + asys.q
    k = ep.k
    tang = failed.tang.copy()
    tau, a_minus = sol.z[c:c + k], sol.z[c + k:]
    tang[ep.candidates] = np.where(a_minus > 0, -1, np.where(tau > 0, NS, 1))
    normal = lam[:c] > 0
    return StateSolution(lam[:c], lam[c:], a, normal, tang, "solved", sol.iterations,
                         lcp_residual(lam, a, asys.mu, tang, cand),
                         f"dense {method} after: {failed.message}", {"fallback": method})
