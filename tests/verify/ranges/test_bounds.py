"""The proved force bounds of verify.ranges.bounds hold on valid steady states found without
them: random velocities (integers, so ties give non-sliding contacts) fix the contact states;
a linear program written here (not the code under test) finds forces of those states for a
random objective, with no force box; each such valid steady state must satisfy the power
identity I |alpha|^2 = S . a_t - u_obs' . lambda with S . a_t <= 0, |S| <= S_abs, the r alpha
and a_t bounds, and, for its S, admit forces with R <= R_hi (the self-stress
reduction), checked by a second LP written here. And the 10x1 rows' ranges, now proved."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, note, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from rigidlcp import models
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.verify.ranges import steady_ranges
from rigidlcp.verify.ranges.bounds import proved_bounds
from rigidlcp.verify.ranges.steady import NotSteady, _equalities, force_bound


def _state_forces(system, dyn, s, cost, fix_S=None, R_hi=None):
    """Forces of the states s (Eqs. 2.6, 2.7, 2.10 with a_n = 0, no translation), minimizing
    cost x; fix_S: S given (then R only); R_hi: R <= R_hi. None if infeasible/unbounded."""
    c, mu = system.c, system.mu
    E, e = _equalities(dyn)
    W, qt = dyn.W, dyn.q[c:]
    A_eq, b_eq, A_ub, b_ub = [E], [e], [], []
    for al in range(c):
        if mu[al] == 0:
            continue
        if s[al] != 0:
            row = np.zeros(2 * c)
            row[c + al], row[al] = 1.0, s[al] * mu[al]
            A_eq.append(row[None])
            b_eq.append([0.0])
            A_ub.append(-s[al] * W[c + al])
            b_ub.append(s[al] * qt[al])
        else:
            A_eq.append(W[c + al][None])
            b_eq.append([-qt[al]])
            for sg in (1.0, -1.0):
                row = np.zeros(2 * c)
                row[c + al], row[al] = sg, -mu[al]
                A_ub.append(row)
                b_ub.append(0.0)
    bounds = [(0, None if R_hi is None else R_hi[a]) for a in range(c)]
    bounds += [(0, 0) if m == 0 else (None, None) for m in mu]
    if fix_S is not None:
        bounds[c:] = [(v, v) for v in fix_S]
    res = linprog(cost, A_ub=np.array(A_ub).reshape(-1, 2 * c) if A_ub else None,
                  b_ub=np.array(b_ub) if b_ub else None, A_eq=np.vstack(A_eq),
                  b_eq=np.concatenate([np.ravel(b) for b in b_eq]), bounds=bounds,
                  method="highs")
    return res.x if res.status == 0 else None


@settings(max_examples=25)
@given(lx=st.integers(2, 4), ly=st.integers(1, 2), mu_pp=st.sampled_from([0.05, 0.1, 0.3]),
       mu_plane=st.sampled_from([0.1, 0.2, 0.5]), gamma=st.sampled_from([0.01, 0.16, -0.1]),
       seed=st.integers(0, 10_000))
def test_random_valid_steady_states_satisfy_the_bounds(lx, ly, mu_pp, mu_plane, gamma, seed):
    system = models.System(models.rectangular(lx, ly), mu_pp=mu_pp, mu_plane=mu_plane,
                           mu_wall=0.0, gamma=gamma)
    dyn = Dynamics(system)
    c, p, r = system.c, system.p, system.lattice.radius
    E, e = _equalities(dyn)
    fb = proved_bounds(system, dyn, E, e)
    if fb is None:  # only when no steady state has every contact closed (P is empty)
        with pytest.raises(NotSteady):
            force_bound(system, dyn)
        return
    rng = np.random.default_rng(seed)
    found = 0
    k_ = np.arange(p)  # models.rectangular numbers the disks row by row
    sigma = (-1.0) ** (k_ // lx + k_ % lx)
    for k in range(40):
        # checkerboard potentials with ties: x_i = sigma_i y_i, disk-disk v_t = -(x_i + x_j)
        y = rng.integers(0, 2 + k % 3, p).astype(float)
        omega = sigma * y / r if k > 1 else np.zeros(p)
        V = float(rng.integers(-2, 3)) if k > 1 else (1.0, -1.0)[k]
        vt = dyn.velocities(omega, V)[c:]
        s = np.where(system.mu > 0, np.sign(np.round(vt, 12)), 0).astype(int)
        x = _state_forces(system, dyn, s, rng.normal(size=2 * c))
        if x is None:
            continue
        found += 1
        R, S = x[:c], x[c:]
        tol = 1e-7 * max(1.0, float(np.abs(x).max()))
        assert np.all(np.abs(S) <= fb.S_abs + tol)
        ra = r * dyn.accelerations(x)[2 * p:]
        # the power identity behind the r alpha cap (verify.ranges.bounds), from Newton-Euler
        at = (dyn.H @ dyn.accelerations(x) + dyn.u_obs_dot)[c:]
        power = float(np.sum(ra ** 2 / r ** 2 / dyn.Minv[2 * p:]))
        assert power == pytest.approx(S @ at - dyn.u_obs_dot @ x, abs=tol)
        assert S @ at <= tol
        assert np.all(ra >= fb.ra_lo - tol) and np.all(ra <= fb.ra_hi + tol)
        at = (dyn.H @ dyn.accelerations(x) + dyn.u_obs_dot)[c:]
        fr = system.mu > 0
        assert np.all(at[fr] >= fb.at_lo[fr] - tol) and np.all(at[fr] <= fb.at_hi[fr] + tol)
        # R outside the self-stress groups is bounded for every state; inside, some R of the
        # same S and states is within R_hi
        assert np.all(R[~fb.free_R] <= fb.R_hi[~fb.free_R] + tol)
        assert _state_forces(system, dyn, s, np.zeros(2 * c), fix_S=S, R_hi=fb.R_hi) is not None
    note(f"{found} valid steady states checked")


@pytest.mark.slow
@pytest.mark.parametrize("mu_pp, mu_plane, gamma, lo, hi", [
    (0.05, 0.1, 0.01, 0.0145179, 0.0976197),
    (0.05, 0.1, 0.02, 0.0290357, 0.1),
    (0.1, 0.2, 0.02, 0.0669235, 0.1911561)])
def test_rows_ranges_unchanged_and_now_proved(mu_pp, mu_plane, gamma, lo, hi):
    """The three 10x1 rows of issue 21 (values of the box-limited computation before the
    proved bounds, docs/benchmarks.md): the same ranges, now over all valid steady states."""
    system = models.System(models.rectangular(10, 1), mu_pp=mu_pp, mu_plane=mu_plane,
                           mu_wall=0.0, gamma=gamma)
    res = steady_ranges(models.simulate(system, seed=1), time_limit=60)
    assert res.box_proved and res.mu_g.scope == "all valid steady states"
    assert res.mu_g.lo.status == res.mu_g.hi.status == "optimal"
    assert res.mu_g.lo.value == pytest.approx(lo, abs=1e-7)
    assert res.mu_g.hi.value == pytest.approx(hi, abs=1e-7)
