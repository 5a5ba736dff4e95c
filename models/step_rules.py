"""The stop rules of a Moreau-Jean step (models.timestepping): a step no solver solved, a
contact that opens or a disk that translates (the no-displacement regime ends), a steady state,
the time limit. Split out of models/timestepping.py (one job per module). `got` is a step's
_Step, `k` the _Stepper, `opts` the StepOptions of models.timestepping (not imported here:
it imports this module)."""

from __future__ import annotations

import numpy as np


def step_failure(got, opts) -> tuple[str, str] | None:
    """(status, message) of a step no solver solved within check_tol, else None."""
    sol, used = got.sol, got.used
    if sol.status != "solved":
        return (("no_solution" if sol.status in ("ray", "infeasible") else "solver_failed"),
                f"{used} ended with status {sol.status!r} ({sol.message or 'no message'})")
    if not got.res <= opts.check_tol:
        return ("solver_failed", f"Coulomb-law residual {got.res:.3g} > check_tol "
                f"{opts.check_tol:g} ({used})")
    return None


#: A disk translates when its mean translational acceleration over a step exceeds this
#: fraction of max(g, |gamma|) (as models.engine.loop's check: the arrays block every
#: translation, to rounding).
TRANSLATION_TOL = 1e-7


def leaving(got, system, h: float) -> tuple[np.ndarray, np.ndarray]:
    """(contacts that open: u_n > 1e-9 of the velocity scale, disks that translate)."""
    return np.flatnonzero(got.u[:system.c] > 1e-9 * got.u_scale), translating(got, system, h)


def translating(got, system, h: float) -> np.ndarray:
    """The disks that the step's impulses would translate (dnu's translational part != 0) with
    every contact closed: a mechanism of a packing (e.g. a disk pushed along the plane with no
    wall), which the no-displacement regime excludes; the paper's arrays never have one."""
    p = system.p
    size = np.hypot(got.dnu[:p], got.dnu[p:2 * p]) / h
    return np.flatnonzero(size > TRANSLATION_TOL * max(system.g, abs(system.gamma), 1e-12))


def stop_reason(k, opening: np.ndarray, moving: np.ndarray, opts, step: int
          ) -> tuple[str, str] | None:
    """(status, message) when the run stops after this step, else None."""
    if opening.size:
        return ("detachment", f"t = {k.t:.6g}: contact(s) would open (u_n > 0), the "
                f"no-displacement regime ends: {opening[:5].tolist()}")
    if moving.size:
        return ("detachment", f"t = {k.t:.6g}: disk(s) would translate with every contact "
                f"closed, the no-displacement regime ends: disks {moving[:5].tolist()}")
    if k.quiet >= opts.steady_steps:
        return "steady", f"steady state at t = {k.t:.6g} (step {step + 1})"
    if k.t >= opts.t_max:
        return "time_limit", f"t_max = {opts.t_max:g} reached"
    return None
