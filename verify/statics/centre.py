"""A point of P deep in its relative interior, by a primal-dual Newton method with a sparse
direct solve (an alternative to HiGHS's interior-point method, `model.interior_point`).

In the cone coordinates of `model.cone_lp` (w >= 0: u = mu R - S, v = mu R + S at a
frictional contact, R at a frictionless one; lambda = T w) P is {w : K w = b, w >= 0}, with
K = A T. The weighted analytic centre

    w(tau) = argmin { 1 . w - tau sum_j log w_j : K w = b }

exists (and is unique) exactly when P has a point with every w_j > 0: the term 1 . w makes
every level set bounded even when P is unbounded (a recession direction d >= 0, d != 0, has
1 . d > 0), so no box is needed. It is the point of the central path of min 1 . w over P
(Wright, "Primal-Dual Interior-Point Methods", SIAM 1997, ch. 1 and 5) at w_j z_j = tau, with
z = 1 - K^T y > 0; it is found by Newton's method on those equations from an infeasible
start, each step one sparse factorization of the normal matrix K diag(w / z) K^T (SuperLU,
minimum-degree ordering on its symmetric pattern: 0.3 s at 10^4 disks against the tens of
seconds of HiGHS's iterative normal-equation solver, docs/packings.md, Scale). tau is
fixed at one weight, never driven to 0, so the point stays well inside P.

Nothing here is a verdict: when P has an implicit equality (some w_j = 0 on all of P) there is
no centre: the iteration stops (w_j -> 0 and z_j -> inf there, the normal matrix singular or
the duals diverging), or is stopped after STALL steps once a coordinate is below SMALL. Then
local certificates (verify.statics.implicit: exactly checked virtual motions proving w_j = 0
on all of P) are sought around the coordinates below SUSPECT, and the iteration runs again
on the face where the coordinates below SMALL and the proved ones are fixed at 0 (at most
FACE_TRIES faces, each STALL steps, the next one also fixing the small coordinates of the
last); when they are exactly the implicit equalities, that face has a centre, a point of the
relative interior of P; else there is no point (None). The callers check every point
returned against P (`StaticProblem.admissible`) and decide the rows from its slacks as from
any other point of P (a coordinate fixed at 0 leaves its row to verify.statics.hull, which
proves it by a certificate or, failing that, by the slack LPs).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from .implicit import proved_cone
from .model import StaticProblem, cone_lp

#: Newton steps before giving up (from the infeasible start; the 10^4-disk packings of
#: docs/packings.md's Scale need 8-21, its falling 10^4-disk pile stops after 32).
MAX_STEPS = 80
#: Dual or primal iterates beyond this (in weights) mean there is no centre.
DIVERGED = 1e12
#: A coordinate below this (in weights) where the iteration stops is taken for an implicit
#: equality, for one more try on the face where it is 0.
SMALL = 1e-6
#: Newton steps after which the first run gives up when a coordinate is below SMALL (the
#: packings with a centre in docs/packings.md's Scale are centred after 8-21 steps).
STALL = 24
#: Coordinates below this (in weights) where the iteration stops are suspected of being
#: implicit equalities: certificates are sought around them (never taken on suspicion).
SUSPECT = 0.1
#: Most contacts around which certificates are sought for the face (each a few small LPs; a
#: P without points, whose iteration diverges everywhere, would otherwise cost thousands).
SUSPECTS = 300
#: Faces tried after the first run (each with the coordinates found 0 so far fixed at 0).
FACE_TRIES = 3
#: A centred point: every w_j z_j within this factor of tau.
CENTRED = 4.0


def analytic_centre(prob: StaticProblem) -> np.ndarray | None:
    """lambda = T w(tau) (module docstring), tau = the largest disk weight, or None when the
    iteration does not reach a centred point of P with balance residual below 1e-12 of the
    balance's terms (no strictly positive w: an implicit equality; or trouble, e.g. balance
    rows that are dependent without being zero, whose normal matrix is singular). The caller
    checks the point."""
    _, T, _ = cone_lp(prob)
    K = sp.csr_matrix(prob.A @ T)
    s = prob.scale
    b = np.asarray(prob.b, dtype=float) / s  # in weights: tau = 1
    rows = np.diff(K.indptr) > 0  # e.g. the torque rows of frictionless disks: 0 = 0
    if np.any(b[~rows] != 0):
        return None  # 0 = b_i != 0: P is empty (a Farkas certificate says so, not this)
    K, b = K[rows], b[rows]
    w, last = _newton(K, b, stall=STALL)
    zero = np.zeros(K.shape[1], dtype=bool)
    for _ in range(FACE_TRIES):
        if w is not None or last is None:
            break
        # the coordinates that went to 0 are likely implicit equalities; checked local
        # certificates (verify.statics.implicit) around the coordinates below SUSPECT prove
        # some the iteration had not yet driven below SMALL: the centre of the face where
        # they are all 0
        small = zero | (last < SMALL)
        suspects = zero | (last < SUSPECT)
        small |= _proved(prob, suspects if suspects.sum() <= 2 * SUSPECTS else small)
        if small.sum() == zero.sum() or small.all():
            break
        zero = small
        keep = ~zero
        # a face without its own implicit equalities is centred within STALL steps (the
        # faces of docs/packings.md's arrays, 4-12); else its small coordinates are suspects
        face, last_face = _newton(sp.csr_matrix(K[:, keep]), b, reg=1e-12, steps=STALL)
        if face is not None:
            w = np.zeros(keep.size)
            w[keep] = face
        elif last_face is not None:
            last = np.zeros(keep.size)
            last[keep] = last_face
    if w is None and last is not None and np.any(last < SMALL):
        w, _ = _newton(K, b)  # the first run stopped early: the whole run, as before
    return None if w is None else T @ (w * s)


def _proved(prob: StaticProblem, zero: np.ndarray) -> np.ndarray:
    """The cone coordinates (u (k), v (k), then R of the frictionless contacts) that checked
    certificates (verify.statics.implicit) prove to be 0 on all of P, sought around the
    contacts of the coordinates `zero`."""
    c, k = prob.c, prob.fric.size
    plain = np.flatnonzero(prob.mu == 0)
    cone_row = np.r_[prob.fric, c + np.arange(k), plain]  # of each coordinate
    target = np.zeros(c + k, dtype=bool)
    target[cone_row[zero]] = True
    return proved_cone(prob, target, SUSPECTS)[cone_row]


def _newton(K: sp.csr_matrix, b: np.ndarray, reg: float = 0.0, stall: int | None = None,
            steps: int = MAX_STEPS) -> tuple[np.ndarray | None, np.ndarray | None]:
    """(w(1) for {K w = b, w >= 0} and the cost 1 (module docstring), None), or (None, the
    last iterate w) when there is no centred point. reg > 0 adds
    reg times the largest diagonal entry to the normal matrix's diagonal (on a face, K's rows
    may be dependent: the steps are then inexact, the residual test unchanged). stall: give
    up after that many steps when some coordinate is below SMALL (a likely implicit equality:
    the 2483-disk array of docs/packings.md had all 34 of its implicit coordinates below
    SMALL after 21 steps and stopped only after 60); steps: the most Newton steps."""
    m, n = K.shape
    KT = sp.csr_matrix(K.T)
    w, y, z = np.ones(n), np.zeros(m), np.ones(n)
    size = np.abs(K) @ np.ones(n) + np.abs(b) + 1.0  # the balance's terms at w ~ 1
    for step in range(steps):
        if stall is not None and step >= stall and np.any(w < SMALL):
            return None, w
        rp = b - K @ w
        rd = 1.0 - KT @ y - z
        rc = 1.0 - w * z
        feasible = np.all(np.abs(rp) <= 1e-12 * (np.abs(K) @ w + size))
        if feasible and np.max(np.abs(rd)) <= 1e-9 and np.all(w * z <= CENTRED) \
                and np.all(w * z >= 1.0 / CENTRED):
            return w, None
        d = w / z
        N = K @ sp.diags(d) @ KT
        if reg:
            N = N + reg * float(N.diagonal().max()) * sp.eye(m)
        try:
            lu = splu(sp.csc_matrix(N), permc_spec="MMD_AT_PLUS_A",
                      diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        except RuntimeError:  # singular: K has dependent rows, or d degenerated
            return None, w
        dy = lu.solve(rp - K @ ((rc - w * rd) / z))
        dz = rd - KT @ dy
        dw = (rc - w * dz) / z
        if not (np.all(np.isfinite(dy)) and np.all(np.isfinite(dw))):
            return None, w
        if np.max(np.abs(y)) > DIVERGED or np.max(w) > DIVERGED:
            # y -> inf: P empty or an implicit equality (its Farkas-like ray)
            return None, w
        w = w + _step(w, dw) * dw
        a = _step(z, dz)
        y, z = y + a * dy, z + a * dz
    return None, w


def _step(x: np.ndarray, dx: np.ndarray) -> float:
    """The longest step <= 1 keeping x + a dx > 0, shortened to 0.99 of the way to the
    boundary (fraction to the boundary)."""
    neg = dx < 0
    if not neg.any():
        return 1.0
    return float(min(1.0, 0.99 * np.min(-x[neg] / dx[neg])))
