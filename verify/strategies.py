"""Hypothesis strategies for LCP test data, in the style of ``hypothesis.extra.numpy``.

Every strategy draws its numbers through Hypothesis (so failures shrink) and builds matrices
that have the advertised property *by construction*, with the reason in its docstring:

* ``p_matrices(n)``      -- P-matrices (every principal minor positive): unique LCP solution
                            for every q (Samelson, Thrall & Wesler 1958; Murty 1972);
* ``symmetric_psd(n)``   -- symmetric positive semidefinite (optionally singular) matrices;
* ``lcps(matrices)``     -- ``lcp.LCP`` problems, optionally with a planted solution;
* ``degenerate_lcps()``  -- solvable LCPs with zeros in q, degenerate complementary pairs and
                            duplicated rows/columns (the shape of this project's friction LCPs);
* ``mlcps()``            -- ``lcp.MLCP`` problems with a nonsingular A (Schur-reducible);
* ``lattices()``         -- ``models.Lattice`` arrays (rectangular / triangular, valid sizes);
* ``systems()``          -- ``models.System`` with drawn coefficients and driving;
* ``contact_states(sys)``-- (normal, tangential) state vectors for ``models.contact_matrix``;
* ``event_states(sys)``  -- ``models.State`` at an event: angular velocities and, per contact,
                            sliding +1 / -1 or non-sliding candidate 0.

Sizes may be an int or a strategy of ints, and matrix strategies can be passed to ``lcps``:
``lcps(p_matrices(st.integers(1, 6)), planted=True)``. Where a strategy of numbers or of
matrices is asked for (``mu``, ``gamma``, ``candidates``, ``q_elements``, ``matrices``), a
plain number or matrix is taken as that fixed value (``st.just``): ``systems(mu=0.3)``.
Entries are kept O(1) and the constructions keep conditioning moderate, so that a method
disagreeing with another by more than ~1e-8 is a bug, not rounding. Entries lie on a grid of
step 1/1000 (exact zeros and ties included; no 1e-140 next to 1).
"""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from rigidlcp.lcp import LCP, MLCP
from rigidlcp.lcp.errors import InvalidInput

__all__ = [
    "P_KINDS", "p_matrices", "symmetric_psd", "lcps", "degenerate_lcps", "mlcps",
    "planted_solution", "lattices", "systems", "contact_states", "event_states",
]

#: The constructions `p_matrices` draws from.
P_KINDS = ("positive-definite", "diagonally-dominant", "triangular", "scaled")

SizeLike = int | st.SearchStrategy

# Default sizes (module-level so that they are built once).
SMALL = st.integers(1, 8)
SMALL_DEGENERATE = st.integers(2, 8)
FEW = st.integers(0, 2)
NU = st.integers(1, 4)
M_PAIRS = st.integers(1, 5)
LX = st.integers(1, 8)
LY = st.integers(1, 6)


def _strategy(value, name: str, matrix: bool = False) -> st.SearchStrategy:
    """`value` itself when it is a strategy; a plain number (or, with `matrix`, a square
    matrix) as the strategy of that one value; InvalidInput naming `name` otherwise."""
    if isinstance(value, st.SearchStrategy):
        return value
    if matrix:
        a = np.asarray(value, dtype=float) if isinstance(value, (np.ndarray, list)) else None
        if a is not None and a.ndim == 2 and a.shape[0] == a.shape[1] and a.size:
            return st.just(a)
        raise InvalidInput(f"{name} must be a strategy of square matrices or a square matrix, "
                           f"got {type(value).__name__}")
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        return st.just(float(value))
    raise InvalidInput(f"{name} must be a number or a strategy of numbers, got {value!r}")


def _size(draw, n: SizeLike, least: int = 1) -> int:
    value = draw(n) if isinstance(n, st.SearchStrategy) else n
    if not isinstance(value, (int, np.integer)) or value < least:
        raise InvalidInput(f"sizes must be integers >= {least}, got {value!r}")
    return int(value)


#: Entries are drawn on a grid of GRID + 1 points of [lo, hi] (see _unit).
GRID = 1000


def _unit(lo: float = -1.0, hi: float = 1.0) -> st.SearchStrategy[float]:
    """Numbers on a grid of [lo, hi] (step (hi - lo)/GRID; 0 is on it when lo = -hi).

    A grid rather than arbitrary floats: Hypothesis likes values such as 1e-140, whose
    products underflow next to O(1) entries and turn a PSD construction into rounding noise.
    Exact zeros and exact ties (degeneracy) remain common, and shrinking goes to round numbers.
    """
    return st.integers(0, GRID).map(lambda k: lo + (hi - lo) * k / GRID)


