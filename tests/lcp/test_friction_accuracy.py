"""The acceptance of friction-contact answers (lcp.acceptance.friction_accuracy): backward error
worked out by hand, no measure met by inflating r, the forward bound of the contact states'
system on an ill-conditioned case solved by hand, lying methods on both routes (native and
Glocker LCP) reported "inaccurate", Siconos's FC2D files, and verify.certify's same bounds."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rigidlcp import lcp, verify
from rigidlcp.lcp import registry
from rigidlcp.lcp.acceptance.friction_accuracy import (
    OPEN,
    SLIDE_BACKWARD,
    SLIDE_FORWARD,
    STICK,
    assess_fc2d,
    backward_error,
    pattern_system,
    states_of,
)

#: Siconos's FC2D files (read-only, beside the checkout, or this machine's /work/shared for a
#: clone elsewhere, as tests/lcp/test_accuracy.py) when present; else the copies here.
SICONOS = next((d / "shared" / "data" / "siconos" / "fc2d"
                for d in (*Path(__file__).parents, Path("/work"))
                if (d / "shared" / "data" / "siconos" / "fc2d").is_dir()), Path("/nonexistent"))
LOCAL = Path(__file__).resolve().parents[1] / "data" / "siconos"
METHODS = ("states", "nsgs", "lemke", "pivoting", "newton-fb")


@pytest.mark.parametrize("q, r, state", [
    ((-1.0, 0.2), (1.0, -0.2), STICK),            # W = I, mu = 0.5: u = 0, |r_t| < mu r_n
    ((-1.0, 2.0), (1.0, -0.5), SLIDE_FORWARD),    # u_t = 1.5 > 0, r_t = -mu r_n
    ((-1.0, -2.0), (1.0, 0.5), SLIDE_BACKWARD),   # u_t = -1.5 < 0, r_t = +mu r_n
    ((0.5, -3.0), (0.0, 0.0), OPEN),              # q_n >= 0: r = 0
])
def test_hand_solutions_have_zero_errors_and_their_states(q, r, state):
    p = lcp.FrictionContact2D(np.eye(2), q, 0.5)
    assert backward_error(p, np.array(r)) == 0.0
    assert states_of(p, np.array(r)).tolist() == [state]
    acc = assess_fc2d(p, np.array(r))
    assert acc.accepted and acc.ferr <= 4 * np.finfo(float).eps


@pytest.mark.parametrize("d", [1e-3, -1e-3])
def test_backward_error_by_hand(d):
    """W = I, q = (-1, 2), mu = 0.5, r = (1, -0.5 + d): u = (0, 1.5 + d). Row scales
    s = max(|W||r| + |q|, s_d) = s_d = |q|_inf + ||W||_inf |q|_inf / |W|_max = 4, forces' scale
    r_s = max(|r|_inf, |q|_inf / |W|_max) = 2. Sliding rule: min(|u_t| / 4, |r_t + mu r_n| / 2)
    = |d| / 2; for d < 0 the cone is violated by the same |d| / 2; Signorini holds."""
    p = lcp.FrictionContact2D(np.eye(2), (-1.0, 2.0), 0.5)
    assert backward_error(p, np.array([1.0, -0.5 + d])) == pytest.approx(abs(d) / 2, rel=1e-12)


def inflatable() -> lcp.FrictionContact2D:
    """Three frictionless contacts: normals of 0 and 1 coupled by [[1, -1], [-1, 1]] (r_n0 =
    r_n1 is a null direction), contact 2 alone with q_n = -100 (the LCP example of issue 23)."""
    W = np.eye(6)
    W[np.ix_([0, 2], [0, 2])] = [[1.0, -1.0], [-1.0, 1.0]]
    return lcp.FrictionContact2D(W, [-1.0, 0.0, 1.0, 0.0, -100.0, 0.0], 0.0)


def test_inflating_r_meets_no_measure():
    """r = (1e15, 0, 1e15, 0, 0, 0): u_n = (-1, 1, -100). Row 5's scale is s_d = 100 + 2 * 100
    = 300 whatever r is, so berr >= 100 / 300 (an |r|-scaled measure would give ~1e-13)."""
    p = inflatable()
    r = np.array([1e15, 0.0, 1e15, 0.0, 0.0, 0.0])
    assert backward_error(p, r) == pytest.approx(1 / 3, rel=1e-12)

    @lcp.register("fc-inflates-r", accepts="friction-2d", description="test: a liar")
    def liar(problem, **_):
        return lcp.Solution(z=r.copy(), w=problem.u(r), status="solved", method="x")

    try:
        sol = lcp.solve(p, "fc-inflates-r")
        assert sol.status == "inaccurate" and sol.method == "fc-inflates-r"
        assert sol.backward_error >= 1 / 3 * (1 - 1e-12)
        assert not verify.certify(p, r, uniqueness="none").accepted
        good = lcp.solve(p, "lemke")
        assert good.status == "solved" and good.z[4] == pytest.approx(100.0)
        assert good.z[0] - good.z[2] == pytest.approx(1.0)
    finally:
        registry._REGISTRY.pop("fc-inflates-r")


def near_singular(eps: float) -> tuple[lcp.FrictionContact2D, np.ndarray]:
    """Two frictionless contacts, normal block [[1, 1], [1, 1 + eps]], q_n = -W (1, 1): the
    only solution is r_n = (1, 1) (both closed; the block is positive definite)."""
    W = np.eye(4)
    W[np.ix_([0, 2], [0, 2])] = [[1.0, 1.0], [1.0, 1.0 + eps]]
    r = np.array([1.0, 0.0, 1.0, 0.0])
    return lcp.FrictionContact2D(W, -(W @ r), 0.0), r


def test_a_far_answer_with_a_tiny_residual_is_polished_to_the_exact_one():
    """eps = 1e-10: r' = (1.5, 0, 0.5, 0) is 0.5 away along the near-null vector (1, -1) of
    the block, u' = (0, 0, -eps / 2, 0): natural-map residual ~2e-11 < 1e-10 (the old test
    accepted it), backward error ~1e-11; its forward error bound (>= 1/3, its distance to the
    states' exact point) is not. Polished on its states (both closed), it is (1, 1) to ~1e-7
    (condition 4e10 times extended precision)."""
    p, exact = near_singular(1e-10)
    far = np.array([1.5, 0.0, 0.5, 0.0])
    assert lcp.natural_residual(p, far) < 1e-10
    as_given = assess_fc2d(p, far, polish=False)
    assert as_given.berr < 1e-10 and as_given.ferr >= 1 / 3

    @lcp.register("fc-far", accepts="friction-2d", description="test: a sloppy method")
    def sloppy(problem, **_):
        return lcp.Solution(z=far.copy(), w=problem.u(far), status="solved", method="x")

    try:
        sol = lcp.solve(p, "fc-far")
        assert sol.status == "solved" and sol.info["polished"]
        assert sol.forward_error <= 1e-6
        err = np.max(np.abs(sol.z - exact)) / np.max(np.abs(sol.z))
        assert err <= sol.forward_error  # the bound holds against the hand solution
        cert = verify.certify(p, far, uniqueness="none")
        assert not cert.accepted and cert.forward_error >= 1 / 3
    finally:
        registry._REGISTRY.pop("fc-far")


def test_a_system_too_ill_conditioned_for_the_tolerance_is_inaccurate():
    """eps = 1e-13 (condition ~4e13): the states' system of r = (1, 0, 1, 0) cannot be solved
    to 1e-6 (its bound is about condition x extended precision x |K| |y|: ~2.6e-5), so that
    answer is "inaccurate", never "solved", though its backward error is 0. (At eps = 1e-15
    the system is singular to working precision: a continuum, judged by its nearest exact
    point, as for an LCP.)"""
    p, exact = near_singular(1e-13)
    acc = assess_fc2d(p, exact)
    assert acc.berr == 0.0 and 1e-6 < acc.ferr < 1e-3

    @lcp.register("fc-exact", accepts="friction-2d", description="test")
    def exact_method(problem, **_):
        return lcp.Solution(z=exact.copy(), w=problem.u(exact), status="solved", method="x")

    try:
        assert lcp.solve(p, "fc-exact").status == "inaccurate"
    finally:
        registry._REGISTRY.pop("fc-exact")


def test_lying_methods_on_both_routes_are_reported_inaccurate():
    """W = I, q = (-1, 2), mu = 0.5 (the only solution slides: r = (1, -0.5)). A native
    method answering r = 0, and an LCP method (the Glocker route) answering z = 0, both
    "solved": both are judged by the same acceptance and reported "inaccurate"."""
    p = lcp.FrictionContact2D(np.eye(2), (-1.0, 2.0), 0.5)

    @lcp.register("fc-zero", accepts="friction-2d", description="test: a liar")
    def zero_fc(problem, **_):
        return lcp.Solution(z=np.zeros(2), w=problem.q, status="solved", method="x")

    @lcp.register("lcp-zero", accepts="any", description="test: a liar")
    def zero_lcp(M, q, **_):
        return lcp.Solution(z=np.zeros(q.size), w=q, status="solved", method="x")

    try:
        for name in ("fc-zero", "lcp-zero"):
            sol = lcp.solve(p, name)
            assert sol.status == "inaccurate" and sol.method == name, sol
            assert "friction-contact acceptance" in sol.message
            assert sol.backward_error >= 0.1
    finally:
        registry._REGISTRY.pop("fc-zero")
        registry._REGISTRY.pop("lcp-zero")


def siconos_files() -> list[Path]:
    files = sorted(SICONOS.glob("*.dat")) if SICONOS.is_dir() else []
    return files or sorted(LOCAL.glob("F*.dat"))  # the copies: 4 of the 6 small files


@pytest.mark.parametrize("path", [f for f in siconos_files() if "granular" not in f.name],
                         ids=lambda f: f.name)
def test_siconos_fc2d_answers_carry_both_errors_and_the_bounds_hold(path):
    """Every method's "solved" on Siconos's small FC2D files carries a backward error <= 1e-8
    and a forward bound <= 1e-6. Two answers with the same contact states approximate the same
    exact point (a nonsingular states' system has one solution), so they differ by at most the
    sum of their bounds: a test the bounds could fail."""
    p = lcp.load(path)
    got = {}
    for name in METHODS:
        if name.startswith("newton") and p.c > 50:
            continue  # dense Newton on the Glocker LCP: seconds; covered on the small files
        sol = lcp.solve(p, name)
        if sol.status != "solved":
            assert sol.status in ("not_converged", "max_iter"), (name, sol)
            continue
        assert sol.backward_error <= 1e-8 and sol.forward_error <= 1e-6, (name, sol)
        cert = verify.certify(p, sol, uniqueness="none")
        assert cert.accepted and cert.forward_error <= 1e-6
        got[name] = (sol.z, sol.forward_error, states_of(p, sol.z))
    assert {"states", "lemke"} <= set(got)
    names = list(got)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            (ra, fa, sa), (rb, fb, sb) = got[a], got[b]
            K = pattern_system(p, sa)[0].toarray()
            if np.array_equal(sa, sb) and (K.size == 0 or np.linalg.cond(K) < 1e12):
                scale = max(np.max(np.abs(ra)), np.max(np.abs(rb)))
                assert np.max(np.abs(ra - rb)) <= (fa + fb) * scale * 1.01 + 1e-300, (a, b)


@pytest.mark.slow
@pytest.mark.skipif(not SICONOS.is_dir(), reason="shared/data/siconos/fc2d is absent")
@pytest.mark.parametrize("name", ["fc2d_granularflowonwall_00667_00000.dat",
                                  "fc2d_granularflowonwall_02020_00213.dat"])
def test_siconos_granular_files_solved_by_states_with_both_errors(name):
    p = lcp.load(SICONOS / name)
    sol = lcp.solve(p, "states")
    assert sol.status == "solved" and sol.backward_error <= 1e-8 and sol.forward_error <= 1e-6


def test_an_event_friction_contact_problem_non_symmetric_w():
    """A disk-array event as a FrictionContact2D (sliding contacts folded into W: not
    symmetric): 'states' and 'lemke' answers are judged on it and agree within their bounds
    where their contact states agree."""
    from rigidlcp import models

    system = models.System(models.rectangular(4, 2), mu_pp=0.3, mu_plane=0.5, mu_wall=0.2,
                           gamma=0.1)
    fc = models.event_problem(system, models.initial_state(system, seed=3)).friction_contact()
    for name in ("states", "lemke"):
        sol = lcp.solve(fc, name)
        assert sol.status == "solved", (name, sol)
        assert sol.backward_error <= 1e-8 and sol.forward_error <= 1e-6
