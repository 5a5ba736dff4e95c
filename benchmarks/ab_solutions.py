"""Two builds' whole answers compared, bit for bit (a script, not a test): `lcp.solve` and
`lcp.solve_many` on the same problems in two checkouts, every field of every Solution.

benchmarks/ab_builds.py compares the C kernels of two builds in one process; this compares
what a user gets -- status, method, pivots, z, w, residuals, backward error, forward bound,
basis, message, the scalar entries of info -- from the natural call `lcp.solve(lcp.LCP(M, q))`
and from `lcp.solve_many`, so that a change of the Python around the kernels is covered too.
Each checkout runs `dump` in its own environment (e.g. main in a `git worktree` with its own
venv), then `compare` reads both files:

    python benchmarks/ab_solutions.py dump OUT.pkl        (in each checkout)
    python benchmarks/ab_solutions.py compare A.pkl B.pkl

(Answers that differ in the forward bound only are counted apart: `compare`'s docstring.)

The problems: Siconos's LCP files (/work/shared/data/siconos/lcp, when present) and, for three
seeds, n = 1..30, 40, 50, 64, 80, 100, 130 of eight kinds -- A A^T + 0.1 I, nonsymmetric
diagonally dominant, rows and columns scaled over 12 decades (not balanced: Ruiz's sweeps),
rank-deficient PSD, integer-degenerate, ill-conditioned (singular values over 12 decades),
general nonsymmetric (rays), q mixing magnitudes 1e-10 .. 1e2.
"""

from __future__ import annotations

import glob
import pickle
import sys

import numpy as np

from rigidlcp import lcp

SICONOS_LCP = "/work/shared/data/siconos/lcp/*.dat"


def random_problems(seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(seed)
    out = []
    for n in [*range(1, 31), 40, 50, 64, 80, 100, 130]:
        for kind in range(8):
            A = rng.standard_normal((n, n))
            q = None
            if kind == 0:
                M = A @ A.T + 0.1 * np.eye(n)
            elif kind == 1:
                M = A + n * np.eye(n)
            elif kind == 2:
                s = 10.0 ** rng.uniform(-6, 6, n)
                M = (s[:, None] * (A @ A.T + 0.1 * np.eye(n))) * s[None, :]
            elif kind == 3:
                B = A[:, : max(1, n // 2)]
                M = B @ B.T
            elif kind == 4:
                M = rng.integers(-2, 3, (n, n)).astype(float)
                M = M @ M.T + np.eye(n)
                q = rng.integers(-2, 3, n).astype(float)
            elif kind == 5:
                U, _ = np.linalg.qr(A)
                M = U @ np.diag(10.0 ** -rng.uniform(0, 12, n)) @ U.T
            elif kind == 6:
                M = A
            else:
                M = A @ A.T + 0.1 * np.eye(n)
                q = rng.standard_normal(n) * 10.0 ** rng.integers(-10, 3, n)
            out.append((M, rng.standard_normal(n) if q is None else q))
    return out


def problems() -> list[tuple[np.ndarray, np.ndarray]]:
    out = []
    for path in sorted(glob.glob(SICONOS_LCP)):
        P = lcp.load(path)
        out.append((P.M, P.q))
    for seed in (23, 24, 25):
        out.extend(random_problems(seed))
    return out


def key(s) -> tuple:
    def raw(x):
        return None if x is None else np.asarray(x).tobytes()

    return (s.status, s.method, s.iterations, raw(s.z), raw(s.w), repr(s.residual),
            repr(s.scaled_residual), repr(s.backward_error), repr(s.forward_error),
            None if s.basis is None else np.asarray(s.basis).tolist(), s.message,
            sorted((k, repr(v)) for k, v in s.info.items()
                   if not isinstance(v, (np.ndarray, dict, list))))


def dump(path: str) -> None:
    ps = problems()
    single = []
    for M, q in ps:
        try:
            single.append(key(lcp.solve(lcp.LCP(M, q))))
        except Exception as exc:  # noqa: BLE001 - compared between the builds
            single.append(("raised", type(exc).__name__, str(exc)))
    many = [key(s) for s in lcp.solve_many([lcp.LCP(M, q) for M, q in ps])]
    with open(path, "wb") as fh:
        pickle.dump({"single": single, "many": many}, fh)
    print(f"{len(ps)} problems; {sum(k[0] == 'solved' for k in single)} solved")


_FERR = 8  # the forward bound's place in `key`


def _without_ferr(k) -> tuple:
    """`key` less the forward bound (also as an info entry)."""
    if k[0] == "raised":
        return k
    info = [(name, v) for name, v in k[-1] if name != "forward_error"]
    return (*k[:_FERR], *k[_FERR + 1:-1], info)


def compare(a: str, b: str) -> int:
    """Count the answers that differ; those that differ in the forward bound only (B reporting
    the comparison-matrix bound where A formed |K^-1|, issue 23) are counted apart, and must
    have B's bound no smaller than A's, with the same verdict at FERR_TOL and at bench's
    accuracies."""
    from rigidlcp.bench.report import ACCURACIES
    from rigidlcp.lcp.acceptance.accuracy import FERR_TOL

    with open(a, "rb") as fa, open(b, "rb") as fb:
        A, B = pickle.load(fa), pickle.load(fb)
    differ = bad_bounds = 0
    for way in A:
        bad = [i for i, (x, y) in enumerate(zip(A[way], B[way])) if x != y]
        ferr_only = [i for i in bad if _without_ferr(A[way][i]) == _without_ferr(B[way][i])]
        bad = [i for i in bad if i not in ferr_only]
        bad += list(range(min(len(A[way]), len(B[way])), max(len(A[way]), len(B[way]))))
        differ += len(bad)
        print(f"{way}: {len(A[way])} answers, {len(bad) + len(ferr_only)} differ in a field or "
              f"a bit" + (f" (first: {bad[:10]})" if bad else ""))
        if ferr_only:
            fa_ = np.array([float(A[way][i][_FERR]) for i in ferr_only])
            fb_ = np.array([float(B[way][i][_FERR]) for i in ferr_only])
            smaller = int(np.sum(fb_ < fa_))
            verdicts = int(sum(np.sum((fa_ <= t) != (fb_ <= t)) for t in (FERR_TOL, *ACCURACIES)))
            bad_bounds += smaller + verdicts
            print(f"  {len(ferr_only)} in the forward bound only: {smaller} smaller in "
                  f"{b} than in {a}, {verdicts} verdicts changed; ratio {np.min(fb_ / fa_):.3g} "
                  f"to {np.max(fb_ / fa_):.3g}, largest {fb_.max():.3g}")
    return 1 if differ or bad_bounds else 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "dump":
        dump(sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        sys.exit(compare(sys.argv[2], sys.argv[3]))
    else:
        sys.exit(__doc__)
