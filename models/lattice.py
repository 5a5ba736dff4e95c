"""Disks in a box (two vertical walls and a basal plane) and the regular arrays of equal disks.

A `Lattice` is the geometry every model reads: centres, one radius per disk (and optionally one
mass and one moment of inertia per disk), the walls x = left, x = right and every contact.
The regular arrays of the paper (Sec. II A, Fig. 1) are two generators of it; any other set of
disks is built by models.packing (contacts detected with a stated gap tolerance).
Units of the arrays: radius r (default 1). The box spans 0 <= x <= 2 r Lx; the plane is y = 0.

* rectangular(Lx, Ly): Ly rows of Lx disks, each row touching both walls; columns stacked.
* triangular(Lx, Ly): rows alternate between Lx disks (touching both walls) and Lx - 1 disks
  sitting in the hollows (touching neither wall); the bottom row is a full row on the plane.
  Lx is the paper's: the number of disks in the rows that touch both walls (Eq. 3.3).

Contact alpha joins body i (always a disk) and body j (a disk or an obstacle). Its unit normal n
points from i to j and its tangent is t = n rotated by +90 degrees (mechanics.md). For two disks,
i is the lower (or, in a row, the left) one, so n points up or to the right.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigidlcp.lcp.errors import InvalidInput

#: Codes of the obstacles in `Lattice.j` (disks have indices >= 0).
LEFT_WALL, RIGHT_WALL, PLANE = -1, -2, -3
OBSTACLE_NAMES = {LEFT_WALL: "left wall", RIGHT_WALL: "right wall", PLANE: "plane"}
#: Contact kinds, as in the paper's three coefficients of friction.
KINDS = ("pp", "plane", "wall")


class InvalidSystem(InvalidInput):
    """A lattice or system that cannot be built; the message names the parameter."""


@dataclass(frozen=True, eq=False)
class Lattice:
    """Positions of the disks and every contact (all contacts are closed: interstice zero).

    Arrays: x (p, 2) centres; row, col (p,) indices (-1 for a packing); for each contact alpha:
    i[alpha] (disk), j[alpha] (disk index or LEFT_WALL / RIGHT_WALL / PLANE), n[alpha], t[alpha]
    unit vectors, kind[alpha] in KINDS.
    Per disk: radii (p,) (default: every disk has `radius`); masses, inertias (p,) or None (then
    models.System gives them: one mass m, I = m r_i^2 / 2). `radius` is the radius of an array,
    the mean radius of a packing (a length scale). left, right: the walls' abscissae (None: no
    such wall; the arrays' are 0 and 2 r Lx). name: "rect", "tri" or "packing".
    """

    name: str
    lx: int
    ly: int
    radius: float
    x: np.ndarray
    row: np.ndarray
    col: np.ndarray
    i: np.ndarray
    j: np.ndarray
    n: np.ndarray
    t: np.ndarray
    kind: np.ndarray
    radii: np.ndarray | None = None
    masses: np.ndarray | None = None
    inertias: np.ndarray | None = None
    left: float | None = 0.0
    right: float | None = None
    gap_tol: float = 0.0

    def __post_init__(self) -> None:
        if self.radii is None:
            object.__setattr__(self, "radii", np.full(self.x.shape[0], float(self.radius)))
        if self.right is None and self.name in ("rect", "tri"):
            object.__setattr__(self, "right", 2.0 * self.radius * self.lx)

    @property
    def regular(self) -> bool:
        """True for the paper's arrays (rect, tri), False for a general packing."""
        return self.name in ("rect", "tri")

    @property
    def p(self) -> int:
        """Number of disks."""
        return self.x.shape[0]

    @property
    def c(self) -> int:
        """Number of contacts."""
        return self.i.size

    @property
    def width(self) -> float:
        """The box's width: 2 r Lx for the arrays, right - left (or the disks' extent)."""
        if self.regular:
            return 2.0 * self.radius * self.lx
        lo = self.left if self.left is not None else float(np.min(self.x[:, 0] - self.radii))
        hi = self.right if self.right is not None else float(np.max(self.x[:, 0] + self.radii))
        return hi - lo

    def label(self, alpha: int) -> str:
        """Human-readable name of contact alpha, e.g. 'disk 3 (row 0, col 3) - plane'."""
        i, j = int(self.i[alpha]), int(self.j[alpha])
        other = OBSTACLE_NAMES[j] if j < 0 else self.disk_label(j)
        return f"#{alpha} {self.disk_label(i)} - {other}"

    def disk_label(self, k: int) -> str:
        if not self.regular:
            return f"disk {k}"
        return f"disk {k} (row {int(self.row[k])}, col {int(self.col[k])})"

    def contacts_of_kind(self, kind: str) -> np.ndarray:
        if kind not in KINDS:
            raise InvalidSystem(f"contact kind must be one of {KINDS}, got {kind!r}")
        return np.flatnonzero(self.kind == kind)

    def __repr__(self) -> str:
        size = f" {self.lx}x{self.ly}" if self.regular else ""
        return f"<Lattice {self.name}{size}: {self.p} disks, {self.c} contacts>"

    def title(self) -> str:
        """'rect 4x3' for an array, 'packing of 120 disks' for a packing (figure titles)."""
        return f"{self.name} {self.lx}x{self.ly}" if self.regular else f"packing of {self.p} disks"


