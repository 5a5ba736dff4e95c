"""verify.statics.centre (the analytic centre of P, the fast path of existence and dimension)
and the rank of hull.dimension, against the path they replace: HiGHS's IPM in a box, then the
per-row slack LPs (forceset.analyse with the centre switched off), and against a dense SVD.

The centre exists exactly when P has a point with every cone coordinate w_j > 0, i.e. when no
inequality of P is an implicit equality (centre's docstring): so on a packing whose existing
analysis labels no contact "R=0" or "S=+-muR" it must give a point of P at which every
inequality row has a clearly positive slack (> 1e-6 of the largest weight, the rule of
hull.implicit_equalities); where some are labelled, any point of P it gives (the centre of
a face) must have no clear slack on a row the labels say is an equality on all of P.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.verify.statics import forceset, hull
from rigidlcp.verify.statics.centre import analytic_centre
from rigidlcp.verify.statics.hull import DENSE_RANK_LIMIT, dimension, reduced_balance
from rigidlcp.verify.statics.model import StaticProblem


def _old(system: models.System) -> forceset.ForceSet:
    """analyse as before the centre: HiGHS's IPM, then the slack LPs (no certificates of
    verify.statics.implicit either)."""
    with pytest.MonkeyPatch.context() as m:
        m.setattr(forceset, "analytic_centre", lambda prob: None)
        m.setattr(hull, "proved_rows", lambda prob, undecided: np.zeros_like(undecided))
        return forceset.analyse(system, ranges=False)


def _agree(system: models.System) -> forceset.ForceSet:
    """The new path gives the old one's verdict, labels and dimension; the centre is a point
    of P deciding every row exactly when there is no implicit equality."""
    new, old = forceset.analyse(system, ranges=False), _old(system)
    assert new.exists == old.exists
    if not new.exists:
        return new
    assert new.implicit == old.implicit
    assert new.dimension == old.dimension
    prob = StaticProblem(system)
    assert prob.admissible(new.solution)
    lam = analytic_centre(prob)
    if not any(old.implicit):
        assert lam is not None and prob.admissible(lam)
    if lam is not None and prob.admissible(lam):
        slack = np.r_[lam[: prob.c], -(prob.G @ lam)]
        clear = slack > 1e-6 * prob.scale
        assert not np.any(clear & _implicit_rows(prob, old.implicit))
        assert any(old.implicit) or np.all(clear)
    return new


def _implicit_rows(prob: StaticProblem, implicit: list[str]) -> np.ndarray:
    """The inequality rows (-R <= 0 for the c contacts, then S - mu R <= 0 and -S - mu R <= 0
    for the k frictional ones) that the labels say hold with equality on all of P."""
    c, k = prob.c, prob.fric.size
    rows = np.zeros(c + 2 * k, dtype=bool)
    rows[:c] = [kind == "R=0" for kind in implicit]
    for n, a in enumerate(prob.fric):
        rows[c + n] = implicit[a] in ("R=0", "S=+muR")
        rows[c + k + n] = implicit[a] in ("R=0", "S=-muR")
    return rows


def _packing(x, left=None, right=None, **mu) -> models.System:
    lat = models.make_packing(x, np.ones(len(x)), m=np.ones(len(x)), left=left, right=right)
    return models.System(lat, **mu)


S3 = np.sqrt(3.0)


@pytest.mark.parametrize("system, implicit", [
    # tests/verify/statics/test_forceset.py's cases 1-3: R_w = 0 on all of P below mu_w = 1
    (_packing([[1.0, 1.0]], left=0.0, mu_plane=0.5, mu_wall=0.9), True),
    (_packing([[1.0, 1.0]], left=0.0, mu_plane=0.5, mu_wall=1.5), False),
    # at mu_w = 1 exactly: S_w = -R_w = -mu_w R_w on all of P, with R_w in [0, 1]
    (_packing([[1.0, 1.0]], left=0.0, mu_plane=0.5, mu_wall=1.0), True),
    (_packing([[1.0, 1.0]], left=0.0, right=2.0, mu_pp=0.5, mu_plane=0.5, mu_wall=0.5),
     False),
    (_packing([[1.0, 1.0]], left=0.0, right=2.0), False),  # mu = 0: S = 0 by bounds
    (_packing([[1, 1], [3, 1], [2, 1 + S3]], left=0.0, right=4.0), False),
    (_packing([[1, 1], [3, 1], [2, 1 + S3]]), None),  # no equilibrium
])
def test_closed_form_cases(system, implicit):
    fs = _agree(system)
    if implicit is None:
        assert fs.exists is False
    else:
        assert fs.exists and bool(any(fs.implicit)) == implicit


@pytest.mark.parametrize("kind", ["rect", "tri"])
@pytest.mark.parametrize("mu", [0.0, 0.5])
def test_symmetric_arrays(kind, mu):
    """Arrays written as packings (symmetric, many equal contacts), with and without friction."""
    lat = models.make_lattice(kind, 6, 5)
    pk = models.make_packing(lat.x, lat.radii, left=lat.left, right=lat.right)
    _agree(models.System(pk, mu_pp=mu, mu_plane=mu, mu_wall=mu))


@settings(max_examples=10)
@given(n=st.integers(2, 120), seed=st.integers(0, 10**5),
       mu=st.sampled_from([0.0, 0.1, 0.3, 0.5, 0.988, 1.0, 1.5, 2.0]),
       spread=st.floats(1.0, 1.6), across=st.sampled_from([1, 2, 3, 6]))
def test_new_path_agrees_on_deposited_packings(n, seed, mu, spread, across):
    """Deposited piles (narrow boxes wedge disks between the walls; mu = 0, mu near and
    above 1 and mu_wall = 1 give implicit equalities and unbounded P); the box is `across`
    largest diameters wide."""
    lat = deposit(n, seed=seed, radii=(1.0, spread), width=2.0 * spread * across)
    _agree(models.System(lat, mu_pp=mu, mu_plane=mu, mu_wall=0.5 * mu))


def test_piles_of_30_to_300_disks():
    for n, seed in ((30, 2), (100, 4), (300, 4)):
        lat = deposit(n, seed=seed, radii=(0.8, 1.2))
        _agree(models.System(lat, mu_pp=0.5, mu_plane=0.5, mu_wall=0.5))


def _reference_balance(prob: StaticProblem, implicit: list[str]) -> np.ndarray:
    """reduced_balance's definition, one contact at a time."""
    A, c, cols = prob.A.toarray(), prob.c, []
    for a, kind in enumerate(implicit):
        if kind == "R=0":
            continue
        if prob.mu[a] == 0:
            cols.append(A[:, a])
        elif kind:
            cols.append(A[:, a] + (prob.mu[a] if kind == "S=+muR" else -prob.mu[a]) * A[:, c + a])
        else:
            cols += [A[:, a], A[:, c + a]]
    return np.column_stack(cols) if cols else np.zeros((A.shape[0], 0))


