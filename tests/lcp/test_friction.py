"""lcp.FrictionContact2D: the natural map on hand-solved contacts, every method on small
problems (agreement where the forces are unique, the natural-map residual everywhere), the
determinism of `states`, and verify.certify on its answers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from rigidlcp import lcp, verify
from rigidlcp.lcp.problems.friction import natural_residual, project_cone
from rigidlcp.lcp.solvers.enumeration import enumerate_solutions

DATA = Path(__file__).resolve().parents[1] / "data" / "siconos"
FC_METHODS = ["lemke", "pivoting", "enumerate", "states", "nsgs", "newton-min", "newton-fb"]


@pytest.mark.parametrize("q, r_hand, u_hand", [
    # W = I, mu = 0.5. Stick: u = 0, r = -q, |r_t| = 0.2 <= 0.5 r_n.
    ((-1.0, 0.2), (1.0, -0.2), (0.0, 0.0)),
    # Slide forward: r_n = 1 (u_n = 0), r_t = -mu r_n = -0.5, u_t = -0.5 + 2 = 1.5 > 0.
    ((-1.0, 2.0), (1.0, -0.5), (0.0, 1.5)),
    # Open: q_n >= 0, r = 0, u = q.
    ((0.5, -3.0), (0.0, 0.0), (0.5, -3.0)),
])
def test_one_contact_solved_by_hand(q, r_hand, u_hand):
    p = lcp.FrictionContact2D(np.eye(2), q, 0.5)
    assert natural_residual(p, np.array(r_hand)) == 0.0
    assert natural_residual(p, np.array(r_hand) + [0.0, 1e-3]) > 0
    for name in FC_METHODS:
        sol = lcp.solve(p, name)
        assert sol.status == "solved", (name, sol)
        assert np.allclose(sol.z, r_hand, atol=1e-12) and np.allclose(sol.w, u_hand, atol=1e-12)


def test_cone_projection_is_a_projection():
    rng = np.random.default_rng(0)
    x = rng.standard_normal(200) * 3
    mu = rng.uniform(0, 2, 100)
    p = project_cone(x, mu)
    assert np.all(np.abs(p[1::2]) <= mu * p[0::2] + 1e-12)
    assert np.allclose(project_cone(p, mu), p)
    # the residual is orthogonal to the cone's points (2D: checked on the two extreme rays)
    d = x - p
    for s in (1.0, -1.0):
        assert np.all(d[0::2] + s * mu * d[1::2] <= 1e-12)


def random_fc(rng, c: int, mu_max: float = 0.6, sparse: bool = False) -> lcp.FrictionContact2D:
    """W = H M^-1 H' of c random contacts on c + 1 disks (positive semidefinite), q random."""
    H = rng.standard_normal((2 * c, 3 * (c + 1)))
    W = H @ H.T / (3 * (c + 1)) + 1e-3 * np.eye(2 * c)
    q = rng.standard_normal(2 * c)
    mu = rng.uniform(0, mu_max, c)
    return lcp.FrictionContact2D(sp.csr_matrix(W) if sparse else W, q, mu)


@pytest.mark.parametrize("seed", range(8))
def test_methods_agree_where_the_forces_are_unique(seed):
    rng = np.random.default_rng(seed)
    p = random_fc(rng, 3, sparse=bool(seed % 2))
    glocker = p.to_lcp()
    forces = {tuple(np.round(p.r_from_lcp(s.z), 9)) for s in enumerate_solutions(glocker)}
    for name in FC_METHODS:
        sol = lcp.solve(p, name)
        if name == "newton-min" and sol.status != "solved":
            continue  # a local method: it may stop at a stationary point, never claims it
        assert sol.status == "solved", (name, sol)
        assert sol.residual <= 1e-10 and natural_residual(p, sol.z) <= 1e-10
        if len(forces) == 1:
            assert np.allclose(sol.z, next(iter(forces)), atol=1e-7), name
        cert = verify.certify(p, sol)
        assert cert.accepted, (name, cert)


def test_states_is_deterministic_on_the_siconos_file():
    p = lcp.load(DATA / "FrictionContactProblem00031.dat")
    a, b = lcp.solve(p, "states"), lcp.solve(p, "states")
    assert a.status == b.status == "solved"
    assert a.iterations == b.iterations and np.array_equal(a.z, b.z)


@pytest.mark.parametrize("name", ["FrictionContactProblem00031.dat",
                                  "FC2D_SliderCrankLagrangian00000.dat"])
def test_siconos_files_solved_to_1e_10_by_every_pivoting_method(name):
    p = lcp.load(DATA / name)
    for method in ("lemke", "pivoting", "states"):
        sol = lcp.solve(p, method)
        assert sol.status == "solved" and natural_residual(p, sol.z) <= 1e-10, (method, sol)


def test_certify_friction_answers_forces_unique_and_rejects_a_wrong_one():
    p = lcp.FrictionContact2D(np.eye(2), (-1.0, 2.0), 0.5)
    sol = lcp.solve(p, "lemke")
    cert = verify.certify(p, sol)
    assert cert.accepted and cert.observables["forces"] is True
    bad = verify.certify(p, sol.z + [0.0, 0.1], uniqueness="none")
    assert not bad.accepted


def test_friction_methods_refuse_an_lcp_and_bad_input_is_named():
    with pytest.raises(lcp.NotApplicable, match="friction-contact"):
        lcp.solve(lcp.LCP(np.eye(2), -np.ones(2)), "nsgs")
    with pytest.raises(lcp.InvalidProblem, match="mu must be"):
        lcp.FrictionContact2D(np.eye(2), np.zeros(2), -0.1)
    with pytest.raises(lcp.InvalidProblem, match="2c x 2c"):
        lcp.FrictionContact2D(np.eye(3), np.zeros(3), 0.1)


def test_repr_counts_the_contact_states_not_a_glocker_basis():
    """The repr of a friction answer said "active set : k of 2c z basic", k counting a basis of
    the Glocker LCP (3c unknowns; the closed contacts for `states`) against r's 2c entries
    (session 7's closing note). It now counts the answer's contact states, here the three
    contacts of test_one_contact_solved_by_hand side by side (W = I): stick, slide, open."""
    p = lcp.FrictionContact2D(np.eye(6), np.array([-1.0, 0.2, -1.0, 2.0, 0.5, -3.0]), 0.5)
    for name in FC_METHODS:
        sol = lcp.solve(p, name)
        assert sol.status == "solved", (name, sol)
        assert sol.info["contact_states"] == {"open": 1, "sticking": 1, "sliding": 1}
        text = repr(sol)
        assert "contacts   : 2 of 3 closed (1 sticking, 1 sliding)" in text, text
        assert "z basic" not in text and "relative natural-map residual" in text
    plain = repr(lcp.solve(lcp.LCP(np.eye(2), -np.ones(2)), "lemke"))
    assert "active set : 2 of 2 z basic" in plain and "contacts" not in plain
