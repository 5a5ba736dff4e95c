"""The speed changes of issue 23 change no answer and no refusal.

* The C kernel's work array of `solve_eq` / `solve_batch` (lcp/_lemke_c.c: T's columns
  padded to a multiple of 4 doubles from n = 8, the block 64-byte aligned, on the stack up to
  n = 32 and malloc'd above; its columns updated lazily, when read) gives the z, pivots, basis
  and status of the general path, whose dictionary comes from Python with no padding and is
  updated eagerly (`_lemke_kernel.run`), bit for bit: on sizes
  that are and are not multiples of 4, on both sides of the stack/heap boundary, on random,
  degenerate (ties, duplicated rows and columns, zeros in q) and badly scaled problems.
* `lcp.LCP(M, q)`'s quick route for plain finite float64 data gives the arrays the general
  validation gives (values, dtype, layout, own copies), and every other input -- NaN, Inf,
  wrong shapes, Fortran order, views, integers, lists, complex -- is validated or refused
  exactly as before.
* `solve_batch`'s max|M| of each solved problem, handed to `measure_batch` (solve_many), gives
  the measure that measures max|M| itself, to the bit.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp import _lemke_kernel as kernel
from rigidlcp.lcp.errors import InvalidProblem
from rigidlcp.lcp.problems import problem as problem_module

from .test_fast_lemke import assert_same_answer, same

compiled = pytest.mark.skipif(not kernel.enabled(), reason="the C extension is not built or is off")

#: Around the padding threshold (n = 8; n = 16 before), the stack/heap boundary of the work
#: block (n = 32/33; 28/29 before), not multiples of 4, and larger.
SIZES = (3, 7, 8, 9, 10, 12, 13, 15, 16, 17, 23, 27, 28, 29, 31, 32, 33, 50, 61, 64, 65)


def _problem(n: int, kind: str, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng([seed, n])
    A = rng.standard_normal((n, n))
    q = rng.standard_normal(n)
    if kind == "psd":
        return A @ A.T + 0.1 * np.eye(n), q
    if kind == "general":
        return A, q
    if kind == "scaled":  # rows, columns and q over decades: Ruiz's sweeps run in numpy
        D = np.exp(rng.uniform(-8, 8, n))
        return D[:, None] * (A @ A.T + np.eye(n)) * D[None, :], q * np.exp(rng.uniform(-8, 8))
    if kind == "degenerate":  # small integers, zeros in q, a duplicated row and column
        M = rng.integers(-2, 3, (n, n)).astype(float) + 2 * np.eye(n)
        q = rng.integers(-2, 2, n).astype(float)
        if n >= 2:
            M[1, :], q[1] = M[0, :], q[0]
            M[:, n - 1] = M[:, 0]
        return M, q
    # "ties": every ratio of the first pivot ties (q = -1, M = 1 1^T + I)
    return np.ones((n, n)) + np.eye(n), -np.ones(n)


@compiled
@pytest.mark.parametrize("kind", ["psd", "general", "scaled", "degenerate", "ties"])
@pytest.mark.parametrize("n", SIZES)
def test_padded_work_array_gives_the_general_answer(n, kind):
    for seed in range(3):
        assert_same_answer(lcp.LCP(*_problem(n, kind, seed)))


@compiled
@pytest.mark.parametrize("n", (5, 25, 33))
def test_batch_with_the_padded_work_array_gives_the_loops_answers(n):
    problems = [lcp.LCP(*_problem(n, kind, seed))
                for kind in ("psd", "degenerate", "ties") for seed in range(4)]
    many = lcp.solve_many(problems, "lemke")
    for sol, p in zip(many, problems):
        one = lcp.solve(p, "lemke")
        assert sol.status == one.status
        assert same(sol.z, one.z) and sol.iterations == one.iterations


def _general_route(M, q) -> tuple[np.ndarray, np.ndarray]:
    """The arrays the general validation (as_matrix, as_vector) makes of M and q."""
    Mv = problem_module.as_matrix("M", M, (None, None))
    return Mv, problem_module.as_vector("q", q, Mv.shape[0])


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 9), st.integers(0, 2**32 - 1))
def test_quick_route_makes_the_arrays_of_the_general_validation(n, seed):
    rng = np.random.default_rng(seed)
    M, q = rng.standard_normal((n, n)) * 10.0 ** rng.integers(-300, 300), rng.standard_normal(n)
    p = lcp.LCP(M, q)
    Mg, qg = _general_route(M, q)
    assert same(p.M, Mg) and same(p.q, qg)
    assert p.M.flags.c_contiguous and p.M.flags.owndata and p.q.flags.owndata
    M[0, 0] = q[0] = 12345.0  # the problem keeps its own copies
    assert p.M[0, 0] != 12345.0 and p.q[0] != 12345.0


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("where", ["M", "q"])
def test_non_finite_data_are_refused_with_the_same_message(where, bad):
    M, q = np.eye(3), -np.ones(3)
    (M if where == "M" else q)[(1, 2) if where == "M" else 1] = bad
    with pytest.raises(InvalidProblem) as got:
        lcp.LCP(M, q)
    with pytest.raises(InvalidProblem) as want:
        _general_route(M, q)
    assert str(got.value) == str(want.value)
    assert "NaN or Inf" in str(got.value)


@pytest.mark.parametrize("M, q", [
    (np.eye(3), np.ones(2)),                      # q too short
    (np.ones((2, 3)), np.ones(2)),                # M not square
    (np.ones(4), np.ones(2)),                     # M not 2-D
    (np.zeros((0, 0)), np.zeros(0)),              # empty
    (np.eye(2) * (1 + 1j), np.ones(2)),           # complex
    (np.eye(2), np.array(["a", "b"])),            # not numeric
])
def test_bad_shapes_and_types_are_refused_as_before(M, q):
    with pytest.raises(InvalidProblem):
        lcp.LCP(M, q)


@pytest.mark.parametrize("make", [
    lambda M, q: (np.asfortranarray(M), q),                 # Fortran order
    lambda M, q: (M[:, ::-1][:, ::-1], q[::-1][::-1]),      # views with strides
    lambda M, q: (M.astype(np.float32), q),                 # another float type
    lambda M, q: (np.round(M).astype(int), q.tolist()),     # integers and a list
    lambda M, q: (M, q[:, None]),                           # q as a column
])
def test_other_inputs_take_the_general_validation(make):
    rng = np.random.default_rng(7)
    M0, q0 = rng.standard_normal((4, 4)), rng.standard_normal(4)
    M, q = make(M0, q0)
    p = lcp.LCP(M, q)
    Mg, qg = _general_route(M, q)
    assert same(p.M, Mg) and same(p.q, qg)


@compiled
@pytest.mark.parametrize("kind", ["psd", "general", "scaled", "degenerate", "ties"])
@pytest.mark.parametrize("n", SIZES)
def test_padded_kernel_takes_the_pivots_of_the_unpadded_loop(n, kind):
    """Every outcome (solved, ray, pivot limit, cycling), not only the accepted ones: the code
    and pivot count of `solve_eq` (padded work array) against lemke() on the same equilibrated
    data (its dictionary from Python, unpadded), and z in the user's units when solved."""
    _same_pivots(n, kind, range(3))


