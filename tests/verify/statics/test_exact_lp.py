"""verify.statics.exact_lp: the range and sliding LPs of small piles solved in rationals, each
answer with its certificate checked exactly (the last retry of verify.statics.ends).

Hand case: a disk in the corner of the left wall and the plane (test_forceset.py's closed
form): below mu_w = 1 the wall carries nothing (roll the disk away from the wall: gravity does
no work, the wall contact opens with g_n = |g_t|), so R of the plane is the weight m g and
S = 0 at both contacts, exactly.
"""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.verify.statics import exact_lp
from rigidlcp.verify.statics.forceset import analyse
from rigidlcp.verify.statics.model import StaticProblem


def _contact(lat, i: int, j: int) -> int:
    return next(a for a in range(lat.c) if {int(lat.i[a]), int(lat.j[a])} == {i, j})


@pytest.mark.parametrize("n, seed, mu", [(3, 1, 1.001953125), (2, 1, 0.99999)])
def test_deep_profile_unknowns_are_decided_exactly(n, seed, mu):
    """The deep profile's two "unknown" answers (docs/packings.md): equal disks in a row
    between walls. n 3, mu 1.001953125: max S of contact 3 and min S of contact 4 are infinite
    by exact rays; n 2, mu 0.99999: contact 0 cannot slide (its faces are empty, by exact
    Farkas certificates). Nothing is left unknown."""
    lat = deposit(n, seed=seed, radii=(1.0, 1.0), width=6.0)
    system = models.System(lat, mu_pp=mu, mu_plane=mu, mu_wall=mu)
    fs = analyse(system)
    assert fs.exists and fs.unchecked == 0 and not fs.unknown
    prob = StaticProblem(system)
    if n == 3:
        c = prob.c
        assert fs.hi[c + 3] == np.inf and fs.lo[c + 4] == -np.inf
        for k, s in ((c + 3, -1.0), (c + 4, 1.0)):
            e = np.zeros(prob.n)
            e[k] = s
            got = exact_lp.solve(prob, e)
            assert got is not None and got.status == "unbounded"
    else:
        assert not fs.sliding[0] and not fs.sliding_unknown[0]


@pytest.mark.parametrize("mu_wall", [0.5, 0.9])
def test_exact_lp_on_the_corner_disk(mu_wall):
    """A disk in the corner of the left wall and the plane (tests/verify/statics/
    test_forceset.py's closed form): below mu_w = 1 the wall carries nothing, so R of the
    plane is the weight m g exactly and S = 0 at both contacts; the exact LP's optima and
    certificates give exactly that."""
    lat = models.make_packing(np.array([[1.0, 1.0]]), np.ones(1), m=np.ones(1), left=0.0)
    system = models.System(lat, mu_plane=0.5, mu_wall=mu_wall)
    prob = StaticProblem(system)
    weight = float(system.masses[0]) * system.g
    plane = _contact(lat, 0, -3)
    for k, want in ((plane, weight), (1 - plane, 0.0)):
        for s in (1.0, -1.0):
            e = np.zeros(prob.n)
            e[k] = s
            got = exact_lp.solve(prob, e)
            assert got is not None and got.status == "optimal"
            assert float(got.value) == s * want


def test_exact_optima_agree_with_linprog_on_a_pile_of_20():
    """On a generic 20-disk pile (60 balance rows, the largest solved exactly), where linprog
    finds optima far inside its tolerances, the exact optima are linprog's to 1e-9, and each
    exact point (rounded once per entry) lies in P."""
    from scipy.optimize import linprog

    lat = deposit(20, seed=5, radii=(0.8, 1.2))
    prob = StaticProblem(models.System(lat, mu_pp=0.5, mu_plane=0.5, mu_wall=0.5))
    assert prob.A.shape[0] <= exact_lp.MAX_ROWS
    bounds = [(None if not np.isfinite(lo) else lo, None if not np.isfinite(hi) else hi)
              for lo, hi in zip(prob.lb, prob.ub)]
    for k in (0, prob.c + 3):
        e = np.zeros(prob.n)
        e[k] = -1.0
        got = exact_lp.solve(prob, e)
        ref = linprog(e, A_ub=prob.G, b_ub=np.zeros(prob.G.shape[0]), A_eq=prob.A,
                      b_eq=prob.b, bounds=bounds, method="highs")
        assert ref.status == 0 and got is not None and got.status == "optimal"
        assert abs(float(got.value) - ref.fun) <= 1e-9 * max(1.0, abs(ref.fun))
        assert prob.admissible(got.lam) and abs(got.lam[k] + float(got.value)) <= 1e-12 * abs(
            float(got.value))
