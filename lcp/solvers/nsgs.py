"""Nonsmooth Gauss-Seidel on the exact 2D Coulomb cone (method ``nsgs``, friction contact only).

One sweep visits the contacts alpha = 0, ..., c-1 in order and solves the *local* problem of
contact alpha exactly, the others' forces fixed (Jean & Moreau's NSCD / Siconos's fc2d_nsgs):

    u_alpha = W_aa r_alpha + qt_alpha,   qt_alpha = q_alpha + sum_{beta != alpha} W_ab r_beta,

a 2 x 2 friction-contact problem whose solution is one of (Signorini-Coulomb, Eq. 2.5-2.6):

* open:   r = 0,                                  valid when qt_n >= 0;
* stick:  u = 0, r = -W_aa^-1 qt,                 valid when |r_t| <= mu r_n;
* slide:  u_n = 0, r_t = -s mu r_n (s = +1 or -1), r_n = -qt_n / (W_nn - s mu W_nt) >= 0,
          valid when s u_t >= 0.

The first valid case in that order is taken (for a positive definite W_aa exactly one holds,
up to ties). When none is (an indefinite W_aa), the projection step r <- P_K(r - uhat / W_nn)
is taken instead and counted in info["projection_steps"].

Stopping: after each sweep, the relative natural-map residual (lcp.friction) <= tol. NSGS
converges for symmetric positive definite W (it is then block coordinate descent on a convex
problem for frictionless contacts, and in practice with friction), slowly on large granular
packings; "not_converged" with the residual when max_iter sweeps do not reach tol.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..problems.friction import FrictionContact2D, natural_residual, project_cone
from ..problems.problem import InvalidProblem
from ..problems.solution import Solution
from ..registry import register


def _local(Waa: np.ndarray, qt: np.ndarray, mu: float, r: np.ndarray) -> tuple[np.ndarray, bool]:
    """The exact solution of the 2 x 2 local problem (module doc); (r, True) or a projection
    step (r, False)."""
    qn, qtt = qt
    if qn >= 0:
        return np.zeros(2), True
    det = Waa[0, 0] * Waa[1, 1] - Waa[0, 1] * Waa[1, 0]
    if det != 0:
        rs = -np.array([Waa[1, 1] * qn - Waa[0, 1] * qtt, -Waa[1, 0] * qn + Waa[0, 0] * qtt]) / det
        if rs[0] >= 0 and abs(rs[1]) <= mu * rs[0]:
            return rs, True
    for s in (1.0, -1.0):
        den = Waa[0, 0] - s * mu * Waa[0, 1]
        if den <= 0:
            continue
        rn = -qn / den
        if rn < 0:
            continue
        ut = (Waa[1, 0] - s * mu * Waa[1, 1]) * rn + qtt
        if s * ut >= 0:
            return np.array([rn, -s * mu * rn]), True
    u = Waa @ r + qt
    uhat = np.array([u[0] + mu * abs(u[1]), u[1]])
    step = 1.0 / max(Waa[0, 0], 1e-300)
    return project_cone(r - step * uhat, np.array([mu])), False


def solve_nsgs(problem: FrictionContact2D, *, tol: float = 1e-12, max_iter: int = 10_000,
               r0: np.ndarray | None = None) -> Solution:
    """Nonsmooth Gauss-Seidel (module doc). tol: relative natural-map residual to stop at
    (checked after every sweep); max_iter: sweeps; r0: start (default 0)."""
    if not (0 < tol < 1):
        raise InvalidProblem(f"tol must be in (0, 1), got {tol!r}")
    if not (isinstance(max_iter, int) and max_iter >= 1):
        raise InvalidProblem(f"max_iter must be a positive integer, got {max_iter!r}")
    c, mu = problem.c, problem.mu
    W = sp.csc_matrix(problem.W)
    diag = [W[2 * a:2 * a + 2, 2 * a:2 * a + 2].toarray() for a in range(c)]
    r = np.zeros(2 * c) if r0 is None else np.asarray(r0, dtype=float).copy()
    u = W @ r + problem.q
    indptr, indices, data = W.indptr, W.indices, W.data
    projections, res, sweep = 0, np.inf, 0
    for sweep in range(1, max_iter + 1):
        for a in range(c):
            i = 2 * a
            ra = r[i:i + 2]
            qt = u[i:i + 2] - diag[a] @ ra
            new, exact = _local(diag[a], qt, float(mu[a]), ra)
            projections += not exact
            d = new - ra
            if d[0] != 0.0:
                lo, hi = indptr[i], indptr[i + 1]
                u[indices[lo:hi]] += data[lo:hi] * d[0]
            if d[1] != 0.0:
                lo, hi = indptr[i + 1], indptr[i + 2]
                u[indices[lo:hi]] += data[lo:hi] * d[1]
            r[i:i + 2] = new
        u = W @ r + problem.q  # no drift
        res = natural_residual(problem, r, u)
        if not np.isfinite(res):
            return Solution(z=r, w=u, status="failed", method="nsgs", iterations=sweep,
                            message="the iterate is not finite")
        if res <= tol:
            return Solution(z=r, w=u, status="solved", method="nsgs", iterations=sweep,
                            info={"projection_steps": projections})
    return Solution(z=r, w=u, status="not_converged", method="nsgs", iterations=sweep,
                    message=f"relative natural-map residual {res:.3e} > {tol:g} after "
                    f"{max_iter} sweeps", info={"projection_steps": projections})


register(
    "nsgs", accepts="friction-2d",
    description="Nonsmooth Gauss-Seidel with the exact 2D local solver (Siconos's fc2d_nsgs); "
    "a baseline: slow on large packings.",
)(solve_nsgs)
