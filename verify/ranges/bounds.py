"""Proved per-contact bounds on the forces of valid steady states, for the big-M constants of
verify.ranges.steady (docs/mechanics.md, "Valid steady states and their ranges", "Force
bounds").

Every valid steady state lies in the relaxation P = {x = [R; S]: a_n = 0, no translation,
R >= 0, |S| <= mu R, S = 0 where mu = 0, |r alpha| <= M* where the rotation cap M* is
proved}. Linear programs over P give

* |S_a| <= S_abs[a] and the bounds of r alpha (linear in S): valid for *every* steady state;
* R_a <= R_hi[a] for the contacts whose R is bounded over P.

The other R (the rows' self-stress, Fig. 5d) are unbounded over P. They are handled by a
reduction that keeps S: if the R-only self-stresses of the unbounded contacts are spanned by
vectors z_G >= 0 with disjoint supports G (a row between frictionless walls: z = 1 on its
horizontal and wall contacts), then R - t z_G with S unchanged satisfies the balance for every
t; decrease t until a contact b of G is tight (R_b = |S_b| / mu_b, or R_b = 0 where mu_b = 0;
t = 0 already when b slides). S, alpha, a_t, the velocities and every contact state are
unchanged (a_t depends on S only: H's normal rows carry no rotation), so the reduced state is a
valid steady state with the same S-observables, and there R_b / z_b <= rho_b = S_abs[b] / mu_b
(0 if mu_b = 0). With d_a = R_a / z_a - R_ref / z_ref (invariant under z_G, bounded over P by
linear programs: [dmin_a, dmax_a]),

    R_a <= z_a (max_b (rho_b / z_b - dmin_b) + dmax_a)      for every a in G.

So for an observable of S (mu_g, alpha, S, and the bounded R) the extremes over all valid
steady states equal those over the states with R <= R_hi: the bound is proved for it. An
observable that weighs an R of a self-stress group is not covered (`free_R`).

The angular accelerations obey a maximum principle (`rotation_cap`): |r alpha_i| <= max |b|
over the one-disk frictional contacts (b = a_t at alpha = 0: gamma for the plane), proved for
every valid steady state, not only over P; where it applies, the LPs for r alpha and a_t are
not needed (their bounds follow from the cap).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.linalg import null_space

from rigidlcp.lcp.quiet import new_highs
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.system import System
from rigidlcp.verify.certificates.uniqueness import quiet_highs

#: Relative and absolute margins added to every LP bound (the LPs' tolerance is 1e-10).
MARGIN_REL, MARGIN_ABS = 1e-6, 1e-7
#: HiGHS settings tried, in turn, on a bound LP that ends in numerical trouble (after a run
#: from scratch): without presolve, and with other simplex scalings (tests/verify/ranges/
#: test_tiny_friction.py: each rescues some of the LPs of rect/tri arrays at mu_pp ~ 1e-8).
RETRIES = ({"presolve": "off"}, {"simplex_scale_strategy": 4}, {"simplex_scale_strategy": 0})


@dataclass
class ForceBounds:
    """Per-contact |S| <= S_abs, R <= R_hi (proved for observables of S and of the R outside
    free_R), per-disk ra_lo <= r alpha <= ra_hi, per-contact at_lo <= a_t <= at_hi; groups:
    the self-stress groups (contact indices) reduced as in the module docstring."""

    S_abs: np.ndarray
    R_hi: np.ndarray
    ra_lo: np.ndarray
    ra_hi: np.ndarray
    at_lo: np.ndarray
    at_hi: np.ndarray
    free_R: np.ndarray
    groups: list[np.ndarray]
    n_lp: int


class _P:
    """The relaxation P in one HiGHS instance; `extreme(L)` = (min, max) of L x over P (+-inf
    where unbounded), or None if P is empty or an LP fails."""

    def __init__(self, system: System, dyn: Dynamics, E: np.ndarray, e: np.ndarray,
                 ra_rows: np.ndarray | None = None, ra_cap: float = np.inf):
        """ra_rows, ra_cap: also |ra_rows @ x| <= ra_cap (the rotation cap, valid on every
        valid steady state: P then stays a relaxation of them)."""
        import highspy

        c, mu = system.c, system.mu
        fr = np.flatnonzero(mu > 0)
        F = fr.size
        rows = sp.vstack([sp.csr_matrix(E),
                          sp.csr_matrix((np.r_[mu[fr], np.ones(F)],
                                         (np.r_[np.arange(F), np.arange(F)], np.r_[fr, c + fr])),
                                        shape=(F, 2 * c)),
                          sp.csr_matrix((np.r_[mu[fr], -np.ones(F)],
                                         (np.r_[np.arange(F), np.arange(F)], np.r_[fr, c + fr])),
                                        shape=(F, 2 * c))]).tocsc()
        row_lo, row_hi = np.r_[e, np.zeros(2 * F)], np.r_[e, np.full(2 * F, np.inf)]
        if ra_rows is not None and np.isfinite(ra_cap):
            rows = sp.vstack([rows, sp.csr_matrix(ra_rows)]).tocsc()
            row_lo = np.r_[row_lo, np.full(ra_rows.shape[0], -ra_cap)]
            row_hi = np.r_[row_hi, np.full(ra_rows.shape[0], ra_cap)]
        lp = highspy.HighsLp()
        lp.num_col_, lp.num_row_ = 2 * c, rows.shape[0]
        lp.col_cost_ = np.zeros(2 * c)
        lp.col_lower_ = np.r_[np.zeros(c), np.where(mu > 0, -np.inf, 0.0)]
        lp.col_upper_ = np.r_[np.full(c, np.inf), np.where(mu > 0, np.inf, 0.0)]
        lp.row_lower_, lp.row_upper_ = row_lo, row_hi
        lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
        lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (
            rows.indptr, rows.indices, rows.data)
        h = new_highs(primal_feasibility_tolerance=1e-10, dual_feasibility_tolerance=1e-10)
        h.passModel(lp)
        self.h, self.hs, self.n, self.count = h, highspy, 2 * c, 0

    def _opt(self, cost: np.ndarray) -> float | None:
        h, hs = self.h, self.hs
        h.changeColsCost(self.n, np.arange(self.n, dtype=np.int32), cost)
        self.count += 1
        with quiet_highs():
            h.run()
        st = h.getModelStatus()
        # HiGHS in numerical trouble (kUnknown, kSolveError: seen at mu_pp ~ 1e-8 - 1e-7, where
        # R reaches ~ 1/mu and the rows' terms span 1e8): once more from scratch, then with
        # the other settings of RETRIES (same tolerances, so a bound is as good as a first one)
        for retry in ({}, *RETRIES):
            if st not in (hs.HighsModelStatus.kUnknown, hs.HighsModelStatus.kSolveError):
                break
            h.clearSolver()
            saved = {key: _option(h, key) for key in retry}
            for key, value in retry.items():
                h.setOptionValue(key, value)
            try:
                with quiet_highs():
                    h.run()
            finally:
                for key, value in saved.items():
                    h.setOptionValue(key, value)
            st = h.getModelStatus()
        if st == hs.HighsModelStatus.kOptimal:
            return float(h.getInfo().objective_function_value)
        if st in (hs.HighsModelStatus.kUnbounded, hs.HighsModelStatus.kUnboundedOrInfeasible):
            return -np.inf
        return None

    def extreme(self, L: np.ndarray) -> tuple[float, float] | None:
        lo, hi = self._opt(L), self._opt(-L)
        if lo is None or hi is None:
            return None
        return lo, -hi


def _option(h, key: str):
    """HiGHS option `key`'s value (highspy returns (status, value) or the value alone)."""
    v = h.getOptionValue(key)
    return v[1] if isinstance(v, tuple) else v


