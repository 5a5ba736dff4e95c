"""Null space of the paper's contact matrix (Eq. 2.15) by SVD (Eq. 3.1), and its structures.

For a vector of contact states, `models.contact_matrix` gives M x = b, x = [R (c); S (c)].
`null_space` computes

* the SVD M = U diag(w) V^T (Eq. 3.1) and the numerical rank with the tolerance
  tol = max(shape) * eps * w_max, the standard choice (numpy.linalg.matrix_rank, Numerical
  Recipes' svdcmp, which the paper cites): a singular value below it is indistinguishable from
  the backward error of the SVD itself (||dM|| ~ eps ||M||, and ||M||_2 = w_max). The gap
  around it is reported (`gap`): in these matrices the smallest kept and the largest dropped
  singular values are ~10^13 apart, so the count does not depend on the choice, and it is
  cross-checked against the exact rank in Q(sqrt 3) (`verify.qsqrt3`) in the tests;
* the dimension of the null space and the contacts that contribute to it (Eq. 3.2): contact alpha
  contributes iff its R or S coordinate is nonzero in some null vector, i.e. iff the rows alpha
  and c + alpha of the orthonormal null basis V0 are not both zero. "Zero" is a row norm below
  `support_tol` = sqrt(eps); the perturbation bound on the computed null space (Wedin:
  sin angle <= ||dM|| / w_r, with w_r the smallest kept singular value) is reported beside it
  (`basis_error`) and is far smaller for these matrices;
* a localized basis (`localized_basis`): each vector involves as few contacts as we can find,
  so that the structures of Fig. 5 show (rows between the walls, the 12-contact hexagons of a
  triangular array). Method: for every coordinate k in the support, the L1-smallest null vector
  with x_k = 1 (a linear program; its optimal vertex is a *circuit*, a null vector of minimal
  support), polished to an exact null vector of M restricted to that support; then the sparsest
  circuits are taken greedily while they stay independent (the matroid greedy algorithm), and
  any missing dimension is filled by an L1-smallest vector with a normalization that forces
  independence. The paper notes (end of Sec. III B) that any basis is as good as another;
  sparse ones are the readable ones.

`rotation_loops` is the paper's kinematic reading of Fig. 5(b), 5(c), 5(e): in the regime of the
paper (no particle displacement), the NS condition of contact alpha reduces to
omega_i + omega_j = 0 (omega_i = 0 against an obstacle), and "three NS contacts of a loop of
four disks imply the fourth" is a linear dependency among those equations -- a vector of the
*left* null space of the contact-disk matrix K. See docs/verification.md: those loops are not
null vectors of M (whose null vectors are self-equilibrated forces), but they have the same
count.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog
from threadpoolctl import threadpool_limits

import models

EPS = np.finfo(float).eps
#: A row of the orthonormal null basis with a norm below this is zero (Eq. 3.2).
SUPPORT_TOL = float(np.sqrt(EPS))
#: Relative size below which an entry of a (max-normalized) localized vector is zero.
ENTRY_TOL = 1e-9
#: Components of x whose residual after projection on the chosen vectors counts as new.
INDEPENDENCE_TOL = 1e-8

KINDS = ("normal", "tangential")


def paper_states(
    system: models.System, kind: str, signs: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The contact states of Eq. (3.3) / Eq. (3.4): (normal, tangential) for `contact_matrix`.

    kind "normal": every contact transmitting and sliding, with the sliding signs `signs`
    (default +1; the count does not depend on them, see docs/verification.md).
    kind "tangential": every contact transmitting and non-sliding (the static state, zero
    rotation velocities), except frictionless contacts (mu = 0), whose friction force is zero:
    they get the sliding equation S + s mu R = S = 0.
    """
    c = system.c
    normal = np.ones(c, dtype=bool)
    if kind == "normal":
        tangential = np.ones(c, dtype=int) if signs is None else np.asarray(signs, dtype=int)
        if tangential.shape != (c,) or not np.all(np.isin(tangential, (-1, 1))):
            raise ValueError(f"signs must hold -1 or +1 for each of the {c} contacts")
    elif kind == "tangential":
        tangential = np.where(system.mu > 0, 0, 1)
    else:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    return normal, tangential


