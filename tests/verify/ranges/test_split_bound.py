"""verify.ranges.split (a certified lower bound by a case split on contact states, plane
contacts first) against the big-M MILP's proved ends on small systems:

* with the target at the proved end, every case closes and the bound equals the end (to the
  rounding margin): never above it;
* with the target above the end, the case holding the optimum never closes, and the bound
  stays at or below the end (a bound, whatever the time limit);
* the root case's bound (no state fixed) is below every end.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import models
from rigidlcp.verify.ranges import steady_ranges
from rigidlcp.verify.ranges.cap_split import cap_contacts, cap_split_bound
from rigidlcp.verify.ranges.milp import MilpModel
from rigidlcp.verify.ranges.observables import mu_g_vector
from rigidlcp.verify.ranges.split import case_bound, split_bound
from rigidlcp.verify.ranges.steady import formulate

SYSTEMS = [(models.rectangular(3, 2), 0.16), (models.triangular(3, 2), 0.16),
           (models.rectangular(2, 1), -0.1)]


def _ends(lattice, gamma):
    system = models.System(lattice, mu_pp=0.1, mu_plane=0.2, mu_wall=0.0, gamma=gamma)
    r = steady_ranges(system, which="mu_g", time_limit=60, kinematics="big-M").mu_g
    assert r.lo.status == r.hi.status == "optimal"
    form = formulate(system)
    model = MilpModel(form)
    L = np.zeros(model.n)
    L[:2 * system.c] = mu_g_vector(system)
    return model, L, float(r.lo.value), float(r.hi.value)


@pytest.mark.parametrize("lattice, gamma", SYSTEMS)
def test_split_bound_closes_at_the_big_M_end(lattice, gamma):
    model, L, lo, hi = _ends(lattice, gamma)
    for cost, end in ((L, lo), (-L, -hi)):
        res = split_bound(model, cost, end, time_limit=60)
        assert res.closed, res
        assert res.bound <= end + 1e-12
        assert res.bound >= end - 1e-8 * max(1.0, abs(end))
        assert case_bound(model, cost, {})[0] <= end + 1e-12


@pytest.mark.parametrize("lattice, gamma", SYSTEMS)
def test_split_bound_never_passes_the_end(lattice, gamma):
    model, L, lo, hi = _ends(lattice, gamma)
    for cost, end in ((L, lo), (-L, -hi)):
        res = split_bound(model, cost, end + 0.05, time_limit=5)
        assert not res.closed
        assert res.bound <= end + 1e-12


# --- verify.ranges.cap_split: the case split on the cap contacts with a_t = 0 ---------------

def _witnesses(system):
    r = steady_ranges(system, which="alpha", time_limit=60, kinematics="big-M")
    return r, [e.witness for rg in r.ranges.values() for e in (rg.lo, rg.hi)
               if e.witness is not None and e.witness.residual <= 1e-8]


@pytest.mark.parametrize("lattice, gamma", SYSTEMS)
def test_cap_split_facts_hold_on_valid_steady_states(lattice, gamma):
    """(a) and (c) of cap_split's docstring on every witness (checked valid steady states; the
    alpha ends put disks at the cap, so (c) is met with Z nonempty), computed here from
    models.Dynamics: a_t = H nu' + u_obs'."""
    system = models.System(lattice, mu_pp=0.1, mu_plane=0.2, mu_wall=0.0, gamma=gamma)
    form = formulate(system)
    caps = cap_contacts(form)
    assert caps is not None
    beta, disk, eps, M = caps
    assert M == pytest.approx(abs(gamma))
    dyn, c, r = form.dyn, system.c, system.lattice.radius
    _, wits = _witnesses(system)
    met = 0
    for w in wits:
        lam = np.concatenate([w.R, w.S])
        a_t = (dyn.H @ dyn.accelerations(lam) + dyn.u_obs_dot)[c:][beta]
        b = np.asarray(dyn.u_obs_dot)[c:][beta]
        z = np.abs(a_t) <= 1e-9
        scale = max(1.0, float(np.max(np.abs(lam))))
        # (a) off Z: sliding with s = sgn b
        np.testing.assert_allclose(w.S[beta][~z], -np.sign(b[~z]) * 0.2 * w.R[beta][~z],
                                   atol=1e-8 * scale)
        if z.any():
            met += 1
            I = 1.0 / dyn.Minv[2 * system.p:]
            lhs = -float(np.sum(np.sign(b[z]) * w.S[beta][z]))
            rhs = M * float(np.sum(I[np.unique(disk[z])] / r ** 2))
            assert lhs >= rhs - 1e-8 * scale
    assert met > 0


@pytest.mark.parametrize("lattice, gamma", SYSTEMS)
def test_cap_split_bound_below_the_big_M_end(lattice, gamma):
    model, L, lo, hi = _ends(lattice, gamma)
    system = model.form.system
    res = cap_split_bound(model.form, mu_g_vector(system))
    assert res is not None and res.cases == 2 ** len(cap_contacts(model.form)[0])
    assert res.bound <= lo + 1e-12
    assert np.isfinite(res.bound)


@pytest.mark.parametrize("lattice, gamma", SYSTEMS[:2])
def test_open_ends_get_proved_bounds_around_the_big_M_ends(lattice, gamma):
    """Ends left undecided (here made so) get bounds that contain the big-M MILP's ends; with
    no witness they stay undecided, and the JSON's "bounds" carries them (null stays in
    "mu_g")."""
    from rigidlcp.verify.ranges import End, Range
    from rigidlcp.verify.ranges.cap_split import bound_open_ends
    from rigidlcp.verify.ranges.valid_steady import SteadyRanges

    model, L, lo, hi = _ends(lattice, gamma)
    form = model.form
    rg = {"mu_g": Range("mu_g", End("time limit"), End("time limit"))}
    bound_open_ends(form, rg, {"mu_g": mu_g_vector(form.system)})
    e_lo, e_hi = rg["mu_g"].lo, rg["mu_g"].hi
    assert e_lo.status == e_hi.status == "time limit"
    assert e_lo.bound <= lo + 1e-12 and e_hi.bound >= hi - 1e-12
    d = SteadyRanges(form.system, rg, form.U, form.box_proved, form.V_mode, 0.0).to_dict()
    assert d["steady"]["mu_g"] == [None, None]
    assert d["steady"]["bounds"]["mu_g"] == [e_lo.bound, e_hi.bound]


@pytest.mark.slow
def test_cap_split_on_fig9_below_a_checked_witness():
    """Fig. 9's system: the cap split's bound is positive and below the least mu_g of the
    rolling-checkerboard seeds (each checked by steady_check here); every plane contact is a
    cap contact (b = -gamma)."""
    from rigidlcp.models.lattice import PLANE
    from rigidlcp.verify.ranges.steady import state_extreme, state_velocities
    from rigidlcp.verify.ranges.valid_steady import seed_states
    from rigidlcp.verify.ranges.witness import steady_check

    system = models.System(models.rectangular(10, 4), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.16)
    form = formulate(system)
    beta, _, _, M = cap_contacts(form)
    assert set(beta) == set(np.flatnonzero(system.lattice.j == PLANE)) and M == 0.16
    L = mu_g_vector(system)
    res = cap_split_bound(form, L)
    assert res.bound > 0
    c, met = system.c, []
    for s in seed_states(form):
        status, x, _ = state_extreme(form, s, L, 1)
        vel = state_velocities(form, s)
        if status == "optimal" and vel is not None:
            if steady_check(system, vel[0], vel[1], x[:c], x[c:], form.dyn)[0] <= 1e-8:
                met.append(float(L @ x))
    assert met and res.bound <= min(met)


def _cap_case_min(form, L, z):
    """min L . x over cap_split's case Z (z: a mask over the cap contacts), written here from
    the docstring with scipy's linprog, cold: None when the case is empty."""
    from itertools import chain

    from scipy.optimize import linprog

    from rigidlcp.verify.ranges.observables import alpha_rows
    from rigidlcp.verify.ranges.steady import _equalities

    system, dyn = form.system, form.dyn
    c, p, mu, r = system.c, system.p, system.mu, system.lattice.radii
    beta, disk, eps, M = cap_contacts(form)
    b = np.asarray(dyn.u_obs_dot, float)[c:]
    ra = r[:, None] * alpha_rows(system, dyn)
    E, e = _equalities(dyn)
    I2 = np.eye(2 * c)
    fr = np.flatnonzero(mu > 0)
    A_ub = list(chain(-(mu[fr, None] * I2[fr] - I2[c + fr]), -(mu[fr, None] * I2[fr] + I2[c + fr]),
                      ra, -ra))
    b_ub = list(chain(np.zeros(2 * fr.size), np.full(2 * p, M)))
    A_eq, b_eq = list(E), list(e)
    for k in range(beta.size):
        if z[k]:  # (b): the disk at the cap
            A_eq.append(eps[k] * ra[disk[k]])
            b_eq.append(-b[beta[k]])
        else:  # (a): sliding with s = sgn b
            A_eq.append(mu[beta[k]] * np.sign(b[beta[k]]) * I2[beta[k]] + I2[c + beta[k]])
            b_eq.append(0.0)
    if z.any():  # (c)
        D = r * r * dyn.Minv[2 * p:]
        row = np.zeros(2 * c)
        row[c + beta[z]] = np.sign(b[beta[z]])
        A_ub.append(row)
        b_ub.append(-M * float(np.sum(1.0 / D[np.unique(disk[z])])))
    res = linprog(L, A_ub=np.array(A_ub), b_ub=np.array(b_ub), A_eq=np.array(A_eq),
                  b_eq=np.array(b_eq), bounds=list(zip(form.lb[:2 * c], form.ub[:2 * c])),
                  method="highs")
    assert res.status in (0, 2), res.message
    return None if res.status == 2 else float(res.fun)


