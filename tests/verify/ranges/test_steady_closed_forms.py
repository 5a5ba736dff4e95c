"""Closed forms for verify.ranges.steady_ranges, derived by hand (units m = r = g = 1,
I = 1/2).

One disk between the walls on the plane (rect 1x1). Forces on the disk (models.dynamics sign
conventions: the force on body j is R n + S t, the disk is body i): from the plane
(-S_P, R_P), from the left wall (R_L, S_L), from the right wall (-R_R, -S_R). Balances with
the inertial force -m gamma:

    horizontal  R_L - R_R - S_P - gamma = 0,
    vertical    S_L - S_R + R_P - 1 = 0,
    torque      alpha / 2 = -(S_L + S_R + S_P),
    a_t: plane -gamma - alpha, walls -alpha;   v_t: plane -V - omega, walls -omega.

The wall pair carries a free self-stress x = R_R >= 0 (the row of Fig. 5d, length 1).
"""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.models.lattice import LEFT_WALL, PLANE, RIGHT_WALL
from rigidlcp.verify.ranges import steady_ranges
from rigidlcp.verify.ranges.observables import mu_g_vector
from rigidlcp.verify.ranges.steady import formulate, state_extreme
from rigidlcp.verify.ranges.witness import steady_check


def _disk(mu_wall: float, gamma: float, mu_plane: float = 0.2) -> models.System:
    return models.System(models.rectangular(1, 1), mu_pp=0.1, mu_plane=mu_plane,
                         mu_wall=mu_wall, gamma=gamma)


def _index(system, j):
    return int(np.flatnonzero(system.lattice.j == j)[0])


@pytest.mark.parametrize("gamma, mu_g, alpha", [(0.1, 0.05, -0.1), (0.5, 0.2, -0.4)])
def test_single_disk_frictionless_walls_every_range_a_point(gamma, mu_g, alpha):
    """Walls frictionless: S_L = S_R = 0, so R_P = 1. Rolling (plane non-sliding) needs
    a_t = -gamma - alpha = 0: alpha = -gamma, S_P = -alpha / 2 = gamma / 2, admissible iff
    gamma / 2 <= mu_P = 0.2. Sliding with v_t < 0: S_P = +mu_P, alpha = -2 mu_P = -0.4,
    a_t = -gamma + 0.4 must be <= 0: gamma >= 0.4. Sliding with v_t > 0: S_P = -0.2,
    alpha = +0.4, a_t = -gamma - 0.4 < 0: never. So gamma = 0.1 has only the rolling state
    (mu_g = 0.05, alpha = -0.1) and gamma = 0.5 only the sliding one (mu_g = 0.2,
    alpha = -0.4): every range a point, except the walls' R, unbounded (the self-stress x)."""
    s = _disk(0.0, gamma)
    res = steady_ranges(s, which="all", time_limit=20)
    P, L, Rw = (_index(s, j) for j in (PLANE, LEFT_WALL, RIGHT_WALL))
    expect = {"mu_g": mu_g, "alpha[0]": alpha, f"R[{P}]": 1.0, f"S[{P}]": mu_g}
    for name, value in expect.items():
        r = res.ranges[name]
        assert r.lo.status == r.hi.status == "optimal", name
        assert r.lo.value == pytest.approx(value, abs=1e-9), name
        assert r.hi.value == pytest.approx(value, abs=1e-9), name
    # R_L - R_R = S_P + gamma: R_R in [0, inf), R_L in [S_P + gamma, inf)
    assert res.ranges[f"R[{Rw}]"].lo.value == pytest.approx(0.0, abs=1e-9)
    assert res.ranges[f"R[{L}]"].lo.value == pytest.approx(mu_g + gamma, abs=1e-9)
    for k in (L, Rw):
        hi = res.ranges[f"R[{k}]"].hi
        assert hi.status == "unbounded" and hi.value == np.inf
        assert hi.ray[k] > 0  # the ray loads the walls
    assert res.ranges[f"S[{L}]"].width == 0.0


