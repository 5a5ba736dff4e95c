"""A proved bound of an observable of the forces over the valid steady states by a best-first
case split on each disk's *cap state* and then on contact states (`disk_split_bound`).

Setting as in verify.ranges.bounds.rotation_cap: with no translation, a_t = T_u ra + b on the
frictional contacts (ra = r alpha, each row of T_u one or two entries of one sign eps, b = 0 on
two-disk rows), and every valid steady state has |ra_i| <= M* (the rotation cap). On every
valid steady state, every frictional contact satisfies

    a_t > 0  =>  S = -mu R,      a_t < 0  =>  S = +mu R                         (*)

(a sliding contact has S = -s mu R with s a_t >= 0; a non-sliding one has a_t = 0).

Cases. Each disk's ra lies in [-M*, M*]; a case narrows it to one of {-M*}, {+M*}, (-M*, M*],
[-M*, M*), (-M*, M*) (or leaves it), by binary splits at a cap point: [-M*, M*] into {-M*} and
(-M*, M*] (or {+M*} and [-M*, M*)), (-M*, M*] into {+M*} and (-M*, M*), and so on; the two
children cover the parent. Given these sets, a_t = sum eps ra + b of a contact lies in an
interval computed exactly (in units of M*, with its open ends). Where that interval lies in
(0, inf) (resp. (-inf, 0)), (*) fixes S = -mu R (resp. +mu R): a linear equality valid on
every valid steady state of the case. E.g. a disk at -M* next to one in (-M*, M*): a_t =
M* - ra_j > 0, the contact slides. The cap split of verify.ranges.cap_split is the first level
of this one (a plane contact has a_t = -M* - ra_i: it slides unless its disk is at -M*), and
its inequality (c) follows from these equalities and the torque balance. A contact whose
interval holds 0 with neither disk at a point is split three ways: a_t >= 0 and S = -mu R;
a_t <= 0 and S = +mu R; a_t = 0 — again covering every valid steady state of the case, by (*).

The power cut. With no translation nu' = (0, alpha) and f has no torque, so nu'^T M nu' =
nu'^T (H^T lambda + f) = (a - u_obs') . lambda gives, as a_n = 0,

    sum_i ra_i^2 / D_i = sum_i I_i alpha_i^2 = S . a_t - u_obs' . lambda     (D_i = r^2 / I_i),

and S . a_t <= 0 contact by contact on every valid steady state, so -u_obs' . lambda >=
sum_i ra_i^2 / D_i (-u_obs' . lambda = gamma F_g here: the plane is the moving obstacle). It
enters each LP through
columns z_i >= tangents of ra_i^2 / D_i at ra = +-k M* / 4, k = 1..4 (ra^2 >= 2 t ra - t^2),
0 <= z_i <= M*^2 / D_i (the rotation cap), and the row -u_obs' . lambda >= sum_i z_i: every valid
steady state with z_i = ra_i^2 / D_i satisfies them. A disk at a cap state has z_i = M*^2 / D_i
exactly. In a case where a contact's a_t is a constant a_beta != 0 (its disks at cap points, or
a one-disk contact whose disk is at one), its term -S_beta a_beta >= 0 is linear and is kept:
the row is -u_obs' . lambda + sum_const S_beta a_beta >= sum_i z_i (`power_row`).

Each case is one linear program: the relaxation P of verify.ranges.bounds (a_n = 0, no
translation, R >= 0, |S| <= mu R, S = 0 where mu = 0) over the proved force box (valid for
observables of S and of the bounded R), with the disks' ra fixed or in [-M*, M*], the
equalities above and the power cut. Its minimum is bounded by the certified Lagrangian bound
of verify.ranges.milp (`certified_result`); an empty case is closed only by a checked Farkas
ray. The least bound over the cases left open (and those closed) is a lower bound of the
observable over every valid steady state, whatever the time limit. The velocities need no
case: with gamma != 0, (omega, V) = (alpha, gamma) t gives v_t = a_t t, so every state of
forces and accelerations satisfying (*) is a valid steady state; a case point satisfying (*)
is turned into a witness that way (`witness_of`) and decided by `steady_check`, as always.

Split order (best-first on the bound): the contact of largest violation of (*) at the case's
LP point, |a_t| (mu R + sgn(a_t) S); its disk is split at the cap point where its a_t is 0
when the contact's other disk is at a point (or the contact is one-disk, e.g. the plane); else
a disk of the contact with |ra| >= M*/2 at the LP point, at the cap of that sign; else the
contact itself. A case whose LP point violates (*) nowhere (to 1e-12) is attained by that
point: it is the case of least bound, so the point is the minimum if it passes as a witness;
the search stops there and returns it as the candidate.
"""

