"""Time limits counted in CPU seconds (verify.ranges.milp.clock, MilpModel(..., "cpu"),
steady_ranges(clock="cpu"), disk_split_bound(clock_name="cpu")):

* the clock changes when a search stops, never what a finished search answers: every end of
  the small systems (issue 21's 10x1 rows, random small arrays) is the same with either clock
  (on random arrays also a "failed" end or "no valid steady state": the deep profile met both
  at mu_pp ~ 1e-7, with either clock; the second was HiGHS's presolve, now re-checked:
  test_milp_recheck.py);
* a CPU limit reached is a time limit, never a bound or "optimal", and it does not leak into
  the next solve of the same model (HiGHS keeps the interrupt flag between runs: a model whose
  callback only ever *set* it answered "time limit" at once from then on);
* a wrong clock is refused before any work (ValueError).

No timed assertion: only statuses and values.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import models
from rigidlcp.verify.ranges import steady_ranges
from rigidlcp.verify.ranges.disk_split import disk_split_bound
from rigidlcp.verify.ranges.milp import MilpModel, clock
from rigidlcp.verify.ranges.observables import mu_g_vector
from rigidlcp.verify.ranges.result import OPTIMAL, TIME_LIMIT
from rigidlcp.verify.ranges.steady import NotSteady, formulate


def _system(lx, ly, mpp, mpl, gamma):
    return models.System(models.rectangular(lx, ly), mu_pp=mpp, mu_plane=mpl, mu_wall=0.0,
                         gamma=gamma)


def _ends(r):
    return {(name, side): (getattr(rg, side).status, getattr(rg, side).value)
            for name, rg in r.ranges.items() for side in ("lo", "hi")}


def _answer(system, which, clock_name):
    try:
        return _ends(steady_ranges(system, which=which, time_limit=60, split=False,
                                   clock=clock_name))
    except NotSteady as e:  # an answer too ("no valid steady state")
        return str(e)


def _same_ends(system, which="mu_g", all_optimal=True):
    a, b = _answer(system, which, "wall"), _answer(system, which, "cpu")
    if isinstance(a, str) or isinstance(b, str):
        assert a == b
        return
    assert a.keys() == b.keys()
    for k in a:
        assert a[k][0] == b[k][0], (k, a[k], b[k])
        assert a[k][0] == OPTIMAL or not all_optimal, (k, a[k])
        if a[k][0] == OPTIMAL:
            assert b[k][1] == pytest.approx(a[k][1], abs=1e-9), k


@pytest.mark.parametrize("mpp, mpl, gamma", [(0.05, 0.1, 0.01), (0.1, 0.2, 0.02)])
def test_rows_10x1_same_ends_with_either_clock(mpp, mpl, gamma):
    _same_ends(_system(10, 1, mpp, mpl, gamma))


@settings(max_examples=6)
@given(lx=st.integers(2, 4), ly=st.integers(1, 2), mpp=st.floats(0.0, 0.4),
       mpl=st.floats(0.05, 0.4), gamma=st.floats(0.01, 0.4))
def test_small_arrays_same_ends_with_either_clock(lx, ly, mpp, mpl, gamma):
    _same_ends(_system(lx, ly, mpp, mpl, gamma), which="alpha", all_optimal=False)


@pytest.fixture(scope="module")
def fig9_form():
    return formulate(_system(10, 4, 0.1, 0.2, 0.16))


def test_cpu_limit_is_a_time_limit_and_does_not_leak(fig9_form):
    """Fig. 9's min mu_g (open at any limit used so far: docs/benchmarks.md) stopped by a tiny
    CPU limit is "time limit" (HiGHS: interrupted); the next objective on the same model, max
    mu_g (closed at HiGHS's root, = mu_plane 0.2), is then solved to optimality."""
    form = fig9_form
    model = MilpModel(form, "proportional", "cpu")
    L = np.zeros(form.A.shape[1])
    L[:2 * form.system.c] = mu_g_vector(form.system)
    st_lo, _ = model.solve(L, 1e-3)
    assert st_lo == TIME_LIMIT
    assert model.h.getModelStatus() == model.hs.HighsModelStatus.kInterrupt
    st_hi, x = model.solve(-L, 120.0)
    assert st_hi == OPTIMAL
    assert float(L @ x) == pytest.approx(0.2, abs=1e-9)


def test_disk_split_same_bound_with_either_clock():
    """The disk split's bound after a fixed number of cases does not depend on the clock."""
    system = _system(10, 1, 0.1, 0.2, 0.02)
    form = formulate(system)
    L = mu_g_vector(system)
    a = disk_split_bound(form, L, 1.0, 1e9, max_cases=60, clock_name="wall")
    b = disk_split_bound(form, L, 1.0, 1e9, max_cases=60, clock_name="cpu")
    assert (a.bound, a.cases, a.open, a.empty) == (b.bound, b.cases, b.open, b.empty)


def test_wrong_clock_refused():
    with pytest.raises(ValueError, match="clock"):
        clock("gpu")
    with pytest.raises(ValueError, match="clock"):
        steady_ranges(_system(2, 1, 0.1, 0.2, 0.1), clock="gpu")
