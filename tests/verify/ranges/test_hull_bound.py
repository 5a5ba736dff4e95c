"""benchmarks/hull_bound.py (the convex-hull / Lagrangian relaxation of the contacts whose
order is open, tried on Fig. 9's open ends and not kept in the library, docs/mechanics.md):

* it contains every valid steady state: the checked witnesses of verify.ranges.steady_ranges
  (both ends of mu_g, and of every alpha on a 2x2 array; issue 21's 10x1 rows, a 3x2 array,
  random small arrays), lifted
  by the formulas of the module's docstring, satisfy every row and column bound (a sign error
  in a state's copy, a weight or the self-RLT row fails here);
* its bound, at the root and inside the disk split (cases_class=HullCases), never passes the
  MILP's proved ends, and the disk split with it still reaches them;
* claim (2): with the balances (and xi's definition) dualized at the LP's own multipliers, the
  Lagrangian function computed by enumerating every binary xi (each contact's best point of
  its state's polytope by its own small LP, scipy) equals the LP's value: the hull LP is the
  Lagrangian dual, the best bound of any relaxation that keeps the contacts exact and the
  balances as multipliers. A non-submodular pairing would leave a gap here.
"""

from __future__ import annotations

import importlib.util
import itertools
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from rigidlcp import models
from rigidlcp.verify.ranges import steady_ranges
from rigidlcp.verify.ranges.bounds import rotation_cap
from rigidlcp.verify.ranges.disk_split import disk_split_bound
from rigidlcp.verify.ranges.observables import mu_g_vector
from rigidlcp.verify.ranges.steady import NotSteady, formulate

_PATH = Path(__file__).resolve().parents[3] / "benchmarks" / "hull_bound.py"
_spec = importlib.util.spec_from_file_location("hull_bound_bench", _PATH)
hb = importlib.util.module_from_spec(_spec)
sys.modules[_spec.name] = hb
_spec.loader.exec_module(hb)


def _system(lattice, gamma, mpp=0.1, mpl=0.2):
    return models.System(lattice, mu_pp=mpp, mu_plane=mpl, mu_wall=0.0, gamma=gamma)


ROWS = [_system(models.rectangular(10, 1), 0.01, 0.05, 0.1),
        _system(models.rectangular(10, 1), 0.02, 0.1, 0.2),
        _system(models.rectangular(3, 2), 0.1), _system(models.rectangular(2, 2), 0.05)]


_CACHE: dict = {}


def _witnesses(system, which="all"):
    """(steady_ranges' result, [x = [R; S] of every checked witness]); `which` "all" (every
    alpha too) on the 2x2 array, "mu_g" elsewhere (kept once per system)."""
    key = id(system)
    if key in _CACHE:
        return _CACHE[key]
    r = steady_ranges(system, which=which, time_limit=60, split=False)
    xs = []
    for rng in r.ranges.values():
        for end in (rng.lo, rng.hi):
            if end.witness is not None:
                xs.append(np.r_[end.witness.R, end.witness.S])
    _CACHE[key] = r, xs
    return r, xs


def _assert_lift_feasible(hull, x):
    v = hull.lift(x)
    scale = 1.0 + float(np.max(np.abs(v)))
    tol = 1e-9 * scale
    Av = hull.A @ v
    assert np.all(Av >= hull.lo - tol), np.flatnonzero(Av < hull.lo - tol)
    assert np.all(Av <= hull.hi + tol), np.flatnonzero(Av > hull.hi + tol)
    assert np.all(v >= hull.lb - tol) and np.all(v <= hull.ub + tol)


@pytest.mark.parametrize("k", range(len(ROWS)))
def test_witnesses_lie_in_the_hull(k):
    system = ROWS[k]
    form = formulate(system)
    r, xs = _witnesses(system, "all" if system.p <= 4 else "mu_g")
    assert len(xs) >= 2
    L = mu_g_vector(system)
    for power, rlt in ((False, False), (True, False), (True, True)):
        hull = hb.Hull(form, L, power=power, rlt=rlt)
        for x in xs:
            _assert_lift_feasible(hull, x)


def test_a_wrong_copy_is_caught():
    """The lift check can fail: a witness with one sliding contact's S flipped violates the
    hull rows (the state copy S = -sgn(a) mu R)."""
    system = ROWS[1]
    form = formulate(system)
    _, xs = _witnesses(system, "mu_g")
    hull = hb.Hull(form, mu_g_vector(system))
    x = xs[0].copy()
    c = system.c
    slide = [b for b in np.flatnonzero(system.mu > 0) if abs(x[c + b]) > 1e-3]
    x[c + slide[0]] *= -1
    with pytest.raises(AssertionError):
        _assert_lift_feasible(hull, x)


