"""Where the natural call's time goes at small n (a script, not a test): issue 23.

For each n in --sizes, the 20 problems of benchmarks/peers_small.py (M = A A^T + 0.1 I,
q ~ N(0, 1)) are timed in each of these ways, by the CPU time of the calling thread
(`time.thread_time`), best of --repeats passes, us per call:

  natural        lcp.solve(lcp.LCP(M, q))
  prebuilt       lcp.solve(P)
  LCP            lcp.LCP(M, q)
  solve_lemke    lcp.solvers.fast_lemke.solve_lemke(P)   (the fast path in Python, without
                                                         lcp.solve)
  entry          lcp.solvers.fast_lemke.entry(P)         (the same steps in C, solve_default:
                                                         what lcp.solve(P) calls)
  C call         its one C call, _lemke_c.solve_lcp       (solve, acceptance, M z, measure,
                                                         the Solution)
  solve+accept   _lemke_c.solve_accept                   (the solve and its acceptance)
  solve          _lemke_c.solve_eq                       (the solve alone)
  np.dot         np.dot(M, q, w)                         (numpy's M z from Python)

    python benchmarks/small_parts.py [--sizes 10,30,50] [--repeats 7]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from rigidlcp import lcp
from rigidlcp.lcp import _lemke_kernel as kernel
from rigidlcp.lcp.solvers import fast_lemke

sys.path.insert(0, str(Path(__file__).parent))
from peers_small import problem_set  # noqa: E402


def per_call(f, args_list, inner: int, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        t0 = time.thread_time()
        for args in args_list:
            for _ in range(inner):
                f(*args)
        best = min(best, (time.thread_time() - t0) / (len(args_list) * inner))
    return 1e6 * best


def parts(n: int, repeats: int) -> list[float]:
    """The us per call of each way (module docstring), in its order, at size n."""
    c = kernel._lemke_c
    Ms, qs = problem_set(n, 20, 0)
    pairs = [(np.ascontiguousarray(Ms[i]), np.ascontiguousarray(qs[i])) for i in range(20)]
    problems = [(lcp.LCP(M, q),) for M, q in pairs]
    inner, max_iter = max(1, round(2000 / n)), 1000 + 100 * n
    z, basis, w = np.empty(n), np.empty(n, dtype=np.intp), np.empty(n)
    tol, upto = fast_lemke.DEFAULT_TOL, fast_lemke._UPTO
    calls = (
        (lambda M, q: lcp.solve(lcp.LCP(M, q)), pairs),
        (lcp.solve, problems),
        (lcp.LCP, pairs),
        (fast_lemke.solve_lemke, problems),
        (fast_lemke.entry, problems),
        (lambda M, q: c.solve_lcp(M, q, tol, max_iter, upto), pairs),
        (lambda M, q: c.solve_accept(M, q, tol, max_iter, z, basis), pairs),
        (lambda M, q: c.solve_eq(M, q, None, None, None, tol, max_iter, z, basis), pairs),
        (lambda M, q: np.dot(M, q, w), pairs),
    )
    return [per_call(f, a, inner, repeats) for f, a in calls]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="10,30,50")
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args(argv)
    if fast_lemke._solve_lcp is None:
        print("the C extensions are not built: nothing to take apart")
        return 0
    print(f"CPU us per call, best of {args.repeats}; load average {os.getloadavg()[0]:.2f}; "
          f"M z by numpy's own gemv from C: {kernel.numpy_gemv()}")
    ways = ("natural", "prebuilt", "LCP", "solve_lemke", "entry", "C call", "solve+accept",
            "solve", "np.dot")
    print(f"{'n':>4} " + " ".join(f"{w:>13}" for w in ways))
    for n in [int(s) for s in args.sizes.split(",") if s.strip()]:
        times = parts(n, args.repeats)
        print(f"{n:>4} " + " ".join(f"{t:>13.2f}" for t in times), flush=True)
    print(f"load average at end {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
