"""`rigidlcp ranges RUN.npz [--json] [--deep S] [--clock cpu|wall]`: the range of mu_g (and
of every angular acceleration, R, S) over every valid steady state of a steady run's system
(rigidlcp.verify.ranges), with a witness state at each end, beside the run's own value and the
range over its own contact states; time limits in CPU seconds unless --clock wall."""

from __future__ import annotations

import argparse
import json


def register(sub) -> None:
    p = sub.add_parser(
        "ranges", help="ranges of mu_g and other observables over all valid steady states",
        description="For a run saved by `rigidlcp simulate --out` that ended steady: the range "
        "of mu_g (and of each angular acceleration; with --observables all, of each R and S) "
        "over every valid steady state of its system (docs/mechanics.md, 'Valid steady "
        "states'), over every contact-state set the kinematics admit, each end with a "
        "witness state checked against the laws; beside it, the range over the run's own "
        "contact states. An end stopped by --time-limit is reported as 'time limit' with the "
        "value met, never as the end itself; where a case split on the plane contacts proves "
        "a bound on it (verify.ranges.cap_split; with --deep S also the case split on the "
        "disks' cap states, verify.ranges.disk_split, S seconds per open end), the bound is "
        "added ('bounds' in the JSON).")
    p.add_argument("run", help="a run file (RUN.npz, with its RUN.json)")
    p.add_argument("--observables", choices=("mu_g", "alpha", "all"), default="alpha",
                   help="mu_g only; mu_g and every angular acceleration (default); also "
                   "every R and S")
    p.add_argument("--time-limit", type=float, default=10.0,
                   help="seconds of MILP per end (default 10), on --clock")
    p.add_argument("--clock", choices=("cpu", "wall"), default="cpu",
                   help="how --time-limit and --deep are counted: this process's CPU "
                   "seconds (default: where a search stops, hence which ends are decided, "
                   "does not depend on the machine's load; on a loaded machine the wait is "
                   "longer, and HiGHS checks the limit only between some of its steps, so "
                   "an end may overrun it) or wall-clock seconds (the wait is bounded, the "
                   "answers may depend on the load)")
    p.add_argument("--box", type=float, default=None,
                   help="force box R <= BOX when no bound is proved (default 10 m_g g)")
    p.add_argument("--deep", type=float, default=None, metavar="S",
                   help="also the case split on the disks' cap states (verify.ranges."
                   "disk_split), S seconds per end left open: a better proved bound")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bar on stderr (one step per end's search)")
    p.set_defaults(func=cmd_ranges)


def cmd_ranges(args: argparse.Namespace) -> int:
    from rigidlcp.lcp.errors import InvalidInput
    from rigidlcp.models.runio import load_run
    from rigidlcp.verify.ranges import steady_ranges
    from rigidlcp.verify.ranges.steady import NoVelocityBound

    if not args.time_limit > 0:
        raise ValueError(f"--time-limit must be > 0, got {args.time_limit}")
    if args.box is not None and not args.box > 0:
        raise ValueError(f"--box must be > 0, got {args.box}")
    if args.deep is not None and not 0 < args.deep < float("inf"):
        raise ValueError(f"--deep must be a number of seconds > 0, got {args.deep}")
    run = load_run(args.run)
    if run.status != "steady":  # the library's refusal offers a Python-only way out
        raise InvalidInput(f"{args.run}: the run ended {run.status!r} ({run.message}), not in "
                           "a steady state: `rigidlcp ranges` needs a run that reached one "
                           "(rerun `rigidlcp simulate` with a larger --t-max or --max-events)")
    _warn_long(run.system, args)
    bars: list = []

    def progress(done: int, total: int, name: str) -> None:
        if not bars:
            from rigidlcp.models.progress import new_bar

            bars.append(new_bar(total=total, desc="range ends", unit="end"))
        bars[0].set_postfix_str(name, refresh=False)
        bars[0].update(done - bars[0].n)

    try:
        result = steady_ranges(run, which=args.observables, time_limit=args.time_limit,
                               box=args.box, split=True if args.deep is None else args.deep,
                               clock=args.clock,
                               progress=None if args.no_progress else progress)
    except NoVelocityBound as exc:
        raise NoVelocityBound(f"{args.run}: the ranges over all valid steady states do not "
                              f"handle this system ({exc})") from None
    finally:
        for bar in bars:
            bar.close()
    if args.json:
        print(json.dumps(result.to_dict()))
    else:
        print(result.table())
    return 0


#: A run whose MILPs may take longer than this (seconds, at their time limits) is announced.
LONG_RUN_S = 60.0


def _warn_long(system, args: argparse.Namespace) -> None:
    """Say on stderr, before the work, how long the MILPs may take: one per end of every
    observable, each up to --time-limit (a 10 x 4 run: about 14 min); a bar then counts the
    ends."""
    import sys

    n = 1 + (system.p if args.observables in ("alpha", "all") else 0) \
        + (2 * system.c if args.observables == "all" else 0)
    worst = 2 * n * args.time_limit
    if worst < LONG_RUN_S:
        return
    what = "mu_g" + (f" and {system.p} angular accelerations" if n > 1 else "") \
        + (f" and R, S of {system.c} contacts" if args.observables == "all" else "")
    span = f"{worst:.0f} s" if worst < 300 else f"{worst / 60:.0f} min"
    unit = "CPU s" if args.clock == "cpu" else "s"
    print(f"rigidlcp ranges: {2 * n} MILP ends ({what}), each up to {args.time_limit:g} {unit}: "
          f"up to about {span}; `--observables mu_g` for mu_g alone, --time-limit S to stop "
          "each end sooner", file=sys.stderr, flush=True)

