"""The seed contact-state sets of verify.ranges.valid_steady: simple velocities (the locked
array, the rolling checkerboards) whose states are tried at every end before any search, and
the MIP starts they give (each checked by verify.ranges.witness.steady_check)."""

from __future__ import annotations

import numpy as np

from rigidlcp.models.system import System

from .milp import MilpModel
from .result import OPTIMAL
from .steady import Formulation, least_R, state_extreme, state_velocities
from .witness import WITNESS_TOL, steady_check


def two_colouring(adj: list[list[int]]) -> np.ndarray | None:
    """sigma = +-1 (floats) per vertex with sigma_i = -sigma_j across every edge of the graph
    `adj` (adjacency lists), each component's lowest vertex +1; None if it is not bipartite."""
    sigma = np.zeros(len(adj))
    for root in range(len(adj)):
        if sigma[root]:
            continue
        sigma[root], stack = 1.0, [root]
        while stack:
            i = stack.pop()
            for j in adj[i]:
                if not sigma[j]:
                    sigma[j] = -sigma[i]
                    stack.append(j)
                elif sigma[j] == sigma[i]:
                    return None
    return sigma


def _two_colouring(system: System) -> np.ndarray | None:
    """two_colouring of the disks across every disk-disk contact, or None (the contact graph
    is not bipartite)."""
    lat, p = system.lattice, system.p
    nbr: list[list[int]] = [[] for _ in range(p)]
    for i, j in zip(lat.i, lat.j):
        if 0 <= i < p and 0 <= j < p:
            nbr[int(i)].append(int(j))
            nbr[int(j)].append(int(i))
    return two_colouring(nbr)


def seed_states(form: Formulation) -> list[np.ndarray]:
    """Contact-state sets of simple velocities, tried at every end (each kept when its
    velocities and some forces exist): V = +1 and -1 (V free) or V of the run's sign, with
    no rotation (omega = 0: every disk-disk contact non-sliding, every frictional contact with
    the plane sliding the same way: the locked array), and, where the disk-disk contacts
    2-colour the disks, the rolling checkerboards r omega_i = +-sigma_i V (every disk-disk
    contact non-sliding, the first-row disks of one colour rolling: Fig. 9's least mu_g
    met, 0.1050919, is one)."""
    system, dyn = form.system, form.dyn
    Vs = {"free": (1.0, -1.0), "zero": (0.0,), "positive": (1.0,),
          "negative": (-1.0,)}[form.V_mode]
    sigma = _two_colouring(system)
    spins = [np.zeros(system.p)] + ([] if sigma is None else [sigma, -sigma])
    out: list[np.ndarray] = []
    zero = np.zeros(2 * system.c)
    for V in Vs:
        for spin in spins:
            u = spin * V
            if V == 0 and np.any(u):
                continue
            vt = dyn.velocities(u / system.lattice.radii, V)[system.c:]
            s = np.where((system.mu > 0) & (np.abs(vt) > 1e-12), np.sign(vt), 0).astype(int)
            if any(np.array_equal(s, t) for t in out):
                continue
            if (state_velocities(form, s) is not None
                    and state_extreme(form, s, zero, 1)[0] == OPTIMAL):
                out.append(s)
    return out


def seed_starts(form: Formulation, model: MilpModel, L: np.ndarray, sense: int
                 ) -> list[np.ndarray]:
    """MIP starts for one end: the extreme of L over each seed state set (a linear program),
    where it is finite and its witness passes steady_check."""
    c, out = form.system.c, []
    for s in model.seeds:
        status, x, _ = state_extreme(form, s, L, sense)
        vel = state_velocities(form, s)
        if status != OPTIMAL or vel is None:
            continue
        R, S = x[:c], x[c:]
        if form.R_hi is not None and np.any(R > form.R_hi):
            R = least_R(form, s, S)  # same S and states, R within the proved bounds
            if R is None or np.any(R > form.R_hi):
                continue
        if steady_check(form.system, vel[0], vel[1], R, S, form.dyn)[0] <= WITNESS_TOL:
            out.append(form.start(R, S, vel[0], vel[1], s))
    return out
