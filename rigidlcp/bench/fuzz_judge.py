"""How the fuzz harness judges one answer without trusting the solver (rigidlcp.bench.fuzz's
module doc says what each outcome means): the scaled residual recomputed here, an LP for
"infeasible", the method's own answer timed (`attempt`), a wrong case saved (`save_case`).
Shared by the generated cases (fuzz.py) and the files (fuzz_files.py).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from rigidlcp import lcp

from .fuzz_cases import Case
from .own import OWN_ANSWER

#: The exhaustive methods (accepts "small-n": enumerate, enumerate-mlcp; 2^n bases) are run
#: for n up to this in the fuzz.
ENUM_MAX_N = 10
#: Acceptance tolerance of verify.certify.
TOL = 1e-8
#: Options per method, to bound the time of slow iterations (pgs sweeps in pure Python).
OPTIONS = {"pgs": {"max_iter": 2000}}
OUTCOMES = ("solved", "honest", "refused", "crash", "WRONG")


def judge_residual(M: np.ndarray, q: np.ndarray, z: np.ndarray) -> float:
    """max|min(z/z_s, w/w_s)| with z_s = max(|z|, |q|/|M|max), w_s = |q| + ||M||_inf z_s."""
    z = np.asarray(z, dtype=float)
    if z.shape != q.shape or not np.all(np.isfinite(z)):
        return np.inf
    mmax = float(np.abs(M).max())
    zs = max(float(np.abs(z).max()), float(np.abs(q).max()) / mmax if mmax else 0.0) or 1.0
    ws = (float(np.abs(q).max()) + float(np.abs(M).sum(axis=1).max()) * zs) or 1.0
    return float(np.max(np.abs(np.minimum(z / zs, (M @ z + q) / ws))))


def lp_feasible(M: np.ndarray, q: np.ndarray) -> bool | None:
    """Has {z >= 0 : M z + q >= 0} a point? (HiGHS; rows normalized by their largest entry.)"""
    from scipy.optimize import linprog  # on first use: `rigidlcp --help` loads no scipy

    s = np.maximum(np.abs(M).max(axis=1), np.abs(q))
    s[s == 0] = 1.0
    res = linprog(np.zeros(q.size), A_ub=-M / s[:, None], b_ub=q / s,
                  bounds=[(0, None)] * q.size, method="highs")
    return {0: True, 2: False}.get(res.status)


def judge(case: Case, status: str, z: np.ndarray) -> tuple[str, str]:
    """(outcome, reason) of one answer; see the module docstring."""
    if status == "solved":
        if case.solvable is False:
            return "WRONG", "solved, but the problem is infeasible by construction"
        r = judge_residual(case.M, case.q, z)
        return ("solved", "") if r <= TOL else ("WRONG", f"solved with scaled residual {r:.3g}")
    if status != "infeasible":
        return "honest", status
    if case.solvable:
        return "WRONG", "infeasible, but the problem is solvable by construction"
    if case.solvable is False:
        return "solved", ""
    feasible = lp_feasible(case.M, case.q)
    if feasible is False:
        return "solved", ""
    if case.n <= ENUM_MAX_N:
        if not lcp.enumerate_solutions(lcp.LCP(case.M, case.q)):
            return "solved", ""
        return "WRONG", "infeasible, but the enumeration finds a solution"
    return "WRONG", f"infeasible not confirmed (LP feasible: {feasible})"


def attempt(problem, method: str) -> tuple[lcp.Solution | None, dict]:
    """Solve, timed, the method's own answer (no other method's answer substituted:
    bench.own.OWN_ANSWER); (None, result) when the method refused or crashed, else (solution,
    {"seconds": ...}) for the judge."""
    t0 = time.perf_counter()
    try:
        sol = lcp.solve(problem, method, **OWN_ANSWER, **OPTIONS.get(method, {}))
    except lcp.NotApplicable as exc:
        return None, {"outcome": "refused", "reason": str(exc),
                      "seconds": time.perf_counter() - t0}
    except Exception as exc:  # noqa: BLE001 - a crash is what the harness is looking for
        return None, {"outcome": "crash", "reason": f"{type(exc).__name__}: {exc}",
                      "seconds": time.perf_counter() - t0}
    seconds = time.perf_counter() - t0
    if "exception" in sol.info:
        return None, {"outcome": "crash", "reason": sol.info["exception"].strip(),
                      "seconds": seconds}
    return sol, {"seconds": seconds, "status": sol.status}


def save_case(case: Case, method: str, result: dict, out: Path) -> Path:
    meta = {"class": case.kind, "seed": case.seed, "method": method,
            "outcome": result["outcome"], "reason": result["reason"],
            "p_matrix": case.p_matrix, "solvable": case.solvable}
    return lcp.LCP(case.M, case.q, name=f"{case.kind}-{case.seed}-{method}",
                   meta=meta).save(out / f"{case.kind}-{case.seed}-{method}.npz")
