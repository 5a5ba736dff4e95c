"""Pivoting on contact states (issue 6; promoted to lcp by issue 12: method ``states`` of
lcp.states, and the sparse event engine's solver, models.engine.sparse).

`solve_states` is lcp.pivoting's iteration written on contact states (the paper's Sec. II C):
block principal pivoting on every violated state while their number drops (Judice & Pires),
else single flips (the most violated state first; Murty's least index after a cycle), the next
violated indices when a flip makes the active system singular, with a cycle test, a local
Lemke rescue and an iteration limit. Two safeguards of issue 13 for these non-P problems: a
block step opens at most one contact per connected cluster of contacts in tension
(`_one_per_component`), and (option `stall`, used by method ``states``) a run of steps without
a new least number of violations calls the local rescue instead of flipping on. Indices: the
normal state of contact alpha is alpha, its tangential state c + alpha. The sign tests and
their relative scales follow lcp.pivoting (see `violations`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .state_factor import NS, ActiveSystem, SingularSystem, StateFactor
from .state_rescue import EventLCP, local_rescue


@dataclass
class StateSolution:
    """The result of `solve_states`: forces, accelerations a = W lambda + q, the states."""

    R: np.ndarray
    S: np.ndarray
    a: np.ndarray
    normal: np.ndarray
    tang: np.ndarray
    status: str
    iterations: int
    residual: float  # max|min(z, w)| of the event LCP (z = [R, tau, a_minus])
    message: str = ""
    info: dict = field(default_factory=dict)


def violations(lam: np.ndarray, a: np.ndarray, asys: ActiveSystem, normal: np.ndarray,
               tang: np.ndarray, cand: np.ndarray, tol: float
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(indices, new tangential codes, sizes): violated inequalities, normal alpha as alpha
    and tangential alpha as c + alpha, in increasing order, and how much each is violated
    relative to its scale (the tests and scales follow lcp.pivoting: forces against
    max(|lambda|, |q| / |W|), accelerations against |q_i| + (|W| |lambda|)_i floored at 1e-4
    of its largest value)."""
    c, mu, W, q = asys.c, asys.mu, asys.W, asys.q
    R, S = lam[:c], lam[c:]
    wmax = float(np.abs(W.data).max(initial=0.0)) or 1.0
    fscale = max(float(np.abs(lam).max(initial=0.0)), float(np.abs(q).max(initial=0.0)) / wmax)
    ascale = np.abs(q) + asys.absW @ np.abs(lam)
    ascale = np.maximum(ascale, 1e-4 * float(ascale.max(initial=0.0)))
    an, at = a[:c], a[c:]
    bad_n = np.where(normal, R < -tol * fscale, an < -tol * ascale[:c])
    lo = S < -mu * R - tol * fscale
    hi = S > mu * R + tol * fscale
    new_t = tang.copy()
    bad_t = np.zeros(c, dtype=bool)
    is_ns = cand & (tang == NS)
    bad_t |= is_ns & (lo | hi)
    new_t[is_ns & lo] = 1
    new_t[is_ns & hi & ~lo] = -1
    plus = cand & (tang == 1) & (at < -tol * ascale[c:])
    minus = cand & (tang == -1) & (at > tol * ascale[c:])
    bad_t |= plus | minus
    new_t[plus | minus] = NS
    size_n = np.where(normal, -R / fscale, -an / ascale[:c])
    cone = np.maximum(-mu * R - S, S - mu * R) / fscale
    size_t = np.where(tang == NS, cone, np.abs(at) / ascale[c:])
    H = np.concatenate([np.flatnonzero(bad_n), c + np.flatnonzero(bad_t)])
    return H, new_t, np.concatenate([size_n, size_t])[H]


def lcp_residual(lam: np.ndarray, a: np.ndarray, mu: np.ndarray, tang: np.ndarray,
                 cand: np.ndarray) -> float:
    """max|min(z, w)| of the event LCP for z = [R, tau, a_minus] recovered from the states."""
    c = mu.size
    R, S, an, at = lam[:c], lam[c:], a[:c], a[c:]
    tau = (mu * R + S)[cand]
    a_minus = np.where(tang == -1, -at, 0.0)[cand]
    z = np.concatenate([R, tau, a_minus])
    w = np.concatenate([an, (at + np.where(tang == -1, -at, 0.0))[cand], 2 * mu[cand] *
                        R[cand] - tau])
    return float(np.max(np.abs(np.minimum(z, w)), initial=0.0))


