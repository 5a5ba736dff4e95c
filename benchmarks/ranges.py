"""Ranges over all valid steady states (verify.ranges.steady_ranges, issue 21): a script, not
a test.

    python benchmarks/ranges.py [--time-limit SECONDS] [--skip-alpha] [--deep SECONDS]
                                [--kinematics auto|proportional|lazy|big-M] [--clock cpu|wall]

1. The four rows of issue 21's table (rect 10x1 at 0.05/0.1/0, gamma 0.01 and 0.02; rect 10x1
   at 0.1/0.2/0, gamma 0.02; Fig. 9: rect 10x4 at 0.1/0.2/0, gamma 0.16), each from the run of
   seed 1: the run's mu_g, the range over the valid steady states with the run's own contact
   states (linear programs), and over every contact-state set (a certified relaxation bound
   attained by a checked witness, else the MILP: by default without velocities
   (verify.ranges.proportional), `--kinematics lazy` the previous one with lazy kinematic cuts;
   "time limit" ends show the best value met, which is *not* a bound).
2. Fig. 9's system: mu_g and every angular acceleration, with the time of each end.

Ends left at the time limit get a proved bound (verify.ranges.cap_split; with --deep S also
verify.ranges.disk_split's case split on the disks' cap states, S seconds per end). The time
limits count this process's CPU seconds by default (`--clock cpu`: the same work whatever the
machine's load; `--clock wall` as before this option). Times: wall seconds and CPU seconds of
this process (time.process_time), with the load average.
"""

from __future__ import annotations

import argparse
import os
import time

from rigidlcp import models
from rigidlcp.verify.ranges import steady_ranges
from rigidlcp.verify.ranges.result import OPTIMAL

CASES = [("rect 10x1 0.05/0.1/0 gamma 0.01", 10, 1, 0.05, 0.1, 0.01),
         ("rect 10x1 0.05/0.1/0 gamma 0.02", 10, 1, 0.05, 0.1, 0.02),
         ("rect 10x1 0.1/0.2/0 gamma 0.02", 10, 1, 0.1, 0.2, 0.02),
         ("Fig. 9 rect 10x4 0.1/0.2/0 gamma 0.16", 10, 4, 0.1, 0.2, 0.16)]


def cell(e) -> str:
    if e.status == OPTIMAL:
        return f"{e.value:.7f}"
    if e.best is not None:
        proved = "" if e.bound is None else f"; proved bound {e.bound:.7f}"
        return f"TL (met {e.best:.7f}{proved})"
    return e.status


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--time-limit", type=float, default=5.0, help="seconds per MILP end")
    ap.add_argument("--skip-alpha", action="store_true")
    ap.add_argument("--deep", type=float, default=0.0,
                    help="seconds of the disk split per end left open (0: cap split only)")
    ap.add_argument("--kinematics", default="auto",
                    choices=("auto", "proportional", "lazy", "big-M"),
                    help="the steady MILP's velocities (verify.ranges.steady_ranges)")
    ap.add_argument("--clock", default="cpu", choices=("cpu", "wall"),
                    help="how --time-limit and --deep are counted (default: CPU seconds)")
    args = ap.parse_args()
    split = True if args.deep <= 0 else args.deep
    kin = args.kinematics
    print(f"time limit {args.time_limit:g} s per end, disk split {args.deep:g} s per open end, "
          f"kinematics {kin}, {args.clock} clock; load {os.getloadavg()[0]:.2f}\n")
    print("| case | run mu_g | own states | all valid steady states | s | CPU s |")
    print("|---|---|---|---|---|---|")
    fig9_run = None
    for name, lx, ly, mpp, mpl, gamma in CASES:
        s = models.System(models.rectangular(lx, ly), mu_pp=mpp, mu_plane=mpl, mu_wall=0.0,
                          gamma=gamma)
        run = models.simulate(s, seed=1)
        if ly == 4:
            fig9_run = run
        t0, c0 = time.perf_counter(), time.process_time()
        r = steady_ranges(run, which="mu_g", time_limit=args.time_limit, split=split,
                          kinematics=kin, clock=args.clock)
        secs, cpu = time.perf_counter() - t0, time.process_time() - c0
        own, every = r.own["mu_g"], r.mu_g
        print(f"| {name} | {run.records[-1].mu_g:.7f} | [{cell(own.lo)}, {cell(own.hi)}] | "
              f"[{cell(every.lo)}, {cell(every.hi)}] | {secs:.1f} | {cpu:.1f} |")
    if args.skip_alpha:
        return 0
    print("\nFig. 9 (rect 10x4, seed 1): mu_g and every angular acceleration over all valid "
          "steady states")
    t0, c0 = time.perf_counter(), time.process_time()
    r = steady_ranges(fig9_run, which="alpha", time_limit=args.time_limit, split=split,
                      kinematics=kin, clock=args.clock)
    total, cpu = time.perf_counter() - t0, time.process_time() - c0
    print("| observable | min | max | run | s (min) | s (max) |")
    print("|---|---|---|---|---|---|")
    decided = by_bound = 0
    for name, rg in r.ranges.items():
        decided += rg.lo.status == OPTIMAL
        decided += rg.hi.status == OPTIMAL
        by_bound += sum(e.status == OPTIMAL and e.note.startswith("proved by")
                        for e in (rg.lo, rg.hi))
        print(f"| {name} | {cell(rg.lo)} | {cell(rg.hi)} | {r.run_values[name]:.7f} | "
              f"{rg.lo.seconds:.2f} | {rg.hi.seconds:.2f} |")
    print(f"\n{decided} of {2 * len(r.ranges)} ends decided ({by_bound} attain the certified "
          f"relaxation bound; the others: HiGHS closed the gap); total {total:.1f} s, "
          f"{cpu:.1f} CPU s, load {os.getloadavg()[0]:.2f} "
          f"(force box R <= {r.U:g}, {'proved' if r.box_proved else 'not proved'})")
    for name, rg in r.ranges.items():
        for e in (rg.lo, rg.hi):
            if e.status != OPTIMAL:
                print(f"{name}: {e.note}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
