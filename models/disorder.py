"""Regular arrays with size disorder (issue 22.2): seeded radii, contacts exact by construction.

`with_size_disorder(lattice, spread, seed)` redraws the radii of a triangular array (or of a
single row) uniformly in [r (1 - spread), r (1 + spread)] and rebuilds it so that every contact
stays exact: the disks of a triangular array cannot all keep their regular positions once
their radii differ (it is over-constrained), so

* the bottom row lies on the plane, each disk touching the previous one (centres
  2 sqrt(r_k r_(k+1)) apart, the first against the left wall) and the right wall is set
  against the last one: the row touches both walls, as in the arrays;
* each disk of the rows above is dropped at its site's abscissa (scaled to the new width) and
  comes to rest on two supports by the deposition rule of models.deposition (it falls, then
  rolls down to a stable position: disk, wall or plane), row by row, left to right.

No two disks overlap (each is placed touching, never crossing, what is there); `models.packing`
detects the contacts with its gap tolerance and would refuse an overlap naming the pair. With
spread = 0 the triangular array comes back (tests/models/test_disorder.py). A rectangular array
of two rows or more has no such construction (its stacked columns are not stable on two
supports) and is refused by name; `with_vacancies` (models.deposition) removes disks instead.
"""

from __future__ import annotations

import math

import numpy as np

from .deposition import _Pile
from .lattice import InvalidSystem, Lattice
from .packing import GAP_TOL, packing


def with_size_disorder(lattice: Lattice, spread: float, seed: int = 0,
                       gap_tol: float = GAP_TOL) -> Lattice:
    """The array `lattice` (triangular, or any one-row array) with radii uniform in
    [r (1 - spread), r (1 + spread)], 0 <= spread < 1/2, drawn from `seed`; m = r^2,
    I = m r^2 / 2 as in the packing files (module docstring)."""
    if not isinstance(lattice, Lattice) or not lattice.regular:
        raise InvalidSystem("size disorder needs a regular array (models.rectangular or "
                            "models.triangular)")
    if lattice.name == "rect" and lattice.ly > 1:
        raise InvalidSystem("a rectangular array with size disorder has no stable form with "
                            "exact contacts (its columns do not rest on two supports): use a "
                            "triangular array, ly = 1, or models.deposition.deposit")
    try:
        spread = float(spread)
    except (TypeError, ValueError):
        raise InvalidSystem(f"spread must be a number in [0, 0.5), got {spread!r}") from None
    if not 0 <= spread < 0.5:
        raise InvalidSystem(f"spread must be a number in [0, 0.5), got {spread!r}")
    rng = np.random.default_rng(seed)
    r0 = lattice.radius
    r = r0 * (1.0 + spread * rng.uniform(-1.0, 1.0, lattice.p))
    order = np.lexsort((lattice.x[:, 0], lattice.row))  # row by row, left to right
    bottom = order[lattice.row[order] == 0]
    left = 0.0 if lattice.left is None else float(lattice.left)
    xs = np.zeros((lattice.p, 2))
    x = left + r[bottom[0]]
    for a, b in zip(np.r_[-1, bottom[:-1]], bottom):
        if a >= 0:
            x += 2.0 * math.sqrt(r[a] * r[b])  # two disks on the plane, touching
        xs[b] = (x, r[b])
    width = x + r[bottom[-1]] - left
    pile = _Pile(width, float(r.max()), lattice.p, rng)
    scale = width / lattice.width
    for k in order:  # _Pile works in [0, width]: shift by `left` at the end
        x0 = min(max((lattice.x[k, 0] - left) * scale, r[k]), width - r[k])  # in the box
        centre = xs[k] - (left, 0.0) if lattice.row[k] == 0 else pile.place(float(r[k]),
                                                                             float(x0))
        pile.add(float(r[k]), centre)
        xs[k] = centre
    xs[:, 0] += left
    m = r**2
    return packing(xs, r, m, 0.5 * m * r**2, left=left, right=left + width, gap_tol=gap_tol)


__all__ = ["with_size_disorder"]
