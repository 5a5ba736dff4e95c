"""Exhaustive enumeration of complementary bases (method ``enumerate``; small n only).

For every subset alpha of {0, ..., n-1} (the indices where z may be positive; beta is the
complement, where z = 0) the complementary basis gives

    M_aa z_a = -q_a,    z_b = 0,    w = M z + q,

and the basis yields a solution when z_a >= 0 and w_b >= 0 (w_a = 0 by construction). Every
solution of the LCP lies in the set of some basis, so scanning all 2^n subsets finds them all
(Cottle, Pang & Stone, *The Linear Complementarity Problem*, 1992, Sec. 1.4 and 3.9).

Singular principal submatrices. A solution may exist only on a basis whose M_aa is singular
(example: M = [[0, 0], [1, -1]], q = [0, -1], whose solutions are z = (1 + s, s), s >= 0, and
also z = (t, 0), t >= 1: every nonsingular basis fails). Skipping such bases would miss
solutions, and taking the minimum-norm least-squares point would too (here it is z = 0). What
is done instead, for a basis whose M_aa is singular or has condition number above 1/rcond:

* an SVD gives the numerical rank r, a particular solution z_p and a null-space basis N of M_aa;
  if -q_a is not in the range of M_aa (to the tolerance), the basis has no solution;
* otherwise the basis's solution set is the polyhedron {y : z_p + N y >= 0, w_b(y) >= 0}, and
  a linear program (HiGHS through scipy.optimize.linprog) finds one of its points (a vertex,
  minimizing sum z_a), or proves it empty;
* two more LPs with a random objective measure its extent: a set wider than the tolerance (or
  unbounded) means a *continuum* of solutions, flagged ``info["continuum"] = True``.

A nonsingular basis gives at most one point, so the LCP has infinitely many solutions exactly
when some singular basis has a continuum: ``enumerate_solutions`` therefore answers the
uniqueness question completely (to the tolerance), not only "how many vertices".

Tolerances are relative to the data: z_a >= -tol * z_scale with z_scale = max(|z|, |q|/|M|),
and w_i >= -tol * (|q_i| + sum_j |M_ij| |z_j|) (the size of the terms that make w_i, floored
at 1e-4 of the largest such size); the same bound limits |w_a|, which screens near-singular
bases whose solve lost accuracy.

Cost: 2^n small solves, done in batches with numpy's stacked ``inv`` (one refinement step), so
n = 12 takes a few tens of milliseconds and n = 20 (10^6 bases) tens of seconds.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog

from ..problems.problem import LCP, MLCP, InvalidProblem, NotApplicable
from ..problems.solution import Solution, complementarity_residual
from ..registry import register

#: Default largest n for exhaustive enumeration (2^20 = 1,048,576 bases).
MAX_N = 20
#: Bases whose estimated 1-norm condition number exceeds 1/RCOND are treated as singular.
RCOND = 1e-10
#: Row scales of w are at least FLOOR times the largest one (see _Scales.w_scale).
FLOOR = 1e-4
#: A singular basis's solution set wider than WIDTH_FACTOR * tol * z_scale is a continuum.
WIDTH_FACTOR = 1e3
#: HiGHS tolerances for the LPs of singular bases (its defaults are 1e-7).
_HIGHS = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}
#: Work per batch (elements of the stacked arrays), to bound memory at n = 20.
_BATCH_ELEMENTS = 2_000_000


@dataclass
class _Candidate:
    order: int  # position in the enumeration order (size, then lexicographic)
    alpha: tuple[int, ...]
    z: np.ndarray
    singular: bool
    continuum: bool


class _Scales:
    """Data scales for the relative tolerances."""

    def __init__(self, M: np.ndarray, q: np.ndarray, tol: float):
        self.tol = tol
        self.m = float(np.max(np.abs(M))) or 1.0
        self.q = float(np.max(np.abs(q)))
        self.absM = np.abs(M)
        self.absq = np.abs(q)

    def z_scale(self, z: np.ndarray) -> np.ndarray:
        """Per candidate (rows of z): max(|z|_inf, |q|_inf / |M|_max), at least tiny."""
        return np.maximum(np.max(np.abs(z), axis=-1, initial=0.0), self.q / self.m) + 1e-300

    def w_scale(self, z: np.ndarray) -> np.ndarray:
        """Per candidate and row: |q_i| + sum_j |M_ij| |z_j|, at least FLOOR times its max.

        The row scale makes the test invariant under scaling a row of (M, q); the floor keeps
        a row whose entries are all tiny (1e-70 next to O(1) rows) from demanding accuracy
        beyond the rounding level of the whole problem.
        """
        ws = self.absq + np.abs(z) @ self.absM.T + 1e-300
        return np.maximum(ws, FLOOR * np.max(ws, axis=-1, keepdims=True))

    def accept(self, z: np.ndarray, w: np.ndarray, alpha_mask: np.ndarray) -> np.ndarray:
        """Rows (candidates) that are complementary solutions to the tolerance."""
        tz = self.tol * self.z_scale(z)[:, None]
        tw = self.tol * self.w_scale(z)
        z_ok = np.all((z >= -tz) | ~alpha_mask, axis=1)
        w_ok = np.all(w >= -tw, axis=1)
        eq_ok = np.all((np.abs(w) <= tw) | ~alpha_mask, axis=1)
        return z_ok & w_ok & eq_ok


def _combinations(n: int, k: int, chunk: int):
    """Index arrays (chunk x k) of the k-subsets of range(n), in lexicographic order."""
    it = itertools.combinations(range(n), k)
    while True:
        block = list(itertools.islice(it, chunk))
        if not block:
            return
        yield np.array(block, dtype=np.intp).reshape(len(block), k)


def _batched_inverse(Ms: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverses of a stack of matrices and a mask of those that are numerically nonsingular."""
    c = Ms.shape[0]
    ok = np.ones(c, dtype=bool)
    try:
        X = np.linalg.inv(Ms)
    except np.linalg.LinAlgError:  # some member exactly singular: find them, invert the rest
        s = np.linalg.svd(Ms, compute_uv=False)
        ok = s[:, -1] > s[:, 0] * RCOND
        X = np.zeros_like(Ms)
        if ok.any():
            try:
                X[ok] = np.linalg.inv(Ms[ok])
            except np.linalg.LinAlgError:
                for i in np.flatnonzero(ok):
                    try:
                        X[i] = np.linalg.inv(Ms[i])
                    except np.linalg.LinAlgError:
                        ok[i] = False
    norm1 = np.max(np.sum(np.abs(Ms), axis=1), axis=1)
    norm1_inv = np.max(np.sum(np.abs(X), axis=1), axis=1)
    with np.errstate(invalid="ignore", over="ignore"):
        ok &= np.isfinite(norm1_inv) & (norm1 * norm1_inv * RCOND <= 1.0)
    return X, ok


