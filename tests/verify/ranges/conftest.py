"""The brute force over tangential state sets and a_t sign patterns that test_brute_force,
test_patterns, test_proportional and test_unequal_radii share, written independently of the
code under test (docs/mechanics.md's definitions, LPs built here): fixtures, since test modules
do not import each other."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.optimize import linprog

from rigidlcp import models
from rigidlcp.models.dynamics import Dynamics


def pattern_lp(system: models.System, sig) -> dict:
    """linprog's arguments (A_ub, b_ub, A_eq, b_eq, bounds over x = [R; S]) of the forces of
    the a_t sign pattern sig (one entry per frictional contact: +1: a_t >= 0, S = -mu R;
    -1: a_t <= 0, S = +mu R; 0: a_t = 0, |S| <= mu R), with no translation, a_n = 0, R >= 0
    and S = 0 where mu = 0: one piece of Q (docs/mechanics.md, 'Through proportional
    velocities'), built from models.Dynamics alone."""
    dyn = Dynamics(system)
    c, p, mu = system.c, system.p, system.mu
    H = dyn.H.toarray()
    acc = dyn.Minv[:, None] * H.T  # nu' = acc @ x + Minv f
    a_rel = H @ acc  # a = a_rel x + H Minv f + u_obs'
    a0 = H @ (dyn.Minv * dyn.f) + dyn.u_obs_dot
    eq, eq_b = [acc[:2 * p], a_rel[:c]], [-(dyn.Minv * dyn.f)[:2 * p], -a0[:c]]
    ub, ub_b = [], []
    for sg, al in zip(np.asarray(sig, dtype=int), np.flatnonzero(mu > 0)):
        if sg:
            row = np.zeros(2 * c)
            row[c + al], row[al] = 1.0, sg * mu[al]
            eq.append(row[None])
            eq_b.append([0.0])
            ub.append(-sg * a_rel[c + al])
            ub_b.append(sg * a0[c + al])
        else:
            eq.append(a_rel[c + al][None])
            eq_b.append([-a0[c + al]])
            for k in (1, -1):
                row = np.zeros(2 * c)
                row[c + al], row[al] = k, -mu[al]
                ub.append(row)
                ub_b.append(0.0)
    bounds = [(0, None)] * c + [(None, None) if m > 0 else (0, 0) for m in mu]
    return dict(A_ub=np.array(ub) if ub else None, b_ub=ub_b if ub else None,
                A_eq=np.vstack(eq), b_eq=np.concatenate(eq_b), bounds=bounds)


def state_set_lps(system: models.System):
    """For every state set s in {+1, -1, 0}^F (F: the frictional contacts) that velocities admit
    (s v_t >= 1 sliding, v_t = 0 non-sliding, V free: gamma != 0), the force LP of its valid
    steady states: (s, dict of linprog's A_ub, b_ub, A_eq, b_eq, bounds over x = [R; S]) with
    no translation, a_n = 0, Coulomb and the states' laws (`pattern_lp` of s)."""
    dyn = Dynamics(system)
    c, p = system.c, system.p
    H = dyn.H.toarray()
    T = np.column_stack([H[c:, 2 * p:], dyn.u_obs(1.0)[c:]])  # v_t = T [omega; V]
    fr = np.flatnonzero(system.mu > 0)
    for states in itertools.product((1, -1, 0), repeat=fr.size):
        s = np.zeros(c, dtype=int)
        s[fr] = states
        sl, ns = fr[s[fr] != 0], fr[s[fr] == 0]
        kin = linprog(np.zeros(p + 1), A_ub=-(s[sl][:, None] * T[sl]) if sl.size else None,
                      b_ub=-np.ones(sl.size) if sl.size else None,
                      A_eq=T[ns] if ns.size else None, b_eq=np.zeros(ns.size) if ns.size else None,
                      bounds=[(None, None)] * (p + 1), method="highs")
        if kin.status != 0:
            continue
        yield s, pattern_lp(system, states)


@pytest.fixture(scope="session")
def state_lps():
    """state_set_lps, for the tests."""
    return state_set_lps


@pytest.fixture(scope="session")
def q_pattern_lp():
    """pattern_lp, for the tests."""
    return pattern_lp


def best_over(L: np.ndarray, sense: int, lps) -> tuple[str, float]:
    """("optimal", value) / ("unbounded", inf) of min (sense +1) or max (sense -1) of L x over
    the union of the polyhedra of `lps` (linprog's arguments, e.g. of `pattern_lp` or
    `state_set_lps`): the best of their LPs; an unbounded one makes the union unbounded."""
    best = None
    for lp in lps:
        r = linprog(sense * L, **lp, method="highs",
                    options={"primal_feasibility_tolerance": 1e-10})
        if r.status == 3:
            return "unbounded", np.inf
        if r.status == 0 and (best is None or r.fun < best):
            best = r.fun
    assert best is not None, "every LP empty: no point to take the best of"
    return "optimal", sense * best


@pytest.fixture(scope="session")
def lp_union_best():
    """best_over, for the tests."""
    return best_over
