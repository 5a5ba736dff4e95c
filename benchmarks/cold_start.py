"""The cold first event of the sparse path (a script, not a test): the current rule for a new
base (StateFactor.set_states refactors when the solves for the new rows would cost more than a
factorization) against the rule before issue 13 (refactor only above max_updates rows),
alternating in one process.

    python benchmarks/cold_start.py [--sizes 40,70,100] [--repeats 3]

Parameters as benchmarks/scale.py (rect LxL, mu_pp = 0.02, mu_plane = 0.2, mu_wall = 0,
gamma = 0.16 g, seed 1); one event (`simulate_sparse(..., max_events=1)`), one BLAS thread.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time

import numpy as np
from threadpoolctl import threadpool_limits

from rigidlcp import models
from rigidlcp.models import sparse_event
from rigidlcp.models.engine.sparse import simulate_sparse


def first_event(L: int, old_rule: bool) -> tuple[float, dict, float]:
    cls = sparse_event.StateFactor
    refactor, propose = cls.refactor, cls._propose

    def refactor_old(self, normal, tang):
        refactor(self, normal, tang)
        self.column_seconds = 0.0  # never weigh the solves: the rule before issue 13

    def propose_old(self, *a):
        out = propose(self, *a)
        self.column_seconds = 0.0
        return out

    if old_rule:
        cls.refactor, cls._propose = refactor_old, propose_old
    try:
        system = models.System(models.make_lattice("rect", L, L), mu_pp=0.02, mu_plane=0.2,
                               mu_wall=0.0, gamma=0.16)
        t0 = time.perf_counter()
        run = simulate_sparse(system, seed=1, max_events=1)
        wall = time.perf_counter() - t0
    finally:
        cls.refactor, cls._propose = refactor, propose
    info = run.sparse_info
    return float(info["seconds"][0]), info, wall


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="40,70,100")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    print(f"Cold first event, sparse path; median of {args.repeats} alternating runs; python "
          f"{platform.python_version()}, {os.cpu_count()} CPUs, load average "
          f"{os.getloadavg()[0]:.2f}; one BLAS thread")
    header = f"{'L':>4} {'rule':<22} {'first s':>8} {'factorizations':>14} {'iterations':>10}"
    print(header)
    print("-" * len(header))
    with threadpool_limits(1):
        for L in (int(x) for x in args.sizes.split(",")):
            res: dict[bool, list] = {False: [], True: []}
            for _ in range(args.repeats):
                for old in (False, True):
                    res[old].append(first_event(L, old))
            for old in (False, True):
                r = res[old]
                print(f"{L:>4} {'before (max_updates)' if old else 'now (weigh solves)':<22} "
                      f"{np.median([x[0] for x in r]):>8.2f} "
                      f"{r[0][1]['factorizations']:>14} {r[0][1]['iterations'][0]:>10}")
    print(f"load average at the end {os.getloadavg()[0]:.2f} (2-core machine shared with other "
          "jobs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