def solve_states(factor: StateFactor, cand: np.ndarray, normal: np.ndarray, tang: np.ndarray,
                 *, tol: float = 1e-10, max_iter: int | None = None, block_tries: int = 3,
                 max_rescues: int = 8, single: str = "largest", stall: int = 0
                 ) -> StateSolution:
    """Pivot on contact states from (normal, tang) to a solution of the event LCP.

    cand: mask of the non-sliding candidates (their tangential state may change); the other
    contacts keep their code in `tang` (sliding sign, or 0 when frictionless). The factor is
    updated in place and keeps the final states (the warm start of the next event).

    A block step onto a singular system is retried on the first half, quarter, ... of the
    violated indices. Single flips take the most violated state first (single="largest"),
    which on these non-P problems needs far fewer steps than Murty's least index (at 20x20
    near the steady state: 232 instead of 3122 flips at the worst event); after a cycle the
    event continues with the least-index rule (single="least" from the start), whose
    finiteness on P-matrices is the textbook guarantee. When the iteration cycles (a state
    recurs) or no flip of a violated state gives a nonsingular system, a *local rescue*
    solves the event LCP restricted to the violated contacts and their neighbours (the other
    states fixed: their principal pivot transform, a dense LCP of a few hundred unknowns) by
    lexicographic Lemke, and the iteration resumes from its states; up to `max_rescues`
    times, on a growing neighbourhood.

    Safeguards (issue 13): the block step at a new least number of violations opens only the
    most violated contact of each connected cluster of T contacts with R < 0 (the other flips
    of H are all taken; "component_steps" when that cut H). With stall > 0, after `stall`
    steps without a new least number of violations the local rescue runs (up to
    `max_rescues` such "stall_rescues", besides the rescues above; a failed one lets the
    iteration go on): method ``states`` uses stall = STALL (the 2020-contact Siconos problem:
    27 instead of 153 iterations), the event engine does not (with stall = 10 the run of 20 x 20
    disks made 45 stall rescues near its steady state and took 684 s for 747 events, against
    6.4 s for the whole run without). Both only choose *which* states to flip: every
    "solved" is the same sign check, and Murty's least-index rule after a cycle still decides
    on P-matrices, so finiteness is kept (the record-improving steps are at most the initial
    number of violations, the stall rescues at most max_rescues).
    Status: "solved", "max_iter", or "failed"; info counts the steps of each kind and "flips",
    the state changes made by all of them.
    """
    asys = factor.sys
    c = asys.c
    max_iter = max(1000, 20 * c) if max_iter is None else max_iter
    info = {"block_steps": 0, "independent": 0, "partial_blocks": 0, "single_flips": 0,
            "fallback_flips": 0, "rescues": 0, "warm_start_rejected": 0,
            "component_steps": 0, "stall_rescues": 0, "flips": 0}
    try:
        factor.set_states(normal, tang)
    except SingularSystem:
        info["warm_start_rejected"] += 1  # keep the factor's (previous) states where allowed
        n2, t2 = factor.normal.copy(), factor.tang.copy()
        t2[~cand] = tang[~cand]
        t2[cand & ~np.isin(t2, (1, -1, NS))] = NS
        try:
            factor.set_states(n2, t2)
        except SingularSystem:
            factor.refactor(np.zeros(c, dtype=bool), np.where(cand, 1, tang).astype(np.int8))
    record, tries, it = np.inf, block_tries, 0
    since_record, stalls = 0, 0
    largest_first = single == "largest"
    seen: dict = {}
    fs0 = factor.stats["factorizations"]
    zform: EventLCP | None = None
    prev = (factor.normal.copy(), factor.tang.copy())
    while True:
        info["flips"] += int(np.count_nonzero(factor.normal != prev[0])
                             + np.count_nonzero(factor.tang != prev[1]))
        prev = (factor.normal.copy(), factor.tang.copy())
        if factor.worn:
            try:
                factor.refactor(factor.normal, factor.tang)
            except SingularSystem:
                pass
        lam = factor.solve_current()
        a = asys.W @ lam + asys.q
        H, new_t, size = violations(lam, a, asys, factor.normal, factor.tang, cand, tol)
        info["factorizations"] = factor.stats["factorizations"] - fs0
        out = (factor, lam, a, cand, it, info)
        if H.size == 0:
            return _result(*out, "solved")
        if it >= max_iter:
            return _result(*out, "max_iter", f"{H.size} inequalities still fail after {it} "
                           "changes")
        key = (factor.normal.tobytes(), factor.tang.tobytes(), record, tries)
        stuck = key in seen
        seen[key] = it
        it += 1
        if stuck and largest_first:  # a cycle: Murty's least-index rule from here on
            largest_first, seen, stuck = False, {key: it}, False
        since_record += 1
        if not stuck and stall and since_record > stall and stalls < max_rescues:
            since_record, stalls = 0, stalls + 1  # no new record for `stall` steps
            if zform is None:
                zform = EventLCP(asys, factor.tang, cand)
            info["stall_rescues"] += 1
            if local_rescue(factor, zform, H, min_contacts=24 * 2 ** stalls, radius=1 + stalls):
                record, tries, seen = np.inf, block_tries, {}
                continue
        if not stuck:
            if H.size < record:
                record, tries, since_record = H.size, block_tries, 0
                Hb = _one_per_component(H, size, c, factor.normal, asys.adjacency) \
                    if COMPONENTS else H
                if _block_step(factor, new_t, Hb, c, info,
                               "block_steps" if Hb.size == H.size else "component_steps"):
                    continue
                tries = 0
            elif tries > 0 and INDEPENDENT:
                tries -= 1
                Hi = _independent(H, c, asys.adjacency)
                if Hi.size > 1 and _block_step(factor, new_t, Hi, c, info, "independent"):
                    continue
            elif tries > 0:
                tries -= 1
                if _block_step(factor, new_t, H, c, info):
                    continue
                tries = 0
            order = H[np.argsort(-size, kind="stable")] if largest_first else H
            if _single_flip(factor, new_t, order, c, info):
                continue
        # a cycle, or no usable flip: the local rescue
        if info["rescues"] >= max_rescues:
            why = "the pivoting cycles" if stuck else "no flip gives a nonsingular system"
            return _result(*out, "failed", f"{why}; {info['rescues']} local rescues did not "
                           f"help ({H.size} violated states)")
        if zform is None:
            zform = EventLCP(asys, factor.tang, cand)
        grow = 2 ** info["rescues"]
        info["rescues"] += 1
        if local_rescue(factor, zform, H, min_contacts=24 * grow, radius=1 + info["rescues"]):
            record, tries, seen = np.inf, block_tries, {}


