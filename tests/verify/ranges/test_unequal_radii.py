"""verify.ranges.steady_ranges on packings with unequal radii (issue 22, point 4): a closed
form by hand, a brute force over every sign pattern of a_t, and seeded piles.

Closed form: two disks on the plane, radii r1 = 0.8 (left, touching the left wall) and
r2 = 1.2 (right, touching the right wall), touching each other; masses 1, moments of inertia
I1 = 0.3, I2 = 0.9 (not m r^2 / 2, so that r_i and I_i enter separately); g = 1, gamma = 0.4;
walls and the disk-disk contact frictionless, plane mu = 0.3. Centres (r1, r1) and
(r1 + 2 sqrt(r1 r2), r2): the disk-disk normal n = (c, s), c = 2 sqrt(r1 r2) / (r1 + r2),
s = (r2 - r1) / (r1 + r2) = 0.2. With N >= 0 the disk-disk force, the plane's tangential force
on disk i entering as in tests/verify/ranges/test_steady_closed_forms.py (-S_Pi horizontally):

    disk 1: R_L - N c - S_P1 - gamma = 0,  R_P1 = 1 + N s,  I1 alpha1 = -r1 S_P1,
    disk 2: N c - R_R - S_P2 - gamma = 0,  R_P2 = 1 - N s,  I2 alpha2 = -r2 S_P2,
    plane a_t,i = -gamma - r_i alpha_i = -gamma + r_i^2 S_Pi / I_i.

With k_i = I_i / r_i^2 (k1 = 0.46875, k2 = 0.625): rolling (a_t = 0) gives S_Pi = k_i gamma,
admissible iff k_i gamma <= mu R_Pi; sliding with v_t < 0 gives S_Pi = mu R_Pi and a_t <= 0
iff mu R_Pi <= k_i gamma; sliding with v_t > 0 gives a_t < 0: never. So
S_Pi = min(k_i gamma, mu R_Pi). Disk 1: k1 gamma = 0.1875 < mu R_P1 (>= 0.3): S_P1 = 0.1875,
alpha1 = -gamma / r1 = -0.5 for every N. Disk 2: S_P2 = min(0.25, 0.3 (1 - 0.2 N)), with
R_P2 >= 0 (N <= 5) and R_R >= 0 (N c >= S_P2 + gamma, N >= 0.664 at most): N in [0.6634, 5],
S_P2 from 0.25 (N <= 5/6) down to 0 (N = 5). Hence mu_g = (S_P1 + S_P2) / 2 in
[0.09375, 0.21875] and alpha2 = -r2 S_P2 / I2 in [-1/3, 0].
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.lattice import PLANE
from rigidlcp.models.packing import packing
from rigidlcp.verify.ranges import steady_ranges
from rigidlcp.verify.ranges.observables import mu_g_vector
from rigidlcp.verify.ranges.steady import NotSteady
from rigidlcp.verify.ranges.witness import steady_check

R1, R2, I1, I2 = 0.8, 1.2, 0.3, 0.9


def _two_disks() -> models.System:
    x2 = R1 + 2.0 * np.sqrt(R1 * R2)
    lat = packing([[R1, R1], [x2, R2]], [R1, R2], m=[1.0, 1.0], I=[I1, I2], left=0.0,
                  right=x2 + R2)
    return models.System(lat, mu_pp=0.0, mu_plane=0.3, mu_wall=0.0, gamma=0.4)


def test_two_disks_of_unequal_radii_closed_form():
    s = _two_disks()
    lat = s.lattice
    assert s.c == 5 and sorted(lat.j.tolist()).count(PLANE) == 2
    res = steady_ranges(s, which="alpha", time_limit=30)
    expect = {"mu_g": (0.09375, 0.21875), "alpha[0]": (-0.5, -0.5),
              "alpha[1]": (-1.0 / 3.0, 0.0)}
    for name, (lo, hi) in expect.items():
        r = res.ranges[name]
        assert r.lo.status == r.hi.status == "optimal", name
        assert r.lo.value == pytest.approx(lo, abs=1e-9), name
        assert r.hi.value == pytest.approx(hi, abs=1e-9), name
        assert r.scope == "all valid steady states", name
        for e in (r.lo, r.hi):  # each witness a valid steady state by the independent check
            w = e.witness
            res_w, _ = steady_check(s, w.omega, w.V, w.R, w.S)
            assert res_w <= 1e-9, name


def test_steady_check_by_hand_on_two_disks():
    """steady_check with per-disk radii: the state N = 1 of the closed form (disk 1 rolling,
    disk 2 sliding back: S_P2 = 0.3 (1 - 0.2) = 0.24 <= k2 gamma = 0.25) moving at
    (omega, V) = (alpha, gamma) is valid; the same forces with disk 2's spin from the mean
    radius (r = 1, which an equal-radii formula would use) are not."""
    s = _two_disks()
    lat, dyn = s.lattice, Dynamics(s)
    c_, s_ = 2 * np.sqrt(R1 * R2) / (R1 + R2), (R2 - R1) / (R1 + R2)
    N, gamma = 1.0, 0.4
    SP = {0: 0.1875, 1: 0.3 * (1 - s_ * N)}
    RP = {0: 1 + N * s_, 1: 1 - N * s_}
    R, S = np.zeros(s.c), np.zeros(s.c)
    for a in range(s.c):
        if lat.j[a] == PLANE:
            R[a], S[a] = RP[lat.i[a]], SP[lat.i[a]]
        elif lat.j[a] >= 0:
            R[a] = N
        elif lat.i[a] == 0:
            R[a] = N * c_ + SP[0] + gamma
        else:
            R[a] = N * c_ - SP[1] - gamma
    alpha = dyn.accelerations(np.concatenate([R, S]))[2 * s.p:]
    assert alpha == pytest.approx([-R1 * SP[0] / I1, -R2 * SP[1] / I2], abs=1e-12)
    assert np.allclose(dyn.accelerations(np.concatenate([R, S]))[:2 * s.p], 0.0, atol=1e-12)
    res, states = steady_check(s, alpha, gamma, R, S)
    assert res <= 1e-12
    plane = np.flatnonzero(lat.j == PLANE)
    assert sorted(states[plane].tolist()) == [-1, 0]  # disk 1 rolls, disk 2 slides back
    # disk 2 turning at r = 1's rate: its plane contact slides the other way, S breaks the law
    wrong = alpha.copy()
    wrong[1] = -(gamma + 0.5) / 1.0
    res_wrong, _ = steady_check(s, wrong, gamma, R, S)
    assert res_wrong > 1e-3


def _brute_force(system: models.System, obs: dict[str, np.ndarray], pattern_lp
                 ) -> dict[str, tuple[float, float]]:
    """{name: (min, max)} of L . x over every sign pattern of a_t (+, -, 0 per frictional
    contact): one feasibility LP each, then the extremes on the feasible ones, each LP
    conftest's pattern_lp (from models.dynamics alone: a_n = 0, no translation, R >= 0,
    |S| <= mu R, S = 0 where mu = 0; pattern + : a_t >= 0, S = -mu R; - : a_t <= 0,
    S = +mu R; 0 : a_t = 0; docs/mechanics.md, 'Through proportional velocities'). +-inf
    where some pattern's LP is unbounded; (inf, -inf) when no pattern is feasible."""
    c = system.c
    out = {name: (np.inf, -np.inf) for name in obs}
    for pattern in itertools.product((1, -1, 0), repeat=int(np.count_nonzero(system.mu > 0))):
        kw = dict(**pattern_lp(system, pattern), method="highs")
        if linprog(np.zeros(2 * c), **kw).status != 0:
            continue
        for name, L in obs.items():
            lo, hi = out[name]
            for sense in (1.0, -1.0):
                r = linprog(sense * L, **kw)
                assert r.status in (0, 3), r.message
                val = -sense * np.inf if r.status == 3 else sense * r.fun
                lo, hi = min(lo, val), max(hi, val)
            out[name] = (lo, hi)
    return out


