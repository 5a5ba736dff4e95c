"""Certificates that a packing has no equilibrium: P (verify.statics.model) is empty.

Farkas's lemma for P = {lambda : H^T lambda = b, R >= 0, |S| <= mu R}: P is empty iff some
virtual velocities y of the disks (3p) have relative velocities g = H y in the dual cone of
every contact, g_n >= mu |g_t| (g_n >= 0 and g_t free where mu = 0), while gravity does
positive work, b . y < 0. (For lambda in P, b . y = lambda . H y = sum R g_n + S g_t
>= sum R (g_n - mu |g_t|) >= 0.) In rows: C y <= 0 with C = [-H_n + mu H_t; -H_n - mu H_t]
(the second block at frictional contacts only).

y comes from one LP (min b . y, C y <= 0, |y| <= 1) and is checked, never taken on the LP's
word, in two ways:

* floating point (evidence only): with v the violations of the cone rows, every lambda in P
  has sum R >= radius = (-b . y) / max(v); `check` keeps y when that radius exceeds
  RADIUS_WEIGHTS times the packing's weight. A radius bounds the size of the equilibria; it
  does not prove that there is none (as for LCPs in lcp.acceptance.farkas: a float
  certificate of radius 9.3e14 was once accepted on a P-matrix LCP with solutions of size
  2.4e16). HiGHS leaves C y <= 0 to its feasibility tolerance (~1e-11 here), which caps that
  radius near 1e10 weights; so y is first projected onto the cone rows it makes (nearly)
  active (`_polish`: least squares, twice), which leaves rounding-size violations.
* exact (the proof): the rows y nearly makes active are made exactly active by a rational y
  (python-flint's row reduction, free unknowns at y's values as small fractions) and
  C y <= 0, b . y < 0 are checked in rational arithmetic on the float data as stored (each
  double is a rational; mu too; the rows of C are formed exactly from H), as
  lcp.acceptance.farkas does for LCPs. Such a y proves P empty for the stored data: no
  tolerance and no radius (radius = inf, exact True). Dense here up to EXACT_MAX_P disks;
  beyond, on y's support only (`farkas`'s `exact` argument: verify.statics.local.
  support_certificate, whose cost grows with the disks y moves, not with the packing).

Only an exact certificate `proves` P empty. Otherwise no claim is made: `analyse` reports the
existence as undecided, with the best floating-point certificate's radius as evidence, rather
than "no".
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import scipy.sparse as sp

from rigidlcp.lcp.quiet import new_highs

from .model import StaticProblem

#: A floating-point certificate must exclude every equilibrium with sum R below this many
#: weights.
RADIUS_WEIGHTS = 1e9
#: Largest number of disks for the exact re-check (dense rational row reduction).
EXACT_MAX_P = 150
#: Largest number of disks for the Farkas LP's second try, with crossover (slow at scale).
CROSSOVER_MAX_P = 3000


@dataclass
class Certificate:
    """y (3p) with H y in the dual cone and b . y < 0. radius: no lambda in P has sum R below
    it (inf when exact); gap: -b . y with |y|_inf = 1; exact: checked in rational arithmetic.
    y is None when not even the floating-point check passed (radius: the best one found)."""

    y: np.ndarray | None
    radius: float
    gap: float
    exact: bool = False

    @property
    def proves(self) -> bool:
        """P is empty: only an exactly checked y proves it (module docstring)."""
        return self.exact and self.y is not None


def cone_rows(prob: StaticProblem) -> sp.csr_matrix:
    """C: C y <= 0 iff H y is in the dual cone of every contact (module docstring)."""
    c, mu = prob.c, prob.mu
    H = sp.csr_matrix(prob.A.T)
    Hn, Ht = H[:c], H[c:]
    fr = mu > 0
    return sp.vstack([-Hn + sp.diags(mu) @ Ht, (-Hn - sp.diags(mu) @ Ht)[fr]], format="csr")


def check(prob: StaticProblem, y: np.ndarray) -> Certificate:
    """The floating-point check of y (module docstring); y is None in the answer when the
    radius is too small or gravity does no work."""
    c, mu = prob.c, prob.mu
    g = prob.A.T @ y  # H y
    v = np.where(mu > 0, mu * np.abs(g[c:]) - g[:c], -g[:c])
    top = float(np.max(np.abs(y), initial=0.0))
    gap = -float(prob.b @ y) / top if top > 0 else 0.0
    worst = float(np.max(v, initial=0.0)) / top if top > 0 else 0.0
    radius = np.inf if worst <= 0 else gap / worst
    weight = float(np.sum(prob.system.masses)) * prob.system.g
    ok = gap > 0 and radius >= RADIUS_WEIGHTS * weight
    return Certificate(y / top if ok else None, float(radius) if gap > 0 else 0.0, gap)


#: An exact check of a candidate y beyond EXACT_MAX_P disks: an exact Certificate or None.
ExactCheck = Callable[[StaticProblem, np.ndarray], "Certificate | None"]


def farkas(prob: StaticProblem, exact: ExactCheck | None = None) -> Certificate:
    """An exactly checked certificate that P is empty (`proves`), else the best evidence
    (module docstring): a floating-point certificate with its radius (exact False), or y None
    with the best radius found. exact: the exact check used beyond EXACT_MAX_P disks (None:
    none there)."""
    C = cone_rows(prob)
    # first HiGHS's IPM without crossover (its interior optimum, polished): 2.2 against 3.7 CPU
    # s on a 3000-disk pile, and at 10^4 disks the crossover did not end in 15 minutes
    # (docs/packings.md, Scale); then, on piles small enough, with crossover (a vertex, whose
    # nearly active rows the polishing and the exact check find more reliably)
    best = Certificate(None, 0.0, 0.0)
    for crossover in (False, True):
        if crossover and prob.p > CROSSOVER_MAX_P:
            break
        y = farkas_lp(prob, C, crossover)
        if y is None:
            continue
        cert = _settle(prob, C, y, exact)
        if cert.proves:
            return cert
        best = max(best, cert, key=lambda k: k.radius)
    return best


def farkas_lp(prob: StaticProblem, C: sp.csr_matrix, crossover: bool) -> np.ndarray | None:
    """y of min b . y, C y <= 0, |y|_inf <= 1 by HiGHS's IPM (with or without crossover), or
    None when HiGHS reports no optimum or b . y >= 0 (no claim either way)."""
    import highspy

    m, n = C.shape
    Cc = sp.csc_matrix(C)
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = n, m
    lp.col_cost_ = np.asarray(prob.b, dtype=float)
    lp.col_lower_, lp.col_upper_ = -np.ones(n), np.ones(n)
    lp.row_lower_, lp.row_upper_ = np.full(m, -highspy.kHighsInf), np.zeros(m)
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (
        Cc.indptr, Cc.indices, Cc.data)
    h = new_highs(solver="ipm", run_crossover="on" if crossover else "off",
                  primal_feasibility_tolerance=1e-10, dual_feasibility_tolerance=1e-10)
    h.passModel(lp)
    h.run()
    if h.getModelStatus() != highspy.HighsModelStatus.kOptimal:
        return None
    y = np.asarray(h.getSolution().col_value, dtype=float)
    return y if float(prob.b @ y) < 0 else None


def _settle(prob: StaticProblem, C: sp.csr_matrix, y: np.ndarray,
            exact: ExactCheck | None = None) -> Certificate:
    """The LP's y checked exactly (dense up to EXACT_MAX_P disks, else by `exact`), polished
    first, then as it is; when no exact check passes, the better floating-point check of the
    two (evidence, exact False)."""
    polished = _polish(C, y)
    best = max(check(prob, polished), check(prob, y), key=lambda k: k.radius)
    for cand in (polished, y):
        if prob.p <= EXACT_MAX_P:
            cert = exact_certificate(prob, cand)
        else:
            cert = None if exact is None else exact(prob, cand)
        if cert is not None and cert.proves:
            return cert
    return best


def _polish(C: sp.csr_matrix, y: np.ndarray) -> np.ndarray:
    """Project y onto the cone rows J it makes nearly active, {C_J y = 0} (least squares,
    twice): the LP's tolerance-size violations become rounding."""
    from scipy.sparse.linalg import lsqr

    y = np.asarray(y, dtype=float).copy()
    scale = float(np.max(np.abs(y), initial=1.0))
    for _ in range(2):
        g = C @ y
        J = np.flatnonzero(g > -1e-8 * scale)
        if J.size == 0:
            break
        CJ = C[J]
        step = lsqr(CJ, CJ @ y, atol=1e-15, btol=1e-15, iter_lim=10 * C.shape[1])[0]
        y -= step
    return y


