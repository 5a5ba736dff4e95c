"""Issue 11: every "solved" is true, every "infeasible" is proved, answers do not depend on units.

The facts used are known without the solvers: a P-matrix (symmetric part positive definite) has
exactly one solution for every q; a planted (z*, w*) is a solution; a Farkas vector built into
the data proves infeasibility; verify.certify's acceptance test is the definition of solved.
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from flint import fmpq, fmpq_mat
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.bench.fuzz_cases import robust_infeasible
from rigidlcp.lcp import api
from rigidlcp.lcp.acceptance.farkas import find_certificate
from rigidlcp.lcp.acceptance.residual import TOL, check, scaled_residual
from rigidlcp.lcp.acceptance.scaling import ruiz
from rigidlcp.lcp.solvers.enumeration import _Scales, _singular_basis
from rigidlcp.lcp.solvers.lemke_exact import lemke_exact
from rigidlcp.verify import certify

DATA = Path(__file__).resolve().parents[1] / "data"
SEEDS = st.integers(0, 2**32 - 1)


def p_matrix(rng, n: int, spread: float = 0.0) -> np.ndarray:
    """S + K, S symmetric positive definite (eigenvalues 1 .. 10^-spread), K skew: a P-matrix."""
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    lam = np.logspace(0, -spread, n) if spread else rng.uniform(0.1, 2.0, n)
    K = rng.standard_normal((n, n))
    return (Q * lam) @ Q.T + rng.uniform(0, 1) * (K - K.T)


def infeasible_lcp(rng, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M^T y = -eps 1 < 0, y >= 0, q^T y < 0 (rigidlcp.bench.fuzz_cases): y is a Farkas
    certificate that {z >= 0 : M z + q >= 0} is empty, for every nearby problem too."""
    return robust_infeasible(rng, n)


@settings(max_examples=60)
@given(st.integers(2, 14), SEEDS, st.sampled_from(["lemke", "pivoting"]))
def test_scaled_p_matrix_lcps_get_the_same_answer(n, seed, method):
    """R M C, R q with positive R, C (1e-8 .. 1e8) is the same LCP in other units: z = C z'."""
    rng = np.random.default_rng(seed)
    M, q = p_matrix(rng, n), rng.standard_normal(n)
    r, c = 10.0 ** rng.uniform(-8, 8, n), 10.0 ** rng.uniform(-8, 8, n)
    base = lcp.solve(lcp.LCP(M, q), method)
    scaled = lcp.solve(lcp.LCP(r[:, None] * M * c[None, :], r * q), method)
    assert base.status == scaled.status == "solved", (base.message, scaled.message)
    back = c * scaled.z
    np.testing.assert_allclose(back, base.z, rtol=1e-6, atol=1e-9 * np.abs(base.z).max())
    # the residual reported is the one of the problem passed (the scaled one)
    assert scaled.scaled_residual == pytest.approx(
        scaled_residual(r[:, None] * M * c[None, :], r * q, scaled.z), abs=1e-15)
    assert scaled.info["equilibrated"] is True


def test_equilibration_can_be_switched_off_and_is_reported():
    rng = np.random.default_rng(1)
    P = lcp.LCP(p_matrix(rng, 6), rng.standard_normal(6))
    assert lcp.solve(P, "lemke").info["equilibrated"] is True
    assert lcp.solve(P, "lemke", equilibrate=False).info["equilibrated"] is False
    assert lcp.solve(P, "pgs").info["equilibrated"] is False  # pgs: off unless asked
    assert lcp.solve(P, "pgs", equilibrate=True).status == "solved"


