"""Indeterminate forces (Sec. III C, Fig. 4): admissible sets, force ranges, particular solutions.

When the contact matrix of Eq. (2.15) is singular (Sec. III B), the forces x = [R; S] compatible
with the contact laws form a polyhedron, not a point:

    P = {x : A_eq x = b_eq,  A_ub x <= b_ub,  R >= 0}.

Two ways to fix what is known and leave the rest free:

* `state_polyhedron(system, normal, tangential)`: a given vector of contact states. A_eq x = b_eq
  is the paper's M x = b (models.contact_matrix: a_n = 0 on T contacts, Eq. 2.9; R = 0 on NT
  contacts, Eq. 2.8; a_t = 0 on non-sliding ones, Eq. 2.12; S = -sgn(v_t) mu R on sliding ones,
  Eq. 2.10), and the inequalities are those of the contact laws: R >= 0 (Eq. 2.5), a_n >= 0 on NT
  contacts (Eq. 2.5), |S| <= mu R on NS contacts (Eq. 2.7). A frictionless contact (mu = 0)
  always gets S = 0, whatever its tangential state. Every point of P is a solution of the event's
  complementarity problem; different points may have different angular accelerations (a sliding
  friction force mu R changes with R and exerts a torque).
* `solution_polyhedron(event_problem, z)`: every force vector with the same generalized
  accelerations nu' as the LCP solution z (H^T x = H^T x*, Newton-Euler M nu' = H^T x + f) and
  the contact laws those accelerations impose: R = 0 where a_n > 0; S = -s mu R on sliding
  contacts; on a non-sliding candidate S = -mu R if a_t > 0, +mu R if a_t < 0, |S| <= mu R if
  a_t = 0. These are exactly the LCP solutions with the accelerations of z. (Fixing the LCP's w
  instead would also fix the slack 2 mu R - tau, a force: `lcp_polyhedron` does that for a bare
  LCP, {z' >= 0 : M z' + q = w*, z'_i = 0 where w*_i > 0}.)

Over P: `force_ranges` (the [min, max] of every force and of observables such as the global
friction F_g = sum of S over plane contacts, models.observables, by linear programs);
`min_norm_solution` (least |x|_2, a QP through cvxpy with Clarabel or OSQP); `paper_solution`
(the paper's choice, Sec. III C: "as many sliding and nontransmitting contacts as possible":
the most contacts with R = 0, plus non-sliding contacts with S = +-mu R, by a MILP, or the
L1 heuristic min sum R); `random_vertex` (a vertex minimizing a random positive weighting of R:
the different normal-force networks of Fig. 4).

The polyhedra and ranges live in verify/polyhedra.py and are re-exported here, so that
`from rigidlcp.verify.forces.particular import ...` reaches everything.
"""

from __future__ import annotations

from dataclasses import dataclass

import cvxpy as cp
import numpy as np
import scipy.sparse as sp
from scipy.optimize import Bounds, LinearConstraint, milp

from rigidlcp.lcp.errors import InvalidInput
from rigidlcp.verify.certificates.uniqueness import quiet_highs

from .polyhedra import (
    EmptyPolyhedron,
    Polyhedron,
    Ranges,
    event_z,
    force_ranges,
    global_friction_vector,
    lcp_polyhedron,
    solution_polyhedron,
    state_polyhedron,
)

__all__ = [
    "EmptyPolyhedron", "Polyhedron", "Ranges", "event_z", "force_ranges",
    "global_friction_vector", "lcp_polyhedron", "solution_polyhedron", "state_polyhedron",
    "Particular", "min_norm_solution", "paper_solution", "random_vertex",
]

#: Cap on forces for the MILP when the polyhedron is unbounded, in units of the force scale.
UNBOUNDED_CAP = 1e3

# --------------------------------------------------------------------------------------------
# particular solutions
# --------------------------------------------------------------------------------------------

