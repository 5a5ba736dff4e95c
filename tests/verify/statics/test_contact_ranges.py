"""verify.statics.contact_ranges: the range LPs split into chunks (worker processes) give the
ends of one LP per end without any filter (scipy's linprog on P written with its cone rows, an
independent method), and the serial ranges.

The chunked run is exercised two ways: in this process, over any partition of the contacts
into chunks solved by two ForceLPs with the witnesses carried and merged as the workers do
(a property over generated piles), and once for real with two worker processes.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.verify.statics.contact_ranges import Witnesses, ranges_of, sliding_of
from rigidlcp.verify.statics.forceset import analyse
from rigidlcp.verify.statics.model import DualForceLP, ForceLP, StaticProblem


def _unfiltered_ends(prob: StaticProblem) -> tuple[np.ndarray, np.ndarray]:
    """Every end by its own LP (linprog, cone rows as rows, no warm start, no filter); NaN
    where linprog fails on each of its methods (status 4)."""
    bounds = [(None if not np.isfinite(lo) else lo, None if not np.isfinite(hi) else hi)
              for lo, hi in zip(prob.lb, prob.ub)]
    lo, hi = np.zeros(prob.n), np.zeros(prob.n)
    for k in range(prob.n):
        for sgn, out in ((1.0, lo), (-1.0, hi)):
            e = np.zeros(prob.n)
            e[k] = sgn
            for method in ("highs", "highs-ds", "highs-ipm"):
                res = linprog(e, A_ub=prob.G, b_ub=np.zeros(prob.G.shape[0]), A_eq=prob.A,
                              b_eq=prob.b, bounds=bounds, method=method)
                if res.status != 4:  # 4: the reference's own numerical failure (HiGHS's
                    break  # "Solve error": n 11, seed 110, mu 0.99999): try another method
            assert res.status in (0, 3, 4), res.message
            # NaN: no reference for this end (linprog failed on every method); not compared
            out[k] = res.x[k] if res.status == 0 else -sgn * np.inf if res.status == 3 else np.nan
    return lo, hi


def _same(got: np.ndarray, want: np.ndarray, scale: float) -> None:
    known = ~np.isnan(want)  # NaN: linprog, the reference, failed there
    got, want = got[known], want[known]
    inf = ~np.isfinite(want)
    assert np.array_equal(got[inf], want[inf]), np.flatnonzero(inf)
    assert np.all(np.abs(got[~inf] - want[~inf]) <= 1e-7 * scale), np.max(
        np.abs(got[~inf] - want[~inf]))


def _pile(n: int, seed: int, mu: float):
    lat = deposit(n, seed=seed, radii=(0.8, 1.2), width=2.0 * max(3, n // 3))
    return models.System(lat, mu_pp=mu, mu_plane=mu, mu_wall=mu)


@settings(max_examples=8)
@given(n=st.integers(3, 14), seed=st.integers(0, 10**4), mu=st.floats(0.1, 1.0),
       cuts=st.lists(st.integers(1, 40), min_size=1, max_size=6))
def test_chunks_with_merged_witnesses_give_the_unfiltered_ends(n, seed, mu, cuts):
    system = _pile(n, seed, mu)
    fs = analyse(system, ranges=False)
    if not fs.exists:
        return
    prob = StaticProblem(system)
    c = prob.c
    bounds = sorted({0, c, *[x % (c + 1) for x in cuts]})
    chunks = [np.arange(a, b) for a, b in zip(bounds[:-1], bounds[1:]) if b > a]
    # two "workers", each warm from its own chunks: one solves the range LPs through their
    # dual (DualForceLP, as the workers do), the other by ForceLP's primal simplex
    primal = [ForceLP(prob), ForceLP(prob)]
    lps = [DualForceLP(prob, primal[0]), primal[1]]
    for lp in lps:
        lp.solve(np.zeros(prob.n))
    wit = Witnesses.of(prob, fs.solution)
    lo, hi = np.zeros(prob.n), np.zeros(prob.n)
    for x, ch in enumerate(chunks):
        mine = Witnesses(wit.r_min.copy(), wit.s_max.copy(), wit.s_min.copy(),
                         wit.seen.copy())  # what a worker receives
        lo_x, hi_x, _, unchecked = ranges_of(prob, lps[x % 2], fs.implicit, ch, mine)
        assert unchecked == 0
        m = len(ch)
        lo[ch], hi[ch], lo[c + ch], hi[c + ch] = lo_x[:m], hi_x[:m], lo_x[m:], hi_x[m:]
        wit.merge(mine)
    want_lo, want_hi = _unfiltered_ends(prob)
    scale = max(1.0, float(np.max(np.abs(want_hi[np.isfinite(want_hi)]), initial=0.0)))
    _same(lo, want_lo, scale)
    _same(hi, want_hi, scale)
    # the sliding contacts, chunk by chunk, are those of the serial run
    serial = analyse(system)
    runs = [sliding_of(prob, primal[x % 2], fs.implicit, hi[:c], wit.seen, ch)
            for x, ch in enumerate(chunks)]
    assert np.array_equal(np.concatenate([r[0] for r in runs]), serial.sliding)
    assert sum(r[2] for r in runs) == 0 and serial.unchecked == 0
    _same(serial.lo, want_lo, scale)
    _same(serial.hi, want_hi, scale)


@pytest.mark.parametrize("n, seed, mu", [(24, 1, 0.5)])
def test_two_worker_processes_give_the_serial_ranges(n, seed, mu):
    system = _pile(n, seed, mu)
    one, two = analyse(system), analyse(system, jobs=2)
    assert one.exists and two.exists and two.unchecked == 0
    scale = max(1.0, float(np.max(np.abs(one.hi[np.isfinite(one.hi)]))))
    _same(two.lo, one.lo, scale)
    _same(two.hi, one.hi, scale)
    assert np.array_equal(two.sliding, one.sliding)
    assert two.to_dict()["contacts"][0].keys() == one.to_dict()["contacts"][0].keys()


@settings(max_examples=6)
@given(n=st.integers(3, 12), seed=st.integers(0, 10**4), mu=st.floats(0.1, 1.0),
       through_dual=st.booleans())
@example(n=11, seed=110, mu=0.99999, through_dual=True)  # linprog's "Solve error" (retried)
def test_dual_bound_certifies_the_optimum_and_refuses_a_cost_it_does_not_bound(n, seed, mu,
                                                                              through_dual):
    """ForceLP.certified (row duals) and DualForceLP.certified (the dual LP's optimum): the y
    of max R_a certifies R_a <= max on P (weak duality); read against the cost -e_b of another
    contact whose R_b exceeds its value at that optimum somewhere in P (an unfiltered LP finds
    it), it must not, or R_b would be bounded by it."""
    system = _pile(n, seed, mu)
    if not analyse(system, ranges=False).exists:
        return
    prob = StaticProblem(system)
    lp = DualForceLP(prob, ForceLP(prob)) if through_dual else ForceLP(prob)
    _, want_hi = _unfiltered_ends(prob)
    for a in range(prob.c):
        e = np.zeros(prob.n)
        e[a] = -1.0
        status, lam = lp.solve(e)
        if status != "optimal":
            continue
        assert prob.admissible(lam) and lp.certified(e, lam), a
        for b in range(prob.c):
            if want_hi[b] > lam[b] + 1e-6 * max(1.0, abs(lam[b])):
                f = np.zeros(prob.n)
                f[b] = -1.0
                assert not lp.certified(f, lam), (a, b)


@pytest.mark.parametrize("mu", [0.0, 0.5])
def test_unbounded_ends_are_proved_by_a_checked_ray(mu):
    """Three disks in a pyramid between walls 4 apart (test_forceset's case 3): the bottom
    pair's contact and the walls can pinch with any force, so max R is +inf there; each such
    end comes with HiGHS's primal ray, checked (ForceLP.ray_checked), and the same ray read
    against the opposite cost (which it increases) is refused."""
    x = [[1.0, 1.0], [3.0, 1.0], [2.0, 1.0 + np.sqrt(3.0)]]
    lat = models.make_packing(x, np.ones(3), m=np.ones(3), left=0.0, right=4.0)
    system = models.System(lat, mu_pp=mu, mu_plane=mu, mu_wall=mu)
    fs = analyse(system)
    assert fs.exists and fs.unchecked == 0
    assert np.isinf(fs.hi[: fs.c]).sum() == 3  # the pair and the two walls
    prob = StaticProblem(system)
    for lp in (ForceLP(prob), DualForceLP(prob, ForceLP(prob))):
        for a in np.flatnonzero(np.isinf(fs.hi[: fs.c])):
            e = np.zeros(prob.n)
            e[a] = -1.0
            assert lp.solve(e)[0] == "unbounded"
            assert lp.ray_checked(e), a
            if isinstance(lp, ForceLP):
                assert not lp.ray_checked(-e), a


@settings(max_examples=10)
@given(n=st.integers(3, 20), seed=st.integers(0, 10**4), mu=st.floats(0.05, 1.2))
def test_analyse_gives_the_ranges_of_the_primal_simplex_loop(n, seed, mu):
    """main's range LPs (ForceLP's primal simplex, one warm LP, the same filters), computed
    here, against analyse's (through the dual): the same ends to the LPs' tolerance, nothing
    unchecked."""
    system = _pile(n, seed, mu)
    fs = analyse(system)
    if not fs.exists:
        return
    prob = StaticProblem(system)
    lp = ForceLP(prob)
    every = np.arange(prob.c)
    # over every contact in order, ranges_of's [R; S] layout is P's
    want_lo, want_hi, _, unchecked = ranges_of(prob, lp, fs.implicit, every,
                                               Witnesses.of(prob, fs.solution))
    scale = max(1.0, float(np.max(np.abs(want_hi[np.isfinite(want_hi)]), initial=0.0)))
    assert unchecked == 0 and fs.unchecked == 0
    _same(fs.lo, want_lo, scale)
    _same(fs.hi, want_hi, scale)


@pytest.mark.parametrize("jobs", [0, -1, 1.5, True, "2"])
def test_bad_jobs_refused_before_any_lp(jobs):
    """A number of workers that is not an integer >= 1 is refused by name (InvalidInput,
    still a ValueError) before any LP, also where the ranges would not be computed."""
    from rigidlcp.lcp.errors import InvalidInput

    system = models.System(deposit(4, seed=1, radii=(0.8, 1.2), width=4.0))
    for ranges in (True, False):
        with pytest.raises(InvalidInput, match="jobs must be an integer >= 1"):
            analyse(system, ranges=ranges, jobs=jobs)


def test_dual_lp_without_changeRowsBounds_gives_the_same_ends():
    """highspy 1.10 (the lowest pyproject allows) has no Highs.changeRowsBounds: DualForceLP
    then sets the changed rows one at a time, with the same optima."""
    import highspy

    class Old:  # a Highs as 1.10 shows it: every attribute but changeRowsBounds
        def __init__(self, h):
            self._h = h

        def __getattr__(self, name):
            if name == "changeRowsBounds":
                raise AttributeError(name)
            return getattr(self._h, name)

    assert hasattr(highspy.Highs(), "changeRowBounds")
    prob = StaticProblem(_pile(12, 1, 0.5))
    new, old = DualForceLP(prob, ForceLP(prob)), DualForceLP(prob, ForceLP(prob))
    old.h = Old(old.h)
    optimal = 0
    for k in range(min(prob.n, 8)):
        for sgn in (-1.0, 1.0):
            e = np.zeros(prob.n)
            e[k] = sgn
            (s1, x1), (s2, x2) = new.solve(e), old.solve(e)
            assert s1 == s2
            if s1 == "optimal":
                optimal += 1
                assert abs(e @ x1 - e @ x2) <= 1e-9 * prob.scale
    assert optimal
