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


class StepProblem:
    """The LCP of a step for given predicted sliding contacts (P_t = -s mu P_n substituted, as
    Eq. 2.10 at velocity level; checked a posteriori by the Coulomb residual of the whole
    step) and candidates (the split above). M depends on that choice only; q = the free
    velocities b."""

    def __init__(self, system: System, dyn: Dynamics, s_fixed: np.ndarray):
        c, mu = system.c, system.mu
        self.system, self.dyn = system, dyn
        fric = mu > 0
        self.s_fixed = np.where(fric, s_fixed, 0).astype(int)
        self.cand = np.flatnonzero(fric & (self.s_fixed == 0))
        k = self.k = self.cand.size
        n = self.n = c + 2 * k
        G = np.zeros((2 * c, n))
        G[np.arange(c), np.arange(c)] = 1.0
        G[c + np.arange(c), np.arange(c)] = -self.s_fixed * mu  # sliding: P_t = -s mu P_n
        G[c + self.cand, self.cand] = -mu[self.cand]  # candidates: P_t = tau - mu P_n
        G[c + self.cand, c + np.arange(k)] = 1.0
        WG = dyn.W @ G
        M = np.zeros((n, n))
        M[:c] = WG[:c]  # u_n
        M[c:c + k] = WG[c:][self.cand]  # u_t ...
        M[c:c + k, c + k:] += np.eye(k)  # ... + u_minus = u_plus
        M[c + k + np.arange(k), self.cand] = 2.0 * mu[self.cand]  # 2 mu P_n - tau
        M[c + k:, c:c + k] -= np.eye(k)
        self.G, self.M = G, M

    def lcp(self, b: np.ndarray, t: float) -> lcp.LCP:
        c, k = self.system.c, self.k
        q = np.concatenate([b[:c], b[c:][self.cand], np.zeros(k)])
        return lcp.LCP(self.M, q, name="moreau-jean step", meta={"t": t})

    def warm_active(self, P: np.ndarray, ut: np.ndarray) -> np.ndarray:
        """Basic variables guessed from the previous step: P_n > 0; tau > 0 unless the
        contact slid forwards (P_t = -mu P_n); u_minus > 0 when it slid backwards."""
        c, k = self.system.c, self.k
        active = list(np.flatnonzero(P[:c] > 0))
        for pos, alpha in enumerate(self.cand):
            if ut[alpha] <= 0:
                active.append(c + pos)
            if ut[alpha] < 0:
                active.append(c + k + pos)
        return np.array(sorted(active), dtype=int)


