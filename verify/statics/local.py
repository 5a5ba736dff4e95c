"""Local Farkas certificates: a cluster of disks that can move while all the others stay put.

A Farkas certificate (verify.statics.farkas) is a virtual motion y = (u, v, w per disk) under
which gravity does work, b . y < 0, while every contact's relative velocity g = H y lies in its
dual cone, g_n >= mu |g_t| (C y <= 0). Take y = 0 outside a set D of disks. A contact between
two disks outside D, or between such a disk and an obstacle, has g = 0: its rows of C y are 0,
so they hold exactly. A contact of a disk of D with a disk outside D (or an obstacle) has the
relative velocity of a disk moving against a fixed body: its rows involve only D's unknowns.
So y_D with C_D y_D <= 0 (the rows of the contacts touching D, the columns of D) and
b_D . y_D < 0, extended by zeros, IS a certificate for the whole packing: no equilibrium.

Deposited piles lose their equilibrium locally (a 3000-disk pile at mu = 0.5: the whole
certificate of the global LP moves 11 disks near the top; docs/packings.md, Scale), and a small
cluster's certificate is checked in exact rational arithmetic, which needs no radius bound.
`scan` looks for one in square windows of the packing (side L, stride L / 2, so that every
cluster whose centres span at most L / 2 in x and in y lies inside one window), from the top
of the pile down, L doubling from START_DIAMETERS largest diameters while no window holds
more than MAX_WINDOW_DISKS disks. Each window is one small LP, min b_D . y_D, C_D y_D <= 0,
|y_D| <= 1, by HiGHS's simplex (a vertex: its nearly active rows are the exact ones); an
optimum below zero is shrunk to its support and checked exactly (`exact_local`): the nearly
active rows made exactly active by a rational y (python-flint's row reduction, free unknowns
at the float y's values as small fractions), then C_D y <= 0 and b_D . y < 0 in rational
arithmetic on the stored (float) H, b, mu. Only an exactly checked y is returned. A scan that
finds none proves nothing (the loss of equilibrium may be global): the caller goes on.

The same exact check settles the global Farkas LP's y on piles of any size
(`support_certificate`): the disks y moves split into clusters linked by their contacts; a
row of C touches one cluster only (or none: then it is 0), so y is a certificate iff each
cluster's part satisfies its rows and one has b_D . y_D < 0, which alone is then a local
certificate. Each such cluster of at most EXACT_MAX_DISKS disks, smallest first, is checked
exactly as above: the cost grows with the disks y moves, not with the packing (11 disks on
the 3000-disk pile).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from rigidlcp.lcp.quiet import new_highs

from .farkas import cone_rows, first_exact, rational, small_rational
from .model import StaticProblem

#: First window side, in largest diameters (the 11 disks of the 3000-disk pile's global
#: certificate span ~4; its local ones, 2-3 disks, ~2).
START_DIAMETERS = 6.0
#: No window larger than this many disks after the first side (beyond it the global Farkas
#: LP is the tool: on a 10^4-disk pile whose small windows held no certificate, windows of
#: ~800 disks took minutes).
MAX_WINDOW_DISKS = 500
#: Largest support (disks) checked in exact arithmetic.
EXACT_MAX_DISKS = 200
#: A window's LP optimum b . y below -GAP x (the largest disk weight) is checked exactly.
GAP = 1e-9
#: A disk moves under y when some of its u, v, w exceeds this fraction of |y|_inf.
MOVES = 1e-9


@dataclass
class LocalCertificate:
    """A certificate moving only `disks`. exact: the checked rational y, {column of y (u, v, w
    blocks of p): value} on the disks' columns (zero elsewhere), with C y <= 0 and b . y < 0
    exactly; y: its float image (3p, |y|_inf = 1; rounding may leave ~1e-16 violations);
    gap = -b . y; windows: LPs solved to find it."""

    y: np.ndarray
    disks: np.ndarray
    gap: float
    windows: int
    exact: dict


class Cone:
    """C (cone rows, verify.statics.farkas.cone_rows) with, per row, its contact."""

    def __init__(self, prob: StaticProblem):
        self.prob = prob
        self.C = cone_rows(prob)
        self.contact = np.r_[np.arange(prob.c), prob.fric]
        lat = prob.system.lattice
        self.i, self.j = lat.i, lat.j

    def rows_of(self, D: np.ndarray) -> np.ndarray:
        """The rows of the contacts touching a disk of D."""
        inside = np.zeros(self.prob.p, dtype=bool)
        inside[D] = True
        touch = inside[self.i] | ((self.j >= 0) & inside[np.maximum(self.j, 0)])
        return np.flatnonzero(touch[self.contact])

    def cols_of(self, D: np.ndarray) -> np.ndarray:
        p = self.prob.p
        return np.r_[D, p + D, 2 * p + D]


def window_lp(cone: Cone, D: np.ndarray, target: np.ndarray | None = None
              ) -> tuple[float, np.ndarray | None]:
    """(min b_D . y_D, its y_D) over C_D y_D <= 0, |y_D|_inf <= 1 by HiGHS's simplex;
    (0, None) when HiGHS reports no optimum. With `target` (cone rows of contacts touching D):
    min sum_target (C y)_r subject also to b_D . y_D = 0 (verify.statics.implicit)."""
    import highspy

    rows, cols = cone.rows_of(D), cone.cols_of(D)
    Cd = sp.csc_matrix(cone.C[rows][:, cols])
    cost = np.asarray(cone.prob.b[cols], dtype=float)
    bounds = np.zeros(rows.size)
    if target is not None:
        cost = np.asarray(cone.C[target][:, cols].sum(axis=0), dtype=float).ravel()
        Cd = sp.vstack([Cd, sp.csr_matrix(np.asarray(cone.prob.b[cols], dtype=float)[None, :])],
                       format="csc")
        bounds = np.r_[bounds, 0.0]
    m, n = Cd.shape
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = n, m
    lp.col_cost_ = cost
    lp.col_lower_, lp.col_upper_ = -np.ones(n), np.ones(n)
    lp.row_lower_ = np.full(m, -highspy.kHighsInf)
    if target is not None:
        lp.row_lower_[-1] = 0.0
    lp.row_upper_ = bounds
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (
        Cd.indptr, Cd.indices, Cd.data)
    h = new_highs(solver="simplex", primal_feasibility_tolerance=1e-10,
                  dual_feasibility_tolerance=1e-10)
    h.passModel(lp)
    h.run()
    if h.getModelStatus() != highspy.HighsModelStatus.kOptimal:
        return 0.0, None
    return float(h.getInfo().objective_function_value), np.asarray(
        h.getSolution().col_value, dtype=float)


def exact_local(prob: StaticProblem, D: np.ndarray, yD: np.ndarray,
                active_tol: float = 1e-9) -> dict | None:
    """A rational y on the disks D near yD (3|D|: u, v, w blocks), the cone rows yD makes
    nearly active made exactly active, checked exactly: C_D y <= 0 and b_D . y < 0 for the
    stored H, b, mu (module docstring). {column of the full y: Fraction} on D's columns, or
    None when the check fails."""
    cone = Cone(prob)
    rows, cols = cone.rows_of(D), cone.cols_of(D)
    exact_rows = window_rows(cone, rows, cols)
    bq = [rational(v) for v in prob.b[cols]]
    scale = float(np.max(np.abs(yD), initial=0.0))
    if scale == 0:
        return None
    yD = yD / scale
    g = cone.C[rows][:, cols] @ yD
    found = first_exact(exact_rows, bq, np.flatnonzero(g > -active_tol),
                        [small_rational(v) for v in yD])
    if found is None:
        return None
    return {int(k): Fraction(int(v.p), int(v.q)) for k, v in zip(cols, found[0])}


def window_rows(cone: Cone, rows: np.ndarray, cols: np.ndarray) -> list[list]:
    """The cone rows `rows` of C on the columns `cols` in rationals (one list of fmpq per row):
    -H_n + mu H_t (row < c) or -H_n - mu H_t, from the stored H and mu."""
    from flint import fmpq

    prob = cone.prob
    where = {int(k): s for s, k in enumerate(cols)}
    H = sp.csr_matrix(prob.A.T)
    c, mu = prob.c, prob.mu
    out = []
    for r in rows:
        a = int(cone.contact[r])
        mq = rational(mu[a]) * (1 if r < c else -1)
        row = [fmpq(0)] * cols.size
        for k, coef in ((a, fmpq(-1)), (c + a, mq)):
            lo, hi = H.indptr[k], H.indptr[k + 1]
            for col, val in zip(H.indices[lo:hi], H.data[lo:hi]):
                s = where.get(int(col))
                if s is not None:
                    row[s] += coef * rational(val)
        out.append(row)
    return out


def windows(prob: StaticProblem, side: float) -> list[np.ndarray]:
    """The disks of each square window of the given side (stride side / 2), top rows first;
    windows holding no disk, or the same disks as an earlier one, left out."""
    lat = prob.system.lattice
    x = lat.x
    lo, hi = x.min(axis=0), x.max(axis=0)
    step = side / 2
    nx = max(1, int(np.ceil((hi[0] - lo[0]) / step)))
    ny = max(1, int(np.ceil((hi[1] - lo[1]) / step)))
    cx = np.minimum(((x[:, 0] - lo[0]) // step).astype(int), nx - 1)
    cy = np.minimum(((x[:, 1] - lo[1]) // step).astype(int), ny - 1)
    # window (a, b) covers cells a..a+1 in x and b..b+1 in y
    out, seen = [], set()
    for b in range(max(ny - 1, 1) - 1, -1, -1):
        for a in range(max(nx - 1, 1)):
            D = np.flatnonzero((cx >= a) & (cx <= a + 1) & (cy >= b) & (cy <= b + 1))
            key = D.tobytes()
            if D.size and key not in seen:
                seen.add(key)
                out.append(D)
    return out


def scan(prob: StaticProblem, start: float = START_DIAMETERS,
         max_disks: int = MAX_WINDOW_DISKS, levels: int | None = None,
         progress: Callable[[int, float], None] | None = None) -> LocalCertificate | None:
    """The first exactly checked local certificate found in the windows (module docstring),
    or None (no claim). start: the first side in largest diameters; levels: how many sides
    (None: until a window holds max_disks disks or the whole packing); progress(windows
    solved, side) after each side."""
    if prob.p == 0:
        return None
    cone = Cone(prob)
    dmax = 2.0 * float(np.max(prob.system.lattice.radii))
    weight = float(np.max(prob.system.masses)) * prob.system.g
    side, solved, level = start * dmax, 0, 0
    while levels is None or level < levels:
        level += 1
        wins = windows(prob, side)
        if level > 1 and max(D.size for D in wins) > max_disks:
            return None
        for D in wins:
            value, yD = window_lp(cone, D)
            solved += 1
            if yD is not None and value < -GAP * weight:
                cert = _settle(prob, cone, D, yD, solved)
                if cert is not None:
                    return cert
        if progress:
            progress(solved, side)
        if len(wins) == 1:
            return None
        side *= 2
    return None


def _settle(prob: StaticProblem, cone: Cone, D: np.ndarray, yD: np.ndarray,
            solved: int) -> LocalCertificate | None:
    """The window's y shrunk to the disks it moves and checked exactly."""
    k = D.size
    moving = np.max(np.abs(yD.reshape(3, k)), axis=0) > MOVES * np.max(np.abs(yD))
    S = D[moving]
    if S.size == 0 or S.size > EXACT_MAX_DISKS:
        return None
    yS = yD.reshape(3, k)[:, moving].reshape(-1)
    exact = exact_local(prob, S, yS)
    if exact is None:  # the support's own LP: a vertex of the smaller problem
        value, yS = window_lp(cone, S)
        if yS is not None and value < 0:
            exact = exact_local(prob, S, yS)
    if exact is None:
        return None
    y = np.zeros(3 * prob.p)
    for k, v in exact.items():
        y[k] = v.numerator / v.denominator
    y /= float(np.max(np.abs(y)))
    return LocalCertificate(y, S, -float(prob.b @ y), solved, exact)


