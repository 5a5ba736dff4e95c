"""The sparse backend of the event loop (issue 6): `SparseBackend`, and `simulate_sparse`.

The same evolution as the dense backend (the one loop of models/engine/loop.py: exact event
times, contact states decided at every event, the same stop reasons and records), with each
event solved by models.sparse_event: warm-started pivoting on contact states with one sparse LU
reused, by row updates, across pivots and events. Nothing dense of size c is formed, so arrays
of 10^4 disks fit.

Differences from the dense path, on purpose:

* no selection among the solutions of a non-unique event (the dense default is
  select="face-min-norm", a dense optimization): the pivoting returns a vertex of the
  solution set, as the dense path does with select="none". When an event's accelerations are
  unique (the usual case: hyperstatic rows make *forces* indeterminate, not accelerations) the
  trajectory does not depend on that choice; the forces may.
* when the pivoting fails at an event (a cycle, or no nonsingular flip), that event is solved by
  the dense `fallback` method when the event LCP has at most `fallback_max_n` unknowns;
  otherwise the run stops with "solver_failed".
* records="light" (an option of the loop) keeps only the scalars of each record except the last,
  so that long runs of large arrays do not hold c-sized arrays per event.

As the dense path, when an event's solution would open a contact or translate a disk, the
closed-solution search (closed_search, on by default) looks for a solution of the same event
keeping every contact closed, on the event LCP assembled in sparse form
(models/engine/sparse_closed.py), follows it or proves there is none; `closed_events` and
the verdict in the run's message as for the dense backend. A run that never detaches is the
same with it on or off.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from rigidlcp import lcp
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.event import State, initial_state
from rigidlcp.models.sparse_event import (
    NS,
    ActiveSystem,
    SingularSystem,
    StateFactor,
    sparse_delassus,
)
from rigidlcp.models.system import System

from .loop import Limits, Outcome, blas_limit, regime_left, run_events
from .records import Run
from .sparse_pivoting import StateSolution, lcp_residual, solve_states

METHOD = "sparse-pivoting"
#: The pivoting's counters summed over a run in run.sparse_info.
COUNTERS = ("block_steps", "independent", "partial_blocks", "single_flips", "fallback_flips",
            "rescues", "factorizations", "component_steps", "stall_rescues", "flips")


@dataclass
class SparseBackend:
    """Solve each event by warm-started pivoting on contact states (models/engine/loop.py's
    `Backend`; see the module doc). tol, max_updates: of the pivoting (models.sparse_event);
    fallback / fallback_max_n: the dense method for an event the pivoting fails on, and the
    largest LCP it is used for; event_hook(k, seconds, solution, active_system): called after
    event k, outside its timing (benchmarks time a factorization of the final active system).
    `info` holds the seconds and iterations of every event and the pivoting's counters."""

    system: System
    dyn: Dynamics
    warm_start: bool = True
    tol: float = 1e-10
    max_updates: int = 400
    fallback: str | None = "lemke"
    fallback_max_n: int = 3000
    event_hook: Callable[[int, float, StateSolution, ActiveSystem], None] | None = None
    method: str = METHOD
    info: dict = field(default_factory=lambda: {"seconds": [], "iterations": [], "fallbacks": 0,
                                                **dict.fromkeys(COUNTERS, 0)})
    check_tol: float = 1e-8  # the loop's acceptance, also of a closed solution followed
    closed_search: bool = True
    #: events (indices) where a solution keeping every contact closed was followed instead of
    #: the pivoting's, which would have opened one; events where the search ran
    closed_events: list = field(default_factory=list)
    closed_searched: int = 0

    def __post_init__(self) -> None:
        self.asys = ActiveSystem(sparse_delassus(self.dyn), self.dyn.q, self.system.mu)
        self.factor: StateFactor | None = None
        self.prev_cand = np.zeros(self.system.c, dtype=bool)

    def solve(self, state: State) -> Outcome:
        t0 = _time.perf_counter()
        c, mu, asys = self.system.c, self.system.mu, self.asys
        s_in = np.where(mu == 0, 0, np.asarray(state.s, dtype=int))
        cand = (s_in == 0) & (mu > 0)
        normal0, tang0 = self._start(s_in, cand)
        sol = solve_states(self.factor, cand, normal0, tang0, tol=self.tol)
        for key in COUNTERS:
            self.info[key] += sol.info.get(key, 0)
        n_lcp = c + 2 * int(cand.sum())
        fell_back = sol.status != "solved" and self.fallback is not None \
            and n_lcp <= self.fallback_max_n
        if fell_back:
            sol = self._fall_back(state, cand, sol)
        self.prev_cand = cand
        q_lcp = np.concatenate([asys.q[:c], asys.q[c:][cand]])
        scale = max(float(np.abs(q_lcp).max(initial=0.0)), self.system.mass * self.system.g,
                    1e-300)
        if sol.status != "solved":
            return Outcome("solver_failed", METHOD, f"{METHOD} ended with status "
                           f"{sol.status!r} ({sol.message or 'no message'})")
        lam = np.concatenate([sol.R, sol.S])
        nu_dot = self.dyn.accelerations(lam)
        a = self.dyn.H @ nu_dot + self.dyn.u_obs_dot
        residual, note = float(sol.residual), ""
        p = self.system.p
        if self.closed_search and residual <= self.check_tol * scale and regime_left(
                self.system, a[:c], nu_dot[:2 * p], residual):
            lam, nu_dot, a, residual, note = self._closed(state, sol, scale, lam, nu_dot, a,
                                                          residual)
        elapsed = _time.perf_counter() - t0
        self.info["seconds"].append(elapsed)
        self.info["iterations"].append(int(sol.iterations))
        if self.event_hook is not None:
            self.event_hook(len(self.info["seconds"]) - 1, elapsed, sol, asys)
        return Outcome("solved", METHOD, R=lam[:c], S=lam[c:], omega_dot=nu_dot[2 * p:],
                       a_n=a[:c], a_t=a[c:], residual=residual, scale=scale,
                       iterations=int(sol.iterations), n_lcp=n_lcp, fallback=fell_back,
                       note=note)

    def _closed(self, state: State, sol: StateSolution, scale: float, lam, nu_dot, a,
                residual):
        """The closed-solution search at this event (module doc): the closed solution's
        (lambda, nu', a, residual, verdict) when one is found and passes the engine's own
        acceptance, else the pivoting's with the verdict."""
        from .sparse_closed import closed_event, states_of

        self.closed_searched += 1
        c, p = self.system.c, self.system.p
        found, sc = closed_event(self.system, state, self.dyn, scale, self.check_tol)
        if found.status != "found":
            return lam, nu_dot, a, residual, found.message
        z = found.z
        r = float(lcp.complementarity_residual(z, sc.problem.M @ z + sc.problem.q))
        lam2 = sc.G @ z
        nu2 = self.dyn.accelerations(lam2)
        a2 = self.dyn.H @ nu2 + self.dyn.u_obs_dot
        if r > self.check_tol * scale or regime_left(self.system, a2[:c], nu2[:2 * p], r):
            return lam, nu_dot, a, residual, (
                f"undecided: the closed solution found fails the engine's check (residual "
                f"{r:.3g}, max a_n {a2[:c].max(initial=0):.3g})")
        self.closed_events.append(len(self.info["seconds"]))
        try:  # the next event starts from the closed solution's states when it can
            self.factor.set_states(*states_of(sc, z, sol.tang, c))
        except SingularSystem:
            pass
        return lam2, nu2, a2, r, found.message

    def _start(self, s_in: np.ndarray, cand: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The states the pivoting starts from: `cold_start` at the first event (where the
        sparse LU of the active system is made, to be kept and updated after) or without warm
        start; else the previous event's final states (a contact that has just stopped is
        guessed non-sliding, a candidate that stays one keeps its state)."""
        if self.factor is None:
            self.factor = StateFactor(self.asys, np.zeros(self.system.c, dtype=bool),
                                      np.where(cand, 1, s_in).astype(np.int8), self.max_updates)
            return cold_start(self.asys, s_in, cand)
        if not self.warm_start:
            return cold_start(self.asys, s_in, cand)
        tang0 = np.where(cand, np.where(self.prev_cand, self.factor.tang, NS), s_in)
        return self.factor.normal.copy(), tang0.astype(np.int8)

    def _fall_back(self, state: State, cand: np.ndarray, failed: StateSolution
                   ) -> StateSolution:
        self.info["fallbacks"] += 1
        sol = _dense_fallback(self.system, state, self.dyn, self.asys, cand, self.fallback,
                              failed)
        if sol.status == "solved":
            try:  # the next event starts from the fallback's states when it can
                self.factor.set_states(sol.normal, sol.tang)
            except SingularSystem:
                pass
        return sol


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
    closed_search: bool = True,
) -> Run:
    """Evolve `system` event by event on the sparse path (see the module doc and
    `SparseBackend` for the options; the others as models.simulate). The run's `sparse_info`
    holds the seconds of every event and the pivoting's counters; run.closed the
    closed-solution search's events (as models.simulate's)."""
    if state is None:
        state = initial_state(system, omega=omega, seed=seed)
    backend = SparseBackend(system, Dynamics(system), warm_start=warm_start, tol=tol,
                            max_updates=max_updates, fallback=fallback,
                            fallback_max_n=fallback_max_n, event_hook=event_hook,
                            check_tol=check_tol, closed_search=bool(closed_search))
    limits = Limits(t_max, max_events, check_tol, zeno_events, zeno_time)
    with blas_limit(blas_threads):
        run = run_events(system, state, backend, limits, progress, records)
    from .dense import closed_note

    return closed_note(backend, run)


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
