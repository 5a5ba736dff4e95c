"""Batch benchmark (a script, not a test): problems per second of `lcp.solve_many` against a
loop of `lcp.solve` and a loop of Siconos's `lcp_lexicolemke` on the same problems.

    python benchmarks/batch.py [--sizes 10,50] [--count 2000] [--repeats 5] [--seed 0]

For each n, --count seeded random LCPs M = A A^T + 0.1 I, q ~ N(0, 1) (as benchmarks/lcp_dense.py)
are solved by Lemke three ways, each --repeats times, interleaved so that all three see the same
machine load: `lcp.solve_many(problems, "lemke")`, `[lcp.solve(p, "lemke") for p in problems]`,
and Siconos in a /usr/bin/python3 subprocess (benchmarks/_siconos_lemke.py), timed inside that
process: the whole loop (problem object, options, call: what a user's loop costs) and the solver
calls alone. The table gives medians; the pivot counts of the three are compared problem by
problem (Siconos counts one pivot less: it skips the first, z0 entering).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from rigidlcp import lcp

sys.path.insert(0, str(Path(__file__).parent))
from lcp_dense import Siconos  # noqa: E402


def problems_of(n: int, count: int, seed: int) -> list[lcp.LCP]:
    rng = np.random.default_rng([seed, n, count])
    out = []
    for _ in range(count):
        A = rng.standard_normal((n, n))
        out.append(lcp.LCP(A @ A.T + 0.1 * np.eye(n), rng.standard_normal(n)))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="10,50")
    ap.add_argument("--count", type=int, default=2000, help="problems per size")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    from rigidlcp.lcp import _lemke_kernel

    sic = Siconos()
    print(f"Batch benchmark: {args.count} LCPs per size (M = A A^T + 0.1 I, q ~ N(0, 1)), "
          f"Lemke; median of {args.repeats} interleaved runs")
    print(f"python {platform.python_version()}, numpy {np.__version__}, {os.cpu_count()} CPUs, "
          f"load average at start {os.getloadavg()[0]:.2f}; compiled kernel: "
          f"{_lemke_kernel.enabled()}; Siconos: {sic.version if sic.available else sic.reason}")
    header = (f"{'n':>4} {'way':<28} {'median s':>9} {'problems/s':>11} {'us/problem':>11} "
              f"{'x Siconos loop':>14} {'x Siconos calls':>15}")
    print(header)
    print("-" * len(header))
    with tempfile.TemporaryDirectory(prefix="batch_") as tmp:
        for n in sizes:
            problems = problems_of(n, args.count, args.seed)
            Ms_path, qs_path = Path(tmp, f"Ms{n}.npy"), Path(tmp, f"qs{n}.npy")
            np.save(Ms_path, np.stack([p.M for p in problems]))
            np.save(qs_path, np.stack([p.q for p in problems]))
            t_many, t_loop, s_loop, s_calls = [], [], [], []
            lcp.solve_many(problems[:10])  # warm-up (imports, rounding probe)
            for _ in range(args.repeats):
                t0 = time.perf_counter()
                many = lcp.solve_many(problems, "lemke")
                t_many.append(time.perf_counter() - t0)
                t0 = time.perf_counter()
                loop = [lcp.solve(p, "lemke") for p in problems]
                t_loop.append(time.perf_counter() - t0)
                if sic.available:
                    assert sic.proc is not None
                    import json

                    sic.proc.stdin.write(json.dumps({"Ms": str(Ms_path), "qs": str(qs_path)})
                                         + "\n")
                    sic.proc.stdin.flush()
                    out = json.loads(sic.proc.stdout.readline())
                    s_loop.append(out["loop"])
                    s_calls.append(out["calls"])
            assert all(s.status == "solved" for s in many), "a batch answer is not solved"
            worst = max(s.residual for s in many)
            same_loop = all(a.iterations == b.iterations and np.array_equal(a.z, b.z)
                            for a, b in zip(many, loop))
            ref_loop = float(np.median(s_loop)) if s_loop else float("nan")
            ref_calls = float(np.median(s_calls)) if s_calls else float("nan")
            rows = [("lcp.solve_many", t_many), ("loop of lcp.solve", t_loop)]
            if s_loop:
                rows += [("Siconos loop (objects+call)", s_loop), ("Siconos calls only", s_calls)]
            for name, times in rows:
                med = float(np.median(times))
                print(f"{n:>4} {name:<28} {med:>9.4f} {args.count / med:>11.0f} "
                      f"{1e6 * med / args.count:>11.2f} {med / ref_loop:>14.2f} "
                      f"{med / ref_calls:>15.2f}")
            pivots = np.array([s.iterations for s in many])
            note = ""
            if s_loop:
                sp = np.array(out["pivots"]) + 1
                moved = pivots > 0  # q >= 0: no pivot in rigidlcp, Siconos reports 0 (+1)
                bad = sum(not _accepted(p, z) for p, z in zip(problems, out["zs"]))
                note = (f"; pivots equal to Siconos's (+1) on "
                        f"{int(np.sum(pivots[moved] == sp[moved]))}/{int(moved.sum())} with "
                        f"q not >= 0, Siconos failures {out['failures']} (its info), Siconos "
                        f"answers failing rigidlcp's check {bad}")
            print(f"     solve_many = loop of solve (z, pivots) on all: {same_loop}; worst "
                  f"residual {worst:.1e}; median pivots {int(np.median(pivots))}{note}")
    print(f"load average at end {os.getloadavg()[0]:.2f}; the machine (2 cores) was shared "
          "with other jobs")
    sic.close()
    return 0


def _accepted(problem: lcp.LCP, z: list[float]) -> bool:
    """A Siconos answer judged by rigidlcp's own check (verify.certify), not by its info."""
    from rigidlcp.verify.certificates.certify import certify

    answer = lcp.Solution(z=np.asarray(z, dtype=float), w=np.zeros(0), status="solved",
                          method="siconos")
    with np.errstate(all="ignore"):
        return certify(problem, answer, uniqueness="none").accepted


if __name__ == "__main__":
    sys.exit(main())
