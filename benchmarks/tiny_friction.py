"""The explicit search that found the steady-range ends not decided at a tiny interparticle
friction (issue 21; tests/verify/ranges/test_tiny_friction.py; docs/mechanics.md, "A tiny
interparticle friction"): random small rect / tri arrays (lx 2-4, ly 1-2, mu_wall 0), mu_pp
log-uniform in [1e-8, 1e-6], mu_plane in [0.05, 0.4], gamma in [0.01, 0.4]; for each, the
steady ranges of mu_g and every angular acceleration (`steady_ranges(..., which="alpha",
split=False, clock="cpu")`), and every end that is neither optimal nor unbounded, or the
system's NotSteady, with its reason. Prints one line per such system and the totals.

    python benchmarks/tiny_friction.py [--count 80] [--seed 3] [--time-limit 20]
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

from rigidlcp import models
from rigidlcp.verify.ranges import steady_ranges
from rigidlcp.verify.ranges.steady import NotSteady


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=80)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--time-limit", type=float, default=20.0, help="CPU s per end")
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    bad_systems = bad_ends = not_steady = 0
    c0 = time.process_time()
    for _ in range(args.count):
        lat = str(rng.choice(["rect", "tri"]))
        lx, ly = int(rng.integers(2, 5)), int(rng.integers(1, 3))
        mpp = float(10 ** rng.uniform(-8, -6))
        mpl, gamma = float(rng.uniform(0.05, 0.4)), float(rng.uniform(0.01, 0.4))
        lattice = (models.rectangular if lat == "rect" else models.triangular)(lx, ly)
        system = models.System(lattice, mu_pp=mpp, mu_plane=mpl, mu_wall=0.0, gamma=gamma)
        try:
            r = steady_ranges(system, which="alpha", time_limit=args.time_limit, split=False,
                              clock="cpu")
            bad = [(name, side, getattr(rg, side).status, getattr(rg, side).note)
                   for name, rg in r.ranges.items() for side in ("lo", "hi")
                   if getattr(rg, side).status not in ("optimal", "unbounded")]
        except NotSteady as exc:
            bad, not_steady = [("NotSteady", str(exc))], not_steady + 1
        if bad:
            bad_systems += 1
            bad_ends += len(bad)
            print(json.dumps([lat, lx, ly, mpp, mpl, gamma]), bad, flush=True)
    print(f"{args.count} systems (seed {args.seed}): {bad_systems} with an end not decided "
          f"({bad_ends} ends; {not_steady} NotSteady); {time.process_time() - c0:.1f} CPU s, "
          f"load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
