"""verify.steadiness: the one definition of a valid steady state (docs/mechanics.md), by hand
on each condition, and its three callers agreeing on a run's steady state and on a state whose
sliding contacts would decelerate."""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.verify.certificates.run import steady_state
from rigidlcp.verify.integrators import event_check
from rigidlcp.verify.ranges.witness import steady_check
from rigidlcp.verify.steadiness import KINEMATICS, from_velocities, steadiness


def _row() -> models.System:
    """2x1 row between frictionless walls: contacts plane, plane, left wall, disk-disk, right
    wall with mu = (0.2, 0.2, 0, 0.1, 0)."""
    return models.System(models.rectangular(2, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                         gamma=0.02)


@pytest.mark.parametrize("change, condition, value", [
    ({"a_n": [0, 0, 0, 0.3, 0]}, "a_n", 0.3),
    ({"a_t": [0, 0, 0, 0.25, 0]}, "non-sliding a_t", 0.25),      # contact 3 sticks (s = 0)
    ({"s": [1, 0, 0, 0, 0], "a_t": [-0.5, 0, 0, 0, 0], "S": [-0.2, 0, 0, 0, 0]},
     "decelerating", 0.5),                                       # s a_t = -0.5
    ({"R": [1, 1, -0.1, 0, 0]}, "R >= 0", 0.1),                  # frictionless: cone holds
    ({"S": [0, 0.4, 0, 0, 0]}, "cone", 0.2),                     # |S| - mu R = 0.2
    ({"S": [0, 0, 0.1, 0, 0]}, "cone+frictionless S", 0.1),     # mu = 0: both say S = 0
    ({"s": [-1, 0, 0, 0, 0], "a_t": [-1.0, 0, 0, 0, 0]}, "sliding law", 0.2),   # S = 0 != mu R
])
def test_each_condition_by_hand(change, condition, value):
    """Forces and accelerations on unit scales (f_scale = a_scale = 1): each change violates
    the conditions named (one, or two that say the same), by the value worked out by hand."""
    base = {"R": [1.0, 1.0, 0.0, 0.0, 0.0], "S": [0.0] * 5, "s": [0] * 5, "a_n": [0.0] * 5,
            "a_t": [0.0] * 5}
    assert steadiness(_row(), **base, f_scale=1.0, a_scale=1.0).residual == 0.0
    st = steadiness(_row(), **{**base, **change}, f_scale=1.0, a_scale=1.0)
    assert list(st.failing(1e-12)) == condition.split("+")
    assert st.residual == pytest.approx(value, rel=1e-12)
    assert st.steady(1e-12, KINEMATICS) == (condition not in KINEMATICS)


def test_the_three_callers_agree_on_a_run():
    """A 4x1 row run to its steady state: event_check and steady_check (one time unit later,
    the velocities advanced by the accelerations) say steady; the same forces with every
    velocity reversed make the sliding contacts decelerate, which all three report."""
    system = models.System(models.rectangular(4, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.02)
    run = models.simulate(system, seed=1)
    assert run.status == "steady"
    rec = run.last
    assert event_check(system, rec).steady
    omega1, V1 = rec.omega + rec.omega_dot, rec.V + system.gamma
    assert steady_check(system, omega1, V1, rec.R, rec.S)[0] <= 1e-8
    assert from_velocities(system, omega1, V1, rec.R, rec.S).residual == steady_check(
        system, omega1, V1, rec.R, rec.S)[0]
    sliding = np.flatnonzero(rec.s != 0)
    assert sliding.size
    # the same accelerations with every sliding state reversed: those contacts decelerate
    flipped = models.State(rec.t, np.asarray(rec.omega), rec.V, -np.asarray(rec.s))
    ep = models.event_problem(system, models.State(rec.t, np.asarray(rec.omega), rec.V,
                                                   np.asarray(rec.s)))
    from rigidlcp.verify.forces.polyhedra import event_z

    es = ep.unpack(event_z(ep, np.r_[rec.R, rec.S]))
    ok, why = steady_state(ep, flipped, type(es)(**{**es.__dict__, "s": -es.s}))
    assert not ok and "decelerate" in why
    bad = event_check(system, type(rec)(**{**rec.__dict__, "s": -np.asarray(rec.s)}))
    assert not bad.steady and "decelerate" in bad.note
    res, _ = steady_check(system, -omega1, -V1, rec.R, rec.S)
    assert res > 1e-3
