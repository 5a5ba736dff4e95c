"""Contact-state pivoting for 2D friction contact (method ``states``).

The paper's contact-state iteration (Sec. II C) on a FrictionContact2D: the implementation is
the event solver of the disk arrays, lcp.state_pivoting.solve_states (block principal
pivoting on contact states, sparse LU with row updates, a local Lemke rescue), applied with
every contact a non-sliding candidate. Its states are, per contact, T/NT (r_n basic or
u_n basic) and NS/+/- (u_t = 0, or r_t = -mu r_n / +mu r_n), i.e. the complementary bases of
the Glocker LCP (lcp.friction). It is deterministic: the same problem gives the same answer and
the same iteration count on every run (refactoring is triggered by counts, not by time).

Start: T wherever q_n <= 0 (the free motion closes the contact), and sliding the way q_t drives
it (as models.engine.sparse's cold start). Status: "solved", "max_iter" or "failed" (with the
number of still violated states).
"""

from __future__ import annotations

import numpy as np

from ..problems.friction import FrictionContact2D
from ..problems.problem import InvalidProblem
from ..problems.solution import Solution
from ..registry import register


def solve_states_fc2d(problem: FrictionContact2D, *, tol: float = 1e-10,
                      max_iter: int | None = None, max_updates: int = 400) -> Solution:
    """Contact-state pivoting (module doc). tol: the sign tests' relative tolerance
    (lcp.state_pivoting.violations); max_iter: state changes (default max(1000, 20 c));
    max_updates: row replacements before a fresh sparse LU."""
    if not (0 < tol < 1):
        raise InvalidProblem(f"tol must be in (0, 1), got {tol!r}")
    from .state_factor import ActiveSystem, StateFactor
    from .state_pivoting import STALL, solve_states

    c, mu = problem.c, problem.mu
    Wb, qb = problem.blocks()
    asys = ActiveSystem(Wb, qb, mu)
    cand = mu > 0
    tang_fixed = np.zeros(c, dtype=np.int8)  # frictionless contacts: S = 0
    scale = float(np.abs(qb).max(initial=0.0)) or 1.0
    normal0 = qb[:c] <= 1e-12 * scale
    tang0 = np.where(cand, np.where(qb[c:] < 0, -1, 1), tang_fixed).astype(np.int8)
    factor = StateFactor(asys, np.zeros(c, dtype=bool), np.where(cand, 1, 0).astype(np.int8),
                         max_updates)
    res = solve_states(factor, cand, normal0, tang0, tol=tol, max_iter=max_iter, stall=STALL)
    r = np.empty(2 * c)
    r[0::2], r[1::2] = res.R, res.S
    info = dict(res.info)
    info["lcp_residual"] = res.residual
    return Solution(z=r, w=problem.u(r), status=res.status, method="states",
                    iterations=res.iterations, message=res.message, info=info,
                    basis=np.flatnonzero(res.normal))


register(
    "states", accepts="friction-2d",
    description="The paper's contact-state pivoting (sparse LU with row updates; the disk "
    "arrays' event solver); deterministic.",
)(solve_states_fc2d)
