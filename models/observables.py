"""Observables of the paper: contact states, global friction, dissipation, balances, energy.

Signs (DESIGN.md): the force of the plane on a disk is -(R n + S t) with n = (0, -1), t = (1, 0),
so its horizontal part is -S. The global friction F_g = sum over plane contacts of S is counted
positive when it opposes the box's motion relative to the plane, so that Eq. (2.1) reads
N - F_g = m_g gamma; mu_g = F_g / (m_g g). The dissipation rate is D = -sum S v_t >= 0 and the
power the plane gives the disks is F_g V, so between events d(E_rot)/dt = F_g V - D.
"""

from __future__ import annotations

import numpy as np

from .lattice import LEFT_WALL, PLANE, RIGHT_WALL
from .system import System


def global_friction(system: System, S: np.ndarray) -> float:
    """F_g = sum of S over the plane contacts (Eq. 2.1 convention)."""
    return float(np.sum(S[system.lattice.j == PLANE]))


def global_friction_coefficient(system: System, S: np.ndarray) -> float:
    """mu_g = F_g / (m_g g)."""
    return global_friction(system, S) / (system.total_mass * system.g)


def dissipation_rate(S: np.ndarray, vt: np.ndarray) -> float:
    """D = -sum_alpha S_alpha v_t,alpha (>= 0 under Coulomb's law)."""
    return float(-np.dot(S, vt))


def rotational_energy(system: System, omega: np.ndarray) -> float:
    return 0.5 * system.inertia * float(np.dot(omega, omega))


def obstacle_force_on_disks(system: System, R: np.ndarray, S: np.ndarray) -> np.ndarray:
    """Total force (x, y) of the plane and the walls on the disks: -(R n + S t) summed."""
    lat = system.lattice
    obst = lat.j < 0
    f = -(R[obst, None] * lat.n[obst] + S[obst, None] * lat.t[obst])
    return f.sum(axis=0)


def horizontal_balance(system: System, R: np.ndarray, S: np.ndarray) -> float:
    """Residual of Eq. (2.1) seen from the box: (plane + walls horizontal force) - m_g gamma."""
    return float(obstacle_force_on_disks(system, R, S)[0] - system.total_mass * system.gamma)


def state_counts(system: System, record) -> dict:
    """Counts of transmitting / non-sliding / sliding contacts of a record, by kind."""
    R, s = record.R, record.s
    tol = 1e-9 * system.mass * max(system.g, abs(system.gamma), 1e-12)
    T = R > tol
    out = {"T": int(T.sum()), "NT": int((~T).sum())}
    for kind in ("pp", "plane", "wall"):
        sel = system.lattice.kind == kind
        out[f"NS_{kind}"] = int(((s == 0) & sel & (system.mu > 0)).sum())
        out[f"sliding_{kind}"] = int(((s != 0) & sel).sum())
    return out


def states_text(system: System, R: np.ndarray, s: np.ndarray) -> list[str]:
    """Per contact: 'T' / 'NT' and 'NS' / 'S+' / 'S-' (frictionless contacts: 'free')."""
    tol = 1e-9 * system.mass * max(system.g, abs(system.gamma), 1e-12)
    out = []
    for a in range(system.c):
        normal = "T" if R[a] > tol else "NT"
        if system.mu[a] == 0:
            tang = "free"
        else:
            tang = {0: "NS", 1: "S+", -1: "S-"}[int(s[a])]
        out.append(f"{normal}/{tang}")
    return out


__all__ = [
    "global_friction", "global_friction_coefficient", "dissipation_rate", "rotational_energy",
    "obstacle_force_on_disks", "horizontal_balance", "state_counts", "states_text",
    "LEFT_WALL", "RIGHT_WALL", "PLANE",
]
