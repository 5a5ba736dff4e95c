"""min cost . lambda over P (or a face of P) solved in rational arithmetic, for small piles: the
last retry of verify.statics.ends, where the floating-point LPs and their checks leave an end
or a sliding verdict unknown.

In the cone coordinates of verify.statics.model.cone_lp, P = {w >= 0 : K w = b}, K = A T, all
formed exactly from the stored doubles (verify.statics.exact.exact_columns). The LP
min (T^T cost) . w over P, with the `fixed` coordinates dropped (a face: those are 0), is
solved by the two-phase primal simplex on a dense tableau of python-flint fmpq's with Bland's
rule (the lowest-index entering column with a negative reduced cost, the lowest-index
leaving row on a tie: no cycling; Chvatal, "Linear Programming", 1983, ch. 3). Nothing is
taken on the simplex's word: each answer is returned with its certificate, checked exactly
on the original K and b:

* "optimal": w >= 0 with K w = b and a y with every reduced cost (T^T cost)_j - K_j . y >= 0
  and (T^T cost) . w = b . y: the value is the minimum (weak duality), attained at T w;
* "unbounded": d >= 0 with K d = 0 and (T^T cost) . d < 0 (and a point of P): a ray;
* "infeasible": y with K_j . y <= 0 for every column and b . y > 0 (Farkas: the face is
  empty).

Dense and exact, so only for P of at most MAX_ROWS balance rows (deposited piles of a few
disks, where the degenerate symmetric optima of docs/packings.md's "Still open" arise).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .exact import exact_columns
from .model import StaticProblem

#: Largest P (balance rows: 3 per disk) solved exactly.
MAX_ROWS = 60
#: Most pivots (both phases) before giving up.
MAX_PIVOTS = 3000


@dataclass
class ExactAnswer:
    """status "optimal" (lam = T w, value = the minimum, exactly as a Fraction), "unbounded"
    (a checked ray; lam a point of P) or "infeasible" (a checked Farkas certificate)."""

    status: str
    lam: np.ndarray | None = None
    value: object = None


def solve(prob: StaticProblem, cost: np.ndarray, fixed: tuple[int, ...] = ()
          ) -> ExactAnswer | None:
    """The checked exact answer (module docstring), or None (too large, pivots exhausted, or
    a check that fails, which would be a bug)."""
    from flint import fmpq

    m = prob.A.shape[0]
    if m > MAX_ROWS:
        return None
    data, bq = exact_columns(prob, np.asarray(cost, dtype=float))
    cols = [j for j in range(len(data)) if j not in set(int(f) for f in fixed)]
    K = [data[j][0] for j in cols]  # K[n][i]: column n, row i
    c = [data[j][1] for j in cols]
    n = len(cols)
    zero = fmpq(0)
    sign = [fmpq(-1) if v < 0 else fmpq(1) for v in bq]
    # tableau rows i: [sign_i K_i (n), artificial identity (m) | sign_i b_i]
    T = [[sign[i] * K[j][i] for j in range(n)] + [fmpq(1) if r == i else zero for r in range(m)]
         + [sign[i] * bq[i]] for i in range(m)]
    basis = [n + i for i in range(m)]
    phase1 = [zero] * n + [fmpq(1)] * m
    pivots = _simplex(T, basis, phase1, n + m, MAX_PIVOTS)
    if pivots is None:
        return None
    y1 = _duals(T, basis, phase1, m)  # for the sign-flipped rows
    if sum((T[i][-1] for i in range(m) if basis[i] >= n), zero) > 0:
        y = [s * v for s, v in zip(sign, y1)]  # a Farkas certificate in the original rows
        farkas = all(_dot(K[j], y) <= 0 for j in range(n)) and _dot(bq, y) > 0
        return ExactAnswer("infeasible") if farkas else None
    # drive the artificials (all at 0) out of the basis where a structural column can enter
    for i in range(m):
        if basis[i] >= n:
            enter = next((j for j in range(n) if T[i][j] != 0), None)
            if enter is not None:
                _pivot(T, basis, i, enter)
    allowed = n  # artificials never enter again; those left sit on redundant rows at 0
    phase2 = c + [zero] * m
    if _simplex(T, basis, phase2, allowed, MAX_PIVOTS - pivots, ray=True) is None:
        return None
    w = [zero] * n
    for i, j in enumerate(basis):
        if j < n:
            w[j] = T[i][-1]
    if not (all(v >= 0 for v in w) and all(
            sum((K[j][i] * w[j] for j in range(n)), zero) == bq[i] for i in range(m))):
        return None
    lam = _lam(prob, cols, w)
    return _finish(K, c, bq, T, basis, phase2, w, lam)


def _finish(K: list, c: list, bq: list, T: list, basis: list, cost: list, w: list,
            lam: np.ndarray) -> ExactAnswer | None:
    """The phase-2 end: a checked ray when the simplex stopped on one, else a checked
    optimum (module docstring)."""
    from fractions import Fraction

    from flint import fmpq

    zero = fmpq(0)
    m, n = len(bq), len(c)
    r = _reduced(T, basis, cost, n)
    enter = next((j for j in range(n) if r[j] < 0), None)
    if enter is not None:  # no leaving row (_simplex stopped on a ray): d_enter = 1
        d = [zero] * n
        d[enter] = fmpq(1)
        for i, j in enumerate(basis):
            if j < n:
                d[j] = -T[i][enter]
        ok = (all(v >= 0 for v in d)
              and all(sum((K[j][i] * d[j] for j in range(n)), zero) == 0 for i in range(m))
              and _dot(c, d) < 0)
        return ExactAnswer("unbounded", lam) if ok else None
    y = _duals(T, basis, cost, m)
    # the rows were sign-flipped where b < 0: y for the original rows
    y = [(-v if b < 0 else v) for v, b in zip(y, bq)]
    if not all(c[j] - _dot(K[j], y) >= 0 for j in range(n)):
        return None
    value = _dot(c, w)
    if value != _dot(bq, y):
        return None
    return ExactAnswer("optimal", lam, Fraction(int(value.p), int(value.q)))


def _dot(a: list, b: list):
    from flint import fmpq

    return sum((x * y for x, y in zip(a, b)), fmpq(0))


def _lam(prob: StaticProblem, cols: list[int], w: list) -> np.ndarray:
    """lambda = T w in floats (each entry rounded once from its exact value)."""
    from flint import fmpq

    from .model import cone_lp

    _, Tm, _ = cone_lp(prob)
    Tm = Tm.tocsr()
    out = np.zeros(prob.n)
    full = {j: v for j, v in zip(cols, w)}
    for r in range(prob.n):
        acc = fmpq(0)
        for j in Tm.indices[Tm.indptr[r]:Tm.indptr[r + 1]]:
            if int(j) in full:
                acc += _exact_t(prob, r, int(j)) * full[int(j)]
        out[r] = int(acc.p) / int(acc.q)
    return out


def _exact_t(prob: StaticProblem, r: int, j: int):
    """T's entry (row r of lambda, cone coordinate j) exactly: 1/(2 mu), -1/2 or 1/2, or 1."""
    from flint import fmpq

    from .farkas import rational

    k = prob.fric.size
    if j >= 2 * k:
        return fmpq(1)
    a = int(prob.fric[j % k])
    if r == a:
        return 1 / (2 * rational(prob.mu[a]))
    return fmpq(-1 if j < k else 1, 2)


