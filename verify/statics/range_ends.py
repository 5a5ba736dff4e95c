"""The range ends of a set of contacts, one end after another (verify.statics.contact_ranges's
`ranges_of`): the order of the LPs, the ends settled without one, and the witnesses.

An end is settled, in this order of preference, by

1. a bound attained at a checked point (`Witnesses`): min R = 0 (R >= 0) when some checked
   point has R = 0, max S = mu max R (S <= mu R) or min S = -mu max R when one has
   S = +-mu max R, to 1e-9 of the force scale, as LP optima are;
2. a kept optimal basis (`Vertices`): among the optima met so far the one with the best value
   for this end is tested for it (verify.statics.ends.at_basis: one sparse LU, the same check
   as an LP's optimum); an optimum of one LP is often optimal for other ends too (a quarter of
   the LPs of a deposited pile);
3. its LP, warm-started from the last optimum (verify.statics.ends.settle, with its checks and
   retries); when no retry passes, the LP once more from the best kept optimum for this end
   (with the same checks; a warm "unbounded" whose ray fails its check has come from one
   start and not from another: n 13, seed 592, mu 1.078125); an end still unsettled is
   unknown: NaN.

The next LP is the end whose best known value the last optimum comes closest to (its regret:
value at the last optimum minus the best value at any checked point, relative to that value
or to the force scale), the nearest contact (by its first disk's centre) first on a tie: the
dual simplex then restarts near its optimum (about a third fewer pivots than contact after
contact on deposited piles, docs/packings.md). An S end waits for its contact's max R, so
that bound 1 can settle it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from .ends import Evidence, Unknown, at_basis, basis_of, settle
from .hull import ZERO
from .model import DualForceLP, ForceLP, StaticProblem


@dataclass
class Witnesses:
    """Per contact, over the checked points of P met so far: the smallest R (r_min), the
    largest and smallest S (s_max, s_min), whether |S| = mu R with R > 0 (seen), and the
    largest R (r_max; None: not kept, then taken from the first point added)."""

    r_min: np.ndarray
    s_max: np.ndarray
    s_min: np.ndarray
    seen: np.ndarray
    r_max: np.ndarray | None = None

    @classmethod
    def of(cls, prob: StaticProblem, lam: np.ndarray) -> Witnesses:
        c = prob.c
        return cls(lam[:c].copy(), lam[c:].copy(), lam[c:].copy(), at_bound(prob, lam),
                   lam[:c].copy())

    def add(self, prob: StaticProblem, lam: np.ndarray) -> None:
        c = prob.c
        self.seen |= at_bound(prob, lam)
        np.minimum(self.r_min, lam[:c], out=self.r_min)
        np.maximum(self.s_max, lam[c:], out=self.s_max)
        np.minimum(self.s_min, lam[c:], out=self.s_min)
        if self.r_max is None:
            self.r_max = lam[:c].copy()
        np.maximum(self.r_max, lam[:c], out=self.r_max)

    def merge(self, other: Witnesses) -> None:
        """Each entry is attained at some checked point, so the best of two is too."""
        self.seen |= other.seen
        np.minimum(self.r_min, other.r_min, out=self.r_min)
        np.maximum(self.s_max, other.s_max, out=self.s_max)
        np.minimum(self.s_min, other.s_min, out=self.s_min)
        if other.r_max is not None:
            if self.r_max is None:
                self.r_max = other.r_max.copy()
            np.maximum(self.r_max, other.r_max, out=self.r_max)

    def best(self, k: np.ndarray, sgn: np.ndarray) -> np.ndarray:
        """The best value of sgn lambda_k (min: sgn +1, max: -1) at the points met so far."""
        c = self.r_min.size
        r_max = self.r_max if self.r_max is not None else self.r_min
        lo = np.where(k < c, self.r_min[k % c], self.s_min[k % c])
        hi = np.where(k < c, r_max[k % c], self.s_max[k % c])
        return np.where(sgn > 0, lo, -hi)


def at_bound(prob: StaticProblem, lam: np.ndarray) -> np.ndarray:
    """Contacts at the Coulomb bound with R > 0 at a checked point of P (|S| >= mu R up to
    1e-9 of the contact's own R or the largest weight, R > ZERO x scale): witnesses that they
    can slide. (Up to 1e-9 of the largest force of the point, as before, a contact with
    mu R - |S| = 0.118 = 0.06 R counted as sliding beside forces of 2.8e8 weights, where
    that face of P is empty, proved exactly: n 13, seed 1, mu 0.99999; docs/packings.md.)"""
    c, mu = prob.c, prob.mu
    R, S = lam[:c], lam[c:]
    tol = 1e-9 * np.maximum(prob.scale, np.abs(R))
    return (mu > 0) & (R > ZERO * prob.scale) & (np.abs(S) >= mu * R - tol)


class Vertices:
    """Optimal bases met so far (their basic cone columns, as bit masks) and, per end
    (index k in [R; S], min or max), the one with the best value: tested by `ranges_of` before
    that end's LP. `tested`, `settled`: how many tests were made and how many settled an end."""

    def __init__(self, prob: StaticProblem, nw: int):
        self.nw, self.masks = nw, []
        self.best = np.full(2 * prob.n, np.inf)  # min lambda_k, then min -lambda_k
        self.arg = np.full(2 * prob.n, -1)
        self.last, self.tested, self.settled = -1, 0, 0

    def add(self, lam: np.ndarray, cols: np.ndarray | None) -> None:
        if cols is None:
            self.last = -1
            return
        mask = np.zeros(self.nw, dtype=bool)
        mask[cols] = True
        self.masks.append(np.packbits(mask))
        self.last = len(self.masks) - 1
        v = np.r_[lam, -lam]
        better = v < self.best
        self.best[better], self.arg[better] = v[better], self.last

    def candidate(self, k: int, sgn: float, last: bool = False) -> np.ndarray | None:
        """The basic columns of the best kept optimum for the end, unless there is none or,
        without `last`, it is the last one (the warm LP starts there anyway)."""
        j = self.arg[k if sgn > 0 else self.best.size // 2 + k]
        if j < 0 or (j == self.last and not last):
            return None
        return np.flatnonzero(np.unpackbits(self.masks[j], count=self.nw))


def ranges_of(prob: StaticProblem, lp: DualForceLP | ForceLP, implicit: list[str],
              contacts: np.ndarray, wit: Witnesses, step: Callable[[int], None] | None = None,
              unknown: list[Unknown] | None = None, retried: list[int] | None = None,
              vertices: Vertices | None = None, known: dict | None = None,
              record: Callable[[int, str, float], None] | None = None
              ) -> tuple[np.ndarray, np.ndarray, int, int]:
    """(lo, hi) of [R; S] at `contacts` (each (2 len(contacts),): R then S; NaN: unknown),
    LPs solved, ends reported unknown (their check failed after the retries; appended to
    `unknown` with their evidence, indices in P's [R; S]); wit is updated with every checked
    optimum; retried[0] counts the answers settled by a retry; vertices: the optimal bases
    kept (module docstring; a new store when None). step(n): called with the number of ends
    settled (by LP, kept basis or bound) as they are. known: {(k, "min" | "max"): value}
    ends settled before (a resumed run), settled first as they are; record(k, side, value):
    called for each end settled here (not the unknown ones)."""
    c, mu = prob.c, prob.mu
    contacts = np.asarray(contacts, dtype=int)
    m = contacts.size
    lo, hi = np.zeros(2 * m), np.zeros(2 * m)
    vertices = vertices if vertices is not None else Vertices(prob, _nw(lp))
    # ends e = q m + x, q: 0 max R, 1 min R, 2 max S, 3 min S of contact contacts[x]
    q = np.repeat(np.arange(4), m)
    x_of = np.tile(np.arange(m), 4)
    a_of = contacts[x_of]
    k_of = np.where(q < 2, a_of, c + a_of)
    sgn = np.where(q % 2 == 0, -1.0, 1.0)
    out = np.zeros(4 * m)  # the ends' values (0 where R = S = 0 or S = 0 on all of P)
    kinds = [implicit[a] for a in contacts]
    todo = np.zeros(4 * m, dtype=bool)
    for x, a in enumerate(contacts):
        if kinds[x] == "R=0":  # R = S = 0 on all of P
            if step:
                step(0)
            continue
        todo[[x, m + x]] = True
        todo[[2 * m + x, 3 * m + x]] = mu[a] > 0 and not kinds[x]
    lps = 0
    found: list[Unknown] = []
    tol = 1e-9 * prob.scale
    last_lam: np.ndarray | None = None
    last_x = 0
    lat = prob.system.lattice
    where = np.asarray(lat.x, dtype=float)[np.asarray(lat.i)[contacts]]  # the contacts' disks

    def settle_end(e: int, value: float) -> None:
        out[e] = value
        todo[e] = False
        if step:
            step(1)
        if record is not None and not np.isnan(value):
            record(int(k_of[e]), "max" if q[e] % 2 == 0 else "min", float(value))

    for e in np.flatnonzero(todo) if known else ():
        key = (int(k_of[e]), "max" if q[e] % 2 == 0 else "min")
        if key in known:
            out[e] = known[key]
            todo[e] = False
            if step:
                step(1)

    while True:
        # 1. bounds attained at checked points
        for x in np.flatnonzero(todo[m:2 * m] & (wit.r_min[contacts] <= ZERO * prob.scale)):
            settle_end(m + x, max(float(wit.r_min[contacts[x]]), 0.0))
        with np.errstate(invalid="ignore"):  # 0 x inf where mu = 0: not ready
            top = mu[contacts] * out[:m]  # mu max R where settled (todo[:m] False)
        ready = ~todo[:m] & np.isfinite(top)
        for x in np.flatnonzero(todo[2 * m:3 * m] & ready
                                & (wit.s_max[contacts] >= top - tol)):
            settle_end(2 * m + x, min(float(wit.s_max[contacts[x]]), float(top[x])))
        for x in np.flatnonzero(todo[3 * m:] & ready & (wit.s_min[contacts] <= -top + tol)):
            settle_end(3 * m + x, max(float(wit.s_min[contacts[x]]), -float(top[x])))
        # the next end: S ends once their max R is settled
        able = todo & ~((q >= 2) & np.tile(todo[:m], 4))
        cand = np.flatnonzero(able)
        if cand.size == 0:
            break
        if last_lam is None:
            e = int(cand[np.lexsort((q[cand], x_of[cand]))[0]])
        else:
            best = wit.best(k_of[cand], sgn[cand])
            now = sgn[cand] * last_lam[k_of[cand]]
            regret = (now - best) / np.maximum(np.abs(best), prob.scale)
            near = np.sum((where[x_of[cand]] - where[last_x]) ** 2, axis=1)
            e = int(cand[np.lexsort((near, regret))[0]])
        k, s = int(k_of[e]), float(sgn[e])
        cost = np.zeros(prob.n)
        cost[k] = s
        # 2. a kept optimal basis, 3. the LP
        cols = vertices.candidate(k, s)
        end = None
        if cols is not None:
            vertices.tested += 1
            end = at_basis(prob, lp, cols, cost)
            vertices.settled += end is not None
        if end is None:
            end = settle(prob, lp, cost)
            lps += end.lps
            best = vertices.candidate(k, s, last=True)
            if end.status == "unknown" and isinstance(lp, DualForceLP) and best is not None:
                lp.set_basis(best)  # no retry passed: the LP again, from another start
                again = settle(prob, lp, cost)
                lps += again.lps
                if again.status != "unknown":
                    own = again.how in ("warm", "basis")
                    end = replace(again, how="kept start" if own else again.how,
                                  first=end.first)
            if retried is not None:
                retried[0] += end.retried
            if end.status == "optimal" and end.how in ("warm", "basis", "kept start"):
                vertices.add(end.lam, basis_of(prob, lp))
                last_lam = end.lam
            else:
                vertices.add(end.lam, None)
                last_lam = None
        last_x = x_of[e]
        if end.status == "unbounded":
            settle_end(e, -s * np.inf)
        elif end.status == "unknown":
            found.append(Unknown(k, "min" if s > 0 else "max", end.evidence))
            settle_end(e, np.nan)
        else:
            wit.add(prob, end.lam)
            settle_end(e, float(end.lam[k]))
    hi[:m], lo[:m], hi[m:], lo[m:] = out[:m], out[m:2 * m], out[2 * m:3 * m], out[3 * m:]
    for x, a in enumerate(contacts):  # S = +- mu R on all of P
        if mu[a] > 0 and kinds[x] in ("S=+muR", "S=-muR"):
            sg = mu[a] if kinds[x] == "S=+muR" else -mu[a]
            lo[m + x], hi[m + x] = ((sg * lo[x], sg * hi[x]) if sg > 0 else
                                    (sg * hi[x], sg * lo[x]))
            for side, v in (("min", lo[m + x]), ("max", hi[m + x])):
                if np.isnan(v):  # S = +-mu R of an unknown end of R: unknown too
                    found.append(Unknown(c + int(a), side, Evidence(
                        "from R", np.nan, 0.0, "S = +-mu R of an unknown R end")))
    if unknown is not None:
        unknown.extend(found)
    return lo, hi, lps, len(found)


def spatial_order(prob: StaticProblem) -> np.ndarray:
    """The contacts in a serpentine over the pile (by their first disk's centre: bands two
    largest diameters high, left to right then right to left), so that a run of consecutive
    contacts is a patch of neighbours (the chunks of verify.statics.contact_ranges' workers;
    contact indices follow the kind and the deposition order, across the whole width)."""
    lat = prob.system.lattice
    where = np.asarray(lat.x, dtype=float)[np.asarray(lat.i, dtype=int)]
    if where.shape[0] == 0:
        return np.zeros(0, dtype=int)
    radii = np.asarray(lat.radii if lat.radii is not None else [lat.radius], dtype=float)
    band = np.floor((where[:, 1] - where[:, 1].min()) / (4.0 * float(radii.max()))).astype(int)
    along = np.where(band % 2 == 0, where[:, 0], -where[:, 0])
    return np.lexsort((along, band))


def _nw(lp: DualForceLP | ForceLP) -> int:
    return (lp.primal if isinstance(lp, DualForceLP) else lp).nw
