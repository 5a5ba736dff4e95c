"""verify.forces.particular: force polyhedra, ranges, particular solutions; `rigidlcp forces`."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rigidlcp import lcp, models
from rigidlcp.cli.main import main
from rigidlcp.verify import certify
from rigidlcp.verify.forces.particular import (
    EmptyPolyhedron,
    event_z,
    force_ranges,
    global_friction_vector,
    lcp_polyhedron,
    min_norm_solution,
    paper_solution,
    random_vertex,
    solution_polyhedron,
    state_polyhedron,
)


def all_transmitting(system: models.System, seed: int | None = None):
    """The event of random angular velocities (all frictional contacts sliding), the solver's
    solution, and the polyhedron of its contact states."""
    state = models.initial_state(system, seed=seed)
    ep = models.event_problem(system, state)
    sol = lcp.solve(ep.lcp, method="lemke")
    es = ep.unpack(sol.z)
    return ep, sol, state_polyhedron(system, es.a_n <= 1e-9, es.s)


# -- the analytic case: one row between the walls ------------------------------------------------


@pytest.mark.parametrize("gamma", [0.0, 0.1, -0.2])
@pytest.mark.parametrize("lx", [1, 3, 4])
def test_single_row_ranges_are_tight(lx, gamma):
    """Frictionless row of lx disks on the plane between two walls. Disk k is pushed right by
    its left lateral contact (R_k) and left by its right one (R_{k+1}) and feels -m gamma:
    R_{k+1} = R_k - m gamma, so R_k = R_0 - k m gamma with R_0 free (the row's self-stress)
    but every R_k >= 0: R_k in [max over the row of the lower bounds, inf). The plane carries
    m g per disk; F_g = 0."""
    m, g = 1.0, 1.0
    system = models.System(models.rectangular(lx, 1), mu_pp=0.0, mu_plane=0.0, mu_wall=0.0,
                           gamma=gamma, mass=m, g=g)
    lat = system.lattice
    poly = state_polyhedron(system, np.ones(system.c, bool), np.zeros(system.c, int))
    rng = force_ranges(poly, {"F_g": global_friction_vector(system)})
    c = system.c
    plane = lat.j == models.PLANE
    np.testing.assert_allclose(rng.lo[:c][plane], m * g, atol=1e-9)
    np.testing.assert_allclose(rng.hi[:c][plane], m * g, atol=1e-9)
    # lateral contacts from left to right: left wall, the lx - 1 disk pairs, right wall
    lateral = [a for a in range(c) if not plane[a]]
    lateral.sort(key=lambda a: lat.x[lat.i[a], 0] + lat.radius * lat.n[a, 0])
    k = np.arange(lx + 1)
    R0_min = max(0.0, lx * m * gamma)  # R_k >= 0 for every k
    np.testing.assert_allclose(rng.lo[lateral], R0_min - k * m * gamma, atol=1e-9)
    assert np.all(np.isinf(rng.hi[lateral]))
    assert rng.observables["F_g"] == pytest.approx((0.0, 0.0), abs=1e-12)
    # the minimum-norm point has the least compression: the lower ends of the ranges
    for solver in ("CLARABEL", "OSQP"):
        mn = min_norm_solution(poly, solver)
        np.testing.assert_allclose(mn.R[lateral], rng.lo[lateral], atol=1e-6)
        assert mn.eq_residual <= 1e-8 and mn.violation <= 1e-8
    # the paper's choice zeroes every lateral force it can: all of them when gamma = 0
    pa = paper_solution(poly)
    assert pa.n_nt == (lx + 1 if gamma == 0 else 1)
    assert "unbounded" in pa.message


def test_single_row_lcp_solution_inside_ranges():
    system = models.System(models.rectangular(3, 1), mu_pp=0.0, mu_plane=0.0, mu_wall=0.0,
                           gamma=0.1)  # frictionless, as the analytic case above
    ep, sol, poly = all_transmitting(system)
    x = ep.forces(sol.z)
    rng = force_ranges(solution_polyhedron(ep, sol.z))
    assert rng.contains(x, 1e-9)
    assert np.all(np.isinf(rng.hi[3:7]))  # the compression stays free at fixed accelerations


# -- ranges contain the solver's solution; particular solutions are admissible -------------------


@pytest.fixture(scope="module")
def tri_3x3():
    system = models.System(models.triangular(3, 3), mu_pp=0.3, mu_plane=0.3)
    return system, *all_transmitting(system, seed=2)


def test_ranges_contain_the_solver_solution(tri_3x3):
    system, ep, sol, poly = tri_3x3
    x = ep.forces(sol.z)
    assert poly.contains(x)
    gvec = global_friction_vector(system)
    rng = force_ranges(poly, {"F_g": gvec})
    assert rng.contains(x, 1e-8)
    lo, hi = rng.observables["F_g"]
    assert lo - 1e-9 <= gvec @ x <= hi + 1e-9
    assert hi - lo > 1e-3  # indeterminate global friction in this state


def test_particular_solutions_are_lcp_solutions(tri_3x3):
    system, ep, sol, poly = tri_3x3
    rng = force_ranges(poly)
    found = [min_norm_solution(poly, "CLARABEL"), min_norm_solution(poly, "OSQP"),
             paper_solution(poly, ranges=rng), paper_solution(poly, "l1"),
             random_vertex(poly, 0), random_vertex(poly, 1)]
    for p in found:
        assert p.eq_residual <= 1e-7 and p.violation <= 1e-7, p.method
        assert rng.contains(p.x, 1e-6)
        assert certify(ep, event_z(ep, p.x), uniqueness="none", tol=1e-7).accepted, p.method
    mn_c, mn_o, paper, l1 = found[:4]
    np.testing.assert_allclose(mn_c.x, mn_o.x, atol=1e-5)
    assert np.linalg.norm(mn_c.x) <= np.linalg.norm(ep.forces(sol.z)) + 1e-8
    assert np.linalg.norm(mn_c.x) <= min(np.linalg.norm(p.x) for p in found[2:]) + 1e-8
    assert paper.n_nt >= max(l1.n_nt, mn_c.n_nt, found[4].n_nt, found[5].n_nt)


def test_fixed_accelerations_fix_the_forces_when_all_contacts_slide(tri_3x3):
    """All contacts sliding: a self-stress changes R, hence the friction mu R and the torques,
    hence the angular accelerations. Fixing the accelerations leaves a single force vector."""
    system, ep, sol, poly = tri_3x3
    rng = force_ranges(solution_polyhedron(ep, sol.z))
    assert np.max(rng.width) <= 1e-8
    np.testing.assert_allclose(rng.lo, ep.forces(sol.z), atol=1e-8)


def test_fixed_accelerations_2x2_example():
    """The natural solution of the 2 x 2 example (tests/verify/test_certify.py) lies in a
    continuum of forces with the same accelerations: every vertex is an LCP solution with them."""
    system = models.System(models.rectangular(2, 2), mu_pp=0.1, mu_plane=0.2, gamma=0.1)
    s = np.array([0, 0, 0, 1, 0, 0, 0, 0, -1, 0])
    ep = models.event_problem(system, models.State(8.52, np.zeros(4), 0.0, s))
    sol = lcp.solve(ep.lcp, method="lemke")
    poly = solution_polyhedron(ep, sol.z)
    rng = force_ranges(poly, {"F_g": global_friction_vector(system)})
    assert rng.contains(ep.forces(sol.z), 1e-9)
    assert np.max(rng.width) > 1.0
    lo, hi = rng.observables["F_g"]
    assert hi - lo > 0.1
    omega_dot = ep.unpack(sol.z).omega_dot
    for seed in range(4):
        z = event_z(ep, random_vertex(poly, seed).x)
        assert certify(ep, z, uniqueness="none").accepted
        np.testing.assert_allclose(ep.unpack(z).omega_dot, omega_dot, atol=1e-9)


def test_lcp_polyhedron_fixes_w():
    # the frictionless row: w is unique, z is a continuum; every point has the same w
    system = models.System(models.rectangular(3, 1), gamma=0.1)
    ep = models.event_problem(system, models.initial_state(system))
    sol = lcp.solve(ep.lcp, method="lemke")
    poly = lcp_polyhedron(ep.lcp.M, ep.lcp.q, sol.z)
    for seed in range(3):
        z = random_vertex(poly, seed).x
        np.testing.assert_allclose(ep.lcp.M @ z, ep.lcp.M @ sol.z, atol=1e-9)
        assert certify(ep.lcp, z, uniqueness="none").accepted


def test_inadmissible_states_are_reported():
    # A single disk on the plane with its only supporting contact NT: nothing holds it up.
    system = models.System(models.rectangular(1, 1))
    normal = np.ones(system.c, bool)
    normal[system.lattice.j == models.PLANE] = False
    poly = state_polyhedron(system, normal, np.zeros(system.c, int))
    with pytest.raises(EmptyPolyhedron):
        force_ranges(poly)


# -- the command ---------------------------------------------------------------------------------


def test_forces_command(tmp_path, capsys):
    out = tmp_path / "fig4"
    code = main(["forces", "--lattice", "tri", "--lx", "4", "--ly", "2", "--seed", "3",
                 "--networks", "5", "--out", str(out), "--json"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    nets = summary["networks"]
    assert len(nets) == 5 and all(n["accepted"] for n in nets)
    R = np.array([n["R"] for n in nets])
    assert len({tuple(np.round(r, 6)) for r in R}) == 5  # five different networks
    assert summary["candidates"] == 0  # every frictional contact slides
    for path in summary["png"]:
        assert (out / path.split("/")[-1]).stat().st_size > 1000
    assert (out / "forces.json").exists()
    # a small array has few vertices: fewer networks than asked, and it says so
    argv = ["forces", "--lattice", "tri", "--lx", "3", "--ly", "2", "--seed", "3",
            "--networks", "6", "--out", str(out)]
    assert main(argv) == 2  # the files of the first call are the user's now
    assert "--force" in capsys.readouterr().err
    code = main(argv + ["--force"])
    assert code == 0 and "only 4 distinct networks" in capsys.readouterr().out


@pytest.mark.slow
def test_forces_command_fig4_size(tmp_path, capsys):
    code = main(["forces", "--lattice", "tri", "--lx", "5", "--ly", "4", "--out",
                 str(tmp_path)])
    assert code == 0
    text = capsys.readouterr().out
    assert "paper's choice" in text and "F_g in [" in text
