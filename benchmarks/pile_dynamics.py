"""The paper's dynamics on seeded deposited piles (docs/packings.md, "The paper's dynamics on a
packing"): how each run ends, and why (a script, not a test; it prints a markdown table).

    python benchmarks/pile_dynamics.py [--seeds 1:10] [--max-events 2000] [--no-closed-search]
                                       [--rows 0,1,...]

Rows: `deposit(n, seed, radii=(0.8, 1.2), width)` for the (n, width) of each row, one mu on
every contact, gamma = 0.1, the default method; started with random spins (spin seed 1) or at
rest (omega = 0: every contact a candidate). Columns: runs ending steady; detachments proved by
the regime check (verify.statics.regime: no forces hold the translations); detachments proved
by the closed-solution search (models/engine/closed.py: no solution of the event's LCP keeps
every contact closed); detachments left undecided by both; runs ending "no_solution" or
otherwise; and the runs in which a closed solution was followed at some event (their count is
part of the others: those runs went on). CPU seconds (process time) of the whole row.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.verify.statics.regime import regime

ROWS = [(12, 6.0, "spins", 0.1), (12, 6.0, "spins", 0.3), (12, 6.0, "rest", 0.1),
        (12, 6.0, "rest", 0.3), (12, 6.0, "rest", 0.5), (30, 8.0, "spins", 0.05),
        (30, 8.0, "spins", 0.1), (30, 8.0, "spins", 0.3), (30, 8.0, "spins", 0.5),
        (30, 8.0, "rest", 0.3)]


def outcome(run: models.Run, system: models.System) -> str:
    """steady, proved-regime, proved-lcp, undecided, no_solution or the run's status."""
    if run.status != "detachment":
        return run.status
    if regime(system, run.final).exists is False:
        return "proved-regime"
    return "proved-lcp" if "proved: no solution of the event" in run.message else "undecided"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1:10")
    ap.add_argument("--max-events", type=int, default=2000)
    ap.add_argument("--no-closed-search", action="store_true")
    ap.add_argument("--rows", default="", help="comma-separated row numbers (default: all)")
    args = ap.parse_args()
    lo, hi = (int(v) for v in args.seeds.split(":"))
    print("| pile | start | mu | steady | proved (regime) | proved (closed search) | undecided "
          "| no solution | other | closed followed | CPU s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    rows = [ROWS[int(i)] for i in args.rows.split(",")] if args.rows else ROWS
    for n, width, start, mu in rows:
        counts: dict[str, int] = {}
        followed = 0
        t0 = time.process_time()
        for seed in range(lo, hi + 1):
            pile = deposit(n, seed=seed, radii=(0.8, 1.2), width=width)
            system = models.System(pile, mu_pp=mu, mu_plane=mu, mu_wall=mu, gamma=0.1)
            state = (models.initial_state(system, seed=1) if start == "spins"
                     else models.initial_state(system, omega=np.zeros(system.p)))
            run = models.simulate(system, state, max_events=args.max_events,
                                  closed_search=not args.no_closed_search)
            key = outcome(run, system)
            counts[key] = counts.get(key, 0) + 1
            followed += bool(run.closed and run.closed["followed"])
        known = ("steady", "proved-regime", "proved-lcp", "undecided", "no_solution")
        other = sum(v for k, v in counts.items() if k not in known)
        print(f"| {n} disks, width {width:g} | {start} | {mu:g} | "
              + " | ".join(str(counts.get(k, 0)) for k in known)
              + f" | {other} | {followed} | {time.process_time() - t0:.1f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