def _pad(v: float) -> float:
    return v + MARGIN_REL * abs(v) + MARGIN_ABS


def _groups(ER: np.ndarray, free: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]] | None:
    """[(contacts G, z_G > 0)]: the R-only self-stresses of the contacts `free` as vectors with
    disjoint supports covering `free`, or None when they are not of that form."""
    N = null_space(ER[:, free])
    k = N.shape[1]
    if k == 0:
        return None
    norms = np.linalg.norm(N, axis=1)
    if np.any(norms < 1e-9):
        return None
    unit = N / norms[:, None]
    label = -np.ones(free.size, dtype=int)
    out = []
    for a in range(free.size):
        if label[a] >= 0:
            continue
        same = np.abs(np.abs(unit @ unit[a]) - 1.0) < 1e-9
        label[same] = len(out)
        z = N[same] @ N[a] / (norms[a] ** 2)
        z = z * np.sign(z[0])
        if np.any(z <= 1e-9):
            return None
        out.append((free[same], z))
    if len(out) != k:
        return None
    for G, z in out:
        if np.max(np.abs(ER[:, G] @ z), initial=0.0) > 1e-9 * max(1.0, np.abs(ER).max()):
            return None
    return out


def rotation_cap(system: System, dyn: Dynamics) -> float | None:
    """M* with |r alpha_i| <= M* for every disk in every valid steady state (a discrete
    maximum principle), or None when the contact geometry is not of the form it needs.

    With no translation, a_t = T_u ra + b (ra_i = r_i alpha_i, each disk's own radius;
    b = u_obs'_t, gamma's part) and, by the torque balance, ra = D T_u^T S with
    D = diag(r_i^2 / I_i) > 0 (verify.ranges.steady). It
    needs: every frictional row of T_u has at most two nonzero entries, all of one sign
    eps_beta (disk-disk -(u_i + u_j), plane -V - u_i, wall -u_i), and b_beta = 0 on the
    two-disk rows; then M* = max |b_beta| over the one-disk frictional rows (gamma here).

    Proof. Every valid steady state has S_beta a_t,beta <= 0 on every contact (sliding
    S = -s mu R with s a_t >= 0; non-sliding a_t = 0; frictionless S = 0). Suppose
    M = max_i |ra_i| > M*, K = {i: |ra_i| = M}, sigma_i = sgn ra_i. Then
    Phi = sum_K sigma_i ra_i / D_i = sum_K M / D_i > 0, and also, from ra_i / D_i =
    sum_beta T_beta,i S_beta, Phi = sum_K sigma_i sum_{beta at i} eps_beta S_beta. Per term:
    a two-disk contact (i, j) with j in K and sigma_j = -sigma_i cancels (sigma_i + sigma_j
    = 0); otherwise sgn(ra_i + ra_j) = sigma_i (|ra_j| < M or sigma_j = sigma_i), so
    sgn a_t = eps_beta sigma_i and S a_t <= 0 gives sigma_i eps_beta S_beta <= 0; a one-disk
    contact has |b| <= M* < M, so again sgn a_t = eps_beta sigma_i and the term is <= 0. So
    Phi <= 0: a contradiction. Hence max |ra_i| <= M*.
    """
    c, p, r = system.c, system.p, system.lattice.radii
    H = dyn.H.toarray()
    if np.any(H[:c, 2 * p:] != 0):  # a normal row with rotation: not ra = D T_u^T S
        return None
    Tu = H[c:, 2 * p:] / r
    b = np.asarray(dyn.u_obs_dot, float)[c:]
    cap = 0.0
    for beta in np.flatnonzero(system.mu > 0):
        row = Tu[beta][Tu[beta] != 0]
        if row.size == 0:
            continue
        if row.size > 2 or np.any(np.abs(row - row[0]) > 1e-12 * abs(row[0])):
            return None  # unequal weights or signs: sgn(a_t) not fixed by the larger |ra|
        if row.size == 2:
            if b[beta] != 0:
                return None
        else:
            cap = max(cap, abs(float(b[beta])))
    return cap


