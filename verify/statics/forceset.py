"""The set of admissible contact forces of a packing at rest (verify.statics.model's P).

`analyse(system)` answers, each answer checked in code:

* exists: a lambda in P (checked against P), or a Farkas certificate that P is empty (virtual
  velocities under which every contact opens or slides within its cone while gravity does
  work), checked in floating point with a radius or in exact rational arithmetic
  (verify.statics.farkas); when neither passes, exists is None (undecided, with the reason),
  never a guess.
* dimension: of P itself, i.e. of its affine hull. An inequality of P that holds with equality
  on all of P (an implicit equality: R = 0, S = mu R or S = -mu R on the whole set) is found
  by linear programs maximizing slacks t_k in [0, scale] of the undecided rows (a row whose
  slack can be made positive is not implicit; when no undecided row can, all are: at most one
  LP per row, a few in practice). An interior point of P (HiGHS's IPM without crossover,
  checked to lie in P) decides most rows first: a clearly positive slack there is a witness.
  Then dim P = (number of unknowns left once the implicit equalities are substituted) - rank
  of the balance equations on them: full row rank is settled by the extreme eigenvalues of
  B B^T (sparse, any size) when sigma_min > 1e-6 sigma_max, else by a dense SVD with the
  standard tolerance max(shape) eps sigma_max (the singular values at the cut are reported).
* ranges: [min, max] of every R and S over P (two LPs each, warm-started; +-inf unbounded),
  every optimum checked to lie in P.
* sliding: whether |S| = mu R with R > 0 is attainable at each frictional contact (a checked
  optimum of a range LP at the bound is a witness; else an LP with
  that cone row made an equality), and their count against McNamara & Herrmann's 2M - 3N
  (M contacts, N disks): a packing with s contacts simultaneously at the Coulomb bound has
  dim P >= 0 only if s <= 2M - 3N generically.
* diameter: between the widest range and the diagonal of the box of ranges.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

from rigidlcp import models

from .farkas import farkas
from .model import LP_TOL, ForceLP, StaticProblem, interior_point

#: A slack or a force below this times the largest disk weight is zero.
ZERO = 1e-9
#: Largest number of unknowns whose rank is computed (dense SVD).
DENSE_RANK_LIMIT = 8000


@dataclass
class ForceSet:
    """The answers of `analyse` (module docstring). lo, hi: (2c,) ranges of [R; S];
    implicit[alpha]: "R=0", "S=+muR", "S=-muR" or "" (no implicit equality); sliding (c,)."""

    system: models.System
    exists: bool | None  # None: undecided (`undecided` says why)
    solution: np.ndarray | None = None
    certificate: np.ndarray | None = None
    radius: float | None = None
    dimension: int | None = None
    rank_gap: tuple[float | None, float | None] = (None, None)
    implicit: list[str] = field(default_factory=list)
    lo: np.ndarray | None = None
    hi: np.ndarray | None = None
    sliding: np.ndarray | None = None
    unchecked: int = 0  # LP optima that failed the check against P (none expected)
    residuals: tuple[float, float] = (0.0, 0.0)  # of `solution`: balance, laws (force units)
    lps: int = 0
    exact: bool = False  # the Farkas certificate is checked in exact rational arithmetic
    undecided: str = ""

    @property
    def c(self) -> int:
        return self.system.c

    @property
    def sliding_bound(self) -> int:
        """McNamara & Herrmann's 2M - 3N (M contacts, N disks)."""
        return 2 * self.system.c - 3 * self.system.p

    @property
    def width(self) -> np.ndarray:
        return self.hi - self.lo

    def diameter(self) -> tuple[float, float]:
        """(lower, upper) bounds on the diameter of P from the ranges."""
        w = self.width
        return float(np.max(w, initial=0.0)), float(np.sqrt(np.sum(w**2)))

    def box(self) -> dict:
        lat = self.system.lattice
        return {"left": lat.left, "right": lat.right, "plane": 0.0}

    def to_dict(self) -> dict:
        """The JSON of `rigidlcp forceset --json` (null for an unbounded end)."""
        lat, c = self.system.lattice, self.c
        out = {"exists": self.exists, "dimension": self.dimension, "box": self.box(),
               "p": lat.p, "c": c, "mu": {"pp": self.system.mu_pp,
                                          "plane": self.system.mu_plane,
                                          "wall": self.system.mu_wall}}
        if not self.exists:
            out["farkas_radius"] = None if self.radius == np.inf else self.radius
            out["farkas_exact"] = self.exact
            if self.exists is None:
                out["undecided"] = self.undecided
            out["contacts"] = [{"i": int(i), "j": int(j), "R": None, "S": None}
                               for i, j in zip(lat.i, lat.j)]
            return out

        def end(v: float):
            return None if not np.isfinite(v) else float(v) + 0.0  # no "-0.0"

        if self.lo is None:  # existence and dimension only
            out["contacts"] = [{"i": int(i), "j": int(j), "implicit": self.implicit[a] or None}
                               for a, (i, j) in enumerate(zip(lat.i, lat.j))]
            out.update(unique=self.dimension == 0, rank_gap=list(self.rank_gap),
                       solution_residuals=list(self.residuals))
            return out

        out["contacts"] = [
            {"i": int(lat.i[a]), "j": int(lat.j[a]),
             "R": [end(self.lo[a]), end(self.hi[a])],
             "S": [end(self.lo[c + a]), end(self.hi[c + a])],
             "implicit": self.implicit[a] or None, "can_slide": bool(self.sliding[a])}
            for a in range(c)]
        lo, hi = self.diameter()
        out.update(solution_residuals=list(self.residuals),
                   unique=self.dimension == 0, rank_gap=list(self.rank_gap),
                   sliding=int(self.sliding.sum()), sliding_bound_2M_3N=self.sliding_bound,
                   diameter=[end(lo), end(hi)], lps=self.lps,
                   unchecked_optima=self.unchecked)
        return out


