"""Uniqueness of LCP solutions: P-matrix test, enumeration verdicts, and a MILP search.

The LCP is w = M z + q, 0 <= z perp w >= 0. Its solution set is the union, over complementary
bases alpha, of the polyhedra P_alpha = {z : z_b = 0, z_a >= 0, w_a = 0, w_b >= 0} (beta the
complement of alpha); every P_alpha lies in the orthant z >= 0, so it is pointed.

Three tools, from cheapest to most general:

* ``p_matrix_test``: M is a P-matrix (every principal minor positive) iff the LCP has exactly one
  solution for every q (Samelson, Thrall & Wesler 1958; Cottle, Pang & Stone 1992, Thm 3.3.7).
  Checked by all 2^n - 1 principal minors for small n, and for any n by the sufficient condition
  that the symmetric part (M + M^T)/2 be positive definite (necessary too when M is symmetric).
* ``lcp.enumerate_solutions`` (used by verify.certify): every complementary basis, small n.
* ``milp_search``: a mixed-integer program (scipy.optimize.milp, i.e. HiGHS) for a solution other
  than a given z*, with binary variables y for the complementarity and big-M bounds.

Scales (lcp.residual, shared with lcp.solve and verify.certify): z_s = max(|z*|_inf, |q|_inf /
|M|_max) is the size of a solution and w_s = |q|_inf + ||M||_inf z_s bounds the size of the
terms of w = M z + q.
Every margin below is relative to these scales.
"""

from __future__ import annotations

import contextlib
import itertools
import time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import Bounds, LinearConstraint, linprog, milp

from rigidlcp.lcp.quiet import quiet_stdout
from rigidlcp.lcp.residual import scaled_residual, scales

__all__ = ["PMatrixTest", "Search", "milp_search", "p_matrix_test", "quiet_highs",
           "scaled_residual", "scales", "sign_pattern"]

#: Largest n for the principal-minor test (2^n - 1 determinants).
P_MINORS_MAX_N = 12
#: A principal submatrix with sigma_min <= RCOND * sigma_max is treated as numerically singular.
RCOND = 1e-10
#: Default box for the MILP: 0 <= z <= BOUND_FACTOR * z_s.
BOUND_FACTOR = 1e3
#: HiGHS tolerances for the MILP and the polishing LP (its defaults are 1e-6 / 1e-7). Options
#: other than scipy's own five are passed to HiGHS verbatim (scipy warns; the warning is muted).
_HIGHS_MILP = {"mip_feasibility_tolerance": 1e-9, "primal_feasibility_tolerance": 1e-9}
_HIGHS_LP = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


@contextlib.contextmanager
def quiet_highs() -> Iterator[None]:
    """Silence HiGHS's C++ debug prints (e.g. "HighsMipSolverData::transformNewInteger...") that
    go to file descriptor 1 whatever log_to_console says (lcp.quiet.quiet_stdout), and scipy's
    warning about passing HiGHS options verbatim."""
    with warnings.catch_warnings(), quiet_stdout():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


# --------------------------------------------------------------------------------------------
# scales and residuals
# --------------------------------------------------------------------------------------------

def sign_pattern(z: np.ndarray, w: np.ndarray, zs: float, ws: float, delta: float) -> np.ndarray:
    """+1 where z_i > delta z_s, -1 where w_i > delta w_s, 0 where both are ~0 (degenerate).

    (If both exceed the margin the pair is not complementary; the larger relative one wins.)
    """
    zr, wr = z / zs, w / ws
    out = np.zeros(z.size, dtype=int)
    out[(zr > delta) & (zr >= wr)] = 1
    out[(wr > delta) & (wr > zr)] = -1
    return out


# --------------------------------------------------------------------------------------------
# P-matrix test
# --------------------------------------------------------------------------------------------

@dataclass
class PMatrixTest:
    """is_p: True (proved, to the stated conditioning margin), False (a principal minor is
    <= 0), None (undecided: near-singular minors, or n too large for the minors)."""

    is_p: bool | None
    how: str
    witness: tuple[int, ...] | None = None
    minors_checked: int = 0
    message: str = ""


