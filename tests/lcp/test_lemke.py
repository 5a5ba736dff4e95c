"""Tests of lcp.lemke: an exact (fractions) lexicographic reference on small degenerate problems,
random P-matrix and PSD LCPs, Murty's exponential example, ray and infeasibility certificates,
and input validation."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp.solvers.lemke import lemke

# --------------------------------------------------------------------------------------------
# Exact reference: Lemke's method with the lexicographic ratio test, in rational arithmetic.
# --------------------------------------------------------------------------------------------


def reference_lemke(M, q, d=None, max_pivots: int = 100_000) -> dict:
    """Lexicographic Lemke (Cottle-Pang-Stone Alg. 4.4.5 + Sec. 4.9) on the full tableau
    [I | -M | -d | q] in fractions.Fraction, written independently of lcp.lemke.

    Variables: w_i = i, z_i = n + i, z0 = 2n. Rules (the ones lcp.lemke documents): the first
    leaving row is the lexicographic minimum of (q_i, e_i) / d_i; afterwards the complement of
    the leaving variable enters, the blocking rows are those with a positive entry alpha_i in
    its column, and the leaving row minimizes (beta_i, B^-1[i, :]) / alpha_i lexicographically,
    except that z0 leaves whenever its ratio is among the minimal ones. A ray whose z0 is 0 is
    a solution.
    """
    n = len(q)
    F = Fraction
    M = [[F(x) for x in row] for row in np.asarray(M).tolist()]
    q = [F(x) for x in np.asarray(q).tolist()]
    d = [F(1)] * n if d is None else [F(x) for x in np.asarray(d).tolist()]
    if all(qi >= 0 for qi in q):
        return {"status": "solved", "z": [F(0)] * n, "basis": [], "pivots": 0}
    Z0 = 2 * n
    tab = [
        [F(int(i == j)) for j in range(n)] + [-M[i][j] for j in range(n)] + [-d[i], q[i]]
        for i in range(n)
    ]
    basic = list(range(n))

    def key(i: int, alpha: Fraction) -> list:
        return [x / alpha for x in [tab[i][-1]] + tab[i][:n]]

    def pivot(r: int, c: int) -> int:
        p = tab[r][c]
        tab[r] = [x / p for x in tab[r]]
        for i in range(n):
            if i != r and tab[i][c] != 0:
                f = tab[i][c]
                tab[i] = [x - f * y for x, y in zip(tab[i], tab[r], strict=True)]
        left, basic[r] = basic[r], c
        return left

    r = min(range(n), key=lambda i: key(i, d[i]))
    leaving = pivot(r, Z0)
    pivots = 1
    while leaving != Z0:
        if pivots >= max_pivots:
            return {"status": "max_iter", "pivots": pivots}
        entering = leaving + n if leaving < n else leaving - n
        rows = [i for i in range(n) if tab[i][entering] > 0]
        if not rows:
            z0_row = basic.index(Z0)
            if tab[z0_row][-1] == 0:
                break
            name = f"w[{entering}]" if entering < n else f"z[{entering - n}]"
            return {"status": "ray", "entering": name, "pivots": pivots}
        ratios = {i: tab[i][-1] / tab[i][entering] for i in rows}
        tmin = min(ratios.values())
        tied = [i for i in rows if ratios[i] == tmin]
        if Z0 in [basic[i] for i in tied]:
            r = basic.index(Z0)
        else:
            r = min(tied, key=lambda i: key(i, tab[i][entering]))
        leaving = pivot(r, entering)
        pivots += 1
    z = [F(0)] * n
    for i, v in enumerate(basic):
        if n <= v < 2 * n:
            z[v - n] = tab[i][-1]
    return {"status": "solved", "z": z, "pivots": pivots,
            "basis": sorted(v - n for v in basic if n <= v < 2 * n)}


def assert_matches_reference(M, q, d=None) -> None:
    ref = reference_lemke(M, q, d)
    sol = lemke(np.asarray(M, float), np.asarray(q, float), d=d)
    ref_status = {"ray": {"ray", "infeasible"}}.get(ref["status"], {ref["status"]})
    assert sol.status in ref_status, (sol.status, ref["status"], sol.message)
    assert sol.iterations == ref["pivots"]
    if ref["status"] == "solved":
        assert sol.basis.tolist() == ref["basis"]
        np.testing.assert_allclose(sol.z, [float(x) for x in ref["z"]], rtol=1e-9, atol=1e-9)
    elif ref["status"] == "ray":
        assert sol.info["entering"] == ref["entering"]


# --------------------------------------------------------------------------------------------
# Problem generators
# --------------------------------------------------------------------------------------------

small_ints = st.integers(-3, 3)


@st.composite
def degenerate_integer_lcps(draw, max_n: int = 5):
    """Small integer LCPs made degenerate: zeros in q, duplicated rows and/or columns."""
    n = draw(st.integers(1, max_n))
    M = np.array(draw(st.lists(small_ints, min_size=n * n, max_size=n * n))).reshape(n, n)
    q = np.array(draw(st.lists(small_ints, min_size=n, max_size=n)))
    zeros = draw(st.lists(st.booleans(), min_size=n, max_size=n))
    q[np.array(zeros)] = 0
    if n >= 2 and draw(st.booleans()):
        i, j = draw(st.permutations(range(n)))[:2]
        if draw(st.booleans()):
            M[j, :], q[j] = M[i, :], q[i]
        if draw(st.booleans()):
            M[:, j] = M[:, i]
    return M, q


def friction_lcp(W: np.ndarray, mu: np.ndarray, qn: np.ndarray, qt: np.ndarray):
    """The LCP of docs/mechanics.md's non-sliding contacts (tau = mu R + S, a_+ = a_t + a_-):

        a_n       = (W_nn - mu W_nt) R + W_nt tau + q_n            0 <= R    perp a_n
        a_+       = (W_tn - mu W_tt) R + W_tt tau + a_- + q_t      0 <= tau  perp a_+
        2 mu R - tau                                               0 <= a_-  perp (.)

    degenerate by construction: the last block of q is zero.
    """
    c = mu.size
    Wnn, Wnt, Wtn, Wtt = W[:c, :c], W[:c, c:], W[c:, :c], W[c:, c:]
    Mu, I, Z = np.diag(mu), np.eye(c), np.zeros((c, c))
    M = np.block([
        [Wnn - Wnt @ Mu, Wnt, Z],
        [Wtn - Wtt @ Mu, Wtt, I],
        [2 * Mu, -I, Z],
    ])
    return M, np.concatenate([qn, qt, np.zeros(c)])


def random_p_matrix(rng: np.random.Generator, n: int, kind: int) -> np.ndarray:
    if kind == 0:  # positive definite, non-symmetric: A A^T + skew + 0.1 I
        A, K = rng.standard_normal((n, n)), rng.standard_normal((n, n))
        return A @ A.T + (K - K.T) + 0.1 * np.eye(n)
    if kind == 1:  # triangular with positive diagonal, permuted: P but not PD in general
        L = np.tril(rng.uniform(-3, 3, (n, n)), -1) + np.diag(rng.uniform(0.5, 2, n))
        p = rng.permutation(n)
        return L[np.ix_(p, p)]
    # strictly row diagonally dominant with positive diagonal
    B = rng.uniform(-1, 1, (n, n))
    np.fill_diagonal(B, 0)
    return B + np.diag(np.abs(B).sum(axis=1) + rng.uniform(0.1, 1, n))


def murty_matrix(n: int) -> np.ndarray:
    """Murty (1978): lower triangular, 1 on the diagonal and 2 below it (a P-matrix)."""
    return np.tril(2 * np.ones((n, n)), -1) + np.eye(n)


def murty_q(n: int) -> np.ndarray:
    """Murty's q^(n): q_i = -(2^n + 2^(n-1) + ... + 2^(n-i+1)), i = 1..n (his Sec. 6.2)."""
    return -np.cumsum([2.0 ** (n - k) for k in range(n)])


