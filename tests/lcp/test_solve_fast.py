"""The one-crossing route of `lcp.solve`'s common call (lcp/_lemke_c.c: solve_fast, used by
lcp/solvers/fast_lemke.py): the solve, its acceptance, numpy's M z and the measure in one C
call give what the separate calls give (solve_accept, then M.dot(z) and lcp_measure), bit for
bit, on random, badly scaled, degenerate, infeasible and ill-conditioned problems, across the
sizes where the C code changes its buffers; and the verdict on its numbers rejects an answer
that fails any part of the acceptance (the general path then answers), in the Python and in C
(solve_lcp, which also builds the Solution)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings

from rigidlcp import lcp
from rigidlcp.lcp import _lemke_kernel as kernel
from rigidlcp.lcp.acceptance import residual
from rigidlcp.lcp.solvers import fast_lemke

from .test_fast_lemke import assert_same_answer, outcome, random_lcps, same
from .test_lemke import degenerate_integer_lcps

compiled = pytest.mark.skipif(fast_lemke._solve_fast is None,
                              reason="the C extensions are not built or are off")


def two_calls(M, q, upto):
    """What solve_lemke did before solve_fast: solve_accept, numpy's M z, the C measure."""
    n = q.size
    z, basis = np.empty(n), np.empty(n, dtype=np.intp)
    code, pivots, m, acode, berr, ferr, refined = fast_lemke._solve_accept(
        M, q, fast_lemke.DEFAULT_TOL, 1000 + 100 * n, z, basis)
    w, raw, scaled = None, np.nan, np.nan
    if code == 0 and acode == 0:
        w = M.dot(z)
        got = fast_lemke._measure(M, q, z, w) if n <= upto else None
        if got is not None:
            raw, scaled = got[0], got[1]
        else:
            w = M.dot(z)
    return (code, pivots, m, acode, berr, ferr, refined, raw, scaled), z, w, basis[:m]


def one_call(M, q, upto):
    n = q.size
    z, w, basis = np.empty(n), np.empty(n), np.empty(n, dtype=np.intp)
    out = fast_lemke._solve_fast(M, q, fast_lemke.DEFAULT_TOL, 1000 + 100 * n, z, w, basis,
                                 np.dot, upto)
    return out, z, w, basis[:out[2]]


def assert_one_call_is_two(M, q):
    upto = kernel.sums_verified_upto()
    for limit in (upto, 0):  # measured in C, and left to numpy (raw, scaled NaN)
        a, za, wa, ba = two_calls(M, q, limit)
        b, zb, wb, bb = one_call(M, q, limit)
        assert all(same(x, y) for x, y in zip(a, b)), (a, b)
        if a[0] != 0:  # not solved (or not balanced): z, w mean nothing
            continue
        assert same(za, zb) and same(ba, bb)
        if a[3] == 0:
            # w: numpy's M z (np.dot into w, the BLAS call of M.dot), + q when measured in C
            assert same(wb, wa if limit else M.dot(zb))


@compiled
@settings(max_examples=200, deadline=None)
@given(random_lcps(max_n=40, kinds=("general", "psd", "p-dominant", "scaled", "extreme",
                                    "q>=0")))
def test_one_call_gives_the_separate_calls_numbers(problem):
    assert_one_call_is_two(*problem)


@compiled
@settings(max_examples=60, deadline=None)
@given(random_lcps(max_n=40, kinds=("psd", "p-dominant", "scaled", "extreme", "general")))
def test_the_whole_call_is_the_general_paths_up_to_n_40(problem):
    """lcp.solve(P) through the one call against the general path (lcp.trust, whose lemke()
    builds its dictionary with `setup` and pivots with `run`: another fill than solve_fast's),
    every field bit for bit, at sizes where the four-lane passes and the blocked fill run."""
    assert_same_answer(lcp.LCP(*problem))


@compiled
@settings(max_examples=200, deadline=None)
@given(degenerate_integer_lcps(max_n=6))
def test_one_call_on_degenerate_problems(problem):
    M, q = problem
    assert_one_call_is_two(M.astype(float), q.astype(float))


