"""Tried and dropped (docs/benchmarks.md, "The order of the angular accelerations"): a proved
bound of an observable of the forces over the valid steady states by a best-first branch and
bound on the *order* of the disks' angular accelerations (`order_split_bound`), against
verify.ranges.disk_split at the same number of cases on Fig. 9's two open ends:

    python benchmarks/order_split.py [--cases N] [--ends mu_g,alpha9]

It is a script, not part of the library: at equal numbers of LPs its bounds are those of the
disk split (within a few per cent either way), so it closes nothing the disk split does not.
tests/verify/ranges/test_order_split.py checks that its bounds are bounds (they reach the
MILP's ends on small systems and never pass them).

Setting as in verify.ranges.disk_split: with no translation a_t = T_u ra + b on the frictional
contacts (ra = r alpha; a two-disk row -(ra_i + ra_j) times a sign eps, b = 0 there; a one-disk
row eps ra_i + b), and |ra_i| <= M* on every valid steady state (the rotation cap). On every
valid steady state each frictional contact satisfies

    a_t > 0  =>  S = -mu R,      a_t < 0  =>  S = +mu R                         (*)

Order. When the two-disk contacts 2-colour the disks (sigma_i = +-1, sigma_j = -sigma_i on
every two-disk contact: the rectangular lattices), w_i = sigma_i ra_i turns every a_t into a
difference: a two-disk contact has a_t = eps (sigma_i ra_i... ) = eps sigma_i (w_i - w_j), a
one-disk contact a_t = eps sigma_i (w_i - k) with the constant k = -b / (eps sigma_i). So the
sign of every a_t is the *order* of two nodes of a graph whose nodes are the disks' w and the
constants k (with BOT = -M* <= w_i <= TOP = +M*, the cap; on Fig. 9's system the plane's k is
-+M*). A case is a set of relations u < v, u = v between nodes; it holds the valid steady
states whose w satisfy them. Its transitive closure (u < v, v = x => u < x; u <= v <= u => u =
v; a relation u < u: the case is empty, with no LP) fixes the sign of every contact whose two
nodes are ordered in it, possibly through other nodes (a path u < x < y < v orders the
contact u-v: several contacts fixed at once), where verify.ranges.disk_split fixes a contact
only from its own disks' cap states.

Each case is disk_split's linear program (`disk_split._Cases`: the relaxation P over the
proved force box, the power cut) with (*) imposed on the contacts ordered strictly (S = -+mu R
and a_t of that sign, its closure a_t >= 0 or <= 0), a_t = 0 on those with equal nodes, a_t
>= 0 or <= 0 (no S) on those ordered only weakly, and each disk's cap state read off its
order with BOT and TOP. Its minimum is bounded by the certified Lagrangian bound
(verify.ranges.milp.certified_result); an empty case is closed by a checked Farkas ray, or
by a contradiction of its relations (u < u after the closure). A case is split on the
frictional contact of largest violation of (*) at its LP point whose order is still open,
into its three orders (u < v, u = v, u > v; two when u <= v is known): the children cover the
parent. The least bound over the cases left open (and those closed) is a lower bound over
every valid steady state, whatever the time limit; the time limit is CPU time
(time.process_time), so that a result does not depend on the machine's load.
"""

from __future__ import annotations

import argparse
import heapq
import os
import time
from dataclasses import dataclass, field

import numpy as np

from rigidlcp.verify.ranges.bounds import rotation_cap
from rigidlcp.verify.ranges.disk_split import DOWN, INSIDE, NOTDOWN, NOTUP, OPEN, UP, _Cases
from rigidlcp.verify.ranges.seeds import two_colouring
from rigidlcp.verify.ranges.steady import Formulation, velocity_box


@dataclass
class OrderSplitBound:
    """As disk_split.DiskSplitBound: bound (proved lower bound of cost . x over every valid
    steady state), closed (every case closed at target), cases (LPs solved), open (cases
    left), empty (cases proved empty: `contradictions` of them by their relations alone),
    seconds (CPU), candidate (an LP point satisfying (*), or None)."""

    bound: float
    closed: bool
    cases: int
    open: int
    empty: int
    contradictions: int
    seconds: float
    candidate: np.ndarray | None = field(default=None, repr=False)
    implied: int = 0  # contacts ordered by the closure beyond the relations branched on,
    # summed over the cases solved


@dataclass
class OrderGraph:
    """Nodes 0..p-1 the disks' w_i = sigma_i ra_i, then BOT (-M*), TOP (+M*) and the other
    constants; per frictional contact k (index into the frictional contacts) its nodes
    (u[k], v[k]) and sign o[k]: a_t = o[k] M*-free form o (w_u - w_v)."""

    sigma: np.ndarray
    value: np.ndarray  # per constant node (index n - p): its value (units of ra)
    u: np.ndarray
    v: np.ndarray
    o: np.ndarray
    p: int

    @property
    def n(self) -> int:
        return self.p + self.value.size


