"""`rigidlcp certify-run RUN.npz --out DIR`: uniqueness verdicts at every event of a saved run
(rigidlcp.verify.certificates.run)."""

from __future__ import annotations

import argparse
import json
import sys


def register(sub) -> None:
    p = sub.add_parser(
        "certify-run", help="uniqueness of accelerations, forces and contact states at every "
        "event of a run",
        description="Certify every event of a run saved by `rigidlcp simulate --out`: for the "
        "accelerations, the forces and the contact states, is the recorded solution the only "
        "one? Stages: the face (same contact states), other solvers, a MILP. One strict-JSON line "
        "per event in DIR/certificates.jsonl (resumable) with every witness found (its z, "
        "residual and how the observables differ; at a steady event, whether the witness is "
        "itself a steady state), totals in DIR/summary.json, a figure DIR/determinacy.png. See "
        "docs/verification.md.")
    p.add_argument("run", help="a run file (RUN.npz, with its RUN.json)")
    p.add_argument("--out", help="output directory (default: RUN_cert beside the run); never "
                   "overwritten without --resume or --force")
    p.add_argument("--resume", action="store_true", help="continue an interrupted certification")
    p.add_argument("--force", action="store_true", help="start afresh in an existing --out")
    p.add_argument("--jobs", type=int, default=1, help="worker processes (default 1)")
    p.add_argument("--time-limit", type=float, default=10.0,
                   help="seconds per MILP, per question (default 10), on --clock")
    p.add_argument("--clock", choices=("cpu", "wall"), default="cpu",
                   help="how --time-limit is counted: this process's CPU seconds (default; "
                   "the verdicts then do not depend on the machine's load, a loaded machine "
                   "only waits longer) or wall-clock seconds")
    p.add_argument("--tries", type=int, default=8, help="other-solver attempts (default 8)")
    p.add_argument("--ranges", action="store_true",
                   help="also the range of every observable over the face (more LPs)")
    p.add_argument("--events", help="events to certify: K, K1,K2,... or START:STOP (default all)")
    p.add_argument("--json", action="store_true", help="print the totals as JSON")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=cmd_certify_run)


def parse_events(text: str | None) -> list[int] | None:
    """'5', '1,4,9' or '10:20' (STOP excluded) -> list of events; None -> all."""
    if text is None:
        return None
    try:
        if ":" in text:
            a, b = text.split(":")
            events = list(range(int(a), int(b)))
        else:
            events = [int(x) for x in text.split(",")]
    except ValueError:
        raise ValueError(f"--events takes K, K1,K2,... or START:STOP, got {text!r}") from None
    if not events:  # e.g. 5:2: nothing to certify, and an empty output folder would remain
        raise ValueError(f"--events {text!r} selects no event (START:STOP needs START < STOP)")
    return events


def cmd_certify_run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from rigidlcp.models.runio import run_paths
    from rigidlcp.verify.certificates.run import certify_run, format_totals

    if args.resume and args.force:
        raise ValueError("--resume and --force exclude each other")
    if not args.time_limit > 0 or args.tries < 0:
        raise ValueError("--time-limit must be > 0 and --tries >= 0")
    if args.jobs < 1:  # before the progress bar starts: one line, not a bar and a line
        raise ValueError(f"--jobs must be >= 1, got {args.jobs}")
    data_path, _ = run_paths(args.run)
    out = Path(args.out) if args.out else data_path.with_name(data_path.stem + "_cert")
    try:
        res = certify_run(args.run, out, time_limit=args.time_limit, tries=args.tries,
                          ranges=args.ranges, events=parse_events(args.events), jobs=args.jobs,
                          resume=args.resume, force=args.force, progress=not args.no_progress,
                          clock=getattr(args, "clock", "cpu"))
    except KeyboardInterrupt:
        print(f"rigidlcp certify-run: interrupted; finished events are in {out} "
              "(rerun with --resume)", file=sys.stderr)
        return 130
    if args.json:
        print(json.dumps(res.totals, indent=1))
    else:
        if res.skipped:
            print(f"resumed: {res.skipped} events already certified, {res.ran} now")
        print(format_totals(res.totals))
        print(f"written: {out}/certificates.jsonl, summary.json, determinacy.png, "
              "options.json")
    return 0
