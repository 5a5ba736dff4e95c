"""The solver-comparison harness behind ``rigidlcp bench`` (issue 6).

Every method is run on every problem of the chosen sets, one solve at a time, with a time limit
per solve, and every answer is checked here, never taken from the solver:

* a claimed solution ("solved") is certified by `verify.certify` (uniqueness "none": the
  residual certificate only, scaled residual <= tol); uncertified counts as a failure; so
  does a point the check accepts on an LCP with an exact Farkas certificate (no feasible
  point exists: Drake's Moby returns z ~ 1e14 with w negative by O(1) on the infeasible set,
  which the scaled measures accept);
* a claim that no solution exists ("infeasible") is accepted only with the
  project's own proof, the one `lcp.solve` needs for its "infeasible": a Farkas certificate
  y >= 0, M'y <= 0, q'y < 0 (so no z >= 0 has M z + q >= 0) found by HiGHS and checked in
  exact rational arithmetic on the data as stored (lcp.acceptance.farkas); a certificate that
  holds only in floating point proves nothing (a P-matrix singular to working precision has
  one, and a solution beyond it) and the claim counts as "unproved_infeasible". (An LCP can
  be feasible and still have no solution when M is not copositive-plus; such a claim cannot
  be certified this way either and counts as a failure.)
* a secondary ray ("ray", Lemke's termination, rigidlcp's or a peer's) is no claim that no
  solution exists: on a problem with an exact Farkas certificate it counts as "infeasible"
  (the LCP has none), otherwise its outcome is "ray", a failure that claims nothing (Lemke's
  method can end on a ray of an LCP that has solutions when M is not copositive-plus:
  Cottle-Pang-Stone Sec. 4.4; Siconos's bimatrix game lcp_CPS_3 does, after one pivot).
* a solve longer than the time limit, a refusal (NotApplicable), an exception, or any other
  status (max_iter, not_converged, failed) is a failure.

Problems: LCPs, MLCPs (given to the methods as they are: a singular A is the method's affair,
see lcp.mlcp_full), 2D friction-contact problems (certified by their natural-map residual,
verify.certify) and `Unreadable` files (one row, method "-", outcome "unreadable", with the
reason). A claim that no solution exists is certified for LCPs only (Farkas).

Isolation: rigidlcp's methods run in a worker process started by "forkserver" (or "spawn"),
never forked from this multi-threaded process; a method registered at run time is sent to it
by reference (a module-level function, e.g. the test doubles); a solve that does not answer within
the limit is killed with its worker, and a fresh worker takes the next solve. The time is
measured in the worker around `lcp.solve` (validation, the method, w = M z + q); each method
first solves a 2 x 2 problem, untimed, in every fresh worker (imports, caches). The worker
uses one BLAS thread (threadpoolctl): solves never run in parallel.

Siconos's solvers (runners.SICONOS_METHODS: Lemke, enumeration and PGS on LCPs; enumeration,
direct enumeration and Fischer-Burmeister on MLCPs; NSGS, Lemke and enumeration on 2D friction
contact) run in a long-lived /usr/bin/python3 subprocess (rigidlcp/bench/_siconos_helper.py,
problems passed as .npy files, only the driver call timed) when that interpreter can import
siconos.numerics; their answers are certified here like every other.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np
from scipy.optimize import linprog

from rigidlcp import lcp
from rigidlcp.lcp import LCP, MLCP, Solution
from rigidlcp.lcp.acceptance.farkas import find_certificate
from rigidlcp.lcp.acceptance.scaling import ruiz
from rigidlcp.verify.certificates.certify import certify

from .peers import PEERS, peer_available
from .problem_sets import Unreadable
from .runners import GRACE, LocalRunner
from .siconos_runner import SICONOS_METHODS, SiconosRunner

__all__ = ["Result", "problem_kind", "judge", "run_bench", "farkas_certificate", "exact_farkas",
           "write_csv", "append_csv", "read_csv", "available_methods", "check_methods",
           "LocalRunner", "PEERS", "SiconosRunner", "SICONOS_METHODS", "GRACE"]

#: Statuses the harness checks for a proof that no solution exists: the claim "infeasible" and
#: Lemke's termination "ray" (no claim: without a proof its outcome is "ray", not
#: "unproved_infeasible").
NO_SOLUTION = ("infeasible", "ray")


@dataclass
class Result:
    """One (problem, method) solve. outcome: "solved" (certified solution), "infeasible"
    (certified: an LP proved it), or the failure: "uncertified", "timeout", "not_applicable",
    "error", "unproved_infeasible" (a claim "infeasible" without a proof), or the method's own
    status (max_iter, not_converged, failed, ray: Lemke's termination without a proof of
    infeasibility, which claims nothing, ...)."""

    set: str
    problem: str
    n: int
    method: str
    outcome: str
    success: bool
    status: str  # what the method said
    time: float  # seconds of the solve (the time limit for timeouts)
    iterations: int | None
    residual: float  # max|min(z, w)| with w = M z + q recomputed here (nan: no point)
    scaled_residual: float  # verify.certify's acceptance measure (nan: no point)
    expected: str
    message: str = ""
    kind: str = ""  # the kind of problem: "LCP", "MLCP", "FC2D" ("-" unreadable, "" unknown)
    #: a bound on the forward error of a claimed solution, where the method or the check
    #: reports one (Solution.info["forward_error"] or the certificate's); nan: none reported
    forward_error: float = math.nan
    #: the check's backward error where it reports one (verify.certify's backward_error, a
    #: measure that z's size cannot inflate); nan: none (the scaled residual stands for it)
    backward_error: float = math.nan


def problem_kind(problem) -> str:
    """"LCP", "MLCP" or "FC2D" (the report's common SGM is per kind); "-" for an unreadable
    file."""
    if isinstance(problem, Unreadable):
        return "-"
    if isinstance(problem, MLCP):
        return "MLCP"
    if isinstance(problem, lcp.FrictionContact2D):
        return "FC2D"
    return "LCP"


CSV_FIELDS = [f.name for f in fields(Result)]


# --------------------------------------------------------------------------------------------
# certification of claims that no solution exists
# --------------------------------------------------------------------------------------------

def farkas_certificate(M: np.ndarray, q: np.ndarray) -> np.ndarray | None:
    """y >= 0 with M'y <= 0 and q'y <= -1 (scaled), found by an LP, or None (checked in floating
    point only: evidence, not the judge's proof, which is `exact_farkas`).

    Such a y proves that {z >= 0 : M z + q >= 0} is empty: y'(M z + q) = (M'y)'z + q'y < 0.
    The LP is solved on M, q scaled to max|entry| = 1; the certificate is re-checked with a
    margin of 1e-9 relative to |y| and the data.
    """
    n = q.size
    s = max(float(np.abs(M).max(initial=0.0)), float(np.abs(q).max(initial=0.0)), 1e-300)
    Ms, qs = M / s, q / s
    A = np.vstack([Ms.T, qs[None, :]])
    b = np.concatenate([np.zeros(n), [-1.0]])
    res = linprog(np.zeros(n), A_ub=A, b_ub=b, bounds=[(0, None)] * n, method="highs")
    if res.status != 0:
        return None
    y = np.maximum(res.x, 0.0)
    ynorm = float(np.abs(y).sum())
    if qs @ y >= -0.5 or np.any(Ms.T @ y > 1e-9 * max(ynorm, 1.0)):
        return None
    return y


def exact_farkas(problem: LCP) -> np.ndarray | None:
    """y >= 0 (the problem's units) with M'y <= 0 and q'y < 0 holding in exact rational
    arithmetic on the stored data (lcp.acceptance.farkas.find_certificate on the equilibrated
    problem, as `lcp.solve` checks its own "infeasible"), or None: no certificate, or only one
    that holds in floating point. The bench's proof of a claim that no solution exists."""
    M = problem.M.toarray() if hasattr(problem.M, "toarray") else np.asarray(problem.M)
    eq = ruiz(np.asarray(M, dtype=float), np.asarray(problem.q, dtype=float))
    with np.errstate(all="ignore"):
        cert = find_certificate(eq)
    return cert.y if cert is not None and cert.exact else None


_FARKAS_SEEN: dict[int, tuple] = {}  # id(problem) -> (problem, its exact certificate or None)


def _no_feasible_point(problem: LCP) -> bool:
    """Whether `problem` has an exact Farkas certificate (so no z >= 0 has M z + q >= 0 and no
    claimed solution can be one); one LP per problem object in a run (cached)."""
    seen = _FARKAS_SEEN.get(id(problem))
    if seen is None or seen[0] is not problem:
        if len(_FARKAS_SEEN) > 4096:
            _FARKAS_SEEN.clear()
        seen = _FARKAS_SEEN[id(problem)] = (problem, exact_farkas(problem))
    return seen[1] is not None


# --------------------------------------------------------------------------------------------
# the run
# --------------------------------------------------------------------------------------------

def judge(problem, method: str, set_name: str, raw: dict, time_limit: float,
          tol: float) -> Result:
    """Turn a runner's raw answer into a Result, certifying it (see the module doc)."""
    if isinstance(problem, Unreadable):
        return Result(set=set_name, problem=problem.name, n=0, method="-",
                      outcome="unreadable", success=False, status="unreadable", time=0.0,
                      iterations=None, residual=math.nan, scaled_residual=math.nan,
                      expected="-", message=problem.reason, kind="-")
    expected = str(problem.meta.get("expected", "unknown"))
    base = dict(set=set_name, problem=problem.name, n=problem.n, method=method,
                expected=expected, message=raw.get("message", ""), kind=problem_kind(problem))
    kind = raw["kind"]
    if kind != "answer":
        t = time_limit if kind == "timeout" else float(raw.get("time", 0.0))
        return Result(**base, outcome=kind, success=False, status=kind, time=t,
                      iterations=None, residual=math.nan, scaled_residual=math.nan)
    status, t, z = raw["status"], float(raw["time"]), raw["z"]
    res = scaled = forward = backward = math.nan
    if z.shape == (problem.n,) and np.all(np.isfinite(z)):
        answer = Solution(z=z, w=np.zeros(0), status=status, method=method, u=raw.get("u"),
                          basis=raw.get("basis"))
        with np.errstate(all="ignore"):
            cert = certify(problem, answer, tol=tol, uniqueness="none")
        res, scaled = cert.residual, cert.scaled_residual
        accepted = cert.accepted
        forward = _forward_error(raw, cert)
        backward = float(getattr(cert, "backward_error", math.nan))
    else:
        accepted = False
    if t > time_limit:
        outcome = "timeout"
    elif status == "solved":
        outcome = "solved" if accepted else "uncertified"
        if accepted and isinstance(problem, LCP) and _no_feasible_point(problem):
            # the check accepted a point of an LCP that provably has none (a z inflated to
            # ~1e14 with w negative by O(1) passes its scaled measures): not a solution
            outcome = "uncertified"
            base["message"] = (base["message"] + "; " if base["message"] else "") + (
                "the LCP has no feasible point (an exact Farkas certificate): not a solution")
    elif status in NO_SOLUTION:
        proved = isinstance(problem, LCP) and exact_farkas(problem) is not None
        outcome = "infeasible" if proved else (
            "ray" if status == "ray" else "unproved_infeasible")
    else:
        outcome = status
    return Result(**base, outcome=outcome, success=outcome in ("solved", "infeasible"),
                  status=status, time=min(t, time_limit) if outcome != "timeout" else time_limit,
                  iterations=raw.get("iterations"), residual=res, scaled_residual=scaled,
                  forward_error=forward if outcome == "solved" else math.nan,
                  backward_error=backward)


def _forward_error(raw: dict, cert) -> float:
    """The forward error bound of an answer: the method's (raw "forward_error", from
    Solution.forward_error or Solution.info) or the certificate's (its forward_error),
    whichever is larger; nan when neither reports one."""
    values = [raw.get("forward_error"), getattr(cert, "forward_error", None)]
    values = [float(v) for v in values if v is not None and not math.isnan(float(v))]
    return max(values) if values else math.nan


def check_methods(methods: Iterable[str], siconos: SiconosRunner | None) -> None:
    """ValueError naming the first method that cannot run: unknown, a Siconos method without
    Siconos, a peer whose package is not installed."""
    known = {m.name for m in lcp.methods()}
    for m in methods:
        if m not in known and m not in SICONOS_METHODS and m not in PEERS:
            every = sorted(known) + list(SICONOS_METHODS) + list(PEERS)
            raise ValueError(f"unknown method {m!r}{lcp.registry.did_you_mean(m, every)}; "
                             f"available: {', '.join(every)} (a method of your own: register "
                             "it in a script that calls run_bench, docs/bench.md 'A test "
                             "double')")
        if m in SICONOS_METHODS and (siconos is None or not siconos.available):
            raise ValueError(f"{m} needs Siconos: "
                             f"{siconos.reason if siconos else 'no Siconos runner given'}")
        if m in SICONOS_METHODS and not siconos.offers(m):
            raise ValueError(f"{m} needs Siconos's {SICONOS_METHODS[m].kind} solvers, which "
                             f"Siconos {siconos.version} at {siconos.python} does not have")
        if m in PEERS:
            ok, why = peer_available(m)
            if not ok:
                raise ValueError(f"{m} is not available: {why}")


def available_methods(siconos: SiconosRunner | None) -> list[str]:
    """rigidlcp's registered methods, and Siconos's when its runner is available."""
    names = [m.name for m in lcp.methods()]
    if siconos is not None and siconos.available:
        names += [m for m in SICONOS_METHODS if siconos.offers(m)]
    return names


def run_bench(
    sets: dict[str, list[LCP | MLCP]], methods: Iterable[str], *, time_limit: float = 10.0,
    tol: float = 1e-8, isolate: bool = True, siconos: SiconosRunner | None = None,
    progress: Callable[[Result], None] | None = None, grace: float = GRACE,
    batch: bool = True, skip: Iterable[tuple[str, str, str]] = (),
    warmups: dict | None = None,
) -> list[Result]:
    """Run every method on every problem of `sets` ({set name: problems}); one Result each.

    methods: rigidlcp method names (lcp.methods()), "siconos-*" names (need `siconos`,
    an available SiconosRunner) and peers (bench.peers.PEERS, need their package). A name
    that cannot run raises ValueError before anything runs (check_methods).
    skip: (set, problem, method) triples already done (a resumed run): not run again.
    warmups: a dict filled with {method: [seconds of each untimed warm-up solve]}.
    time_limit: seconds per solve; grace: extra seconds allowed for passing data to and from
    the worker before it is killed (a solve measured above time_limit fails either way).
    batch: the LCPs of a set that share a size are given to a method with a compiled batch
    path (lcp.batch.COMPILED_BATCH: lemke) in one `lcp.solve_many` call, each timed as the
    batch's mean (message "batch of k"); a batch that fails or overruns k time limits is
    solved one problem at a time instead.
    """
    methods = list(methods)
    check_methods(methods, siconos)
    done = set(skip or ())
    local = LocalRunner(isolate, grace)
    results: list[Result] = []
    try:
        for set_name, problems in sets.items():
            todo = [p for p in problems if isinstance(p, Unreadable) or any(
                (set_name, p.name, m) not in done for m in methods)]
            batched = _batched_answers(local, todo, methods, time_limit) if batch else {}
            for problem in todo:
                if isinstance(problem, Unreadable):
                    if (set_name, problem.name, "-") in done:
                        continue
                    results.append(judge(problem, "-", set_name, {}, time_limit, tol))
                    if progress is not None:
                        progress(results[-1])
                    continue
                for method in methods:
                    if (set_name, problem.name, method) in done:
                        continue
                    runner = siconos if method in SICONOS_METHODS else local
                    raw = batched.get((id(problem), method)) or runner.solve(
                        problem, method, time_limit)
                    r = judge(problem, method, set_name, raw, time_limit, tol)
                    results.append(r)
                    if progress is not None:
                        progress(r)
    finally:
        local.close(wait=5.0)
        if warmups is not None:
            for runner in (local, siconos):
                for m, ts in getattr(runner, "warmups", {}).items():
                    warmups.setdefault(m, []).extend(ts)
    return results


def _batched_answers(local: LocalRunner, problems: list, methods: list[str],
                     time_limit: float) -> dict:
    """{(id(problem), method): raw answer} for the plain LCPs of a set solved by solve_many:
    methods of lcp.batch.COMPILED_BATCH, groups of at least two LCPs of one size."""
    from rigidlcp.lcp.batch import COMPILED_BATCH

    groups: dict[int, list] = {}
    for p in problems:
        if type(p) is LCP:
            groups.setdefault(p.n, []).append(p)
    out: dict = {}
    for method in (m for m in methods if m in COMPILED_BATCH):
        for group in (g for g in groups.values() if len(g) >= 2):
            raws = local.solve_batch(group, method, time_limit)
            for p, raw in zip(group, raws or []):
                msg = raw["message"]
                raw["message"] = f"batch of {raw['batch']}" + (f"; {msg}" if msg else "")
                out[(id(p), method)] = raw
    return out


def _row(r: Result) -> dict:
    row = asdict(r)
    row["time"] = f"{r.time:.6g}"
    for key in ("residual", "scaled_residual", "forward_error", "backward_error"):
        row[key] = "" if math.isnan(row[key]) else f"{row[key]:.3e}"
    row["iterations"] = "" if r.iterations is None else r.iterations
    return row


def write_csv(results: list[Result], path: str | os.PathLike) -> Path:
    """results.csv: one row per (problem, method), the columns of `Result`."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=CSV_FIELDS)
        writer.writeheader()
        for r in results:
            writer.writerow(_row(r))
    return path


def append_csv(result: Result, path: str | os.PathLike) -> None:
    """Add one row to results.csv as soon as it is judged (a header first for a new file),
    so that an interrupted run can be resumed (`rigidlcp bench --resume`)."""
    path = Path(path)
    new = not path.exists() or path.stat().st_size == 0
    with open(path, "a", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=CSV_FIELDS)
        if new:
            writer.writeheader()
        writer.writerow(_row(result))
        fh.flush()


def read_csv(path: str | os.PathLike) -> list[Result]:
    """Results back from results.csv (e.g. to redo a report)."""
    out = []
    with open(path, newline="") as fh:
        for row in csv.DictReader(fh):
            out.append(Result(
                set=row["set"], problem=row["problem"], n=int(row["n"]), method=row["method"],
                outcome=row["outcome"], success=row["success"] == "True", status=row["status"],
                time=float(row["time"]),
                iterations=int(row["iterations"]) if row["iterations"] else None,
                residual=float(row["residual"]) if row["residual"] else math.nan,
                scaled_residual=(float(row["scaled_residual"]) if row["scaled_residual"]
                                 else math.nan),
                expected=row["expected"], message=row["message"], kind=row.get("kind", ""),
                forward_error=(float(row["forward_error"]) if row.get("forward_error")
                               else math.nan),
                backward_error=(float(row["backward_error"]) if row.get("backward_error")
                                else math.nan)))
    return out
