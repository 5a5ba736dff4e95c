"""Null space of the paper's contact matrix (Eq. 2.15) by SVD (Eq. 3.1), and its structures.

For a vector of contact states, `models.contact_matrix` gives M x = b, x = [R (c); S (c)].
`null_space` computes

* the SVD M = U diag(w) V^T (Eq. 3.1) and the numerical rank with the tolerance
  tol = max(shape) * eps * w_max, the standard choice (numpy.linalg.matrix_rank, Numerical
  Recipes' svdcmp, which the paper cites): a singular value below it is indistinguishable from
  the backward error of the SVD itself (||dM|| ~ eps ||M||, and ||M||_2 = w_max). The gap
  around it is reported (`gap`): in these matrices the smallest kept and the largest dropped
  singular values are ~10^13 apart, so the count does not depend on the choice, and it is
  cross-checked against the exact rank in Q(sqrt 3) (`verify.nullspace.qsqrt3`) in the tests;
* the dimension of the null space and the contacts that contribute to it (Eq. 3.2): contact alpha
  contributes iff its R or S coordinate is nonzero in some null vector, i.e. iff the rows alpha
  and c + alpha of the orthonormal null basis V0 are not both zero. "Zero" is a row norm below
  `support_tol` = sqrt(eps); the perturbation bound on the computed null space (Wedin:
  sin angle <= ||dM|| / w_r, with w_r the smallest kept singular value) is reported beside it
  (`basis_error`) and is far smaller for these matrices;
* a localized basis (`localized_basis`, in `verify.nullspace.sparse`): each vector involves as few
  contacts as we can find, so that the structures of Fig. 5 show (rows between the walls, the
  12-contact hexagons of a triangular array); the local candidates come from `contact_patches`
  (a disk and its neighbours). The paper notes (end of Sec. III B) that any basis is as good as
  another; sparse ones are the readable ones.

The kinematic reading of Fig. 5(b), 5(c), 5(e) (loops of NS contacts, which are not null vectors
of M but have the same count) is in `verify.nullspace.loops`; its names are re-exported here.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from threadpoolctl import threadpool_limits

from rigidlcp import models
from rigidlcp.lcp.errors import InvalidFile, InvalidInput

from .loops import LoopBasis, closed_form_loops, rotation_loops, rotation_matrix
from .sparse import (
    ENTRY_TOL,
    EPS,
    INDEPENDENCE_TOL,
    SUPPORT_TOL,
    localized_basis,
    svd_rank,
)

__all__ = [
    "KINDS", "paper_states", "NullSpace", "null_space", "read_states", "contact_patches",
    "svd_rank", "localized_basis", "EPS", "SUPPORT_TOL", "ENTRY_TOL", "INDEPENDENCE_TOL",
    "LoopBasis", "rotation_loops", "rotation_matrix", "closed_form_loops",
]

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
            raise InvalidInput(f"signs must hold -1 or +1 for each of the {c} contacts")
    elif kind == "tangential":
        tangential = np.where(system.mu > 0, 0, 1)
    else:
        raise InvalidInput(f"kind must be one of {KINDS}, got {kind!r}")
    return normal, tangential

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

    from rigidlcp.lcp.io.files import open_npz

    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(2, "No such states file", str(path))
    if path.is_dir():
        raise InvalidFile(f"{path} is a directory, not a states file (.json or .npz)")
    if path.suffix == ".npz":
        with open_npz(path, "a states file (.npz with 'normal' and 'tangential')") as f:
            data = {k: f[k] for k in f.files}
            data = {k: (v.item() if v.ndim == 0 else v) for k, v in data.items()}
    else:
        try:
            data = json.loads(path.read_text())
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise InvalidFile(f"{path} is not a states file (JSON: {exc})") from None
        if not isinstance(data, dict):
            raise InvalidFile(f"{path}: expected a JSON object with 'normal' and 'tangential'")
    names = {"rect": ("rect", "rectangular"), "tri": ("tri", "triangular")}.get(
        lattice.name, (lattice.name,))
    checks = (("lattice", lambda v: str(v).lower() in names, lattice.name),
              ("lx", lambda v: int(v) == lattice.lx, lattice.lx),
              ("ly", lambda v: int(v) == lattice.ly, lattice.ly))
    for key, ok, want in checks:
        if key in data and not ok(data[key]):
            raise InvalidFile(f"{path}: {key} = {data[key]!r} but the lattice has {want!r}")
    for key in ("normal", "tangential"):
        if key not in data:
            raise InvalidFile(f"{path}: missing '{key}' (one state per contact)")
    c = lattice.c
    normal = [_NORMAL_WORDS.get(v, v) if isinstance(v, str) else v for v in data["normal"]]
    tang = [_TANGENTIAL_WORDS.get(v, v) if isinstance(v, str) else v for v in data["tangential"]]
    for key, values, ok in (("normal", normal, (True, False, 0, 1)),
                            ("tangential", tang, (-1, 0, 1))):
        if len(values) != c:
            raise InvalidFile(f"{path}: '{key}' has {len(values)} entries, the lattice has {c} "
                             "contacts")
        bad = [v for v in values if isinstance(v, str) or v not in ok]
        if bad:
            raise InvalidFile(f"{path}: '{key}' has invalid states {bad[:3]!r} (allowed: "
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
