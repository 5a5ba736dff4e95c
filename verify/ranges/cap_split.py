"""A proved lower bound of an observable of S (mu_g) over the valid steady states, by a case
split on which *cap contacts* have a_t = 0 (`cap_split_bound`).

Setting (verify.ranges.bounds.rotation_cap): with no translation a_t = T_u ra + b (ra = r alpha),
ra = D T_u^T S (D = r^2 / I), T_u's frictional rows of one or two entries +-1 of one sign,
b = 0 on two-disk rows, and every valid steady state has |ra_i| <= M* = max |b| over the
one-disk frictional contacts. Cap contacts: the one-disk frictional contacts beta with
|b_beta| = M* (the plane, b = -gamma, on Fig. 9's system), eps_beta their T_u entry, i(beta)
their disk. On every valid steady state, for Z = {cap contacts with a_t = 0}:

(a) beta not in Z: a_t = eps ra_i + b != 0 has the sign of b (|eps ra_i| <= |b|), so the contact
    slides with s = sgn b (a non-sliding one has a_t = 0; a sliding one s a_t >= 0):
    S_beta = -sgn(b) mu R_beta.
(b) beta in Z: ra_i = -b / eps (linear), so |ra_i| = M*: the disk attains the cap.
(c) Z nonempty: with K = {i: |ra_i| = M*} (it holds the disks of Z) and sigma_i = sgn ra_i,
    Phi = sum_K sigma_i ra_i / D_i = M* sum_K 1/D_i, and Phi = sum_K sigma_i (T_u^T S)_i is, as
    in rotation_cap's proof, a sum of terms <= 0 (S a_t <= 0 on every contact of a valid steady
    state, the larger |ra| deciding sgn a_t) except those of the contacts of Z, whose term is
    sigma_i eps_beta S_beta = -sgn(b_beta) S_beta (a cap contact of a disk of K not in Z has
    a_t = 2 eps sigma_i M*: its term is <= 0). Hence
        -sum_{beta in Z} sgn(b_beta) S_beta >= M* sum_{i in disks(Z)} 1 / D_i.

Each Z gives a linear program: the relaxation P of verify.ranges.bounds (a_n = 0, no
translation, R >= 0, |S| <= mu R, S = 0 where mu = 0, |ra| <= M*) with (a), (b), (c), over the
proved force box (R <= R_hi, |S| <= S_abs: valid for observables of S). Its minimum is bounded
by the certified Lagrangian bound (verify.ranges.milp.certified_result), an empty case is
closed only by a checked Farkas ray, and the least bound over all 2^|cap| cases (they cover
every valid steady state) is a lower bound over every valid steady state.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rigidlcp.lcp.quiet import new_highs
from rigidlcp.verify.certificates.uniqueness import quiet_highs

from .bounds import rotation_cap
from .disk_split import _load, disk_split_bound, witness_of
from .milp import certified_result
from .observables import alpha_rows
from .result import OPTIMAL, TIME_LIMIT, value_text, witness_tolerance
from .steady import Formulation, _equalities, velocity_box

#: At most this many cap contacts (2^n linear programs).
MAX_CAP = 16


@dataclass
class CapSplitBound:
    """bound: proved lower bound of L . x over every valid steady state; worst: the Z (cap
    contact indices) whose case gives it; cases, empty: the cases solved, those proved empty."""

    bound: float
    worst: tuple[int, ...]
    cases: int
    empty: int
    seconds: float


def cap_contacts(form: Formulation) -> tuple[np.ndarray, np.ndarray, np.ndarray, float] | None:
    """(cap contacts beta, their disks i, their eps, M*) or None when the rotation cap does not
    apply or no cap contact exists (module docstring)."""
    system, dyn = form.system, form.dyn
    M = rotation_cap(system, dyn)
    if M is None or M <= 0:
        return None
    T_u, _, _ = velocity_box(dyn)
    b = np.asarray(dyn.u_obs_dot, float)[system.c:]
    beta, disk, eps = [], [], []
    for a in np.flatnonzero(system.mu > 0):
        nz = np.flatnonzero(T_u[a])
        if nz.size == 1 and abs(abs(b[a]) - M) <= 1e-12 * M:
            beta.append(a)
            disk.append(int(nz[0]))
            eps.append(float(T_u[a, nz[0]]))
    if not beta:
        return None
    return np.array(beta), np.array(disk), np.array(eps), float(M)


def cap_split_bound(form: Formulation, L: np.ndarray) -> CapSplitBound | None:
    """min over the cases Z of the certified bound of min L . x (module docstring); None when
    it does not apply (no proved force box, no rotation cap, no cap contact, more than
    MAX_CAP cap contacts, or L weighs an R whose bound is not proved). The cases are visited in
    Gray-code order: from one case to the next one cap contact enters or leaves Z, so only its
    rows (a), (b), its entry of (c) and (c)'s bound change and each LP starts from the
    previous one's basis; every case is still bounded by its own certificate."""
    import highspy

    t0 = time.perf_counter()
    system, dyn = form.system, form.dyn
    c, p, mu, r = system.c, system.p, system.mu, system.lattice.radii
    L = np.asarray(L, float)
    caps = cap_contacts(form)
    if caps is None or form.R_hi is None or not form.proved_for(L):
        return None
    beta, disk, eps, M = caps
    if beta.size > MAX_CAP:
        return None
    b = np.asarray(dyn.u_obs_dot, float)[c:]
    D = r * r * dyn.Minv[2 * p:]
    ra = r[:, None] * alpha_rows(system, dyn)  # r alpha = ra @ x
    E, e = _equalities(dyn)
    fr = np.flatnonzero(mu > 0)
    I2 = np.eye(2 * c)
    base = [E, mu[fr, None] * I2[fr] - I2[c + fr], mu[fr, None] * I2[fr] + I2[c + fr], ra]
    base_lo = np.r_[e, np.zeros(2 * fr.size), np.full(p, -M)]
    base_hi = np.r_[e, np.full(2 * fr.size, np.inf), np.full(p, M)]
    lb = form.lb[:2 * c].copy()
    ub = form.ub[:2 * c].copy()
    h = new_highs(primal_feasibility_tolerance=1e-10, dual_feasibility_tolerance=1e-10)
    n = beta.size
    rows_a = mu[beta, None] * np.sign(b[beta])[:, None] * I2[beta] + I2[c + beta]  # (a)
    rows_b = eps[:, None] * ra[disk]  # (b)
    Ad = np.vstack([*base, rows_a, rows_b, np.zeros((1, 2 * c))])  # last: (c), per case
    ia, ib, ic = Ad.shape[0] - 2 * n - 1, Ad.shape[0] - n - 1, Ad.shape[0] - 1
    row_lo = np.r_[base_lo, np.zeros(n), np.full(n, -np.inf), -np.inf]  # the case Z = {}
    row_hi = np.r_[base_hi, np.zeros(n), np.full(n, np.inf), np.inf]
    _load(h, highspy, L, Ad, row_lo, row_hi, lb, ub)
    # the constraint matrix for the certificates, with row (c)'s entries stored (updated per
    # case in place: no new sparse matrix per case)
    Ad[ic, c + beta] = 1.0
    A = sp.csr_matrix(Ad)
    Ad[ic, c + beta] = 0.0
    row_c = A.indptr[ic] + np.searchsorted(A.indices[A.indptr[ic]:A.indptr[ic + 1]], c + beta)
    A.data[row_c] = 0.0
    z = np.zeros(n, dtype=bool)
    best, worst, cases, empty = np.inf, (), 0, 0
    for g in range(2 ** n):  # Gray code: one cap contact changes from one case to the next
        if g:
            k = int((g & -g).bit_length() - 1)
            z[k] = not z[k]
            _set_case(h, z, k, ia, ib, ic, c + int(beta[k]), -b[beta[k]],
                      -np.sign(b[beta[k]]), row_lo, row_hi, A, row_c)
            row_lo[ic] = M * float(np.sum(1.0 / D[np.unique(disk[z])])) if z.any() else -np.inf
            h.changeRowBounds(ic, float(row_lo[ic]), float(row_hi[ic]))
        with quiet_highs():
            h.run()
        if h.getModelStatus() not in (highspy.HighsModelStatus.kOptimal,
                                      highspy.HighsModelStatus.kInfeasible):
            h.clearSolver()  # warm start in trouble: once more from scratch
            with quiet_highs():
                h.run()
        bound = certified_result(h, highspy, L, A, row_lo, row_hi, lb, ub)[0]
        cases += 1
        empty += bound == np.inf
        if bound < best:
            best, worst = bound, tuple(int(beta[k]) for k in np.flatnonzero(z))
    return CapSplitBound(float(best), worst, cases, empty, time.perf_counter() - t0)


