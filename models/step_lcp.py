"""The LCP of one Moreau-Jean step and its check (models.timestepping's derivation, in its
module docstring): `StepProblem` builds w = M z + q over z = [P_n (c), tau (k), u_minus (k)]
for given predicted sliding contacts, `coulomb_residual` measures the velocity-level laws of
a step from (P, u) directly. Split out of models/timestepping.py (one job per module; both
names are re-exported there)."""

from __future__ import annotations

import numpy as np

from rigidlcp import lcp

from .dynamics import Dynamics
from .system import System


class StepProblem:
    """The LCP of a step for given predicted sliding contacts (P_t = -s mu P_n substituted, as
    Eq. 2.10 at velocity level; checked a posteriori by the Coulomb residual of the whole
    step) and candidates (the split above). M depends on that choice only; q = the free
    velocities b."""

    def __init__(self, system: System, dyn: Dynamics, s_fixed: np.ndarray):
        c, mu = system.c, system.mu
        self.system, self.dyn = system, dyn
        fric = mu > 0
        self.s_fixed = np.where(fric, s_fixed, 0).astype(int)
        self.cand = np.flatnonzero(fric & (self.s_fixed == 0))
        k = self.k = self.cand.size
        n = self.n = c + 2 * k
        G = np.zeros((2 * c, n))
        G[np.arange(c), np.arange(c)] = 1.0
        G[c + np.arange(c), np.arange(c)] = -self.s_fixed * mu  # sliding: P_t = -s mu P_n
        G[c + self.cand, self.cand] = -mu[self.cand]  # candidates: P_t = tau - mu P_n
        G[c + self.cand, c + np.arange(k)] = 1.0
        WG = dyn.W @ G
        M = np.zeros((n, n))
        M[:c] = WG[:c]  # u_n
        M[c:c + k] = WG[c:][self.cand]  # u_t ...
        M[c:c + k, c + k:] += np.eye(k)  # ... + u_minus = u_plus
        M[c + k + np.arange(k), self.cand] = 2.0 * mu[self.cand]  # 2 mu P_n - tau
        M[c + k:, c:c + k] -= np.eye(k)
        self.G, self.M = G, M

    def lcp(self, b: np.ndarray, t: float) -> lcp.LCP:
        c, k = self.system.c, self.k
        q = np.concatenate([b[:c], b[c:][self.cand], np.zeros(k)])
        return lcp.LCP(self.M, q, name="moreau-jean step", meta={"t": t})

    def warm_active(self, P: np.ndarray, ut: np.ndarray) -> np.ndarray:
        """Basic variables guessed from the previous step: P_n > 0; tau > 0 unless the
        contact slid forwards (P_t = -mu P_n); u_minus > 0 when it slid backwards."""
        c, k = self.system.c, self.k
        active = list(np.flatnonzero(P[:c] > 0))
        for pos, alpha in enumerate(self.cand):
            if ut[alpha] <= 0:
                active.append(c + pos)
            if ut[alpha] < 0:
                active.append(c + k + pos)
        return np.array(sorted(active), dtype=int)


def coulomb_residual(system: System, P: np.ndarray, u: np.ndarray, P_scale: float,
                     u_scale: float) -> float:
    """Scaled residual of the velocity-level laws of a step (natural maps, each 0 iff the law
    holds): Signorini |min(P_n / Ps, u_n / us)| and Coulomb
    |P_t - proj_[-mu P_n, mu P_n](P_t - u_t Ps / us)| / Ps, maximized over the contacts."""
    c, mu = system.c, system.mu
    Pn, Pt, un, ut = P[:c] / P_scale, P[c:] / P_scale, u[:c] / u_scale, u[c:] / u_scale
    r_n = np.abs(np.minimum(Pn, un))
    bound = mu * np.maximum(Pn, 0.0)
    r_t = np.abs(Pt - np.clip(Pt - ut, -bound, bound))
    return float(max(r_n.max(initial=0.0), r_t.max(initial=0.0)))


def solve_step(problem: lcp.LCP, opts, warm: np.ndarray | None):
    """Warm pivoting from the previous step's basis (when given), then opts.method, then
    opts.fallback (opts: models.timestepping.StepOptions).
    Returns (solution, name of the method that produced it, whether a fallback was used)."""
    tried = []
    if warm is not None:
        sol = lcp.solve(problem, "pivoting", active=warm, max_iter=20)
        if sol.status == "solved":
            return sol, "pivoting-warm", False
        tried.append(f"pivoting-warm: {sol.status}")
    sol = lcp.solve(problem, opts.method)
    if sol.status == "solved" or opts.fallback is None or opts.fallback == opts.method:
        if tried and sol.status != "solved":
            sol.message = "; ".join(tried + [f"{opts.method}: {sol.message}"])
        return sol, opts.method, False
    first = sol
    sol = lcp.solve(problem, opts.fallback)
    if sol.status != "solved":
        sol.message = "; ".join(tried + [f"{opts.method}: {first.status}",
                                         f"{opts.fallback}: {sol.message}"])
    return sol, opts.fallback, True


__all__ = ["StepProblem", "coulomb_residual", "solve_step"]