@pytest.mark.parametrize("k", range(len(ROWS)))
def test_bounds_never_pass_the_milp_ends(k):
    system = ROWS[k]
    form = formulate(system)
    r, _ = _witnesses(system, "all" if system.p <= 4 else "mu_g")
    assert r.mu_g.lo.status == r.mu_g.hi.status == "optimal"
    lo, hi = r.mu_g.lo.value, r.mu_g.hi.value
    L = mu_g_vector(system)
    tol = 1e-9
    for sense, end in ((1.0, lo), (-1.0, -hi)):
        for power, rlt in ((False, False), (True, False), (True, True)):
            b, _ = hb.Hull(form, sense * L, power=power, rlt=rlt).solve()
            assert b <= end + tol
        res = disk_split_bound(form, sense * L, end, 1e9, max_cases=20000,
                               cases_class=hb.HullCases)
        assert res.bound <= end + tol
        assert res.closed or res.candidate is not None  # it reaches the end
        assert res.bound >= end - 1e-7 * max(1.0, abs(end))


def _lagrangian(hull, form, y, nbal):
    """y . rhs + min over X_bin of the Lagrangian's cost, by enumerating every binary xi
    (claim (2) of the module: per contact the best point of its state's polytope)."""
    system = form.system
    c, p = system.c, system.p
    A = hull.A.tocsr()
    Ab = A[:nbal]
    rhs = hull.lo[:nbal]
    d = hull.cost - Ab.T @ y  # reduced cost; columns: x | xi | (z none) | per contact...
    dx, dxi = d[:2 * c], d[hull.ixi:hull.ixi + p]
    # frictionless contacts (and any other R, S not in a frictional contact's copies):
    fr = set(int(b) for b, *_ in hull.layout)
    base = float(y @ rhs)
    for beta in range(c):
        if beta in fr:
            continue
        for j in (beta, c + beta):
            base += min(dx[j] * hull.lb[j], dx[j] * hull.ub[j])
    # any other column with a cost (marginals, copies, the fixed 1) must have none left
    rest = np.ones(A.shape[1], bool)
    rest[:2 * c] = rest[hull.ixi:hull.ixi + p] = False
    assert np.allclose(d[rest][hull.lb[rest] != hull.ub[rest]], 0.0, atol=1e-12)

    def best(beta, a):  # min dx . (R, S) over the state's polytope in the box
        m, lb, ub = system.mu[beta], hull.lb, hull.ub
        cost = [dx[beta], dx[c + beta]]
        bnds = [(lb[beta], ub[beta]), (lb[c + beta], ub[c + beta])]
        if a == 0:
            res = linprog(cost, A_ub=[[-m, 1.0], [-m, -1.0]], b_ub=[0, 0], bounds=bnds,
                          method="highs")
        else:
            res = linprog(cost, A_eq=[[np.sign(a) * m, 1.0]], b_eq=[0], bounds=bnds,
                          method="highs")
        return res.fun if res.status == 0 else np.inf

    M = hull.M
    T_u = hb.velocity_box(form.dyn)[0]
    b_obs = np.asarray(form.dyn.u_obs_dot, float)[c:]
    cache = {}
    out = np.inf
    for bits in itertools.product((0, 1), repeat=p):
        xi = np.array(bits, float)
        w = M * (2 * xi - 1)
        total = base + float(dxi @ xi)
        for beta, nz, _, _ in hull.layout:
            a = float(T_u[beta, nz] @ (hull.sigma[nz] * w[nz]) + b_obs[beta])
            key = (beta, 0 if abs(a) < 1e-12 * M else int(np.sign(a)))
            if key not in cache:
                cache[key] = best(beta, key[1])
            total += cache[key]
        out = min(out, total)
    return out


@pytest.mark.parametrize("lattice,gamma", [((3, 1), 0.02), ((2, 2), 0.05), ((3, 2), 0.1)])
def test_the_hull_is_the_lagrangian_dual(lattice, gamma):
    system = _system(models.rectangular(*lattice), gamma)
    form = formulate(system)
    L = mu_g_vector(system)
    hull = hb.Hull(form, L, power=False, rlt=False)
    b, x = hull.solve()
    assert np.isfinite(b)
    value = float(hull.h.getInfo().objective_function_value)
    nbal = form.dyn.c + 2 * system.p + system.p  # a_n = 0, no translation, xi's definition
    assert hull.lo[:nbal].tolist() == hull.hi[:nbal].tolist()  # equalities
    y = np.asarray(hull.h.getSolution().row_dual, float)[:nbal]
    lag = max(_lagrangian(hull, form, y, nbal), _lagrangian(hull, form, -y, nbal))
    assert lag == pytest.approx(value, rel=1e-7, abs=1e-9)
    assert b <= value + 1e-9  # the certified bound is below the LP's value


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(nx=st.integers(1, 4), ny=st.integers(1, 2), gamma=st.floats(0.005, 0.3),
       mpp=st.floats(0.02, 0.5), mpl=st.floats(0.05, 0.6))
def test_random_witnesses_lie_in_the_hull(nx, ny, gamma, mpp, mpl):
    system = _system(models.rectangular(nx, ny), gamma, mpp, mpl)
    form = formulate(system)
    assume(rotation_cap(system, form.dyn) and form.R_hi is not None
           and form.proved_for(mu_g_vector(system)))
    try:
        _, xs = _witnesses(system, "mu_g")
    except NotSteady:
        assume(False)
    hull = hb.Hull(form, mu_g_vector(system), rlt=True)
    for x in xs:
        _assert_lift_feasible(hull, x)
