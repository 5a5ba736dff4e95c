"""Valid steady states through proportional velocities (verify.ranges.proportional,
docs/mechanics.md): the ranges of (R, S)-observables over the valid steady states are those of
one complementarity system without velocities, Q (a_n = 0, no translation, the cone, Coulomb
read off a_t). Checked here against

* the previous search with velocities in the MILP (lazy kinematic cuts, and big-M), which
  stays available as kinematics="lazy" / "big-M";
* a brute force written here over the sign patterns of a_t (an LP per pattern, from
  models.Dynamics, no velocity anywhere) on small systems, and on the 10x1 rows an MILP of Q
  written here with scipy's milp (its pattern's LP gives the value);
* the witnesses: velocities (omega, V) = (alpha, gamma) t, each passing steady_check.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.optimize import Bounds, LinearConstraint, linprog, milp

from rigidlcp import models
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.lattice import PLANE
from rigidlcp.verify.ranges import proportional, steady_ranges
from rigidlcp.verify.ranges.steady import formulate
from rigidlcp.verify.ranges.witness import steady_check


def _q_parts(system: models.System):
    """(acc, a_rel, a0, fr): nu' = acc x + Minv f, a = a_rel x + a0, the frictional contacts."""
    dyn = Dynamics(system)
    H, Minv, f = dyn.H.toarray(), dyn.Minv, dyn.f
    acc = Minv[:, None] * H.T
    a_rel = H @ acc
    a0 = H @ (Minv * f) + dyn.u_obs_dot
    return acc, a_rel, a0, np.flatnonzero(system.mu > 0)


def _brute(system: models.System, L: np.ndarray, sense: int, pattern_lp, best_over
           ) -> tuple[str, float]:
    """("optimal", value) / ("unbounded", inf) of L x over Q: the best of every a_t sign
    pattern's LP (conftest's pattern_lp and best_over)."""
    signs = itertools.product((1, -1, 0), repeat=_q_parts(system)[3].size)
    return best_over(L, sense, (pattern_lp(system, np.array(sig)) for sig in signs))


def _alpha_rows(system: models.System) -> np.ndarray:
    acc = _q_parts(system)[0]
    return acc[2 * system.p:]


def _check_witness(system: models.System, w, V_ref: float | None = None) -> None:
    """The witness moves at (alpha, gamma) t and passes the independent check."""
    g = system.gamma
    t = w.V / g if g != 0 else 1.0
    assert t > 0 or g == 0
    if V_ref is not None:
        assert w.V == pytest.approx(V_ref, rel=1e-12)
    assert np.allclose(w.omega, w.alpha * t, atol=1e-12 * max(1.0, t))
    v_scale = max(float(np.sqrt(system.g * system.lattice.radius)), abs(w.V))
    assert steady_check(system, w.omega, w.V, w.R, w.S, None, v_scale)[0] <= 1e-8
    assert w.residual <= 1e-8


@pytest.mark.parametrize("lattice, mu, gamma", [
    (models.rectangular(1, 1), (0.1, 0.2, 0.0), 0.1),
    (models.rectangular(1, 1), (0.1, 0.2, 0.0), 0.5),
    (models.rectangular(1, 1), (0.1, 0.2, 0.3), 0.3),
    (models.rectangular(2, 1), (0.1, 0.2, 0.0), 0.05),
    (models.rectangular(2, 1), (0.3, 0.1, 0.0), -0.15),
    (models.rectangular(3, 1), (0.05, 0.1, 0.0), 0.02),
])
def test_ranges_equal_brute_force_over_a_t_patterns(q_pattern_lp, lp_union_best, lattice, mu,
                                                     gamma):
    """mu_g and every alpha over all valid steady states (default kinematics: proportional)
    equal the extremes over every a_t sign pattern's LP, written here without velocities."""
    s = models.System(lattice, mu_pp=mu[0], mu_plane=mu[1], mu_wall=mu[2], gamma=gamma)
    res = steady_ranges(s, which="alpha", time_limit=30)
    c = s.c
    g = np.zeros(2 * c)
    g[c + np.flatnonzero(s.lattice.j == PLANE)] = 1.0 / (s.total_mass * s.g)
    obs = {"mu_g": g} | {f"alpha[{i}]": row for i, row in enumerate(_alpha_rows(s))}
    for name, L in obs.items():
        for end, sense in ((res.ranges[name].lo, 1), (res.ranges[name].hi, -1)):
            status, value = _brute(s, L, sense, q_pattern_lp, lp_union_best)
            assert end.status == status, (name, end)
            if status == "optimal":
                assert end.value == pytest.approx(value, abs=1e-9), name
                _check_witness(s, end.witness)


