"""The fast path of `lcp.solve` (lcp/solvers/fast_lemke.py), the C measure of lcp.residual and the
batch path give exactly what the general path gives: the same Solution, field for field and
bit for bit, on random, degenerate and badly scaled problems; anything else (bad input, other
options, a ray, no compiled kernel) goes to the general path, which answers or raises as
before."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp import _lemke_kernel as kernel
from rigidlcp.lcp import api
from rigidlcp.lcp.acceptance import residual
from rigidlcp.lcp.acceptance.scaling import _pow2, ruiz
from rigidlcp.lcp.errors import RigidLCPError
from rigidlcp.lcp.problems.solution import Solution, solved_lcp
from rigidlcp.lcp.solvers import fast_lemke

from .test_lemke import degenerate_integer_lcps

compiled = pytest.mark.skipif(not kernel.enabled(), reason="the C extension is not built or is off")



def fields(sol) -> list[str]:
    """The Solution's field names (its slots: a Solution has no __dict__)."""
    return [f.name for f in dataclasses.fields(sol)]

def same(x, y) -> bool:
    """Equal, bit for bit (arrays: dtype, shape, values, NaNs and signs of zeros), recursively."""
    if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
        return (isinstance(x, np.ndarray) and isinstance(y, np.ndarray) and x.dtype == y.dtype
                and x.shape == y.shape and x.tobytes() == y.tobytes())
    if isinstance(x, dict):
        return isinstance(y, dict) and list(x) == list(y) and all(same(x[k], y[k]) for k in x)
    if isinstance(x, float) and isinstance(y, float):
        return np.float64(x).tobytes() == np.float64(y).tobytes()
    return type(x) is type(y) and x == y


def general(problem, **kw):
    """lcp.solve without the fast path (the general path: lcp.trust.solve_checked)."""
    saved = api._FAST
    api._FAST = lambda p: None
    try:
        return lcp.solve(problem, "lemke", **kw)
    finally:
        api._FAST = saved


def outcome(f, problem):
    try:
        return f(problem)
    except Exception as exc:  # noqa: BLE001 - compared between the two paths
        return exc


def assert_same_answer(problem):
    fast, slow = outcome(lambda p: lcp.solve(p, "lemke"), problem), outcome(general, problem)
    if isinstance(slow, Exception):
        assert type(fast) is type(slow) and str(fast) == str(slow)
        return None
    assert type(fast) is type(slow)
    for key in fields(slow):
        assert same(getattr(fast, key), getattr(slow, key)), key
    return fast


@st.composite
def random_lcps(draw, max_n: int = 12,
                kinds: tuple[str, ...] = ("general", "psd", "scaled", "extreme", "q>=0")):
    """Random, PSD, P-matrix (non-symmetric: diagonally dominant or triangular), badly scaled
    (rows, columns and q over many decades) and extreme problems (of the given kinds)."""
    n = draw(st.integers(1, max_n))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    kind = draw(st.sampled_from(kinds))
    A = rng.standard_normal((n, n))
    q = rng.standard_normal(n)
    if kind == "general":
        M = A
    elif kind == "psd":
        M = A @ A.T + 0.1 * np.eye(n)
    elif kind == "p-dominant":
        M = A + np.diag(np.abs(A).sum(axis=1) + 0.1)
    elif kind == "p-triangular":
        M = np.triu(A, 1) + np.diag(np.exp(rng.uniform(-3, 3, n)))
    elif kind == "scaled":
        D = np.exp(rng.uniform(-20, 20, n))
        M = D[:, None] * (A @ A.T + np.eye(n)) * D[None, :]
        q = q * np.exp(rng.uniform(-20, 20))
    elif kind == "extreme":
        M = (A @ A.T + np.eye(n)) * 10.0 ** rng.uniform(-150, 150)
        q = q * 10.0 ** rng.uniform(-150, 150)
    else:
        M, q = A, np.abs(q)
    return M, q


@compiled
@settings(max_examples=300, deadline=None)
@given(random_lcps())
def test_fast_path_gives_the_general_answer_on_random_problems(problem):
    assert_same_answer(lcp.LCP(*problem))


