"""Packings at scale (issue 22): deposition, and the statics of deposited piles (a script, not a
test; it prints a markdown table).

    python benchmarks/packings.py [--deposit 1000,10000] [--statics 100,1000] [--ranges 100]
                                  [--arrays 100] [--mu 0.5] [--seed 1] [--radii 0.8:1.2]
                                  [--jobs 1] [--sample 1000:64[:8]] [--holes 3]

deposit N: `models.deposition.deposit` of N disks (radii uniform in --radii, default width).
statics N: existence and dimension (`verify.statics.forceset.analyse(ranges=False)`).
ranges N: the whole analysis: also the range of every R and S and the sliding contacts, the
range LPs in --jobs worker processes (verify.statics.contact_ranges).
arrays L: existence and dimension of the L x L rectangular and triangular arrays written as
packings (`models.make_packing`: packings that stand, where deposited piles at scale fall);
with --holes K, every K-th disk of their top row removed (from the left; a disk of the rect
array's top row then beside one neighbour only can roll away from it on the disk below: with
mu < 1 that contact, and a top disk's right wall, carry R = 0 on all of P: implicit
equalities, a few per row, proved by verify.statics.implicit).
sample N:K[:B]: the ranges of K contacts of an N-disk pile (one warm DualForceLP as in
`analyse`, in this process, the LPs ordered and kept bases tried as in
verify.statics.range_ends), and the whole pile's range LPs extrapolated from them (c / K times
the time): an estimate where the whole run takes too long. The K contacts are spread evenly
over the contacts (B = K, the default), or are B clusters of K / B contacts each, the nearest
(by their first disk's centre) to B contacts at evenly spread heights: neighbours, whose
optima the ordered LPs reuse, as in the whole pile.
Wall-clock seconds and CPU seconds (process time, worker processes included) of one run each.
"""

from __future__ import annotations

import argparse
import resource
import time

import numpy as np

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.verify.statics.contact_ranges import Vertices, Witnesses, ranges_of
from rigidlcp.verify.statics.forceset import analyse
from rigidlcp.verify.statics.model import DualForceLP, ForceLP, StaticProblem


def _sizes(text: str) -> list[int]:
    return [int(v) for v in text.split(",") if v]


def _cpu() -> float:
    """CPU seconds of this process and of its finished children (the range workers)."""
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + kids.ru_utime + kids.ru_stime


def _timed(fn):
    t, c = time.perf_counter(), _cpu()
    out = fn()
    return out, time.perf_counter() - t, _cpu() - c


def _without_holes(x: np.ndarray, every: int) -> np.ndarray:
    """The indices of the disks kept when every `every`-th disk of the top row (highest
    centres, from the left) is removed (every 0: all)."""
    if every <= 0:
        return np.arange(len(x))
    top = np.flatnonzero(x[:, 1] == x[:, 1].max())
    top = top[np.argsort(x[top, 0])]
    return np.setdiff1d(np.arange(len(x)), top[::every])


