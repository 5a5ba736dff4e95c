"""Contact states and their active system (the paper's Sec. II C): K(states) of a
friction-contact problem a = W lambda + q (lambda = [R; S], block layout [normal; tangent])
and the sparse LU of a base system, which lcp.solvers.state_factor updates row by row.

The solver works on *contact states*, the paper's own unknowns (Sec. II C, Eq. 2.15): per
contact a normal state, T (a_n = 0, R free) or NT (R = 0), and a tangential one: a sliding
contact keeps S + s mu R = 0 (s = sgn v_t; S = 0 when mu = 0), a non-sliding candidate is NS
(a_t = 0), "+" (S = -mu R, a_t >= 0) or "-" (S = +mu R, a_t <= 0). For a vector of states the
2c x 2c active system K lambda = r takes row alpha of W (with r = -q_alpha) where a state sets
an acceleration to zero, and a unit or friction-cone row (r = 0) where it sets a force:

    T: W_n,alpha lambda = -q_n,alpha     NT: R_alpha = 0
    NS: W_t,alpha lambda = -q_t,alpha    +/-/sliding: S_alpha + s mu R_alpha = 0.

These are exactly the complementary bases of the event LCP: with tau = mu R + S, NS is
{tau basic, a_minus not}, "+" {neither}, "-" {both}; the fourth combination (a_minus basic,
tau not) forces R = S = 0 and every solution it admits is also admitted by NT with "+" or "-",
so it is never needed. The inequalities to check are those of lcp.pivoting in these terms:

    T: R >= 0;   NT: a_n >= 0;   NS: |S| <= mu R;   "+": a_t >= 0;   "-": a_t <= 0,

and a state that violates its inequality is flipped (T <-> NT; NS -> "+" when S < -mu R,
NS -> "-" when S > mu R; "+"/"-" -> NS). The iteration is lcp.pivoting's: block principal
pivoting (all violations at once) while the number of violations drops (Judice & Pires),
otherwise single flips on the least violating index (Murty), the next violating indices when a
flip makes K singular, a cycle test and an iteration limit.

This module holds the active system (`ActiveSystem`) and the sparse LU of a base system
(`ReducedLU`, `_FullLU`, `factorize`); lcp.solvers.state_factor updates it row by row between
pivots (`StateFactor`, its module doc: the factorizations) and re-exports these names. Split
from state_factor.py by job (session 8).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

#: Tangential state codes: +1 / -1 (S + code mu R = 0; sliding, or a candidate's "+"/"-"),
#: 0 (S = 0: frictionless) and NS (a_t = 0, candidates only).
NS = 2
#: SuperLU's column ordering: minimum degree on K + K' suits K, whose pattern is nearly
#: symmetric (W's); SuperLU's default COLAMD fills ~10x more at 100 x 100 disks.
PERMC = "MMD_AT_PLUS_A"
#: SuperLU options: prefer the diagonal pivot (threshold 0.01) and keep the symmetric
#: ordering; about 30% less fill and time than partial pivoting here. The pivot-ratio test,
#: the capacitance condition test and the iterative refinement guard the accuracy.
SPLU_OPTIONS = {"DiagPivotThresh": 0.01, "SymmetricMode": True}


def factorize(K: sp.spmatrix):
    """SuperLU factorization of an active system with the solver's ordering and options."""
    return splu(K.tocsc(), permc_spec=PERMC, options=dict(SPLU_OPTIONS))


# --------------------------------------------------------------------------------------------
# the active system of a vector of states, and the LU of a base system
# --------------------------------------------------------------------------------------------

