"""Contact-state linear algebra (the paper's Sec. II C): the active system K(states) of a
friction-contact problem a = W lambda + q (lambda = [R; S], block layout [normal; tangent])
and its sparse LU with row updates. Used by lcp.state_pivoting (method ``states``) and by the
disk arrays' sparse event engine (models.sparse_event, models.engine).

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

Factorizations. Between two events the geometry does not change, so W and q never change:
only the states do, and a state change replaces *one row* of K. One sparse LU (SuperLU,
scipy.sparse.linalg.splu) of a base system K0 therefore serves many pivots and many events:
K = K0 + E Delta (E: the replaced rows' unit columns, Delta: new rows minus old rows) is
solved by the Schur-complement (capacitance) method,

    K^-1 r = y - Y C^-1 (Delta y),   y = K0^-1 r,   Y = K0^-1 E,   C = I + Delta Y,

where each column of Y costs one solve with the LU (cached per row) and C is a small dense
matrix. K0 itself is not factored whole: its rows that fix a force (NT, and the tangential rows
of sliding, "+" and "-" states) have unit pivots and are eliminated exactly, and SuperLU
factors the rows of W the states keep in their own unknowns (`ReducedLU`: at 100 x 100 disks
20000 rows instead of 40200, about half the time). K is singular exactly when C is (checked by
LAPACK's condition estimate); a base is refactored when the rows replaced since its
factorization exceed `max_updates`, or when more than `refactor_solves` columns of Y have been
solved for since (a count, not a clock, so that a solve is deterministic: same pivots, same
answer on every run; the default is the measured cost of one factorization in column solves on
the 2020-contact Siconos problem, about 23); a change of more rows than that budget allows is a
fresh factorization. A solve is followed by one step of iterative refinement against K itself.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.sparse as sp
from scipy.linalg import LinAlgWarning, lu_factor, lu_solve
from scipy.linalg.lapack import dgecon
from scipy.sparse.linalg import splu

from ..errors import RigidLCPError

#: Tangential state codes: +1 / -1 (S + code mu R = 0; sliding, or a candidate's "+"/"-"),
#: 0 (S = 0: frictionless) and NS (a_t = 0, candidates only).
NS = 2
#: C (and a refactored base) counts as singular below this reciprocal condition estimate.
RCOND = 1e-12
#: A fresh LU whose pivots span more than 1 / PIVOT_RATIO is treated as singular.
PIVOT_RATIO = 1e-13
#: Refactor after this many column solves with the base LU (see the module doc).
REFACTOR_SOLVES = 24
#: Factor the reduced system of the rows of W the states keep (`ReducedLU`), not all of K.
REDUCED = True
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
# the active system of a vector of states, and its factorization with row updates
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
        #: rounding leaves its smallest pivot above PIVOT_RATIO (the reduced LU's pivots can be:
        #: 1e-13 .. 5e-13 on singular systems where the whole K's were 1e-15).
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


class SingularSystem(RigidLCPError):
    """The active system of a vector of states is singular (to the stated tolerance)."""


@dataclass
class _Update:
    """Rows replaced since the base factorization (in slot order, aligned with the columns of
    StateFactor.Y), their Delta rows (new row - base row) and C = I + Delta Y, factored."""

    rows: list[int] = field(default_factory=list)
    slots: dict[int, int] = field(default_factory=dict)  # row -> slot
    delta: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)
    C: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    lu: tuple | None = None
    D: sp.csr_matrix | None = None  # the Delta rows as one sparse matrix


class StateFactor:
    """K(states) of the current states: a sparse LU of a base K0 and row replacements by the
    capacitance method (see the module doc). `normal`, `tang` are the current states."""

    def __init__(self, system: ActiveSystem, normal: np.ndarray, tang: np.ndarray,
                 max_updates: int = 400, refactor_solves: int = REFACTOR_SOLVES):
        self.sys = system
        self.max_updates = max_updates
        self.refactor_solves = refactor_solves
        self.stats = {"factorizations": 0, "factor_seconds": 0.0, "update_solves": 0,
                      "update_seconds": 0.0}
        self.refactor(normal, tang)

    # -- the base ---------------------------------------------------------------------------
    def refactor(self, normal: np.ndarray, tang: np.ndarray) -> None:
        """Factor K(states) as the new base; raises SingularSystem (keeping the old one)."""
        K = self.sys.matrix(normal, tang)
        t0 = time.perf_counter()
        try:
            lu = ReducedLU(self.sys, normal, tang) if REDUCED else _FullLU(K)
        except RuntimeError as exc:  # "Factor is exactly singular"
            raise SingularSystem(str(exc)) from None
        elapsed = time.perf_counter() - t0
        d = lu.pivots
        self.stats["factorizations"] += 1
        self.stats["factor_seconds"] += elapsed
        if d.min() <= PIVOT_RATIO * d.max():
            raise SingularSystem(f"pivot ratio {d.min() / d.max():.2e}")
        if lu.cond_bound * PIVOT_RATIO > 1.0:
            raise SingularSystem(f"condition number >= {lu.cond_bound:.2e}")
        self.K0, self.lu = K, lu
        self.last_factor_seconds = elapsed
        self.Y = np.zeros((self.sys.N, 32))
        self.spent = 0.0
        self.solves_since = 0
        self.update = _Update()
        self.normal, self.tang = normal.copy(), tang.copy()

    @property
    def worn(self) -> bool:
        """Refactor? (more replaced rows than max_updates, or more than refactor_solves
        column solves since the factorization: counts, never clocks)"""
        return (len(self.update.rows) > self.max_updates
                or self.solves_since > self.refactor_solves)

    # -- row updates ------------------------------------------------------------------------
    def _delta(self, r: int, normal: np.ndarray, tang: np.ndarray):
        ci, cv = self.sys.row(r, normal, tang)
        lo, hi = self.K0.indptr[r], self.K0.indptr[r + 1]
        return _sparse_sub(ci, cv, self.K0.indices[lo:hi], self.K0.data[lo:hi])

    def _propose(self, normal: np.ndarray, tang: np.ndarray, changed: np.ndarray) -> _Update:
        """The update for K(states), given the rows that differ from the current states;
        raises SingularSystem when that K is singular. New rows get a slot and a column of Y
        (one solve with the base LU)."""
        up = self.update
        rows, slots, delta = list(up.rows), dict(up.slots), list(up.delta)
        m_old = len(rows)
        touched = set()
        for r in changed.tolist():
            d = self._delta(r, normal, tang)
            if r in slots:
                delta[slots[r]] = d
            else:
                slots[r] = len(rows)
                rows.append(r)
                delta.append(d)
            touched.add(slots[r])
        m = len(rows)
        if m > self.Y.shape[1]:
            self.Y = np.concatenate([self.Y, np.zeros((self.sys.N, max(m, self.Y.shape[1])))],
                                    axis=1)
        t0 = time.perf_counter()
        if m > m_old:  # the new columns of Y in one multi-right-hand-side solve
            E = np.zeros((self.sys.N, m - m_old))
            E[rows[m_old:], np.arange(m - m_old)] = 1.0
            self.Y[:, m_old:m] = self.lu.solve(E)
        dt = time.perf_counter() - t0
        self.spent += dt
        self.stats["update_solves"] += m - m_old
        self.solves_since += m - m_old
        self.stats["update_seconds"] += dt
        Ym = self.Y[:, :m]
        C = np.eye(m)
        C[:m_old, :m_old] = up.C
        for j in touched:  # rows of C whose Delta changed (and the new ones)
            ci, cv = delta[j]
            C[j, :] = cv @ Ym[ci, :] if ci.size else 0.0
            C[j, j] += 1.0
        if m > m_old:  # new columns of the old, untouched rows
            old = [i for i in range(m_old) if i not in touched]
            if old:
                Dold = _rows_matrix([delta[i] for i in old], self.sys.N)
                C[np.ix_(old, range(m_old, m))] = Dold @ Ym[:, m_old:]
        new = _Update(rows, slots, delta, C, D=_rows_matrix(delta, self.sys.N))
        if m:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", LinAlgWarning)
                lu, piv = lu_factor(C, check_finite=False)
            anorm = float(np.max(np.sum(np.abs(C), axis=0)))
            rcond, _ = dgecon(lu, anorm, norm="1")
            if not np.all(np.diagonal(lu) != 0) or not rcond >= RCOND:
                raise SingularSystem(f"capacitance rcond {rcond:.2e}")
            new.lu = (lu, piv)
        return new

    def set_states(self, normal: np.ndarray, tang: np.ndarray) -> None:
        """Make K(states) current (row updates, or a new base when many rows change);
        raises SingularSystem and keeps the previous states when it is singular."""
        changed = np.flatnonzero(np.concatenate([normal != self.normal, tang != self.tang]))
        if changed.size == 0:
            return
        rows = set(self.update.rows)
        new = len(set(changed.tolist()) - rows)
        if len(rows) + new > self.max_updates or self.solves_since + new > self.refactor_solves:
            self.refactor(normal, tang)  # cheaper than `new` column solves and their update
            return
        self.update = self._propose(normal, tang, changed)
        self.normal, self.tang = normal.copy(), tang.copy()

    # -- solves -----------------------------------------------------------------------------
    def solve(self, b: np.ndarray) -> np.ndarray:
        """K^-1 b for the current states."""
        y = self.lu.solve(b)
        up = self.update
        if not up.rows:
            return y
        t = up.D @ y
        return y - self.Y[:, :len(up.rows)] @ lu_solve(up.lu, t, check_finite=False)

    def solve_current(self) -> np.ndarray:
        """lambda of the current states, refined once when the residual |K x - b| exceeds
        1e-12 of |K| |x| + |b| (the capacitance update can lose a few digits)."""
        b = self.sys.rhs(self.normal, self.tang)
        x = self.solve(b)
        r = b - self.sys.apply(x, self.normal, self.tang)
        scale = float(np.abs(b).max(initial=0.0)) + self.sys.wnorm * float(
            np.abs(x).max(initial=0.0))
        if np.abs(r).max(initial=0.0) > 1e-12 * scale:
            x = x + self.solve(r)
            self.stats["refinements"] = self.stats.get("refinements", 0) + 1
        return x


def _rows_matrix(rows: list[tuple[np.ndarray, np.ndarray]], N: int) -> sp.csr_matrix:
    """Sparse rows given as (indices, values) stacked into a csr matrix."""
    indptr = np.concatenate([[0], np.cumsum([ci.size for ci, _ in rows])])
    indices = np.concatenate([ci for ci, _ in rows]) if rows else np.zeros(0, int)
    data = np.concatenate([cv for _, cv in rows]) if rows else np.zeros(0)
    return sp.csr_matrix((data, indices, indptr), shape=(len(rows), N))


def _sparse_sub(ai, av, bi, bv) -> tuple[np.ndarray, np.ndarray]:
    """(a - b) of two sparse rows given as (indices, values), zeros dropped."""
    idx = np.concatenate([ai, bi])
    val = np.concatenate([av, -bv])
    uniq, inv = np.unique(idx, return_inverse=True)
    out = np.zeros(uniq.size)
    np.add.at(out, inv, val)
    keep = out != 0
    return uniq[keep], out[keep]
