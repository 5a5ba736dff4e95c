"""MLCPs solved without the Schur reduction (A singular, ill-conditioned, or any A).

`lcp.solve` reduces an MLCP to an LCP by the Schur complement when A is well conditioned. When
it is not, an LCP method solves the *split* LCP of the full (u, v) system, u = u+ - u-:

    z = [u+, u-, v] >= 0,   w = [ A u + C v + a ; -(A u + C v + a) ; D u + B v + b ] >= 0,

whose first two blocks force A u + C v + a = 0 (both >= 0), so its solutions are exactly the
MLCP's (u+ = max(u, 0), u- = max(-u, 0) map a solution back). Methods with a native MLCP form
(newton-*, enumerate-mlcp) get the MLCP itself. Every answer's w and equality residual are
recomputed here, and a "solved" is polished on its pattern and judged as every answer of
`lcp.solve` is (lcp.accuracy's backward error and forward error bound on the full system,
verify.certify's scaled residuals, 1e-8): one that fails becomes "inaccurate".
"""

from __future__ import annotations

import itertools

import numpy as np

from ..acceptance.accuracy import assess_mlcp
from ..acceptance.residual import check
from ..problems.problem import LCP, MLCP, NotApplicable
from ..problems.solution import Solution, complementarity_residual
from ..registry import register

#: relative acceptance of an unreduced MLCP answer (verify.certify's default tol)
MLCP_TOL = 1e-8


def split_lcp(problem: MLCP) -> LCP:
    """The LCP of the full system with u split into nonnegative parts (module doc)."""
    A, C, D, B, a, b = problem.A, problem.C, problem.D, problem.B, problem.a, problem.b
    M = np.block([[A, -A, C], [-A, A, -C], [D, -D, B]])
    return LCP(M, np.concatenate([a, -a, b]), name=problem.name,
               meta={**problem.meta, "reduced_from": "MLCP (u split)"})


def _norm(X: np.ndarray) -> float:
    return float(np.max(np.sum(np.abs(X), axis=1))) if X.size else 0.0


def check_mlcp(problem: MLCP, sol: Solution, tol: float = MLCP_TOL,
               basis: np.ndarray | None = None) -> Solution:
    """Recompute w and the residuals of (u, v); a "solved" is polished on its pattern (`basis`:
    the basic v's when the method gives them) and judged as lcp.trust judges every answer
    (lcp.accuracy: backward error, forward error bound; lcp.residual's scaled residuals); one
    that fails becomes "inaccurate"."""
    v = np.asarray(sol.z, dtype=float)
    u = np.asarray(sol.u, dtype=float) if sol.u is not None else np.zeros(problem.nu)
    if v.shape != (problem.n,) or u.shape != (problem.nu,) or not (
            np.all(np.isfinite(v)) and np.all(np.isfinite(u))):
        sol.status = "failed" if sol.status == "solved" else sol.status
        sol.message = (sol.message + "; " if sol.message else "") + "method returned a bad u, v"
        v, u = np.zeros(problem.n), np.zeros(problem.nu)
    acc = None
    if sol.status == "solved":
        acc = assess_mlcp(problem, v, u, basis)
        if acc.refined:
            v, u = acc.v, acc.u
            sol.info["polished"] = True
        sol.backward_error, sol.forward_error = acc.berr, acc.ferr
    w, eq = problem.residuals(u, v)
    sol.z, sol.u, sol.w, sol.eq_residual = v, u, w, eq
    sol.residual = complementarity_residual(v, w)
    chk = check(problem, v, u, tol=tol)  # the acceptance test of lcp.solve and certify
    scaled, scaled_eq = chk.scaled_residual, chk.scaled_eq_residual
    sol.scaled_residual = max(scaled, scaled_eq)
    sol.info["scaled_residual"], sol.info["scaled_eq_residual"] = scaled, scaled_eq
    if sol.status == "solved" and not (scaled <= tol and scaled_eq <= tol and acc.accepted):
        sol.status = "inaccurate"
        sol.message = (sol.message + "; " if sol.message else "") + (
            f"the answer fails the MLCP check (backward error {acc.berr:.2e}, forward error "
            f"bound {acc.ferr:.2e}, scaled residual {scaled:.2e}, equality {scaled_eq:.2e}; "
            f"limits {tol:g} and lcp.accuracy.FERR_TOL), after polishing on its pattern")
    return sol


