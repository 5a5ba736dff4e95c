"""The norm bound of verify.certificates.bounds: no solution with |z|_1 >= S (a MILP)."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings

from rigidlcp import lcp
from rigidlcp.verify.certificates.bounds import no_solution_beyond
from rigidlcp.verify.strategies import degenerate_lcps


def test_two_point_solution_set():
    # w = 1 - z: solutions z = 0 and z = 1
    M, q = np.array([[-1.0]]), np.array([1.0])
    assert no_solution_beyond(M, q, 2.0).proved is True
    found = no_solution_beyond(M, q, 0.5)
    assert found.proved is False and "verified" in found.message


def test_a_ray_is_not_bounded():
    # M = [[1, -1], [-1, 1]], q = 0: the ray z1 = z2 >= 0
    out = no_solution_beyond(np.array([[1.0, -1.0], [-1.0, 1.0]]), np.zeros(2), 1e6)
    assert out.proved is not True


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(degenerate_lcps())
def test_no_bound_is_proved_below_an_enumerated_solution(problem):
    sols = lcp.enumerate_solutions(problem)
    # the largest enumerated solution is never excluded by a bound below it
    big = max(float(np.sum(s.z)) for s in sols)
    if big > 0:
        assert no_solution_beyond(problem.M, problem.q, 0.99 * big).proved is not True
