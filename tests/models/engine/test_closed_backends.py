"""The closed-solution search beyond the dense event backend (issue 22, point 4): the sparse
backend (models/engine/sparse_closed.py) and the time-stepper (models/step_closed.py) report a
detachment that the event (step) forces, and follow a closed solution where one exists, as the
dense backend does (tests/models/engine/test_closed.py). By hand: the V-groove of
tests/verify/statics/test_groove.py (forced from mu > 1/3; below, the closed solution of least
sum R derived there)."""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.models.engine.closed import event_closed, search
from rigidlcp.models.engine.sparse import simulate_sparse
from rigidlcp.models.engine.sparse_closed import sparse_closed
from rigidlcp.models.step_closed import search_step
from rigidlcp.models.step_lcp import StepProblem, coulomb_residual
from rigidlcp.models.timestepping import moreau_jean

from ...verify.statics.test_groove import _closed_by_hand, _groove
from .test_closed import _small_case, laws_residual, scale_of

EXAMPLES = (settings.get_profile("deep").max_examples
            if os.environ.get("HYPOTHESIS_PROFILE") == "deep" else 10)
PROVED = "proved: no solution of the {} keeps every contact closed"


def _spinning_groove(mu: float):
    system = _groove(mu)
    return system, models.initial_state(system, omega=np.array([0.0, 0.0, 1.0]))


def _same_verdict(system, state):
    """The dense and the sparse forms of one event's closed problem, and both verdicts."""
    ep = models.event_problem(system, state)
    dense = event_closed(ep)
    sparse = sparse_closed(system, state, models.Dynamics(system)).problem
    scale = scale_of(ep)
    size = max(1.0, float(np.abs(dense.M).max()))
    assert np.abs(sparse.M.toarray() - dense.M).max() <= 1e-13 * size
    assert np.abs(sparse.A.toarray() - dense.A).max() <= 1e-13 * size
    assert np.abs(sparse.q - dense.q).max() <= 1e-13 * scale
    assert np.abs(sparse.b - dense.b).max() <= 1e-13 * scale
    return ep, search(dense, scale, 1e-8), search(sparse, scale, 1e-8)


@settings(deadline=None, max_examples=EXAMPLES)
@given(n=st.integers(3, 8), seed=st.integers(0, 10_000), mu=st.sampled_from([0.1, 0.3, 0.5, 0.8]),
       spins=st.booleans())
def test_sparse_and_dense_searches_agree(n, seed, mu, spins):
    """On small seeded piles the sparse backend's event LCP is the dense one (to rounding), and
    the search gives the same verdict on both: "none" on one is "none" on the other, and a
    closed solution found on either has the same least sum R and satisfies the event's laws
    (independent residual); "undecided" only at the limits, on both."""
    system, state = _small_case(n, seed, mu, spins)
    ep, d, s = _same_verdict(system, state)
    assert d.status == s.status, (d.message, s.message)
    if d.status == "found":
        R_d, R_s = d.z[:system.c].sum(), s.z[:system.c].sum()
        assert abs(R_d - R_s) <= 1e-8 * max(1.0, R_d)
        es = ep.unpack(s.z)
        assert laws_residual(system, state.s, es.R, es.S, es.omega_dot) <= 1e-9
        assert np.abs(es.a_n).max(initial=0.0) <= 1e-9 * system.g


@pytest.mark.parametrize("n,seed,mu,spins", [(6, 3, 0.5, False), (8, 7, 0.3, True)])
def test_sparse_and_dense_searches_agree_examples(n, seed, mu, spins):
    test_sparse_and_dense_searches_agree.hypothesis.inner_test(n, seed, mu, spins)


@pytest.mark.parametrize("mu", [0.4, 0.5])
def test_groove_forced_on_every_integrator(mu):
    """From mu > 1/3 the groove's detachment is forced (test_groove's derivation): the sparse
    backend and the time-stepper prove it as the dense backend does, and stop."""
    system, state = _spinning_groove(mu)
    for run, what in ((models.simulate(system, state, max_events=1), "event"),
                      (simulate_sparse(system, state, max_events=1), "event"),
                      (moreau_jean(system, state, h=0.01, max_steps=3), "step")):
        assert run.status == "detachment", run.message
        assert PROVED.format(what) in run.message
        assert run.closed == {"search": True, "searched": 1, "followed": []}
    off = moreau_jean(system, state, h=0.01, max_steps=3, closed_search=False)
    assert off.status == "detachment" and "proved" not in off.message
    assert off.closed == {"search": False, "searched": 0, "followed": []}


