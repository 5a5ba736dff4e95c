"""An "infeasible" from HiGHS is re-checked without presolve (verify.ranges.milp.MilpModel):
found by the deep profile of tests/verify/ranges/test_clock.py, rect 3x2 at mu_pp =
1.192092896e-07, mu_plane 0.25, gamma 0.328125 was reported "no valid steady state" (HiGHS's
presolve said infeasible) while a valid steady state exists. The state is derived here
independently of the MILP: the contact states of the minimum of mu_g at mu_pp = 1e-3 (a nearby
system), their forces by one linear program at mu_pp = 1.192092896e-07 (`state_extreme`),
their velocities by `state_velocities`, and `steady_check`'s independent residual.
"""

from __future__ import annotations

import numpy as np

from rigidlcp import models
from rigidlcp.verify.ranges import steady_ranges
from rigidlcp.verify.ranges.milp import MilpModel
from rigidlcp.verify.ranges.observables import mu_g_vector
from rigidlcp.verify.ranges.result import OPTIMAL
from rigidlcp.verify.ranges.steady import formulate, state_extreme, state_velocities
from rigidlcp.verify.ranges.witness import steady_check

TINY = 1.192092896e-07


def _system(mpp):
    return models.System(models.rectangular(3, 2), mu_pp=mpp, mu_plane=0.25, mu_wall=0.0,
                         gamma=0.328125)


def state_near(system_at, tiny: float):
    """A steady state of system_at(tiny) found without the MILP at that mu_pp: the contact
    states of the minimum of mu_g at mu_pp = 1e-3 (a nearby system), their forces at `tiny`
    by one LP (asserted optimal), their velocities. (system, form, its mu_g, steady_check's
    independent residual), for the caller's own tolerance."""
    near = steady_ranges(system_at(1e-3), which="mu_g", time_limit=60, split=False)
    s = np.asarray(near.mu_g.lo.witness.s)
    system = system_at(tiny)
    form = formulate(system)
    L = mu_g_vector(system)
    status, x, _ = state_extreme(form, s, L, +1)
    assert status == OPTIMAL
    omega, V = state_velocities(form, s)
    res, _ = steady_check(system, omega, V, x[:system.c], x[system.c:])
    return system, form, float(L @ x), res


def _a_valid_state():
    system, form, value, res = state_near(_system, TINY)
    assert res <= 1e-8
    return system, form, value


def test_feasible_milp_not_reported_infeasible():
    system, form, value = _a_valid_state()
    for kin in ("proportional", "lazy"):
        model = MilpModel(form, kin)
        cost = np.zeros(form.A.shape[1])
        cost[:2 * system.c] = mu_g_vector(system)
        st, x = model.solve(cost, 60.0)
        assert st == OPTIMAL, kin
        assert float(cost @ x) <= value + 1e-9
    r = steady_ranges(system, which="mu_g", time_limit=60, split=False)  # no NotSteady
    assert r.mu_g.lo.status == OPTIMAL
    assert r.mu_g.lo.value <= value + 1e-9
    assert r.mu_g.lo.witness.residual <= 1e-8
