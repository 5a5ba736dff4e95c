"""Arrays with size disorder (models.disorder, issue 22.2): invariants checked independently of
the code that places the disks, the regular array at spread 0, refusals by name, the CLI."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import nnls

from rigidlcp import models
from rigidlcp.cli.main import main
from rigidlcp.models.disorder import with_size_disorder
from rigidlcp.models.packing import report
from rigidlcp.models.packing_io import read_packing

from .test_deposition import assert_inside_without_overlap


def _check(lat: models.Lattice, regular: models.Lattice, spread: float) -> None:
    """No overlap beyond the gap tolerance (all pairs), inside the box, radii in range, the
    bottom row against both walls, and every disk held by what was placed before it (row by
    row, left to right): (0, 1) = sum R_c n_c with R >= 0 over those contacts."""
    r = lat.radii
    r0 = regular.radius
    assert np.all(r >= r0 * (1 - spread) - 1e-15) and np.all(r <= r0 * (1 + spread) + 1e-15)
    assert_inside_without_overlap(lat)
    walls = {int(j) for j in lat.j[lat.j < 0]}
    assert {models.LEFT_WALL, models.RIGHT_WALL} <= walls
    rank = np.empty(lat.p, dtype=int)
    rank[np.lexsort((regular.x[:, 0], regular.row))] = np.arange(lat.p)
    for k in range(lat.p):
        normals = [-lat.n[a] for a in np.flatnonzero(lat.i == k)
                   if lat.j[a] < 0 or rank[lat.j[a]] < rank[k]]
        normals += [lat.n[a] for a in np.flatnonzero(lat.j == k) if rank[lat.i[a]] < rank[k]]
        assert normals, k
        _, residual = nnls(np.array(normals).T, np.array([0.0, 1.0]))
        assert residual <= 1e-9, (k, residual)
    rep = report(lat)
    assert not rep.rattlers and len(rep.clusters) == 1


@pytest.mark.parametrize("lx, ly", [(2, 1), (3, 2), (5, 4), (6, 5)])
def test_spread_zero_gives_the_triangular_array(lx, ly):
    tri = models.triangular(lx, ly)
    lat = with_size_disorder(tri, 0.0, seed=3)
    assert lat.p == tri.p and lat.c == tri.c and lat.width == tri.width
    assert np.max(np.abs(lat.x - tri.x)) <= 1e-12 * tri.width


@settings(max_examples=25, deadline=None)
@given(lx=st.integers(2, 8), ly=st.integers(1, 6), spread=st.floats(0.0, 0.45),
       seed=st.integers(0, 2**31))
def test_invariants(lx, ly, spread, seed):
    tri = models.triangular(lx, ly)
    lat = with_size_disorder(tri, spread, seed=seed)
    assert lat.p == tri.p
    _check(lat, tri, spread)
    again = with_size_disorder(tri, spread, seed=seed)  # seeded
    assert np.array_equal(again.x, lat.x) and np.array_equal(again.radii, lat.radii)


def test_a_row_of_the_rectangular_array():
    rect = models.rectangular(6, 1)
    lat = with_size_disorder(rect, 0.2, seed=1)
    _check(lat, rect, 0.2)
    assert lat.c == 6 + 5 + 2  # plane, neighbours, walls: every contact kept


@pytest.mark.parametrize("lattice, spread, match", [
    (models.rectangular(3, 2), 0.1, "rectangular array with size disorder"),
    (models.triangular(3, 2), 0.5, "spread must be"),
    (models.triangular(3, 2), -0.1, "spread must be"),
    (models.triangular(3, 2), "wide", "spread must be"),
    (models.make_packing([[1.0, 1.0]], [1.0]), 0.1, "regular array"),
])
def test_refused_by_name(lattice, spread, match):
    with pytest.raises(models.InvalidSystem, match=match):
        with_size_disorder(lattice, spread, seed=0)


def test_pack_array_with_size_disorder(tmp_path, capsys):
    out = tmp_path / "tri.csv"
    assert main(["pack", "--array", "tri", "--lx", "5", "--ly", "3", "--size-disorder", "0.1",
                 "--seed", "2", "--out", str(out)]) == 0
    lat = read_packing(out)
    want = with_size_disorder(models.triangular(5, 3), 0.1, seed=2)
    assert np.allclose(lat.x, want.x, rtol=0, atol=1e-12) and lat.c == want.c
    assert "size disorder 0.1" in capsys.readouterr().out
    bad = tmp_path / "bad.csv"
    assert main(["pack", "--array", "rect", "--ly", "2", "--size-disorder", "0.1", "--out",
                 str(bad)]) == 2
    assert main(["pack", "--n", "4", "--size-disorder", "0.1", "--out", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 2 and not bad.exists()
