"""Moreau-Jean time-stepping (theta-method): a second integrator of the same systems.

The event-driven evolution (models.engine) is exact: it finds the next event analytically.
This module integrates the same systems with a fixed step h instead, as NSCD codes (Siconos,
LMGC90) do. It shares with the event loop the kinematics (models.dynamics: H, M, f, u_obs) and
the LCP solvers, and where a step's solution is not unique it follows the point of its
selection rule (models.selection; default "none": the solver's): agreement between the two is
a self-consistency check of this code, not an independent confirmation (docs/integrators.md).

The geometry does not change (the paper's regime, no particle displacement): every contact stays
closed and the step from t_k to t_{k+1} = t_k + h is, with impulses P = [P_n (c); P_t (c)]
(P = h lambda over the step):

    M (nu^{k+1} - nu^k) = h f_theta + H^T P,    f_theta = theta f(t_{k+1}) + (1 - theta) f(t_k),
    u^{k+1} = H nu^{k+1} + u_obs(V_{k+1}) = W P + b,    b = H (nu^k + h M^-1 f_theta)
                                                            + u_obs(V_{k+1}),

with W = H M^-1 H^T (Eqs. 2.13-2.14) and the contact laws at velocity level, on u^{k+1}:

* Signorini (velocity form of Eq. 2.5):  0 <= P_n  perp  u_n >= 0;
* exact 2D Coulomb (Eq. 2.6 at velocity level): u_t > 0 => P_t = -mu P_n, u_t < 0 =>
  P_t = +mu P_n, u_t = 0 => |P_t| <= mu P_n; frictionless contacts P_t = 0.

Coulomb is written as an LCP by splitting u_t = u_plus - u_minus with tau = mu P_n + P_t
(the derivation of docs/mechanics.md, with accelerations replaced by velocities):

    0 <= tau      perp  u_plus = u_t + u_minus >= 0,
    0 <= u_minus  perp  2 mu P_n - tau >= 0,

so z = [P_n (c), tau (k), u_minus (k)] over the k frictional contacts, w = [u_n, u_plus,
2 mu P_n - tau], and w = M z + q with a constant M (W and mu do not change) and q = the free
velocities b. The LCP is built here from W, independently of models.event.

f is constant (gravity and the box's inertial force), so f_theta = f for every theta in
[1/2, 1]: theta is accepted and recorded, and the result does not depend on it in this regime
(a test checks that). The time-stepper's "forces" are P / h, its angular accelerations
(omega^{k+1} - omega^k) / h.

Every step is solved by `lcp.solve` (warm-started "pivoting" from the previous step's basis when
warm_start, then `method`, then `fallback`) and checked: the Coulomb-law residual of the step,
computed from (P, u) directly (the natural map of Signorini and of Coulomb's law, scaled), is
recorded; a step whose residual exceeds check_tol, or that no solver solves, stops the run with
"solver_failed" / "no_solution" and a message naming t and the step: never skipped.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from rigidlcp import lcp

from .dynamics import Dynamics
from .engine.records import EventRecord, Run
from .event import State, initial_state
from .lattice import InvalidSystem
from .observables import dissipation_rate, global_friction
from .selection import Selection, select
from .step_lcp import StepProblem, coulomb_residual, solve_step
from .step_rules import leaving, step_failure, stop_reason
from .system import System


class InvalidStep(InvalidSystem):
    """Bad time-stepping options (h, theta, limits): the message names the option."""


@dataclass(frozen=True)
class StepOptions:
    """Options of `moreau_jean` (validated once, when built)."""

    h: float
    theta: float = 1.0
    method: str = "lemke"
    fallback: str | None = "pivoting"
    warm_start: bool = True
    check_tol: float = 1e-8
    steady_steps: int = 20
    record_every: int = 0
    max_steps: int = 2_000_000
    t_max: float = np.inf
    selection: str = "none"
    closed_search: bool = True

    def __post_init__(self) -> None:
        h = _number("h", self.h)
        if not (np.isfinite(h) and h > 0):
            raise InvalidStep(f"h must be a finite number > 0, got {self.h!r}")
        theta = _number("theta", self.theta)
        if not 0.5 <= theta <= 1.0:
            raise InvalidStep(f"theta must lie in [0.5, 1], got {self.theta!r}")
        tol = _number("check_tol", self.check_tol)
        if not (np.isfinite(tol) and tol > 0):
            raise InvalidStep(f"check_tol must be a finite number > 0, got {self.check_tol!r}")
        for name in ("steady_steps", "record_every", "max_steps"):
            v = getattr(self, name)
            if not isinstance(v, (int, np.integer)) or v < (1 if name != "record_every" else 0):
                raise InvalidStep(f"{name} must be an integer >= "
                                  f"{1 if name != 'record_every' else 0}, got {v!r}")
        t_max = _number("t_max", self.t_max)
        if not t_max > 0:
            raise InvalidStep(f"t_max must be > 0, got {self.t_max!r}")
        for name in (self.method, self.fallback):
            if name is not None:
                lcp.get_method(name)  # InvalidProblem naming the available methods
        rule = Selection.parse(self.selection)  # InvalidSelection naming the rules
        if rule.rule == "global":
            raise InvalidStep("selection 'global' is the event engine's (a MILP per event); a "
                              "step takes none, face-min-norm, max-sum-R[:CAP] or random:SEED")
        object.__setattr__(self, "h", h)
        object.__setattr__(self, "theta", theta)


def _number(name: str, value) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise InvalidStep(f"{name} must be a number, got {value!r}") from None


def moreau_jean(
    system: System,
    state: State | None = None,
    *,
    h: float,
    theta: float = 1.0,
    omega: np.ndarray | None = None,
    seed: int | None = None,
    progress: Callable[[Run, float, np.ndarray], None] | None = None,
    **options,
) -> Run:
    """Integrate `system` with Moreau-Jean steps of size h (theta-method) until a steady state.

    Returns a models.evolution.Run in the event-driven format (save_run / `rigidlcp plot` work):
    one EventRecord at every step whose contact states differ from the previous step's, every
    `record_every` steps (0: none), and at the last step. A record holds t = t_{k+1}, the
    velocities after the step (omega, V, vt = u_t^{k+1}), the step's mean forces R, S = P / h
    and angular accelerations (omega^{k+1} - omega^k) / h, the tangential states s (+1 / -1
    sliding with sgn u_t, 0 sticking: u_t = 0 to rounding) and s_in (the previous step's), the
    Coulomb-law residual (scaled, see `coulomb_residual`) and the LCP method that solved it.

    Stops: "steady" (states unchanged, angular accelerations unchanged to 1e-9 g / r and no
    sliding contact decelerating, for `steady_steps` steps: nothing can change any more),
    "time_limit", "event_limit" (max_steps), "detachment" (u_n > 0: the no-displacement regime
    ends), "no_solution" / "solver_failed" (a step no solver solves within check_tol).
    options: the fields of StepOptions (method, fallback, warm_start, check_tol, steady_steps,
    record_every, max_steps, t_max, selection, closed_search); bad values raise
    InvalidStep. selection: which
    solution of a step's LCP is followed where it has more than one (models/selection.py):
    "none" (default: the solver's, warm-started from the previous step), "face-min-norm",
    "max-sum-R[:CAP]" or "random:SEED" (sum of P_n in place of sum R); a selected point must
    pass the same Coulomb-law check as the solver's, else the solver's is kept. closed_search
    (default True): when a step's solution would open a contact or translate a disk, its
    solution of least sum P_n keeping every contact closed is followed, or its absence proved
    (models/step_closed.py; run.closed and the message say which, as for the event engine).
    progress(run, t, omega) is called after every step with the time and the angular
    velocities reached.
    """
    opts = StepOptions(h=h, theta=theta, **options)
    from threadpoolctl import threadpool_limits

    with threadpool_limits(1):  # small dense problems: one BLAS thread is fastest
        return _integrate(system, state, opts, omega, seed, progress)


def _integrate(system, state, opts, omega, seed, progress) -> Run:
    """The steps of `moreau_jean` (its docstring): solve (`_step`), record (`_record`), stop."""
    dyn = Dynamics(system)
    state = (initial_state(system, omega=omega, seed=seed) if state is None else state).copy()
    h, p = opts.h, system.p
    run = Run(system, method=f"moreau-jean h={h:g} theta={opts.theta:g} ({opts.method}"
              + (f", selection {opts.selection})" if opts.selection != "none" else ")"))
    k = _Stepper(system, dyn, opts, state)
    run.closed = {"search": opts.closed_search, "searched": 0, "followed": []}
    start = _time.perf_counter()
    for step in range(opts.max_steps):
        got = k.step()
        failure = step_failure(got, opts)
        if failure:
            run.status = failure[0]
            run.message = f"step {step} (t = {k.t:.6g} -> {k.t + h:.6g}): {failure[1]}"
            break
        opening, moving = leaving(got, system, h)
        note = ""
        if opts.closed_search and (opening.size or moving.size):
            got, note = k.closed(got, run.closed, step)
            opening, moving = leaving(got, system, h)
        rec, settled = k.record(got)
        k.quiet = k.quiet + 1 if settled else 0
        changed = not np.array_equal(rec.s, k.s_prev)
        if step == 0:  # the run's records start at its initial state (plots, dissipated
            # energy from t = state.t): the first step's forces, from the initial velocities
            run.records.append(replace(rec, t=k.t, V=k.V, omega=k.nu[2 * p:].copy(),
                                       vt=k.ut_prev.copy(),
                                       dissipation=dissipation_rate(rec.S, k.ut_prev)))
        k.advance(got, rec)
        last = (opening.size or moving.size or k.quiet >= opts.steady_steps or k.t >= opts.t_max
                or step + 1 == opts.max_steps)
        if changed or last or (opts.record_every and (step + 1) % opts.record_every == 0):
            run.records.append(rec)
        stop = stop_reason(k, opening, moving, opts, step)
        if stop:
            run.status, run.message = stop[0], stop[1] + (
                f"; {note}" if note and stop[0] == "detachment" else "")
            if opening.size:
                run.contacts = opening.tolist()
            break
        if progress is not None:
            progress(run, k.t, k.nu[2 * p:])
    else:
        run.status, run.message = "event_limit", f"{opts.max_steps} steps"
    run.final = State(k.t, k.nu[2 * p:].copy(), k.V, k.s_prev.copy())
    if run.closed["followed"]:
        ev = run.closed["followed"]
        run.message += (f"; at {len(ev)} step(s) ({', '.join(str(e) for e in ev[:10])}"
                        f"{', ...' if len(ev) > 10 else ''}) the step's solution would open a "
                        "contact and one keeping every contact closed was followed")
    run.wall_time = _time.perf_counter() - start
    return run


@dataclass
class _Step:
    """One step's solution: the LCP's answer, who produced it, and the impulses P, velocity
    change dnu, velocities u after the step and the Coulomb-law residual of the point kept."""

    sol: lcp.Solution
    used: str
    fell_back: bool
    sp: StepProblem | None
    P: np.ndarray | None
    dnu: np.ndarray | None
    u: np.ndarray | None
    res: float
    u_scale: float
    b: np.ndarray | None = None  # the free velocities of the step (its LCP's q)


class _Stepper:
    """The time-stepper's state between steps (velocities, previous states, impulses and
    tangential velocities, the steady counter) and its step problems (one per substituted
    sliding set, cached)."""

    def __init__(self, system, dyn: Dynamics, opts: StepOptions, state: State) -> None:
        self.system, self.dyn, self.opts = system, dyn, opts
        self.problems: dict[bytes, StepProblem] = {}
        h, c = opts.h, system.c
        self.nu = np.concatenate([np.zeros(2 * system.p), state.omega])
        self.t, self.V = state.t, state.V
        f_theta = opts.theta * dyn.f + (1.0 - opts.theta) * dyn.f  # f does not depend on t
        self.free_dnu = h * dyn.Minv * f_theta
        self.acc_scale = max(system.g, abs(system.gamma), 1e-12) / system.lattice.radius
        self.P_floor = h * system.mass * max(system.g, abs(system.gamma), 1e-12)
        self.s_prev = np.asarray(state.s, int).copy()
        self.ut_prev = dyn.velocities(state.omega, state.V)[c:]
        self.at_prev = np.full(c, np.inf)
        self.od_prev: np.ndarray | None = None
        self.P_prev: np.ndarray | None = None
        self.quiet = 0
        self.rule = Selection.parse(opts.selection)

    def step_problem(self, s_fixed: np.ndarray) -> StepProblem:
        key = s_fixed.astype(np.int8).tobytes()
        if key not in self.problems:
            if len(self.problems) > 64:
                self.problems.clear()
            self.problems[key] = StepProblem(self.system, self.dyn, s_fixed)
        return self.problems[key]

    def step(self) -> _Step:
        """Solve the step from t to t + h: contacts predicted to keep sliding (far from v_t = 0
        at their rate) substituted first, checked by the residual of the whole step, else every
        frictional contact a candidate; the selection rule's point first, the solver's if it
        fails the Coulomb-law check."""
        system, dyn, opts, c, h = self.system, self.dyn, self.opts, self.system.c, self.opts.h
        V_next = self.V + system.gamma * h
        b = dyn.H @ (self.nu + self.free_dnu) + dyn.u_obs(V_next)
        u_scale = max(float(np.abs(b).max(initial=0.0)), system.g * h, 1e-300)
        keep = (self.s_prev != 0) & (np.abs(self.ut_prev) > 2.0 * h * np.abs(self.at_prev))
        attempts = [np.where(keep, self.s_prev, 0)] if keep.any() else []
        attempts.append(np.zeros(c, int))
        got = None
        for s_fixed in attempts:
            sp = self.step_problem(s_fixed)
            warm = (sp.warm_active(self.P_prev, self.ut_prev)
                    if opts.warm_start and self.P_prev is not None else None)
            problem = sp.lcp(b, self.t + h)
            sol, used, fell_back = solve_step(problem, opts, warm)
            res = got.res if got is not None else np.inf
            got = _Step(sol, used, fell_back, sp, None, None, None, res, u_scale, b)
            if sol.status != "solved":
                continue
            points = [sol.z]
            if self.rule.rule != "none":  # the rule's point first, the solver's if it fails
                stick = np.arange(sp.n) < c + sp.k
                y, how = select(problem, sol.z, sp.G, c, stick, self.rule)  # random: the face's
                if not how.startswith("failed"):
                    points.insert(0, y)
            for z in points:
                self.point(got, z, V_next)
                if got.res <= opts.check_tol:
                    break
            if got.res <= opts.check_tol:
                break
        return got

    def point(self, got: _Step, z: np.ndarray, V_next: float) -> None:
        """Fill got with the impulses, velocity change, velocities and residual of z."""
        dyn = self.dyn
        got.P = got.sp.G @ z
        got.dnu = dyn.Minv * (dyn.H.T @ got.P) + self.free_dnu
        got.u = dyn.H @ (self.nu + got.dnu) + dyn.u_obs(V_next)
        P_scale = max(float(np.abs(got.P).max(initial=0.0)), self.P_floor)
        got.res = coulomb_residual(self.system, got.P, got.u, P_scale, got.u_scale)

    def closed(self, got: _Step, closed: dict, step: int) -> tuple[_Step, str]:
        """The step's solution of least sum P_n keeping every contact closed
        (models/step_closed.py) in place of `got`, which would open one or translate a disk,
        when it passes the step's own checks; else `got`, with the search's verdict."""
        from .step_closed import search_step

        closed["searched"] += 1
        sp = self.step_problem(np.zeros(self.system.c, int))
        scale = max(got.u_scale, self.P_floor)
        found = search_step(sp, self.dyn, got.b, self.free_dnu, scale, self.opts.check_tol)
        if found.status != "found":
            return got, found.message
        new = _Step(got.sol, "closed search", False, sp, None, None, None, np.inf, got.u_scale,
                    got.b)
        self.point(new, found.z, self.V + self.system.gamma * self.opts.h)
        opening, moving = leaving(new, self.system, self.opts.h)
        if new.res > self.opts.check_tol or opening.size or moving.size:
            return got, (f"undecided: the closed solution found fails the step's check "
                         f"(residual {new.res:.3g}, max u_n {new.u[:self.system.c].max():.3g})")
        closed["followed"].append(step)
        return new, found.message

    def record(self, got: _Step) -> tuple[EventRecord, bool]:
        """The step's record (t + h, velocities after it, mean forces, states) and whether it
        is settled (states and omega' unchanged, no sliding contact decelerating)."""
        system, h, c, p = self.system, self.opts.h, self.system.c, self.system.p
        nu_next = self.nu + got.dnu
        ut = got.u[c:]
        s = np.where(np.abs(ut) <= 1e-9 * got.u_scale, 0, np.sign(ut)).astype(int)
        s[system.mu == 0] = 0
        omega_dot = got.dnu[2 * p:] / h
        at = (ut - self.ut_prev) / h
        S = got.P[c:] / h
        rec = EventRecord(
            t=self.t + h, V=self.V + system.gamma * h, omega=nu_next[2 * p:].copy(),
            omega_dot=omega_dot, R=got.P[:c] / h, S=S, s=s, s_in=self.s_prev.copy(),
            vt=ut.copy(), at=at,
            mu_g=global_friction(system, S) / (system.total_mass * system.g or 1.0),
            dissipation=dissipation_rate(S, ut), iterations=int(got.sol.iterations),
            residual=got.res, n_lcp=got.sp.n, method=got.used, fallback=got.fell_back)
        settled = (np.array_equal(s, self.s_prev) and self.od_prev is not None
                   and np.abs(omega_dot - self.od_prev).max(initial=0.0)
                   <= 1e-9 * self.acc_scale
                   and not np.any((s != 0) & (s * (ut - self.ut_prev) < -1e-12 * got.u_scale)))
        return rec, bool(settled)

    def advance(self, got: _Step, rec: EventRecord) -> None:
        """Move to t + h."""
        self.t, self.V, self.nu = rec.t, rec.V, self.nu + got.dnu
        self.od_prev, self.s_prev, self.P_prev = rec.omega_dot, rec.s, got.P
        self.ut_prev, self.at_prev = rec.vt, rec.at


__all__ = ["InvalidStep", "StepOptions", "StepProblem", "coulomb_residual", "moreau_jean"]
