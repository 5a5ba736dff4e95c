"""The local rescue of contact-state pivoting (lcp.solvers.state_pivoting, issue 13): the
event LCP in its z-form (`EventLCP`: z = [R, tau, a_minus], models.event's layout) around the
violated contacts and their neighbours, the other states fixed (a principal pivot transform),
solved by dense lexicographic Lemke and checked as lcp.solve checks it (`local_rescue`).
Split from state_pivoting.py by job (session 8); re-exported there.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .state_factor import NS, ActiveSystem, SingularSystem, StateFactor, factorize


class EventLCP:
    """The event LCP w = M z + q, z = [R (c), tau (k), a_minus (k)] (models.event's layout),
    with a sparse M = B + rows of W G, built from the active system's W, q and the event's
    sliding signs and candidates."""

    def __init__(self, asys: ActiveSystem, tang: np.ndarray, cand: np.ndarray):
        c, mu = asys.c, asys.mu
        self.c, self.cand = c, cand
        cj = np.flatnonzero(cand)
        k = cj.size
        self.cj, self.k, self.n = cj, k, c + 2 * k
        idx, kk = np.arange(c), np.arange(k)
        s = np.where(cand, 0, np.where(np.isin(tang, (1, -1)), tang, 0)).astype(float)
        slope = np.where(cand, -mu, -s * mu)
        G = sp.csr_matrix((np.concatenate([np.ones(c), slope, np.ones(k)]),
                           (np.concatenate([idx, c + idx, c + cj]),
                            np.concatenate([idx, idx, c + kk]))), shape=(2 * c, self.n))
        WG = (asys.W @ G).tocsr()
        B = sp.csr_matrix((np.concatenate([np.ones(k), 2.0 * mu[cj], -np.ones(k)]),
                           (np.concatenate([c + kk, c + k + kk, c + k + kk]),
                            np.concatenate([c + k + kk, cj, c + kk]))), shape=(self.n, self.n))
        top = sp.vstack([WG[:c], WG[c + cj], sp.csr_matrix((k, self.n))])
        self.M = (top + B).tocsr()
        self.q = np.concatenate([asys.q[:c], asys.q[c + cj], np.zeros(k)])
        self.pos = -np.ones(c, dtype=int)  # candidate position of each contact
        self.pos[cj] = kk
        self.adjacency = asys.adjacency

    def basis(self, normal: np.ndarray, tang: np.ndarray) -> np.ndarray:
        """The z-basis (mask) of a vector of states: R basic on T; tau on NS and "-";
        a_minus on "-"."""
        t = tang[self.cj]
        return np.concatenate([normal, (t == NS) | (t == -1), t == -1])

    def z_indices(self, contacts: np.ndarray) -> np.ndarray:
        p = self.pos[contacts]
        p = p[p >= 0]
        return np.concatenate([contacts, self.c + p, self.c + self.k + p])


def local_rescue(factor: StateFactor, ev: EventLCP, H: np.ndarray, *, min_contacts: int = 24,
                 radius: int = 2, max_n: int = 1500) -> bool:
    """Re-solve the states of the contacts of H and their neighbours (rings of the contact
    graph, at least `radius` rings and `min_contacts` contacts, at most max_n LCP unknowns),
    the other states fixed: the LCP of those unknowns is the principal pivot transform
    M_FF - M_Fa M_aa^-1 M_aF, q_F - M_Fa M_aa^-1 q_a (a: the basic unknowns outside F),
    solved by dense lexicographic Lemke, checked as `lcp.solve(LCP(...), "lemke")` checks it
    (the same steps, lcp.acceptance.trust, without importing the facade from below it). Sets
    the factor's states; False when it cannot."""
    from ..acceptance.residual import TOL
    from ..acceptance.trust import Run, solve_checked
    from ..problems.problem import LCP
    from ..registry import lookup
    from . import lemke  # noqa: F401  (registers "lemke")

    c = ev.c
    F = np.unique(H % c)
    ring = 0
    while ring < radius or F.size < min_contacts:
        grown = np.unique(np.concatenate([F, ev.adjacency[F].indices]))
        ring += 1
        if grown.size == F.size or ev.z_indices(grown).size > max_n:
            break
        F = grown
    zF = ev.z_indices(F)
    inF = np.zeros(ev.n, dtype=bool)
    inF[zF] = True
    basic = ev.basis(factor.normal, factor.tang)
    aX = np.flatnonzero(basic & ~inF)
    M = ev.M
    MFF = M[zF][:, zF].toarray()
    qF = ev.q[zF].copy()
    if aX.size:
        try:
            lu = factorize(M[aX][:, aX])
        except RuntimeError:
            return False
        d = np.abs(lu.U.diagonal())
        if d.min() <= 1e-13 * d.max():
            return False
        rhs = np.column_stack([M[aX][:, zF].toarray(), ev.q[aX]])
        sol = lu.solve(rhs)
        MFa = M[zF][:, aX]
        MFF -= MFa @ sol[:, :-1]
        qF -= MFa @ sol[:, -1]
    sub = LCP(MFF, qF)
    res = solve_checked(Run(sub, sub, lookup, TOL), "lemke", True, True, {})
    if res.status != "solved":
        return False
    zb = np.zeros(zF.size, dtype=bool)
    zb[np.asarray(res.basis, dtype=int)] = True
    normal, tang = factor.normal.copy(), factor.tang.copy()
    nR = np.isin(zF, F)  # the R unknowns come first in z_indices
    normal[F] = zb[: F.size] if nR[: F.size].all() else normal[F]
    p = ev.pos[F]
    candF = F[p >= 0]
    kf = candF.size
    tau_b, am_b = zb[F.size:F.size + kf], zb[F.size + kf:]
    tang[candF] = np.where(tau_b & ~am_b, NS, np.where(am_b & tau_b, -1, 1))
    try:
        factor.set_states(normal, tang)
    except SingularSystem:
        return False
    return True
