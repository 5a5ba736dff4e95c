"""verify.strategies: each construction has its property, checked independently."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.verify.strategies import (
    P_KINDS,
    degenerate_lcps,
    lcps,
    mlcps,
    p_matrices,
    symmetric_psd,
)

SETTINGS = settings(max_examples=60, deadline=None)


def principal_minors(M: np.ndarray):
    n = M.shape[0]
    for k in range(1, n + 1):
        for alpha in itertools.combinations(range(n), k):
            yield alpha, np.linalg.det(M[np.ix_(alpha, alpha)])


@SETTINGS
@given(st.sampled_from(P_KINDS).flatmap(lambda k: p_matrices(st.integers(1, 6), kind=k)))
def test_p_matrices_have_positive_principal_minors(M):
    for alpha, det in principal_minors(M):
        assert det > 0, (alpha, det)


def test_triangular_p_matrices_are_not_all_positive_definite():
    # The "triangular" kind exists to reach P-matrices outside the PD class.
    found = []

    @settings(max_examples=100, deadline=None)
    @given(p_matrices(st.integers(3, 6), kind="triangular"))
    def collect(M):
        found.append(np.linalg.eigvalsh(M + M.T)[0] < 0)

    collect()
    assert any(found)


@SETTINGS
@given(st.integers(1, 8).flatmap(lambda n: st.tuples(st.just(n), symmetric_psd(n))))
def test_symmetric_psd_nonsingular(drawn):
    n, M = drawn
    assert M.shape == (n, n) and np.array_equal(M, M.T)
    assert np.linalg.eigvalsh(M)[0] >= 0.1 - 1e-12


@SETTINGS
@given(st.integers(2, 8).flatmap(lambda n: st.tuples(st.just(n), symmetric_psd(n, True))))
def test_symmetric_psd_singular(drawn):
    n, M = drawn
    lam = np.linalg.eigvalsh(M)
    scale = max(1.0, abs(lam[-1]))
    assert lam[0] >= -1e-12 * scale
    assert np.linalg.matrix_rank(M, tol=1e-10 * scale) < n


@SETTINGS
@given(lcps(planted=True))
def test_planted_lcps_carry_a_solution(problem):
    z = np.array(problem.meta["planted_z"])
    w = problem.M @ z + problem.q
    assert lcp.complementarity_residual(z, w) <= 1e-12
    assert np.allclose(w, problem.meta["planted_w"], atol=1e-12)


@SETTINGS
@given(degenerate_lcps(st.integers(2, 8)))
def test_degenerate_lcps_are_degenerate_and_solved_by_their_planted_z(problem):
    z = np.array(problem.meta["planted_z"])
    assert lcp.complementarity_residual(z, problem.M @ z + problem.q) <= 1e-12
    for i, j in problem.meta["duplicated"]:
        assert np.array_equal(problem.M[i], problem.M[j])
        assert np.array_equal(problem.M[:, i], problem.M[:, j])
        assert problem.q[i] == problem.q[j]


def test_degenerate_lcps_produce_zeros_in_q_and_duplicates():
    seen = {"zero": False, "dup": False}

    @settings(max_examples=60, deadline=None)
    @given(degenerate_lcps(st.integers(3, 8)))
    def collect(problem):
        seen["zero"] |= bool(np.any(problem.q == 0))
        seen["dup"] |= bool(problem.meta["duplicated"])

    collect()
    assert all(seen.values()), seen


@SETTINGS
@given(mlcps())
def test_mlcps_are_schur_reducible_to_p_matrix_lcps(problem):
    reduced = problem.to_lcp()
    M = reduced.M
    assert np.linalg.eigvalsh(0.5 * (M + M.T))[0] > 0  # positive definite, hence P
