"""Metrics, performance profiles and report.md of a ``rigidlcp bench`` run (issue 6).

Metrics per set and method (qpbenchmark's conventions, stated in the report):

* success rate: the fraction of problems with a certified answer (rigidlcp.bench.harness.judge);
* shifted geometric mean of the solve time, shift s = 10 ms:
  sgm = exp(mean(log(t_i + s))) - s over *all* problems, a failure counted at the time limit
  (so a method cannot look fast by failing fast);
* iterations: the median over the successes of the method's own count (pivots for lemke,
  pivoting and enumerate's bases, sweeps for pgs, interior-point or ADMM iterations for the QP
  methods, Siconos's SICONOS_IPARAM_ITER_DONE): comparable within a method, not across;
* worst residual: the largest scaled complementarity residual (verify.certify's measure,
  max_i |min(z_i / z_s, w_i / w_s)|; friction contact: the relative natural-map residual) over
  the answers the method claimed were solutions;
* refused: problems the method declined (NotApplicable: outside its class or size limit),
  reported apart from its failures (a refusal still counts at the time limit in the SGM);
* SGM over the common problems, per kind of problem (LCP, MLCP, FC2D): for each kind, the
  methods compared on it are those that accept at least one problem of that kind, and the
  common problems are the problems of that kind that every one of them accepts (none refused
  it); the same mean over only those, a fair comparison of methods with different domains
  ("-" for a method that refuses every problem of the kind).
Unreadable files (method "-") are listed with their reason, outside every method's numbers.

Performance profile (Dolan & More, Math. Program. 91, 201, 2002): with t_ps the time of method
s on problem p (infinite when it failed), r_ps = t_ps / min_s t_ps, and
rho_s(tau) = |{p : r_ps <= tau}| / |P|, plotted against log2(tau). rho_s(1) is the fraction of
problems on which s was fastest, rho_s(inf) its success rate.
"""

from __future__ import annotations

import math
import os
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .harness import Result

SHIFT = 0.010  # seconds


def shifted_geometric_mean(times: Sequence[float], shift: float = SHIFT) -> float:
    """exp(mean(log(t + shift))) - shift (nan for no times)."""
    t = np.asarray(times, dtype=float)
    if t.size == 0:
        return math.nan
    return float(np.exp(np.mean(np.log(t + shift))) - shift)


@dataclass
class Summary:
    """Metrics of one method on one set (or on all sets: set = "all")."""

    set: str
    method: str
    problems: int
    successes: int
    sgm_time: float
    median_iterations: float
    worst_residual: float
    failures: Counter
    refused: int = 0
    #: {kind: SGM over the common problems of that kind} (kinds the method is compared on)
    sgm_common: dict = field(default_factory=dict)
    #: {kind: number of common problems of that kind} (the same for every method)
    common: dict = field(default_factory=dict)

    @property
    def rate(self) -> float:
        return self.successes / self.problems if self.problems else math.nan


def summarize(results: Sequence[Result], time_limit: float, set_name: str | None = None
              ) -> list[Summary]:
    """One Summary per method over the results of `set_name` (None: every set, "all")."""
    rows = [r for r in results if (set_name is None or r.set == set_name) and r.method != "-"]
    common_sets = common_problems(rows)
    out = []
    for method in dict.fromkeys(r.method for r in rows):
        mine = [r for r in rows if r.method == method]
        sgm_common = {}
        for kind, (compared, problems) in common_sets.items():
            if method in compared:
                sgm_common[kind] = shifted_geometric_mean(
                    [r.time if r.success else time_limit for r in mine
                     if r.kind == kind and (r.set, r.problem) in problems])
        ok = [r for r in mine if r.success]
        times = [r.time if r.success else time_limit for r in mine]
        its = [r.iterations for r in ok if r.iterations is not None]
        claimed = [r.scaled_residual for r in mine
                   if r.status == "solved" and not math.isnan(r.scaled_residual)]
        out.append(Summary(
            set=set_name or "all", method=method, problems=len(mine), successes=len(ok),
            sgm_time=shifted_geometric_mean(times),
            median_iterations=float(np.median(its)) if its else math.nan,
            worst_residual=max(claimed) if claimed else math.nan,
            failures=Counter(r.outcome for r in mine
                             if not r.success and r.outcome != "not_applicable"),
            refused=sum(r.outcome == "not_applicable" for r in mine),
            sgm_common=sgm_common, common={k: len(p) for k, (_, p) in common_sets.items()}))
    return out