def p_matrix_test(M: np.ndarray, max_n: int = P_MINORS_MAX_N, rcond: float = RCOND) -> PMatrixTest:
    """Is M a P-matrix? (every principal minor det M_aa > 0).

    1 x 1 minors (the diagonal) are data and are compared with 0 exactly. A larger minor counts
    as positive when its LU determinant is positive and its submatrix is well conditioned
    (sigma_min > rcond sigma_max), so that the sign is not an artefact of rounding; a negative
    determinant of a well-conditioned submatrix proves M is not P; a near-singular submatrix
    leaves the question undecided. For n > max_n only the sufficient test runs: the symmetric
    part (M + M^T)/2 positive definite (smallest eigenvalue > rcond times the largest |.|)
    implies P; for symmetric M a negative eigenvalue disproves it.
    """
    M = np.asarray(M, dtype=float)
    n = M.shape[0]
    diag = np.diagonal(M)
    if np.any(diag <= 0):
        i = int(np.flatnonzero(diag <= 0)[0])
        return PMatrixTest(False, "principal minors", (i,), i + 1,
                           f"diagonal entry M[{i},{i}] = {diag[i]:.3g} <= 0: not a P-matrix")
    Hs = 0.5 * (M + M.T)
    eig = np.linalg.eigvalsh(Hs)
    big = max(float(np.max(np.abs(eig))), 1e-300)
    symmetric = bool(np.max(np.abs(M - M.T)) <= 1e-14 * max(float(np.max(np.abs(M))), 1e-300))
    if eig[0] > rcond * big:
        return PMatrixTest(True, "symmetric part positive definite", None, 0,
                           f"lambda_min((M + M^T)/2) = {eig[0]:.3g} > 0 implies P")
    if symmetric and eig[0] < -rcond * big:
        return PMatrixTest(False, "symmetric: eigenvalues", None, 0,
                           f"M symmetric with eigenvalue {eig[0]:.3g} < 0: not P")
    if n > max_n:
        return PMatrixTest(None, "none", None, 0,
                           f"n = {n} > {max_n}: principal minors not enumerated, and the "
                           "sufficient test (symmetric part positive definite) fails")
    checked = n
    undecided: tuple[int, ...] | None = None
    for k in range(2, n + 1):
        idx = np.array(list(itertools.combinations(range(n), k)), dtype=np.intp)
        subs = M[idx[:, :, None], idx[:, None, :]]
        sign, _ = np.linalg.slogdet(subs)
        sv = np.linalg.svd(subs, compute_uv=False)
        well = sv[:, -1] > rcond * sv[:, 0]
        checked += idx.shape[0]
        bad = np.flatnonzero(well & (sign <= 0))
        if bad.size:
            a = tuple(int(j) for j in idx[bad[0]])
            return PMatrixTest(False, "principal minors", a, checked,
                               f"principal minor on {list(a)} is negative: not a P-matrix")
        if undecided is None and not np.all(well):
            undecided = tuple(int(j) for j in idx[np.flatnonzero(~well)[0]])
    if undecided is not None:
        return PMatrixTest(None, "principal minors", undecided, checked,
                           f"principal submatrix on {list(undecided)} is singular to rounding "
                           f"(sigma_min <= {rcond:g} sigma_max): P-property undecided")
    return PMatrixTest(True, "principal minors", None, checked,
                       f"all {checked} principal minors positive (well conditioned)")


# --------------------------------------------------------------------------------------------
# MILP search for another solution
# --------------------------------------------------------------------------------------------

@dataclass
class Search:
    """Result of `milp_search`.

    status: "found" (another solution, verified), "none" (no other solution in the box, to the
    margins), "unknown" (time limit, or a MILP point that did not survive verification).
    """

    status: str
    target: str
    other: np.ndarray | None = None
    deviation: float = 0.0  # the found solution's max relative difference in the target
    bound: float = np.inf
    delta: float = 0.0
    seconds: float = 0.0
    message: str = ""
    info: dict = field(default_factory=dict)


