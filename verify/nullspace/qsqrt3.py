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
assembled exactly, with the same rules as `models.contact_matrix`. Standard library only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from rigidlcp import models

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
        raise ValueError(f"one state per contact expected ({c})")
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


def rref(rows: list[Row]) -> tuple[list[Row], list[int]]:
    """Reduced row echelon form by exact Gauss-Jordan elimination on sparse rows.

    Returns the nonzero rows (each with a leading 1 at its pivot column, zero in the other pivot
    columns) and the pivot columns, in order. len(pivots) is the exact rank.
    """
    work = [dict(r) for r in rows if r]
    reduced: list[Row] = []
    pivots: list[int] = []
    while work:
        col = min(min(r) for r in work)  # leftmost column with a nonzero entry
        k = next(i for i, r in enumerate(work) if col in r)
        prow = work.pop(k)
        inv = prow[col].inverse()
        prow = {j: v * inv for j, v in prow.items()}
        nxt = []
        for r in work:
            if col in r:
                f = r.pop(col)
                for j, v in prow.items():
                    if j != col:
                        r[j] = r.get(j, ZERO) - f * v
                r = _clean(r)
            if r:
                nxt.append(r)
        work = nxt
        for r in reduced:  # back-substitution keeps the form reduced
            if col in r:
                f = r.pop(col)
                for j, v in prow.items():
                    if j != col:
                        r[j] = r.get(j, ZERO) - f * v
                for j in [j for j, v in r.items() if not v]:
                    del r[j]
        reduced.append(prow)
        pivots.append(col)
    return reduced, pivots


def exact_rank(rows: list[Row]) -> int:
    """Exact rank (over Q(sqrt 3), hence over R)."""
    return len(rref(rows)[1])


def exact_null_support(rows: list[Row], ncols: int) -> tuple[int, set[int]]:
    """Exact null-space dimension and the columns that are nonzero in some null vector.

    With the reduced echelon form, the null space is spanned by one vector per free column f:
    x_f = 1, x_p = -rref[p, f] for every pivot column p. A column is in the support iff it is
    free or its pivot row has a nonzero entry in some free column.
    """
    reduced, pivots = rref(rows)
    free = set(range(ncols)) - set(pivots)
    support = set(free)
    for row, p in zip(reduced, pivots):
        if any(j in free for j in row if j != p):
            support.add(p)
    return len(free), support


def exact_null_dim(system: models.System, normal: np.ndarray, tangential: np.ndarray) -> int:
    """dim ker M of Eq. (2.15), computed exactly."""
    return 2 * system.c - exact_rank(exact_contact_matrix(system, normal, tangential))
