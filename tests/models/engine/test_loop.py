"""models.engine.loop: the stop rules and the exact event times, with a scripted backend.

The backend below prescribes the angular acceleration of one disk on the plane (rect 1 x 1)
instead of solving the contact laws, so that every number the loop computes can be derived by
hand: the plane contact's v_t is linear in time, and it reaches zero at t* = |v_t(0)| / |a_t|.
"""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.models.engine.loop import Limits, Outcome, run_events, states_after

PLANE = 0  # contact 0 of rect 1 x 1 is the disk on the plane (then the two walls)


class Scripted:
    """A backend whose event solution is prescribed: omega_dot (or a failure); forces: the
    plane's R = m g, the others zero."""

    method = "scripted"
    info = None

    def __init__(self, system, omega_dot=(0.0,), a_n=0.0, status="solved", residual=0.0):
        self.system, self.dyn = system, models.Dynamics(system)
        self.omega_dot = list(omega_dot)
        self.a_n, self.status, self.residual = a_n, status, residual
        self.calls = 0

    def solve(self, state):
        self.calls += 1
        c, p = self.system.c, self.system.p
        if self.status != "solved":
            return Outcome(self.status, self.method, "scripted failure", [PLANE])
        od = np.array([self.omega_dot[min(self.calls, len(self.omega_dot)) - 1]])
        a = self.dyn.H @ np.concatenate([np.zeros(2 * p), od]) + self.dyn.u_obs_dot
        a_n = a[:c].copy()
        a_n[PLANE] = self.a_n
        R = np.zeros(c)
        R[PLANE] = self.system.masses[0] * self.system.g  # the plane holds the weight: the
        # disk does not translate (the loop stops a run whose disks would)
        return Outcome("solved", self.method, R=R, S=np.zeros(c), omega_dot=od,
                       a_n=a_n, a_t=a[c:], residual=self.residual, scale=1.0, n_lcp=c)


@pytest.fixture
def system():
    return models.System(models.rectangular(1, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                         gamma=0.0)


def start(system, omega=1.0):
    return models.initial_state(system, omega=[omega])


def test_event_time_is_exact_and_the_run_ends_steady(system):
    state = start(system)
    dyn = models.Dynamics(system)
    vt0 = dyn.velocities(state.omega, state.V)[system.c + PLANE]
    # omega_dot = -0.25 drives omega (hence v_t at the plane, linear in omega) to zero at t = 4;
    # then omega_dot = 0 keeps the contact non-sliding: no further event.
    run = run_events(system, state, Scripted(system, omega_dot=[-0.25, 0.0]))
    assert vt0 != 0 and state.s[PLANE] == np.sign(vt0)
    assert run.status == "steady" and run.n_events == 2
    assert run.records[1].t == pytest.approx(4.0, rel=1e-15)
    assert run.records[1].s_in[PLANE] == 0  # it arrived as a non-sliding candidate
    assert run.records[1].omega == pytest.approx([0.0], abs=1e-15)


def test_time_limit_advances_the_final_state_to_t_max(system):
    run = run_events(system, start(system), Scripted(system, omega_dot=[-0.25]),
                     Limits(t_max=1.5))
    assert run.status == "time_limit" and run.n_events == 1
    assert run.final.t == 1.5 and run.final.omega == pytest.approx([1.0 - 0.25 * 1.5])


def test_event_limit(system):
    run = run_events(system, start(system), Scripted(system, omega_dot=[-0.25, 0.0]),
                     Limits(max_events=1))
    assert run.status == "event_limit" and run.n_events == 1 and run.final.t == 0.0


def test_failure_of_the_backend_stops_with_its_status_and_contacts(system):
    run = run_events(system, start(system), Scripted(system, status="no_solution"))
    assert run.status == "no_solution" and run.contacts == [PLANE] and run.n_events == 0
    assert "scripted failure" in run.message


def test_residual_above_tolerance_is_solver_failed(system):
    run = run_events(system, start(system), Scripted(system, residual=2e-8),
                     Limits(check_tol=1e-8))
    assert run.status == "solver_failed" and "residual" in run.message


def test_opening_contact_is_detachment_and_named(system):
    run = run_events(system, start(system), Scripted(system, a_n=1e-3))
    assert run.status == "detachment" and run.contacts == [PLANE]
    assert "plane" in run.message and run.n_events == 1


def test_zeno_guard_stops_accumulating_events(system):
    # With zeno_events = 0 the guard allows no event at all within its window: the next event
    # (t = 4, inside the 10-unit window) is reported as accumulating, and not taken.
    run = run_events(system, start(system), Scripted(system, omega_dot=[-0.25, 0.0]),
                     Limits(zeno_events=0, zeno_time=10.0))
    assert run.status == "zeno" and run.n_events == 1


def test_states_after_follow_eq_2_7():
    mu = np.array([0.2, 0.2, 0.2, 0.0])
    s_in = np.array([1, 0, 0, 1])  # sliding, two candidates, frictionless
    a_t = np.array([-5.0, 3.0, 1e-12, 7.0])
    assert states_after(s_in, mu, a_t, tol_a=1e-9).tolist() == [1, 1, 0, 0]


def test_records_light_keeps_only_the_last_arrays(system):
    run = run_events(system, start(system), Scripted(system, omega_dot=[-0.25, 0.0]),
                     records="light")
    assert run.records[0].omega.size == 0 and run.records[-1].omega.size == 1
    with pytest.raises(ValueError, match="records"):
        run_events(system, start(system), Scripted(system), records="some")


def test_a_translating_disk_ends_the_regime():
    """A disk on the plane alone (no wall) dragged by the sliding plane: every contact stays
    closed (a_n = 0) but the friction mu m g accelerates it sideways; the paper's regime ends
    (the arrays never have such a mechanism: their contacts block every translation)."""
    lat = models.make_packing(np.array([[3.0, 1.0]]), [1.0], left=0.0, right=None)
    system = models.System(lat, mu_plane=0.2, gamma=0.0, V0=1.0)
    run = models.simulate(system, omega=np.zeros(1))
    assert run.status == "detachment" and run.n_events == 1
    assert "would translate" in run.message and "|v'| = 0.2" in run.message