def svd_rank(M: np.ndarray, tol: float | None = None) -> tuple[np.ndarray, np.ndarray, float, int]:
    """SVD of M (Eq. 3.1): (singular values w, descending; V; tol; numerical rank).

    tol defaults to max(M.shape) * eps * w_max (see the module docstring).
    """
    M = np.asarray(M, dtype=float)
    if M.ndim != 2 or not np.all(np.isfinite(M)):
        raise ValueError("M must be a finite 2-D array")
    if M.size == 0:
        return np.zeros(0), np.eye(M.shape[1]), 0.0, 0
    # V must be complete (all of R^n): full_matrices only matters when M has fewer rows.
    _, w, Vt = np.linalg.svd(M, full_matrices=M.shape[0] < M.shape[1])
    if tol is None:
        tol = max(M.shape) * EPS * (w[0] if w.size else 0.0)
    rank = int(np.sum(w > tol))
    return w, Vt.T, float(tol), rank


@dataclass
class NullSpace:
    """ker M for one vector of contact states (Eqs. 2.15, 3.1, 3.2)."""

    system: models.System
    normal: np.ndarray
    tangential: np.ndarray
    M: np.ndarray = field(repr=False)
    singular_values: np.ndarray = field(repr=False)
    tol: float
    rank: int
    basis: np.ndarray = field(repr=False)  # orthonormal, (2c, dim): the columns of V, w = 0
    contributing: np.ndarray  # contact indices (Eq. 3.2)
    localized: np.ndarray | None = field(default=None, repr=False)  # (2c, dim), sparse

    @property
    def dim(self) -> int:
        return self.basis.shape[1]

    @property
    def c(self) -> int:
        return self.system.c

    @property
    def gap(self) -> tuple[float | None, float | None]:
        """(smallest singular value kept, largest one counted as zero)."""
        w = self.singular_values
        kept = float(w[self.rank - 1]) if self.rank > 0 else None
        dropped = float(w[self.rank]) if self.rank < w.size else (0.0 if self.dim else None)
        return kept, dropped

    @property
    def basis_error(self) -> float:
        """Wedin's bound on the angle between the computed and the exact null space:
        max(shape) eps w_max / w_r (w_r: the smallest singular value kept)."""
        kept = self.gap[0]
        if not kept:
            return 0.0
        return max(self.M.shape) * EPS * float(self.singular_values[0]) / kept

    def contacts_of(self, x: np.ndarray) -> np.ndarray:
        """Contacts alpha with R_alpha or S_alpha nonzero in a (max-normalized) vector x."""
        x = np.asarray(x, dtype=float)
        scale = max(np.abs(x).max(initial=0.0), 1e-300)
        nz = np.abs(x) > ENTRY_TOL * scale
        return np.flatnonzero(nz[: self.c] | nz[self.c :])

    def to_dict(self) -> dict:
        """A JSON-friendly summary (the localized basis included when computed)."""
        lat = self.system.lattice
        kept, dropped = self.gap
        out = {
            "lattice": lat.name, "lx": lat.lx, "ly": lat.ly, "p": lat.p, "c": lat.c,
            "mu_pp": self.system.mu_pp, "mu_plane": self.system.mu_plane,
            "mu_wall": self.system.mu_wall,
            "normal": ["T" if s else "NT" for s in self.normal],
            "tangential": [_TNAME[int(s)] for s in self.tangential],
            "shape": list(self.M.shape), "rank": self.rank, "dim": self.dim,
            "tol": self.tol, "sigma_max": float(self.singular_values[0]) if self.rank else 0.0,
            "smallest_kept": kept, "largest_dropped": dropped,
            "basis_error": self.basis_error, "support_tol": SUPPORT_TOL,
            "contributing": [int(a) for a in self.contributing],
        }
        if self.localized is not None:
            out["localized"] = [self.vector_dict(x) for x in self.localized.T]
        return out

    def vector_dict(self, x: np.ndarray) -> dict:
        contacts = self.contacts_of(x)
        c = self.c
        return {
            "contacts": [int(a) for a in contacts],
            "labels": [self.system.lattice.label(int(a)) for a in contacts],
            "R": [float(x[a]) for a in contacts],
            "S": [float(x[c + a]) for a in contacts],
        }


