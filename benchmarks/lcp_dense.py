"""Dense LCP benchmark (a script, not a test).

For n in --sizes, a seeded random LCP M = A A^T + 0.1 I, q ~ N(0, 1) (A standard normal) is
solved by every registered method of `lcp.methods()`; the table gives the median wall time of
`lcp.solve(problem, method=...)` over --repeats runs, the iterations (pivots for the pivoting
methods, sweeps or iterations for the others), the status and the residual max|min(z, w)|.
Methods are skipped when they refuse the problem (NotApplicable), are not implemented, exceed
their registered n limit, or took more than --budget seconds on a smaller n.

When /usr/bin/python3 can import siconos.numerics (Debian's python3-siconos), Siconos's
lexicographic Lemke (lcp_lexicolemke, SICONOS_LCP_LEMKE) solves the same problems in a
subprocess (benchmarks/_siconos_lemke.py; matrices passed as .npy files; only the solve call is
timed), interleaved run by run with rigidlcp's `lemke` so that both see the same machine load,
and a second table gives the time ratio rigidlcp/Siconos and both pivot counts (for lemke, and
for the other methods named by --against).

    python benchmarks/lcp_dense.py [--sizes 10,50,100,200,500,1000] [--repeats 5] [--seed 0]
                                   [--methods lemke,...] [--inner 1|N|auto]
                                   [--against lemke,pivoting]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from rigidlcp import lcp

SYSTEM_PYTHON = "/usr/bin/python3"
HELPER = Path(__file__).with_name("_siconos_lemke.py")


def dense_problem(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """M = A A^T + 0.1 I, q ~ N(0, 1), from the generator seeded with (seed, n)."""
    rng = np.random.default_rng([seed, n])
    A = rng.standard_normal((n, n))
    return A @ A.T + 0.1 * np.eye(n), rng.standard_normal(n)


class Siconos:
    """Siconos's lexicographic Lemke in a long-lived /usr/bin/python3 subprocess."""

    def __init__(self) -> None:
        self.proc: subprocess.Popen | None = None
        self.reason = ""
        self.version = ""
        if not os.path.exists(SYSTEM_PYTHON):
            self.reason = f"{SYSTEM_PYTHON} not found"
            return
        self.proc = subprocess.Popen(
            [SYSTEM_PYTHON, str(HELPER)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            text=True, bufsize=1,
        )
        hello = self.proc.stdout.readline()
        ready = json.loads(hello) if hello else {"ready": False, "error": "helper died"}
        if not ready.get("ready"):
            self.reason = f"{SYSTEM_PYTHON} cannot import siconos.numerics ({ready.get('error')})"
            self.close()
            return
        self.version = _debian_version("python3-siconos")

    @property
    def available(self) -> bool:
        return self.proc is not None

    def solve(self, M_path: Path, q_path: Path, max_iter: int, inner: int = 1) -> dict:
        assert self.proc is not None
        req = {"M": str(M_path), "q": str(q_path), "max_iter": max_iter, "inner": inner}
        self.proc.stdin.write(json.dumps(req) + "\n")
        self.proc.stdin.flush()
        return json.loads(self.proc.stdout.readline())

    def close(self) -> None:
        if self.proc is not None:
            self.proc.stdin.close()
            self.proc.wait(timeout=60)
            self.proc = None


def _debian_version(package: str) -> str:
    if shutil.which("dpkg-query") is None:
        return "?"
    out = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", package],
                         capture_output=True, text=True, check=False)
    return out.stdout.strip() or "?"


def _time_solve(problem: lcp.LCP, method: str, inner: int = 1
                ) -> tuple[float, float, lcp.Solution]:
    """Wall and CPU (process) seconds of one lcp.solve call (the mean of `inner` calls in a
    row: warm caches, as in a loop over problems)."""
    c0, t0 = time.process_time(), time.perf_counter()
    for _ in range(inner):
        sol = lcp.solve(problem, method=method)
    return (time.perf_counter() - t0) / inner, (time.process_time() - c0) / inner, sol