def rational(x: float):
    """x exactly, as a python-flint fmpq (every float is a fraction)."""
    from flint import fmpq  # a dependency (pyproject); imported on first use

    f = Fraction(float(x))
    return fmpq(f.numerator, f.denominator)


def small_rational(x: float):
    """The fraction nearest x with a denominator <= 10^6 (a start for free unknowns)."""
    from flint import fmpq

    f = Fraction(float(x)).limit_denominator(10**6)
    return fmpq(f.numerator, f.denominator)


def exact_cone_rows(prob: StaticProblem) -> list[list]:
    """The cone rows C of `cone_rows` in rationals: -H_n + mu H_t for every contact, then
    -H_n - mu H_t where mu > 0 (one list of fmpq per row, one entry per balance row)."""
    from flint import fmpq

    c, mu, m = prob.c, prob.mu, prob.A.shape[0]
    H = sp.coo_matrix(prob.A.T)
    Hq = [[fmpq(0)] * m for _ in range(2 * c)]
    for i, j, v in zip(H.row, H.col, H.data):
        Hq[int(i)][int(j)] = rational(v)
    rows = []
    for a in range(c):
        mq = rational(mu[a])
        rows.append([-hn + mq * ht for hn, ht in zip(Hq[a], Hq[c + a])])
    for a in np.flatnonzero(mu > 0):
        mq = rational(mu[a])
        rows.append([-hn - mq * ht for hn, ht in zip(Hq[a], Hq[c + a])])
    return rows


