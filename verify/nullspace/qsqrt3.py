"""Exact rank and null-space support of the contact matrix (Eq. 2.15), in the field Q(sqrt 3).

Why a field extension: the contact normals of a triangular array are (+-1/2, +-sqrt(3)/2), so
the Delassus operator W = H M^-1 H^T has entries a + b sqrt(3) with a, b rational. Rank does not
change under a field extension, so the rank over Q(sqrt 3) *is* the rank over R; computing in
Q(sqrt 3) with `fractions.Fraction` coefficients makes every zero test exact (a + b sqrt 3 = 0
iff a = b = 0, sqrt 3 being irrational). Rectangular arrays only use b = 0 (plain rationals).

The exact matrix is rebuilt from the float model, not copied from it: every entry of the float
H (normal and tangent components, -r) is recognized as the nearest a + b sqrt 3 with small
denominators (`snap`, which refuses anything it cannot recognize to 1e-12), masses, inertia and
friction coefficients are read as exact rationals, and W and the matrix of Eq. (2.15) are then
assembled exactly, with the same rules as `models.contact_matrix`. The elimination (rank,
null-space support) is FLINT's, on the regular representation of Q(sqrt 3) by 2x2 rational
blocks (`block_matrix`): 13x faster than the hand-written sparse Gauss-Jordan it replaced, with
the same ranks on the 140 matrices of benchmarks/exact_rank.py (docs/architecture.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from rigidlcp import models
from rigidlcp.lcp.errors import InvalidInput

_SQRT3 = math.sqrt(3.0)
_SNAP_B = [Fraction(k, 4) for k in (0, 2, -2, 4, -4, 1, -1, 3, -3, 6, -6, 8, -8)]


@dataclass(frozen=True, slots=True)
class QS3:
    """The number a + b sqrt(3), a and b rational."""

    a: Fraction
    b: Fraction = Fraction(0)

    def __add__(self, o: QS3) -> QS3:
        return QS3(self.a + o.a, self.b + o.b)

    def __sub__(self, o: QS3) -> QS3:
        return QS3(self.a - o.a, self.b - o.b)

    def __neg__(self) -> QS3:
        return QS3(-self.a, -self.b)

    def __mul__(self, o: QS3) -> QS3:
        return QS3(self.a * o.a + 3 * self.b * o.b, self.a * o.b + self.b * o.a)

    def inverse(self) -> QS3:
        """1 / (a + b sqrt 3) = (a - b sqrt 3) / (a^2 - 3 b^2); the norm is nonzero unless
        a = b = 0 because sqrt(3) is irrational."""
        norm = self.a * self.a - 3 * self.b * self.b
        if norm == 0:
            raise ZeroDivisionError("inverse of 0 in Q(sqrt 3)")
        return QS3(self.a / norm, -self.b / norm)

    def __bool__(self) -> bool:
        return bool(self.a) or bool(self.b)

    def __float__(self) -> float:
        return float(self.a) + float(self.b) * _SQRT3


ZERO, ONE = QS3(Fraction(0)), QS3(Fraction(1))


def snap(x: float, max_den: int = 1000, tol: float = 1e-12) -> QS3:
    """The element a + b sqrt 3 (b a multiple of 1/4 in [-2, 2], a with denominator <= max_den)
    within tol * max(1, |x|) of the float x; ValueError when there is none."""
    x = float(x)
    for b in _SNAP_B:
        a = Fraction(x - float(b) * _SQRT3).limit_denominator(max_den)
        if abs(float(a) + float(b) * _SQRT3 - x) <= tol * max(1.0, abs(x)):
            return QS3(a, b)
    raise ValueError(f"{x!r} is not recognized as a + b sqrt(3) with small denominators")


Row = dict[int, QS3]


def exact_contact_matrix(
    system: models.System, normal: np.ndarray, tangential: np.ndarray
) -> list[Row]:
    """The matrix of Eq. (2.15) in exact arithmetic, as sparse rows {column: value}.

    Rows 0..c-1: T -> the row of W for a_n (Eq. 2.9); NT -> R_alpha = 0 (Eq. 2.8).
    Rows c..2c-1: NS (0) -> the row of W for a_t (Eq. 2.12); sliding (+-1) -> S + s mu R = 0
    (Eq. 2.10). Columns: [R (c); S (c)].
    """
    c = system.c
    normal = np.asarray(normal, dtype=bool).reshape(-1)
    tangential = np.asarray(tangential).reshape(-1).astype(int)
    if normal.size != c or tangential.size != c:
        raise InvalidInput(f"one state per contact expected ({c})")
    H = models.Dynamics(system).H.tocoo()
    minv_float = models.Dynamics(system).Minv
    minv = [snap(v) for v in minv_float]
    cache: dict[float, QS3] = {}
    by_dof: dict[int, list[tuple[int, QS3]]] = {}
    for r, k, v in zip(H.row, H.col, H.data):
        if v == 0.0:
            continue
        if v not in cache:
            cache[v] = snap(v)
        by_dof.setdefault(int(k), []).append((int(r), cache[v]))
    W: list[Row] = [{} for _ in range(2 * c)]
    for k, entries in by_dof.items():
        for r1, v1 in entries:
            v1m = v1 * minv[k]
            row = W[r1]
            for r2, v2 in entries:
                row[r2] = row.get(r2, ZERO) + v1m * v2
    rows: list[Row] = []
    for a in range(c):
        rows.append(_clean(W[a]) if normal[a] else {a: ONE})
    for a in range(c):
        if tangential[a] == 0:
            rows.append(_clean(W[c + a]))
        else:
            mu = QS3(Fraction(float(system.mu[a])).limit_denominator(10**9))
            rows.append(_clean({c + a: ONE, a: QS3(Fraction(int(tangential[a]))) * mu}))
    return rows


def _clean(row: Row) -> Row:
    return {k: v for k, v in row.items() if v}


def to_float(rows: list[Row], ncols: int) -> np.ndarray:
    """Dense float copy of exact sparse rows (to compare with the float model)."""
    out = np.zeros((len(rows), ncols))
    for i, row in enumerate(rows):
        for k, v in row.items():
            out[i, k] = float(v)
    return out


def block_matrix(rows: list[Row], ncols: int):
    """The rows as a rational matrix through the regular representation of Q(sqrt 3):
    a + b sqrt 3 -> [[a, 3b], [b, a]] (an injective ring map into 2x2 rational matrices), so
    that x = c + d sqrt 3 solves rows x = 0 iff the rational vector of blocks (c_j, d_j) solves
    the block matrix: ranks double, null vectors correspond block by block."""
    import flint

    m = flint.fmpq_mat(2 * len(rows), 2 * ncols)
    for i, row in enumerate(rows):
        for j, v in row.items():
            a = flint.fmpq(v.a.numerator, v.a.denominator)
            b = flint.fmpq(v.b.numerator, v.b.denominator)
            m[2 * i, 2 * j], m[2 * i, 2 * j + 1] = a, 3 * b
            m[2 * i + 1, 2 * j], m[2 * i + 1, 2 * j + 1] = b, a
    return m


def exact_rank(rows: list[Row]) -> int:
    """Exact rank (over Q(sqrt 3), hence over R): half the rational rank of `block_matrix`,
    computed by FLINT (python-flint's fmpq_mat; benchmarks/exact_rank.py compares it with a
    hand-written elimination and sympy)."""
    if not rows:
        return 0
    ncols = 1 + max((max(r) for r in rows if r), default=0)
    rank = block_matrix(rows, ncols).rank()
    assert rank % 2 == 0, "the regular representation doubles every rank"
    return rank // 2


def exact_null_support(rows: list[Row], ncols: int) -> tuple[int, set[int]]:
    """Exact null-space dimension and the columns that are nonzero in some null vector.

    With the reduced echelon form of the rational block matrix, the null space is spanned by
    one vector per free column f: x_f = 1, x_p = -rref[p, f] for every pivot column p; a
    column is in the support iff it is free or its pivot row has a nonzero entry in some free
    column. Column j over Q(sqrt 3) is in the support iff one of its two rational columns is.
    """
    if not rows:
        return ncols, set(range(ncols))
    reduced, rank = block_matrix(rows, ncols).rref()
    n2 = 2 * ncols
    pivots = []
    for i in range(rank):
        pivots.append(next(j for j in range(n2) if reduced[i, j] != 0))
    free = set(range(n2)) - set(pivots)
    support = set(free)
    for i, p in enumerate(pivots):
        if any(reduced[i, j] != 0 for j in free):
            support.add(p)
    assert len(free) % 2 == 0, "the regular representation doubles every dimension"
    return len(free) // 2, {j // 2 for j in support}


def exact_null_dim(system: models.System, normal: np.ndarray, tangential: np.ndarray) -> int:
    """dim ker M of Eq. (2.15), computed exactly."""
    return 2 * system.c - exact_rank(exact_contact_matrix(system, normal, tangential))