def order_graph(form: Formulation, M: float) -> OrderGraph | None:
    """The graph of the module docstring, or None when the two-disk contacts do not 2-colour
    the disks or a row is not of the form it needs."""
    system, dyn = form.system, form.dyn
    c, p = system.c, system.p
    fr = np.flatnonzero(system.mu > 0)
    T_u, _, _ = velocity_box(dyn)
    b = np.asarray(dyn.u_obs_dot, float)[c:]
    adj: list[list[int]] = [[] for _ in range(p)]
    for a in fr:
        nz = np.flatnonzero(T_u[a])
        if nz.size == 2:
            if T_u[a, nz[0]] != T_u[a, nz[1]] or b[a] != 0:
                return None
            adj[nz[0]].append(int(nz[1]))
            adj[nz[1]].append(int(nz[0]))
        elif nz.size != 1:
            return None
    sigma = two_colouring(adj)
    if sigma is None:
        return None
    sigma = sigma.astype(int)
    consts = [-M, M]
    u, v, o = [], [], []
    for a in fr:
        nz = np.flatnonzero(T_u[a])
        i = int(nz[0])
        eps = float(T_u[a, i])
        if nz.size == 2:  # a_t = eps (sigma_i w_i + sigma_j w_j) = eps sigma_i (w_i - w_j)
            u.append(i)
            v.append(int(nz[1]))
        else:  # a_t = eps sigma_i (w_i - k), k = -b / (eps sigma_i)
            k = -b[a] / (eps * sigma[i])
            if abs(k) > M * (1 + 1e-12):
                k = float(np.sign(k)) * 2 * M  # never reached by w: a constant beyond the cap
            hit = [m for m, x in enumerate(consts) if abs(x - k) <= 1e-12 * M]
            if not hit:
                consts.append(float(k))
                hit = [len(consts) - 1]
            u.append(i)
            v.append(p + hit[0])
        o.append(int(np.sign(eps * sigma[i])))
    return OrderGraph(sigma, np.array(consts), np.array(u), np.array(v), np.array(o), p)


def initial_relations(g: OrderGraph) -> tuple[np.ndarray, np.ndarray]:
    """(le, lt) boolean n x n: u <= v, u < v known for every case (the cap BOT <= w <= TOP,
    the constants' own order)."""
    n, p = g.n, g.p
    le = np.eye(n, dtype=bool)
    lt = np.zeros((n, n), dtype=bool)
    BOT, TOP = p, p + 1
    le[BOT, :p] = le[:p, TOP] = True
    for a in range(p, n):
        for b_ in range(p, n):
            x, y = g.value[a - p], g.value[b_ - p]
            le[a, b_] |= x <= y
            lt[a, b_] |= x < y
    return closure(le, lt)


