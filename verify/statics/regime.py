"""Does an event admit the paper's regime (no particle displacement)? A checked yes or no.

The paper's dynamics (Sec. II) keeps every disk in place: only the rotations evolve. At an
event with tangential states s (models.State: +1/-1 sliding, 0 candidate), the disks stay in
place only if some contact forces lambda = [R; S] hold every disk's *translation* at rest:

    H_x^T lambda + f_x = 0        (the vx, vy rows of Newton-Euler, models.dynamics; 2p rows)
    R >= 0,   S = -s mu R on a sliding contact (Eq. 2.10),   |S| <= mu R on a candidate
    (Eq. 2.7),   S = 0 where mu = 0.

(The torques are free: they set the angular accelerations.) Every solution of the event's LCP
with a_n = 0 on every contact and translations at rest satisfies these, so when they have no
solution *every* solution of the event leaves the regime: the detachment is the physics of the
packing under those sliding directions, not a choice of the solver. That is proved by a Farkas
certificate y (2p, a virtual translation of the disks): with lambda = T w, w >= 0 (cone
coordinates: R = w, S = -s mu w when sliding; u = mu R - S, v = mu R + S for a candidate),
K = A T must satisfy K^T y <= 0 while b . y > 0, so that no w >= 0 gives K w = b. It is first
checked in floating point with a margin, then proved in exact rational arithmetic on the data
as stored (`check`: every double is a fraction; y as found, or its small-fraction form): only
an exactly checked y makes the answer "no". A y that passes only in floating point bounds the
size of any forces (its radius) but proves nothing, and leaves the answer undecided with that
evidence (as lcp.acceptance.farkas and verify.statics.farkas do).

When they have a solution (a witness, checked), the regime is possible for the translations;
whether the event's LCP selects such a solution is then the selection's business (the tangential
complementarity of Eq. 2.7 is not part of this test): `regime` says "possible", not "kept".
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

from rigidlcp import models


@dataclass
class Regime:
    """exists: True (a checked witness lam), False (a checked certificate y) or None
    (undecided: the LP failed or its answer did not pass the check). margin: for a certificate,
    b . y over the size of its terms (> 0); for a witness, the balance residual."""

    exists: bool | None
    lam: np.ndarray | None = None
    y: np.ndarray | None = None
    margin: float = float("nan")
    message: str = ""

    def text(self) -> str:
        return self.message


def _cone(system: models.System, s: np.ndarray) -> sp.csr_matrix:
    """T (2c x nw): lambda = T w, w >= 0 spans the contact laws of the states s (module doc)."""
    c, mu = system.c, np.asarray(system.mu, dtype=float)
    rows, cols, vals, col = [], [], [], 0
    for a in range(c):
        if mu[a] == 0:  # R = w, S = 0
            rows += [a]
            cols += [col]
            vals += [1.0]
            col += 1
        elif s[a] != 0:  # sliding: R = w, S = -s mu w
            rows += [a, c + a]
            cols += [col, col]
            vals += [1.0, -float(s[a]) * mu[a]]
            col += 1
        else:  # candidate: R = (u + v) / 2 mu, S = (v - u) / 2
            rows += [a, c + a, a, c + a]
            cols += [col, col, col + 1, col + 1]
            vals += [0.5 / mu[a], -0.5, 0.5 / mu[a], 0.5]
            col += 2
    return sp.csr_matrix((vals, (rows, cols)), shape=(2 * c, col))


def regime(system: models.System, state: models.State, tol: float = 1e-9) -> Regime:
    """Whether some contact forces keep every disk's translation at rest at the event of
    `state` (module doc): a checked witness, a checked Farkas certificate, or undecided."""
    p = system.p
    dyn = models.Dynamics(system)
    A = sp.csr_matrix(dyn.H.T)[: 2 * p]  # the vx, vy rows of H^T
    b = -dyn.f[: 2 * p]
    s = np.asarray(state.s, dtype=int)
    T = _cone(system, s)
    K = sp.csr_matrix(A @ T)
    scale = float(np.max(np.abs(b), initial=0.0)) or 1.0
    res = linprog(np.zeros(K.shape[1]), A_eq=K, b_eq=b, bounds=(0, None), method="highs")
    if res.status == 0:
        lam = T @ res.x
        resid = float(np.max(np.abs(A @ lam - b), initial=0.0))
        terms = float(np.max(abs(A) @ np.abs(lam) + np.abs(b), initial=0.0))
        if resid <= tol * max(terms, scale) and np.all(res.x >= -tol * max(terms, scale)):
            return Regime(True, lam=lam, margin=resid,
                          message="the regime is possible: forces with R >= 0 and the sliding "
                          f"laws hold every translation (balance residual {resid:.2g})")
        return Regime(None, message=f"undecided: the witness fails its check ({resid:.2g})")
    return certificate(K, b, A, T)


def certificate(K: sp.csr_matrix, b: np.ndarray, A: sp.csr_matrix | None = None,
                T: sp.csr_matrix | None = None) -> Regime:
    """y with K^T y <= 0 and b . y > 0 (no w >= 0 solves K w = b), found by an LP in the box
    |y| <= 1, then checked (`check`; exactly on A and T, K = A T, when given)."""
    res = linprog(-b, A_ub=K.T, b_ub=np.zeros(K.shape[1]), bounds=(-1, 1), method="highs")
    if res.status != 0 or -res.fun <= 0:
        return Regime(None, message="undecided: no equilibrium found and no certificate")
    return check(K, b, res.x, A, T)


#: A certificate must exclude every w with sum w below this many times sum |b| (the loads).
RADIUS_LOADS = 1e9


def check(K: sp.csr_matrix, b: np.ndarray, y: np.ndarray, A: sp.csr_matrix | None = None,
          T: sp.csr_matrix | None = None) -> Regime:
    """The Farkas certificate y checked in floating point, then exactly. If some w >= 0 solved
    K w = b, then b . y = sum_j w_j K_j . y <= max(0, max_j K_j . y) sum w: with gap = b . y > 0
    and worst = max_j K_j . y, every solution has sum w >= gap / worst (infinite when worst <=
    0). A y whose radius reaches RADIUS_LOADS x sum |b| is then checked in rationals
    (`exact_farkas`, on A and T when given: K = A T as stored, not its rounded product); only
    then "no" (exists False). Otherwise undecided, y and its radius kept as evidence."""
    gap = float(b @ y)
    worst = float(np.max(K.T @ y, initial=0.0))
    radius = np.inf if worst <= 0 else gap / worst
    loads = float(np.sum(np.abs(b))) or 1.0
    if not (gap > 0 and radius >= RADIUS_LOADS * loads):
        return Regime(None, message="undecided: the certificate fails its check")
    exact = exact_farkas(K if A is None else A, b, y, None if A is None else T)
    if exact is None:
        return Regime(None, y=y, margin=radius,
                      message="undecided: a Farkas certificate passes in floating point (b.y = "
                      f"{gap:.3g} > 0, forces would exceed {radius:.3g} x the loads) but not in "
                      "exact arithmetic: that the event leaves the no-displacement regime is "
                      "not proved")
    return Regime(False, y=exact, margin=radius,
                  message="no forces keep the disks in place (Farkas certificate checked in "
                  f"exact arithmetic: b.y = {gap:.3g} > 0, K^T y <= 0): every solution of the "
                  "event leaves the no-displacement regime")


def _columns_dot(C: sp.csc_matrix, v: dict[int, Fraction]) -> dict[int, Fraction]:
    """C^T v in rationals, C's doubles read exactly (v and the result by their nonzeros)."""
    out: dict[int, Fraction] = {}
    for j in range(C.shape[1]):
        lo, hi = C.indptr[j], C.indptr[j + 1]
        acc = sum((Fraction(float(c)) * v[int(i)] for i, c in zip(C.indices[lo:hi], C.data[lo:hi])
                   if int(i) in v), Fraction(0))
        if acc:
            out[j] = acc
    return out


