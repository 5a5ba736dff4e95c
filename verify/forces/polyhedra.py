"""Admissible force sets of indeterminate states (Sec. III C): polyhedra and force ranges.

The forces x = [R; S] compatible with the contact laws form a polyhedron
P = {x : A_eq x = b_eq, A_ub x <= b_ub, R >= 0} (see forces.particular, which re-exports every
name of this module, for the two ways to build it and for the particular solutions):
`state_polyhedron` (a vector of contact states: Eq. 2.15 and the laws' inequalities),
`solution_polyhedron` (the accelerations of an event solution fixed), `lcp_polyhedron` (the w of
an LCP solution fixed), and `force_ranges` ([min, max] of each force and of observables such as
F_g, by linear programs).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linprog

from rigidlcp.lcp.errors import InvalidInput, RigidLCPError
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.event import EventProblem, acceleration_tol, contact_matrix
from rigidlcp.models.lattice import PLANE
from rigidlcp.models.system import System
from rigidlcp.verify.certificates.uniqueness import scales

_HIGHS = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


class EmptyPolyhedron(RigidLCPError, ValueError):
    """The contact states (or the accelerations) admit no force: the states are not admissible."""


@dataclass
class Polyhedron:
    """{x : A_eq x = b_eq, A_ub x <= b_ub, lb <= x <= ub}; x = [R (c); S (c)] for forces.

    ns: contacts whose friction is free in [-mu R, mu R]; mu: coefficients; scale: force scale
    (max(m g, m |gamma|) per disk, or |z*| for an LCP) used by the zero tests.
    """

    A_eq: np.ndarray
    b_eq: np.ndarray
    A_ub: np.ndarray
    b_ub: np.ndarray
    lb: np.ndarray
    ub: np.ndarray
    c: int
    mu: np.ndarray
    ns: np.ndarray
    scale: float
    description: str = ""
    system: System | None = field(default=None, repr=False)

    @property
    def n(self) -> int:
        return self.lb.size

    def residuals(self, x: np.ndarray) -> tuple[float, float]:
        """(max|A_eq x - b_eq|, largest violation of the inequalities and bounds)."""
        eq = float(np.max(np.abs(self.A_eq @ x - self.b_eq), initial=0.0))
        viol = max(float(np.max(self.A_ub @ x - self.b_ub, initial=0.0)),
                   float(np.max(self.lb - x, initial=0.0)), float(np.max(x - self.ub, initial=0.0)))
        return eq, viol

    def contains(self, x: np.ndarray, tol: float = 1e-8) -> bool:
        """x in P up to tol times the scale (equations scaled by the size of their terms)."""
        eq, viol = self.residuals(x)
        terms = float(np.max(np.abs(self.A_eq) @ np.abs(x) + np.abs(self.b_eq), initial=0.0))
        return eq <= tol * max(terms, self.scale) and viol <= tol * self.scale

    def lp(self, cost: np.ndarray, **extra):
        """linprog (HiGHS) of cost . x over P."""
        return linprog(cost, A_ub=self.A_ub if self.A_ub.size else None,
                       b_ub=self.b_ub if self.b_ub.size else None,
                       A_eq=self.A_eq, b_eq=self.b_eq, bounds=self._bounds(), method="highs",
                       options=_HIGHS, **extra)

    def _bounds(self) -> list[tuple[float | None, float | None]]:
        return [(None if not np.isfinite(lo) else lo, None if not np.isfinite(hi) else hi)
                for lo, hi in zip(self.lb, self.ub)]


def _force_scale(system: System) -> float:
    return system.mass * max(system.g, abs(system.gamma), 1e-12)


def state_polyhedron(system: System, normal: np.ndarray, tangential: np.ndarray,
                     dyn: Dynamics | None = None) -> Polyhedron:
    """Forces admissible for a vector of contact states (Eq. 2.15 and the laws' inequalities).

    normal[alpha]: True = transmitting (T), False = nontransmitting (NT). tangential[alpha]:
    0 = non-sliding (NS), +1 / -1 = sliding with sgn(v_t) = +-1 (at v_t != 0: no sign condition on
    a_t). See the module docstring.
    """
    dyn = dyn or Dynamics(system)
    c, mu = system.c, system.mu
    normal = np.asarray(normal, dtype=bool).reshape(-1)
    tang = np.array(tangential, dtype=int).reshape(-1)
    if normal.size != c or tang.size != c:
        raise InvalidInput(f"one state per contact expected ({c})")
    tang[mu == 0] = 1  # frictionless: the row S + 1 * 0 * R = 0
    A_eq, b_eq = contact_matrix(system, normal, tang, dyn)
    rows, rhs = [], []
    ns = (tang == 0) & (mu > 0)
    for a in np.flatnonzero(ns):  # |S| <= mu R
        for sgn in (1.0, -1.0):
            r = np.zeros(2 * c)
            r[c + a], r[a] = sgn, -mu[a]
            rows.append(r)
            rhs.append(0.0)
    for a in np.flatnonzero(~normal):  # a_n = (W x + q)_n >= 0 on NT contacts
        rows.append(-dyn.W[a])
        rhs.append(dyn.q[a])
    lb = np.r_[np.zeros(c), np.full(c, -np.inf)]
    return Polyhedron(
        A_eq, b_eq, np.array(rows).reshape(-1, 2 * c), np.array(rhs), lb, np.full(2 * c, np.inf),
        c, mu.copy(), ns, _force_scale(system),
        f"contact states: {int(normal.sum())} T / {int((~normal).sum())} NT, "
        f"{int(ns.sum())} NS, {int(((tang != 0) & (mu > 0)).sum())} sliding", system,
    )


def solution_polyhedron(ep: EventProblem, z: np.ndarray, tol: float | None = None) -> Polyhedron:
    """All forces with the generalized accelerations of the LCP solution z (module docstring).

    tol: the zero test for accelerations (default models.event.acceleration_tol).
    """
    system, dyn = ep.system, ep.dyn
    c, mu = system.c, system.mu
    x_star = ep.forces(np.asarray(z, dtype=float))
    a = dyn.W @ x_star + dyn.q
    tol_a = acceleration_tol(system) if tol is None else tol
    HT = np.asarray(dyn.H.T.todense())
    eq_rows = [HT]
    eq_rhs = [HT @ x_star]
    ub_rows, ub_rhs = [], []

    def row(entries: dict[int, float]) -> np.ndarray:
        r = np.zeros(2 * c)
        for k, v in entries.items():
            r[k] = v
        return r

    ns = np.zeros(c, dtype=bool)
    cand = set(ep.candidates.tolist())
    for al in range(c):
        if a[al] > tol_a:
            eq_rows.append(row({al: 1.0})[None, :])
            eq_rhs.append(np.zeros(1))
        if mu[al] == 0:
            slope = 0.0
        elif al not in cand:
            slope = float(ep.s[al])  # S = -s mu R (Eq. 2.10)
        elif a[c + al] > tol_a:
            slope = 1.0  # S = -mu R
        elif a[c + al] < -tol_a:
            slope = -1.0  # S = +mu R
        else:
            ns[al] = True
            ub_rows += [row({c + al: 1.0, al: -mu[al]}), row({c + al: -1.0, al: -mu[al]})]
            ub_rhs += [0.0, 0.0]
            continue
        eq_rows.append(row({c + al: 1.0, al: slope * mu[al]})[None, :])
        eq_rhs.append(np.zeros(1))
    lb = np.r_[np.zeros(c), np.full(c, -np.inf)]
    return Polyhedron(
        np.vstack(eq_rows), np.concatenate(eq_rhs), np.array(ub_rows).reshape(-1, 2 * c),
        np.array(ub_rhs), lb, np.full(2 * c, np.inf), c, mu.copy(), ns, _force_scale(system),
        "forces with the accelerations of a given solution", system,
    )


def lcp_polyhedron(M: np.ndarray, q: np.ndarray, z: np.ndarray, delta: float = 1e-9
                   ) -> Polyhedron:
    """{z' >= 0 : M z' + q = w*, z'_i = 0 where w*_i > delta w_s}: the LCP solutions with w = w*.

    (Variables z', c = n, no friction structure: paper_solution then maximizes zeros of z'.)
    """
    M, q, z = (np.asarray(v, dtype=float) for v in (M, q, z))
    n = q.size
    zs, ws = scales(M, q, z)
    w = M @ z + q
    ub = np.where(w > delta * ws, 0.0, np.inf)
    return Polyhedron(M, w - q, np.zeros((0, n)), np.zeros(0), np.zeros(n), ub, n,
                      np.zeros(n), np.zeros(n, dtype=bool), zs, "LCP solutions with w fixed")


def global_friction_vector(system: System) -> np.ndarray:
    """F_g = g . x with x = [R; S]: the sum of S over the plane contacts (models.observables)."""
    g = np.zeros(2 * system.c)
    g[system.c + np.flatnonzero(system.lattice.j == PLANE)] = 1.0
    return g


# --------------------------------------------------------------------------------------------
# ranges
# --------------------------------------------------------------------------------------------

@dataclass
class Ranges:
    """[lo, hi] of every variable (lo[:c], hi[:c]: R; lo[c:], hi[c:]: S) and of observables.
    +-inf: unbounded over the polyhedron."""

    lo: np.ndarray
    hi: np.ndarray
    c: int
    observables: dict[str, tuple[float, float]] = field(default_factory=dict)

    @property
    def width(self) -> np.ndarray:
        return self.hi - self.lo

    def indeterminate(self, tol: float) -> np.ndarray:
        """Indices of the variables whose range is wider than tol."""
        return np.flatnonzero(self.width > tol)

    def contains(self, x: np.ndarray, tol: float) -> bool:
        return bool(np.all(x >= self.lo - tol) and np.all(x <= self.hi + tol))


def force_ranges(poly: Polyhedron, observables: dict[str, np.ndarray] | None = None,
                 variables: np.ndarray | None = None) -> Ranges:
    """min and max of each variable (default: all) and of each observable g . x over P:
    two LPs each (HiGHS). Raises EmptyPolyhedron when P is empty."""
    first = poly.lp(np.zeros(poly.n))
    if first.status == 2:
        raise EmptyPolyhedron(f"no admissible forces ({poly.description}): {first.message}")
    idx = np.arange(poly.n) if variables is None else np.asarray(variables, dtype=int)
    lo = np.full(poly.n, np.nan)
    hi = np.full(poly.n, np.nan)

    def extent(g: np.ndarray) -> tuple[float, float]:
        out = []
        for sgn in (1.0, -1.0):
            r = poly.lp(sgn * g)
            if r.status == 3:
                out.append(-np.inf if sgn > 0 else np.inf)
            elif r.status == 0:
                out.append(sgn * r.fun)
            else:
                raise RuntimeError(f"LP failed while measuring a range: {r.message}")
        return out[0], out[1]

    for k in idx:
        e = np.zeros(poly.n)
        e[k] = 1.0
        lo[k], hi[k] = extent(e)
    obs = {name: extent(np.asarray(g, dtype=float)) for name, g in (observables or {}).items()}
    return Ranges(lo, hi, poly.c, obs)


def event_z(ep: EventProblem, x: np.ndarray) -> np.ndarray:
    """The event LCP's z = [R, tau, a_minus] of a force vector x = [R; S] (models.event):
    tau = mu R + S and a_minus = max(-a_t, 0) on the non-sliding candidates."""
    c = ep.system.c
    x = np.asarray(x, dtype=float)
    cand = ep.candidates
    a_t = (ep.dyn.W @ x + ep.dyn.q)[c:]
    tau = ep.system.mu[cand] * x[cand] + x[c + cand]
    return np.concatenate([x[:c], tau, np.maximum(-a_t[cand], 0.0)])
