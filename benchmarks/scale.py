"""Scaling of the sparse event path (issue 6): time per event against array size.

    python benchmarks/scale.py [--sizes 10,20,40,70,100] [--events 1000] [--budget 600]
                               [--gamma G] [--mu-pp M] [--seed S] [--lattice rect]

For each rectangular array LxL, `rigidlcp.models.engine.sparse.simulate_sparse` runs from the
seeded random angular velocities for --events events, or to its steady state, or until the
run's wall clock passes --budget seconds. Printed per size: disks, contacts, the events run and
why the run stopped, the wall time, the median time per event (the first event, a cold start,
is reported separately and left out of the median), the median time of the solver's sparse LU
(lcp.state_factor.ReducedLU: SuperLU of the rows of W that the states keep) of the same events'
final active systems, factored in the same run outside the timed events (a sample of up to
--lu-samples events), and their ratio; then the exponent of time per event against the number
of disks, fitted by least squares on log-log over the sizes that ran at least 10 events. One
process, one BLAS thread; the machine may be shared: say so when quoting.

Parameters: Fig. 9's (mu_plane = 0.2, mu_wall = 0, gamma = 0.16 g) except mu_pp = 0.02 by
default. With Fig. 9's mu_pp = 0.1 the runs of arrays 60 or more disks wide stop at the first
event with "detachment": sliding friction at the side contacts lifts bottom disks off the
plane (a_n > 0; the dense path finds the same at 100 x 5 and 60 x 10), which ends the
paper's no-displacement regime; mu_pp = 0.02 keeps every size in it.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))

import numpy as np  # noqa: E402

from rigidlcp import models  # noqa: E402
from rigidlcp.lcp.solvers.state_factor import ReducedLU  # noqa: E402
from rigidlcp.models.engine.sparse import simulate_sparse  # noqa: E402


class Budget(Exception):
    """The run's wall-clock budget is spent."""


def run_size(lattice: str, L: int, args) -> dict:
    t0 = time.perf_counter()
    system = models.System(models.make_lattice(lattice, L, L), mu_pp=args.mu_pp,
                           mu_plane=args.mu_plane, mu_wall=args.mu_wall, gamma=args.gamma)
    build = time.perf_counter() - t0
    sample = set(np.linspace(1, args.events - 1, args.lu_samples).round().astype(int).tolist())
    lu_times: list[float] = []
    start = time.perf_counter()

    def hook(k, seconds, sol, asys) -> None:
        if k in sample:
            t = time.perf_counter()
            ReducedLU(asys, sol.normal, sol.tang)
            lu_times.append(time.perf_counter() - t)

    def progress(run) -> None:
        if time.perf_counter() - start > args.budget:
            raise Budget

    status, n_events, seconds, info = "?", 0, [], {}
    holder: dict = {}

    def keep(run) -> None:
        holder["run"] = run
        progress(run)

    try:
        run = simulate_sparse(system, seed=args.seed, max_events=args.events, records="light",
                              event_hook=hook, progress=keep)
        status, n_events, info = run.status, run.n_events, run.sparse_info
    except Budget:
        run = holder["run"]
        status, n_events, info = f"budget {args.budget:g}s", run.n_events, run.sparse_info
    wall = time.perf_counter() - start
    seconds = np.array(info.get("seconds", []))
    rest = seconds[1:] if seconds.size > 1 else seconds
    med = float(np.median(rest)) if rest.size else float("nan")
    lu = float(np.median(lu_times)) if lu_times else float("nan")
    return dict(L=L, p=system.p, c=system.c, events=n_events, status=status, wall=wall,
                build=build, first=float(seconds[0]) if seconds.size else float("nan"),
                median=med, lu=lu, ratio=med / lu if lu_times else float("nan"),
                rescues=info.get("rescues", 0), stalls=info.get("stall_rescues", 0),
                fallbacks=info.get("fallbacks", 0),
                factorizations=info.get("factorizations", 0), lu_samples=len(lu_times))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="10,20,40,70,100")
    ap.add_argument("--lattice", default="rect", choices=("rect", "tri"))
    ap.add_argument("--events", type=int, default=1000)
    ap.add_argument("--budget", type=float, default=600.0, help="wall seconds per size")
    ap.add_argument("--lu-samples", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--mu-pp", type=float, default=0.02)
    ap.add_argument("--mu-plane", type=float, default=0.2)
    ap.add_argument("--mu-wall", type=float, default=0.0)
    ap.add_argument("--gamma", type=float, default=0.16)
    args = ap.parse_args()
    sizes = [int(s) for s in args.sizes.split(",") if s.strip()]
    print(f"Sparse event path: {args.lattice} LxL arrays, mu_pp = {args.mu_pp}, mu_plane = "
          f"{args.mu_plane}, mu_wall = {args.mu_wall}, gamma = {args.gamma} g, seed "
          f"{args.seed}; up to {args.events} events or {args.budget:g} s per size")
    print(f"python {platform.python_version()}, numpy {np.__version__}, {os.cpu_count()} CPUs, "
          f"load average {os.getloadavg()[0]:.2f} at the start; one BLAS thread")
    header = (f"{'L':>4} {'disks':>6} {'contacts':>8} {'events':>6} {'status':<13} "
              f"{'wall s':>8} {'first s':>8} {'median ms':>10} {'LU ms':>8} {'ratio':>6} "
              f"{'refact':>6} {'rescues':>7} {'stalls':>6} {'dense fb':>8}")
    print(header)
    print("-" * len(header))
    rows = []
    for L in sizes:
        r = run_size(args.lattice, L, args)
        rows.append(r)
        print(f"{r['L']:>4} {r['p']:>6} {r['c']:>8} {r['events']:>6} {r['status']:<13} "
              f"{r['wall']:>8.1f} {r['first']:>8.2f} {1e3 * r['median']:>10.2f} "
              f"{1e3 * r['lu']:>8.2f} {r['ratio']:>6.2f} {r['factorizations']:>6} "
              f"{r['rescues']:>7} {r['stalls']:>6} {r['fallbacks']:>8}", flush=True)
    fit = [r for r in rows if r["events"] >= 10 and np.isfinite(r["median"])]
    if len(fit) >= 2:
        x = np.log([r["p"] for r in fit])
        y = np.log([r["median"] for r in fit])
        slope = float(np.polyfit(x, y, 1)[0])
        print(f"exponent of the median time per event against disks, sizes "
              f"{', '.join(str(r['L']) for r in fit)}: {slope:.2f}")
    else:
        print("exponent: fewer than two sizes ran 10 events")
    print(f"load average at the end {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
