"""verify.ranges.split (a certified lower bound by a case split on contact states, plane
contacts first) against the big-M MILP's proved ends on small systems:

* with the target at the proved end, every case closes and the bound equals the end (to the
  rounding margin): never above it;
* with the target above the end, the case holding the optimum never closes, and the bound
  stays at or below the end (a bound, whatever the time limit);
* the root case's bound (no state fixed) is below every end.
"""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.verify.ranges import steady_ranges
from rigidlcp.verify.ranges.milp import MilpModel
from rigidlcp.verify.ranges.observables import mu_g_vector
from rigidlcp.verify.ranges.split import case_bound, split_bound
from rigidlcp.verify.ranges.steady import formulate

SYSTEMS = [(models.rectangular(3, 2), 0.16), (models.triangular(3, 2), 0.16),
           (models.rectangular(2, 1), -0.1)]


def _ends(lattice, gamma):
    system = models.System(lattice, mu_pp=0.1, mu_plane=0.2, mu_wall=0.0, gamma=gamma)
    r = steady_ranges(system, which="mu_g", time_limit=60, kinematics="big-M").mu_g
    assert r.lo.status == r.hi.status == "optimal"
    form = formulate(system)
    model = MilpModel(form)
    L = np.zeros(model.n)
    L[:2 * system.c] = mu_g_vector(system)
    return model, L, float(r.lo.value), float(r.hi.value)


@pytest.mark.parametrize("lattice, gamma", SYSTEMS)
def test_split_bound_closes_at_the_big_M_end(lattice, gamma):
    model, L, lo, hi = _ends(lattice, gamma)
    for cost, end in ((L, lo), (-L, -hi)):
        res = split_bound(model, cost, end, time_limit=60)
        assert res.closed, res
        assert res.bound <= end + 1e-12
        assert res.bound >= end - 1e-8 * max(1.0, abs(end))
        assert case_bound(model, cost, {})[0] <= end + 1e-12


@pytest.mark.parametrize("lattice, gamma", SYSTEMS)
def test_split_bound_never_passes_the_end(lattice, gamma):
    model, L, lo, hi = _ends(lattice, gamma)
    for cost, end in ((L, lo), (-L, -hi)):
        res = split_bound(model, cost, end + 0.05, time_limit=5)
        assert not res.closed
        assert res.bound <= end + 1e-12
