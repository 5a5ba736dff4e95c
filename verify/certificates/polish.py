"""The polishing LP of the uniqueness MILP (verify.certificates.uniqueness.milp_search): an
exact solution of the LCP on the basis the MILP proposes, with the target's difference from
z*, or the proof that the basis holds none (then cutting it off loses nothing). Split out of
uniqueness.py (one job per module)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import linprog

from rigidlcp.lcp.acceptance.residual import scaled_residual

from .highs import HIGHS_LP


def polish_basis(M, q, z_star, y, target, chosen, L, delta, zs, ws, pat, extra
                 ) -> tuple[np.ndarray | None, bool]:
    """(z, proved): an exact solution z on the MILP's basis y with the target's difference (an
    LP per way of differing, the MILP's chosen ones first), or None; `proved` is True when every
    one of those LPs was proved infeasible, i.e. the basis holds no such solution and cutting it
    off loses nothing. (The MILP's binaries may pick a disjunct that rounding made look
    satisfied while the basis holds a solution that differs elsewhere: all are tried.)"""
    n = q.size
    a, b = np.flatnonzero(y), np.flatnonzero(~y)
    bounds = [(0.0, None) if y[i] else (0.0, 0.0) for i in range(n)]
    order = np.r_[np.flatnonzero(chosen), np.flatnonzero(~chosen)]
    ways: list[tuple[np.ndarray, float] | None] = []
    check = None
    if target == "pattern":
        plus, minus = np.flatnonzero(pat == 1), np.flatnonzero(pat == -1)
        deg = np.flatnonzero(pat == 0)
        if np.any(~y[plus]) or np.any(y[minus]):
            ways = [None]  # the basis itself differs from z*'s pattern
        for k in order if not ways else []:
            i = deg[k]
            if y[i]:
                row = np.zeros(n)
                row[i] = -1.0 / zs  # z_i >= delta zs
                ways.append((row, -delta * (1 - 1e-3)))
            else:
                ways.append((-M[i] / ws, q[i] / ws - delta * (1 - 1e-3)))  # w_i >= delta ws
    else:
        v_star = L @ z_star
        sL = max(float(np.max(np.sum(np.abs(L), axis=1))) * zs, float(np.max(np.abs(v_star))),
                 1e-300)
        for k in order:
            j, sgn = extra[k]
            ways.append((-sgn * L[j] / sL, -sgn * v_star[j] / sL - delta * (1 - 1e-3)))

        def check(z):
            return float(np.max(np.abs(L @ (z - z_star)))) >= delta * sL * (1 - 1e-2)
    proved = True
    for way in ways:
        A_ub, b_ub = [-M[b]], [q[b]]
        if way is not None:
            A_ub.append(way[0][None, :])
            b_ub.append(np.array([way[1]]))
        res = linprog(np.ones(n), A_ub=np.vstack(A_ub), b_ub=np.concatenate(b_ub),
                      A_eq=M[a] if a.size else None, b_eq=-q[a] if a.size else None,
                      bounds=bounds, method="highs", options=HIGHS_LP)
        if res.status == 2:
            continue
        proved = False
        if res.status != 0 or res.x is None:
            continue
        z = np.maximum(res.x, 0.0)
        if scaled_residual(M, q, z) <= 1e-8 and (check is None or check(z)):
            return z, False
    return None, proved
