"""The run summary's observables mean what their names say (issue 14.4)."""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.models.observables import (
    ZERO_TOL,
    dissipated_energy,
    dissipation_summary,
    regime,
    reported,
)
from rigidlcp.models.plot import dissipation_curve


@pytest.fixture(scope="module")
def runs():
    lat = models.rectangular(4, 2)
    accel = models.simulate(models.System(lat, gamma=0.1), seed=1, progress=False)
    const = models.simulate(models.System(lat, gamma=0.0, V0=1.0), seed=1, progress=False)
    return accel, const


def test_dissipated_energy_is_the_integral_of_the_rate(runs):
    """Exact integral of the piecewise-linear D against an independent fine trapezoid rule
    over the sampled curve D(t) of models.plot."""
    for run in runs:
        t, D = dissipation_curve(run, samples=2001)
        keep = t <= run.last.t
        numeric = float(np.sum(0.5 * (D[keep][1:] + D[keep][:-1]) * np.diff(t[keep])))
        exact = dissipated_energy(run.records)
        assert exact == pytest.approx(numeric, rel=1e-9, abs=1e-12)
        s = run.summary()
        assert s["dissipated_energy"] == exact
        assert s["dissipated_energy_interval"] == [run.records[0].t, run.last.t]


def test_rate_and_slope_at_the_last_event(runs):
    accel, const = runs
    for run in runs:
        last = run.last
        s = run.summary()
        raw = -float(last.S @ last.vt)
        assert s["dissipation_rate"] == reported(raw, np.sum(np.abs(last.R) + np.abs(last.S))
                                                 * np.max(np.abs(last.vt)))
    # constant acceleration: the sliding velocities grow, D grows linearly in the steady state
    s = accel.summary()
    assert accel.steady and s["dissipation_rate_slope"] > 0
    # constant velocity: the steady state dissipates nothing (Fig. 13), reported as exactly 0
    s = const.summary()
    assert const.steady and s["dissipation_rate"] == 0.0 and s["dissipation_rate_slope"] == 0.0
    assert s["mu_g"] == 0.0 and s["F_g"] == 0.0  # not -2.8e-17


def test_reported_zero_within_the_stated_tolerance():
    assert reported(-9.6e-31, 10.0) == 0.0
    assert reported(-2 * ZERO_TOL, 1.0) == -2 * ZERO_TOL  # real negatives stay visible
    assert reported(0.5, 1.0) == 0.5


def test_regime_flags():
    assert regime("steady") == {"paper_regime": True}
    for status in ("detachment", "zeno"):
        r = regime(status)
        assert r["paper_regime"] is False and r["regime_note"]


def test_short_reprs_and_bool_progress(runs, capsys):
    accel, _ = runs
    assert len(repr(accel)) < 200 and "steady" in repr(accel)
    assert len(repr(accel.records)) < 200 * accel.n_events
    system = models.System(models.rectangular(3, 1), gamma=0.1)
    run = models.simulate(system, seed=1, progress=True)
    assert run.steady
    with pytest.raises(TypeError):
        models.simulate(system, seed=1, progress="yes")


def test_empty_summary():
    assert dissipation_summary([]) == {}


def test_reprs_report_rounding_noise_as_zero():
    """A steady state at gamma = 0 where no contact slides: v_t = 0 at every contact, so
    D = -sum S v_t = 0, and the repr prints 0, not the -1e-31 that rounding leaves; mu_g is
    printed as `reported` gives it (0 within ZERO_TOL)."""
    run = models.simulate(models.System(models.rectangular(4, 2), gamma=0.0), seed=1,
                          progress=False)
    last = run.last
    assert run.steady and not np.any(last.s != 0)  # every v_t is 0 up to rounding
    assert "D = 0," in repr(last)
    mu = f"mu_g = {reported(last.mu_g, 1.0):.6g},"
    assert mu in repr(last) and mu in repr(run)