def milp_search(
    M: np.ndarray, q: np.ndarray, z_star: np.ndarray, target: str = "pattern",
    L: np.ndarray | None = None, *, delta: float = 1e-4, bound: float | None = None,
    time_limit: float = 10.0, objective: str = "none", retries: int = 5,
) -> Search:
    """Search for an LCP solution other than z_star, as a MILP (HiGHS through scipy.optimize.milp).

    Formulation, in the scaled unknowns zeta = z / U (U the box bound, so 0 <= zeta <= 1), with
    w = U M zeta + q, binaries y (y_i = 1: z_i may be positive and w_i = 0; y_i = 0: z_i = 0):

        w >= 0,   zeta_i <= y_i,   w_i <= w_max,i (1 - y_i),

    w_max,i = max(0, q_i + U sum_j max(M_ij, 0)) being the largest w_i over the box: these
    big-M constants are exact consequences of 0 <= z <= U, so within the box no solution is cut
    off. The verdict is therefore *relative to the box*: another solution with some z_i > U is
    not seen (the solution set of an LCP can be unbounded, and no a-priori bound holds for
    floating-point data). Default U = 1e3 z_s.

    target "pattern": another solution with a different sign pattern (+: z_i > 0, -: w_i > 0,
      0: both 0). Where z*_i > delta z_s, y_i = 0 (so z_i = 0); or where w*_i > delta w_s,
      y_i = 1 (so w_i = 0); or, at a degenerate i of z*, z_i / z_s + w_i / w_s >= delta
      (binary d_i). At least one of these must hold. Since the P_alpha are pointed, the sign
      pattern is unique iff z is: this answers "is z unique" (up to delta at degenerate pairs).
    target "values": another solution with |(L (z - z*))_j| >= delta s_L for some row j
      (binaries e_j+, e_j-; s_L = max(||L||_inf z_s, |L z*|_inf)). L = M asks for another w,
      L = I another z, L = an acceleration map another set of accelerations.

    Margin: delta is relative (to z_s, w_s, s_L) and is raised, if smaller, to 100 times the
    MILP's leakage 1e-9 U / z_s (HiGHS treats y within 1e-9 of 0 as 0, which lets z_i reach
    1e-9 U); with the default box this floor is 1e-4, the default delta. The margin used is
    reported in `Search.delta`.

    A MILP point is never trusted: its basis (y) is fixed and the solution on it recomputed by
    an LP with the target's inequality (tolerance 1e-10), then checked (scaled residual <= 1e-8
    and the difference present). objective "min-sum" asks for the other solution of least sum z
    (HiGHS must then prove optimality; a feasible point at the time limit is still used);
    "none" (default) stops at the first feasible point. A basis that fails verification is cut
    off (a no-good cut on y) and the MILP asked again, at most `retries` times; the total time
    is bounded by `time_limit` seconds. Every way of differing is tried on that basis (the
    MILP's binaries may pick one that rounding made look satisfied); the cut is *proved* only
    if all their LPs are infeasible, and an infeasible MILP after an unproved cut answers
    "unknown", never "none" (a false "unique" is the worst answer a verifier can give).
    "none" rests on HiGHS's "infeasible", given twice, at two tolerances (`confirmed_milp`):
    the MILP solver's verdict, not a certificate this module checks.
    """
    t0 = time.perf_counter()
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    z_star = np.asarray(z_star, dtype=float)
    n = q.size
    zs, ws = scales(M, q, z_star)
    U = float(bound) if bound is not None else BOUND_FACTOR * zs
    # HiGHS accepts y within 1e-9 of an integer, so z_i <= 1e-9 U "vanishes": a margin below
    # ~100 times this leakage would let rounding pass for a difference. Raise delta to it.
    floor = 100.0 * _HIGHS_MILP["mip_feasibility_tolerance"] * U / zs
    delta = max(float(delta), floor)
    w_star = M @ z_star + q
    if target not in ("pattern", "values"):
        raise ValueError(f"target must be 'pattern' or 'values', got {target!r}")
    if target == "values" and L is None:
        raise ValueError("target 'values' needs the matrix L")
    res = Search("unknown", target, bound=U, delta=delta)

    # Columns: zeta (n) | y (n) | extra binaries.
    rows: list[np.ndarray] = []
    lo: list[float] = []
    hi: list[float] = []

    def add(row: np.ndarray, lb: float, ub: float) -> None:
        s = float(np.max(np.abs(row))) or 1.0  # normalize each row to max |coefficient| 1
        rows.append(row / s)
        lo.append(lb / s)
        hi.append(ub / s)

    UM = U * M
    wmax = np.maximum(q + U * np.sum(np.maximum(M, 0.0), axis=1), 0.0)
    extra: list[tuple] = []  # description of each extra binary
    if target == "pattern":
        pat = sign_pattern(z_star, w_star, zs, ws, delta)
        deg = np.flatnonzero(pat == 0)
        n_extra = deg.size
    else:
        L = np.atleast_2d(np.asarray(L, dtype=float))
        v_star = L @ z_star
        sL = max(float(np.max(np.sum(np.abs(L), axis=1))) * zs, float(np.max(np.abs(v_star))),
                 1e-300)
        dL = delta * sL
        for j in range(L.shape[0]):
            for sgn in (1.0, -1.0):
                gain = sgn * L[j]
                best = U * float(np.sum(np.maximum(gain, 0.0))) - sgn * v_star[j]
                if best >= dL:  # the deviation is reachable inside the box
                    extra.append((j, sgn))
        n_extra = len(extra)
    N = 2 * n + n_extra
    for i in range(n):
        r = np.zeros(N)
        r[:n] = UM[i]
        add(r, -q[i], np.inf)  # w_i >= 0
        r = np.zeros(N)
        r[i], r[n + i] = 1.0, -1.0
        add(r, -np.inf, 0.0)  # zeta_i <= y_i
        r = np.zeros(N)
        r[:n] = UM[i]
        r[n + i] = wmax[i]
        add(r, -np.inf, wmax[i] - q[i])  # w_i <= wmax_i (1 - y_i)
    cut = np.zeros(N)
    if target == "pattern":
        plus, minus = np.flatnonzero(pat == 1), np.flatnonzero(pat == -1)
        cut[n + plus] = -1.0
        cut[n + minus] = 1.0
        cut[2 * n:] = 1.0
        add(cut, 1.0 - plus.size, np.inf)
        for k, i in enumerate(deg):  # z_i/zs + w_i/ws >= delta d_i
            r = np.zeros(N)
            r[i] = U / zs
            r[:n] += UM[i] / ws
            r[2 * n + k] = -delta
            add(r, -q[i] / ws, np.inf)
    else:
        if not extra:
            res.status, res.seconds = "none", time.perf_counter() - t0
            res.message = (f"no row of L can move by {delta:g} s_L inside the box z <= {U:.3g}")
            return res
        for k, (j, sgn) in enumerate(extra):
            gain = sgn * L[j]
            big = dL + sgn * v_star[j] - U * float(np.sum(np.minimum(gain, 0.0)))
            r = np.zeros(N)
            r[:n] = U * gain
            r[2 * n + k] = -big
            add(r, dL - big + sgn * v_star[j], np.inf)
        cut[2 * n:] = 1.0
        add(cut, 1.0, np.inf)
    c = np.zeros(N)
    if objective == "min-sum":
        c[:n] = 1.0
    elif objective != "none":
        raise ValueError(f"objective must be 'min-sum' or 'none', got {objective!r}")
    integrality = np.r_[np.zeros(n), np.ones(N - n)]
    rejected = unproved = 0
    for _attempt in range(retries + 1):
        left = time_limit - (time.perf_counter() - t0)
        if left <= 0:
            res.message = f"time limit {time_limit:g} s reached"
            break
        A = sp.csr_matrix(np.array(rows))
        cons = LinearConstraint(A, np.array(lo), np.array(hi))
        out, runs = confirmed_milp(c, integrality, cons, left)
        res.info = {"milp_status": int(out.status), "milp_message": str(out.message),
                    "binaries": N - n, "rejected_bases": rejected, "milp_runs": runs}
        if out.x is None:
            if out.status == 2 and runs < 2:
                res.message = ("MILP infeasible at tolerance 1e-9; no time left to confirm "
                               "it at 1e-8: unknown")
            elif out.status == 2 and unproved:  # a cut that was not proved may hide a solution
                res.message = (f"MILP infeasible after {rejected} bases were cut, {unproved} of "
                               "them without proof that they hold no other solution: unknown")
            elif out.status == 2:  # proved infeasible, every cut proved
                res.status = "none"
                res.message = (f"no other solution with z <= {U:.3g} (MILP infeasible"
                               + (f" after {rejected} bases, each proved empty by LP, were cut"
                                  if rejected else "") + ")")
            else:
                res.message = f"MILP stopped without a point: {out.message}"
            break
        y = out.x[n:2 * n] > 0.5
        chosen = out.x[2 * n:] > 0.5
        other, proved = _polish(M, q, z_star, y, target, chosen, L, delta, zs, ws,
                                pat if target == "pattern" else None, extra)
        if other is not None:
            res.status, res.other = "found", other
            if target == "pattern":
                res.deviation = float(np.max(np.abs(other - z_star))) / zs
            else:
                res.deviation = float(np.max(np.abs(L @ (other - z_star)))) / sL
            res.message = ("another solution (max relative difference "
                           f"{res.deviation:.3g}) found"
                           + ("" if out.status == 0 else " (time limit hit)"))
            break
        # The basis proposed carries no exact solution with the target (rounding in the MILP):
        # cut it off (no-good cut on y) and ask again. The cut is sound only if every way the
        # target can differ was proved infeasible on this basis (`proved`); else a "none" at the
        # end would rest on it, and becomes "unknown".
        rejected += 1
        unproved += not proved
        r = np.zeros(N)
        r[n:2 * n] = np.where(y, -1.0, 1.0)
        add(r, 1.0 - float(np.sum(y)), np.inf)
    else:
        res.message = (f"{rejected} bases proposed by the MILP carried no exact solution with "
                       "the target's difference (rounding): verdict unknown")
    res.info["rejected_bases"] = rejected
    res.info["unproved_cuts"] = unproved
    res.seconds = time.perf_counter() - t0
    res.message += f" [{res.seconds:.2f} s]"
    return res


