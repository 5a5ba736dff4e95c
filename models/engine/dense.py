"""The dense backend of the event loop: the event LCP of models.event solved by any `lcp` method.

Per event (models/engine/loop.py owns the loop and its stop rules): the LCP of Eq. (2.7)
(models.event.event_problem), solved by `method` ("pivoting" warm-started from the previous
event's contact states), the `fallback` method where it fails, then — when the event's solution
is not unique (hyperstatic rows, loops of non-sliding contacts, Sec. III) — a canonical point of
the solution set (`select`, see `DenseBackend`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rigidlcp import lcp
from rigidlcp.lcp.faces.face import face_minimum_norm, global_minimum_norm
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.event import (
    EventProblem,
    EventSolution,
    State,
    acceleration_tol,
    event_problem,
)
from rigidlcp.models.selection import Selection, select
from rigidlcp.models.system import System

from .loop import Outcome, regime_left

#: How an event's particular solution is chosen when it is not unique (see `DenseBackend`;
#: "random" is given with its seed, "random:SEED"; models/selection.py).
SELECT = ("face-min-norm", "max-sum-R", "random", "global", "none")


@dataclass
class DenseBackend:
    """Solve each event's dense LCP (models/engine/loop.py's `Backend`).

    method: any `lcp` method; "pivoting" is warm-started from the previous event's contact states
    when warm_start is true. fallback: the method used where `method` fails (None: stop).

    select: "face-min-norm" (default) replaces the solver's solution by a canonical point of its
    face (`lcp.face.face_minimum_norm`): the least total normal force sum R, and among those the
    least |lambda|, so that the result does not depend on which point a method happened to
    return (docs/theory.md, "Non-unique events"). The face walk is local: "global" minimizes
    sum R over every solution of the event (a mixed-integer program, slower). "none" keeps the
    solver's solution. "max-sum-R[:CAP]" (the other end: the largest sum R) and "random:SEED" (a
    seeded random point of the face) are the other rules of models/selection.py, for ensembles
    over rules; their points are checked like the solver's (residual <= check_tol x scale, else
    the face-min-norm point is kept). dump_dir: write every event's LCP to DIR/event_NNNNNN.npz.

    closed_search: when the selected point would open a contact or translate a disk (the loop's
    stop rules, `leaves_regime`), the event's solution of least sum R with every contact closed
    is followed instead, or its absence proved (models/engine/closed.py; the verdict goes in the
    Outcome's note, the events followed in `closed_events`).
    """

    system: System
    dyn: Dynamics
    method: str = "lemke"
    fallback: str | None = "lemke"
    select: str = "face-min-norm"
    warm_start: bool = True
    dump_dir: str | None = None
    check_tol: float = 1e-8  # the loop's acceptance; only accepted solutions are selected among
    closed_search: bool = True
    info: dict | None = None
    _prev: EventSolution | None = field(default=None, repr=False)
    _events: int = field(default=0, repr=False)
    _rule: Selection | None = field(default=None, repr=False)
    _rng: np.random.Generator | None = field(default=None, repr=False)
    #: events where the rule's face was unbounded in sum R (the cap applied) / where the rule's
    #: point failed the acceptance test (the face-min-norm point was kept)
    capped: int = field(default=0, repr=False)
    rejected: int = field(default=0, repr=False)
    #: events (indices) where the selected solution would open a contact or translate a disk
    #: and a solution keeping every contact closed was followed instead (models/engine/closed.py)
    closed_events: list = field(default_factory=list, repr=False)
    closed_searched: int = field(default=0, repr=False)  # events where the search ran

    def __post_init__(self) -> None:
        self._rule = Selection.parse(self.select)  # InvalidSelection (a ValueError) naming RULES
        self._rng = self._rule.rng()  # "random:SEED": one generator per run
        for name in (self.method, self.fallback):
            if name is not None:
                lcp.get_method(name)  # raises InvalidProblem naming the available methods

    def solve(self, state: State) -> Outcome:
        ep = event_problem(self.system, state, self.dyn)
        sol, fell_back = self._solve_lcp(ep, state)
        if self.dump_dir is not None:
            ep.lcp.save(f"{self.dump_dir}/event_{self._events:06d}.npz")
        self._events += 1
        scale = max(np.abs(ep.lcp.q).max(initial=0.0), self.system.mass * self.system.g, 1e-300)
        if sol.status != "solved":
            contacts = contacts_of_ray(ep, sol)
            return Outcome(
                "no_solution" if sol.status in ("ray", "infeasible") else "solver_failed",
                self.method, f"{self.method} ended with status {sol.status!r} "
                f"({sol.message or 'no message'}); contacts involved: {contacts}", contacts)
        z, residual = sol.z, sol.residual
        if self.select != "none" and residual <= self.check_tol * scale:  # accepted points only
            z, residual = self._select(ep, z, residual)
            if self._rule.rule in ("max-sum-R", "random"):
                z, residual = self._other_rule(ep, z, residual, scale)
        es = ep.unpack(z)
        note = ""
        if self.closed_search and residual <= self.check_tol * scale and leaves_regime(
                ep, es, residual):
            self.closed_searched += 1
            from .closed import closed_solution  # scipy.optimize only when a run would stop

            found = closed_solution(ep, scale, self.check_tol)
            note = found.message
            if found.status == "found":  # checked again by the engine's own acceptance
                r = lcp.complementarity_residual(found.z, ep.lcp.M @ found.z + ep.lcp.q)
                closed = ep.unpack(found.z)
                if r <= self.check_tol * scale and not leaves_regime(ep, closed, r):
                    self.closed_events.append(self._events - 1)
                    z, residual, es = found.z, r, closed
                else:
                    note = (f"undecided: the closed solution found fails the engine's check "
                            f"(residual {r:.3g}, max a_n {closed.a_n.max(initial=0):.3g})")
        self._prev = es
        return Outcome("solved", sol.method, R=es.R, S=es.S, omega_dot=es.omega_dot,
                       a_n=es.a_n, a_t=es.a_t, residual=residual, scale=scale,
                       iterations=sol.iterations, n_lcp=z.size, fallback=fell_back, note=note)

    def _solve_lcp(self, ep: EventProblem, state: State) -> tuple[lcp.Solution, bool]:
        options = {}
        if self.method == "pivoting" and self.warm_start and self._prev is not None:
            options["active"] = warm_active_set(ep, self._prev, state)
        sol = lcp.solve(ep.lcp, method=self.method, **options)
        if sol.status == "solved" or self.fallback is None or self.fallback == self.method:
            return sol, False
        first = sol
        sol = lcp.solve(ep.lcp, method=self.fallback)
        if sol.status != "solved":
            sol.message = f"{self.method}: {first.status}; {self.fallback}: {sol.message}"
        return sol, True

    def _select(self, ep: EventProblem, z: np.ndarray, residual: float
                ) -> tuple[np.ndarray, float]:
        """The canonical point of the solution set (see the class doc); z unchanged when the
        selection does not apply."""
        c = self.system.c
        least_force = np.zeros(ep.lcp.n)
        least_force[:c] = 1.0  # sum of R over the contacts: z = [R, tau, a_minus]
        # Degenerate pairs open the way that keeps contacts closed and candidates non-sliding:
        # R (a_n = 0), tau (a_plus = 0, S inside the cone), but not a_minus (a_minus = 0).
        stick_side = np.zeros(ep.lcp.n, bool)
        stick_side[: c + ep.k] = True
        face = global_selection(ep, z, least_force) if self._rule.rule == "global" else None
        if face is None or face.status.startswith("failed"):
            face = face_minimum_norm(ep.lcp, z, ep.G, c=least_force, z_side=stick_side)
        if not face.status.startswith("selected"):
            return z, residual
        return face.z, lcp.complementarity_residual(face.z, ep.lcp.M @ face.z + ep.lcp.q)


    def _other_rule(self, ep: EventProblem, z0: np.ndarray, r0: float, scale: float
                    ) -> tuple[np.ndarray, float]:
        """The point of "max-sum-R" / "random" from the face-min-norm point z0 (models.selection),
        kept only if it passes the acceptance test the solver's point passed."""
        stick_side = np.zeros(ep.lcp.n, bool)
        stick_side[: self.system.c + ep.k] = True
        y, status = select(ep.lcp, z0, ep.G, self.system.c, stick_side, self._rule, self._rng)
        if status.startswith("failed"):
            self.rejected += 1
            return z0, r0
        r = lcp.complementarity_residual(y, ep.lcp.M @ y + ep.lcp.q)
        if r > self.check_tol * scale:
            self.rejected += 1
            return z0, r0
        self.capped += status == "capped"
        return y, r


def leaves_regime(ep: EventProblem, es: EventSolution, residual: float) -> bool:
    """Whether the solution es would stop the run (models/engine/loop.py's `_detached` and
    `_translating`, same thresholds): a contact opens, or a disk translates."""
    return regime_left(ep.system, es.a_n, es.trans_acc, residual)


def closed_note(backend, run):
    """Say in run.closed and run.message at which events a closed solution was followed
    instead of a selected one that would have opened a contact (models/engine/closed.py; the
    dense and the sparse backends)."""
    if getattr(backend, "closed_events", None) is not None:
        run.closed = {"search": backend.closed_search, "searched": backend.closed_searched,
                      "followed": list(backend.closed_events)}
        if backend.closed_events:
            ev = backend.closed_events
            shown = ", ".join(str(e) for e in ev[:10]) + (", ..." if len(ev) > 10 else "")
            run.message += (f"; at {len(ev)} event(s) ({shown}) the selected solution would "
                            "open a contact and one keeping every contact closed was followed")
    return run


def selection_note(backend, run):
    """Name a non-default selection rule in run.method and say in run.message at how many
    events its cap applied or its point was rejected (models/selection.py)."""
    if isinstance(backend, DenseBackend) and backend.select != "face-min-norm":
        run.method += f" (selection {backend.select})"
        notes = [f"{n} events {what}" for n, what in (
            (backend.capped, "at the cap of sum R (unbounded face)"),
            (backend.rejected, "kept the face-min-norm point (the rule's failed)")) if n]
        if notes:
            run.message += f"; selection {backend.select}: " + ", ".join(notes)
    return run


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