_TNAME = {0: "NS", 1: "+", -1: "-"}
_NORMAL_WORDS = {"T": True, "NT": False}
_TANGENTIAL_WORDS = {"NS": 0, "+": 1, "-": -1, "+1": 1, "-1": -1}


def read_states(path: str, lattice: models.Lattice) -> tuple[np.ndarray, np.ndarray]:
    """Contact states from a file: (normal, tangential) for `models.contact_matrix`.

    JSON: {"normal": [...], "tangential": [...]} with one entry per contact, in the order of
    `lattice` (contact alpha = `lattice.label(alpha)`). normal: "T" / "NT", or true / false,
    or 1 / 0. tangential: "NS" / "+" / "-", or 0 / +1 / -1 (sliding with sgn v_t = +-1).
    Optional keys "lattice", "lx", "ly" are checked against `lattice`. The JSON written by
    `rigidlcp nullspace --json` has this form, so it can be edited and read back.
    .npz: arrays "normal" (bool or 0/1) and "tangential" (integers -1, 0, 1), same order;
    optional scalars "lattice", "lx", "ly".
    """
    import json
    from pathlib import Path

    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no such states file: {path}")
    if path.suffix == ".npz":
        with np.load(path, allow_pickle=False) as f:
            data = {k: f[k] for k in f.files}
            data = {k: (v.item() if v.ndim == 0 else v) for k, v in data.items()}
    else:
        data = json.loads(path.read_text())
        if not isinstance(data, dict):
            raise ValueError(f"{path}: expected a JSON object with 'normal' and 'tangential'")
    names = {"rect": ("rect", "rectangular"), "tri": ("tri", "triangular")}[lattice.name]
    checks = (("lattice", lambda v: str(v).lower() in names, lattice.name),
              ("lx", lambda v: int(v) == lattice.lx, lattice.lx),
              ("ly", lambda v: int(v) == lattice.ly, lattice.ly))
    for key, ok, want in checks:
        if key in data and not ok(data[key]):
            raise ValueError(f"{path}: {key} = {data[key]!r} but the lattice has {want!r}")
    for key in ("normal", "tangential"):
        if key not in data:
            raise ValueError(f"{path}: missing '{key}' (one state per contact)")
    c = lattice.c
    normal = [_NORMAL_WORDS.get(v, v) if isinstance(v, str) else v for v in data["normal"]]
    tang = [_TANGENTIAL_WORDS.get(v, v) if isinstance(v, str) else v for v in data["tangential"]]
    for key, values, ok in (("normal", normal, (True, False, 0, 1)),
                            ("tangential", tang, (-1, 0, 1))):
        if len(values) != c:
            raise ValueError(f"{path}: '{key}' has {len(values)} entries, the lattice has {c} "
                             "contacts")
        bad = [v for v in values if isinstance(v, str) or v not in ok]
        if bad:
            raise ValueError(f"{path}: '{key}' has invalid states {bad[:3]!r} (allowed: "
                             f"{'T/NT' if key == 'normal' else 'NS/+/-'})")
    return np.array(normal, dtype=bool), np.array(tang, dtype=int)


def null_space(
    system: models.System,
    normal: np.ndarray,
    tangential: np.ndarray,
    localize: bool = False,
    tol: float | None = None,
) -> NullSpace:
    """The null space of the contact matrix of Eq. (2.15) for the given contact states.

    localize: also compute `localized_basis` (one LP per contributing contact; seconds for a
    few hundred contacts). BLAS runs on one thread: these matrices are small and dense, and
    threads only cost time (a lot of it on a loaded machine).
    """
    M, _ = models.contact_matrix(system, normal, tangential)
    with threadpool_limits(1):
        w, V, tol, rank = svd_rank(M, tol)
    basis = V[:, rank:]
    c = system.c
    norms = np.sqrt(np.sum(basis[:c] ** 2, axis=1) + np.sum(basis[c:] ** 2, axis=1))
    contributing = np.flatnonzero(norms > SUPPORT_TOL)
    ns = NullSpace(system, np.asarray(normal, bool), np.asarray(tangential, int), M, w, tol,
                   rank, basis, contributing)
    if localize:
        patches = contact_patches(system.lattice, 1)
        ns.localized = localized_basis(M, basis, contact_count=c, patches=patches)
    return ns


