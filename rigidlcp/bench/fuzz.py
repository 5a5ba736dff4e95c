"""Fuzz harness: every registered method on generated LCPs, judged independently of the solvers.

`run_fuzz(count, seed, out)` draws `count` problems (the classes of rigidlcp.bench.fuzz_cases,
in turn), runs every method of `lcp.methods()` on each (enumerate only for n <= ENUM_MAX_N),
and judges each answer with what is known *without the solvers*:

* "solved": w = M z + q recomputed and the scaled residual of verify.certify's acceptance
  test (re-implemented in rigidlcp.bench.fuzz_judge, not imported from the solver side)
  <= 1e-8 on the problem as generated (unscaled). Otherwise SILENT WRONG.
* "infeasible": true only if the LCP has no feasible point, decided by an LP (HiGHS through
  scipy, on the problem as generated, after a Ruiz-free row normalization) and, for n <= 10,
  by the enumeration of every complementary basis finding nothing; it is SILENT WRONG for a
  P-matrix (by construction), a planted solution, or a strictly copositive class.
* any other status: an honest failure; NotApplicable: refused; any other exception (or
  ``info["exception"]``): crash.

It prints a table class x method (solved / honest failure / refused / crash / SILENT WRONG,
median time per solve; lemke solves the cases of a class among CHUNK drawn at a time in one
`lcp.solve_many` call, the same answers as one call each, its time per solve being that
call's mean) and writes every silent-wrong or crashing case to OUT as
`<class>-<seed>-<method>.npz` (an `lcp.LCP` file with the verdict in its meta), which
tests/lcp/test_fuzz_regressions.py loads.
Run: `python -m rigidlcp.bench.fuzz --count N --seed S --out DIR` (CLI: `rigidlcp fuzz`).
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

from rigidlcp import lcp
from rigidlcp.lcp.batch import COMPILED_BATCH
from rigidlcp.lcp.errors import InvalidInput, InvalidProblem, OutputExists, RigidLCPError

from .fuzz_cases import CLASSES, Case, make_case
from .fuzz_judge import (  # noqa: F401 (judge_residual, lp_feasible: public here too)
    ENUM_MAX_N,
    OPTIONS,
    OUTCOMES,
    TOL,
    attempt,
    judge,
    judge_residual,
    lp_feasible,
    save_case,
)
from .own import OWN_ANSWER

#: Cases drawn at a time: the methods with a compiled batch path (lcp.batch.COMPILED_BATCH:
#: lemke) solve them in one lcp.solve_many call; the others one by one.
CHUNK = 64


def batch_attempt(cases: list[Case], method: str) -> list[tuple[lcp.Solution, dict]] | None:
    """`attempt` for many cases in one `lcp.solve_many` call (the same answers as one call
    each; the time of each is the call's mean). None when the call raised or any answer
    carries an exception: the cases are then attempted one by one, so that a crash is
    attributed to its case."""
    problems = [lcp.LCP(c.M, c.q) for c in cases]
    t0 = time.perf_counter()
    try:
        sols = lcp.solve_many(problems, method, **OWN_ANSWER, **OPTIONS.get(method, {}))
    except Exception:  # noqa: BLE001 - one by one instead
        return None
    mean = (time.perf_counter() - t0) / max(len(cases), 1)
    if any("exception" in sol.info for sol in sols):
        return None
    return [(sol, {"seconds": mean, "status": sol.status}) for sol in sols]


def batch_by_class(cases: list[Case], method: str) -> list | None:
    """`batch_attempt` per class of problem (so that each class's time is its own mean), in
    the order of `cases`; an entry is None where its class's call must go one by one."""
    out: list = [None] * len(cases)
    by_kind: dict[str, list[int]] = defaultdict(list)
    for i, case in enumerate(cases):
        by_kind[case.kind].append(i)
    for idx in by_kind.values():
        done = batch_attempt([cases[i] for i in idx], method)
        for i, d in zip(idx, done or [None] * len(idx)):
            out[i] = d
    return out


def run_case(case: Case, method: str, done: tuple | None = None) -> dict:
    """Attempt and judge one case (`done`: its (solution, result) from `batch_attempt`)."""
    sol, res = done if done is not None else attempt(lcp.LCP(case.M, case.q), method)
    if sol is not None:
        res["outcome"], res["reason"] = judge(case, sol.status, sol.z)
    return res


#: seconds between the one-line progress counts on stderr (unless --no-progress)
PROGRESS_SECONDS = 10.0


def run_fuzz(count: int, seed: int = 0, out: str | Path | None = None,
             classes: tuple[str, ...] = CLASSES, methods: tuple[str, ...] | None = None,
             progress=None) -> dict:
    """Fuzz `count` problems; returns {"table": {(class, method): {outcome: count, "seconds":
    [...]}}, "saved": [paths], ...}. `progress(k, partial_result)` is called after each."""
    names = methods or tuple(m.name for m in lcp.methods())
    exhaustive = {m.name for m in lcp.methods() if m.accepts == "small-n"}
    out_dir = Path(out) if out is not None else None
    table: dict = defaultdict(lambda: {**{o: 0 for o in OUTCOMES}, "seconds": []})
    saved: list[Path] = []
    for start in range(0, count, CHUNK):
        cases = [make_case(classes[k % len(classes)], seed * 1_000_003 + k)
                 for k in range(start, min(count, start + CHUNK))]
        batched = {m: batch_by_class(cases, m) for m in names if m in COMPILED_BATCH}
        for j, case in enumerate(cases):
            k = start + j
            for method in names:
                if method in exhaustive and case.n > ENUM_MAX_N:
                    continue
                done = batched[method][j] if method in batched else None
                res = run_case(case, method, done)
                cell = table[(case.kind, method)]
                cell[res["outcome"]] += 1
                cell["seconds"].append(res["seconds"])
                if res["outcome"] in ("WRONG", "crash") and out_dir is not None:
                    saved.append(save_case(case, method, res, out_dir))
            if progress is not None:
                progress(k + 1, {"table": dict(table), "saved": saved, "count": k + 1,
                                 "seed": seed})
    return {"table": dict(table), "saved": saved, "count": count, "seed": seed}


def format_table(result: dict) -> str:
    """Markdown table: class x method -> solved / honest / refused / crash / WRONG, time."""
    table = result["table"]
    lines = ["| class | method | solved | honest failure | refused | crash | SILENT WRONG "
             "| median ms |", "|---|---|---:|---:|---:|---:|---:|---:|"]
    order = {c: i for i, c in enumerate(CLASSES)}
    for (kind, method), cell in sorted(table.items(),
                                       key=lambda kv: (order.get(kv[0][0], 99), kv[0])):
        ms = 1e3 * float(np.median(cell["seconds"])) if cell["seconds"] else float("nan")
        lines.append(f"| {kind} | {method} | {cell['solved']} | {cell['honest']} | "
                     f"{cell['refused']} | {cell['crash']} | {cell['WRONG']} | {ms:.2f} |")
    return "\n".join(lines)


def add_arguments(ap: argparse.ArgumentParser) -> None:
    """The options of `rigidlcp fuzz` (and of `python -m rigidlcp.bench.fuzz`)."""
    ap.add_argument("--count", type=int, default=1000, help="problems to draw (default 1000)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the draw (default 0)")
    ap.add_argument("--out", default=None, help="folder for the silent-wrong / crash cases "
                    "(must not exist yet)")
    ap.add_argument("--classes", default=",".join(CLASSES),
                    help="comma-separated classes (default: all, %(default)s)")
    ap.add_argument("--methods", default=None, help="comma-separated methods (default: all)")
    ap.add_argument("--progress", type=int, default=0, metavar="K",
                    help="print the table so far to stderr every K problems (default: never; "
                    f"a one-line count goes to stderr every {PROGRESS_SECONDS:g} s anyway)")
    ap.add_argument("--no-progress", action="store_true",
                    help="no progress lines on stderr")
    ap.add_argument("--files", nargs="+", default=None, help="judge the methods on these LCP "
                    "and MLCP files (Siconos's text formats or .npz) instead of generated "
                    "problems")


def run_from_args(args: argparse.Namespace) -> int:
    """Run, print the table; 0 if no answer was silently wrong or crashed, else 1. Bad
    arguments raise InvalidInput / OutputExists (one line and exit status 2 on the CLI)."""
    classes = tuple(c for c in args.classes.split(",") if c)
    bad = [c for c in classes if c not in CLASSES]
    if bad:
        raise InvalidInput(f"unknown class(es) {bad}; classes: {', '.join(CLASSES)}")
    if args.count < 1:
        raise InvalidInput(f"--count must be >= 1, got {args.count}")
    if args.seed < 0:
        raise InvalidInput(f"--seed must be >= 0, got {args.seed}")
    if args.out is not None and Path(args.out).exists():
        raise OutputExists(f"--out {args.out} exists; give a new folder")
    methods = tuple(m for m in args.methods.split(",") if m) if args.methods else None
    for m in methods or ():
        try:
            lcp.get_method(m)  # an unknown name raises InvalidProblem
        except InvalidProblem as exc:  # the command line cannot import a user's method
            raise InvalidProblem(f"{exc} (a method of your own: register it in your script "
                                 "and call rigidlcp.bench.fuzz.run_fuzz(count, seed, out, "
                                 "methods=(...)), docs/fuzz.md)") from None
    t0 = time.perf_counter()
    if args.files:
        missing = [f for f in args.files if not Path(f).is_file()]
        if missing:
            raise InvalidInput(f"no such file {missing[0]}")
        from .fuzz_files import run_files

        result = run_files(args.files, methods, args.out)
        what = f"{len(args.files)} files"
    else:
        every = max(1, args.progress)
        last = [t0]

        def progress(k: int, partial: dict) -> None:
            now = time.perf_counter()
            if k >= args.count:
                return
            if args.progress and k % every == 0:
                print(f"[{k} of {args.count} problems, {now - t0:.0f} s]\n"
                      + format_table(partial), file=sys.stderr, flush=True)
            elif now - last[0] >= PROGRESS_SECONDS:
                bad = sum(c["WRONG"] + c["crash"] for c in partial["table"].values())
                print(f"fuzz: {k} of {args.count} problems, {now - t0:.0f} s, {bad} "
                      "silent-wrong or crashing so far", file=sys.stderr, flush=True)
            else:
                return
            last[0] = now

        result = run_fuzz(args.count, args.seed, args.out, classes, methods,
                          progress=None if args.no_progress else progress)
        what = f"{args.count} problems, seed {args.seed}"
    print(format_table(result))
    for (_, method), cell in result["table"].items():
        if method == "reader":  # a file no method could be given: say why
            print(f"refused by the reader: {cell['reason']}")
    wrong = sum(c["WRONG"] + c["crash"] for c in result["table"].values())
    print(f"\n{what}, {time.perf_counter() - t0:.0f} s; "
          f"{wrong} silent-wrong or crashing answers"
          + (f" saved in {args.out}" if args.out and wrong else ""))
    return 1 if wrong else 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="rigidlcp fuzz", description=__doc__.split("\n")[0])
    add_arguments(ap)
    args = ap.parse_args(argv)
    try:
        return run_from_args(args)
    except (RigidLCPError, ValueError) as exc:
        print(f"rigidlcp fuzz: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