def _at(lat, i, j) -> int:
    return int(np.flatnonzero((lat.i == i) & (lat.j == j))[0])


def _assert_hand(system, rec, mu):
    lat, want = system.lattice, _closed_by_hand(mu)
    for key, alpha in (("1", _at(lat, 0, 2)), ("2", _at(lat, 1, 2)), ("_L", _at(lat, 0, -1)),
                       ("_p", _at(lat, 0, -3)), ("_W", _at(lat, 1, -2)),
                       ("_p2", _at(lat, 1, -3))):
        assert abs(rec.R[alpha] - want["R" + key]) <= 1e-10, key
        assert abs(rec.S[alpha] - want["S" + key]) <= 1e-10, key
    np.testing.assert_allclose(rec.omega_dot, want["omega_dot"], rtol=0, atol=1e-10)


@pytest.mark.parametrize("mu", [0.2, 0.3])
def test_groove_closed_solution_followed_by_the_sparse_backend(mu, monkeypatch):
    """Up to mu = 1/3 a closed solution exists: with the sparse backend told that the
    pivoting's solution leaves the regime, it follows the closed solution of least sum R,
    the one derived by hand."""
    import rigidlcp.models.engine.sparse as sparse

    calls, real = [], sparse.regime_left

    def pivoting_leaves(*args):
        calls.append(1)
        return len(calls) == 1 or real(*args)

    monkeypatch.setattr(sparse, "regime_left", pivoting_leaves)
    system, state = _spinning_groove(mu)
    run = simulate_sparse(system, state, max_events=1)
    assert run.closed["followed"] == [0], run.message
    _assert_hand(system, run.records[0], mu)


@pytest.mark.parametrize("mu", [0.2, 0.3])
def test_groove_closed_solution_followed_by_the_time_stepper(mu, monkeypatch):
    """The same at the velocity level: the step's closed solution of least sum P_n has
    P = h lambda with lambda the hand-derived forces (the top disk still slides, u_t < 0, and
    the lower disks stick: omega = 0 after the step, so the equations are the event's times h);
    the record's R, S = P / h and omega' = (omega^{k+1} - omega^k) / h are the hand values."""
    import rigidlcp.models.timestepping as ts

    calls, real = [], ts.leaving

    def step_leaves(got, system, h):
        calls.append(1)
        if len(calls) == 1:
            return np.array([0]), np.zeros(0, int)
        return real(got, system, h)

    monkeypatch.setattr(ts, "leaving", step_leaves)
    system, state = _spinning_groove(mu)
    run = moreau_jean(system, state, h=0.01, max_steps=1)
    assert run.closed["followed"] == [0], run.message
    _assert_hand(system, run.records[0], mu)


@settings(deadline=None, max_examples=EXAMPLES)
@given(n=st.integers(3, 8), seed=st.integers(0, 10_000), mu=st.sampled_from([0.1, 0.3, 0.5, 0.8]),
       spins=st.booleans())
