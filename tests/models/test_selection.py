"""Selection rules (models/selection.py, issue 21.4): each rule is a parameter, lands on a
valid point of the solution set, and rules differ where the set is known not to be a point."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rigidlcp import lcp, models
from rigidlcp.cli import main
from rigidlcp.models.selection import InvalidSelection, Selection, select
from rigidlcp.models.timestepping import InvalidStep, moreau_jean
from rigidlcp.verify import certify
from rigidlcp.verify.ensemble import format_ensemble, selection_ensemble
from rigidlcp.verify.integrators import event_check
from rigidlcp.verify.strategies import event_states, systems

RULES = ("face-min-norm", "max-sum-R", "random:0", "random:5")


def _row(gamma: float = 0.02) -> models.System:
    """A 10x1 row between frictionless walls: the row's self-stress (a horizontal compression)
    makes the forces of its events a continuum (Sec. III)."""
    return models.System(models.rectangular(10, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                         gamma=gamma)


def _stick_side(ep) -> np.ndarray:
    side = np.zeros(ep.lcp.n, bool)
    side[: ep.system.c + ep.k] = True
    return side


def test_parse_and_refuse():
    assert str(Selection.parse("random:7")) == "random:7"
    assert Selection.parse("max-sum-R:3").cap == 3.0
    for bad in ("best", "random", "random:x", "random:-1", "max-sum-R:0.5", "none:1"):
        with pytest.raises(InvalidSelection):
            Selection.parse(bad)
    with pytest.raises(ValueError, match="random:SEED"):
        models.simulate(_row(), seed=1, selection="random")
    with pytest.raises(InvalidStep, match="global"):
        moreau_jean(_row(), seed=1, h=4e-3, selection="global")


def test_rules_land_on_different_valid_points_of_the_row_self_stress():
    """At the first event of the row the solution set is a continuum: every rule's point is a
    solution (independent certificate), max-sum-R has the larger sum R, the random points
    differ between seeds and lie within the sum-R interval of the two ends."""
    system = _row()
    ep = models.event_problem(system, models.initial_state(system, seed=1))
    z = lcp.solve(ep.lcp, method="lemke").z
    c = system.c
    points = {}
    for rule in RULES:
        sel = Selection.parse(rule)
        y, status = select(ep.lcp, z, ep.G, c, _stick_side(ep), sel)
        assert not status.startswith("failed"), (rule, status)
        assert certify(ep, y, uniqueness="none").accepted, rule
        points[rule] = y
    lo, hi = points["face-min-norm"][:c].sum(), points["max-sum-R"][:c].sum()
    assert hi > lo * (1 + 1e-3)
    for rule in ("random:0", "random:5"):
        assert lo - 1e-9 <= points[rule][:c].sum() <= hi + 1e-9
    assert np.max(np.abs(points["random:0"] - points["random:5"])) > 1e-6


def test_steady_states_of_two_rules_differ_and_both_are_valid():
    """The row ends steady under each rule; the two steady states differ in mu_g, and each is
    a steady solution of the exact event laws at its configuration."""
    system = _row()
    a = models.simulate(system, seed=1, selection="face-min-norm")
    b = models.simulate(system, seed=1, selection="max-sum-R")
    assert a.status == b.status == "steady"
    assert abs(a.last.mu_g - b.last.mu_g) > 1e-3
    assert a.method == "lemke" and b.method == "lemke (selection max-sum-R)"
    for run in (a, b):
        chk = event_check(system, run.last)
        assert chk.valid and chk.steady


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(systems(st.sampled_from([models.rectangular(2, 1), models.rectangular(3, 1),
                                models.rectangular(2, 2), models.triangular(2, 1)]))
       .flatmap(lambda s: event_states(s).map(lambda state: (s, state))),
       st.sampled_from(RULES))
def test_every_selected_point_satisfies_the_laws(data, rule):
    system, state = data
    ep = models.event_problem(system, state)
    sol = lcp.solve(ep.lcp, method="lemke")
    if sol.z is None or not certify(ep, sol.z, uniqueness="none").accepted:
        return  # no solution (Painleve) or an inaccurate one: nothing to select from
    sel = Selection.parse(rule)
    y, status = select(ep.lcp, sol.z, ep.G, system.c, _stick_side(ep), sel)
    if status.startswith("failed"):
        return  # the engine then keeps the solver's (checked) point
    assert certify(ep, y, uniqueness="none").accepted


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(systems(st.sampled_from([models.rectangular(2, 1), models.rectangular(3, 1),
                                models.rectangular(2, 2)])),
       st.integers(0, 10_000), st.sampled_from(RULES))
def test_every_selected_step_point_satisfies_the_step_laws(system, seed, rule):
    """The same on a Moreau-Jean step's LCP (z = [P_n, tau, u_minus], every frictional contact
    a candidate), checked by the step's own Coulomb-law residual of the impulses P = G z."""
    from rigidlcp.models.dynamics import Dynamics
    from rigidlcp.models.timestepping import StepProblem, coulomb_residual

    dyn = Dynamics(system)
    h = 1e-2
    omega = np.random.default_rng(seed).uniform(-1, 1, system.p)
    nu = np.concatenate([np.zeros(2 * system.p), omega])
    b = dyn.H @ (nu + h * dyn.Minv * dyn.f) + dyn.u_obs(h * system.gamma)
    sp = StepProblem(system, dyn, np.zeros(system.c, int))
    problem = sp.lcp(b, h)
    sol = lcp.solve(problem, method="lemke")
    if sol.status != "solved":
        return
    sel = Selection.parse(rule)
    y, status = select(problem, sol.z, sp.G, system.c, np.arange(sp.n) < system.c + sp.k,
                       sel)
    if status.startswith("failed"):
        return
    P = sp.G @ y
    u = dyn.H @ (nu + dyn.Minv * (dyn.H.T @ P) + h * dyn.Minv * dyn.f) + dyn.u_obs(
        h * system.gamma)
    P_scale = max(float(np.abs(P).max()), h * system.mass * system.g)
    u_scale = max(float(np.abs(b).max()), system.g * h)
    assert coulomb_residual(system, P, u, P_scale, u_scale) <= 1e-8


