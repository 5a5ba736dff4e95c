"""How much any change to the range LPs of a deposited pile (issue 22, "Scale") could gain, by
kind of change, measured on the LPs that verify.statics.range_ends actually solves (a script,
not a test; it prints a markdown table).

    python benchmarks/range_limits.py [--n 300] [--sample K:B] [--rings 1,2,4,8] [--mu 0.5]
                                      [--seed 1] [--radii 0.8:1.2]

The ranges of every contact of the `--n`-disk pile (or of K contacts in B clusters, as
benchmarks/packings.py's --sample) are computed as `forceset` does (`ranges_of`: one warm
DualForceLP, the LPs ordered by regret, ends settled by bounds attained at witnesses and at
kept bases without an LP), and each LP that runs is measured:

* witness at the optimum: the best value of that end over the checked points met before the
  LP already equals the LP's optimum (to 1e-9 of the force scale). An end decided without its
  LP needs a point of P at its optimum, so filtering by bounds (Gleixner et al., J. Glob.
  Optim. 2017: trivial bounds, Lagrangian bounds from kept duals) and outer bounds from window
  relaxations can skip at most these LPs (their pivots and CPU s are the most they can save);
* dual y within k rings: the disks whose balance rows carry y != 0 in the LP's optimal dual
  (its virtual motion: |y| > 1e-9 max |y| on the disk's x, y or rotation row) lie within k
  rings of touching disks around the contact. The LP over that window (the other disks held
  fixed: a relaxation of P) has the same optimum only then; it is cheap only for these LPs;
* basis changes: the basic cone columns of the new optimum not basic at the last optimum
  (the warm start; each pivot changes one), and the fewest from any optimum kept so far (the
  best start any order or kept basis could offer): pivots / changes is how far HiGHS's path
  is from the shortest, and changes x CPU per pivot a floor on any simplex from these starts.

--order other than "regret" (the default, range_ends' own) measures another order of the
contacts, `ranges_of` called on --chunk contacts at a time (regret within each chunk, the
witnesses and kept bases carried over): "hilbert" (a Hilbert curve through the contacts'
first disks), "serpentine" (range_ends.spatial_order, the workers' chunks), "topdown" (by
height, from the top), "index" (the contacts' own order); with --chunk 1 the ends of one
contact follow each other (max R, min R, max S, min S as the bounds allow).

CPU seconds are process time (the LPs only, this process); wall seconds and `uptime`'s load
are printed with them.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.verify.statics import ends, range_ends
from rigidlcp.verify.statics.forceset import analyse
from rigidlcp.verify.statics.model import DualForceLP, ForceLP, StaticProblem
from rigidlcp.verify.statics.range_ends import Vertices, Witnesses, ranges_of, spatial_order

sys.path.insert(0, str(Path(__file__).parent))
from packings import _picks  # noqa: E402  (the contacts of packings.py's --sample)


class Rings:
    """The disks within k rings of touching disks around a contact's disks."""

    def __init__(self, lat: models.Lattice):
        self.i, self.j = np.asarray(lat.i, dtype=int), np.asarray(lat.j, dtype=int)
        self.adj: list[set[int]] = [set() for _ in range(lat.p)]
        for i, j in zip(self.i, self.j):
            if j >= 0:
                self.adj[i].add(int(j))
                self.adj[j].add(int(i))

    def reach(self, a: int, disks: set[int], most: int) -> int:
        """The fewest rings around contact a holding `disks` (most + 1: more than `most`)."""
        W = {int(self.i[a])} | ({int(self.j[a])} if self.j[a] >= 0 else set())
        for k in range(most + 1):
            if disks <= W:
                return k
            W = W.union(*(self.adj[d] for d in W))
        return most + 1