def _matrix(draw, rows: int, cols: int, lo: float = -1.0, hi: float = 1.0) -> np.ndarray:
    return draw(arrays(np.float64, (rows, cols), elements=_unit(lo, hi)))


def _vector(draw, size: int, lo: float = -1.0, hi: float = 1.0) -> np.ndarray:
    return draw(arrays(np.float64, (size,), elements=_unit(lo, hi)))


@st.composite
def p_matrices(draw, n: SizeLike = SMALL, *, kind: str | None = None) -> np.ndarray:
    """n x n P-matrices, P by construction (``kind`` one of P_KINDS, or drawn when None).

    * positive-definite: B B' + c I + (K - K'), c in [0.1, 1]: the symmetric part is >= c I,
      so x'Mx > 0 for x != 0, which gives positive principal minors (and |M^-1| <= 1/c);
      usually non-symmetric;
    * diagonally-dominant: off-diagonal entries in [-1, 1], M_ii = sum_j |M_ij| + margin,
      margin in [0.1, 1]: every principal submatrix is strictly diagonally dominant with a
      positive diagonal, hence has a positive determinant;
    * triangular: a lower-triangular matrix with diagonal in [1, 2] (off-diagonal in [-1, 1])
      under a symmetric permutation P L P': its principal submatrices are triangular with
      positive diagonal. Typically *not* positive definite (symmetric part indefinite);
    * scaled: D1 M D2 with M of one of the kinds above and positive diagonal D1, D2 in
      [0.5, 2]: each principal minor is multiplied by a positive number.
    """
    size = _size(draw, n)
    kind = kind if kind is not None else draw(st.sampled_from(P_KINDS))
    if kind not in P_KINDS:
        raise InvalidInput(f"kind must be one of {P_KINDS} or None, got {kind!r}")
    if kind == "positive-definite":
        B = _matrix(draw, size, size)
        K = _matrix(draw, size, size) * draw(_unit(0.0, 2.0))
        c = draw(_unit(0.1, 1.0))
        return B @ B.T + c * np.eye(size) + (K - K.T)
    if kind == "diagonally-dominant":
        M = _matrix(draw, size, size)
        np.fill_diagonal(M, 0.0)
        margin = _vector(draw, size, 0.1, 1.0)
        np.fill_diagonal(M, np.abs(M).sum(axis=1) + margin)
        return M
    if kind == "triangular":
        L = np.tril(_matrix(draw, size, size), -1)
        L += np.diag(_vector(draw, size, 1.0, 2.0))
        perm = np.array(draw(st.permutations(range(size))), dtype=np.intp)
        return L[np.ix_(perm, perm)]
    base = draw(p_matrices(size, kind=draw(st.sampled_from(P_KINDS[:3]))))
    d1, d2 = _vector(draw, size, 0.5, 2.0), _vector(draw, size, 0.5, 2.0)
    return d1[:, None] * base * d2[None, :]


@st.composite
def symmetric_psd(
    draw, n: SizeLike = SMALL, singular: bool = False, *, rank: SizeLike | None = None
) -> np.ndarray:
    """n x n symmetric positive semidefinite matrices B B' (B is n x r, entries in [-1, 1]).

    singular=False: r = n plus c I with c in [0.1, 1], so the least eigenvalue is >= c
    (positive definite). singular=True: r < n (drawn from [0, n-1] unless ``rank`` is given),
    no shift, so rank M = r < n: a genuinely singular matrix, as the Delassus operator of a
    hyperstatic contact network is. The result is symmetrized exactly.
    """
    size = _size(draw, n)
    if singular:
        r = _size(draw, rank) if rank is not None else draw(st.integers(0, size - 1))
        if r >= size:
            raise InvalidInput(f"a singular matrix needs rank < n = {size}, got {r}")
        B = _matrix(draw, size, r) if r else np.zeros((size, 0))
        M = B @ B.T
    else:
        if rank is not None:
            raise InvalidInput("rank applies only with singular=True")
        B = _matrix(draw, size, size)
        M = B @ B.T + draw(_unit(0.1, 1.0)) * np.eye(size)
    return 0.5 * (M + M.T)


