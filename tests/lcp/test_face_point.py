"""lcp.face.face_is_point: a proof that face_minimum_norm has nothing to select. Whenever it says
"point", the selection returns z itself; it says "not point" where the face has a null space."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp.faces.face import face_is_point, face_minimum_norm

from .test_lemke import degenerate_integer_lcps, friction_lcp


@settings(max_examples=150, deadline=None)
@given(degenerate_integer_lcps(max_n=5), st.lists(st.booleans(), min_size=5, max_size=5))
def test_point_means_the_selection_keeps_z(problem, side):
    M, q = problem
    P = lcp.LCP(M, q)
    sol = lcp.solve(P, "lemke")
    if not sol.success:
        return
    z_side = np.array(side[: q.size])
    check = face_is_point(P, sol.z, z_side=z_side)
    face = face_minimum_norm(P, sol.z, c=np.ones(q.size), z_side=z_side)
    if check.point:
        assert face.nullity == 0 and face.status == "unique"
        np.testing.assert_array_equal(face.z, sol.z)
    if face.nullity > 0:  # a face with a null space is never called a point
        assert not check.point


def test_p_matrix_faces_are_points_and_strict_solutions_isolated():
    rng = np.random.default_rng(0)
    for _ in range(20):
        A = rng.standard_normal((8, 8))
        P = lcp.LCP(A @ A.T + 0.5 * np.eye(8), rng.standard_normal(8))
        sol = lcp.solve(P, "lemke")
        check = face_is_point(P, sol.z)
        assert check.point  # every principal submatrix of a P-matrix is nonsingular
        w = P.M @ sol.z + P.q
        strict = bool(np.all((sol.z > 1e-9) | (w > 1e-9)))
        assert check.isolated == strict


def test_hyperstatic_friction_face_is_not_a_point():
    """W = H H^T singular (more contact forces than degrees of freedom) and equal q_n: the
    forces of the solution are not unique and face_is_point must not claim otherwise."""
    c = 6
    rng = np.random.default_rng(3)
    H = rng.standard_normal((2 * c, 5))
    M, q = friction_lcp(H @ H.T, np.full(c, 0.3), -np.ones(c), np.zeros(c))
    P = lcp.LCP(M, q)
    sol = lcp.solve(P, "lemke")
    check = face_is_point(P, sol.z)
    face = face_minimum_norm(P, sol.z, c=np.r_[np.ones(c), np.zeros(2 * c)])
    assert face.nullity > 0 and not check.point and not check.isolated


def test_empty_support_is_a_point():
    P = lcp.LCP(np.eye(2), np.array([1.0, 2.0]))
    check = face_is_point(P, np.zeros(2))
    assert check.point and check.isolated and check.A.size == 0