from __future__ import annotations

import heapq
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from rigidlcp.lcp.quiet import new_highs
from rigidlcp.verify.certificates.uniqueness import quiet_highs

from .bounds import rotation_cap
from .milp import certified_result, clock
from .observables import alpha_rows
from .steady import Formulation, _equalities, least_R, velocity_box
from .witness import SteadyWitness, make_witness

#: A candidate witness passes when its independent residual is at most this.
WITNESS_TOL = 1e-8

#: Cap states of a disk (ra in units of M*): OPEN [-1, 1] (not split), DOWN {-1}, UP {+1},
#: NOTDOWN (-1, 1], NOTUP [-1, 1), INSIDE (-1, 1); as (lo, hi, lo open, hi open).
OPEN, DOWN, UP, NOTDOWN, NOTUP, INSIDE = range(6)
_IV = {OPEN: (-1, 1, False, False), DOWN: (-1, -1, False, False), UP: (1, 1, False, False),
       NOTDOWN: (-1, 1, True, False), NOTUP: (-1, 1, False, True), INSIDE: (-1, 1, True, True)}
#: Splitting a state at the point -1 / +1: (the point's state, the rest's state).
_AT = {(OPEN, -1): (DOWN, NOTDOWN), (OPEN, 1): (UP, NOTUP), (NOTDOWN, 1): (UP, INSIDE),
       (NOTUP, -1): (DOWN, INSIDE)}
#: A violation of (*) below this (force x acceleration, relative) counts as none.
VIOL_TOL = 1e-12


@dataclass
class DiskSplitBound:
    """bound: a proved lower bound of cost . x over every valid steady state; closed: every
    case closed at target (so the end is decided when a checked state attains target);
    cases: LPs solved; open: cases left; empty: cases proved empty; candidate: an LP point
    satisfying (*) with a value below target (a state to check), or None."""

    bound: float
    closed: bool
    cases: int
    open: int
    empty: int
    seconds: float
    candidate: np.ndarray | None = field(default=None, repr=False)


