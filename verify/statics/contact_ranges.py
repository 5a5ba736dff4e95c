"""The range [min, max] of every R and S over P and the contacts that can slide (the LPs of
verify.statics.forceset's `analyse`), in this process or split over worker processes.

Each end is the optimum of a range LP (DualForceLP: dual simplex on its dual, warm-started from
the previous optimum) checked to lie in P and certified by the dual's optimum y (weak duality,
`DualForceLP.certified`; an infinite end by HiGHS's primal ray of ForceLP,
`ForceLP.ray_checked`); an answer failing its check is retried (its basis solved again, then
a cold LP: verify.statics.ends) and, when no retry passes, the end is unknown: NaN in lo / hi,
listed with the evidence in `unknown`, never a number nor +-inf. Or the end needs no LP
(verify.statics.range_ends, which also orders the LPs): a bound that holds on all of P and is
attained at a checked point of P (min R = 0 when some checked point has R = 0, max S = mu max R
or min S = -mu max R when one has S = +-mu max R; witness values within 1e-9 of the force
scale of the bound, as LP optima are), or an optimal basis kept from an earlier LP that is
optimal for this end too, with the same check as an LP's optimum.

With jobs > 1 the contacts are cut into chunks solved by `jobs` worker processes, each holding
its own LPs of P warm from chunk to chunk; the witnesses found so far (by every worker)
travel with each chunk, so the filtering above works across workers. The LPs are the same
LPs with the same checks: the ends agree with jobs = 1 to the LPs' tolerance (tested).
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, field

import numpy as np

from rigidlcp import models
from rigidlcp.lcp.errors import InvalidInput

from .ends import Unknown, settle
from .hull import ZERO
from .model import DualForceLP, ForceLP, StaticProblem
from .range_ends import Vertices, Witnesses, at_bound, ranges_of, spatial_order

__all__ = ["Ranges", "Vertices", "Witnesses", "at_bound", "contact_ranges", "end_count",
           "ranges_of", "sliding_of"]


@dataclass
class Ranges:
    """lo, hi: (2c,) ranges of [R; S] (+-inf unbounded, NaN unknown); sliding (c,);
    sliding_unknown (c,): whether the sliding verdict rests on an LP whose check failed (then
    sliding is False there, but unknown); lps solved; unchecked: ends and sliding verdicts
    reported unknown (none expected); unknown: their ends with the evidence; retried: LP
    answers that failed their check and were settled by a retry (verify.statics.ends)."""

    lo: np.ndarray
    hi: np.ndarray
    sliding: np.ndarray
    lps: int = 0
    unchecked: int = 0
    unknown: list[Unknown] = field(default_factory=list)
    sliding_unknown: np.ndarray | None = None
    retried: int = 0


def end_count(prob: StaticProblem, implicit: list[str]) -> int:
    """The range ends `contact_ranges` settles, the progress total: each end counted once
    whether an LP, a kept basis or a bound attained at a checked point settled it
    (verify.statics.range_ends), so the count reaches it exactly; the LPs run are fewer
    (Ranges.lps, which also counts the sliding LPs)."""
    todo = [a for a in range(prob.c) if implicit[a] != "R=0"]
    return 2 * len(todo) + 2 * sum(1 for a in todo if prob.mu[a] > 0 and not implicit[a])


def sliding_of(prob: StaticProblem, lp: ForceLP, implicit: list[str], hi_R: np.ndarray,
               seen: np.ndarray, contacts: np.ndarray, unsure: list[int] | None = None,
               retried: list[int] | None = None) -> tuple[np.ndarray, int, int]:
    """Whether S = +-mu R with R > 0 is attainable at each of `contacts` (forceset's
    docstring), the LPs solved and the verdicts left unknown (a "no" rests on checked LP
    answers: optima in P certified by their duals on the face, or checked rays, or HiGHS's
    "infeasible" for the face with a checked Farkas certificate, verify.statics.ends; when an
    answer fails its check after the retries of verify.statics.ends, and no other answer
    says "yes", the contact is appended to `unsure` and its verdict is False there, but
    unknown); hi_R: (c,) max R (NaN: unknown); seen: (c,) contacts already found at the
    bound at a checked optimum (no LP needed); retried[0] counts the answers settled by a
    retry."""
    k = prob.fric.size
    row_of = {int(a): n for n, a in enumerate(prob.fric)}
    out = np.array([bool(seen[a]) for a in contacts], dtype=bool)
    lps = 0
    found: list[int] = []
    for x, a in enumerate(contacts):
        kind = implicit[a]
        if prob.mu[a] <= 0 or kind == "R=0" or out[x]:
            continue
        if kind:
            out[x] = hi_R[a] > ZERO * prob.scale
            if np.isnan(hi_R[a]):
                found.append(int(a))
            continue
        n = row_of[int(a)]
        doubt = False
        for row in (n, k + n):
            col = lp.set_cone_row(row, True)
            e = np.zeros(prob.n)
            e[a] = -1.0

            def cold(row: int = row) -> ForceLP:
                fresh = ForceLP(prob)
                fresh.set_cone_row(row, True)
                return fresh

            end = settle(prob, lp, e, fixed=(col,), cold=cold, as_is=("infeasible",))
            lps += end.lps
            if retried is not None:
                retried[0] += end.retried
            lp.set_cone_row(row, False)
            doubt |= end.status == "unknown"
            if end.status == "unbounded" or (end.status == "optimal"
                                             and end.lam[a] > ZERO * prob.scale):
                out[x] = True
                break
        if doubt and not out[x]:
            found.append(int(a))
    if unsure is not None:
        unsure.extend(found)
    return out, lps, len(found)


def contact_ranges(prob: StaticProblem, lp: ForceLP | None, implicit: list[str],
                   witness: np.ndarray,
                   progress: Callable[[int, int, str], None] | None = None,
                   jobs: int = 1, known: dict | None = None,
                   record: Callable[[int, str, float], None] | None = None) -> Ranges:
    """The ranges of every R and S and the sliding contacts (module docstring). witness: a
    checked point of P; lp: a ForceLP of P (built here if None; unused when jobs > 1);
    progress(done, total, "ranges") as the ends are settled (by any means: `end_count`).
    known: {(k, "min" | "max"): value} ends of [R; S] settled by an earlier run on the same P
    (each a checked end then), taken as they are (a resumed `rigidlcp forceset --out`);
    record(k, side, value): called for every end settled here but an unknown one."""
    check_jobs(jobs)
    c = prob.c
    total, done = end_count(prob, implicit), 0

    def step(ends: int) -> None:
        nonlocal done
        done += ends
        if progress:
            progress(done, total, "ranges")

    wit = Witnesses.of(prob, witness)
    if jobs > 1 and c > 1:
        return _in_workers(prob, implicit, wit, step, jobs, known or {}, record)
    lp = lp or ForceLP(prob)
    every = np.arange(c)
    unknown: list[Unknown] = []
    unsure: list[int] = []
    retried = [0]
    lo, hi, lps, unchecked = ranges_of(prob, DualForceLP(prob, lp), implicit, every, wit, step,
                                       unknown, retried, known=known, record=record)
    sliding, more, bad = sliding_of(prob, lp, implicit, hi[:c], wit.seen, every, unsure,
                                    retried)
    return Ranges(lo, hi, sliding, lps + more, unchecked + bad, unknown,
                  _mask(c, unsure), retried[0])


def _mask(c: int, unsure: list[int]) -> np.ndarray:
    out = np.zeros(c, dtype=bool)
    out[np.asarray(unsure, dtype=int)] = True
    return out


def check_jobs(jobs: int) -> None:
    """Refuse a number of worker processes that is not an integer >= 1 (InvalidInput)."""
    if isinstance(jobs, bool) or not isinstance(jobs, (int, np.integer)) or jobs < 1:
        raise InvalidInput(f"jobs must be an integer >= 1, got {jobs!r}")


_WORKER: dict = {}


def _start(system: models.System) -> None:
    """A worker's P and its ForceLP, solved once so that every chunk starts warm."""
    prob = StaticProblem(system)
    lp = ForceLP(prob)
    lp.solve(np.zeros(prob.n))
    dual = DualForceLP(prob, lp)
    dual.solve(np.zeros(prob.n))
    _WORKER.update(prob=prob, lp=lp, dual=dual, vertices=Vertices(prob, lp.nw))


