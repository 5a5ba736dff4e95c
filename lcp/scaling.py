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
    for _ in range(sweeps):
        S = A * r[:, None] * c[None, :]
        rmax = S.max(axis=1)
        rf = np.where(rmax > 0, _pow2(1.0 / np.sqrt(np.where(rmax > 0, rmax, 1.0))), 1.0)
        r *= rf
        S = A * r[:, None] * c[None, :]
        cmax = S.max(axis=0)
        cf = np.where(cmax > 0, _pow2(1.0 / np.sqrt(np.where(cmax > 0, cmax, 1.0))), 1.0)
        c *= cf
        if np.all(rf == 1.0) and np.all(cf == 1.0):
            break
    qmax = float(np.max(np.abs(q * r)))
    if qmax > 0:
        # A change of unit s of z and w together: R w / s = (R M C)(C^-1 z / s) + R q / s.
        s = float(_pow2(np.array(qmax)))
        r, c = r / s, c * s
    return Equilibration(M=M * r[:, None] * c[None, :], q=q * r, r=r, c=c)