class _Cases:
    """The LP of one case in one HiGHS instance. Columns x = [R; S] (2c) | z (p, the power
    cut's ra_i^2 / D_i). Rows: E x = e | mu R + S >= 0 | mu R - S >= 0 (per frictional
    contact; = 0 fixes S = -mu R, +mu R) | ra (per disk) | a_t (per frictional contact) | the
    power cut | its tangents (per disk, at ra = +-k M* / 4, k = 1..4)."""

    def __init__(self, form: Formulation, cost: np.ndarray, M: float):
        import highspy

        system, dyn = form.system, form.dyn
        c, p, mu, r = system.c, system.p, system.mu, system.lattice.radii
        self.hs, self.c, self.p, self.M = highspy, c, p, M
        fr = self.fric = np.flatnonzero(mu > 0)
        F = fr.size
        T_u, _, _ = velocity_box(dyn)
        Tf = T_u[fr]
        E, e = _equalities(dyn)
        I2 = np.eye(2 * c)
        self.W = np.asarray(dyn.W)[c + fr]
        self.q = np.asarray(dyn.q, float)[c + fr]
        ra = r[:, None] * alpha_rows(system, dyn)
        D = r * r * dyn.Minv[2 * p:]
        # power cut: -u_obs' . lambda - sum_i z_i >= 0, z_i >= (2 t ra_i - t^2) / D_i
        pw = np.r_[-np.asarray(dyn.u_obs_dot, float), -np.ones(p)]
        ts = M * np.array([-1.0, -0.75, -0.5, -0.25, 0.25, 0.5, 0.75, 1.0])
        tan = np.vstack([np.hstack([-2 * t / D[i] * ra[i], np.eye(p)[i]])
                         for i in range(p) for t in ts])
        tan_lo = np.array([-t * t / D[i] for i in range(p) for t in ts])
        Z = np.zeros
        A = np.vstack([np.hstack([E, Z((E.shape[0], p))]),
                       np.hstack([mu[fr, None] * I2[fr] + I2[c + fr], Z((F, p))]),
                       np.hstack([mu[fr, None] * I2[fr] - I2[c + fr], Z((F, p))]),
                       np.hstack([ra, Z((p, p))]), np.hstack([self.W, Z((F, p))]),
                       pw[None, :], tan])
        self.r_cp, self.r_cm = E.shape[0], E.shape[0] + F
        self.r_ra, self.r_a = E.shape[0] + 2 * F, E.shape[0] + 2 * F + p
        lo = np.r_[e, np.zeros(2 * F), np.full(p, -M), np.full(F, -np.inf), 0.0, tan_lo]
        hi = np.r_[e, np.full(2 * F, np.inf), np.full(p, M), np.full(F, np.inf), np.inf,
                   np.full(tan.shape[0], np.inf)]
        self.lb = np.r_[form.lb[:2 * c], np.zeros(p)]
        self.ub = np.r_[form.ub[:2 * c], M * M / D]
        nomu = np.flatnonzero(mu == 0)
        self.lb[c + nomu] = self.ub[c + nomu] = 0.0
        self.Ad, self.A = A, sp.csr_matrix(A)
        self.r_pw, self.pw = self.r_a + F, pw
        self.lo0, self.hi0 = lo, hi
        self.cost = np.r_[np.asarray(cost, float), np.zeros(p)]
        self.mu = mu[fr]
        self.h = new_highs(primal_feasibility_tolerance=1e-10, dual_feasibility_tolerance=1e-10,
                           presolve="off")
        _load(self.h, highspy, self.cost, A, lo, hi, self.lb, self.ub)
        self.cur_lo, self.cur_hi = lo.copy(), hi.copy()
        # a_t = sum eps ra_i + b per contact: its disks, eps and b / M* (exact units of M*)
        self.nz = [np.flatnonzero(row) for row in Tf]
        self.eps = [row[row != 0] for row in Tf]
        self.bM = np.asarray(dyn.u_obs_dot, float)[c + fr] / M

    def interval(self, disks: np.ndarray, k: int) -> tuple[float, float, bool, bool]:
        """a_t / M* of contact k over the case: (lo, hi, lo open, hi open)."""
        lo = hi = float(self.bM[k])
        lo_open = hi_open = False
        for i, e in zip(self.nz[k], self.eps[k]):
            a, b, ao, bo = _IV[int(disks[i])]
            if e < 0:
                a, b, ao, bo = -b, -a, bo, ao
            lo, hi = lo + abs(e) * a, hi + abs(e) * b
            lo_open, hi_open = lo_open or ao, hi_open or bo
        return lo, hi, lo_open, hi_open

    def sign_of_a(self, disks: np.ndarray) -> np.ndarray:
        """Per frictional contact: +1 / -1 where a_t > 0 / < 0 on every state of the case,
        0 where a_t = 0 on every one, 2 where undecided (module docstring)."""
        out = np.full(self.fric.size, 2, dtype=int)
        for k in range(self.fric.size):
            lo, hi, lo_open, hi_open = self.interval(disks, k)
            tiny = 1e-12 * (1.0 + abs(self.bM[k]))
            if lo > tiny or (abs(lo) <= tiny and lo_open):
                out[k] = 1
            elif hi < -tiny or (abs(hi) <= tiny and hi_open):
                out[k] = -1
            elif abs(lo) <= tiny and abs(hi) <= tiny:
                out[k] = 0
        return out

    def power_row(self, disks: np.ndarray) -> np.ndarray:
        """The power cut's row in the case: -u_obs' . lambda - sum z + sum S_beta a_beta over
        the contacts whose a_t is a constant a_beta != 0 there (both disks at a cap point, or
        a one-disk contact at one): the terms -S a >= 0 kept exactly where they are linear."""
        row = self.pw.copy()
        for k in range(self.fric.size):
            lo, hi, _, _ = self.interval(disks, k)
            if lo == hi and abs(lo) > 1e-12:
                row[self.c + self.fric[k]] += lo * self.M
        return row

    def bounds(self, disks: np.ndarray, contacts: dict[int, int]
               ) -> tuple[np.ndarray, np.ndarray]:
        """The row bounds (lo, hi) of the case's LP."""
        lo, hi = self.lo0.copy(), self.hi0.copy()
        sgn = self.sign_of_a(disks)
        for k, st in contacts.items():  # split contacts: 11 (a >= 0), 9 (a <= 0), 10 (a = 0)
            sgn[k] = 10 + st
        for k in range(self.fric.size):
            s = sgn[k]
            if s in (1, 11):
                hi[self.r_cp + k] = 0.0
            if s in (-1, 9):
                hi[self.r_cm + k] = 0.0
            if s in (11, 10):
                lo[self.r_a + k] = -self.q[k]
            if s in (9, 10):
                hi[self.r_a + k] = -self.q[k]
        for i in range(self.p):
            a, b, _, _ = _IV[int(disks[i])]
            lo[self.r_ra + i], hi[self.r_ra + i] = a * self.M, b * self.M
        return lo, hi

    def solve(self, disks: np.ndarray, contacts: dict[int, int]
              ) -> tuple[float, np.ndarray | None]:
        """(certified lower bound, LP point) of the case."""
        lo, hi = self.bounds(disks, contacts)
        return self.solve_with(disks, lo, hi)

    def solve_with(self, disks: np.ndarray, lo: np.ndarray, hi: np.ndarray
                   ) -> tuple[float, np.ndarray | None]:
        """(certified lower bound, LP point) with the row bounds lo, hi and the power row of
        `disks` loaded into the kept model (only the entries that changed)."""
        h = self.h
        row = self.power_row(disks)
        for j in np.flatnonzero(row != self.Ad[self.r_pw]):
            h.changeCoeff(self.r_pw, int(j), float(row[j]))
        if np.any(row != self.Ad[self.r_pw]):
            self.Ad = self.Ad.copy()
            self.Ad[self.r_pw] = row
            self.A = sp.csr_matrix(self.Ad)
        for i in np.flatnonzero((lo != self.cur_lo) | (hi != self.cur_hi)):
            h.changeRowBounds(int(i), float(lo[i]), float(hi[i]))
        self.cur_lo, self.cur_hi = lo, hi
        with quiet_highs():
            h.run()
        hs = self.hs
        if h.getModelStatus() not in (hs.HighsModelStatus.kOptimal,
                                      hs.HighsModelStatus.kInfeasible):
            h.clearSolver()
            with quiet_highs():
                h.run()
        b, x = certified_result(h, hs, self.cost, self.A, lo, hi, self.lb, self.ub)
        return b, (None if x is None else x[:2 * self.c])

    def violation(self, x: np.ndarray) -> np.ndarray:
        """|a_t| (mu R + sgn(a_t) S) per frictional contact at x (0 where (*) holds)."""
        c = self.c
        a = self.W @ x + self.q
        R, S = x[self.fric], x[c + self.fric]
        v = np.abs(a) * np.maximum(self.mu * R + np.sign(a) * S, 0.0)
        scale = max(1.0, float(np.max(np.abs(x))))
        return np.where(v > VIOL_TOL * scale, v, 0.0)

    def split(self, disks: np.ndarray, contacts: dict[int, int], x: np.ndarray,
              v: np.ndarray):
        """The split of a case whose LP point x violates (*) (v > 0 somewhere): a list of
        children (disks, contacts), or None when nothing is left to split."""
        ra_x = None
        for k in np.argsort(-v):
            if v[k] <= 0:
                return None
            if k in contacts:
                continue
            nz, eps = self.nz[k], self.eps[k]
            pts = []  # (disk, point) whose split decides the sign of a_t here
            if nz.size == 1:
                z = -self.bM[k] / eps[0]
                if abs(abs(z) - 1.0) <= 1e-12:
                    pts.append((int(nz[0]), int(round(z))))
            else:
                (i, j), (ei, ej) = nz, eps
                for a_, b_, ea, eb in ((i, j, ei, ej), (j, i, ej, ei)):
                    lo, hi, _, _ = _IV[int(disks[b_])]
                    if lo == hi:  # b_ at a point: a_t = 0 iff ra_a = -eb lo / ea
                        pts.append((int(a_), int(round(-eb * lo / ea))))
                if not pts:
                    if ra_x is None:
                        ra_x = self._ra(x)
                    for a_ in sorted((i, j), key=lambda d: -abs(ra_x[d])):
                        if abs(ra_x[a_]) >= 0.5 * self.M:
                            pts.append((int(a_), int(np.sign(ra_x[a_]))))
            for d, z in pts:
                if (int(disks[d]), z) in _AT:
                    kids = []
                    for st in _AT[(int(disks[d]), z)]:
                        child = disks.copy()
                        child[d] = st
                        kids.append((child, contacts))
                    return kids
            return [(disks, {**contacts, int(k): st}) for st in (1, -1, 0)]
        return None

    def _ra(self, x: np.ndarray) -> np.ndarray:
        return self.A[self.r_ra:self.r_ra + self.p, :2 * self.c] @ x