@compiled
@settings(max_examples=300, deadline=None)
@given(degenerate_integer_lcps(max_n=6))
def test_fast_path_gives_the_general_answer_on_degenerate_problems(problem):
    """Ties, rays, infeasible problems, q >= 0: solved ones by the fast path, the rest by the
    general path, every one as the general path answers it."""
    assert_same_answer(lcp.LCP(*problem))


@compiled
def test_fast_path_is_taken_and_leaves_the_rest():
    rng = np.random.default_rng(3)
    A = rng.standard_normal((8, 8))
    P = lcp.LCP(A @ A.T + np.eye(8), rng.standard_normal(8))
    assert fast_lemke.solve_lemke(P) is not None  # balanced: equilibrated in C
    D = np.exp(rng.uniform(-10, 10, 8))
    S = lcp.LCP(D[:, None] * P.M * D[None, :], P.q)
    assert fast_lemke.solve_lemke(S) is not None  # not balanced: ruiz's factors passed
    assert same(fast_lemke.solve_lemke(S).z, general(S).z)
    ray = lcp.LCP(np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, -1.0]))
    assert fast_lemke.solve_lemke(ray) is None  # infeasible: the general path proves it
    assert lcp.solve(ray).status == "infeasible"
    fortran = lcp.LCP(np.asfortranarray(P.M), P.q)
    assert fast_lemke.solve_lemke(fortran) is None
    assert_same_answer(fortran)
    previous = kernel.use_compiled(False)
    try:
        assert fast_lemke.solve_lemke(P) is None  # no kernel: the numpy loop, same answer
        assert same(lcp.solve(P).z, general(P).z)
    finally:
        kernel.use_compiled(previous)


@compiled
def test_options_and_other_settings_take_the_general_path(monkeypatch):
    rng = np.random.default_rng(4)
    A = rng.standard_normal((6, 6))
    P = lcp.LCP(A @ A.T + np.eye(6), rng.standard_normal(6))
    calls = []
    real = fast_lemke.solve_lemke
    monkeypatch.setattr(api, "_FAST", lambda p: calls.append(p) or real(p))
    lcp.solve(P)
    lcp.solve(P, "lemke", equilibrate=True)
    assert len(calls) == 2
    for kw in ({"max_iter": 50}, {"equilibrate": False}, {"tol": 1e-9}):
        sol = lcp.solve(P, "lemke", **kw)
        assert sol.status == "solved"
    lcp.solve(P, "pivoting")
    assert len(calls) == 2
    M = lcp.MLCP(np.eye(1), np.ones((1, 2)), np.ones((2, 1)), np.eye(2), np.zeros(1),
                 np.array([-1.0, 2.0]))
    assert lcp.solve(M).u is not None and len(calls) == 2


@compiled
def test_a_method_registered_as_lemke_replaces_the_fast_path():
    info = api._REGISTRY["lemke"]
    seen = []

    @api.register("lemke", accepts="any", description="test double", equilibrate=True,
                  replace=True)
    def double(M, q):
        seen.append(1)
        return Solution(z=np.zeros(q.size), w=q.copy(), status="solved", method="lemke")

    try:
        assert fast_lemke.solve_lemke(lcp.LCP(np.eye(2), np.ones(2))) is None
        lcp.solve(lcp.LCP(np.eye(2), np.ones(2)), "lemke")
        assert seen
    finally:
        api._REGISTRY["lemke"] = info


