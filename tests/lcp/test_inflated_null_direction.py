"""A point inflated along a null direction of M cannot pass the acceptance (issue 23 point 2).

The bench's integer-built infeasible n4-0 has M d = 0 exactly for d = (0, 1, 2, 0) >= 0, so
z = t d + z0 has w = M z0 + q for every t (w_2 = -7 at z0 = 0: no solution; the LCP has an
exact Farkas certificate). Its componentwise backward error falls like 1/t (the rows' terms
|M| |z| grow), and the pattern {1, 2}'s system K_PP = [[8, -4], [-4, 2]] is singular and
inconsistent (8 y1 - 4 y2 = 7 and -4 y1 + 2 y2 = -2), which the consistency test judged at
the inflated y, where the residual 3 looks like rounding of 1e14-sized terms: verify.certify
accepted z = 1e13 d (forward bound 3.7e-14; a peer, Drake's Moby, returned such a point as a
solution). The test is now made at the least-norm point as well, so ferr = inf."""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import lcp
from rigidlcp.bench.problem_sets import get_set
from rigidlcp.lcp import api
from rigidlcp.verify import certify

D = np.array([0.0, 1.0, 2.0, 0.0])


def n4_0() -> lcp.LCP:
    p = get_set("infeasible", sizes=(4,), per_size=1)[0]
    assert not np.any(p.M @ D) and (p.M @ D == 0).all()  # exactly, in the stored doubles
    return p


@pytest.mark.parametrize("t", [1e6, 1e10, 1e13, 1e14, 1e15])
@pytest.mark.parametrize("z0", [(0.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.5), (1.0, 0, 0, 1.0)])
def test_certify_rejects_a_point_inflated_along_a_null_direction(t, z0):
    p = n4_0()
    z = t * D + np.array(z0)
    sol = lcp.Solution(z=z, w=p.M @ z + p.q, status="solved", method="proposed")
    c = certify(p, sol, uniqueness="none")
    assert not c.accepted and c.forward_error == np.inf


@pytest.fixture
def inflator():
    @api.register("test-inflator", accepts="any", description="proposes t d (tests only)")
    def propose(M, q):
        z = 1e13 * D
        return lcp.Solution(z=z, w=M @ z + q, status="solved", method="test-inflator",
                            basis=np.array([1, 2]))
    yield propose
    api._REGISTRY.pop("test-inflator", None)


def test_lcp_solve_does_not_call_it_solved(inflator):
    p = n4_0()
    sol = lcp.solve(p, method="test-inflator")
    assert sol.status != "solved" and sol.method == "test-inflator", sol.message