def disk_split_bound(form: Formulation, cost: np.ndarray, target: float, time_limit: float,
                     tol: float = 1e-9, max_cases: int | None = None, clock_name: str = "wall",
                     cases_class=None) -> DiskSplitBound | None:
    """A proved lower bound of cost . x (x = [R; S]) over every valid steady state (module
    docstring), splitting until every case is bounded at >= target - tol, the time limit or
    max_cases; None where it does not apply (no proved force box for cost, no rotation cap,
    T_u not of the form it needs). clock_name: the time limit in "wall" or "cpu" seconds
    (verify.ranges.milp.clock); `seconds` is wall time either way. cases_class: the case LP
    (default `_Cases`; a subclass may add rows valid on every valid steady state, as
    benchmarks/hull_bound.py does)."""
    now = clock(clock_name)
    t0, c0 = time.perf_counter(), now()
    system, dyn = form.system, form.dyn
    M = rotation_cap(system, dyn)
    if M is None or M <= 0 or form.R_hi is None or not form.proved_for(cost):
        return None
    cases = (cases_class or _Cases)(form, cost, M)
    goal = target - tol * max(1.0, abs(target))
    heap: list = []
    tick, n_cases, empty, closed_min, candidate = 0, 0, 0, np.inf, None

    def push(disks, contacts, parent_bound):
        nonlocal tick, n_cases, empty, closed_min
        b, x = cases.solve(disks, contacts)
        n_cases += 1
        if b == np.inf:
            empty += 1
            return
        b = max(b, parent_bound)
        if b >= goal:
            closed_min = min(closed_min, b)
            return
        tick += 1
        heapq.heappush(heap, (b, tick, disks, contacts, x))

    push(np.full(system.p, OPEN), {}, -np.inf)
    while heap and now() - c0 < time_limit and (
            max_cases is None or n_cases < max_cases):
        b, tk, disks, contacts, x = heapq.heappop(heap)
        kids = None if x is None else cases.split(disks, contacts, x, cases.violation(x))
        if kids is None:  # no point, or a point satisfying (*): the case stays open
            if x is not None and not np.any(cases.violation(x) > 0):
                candidate = x
            heapq.heappush(heap, (b, tk, disks, contacts, None))
            break
        for child, ctc in kids:
            push(child, ctc, b)
    bound = min([e[0] for e in heap] + [closed_min])
    return DiskSplitBound(float(bound), not heap, n_cases, len(heap), empty,
                          time.perf_counter() - t0, candidate)