def _hilbert(x: np.ndarray, y: np.ndarray, side: int = 1024) -> np.ndarray:
    """The index of each point (x, y) along a Hilbert curve over their bounding square."""
    size = max(np.ptp(x), np.ptp(y)) + 1e-12
    X = ((x - x.min()) / size * (side - 1)).astype(int)
    Y = ((y - y.min()) / size * (side - 1)).astype(int)
    d = np.zeros(x.size, dtype=np.int64)
    s = side // 2
    while s > 0:
        rx, ry = (X & s) > 0, (Y & s) > 0
        d += s * s * ((3 * rx) ^ ry)
        flip = ~ry & rx
        X, Y = np.where(flip, side - 1 - X, X), np.where(flip, side - 1 - Y, Y)
        X, Y = np.where(~ry, Y, X), np.where(~ry, X, Y)
        s //= 2
    return d


def _ordered(prob: StaticProblem, contacts: np.ndarray, order: str) -> np.ndarray:
    lat = prob.system.lattice
    where = np.asarray(lat.x, dtype=float)[np.asarray(lat.i)][contacts]
    if order == "hilbert":
        return contacts[np.argsort(_hilbert(where[:, 0], where[:, 1]), kind="stable")]
    if order == "serpentine":
        rank = np.empty(prob.c, dtype=int)
        rank[spatial_order(prob)] = np.arange(prob.c)
        return contacts[np.argsort(rank[contacts], kind="stable")]
    if order == "topdown":
        return contacts[np.argsort(-where[:, 1], kind="stable")]
    return contacts