def judged(problem: lcp.LCP, z: list[float]) -> str:
    """"ok" when a peer's answer passes rigidlcp's own check (verify.certify, uniqueness
    "none"), else "NOT": a peer's info = 0 is a claim, not a proof."""
    from rigidlcp.lcp import Solution
    from rigidlcp.verify.certificates.certify import certify

    answer = Solution(z=np.asarray(z, dtype=float), w=np.zeros(0), status="solved",
                      method="siconos")
    with np.errstate(all="ignore"):
        ok = certify(problem, answer, uniqueness="none").accepted
    return "ok" if ok else "NOT"


def inner_calls(n: int, inner: str) -> int:
    """Calls per timed sample: --inner N, or "auto": about 20000 / n^2 (200 at n = 10, 1 from
    n = 142 on), so that a sample is not one cold call of a few microseconds."""
    return max(1, round(20000 / n**2)) if inner == "auto" else int(inner)


def run(sizes: list[int], repeats: int, seed: int, budget: float, methods: list[str] | None,
        use_siconos: bool, inner: str = "1", against: tuple[str, ...] = ("lemke",)) -> None:
    infos = [m for m in lcp.methods() if methods is None or m.name in methods]
    siconos = Siconos() if use_siconos else None
    print("Dense LCP benchmark: M = A A^T + 0.1 I, q ~ N(0, 1), A standard normal, "
          f"seed ({seed}, n); median of {repeats} runs of lcp.solve")
    print(f"python {platform.python_version()}, numpy {np.__version__}, {os.cpu_count()} CPUs, "
          f"load average at start {os.getloadavg()[0]:.2f}; lemke timed as the mean of --inner "
          f"{inner} calls in a row (Siconos likewise)")
    print()
    header = (f"{'n':>5}  {'method':<12} {'status':<13} {'iters':>7} {'median [ms]':>12} "
              f"{'residual':>9}")
    print(header)
    print("-" * len(header))
    too_slow: dict[str, int] = {}
    pairs: list[dict] = []
    with tempfile.TemporaryDirectory(prefix="lcp_dense_") as tmp:
        for n in sizes:
            M, q = dense_problem(n, seed)
            problem = lcp.LCP(M, q, name=f"dense-{n}")
            M_path, q_path = Path(tmp, f"M{n}.npy"), Path(tmp, f"q{n}.npy")
            np.save(M_path, M)
            np.save(q_path, q)
            for info in infos:
                name = info.name
                skip = ""
                if info.max_n is not None and n > info.max_n:
                    skip = f"skipped: registered for n <= {info.max_n}"
                elif name in too_slow:
                    skip = f"skipped: over the {budget:g} s budget at n = {too_slow[name]}"
                if skip:
                    print(f"{n:>5}  {name:<12} {skip}")
                    continue
                try:
                    t, _, sol = _time_solve(problem, name)  # trial run (warms caches, imports)
                except lcp.NotApplicable as exc:
                    print(f"{n:>5}  {name:<12} skipped: not applicable ({exc})")
                    continue
                except NotImplementedError as exc:
                    print(f"{n:>5}  {name:<12} skipped: not implemented ({exc})")
                    continue
                except Exception as exc:  # noqa: BLE001 - a benchmark reports, never dies
                    print(f"{n:>5}  {name:<12} skipped: raised {type(exc).__name__}: {exc}")
                    continue
                times, cpus = [t], []
                sic: list[dict] = []
                if t > budget:
                    too_slow[name] = n
                else:
                    times = []
                    k = inner_calls(n, inner) if name in against else 1
                    for _ in range(repeats):
                        t, c, sol = _time_solve(problem, name, k)
                        times.append(t)
                        cpus.append(c)
                        if name in against and siconos is not None and siconos.available:
                            sic.append(siconos.solve(M_path, q_path, 1000 + 100 * n, k))
                note = "  (1 run: over budget)" if len(times) == 1 and repeats > 1 else ""
                print(f"{n:>5}  {name:<12} {sol.status:<13} {sol.iterations:>7} "
                      f"{1e3 * np.median(times):>12.3f} {sol.residual:>9.1e}{note}")
                if sic:
                    pairs.append({"n": n, "method": name, "ours": times, "ours_cpu": cpus,
                                  "pivots": sol.iterations,
                                  "siconos": [s["time"] for s in sic],
                                  "siconos_cpu": [s["cpu"] for s in sic],
                                  "sic_pivots": sic[-1]["iterations"],
                                  "sic_info": sic[-1]["info"],
                                  "sic_judged": judged(problem, sic[-1]["z"]),
                                  "sic_residual": sic[-1]["residual"]})
    print()
    _report_siconos(siconos, pairs, use_siconos)
    print(f"load average at end {os.getloadavg()[0]:.2f}")
    if siconos is not None:
        siconos.close()