def common_problems(rows: Sequence[Result]) -> dict[str, tuple[set, set]]:
    """{kind: (compared methods, common problems)} over `rows` (one set's or all results):
    the methods compared on a kind accept (do not refuse) at least one of its problems; its
    common problems, (set, problem) pairs, are those that none of these methods refused."""
    out = {}
    order = {"LCP": 0, "MLCP": 1, "FC2D": 2}
    for kind in sorted(dict.fromkeys(r.kind for r in rows), key=lambda k: order.get(k, 3)):
        mine = [r for r in rows if r.kind == kind]
        compared = {r.method for r in mine if r.outcome != "not_applicable"}
        refused = {(r.set, r.problem) for r in mine
                   if r.method in compared and r.outcome == "not_applicable"}
        out[kind] = (compared, {(r.set, r.problem) for r in mine} - refused)
    return out


def profile_data(results: Sequence[Result], set_name: str | None = None
                 ) -> tuple[list[str], np.ndarray]:
    """(methods, ratios): ratios[p, s] = t_ps / min_s t_ps (inf for a failure; all inf when
    every method failed on p). Times are floored at 1 microsecond."""
    rows = [r for r in results if (set_name is None or r.set == set_name) and r.method != "-"]
    methods = list(dict.fromkeys(r.method for r in rows))
    problems = list(dict.fromkeys((r.set, r.problem) for r in rows))
    T = np.full((len(problems), len(methods)), np.inf)
    index = {p: i for i, p in enumerate(problems)}
    for r in rows:
        if r.success:
            T[index[(r.set, r.problem)], methods.index(r.method)] = max(r.time, 1e-6)
    best = T.min(axis=1, initial=np.inf)
    with np.errstate(invalid="ignore"):
        ratios = np.where(np.isfinite(best)[:, None], T / best[:, None], np.inf)
    return methods, ratios


