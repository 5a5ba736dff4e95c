"""verify.nullspace.contact:
SVD rank against exact rank, Eq. (3.2), localized bases, Fig. 5 structures."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import models
from rigidlcp.cli.main import main
from rigidlcp.lcp.errors import InvalidFile
from rigidlcp.verify.nullspace import contact as vn
from rigidlcp.verify.nullspace import qsqrt3 as q3

MU = {"mu_pp": 0.3, "mu_plane": 0.4, "mu_wall": 0.2}
SMALL = [("rect", 2, 1), ("rect", 3, 2), ("rect", 3, 3), ("rect", 4, 2),
         ("tri", 2, 2), ("tri", 3, 2), ("tri", 3, 3), ("tri", 4, 2)]


def system(lattice: str, lx: int, ly: int, **mu) -> models.System:
    return models.System(models.make_lattice(lattice, lx, ly), **{**MU, **mu})


def random_states(sysm: models.System, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    normal = rng.random(sysm.c) < 0.8
    tangential = rng.choice([-1, 0, 0, 1], sysm.c)
    return normal, tangential


def contacts_of_support(support: set[int], c: int) -> set[int]:
    return {k % c for k in support}


# -- rank: SVD against exact arithmetic --------------------------------------------------------


@pytest.mark.parametrize("lattice,lx,ly", SMALL)
@pytest.mark.parametrize("states", ["normal", "tangential", "random0", "random1"])
def test_svd_dimension_and_support_equal_exact(lattice, lx, ly, states):
    sysm = system(lattice, lx, ly)
    if states.startswith("random"):
        normal, tangential = random_states(sysm, int(states[-1]) + 10 * lx + ly)
    else:
        normal, tangential = vn.paper_states(sysm, states)
    ns = vn.null_space(sysm, normal, tangential)
    rows = q3.exact_contact_matrix(sysm, normal, tangential)
    dim, support = q3.exact_null_support(rows, 2 * sysm.c)
    assert ns.dim == dim
    assert set(ns.contributing.tolist()) == contacts_of_support(support, sysm.c)
    kept, dropped = ns.gap
    if ns.dim and ns.rank:  # the tolerance sits in a wide gap
        assert kept > 1e10 * dropped and kept > 1e3 * ns.tol > 1e3 * dropped
        assert ns.basis_error < 1e-2 * vn.SUPPORT_TOL  # the support test is robust


@pytest.mark.parametrize("lattice,lx,ly", [("rect", 3, 2), ("tri", 3, 3)])
def test_exact_matrix_is_the_models_matrix(lattice, lx, ly):
    # The exact assembly (snapped H, exact W) reproduces models.contact_matrix to rounding.
    sysm = system(lattice, lx, ly)
    for seed in range(3):
        normal, tangential = random_states(sysm, seed)
        M, _ = models.contact_matrix(sysm, normal, tangential)
        ex = q3.to_float(q3.exact_contact_matrix(sysm, normal, tangential), 2 * sysm.c)
        np.testing.assert_allclose(ex, M, rtol=0, atol=1e-13 * np.abs(M).max())


def test_snap_recognizes_lattice_numbers_and_refuses_others():
    assert q3.snap(np.sqrt(3) / 2) == q3.QS3(q3.Fraction(0), q3.Fraction(1, 2))
    assert q3.snap(-0.5) == q3.QS3(q3.Fraction(-1, 2))
    one_plus_sqrt3 = q3.QS3(q3.Fraction(1), q3.Fraction(1))
    assert one_plus_sqrt3.inverse() * one_plus_sqrt3 == q3.ONE
    with pytest.raises(ValueError):
        q3.snap(np.pi)


def test_wedged_corner_at_mu_one_is_an_exact_extra_singularity():
    # mu = 1: a sliding force makes 45 degrees with its normal, so on a disk the plane and the
    # row contact can push along one line (docs/verification.md); exact rank confirms it.
    sysm = system("rect", 3, 1, mu_pp=1.0, mu_plane=1.0, mu_wall=1.0)
    normal = np.ones(sysm.c, bool)
    signs = np.array([-1, -1, -1, 1, 1, 1, 1])
    assert q3.exact_null_dim(sysm, normal, signs) == 4
    assert vn.null_space(sysm, normal, signs).dim == 4
    assert vn.null_space(sysm, normal, np.ones(sysm.c, int)).dim == 1  # generic signs: c - 2p
    assert sysm.c - 2 * sysm.p == 1


# -- Eq. (3.2) and the localized basis ----------------------------------------------------------


def assert_localized_basis(ns: vn.NullSpace) -> None:
    X = ns.localized
    assert X.shape == (2 * ns.c, ns.dim)
    assert np.abs(ns.M @ X).max() < 1e-10 * max(1.0, ns.singular_values[0])
    assert np.linalg.matrix_rank(X, tol=1e-8) == ns.dim
    for x in X.T:  # each vector is a circuit: its support carries one null direction
        supp = np.flatnonzero(x)
        w, _, _, rank = vn.svd_rank(ns.M[:, supp], ns.tol)
        assert supp.size - rank == 1


def row_contacts(lat: models.Lattice, row: int) -> set[int]:
    lateral = (lat.kind == "wall") | ((lat.j >= 0) & (lat.n[:, 1] == 0))
    return set(np.flatnonzero(lateral & (lat.row[lat.i] == row)).tolist())


def test_rectangular_normal_basis_is_the_rows_between_the_walls():
    # Fig. 5(d): one singularity per row, the Lx + 1 lateral contacts of the row. With one mu
    # and one sliding sign along a row, the friction forces of the row cancel on every disk;
    # with mu_wall != mu_pp the row's vector also involves the contacts that carry the
    # difference (still one vector per row, the count is the same).
    sysm = system("rect", 4, 3, mu_wall=MU["mu_pp"])
    ns = vn.null_space(sysm, *vn.paper_states(sysm, "normal"), localize=True)
    assert_localized_basis(ns)
    lat = sysm.lattice
    got = sorted(sorted(ns.contacts_of(x).tolist()) for x in ns.localized.T)
    assert got == sorted(sorted(row_contacts(lat, m)) for m in range(lat.ly))
    assert set(ns.contributing.tolist()) == set().union(*(row_contacts(lat, m) for m in range(3)))


def test_triangular_normal_basis_shows_hexagons_and_rows():
    # Fig. 5(a): 12 contacts = a disk's six spokes and the six rim contacts of its neighbours.
    sysm = system("tri", 5, 4, mu_wall=MU["mu_pp"])  # one mu along a row: see above
    ns = vn.null_space(sysm, *vn.paper_states(sysm, "normal"), localize=True)
    assert_localized_basis(ns)
    lat = sysm.lattice
    supports = [set(ns.contacts_of(x).tolist()) for x in ns.localized.T]
    wheels = []
    for k in range(lat.p):
        spokes = set(np.flatnonzero((lat.i == k) | (lat.j == k)).tolist())
        nb = {int(lat.j[a]) if lat.i[a] == k else int(lat.i[a]) for a in spokes}
        if len(spokes) == 6 and min(nb) >= 0:
            rim = {a for a in range(lat.c) if lat.i[a] in nb and lat.j[a] in nb}
            wheels.append(spokes | rim)
    assert len(wheels) == 5 and all(len(w) == 12 for w in wheels)
    hexagons = [s for s in supports if s in wheels]
    assert len(hexagons) >= 4  # (the fifth is a combination of the others and the boundary's)
    assert row_contacts(lat, 0) in supports and row_contacts(lat, 2) in supports  # full rows


def square_loops(lat: models.Lattice) -> list[set[int]]:
    """The four contacts around each 2 x 2 block of disks of a rectangular array."""
    where = {(int(lat.row[k]), int(lat.col[k])): k for k in range(lat.p)}

    def contact(a: int, b: int) -> int:
        return int(np.flatnonzero((lat.i == a) & (lat.j == b))[0])

    out = []
    for m in range(lat.ly - 1):
        for k in range(lat.lx - 1):
            d00, d01 = where[m, k], where[m, k + 1]
            d10, d11 = where[m + 1, k], where[m + 1, k + 1]
            out.append({contact(d00, d01), contact(d10, d11), contact(d00, d10),
                        contact(d01, d11)})
    return out


def test_fig5b_loops_of_four_contacts_in_a_3x3_rectangular_array():
    # The paper's Fig. 5(b): "if three of the contacts [of a loop of four disks] are NS, then
    # the fourth contact is necessarily NS". In the no-displacement regime the NS equation of a
    # contact is omega_i + omega_j = 0: the loops are dependencies among the NS equations.
    # With the particle-particle contacts NS (the bulk), the localized basis of those
    # dependencies is exactly the (Lx - 1)(Ly - 1) = 4 loops, four contacts each, +1 -1 +1 -1.
    sysm = system("rect", 3, 3, mu_plane=0.0, mu_wall=0.0)
    lat = sysm.lattice
    ns_mask = vn.paper_states(sysm, "tangential")[1] == 0
    assert set(np.flatnonzero(ns_mask).tolist()) == set(np.flatnonzero(lat.kind == "pp").tolist())
    loops = vn.rotation_loops(lat, ns_mask)
    assert loops.dim == vn.closed_form_loops(lat, ns_mask) == 4
    got = [set(loop) for loop in loops.loops()]
    assert all(len(s) == 4 for s in got)
    assert sorted(map(sorted, got)) == sorted(map(sorted, square_loops(lat)))
    for loop in loops.loops():
        np.testing.assert_allclose(sorted(loop.values()), [-1, -1, 1, 1], atol=1e-12)
    # The same count appears in ker M (Eq. 2.15): dim ker M(NS) - dim ker M(sliding) = 4 ...
    states = vn.paper_states(sysm, "tangential")
    normal_dim = vn.null_space(sysm, *vn.paper_states(sysm, "normal")).dim
    assert vn.null_space(sysm, *states).dim - normal_dim == 4
    # ... but a loop is not a null vector of M: with translations in M, the eight force
    # components of a loop's four contacts cannot balance its four disks (exact rank 8).
    rows = q3.exact_contact_matrix(sysm, *states)
    for loop in square_loops(lat):
        cols = sorted(loop) + [a + lat.c for a in sorted(loop)]
        sub = [{cols.index(k): v for k, v in r.items() if k in cols} for r in rows]
        assert q3.exact_rank(sub) == 8


def test_fig5e_loops_through_the_plane():
    # Fig. 5(e)/Fig. 6: a row on the plane, alternate disks rolling (NS on the plane), the
    # others sliding on it, frictionless walls: loops plane - disk - disk - disk - plane.
    sysm = system("rect", 7, 1, mu_wall=0.0)
    lat = sysm.lattice
    tangential = vn.paper_states(sysm, "tangential")[1]
    plane = np.flatnonzero(lat.kind == "plane")
    tangential[plane[1::2]] = 1
    loops = vn.rotation_loops(lat, tangential == 0)
    assert loops.dim == 3
    for k, loop in enumerate(loops.loops()):
        d = 2 * k
        pp = [int(np.flatnonzero((lat.i == d + m) & (lat.j == d + m + 1))[0]) for m in (0, 1)]
        assert set(loop) == {int(plane[d]), int(plane[d + 2]), *pp}
    normal_dim = vn.null_space(sysm, *vn.paper_states(sysm, "normal")).dim
    assert vn.null_space(sysm, np.ones(lat.c, bool), tangential).dim - normal_dim == 3


def test_rectangular_3x3_tangential_basis_all_ns():
    # Eq. (3.4)'s state (every contact NS, rough walls): 15 = 3 + 12 null vectors; the
    # sparsest are the two corner wedges (disk - wall - plane, 2 contacts) and the three rows.
    sysm = system("rect", 3, 3)
    ns = vn.null_space(sysm, *vn.paper_states(sysm, "tangential"), localize=True)
    assert ns.dim == 15
    assert_localized_basis(ns)
    sizes = [len(ns.contacts_of(x)) for x in ns.localized.T]
    assert sizes[:2] == [2, 2] and min(sizes[2:]) == 4
    supports = [set(ns.contacts_of(x).tolist()) for x in ns.localized.T]
    lat = sysm.lattice
    assert all(row_contacts(lat, m) in supports for m in range(3))
    loops = vn.rotation_loops(lat, np.ones(lat.c, bool))
    assert loops.dim == lat.c - lat.p == 12
    # corners (disk between plane and wall, 2 contacts), ground-disk-disk-ground (3), and
    # loops of four (the squares of Fig. 5b, or equally short paths between obstacles)
    assert sorted(len(loop) for loop in loops.loops()) == [2, 2] + [3] * 6 + [4] * 4


@settings(max_examples=40, deadline=None)
@given(st.sampled_from(["rect", "tri"]), st.integers(2, 5), st.integers(1, 4),
       st.integers(0, 2**32 - 1))
def test_ns_contacts_add_the_loops_of_the_contact_graph(lattice, lx, ly, seed):
    # For any set A of NS contacts (the others sliding), all contacts T:
    # dim ker M(A) - dim ker M(no NS) = |A| - rank K(A)  (docs/verification.md).
    sysm = system(lattice, lx, ly)
    rng = np.random.default_rng(seed)
    A = rng.random(sysm.c) < rng.random()
    signs = rng.choice([-1, 1], sysm.c)
    tangential = np.where(A, 0, signs)
    normal = np.ones(sysm.c, bool)
    base = vn.null_space(sysm, normal, signs).dim
    extra = vn.null_space(sysm, normal, tangential).dim - base
    assert extra == vn.closed_form_loops(sysm.lattice, A)
    K = vn.rotation_matrix(sysm.lattice, A)
    assert extra == A.sum() - (np.linalg.matrix_rank(K) if A.any() else 0)


# -- states files and the command line ----------------------------------------------------------


def test_read_states_json_npz_and_errors(tmp_path):
    lat = models.rectangular(3, 2)
    normal = [True] * lat.c
    tang = ["NS"] * lat.c
    tang[0] = "+"
    path = tmp_path / "s.json"
    path.write_text(json.dumps({"lattice": "rect", "lx": 3, "ly": 2, "normal": normal,
                                "tangential": tang}))
    n, t = vn.read_states(str(path), lat)
    assert n.all() and t[0] == 1 and not t[1:].any()
    np.savez(tmp_path / "s.npz", normal=np.array(normal), tangential=t)
    n2, t2 = vn.read_states(str(tmp_path / "s.npz"), lat)
    assert (n2 == n).all() and (t2 == t).all()
    with pytest.raises(InvalidFile, match="lx"):
        vn.read_states(str(path), models.rectangular(4, 2))
    path.write_text(json.dumps({"normal": normal[:-1], "tangential": tang}))
    with pytest.raises(InvalidFile, match="entries"):
        vn.read_states(str(path), lat)
    path.write_text(json.dumps({"normal": normal, "tangential": ["NS"] * (lat.c - 1) + ["x"]}))
    with pytest.raises(InvalidFile, match="invalid"):
        vn.read_states(str(path), lat)


def test_cli_nullspace_text_json_plot_and_file(tmp_path, capsys):
    png = tmp_path / "ns.png"
    assert main(["nullspace", "--lattice", "rect", "--lx", "4", "--ly", "3", "--states",
                 "normal", "--mu-wall", "0.3", "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "dim ker M = 3" in out and "contributing contacts (Eq. 3.2): 15 of 27" in out
    assert png.exists() and png.stat().st_size > 1000
    assert main(["nullspace", "--lx", "3", "--ly", "2", "--states", "tangential", "--json",
                 "--loops"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["dim"] == 10 and len(data["localized"]) == 10 and len(data["loops"]) == 8
    states = tmp_path / "states.json"  # the JSON output is a valid states file
    states.write_text(json.dumps(data))
    assert main(["nullspace", "--lx", "3", "--ly", "2", "--states", str(states), "--json",
                 "--no-localize"]) == 0
    assert json.loads(capsys.readouterr().out)["dim"] == 10
    assert main(["nullspace", "--lx", "4", "--ly", "2", "--states", str(states)]) == 2
    assert "lx" in capsys.readouterr().err