def _check_size(name: str, value, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise InvalidSystem(f"{name} must be an integer, got {value!r}")
    if value < minimum:
        raise InvalidSystem(f"{name} must be >= {minimum}, got {value}")
    return int(value)


#: The largest array built: 10^6 disks (2 x 10^6 contacts). The sparse event path handles
#: 100 x 100 disks in seconds per hundred events; a million disks already needs gigabytes for
#: one factorization, and a size past this is a typo (a missing comma), not a system.
MAX_DISKS = 1_000_000


def _check_disks(lx: int, ly: int) -> None:
    if lx * ly > MAX_DISKS:
        raise InvalidSystem(f"an array of lx x ly = {lx} x {ly} disks is larger than the "
                            f"{MAX_DISKS} disks this toolkit builds")


def _check_radius(radius) -> float:
    r = float(radius)
    if not np.isfinite(r) or r <= 0:
        raise InvalidSystem(f"radius must be a positive finite number, got {radius!r}")
    return r


def rectangular(lx: int, ly: int, radius: float = 1.0) -> Lattice:
    """Ly rows of Lx disks in columns; every row touches both walls, the bottom row the plane."""
    lx, ly, r = _check_size("lx", lx, 1), _check_size("ly", ly, 1), _check_radius(radius)
    _check_disks(lx, ly)
    rows = [[(r + 2 * r * k, r + 2 * r * m) for k in range(lx)] for m in range(ly)]
    return _build("rect", lx, ly, r, rows, full=[True] * ly)


def triangular(lx: int, ly: int, radius: float = 1.0) -> Lattice:
    """Rows alternate Lx disks (touching both walls) and Lx - 1 disks in the hollows.

    The bottom row is a full row resting on the plane. Needs lx >= 2 when ly >= 2 (a row of
    lx - 1 >= 1 disks must exist above the bottom row).
    """
    lx, ly, r = _check_size("lx", lx, 1), _check_size("ly", ly, 1), _check_radius(radius)
    _check_disks(lx, ly)
    if ly >= 2 and lx < 2:
        raise InvalidSystem(
            f"a triangular array with ly = {ly} rows needs lx >= 2 (the rows in the hollows "
            f"hold lx - 1 disks), got lx = {lx}"
        )
    h = np.sqrt(3.0) * r
    rows = []
    for m in range(ly):
        if m % 2 == 0:
            rows.append([(r + 2 * r * k, r + h * m) for k in range(lx)])
        else:
            rows.append([(2 * r + 2 * r * k, r + h * m) for k in range(lx - 1)])
    return _build("tri", lx, ly, r, rows, full=[m % 2 == 0 for m in range(ly)])


def _build(name: str, lx: int, ly: int, r: float, rows: list, full: list[bool]) -> Lattice:
    x, row, col, index = [], [], [], []
    for m, disks in enumerate(rows):
        index.append([])
        for k, pos in enumerate(disks):
            index[m].append(len(x))
            x.append(pos)
            row.append(m)
            col.append(k)
    x = np.array(x, dtype=float)
    ci, cj, normals, kinds = [], [], [], []

    def add(i: int, j: int, n, kind: str) -> None:
        ci.append(i)
        cj.append(j)
        normals.append(n)
        kinds.append(kind)

    for k in index[0]:  # the plane, below the bottom row
        add(k, PLANE, (0.0, -1.0), "plane")
    for m, ids in enumerate(index):
        if full[m]:
            add(ids[0], LEFT_WALL, (-1.0, 0.0), "wall")
        for a, b in zip(ids[:-1], ids[1:]):
            add(a, b, (1.0, 0.0), "pp")
        if full[m]:
            add(ids[-1], RIGHT_WALL, (1.0, 0.0), "wall")
        if m + 1 < len(index):  # contacts with the row above: every pair at distance 2r
            above = index[m + 1]
            d = x[above][None, :, :] - x[ids][:, None, :]  # d[a, b] = x_b - x_a
            touching = np.abs(np.hypot(d[..., 0], d[..., 1]) - 2 * r) <= 1e-9 * r
            for a, b in np.argwhere(touching):  # a (this row) outer, b (the row above) inner
                add(ids[a], above[b], tuple(d[a, b] / (2 * r)), "pp")
    n = np.array(normals, dtype=float)
    t = np.column_stack([-n[:, 1], n[:, 0]])  # n rotated by +90 degrees
    return Lattice(
        name=name, lx=lx, ly=ly, radius=r, x=x, row=np.array(row), col=np.array(col),
        i=np.array(ci), j=np.array(cj), n=n, t=t, kind=np.array(kinds),
    )


def make_lattice(kind: str, lx: int, ly: int, radius: float = 1.0) -> Lattice:
    """`rectangular` or `triangular` by name ('rect'/'rectangular', 'tri'/'triangular')."""
    key = str(kind).lower()
    if key in ("rect", "rectangular"):
        return rectangular(lx, ly, radius)
    if key in ("tri", "triangular"):
        return triangular(lx, ly, radius)
    raise InvalidSystem(f"lattice must be 'rect' or 'tri', got {kind!r}")
