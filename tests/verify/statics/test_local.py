"""verify.statics.local: certificates of a cluster of disks moving while the others stay put.

Each certificate is re-checked here independently of the module: the relative velocities are
computed from the packing's geometry (models.dynamics' convention: g_n = (v_j - v_i) . n,
g_t = (v_j - v_i) . t - r_i w_i - r_j w_j, obstacles at rest) in Fraction arithmetic on the
stored floats, from the certificate's rational y; it must satisfy g_n >= mu |g_t| at every
contact and do positive work, sum m_i g v_i < 0 (b . y < 0).

Hand-made cases (radius-1 disks unless stated, g = 1):

1. A disk resting on a single disk at 30 degrees from the vertical: a single contact force
   through the centre cannot be vertical, so there is no equilibrium at any mu; the disk rolls
   off (v along the tangent, w = v . t / r: g_n = 0, g_t = 0). The lower disk sits in the
   corner of the left wall and the plane.
2. A disk of radius 1 against the left wall, resting on a disk of radius 0.3 in the corner
   below it: both supports push it to the right (wall normal (1, 0); the small disk's normal
   at 32.6 degrees from the vertical, on the left), so at mu = 0.5, whose cones
   (half-angle 26.6 degrees) exclude the vertical on both, no force in the cones can carry the
   weight: no equilibrium.
3. Stable packings (a checked equilibrium exists): the frictionless pyramid between walls,
   a rectangular array: no certificate may be found.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.verify.statics.forceset import analyse
from rigidlcp.verify.statics.local import scan, window_lp, windows
from rigidlcp.verify.statics.model import StaticProblem


def independent_check(system: models.System, exact: dict) -> Fraction:
    """-b . y (> 0) after checking the dual cone exactly at every contact (module docstring)."""
    lat, p = system.lattice, system.lattice.p
    F = Fraction
    y = {k: exact.get(k, F(0)) for k in range(3 * p)}
    r = lat.radii

    def vel(k: int) -> tuple:
        if k < 0:
            return F(0), F(0), F(0), F(0)
        return y[k], y[p + k], y[2 * p + k], F(float(r[k]))

    for a in range(lat.c):
        i, j = int(lat.i[a]), int(lat.j[a])
        ui, vi, wi, ri = vel(i)
        uj, vj, wj, rj = vel(j)
        n = [F(float(v)) for v in lat.n[a]]
        t = [F(float(v)) for v in lat.t[a]]
        gn = (uj - ui) * n[0] + (vj - vi) * n[1]
        gt = (uj - ui) * t[0] + (vj - vi) * t[1] - ri * wi - (rj * wj if j >= 0 else 0)
        mu = F(float(system.mu[a]))
        assert gn >= mu * abs(gt), (a, gn, gt)
    work = sum(F(float(m)) * F(float(system.g)) * y[p + k]
               for k, m in enumerate(system.masses))
    assert work < 0
    return -work


def _system(x, r, left=None, right=None, mu=0.5) -> models.System:
    r = np.asarray(r, dtype=float)
    lat = models.make_packing(np.asarray(x, dtype=float), r, m=r**2, left=left, right=right)
    return models.System(lat, mu_pp=mu, mu_plane=mu, mu_wall=mu)


S30 = math.sin(math.pi / 6)
C30 = math.cos(math.pi / 6)
ON_ONE = ([[1.0, 1.0], [1.0 + 2 * S30, 1.0 + 2 * C30]], [1.0, 1.0])
IN_CORNER = ([[0.3, 0.3], [1.0, 0.3 + math.sqrt(1.3**2 - 0.7**2)]], [0.3, 1.0])


@pytest.mark.parametrize("mu", [0.0, 0.5, 2.0])
def test_disk_on_a_single_support_rolls_off(mu):
    system = _system(*ON_ONE, left=0.0, mu=mu)
    assert system.lattice.c == 3  # corner (2) and the pair
    cert = scan(StaticProblem(system))
    # the falling disk; the lower one may move too at no work (frictionless: it slides away
    # from the wall), a vertex of the window's LP as good as any
    assert cert is not None and 1 in cert.disks
    assert independent_check(system, cert.exact) > 0
    fs = analyse(system, ranges=False)
    assert fs.exists is False and fs.exact and 1 in fs.moving
    assert fs.to_dict()["farkas_disks"] == [int(k) for k in fs.moving]


def test_disk_on_two_supports_outside_their_cones():
    system = _system(*IN_CORNER, left=0.0, mu=0.5)
    lat = system.lattice
    assert sorted(zip(lat.i.tolist(), lat.j.tolist())) == sorted(
        [(0, models.lattice.LEFT_WALL), (0, models.lattice.PLANE), (0, 1),
         (1, models.lattice.LEFT_WALL)])
    cert = scan(StaticProblem(system))
    assert cert is not None and 1 in cert.disks
    assert independent_check(system, cert.exact) > 0
    assert analyse(system, ranges=False).exists is False


S3 = math.sqrt(3.0)


@pytest.mark.parametrize("system", [
    _system([[1.0, 1.0], [3.0, 1.0], [2.0, 1.0 + S3]], [1, 1, 1], left=0.0, right=4.0, mu=0.0),
    models.System(models.rectangular(6, 5), mu_pp=0.3, mu_plane=0.3, mu_wall=0.3),
])
def test_no_certificate_where_an_equilibrium_exists(system):
    fs = analyse(system, ranges=False)
    assert fs.exists is True
    prob = StaticProblem(system)
    assert scan(prob) is None
    for D in windows(prob, 4.0):  # every window's LP: nothing below zero beyond rounding
        value, _ = window_lp(_cone(prob), D)
        assert value >= -1e-9


def _cone(prob):
    from rigidlcp.verify.statics.local import Cone

    return Cone(prob)


def test_windows_cover_every_disk_and_small_clusters():
    """Every set of disks whose centres span at most side / 2 in x and in y lies in a window."""
    pile = deposit(300, seed=3, radii=(0.8, 1.2))
    prob = StaticProblem(models.System(pile, mu_pp=0.5, mu_plane=0.5, mu_wall=0.5))
    side = 6.0
    wins = [set(D.tolist()) for D in windows(prob, side)]
    x = pile.x
    rng = np.random.default_rng(0)
    for _ in range(200):
        k = int(rng.integers(pile.p))
        near = np.flatnonzero((np.abs(x[:, 0] - x[k, 0]) <= side / 4)
                              & (np.abs(x[:, 1] - x[k, 1]) <= side / 4))
        assert any(set(near.tolist()) <= w for w in wins)


@settings(max_examples=12, deadline=None)
@given(n=st.integers(3, 60), seed=st.integers(0, 10**6),
       mu=st.sampled_from([0.0, 0.2, 0.5, 1.0]))
def test_local_certificates_on_deposited_piles(n, seed, mu):
    """A local certificate passes the independent exact check, and it never coexists with a
    checked equilibrium (which the global analysis finds independently of the scan)."""
    system = models.System(deposit(n, seed=seed, radii=(0.8, 1.2)), mu_pp=mu, mu_plane=mu,
                           mu_wall=mu)
    prob = StaticProblem(system)
    cert = scan(prob)
    if cert is not None:
        assert independent_check(system, cert.exact) > 0
        assert set(cert.exact) <= set(np.r_[cert.disks, prob.p + cert.disks,
                                            2 * prob.p + cert.disks].tolist())
    from rigidlcp.verify.statics.model import ForceLP

    status, lam = ForceLP(prob).solve(np.zeros(prob.n))
    if status == "optimal" and prob.admissible(lam):
        assert cert is None


def test_independent_check_refuses_a_spoiled_certificate():
    """The check above can fail: the falling disk's rotation dropped (it then slides on its
    support, g_n = 0 < mu |g_t|) or its motion reversed (gravity does negative work)."""
    system = _system(*ON_ONE, left=0.0, mu=0.5)
    cert = scan(StaticProblem(system))
    p = system.lattice.p
    no_roll = dict(cert.exact)
    no_roll[2 * p + 1] = Fraction(0)
    reversed_ = {k: -v for k, v in cert.exact.items()}
    for bad in (no_roll, reversed_):
        with pytest.raises(AssertionError):
            independent_check(system, bad)