def analyse(system: models.System, ranges: bool = True, progress=None) -> ForceSet:
    """Existence, dimension, ranges and sliding contacts of P (module docstring).
    progress(done, total, stage): called as the LPs of the ranges are solved."""
    prob = StaticProblem(system)
    weight = float(np.sum(system.masses)) * system.g
    # the IPM is fast, and its point a relative-interior witness; when it finds no point in
    # its box, a Farkas certificate (one LP, IPM) usually settles existence before any
    # simplex (27 CPU s for the equilibrium LP of a 3000-disk pile without equilibrium)
    status, lam = interior_point(prob, 1e3 * weight)
    interior = status == "optimal" and prob.admissible(lam)
    lp = cert = None
    if not interior:
        if status != "optimal":  # HiGHS's IPM says "infeasible" or stops undecided
            cert = farkas(prob)
        if cert is None or not cert.proves:
            lp = ForceLP(prob)
            status, lam = lp.solve(np.zeros(prob.n))
        if cert is not None and cert.proves or status != "optimal" or not prob.admissible(lam):
            cert = cert if cert is not None else farkas(prob)
            if not cert.proves:  # neither a checked solution nor a checked certificate
                return ForceSet(system, None, radius=cert.radius, lps=3,
                                undecided=f"equilibrium LP {status}; Farkas certificate "
                                f"not proved (radius {cert.radius:.3g} weights' units)")
            return ForceSet(system, False, certificate=cert.y, radius=cert.radius, lps=3,
                            exact=cert.exact)
    witness = lam
    if interior and max(prob.residuals(lam)) > 1e-12 * prob.scale:
        # the IPM's point (no crossover) is within its own tolerance, ~1e-8, of P; the
        # reported network is a simplex vertex when that is closer (checked the same way)
        lp = ForceLP(prob)
        status, vertex = lp.solve(np.zeros(prob.n))
        if (status == "optimal" and prob.admissible(vertex)
                and max(prob.residuals(vertex)) < max(prob.residuals(lam))):
            witness = vertex
    fs = ForceSet(system, True, solution=witness, lps=1, residuals=prob.residuals(witness))
    fs.implicit = implicit_equalities(prob, lam if interior else None)
    fs.dimension, fs.rank_gap = dimension(prob, fs.implicit)
    if ranges:
        _ranges(prob, lp or ForceLP(prob), fs, progress)
    return fs