@compiled
@pytest.mark.parametrize("n", [1, 4, 15, 16, 17, 28, 29, 63, 64, 65, 100, 131])
def test_one_call_across_buffer_sizes(n):
    """Around the stack / heap boundary of the work array (n = 28 / 29), the column padding
    (n = 16) and the z buffer (n = 64); nonsymmetric, ill-conditioned and PSD data."""
    rng = np.random.default_rng(n)
    A = rng.standard_normal((n, n))
    U, _, V = np.linalg.svd(rng.standard_normal((n, n)))
    for M in (A @ A.T + 0.1 * np.eye(n), A + np.diag(np.abs(A).sum(axis=1)),
              U @ np.diag(np.logspace(0, -12, n)) @ U.T, U @ np.diag(np.logspace(0, 9, n)) @ V):
        assert_one_call_is_two(M, rng.standard_normal(n))


@compiled
def test_infeasible_and_unbalanced_problems_are_handed_back():
    """A ray (infeasible) is not solved: code 1-3 and nothing measured; an unbalanced M comes
    back as NEEDS_RUIZ before any pivot; the whole call then answers as the general path."""
    ray = lcp.LCP(np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, -1.0]))
    out, _, _, _ = one_call(ray.M, ray.q, 100)
    assert out[0] != kernel.SOLVED and np.isnan(out[7])
    D = np.diag([1e-6, 1.0, 1e6])
    S = lcp.LCP(D @ (np.eye(3) + 0.3) @ D, -np.ones(3))
    out, _, _, _ = one_call(S.M, S.q, 100)
    assert out[0] == kernel.NEEDS_RUIZ and out[1] == 0
    for P in (ray, S):
        assert_same_answer(P)


@compiled
@pytest.mark.parametrize("M, q", [
    (np.ones(9), -np.ones(3)),                 # M a vector of n * n entries
    (np.ones((1, 9)), -np.ones(3)),            # n * n entries, not n x n
    (np.ones((3, 3)), -np.ones((3, 1))),       # q a column
    (np.ones((3, 3)), np.float64(-1.0)),       # q a number
    (np.ones((3, 3), dtype=">f8"), -np.ones(3)),  # not native
])
def test_one_call_refuses_other_shapes_and_types(M, q):
    """The C call checks the shapes and dtypes the Python checks did; solve_lemke declines and
    the general path answers or raises as before."""
    with pytest.raises((ValueError, TypeError, BufferError)):
        one_call(M, q, 100)
    P = lcp.LCP(np.eye(3), -np.ones(3))
    object.__setattr__(P, "M", M)
    object.__setattr__(P, "q", q)
    assert fast_lemke.solve_lemke(P) is None


@compiled
@pytest.mark.parametrize("slot, value", [(4, 1e-7), (5, 1.0), (8, 1e-7), (8, np.nan),
                                         (4, np.inf), (5, np.nan), (7, np.nan)])
def test_a_failed_measure_is_never_solved(monkeypatch, slot, value):
    """Whatever number of the acceptance fails -- backward error (slot 4), forward bound (5),
    scaled residual (8) -- or is not a number, solve_lemke declines (None) and the general
    path judges the answer itself. (raw NaN, slot 7, means "not measured in C": numpy
    measures, and the answer is the general path's.) The Python's verdict, on the numbers
    solve_lcp hands back (its own verdict switched off: no tolerance passes; the C verdict is
    test_the_c_verdict_is_the_pythons)."""
    rng = np.random.default_rng(7)
    A = rng.standard_normal((6, 6))
    P = lcp.LCP(A @ A.T + np.eye(6), rng.standard_normal(6))
    assert fast_lemke.solve_lemke(P) is not None
    real = fast_lemke._solve_lcp

    def tampered(*args):
        out = list(real(*args))
        out[slot] = value
        return tuple(out)

    monkeypatch.setattr(fast_lemke, "_solve_lcp", tampered)
    try:
        fast_lemke._setup(-1.0, -1.0)  # solve_lcp hands its numbers back, never a Solution
        if slot == 7:
            sol = fast_lemke.solve_lemke(P)
            assert sol is not None
            assert_same_answer(P)
        else:
            assert fast_lemke.solve_lemke(P) is None
    finally:
        fast_lemke._setup()
    sol = lcp.solve(P)
    assert sol.status == "solved" and residual.check(P, sol.z).accepted


