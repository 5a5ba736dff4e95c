"""verify.ranges.disk_split (a proved bound by a case split on the disks' cap states):

* its facts hold on checked valid steady states: the power identity (computed here from
  models.Dynamics), the cut, every sign-fixed contact's S = -+mu R, and the witness lies in
  the LP of its own case (row by row), and the velocities (alpha, gamma) make its forces a
  checked steady state (no case on velocities);
* with the target at an end proved by the MILP, the bound reaches the end and never passes
  it; with a target above, it stays at or below the end, whatever the budget;
* the 10x1 rows of issue 21's table (both ends proved by the MILP), where the cap split
  stays far below the minimum, and a case point satisfying every law becomes a checked
  witness.
"""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.verify.ranges import End, Range, steady_ranges
from rigidlcp.verify.ranges.bounds import rotation_cap
from rigidlcp.verify.ranges.cap_split import bound_open_ends, cap_split_bound
from rigidlcp.verify.ranges.disk_split import (
    DOWN,
    INSIDE,
    UP,
    _Cases,
    disk_split_bound,
    witness_of,
)
from rigidlcp.verify.ranges.observables import mu_g_vector
from rigidlcp.verify.ranges.steady import formulate

SYSTEMS = [(models.rectangular(3, 2), 0.16), (models.triangular(3, 2), 0.16),
           (models.rectangular(2, 1), -0.1)]
ROWS = [(0.05, 0.1, 0.01), (0.05, 0.1, 0.02), (0.1, 0.2, 0.02)]  # rect 10x1, issue 21


def _system(lattice, gamma, mpp=0.1, mpl=0.2):
    return models.System(lattice, mu_pp=mpp, mu_plane=mpl, mu_wall=0.0, gamma=gamma)


def _ends_and_witnesses(system, which="mu_g"):
    r = steady_ranges(system, which=which, time_limit=60, split=False)
    wits = [e.witness for rg in r.ranges.values() for e in (rg.lo, rg.hi)
            if e.witness is not None and e.witness.residual <= 1e-8]
    return r, wits


@pytest.mark.parametrize("lattice, gamma", SYSTEMS)
def test_case_facts_hold_on_valid_steady_states(lattice, gamma):
    system = _system(lattice, gamma)
    form = formulate(system)
    dyn, c, p = form.dyn, system.c, system.p
    M = rotation_cap(system, dyn)
    cases = _Cases(form, mu_g_vector(system), M)
    _, wits = _ends_and_witnesses(system, "alpha")
    assert wits
    r = system.lattice.radius
    I = 1.0 / dyn.Minv[2 * p:]
    kept = 0.0
    for w in wits:
        lam = np.concatenate([w.R, w.S])
        scale = max(1.0, float(np.max(np.abs(lam))))
        nu = dyn.accelerations(lam)
        a = dyn.H @ nu + dyn.u_obs_dot
        # the power identity and the cut, from Newton-Euler here
        power = float(np.sum(I * nu[2 * p:] ** 2))
        drive = -float(np.dot(dyn.u_obs_dot, lam))
        assert power == pytest.approx(float(np.dot(a[c:], w.S)) + drive, abs=1e-12 * scale)
        assert drive >= power - 1e-12 * scale
        # the witness's own case: each disk at its cap state
        ra = r * nu[2 * p:]
        disks = np.where(np.abs(ra - M) <= 1e-9 * M, UP,
                         np.where(np.abs(ra + M) <= 1e-9 * M, DOWN, INSIDE))
        sgn = cases.sign_of_a(disks)
        fr = cases.fric
        for k, al in enumerate(fr):
            if sgn[k] in (1, -1):
                assert np.sign(a[c + al]) == sgn[k]
                assert w.S[al] == pytest.approx(-sgn[k] * system.mu[al] * w.R[al],
                                                abs=1e-8 * scale)
        lo, hi = cases.bounds(disks, {})
        z = ra ** 2 / (r * r * dyn.Minv[2 * p:])
        xz = np.concatenate([lam, z])
        row = cases.A @ xz
        row[cases.r_pw] = cases.power_row(disks) @ xz  # the case's own power cut
        # ... which keeps exactly the terms -S a of the contacts with a constant a_t != 0
        const = np.array([(lambda iv: iv[0] == iv[1] and iv[0] != 0)(cases.interval(disks, k))
                          for k in range(fr.size)])
        rest = -float(np.dot(w.S[fr[~const]], a[c + fr[~const]]))
        assert row[cases.r_pw] == pytest.approx(rest, abs=1e-12 * scale)
        kept += float(np.sum(np.abs(w.S[fr[const]] * a[c + fr[const]])))
        tol = 1e-8 * scale
        assert np.all(row >= lo - tol) and np.all(row <= hi + tol)
        assert np.all(z <= cases.ub[2 * c:] + 1e-15)
        # the velocities need no case: (omega, V) = (alpha, gamma) makes the forces a checked
        # valid steady state (docs/mechanics.md)
        again = witness_of(form, lam)
        assert again is not None and again.residual <= 1e-8
        np.testing.assert_allclose(again.S, w.S)
    assert kept > 0  # some witness has a sliding contact of constant a_t in its case


