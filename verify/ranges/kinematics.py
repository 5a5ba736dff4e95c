"""Which contact-state sets the velocities admit, decided combinatorially, and a short reason
when they do not (a cut for verify.ranges.milp's lazy search).

Every tangential velocity is v_t = +-x_i +- x_j in x = (r omega, V), r_i each disk's own radius
(verify.ranges.steady.velocity_box checks it), so the conditions of the states s (s v_t >= 1
sliding, v_t = 0 non-sliding; V as the formulation's V_mode) are unit two-variable inequalities
a_i x_i + a_j x_j <= b. Such a system is feasible iff its doubled constraint graph (a node for
+x_k and one for -x_k; the inequality is the edge from the node of -a_j x_j to that of a_i x_i
with weight b, and its mirror; a one-variable a x_i <= b is an edge of weight 2b) has no
negative cycle (the UTVPI/octagon closure), and then x_k = (d(+x_k) - d(-x_k)) / 2 solves it, d
the shortest-path distances from a source joined to every node by 0-weight edges. A negative
cycle names the contacts whose states cannot hold together: every valid steady state has
another state on at least one of them."""

from __future__ import annotations

import numpy as np

from .steady import Formulation, velocity_box


def _edges(form: Formulation, s: np.ndarray, only: np.ndarray | None = None,
           V_free: bool = False) -> list[tuple[int, int, float, int]]:
    """(from, to, weight, contact or -1) of the doubled graph; node 2k is +x_k, 2k+1 is -x_k
    (k = p for V). only: the contacts whose states are asked (mask; default all); V_free: no
    condition on V."""
    T_u, T_V, _ = velocity_box(form.dyn)
    T = np.column_stack([T_u, T_V])
    p = form.system.p
    out: list[tuple[int, int, float, int]] = []

    def node(k: int, sign: float) -> int:
        return 2 * k + (0 if sign > 0 else 1)

    def add(terms: list[tuple[int, float]], b: float, tag: int) -> None:
        if len(terms) == 1:
            (k, a), = terms
            out.append((node(k, -a), node(k, a), 2.0 * b, tag))
        else:
            (i, ai), (j, aj) = terms
            out.append((node(j, -aj), node(i, ai), b, tag))
            out.append((node(i, -ai), node(j, aj), b, tag))

    for al in form.fric:
        terms = [(int(k), float(T[al, k])) for k in np.flatnonzero(T[al])]
        if not terms or (only is not None and not only[al]):
            continue
        neg = [(k, -a) for k, a in terms]
        if s[al] > 0:  # v >= 1: -v <= -1
            add(neg, -1.0, int(al))
        elif s[al] < 0:  # v <= -1
            add(terms, -1.0, int(al))
        else:  # v = 0
            add(terms, 0.0, int(al))
            add(neg, 0.0, int(al))
    if V_free:
        pass
    elif form.V_mode == "zero":
        add([(p, 1.0)], 0.0, -1)
        add([(p, -1.0)], 0.0, -1)
    elif form.V_mode == "positive":
        add([(p, -1.0)], -1.0, -1)
    elif form.V_mode == "negative":
        add([(p, 1.0)], -1.0, -1)
    return out


def realizable(form: Formulation, s: np.ndarray, only: np.ndarray | None = None,
               V_free: bool = False) -> tuple[bool, np.ndarray | list[int]]:
    """(True, x = (r omega, V)) with the signs s, or (False, the contacts of a negative cycle:
    their states admit no velocities together). Bellman-Ford on the doubled graph. only (a
    mask of contacts) and V_free: ask the signs on those contacts only, V free (a negative
    cycle of the smaller system is one of the whole: its cut stays valid)."""
    n = 2 * (form.system.p + 1)
    edges = _edges(form, s, only, V_free)
    if not edges:
        return True, np.zeros(n // 2)
    src = np.array([e[0] for e in edges])
    dst = np.array([e[1] for e in edges])
    w = np.array([e[2] for e in edges])
    d = np.zeros(n)  # the source's 0-weight edges
    pred = -np.ones(n, dtype=int)  # edge index into each node
    changed = -1
    for _ in range(n + 1):
        cand = d[src] + w
        better = cand < d[dst] - 1e-12
        if not better.any():
            x = (d[0::2] - d[1::2]) / 2.0
            return True, x
        # relax the best candidate per destination (a valid Bellman-Ford step)
        order = np.flatnonzero(better)
        order = order[np.argsort(cand[order])[::-1]]  # the smallest written last
        d[dst[order]] = cand[order]
        pred[dst[order]] = order
        changed = int(dst[order[-1]])
    # a node relaxed in round n + 1 lies on or after a negative cycle of the predecessor
    # graph: walk back n steps, then around; checked (else: every contact, a no-good cut)
    everything = sorted(int(a) for a in form.fric)
    v = changed
    for _ in range(n):
        if pred[v] < 0:
            return False, everything
        v = int(src[pred[v]])
    cycle, u = [], v
    for _ in range(n + 1):
        e = int(pred[u])
        if e < 0:
            return False, everything
        cycle.append(e)
        u = int(src[e])
        if u == v:
            break
    if u != v or float(w[cycle].sum()) >= 0:
        return False, everything
    return False, sorted({edges[e][3] for e in cycle if edges[e][3] >= 0})
