"""The CSV of `write_packing` / `rigidlcp pack --out FILE.csv` read by other people's tools
(issue 22's fixed interface: "a CSV whose header names at least x, y, r"): its first line is
the header, so Python's csv.DictReader, numpy.genfromtxt(names=True) and pandas.read_csv (when
installed) read x, y, r as written; the walls travel in the columns box_left, box_right and
come back on reading; files of the old format (a first line `# box: left=.. right=..`) still
read."""

from __future__ import annotations

import csv
import importlib.util

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.models.packing_io import read_disks, read_packing, write_packing


def _written(tmp_path, lat, name="pile.csv"):
    return write_packing(tmp_path / name, lat)


def test_the_first_line_is_the_header(tmp_path):
    path = _written(tmp_path, deposit(5, seed=1, radii=(0.8, 1.2)))
    first = path.read_text().splitlines()[0]
    assert first == "x,y,r,m,I,box_left,box_right"


@pytest.mark.parametrize("walls", [(None, None), ("none", 1e3)])
def test_standard_readers_read_x_y_r(tmp_path, walls):
    """csv.DictReader and numpy.genfromtxt give the written x, y, r exactly (repr of each
    double); pandas too when installed; the box columns hold the walls (a wall "none" is
    NaN to numpy)."""
    lat = deposit(30, seed=2, radii=(0.7, 1.3))
    if walls[0] == "none":
        lat = read_packing(_written(tmp_path, lat, "src.csv"), left="none", right=walls[1])
    path = _written(tmp_path, lat)
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == lat.p
    for k, row in enumerate(rows):
        assert (float(row["x"]), float(row["y"]), float(row["r"])) == (
            lat.x[k, 0], lat.x[k, 1], lat.radii[k])
        assert row["box_left"] == ("none" if lat.left is None else repr(lat.left))
    data = np.genfromtxt(path, names=True, delimiter=",")
    assert np.array_equal(data["x"], lat.x[:, 0]) and np.array_equal(data["y"], lat.x[:, 1])
    assert np.array_equal(data["r"], lat.radii)
    left = np.nan if lat.left is None else lat.left
    assert np.array_equal(data["box_left"], np.full(lat.p, left), equal_nan=True)
    if importlib.util.find_spec("pandas") is not None:
        import pandas

        frame = pandas.read_csv(path)
        assert np.array_equal(frame["x"].to_numpy(), lat.x[:, 0])
        assert np.array_equal(frame["r"].to_numpy(), lat.radii)


@settings(max_examples=10, deadline=None)
@given(n=st.integers(1, 25), seed=st.integers(0, 10**6),
       left=st.sampled_from([None, "none", -0.5]), right=st.sampled_from([None, "none", 1e3]))
def test_round_trip_keeps_the_box(tmp_path_factory, n, seed, left, right):
    """Any deposited pile, any walls (its own, none, or moved out): written and read back,
    the same disks and the same walls, exactly."""
    tmp = tmp_path_factory.mktemp("rt")
    lat = read_packing(write_packing(tmp / "a.csv", deposit(n, seed=seed, radii=(0.8, 1.2))),
                       left=left, right=right)
    back = read_packing(write_packing(tmp / "b.csv", lat))
    assert (back.left, back.right) == (lat.left, lat.right)
    for name in ("x", "radii", "masses", "inertias", "i", "j"):
        assert np.array_equal(getattr(back, name), getattr(lat, name)), name


def test_old_format_with_a_box_comment_still_reads(tmp_path):
    """A file as `rigidlcp pack` wrote it before: `# box:` first, then the header."""
    f = tmp_path / "old.csv"
    f.write_text("# box: left=0.0 right=none\nx,y,r,m,I\n1.0,1.0,1.0,1.0,0.5\n"
                 "3.0,1.0,1.0,1.0,0.5\n")
    d = read_disks(f)
    assert (d.left, d.right) == (0.0, "none")
    lat = read_packing(f)
    assert lat.left == 0.0 and lat.right is None and lat.p == 2
    assert np.array_equal(lat.x, [[1.0, 1.0], [3.0, 1.0]])


def test_the_box_columns_give_the_walls_of_a_hand_made_file(tmp_path):
    """Box columns in any position; the walls are not the tight box."""
    f = tmp_path / "hand.csv"
    f.write_text("box_right,r,x,y,box_left\n5,1,1,1,-1\n5,1,3,1,-1\n")
    lat = read_packing(f)
    assert (lat.left, lat.right) == (-1.0, 5.0)
    assert read_disks(f).box() == (-1.0, 5.0)
    lat2 = models.make_packing(lat.x, lat.radii, left=lat.left, right=lat.right)
    assert lat2.c == lat.c
