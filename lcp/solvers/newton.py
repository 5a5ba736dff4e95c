"""Semismooth Newton methods (``newton-min``, ``newton-fb``) for LCPs and MLCPs.

The MLCP  A u + C v + a = 0,  w = D u + B v + b,  0 <= v perp w >= 0  (an LCP has no u) is the
square nonsmooth system H(x) = 0, x = (u, v),

    H(x) = [ A u + C v + a ;  phi(v_i, w_i) for every pair i ],

with an NCP function phi, zero iff 0 <= v_i perp w_i >= 0:

* min map (``newton-min``): phi(a, b) = min(a, b) (Pang's B-differentiable Newton; Siconos's
  newton_min);
* Fischer-Burmeister (``newton-fb``): phi(a, b) = sqrt(a^2 + b^2) - a - b (De Luca, Facchinei &
  Kanzow, Math. Program. 75, 407, 1996; Siconos's newton_FB; PATH's merit function).

Each iteration solves J d = -H(x) with an element J of the generalized (Clarke / B-)
Jacobian (a singular J: least squares) and globalizes with an Armijo line search on the merit
function Psi(x) = |H(x)|^2 / 2: the step t = 1, beta, beta^2, ... is taken when

    Psi(x + t d) <= Psi(x) + sigma t grad Psi(x) . d        (Fischer-Burmeister: Psi is C^1)
    Psi(x + t d) <= (1 - 2 sigma t) Psi(x)                   (min map: grad Psi . d = -2 Psi
                                                              for the Newton direction)

For Fischer-Burmeister, a Newton direction that is not a good descent direction
(grad Psi . d > -rho |d|^2.1) is replaced by the steepest descent -grad Psi (the DFK rule).

Statuses: "solved" (max|H| <= tol times the data scale), "max_iter", "not_converged" (the line
search fails: x is a stationary point of Psi that does not solve the problem; Newton methods
prove nothing about existence), "failed" (non-finite iterate). `lcp.solve` recomputes w and the
residual of the answer itself.
"""

from __future__ import annotations

import numpy as np

from ..problems.problem import MLCP, InvalidProblem
from ..problems.solution import Solution
from ..registry import register

SIGMA, BETA, RHO, P_DFK = 1e-4, 0.5, 1e-10, 2.1


def _check(tol: float, max_iter: int) -> None:
    if not (isinstance(tol, (int, float)) and 0 < tol < 1):
        raise InvalidProblem(f"tol must be in (0, 1), got {tol!r}")
    if not (isinstance(max_iter, int) and max_iter >= 1):
        raise InvalidProblem(f"max_iter must be a positive integer, got {max_iter!r}")