def test_ruiz_equilibration_maps_solutions_back_exactly():
    """z solves (M, q) iff z / c solves (R M C, R q): powers of 2, so no rounding at all."""
    rng = np.random.default_rng(2)
    M, q = p_matrix(rng, 5), rng.standard_normal(5)
    r, c = 10.0 ** rng.uniform(-8, 8, 5), 10.0 ** rng.uniform(-8, 8, 5)
    e = ruiz(r[:, None] * M * c[None, :], r * q)
    assert np.all(np.log2(e.r) % 1 == 0) and np.all(np.log2(e.c) % 1 == 0)
    big = np.abs(e.M).max(axis=1)
    assert np.all((big > 0.25) & (big <= 4.0))  # every row equilibrated to within 2^2
    np.testing.assert_array_equal(e.M, (r[:, None] * M * c[None, :]) * e.r[:, None] * e.c)


@pytest.mark.parametrize("method", ["lemke", "pivoting", "enumerate"])
def test_a_tiny_q_beside_a_huge_balanced_m_is_solved_not_refused(method):
    """|M| ~ 1e160, |q| ~ 1e-150: the unit change of q (r ~ 1e150, c ~ 1e-150) once overflowed
    M r to inf before c brought it back, and a valid LCP was refused as containing NaN or Inf.
    The solution is z = -M^-1 q = [0.2, 0.6] 1e-310 (M = [[2, 1], [1, 3]] 1e160, both z_i > 0)."""
    M = np.array([[2.0, 1.0], [1.0, 3.0]]) * 1e160
    q = np.array([-1.0, -2.0]) * 1e-150
    eq = ruiz(M, q)
    assert np.isfinite(eq.M).all() and 0.5 <= np.abs(eq.q).max() <= 2.0
    sol = lcp.solve(lcp.LCP(M, q), method)
    assert sol.status == "solved"
    assert np.allclose(sol.z / 1e-310, [0.2, 0.6], rtol=1e-9)


@settings(max_examples=80)
@given(st.integers(2, 30), SEEDS, st.sampled_from(["lemke", "pivoting", "enumerate", "pgs"]),
       st.sampled_from(["P", "ill-P", "scaled", "random", "integer"]))
def test_solved_is_always_accepted_by_certify(n, seed, method, kind):
    rng = np.random.default_rng(seed)
    if kind == "random":
        M = rng.standard_normal((n, n))
    elif kind == "integer":
        M = rng.integers(-3, 4, (n, n)).astype(float)
    else:
        M = p_matrix(rng, n, spread=rng.uniform(8, 16) if kind == "ill-P" else 0.0)
    q = rng.standard_normal(n)
    if kind == "scaled":
        r, c = 10.0 ** rng.uniform(-8, 8, n), 10.0 ** rng.uniform(-8, 8, n)
        M, q = r[:, None] * M * c[None, :], r * q
    if method == "enumerate" and n > 10:
        return
    problem = lcp.LCP(M, q)
    try:
        sol = lcp.solve(problem, method, **({"max_iter": 300} if method == "pgs" else {}))
    except lcp.NotApplicable:  # pgs and a nonpositive diagonal: a refusal, not an answer
        return
    assert sol.status in lcp.STATUSES
    if sol.status == "solved":
        assert certify(problem, sol, uniqueness="none").accepted
        assert sol.scaled_residual <= TOL
    if kind in ("P", "scaled"):
        assert sol.status != "infeasible"


@settings(max_examples=40)
@given(st.integers(2, 25), SEEDS, st.sampled_from(["lemke", "pivoting", "enumerate"]))
def test_infeasible_carries_a_checked_farkas_certificate(n, seed, method):
    rng = np.random.default_rng(seed)
    M, q, _ = infeasible_lcp(rng, n)
    if method == "enumerate" and n > 10:
        return
    sol = lcp.solve(lcp.LCP(M, q), method)
    assert sol.status == "infeasible", sol.message
    y = sol.info["farkas"]
    assert np.all(y >= 0) and y.sum() == pytest.approx(1.0)
    assert float(q @ y) < 0
    assert np.max(M.T @ y) <= 1e-14 * np.abs(M).max()  # rounding (the data give -eps < 0)
    assert sol.info["farkas_exact"] is True and sol.info["farkas_radius"] == np.inf


