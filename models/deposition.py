"""Sequential deposition under gravity in the box (Visscher & Bolsterli's rule), and defects.

`deposit(n, seed, radii=(a, b), width=W)` drops n disks, one at a time, each from a random
abscissa above the pile. A disk falls vertically until it touches a disk or the plane, then
rolls down on what it touches (steepest descent on the pile, keeping that contact) until it
rests on two supports whose forces hold its weight: disk/disk, disk/wall or disk/plane. A disk
that reaches the plane without touching a disk slides along it (to a side drawn from the seed)
until it touches a disk or a wall. So every disk is placed at a stable resting position of the
pile, with its contacts exact by construction (distances equal to r_i + r_j up to rounding):
`models.packing` finds them with its default gap tolerance. A position found by a grazing
intersection (a disk beside another at its equator, common in monodisperse piles) is refined
onto its two best-conditioned supports (`_Pile.polish`), so that a contact meant horizontal is
not tilted by sqrt(eps). Radii are uniform in [a, b]
(a = b: monodisperse), drawn from `seed` with the drop abscissae.

`with_vacancies(lattice, fraction, seed)`: a regular array with disks removed at random
(contacts of the remaining ones kept: an array with vacancies).

The neighbours of a disk are found on a uniform grid of cells of side 2 max(r).
"""

from __future__ import annotations

import math

import numpy as np

from .lattice import InvalidSystem, Lattice
from .packing import GAP_TOL, packing

_TOL = 1e-12  # relative: force signs and angles compared with this margin
#: supports within this gap (times r) of a resting position are refined onto (_Pile.polish)
POLISH_REACH = 1e-6
#: radii whose masses r^2 and inertias r^4 / 2 are normal floats (outside, they overflow or
#: underflow: `pack --radii 1:1e300` warned of an overflow, then refused the inertia)
R_LIMITS = (1e-76, 1e76)


class _Grid:
    """Disks hashed by cell (side h): candidates near a point in O(1) cells."""

    def __init__(self, h: float):
        self.h = h
        self.cells: dict[tuple[int, int], list[int]] = {}
        self.columns: dict[int, list[int]] = {}

    def add(self, k: int, x: float, y: float) -> None:
        cx, cy = int(math.floor(x / self.h)), int(math.floor(y / self.h))
        self.cells.setdefault((cx, cy), []).append(k)
        self.columns.setdefault(cx, []).append(k)

    def near(self, x: float, y: float, reach: float) -> list[int]:
        n = int(math.ceil(reach / self.h))
        cx, cy = int(math.floor(x / self.h)), int(math.floor(y / self.h))
        out: list[int] = []
        for i in range(cx - n, cx + n + 1):
            for j in range(cy - n, cy + n + 1):
                out += self.cells.get((i, j), [])
        return out

    def column(self, x: float, reach: float) -> list[int]:
        n = int(math.ceil(reach / self.h))
        cx = int(math.floor(x / self.h))
        out: list[int] = []
        for i in range(cx - n, cx + n + 1):
            out += self.columns.get(i, [])
        return out


