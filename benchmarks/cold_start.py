"""The cold first event of the sparse path (a script, not a test): first-event time and
factorizations, with the refactoring rule of lcp.state_factor (a new base once the column
solves since the last one would exceed REFACTOR_SOLVES) against updates up to max_updates rows
(no solve count: the rule before issue 13, without its clock), alternating in one process.

    python benchmarks/cold_start.py [--sizes 40,70,100] [--repeats 3]

Parameters as benchmarks/scale.py (rect LxL, mu_pp = 0.02, mu_plane = 0.2, mu_wall = 0,
gamma = 0.16 g, seed 1); one event (`simulate_sparse(..., max_events=1)`), one BLAS thread.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys

import numpy as np
from threadpoolctl import threadpool_limits

from rigidlcp import models
from rigidlcp.lcp import state_factor
from rigidlcp.models.engine.sparse import simulate_sparse


def first_event(L: int, refactor_solves: int) -> tuple[float, dict]:
    init = state_factor.StateFactor.__init__
    defaults = init.__defaults__
    init.__defaults__ = (defaults[0], refactor_solves)
    try:
        system = models.System(models.make_lattice("rect", L, L), mu_pp=0.02, mu_plane=0.2,
                               mu_wall=0.0, gamma=0.16)
        run = simulate_sparse(system, seed=1, max_events=1)
    finally:
        init.__defaults__ = defaults
    info = run.sparse_info
    return float(info["seconds"][0]), info


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="40,70,100")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    rules = {f"solve count ({state_factor.REFACTOR_SOLVES})": state_factor.REFACTOR_SOLVES,
             "max_updates only": 10**9}
    print(f"Cold first event, sparse path; median of {args.repeats} alternating runs; python "
          f"{platform.python_version()}, {os.cpu_count()} CPUs, load average "
          f"{os.getloadavg()[0]:.2f}; one BLAS thread")
    header = (f"{'L':>4} {'refactoring rule':<22} {'first s':>8} {'factorizations':>14} "
              f"{'iterations':>10}")
    print(header)
    print("-" * len(header))
    with threadpool_limits(1):
        for L in (int(x) for x in args.sizes.split(",")):
            res: dict[str, list] = {k: [] for k in rules}
            for _ in range(args.repeats):
                for name, value in rules.items():
                    res[name].append(first_event(L, value))
            for name, r in res.items():
                print(f"{L:>4} {name:<22} {np.median([x[0] for x in r]):>8.2f} "
                      f"{r[0][1]['factorizations']:>14} {r[0][1]['iterations'][0]:>10}")
    print(f"load average at the end {os.getloadavg()[0]:.2f} (2-core machine shared with other "
          "jobs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