def test_single_disk_rough_walls_self_stress_family():
    """Walls with mu_W = 0.1, gamma = 0.1, mu_P = 0.2. Contact states: plane rolling, both
    walls sliding with v_t > 0 (V > 0, omega = -V): alpha = -gamma, wall a_t = gamma >= 0.
    Then S_L = -mu_W R_L, S_R = -mu_W x, and the balances give
        S_P (1 - mu_W) = gamma / 2 + mu_W gamma + 2 mu_W x,
        R_P = 1 + mu_W (S_P + gamma),   S_P <= mu_P R_P,
    a family linear in the self-stress x >= 0: mu_g = S_P from
        gamma (1/2 + mu_W) / (1 - mu_W) = 0.0666...  (x = 0)
    to  mu_P (1 + mu_W gamma) / (1 - mu_P mu_W) = 0.2061224...  (plane at its Coulomb bound).

    Over all contact states: walls non-sliding (omega = 0, alpha = 0), plane sliding with
    v_t < 0: S_P = mu_P R_P and S_L + S_R = -S_P; the vertical balance gives
    R_P (1 + mu_P) = 1 - 2 S_L with |S_L| <= mu_W R_L, R_L as large as the self-stress makes
    it: R_P takes every value >= 0, so mu_g = mu_P R_P is unbounded above and reaches 0 (the
    disk held by the walls). No state has mu_g < 0: S_P < 0 needs plane sliding with v_t > 0
    and a_t >= 0, i.e. alpha <= -gamma < 0, which makes the walls' a_t = -alpha > 0, so both
    walls slide with S = -mu_W R <= 0 and the torque alpha / 2 = mu_W (R_L + R_R) + mu_P R_P
    >= 0: a contradiction. Range: [0, +inf)."""
    mu_W, gamma, mu_P = 0.1, 0.1, 0.2
    s = _disk(mu_W, gamma, mu_P)
    form = formulate(s)
    P, L, Rw = (_index(s, j) for j in (PLANE, LEFT_WALL, RIGHT_WALL))
    states = np.zeros(s.c, dtype=int)
    states[[L, Rw]] = 1
    Lg = mu_g_vector(s)
    lo = state_extreme(form, states, Lg, +1)
    hi = state_extreme(form, states, Lg, -1)
    assert lo[0] == hi[0] == "optimal"
    assert Lg @ lo[1] == pytest.approx(gamma * (0.5 + mu_W) / (1 - mu_W), abs=1e-12)
    assert Lg @ hi[1] == pytest.approx(mu_P * (1 + mu_W * gamma) / (1 - mu_P * mu_W), abs=1e-12)
    res = steady_ranges(s, time_limit=20)
    assert res.mu_g.lo.status == "optimal"
    assert res.mu_g.lo.value == pytest.approx(0.0, abs=1e-9)
    assert res.mu_g.hi.status == "unbounded"
    w = res.mu_g.lo.witness
    assert steady_check(s, w.omega, w.V, w.R, w.S)[0] <= 1e-8
    assert w.R[P] == pytest.approx(0.0, abs=1e-9)


def test_frictionless_row_between_frictionless_walls():
    """rect 3x1, mu_pp = mu_wall = 0: each disk is the single disk of the first test (no
    torque but the plane's), rolling at gamma = 0.1 < 2 mu_P: mu_g = 0.05 and every alpha =
    -0.1, a point, whatever the row's self-stress (every lateral and wall R unbounded)."""
    s = models.System(models.rectangular(3, 1), mu_pp=0.0, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.1)
    res = steady_ranges(s, which="alpha", time_limit=20)
    for name, r in res.ranges.items():
        want = 0.05 if name == "mu_g" else -0.1
        assert r.lo.value == pytest.approx(want, abs=1e-9)
        assert r.hi.value == pytest.approx(want, abs=1e-9)


@pytest.mark.parametrize("V0", [1.0, -0.5, 0.0])
def test_constant_velocity_V_is_the_runs(V0):
    """gamma = 0: V = V0 is fixed (docs/mechanics.md). One disk, smooth walls: rolling needs
    omega = -V0 and alpha = 0, so S_P = 0; sliding with v_t < 0 needs S_P = mu_P, alpha = -0.4
    and a_t = +0.4 <= 0, with v_t > 0 alpha = +0.4 and a_t = -0.4 >= 0: both impossible.
    mu_g = 0 and alpha = 0, and the witness has V = V0, omega = -V0."""
    s = models.System(models.rectangular(1, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.0, V0=V0)
    res = steady_ranges(s, which="alpha", time_limit=20)
    assert res.V_mode == {1.0: "positive", -0.5: "negative", 0.0: "zero"}[V0]
    for r in res.ranges.values():
        assert r.lo.value == pytest.approx(0.0, abs=1e-12)
        assert r.hi.value == pytest.approx(0.0, abs=1e-12)
    w = res.mu_g.lo.witness
    assert w.V == V0 and w.omega[0] == pytest.approx(-V0, abs=1e-12)