def _report_siconos(siconos: Siconos | None, pairs: list[dict], use_siconos: bool) -> None:
    if not use_siconos:
        print("Siconos comparison skipped (--no-siconos).")
        return
    if siconos is None or not (siconos.available or pairs):
        print(f"Siconos comparison skipped: {siconos.reason if siconos else 'disabled'}.")
        return
    print(f"rigidlcp vs Siconos lcp_lexicolemke (python3-siconos {siconos.version}, "
          f"{SYSTEM_PYTHON} subprocess, solve call only), runs interleaved, medians")
    print("Siconos counts the pivots after the first one (z0 entering); rigidlcp's lemke counts "
          "all, so equal paths show lemke = Siconos + 1 (pivoting counts its own iterations).")
    print("checked: Siconos's answer judged by rigidlcp's own check (verify.certify): 'NOT' is")
    print("an answer that is not a solution, whatever Siconos's info says.")
    print("Wall time: medians and ratio = rigidlcp/Siconos; best = min/min over the runs. CPU: the")
    print("same with process CPU time (less sensitive to other jobs on the machine).")
    header = (f"{'n':>5} {'method':<9} {'rigidlcp [ms]':>14} {'Siconos [ms]':>13} {'ratio':>6} "
              f"{'best':>6} {'CPU ratio':>9} {'pivots':>7} {'Siconos+1':>9} {'info':>5} "
              f"{'Siconos res':>11} {'checked':>7}")
    print(header)
    print("-" * len(header))
    for p in pairs:
        ours, theirs = float(np.median(p["ours"])), float(np.median(p["siconos"]))
        best = min(p["ours"]) / min(p["siconos"])
        cpu = float(np.median(p["ours_cpu"])) / max(float(np.median(p["siconos_cpu"])), 1e-9)
        print(f"{p['n']:>5} {p['method']:<9} {1e3 * ours:>14.3f} {1e3 * theirs:>13.3f} "
              f"{ours / theirs:>6.2f} {best:>6.2f} {cpu:>9.2f} {p['pivots']:>7} "
              f"{p['sic_pivots'] + 1:>9} "
              f"{p['sic_info']:>5} {p['sic_residual']:>11.1e} {p['sic_judged']:>7}")
    print()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="10,50,100,200,500,1000",
                        help="comma-separated n (default: %(default)s)")
    parser.add_argument("--repeats", type=int, default=5, help="timed runs per solve (default 5)")
    parser.add_argument("--seed", type=int, default=0, help="problem seed (default 0)")
    parser.add_argument("--budget", type=float, default=2.0,
                        help="seconds per solve above which a method is not run at larger n")
    parser.add_argument("--methods", default=None, help="comma-separated subset of methods")
    parser.add_argument("--no-siconos", action="store_true", help="do not run Siconos")
    parser.add_argument("--against", default="lemke",
                        help="comma-separated methods timed against Siconos, interleaved "
                        "(default: %(default)s; e.g. lemke,pivoting)")
    parser.add_argument("--inner", default="1",
                        help="lemke (and Siconos) calls per timed sample, their mean reported: "
                        "an integer or 'auto' (about 20000 / n^2); default 1")
    args = parser.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",") if s.strip()]
    if not sizes or min(sizes) < 1 or args.repeats < 1:
        parser.error("--sizes must be positive integers and --repeats >= 1")
    methods = args.methods.split(",") if args.methods else None
    run(sizes, args.repeats, args.seed, args.budget, methods, not args.no_siconos, args.inner,
        tuple(args.against.split(",")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
