"""A certified bound on every solution of an LCP: no solution has |z|_1 >= S (a MILP).

The MILP of verify.certificates.uniqueness.milp_search sees only the box 0 <= z <= U. This
module removes that proviso when it can: z solves LCP(M, q) with |z|_1 = s >= S iff
zeta = z / s and theta = 1 / s in (0, 1/S] satisfy

    zeta >= 0,  sum(zeta) = 1,  w' = M zeta + theta q >= 0,  zeta_i w'_i = 0,

(w' = w / s). Every quantity is bounded *without any assumption*: 0 <= zeta_i <= 1 and, since
M zeta is a convex combination of the columns of M, w'_i <= max_j M_ij + max(q_i, 0) / S. With
binaries y (y_i = 1: zeta_i may be positive and w'_i = 0), these exact big-M constants give a
MILP that is infeasible if no solution has |z|_1 >= S and no nonzero d >= 0 solves LCP(M, 0)
(theta = 0 is allowed: the closure of the large solutions). A point with theta > 0 gives a
solution z = zeta / theta, verified by its residual. HiGHS's tolerances can only let
spurious points in (y within 1e-9 of an integer), never cut real ones out; HiGHS did cut
one out once (uniqueness.confirmed_milp), so "infeasible" counts only when HiGHS gives it
at 1e-9 and again at 1e-8, as milp_search's "none": HiGHS's verdict, not a
checked certificate.

Then |z|_inf <= |z|_1 < S for every solution, and a "none" of milp_search in the box U >= S is a
global verdict.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.optimize import Bounds, LinearConstraint

from rigidlcp.lcp.errors import InvalidInput

from .clocked import clock
from .uniqueness import confirmed_milp, scaled_residual

_HIGHS = {"mip_feasibility_tolerance": 1e-9, "primal_feasibility_tolerance": 1e-9}


@dataclass
class NormBound:
    """proved: True (no solution with |z|_1 >= S), False (a solution with |z|_1 >= S exists,
    verified), None (undecided: time limit, or only a direction theta = 0 of LCP(M, 0))."""

    proved: bool | None
    S: float
    seconds: float
    message: str


def no_solution_beyond(M: np.ndarray, q: np.ndarray, S: float, time_limit: float = 10.0,
                       clock_name: str = "cpu") -> NormBound:
    """Decide whether LCP(M, q) has a solution with |z|_1 >= S (module docstring), within
    time_limit seconds on the clock `clock_name` ("cpu": this process's CPU seconds, or
    "wall"; verify.certificates.clocked). `seconds`: wall seconds."""
    clock(clock_name)  # a wrong clock refused before any work
    t0 = time.perf_counter()
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    n = q.size
    if not S > 0:
        raise InvalidInput(f"S must be positive, got {S}")
    wmax = np.maximum(np.max(M, axis=1) + np.maximum(q, 0.0) / S, 0.0)
    # columns: zeta (n) | theta | y (n)
    N = 2 * n + 1
    lo, hi = [], []
    A = sp.lil_matrix((3 * n + 1, N))
    for i in range(n):
        A[i, :n] = M[i]  # w'_i = M_i zeta + theta q_i >= 0
        A[i, n] = q[i]
        lo.append(0.0)
        hi.append(np.inf)
    for i in range(n):  # zeta_i - y_i <= 0
        A[n + i, i] = 1.0
        A[n + i, n + 1 + i] = -1.0
        lo.append(-np.inf)
        hi.append(0.0)
    for i in range(n):  # w'_i + wmax_i y_i <= wmax_i
        A[2 * n + i, :n] = M[i]
        A[2 * n + i, n] = q[i]
        A[2 * n + i, n + 1 + i] = wmax[i]
        lo.append(-np.inf)
        hi.append(wmax[i])
    A[3 * n, :n] = 1.0  # sum zeta = 1
    lo.append(1.0)
    hi.append(1.0)
    ub = np.r_[np.ones(n), 1.0 / S, np.ones(n)]
    integrality = np.r_[np.zeros(n + 1), np.ones(n)]
    out, runs = confirmed_milp(np.zeros(N), integrality,
                      LinearConstraint(A.tocsr(), np.array(lo), np.array(hi)), time_limit,
                      bounds=Bounds(np.zeros(N), ub), options=_HIGHS, clock_name=clock_name)
    secs = time.perf_counter() - t0
    if out.status == 2 and runs < 2:
        return NormBound(None, S, secs, "MILP infeasible at tolerance 1e-9; no time left to "
                         "confirm it at 1e-8: undecided")
    if out.status == 2:
        return NormBound(True, S, secs, f"no solution with |z|_1 >= {S:.3g} (MILP infeasible, "
                         f"{secs:.2f} s)")
    if out.x is not None:
        theta = float(out.x[n])
        if theta > 1e-12:
            z = np.maximum(out.x[:n], 0.0) / theta
            if scaled_residual(M, q, z) <= 1e-8:
                return NormBound(False, S, secs, f"a solution with |z|_1 = "
                                 f"{float(np.sum(z)):.3g} >= {S:.3g} exists (verified)")
        return NormBound(None, S, secs, "no bound proved: the MILP's point "
                         + ("is a nonzero solution of LCP(M, 0), a recession direction (the "
                            "solution set may be unbounded)" if theta <= 1e-12
                            else "is not an accurate solution"))
    return NormBound(None, S, secs, f"norm bound undecided: {out.message}")
