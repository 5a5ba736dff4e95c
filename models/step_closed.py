"""The closed-solution search of the time-stepper: a step's solution that keeps every contact
closed, or a proof that there is none (models/engine/closed.py's `search` on the step LCP).

A Moreau-Jean step (models.timestepping) solves the velocity-level LCP of models.step_lcp,
z = [P_n (c), tau (k), u_minus (k)] over every frictional contact as a candidate (the exact
Signorini-Coulomb laws of the step), w = [u_n, u_plus, 2 mu P_n - tau] = M z + b. When the
step's solution would open a contact (u_n > 0 at the end of the step) or translate a disk, the
regime ends only if every solution of the same step does. The closed rows are

    u_n^{k+1} = M[:c] z + b_n = 0 on every contact,
    dnu_x = M^-1 (H^T G z)_x + h M^-1 f_x = 0 for every disk (vx, vy: no translation),

and the search is the event engine's (least sum P_n over the closed solutions; "none" only
when every node is discarded with a checked Farkas certificate; "undecided" at its limits).
The step's own acceptance (the Coulomb-law residual, u_n and the translations) checks a
closed solution again before it is followed (models.timestepping).
"""

from __future__ import annotations

import numpy as np

from .dynamics import Dynamics
from .engine.closed import ClosedProblem, ClosedSearch, search
from .step_lcp import StepProblem


def step_closed(sp: StepProblem, dyn: Dynamics, b: np.ndarray, free_dnu: np.ndarray
                ) -> ClosedProblem:
    """The step LCP of `sp` (every frictional contact a candidate) with free velocities b and
    its closed rows (module doc); free_dnu = h M^-1 f_theta."""
    system = sp.system
    c, p = system.c, system.p
    if np.any(sp.s_fixed != 0):
        raise ValueError("the closed search takes the step LCP with no sliding substituted")
    problem = sp.lcp(b, 0.0)
    M, q = problem.M, problem.q
    acc = np.asarray(dyn.Minv[: 2 * p, None] * (dyn.H_T[: 2 * p] @ sp.G))  # dnu_x per unit z
    A = np.vstack([M[:c], acc])
    return ClosedProblem(M, q, c, A, np.concatenate([q[:c], free_dnu[: 2 * p]]), what="step")


def search_step(sp: StepProblem, dyn: Dynamics, b: np.ndarray, free_dnu: np.ndarray,
                scale: float, tol: float) -> ClosedSearch:
    """The closed solution of least sum P_n of the step, or a proof that there is none
    (module doc); scale: the step's (max of the free velocities' and the impulses' scales)."""
    return search(step_closed(sp, dyn, b, free_dnu), scale, tol)
