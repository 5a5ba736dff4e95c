"""verify.statics.ensemble: uniform samples of the admissible forces P.

Closed forms (derived in tests/verify/statics/test_forceset.py's docstring, unit weights):
1. A disk in the corner of the left wall and the plane, mu_wall = 1, mu_plane = 1/2: P is the
   segment R_p = 1 + s, R_w = S_p = s, S_w = -s, s in [0, 1]. A uniform law on it has s
   uniform on [0, 1]: mean R_p = 3/2, variance 1/12.
2. A disk on the plane between two walls 2 apart, frictionless: R_p = 1, R_L = R_R in
   [0, inf): unbounded, refused without a cap; with sum R <= cap, R_L uniform on
   [0, (cap - 1) / 2].
On deposited piles: every sampled network satisfies balance and the cones (checked here
independently of the sampler's own check), and the centred samples span exactly dim P.
"""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.models.lattice import LEFT_WALL, PLANE, RIGHT_WALL
from rigidlcp.verify.statics.ensemble import (
    UnboundedForceSet,
    hit_and_run,
    hopsy_available,
    sample,
)
from rigidlcp.verify.statics.forceset import analyse

SAMPLERS = ["hit-and-run", pytest.param("hopsy", marks=pytest.mark.skipif(
    not hopsy_available(), reason="hopsy not installed (optional extra [ensemble])"))]


def _system(x, left=None, right=None, **mu) -> models.System:
    lat = models.make_packing(x, np.ones(len(x)), m=np.ones(len(x)), left=left, right=right)
    return models.System(lat, **mu)


def _col(system, j_code):
    lat = system.lattice
    return int(np.flatnonzero(lat.j == j_code)[0])


@pytest.mark.parametrize("sampler", SAMPLERS)
def test_corner_segment_is_sampled_uniformly(sampler):
    system = _system(np.array([[1.0, 1.0]]), left=0.0, mu_pp=0.5, mu_plane=0.5, mu_wall=1.0)
    ens = sample(system, n=2000, seed=3, sampler=sampler, thinning=5)
    assert ens.forceset.dimension == 1
    Rp = ens.R[:, _col(system, PLANE)]
    assert Rp.min() >= 1 - 1e-9 and Rp.max() <= 2 + 1e-9
    # mean and variance of U[1, 2]: standard errors ~ 0.0065 and ~ 0.002 at 2000 samples
    assert abs(Rp.mean() - 1.5) < 0.04
    assert abs(Rp.var() - 1 / 12) < 0.015


def test_unbounded_set_needs_a_cap():
    system = _system(np.array([[1.0, 1.0]]), left=0.0, right=2.0, mu_pp=0.0, mu_plane=0.0,
                     mu_wall=0.0)
    with pytest.raises(UnboundedForceSet):
        sample(system, n=10)
    ens = sample(system, n=1500, seed=1, cap=5.0, sampler="hit-and-run", thinning=3)
    RL, RR = ens.R[:, _col(system, LEFT_WALL)], ens.R[:, _col(system, RIGHT_WALL)]
    np.testing.assert_allclose(RL, RR, atol=1e-9)
    np.testing.assert_allclose(ens.R[:, _col(system, PLANE)], 1.0, atol=1e-9)
    assert RL.max() <= 2.0 + 1e-9 and abs(RL.mean() - 1.0) < 0.06  # U[0, 2]
    with pytest.raises(ValueError, match="interior point"):
        sample(system, n=10, cap=0.5)  # sum R >= R_p = 1 on P


def test_unique_forces_give_one_network():
    system = _system(np.array([[1.0, 1.0]]), mu_pp=0.3, mu_plane=0.3, mu_wall=0.3)
    ens = sample(system, n=5)
    assert ens.forceset.dimension == 0
    np.testing.assert_allclose(ens.R, 1.0)
    assert ens.fluctuation() == 0.0


def test_hit_and_run_triangle_centroid():
    A = np.array([[-1.0, 0.0], [0.0, -1.0], [1.0, 1.0]])
    b = np.array([0.0, 0.0, 1.0])
    ys = hit_and_run(A, b, np.array([0.2, 0.2]), 4000, 5, np.random.default_rng(0))
    assert np.all(A @ ys.T <= b[:, None] + 1e-12)
    np.testing.assert_allclose(ys.mean(axis=0), [1 / 3, 1 / 3], atol=0.02)


@pytest.mark.parametrize("sampler", SAMPLERS)
@pytest.mark.parametrize("seed", [4, 7])
def test_deposited_samples_are_admissible_and_span_the_set(sampler, seed):
    pile = deposit(10, seed=seed, radii=(0.8, 1.2), width=6.0)
    system = models.System(pile, mu_pp=0.5, mu_plane=0.5, mu_wall=0.5)
    fs = analyse(system, ranges=False)
    assert fs.exists and fs.dimension > 0
    ens = sample(fs, n=200, seed=1, sampler=sampler)
    lam = ens.samples
    c = pile.c
    R, S = lam[:, :c], lam[:, c:]
    dyn = models.Dynamics(system)
    scale = float(np.abs(lam).max())
    # balance H^T lambda + f = 0 and the cones R >= 0, |S| <= mu R, to 1e-10 of the forces
    assert np.abs(lam @ dyn.H + dyn.f).max() <= 1e-10 * scale
    assert R.min() >= -1e-10 * scale
    assert (np.abs(S) - system.mu * R).max() <= 1e-10 * scale
    X = lam - lam.mean(axis=0)
    sv = np.linalg.svd(X, compute_uv=False)
    rank = int(np.sum(sv > 1e-8 * sv[0]))
    assert rank == fs.dimension
    f = ens.f()
    assert abs(f.mean() - 1.0) < 1e-12 and f.min() >= 0
