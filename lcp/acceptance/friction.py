"""`lcp.solve`'s branch for a 2D friction-contact problem and its acceptance: a native method
(nsgs, states, newton-*) gets the problem, an LCP method the Glocker LCP (lcp.problems.friction),
whose answer is judged as every LCP answer is (lcp.acceptance.accuracy.judge_lcp); then r is
recovered and its natural-map residual recomputed (`finish`)."""

from __future__ import annotations

import numpy as np

from ..errors import NotApplicable
from ..problems.friction import FrictionContact2D, natural_residual
from ..problems.solution import Solution
from .accuracy import judge_lcp

#: A friction-contact answer counts as solved at this relative natural-map residual.
FC_TOL = 1e-10


def finish(problem: FrictionContact2D, sol: Solution, tol: float = FC_TOL) -> Solution:
    """Recompute u = W r + q and the residual of a method's r (never trusted), set z = r,
    w = u; a "solved" above `tol` becomes "not_converged" with the number in the message."""
    r = np.asarray(sol.z, dtype=float).reshape(-1)
    if r.shape != (problem.n,) or not np.all(np.isfinite(r)):
        sol.status = "failed" if sol.status == "solved" else sol.status
        sol.message = (sol.message + "; " if sol.message else "") + "method returned a bad r"
        r = np.zeros(problem.n)
    u = problem.u(r)
    res = natural_residual(problem, r, u)
    sol.z, sol.w, sol.residual = r, u, res
    sol.info["natural_residual"] = res
    if sol.status == "solved" and not res <= tol:
        sol.status = "not_converged"
        sol.message = (sol.message + "; " if sol.message else "") + (
            f"relative natural-map residual {res:.3e} > {tol:g}")
    return sol


def solve_friction(problem: FrictionContact2D, info, options: dict) -> Solution:
    """lcp.solve's branch for a FrictionContact2D: native methods (nsgs, states, newton-*)
    get the problem; LCP methods solve the Glocker LCP (then r is recovered)."""
    tol = options.pop("fc_tol", FC_TOL)
    if "friction-2d" in info.native:
        sol = info.native["friction-2d"](problem, **options)
    elif info.accepts == "friction-2d":
        sol = info.func(problem, **options)
    else:
        lcp_form = problem.to_lcp()
        if info.max_n is not None and lcp_form.n > info.max_n:
            raise NotApplicable(f"method {info.name!r} is limited to n <= {info.max_n}; the "
                                f"Glocker LCP of this problem has n = {lcp_form.n}")
        sol = info.func(lcp_form.M, lcp_form.q, **options)
        z = np.asarray(sol.z, dtype=float)
        if sol.status == "solved" and z.shape == (lcp_form.n,) and np.all(np.isfinite(z)):
            # lcp.trust's verdict on the Glocker LCP: polished on the basis, both errors
            ok, z, _, _, _, acc = judge_lcp(lcp_form.M, lcp_form.q, z, sol.basis)
            sol.backward_error, sol.forward_error = acc.berr, acc.ferr
            if acc.refined:
                sol.info["polished"] = True
            if not ok:
                sol.status = "inaccurate"
                sol.message = (sol.message + "; " if sol.message else "") + (
                    f"the Glocker LCP answer fails the acceptance test (backward error "
                    f"{acc.berr:.3g}, forward error bound {acc.ferr:.3g})")
        if z.shape == (lcp_form.n,) and np.all(np.isfinite(z)):
            sol.info["lcp_residual"] = float(np.max(np.abs(np.minimum(z, lcp_form.M @ z
                                                                        + lcp_form.q))))
            sol.z = problem.r_from_lcp(z)
    sol.method = info.name
    return finish(problem, sol, tol)