def exact_certificate(prob: StaticProblem, y: np.ndarray, active_tol: float = 1e-9
                      ) -> Certificate | None:
    """A rational y near the float y with the nearly active cone rows exactly active, checked
    exactly: C y <= 0 and b . y < 0 for the stored (float) H, b, mu (module docstring)."""
    rows = exact_cone_rows(prob)
    bq = [rational(v) for v in prob.b]
    y = np.asarray(y, dtype=float) / float(np.max(np.abs(y)))
    g = cone_rows(prob) @ y
    found = first_exact(rows, bq, np.flatnonzero(g > -active_tol),
                        [small_rational(v) for v in y])
    if found is None:
        return None
    cand, work = found
    yf = np.array([int(v.p) / int(v.q) for v in cand])
    top = float(np.max(np.abs(yf)))
    return Certificate(yf / top, np.inf, -(int(work.p) / int(work.q)) / top, exact=True)


def first_exact(rows: list[list], bq: list, J: np.ndarray, start: list
                ) -> tuple[list, object] | None:
    """The first rational candidate (`candidates`: the y with the cone rows J exactly active
    and its free unknowns at `start`, then `start` itself, then J less one row of a numerical
    dependency) that is a Farkas certificate exactly: b . y < 0 and row . y <= 0 for every row
    (C y <= 0). (y, b . y) as python-flint fmpq's, or None when none passes."""
    from flint import fmpq

    for cand in candidates(rows, J, start):
        work = sum((bi * yi for bi, yi in zip(bq, cand)), fmpq(0))
        if work >= 0:
            continue
        if all(sum((r * yi for r, yi in zip(row, cand)), fmpq(0)) <= 0 for row in rows):
            return cand, work
    return None


#: Most rows of a numerical dependency tried for dropping (`candidates`).
DROP_TRIES = 8


def candidates(rows: list[list], J: np.ndarray, start: list) -> Iterator[list]:
    """Rational candidates for first_exact, each computed only when asked: the y with the
    rows J exactly active (free unknowns at `start`), `start`, and then, when the rows J are
    dependent in floating point but not exactly (the stored data's rounding of a degenerate
    contact geometry: 71 rows of rank 70 in floats, 71 exactly, on a 400-disk pile, whose
    exact null space then violates another row by 0.66), the y of J less one of the rows of a
    numerical dependency (the largest coefficients first, at most DROP_TRIES): that row is
    then within rounding of 0, on either side, so several are tried."""
    from flint import fmpq_mat

    def active(Jk: np.ndarray) -> list | None:
        A = fmpq_mat(len(Jk), len(start), [v for j in Jk for v in rows[int(j)]])
        return solve_homogeneous(A, start)

    if J.size:
        cand = active(J)
        if cand is not None:
            yield cand
    yield start
    if J.size < 2:
        return
    # p / q: python-flint's fmpq has no __float__ before 0.7 (the lowest-direct job)
    F = np.array([[int(v.p) / int(v.q) for v in rows[int(j)]] for j in J])
    U, sv, _ = np.linalg.svd(F)
    rank = int(np.sum(sv > max(F.shape) * np.finfo(float).eps * sv[0])) if sv.size else 0
    if rank >= J.size:
        return
    u = U[:, rank]  # a left null vector: sum_k u_k row_k ~ 0
    for k in np.argsort(-np.abs(u), kind="stable")[:DROP_TRIES]:
        if abs(u[k]) <= 1e-8 * float(np.max(np.abs(u))):
            break
        cand = active(np.delete(J, k))
        if cand is not None:
            yield cand


def solve_homogeneous(A, start: list) -> list | None:
    """The rational y with A y = 0, free unknowns (non-pivots of A's reduced row echelon
    form) at `start`; None if that makes y = 0."""
    from flint import fmpq

    n = A.ncols()
    R, rank = A.rref()
    pivots, col = [], 0
    for r in range(rank):
        while R[r, col] == 0:
            col += 1
        pivots.append(col)
        col += 1
    free = [k for k in range(n) if k not in set(pivots)]
    y = [fmpq(0)] * n
    for k in free:
        y[k] = start[k]
    for r, k in enumerate(pivots):
        y[k] = -sum((R[r, f] * y[f] for f in free), fmpq(0))
    return None if all(v == 0 for v in y) else y
