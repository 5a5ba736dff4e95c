"""verify.event_ranges where the MILP's box is not proved (LCP(M, 0) has a nonzero solution): the
pattern search's proof of every end (docs/verification.md, "The pattern search"); a script, not
a test; it prints a markdown table.

    python benchmarks/event_search.py [--time-limit 20] [--sizes 2x1,3x1,3x2,4x2]

Cases: rect lx x ly (mu_pp 0.1, mu_plane 0.2, mu_wall 0, gamma 0.1) from rest, the example of
docs/verification.md at 2x1: every contact a non-sliding candidate. Columns: n (the LCP's
size), whether the box is proved, the ends (mu_g and each alpha, min and max) by status, the
largest number of node LPs of one end, CPU seconds (process time) of event_ranges (its MILPs
and the searches) and of the searches alone.
"""

from __future__ import annotations

import argparse
import time
from collections import Counter

from rigidlcp import lcp, models
from rigidlcp.verify.ranges import event, pattern_search


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--time-limit", type=float, default=20.0,
                    help="seconds per MILP, CPU seconds per end of the search")
    ap.add_argument("--sizes", default="2x1,3x1,3x2,4x2")
    args = ap.parse_args()
    spent = {"cpu": 0.0, "nodes": 0}
    inner = pattern_search.extreme

    def timed(*a, **k):  # the searches' own CPU time and node count
        t = time.process_time()
        end, stats = inner(*a, **k)
        spent["cpu"] += time.process_time() - t
        spent["nodes"] = max(spent["nodes"], stats.nodes)
        return end, stats

    event.extreme = timed
    print("| system | n | box proved | ends | most node LPs | CPU s | search CPU s |")
    print("|---|---|---|---|---|---|---|")
    for size in args.sizes.split(","):
        lx, ly = (int(v) for v in size.split("x"))
        s = models.System(models.rectangular(lx, ly), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                          gamma=0.1)
        ep = models.event_problem(s, models.initial_state(s))
        spent.update(cpu=0.0, nodes=0)
        t = time.process_time()
        r = event.event_ranges(ep, lcp.solve(ep.lcp), time_limit=args.time_limit)
        cpu = time.process_time() - t
        ends = Counter(e.status for rr in r.every.values() for e in (rr.lo, rr.hi))
        print(f"| rect {size} from rest | {ep.lcp.n} | {r.bound_proved} | "
              f"{', '.join(f'{k} {v}' for k, v in sorted(ends.items()))} | {spent['nodes']} | "
              f"{cpu:.2f} | {spent['cpu']:.2f} |", flush=True)


if __name__ == "__main__":
    main()
