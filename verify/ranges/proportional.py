"""Valid steady states through proportional velocities (docs/mechanics.md, "Valid steady states
through proportional velocities"): the forces and angular accelerations of the valid steady
states, without velocities.

In the paper's regime a steady state has no translation, so a_t = T_u (r alpha) + T_V gamma
and v_t = T_u (r omega) + T_V V with the same T (models.dynamics: a = H nu' + u_obs', u_obs'
= u_obs(gamma)). Let Q be the forces x = [R; S] with no translation, a_n = 0, R >= 0, |S| <=
mu R, S = 0 where mu = 0, and Coulomb read off a_t:

    a_t > 0 => S = -mu R;   a_t < 0 => S = +mu R   (a_t = 0: only the cone).

(i) Every valid steady state has its forces in Q: a contact with a_t > 0 cannot be non-sliding
(a_t = 0) nor slide with v_t < 0 (a_t <= 0), so it slides with v_t > 0 and S = -mu R; the same
for a_t < 0. (ii) If V = gamma t is admitted by the V condition for some t > 0 (`exact`), every
x of Q with (omega, V) = (alpha, gamma) t is a valid steady state: v_t = a_t t, so a contact
with a_t != 0 slides the way it accelerates (s a_t > 0, S = -s mu R by Q), one with a_t = 0 is
non-sliding and keeps a_t = 0; no translation, a_n = 0 and the cone hold in Q. Hence, for
every observable of (R, S) (mu_g, each alpha, R, S), its values over all valid steady states
are its values over Q: one complementarity system with no velocity variables, and the lazy
kinematic cuts of verify.ranges.milp are not needed (`MilpModel(form, "proportional")`).

`exact` fails only when gamma = 0 and V must be nonzero (a constant velocity V0 != 0; then
every alpha is 0, every a_t = 0, and Q holds states the velocities may not admit), or for a
V_mode of the other sign than gamma (passed by hand): there the kinematics stay.
"""

from __future__ import annotations

import numpy as np

from .steady import Formulation


def exact(form: Formulation) -> bool:
    """Whether V = gamma t (t > 0) meets form.V_mode: then the forces of the valid steady
    states are exactly Q (module docstring)."""
    g = form.system.gamma
    return {"free": True, "zero": g == 0, "positive": g > 0, "negative": g < 0}[form.V_mode]


def velocities(form: Formulation, R: np.ndarray, S: np.ndarray, V_ref: float | None = None
               ) -> tuple[np.ndarray, float]:
    """(omega, V) = (alpha, gamma) t of the forces (R, S), alpha from Newton-Euler; t = V_ref /
    gamma when that is positive (the witness then moves at the run's V), else t = 1."""
    system = form.system
    p, g = system.p, system.gamma
    alpha = form.dyn.accelerations(np.concatenate([R, S]))[2 * p:]
    t = V_ref / g if (V_ref is not None and g != 0 and V_ref / g > 0) else 1.0
    return alpha * t, g * t


def velocity_scale(form: Formulation, V: float) -> float:
    """The scale under which a tangential velocity of a proportional witness is rounding
    noise (steady_check's v_scale): sqrt(g r) as for a run, or |V| if larger."""
    system = form.system
    return max(float(np.sqrt(system.g * system.lattice.radius)), abs(V))
