"""Where `lcp.solve_many`'s time goes at small n (a script, not a test): issue 23.

For each n in --sizes, the 20 problems of benchmarks/peers_small.py (M = A A^T + 0.1 I,
q ~ N(0, 1)), each repeated round(2000 / n) times in a row as peers_small's solve_many way does,
are timed in each of these ways, by the CPU time of the calling thread (`time.thread_time`),
best of --repeats passes, us per problem:

  solve_many       lcp.solve_many(problems)                  (the previous result freed
                                                              inside the timing, as in
                                                              peers_small)
  collector off    the same with gc.disable() around the call (what the collector's passes
                                                              over the new Solutions cost)
  stack_lcps       the grouping and stacking in C (lcp/_batch_solutions.h)
  _lemke_batch     lcp.batch._lemke_batch on the stacks       (all below, and the Python
                                                              around them)
  solve_batch      the C loop: equilibration, Lemke, z back, the acceptance (`acc`)
  M Z              numpy's matmul of the stack
  measure          _lemke_kernel.measure_batch
  batch_solutions  the verdicts and the Solutions in C

"objects" (solve_many less stack_lcps, solve_batch, M Z and measure) is what the per-problem
Python objects and the glue cost: a result that built no object per problem could save at most
that much.

    python benchmarks/batch_parts.py [--sizes 10,30] [--repeats 7]
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
import time
from pathlib import Path

import numpy as np

import rigidlcp.lcp._lemke_kernel as kernel
from rigidlcp import lcp
from rigidlcp.lcp import batch
from rigidlcp.lcp.acceptance.accuracy import FERR_TOL
from rigidlcp.lcp.acceptance.residual import TOL
from rigidlcp.lcp.solvers.lemke import DEFAULT_TOL

sys.path.insert(0, str(Path(__file__).parent))
from peers_small import problem_set  # noqa: E402

clock = time.thread_time


def best(f, repeats: int, k: int) -> float:
    """The best of `repeats` timings of f(), in us per problem (its result freed outside)."""
    out = np.inf
    for _ in range(repeats):
        t0 = clock()
        x = f()
        out = min(out, clock() - t0)
        del x
    return 1e6 * out / k


def parts(n: int, repeats: int) -> dict[str, float]:
    Ms, qs = problem_set(n, 20, 0)
    problems = [lcp.LCP(np.ascontiguousarray(Ms[i]), np.ascontiguousarray(qs[i]))
                for i in range(20)]
    repeated = [p for p in problems for _ in range(max(1, round(2000 / n)))]
    k = len(repeated)
    lcp.solve_many(repeated[:2])  # warm-up
    t: dict[str, float] = {}
    many, t["solve_many"] = None, np.inf
    for _ in range(repeats):  # as peers_small: the previous result is freed in the timing
        t0 = clock()
        many = lcp.solve_many(repeated)
        t["solve_many"] = min(t["solve_many"], 1e6 * (clock() - t0) / k)
    del many
    was = gc.isenabled()
    gc.disable()
    try:
        t["collector off"] = best(lambda: lcp.solve_many(repeated), repeats, k)
    finally:
        if was:
            gc.enable()
    _n, _idx, SM, SQ = kernel._lemke_c.stack_lcps(repeated, lcp.LCP)[0]
    t["stack_lcps"] = best(lambda: kernel._lemke_c.stack_lcps(repeated, lcp.LCP), repeats, k)
    t["_lemke_batch"] = best(lambda: batch._lemke_batch(SM, SQ, True, {}, None), repeats, k)
    Z, basic = np.empty((k, n)), np.empty((k, n), dtype=np.int8)
    codes, pivots = np.empty(k, dtype=np.int64), np.empty(k, dtype=np.int64)
    acc, d, mmax = np.empty((k, 4)), np.ones(n), np.empty(k)
    t["solve_batch"] = best(lambda: kernel.solve_batch(SM, SQ, d, DEFAULT_TOL, 1000 + 100 * n,
                                                       Z, basic, codes, pivots,
                                                       equilibrate=True, acc=acc, mmax=mmax),
                            repeats, k)
    t["M Z"] = best(lambda: np.matmul(SM, Z[:, :, None])[:, :, 0], repeats, k)
    W = np.matmul(SM, Z[:, :, None])[:, :, 0]
    t["measure"] = best(lambda: kernel.measure_batch(SM, SQ, Z, W.copy(), mmax), repeats, k)
    measured = kernel.measure_batch(SM, SQ, Z, W, mmax)  # W becomes M Z + q
    t["batch_solutions"] = best(lambda: kernel._lemke_c.batch_solutions(
        Z, W, basic, codes, pivots, acc, measured, TOL, FERR_TOL, True), repeats, k)
    t["objects"] = t["solve_many"] - sum(t[w] for w in ("stack_lcps", "solve_batch", "M Z",
                                                        "measure"))
    return t


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="10,30")
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args(argv)
    if not kernel.enabled():
        print("the C extension is not built or is off: no batch loop to take apart")
        return 0
    print(f"solve_many's parts, us of CPU per problem, best of {args.repeats}; load average at "
          f"start {os.getloadavg()[0]:.2f}")
    rows = [(n, parts(n, args.repeats)) for n in
            (int(s) for s in args.sizes.split(",") if s.strip())]
    names = list(rows[0][1])
    print(f"{'n':>4} " + " ".join(f"{w:>15}" for w in names))
    for n, t in rows:
        print(f"{n:>4} " + " ".join(f"{t[w]:>15.3f}" for w in names))
    print(f"load average at end {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