@settings(max_examples=10)
@given(n=st.integers(2, 40), seed=st.integers(0, 10**5),
       mu=st.sampled_from([0.0, 0.3, 1.0]), data=st.data())
def test_reduced_balance_and_rank_against_dense(n, seed, mu, data):
    """The vectorized reduced_balance equals its per-contact definition, and dimension's rank
    (the sparse full-row-rank test, else the SVD) equals numpy's matrix_rank, for arbitrary
    labels."""
    lat = deposit(n, seed=seed, radii=(0.8, 1.2))
    prob = StaticProblem(models.System(lat, mu_pp=mu, mu_plane=0.5, mu_wall=mu))
    implicit = data.draw(st.lists(st.sampled_from(["", "", "", "R=0", "S=+muR", "S=-muR"]),
                                  min_size=prob.c, max_size=prob.c))
    B = reduced_balance(prob, implicit)
    D = _reference_balance(prob, implicit)
    assert np.array_equal(B.toarray(), D)
    dim, _ = dimension(prob, implicit)
    assert dim == D.shape[1] - (np.linalg.matrix_rank(D) if D.size else 0)


@pytest.mark.parametrize("kind", ["rect", "tri"])
def test_full_row_rank_of_arrays_against_dense(kind):
    """The sparse test's full row rank (Gershgorin's bound for sigma_max) on arrays, where
    B B^T is nonsingular: the dimension is the SVD's."""
    lat = models.make_lattice(kind, 12, 10)
    pk = models.make_packing(lat.x, lat.radii, left=lat.left, right=lat.right)
    prob = StaticProblem(models.System(pk, mu_pp=0.5, mu_plane=0.5, mu_wall=0.5))
    B = reduced_balance(prob, [""] * prob.c)
    assert B.shape[1] <= DENSE_RANK_LIMIT
    dim, (kept, dropped) = dimension(prob, [""] * prob.c)
    assert dropped is None and kept > 0  # settled by the sparse test
    assert dim == B.shape[1] - np.linalg.matrix_rank(B.toarray())
    assert isinstance(B, sp.csc_matrix)
