"""Metrics and summary tables of a ``rigidlcp bench`` run (issue 6); the profiles are drawn by
rigidlcp.bench.profiles and report.md written by rigidlcp.bench.report_md.

Metrics per set and method (qpbenchmark's conventions, stated in the report):

* success rate: the fraction of problems with a certified answer (rigidlcp.bench.harness.judge);
* shifted geometric mean of the solve time, shift s = 10 ms:
  sgm = exp(mean(log(t_i + s))) - s over the problems the method accepted (a refusal is not
  timed: the method never ran), a failure counted at the time limit (so a method cannot look
  fast by failing fast);
* success at stated accuracies (ACCURACIES, 1e-8 and 1e-12): the answers certified with a
  backward error (the scaled residual) <= the accuracy, and, where a forward error bound is
  reported, with that bound <= the accuracy; a certified "no solution" counts at every
  accuracy;
* SGM residual: the shifted geometric mean (shift 1e-16, rounding level) of the scaled
  residual over the accepted problems, an answer without a point (a failure) counted at 1;
* iterations: the median over the successes of the method's own count (pivots for lemke,
  pivoting and enumerate's bases, sweeps for pgs, interior-point or ADMM iterations for the QP
  methods, Siconos's SICONOS_IPARAM_ITER_DONE): comparable within a method, not across;
* worst residual: the largest scaled complementarity residual (verify.certify's measure,
  max_i |min(z_i / z_s, w_i / w_s)|; friction contact: the relative natural-map residual) over
  the answers the method claimed were solutions;
* refused: problems the method declined (NotApplicable: outside its class or size limit),
  reported apart from its failures and outside the SGMs;
* SGM over the common problems, per kind of problem (LCP, MLCP, FC2D): for each kind, the
  methods compared on it are those that accept at least half of its problems (COMMON_SHARE),
  and the common problems are the problems of that kind that every one of them accepts (none
  refused it); the same mean over only those, a fair comparison of methods with different
  domains ("-" for a method outside the comparison: one that accepts fewer than half of the
  kind's problems, e.g. pgs, which needs a positive diagonal, on Fig. 9's event LCPs, would
  otherwise shrink the common problems to the few it takes).
Unreadable files (method "-") are listed with their reason, outside every method's numbers.

Performance profile (Dolan & More, Math. Program. 91, 201, 2002): with t_ps the time of method
s on problem p (infinite when it failed), r_ps = t_ps / min_s t_ps, and
rho_s(tau) = |{p : r_ps <= tau}| / |P|, plotted against log2(tau). rho_s(1) is the fraction of
problems on which s was fastest, rho_s(inf) its success rate.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .harness import Result

SHIFT = 0.010  # seconds
RESIDUAL_SHIFT = 1e-16  # the SGM of residuals: rounding level
ACCURACIES = (1e-8, 1e-12)  # success rates at these backward / forward errors
#: A method is compared on the common problems of a kind when it accepts at least this share
#: of the kind's problems; the common problems are those all such methods accept.
COMMON_SHARE = 0.5


def at_accuracy(r: Result, accuracy: float, forward: bool = False) -> bool:
    """Whether `r` succeeded with its backward error (forward=False: the check's backward
    error, else the scaled residual) or its forward error bound (forward=True) <= accuracy; a
    certified infeasibility counts."""
    if r.outcome == "infeasible":
        return True
    backward = r.scaled_residual if math.isnan(r.backward_error) else r.backward_error
    value = r.forward_error if forward else backward
    return r.outcome == "solved" and value <= accuracy


def shifted_geometric_mean(times: Sequence[float], shift: float = SHIFT) -> float:
    """exp(mean(log(t + shift))) - shift (nan for no times)."""
    t = np.asarray(times, dtype=float)
    if t.size == 0:
        return math.nan
    return max(float(np.exp(np.mean(np.log(t + shift))) - shift), 0.0)


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
    #: {accuracy: (successes with backward error <= it, with forward bound <= it or None
    #: when the method reported no forward bound)}
    at_accuracy: dict = field(default_factory=dict)
    sgm_residual: float = math.nan

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
        ran = [r for r in mine if r.outcome != "not_applicable"]
        times = [r.time if r.success else time_limit for r in ran]
        its = [r.iterations for r in ok if r.iterations is not None]
        claimed = [r.scaled_residual for r in mine
                   if r.status == "solved" and not math.isnan(r.scaled_residual)]
        has_forward = any(not math.isnan(r.forward_error) for r in ok)
        accuracy = {a: (sum(at_accuracy(r, a) for r in mine),
                        sum(at_accuracy(r, a, True) for r in mine) if has_forward else None)
                    for a in ACCURACIES}
        residuals = [0.0 if r.outcome == "infeasible" else
                     1.0 if math.isnan(r.scaled_residual) else min(r.scaled_residual, 1.0)
                     for r in ran]
        out.append(Summary(
            set=set_name or "all", method=method, problems=len(mine), successes=len(ok),
            sgm_time=shifted_geometric_mean(times),
            median_iterations=float(np.median(its)) if its else math.nan,
            worst_residual=max(claimed) if claimed else math.nan,
            failures=Counter(r.outcome for r in mine
                             if not r.success and r.outcome != "not_applicable"),
            refused=len(mine) - len(ran),
            sgm_common=sgm_common, common={k: len(p) for k, (_, p) in common_sets.items()},
            at_accuracy=accuracy,
            sgm_residual=shifted_geometric_mean(residuals, RESIDUAL_SHIFT)))
    return out


def common_problems(rows: Sequence[Result], share: float = COMMON_SHARE
                    ) -> dict[str, tuple[set, set]]:
    """{kind: (compared methods, common problems)} over `rows` (one set's or all results):
    the methods compared on a kind accept (do not refuse) at least `share` of its problems
    (and at least one); its common problems, (set, problem) pairs, are those that none of
    these methods refused."""
    out = {}
    order = {"LCP": 0, "MLCP": 1, "FC2D": 2}
    for kind in sorted(dict.fromkeys(r.kind for r in rows), key=lambda k: order.get(k, 3)):
        mine = [r for r in rows if r.kind == kind]
        problems = {(r.set, r.problem) for r in mine}
        accepted = Counter(r.method for r in mine if r.outcome != "not_applicable")
        compared = {m for m, k in accepted.items() if k >= share * len(problems)}
        refused = {(r.set, r.problem) for r in mine
                   if r.method in compared and r.outcome == "not_applicable"}
        out[kind] = (compared, problems - refused)
    return out


def profile_data(results: Sequence[Result], set_name: str | None = None,
                 kind: str | None = None) -> tuple[list[str], np.ndarray]:
    """(methods, ratios): ratios[p, s] = t_ps / min_s t_ps (inf for a failure; all inf when
    every method failed on p), over the problems of `set_name` and `kind` (None: all), for
    the methods that accept at least one of them (a method that refused all is left out).
    Times are floored at 1 microsecond."""
    rows = [r for r in results if (set_name is None or r.set == set_name) and r.method != "-"
            and (kind is None or r.kind == kind)]
    applies = {r.method for r in rows if r.outcome != "not_applicable"}
    rows = [r for r in rows if r.method in applies]
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


def _fmt_time(t: float) -> str:
    return "-" if math.isnan(t) else f"{1e3 * t:.3g} ms" if t < 1 else f"{t:.3g} s"


def _fmt(v: float, spec: str) -> str:
    return "-" if math.isnan(v) else format(v, spec)


def summary_table(summaries: Sequence[Summary]) -> list[str]:
    """Markdown table lines of summaries: one "SGM time, common" column per kind of problem
    (the number of common problems of that kind in its header), then the successes at each
    of ACCURACIES (backward / forward; "n/a": no forward bound reported)."""
    common = summaries[0].common if summaries else {}
    heads = "".join(f" SGM time, common {k or 'problems'} ({n}) |" for k, n in common.items())
    acc = "".join(f" success at {a:.0e} (backward / forward) |" for a in ACCURACIES)
    lines = [f"| method | success | refused | SGM time |{heads}{acc} SGM residual | "
             "median iterations | worst residual | failures |",
             "|---|---:|---:|---:|" + "---:|" * (len(common) + len(ACCURACIES))
             + "---:|---:|---:|---|"]
    for s in summaries:
        fails = ", ".join(f"{k} {v}" for k, v in sorted(s.failures.items())) or "-"
        cells = "".join(f" {_fmt_time(s.sgm_common.get(k, math.nan))} |" for k in common)
        for a in ACCURACIES:
            back, fwd = s.at_accuracy.get(a, (0, None))
            cells += f" {back} / {'n/a' if fwd is None else fwd} |"
        ran = s.problems - s.refused
        lines.append(
            f"| {s.method} | {s.successes}/{s.problems} ({100 * s.rate:.0f}%) | {s.refused} | "
            f"{_fmt_time(s.sgm_time) if ran else '-'} |{cells} "
            f"{_fmt(s.sgm_residual, '.1e') if ran else '-'} | "
            f"{_fmt(s.median_iterations, '.0f')} | {_fmt(s.worst_residual, '.1e')} | "
            f"{fails} |")
    return lines