def _reduced(T: list, basis: list, cost: list, width: int) -> list:
    """The reduced costs cost_j - cost_B . T_j of the first `width` columns."""
    return [cost[j] - sum((cost[basis[i]] * T[i][j] for i in range(len(T))), cost[j] * 0)
            for j in range(width)]


def _duals(T: list, basis: list, cost: list, m: int) -> list:
    """y = cost_B B^-1 of the tableau's rows, read off the artificial columns (the last m
    before the right-hand side, whose original columns are the identity)."""
    n = len(T[0]) - 1 - m
    return [sum((cost[basis[i]] * T[i][n + r] for i in range(m)), cost[0] * 0)
            for r in range(m)]


def _pivot(T: list, basis: list, i: int, j: int) -> None:
    piv = T[i][j]
    T[i] = [v / piv for v in T[i]]
    for r in range(len(T)):
        if r != i and T[r][j] != 0:
            f = T[r][j]
            T[r] = [a - f * b for a, b in zip(T[r], T[i])]
    basis[i] = j


def _simplex(T: list, basis: list, cost: list, allowed: int, limit: int,
             ray: bool = False) -> int | None:
    """Bland's rule pivots until no column among the first `allowed` has a negative reduced
    cost (the pivots made), or, with ray, a column without a leaving row (stops there); None
    when `limit` pivots do not suffice."""
    for count in range(limit + 1):
        r = _reduced(T, basis, cost, allowed)
        enter = next((j for j in range(allowed) if r[j] < 0), None)
        if enter is None:
            return count
        best, leave = None, None
        for i in range(len(T)):
            if T[i][enter] > 0:
                ratio = T[i][-1] / T[i][enter]
                if best is None or ratio < best or (ratio == best and basis[i] < basis[leave]):
                    best, leave = ratio, i
        if leave is None:
            return count if ray else None
        _pivot(T, basis, leave, enter)
    return None
