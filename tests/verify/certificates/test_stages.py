"""Staged uniqueness certificates (verify.certificates.stages): known answers, witnesses that
are solutions, and agreement with exhaustive enumeration."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from rigidlcp import lcp, models
from rigidlcp.verify import certify
from rigidlcp.verify.certificates import certify_stages
from rigidlcp.verify.certificates.stages import OTHER, UNIQUE, UNKNOWN, independent_residual
from rigidlcp.verify.certificates.uniqueness import scales
from rigidlcp.verify.strategies import (
    degenerate_lcps,
    event_states,
    lcps,
    symmetric_psd,
    systems,
)


def _lcp(M, q) -> lcp.LCP:
    return lcp.LCP(np.array(M, dtype=float), np.array(q, dtype=float))


def _check_witness(problem: lcp.LCP, cert) -> None:
    """Every witness is a solution (two residuals) and differs by more than the margin."""
    for v in cert.verdicts.values():
        if v.verdict == OTHER and v.witness is not None:
            w = v.witness
            assert independent_residual(problem.M, problem.q, w.z) <= 1e-8
            assert certify(problem, w.z, uniqueness="none").accepted
            assert w.difference > 1e-4


def test_unique_but_not_a_p_matrix_is_decided_by_the_milp():
    # M skew-symmetric (zero diagonal, not P), q > 0: z = 0 is the only solution, since
    # z_1 > 0 would need w_1 = 1 + z_2 = 0.
    problem = _lcp([[0, 1], [-1, 0]], [1, 1])
    cert = certify_stages(problem, np.zeros(2))
    assert cert.accepted and cert.face_dim == 0
    for name in ("z", "w", "states"):
        assert cert.verdicts[name].verdict == UNIQUE, cert
    assert cert.verdicts["z"].stage == "milp (c2)"
    assert "box" in cert.verdicts["z"].scope


def test_segment_of_solutions_is_found_on_the_face():
    # M = [[1, 1], [1, 1]], q = (-1, -1): the solutions are z1 + z2 = 1, z >= 0; from (1/2, 1/2)
    # the face (both z > 0) is the whole segment: z varies, w = 0 and z1 + z2 do not.
    problem = _lcp([[1, 1], [1, 1]], [-1, -1])
    z = np.array([0.5, 0.5])
    cert = certify_stages(problem, z, observables={"z": np.eye(2), "w": problem.M,
                                                   "sum": [[1.0, 1.0]]})
    v = cert.verdicts["z"]
    assert v.verdict == OTHER and v.stage == "face (a)" and v.witness.same_states
    assert v.witness.changed == []
    np.testing.assert_allclose(v.lo, [0, 0], atol=1e-9)  # ranges over the face: [0, 1] each
    np.testing.assert_allclose(v.hi, [1, 1], atol=1e-9)
    assert cert.face_dim == 1
    for name in ("w", "sum"):
        assert cert.verdicts[name].verdict == UNIQUE
        assert "unique within the face" in cert.verdicts[name].reason
    _check_witness(problem, cert)


def test_other_pattern_is_found_beyond_a_point_face():
    # M = [[1, 2], [2, 1]], q = (-1, -1): solutions (1, 0), (0, 1), (1/3, 1/3). From (1, 0)
    # the face is a point (M_PP = 1): only other contact states give other solutions.
    problem = _lcp([[1, 2], [2, 1]], [-1, -1])
    cert = certify_stages(problem, np.array([1.0, 0.0]))
    assert cert.face_dim == 0
    v = cert.verdicts["z"]
    assert v.verdict == OTHER and v.stage in ("other solvers (c1)", "milp (c2)")
    assert v.witness.changed and not v.witness.same_states
    assert cert.verdicts["states"].verdict == OTHER
    _check_witness(problem, cert)
    # without the cheap solvers, the MILP finds it too
    cert = certify_stages(problem, np.array([1.0, 0.0]), tries=0)
    assert cert.verdicts["z"].verdict == OTHER and cert.verdicts["z"].stage == "milp (c2)"
    _check_witness(problem, cert)


def test_undecided_without_the_milp_says_why():
    problem = _lcp([[0, 1], [-1, 0]], [1, 1])
    cert = certify_stages(problem, np.zeros(2), milp=False)
    assert cert.verdicts["z"].verdict == UNKNOWN and cert.verdicts["z"].reason


def test_rejected_solution_gets_no_verdict():
    problem = _lcp([[2, 1], [1, 2]], [-1, -1])
    cert = certify_stages(problem, np.array([0.5, 0.0]))
    assert not cert.accepted
    assert all(v.verdict == UNKNOWN and v.stage == "residual" for v in cert.verdicts.values())


def _general(n: int):
    return arrays(np.float64, (n, n), elements=st.integers(-4, 4).map(lambda k: k / 4))


_SMALL_LCPS = st.one_of(
    degenerate_lcps(st.integers(2, 8)),
    lcps(symmetric_psd(st.integers(1, 6), singular=True), planted=True),
    st.integers(1, 6).flatmap(lambda n: lcps(_general(n), planted=True)),
)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_SMALL_LCPS)
def test_unique_verdicts_agree_with_enumeration(problem):
    z = np.array(problem.meta["planted_z"])
    cert = certify_stages(problem, z, time_limit=5.0)
    assert cert.accepted
    _check_witness(problem, cert)
    sols = lcp.enumerate_solutions(problem)
    zs, _ = scales(problem.M, problem.q, z)
    for name, L in (("z", np.eye(problem.n)), ("w", problem.M)):
        v = cert.verdicts[name]
        if v.verdict != UNIQUE:
            continue
        sL = max(np.abs(L).sum(axis=1).max() * zs, np.abs(L @ z).max(), 1e-300)
        box = float(v.scope.split("<=")[2].split()[0]) if "box" in v.scope else np.inf
        for s in sols:
            if np.max(s.z) > box:  # outside the box the verdict is stated relative to
                continue
            assert np.max(np.abs(L @ (s.z - z))) <= 1e-3 * sL, (name, s.z, z, v)
            if name == "z":
                assert not s.info.get("continuum"), (s.z, v)


@pytest.fixture(scope="module")
def small_runs():
    out = []
    # frictionless disk-disk contacts: the row compression is free (forces not unique) but
    # does not turn the disks (accelerations unique); with friction it does
    for lattice, mu in ((models.rectangular(2, 1), (0.0, 0.2, 0.0)),
                        (models.rectangular(2, 1), (0.1, 0.2, 0.0)),
                        (models.rectangular(3, 1), (0.3, 0.3, 0.3))):
        system = models.System(lattice, mu_pp=mu[0], mu_plane=mu[1], mu_wall=mu[2], gamma=0.16)
        out.append(models.simulate(system, models.initial_state(system, seed=1),
                                   max_events=12))
    return out


def _agrees_on_event(ep, z):
    cert = certify_stages(ep, z, time_limit=5.0)
    assert cert.accepted
    _check_witness(ep.lcp, cert)
    sols = lcp.enumerate_solutions(ep.lcp)
    from rigidlcp.verify.certificates.stages import observables_of

    _, obs = observables_of(ep)
    zs, _ = scales(ep.lcp.M, ep.lcp.q, z)
    checked = 0
    for name, L in obs.items():
        if cert.verdicts[name].verdict == UNIQUE:
            checked += 1
            sL = max(np.abs(L).sum(axis=1).max() * zs, np.abs(L @ z).max())
            for s in sols:
                assert np.max(np.abs(L @ (s.z - z))) <= 1e-3 * sL, (name, cert)
    return checked


def test_event_verdicts_agree_with_enumeration(small_runs):
    from rigidlcp.verify.forces.polyhedra import event_z

    seen = unique = 0
    for run in small_runs:
        for k in range(run.n_events):
            ep = models.event_problem(run.system, run.state_at(k))
            if ep.lcp.n > 14:
                continue
            rec = run.records[k]
            unique += _agrees_on_event(ep, event_z(ep, np.r_[rec.R, rec.S]))
            seen += 1
    assert seen >= 5 and unique >= 3  # the rect 2x1 frictionless row: accelerations unique


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(systems(st.sampled_from([models.rectangular(2, 1), models.rectangular(3, 1),
                                models.triangular(2, 1)]))
       .flatmap(lambda s: event_states(s).map(lambda state: (s, state))))
def test_drawn_event_verdicts_agree_with_enumeration(data):
    system, state = data
    ep = models.event_problem(system, state)
    if ep.lcp.n > 12:
        return
    sol = lcp.solve(ep.lcp, method="lemke")
    if sol.z is None or not certify(ep, sol.z, uniqueness="none").accepted:
        return  # no solution (Painleve) or an inaccurate one: nothing to certify
    _agrees_on_event(ep, sol.z)


def test_certify_staged_fills_the_classic_certificate():
    problem = _lcp([[1, 2], [2, 1]], [-1, -1])
    cert = certify(problem, np.array([1.0, 0.0]), uniqueness="staged")
    assert cert.method == "staged" and cert.staged is not None
    assert cert.z_unique is False and cert.w_unique is False and cert.pattern_unique is False
    assert certify(problem, cert.other, uniqueness="none").accepted
    cert = certify(_lcp([[0, 1], [-1, 0]], [1, 1]), np.zeros(2), uniqueness="staged")
    assert cert.z_unique is True and cert.w_unique is True


def test_fig9_size_event_witness_keeps_the_tangential_states():
    # rect 10x4 (Fig. 9's array), seed 1: at the first event the accelerations are not unique,
    # and the witness is a solution with the same tangential states (a face witness)
    from rigidlcp.verify.forces.polyhedra import event_z

    system = models.System(models.rectangular(10, 4), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.16)
    run = models.simulate(system, models.initial_state(system, seed=1), max_events=1)
    ep = models.event_problem(system, run.state_at(0))
    rec = run.records[0]
    z = event_z(ep, np.r_[rec.R, rec.S])
    cert = certify_stages(ep, z, milp=False)
    v = cert.verdicts["accelerations"]
    assert v.verdict == OTHER and v.stage == "face (a)"
    a, b = ep.unpack(z), ep.unpack(v.witness.z)
    assert np.array_equal(a.s, b.s)
    assert np.max(np.abs(a.omega_dot - b.omega_dot)) > 1e-3
    assert np.max(np.abs(a.trans_acc - b.trans_acc)) < 1e-9  # no displacement either way
    _check_witness(ep.lcp, cert)


def test_unbounded_ranges_are_infinite():
    # M = [[1, -1], [-1, 1]], q = 0: the ray z1 = z2 = t >= 0 is a face of solutions
    problem = _lcp([[1, -1], [-1, 1]], [0, 0])
    cert = certify_stages(problem, np.array([1.0, 1.0]))
    v = cert.verdicts["z"]
    assert v.verdict == OTHER and v.stage == "face (a)"
    np.testing.assert_allclose(v.lo, [0, 0], atol=1e-9)
    assert np.all(np.isinf(v.hi))
    assert cert.verdicts["w"].verdict == UNIQUE
