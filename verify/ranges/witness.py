"""Independent checks of range witnesses: a steady state against the laws, contact by contact.

`steady_check` does not use the MILP or its W: it recomputes the accelerations from Newton-Euler
(nu' = M^-1 (H^T lambda + f), a = H nu' + u_obs', models.dynamics) and the tangential velocities
from (omega, V), reads each contact's state off the sign of its v_t, and measures how far the
state is from the definition of a valid steady state (docs/mechanics.md):

    a_n = 0 and no translation; R >= 0; |S| <= mu R; S = 0 where mu = 0;
    v_t > 0: S = -mu R and a_t >= 0;  v_t < 0: S = +mu R and a_t <= 0;  v_t = 0: a_t = 0.

Residuals are relative: forces to the force scale (max |lambda|, m g), accelerations to
max(g, |gamma|) times (1 + |lambda| / (m g)), velocities to max |v_t| (the cone's scale).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.observables import global_friction_coefficient
from rigidlcp.models.system import System

from ..steadiness import from_velocities

#: A witness is accepted when its independent residual is at most this.
WITNESS_TOL = 1e-8


@dataclass
class SteadyWitness:
    """A steady state: velocities omega (per disk) and V, angular accelerations alpha, forces
    R and S (per contact), contact pairs [i, j] (obstacles -1 left wall, -2 right wall, -3
    plane), the tangential states s (+1/-1 sliding, 0 non-sliding or frictionless), mu_g, and
    the independent residual of `steady_check`."""

    omega: np.ndarray
    V: float
    alpha: np.ndarray
    R: np.ndarray
    S: np.ndarray
    pairs: np.ndarray
    s: np.ndarray
    mu_g: float
    residual: float

    def to_dict(self) -> dict:
        return {"mu_g": float(self.mu_g), "omega": self.omega.tolist(), "V": float(self.V),
                "alpha": self.alpha.tolist(), "R": self.R.tolist(), "S": self.S.tolist(),
                "pairs": self.pairs.tolist(), "s": self.s.tolist(),
                "residual": float(self.residual)}

    def __repr__(self) -> str:
        n_sl = int(np.sum(self.s != 0))
        return (f"<SteadyWitness mu_g={self.mu_g:.7g}, V={self.V:.4g}, {n_sl} sliding, "
                f"max|alpha|={np.max(np.abs(self.alpha), initial=0):.3g}, "
                f"max R={np.max(self.R, initial=0):.3g}, residual {self.residual:.1e}>")


def steady_check(system: System, omega, V: float, R, S, dyn: Dynamics | None = None,
                 v_scale: float = 0.0) -> tuple[float, np.ndarray]:
    """(residual, s): the largest relative violation of the steady-state laws (module
    docstring; the definition is verify.steadiness's) by (omega, V, R, S), and the states read
    off sgn(v_t) (0 where |v_t| <= 1e-9 max(max|v_t|, v_scale); v_scale: the velocity scale of
    a run, whose rounding noise (1e-16) is not a velocity)."""
    st = from_velocities(system, omega, V, R, S, dyn, v_scale)
    return st.residual, st.s


def make_witness(system: System, omega, V: float, R, S, dyn: Dynamics | None = None,
                 v_scale: float = 0.0) -> SteadyWitness:
    """A SteadyWitness with its alpha, mu_g and independent residual computed here."""
    dyn = dyn or Dynamics(system)
    lam = np.concatenate([R, S])
    alpha = dyn.accelerations(lam)[2 * system.p:]
    res, s = steady_check(system, omega, V, R, S, dyn, v_scale)
    lat = system.lattice
    return SteadyWitness(np.asarray(omega, float), float(V), alpha, np.asarray(R, float),
                         np.asarray(S, float), np.column_stack([lat.i, lat.j]), s,
                         global_friction_coefficient(system, np.asarray(S, float)), res)