def test_time_stepper_rules_reach_different_checked_steady_states():
    system = _row()
    a = moreau_jean(system, seed=1, h=4e-3, t_max=20)
    b = moreau_jean(system, seed=1, h=4e-3, t_max=20, selection="max-sum-R")
    assert a.status == b.status == "steady"
    assert abs(a.last.mu_g - b.last.mu_g) > 1e-3
    assert "selection max-sum-R" in b.method
    assert event_check(system, b.last).valid


def test_ensemble_and_command(capsys):
    ens = selection_ensemble(_row(), seed=1, rules=("face-min-norm", "max-sum-R"))
    lo, hi = ens.mu_g_range
    assert hi - lo > 1e-3 and ens.distinct_states == 2
    assert "spread" in format_ensemble(ens)
    assert main(["compare-integrators", "--lx", "4", "--ly", "1", "--gamma", "0.02",
                 "--ensemble", "face-min-norm,random:3"]) == 0
    assert "valid steady states: 2 of 2" in capsys.readouterr().out
    assert main(["compare-integrators", "--lx", "4", "--ly", "1", "--ensemble",
                 "face-min-norm,nosuch"]) == 2
    err = capsys.readouterr().err
    assert "nosuch" in err and len(err.strip().splitlines()) == 1
    assert main(["compare-integrators", "--lx", "2", "--ly", "1", "--step-rules", "none"]) == 2
    assert "--ensemble" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:  # argparse: one line, exit status 2
        main(["timestep", "--lx", "2", "--ly", "1", "--selection", "best"])
    assert exc.value.code == 2 and "--selection" in capsys.readouterr().err


def test_random_point_is_a_function_of_the_face():
    """Without the event engine's per-run generator (the time-stepper's case) "random:SEED"
    draws its functionals and weights from SEED and a fingerprint of the face: the same face
    gives the same point on every call (a per-run generator gives a new one at every call),
    another seed another point, and the generator depends on the support."""
    system = _row()
    ep = models.event_problem(system, models.initial_state(system, seed=1))
    z = lcp.solve(ep.lcp, method="lemke").z
    sel = Selection.parse("random:4")
    a, _ = select(ep.lcp, z, ep.G, system.c, _stick_side(ep), sel)
    b, _ = select(ep.lcp, z, ep.G, system.c, _stick_side(ep), sel)
    other, _ = select(ep.lcp, z, ep.G, system.c, _stick_side(ep), Selection.parse("random:5"))
    assert np.array_equal(a, b) and np.max(np.abs(a - other)) > 1e-6
    mask = np.zeros(7, bool)
    mask[[1, 3]] = True
    draw = sel.face_rng(mask).standard_normal(3)
    assert np.array_equal(draw, sel.face_rng(mask.copy()).standard_normal(3))
    mask[4] = True
    assert not np.array_equal(draw, sel.face_rng(mask).standard_normal(3))


def test_time_stepper_random_rules_settle_in_the_ensemble():
    """issue 21.4: the time-stepper under random:1 and random:2 (a 4x1 row, whose steps' forces
    are a continuum) reaches steady states, each checked against the exact event laws
    (valid, steady), and they spread mu_g beyond the event engine's face-min-norm state."""
    system = models.System(models.rectangular(4, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.02)
    ens = selection_ensemble(system, seed=1, rules=("face-min-norm",), h=1e-2, t_max=20,
                             step_rules=("random:1", "random:2"))
    assert [r.rule for r in ens.rows] == ["face-min-norm", "random:1", "random:2"]
    for row in ens.rows:
        assert row.run.status == "steady" and row.valid_steady, (row.rule, row.run.message)
    lo, hi = ens.mu_g_range
    assert hi - lo > 1e-3


@pytest.mark.slow
def test_compare_integrators_ensemble_with_a_random_step_rule(capsys):
    assert main(["compare-integrators", "--lx", "4", "--ly", "1", "--gamma", "0.02",
                 "--mu-wall", "0", "--ensemble", "face-min-norm", "--step-rules", "random:1",
                 "--h", "0.01"]) == 0
    out = capsys.readouterr().out
    assert "valid steady states: 2 of 2" in out