@st.composite
def planted_solution(draw, M: np.ndarray, *, degenerate: bool = True):
    """(z, w, q) with q = w - M z, z >= 0, w >= 0, z'w = 0: z solves LCP(M, q).

    Each index is drawn as z_i > 0 (then w_i = 0), w_i > 0 (z_i = 0), or, when ``degenerate``,
    z_i = w_i = 0 (a degenerate pair). Values are in [0.1, 1]. For positive semidefinite M this
    also makes a problem that is solvable at all (a singular PSD M with a random q need not be).
    """
    if isinstance(M, st.SearchStrategy):
        raise InvalidInput("planted_solution takes a matrix, not a strategy: for drawn "
                           "matrices use lcps(matrices, planted=True), or draw M first")
    n = M.shape[0]
    states = st.sampled_from(("z", "w", "0") if degenerate else ("z", "w"))
    pattern = draw(st.lists(states, min_size=n, max_size=n))
    values = _vector(draw, n, 0.1, 1.0)
    z = np.where(np.array(pattern) == "z", values, 0.0)
    w = np.where(np.array(pattern) == "w", values, 0.0)
    return z, w, w - M @ z


@st.composite
def lcps(
    draw, matrices: st.SearchStrategy[np.ndarray] | None = None, *, planted: bool = False,
    q_elements: st.SearchStrategy[float] | None = None,
) -> LCP:
    """``lcp.LCP(M, q)`` with M drawn from ``matrices`` (default: P-matrices, n in 1..8).

    q has entries from ``q_elements`` (default [-1, 1]); with ``planted=True`` q is built from
    a planted complementary pair instead (see planted_solution), recorded in
    ``meta["planted_z"]`` and ``meta["planted_w"]`` (lists). A plain matrix in place of
    ``matrices`` is that fixed M.
    """
    M = draw(_strategy(matrices, "matrices", matrix=True) if matrices is not None
             else p_matrices())
    n = M.shape[0]
    if planted:
        z, w, q = draw(planted_solution(M))
        return LCP(M, q, meta={"planted_z": z.tolist(), "planted_w": w.tolist()})
    elements = _unit() if q_elements is None else _strategy(q_elements, "q_elements")
    q = draw(arrays(np.float64, (n,), elements=elements))
    return LCP(M, q)


@st.composite
def degenerate_lcps(
    draw, n: SizeLike = SMALL_DEGENERATE, *, base: str | None = None, zeros: bool = True,
    duplicates: SizeLike = FEW,
) -> LCP:
    """Solvable degenerate LCPs of size n: zeros in q and duplicated rows/columns.

    A base LCP of size n0 = n - k (k duplicates) gets a planted solution (z0, w0) with
    degenerate pairs; ``base`` "p" (P-matrix), "psd" (symmetric PSD, possibly singular) or
    None (either). With ``zeros``, q_i is set to 0 at some indices outside supp(z0) where
    (M z0)_i >= 0, which keeps z0 a solution. Then k indices are duplicated:
    M = E M0 E', q = E q0 with E stacking I and copies of rows of I, so that rows *and*
    columns repeat (M is then singular and no longer P); z = (z0, 0) still solves it. Finally
    a symmetric permutation mixes the copies in. meta holds "planted_z", "duplicated" (the
    pairs, after permutation) and "base".
    """
    size = _size(draw, n)
    k = min(_size(draw, duplicates, least=0), size - 1)
    n0 = size - k
    base = base if base is not None else draw(st.sampled_from(("p", "psd")))
    if base == "p":
        M0 = draw(p_matrices(n0))
    elif base == "psd":
        M0 = draw(symmetric_psd(n0, singular=n0 > 1 and draw(st.booleans())))
    else:
        raise InvalidInput(f"base must be 'p', 'psd' or None, got {base!r}")
    z0, w0, q0 = draw(planted_solution(M0))
    if zeros:
        Mz = M0 @ z0
        can = np.flatnonzero((z0 == 0) & (Mz >= 0))
        if can.size:
            chosen = draw(st.lists(st.sampled_from(can.tolist()), min_size=1, unique=True))
            q0[chosen] = 0.0
    copies = [draw(st.integers(0, n0 - 1)) for _ in range(k)]
    E = np.vstack([np.eye(n0)] + [np.eye(n0)[[j]] for j in copies])
    M, q = E @ M0 @ E.T, E @ q0
    z = np.concatenate([z0, np.zeros(k)])
    perm = np.array(draw(st.permutations(range(size))), dtype=np.intp)
    inv = np.argsort(perm)
    M, q, z = M[np.ix_(perm, perm)], q[perm], z[perm]
    pairs = [(int(inv[j]), int(inv[n0 + i])) for i, j in enumerate(copies)]
    return LCP(M, q, meta={"planted_z": z.tolist(), "duplicated": pairs, "base": base})


