"""Lemke's method in exact rational arithmetic: the lexicographic rule that cannot cycle.

The float run of lcp.lemke breaks ratio ties lexicographically (Cottle, Pang & Stone 1992,
Sec. 4.9), but two rows whose lexicographic keys differ by less than the rounding of the
dictionary look tied, and a wrong choice can revisit a basis ("numerical cycling"). In exact
arithmetic the rows of B^-1 are distinct, so the rule is a total order and Lemke's path never
repeats a basis (CPS Thm 4.9.4). `lemke_exact` runs the same algorithm on the data as given
(every double is a rational number) with python-flint's exact rationals: each pivot is exact,
each tie is decided exactly. It is the fall-back of lcp.lemke when the float run cycles or
ends on a ray that proves nothing (small n only: the entries' sizes grow with the pivots).
For a cycling run of larger n, `ExactTies` keeps the pivots in floats and decides exactly
only the ratio ties that rounding may have decided (`ambiguous_tie`), from the data and the
current basis; `with_exact_ties` is that rerun.

Tableau: [I, -M, -d | q] with basis {w}, i.e. w - M z - d z0 = q; the basic variables are
x_B = rhs - col t along an entering column. Variables: w_i = i, z_i = n + i, z0 = 2n.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from ..problems.solution import Solution

#: Largest n the exact run takes after a cycling float run (cost O(n^2) rational operations
#: per pivot, with growing entries: ~0.5 s at n = 60), and after a ray that proves nothing
#: (rays are common on general M: the rerun is kept cheap there).
EXACT_MAX_N = 60
EXACT_RAY_MAX_N = 24


def _rationals(values) -> list:
    from flint import fmpq  # a dependency (pyproject); loaded on first use

    out = []
    for v in values:
        f = Fraction(float(v))
        out.append(fmpq(f.numerator, f.denominator))
    return out


def lemke_exact(M: np.ndarray, q: np.ndarray, d: np.ndarray, max_iter: int) -> Solution:
    """Lemke's method with covering vector d, pivots and lexicographic ratio tests in exact
    rationals (module doc). Status "solved" (z exact, rounded once to double), "ray" (a
    secondary ray; info["ray"] the direction in (z, z0)) or "max_iter"."""
    from flint import fmpq

    n = q.size
    zero = fmpq(0)
    Mq = _rationals(M.ravel())
    dq, qq = _rationals(d), _rationals(q)
    width = 2 * n + 1
    # rows: [coefficients of w (n), z (n), z0 (1)], rhs separately
    T = []
    for i in range(n):
        row = [zero] * width
        row[i] = fmpq(1)
        for j in range(n):
            row[n + j] = -Mq[i * n + j]
        row[2 * n] = -dq[i]
        T.append(row)
    rhs = list(qq)
    basic = list(range(n))

    def key(i: int, col: list):
        """The lexicographic key (rhs_i, (B^-1)_i) / col_i of row i: B^-1 is the w block."""
        c = col[i]
        return [rhs[i] / c] + [T[i][j] / c for j in range(n)]

    def pivot(r: int, s: int) -> int:
        p = T[r][s]
        T[r] = [v / p for v in T[r]]
        rhs[r] = rhs[r] / p
        for i in range(n):
            if i != r and T[i][s] != 0:
                f = T[i][s]
                Ti, Tr = T[i], T[r]
                T[i] = [a - f * b for a, b in zip(Ti, Tr)]
                rhs[i] = rhs[i] - f * rhs[r]
        leaving = basic[r]
        basic[r] = s
        return leaving

    # step 0: z0 enters; the row of the lexicographically smallest (q_i, e_i) / d_i leaves
    # (the most negative q_i / d_i: every rhs becomes >= 0)
    r = min(range(n), key=lambda i: [qq[i] / dq[i]] + [fmpq(int(i == j)) / dq[i]
                                                        for j in range(n)])
    s = 2 * n
    pivots = 0
    while True:
        leaving = pivot(r, s)
        pivots += 1
        if leaving == 2 * n:
            return _solution(basic, rhs, n, pivots, "solved")
        if pivots >= max_iter:
            sol = _solution(basic, rhs, n, pivots, "max_iter")
            sol.message = f"pivot limit {pivots} reached (exact arithmetic)"
            return sol
        s = leaving + n if leaving < n else leaving - n
        col = [T[i][s] for i in range(n)]
        rows = [i for i in range(n) if col[i] > 0]
        if not rows:
            return _ray(basic, rhs, col, s, n, pivots)
        ratio = min(rhs[i] / col[i] for i in rows)
        tied = [i for i in rows if rhs[i] / col[i] == ratio]
        z0_rows = [i for i in tied if basic[i] == 2 * n]
        r = z0_rows[0] if z0_rows else min(tied, key=lambda i: key(i, col))


def _float(x) -> float:
    """The double nearest a python-flint rational (its numerator over its denominator: Python's
    int division rounds correctly; python-flint < 0.7's fmpq has no __float__)."""
    return int(x.p) / int(x.q)


def _solution(basic: list, rhs: list, n: int, pivots: int, status: str) -> Solution:
    x = np.zeros(2 * n + 1)
    for i, var in enumerate(basic):
        x[var] = _float(rhs[i])
    z = x[n:2 * n]
    basis = np.array(sorted(v - n for v in basic if n <= v < 2 * n), dtype=np.intp)
    return Solution(z=z.copy(), w=x[:n].copy(), status=status, method="lemke",
                    iterations=pivots, basis=basis,
                    info={"exact": True, "z0": float(x[2 * n])})


def _ray(basic: list, rhs: list, col: list, s: int, n: int, pivots: int) -> Solution:
    """A secondary ray: x_B = rhs - col t, x_s = t, t -> infinity."""
    sol = _solution(basic, rhs, n, pivots, "ray")
    dz = np.zeros(2 * n + 1)
    for i, var in enumerate(basic):
        dz[var] = -_float(col[i])
    dz[s] = 1.0
    ray = np.append(dz[n:2 * n], dz[2 * n])
    ray /= max(float(np.abs(ray).max()), 1e-300)
    name = f"w[{s}]" if s < n else f"z[{s - n}]"
    sol.info.update({"ray": ray, "entering": name, "point": sol.z.copy()})
    y = np.maximum(ray[:n], 0.0)
    if y.sum() > 0:
        sol.info["farkas"] = y / y.sum()
    sol.message = (f"secondary ray after {pivots} pivots in exact arithmetic ({name} "
                   "entering unblocked)")
    return sol


#: Largest n whose float run, after it cycled (n > EXACT_MAX_N: the exact run is too slow), is
#: redone with its ambiguous ratio ties decided exactly (`ExactTies`: two rational solves
#: with the basis per such tie, ~0.03 s at n = 60 and ~0.2 s at n = 120 on dense data, and the
#: numpy loop, 10-40 times the compiled one's time: benchmarks/lemke_fallback.py).
EXACT_TIES_MAX_N = 150


class ExactTies:
    """The lexicographic ratio test of a float run of Lemke's method decided exactly.

    The float run (lcp.lemke._Lemke) breaks ratio ties by the rows of B^-1 read from its
    dictionary (Cottle-Pang-Stone Sec. 4.9); when two tied rows' keys differ by less than the
    dictionary's rounding, it can pick the wrong row, and the path leaves the exact
    lexicographic path (which never repeats a basis). `choose` redoes such a choice in
    rationals from the data as given (each double a rational) and the current basis: with
    B the basic columns of [I, -M, -d], beta = B^-1 q and alpha = B^-1 N_e (N_e the entering
    variable's column; its negative in step 0, where z0 enters and the row of least
    q_i / d_i leaves), it takes among the float candidate rows with alpha_i > 0 those of
    least beta_i / alpha_i, then z0's row if it is one of them, else the lexicographically
    least B^-1[i, :] / alpha_i (rows of B^-1 from B^T y = e_i). Only the choice is exact; the
    dictionary stays in floats."""

    def __init__(self, M: np.ndarray, q: np.ndarray, d: np.ndarray):
        self.n = n = q.size
        Mq = _rationals(M.ravel())
        self.neg_cols = [[-Mq[i * n + j] for i in range(n)] for j in range(n)]
        self.q = _rationals(q)
        self.neg_d = [-v for v in _rationals(d)]
        self.decided = 0  # number of exact decisions taken

    def column(self, var: int) -> list:
        """Column of variable `var` (w_i = i, z_j = n + j, z0 = 2n) in [I, -M, -d]."""
        from flint import fmpq

        n = self.n
        if var < n:
            return [fmpq(int(i == var)) for i in range(n)]
        return self.neg_cols[var - n] if var < 2 * n else self.neg_d

    def choose(self, basic, entering: int, rows) -> int | None:
        """The exact lexicographic choice among `rows` (the float candidates) for the
        entering variable, basic[i] the variable of row i; None when the exact data do not
        support a choice there (no candidate with alpha_i > 0, or B singular: the float path
        has left the exact one before this pivot)."""
        from flint import fmpq_mat

        n = self.n
        cols = [self.column(int(v)) for v in basic]
        B = fmpq_mat(n, n, [cols[j][i] for i in range(n) for j in range(n)])
        Ne = self.column(entering)
        try:
            X = B.solve(fmpq_mat(n, 2, [v for i in range(n) for v in (self.q[i], Ne[i])]))
        except ZeroDivisionError:
            return None
        sign = -1 if entering == 2 * n else 1  # step 0: alpha = d
        alpha = [sign * X[i, 1] for i in range(n)]
        cand = [int(i) for i in rows if alpha[int(i)] > 0]
        if not cand:
            return None
        self.decided += 1
        theta = {i: X[i, 0] / alpha[i] for i in cand}
        least = min(theta.values())
        tied = [i for i in cand if theta[i] == least]
        z0 = [i for i in tied if int(basic[i]) == 2 * n]
        if z0 or len(tied) == 1:
            return (z0 or tied)[0]
        E = fmpq_mat(n, len(tied), [int(i == r) for i in range(n) for r in tied])
        Y = B.transpose().solve(E)  # column k: row tied[k] of B^-1
        k = min(range(len(tied)), key=lambda k: [Y[j, k] / alpha[tied[k]] for j in range(n)])
        return tied[k]


def ambiguous_tie(run, rows: np.ndarray, alpha: np.ndarray, theta: np.ndarray) -> bool:
    """Can rounding have decided the lexicographic choice among the tied `rows` of a float
    run (lcp.lemke._Lemke: its dictionary T, slot_np, basic_np, tol; pivots alpha > 0, ratios
    theta)? Yes when their ratios are not equal as floats (a near-tie: equal or not, exactly?),
    when two of them differ in a column of B^-1 (of a nonbasic w) by less than the tie
    tolerance but not by zero, or when two rows with a basic z (no unit column) agree to it in
    every column (its lexico_min would then take the larger pivot). Otherwise the rows are
    told apart by unit columns and by differences above the tolerance: `ExactTies` is not
    needed."""
    if theta.max() > theta.min():
        return True
    n = run.n
    slot_w = run.slot_np[:n]
    V = -run.T[np.ix_(rows, slot_w[slot_w >= 0])] / alpha[:, None]
    eps = run.tol * max(float(np.abs(V).max(initial=0.0)), float((1.0 / alpha).max()))
    spread = V.max(axis=0, initial=-np.inf) - V.min(axis=0, initial=np.inf)
    if np.any((spread > 0) & (spread <= eps)):
        return True
    zrows = run.basic_np[rows] >= n
    return bool(np.count_nonzero(zrows) >= 2 and not np.any(
        V[zrows].max(axis=0, initial=-np.inf) - V[zrows].min(axis=0, initial=np.inf) > eps))


def with_exact_ties(first: Solution, run, M: np.ndarray, q: np.ndarray, d: np.ndarray
                    ) -> Solution:
    """A float run that cycled (`first`) done again by `run(ties)` (lcp.lemke._Lemke's numpy
    loop) with each ratio tie that rounding may have decided decided by `ExactTies`: the
    float pivots follow the exact lexicographic path wherever the float ratio test sees the
    exact candidates. The message says so; info["exact_ties"] = the number of exact
    decisions."""
    ties = ExactTies(M, q, d)
    sol = run(ties)
    sol.message = (f"{first.message}; rerun with its ambiguous ratio ties decided in exact "
                   f"rational arithmetic ({ties.decided}): {sol.message}").rstrip(": ")
    sol.info["exact_ties"] = ties.decided
    return sol