# --------------------------------------------------------------------------------------------
# Tests
# --------------------------------------------------------------------------------------------


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(degenerate_integer_lcps())
def test_matches_exact_reference_on_degenerate_problems(problem):
    M, q = problem
    assert_matches_reference(M, q)


@settings(max_examples=100, deadline=None)
@given(degenerate_integer_lcps(max_n=4), st.lists(st.integers(1, 4), min_size=4, max_size=4))
def test_matches_exact_reference_with_covering_vector(problem, d):
    M, q = problem
    assert_matches_reference(M, q, d=np.array(d[: q.size], float))


@settings(max_examples=80, deadline=None)
@given(st.integers(1, 4), st.integers(0, 2**32 - 1), st.booleans())
def test_friction_lcp_matches_exact_reference(c, seed, symmetric):
    """Friction LCPs with small rational data: the zero block of q ties the ratio test, and
    with `symmetric` (equal q_n, q_t = 0, as in a regular array under gravity) so does q_n."""
    rng = np.random.default_rng(seed)
    J = rng.integers(-2, 3, (2 * c, 2 * c))
    W = J @ J.T + np.eye(2 * c)
    mu = rng.integers(1, 4, c) / 4
    qn, qt = rng.integers(-3, 2, c), rng.integers(-2, 3, c)
    if symmetric:
        qn, qt = -np.ones(c), np.zeros(c)
    M, q = friction_lcp(W, mu, qn, qt)
    assert_matches_reference(M, q)
    sol = lcp.solve(lcp.LCP(M, q), method="lemke")
    if sol.status == "solved":
        assert sol.residual <= 1e-9


