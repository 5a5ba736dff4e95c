"""The 2D friction-contact problem (Siconos's fc2d layout) and its natural-map residual.

FrictionContact2D(W, q, mu): c contacts, unknowns r (forces) and u = W r + q (relative
velocities or accelerations), both of length 2c in Siconos's per-contact layout
[r_n0, r_t0, r_n1, r_t1, ...] (normal, then tangent, of contact alpha at 2 alpha, 2 alpha + 1).
Per contact, with the Coulomb cone K_alpha = {r : |r_t| <= mu_alpha r_n} and De Saxce's
modified velocity uhat = (u_n + mu |u_t|, u_t):

    K_alpha  contains  r_alpha   perp   uhat_alpha  in  K_alpha^*,

which is exactly Signorini (0 <= r_n perp u_n >= 0) with Coulomb's law (the paper's Eq. 2.5,
2.6): |r_t| <= mu r_n, and u_t != 0 => r_t = -mu r_n sgn(u_t).

Natural map (Siconos's fc3d unitary error, in 2D): F_alpha = r_alpha - P_K(r_alpha - uhat_alpha);
zero at every contact iff (r, u) solves the problem. `natural_residual` gives ||F||_2 / max(1,
||q||_2)... see its docstring for the exact scaling.

The Glocker LCP (`to_lcp`): z = [R (c), tau (c), a_minus (c)], tau = mu R + r_t,

    w = [u_n,  u_t + a_minus,  2 mu R - tau],   0 <= z perp w >= 0,

(models.event's layout with every contact a non-sliding candidate): its solutions are the
problem's, r_t = tau - mu R.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .problem import LCP, InvalidProblem, as_vector


@dataclass(frozen=True, eq=False)
class FrictionContact2D:
    """u = W r + q, Coulomb friction with per-contact mu (see the module doc).

    W: the Delassus operator, 2c x 2c, dense or scipy.sparse, Siconos's (normal, tangent)
    layout per contact; q: length 2c; mu: length c (or a scalar), mu >= 0.
    """

    W: np.ndarray | sp.spmatrix
    q: np.ndarray
    mu: np.ndarray
    name: str = ""
    meta: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        W = self.W
        if sp.issparse(W):
            W = sp.csr_matrix(W, dtype=float)
            if W.shape[0] != W.shape[1]:
                raise InvalidProblem(f"W must be square, got shape {W.shape}")
            if not np.all(np.isfinite(W.data)):
                raise InvalidProblem("W contains NaN or Inf")
        else:
            from .problem import as_matrix

            W = as_matrix("W", W, (None, None))
            if W.shape[0] != W.shape[1]:
                raise InvalidProblem(f"W must be square, got shape {W.shape}")
        if W.shape[0] % 2:
            raise InvalidProblem(f"W must be 2c x 2c (normal and tangent per contact), got "
                                 f"{W.shape[0]} rows")
        c = W.shape[0] // 2
        q = as_vector("q", self.q, 2 * c)
        mu = np.asarray(self.mu, dtype=float)
        mu = np.full(c, float(mu)) if mu.ndim == 0 else as_vector("mu", mu, c)
        if np.any(mu < 0) or not np.all(np.isfinite(mu)):
            raise InvalidProblem(f"mu must be finite and >= 0; contact {int(np.argmin(mu))} "
                                 f"has mu = {mu.min()}")
        object.__setattr__(self, "W", W)
        object.__setattr__(self, "q", q)
        object.__setattr__(self, "mu", mu)

    @property
    def c(self) -> int:
        """Number of contacts."""
        return self.mu.size

    @property
    def n(self) -> int:
        """Number of unknowns (2c)."""
        return 2 * self.c

    def u(self, r: np.ndarray) -> np.ndarray:
        return self.W @ r + self.q

    def dense_W(self) -> np.ndarray:
        return self.W.toarray() if sp.issparse(self.W) else self.W

    def blocks(self) -> tuple[sp.csr_matrix, np.ndarray]:
        """W and q permuted to the block layout [normal (c); tangent (c)] (models' layout)."""
        p = np.concatenate([np.arange(0, self.n, 2), np.arange(1, self.n, 2)])
        Wb = sp.csr_matrix(self.W)[p][:, p].tocsr()
        return Wb, self.q[p]

    # -- the Glocker LCP --------------------------------------------------------------------
    def to_lcp(self) -> LCP:
        """The Glocker LCP of the module doc (dense M, 3c x 3c)."""
        c, mu = self.c, self.mu
        W = self.dense_W()
        Wn, Wt = W[0::2], W[1::2]          # rows: normal / tangent
        Wnn, Wnt, Wtn, Wtt = Wn[:, 0::2], Wn[:, 1::2], Wt[:, 0::2], Wt[:, 1::2]
        I, Z = np.eye(c), np.zeros((c, c))
        M = np.block([
            [Wnn - Wnt * mu, Wnt, Z],
            [Wtn - Wtt * mu, Wtt, I],
            [2 * np.diag(mu), -I, Z],
        ])
        qz = np.concatenate([self.q[0::2], self.q[1::2], np.zeros(c)])
        return LCP(M, qz, name=self.name, meta={**self.meta, "reduced_from": "FC2D"})

    def r_from_lcp(self, z: np.ndarray) -> np.ndarray:
        """The forces r (Siconos's layout) of a Glocker LCP vector z."""
        c = self.c
        R, tau = z[:c], z[c:2 * c]
        r = np.empty(2 * c)
        r[0::2], r[1::2] = R, tau - self.mu * R
        return r

    def lcp_from_r(self, r: np.ndarray) -> np.ndarray:
        """A Glocker LCP vector z for the forces r (a_minus = max(-u_t, 0))."""
        u = self.u(r)
        R, S = r[0::2], r[1::2]
        return np.concatenate([R, self.mu * R + S, np.maximum(-u[1::2], 0.0)])

    def __repr__(self) -> str:
        label = f" {self.name!r}" if self.name else ""
        kind = "sparse" if sp.issparse(self.W) else "dense"
        return f"<FrictionContact2D{label} contacts={self.c} ({kind} W)>"


def project_cone(x: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """Projection onto the product of 2D Coulomb cones {|x_t| <= mu x_n} (Siconos layout)."""
    xn, xt = x[0::2], x[1::2]
    out = np.zeros_like(x)
    inside = np.abs(xt) <= mu * xn
    polar = xn <= -mu * np.abs(xt)
    edge = ~inside & ~polar
    t = (xn + mu * np.abs(xt)) / (1.0 + mu * mu)
    out[0::2] = np.where(inside, xn, np.where(edge, t, 0.0))
    out[1::2] = np.where(inside, xt, np.where(edge, np.sign(xt) * mu * t, 0.0))
    return out


def natural_map(problem: FrictionContact2D, r: np.ndarray, u: np.ndarray | None = None
                ) -> np.ndarray:
    """F = r - P_K(r - uhat), uhat = (u_n + mu |u_t|, u_t), Siconos's layout (rho = 1)."""
    u = problem.u(r) if u is None else u
    uhat = u.copy()
    uhat[0::2] += problem.mu * np.abs(u[1::2])
    return r - project_cone(r - uhat, problem.mu)


def natural_residual(problem: FrictionContact2D, r: np.ndarray, u: np.ndarray | None = None
                     ) -> float:
    """Relative natural-map residual ||F||_2 / ||q||_2 (||F||_2 when ||q||_2 is below 1e-300),
    Siconos's normalization of its friction-contact error."""
    F = natural_map(problem, r, u)
    nq = float(np.linalg.norm(problem.q))
    return float(np.linalg.norm(F)) / (nq if nq > 1e-300 else 1.0)


def per_contact_residual(problem: FrictionContact2D, r: np.ndarray) -> np.ndarray:
    """|F_alpha|_2 per contact (where the natural map fails)."""
    F = natural_map(problem, r)
    return np.hypot(F[0::2], F[1::2])
