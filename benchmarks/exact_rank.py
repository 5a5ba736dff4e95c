"""Exact ranks of the contact matrix (Eq. 2.15) over Q(sqrt 3), on the Eq. (3.3)/(3.4) table:
the toolkit's way (verify/nullspace/qsqrt3.py) against sympy.

    python benchmarks/exact_rank.py [--lx 2:8] [--ly 1:5]

* qsqrt3 — `qsqrt3.exact_rank`: python-flint's `fmpq_mat.rank()` on the regular representation
  of Q(sqrt 3), a + b sqrt 3 -> [[a, 3b], [b, a]] (an injective ring map into 2x2 rational
  matrices: the rational rank of the 2m x 2n block matrix is twice the rank over Q(sqrt 3));
* sympy — `DomainMatrix` over the algebraic field QQ<sqrt(3)> (`rank()`): an independent
  check of the embedding (same ranks), and the slower library.

Until commit 2a976d6 qsqrt3 eliminated by hand (sparse Gauss-Jordan on pairs of Fractions);
that version's numbers are in docs/architecture.md.

Every lattice is done in both of the paper's states (normal: all T and sliding; tangential: all
T and non-sliding). Prints one row per library: cases, agreement with qsqrt3, total seconds.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from rigidlcp import models
from rigidlcp.verify.nullspace import qsqrt3 as q3
from rigidlcp.verify.nullspace.contact import paper_states


def _range(text: str) -> range:
    a, b = (int(x) for x in text.split(":"))
    return range(a, b + 1)


def rank_sympy(rows, ncols: int) -> int:
    from sympy import QQ, sqrt
    from sympy.polys.matrices import DomainMatrix

    K = QQ.algebraic_field(sqrt(3))
    r3 = K.from_sympy(sqrt(3))
    dense = [[K.zero] * ncols for _ in rows]
    for i, row in enumerate(rows):
        for j, v in row.items():
            dense[i][j] = K.convert(QQ(v.a.numerator, v.a.denominator)) + K.convert(
                QQ(v.b.numerator, v.b.denominator)) * r3
    return DomainMatrix(dense, (len(rows), ncols), K).rank()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lx", type=_range, default=_range("2:8"))
    ap.add_argument("--ly", type=_range, default=_range("1:5"))
    args = ap.parse_args()
    cases = []
    for lattice in ("rect", "tri"):
        for lx in args.lx:
            for ly in args.ly:
                system = models.make_system(lattice, lx, ly, mu_pp=0.3, mu_plane=0.3,
                                            mu_wall=0.3)
                for kind in ("normal", "tangential"):
                    rows = q3.exact_contact_matrix(system, *paper_states(system, kind))
                    cases.append((f"{lattice} {lx}x{ly} {kind}", rows, 2 * system.c))
    methods = {"qsqrt3": lambda rows, n: q3.exact_rank(rows), "sympy": rank_sympy}
    ranks, seconds = {}, {}
    for name, func in methods.items():
        t0 = time.perf_counter()
        ranks[name] = [func(rows, n) for _, rows, n in cases]
        seconds[name] = time.perf_counter() - t0
    print(f"python benchmarks/exact_rank.py  ({len(cases)} contact matrices, "
          f"largest {max(n for *_, n in cases)} columns)")
    print(f"{'library':<8} {'agree':>7} {'seconds':>9} {'per matrix (ms)':>16}")
    for name in methods:
        agree = int(np.sum(np.array(ranks[name]) == np.array(ranks["qsqrt3"])))
        print(f"{name:<8} {agree:>3}/{len(cases):<3} {seconds[name]:>9.2f} "
              f"{1e3 * seconds[name] / len(cases):>16.1f}")


if __name__ == "__main__":
    main()