class _Pile:
    """The disks placed so far, in the box [0, width] above the plane y = 0."""

    def __init__(self, width: float, rmax: float, capacity: int, rng: np.random.Generator):
        self.width, self.rng = width, rng
        self.x = np.zeros((capacity, 2))
        self.r = np.zeros(capacity)
        self.p = 0
        self.grid = _Grid(2.0 * rmax)
        self.rmax = rmax

    def place(self, r: float, x0: float) -> np.ndarray:
        """The resting centre of a disk of radius r dropped at abscissa x0."""
        p = self._fall(r, x0, math.inf)
        for _ in range(10 * self.p + 100):  # every move ends strictly lower: it terminates
            contacts = self._touching(r, p)
            if [c[0] for c in contacts] == ["plane"]:  # on the plane alone: slide along it
                return self._slide(r, p, 1.0 if self.rng.random() < 0.5 else -1.0)
            move = self._descent(contacts)
            if move is None:  # no way down: the supports hold the weight
                return p
            if move[0] == "fall":
                p = self._fall(r, p[0], p[1])
            else:
                p = self._roll(r, move[1], p, move[2], {c[1] for c in contacts})
        raise RuntimeError("deposition: a disk did not come to rest (please report)")

    def _touching(self, r: float, p: np.ndarray, rel: float = 1e-9
                  ) -> list[tuple[str, int, np.ndarray]]:
        """(kind, index, unit normal from the support to the disk) of every body touching a
        disk of radius r at p (gap within rel r)."""
        tol = rel * r
        out = []
        if abs(p[1] - r) <= tol:
            out.append(("plane", -3, np.array([0.0, 1.0])))
        if abs(p[0] - r) <= tol:
            out.append(("wall", -1, np.array([1.0, 0.0])))
        if abs(self.width - r - p[0]) <= tol:
            out.append(("wall", -2, np.array([-1.0, 0.0])))
        for k in self.grid.near(p[0], p[1], r + self.rmax):
            d = p - self.x[k]
            dist = math.hypot(d[0], d[1])
            if abs(dist - r - self.r[k]) <= tol:
                out.append(("disk", k, d / dist))
        return out

    def _descent(self, contacts) -> tuple | None:
        """The steepest way down that opens no contact's interpenetration: a free fall, or
        rolling on a disk below (("roll", k, direction)); None when there is none."""
        normals = [c[2] for c in contacts]

        def free(v: np.ndarray) -> bool:
            return all(float(v @ n) >= -_TOL for n in normals)

        best = None
        if free(np.array([0.0, -1.0])):
            return ("fall",)
        for kind, k, n in contacts:
            if kind != "disk" or n[1] <= _TOL:
                continue
            if abs(n[0]) <= _TOL:  # on the very top: either side
                dirs = [1.0, -1.0] if self.rng.random() < 0.5 else [-1.0, 1.0]
            else:
                dirs = [math.copysign(1.0, n[0])]
            for direction in dirs:
                tau = np.array([n[1], -n[0]]) if direction > 0 else np.array([-n[1], n[0]])
                if tau[1] < -_TOL and free(tau) and (best is None or tau[1] < best[0]):
                    best = (tau[1], k, direction)
        return None if best is None else ("roll", best[1], best[2])

    # -- a disk falling vertically at abscissa x from height y_top --------------------------
    def _fall(self, r: float, x: float, y_top: float) -> np.ndarray:
        """Where a disk falling from (x, y_top) first touches a disk or the plane."""
        best = r  # the plane
        ks = self.grid.column(x, r + self.rmax)
        if ks:
            ks = np.array(ks)
            dx = x - self.x[ks, 0]
            D = r + self.r[ks]
            ok = np.abs(dx) < D
            if np.any(ok):
                y = self.x[ks[ok], 1] + np.sqrt(D[ok] ** 2 - dx[ok] ** 2)
                y = y[y < y_top - 1e-9 * r]  # bodies touched now are not met again
                best = max(best, float(y.max(initial=-np.inf)))
        return np.array([x, best])

    # -- a disk rolling down on disk `on` in `direction` (+1: to the right) ------------------
    def _roll(self, r: float, on: int, pos: np.ndarray, direction: float,
              touching: set) -> np.ndarray:
        """Where a disk rolling on `on` first touches another body (or leaves `on`, at its
        equator); bodies touched at the start are met only past 1e-9 rad."""
        a, D = self.x[on], r + self.r[on]
        theta0 = max(math.atan2(direction * (pos[0] - a[0]), pos[1] - a[1]), 0.0)
        hits = [(math.pi / 2, "edge")]  # (theta, what)
        wall = self.width - r if direction > 0 else r
        s = direction * (wall - a[0]) / D
        if s <= 1.0:
            hits.append((math.asin(max(s, -1.0)), "wall"))
        cplane = (r - a[1]) / D  # a[1] + D cos(theta) = r
        if -1.0 <= cplane <= 1.0:
            hits.append((math.acos(cplane), "plane"))
        for k in self.grid.near(a[0], a[1], D + r + self.rmax):
            if k != on:
                for th in _circle_hits(a, D, self.x[k], r + self.r[k], direction):
                    if th > theta0 + (1e-9 if k in touching else 1e-12):
                        hits.append((th, "disk"))
        th, what = min(h for h in hits if h[0] > theta0 + 1e-12 or h[1] == "edge")
        th = max(th, theta0)
        p = a + D * np.array([direction * math.sin(th), math.cos(th)])
        if what == "wall":
            p[0] = wall
        elif what == "plane":
            p[1] = r
        return p

    def _slide(self, r: float, pos: np.ndarray, direction: float) -> np.ndarray:
        """Slide along the plane (y = r) until touching a disk or a wall."""
        x0 = pos[0]
        stop = self.width - r if direction > 0 else r
        for k in self.grid.column(x0, self.width):  # every disk low enough to be met
            h = r - self.x[k, 1]
            D = r + self.r[k]
            if abs(h) >= D:
                continue
            xk = self.x[k, 0] - direction * math.sqrt(D * D - h * h)
            if direction * (xk - x0) >= -1e-12 * r and direction * (xk - stop) < 0:
                stop = xk
        return np.array([stop, r])

    def polish(self, r: float, p: np.ndarray) -> np.ndarray:
        """p refined onto its two best-conditioned supports (largest |n1 x n2|) by Newton's
        method on their gap functions (gradient: the unit normal). Resting positions found by
        grazing intersections (a fall or a roll ending at a support's equator) carry errors
        of sqrt(eps) ~ 2e-8 along the badly conditioned direction, which tilt a contact that
        should be horizontal by that much and make a force network balance it with forces of
        1/tilt ~ 1e8 weights; refined on the supports that fix p well, such a contact is
        exact to rounding. The supports are looked for within POLISH_REACH r (such a position
        misses a third support by ~1e-8 r); the refined point is kept only if each of them is
        then a contact (gap within 1e-9 r) and nothing overlaps beyond that."""
        contacts = self._touching(r, p, POLISH_REACH)
        if len(contacts) < 3:  # on two supports: they are the ones p was computed from
            return p
        best, pair = 0.0, None
        for a in range(len(contacts)):
            for b in range(a + 1, len(contacts)):
                n1, n2 = contacts[a][2], contacts[b][2]
                det = abs(n1[0] * n2[1] - n1[1] * n2[0])
                if det > best:
                    best, pair = det, (contacts[a], contacts[b])
        if pair is None or best < 1e-3:
            return p
        q = p.copy()
        for _ in range(4):
            g = np.array([self._gap(r, q, c) for c in pair])
            J = np.array([self._normal(r, q, c) for c in pair])
            q = q - np.linalg.solve(J, g)
        for kind, k, _n in pair:  # a wall or the plane: exactly at r from it
            if kind == "plane":
                q[1] = r
            elif k == -1:
                q[0] = r
            elif k == -2:
                q[0] = self.width - r
        tol = 1e-9 * r
        if any(abs(self._gap(r, q, c)) > tol for c in contacts):
            return p
        for k in self.grid.near(q[0], q[1], r + self.rmax):
            if math.hypot(*(q - self.x[k])) - r - self.r[k] < -tol:
                return p
        return q

    def _gap(self, r: float, p: np.ndarray, contact) -> float:
        kind, k, _ = contact
        if kind == "plane":
            return float(p[1] - r)
        if kind == "wall":
            return float(p[0] - r) if k == -1 else float(self.width - r - p[0])
        return math.hypot(p[0] - self.x[k, 0], p[1] - self.x[k, 1]) - r - float(self.r[k])

    def _normal(self, r: float, p: np.ndarray, contact) -> np.ndarray:
        kind, k, n = contact
        return n if kind != "disk" else _unit(p - self.x[k])

    def add(self, r: float, c: np.ndarray) -> None:
        k = self.p
        self.x[k], self.r[k] = c, r
        self.grid.add(k, c[0], c[1])
        self.p += 1


