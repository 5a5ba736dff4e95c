"""The compiled pivot loop of Lemke's method (lcp/_lemke_kernel.py, lcp/_lemke_c.c) against the
numpy loop it replaces: the same pivots (row, slot) in the same order, the same outcome and the
same numbers, on the degenerate problems of test_lemke.py, rays, pivot limits and cycling."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp import _lemke_kernel as kernel
from rigidlcp.lcp.solvers.lemke import _Lemke

from .test_lemke import degenerate_integer_lcps, friction_lcp, murty_matrix, murty_q

pytestmark = pytest.mark.skipif(not kernel.COMPILED, reason="the C extension is not built")


def run_both(M, q, d=None, tol=1e-10, max_iter=10_000):
    M, q = np.asarray(M, float), np.asarray(q, float)
    d = np.ones(q.size) if d is None else np.asarray(d, float)
    out = []
    for compiled in (True, False):
        previous = kernel.use_compiled(compiled)
        try:
            run = _Lemke(M, q, d, tol)
            run.trace = []
            sol = run.run(max_iter)
        finally:
            kernel.use_compiled(previous)
        out.append((run.trace, sol))
    return out


def assert_same(M, q, **kw):
    (trace_c, sol_c), (trace_p, sol_p) = run_both(M, q, **kw)
    assert trace_c == trace_p
    assert sol_c.status == sol_p.status and sol_c.iterations == sol_p.iterations
    assert sol_c.message == sol_p.message
    np.testing.assert_array_equal(sol_c.z, sol_p.z)
    np.testing.assert_array_equal(sol_c.w, sol_p.w)
    np.testing.assert_array_equal(sol_c.basis, sol_p.basis)
    return sol_c


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(degenerate_integer_lcps())
def test_same_pivots_on_degenerate_problems(problem):
    M, q = problem
    if np.all(q >= 0):
        q = q.copy()
        q[0] = -1
    assert_same(M, q)


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 12), st.integers(0, 2**32 - 1), st.booleans())
def test_same_pivots_on_friction_lcps(c, seed, symmetric):
    """Equal q_n and q_t = 0 tie dozens of rows: the lexicographic rule runs on most pivots."""
    rng = np.random.default_rng(seed)
    H = rng.standard_normal((2 * c, max(1, 3 * c // 2)))
    qn = -np.ones(c) if symmetric else rng.standard_normal(c)
    qt = np.zeros(c) if symmetric else rng.standard_normal(c)
    M, q = friction_lcp(H @ H.T, rng.uniform(0.1, 0.6, c), qn, qt)
    assert_same(M, q)


@pytest.mark.parametrize("n", [1, 2, 10, 57, 130])
def test_same_pivots_and_numbers_on_random_lcps(n):
    rng = np.random.default_rng(n)
    A = rng.standard_normal((n, n))
    sol = assert_same(A @ A.T + 0.1 * np.eye(n), rng.standard_normal(n),
                      d=rng.uniform(0.5, 2, n))
    assert sol.status == "solved"


def test_same_ray_and_infeasibility_certificate():
    M = np.array([[1.0, -1.0], [-1.0, 1.0]])  # PSD; q makes the LCP infeasible
    sol = assert_same(M, np.array([-1.0, -1.0]))
    assert sol.status == "infeasible"


def test_same_pivot_limit():
    sol = assert_same(murty_matrix(8), murty_q(8), max_iter=50)
    assert sol.status == "max_iter" and sol.iterations == 50


def test_update_rounds_product_and_sum_separately():
    """Both loops round each entry of the rank-one update twice (product, then sum; no fused
    multiply-add), on any CPU: one pivot of a 67 x 67 problem (OpenBLAS's Haswell dger fuses
    blocks of 16 rows and rounds the other 3 twice, so a BLAS-shaped rule differs somewhere)
    gives T + outer(col, row) as numpy rounds it, and that differs from the fused result."""
    from fractions import Fraction

    rng = np.random.default_rng(1)
    n = 67
    M, q, d = rng.standard_normal((n, n)), -rng.uniform(0.5, 1.5, n), rng.uniform(0.5, 2, n)
    r = int(np.argmin(q / d))  # z0 enters (slot n); the row of min q_i / d_i leaves
    for compiled in (True, False):
        previous = kernel.use_compiled(compiled)
        try:
            L = _Lemke(M, q, d, 1e-10)
            T0 = L.T.copy()
            sol = L.run(1)
        finally:
            kernel.use_compiled(previous)
        assert sol.status == "max_iter" and sol.iterations == 1
        col = T0[:, n].copy()
        row = T0[r, :] * (-1.0 / col[r])
        row[n] = 1.0 / col[r]
        T = T0.copy()
        T[r, :] = 0.0
        T[:, n] = 0.0
        col[r] = 1.0
        fused = np.array([[float(Fraction(T[i, c]) + Fraction(col[i]) * Fraction(row[c]))
                           for c in range(n + 2)] for i in range(n)])
        T += np.multiply.outer(col, row)
        np.testing.assert_array_equal(L.T, T)
        assert (T != fused).any()  # the rule is not vacuous here


def test_real_event_cycles_in_both_loops():
    """The event of test_lemke.py whose basis repeats at a fine tolerance (rounding defeats the
    lexicographic rule; at tol = 1e-12 with the update rounded twice): the compiled loop finds
    the same repeat after the same pivots."""
    P = lcp.load(Path(__file__).parent.parent / "data" / "event_rect20x10_cycling.npz")
    sol = assert_same(P.M, P.q, tol=1e-12)
    assert sol.info.get("cycling")


def test_switch():
    previous = kernel.use_compiled(True)
    assert kernel.enabled()
    kernel.use_compiled(False)
    assert not kernel.enabled()
    kernel.use_compiled(previous)
    assert kernel.enabled() == previous


def test_plain_finite_refuses_what_needs_validation():
    previous = kernel.use_compiled(True)
    try:
        check_plain_finite()
    finally:
        kernel.use_compiled(previous)


def check_plain_finite():
    M, q = np.eye(2), np.array([-1.0, 1.0])
    assert kernel.plain_finite(M, q) == (True, -1.0)
    assert not kernel.plain_finite(M.tolist(), q)[0]
    assert not kernel.plain_finite(np.asfortranarray([[1.0, 2.0], [3.0, 4.0]]), q)[0]
    assert not kernel.plain_finite(np.array([[1.0, np.nan], [0.0, 1.0]]), q)[0]
    assert not kernel.plain_finite(M, np.array([-1.0, np.inf]))[0]
    with pytest.raises(lcp.InvalidProblem, match="NaN or Inf"):
        lcp.lemke.lemke(np.array([[1.0, np.nan], [0.0, 1.0]]), q)
