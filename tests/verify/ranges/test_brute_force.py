"""verify.ranges against brute force written here, independently of the code under test:

* steady states: every tangential state set in {+1, -1, 0}^F of a tiny system, each with a
  velocity LP (is there (omega, V) with these signs?) and a force LP (extreme of mu_g), both
  built from models.Dynamics (H, M^-1, f, u_obs) and the definition in docs/mechanics.md;
* events: every complementary pattern of a small event LCP, an LP per pattern.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.optimize import linprog

from rigidlcp import lcp, models
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.lattice import PLANE
from rigidlcp.verify.ranges import event_ranges, steady_ranges
from rigidlcp.verify.ranges.event import event_observables


def _steady_brute(system: models.System, sense: int) -> tuple[str, float]:
    """("optimal", value) / ("unbounded", inf) of sense * mu_g over every valid steady state."""
    dyn = Dynamics(system)
    c, p, mu = system.c, system.p, system.mu
    H = dyn.H.toarray()
    Minv, f = dyn.Minv, dyn.f
    acc = Minv[:, None] * H.T  # nu' = acc @ x + Minv f
    a_rel = H @ acc  # a = a_rel x + H Minv f + u_obs'
    a0 = H @ (Minv * f) + dyn.u_obs_dot
    Tw = H[c:, 2 * p:]  # v_t = Tw omega + TV V
    TV = dyn.u_obs(1.0)[c:]
    fr = np.flatnonzero(mu > 0)
    g = np.zeros(2 * c)
    g[c + np.flatnonzero(system.lattice.j == PLANE)] = 1.0 / (system.total_mass * system.g)
    best = None
    for states in itertools.product((1, -1, 0), repeat=fr.size):
        s = np.zeros(c, dtype=int)
        s[fr] = states
        # velocities: s v_t >= 1 (sliding), v_t = 0 (non-sliding); V free (gamma != 0)
        sl, ns = fr[s[fr] != 0], fr[s[fr] == 0]
        T = np.column_stack([Tw, TV])
        kin = linprog(np.zeros(p + 1), A_ub=-(s[sl][:, None] * T[sl]) if sl.size else None,
                      b_ub=-np.ones(sl.size) if sl.size else None,
                      A_eq=T[ns] if ns.size else None, b_eq=np.zeros(ns.size) if ns.size else None,
                      bounds=[(None, None)] * (p + 1), method="highs")
        if kin.status != 0:
            continue
        # forces: no translation, a_n = 0, Coulomb, the states' laws
        eq = [acc[:2 * p], a_rel[:c]]
        eq_b = [-(Minv * f)[:2 * p], -a0[:c]]
        ub, ub_b = [], []
        for al in range(c):
            if mu[al] == 0:
                continue
            row = np.zeros(2 * c)
            if s[al] != 0:
                row[c + al], row[al] = 1.0, s[al] * mu[al]
                eq.append(row[None])
                eq_b.append([0.0])
                ub.append(-s[al] * a_rel[c + al])
                ub_b.append(s[al] * a0[c + al])
            else:
                eq.append(a_rel[c + al][None])
                eq_b.append([-a0[c + al]])
                for sg in (1, -1):
                    row = np.zeros(2 * c)
                    row[c + al], row[al] = sg, -mu[al]
                    ub.append(row)
                    ub_b.append(0.0)
        bounds = [(0, None)] * c + [(None, None) if m > 0 else (0, 0) for m in mu]
        r = linprog(sense * g, A_ub=np.array(ub) if ub else None, b_ub=ub_b if ub else None,
                    A_eq=np.vstack(eq), b_eq=np.concatenate(eq_b), bounds=bounds,
                    method="highs", options={"primal_feasibility_tolerance": 1e-10})
        if r.status == 3:
            return "unbounded", np.inf
        if r.status == 0 and (best is None or r.fun < best):
            best = r.fun
    assert best is not None
    return "optimal", sense * best


@pytest.mark.parametrize("lx, mu_pp, mu_plane, mu_wall, gamma", [
    (2, 0.1, 0.2, 0.0, 0.05),
    (2, 0.3, 0.1, 0.0, 0.15),
    (3, 0.05, 0.1, 0.0, 0.02),
])
def test_steady_mu_g_range_equals_enumeration(lx, mu_pp, mu_plane, mu_wall, gamma):
    s = models.System(models.rectangular(lx, 1), mu_pp=mu_pp, mu_plane=mu_plane,
                      mu_wall=mu_wall, gamma=gamma)
    res = steady_ranges(s, time_limit=30)
    for end, sense in ((res.mu_g.lo, 1), (res.mu_g.hi, -1)):
        status, value = _steady_brute(s, sense)
        assert end.status == status
        if status == "optimal":
            assert end.value == pytest.approx(value, abs=1e-9)
            assert end.witness.mu_g == pytest.approx(value, abs=1e-9)  # attained


def _event_brute(M, q, Ls):
    """{(k, sense): ("optimal", value) | ("unbounded", inf)} over every pattern: a feasibility
    LP per pattern, then an LP per observable and sense on the feasible ones."""
    n = q.size
    best: dict = {}
    for y in itertools.product((0, 1), repeat=n):
        y = np.array(y, bool)
        eq, ub = np.flatnonzero(y), np.flatnonzero(~y)
        kw = dict(A_ub=-M[ub] if ub.size else None, b_ub=q[ub] if ub.size else None,
                  A_eq=M[eq] if eq.size else None, b_eq=-q[eq] if eq.size else None,
                  bounds=[(0, None) if v else (0, 0) for v in y], method="highs")
        if linprog(np.zeros(n), **kw).status != 0:
            continue
        for k, L in enumerate(Ls):
            for sense in (1, -1):
                r = linprog(sense * L, **kw)
                old = best.get((k, sense))
                if r.status == 3:
                    best[(k, sense)] = ("unbounded", np.inf)
                elif r.status == 0 and (old is None or (old[0] == "optimal"
                                                        and r.fun < sense * old[1])):
                    best[(k, sense)] = ("optimal", r.fun * sense)
    return best


@pytest.mark.parametrize("gamma, seed", [(0.1, None), (0.3, None), (0.2, 2)])
def test_event_ranges_equal_enumeration(gamma, seed):
    """rect 2x1 (mu_wall = 0): from rest (seed None) every frictional contact is a
    non-sliding candidate, n = 11 (2048 patterns); seed 2: random spins, all sliding."""
    s = models.System(models.rectangular(2, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=gamma)
    ep = models.event_problem(s, models.initial_state(s, seed=seed))
    assert ep.lcp.n <= 11
    sol = lcp.solve(ep.lcp)
    res = event_ranges(ep, sol, time_limit=20)
    M, q = np.asarray(ep.lcp.M, float), np.asarray(ep.lcp.q, float)
    obs = event_observables(ep)
    names = ("mu_g", "alpha[0]", "alpha[1]")
    brute = _event_brute(M, q, [obs[k] for k in names])
    for k, name in enumerate(names):
        r = res.every[name]
        for end, sense in ((r.lo, 1), (r.hi, -1)):
            status, value = brute[(k, sense)]
            if status == "optimal":
                assert end.status == "optimal", (name, end)
                assert end.value == pytest.approx(value, abs=1e-9)
                assert obs[name] @ end.witness == pytest.approx(value, abs=1e-9)  # attained
            else:
                assert end.status == "unbounded", (name, end)
        face = res.face[name]
        assert face.lo.value >= r.lo.value - 1e-9 and face.hi.value <= r.hi.value + 1e-9
        assert r.contains(res.selected[name]) and face.contains(res.selected[name])
