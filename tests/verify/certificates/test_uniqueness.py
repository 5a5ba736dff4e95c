"""verify.certificates.uniqueness:
the P-matrix test, scales, and the MILP search for another solution."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.verify.certificates.uniqueness import (
    milp_search,
    p_matrix_test,
    scaled_residual,
    sign_pattern,
)
from rigidlcp.verify.strategies import lcps, p_matrices

SETTINGS = settings(max_examples=25, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])

#: w = M z + q with M = [[1, 2], [2, 1]], q = (-1, -1): three solutions,
#: z = (1, 0), (0, 1) and (1/3, 1/3) (the standard example of a non-P LCP).
TWO_M = np.array([[1.0, 2.0], [2.0, 1.0]])
TWO_Q = np.array([-1.0, -1.0])
TWO_SOLUTIONS = [np.array([1.0, 0.0]), np.array([0.0, 1.0]), np.array([1.0, 1.0]) / 3]


def is_solution(M, q, z, tol=1e-8) -> bool:
    return scaled_residual(M, q, z) <= tol


def with_two_solution_block(M: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Append the 2 x 2 block above to an LCP (block diagonal): the result has >= 3 solutions."""
    n = q.size
    big = np.zeros((n + 2, n + 2))
    big[:n, :n] = M
    big[n:, n:] = TWO_M
    return big, np.r_[q, TWO_Q]


# -- P-matrix test -------------------------------------------------------------------------------


@SETTINGS
@given(p_matrices(st.integers(1, 7)))
def test_p_matrices_are_recognized(M):
    res = p_matrix_test(M)
    assert res.is_p is True, res.message


def test_negative_principal_minor_is_found():
    # Positive diagonal, but det of the leading 2 x 2 block is 1 - 4 < 0.
    res = p_matrix_test(TWO_M)
    assert res.is_p is False
    M = np.array([[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]]) + 0.1 * np.triu(
        np.ones((3, 3)), 1)
    res = p_matrix_test(M)
    assert res.is_p is False and res.witness == (0, 1)


def test_zero_diagonal_is_not_p():
    M = np.array([[0.0, 1.0], [-1.0, 1.0]])
    res = p_matrix_test(M)
    assert res.is_p is False and res.witness == (0,)


def test_nonsymmetric_p_matrix_without_pd_symmetric_part():
    # [[1, -3], [0, 1]]: minors 1, 1, 1 (P), but (M + M^T)/2 has eigenvalues 1 +- 1.5.
    M = np.array([[1.0, -3.0], [0.0, 1.0]])
    res = p_matrix_test(M)
    assert res.is_p is True and res.how == "principal minors" and res.minors_checked == 3


def test_large_n_without_sufficient_condition_is_undecided():
    M = np.eye(14)
    M[0, 1] = -5.0  # triangular: still P, but the symmetric part is indefinite
    res = p_matrix_test(M, max_n=12)
    assert res.is_p is None


# -- scales and patterns -------------------------------------------------------------------------


def test_scaled_residual_and_pattern():
    z = np.array([1.0, 0.0])
    assert scaled_residual(TWO_M, TWO_Q, z) == 0.0
    assert scaled_residual(TWO_M, TWO_Q, z + np.array([0.0, 1e-3])) > 1e-4
    w = TWO_M @ z + TWO_Q
    assert sign_pattern(z, w, 1.0, 4.0, 1e-6).tolist() == [1, -1]
    assert sign_pattern(np.zeros(2), np.zeros(2), 1.0, 1.0, 1e-6).tolist() == [0, 0]


# -- MILP search ---------------------------------------------------------------------------------


@pytest.mark.parametrize("start", range(3))
def test_milp_finds_another_solution_of_the_two_solution_lcp(start):
    z0 = TWO_SOLUTIONS[start]
    res = milp_search(TWO_M, TWO_Q, z0, "pattern")
    assert res.status == "found", res.message
    assert is_solution(TWO_M, TWO_Q, res.other)
    assert np.max(np.abs(res.other - z0)) > 0.1
    assert any(np.allclose(res.other, s, atol=1e-9) for s in TWO_SOLUTIONS)


