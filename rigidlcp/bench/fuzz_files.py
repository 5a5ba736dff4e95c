"""The fuzz harness on files: every method on LCP and MLCP files (Siconos's text formats or the
toolkit's .npz), each answer judged without trusting the solver (docs/fuzz.md).

LCP files are judged as generated cases are (rigidlcp/bench/fuzz.py). An MLCP answer (u, v) is
judged here on the problem as given: the equality residual |A u + C v + a|_inf scaled by
|a|_inf + ||A||_inf |u|_inf + ||C||_inf |v|_inf, and the complementarity residual of (v, w),
w = D u + B v + b, scaled as fuzz.judge_residual scales an LCP's; both must be <= fuzz.TOL.
An "infeasible" MLCP is confirmed by an LP (HiGHS): no u, v >= 0 with A u + C v + a = 0 and
D u + B v + b >= 0. A file that cannot be read as an LCP or MLCP is a "refused" row with the
reason, for every method.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np

from rigidlcp import lcp

from .fuzz_cases import Case
from .fuzz_judge import ENUM_MAX_N, OUTCOMES, TOL, attempt, judge, save_case


def judge_mlcp(P: lcp.MLCP, status: str, u: np.ndarray | None, v: np.ndarray) -> tuple[str, str]:
    """(outcome, reason) of one answer to an MLCP (see the module doc)."""
    if status == "infeasible":
        feasible = mlcp_feasible(P)
        if feasible is False:
            return "solved", ""
        return "WRONG", f"infeasible not confirmed (LP feasible: {feasible})"
    if status != "solved":
        return "honest", status
    u = np.zeros(P.nu) if u is None else np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    if u.shape != (P.nu,) or v.shape != (P.n,) or not (np.all(np.isfinite(u))
                                                        and np.all(np.isfinite(v))):
        return "WRONG", "solved, but (u, v) has the wrong shape or non-finite entries"
    um, vm = float(np.abs(u).max(initial=0.0)), float(np.abs(v).max(initial=0.0))
    eq_scale = (float(np.abs(P.a).max(initial=0.0)) + _norm(P.A) * um + _norm(P.C) * vm)
    eq = float(np.abs(P.A @ u + P.C @ v + P.a).max(initial=0.0)) / (eq_scale or 1.0)
    w = P.D @ u + P.B @ v + P.b
    bmax = float(np.abs(P.B).max(initial=0.0))
    vs = max(vm, float(np.abs(P.b).max(initial=0.0)) / bmax if bmax else 0.0) or 1.0
    ws = (float(np.abs(P.b).max(initial=0.0)) + _norm(P.D) * um + _norm(P.B) * vs) or 1.0
    comp = float(np.max(np.abs(np.minimum(v / vs, w / ws)), initial=0.0))
    if eq <= TOL and comp <= TOL:
        return "solved", ""
    return "WRONG", f"solved with scaled residuals {comp:.3g} (complementarity), {eq:.3g} (eq)"


def mlcp_feasible(P: lcp.MLCP) -> bool | None:
    """Has {u free, v >= 0 : A u + C v + a = 0, D u + B v + b >= 0} a point? (HiGHS)"""
    from scipy.optimize import linprog

    nu, n = P.nu, P.n
    res = linprog(np.zeros(nu + n), A_eq=np.hstack([P.A, P.C]), b_eq=-P.a,
                  A_ub=-np.hstack([P.D, P.B]), b_ub=P.b,
                  bounds=[(None, None)] * nu + [(0, None)] * n, method="highs")
    return {0: True, 2: False}.get(res.status)


def _norm(X: np.ndarray) -> float:
    return float(np.abs(X).sum(axis=1).max(initial=0.0)) if X.size else 0.0


def run_files(paths, methods: tuple[str, ...] | None = None, out: str | Path | None = None
              ) -> dict:
    """Every method on each file (class = the file name); the result as fuzz.run_fuzz's."""
    names = methods or tuple(m.name for m in lcp.methods())
    exhaustive = {m.name for m in lcp.methods() if m.accepts == "small-n"}
    table: dict = defaultdict(lambda: {**{o: 0 for o in OUTCOMES}, "seconds": []})
    saved: list[Path] = []
    for path in map(Path, paths):
        try:
            P = lcp.load(path)
        except (lcp.InvalidProblem, lcp.NotApplicable) as exc:  # the reader says why, where
            P, refusal = None, str(exc)
        if P is not None and not isinstance(P, (lcp.LCP, lcp.MLCP)):
            P, refusal = None, (f"{path}: a {type(P).__name__}, not an LCP or MLCP (fuzz "
                                "--files judges those; `rigidlcp bench --set FOLDER` takes "
                                "friction contact too)")
        for method in names:
            cell = table[(path.stem, method)]
            if P is None or not isinstance(P, (lcp.LCP, lcp.MLCP)):
                cell["refused"] += 1
                continue
            if method in exhaustive and P.n > ENUM_MAX_N:
                continue
            res = _run(P, method)
            cell[res["outcome"]] += 1
            cell["seconds"].append(res["seconds"])
            if res["outcome"] in ("WRONG", "crash") and out is not None:
                saved.append(_save(P, path, method, res, Path(out)))
        if P is None:
            table[(path.stem, "reader")] = {**{o: 0 for o in OUTCOMES}, "refused": 1,
                                            "seconds": [], "reason": refusal}
    return {"table": dict(table), "saved": saved}


def _run(P, method: str) -> dict:
    sol, res = attempt(P, method)
    if sol is None:
        return res
    if isinstance(P, lcp.MLCP):
        res["outcome"], res["reason"] = judge_mlcp(P, sol.status, sol.u, sol.z)
    else:
        res["outcome"], res["reason"] = judge(Case("file", 0, P.M, P.q), sol.status, sol.z)
    return res


def _save(P, path: Path, method: str, res: dict, out: Path) -> Path:
    if isinstance(P, lcp.LCP):
        return save_case(Case(path.stem, 0, P.M, P.q), method, res, out)
    out.mkdir(parents=True, exist_ok=True)
    return P.save(out / f"{path.stem}-{method}.npz")
