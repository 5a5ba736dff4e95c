"""Geometry as data (issue 22.1): any set of disks, the arrays as generators of it.

* The regular arrays' event problems are bit for bit those of the code before per-disk radii,
  masses and inertias (tests/data/event_lcps_regular_2eda03e.npz, written at commit 2eda03e
  by `_event_arrays` below).
* An array rebuilt as a packing (contacts detected from the centres and radii) has the same
  H, W, q and event LCPs, up to the order of the contacts: exactly, not approximately.
* Overlaps are refused by name; rattlers and floating clusters reported; per-disk radii reach
  the tangential velocities; a packing run saves and reloads its geometry.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.event import State, event_problem, initial_state
from rigidlcp.models.packing import Overlap, packing, report

DATA = Path(__file__).resolve().parents[1] / "data" / "event_lcps_regular_2eda03e.npz"


def _event_arrays() -> dict[str, np.ndarray]:
    out = {}
    for name, lx, ly in (("rect", 4, 3), ("tri", 4, 3), ("rect", 1, 1), ("tri", 3, 4)):
        for kw in ({}, {"gamma": 0.3, "V0": 1.0, "mass": 2.0}, {"inertia": 0.7, "mu_wall": 0.2}):
            sysm = models.System(models.make_lattice(name, lx, ly, radius=0.37), **kw)
            for seed in (None, 1, 2):
                ep = event_problem(sysm, initial_state(sysm, seed=seed))
                key = f"{name}{lx}{ly}_{sorted(kw)}_{seed}"
                out[key + "_M"], out[key + "_q"] = ep.lcp.M, ep.lcp.q
            d = Dynamics(sysm)
            out[key + "_H"], out[key + "_f"], out[key + "_Minv"] = d.H.toarray(), d.f, d.Minv
            out[key + "_tm"] = np.array(sysm.total_mass)
            out[key + "_I"] = np.array(sysm.inertia)
    return out


def test_regular_arrays_bit_for_bit_as_before():
    before = np.load(DATA)
    now = _event_arrays()
    assert sorted(before.files) == sorted(now)
    for key in before.files:
        assert before[key].shape == now[key].shape, key
        assert np.array_equal(before[key], now[key]), key


def _as_packing(lat: models.Lattice) -> models.Lattice:
    return packing(lat.x, lat.radii, left=lat.left, right=lat.right)


def _permutation(lat: models.Lattice, pk: models.Lattice) -> np.ndarray:
    """perm with pk contact perm[a] = lat contact a (same bodies)."""
    where = {(int(i), int(j)): b for b, (i, j) in enumerate(zip(pk.i, pk.j))}
    return np.array([where[(int(i), int(j))] for i, j in zip(lat.i, lat.j)])


def _compare(radius: float, same) -> None:
    lat = models.rectangular(4, 3, radius)
    pk = _as_packing(lat)
    assert pk.c == lat.c and not pk.regular
    perm = _permutation(lat, pk)
    assert np.array_equal(pk.kind[perm], lat.kind)
    same(pk.n[perm], lat.n)
    kw = {"gamma": 0.2, "mu_wall": 0.1}
    sa, sb = models.System(lat, **kw), models.System(pk, **kw)
    rows = np.r_[perm, pk.c + perm]
    da, db = Dynamics(sa), Dynamics(sb)
    same(db.W[np.ix_(rows, rows)], da.W)
    same(db.q[rows], da.q)
    for seed in (None, 3):
        st = initial_state(sa, seed=seed)
        sp = np.zeros(pk.c, dtype=int)
        sp[perm] = st.s
        ea = event_problem(sa, st)
        eb = event_problem(sb, State(0.0, st.omega, st.V, sp))
        # z = [R (c), tau (k), a_minus (k)]: candidates in increasing contact order
        cand_b = {int(a): k for k, a in enumerate(eb.candidates)}
        kb = np.array([cand_b[int(perm[a])] for a in ea.candidates], dtype=int)
        z = np.r_[perm, pk.c + kb, pk.c + eb.k + kb]
        same(eb.lcp.M[np.ix_(z, z)], ea.lcp.M)
        same(eb.lcp.q[z], ea.lcp.q)


def test_rectangular_as_packing_same_event_problems():
    """radius 1: every centre is an integer, so detection must give the array's exact normals
    and hence exactly its event LCPs (contacts permuted)."""
    def exact(a, b):
        assert np.array_equal(a, b)

    _compare(1.0, exact)


def test_rectangular_as_packing_rounding_only():
    """radius 0.37: the array's vertical normals are d / (2 r) with d rounded (not exactly
    unit), the packing's d / |d|; they agree to rounding, and so do the LCPs."""
    def close(a, b):
        assert np.allclose(a, b, rtol=1e-14, atol=1e-14 * max(np.abs(b).max(initial=0), 1))

    _compare(0.37, close)


