"""Named LCP problem sets for solver comparisons (issue 6), in the spirit of qpbenchmark's sets.

A set is a name and either a seeded generator or a folder of problem files. Every problem is an
`lcp.LCP` whose ``meta`` says which set it belongs to, the class it was built to be ("P-matrix",
"symmetric PSD", ...) and what a solver should answer: ``meta["expected"]`` is "solution" or
"infeasible".

Generated sets (numpy, ``default_rng([seed, n, index])``: the same seed gives the same problems):

* ``random-p``: P-matrices (every principal minor positive, hence one solution for every q),
  from four constructions (as verify.strategies.p_matrices): B B' + c I + (K - K') (positive
  definite, non-symmetric), strictly diagonally dominant with a positive diagonal, a permuted
  lower-triangular matrix with a positive diagonal (P but usually not positive definite), and
  D1 M D2 scalings of those; q ~ N(0, 1). (The triangular kind has off-diagonal entries in
  [-3, 3], so that its symmetric part is usually indefinite.)
* ``random-psd``: symmetric positive definite B B' + c I, c in [0.1, 1]; q ~ N(0, 1).
* ``singular-psd``: symmetric PSD B B' of rank r < n (as the Delassus operator of a
  hyperstatic network), q from a planted solution (a singular PSD M with a random q is
  usually infeasible).
* ``degenerate``: planted solutions with degenerate pairs (z_i = w_i = 0), zeros in q and
  duplicated rows and columns (as verify.strategies.degenerate_lcps): singular, not P.
* ``murty``: Murty's example (Murty 1978): M lower triangular with 1 on the diagonal and 2
  below, q_i = -(2^n + 2^(n-1) + ... + 2^(n-i+1)); a P-matrix on which Lemke's method makes
  2^n pivots.
* ``infeasible``: copositive-plus M = S + K (S symmetric PSD, K skew) with a non-negative
  y != 0 in the kernels of S and K, and q with q'y < 0: then M'y = 0, so y is a Farkas
  certificate that {z >= 0 : M z + q >= 0} is empty, and the LCP has no solution.
* ``events-rect``, ``events-tri``: event LCPs of real runs (models.simulate with dump_dir,
  as ``rigidlcp simulate --dump-problems``) of rectangular and triangular arrays of several
  sizes, with Fig. 9's parameters; generated once into a cache folder.

Folders: any directory (``--set path/to/dir``) is a set of its ``*.npz`` files (`lcp.load`)
and ``*.dat`` files (Siconos's numerics test-suite format, rigidlcp.lcp.io.siconos).
"""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rigidlcp import lcp
from rigidlcp.lcp import LCP

P_KINDS = ("positive-definite", "diagonally-dominant", "triangular", "scaled")


# --------------------------------------------------------------------------------------------
# generators (each returns an LCP of the promised class; the tests check the classes)
# --------------------------------------------------------------------------------------------

def random_p_matrix(n: int, rng: np.random.Generator, kind: str = "positive-definite"
                    ) -> np.ndarray:
    """An n x n P-matrix by one of P_KINDS (see the module doc for why each is P)."""
    if kind == "positive-definite":
        B = rng.uniform(-1, 1, (n, n))
        K = rng.uniform(-1, 1, (n, n)) * rng.uniform(0, 2)
        return B @ B.T + rng.uniform(0.1, 1.0) * np.eye(n) + (K - K.T)
    if kind == "diagonally-dominant":
        M = rng.uniform(-1, 1, (n, n))
        np.fill_diagonal(M, 0.0)
        np.fill_diagonal(M, np.abs(M).sum(axis=1) + rng.uniform(0.1, 1.0, n))
        return M
    if kind == "triangular":
        L = np.tril(rng.uniform(-3, 3, (n, n)), -1) + np.diag(rng.uniform(1.0, 2.0, n))
        perm = rng.permutation(n)
        return L[np.ix_(perm, perm)]
    if kind == "scaled":
        base = random_p_matrix(n, rng, P_KINDS[int(rng.integers(0, 3))])
        return rng.uniform(0.5, 2.0, n)[:, None] * base * rng.uniform(0.5, 2.0, n)[None, :]
    raise ValueError(f"kind must be one of {P_KINDS}, got {kind!r}")


