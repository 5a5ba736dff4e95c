"""verify.certify: acceptance, and the three uniqueness verdicts kept apart."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from rigidlcp import lcp, models
from rigidlcp.verify import certify
from rigidlcp.verify.certificates.uniqueness import scaled_residual
from rigidlcp.verify.strategies import lcps, mlcps, p_matrices

SETTINGS = settings(max_examples=25, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])
TWO_M = np.array([[1.0, 2.0], [2.0, 1.0]])
TWO_Q = np.array([-1.0, -1.0])


# -- acceptance ----------------------------------------------------------------------------------


@SETTINGS
@given(lcps(p_matrices(st.integers(1, 6)), planted=True), st.data())
def test_accepts_a_solution_and_rejects_a_perturbed_one(problem, data):
    sol = lcp.solve(problem, method="lemke")
    cert = certify(problem, sol, uniqueness="none")
    assert cert.accepted and cert.scaled_residual <= 1e-8
    i = data.draw(st.integers(0, problem.n - 1))
    sign = data.draw(st.sampled_from([1.0, -1.0]))
    bad = sol.z.copy()
    bad[i] += sign * 1e-4 * cert.z_scale
    rejected = certify(problem, bad, uniqueness="auto")
    assert not rejected.accepted
    assert rejected.scaled_residual > 1e-8
    assert rejected.z_unique is None and rejected.w_unique is None  # not assessed


def test_solver_w_is_not_trusted():
    problem = lcp.LCP(np.eye(2), np.array([-1.0, 1.0]))
    sol = lcp.solve(problem, method="lemke")
    sol.w = np.zeros(2)  # a lying w; the certificate recomputes it
    sol.z = np.array([1.0, 0.5])  # wrong z (w_2 = 1.5 > 0 and z_2 > 0)
    assert not certify(problem, sol).accepted


@SETTINGS
@given(mlcps())
def test_mlcp_residuals_and_u(problem):
    sol = lcp.solve(problem, method="lemke")
    if sol.status != "solved":
        return
    cert = certify(problem, sol, uniqueness="none")
    assert cert.accepted, cert
    assert cert.scaled_eq_residual <= 1e-8
    bad_u = sol.u + 1e-3 * (1.0 + np.abs(sol.u).max())
    sol.u = bad_u
    assert not certify(problem, sol, uniqueness="none").accepted  # equality residual


# -- uniqueness: P-matrices ----------------------------------------------------------------------


@SETTINGS
@given(lcps(p_matrices(st.integers(1, 8)), planted=True))
def test_p_matrix_lcp_is_certified_unique(problem):
    cert = certify(problem, lcp.solve(problem, method="lemke"))
    assert cert.accepted
    assert cert.method.startswith("P-matrix")
    assert cert.w_unique is True and cert.z_unique is True
    # the pattern is unique exactly when the solution is nondegenerate
    assert cert.pattern_unique is (cert.degenerate.size == 0)


def test_degenerate_p_matrix_solution_has_no_unique_pattern():
    # M = I, q = (0, -1): z = (0, 1), w = (0, 0): pair 0 is degenerate (both alternatives hold).
    problem = lcp.LCP(np.eye(2), np.array([0.0, -1.0]))
    cert = certify(problem, np.array([0.0, 1.0]))
    assert cert.z_unique is True and cert.w_unique is True
    assert cert.pattern_unique is False and cert.degenerate.tolist() == [0]


# -- uniqueness: a constructed LCP with several solutions ---------------------------------------


@pytest.mark.parametrize("method", ["enumeration", "milp", "auto"])
def test_two_solution_lcp_is_non_unique(method):
    problem = lcp.LCP(TWO_M, TWO_Q)
    z = np.array([1.0, 0.0])
    cert = certify(problem, z, uniqueness=method)
    assert cert.accepted
    assert cert.z_unique is False and cert.w_unique is False and cert.pattern_unique is False
    assert cert.other is not None and scaled_residual(TWO_M, TWO_Q, cert.other) <= 1e-8
    assert np.max(np.abs(cert.other - z)) > 0.1
    if method == "enumeration":
        assert len(cert.others) == 2  # (0, 1) and (1/3, 1/3)


@SETTINGS
@given(lcps(p_matrices(st.integers(1, 4)), planted=True))
def test_planted_second_block_found_by_enumeration_and_milp(problem):
    n = problem.n
    M = np.zeros((n + 2, n + 2))
    M[:n, :n] = problem.M
    M[n:, n:] = TWO_M
    big = lcp.LCP(M, np.r_[problem.q, TWO_Q])
    sol = lcp.solve(big, method="lemke")
    for method in ("enumeration", "milp"):
        cert = certify(big, sol, uniqueness=method)
        assert cert.method.startswith(method)
        assert cert.z_unique is False and cert.w_unique is False, cert
        assert scaled_residual(big.M, big.q, cert.other) <= 1e-8


def test_w_unique_but_z_not_frictionless_row():
    """A frictionless row between walls: the row compression is free (a self-stress), so the
    forces are not unique; M is symmetric PSD (a convex QP), so w = M z + q is."""
    system = models.System(models.rectangular(3, 1), mu_pp=0.0, mu_plane=0.0, mu_wall=0.0,
                           gamma=0.1)
    ep = models.event_problem(system, models.initial_state(system))
    sol = lcp.solve(ep.lcp, method="lemke")
    for method in ("enumeration", "milp"):
        cert = certify(ep, sol, uniqueness=method)
        assert cert.accepted
        assert cert.w_unique is True, cert
        assert cert.observables["accelerations"] is True
        assert cert.z_unique is False and cert.observables["forces"] is False
        assert cert.pattern_unique is False
        other = ep.unpack(cert.other)
        np.testing.assert_allclose(other.omega_dot, ep.unpack(sol.z).omega_dot, atol=1e-9)


# -- the 2 x 2 rectangular array whose accelerations are not unique ------------------------------

#: The event reached at t ~ 8.52 from initial_state(seed=1) (docs/verification.md): plane and
#: vertical disk-disk contacts are non-sliding candidates, the two lateral disk-disk contacts
#: slide (s = +1 bottom row, -1 top row); walls are frictionless.
STATE_S = np.array([0, 0, 0, 1, 0, 0, 0, 0, -1, 0])
#: The "hanging" solution's basis: the top-right disk hangs by friction (S = mu R = 1) on the
#: lateral contact #8, loaded by the top row's self-stress (R = m g / mu = 10).
HANGING_BASIS = list(range(12)) + [17]


@pytest.fixture(scope="module")
def example_2x2():
    system = models.System(models.rectangular(2, 2), mu_pp=0.1, mu_plane=0.2, gamma=0.1)
    ep = models.event_problem(system, models.State(8.52, np.zeros(4), 0.0, STATE_S))
    natural = lcp.solve(ep.lcp, method="lemke")
    M, q, n = ep.lcp.M, ep.lcp.q, ep.lcp.n
    beta = [i for i in range(n) if i not in HANGING_BASIS]
    res = linprog(np.ones(n), A_eq=M[HANGING_BASIS], b_eq=-q[HANGING_BASIS], A_ub=-M[beta],
                  b_ub=q[beta], bounds=[(0, None) if i in HANGING_BASIS else (0, 0)
                                        for i in range(n)], method="highs")
    assert res.status == 0
    return ep, natural.z, res.x


def test_2x2_example_solutions(example_2x2):
    ep, natural, hanging = example_2x2
    nat, hang = ep.unpack(natural), ep.unpack(hanging)
    assert certify(ep, natural, uniqueness="none").accepted
    assert certify(ep, hanging, uniqueness="none").accepted
    np.testing.assert_allclose(nat.omega_dot, [-0.1, -0.1, 0.1, 0.1], atol=1e-9)
    np.testing.assert_allclose(hang.omega_dot, [-0.1, -0.1, -1.6, -2.0], atol=1e-9)
    np.testing.assert_allclose([hang.R[8], hang.S[8]], [10.0, 1.0], atol=1e-9)


def test_2x2_example_is_not_unique_in_w(example_2x2):
    ep, natural, hanging = example_2x2
    cert = certify(ep, natural)  # n = 18 > 10: "auto" takes the staged path
    assert cert.accepted and cert.method.startswith("staged (auto")
    assert cert.w_unique is False and cert.z_unique is False and cert.pattern_unique is False
    assert cert.observables["accelerations"] is False
    # The evidence, whichever other solutions the MILP returns (HiGHS versions differ): each
    # is a checked solution of the event, and one has other angular accelerations.
    assert cert.others
    for other in cert.others:
        assert certify(ep, other, uniqueness="none").accepted
    mine = ep.unpack(natural).omega_dot
    assert any(np.max(np.abs(ep.unpack(o).omega_dot - mine)) > 1e-6 * np.max(np.abs(mine))
               for o in cert.others)


def test_2x2_example_natural_solution_found_from_the_hanging_one(example_2x2):
    ep, natural, hanging = example_2x2
    cert = certify(ep, hanging, objective="min-sum")
    assert cert.w_unique is False and cert.observables["accelerations"] is False
    target = ep.unpack(natural).omega_dot
    assert any(np.allclose(ep.unpack(o).omega_dot, target, atol=1e-8) for o in cert.others), \
        [ep.unpack(o).omega_dot for o in cert.others]


def test_repr_and_bad_arguments():
    problem = lcp.LCP(TWO_M, TWO_Q)
    text = repr(certify(problem, np.array([1.0, 0.0])))
    assert "ACCEPTED" in text and "another solution exists" in text
    with pytest.raises(ValueError):
        certify(problem, np.zeros(3))
    with pytest.raises(ValueError):
        certify(problem, np.zeros(2), uniqueness="guess")


def test_defaults_decide_fig9_events():
    """verify.certify at its defaults (uniqueness="auto") decides every question at events of
    Fig. 9's run (n = 84 and more: beyond the enumeration, the staged path; issue 21.5), and
    each "another solution exists" rests on a witness that is itself accepted."""
    from rigidlcp import models
    from rigidlcp.verify.forces.polyhedra import event_z

    system = models.System(models.rectangular(10, 4), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.16)
    run = models.simulate(system, seed=1, max_events=10)
    for k in (0, run.n_events - 1):
        ep = models.event_problem(system, run.state_at(k))
        z = event_z(ep, np.r_[run.records[k].R, run.records[k].S])
        cert = certify(ep, z)
        assert cert.accepted and cert.method.startswith("staged (auto")
        flags = [cert.w_unique, cert.z_unique, cert.pattern_unique, *cert.observables.values()]
        assert None not in flags, cert
        if False in flags:
            assert cert.others and all(certify(ep, o, uniqueness="none").accepted
                                       for o in cert.others)