def confirmed_milp(c, integrality, constraints, seconds: float, bounds=None, options=None):
    """(HiGHS's answer, runs). "Infeasible" is asked again without presolve at 10 times the
    mip_feasibility_tolerance (a relaxation; its points are polished), and stands only if that
    run agrees (runs = 2): at 1e-9 HiGHS called test_uniqueness.PRESOLVE_M infeasible (scipy
    1.15.0, 1.17.1 with presolve; 1e-8 finds the point; 1e-6 lets in spurious points)."""
    t0 = time.perf_counter()
    runs = 0
    for tight in (True, False):
        left = seconds - (time.perf_counter() - t0)
        if runs and left <= 0:
            break
        opts = dict(_HIGHS_MILP if options is None else options)
        if not tight:
            opts.update(presolve=False, mip_feasibility_tolerance=1e-8)
        with quiet_highs():
            out = milp(c, integrality=integrality, constraints=constraints,
                       bounds=Bounds(0.0, 1.0) if bounds is None else bounds,
                       options={"time_limit": float(left), **opts})
        runs += 1
        if out.status != 2:
            break
    return out, runs


def _polish(M, q, z_star, y, target, chosen, L, delta, zs, ws, pat, extra
            ) -> tuple[np.ndarray | None, bool]:
    """(z, proved): an exact solution z on the MILP's basis y with the target's difference (an
    LP per way of differing, the MILP's chosen ones first), or None; `proved` is True when every
    one of those LPs was proved infeasible, i.e. the basis holds no such solution and cutting it
    off loses nothing. (The MILP's binaries may pick a disjunct that rounding made look
    satisfied while the basis holds a solution that differs elsewhere: all are tried.)"""
    n = q.size
    a, b = np.flatnonzero(y), np.flatnonzero(~y)
    bounds = [(0.0, None) if y[i] else (0.0, 0.0) for i in range(n)]
    order = np.r_[np.flatnonzero(chosen), np.flatnonzero(~chosen)]
    ways: list[tuple[np.ndarray, float] | None] = []
    check = None
    if target == "pattern":
        plus, minus = np.flatnonzero(pat == 1), np.flatnonzero(pat == -1)
        deg = np.flatnonzero(pat == 0)
        if np.any(~y[plus]) or np.any(y[minus]):
            ways = [None]  # the basis itself differs from z*'s pattern
        for k in order if not ways else []:
            i = deg[k]
            if y[i]:
                row = np.zeros(n)
                row[i] = -1.0 / zs  # z_i >= delta zs
                ways.append((row, -delta * (1 - 1e-3)))
            else:
                ways.append((-M[i] / ws, q[i] / ws - delta * (1 - 1e-3)))  # w_i >= delta ws
    else:
        v_star = L @ z_star
        sL = max(float(np.max(np.sum(np.abs(L), axis=1))) * zs, float(np.max(np.abs(v_star))),
                 1e-300)
        for k in order:
            j, sgn = extra[k]
            ways.append((-sgn * L[j] / sL, -sgn * v_star[j] / sL - delta * (1 - 1e-3)))

        def check(z):
            return float(np.max(np.abs(L @ (z - z_star)))) >= delta * sL * (1 - 1e-2)
    proved = True
    for way in ways:
        A_ub, b_ub = [-M[b]], [q[b]]
        if way is not None:
            A_ub.append(way[0][None, :])
            b_ub.append(np.array([way[1]]))
        res = linprog(np.ones(n), A_ub=np.vstack(A_ub), b_ub=np.concatenate(b_ub),
                      A_eq=M[a] if a.size else None, b_eq=-q[a] if a.size else None,
                      bounds=bounds, method="highs", options=_HIGHS_LP)
        if res.status == 2:
            continue
        proved = False
        if res.status != 0 or res.x is None:
            continue
        z = np.maximum(res.x, 0.0)
        if scaled_residual(M, q, z) <= 1e-8 and (check is None or check(z)):
            return z, False
    return None, proved