def plot_profile(results: Sequence[Result], path: str | os.PathLike, title: str,
                 set_name: str | None = None) -> Path | None:
    """The Dolan-More profile as a PNG (matplotlib Agg); None when there is nothing to plot."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    methods, ratios = profile_data(results, set_name)
    if ratios.size == 0:
        return None
    finite = ratios[np.isfinite(ratios)]
    tau_max = max(2.0, float(finite.max()) * 2 if finite.size else 2.0)
    taus = np.logspace(0, np.log2(tau_max), 400, base=2.0)
    fig, ax = plt.subplots(figsize=(7.6, 4.2))
    for k, method in enumerate(methods):
        rho = (ratios[:, k][None, :] <= taus[:, None]).mean(axis=1)
        ax.step(np.log2(taus), rho, where="post", label=method,
                linestyle=("-", "--", ":", "-.")[k // 10 % 4])
    ax.set_xlabel(r"$\log_2 \tau$  (time within a factor $\tau$ of the fastest)")
    ax.set_ylabel(r"$\rho_s(\tau)$: fraction of problems")
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlim(0, np.log2(tau_max))
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _fmt_time(t: float) -> str:
    return "-" if math.isnan(t) else f"{1e3 * t:.3g} ms" if t < 1 else f"{t:.3g} s"


def _fmt(v: float, spec: str) -> str:
    return "-" if math.isnan(v) else format(v, spec)


def summary_table(summaries: Sequence[Summary]) -> list[str]:
    """Markdown table lines of summaries: one "SGM time, common" column per kind of problem
    (the number of common problems of that kind in its header)."""
    common = summaries[0].common if summaries else {}
    heads = "".join(f" SGM time, common {k or 'problems'} ({n}) |" for k, n in common.items())
    lines = [f"| method | success | refused | SGM time |{heads} median iterations | "
             "worst residual | failures |",
             "|---|---:|---:|---:|" + "---:|" * len(common) + "---:|---:|---|"]
    for s in summaries:
        fails = ", ".join(f"{k} {v}" for k, v in sorted(s.failures.items())) or "-"
        cells = "".join(f" {_fmt_time(s.sgm_common.get(k, math.nan))} |" for k in common)
        lines.append(
            f"| {s.method} | {s.successes}/{s.problems} ({100 * s.rate:.0f}%) | {s.refused} | "
            f"{_fmt_time(s.sgm_time)} |{cells} "
            f"{_fmt(s.median_iterations, '.0f')} | {_fmt(s.worst_residual, '.1e')} | "
            f"{fails} |")
    return lines


def write_report(results: Sequence[Result], out: str | os.PathLike, *, time_limit: float,
                 tol: float, set_info: dict[str, str], header: Sequence[str] = (),
                 notes: Sequence[str] = ()) -> Path:
    """DIR/report.md with a table per set and overall, and DIR/profile_<set>.png plots.

    set_info: {set name: a one-line description (class, expected answer)}. header: lines
    about the run (command, machine); notes: e.g. skipped methods.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    lines = ["# rigidlcp bench report", ""]
    lines += list(header)
    lines += [
        "",
        f"Every answer is checked by the harness: a claimed solution must pass "
        f"`verify.certify` (scaled complementarity residual <= {tol:g}); a claim that no "
        "solution exists must be confirmed by an LP Farkas certificate; a solve over the time "
        f"limit ({time_limit:g} s), a refusal, an error or any other status is a failure.",
        "",
        "Columns: success = certified answers / problems; SGM time = shifted geometric mean "
        f"of the solve time, shift {1e3 * SHIFT:g} ms, failures counted at the time limit; "
        "SGM time, common KIND = the same mean over only the problems of that kind (LCP, MLCP, "
        "FC2D) that every method accepting any problem of the kind accepts ('-': the method "
        "refuses every problem of the kind); "
        "median iterations over the successes (each method's own count: pivots, sweeps or "
        "solver iterations); worst residual = largest scaled residual max|min(z/z_s, w/w_s)| "
        "over the answers claimed as solutions; failures by kind. Profiles: Dolan-More, "
        "rho_s(tau) = fraction of problems solved within a factor tau of the fastest method.",
    ]
    lines += ["", *(f"- {n}" for n in notes)] if notes else []
    unreadable = [r for r in results if r.outcome == "unreadable"]
    if unreadable:
        lines += ["", f"Unreadable files ({len(unreadable)}), not run:", ""]
        lines += [f"- `{r.problem}`: {r.message}" for r in unreadable]
    lines += ["", "## All sets", ""]
    lines += summary_table(summarize(results, time_limit))
    png = plot_profile(results, out / "profile_all.png", "all sets")
    if png is not None:
        lines += ["", f"![performance profile, all sets]({png.name})"]
    for set_name in dict.fromkeys(r.set for r in results):
        n_problems = len({r.problem for r in results if r.set == set_name})
        sizes = sorted({r.n for r in results if r.set == set_name})
        lines += ["", f"## {set_name}", "",
                  f"{set_info.get(set_name, '')} {n_problems} problems, n = "
                  f"{sizes[0]}..{sizes[-1]}.".strip(), ""]
        lines += summary_table(summarize(results, time_limit, set_name))
        png = plot_profile(results, out / f"profile_{_slug(set_name)}.png", set_name, set_name)
        if png is not None:
            lines += ["", f"![performance profile, {set_name}]({png.name})"]
    path = out / "report.md"
    path.write_text("\n".join(lines) + "\n")
    return path


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in name)