@pytest.mark.parametrize("n, seed", [(3, 4), (3, 1), pytest.param(4, 1, marks=pytest.mark.slow),
                                     pytest.param(4, 2, marks=pytest.mark.slow)])
def test_brute_force_over_sign_patterns_of_a_t(q_pattern_lp, n, seed):
    """gamma != 0 (the reduction is exact): steady_ranges against 3^F LPs; (3, 1) has no
    valid steady state by the brute force, and steady_ranges must say so (NotSteady)."""
    pile = deposit(n, seed=seed, radii=(0.7, 1.3), width=2.0 * n)
    assert np.ptp(pile.radii) > 0
    system = models.System(pile, mu_pp=0.2, mu_plane=0.3, mu_wall=0.1, gamma=0.2)
    assert np.count_nonzero(system.mu > 0) <= 8  # 3^F LPs
    dyn = Dynamics(system)
    obs = {"mu_g": mu_g_vector(system)}
    rot = dyn.Minv[2 * system.p:, None] * dyn.H.T.toarray()[2 * system.p:]
    obs.update({f"alpha[{i}]": rot[i] for i in range(system.p)})
    brute = _brute_force(system, obs, q_pattern_lp)
    if brute["mu_g"][0] > brute["mu_g"][1]:  # no pattern feasible
        with pytest.raises(NotSteady):
            steady_ranges(system, which="alpha", time_limit=30)
        return
    res = steady_ranges(system, which="alpha", time_limit=30)
    for name, (lo, hi) in brute.items():
        r = res.ranges[name]
        for end, want in ((r.lo, lo), (r.hi, hi)):
            assert end.status in ("optimal", "unbounded"), (name, end.status)
            assert end.value == pytest.approx(want, abs=1e-7), name
            if end.witness is not None:
                w = end.witness
                assert steady_check(system, w.omega, w.V, w.R, w.S)[0] <= 1e-9, name


@settings(max_examples=6, deadline=None)
@given(n=st.integers(3, 6), seed=st.integers(0, 40), mu=st.sampled_from([0.1, 0.2]))
def test_seeded_unequal_radii_piles_that_reach_a_steady_state(n, seed, mu):
    """Every decided end's witness is a valid steady state; the run's own mu_g lies in the
    range (its state is one of them)."""
    pile = deposit(n, seed=seed, radii=(0.8, 1.2), width=2.0 * n)
    system = models.System(pile, mu_pp=mu, mu_plane=mu, mu_wall=mu, gamma=0.1)
    run = models.simulate(system, seed=1)
    assume(run.status == "steady")
    res = steady_ranges(run, which="alpha", time_limit=20)
    for name, r in res.ranges.items():
        for e in (r.lo, r.hi):
            assert e.status in ("optimal", "unbounded", "time limit"), (name, e.status)
            if e.witness is not None:
                w = e.witness
                assert steady_check(system, w.omega, w.V, w.R, w.S)[0] <= 1e-9, name
    mg = res.ranges["mu_g"]
    tol = 1e-9 * max(1.0, abs(res.run_values["mu_g"]))
    if mg.lo.status == "optimal":
        assert mg.lo.value <= res.run_values["mu_g"] + tol
    if mg.hi.status == "optimal":
        assert res.run_values["mu_g"] <= mg.hi.value + tol
