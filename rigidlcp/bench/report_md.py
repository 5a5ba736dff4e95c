"""report.md of a ``rigidlcp bench`` run, in the manner of qpbenchmark's reports: the environment,
the summary tables (rigidlcp.bench.report) over all sets and per set, one performance profile
per kind of problem (rigidlcp.bench.profiles), the problems solved by nobody, the problems on
which methods disagree, the false claims (a "solved" that fails the check, an "infeasible"
without a proof; a secondary ray claims nothing), every failure by problem with a one-line
command that reruns it, and the results per problem.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from pathlib import Path

from .harness import NO_SOLUTION, Result
from .profiles import plot_profile
from .report import ACCURACIES, RESIDUAL_SHIFT, SHIFT, _fmt_time, summarize, summary_table

KINDS = ("LCP", "MLCP", "FC2D")


def _problems(results: Sequence[Result]) -> dict[tuple[str, str], list[Result]]:
    """{(set, problem): its rows} in run order, unreadable files left out."""
    out: dict[tuple[str, str], list[Result]] = {}
    for r in results:
        if r.method != "-":
            out.setdefault((r.set, r.problem), []).append(r)
    return out


def solved_by_nobody(results: Sequence[Result]) -> list[tuple[tuple[str, str], list[Result]]]:
    """The problems on which no method succeeded, with their rows."""
    return [(key, rows) for key, rows in _problems(results).items()
            if not any(r.success for r in rows)]


def disagreements(results: Sequence[Result]) -> list[tuple[tuple[str, str], str]]:
    """Problems on which the methods' claims contradict each other: a certified solution
    beside a claim that no solution exists (status "infeasible", proved or not), or beside a
    certified infeasibility (which would be a bug of the checks). One line of text each. A
    secondary ray without a proof (outcome "ray", Lemke's termination) is no claim, so no
    disagreement: it is listed with the failures."""
    out = []
    for key, rows in _problems(results).items():
        solved = [r.method for r in rows if r.outcome == "solved"]
        proved = [r.method for r in rows if r.outcome == "infeasible"]
        claims = [f"{r.method} ({r.status})" for r in rows
                  if r.status in NO_SOLUTION and r.outcome not in ("infeasible", "ray")]
        if solved and (proved or claims):
            text = f"certified solutions by {', '.join(solved)}"
            if claims:
                text += f"; claimed no solution: {', '.join(claims)}"
            if proved:
                text += f"; certified infeasible (contradiction): {', '.join(proved)}"
            out.append((key, text))
    return out


def false_claims(results: Sequence[Result]) -> list[Result]:
    """Claims the check rejected: "solved" with an answer that is not a solution
    (uncertified), "infeasible" without a proof (unproved_infeasible). A secondary ray claims
    nothing (outcome "ray"): not listed here."""
    return [r for r in results if r.outcome in ("uncertified", "unproved_infeasible")]


def _cell(r: Result) -> str:
    if r.outcome == "not_applicable":
        return "-"
    if r.outcome == "solved":
        return _fmt_time(r.time)
    if r.outcome == "infeasible":
        return f"no solution, {_fmt_time(r.time)}"
    return f"**{r.outcome}**"


def per_problem_table(results: Sequence[Result], set_name: str) -> list[str]:
    """One row per problem of the set, one column per method: the time of a success, the
    failure in bold, "-" for a refusal."""
    rows = [r for r in results if r.set == set_name and r.method != "-"]
    methods = list(dict.fromkeys(r.method for r in rows))
    cells: dict[str, dict[str, Result]] = {}
    for r in rows:
        cells.setdefault(r.problem, {})[r.method] = r
    lines = ["| problem | n | " + " | ".join(methods) + " |",
             "|---|---:|" + "---:|" * len(methods)]
    for problem, by in cells.items():
        n = next(iter(by.values())).n
        lines.append(f"| `{problem}` | {n} | "
                     + " | ".join(_cell(by[m]) if m in by else "" for m in methods) + " |")
    return lines


def write_report(results: Sequence[Result], out: str | os.PathLike, *, time_limit: float,
                 tol: float, set_info: dict[str, str], header: Sequence[str] = (),
                 notes: Sequence[str] = (), environment: Sequence[tuple[str, str]] = (),
                 rerun: Callable[[Result], str] | None = None,
                 warmups: dict[str, list[float]] | None = None) -> Path:
    """DIR/report.md and DIR/profile_<KIND>.png (one per kind of problem).

    set_info: {set name: a one-line description}; header: lines about the run (command);
    notes: e.g. skipped methods; environment: (what, value) rows (versions, CPU, commit);
    rerun: the command line that reruns one (problem, method) pair; warmups: {method:
    seconds of its untimed warm-up solves}.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    lines = ["# rigidlcp bench report", "", *header]
    if environment:
        lines += ["", "## Environment", "", "| | |", "|---|---|"]
        lines += [f"| {k} | {v} |" for k, v in environment]
    accs = " and ".join(f"{a:g}" for a in ACCURACIES)
    lines += [
        "", "## How answers are judged", "",
        "Every answer is checked by the harness, never taken from the solver (rigidlcp's "
        "methods, Siconos's and the other peers' alike): a claimed solution must pass "
        f"`verify.certify` (scaled complementarity residual <= {tol:g}); a claim that no "
        "solution exists must be confirmed by an LP Farkas certificate (so must a secondary "
        "ray, Lemke's termination, to count as 'infeasible': otherwise its outcome is 'ray', a "
        "failure that claims nothing); a solve over the time "
        f"limit ({time_limit:g} s), an error or any other status is a failure. A refusal "
        "(the method does not take the problem: outside its class or size limit) is counted "
        "apart, never timed and left out of every mean. Every method is timed the same way: "
        "the whole call from Python on the problem's data, one solve at a time, after one "
        "untimed warm-up solve per fresh process (reported apart below).",
        "",
        "Columns: success = certified answers / problems given; SGM time = shifted geometric "
        f"mean of the solve time, shift {1e3 * SHIFT:g} ms, over the accepted problems, "
        "failures counted at the time limit; SGM time, common KIND = the same mean over only "
        "the problems of that kind that every method accepting at least half of the kind's "
        "problems accepts ('-': the method accepts fewer than half of them, and is left out "
        "of that comparison rather than shrinking it to the few it takes); success at an "
        "accuracy "
        f"({accs}) = certified answers whose backward error (the check's, else the scaled "
        "residual) / forward "
        "error bound is at most that accuracy ('n/a': the method reports no forward bound; a "
        "certified 'no solution' counts at every accuracy); SGM residual = shifted geometric "
        f"mean (shift {RESIDUAL_SHIFT:g}) of the scaled residual over the accepted problems, "
        "a failure without a point counted at 1; median iterations over the successes (each "
        "method's own count: not comparable across methods); worst residual = the largest "
        "scaled residual over the answers claimed as solutions. Profiles: Dolan-More, "
        "rho_s(tau) = fraction of problems solved within a factor tau of the fastest method, "
        "one figure per kind of problem, with the methods that accept any of its problems.",
    ]
    lines += ["", *(f"- {n}" for n in notes)] if notes else []
    if warmups:
        lines += ["", "Warm-up (untimed in the results; the first call of each method in a "
                  "fresh process: imports, compilation, caches): " + ", ".join(
                      f"{m} {_fmt_time(max(ts))}" for m, ts in warmups.items()
                      if ts and not math.isnan(max(ts))) + "."]
    unreadable = [r for r in results if r.outcome == "unreadable"]
    if unreadable:
        lines += ["", f"Unreadable files ({len(unreadable)}), not run:", ""]
        lines += [f"- `{r.problem}`: {r.message}" for r in unreadable]
    lines += ["", "## All sets", ""]
    lines += summary_table(summarize(results, time_limit))
    for kind in KINDS:
        png = plot_profile(results, out / f"profile_{kind}.png", f"{kind}s, all sets", kind)
        if png is not None:
            lines += ["", f"![performance profile, {kind}s]({png.name})"]
    for set_name in dict.fromkeys(r.set for r in results):
        ran = {r.problem for r in results if r.set == set_name and r.method != "-"}
        bad = {r.problem for r in results if r.set == set_name and r.method == "-"}
        sizes = sorted({r.n for r in results if r.set == set_name and r.method != "-"})
        count = f"{len(ran)} problem{'s' * (len(ran) != 1)}" + (
            f" ({len(bad)} more unreadable)" if bad else "")
        if sizes:
            count += f", n = {sizes[0]}..{sizes[-1]}"
        lines += ["", f"## {set_name}", "", f"{set_info.get(set_name, '')} {count}.".strip()]
        if ran:
            lines += ["", *summary_table(summarize(results, time_limit, set_name))]
    lines += _sections(results, rerun)
    path = out / "report.md"
    path.write_text("\n".join(lines) + "\n")
    return path


def _sections(results: Sequence[Result], rerun: Callable[[Result], str] | None) -> list[str]:
    """Solved by nobody, methods disagree, false claims, failures by problem, results per
    problem."""
    lines = ["", "## Solved by nobody", ""]
    nobody = solved_by_nobody(results)
    lines += [f"- `{p}` ({s}): " + ", ".join(f"{r.method} {r.outcome}" for r in rows)
              for (s, p), rows in nobody] or ["None: every problem was solved by some method."]
    lines += ["", "## Methods disagree", ""]
    lines += [f"- `{p}` ({s}): {text}" for (s, p), text in disagreements(results)] or [
        "None: no certified solution beside a claim that no solution exists."]
    lines += ["", "## False claims", "",
              "Answers whose claim the check rejected (a 'solved' that is not a solution, an "
              "'infeasible' without a proof): counted as failures of the method that gave "
              "them. A secondary ray without a proof (outcome 'ray') is Lemke's termination, "
              "not a claim: it is a failure, listed by problem below.", ""]
    lines += [f"- {r.method} on `{r.problem}`: {r.outcome} (claimed {r.status}; "
              f"residual {r.residual:.1e}, scaled {r.scaled_residual:.1e})"
              for r in false_claims(results)] or ["None."]
    lines += ["", "## Failures by problem", ""]
    failed = [(key, [r for r in rows if not r.success and r.outcome != "not_applicable"])
              for key, rows in _problems(results).items()]
    failed = [(key, rows) for key, rows in failed if rows]
    for (s, p), rows in failed:
        lines.append(f"- `{p}` ({s}, n = {rows[0].n})")
        for r in rows:
            msg = f": {r.message}" if r.message else ""
            lines.append(f"  - {r.method}: {r.outcome}{msg}")
            if rerun is not None:
                lines.append(f"    rerun: `{rerun(r)}`")
    if not failed:
        lines.append("None.")
    lines += ["", "## Results per problem", "",
              "Time of each success; a failure in bold; '-' a refusal."]
    for set_name in dict.fromkeys(r.set for r in results if r.method != "-"):
        lines += ["", f"### {set_name}", "", *per_problem_table(results, set_name)]
    return lines
