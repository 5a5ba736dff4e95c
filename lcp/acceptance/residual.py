"""The one definition of "solved": the scaled residual and the tolerance of acceptance.

`lcp.solve` checks every answer with `check`, and `verify.certify` accepts with the same
function, so a status "solved" and a certificate "ACCEPTED" can never disagree.

LCP (w = M z + q, 0 <= z perp w >= 0). With the scales

    z_s = max(|z|_inf, |q|_inf / |M|_max),        w_s = |q|_inf + ||M||_inf z_s,

(||.||_inf the largest row sum of |M|) the scaled residual is max_i |min(z_i / z_s, w_i / w_s)|:
zero iff z >= 0, w >= 0 and z_i w_i = 0, and invariant when (M, q) is multiplied by a positive
number or z's unit changes. MLCP (A u + C v + a = 0, w = D u + B v + b): the complementarity part
is measured on the Schur-reduced LCP (M = B - D A^-1 C, q = b - D A^-1 a) when A is invertible,
else with z_s = max(|v|_inf, |b|_inf / ||B||_inf) and w_s = |b|_inf + ||D||_inf |u|_inf +
||B||_inf |v|_inf (lcp.mlcp_full.check_mlcp uses this function); the equality residual
max|A u + C v + a| is divided by |a|_inf + ||A||_inf |u|_inf + ||C||_inf |v|_inf. Accepted iff
both are <= TOL.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import rigidlcp.lcp._lemke_kernel as _kernel

#: Tolerance on the scaled residuals below which an answer is a solution (verify.certify's
#: default `tol`).
TOL = 1e-8


def scales(M: np.ndarray, q: np.ndarray, z: np.ndarray) -> tuple[float, float]:
    """(z_s, w_s): the solution scale max(|z|_inf, |q|_inf/|M|_max) and the w scale
    |q|_inf + ||M||_inf z_s (||.||_inf the max row sum of |M|)."""
    return _scales(M, q, z, norm_inf(M))


def _scales(M: np.ndarray, q: np.ndarray, z: np.ndarray, norm: float) -> tuple[float, float]:
    mmax = float(np.max(np.abs(M))) if M.size else 0.0
    qmax = float(np.max(np.abs(q))) if q.size else 0.0
    zmax = float(np.max(np.abs(z))) if z.size else 0.0
    zs = max(zmax, qmax / mmax if mmax > 0 else 0.0)
    if zs == 0.0:
        zs = 1.0  # z = 0, q = 0: any unit is as good
    ws = qmax + norm * zs if M.size else qmax
    return zs, (ws if ws > 0 else 1.0)  # M = 0 and q = 0: w = 0 exactly


def norm_inf(A: np.ndarray) -> float:
    """||A||_inf, the largest row sum of |A| (0 for an empty matrix)."""
    return float(np.max(np.sum(np.abs(A), axis=1))) if A.size else 0.0


def scaled_residual(M: np.ndarray, q: np.ndarray, z: np.ndarray) -> float:
    """max_i |min(z_i / z_s, w_i / w_s)| with w = M z + q: zero iff (z, w) is complementary."""
    if z.size == 0:
        return 0.0
    zs, ws = scales(M, q, z)
    w = M @ z + q
    return float(np.max(np.abs(np.minimum(z / zs, w / ws))))


def lcp_measure(M: np.ndarray, q: np.ndarray, z: np.ndarray
                ) -> tuple[np.ndarray, float, float, float, float]:
    """(w, max|min(z, w)|, scaled residual, z_s, w_s) of z on the LCP (M, q), w = M z + q: what
    `check` measures on an LCP (`check` calls it), the scaled residual of the module docstring.

    M z is computed by numpy (BLAS); the rest -- w = M z + q, the row sums of |M| (summed in
    numpy's order), maxima, scales and minima -- in C when the extension is built
    (lcp/_lemke_kernel.py's `measure`: the same operations in the same order, hence the same
    numbers; tests/lcp/test_fast_lemke.py compares the two), else by the numpy code below. No
    error state is set here: `check` ignores overflow of a diverged z, and `lcp.solve`'s fast
    path calls it only where nothing can overflow."""
    w = M.dot(z)  # M @ z: the same BLAS call (gemv)
    got = _kernel.measure(M, q, z, w) if z.size else None
    if got is not None:  # w is now M z + q
        return (w, *got)
    w = w + q
    rows = np.add.reduce(np.abs(M), axis=1)  # np.sum(np.abs(M), axis=1), as norm_inf
    zs, ws = _scales(M, q, z, float(np.max(rows)) if M.size else 0.0)
    scaled = float(np.max(np.abs(np.minimum(z / zs, w / ws)))) if z.size else 0.0
    raw = float(np.max(np.abs(np.minimum(z, w)))) if z.size else 0.0
    return w, raw, scaled, zs, ws


@dataclass
class Check:
    """The measured quality of an answer z (and u for an MLCP) on the user's problem."""

    w: np.ndarray
    residual: float  # max|min(z, w)|, unscaled
    scaled_residual: float
    eq_residual: float = 0.0  # MLCP: max|A u + C v + a|
    scaled_eq_residual: float = 0.0
    z_scale: float = 1.0
    w_scale: float = 1.0
    tol: float = TOL
    u: np.ndarray | None = None  # MLCP: the free unknowns measured with v

    @property
    def accepted(self) -> bool:
        return bool(self.scaled_residual <= self.tol and self.scaled_eq_residual <= self.tol)


def check(problem, z: np.ndarray, u: np.ndarray | None = None, tol: float = TOL,
          lcp_form=None) -> Check:
    """Measure z (for an MLCP: v, with u recovered if not given) on `problem`, an LCP or MLCP.

    `lcp_form`: the Schur-reduced LCP of an MLCP when the caller has it (None: reduced here, or
    the direct scales when A is singular). The result's `accepted` is the definition of solved.
    """
    z = np.asarray(z, dtype=float).reshape(-1)
    with np.errstate(all="ignore"):  # a diverged z gives inf / nan: measured, never accepted
        return _check(problem, z, u, tol, lcp_form)


def _check(problem, z: np.ndarray, u, tol: float, lcp_form) -> Check:
    if hasattr(problem, "M"):  # an LCP
        w, raw, scaled, zs, ws = lcp_measure(problem.M, problem.q, z)
        return Check(w=w, residual=raw, scaled_residual=scaled, eq_residual=0.0,
                     scaled_eq_residual=0.0, z_scale=zs, w_scale=ws, tol=tol, u=u)
    if u is None:
        u = problem.recover_u(z)
    w, eq = problem.residuals(u, z)
    eq_scale = (float(np.max(np.abs(problem.a)))
                + norm_inf(problem.A) * float(np.max(np.abs(u), initial=0.0))
                + norm_inf(problem.C) * float(np.max(np.abs(z), initial=0.0)))
    eq_scaled = eq / eq_scale if eq_scale > 0 else eq
    if lcp_form is None:
        try:
            lcp_form = problem.to_lcp()
        except ValueError:  # NotApplicable: A singular, no Schur reduction
            lcp_form = None
    if lcp_form is not None:
        zs, ws = scales(lcp_form.M, lcp_form.q, z)
    else:  # no Schur reduction (A singular): the scales of the full system
        un = float(np.max(np.abs(u), initial=0.0))
        vn = float(np.max(np.abs(z), initial=0.0))
        bn = float(np.max(np.abs(problem.b), initial=0.0))
        zs = max(vn, bn / max(norm_inf(problem.B), 1e-300), 1e-300)
        ws = max(bn + norm_inf(problem.D) * un + norm_inf(problem.B) * vn, 1e-300)
    scaled = float(np.max(np.abs(np.minimum(z / zs, w / ws)))) if z.size else 0.0
    raw = float(np.max(np.abs(np.minimum(z, w)))) if z.size else 0.0
    return Check(w=w, residual=raw, scaled_residual=scaled, eq_residual=float(eq),
                 scaled_eq_residual=float(eq_scaled), z_scale=zs, w_scale=ws, tol=tol, u=u)
