"""Ruiz equilibration of an LCP: the same problem in units where every row and column of M
has largest entry ~1.

For positive diagonal R (rows) and C (columns), z = C z~ solves w = M z + q, 0 <= z perp w >= 0
iff z~ solves

    w~ = M~ z~ + q~,   M~ = R M C,   q~ = R q,   w~ = R w,                              (1)

because positive scalings keep signs and products z_i w_i = 0. Ruiz's iteration (D. Ruiz, "A
scaling algorithm to equilibrate both rows and columns norms in matrices", RAL-TR-2001-034)
divides each row and column by the square root of its largest |entry| until all are within a
factor ~2 of 1; it converges from any positive scaling of M to nearly the same M~, which is
what makes the solvers' answers independent of the user's units. The factors are rounded to
powers of 2, so that (1) is computed without rounding error. q~ is then divided by a power of 2
near |q~|_inf (a change of unit of z and w together).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Ruiz sweeps (each halves the log-imbalance of rows and columns; 1e16 -> ~1 in 8 sweeps).
SWEEPS = 12
#: A matrix whose every row and column maximum is within this factor of the largest entry is
#: left as it is (only q's unit is changed): the sweeps cost O(n^2) each, for nothing.
BALANCED = 16.0


@dataclass(frozen=True)
class Equilibration:
    """M~ = diag(r) M diag(c), q~ = diag(r) q (Eq. 1); z = c * z~, w = w~ / r."""

    M: np.ndarray
    q: np.ndarray
    r: np.ndarray  # row factors (powers of 2), including the unit change of q
    c: np.ndarray  # column factors (powers of 2), including the unit change of q

    def z_back(self, z_tilde: np.ndarray) -> np.ndarray:
        with np.errstate(over="ignore"):  # a diverged z~ stays visible (inf), and is rejected
            return self.c * z_tilde

    def z_to(self, z: np.ndarray) -> np.ndarray:
        return z / self.c

    def w_back(self, w_tilde: np.ndarray) -> np.ndarray:
        return w_tilde / self.r


def _pow2(x: np.ndarray) -> np.ndarray:
    """The power of 2 nearest to x > 0 (in the log sense)."""
    return np.exp2(np.round(np.log2(x)))


def ruiz(M: np.ndarray, q: np.ndarray, sweeps: int = SWEEPS) -> Equilibration:
    """Equilibrate the LCP (M, q) by Ruiz's iteration with power-of-2 factors (see module doc).

    A zero row or column of M keeps the factor 1. Afterwards r is divided and c multiplied by a
    power of 2 near |R q|_inf (a common change of unit of z and w), so that |q~|_inf ~ 1.
    """
    n = q.size
    r, c = np.ones(n), np.ones(n)
    A = np.abs(M)
    rmax, cmax = A.max(axis=1), A.max(axis=0)
    top = float(rmax.max())
    if top > 0 and rmax.min() >= top / BALANCED and cmax.min() >= top / BALANCED:
        sweeps = 0  # already balanced (e.g. every event LCP): Ruiz would change nothing useful
    for sweep in range(sweeps):
        rmax = (A * c).max(axis=1) * r
        rf = _pow2(1.0 / np.sqrt(np.where(rmax > 0, rmax, 1.0)))
        r *= rf
        cmax = (A * r[:, None]).max(axis=0) * c
        cf = _pow2(1.0 / np.sqrt(np.where(cmax > 0, cmax, 1.0)))
        c *= cf
        # stop when no factor moves, or (after a few sweeps) none by more than a factor 2:
        # every row and column maximum is then within [1/4, 4], which is all that is needed
        moved = max(float(np.abs(np.log2(rf)).max()), float(np.abs(np.log2(cf)).max()))
        if moved == 0 or (sweep >= 3 and moved <= 1):
            break
    qmax = float(np.max(np.abs(q * r)))
    if qmax > 0:
        # A change of unit s of z and w together: R w / s = (R M C)(C^-1 z / s) + R q / s.
        s = float(_pow2(np.array(qmax)))
        r, c = r / s, c * s
    with np.errstate(over="ignore"):
        Mt = M * r[:, None] * c[None, :]
    if not np.isfinite(Mt).all():  # M r overflowed before c brought it back (|q| << |M|):
        Mt = M * (r[:, None] * c[None, :])  # the product of the factors first, still exact
    return Equilibration(M=Mt, q=q * r, r=r, c=c)
