"""The collective rotation modes of Sec. IV A (Figs. 8-9), read off a steady state.

The paper names three modes in rectangular arrays driven at a constant acceleration:

* mode 1 -- a disk of the first row rolls on the plane: its plane contact is non-sliding, so
  every such disk has the same angular acceleration, that of rolling: with the plane moving at
  -V(t) in the box frame, a_t = -gamma - r omega' = 0 at the plane contact, omega' = -gamma / r;
* mode 2 -- the disk slides on the plane while turning the way rolling turns it, more slowly
  (the paper: "the angular acceleration decreases in absolute value along the row");
* mode 3 -- neighbours turn alternately in opposite directions, omega'_i = -omega'_j, or do not
  turn at all.

The classifier (`row_modes`), for each disk of a row in order of position:

1. mode 1 if its plane contact is transmitting and non-sliding (first row only);
2. otherwise mode 3 if its omega' is zero (|omega'| <= zero_tol), turns against rolling
   (omega' gamma > 0), or is the exact opposite of a row neighbour's
   (|omega'_k + omega'_j| <= pair_tol, with omega'_j != 0): the alternation of mode 3;
3. otherwise mode 2 (it slides, or is above the first row, and turns the rolling way).

zero_tol and pair_tol default to 1e-6 |gamma| / r: the steady accelerations are exact
solutions of linear systems (rounding ~1e-12), so this only separates exact zeros and exact
pairs from genuine values. Disks touching a wall are flagged: the paper gives them "a particular
status" and its Fig. 9 counts nine of the ten disks of the first row.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigidlcp import models
from rigidlcp.models.lattice import PLANE


@dataclass
class RowModes:
    """Modes of the disks of one row, ordered by x."""

    row: int
    disks: np.ndarray  # disk indices, by position
    omega_dot: np.ndarray
    modes: np.ndarray  # 1, 2 or 3
    wall: np.ndarray  # the disk touches a wall

    def counts(self, exclude: np.ndarray | None = None) -> tuple[int, int, int]:
        keep = np.ones(self.modes.size, bool) if exclude is None else ~exclude
        return tuple(int(np.sum(self.modes[keep] == m)) for m in (1, 2, 3))

    def text(self) -> str:
        return "".join(str(int(m)) for m in self.modes)


def _tol(system: models.System) -> float:
    return 1e-6 * max(abs(system.gamma), system.g, 1e-300) / system.lattice.radius


def row_modes(system: models.System, record, row: int = 0, zero_tol: float | None = None,
              pair_tol: float | None = None) -> RowModes:
    """Classify the disks of `row` of a record (see the module docstring)."""
    lat = system.lattice
    zero_tol = _tol(system) if zero_tol is None else zero_tol
    pair_tol = _tol(system) if pair_tol is None else pair_tol
    disks = np.flatnonzero(lat.row == row)
    disks = disks[np.argsort(lat.x[disks, 0])]
    od = np.asarray(record.omega_dot)[disks]
    T = np.asarray(record.R) > 1e-9 * system.mass * max(system.g, abs(system.gamma), 1e-12)
    plane_ns = np.zeros(disks.size, bool)
    for k, d in enumerate(disks):
        alpha = np.flatnonzero((lat.i == d) & (lat.j == PLANE))
        plane_ns[k] = alpha.size == 1 and T[alpha[0]] and record.s[alpha[0]] == 0
    wall = np.array([np.any((lat.i == d) & (lat.kind == "wall")) for d in disks])
    modes = np.full(disks.size, 2)
    for k in range(disks.size):
        if plane_ns[k]:
            modes[k] = 1
            continue
        against = od[k] * system.gamma > 0
        paired = any(0 <= j < disks.size and abs(od[j]) > zero_tol
                     and abs(od[k] + od[j]) <= pair_tol for j in (k - 1, k + 1))
        if abs(od[k]) <= zero_tol or against or paired:
            modes[k] = 3
    return RowModes(row, disks, od, modes, wall)


def contact_groups(lattice: models.Lattice) -> dict[str, np.ndarray]:
    """Contacts of a rectangular array by role: "lateral" (disk-disk in a row), "column"
    (disk-disk between rows), "column_upper" (between rows >= 1, i.e. not the first-second)."""
    pp = lattice.kind == "pp"
    horizontal = np.abs(lattice.n[:, 1]) < 1e-12
    lateral = pp & horizontal
    column = pp & ~horizontal
    upper = column & (lattice.row[lattice.i] >= 1)
    return {"lateral": np.flatnonzero(lateral), "column": np.flatnonzero(column),
            "column_upper": np.flatnonzero(upper)}


def fig5e_loops(system: models.System, record) -> list[tuple[int, int, int, int]]:
    """Loops of four non-sliding transmitting contacts through the plane (Fig. 5e): plane -
    disk A - disk B - disk C - plane, with A, B, C consecutive in the first row. Returned as
    (plane contact of A, contact A-B, contact B-C, plane contact of C)."""
    lat = system.lattice
    T = np.asarray(record.R) > 1e-9 * system.mass * max(system.g, abs(system.gamma), 1e-12)
    ns = T & (np.asarray(record.s) == 0) & (system.mu > 0)
    first = np.flatnonzero(lat.row == 0)
    first = first[np.argsort(lat.x[first, 0])]

    def contact(i: int, j: int) -> int | None:
        hit = np.flatnonzero(((lat.i == i) & (lat.j == j)) | ((lat.i == j) & (lat.j == i)))
        return int(hit[0]) if hit.size else None

    out = []
    for a, b, c in zip(first[:-2], first[1:-1], first[2:]):
        loop = (contact(a, PLANE), contact(a, b), contact(b, c), contact(c, PLANE))
        if None not in loop and all(ns[x] for x in loop):
            out.append(loop)
    return out


__all__ = ["RowModes", "row_modes", "contact_groups", "fig5e_loops"]