def closure(le: np.ndarray, lt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The transitive closure of the relations: le the reflexive-transitive closure of le | lt,
    lt = le . lt . le (a chain with one strict step is strict)."""
    le = le | lt
    while True:
        nxt = le | ((le.astype(np.uint8) @ le.astype(np.uint8)) > 0)
        if np.array_equal(nxt, le):
            break
        le = nxt
    li = le.astype(np.uint8)
    lt = (li @ ((lt.astype(np.uint8) @ li) > 0).astype(np.uint8)) > 0
    return le, lt


def case_of(g: OrderGraph, le: np.ndarray, lt: np.ndarray
            ) -> tuple[np.ndarray, dict[int, int], dict[int, int]] | None:
    """(disks' cap states, contacts with a_t's sign fixed {k: 1, -1, 0}, contacts with a_t's
    sign bounded only {k: 1 (a_t >= 0), -1 (a_t <= 0)}) of the relations, or None when they
    contradict (u < u)."""
    if np.any(np.diag(lt)):
        return None
    p = g.p
    BOT, TOP = p, p + 1
    disks = np.full(p, OPEN)
    for i in range(p):
        lo_node, hi_node = (BOT, TOP) if g.sigma[i] > 0 else (TOP, BOT)  # ra = -M*, +M*
        at_lo = le[i, lo_node] and le[lo_node, i]
        at_hi = le[i, hi_node] and le[hi_node, i]
        off_lo = lt[BOT, i] if lo_node == BOT else lt[i, TOP]
        off_hi = lt[BOT, i] if hi_node == BOT else lt[i, TOP]
        if at_lo:
            disks[i] = DOWN
        elif at_hi:
            disks[i] = UP
        elif off_lo and off_hi:
            disks[i] = INSIDE
        elif off_lo:
            disks[i] = NOTDOWN
        elif off_hi:
            disks[i] = NOTUP
    fixed, weak = {}, {}
    for k in range(g.u.size):
        u, v, o = int(g.u[k]), int(g.v[k]), int(g.o[k])
        if lt[v, u]:
            fixed[k] = o
        elif lt[u, v]:
            fixed[k] = -o
        elif le[u, v] and le[v, u]:
            fixed[k] = 0
        elif le[v, u]:
            weak[k] = o
        elif le[u, v]:
            weak[k] = -o
    return disks, fixed, weak


def solve_case(cases: _Cases, disks: np.ndarray, fixed: dict[int, int], weak: dict[int, int]
               ) -> tuple[float, np.ndarray | None]:
    """(certified lower bound, LP point) of the case: disk_split's LP with the contacts of
    `fixed` (their sign of a_t and (*)) and the a_t bounds of `weak`."""
    lo, hi = cases.bounds(disks, fixed)
    for k, s in weak.items():
        if s > 0:
            lo[cases.r_a + k] = max(lo[cases.r_a + k], -cases.q[k])
        else:
            hi[cases.r_a + k] = min(hi[cases.r_a + k], -cases.q[k])
    return cases.solve_with(disks, lo, hi)


def order_split_bound(form: Formulation, cost: np.ndarray, target: float, time_limit: float,
                      tol: float = 1e-9, max_cases: int | None = None
                      ) -> OrderSplitBound | None:
    """A proved lower bound of cost . x (x = [R; S]) over every valid steady state (module
    docstring), splitting until every case is bounded at >= target - tol, `time_limit` CPU
    seconds or max_cases LPs; None where it does not apply (no proved force box for cost, no
    rotation cap, contacts that do not 2-colour the disks)."""
    c0 = time.process_time()
    system, dyn = form.system, form.dyn
    M = rotation_cap(system, dyn)
    if M is None or M <= 0 or form.R_hi is None or not form.proved_for(cost):
        return None
    g = order_graph(form, M)
    if g is None:
        return None
    cases = _Cases(form, cost, M)
    goal = target - tol * max(1.0, abs(target))
    heap: list = []
    tick = n_cases = empty = contra = implied = 0
    closed_min, candidate = np.inf, None

    def push(le, lt, parent_bound, depth=0):
        nonlocal tick, n_cases, empty, contra, closed_min, implied
        le, lt = closure(le, lt)
        case = case_of(g, le, lt)
        if case is None:
            empty += 1
            contra += 1
            return
        b, x = solve_case(cases, *case)
        n_cases += 1
        implied += max(len(case[1]) - depth, 0)
        if b == np.inf:
            empty += 1
            return
        b = max(b, parent_bound)
        if b >= goal:
            closed_min = min(closed_min, b)
            return
        tick += 1
        heapq.heappush(heap, (b, tick, le, lt, case[1], x, depth))

    push(*initial_relations(g), -np.inf)
    while heap and time.process_time() - c0 < time_limit and (
            max_cases is None or n_cases < max_cases):
        b, tk, le, lt, fixed, x, depth = heapq.heappop(heap)
        v = None if x is None else cases.violation(x)
        k = None
        if v is not None:
            for kk in np.argsort(-v):
                if v[kk] <= 0:
                    break
                if int(kk) not in fixed:
                    k = int(kk)
                    break
        if k is None:  # no point, or (*) holds at it: the case stays open
            if x is not None and not np.any(v > 0):
                candidate = x
            heapq.heappush(heap, (b, tk, le, lt, fixed, None, depth))
            break
        u, w = int(g.u[k]), int(g.v[k])
        kids = []
        if not le[w, u]:  # u < w possible
            kids.append((u, w, True))
        kids.append(None)  # u = w
        if not le[u, w]:
            kids.append((w, u, True))
        for kid in kids:
            le2, lt2 = le.copy(), lt.copy()
            if kid is None:
                le2[u, w] = le2[w, u] = True
            else:
                lt2[kid[0], kid[1]] = True
            push(le2, lt2, b, depth + 1)
    bound = min([e[0] for e in heap] + [closed_min])
    return OrderSplitBound(float(bound), not heap, n_cases, len(heap), empty, contra,
                           time.process_time() - c0, candidate, implied)


def main() -> int:
    from rigidlcp import models
    from rigidlcp.verify.ranges.disk_split import disk_split_bound
    from rigidlcp.verify.ranges.observables import alpha_rows, mu_g_vector
    from rigidlcp.verify.ranges.steady import formulate

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=1500, help="LPs per search")
    ap.add_argument("--ends", default="mu_g,alpha9", help="min mu_g and/or max alpha_9")
    args = ap.parse_args()
    system = models.System(models.rectangular(10, 4), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.16)
    form = formulate(system)
    # each end as min cost . x, with the best value met (a valid state: no bound passes it)
    ends = {"mu_g": (mu_g_vector(system), 0.1050919108),
            "alpha9": (-alpha_rows(system, form.dyn)[9], -0.1534752959)}
    print(f"Fig. 9, {args.cases} cases per search; load {os.getloadavg()[0]:.2f}")
    print("| end | search | proved bound | open | empty | CPU s |")
    print("|---|---|---|---|---|---|")
    for name in args.ends.split(","):
        L, target = ends[name]
        sense = 1.0 if name == "mu_g" else -1.0
        for label, f in (("order", order_split_bound), ("disk split", disk_split_bound)):
            c0 = time.process_time()
            res = f(form, L, target, 1e9, max_cases=args.cases)
            cpu = time.process_time() - c0
            extra = (f" ({res.implied} contacts ordered by the closure, "
                     f"{res.contradictions} cases empty by it)" if label == "order" else "")
            print(f"| {'min mu_g' if sense > 0 else 'max alpha_9'} | {label}{extra} | "
                  f"{sense * res.bound:.7f} | {res.open} | {res.empty} | {cpu:.1f} |")
    print(f"load {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