def _singular_basis(
    M: np.ndarray, q: np.ndarray, alpha: np.ndarray, sc: _Scales, rng: np.random.Generator
) -> tuple[np.ndarray, bool] | None:
    """A solution on a basis with singular M_aa (and whether the basis holds a continuum).

    Returns None when the basis has no solution. See the module docstring for the method.
    """
    n = q.size
    beta = np.setdiff1d(np.arange(n), alpha)
    Maa = M[np.ix_(alpha, alpha)]
    U, s, Vt = np.linalg.svd(Maa)
    rank = int(np.sum(s > s[0] * RCOND)) if s[0] > 0 else 0
    rhs = -q[alpha]
    coef = U[:, :rank].T @ rhs
    zp = Vt[:rank].T @ (coef / s[:rank])
    N = Vt[rank:].T  # k x d null-space basis, d >= 1
    # Consistency: the part of -q_a outside the range of M_aa must vanish (to the tolerance).
    z_full = np.zeros(n)
    z_full[alpha] = zp
    tw = sc.tol * sc.w_scale(z_full[None, :])[0]
    out_of_range = rhs - U[:, :rank] @ coef
    if np.any(np.abs(out_of_range) > tw[alpha]):
        return None
    tz = sc.tol * float(sc.z_scale(zp[None, :])[0])
    # Feasible set in y: z_p + N y >= 0, M_ba (z_p + N y) + q_b >= 0; if rounding makes it
    # empty, relax by half the tolerance (so that the LP's point passes the final check).
    Mba = M[np.ix_(beta, alpha)]
    A_ub = np.vstack([-N, -(Mba @ N)])
    b_exact = np.concatenate([zp, Mba @ zp + q[beta]])
    b_ub = b_exact + np.concatenate([np.full(alpha.size, tz), tw[beta]]) / 2
    # Rows that do not depend on y (e.g. duplicated columns) decide at once.
    absA = np.abs(A_ub)
    biggest = float(np.max(absA, initial=0.0))
    free_rows = np.max(absA, axis=1, initial=0.0) <= RCOND * (1.0 + biggest)
    if np.any(b_ub[free_rows] < 0):
        return None
    d = N.shape[1]
    if d == 0:  # full rank by the SVD (the cheaper condition estimate said singular): one point
        return (zp, False) if np.all(b_ub >= 0) else None
    bounds = [(None, None)] * d
    res = linprog(N.sum(axis=0), A_ub=A_ub, b_ub=b_ub, bounds=bounds, method="highs",
                  options=_HIGHS)
    if res.status != 0:  # infeasible (2), or numerical trouble: no solution on this basis
        return None
    exact = linprog(N.sum(axis=0), A_ub=A_ub, b_ub=b_exact, bounds=bounds, method="highs",
                    options=_HIGHS)
    if exact.status == 0:  # the same set without the relaxation: a cleaner point
        res = exact
    y = res.x
    z = zp + N @ y
    # Extent of the basis's solution set along a random direction of z-space.
    c = N.T @ rng.standard_normal(alpha.size)
    c /= max(np.linalg.norm(c), 1e-300)
    lo = linprog(c, A_ub=A_ub, b_ub=b_ub, bounds=bounds, method="highs", options=_HIGHS)
    hi = linprog(-c, A_ub=A_ub, b_ub=b_ub, bounds=bounds, method="highs", options=_HIGHS)
    if lo.status == 3 or hi.status == 3:  # unbounded
        continuum = True
    elif lo.status == 0 and hi.status == 0:
        width = -hi.fun - lo.fun
        continuum = width > WIDTH_FACTOR * tz
    else:
        continuum = False
    return z, continuum


