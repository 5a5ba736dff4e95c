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
from rigidlcp.models.lattice import PLANE
from rigidlcp.verify.ranges import event_ranges, steady_ranges
from rigidlcp.verify.ranges.event import event_observables


def _steady_brute(state_lps, system: models.System, sense: int, best_over
                  ) -> tuple[str, float]:
    """("optimal", value) / ("unbounded", inf) of sense * mu_g over every valid steady state:
    the best of the force LPs of every state set the velocities admit (conftest)."""
    c = system.c
    g = np.zeros(2 * c)
    g[c + np.flatnonzero(system.lattice.j == PLANE)] = 1.0 / (system.total_mass * system.g)
    return best_over(g, sense, (lp for _, lp in state_lps(system)))


@pytest.mark.parametrize("lx, mu_pp, mu_plane, mu_wall, gamma", [
    (2, 0.1, 0.2, 0.0, 0.05),
    (2, 0.3, 0.1, 0.0, 0.15),
    (3, 0.05, 0.1, 0.0, 0.02),
])
def test_steady_mu_g_range_equals_enumeration(state_lps, lp_union_best, lx, mu_pp, mu_plane,
                                              mu_wall, gamma):
    s = models.System(models.rectangular(lx, 1), mu_pp=mu_pp, mu_plane=mu_plane,
                      mu_wall=mu_wall, gamma=gamma)
    res = steady_ranges(s, time_limit=30)
    for end, sense in ((res.mu_g.lo, 1), (res.mu_g.hi, -1)):
        status, value = _steady_brute(state_lps, s, sense, lp_union_best)
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
    assert res.proved  # by the proved box, or by the pattern search without it
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