@pytest.mark.parametrize("lattice, gamma", [(models.rectangular(3, 2), 0.16),
                                            (models.rectangular(4, 1), -0.1)])
def test_cap_split_bound_is_the_least_case_minimum(lattice, gamma):
    """The cases are visited in Gray-code order, each from the previous one's LP (one cap
    contact changed): the bound equals the least minimum over all 2^n cases, each solved here
    cold and independently, to the certificate's margin; the worst case attains it."""
    from itertools import product

    system = models.System(lattice, mu_pp=0.1, mu_plane=0.2, mu_wall=0.0, gamma=gamma)
    form = formulate(system)
    beta = cap_contacts(form)[0]
    for L in (mu_g_vector(system), -mu_g_vector(system)):
        res = cap_split_bound(form, L)
        mins = {z: _cap_case_min(form, L, np.array(z)) for z in product((False, True),
                                                                         repeat=beta.size)}
        least = min(v for v in mins.values() if v is not None)
        assert res.cases == len(mins)
        assert res.empty <= sum(v is None for v in mins.values())
        assert res.bound <= least + 1e-12
        assert res.bound >= least - 1e-8 * max(1.0, abs(least))
        worst = tuple(k in res.worst for k in beta)
        assert mins[worst] is not None and mins[worst] <= res.bound + 1e-8


