"""Fig. 9's run to the steady state in process: the face selection's solvers (the default
"small" path, lcp.face_coords, against the "reference" path, the code before issue 13's face
work) and the pivot loop (compiled against numpy), interleaved, same process (a script, not a
test).

    python benchmarks/fig9.py [--repeats 5] [--variants face-min-norm:C:small,...]

Rect 10 x 4, mu_pp = 0.1, mu_plane = 0.2, mu_wall = 0, gamma = 0.16 g, seed 1, method lemke.
A variant is select:loop:solvers (loop C or numpy, `lcp._lemke_kernel.use_compiled`; solvers
small or reference, `lcp.face.face_minimum_norm(..., solvers=...)`). Each repeat runs
`models.simulate` once per variant, alternating; the table gives the median wall time of the
whole run, its CPU time (process_time: less sensitive to other jobs on a shared machine), the
wall time of the Lemke calls and of the face selection (timed by wrapping them), and the
first event whose results (t, states, R, S, mu_g, to 1e-9) differ from the first variant's
run with the same select ("-": none differs).
"""

from __future__ import annotations

import argparse
import functools
import os
import platform
import sys
import time

import numpy as np

from rigidlcp import lcp, models
from rigidlcp.lcp import _lemke_kernel
from rigidlcp.lcp.faces import face as lcp_face

DEFAULT = "face-min-norm:C:small,face-min-norm:C:reference,none:C:-"


def one_run(select: str, compiled: bool, solvers: str) -> tuple[float, float, float, object,
                                                               float]:
    import rigidlcp.models.engine.dense as dense

    spent = {"lemke": 0.0, "face": 0.0}
    solve, face = dense.lcp.solve, dense.face_minimum_norm
    chosen = functools.partial(lcp_face.face_minimum_norm,
                               solvers="small" if solvers == "-" else solvers)

    def timed_solve(*a, **k):
        t0 = time.perf_counter()
        try:
            return solve(*a, **k)
        finally:
            spent["lemke"] += time.perf_counter() - t0

    def timed_face(*a, **k):
        t0 = time.perf_counter()
        try:
            return chosen(*a, **k)
        finally:
            spent["face"] += time.perf_counter() - t0

    previous = _lemke_kernel.use_compiled(compiled)
    dense.face_minimum_norm = timed_face
    lcp.solve = timed_solve
    try:
        system = models.System(models.make_lattice("rect", 10, 4), mu_pp=0.1, mu_plane=0.2,
                               mu_wall=0.0, gamma=0.16)
        t0, c0 = time.perf_counter(), time.process_time()
        run = models.simulate(system, seed=1, select=select)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    finally:
        lcp.solve, dense.face_minimum_norm = solve, face
        _lemke_kernel.use_compiled(previous)
    return wall, spent["lemke"], spent["face"], run, cpu


def first_difference(a, b) -> str:
    """The first event (index) where the runs differ (t, s, R, S, mu_g to 1e-9), or "-"."""
    n = min(a.n_events, b.n_events)
    for name in ("t", "s", "R", "S", "mu_g"):
        x, y = a.array(name)[:n], b.array(name)[:n]
        bad = np.flatnonzero(np.abs(x - y).reshape(n, -1).max(axis=1, initial=0.0) > 1e-9)
        if bad.size:
            n = int(bad[0])
    if n < min(a.n_events, b.n_events) or a.n_events != b.n_events:
        return str(n)
    return "-"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--variants", default=DEFAULT)
    args = ap.parse_args(argv)
    variants = [tuple(v.split(":")) for v in args.variants.split(",")]
    print(f"Fig. 9 (rect 10x4, gamma 0.16, seed 1, lemke), median of {args.repeats} interleaved "
          f"runs; python {platform.python_version()}, {os.cpu_count()} CPUs, load average "
          f"{os.getloadavg()[0]:.2f}; compiled kernel built: {_lemke_kernel.COMPILED}")
    one_run("face-min-norm", True, "small")  # warm-up: imports, first factorizations
    one_run("face-min-norm", True, "reference")
    rows: dict[tuple, list] = {v: [] for v in variants}
    for _ in range(args.repeats):
        for v in variants:
            rows[v].append(one_run(v[0], v[1] == "C", v[2]))
    header = (f"{'select':<14} {'loop':<6} {'solvers':<10} {'events':>6} {'wall s':>7} "
              f"{'cpu s':>6} {'lemke s':>8} {'face s':>7} {'differs at':>10}")
    print(header)
    print("-" * len(header))
    first: dict[str, object] = {}
    for v in variants:
        r = rows[v]
        base = first.setdefault(v[0], r[0][3])
        print(f"{v[0]:<14} {v[1]:<6} {v[2]:<10} {r[0][3].n_events:>6} "
              f"{np.median([x[0] for x in r]):>7.3f} {np.median([x[4] for x in r]):>6.3f} "
              f"{np.median([x[1] for x in r]):>8.3f} "
              f"{np.median([x[2] for x in r]):>7.3f} {first_difference(r[0][3], base):>10}")
    print(f"load average at the end {os.getloadavg()[0]:.2f} (2-core machine shared with other "
          "jobs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
