"""Contact-state linear algebra (the paper's Sec. II C): the active system K(states) of a
friction-contact problem a = W lambda + q (lambda = [R; S], block layout [normal; tangent])
and its sparse LU with row updates. Used by lcp.state_pivoting (method ``states``) and by the
disk arrays' sparse event engine (models.sparse_event, models.engine). The states, K and the
LU of a base system are lcp.solvers.state_system's (its module doc; re-exported here); this
module keeps the row updates between pivots (`StateFactor`).

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

import numpy as np
import scipy.sparse as sp
from scipy.linalg import LinAlgWarning, lu_factor, lu_solve
from scipy.linalg.lapack import dgecon

from ..errors import RigidLCPError
from .state_system import (  # noqa: F401  (re-exported: the names users import from here)
    NS,
    PERMC,
    SPLU_OPTIONS,
    ActiveSystem,
    ReducedLU,
    _FullLU,
    factorize,
)

#: C (and a refactored base) counts as singular below this reciprocal condition estimate.
RCOND = 1e-12
#: A fresh LU whose pivots span more than 1 / PIVOT_RATIO is treated as singular.
PIVOT_RATIO = 1e-13
#: Refactor after this many column solves with the base LU (see the module doc).
REFACTOR_SOLVES = 24
#: Factor the reduced system of the rows of W the states keep (`ReducedLU`), not all of K.
REDUCED = True

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
