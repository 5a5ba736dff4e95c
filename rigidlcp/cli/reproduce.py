"""`rigidlcp reproduce`: the paper's Sec. IV experiments, claims table and figures."""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path


def register(sub) -> None:
    p = sub.add_parser(
        "reproduce", help="run the paper's experiments and judge each claim (report.md)",
        description="Runs the experiments of Sec. IV (Figs. 6-13) and Eqs. (3.3)-(3.4) at the "
        "parameters of the captions, and writes OUT/report.md: each claim of the paper, the "
        "measured number, the criterion and PASS/FAIL, with the figures as PNGs and the "
        "claims as OUT/claims.json. 5-27 min on 2 shared cores, by their load, with the "
        "default executor (docs/reproduction.md). Exit status 0 when every claim was "
        "evaluated (whatever its verdict), 1 when an evaluation failed.")
    p.add_argument("--out", required=True, help="directory of the report")
    p.add_argument("--quick", action="store_true",
                   help="small sizes (2-6 min on 2 shared cores, by their load; for tests): "
                   "every claim is evaluated, but the sizes are not the paper's")
    p.add_argument("--jobs", "-j", type=int, default=None,
                   help="worker processes (default: the CPUs available; 1: in this process)")
    p.add_argument("--dask", default=None, metavar="tcp://HOST:PORT|local",
                   help="run the jobs on a dask.distributed scheduler or a LocalCluster")
    p.add_argument("--force", action="store_true",
                   help="write into an --out directory that is not empty (an earlier run's "
                   "saved jobs there are dropped)")
    p.add_argument("--resume", action="store_true",
                   help="finish an interrupted run in --out: each job is saved in OUT/cells "
                   "as it finishes, and the saved ones are not run again (same --quick only)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=cmd_reproduce)


def cmd_reproduce(args: argparse.Namespace) -> int:
    from rigidlcp.reproduce.claims import evaluate
    from rigidlcp.reproduce.experiments import SELECT, plan, provenance, run_all
    from rigidlcp.reproduce.report import figures, write_report
    from rigidlcp.reproduce.saved import open_out

    if args.jobs is not None and args.jobs < 1:
        raise ValueError(f"--jobs must be >= 1, got {args.jobs}")
    if args.resume and args.force:
        raise ValueError("--resume and --force exclude each other")
    p = plan(quick=args.quick)
    # new or empty unless --force; with --resume, a reproduce folder of the same options
    cells = open_out(args.out, {"--quick": bool(args.quick)}, p, provenance(),
                     force=args.force, resume=args.resume)
    out = Path(args.out)
    command = "rigidlcp reproduce " + " ".join(
        shlex.quote(a) for a in (sys.argv[2:] if sys.argv[1:2] == ["reproduce"] else
                                 ["--out", str(out)] + (["--quick"] if args.quick else [])))
    try:
        res = run_all(p, jobs=args.jobs, dask=args.dask, progress=not args.no_progress,
                      cells=cells)
        claims = evaluate(res)
        files = figures(res, out)
        path = write_report(res, claims, out, files, command)
    except KeyboardInterrupt:
        print(f"\nrigidlcp reproduce: interrupted; the {cells.count()} finished jobs are saved "
              f"in {cells.dir}: rerun the same command with --resume to finish the run",
              file=sys.stderr)
        return 130
    print_claims(claims, f"{path} ({res.wall_time:.0f} s on {res.executor})", SELECT)
    errors = [c for c in claims if c.error]
    for c in errors:
        print(f"{c.id}: evaluation error: {c.error}", file=sys.stderr)
    return 1 if errors else 0


def print_claims(claims, report: str, select: str) -> None:
    """One line per claim: the selection's PASS / FAIL, then its verdict over all valid
    steady states (`overall_word`), then what was measured; a last line with both counts."""
    width = max(len(c.id) for c in claims)
    words = [overall_word(c.overall) for c in claims]
    wide = max(len(w) for w in words)
    print(f"the selection ({select}): PASS / FAIL; over all valid steady states: all / some "
          "/ none / unknown (report.md says which)")
    for c, word in zip(claims, words):
        print(f"{c.verdict}  {word:<{wide}}  {c.id:<{width}}  {c.measured}")
    n_pass = sum(c.passed for c in claims)
    counts = ", ".join(f"{words.count(w)} {w}" for w in dict.fromkeys(words))
    print(f"{n_pass} PASS, {len(claims) - n_pass} FAIL for this toolkit's selection; over all "
          f"valid steady states: {counts}; report: {report}")


def overall_word(text: str) -> str:
    """The verdict of a claim over all valid steady states (rigidlcp.reproduce.overall), in
    one word: "all", "some", "none", "unknown", "not judged" or "n/a" (not a steady-state
    claim): the terminal's summary of report.md's column; a PASS of the selection is one
    state's answer where the steady states are not unique."""
    for word in ("all", "some", "none"):
        if text.startswith(f"holds for {word}"):
            return word
    for word in ("unknown", "not judged", "n/a"):
        if text.startswith(word):
            return word
    return "-"