@SETTINGS
@given(lcps(p_matrices(st.integers(1, 6)), planted=True))
def test_milp_finds_nothing_for_p_matrices(problem):
    z = lcp.solve(problem, method="lemke").z
    res = milp_search(problem.M, problem.q, z, "pattern", time_limit=20)
    assert res.status == "none", res.message
    res = milp_search(problem.M, problem.q, z, "values", problem.M, time_limit=20)
    assert res.status == "none", res.message


@SETTINGS
@given(lcps(p_matrices(st.integers(1, 5)), planted=True))
def test_milp_finds_the_planted_second_block(problem):
    M, q = with_two_solution_block(problem.M, problem.q)
    z = lcp.solve(lcp.LCP(M, q), method="lemke").z
    res = milp_search(M, q, z, "pattern", time_limit=20)
    assert res.status == "found", res.message
    assert is_solution(M, q, res.other)
    # The P block's part is unique; the other solution differs in the 2 x 2 block only.
    n = problem.n
    assert np.allclose(res.other[:n], z[:n], atol=1e-7 * max(1.0, np.abs(z).max()))
    assert np.max(np.abs(res.other[n:] - z[n:])) > 0.1
    res = milp_search(M, q, z, "values", M, time_limit=20)  # and w differs too
    assert res.status == "found" and is_solution(M, q, res.other)


def test_milp_verdict_is_relative_to_the_box():
    # w = 1 - z: z = 0 (w = 1) and z = 1 (w = 0). From z = 0 the other lies at z = 1.
    M, q = np.array([[-1.0]]), np.array([1.0])
    found = milp_search(M, q, np.zeros(1), "pattern")
    assert found.status == "found" and np.allclose(found.other, [1.0])
    hidden = milp_search(M, q, np.zeros(1), "pattern", bound=0.5)
    assert hidden.status == "none" and hidden.bound == 0.5


def test_milp_degenerate_continuum():
    # M = 0, q = 0: every z >= 0 solves it; from the degenerate z = 0 another one is found.
    M, q = np.zeros((1, 1)), np.zeros(1)
    res = milp_search(M, q, np.zeros(1), "pattern")
    assert res.status == "found" and res.other[0] > 0
    # ... but w = 0 for all of them: the value search on w finds nothing.
    assert milp_search(M, q, np.zeros(1), "values", M).status == "none"


def test_milp_values_on_an_observable():
    # Solutions (1, 0) and (0, 1) have the same sum: L = [1, 1] cannot tell them apart, but
    # (1/3, 1/3) has sum 2/3: from (1, 0) a different L z exists.
    L = np.array([[1.0, 1.0]])
    res = milp_search(TWO_M, TWO_Q, TWO_SOLUTIONS[0], "values", L)
    assert res.status == "found"
    assert abs(L @ res.other - 1.0)[0] > 1e-3


def test_milp_bad_arguments():
    with pytest.raises(ValueError):
        milp_search(TWO_M, TWO_Q, TWO_SOLUTIONS[0], "nonsense")
    with pytest.raises(ValueError):
        milp_search(TWO_M, TWO_Q, TWO_SOLUTIONS[0], "values")


#: Issue 11: M = diag(0.5, [[1, 2], [2, 1]]), q = -1 has the solutions (2, 0, 1), (2, 1, 0) and
#: (2, 1/3, 1/3) (the block of TWO_M next to 0.5 z_0 = 1). With scipy 1.11.1 the MILP chose a
#: disjunct (row 0 of w moves) that only rounding satisfied, the polish tried that disjunct
#: alone, and the three true bases were cut: a false "none".
ISSUE_M = np.block([[np.array([[0.5]]), np.zeros((1, 2))], [np.zeros((2, 1)), TWO_M]])
ISSUE_Q = -np.ones(3)


@pytest.mark.parametrize("target", ["values", "pattern"])
def test_milp_finds_the_other_solutions_of_the_issue_example(target):
    z = np.array([2.0, 0.0, 1.0])
    assert is_solution(ISSUE_M, ISSUE_Q, z)
    res = milp_search(ISSUE_M, ISSUE_Q, z, target, ISSUE_M if target == "values" else None)
    assert res.status == "found", res.message
    assert is_solution(ISSUE_M, ISSUE_Q, res.other)
    assert any(np.allclose(res.other, o, atol=1e-9)
               for o in ([2, 1, 0], [2, 1 / 3, 1 / 3]))