@dataclass
class Particular:
    """A chosen point of P: x, how many R vanish (NT) and how many NS frictions sit at +-mu R."""

    x: np.ndarray
    c: int
    method: str
    n_nt: int
    n_at_threshold: int
    eq_residual: float
    violation: float
    message: str = ""

    @property
    def R(self) -> np.ndarray:
        return self.x[: self.c]

    @property
    def S(self) -> np.ndarray:
        return self.x[self.c: 2 * self.c]


def _particular(poly: Polyhedron, x: np.ndarray, method: str, message: str = "",
                zero_tol: float = 1e-9) -> Particular:
    c = poly.c
    R = x[:c]
    t = zero_tol * poly.scale
    nt = int(np.sum(R <= t))
    thr = 0
    if poly.ns.any():
        S = x[c:2 * c]
        thr = int(np.sum(poly.ns & (np.abs(np.abs(S) - poly.mu * R) <= t) & (R > t)))
    eq, viol = poly.residuals(x)
    return Particular(x, c, method, nt, thr, eq, viol, message)


def _independent_rows(A: np.ndarray, b: np.ndarray, rtol: float = 1e-10
                      ) -> tuple[np.ndarray, np.ndarray]:
    """An orthogonal basis of the row space of A (and the matching b), for the QP."""
    if A.shape[0] == 0:
        return A, b
    U, s, Vt = np.linalg.svd(A, full_matrices=False)
    r = int(np.sum(s > rtol * s[0])) if s.size and s[0] > 0 else 0
    return s[:r, None] * Vt[:r], U[:, :r].T @ b