class ActiveSystem:
    """K(states) and its right-hand side, from the constant W, q and mu (see the module doc)."""

    def __init__(self, W: sp.csr_matrix, q: np.ndarray, mu: np.ndarray):
        self.W, self.q, self.mu = W, q, mu
        self.c = mu.size
        self.N = 2 * self.c

    @cached_property
    def absW(self) -> sp.csr_matrix:
        return abs(self.W).tocsr()

    @cached_property
    def wnorm(self) -> float:
        """max row sum of |W| (and 1 + mu for the fixed rows)."""
        return max(float(np.max(self.absW @ np.ones(self.N), initial=0.0)),
                   1.0 + float(self.mu.max(initial=0.0)))

    @cached_property
    def adjacency(self) -> sp.csr_matrix:
        """The contact graph: alpha ~ beta when W couples any of their components (they share
        a disk)."""
        c, W = self.c, abs(self.W)
        P = W[:c, :c] + W[:c, c:] + W[c:, :c] + W[c:, c:]
        return (P != 0).astype(np.int8).tocsr()

    def row(self, i: int, normal: np.ndarray, tang: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Row i of K as (column indices, values)."""
        c = self.c
        if (i < c and normal[i]) or (i >= c and tang[i - c] == NS):
            lo, hi = self.W.indptr[i], self.W.indptr[i + 1]
            return self.W.indices[lo:hi], self.W.data[lo:hi]
        if i < c:
            return np.array([i]), np.array([1.0])
        a = i - c
        code = int(tang[a])
        if code == 0 or self.mu[a] == 0:
            return np.array([i]), np.array([1.0])
        return np.array([a, i]), np.array([code * self.mu[a], 1.0])

    def matrix(self, normal: np.ndarray, tang: np.ndarray) -> sp.csr_matrix:
        """K as a sparse matrix."""
        c = self.c
        useW = np.concatenate([normal, tang == NS])
        Wpart = sp.diags(useW.astype(float)) @ self.W
        idx = np.arange(c)
        fixed_t = tang != NS
        code = np.where(fixed_t, tang, 0).astype(float)
        rows = np.concatenate([idx[~normal], c + idx[fixed_t], c + idx[fixed_t & (code != 0)]])
        cols = np.concatenate([idx[~normal], c + idx[fixed_t], idx[fixed_t & (code != 0)]])
        vals = np.concatenate([np.ones((~normal).sum()), np.ones(fixed_t.sum()),
                               (code * self.mu)[fixed_t & (code != 0)]])
        F = sp.csr_matrix((vals, (rows, cols)), shape=(self.N, self.N))
        return (Wpart + F).tocsr()

    def rhs(self, normal: np.ndarray, tang: np.ndarray) -> np.ndarray:
        useW = np.concatenate([normal, tang == NS])
        return np.where(useW, -self.q, 0.0)

    def apply(self, lam: np.ndarray, normal: np.ndarray, tang: np.ndarray) -> np.ndarray:
        """K lambda, computed from W lambda and the fixed rows."""
        c = self.c
        Wl = self.W @ lam
        out = lam.copy()
        fixed = tang != NS
        code = np.where(fixed, tang, 0)
        out[c:] = np.where(fixed, lam[c:] + code * self.mu * lam[:c], Wl[c:])
        out[:c] = np.where(normal, Wl[:c], lam[:c])
        return out


class ReducedLU:
    """K(states)^-1 by eliminating the rows that fix a force (NT: R = b; fixed tangent:
    S + code mu R = b, pivots 1) and factoring only the rows of W that the states keep (T
    normals, NS tangents) in their own unknowns (R of T, S of NS): with lambda = P x + Q b,
    (W_A P) x = b_A - W_A Q b. Exact block elimination; the reduced matrix has about half the
    rows of K and SuperLU fills it about half as much (100 x 100 disks: 1.2 against 1.9
    million entries). The reduced matrix is equilibrated symmetrically by its diagonal before
    SuperLU sees it. `solve` takes one or several right-hand sides; `pivots` are |U_ii| of
    the equilibrated reduced LU and the unit pivots of the eliminated rows. Raises RuntimeError
    when SuperLU finds the reduced matrix exactly singular."""

    def __init__(self, system: ActiveSystem, normal: np.ndarray, tang: np.ndarray):
        c, N, mu = system.c, system.N, system.mu
        idx = np.arange(c)
        A = np.flatnonzero(np.concatenate([normal, tang == NS]))
        pos = np.full(N, -1)
        pos[A] = np.arange(A.size)
        fixed = tang != NS
        cmu = np.where(fixed, tang, 0) * mu  # S + cmu R = b on the fixed tangential rows
        tie = fixed & (cmu != 0)
        m_T, m_N = tie & normal, tie & ~normal
        self.P = sp.csr_matrix((np.concatenate([np.ones(A.size), -cmu[m_T]]),
                                (np.concatenate([A, c + idx[m_T]]),
                                 np.concatenate([np.arange(A.size), pos[idx[m_T]]]))),
                               shape=(N, A.size))
        self.Q = sp.csr_matrix((np.concatenate([np.ones((~normal).sum() + fixed.sum()),
                                                -cmu[m_N]]),
                                (np.concatenate([idx[~normal], c + idx[fixed], c + idx[m_N]]),
                                 np.concatenate([idx[~normal], c + idx[fixed], idx[m_N]]))),
                               shape=(N, N))
        WA = system.W[A]
        self.WQ = (WA @ self.Q).tocsr()
        self.A = A
        Kr = (WA @ self.P).tocsr()
        # symmetric equilibration r_i = |Kr_ii|^-1/2 (Kr_ii > 0: W's diagonal), so that the
        # pivot and condition tests below do not depend on the units of the contacts
        diag = np.abs(Kr.diagonal())
        rowmax = np.asarray(abs(Kr).max(axis=1).todense()).ravel() if A.size else diag
        self.r = 1.0 / np.sqrt(np.where(diag > 0, diag, np.where(rowmax > 0, rowmax, 1.0)))
        Ks = sp.diags(self.r) @ Kr @ sp.diags(self.r)
        self.lu = factorize(Ks) if A.size else None
        d = np.abs(self.lu.U.diagonal()) if A.size else np.zeros(0)
        self.pivots = np.concatenate([d, np.ones(N - A.size)])
        #: |Ks^-1 b| |Ks| / |b| (infinity norms, a fixed b: the same test on every run) <=
        #: cond(Ks), Ks the equilibrated reduced matrix: a singular K shows here even when
        #: rounding leaves its smallest pivot above state_factor.PIVOT_RATIO (the reduced LU's
        #: pivots can be: 1e-13 .. 5e-13 on singular systems where the whole K's were 1e-15).
        self.cond_bound = 0.0
        if A.size:
            b = np.random.default_rng(0).normal(size=A.size)
            norm = float(np.max(abs(Ks) @ np.ones(A.size)))
            self.cond_bound = float(np.abs(self.lu.solve(b)).max()) * norm / np.abs(b).max()

    def solve(self, b: np.ndarray) -> np.ndarray:
        """K^-1 b (b: a vector or the columns of a matrix)."""
        if self.lu is None:
            return self.Q @ b
        y = np.asarray(b[self.A] - self.WQ @ b, dtype=float)
        r = self.r if y.ndim == 1 else self.r[:, None]
        return self.P @ (r * self.lu.solve(r * y)) + self.Q @ b


class _FullLU:
    """SuperLU of all of K (REDUCED = False: the factorization before issue 13)."""

    def __init__(self, K: sp.spmatrix):
        self.lu = factorize(K)
        self.pivots = np.abs(self.lu.U.diagonal())
        self.cond_bound = 0.0  # not tested (as before issue 13)

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self.lu.solve(b)
