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

The search itself (`search`) takes any `ClosedProblem`: an LCP whose first c unknowns are the
normal forces, with the rows that must vanish, dense or scipy.sparse. The dense event engine
gives it the dense event LCP (`event_closed`); the sparse backend the same LCP assembled from
the sparse MLCP without a dense matrix (models/engine/sparse_closed.py); the time-stepper its
step's velocity-level LCP (models/step_closed.py: u_n = 0 and no disk translating at the end of
the step, with P_n in place of R).
"""

from __future__ import annotations

import heapq
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
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


@dataclass
class ClosedProblem:
    """An LCP w = M z + q (0 <= z perp w >= 0 on the pairs j >= c) whose first c unknowns are
    normal forces (or impulses), with the rows A z + b = 0 that must vanish for every contact
    to stay closed and no disk to translate. M, A: numpy arrays or scipy.sparse matrices.
    what: the problem's name in messages ("event", "step"); time_limited: each LP is also
    given the search's time left (HiGHS's time_limit; for large sparse problems)."""

    M: np.ndarray | sp.spmatrix
    q: np.ndarray
    c: int
    A: np.ndarray | sp.spmatrix
    b: np.ndarray
    what: str = "event"
    time_limited: bool = False

    @property
    def n(self) -> int:
        return int(self.q.size)


def closed_rows(ep: EventProblem) -> tuple[np.ndarray, np.ndarray]:
    """(A, b) with A z + b = [a_n (c); nu'_x (2p)]: the rows that must vanish for every
    contact to stay closed and no disk to translate."""
    system, dyn, M, q = ep.system, ep.dyn, ep.lcp.M, ep.lcp.q
    c, p = system.c, system.p
    acc = dyn.Minv[: 2 * p, None] * (dyn.H_T[: 2 * p] @ ep.G)  # nu'_x per unit z
    acc = np.asarray(acc)
    acc0 = dyn.Minv[: 2 * p] * dyn.f[: 2 * p]
    return np.vstack([M[:c], acc]), np.concatenate([q[:c], acc0])


def event_closed(ep: EventProblem) -> ClosedProblem:
    """The dense event LCP of `ep` as a ClosedProblem (the dense engine's)."""
    A, b = closed_rows(ep)
    return ClosedProblem(ep.lcp.M, ep.lcp.q, ep.system.c, A, b)


def closed_solution(ep: EventProblem, scale: float, tol: float, node_limit: int = 5000,
                    time_limit: float = 30.0) -> ClosedSearch:
    """The closed solution of least sum R of the event `ep`, or a proof that none exists (module
    doc). scale: the problem's scale (the engine's: max |q|, m g); tol: the acceptance of a
    point (every row and complementarity residual <= tol x scale)."""
    return search(event_closed(ep), scale, tol, node_limit, time_limit)


def _vstack(blocks):
    """np.vstack, or scipy.sparse's when a block is sparse (a csr matrix)."""
    if any(sp.issparse(b) for b in blocks):
        return sp.vstack(blocks, format="csr")
    return np.vstack(blocks)


def _check_closed(pb: ClosedProblem, z: np.ndarray) -> float:
    """The largest violation of the closed problem at z (complementarity, sign, rows)."""
    w = pb.M @ z + pb.q
    c = pb.c
    return max(lcp.complementarity_residual(z[c:], w[c:]), float(max(-z.min(initial=0.0), 0)),
               float(np.abs(pb.A @ z + pb.b).max(initial=0.0)))


#: Largest least-squares block (entries) polished densely on a sparse problem (else LSQR).
DENSE_POLISH = 4_000_000


def _polish(pb: ClosedProblem, z: np.ndarray, zero_z: np.ndarray,
            zero_w: np.ndarray) -> np.ndarray:
    """One least-squares correction of the LP point on its support: the rows A z + b = 0 and
    w_j = 0 where z_j > 0 (j >= c) or w_j was fixed to 0 hold to rounding, z_j = 0 off the
    support (HiGHS meets its equalities to ~1e-9 only; the engine's tolerance is 1e-9 g)."""
    c, M, q, A, b = pb.c, pb.M, pb.q, pb.A, pb.b
    scale = max(float(np.abs(z).max(initial=0.0)), 1e-300)
    support = (z > 1e-12 * scale) & ~zero_z
    w = M @ z + q
    tight = np.zeros(z.size, bool)
    tight[c:] = support[c:] | zero_w[c:]
    tight[:c] = zero_w[:c]
    rows = _vstack([A, M[np.flatnonzero(tight)]])
    rhs = -np.concatenate([A @ z + b, w[tight]])
    cols = np.flatnonzero(support)
    if not cols.size:
        return z
    block = rows[:, cols]
    if sp.issparse(block):
        if block.shape[0] * block.shape[1] <= DENSE_POLISH:
            block = block.toarray()
        else:
            from scipy.sparse.linalg import lsqr

            dz = lsqr(block, rhs, atol=1e-15, btol=1e-15, iter_lim=20 * cols.size)[0]
            block = None
    if block is not None:
        dz, *_ = np.linalg.lstsq(block, rhs, rcond=None)
    y = z.copy()
    y[cols] += dz
    y[~support] = 0.0
    return y


def search(pb: ClosedProblem, scale: float, tol: float, node_limit: int = 5000,
           time_limit: float = 30.0) -> ClosedSearch:
    """The closed solution of least sum z[:c] of `pb`, or a proof that none exists (module
    doc): the branch and bound, at most node_limit LPs and time_limit CPU seconds."""
    c, n, what = pb.c, pb.n, pb.what
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
        left = time_limit - (time.process_time() - start)
        if nodes >= node_limit or left < 0:
            return ClosedSearch("undecided", nodes=nodes, message=(
                f"undecided: the search for a closed solution stopped after {nodes} LPs "
                f"({time.process_time() - start:.1f} s CPU)"))
        nodes += 1
        limit = max(left, 1.0) if pb.time_limited else None
        res = _node_lp(pb, cost, zero_z, zero_w, limit)
        if res.status == 2:  # infeasible: discarded only with a checked certificate
            r = _farkas_radius(pb, zero_z, zero_w, limit)
            if r < RADIUS * scale:
                return ClosedSearch("undecided", nodes=nodes, message=(
                    "undecided: an LP of the search is infeasible but its Farkas certificate "
                    f"fails its check (radius {r:.3g})"))
            radius = min(radius, r / scale)
            continue
        if res.status != 0:
            return ClosedSearch("undecided", nodes=nodes,
                                message=f"undecided: an LP of the search ended with {res.message}")
        j, y = _branch_or_point(pb, np.maximum(res.x, 0.0), zero_z, zero_w, scale, tol)
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
    force = "R" if what == "event" else "P_n"
    if best is not None:
        return ClosedSearch("found", z=best[1], nodes=nodes, message=(
            f"a solution keeping every contact closed followed (sum {force} = {best[0]:.6g}, "
            f"least over the closed solutions; {nodes} LP(s))"))
    return ClosedSearch("none", nodes=nodes, radius=radius, message=(
        f"proved: no solution of the {what} keeps every contact closed ({nodes} LP(s), each "
        f"infeasible with a Farkas certificate checked: any closed solution would need "
        f"sum z >= {radius:.3g} x the loads)"))


def _branch_or_point(pb: ClosedProblem, z, zero_z, zero_w, scale, tol):
    """(j, None): the pair j (an index of z) to branch on, the most violated; (-1, y): y the
    node's point, complementary and checked (polished); (-1, None): complementary to the LP's
    accuracy but failing the check after polishing."""
    c = pb.c
    w = pb.M @ z + pb.q
    viol = np.minimum(z[c:], np.maximum(w[c:], 0.0))
    j = int(np.argmax(viol)) if viol.size else 0
    if viol.size and viol[j] > 1e-9 * scale:
        return c + j, None
    y = _polish(pb, z, zero_z, zero_w)
    if _check_closed(pb, y) <= tol * scale:
        return -1, y
    if viol.size and viol[j] > 0:  # not exactly complementary: branch on it
        return c + j, None
    return -1, None


def _node_rows(pb: ClosedProblem, zero_w):
    """A_eq x = b_eq, A_ub x <= b_ub of a node: the closed rows, w_j = 0 where fixed, and
    w_j >= 0 on the tangential rows."""
    M, q, c = pb.M, pb.q, pb.c
    fixed = np.flatnonzero(zero_w)
    A_eq = _vstack([pb.A, M[fixed]])
    b_eq = -np.concatenate([pb.b, q[fixed]])
    free = c + np.flatnonzero(~zero_w[c:])
    return A_eq, b_eq, -M[free], q[free]


#: HiGHS's tolerances in the node LPs.
LP_OPTIONS = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


def _node_lp(pb: ClosedProblem, cost, zero_z, zero_w, limit: float | None):
    A_eq, b_eq, A_ub, b_ub = _node_rows(pb, zero_w)
    bounds = [(0.0, 0.0) if f else (0.0, None) for f in zero_z]
    options = dict(LP_OPTIONS) if limit is None else {**LP_OPTIONS, "time_limit": limit}
    res = None
    for extra in ({}, {"presolve": False}):  # HiGHS may end "unknown" (status 15; highspy
        res = linprog(cost, A_ub=A_ub if b_ub.size else None,  # 1.10): asked again without
                      b_ub=b_ub if b_ub.size else None, A_eq=A_eq,  # its presolve
                      b_eq=b_eq, bounds=bounds, method="highs", options={**options, **extra})
        if res.status in (0, 2, 3):
            break
    return res


def _farkas_radius(pb: ClosedProblem, zero_z, zero_w, limit: float | None = None) -> float:
    """The sum z below which a checked Farkas certificate excludes every point of the node
    (0 when no certificate is found or it fails: gap <= 0)."""
    A_eq, b_eq, A_ub, b_ub = _node_rows(pb, zero_w)
    keep = np.flatnonzero(~zero_z)
    K = _vstack([A_eq, A_ub])[:, keep]
    rhs = np.concatenate([b_eq, b_ub])
    m_eq = b_eq.size
    bounds = [(-1.0, 1.0)] * m_eq + [(0.0, 1.0)] * b_ub.size
    # min rhs . (y, u) subject to K^T (y, u) >= 0
    options = None if limit is None else {"time_limit": limit}
    res = linprog(rhs, A_ub=-K.T, b_ub=np.zeros(K.shape[1]), bounds=bounds, method="highs",
                  options=options)
    if res.status != 0 or res.fun >= 0:
        return 0.0
    yu = res.x
    yu[m_eq:] = np.maximum(yu[m_eq:], 0.0)
    gap = -float(rhs @ yu)
    worst = max(0.0, -float(np.asarray(K.T @ yu).min(initial=0.0)))
    if gap <= 0:
        return 0.0
    return np.inf if worst == 0 else gap / worst