@compiled
@pytest.mark.parametrize("kind", ["psd", "general", "degenerate", "ties"])
def test_lazy_updates_take_the_pivots_of_the_eager_loop(kind):
    """The work array's dictionary is updated lazily (lcp/_lemke_run.h: sync_column; at most
    ECAP = 128 pivots kept, then every column brought up to date), Python's eagerly: at n = 150
    these runs take 90 (psd), 151 with ties (ties), 5838 to a ray (general) and 16000 to the
    pivot limit (degenerate) pivots: the same codes, pivots and z."""
    _same_pivots(150, kind, range(1))


def _same_pivots(n: int, kind: str, seeds) -> None:
    from rigidlcp.lcp.acceptance.scaling import ruiz
    from rigidlcp.lcp.solvers.lemke import DEFAULT_TOL, lemke

    status = {kernel.SOLVED: ("solved",), kernel.RAY: ("ray", "infeasible"),
              kernel.MAX_ITER: ("max_iter",)}
    for seed in seeds:
        M, q = _problem(n, kind, seed)
        eq = ruiz(M, q)
        z, basis = np.empty(n), np.empty(n, dtype=np.intp)
        code, pivots, m, _ = kernel.solve_eq(M, q, eq.r, eq.c, DEFAULT_TOL, 1000 + 100 * n, z,
                                             basis)
        ref = lemke(eq.M, eq.q)
        assert ref.iterations == pivots
        if code in status:
            assert ref.status in status[code]
        if code == kernel.SOLVED:
            assert same(z, eq.z_back(ref.z))
            assert same(basis[:m].astype(np.intp), np.sort(np.asarray(ref.basis, dtype=np.intp)))


