"""A solution of an event that keeps every contact closed, or a proof that there is none.

The event's LCP (models.event, Eq. 2.7) may have several solutions; the selection rules
(models/selection.py) choose within the face of the solver's solution. When the selected one
opens a contact (a_n > 0) or translates a disk, the no-displacement regime of the paper ends
only if *every* solution of the event does. `closed_solution` decides that exactly: it looks
for z = [R, tau, a_minus] >= 0 with w = M z + q and

    a_n = w[:c] = 0 on every contact (closed; Signorini 0 <= R perp a_n >= 0 then holds),
    nu'_x = 0 for every disk (M^-1 (H^T G z + f) on the vx, vy rows: no translation),
    w[c:] >= 0 and z[c:] . w[c:] = 0 (the tangential laws of the candidates, Eq. 2.7),

by a branch and bound over the complementarity pairs (tau_i, a_plus_i), (a_minus_i,
2 mu R_i - tau_i): each node is a linear program (scipy's HiGHS) with some z_j or w_j fixed
to zero, minimizing sum R; a node whose LP point is complementary is a closed solution. The
least sum R over all closed solutions is followed (the "global" rule's objective, restricted
to closed solutions); no big-M bound is needed, so an exhausted tree is a proof.

A node is discarded as infeasible only with a Farkas certificate (y, u >= 0) checked in
floating point: A_eq^T y + A_ub^T u >= -worst and b_eq . y + b_ub . u = -gap < 0, so every z of
the node has sum z >= gap / worst (`RADIUS` times the problem's scale at least, else the node
is undecided). "none" is returned only when every node was so discarded; a node or time limit
gives "undecided". models may use lcp and scipy, never verify (tests/test_architecture.py).
"""

from __future__ import annotations

import heapq
import time
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog

from rigidlcp import lcp
from rigidlcp.models.event import EventProblem

#: A certificate must exclude every node point with sum z below RADIUS x the problem's scale.
RADIUS = 1e9


@dataclass
class ClosedSearch:
    """status: "found" (z: a closed solution, checked), "none" (every node proved infeasible,
    `radius`: the smallest sum z the certificates exclude, in units of `scale`) or "undecided"
    (a limit reached, or an LP whose answer failed its check)."""

    status: str
    z: np.ndarray | None = None
    nodes: int = 0
    radius: float = np.inf
    message: str = ""


def closed_rows(ep: EventProblem) -> tuple[np.ndarray, np.ndarray]:
    """(A, b) with A z + b = [a_n (c); nu'_x (2p)]: the rows that must vanish for every
    contact to stay closed and no disk to translate."""
    system, dyn, M, q = ep.system, ep.dyn, ep.lcp.M, ep.lcp.q
    c, p = system.c, system.p
    acc = dyn.Minv[: 2 * p, None] * (dyn.H_T[: 2 * p] @ ep.G)  # nu'_x per unit z
    acc = np.asarray(acc)
    acc0 = dyn.Minv[: 2 * p] * dyn.f[: 2 * p]
    return np.vstack([M[:c], acc]), np.concatenate([q[:c], acc0])


def _check_closed(ep: EventProblem, A: np.ndarray, b: np.ndarray, z: np.ndarray,
                  tol: float) -> float:
    """The largest violation of the closed problem at z (complementarity, sign, rows)."""
    w = ep.lcp.M @ z + ep.lcp.q
    c = ep.system.c
    return max(lcp.complementarity_residual(z[c:], w[c:]), float(max(-z.min(initial=0.0), 0)),
               float(np.abs(A @ z + b).max(initial=0.0)))


def _polish(ep: EventProblem, A: np.ndarray, b: np.ndarray, z: np.ndarray,
            zero_z: np.ndarray, zero_w: np.ndarray) -> np.ndarray:
    """One least-squares correction of the LP point on its support: the rows A z + b = 0 and
    w_j = 0 where z_j > 0 (j >= c) or w_j was fixed to 0 hold to rounding, z_j = 0 off the
    support (HiGHS meets its equalities to ~1e-9 only; the engine's tolerance is 1e-9 g)."""
    c = ep.system.c
    M, q = ep.lcp.M, ep.lcp.q
    scale = max(float(np.abs(z).max(initial=0.0)), 1e-300)
    support = (z > 1e-12 * scale) & ~zero_z
    w = M @ z + q
    tight = np.zeros(z.size, bool)
    tight[c:] = support[c:] | zero_w[c:]
    tight[:c] = zero_w[:c]
    rows = np.vstack([A, M[tight]])
    rhs = -np.concatenate([A @ z + b, w[tight]])
    cols = np.flatnonzero(support)
    if not cols.size:
        return z
    dz, *_ = np.linalg.lstsq(rows[:, cols], rhs, rcond=None)
    y = z.copy()
    y[cols] += dz
    y[~support] = 0.0
    return y


