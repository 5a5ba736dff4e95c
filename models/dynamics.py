"""Kinematics and dynamics of a system: H, the mass matrix, the Delassus operator W and q.

Generalized velocities nu = [vx (p), vy (p), omega (p)]; contact forces lambda = [R (c), S (c)].
The relative velocity of body j with respect to body i at contact alpha (docs/mechanics.md) is

    u_alpha = (v_j - v_i - (r_i omega_i + r_j omega_j) t) . (n, t)  =  (H nu + u_obs)_alpha,

where u_obs is the prescribed velocity of an obstacle j (the plane moves with -V(t) x in the box
frame). The contact force on j is R n + S t (on i the opposite), so the generalized contact force
is H^T lambda (its power is lambda . H nu), and the torque on disk i is -r_i S (on j: -r_j S).
Newton-Euler in the box frame, M nu' = H^T lambda + f with f = (-m_i gamma, -m_i g, 0) per disk,
gives the relative accelerations of Eqs. (2.13)-(2.14):

    a = W lambda + q,    W = H M^-1 H^T,    q = H M^-1 f + u_obs'.

Rows 0..c-1 of H, W, q, a are normal components (a_n), rows c..2c-1 tangential (a_t).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import scipy.sparse as sp

from .lattice import PLANE
from .system import System


class Dynamics:
    """H, M^-1, f, W, q of a system (all constant while the geometry does not change)."""

    def __init__(self, system: System):
        self.system = system
        lat = system.lattice
        p, c, r = lat.p, lat.c, lat.radii
        rows, cols, vals = [], [], []
        disk_j = lat.j >= 0
        for comp, vec in ((0, lat.n), (1, lat.t)):
            base = comp * c
            for axis in (0, 1):  # vx block then vy block
                a = np.arange(c)
                rows += [base + a, base + a[disk_j]]
                cols += [axis * p + lat.i, axis * p + lat.j[disk_j]]
                vals += [-vec[:, axis], vec[disk_j, axis]]
        a = np.arange(c)  # rotations enter the tangential rows only: -r_i omega_i - r_j omega_j
        rows += [c + a, c + a[disk_j]]
        cols += [2 * p + lat.i, 2 * p + lat.j[disk_j]]
        vals += [-r[lat.i], -r[lat.j[disk_j]]]
        self.H = sp.csr_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
            shape=(2 * c, 3 * p),
        )
        m, inertia = system.masses, system.inertias  # per disk
        self.Minv = np.concatenate([1.0 / m, 1.0 / m, 1.0 / inertia])
        self.f = np.concatenate([-m * system.gamma, -m * system.g, np.zeros(p)])
        self.plane = lat.j == PLANE
        # u_obs = [n . v_obs ; t . v_obs] with v_obs = (-V, 0) on the plane: unit-V coefficients.
        v_plane = np.zeros((c, 2))
        v_plane[self.plane, 0] = -1.0
        self._obs_per_V = np.concatenate(
            [np.einsum("ak,ak->a", lat.n, v_plane), np.einsum("ak,ak->a", lat.t, v_plane)]
        )

    @property
    def p(self) -> int:
        return self.system.p

    @property
    def c(self) -> int:
        return self.system.c

    def u_obs(self, V: float) -> np.ndarray:
        """Obstacle part of the relative velocities when the box moves at V past the plane."""
        return self._obs_per_V * V

    @cached_property
    def u_obs_dot(self) -> np.ndarray:
        """Obstacle part of the relative accelerations (the plane accelerates at -gamma)."""
        return self._obs_per_V * self.system.gamma

    @cached_property
    def W(self) -> np.ndarray:
        """Delassus operator H M^-1 H^T (dense, 2c x 2c)."""
        HM = self.H.multiply(self.Minv[None, :]).tocsr()
        return np.asarray((HM @ self.H.T).todense())

    @cached_property
    def H_T(self) -> sp.csc_matrix:
        """H^T, kept (scipy builds a new transpose on every `H.T`)."""
        return self.H.T

    @cached_property
    def q(self) -> np.ndarray:
        """Free relative accelerations H M^-1 f + u_obs' (all contact forces zero)."""
        return self.H @ (self.Minv * self.f) + self.u_obs_dot

    def velocities(self, omega: np.ndarray, V: float) -> np.ndarray:
        """Relative velocities [v_n; v_t] for angular velocities omega (disks do not translate)."""
        nu = np.concatenate([np.zeros(2 * self.p), omega])
        return self.H @ nu + self.u_obs(V)

    def accelerations(self, lam: np.ndarray) -> np.ndarray:
        """Generalized accelerations nu' = M^-1 (H^T lambda + f)."""
        return self.Minv * (self.H_T @ lam + self.f)

    def relative_accelerations(self, lam: np.ndarray) -> np.ndarray:
        """a = W lambda + q (computed through H, without forming W)."""
        return self.H @ self.accelerations(lam) + self.u_obs_dot