@compiled
@pytest.mark.parametrize("n", (*range(1, 14), 17, 30, 61))
def test_c_assess_agrees_with_the_numpy_assess(n):
    """lcp/acceptance/_accuracy_c.c (rows in blocks of 4, column-wise U^T solve) against
    lcp.accuracy's numpy `assess` (LAPACK's inverse, scipy's estimator: another implementation
    of the same definitions) on Lemke's answers, perturbed answers and permuted bases: the same
    verdict, the same polished point to rounding, backward errors equal to rounding, and the C
    forward bound the numpy code's function (`forward_bound`, |K^-1| formed) at the point C
    returns, bit for bit, and the numpy bound (at its own refined point) equal to it to 1e-3
    relative: |r| is at rounding level there, and its long-double sums differ in order."""
    from rigidlcp.lcp.acceptance import accuracy
    from rigidlcp.lcp.acceptance.scaling import ruiz
    from rigidlcp.lcp.solvers.lemke import DEFAULT_TOL

    if accuracy._accuracy_c is None:
        pytest.skip("the accuracy extension is not built")
    rng = np.random.default_rng(n)
    for kind in ("psd", "scaled", "ties"):
        M, q = _problem(n, kind, 0)
        z, basis = np.empty(n), np.empty(n, dtype=np.intp)
        eq = ruiz(M, q)
        code, _, m, _ = kernel.solve_eq(M, q, eq.r, eq.c, DEFAULT_TOL, 1000 + 100 * n, z, basis)
        assert code == kernel.SOLVED
        for zz, a in ((z, basis[:m]), (z * (1 + 1e-9 * rng.standard_normal(n)),
                                        rng.permutation(basis[:m]))):
            out = np.empty(n)
            got = accuracy._accuracy_c.assess(M, q, zz, np.ascontiguousarray(a, np.int64), out)
            if got[0] != 0:
                continue  # declined: the numpy code runs in that case anyway
            ref = accuracy.assess(M, q, zz, 0, a)
            c_berr, c_ferr, c_refined = got[1], got[2], bool(got[3])
            assert c_refined == ref.refined
            assert (c_berr <= accuracy.TOL) == (ref.berr <= accuracy.TOL)
            assert abs(c_berr - ref.berr) <= 1e-13
            scale = max(float(np.abs(ref.v).max()), 1e-300)
            assert np.abs(out - ref.v).max() <= 1e-12 * scale
            a_s = np.sort(np.asarray(a, dtype=np.intp))
            at_out = accuracy.forward_bound(M[np.ix_(a_s, a_s)], q[a_s], out[a_s])
            if c_refined:
                assert c_ferr == at_out
            assert abs(c_ferr - ref.ferr) <= 1e-3 * ref.ferr
            assert (c_ferr <= accuracy.FERR_TOL) == (ref.ferr <= accuracy.FERR_TOL)