@pytest.mark.parametrize("seed", range(5))
def test_highly_degenerate_friction_lcp_is_solved(seed):
    """n = 90: equal q_n and q_t = 0 tie dozens of rows at once (the lexicographic rule runs
    on most pivots); W = H H^T is singular (fewer degrees of freedom than contact forces)."""
    c = 30
    rng = np.random.default_rng(seed)
    H = rng.standard_normal((2 * c, 45))
    M, q = friction_lcp(H @ H.T, rng.uniform(0.1, 0.6, c), -np.ones(c), np.zeros(c))
    sol = lcp.solve(lcp.LCP(M, q), method="lemke")
    assert sol.status == "solved", sol.message
    assert sol.residual <= 1e-9


def test_reference_agrees_on_hand_checked_degenerate_example():
    # q = (-1, -1, 0) ties the first ratio test (rows 0 and 1) and the zero row ties later.
    M = np.array([[1, 2, 0], [2, 1, 0], [0, 0, 1]])
    q = np.array([-1, -1, 0])
    ref = reference_lemke(M, q)
    assert ref["status"] == "solved"
    z = np.array([float(x) for x in ref["z"]])
    w = M @ z + q
    assert np.all(z >= 0) and np.all(w >= -1e-15) and abs(z @ w) < 1e-15
    assert_matches_reference(M, q)


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 12), st.integers(0, 2), st.integers(0, 2**32 - 1))
def test_random_p_matrix_lcps_are_solved(n, kind, seed):
    rng = np.random.default_rng(seed)
    M = random_p_matrix(rng, n, kind)
    q = rng.standard_normal(n)
    sol = lcp.solve(lcp.LCP(M, q), method="lemke")
    assert sol.status == "solved", sol.message
    assert sol.residual <= 1e-8
    off_basis = np.setdiff1d(np.arange(n), sol.basis)
    assert np.all(sol.z[off_basis] == 0)


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 40), st.integers(0, 2**32 - 1), st.floats(0.0, 0.7))
def test_degenerate_psd_lcps_with_a_solution_are_solved(n, seed, frac_zero):
    """Singular PSD M with duplicated rows/columns and a planted degenerate solution
    (z*_i = w*_i = 0 on a fraction of the indices): Lemke must end with a solution."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, max(1, n // 2)))
    dup = rng.integers(0, n, n // 4)
    A[rng.permutation(n)[: dup.size]] = A[dup]  # duplicated rows of A: M = A A^T duplicates both
    M = A @ A.T
    z_star = np.where(rng.random(n) < 0.5, rng.random(n), 0.0)
    w_star = np.where(z_star > 0, 0.0, rng.random(n))
    both_zero = rng.random(n) < frac_zero
    z_star[both_zero] = w_star[both_zero] = 0.0
    q = w_star - M @ z_star
    sol = lcp.solve(lcp.LCP(M, q), method="lemke")
    assert sol.status == "solved", sol.message
    assert sol.residual <= 1e-8 * max(1.0, np.abs(q).max())


@pytest.mark.parametrize("n", range(1, 11))
def test_murty_example_needs_2_to_the_n_pivots(n):
    sol = lcp.solve(lcp.LCP(murty_matrix(n), murty_q(n)), method="lemke", equilibrate=False)
    assert sol.status == "solved"
    assert sol.residual <= 1e-8
    assert sol.iterations == 2**n


def test_murty_example_exact_reference():
    for n in range(1, 6):
        ref = reference_lemke(murty_matrix(n), murty_q(n))
        assert ref["pivots"] == 2**n
        assert_matches_reference(murty_matrix(n), murty_q(n))


def test_murty_least_index_example_is_solved():
    # Murty's principal-pivoting example (q = -e) has the solution z = e_1.
    for n in range(1, 11):
        sol = lcp.solve(lcp.LCP(murty_matrix(n), -np.ones(n)), method="lemke")
        assert sol.status == "solved"
        np.testing.assert_allclose(sol.z, np.eye(n)[0], atol=1e-12)


def test_max_iter_is_reported():
    sol = lemke(murty_matrix(8), murty_q(8), max_iter=10)
    assert sol.status == "max_iter" and sol.iterations == 10
    assert sol.info["z0"] > 0


def test_q_nonnegative_is_solved_without_pivots():
    sol = lemke(np.array([[-1.0, 2.0], [3.0, -4.0]]), np.array([0.0, 1.0]))
    assert sol.status == "solved" and sol.iterations == 0
    assert np.all(sol.z == 0) and sol.basis.size == 0


def test_infeasible_psd_example():
    # z1 - z2 >= 1 and z2 - z1 >= 1 cannot both hold.
    M = np.array([[1.0, -1.0], [-1.0, 1.0]])
    sol = lcp.solve(lcp.LCP(M, [-1.0, -1.0]), method="lemke")
    assert sol.status == "infeasible", sol.message
    y = sol.info["farkas"]
    assert np.all(y >= 0) and np.all(M.T @ y <= 1e-12) and y @ [-1.0, -1.0] < 0
    assert sol.info["copositive_plus"] is True


def assert_exact_solution_near(M: np.ndarray, q: np.ndarray, sol) -> None:
    """The float data (M, q), read as rationals, have an exact solution z* on sol's basis P
    (M_PP z*_P = -q_P, z* >= 0, w* = M z* + q >= 0 off P), and |sol.z - z*|_inf is within the
    forward error bound sol reports (relative to |z*|_inf)."""
    from flint import fmpq, fmpq_mat

    n, P = len(q), [int(i) for i in sol.basis]
    MQ = [[fmpq(*float(v).as_integer_ratio()) for v in row] for row in M]
    qQ = [fmpq(*float(v).as_integer_ratio()) for v in q]
    zQ = [fmpq(0)] * n
    if P:
        A = fmpq_mat(len(P), len(P), [MQ[i][j] for i in P for j in P])
        y = A.solve(fmpq_mat(len(P), 1, [-qQ[i] for i in P]))
        for k, i in enumerate(P):
            zQ[i] = y[k, 0]
    wQ = [sum((MQ[i][j] * zQ[j] for j in range(n)), fmpq(0)) + qQ[i] for i in range(n)]
    assert all(v >= 0 for v in zQ) and all(wQ[i] >= 0 for i in range(n) if i not in P)
    z_star = np.array([float(Fraction(int(v.p), int(v.q))) for v in zQ])  # flint 0.6: no float()
    err = float(np.max(np.abs(sol.z - z_star)))
    assert err <= sol.forward_error * float(np.max(np.abs(z_star))), err


def copositive_plus_infeasible(n: int, seed: int):
    """M = P S P + P K P (S PSD, K skew, P the projector orthogonal to y >= 0) is
    copositive-plus with M^T y = 0; q^T y < 0 then makes {z >= 0: M z + q >= 0} empty."""
    rng = np.random.default_rng(seed)
    y = np.where(rng.random(n) < 0.6, rng.random(n), 0.0)
    y[rng.integers(n)] = 1.0
    P = np.eye(n) - np.outer(y, y) / (y @ y)
    B, K = rng.standard_normal((n, n)), rng.standard_normal((n, n))
    M = P @ (B @ B.T) @ P + P @ (K - K.T) @ P
    q = rng.standard_normal(n)
    q -= (q @ y + rng.uniform(0.1, 2.0)) * y / (y @ y)  # now q^T y < 0
    return M, q


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 30), st.integers(0, 2**32 - 1))
def test_infeasible_copositive_plus_lcps_end_infeasible(n, seed):
    """Lemke's theorem holds in exact arithmetic. In floating point M^T y = 0 only to rounding
    (~1e-17), so the data are infeasible only within |z| ~ gap / 1e-17, and may be solvable
    beyond: "infeasible" is claimed only with a certificate checked in exact rationals; else
    the status stays "ray", or "failed" when Lemke's own (looser) check had claimed it
    (honest). "solved" only where the float data, read exactly, do have a solution (their
    rounding can make M_PP nonsingular: n 2, seed 27723, det 2.1e-22, z ~ 2.8e21, which the
    exact rerun finds): checked in rationals."""
    M, q = copositive_plus_infeasible(n, seed)
    sol = lcp.solve(lcp.LCP(M, q), method="lemke")
    if sol.status == "solved":
        assert_exact_solution_near(M, q, sol)
        return
    assert sol.status in ("infeasible", "ray", "failed"), sol.message
    assert sol.info["copositive_plus"] is True
    if sol.status == "infeasible":
        assert sol.info["farkas_exact"] is True and sol.info["farkas_radius"] == np.inf


def test_copositive_plus_data_that_rounding_made_solvable():
    """n 2, seed 27723 (a deep-profile example): the rounded data have det M = 2.1e-22 > 0 and
    an exact solution z* ~ (2.8e21, 6.1e19) >= 0; "solved" is then right, checked in rationals
    (the float w = M z + q is ~1786 from cancellation against |M| |z| ~ 1e21)."""
    M, q = copositive_plus_infeasible(2, 27723)
    sol = lcp.solve(lcp.LCP(M, q), method="lemke")
    assert sol.status == "solved", sol.message
    assert_exact_solution_near(M, q, sol)


def test_float_certificates_are_evidence_not_infeasibility():
    """These data are infeasible only within |z~|_1 ~ gap / 1e-17 ~ 1e14 .. 1e16 (M^T y = 0
    holds only to rounding), and such data can have a solution just beyond (the bench's old
    float-built "infeasible" set did: tests/lcp/test_trust.py). So none is "infeasible":
    measured, 23 of these 60 have a floating-point certificate of radius >= lcp.farkas.RADIUS,
    kept in info and said in the message, with the status "failed"; none "solved"."""
    sols = [lcp.solve(lcp.LCP(*copositive_plus_infeasible(2 + s % 29, s)), "lemke")
            for s in range(60)]
    assert not [s for s in sols if s.status in ("infeasible", "solved")]
    noted = [s for s in sols if s.info.get("farkas_exact") is False]
    assert len(noted) >= 15
    for s in noted:
        assert s.info["farkas_radius"] >= 0.1 / np.finfo(float).eps
        assert "infeasibility is not proved" in s.message


def test_ray_on_a_solvable_non_copositive_lcp_is_not_infeasible():
    # M is copositive but not copositive-plus (z = e_1: z'Mz = 0, (M + M^T) z != 0), and the
    # LCP is solvable (z = (2, 2), w = 0), yet Lemke ends on a secondary ray.
    M = np.array([[0.0, 1.0], [1.0, 0.0]])
    q = np.array([-2.0, -2.0])
    assert np.all(M @ [2.0, 2.0] + q == 0)
    sol = lcp.solve(lcp.LCP(M, q), method="lemke")
    assert sol.status == "ray", sol.message
    assert sol.info["copositive_plus"] is False
    ray = sol.info["ray"]
    assert ray.shape == (3,) and np.all(ray >= 0) and np.abs(ray).max() == 1
    assert sol.info["entering"] == reference_lemke(M, q)["entering"] == "z[1]"


def test_ray_certificate_on_non_copositive_infeasible_lcp():
    # Murty's Example 2.9: ray termination, and the LCP has no solution; the ray's z-part is
    # a valid Farkas certificate although M is not copositive-plus.
    M = -np.array([[1.0, 0.0, 3.0], [-1.0, 2.0, 5.0], [2.0, 1.0, 2.0]])
    q = np.array([-3.0, -2.0, -1.0])
    sol = lcp.solve(lcp.LCP(M, q), method="lemke")
    assert sol.status == "infeasible", sol.message
    assert sol.info["copositive_plus"] is False
    y = sol.info["farkas"]
    assert np.all(y >= 0) and np.all(M.T @ y <= 1e-12) and q @ y < 0


@pytest.mark.parametrize(
    "d",
    [np.zeros(3), -np.ones(3), np.array([1.0, 0.0, 1.0]), np.ones(2), np.ones(4),
     np.array([1.0, np.nan, 1.0]), np.array([1.0, np.inf, 1.0]), "abc"],
)
def test_bad_covering_vector_raises(d):
    with pytest.raises(lcp.InvalidProblem, match="d"):
        lemke(np.eye(3), -np.ones(3), d=d)


@pytest.mark.parametrize("opts", [{"tol": 0.0}, {"tol": -1.0}, {"tol": 2.0}, {"tol": "x"},
                                  {"max_iter": 0}, {"max_iter": 2.5}, {"max_iter": True}])
def test_bad_options_raise(opts):
    with pytest.raises(lcp.InvalidProblem):
        lemke(np.eye(3), -np.ones(3), **opts)


def test_covering_vector_through_solve():
    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    q = np.array([-1.0, -1.0])
    sol = lcp.solve(lcp.LCP(M, q), method="lemke", d=[1.0, 3.0])
    assert sol.status == "solved" and sol.residual <= 1e-12
    np.testing.assert_allclose(sol.z, [1 / 3, 1 / 3])


def test_lemke_is_registered():
    info = lcp.get_method("lemke")
    assert info.accepts == "any"
    assert set(info.options) == {"d", "max_iter", "tol"}


def test_numerical_cycling_is_detected_and_restarted(monkeypatch):
    """A basis that repeats proves rounding defeated the lexicographic rule: Lemke says so and
    restarts with coarser ties. Forced here: the first attempt reports a cycle."""
    import rigidlcp.lcp.solvers.lemke as lemke_module

    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    q = np.array([-1.0, -1.0])
    calls = {"n": 0}
    original = lemke_module._Lemke.run

    def run_cycling_once(self, max_iter):
        calls["n"] += 1
        if calls["n"] == 1:  # the first attempt reports a cycle, as a repeated basis would
            sol = self.stopped(3)
            sol.info["cycling"] = True
            sol.message = "numerical cycling: a basis repeated after 3 pivots"
            return sol
        return original(self, max_iter)

    monkeypatch.setattr(lemke_module._Lemke, "run", run_cycling_once)
    monkeypatch.setattr(lemke_module._kernel, "_use", False)  # no whole-run fast path
    # n <= EXACT_MAX_N: the rerun is exact (lcp/solvers/lemke_exact.py; issue 23)
    sol = lcp.solve(lcp.LCP(M, q), "lemke")
    assert sol.success and calls["n"] == 1 and sol.info["exact"]
    assert "exact rational arithmetic" in sol.message
    np.testing.assert_allclose(sol.z, [1 / 3, 1 / 3], rtol=1e-15)
    # EXACT_MAX_N < n <= EXACT_TIES_MAX_N: the float run again, its ambiguous ties exact
    calls["n"] = 0
    monkeypatch.setattr(lemke_module, "EXACT_MAX_N", 1)
    sol = lcp.solve(lcp.LCP(M, q), "lemke")
    assert sol.success and calls["n"] == 2 and "exact_ties" in sol.info
    assert "ambiguous ratio ties decided in exact" in sol.message
    # larger problems restart with coarser ties
    calls["n"] = 0
    monkeypatch.setattr(lemke_module, "EXACT_TIES_MAX_N", 1)
    sol = lcp.solve(lcp.LCP(M, q), "lemke")
    assert sol.success and calls["n"] == 2
    assert sol.info["tol_used"] == pytest.approx(1e-8) and "restarted" in sol.message


def test_real_event_that_cycles_at_a_fine_tolerance():
    """Event 252 of `rigidlcp simulate --lx 20 --ly 10 --gamma 0.16 --seed 1` (n = 720), raw
    data: at tol = 1e-12 rounding defeats the lexicographic rule and a basis repeats (before
    the check, Lemke ran to its pivot limit); the restart with ties at 1e-10 solves it, as
    does the default tolerance directly."""
    from pathlib import Path

    P = lcp.load(Path(__file__).parent.parent / "data" / "event_rect20x10_cycling.npz")
    sol = lcp.solve(P, "lemke", equilibrate=False, tol=1e-12)  # the raw data, where rounding bites
    assert sol.success and sol.residual < 1e-9
    assert "numerical cycling" in sol.message and "restarted" in sol.message
    assert sol.info.get("tol_used") == pytest.approx(1e-10)
    assert lcp.solve(P, "lemke", equilibrate=False).success
    assert lcp.solve(P, "lemke").success  # equilibrated (the default)