def implicit_equalities(prob: StaticProblem, x: np.ndarray | None = None) -> list[str]:
    """Per contact: "R=0", "S=+muR", "S=-muR" or "" (module docstring). x: a point of P
    near its relative interior, if one is known (else one is computed)."""
    c = prob.c
    # inequality rows: -R <= 0 (c), then S - mu R <= 0 and -S - mu R <= 0 (k each)
    Gi = sp.vstack([-sp.eye(c, prob.n), prob.G], format="csr")
    m = Gi.shape[0]
    T = prob.scale
    undecided = np.ones(m, dtype=bool)
    # One interior point settles most rows at once: a row with a clear positive slack at a
    # point of P is not an implicit equality; the slack LPs then decide only the rest.
    if x is None:
        x = interior_point(prob, 1e3 * float(np.sum(prob.system.masses)) * prob.system.g)[1]
    if x is not None:
        weight = float(np.sum(prob.system.masses)) * prob.system.g
        eq, viol = prob.residuals(x)
        if eq <= 1e-9 * weight and viol <= 1e-9 * weight:
            undecided &= ~(-(Gi @ x) > 1e-6 * T)
    while undecided.any():
        cost = np.r_[np.zeros(prob.n), -undecided.astype(float)]
        A_ub = sp.hstack([Gi, sp.eye(m)], format="csr")
        A_eq = sp.hstack([prob.A, sp.csr_matrix((prob.A.shape[0], m))], format="csr")
        bounds = list(zip(prob.lb, prob.ub)) + [(0, T if u else 0) for u in undecided]
        bounds = [(None if not np.isfinite(lo) else lo, None if not np.isfinite(hi) else hi)
                  for lo, hi in bounds]
        res = linprog(cost, A_ub=A_ub, b_ub=np.zeros(m), A_eq=A_eq, b_eq=prob.b,
                      bounds=bounds, method="highs",
                      options={"primal_feasibility_tolerance": LP_TOL})
        if res.status != 0:
            raise RuntimeError(f"slack LP failed: {res.message}")
        t = np.maximum(res.x[prob.n:], -(Gi @ res.x[:prob.n]))  # the rows' actual slacks
        new = undecided & (t > ZERO * T)
        if not new.any():
            break
        undecided &= ~new
    return labels(prob, undecided)


def labels(prob: StaticProblem, undecided: np.ndarray) -> list[str]:
    """Per contact, the strongest implicit equality among the rows left `undecided` (no slack
    found: -R <= 0 for the c contacts, then S - mu R <= 0 and -S - mu R <= 0 for the k
    frictional ones): "R=0" (implies S = +-mu R = 0), "S=+muR", "S=-muR" or ""."""
    c, k = prob.c, prob.fric.size
    out = [""] * c
    for a in range(c):
        if undecided[a]:
            out[a] = "R=0"
    for n, a in enumerate(prob.fric):
        if out[a]:
            continue
        plus, minus = undecided[c + n], undecided[c + k + n]
        # S = mu R and S = -mu R both on all of P give 2 mu R = 0: R = 0 (which implies both)
        if (plus and minus) or ((plus or minus) and not _positive_R(prob, a)):
            out[a] = "R=0"
        elif plus or minus:
            out[a] = "S=+muR" if plus else "S=-muR"
    return out


def _positive_R(prob: StaticProblem, a: int) -> bool:
    """Is R_a > 0 somewhere on P? One LP, max R_a, its optimum checked against P. The slack
    LPs decide R_a >= 0 from points within the LP's tolerance of P, where R_a ~ 1e-9 can be
    rounding on a set with R_a = 0 throughout (a 2-disk pile at mu 0.988 was labelled
    "S=+muR" so); a contact labelled S = +-mu R must have a checked witness of R > 0."""
    bounds = [(None if not np.isfinite(lo) else lo, None if not np.isfinite(hi) else hi)
              for lo, hi in zip(prob.lb, prob.ub)]
    cost = np.zeros(prob.n)
    cost[a] = -1.0
    res = linprog(cost, A_ub=prob.G, b_ub=np.zeros(prob.G.shape[0]), A_eq=prob.A, b_eq=prob.b,
                  bounds=bounds, method="highs")
    if res.status == 3:  # unbounded: R_a takes every large value on P
        return True
    return bool(res.status == 0 and prob.admissible(res.x) and res.x[a] > ZERO * prob.scale)


