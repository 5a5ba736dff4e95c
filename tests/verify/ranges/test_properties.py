"""Properties of verify.ranges on random small systems (hypothesis): every witness satisfies
the laws (checked here, from models.Dynamics, not by the code under test), both ends are
attained, the engine's own selection lies in its range; and typed errors on bad input."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp, models
from rigidlcp.lcp.errors import RigidLCPError
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.verify.ranges import event_ranges, steady_ranges
from rigidlcp.verify.ranges.observables import BadObservable
from rigidlcp.verify.ranges.steady import NotSteady


def _laws(system, w, tol=1e-8) -> bool:
    """The definition of docs/mechanics.md, written out again."""
    dyn = Dynamics(system)
    c, p, mu = system.c, system.p, system.mu
    x = np.concatenate([w.R, w.S])
    nu_dot = dyn.Minv * (dyn.H.T @ x + dyn.f)
    a = dyn.H @ nu_dot + dyn.u_obs_dot
    v = dyn.H @ np.r_[np.zeros(2 * p), w.omega] + dyn.u_obs(w.V)
    scale = max(1.0, float(np.abs(x).max()))
    vs = max(float(np.abs(v[c:]).max()), 1e-300)
    ok = np.all(np.abs(nu_dot[:2 * p]) <= tol * scale) and np.all(np.abs(a[:c]) <= tol * scale)
    ok &= np.all(w.R >= -tol * scale) and np.all(np.abs(w.S) <= mu * w.R + tol * scale)
    for al in range(c):
        if mu[al] == 0:
            ok &= abs(w.S[al]) <= tol * scale
        elif abs(v[c + al]) <= 1e-9 * vs:
            ok &= abs(a[c + al]) <= tol * scale
        else:
            sg = np.sign(v[c + al])
            ok &= abs(w.S[al] + sg * mu[al] * w.R[al]) <= tol * scale
            ok &= sg * a[c + al] >= -tol * scale
    ok &= np.allclose(w.alpha, nu_dot[2 * p:], atol=tol * scale)
    return bool(ok)


systems = st.builds(
    lambda lx, ly, mu_pp, mu_plane, mu_wall, gamma: models.System(
        models.rectangular(lx, ly), mu_pp=mu_pp, mu_plane=mu_plane, mu_wall=mu_wall,
        gamma=gamma),
    st.integers(1, 3), st.integers(1, 2), st.sampled_from([0.0, 0.05, 0.1, 0.3]),
    st.sampled_from([0.1, 0.2, 0.4]), st.sampled_from([0.0, 0.0, 0.1]),
    st.sampled_from([0.01, 0.05, 0.16, -0.1]))


@settings(max_examples=8)
@given(systems, st.integers(0, 3))
def test_steady_witnesses_lawful_attained_and_run_inside(system, seed):
    run = models.simulate(system, seed=seed, max_events=200)
    target = run if run.status == "steady" else system
    res = steady_ranges(target, which="alpha", time_limit=20)
    for r in res.ranges.values():
        for e in (r.lo, r.hi):
            assert e.status in ("optimal", "unbounded"), (r.name, e)
            assert _laws(system, e.witness)
            if e.status == "optimal":
                L = (res.mu_g if r.name == "mu_g" else r)
                value = e.witness.mu_g if r.name == "mu_g" else e.witness.alpha[
                    int(r.name[6:-1])]
                assert value == pytest.approx(e.value, abs=1e-9), L.name
        if run.status == "steady":
            assert r.contains(r.selected, tol=1e-8), (r.name, r.selected, r)
            own = res.own[r.name]
            assert own.lo.value >= r.lo.value - 1e-9 and own.hi.value <= r.hi.value + 1e-9


@settings(max_examples=10)
@given(systems, st.integers(0, 3))
def test_event_selected_solution_lies_in_its_ranges(system, seed):
    state = models.initial_state(system, seed=seed)
    ep = models.event_problem(system, state)
    sol = lcp.solve(ep.lcp)
    if sol.status != "solved":
        return
    res = event_ranges(ep, sol, time_limit=10)
    for name, r in res.every.items():
        f = res.face[name]
        for e in (r.lo, r.hi, f.lo, f.hi):
            assert e.status in ("optimal", "unbounded"), (name, e)
        assert f.contains(res.selected[name], tol=1e-8) and r.contains(res.selected[name],
                                                                       tol=1e-8)


def test_typed_errors():
    s = models.System(models.rectangular(2, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.05)
    with pytest.raises(BadObservable):
        steady_ranges(s, {"mine": np.ones(3)})
    ep = models.event_problem(s, models.initial_state(s))
    with pytest.raises(BadObservable):
        event_ranges(ep, None, {"mine": np.ones(2 * s.c + 1)})
    short = models.simulate(s, seed=1, t_max=1e-4)
    with pytest.raises(NotSteady):
        steady_ranges(short)
    assert issubclass(NotSteady, RigidLCPError) and issubclass(BadObservable, RigidLCPError)


def test_steady_ranges_takes_a_matrix_and_refuses_other_observables_typed():
    """Audit of issue 21 (bad input): steady_ranges took only a dict, and anything else (a
    string, a matrix as event_ranges accepts) raised AttributeError ('str' object has no
    attribute 'items'). A matrix's rows are the observables user[k], as in event_ranges: a row
    equal to mu_g's own vector has mu_g's range; anything else is BadObservable."""
    from rigidlcp.verify.ranges.observables import mu_g_vector
    s = models.System(models.rectangular(2, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.05)
    for bad in ("all", "mu_g", object(), [["a", "b"]]):
        with pytest.raises(BadObservable):
            steady_ranges(s, bad)
    res = steady_ranges(s, np.vstack([mu_g_vector(s), -mu_g_vector(s)]), time_limit=30)
    mu, user, neg = res.ranges["mu_g"], res.ranges["user[0]"], res.ranges["user[1]"]
    assert user.lo.value == pytest.approx(mu.lo.value, abs=1e-12)
    assert user.hi.value == pytest.approx(mu.hi.value, abs=1e-12)
    assert neg.lo.value == pytest.approx(-mu.hi.value, abs=1e-12)
    assert neg.hi.value == pytest.approx(-mu.lo.value, abs=1e-12)


def test_an_unproved_box_is_said_once_in_the_scope():
    """Audit: on docs/verification.md's own example (2x1 from rest: LCP(M, 0) has a nonzero
    solution, so no bound on |z| is proved) each range's scope read "(no bound proved: no
    bound proved: the MILP's point ...)"."""
    s = models.System(models.rectangular(2, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.1)
    ep = models.event_problem(s, models.initial_state(s))
    res = event_ranges(ep, lcp.solve(ep.lcp), time_limit=10)
    assert not res.bound_proved
    for r in res.every.values():
        assert r.scope.count("no bound proved") == 1, r.scope


_ANY_OBSERVABLES = st.one_of(
    st.none(), st.text(max_size=5), st.integers(), st.floats(),
    st.lists(st.floats(), max_size=7),
    st.lists(st.lists(st.floats(), min_size=0, max_size=7), max_size=3),
    st.lists(st.lists(st.text(max_size=2), max_size=3), max_size=2),
    st.dictionaries(st.text(max_size=3), st.lists(st.floats(), max_size=7), max_size=3),
    st.builds(object))


@settings(max_examples=200)
@given(_ANY_OBSERVABLES, st.integers(1, 6))
def test_user_observables_are_checked_vectors_or_bad_observable(obs, size):
    """Whatever a user passes as observables: finite vectors of the stated size, named, or
    BadObservable (never another exception): the one checker of event_ranges and
    steady_ranges."""
    from rigidlcp.verify.ranges.observables import user_observables
    try:
        out = user_observables(obs, size)
    except BadObservable:
        return
    assert isinstance(out, dict)
    for name, v in out.items():
        assert isinstance(name, str) and v.shape == (size,) and np.all(np.isfinite(v))