@pytest.mark.parametrize("lattice, gamma", SYSTEMS)
def test_bound_reaches_and_never_passes_the_milp_ends(lattice, gamma):
    system = _system(lattice, gamma)
    r, _ = _ends_and_witnesses(system)
    assert r.mu_g.lo.status == r.mu_g.hi.status == "optimal"
    form = formulate(system)
    L = mu_g_vector(system)
    for cost, end in ((L, r.mu_g.lo.value), (-L, -r.mu_g.hi.value)):
        res = disk_split_bound(form, cost, end, time_limit=60)
        assert res.bound <= end + 1e-12
        assert res.bound >= end - 1e-8 * max(1.0, abs(end)), res
        above = disk_split_bound(form, cost, end + 0.05, time_limit=2)
        assert above.bound <= end + 1e-12
        assert not above.closed


@pytest.mark.slow
@pytest.mark.parametrize("mpp, mpl, gamma", ROWS)
def test_rows_of_issue_21_min_proved_by_the_disk_split(mpp, mpl, gamma):
    """rect 10x1: the MILP's ends [0.0145179, 0.0976197], [0.0290357, 0.1], [0.0669235,
    0.1911561] (docs/benchmarks.md) are reached by the disk split's bound, where the cap
    split gives only 0.005-0.01 for the minimum."""
    system = _system(models.rectangular(10, 1), gamma, mpp, mpl)
    r, _ = _ends_and_witnesses(system)
    lo, hi = r.mu_g.lo.value, r.mu_g.hi.value
    form = formulate(system)
    L = mu_g_vector(system)
    assert cap_split_bound(form, L).bound < 0.75 * lo
    res = disk_split_bound(form, L, lo, time_limit=60)
    assert lo - 1e-8 <= res.bound <= lo + 1e-12
    if res.candidate is not None:  # a case point satisfying (*): a checked witness at lo
        w = witness_of(form, res.candidate)
        assert w is not None and w.residual <= 1e-8
        assert w.mu_g == pytest.approx(lo, abs=1e-9)
    res = disk_split_bound(form, -L, -hi, time_limit=60)
    assert -hi - 1e-8 <= res.bound <= -hi + 1e-12


@pytest.mark.slow
def test_open_end_decided_by_the_disk_split():
    """An end left open (here: no MILP time) is decided by the disk split with a checked
    witness, at the MILP's value; with the cap split alone it stays open."""
    system = _system(models.rectangular(10, 1), 0.01, 0.05, 0.1)
    ref, _ = _ends_and_witnesses(system)
    form = formulate(system)
    obs = {"mu_g": mu_g_vector(system)}
    for deep, decided in ((0.0, False), (30.0, True)):
        rg = {"mu_g": Range("mu_g", End("time limit"), End("time limit"))}
        bound_open_ends(form, rg, obs, deep)
        e = rg["mu_g"].lo
        assert (e.status == "optimal") == decided, e.note
        assert e.bound <= ref.mu_g.lo.value + 1e-12
        if decided:
            assert e.value == pytest.approx(ref.mu_g.lo.value, abs=1e-9)
            assert e.witness.residual <= 1e-8


@pytest.mark.slow
def test_fig9_disk_split_below_the_checkerboard():
    """Fig. 9's system: a few hundred cases give a finite bound below the least mu_g met (the
    rolling checkerboard, 0.1050919; a valid state, so no bound may pass it)."""
    system = _system(models.rectangular(10, 4), 0.16)
    form = formulate(system)
    res = disk_split_bound(form, mu_g_vector(system), 0.1050919, 1e9, max_cases=300)
    assert np.isfinite(res.bound) and res.bound <= 0.1050919
