"""Lattices and systems: geometry, contact counts, bad input."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import models
from rigidlcp.models.lattice import LEFT_WALL, PLANE, RIGHT_WALL, InvalidSystem


def contact_count(kind: str, lx: int, ly: int) -> int:
    """Counted by hand: rows (lateral + walls), stacks between rows, the plane."""
    if kind == "rect":
        return ly * (lx + 1) + lx * ly  # each row: lx - 1 lateral + 2 walls; lx vertical / row
    full = (ly + 1) // 2
    short = ly // 2
    return lx + full * (lx + 1) + short * (lx - 2) + (ly - 1) * 2 * (lx - 1)


@settings(max_examples=40, deadline=None)
@given(kind=st.sampled_from(["rect", "tri"]), lx=st.integers(2, 12), ly=st.integers(1, 8))
def test_every_contact_touches(kind, lx, ly):
    lat = models.make_lattice(kind, lx, ly)
    r = lat.radius
    assert lat.c == contact_count(kind, lx, ly)
    n_disks = lx * ly if kind == "rect" else ((ly + 1) // 2) * lx + (ly // 2) * (lx - 1)
    assert lat.p == n_disks
    for a in range(lat.c):
        i, j, n = lat.i[a], lat.j[a], lat.n[a]
        assert np.isclose(np.hypot(*n), 1.0)
        assert np.allclose(lat.t[a], [-n[1], n[0]])  # t = n rotated by +90 degrees
        if j >= 0:
            assert np.allclose(lat.x[j] - lat.x[i], 2 * r * n)
        elif j == PLANE:
            assert np.isclose(lat.x[i, 1], r) and np.allclose(n, [0, -1])
        elif j == LEFT_WALL:
            assert np.isclose(lat.x[i, 0], r) and np.allclose(n, [-1, 0])
        elif j == RIGHT_WALL:
            assert np.isclose(lat.x[i, 0], lat.width - r) and np.allclose(n, [1, 0])
    # no two disks overlap, and every pair at distance 2r is a listed contact
    d = np.linalg.norm(lat.x[:, None] - lat.x[None], axis=-1)
    assert np.all(d[np.triu_indices(lat.p, 1)] >= 2 * r - 1e-9)
    touching = {(a, b) for a, b in zip(*np.nonzero(np.isclose(d, 2 * r))) if a < b}
    listed = {tuple(sorted((int(i), int(j)))) for i, j in zip(lat.i, lat.j) if j >= 0}
    assert touching == listed


def test_triangular_rows_alternate():
    lat = models.triangular(5, 4)
    counts = [int(np.sum(lat.row == m)) for m in range(4)]
    assert counts == [5, 4, 5, 4]
    walls = lat.j[lat.kind == "wall"]
    assert set(lat.row[lat.i[lat.kind == "wall"]]) == {0, 2} and walls.size == 4


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: models.rectangular(0, 3), "lx must be >= 1"),
        (lambda: models.rectangular(3, 0), "ly must be >= 1"),
        (lambda: models.rectangular(2.5, 3), "lx must be an integer"),
        (lambda: models.triangular(1, 2), "needs lx >= 2"),
        (lambda: models.rectangular(3, 3, radius=-1), "radius"),
        (lambda: models.make_lattice("hex", 3, 3), "lattice must be"),
        (lambda: models.System(models.rectangular(2, 2), mu_pp=-0.1), "mu_pp"),
        (lambda: models.System(models.rectangular(2, 2), mu_plane=float("nan")), "mu_plane"),
        (lambda: models.System(models.rectangular(2, 2), mu_wall=float("inf")), "mu_wall"),
        (lambda: models.System(models.rectangular(2, 2), gamma=float("nan")), "gamma"),
        (lambda: models.System(models.rectangular(2, 2), V0="fast"), "V0"),
        (lambda: models.System(models.rectangular(2, 2), inertia=0), "inertia"),
        (lambda: models.System(models.rectangular(2, 2), mass=-1), "mass"),
        (lambda: models.System("rect"), "lattice must be"),
    ],
)
def test_bad_input_names_the_problem(call, match):
    with pytest.raises(InvalidSystem, match=match):
        call()


def test_bad_initial_state():
    system = models.System(models.rectangular(2, 2))
    with pytest.raises(ValueError, match="one angular velocity per disk"):
        models.initial_state(system, omega=[1.0, 2.0])
    with pytest.raises(ValueError, match="NaN"):
        models.initial_state(system, omega=[1.0, np.nan, 0, 0])


def test_per_contact_coefficients():
    system = models.System(models.triangular(4, 3), mu_pp=0.1, mu_plane=0.2, mu_wall=0.3)
    lat = system.lattice
    for kind, mu in (("pp", 0.1), ("plane", 0.2), ("wall", 0.3)):
        assert np.all(system.mu[lat.kind == kind] == mu)
