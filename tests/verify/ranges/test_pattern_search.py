"""verify.ranges.pattern_search: the extreme of L . z over every solution of LCP(M, q) with no
box on z (issue 21 point 1), where LCP(M, 0) has a nonzero solution, so that
verify.certificates.bounds.no_solution_beyond cannot bound the solutions.

Hand-made LCPs (each range derived in its test's docstring), the docs' own example through
event_ranges, and a property against an enumeration of all 2^n patterns written here (an LP
per pattern, scipy.optimize.linprog), n <= 6, degenerate and singular M included.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from rigidlcp import lcp, models
from rigidlcp.verify.certificates.bounds import no_solution_beyond
from rigidlcp.verify.ranges import event_ranges
from rigidlcp.verify.ranges.pattern_search import extreme


def _is_solution(M, q, z, tol=1e-8) -> bool:
    """z >= 0, w = M z + q >= 0, z_i w_i = 0, each to tol relative to the sizes involved
    (written here, not the project's residual)."""
    z = np.asarray(z, dtype=float)
    w = M @ z + q
    size = 1.0 + np.max(np.abs(z)) * (1.0 + np.max(np.abs(M))) + np.max(np.abs(q))
    return bool(np.all(z >= -tol * size) and np.all(w >= -tol * size)
                and np.all(np.minimum(np.abs(z), np.abs(w)) <= tol * size))


def _ray_ok(M, q, L, sense, e) -> bool:
    """An "unbounded" end of min sense L . z: L . d has the improving sign and z + t d is a
    solution at t = 1 and t = 1e4 (checked here)."""
    d, z0 = np.asarray(e.ray), np.asarray(e.witness)
    return (sense * float(L @ d) < -1e-12 and np.all(d >= 0)
            and _is_solution(M, q, z0 + d) and _is_solution(M, q, z0 + 1e4 * d))


# -- M = [[0, 1], [-1, 0]], q = (0, 1) ---------------------------------------------------------

M1, Q1 = np.array([[0.0, 1.0], [-1.0, 0.0]]), np.array([0.0, 1.0])


def test_bounded_set_with_a_nonzero_solution_of_lcp_m_0():
    """w1 = z2, w2 = 1 - z1. w2 >= 0: z1 <= 1. If z2 > 0, then w1 > 0 forces z1 = 0 and
    z2 w2 = 0 forces z1 = 1: impossible. So z2 = 0, w1 = 0, and z1 is any value in [0, 1]
    (z1 w1 = 0, z2 w2 = 0): the solution set is the segment {(s, 0)}, s in [0, 1]. LCP(M, 0)
    has d = (0, 1) (M d = (1, 0): d1 = 0, (M d)_2 = 0) with z2 . d = 1 > 0, but its pattern's
    piece {z1 = 0, w2 = 0} is empty (w2 = 1 there). Ranges: z1 in [0, 1], z2 in [0, 0]."""
    nb = no_solution_beyond(M1, Q1, 1e3)
    assert nb.proved is None and "LCP(M, 0)" in nb.message  # the box cannot be proved
    for L, lo, hi in ((np.array([1.0, 0.0]), 0.0, 1.0), (np.array([0.0, 1.0]), 0.0, 0.0)):
        for sense, want in ((1, lo), (-1, hi)):
            e, stats = extreme(M1, Q1, L, sense)
            assert e.status == "optimal", e
            assert e.value == pytest.approx(want, abs=1e-12)
            assert _is_solution(M1, Q1, e.witness) and float(L @ e.witness) == e.value
            assert stats.covered == 4


# -- M = [[1, -1], [-1, 1]], q = (1, -1) ------------------------------------------------------

M2, Q2 = np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([1.0, -1.0])


def test_unbounded_set_bounded_and_unbounded_observables():
    """w1 = z1 - z2 + 1 = -w2: both >= 0 only at w = 0, i.e. z2 = z1 + 1, complementary for
    every z1 >= 0. The solution set is the half-line {(t, t + 1)}, t >= 0, with ray (1, 1)
    (LCP(M, 0): M (1, 1) = 0). So z1 - z2 = -1 on the whole set: range [-1, -1] (proved,
    though the set is unbounded); z2 in [1, +inf), ray (1, 1); -z1 in (-inf, 0]."""
    assert no_solution_beyond(M2, Q2, 1e3).proved is None
    L = np.array([1.0, -1.0])
    for sense in (1, -1):
        e, _ = extreme(M2, Q2, L, sense)
        assert e.status == "optimal" and e.value == pytest.approx(-1.0, abs=1e-12)
        assert _is_solution(M2, Q2, e.witness)
    L = np.array([0.0, 1.0])
    lo, _ = extreme(M2, Q2, L, 1)
    assert lo.status == "optimal" and lo.value == pytest.approx(1.0, abs=1e-12)
    assert np.allclose(lo.witness, [0.0, 1.0], atol=1e-12)
    hi, _ = extreme(M2, Q2, L, -1)
    assert hi.status == "unbounded" and hi.value == np.inf
    assert _ray_ok(M2, Q2, L, -1, hi)
    assert hi.ray[0] == pytest.approx(hi.ray[1], rel=1e-12)  # along (1, 1)
    L = np.array([-1.0, 0.0])
    lo, _ = extreme(M2, Q2, L, 1)
    assert lo.status == "unbounded" and lo.value == -np.inf and _ray_ok(M2, Q2, L, 1, lo)
    hi, _ = extreme(M2, Q2, L, -1)
    assert hi.status == "optimal" and hi.value == pytest.approx(0.0, abs=1e-12)


def test_two_blocks_each_range_the_sum_of_the_blocks():
    """M = diag(M1, M2), q = (Q1, Q2): the solutions are pairs, so L = z1 + (z3 - z4) ranges
    over [0, 1] + {-1} = [-1, 0], z2 + z4 over [0 + 1, 0 + inf) = [1, +inf)."""
    M = np.zeros((4, 4))
    M[:2, :2], M[2:, 2:] = M1, M2
    q = np.r_[Q1, Q2]
    L = np.array([1.0, 0.0, 1.0, -1.0])
    assert extreme(M, q, L, 1)[0].value == pytest.approx(-1.0, abs=1e-12)
    assert extreme(M, q, L, -1)[0].value == pytest.approx(0.0, abs=1e-12)
    L = np.array([0.0, 1.0, 0.0, 1.0])
    assert extreme(M, q, L, 1)[0].value == pytest.approx(1.0, abs=1e-12)
    hi, _ = extreme(M, q, L, -1)
    assert hi.status == "unbounded" and _ray_ok(M, q, L, -1, hi)


def test_no_solution_is_infeasible_and_a_time_limit_is_no_bound():
    """w1 = z1 - 1 with z1 = 0 or w1 = 0, and w2 = -z1 - 1 < 0 always: no solution."""
    M, q = np.array([[1.0, 0.0], [-1.0, 0.0]]), np.array([-1.0, -1.0])
    assert extreme(M, q, np.ones(2), 1)[0].status == "infeasible"
    e, _ = extreme(M2, Q2, np.array([1.0, -1.0]), 1, time_limit=-1.0)
    assert e.status == "time limit" and e.value is None


def test_a_presolve_infeasible_is_asked_again():
    """Found by the property below: w1 = w2 = 0, w3 = -z2 + z3 - z4, w4 = 1 - w3. If z3 > 0:
    w3 = 0, so w4 = 1, z4 = 0 and z3 = z2: the solutions (a, t, t, 0), a, t >= 0, and those
    with z3 = 0; z3 ranges over [0, +inf) along the ray (0, 1, 1, 0). scipy 1.17's HiGHS with
    presolve called the root LP (max z3 over z >= 0, w >= 0) infeasible, though z = 0 is in it:
    the search said "infeasible" for the whole LCP."""
    M = np.array([[0.0, 0, 0, 0], [0, 0, 0, 0], [0, -1, 1, -1], [0, 1, -1, 1]])
    q, L = np.array([0.0, 0, 0, 1]), np.array([0.0, 0, 1, 0])
    lo, _ = extreme(M, q, L, 1)
    assert lo.status == "optimal" and lo.value == 0.0
    hi, _ = extreme(M, q, L, -1)
    assert hi.status == "unbounded" and _ray_ok(M, q, L, -1, hi)
    assert hi.ray[1] == pytest.approx(hi.ray[2], abs=1e-12) and hi.ray[3] == 0.0


def test_a_node_lp_highs_leaves_unknown_is_asked_at_its_default_tolerances():
    """rect 4x2 from rest (gamma 0.1): the node of the min of mu_g with z = 0 on
    {23, 30, 33, 34, 35, 43, 44, 45} and w = 0 on {0, 1, 2, 3, 9, 10, 11, 12, 22, 32} ended
    HiGHS status 15 "unknown" at tolerances 1e-10, with and without presolve, and the search
    said "unproved"; at HiGHS's default tolerances (1e-7, a larger set) it is infeasible,
    so the node is empty."""
    from rigidlcp.verify.ranges.event import event_observables
    from rigidlcp.verify.ranges.pattern_search import _solve
    s = models.System(models.rectangular(4, 2), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.1)
    ep = models.event_problem(s, models.initial_state(s))
    M, q = np.asarray(ep.lcp.M, float), np.asarray(ep.lcp.q, float)
    fixz, fixw = np.zeros(q.size, bool), np.zeros(q.size, bool)
    fixz[[23, 30, 33, 34, 35, 43, 44, 45]] = True
    fixw[[0, 1, 2, 3, 9, 10, 11, 12, 22, 32]] = True
    assert _solve(event_observables(ep)["mu_g"], M, q, fixz, fixw).status == 2


def test_a_search_stopped_by_its_time_limit_gives_no_end(monkeypatch):
    """The docs' example's min and max of mu_g, the search's clock faked (each reading one
    second later) so that it stops after a few nodes: "time limit", no value; the best value
    met is attained (a checked solution) and no better than the end; a bound, where given,
    no worse than the end (the ends: the full search, whose values test_brute_force checks
    against every pattern)."""
    from rigidlcp.verify.ranges import pattern_search
    from rigidlcp.verify.ranges.event import event_observables
    s = models.System(models.rectangular(2, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.1)
    ep = models.event_problem(s, models.initial_state(s))
    M, q = np.asarray(ep.lcp.M, float), np.asarray(ep.lcp.q, float)
    L = event_observables(ep)["mu_g"]
    z = lcp.solve(ep.lcp).z
    bounds = 0
    for sense, limit in ((1, 6.5), (1, 20.5), (-1, 6.5)):
        full, stats = extreme(M, q, L, sense, incumbent=z)
        assert full.status == "optimal" and stats.nodes > limit
        ticks = iter(range(10**6))
        monkeypatch.setattr(pattern_search.time, "process_time",
                            lambda ticks=ticks: float(next(ticks)))
        e, stats = extreme(M, q, L, sense, incumbent=z, time_limit=limit)
        monkeypatch.undo()
        assert e.status == "time limit" and e.value is None and stats.nodes < limit
        assert _is_solution(M, q, e.witness) and float(L @ e.witness) == e.best
        assert sense * e.best >= sense * full.value - 1e-12
        if e.bound is not None:  # min(open nodes' parent LP bounds, best): a proved bound
            bounds += 1
            assert sense * e.bound <= sense * full.value + 1e-12
    assert bounds >= 1  # (sense 1 at 20 nodes: every open node's parent LP bounded)


def test_docs_example_every_pattern_range_is_proved():
    """docs/verification.md's example (rect 2x1 from rest, gamma 0.1): LCP(M, 0) has a nonzero
    solution, so the box is not proved; every end of every range is now proved without it
    (the values themselves: test_brute_force.test_event_ranges_equal_enumeration[0.1-None],
    an enumeration of the 2^11 patterns)."""
    s = models.System(models.rectangular(2, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.1)
    ep = models.event_problem(s, models.initial_state(s))
    res = event_ranges(ep, lcp.solve(ep.lcp), time_limit=10)
    assert not res.bound_proved and res.searched and res.proved
    M, q = np.asarray(ep.lcp.M, float), np.asarray(ep.lcp.q, float)
    for r in res.every.values():
        assert "proved without a box" in r.scope
        for e in (r.lo, r.hi):
            assert e.status == "optimal" and _is_solution(M, q, e.witness)
    assert res.every["mu_g"].hi.value == pytest.approx(0.2, abs=1e-9)  # the docs' comment


# -- against every pattern -------------------------------------------------------------------

def _brute(M, q, L) -> dict:
    """{sense: ("optimal", value) | ("unbounded", None) | ("infeasible", None)} of min
    sense L . z over every pattern: an LP per pattern (linprog), the best of them."""
    n = q.size
    out = {1: ("infeasible", None), -1: ("infeasible", None)}
    for y in itertools.product((False, True), repeat=n):
        y = np.array(y)
        eq, ub = np.flatnonzero(y), np.flatnonzero(~y)
        kw = dict(A_ub=-M[ub] if ub.size else None, b_ub=q[ub] if ub.size else None,
                  A_eq=M[eq] if eq.size else None, b_eq=-q[eq] if eq.size else None,
                  bounds=[(0, None) if v else (0, 0) for v in y], method="highs")
        if linprog(np.zeros(n), **kw).status != 0 and linprog(
                np.zeros(n), options={"presolve": False}, **kw).status != 0:
            continue  # (HiGHS's presolve has called feasible LPs infeasible: asked twice)
        for sense in (1, -1):
            r = linprog(sense * L, **kw)
            if r.status not in (0, 3):
                r = linprog(sense * L, options={"presolve": False}, **kw)
            old = out[sense]
            if old[0] == "unbounded":
                continue
            if r.status == 3:
                out[sense] = ("unbounded", None)
            elif r.status == 0 and (old[0] == "infeasible" or r.fun < sense * old[1]):
                out[sense] = ("optimal", sense * r.fun)
            elif r.status not in (0, 3):
                raise AssertionError(f"brute-force LP: {r.message}")
    return out


@st.composite
def _lcps(draw):
    """(M, q, L), n <= 6, small integers; M general, of rank 1, PSD singular (B B^T, B n x k,
    k < n), or with a zero row and a repeated column: singular and degenerate cases."""
    n = draw(st.integers(1, 6))
    ints = st.integers(-3, 3)
    kind = draw(st.sampled_from(["general", "rank1", "psd", "zero-row"]))
    if kind == "rank1":
        u, v = (np.array(draw(st.lists(ints, min_size=n, max_size=n))) for _ in range(2))
        M = np.outer(u, v).astype(float)
    elif kind == "psd":
        k = draw(st.integers(1, max(1, n - 1)))
        B = np.array(draw(st.lists(ints, min_size=n * k, max_size=n * k))).reshape(n, k)
        M = (B @ B.T).astype(float)
    else:
        M = np.array(draw(st.lists(ints, min_size=n * n, max_size=n * n)),
                     dtype=float).reshape(n, n)
        if kind == "zero-row":
            i, j = draw(st.integers(0, n - 1)), draw(st.integers(0, n - 1))
            M[i] = 0.0
            M[:, j] = M[:, 0]
    q = np.array(draw(st.lists(ints, min_size=n, max_size=n)), dtype=float)
    L = np.array(draw(st.lists(st.integers(-2, 2), min_size=n, max_size=n)), dtype=float)
    return M, q, L


@settings(max_examples=150)
@given(_lcps())
def test_extreme_equals_every_pattern_enumerated(data):
    M, q, L = data
    brute = _brute(M, q, L)
    for sense in (1, -1):
        e, stats = extreme(M, q, L, sense, time_limit=60)
        status, value = brute[sense]
        assert e.status == status, (sense, e, e.note)
        if status == "optimal":
            assert e.value == pytest.approx(value, abs=1e-7, rel=1e-9)
            assert _is_solution(M, q, e.witness)
            assert float(L @ e.witness) == pytest.approx(e.value, abs=1e-12)  # attained
            assert stats.covered == 2 ** q.size
        elif status == "unbounded":
            assert e.value == -sense * np.inf and _ray_ok(M, q, L, sense, e)