def closed_solution(ep: EventProblem, scale: float, tol: float, node_limit: int = 5000,
                    time_limit: float = 30.0) -> ClosedSearch:
    """The closed solution of least sum R of the event `ep`, or a proof that none exists (module
    doc). scale: the problem's scale (the engine's: max |q|, m g); tol: the acceptance of a
    point (every row and complementarity residual <= tol x scale)."""
    c, n = ep.system.c, ep.lcp.n
    M, q = ep.lcp.M, ep.lcp.q
    A, b = closed_rows(ep)
    cost = np.zeros(n)
    cost[:c] = 1.0
    start = time.process_time()
    root = (np.zeros(n, bool), np.zeros(n, bool))  # zero_z, zero_w (fixed by branching)
    heap: list = [(0.0, 0, root)]
    counter, nodes, best, radius = 1, 0, None, np.inf
    while heap:
        bound, _, (zero_z, zero_w) = heapq.heappop(heap)
        if best is not None and bound >= best[0] - 1e-12 * max(1.0, abs(best[0])):
            continue
        if nodes >= node_limit or time.process_time() - start > time_limit:
            return ClosedSearch("undecided", nodes=nodes, message=(
                f"undecided: the search for a closed solution stopped after {nodes} LPs "
                f"({time.process_time() - start:.1f} s CPU)"))
        nodes += 1
        res = _node_lp(A, b, M, q, c, cost, zero_z, zero_w)
        if res.status == 2:  # infeasible: discarded only with a checked certificate
            r = _farkas_radius(A, b, M, q, c, zero_z, zero_w)
            if r < RADIUS * scale:
                return ClosedSearch("undecided", nodes=nodes, message=(
                    "undecided: an LP of the search is infeasible but its Farkas certificate "
                    f"fails its check (radius {r:.3g})"))
            radius = min(radius, r / scale)
            continue
        if res.status != 0:
            return ClosedSearch("undecided", nodes=nodes,
                                message=f"undecided: an LP of the search ended with {res.message}")
        j, y = _branch_or_point(ep, A, b, np.maximum(res.x, 0.0), zero_z, zero_w, scale, tol)
        if y is not None:
            if best is None or float(y[:c].sum()) < best[0]:
                best = (float(y[:c].sum()), y)
            continue
        if j < 0:
            return ClosedSearch("undecided", nodes=nodes, message=(
                "undecided: a complementary LP point fails the engine's check"))
        for fix in (zero_z, zero_w):
            zz, ww = zero_z.copy(), zero_w.copy()
            (zz if fix is zero_z else ww)[j] = True
            heapq.heappush(heap, (float(res.fun), counter, (zz, ww)))
            counter += 1
    if best is not None:
        return ClosedSearch("found", z=best[1], nodes=nodes, message=(
            f"a solution keeping every contact closed followed (sum R = {best[0]:.6g}, least "
            f"over the closed solutions; {nodes} LP(s))"))
    return ClosedSearch("none", nodes=nodes, radius=radius, message=(
        f"proved: no solution of the event keeps every contact closed ({nodes} LP(s), each "
        f"infeasible with a Farkas certificate checked: any closed solution would need "
        f"sum z >= {radius:.3g} x the loads)"))


def _branch_or_point(ep, A, b, z, zero_z, zero_w, scale, tol):
    """(j, None): the pair j (an index of z) to branch on, the most violated; (-1, y): y the
    node's point, complementary and checked (polished); (-1, None): complementary to the LP's
    accuracy but failing the check after polishing."""
    c = ep.system.c
    w = ep.lcp.M @ z + ep.lcp.q
    viol = np.minimum(z[c:], np.maximum(w[c:], 0.0))
    j = int(np.argmax(viol)) if viol.size else 0
    if viol.size and viol[j] > 1e-9 * scale:
        return c + j, None
    y = _polish(ep, A, b, z, zero_z, zero_w)
    if _check_closed(ep, A, b, y, tol) <= tol * scale:
        return -1, y
    if viol.size and viol[j] > 0:  # not exactly complementary: branch on it
        return c + j, None
    return -1, None


def _node_rows(A, b, M, q, c, zero_w):
    """A_eq x = b_eq, A_ub x <= b_ub of a node: the closed rows, w_j = 0 where fixed, and
    w_j >= 0 on the tangential rows."""
    fixed = np.flatnonzero(zero_w)
    A_eq = np.vstack([A, M[fixed]])
    b_eq = -np.concatenate([b, q[fixed]])
    free = np.array([j for j in range(c, M.shape[0]) if not zero_w[j]], dtype=int)
    return A_eq, b_eq, -M[free], q[free]


def _node_lp(A, b, M, q, c, cost, zero_z, zero_w):
    A_eq, b_eq, A_ub, b_ub = _node_rows(A, b, M, q, c, zero_w)
    bounds = [(0.0, 0.0) if f else (0.0, None) for f in zero_z]
    return linprog(cost, A_ub=A_ub if b_ub.size else None, b_ub=b_ub if b_ub.size else None,
                   A_eq=A_eq, b_eq=b_eq, bounds=bounds, method="highs",
                   options={"primal_feasibility_tolerance": 1e-10,
                            "dual_feasibility_tolerance": 1e-10})


def _farkas_radius(A, b, M, q, c, zero_z, zero_w) -> float:
    """The sum z below which a checked Farkas certificate excludes every point of the node
    (0 when no certificate is found or it fails: gap <= 0)."""
    A_eq, b_eq, A_ub, b_ub = _node_rows(A, b, M, q, c, zero_w)
    keep = ~zero_z
    K = np.vstack([A_eq, A_ub])[:, keep]
    rhs = np.concatenate([b_eq, b_ub])
    m_eq = b_eq.size
    bounds = [(-1.0, 1.0)] * m_eq + [(0.0, 1.0)] * b_ub.size
    # min rhs . (y, u) subject to K^T (y, u) >= 0
    res = linprog(rhs, A_ub=-K.T, b_ub=np.zeros(K.shape[1]), bounds=bounds, method="highs")
    if res.status != 0 or res.fun >= 0:
        return 0.0
    yu = res.x
    yu[m_eq:] = np.maximum(yu[m_eq:], 0.0)
    gap = -float(rhs @ yu)
    worst = max(0.0, -float((K.T @ yu).min(initial=0.0)))
    if gap <= 0:
        return 0.0
    return np.inf if worst == 0 else gap / worst
