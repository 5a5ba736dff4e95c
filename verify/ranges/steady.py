"""Ranges of observables over every valid steady state of a system (docs/mechanics.md, "Valid
steady states"), by one mixed-integer program per end (scipy.optimize.milp, i.e. HiGHS).

Unknowns: the forces x = [R (c); S (c)], the velocities u = r omega (p, u_i = r_i omega_i with
each disk's own radius) and V, and per frictional
contact two binaries (y+, y-), y0 = 1 - y+ - y- (sliding with v_t > 0, v_t < 0, non-sliding).
With a = W x + q (models.dynamics) and v = the tangential relative velocities of (omega, V):

    a_n = 0 and the translational accelerations = 0 (every contact closed, no displacement),
    R >= 0, |S| <= mu R (Eq. 2.6), S = 0 where mu = 0,
    y+ => S = -mu R, a_t >= 0, v_t >= 1;   y- => S = +mu R, a_t <= 0, v_t <= -1;
    y0 => a_t = 0, v_t = 0                                            (Eqs. 2.6, 2.7, 2.10).

"v_t >= 1" is the normalization of the strict sign v_t > 0: the admissible (omega, V) of a
contact-state set form a cone (v is linear and homogeneous in (omega, V)), so a state with
strict signs can be scaled until every sliding |v_t| >= 1 (V free when gamma != 0; V = 0 or of
the sign of V0 when gamma = 0: the module `kinematics` below says why and proves the box).

Big-M constants, each a consequence of a bound that is proved or reported as not proved:
* velocities: |u_i|, |V| <= OMEGA = 2 (p + 1) (`velocity_box`: a system of two-variable unit
  inequalities, solved by shortest paths, has a solution within that box whenever it has one);
* forces: per contact |S| <= S_abs, R <= R_hi, proved by verify.ranges.bounds (LPs over the
  relaxation, the rows' self-stress reduced) for every observable of S and of the bounded R
  (`Formulation.proved_for`); where that proof fails, R <= U, proved when the linear
  relaxation bounds sum R, otherwise a box (default `BOX_FACTOR` m_g max(g, |gamma|)) and the
  range is "within the box", each end's contact states then checked for a ray (an end that
  grows without bound on its own contact states is reported "unbounded");
* a_t: the LP bounds of a_t (verify.ranges.bounds), else intervals from the r alpha bounds.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

from rigidlcp.lcp.errors import RigidLCPError
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.system import System

from .bounds import proved_bounds
from .result import OPTIMAL

#: Default force box (per contact) when no bound is proved, in units of m_g max(g, |gamma|).
BOX_FACTOR = 10.0
_MILP = {"mip_feasibility_tolerance": 1e-9, "primal_feasibility_tolerance": 1e-9,
         "mip_rel_gap": 0.0}
_LP = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


class NotSteady(RigidLCPError, ValueError):
    """Steady ranges asked of something that has none: a run that did not end steady, or a
    system without valid steady state."""


class NoVelocityBound(RigidLCPError, ValueError):
    """The tangential velocities are not two-variable unit forms in u = r omega (e.g. a normal
    row with a rotation): the velocity box of `velocity_box` is not proved."""


def velocity_box(dyn: Dynamics) -> tuple[np.ndarray, np.ndarray, float]:
    """(T_u, T_V, OMEGA): v_t = T_u u + T_V V with u_i = r_i omega_i (each disk's own radius:
    unequal radii keep the unit forms, v_t = -(r_i omega_i + r_j omega_j) = -(u_i + u_j)), and
    a box |u|, |V| <= OMEGA that contains a solution of every feasible system of sign
    conditions on v_t.

    Proof: each row of (T_u, T_V) has at most two nonzero entries, each +-1 (checked here;
    models.dynamics: plane -V - u_i, disks -(u_i + u_j), wall -u_i). The conditions v_t = 0,
    s v_t >= 1 and sgn(V0) V >= 1 are then unit two-variable inequalities x_i +- x_j <= b,
    +-x_i <= b with b in {0, -1} (one-variable: 2b in the doubled graph). Such a system is
    feasible iff the doubled constraint graph on 2N nodes (x_i and -x_i; N = p + 1 unknowns) has
    no negative cycle, and then x_i = (d(x_i+) - d(x_i-)) / 2 solves it, d the shortest-path
    distances from a source joined to every node by 0-weight edges (the octagon/UTVPI
    closure). Edge weights are >= -2 and simple paths have <= 2N - 1 edges, so
    -2 (2N - 1) <= d <= 0 and |x_i| <= 2N - 1 < OMEGA = 2N.
    """
    p, c, r = dyn.p, dyn.c, dyn.system.lattice.radii
    Ht = dyn.H[c:].toarray()
    T_u = Ht[:, 2 * p:] / r
    T_V = dyn.u_obs(1.0)[c:]
    T = np.column_stack([T_u, T_V])
    nz = np.abs(T) > 1e-12
    if np.any(nz.sum(axis=1) > 2) or np.any(np.abs(np.abs(T[nz]) - 1.0) > 1e-12):
        raise NoVelocityBound("tangential velocities are not of the form +-x_i +- x_j: the "
                              "velocity box is not proved for this system")
    return np.round(T_u), np.round(T_V), 2.0 * (p + 1)


@dataclass
class Formulation:
    """The MILP's constraint matrix and bounds; columns x = [R, S] (2c) | ra = r alpha (p) |
    u = r omega (p, per-disk r_i) | V | y+ (F) | y- (F), F = the frictional contacts."""

    system: System
    dyn: Dynamics
    A: sp.csr_matrix
    lo: np.ndarray
    hi: np.ndarray
    lb: np.ndarray
    ub: np.ndarray
    integrality: np.ndarray
    fric: np.ndarray
    U: float
    box_proved: bool
    omega_box: float
    V_mode: str  # "free" | "zero" | "positive" | "negative"
    notes: list[str] = field(default_factory=list)
    R_hi: np.ndarray | None = None  # per-contact force bounds (verify.ranges.bounds)
    free_R: np.ndarray | None = None  # contacts whose R bound holds for S-observables only
    v_rows: tuple[int, int] = (0, 0)  # the rows of v_t's big-M constraints (start, stop)

    def proved_for(self, L: np.ndarray) -> bool:
        """Whether the force bounds are proved for the observable L (verify.ranges.bounds:
        not for an observable that weighs the R of a self-stress group)."""
        if not self.box_proved:
            return False
        c = self.system.c
        return self.free_R is None or not np.any(np.asarray(L)[:c][self.free_R] != 0)

    @property
    def n_cont(self) -> int:
        return 2 * self.system.c + 2 * self.system.p + 1

    def start(self, R: np.ndarray, S: np.ndarray, omega: np.ndarray, V: float,
              s: np.ndarray) -> np.ndarray:
        """A full column vector for a known state (a MIP start), velocities scaled into the
        normalization (min sliding |v_t| = 1)."""
        sys_, c, p = self.system, self.system.c, self.system.p
        r = sys_.lattice.radii
        x = np.concatenate([R, S])
        ra = r * self.dyn.accelerations(x)[2 * p:]
        vt = self.dyn.velocities(omega, V)[c:]
        sl = s[self.fric] != 0
        k = 1.0 / max(float(np.min(np.abs(vt[self.fric][sl]), initial=np.inf)), 1e-300)
        k = 1.0 if not np.isfinite(k) else k
        yp = (s[self.fric] > 0).astype(float)
        ym = (s[self.fric] < 0).astype(float)
        return np.concatenate([x, ra, k * r * omega, [k * V], yp, ym])


def _equalities(dyn: Dynamics) -> tuple[np.ndarray, np.ndarray]:
    """Rows E x = e: a_n = 0 (every contact) and the translational accelerations = 0."""
    c, p = dyn.c, dyn.p
    HT = dyn.H.T.toarray()
    E = np.vstack([dyn.W[:c], HT[:2 * p]])
    e = np.concatenate([-dyn.q[:c], -dyn.f[:2 * p]])
    return E, e


def force_bound(system: System, dyn: Dynamics, box: float | None = None) -> tuple[float, bool]:
    """(U, proved): max sum R over the linear relaxation (a_n = 0, no translation, R >= 0,
    |S| <= mu R, S = 0 where mu = 0) if finite (then every valid steady state has R <= U:
    proved), else the box (not proved)."""
    c, mu = system.c, system.mu
    E, e = _equalities(dyn)
    I = np.eye(c)
    A_ub = np.vstack([np.hstack([-np.diag(mu), I]), np.hstack([-np.diag(mu), -I])])
    bounds = [(0, None)] * c + [(0, 0) if m == 0 else (None, None) for m in mu]
    res = linprog(-np.r_[np.ones(c), np.zeros(c)], A_ub=A_ub, b_ub=np.zeros(2 * c), A_eq=E,
                  b_eq=e, bounds=bounds, method="highs", options=_LP)
    if res.status == 2:
        raise NotSteady("no force satisfies a_n = 0 with Coulomb's cone: the system has no "
                        "steady state with every contact closed")
    default = BOX_FACTOR * system.total_mass * max(system.g, abs(system.gamma), 1e-12)
    if res.status == 0:
        return float(-res.fun) * (1 + 1e-6) + 1e-9 * default, True
    return (default if box is None else float(box)), False


def formulate(system: System, box: float | None = None, V_mode: str | None = None
              ) -> Formulation:
    """The MILP of the module docstring (no objective), in sparse form: the translational
    force balance per disk (no translation; with it a_n = 0 on every contact, checked below),
    the torque balance I_i alpha_i = -r_i sum S written for ra_i = r_i alpha_i (per disk), and
    a_t = T_u ra + T_V gamma (the same two-variable form as v_t)."""
    dyn = Dynamics(system)
    c, p, mu = system.c, system.p, system.mu
    r = system.lattice.radii
    fric = np.flatnonzero(mu > 0)
    F = fric.size
    T_u, T_V, OMEGA = velocity_box(dyn)
    Hn_rot = dyn.H[:c].toarray()[:, 2 * p:]
    if np.any(Hn_rot != 0) or np.any(dyn.u_obs_dot[:c] != 0):
        raise NoVelocityBound("a_n depends on rotations or on the plane's motion: not the "
                              "paper's regime")
    E, e = _equalities(dyn)
    fb = proved_bounds(system, dyn, E, e)
    if fb is not None:
        R_hi, S_abs, proved = fb.R_hi, fb.S_abs, True
        U = float(np.max(R_hi, initial=0.0))
    else:
        U, proved = force_bound(system, dyn, box)
        R_hi, S_abs = np.full(c, U), mu * U
    if V_mode is None:
        V_mode = ("free" if system.gamma != 0 else "zero" if system.V0 == 0
                  else "positive" if system.V0 > 0 else "negative")
    n = 2 * c + 2 * p + 1 + 2 * F
    iR, iS, ia, iu, iV = 0, c, 2 * c, 2 * c + p, 2 * c + 2 * p
    yp, ym = iV + 1, iV + 1 + F
    rows, lo, hi = [], [], []
    fidx = np.arange(F)

    def add(block, lower, upper) -> None:
        block = sp.csr_matrix(block)
        rows.append(block)
        lo.append(np.broadcast_to(np.asarray(lower, float), block.shape[0]).copy())
        hi.append(np.broadcast_to(np.asarray(upper, float), block.shape[0]).copy())

    def cols(blocks: dict[int, sp.spmatrix], m: int) -> sp.csr_matrix:
        out = sp.lil_matrix((m, n))
        for start, B in blocks.items():
            B = sp.csr_matrix(B)
            out[:, start:start + B.shape[1]] = B
        return out.tocsr()

    HT = sp.csr_matrix(dyn.H.T)
    add(cols({0: HT[:2 * p]}, 2 * p), -dyn.f[:2 * p], -dyn.f[:2 * p])  # no translation
    torque = sp.diags(r * dyn.Minv[2 * p:]) @ HT[2 * p:]  # ra = r M^-1 (H^T x)_rot
    add(cols({0: -torque, ia: sp.eye(p)}, p), 0.0, 0.0)
    Ef = sp.csr_matrix((np.ones(F), (fidx, fric)), shape=(F, c))
    Mu = sp.diags(mu[fric]) @ Ef
    for sgn in (1.0, -1.0):  # |S| <= mu R
        add(cols({iR: -Mu, iS: sgn * Ef}, F), -np.inf, 0.0)
    big = S_abs[fric] + mu[fric] * R_hi[fric]  # >= S + mu R and mu R - S
    for sgn, ycol in ((1.0, yp), (-1.0, ym)):  # y+ => S + mu R <= 0; y- => mu R - S <= 0
        add(cols({iR: Mu, iS: sgn * Ef, ycol: sp.diags(big)}, F), -np.inf, big)
    if fb is not None:
        ra_lo, ra_hi = fb.ra_lo, fb.ra_hi
    else:  # |ra_i| <= r_i^2 / I_i sum_{contacts of i} mu U over the force box
        touch = np.abs(HT[2 * p:].toarray())[:, c:] > 0
        ra_hi = r * dyn.Minv[2 * p:] * r * (touch @ (mu * U))
        ra_lo = -ra_hi
    gam = T_V[fric] * system.gamma
    Tp, Tm = np.maximum(T_u[fric], 0), np.minimum(T_u[fric], 0)
    A_hi = np.maximum(gam + Tp @ ra_hi + Tm @ ra_lo, 0.0)  # a_t in [A_lo, A_hi] (intervals)
    A_lo = np.minimum(gam + Tp @ ra_lo + Tm @ ra_hi, 0.0)
    if fb is not None:  # the LP bounds of a_t itself
        A_hi = np.maximum(np.minimum(A_hi, fb.at_hi[fric]), 0.0)
        A_lo = np.minimum(np.maximum(A_lo, fb.at_lo[fric]), 0.0)
    Tf = sp.csr_matrix(T_u[fric])
    # a_t = T_u ra + gam in [A_lo y-, A_hi y+]
    add(cols({ia: Tf, ym: sp.diags(-A_lo)}, F), -gam, np.inf)
    add(cols({ia: -Tf, yp: sp.diags(A_hi)}, F), gam, np.inf)
    # v_t = T_u u + T_V V in [y+ - B y-, B y+ - y-]  (B = 2 OMEGA bounds |v_t| in the box)
    B = 2.0 * OMEGA
    TV = sp.csr_matrix(T_V[fric][:, None])
    v_rows = (sum(b.shape[0] for b in rows), sum(b.shape[0] for b in rows) + 2 * F)
    add(cols({iu: Tf, iV: TV, yp: -sp.eye(F), ym: B * sp.eye(F)}, F), 0.0, np.inf)
    add(cols({iu: -Tf, iV: -TV, yp: B * sp.eye(F), ym: -sp.eye(F)}, F), 0.0, np.inf)
    add(cols({yp: sp.eye(F), ym: sp.eye(F)}, F), -np.inf, 1.0)  # y+ + y- <= 1
    lb = np.r_[np.zeros(c), -S_abs, ra_lo, np.full(p, -OMEGA), -OMEGA, np.zeros(2 * F)]
    ub = np.r_[R_hi, S_abs, ra_hi, np.full(p, OMEGA), OMEGA, np.ones(2 * F)]
    if V_mode == "zero":
        lb[iV] = ub[iV] = 0.0
    elif V_mode == "positive":
        lb[iV] = 1.0
    elif V_mode == "negative":
        ub[iV] = -1.0
    elif V_mode != "free":
        raise ValueError(f"V_mode must be free, zero, positive or negative, got {V_mode!r}")
    integrality = np.r_[np.zeros(2 * c + 2 * p + 1), np.ones(2 * F)]
    A = sp.vstack(rows).tocsr()
    return Formulation(system, dyn, A, np.concatenate(lo), np.concatenate(hi), lb, ub,
                       integrality, fric, U, proved, OMEGA, V_mode, [], R_hi,
                       None if fb is None else fb.free_R, v_rows)


def states_of(form: Formulation, y: np.ndarray) -> np.ndarray:
    """Tangential states (+1, -1, 0 non-sliding; 0 also for frictionless) from the binaries."""
    c, p, F = form.system.c, form.system.p, form.fric.size
    s = np.zeros(c, dtype=int)
    base = 2 * c + 2 * p + 1
    yp, ym = y[base:base + F], y[base + F:base + 2 * F]  # columns after them: not states
    s[form.fric] = np.where(yp > 0.5, 1, np.where(ym > 0.5, -1, 0))
    return s


# --------------------------------------------------------------------------------------------
# one contact-state set: its force polyhedron (LP), its rays, its velocities
# --------------------------------------------------------------------------------------------

def _state_lp(form: Formulation, s: np.ndarray, homogeneous: bool = False):
    """(A_ub, b_ub, A_eq, b_eq, bounds) of the forces x admissible for the states s (module
    docstring with the binaries fixed); homogeneous: its recession cone, with sum R <= 1."""
    system, dyn = form.system, form.dyn
    c, mu = system.c, system.mu
    E, e = _equalities(dyn)
    eq, eq_rhs = [E], [np.zeros_like(e) if homogeneous else e]
    ub, ub_rhs = [], []
    qt = np.zeros(c) if homogeneous else dyn.q[c:]
    for al in form.fric:
        row = np.zeros(2 * c)
        if s[al] != 0:
            row[c + al], row[al] = 1.0, s[al] * mu[al]
            eq.append(row[None, :])
            eq_rhs.append(np.zeros(1))
            ub.append(-s[al] * dyn.W[c + al])  # s a_t >= 0
            ub_rhs.append(s[al] * qt[al])
        else:
            eq.append(dyn.W[c + al][None, :])  # a_t = 0
            eq_rhs.append(np.array([-qt[al]]))
            for sgn in (1.0, -1.0):
                row = np.zeros(2 * c)
                row[c + al], row[al] = sgn, -mu[al]
                ub.append(row)
                ub_rhs.append(0.0)
    if homogeneous:
        ub.append(np.r_[np.ones(c), np.zeros(c)])
        ub_rhs.append(1.0)
    bounds = [(0, None)] * c + [(0, 0) if m == 0 else (None, None) for m in mu]
    return (np.array(ub).reshape(-1, 2 * c), np.array(ub_rhs), np.vstack(eq),
            np.concatenate(eq_rhs), bounds)


def state_extreme(form: Formulation, s: np.ndarray, L: np.ndarray, sense: int):
    """(status, x, ray): the extreme of sense * L x (sense +1: min, -1: max) over the forces of
    the states s, without the force box. ray: for "unbounded", a direction d of the recession
    cone with sense * L d < 0, sum R_d <= 1."""
    A_ub, b_ub, A_eq, b_eq, bounds = _state_lp(form, s)
    res = linprog(sense * L, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq, bounds=bounds,
                  method="highs", options=_LP)
    if res.status == 0:
        return OPTIMAL, res.x, None
    if res.status != 3:
        return "infeasible", None, None
    point = linprog(np.zeros_like(L), A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq,
                    bounds=bounds, method="highs", options=_LP)
    A_ub, b_ub, A_eq, b_eq, _ = _state_lp(form, s, homogeneous=True)
    cone = linprog(sense * L, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq, bounds=bounds,
                   method="highs", options=_LP)
    d = cone.x if cone.status == 0 and cone.fun < 0 else None
    return "unbounded", (point.x if point.status == 0 else None), d





def least_R(form: Formulation, s: np.ndarray, S: np.ndarray) -> np.ndarray | None:
    """The R of least sum with the given S on the states s (the self-stress reduction of
    verify.ranges.bounds: same S, same states), or None if the LP fails."""
    A_ub, b_ub, A_eq, b_eq, bounds = _state_lp(form, s)
    c = form.system.c
    bounds = bounds[:c] + [(v, v) for v in S]
    res = linprog(np.r_[np.ones(c), np.zeros(c)], A_ub=A_ub if A_ub.size else None,
                  b_ub=b_ub if A_ub.size else None, A_eq=A_eq, b_eq=b_eq, bounds=bounds,
                  method="highs", options=_LP)
    return res.x[:c] if res.status == 0 else None


def state_velocities(form: Formulation, s: np.ndarray) -> tuple[np.ndarray, float] | None:
    """(omega, V) whose tangential velocities have the signs s (s v_t >= 1 sliding, v_t = 0
    non-sliding; V as form.V_mode), or None when the kinematics admit no such velocities.
    With gamma = 0 and V0 != 0 the cone point is scaled to V = V0."""
    system, dyn = form.system, form.dyn
    p, r = system.p, system.lattice.radii
    T_u, T_V, OMEGA = velocity_box(dyn)
    T = np.column_stack([T_u, T_V])
    fr = form.fric
    sl, ns = fr[s[fr] != 0], fr[s[fr] == 0]
    A_ub = -(s[sl][:, None] * T[sl])
    bounds = [(-OMEGA, OMEGA)] * (p + 1)
    V_lo, V_hi = {"free": (-OMEGA, OMEGA), "zero": (0, 0), "positive": (1, OMEGA),
                  "negative": (-OMEGA, -1)}[form.V_mode]
    bounds[p] = (V_lo, V_hi)
    res = linprog(np.zeros(p + 1), A_ub=A_ub if sl.size else None,
                  b_ub=-np.ones(sl.size) if sl.size else None,
                  A_eq=T[ns] if ns.size else None, b_eq=np.zeros(ns.size) if ns.size else None,
                  bounds=bounds, method="highs", options=_LP)
    if res.status != 0:
        return None
    u, V = res.x[:p], float(res.x[p])
    if form.V_mode in ("positive", "negative"):
        k = system.V0 / V
        u, V = u * k, system.V0
    return u / r, V
