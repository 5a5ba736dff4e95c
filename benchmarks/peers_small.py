"""Small-n speed against the peers, measured in one run (a script, not a test): issue 23's
targets.

For each n in --sizes, --count seeded LCPs M = A A^T + 0.1 I, q ~ N(0, 1) (as
benchmarks/lcp_dense.py) are solved by Lemke in every way below; each way's time is the mean
per call over the set (each problem called --inner times in a row: warm caches, as in a user's
loop), measured in --repeats passes, the ways interleaved pass by pass
so that all see the same machine load:

  natural       lcp.solve(lcp.LCP(M, q))            (the problem built and validated each call)
  prebuilt      lcp.solve(P)                        (P built once)
  solve_many    lcp.solve_many(problems) / count    (the set, each problem --inner times in a
                                                     row as for the others, in one call; the
                                                     previous pass's result freed before the
                                                     clock starts)
  freeing       that result's freeing / count       (timed apart: the --count x --inner
                                                     Solutions of one call, freed at once;
                                                     a single call frees its one Solution
                                                     inside its own timing, hot in cache)
  QuantEcon     quantecon.optimize.lcp_lemke(M, q)  (numba, warm: compiled before timing)
  Sic. natural  Siconos: options, sn.LCP(M, q), linearComplementarity_driver (all timed)
  Sic. driver   Siconos: linearComplementarity_driver on a prebuilt problem and options
  Sic. bare     Siconos: lcp_lexicolemke on a prebuilt problem and options (the solver alone)

Siconos runs in a /usr/bin/python3 subprocess (Debian's python3-siconos;
benchmarks/_siconos_lemke.py) and times itself there; QuantEcon runs in this process. A peer
that is not installed is skipped with a note. Every peer's answer is judged by rigidlcp's own
check (verify.certify): "judged ok" counts the answers that pass. rigidlcp's answers carry
their backward error and forward error bound (lcp.accuracy), checked before they are returned;
the peers' are not checked by the peers.

    python benchmarks/peers_small.py [--sizes 10,20,30,50,100] [--count 20] [--repeats 5]
                                     [--inner auto] [--seed 0] [--clock wall|cpu]

--clock cpu times every way (Siconos's too, in its subprocess) by the CPU time of the timing
thread: on a machine shared with other jobs, wall times swing by tens of percent with the load.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from rigidlcp import lcp

sys.path.insert(0, str(Path(__file__).parent))
from batch import _accepted  # noqa: E402
from lcp_dense import Siconos  # noqa: E402

WAYS = ("natural", "prebuilt", "solve_many", "freeing", "QuantEcon", "Sic. natural",
        "Sic. driver", "Sic. bare")
#: solve_many with the freeing of its result: what a loop that drops each result pays (the
#: way this script timed solve_many before session 10)
MANY_FREED = "solve_many+freeing"


def problem_set(n: int, count: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng([seed, n, count])
    Ms, qs = np.empty((count, n, n)), np.empty((count, n))
    for i in range(count):
        A = rng.standard_normal((n, n))
        Ms[i], qs[i] = A @ A.T + 0.1 * np.eye(n), rng.standard_normal(n)
    return Ms, qs


def _quantecon():
    try:
        from quantecon.optimize import lcp_lemke
    except Exception as exc:  # noqa: BLE001 - any import failure means "skip"
        return None, f"quantecon not importable ({type(exc).__name__}: {exc})"
    import quantecon

    return lcp_lemke, quantecon.__version__


#: --clock: "wall" (time.perf_counter) or "cpu" (time.thread_time: the CPU time of the calling
#: thread, which a loaded machine's waits do not inflate; a BLAS call that numpy hands to
#: OpenBLAS's other threads -- its M z from n ~ 96 on -- is then counted only for its own part)
CLOCKS = {"wall": time.perf_counter, "cpu": time.thread_time}
clock = CLOCKS["wall"]


def _per_call(f, args_list, inner: int) -> float:
    total = 0.0
    for args in args_list:
        t0 = clock()
        for _ in range(inner):
            f(*args)
        total += clock() - t0
    return total / (len(args_list) * inner)


def measure(n: int, count: int, repeats: int, inner: int, seed: int, sic: Siconos, qe,
            tmp: str, stat=min, clock_name: str = "wall") -> dict:
    Ms, qs = problem_set(n, count, seed)
    pairs = [(np.ascontiguousarray(Ms[i]), np.ascontiguousarray(qs[i])) for i in range(count)]
    problems = [lcp.LCP(M, q) for M, q in pairs]
    Ms_path, qs_path = Path(tmp, f"Ms{n}.npy"), Path(tmp, f"qs{n}.npy")
    np.save(Ms_path, Ms)
    np.save(qs_path, qs)
    max_iter = 1000 + 100 * n
    lcp.solve_many(problems[:2])  # warm-up: imports, the rounding probe
    lcp.solve(problems[0])
    if qe is not None:
        qe(*pairs[0], max_iter=max_iter)  # numba compiles here (not timed)
    repeated = [p for p in problems for _ in range(inner)]
    times: dict[str, list[float]] = {w: [] for w in WAYS}
    answers: dict[str, list] = {}
    many = None
    for _ in range(repeats):
        times["natural"].append(_per_call(lambda M, q: lcp.solve(lcp.LCP(M, q)), pairs, inner))
        times["prebuilt"].append(_per_call(lcp.solve, [(p,) for p in problems], inner))
        if many is not None:  # the previous pass's Solutions freed, timed apart
            t0 = clock()
            many = None
            times["freeing"].append((clock() - t0) / (inner * count))
        t0 = clock()  # the same sequence as the others: each problem inner times
        many = lcp.solve_many(repeated)
        times["solve_many"].append((clock() - t0) / (inner * count))
        if qe is not None:
            times["QuantEcon"].append(_per_call(lambda M, q: qe(M, q, max_iter=max_iter),
                                                pairs, inner))
        if sic.available:
            for way, how in (("Sic. natural", "natural"), ("Sic. driver", "driver"),
                             ("Sic. bare", "bare")):
                sic.proc.stdin.write(json.dumps({"set_Ms": str(Ms_path), "set_qs": str(qs_path),
                                                 "how": how, "inner": inner,
                                                 "max_iter": max_iter,
                                                 "clock": clock_name}) + "\n")
                sic.proc.stdin.flush()
                out = json.loads(sic.proc.stdout.readline())
                times[way].append(out["per_call"])
                answers[way] = out["zs"]
    many = many[::inner]
    answers["natural"] = [s.z for s in many]
    if qe is not None:
        answers["QuantEcon"] = [qe(M, q, max_iter=max_iter).z for M, q in pairs]
    judged = {w: sum(_accepted(p, list(z)) for p, z in zip(problems, zs))
              for w, zs in answers.items()}
    solved = sum(s.status == "solved" for s in many)
    out = {w: float(stat(t)) for w, t in times.items() if t}
    if "freeing" in out:
        out[MANY_FREED] = out["solve_many"] + out["freeing"]
    return {"n": n, "times": out, "judged": judged, "solved": solved, "count": count}


def report(rows: list[dict]) -> None:
    us = "us"
    print()
    head = f"{'n':>4} " + " ".join(f"{w + ' [' + us + ']':>17}" for w in WAYS)
    print(head)
    print("-" * len(head))
    for r in rows:
        t = r["times"]
        print(f"{r['n']:>4} " + " ".join(
            f"{1e6 * t[w]:>17.2f}" if w in t else f"{'-':>17}" for w in WAYS))
    print()
    print("Ratios (rigidlcp / peer; below 1: rigidlcp faster). Targets of issue 23: at n = 10 "
          "natural / Sic. driver <= 1.5 and natural / QuantEcon < 1;")
    print("solve_many / Sic. bare <= 1 (judged with the freeing of its result: "
          f"{MANY_FREED}); from n = 30, natural / every peer's natural call < 1. "
          "(Sic. natural: the driver with Siconos's objects built in the call.)")
    cols = [("natural", "Sic. natural"), ("natural", "Sic. driver"), ("natural", "QuantEcon"),
            ("prebuilt", "Sic. bare"), ("solve_many", "Sic. bare"), (MANY_FREED, "Sic. bare")]
    head = f"{'n':>4} " + " ".join(f"{a + '/' + b:>30}" for a, b in cols)
    print(head)
    print("-" * len(head))
    for r in rows:
        t = r["times"]
        print(f"{r['n']:>4} " + " ".join(
            f"{t[a] / t[b]:>30.2f}" if a in t and b in t else f"{'-':>30}" for a, b in cols))
    print()
    print("Answers judged by rigidlcp's check (verify.certify), out of the set:")
    for r in rows:
        parts = ", ".join(f"{w} {k}/{r['count']}" for w, k in r["judged"].items())
        print(f"  n = {r['n']}: rigidlcp solved {r['solved']}/{r['count']}; judged ok: {parts}")


def lcp_construction(sizes: list[int]) -> None:
    """lcp.LCP(M, q)'s quick route for plain finite float64 data (LCP.__init__ in C) against the
    general validation it skips (forced by the Python __init__ with its quick route off), best
    of 3 x 5 x 20000 calls, interleaved."""
    import timeit

    from rigidlcp.lcp.problems import problem as module

    quick, c_init = module._init, module.LCP.__init__
    if quick is None:
        print("lcp.LCP(M, q): no quick route (the C extension is not built)")
        return
    try:
        for n in sizes:
            rng = np.random.default_rng(n)
            A = rng.standard_normal((n, n))
            M, q = A @ A.T + 0.1 * np.eye(n), rng.standard_normal(n)
            best = {"general": np.inf, "quick": np.inf}
            for _ in range(3):
                for name, check in (("general", None), ("quick", quick)):
                    module._init = check  # the general route: the Python __init__ without it
                    module.LCP.__init__ = c_init if check else module._py_init
                    t = min(timeit.repeat(lambda: lcp.LCP(M, q), number=20000, repeat=5))  # noqa: B023
                    best[name] = min(best[name], t / 20000)
            print(f"lcp.LCP(M, q) at n = {n}: general validation {1e6 * best['general']:.2f} us, "
                  f"quick route {1e6 * best['quick']:.2f} us")
    finally:
        module._init, module.LCP.__init__ = quick, c_init


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="10,20,30,50,100")
    ap.add_argument("--count", type=int, default=20, help="problems per size")
    ap.add_argument("--repeats", type=int, default=5, help="interleaved passes (median)")
    ap.add_argument("--inner", default="auto",
                    help="calls per problem in a row: an integer or 'auto' (about 2000 / n)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--stat", choices=("min", "median"), default="min",
                    help="over the passes (default: %(default)s)")
    ap.add_argument("--clock", choices=tuple(CLOCKS), default="wall",
                    help="wall time, or the CPU time of the timing thread, every way the same "
                         "(default: %(default)s)")
    args = ap.parse_args(argv)
    global clock
    clock = CLOCKS[args.clock]
    sizes = [int(s) for s in args.sizes.split(",") if s.strip()]
    qe, qe_version = _quantecon()
    sic = Siconos()
    print("Small-n Lemke against the peers, one run: M = A A^T + 0.1 I, q ~ N(0, 1); mean "
          f"{args.clock} time per call over {args.count} problems, {args.stat} of "
          f"{args.repeats} interleaved passes")
    print(f"python {platform.python_version()}, numpy {np.__version__}, {os.cpu_count()} CPUs, "
          f"load average at start {os.getloadavg()[0]:.2f}; QuantEcon: "
          f"{qe_version if qe is not None else 'skipped: ' + qe_version}; Siconos: "
          f"{'python3-siconos ' + sic.version if sic.available else 'skipped: ' + sic.reason}")
    rows = []
    with tempfile.TemporaryDirectory(prefix="peers_small_") as tmp:
        for n in sizes:
            inner = max(1, round(2000 / n)) if args.inner == "auto" else int(args.inner)
            rows.append(measure(n, args.count, args.repeats, inner, args.seed, sic, qe, tmp,
                                min if args.stat == "min" else np.median, args.clock))
    report(rows)
    lcp_construction(sizes)
    print(f"load average at end {os.getloadavg()[0]:.2f}; the machine was shared with other jobs")
    if sic.available:
        sic.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
