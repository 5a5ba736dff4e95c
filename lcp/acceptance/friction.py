"""`lcp.solve`'s branch for a 2D friction-contact problem and its one acceptance: a native
method (nsgs, states, a registered friction-2d method) gets the problem, an LCP method the
Glocker LCP (lcp.problems.friction), whose z is mapped to the forces r; every answer, whichever
route it took, is then judged by `finish` on the friction-contact conditions themselves
(lcp.acceptance.friction_accuracy: backward error, forward error bound of its contact states'
system, polished on them) and by its natural-map residual."""

from __future__ import annotations

import numpy as np

from ..errors import NotApplicable
from ..problems.friction import FrictionContact2D, natural_residual
from ..problems.solution import Solution
from .friction_accuracy import (
    OPEN,
    SLIDE_BACKWARD,
    SLIDE_FORWARD,
    STICK,
    assess_fc2d,
    states_of_glocker_basis,
)
from .residual import TOL

#: A friction-contact answer counts as solved at this relative natural-map residual.
FC_TOL = 1e-10


def _note(sol: Solution, text: str) -> None:
    sol.message = (sol.message + "; " if sol.message else "") + text


def finish(problem: FrictionContact2D, sol: Solution, tol: float = FC_TOL,
           states: np.ndarray | None = None) -> Solution:
    """The acceptance of every friction-contact answer. The method's r is never trusted: it
    is polished on its contact states (`states`, the method's final ones, or read off r) and
    judged (lcp.acceptance.friction_accuracy); u = W r + q and the natural-map residual are
    recomputed; z = r, w = u. A "solved" that fails (backward error > lcp.residual.TOL,
    forward error bound > lcp.accuracy.FERR_TOL or natural-map residual > `tol`) becomes
    "inaccurate", its errors in the message. A judged answer's contact states are counted in
    info["contact_states"] (open / sticking / sliding), which its repr shows; sol.basis stays
    the method's own (a Glocker LCP basis, or the states method's closed contacts)."""
    r = np.asarray(sol.z, dtype=float).reshape(-1)
    acc = None
    if r.shape != (problem.n,) or not np.all(np.isfinite(r)):
        sol.status = "failed" if sol.status == "solved" else sol.status
        _note(sol, "method returned a bad r")
        r = np.zeros(problem.n)
    elif sol.status == "solved":
        acc = assess_fc2d(problem, r, states)
        sol.backward_error, sol.forward_error = acc.berr, acc.ferr
        if acc.refined:
            r = acc.r
            sol.info["polished"] = True
    u = problem.u(r)
    res = natural_residual(problem, r, u)
    sol.z, sol.w, sol.residual = r, u, res
    if acc is not None:  # the judged answer's contact states (sol.basis is the method's own)
        st = acc.states
        sol.info["contact_states"] = {"open": int(np.sum(st == OPEN)),
                                      "sticking": int(np.sum(st == STICK)),
                                      "sliding": int(np.sum((st == SLIDE_FORWARD)
                                                            | (st == SLIDE_BACKWARD)))}
    sol.scaled_residual = res
    sol.info["natural_residual"] = res
    if acc is not None and not (res <= tol and acc.accepted):
        sol.status = "inaccurate"
        _note(sol, f"the answer fails the friction-contact acceptance test: backward error "
              f"{acc.berr:.3g}, forward error bound {acc.ferr:.3g}, relative natural-map "
              f"residual {res:.3g} (limits {TOL:g}, lcp.accuracy.FERR_TOL, {tol:g}), after "
              "polishing on its contact states")
    return sol


def solve_friction(problem: FrictionContact2D, info, options: dict) -> Solution:
    """lcp.solve's branch for a FrictionContact2D: native methods (nsgs, states, a registered
    friction-2d method) get the problem; LCP methods solve the Glocker LCP (then r is
    recovered, and the Glocker basis gives the contact states). One acceptance: `finish`."""
    tol = options.pop("fc_tol", FC_TOL)
    states = None
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
        if z.shape == (lcp_form.n,) and np.all(np.isfinite(z)):
            sol.info["lcp_residual"] = float(np.max(np.abs(np.minimum(z, lcp_form.M @ z
                                                                        + lcp_form.q))))
            sol.z = problem.r_from_lcp(z)
            if sol.basis is not None:
                states = states_of_glocker_basis(problem, sol.basis)
    sol.method = info.name
    return finish(problem, sol, tol, states)
