"""Issue 23: a method's answer is its own, every "solved" carries a backward error and a forward
error bound that hold, inflating z meets no acceptance measure, Lemke decides ties exactly,
and an exact Farkas certificate is accepted.

Facts used, known without the solvers: the exact solution of a basis system (rational
arithmetic, python-flint); the unique solution of a P-matrix LCP; Farkas vectors built into the
data; the inflated point of the issue (w_3 = -100 on a row z does not touch).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from flint import fmpq, fmpq_mat
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp import api
from rigidlcp.lcp.acceptance.accuracy import FERR_TOL, assess_lcp, backward_error
from rigidlcp.lcp.acceptance.farkas import RADIUS, check_certificate, exact_certificate
from rigidlcp.lcp.acceptance.residual import TOL, scaled_residual
from rigidlcp.lcp.acceptance.scaling import ruiz
from rigidlcp.lcp.solvers import lemke as lemke_module
from rigidlcp.lcp.solvers.lemke_exact import lemke_exact
from rigidlcp.verify import certify

SICONOS_MLCP = Path("/work/shared/data/siconos/mlcp")

#: The issue's inflated point: w = (-1, 1, -100), scaled residual 5e-14 by lcp.residual.
M_INFL = np.array([[1.0, -1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
Q_INFL = np.array([-1.0, 1.0, -100.0])
Z_INFL = np.array([1e15, 1e15, 0.0])


@pytest.fixture
def liars():
    """Test-only methods: one says "solved" with z = 1, one proposes the inflated point."""

    @api.register("test-ones", accepts="any", description="z = 1, 'solved' (tests only)")
    def ones(M, q):
        return lcp.Solution(z=np.ones(q.size), w=q, status="solved", method="test-ones")

    @api.register("test-inflated", accepts="any", description="the inflated point (tests only)")
    def inflated(M, q):
        return lcp.Solution(z=Z_INFL.copy(), w=q, status="solved", method="test-inflated")

    yield
    api._REGISTRY.pop("test-ones", None)
    api._REGISTRY.pop("test-inflated", None)


def exact_basis_solution(M: np.ndarray, q: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """z with z_a = -M_aa^-1 q_a exactly (rationals), z_b = 0, rounded once to double."""
    a = [int(i) for i in basis]
    z = np.zeros(q.size)
    if not a:
        return z
    A = fmpq_mat(len(a), len(a), [fmpq(*float(M[i, j]).as_integer_ratio()) for i in a
                                  for j in a])
    b = fmpq_mat(len(a), 1, [-fmpq(*float(q[i]).as_integer_ratio()) for i in a])
    x = A.solve(b)
    for k, i in enumerate(a):
        z[i] = int(x[k, 0].p) / int(x[k, 0].q)  # python-flint < 0.7: fmpq has no __float__
    return z


def test_the_inflated_point_meets_no_acceptance_measure(liars):
    """Issue 23: z = (1e15, 1e15, 0) has lcp.residual's scaled residual 5e-14 but w_3 = -100
    on a row z does not touch; it is neither "solved" nor accepted by verify.certify."""
    P = lcp.LCP(M_INFL, Q_INFL)
    assert scaled_residual(M_INFL, Q_INFL, Z_INFL) < 1e-13  # the old measure is fooled
    assert backward_error(M_INFL, Q_INFL, Z_INFL, 0) >= 0.3  # w_3 / max(100, s_d = 300)
    assert not certify(P, Z_INFL, uniqueness="none").accepted
    sol = lcp.solve(P, "test-inflated")
    assert sol.status != "solved" and sol.method == "test-inflated"
    assert not certify(P, sol, uniqueness="none").accepted
    # the LCP's solutions: z_3 = 100 and z_1 = z_2 + 1; every method that solves finds one
    for name in ("lemke", "pivoting"):
        good = lcp.solve(P, name)
        assert good.status == "solved" and good.z[2] == pytest.approx(100.0)
        assert good.z[0] - good.z[1] == pytest.approx(1.0)


def test_a_lying_method_is_reported_failed_under_its_own_name(liars):
    rng = np.random.default_rng(0)
    A = rng.standard_normal((6, 6))
    M, q = A @ A.T + np.eye(6), rng.standard_normal(6)
    q[0] = 10.0  # z = 1 is not a solution (z_0 = 0 there)
    P = lcp.LCP(M, q)
    sol = lcp.solve(P, "test-ones")
    assert sol.status == "inaccurate" and sol.method == "test-ones"
    assert sol.backward_error > TOL and "fallback_for" not in sol.info
    assert not certify(P, sol, uniqueness="none").accepted
    many = lcp.solve_many([P, P], "test-ones")
    assert [s.status for s in many] == ["inaccurate"] * 2
    assert all(s.method == "test-ones" for s in many)
    got = lcp.solve(P, "test-ones", fallback=("lemke",))
    assert got.status == "solved" and got.method == "lemke"
    assert got.info["fallback_for"] == {"method": "test-ones", "status": "solved",
                                        "message": ""}
    assert "fallback 'lemke'" in got.message


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 14), st.integers(0, 2**32 - 1), st.sampled_from([0.0, 6.0, 11.0]),
       st.sampled_from(["lemke", "pivoting"]))
def test_every_solved_carries_errors_and_the_forward_bound_holds(n, seed, spread, method):
    """The forward error bound is a bound: the exact solution on the answer's basis (rational
    arithmetic) is within forward_error |z|_inf, on P-matrix LCPs of condition up to 1e11."""
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    lam = np.logspace(0, -spread, n) if spread else rng.uniform(0.1, 2.0, n)
    K = rng.standard_normal((n, n))
    M = (Q * lam) @ Q.T + 0.1 * (K - K.T)
    q = rng.standard_normal(n)
    sol = lcp.solve(lcp.LCP(M, q), method)
    if sol.status != "solved":
        assert sol.status == "inaccurate"
        assert sol.backward_error > TOL or sol.forward_error > FERR_TOL
        return
    assert sol.backward_error <= TOL and sol.forward_error <= FERR_TOL
    exact = exact_basis_solution(M, q, sol.basis)
    err = np.max(np.abs(sol.z - exact)) / max(np.max(np.abs(sol.z)), 1e-300)
    assert err <= sol.forward_error


def test_polishing_on_the_basis_brings_a_poor_answer_to_rounding_level():
    """A basis answer off by 1e-7 (relative) is refined on its basis to the exact solution."""
    rng = np.random.default_rng(3)
    A = rng.standard_normal((8, 8))
    M = A @ A.T + 1e-4 * np.eye(8)
    q = -M @ rng.uniform(0.5, 1.0, 8)  # a planted positive solution (cond(M) ~ 1e5)
    basis = np.arange(8)
    exact = exact_basis_solution(M, q, basis)
    assert np.all(exact > 0)
    z = exact * (1 + 1e-7 * rng.standard_normal(8))
    acc = assess_lcp(M, q, z, basis)
    assert acc.refined and acc.berr <= 1e-15
    assert np.max(np.abs(acc.v - exact)) <= acc.ferr * np.max(np.abs(exact))
    assert acc.ferr <= 1e-9
    unpolished = assess_lcp(M, q, z, basis, polish=False)  # judged as given
    assert not unpolished.refined
    assert unpolished.ferr >= np.max(np.abs(z - exact)) / np.max(np.abs(z))


@pytest.mark.skipif(not (SICONOS_MLCP / "Buck2_mlcp.dat").exists(),
                    reason="Siconos's data (/work/shared/data/siconos) not present")
def test_buck2_is_answered_with_its_solution_or_not_solved():
    """Issue 23: enumerate-mlcp answered "solved" on Buck2 (equality residual 9e-10) with u
    3.0 away from the only solution; verify.certify accepted it. Every "solved" must now agree
    with newton-min's (independent: semismooth Newton, at 1e-16) within its forward bound."""
    P = lcp.load(SICONOS_MLCP / "Buck2_mlcp.dat")
    ref = lcp.solve(P, "newton-min")
    assert ref.status == "solved" and ref.forward_error <= 1e-12
    raw = lcp.get_method("enumerate-mlcp").native["mlcp"](P)  # the method's own answer
    assert np.max(np.abs(raw.u - ref.u)) > 1.0  # the wrong point
    assert not certify(P, raw, uniqueness="none").accepted
    for name in ("enumerate-mlcp", "newton-fb", "lemke", "pivoting"):
        sol = lcp.solve(P, name)
        if sol.status == "solved":
            x, xr = np.r_[sol.u, sol.v], np.r_[ref.u, ref.v]
            scale = np.max(np.abs(xr))
            assert np.max(np.abs(x - xr)) <= (sol.forward_error + ref.forward_error) * scale
    assert lcp.solve(P, "enumerate-mlcp").status == "inaccurate"


