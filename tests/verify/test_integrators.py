"""verify.integrators: cross-checks of the two integrators, first order, the CLI command."""

import copy

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.verify.integrators import compare_integrators, event_check, step_check


@pytest.fixture(scope="module")
def row3():
    return models.System(models.rectangular(3, 1), mu_pp=0.1, mu_plane=0.2, gamma=0.05)


def test_event_check_accepts_exact_steady_states_and_rejects_perturbed_ones(row3):
    ed = models.simulate(row3, seed=1)
    assert ed.status == "steady"
    chk = event_check(row3, ed.last)
    assert chk.valid and chk.steady and chk.omega_dot_gap < 1e-12
    assert step_check(row3, ed.last, 1e-3).valid
    bad = copy.deepcopy(ed.last)
    k = int(np.flatnonzero(bad.s != 0)[0])
    bad.S[k] *= 0.9  # a sliding contact below the Coulomb bound
    assert not event_check(row3, bad).valid
    assert not step_check(row3, bad, 1e-3).valid


def test_steady_states_agree_and_cross_check(row3):
    cmp = compare_integrators(row3, seed=1, hs=(4e-3, 2e-3))
    for r in cmp.rows:
        assert r.run.status == "steady" and r.d_states == 0
        assert r.d_alpha < 1e-12 and r.d_mu_g < 1e-12
        assert r.ts_in_event.valid and r.ts_in_event.steady and r.ed_in_step.valid
        assert r.modes == cmp.modes


@pytest.mark.slow
def test_first_order_in_h(row3):
    """The error an event leaves is (t_{k+1} - t_event) |jump of omega'| <= h |jump|; averaged
    over shifted grids, the sup error over the steps halves with h (order 1)."""
    cmp = compare_integrators(row3, seed=1, hs=(8e-3, 4e-3, 2e-3), t_max=1.7, phases=6)
    orders = cmp.orders("d_omega_max")
    assert all(0.75 <= o <= 1.25 for o in orders), orders


def test_2x2_event_accelerations_not_unique_by_the_laws_themselves():
    """docs/mechanics.md example 1: the MILP's second solution of the event at t = 8.52281
    keeps every contact closed (a_n = 0) and satisfies the laws contact by contact
    (event_check, which does not use the event LCP), with other angular accelerations."""
    from rigidlcp import lcp
    from rigidlcp.models.engine.records import EventRecord
    from rigidlcp.verify.certificates.certify import certify

    system = models.System(models.rectangular(2, 2), mu_pp=0.1, mu_plane=0.2, gamma=0.1)
    run = models.simulate(system, seed=1, select="none")
    assert abs(run.records[6].t - 8.52281) < 1e-5
    state = run.state_at(6)
    ep = models.event_problem(system, state)
    sol = lcp.solve(ep.lcp, "lemke")
    cert = certify(ep, sol, uniqueness="milp")
    assert cert.observables["accelerations"] is False and cert.observables["forces"] is False
    # Which other solutions the MILP returns depends on the HiGHS build: assert the property
    # (some other solution keeps every contact closed and has other accelerations), not which.
    ours = ep.unpack(sol.z)
    closed = [o for o in map(ep.unpack, cert.others) if np.abs(o.a_n).max() < 1e-12]
    other = max(closed, key=lambda o: np.abs(o.omega_dot - ours.omega_dot).max())
    assert np.abs(other.omega_dot - ours.omega_dot).max() > 1e-3
    rec = EventRecord(t=state.t, V=state.V, omega=state.omega, omega_dot=other.omega_dot,
                      R=other.R, S=other.S, s=other.s, s_in=state.s, vt=None, at=other.a_t,
                      mu_g=0.0, dissipation=0.0, iterations=0, residual=0.0, n_lcp=0,
                      method="milp")
    assert event_check(system, rec).valid


@pytest.mark.slow
def test_two_valid_steady_states_selected_by_the_rule():
    """rect 5x3, gamma 0.3: the two integrators end with the same contact states and mu_g but
    angular accelerations 4e-3 apart; both satisfy the other's laws, lemke's own vertex at the
    time-stepper's state is the time-stepper's steady state, and the least-sum-R face walk
    moves it to the event-driven one (docs/integrators.md)."""
    from rigidlcp.models.timestepping import moreau_jean
    from rigidlcp.verify.integrators import examine_steady_states

    system = models.System(models.rectangular(5, 3), mu_pp=0.1, mu_plane=0.2, gamma=0.3)
    ed = models.simulate(system, seed=1)
    ts = moreau_jean(system, seed=1, h=4e-3)
    x = examine_steady_states(system, ed, ts, 4e-3)
    assert x.differing == [] and x.d_alpha > 1e-3
    assert x.ts_in_event.valid and x.ts_in_event.steady and x.ed_in_step.valid
    assert x.raw_vs_ts < 1e-10 and x.selected_vs_ed < 1e-10
    assert x.sum_R[0] < x.sum_R[1]  # the event-driven rule: least sum R
    assert x.ed_from_ts.status == "steady"
    assert np.allclose(x.ed_from_ts.last.omega_dot, ed.last.omega_dot, atol=1e-10)
    assert np.allclose(x.ts_from_ed.last.omega_dot, ts.last.omega_dot, atol=1e-10)