def _picks(prob: StaticProblem, k: int, blocks: int) -> np.ndarray:
    """k contacts: spread evenly over the contacts' indices (blocks = k), or `blocks` clusters
    of the k / blocks contacts nearest to contacts at evenly spread heights (module
    docstring)."""
    if blocks >= k:
        return np.unique(np.linspace(0, prob.c - 1, k).round().astype(int))
    lat = prob.system.lattice
    where = np.asarray(lat.x, dtype=float)[np.asarray(lat.i)]
    by_height = np.argsort(where[:, 1], kind="stable")
    centres = by_height[np.linspace(0, prob.c - 1, blocks).round().astype(int)]
    size = max(1, k // blocks)
    near = [np.argsort(np.sum((where - where[a]) ** 2, axis=1), kind="stable")[:size]
            for a in centres]
    return np.unique(np.concatenate(near))


def _sample(system: models.System, k: int, blocks: int) -> tuple[str, float, float]:
    """The ranges of k contacts of the pile (`_picks`), and the whole pile's extrapolated."""
    fs = analyse(system, ranges=False)
    if not fs.exists:
        return f"no equilibrium ({fs.exists})", 0.0, 0.0
    prob = StaticProblem(system)
    lp = DualForceLP(prob, ForceLP(prob))
    lp.solve(np.zeros(prob.n))
    picks = _picks(prob, k, blocks)
    wit = Witnesses.of(prob, fs.solution)
    kept = Vertices(prob, lp.primal.nw)
    (_, _, lps, unchecked), wall, cpu = _timed(
        lambda: ranges_of(prob, lp, fs.implicit, picks, wit, vertices=kept))
    f = prob.c / picks.size
    where = "spread" if blocks >= k else f"in {blocks} clusters"
    return (f"{picks.size} of {prob.c} contacts ({where}): {lps} LPs ({unchecked} unchecked, "
            f"{kept.settled} ends at kept bases), {cpu / max(lps, 1):.3f} CPU s per LP; whole "
            f"pile ~{lps * f:.0f} LPs, ~{cpu * f:.1f} CPU s"), wall, cpu


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--deposit", type=_sizes, default=[1000, 10000])
    ap.add_argument("--statics", type=_sizes, default=[100, 1000])
    ap.add_argument("--ranges", type=_sizes, default=[100])
    ap.add_argument("--arrays", type=_sizes, default=[])
    ap.add_argument("--mu", type=float, default=0.5)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--radii", default="0.8:1.2")
    ap.add_argument("--jobs", type=int, default=1, help="worker processes of the range LPs")
    ap.add_argument("--sample", default="", help="N:K[:B] (see above)")
    ap.add_argument("--holes", type=int, default=0,
                    help="remove every K-th disk of the arrays' top row (0: none)")
    args = ap.parse_args()
    radii = tuple(float(v) for v in args.radii.split(":"))
    print(f"radii {radii[0]}:{radii[1]}, seed {args.seed}, mu = {args.mu} on every contact, "
          f"range LPs in {args.jobs} process(es)\n")
    sample = tuple(int(v) for v in args.sample.split(":")) if args.sample else None
    if sample and len(sample) == 2:
        sample = (*sample, sample[1])
    print("| task | disks | contacts | result | wall s | CPU s |")
    print("|---|---|---|---|---|---|")
    piles = {}
    extra = {sample[0]} if sample else set()
    for n in sorted(set(args.deposit) | set(args.statics) | set(args.ranges) | extra):
        pile, wall, cpu = _timed(lambda n=n: deposit(n, seed=args.seed, radii=radii))
        piles[n] = pile
        if n in args.deposit:
            print(f"| deposition | {n} | {pile.c} | - | {wall:.2f} | {cpu:.2f} |", flush=True)
    for task, sizes, full in (("existence + dimension", args.statics, False),
                              ("+ ranges of R, S + sliding", args.ranges, True)):
        for n in sizes:
            pile = piles[n]
            system = models.System(pile, mu_pp=args.mu, mu_plane=args.mu, mu_wall=args.mu)
            fs, wall, cpu = _timed(lambda s=system, f=full: analyse(s, ranges=f,
                                                                    jobs=args.jobs))
            result = (f"exists, dim {fs.dimension}" if fs.exists else
                      f"undecided ({fs.undecided})" if fs.exists is None else
                      "no equilibrium (Farkas, exact)" if fs.exact else
                      f"no equilibrium (Farkas, radius {fs.radius:.2g})")
            if full and fs.exists:
                result += f", {fs.lps} LPs, {int(fs.sliding.sum())} can slide"
            print(f"| {task} | {n} | {pile.c} | {result} | {wall:.2f} | {cpu:.2f} |",
                  flush=True)
    for L in args.arrays:
        for kind in ("rect", "tri"):
            lat = models.make_lattice(kind, L, L)
            keep = _without_holes(lat.x, args.holes)
            pk = models.make_packing(lat.x[keep], lat.radii[keep], left=lat.left,
                                     right=lat.right)
            system = models.System(pk, mu_pp=args.mu, mu_plane=args.mu, mu_wall=args.mu)
            fs, wall, cpu = _timed(lambda s=system: analyse(s, ranges=False))
            result = (f"exists, dim {fs.dimension}" if fs.exists else
                      f"undecided ({fs.undecided})" if fs.exists is None else
                      "no equilibrium")
            result += f", {sum(bool(s) for s in fs.implicit)} implicit" if fs.exists else ""
            holes = f", top row holes every {args.holes}" if args.holes else ""
            print(f"| existence + dimension, {kind} {L}x{L} array{holes} | {pk.p} | {pk.c} "
                  f"| {result} | {wall:.2f} | {cpu:.2f} |", flush=True)
    if sample:
        n, k, blocks = sample
        pile = piles[n]
        system = models.System(pile, mu_pp=args.mu, mu_plane=args.mu, mu_wall=args.mu)
        result, wall, cpu = _sample(system, k, blocks)
        print(f"| ranges, sample | {n} | {pile.c} | {result} | {wall:.2f} | {cpu:.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