@compiled
@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # the general path's ruiz on inf
@pytest.mark.parametrize("where", ["M", "q"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_bad_numbers_after_construction_raise_as_the_general_path(where, bad):
    """An LCP validates its data when built; one whose arrays were changed in place since
    reaches solve with NaN or Inf: both paths raise the same typed error."""
    P = lcp.LCP(np.eye(3) + 0.5, -np.ones(3))
    getattr(P, where)[(1, 2) if where == "M" else 1] = bad
    with pytest.raises(lcp.InvalidProblem) as fast:
        lcp.solve(P)
    with pytest.raises(lcp.InvalidProblem) as slow:
        general(P)
    assert str(fast.value) == str(slow.value)
    assert fast_lemke.solve_lemke(P) is None


@compiled
@pytest.mark.parametrize("M, q", [
    (np.ones(9), -np.ones(3)),                      # M a vector
    (np.ones((3, 4)), -np.ones(3)),                 # not square
    (np.ones((3, 3)), -np.ones(4)),                 # q of another size
    (np.ones((3, 3), dtype=np.float32), -np.ones(3)),
    (np.ones((3, 3)).tolist(), -np.ones(3)),        # not an array
])
def test_wrong_shapes_or_types_forced_in_take_the_general_path(M, q):
    """Data that did not pass LCP's validation (set behind its back) never reach the C call:
    the fast path declines, the general path answers or raises as before."""
    P = lcp.LCP(np.eye(3), -np.ones(3))
    object.__setattr__(P, "M", M)
    object.__setattr__(P, "q", q)
    assert fast_lemke.solve_lemke(P) is None
    fast, slow = outcome(lcp.solve, P), outcome(general, P)
    assert type(fast) is type(slow)
    if isinstance(slow, Exception):
        assert str(fast) == str(slow)


@compiled
def test_read_only_data_take_the_general_path():
    P = lcp.LCP(np.eye(3) + 0.5, -np.ones(3))
    P.M.flags.writeable = False
    assert fast_lemke.solve_lemke(P) is None
    assert_same_answer(P)


@compiled
def test_numbers_that_could_overflow_the_check_take_the_general_path():
    """|M| near the largest double: numpy's M z or the row sums could overflow (and warn);
    the fast path leaves such problems to the general path, which measures under errstate."""
    P = lcp.LCP(np.full((3, 3), 1e307) + np.eye(3) * 1e307, -np.ones(3) * 1e307)
    assert fast_lemke.solve_lemke(P) is None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert_same_answer(P)


@compiled
@pytest.mark.parametrize("k", [-900, -40, -1, 0, 1, 3, 52, 900])
def test_unit_of_q_near_a_midpoint_is_decided_as_numpy_does(k):
    """The power of 2 nearest |q|_inf (lcp.scaling's _pow2) is read from the bits in C, except
    within 1e-9 of sqrt(2) 2^k, where numpy decides; on both sides and on it, the answer is
    the general path's."""
    mid = np.sqrt(2.0) * 2.0**k
    A = np.array([[2.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 2.5]])
    for qmax in (mid, np.nextafter(mid, 0), np.nextafter(mid, 2 * mid), mid * (1 + 1e-8),
                 mid * (1 - 1e-8), 2.0**k, 1.5 * 2.0**k):
        P = lcp.LCP(A * 2.0**k, np.array([-qmax, 0.3 * qmax, -0.5 * qmax]))
        assert_same_answer(P)
        eq = ruiz(P.M, P.q)
        s = float(_pow2(np.array(qmax)))
        assert eq.c[0] == s  # balanced: c = s exactly


def reference_measure(M, q, z):
    """lcp.residual's LCP measure as written before the C version (numpy only)."""
    w = M @ z + q
    mmax = float(np.max(np.abs(M)))
    qmax = float(np.max(np.abs(q)))
    zmax = float(np.max(np.abs(z)))
    zs = max(zmax, qmax / mmax if mmax > 0 else 0.0)
    if zs == 0.0:
        zs = 1.0
    ws = qmax + float(np.max(np.sum(np.abs(M), axis=1))) * zs
    ws = ws if ws > 0 else 1.0
    scaled = float(np.max(np.abs(np.minimum(z / zs, w / ws))))
    raw = float(np.max(np.abs(np.minimum(z, w))))
    return w, raw, scaled, zs, ws


@st.composite
def measured(draw):
    n = draw(st.integers(1, 300))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    spread = draw(st.sampled_from([0.0, 1.0, 30.0, 150.0]))
    M = rng.standard_normal((n, n)) * np.exp(rng.uniform(-spread, spread, (n, n)))
    q = rng.standard_normal(n) * np.exp(rng.uniform(-spread, spread))
    z = np.maximum(rng.standard_normal(n), 0) * np.exp(rng.uniform(-spread, spread))
    zeros = draw(st.sampled_from(["none", "z", "q", "M"]))
    if zeros == "z":
        z[:] = 0.0
    elif zeros == "q":
        q[:] = 0.0
    elif zeros == "M":
        M[:] = 0.0
    return M, q, z


@compiled
@settings(max_examples=200, deadline=None)
@given(measured())
def test_c_measure_equals_numpy_bit_for_bit(data):
    """lcp_measure in C (w, the row sums in numpy's pairwise order, the scales, the minima)
    against the numpy code it replaces, and against its own numpy fallback."""
    M, q, z = data
    with np.errstate(all="ignore"):
        ref = reference_measure(M, q, z)
        got = residual.lcp_measure(M, q, z)
        assert kernel.measure(M, q, z, M.dot(z)) is not None  # the C code did measure
        previous = kernel.use_compiled(False)
        try:
            fallback = residual.lcp_measure(M, q, z)
        finally:
            kernel.use_compiled(previous)
    for a, b, c in zip(ref, got, fallback):
        assert same(a, b) and same(a, c)


@compiled
def test_c_measure_declines_non_finite_and_strided_data():
    M, q, z = np.eye(3), np.ones(3), np.ones(3)
    Mz = M.dot(z)
    for args in ((M, q, np.array([1.0, np.nan, 0.0])), (M, np.array([1.0, np.inf, 0.0]), z),
                 (np.full((3, 3), 1e308), q, np.full(3, 1e308)), (M, q, np.ones(6)[::2]),
                 (np.asfortranarray(M + np.triu(M, 1)), q, z), (M, q.astype(np.float32), z)):
        before = Mz.copy()
        assert kernel.measure(*args, Mz) is None
        assert same(Mz, before)  # untouched
        with np.errstate(all="ignore"):
            assert all(same(a, b) for a, b in zip(residual.lcp_measure(*args),
                                                  reference_measure(*args)))


@compiled
def test_row_sums_follow_numpys_order(monkeypatch):
    """The C row sums agree with numpy's wherever the probe says so (numpy 1.24-2.2 sum rows of
    10007 terms in another order than 2.3+: the probe then stops at 4099, and `measure` leaves
    longer rows to numpy), and `measure` declines beyond the verified length."""
    upto = kernel.sums_verified_upto()
    assert upto >= 1000  # every numpy tried (1.24-2.5) agrees up to 4099
    assert kernel.sums_as_numpy() == (upto == kernel.PROBE_SIZES[-1])
    monkeypatch.setattr(kernel, "_sums_upto", 5)  # as if the probe had stopped at 5
    for n, measured in ((5, True), (6, False)):
        M, z = np.eye(n), np.ones(n)
        assert (kernel.measure(M, -z, z, M.dot(z)) is not None) == measured
    rng = np.random.default_rng(5)
    for n in range(1, 400, 7):
        P = rng.standard_normal((4, n)) * np.exp(rng.uniform(-60, 60, (4, n)))
        out = np.empty(4)
        kernel._lemke_c.abs_row_sums(P, out, n)
        assert same(out, np.add.reduce(np.abs(P), axis=1))
        assert same(out, np.sum(np.abs(P), axis=1))


def test_solved_lcp_builds_the_same_solution_as_the_dataclass():
    z, w, b = np.array([1.0, 0.0]), np.array([0.0, 2.0]), np.array([0])
    fast = solved_lcp(z, w, "lemke", 3, 0.5, 0.25, b, "msg", {"equilibrated": True})
    slow = Solution(z=z, w=w, status="solved", method="lemke", iterations=3, residual=0.5,
                    eq_residual=0.0, scaled_residual=0.25, basis=b, u=None, message="msg",
                    info={"equilibrated": True})
    assert type(fast) is type(slow)
    assert all(same(getattr(fast, k), getattr(slow, k)) for k in fields(slow))
    assert repr(fast) == repr(slow) and fast.success and fast.to_dict() == slow.to_dict()


@compiled
@settings(max_examples=60, deadline=None)
@given(st.lists(random_lcps(max_n=6), min_size=1, max_size=8))
def test_batch_gives_the_loops_answers_bit_for_bit(problems):
    lcps = [lcp.LCP(M, q) for M, q in problems]
    try:
        loop = [lcp.solve(p) for p in lcps]
    except RigidLCPError:
        return  # the general path refuses some extreme data (as before); not the batch's case
    many = lcp.solve_many(lcps)
    for got, one in zip(many, loop):
        assert type(got) is type(one)
        for key in fields(one):
            if key in ("z", "w", "basis"):  # views into the batch's arrays: compare values
                assert same(np.array(getattr(got, key)), np.array(getattr(one, key))), key
            else:
                assert same(getattr(got, key), getattr(one, key)), key