def test_triangular_as_packing_same_contacts():
    lat = models.triangular(4, 3)
    pk = _as_packing(lat)
    perm = _permutation(lat, pk)
    assert np.allclose(pk.n[perm], lat.n, rtol=0, atol=1e-15)


def test_overlaps_refused_by_name():
    with pytest.raises(Overlap, match="disks 0 and 1 overlap by 0.5"):
        packing([[1, 1], [2.5, 1]], [1, 1])
    with pytest.raises(Overlap, match="disk 1 overlaps the plane by 0.1"):
        packing([[1, 1], [4, 0.9]], [1, 1])
    with pytest.raises(Overlap, match="disk 0 overlaps the left wall"):
        packing([[1, 1]], [1], left=0.5)
    err = pytest.raises(Overlap, packing, [[1, 1], [3 - 1e-6, 1]], [1, 1]).value
    assert (err.i, err.j) == (0, 1) and err.overlap == pytest.approx(1e-6)
    # within the stated tolerance: a contact, not an overlap
    assert packing([[1, 1], [3 - 1e-10, 1]], [1, 1]).c == 3
    assert packing([[1, 1], [3 + 1e-10, 1]], [1, 1]).c == 3
    assert packing([[1, 1], [3 + 1e-6, 1]], [1, 1]).c == 2


def test_rattlers_and_clusters():
    # two disks on the plane side by side, one floating above, one alone on the plane
    lat = packing([[1, 1], [3, 1], [10, 5], [20, 1]], [1, 1, 1, 1], left=0, right=30)
    rep = report(lat)
    assert rep.rattlers == [2, 3]  # 2 touches nothing; 3 only the plane
    assert [sorted(c) for c in rep.clusters] == [[0, 1], [2], [3]]
    assert [rep.clusters[k] for k in rep.floating] == [[2]]


def test_per_disk_radii_reach_tangential_velocity():
    # disk 0 (r = 1) on the plane, disk 1 (r = 2) beside it, touching
    d = 3.0 / np.sqrt(2.0)
    lat = packing([[1, 2], [1 + d, 2 + d]], [1.0, 2.0], left=None, right=None)
    sysm = models.System(lat, mu_plane=0.3)
    pp = int(np.flatnonzero(lat.kind == "pp")[0])
    omega = np.array([0.7, -1.3])
    vt = Dynamics(sysm).velocities(omega, 0.0)[lat.c + pp]
    assert vt == pytest.approx(-(1.0 * 0.7 + 2.0 * -1.3), rel=1e-15)
    # default inertia I_i = m r_i^2 / 2, total mass the sum
    assert np.allclose(sysm.inertias, [0.5, 2.0])
    heavy = packing(lat.x, lat.radii, m=[1.0, 4.0], I=[0.5, 8.0])
    assert models.System(heavy).total_mass == 5.0
    with pytest.raises(models.InvalidSystem, match="mass: the packing gives"):
        models.System(heavy, mass=2.0)


def test_packing_run_saves_and_reloads_geometry(tmp_path):
    from rigidlcp.models.runio import load_run, save_run

    a, b = np.array([1.0, 1.0]), np.array([1 + 2 * np.sqrt(1.5), 1.5])  # r = 1 and 1.5
    d = np.linalg.norm(b - a)  # 2.5: disk 2 (r = 1) rests on both, at 2 from a and 2.5 from b
    along = (4.0 - 6.25 + d**2) / (2 * d)
    u = (b - a) / d
    top = a + along * u + np.sqrt(4.0 - along**2) * np.array([-u[1], u[0]])
    lat = packing([a, b, top], [1.0, 1.5, 1.0], m=[1, 2.25, 1], left=0, right=b[0] + 1.5)
    assert lat.c == 7
    run = models.simulate(models.System(lat, gamma=0.1), seed=1, max_events=10)
    path = save_run(run, tmp_path / "run")
    back = load_run(path)
    bl = back.system.lattice
    assert np.array_equal(bl.x, lat.x) and np.array_equal(bl.radii, lat.radii)
    assert np.array_equal(bl.i, lat.i) and np.array_equal(bl.j, lat.j)
    assert np.array_equal(back.system.masses, [1, 2.25, 1])
    assert np.array_equal(back.system.inertias, run.system.inertias)
    assert np.array_equal(back.array("R"), run.array("R"))


def test_closed_forms_refuse_a_packing():
    from rigidlcp.verify.nullspace.formulas import NoClosedForm, closed_forms

    assert closed_forms(models.rectangular(3, 2)) == {"normal": 2, "tangential": 3 * 2 + 2}
    with pytest.raises(NoClosedForm, match="general packing has none"):
        closed_forms(packing([[1, 1]], [1.0]))