@pytest.mark.parametrize("lattice, gamma", [
    (models.rectangular(3, 2), 0.16),
    (models.triangular(3, 2), 0.16),
    (models.rectangular(2, 1), -0.1),
])
def test_proportional_equals_lazy_kinematics(lattice, gamma):
    """The MILP without velocities gives the ends of the one with lazy kinematic cuts."""
    s = models.System(lattice, mu_pp=0.1, mu_plane=0.2, mu_wall=0.0, gamma=gamma)
    a = steady_ranges(s, which="alpha", time_limit=60, kinematics="proportional")
    b = steady_ranges(s, which="alpha", time_limit=60, kinematics="lazy")
    for name, ra in a.ranges.items():
        rb = b.ranges[name]
        for ea, eb in ((ra.lo, rb.lo), (ra.hi, rb.hi)):
            assert ea.status == eb.status == "optimal", (name, ea, eb)
            assert ea.value == pytest.approx(eb.value, abs=1e-9), name
            _check_witness(s, ea.witness)


def _q_milp_value(system: models.System, L: np.ndarray, sense: int, U: float,
                  pattern_lp) -> float:
    """The extreme of L over Q with R <= U by an MILP written here (binaries per frictional
    contact: a_t >= 0 with S = -mu R, a_t <= 0 with S = +mu R, or a_t = 0), then the exact LP
    of its a_t pattern: the value."""
    c, p, mu = system.c, system.p, system.mu
    acc, a_rel, a0, fr = _q_parts(system)
    F = fr.size
    Minv_f = Dynamics(system).Minv * Dynamics(system).f
    n = 2 * c + 2 * F  # x | y+ | y-
    A_big = 2.0 * np.max(np.abs(a_rel[c:][fr])) * mu.max() * U * c + np.max(np.abs(a0))
    cons = []

    def row(xpart, yp=None, ym=None):
        r = np.zeros(n)
        r[:2 * c] = xpart
        for k, v in (yp or {}).items():
            r[2 * c + k] = v
        for k, v in (ym or {}).items():
            r[2 * c + F + k] = v
        return r

    for M, b in ((acc[:2 * p], -Minv_f[:2 * p]), (a_rel[:c], -a0[:c])):
        cons.append(LinearConstraint(np.hstack([M, np.zeros((M.shape[0], 2 * F))]), b, b))
    for k, al in enumerate(fr):
        eS, eR = np.zeros(2 * c), np.zeros(2 * c)
        eS[c + al], eR[al] = 1.0, mu[al]
        M = 2.0 * mu[al] * U
        cons += [LinearConstraint(row(eS - eR), -np.inf, 0),  # |S| <= mu R
                 LinearConstraint(row(-eS - eR), -np.inf, 0),
                 LinearConstraint(row(eS + eR, {k: M}), -np.inf, M),  # y+ => S = -mu R
                 LinearConstraint(row(eR - eS, ym={k: M}), -np.inf, M),  # y- => S = +mu R
                 LinearConstraint(row(a_rel[c + al], ym={k: A_big}), -a0[c + al], np.inf),
                 LinearConstraint(row(a_rel[c + al], yp={k: -A_big}), -np.inf, -a0[c + al]),
                 LinearConstraint(row(np.zeros(2 * c), {k: 1}, {k: 1}), -np.inf, 1)]
    lb = np.r_[np.zeros(c), -mu * U, np.zeros(2 * F)]
    ub = np.r_[np.full(c, U), mu * U, np.ones(2 * F)]
    res = milp(np.r_[sense * L, np.zeros(2 * F)], constraints=cons, bounds=Bounds(lb, ub),
               integrality=np.r_[np.zeros(2 * c), np.ones(2 * F)],
               options={"mip_rel_gap": 0.0, "time_limit": 120})
    assert res.status == 0
    y = np.round(res.x[2 * c:]).astype(int)
    sig = y[:F] - y[F:]
    lp = pattern_lp(system, sig)
    lp["bounds"] = [(0, U)] * c + list(lp["bounds"][c:])
    r = linprog(sense * L, **lp, method="highs",
                options={"primal_feasibility_tolerance": 1e-10})
    assert r.status == 0
    return sense * r.fun


