"""The solvers against each other, against enumeration, and on their documented edge cases."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp.solvers.enumeration import enumerate_solutions
from rigidlcp.verify.strategies import degenerate_lcps, lcps, mlcps, p_matrices, symmetric_psd

SETTINGS = settings(max_examples=40, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])
EXPECTED = {"enumerate", "pivoting", "pgs", "qp-clarabel", "qp-osqp"}


def registered() -> dict[str, lcp.MethodInfo]:
    return {m.name: m for m in lcp.methods()}


def is_symmetric_psd(M: np.ndarray) -> bool:
    scale = max(float(np.max(np.abs(M))), 1e-300)
    if np.max(np.abs(M - M.T)) > 1e-9 * scale:
        return False
    return bool(np.linalg.eigvalsh(0.5 * (M + M.T))[0] >= -1e-9 * scale * M.shape[0])


def close(a: np.ndarray, b: np.ndarray, tol: float = 1e-8) -> bool:
    return bool(np.max(np.abs(a - b)) <= tol * max(1.0, float(np.max(np.abs(b)))))


def murty_example(n: int) -> lcp.LCP:
    """Murty's triangular P-matrix (1 on the diagonal, 2 above it) with q = -1.

    This is the matrix of Murty's exponential examples for pivoting methods (Murty 1978;
    Murty, *Linear Complementarity, Linear and Nonlinear Programming*, 1988, Ch. 6): with a
    bad pivot order they visit exponentially many bases. Its unique solution is z = e_n.
    """
    M = np.eye(n) + 2 * np.triu(np.ones((n, n)), 1)
    return lcp.LCP(M, -np.ones(n))


# -- the registry -------------------------------------------------------------------------


def test_registry_lists_the_methods_with_what_they_accept():
    reg = registered()
    assert EXPECTED <= set(reg)
    assert reg["enumerate"].accepts == "small-n" and reg["enumerate"].max_n == 20
    assert reg["pivoting"].accepts == "any"
    assert reg["qp-clarabel"].accepts == reg["qp-osqp"].accepts == "symmetric-psd"
    assert {"active", "max_iter", "tol"} <= set(reg["pivoting"].options)
    assert {"tol", "max_iter", "z0", "omega"} <= set(reg["pgs"].options)
    assert "select" in reg["enumerate"].options
    assert callable(lcp.methods)  # importing lcp.methods (the module) must not shadow it


# -- P-matrices: one solution, every method finds it ----------------------------------------


@SETTINGS
@given(lcps(p_matrices(st.integers(1, 12))))
def test_p_matrix_lcps_every_applicable_method_agrees_with_enumeration(problem):
    ref = enumerate_solutions(problem)
    assert len(ref) == 1 and not ref[0].info["continuum"], "a P-matrix LCP has one solution"
    z_ref = ref[0].z
    for name, info in registered().items():
        if info.accepts == "symmetric-psd" and not is_symmetric_psd(problem.M) or \
                info.accepts == "friction-2d":
            with pytest.raises(lcp.NotApplicable):
                lcp.solve(problem, name)
            continue
        if name == "pgs":
            continue  # convergence is not guaranteed on every P-matrix: see tests/lcp/test_pgs.py
        sol = lcp.solve(problem, name)
        assert sol.status == "solved", (name, sol)
        assert sol.residual <= 1e-8, (name, sol)
        assert close(sol.z, z_ref), (name, sol.z, z_ref)


@SETTINGS
@given(lcps(p_matrices(st.integers(1, 8))))
def test_pgs_never_claims_a_wrong_solution(problem):
    z_ref = enumerate_solutions(problem)[0].z
    sol = lcp.solve(problem, "pgs", max_iter=300)
    assert sol.status in ("solved", "not_converged", "failed")
    if sol.status == "solved":
        assert sol.residual <= 1e-10 * max(1.0, np.max(np.abs(problem.q)))
        assert close(sol.z, z_ref, 1e-6)
    else:
        assert sol.info["residual"] > 1e-10 * max(1.0, np.max(np.abs(problem.q)))


# -- symmetric PSD, possibly singular: w is unique, z need not be --------------------------


@SETTINGS
@given(st.data())
def test_psd_lcps_pivoting_and_qp_agree_on_w(data):
    n = data.draw(st.integers(1, 40), label="n")
    singular = data.draw(st.booleans(), label="singular")
    M = data.draw(symmetric_psd(n, singular=singular and n > 1))
    problem = data.draw(lcps(st.just(M), planted=True))
    names = ["pivoting", "qp-clarabel", "qp-osqp"] + (["lemke"] if "lemke" in registered()
                                                       else [])
    w_planted = np.array(problem.meta["planted_w"])
    for name in names:
        sol = lcp.solve(problem, name)
        assert sol.status == "solved", (name, sol)
        assert sol.residual <= 1e-8, (name, sol)
        # For symmetric PSD M every solution has the same w (Cottle-Pang-Stone Thm 3.1.7).
        assert close(sol.w, w_planted, 1e-7), (name, np.max(np.abs(sol.w - w_planted)))


# -- degenerate problems --------------------------------------------------------------------


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(degenerate_lcps())
def test_degenerate_lcps_enumeration_and_pivoting_find_solutions(problem):
    z_planted = np.array(problem.meta["planted_z"])
    sols = enumerate_solutions(problem)
    assert sols, "the planted solution exists, enumeration must find one"
    for s in sols:
        assert s.residual <= 1e-8
    # The planted solution is one of them, or lies on a continuum that enumeration reports.
    hit = any(close(s.z, z_planted, 1e-7) for s in sols)
    assert hit or any(s.info["continuum"] for s in sols)
    # Duplicated P or PSD matrices are sufficient: the criss-cross safeguard must finish.
    sol = lcp.solve(problem, "pivoting")
    assert sol.status == "solved" and sol.residual <= 1e-8, sol


# -- enumeration ----------------------------------------------------------------------------


def test_enumeration_finds_all_isolated_solutions():
    sols = enumerate_solutions(np.array([[1.0, 2.0], [2.0, 1.0]]), np.array([-1.0, -1.0]))
    got = sorted(tuple(np.round(s.z, 12)) for s in sols)
    assert got == sorted([(0.0, 1.0), (1.0, 0.0), (round(1 / 3, 12), round(1 / 3, 12))])
    assert not any(s.info["continuum"] for s in sols)


def test_enumeration_finds_solutions_that_only_singular_bases_hold():
    # Solutions z = (1 + s, s) and (t, 0), t >= 1; every nonsingular basis fails.
    M, q = np.array([[0.0, 0.0], [1.0, -1.0]]), np.array([0.0, -1.0])
    sols = enumerate_solutions(M, q)
    assert len(sols) >= 1
    for s in sols:
        assert s.info["singular"] and s.info["continuum"]
        assert s.residual <= 1e-12


def test_enumeration_flags_a_continuum_on_a_singular_psd_problem():
    sols = enumerate_solutions(lcp.LCP(np.ones((2, 2)), -np.ones(2)))
    assert any(s.info["continuum"] for s in sols)
    for s in sols:
        assert abs(s.z.sum() - 1) < 1e-12


def test_enumerate_reports_infeasible_with_evidence():
    sol = lcp.solve(lcp.LCP([[1.0, -1.0], [-1.0, 1.0]], [-1.0, -1.0]), "enumerate")
    assert sol.status == "infeasible" and sol.info["bases_checked"] == 4
    assert "no solution" in sol.message


def test_enumerate_select_min_norm_counts_solutions():
    problem = lcp.LCP([[1.0, 2.0], [2.0, 1.0]], [-1.0, -1.0])
    sol = lcp.solve(problem, "enumerate", select="min-norm")
    assert sol.info["solutions"] == 3
    assert close(sol.z, np.array([1 / 3, 1 / 3]))
    with pytest.raises(lcp.InvalidProblem, match="select"):
        lcp.solve(problem, "enumerate", select="best")


def test_enumerate_refuses_large_n():
    with pytest.raises(lcp.NotApplicable, match="n <= 20"):
        lcp.solve(lcp.LCP(np.eye(21), -np.ones(21)), "enumerate")


def test_enumeration_handles_q_zero_as_one_degenerate_solution():
    sols = enumerate_solutions(np.eye(6) + 0.1, np.zeros(6))
    assert len(sols) == 1 and np.all(sols[0].z == 0)
    assert sols[0].info["n_bases"] == 2**6  # every basis gives z = 0


# -- pivoting -------------------------------------------------------------------------------


@pytest.mark.parametrize("n", [1, 2, 5, 10])
def test_pivoting_solves_murty_example(n):
    problem = murty_example(n)
    expected = np.zeros(n)
    expected[-1] = 1.0
    sol = lcp.solve(problem, "pivoting")
    assert sol.status == "solved" and sol.residual <= 1e-12
    assert close(sol.z, expected)
    assert close(enumerate_solutions(problem)[0].z, expected)


def test_pivoting_with_single_pivots_solves_murty_example():
    # block_tries=0: a block step only when the count of failures drops, else least index.
    sol = lcp.solve(murty_example(10), "pivoting", block_tries=0, active=[])
    assert sol.status == "solved" and sol.residual <= 1e-12 and sol.info["single_pivots"] > 0


@SETTINGS
@given(lcps(p_matrices(st.integers(1, 10))))
def test_pivoting_warm_start_from_the_answer_takes_no_pivot(problem):
    first = lcp.solve(problem, "pivoting")
    again = lcp.solve(problem, "pivoting", active=first.basis)
    assert again.status == "solved" and again.iterations == 0
    mask = np.zeros(problem.n, dtype=bool)
    mask[first.basis] = True
    assert lcp.solve(problem, "pivoting", active=mask).iterations == 0


def test_pivoting_proves_infeasibility_with_a_tableau_row():
    sol = lcp.solve(lcp.LCP([[1.0, -1.0], [-1.0, 1.0]], [-1.0, -1.0]), "pivoting")
    assert sol.status == "infeasible"
    cert = sol.info["certificate"]
    assert cert["qbar_r"] < 0 and cert["max_coefficient"] <= 0


def test_pivoting_reports_max_iter_and_cycles():
    sol = lcp.solve(murty_example(6), "pivoting", max_iter=0, repair=False)  # its own status
    assert sol.status == "max_iter" and sol.info["infeasible_indices"]
    # Not sufficient (negative diagonal): the criss-cross guarantee is void, it must say so.
    sol = lcp.solve(lcp.LCP([[0.0, 0.0], [1.0, -1.0]], [0.0, -1.0]), "pivoting")
    assert sol.status in ("failed", "max_iter")


@pytest.mark.parametrize("bad", [[5], [-1], [0.5], np.ones(3, dtype=bool)])
def test_pivoting_rejects_bad_warm_starts(bad):
    with pytest.raises(lcp.InvalidProblem, match="active"):
        lcp.solve(lcp.LCP(np.eye(2), [-1.0, 1.0]), "pivoting", active=bad)


def test_pivoting_falls_back_from_a_singular_warm_start():
    problem = lcp.LCP(np.ones((2, 2)), [-1.0, -1.0])
    sol = lcp.solve(problem, "pivoting", active=[0, 1])
    assert sol.status == "solved" and sol.info["warm_start_rejected"] == [0, 1]


# -- pgs ------------------------------------------------------------------------------------


def test_pgs_refuses_a_nonpositive_diagonal():
    with pytest.raises(lcp.NotApplicable, match="diagonal"):
        lcp.solve(lcp.LCP([[0.0, 1.0], [1.0, 1.0]], [-1.0, 1.0]), "pgs")


def test_pgs_reports_not_converged_with_its_residual():
    problem = lcp.LCP([[1.0, 0.9], [0.9, 1.0]], [-1.0, -1.0])
    sol = lcp.solve(problem, "pgs", max_iter=2)
    assert sol.status == "not_converged" and sol.iterations == 2
    assert sol.info["residual"] > 1e-10 and "residual" in sol.message
    assert lcp.solve(problem, "pgs", omega=1.5, z0=sol.z).status == "solved"


@pytest.mark.parametrize("opts", [{"omega": 2.0}, {"omega": 0.0}, {"tol": -1.0},
                                  {"max_iter": -1}, {"z0": [1.0]}])
def test_pgs_rejects_bad_options(opts):
    with pytest.raises(lcp.InvalidProblem):
        lcp.solve(lcp.LCP(np.eye(2), [-1.0, 1.0]), "pgs", **opts)


# -- QP methods -----------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["qp-clarabel", "qp-osqp"])
def test_qp_refuses_non_symmetric_and_indefinite(name):
    with pytest.raises(lcp.NotApplicable, match="not symmetric"):
        lcp.solve(lcp.LCP([[1.0, 2.0], [0.0, 1.0]], [-1.0, 1.0]), name)
    with pytest.raises(lcp.NotApplicable, match="not positive semidefinite"):
        lcp.solve(lcp.LCP([[1.0, 0.0], [0.0, -1.0]], [-1.0, 1.0]), name)


@pytest.mark.parametrize("name", ["qp-clarabel", "qp-osqp"])
def test_qp_reports_infeasible_psd_lcp_with_a_ray(name):
    M, q = np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, -1.0])
    sol = lcp.solve(lcp.LCP(M, q), name)
    assert sol.status == "infeasible"
    d = np.asarray(sol.info["ray"])
    assert d.min() >= -1e-8 and np.max(np.abs(M @ d)) <= 1e-6 and q @ d < 0


@pytest.mark.parametrize("name", ["qp-clarabel", "qp-osqp"])
def test_qp_polish_reaches_the_residual_and_raw_is_reported(name):
    rng = np.random.default_rng(7)
    A = rng.normal(size=(30, 30))
    problem = lcp.LCP(A @ A.T + 0.1 * np.eye(30), rng.normal(size=30))
    sol = lcp.solve(problem, name)
    assert sol.status == "solved" and sol.residual <= 1e-10
    assert "raw_residual" in sol.info
    raw = lcp.solve(problem, name, polish=False)
    assert raw.residual == pytest.approx(raw.info["raw_residual"])


# -- MLCP: the Schur reduction ----------------------------------------------------------------


def assembled_lcp(p: lcp.MLCP) -> lcp.LCP:
    """The MLCP as one LCP, with u = u_plus - u_minus and the equality as two inequalities."""
    A, C, D, B = p.A, p.C, p.D, p.B
    M = np.block([[A, -A, C], [-A, A, -C], [D, -D, B]])
    return lcp.LCP(M, np.concatenate([p.a, -p.a, p.b]))


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mlcps(st.integers(1, 2), st.integers(1, 4)))
def test_mlcp_schur_reduction_agrees_with_the_assembled_lcp(problem):
    nu = problem.nu
    # Reduced by hand ...
    M = problem.B - problem.D @ np.linalg.solve(problem.A, problem.C)
    q = problem.b - problem.D @ np.linalg.solve(problem.A, problem.a)
    by_hand = enumerate_solutions(M, q)
    assert len(by_hand) == 1
    # ... and the whole MLCP as one (degenerate) LCP in (u+, u-, v).
    big = enumerate_solutions(assembled_lcp(problem))
    assert big
    for name in ("pivoting", "enumerate"):
        sol = lcp.solve(problem, name)
        assert sol.status == "solved" and sol.residual <= 1e-8 and sol.eq_residual <= 1e-8
        assert close(sol.v, by_hand[0].z)
        for s in big:
            u = s.z[:nu] - s.z[nu:2 * nu]
            assert close(sol.v, s.z[2 * nu:], 1e-7) and close(sol.u, u, 1e-7)


def test_mlcp_with_singular_a_is_solved_on_the_full_system_not_refused():
    # Issue 12: a singular A is no reason to refuse. Here u1 + u2 + v = 0 (twice) and
    # w = u1 + u2 + v - 1 = -1 < 0 for every u, v: no solution, never "solved".
    singular = lcp.MLCP(np.array([[1.0, 1.0], [1.0, 1.0]]), np.ones((2, 1)), np.ones((1, 2)),
                        np.eye(1), np.zeros(2), -np.ones(1))
    for name in ("pivoting", "lemke", "newton-min", "newton-fb", "enumerate-mlcp"):
        assert lcp.solve(singular, name).status != "solved", name
    # A zero mass: u1 + v = 0, 0 u2 + v = 0, w = u1 + u2 + v - 1: v = 0, u1 = 0, u2 >= 1.
    zero_mass = lcp.MLCP(np.diag([1.0, 0.0]), np.ones((2, 1)), np.ones((1, 2)), np.eye(1),
                         np.zeros(2), -np.ones(1))
    # (Lemke on the split LCP ends on a ray here: that M is not copositive-plus.)
    for name in ("enumerate", "newton-min", "newton-fb", "enumerate-mlcp"):
        sol = lcp.solve(zero_mass, name)
        assert sol.status == "solved", (name, sol)
        assert sol.eq_residual <= 1e-12 and sol.residual <= 1e-12, name
        assert abs(sol.v[0]) <= 1e-12 and abs(sol.u[0]) <= 1e-12 and sol.u[1] >= 1 - 1e-12
