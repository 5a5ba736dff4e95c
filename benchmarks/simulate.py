"""Event-driven runs to the steady state: events, wall time, events per second.

    python benchmarks/simulate.py [--budget SECONDS] [--cases rect10x4,...] [--methods ...]

Each case is run with Fig. 9's parameters (mu_pp = 0.1, mu_plane = 0.2, mu_wall = 0,
gamma = 0.16 g, seed 1) -- except the wide arrays, driven at gamma = 0.1 g: a top-row disk
next to the loaded wall is lifted by the friction of its two sliding lateral contacts when
2 mu_pp gamma Lx > 1 (40x20 at 0.16 g stops with "detachment" at its first event) -- by
`lemke` and by `pivoting` warm-started from the previous event, with
the default event selection (face-min-norm) and with --select none as a second row. A run that
exceeds the time budget stops at its time limit and is reported as such (events/s still
meaningful). Not a test: it prints a table.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))

import numpy as np  # noqa: E402

from rigidlcp import models  # noqa: E402

CASES = {"rect10x4": ("rect", 10, 4, 0.16), "rect20x10": ("rect", 20, 10, 0.1),
         "rect40x20": ("rect", 40, 20, 0.1), "tri10x4": ("tri", 10, 4, 0.16)}


class Budget(Exception):
    pass


def run_case(case: str, method: str, select: str, budget: float) -> dict:
    lattice, lx, ly, gamma = CASES[case]
    system = models.System(models.make_lattice(lattice, lx, ly), mu_pp=0.1, mu_plane=0.2,
                           mu_wall=0.0, gamma=gamma)
    start = time.perf_counter()
    done = [0]

    def progress(run) -> None:
        done[0] = run.n_events
        if time.perf_counter() - start > budget:
            raise Budget

    try:
        run = models.simulate(system, seed=1, method=method, select=select, progress=progress)
        status, events = run.status, run.n_events
        n_lcp = int(np.median(run.array("n_lcp"))) if run.records else 0
        pivots = int(np.median(run.array("iterations"))) if run.records else 0
    except Budget:  # events/s still measured over the events done within the budget
        status, events, n_lcp, pivots = f"budget {budget:g}s", done[0], 0, 0
    wall = time.perf_counter() - start
    return dict(case=case, p=system.p, c=system.c, method=method, select=select, status=status,
                events=events, wall=wall, n_lcp=n_lcp, pivots=pivots)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--methods", default="lemke,pivoting")
    ap.add_argument("--selects", default="face-min-norm,none")
    ap.add_argument("--budget", type=float, default=120.0, help="seconds per run")
    args = ap.parse_args()
    header = (f"{'case':<10} {'disks':>5} {'contacts':>8} {'method':<9} {'select':<13} "
              f"{'status':<12} {'events':>6} {'wall s':>8} {'events/s':>9} {'median n':>8} "
              f"{'pivots':>6}")
    print(header)
    print("-" * len(header))
    for case in args.cases.split(","):
        for method in args.methods.split(","):
            for select in args.selects.split(","):
                if method == "sparse-pivoting" and select != "none":
                    continue  # the sparse path keeps the pivoting's own solution
                r = run_case(case, method, select, args.budget)
                rate = f"{r['events'] / r['wall']:.2f}" if r["events"] > 0 else "-"
                events = r["events"]
                print(f"{r['case']:<10} {r['p']:>5} {r['c']:>8} {r['method']:<9} "
                      f"{r['select']:<13} {r['status']:<12} {events:>6} {r['wall']:>8.2f} "
                      f"{rate:>9} {r['n_lcp']:>8} {r['pivots']:>6}", flush=True)


if __name__ == "__main__":
    main()