def _exact_ok(A: sp.csr_matrix, b: np.ndarray, T: sp.csr_matrix | None,
              yq: dict[int, Fraction]) -> bool:
    """b . y > 0 and (A T)^T y <= 0 in rationals (y given on its support yq)."""
    if sum((Fraction(float(b[i])) * v for i, v in yq.items()), Fraction(0)) <= 0:
        return False
    u = _columns_dot(sp.csc_matrix(A), yq)  # A^T y
    K_y = u if T is None else _columns_dot(sp.csc_matrix(T), u)  # T^T A^T y
    return all(v <= 0 for v in K_y.values())


#: Largest support of y (2 unknowns per disk it moves) for the exact row reduction of
#: `exact_farkas` (dense, in rationals): ~3 CPU s at 100 disks (about 200 unknowns), 235 CPU s
#: at 300 (a spun 300-disk pile, 2026-11-28); beyond it a certificate that passes only in
#: floating point leaves the regime undecided.
EXACT_SUPPORT = 200


def exact_farkas(A: sp.csr_matrix, b: np.ndarray, y: np.ndarray,
                 T: sp.csr_matrix | None = None) -> np.ndarray | None:
    """A y that proves in exact rationals that no w >= 0 solves (A T) w = b (T None: A w = b):
    b . y > 0 and (A T)^T y <= 0, with A, T, b the stored doubles read as fractions. Tried: y
    as found; then, on y's support (entries above 1e-12 max|y|; y is 0 elsewhere, so the
    columns that do not touch it contribute 0), the rational y that makes the nearly active
    columns exactly active, and y's small-fraction form (verify.statics.farkas.first_exact, as
    forceset's certificates). None when none passes."""
    from .farkas import first_exact, rational, small_rational

    y = np.asarray(y, dtype=float)
    top = float(np.max(np.abs(y), initial=0.0))
    if not top > 0 or not np.all(np.isfinite(y)):
        return None
    A, b = sp.csr_matrix(A), np.asarray(b, dtype=float)
    plain = {int(i): Fraction(float(y[i])) for i in np.flatnonzero(y)}
    if _exact_ok(A, b, T, plain):
        return y
    y = y / top
    S = np.flatnonzero(np.abs(y) > 1e-12)
    if S.size > EXACT_SUPPORT:
        return None
    K = sp.csc_matrix(A[S] @ T if T is not None else A[S])
    touched = np.flatnonzero(np.diff(K.indptr))
    At = sp.csc_matrix(A[S])  # columns of A on the support rows
    Tc = sp.csc_matrix(T) if T is not None else None
    rows = []
    for j in touched:  # column j of (A T) on the support, exactly
        col: dict[int, object] = {}
        terms = (zip(Tc.indices[Tc.indptr[j]:Tc.indptr[j + 1]],
                     Tc.data[Tc.indptr[j]:Tc.indptr[j + 1]]) if Tc is not None
                 else [(j, 1.0)])
        for k, t in terms:
            tq = rational(t)
            for i, a in zip(At.indices[At.indptr[k]:At.indptr[k + 1]],
                            At.data[At.indptr[k]:At.indptr[k + 1]]):
                col[int(i)] = col.get(int(i), 0) + tq * rational(a)
        rows.append([col.get(i, rational(0.0)) for i in range(S.size)])
    g = K[:, touched].T @ y[S]
    found = first_exact(rows, [rational(-v) for v in b[S]], np.flatnonzero(g > -1e-9),
                        [small_rational(v) for v in y[S]])
    if found is None:
        return None
    out = np.zeros(len(y))
    out[S] = [int(v.p) / int(v.q) for v in found[0]]
    return out / float(np.max(np.abs(out)))