def random_psd(n: int, rng: np.random.Generator, rank: int | None = None) -> np.ndarray:
    """Symmetric PSD: B B' + c I (rank None: positive definite, c in [0.1, 1]) or B B' with B
    n x rank (rank < n: singular). Symmetrized exactly."""
    if rank is None:
        B = rng.uniform(-1, 1, (n, n))
        M = B @ B.T + rng.uniform(0.1, 1.0) * np.eye(n)
    else:
        if not 0 <= rank < n:
            raise ValueError(f"a singular PSD matrix needs 0 <= rank < n = {n}, got {rank}")
        B = rng.uniform(-1, 1, (n, rank))
        M = B @ B.T
    return 0.5 * (M + M.T)


def planted(M: np.ndarray, rng: np.random.Generator, degenerate: float = 0.0
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(z, w, q = w - M z) with z, w >= 0 complementary: z solves LCP(M, q). Each pair is
    z_i > 0, w_i > 0, or (with probability `degenerate`, and at least once when it is > 0)
    z_i = w_i = 0; values in [0.1, 1]."""
    n = M.shape[0]
    u = rng.uniform(size=n)
    values = rng.uniform(0.1, 1.0, n)
    zero = u < degenerate
    pos_z = ~zero & (u < degenerate + (1 - degenerate) / 2)
    if degenerate > 0 and not zero.any():  # promise at least one degenerate pair
        zero[int(rng.integers(0, n))] = True
        pos_z &= ~zero
    z = np.where(pos_z, values, 0.0)
    w = np.where(~zero & ~pos_z, values, 0.0)
    return z, w, w - M @ z


def degenerate_lcp(n: int, rng: np.random.Generator, duplicates: int = 2) -> LCP:
    """A solvable degenerate LCP of size n: a planted solution with degenerate pairs, zeros in
    q and `duplicates` duplicated indices (rows *and* columns repeat), symmetrically permuted.
    meta: planted_z, duplicated (index pairs), base ("p" or "psd")."""
    k = min(duplicates, n - 1)
    n0 = n - k
    base = "p" if rng.uniform() < 0.5 else "psd"
    if base == "p":
        M0 = random_p_matrix(n0, rng, P_KINDS[int(rng.integers(0, 4))])
    else:
        M0 = random_psd(n0, rng, rank=int(rng.integers(0, n0)) if n0 > 1 else None)
    z0, w0, q0 = planted(M0, rng, degenerate=0.3)
    # q_i = 0 where z_i = 0 < w_i keeps w_i = (M z0)_i >= 0 (degenerate pairs are left alone)
    can = np.flatnonzero((z0 == 0) & (w0 > 0) & (M0 @ z0 >= 0))
    if can.size:
        q0[rng.choice(can, size=max(1, can.size // 2), replace=False)] = 0.0
    copies = rng.integers(0, n0, k)
    E = np.vstack([np.eye(n0), np.eye(n0)[copies]])
    M, q = E @ M0 @ E.T, E @ q0
    z = np.concatenate([z0, np.zeros(k)])
    perm = rng.permutation(n)
    inv = np.argsort(perm)
    pairs = [(int(inv[j]), int(inv[n0 + i])) for i, j in enumerate(copies)]
    return LCP(M[np.ix_(perm, perm)], q[perm],
               meta={"planted_z": z[perm].tolist(), "duplicated": pairs, "base": base})


def murty_lcp(n: int) -> LCP:
    """Murty's exponential example: L lower triangular (1 on, 2 below the diagonal),
    q_i = -(2^n + ... + 2^(n-i+1)), i = 1..n."""
    M = np.tril(2.0 * np.ones((n, n)), -1) + np.eye(n)
    q = -np.cumsum([2.0 ** (n - k) for k in range(n)])
    return LCP(M, q)


def infeasible_lcp(n: int, rng: np.random.Generator) -> LCP:
    """A copositive-plus LCP with no solution, with its Farkas certificate in meta["farkas_y"].

    Integer data, so that the certificate holds exactly in the stored doubles: y >= 0 integer
    (a random support, one entry 1), G (k x n) integer with G y = 0 (each row a combination of
    y_j e_i - y_i e_j); S = G^T G (symmetric PSD, S y = 0) and K = G^T T G with T skew
    (K y = 0); M = S + K is copositive-plus (M + M^T = 2 S is PSD) and M^T y = 0 exactly. q is
    integer with q^T y = -d, d >= 1. Then y^T (M z + q) = q^T y < 0 for every z, so no z >= 0
    has M z + q >= 0, and `lcp.farkas`'s exact check proves it. (Built in floating point,
    M^T y = 0 held only to rounding, and such data can be a P-matrix with a solution of size
    ~1e16: three of the six default problems were.)
    """
    if n < 1:
        raise ValueError("n must be >= 1")
    y = np.zeros(n, dtype=np.int64)
    support = rng.choice(n, size=int(rng.integers(1, n + 1)), replace=False)
    y[support] = rng.integers(1, 4, support.size)
    s = int(support[0])
    y[s] = 1
    k = max(1, n - 1)
    G = np.zeros((k, n), dtype=np.int64)
    for row in G:
        for i in rng.choice(n, size=min(n, 3), replace=False):
            if i != s:  # (y_i e_s - y_s e_i) . y = y_i y_s - y_s y_i = 0
                c = int(rng.integers(-2, 3))
                row[s] += c * y[i]
                row[i] -= c * y[s]
    T = rng.integers(-2, 3, (k, k))
    T = T - T.T
    M = G.T @ G + G.T @ T @ G
    q = rng.integers(-3, 4, n)
    q[s] -= int(q @ y) + int(rng.integers(1, 4))
    assert not (M.T @ y).any() and q @ y < 0
    return LCP(M.astype(float), q.astype(float), meta={"farkas_y": y.astype(float).tolist()})


# --------------------------------------------------------------------------------------------
# the named sets
# --------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class SetInfo:
    """A named problem set: what it promises and how it is built."""

    name: str
    problem_class: str
    expected: str  # "solution" or "infeasible"
    description: str
    build: Callable[..., list[LCP]]


DEFAULT_SIZES = (4, 8, 16, 32, 64)
MURTY_SIZES = (4, 6, 8, 10, 12, 14, 16)
#: Event sets: (lattice, lx, ly) of the runs, and the events kept per run (evenly spaced).
EVENT_SIZES = {"rect": ((4, 3), (6, 4), (10, 4)), "tri": ((4, 3), (6, 4), (10, 4))}
EVENTS_PER_RUN = 8
#: Fig. 9's parameters (mu_pp, mu_plane, mu_wall, gamma/g) and the run's seed.
EVENT_SYSTEM = {"mu_pp": 0.1, "mu_plane": 0.2, "mu_wall": 0.0, "gamma": 0.16}
EVENT_RUN = {"seed": 1, "max_events": 300}


def _seeded(name: str, cls: str, make: Callable[[int, np.random.Generator, int], LCP],
            sizes: Iterable[int], per_size: int, seed: int, expected: str = "solution"
            ) -> list[LCP]:
    out = []
    for n in sizes:
        for k in range(per_size):
            rng = np.random.default_rng([seed, n, k])
            p = make(n, rng, len(out))  # the running index: constructions cycle through it
            meta = {**p.meta, "set": name, "class": cls, "expected": expected, "n": n,
                    "index": k, "seed": seed}
            out.append(LCP(p.M, p.q, name=f"{name}/n{n}-{k}", meta=meta))
    return out


def _random_p(seed: int = 0, sizes=DEFAULT_SIZES, per_size: int = 2, **_) -> list[LCP]:
    def make(n, rng, j):
        kind = P_KINDS[j % len(P_KINDS)]
        return LCP(random_p_matrix(n, rng, kind), rng.standard_normal(n), meta={"kind": kind})
    return _seeded("random-p", "P-matrix", make, sizes, per_size, seed)


def _random_psd(seed: int = 0, sizes=DEFAULT_SIZES, per_size: int = 2, **_) -> list[LCP]:
    def make(n, rng, k):
        return LCP(random_psd(n, rng), rng.standard_normal(n))
    return _seeded("random-psd", "symmetric positive definite", make, sizes, per_size, seed)


def _singular_psd(seed: int = 0, sizes=DEFAULT_SIZES, per_size: int = 2, **_) -> list[LCP]:
    def make(n, rng, j):
        rank = max(0, n // 2 - j % 2) if n > 1 else 0
        M = random_psd(n, rng, rank=rank)
        z, _, q = planted(M, rng)
        return LCP(M, q, meta={"rank": rank, "planted_z": z.tolist()})
    return _seeded("singular-psd", "singular symmetric PSD", make, sizes, per_size, seed)


def _degenerate(seed: int = 0, sizes=DEFAULT_SIZES, per_size: int = 2, **_) -> list[LCP]:
    def make(n, rng, k):
        return degenerate_lcp(n, rng, duplicates=max(1, n // 8))
    return _seeded("degenerate", "degenerate", make, [s for s in sizes if s >= 2], per_size,
                   seed)


def _murty(sizes=MURTY_SIZES, **_) -> list[LCP]:
    return _seeded("murty", "Murty's example (P-matrix)", lambda n, rng, k: murty_lcp(n),
                   sizes, 1, 0)


def _infeasible(seed: int = 0, sizes=DEFAULT_SIZES, per_size: int = 2, **_) -> list[LCP]:
    return _seeded("infeasible", "copositive-plus, infeasible",
                   lambda n, rng, k: infeasible_lcp(n, rng), sizes, per_size, seed,
                   expected="infeasible")


def default_cache_dir() -> Path:
    """$RIGIDLCP_CACHE, else ~/.cache/rigidlcp: where harvested event problems are kept."""
    root = os.environ.get("RIGIDLCP_CACHE") or Path.home() / ".cache" / "rigidlcp"
    return Path(root) / "problem_sets"


def harvest_events(lattice: str, lx: int, ly: int, folder: str | os.PathLike, *,
                   seed: int = EVENT_RUN["seed"], max_events: int = EVENT_RUN["max_events"],
                   method: str = "lemke") -> Path:
    """Run models.simulate with dump_dir=folder (Fig. 9's parameters) unless the folder already
    holds a complete harvest of the same run; returns the folder. A file run.json records the
    run (system, status, events) and marks the harvest complete."""
    from rigidlcp import models

    folder = Path(folder)
    params = {"lattice": lattice, "lx": lx, "ly": ly, **EVENT_SYSTEM, "seed": seed,
              "max_events": max_events, "method": method}
    marker = folder / "run.json"
    if marker.exists():
        done = json.loads(marker.read_text())
        if done.get("params") == params:
            return folder
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    system = models.System(models.make_lattice(lattice, lx, ly), **EVENT_SYSTEM)
    run = models.simulate(system, seed=seed, method=method, max_events=max_events,
                          dump_dir=str(folder))
    marker.write_text(json.dumps({"params": params, "status": run.status,
                                  "message": run.message, "events": run.n_events,
                                  "p": system.p, "c": system.c}, indent=1))
    return folder


def _events(lattice: str, seed: int = 0, sizes=None, per_run: int = EVENTS_PER_RUN,
            cache_dir=None, **_) -> list[LCP]:
    # `seed` of the set is not the run's seed: harvested runs are fixed (EVENT_RUN), so that
    # the cache is shared; it only matters for generated sets.
    name = f"events-{lattice}"
    root = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    out = []
    for lx, ly in sizes or EVENT_SIZES[lattice]:
        folder = harvest_events(lattice, lx, ly, root / name / f"{lattice}{lx}x{ly}")
        run = json.loads((folder / "run.json").read_text())
        files = sorted(folder.glob("event_*.npz"))
        keep = np.unique(np.linspace(0, len(files) - 1, min(per_run, len(files))).round()
                         .astype(int)) if files else []
        for i in keep:
            p = lcp.load(files[i])
            meta = {**p.meta, "set": name, "class": "event LCP", "expected": "solution",
                    "lattice": lattice, "lx": lx, "ly": ly, "p": run["p"],
                    "contacts": run["c"], "file": str(files[i])}
            out.append(LCP(p.M, p.q, name=f"{name}/{lattice}{lx}x{ly}/{files[i].stem}",
                           meta=meta))
    return out


SETS: dict[str, SetInfo] = {s.name: s for s in (
    SetInfo("random-p", "P-matrix", "solution",
            "P-matrices of four constructions, q ~ N(0, 1); n = 4..64", _random_p),
    SetInfo("random-psd", "symmetric positive definite", "solution",
            "B B' + c I, q ~ N(0, 1); n = 4..64", _random_psd),
    SetInfo("singular-psd", "singular symmetric PSD", "solution",
            "B B' of rank < n with a planted solution; n = 4..64", _singular_psd),
    SetInfo("degenerate", "degenerate", "solution",
            "planted degenerate solutions, zeros in q, duplicated rows/columns; n = 4..64",
            _degenerate),
    SetInfo("murty", "Murty's example (P-matrix)", "solution",
            "Murty (1978): 2^n Lemke pivots; n = 4..16", _murty),
    SetInfo("infeasible", "copositive-plus, infeasible", "infeasible",
            "S + K (PSD + skew) with a Farkas certificate y >= 0; n = 4..64", _infeasible),
    SetInfo("events-rect", "event LCP", "solution",
            "events of rectangular arrays 4x3, 6x4, 10x4 (Fig. 9 parameters), 8 per run",
            lambda **kw: _events("rect", **kw)),
    SetInfo("events-tri", "event LCP", "solution",
            "events of triangular arrays 4x3, 6x4, 10x4 (Fig. 9 parameters), 8 per run",
            lambda **kw: _events("tri", **kw)),
)}


def list_sets() -> list[SetInfo]:
    """The named sets (a folder path is also a set, see `get_set`)."""
    return list(SETS.values())


def get_set(spec: str, *, seed: int = 0, cache_dir: str | os.PathLike | None = None,
            **params) -> list[LCP]:
    """The problems of a named set or of a folder.

    spec: a name of `list_sets()`, or a directory of *.npz / *.dat files. seed: the generators'
    seed. cache_dir: where event sets are harvested (default `default_cache_dir()`). params go
    to the generator (sizes, per_size, per_run).
    """
    if spec in SETS:
        return SETS[spec].build(seed=seed, cache_dir=cache_dir, **params)
    path = Path(spec)
    if path.is_dir():
        return load_folder(path)
    where = "" if path.is_absolute() else (
        f" (a relative folder is read from the current folder, {Path.cwd()})")
    raise ValueError(f"unknown problem set {spec!r}: not a name ({', '.join(SETS)}) nor a "
                     f"directory{where}")


@dataclass(frozen=True)
class Unreadable:
    """A file of a folder set that could not be read: the bench reports it as a row with
    status "unreadable" and the reason, and goes on."""

    name: str
    reason: str
    meta: dict = field(default_factory=dict)
    n: int = 0


def load_folder(folder: str | os.PathLike) -> list:
    """Every *.npz and *.dat file of a folder (lcp.load: npz, or Siconos's LCP, MLCP or 2D
    friction-contact text), sorted by name; the problems keep their kind (an MLCP is not
    reduced here). A file that cannot be read, or whose problem rigidlcp does not take (e.g. a
    rectangular MLCP), is an `Unreadable` with the reason (its error message)."""
    folder = Path(folder)
    files = sorted([*folder.glob("*.npz"), *folder.glob("*.dat")])
    if not files:
        raise ValueError(f"{folder} holds no *.npz or *.dat problem files")
    out: list = []
    for f in files:
        name = f"{folder.name}/{f.stem}"
        try:
            p = lcp.load(f)
        except (ValueError, OSError) as exc:  # InvalidProblem, NotApplicable, bad zip, ...
            out.append(Unreadable(name, str(exc), {"set": folder.name, "file": str(f)}))
            continue
        meta = {**p.meta, "set": folder.name, "class": "folder", "file": str(f)}
        meta.setdefault("expected", "unknown")
        out.append(dataclasses.replace(p, name=name, meta=meta))
    return out
