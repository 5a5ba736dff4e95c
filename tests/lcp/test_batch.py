"""lcp.solve_many (lcp/batch.py) against a loop of lcp.solve: the same answers (z, status,
pivots, basis, evidence), every answer checked (w recomputed, residual stored), bad input
refused with a typed error."""

from __future__ import annotations

import dataclasses
import gc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp import _lemke_kernel as kernel

from .test_fast_lemke import same
from .test_lemke import degenerate_integer_lcps, murty_matrix, murty_q


def same_outcome(a, b) -> bool:
    """Two Solutions equal field for field, bit for bit."""
    return type(a) is type(b) and all(same(getattr(a, f.name), getattr(b, f.name))
                                      for f in dataclasses.fields(a))


def random_lcps(k: int, n: int, seed: int) -> list[lcp.LCP]:
    rng = np.random.default_rng([seed, n])
    out = []
    for _ in range(k):
        A = rng.standard_normal((n, n))
        out.append(lcp.LCP(A @ A.T + 0.1 * np.eye(n), rng.standard_normal(n)))
    return out


def assert_same_as_loop(problems, method="lemke", **options):
    many = lcp.solve_many(problems, method, **options)
    assert len(many) == len(problems)
    for p, got in zip(problems, many):
        one = lcp.solve(p, method, **options)
        assert (got.status, got.iterations, got.message) == (one.status, one.iterations,
                                                               one.message)
        assert got.method == one.method
        np.testing.assert_array_equal(got.z, one.z)
        scale = 1e-12 * (1 + np.abs(p.q if isinstance(p, lcp.LCP) else p.b).max())
        np.testing.assert_allclose(got.w, one.w, rtol=0, atol=scale)
        assert got.residual == pytest.approx(one.residual, abs=scale)
        if one.basis is not None:
            np.testing.assert_array_equal(got.basis, one.basis)
        assert set(got.info) == set(one.info)
    return many


@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("n", [1, 3, 10, 40])
def test_lemke_batch_equals_a_loop_of_solve(n, compiled):
    previous = kernel.use_compiled(compiled)
    try:
        sols = assert_same_as_loop(random_lcps(20, n, 0))
    finally:
        kernel.use_compiled(previous)
    assert all(s.status == "solved" and s.residual < 1e-9 for s in sols)


@settings(max_examples=40, deadline=None)
@given(degenerate_integer_lcps(max_n=4))
def test_batch_on_degenerate_problems(problem):
    """Rays, infeasible problems, q >= 0, ties: each as a single solve answers it."""
    M, q = problem
    P = lcp.LCP(M, q)
    assert_same_as_loop([P, P, lcp.LCP(M, -np.abs(q) - 1)])


def test_mixed_sizes_statuses_and_mlcp():
    M, q = np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, -1.0])  # infeasible
    mlcp = lcp.MLCP(np.eye(1), np.ones((1, 2)), np.ones((2, 1)), np.eye(2), np.zeros(1),
                    np.array([-1.0, 2.0]))
    problems = [*random_lcps(3, 5, 1), lcp.LCP(M, q), lcp.LCP(murty_matrix(6), murty_q(6)),
                mlcp, *random_lcps(2, 7, 2)]
    sols = assert_same_as_loop(problems, max_iter=40)
    assert sols[3].status == "infeasible"
    # Murty's example needs 2^6 pivots on its raw data; equilibrated (lcp.solve's default for
    # lemke, issue 11) it is solved within 40, or a fall-back solves it: batch == loop above
    assert sols[4].status in ("max_iter", "solved")
    assert sols[5].u is not None


def test_other_methods_and_stacked_arrays():
    problems = random_lcps(6, 8, 3)
    assert_same_as_loop(problems, "pivoting")
    Ms = np.stack([p.M for p in problems])
    qs = np.stack([p.q for p in problems])
    for a, b in zip(lcp.solve_many((Ms, qs)), lcp.solve_many(problems)):
        np.testing.assert_array_equal(a.z, b.z)


def test_bad_input_is_refused():
    with pytest.raises(lcp.InvalidProblem, match="option"):
        lcp.solve_many(random_lcps(2, 3, 0), "lemke", bogus=1)
    with pytest.raises(lcp.InvalidProblem, match="unknown method"):
        lcp.solve_many(random_lcps(2, 3, 0), "nope")
    with pytest.raises(lcp.InvalidProblem, match=r"problems\[1\]"):
        lcp.solve_many([random_lcps(1, 3, 0)[0], "x"])
    with pytest.raises(lcp.InvalidProblem, match="NaN"):
        lcp.solve_many((np.full((2, 3, 3), np.nan), np.zeros((2, 3))))
    with pytest.raises(lcp.InvalidProblem, match="shape"):
        lcp.solve_many((np.zeros((2, 3, 3)), np.zeros((2, 4))))
    assert lcp.solve_many([]) == []


