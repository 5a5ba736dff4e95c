"""The report's cross-checks of steady states: kept by the toolkit's time-stepper
(self-consistency), certified determinacy, and the Fig. 8-9 "any selection" rows
(rigidlcp.reproduce.crosscheck, claims)."""

import dataclasses
from types import SimpleNamespace

import numpy as np
import pytest

from rigidlcp import lcp, models
from rigidlcp.models.event import event_problem
from rigidlcp.reproduce.claims import evaluate
from rigidlcp.reproduce.columns import fig9_any
from rigidlcp.reproduce.crosscheck import (
    TOL_ALPHA,
    TS_DEFINITION,
    certify_steady,
    confirm_by_timestepping,
)
from rigidlcp.reproduce.experiments import SELECT, Results
from rigidlcp.reproduce.experiments import plan as make_plan


def row10(gamma=0.05, mu_pp=0.1):
    return models.System(models.rectangular(10, 1), mu_pp=mu_pp, mu_plane=0.2, gamma=gamma)


def test_a_steady_state_of_both_integrators_is_confirmed():
    """10 x 1 rows: the two integrators agree to ~1e-14 (docs/integrators.md), so the
    event-driven steady state is confirmed, with drifts far below the stated tolerances."""
    run = models.simulate(row10(), seed=1)
    x = confirm_by_timestepping(run, "row")
    assert not x.error and x.confirmed, x.text()
    assert x.status == "steady" and x.states_differing == 0
    assert x.d_alpha <= 1e-3 * TOL_ALPHA and x.d_mu_g <= 1e-12
    assert x.modes_ts == x.modes_ed and x.ts_valid_event and x.ed_in_step <= 1e-8
    assert x.text().startswith("row: kept")


def test_a_state_that_is_not_steady_for_the_integrator_is_not_confirmed():
    """Perturb the recorded steady accelerations: the time-stepper, started from the same
    velocities, finds the true ones, and the drift is the perturbation."""
    run = models.simulate(row10(), seed=1)
    last = run.records[-1]
    bumped = last.omega_dot.copy()
    bumped[3] += 1e-3
    run.records[-1] = dataclasses.replace(last, omega_dot=bumped)
    x = confirm_by_timestepping(run, "row")
    assert not x.error and not x.confirmed
    assert x.d_alpha == pytest.approx(1e-3, rel=1e-6)
    assert "NOT kept" in x.text()


def test_a_broken_check_is_reported_as_a_fail_not_dropped():
    run = models.simulate(row10(), seed=1, max_events=2)  # not steady
    x = confirm_by_timestepping(run, "short")
    assert x.error and not x.confirmed and "FAIL (evaluation error" in x.text()
    # Claims whose checks never ran: the column says FAIL, formula claims say n/a.
    claims = evaluate(Results(make_plan(quick=True)))
    for c in claims:
        if c.id.startswith(("eq", "formulas")):
            assert c.ts.startswith("n/a") and c.ts_confirmed is None
        else:
            assert c.ts.startswith("FAIL (evaluation error") and c.ts_confirmed is False, c
            assert "FAIL (evaluation error" in c.determinacy or c.determinacy.startswith(
                "not certified"), c
    assert "Moreau-Jean" in TS_DEFINITION and "kept when" in TS_DEFINITION


def _acc_of(ep, z):
    return ep.unpack(z).omega_dot


def test_certified_determinacy_agrees_with_enumeration():
    """Small steady states (n <= 16): the certificate's verdict on the accelerations agrees
    with the enumeration of every complementary basis of the event LCP."""
    for system, seed in ((models.System(models.rectangular(2, 1), mu_pp=0.0, mu_plane=0.2,
                                        gamma=0.1), 1),
                         (models.System(models.rectangular(2, 1), mu_pp=0.3, mu_plane=0.3,
                                        gamma=0.1), 2)):
        run = models.simulate(system, seed=seed)
        d = certify_steady(run, "small")
        assert not d.error and d.accepted, d.text()
        ep = event_problem(system, run.state_at(run.n_events - 1))
        assert ep.lcp.n <= 16
        sols = lcp.enumerate_solutions(ep.lcp)
        accs = [_acc_of(ep, s.z) for s in sols]
        spread = max(float(np.abs(a - accs[0]).max()) for a in accs)
        continuum = any(s.info.get("continuum") for s in sols)
        v = d.verdicts["accelerations"]["verdict"]
        if v == "unique":
            assert spread <= 1e-8, (spread, d.text())
        else:
            assert v == "another solution exists" and (spread > 1e-8 or continuum)
            assert d.verdicts["accelerations"]["witness"]["residual"] <= 1e-8


@pytest.mark.slow
def test_fig9_steady_state_has_non_unique_accelerations_and_is_not_confirmed():
    """docs/verification.md: Fig. 9's steady state has non-unique accelerations (a face
    witness with the same contact states); the time-stepper started there moves to another
    point of that set (docs/integrators.md: 6.37e-3 in omega')."""
    system = models.System(models.rectangular(10, 4), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.16)
    run = models.simulate(system, seed=1)
    d = certify_steady(run, "fig9")
    acc = d.verdicts["accelerations"]
    assert acc["verdict"] == "another solution exists" and acc["stage"] == "face (a)"
    assert acc["witness"]["same_states"] and acc["witness"]["residual"] <= 1e-12
    x = confirm_by_timestepping(run, "fig9")
    assert not x.confirmed and x.states_differing == 0 and x.d_alpha > 1e-4
    assert x.ed_in_step <= 1e-8  # the ED state is a solution of the step laws too


def _fake_run(system, modes_od, plane_s, steady=True):
    lat = system.lattice
    c = system.c
    s = np.ones(c, int)
    s[np.flatnonzero(lat.j == models.PLANE)] = plane_s
    rec = SimpleNamespace(omega_dot=np.asarray(modes_od, float), s=s, R=np.ones(c), mu_g=0.1)
    return SimpleNamespace(system=system, last=rec, steady=steady,
                           status="steady" if steady else "zeno", n_events=1)


def test_any_selection_is_judged_by_its_criterion():
    """A 10-disk row with modes 3322211111 has 4/3/2 once the right wall disk is left out: the
    claim passes when that run is steady, and not when it is not (zeno)."""
    system = row10(gamma=0.16)
    roll = -0.16
    od = [1e-4, -1e-4, -0.03, -0.05, -0.07, roll, roll, roll, roll, roll]
    plane = [-1, -1, -1, -1, -1, 0, 0, 0, 0, 0]
    p = make_plan(quick=True)
    cfg = p["fig9"]
    for steady, expect in ((True, True), (False, False)):
        res = Results(p)
        res.runs["fig9"] = {(cfg["seeds"][0], cfg["gamma"], SELECT): _fake_run(system, od, plane),
                            (cfg["seeds"][0], cfg["gamma"], "none/pivoting"):
                            _fake_run(system, od, plane, steady=steady)}
        if not steady:  # the default selection gives another pattern
            res.runs["fig9"][(cfg["seeds"][0], cfg["gamma"], SELECT)] = _fake_run(
                system, [roll] * 10, [0] * 10)
        c = fig9_any(res)
        assert c.passed is expect, c.measured
        assert "3322211111 (5/3/2" in c.measured
        assert ("Reached by: none" in c.measured) is not expect