def box_on_plane() -> tuple[np.ndarray, np.ndarray]:
    """A box resting on a plane on 4 corners, each with a normal and two tangent directions
    (12 unknowns): W = J M^-1 J^T has rank 6, q is -1e-2 (gravity dt) on the normals and
    +-1e-10 (velocity noise) on the tangents: many solutions, ties everywhere."""
    a = b = h = 0.5
    Minv = np.zeros((6, 6))
    Minv[:3, :3] = np.eye(3)
    Minv[3:, 3:] = np.diag(1 / np.array([(b * b + h * h) / 3, (a * a + h * h) / 3,
                                         (a * a + b * b) / 3]))
    dirs = np.eye(3)[[2, 0, 1]]
    rows, q = [], []
    for k, (sx, sy) in enumerate([(1, 1), (1, -1), (-1, 1), (-1, -1)]):
        r = np.array([sx * a, sy * b, -h])
        for j, dv in enumerate(dirs):
            rows.append(np.r_[dv, np.cross(r, dv)])
            q.append(-1e-2 if j == 0 else (1e-10 if (k + j) % 2 else -1e-10))
    J = np.array(rows)
    return J @ Minv @ J.T, np.array(q)


def test_lemke_solves_a_degenerate_12_variable_lcp_without_cycling():
    M, q = box_on_plane()
    sols = lcp.enumerate_solutions(lcp.LCP(M, q))
    assert len(sols) >= 2  # not unique
    for eq in (True, False):
        sol = lcp.solve(lcp.LCP(M, q), "lemke", equilibrate=eq)
        assert sol.status == "solved" and "cycling" not in sol.message
        assert certify(lcp.LCP(M, q), sol, uniqueness="none").accepted
    exact = lemke_exact(M, q, np.ones(12), 1000)
    assert exact.status == "solved"
    assert scaled_residual(M, q, exact.z) <= 1e-15