def _scan(
    M: np.ndarray, q: np.ndarray, tol: float, first: bool
) -> tuple[list[_Candidate], dict]:
    """Enumerate the complementary bases in order of size; stop at the first hit if `first`."""
    n = q.size
    sc = _Scales(M, q, tol)
    rng = np.random.default_rng(0)  # the extent test's direction: reproducible
    found: list[_Candidate] = []
    stats = {"bases_checked": 0, "singular_bases": 0, "lp_bases": 0}
    # alpha = {}: z = 0, w = q.
    stats["bases_checked"] += 1
    if sc.accept(np.zeros((1, n)), q[None, :], np.zeros((1, n), dtype=bool))[0]:
        found.append(_Candidate(0, (), np.zeros(n), False, False))
        if first:
            return found, stats
    order = 1
    MT = M.T
    for k in range(1, n + 1):
        chunk = max(1, _BATCH_ELEMENTS // (k * max(k, n)))
        for idx in _combinations(n, k, chunk):
            c = idx.shape[0]
            stats["bases_checked"] += c
            Ms = M[idx[:, :, None], idx[:, None, :]]
            qa = q[idx]
            X, ok = _batched_inverse(Ms)
            za = -np.einsum("cij,cj->ci", X, qa)
            r = np.einsum("cij,cj->ci", Ms, za) + qa
            za -= np.einsum("cij,cj->ci", X, r)  # one step of iterative refinement
            Z = np.zeros((c, n))
            np.put_along_axis(Z, idx, za, axis=1)
            W = q + np.einsum("ck,ckn->cn", za, MT[idx])
            mask = np.zeros((c, n), dtype=bool)
            np.put_along_axis(mask, idx, True, axis=1)
            good = ok & sc.accept(Z, W, mask)
            hits = [(int(i), Z[i], False, False) for i in np.flatnonzero(good)]
            bad = np.flatnonzero(~ok)
            stats["singular_bases"] += bad.size
            for i in bad:
                if first and hits and hits[0][0] < i:
                    break
                stats["lp_bases"] += 1
                got = _singular_basis(M, q, idx[i], sc, rng)
                if got is None:
                    continue
                z = np.zeros(n)
                z[idx[i]] = got[0]
                w = M @ z + q
                if sc.accept(z[None, :], w[None, :], mask[i][None, :])[0]:
                    hits.append((int(i), z, True, got[1]))
            hits.sort(key=lambda h: h[0])
            for i, z, singular, continuum in hits:
                found.append(_Candidate(order + i, tuple(int(j) for j in idx[i]), z, singular,
                                        continuum))
                if first:
                    return found, stats
            order += c
    return found, stats


def _dedup(cands: list[_Candidate], tol: float) -> list[tuple[_Candidate, int]]:
    """Distinct solutions (to `tol`, relative), each with the number of bases that gave it."""
    uniques: list[_Candidate] = []
    counts: list[int] = []
    reps: list[np.ndarray] = []
    for cand in cands:
        if reps:
            R = np.array(reps)
            scale = 1.0 + np.maximum(np.max(np.abs(R), axis=1), np.max(np.abs(cand.z)))
            close = np.max(np.abs(R - cand.z), axis=1) <= 1e2 * tol * scale
            j = int(np.argmax(close)) if close.any() else -1
            if j >= 0:
                counts[j] += 1
                uniques[j].continuum |= cand.continuum
                continue
        uniques.append(cand)
        counts.append(1)
        reps.append(cand.z)
    return list(zip(uniques, counts, strict=True))


def _as_lcp(problem_or_M, q) -> tuple[LCP, MLCP | None]:
    if isinstance(problem_or_M, MLCP):
        if q is not None:
            raise InvalidProblem("q must not be given together with a problem object")
        return problem_or_M.to_lcp(), problem_or_M
    if isinstance(problem_or_M, LCP):
        if q is not None:
            raise InvalidProblem("q must not be given together with a problem object")
        return problem_or_M, None
    if q is None:
        raise InvalidProblem("q is missing: pass an LCP/MLCP, or M and q")
    return LCP(problem_or_M, q), None


def _solution(lcp: LCP, mlcp: MLCP | None, cand: _Candidate, count: int, stats: dict,
              method: str = "enumerate") -> Solution:
    z = np.maximum(cand.z, 0.0)  # only entries within the tolerance of 0 can be negative
    sol = Solution(
        z=z, w=lcp.M @ z + lcp.q, status="solved", method=method,
        iterations=int(stats["bases_checked"]), basis=np.array(cand.alpha, dtype=np.intp),
        info={"singular": cand.singular, "continuum": cand.continuum, "n_bases": count},
    )
    if mlcp is not None:
        sol.u = mlcp.recover_u(z)
        sol.w, sol.eq_residual = mlcp.residuals(sol.u, z)
    sol.residual = complementarity_residual(sol.z, sol.w)
    return sol


def enumerate_solutions(
    problem_or_M: LCP | MLCP | np.ndarray, q: np.ndarray | None = None, *,
    tol: float = 1e-9, max_n: int = MAX_N,
) -> list[Solution]:
    """All distinct solutions of an LCP, by enumerating every complementary basis.

    `problem_or_M` is an `LCP`, an `MLCP` (reduced by the Schur complement; u is recovered), or
    a matrix M given with `q`. Solutions closer than ~100 tol (relative) are merged;
    ``info["n_bases"]`` counts the bases that gave each one (more than one: a degenerate solution),
    ``info["singular"]`` says it came from a singular M_aa (found by an LP), and
    ``info["continuum"]`` that it is one point of a continuum of solutions. So the LCP has a
    unique solution iff the list has one element whose ``info["continuum"]`` is False.
    Solutions are ordered by basis size, then lexicographically.
    """
    lcp, mlcp = _as_lcp(problem_or_M, q)
    _check_tol(tol)
    if lcp.n > max_n:
        raise NotApplicable(
            f"enumeration visits 2^n bases; n = {lcp.n} exceeds max_n = {max_n}"
        )
    cands, stats = _scan(lcp.M, lcp.q, tol, first=False)
    return [_solution(lcp, mlcp, c, k, stats) for c, k in _dedup(cands, tol)]


def _check_tol(tol: float) -> None:
    if not (isinstance(tol, (int, float)) and math.isfinite(tol) and 0 < tol < 1):
        raise InvalidProblem(f"tol must be a number in (0, 1), got {tol!r}")


@register(
    "enumerate", accepts="small-n", max_n=MAX_N, equilibrate=True,
    description="Every complementary basis (2^n solves; singular bases by LP): all solutions, "
    "hence uniqueness; returns the first (or the min-norm) one.",
)
def solve_enumerate(M: np.ndarray, q: np.ndarray, *, tol: float = 1e-9,
                    select: str = "first") -> Solution:
    """Solve an LCP by exhaustive enumeration of complementary bases (Murty 1988, Sec. 1.1).

    `select`: "first" stops at the first basis (by size, then lexicographic) that gives a
    solution; "min-norm" enumerates everything and returns the solution of least |z|_2, with
    the number of distinct solutions in ``info["solutions"]``. Status "infeasible" when no
    basis gives a solution (the exhaustive scan is the evidence: ``info["bases_checked"]``).
    `iterations` is the number of bases examined.
    """
    _check_tol(tol)
    if select not in ("first", "min-norm"):
        raise InvalidProblem(f"select must be 'first' or 'min-norm', got {select!r}")
    lcp = LCP(M, q)
    cands, stats = _scan(lcp.M, lcp.q, tol, first=select == "first")
    if not cands:
        return Solution(
            z=np.zeros(lcp.n), w=lcp.q.copy(), status="infeasible", method="enumerate",
            iterations=int(stats["bases_checked"]),
            message=f"none of the {stats['bases_checked']} complementary bases gives a solution "
            f"(tolerance {tol:g}): the LCP has no solution",
            info=dict(stats),
        )
    uniq = _dedup(cands, tol)
    if select == "min-norm":
        best, count = min(uniq, key=lambda cc: float(np.linalg.norm(cc[0].z)))
    else:
        best, count = uniq[0]
    sol = _solution(lcp, None, best, count, stats)
    sol.info.update(stats)
    if select == "min-norm":
        sol.info["solutions"] = len(uniq)
        sol.info["any_continuum"] = any(c.continuum for c, _ in uniq)
    return sol
