"""Particular solutions on faces of the solution set (lcp.face), on analytic cases."""

import numpy as np
import pytest

from rigidlcp import lcp
from rigidlcp.lcp.faces.face import face_minimum_norm, global_minimum_norm

# w = M z + q with M = [[1, 1], [1, 1]], q = (-1, -1): every z >= 0 with z1 + z2 = 1 solves it.
SEGMENT = lcp.LCP(np.array([[1.0, 1.0], [1.0, 1.0]]), np.array([-1.0, -1.0]))


@pytest.mark.parametrize("start", [np.array([1.0, 0.0]), np.array([0.0, 1.0]),
                                   np.array([0.3, 0.7])])
def test_minimum_norm_point_of_a_segment_does_not_depend_on_the_start(start):
    res = face_minimum_norm(SEGMENT, start)
    assert res.status == "selected" and res.nullity == 1
    assert np.allclose(res.z, [0.5, 0.5], atol=1e-12)


def test_linear_stage_then_norm():
    res = face_minimum_norm(SEGMENT, np.array([0.3, 0.7]), c=np.array([1.0, 0.0]))
    assert np.allclose(res.z, [0.0, 1.0], atol=1e-12)  # min z1 on the segment


def test_unique_solution_is_left_alone():
    P = lcp.LCP(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-1.0, -1.0]))
    z = lcp.solve(P, "lemke").z
    res = face_minimum_norm(P, z)
    assert res.status == "unique" and np.array_equal(res.z, z)


def test_global_minimum_over_two_separate_solutions():
    # Pairs 1-2: w1 = z2 - 1, w2 = z1 - 1, whose only solution is z1 = z2 = 1. Pair 3:
    # w3 = 1 - z3, solved by z3 = 0 (w3 = 1) and by z3 = 1 (w3 = 0): two isolated solutions.
    M = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    q = np.array([-1.0, -1.0, 1.0])  # third pair: w3 = 1 - z3: z3 = 0 (w3 = 1) or z3 = 1
    P = lcp.LCP(M, q)
    far = np.array([1.0, 1.0, 1.0])
    assert lcp.complementarity_residual(far, M @ far + q) == 0
    c = np.array([0.0, 0.0, 1.0])
    res = global_minimum_norm(P, np.eye(3), c, z_upper=np.full(3, 10.0), w_upper=np.full(3, 10.0))
    assert res.status.startswith("selected")
    assert np.allclose(res.z, [1.0, 1.0, 0.0], atol=1e-9)  # z3 = 0 is the other, lower solution
    # the local walk from (1, 1, 1) cannot leave its isolated point
    assert np.allclose(face_minimum_norm(P, far, c=c).z, far)