def coulomb_residual(system: System, P: np.ndarray, u: np.ndarray, P_scale: float,
                     u_scale: float) -> float:
    """Scaled residual of the velocity-level laws of a step (natural maps, each 0 iff the law
    holds): Signorini |min(P_n / Ps, u_n / us)| and Coulomb
    |P_t - proj_[-mu P_n, mu P_n](P_t - u_t Ps / us)| / Ps, maximized over the contacts."""
    c, mu = system.c, system.mu
    Pn, Pt, un, ut = P[:c] / P_scale, P[c:] / P_scale, u[:c] / u_scale, u[c:] / u_scale
    r_n = np.abs(np.minimum(Pn, un))
    bound = mu * np.maximum(Pn, 0.0)
    r_t = np.abs(Pt - np.clip(Pt - ut, -bound, bound))
    return float(max(r_n.max(initial=0.0), r_t.max(initial=0.0)))


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
    record_every, max_steps, t_max, selection); bad values raise InvalidStep. selection: which
    solution of a step's LCP is followed where it has more than one (models/selection.py):
    "none" (default: the solver's, warm-started from the previous step), "face-min-norm",
    "max-sum-R[:CAP]" or "random:SEED" (sum of P_n in place of sum R); a selected point must
    pass the same Coulomb-law check as the solver's, else the solver's is kept.
    progress(run, t, omega) is called after every step with the time and the angular
    velocities reached.
    """
    opts = StepOptions(h=h, theta=theta, **options)
    from threadpoolctl import threadpool_limits

    with threadpool_limits(1):  # small dense problems: one BLAS thread is fastest
        return _integrate(system, state, opts, omega, seed, progress)


def _integrate(system, state, opts, omega, seed, progress) -> Run:
    dyn = Dynamics(system)
    problems: dict[bytes, StepProblem] = {}

    def step_problem(s_fixed: np.ndarray) -> StepProblem:
        key = s_fixed.astype(np.int8).tobytes()
        if key not in problems:
            if len(problems) > 64:
                problems.clear()
            problems[key] = StepProblem(system, dyn, s_fixed)
        return problems[key]

    state = (initial_state(system, omega=omega, seed=seed) if state is None else state).copy()
    h, c, p = opts.h, system.c, system.p
    run = Run(system, method=f"moreau-jean h={h:g} theta={opts.theta:g} ({opts.method}"
              + (f", selection {opts.selection})" if opts.selection != "none" else ")"))
    nu = np.concatenate([np.zeros(2 * p), state.omega])
    t, V = state.t, state.V
    f_theta = opts.theta * dyn.f + (1.0 - opts.theta) * dyn.f  # f does not depend on t
    free_dnu = h * dyn.Minv * f_theta
    acc_scale = max(system.g, abs(system.gamma), 1e-12) / system.lattice.radius
    P_floor = h * system.mass * max(system.g, abs(system.gamma), 1e-12)
    s_prev = np.asarray(state.s, int).copy()
    ut_prev = dyn.velocities(state.omega, V)[c:]
    at_prev = np.full(c, np.inf)
    od_prev, P_prev = None, None
    quiet = 0
    rule = Selection.parse(opts.selection)
    start = _time.perf_counter()
    for step in range(opts.max_steps):
        V_next = V + system.gamma * h
        b = dyn.H @ (nu + free_dnu) + dyn.u_obs(V_next)
        u_scale = max(float(np.abs(b).max(initial=0.0)), system.g * h, 1e-300)
        # Contacts predicted to keep sliding (far from v_t = 0 at their rate): substituted;
        # the prediction is checked by the residual of the whole step, else every frictional
        # contact is a candidate.
        keep = (s_prev != 0) & (np.abs(ut_prev) > 2.0 * h * np.abs(at_prev))
        attempts = [np.where(keep, s_prev, 0)] if keep.any() else []
        attempts.append(np.zeros(c, int))
        for s_fixed in attempts:
            sp = step_problem(s_fixed)
            warm = (sp.warm_active(P_prev, ut_prev)
                    if opts.warm_start and P_prev is not None else None)
            problem = sp.lcp(b, t + h)
            sol, used, fell_back = _solve_step(problem, opts, warm)
            if sol.status != "solved":
                continue
            points = [sol.z]
            if rule.rule != "none":  # the rule's point first, the solver's if it fails
                stick = np.arange(sp.n) < c + sp.k
                y, how = select(problem, sol.z, sp.G, c, stick, rule)  # random: the face's
                if not how.startswith("failed"):
                    points.insert(0, y)
            for z in points:
                P = sp.G @ z
                dnu = dyn.Minv * (dyn.H.T @ P) + free_dnu
                u = dyn.H @ (nu + dnu) + dyn.u_obs(V_next)
                P_scale = max(float(np.abs(P).max(initial=0.0)), P_floor)
                res = coulomb_residual(system, P, u, P_scale, u_scale)
                if res <= opts.check_tol:
                    break
            if res <= opts.check_tol:
                break
        if sol.status != "solved":
            run.status = "no_solution" if sol.status in ("ray", "infeasible") else "solver_failed"
            run.message = (f"step {step} (t = {t:.6g} -> {t + h:.6g}): {used} ended with status "
                           f"{sol.status!r} ({sol.message or 'no message'})")
            break
        if not res <= opts.check_tol:
            run.status = "solver_failed"
            run.message = (f"step {step} (t = {t:.6g} -> {t + h:.6g}): Coulomb-law residual "
                           f"{res:.3g} > check_tol {opts.check_tol:g} ({used})")
            break
        nu_next = nu + dnu
        ut = u[c:]
        s = np.where(np.abs(ut) <= 1e-9 * u_scale, 0, np.sign(ut)).astype(int)
        s[system.mu == 0] = 0
        omega_dot = dnu[2 * p:] / h
        at = (ut - ut_prev) / h
        S = P[c:] / h
        rec = EventRecord(
            t=t + h, V=V_next, omega=nu_next[2 * p:].copy(), omega_dot=omega_dot,
            R=P[:c] / h, S=S, s=s, s_in=s_prev.copy(), vt=ut.copy(), at=at,
            mu_g=global_friction(system, S) / (system.total_mass * system.g or 1.0),
            dissipation=dissipation_rate(S, ut), iterations=int(sol.iterations),
            residual=res, n_lcp=sp.n, method=used, fallback=fell_back)
        opening = np.flatnonzero(u[:c] > 1e-9 * u_scale)
        changed = not np.array_equal(s, s_prev)
        settled = (not changed and od_prev is not None
                   and np.abs(omega_dot - od_prev).max(initial=0.0) <= 1e-9 * acc_scale
                   and not np.any((s != 0) & (s * (ut - ut_prev) < -1e-12 * u_scale)))
        quiet = quiet + 1 if settled else 0
        if step == 0:  # the run's records start at its initial state (plots, dissipated
            # energy from t = state.t): the first step's forces, from the initial velocities
            run.records.append(replace(rec, t=t, V=V, omega=nu[2 * p:].copy(), vt=ut_prev.copy(),
                                       dissipation=dissipation_rate(S, ut_prev)))
        t, V, nu, od_prev, s_prev, P_prev = t + h, V_next, nu_next, omega_dot, s, P
        ut_prev, at_prev = ut, at
        last = (opening.size or quiet >= opts.steady_steps or t >= opts.t_max
                or step + 1 == opts.max_steps)
        if changed or last or (opts.record_every and (step + 1) % opts.record_every == 0):
            run.records.append(rec)
        if opening.size:
            run.status, run.contacts = "detachment", opening.tolist()
            run.message = (f"t = {t:.6g}: contact(s) would open (u_n > 0), the no-displacement "
                           f"regime ends: {opening[:5].tolist()}")
            break
        if quiet >= opts.steady_steps:
            run.status, run.message = "steady", f"steady state at t = {t:.6g} (step {step + 1})"
            break
        if t >= opts.t_max:
            run.status, run.message = "time_limit", f"t_max = {opts.t_max:g} reached"
            break
        if progress is not None:
            progress(run, t, nu[2 * p:])
    else:
        run.status, run.message = "event_limit", f"{opts.max_steps} steps"
    run.final = State(t, nu[2 * p:].copy(), V, s_prev.copy())
    run.wall_time = _time.perf_counter() - start
    return run


def _solve_step(problem: lcp.LCP, opts: StepOptions, warm: np.ndarray | None):
    """Warm pivoting from the previous step's basis (when given), then method, then fallback.
    Returns (solution, name of the method that produced it, whether a fallback was used)."""
    tried = []
    if warm is not None:
        sol = lcp.solve(problem, "pivoting", active=warm, max_iter=20)
        if sol.status == "solved":
            return sol, "pivoting-warm", False
        tried.append(f"pivoting-warm: {sol.status}")
    sol = lcp.solve(problem, opts.method)
    if sol.status == "solved" or opts.fallback is None or opts.fallback == opts.method:
        if tried and sol.status != "solved":
            sol.message = "; ".join(tried + [f"{opts.method}: {sol.message}"])
        return sol, opts.method, False
    first = sol
    sol = lcp.solve(problem, opts.fallback)
    if sol.status != "solved":
        sol.message = "; ".join(tried + [f"{opts.method}: {first.status}",
                                         f"{opts.fallback}: {sol.message}"])
    return sol, opts.fallback, True


__all__ = ["InvalidStep", "StepOptions", "StepProblem", "coulomb_residual", "moreau_jean"]
