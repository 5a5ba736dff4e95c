"""benchmarks/order_split.py (the branch and bound on the order of w_i = sigma_i r alpha_i,
tried on Fig. 9's open ends and dropped, docs/benchmarks.md): its numbers are bounds.

* the closure: a chain with one strict step is strict, u < v = u is a contradiction, and a
  contact is ordered through a path of other disks;
* on small systems (issue 21's 10x1 rows, small arrays) with the target at an end the MILP
  proved (verify.ranges.steady_ranges), its bound reaches the end and never passes it; with
  the target above the end, it stays at or below the end; on random small arrays it never
  passes the end (the deep profile found two that it does not close: near-frictionless
  contacts, mu_pp ~ 1e-7, where it stalls on a point violating (*) only within the LP's
  tolerances, and a system without proved force bounds, where neither it nor the disk split
  applies; a case point's witness is compared to what its value is known to; examples whose
  MILP ends are not both "optimal", or said to have no valid steady state, are skipped);
* a deliberately wrong case bound (the certificate's value raised by 0.05) is caught by that
  same comparison.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from rigidlcp import models
from rigidlcp.verify.ranges import steady_ranges
from rigidlcp.verify.ranges.disk_split import disk_split_bound, witness_of
from rigidlcp.verify.ranges.observables import mu_g_vector
from rigidlcp.verify.ranges.result import witness_tolerance
from rigidlcp.verify.ranges.steady import NotSteady, formulate

_PATH = Path(__file__).resolve().parents[3] / "benchmarks" / "order_split.py"
_spec = importlib.util.spec_from_file_location("order_split_bench", _PATH)
osb = importlib.util.module_from_spec(_spec)
sys.modules[_spec.name] = osb  # its dataclasses look their module up there
_spec.loader.exec_module(osb)


def _system(lattice, gamma, mpp=0.1, mpl=0.2):
    return models.System(lattice, mu_pp=mpp, mu_plane=mpl, mu_wall=0.0, gamma=gamma)


def _milp_ends(system):
    try:
        r = steady_ranges(system, which="mu_g", time_limit=60, split=False)
    except NotSteady:  # no reference (the deep profile met it at mu_pp ~ 1e-7)
        return None
    if r.mu_g.lo.status == r.mu_g.hi.status == "optimal":
        return r.mu_g.lo.value, r.mu_g.hi.value
    return None


def _check_reaches_never_passes(system, max_cases=20000, must_close=True):
    ends = _milp_ends(system)
    if not must_close:  # a random system: compared only where the MILP decided both ends
        # (the deep profile met "failed" ends and NotSteady at mu_pp ~ 1e-7; the NotSteady was
    # HiGHS's presolve, now re-checked: test_milp_recheck.py)
        assume(ends is not None)
    assert ends is not None
    lo, hi = ends
    form = formulate(system)
    L = mu_g_vector(system)
    for cost, end in ((L, lo), (-L, -hi)):
        res = osb.order_split_bound(form, cost, end, 1e9, max_cases=max_cases)
        if res is None:  # not applicable (no proved force box or no rotation cap; a
            # rectangular array always 2-colours): exactly where the disk split is not
            assert not must_close
            assert disk_split_bound(form, cost, end, 1e9, max_cases=1) is None
            continue
        assert res.bound <= end + 1e-12, res
        assert res.closed or not must_close, res
        if res.closed:
            assert res.bound >= end - 1e-8 * max(1.0, abs(end)), res
        elif res.candidate is not None:  # stopped at a case point satisfying (*): where it
            # is a checked steady state, no better than the end
            w = witness_of(form, res.candidate)
            if w is not None:
                x = np.concatenate([w.R, w.S])
                # to what its value is known (its residual: verify.ranges.result)
                tol = witness_tolerance(system, cost, x, w.residual)
                assert float(cost @ x) >= end - 1e-8 * max(1.0, abs(end)) - tol
        # else: stalled (a case whose LP point violates (*) only on contacts already ordered,
        # within the LP's tolerances: seen with mu_pp ~ 1e-7); the bound above still holds
        above = osb.order_split_bound(form, cost, end + 0.05, 1e9, max_cases=40)
        assert above.bound <= end + 1e-12
        assert not above.closed


def test_closure():
    n = 4
    le, lt = np.eye(n, dtype=bool), np.zeros((n, n), dtype=bool)
    lt[0, 1] = True  # 0 < 1
    le[1, 2] = le[2, 1] = True  # 1 = 2
    le[2, 3] = True  # 2 <= 3
    cle, clt = osb.closure(le, lt)
    assert clt[0, 2] and clt[0, 3] and cle[1, 3] and not clt[1, 3]
    assert not np.any(np.diag(clt))
    le[3, 0] = True  # 3 <= 0: 0 < 1 = 2 <= 3 <= 0, a contradiction
    assert np.any(np.diag(osb.closure(le, lt)[1]))


def test_contact_ordered_through_a_path():
    """rect 2x2 (a square of contacts): three strict relations around the square order the
    fourth contact, which a split on each contact's own sign leaves open."""
    system = _system(models.rectangular(2, 2), 0.16)
    form = formulate(system)
    g = osb.order_graph(form, 0.16)
    assert g is not None
    le, lt = osb.initial_relations(g)
    two = [k for k in range(g.u.size) if g.v[k] < g.p]  # the disk-disk contacts
    assert len(two) == 4
    # the square's cycle: 0-1, 1-3, 3-2, 2-0 (disks row by row)
    edges = {frozenset((int(g.u[k]), int(g.v[k]))): k for k in two}
    path = [(0, 1), (1, 3), (3, 2)]
    for a, b in path:
        lt[a, b] = True
    le, lt = osb.closure(le, lt)
    case = osb.case_of(g, le, lt)
    assert case is not None
    fixed = case[1]
    k = edges[frozenset((2, 0))]
    assert k in fixed and fixed[k] != 0  # 0 < 2 through 1 and 3: its sign is fixed