def test_milp_finds_another_solution_for_the_issue_family():
    """The issue's 30 variants (M[0, 0] and q[0] changed): every one has three solutions."""
    for m00 in np.linspace(0.2, 3.0, 6):
        for q0 in (-0.5, -1.0, -2.0, -3.0, -4.0):
            M, q = ISSUE_M.copy(), ISSUE_Q.copy()
            M[0, 0], q[0] = m00, q0
            z = np.array([-q0 / m00, 0.0, 1.0])
            res = milp_search(M, q, z, "values", M)
            assert res.status == "found", (m00, q0, res.message)


def test_milp_answers_unknown_when_a_cut_was_not_proved(monkeypatch):
    """A basis whose polish failed without proof (an LP that did not decide) may hold a
    solution: a MILP made infeasible by such cuts must not answer "none"."""
    import rigidlcp.verify.certificates.uniqueness as uq

    monkeypatch.setattr(uq, "polish_basis", lambda *a, **k: (None, False))
    z = np.array([2.0, 0.0, 1.0])
    res = uq.milp_search(ISSUE_M, ISSUE_Q, z, "values", ISSUE_M, retries=10)
    assert res.status == "unknown", res.message
    assert res.info["unproved_cuts"] >= 1


#: Drawn by the deep hypothesis profile for test_milp_finds_the_planted_second_block: a 5 x 5
#: P-matrix block (planted z = (0.1, 0, 0.1, 0.1, 0.1)) beside TWO_M. At
#: mip_feasibility_tolerance 1e-9 HiGHS called the "values" MILP (L = M) infeasible although
#: the solution with the 2 x 2 block at (1, 0) instead of (0, 1) satisfies it to 2e-16 (scipy
#: 1.17.1 with presolve, 1.15.0 with or without; at 1e-8 HiGHS finds it): a false
#: "none".
PRESOLVE_M = np.array([[3.856, -1.0, 0.756, -1.0, -1.0], [0.426, 3.9599, -0.83, -1.0, -1.0],
                       [-0.998, -0.808, 2.582, 0.198, 0.478], [-1.0, -0.96, 0.128, 3.5912, -1.0],
                       [-1.0, -1.0, -0.664, 0.878, 3.642]])
PRESOLVE_Q = np.array([-0.2612, 0.3404, -0.226, -0.17192, -0.2856])


@pytest.mark.parametrize("target", ["values", "pattern"])
def test_milp_does_not_trust_a_single_infeasible(target):
    M, q = with_two_solution_block(PRESOLVE_M, PRESOLVE_Q)
    z = np.array([0.1, 0.0, 0.1, 0.1, 0.1, 0.0, 1.0])
    assert is_solution(M, q, z)
    res = milp_search(M, q, z, target, M if target == "values" else None, time_limit=20)
    assert res.status == "found", res.message
    assert is_solution(M, q, res.other)
    assert np.max(np.abs(res.other[5:] - z[5:])) > 0.1


@pytest.mark.parametrize("clock_name", ["cpu", "wall"])
def test_milp_none_needs_two_infeasible_answers(monkeypatch, clock_name):
    """"none" needs HiGHS's "infeasible" at 1e-9 and again at 1e-8; with no time
    left for the second run (on the clock the limit counts), the answer is "unknown"."""
    import rigidlcp.verify.certificates.clocked as clocked
    import rigidlcp.verify.certificates.uniqueness as uq

    M, q = np.eye(2), np.array([-1.0, 1.0])  # P-matrix: one solution, z = (1, 0)
    res = uq.milp_search(M, q, np.array([1.0, 0.0]), "pattern", clock_name=clock_name)
    assert res.status == "none" and res.info["milp_runs"] == 2, res.message
    real = uq.solve_milp

    def slow(*a, **k):  # the first run uses up the whole budget
        out = real(*a, **k)
        monkeypatch.setitem(clocked.CLOCKS, clock_name, lambda: 1e12)
        return out

    monkeypatch.setattr(uq, "solve_milp", slow)
    res = uq.milp_search(M, q, np.array([1.0, 0.0]), "pattern", clock_name=clock_name)
    assert res.status == "unknown" and res.info["milp_runs"] == 1, res.message