def _l1_smallest(V: np.ndarray, a: np.ndarray) -> np.ndarray | None:
    """argmin ||V y||_1 subject to a . y = 1, returned as x = V y (a linear program).

    Variables (y, u), u >= 0 bounding |V y| from above; the dual simplex returns a vertex, i.e.
    a null vector of minimal support (a circuit) in the generic case.
    """
    n, d = V.shape
    Vs = sp.csr_matrix(V)
    eye = sp.identity(n, format="csr")
    A_ub = sp.vstack([sp.hstack([Vs, -eye]), sp.hstack([-Vs, -eye])], format="csr")
    res = linprog(
        np.r_[np.zeros(d), np.ones(n)], A_ub=A_ub, b_ub=np.zeros(2 * n),
        A_eq=np.r_[a, np.zeros(n)][None, :], b_eq=[1.0],
        bounds=[(None, None)] * d + [(0, None)] * n, method="highs-ds",
    )
    if res.status != 0:
        return None
    return V @ res.x[:d]


def _polish(M: np.ndarray, x: np.ndarray, tol: float) -> np.ndarray:
    """Zero the negligible entries of x; when its support carries exactly one null direction of
    M (a circuit), return that direction computed from M restricted to the support."""
    x = x / np.abs(x).max()
    supp = np.flatnonzero(np.abs(x) > ENTRY_TOL)
    w, V, _, rank = svd_rank(M[:, supp], tol)
    if supp.size - rank == 1:
        y = V[:, -1]
        y = y if y @ x[supp] > 0 else -y
        x = np.zeros_like(x)
        x[supp] = y
    else:
        x[np.abs(x) <= ENTRY_TOL] = 0.0
    k = np.argmax(np.abs(x))
    x = x / x[k]
    x[np.abs(x) <= ENTRY_TOL] = 0.0
    return x + 0.0  # no negative zeros


def _n_contacts(x: np.ndarray, contact_count: int | None) -> int:
    nz = x != 0
    if contact_count is None:
        return int(nz.sum())
    c = contact_count
    return int(np.sum(nz[:c] | nz[c:]))


def contact_patches(lattice: models.Lattice, radius: int = 1) -> list[np.ndarray]:
    """Column sets of x = [R; S] for local searches: for each disk k, the contacts whose disks
    all lie within `radius` pp-contact steps of k (obstacle contacts of those disks included).
    radius 1 around a disk with six neighbours is the 12-contact hexagon of Fig. 5(a)."""
    p, c = lattice.p, lattice.c
    adj: list[set[int]] = [set() for _ in range(p)]
    for a in range(c):
        i, j = int(lattice.i[a]), int(lattice.j[a])
        if j >= 0:
            adj[i].add(j)
            adj[j].add(i)
    patches = []
    for k in range(p):
        ball, front = {k}, {k}
        for _ in range(radius):
            front = {m for f in front for m in adj[f]} - ball
            ball |= front
        inside = np.isin(lattice.i, list(ball)) & ((lattice.j < 0) | np.isin(lattice.j, list(ball)))
        a = np.flatnonzero(inside)
        patches.append(np.r_[a, a + c])
    return patches


