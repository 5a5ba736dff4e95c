"""The sparse path (models.sparse_event, sparse_pivoting, sparse_evolution): the sparse MLCP is
models.event's, the active system is the paper's contact matrix, row updates solve what a fresh
factorization solves, the pivoting returns solutions of the event LCP, and dense and sparse
runs agree event by event where the events have one solution."""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import lcp, models
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.engine.sparse import simulate_sparse
from rigidlcp.models.engine.sparse_pivoting import solve_states
from rigidlcp.models.event import State, contact_matrix, event_problem, initial_state
from rigidlcp.models.sparse_event import (
    NS,
    ActiveSystem,
    SingularSystem,
    StateFactor,
    sparse_delassus,
    sparse_mlcp,
)

FIG9 = dict(mu_pp=0.1, mu_plane=0.2, mu_wall=0.0, gamma=0.16)


def fig9(lattice: str, lx: int, ly: int, **kw) -> models.System:
    return models.System(models.make_lattice(lattice, lx, ly), **{**FIG9, **kw})


def mixed_state(system: models.System, seed: int) -> State:
    """Random angular velocities, some contacts made non-sliding candidates."""
    rng = np.random.default_rng(seed)
    st = initial_state(system, seed=seed)
    st.s = np.where(rng.uniform(size=system.c) < 0.4, 0, st.s)
    return st


def z_of(ep, R, S, at, tang):
    """The event LCP's z = [R, tau, a_minus] of a sparse solution."""
    cand, mu = ep.candidates, ep.system.mu
    return np.concatenate([R, mu[cand] * R[cand] + S[cand],
                           np.where(tang[cand] == -1, -at[cand], 0.0)])


@pytest.mark.parametrize("lattice, lx, ly", [("rect", 4, 3), ("tri", 5, 3)])
def test_sparse_mlcp_is_the_event_mlcp(lattice, lx, ly):
    system = fig9(lattice, lx, ly, mu_wall=0.3)
    st = mixed_state(system, 1)
    dense = event_problem(system, st).mlcp
    sparse = sparse_mlcp(system, st).to_dense()
    for key in ("A", "C", "D", "B", "a", "b"):
        np.testing.assert_allclose(getattr(sparse, key), getattr(dense, key), atol=1e-14,
                                   err_msg=key)


@pytest.mark.parametrize("lattice, lx, ly", [("rect", 4, 3), ("tri", 4, 3)])
def test_active_system_is_the_papers_contact_matrix(lattice, lx, ly):
    system = fig9(lattice, lx, ly, mu_wall=0.3)  # every contact frictional
    dyn = Dynamics(system)
    asys = ActiveSystem(sparse_delassus(dyn), dyn.q, system.mu)
    np.testing.assert_allclose(asys.W.toarray(), dyn.W, atol=1e-14)
    rng = np.random.default_rng(0)
    for _ in range(5):
        normal = rng.uniform(size=system.c) < 0.6
        tangential = rng.choice([0, 1, -1], system.c)
        Mc, rhs = contact_matrix(system, normal, tangential, dyn)
        tang = np.where(tangential == 0, NS, tangential).astype(np.int8)
        np.testing.assert_allclose(asys.matrix(normal, tang).toarray(), Mc, atol=1e-14)
        np.testing.assert_allclose(asys.rhs(normal, tang), rhs, atol=1e-14)
        x = rng.standard_normal(2 * system.c)
        np.testing.assert_allclose(asys.apply(x, normal, tang), Mc @ x, atol=1e-12)


def test_row_updates_solve_what_a_fresh_factorization_solves():
    system = fig9("rect", 6, 4, mu_wall=0.3)
    dyn = Dynamics(system)
    asys = ActiveSystem(sparse_delassus(dyn), dyn.q, system.mu)
    c = system.c
    normal = np.ones(c, dtype=bool)
    normal[system.lattice.j == models.RIGHT_WALL] = False
    tang = np.ones(c, dtype=np.int8)
    factor = StateFactor(asys, normal, tang, max_updates=50)
    rng = np.random.default_rng(2)
    checked = singular = 0
    for _ in range(40):
        n2, t2 = factor.normal.copy(), factor.tang.copy()
        flip = rng.choice(2 * c, size=int(rng.integers(1, 4)), replace=False)
        for i in flip:
            if i < c:
                n2[i] = ~n2[i]
            else:
                t2[i - c] = rng.choice([NS, 1, -1])
        K = asys.matrix(n2, t2).toarray()
        try:
            factor.set_states(n2, t2)
        except SingularSystem:
            singular += 1
            # refused only when K is (numerically) singular
            assert np.linalg.cond(K) > 1e8
            continue
        b = asys.rhs(n2, t2)
        np.testing.assert_allclose(factor.solve_current(), np.linalg.solve(K, b),
                                   rtol=1e-8, atol=1e-9)
        checked += 1
    assert checked > 20
    assert factor.update.rows  # the updates were exercised, not only refactorizations