def reduced_balance(prob: StaticProblem, implicit: list[str]) -> sp.csc_matrix:
    """The balance matrix on the unknowns left once the implicit equalities are substituted:
    per contact none (R = 0), one column A_R +- mu A_S (S = +-mu R; or A_R when mu = 0), or
    two (A_R, A_S)."""
    A = sp.csc_matrix(prob.A)
    c, mu = prob.c, prob.mu
    cols = []
    for a in range(c):
        kind = implicit[a]
        if kind == "R=0":
            continue
        if mu[a] == 0:
            cols.append(A[:, a])
        elif kind:
            cols.append(A[:, a] + (mu[a] if kind == "S=+muR" else -mu[a]) * A[:, c + a])
        else:
            cols += [A[:, a], A[:, c + a]]
    return sp.hstack(cols, format="csc") if cols else sp.csc_matrix((A.shape[0], 0))


def dimension(prob: StaticProblem, implicit: list[str]
              ) -> tuple[int | None, tuple[float | None, float | None]]:
    """(dim P, (smallest singular value kept, largest dropped)); None when the rank is not
    settled (rank deficient above the dense limit)."""
    B = reduced_balance(prob, implicit)
    B = B[np.flatnonzero(np.diff(B.tocsr().indptr))]  # rows that are exactly zero: rank 0
    if B.shape[1] == 0 or B.shape[0] == 0:
        return B.shape[1], (None, None)
    full = _full_row_rank(B)
    if full is not None:
        return B.shape[1] - B.shape[0], (full, None)
    if B.shape[1] > DENSE_RANK_LIMIT:
        return None, (None, None)
    w = np.linalg.svd(B.toarray(), compute_uv=False)
    tol = max(B.shape) * np.finfo(float).eps * float(w[0])
    rank = int(np.sum(w > tol))
    kept = float(w[rank - 1]) if rank else None
    dropped = float(w[rank]) if rank < w.size else None
    return B.shape[1] - rank, (kept, dropped)


def _full_row_rank(B: sp.csr_matrix) -> float | None:
    """sigma_min(B) when B (rows <= columns) has full row rank beyond doubt, else None.

    The extreme eigenvalues of B B^T (sparse: shift-invert at 0 for the smallest) give
    sigma_min and sigma_max; rank = rows by the SVD's own rule (sigma_min > max(shape) eps
    sigma_max) is accepted only with a wide margin, sigma_min > 1e-6 sigma_max, since the
    eigenvalues of B B^T carry an absolute error ~ eps sigma_max^2 (else the dense SVD, or
    None, decides)."""
    from scipy.sparse.linalg import ArpackError, ArpackNoConvergence, eigsh

    rows, cols = B.shape
    if rows > cols:
        return None
    C = (B @ B.T).tocsc()
    if rows < 3:
        ev = np.linalg.eigvalsh(C.toarray())
        lo, hi = float(ev[0]), float(ev[-1])
    else:
        try:
            hi = float(eigsh(C, k=1, which="LA", return_eigenvectors=False, tol=1e-6)[0])
            lo = float(eigsh(C, k=1, sigma=0.0, which="LM", return_eigenvectors=False,
                             tol=1e-6)[0])
        except (ArpackError, ArpackNoConvergence, RuntimeError, ValueError):
            return None  # e.g. C exactly singular: the factorization at sigma = 0 fails
    if hi <= 0 or lo <= 0:
        return None
    smin, smax = np.sqrt(lo), np.sqrt(hi)
    return float(smin) if smin > 1e-6 * smax else None


