"""The lattice / system / state strategies produce what they promise, and the event problems
they make are well formed and solved by Lemke with the contact laws holding."""

import numpy as np
from hypothesis import given, settings

from rigidlcp import lcp, models
from rigidlcp.verify.certificates.laws import check_contact_laws
from rigidlcp.verify.strategies import contact_states, event_states, lattices, systems


@settings(max_examples=30, deadline=None)
@given(lat=lattices())
def test_lattices_are_valid(lat):
    assert lat.p >= 1 and lat.c >= lat.p  # every disk has at least one contact
    assert lat.name in ("rect", "tri")


@settings(max_examples=20, deadline=None)
@given(data=systems(lattice=lattices(lx=3, ly=2)).flatmap(
    lambda s: event_states(s).map(lambda st: (s, st))))
def test_event_states_give_solvable_events(data):
    system, state = data
    assert np.all(system.mu >= 0) and state.s.shape == (system.c,)
    assert np.all(state.s[system.mu == 0] == 0)
    ep = models.event_problem(system, state)
    sol = lcp.solve(ep.lcp, "lemke")
    if sol.success:  # a ray is possible (non-copositive M): the laws hold for every solution
        es = ep.unpack(sol.z)
        check_contact_laws(system, state, es.R, es.S, tol=1e-7)


@settings(max_examples=20, deadline=None)
@given(data=systems(lattice=lattices(lx=3, ly=2)).flatmap(
    lambda s: contact_states(s).map(lambda st: (s, st))))
def test_contact_states_fit_the_contact_matrix(data):
    system, (normal, tangential) = data
    Mc, b = models.contact_matrix(system, normal, tangential)
    assert Mc.shape == (2 * system.c, 2 * system.c) and b.shape == (2 * system.c,)