@pytest.mark.parametrize("mu_pp, mu_plane, gamma", [(0.05, 0.1, 0.01), (0.1, 0.2, 0.02)])
def test_rows_10x1_equal_an_milp_of_Q_written_here(q_pattern_lp, mu_pp, mu_plane, gamma):
    """Fig. 11's 10x1 rows: mu_g and alpha_0, alpha_9 over all valid steady states equal the
    MILP of Q written here (forces boxed by U >= the proved bounds, which loses no extreme of
    an S-observable: docs/mechanics.md's self-stress reduction), and equal the lazy search."""
    s = models.System(models.rectangular(10, 1), mu_pp=mu_pp, mu_plane=mu_plane, mu_wall=0.0,
                      gamma=gamma)
    U = 100.0
    assert float(np.max(formulate(s).R_hi)) < U
    rows = _alpha_rows(s)
    extra = {"a0": rows[0], "a9": rows[9]}
    res = steady_ranges(s, extra, which="mu_g", time_limit=60)
    lazy = steady_ranges(s, extra, which="mu_g", time_limit=60, kinematics="lazy")
    c = s.c
    g = np.zeros(2 * c)
    g[c + np.flatnonzero(s.lattice.j == PLANE)] = 1.0 / (s.total_mass * s.g)
    for name, L in (("mu_g", g), ("a0", rows[0]), ("a9", rows[9])):
        for side, sense in (("lo", 1), ("hi", -1)):
            end = getattr(res.ranges[name], side)
            assert end.status == "optimal", (name, end)
            assert end.value == pytest.approx(_q_milp_value(s, L, sense, U, q_pattern_lp),
                                              abs=1e-9), name
            assert end.value == pytest.approx(getattr(lazy.ranges[name], side).value,
                                              abs=1e-9)
            _check_witness(s, end.witness)


def test_witnesses_move_at_the_runs_V():
    """Given a steady run, the witnesses' V is the run's V one time unit after its last event
    ((omega, V) = (alpha, gamma) t with t = V / gamma)."""
    s = models.System(models.rectangular(3, 1), mu_pp=0.05, mu_plane=0.1, mu_wall=0.0,
                      gamma=0.02)
    run = models.simulate(s, seed=1)
    assert run.status == "steady"
    res = steady_ranges(run, which="mu_g", time_limit=30)
    V_ref = run.final.V + s.gamma
    for end in (res.mu_g.lo, res.mu_g.hi):
        assert end.status == "optimal"
        _check_witness(s, end.witness, V_ref)


