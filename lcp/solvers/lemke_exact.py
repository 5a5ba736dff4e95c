"""Lemke's method in exact rational arithmetic: the lexicographic rule that cannot cycle.

The float run of lcp.lemke breaks ratio ties lexicographically (Cottle, Pang & Stone 1992,
Sec. 4.9), but two rows whose lexicographic keys differ by less than the rounding of the
dictionary look tied, and a wrong choice can revisit a basis ("numerical cycling"). In exact
arithmetic the rows of B^-1 are distinct, so the rule is a total order and Lemke's path never
repeats a basis (CPS Thm 4.9.4). `lemke_exact` runs the same algorithm on the data as given
(every double is a rational number) with python-flint's exact rationals: each pivot is exact,
each tie is decided exactly. It is the fall-back of lcp.lemke when the float run cycles or
ends on a ray that proves nothing (small n only: the entries' sizes grow with the pivots).

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