@compiled
@pytest.mark.parametrize("k", range(0, 19, 2))
def test_c_assess_singularity_test_across_conditioning(k):
    """The C `assess` declines (code 1: the numpy code's SVD path decides) a pattern system
    singular to working precision -- Skeel's condition || |K^-1| |K| 1 || beyond 1 / (m eps) --
    and handles a well-conditioned one (lcp/acceptance/_bound_core.h: forward_bound, from
    |K^-1|'s columns). Conditions 1 .. 1e18, away from the threshold by a factor 100 either way
    (near it the computed condition, rounded, may
    fall on either side)."""
    from rigidlcp.lcp.acceptance import accuracy

    if accuracy._accuracy_c is None:
        pytest.skip("the accuracy extension is not built")
    m = 8
    rng = np.random.default_rng(k)
    U, _ = np.linalg.qr(rng.standard_normal((m, m)))
    V, _ = np.linalg.qr(rng.standard_normal((m, m)))
    K = U @ np.diag(np.logspace(0, -k, m)) @ V.T
    q = rng.standard_normal(m)
    with np.errstate(all="ignore"):
        skeel = float(np.max(np.abs(np.linalg.inv(K)) @ np.abs(K).sum(axis=1)))
    out = np.empty(m)
    code = accuracy._accuracy_c.assess(K, q, np.abs(rng.standard_normal(m)),
                                       np.arange(m, dtype=np.int64), out)[0]
    if skeel * m * np.finfo(float).eps > 100:
        assert code == 1
    elif skeel * m * np.finfo(float).eps < 0.01:
        assert code == 0


@compiled
@pytest.mark.parametrize("kind", ["psd", "general", "scaled", "degenerate", "ties"])
@pytest.mark.parametrize("n", (3, 8, 10, 17, 31, 33))
def test_the_batch_measure_with_the_solves_max_is_the_measure(n, kind):
    """solve_batch's mmax is max|M_p| exactly where it solved problem p (-1 elsewhere: rays,
    limits, an M that is not balanced), and measure_batch given it measures every problem to
    the same bits as measuring max|M_p| itself (residual, scaled residual, z_s, w_s, w)."""
    _check_batch_measure(n, kind, range(4))


@compiled
@settings(max_examples=40)
@given(st.integers(1, 40), st.sampled_from(["psd", "general", "scaled", "degenerate"]),
       st.integers(0, 2**32 - 1))
def test_the_batch_measure_with_the_solves_max_is_the_measure_on_random_problems(n, kind, seed):
    """The same, on random sizes and seeds."""
    _check_batch_measure(n, kind, range(seed, seed + 3))


def _check_batch_measure(n: int, kind: str, seeds) -> None:
    from rigidlcp.lcp.solvers.lemke import DEFAULT_TOL

    pairs = [_problem(n, kind, seed) for seed in seeds]
    Ms, qs = np.stack([M for M, _ in pairs]), np.stack([q for _, q in pairs])
    k = len(pairs)
    Z, basic = np.empty((k, n)), np.empty((k, n), dtype=np.int8)
    codes, pivots = np.empty(k, dtype=np.int64), np.empty(k, dtype=np.int64)
    acc, mmax = np.empty((k, 4)), np.full(k, np.nan)
    kernel.solve_batch(Ms, qs, np.ones(n), DEFAULT_TOL, 1000 + 100 * n, Z, basic, codes, pivots,
                       equilibrate=True, acc=acc, mmax=mmax)
    for p in range(k):
        expected = np.abs(Ms[p]).max() if codes[p] == kernel.SOLVED else -1.0
        assert mmax[p] == expected, (p, codes[p])
    W = np.matmul(Ms, Z[:, :, None])[:, :, 0]
    W_own, W_given = W.copy(), W.copy()
    own = kernel.measure_batch(Ms, qs, Z, W_own)
    given_max = kernel.measure_batch(Ms, qs, Z, W_given, mmax)
    assert own is not None and given_max is not None
    assert own.tobytes() == given_max.tobytes()
    assert W_own.tobytes() == W_given.tobytes()
