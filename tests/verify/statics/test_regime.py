"""verify.statics.regime: does an event admit forces that keep every disk in place (the paper's
no-displacement regime)? Checked against a case by hand and against the event engine."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import linprog

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.verify.statics.regime import regime


def _disk_at_left_wall(gamma: float, mu_plane: float) -> models.System:
    """One unit disk on the plane touching the left wall (no right wall)."""
    lat = models.make_packing(np.array([[1.0, 1.0]]), [1.0], left=0.0, right=None)
    assert sorted(lat.kind) == ["plane", "wall"]
    return models.System(lat, mu_pp=0.0, mu_plane=mu_plane, mu_wall=0.0, gamma=gamma)


@pytest.mark.parametrize("gamma, mu_plane, held", [
    (0.3, 0.0, True),    # the inertial force -m gamma pushes the disk onto the wall
    (-0.3, 0.2, False),  # pulled off the wall: the plane holds at most mu m g = 0.2 < 0.3
    (-0.3, 0.4, True),   # ... or 0.4 >= 0.3
    (-0.3, 0.3, True),   # the bound itself: S = mu R exactly
])
def test_disk_at_a_wall_by_hand(gamma, mu_plane, held):
    """By hand: x balance -m gamma + R_wall - S_plane = 0 with R_wall >= 0, |S| <= mu m g (at
    rest every contact is a candidate): the disk stays iff gamma >= 0 or |gamma| <= mu g."""
    system = _disk_at_left_wall(gamma, mu_plane)
    state = models.initial_state(system, omega=np.zeros(1))
    r = regime(system, state)
    assert r.exists is held, r.text()
    if held:
        c = system.c
        R, S = r.lam[:c], r.lam[c:]
        assert np.all(R >= -1e-12) and np.all(np.abs(S) <= system.mu * R + 1e-12)
    else:
        run = models.simulate(system, state)
        assert run.status == "detachment"  # the engine agrees: the wall contact opens
        assert r.y is not None and "Farkas" in r.text()


def test_sliding_plane_fixes_the_friction():
    """Sliding (V0 > 0, omega = 0: v_t = -V < 0 at the plane, so S = +mu R, Eq. 2.10): the
    friction is no longer free. The plane drags the disk towards the wall with mu m g, the
    inertial force -m gamma pulls it away: x balance gives R_wall = m gamma + mu m g, >= 0 iff
    gamma >= -mu g (here mu = 0.2)."""
    for gamma, held in ((-0.3, False), (-0.1, True)):
        system = models.System(_disk_at_left_wall(gamma, 0.2).lattice, mu_pp=0.0,
                               mu_plane=0.2, mu_wall=0.0, gamma=gamma, V0=1.0)
        state = models.initial_state(system, omega=np.zeros(1))
        assert state.s[system.plane_contacts].tolist() == [-1]
        assert regime(system, state).exists is held


def _lp_says_infeasible(system: models.System, state: models.State) -> bool:
    """The same question in the variables lambda = [R; S] with inequality rows (an independent
    formulation of the regime's constraints)."""
    dyn = models.Dynamics(system)
    p, c, mu, s = system.p, system.c, np.asarray(system.mu), np.asarray(state.s)
    A = dyn.H.T.toarray()[: 2 * p]
    b = -dyn.f[: 2 * p]
    eq_rows, ub_rows = [A], []
    for a in range(c):
        e = np.zeros(2 * c)
        if mu[a] == 0 or s[a] != 0:  # S = -s mu R (0 where frictionless)
            e[c + a], e[a] = 1.0, float(s[a]) * mu[a]
            eq_rows.append(e[None])
        else:
            for sign in (1.0, -1.0):
                u = np.zeros(2 * c)
                u[c + a], u[a] = sign, -mu[a]
                ub_rows.append(u[None])
    A_eq = np.vstack(eq_rows)
    b_eq = np.r_[b, np.zeros(A_eq.shape[0] - b.size)]
    res = linprog(np.zeros(2 * c), A_ub=np.vstack(ub_rows) if ub_rows else None,
                  b_ub=np.zeros(len(ub_rows)) if ub_rows else None, A_eq=A_eq, b_eq=b_eq,
                  bounds=[(0, None)] * c + [(None, None)] * c, method="highs")
    return res.status == 2


def test_deposited_pile_spun_at_random_detaches_by_force():
    """The pile `rigidlcp pack --n 20 --seed 1 --radii 0.8:1.2` with the CLI's defaults: every
    disk-disk contact slides at t = 0 and no forces hold the pile: the certificate, the engine
    (detachment at t = 0) and an independent LP agree."""
    pile = deposit(20, seed=1, radii=(0.8, 1.2), width=8.0)
    system = models.System(pile, gamma=0.1)
    state = models.initial_state(system, seed=1)
    r = regime(system, state)
    assert r.exists is False
    assert _lp_says_infeasible(system, state)
    run = models.simulate(system, state)
    assert run.status == "detachment" and run.final.t == 0


def test_deposited_pile_runs_to_a_steady_state_in_the_regime():
    """A 12-disk pile (seed 5, width 6) with mu = 0.1 on every contact, driven at gamma = 0.1:
    the event engine reaches a steady state; at its last event every contact is closed
    (a_n = 0), no disk translates (the generalized accelerations' vx, vy vanish) and the
    regime check finds the forces that hold it."""
    pile = deposit(12, seed=5, radii=(0.8, 1.2), width=6.0)
    system = models.System(pile, mu_pp=0.1, mu_plane=0.1, mu_wall=0.1, gamma=0.1)
    run = models.simulate(system, seed=1)
    assert run.status == "steady", run.message
    last, dyn, p = run.last, models.Dynamics(system), system.p
    lam = np.r_[last.R, last.S]
    scale = float(np.max(np.abs(dyn.f)))
    assert np.max(np.abs(dyn.accelerations(lam)[: 2 * p])) <= 1e-9 * scale
    assert np.max(np.abs(dyn.relative_accelerations(lam)[: system.c])) <= 1e-9 * scale
    assert regime(system, run.final).exists is True
    assert not _lp_says_infeasible(system, run.final)


def test_time_stepper_reaches_the_same_steady_state_on_the_pile():
    """Moreau-Jean (h = 0.02) on the same pile ends steady in the same contact states with the
    same mu_g as the event engine (an independent integrator: docs/integrators.md)."""
    from rigidlcp.models.timestepping import moreau_jean

    pile = deposit(12, seed=5, radii=(0.8, 1.2), width=6.0)
    system = models.System(pile, mu_pp=0.1, mu_plane=0.1, mu_wall=0.1, gamma=0.1)
    ev = models.simulate(system, seed=1)
    ts = moreau_jean(system, seed=1, h=0.02, t_max=8)
    assert ev.status == ts.status == "steady"
    assert np.array_equal(ev.last.s, ts.records[-1].s)
    assert abs(ev.last.mu_g - ts.summary()["mu_g"]) <= 1e-9


def test_a_float_only_certificate_proves_nothing():
    """K = [-1, 1e-30], b = 1: w = (0, 1e30) solves K w = b exactly, yet y = 1 passes the
    floating-point test (b.y = 1 > 0, max K^T y = 1e-30: every solution has sum w >= 1e30,
    beyond RADIUS_LOADS). It must not be a "no"; the exact check refuses it."""
    from rigidlcp.verify.statics.regime import check

    K, b = sp.csr_matrix(np.array([[-1.0, 1e-30]])), np.array([1.0])
    r = check(K, b, np.array([1.0]))
    assert r.exists is None and r.y is not None and r.margin >= 1e29
    assert "not in exact arithmetic" in r.text()
    # K = [-1, -2]: no w >= 0 gives K w = 1, and y = 1 proves it exactly
    proved = check(sp.csr_matrix(np.array([[-1.0, -2.0]])), b, np.array([1.0]))
    assert proved.exists is False and "exact" in proved.text()


def test_the_exact_check_uses_the_product_as_stored():
    """K = A T with A = [1, 1], T = [[0.1], [-0.1]]: the float product of K is 0 or a rounding
    of it, but exactly (A T) = 0.1 - 0.1 = 0 (both 0.1 the same double), so y = 1 with b = 1 has
    (A T)^T y = 0 <= 0 and b.y = 1 > 0: proved from A and T themselves."""
    from rigidlcp.verify.statics.regime import exact_farkas

    A = sp.csr_matrix(np.array([[1.0, 1.0]]))
    T = sp.csr_matrix(np.array([[0.1], [-0.1]]))
    assert exact_farkas(A, np.array([1.0]), np.array([1.0]), T) is not None
    T_bad = sp.csr_matrix(np.array([[0.1], [-0.09999999999999999]]))  # A T > 0 exactly
    assert exact_farkas(A, np.array([1.0]), np.array([1.0]), T_bad) is None