@pytest.mark.parametrize("method", ["lemke", "pivoting", "enumerate", "newton-min"])
def test_a_float_certificate_of_a_solvable_lcp_is_not_infeasibility(method):
    """The bench's old "infeasible" set, n16-0 (built in floats: M^T y = 0 only to rounding),
    stored in tests/data. M + M^T is positive definite as stored (smallest eigenvalue 6.9e-16
    in floats; its leading principal minors are positive in exact rationals, Sylvester), so M
    is a P-matrix and the LCP has a unique solution, of size ~2.4e16, which Lemke's method in
    exact rationals finds. Every method had answered
    "infeasible" on a floating-point certificate of radius 9.3e14 - 2.8e15; none may now. The
    certificate stays as evidence (info, message) with farkas_exact False."""
    d = np.load(DATA / "float_certificate_p_matrix_n16.npz")
    M, q = d["M"], d["q"]
    n, F = q.size, [Fraction(float(v)) for v in M.ravel()]
    S = fmpq_mat(n, n, [fmpq(*(F[i * n + j] + F[j * n + i]).as_integer_ratio())
                        for i in range(n) for j in range(n)])  # M + M^T in exact rationals
    for k in range(1, n + 1):
        minor = fmpq_mat(k, k, [S[i, j] for i in range(k) for j in range(k)])
        assert minor.det() > 0
    exact = lemke_exact(M, q, np.ones(q.size), 1000)
    assert exact.status == "solved" and np.max(exact.z) > 1e15  # a solution exists
    sol = lcp.solve(lcp.LCP(M, q), method)
    assert sol.status != "infeasible", sol.message
    if "farkas" in sol.info:
        assert sol.info["farkas_exact"] is False
        assert "infeasibility is not proved" in sol.message


def test_a_p_matrix_lcp_never_gets_a_certificate():
    rng = np.random.default_rng(3)
    for _ in range(30):
        n = int(rng.integers(2, 20))
        M, q = p_matrix(rng, n, spread=rng.uniform(0, 12)), rng.standard_normal(n)
        assert find_certificate(ruiz(M, q)) is None


@pytest.fixture
def liar():
    """A test-only method that returns a wrong z with status "solved" (or a false infeasible)."""
    claims = {}

    @api.register("test-liar", accepts="any", description="returns wrong answers (tests only)")
    def lie(M, q, *, claim: str = "solved"):
        n = q.size
        claims["last"] = claim
        return lcp.Solution(z=np.ones(n), w=q, status=claim, method="test-liar",
                            basis=np.arange(n) if claim == "solved" else None)

    yield lie
    api._REGISTRY.pop("test-liar", None)


def test_a_wrong_solved_becomes_inaccurate_with_its_residual(liar):
    rng = np.random.default_rng(4)
    M, q = p_matrix(rng, 5), rng.standard_normal(5) - 3.0
    sol = lcp.solve(lcp.LCP(M, q), "test-liar", repair=False)
    # the basis {0..4} holds z = -M^-1 q, which is not >= 0 here: no repair on it either
    if sol.status == "solved":
        assert check(lcp.LCP(M, q), sol.z).accepted
    else:
        assert sol.status == "inaccurate"
        assert sol.scaled_residual > TOL
        assert "acceptance test" in sol.message


def test_a_wrong_solved_is_not_replaced_by_another_methods_answer(liar):
    """Issue 23: lcp.solve(problem, method=X) returns X's own answer; another method's answer
    only with fallback=..., and then under that method's name."""
    rng = np.random.default_rng(5)
    M, q = p_matrix(rng, 6), rng.standard_normal(6)
    q[0] = 10.0  # z = 1 is not a solution
    P = lcp.LCP(M, q)
    sol = lcp.solve(P, "test-liar")
    assert sol.status == "inaccurate" and sol.method == "test-liar"
    assert "fallback_for" not in sol.info and not certify(P, sol, uniqueness="none").accepted
    assert "method='test-liar'" in repr(sol) and "status='inaccurate'" in repr(sol)
    got = lcp.solve(P, "test-liar", fallback=True)
    assert got.status == "solved" and got.method == "pivoting"
    assert got.info["fallback_for"]["method"] == "test-liar"
    assert got.info["fallback_for"]["status"] == "solved"  # what the liar claimed
    assert "method='pivoting'" in repr(got)
    assert certify(P, got, uniqueness="none").accepted
    assert lcp.solve(P, "test-liar", fallback="lemke").method == "lemke"
    with pytest.raises(lcp.InvalidProblem):
        lcp.solve(P, "test-liar", fallback="no-such-method")


