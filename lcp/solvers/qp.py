"""Symmetric PSD LCPs as quadratic programs (methods ``qp-clarabel`` and ``qp-osqp``).

For symmetric M the LCP (w = M z + q, 0 <= z perp w >= 0) is the KKT system of

    minimize 1/2 z' M z + q' z   subject to z >= 0,

with w the multiplier of z >= 0; for positive semidefinite M the QP is convex, every KKT point
is a minimizer and conversely, and the QP is unbounded below exactly when the LCP has no
solution (Cottle, Pang & Stone 1992, Sec. 1.2 and Thm 3.1.2). A non-symmetric M is not the
Hessian of anything and an indefinite one makes KKT points non-global: both are refused with
NotApplicable, never solved wrongly.

Backends, through their own Python APIs (no modelling layer): Clarabel (interior point,
Goulart & Chen 2024) and OSQP (ADMM, Stellato et al. 2020; first order, so its raw answer is
accurate to its eps only). The answer is then *polished*: on the estimated active set
alpha = {i : z_i > w_i} the equations M_aa z_a = -q_a are solved by least squares starting
from the solver's point (minimum-norm correction, so that on a singular M_aa the point stays
where the solver put it), z_b = 0; entries that turn negative leave alpha and the solve is
repeated; the polished point is kept only if it lowers the residual max|min(z, w)|.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
from scipy.linalg import lstsq

from ..problems.problem import InvalidProblem, NotApplicable
from ..problems.solution import Solution, complementarity_residual
from ..quiet import quiet_stdout
from ..registry import register


def check_symmetric_psd(M: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """Return the symmetric part of M, or raise NotApplicable saying how M fails.

    Symmetric: max|M - M'| <= tol * max|M|. PSD: the least eigenvalue of (M + M')/2 is at least
    -tol * (its largest |eigenvalue|) -- rounding in forming M (e.g. A A') stays far inside.
    """
    scale = float(np.max(np.abs(M))) or 1.0
    asym = float(np.max(np.abs(M - M.T)))
    if asym > tol * scale:
        i, j = np.unravel_index(int(np.argmax(np.abs(M - M.T))), M.shape)
        raise NotApplicable(
            f"M is not symmetric (|M[{i},{j}] - M[{j},{i}]| = {asym:.3g}, relative "
            f"{asym / scale:.3g} > {tol:g}): the QP form applies only to symmetric PSD M; "
            "use 'lemke' or 'pivoting'"
        )
    S = 0.5 * (M + M.T)
    lam = np.linalg.eigvalsh(S)
    big = max(float(np.max(np.abs(lam))), 1e-300)
    if lam[0] < -tol * big:
        raise NotApplicable(
            f"M is not positive semidefinite (least eigenvalue {lam[0]:.3g}, relative "
            f"{lam[0] / big:.3g} < -{tol:g}): the QP is non-convex and its KKT points need not "
            "solve the LCP globally; use 'lemke' or 'pivoting'"
        )
    return S


def active_set_polish(
    M: np.ndarray, q: np.ndarray, z: np.ndarray, rounds: int = 6
) -> tuple[np.ndarray, int]:
    """Active-set least-squares polish of an approximate solution (see module doc).

    Each round takes alpha = {i : z_i > w_i} at the current point and moves z_a to the
    nearest solution of M_aa z_a = -q_a (minimum-norm least-squares correction), z_b = 0.
    Entries that come out negative are clipped and kept out of alpha afterwards (on a
    degenerate or singular problem the nearest point of the affine set may lie slightly outside
    z >= 0); rounds stop when alpha repeats. For symmetric PSD M any z_a >= 0 solving those
    equations, with alpha inside {w* = 0} and containing the support of a solution z*, is
    itself a solution: M (z - z*) = 0 follows from (z - z*)' M (z - z*) = 0.
    Returns the best point met (never worse than max(z, 0)) and the number of rounds run.
    """
    z = np.maximum(z, 0.0)
    w = M @ z + q
    best_z, best = z, complementarity_residual(z, w)
    dropped = np.zeros(z.size, dtype=bool)
    seen: set[bytes] = set()
    done = 0
    for _ in range(rounds):
        a = np.flatnonzero((z > w) & ~dropped)
        if best == 0.0 or a.tobytes() in seen:
            break
        seen.add(a.tobytes())
        done += 1
        trial = np.zeros_like(z)
        if a.size:
            Maa = M[np.ix_(a, a)]
            r = Maa @ z[a] + q[a]
            za = z[a] + lstsq(Maa, -r, cond=1e-13, check_finite=False)[0]
            dropped[a[za < 0]] = True
            trial[a] = np.maximum(za, 0.0)
        z, w = trial, M @ trial + q
        res = complementarity_residual(z, w)
        if res < best:
            best_z, best = z, res
    return best_z, done


def _check_options(eps: float, max_iter: int, tol: float) -> None:
    if not (isinstance(eps, (int, float)) and math.isfinite(eps) and eps > 0):
        raise InvalidProblem(f"eps must be a positive number, got {eps!r}")
    if not (isinstance(max_iter, (int, np.integer)) and max_iter > 0):
        raise InvalidProblem(f"max_iter must be a positive integer, got {max_iter!r}")
    if not (isinstance(tol, (int, float)) and math.isfinite(tol) and tol > 0):
        raise InvalidProblem(f"tol must be a positive number, got {tol!r}")


def _finish(M, q, x, method: str, solver_status: str, solver_ok: bool, iters: int,
            do_polish: bool, tol: float, info: dict) -> Solution:
    z = np.maximum(np.asarray(x, dtype=float), 0.0)
    raw = complementarity_residual(z, M @ z + q)
    info.update(solver_status=solver_status, raw_residual=raw)
    if do_polish and np.all(np.isfinite(z)):
        z, info["polish_rounds"] = active_set_polish(M, q, z)
    w = M @ z + q
    res = complementarity_residual(z, w)
    target = tol * max(1.0, float(np.max(np.abs(q))))
    basis = np.flatnonzero(z > w)
    if solver_ok and res <= target:
        return Solution(z=z, w=w, status="solved", method=method, iterations=iters,
                        basis=basis, info=info)
    return Solution(
        z=z, w=w, status="not_converged", method=method, iterations=iters, basis=basis,
        message=f"solver status {solver_status!r}; residual {res:.3e} (target {target:.3e})",
        info=info,
    )


def _unbounded(M, q, d, method: str, solver_status: str, iters: int) -> Solution:
    """The QP is unbounded below: for PSD M the LCP has no solution."""
    info: dict = {"solver_status": solver_status}
    d = np.asarray(d, dtype=float) if d is not None else None
    if d is not None and np.all(np.isfinite(d)) and np.max(np.abs(d)) > 0:
        d = d / np.max(np.abs(d))
        info["ray"] = d  # a direction d >= 0 with M d ~ 0 and q'd < 0
        info["ray_check"] = {"min_d": float(d.min()), "max_abs_Md": float(np.max(np.abs(M @ d))),
                             "q_dot_d": float(q @ d)}
    n = q.size
    return Solution(
        z=np.zeros(n), w=q.copy(), status="infeasible", method=method, iterations=iters,
        message="the QP is unbounded below (solver certificate): for symmetric PSD M the LCP "
        "has no solution (Cottle-Pang-Stone Thm 3.1.2)", info=info,
    )


@register(
    "qp-clarabel", accepts="symmetric-psd",
    description="min 1/2 z'Mz + q'z, z >= 0 by Clarabel (interior point), then active-set "
    "polish.",
)
def solve_qp_clarabel(
    M: np.ndarray, q: np.ndarray, *, eps: float = 1e-10, max_iter: int = 200,
    polish: bool = True, tol: float = 1e-8, psd_tol: float = 1e-9,
) -> Solution:
    """Solve a symmetric PSD LCP as a convex QP with Clarabel (module doc).

    eps: Clarabel's gap and feasibility tolerances; max_iter: its iteration limit; polish: run
    the active-set polish; tol: "solved" needs max|min(z, w)| <= tol * max(1, |q|_inf);
    psd_tol: relative tolerance of the symmetry and PSD checks. Status "solved",
    "not_converged", "infeasible" (QP unbounded; ``info["ray"]``) or "failed".
    """
    import clarabel

    _check_options(eps, max_iter, tol)
    S = check_symmetric_psd(M, psd_tol)
    n = q.size
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.max_iter = int(max_iter)
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = eps
    settings.tol_ktratio = min(settings.tol_ktratio, eps)
    P = sp.csc_matrix(np.triu(S))
    A = -sp.identity(n, format="csc")  # s = 0 - A z = z in the nonnegative cone
    solver = clarabel.DefaultSolver(P, q, A, np.zeros(n), [clarabel.NonnegativeConeT(n)],
                                    settings)
    out = solver.solve()
    status = str(out.status)
    if status in ("DualInfeasible", "AlmostDualInfeasible"):
        return _unbounded(M, q, out.x, "qp-clarabel", status, out.iterations)
    # Any answer is checked below: "solved" only when its residual meets tol.
    ok = status in ("Solved", "AlmostSolved", "MaxIterations", "InsufficientProgress")
    x = np.asarray(out.x, dtype=float)
    if x.shape != (n,) or not np.all(np.isfinite(x)):
        return Solution(z=np.zeros(n), w=q.copy(), status="failed", method="qp-clarabel",
                        iterations=out.iterations, message=f"Clarabel status {status!r}",
                        info={"solver_status": status})
    return _finish(M, q, x, "qp-clarabel", status, ok, out.iterations, polish, tol, {})


@register(
    "qp-osqp", accepts="symmetric-psd",
    description="min 1/2 z'Mz + q'z, z >= 0 by OSQP (ADMM, first order; its own polishing), "
    "then active-set polish.",
)
def solve_qp_osqp(
    M: np.ndarray, q: np.ndarray, *, eps: float = 1e-10, max_iter: int = 100_000,
    polish: bool = True, tol: float = 1e-8, psd_tol: float = 1e-9,
) -> Solution:
    """Solve a symmetric PSD LCP as a convex QP with OSQP (module doc).

    eps: OSQP's eps_abs and eps_rel; max_iter: its ADMM iteration limit; polish: OSQP's own
    polishing and then the active-set polish; tol, psd_tol: as for qp-clarabel. Status
    "solved", "not_converged", "infeasible" (QP unbounded; ``info["ray"]``) or "failed".
    """
    import osqp

    _check_options(eps, max_iter, tol)
    S = check_symmetric_psd(M, psd_tol)
    n = q.size
    prob = osqp.OSQP()
    prob.setup(
        sp.csc_matrix(np.triu(S)), q, sp.identity(n, format="csc"), np.zeros(n),
        np.full(n, np.inf), verbose=False, eps_abs=eps, eps_rel=eps, max_iter=int(max_iter),
        polishing=bool(polish),
    )
    with quiet_stdout():
        out = prob.solve(raise_error=False)
    status = str(out.info.status)
    iters = int(out.info.iter)
    if status.startswith("dual infeasible"):
        d = getattr(out, "dual_inf_cert", None)
        return _unbounded(M, q, d, "qp-osqp", status, iters)
    x = np.asarray(out.x, dtype=float) if out.x is not None else np.full(n, np.nan)
    if x.shape != (n,) or not np.all(np.isfinite(x)):
        return Solution(z=np.zeros(n), w=q.copy(), status="failed", method="qp-osqp",
                        iterations=iters, message=f"OSQP status {status!r}",
                        info={"solver_status": status})
    # Any answer is checked below: "solved" only when its residual meets tol.
    ok = status in ("solved", "solved inaccurate", "maximum iterations reached")
    info = {"osqp_polish": int(getattr(out.info, "status_polish", 0))}
    return _finish(M, q, x, "qp-osqp", status, ok, iters, polish, tol, info)
