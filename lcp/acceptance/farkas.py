"""Certificates of infeasibility: the LCP has no solution because it has no feasible point.

Farkas's lemma: {z >= 0 : M z + q >= 0} is empty iff some y >= 0 has M^T y <= 0 and q^T y < 0
(then 0 <= y^T (M z + q) = (M^T y)^T z + q^T y < 0 for every z >= 0, a contradiction). Such a y
is found by HiGHS on the *equilibrated* problem (lcp.scaling: M~ = R M C, q~ = R q), as

    min q~^T y   subject to   M~^T y <= 0,   sum(y) = 1,   y >= 0,                      (1)

and it is checked, not taken from the solver. First in floating point: with g = M~^T y and gap
-q~^T y > 0, every feasible z~ obeys gap <= max(g, 0)^T z~, so no feasible point has
|z~|_1 < radius = gap / max(g_+). That bounds the size of feasible points but proves no
infeasibility: float data whose M^T y = 0 holds only to rounding may have a solution just
beyond the radius (a P-matrix singular to working precision does: the bench's first
"infeasible" sets had |z| ~ 1e16 solutions behind float certificates of radius 9e14). So the
status "infeasible" needs the exact check below; a certificate that passes only the float test
(gap >= GAP, radius >= RADIUS, and HiGHS finds {z~ >= 0, M~ z~ + q~ >= 0} infeasible) is kept
as evidence (`Farkas.exact` False) and said, never reported as "infeasible" (lcp.trust).
y maps back to the user's problem as R y~ (the sign conditions are invariant under positive
scalings). When (1)'s y leaves HiGHS's tolerance in M~^T y, it is projected onto the active
constraints (`_polish`), and failing that the most robust certificate (`_interior`, margin
t > 0) is tried.

**Exact check.** Every candidate that the float test does not reject for a wrong sign is
checked in exact rational arithmetic on the data as stored (each double is a rational
number; the equilibration's factors are powers of 2, so M~ and q~ are exact too):
`exact_certificate` tries y itself, y as small fractions, and (n <= EXACT_MAX_N) a rational
y >= 0 on y's support with the nearly active rows of M~^T y made exactly 0 (python-flint's
exact row reduction, free unknowns set to y's values as small fractions); it checks y >= 0,
M^T y <= 0, q^T y < 0 exactly. Such a y proves that the LCP *as stored* has no feasible point:
no tolerance and no radius are involved, and the LP's primal check is not needed. Beyond
EXACT_DIRECT_MAX_N unknowns no exact check is made, so no "infeasible" is claimed.

A P-matrix LCP always has a solution, so it never gets an exact certificate (a float one only
when its solution is beyond `radius` in the equilibrated units, i.e. M is singular to working
precision).
Copositive-plus M (e.g. M + M^T PSD): a feasible LCP is solvable (Lemke's theorem, Cottle, Pang
& Stone Thm 4.4.13), so infeasibility of the LCP is exactly this certificate.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from .scaling import Equilibration

#: Least q~^T y (sum y = 1, |q~|_inf ~ 1) a certificate must reach.
GAP = 1e-7
#: Least radius (equilibrated units, |M~|_max ~ 1) inside which no feasible point may exist:
#: 1 / (10 eps) ~ 4.5e14. A matrix that is P beyond rounding (lambda_min of the symmetric part
#: > 100 n eps) has its solution at |z~|_1 <= sqrt(n) / (100 eps), inside this radius for
#: n <= 100, so it cannot be certified; a smaller radius would "prove" solvable LCPs whose
#: solution is merely huge (e.g. |z~| ~ 1e16 for cond(M) ~ 1e16) infeasible.
RADIUS = 0.1 / np.finfo(float).eps
#: Largest n for the exact row reduction onto y's active rows (rational arithmetic, O(n^3)).
EXACT_MAX_N = 200
#: Largest n for the exact check of y itself (n^2 rational products).
EXACT_DIRECT_MAX_N = 1000
_HIGHS = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


@dataclass
class Farkas:
    """A checked certificate: y >= 0 (user units) with M^T y <= 0 and q^T y < 0 (to rounding)."""

    y: np.ndarray
    gap: float  # -q~^T y~ with sum y~ = 1
    radius: float  # no feasible z~ with |z~|_1 below this (equilibrated units)
    exact: bool = False  # checked in exact rational arithmetic (then radius = inf)

    @property
    def how(self) -> str:
        if self.exact:
            return (f"checked in exact rational arithmetic: M^T y <= 0 and q^T y < 0 hold "
                    f"exactly, gap {self.gap:.3g}")
        return f"gap {self.gap:.3g}, no feasible point within radius {self.radius:.3g}"

    def as_info(self) -> dict:
        return {"farkas": self.y, "farkas_gap": self.gap, "farkas_radius": self.radius,
                "farkas_exact": self.exact}


def check_certificate(eq: Equilibration, y_tilde: np.ndarray) -> Farkas | None:
    """Check a candidate y~ >= 0 for the equilibrated problem; None if it proves nothing."""
    y = np.maximum(np.asarray(y_tilde, dtype=float), 0.0)
    total = float(y.sum())
    if not np.isfinite(total) or total <= 0:
        return None
    y = y / total
    g = eq.M.T @ y
    gap = -float(eq.q @ y)
    slack = float(np.max(np.maximum(g, 0.0)))
    radius = np.inf if slack == 0 else gap / slack
    if not gap > 0:
        return None
    exact = exact_certificate(eq, y)
    if exact is not None or not (gap >= GAP and radius >= RADIUS):
        return exact
    return Farkas(y=y * eq.r / float(np.sum(y * eq.r)), gap=gap, radius=float(radius))


def _float(x) -> float:
    """The double nearest a python-flint rational (numerator over denominator: Python's int
    division rounds correctly; python-flint < 0.7's fmpq has no __float__)."""
    return int(x.p) / int(x.q)


def _q(x: float):
    from flint import fmpq  # a dependency (pyproject); imported on first use

    f = Fraction(float(x))
    return fmpq(f.numerator, f.denominator)


def exact_certificate(eq: Equilibration, y: np.ndarray, active_tol: float = 1e-9
                      ) -> Farkas | None:
    """A Farkas certificate near the float y (sum y = 1, equilibrated units), checked in exact
    rational arithmetic (module doc), or None. Candidates: y itself, y as small fractions, and
    the exact solution of {(M~^T y)_J = 0 on the rows J that y nearly makes active, sum y = 1}
    on y's support with the free unknowns at y's values (as small fractions)."""
    n = y.size
    if n > EXACT_DIRECT_MAX_N:
        return None
    from flint import fmpq, fmpq_mat

    MT = fmpq_mat(n, n, [_q(v) for v in eq.M.T.ravel()])
    qv = [_q(v) for v in eq.q]
    small = [fmpq(Fraction(float(v)).limit_denominator(10**6).numerator,
                  Fraction(float(v)).limit_denominator(10**6).denominator) for v in y]
    cands = [[_q(v) for v in y], small]
    g = eq.M.T @ y
    S = np.flatnonzero(y > 1e-12 * y.max())
    J = np.flatnonzero(g > -active_tol)
    if S.size and J.size and n <= EXACT_MAX_N:
        cands.append(_active_solution(MT, S, J, small, n))
    for cand in cands:
        if cand is None or any(v < 0 for v in cand):
            continue
        yv = fmpq_mat(n, 1, cand)
        if not all(v <= 0 for v in (MT * yv).entries()):
            continue
        qty = sum((qi * yi for qi, yi in zip(qv, cand)), fmpq(0))
        if qty >= 0:
            continue
        total = sum(cand, fmpq(0))
        yf = np.array([_float(v / total) for v in cand])
        gap = -_float(qty / total)
        return Farkas(y=yf * eq.r / float(np.sum(yf * eq.r)), gap=gap, radius=np.inf,
                      exact=True)
    return None


def _active_solution(MT, S: np.ndarray, J: np.ndarray, start: list, n: int):
    """The rational y with support in S, (M^T y)_J = 0, sum y = 1, free unknowns at `start`
    (None if the system is inconsistent)."""
    from flint import fmpq, fmpq_mat

    rows = [[MT[int(j), int(i)] for i in S] + [fmpq(0)] for j in J]
    rows.append([fmpq(1)] * S.size + [fmpq(1)])
    A = fmpq_mat(len(rows), S.size + 1, [v for r in rows for v in r])
    R, rank = A.rref()
    pivots, col = [], 0
    for r in range(rank):
        while col <= S.size and R[r, col] == 0:
            col += 1
        if col == S.size:  # a pivot in the right-hand side: inconsistent
            return None
        pivots.append(col)
        col += 1
    free = [c for c in range(S.size) if c not in pivots]
    ys = [fmpq(0)] * S.size
    for c in free:
        ys[c] = start[int(S[c])]
    for r, c in enumerate(pivots):
        ys[c] = R[r, S.size] - sum((R[r, f] * ys[f] for f in free), fmpq(0))
    y = [fmpq(0)] * n
    for c, i in enumerate(S):
        y[int(i)] = ys[c]
    return y


def _polish(eq: Equilibration, y: np.ndarray) -> np.ndarray:
    """HiGHS's y meets M~^T y <= 0 to its feasibility tolerance (1e-10), far above rounding:
    on the support S of y and the constraints J it makes (nearly) active, project y onto
    {(M~^T)_JS y_S = 0} (one least-squares correction, twice) so that the slack is rounding."""
    y = np.maximum(np.asarray(y, dtype=float), 0.0)
    for _ in range(2):
        g = eq.M.T @ y
        S = np.flatnonzero(y > 1e-12 * y.max())
        J = np.flatnonzero(g > -1e-8)
        if S.size == 0 or J.size == 0:
            break
        A = eq.M.T[np.ix_(J, S)]
        step, *_ = np.linalg.lstsq(A, A @ y[S], rcond=None)
        y[S] = np.maximum(y[S] - step, 0.0)
    return y


def _linprog(*args, **kwargs):
    from scipy.optimize import linprog  # loaded on first use: `import rigidlcp.lcp` stays cheap

    return linprog(*args, **kwargs)


def _interior(eq: Equilibration) -> np.ndarray:
    """The most robust certificate: max t with M~^T y + t 1 <= 0, q~^T y + t <= 0, sum y = 1,
    y >= 0, t <= 1. When t > 0 every inequality holds with margin t, far above HiGHS's
    tolerance, so the floating-point check sees M~^T y < 0 (infinite radius)."""
    n = eq.q.size
    A = np.vstack([np.column_stack([eq.M.T, np.ones(n)]), np.r_[eq.q, 1.0][None, :]])
    c = np.zeros(n + 1)
    c[-1] = -1.0
    res = _linprog(c, A_ub=A, b_ub=np.zeros(n + 1), A_eq=np.r_[np.ones(n), 0.0][None, :],
                  b_eq=[1.0], bounds=[(0, None)] * n + [(None, 1.0)], method="highs",
                  options=_HIGHS)
    if res.status != 0 or res.x is None or res.x[-1] <= 0:
        return np.zeros(n)
    return res.x[:n]


def find_certificate(eq: Equilibration, candidate: np.ndarray | None = None) -> Farkas | None:
    """A checked Farkas certificate of the equilibrated LCP (try `candidate`, in user units,
    first), or None when none exists (the LCP has feasible points) or none passes the check."""
    n = eq.q.size
    found = None
    if candidate is not None:
        cand = np.asarray(candidate, dtype=float)
        if cand.shape == (n,) and np.all(np.isfinite(cand)):
            found = check_certificate(eq, cand / eq.r)
    if found is None:
        res = _linprog(eq.q, A_ub=eq.M.T, b_ub=np.zeros(n), A_eq=np.ones((1, n)), b_eq=[1.0],
                      bounds=[(0, None)] * n, method="highs", options=_HIGHS)
        if res.status != 0 or res.x is None:
            return None
        found = check_certificate(eq, res.x)
        if found is None:
            found = check_certificate(eq, _polish(eq, res.x))
        if found is None:
            found = check_certificate(eq, _interior(eq))
        if found is None:
            return None
    if found.exact:  # a proof in exact arithmetic: no LP has a say
        return found
    primal = _linprog(np.zeros(n), A_ub=-eq.M, b_ub=eq.q, bounds=[(0, None)] * n,
                     method="highs", options=_HIGHS)
    if primal.status != 2:  # HiGHS finds feasible points (or cannot decide): no claim
        return None
    return found


def numerically_psd(S: np.ndarray) -> bool:
    """Is the symmetric S positive semidefinite to rounding? Cholesky of S + delta I with
    delta = 100 n eps ||S||_F succeeds iff (to rounding) lambda_min(S) > -delta. With S = M + M^T
    it tests a sufficient condition for M to be copositive-plus."""
    n = S.shape[0]
    delta = 100 * n * np.finfo(float).eps * max(float(np.linalg.norm(S)), 1e-300)
    try:
        np.linalg.cholesky(S + delta * np.eye(n))
    except np.linalg.LinAlgError:
        return False
    return True
