"""A new user's first calls of verify.strategies (session 27): `systems(mu=0.3)`,
`lcps(np.eye(2))` and `lattices("rect")` failed with AttributeError or drew lattices named 'r';
a plain value now stands for that fixed value, and what cannot be one is an InvalidInput."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp.errors import InvalidInput
from rigidlcp.models.system import InvalidSystem
from rigidlcp.verify.strategies import (
    event_states,
    lattices,
    lcps,
    p_matrices,
    planted_solution,
    systems,
)

M0 = np.array([[2.0, 1.0], [1.0, 2.0]])


@settings(max_examples=20, deadline=None)
@given(systems(lattice=lattices("rect", lx=3, ly=2), mu=0.3, gamma=0.1))
def test_a_number_fixes_mu_and_gamma(system):
    assert system.lattice.name == "rect"
    assert (system.mu_pp, system.mu_plane, system.mu_wall, system.gamma) == (0.3, 0.3, 0.3, 0.1)


@settings(max_examples=20, deadline=None)
@given(systems(lattice=lattices(("tri",), lx=3, ly=2), mu=0).flatmap(
    lambda s: event_states(s, candidates=1.0).map(lambda state: (s, state))))
def test_plain_values_in_event_states(data):
    system, state = data
    assert system.lattice.name == "tri" and np.all(system.mu == 0)
    assert np.all(state.s == 0)  # frictionless: every contact carries 0


@settings(max_examples=20, deadline=None)
@given(lcps(M0, planted=True), lcps(M0.tolist(), q_elements=-1))
def test_a_plain_matrix_is_the_fixed_M(planted, fixed_q):
    for problem in (planted, fixed_q):
        assert np.array_equal(problem.M, M0)
    z, w = np.array(planted.meta["planted_z"]), np.array(planted.meta["planted_w"])
    assert np.allclose(M0 @ z + planted.q, w) and z @ w == 0  # planted: z solves it
    assert np.array_equal(fixed_q.q, [-1.0, -1.0])
    sol = lcp.solve(fixed_q, method="lemke")  # the P-matrix's one solution: (1/3, 1/3)
    assert np.allclose(sol.z, [1 / 3, 1 / 3])


@pytest.mark.parametrize("strategy, says", [
    (lambda: systems(mu="0.3"), "mu must be a number or a strategy of numbers"),
    (lambda: systems(gamma=True), "gamma must be a number or a strategy of numbers"),
    (lambda: lcps(np.ones((2, 3))), "matrices must be a strategy of square matrices"),
    (lambda: lcps("M"), "matrices must be a strategy of square matrices"),
    (lambda: planted_solution(p_matrices(3)), "planted_solution takes a matrix, not a strategy"),
])
def test_what_cannot_be_a_value_is_named(strategy, says):
    @settings(max_examples=1, deadline=None, database=None)
    @given(strategy())
    def draw_one(x):
        pass

    with pytest.raises(InvalidInput, match=says):
        draw_one()


def test_a_negative_mu_is_the_systems_own_refusal():
    @settings(max_examples=1, deadline=None, database=None)
    @given(systems(mu=-1))
    def draw_one(system):
        pass

    with pytest.raises(InvalidSystem, match="must be a finite number >= 0"):
        draw_one()


def test_lattices_of_one_kind_as_a_string():
    drawn = st.lists(lattices("tri", lx=3, ly=2), min_size=5, max_size=5)

    @settings(max_examples=5, deadline=None)
    @given(drawn)
    def check(lats):
        assert {lat.name for lat in lats} == {"tri"}

    check()