def min_norm_solution(poly: Polyhedron, solver: str = "CLARABEL") -> Particular:
    """The point of P of least Euclidean norm |x|_2 (a QP through cvxpy; Clarabel or OSQP).

    The equations are first reduced to an orthogonal basis of their row space (the contact
    matrix is singular, that is the point), so the QP has independent equality constraints.
    """
    solver = solver.upper()
    if solver not in ("CLARABEL", "OSQP"):
        raise InvalidInput(f"solver must be 'CLARABEL' or 'OSQP', got {solver!r}")
    A, b = _independent_rows(poly.A_eq, poly.b_eq)
    x = cp.Variable(poly.n)
    cons = [A @ x == b]
    if poly.A_ub.size:
        cons.append(poly.A_ub @ x <= poly.b_ub)
    fin_lo, fin_hi = np.isfinite(poly.lb), np.isfinite(poly.ub)
    if fin_lo.any():
        cons.append(x[np.flatnonzero(fin_lo)] >= poly.lb[fin_lo])
    if fin_hi.any():
        cons.append(x[np.flatnonzero(fin_hi)] <= poly.ub[fin_hi])
    prob = cp.Problem(cp.Minimize(cp.sum_squares(x)), cons)
    opts = ({"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10}
            if solver == "CLARABEL" else
            {"eps_abs": 1e-10, "eps_rel": 1e-10, "polishing": True, "max_iter": 200_000})
    prob.solve(solver=solver, **opts)
    if prob.status not in ("optimal", "optimal_inaccurate") or x.value is None:
        if prob.status in ("infeasible", "infeasible_inaccurate"):
            raise EmptyPolyhedron(f"no admissible forces ({poly.description})")
        raise RuntimeError(f"{solver} ended with status {prob.status}")
    x0 = np.asarray(x.value, dtype=float)
    xp = _polish_min_norm(poly, x0)
    polished = xp is not None
    return _particular(poly, xp if polished else x0, f"min-norm ({solver.lower()})",
                       prob.status + ("; active-set polished" if polished else ""))


def _polish_min_norm(poly: Polyhedron, x: np.ndarray, active_tol: float = 1e-4
                     ) -> np.ndarray | None:
    """Active-set polish of a QP point: interior-point methods leave weakly active constraints
    (zero multiplier, e.g. R = 0 where the objective's gradient vanishes) at ~sqrt(gap) from the
    bound. The constraints within active_tol x scale of being tight are made equalities and the
    minimum-norm solution of the resulting linear system (pinv) is taken; it is kept if it is
    feasible to 1e-10 x scale and its norm is not larger (it is then the exact QP optimum
    for that active set)."""
    t = active_tol * poly.scale
    rows = [poly.A_eq]
    rhs = [poly.b_eq]
    if poly.A_ub.size:
        act = poly.b_ub - poly.A_ub @ x <= t
        rows.append(poly.A_ub[act])
        rhs.append(poly.b_ub[act])
    for bound, sgn in ((poly.lb, 1.0), (poly.ub, -1.0)):
        act = np.isfinite(bound) & (sgn * (x - bound) <= t)
        E = np.eye(poly.n)[act]
        rows.append(E)
        rhs.append(bound[act])
    A, b = np.vstack(rows), np.concatenate(rhs)
    xp = np.linalg.pinv(A, rcond=1e-12) @ b
    eq, viol = poly.residuals(xp)
    ok = eq <= 1e-10 * max(poly.scale, 1.0) and viol <= 1e-10 * poly.scale
    if ok and np.linalg.norm(xp) <= np.linalg.norm(x) * (1 + 1e-9) + 1e-12 * poly.scale:
        return xp
    return None


def random_vertex(poly: Polyhedron, rng: np.random.Generator | int | None = None) -> Particular:
    """A vertex of P minimizing w . R with random weights w ~ U(0, 1) (R >= 0: always bounded)."""
    rng = np.random.default_rng(rng)
    cost = np.zeros(poly.n)
    cost[:poly.c] = rng.uniform(0.0, 1.0, poly.c)
    r = poly.lp(cost)
    if r.status == 2:
        raise EmptyPolyhedron(f"no admissible forces ({poly.description})")
    if r.status != 0:
        raise RuntimeError(f"LP failed: {r.message}")
    return _particular(poly, r.x, "random vertex")


def paper_solution(poly: Polyhedron, method: str = "milp", time_limit: float = 10.0,
                   ranges: Ranges | None = None) -> Particular:
    """The paper's choice (Sec. III C): as many nontransmitting (R = 0) and sliding (S = +-mu R
    at NS contacts) contacts as possible.

    method "milp": maximize #{R = 0} + #{NS contacts with S = +-mu R} exactly (HiGHS), binaries
      b (R = 0), p (S = mu R), m (S = -mu R); big-M constants from the LP ranges of R (valid,
      hence exact, when P is bounded in R; otherwise R <= 1e3 x the force scale is imposed and
      the message says so); the point is then recomputed by an LP on the chosen zero set.
      A time limit returns the best point found ("optimal" is then not claimed).
    method "l1": minimize sum R (one LP): a vertex, with many R = 0 in practice; no guarantee.
    """
    if method == "l1":
        cost = np.zeros(poly.n)
        cost[:poly.c] = 1.0
        r = poly.lp(cost)
        if r.status != 0:
            raise EmptyPolyhedron(f"no admissible forces ({poly.description}): {r.message}")
        return _particular(poly, r.x, "paper (L1 heuristic: min sum R)")
    if method != "milp":
        raise InvalidInput(f"method must be 'milp' or 'l1', got {method!r}")
    c, n = poly.c, poly.n
    ranges = ranges or force_ranges(poly, variables=np.arange(c))
    Rmax = ranges.hi[:c].copy()
    capped = ~np.isfinite(Rmax)
    cap = UNBOUNDED_CAP * poly.scale
    Rmax[capped] = cap
    Rmax = np.maximum(Rmax, 0.0)
    t = 1e-9 * poly.scale
    var_b = np.flatnonzero(Rmax > t)  # R that can be nonzero: a binary each
    ns = np.flatnonzero(poly.ns[:c] & (Rmax > t)) if poly.ns.size else np.zeros(0, dtype=int)
    nb = var_b.size + 2 * ns.size
    N = n + nb
    rows, lo, hi = [], [], []

    def add(r: np.ndarray, a: float, b: float) -> None:
        s = float(np.max(np.abs(r))) or 1.0
        rows.append(r / s)
        lo.append(a / s)
        hi.append(b / s)

    for k in range(poly.A_eq.shape[0]):
        r = np.zeros(N)
        r[:n] = poly.A_eq[k]
        add(r, poly.b_eq[k], poly.b_eq[k])
    for k in range(poly.A_ub.shape[0]):
        r = np.zeros(N)
        r[:n] = poly.A_ub[k]
        add(r, -np.inf, poly.b_ub[k])
    for k, al in enumerate(var_b):  # R <= Rmax (1 - b)
        r = np.zeros(N)
        r[al], r[n + k] = 1.0, Rmax[al]
        add(r, -np.inf, Rmax[al])
    for k, al in enumerate(ns):  # mu R - S <= 2 mu Rmax (1 - p), mu R + S <= 2 mu Rmax (1 - m)
        big = 2.0 * poly.mu[al] * Rmax[al]
        jp, jm = n + var_b.size + 2 * k, n + var_b.size + 2 * k + 1
        for sgn, j in ((-1.0, jp), (1.0, jm)):
            r = np.zeros(N)
            r[al], r[c + al], r[j] = poly.mu[al], sgn, big
            add(r, -np.inf, big)
        r = np.zeros(N)
        r[jp] = r[jm] = 1.0
        add(r, -np.inf, 1.0)
    cost = np.r_[np.zeros(n), -np.ones(nb)]
    lb = np.r_[poly.lb, np.zeros(nb)]
    ub = np.r_[np.where(np.r_[capped, np.zeros(n - c, dtype=bool)], cap, poly.ub), np.ones(nb)]
    integrality = np.r_[np.zeros(n), np.ones(nb)]
    with quiet_highs():
        out = milp(cost, integrality=integrality, bounds=Bounds(lb, ub),
                   constraints=LinearConstraint(sp.csr_matrix(np.array(rows)), lo, hi),
                   options={"time_limit": float(time_limit), "mip_feasibility_tolerance": 1e-9,
                            "primal_feasibility_tolerance": 1e-9})
    if out.x is None:
        if out.status == 2:
            raise EmptyPolyhedron(f"no admissible forces ({poly.description})")
        raise RuntimeError(f"MILP stopped without a point: {out.message}")
    bsel = out.x[n:n + var_b.size] > 0.5
    pm = out.x[n + var_b.size:].reshape(-1, 2) > 0.5 if ns.size else np.zeros((0, 2), bool)
    # Exact point on the chosen zero set: an LP with those equalities.
    extra_rows, extra_rhs = [], []
    for al in var_b[bsel]:
        r = np.zeros(n)
        r[al] = 1.0
        extra_rows.append(r)
        extra_rhs.append(0.0)
    for k, al in enumerate(ns):
        for col, sgn in ((0, -1.0), (1, 1.0)):  # p: S = mu R; m: S = -mu R
            if pm[k, col]:
                r = np.zeros(n)
                r[al], r[c + al] = poly.mu[al], sgn
                extra_rows.append(r)
                extra_rhs.append(0.0)
    exact = Polyhedron(np.vstack([poly.A_eq] + [np.array(extra_rows).reshape(-1, n)]),
                       np.r_[poly.b_eq, extra_rhs], poly.A_ub, poly.b_ub, poly.lb, poly.ub,
                       poly.c, poly.mu, poly.ns, poly.scale, poly.description, poly.system)
    cost = np.zeros(n)
    cost[:c] = 1.0
    r = exact.lp(cost)
    x = r.x if r.status == 0 else out.x[:n]
    msg = "optimal" if out.status == 0 else f"best found ({out.message})"
    if capped.any():
        msg += f"; R unbounded on {int(capped.sum())} contacts: capped at {cap:.3g}"
    return _particular(poly, x, "paper (MILP: most R = 0 and S = +-mu R)", msg)
