"""Certificates of the implicit equalities of P (verify.statics.model): local virtual motions
that prove a cone inequality of P holds with equality on the whole set, checked exactly.

Take y (3p virtual velocities of the disks) whose relative velocities lie in the dual cone of
every contact, C y <= 0 (the cone rows of verify.statics.farkas), while gravity does no work,
b . y = 0 (e.g. a disk rolling away sideways). For every lambda in P (farkas's docstring),

    0 = b . y = lambda . H y = sum_a R_a g_n + S_a g_t
      = -sum over frictional contacts of (u (C y)_a + v (C y)_(c+n)) / (2 mu)
        - sum over frictionless ones of R (C y)_a,

with u = mu R - S >= 0 and v = mu R + S >= 0 (g = H y; (C y)_a = -g_n + mu g_t,
(C y)_(c+n) = -g_n - mu g_t). Every term is >= 0, so each is 0: a cone coordinate whose row
has (C y)_r < 0 vanishes on all of P. u = 0 is S = mu R on all of P, v = 0 is S = -mu R, both
(or R at a frictionless contact) R = 0. (In the cone coordinates of verify.statics.centre
this is K^T y >= 0 with b . y = 0, positive on the coordinates that vanish: the lead
docs/packings.md noted in the diverging duals of the centre's Newton iteration.)

As for the local Farkas certificates (verify.statics.local), y = 0 outside a set D of disks
is such a certificate when C_D y_D <= 0 on the rows of the contacts touching D and
b_D . y_D = 0. So for each contact with an undecided row, D starts as the contact's disks and
grows by rings of touching disks (at most RINGS, MAX_DISKS disks), each ring one small LP
(local.window_lp with target rows: min the sum of their (C y)_r, C_D y_D <= 0,
b_D . y_D = 0, |y_D| <= 1). An optimum below -GAP is shrunk to the disks it moves and checked
in rational arithmetic on the stored H, b, mu: the rows it makes nearly active and b . y = 0
made exactly active (free unknowns at the float y's values as small fractions), then
C y <= 0 and b . y = 0 exactly; every row with (C y)_r < 0 exactly is proved. A row no
certificate proves proves nothing: it goes to the slack LPs of verify.statics.hull.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .farkas import rational, small_rational, solve_homogeneous
from .local import Cone, window_lp, window_rows
from .model import StaticProblem

#: Rings of touching disks added to a contact's disks before giving up on it.
RINGS = 2
#: Largest window (disks).
MAX_DISKS = 60
#: A window LP's optimum must be below -GAP (|y| <= 1) to be checked.
GAP = 1e-9
#: Most contacts with undecided rows for which certificates are sought (each a few LPs).
MAX_CONTACTS = 2000


def gi_to_cone(prob: StaticProblem, r: int) -> list[int]:
    """The cone rows (farkas.cone_rows's numbering) whose coordinates vanish exactly when the
    inequality row r of hull's numbering (-R <= 0 for the c contacts, then S - mu R <= 0 and
    -S - mu R <= 0 for the k frictional ones) holds with equality."""
    c, k = prob.c, prob.fric.size
    if r < c:
        if prob.mu[r] == 0:
            return [r]
        n = int(np.searchsorted(prob.fric, r))
        return [r, c + n]  # R = 0 iff u = v = 0
    if r < c + k:
        return [int(prob.fric[r - c])]  # u = mu R - S
    return [c + r - c - k]  # v = mu R + S


def proved_rows(prob: StaticProblem, undecided: np.ndarray) -> np.ndarray:
    """The rows among `undecided` (hull's numbering, gi_to_cone) that a checked certificate
    (module docstring) proves to hold with equality on all of P."""
    out = np.zeros(undecided.size, dtype=bool)
    rows = np.flatnonzero(undecided)
    if rows.size == 0:
        return out
    target = np.zeros(prob.c + prob.fric.size, dtype=bool)
    for r in rows:
        target[gi_to_cone(prob, int(r))] = True
    proved = proved_cone(prob, target)
    for r in rows:
        out[r] = bool(np.all(proved[gi_to_cone(prob, int(r))]))
    return out


def proved_cone(prob: StaticProblem, target: np.ndarray, limit: int = MAX_CONTACTS
                ) -> np.ndarray:
    """The cone rows (farkas.cone_rows's numbering) proved to vanish on all of P by checked
    certificates (module docstring) sought around the contacts of the `target` rows: all of
    the target rows when it works, and any other row the certificates prove; none sought
    when the targets span more than `limit` contacts."""
    cone = Cone(prob)
    proved = np.zeros(cone.C.shape[0], dtype=bool)
    contacts = np.unique(cone.contact[target])
    if contacts.size == 0 or contacts.size > limit:
        return proved
    lat = prob.system.lattice
    disk = lat.j >= 0
    p = prob.p
    touch = sp.csr_matrix((np.ones(int(disk.sum())), (lat.i[disk], lat.j[disk])), shape=(p, p))
    touch = (touch + touch.T).tocsr()
    for a in contacts:
        mine = np.flatnonzero(target & (cone.contact == a))
        D = np.unique([int(lat.i[a])] + ([int(lat.j[a])] if lat.j[a] >= 0 else []))
        for ring in range(RINGS + 1):
            if np.all(proved[mine]):
                break
            if ring:
                inside = np.zeros(p, dtype=bool)
                inside[D] = True
                D = np.flatnonzero(inside | (touch @ inside > 0))
            if D.size > MAX_DISKS:
                break
            rows_D = cone.rows_of(D)
            t = rows_D[target[rows_D] & ~proved[rows_D]]
            if t.size == 0:
                break
            value, yD = window_lp(cone, D, t)
            if yD is not None and value < -GAP:
                proved |= exact_vanishing(cone, D, yD)
    return proved


def exact_vanishing(cone: Cone, D: np.ndarray, yD: np.ndarray,
                    active_tol: float = 1e-9) -> np.ndarray:
    """The cone rows proved to vanish on all of P by a rational y near yD (3|D|: u, v, w blocks
    of the disks D), checked exactly (module docstring): a boolean per cone row, all False when
    the check fails."""
    from flint import fmpq, fmpq_mat

    out = np.zeros(cone.C.shape[0], dtype=bool)
    k = D.size
    scale = float(np.max(np.abs(yD), initial=0.0))
    if scale == 0:
        return out
    blocks = yD.reshape(3, k) / scale
    moving = np.max(np.abs(blocks), axis=0) > 1e-9
    S = D[moving]
    ys = blocks[:, moving].reshape(-1)
    rows, cols = cone.rows_of(S), cone.cols_of(S)
    exact = window_rows(cone, rows, cols)
    bq = [rational(v) for v in cone.prob.b[cols]]
    g = cone.C[rows][:, cols] @ ys
    J = np.flatnonzero(g > -active_tol)
    A = fmpq_mat(J.size + 1, cols.size, [v for j in J for v in exact[int(j)]] + bq)
    y = solve_homogeneous(A, [small_rational(v) for v in ys])
    if y is None or sum((b * v for b, v in zip(bq, y)), fmpq(0)) != 0:
        return out
    Cy = [sum((e * v for e, v in zip(row, y)), fmpq(0)) for row in exact]
    if any(v > 0 for v in Cy):
        return out
    out[rows[[n for n, v in enumerate(Cy) if v < 0]]] = True
    return out
