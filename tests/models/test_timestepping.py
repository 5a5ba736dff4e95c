"""Moreau-Jean time-stepping: analytic disk, agreement with the event-driven runs, first order,
balances, run format, bad input."""

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.models.observables import horizontal_balance
from rigidlcp.models.runio import load_run, save_run
from rigidlcp.models.timestepping import InvalidStep, StepOptions, moreau_jean

# One disk on the plane between frictionless walls (tests/models/test_evolution.py): rolling
# while |gamma| < gamma* = mu m g r^2 / I, with omega' = -gamma / r and mu_g = I gamma / (r^2 m g);
# beyond, sliding with S = sgn(gamma) mu m g, mu_g = sgn(gamma) mu. From a sliding start below
# the threshold the disk rolls from t* = -v_t(0) / a_t, a_t = -gamma - s mu m g r^2 / I; the
# time-stepper sticks at the end of the step that contains t*.


@pytest.mark.parametrize("mu, gamma, inertia, omega0", [
    (0.3, 0.16, 0.5, 0.7), (0.3, -0.4, 0.5, -0.2), (0.2, 0.5, 0.5, 0.3), (0.1, 0.3, 0.25, 1.0),
    (0.5, 0.25, 1.0, -0.8)])
def test_one_disk_rolling_and_sliding(mu, gamma, inertia, omega0):
    m = g = r = 1.0
    h = 1e-3
    gstar = mu * m * g * r**2 / inertia
    system = models.System(models.rectangular(1, 1), mu_plane=mu, gamma=gamma, inertia=inertia)
    run = moreau_jean(system, omega=[omega0], h=h)
    assert run.status == "steady", run.message
    last = run.last
    if abs(gamma) < gstar:
        assert np.isclose(last.omega_dot[0], -gamma / r, rtol=1e-10)
        assert np.isclose(last.mu_g, inertia * gamma / r**2 / (m * g), rtol=1e-10)
        assert last.s[plane(system)] == 0  # the plane contact sticks
        vt0 = -0.0 - r * omega0
        a_t = -gamma - np.sign(vt0) * mu * m * g * r**2 / inertia
        t_star = -vt0 / a_t
        first_stick = next(rec.t for rec in run.records if rec.s[plane(system)] == 0)
        assert t_star <= first_stick + 1e-12 <= t_star + h + 1e-9
    else:
        S = np.sign(gamma) * mu * m * g
        assert np.isclose(last.omega_dot[0], -r * S / inertia, rtol=1e-10)
        assert np.isclose(last.mu_g, np.sign(gamma) * mu, rtol=1e-10)
        assert last.s[plane(system)] == -np.sign(gamma)


def plane(system):
    return int(system.plane_contacts[0])


# --- agreement with the event-driven runs (10 x 1 rows) ----------------------------------------

@pytest.mark.parametrize("gamma, seed", [(0.05, 1), (0.02, 2)])
def test_steady_state_of_a_10x1_row_agrees_with_event_driven(gamma, seed):
    system = models.System(models.rectangular(10, 1), mu_pp=0.1, mu_plane=0.2, gamma=gamma)
    ed = models.simulate(system, seed=seed)
    ts = moreau_jean(system, seed=seed, h=2e-3)
    assert ed.status == ts.status == "steady"
    assert np.allclose(ts.last.omega_dot, ed.last.omega_dot, atol=1e-12)
    assert np.isclose(ts.last.mu_g, ed.last.mu_g, atol=1e-12)
    assert np.array_equal(ts.last.s, ed.last.s)
    # Both reach their steady state at the same time, to within the steps the detection waits.
    assert ed.last.t <= ts.last.t <= ed.last.t + (20 + 2) * 2e-3


def test_every_step_checked_balanced_and_theta_free():
    """Each record's Coulomb residual is within check_tol, its mean forces satisfy Eq. (2.1)
    exactly (the disks do not translate), and theta does not change anything (f constant)."""
    system = models.System(models.rectangular(4, 2), mu_pp=0.1, mu_plane=0.2, mu_wall=0.05,
                           gamma=0.16)
    a = moreau_jean(system, seed=3, h=2e-3, t_max=1.0, record_every=7)
    b = moreau_jean(system, seed=3, h=2e-3, t_max=1.0, record_every=7, theta=0.5)
    assert a.status == "time_limit" and len(a.records) > 20
    for rec in a.records:
        assert rec.residual <= 1e-8
        assert abs(horizontal_balance(system, rec.R, rec.S)) < 1e-9 * system.total_mass
        assert rec.dissipation >= -1e-12
    assert len(a.records) == len(b.records)
    for ra, rb in zip(a.records, b.records):
        assert np.array_equal(ra.omega, rb.omega) and np.array_equal(ra.R, rb.R)


def test_run_format_round_trip(tmp_path):
    system = models.System(models.rectangular(3, 2), mu_pp=0.1, mu_plane=0.2, gamma=0.1)
    run = moreau_jean(system, seed=1, h=5e-3, t_max=0.5, record_every=10)
    back = load_run(save_run(run, tmp_path / "ts"))
    assert back.status == run.status and back.method == run.method
    assert back.n_events == run.n_events
    assert np.array_equal(back.array("omega_dot"), run.array("omega_dot"))
    assert np.array_equal(back.array("residual"), run.array("residual"))


@pytest.mark.parametrize("options", [dict(h=0.0), dict(h=-1e-3), dict(h=np.nan),
                                     dict(h=1e-3, theta=0.4), dict(h=1e-3, theta=1.2),
                                     dict(h="x"), dict(h=1e-3, steady_steps=0),
                                     dict(h=1e-3, t_max=-1.0), dict(h=1e-3, method="nope")])
def test_bad_options_raise_typed_errors(options):
    system = models.System(models.rectangular(1, 1), mu_plane=0.2, gamma=0.1)
    with pytest.raises(ValueError) as info:
        moreau_jean(system, omega=[0.0], **options)
    assert isinstance(info.value, (InvalidStep, models.InvalidSystem)) or "method" in str(
        info.value)
    with pytest.raises(ValueError):
        StepOptions(**options)


def test_a_disk_pushed_along_the_plane_with_no_wall_is_a_detachment():
    """A lone disk on the driven plane, walls far away: nothing balances the plane's friction
    horizontally, so the disk would translate (the paper's regime ends). The time-stepper ran
    it to 'steady' with mu_g 0; the event engine stops it as a detachment (models.engine.loop);
    so must the time-stepper, at its first step, naming the disk."""
    from rigidlcp.models.packing import packing

    lone = packing(np.array([[5.0, 1.0]]), np.array([1.0]), left=0.0, right=20.0)
    system = models.System(lone, gamma=0.5)
    run = moreau_jean(system, seed=1, h=1e-3)
    assert run.status == "detachment" and "would translate" in run.message
    assert "disks [0]" in run.message and len(run.records) <= 2
    events = models.simulate(system, seed=1)
    assert events.status == "detachment" and "would translate" in events.message