def solve_mlcp_unreduced(problem: MLCP, info, options: dict) -> Solution | None:
    """lcp.solve's MLCP branch: a native MLCP method; else None when the Schur reduction
    applies (the usual path); else the method on the split LCP."""
    basis = None  # the split LCP's basis indexes [u+; u-; v]: the pattern is read from v
    if "mlcp" in info.native:
        sol = info.native["mlcp"](problem, **options)
        basis = sol.basis
    else:
        try:
            problem.to_lcp()
            return None
        except NotApplicable as exc:
            why = str(exc)
        lcp = split_lcp(problem)
        if info.max_n is not None and lcp.n > info.max_n:
            raise NotApplicable(f"{why}; the split LCP of the full system has n = {lcp.n} > "
                                f"{info.max_n}, the limit of method {info.name!r}")
        sol = info.func(lcp.M, lcp.q, **options)
        z = np.asarray(sol.z, dtype=float)
        nu = problem.nu
        if z.shape == (lcp.n,):
            sol.u, sol.z = z[:nu] - z[nu:2 * nu], z[2 * nu:]
        sol.info["reduction"] = "u split into u+ - u- (A not reducible: " + why + ")"
    sol.method = info.name
    return check_mlcp(problem, sol, basis=basis)


#: enumerate-mlcp's limit on the number of complementarity pairs (2^m systems)
ENUM_MAX_M = 16


def _enum_mlcp(problem: MLCP, *, tol: float = 1e-9) -> Solution:
    """Every complementary pattern of the full system (no reduction, any A): for each index
    set alpha of basic v's, [A C_a; D_a B_aa] [u; v_a] = -[a; b_a] by least squares, kept when
    it solves those equations and v_a >= 0, w >= 0 (relative tol). The first found is
    returned; "infeasible" is not claimed (a singular system's affine set is sampled at its
    minimum-norm point only), the status is then "failed"."""
    A, C, D, B, a, b = problem.A, problem.C, problem.D, problem.B, problem.a, problem.b
    nu, m = problem.nu, problem.n
    if m > ENUM_MAX_M:
        raise NotApplicable(f"enumerate-mlcp is limited to m <= {ENUM_MAX_M} pairs; this MLCP "
                            f"has m = {m}")
    K = np.block([[A, C], [D, B]])
    rhs = -np.concatenate([a, b])
    scale = max(float(np.max(np.abs(rhs))), 1e-300)
    tried = 0
    for k in range(m + 1):
        for alpha in itertools.combinations(range(m), k):
            tried += 1
            idx = np.concatenate([np.arange(nu), nu + np.asarray(alpha, dtype=int)])
            sub = K[np.ix_(idx, idx)]
            x = np.linalg.lstsq(sub, rhs[idx], rcond=None)[0]
            full = np.zeros(nu + m)
            full[idx] = x
            res = K @ full - rhs  # = [A u + C v + a; w]
            xs = max(float(np.max(np.abs(full))), 1e-300)
            sc = scale + _norm(K) * xs
            if np.max(np.abs(res[idx])) > tol * sc:
                continue
            v, w = full[nu:], res[nu:]
            if np.min(v, initial=0.0) < -tol * xs or np.min(w, initial=0.0) < -tol * sc:
                continue
            sol = Solution(z=np.maximum(v, 0.0), w=w, status="solved", method="enumerate-mlcp",
                           iterations=tried, basis=np.asarray(alpha, dtype=int),
                           u=full[:nu].copy())
            return sol
    return Solution(z=np.zeros(m), w=b.copy(), status="failed", method="enumerate-mlcp",
                    iterations=tried, u=np.zeros(nu),
                    message=f"no complementary pattern of the {tried} gave a solution at their "
                    "least-squares points (no proof that none exists)")


@register(
    "enumerate-mlcp", accepts="small-n", max_n=ENUM_MAX_M, native={"mlcp": _enum_mlcp},
    description="Enumeration of the complementary patterns of the full MLCP system (any A, "
    "least squares on singular systems); an LCP is an MLCP without u.",
)
def enumerate_mlcp_lcp(M: np.ndarray, q: np.ndarray, *, tol: float = 1e-9) -> Solution:
    """An LCP as an MLCP with one trivial free unknown (u = 0: 1 u + 0 v + 0 = 0)."""
    m = q.size
    mlcp = MLCP(np.eye(1), np.zeros((1, m)), np.zeros((m, 1)), M, np.zeros(1), q)
    sol = _enum_mlcp(mlcp, tol=tol)
    sol.u = None
    return sol