def localized_basis(
    M: np.ndarray,
    basis: np.ndarray,
    contact_count: int | None = None,
    patches: list[np.ndarray] = (),
    exhaustive: bool | None = None,
    seed: int = 0,
) -> np.ndarray:
    """A basis of ker M (given by an orthonormal `basis`) whose vectors have small supports.

    Candidates: (1) for each column set in `patches`, the null vectors of M supported there
    (ker M[:, patch], embedded), localized by L1 inside the patch -- these are genuine null
    vectors of M and catch local structures such as the hexagons of Fig. 5(a), which a global
    L1 minimum may trade for a longer but lighter vector; (2) for the coordinates of the support
    not yet covered (all of them when `exhaustive`, the default when there are no patches and
    2c <= 400), the global L1-smallest null vector with x_k = 1. Then the matroid greedy
    algorithm keeps the sparsest independent ones, and a normalization orthogonal to the kept
    span fills any missing dimension.

    contact_count c: coordinates k and c + k belong to the same contact (x = [R; S] of Eq.
    2.15); supports are then measured in contacts. Vectors are scaled so that their largest
    entry is +1 and sorted by support size.
    """
    n, d = basis.shape
    if d == 0:
        return np.zeros((n, 0))
    with threadpool_limits(1):  # small dense matrices: one BLAS thread is fastest (and much
        return _localized_basis(M, basis, contact_count, patches, exhaustive, seed)  # faster
        # on a loaded machine)


def _localize_within(M: np.ndarray, V: np.ndarray, tol: float) -> list[np.ndarray]:
    """L1 circuits of the span of V (orthonormal columns), one LP per support coordinate."""
    if V.shape[1] == 1:
        return [_polish(M, V[:, 0], tol)]
    out = []
    for k in np.flatnonzero(np.linalg.norm(V, axis=1) > SUPPORT_TOL):
        x = _l1_smallest(V, V[k])
        if x is not None:
            out.append(_polish(M, x, tol))
    return out


def _representatives(basis: np.ndarray, contact_count: int | None) -> np.ndarray:
    """One coordinate per contact of the support (its R, else its S): supports are counted in
    contacts, so one L1 problem per contact suffices."""
    nonzero = np.linalg.norm(basis, axis=1) > SUPPORT_TOL
    if contact_count is None:
        return np.flatnonzero(nonzero)
    c = contact_count
    a = np.flatnonzero(nonzero[:c] | nonzero[c:])
    return np.where(nonzero[a], a, a + c)


def _localized_basis(M: np.ndarray, basis: np.ndarray, contact_count: int | None,
                     patches, exhaustive: bool | None, seed: int) -> np.ndarray:
    n, d = basis.shape
    tol = max(M.shape) * EPS * np.linalg.norm(M, 2)
    found: list[np.ndarray] = []
    covered = np.zeros(n, dtype=bool)
    seen: set[tuple[int, ...]] = set()
    for cols in patches:
        _, V, _, rank = svd_rank(M[:, cols], tol)
        if V.shape[1] - rank == 0 or tuple(cols) in seen:
            continue
        seen.add(tuple(cols))
        for y in _localize_within(M[:, cols], V[:, rank:], tol):
            x = np.zeros(n)
            x[cols] = y
            covered |= x != 0
            found.append(x)
    if exhaustive is None:
        exhaustive = n <= 400
    for k in _representatives(basis, contact_count):
        if not exhaustive and covered[k]:
            continue
        x = _l1_smallest(basis, basis[k])
        if x is None:
            continue
        x = _polish(M, x, tol)
        covered |= x != 0
        found.append(x)

    def key(x: np.ndarray) -> tuple:
        nz = np.flatnonzero(x)
        return (_n_contacts(x, contact_count), nz.size, tuple(nz))

    chosen: list[np.ndarray] = []
    Q = np.zeros((n, 0))
    for x in sorted(found, key=key):
        r = x - Q @ (Q.T @ x)
        if np.linalg.norm(r) > INDEPENDENCE_TOL * np.linalg.norm(x):
            chosen.append(x)
            Q = np.column_stack([Q, r / np.linalg.norm(r)])
        if len(chosen) == d:
            break
    rng = np.random.default_rng(seed)
    while len(chosen) < d:  # a normalization orthogonal to the chosen span forces independence
        g = basis @ rng.standard_normal(d)
        g -= Q @ (Q.T @ g)
        x = _l1_smallest(basis, basis.T @ g)
        x = basis @ (basis.T @ g) if x is None else _polish(M, x, tol)
        r = x - Q @ (Q.T @ x)
        chosen.append(x)
        Q = np.column_stack([Q, r / np.linalg.norm(r)])
    return np.column_stack(sorted(chosen, key=key))