def clusters(prob: StaticProblem, y: np.ndarray) -> list[np.ndarray]:
    """The disks y (3p) moves, split into clusters linked by their contacts (module
    docstring), smallest first."""
    p = prob.p
    move = np.max(np.abs(np.asarray(y, dtype=float).reshape(3, p)), axis=0)
    S = np.flatnonzero(move > MOVES * float(np.max(move, initial=0.0)))
    if S.size == 0 or not np.max(move) > 0:
        return []
    lat = prob.system.lattice
    where = np.full(p, -1)
    where[S] = np.arange(S.size)
    j = np.maximum(lat.j, 0)
    both = (lat.j >= 0) & (where[lat.i] >= 0) & (where[j] >= 0)
    links = sp.coo_matrix((np.ones(int(both.sum())), (where[lat.i[both]], where[j[both]])),
                          shape=(S.size, S.size))
    n, label = connected_components(links, directed=False)
    return sorted((S[label == k] for k in range(n)), key=len)


def support_certificate(prob: StaticProblem, y: np.ndarray,
                        max_disks: int = EXACT_MAX_DISKS) -> LocalCertificate | None:
    """An exactly checked certificate from a (global) candidate y (3p): its clusters
    (`clusters`) of at most max_disks disks with b_D . y_D < 0, smallest first, each checked
    exactly as a window's y (module docstring); the first that passes, or None (no claim)."""
    yb = np.asarray(y, dtype=float).reshape(3, prob.p)
    cone = Cone(prob)
    for D in clusters(prob, y):
        yD = yb[:, D].reshape(-1)
        if D.size > max_disks or not float(prob.b[cone.cols_of(D)] @ yD) < 0:
            continue
        cert = _settle(prob, cone, D, yD, 0)
        if cert is not None:
            return cert
    return None