def _set_case(h, z: np.ndarray, k: int, ia: int, ib: int, ic: int, col: int, rhs_b: float,
              coef: float, row_lo: np.ndarray, row_hi: np.ndarray, A: sp.csr_matrix,
              row_c: np.ndarray) -> None:
    """Cap contact k (column `col` of its S) into Z (z[k]) or out of it: its rows (a) and (b)
    and its entry of row (c), in HiGHS, in the row bounds and in A (for the certificate)."""
    inf = np.inf
    row_lo[ia + k], row_hi[ia + k] = (-inf, inf) if z[k] else (0.0, 0.0)
    row_lo[ib + k], row_hi[ib + k] = (rhs_b, rhs_b) if z[k] else (-inf, inf)
    for i in (ia + k, ib + k):
        h.changeRowBounds(i, float(row_lo[i]), float(row_hi[i]))
    A.data[row_c[k]] = coef if z[k] else 0.0
    h.changeCoeff(ic, col, float(A.data[row_c[k]]))


def bound_open_ends(form: Formulation, ranges: dict, obs: dict[str, np.ndarray],
                    deep: float = 0.0, clock_name: str = "wall") -> None:
    """Give each end left at the time limit the proved bound of `cap_split_bound` (End.bound,
    and a note), where it applies; with deep > 0 also that of verify.ranges.disk_split's case
    split (deep seconds per end; the better bound is kept, and a case point satisfying every
    contact law is checked as a witness). An end whose best value met attains its bound is
    decided."""
    for name, L in obs.items():
        for side, sense in (("lo", 1.0), ("hi", -1.0)):
            end = getattr(ranges[name], side)
            if end.status != TIME_LIMIT:
                continue
            res = cap_split_bound(form, sense * L)
            how, bound = "", -np.inf
            if res is not None and np.isfinite(res.bound):
                end.seconds += res.seconds
                how, bound = (f"the case split on the cap contacts with a_t = 0 ({res.cases} "
                              f"certified LPs, {res.empty} empty)"), res.bound
            dres = None
            if deep > 0:
                target = np.inf if end.best is None else sense * end.best
                dres = disk_split_bound(form, sense * L, target, deep, clock_name=clock_name)
            if dres is not None:
                end.seconds += dres.seconds
                wit = None if dres.candidate is None else witness_of(form, dres.candidate)
                if wit is not None and sense * float(L @ np.r_[wit.R, wit.S]) < (
                        np.inf if end.best is None else sense * end.best):
                    x = np.r_[wit.R, wit.S]
                    end.best, end.witness = float(L @ x), wit
                    end.residual = wit.residual
                    end.tol = witness_tolerance(form.system, L, x, wit.residual)
                if dres.bound > bound:
                    how, bound = (f"the case split on the disks' cap states ({dres.cases} "
                                  f"certified LPs, {dres.empty} empty, {dres.open} left)"), \
                        dres.bound
            if not np.isfinite(bound):
                continue
            end.bound = sense * bound
            how = f"proved {'>=' if sense > 0 else '<='} {end.bound:.10g} by {how}"
            if end.best is not None and end.witness is not None and (
                    sense * end.best <= bound + 1e-9 * max(1.0, abs(bound))):
                end.status, end.value = OPTIMAL, end.best
                end.note = f"{how}; attained by the witness"
            else:
                # as the ranges table prints it: no digit below what it is known to
                met = "" if end.best is None else f"; best met {value_text(end.best, end.tol)}"
                end.note = f"{'min' if sense > 0 else 'max'} not decided: {how}{met}"