def test_not_exact_at_constant_velocity():
    """gamma = 0 with V0 != 0: Q holds forces no velocity admits, so auto keeps the
    kinematics and "proportional" is refused."""
    s = models.System(models.rectangular(2, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.0, V0=1.0)
    assert not proportional.exact(formulate(s))
    with pytest.raises(ValueError, match="not exact"):
        steady_ranges(s, time_limit=10, kinematics="proportional")
    free = models.System(models.rectangular(2, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                         gamma=0.1)
    assert proportional.exact(formulate(free))
    assert not proportional.exact(formulate(free, V_mode="negative"))


@given(gamma=st.floats(0.01, 0.6), mu_pp=st.floats(0.0, 0.5), mu_plane=st.floats(0.01, 0.5),
       lx=st.integers(1, 3))
def test_every_point_of_Q_is_a_valid_steady_state(q_pattern_lp, gamma, mu_pp, mu_plane, lx):
    """A random point of Q (an LP with a random objective over a random a_t pattern), moved
    at (alpha, gamma), passes steady_check: the reduction's direction (ii)."""
    s = models.System(models.rectangular(lx, 1), mu_pp=mu_pp, mu_plane=mu_plane, mu_wall=0.0,
                      gamma=gamma)
    rng = np.random.default_rng(int(gamma * 1e6) + lx)
    fr = _q_parts(s)[3]
    for _ in range(6):
        sig = rng.integers(-1, 2, fr.size)
        lp = q_pattern_lp(s, sig)
        lp["bounds"] = [(0, 50.0)] * s.c + list(lp["bounds"][s.c:])
        r = linprog(rng.normal(size=2 * s.c), **lp, method="highs",
                    options={"primal_feasibility_tolerance": 1e-10})
        if r.status != 0:
            continue
        R, S = r.x[:s.c], r.x[s.c:]
        alpha = _alpha_rows(s) @ r.x
        v_scale = max(float(np.sqrt(s.g * s.lattice.radius)), gamma)
        assert steady_check(s, alpha, gamma, R, S, None, v_scale)[0] <= 1e-8


# -- pattern questions: states checked only where a_t = 0 ------------------------------------


def _admitted(state_lps, system: models.System) -> list[np.ndarray]:
    """Every state set some valid steady state has (conftest's velocity and force LPs)."""
    return [s for s, lp in state_lps(system)
            if linprog(np.zeros(2 * system.c), **lp, method="highs").status in (0, 3)]


@pytest.mark.parametrize("size, mu, gamma", [((2, 2), (0.1, 0.2), 0.1),
                                             ((3, 1), (0.3, 0.1), -0.05)])
def test_patterns_checked_where_a_t_is_zero_equal_brute_force(state_lps, size, mu, gamma):
    """find_state with the kinematics asked only on the contacts with a_t = 0 ("lazy-a_t")
    answers as the brute force over every admitted state set, and as the full lazy check,
    for every contact fixed to each state and for deterministic pairs of fixed contacts."""
    from rigidlcp.verify.ranges.patterns import FOUND, Lit, Pattern, find_state, non_sliding

    s = models.System(models.rectangular(*size), mu_pp=mu[0], mu_plane=mu[1], mu_wall=0.0,
                      gamma=gamma)
    admitted = _admitted(state_lps, s)
    fr = [int(a) for a in np.flatnonzero(s.mu > 0)]
    rng = np.random.default_rng(7)
    asks = [{a: v} for a in fr for v in (1, -1, 0)]
    asks += [dict(zip(rng.choice(fr, 2, replace=False).tolist(),
                      rng.choice([1, -1, 0], 2).tolist())) for _ in range(8)]
    form = formulate(s)
    for fixed in asks:
        P = Pattern()
        for a, v in fixed.items():
            P.all_of([Lit((({1: "y+", -1: "y-"}[v], a, 1.0),), lo=1.0)] if v else
                     [non_sliding(a)])
        want = any(all(t[a] == v for a, v in fixed.items()) for t in admitted)
        for kin in ("lazy-a_t", "lazy"):
            res = find_state(form, P, time_limit=30, kinematics=kin)
            assert res.status == (FOUND if want else "infeasible"), (fixed, kin, res)
            if want:
                assert res.witness.residual <= 1e-8
                assert all(res.witness.s[a] == v for a, v in fixed.items())


def test_lazy_a_t_refused_where_not_exact():
    from rigidlcp.verify.ranges.milp import MilpModel

    s = models.System(models.rectangular(2, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.0, V0=1.0)
    with pytest.raises(ValueError, match="lazy-a_t"):
        MilpModel(formulate(s), "lazy-a_t")
