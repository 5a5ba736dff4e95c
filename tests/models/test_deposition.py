"""Sequential deposition (issue 22.2): its invariants, checked independently of the code that
places the disks.

* No overlap beyond the gap tolerance (all pairs, brute force) and every disk inside the box.
* Every disk is supported: the contacts it has with the bodies placed before it (earlier disks,
  walls, plane) hold its weight with compressive forces, i.e. (0, 1) = sum R_c n_c with R >= 0
  (non-negative least squares residual ~ 0; n_c from the support to the disk). So no disk is a
  rattler and every cluster of the contact graph rests on an obstacle.
* Seeded: the same seed gives the same packing; radii within [MIN, MAX].
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import nnls

from rigidlcp import models
from rigidlcp.models.deposition import deposit, with_vacancies
from rigidlcp.models.packing import report


def assert_inside_without_overlap(lat: models.Lattice) -> None:
    """No two disks overlap beyond the gap tolerance (all pairs), every disk above the plane
    and between the walls."""
    x, r = lat.x, lat.radii
    d = np.hypot(*(x[:, None, :] - x[None, :, :]).transpose(2, 0, 1))
    gap = d - r[:, None] - r[None, :]
    np.fill_diagonal(gap, np.inf)
    assert gap.min() >= -1e-9 * r.min()
    assert np.all(x[:, 1] - r >= -1e-9 * r) and np.all(x[:, 0] - r >= lat.left - 1e-9 * r)
    assert np.all(x[:, 0] + r <= lat.right + 1e-9 * r)


def _check_invariants(lat: models.Lattice) -> None:
    assert_inside_without_overlap(lat)
    for k in range(lat.p):
        normals = [-lat.n[a] for a in np.flatnonzero(lat.i == k)
                   if lat.j[a] < 0 or lat.j[a] < k]
        normals += [lat.n[a] for a in np.flatnonzero(lat.j == k) if lat.i[a] < k]
        assert len(normals) >= 1, k
        _, residual = nnls(np.array(normals).T, np.array([0.0, 1.0]))
        assert residual <= 1e-9, (k, residual)
    rep = report(lat)
    assert rep.rattlers == [] and rep.floating == []  # clusters may be several, all grounded


@pytest.mark.parametrize("radii", [(1.0, 1.0), (0.5, 1.5), (0.9, 1.1)])
def test_deposition_invariants(radii):
    lat = deposit(150, seed=7, radii=radii)
    _check_invariants(lat)
    assert np.all((lat.radii >= radii[0]) & (lat.radii <= radii[1]))
    again = deposit(150, seed=7, radii=radii)
    assert np.array_equal(again.x, lat.x) and np.array_equal(again.radii, lat.radii)


@settings(max_examples=25)
@given(n=st.integers(1, 40), seed=st.integers(0, 10**6),
       a=st.floats(0.2, 2.0), spread=st.floats(1.0, 4.0), cells=st.integers(1, 8))
def test_deposition_invariants_property(n, seed, a, spread, cells):
    b = a * spread
    _check_invariants(deposit(n, seed=seed, radii=(a, b), width=2 * b * cells))


def test_narrow_box_and_bad_arguments():
    lat = deposit(5, seed=1, radii=(1.0, 1.0), width=2.0)  # a column: each disk on the last
    assert np.allclose(lat.x[:, 0], 1.0) and np.allclose(lat.x[:, 1], [1, 3, 5, 7, 9])
    with pytest.raises(models.InvalidSystem, match="width"):
        deposit(5, radii=(1.0, 1.0), width=1.5)
    with pytest.raises(models.InvalidSystem, match="radii"):
        deposit(5, radii=(2.0, 1.0))
    for radii in ((1.0, 1e300), (1e80, 1e80), (1e-100, 1e-100), (1e-300, 1.0)):
        with pytest.raises(models.InvalidSystem, match="inertia r"):  # before any disk falls
            deposit(5, radii=radii)
    for radii in ((1e76, 1e76), (1e-76, 1e-76)):  # the ends: masses and inertias normal
        lat = deposit(5, seed=1, radii=radii)
        assert np.all(np.isfinite(lat.inertias)) and np.all(lat.inertias > 0)
    with pytest.raises(models.InvalidSystem, match="n must be"):
        deposit(0)


def test_vacancies_keep_exact_contacts_and_report_rattlers():
    lat = models.rectangular(6, 4)
    holed = with_vacancies(lat, 0.25, seed=2)
    assert holed.p == 18
    rep = report(holed)
    # in a rectangular array a disk loses a support with each vacancy below or beside it:
    # rattlers are exactly the disks left with fewer than two contacts
    deg = np.bincount(holed.i, minlength=holed.p) + np.bincount(holed.j[holed.j >= 0],
                                                                minlength=holed.p)
    assert rep.rattlers == np.flatnonzero(deg < 2).tolist()


@pytest.mark.parametrize("seed", range(8))
def test_no_contact_tilted_by_rounding(seed):
    """Monodisperse piles put disks side by side at a support's equator (a wall, a row). The
    grazing intersections that find such a position (asin or sqrt near 1 or 0) are off by
    sqrt(eps) ~ 2e-8, which tilted a horizontal contact by that much and left the disk on it
    alone, a support whose force balance needs ~1e8 weights (seed 3: R >= 7.9e7 at a wall in
    `rigidlcp forceset`). Refined onto its best-conditioned supports, no contact normal is
    within (1e-12, 1e-6) of an axis: exact to rounding, or clearly tilted."""
    lat = deposit(50, seed)
    tilt = np.minimum(np.abs(lat.n[:, 0]), np.abs(lat.n[:, 1]))
    assert not np.any((tilt > 1e-12) & (tilt < 1e-6)), tilt[(tilt > 1e-12) & (tilt < 1e-6)]
    _check_invariants(lat)
