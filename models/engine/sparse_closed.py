"""The closed-solution search of the sparse backend (models/engine/closed.py's `search` on the
event LCP assembled from the sparse MLCP, no dense matrix formed).

models.sparse_event's MLCP, A u + C z + a = 0, w = D u + B z + b with A = diag(masses) and
C = -H^T G, eliminates the accelerations without fill: u = M^-1 (H^T G z + f), so

    w = M_lcp z + q,   M_lcp = D M^-1 H^T G + B,   q = D M^-1 f + b,

the dense engine's event LCP (models.event, Eq. 2.7) as a scipy.sparse matrix, and the rows
that must vanish for every contact to stay closed and no disk to translate are w[:c] (a_n)
and the vx, vy rows of u (nu'_x = M^-1 (H^T G z + f)). The search is then the dense engine's,
node for node, with HiGHS on sparse rows (each LP also limited to the search's time left).
On large piles an exhaustive tree cannot end: the search then stops at its limits
("undecided"), never with a guess.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.event import State
from rigidlcp.models.sparse_event import sparse_mlcp
from rigidlcp.models.system import System

from .closed import ClosedProblem, ClosedSearch, search


@dataclass
class SparseClosed:
    """The sparse event LCP of a state (z = [R, tau, a_minus]) with lambda = G z and its
    closed rows (`problem`)."""

    problem: ClosedProblem
    G: sp.csr_matrix
    candidates: np.ndarray


def sparse_closed(system: System, state: State, dyn: Dynamics) -> SparseClosed:
    """The event LCP at `state` in sparse form, with its closed rows (module doc)."""
    ml = sparse_mlcp(system, state, dyn)
    c, p = system.c, system.p
    Minv = sp.diags(dyn.Minv)
    HtG = (-ml.C).tocsr()  # H^T G
    M = (ml.D @ Minv @ HtG + ml.B).tocsr()
    q = ml.D @ (dyn.Minv * dyn.f) + ml.b
    acc = (Minv @ HtG).tocsr()[: 2 * p]  # nu'_x per unit z
    acc0 = dyn.Minv[: 2 * p] * dyn.f[: 2 * p]
    A = sp.vstack([M[:c], acc], format="csr")
    b = np.concatenate([q[:c], acc0])
    G = _forces_map(system, state, ml.candidates)
    return SparseClosed(ClosedProblem(M, q, c, A, b, time_limited=True), G, ml.candidates)


def _forces_map(system: System, state: State, cand: np.ndarray) -> sp.csr_matrix:
    """lambda = G z (models.event: R = z[:c]; S = -s mu R sliding, tau - mu R candidates)."""
    c, mu = system.c, system.mu
    s = np.where(mu == 0, 0, np.asarray(state.s, dtype=int))
    k = cand.size
    idx = np.arange(c)
    slope = np.where((s == 0) & (mu > 0), -mu, -s * mu)
    return sp.csr_matrix((np.concatenate([np.ones(c), slope, np.ones(k)]),
                          (np.concatenate([idx, c + idx, c + cand]),
                           np.concatenate([idx, idx, c + np.arange(k)]))),
                         shape=(2 * c, c + 2 * k))


def states_of(sc: SparseClosed, z: np.ndarray, tang: np.ndarray, c: int
              ) -> tuple[np.ndarray, np.ndarray]:
    """The contact states of a closed solution z, for the next event's warm start (as the
    dense fallback reads them: normal T where R > 0; a candidate -1 where a_minus > 0, NS
    where tau > 0, else +1); `tang` gives the other contacts' states."""
    from rigidlcp.models.sparse_event import NS

    k = sc.candidates.size
    tau, a_minus = z[c:c + k], z[c + k:]
    tang = np.array(tang, copy=True)
    tang[sc.candidates] = np.where(a_minus > 0, -1, np.where(tau > 0, NS, 1))
    return z[:c] > 0, tang


def closed_event(system: System, state: State, dyn: Dynamics, scale: float, tol: float
                 ) -> tuple[ClosedSearch, SparseClosed]:
    """Search the event at `state` (module doc): the verdict (its z: the closed solution of
    least sum R, when found) and the problem searched."""
    sc = sparse_closed(system, state, dyn)
    return search(sc.problem, scale, tol), sc