def _unit(v: np.ndarray) -> np.ndarray:
    return v / math.hypot(v[0], v[1])


def _circle_hits(a: np.ndarray, D: float, b: np.ndarray, E: float, direction: float):
    """Angles theta (from the vertical, towards `direction`) of the points a + D (dir sin,
    cos) at distance E from b."""
    d = b - a
    dist = math.hypot(d[0], d[1])
    if dist > D + E or dist < abs(D - E) or dist == 0:
        return []
    along = (D * D - E * E + dist * dist) / (2 * dist)
    h = math.sqrt(max(D * D - along * along, 0.0))
    u = d / dist
    out = []
    for sgn in (1.0, -1.0):
        q = along * u + sgn * h * np.array([-u[1], u[0]])
        out.append(math.atan2(direction * q[0], q[1]))
    return out


def _radii(n: int, radii: tuple[float, float], rng: np.random.Generator) -> np.ndarray:
    a, b = (float(v) for v in radii)
    if not (math.isfinite(a) and math.isfinite(b) and 0 < a <= b):
        raise InvalidSystem(f"radii must be MIN:MAX with 0 < MIN <= MAX, got {a}:{b}")
    if not (R_LIMITS[0] <= a and b <= R_LIMITS[1]):  # m = r^2, I = m r^2 / 2 must be normal
        raise InvalidSystem(f"radii must lie in [{R_LIMITS[0]:.0e}, {R_LIMITS[1]:.0e}] (the "
                            f"inertia r^4 / 2 a normal float), got {a:g}:{b:g}")
    return np.full(n, a) if a == b else rng.uniform(a, b, n)


