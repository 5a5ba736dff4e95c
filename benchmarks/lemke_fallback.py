"""The cost of a float Lemke run whose ambiguous ratio ties are decided exactly
(lcp.lemke_exact.ExactTies), against the compiled loop (a script, not a test).

`lcp.lemke` uses it where the float run cycled and n is too large for the exact run
(lcp.lemke_exact.EXACT_MAX_N < n <= EXACT_TIES_MAX_N), before it restarts with coarser ties;
it was tried as the rerun of every problem the compiled run did not solve, and this table
is why it is not: the numpy loop it needs costs 10-40 times the compiled loop on problems
that end on a ray, for no outcome changed on these problems. It prints, per kind and n, the CPU
time per problem of the two runs (`_Lemke.run` compiled; numpy with ExactTies), the number of
exact decisions, and whether the outcomes (status, pivots, basis) agree:

    python benchmarks/lemke_fallback.py [--seeds 3]

Kinds: "general" (M with N(0, 1) entries: most end on a ray), "integer" (entries in -3..3,
q in -3..3: many exact ties), "friction-like" (q with equal entries and zeros: many rows
tied at theta = 0).
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from rigidlcp.lcp.solvers.lemke import _Lemke
from rigidlcp.lcp.solvers.lemke_exact import ExactTies


def problem(kind: str, n: int, rng: np.random.Generator):
    if kind == "general":
        return rng.standard_normal((n, n)), rng.standard_normal(n)
    if kind == "integer":
        M = rng.integers(-3, 4, (n, n)).astype(float)
        M[np.diag_indices(n)] = rng.integers(1, 4, n)
        return M, rng.integers(-3, 4, n).astype(float)
    A = rng.standard_normal((n, n // 2))  # friction-like: PSD part, skew part, ties in q
    M = A @ A.T + 0.5 * (rng.standard_normal((n, n)) - rng.standard_normal((n, n)).T)
    q = np.where(np.arange(n) % 3 == 0, -1.0, 0.0)
    return M, q


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3)
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f}; CPU time per problem (time.process_time)")
    print(f"{'kind':>14} {'n':>4} {'compiled [ms]':>14} {'exact ties [ms]':>16} "
          f"{'exact decisions':>16} {'same outcome':>13}")
    for kind in ("general", "integer", "friction-like"):
        for n in (10, 30, 60, 100, 150):
            t_c = t_e = 0.0
            decided = same = 0
            for seed in range(args.seeds):
                M, q = problem(kind, n, np.random.default_rng(seed))
                d = np.ones(n)
                t0 = time.process_time()
                a = _Lemke(M, q, d, 1e-10).run(1000 + 100 * n)
                t1 = time.process_time()
                X = ExactTies(M, q, d)
                b = _Lemke(M, q, d, 1e-10, X).run(1000 + 100 * n)
                t2 = time.process_time()
                t_c, t_e = t_c + t1 - t0, t_e + t2 - t1
                decided += X.decided
                same += (a.status, a.iterations) == (b.status, b.iterations) and \
                    np.array_equal(a.basis, b.basis)
            k = args.seeds
            print(f"{kind:>14} {n:>4} {1e3 * t_c / k:>14.2f} {1e3 * t_e / k:>16.2f} "
                  f"{decided:>16} {same:>10}/{k}")


if __name__ == "__main__":
    main()
