"""What a new user tripped on in verify's Python API (session 30): `event_states(systems())`
(a strategy where a System is asked for) was an AttributeError on a hypothesis strategy;
`steady_ranges(..., time_limit=-1)` (or NaN, or 0) was taken, leaving every end it touched at
"time limit" without a search; a misspelt `which` or `clock` was a bare ValueError; and
`event_ranges(ep.lcp, ...)` an AttributeError. Each is now the toolkit's typed error, naming
the argument (still a ValueError where it was one)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings

from rigidlcp import lcp, models, verify
from rigidlcp.lcp.errors import InvalidInput
from rigidlcp.verify.ranges.observables import BadObservable
from rigidlcp.verify.strategies import contact_states, event_states, systems


@pytest.mark.parametrize("strategy, name", [(event_states, "event_states"),
                                            (contact_states, "contact_states")])
def test_a_strategy_where_a_system_is_asked_for(strategy, name):
    @settings(max_examples=1, deadline=None, database=None)
    @given(strategy(systems()))
    def draw_one(x):
        pass

    with pytest.raises(InvalidInput, match=f"{name} takes a models.System, not a strategy: "
                                           "draw the system first"):
        draw_one()


def test_the_flatmap_the_message_suggests_draws_pairs():
    @settings(max_examples=5, deadline=None, database=None)
    @given(systems().flatmap(lambda s: event_states(s).map(lambda x: (s, x))))
    def draw(pair):
        system, state = pair
        assert state.s.size == system.c and state.omega.size == system.p

    draw()


@pytest.fixture(scope="module")
def one_disk():
    """A single disk between smooth walls at gamma 0.1: it rolls, mu_g = gamma / 2."""
    return models.System(models.rectangular(1, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                         gamma=0.1)


@pytest.mark.parametrize("time_limit", [-1.0, 0.0, float("nan"), "10", True])
def test_steady_ranges_refuses_a_time_limit_that_is_not_seconds(one_disk, time_limit):
    with pytest.raises(InvalidInput, match="time_limit must be a number of seconds > 0"):
        verify.steady_ranges(one_disk, time_limit=time_limit)


def test_steady_ranges_names_a_misspelt_which_or_clock(one_disk):
    with pytest.raises(BadObservable, match="which must be 'all', 'alpha' or 'mu_g'"):
        verify.steady_ranges(one_disk, which="mu")
    with pytest.raises(InvalidInput, match="clock must be 'wall' or 'cpu', got 'CPU'"):
        verify.steady_ranges(one_disk, clock="CPU")
    r = verify.steady_ranges(one_disk, time_limit=5)  # the same call, well formed
    assert r.mu_g.lo.value == pytest.approx(0.05) and r.mu_g.hi.value == pytest.approx(0.05)


def test_event_ranges_takes_the_event_problem_not_its_lcp(one_disk):
    ep = models.event_problem(one_disk, models.initial_state(one_disk))
    sol = lcp.solve(ep.lcp)
    with pytest.raises(InvalidInput, match="event_ranges takes a models.EventProblem"):
        verify.event_ranges(ep.lcp, sol)
    with pytest.raises(InvalidInput, match="time_limit must be"):
        verify.event_ranges(ep, sol, time_limit=-1)
    r = verify.event_ranges(ep, sol, time_limit=10)
    assert r is not None


def test_certify_without_a_solution_says_so():
    """`verify.certify(problem, None)` (a forgotten solve) said "the solution has 1 entries,
    the problem 2 pairs"."""
    import numpy as np

    problem = lcp.LCP(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-1.0, -1.0]))
    with pytest.raises(InvalidInput, match="certify needs a solution.*got None"):
        verify.certify(problem, None)
    assert verify.certify(problem, lcp.solve(problem)).accepted