@compiled
@pytest.mark.parametrize("seed", range(4))
def test_the_c_verdict_is_the_pythons(seed):
    """solve_lcp builds the Solution exactly when the Python's verdict on its numbers is
    "accepted" (scaled <= TOL, berr <= TOL, ferr <= FERR_TOL): with each tolerance set at the
    number it judges (accepted: <=) and one ulp below it (declined: the numbers handed back),
    and the Solution then field for field the general path's."""
    rng = np.random.default_rng(seed)
    n = 4 + 7 * seed
    A = rng.standard_normal((n, n))
    P = lcp.LCP(A @ A.T + 0.1 * np.eye(n), rng.standard_normal(n))
    args = (P.M, P.q, fast_lemke.DEFAULT_TOL, 1000 + 100 * n, kernel.sums_verified_upto())
    try:
        fast_lemke._setup(-1.0, -1.0)
        code, _, _, acode, berr, ferr, _, raw, scaled, *_ = fast_lemke._solve_lcp(*args)
        assert code == kernel.SOLVED and acode == 0 and raw == raw
        tol, ftol = max(berr, scaled), ferr
        for t, f, accepted in ((tol, ftol, True), (np.nextafter(tol, -1), ftol, False),
                               (tol, np.nextafter(ftol, -1), False), (np.nan, ftol, False),
                               (tol, np.nan, False)):
            fast_lemke._setup(t, f)
            out = fast_lemke._solve_lcp(*args)
            assert (type(out) is not tuple) == accepted, (t, f)
            if accepted:
                assert out.backward_error == berr and out.forward_error == ferr
                assert out.scaled_residual == scaled and out.residual == raw
    finally:
        fast_lemke._setup()
    assert_same_answer(P)


@compiled
def test_the_c_solution_fills_every_slot_or_sets_the_fields_by_name():
    """solve_lcp writes the Solution's 14 slots directly (their offsets read from the class's
    member descriptors by solve_setup); given a class whose fields are not plain slots (here a
    dataclass with a __dict__), it sets them by name instead. Both objects equal the general
    path's answer field for field."""
    from rigidlcp.lcp.problems.solution import Solution

    rng = np.random.default_rng(5)
    A = rng.standard_normal((7, 7))
    P = lcp.LCP(A @ A.T + 0.1 * np.eye(7), rng.standard_normal(7))
    assert not hasattr(Solution(np.zeros(1), np.zeros(1), "failed", "x"), "__dict__")
    args = (P.M, P.q, fast_lemke.DEFAULT_TOL, 1700, kernel.sums_verified_upto())
    slotted = fast_lemke._solve_lcp(*args)
    assert type(slotted) is Solution

    @dataclasses.dataclass
    class Plain:  # the same fields, in a __dict__
        z: object
        w: object
        status: object
        method: object
        iterations: object
        residual: object
        eq_residual: object
        scaled_residual: object
        basis: object
        u: object
        message: object
        info: object
        backward_error: object
        forward_error: object

    try:
        kernel._lemke_c.solve_setup(np.dot, np.empty, np.intp, object.__new__, Plain,
                                    fast_lemke._Q_NONNEGATIVE, residual.TOL, fast_lemke.FERR_TOL)
        by_name = fast_lemke._solve_lcp(*args)
    finally:
        fast_lemke._setup()
    assert type(by_name) is Plain and list(vars(by_name)) == [
        f.name for f in dataclasses.fields(Solution)]
    one = assert_same_answer(P)
    for f in dataclasses.fields(Solution):
        assert same(getattr(slotted, f.name), getattr(one, f.name)), f.name
        assert same(getattr(by_name, f.name), getattr(one, f.name)), f.name


@compiled
@pytest.mark.parametrize("mscale, qscale", [(1.0, 1.0), (1e300, 1e-300), (1e-300, 1e300),
                                            (1e-200, 1e-150), (1e250, 1e100), (1e-310, 1.0),
                                            (1.0, 0.0)])