@st.composite
def mlcps(draw, nu: SizeLike = NU, m: SizeLike = M_PAIRS) -> MLCP:
    """MLCPs A u + C v + a = 0, w = D u + B v + b, 0 <= v perp w >= 0, Schur-reducible.

    A is a positive diagonal (a mass matrix) or positive definite (non-symmetric), so it is
    nonsingular and A^-1 is positive definite too; C = -D' with D in [-1, 1] and B positive
    definite (kind "positive-definite"), so the Schur complement B - D A^-1 C = B + D A^-1 D'
    is positive definite, a P-matrix: the MLCP has exactly one solution.
    """
    nu_, m_ = _size(draw, nu), _size(draw, m)
    if draw(st.booleans()):
        A = np.diag(_vector(draw, nu_, 0.5, 2.0))
    else:
        A = draw(p_matrices(nu_, kind="positive-definite"))
    D = _matrix(draw, m_, nu_)
    B = draw(p_matrices(m_, kind="positive-definite"))
    a, b = _vector(draw, nu_), _vector(draw, m_)
    return MLCP(A, -D.T, D, B, a, b)


# --- lattices, systems and contact states (models) ---------------------------------------------

@st.composite
def lattices(draw, kinds: tuple[str, ...] = ("rect", "tri"), lx: SizeLike = LX,
             ly: SizeLike = LY):
    """``models.Lattice`` of a drawn kind and size; triangular arrays of two or more rows get
    lx >= 2 (their rows in the hollows hold lx - 1 disks). ``kinds``: a tuple of "rect" and
    "tri", or one of them as a string."""
    from rigidlcp import models

    kind = draw(st.sampled_from((kinds,) if isinstance(kinds, str) else tuple(kinds)))
    n_rows = _size(draw, ly)
    least = 2 if kind == "tri" and n_rows >= 2 else 1
    n_cols = max(_size(draw, lx), least)
    return models.make_lattice(kind, n_cols, n_rows)


@st.composite
def systems(draw, lattice=None, mu: st.SearchStrategy[float] | None = None,
            gamma: st.SearchStrategy[float] | None = None):
    """``models.System`` on ``lattice`` (a Lattice, a strategy of them, or None for
    ``lattices()``), coefficients per kind from ``mu`` (default 0 to 0.5 on a grid, 0 included)
    and driving acceleration from ``gamma`` (default -0.5 to 0.5); a plain number for ``mu``
    or ``gamma`` fixes it."""
    from rigidlcp import models

    if lattice is None:
        lattice = lattices()
    lat = draw(lattice) if isinstance(lattice, st.SearchStrategy) else lattice
    mu = _unit(0.0, 0.5) if mu is None else _strategy(mu, "mu")
    gamma = _unit(-0.5, 0.5) if gamma is None else _strategy(gamma, "gamma")
    return models.System(lat, mu_pp=draw(mu), mu_plane=draw(mu), mu_wall=draw(mu),
                         gamma=draw(gamma), V0=draw(_unit(-1.0, 1.0)))


def _system(system, name: str):
    """`system` when it is a models.System; InvalidInput otherwise, saying how to draw one
    first when it is a strategy (``event_states(systems())`` is the natural first try)."""
    from rigidlcp import models

    if isinstance(system, st.SearchStrategy):
        raise InvalidInput(f"{name} takes a models.System, not a strategy: draw the system "
                           f"first, e.g. systems().flatmap(lambda s: {name}(s).map("
                           "lambda x: (s, x)))")
    if not isinstance(system, models.System):
        raise InvalidInput(f"{name} takes a models.System, got {type(system).__name__}")
    return system


@st.composite
def contact_states(draw, system):
    """(normal, tangential) for ``models.contact_matrix``: normal[alpha] True (T) / False (NT),
    tangential[alpha] in {0 (NS), +1, -1 (sliding)}."""
    c = _system(system, "contact_states").c
    normal = draw(arrays(bool, c))
    tangential = draw(arrays(np.int64, c, elements=st.sampled_from([0, 1, -1])))
    return normal, tangential


@st.composite
def event_states(draw, system, candidates: st.SearchStrategy[float] | None = None):
    """``models.State`` at t = 0: angular velocities in [-1, 1] (grid) and per contact +1 / -1
    (sliding that way) or 0 (non-sliding candidate, drawn with probability ``candidates``,
    default in [0, 1]); frictionless contacts carry 0."""
    from rigidlcp import models

    p, c = _system(system, "event_states").p, system.c
    omega = _vector(draw, p)
    frac = draw(_unit(0.0, 1.0) if candidates is None else _strategy(candidates, "candidates"))
    stick = draw(arrays(np.float64, c, elements=_unit(0.0, 1.0))) < frac
    signs = draw(arrays(np.int64, c, elements=st.sampled_from([1, -1])))
    s = np.where(stick | (system.mu == 0), 0, signs)
    return models.State(0.0, omega, float(system.V0), s)