def newton_mixed(A, C, D, B, a, b, *, phi: str, tol: float = 1e-12, max_iter: int = 100,
                 x0: np.ndarray | None = None) -> Solution:
    """Semismooth Newton on H(x) (module doc); A may be 0 x 0 (an LCP). Returns the Solution
    with z = v and u set (u is None for an LCP)."""
    _check(tol, max_iter)
    nu, m = a.size, b.size
    N = nu + m
    top = np.hstack([A, C]) if nu else np.zeros((0, N))
    bot = np.hstack([D, B]) if nu else B
    scale = max(float(np.max(np.abs(np.concatenate([a, b])), initial=0.0)),
                float(np.max(np.abs(np.vstack([top, bot])), initial=0.0)) * 1e-16, 1e-300)
    x = np.zeros(N) if x0 is None else np.asarray(x0, dtype=float).copy()

    def H(x: np.ndarray):
        v = x[nu:]
        w = bot @ x + b
        eq = top @ x + a
        if phi == "min":
            f = np.minimum(v, w)
        else:
            f = np.hypot(v, w) - v - w
        return np.concatenate([eq, f]), v, w

    def jac(v: np.ndarray, w: np.ndarray) -> np.ndarray:
        J = np.zeros((N, N))
        J[:nu] = top
        if phi == "min":
            rows = np.flatnonzero(v <= w)
            Jb = bot.copy()
            Jb[rows] = 0.0
            Jb[rows, nu + rows] = 1.0
            J[nu:] = Jb
            return J
        r = np.hypot(v, w)
        zero = r <= 1e-300
        rr = np.where(zero, 1.0, r)
        da = np.where(zero, 1 / np.sqrt(2) - 1, v / rr - 1)
        db = np.where(zero, 1 / np.sqrt(2) - 1, w / rr - 1)
        Jb = db[:, None] * bot
        Jb[np.arange(m), nu + np.arange(m)] += da
        J[nu:] = Jb
        return J

    h, v, w = H(x)
    psi = 0.5 * float(h @ h)
    status, message, it, steps = "max_iter", "", 0, {"newton": 0, "gradient": 0, "lstsq": 0}
    for it in range(1, max_iter + 1):
        if np.max(np.abs(h), initial=0.0) <= tol * scale:
            status, it = "solved", it - 1
            break
        J = jac(v, w)
        try:
            d = np.linalg.solve(J, -h)
            if not np.all(np.isfinite(d)):
                raise np.linalg.LinAlgError
        except np.linalg.LinAlgError:
            d = np.linalg.lstsq(J, -h, rcond=None)[0]
            steps["lstsq"] += 1
        grad = J.T @ h
        slope = float(grad @ d)
        if phi == "fb" and slope > -RHO * float(np.linalg.norm(d)) ** P_DFK:
            d, slope = -grad, -float(grad @ grad)
            steps["gradient"] += 1
        else:
            steps["newton"] += 1
        t, accepted = 1.0, False
        while t > 1e-12:
            x_new = x + t * d
            h_new, v_new, w_new = H(x_new)
            psi_new = 0.5 * float(h_new @ h_new)
            bound = (psi + SIGMA * t * slope) if phi == "fb" else (1 - 2 * SIGMA * t) * psi
            if psi_new <= bound:
                accepted = True
                break
            t *= BETA
        if not accepted:
            if phi == "min" and float(grad @ grad) > 0:  # fall back on a gradient step
                d = -grad
                t = 1.0
                while t > 1e-12:
                    x_new = x + t * d
                    h_new, v_new, w_new = H(x_new)
                    psi_new = 0.5 * float(h_new @ h_new)
                    if psi_new <= psi - SIGMA * t * float(grad @ grad):
                        accepted = True
                        steps["gradient"] += 1
                        break
                    t *= BETA
            if not accepted:
                status = "not_converged"
                message = (f"the line search failed at iteration {it} (merit {psi:.3e}): a "
                           "stationary point of the merit function that is not a solution")
                break
        x, h, v, w, psi = x_new, h_new, v_new, w_new, psi_new
        if not np.all(np.isfinite(x)):
            status, message = "failed", "the iterate is not finite"
            break
    else:
        if np.max(np.abs(h), initial=0.0) <= tol * scale:
            status = "solved"
        else:
            message = f"max|H| = {np.max(np.abs(h)):.3e} after {max_iter} iterations"
    v = np.maximum(x[nu:], 0.0) if status == "solved" else x[nu:]
    sol = Solution(z=v.copy(), w=bot @ x + b, status=status, method=f"newton-{phi}",
                   iterations=it, message=message,
                   info={"merit": psi, "steps": steps})
    if status == "solved":
        sol.basis = np.flatnonzero(v > w)
    if nu:
        sol.u = x[:nu].copy()
    return sol


def _lcp(phi: str):
    def solve_lcp(M: np.ndarray, q: np.ndarray, *, tol: float = 1e-12, max_iter: int = 100,
                  z0: np.ndarray | None = None) -> Solution:
        e = np.zeros((0, 0))
        return newton_mixed(e, np.zeros((0, q.size)), np.zeros((q.size, 0)), M, np.zeros(0), q,
                            phi=phi, tol=tol, max_iter=max_iter, x0=z0)
    return solve_lcp


def _mlcp(phi: str):
    def solve_mlcp(problem: MLCP, *, tol: float = 1e-12, max_iter: int = 100,
                   z0: np.ndarray | None = None) -> Solution:
        x0 = None if z0 is None else np.concatenate([np.zeros(problem.nu), z0])
        return newton_mixed(problem.A, problem.C, problem.D, problem.B, problem.a, problem.b,
                            phi=phi, tol=tol, max_iter=max_iter, x0=x0)
    return solve_mlcp


newton_min = register(
    "newton-min", accepts="any", native={"mlcp": _mlcp("min")},
    description="Semismooth Newton on the min map with an Armijo line search (LCP; MLCP "
    "unreduced, any A; FC2D by its Glocker LCP); local, no existence proof.",
)(_lcp("min"))

newton_fb = register(
    "newton-fb", accepts="any", native={"mlcp": _mlcp("fb")},
    description="Semismooth Newton on the Fischer-Burmeister function with an Armijo line "
    "search on its merit (LCP; MLCP unreduced; FC2D by its Glocker LCP).",
)(_lcp("fb"))
