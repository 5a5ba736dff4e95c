"""Regenerate docs/comparison.md, the solver comparison, with one command:

    python docs/make_comparison.py                    # the stated collection (a few minutes)
    python docs/make_comparison.py --quick --out DIR  # a small subset, into DIR (a look only)
    python docs/make_comparison.py --run DIR          # keep the bench run in DIR; run again,
                                                      # it reuses a finished run (the page is
                                                      # written again) or resumes a broken one

The collection (stated in the page it writes):

* Siconos's numerics test files: its LCP, MLCP and 2D friction-contact folders
  (../shared/data/siconos, or --siconos-data; skipped with a note when absent);
* the generated families of `rigidlcp bench --list` (random-p, random-psd, singular-psd,
  degenerate, murty, infeasible);
* the event LCPs of Fig. 9's run (rect 10 x 4, mu_pp 0.1, mu_plane 0.2, mu_wall 0,
  gamma 0.16 g, seed 1: every event LCP the run solved, as `rigidlcp simulate
  --dump-problems` writes them), harvested into the cache;
* the fuzz harness's hard classes (rigidlcp.bench.fuzz_cases: ill-conditioned P, scaled,
  singular PSD, degenerate, integer ties, robustly infeasible, ...), seeded, written as .npz.

It runs `rigidlcp bench` on all of them in this process, with every rigidlcp method, every
Siconos solver when /usr/bin/python3 has siconos, and every installed peer
(`pip install -e ".[peers]"`), then writes docs/comparison.md (the tables, the side-by-side
on Fig. 9's events, what each method is good for), docs/comparison/report.md (the full report:
every failure with its rerun line, results per problem) and the profiles
docs/comparison/profile_<KIND>.png. Existing files there are replaced (this script owns them).
The collection's folders are written to CACHE/comparison/collection (CACHE: --cache, else
$RIGIDLCP_CACHE or ~/.cache/rigidlcp), where the report's rerun lines find them.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import sys
import tempfile
from pathlib import Path

DOCS = Path(__file__).resolve().parent
#: ../shared/data/siconos beside the checkout (the nearest ancestor folder that has it)
SICONOS_DATA = next((a / "shared" / "data" / "siconos" for a in DOCS.parents
                     if (a / "shared" / "data" / "siconos").is_dir()),
                    DOCS.parent.parent / "shared" / "data" / "siconos")
FAMILIES = ("random-p", "random-psd", "singular-psd", "degenerate", "murty", "infeasible")
SIZES = "4,16,64"
HARD_PER_CLASS = 3


def build_collection(root: Path, siconos_data: Path, quick: bool, cache: Path
                     ) -> tuple[list[str], list[tuple[str, str]], list[str]]:
    """(the --set specs, (set, what it is) rows, notes): folders written under root (kept, so
    that the report's rerun lines work)."""
    import numpy as np

    from rigidlcp import lcp
    from rigidlcp.bench.fuzz_cases import CLASSES, make_case
    from rigidlcp.bench.problem_sets import harvest_events

    specs, rows, notes = [], [], []
    for kind, what in (("lcp", "LCP"), ("mlcp", "MLCP"), ("fc2d", "2D friction-contact")):
        folder = siconos_data / kind
        if folder.is_dir():
            link = root / f"siconos-{kind}"
            shutil.copytree(folder, link)
            if quick:  # the two smallest files of each kind
                files = sorted(link.glob("*.dat"), key=lambda f: f.stat().st_size)
                for f in files[2:]:
                    f.unlink()
            specs.append(str(link))
            rows.append((f"siconos-{kind}", f"Siconos's {what} test files "
                         f"(numerics/src/.../test/data, {siconos_data})"))
        else:
            notes.append(f"Siconos's {what} files skipped: {folder} not found")
    for name in FAMILIES[:2] if quick else FAMILIES:
        specs.append(name)
        rows.append((name, f"`rigidlcp bench --list`'s {name} family, n = "
                     f"{'4' if quick else SIZES}, two per size, seed 0"))
    cache_dir = cache / "comparison"
    lx, ly = (4, 3) if quick else (10, 4)
    events = harvest_events("rect", lx, ly, cache_dir / f"fig9-rect{lx}x{ly}")
    fig9 = root / "fig9-events"
    fig9.mkdir()
    for f in sorted(events.glob("event_*.npz")):
        shutil.copy(f, fig9 / f.name)
    specs.append(str(fig9))
    rows.append(("fig9-events", f"every event LCP of Fig. 9's run (rect {lx} x {ly}, mu_pp "
                 "0.1, mu_plane 0.2, mu_wall 0, gamma 0.16 g, seed 1, lemke), as `rigidlcp "
                 "simulate --dump-problems` writes them"))
    hard = root / "hard-classes"
    hard.mkdir()
    for k, kind in enumerate(CLASSES[:3] if quick else CLASSES):
        for j in range(1 if quick else HARD_PER_CLASS):
            case = make_case(kind, 1000 * k + j)
            meta = {"expected": {True: "solution", False: "infeasible"}.get(case.solvable,
                                                                             "unknown")}
            lcp.LCP(np.asarray(case.M), np.asarray(case.q), name=f"{kind}-{j}",
                    meta=meta).save(hard / f"{kind}-{j}.npz")
    specs.append(str(hard))
    rows.append(("hard-classes", f"the fuzz harness's classes (rigidlcp.bench.fuzz_cases, "
                 f"{'1' if quick else HARD_PER_CLASS} per class, seeds 1000 k + j): "
                 + ", ".join(CLASSES[:3] if quick else CLASSES)))
    return specs, rows, notes


def raised(results, method: str) -> tuple[int, int, str]:
    """(calls that raised an exception, calls made, the most common message) of `method`
    over `results` (refusals are no calls)."""
    ran = [r for r in results if r.method == method and r.outcome != "not_applicable"]
    errors = [r.message for r in ran if r.outcome == "error"]
    common = max(set(errors), key=errors.count) if errors else ""
    return len(errors), len(ran), common


def good_for(results, method: str, summaries_by_set: dict) -> str:
    """One line from the results: first, when at least half of the method's calls raised an
    exception, that it is broken here (how many, the message); then the sets the method
    solved entirely (and where it was the fastest such method by SGM time), the sets where it
    solved none, those where it failed some, the sets it refused."""
    full, fastest, none, partial, refused = [], [], [], [], []
    for set_name, by in summaries_by_set.items():
        s = by.get(method)
        if s is None:
            continue
        ran = s.problems - s.refused
        if ran == 0:
            refused.append(set_name)
        elif s.successes == s.problems:
            full.append(set_name)
            best = min((x.sgm_time for x in by.values() if x.successes == x.problems
                        and x.problems), default=math.nan)
            if s.sgm_time <= best:
                fastest.append(set_name)
        elif s.successes == 0:
            none.append(f"{set_name} 0/{s.problems}"
                        + (f" ({s.refused} refused)" if s.refused else ""))
        else:
            partial.append(f"{set_name} {s.successes}/{s.problems}"
                           + (f" ({s.refused} refused)" if s.refused else ""))
    parts = []
    errors, calls, message = raised(results, method)
    if calls and 2 * errors >= calls:
        parts.append(f"**broken here: {errors} of its {calls} calls raised an exception** "
                     f"(`{message}`)")
    if full:
        parts.append(f"solves all of {', '.join(full)}")
    if fastest:
        parts.append(f"fastest of those that do on {', '.join(fastest)}")
    if partial:
        parts.append(f"solves part of {'; '.join(partial)}")
    if none:
        parts.append(f"solves none of {'; '.join(none)}")
    mine = [r for r in results if r.method == method]
    false = sum(r.outcome == "uncertified" for r in mine)
    if false:
        parts.append(f"**{false} false success{'es' if false > 1 else ''}** (answers it called "
                     "solutions that are not: check its 'solved' before use)")
    unproved = sum(r.outcome == "unproved_infeasible" for r in mine)
    if unproved:
        parts.append(f"{unproved} claim{'s' if unproved > 1 else ''} of no solution without "
                     "a proof (no exact Farkas certificate: a failure, not an answer)")
    rays = sum(r.outcome == "ray" for r in mine)
    if rays:
        parts.append(f"{rays} secondary ray{'s' if rays > 1 else ''} (Lemke's termination; no "
                     "proof of infeasibility and no claim of it: a failure, not an answer)")
    if refused:
        parts.append(f"does not take {', '.join(refused)}")
    return "; ".join(parts) or "-"


def in_short(results, summaries_by_set: dict) -> list[str]:
    """Markdown lines answering "which method for which problems": per set, the methods that
    certified every problem and the fastest of them by SGM time (else the most certified),
    then the methods with false successes and the broken ones."""
    lines = ["| set | certified every problem | fastest of those (SGM time) |",
             "|---|---|---|"]
    for set_name, by in summaries_by_set.items():
        ran = {m: x for m, x in by.items() if x.refused < x.problems}
        full = [m for m, x in ran.items() if x.successes == x.problems]
        if full:
            best = min(full, key=lambda m: ran[m].sgm_time)
            lines.append(f"| {set_name} | {', '.join(full)} | {best} "
                         f"({_time(ran[best].sgm_time)}) |")
        elif ran:
            top = max(x.successes for x in ran.values())
            most = [m for m, x in ran.items() if x.successes == top]
            lines.append(f"| {set_name} | none; most: {', '.join(most)} "
                         f"({top}/{ran[most[0]].problems}) | - |")
    methods = list(dict.fromkeys(r.method for r in results if r.method != "-"))
    false = {m: sum(r.method == m and r.outcome == "uncertified" for r in results)
             for m in methods}
    false = {m: k for m, k in false.items() if k}
    if false:
        lines += ["", "Called solutions that are not (their 'solved' must be checked): "
                  + ", ".join(f"{m} {k}" for m, k in false.items()) + "."]
    broken = []
    for m in methods:
        errors, calls, message = raised(results, m)
        if calls and 2 * errors >= calls:
            broken.append(f"{m} ({errors} of {calls} calls raised `{message}`)")
    if broken:
        lines += ["", "Broken here: " + "; ".join(broken) + "."]
    return lines


def _time(t: float) -> str:
    return "-" if math.isnan(t) else f"{1e3 * t:.3g} ms" if t < 1 else f"{t:.3g} s"


def write_page(path: Path, results, rows, notes, command: str, time_limit: float) -> None:
    from rigidlcp import lcp
    from rigidlcp.bench.peers import PEERS
    from rigidlcp.bench.report import summarize, summary_table
    from rigidlcp.bench.siconos_runner import SICONOS_METHODS

    sets = list(dict.fromkeys(r.set for r in results if r.method != "-"))
    methods = list(dict.fromkeys(r.method for r in results if r.method != "-"))
    by_set = {s: {x.method: x for x in summarize(results, time_limit, s)} for s in sets}
    described = {m.name: m.description for m in lcp.methods()}
    described.update({m: p.description for m, p in PEERS.items()})
    described.update({m: f"Siconos {s.solver} ({s.kind})" for m, s in SICONOS_METHODS.items()})
    lines = [
        "# Solver comparison", "",
        f"Generated by `{command}` (do not edit by hand). The full report, with every "
        "failure and the command that reruns it and the results per problem, is "
        "[comparison/report.md](comparison/report.md); how answers are judged and timed is "
        "in [bench.md](bench.md). Every answer, rigidlcp's and every peer's, is judged by the "
        "same check; every method is timed as the whole call from Python on M and q "
        "(rigidlcp: `lcp.solve(lcp.LCP(M, q), method)`, one call per problem, no batches) "
        "after an untimed warm-up (with its own limit, so that an import or numba's "
        "compilation is not counted as a timeout; its times are in the report); times are "
        "indicative (a shared 2-core machine).", "",
        "How to read the tables: *success* counts certified answers (a solution that passes "
        "`verify.certify`, or a claim of no solution backed by a Farkas certificate that "
        "holds in exact rational arithmetic); *SGM time* is the shifted geometric mean "
        "(shift 10 ms) of the time over the problems the method accepted, each failure "
        f"counted at the time limit ({time_limit:g} s), so a method that fails fast does "
        "not look fast; *SGM time, common KIND (k)* is the same mean over the k problems "
        "of that kind that every method accepting at least half of the kind's problems "
        "accepts ('-': the method accepts fewer than half, and is left out of that "
        "comparison rather than shrinking it to the few problems it takes); *refused* "
        "problems (outside the method's class or size limit) are neither timed nor "
        "failures.", ""]
    lines += ["## In short", "",
              "Per set, the methods whose every answer was certified, and the fastest of "
              "them; the details follow.", "", *in_short(results, by_set), ""]
    lines += ["## The collection", "", "| set | what |", "|---|---|"]
    lines += [f"| {s} | {w} |" for s, w in rows]
    lines += ["", *(f"- {n}" for n in notes)] if notes else []
    lines += ["", "## Successes per set", "",
              "Certified answers / problems given; '-': the method takes none of the set; "
              "'k false': k answers the method called solutions that are not (the check "
              "rejected them; see below); 'k raised': k calls ended in an exception; 'k "
              "refused': k problems outside the method's class or size limit.", "",
              "| method | " + " | ".join(sets) + " |", "|---|" + "---:|" * len(sets)]
    for m in methods:
        cells = []
        for s in sets:
            x = by_set[s].get(m)
            marks = [f"{x.failures[k]} {word}" for k, word in
                     (("uncertified", "false"), ("error", "raised"))
                     if x is not None and x.failures.get(k, 0)]
            if x is not None and 0 < x.refused < x.problems:
                marks.append(f"{x.refused} refused")
            cells.append("-" if x is None or x.refused == x.problems
                         else f"{x.successes}/{x.problems}"
                         + (f" ({', '.join(marks)})" if marks else ""))
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    fig9 = by_set.get("fig9-events", {})
    if fig9:
        lines += ["", "## Side by side on Fig. 9's event LCPs", "",
                  "rigidlcp's methods against the peers on every event LCP of Fig. 9's run "
                  "(the same problems, one process, the same check; the methods that take "
                  "them).", "",
                  *summary_table([x for x in fig9.values() if x.refused < x.problems])]
    lines += ["", "## All sets", "", *summary_table(list(summarize(results, time_limit)))]
    false = [r for r in results if r.outcome == "uncertified"]
    lines += ["", "## False successes", "",
              "Answers a method reported as solutions that the check rejected (rigidlcp's own "
              "methods are checked inside `lcp.solve` and say `inaccurate` instead, so they "
              "never appear here):", ""]
    for m in dict.fromkeys(r.method for r in false):
        mine = [r for r in false if r.method == m]
        worst = max((r.residual for r in mine if not math.isnan(r.residual)), default=math.nan)
        names = ", ".join(f"`{r.problem}`" for r in mine[:4]) + (", ..." if len(mine) > 4
                                                                  else "")
        lines.append(f"- **{m}**: {len(mine)} (largest residual max|min(z, w)| "
                     f"{worst:.1e}): {names}")
    if not false:
        lines.append("None.")
    lines += ["", "## Performance profiles", ""]
    for kind in ("LCP", "MLCP", "FC2D"):
        if (path.parent / "comparison" / f"profile_{kind}.png").exists():
            lines += [f"![{kind}s](comparison/profile_{kind}.png)", ""]
    lines += ["## What each method is good for", "",
              "From the results above (the method's class and limits in "
              "[solvers.md](solvers.md)).", ""]
    lines += [f"- **{m}** ({described.get(m, '')}): {good_for(results, m, by_set)}."
              for m in methods]
    path.write_text("\n".join(lines) + "\n")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="a small subset (a look only)")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="where comparison.md and comparison/ go (default: docs/)")
    p.add_argument("--time-limit", type=float, default=2.0, help="seconds per solve")
    p.add_argument("--siconos-data", default=str(SICONOS_DATA), metavar="DIR")
    p.add_argument("--cache", default=None, metavar="DIR", help="where Fig. 9 is harvested")
    p.add_argument("--run", default=None, metavar="DIR",
                   help="keep the bench run (results.csv, report.md) in DIR instead of a "
                        "temporary folder; a finished run there is reused as it is (only the "
                        "page is written again), an interrupted one is resumed (the pairs "
                        "done are not run again)")
    args = p.parse_args(argv)
    from rigidlcp.bench.harness import read_csv
    from rigidlcp.cli.main import main as rigidlcp

    out = Path(args.out) if args.out else DOCS
    figures = out / "comparison"
    from rigidlcp.bench.problem_sets import default_cache_dir

    cache = Path(args.cache) if args.cache else default_cache_dir()
    root = cache / "comparison" / ("collection-quick" if args.quick else "collection")
    if root.exists():
        shutil.rmtree(root)  # rebuilt each time: the same seeds give the same files
    root.mkdir(parents=True)
    with tempfile.TemporaryDirectory(prefix="comparison_") as tmp:
        specs, rows, notes = build_collection(root, Path(args.siconos_data), args.quick,
                                              cache)
        run = Path(args.run) if args.run else Path(tmp) / "run"
        argv_bench = ["bench", "--set", ",".join(specs), "--out", str(run), "--quiet",
                      "--no-batch", "--time-limit", f"{args.time_limit:g}", "--sizes",
                      "4" if args.quick else SIZES]
        if (run / "report.md").is_file():  # a finished run (bench writes it last): reused
            print(f"reusing the finished bench run in {run} (remove it to run again)",
                  flush=True)
        else:
            if (run / "results.csv").is_file():
                argv_bench.append("--resume")  # an interrupted run: only what is missing runs
            print("rigidlcp " + " ".join(argv_bench), flush=True)
            if rigidlcp(argv_bench) != 0:
                sys.exit("rigidlcp bench failed")
        results = read_csv(run / "results.csv")
        if figures.exists():
            shutil.rmtree(figures)
        figures.mkdir(parents=True)
        for f in run.glob("profile_*.png"):
            shutil.copy(f, figures / f.name)
        home = str(Path.home())
        report = (run / "report.md").read_text().replace(str(run), "OUT")
        report = report.replace(home + os.sep, "~" + os.sep)
        (figures / "report.md").write_text(report)
        command = "python docs/make_comparison.py" + (" --quick" if args.quick else "") + (
            f" --time-limit {args.time_limit:g}" if args.time_limit != 2.0 else "")
        write_page(out / "comparison.md", results, rows, notes, command, args.time_limit)
    print(f"wrote {out / 'comparison.md'} and {figures}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
