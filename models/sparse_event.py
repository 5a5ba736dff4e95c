"""The event problem in sparse form, solved by warm-started pivoting on contact states (issue 6).

The event MLCP (models.event) in Siconos's layout, with scipy.sparse matrices:

    A u + C z + a = 0,   w = D u + B z + b,   0 <= z perp w >= 0,
    A = M (diagonal masses), C = -H' G, a = -f, D = [H_n; P H_t; 0], b = [u_obs'_n; P u_obs'_t; 0],

with z = [R (c), tau (k), a_minus (k)] (`sparse_mlcp`; its dense copy equals event_problem's
MLCP). Because A is diagonal, u = A^-1 (H' G z + f) eliminates the accelerations *without
fill*: every relative acceleration is a = W lambda + q with the sparse Delassus operator
W = H M^-1 H' (about 17 entries per row for a rectangular array) and lambda = [R; S].

The contact-state solver (the active system K(states), its sparse LU with row updates, the
constants) lives in rigidlcp.lcp.solvers.state_factor and is re-exported here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rigidlcp.lcp.solvers.state_factor import (  # noqa: F401  (re-exported: models' own names)
    NS,
    PERMC,
    PIVOT_RATIO,
    RCOND,
    REFACTOR_SOLVES,
    SPLU_OPTIONS,
    ActiveSystem,
    SingularSystem,
    StateFactor,
    factorize,
)

from .dynamics import Dynamics
from .event import State
from .system import System


def sparse_delassus(dyn: Dynamics) -> sp.csr_matrix:
    """W = H M^-1 H' as a sparse matrix (rows: [a_n; a_t], columns: [R; S])."""
    H = dyn.H.tocsr()
    return (H @ sp.diags(dyn.Minv) @ H.T).tocsr()


@dataclass
class SparseMLCP:
    """The event MLCP with sparse A, C, D, B (see the module doc); z = [R, tau, a_minus]."""

    A: sp.spmatrix
    C: sp.spmatrix
    D: sp.spmatrix
    B: sp.spmatrix
    a: np.ndarray
    b: np.ndarray
    candidates: np.ndarray

    def to_dense(self):
        """The same problem as an lcp.MLCP (small systems only)."""
        from rigidlcp.lcp import MLCP

        return MLCP(*(m.toarray() for m in (self.A, self.C, self.D, self.B)), self.a, self.b)


def sparse_mlcp(system: System, state: State, dyn: Dynamics | None = None) -> SparseMLCP:
    """The MLCP of the event at `state` with scipy.sparse matrices (models.event's layout)."""
    dyn = dyn or Dynamics(system)
    c, p, mu = system.c, system.p, system.mu
    s = np.where(mu == 0, 0, np.asarray(state.s, dtype=int))
    cand = np.flatnonzero((s == 0) & (mu > 0))
    k = cand.size
    n = c + 2 * k
    idx, kk = np.arange(c), np.arange(k)
    slope = np.where((s == 0) & (mu > 0), -mu, -s * mu)
    G = sp.csr_matrix((np.concatenate([np.ones(c), slope, np.ones(k)]),
                       (np.concatenate([idx, c + idx, c + cand]),
                        np.concatenate([idx, idx, c + kk]))), shape=(2 * c, n))
    H = dyn.H.tocsr()
    P = sp.csr_matrix((np.ones(k), (kk, cand)), shape=(k, c))
    D = sp.vstack([H[:c], P @ H[c:], sp.csr_matrix((k, 3 * p))]).tocsr()
    B = sp.csr_matrix((np.concatenate([np.ones(k), 2.0 * mu[cand], -np.ones(k)]),
                       (np.concatenate([c + kk, c + k + kk, c + k + kk]),
                        np.concatenate([c + k + kk, cand, c + kk]))), shape=(n, n))
    b = np.concatenate([dyn.u_obs_dot[:c], dyn.u_obs_dot[c:][cand], np.zeros(k)])
    return SparseMLCP(sp.diags(1.0 / dyn.Minv).tocsr(), (-(H.T @ G)).tocsr(), D, B, -dyn.f,
                      b, cand)