@pytest.mark.parametrize("lattice, gamma", [(models.rectangular(3, 2), 0.16),
                                            (models.rectangular(2, 1), -0.1),
                                            (models.rectangular(4, 2), 0.1)])
def test_reaches_and_never_passes_the_milp_ends(lattice, gamma):
    _check_reaches_never_passes(_system(lattice, gamma))


@pytest.mark.parametrize("mpp, mpl, gamma", [(0.05, 0.1, 0.01), (0.1, 0.2, 0.02)])
def test_rows_10x1(mpp, mpl, gamma):
    _check_reaches_never_passes(_system(models.rectangular(10, 1), gamma, mpp, mpl))


@settings(max_examples=6)
@given(lx=st.integers(2, 4), ly=st.integers(1, 2), mpp=st.floats(0.0, 0.4),
       mpl=st.floats(0.05, 0.4), gamma=st.floats(0.01, 0.4))
def test_random_small_arrays(lx, ly, mpp, mpl, gamma):
    _check_reaches_never_passes(_system(models.rectangular(lx, ly), gamma, mpp, mpl),
                                must_close=False)


def test_a_wrong_case_bound_is_caught(monkeypatch):
    """Each case's bound raised by 0.05 (no longer the certificate's): the bound passes the
    MILP's end, which the comparison above rejects."""
    system = _system(models.rectangular(10, 1), 0.02)
    lo, _ = _milp_ends(system)
    form = formulate(system)
    from rigidlcp.verify.ranges import disk_split  # the case LPs run in its solve_with

    real = disk_split.certified_result

    def wrong(*args):
        b, x = real(*args)
        return (b + 0.05 if np.isfinite(b) else b), x

    monkeypatch.setattr(disk_split, "certified_result", wrong)
    res = osb.order_split_bound(form, mu_g_vector(system), lo, 1e9)
    assert res.bound > lo + 1e-12
