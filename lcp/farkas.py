"""Certificates of infeasibility: the LCP has no solution because it has no feasible point.

Farkas's lemma: {z >= 0 : M z + q >= 0} is empty iff some y >= 0 has M^T y <= 0 and q^T y < 0
(then 0 <= y^T (M z + q) = (M^T y)^T z + q^T y < 0 for every z >= 0, a contradiction). Such a y
is found by HiGHS on the *equilibrated* problem (lcp.scaling: M~ = R M C, q~ = R q), as

    min q~^T y   subject to   M~^T y <= 0,   sum(y) = 1,   y >= 0,                      (1)

and it is checked in floating point, not taken from the solver: with g = M~^T y and gap
-q~^T y > 0, every feasible z~ obeys gap <= max(g, 0)^T z~, so no feasible point has
|z~|_1 < radius = gap / max(g_+). The certificate is accepted when gap >= GAP (the data are
O(1) after equilibration) and radius >= RADIUS ~ 4.5e14 (rounding of M~^T y then cannot hide a
feasible point of reasonable size), and when HiGHS also finds the primal feasibility problem
{z~ >= 0, M~ z~ + q~ >= 0} infeasible. Below that radius the float data cannot tell "no
solution" from "a solution of size ~1/eps": no claim is made (the status says so). y maps back
to the user's problem as R y~ (the sign conditions are invariant under positive scalings).
When (1)'s y leaves HiGHS's tolerance in M~^T y, it is projected onto the active constraints
(`_polish`), and failing that the most robust certificate (`_interior`, margin t > 0) is tried.

A P-matrix LCP always has a solution, so it never gets a certificate (unless its solution is
beyond `radius` in the equilibrated units, i.e. M is singular to working precision).
Copositive-plus M (e.g. M + M^T PSD): a feasible LCP is solvable (Lemke's theorem, Cottle, Pang
& Stone Thm 4.4.13), so infeasibility of the LCP is exactly this certificate.
"""

from __future__ import annotations

from dataclasses import dataclass

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
_HIGHS = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


@dataclass
class Farkas:
    """A checked certificate: y >= 0 (user units) with M^T y <= 0 and q^T y < 0 (to rounding)."""

    y: np.ndarray
    gap: float  # -q~^T y~ with sum y~ = 1
    radius: float  # no feasible z~ with |z~|_1 below this (equilibrated units)

    def as_info(self) -> dict:
        return {"farkas": self.y, "farkas_gap": self.gap, "farkas_radius": self.radius}


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
    if not (gap >= GAP and radius >= RADIUS):
        return None
    return Farkas(y=y * eq.r / float(np.sum(y * eq.r)), gap=gap, radius=float(radius))


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