def test_repair_false_reaches_every_single_solve():
    """repair=False: the answers of a loop of lcp.solve(..., repair=False), the hard ones too
    (infeasible, a pivot limit, an MLCP), with every field as above."""
    M, q = np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, -1.0])  # infeasible
    problems = [*random_lcps(4, 6, 4), lcp.LCP(M, q), lcp.LCP(murty_matrix(6), murty_q(6))]
    sols = assert_same_as_loop(problems, max_iter=20, repair=False)
    assert sols[4].status == "infeasible"
    assert_same_as_loop(problems, "pivoting", repair=False)


@pytest.mark.skipif(not kernel.enabled(), reason="the C extension is not built or is off")
def test_each_answer_is_judged_once(monkeypatch):
    """The compiled batch assesses each answer in the solver's own C call (backward error,
    polishing, forward bound) and measures it once: neither the numpy `judge_lcp` nor a single
    `lcp.solve` runs for an answer the batch accepts, and the answers, with their bounds, are a
    loop of `lcp.solve`'s, bit for bit."""
    from rigidlcp.lcp import batch
    from rigidlcp.lcp.acceptance import accuracy

    if accuracy._accuracy_c is None:
        pytest.skip("the accuracy extension is not built")
    problems = random_lcps(12, 9, 5)
    loop = [lcp.solve(p) for p in problems]
    calls = []
    monkeypatch.setattr(batch, "judge_lcp", lambda *a: calls.append("judge") or None)
    monkeypatch.setattr(batch, "solve", lambda *a, **k: calls.append("solve") or None)
    many = lcp.solve_many(problems)
    assert calls == []
    for got, one in zip(many, loop):
        assert got.status == one.status == "solved"
        for field in ("z", "w", "basis"):
            assert getattr(got, field).tobytes() == getattr(one, field).tobytes()
        for field in ("residual", "scaled_residual", "backward_error", "forward_error",
                      "iterations"):
            assert repr(getattr(got, field)) == repr(getattr(one, field))
        assert got.info == one.info


@st.composite
def batches(draw):
    """A list of LCPs of mixed sizes (1..12) and kinds -- A A^T + 0.1 I, nonsymmetric, integer
    degenerate (rays, infeasible, q >= 0, ties) -- some of them repeated, as a study's list is."""
    out = []
    for _ in range(draw(st.integers(1, 8))):
        n = draw(st.integers(1, 12))
        seed = draw(st.integers(0, 2**16))
        rng = np.random.default_rng(seed)
        kind = draw(st.sampled_from(["psd", "nonsymmetric", "degenerate"]))
        if kind == "psd":
            A = rng.standard_normal((n, n))
            M, q = A @ A.T + 0.1 * np.eye(n), rng.standard_normal(n)
        elif kind == "nonsymmetric":
            M, q = rng.standard_normal((n, n)) + n * np.eye(n), rng.standard_normal(n)
        else:
            M = rng.integers(-2, 3, (n, n)).astype(float)
            q = rng.integers(-2, 3, n).astype(float)
        out += [lcp.LCP(M, q)] * draw(st.integers(1, 3))
    return out


@given(batches())
def test_solve_many_is_a_loop_of_solve_field_by_field(problems):
    """Every field of every Solution -- z, w, status, method, pivots, residuals, backward and
    forward error, basis, u, message, info -- bit for bit that of `lcp.solve(p)`, whichever
    route each answer took (the C loop and batch_solutions, numpy's judge, `lcp.solve`)."""
    many = lcp.solve_many(problems)
    assert type(many) is list and len(many) == len(problems)
    for p, got in zip(problems, many):
        assert same_outcome(got, lcp.solve(p))


@pytest.mark.parametrize("enabled", [True, False])
def test_solve_many_leaves_the_collector_as_it_found_it(enabled):
    """batch_solutions turns the collector off while it builds the Solutions (lcp/
    _batch_solutions.h) and back on only if it was on."""
    was = gc.isenabled()
    try:
        gc.enable() if enabled else gc.disable()
        sols = lcp.solve_many(random_lcps(30, 4, 6))
        assert gc.isenabled() is enabled
        assert all(s.status == "solved" for s in sols)
    finally:
        gc.enable() if was else gc.disable()