# -- the kinematic loops of Fig. 5(b), 5(c), 5(e) ------------------------------------------------


def rotation_matrix(lattice: models.Lattice, ns: np.ndarray) -> np.ndarray:
    """K (|NS| x p): the NS condition of contact alpha without translations (the paper's regime),
    -r (omega_i + omega_j) = 0, or -r omega_i = 0 against an obstacle, divided by -r."""
    ns = np.flatnonzero(ns)
    K = np.zeros((ns.size, lattice.p))
    K[np.arange(ns.size), lattice.i[ns]] = 1.0
    disk = lattice.j[ns] >= 0
    K[np.arange(ns.size)[disk], lattice.j[ns][disk]] += 1.0
    return K


@dataclass
class LoopBasis:
    """Dependencies among the NS equations of the no-displacement regime (left ker K)."""

    lattice: models.Lattice
    ns_contacts: np.ndarray  # the NS contacts (rows of K)
    vectors: np.ndarray  # (|NS|, dim): coefficients of the dependent combinations

    @property
    def dim(self) -> int:
        return self.vectors.shape[1]

    def loops(self) -> list[dict[int, float]]:
        """Each basis vector as {contact: coefficient} (the loops of Fig. 5b/5c/5e)."""
        return [{int(self.ns_contacts[k]): float(v[k]) for k in np.flatnonzero(v)}
                for v in self.vectors.T]


def rotation_loops(lattice: models.Lattice, ns: np.ndarray) -> LoopBasis:
    """The localized basis of left ker K for the NS contacts `ns` (a boolean mask).

    Its dimension is |NS| - rank K = |NS| - p + (number of connected components of the graph
    (disks, NS contacts) that are bipartite and touch no obstacle through an NS contact), K
    being an unsigned incidence matrix (`closed_form_loops`).
    """
    ns = np.asarray(ns, dtype=bool)
    K = rotation_matrix(lattice, ns)
    idx = np.flatnonzero(ns)
    if idx.size == 0:
        return LoopBasis(lattice, idx, np.zeros((0, 0)))
    w, V, _, rank = svd_rank(K.T)
    return LoopBasis(lattice, idx, localized_basis(K.T, V[:, rank:]))


def closed_form_loops(lattice: models.Lattice, ns: np.ndarray) -> int:
    """|NS| - rank K, with rank K = p - (bipartite components without an obstacle NS contact).

    A component of the graph (disks, NS pp contacts) has a nonzero rotation mode with
    omega_i + omega_j = 0 on all its edges iff it is bipartite (alternate signs), and that mode
    survives iff none of its disks has an NS contact with a wall or the plane.
    """
    ns = np.asarray(ns, dtype=bool)
    p = lattice.p
    parent = list(range(p))
    parity = [0] * p  # parity relative to the parent

    def find(k: int) -> tuple[int, int]:
        par = 0
        while parent[k] != k:
            par ^= parity[k]
            k = parent[k]
        return k, par

    bipartite = [True] * p
    grounded = [False] * p
    for a in np.flatnonzero(ns):
        i, j = int(lattice.i[a]), int(lattice.j[a])
        ri, pi = find(i)
        if j < 0:
            grounded[ri] = True
            continue
        rj, pj = find(j)
        if ri == rj:
            if pi == pj:  # an odd cycle
                bipartite[ri] = False
            continue
        parent[rj] = ri
        parity[rj] = pi ^ pj ^ 1  # i and j get opposite signs
        bipartite[ri] = bipartite[ri] and bipartite[rj]
        grounded[ri] = grounded[ri] or grounded[rj]
    roots = {find(k)[0] for k in range(p)}
    free_modes = sum(1 for r in roots if bipartite[r] and not grounded[r])
    return int(ns.sum()) - (p - free_modes)
