"""verify.ranges.patterns.find_state(..., clock=): the time limit in wall or CPU seconds
(verify.ranges.milp.clock). The clock changes when a search stops, never what a finished
search answers; a wrong clock is refused before any work. No timed assertion."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import models
from rigidlcp.models.lattice import PLANE
from rigidlcp.verify.ranges.patterns import Pattern, find_state, non_sliding, sliding


def _plane_contacts(system) -> np.ndarray:
    lat = system.lattice
    return np.flatnonzero((lat.j == PLANE) & (system.mu > 0))


def test_wrong_clock_refused():
    s = models.System(models.rectangular(1, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.1)
    with pytest.raises(ValueError, match="clock"):
        find_state(s, Pattern().all_of([non_sliding(0)]), clock="gpu")


@settings(max_examples=6, deadline=None)
@given(lx=st.integers(2, 4), ly=st.integers(1, 2), mpp=st.floats(0.0, 0.4),
       mpl=st.floats(0.05, 0.4), gamma=st.floats(0.01, 0.4), every=st.booleans())
def test_same_answer_with_either_clock(lx, ly, mpp, mpl, gamma, every):
    """"Every plane contact sliding" / "every plane contact non-sliding": the same status
    (found / infeasible) with either clock, each witness passing find_state's checks."""
    system = models.System(models.rectangular(lx, ly), mu_pp=mpp, mu_plane=mpl, mu_wall=0.0,
                           gamma=gamma)
    lit = sliding if every else non_sliding
    P = Pattern().all_of([lit(int(a)) for a in _plane_contacts(system)])
    try:
        a = find_state(system, P, time_limit=60.0, clock="wall")
    except Exception as exc:  # no valid steady state, no velocity bound: the same either way
        with pytest.raises(type(exc)):
            find_state(system, P, time_limit=60.0, clock="cpu")
        return
    b = find_state(system, P, time_limit=60.0, clock="cpu")
    assert a.status == b.status, (a, b)
    assert a.proved == b.proved
