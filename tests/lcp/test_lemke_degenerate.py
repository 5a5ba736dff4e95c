"""Lemke on degenerate integer LCPs (many exact ratio ties) never cycles, and every answer is
checked against an exact enumeration of the complementary patterns (issue 23, point 3).

Integer data (entries in -3..3, q with many zeros: the hard classes' integer-tie kind) make
ratio ties exact and frequent, so the lexicographic rule decides most pivots. The float run
with its ambiguous ties decided in rationals (lcp.lemke_exact.ExactTies) must take the exact
path: the same outcome, pivots and final basis as Lemke in exact rational arithmetic
(lcp.lemke_exact.lemke_exact), which cannot cycle (Cottle-Pang-Stone Thm 4.9.4). And
`lcp.solve`'s lemke answers, on the same problems: "solved" only with a point that
verify.certify accepts and that is the exact solution of one of the complementary patterns the
enumeration finds; "infeasible" only when the enumeration finds no solution; on a
copositive-plus M (M + M^T PSD: Lemke's theorem) a solution exactly when the enumeration finds
one, else "infeasible"; never a repeated basis or a pivot limit.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp.acceptance.farkas import numerically_psd
from rigidlcp.lcp.solvers import lemke as lemke_module
from rigidlcp.lcp.solvers.lemke import _Lemke
from rigidlcp.lcp.solvers.lemke_exact import EXACT_MAX_N, EXACT_TIES_MAX_N, ExactTies, lemke_exact
from rigidlcp.verify import certify

from .test_accuracy import box_on_plane


def integer_lcp(n: int, seed: int, zeros: float, copositive_plus: bool):
    """Integer M and q with many ties: entries in -3..3 (positive diagonal in 0..3), a share
    `zeros` of q set to 0; copositive_plus: M = B B^T + S - S^T with integer B and S (then
    M + M^T = 2 B B^T is PSD)."""
    rng = np.random.default_rng(seed)
    if copositive_plus:
        B = rng.integers(-2, 3, (n, max(1, n // 2)))
        S = np.triu(rng.integers(-2, 3, (n, n)), 1)
        M = (B @ B.T + S - S.T).astype(float)
    else:
        M = rng.integers(-3, 4, (n, n)).astype(float)
        M[np.diag_indices(n)] = rng.integers(0, 4, n)
    q = rng.integers(-3, 4, n).astype(float)
    q[rng.random(n) < zeros] = 0.0
    if q.min() >= 0:
        q[rng.integers(n)] = -1.0
    return M, q


def exact_solutions(M: np.ndarray, q: np.ndarray) -> dict[tuple[int, ...], list]:
    """{pattern alpha: z_alpha} for every alpha with M_alpha,alpha nonsingular whose exact
    solution of M_aa z_a = -q_a has z_a >= 0 and w = M z + q >= 0 (rationals: python-flint)."""
    from flint import fmpq_mat

    n = q.size
    Mi, qi = M.astype(int), q.astype(int)
    found = {}
    if qi.min() >= 0:
        found[()] = []
    for k in range(1, n + 1):
        for a in combinations(range(n), k):
            A = fmpq_mat([[int(Mi[r, c]) for c in a] for r in a])
            if A.det() == 0:
                continue
            x = A.solve(fmpq_mat([[-int(qi[r])] for r in a]))
            za = [x[t, 0] for t in range(k)]
            if min(za) < 0:
                continue
            if all(int(qi[r]) + sum(int(Mi[r, a[t]]) * za[t] for t in range(k)) >= 0
                   for r in range(n) if r not in a):
                found[a] = za
    return found


def _path(sol):
    """Outcome, pivots and final basis (a checked "infeasible" is Lemke's ray)."""
    return ("ray" if sol.status == "infeasible" else sol.status, sol.iterations,
            tuple(int(i) for i in sol.basis))


@settings(max_examples=60)
@given(n=st.integers(2, 8), seed=st.integers(0, 2**32 - 1),
       zeros=st.sampled_from([0.0, 0.4, 0.7]), copositive_plus=st.booleans())
def test_float_lemke_with_exact_ties_takes_the_exact_path(n, seed, zeros, copositive_plus):
    M, q = integer_lcp(n, seed, zeros, copositive_plus)
    d, limit = np.ones(n), 1000 + 100 * n
    ties = ExactTies(M, q, d)
    sol = _Lemke(M, q, d, 1e-10, ties).run(limit)
    assert not sol.info.get("cycling") and sol.status in ("solved", "ray", "infeasible")
    assert _path(sol) == _path(lemke_exact(M, q, d, limit))


@settings(max_examples=60)
@given(n=st.integers(2, 8), seed=st.integers(0, 2**32 - 1),
       zeros=st.sampled_from([0.0, 0.4, 0.7]), copositive_plus=st.booleans())
def test_lemke_answers_agree_with_exact_enumeration(n, seed, zeros, copositive_plus):
    M, q = integer_lcp(n, seed, zeros, copositive_plus)
    problem = lcp.LCP(M, q)
    found = exact_solutions(M, q)
    sol = lcp.solve(problem)
    assert sol.status in ("solved", "ray", "infeasible"), sol.message
    assert "cycling" not in sol.message
    if sol.status == "solved":
        assert certify(problem, sol, uniqueness="none").accepted
        alpha = tuple(int(i) for i in np.flatnonzero(sol.z > 0))
        match = [a for a in found if set(alpha) <= set(a)
                 and np.allclose(sol.z[list(a)], [int(v.p) / int(v.q) for v in found[a]], rtol=1e-9,
                                 atol=1e-12 * max(1.0, float(np.abs(sol.z).max())))
                 and np.all(np.delete(sol.z, list(a)) == 0)]
        assert match, (sol.z, list(found))
    elif sol.status == "infeasible":
        assert not found  # an exact Farkas certificate: nothing is feasible
    else:
        assert "no proof of infeasibility" in sol.message
    if numerically_psd(M + M.T):  # copositive-plus: Lemke solves every feasible LCP
        assert (sol.status == "solved") == bool(found)


def _box_stack(k: int):
    """k boxes resting on a plane (tests/lcp/test_accuracy.py's box_on_plane: 12 unknowns
    each, q = -1e-2 on the normals, +-1e-10 on the tangents, ties everywhere), uncoupled."""
    M0, q0 = box_on_plane()
    M = np.kron(np.eye(k), M0)
    return M, np.tile(q0, k)


def test_a_cycling_float_run_past_the_exact_size_is_redone_with_exact_ties(monkeypatch):
    """n = 72 > EXACT_MAX_N: when the float run reports a repeated basis, lemke() reruns it
    with its ambiguous ties decided in rationals (not at once with coarser ties), and the
    answer is certified."""
    M, q = _box_stack(6)
    n = q.size
    assert EXACT_MAX_N < n <= EXACT_TIES_MAX_N
    real_run = lemke_module._Lemke.run

    def cycling_without_exact_ties(self, max_iter):
        sol = real_run(self, max_iter)
        if self.exact is None:
            sol.status, sol.info["cycling"] = "max_iter", True
            sol.message = "numerical cycling: a basis repeated after 11 pivots"
        return sol

    monkeypatch.setattr(lemke_module._Lemke, "run", cycling_without_exact_ties)
    monkeypatch.setattr(lemke_module._kernel, "solve_one", lambda *a: None)
    sol = lemke_module.lemke(M, q)
    assert sol.status == "solved" and "exact_ties" in sol.info
    assert "ambiguous ratio ties decided in exact rational arithmetic" in sol.message
    assert "restarted with tol" not in sol.message
    assert certify(lcp.LCP(M, q), sol, uniqueness="none").accepted


def test_exact_ties_decide_a_near_tie_that_floats_cannot():
    """Two rows whose ratios differ by 1e-17 relative (below any float tie tolerance) are
    tied in floats; ExactTies reads the data as rationals and takes the exact minimum. Step 0
    (B = I, z0 entering): the row of least q_i / d_i leaves; q_1 / 3 < q_0 / 3 exactly when
    q_1 < q_0, which the doubles below are (one unit in the last place apart)."""
    q0 = -1.0
    q1 = np.nextafter(q0, -2.0)  # q1 < q0 by one ulp
    M = np.array([[1.0, 0.0], [0.0, 1.0]])
    q = np.array([q0, q1])
    d = np.array([3.0, 3.0])
    ties = ExactTies(M, q, d)
    assert ties.choose([0, 1], 4, [0, 1]) == 1
    q = np.array([q1, q0])
    assert ExactTies(M, q, d).choose([0, 1], 4, [0, 1]) == 0
