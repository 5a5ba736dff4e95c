"""Two builds of the C kernels side by side in one process (a script, not a test): the same
answers, bit for bit, and the time of each.

    python benchmarks/ab_builds.py --ref DIR [--sizes 10,30,50,100,200]

DIR holds another build's `_lemke_c*.so` and `_accuracy_c*.so` (e.g. of main: `git worktree
add /tmp/main-build main && cd /tmp/main-build && python setup.py build_ext --inplace`, then
DIR = /tmp/main-build/lcp). Both builds solve the same problems -- random, badly scaled,
nonsymmetric, rank-deficient, integer-degenerate, all-ties; n from 1 to 203 -- and the script
counts the answers that differ in any bit: `solve_eq` (code, pivots, z, basis, bounds, with and
without Ruiz factors), `solve_batch` (z, basic set, codes, pivots) and `assess` (code, berr,
ferr, refined, the polished z) on Lemke's answers, on perturbed ones and on wrong bases. Answers
that differ in `assess`'s forward bound only (a build that reports the comparison-matrix bound
where it certifies, issue 23) are counted apart: that bound must be no smaller than the other
build's and give the same verdict at FERR_TOL and at bench's stated accuracies. Then the
time per call of `solve_eq` and `assess` for each build on M = A A^T + 0.1 I (best of 5, runs
interleaved).
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import sys
import timeit
from functools import partial
from pathlib import Path

import numpy as np

from rigidlcp.bench.report import ACCURACIES
from rigidlcp.lcp import _lemke_c
from rigidlcp.lcp.acceptance import _accuracy_c
from rigidlcp.lcp.acceptance.accuracy import FERR_TOL
from rigidlcp.lcp.acceptance.scaling import ruiz


def load(directory: Path, name: str):
    path = next(directory.glob(f"{name}*.so"), None) or next(directory.glob(f"{name}*.pyd"))
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def problems(rng: np.random.Generator):
    for n in [*range(1, 40), 47, 50, 63, 64, 65, 99, 100, 101, 150, 203]:
        for kind in range(6):
            A = rng.standard_normal((n, n))
            if kind == 0:
                M, q = A @ A.T + 0.1 * np.eye(n), rng.standard_normal(n)
            elif kind == 1:  # integer data, q = -1: ties
                M, q = rng.integers(-2, 3, (n, n)).astype(float) + 3 * np.eye(n), -np.ones(n)
            elif kind == 2:  # rows and columns over eight decades: Ruiz's sweeps
                s = 10.0 ** rng.uniform(-4, 4, n)
                M = (A @ A.T + np.eye(n)) * s[:, None] * s[None, :]
                q = rng.standard_normal(n) * s
            elif kind == 3:  # nonsymmetric, diagonally dominant
                M, q = A + n * np.eye(n), rng.standard_normal(n)
            elif kind == 4:  # rank deficient, zeros in q
                B = A[:, : max(1, n // 2)]
                M, q = B @ B.T, rng.integers(-1, 2, n).astype(float)
            else:  # identical rows and columns
                M, q = np.ones((n, n)) + np.eye(n), -np.ones(n)
            yield n, np.ascontiguousarray(M), np.ascontiguousarray(q)


def compare(ref_lemke, ref_acc) -> tuple[int, int, list[tuple[float, float]]]:
    """(answers compared, answers differing in any bit but `assess`'s forward bound, the
    (other, this) forward bounds of the answers that differ in that bound only)."""
    rng = np.random.default_rng(1)
    count = differ = 0
    ferr: list[tuple[float, float]] = []
    for n, M, q in problems(rng):
        eq = ruiz(M, q)
        for r, c in ((None, None), (eq.r, eq.c)):
            got = []
            for mod in (ref_lemke, _lemke_c):
                z, b = np.empty(n), np.empty(n, dtype=np.intp)
                res = mod.solve_eq(M, q, r, c, None, 1e-10, 1000 + 100 * n, z, b)
                got.append((res, z.tobytes(), b[: res[2]].tobytes()))
            count += 1
            differ += got[0] != got[1]
        k = 4
        Ms = np.ascontiguousarray(np.stack([M + 0.01 * i * np.eye(n) for i in range(k)]))
        qs = np.ascontiguousarray(np.stack([q] * k))
        got = []
        for mod in (ref_lemke, _lemke_c):
            Z, B = np.empty((k, n)), np.empty((k, n), dtype=np.int8)
            codes, piv = np.empty(k, dtype=np.int64), np.empty(k, dtype=np.int64)
            mod.solve_batch(Ms, qs, np.ones(n), 1e-10, 1000 + 100 * n, Z, B, codes, piv, 1)
            got.append((Z[codes == 0].tobytes(), B.tobytes(), codes.tobytes(), piv.tobytes()))
        count += k
        differ += got[0] != got[1]
        z, b = np.empty(n), np.empty(n, dtype=np.intp)
        code, _, m, _ = _lemke_c.solve_eq(M, q, eq.r, eq.c, None, 1e-10, 1000 + 100 * n, z, b)
        for basis in (b[:m].copy(), rng.permutation(b[:m]), np.arange(1 + n // 3)):
            for zz in (z, z * (1 + 1e-7 * rng.standard_normal(n)),
                       np.abs(rng.standard_normal(n))):
                basis = np.ascontiguousarray(basis, dtype=np.int64)
                o1, o2 = np.empty(n), np.empty(n)
                r1 = ref_acc.assess(M, q, zz, basis, o1)
                r2 = _accuracy_c.assess(M, q, zz, basis, o2)
                same = (r1[0] == r2[0] and r1[3] == r2[3]
                        and np.float64(r1[1]).tobytes() == np.float64(r2[1]).tobytes()
                        and (r1[0] != 0 or o1.tobytes() == o2.tobytes()))
                count += 1
                differ += not same
                if same and np.float64(r1[2]).tobytes() != np.float64(r2[2]).tobytes():
                    ferr.append((r1[2], r2[2]))
    return count, differ, ferr


def ferr_report(ferr: list[tuple[float, float]]) -> bool:
    """Print how the forward bounds that differ differ (this build's against the other's):
    each must be no smaller and give the same verdict at FERR_TOL and at every accuracy bench
    states. Returns whether they all do."""
    if not ferr:
        return True
    ref, new = np.array(ferr).T
    smaller = int(np.sum(new < ref))
    verdicts = int(sum(np.sum((ref <= a) != (new <= a)) for a in (FERR_TOL, *ACCURACIES)))
    ratio = new / ref
    print(f"  of which {len(ferr)} differ in the forward bound only: {smaller} smaller than the "
          f"other build's, {verdicts} verdicts changed (at {FERR_TOL:g}, "
          f"{', '.join(f'{a:g}' for a in ACCURACIES)}); this / other {ratio.min():.3g} to "
          f"{ratio.max():.3g} (median {np.median(ratio):.3g}), largest bound {new.max():.3g}")
    return smaller == 0 and verdicts == 0


def timing(sizes, ref_lemke, ref_acc) -> None:
    print(f"{'n':>5} {'m':>4} {'solve_eq ref [us]':>18} {'new [us]':>9} {'new/ref':>8} "
          f"{'assess ref [us]':>16} {'new [us]':>9} {'new/ref':>8}")
    for n in sizes:
        rng = np.random.default_rng([0, n])
        A = rng.standard_normal((n, n))
        M, q = A @ A.T + 0.1 * np.eye(n), rng.standard_normal(n)
        z, b, out = np.empty(n), np.empty(n, dtype=np.intp), np.empty(n)
        code, _, m, _ = _lemke_c.solve_eq(M, q, None, None, None, 1e-10, 1000 + 100 * n, z, b)
        basis = b[:m].copy()
        k = max(5, 100000 // n**2)
        best: dict[str, float] = {}
        args = (M, q, None, None, None, 1e-10, 1000 + 100 * n, z, b)
        calls = (("eq ref", partial(ref_lemke.solve_eq, *args)),
                 ("eq new", partial(_lemke_c.solve_eq, *args)),
                 ("acc ref", partial(ref_acc.assess, M, q, z, basis, out)),
                 ("acc new", partial(_accuracy_c.assess, M, q, z, basis, out)))
        for _ in range(2):  # interleaved
            for key, f in calls:
                t = min(timeit.repeat(f, number=k, repeat=5)) / k * 1e6
                best[key] = min(best.get(key, np.inf), t)
        print(f"{n:>5} {m:>4} {best['eq ref']:>18.1f} {best['eq new']:>9.1f} "
              f"{best['eq new'] / best['eq ref']:>8.2f} {best['acc ref']:>16.1f} "
              f"{best['acc new']:>9.1f} {best['acc new'] / best['acc ref']:>8.2f}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ref", required=True, type=Path, help="directory of the other build's .so")
    ap.add_argument("--sizes", default="10,30,50,100,200")
    args = ap.parse_args(argv)
    ref_lemke, ref_acc = load(args.ref, "_lemke_c"), load(args.ref, "_accuracy_c")
    print(f"this build: {Path(_lemke_c.__file__).parent}; other build: {args.ref}; load "
          f"average {os.getloadavg()[0]:.2f}")
    count, differ, ferr = compare(ref_lemke, ref_acc)
    print(f"{count} answers compared (solve_eq, solve_batch, assess): "
          f"{differ + len(ferr)} differ in a bit")
    bounds_ok = ferr_report(ferr)
    timing([int(s) for s in args.sizes.split(",")], ref_lemke, ref_acc)
    return 1 if differ or not bounds_ok else 0


if __name__ == "__main__":
    sys.exit(main())
