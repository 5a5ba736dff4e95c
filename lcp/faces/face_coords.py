"""The face of an LCP solution in its own coordinates, and its small linear and quadratic programs.

With A the face's support and N an orthonormal basis of the null space of M_AA, every point of
the face F(z) (see lcp.face) is y_A = z_A + N x, y_Ac = z_Ac, with

    -N x <= z_A                    (y_A >= 0)
    -M_{Ac,A} N x <= w_Ac          (w_Ac >= 0, w = M z + q),

since M_AA N = 0 keeps (M y + q)_A = w_A = 0. x has d = nullity(M_AA) entries (4..23 on the
paper's arrays, against |A| = 84..139 unknowns of y_A): the face's linear program (least c'y)
and quadratic program (least |G y|) are small dense problems in x, solved here by DAQP, a dual
active-set method (exact to rounding on its final active set, no interior-point polishing).

The rank of M_AA is decided as the SVD decides it (singular values above
rank_tol = 1e3 max(|A|) eps max(sigma_max, 1)), but from a column-pivoted QR, M_AA P = Q R,
which costs a fraction of an SVD: with R11 the leading r x r block and R22 the trailing one,
sigma_r(M_AA) >= sigma_min(R11) >= 1 / |R11^-1|_F (R11 is a submatrix of R, whose singular
values are M_AA's) and sigma_{r+1}(M_AA) <= |R22|_2 <= |R22|_F (Weyl: R minus its first r
rows has rank r). When both bounds clear rank_tol by a margin (10, as in lcp.face.face_is_point)
the rank is r for the SVD too; otherwise the SVD decides. The null space is then
P [-R11^-1 R12; I], orthonormalized; the face point does not depend on the basis of N.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

RANK_MARGIN = 10.0
DAQP_INF = 1e30


def null_space(MAA: np.ndarray, *, method: str = "qr") -> tuple[np.ndarray, str]:
    """Orthonormal basis (columns) of the null space of the square M_AA, rank decided as by
    the SVD threshold; returns (N, "qr") when the pivoted QR proved the rank (module doc), else
    (N, "svd")."""
    n = MAA.shape[0]
    if method == "qr":
        N = _null_space_qr(MAA)
        if N is not None:
            return N, "qr"
    _, sig, Vt = np.linalg.svd(MAA)
    rank_tol = n * np.finfo(float).eps * max(sig.max(initial=0.0), 1.0) * 1e3
    rank = int(np.sum(sig > rank_tol))
    return Vt[rank:].T, "svd"


def _null_space_qr(MAA: np.ndarray) -> np.ndarray | None:
    n = MAA.shape[0]
    QR, jpvt, _, _, info = sla.lapack.dgeqp3(MAA)  # LAPACK's pivoted QR: R in the upper part
    if info != 0:
        return None
    piv = jpvt - 1  # Fortran's 1-based column order
    diag = np.abs(np.diag(QR))
    # sigma_max lies between the largest column norm |R_00| and |M_AA|_F
    unit = n * np.finfo(float).eps * 1e3
    tol_lo = unit * max(float(diag[0]), 1.0)
    tol_hi = unit * max(float(np.linalg.norm(MAA)), 1.0)
    r = int(np.sum(diag > tol_lo))
    if r < n and np.linalg.norm(np.triu(QR[r:, r:])) > tol_lo / RANK_MARGIN:
        return None  # sigma_{r+1} not proved below the threshold
    inv = _lower_bound_ok(QR, r, tol_hi) if r else np.zeros((0, 0))
    if inv is None:
        return None  # sigma_r not proved above it
    if r == n:
        return np.zeros((n, 0))
    basis = np.zeros((n, n - r))
    basis[piv[:r]] = -inv @ QR[:r, r:]
    basis[piv[r:]] = np.eye(n - r)
    return np.linalg.qr(basis)[0]


def _lower_bound_ok(R: np.ndarray, r: int, tol_hi: float) -> np.ndarray | None:
    """R11^-1 if 1/|R11^-1|_F (a lower bound on sigma_r) exceeds RANK_MARGIN x tol_hi (dtrtri
    reads and writes the upper triangle only: R's lower part, Householder vectors, is cut)."""
    inv, info = sla.lapack.dtrtri(R[:r, :r], lower=0)
    inv = np.triu(inv)
    if info != 0 or not np.all(np.isfinite(inv)):
        return None
    if 1.0 / np.linalg.norm(inv) <= RANK_MARGIN * tol_hi:
        return None
    return inv


class _Face:
    """F(z) parametrized as y_A = z_A + N x (N: null space of M_AA), y_Ac = 0, Aineq x <= bineq.

    A = {i : w_i = 0} (the largest face) unless the caller gives A. null: "qr" (certified
    pivoted QR, SVD when the rank is not clear) or "svd" (the SVD always, as before issue 13).
    """

    def __init__(self, M: np.ndarray, q: np.ndarray, z: np.ndarray, tol: float,
                 A: np.ndarray | None = None, null: str = "qr", w: np.ndarray | None = None):
        w = M @ z + q if w is None else w  # w: the caller's M z + q, if at hand
        self.z = z
        self.A = np.flatnonzero(w <= tol) if A is None else np.asarray(A)
        in_A = np.zeros(q.size, bool)
        in_A[self.A] = True
        Ac = np.flatnonzero(~in_A)
        self.null_method = "none"
        if self.A.size == 0:
            self.nullity, self.N = 0, np.zeros((0, 0))
            return
        MA = M[:, self.A]
        self.N, self.null_method = null_space(MA[self.A], method=null)
        self.nullity = self.N.shape[1]
        # y_A = z_A + N x >= 0 and w_Ac + M_{Ac,A} N x >= 0 (w_Ac > tol > 0; z_A clipped at 0)
        self.Aineq = np.vstack([-self.N, -(MA[Ac] @ self.N)])
        self.bineq = np.concatenate([np.maximum(z[self.A], 0.0), np.maximum(w[Ac], 0.0)])

    def point(self, x: np.ndarray) -> np.ndarray:
        y = self.z.copy()
        y[self.A] = np.maximum(self.z[self.A] + self.N @ x, 0.0)
        return y


def small_lp(g: np.ndarray, Aineq: np.ndarray, bineq: np.ndarray) -> np.ndarray | None:
    """A minimizer of g'x over {Aineq x <= bineq} (x = 0 feasible), by DAQP's proximal-point
    iterations; None unless DAQP reports an optimum that is feasible to 1e-11 |bineq| and
    multipliers lam (DAQP's, or those of the tight constraints by least squares) prove
    optimality: lam >= 0, g + Aineq' lam = 0 and lam' (bineq - Aineq x)
    = 0, each to 1e-9 of its scale (then g'x exceeds the minimum by at most those residuals
    times the size of x, by weak duality)."""
    d = g.size
    # proximal weight: a first step of ~100 |bineq| / |g| reaches the optimal face in 1-3
    # outer iterations on Fig. 9's faces (weight 1: ~7); the optimum does not depend on it
    gmax = float(np.abs(g).max(initial=0.0))
    prox = 1e-2 * gmax / max(float(np.abs(bineq).max(initial=0.0)), 1e-300) if gmax > 0 else 1.0
    out = _daqp(np.zeros((d, d)), g, Aineq, bineq, None, None, prox=prox)
    if out is None:
        return None
    x, lam = out
    gscale = max(float(np.abs(g).max(initial=0.0)), 1e-300)
    bscale = max(float(np.abs(bineq).max(initial=0.0)), 1.0)
    slack = bineq - Aineq @ x

    def proves(lam: np.ndarray) -> bool:
        return bool(lam.min(initial=0.0) >= -1e-9 * gscale
                    and np.abs(g + Aineq.T @ lam).max(initial=0.0) <= 1e-9 * gscale
                    and abs(lam @ slack) <= 1e-9 * gscale * bscale)

    if proves(lam):
        return x
    # DAQP's multipliers are those of its last proximal step (g + prox (x - x_k) + A'lam = 0):
    # when that step was long they miss stationarity. The multipliers of the constraints
    # tight at x, by least squares, may still prove x optimal.
    tight = np.flatnonzero(slack <= 1e-11 * bscale)
    if tight.size == 0:
        return None
    exact = np.zeros_like(lam)
    exact[tight] = np.linalg.lstsq(Aineq[tight].T, -g, rcond=None)[0]
    return x if proves(exact) else None


def small_qp(P: np.ndarray, f: np.ndarray, Aineq: np.ndarray, bineq: np.ndarray,
             Aeq: np.ndarray | None = None, beq: np.ndarray | None = None,
             start: np.ndarray | None = None) -> np.ndarray | None:
    """min 1/2 x'Px + f'x s.t. Aeq x = beq, Aineq x <= bineq (P positive definite), by DAQP
    (a dual active-set method: the answer solves the KKT system of its final active set); None
    unless it reports an optimum that is feasible to 1e-11 |b|. start: a feasible point whose
    tight constraints seed the active set (the linear stage's minimizer: ~30% fewer
    iterations on Fig. 9's faces); the optimum does not depend on it."""
    out = _daqp(P, f, Aineq, bineq, Aeq, beq, prox=0.0, start=start)
    return None if out is None else out[0]


def _daqp(P, f, Aineq, bineq, Aeq, beq, *, prox: float, start: np.ndarray | None = None):
    """(x, multipliers of the inequalities) from DAQP, or None (not optimal, not feasible)."""
    import daqp

    if Aeq is None:
        Aeq, beq = np.zeros((0, f.size)), np.zeros(0)
    A = np.ascontiguousarray(np.vstack([Aeq, Aineq]))
    upper = np.concatenate([beq, bineq])
    lower = np.concatenate([beq, np.full(bineq.size, -DAQP_INF)])
    sense = np.concatenate([np.full(beq.size, 5, np.int32), np.zeros(bineq.size, np.int32)])
    scale = max(float(np.abs(upper).max(initial=0.0)), 1.0)
    options = {"primal_tol": 1e-12 * scale, "iter_limit": 2000}
    if prox > 0:  # a linear program: DAQP's proximal-point iterations with this weight
        options["eps_prox"] = min(max(prox, 1e-12), 1e6)
    if start is not None and start.size:
        options["primal_start"] = np.asarray(start, float)
    x, _, flag, info = daqp.solve(np.ascontiguousarray(P), np.asarray(f, float), A, upper,
                                  lower, sense, **options)
    if flag != 1 or not np.all(np.isfinite(x)):
        return None
    x = np.asarray(x, float)
    if np.any(Aineq @ x > bineq + 1e-11 * scale) or np.any(
            np.abs(Aeq @ x - beq) > 1e-11 * scale):
        return None
    return x, np.asarray(info["lam"], float)[beq.size:]