def test_a_false_infeasible_is_never_returned(liar):
    rng = np.random.default_rng(6)
    M, q = p_matrix(rng, 6), rng.standard_normal(6)
    P = lcp.LCP(M, q)
    sol = lcp.solve(P, "test-liar", claim="infeasible")
    assert sol.status == "failed" and "not proved" in sol.message and sol.method == "test-liar"
    got = lcp.solve(P, "test-liar", claim="infeasible", fallback=True)
    assert got.status == "solved" and got.method == "pivoting"
    sol = lcp.solve(P, "test-liar", claim="infeasible", repair=False)
    assert sol.status == "failed" and "not proved" in sol.message


def test_mlcp_answers_are_checked_with_the_equality_residual():
    rng = np.random.default_rng(7)
    nu, m = 4, 5
    A = p_matrix(rng, nu) + 3 * np.eye(nu)
    C, D = rng.standard_normal((nu, m)), rng.standard_normal((m, nu))
    B = p_matrix(rng, m) + D @ np.linalg.solve(A, C)  # Schur complement B - D A^-1 C is P
    P = lcp.MLCP(A, C, D, B, rng.standard_normal(nu), rng.standard_normal(m))
    for method in ("lemke", "pivoting", "enumerate"):
        sol = lcp.solve(P, method)
        assert sol.status == "solved"
        cert = certify(P, sol, uniqueness="none")
        assert cert.accepted and sol.scaled_residual <= TOL
        assert sol.scaled_residual == pytest.approx(
            max(cert.scaled_residual, cert.scaled_eq_residual), abs=1e-15)


def test_enumerate_does_not_crash_on_a_basis_only_the_condition_estimate_calls_singular():
    """Regression: the 1-norm condition estimate (> 1e10) flagged this 5 x 5 basis singular
    while its SVD has full rank (sigma ratio > 1e-10): the LP then had 0 unknowns and linprog
    raised 'c must be a 1-D array'."""
    U, _ = np.linalg.qr(np.random.default_rng(0).standard_normal((5, 5)))
    A = (U * np.logspace(0, -9.9, 5)) @ U.T
    z0 = np.array([1.0, 2.0, 0.5, 1.5, 1.0])
    q = -A @ z0
    alpha = np.arange(5)
    got = _singular_basis(A, q, alpha, _Scales(A, q, 1e-9), np.random.default_rng(0))
    assert got is None or np.all(np.isfinite(got[0]))
    sol = lcp.solve(lcp.LCP(A, q), "enumerate")
    assert sol.status in ("solved", "inaccurate", "failed")
    if sol.status == "solved":
        assert check(lcp.LCP(A, q), sol.z).accepted


def test_issue_example_ill_conditioned_p_matrix_is_never_a_false_solved():
    """Issue 11: lemke said "solved" with residual 6e8 on a 55 x 55 P-matrix LCP of cond ~4e16.
    Whatever the status now, a "solved" passes the acceptance test and "infeasible" is absent."""
    rng = np.random.default_rng(11)
    for _ in range(5):
        M, q = p_matrix(rng, 55, spread=16.5), rng.standard_normal(55)
        for method in ("lemke", "pivoting"):
            sol = lcp.solve(lcp.LCP(M, q), method)
            assert sol.status != "infeasible"
            if sol.status == "solved":
                assert check(lcp.LCP(M, q), sol.z).accepted
