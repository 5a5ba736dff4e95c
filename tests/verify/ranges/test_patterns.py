"""verify.ranges.patterns: "is there a valid steady state with these contact states / forces /
alpha?" against answers derived by hand (tests/verify/ranges/test_steady_closed_forms.py's
single disk and frictionless row, units m = r = g = 1) and against brute force written here
(every tangential state set of a 2x2 array and a 3x1 row, a velocity LP and a force LP
each)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from rigidlcp import models
from rigidlcp.models.lattice import PLANE
from rigidlcp.verify.ranges.patterns import (
    FOUND,
    Lit,
    Pattern,
    at_least,
    at_most,
    find_state,
    non_sliding,
    sliding,
)
from rigidlcp.verify.ranges.witness import steady_check


def _disk(gamma: float, mu_wall: float = 0.0) -> models.System:
    return models.System(models.rectangular(1, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=mu_wall,
                         gamma=gamma)


def _plane(system, d: int = 0) -> int:
    lat = system.lattice
    return int(np.flatnonzero((lat.i == d) & (lat.j == PLANE))[0])


def _accepted(system, res, states: dict[int, int] | None = None) -> None:
    """A witness: valid (steady_check, called here) and with the states asked."""
    assert res.status == FOUND, res
    w = res.witness
    assert steady_check(system, w.omega, w.V, w.R, w.S)[0] <= 1e-8
    for a, s in (states or {}).items():
        assert w.s[a] == s, (a, w.s)


@pytest.mark.parametrize("gamma, rolls", [(0.1, True), (0.5, False)])
def test_single_disk_rolls_or_slides_by_hand(gamma, rolls):
    """Smooth walls: rolling needs S_P = gamma / 2 <= mu_P = 0.2; sliding with v_t < 0 needs
    gamma >= 0.4; sliding with v_t > 0 never (test_steady_closed_forms). So at gamma = 0.1
    the plane contact is non-sliding in every valid steady state, at 0.5 sliding with
    v_t < 0 in every one; each answer "none" is proved (the force bounds are)."""
    s = _disk(gamma)
    P = _plane(s)
    ns = find_state(s, Pattern().all_of([non_sliding(P)]))
    sl = find_state(s, Pattern().all_of([sliding(P)]))
    up = find_state(s, Pattern().all_of([Lit((("y+", P, 1.0),), lo=1.0)]))
    assert up.status == "infeasible" and up.proved
    yes, no = (ns, sl) if rolls else (sl, ns)
    _accepted(s, yes, {P: 0 if rolls else -1})
    assert no.status == "infeasible" and no.proved, no
    # alpha = -gamma on the rolling disk, -0.4 on the sliding one: r alpha <= -0.3 only at 0.5
    fast = find_state(s, Pattern().all_of([at_most("ra", 0, -0.3)]))
    assert (fast.status == FOUND) != rolls


def test_a_strict_literal_at_its_threshold_is_unknown_not_a_verdict():
    """Single disk, smooth walls: R_P = 1 in every valid steady state (the vertical balance).
    "R_P >= 1" has a witness; "R_P > 1" is solved closed first (R_P >= 1: feasible, but the
    witness fails the strict test), then tightened (R_P >= 1 + margin: infeasible), so the
    answer is "unknown" (only states at the threshold): the closed MILP cannot prove a strict
    "none". "R_P > 1.1" is infeasible already closed: "none", proved."""
    s = _disk(0.1)
    P = _plane(s)
    _accepted(s, find_state(s, Pattern().all_of([at_least("R", P, 1.0)])))
    edge = find_state(s, Pattern().all_of([at_least("R", P, 1.0, strict=True, margin=1e-6)]))
    assert edge.status == "unknown" and edge.witness is None, edge
    far = find_state(s, Pattern().all_of([at_least("R", P, 1.1, strict=True, margin=1e-6)]))
    assert far.status == "infeasible" and far.proved, far


def test_frictionless_row_every_disk_rolls():
    """rect 3x1, mu_pp = mu_wall = 0: each disk is the single disk (no torque but the
    plane's), so every disk rolls (mode 1: plane non-sliding and transmitting, R_P = 1) in
    every valid steady state: "some plane contact slides" and "fewer than three disks in
    mode 1" are infeasible, "all three" has a witness."""
    s = models.System(models.rectangular(3, 1), mu_pp=0.0, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.1)
    pl = [_plane(s, d) for d in range(3)]
    some = find_state(s, Pattern().any_of([[sliding(a)] for a in pl]))
    assert some.status == "infeasible" and some.proved
    P = Pattern()
    for k, a in enumerate(pl):  # m_k => mode 1 (R > 0.5); n_k => not; one of them (a count
        # of the m_k counts the disks in mode 1 only with both sides: guards are one-way)
        P.all_of([non_sliding(a), at_least("R", a, 0.5, strict=True)],
                 guard=P.indicator(f"m{k}"))
        P.any_of([[sliding(a)], [at_most("R", a, 0.5)]], guard=P.indicator(f"n{k}"))
        P.count({f"m{k}": 1, f"n{k}": 1}, 1, 1)
    for n, want in ((3, FOUND), (2, "infeasible")):
        Q = Pattern(list(P.clauses), list(P.indicators), list(P.counts))
        Q.count({f"m{k}": 1 for k in range(3)}, n, n)
        res = find_state(s, Q)
        assert res.status == want, (n, res)
    _accepted(s, find_state(s, P.count({"m0": 1, "m1": 1, "m2": 1}, 3, 3)), {a: 0 for a in pl})


def test_rough_walls_answers_within_the_box_only():
    """One disk between rough walls (mu_W = 0.1, gamma 0.1): the walls can hold the disk up,
    R_P = 0 (test_steady_closed_forms: mu_g reaches 0), a witness; sliding with v_t > 0 on the
    plane is impossible (ibid.), but the force bound is not proved there (S unbounded on the
    relaxation), so "infeasible" says within the force box (proved False)."""
    s = _disk(0.1, mu_wall=0.1)
    P = _plane(s)
    held = find_state(s, Pattern().all_of([at_most("R", P, 1e-12)]))
    _accepted(s, held)
    up = find_state(s, Pattern().all_of([Lit((("y+", P, 1.0),), lo=1.0)]))
    assert up.status == "infeasible" and not up.proved


# -- brute force: every tangential state set of a small array -----------------------------------


def _admitted(state_lps, system: models.System) -> list[np.ndarray]:
    """Every state set in {+1, -1, 0}^F that some valid steady state has: velocities with
    those signs (V free) and forces with the laws (docs/mechanics.md; conftest's LPs)."""
    return [s for s, lp in state_lps(system)
            if linprog(np.zeros(2 * system.c), **lp, method="highs").status in (0, 3)]


SYSTEMS = [((2, 2), dict(mu_pp=0.1, mu_plane=0.2, gamma=0.1)),
           ((3, 1), dict(mu_pp=0.3, mu_plane=0.1, gamma=-0.05))]
_CACHE: dict[int, tuple] = {}


def _system(state_lps, k: int):
    if k not in _CACHE:
        size, mu = SYSTEMS[k]
        s = models.System(models.rectangular(*size), mu_wall=0.0, **mu)
        _CACHE[k] = (s, _admitted(state_lps, s))
    return _CACHE[k]


@pytest.mark.slow
@settings(max_examples=12, deadline=None)
@given(k=st.integers(0, len(SYSTEMS) - 1), data=st.data())
def test_state_patterns_agree_with_brute_force(state_lps, k, data):
    """A random pattern of states (some contacts fixed to a state, one "some of these slide"
    clause): feasible iff some admitted state set matches it; every witness is valid
    (steady_check) and has the states asked."""
    s, admitted = _system(state_lps, k)
    fr = [int(a) for a in np.flatnonzero(s.mu > 0)]
    fixed = data.draw(st.dictionaries(st.sampled_from(fr), st.sampled_from((1, -1, 0)),
                                      max_size=3))
    anyof = data.draw(st.lists(st.sampled_from(fr), max_size=3, unique=True))
    P = Pattern()
    for a, v in fixed.items():
        P.all_of([Lit((({1: "y+", -1: "y-"}[v], a, 1.0),), lo=1.0)] if v else
                 [non_sliding(a)])
    if anyof:
        P.any_of([[sliding(a)] for a in anyof])
    want = any(all(t[a] == v for a, v in fixed.items())
               and (not anyof or any(t[a] != 0 for a in anyof)) for t in admitted)
    res = find_state(s, P, time_limit=30)
    assert res.status == (FOUND if want else "infeasible"), (fixed, anyof, res)
    if want:
        _accepted(s, res, fixed)
        if anyof:
            assert any(res.witness.s[a] != 0 for a in anyof)