def _ranges(prob: StaticProblem, lp: ForceLP, fs: ForceSet, progress) -> None:
    """The ranges, with LPs skipped where a checked point of P already attains a bound that
    holds on all of P: min R = 0 (R >= 0) when some checked optimum has R = 0, and
    max S = mu max R (S <= mu R) or min S = -mu max R when one has S = +-mu max R. Witness
    values are within 1e-9 of the force scale of the bound, as LP optima are."""
    c, n, mu = prob.c, prob.n, prob.mu
    lo, hi = np.zeros(n), np.zeros(n)
    seen = np.zeros(c, dtype=bool)  # contacts found at |S| = mu R, R > 0 at some optimum
    r_min = fs.solution[:c].copy()  # smallest R, largest and smallest S at checked points
    s_max, s_min = fs.solution[c:].copy(), fs.solution[c:].copy()
    todo = [a for a in range(c) if fs.implicit[a] != "R=0"]
    total = len(todo) * 2 + sum(1 for a in todo if mu[a] > 0 and not fs.implicit[a]) * 2
    done = 0

    def tol(lam: np.ndarray | None = None) -> float:
        big = float(np.max(np.abs(lam), initial=0.0)) if lam is not None else 0.0
        return 1e-9 * max(prob.scale, big)

    def bound(k: int, sgn: float) -> float:
        nonlocal done
        e = np.zeros(n)
        e[k] = sgn
        status, lam = lp.solve(e)
        fs.lps += 1
        done += 1
        if status == "unbounded":
            return -sgn * np.inf
        if status != "optimal":
            raise RuntimeError(f"range LP {status} on a non-empty P (please report)")
        ok = prob.admissible(lam)
        fs.unchecked += not ok
        if ok:
            seen[:] |= _at_bound(prob, lam)
            np.minimum(r_min, lam[:c], out=r_min)
            np.maximum(s_max, lam[c:], out=s_max)
            np.minimum(s_min, lam[c:], out=s_min)
        return float(lam[k])

    for a in todo:
        hi[a] = bound(a, -1.0)
        if r_min[a] <= ZERO * prob.scale:  # R = 0 attained: min R = 0
            lo[a] = max(float(r_min[a]), 0.0)
            done += 1
        else:
            lo[a] = bound(a, 1.0)
        kind = fs.implicit[a]
        if mu[a] > 0 and kind:  # S = +- mu R on all of P
            sg = mu[a] if kind == "S=+muR" else -mu[a]
            lo[c + a], hi[c + a] = sorted((sg * lo[a], sg * hi[a]))
        elif mu[a] > 0:
            top = mu[a] * hi[a]
            if np.isfinite(top) and s_max[a] >= top - tol():
                hi[c + a] = min(float(s_max[a]), top)
                done += 1
            else:
                hi[c + a] = bound(c + a, -1.0)
            if np.isfinite(top) and s_min[a] <= -top + tol():
                lo[c + a] = max(float(s_min[a]), -top)
                done += 1
            else:
                lo[c + a] = bound(c + a, 1.0)
        if progress:
            progress(done, total, "ranges")
    fs.lo, fs.hi = lo, hi
    fs.sliding = _sliding(prob, lp, fs, seen)


def _at_bound(prob: StaticProblem, lam: np.ndarray) -> np.ndarray:
    """Contacts at the Coulomb bound with R > 0 at a checked point of P (|S| >= mu R up to
    1e-9 of the force scale, R > ZERO x scale): witnesses that they can slide."""
    c, mu = prob.c, prob.mu
    R, S = lam[:c], lam[c:]
    tol = 1e-9 * max(prob.scale, float(np.max(np.abs(lam), initial=0.0)))
    return (mu > 0) & (R > ZERO * prob.scale) & (np.abs(S) >= mu * R - tol)


def _sliding(prob: StaticProblem, lp: ForceLP, fs: ForceSet,
             seen: np.ndarray | None = None) -> np.ndarray:
    """Whether S = +-mu R with R > 0 is attainable at each contact (module docstring);
    seen: contacts already found at the bound at a checked optimum (no LP needed)."""
    c, k = prob.c, prob.fric.size
    out = np.zeros(c, dtype=bool) if seen is None else seen.copy()
    for n, a in enumerate(prob.fric):
        kind = fs.implicit[a]
        if kind == "R=0" or out[a]:
            continue
        if kind:
            out[a] = fs.hi[a] > ZERO * prob.scale
            continue
        for row in (n, k + n):
            lp.set_cone_row(row, True)
            e = np.zeros(prob.n)
            e[a] = -1.0
            status, lam = lp.solve(e)
            fs.lps += 1
            lp.set_cone_row(row, False)
            if status == "unbounded" or (status == "optimal" and lam[a] > ZERO * prob.scale):
                out[a] = True
                break
    return out
