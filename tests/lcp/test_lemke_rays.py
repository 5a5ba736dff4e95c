"""Why lemke ends on a secondary ray where other methods solve (issue 23, point 3), and what is
reported then.

docs/comparison.md showed lemke ending on a ray on Siconos's lcp_CPS_3, on 7 of its MLCPs
(Buck2, BuckConverter, BuckFirstStep, PD, diodeBridge, diodeBridge20, diodeBridge40: A singular
or of condition 2.6e12, so lemke runs on the split LCP of lcp.mlcp_full, whose M is not
copositive-plus) and on the hard classes' integer-tie-0 and -1. In every case Lemke's method in
exact rational arithmetic (lcp.lemke_exact, the data's doubles read as rationals; equilibrated
or not) ends on a secondary ray too: the ray is Lemke's termination on a matrix that is not
copositive-plus (Cottle-Pang-Stone Sec. 4.4), not float tie-breaking and not scaling. Such a ray
proves nothing, and the status says so: "ray (Lemke's termination; no proof of infeasibility)",
never "infeasible", and the bench counts it as the failure "ray", not as a claim that no
solution exists (rigidlcp.bench.harness).
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np

from rigidlcp import lcp
from rigidlcp.bench.fuzz_cases import make_case
from rigidlcp.bench.harness import judge
from rigidlcp.bench.report_md import disagreements, false_claims
from rigidlcp.lcp.acceptance.farkas import numerically_psd
from rigidlcp.lcp.acceptance.scaling import ruiz
from rigidlcp.lcp.solvers.lemke_exact import lemke_exact
from rigidlcp.lcp.solvers.mlcp_full import split_lcp
from rigidlcp.verify import certify

from .test_lemke_degenerate import exact_solutions

DATA = Path(__file__).resolve().parents[1] / "data" / "siconos"
NO_PROOF = "ray (Lemke's termination; no proof of infeasibility)"


def _exact_lemke_ends_on_a_ray(M: np.ndarray, q: np.ndarray) -> bool:
    """Lemke (covering vector ones) in exact rationals, on the data and on their Ruiz
    equilibration (what lcp.solve gives lemke), ends on a secondary ray both times."""
    n = q.size
    eq = ruiz(M, q)
    return all(lemke_exact(A, b, np.ones(n), 1000 + 100 * n).status == "ray"
               for A, b in ((M, q), (eq.M, eq.q)))


def _bench_row(problem, sol):
    raw = {"kind": "answer", "z": sol.z, "status": sol.status, "time": 1e-3,
           "iterations": sol.iterations, "message": sol.message}
    return judge(problem, "lemke", "s", raw, 10.0, 1e-8)


def test_bimatrix_game_cps_3_ends_on_a_ray_that_claims_nothing():
    """lcp_CPS_3 (CPS Example 4.4.23, a bimatrix game: M = [[0, A], [B^T, 0]] > 0 off its zero
    diagonal blocks, q = -1): Lemke's first pivot (z0 enters, row 3 leaves: all q_i tie, the
    lexicographic rule takes the last row) makes z[3] enter unblocked, in exact arithmetic as
    in floats. The LCP has solutions: z = (1, 4, 1, 4) / 90 gives w = 0, exactly."""
    P = lcp.load(DATA / "lcp_CPS_3.dat")
    assert not numerically_psd(P.M + P.M.T)
    z = [Fraction(v, 90) for v in (1, 4, 1, 4)]  # a solution, checked in rationals
    w = [sum(Fraction(P.M[i, j]) * z[j] for j in range(4)) + Fraction(P.q[i])
         for i in range(4)]
    assert all(v >= 0 for v in z) and w == [0, 0, 0, 0]
    assert _exact_lemke_ends_on_a_ray(P.M, P.q)
    sol = lcp.solve(P)
    assert sol.status == "ray" and sol.iterations == 1
    assert NO_PROOF in sol.message and "infeasible" not in sol.message.replace(
        "infeasibility", "")
    assert sol.info["exact_rerun"] == "ray"
    assert "not rounding" in sol.message
    row = _bench_row(P, sol)
    assert row.outcome == "ray" and not row.success  # a failure, not a claim of no solution
    solved = judge(P, "pivoting", "s", {"kind": "answer", "z": np.array([1, 4, 1, 4]) / 90,
                                        "status": "solved", "time": 1e-3}, 10.0, 1e-8)
    assert solved.outcome == "solved"
    assert disagreements([row, solved]) == [] and false_claims([row, solved]) == []


def test_split_mlcps_end_on_lemkes_ray_and_say_so():
    """diodeBridge (A singular) and Buck2 (A of condition 2.6e12) are solved by lcp.solve's
    lemke on the split LCP (u = u+ - u-), whose M = F K F^T (K the MLCP's full matrix) is not
    copositive-plus here: exact Lemke ends on a ray as the float run does. newton-min
    solves both (a certified solution: no infeasibility to prove)."""
    for name in ("diodeBridge_mlcp.dat", "Buck2_mlcp.dat"):
        P = lcp.load(DATA / name)
        S = split_lcp(P)
        assert not numerically_psd(S.M + S.M.T)
        assert _exact_lemke_ends_on_a_ray(S.M, S.q), name
        sol = lcp.solve(P)
        assert sol.status == "ray" and NO_PROOF in sol.message, name
        ref = lcp.solve(P, method="newton-min")
        assert ref.status == "solved" and certify(P, ref).accepted, name


def test_buck2_every_solved_answer_is_its_solution():
    """Buck2: the u block A has condition 2.6e12. newton-min and newton-fb (two independent
    methods) reach the same solution, each with a forward error bound below 1e-12; every
    method of lcp.solve that takes the MLCP either answers that point or not "solved" (issue
    23: enumerate-mlcp's "solved" was 3.0 away in u)."""
    P = lcp.load(DATA / "Buck2_mlcp.dat")
    ref, fb = lcp.solve(P, method="newton-min"), lcp.solve(P, method="newton-fb")
    assert ref.status == fb.status == "solved"
    assert ref.forward_error < 1e-12 and fb.forward_error < 1e-12
    scale_u, scale_z = np.abs(ref.u).max(), np.abs(ref.z).max()
    assert np.abs(fb.u - ref.u).max() <= 1e-12 * scale_u
    assert np.abs(fb.z - ref.z).max() <= 1e-12 * scale_z
    for m in lcp.methods():
        try:
            sol = lcp.solve(P, method=m.name)
        except lcp.NotApplicable:
            continue
        if sol.status == "solved":
            assert np.abs(sol.u - ref.u).max() <= 1e-8 * scale_u, m.name
            assert np.abs(sol.z - ref.z).max() <= 1e-8 * scale_z, m.name


def test_integer_tie_cases_are_feasible_lcps_without_a_solution():
    """The hard classes' integer-tie-0 and -1 (rigidlcp.bench.fuzz_cases, seeds 8000, 8001, as
    docs/make_comparison.py draws them): exact Lemke ends on a ray, and the LCPs are
    feasible (the LP point below, checked in rationals) so "infeasible" would be false; no
    complementary pattern with a nonsingular principal block gives a solution (exact
    enumeration: every one of the 2^n patterns). lemke's "ray" is the honest answer."""
    feasible = {0: {2: Fraction(1, 4), 5: Fraction(5, 8), 7: Fraction(5, 16),
                    8: Fraction(19, 16), 11: Fraction(11, 16)}}
    for j in (0, 1):
        case = make_case("integer-tie", 8000 + j)
        M, q, n = case.M.astype(int), case.q.astype(int), case.n
        assert _exact_lemke_ends_on_a_ray(case.M, case.q)
        sol = lcp.solve(lcp.LCP(case.M, case.q))
        assert sol.status == "ray" and NO_PROOF in sol.message
        assert sol.info["exact_rerun"] == "ray"
        if j in feasible:
            z = [feasible[j].get(i, Fraction(0)) for i in range(n)]
            assert all(sum(int(M[i, k]) * z[k] for k in range(n)) + int(q[i]) >= 0
                       for i in range(n))
        # no nonsingular pattern's exact solution is a solution (exact enumeration)
        assert exact_solutions(case.M, case.q) == {}, j
        assert q.min() < 0  # the empty pattern (z = 0) is not one either