def test_step_closed_solutions_satisfy_the_step_laws(n, seed, mu, spins):
    """On small seeded piles, the first step's closed solution: its impulses satisfy the
    velocity-level Signorini-Coulomb laws (the step's Coulomb residual), u_n = 0 on every
    contact and no disk translates; "none" never when the step's own solution is closed."""
    system, state = _small_case(n, seed, mu, spins)
    h = 0.01
    dyn = models.Dynamics(system)
    sp = StepProblem(system, dyn, np.zeros(system.c, int))
    free_dnu = h * dyn.Minv * dyn.f
    nu = np.concatenate([np.zeros(2 * system.p), state.omega])
    b = dyn.H @ (nu + free_dnu) + dyn.u_obs(state.V + system.gamma * h)
    u_scale = max(float(np.abs(b).max()), system.g * h)
    P_floor = h * system.mass * max(system.g, abs(system.gamma))
    found = search_step(sp, dyn, b, free_dnu, max(u_scale, P_floor), 1e-8)
    first = moreau_jean(system, state, h=h, max_steps=1, closed_search=False)
    own_closed = first.status != "detachment"
    if found.status == "none":
        assert not own_closed
        return
    if found.status != "found":
        return
    P = sp.G @ found.z
    dnu = dyn.Minv * (dyn.H.T @ P) + free_dnu
    u = dyn.H @ (nu + dnu) + dyn.u_obs(state.V + system.gamma * h)
    P_scale = max(float(np.abs(P).max()), P_floor)
    assert coulomb_residual(system, P, u, P_scale, u_scale) <= 1e-8
    assert np.abs(u[:system.c]).max() <= 1e-9 * u_scale
    assert np.abs(dnu[:2 * system.p]).max() <= 1e-9 * u_scale


@pytest.mark.parametrize("n,seed,mu,spins", [(6, 3, 0.5, False), (5, 11, 0.3, True)])
def test_step_closed_solutions_examples(n, seed, mu, spins):
    test_step_closed_solutions_satisfy_the_step_laws.hypothesis.inner_test(n, seed, mu, spins)


def test_spun_pile_proved_on_every_integrator():
    """docs/packings.md's spun 20-disk pile: no forces hold its translations, so no solution
    of its first event or step keeps every contact closed: each integrator proves it."""
    system = models.System(deposit(20, seed=1, radii=(0.8, 1.2), width=8.0), gamma=0.1)
    state = models.initial_state(system, seed=1)
    dense = models.simulate(system, state)
    sparse = simulate_sparse(system, state)
    step = moreau_jean(system, state, h=0.01)
    assert dense.status == sparse.status == step.status == "detachment"
    assert dense.contacts == sparse.contacts  # the same contacts open; the same verdict
    assert dense.message.split("; proved")[0] == sparse.message.split("; proved")[0]
    assert PROVED.format("event") in dense.message
    assert PROVED.format("event") in sparse.message and PROVED.format("step") in step.message


def test_sparse_follows_the_closed_solution_the_dense_backend_follows():
    """The 12-disk pile at rest, mu = 0.5 (tests/models/engine/test_closed.py): the sparse
    pivoting's first solution opens a contact too; the sparse backend follows a closed
    solution, of the same least sum R, and reaches the same steady state; off, it stops."""
    pile = deposit(12, seed=2, radii=(0.8, 1.2), width=6.0)
    system = models.System(pile, mu_pp=0.5, mu_plane=0.5, mu_wall=0.5, gamma=0.1)
    state = models.initial_state(system, omega=np.zeros(system.p))
    dense, sparse = models.simulate(system, state), simulate_sparse(system, state)
    assert sparse.status == dense.status == "steady"
    assert sparse.closed["followed"] == dense.closed["followed"] == [0]
    assert abs(sparse.records[0].R.sum() - dense.records[0].R.sum()) <= 1e-8
    rec = sparse.records[0]
    assert laws_residual(system, rec.s_in, rec.R, rec.S, rec.omega_dot) <= 1e-9
    off = simulate_sparse(system, state, closed_search=False)
    assert off.status == "detachment" and off.closed["searched"] == 0


def test_arrays_unchanged_bit_for_bit_on_the_sparse_backend_and_the_time_stepper():
    """A regular array never detaches: neither search runs, and the runs are the same bit
    for bit with it on (the default) or off."""
    system = models.System(models.rectangular(6, 3), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.16)
    pairs = ((simulate_sparse(system, seed=1), simulate_sparse(system, seed=1,
                                                               closed_search=False)),
             (moreau_jean(system, seed=1, h=0.01, max_steps=400),
              moreau_jean(system, seed=1, h=0.01, max_steps=400, closed_search=False)))
    for on, off in pairs:
        assert on.closed["searched"] == 0
        assert (on.status, on.n_events, on.message) == (off.status, off.n_events, off.message)
        for name in ("t", "mu_g", "R", "S", "omega", "omega_dot"):
            assert np.array_equal(on.array(name), off.array(name)), name
