"""Projected Gauss-Seidel (lcp.pgs) against the rates its convergence theorems give.

PGS converges linearly, at a rate set by the matrix; a fixed sweep budget and tolerance is
therefore not a theorem (a symmetric positive definite M = 12 * 11' + 0.1 I of condition 1441,
which `symmetric_psd(12)` can draw, needs ~20,000 sweeps for a residual of 1e-13). Each test
below computes, for the drawn matrix, the bound a theorem gives after k sweeps from z0 = 0 and
checks the iterate against it and against the enumeration's answer z*, at checkpoints k; the
only slack is the rounding of the quantities compared (stated where it is used).
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp.solvers.enumeration import enumerate_solutions
from rigidlcp.verify.strategies import lcps, p_matrices, symmetric_psd

SETTINGS = settings(max_examples=40, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])
EPS = np.finfo(float).eps
CHECKPOINTS = (1, 2, 3, 5, 10, 30, 100, 300, 1000, 3000, 10_000, 20_000)


def sweeps(problem: lcp.LCP, z: np.ndarray, k: int) -> np.ndarray:
    """k more PGS sweeps from z (the raw iteration: no early stop short of an exact zero
    residual, no equilibration, no repair)."""
    if k == 0:
        return z
    sol = lcp.solve(problem, "pgs", tol=1e-300, max_iter=k, z0=z, repair=False)
    assert sol.status in ("solved", "not_converged"), sol
    return sol.z


def reference(problem: lcp.LCP) -> tuple[np.ndarray, np.ndarray]:
    ref = enumerate_solutions(problem)
    assert len(ref) == 1, "a P-matrix LCP has one solution"
    z_star = ref[0].z
    return z_star, problem.M @ z_star + problem.q


@SETTINGS
@given(lcps(p_matrices(st.integers(1, 12), kind="diagonally-dominant")))
def test_pgs_contracts_in_the_max_norm_on_diagonally_dominant_matrices(problem):
    """M strictly diagonally dominant by rows: ||z_k - z*||_inf <= rho^k ||z*||_inf, with
    rho = max_i sum_{j != i} |M_ij| / M_ii < 1 (z0 = 0).

    Proof: z*_i = max(0, -(sum_{j != i} M_ij z*_j + q_i) / M_ii) (the fixed point), and a sweep
    sets z+_i by the same formula with z+_j (j < i) and z_j (j > i); max(0, .) is 1-Lipschitz,
    so by induction over i, |z+_i - z*_i| <= rho ||z - z*||_inf (Cottle, Pang & Stone 1992,
    Sec. 5.2, for the unprojected Gauss-Seidel argument).

    Then the residual is bounded too: |min(z_i, w_i) - min(z*_i, w*_i)| <= max(1, ||M||_inf)
    ||z - z*||_inf, so `pgs` must stop "solved" within the sweep count at which the bound, plus
    the rounding of w, is below its target: asserted whenever that count exists.

    Rounding: the floating-point iteration is the exact one plus a perturbation of each
    update of at most ~ n eps (|M| |z| + |q|)_i / M_ii, which the contraction sums to at most
    that over (1 - rho); the enumeration's z* carries ~ the same (its basis matrix is
    diagonally dominant with inverse norm <= 1 / min margin). `slack` is 4 times that sum.
    """
    M, q = problem.M, problem.q
    n = q.size
    d = np.diagonal(M)
    rho = float(np.max((np.sum(np.abs(M), axis=1) - d) / d))
    assert rho < 1.0
    z_star, _ = reference(problem)
    size = float(np.max(np.abs(z_star)))
    terms = np.abs(M) @ np.abs(z_star) + np.abs(q)
    slack = 4 * (n + 1) * EPS * float(np.max(terms / d)) / (1.0 - rho)
    z, k = np.zeros(n), 0
    for K in CHECKPOINTS:
        z, k = sweeps(problem, z, K - k), K
        err = float(np.max(np.abs(z - z_star)))
        assert err <= rho ** k * size + slack, (k, err, rho ** k * size, slack)
        if rho ** k * size <= slack:
            break
    # The sweep count that guarantees "solved" at the default tolerance.
    norm = max(1.0, float(np.max(np.sum(np.abs(M), axis=1))))
    w_round = 2 * (n + 1) * EPS * float(np.max(terms))
    target = 1e-10 * max(1.0, float(np.max(np.abs(q))))
    room = (target - w_round) / norm - slack
    if room <= 0:
        event("rounding leaves no room below the default tolerance")
        return
    K = 1 if rho == 0 or size <= room else math.ceil(math.log(room / size) / math.log(rho))
    event(f"guaranteed within {10 ** math.ceil(math.log10(max(K, 1)))} sweeps")
    sol = lcp.solve(problem, "pgs", max_iter=K, repair=False)
    assert sol.status == "solved", (K, sol)
    assert float(np.max(np.abs(sol.z - z_star))) <= rho ** sol.iterations * size + slack


def energy_gap(M: np.ndarray, z: np.ndarray, z_star: np.ndarray, w_star: np.ndarray) -> float:
    """f(z) - f(z*) for f(z) = z'Mz / 2 + q'z, without cancellation: since z*'w* = 0,
    f(z) - f(z*) = (z - z*)'M(z - z*) / 2 + w*'z."""
    e = z - z_star
    return 0.5 * float(e @ M @ e) + float(w_star @ z)


@SETTINGS
@given(lcps(symmetric_psd(st.integers(1, 12))))
def test_pgs_energy_gap_contracts_on_symmetric_positive_definite_matrices(problem):
    """M symmetric positive definite (eigenvalues >= c >= 0.1 by construction): PGS is cyclic
    coordinate minimization of f(z) = z'Mz / 2 + q'z over z >= 0 (Cryer 1971), so f never
    increases, and the gap to the minimum contracts every sweep:

        f(z_{k+1}) - f* <= C / (1 + C) (f(z_k) - f*),   C = ||M^{-1/2} U D^{-1/2}||_2^2,

    U the strict upper triangle and D the diagonal of M. Proof (delta = z+ - z, M = L + D + U):
    (i) the coordinate steps lower f by at least sum_i M_ii delta_i^2 / 2 (an exact minimization
    of a 1-D quadratic over a half-line moves at least that far from its start);
    (ii) step i's optimality with g = M z + q reads, for every t >= 0,
    (g(z+) - U delta)'(t - z+) >= 0; with t = z*, and f quadratic,
    f(z+) - f* = g(z+)'e - e'Me / 2 <= (U delta)'e - e'Me / 2 <= (U delta)'M^{-1}(U delta) / 2
    <= C (f(z) - f(z+)), e = z+ - z*; rearranged, the bound above.

    And e'Me / 2 <= f(z) - f* (the energy gap formula, w* >= 0, z >= 0): the iterate approaches
    the enumeration's z* in the M-norm at that rate. For the matrix above C = 1749: the bound
    after 20,000 sweeps is exp(-11.4) times the initial gap, which the iteration beats (the
    theorem is a bound, not the rate). Checked at the checkpoints, each time with `slack`,
    10 n eps times the size of the energy's terms at z* (the rounding of the gap's evaluation).
    """
    M, q = problem.M, problem.q
    n = q.size
    z_star, w_star = reference(problem)
    Lc = np.linalg.cholesky(M)
    d = np.diagonal(M)
    C = float(np.linalg.norm(np.linalg.solve(Lc, np.triu(M, 1) / np.sqrt(d)), 2) ** 2)
    rate = C / (1.0 + C)
    slack = 10 * n * EPS * float(np.abs(z_star) @ np.abs(M) @ np.abs(z_star)
                                 + np.abs(q) @ np.abs(z_star))
    z, k = np.zeros(n), 0
    gap = gap0 = energy_gap(M, z, z_star, w_star)
    for K in CHECKPOINTS:
        z, k = sweeps(problem, z, K - k), K
        previous, gap = gap, energy_gap(M, z, z_star, w_star)
        bound = rate ** k * gap0
        assert gap <= previous + slack, ("f increased", k, gap, previous)
        assert gap <= bound + slack, ("gap above the theorem's bound", k, gap, bound, C)
        e = z - z_star
        assert 0.5 * float(e @ M @ e) <= bound + slack, ("z_k far from z*", k, C)
        if gap <= slack:
            break
    event(f"C = {10 ** math.ceil(math.log10(max(C, 1.0)))}")