def test_a_cycling_float_run_is_redone_exactly(monkeypatch):
    """When the float run reports a repeated basis, lemke() answers with the exact run."""
    M, q = box_on_plane()
    real_run = lemke_module._Lemke.run

    def cycling(self, max_iter):
        sol = real_run(self, max_iter)
        sol.status, sol.info["cycling"] = "failed", True
        sol.message = "numerical cycling: a basis repeated after 11 pivots"
        return sol

    monkeypatch.setattr(lemke_module._Lemke, "run", cycling)
    monkeypatch.setattr(lemke_module._kernel, "solve_one", lambda *a: None)
    sol = lemke_module.lemke(M, q)
    assert sol.status == "solved" and sol.info["exact"]
    assert "exact rational arithmetic" in sol.message
    assert scaled_residual(M, q, sol.z) <= 1e-15


def farkas_lcp(n: int = 12, amp: int = 3, seed: int = 0):
    """M = N^T N, N integer with N y* = 0 for y*_i = 1/p_i (p_i the primes from 3): M is
    singular PSD with M y* = 0 exactly; q = -1, so q^T y* < 0: y* >= 0 proves by hand that
    {z >= 0 : M z + q >= 0} is empty (y*^T (M z + q) = q^T y* < 0 for every z)."""
    primes = [p for p in range(3, 400) if all(p % k for k in range(2, int(p**0.5) + 1))][:n]
    N = np.zeros((n - 1, n))
    for i in range(1, n):
        N[i - 1, 0], N[i - 1, i] = primes[0], -primes[i]
    rng = np.random.default_rng(seed)
    N = (rng.integers(-amp, amp + 1, (n - 1, n - 1)) + 3 * amp * np.eye(n - 1)) @ N
    y = 1.0 / np.array(primes)
    return N.T @ N, -np.ones(n), y / y.sum()


def test_an_exact_certificate_is_accepted_where_the_radius_test_rejects_it():
    M, q, ystar = farkas_lcp()
    assert np.abs(M).max() < 2**53  # integer data, exact in doubles
    eq = ruiz(M, q)
    # y* rounded to doubles and nudged by 1e-13: M~^T y has entries ~1e-13 > 0, so the
    # radius gap / max(M~^T y)_+ is far below RADIUS: the float test alone rejects it
    y = ystar / eq.r
    y = y * (1 + 1e-13 * np.sin(np.arange(y.size)))
    y /= y.sum()
    g = eq.M.T @ y
    assert g.max() > 0 and (-eq.q @ y) / g.max() < RADIUS
    cert = check_certificate(eq, y)
    assert cert is not None and cert.exact
    # the certificate is y* itself (exact), mapped to the user's units
    np.testing.assert_allclose(cert.y, ystar, rtol=1e-12)
    assert exact_certificate(eq, y) is not None
    for name in ("lemke", "pivoting", "enumerate"):
        sol = lcp.solve(lcp.LCP(M, q), name)
        assert sol.status == "infeasible", (name, sol.message)


def test_the_2x2_singular_psd_lcp_without_solution():
    """M = [[1, -1], [-1, 1]], q = (-1, -1): w_1 + w_2 = -2 for every z, so no feasible point;
    y = (1/2, 1/2) has M^T y = 0 and q^T y = -1."""
    P = lcp.LCP(np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, -1.0]))
    for name in ("lemke", "pivoting", "enumerate", "newton-min", "newton-fb"):
        sol = lcp.solve(P, name)
        assert sol.status != "solved", name
        if sol.status == "infeasible":
            np.testing.assert_allclose(sol.info["farkas"], [0.5, 0.5])
    assert lcp.solve(P, "lemke").status == "infeasible"


def test_exact_check_never_accepts_a_feasible_lcp():
    """A P-matrix LCP has a solution, so no candidate passes the exact check, whatever y."""
    rng = np.random.default_rng(5)
    for _ in range(10):
        n = int(rng.integers(2, 9))
        A = rng.standard_normal((n, n))
        M, q = A @ A.T + 1e-9 * np.eye(n), rng.standard_normal(n)
        eq = ruiz(M, q)
        y = rng.uniform(0, 1, n)
        assert exact_certificate(eq, y / y.sum()) is None
