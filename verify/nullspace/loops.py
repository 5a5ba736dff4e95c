"""The kinematic loops of Fig. 5(b), 5(c), 5(e): dependencies among the NS equations.

In the regime of the paper (no particle displacement), the NS condition of contact alpha
reduces to omega_i + omega_j = 0 (omega_i = 0 against an obstacle), and "three NS contacts of a
loop of four disks imply the fourth" is a linear dependency among those equations -- a vector of
the *left* null space of the contact-disk matrix K. Those loops are not null vectors of the
contact matrix M of Eq. (2.15) (whose null vectors are self-equilibrated forces), but they have
the same count: dim ker M(A) - dim ker M(no NS) = |A| - rank K(A) for any set A of NS contacts
(docs/verification.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigidlcp import models

from .sparse import localized_basis, svd_rank


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
