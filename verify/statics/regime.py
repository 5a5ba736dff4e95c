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
K = A T must satisfy K^T y <= 0 while b . y > 0, so that no w >= 0 gives K w = b. It is checked
in floating point with a margin (`check`).

When they have a solution (a witness, checked), the regime is possible for the translations;
whether the event's LCP selects such a solution is then the selection's business (the tangential
complementarity of Eq. 2.7 is not part of this test): `regime` says "possible", not "kept".
"""

from __future__ import annotations

from dataclasses import dataclass

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
    return certificate(K, b)


def certificate(K: sp.csr_matrix, b: np.ndarray) -> Regime:
    """y with K^T y <= 0 and b . y > 0 (no w >= 0 solves K w = b), found by an LP in the box
    |y| <= 1, then checked (`check`)."""
    res = linprog(-b, A_ub=K.T, b_ub=np.zeros(K.shape[1]), bounds=(-1, 1), method="highs")
    if res.status != 0 or -res.fun <= 0:
        return Regime(None, message="undecided: no equilibrium found and no certificate")
    return check(K, b, res.x)


#: A certificate must exclude every w with sum w below this many times sum |b| (the loads).
RADIUS_LOADS = 1e9


def check(K: sp.csr_matrix, b: np.ndarray, y: np.ndarray) -> Regime:
    """The Farkas certificate y checked in floating point. If some w >= 0 solved K w = b, then
    b . y = sum_j w_j K_j . y <= max(0, max_j K_j . y) sum w: with gap = b . y > 0 and
    worst = max_j K_j . y, every solution has sum w >= gap / worst (infinite when worst <= 0).
    Accepted when that radius exceeds RADIUS_LOADS x sum |b|: no physical forces remain."""
    gap = float(b @ y)
    worst = float(np.max(K.T @ y, initial=0.0))
    radius = np.inf if worst <= 0 else gap / worst
    loads = float(np.sum(np.abs(b))) or 1.0
    if gap > 0 and radius >= RADIUS_LOADS * loads:
        return Regime(False, y=y, margin=radius,
                      message="no forces keep the disks in place (Farkas certificate checked: "
                      f"b.y = {gap:.3g} > 0, max K^T y = {worst:.2g}): every solution of the "
                      "event leaves the no-displacement regime")
    return Regime(None, message="undecided: the certificate fails its check")
