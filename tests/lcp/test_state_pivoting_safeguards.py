"""The safeguards of lcp.state_pivoting (issue 13) and the reduced factorization of
lcp.state_factor: the component step keeps every flip but the extra openings of a cluster,
the iteration terminates and counts its flips, P-matrix LCPs get the solution a dense Lemke
finds with every safeguard on or off, a singular (hyperstatic) chain gets its analytic
accelerations, and scaling the unknowns scales the answer; ReducedLU solves what SuperLU of
all of K solves."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given
from hypothesis import strategies as st
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import spsolve

from rigidlcp import lcp, models
from rigidlcp.lcp.solvers import state_pivoting
from rigidlcp.lcp.solvers.state_factor import (
    NS,
    ActiveSystem,
    ReducedLU,
    SingularSystem,
    StateFactor,
)
from rigidlcp.lcp.solvers.state_pivoting import _one_per_component, solve_states
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.event import initial_state
from rigidlcp.models.sparse_event import sparse_delassus

VARIANTS = [(True, 0), (False, 0), (True, 10), (False, 1), (True, 1)]  # (COMPONENTS, stall)


class CountingFactor(StateFactor):
    """A StateFactor that counts the states each accepted change changes (after the first)."""

    def __init__(self, *args, **kw):
        self.changed: list[int] = []
        super().__init__(*args, **kw)

    def set_states(self, normal, tang):
        before = self.normal.copy(), self.tang.copy()
        super().set_states(normal, tang)
        self.changed.append(int(np.count_nonzero(self.normal != before[0])
                                + np.count_nonzero(self.tang != before[1])))


def chains(rows: int, n: int, eps: float, rng) -> tuple[sp.csr_matrix, np.ndarray]:
    """`rows` rows of n disks (mass 1) between two walls, frictionless: contact k of a row
    between disks k - 1 and k (the walls at both ends), W_nn = D D' + eps I per row (D: the
    (n + 1) x n incidence, singular D D' for eps = 0: the row's self-stress), q_n = D f for
    random forces f on the disks. The tangential block is the identity (mu = 0)."""
    D = sp.diags([np.ones(n), -np.ones(n)], [0, -1], shape=(n + 1, n))
    blocks, q = [], []
    for _ in range(rows):
        blocks.append(D @ D.T + eps * sp.identity(n + 1))
        q.append(D @ rng.normal(size=n))
    c = rows * (n + 1)
    W = sp.block_diag([sp.block_diag(blocks), sp.identity(c)]).tocsr()
    return W, np.concatenate([np.concatenate(q), np.zeros(c)])


def run(W, q, variant, monkeypatch, normal0=None):
    """solve_states from every contact closed (frictionless: tang 0, no candidate)."""
    monkeypatch.setattr(state_pivoting, "COMPONENTS", variant[0])
    c = q.size // 2
    asys = ActiveSystem(W, q, np.zeros(c))
    tang = np.zeros(c, dtype=np.int8)
    factor = CountingFactor(asys, np.zeros(c, dtype=bool), tang)
    normal0 = np.ones(c, dtype=bool) if normal0 is None else normal0
    sol = solve_states(factor, np.zeros(c, dtype=bool), normal0, tang, stall=variant[1])
    return sol, factor


def check_solution(sol, W, q, tol=1e-9):
    c = q.size // 2
    a = (W @ np.concatenate([sol.R, sol.S]) + q)[:c]
    scale = np.abs(q).max() + abs(W).max() * np.abs(sol.R).max()
    assert sol.status == "solved"
    assert sol.R.min() >= -tol * scale and a.min() >= -tol * scale
    assert np.abs(np.minimum(sol.R, a)).max() <= tol * scale
    return a


@given(n=st.integers(2, 30), seed=st.integers(0, 2**31 - 1), data=st.data())
def test_one_per_component_keeps_all_but_the_extra_openings(n, seed, data):
    rng = np.random.default_rng(seed)
    c = n
    A = sp.random(c, c, density=min(1.0, 3.0 / c), random_state=seed)
    adjacency = ((A + A.T + sp.identity(c)) != 0).astype(np.int8).tocsr()
    normal = rng.uniform(size=c) < 0.6
    H = np.unique(rng.choice(2 * c, size=data.draw(st.integers(1, 2 * c)), replace=False))
    size = np.round(rng.uniform(size=H.size), 1)  # ties on purpose
    out = _one_per_component(H, size, c, normal, adjacency)
    opening = (H < c) & normal[np.minimum(H, c - 1)]
    assert np.all(np.isin(out, H)) and np.all(np.diff(np.searchsorted(H, out)) > 0)
    assert np.all(np.isin(H[~opening], out))  # every other flip is taken
    op = H[opening]
    kept = np.isin(op, out)
    if op.size < 2:
        assert kept.all()
        return
    ncomp, lab = connected_components(adjacency[op][:, op], directed=False)
    for k in range(ncomp):
        members = np.flatnonzero(lab == k)
        chosen = members[kept[members]]
        assert chosen.size == 1  # one opening per cluster ...
        best = size[opening][members].max()  # ... its most violated, the first among ties
        assert chosen[0] == members[np.flatnonzero(size[opening][members] == best)[0]]


@pytest.mark.parametrize("variant", VARIANTS)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_p_matrix_chains_get_lemkes_solution_with_counted_flips(variant, seed, monkeypatch):
    """Nearly singular SPD chains (eps = 1e-6: P-matrices, one solution): the all-closed start
    puts a self-stress ~ 1/eps of either sign on each row, the case the component step is
    for. Every variant ends at the dense Lemke solution; `flips` is the number of state
    changes the factor saw."""
    rng = np.random.default_rng(seed)
    W, q = chains(6, 12, 1e-6, rng)
    c = q.size // 2
    sol, factor = run(W, q, variant, monkeypatch)
    check_solution(sol, W, q)
    ref = lcp.solve(lcp.LCP(W[:c, :c].toarray(), q[:c]), method="lemke")
    assert ref.status == "solved"
    np.testing.assert_allclose(sol.R, ref.z, atol=1e-7 * np.abs(ref.z).max())
    assert sol.info["flips"] == sum(factor.changed[1:])
    assert sol.info["flips"] >= np.count_nonzero(~sol.normal)  # each open contact was opened
    if variant[0]:
        assert sol.info["component_steps"] >= 1


@pytest.mark.parametrize("variant", VARIANTS)
def test_hyperstatic_chains_get_the_analytic_accelerations(variant, monkeypatch):
    """eps = 0: each row is hyperstatic (one self-stress), the all-closed system singular and
    the forces not unique. A static solution exists (R_k = R_0 + sum_{i<k} f_i >= 0 with R_0
    large enough), so the accelerations of every solution are zero (W symmetric PSD: W R is
    the same for all solutions)."""
    rng = np.random.default_rng(7)
    W, q = chains(5, 10, 0.0, rng)
    sol, _ = run(W, q, variant, monkeypatch)
    a = check_solution(sol, W, q)
    np.testing.assert_allclose(a, 0.0, atol=1e-9 * np.abs(q).max())


@pytest.mark.parametrize("variant", VARIANTS)
def test_degenerate_and_badly_scaled(variant, monkeypatch):
    """q_n = 0 on a third of the contacts (degenerate), and the unknowns scaled by 1e-4 ..
    1e4 (W -> S W S, q -> S q, R -> S^-1 R; entries of W spread over 1e16): the scaled answer
    is the unscaled one mapped. (SuperLU of the whole unscaled K refused the all-closed start
    of this problem as singular and failed in two of the five variants; ReducedLU equilibrates
    and solves all five.)"""
    rng = np.random.default_rng(3)
    W, q = chains(4, 9, 1e-3, rng)
    c = q.size // 2
    q[:c][rng.uniform(size=c) < 1 / 3] = 0.0
    sol, _ = run(W, q, variant, monkeypatch)
    check_solution(sol, W, q)
    s = np.concatenate([10.0 ** rng.uniform(-4, 4, size=c), np.ones(c)])
    Ws = (sp.diags(s) @ W @ sp.diags(s)).tocsr()
    sol_s, _ = run(Ws, s * q, variant, monkeypatch)
    check_solution(sol_s, Ws, s * q)
    np.testing.assert_allclose(s[:c] * sol_s.R, sol.R, atol=1e-8 * np.abs(sol.R).max())


def test_the_iteration_stops_within_its_limit(monkeypatch):
    """stall = 1 (a rescue after every step without a new record) and a tiny iteration limit:
    the call returns a status, never loops."""
    rng = np.random.default_rng(11)
    W, q = chains(8, 15, 1e-8, rng)
    c = q.size // 2
    asys = ActiveSystem(W, q, np.zeros(c))
    tang = np.zeros(c, dtype=np.int8)
    for max_iter in (1, 3, 1000):
        factor = StateFactor(asys, np.zeros(c, dtype=bool), tang)
        sol = solve_states(factor, np.zeros(c, dtype=bool), np.ones(c, dtype=bool), tang,
                           max_iter=max_iter, stall=1)
        assert sol.status in ("solved", "max_iter", "failed")
        assert sol.iterations <= max_iter
        assert sol.info["stall_rescues"] <= 8


def disk_system(seed: int) -> tuple[ActiveSystem, np.ndarray]:
    system = models.System(models.make_lattice("rect", 5, 4), mu_pp=0.1, mu_plane=0.2,
                           mu_wall=0.3, gamma=0.16)
    dyn = Dynamics(system)
    return ActiveSystem(sparse_delassus(dyn), dyn.q, system.mu), initial_state(system,
                                                                               seed=seed).s


@given(seed=st.integers(0, 2**31 - 1))
def test_reduced_lu_solves_what_the_whole_system_solves(seed):
    rng = np.random.default_rng(seed)
    asys, _ = disk_system(1)
    c = asys.c
    normal = rng.uniform(size=c) < 0.7
    tang = rng.choice(np.array([1, -1, 0, NS], dtype=np.int8), size=c)
    K = asys.matrix(normal, tang).tocsc()
    try:
        red = ReducedLU(asys, normal, tang)
    except RuntimeError:  # exactly singular: so is K
        assert np.linalg.matrix_rank(K.toarray()) < K.shape[0]
        return
    d = red.pivots
    cond = np.linalg.cond(K.toarray())
    refused = d.min() <= 1e-13 * d.max() or red.cond_bound > 1e13  # StateFactor's tests
    Ks = (sp.diags(red.r) @ asys.W[red.A] @ red.P @ sp.diags(red.r)).toarray()
    if np.linalg.cond(Ks) < 1e12:  # a lower bound of the equilibrated matrix's condition
        assert red.cond_bound <= np.linalg.cond(Ks, np.inf) * (1 + 1e-6)
    if cond > 1e16:
        assert refused  # numerically singular systems are refused
    if refused:
        return
    B = rng.normal(size=(asys.N, 3))
    X = red.solve(B)
    ref = spsolve(K, B)
    np.testing.assert_allclose(K @ X, B, atol=1e-9 * np.abs(B).max() * max(1.0, np.abs(X).max()))
    np.testing.assert_allclose(X, ref, atol=1e-14 * cond * max(1.0, np.abs(ref).max()))
    np.testing.assert_allclose(red.solve(B[:, 0]), X[:, 0], atol=1e-12 * np.abs(X).max())


def test_reduced_and_whole_factorizations_give_the_same_event(monkeypatch):
    """One event of a frictional array from the same start: the same states and forces with
    the reduced LU and with SuperLU of all of K."""
    from rigidlcp.lcp.solvers import state_factor

    asys, s = disk_system(2)
    c = asys.c
    cand = np.zeros(c, dtype=bool)
    tang = np.where(asys.mu == 0, 0, s).astype(np.int8)
    out = []
    for reduced in (True, False):
        monkeypatch.setattr(state_factor, "REDUCED", reduced)
        factor = StateFactor(asys, np.zeros(c, dtype=bool), tang)
        try:
            out.append(solve_states(factor, cand, asys.q[:c] <= 0, tang))
        except SingularSystem:  # pragma: no cover - the start is nonsingular here
            raise
    assert out[0].status == out[1].status == "solved"
    np.testing.assert_array_equal(out[0].normal, out[1].normal)
    np.testing.assert_allclose(out[0].R, out[1].R, atol=1e-10 * np.abs(out[1].R).max())
