"""Projected Gauss-Seidel (method ``pgs``): the iteration of NSCD codes, as a baseline.

One sweep visits i = 0, ..., n-1 in order and sets

    z_i <- max(0, z_i - omega (M_i. z + q_i) / M_ii),

using the components already updated in the sweep (Cryer, SIAM J. Control 9, 385, 1971, with
over-relaxation omega; Cottle, Pang & Stone 1992, Sec. 5.2; Jean, Comput. Methods Appl. Mech.
Eng. 177, 235, 1999, for its use in non-smooth contact dynamics). It converges for symmetric
positive definite M with 0 < omega < 2, and for H-matrices with positive diagonal (e.g.
strictly diagonally dominant) with omega <= 1; otherwise it may stall or diverge, which it
reports as "not_converged" (or "failed" when the iterate overflows), never as a solution.
"""

from __future__ import annotations

import math

import numpy as np

from ..problems.problem import InvalidProblem, NotApplicable, as_vector
from ..problems.solution import Solution, complementarity_residual
from ..registry import register


@register(
    "pgs", accepts="any",
    description="Projected Gauss-Seidel (Cryer's SOR): needs a positive diagonal; converges for "
    "symmetric PD or diagonally dominant M, slowly.",
)
def solve_pgs(
    M: np.ndarray, q: np.ndarray, *, tol: float = 1e-10, max_iter: int = 10_000,
    z0=None, omega: float = 1.0,
) -> Solution:
    """Solve an LCP by projected Gauss-Seidel / SOR (Cryer 1971).

    tol: stop when max|min(z, w)| <= tol * max(1, |q|_inf), checked after each sweep with
        w = M z + q recomputed. max_iter: limit on sweeps. z0: starting point (projected onto
        z >= 0; default 0). omega: relaxation factor in (0, 2).

    Status "solved"; "not_converged" when max_iter sweeps end above tol (``info["residual"]``
    is the last residual); "failed" when the iterate stops being finite. Raises NotApplicable
    when some M_ii <= 0 (the update divides by it). iterations counts sweeps.
    """
    n = q.size
    d = np.diagonal(M).copy()
    bad = np.flatnonzero(d <= 0)
    if bad.size:
        raise NotApplicable(
            f"pgs divides by the diagonal of M, which must be positive; M[{bad[0]}, {bad[0]}] = "
            f"{d[bad[0]]:g} ({bad.size} such entries)"
        )
    if not (isinstance(tol, (int, float)) and math.isfinite(tol) and tol > 0):
        raise InvalidProblem(f"tol must be a positive number, got {tol!r}")
    if not (isinstance(max_iter, (int, np.integer)) and max_iter >= 0):
        raise InvalidProblem(f"max_iter must be a non-negative integer, got {max_iter!r}")
    if not (isinstance(omega, (int, float)) and 0 < omega < 2):
        raise InvalidProblem(f"omega must be a number in (0, 2), got {omega!r}")
    z = np.zeros(n) if z0 is None else np.maximum(as_vector("z0", z0, n), 0.0)
    target = tol * max(1.0, float(np.max(np.abs(q))))
    rows = [M[i] for i in range(n)]
    step = omega / d
    w = M @ z + q
    res = complementarity_residual(z, w)
    sweeps = 0
    while res > target and sweeps < max_iter:
        with np.errstate(over="ignore", invalid="ignore"):
            for i in range(n):
                zi = z[i] - step[i] * (rows[i] @ z + q[i])
                z[i] = zi if zi > 0.0 else 0.0
            sweeps += 1
            w = M @ z + q
            res = complementarity_residual(z, w)
        if not math.isfinite(res):
            z = np.where(np.isfinite(z), z, 0.0)
            with np.errstate(over="ignore", invalid="ignore"):
                w = M @ z + q
            return Solution(z=z, w=w, status="failed", method="pgs", iterations=sweeps,
                            message=f"the iterate overflowed after {sweeps} sweeps (diverged)",
                            info={"residual": res, "omega": omega})
    info = {"residual": res, "target": target, "omega": omega}
    basis = np.flatnonzero(z > 0)
    if res <= target:
        return Solution(z=z, w=w, status="solved", method="pgs", iterations=sweeps,
                        basis=basis, info=info)
    return Solution(
        z=z, w=w, status="not_converged", method="pgs", iterations=sweeps, basis=basis,
        message=f"residual {res:.3e} above {target:.3e} after {sweeps} sweeps", info=info,
    )
