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
from rigidlcp.lcp.lemke import _Lemke

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


def test_update_rounds_like_the_blas_of_the_numpy_loop():
    """The C update uses a fused multiply-add exactly when scipy's dger does (probed)."""
    from rigidlcp.lcp import _lemke_c

    assert _lemke_c.set_fma(None) == kernel.blas_uses_fma()
    A = np.asfortranarray(np.random.default_rng(1).standard_normal((9, 9)))
    M, q = A @ A.T, -np.ones(9)
    assert_same(M, q)


def test_real_event_cycles_in_both_loops():
    """The event of test_lemke.py whose basis repeats at tol = 1e-10 after 766 pivots: the
    compiled loop finds the same repeat (its rounding matches the BLAS of the numpy loop)."""
    P = lcp.load(Path(__file__).parent.parent / "data" / "event_rect20x10_cycling.npz")
    sol = assert_same(P.M, P.q)
    assert sol.info.get("cycling") and sol.iterations == 766


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