def _range_chunk(task):
    implicit, contacts, wit, known = task
    unknown: list[Unknown] = []
    retried = [0]
    lo, hi, lps, unchecked = ranges_of(_WORKER["prob"], _WORKER["dual"], implicit, contacts,
                                       wit, None, unknown, retried, _WORKER["vertices"],
                                       known=known)
    return contacts, lo, hi, lps, unchecked, wit, unknown, retried[0]


def _sliding_chunk(task):
    implicit, contacts, hi_R, seen = task
    unsure: list[int] = []
    retried = [0]
    out = sliding_of(_WORKER["prob"], _WORKER["lp"], implicit, hi_R, seen, contacts, unsure,
                     retried)
    return contacts, *out, unsure, retried[0]


def _in_workers(prob: StaticProblem, implicit: list[str], wit: Witnesses, step,
                jobs: int, known: dict, record) -> Ranges:
    c = prob.c
    lo, hi = np.zeros(prob.n), np.zeros(prob.n)
    sliding = np.zeros(c, dtype=bool)
    out = Ranges(lo, hi, sliding, sliding_unknown=np.zeros(c, dtype=bool))
    size = max(1, min(64, c // (8 * jobs)))  # small chunks: balance, and fresh witnesses
    order = spatial_order(prob)  # neighbours in a chunk: their optima settle or start others
    chunks = [order[s:s + size] for s in range(0, c, size)]
    # spawn: fresh interpreters, no inherited threads or locks (HiGHS, BLAS) from this one
    with ProcessPoolExecutor(max_workers=min(jobs, len(chunks)), initializer=_start,
                             initargs=(prob.system,),
                             mp_context=multiprocessing.get_context("spawn")) as pool:

        def run(fn, make, merge) -> None:
            queue, pending = list(chunks), set()
            while queue or pending:
                while queue and len(pending) < 2 * jobs:
                    pending.add(pool.submit(fn, make(queue.pop(0))))
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                for fut in finished:
                    merge(fut.result())

        def merge_ranges(res) -> None:
            contacts, lo_x, hi_x, lps, unchecked, w, unknown, retried = res
            m = len(contacts)
            lo[contacts], hi[contacts] = lo_x[:m], hi_x[:m]
            lo[c + contacts], hi[c + contacts] = lo_x[m:], hi_x[m:]
            out.lps += lps
            out.unchecked += unchecked
            out.unknown.extend(unknown)
            out.retried += retried
            wit.merge(w)
            if record is not None:
                _record_chunk(record, c, contacts, lo_x, hi_x)
            step(int(sum(2 + 2 * (prob.mu[a] > 0 and not implicit[a])
                         for a in contacts if implicit[a] != "R=0")))

        def merge_sliding(res) -> None:
            contacts, s, lps, unchecked, unsure, retried = res
            sliding[contacts] = s
            out.sliding_unknown[unsure] = True
            out.lps += lps
            out.unchecked += unchecked
            out.retried += retried

        run(_range_chunk, lambda ch: (implicit, ch, wit, _known_of(known, c, ch)),
            merge_ranges)
        run(_sliding_chunk, lambda ch: (implicit, ch, hi[:c], wit.seen), merge_sliding)
    out.unknown.sort(key=lambda u: (u.k, u.side))
    return out


def _known_of(known: dict, c: int, contacts: np.ndarray) -> dict:
    """The known ends of a chunk's contacts (R: k = a, S: k = c + a)."""
    ks = set(int(a) for a in contacts) | set(c + int(a) for a in contacts)
    return {key: v for key, v in known.items() if key[0] in ks}


def _record_chunk(record, c: int, contacts: np.ndarray, lo_x: np.ndarray,
                  hi_x: np.ndarray) -> None:
    """record(k, side, value) for a chunk's ends (lo_x, hi_x: R then S), unknown ones left
    out."""
    m = len(contacts)
    for x, a in enumerate(contacts):
        for k, pos in ((int(a), x), (c + int(a), m + x)):
            for side, v in (("min", lo_x[pos]), ("max", hi_x[pos])):
                if not np.isnan(v):
                    record(k, side, float(v))