def witness_of(form: Formulation, x: np.ndarray) -> SteadyWitness | None:
    """A checked steady state from a case point x = [R; S] that satisfies (*) (module
    docstring): the velocities (omega, V) = (alpha, gamma) (so v_t = a_t), the states read
    off sgn a_t, R reduced to least sum R with the same S on those states (the velocities and
    accelerations depend on S only), and `steady_check`'s residual <= WITNESS_TOL; else None."""
    system, dyn = form.system, form.dyn
    c, p = system.c, system.p
    if system.gamma == 0:
        return None
    omega = dyn.accelerations(x)[2 * p:]
    at = dyn.relative_accelerations(x)[c:]
    s = np.where(system.mu > 0, np.sign(np.where(np.abs(at) > 1e-9 * abs(system.gamma),
                                                 at, 0.0)), 0).astype(int)
    R = least_R(form, s, x[c:])
    if R is None:
        R = x[:c]
    wit = make_witness(system, omega, system.gamma, R, x[c:], dyn)
    return wit if wit.residual <= WITNESS_TOL else None


def _load(h, hs, cost, A, row_lo, row_hi, lb, ub) -> None:
    """Pass the LP min cost.x, row_lo <= A x <= row_hi, lb <= x <= ub to the instance h."""
    lp = hs.HighsLp()
    Ac = sp.csc_matrix(A)
    lp.num_col_, lp.num_row_ = A.shape[1], A.shape[0]
    lp.col_cost_, lp.col_lower_, lp.col_upper_ = cost, lb, ub
    lp.row_lower_, lp.row_upper_ = row_lo, row_hi
    lp.a_matrix_.format_ = hs.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (
        Ac.indptr, Ac.indices, Ac.data)
    h.passModel(lp)
