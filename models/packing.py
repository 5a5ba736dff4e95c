"""Any set of disks in the box: contacts detected, overlaps refused, rattlers and clusters found.

`packing(x, r, m, I, left=, right=)` builds the `Lattice` (models.lattice) of disks with centres
x (p, 2), radii r (p,) and optionally masses m and moments of inertia I (p,), between the walls
x = left and x = right (None: no such wall) above the plane y = 0 (driven as for the arrays).

Contacts (closed contacts, interstice zero, as in the paper's arrays). With the gap
g = |x_j - x_i| - r_i - r_j of two disks (x - r - left, right - x - r, y - r for the obstacles)
and the scale s = min(r_i, r_j) (r_i for an obstacle), a pair is a contact when |g| <= gap_tol s;
a pair with g < -gap_tol s overlaps and is refused (`Overlap`, naming the pair and the overlap).
The default gap_tol = 1e-9 keeps contacts that are exact up to rounding (a deposited packing
written with 17 significant digits) and nothing else; gap_tol is at most MAX_GAP_TOL = 0.05.
Normals point from i to j; of two disks
i is the lower one (the left one at equal heights), as in the arrays.

`report(lattice)`: rattlers (disks with fewer than two contacts, obstacles counted) and the
clusters of the contact graph of the disks, those touching no obstacle marked as floating, and
the near misses of those disks (a gap beyond gap_tol but within NEAR_GAP of the radius).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .lattice import LEFT_WALL, MAX_DISKS, PLANE, RIGHT_WALL, InvalidSystem, Lattice

#: Default relative gap tolerance (module docstring).
GAP_TOL = 1e-9
#: Largest gap tolerance accepted: overlaps up to 5 % of the smaller radius (a soft-particle
#: DEM packing's contacts, say) are read as contacts of rigid disks; beyond that two disks
#: interpenetrate and the packing is not one of touching rigid disks (the paper's model).
MAX_GAP_TOL = 0.05
#: A rattler's or floating disk's gap up to this fraction of the radius is named by `report`
#: as a near miss (a contact lost to rounded coordinates, most likely).
NEAR_GAP = 1e-3


class Overlap(InvalidSystem):
    """Two bodies overlap by more than the gap tolerance; the message names them."""

    def __init__(self, message: str, i: int, j: int, overlap: float):
        super().__init__(message)
        self.i, self.j, self.overlap = i, j, overlap


def _array(name: str, value, shape: tuple, positive: bool = False) -> np.ndarray:
    try:
        a = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidSystem(f"{name} must be an array of numbers") from None
    if a.shape != shape:
        raise InvalidSystem(f"{name} must have shape {shape}, got {a.shape}")
    bad = ~np.isfinite(a)
    if np.any(bad):
        raise InvalidSystem(f"{name} of disk {int(np.argwhere(bad)[0][0])} is not finite")
    if positive and np.any(a <= 0):
        k = int(np.flatnonzero(a <= 0)[0])
        raise InvalidSystem(f"{name} of disk {k} must be > 0, got {a[k]!r}")
    a.setflags(write=False)
    return a


def _wall(name: str, value) -> float | None:
    if value is None:
        return None
    v = float(value)
    if not np.isfinite(v):
        raise InvalidSystem(f"{name} must be a finite abscissa or None, got {value!r}")
    return v


def packing(x, r, m=None, I=None, *, left: float | None = None,  # noqa: E741 (the paper's I)
            right: float | None = None, gap_tol: float = GAP_TOL) -> Lattice:
    """The Lattice of disks x (p, 2), r (p,) [, m, I (p,)] in the box (module docstring).

    Raises Overlap for two bodies overlapping beyond gap_tol, InvalidSystem for bad arrays.
    """
    r = np.array(r, dtype=float).reshape(-1) if np.ndim(r) else r
    p = np.size(r)
    if p == 0:
        raise InvalidSystem("a packing needs at least one disk")
    if p > MAX_DISKS:
        raise InvalidSystem(f"a packing of {p} disks is larger than the {MAX_DISKS} disks "
                            "this toolkit builds")
    r = _array("radius", r, (p,), positive=True)
    x = _array("centre", x, (p, 2))
    m = None if m is None else _array("mass", m, (p,), positive=True)
    I = None if I is None else _array("moment of inertia", I, (p,), positive=True)  # noqa: E741
    left, right = _wall("left", left), _wall("right", right)
    if left is not None and right is not None and right <= left:
        raise InvalidSystem(f"the right wall ({right}) must be right of the left wall ({left})")
    tol = float(gap_tol)
    if not (np.isfinite(tol) and 0 <= tol <= MAX_GAP_TOL):
        raise InvalidSystem(f"gap_tol must be in [0, {MAX_GAP_TOL:g}] (a fraction of the radius; "
                            f"more is interpenetration, not rigid disks in contact), got "
                            f"{gap_tol!r}")
    ci, cj, normals, kinds = _contacts(x, r, left, right, tol)
    n = np.array(normals, dtype=float).reshape(-1, 2)
    t = np.column_stack([-n[:, 1], n[:, 0]])
    rmean = float(np.mean(r))
    lo = left if left is not None else float(np.min(x[:, 0] - r))
    hi = right if right is not None else float(np.max(x[:, 0] + r))
    lx = max(1, int(round((hi - lo) / (2 * rmean))))
    ly = max(1, int(round(float(np.max(x[:, 1] + r)) / (2 * rmean))))
    minus = np.full(p, -1)
    return Lattice(
        name="packing", lx=lx, ly=ly, radius=rmean, x=x, row=minus, col=minus.copy(),
        i=np.array(ci, dtype=int), j=np.array(cj, dtype=int), n=n, t=t,
        kind=np.array(kinds, dtype="<U5"), radii=r, masses=m, inertias=I, left=left,
        right=right, gap_tol=tol,
    )


def _contacts(x: np.ndarray, r: np.ndarray, left, right, tol: float):
    """(i, j, n, kind) of every contact: the plane, the walls, then disk pairs (i < j by index
    of the pair list, i the lower disk)."""
    ci, cj, normals, kinds = [], [], [], []
    obstacles = [(PLANE, "plane", x[:, 1] - r, (0.0, -1.0))]
    if left is not None:
        obstacles.append((LEFT_WALL, "left wall", x[:, 0] - r - left, (-1.0, 0.0)))
    if right is not None:
        obstacles.append((RIGHT_WALL, "right wall", right - x[:, 0] - r, (1.0, 0.0)))
    for code, name, gap, normal in obstacles:
        over = gap < -tol * r
        if np.any(over):
            k = int(np.flatnonzero(over)[np.argmin(gap[over])])
            raise Overlap(f"disk {k} overlaps the {name} by {-gap[k]:.3g} (gap tolerance "
                          f"{tol:g} x radius {r[k]:.6g})", k, code, float(-gap[k]))
        kind = "plane" if code == PLANE else "wall"
        for k in np.flatnonzero(np.abs(gap) <= tol * r):
            ci.append(int(k))
            cj.append(code)
            normals.append(normal)
            kinds.append(kind)
    pairs = cKDTree(x).query_pairs(2.0 * float(r.max()) * (1.0 + tol), output_type="ndarray")
    if pairs.size:
        a, b = pairs[:, 0], pairs[:, 1]
        d = x[b] - x[a]
        dist = np.hypot(d[:, 0], d[:, 1])
        gap = dist - r[a] - r[b]
        s = np.minimum(r[a], r[b])
        over = gap < -tol * s
        if np.any(over):
            w = np.flatnonzero(over)[np.argmin(gap[over])]
            i, j = int(a[w]), int(b[w])
            raise Overlap(f"disks {i} and {j} overlap by {-gap[w]:.3g} (gap tolerance "
                          f"{tol:g} x radius {s[w]:.6g})", i, j, float(-gap[w]))
        touch = np.flatnonzero(np.abs(gap) <= tol * s)
        touch = touch[np.lexsort((b[touch], a[touch]))]
        for w in touch:
            i, j, dv = int(a[w]), int(b[w]), d[w]
            if dv[1] < 0 or (dv[1] == 0 and dv[0] < 0):  # i: the lower (or left) disk
                i, j, dv = j, i, -dv
            ci.append(i)
            cj.append(j)
            normals.append(tuple(dv / dist[w]))
            kinds.append("pp")
    return ci, cj, normals, kinds


@dataclass
class PackingReport:
    """rattlers: disks with fewer than two contacts; clusters: the connected components of the
    disks' contact graph (lists of disk indices, largest first); floating: the clusters that
    touch no obstacle (nothing can hold them up)."""

    rattlers: list[int]
    clusters: list[list[int]]
    floating: list[int]  # indices into clusters
    #: (i, j, gap / smaller radius) of rattlers' and floating disks' near misses (_near_misses)
    near: list[tuple[int, int, float]] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"rattlers": self.rattlers, "clusters": len(self.clusters),
                "cluster_sizes": [len(c) for c in self.clusters],
                "floating_clusters": [self.clusters[k] for k in self.floating]}

    def text(self) -> str:
        out = (f"{len(self.rattlers)} rattler(s) (fewer than two contacts), "
               f"{len(self.clusters)} cluster(s)")
        if self.floating:
            out += f", {len(self.floating)} touching no wall or plane"
        if self.near:
            i, j, g = self.near[0]
            other = {PLANE: "the plane", LEFT_WALL: "the left wall",
                     RIGHT_WALL: "the right wall"}.get(j, f"disk {j}")
            e = 10.0 ** (math.floor(math.log10(g)) - 1)  # g rounded up to 2 digits
            out += (f"; {len(self.near)} near miss(es) of these: disk {i} is {g:.2g} x radius "
                    f"from {other}, beyond the gap tolerance (rounded coordinates? --gap-tol "
                    f"{math.ceil(g * (1 + 1e-9) / e) * e:.2g} makes it a contact)")
        return out


def report(lattice: Lattice) -> PackingReport:
    """Rattlers and clusters of a lattice (module docstring)."""
    p = lattice.p
    degree = np.bincount(lattice.i, minlength=p) + np.bincount(lattice.j[lattice.j >= 0],
                                                               minlength=p)
    pp = lattice.j >= 0
    graph = coo_matrix((np.ones(int(pp.sum())), (lattice.i[pp], lattice.j[pp])), shape=(p, p))
    _, labels = connected_components(graph, directed=False)
    grounded = np.zeros(labels.max() + 1, dtype=bool)
    grounded[labels[lattice.i[lattice.j < 0]]] = True
    order = sorted(range(labels.max() + 1), key=lambda k: (-int(np.sum(labels == k)), k))
    clusters = [np.flatnonzero(labels == k).tolist() for k in order]
    floating = [n for n, k in enumerate(order) if not grounded[k]]
    rattlers = np.flatnonzero(degree < 2).tolist()
    loose = sorted(set(rattlers).union(*(clusters[n] for n in floating)))
    return PackingReport(rattlers, clusters, floating, _near_misses(lattice, loose))


def _near_misses(lattice: Lattice, disks: list[int]) -> list[tuple[int, int, float]]:
    """(i, j, g / s) of the near misses of `disks` (rattlers, floating clusters): gaps g > 0
    beyond the contact tolerance but within NEAR_GAP s (s the smaller radius; j a disk or an
    obstacle code), closest first. A coordinate rounded to a few digits turns a contact into
    such a gap: the disk then looks like a rattler, and the pile may have no equilibrium."""
    if not disks or lattice.radii is None:
        return []
    x, r, tol = lattice.x, lattice.radii, lattice.gap_tol
    out = []
    sides = [(PLANE, x[:, 1] - r)]
    if lattice.left is not None:
        sides.append((LEFT_WALL, x[:, 0] - r - lattice.left))
    if lattice.right is not None:
        sides.append((RIGHT_WALL, lattice.right - x[:, 0] - r))
    for k in disks:
        for code, gap in sides:
            if tol * r[k] < gap[k] <= NEAR_GAP * r[k]:
                out.append((k, code, float(gap[k] / r[k])))
        d = np.hypot(*(x - x[k]).T) - r - r[k]
        s = np.minimum(r, r[k])
        for j in np.flatnonzero((d > tol * s) & (d <= NEAR_GAP * s)):
            if j != k:
                out.append((k, int(j), float(d[j] / s[j])))
    return sorted(out, key=lambda m: m[2])


#: The name under which `rigidlcp.models` exports `packing` (the submodule owns the bare name).
make_packing = packing