def test_a_hyperstatic_state_is_refused():
    # Every contact transmitting and non-sliding: more equations than degrees of freedom.
    system = fig9("rect", 4, 3)
    dyn = Dynamics(system)
    asys = ActiveSystem(sparse_delassus(dyn), dyn.q, system.mu)
    c = system.c
    tang = np.where(system.mu > 0, NS, 0).astype(np.int8)
    assert np.linalg.matrix_rank(asys.matrix(np.ones(c, bool), tang).toarray()) < 2 * c
    with pytest.raises(SingularSystem):
        StateFactor(asys, np.ones(c, dtype=bool), tang)
    factor = StateFactor(asys, np.zeros(c, dtype=bool), np.where(tang == NS, 1, 0).astype(
        np.int8))
    with pytest.raises(SingularSystem):
        factor.set_states(np.ones(c, dtype=bool), tang)
    assert not factor.normal.any()  # the refused states are not taken


@pytest.mark.parametrize("lattice, lx, ly, seed", [("rect", 5, 3, 1), ("tri", 4, 3, 2),
                                                   ("rect", 6, 4, 3)])
def test_solve_states_returns_a_solution_of_the_event_lcp(lattice, lx, ly, seed):
    system = fig9(lattice, lx, ly, mu_wall=0.3)
    st = mixed_state(system, seed)
    ep = event_problem(system, st)
    dyn = Dynamics(system)
    asys = ActiveSystem(sparse_delassus(dyn), dyn.q, system.mu)
    c = system.c
    s = np.where(system.mu == 0, 0, st.s)
    cand = (s == 0) & (system.mu > 0)
    factor = StateFactor(asys, np.zeros(c, bool), np.where(cand, 1, s).astype(np.int8))
    sol = solve_states(factor, cand, asys.q[:c] <= 0, np.where(cand, 1, s).astype(np.int8))
    assert sol.status == "solved"
    z = z_of(ep, sol.R, sol.S, sol.a[c:], sol.tang)
    w = ep.lcp.M @ z + ep.lcp.q
    scale = max(1.0, np.abs(ep.lcp.q).max())
    assert lcp.complementarity_residual(z, w) <= 1e-9 * scale
    assert sol.residual == pytest.approx(lcp.complementarity_residual(z, w), abs=1e-9 * scale)


@pytest.mark.parametrize("lattice, lx, ly, seed", [("rect", 3, 2, 1), ("rect", 4, 3, 1),
                                                   ("rect", 4, 3, 2), ("rect", 5, 3, 3)])
def test_dense_and_sparse_runs_agree_at_every_event(lattice, lx, ly, seed):
    # Runs whose events have one solution each (frictionless walls, small arrays): the
    # trajectories must agree event by event. Non-unique events: tests/verify.
    system = fig9(lattice, lx, ly)
    dense = models.simulate(system, seed=seed, method="lemke", select="none")
    sparse = simulate_sparse(system, seed=seed)
    assert dense.status == sparse.status == "steady"
    assert dense.n_events == sparse.n_events
    for a, b in zip(dense.records, sparse.records):
        assert np.array_equal(a.s_in, b.s_in) and np.array_equal(a.s, b.s)
        assert b.t == pytest.approx(a.t, abs=1e-9)
        for key in ("omega", "omega_dot", "R", "S", "at"):
            np.testing.assert_allclose(getattr(b, key), getattr(a, key), atol=1e-9,
                                       err_msg=key)
    assert sparse.records[-1].method == "sparse-pivoting"


def test_light_records_keep_the_last_event_whole():
    system = fig9("rect", 4, 3)
    run = simulate_sparse(system, seed=1, records="light")
    assert run.records[0].R.size == 0 and run.records[-1].R.size == system.c
    assert run.summary()["events"] == run.n_events
    assert len(run.sparse_info["seconds"]) == run.n_events
    with pytest.raises(ValueError, match="records"):
        simulate_sparse(system, seed=1, records="some")