@pytest.mark.parametrize("n", [3, 8, 13, 30])
def test_dictionary_of_a_balanced_m_is_filled_as_with_explicit_factors(n, mscale, qscale):
    """solve_eq with r = c = None (the balanced case, equilibrated in C: its dictionary filled
    in one pass, four rows and columns at a time, mu known beforehand) gives what it gives with
    the same units passed as factors (r = 1/s, c = s: the general fill, then the division by
    mu), bit for bit: code, pivots, z, basis, bounds, with d = ones or given -- also where the
    scaled entries overflow (NOT_FINITE), underflow to subnormals or q = 0."""
    rng = np.random.default_rng(n)
    A = rng.standard_normal((n, n))
    M, q = (A @ A.T + np.eye(n)) * mscale, rng.standard_normal(n) * qscale
    qmax = np.max(np.abs(q))
    s = 2.0 ** np.round(np.log2(qmax)) if qmax > 0 else 1.0
    for d in (None, rng.uniform(0.5, 3.0, n)):  # Lemke's covering vector: ones, or given
        outs = []
        for r, c in ((None, None), (np.full(n, 1.0 / s), np.full(n, s))):
            z, basis = np.zeros(n), np.zeros(n, dtype=np.int64)
            code, pivots, m, bounds = kernel._lemke_c.solve_eq(M, q, r, c, d, 1e-12,
                                                               1000 + 100 * n, z, basis)
            outs.append((code, pivots, m, bounds, z, basis[:m]))
        if outs[0][0] == kernel.NEEDS_RUIZ:  # s not decided in C (near a midpoint)
            continue
        assert all(same(np.asarray(x), np.asarray(y)) for x, y in zip(*outs)), outs


@compiled
@settings(max_examples=40, deadline=None)
@given(random_lcps(max_n=40))
def test_m_z_by_numpys_own_gemv_is_numpys_dot(problem):
    """M z by the cblas_dgemv numpy's dot calls, found in numpy's BLAS library and called from
    C (lcp/_blas.h; lcp/_lemke_kernel.py: numpy_gemv), is np.dot's M z bit for bit; and the
    fast path's Solution is the same with and without it (np.dot called from C instead)."""
    if not kernel.numpy_gemv():
        pytest.skip("numpy's BLAS is not one numpy_gemv recognizes: np.dot is called from C")
    M, q = problem
    n = q.size
    for z in (q, np.abs(q) * 1e150, q * 1e-170):
        w = np.empty(n)
        if n >= 2:
            assert kernel._lemke_c.gemv(M, z, w)
            with np.errstate(all="ignore"):  # extreme data overflow: compared all the same
                assert same(w, np.dot(M, z)) and same(w, M.dot(z))
        else:  # numpy multiplies a 1 x 1 by a scalar product: not taken by gemv
            assert not kernel._lemke_c.gemv(M, z, w)
    P = lcp.LCP(M, q)
    with_gemv = outcome(fast_lemke.solve_lemke, P)
    kernel._lemke_c.gemv_setup(0, False)
    try:
        without = outcome(fast_lemke.solve_lemke, P)
    finally:
        kernel._lemke_c.gemv_setup(*kernel._gemv_address())
    assert type(with_gemv) is type(without)
    if isinstance(without, lcp.Solution):
        for f in dataclasses.fields(without):
            assert same(getattr(with_gemv, f.name), getattr(without, f.name)), f.name


@compiled
def test_no_gemv_is_used_when_numpys_blas_is_not_recognized(monkeypatch):
    """numpy_gemv sets no function when it finds none (another BLAS): gemv then declines and
    the fast path calls np.dot from C, with the general path's answer."""
    monkeypatch.setattr(kernel, "_gemv_found", None)
    monkeypatch.setattr(kernel, "_gemv_address", lambda: None)
    try:
        assert kernel.numpy_gemv() is False
        assert not kernel._lemke_c.gemv(np.eye(3), np.ones(3), np.empty(3))
        rng = np.random.default_rng(3)
        A = rng.standard_normal((9, 9))
        assert_same_answer(lcp.LCP(A @ A.T + np.eye(9), rng.standard_normal(9)))
    finally:
        monkeypatch.undo()
        kernel._gemv_found = None
        assert kernel.numpy_gemv() == (kernel._gemv_address() is not None)
