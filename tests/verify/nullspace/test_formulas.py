"""verify.nullspace.formulas:
the paper's Eqs. (3.3)/(3.4) against SVD counts, and the corrected forms."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import models
from rigidlcp.cli.main import main
from rigidlcp.lcp.errors import InvalidInput
from rigidlcp.verify import paper_singularities
from rigidlcp.verify.nullspace import formulas as vf

LATTICE = st.sampled_from(["rect", "tri"])
KIND = st.sampled_from(["normal", "tangential"])


@settings(max_examples=40, deadline=None)
@given(LATTICE, st.integers(2, 9), st.integers(1, 7), KIND,
       st.sampled_from(["rough", "frictionless"]))
def test_computed_count_equals_the_documented_closed_form(lattice, lx, ly, kind, walls):
    r = paper_singularities(lattice, lx, ly, kind, walls)
    assert r.computed == r.closed_form == vf.closed_form(lattice, lx, ly, kind, walls)
    if kind == "tangential":  # whole null space = Eq. (3.3) + the NS part
        assert r.whole == vf.closed_form(lattice, lx, ly, "normal") + r.closed_form


@settings(max_examples=25, deadline=None)
@given(LATTICE, st.integers(2, 6), st.integers(1, 5),
       st.lists(st.sampled_from([0.0, 0.05, 0.3, 0.5, 0.8, 0.9]), min_size=3, max_size=3),
       st.integers(0, 2**32 - 1))
def test_normal_count_does_not_depend_on_mu_or_sliding_signs(lattice, lx, ly, mus, seed):
    # Away from the special coefficients (mu = 1, tan 30, tan 60 degrees: see test_nullspace)
    sysm = models.System(models.make_lattice(lattice, lx, ly), *mus)
    signs = np.random.default_rng(seed).choice([-1, 1], sysm.c)
    assert vf.null_dim(sysm, "normal", signs) == vf.closed_form(lattice, lx, ly, "normal")


@pytest.mark.parametrize("lattice", ["rect", "tri"])
@pytest.mark.parametrize("lx,ly", [(2, 1), (3, 4), (5, 3), (6, 6), (7, 1)])
def test_closed_form_sizes_match_the_lattice(lattice, lx, ly):
    lat = models.make_lattice(lattice, lx, ly)
    assert vf.sizes(lattice, lx, ly) == (lat.p, lat.c)
    assert vf.full_rows(lattice, ly) == len(set(lat.row[lat.i[lat.kind == "wall"]]))


@pytest.mark.parametrize("lattice", ["rect", "tri"])
@pytest.mark.parametrize("lx,ly", [(2, 1), (2, 5), (4, 4), (7, 3), (9, 6)])
def test_frameworks_are_rigid(lattice, lx, ly):
    # The derivations' hypotheses: central forces pin every translation (rank 2p) and, with
    # every contact rough, no motion leaves all contacts at rest (H has full column rank 3p).
    sysm = models.System(models.make_lattice(lattice, lx, ly), **vf.DEFAULT_MU)
    H = models.Dynamics(sysm).H.toarray()
    assert np.linalg.matrix_rank(H[: sysm.c, : 2 * sysm.p]) == 2 * sysm.p
    assert np.linalg.matrix_rank(H) == 3 * sysm.p


def test_where_the_paper_holds_and_where_it_does_not():
    # Rectangular: both closed forms hold (rough walls for Eq. 3.4).
    for lx, ly in [(2, 1), (4, 3), (7, 5)]:
        for kind in ("normal", "tangential"):
            r = paper_singularities("rect", lx, ly, kind)
            assert r.paper_agrees, r
    # Eq. (3.4) counts the NS increment: the whole null space is Eq. 3.3 + Eq. 3.4.
    r = paper_singularities("rect", 4, 3, "tangential")
    assert (r.computed, r.whole) == (15, 18) == (4 * 3 + 3, 4 * 3 + 2 * 3)
    # With frictionless walls (the paper's runs) Eq. (3.4) overcounts by the 2 Ly wall contacts.
    assert paper_singularities("rect", 4, 3, "tangential", "frictionless").computed == 9
    # Triangular Eq. (3.3) fails except when Lx = ceil(Ly / 2): (4, 4) gives 8, not 10.
    r = paper_singularities("tri", 4, 4, "normal")
    assert (r.paper, r.computed) == (10, 8)
    assert paper_singularities("tri", 2, 4, "normal").paper_agrees
    assert paper_singularities("tri", 3, 1, "normal").computed == 1  # one row: not Lx = 3
    # Triangular Eq. (3.4) holds for even Ly, is one short for odd Ly (bottom and top full).
    assert paper_singularities("tri", 5, 4, "tangential").paper_agrees
    r = paper_singularities("tri", 5, 3, "tangential")
    assert r.computed == r.paper + 1


def test_invalid_arguments():
    with pytest.raises(InvalidInput, match="kind"):
        paper_singularities("rect", 3, 3, "both")
    with pytest.raises(InvalidInput, match="lattice"):
        vf.paper_formula("hex", 3, 3, "normal")
    with pytest.raises(InvalidInput, match="walls"):
        vf.closed_form("rect", 3, 3, "normal", walls="sticky")


def test_cli_verify_formulas_text_and_json(capsys):
    assert main(["verify-formulas", "--lx", "2", "4", "--ly", "1", "4"]) == 0
    out = capsys.readouterr().out
    assert out.split()[:3] == ["lattice", "lx", "ly"]
    assert "tri: 12 cases; paper agrees with the SVD: Eq. 3.3 2, Eq. 3.4 6" in out
    assert main(["verify-formulas", "--lattice", "tri", "--lx", "4", "4", "--ly", "4", "4",
                 "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    (row,) = data["rows"]
    assert (row["Nn_paper"], row["Nn_svd"], row["Nt_paper"], row["Nt_svd"]) == (10, 8, 22, 22)
    assert main(["verify-formulas", "--lattice", "tri", "--lx", "4", "4", "--ly", "3", "4",
                 "--grid"]) == 0
    out = capsys.readouterr().out
    assert "| 4 | 6 [8] | 8 [10] |" in out and "| 4 | 17 [16] | 22 |" in out
    assert main(["verify-formulas", "--lx", "3", "2"]) == 2


@pytest.mark.slow
def test_full_table_agrees_with_the_corrected_forms():
    # The table of docs/verification.md: lx 2..12, ly 1..8, both lattices (about 10 s).
    rows = vf.formula_table()
    s = vf.summary(rows)
    assert s["rect"] == {"cases": 88, "Nn_paper_agrees": 88, "Nt_paper_agrees": 88,
                         "Nn_closed_agrees": 88, "Nt_closed_agrees": 88,
                         "whole_is_Nn_plus_Nt": 88}
    assert s["tri"] == {"cases": 88, "Nn_paper_agrees": 6, "Nt_paper_agrees": 44,
                        "Nn_closed_agrees": 88, "Nt_closed_agrees": 88,
                        "whole_is_Nn_plus_Nt": 88}
