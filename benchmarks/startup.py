"""Start-up costs, each in a fresh interpreter (a script, not a test): imports, `rigidlcp --help`,
and the first `lcp.solve(..., "lemke")` of a process against the second (the first-call pause a
CLI user would notice: a JIT would show here).

    python benchmarks/startup.py [--repeats 7] [--baseline DIR] [--main-job]

--baseline DIR: a directory holding another copy of the package as `DIR/rigidlcp` (with
`lcp`, `models`, `verify` inside, e.g. an unpacked older commit); each measurement is then also
taken with PYTHONPATH=DIR, interleaved with the current one, so that both see the same load.
Medians of --repeats fresh processes. --main-job: only the README's main job as a command
(`rigidlcp simulate --lattice rect --lx 10 --ly 4 --mu-pp 0.1 --mu-plane 0.2 --mu-wall 0
--gamma 0.1 --seed 1 --out RUN.npz`, the whole process timed).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time

import numpy as np

CASES = {
    "import rigidlcp.lcp": "import rigidlcp.lcp",
    "import lcp, models, verify": "import rigidlcp.lcp, rigidlcp.models, rigidlcp.verify",
    "rigidlcp --help (parser)": (
        "import importlib\nimportlib.import_module('rigidlcp.cli.main').build_parser()"),
}

FIRST_SOLVE = """
import time
t0 = time.perf_counter()
import numpy as np
from rigidlcp import lcp
rng = np.random.default_rng([0, 10]); A = rng.standard_normal((10, 10))
P = lcp.LCP(A @ A.T + 0.1 * np.eye(10), rng.standard_normal(10))
t1 = time.perf_counter(); s = lcp.solve(P, "lemke"); t2 = time.perf_counter()
lcp.solve(P, "lemke"); t3 = time.perf_counter()
assert s.status == "solved"
print(__import__("json").dumps([t1 - t0, t2 - t1, t3 - t2]))
"""


def timed(code: str, env: dict) -> float:
    wrapped = ("import time\n_t0 = time.perf_counter()\n" + code
               + "\nprint(time.perf_counter() - _t0)")
    out = subprocess.run([sys.executable, "-c", wrapped], capture_output=True, text=True,
                         env=env, check=True, cwd="/")
    return float(out.stdout.split()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--baseline", default=None)
    ap.add_argument("--main-job", action="store_true")
    args = ap.parse_args(argv)
    envs = {"current": dict(os.environ)}
    if args.baseline:
        envs["baseline"] = {**os.environ, "PYTHONPATH": os.path.abspath(args.baseline)}
    print(f"Start-up, fresh interpreter each time, median of {args.repeats}; python "
          f"{platform.python_version()}, {os.cpu_count()} CPUs, load average "
          f"{os.getloadavg()[0]:.2f} (2-core machine shared with other jobs)")
    if args.main_job:
        main_job(envs, args.repeats)
        return 0
    header = f"{'what':<34}" + "".join(f"{k + ' s':>14}" for k in envs)
    print(header)
    print("-" * len(header))
    for name, code in CASES.items():
        res: dict[str, list] = {k: [] for k in envs}
        for _ in range(args.repeats):
            for k, env in envs.items():
                res[k].append(timed(code, env))
        print(f"{name:<34}" + "".join(f"{np.median(v):>14.3f}" for v in res.values()))
    res = {k: [] for k in envs}
    for _ in range(args.repeats):
        for k, env in envs.items():
            out = subprocess.run([sys.executable, "-c", FIRST_SOLVE], capture_output=True,
                                 text=True, env=env, check=True, cwd="/")
            res[k].append(json.loads(out.stdout.split("\n")[-2]))
    for i, label in enumerate(("  imports + problem", "  first lemke solve (n = 10)",
                               "  second lemke solve")):
        print(f"{label:<34}" + "".join(f"{np.median([r[i] for r in v]):>14.4f}"
                                       for v in res.values()))
    print(f"load average at the end {os.getloadavg()[0]:.2f}")
    return 0


MAIN_JOB = ("simulate --lattice rect --lx 10 --ly 4 --mu-pp 0.1 --mu-plane 0.2 --mu-wall 0 "
            "--gamma 0.1 --seed 1").split()


def main_job(envs: dict, repeats: int) -> None:
    res: dict[str, list] = {k: [] for k in envs}
    events = {}
    with tempfile.TemporaryDirectory(prefix="startup_") as tmp:
        for i in range(repeats):
            for k, env in envs.items():
                out = os.path.join(tmp, f"{k}{i}.npz")
                cmd = [sys.executable, "-c", "import sys\nfrom rigidlcp.cli.main import main\n"
                       "sys.exit(main())", *MAIN_JOB, "--out", out]
                t0 = time.perf_counter()
                proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd="/")
                res[k].append(time.perf_counter() - t0)
                assert proc.returncode == 0, proc.stderr[-500:]
                line = [x for x in proc.stdout.splitlines() if x.strip().startswith("events")]
                events[k] = line[0].split()[-1] if line else "?"
    print("rigidlcp " + " ".join(MAIN_JOB) + " --out RUN.npz")
    for k, v in res.items():
        print(f"  {k:<10} median {np.median(v):.2f} s over {len(v)} runs "
              f"({', '.join(f'{x:.2f}' for x in v)}); events {events[k]}")
    print(f"load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    sys.exit(main())
