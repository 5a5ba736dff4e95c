"""The event LCP against the contact laws themselves (Eqs. 2.5-2.7, 2.10) and the paper's
alternative-equation enumeration (Sec. II C), with mixed coefficients of friction."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp, models
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.event import State, contact_matrix, event_problem
from rigidlcp.verify.certificates.laws import check_contact_laws

TOL = 1e-8


def state_enumeration(system, state):
    """The paper's way (Sec. II C) done exhaustively: every vector of contact states (T/NT,
    and NS/S+/S- for a candidate), the linear system of Eq. (2.15), kept when it is
    nonsingular and its solution satisfies the inequalities. Returns the accelerations found."""
    c, mu = system.c, system.mu
    dyn = Dynamics(system)
    cand = (state.s == 0) & (mu > 0)
    options = [[0, 1, -1] if cand[a] else [int(state.s[a])] for a in range(c)]
    found = []
    for normal in itertools.product([True, False], repeat=c):
        for tang in itertools.product(*options):
            tang = np.array(tang)
            Mc, b = contact_matrix(system, np.array(normal), tang, dyn)
            if np.linalg.matrix_rank(Mc) < 2 * c:
                continue
            x = np.linalg.solve(Mc, b)
            R, S = x[:c], x[c:]
            a = dyn.relative_accelerations(x)
            an, at = a[:c], a[c:]
            ok = np.all(R >= -TOL) and np.all(an >= -TOL) and np.all(np.abs(S) <= mu * R + TOL)
            started = cand & (tang != 0)  # a candidate that slides must accelerate that way
            ok &= np.all(tang[started] * at[started] >= -TOL)
            if ok:
                found.append(dyn.accelerations(x))
    return found


def mixed_system(lattice, lx, ly):
    return models.System(models.make_lattice(lattice, lx, ly), mu_pp=0.3, mu_plane=0.15,
                         mu_wall=0.45, gamma=0.4)


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 10_000), stick=st.sets(st.integers(0, 4), max_size=3))
def test_lcp_equals_contact_laws_row_of_two(seed, stick):
    """2x1 row with mixed mu: every LCP solution obeys the contact laws, and every solution of
    the paper's state enumeration is among the LCP's solutions."""
    system = mixed_system("rect", 2, 1)
    rng = np.random.default_rng(seed)
    omega = rng.uniform(-1, 1, system.p)
    s = models.initial_state(system, omega=omega).s
    s[sorted(stick)] = 0  # some contacts as non-sliding candidates
    state = State(0.0, omega, 0.0, s)
    ep = event_problem(system, state)
    sols = lcp.enumerate_solutions(ep.lcp)
    assert sols, "the event LCP has a solution"
    acc_lcp = []
    for sol in sols:
        es = ep.unpack(sol.z)
        check_contact_laws(system, state, es.R, es.S)
        acc_lcp.append(np.concatenate([es.trans_acc, es.omega_dot]))
    # The converse cannot be asked of the enumeration: the row between the walls is hyperstatic,
    # so its all-transmitting state systems are singular and skipped there.
    for a in state_enumeration(system, state):
        assert any(np.allclose(a, b, atol=1e-7) for b in acc_lcp)


@pytest.mark.parametrize("lattice, lx, ly", [("rect", 2, 2), ("tri", 3, 2), ("rect", 1, 1)])
def test_lemke_solution_obeys_contact_laws(lattice, lx, ly):
    system = mixed_system(lattice, lx, ly)
    for seed in range(5):
        state = models.initial_state(system, seed=seed)
        state.s[::3] = 0  # mixed candidates and sliding contacts
        ep = event_problem(system, state)
        sol = lcp.solve(ep.lcp, "lemke")
        assert sol.success and sol.residual < 1e-10
        es = ep.unpack(sol.z)
        check_contact_laws(system, state, es.R, es.S)
        # The paper's contact matrix (Eq. 2.15) for the solution's states holds for its forces.
        normal = es.R > 1e-9
        Mc, b = contact_matrix(system, normal, es.s)
        assert np.allclose(Mc @ np.concatenate([es.R, es.S]), b, atol=1e-9)


def test_mlcp_schur_complement_is_the_lcp():
    system = mixed_system("tri", 4, 3)
    state = models.initial_state(system, seed=3)
    state.s[::2] = 0
    ep = event_problem(system, state)
    reduced = ep.mlcp.to_lcp()
    assert np.allclose(reduced.M, ep.lcp.M, atol=1e-12)
    assert np.allclose(reduced.q, ep.lcp.q, atol=1e-12)
    sol = lcp.solve(ep.mlcp, "lemke")
    assert sol.success and sol.eq_residual < 1e-10
    # u of the MLCP is the generalized acceleration computed from the forces.
    assert np.allclose(sol.u, ep.dyn.accelerations(ep.forces(sol.z)), atol=1e-10)


def test_lcp_size_is_c_plus_two_candidates():
    system = mixed_system("rect", 3, 2)
    state = models.initial_state(system, seed=0)
    state.s[:5] = 0
    ep = event_problem(system, state)
    k = int(np.sum((state.s == 0) & (system.mu > 0)))
    assert ep.lcp.n == system.c + 2 * k


def test_contact_matrix_rejects_bad_states():
    system = mixed_system("rect", 2, 1)
    with pytest.raises(ValueError, match="one state per contact"):
        contact_matrix(system, np.ones(3, bool), np.zeros(3, int))
    with pytest.raises(ValueError, match="tangential states"):
        contact_matrix(system, np.ones(system.c, bool), np.full(system.c, 2))


# -- the event as a friction-contact problem (lcp.FrictionContact2D) ---------------------------


@pytest.mark.parametrize("method", ["lemke", "states", "nsgs", "newton-fb"])
def test_event_as_friction_contact_problem_obeys_the_contact_laws(method):
    """Every event of a run, cast as a FrictionContact2D and solved by a friction-contact
    method, gives forces that satisfy the contact laws checked from the forces alone
    (verify.certificates.laws, independent of both formulations)."""
    from rigidlcp.verify.certificates.laws import contact_law_residuals

    system = models.System(models.rectangular(4, 2), mu_pp=0.3, mu_plane=0.5, mu_wall=0.2,
                           gamma=0.1)
    run = models.simulate(system, seed=3, max_events=6)
    assert run.n_events >= 3
    for k in range(run.n_events):
        state = run.state_at(k)
        ep = models.event_problem(system, state)
        fc = ep.friction_contact()
        assert fc.c == system.c and np.all(fc.mu[ep.s != 0] == 0)
        sol = lcp.solve(fc, method=method)
        assert sol.status == "solved", (k, sol)
        lam = ep.forces_of(sol.z)
        R, S = lam[: system.c], lam[system.c:]
        scale = max(1.0, float(np.abs(lam).max()))
        worst = max(contact_law_residuals(system, state, R, S).values())
        assert worst <= 1e-7 * scale, (k, contact_law_residuals(system, state, R, S))
        # the same forces give the same relative accelerations in both layouts
        a = ep.dyn.relative_accelerations(lam)
        u = fc.u(sol.z)
        assert np.allclose(u[0::2], a[: system.c], atol=1e-8 * scale)


@pytest.mark.parametrize("kwargs, message", [
    ({"seed": -1}, "seed must be an integer >= 0"),
    ({"seed": 1, "omega_scale": -1.0}, "omega_scale must be a finite number >= 0"),
    ({"omega": np.zeros(3)}, "one angular velocity per disk"),
    ({"omega": np.full(8, np.nan)}, "omega contains NaN or Inf"),
])
def test_initial_state_bad_input_is_a_typed_error(kwargs, message):
    from rigidlcp.lcp.errors import InvalidInput

    system = models.System(models.rectangular(4, 2))
    with pytest.raises(InvalidInput, match=message):
        models.initial_state(system, **kwargs)
