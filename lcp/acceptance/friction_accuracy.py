"""Backward error and forward error bound of a 2D friction-contact answer (lcp.FrictionContact2D).

The LCP/MLCP measures of lcp.acceptance.accuracy, for the friction-contact conditions
themselves (Signorini with Coulomb, the paper's Eq. 2.5-2.6), in Siconos's layout
r = [r_n0, r_t0, ...], u = W r + q.

**Backward error** (row by row, on the data's scale, never on |r|). Each row of u is judged
against its own terms, s = max(|W| |r| + |q|, s_d) with the data's scale
s_d = |q|_inf + ||W||_inf |q|_inf / |W|_max (lcp.acceptance.accuracy.data_scale), the forces
normwise against r_s = max(|r|_inf, |q|_inf / |W|_max) (as the z side of an LCP). Per contact,
with ^ for those scaled quantities (r^ = r / r_s, u^_i = u_i / s_i):

    Signorini      |min(r^_n, u^_n)|
    Coulomb cone   max(0, |r^_t| - mu r^_n)
    sliding rule   min(|u^_t|, |r^_t + mu r^_n sgn(u_t)|)    (u_t != 0 => r_t = -mu r_n sgn u_t)

and berr is the largest of them over all contacts. It is zero exactly at a solution and, as for
an LCP, cannot be met by inflating r: a row that r does not touch keeps its size.

**Contact states and their system.** Each contact is open (r = 0), sticking (u = 0, r inside
the cone), sliding forward (u_n = 0, u_t > 0, r_t = -mu r_n) or backward (r_t = +mu r_n); a
frictionless closed contact counts as sliding (r_t = 0). The states fix a square linear system
K y = -k: the unknowns y are r_n of the closed contacts and r_t of the sticking ones (a sliding
r_t is -s mu r_n), the rows u_n of the closed contacts and u_t of the sticking ones. The states
are the method's where it ended on a basis (a Glocker LCP basis, `states_of_glocker_basis`),
else read off the answer (`states_of`: closed where r^_n > u^_n; sticking where |u^_t| is
below the cone's slack mu r^_n - |r^_t|).

**Forward error bound**: LAPACK's FERR of that system after refinement with extended-precision
residuals (lcp.acceptance.accuracy.refine; a sparse LU and Hager-Higham's estimate above
DENSE_MAX unknowns): how far the answer may be from the exact solution of its states. A
singular system (a continuum of forces) uses the pseudo-inverse at its numerical rank (the
nearest exact point); an inconsistent one has an infinite bound. The answer as given adds its
distance to the refined point. Where the method ended on a basis, or where the answer as given
fails the test, the refined point (r_n clipped at 0) replaces it when its backward error is not
larger (or at rounding level): "polished".

**Accepted** iff berr <= lcp.residual.TOL and ferr <= lcp.accuracy.FERR_TOL (the LCP limits).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..problems.friction import FrictionContact2D
from .accuracy import FERR_TOL, STEPS, refine
from .residual import TOL

OPEN, STICK, SLIDE_FORWARD, SLIDE_BACKWARD = 0, 1, 2, 3
#: Above this many unknowns the pattern system is factored sparse (no dense K).
DENSE_MAX = 1500
_EPS = float(np.finfo(float).eps)
_EPS_LD = float(np.finfo(np.longdouble).eps)


@dataclass
class FCAccuracy:
    """The quality of a friction-contact answer r (module doc)."""

    berr: float
    ferr: float
    states: np.ndarray  # per contact: OPEN, STICK, SLIDE_FORWARD, SLIDE_BACKWARD
    r: np.ndarray  # the answer judged (the polished one when refined)
    refined: bool = False

    @property
    def accepted(self) -> bool:
        return bool(self.berr <= TOL and self.ferr <= FERR_TOL)


def _abs(W):
    return abs(W) if sp.issparse(W) else np.abs(W)


def scales(problem: FrictionContact2D, r: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """(u, s, r_s): u = W r + q, each row's scale s and the forces' scale r_s (module doc)."""
    W, q = problem.W, problem.q
    absW = _abs(W)
    qmax = float(np.max(np.abs(q), initial=0.0))
    wmax = float(absW.max()) if W.shape[0] else 0.0
    rowsum = float(np.max(np.asarray(absW.sum(axis=1)).ravel(), initial=0.0))
    s_d = qmax + rowsum * (qmax / wmax) if wmax > 0 else qmax
    with np.errstate(all="ignore"):
        u = W @ r + q
        s = np.maximum(absW @ np.abs(r) + np.abs(q), s_d)
    r_s = max(float(np.max(np.abs(r), initial=0.0)), qmax / wmax if wmax > 0 else 0.0)
    return u, s, (r_s if r_s > 0 else 1.0)


def _ratio(x: np.ndarray, s: np.ndarray) -> np.ndarray:
    with np.errstate(all="ignore"):
        return np.where(s > 0, x / np.where(s > 0, s, 1.0), np.where(x == 0, 0.0,
                                                                     np.sign(x) * np.inf))


def backward_error(problem: FrictionContact2D, r: np.ndarray) -> float:
    """berr of the module doc (the largest per-contact violation, scaled on the data)."""
    r = np.asarray(r, dtype=float)
    if r.size == 0:
        return 0.0
    if not np.all(np.isfinite(r)):
        return np.inf
    u, s, r_s = scales(problem, r)
    mu = problem.mu
    rn, rt = r[0::2] / r_s, r[1::2] / r_s
    un, ut = _ratio(u[0::2], s[0::2]), _ratio(u[1::2], s[1::2])
    with np.errstate(all="ignore"):
        signorini = np.abs(np.minimum(rn, un))
        cone = np.maximum(np.abs(rt) - mu * rn, 0.0)
        slide = np.minimum(np.abs(ut), np.abs(rt + mu * rn * np.sign(u[1::2])))
        out = float(np.max(np.concatenate([signorini, cone, slide])))
    return out if np.isfinite(out) else np.inf


def states_of(problem: FrictionContact2D, r: np.ndarray) -> np.ndarray:
    """The contact states an answer r takes (module doc)."""
    u, s, r_s = scales(problem, r)
    mu = problem.mu
    rn, rt = r[0::2] / r_s, r[1::2] / r_s
    un, ut = _ratio(u[0::2], s[0::2]), _ratio(u[1::2], s[1::2])
    closed = (r[0::2] > 0) & (rn > un)
    stick = closed & (mu > 0) & (np.abs(ut) <= mu * rn - np.abs(rt))
    forward = np.where(u[1::2] != 0, u[1::2] > 0, r[1::2] <= 0)
    return np.where(~closed, OPEN, np.where(stick, STICK, np.where(
        forward, SLIDE_FORWARD, SLIDE_BACKWARD))).astype(np.int8)


def states_of_glocker_basis(problem: FrictionContact2D, basis) -> np.ndarray | None:
    """The contact states of a basis of the Glocker LCP (z = [R, tau, a_minus], lcp.problems.
    friction): R basic: closed; then tau and a_minus basic: sliding backward (r_t = +mu R),
    tau only: sticking, neither: sliding forward. None for a basis that is not one."""
    c = problem.c
    b = np.asarray(basis, dtype=np.intp).reshape(-1)
    if b.size and (b.min() < 0 or b.max() >= 3 * c or np.unique(b).size < b.size):
        return None
    inb = np.zeros(3 * c, dtype=bool)
    inb[b] = True
    R, tau, am = inb[:c], inb[c:2 * c], inb[2 * c:]
    if np.any(am & ~tau) or np.any(~R & (tau | am) & (problem.mu > 0)):
        return None
    st = np.where(~R, OPEN, np.where(tau & am, SLIDE_BACKWARD, np.where(
        tau, STICK, SLIDE_FORWARD))).astype(np.int8)
    st[R & (problem.mu == 0)] = SLIDE_FORWARD
    return st


def pattern_system(problem: FrictionContact2D, states: np.ndarray
                   ) -> tuple[sp.csr_matrix, np.ndarray, sp.csr_matrix]:
    """(K, k, T) of the states: K y + k = 0 is the system of the module doc and r = T y."""
    c, mu = problem.c, problem.mu
    closed = np.flatnonzero(states != OPEN)
    stick = np.flatnonzero(states == STICK)
    nc, m = closed.size, closed.size + stick.size
    s = np.where(states[closed] == SLIDE_BACKWARD, -1.0, 1.0)
    slide = states[closed] != STICK
    rows = np.concatenate([2 * closed, 2 * closed[slide] + 1, 2 * stick + 1])
    cols = np.concatenate([np.arange(nc), np.flatnonzero(slide), nc + np.arange(stick.size)])
    vals = np.concatenate([np.ones(nc), -s[slide] * mu[closed[slide]], np.ones(stick.size)])
    T = sp.csr_matrix((vals, (rows, cols)), shape=(2 * c, m))
    eqs = np.concatenate([2 * closed, 2 * stick + 1])
    K = sp.csr_matrix(problem.W)[eqs] @ T
    return sp.csr_matrix(K), problem.q[eqs], T


def _refine_sparse(K: sp.csr_matrix, k: np.ndarray, y0: np.ndarray) -> tuple[np.ndarray, float]:
    """lcp.acceptance.accuracy.refine for a large sparse K (sparse LU, the norm of |K^-1| g
    estimated as LAPACK does); an exactly singular K has ferr = inf."""
    import warnings

    from scipy.sparse.linalg import LinearOperator, onenormest, splu

    m = k.size
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            lu = splu(K.tocsc())
    except RuntimeError:
        return y0, np.inf

    def solve(rhs, trans=False):
        return lu.solve(np.ascontiguousarray(rhs, dtype=float), trans="T" if trans else "N")

    ld = np.longdouble
    Kld, kld = K.astype(ld), k.astype(ld)

    def residual(y):
        return (Kld @ y.astype(ld) + kld).astype(float)

    y = np.array(y0, dtype=float)
    with np.errstate(all="ignore"):
        if not np.all(np.isfinite(y)):
            y = -solve(k)
        prev = np.inf
        for _ in range(STEPS):
            d = solve(residual(y))
            size = float(np.max(np.abs(d)))
            if not np.isfinite(size) or size >= prev:
                break
            y, prev = y - d, size
            if size <= _EPS * float(np.max(np.abs(y))):
                break
        g = np.abs(residual(y)) + (m + 1) * _EPS_LD * (abs(K) @ np.abs(y) + np.abs(k))
        op = LinearOperator((m, m), dtype=float,
                            matvec=lambda t: g * solve(np.ravel(t), True),
                            rmatvec=lambda t: solve(g * np.ravel(t), False))
        ferr = float(onenormest(op)) / max(float(np.max(np.abs(y))), 1e-300) + _EPS
    return y, (ferr if np.isfinite(ferr) else np.inf)


def assess_fc2d(problem: FrictionContact2D, r: np.ndarray, states: np.ndarray | None = None,
                polish: bool | None = None) -> FCAccuracy:
    """berr and ferr of the answer r (module doc). states: the method's final contact states
    (then the answer is polished on them by default); polish: True / False forces it; None
    polishes where states were given or where the answer as given fails the test."""
    r = np.asarray(r, dtype=float).reshape(-1)
    berr = backward_error(problem, r)
    finite = bool(np.all(np.isfinite(r)))
    if states is None:
        st = states_of(problem, r) if finite else np.zeros(problem.c, np.int8)
    else:
        st = np.asarray(states, dtype=np.int8)
    K, k, T = pattern_system(problem, st)
    x = np.where(np.isfinite(r), r, 0.0)
    y0 = np.concatenate([x[0::2][st != OPEN], x[1::2][st == STICK]])
    if k.size <= DENSE_MAX:
        y, ferr = refine(K.toarray(), k, y0)
    else:
        y, ferr = _refine_sparse(K, k, y0)
    rp = T @ y if np.all(np.isfinite(y)) else np.full(r.size, np.nan)
    rp[0::2] = np.maximum(rp[0::2], 0.0)
    with np.errstate(all="ignore"):
        gap = float(np.max(np.abs(r - rp), initial=0.0))
        given = ferr + gap / max(float(np.max(np.abs(r), initial=0.0)), 1e-300)
    given = given if np.isfinite(given) else np.inf
    if polish is None:
        polish = states is not None or not (berr <= TOL and given <= FERR_TOL)
    if polish and np.all(np.isfinite(rp)):
        bp = backward_error(problem, rp)
        if bp <= max(berr, 8 * r.size * _EPS):
            return FCAccuracy(berr=bp, ferr=ferr, states=st, r=rp, refined=True)
    return FCAccuracy(berr=berr, ferr=given, states=st, r=r)