def deposit(n: int, seed: int = 0, radii: tuple[float, float] = (1.0, 1.0),
            width: float | None = None, gap_tol: float = GAP_TOL,
            progress=None) -> Lattice:
    """n disks deposited in the box [0, width] (module docstring); width defaults to
    2 mean(r) round(sqrt(n)) (at least 4 mean radii). progress(k, n): called as disks land."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise InvalidSystem(f"n must be an integer >= 1, got {n!r}")
    rng = np.random.default_rng(seed)
    r = _radii(int(n), radii, rng)
    rmean = float(np.mean([radii[0], radii[1]]))
    if width is None:
        width = 2.0 * rmean * max(2, round(math.sqrt(n)))
    width = float(width)
    if not (math.isfinite(width) and width >= 2.0 * float(r.max())):
        raise InvalidSystem(f"width must be >= the largest diameter {2 * r.max():g}, "
                            f"got {width!r}")
    pile = _Pile(width, float(r.max()), int(n), rng)
    for k in range(int(n)):
        x0 = rng.uniform(r[k], width - r[k]) if width > 2 * r[k] else width / 2
        rest = pile.place(float(r[k]), x0)
        pile.add(float(r[k]), pile.polish(float(r[k]), rest))
        if progress is not None:
            progress(k + 1, int(n))
    m = r**2
    return packing(pile.x, r, m, 0.5 * m * r**2, left=0.0, right=width, gap_tol=gap_tol)


def with_vacancies(lattice: Lattice, fraction: float, seed: int = 0) -> Lattice:
    """The disks of `lattice` with round(fraction p) of them removed at random (seeded)."""
    if not (0 <= fraction < 1):
        raise InvalidSystem(f"fraction must be in [0, 1), got {fraction!r}")
    rng = np.random.default_rng(seed)
    gone = rng.choice(lattice.p, size=int(round(fraction * lattice.p)), replace=False)
    keep = np.setdiff1d(np.arange(lattice.p), gone)
    sub = lambda a: None if a is None else a[keep]  # noqa: E731
    return packing(lattice.x[keep], lattice.radii[keep], sub(lattice.masses),
                   sub(lattice.inertias), left=lattice.left, right=lattice.right)
