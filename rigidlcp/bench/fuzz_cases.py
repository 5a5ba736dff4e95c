"""Generated LCP classes for the fuzz harness (rigidlcp.bench.fuzz), each with what is known
about it *by construction*: a P-matrix (exactly one solution), a planted solution (solvable),
or a Farkas vector (infeasible). The judge uses these facts, never a solver's word.

Classes (n from 2 to 60, drawn log-uniformly):

P            M = S + K, S symmetric positive definite, K skew: (M + M^T)/2 = S > 0, so M is P.
ill-P        the same with eigenvalues of S spread over 1 .. 1e-6 to 1e-16.5 (cond(M) up to ~3e16);
             counted as P (judged as such) only when lambda_min((M + M^T)/2), computed, exceeds
             100 n eps lambda_max: beyond that the float matrix need not be P.
PSD          M = B B^T + K (rank n/2 or more), q from a planted solution (solvable).
singular-PSD M = B B^T, B of rank ~n/3, planted solution (a continuum of solutions is typical).
copositive+  M = S + N + K, S PSD of low rank, N > 0 entrywise: strictly copositive, solvable.
degenerate   P-matrix with a planted solution where z_i = w_i = 0 at ~1/3 of the indices.
Z            M = s I - N, N >= 0: a Z-matrix; P (an M-matrix) when s > rho(N), else not.
nonnegative  M >= 0 entrywise with positive diagonal (strictly copositive: solvable).
integer-tie  integer M (-3..3, diagonal 1..3) and q (-3..3): many exact ties; solvability open.
scaled       a P-class problem with rows and columns scaled by 10^U(-8, 8) (same problem, other
             units): still a P-matrix.
infeasible   M = P (S + K) P - eps y 1^T / y^T y, P the projector orthogonal to y >= 0, and
             q^T y < 0 (robust_infeasible): M^T y = -eps 1, so {z >= 0, M z + q >= 0} is empty,
             robustly (y is the Farkas vector).
event        the LCP of an event of a small lattice (models.event_problem) with mixed friction
             (sliding and non-sliding contacts); solvability open.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

CLASSES = ("P", "ill-P", "PSD", "singular-PSD", "copositive+", "degenerate", "Z",
           "nonnegative", "integer-tie", "scaled", "infeasible", "event")


@dataclass
class Case:
    """One generated LCP and the facts known about it by construction."""

    kind: str
    seed: int
    M: np.ndarray
    q: np.ndarray
    p_matrix: bool = False
    solvable: bool | None = None  # True: planted / P / copositive; False: infeasible
    planted: np.ndarray | None = None
    farkas: np.ndarray | None = None
    meta: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        return self.q.size


def draw_n(rng: np.random.Generator, lo: int = 2, hi: int = 60) -> int:
    return int(round(np.exp(rng.uniform(np.log(lo), np.log(hi + 0.49)))))


def _spd(rng, n: int, spread: float = 0.0) -> np.ndarray:
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    lam = np.logspace(0, -spread, n) if spread else rng.uniform(0.1, 2.0, n)
    return (Q * lam) @ Q.T


def _skew(rng, n: int, size: float = 1.0) -> np.ndarray:
    K = rng.standard_normal((n, n)) * size
    return K - K.T


def _planted(rng, M: np.ndarray, degenerate: float = 0.0):
    """q = w* - M z* for a complementary (z*, w*): the LCP then has z* as a solution."""
    n = M.shape[0]
    pos = rng.random(n) < 0.5
    z = np.where(pos, rng.uniform(0.1, 2.0, n), 0.0)
    w = np.where(pos, 0.0, rng.uniform(0.1, 2.0, n))
    if degenerate:
        both = rng.random(n) < degenerate
        z[both] = w[both] = 0.0
    return w - M @ z, z


def make_case(kind: str, seed: int) -> Case:
    """The case of class `kind` drawn with `seed` (reproducible)."""
    rng = np.random.default_rng([seed, CLASSES.index(kind)])
    n = draw_n(rng)
    if kind == "P":
        M = _spd(rng, n) + _skew(rng, n, rng.uniform(0, 1))
        return Case(kind, seed, M, rng.standard_normal(n), p_matrix=True, solvable=True)
    if kind == "ill-P":
        M = _spd(rng, n, spread=rng.uniform(6, 16.5)) + _skew(rng, n, 1e-3 * rng.random())
        # In floating point M is P for sure only if lambda_min((M + M^T)/2) clears rounding.
        lam = np.linalg.eigvalsh(0.5 * (M + M.T))
        sure = bool(lam[0] > 100 * n * np.finfo(float).eps * abs(lam[-1]))
        return Case(kind, seed, M, rng.standard_normal(n), p_matrix=sure,
                    solvable=True if sure else None, meta={"lambda_min": float(lam[0])})
    if kind in ("PSD", "singular-PSD"):
        k = max(1, n // 2 if kind == "PSD" else n // 3)
        B = rng.standard_normal((n, k if kind == "singular-PSD" else n))
        M = B @ B.T + (_skew(rng, n, 0.5) if kind == "PSD" else 0.0)
        q, z = _planted(rng, M)
        return Case(kind, seed, M, q, solvable=True, planted=z)
    if kind == "copositive+":
        B = rng.standard_normal((n, max(1, n // 4)))
        M = B @ B.T + rng.uniform(0.01, 1.0, (n, n)) + _skew(rng, n, 0.3)
        return Case(kind, seed, M, rng.standard_normal(n), solvable=True)
    if kind == "degenerate":
        M = _spd(rng, n) + _skew(rng, n, rng.uniform(0, 1))
        q, z = _planted(rng, M, degenerate=0.35)
        return Case(kind, seed, M, q, p_matrix=True, solvable=True, planted=z)
    if kind == "Z":
        N = np.where(rng.random((n, n)) < 0.4, rng.random((n, n)), 0.0)
        np.fill_diagonal(N, 0.0)
        rho = float(np.max(np.abs(np.linalg.eigvals(N))))
        s = rho * rng.uniform(0.7, 1.5) + 1e-3
        M = s * np.eye(n) - N
        is_p = s > rho * (1 + 1e-9)
        return Case(kind, seed, M, rng.standard_normal(n), p_matrix=is_p,
                    solvable=True if is_p else None, meta={"s_over_rho": s / max(rho, 1e-300)})
    if kind == "nonnegative":
        M = rng.random((n, n)) * (rng.random((n, n)) < 0.5)
        M[np.diag_indices(n)] = rng.uniform(0.1, 1.0, n)
        return Case(kind, seed, M, rng.standard_normal(n), solvable=True)
    if kind == "integer-tie":
        M = rng.integers(-3, 4, (n, n)).astype(float)
        M[np.diag_indices(n)] = rng.integers(1, 4, n)
        return Case(kind, seed, M, rng.integers(-3, 4, n).astype(float))
    if kind == "scaled":
        base = make_case("P", seed)
        r, c = 10.0 ** rng.uniform(-8, 8, base.n), 10.0 ** rng.uniform(-8, 8, base.n)
        return Case(kind, seed, r[:, None] * base.M * c[None, :], r * base.q, p_matrix=True,
                    solvable=True, meta={"r": r, "c": c})
    if kind == "infeasible":
        M, q, y = robust_infeasible(rng, n)
        return Case(kind, seed, M, q, solvable=False, farkas=y)
    if kind == "event":
        return _event_case(rng, seed)
    raise ValueError(f"unknown class {kind!r}; classes: {', '.join(CLASSES)}")


def robust_infeasible(rng: np.random.Generator, n: int):
    """(M, q, y): M = P (S + K) P - eps y 1^T / (y^T y) (P the projector orthogonal to y >= 0),
    so M^T y = -eps 1 with eps in [0.01, 0.1], and q^T y < 0: y proves {z >= 0 : M z + q >= 0}
    empty, and so it does for every problem within relative distance ~eps / |M| (a *robust*
    infeasibility). With eps = 0 (M^T y = 0 only up to rounding) the float problem has
    neighbours at relative distance ~1e-16 with solutions of size ~1/eps_machine, which the
    acceptance test (a relative backward error of 1e-8) rightly cannot tell from solutions."""
    y = np.where(rng.random(n) < 0.6, rng.random(n), 0.0)
    y[rng.integers(n)] = 1.0
    P = np.eye(n) - np.outer(y, y) / (y @ y)
    eps = rng.uniform(0.01, 0.1)
    M = P @ (_spd(rng, n) + _skew(rng, n)) @ P - eps * np.outer(y, np.ones(n)) / (y @ y)
    q = rng.standard_normal(n)
    q -= (q @ y + rng.uniform(0.1, 2.0)) * y / (y @ y)
    return M, q, y


def _event_case(rng: np.random.Generator, seed: int) -> Case:
    from rigidlcp import models

    kind = str(rng.choice(["rect", "tri"]))
    ly = int(rng.integers(1, 4))
    lx = int(rng.integers(2 if kind == "tri" and ly >= 2 else 1, 5))
    lat = models.make_lattice(kind, lx, ly)
    mu = [float(rng.choice([0.0, 0.1, 0.2, 0.3, 0.5])) for _ in range(3)]
    system = models.System(lat, mu_pp=mu[0], mu_plane=mu[1], mu_wall=mu[2],
                           gamma=float(rng.uniform(-0.5, 0.5)), V0=float(rng.uniform(-1, 1)))
    omega = rng.uniform(-1, 1, system.p)
    stick = rng.random(system.c) < rng.random()
    s = np.where(stick | (system.mu == 0), 0, rng.choice([1, -1], system.c))
    ep = models.event_problem(system, models.State(0.0, omega, float(system.V0), s))
    P = ep.lcp
    return Case("event", seed, np.array(P.M), np.array(P.q),
                meta={"lattice": f"{kind} {lx}x{ly}", "mu": mu})
