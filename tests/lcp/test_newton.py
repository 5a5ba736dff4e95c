"""lcp.newton: semismooth Newton (min map, Fischer-Burmeister) against Lemke and the Schur
reduction on problems with one solution, and its statuses where there is none."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.verify.strategies import lcps, mlcps, p_matrices

SETTINGS = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def close(a, b, tol=1e-8) -> bool:
    return bool(np.max(np.abs(a - b)) <= tol * max(1.0, float(np.max(np.abs(b)))))


@SETTINGS
@given(lcps(p_matrices(st.integers(1, 15))))
def test_fb_newton_agrees_with_lemke_on_p_matrix_lcps(problem):
    ref = lcp.solve(problem, "lemke")
    assert ref.status == "solved"
    sol = lcp.solve(problem, "newton-fb")
    assert sol.status == "solved", sol
    assert close(sol.z, ref.z, 1e-7)


@SETTINGS
@given(lcps(p_matrices(st.integers(1, 15))))
def test_min_newton_when_solved_agrees_with_lemke(problem):
    sol = lcp.solve(problem, "newton-min")
    if sol.status == "solved":  # local: it may stop, it never claims a wrong answer
        assert close(sol.z, lcp.solve(problem, "lemke").z, 1e-7)


@SETTINGS
@given(mlcps())
def test_newton_on_the_unreduced_mlcp_matches_the_schur_reduction(problem):
    ref = lcp.solve(problem, "lemke")
    for name in ("newton-fb", "newton-min"):
        sol = lcp.solve(problem, name)
        if name == "newton-min" and sol.status != "solved":
            continue
        assert sol.status == "solved", (name, sol)
        assert close(sol.v, ref.v, 1e-7) and close(sol.u, ref.u, 1e-7)


def test_no_solution_is_never_solved():
    # w = -z - 1 < 0 for every z >= 0: no solution.
    p = lcp.LCP(np.array([[-1.0]]), np.array([-1.0]))
    for name in ("newton-min", "newton-fb"):
        sol = lcp.solve(p, name)
        # lcp.solve turns a stop without solution into "infeasible" when it can prove it
        # (issue 11): y = 1 has M^T y = -1 <= 0 and q^T y = -1 < 0
        assert sol.status in ("not_converged", "max_iter", "infeasible"), sol
        if sol.status == "infeasible":
            assert sol.info["farkas"] == pytest.approx([1.0])


def test_options_are_checked():
    p = lcp.LCP(np.eye(2), -np.ones(2))
    with pytest.raises(lcp.InvalidProblem, match="tol"):
        lcp.solve(p, "newton-fb", tol=2.0)
    with pytest.raises(lcp.InvalidProblem, match="max_iter"):
        lcp.solve(p, "newton-min", max_iter=0)
    sol = lcp.solve(p, "newton-min", z0=np.array([5.0, 5.0]))
    assert sol.status == "solved" and np.allclose(sol.z, 1.0)
