"""Fig. 9's run to the steady state in process: the compiled Lemke loop against the numpy loop
(the code before issue 13), interleaved, same process (a script, not a test).

    python benchmarks/fig9.py [--repeats 5] [--selects face-min-norm,none]

Rect 10 x 4, mu_pp = 0.1, mu_plane = 0.2, mu_wall = 0, gamma = 0.16 g, seed 1, method lemke.
Each repeat runs `models.simulate` once with the compiled loop and once with the numpy loop
(`lcp._lemke_kernel.use_compiled`), alternating; the table gives the median wall time of the
whole run, of the Lemke calls and of the face selection (timed by wrapping them), and whether
the two runs agree (events, states, mu_g to 1e-12).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time

import numpy as np

from rigidlcp import lcp, models
from rigidlcp.lcp import _lemke_kernel


def one_run(select: str, compiled: bool) -> tuple[float, float, float, object]:
    import rigidlcp.models.engine.dense as dense

    spent = {"lemke": 0.0, "face": 0.0}
    solve, face = dense.lcp.solve, dense.face_minimum_norm

    def timed_solve(*a, **k):
        t0 = time.perf_counter()
        try:
            return solve(*a, **k)
        finally:
            spent["lemke"] += time.perf_counter() - t0

    def timed_face(*a, **k):
        t0 = time.perf_counter()
        try:
            return face(*a, **k)
        finally:
            spent["face"] += time.perf_counter() - t0

    previous = _lemke_kernel.use_compiled(compiled)
    dense.face_minimum_norm = timed_face
    lcp.solve = timed_solve
    try:
        system = models.System(models.make_lattice("rect", 10, 4), mu_pp=0.1, mu_plane=0.2,
                               mu_wall=0.0, gamma=0.16)
        t0 = time.perf_counter()
        run = models.simulate(system, seed=1, select=select)
        wall = time.perf_counter() - t0
    finally:
        lcp.solve, dense.face_minimum_norm = solve, face
        _lemke_kernel.use_compiled(previous)
    return wall, spent["lemke"], spent["face"], run


def same(a, b) -> bool:
    return (a.status == b.status and a.n_events == b.n_events
            and np.array_equal(a.array("s"), b.array("s"))
            and np.allclose(a.array("t"), b.array("t"), rtol=0, atol=1e-12)
            and np.allclose(a.array("mu_g"), b.array("mu_g"), rtol=0, atol=1e-12))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--selects", default="face-min-norm,none")
    args = ap.parse_args(argv)
    print(f"Fig. 9 (rect 10x4, gamma 0.16, seed 1, lemke), median of {args.repeats} interleaved "
          f"runs; python {platform.python_version()}, {os.cpu_count()} CPUs, load average "
          f"{os.getloadavg()[0]:.2f}; compiled kernel built: {_lemke_kernel.COMPILED}")
    one_run("none", True)  # warm-up: imports, first factorizations
    header = (f"{'select':<14} {'pivot loop':<10} {'events':>6} {'wall s':>7} {'lemke s':>8} "
              f"{'face s':>7} {'same run':>8}")
    print(header)
    print("-" * len(header))
    for select in args.selects.split(","):
        rows: dict[bool, list] = {True: [], False: []}
        for _ in range(args.repeats):
            for compiled in (True, False):
                rows[compiled].append(one_run(select, compiled))
        agree = same(rows[True][0][3], rows[False][0][3])
        for compiled in (True, False):
            r = rows[compiled]
            print(f"{select:<14} {'C' if compiled else 'numpy':<10} {r[0][3].n_events:>6} "
                  f"{np.median([x[0] for x in r]):>7.3f} {np.median([x[1] for x in r]):>8.3f} "
                  f"{np.median([x[2] for x in r]):>7.3f} {str(agree):>8}")
    print(f"load average at the end {os.getloadavg()[0]:.2f} (2-core machine shared with other "
          "jobs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
