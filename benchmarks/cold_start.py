"""The cold first event of the sparse path (a script, not a test): first-event time, block steps
and factorizations with the safeguards and the reduced factorization of issue 13 switched on
and off, alternating in one process.

    python benchmarks/cold_start.py [--sizes 40,70,100] [--repeats 3]

Variants: "issue 13" (the defaults: the component step of lcp.state_pivoting and
lcp.state_factor.ReducedLU); "full-K LU" (REDUCED = False: SuperLU of all of K); "no component
step" (COMPONENTS = False: a block step flips every violated state); "before" (both off, the
solver before issue 13; the event engine does not use the stall rescue). Parameters as
benchmarks/scale.py (rect LxL, mu_pp = 0.02, mu_plane = 0.2, mu_wall = 0, gamma = 0.16 g, seed
1); one event (`simulate_sparse(..., max_events=1)`), one BLAS thread. "factorizations" counts
the cold start's own one.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys

import numpy as np
from threadpoolctl import threadpool_limits

from rigidlcp import models
from rigidlcp.lcp.solvers import state_factor, state_pivoting
from rigidlcp.models.engine.sparse import simulate_sparse

VARIANTS = {"issue 13": (True, True), "full-K LU": (False, True),
            "no component step": (True, False), "before": (False, False)}


def first_event(L: int, reduced: bool, components: bool) -> tuple[float, dict]:
    saved = state_factor.REDUCED, state_pivoting.COMPONENTS
    state_factor.REDUCED, state_pivoting.COMPONENTS = reduced, components
    try:
        system = models.System(models.make_lattice("rect", L, L), mu_pp=0.02, mu_plane=0.2,
                               mu_wall=0.0, gamma=0.16)
        run = simulate_sparse(system, seed=1, max_events=1)
    finally:
        state_factor.REDUCED, state_pivoting.COMPONENTS = saved
    info = run.sparse_info
    return float(info["seconds"][0]), info


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="40,70,100")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    print(f"Cold first event, sparse path; median of {args.repeats} alternating runs; python "
          f"{platform.python_version()}, {os.cpu_count()} CPUs, load average "
          f"{os.getloadavg()[0]:.2f}; one BLAS thread")
    header = (f"{'L':>4} {'variant':<18} {'first s':>8} {'factorizations':>14} "
              f"{'iterations':>10} {'flips':>6}")
    print(header)
    print("-" * len(header))
    with threadpool_limits(1):
        for L in (int(x) for x in args.sizes.split(",")):
            res: dict[str, list] = {k: [] for k in VARIANTS}
            for _ in range(args.repeats):
                for name, flags in VARIANTS.items():
                    res[name].append(first_event(L, *flags))
            for name, r in res.items():
                info = r[0][1]
                print(f"{L:>4} {name:<18} {np.median([x[0] for x in r]):>8.2f} "
                      f"{info['factorizations'] + 1:>14} {info['iterations'][0]:>10} "
                      f"{info['flips']:>6}")
    print(f"load average at the end {os.getloadavg()[0]:.2f} (2-core machine shared with other "
          "jobs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