def proved_bounds(system: System, dyn: Dynamics, E: np.ndarray, e: np.ndarray
                  ) -> ForceBounds | None:
    """The bounds of the module docstring, or None when they cannot be proved (an S or an
    r alpha unbounded over P, self-stresses not of disjoint nonnegative support, a difference
    d_a unbounded). E x = e: a_n = 0 and no translation (verify.ranges.steady)."""
    c, p, mu = system.c, system.p, system.mu
    r = system.lattice.radii
    HT = dyn.H.T.toarray()
    Lra = (r * dyn.Minv[2 * p:])[:, None] * HT[2 * p:]
    m_star = rotation_cap(system, dyn)
    P = _P(system, dyn, E, e, Lra, np.inf if m_star is None else m_star * (1 + 1e-9) + 1e-15)
    S_abs, R_hi = np.zeros(c), np.full(c, np.inf)
    I2 = np.eye(2 * c)
    for a in range(c):
        top = P._opt(-I2[a])  # max R_a (one LP: R >= 0 needs no lower bound)
        if top is None:
            return None
        if np.isfinite(top):
            R_hi[a] = _pad(max(-top, 0.0))
        if mu[a] > 0:
            ext = P.extreme(I2[c + a])
            if ext is None or not np.all(np.isfinite(ext)):
                return None
            S_abs[a] = _pad(max(abs(ext[0]), abs(ext[1])))
    Tu = dyn.H[c:].toarray()[:, 2 * p:] / r
    gam = dyn.u_obs(1.0)[c:] * system.gamma
    at_lo, at_hi = np.zeros(c), np.zeros(c)
    if m_star is not None:  # the maximum principle: no LP needed for r alpha and a_t
        ra_hi = np.full(p, m_star * (1 + 1e-9) + 1e-15)  # exact up to rounding
        ra_lo = -ra_hi
        for a in np.flatnonzero(mu > 0):
            Tp, Tm = np.maximum(Tu[a], 0.0), np.minimum(Tu[a], 0.0)
            at_lo[a] = gam[a] + Tp @ ra_lo + Tm @ ra_hi
            at_hi[a] = gam[a] + Tp @ ra_hi + Tm @ ra_lo
    else:
        ra_lo, ra_hi = np.zeros(p), np.zeros(p)
        for i in range(p):
            ext = P.extreme(Lra[i])
            if ext is None or not np.all(np.isfinite(ext)):
                return None
            ra_lo[i], ra_hi[i] = -_pad(-ext[0]), _pad(ext[1])
        # Power: nu'^T M nu' = nu'^T (H^T lambda + f) with no translation gives
        # sum_i I_i alpha_i^2 = S . a_t - u_obs'^T lambda, and S . a_t <= 0 on every valid
        # steady state (sliding: S = -s mu R, s a_t >= 0; non-sliding: a_t = 0; frictionless:
        # S = 0), so I_i alpha_i^2 <= max over P of (-u_obs'^T lambda) (= gamma F_g at most), and
        # |r_i alpha_i| <= r_i sqrt(max / I_i) with each disk's r_i and I_i.
        ext = P.extreme(-np.asarray(dyn.u_obs_dot, float))
        if ext is not None and np.isfinite(ext[1]):
            I_rot = 1.0 / dyn.Minv[2 * p:]
            cap = r * np.sqrt(_pad(max(ext[1], 0.0)) / I_rot)
            ra_lo, ra_hi = np.maximum(ra_lo, -_pad(cap)), np.minimum(ra_hi, _pad(cap))
        # a_t of each frictional contact: T_u r alpha + T_V gamma (verify.ranges.steady),
        # one LP pair each (tighter than the sum of the r alpha intervals)
        for a in np.flatnonzero(mu > 0):
            ext = P.extreme(Tu[a] @ Lra)
            if ext is None or not np.all(np.isfinite(ext)):
                return None
            Tp, Tm = np.maximum(Tu[a], 0.0), np.minimum(Tu[a], 0.0)  # or the r alpha box
            at_lo[a] = gam[a] + max(-_pad(-ext[0]), Tp @ ra_lo + Tm @ ra_hi)
            at_hi[a] = gam[a] + min(_pad(ext[1]), Tp @ ra_hi + Tm @ ra_lo)
    free = np.flatnonzero(~np.isfinite(R_hi))
    groups = []
    if free.size:
        found = _groups(E[:, :c], free)
        if found is None:
            return None
        with np.errstate(over="ignore"):  # mu ~ 1e-320: rho = S_abs / mu overflows
            rho = np.where(mu > 0, S_abs / np.where(mu > 0, mu, 1.0), 0.0)
        if not np.all(np.isfinite(rho)):
            return None  # no finite bound: the box, said "not proved"
        for G, z in found:
            ref = G[0]
            dmin, dmax = np.zeros(G.size), np.zeros(G.size)
            for k, a in enumerate(G[1:], start=1):
                L = np.zeros(2 * c)
                L[a], L[ref] = 1.0 / z[k], -1.0 / z[0]
                ext = P.extreme(L)
                if ext is None or not np.all(np.isfinite(ext)):
                    return None
                dmin[k], dmax[k] = ext
            top = np.max(rho[G] / z - dmin)
            R_hi[G] = _pad(z * (top + dmax))
            groups.append(G)
    free_R = np.zeros(c, dtype=bool)
    if groups:
        free_R[np.concatenate(groups)] = True
    return ForceBounds(S_abs, R_hi, ra_lo, ra_hi, at_lo, at_hi, free_R, groups, P.count)