INDEPENDENT = True
#: Block steps open at most one contact per connected component of the contacts to open.
COMPONENTS = True
#: lcp.states' `stall`: a local rescue after this many steps without a new least number of
#: violations. The sparse event engine keeps stall = 0 (see solve_states).
STALL = 10


def _one_per_component(H: np.ndarray, size: np.ndarray, c: int, normal: np.ndarray,
                       adjacency: sp.csr_matrix) -> np.ndarray:
    """H (in its order) with its opening flips (T contacts with R < 0) cut to the most
    violated one per connected component of those contacts in the contact graph; ties go to
    the first in H. A hyperstatic cluster of closed contacts (a row of disks between two walls)
    carries an indeterminate self-stress; with every contact closed that self-stress shows up
    as tension on a whole connected stretch, and opening its most stretched contact releases
    it, where opening every contact in tension cuts the cluster into pieces that the next steps
    must close again (at 100 x 100 disks: 1813 contacts opened where 100 open in the
    solution)."""
    from scipy.sparse.csgraph import connected_components
    opening = (H < c) & normal[np.minimum(H, c - 1)]
    if opening.sum() < 2:
        return H
    idx = H[opening]
    ncomp, lab = connected_components(adjacency[idx][:, idx], directed=False)
    if ncomp == idx.size:
        return H
    order = np.lexsort((np.arange(idx.size), -size[opening], lab))  # most violated first
    first = np.ones(idx.size, dtype=bool)
    first[1:] = lab[order][1:] != lab[order][:-1]
    keep = np.zeros(idx.size, dtype=bool)
    keep[order[first]] = True
    mask = ~opening
    mask[np.flatnonzero(opening)[keep]] = True
    return H[mask]


def _independent(H: np.ndarray, c: int, adjacency: sp.csr_matrix) -> np.ndarray:
    """A subset of H whose contacts are pairwise not adjacent (greedy, least index first):
    flips that barely interact, each close to a single principal pivot."""
    taken = np.zeros(c, dtype=bool)
    blocked = np.zeros(c, dtype=bool)
    keep = []
    for pos, h in enumerate(H.tolist()):
        a = h % c
        if taken[a]:
            keep.append(pos)  # both states of one contact
            continue
        if blocked[a]:
            continue
        taken[a] = True
        blocked[adjacency.indices[adjacency.indptr[a]:adjacency.indptr[a + 1]]] = True
        keep.append(pos)
    return H[keep]


def _block_step(factor: StateFactor, new_t, H, c, info, kind: str = "block_steps") -> bool:
    """Flip all of H; when that system is singular, the first half, quarter, ... of H."""
    size = H.size
    while size >= 2 or size == H.size:
        n2, t2 = _flip(factor.normal, factor.tang, new_t, H[:size], c)
        try:
            factor.set_states(n2, t2)
        except SingularSystem:
            size //= 2
            if size < 2:
                return False
            continue
        info[kind if size == H.size else "partial_blocks"] += 1
        return True
    return False


def _single_flip(factor: StateFactor, new_t, H, c, info) -> bool:
    """Murty's least index; the next violated indices when a flip is singular."""
    for pos in range(H.size):
        n2, t2 = _flip(factor.normal, factor.tang, new_t, H[pos:pos + 1], c)
        try:
            factor.set_states(n2, t2)
        except SingularSystem:
            continue
        info["single_flips" if pos == 0 else "fallback_flips"] += 1
        return True
    return False


def _result(factor, lam, a, cand, it, info, status, message="") -> StateSolution:
    c = factor.sys.c
    return StateSolution(lam[:c].copy(), lam[c:].copy(), a, factor.normal.copy(),
                         factor.tang.copy(), status, it,
                         lcp_residual(lam, a, factor.sys.mu, factor.tang, cand), message, info)


def _flip(normal, tang, new_t, H, c):
    n2, t2 = normal.copy(), tang.copy()
    hn = H[H < c]
    n2[hn] = ~n2[hn]
    ht = H[H >= c] - c
    t2[ht] = new_t[ht]
    return n2, t2
