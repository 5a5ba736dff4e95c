"""The complementarity problem of an event (Sec. II B-C) and the paper's contact matrix (Eq. 2.15).

At an event every contact is closed (no displacement) and carries (R, S). With lambda = [R; S]
and a = W lambda + q (models.dynamics):

* Signorini at acceleration level, Eq. (2.5), on every contact:   0 <= R  perp  a_n >= 0;
* a sliding contact (v_t != 0), Eq. (2.10): S = -sgn(v_t) mu R is substituted, each contact with
  its own mu (the coefficient of the contact whose force it is multiplies that column of W);
* a frictionless contact (mu = 0): S = 0;
* a non-sliding candidate (v_t = 0, mu > 0), the three alternatives of Eq. (2.7), written with
  tau = mu R + S in [0, 2 mu R] and a_t = a_plus - a_minus:
      0 <= tau       perp  a_plus = a_t + a_minus >= 0,
      0 <= a_minus   perp  2 mu R - tau >= 0.
  (a_t > 0 forces tau = 0, i.e. S = -mu R; a_t < 0 forces a_minus > 0, i.e. S = +mu R;
  a_t = 0 leaves S anywhere in [-mu R, mu R]: exactly Eq. (2.7).)

The LCP unknowns are z = [R (c), tau (k), a_minus (k)] for k candidates, so n = c + 2k.
The MLCP keeps the free generalized accelerations u = nu' (Siconos's layout):
    M u - H^T G z - f = 0,      w = D u + B v + b,
whose Schur complement is the LCP.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from rigidlcp.lcp import LCP, MLCP
from rigidlcp.lcp.errors import InvalidInput
from rigidlcp.lcp.problems.friction import FrictionContact2D

from .dynamics import Dynamics
from .system import System


@dataclass
class State:
    """The kinematic state at time t: angular velocities omega, the box's velocity V relative to
    the plane, and the tangential state s of every contact: +1 / -1 sliding with sgn(v_t) = s,
    0 when v_t = 0 (a non-sliding candidate; frictionless contacts carry 0 too, unused).

    s is kept explicitly rather than read off sgn(v_t): at an event v_t is zero only up to
    rounding, and the sign a contact slides with is decided by the LCP (Eq. 2.7), not by noise.
    """

    t: float
    omega: np.ndarray
    V: float
    s: np.ndarray

    def copy(self) -> State:
        return State(self.t, self.omega.copy(), self.V, self.s.copy())


def initial_state(
    system: System,
    omega: np.ndarray | None = None,
    seed: int | None = None,
    omega_scale: float = 1.0,
    zero_tol: float = 0.0,
) -> State:
    """State at t = 0: the given angular velocities, or uniform in [-omega_scale, omega_scale]
    drawn from `seed` (zeros when neither is given). Contacts with |v_t| <= zero_tol start as
    non-sliding candidates."""
    p = system.p
    if omega is None and seed is not None:
        if not (np.isfinite(omega_scale) and omega_scale >= 0):
            raise InvalidInput(f"omega_scale must be a finite number >= 0, got {omega_scale!r}")
        if isinstance(seed, (int, np.integer)) and seed < 0:  # numpy's own message names none
            raise InvalidInput(f"seed must be an integer >= 0, got {seed!r}")
    if omega is None:
        omega = (
            np.zeros(p) if seed is None
            else np.random.default_rng(seed).uniform(-omega_scale, omega_scale, p)
        )
    omega = np.array(omega, dtype=float).reshape(-1)
    if omega.size != p:
        raise InvalidInput(f"omega must have one angular velocity per disk ({p}), got {omega.size}")
    if not np.all(np.isfinite(omega)):
        raise InvalidInput("omega contains NaN or Inf")
    vt = Dynamics(system).velocities(omega, system.V0)[system.c:]
    s = np.where(np.abs(vt) <= zero_tol, 0, np.sign(vt)).astype(int)
    s[system.mu == 0] = 0
    return State(0.0, omega, float(system.V0), s)


@dataclass
class EventProblem:
    """The LCP / MLCP of one event, with what is needed to turn its solution into mechanics."""

    system: System
    dyn: Dynamics
    s: np.ndarray  # sgn(v_t) for sliding contacts, 0 for candidates and frictionless contacts
    candidates: np.ndarray  # indices of the non-sliding candidates (v_t = 0, mu > 0)
    G: np.ndarray  # lambda = G z
    lcp: LCP
    B: np.ndarray = field(repr=False)  # w = D u + B z + b (shared by the LCP and the MLCP)
    b: np.ndarray = field(repr=False)
    t: float = 0.0

    @property
    def k(self) -> int:
        return self.candidates.size

    @cached_property
    def mlcp(self) -> MLCP:
        """The MLCP in Siconos's layout: M u - H^T G z - f = 0, w = D u + B z + b. Built on
        first use (a run solves the LCP and never needs it)."""
        c, k, dyn = self.system.c, self.k, self.dyn
        H = dyn.H.toarray()
        D = np.vstack([H[:c], H[c:][self.candidates], np.zeros((k, 3 * self.system.p))])
        return MLCP(np.diag(1.0 / dyn.Minv), -(H.T @ self.G), D, self.B, -dyn.f, self.b,
                    name="event", meta={"t": self.t})

    def forces(self, z: np.ndarray) -> np.ndarray:
        """lambda = [R; S] of a solution z."""
        return self.G @ z

    def friction_contact(self) -> FrictionContact2D:
        """This event as a 2D friction-contact problem (lcp.FrictionContact2D, Siconos's layout:
        normal and tangent of contact alpha at 2 alpha, 2 alpha + 1) at acceleration level.

        A non-sliding candidate is a contact of the problem with its own mu (Eqs. 2.5, 2.7 are
        the problem's Signorini-Coulomb law). A sliding contact's friction S = -s mu R
        (Eq. 2.10) is folded into the column of its R, which makes W non-symmetric, and its
        tangent unknown is a dummy with mu = 0 and a zero column (so r_t = 0 and u_t is free),
        as is a frictionless contact's. `forces_of` maps the problem's r back to [R; S]."""
        c, mu = self.system.c, self.system.mu
        W, q = self.dyn.W.copy(), self.dyn.q
        sliding = (self.s != 0) & (mu > 0)
        slope = np.where(sliding, -self.s * mu, 0.0)
        W[:, :c] += W[:, c:] * slope
        W[:, c:][:, sliding] = 0.0
        order = np.arange(2 * c).reshape(2, c).T.reshape(-1)  # [n0, t0, n1, t1, ...]
        mu_fc = np.zeros(c)
        mu_fc[self.candidates] = mu[self.candidates]
        return FrictionContact2D(W[np.ix_(order, order)], q[order], mu_fc, name="event",
                                 meta={"t": self.t})

    def forces_of(self, r: np.ndarray) -> np.ndarray:
        """lambda = [R; S] of a solution r of `friction_contact` (Siconos's layout)."""
        mu = self.system.mu
        r = np.asarray(r, dtype=float).reshape(-1)
        R = r[0::2]
        S = np.where((self.s != 0) & (mu > 0), -self.s * mu * R, 0.0)
        S[self.candidates] = r[1::2][self.candidates]
        return np.concatenate([R, S])

    def unpack(self, z: np.ndarray, tol: float | None = None) -> EventSolution:
        """Forces, accelerations and contact states of an LCP solution z."""
        c, p = self.system.c, self.system.p
        lam = self.forces(z)
        nu_dot = self.dyn.accelerations(lam)
        a = self.dyn.H @ nu_dot + self.dyn.u_obs_dot
        tol_a = acceleration_tol(self.system) if tol is None else tol
        new_s = self.s.copy()
        at = a[c:][self.candidates]
        new_s[self.candidates] = np.where(at > tol_a, 1, np.where(at < -tol_a, -1, 0))
        return EventSolution(
            R=lam[:c], S=lam[c:], omega_dot=nu_dot[2 * p:], trans_acc=nu_dot[: 2 * p],
            a_n=a[:c], a_t=a[c:], s=new_s, z=z,
        )


@dataclass
class EventSolution:
    """Forces and accelerations of an event. s: the tangential state after the event
    (+1/-1 sliding, 0 non-sliding, i.e. v_t = a_t = 0, or frictionless)."""

    R: np.ndarray
    S: np.ndarray
    omega_dot: np.ndarray
    trans_acc: np.ndarray
    a_n: np.ndarray
    a_t: np.ndarray
    s: np.ndarray
    z: np.ndarray


def acceleration_tol(system: System) -> float:
    """Zero test for accelerations: 1e-9 of the driving scale (g, |gamma|)."""
    return 1e-9 * max(system.g, abs(system.gamma), 1e-12)


def event_problem(system: System, state: State, dyn: Dynamics | None = None) -> EventProblem:
    """The LCP of the event at `state` (and its MLCP, of which the LCP is the Schur complement)."""
    dyn = dyn or Dynamics(system)
    c = system.c
    mu = system.mu
    s = np.asarray(state.s, dtype=int).reshape(-1)
    if s.size != c or not np.all((s >= -1) & (s <= 1)):
        raise ValueError(f"state.s must hold one of -1, 0, +1 per contact ({c})")
    frictionless = mu == 0
    cand_mask = (s == 0) & ~frictionless
    s = np.where(frictionless, 0, s)
    cand = np.flatnonzero(cand_mask)
    k = cand.size
    n = c + 2 * k
    # lambda = G z: R = z[:c]; S = -s mu R (sliding), tau - mu R (candidates), 0 (frictionless).
    G = np.zeros((2 * c, n))
    G[np.arange(c), np.arange(c)] = 1.0
    slope = np.where(cand_mask, -mu, -s * mu)
    G[c + np.arange(c), np.arange(c)] = slope
    G[c + cand, c + np.arange(k)] = 1.0
    # Complementarity rows: w = D u + B z + b (D in EventProblem.mlcp).
    B = np.zeros((n, n))
    B[c : c + k, c + k :] = np.eye(k)  # a_plus = a_t + a_minus
    B[c + k + np.arange(k), cand] = 2.0 * mu[cand]  # 2 mu R - tau
    B[c + k :, c : c + k] = -np.eye(k)
    b = np.concatenate([dyn.u_obs_dot[:c], dyn.u_obs_dot[c:][cand], np.zeros(k)])
    # The Schur complement, assembled from W directly (cheaper than through the MLCP): the
    # rows of W G that enter (a_n, and a_t of the candidates); G has one or two entries per
    # column (R: 1 and the slope; tau: 1; a_minus: none), so W G is two column operations.
    Wr = dyn.W[np.concatenate([np.arange(c), c + cand])]
    M = B.copy()
    M[: c + k, :c] += Wr[:, :c] + Wr[:, c:] * slope
    M[: c + k, c : c + k] += Wr[:, c + cand]
    q = np.concatenate([dyn.q[:c], dyn.q[c:][cand], np.zeros(k)])
    lcp = LCP(M, q, name="event", meta={"t": state.t, "c": c, "k": k})
    return EventProblem(system, dyn, s, cand, G, lcp, B, b, state.t)


def contact_matrix(
    system: System,
    normal: np.ndarray,
    tangential: np.ndarray,
    dyn: Dynamics | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The paper's linear system M x = b (Eq. 2.15) for given contact states.

    x = [R (c); S (c)]. normal[alpha]: True (T: a_n = 0, Eq. 2.9) or False (NT: R = 0, Eq. 2.8).
    tangential[alpha]: 0 (NS: a_t = 0, Eq. 2.12) or +1 / -1 (sliding with sgn(v_t) = +-1:
    S + sgn mu R = 0, Eq. 2.10). Rows 0..c-1 are the normal equations, c..2c-1 the tangential.

    The states are taken literally, as the paper's iteration does: "NS" writes a_t = 0 even on a
    frictionless contact (where Coulomb's law would give S = 0), so that the counts of Eq. (3.4)
    can be computed with rough walls; admissibility of the states is the caller's business.
    """
    dyn = dyn or Dynamics(system)
    c = system.c
    normal = np.asarray(normal, dtype=bool).reshape(-1)
    tangential = np.asarray(tangential).reshape(-1)
    if normal.size != c or tangential.size != c:
        raise ValueError(
            f"one state per contact expected ({c}): got {normal.size} normal and "
            f"{tangential.size} tangential states"
        )
    if not np.all(np.isin(tangential, (-1, 0, 1))):
        raise ValueError("tangential states must be 0 (NS), +1 or -1 (sliding)")
    W, q = dyn.W, dyn.q
    Mc = np.zeros((2 * c, 2 * c))
    rhs = np.zeros(2 * c)
    idx = np.arange(c)
    Mc[idx[normal]] = W[idx[normal]]
    rhs[idx[normal]] = -q[idx[normal]]
    Mc[idx[~normal], idx[~normal]] = 1.0
    ns = tangential == 0
    Mc[c + idx[ns]] = W[c + idx[ns]]
    rhs[c + idx[ns]] = -q[c + idx[ns]]
    sl = idx[~ns]
    Mc[c + sl, c + sl] = 1.0
    Mc[c + sl, sl] = tangential[sl] * system.mu[sl]
    return Mc, rhs