@settings(max_examples=15)
@given(lx=st.integers(1, 4), ly=st.integers(1, 2), mu_pp=st.sampled_from([0.05, 0.1, 0.3]),
       mu_plane=st.sampled_from([0.1, 0.2, 0.5]),
       gamma=st.sampled_from([-0.2, -0.05, 0.02, 0.16]), seed=st.integers(0, 2 ** 16))
def test_cap_split_bound_is_the_least_case_minimum_on_random_systems(lx, ly, mu_pp, mu_plane,
                                                                     gamma, seed):
    """The same on random small arrays and a random observable of S (the force box is proved
    for it), against the 2^n cases solved cold here."""
    from itertools import product

    from rigidlcp.lcp.errors import RigidLCPError

    system = models.System(models.rectangular(lx, ly), mu_pp=mu_pp, mu_plane=mu_plane,
                           mu_wall=0.0, gamma=gamma)
    try:
        form = formulate(system)
    except RigidLCPError:  # no steady state with every contact closed: nothing to bound
        return
    c = system.c
    L = np.zeros(2 * c)
    L[c:] = np.random.default_rng(seed).normal(size=c) * (system.mu > 0)
    res = cap_split_bound(form, L)
    if res is None:
        return
    beta = cap_contacts(form)[0]
    mins = [_cap_case_min(form, L, np.array(z)) for z in product((False, True),
                                                                 repeat=beta.size)]
    least = min((v for v in mins if v is not None), default=np.inf)
    assert res.cases == len(mins)
    if np.isfinite(least):
        assert res.bound <= least + 1e-9 * max(1.0, abs(least))
        assert res.bound >= least - 1e-7 * max(1.0, abs(least))
    else:
        assert res.bound == np.inf or res.bound <= least