def measure(system: models.System, picks: np.ndarray | None, most: int,
            order: str = "regret", chunk: int = 0) -> dict:
    fs = analyse(system, ranges=False)
    if not fs.exists:
        raise SystemExit(f"the pile has no equilibrium ({fs.exists}): nothing to range")
    prob = StaticProblem(system)
    lp = DualForceLP(prob, ForceLP(prob))
    lp.solve(np.zeros(prob.n))
    contacts = np.arange(prob.c) if picks is None else picks
    wit = Witnesses.of(prob, fs.solution)
    rings = Rings(system.lattice)
    nw = lp.primal.nw
    kept = np.zeros((64, nw), dtype=bool)  # the optimal bases met, one row each
    kept[0, ends.basis_of(prob, lp)] = True
    n_kept = [1]
    rows: list[tuple] = []
    real = range_ends.settle
    tol = 1e-9 * prob.scale
    p = prob.p

    def settle(prob_, lp_, cost, *args, **kw):
        nonlocal kept
        k = int(np.flatnonzero(cost)[0])
        s = float(cost[k])
        best = float(wit.best(np.array([k]), np.array([s]))[0])
        t = time.process_time()
        out = real(prob_, lp_, cost, *args, **kw)
        cpu = time.process_time() - t
        pivots = int(lp_.last.h.getInfo().simplex_iteration_count)
        hit = out.lam is not None and abs(s * out.lam[k] - best) <= max(tol, 1e-9 * abs(best))
        reach, change, fewest, moving = most + 1, -1, -1, None
        if out.status == "optimal" and out.how == "warm" and lp_.last is lp_:
            y = np.abs(np.asarray(lp_.h.getSolution().col_value, dtype=float))
            y = np.maximum.reduce([y[:p], y[p:2 * p], y[2 * p:]])
            moving = set(np.flatnonzero(y > 1e-9 * y.max()).tolist()) if y.max() > 0 else set()
            reach = rings.reach(k % prob.c, moving, most)
            cols = ends.basis_of(prob, lp_)
            if cols is not None:
                n = n_kept[0]
                new = np.zeros(nw, dtype=bool)
                new[cols] = True
                # each pivot changes one basic column: count the new ones
                changes = np.count_nonzero(new & ~kept[:n], axis=1)
                change, fewest = int(changes[n - 1]), int(changes.min())
                if n == kept.shape[0]:
                    kept = np.vstack([kept, np.zeros_like(kept)])
                kept[n], n_kept[0] = new, n + 1
        rows.append((pivots, cpu, hit, reach, change, fewest, len(moving) if moving else -1))
        return out

    range_ends.settle = settle
    try:
        vertices = Vertices(prob, lp.primal.nw)
        t, w = time.process_time(), time.perf_counter()
        lps = unchecked = 0
        seq = _ordered(prob, contacts, order)
        size = contacts.size if order == "regret" or chunk <= 0 else chunk
        for s in range(0, seq.size, size):
            got = ranges_of(prob, lp, fs.implicit, seq[s:s + size], wit, vertices=vertices)
            lps, unchecked = lps + got[2], unchecked + got[3]
        cpu, wall = time.process_time() - t, time.perf_counter() - w
    finally:
        range_ends.settle = real
    return dict(prob=prob, contacts=contacts.size, lps=lps, unchecked=unchecked, cpu=cpu,
                wall=wall, rows=np.array(rows, dtype=float), kept=vertices.settled)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=300)
    ap.add_argument("--sample", default="", help="K:B: K contacts in B clusters (B = K: spread)")
    ap.add_argument("--rings", default="1,2,4,8")
    ap.add_argument("--mu", type=float, default=0.5)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--radii", default="0.8:1.2")
    ap.add_argument("--order", default="regret",
                    choices=("regret", "hilbert", "serpentine", "topdown", "index"))
    ap.add_argument("--chunk", type=int, default=1, help="contacts per ranges_of call "
                    "(orders other than regret)")
    args = ap.parse_args()
    radii = tuple(float(v) for v in args.radii.split(":"))
    ks = [int(v) for v in args.rings.split(",") if v]
    pile = deposit(args.n, seed=args.seed, radii=radii)
    system = models.System(pile, mu_pp=args.mu, mu_plane=args.mu, mu_wall=args.mu)
    picks = None
    if args.sample:
        k, b = (int(v) for v in args.sample.split(":"))
        picks = _picks(StaticProblem(system), k, b)
    load = os.getloadavg()[0]
    m = measure(system, picks, max(ks), args.order, args.chunk)
    r = m["rows"]
    piv, cpu = r[:, 0], r[:, 1]
    hit = r[:, 2] > 0
    load = f"{load:.1f}-{os.getloadavg()[0]:.1f}"
    print(f"pile of {args.n} disks (seed {args.seed}, radii {args.radii}, mu {args.mu}), "
          f"{m['contacts']} of {m['prob'].c} contacts, order {args.order}"
          f"{'' if args.order == 'regret' else f' in chunks of {args.chunk}'}; "
          f"load average {load}\n")
    print("| measure | LPs | pivots | CPU s |")
    print("|---|---|---|---|")
    print(f"| every LP run ({m['kept']} ends at kept bases, {m['unchecked']} unknown; the "
          f"whole run with this script's measuring {m['cpu']:.2f} CPU s, {m['wall']:.2f} s "
          f"wall) | {m['lps']} | {piv.sum():.0f} ({piv.sum() / len(r):.0f} per LP) | "
          f"{cpu.sum():.2f} ({cpu.sum() / max(piv.sum(), 1) * 1e3:.3f} ms per pivot) |")
    print(f"| witness already at the optimum (the most filtering or windows can skip) | "
          f"{hit.sum()} | {piv[hit].sum():.0f} | {cpu[hit].sum():.2f} |")
    for k in ks:
        near = r[:, 3] <= k
        both = near & hit
        print(f"| dual y within {k} rings of the contact (of them with a witness at the "
              f"optimum: {both.sum()}, {cpu[both].sum():.2f} CPU s) | {near.sum()} | "
              f"{piv[near].sum():.0f} | {cpu[near].sum():.2f} |")
    moved = r[r[:, 6] >= 0, 6]
    if moved.size:
        q = ", ".join(f"{v:.0f}" for v in np.percentile(moved, [10, 25, 50, 75, 90]))
        print(f"| disks moving in the optimal dual y (10th, 25th, 50th, 75th, 90th percentile:"
              f" {q}) | {moved.size} | - | - |")
    warm = r[:, 4] >= 0
    per = cpu[warm].sum() / max(piv[warm].sum(), 1)
    for name, col in (("basis changes from the last optimum (the warm start)", 4),
                      ("fewest basis changes from any kept optimum", 5)):
        ch = r[warm, col].sum()
        print(f"| {name}: floor of a simplex from there at {per * 1e3:.3f} ms per pivot | "
              f"{warm.sum()} | {ch:.0f} ({piv[warm].sum() / max(ch, 1):.1f}x fewer than "
              f"pivots) | {ch * per:.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
