"""The fast path of `lcp.solve(problem, "pivoting")` (lcp/solvers/fast_pivoting.py,
lcp/solvers/_pivot_c.c) gives exactly what the general path gives -- the same Solution, field
for field and bit for bit -- on random, PSD, P-matrix, badly scaled and degenerate integer
problems, and declines (None: the general path runs from the start) on everything else: a
singular start, a single or exchange pivot, bad data, options, Fortran order, no compiled kernel."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp import _lemke_kernel as kernel
from rigidlcp.lcp import api
from rigidlcp.lcp.problems.solution import Solution
from rigidlcp.lcp.solvers import fast_pivoting

from .test_fast_lemke import fields, outcome, random_lcps, same
from .test_lemke import degenerate_integer_lcps

compiled = pytest.mark.skipif(not fast_pivoting.applies(),
                              reason="the C extension is not built, is off, or scipy's BLAS "
                              "does not round as numpy's")



def general(problem, **kw):
    """lcp.solve(problem, "pivoting") without the fast path (lcp.trust.solve_checked)."""
    saved = api._FAST_PIVOTING
    api._FAST_PIVOTING = lambda p: None
    try:
        return lcp.solve(problem, "pivoting", **kw)
    finally:
        api._FAST_PIVOTING = saved


def assert_same_answer(problem, plain: bool = True) -> Solution | None:
    """Both paths answer alike; the fast path's own answer, when it gives one, is the general
    path's, and on plain data (C-contiguous finite float64) it declines only where the general
    path needed more than block steps."""
    fast, slow = outcome(lambda p: lcp.solve(p, "pivoting"), problem), outcome(general, problem)
    if isinstance(slow, Exception):
        assert type(fast) is type(slow) and str(fast) == str(slow)
        return None
    assert type(fast) is type(slow)
    for key in fields(slow):
        assert same(getattr(fast, key), getattr(slow, key)), key
    own = fast_pivoting.solve_pivoting(problem)
    if own is not None:
        for key in fields(slow):
            assert same(getattr(own, key), getattr(slow, key)), key
    elif plain and slow.status == "solved" and set(slow.info) == {
            "block_steps", "single_pivots", "exchange_pivots", "flips", "equilibrated"}:
        # declined although only block steps were made: only when the general path needed
        # a single pivot (counted in info) or its check failed and it repaired the answer
        assert slow.info["single_pivots"] + slow.info["exchange_pivots"] > 0
    return own


def problems(max_n: int = 30):
    """Random, PSD, P-matrix (non-symmetric, diagonally dominant or triangular), badly scaled
    (rows, columns and q over many decades) and extreme problems."""
    return random_lcps(max_n, kinds=("general", "psd", "p-dominant", "p-triangular", "scaled",
                                     "extreme", "q>=0"))


@compiled
@settings(max_examples=300, deadline=None)
@given(problems())
def test_fast_path_gives_the_general_answer(problem):
    assert_same_answer(lcp.LCP(*problem))


@compiled
@settings(max_examples=300, deadline=None)
@given(degenerate_integer_lcps(max_n=6))
def test_fast_path_gives_the_general_answer_on_degenerate_problems(problem):
    """Ties, singular bases, infeasible problems, q >= 0: as the general path answers."""
    assert_same_answer(lcp.LCP(*problem))


@compiled
def test_fast_path_is_taken_on_most_plain_problems():
    """Not a vacuous equality: the C path answers most P-matrix and PSD problems of the sizes
    the benchmarks use (the same answer as the general path, checked above)."""
    rng = np.random.default_rng(5)
    taken = 0
    for k in range(40):
        n = (1, 2, 10, 50, 100)[k % 5]
        A = rng.standard_normal((n, n))
        M = A @ A.T + 0.1 * np.eye(n) if k % 2 else A + np.diag(np.abs(A).sum(axis=1))
        P = lcp.LCP(M, rng.standard_normal(n))
        taken += assert_same_answer(P) is not None
    assert taken >= 30


@compiled
def test_declines_what_needs_the_python_method():
    singular_start = lcp.LCP(np.ones((2, 2)), -np.ones(2))  # M_aa singular at alpha = {q < 0}
    assert fast_pivoting.solve_pivoting(singular_start) is None
    assert "warm_start_rejected" in general(singular_start).info
    assert_same_answer(singular_start)
    infeasible = lcp.LCP(np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, -1.0]))
    assert fast_pivoting.solve_pivoting(infeasible) is None
    assert lcp.solve(infeasible, "pivoting").status == "infeasible"
    rng = np.random.default_rng(11)
    single = 0
    for _ in range(300):  # problems where block steps cycle and single pivots take over
        n = int(rng.integers(2, 9))
        P = lcp.LCP(rng.standard_normal((n, n)), rng.standard_normal(n))
        slow = general(P)
        if slow.info.get("single_pivots", 0) + slow.info.get("exchange_pivots", 0):
            single += 1
            assert fast_pivoting.solve_pivoting(P) is None
            assert_same_answer(P)
    assert single > 0


@compiled
def test_options_fortran_order_and_no_kernel_take_the_general_path(monkeypatch):
    rng = np.random.default_rng(4)
    A = rng.standard_normal((6, 6))
    P = lcp.LCP(A @ A.T + np.eye(6), rng.standard_normal(6))
    calls = []
    real = fast_pivoting.solve_pivoting
    monkeypatch.setattr(api, "_FAST_PIVOTING", lambda p: calls.append(p) or real(p))
    lcp.solve(P, "pivoting")
    lcp.solve(P, "pivoting", equilibrate=True)
    assert len(calls) == 2
    for kw in ({"max_iter": 50}, {"equilibrate": False}, {"tol": 1e-9}, {"block_tries": 1},
               {"active": [0, 1]}):
        assert lcp.solve(P, "pivoting", **kw).status == "solved"
    assert len(calls) == 2
    fortran = lcp.LCP(np.asfortranarray(P.M), P.q)
    assert fast_pivoting.solve_pivoting(fortran) is None
    assert_same_answer(fortran, plain=False)
    previous = kernel.use_compiled(False)  # as RIGIDLCP_NO_KERNEL=1
    try:
        assert fast_pivoting.solve_pivoting(P) is None
        assert same(lcp.solve(P, "pivoting").z, general(P).z)
    finally:
        kernel.use_compiled(previous)


@compiled
def test_a_method_registered_as_pivoting_replaces_the_fast_path():
    info = api._REGISTRY["pivoting"]

    @api.register("pivoting", accepts="any", description="test double", equilibrate=True,
                  replace=True)
    def double(M, q):
        return Solution(z=np.zeros(q.size), w=q.copy(), status="solved", method="pivoting")

    try:
        assert fast_pivoting.solve_pivoting(lcp.LCP(np.eye(2), np.ones(2))) is None
    finally:
        api._REGISTRY["pivoting"] = info


@compiled
@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # the general path's ruiz on inf
@pytest.mark.parametrize("where", ["M", "q"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_bad_numbers_after_construction_raise_as_the_general_path(where, bad):
    P = lcp.LCP(np.eye(3) + 0.5, -np.ones(3))
    getattr(P, where)[(1, 2) if where == "M" else 1] = bad
    assert fast_pivoting.solve_pivoting(P) is None
    fast, slow = outcome(lambda p: lcp.solve(p, "pivoting"), P), outcome(general, P)
    assert type(fast) is type(slow) and str(fast) == str(slow)


@compiled
@pytest.mark.parametrize("M, q", [
    (np.ones(9), -np.ones(3)),                      # M a vector
    (np.ones((3, 4)), -np.ones(3)),                 # not square
    (np.ones((3, 3)), -np.ones(4)),                 # q of another size
    (np.ones((3, 3), dtype=np.float32), -np.ones(3)),
    (np.ones((3, 3)).tolist(), -np.ones(3)),        # not an array
    (np.ones((0, 0)), np.ones(0)),                  # empty
])
def test_wrong_shapes_or_types_forced_in_take_the_general_path(M, q):
    P = lcp.LCP(np.eye(3), -np.ones(3))
    object.__setattr__(P, "M", M)
    object.__setattr__(P, "q", q)
    assert fast_pivoting.solve_pivoting(P) is None
    fast, slow = outcome(lambda p: lcp.solve(p, "pivoting"), P), outcome(general, P)
    assert type(fast) is type(slow)
    if isinstance(slow, Exception):
        assert str(fast) == str(slow)


@compiled
def test_numbers_that_could_overflow_the_check_take_the_general_path():
    P = lcp.LCP(np.full((3, 3), 1e307) + np.eye(3) * 1e307, -np.ones(3) * 1e307)
    assert fast_pivoting.solve_pivoting(P) is None
    assert_same_answer(P, plain=False)


@compiled
@pytest.mark.parametrize("n", [1, 2, 3, 7, 8, 9, 16, 33, 64, 65, 130, 257])
def test_c_matrix_vector_product_is_numpys(n):
    """The C code's product (scipy's dgemv 'T' on the rows, 0 + ddot at n = 1) is numpy's
    A @ x, bit for bit, on data over many decades (the probe of fast_pivoting, on other
    numbers)."""
    rng = np.random.default_rng(n)
    A = rng.standard_normal((n, n)) * np.exp2(rng.integers(-40, 40, (n, n)))
    x = rng.standard_normal(n) * np.exp2(rng.integers(-40, 40, n))
    y = np.empty(n)
    fast_pivoting._pivot_c.matvec(A, x, y)
    assert y.tobytes() == (A @ x).tobytes()


@compiled
@pytest.mark.parametrize("n", [1, 2, 5, 8, 9, 17, 130])
def test_c_column_sums_are_numpys(n):
    """The 1-norm of M_aa given to the condition estimate: numpy's column sums of |A| (rows
    added in order), bit for bit, on terms over 80 binary orders."""
    rng = np.random.default_rng(100 + n)
    A = rng.standard_normal((n, n)) * np.exp2(rng.integers(-40, 40, (n, n)))
    assert fast_pivoting._pivot_c.col_abs_max(A) == float(np.max(np.sum(np.abs(A), axis=0)))


@compiled
def test_sizes_beyond_the_probe_take_the_general_path():
    n = fast_pivoting.MAX_N + 1
    P = lcp.LCP(np.eye(n) * 2.0 + 0.01, -np.ones(n))
    assert fast_pivoting.solve_pivoting(P) is None
    assert lcp.solve(P, "pivoting").status == "solved"


@st.composite
def conditioned_matrices(draw):
    """m x m matrices U diag(s) V^T with singular values over up to 16 decades, rows and
    columns scaled over up to 12 more, some entries rounded to few bits (ties, exact zeros)."""
    m = draw(st.integers(1, 24))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    U, _ = np.linalg.qr(rng.standard_normal((m, m)))
    V, _ = np.linalg.qr(rng.standard_normal((m, m)))
    s = 10.0 ** -rng.uniform(0, draw(st.floats(0, 16)), m)
    A = (U * s) @ V.T
    scale = draw(st.floats(0, 12))
    A *= 10.0 ** rng.uniform(-scale / 2, scale / 2, m)[:, None]
    A *= 10.0 ** rng.uniform(-scale / 2, scale / 2, m)[None, :]
    if draw(st.booleans()):
        A = np.round(A * 4) / 4
    return np.ascontiguousarray(A)


@compiled
@settings(max_examples=400, deadline=None)
@given(conditioned_matrices())
def test_rcond_shortcut_bounds_dgecons_estimate(A):
    """_pivot_c skips dgecon when anorm * (its bound on the inverse-norm estimate) <=
    0.1 / RCOND. The bound must hold: dgecon's rcond = 1 / (ainvnm anorm) satisfies
    rcond * (anorm * bound) >= 1 (up to the roundings of the two divisions), so wherever the
    shortcut fires dgecon would have found rcond >= 10 RCOND, the same 'nonsingular'."""
    from scipy.linalg.lapack import dgecon

    from rigidlcp.lcp.solvers.pivoting import RCOND

    bound, lu = fast_pivoting._pivot_c.rcond_shortcut(A)
    m = A.shape[0]
    lu = np.array(lu).reshape(m, m, order="F")
    if not np.isfinite(bound):
        return
    anorm = float(np.max(np.sum(np.abs(A), axis=0)))
    rcond, _ = dgecon(lu, anorm, norm="1")
    assert rcond * bound >= 1 - 1e-12
    if bound <= 0.1 / RCOND:
        assert rcond >= RCOND


@compiled
def test_rcond_shortcut_fires_on_well_conditioned_bases():
    """Not vacuous: on well-conditioned matrices the bound is within the limit (dgecon is
    skipped), on a singular-to-rounding one it is not."""
    from rigidlcp.lcp.solvers.pivoting import RCOND

    rng = np.random.default_rng(5)
    for m in (1, 2, 6, 20):
        A = rng.standard_normal((m, m)) + 3 * m * np.eye(m)
        assert fast_pivoting._pivot_c.rcond_shortcut(A)[0] <= 0.1 / RCOND
    u = rng.standard_normal(8)
    A = np.outer(u, u) + 1e-15 * np.eye(8)
    assert not fast_pivoting._pivot_c.rcond_shortcut(A)[0] <= 0.1 / RCOND
