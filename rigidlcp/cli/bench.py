"""`rigidlcp bench`: run LCP methods on named problem sets, certify every answer, and write
DIR/results.csv, DIR/report.md and performance profiles (bench.harness, bench.report).
Usage: docs/bench.md.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import shlex
import sys

from rigidlcp.cli.main import seed

DEFAULT_METHODS = ("lemke,pivoting,pgs,qp-clarabel,qp-osqp,enumerate,newton-min,newton-fb,"
                   "enumerate-mlcp,states,nsgs")


def register(sub) -> None:
    p = sub.add_parser(
        "bench", help="compare LCP methods on named problem sets, every answer certified",
        description="Run every method on every problem of the sets with a time limit per "
        "solve, certify each answer with verify (an uncertified answer is a failure), and "
        "write OUT/results.csv, OUT/report.md (success rate, shifted geometric mean of the "
        "solve time, iterations, worst residual per set and method) and Dolan-More "
        "performance profiles OUT/profile_*.png. Siconos's LCP, MLCP and 2D "
        "friction-contact solvers are added when /usr/bin/python3 can import siconos.numerics.",
        epilog="Sets: see --list; a directory of *.npz / *.dat (Siconos format) files is a "
        "set too. Methods: rigidlcp's (`rigidlcp methods`) and Siconos's (siconos-*, see "
        "--list). Exit status 0 when the run completed (whatever the success rates).")
    p.add_argument("--set", dest="sets", metavar="NAME[,NAME]",
                   help="problem sets (names or directories), comma-separated")
    p.add_argument("--methods", default=None, metavar="M[,M]",
                   help=f"methods, comma-separated (default: {DEFAULT_METHODS}, plus "
                   "every siconos-* method of --list when Siconos is available)")
    p.add_argument("--out", metavar="DIR", help="output directory")
    p.add_argument("--time-limit", type=float, default=10.0, metavar="S",
                   help="seconds per solve; a longer solve is killed and fails (default 10)")
    p.add_argument("--tol", type=float, default=1e-8,
                   help="certification tolerance on the scaled residual (default 1e-8)")
    p.add_argument("--seed", type=seed, default=0, help="seed of the generated sets (default 0)")
    p.add_argument("--sizes", default=None, metavar="N[,N]",
                   help="sizes n for the generated sets (default: each set's own)")
    p.add_argument("--per-size", type=int, default=None, help="problems per size")
    p.add_argument("--cache", default=None, metavar="DIR",
                   help="where event sets are harvested (default $RIGIDLCP_CACHE or "
                   "~/.cache/rigidlcp)")
    p.add_argument("--no-siconos", action="store_true", help="do not look for Siconos")
    p.add_argument("--no-isolation", action="store_true",
                   help="solve in this process (the time limit is then checked afterwards, "
                   "a solve cannot be interrupted)")
    p.add_argument("--no-batch", action="store_true",
                   help="solve every problem in its own call (by default lemke solves the "
                   "LCPs of a set that share a size in one lcp.solve_many call, each timed "
                   "as the batch's mean)")
    p.add_argument("--force", action="store_true",
                   help="write into an --out directory that is not empty")
    p.add_argument("--resume", action="store_true",
                   help="continue the run in --out: the (problem, method) pairs already in "
                   "its results.csv are kept, not run again")
    p.add_argument("--problems", default=None, metavar="NAME[,NAME]",
                   help="only these problems of the sets (names as in results.csv), e.g. "
                   "to rerun one failure")
    p.add_argument("--no-peers", action="store_true",
                   help="do not add the installed peers (quantecon-lemke, drake-moby, "
                   "drake-unrevised-lemke, lemkelcp) to the default methods")
    p.add_argument("--list", action="store_true", help="list the sets and methods and exit")
    p.add_argument("--quiet", "--no-progress", action="store_true",
                   help="no progress lines (--no-progress, as in the other commands)")
    p.set_defaults(func=cmd_bench)


def cmd_bench(args: argparse.Namespace) -> int:
    from rigidlcp import lcp
    from rigidlcp.bench.harness import SICONOS_METHODS, SiconosRunner, check_methods, read_csv
    from rigidlcp.bench.peers import PEERS, peer_available
    from rigidlcp.bench.problem_sets import SETS, get_set, list_sets
    from rigidlcp.lcp.registry import did_you_mean

    siconos = None if args.no_siconos else SiconosRunner()
    try:
        if args.list:
            print("sets:")
            for s in list_sets():
                print(f"  {s.name:<13} {s.problem_class}; expected: {s.expected}. "
                      f"{s.description}")
            print("  DIR           a directory of *.npz / *.dat (Siconos format) files")
            print("methods:")
            for m in lcp.methods():
                print(f"  {m.name}")
            for m, peer in PEERS.items():
                ok, why = peer_available(m)
                print(f"  {m:<24} LCPs: {peer.description} "
                      f"({'available, ' + why if ok else 'unavailable: ' + why})")
            for m, spec in SICONOS_METHODS.items():
                if siconos is None or not siconos.available:
                    state = f"unavailable: {siconos.reason if siconos else '--no-siconos'}"
                else:
                    state = "available" if siconos.offers(m) else (
                        f"unavailable: no {spec.kind} solvers in this Siconos")
                print(f"  {m:<24} {spec.kind} problems ({state})")
            return 0
        missing = [o for o, v in (("--set", args.sets), ("--out", args.out)) if not v]
        if missing:
            raise ValueError(f"{' and '.join(missing)} required (or --list)")
        if not (args.time_limit > 0 and args.tol > 0):
            raise ValueError("--time-limit and --tol must be positive")
        params = {}
        if args.sizes:
            try:
                params["sizes"] = tuple(int(s) for s in args.sizes.split(","))
            except ValueError:
                raise ValueError(f"--sizes takes integers N[,N], got {args.sizes!r}") from None
            if min(params["sizes"]) < 1:
                raise ValueError(f"--sizes must be >= 1, got {args.sizes}")
        if args.per_size is not None:
            if args.per_size < 1:
                raise ValueError(f"--per-size must be >= 1, got {args.per_size}")
            params["per_size"] = args.per_size
        specs = [s.strip() for s in args.sets.split(",") if s.strip()]
        unknown = [s for s in specs if s not in SETS and not os.path.isdir(s)]
        files = [s for s in unknown if os.path.isfile(s)]
        if files:  # one problem file: a set is a folder of them
            raise ValueError(f"--set {files[0]} is a file; --set takes a set name or a folder "
                             "of *.npz / *.dat problem files (for one file: `rigidlcp solve` "
                             "or `rigidlcp certify`)")
        if unknown:
            hint = did_you_mean(unknown[0], SETS) if len(unknown) == 1 else ""
            raise ValueError(f"unknown set(s) {', '.join(unknown)}{hint}: neither a set name "
                             f"({', '.join(SETS)}) nor a folder")
        notes: list[str] = []
        siconos_ok = siconos is not None and siconos.available
        methods = [m.strip() for m in (args.methods or "").split(",") if m.strip()]
        wanted = [m for m in PEERS if not args.methods and not args.no_peers or m in methods]
        peers_ok = {m: peer_available(m) for m in wanted}  # imports only the peers asked for
        if not args.methods:
            methods = DEFAULT_METHODS.split(",") + [m for m in SICONOS_METHODS
                                                    if siconos_ok and siconos.offers(m)]
            if not args.no_peers:
                methods += [m for m in PEERS if peers_ok[m][0]]
                notes += [f"peer {m} not run: {why}" for m, (ok, why) in peers_ok.items()
                          if not ok]
        absent = [m for m in methods if m in SICONOS_METHODS
                  and not (siconos_ok and siconos.offers(m))]
        if absent:
            why = (siconos.reason or f"this Siconos ({siconos.version}) lacks them"
                   if siconos is not None else "--no-siconos")
            notes.append(f"skipped {', '.join(absent)}: Siconos unavailable ({why})")
            methods = [m for m in methods if m not in absent]
        elif not siconos_ok and not args.methods:
            why = siconos.reason if siconos is not None else "--no-siconos"
            notes.append(f"Siconos methods not run: {why}")
        missing_peers = [m for m in methods if m in PEERS and not peers_ok[m][0]]
        notes += [f"skipped {m}: {peers_ok[m][1]}" for m in missing_peers]
        methods = [m for m in methods if m not in missing_peers]
        check_methods(methods, siconos)  # an unknown method: refused before anything is made
        if siconos_ok and any(m in SICONOS_METHODS for m in methods):
            notes.append(f"Siconos: python3-siconos {siconos.version} in a {siconos.python} "
                         "subprocess; timed as the whole call from Python (options, problem "
                         "object, driver); siconos-lemke is given "
                         "max_iter = 1000 + 100 n (as rigidlcp's lemke), siconos-pgs tol "
                         "1e-10 and 10000 sweeps (as rigidlcp's pgs), siconos-fc2d-nsgs tol "
                         "1e-12 and 10000 sweeps (as rigidlcp's nsgs); the enumerations are "
                         "given n <= 20 (LCP), m <= 16 (MLCP), c <= 5 contacts (fc2d); the "
                         "MLCP and fc2d solvers have Siconos's other defaults; a nonzero "
                         "Siconos info is a failure (it proves nothing)")
        if any(m in PEERS for m in methods):
            notes.append("peers (rigidlcp.bench.peers) run in the same worker as rigidlcp's "
                         "methods, timed as the whole call from Python on M and q; "
                         "their 'solved' is a claim, judged by the same check")
        sets, set_info, specs_by_name, names = {}, {}, {}, []
        only = {p.strip() for p in (args.problems or "").split(",") if p.strip()}
        for spec in specs:
            kw = params if spec in SETS and not spec.startswith("events-") else {}
            if spec.startswith("events-") and not args.quiet:  # a silent half minute else
                from rigidlcp.bench.problem_sets import default_cache_dir

                print(f"bench: set {spec}: the event LCPs of its runs, simulated once into "
                      f"{args.cache or default_cache_dir()} (about 30 s the first time)",
                      file=sys.stderr, flush=True)
            problems = get_set(spec, seed=args.seed, cache_dir=args.cache, **kw)
            names += [p.name for p in problems]
            if only:
                problems = [p for p in problems if p.name in only]
            name = spec if spec in SETS else os.path.basename(os.path.normpath(spec))
            sets[name], specs_by_name[name] = problems, spec
            info = SETS.get(spec)
            set_info[name] = (f"{info.problem_class}; expected answer: {info.expected}."
                              if info else f"folder {spec}.")
        if only:
            found = {p.name for ps in sets.values() for p in ps}
            if only - found:
                raise ValueError(f"--problems: no problem named "
                                 f"{', '.join(sorted(only - found))} in the sets"
                                 + _names_hint(sorted(only - found), names))
        csv_path = os.path.join(args.out, "results.csv")
        done: list = []
        if args.resume:
            if not os.path.isfile(csv_path):
                raise ValueError(f"--resume: {csv_path} does not exist")
            _check_same_run(args)
            done = read_csv(csv_path)
        return _run(args, sets, set_info, specs_by_name, methods, siconos, notes, done,
                    {m: peers_ok[m][1] for m in methods if m in PEERS})
    finally:
        if siconos is not None:
            siconos.close()


def _run(args, sets, set_info, specs_by_name, methods, siconos, notes, done, peer_versions
         ) -> int:
    """Run the bench into args.out (created only now, removed again if the run fails before
    writing anything), writing results.csv row by row, then report.md and the profiles."""
    from pathlib import Path

    from rigidlcp.bench.environment import environment
    from rigidlcp.bench.harness import append_csv, run_bench, write_csv
    from rigidlcp.bench.problem_sets import SETS, Unreadable
    from rigidlcp.bench.report_md import write_report
    from rigidlcp.lcp.errors import OutputExists
    from rigidlcp.lcp.io.files import output_dir

    out = Path(args.out)
    created = not out.exists()
    try:
        output_dir(out, force=args.force or args.resume)  # new or empty, unless --force/--resume
    except OutputExists:
        if not (out / "results.csv").is_file():
            raise
        raise OutputExists(f"{out} holds an earlier bench run (results.csv): --resume "
                           "finishes it, --force writes into it (files of the same name are "
                           "overwritten)") from None
    csv_path = out / "results.csv"
    try:
        if not args.resume and csv_path.exists():
            csv_path.unlink()  # --force: a fresh results.csv
        if not args.resume:
            from rigidlcp.lcp.io.files import atomic_write_text

            atomic_write_text(out / OPTIONS, json.dumps(_run_options(args), indent=1) + "\n")
        load0 = os.getloadavg()[0]
        started = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
        total = sum(1 if isinstance(p, Unreadable) else len(methods)
                    for problems in sets.values() for p in problems)
        count = [len(done)]
        mw = max([len(m) for m in methods] + [14])  # the method column, aligned

        def progress(r) -> None:
            append_csv(r, csv_path)
            count[0] += 1
            if not args.quiet:  # progress on stderr: stdout is the result
                print(f"[{count[0]}/{total}] {r.problem:<40} {r.method:<{mw}} {r.outcome:<14} "
                      f"{1e3 * r.time:10.2f} ms", file=sys.stderr, flush=True)

        warmups: dict = {}
        skip = {(r.set, r.problem, r.method) for r in done}
        results = done + run_bench(
            sets, methods, time_limit=args.time_limit, tol=args.tol,
            isolate=not args.no_isolation, siconos=siconos, progress=progress,
            batch=not args.no_batch, skip=skip, warmups=warmups)
    except BaseException as exc:
        if created and out.is_dir() and not any(out.iterdir()):
            out.rmdir()  # a refused or interrupted run leaves nothing behind
        if isinstance(exc, KeyboardInterrupt) and csv_path.is_file():
            print(f"\nrigidlcp bench: interrupted; the finished solves are in {csv_path}: "
                  "rerun the same command with --resume to finish the run", file=sys.stderr)
            return 130
        raise
    command = (f"rigidlcp bench {' '.join(shlex.quote(a) for a in sys.argv[2:])}"
               if sys.argv[1:2] == ["bench"] else "rigidlcp bench (called from Python)")
    header = [f"Command: `{command}`", "",
              f"Sets: {', '.join(sets)}; methods: {', '.join(methods)}; time limit "
              f"{args.time_limit:g} s per solve; seed {args.seed}."]
    if any(r.message.startswith("batch of ") for r in results):
        header += ["", "Batch: the LCPs of a set that share a size were solved by lemke in "
                   "one `lcp.solve_many` call each (results.csv: message 'batch of k'); "
                   "such a row's time is the call's time / k. `--no-batch`: one call per "
                   "problem."]
    if args.resume and done:
        header += ["", f"Resumed: {len(done)} rows kept from the earlier run."]
    generated = []
    if args.sizes:
        generated += ["--sizes", args.sizes]
    if args.per_size is not None:
        generated += ["--per-size", str(args.per_size)]

    def rerun(r) -> str:
        spec = specs_by_name.get(r.set, r.set)
        extra = generated if spec in SETS and not spec.startswith("events-") else []
        if spec.startswith("events-") and args.cache:
            extra = ["--cache", args.cache]
        parts = ["rigidlcp", "bench", "--set", spec, "--problems", r.problem, "--methods",
                 r.method, "--seed", str(args.seed), *extra, "--time-limit",
                 f"{args.time_limit:g}", "--out", "rerun-" + _slug(f"{r.problem}-{r.method}")]
        return " ".join(shlex.quote(p) for p in parts)

    env = environment(peer_versions, started, (load0, os.getloadavg()[0]))
    write_csv(results, csv_path)
    report = write_report(results, out, time_limit=args.time_limit, tol=args.tol,
                          set_info=set_info, header=header, notes=notes, environment=env,
                          rerun=rerun, warmups=warmups)
    _print_summary(results, args.time_limit)
    print(f"wrote {csv_path} and {report}")
    for line in notes:
        print(f"note: {line}")
    return 0


#: The options of a bench run that its kept rows depend on (the problems' data: --seed; their
#: judgement and timing: --tol, --time-limit, batch, isolation), written to OUT/OPTIONS.
OPTIONS = "options.json"


def _run_options(args: argparse.Namespace) -> dict:
    return {"--seed": args.seed, "--tol": args.tol, "--time-limit": args.time_limit,
            "--no-batch": bool(args.no_batch), "--no-isolation": bool(args.no_isolation)}


def _check_same_run(args: argparse.Namespace) -> None:
    """--resume keeps the rows of results.csv: refused when the run in --out had other
    options (a kept row of --seed 0 is another problem than this command's of --seed 5, one
    judged at --tol 1e-8 is not judged at 1e-3). A folder of an older version has no
    OPTIONS: nothing to compare."""
    path = os.path.join(args.out, OPTIONS)
    if not os.path.isfile(path):
        return
    with open(path) as fh:
        before = json.load(fh)
    now = _run_options(args)
    differ = [f"{k} {before[k]} there, {now[k]} here" for k in now
              if k in before and before[k] != now[k]]
    if differ:
        raise ValueError(f"--resume: {args.out} was run with other options ({'; '.join(differ)})"
                         ": its kept rows would not be this run's; give the same options, or "
                         "a new --out")


def _print_summary(results, time_limit: float) -> None:
    """The result on stdout: per method over all sets, certified answers / problems given,
    refusals, failures and the SGM time (report.md has the full tables)."""
    from rigidlcp.bench.report import _fmt_time, summarize

    rows = summarize(results, time_limit)
    width = max([len(s.method) for s in rows] + [6])
    print(f"{'method':<{width}}  {'certified':>11}  {'refused':>7}  {'SGM time':>9}  failures")
    for s in rows:
        ran = s.problems - s.refused
        fails = ", ".join(f"{k} {v}" for k, v in sorted(s.failures.items())) or "-"
        print(f"{s.method:<{width}}  {f'{s.successes}/{s.problems}':>11}  {s.refused:>7}  "
              f"{_fmt_time(s.sgm_time) if ran else '-':>9}  {fails}")
    for r in results:
        if r.method == "-":  # an unreadable file: one row, no method ran on it
            print(f"unreadable: {r.problem}: {r.message}")


def _names_hint(missing: list[str], names: list[str]) -> str:
    """The problem names a --problems NAME most likely meant (a folder's problems are named
    FOLDER/FILE, without the extension), else a few of the sets' names."""
    near = [n for m in missing for n in names
            if n.rsplit("/", 1)[-1] == m.rsplit("/", 1)[-1].rsplit(".", 1)[0]]
    if near:
        return f" (did you mean {', '.join(dict.fromkeys(near))}?)"
    shown = ", ".join(names[:4]) + (", ..." if len(names) > 4 else "")
    return f"; the sets' problems are named like {shown}" if names else ""


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name)
