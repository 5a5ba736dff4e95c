"""The faster search of verify.ranges (issue 21's speed target) against the previous one and
against linear programs written here:

* lazy kinematics (the MILP without the velocities' big-M rows, contact-state sets the
  velocities refuse cut off one negative cycle at a time) gives the same ends as the big-M
  MILP on small systems (rectangular and triangular);
* `kinematics.realizable` agrees with a velocity LP built here from models.Dynamics, its
  velocities have the signs asked, and the contacts of its negative cycle alone admit none;
* the certified Lagrangian bound of verify.ranges.milp never exceeds an LP's optimum and meets
  it at the optimal duals;
* the rotation cap |r alpha_i| <= |gamma| holds on valid steady states of random velocities.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from rigidlcp import models
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.verify.ranges import steady_ranges
from rigidlcp.verify.ranges.bounds import rotation_cap
from rigidlcp.verify.ranges.kinematics import realizable
from rigidlcp.verify.ranges.milp import lagrangian_bound
from rigidlcp.verify.ranges.steady import formulate


def _same_ends(system, which="alpha"):
    a = steady_ranges(system, which=which, time_limit=60, kinematics="lazy")
    b = steady_ranges(system, which=which, time_limit=60, kinematics="big-M")
    for name, ra in a.ranges.items():
        rb = b.ranges[name]
        for ea, eb in ((ra.lo, rb.lo), (ra.hi, rb.hi)):
            assert ea.status == eb.status == "optimal", (name, ea, eb)
            assert ea.value == pytest.approx(eb.value, abs=1e-9), name
            assert ea.witness.residual <= 1e-8


@pytest.mark.parametrize("lattice, gamma", [
    (models.rectangular(3, 2), 0.16),
    (models.triangular(3, 2), 0.16),
    (models.rectangular(2, 1), -0.1),
])
def test_lazy_kinematics_equal_big_M(lattice, gamma):
    _same_ends(models.System(lattice, mu_pp=0.1, mu_plane=0.2, mu_wall=0.0, gamma=gamma))


@pytest.mark.slow
@pytest.mark.parametrize("lx, ly, gamma, which", [(10, 1, 0.02, "alpha"), (4, 2, 0.16, "alpha")])
def test_lazy_kinematics_equal_big_M_larger(lx, ly, gamma, which):
    _same_ends(models.System(models.rectangular(lx, ly), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                             gamma=gamma), which)


def _velocity_lp(T: np.ndarray, s: np.ndarray, rows: np.ndarray, V_fixed: bool) -> bool:
    """Is there x = (r omega, V) with s v >= 1 (sliding) and v = 0 (non-sliding) on `rows`?"""
    sl = [a for a in rows if s[a] != 0]
    ns = [a for a in rows if s[a] == 0]
    bounds = [(None, None)] * T.shape[1]
    if V_fixed:
        bounds[-1] = (0, 0)
    r = linprog(np.zeros(T.shape[1]),
                A_ub=-(s[sl][:, None] * T[sl]) if sl else None, b_ub=-np.ones(len(sl)) if sl
                else None, A_eq=T[ns] if ns else None, b_eq=np.zeros(len(ns)) if ns else None,
                bounds=bounds, method="highs")
    return r.status == 0


@settings(max_examples=20, deadline=None)
@given(lx=st.integers(2, 5), ly=st.integers(1, 3), tri=st.booleans(),
       gamma=st.sampled_from([0.16, 0.0]), seed=st.integers(0, 10_000))
def test_realizable_agrees_with_a_velocity_lp(lx, ly, tri, gamma, seed):
    lattice = (models.triangular if tri else models.rectangular)(lx, ly)
    system = models.System(lattice, mu_pp=0.1, mu_plane=0.2, mu_wall=0.1, gamma=gamma)
    form = formulate(system)
    dyn = Dynamics(system)
    c, p, r = system.c, system.p, lattice.radius
    T = np.column_stack([dyn.H[c:].toarray()[:, 2 * p:] / r, dyn.u_obs(1.0)[c:]])
    fric = np.flatnonzero(system.mu > 0)
    rng = np.random.default_rng(seed)
    for k in range(6):
        if k % 2:  # the signs of random integer velocities, a few changed
            x = rng.integers(-2, 3, p + 1).astype(float)
            if gamma == 0:
                x[-1] = 0.0
            s = np.where(system.mu > 0, np.sign(T @ x), 0).astype(int)
            idx = rng.choice(fric, min(2, fric.size), replace=False)
            s[idx] = rng.integers(-1, 2, idx.size)
        else:
            s = np.zeros(c, dtype=int)
            s[fric] = rng.integers(-1, 2, fric.size)
        ok, info = realizable(form, s)
        assert ok == _velocity_lp(T, s, fric, gamma == 0)
        if ok:
            v = T @ info
            assert np.all(np.where(s[fric] != 0, s[fric] * v[fric] >= 1 - 1e-12,
                                   np.abs(v[fric]) <= 1e-12))
        else:
            assert info and not _velocity_lp(T, s, np.array(info), gamma == 0)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_lagrangian_bound_is_a_bound_and_tight_at_the_duals(seed):
    import highspy

    rng = np.random.default_rng(seed)
    m, n = 5, 8
    A = rng.normal(size=(m, n))
    x0 = rng.uniform(-1, 1, n)
    lo, hi = A @ x0 - rng.uniform(0, 1, m), A @ x0 + rng.uniform(0, 1, m)
    lo[0] = -np.inf
    lb, ub = np.full(n, -2.0), np.full(n, 2.0)
    c = rng.normal(size=n)
    h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.addVars(n, lb, ub)
    h.changeColsCost(n, np.arange(n, dtype=np.int32), c)
    for i in range(m):
        h.addRow(lo[i], hi[i], n, np.arange(n, dtype=np.int32), A[i])
    h.run()
    opt = h.getInfo().objective_function_value
    y = np.asarray(h.getSolution().row_dual)
    As = sp.csr_matrix(A)
    tight = max(lagrangian_bound(c, As, lo, hi, lb, ub, y),
                lagrangian_bound(c, As, lo, hi, lb, ub, -y))
    assert tight <= opt + 1e-12 and tight == pytest.approx(opt, abs=1e-7)
    for _ in range(5):
        assert lagrangian_bound(c, As, lo, hi, lb, ub, rng.normal(size=m)) <= opt + 1e-12


@settings(max_examples=15, deadline=None)
@given(lx=st.integers(1, 4), ly=st.integers(1, 3), gamma=st.sampled_from([0.16, -0.05, 0.3]),
       mu_wall=st.sampled_from([0.0, 0.2]), seed=st.integers(0, 10_000))
def test_rotation_cap_on_valid_steady_states(lx, ly, gamma, mu_wall, seed):
    """Forces of the contact states of random velocities (an LP written here, random cost):
    every valid steady state found has max |r alpha| <= |gamma| (bounds.rotation_cap)."""
    system = models.System(models.rectangular(lx, ly), mu_pp=0.3, mu_plane=0.2,
                           mu_wall=mu_wall, gamma=gamma)
    dyn = Dynamics(system)
    assert rotation_cap(system, dyn) == pytest.approx(abs(gamma))
    c, p, mu, r = system.c, system.p, system.mu, system.lattice.radius
    E = np.vstack([dyn.W[:c], dyn.H.T.toarray()[:2 * p]])
    e = np.concatenate([-dyn.q[:c], -dyn.f[:2 * p]])
    rng = np.random.default_rng(seed)
    T = np.column_stack([dyn.H[c:].toarray()[:, 2 * p:] / r, dyn.u_obs(1.0)[c:]])
    for _ in range(8):
        s = np.where(mu > 0, np.sign(T @ rng.integers(-2, 3, p + 1)), 0).astype(int)
        A_eq, b_eq, A_ub, b_ub = [E], [e], [], []
        for al in np.flatnonzero(mu > 0):
            row = np.zeros(2 * c)
            if s[al]:
                row[c + al], row[al] = 1.0, s[al] * mu[al]
                A_eq.append(row[None])
                b_eq.append([0.0])
                A_ub.append(-s[al] * dyn.W[c + al])
                b_ub.append(s[al] * dyn.q[c + al])
            else:
                A_eq.append(dyn.W[c + al][None])
                b_eq.append([-dyn.q[c + al]])
                for sg in (1.0, -1.0):
                    row = np.zeros(2 * c)
                    row[c + al], row[al] = sg, -mu[al]
                    A_ub.append(row)
                    b_ub.append(0.0)
        res = linprog(rng.normal(size=2 * c), A_ub=np.array(A_ub) if A_ub else None,
                      b_ub=np.array(b_ub) if b_ub else None, A_eq=np.vstack(A_eq),
                      b_eq=np.concatenate([np.ravel(b) for b in b_eq]),
                      bounds=[(0, 50)] * c + [(-50, 50) if m > 0 else (0, 0) for m in mu],
                      method="highs")
        if res.status == 0:
            ra = r * dyn.accelerations(res.x)[2 * p:]
            assert np.max(np.abs(ra), initial=0.0) <= abs(gamma) * (1 + 1e-7) + 1e-9
