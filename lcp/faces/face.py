"""A canonical solution on the face of an LCP solution (for problems whose solution is not unique).

Let z solve w = M z + q, 0 <= z perp w >= 0, and let A = {i : w_i = 0} (the indices where z may
be positive). The face of z,

    F(z) = { y : y_A >= 0, y_{A^c} = 0, (M y + q)_A = 0, (M y + q)_{A^c} >= 0 },

is a convex polyhedron of solutions that share z's complementary pattern (every y in F(z) is a
solution). When M_AA is nonsingular F(z) = {z}. Otherwise two methods can return two different
points of the same face; `face_minimum_norm` returns a point of F(z) that depends only on the
face, not on the point a method found: lexicographically, first the minimum of a linear
functional c'y when `c` is given (a linear program), then, among those minimizers, the unique
minimizer of |G y|^2 + eps |y - z'|^2 (G: a linear map, e.g. from LCP unknowns to contact
forces; z': the point the linear stage ended at, or z; eps = 1e-10 is a tie-break, which matters
only where G is not injective on the face).

`face_minimum_norm` is local: it walks from the given solution over neighbouring faces, so two
solutions in different parts of the solution set can lead to different points.
`global_minimum_norm` is not: it minimizes c'y over the whole solution set by a mixed-integer
linear program (big-M bounds supplied by the caller), then takes the least |G y| on the
minimizer's face. It is slower and is what makes a result independent of the method.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..problems.problem import LCP
from .face_coords import _Face, small_lp, small_qp
from .face_reference import _face_lp, _qp

SOLVERS = ("small", "reference")


@dataclass
class FaceResult:
    z: np.ndarray
    nullity: int  # dimension of the null space of M_AA (0: the face is one point)
    moved: float  # max |z_new - z|
    status: str  # "unique", "selected", or "failed: ..." (then z is the input)


def face_minimum_norm(
    problem: LCP,
    z: np.ndarray,
    G: np.ndarray | None = None,
    *,
    c: np.ndarray | None = None,
    tol: float | None = None,
    eps: float = 1e-10,
    max_walk: int = 20,
    z_side: np.ndarray | None = None,
    solvers: str = "small",
) -> FaceResult:
    """The point of the face of z minimizing c'y, then |G y| (see the module docstring).

    z_side: a boolean mask prescribing, for every degenerate pair (z_i = w_i = 0), the side of
    the face: True lets z_i grow (w_i = 0 kept), False lets w_i grow (z_i = 0 kept). Then each
    step of the walk minimizes over that one face; without it both extreme faces are tried.

    With `c`, the linear stage walks from face to face: a minimizer of c'y on the face of z is
    again a solution, whose own face (its degenerate indices, z_i = w_i = 0, may now go either
    way) can hold a lower c'y; the walk stops when c'y no longer decreases (at most max_walk
    linear programs), so it reaches a local minimum of c'y over the solution set.

    solvers: "small" (default) solves both programs in the face's own coordinates
    y_A = z_A + N x, x of dimension nullity(M_AA), by DAQP (lcp.face_coords); "reference" solves
    them in the unknowns y_A by HiGHS and Clarabel with an SVD null space (the code before
    issue 13, lcp.face_reference). Both give the same point to rounding where the linear
    program's minimizer is unique (tests/lcp/test_face_paths.py). "small" falls back to
    "reference" when one of its programs is not solved or not proved optimal.
    """
    if solvers not in SOLVERS:
        raise ValueError(f"solvers must be one of {SOLVERS}, got {solvers!r}")
    M, q = problem.M, problem.q
    z0 = np.asarray(z, dtype=float)
    scale = max(np.abs(q).max(initial=0.0), np.abs(z0).max(initial=0.0), 1e-300)
    tol = 1e-9 * scale if tol is None else tol
    walk = _Walk(M, q, tol, z_side, solvers == "small")
    try:
        return walk.select(z0, G, c, eps, max_walk, scale)
    except _SmallFailed:  # a small program not solved (or not proved optimal): as before
        return face_minimum_norm(problem, z0, G, c=c, tol=tol, eps=eps, max_walk=max_walk,
                                 z_side=z_side, solvers="reference")


class _SmallFailed(Exception):
    pass


class _Walk:
    """The two stages of face_minimum_norm with one kind of solver: "small" (the face's
    coordinates, lcp.face_coords; faces kept by support so that the final stage reuses the null
    space of the linear stage's face) or "reference" (lcp.face_reference, SVD null space)."""

    def __init__(self, M, q, tol, z_side, small: bool):
        self.M, self.q, self.tol, self.z_side, self.small = M, q, tol, z_side, small
        self.faces: dict[bytes, tuple[_Face, np.ndarray]] = {}  # small: face, its LP minimizer
        self.origin: bytes | None = None  # small: the face whose LP minimizer is the current z
        self.w: np.ndarray | None = None  # M z + q at the last z given to supports()

    def supports(self, z: np.ndarray) -> tuple[np.ndarray, ...]:
        """The candidate faces of z: for degenerate pairs both sides (A = {w <= tol} first), or
        the side prescribed by z_side."""
        w = self.w = self.M @ z + self.q  # kept for the faces built at z
        if self.z_side is None:
            return w <= self.tol, (w <= self.tol) & (z > self.tol)
        return ((w <= self.tol) & ((z > self.tol) | self.z_side),)

    def linear(self, z: np.ndarray, in_A: np.ndarray, c: np.ndarray) -> np.ndarray | None:
        """A minimizer of c'y over the face with support in_A (a vertex for the reference)."""
        if not self.small or not in_A.any():  # an empty face: no program (None)
            return _face_lp(self.M, self.q, np.flatnonzero(in_A), c)
        face = _Face(self.M, self.q, z, self.tol, A=np.flatnonzero(in_A), w=self.w)
        if face.nullity == 0:
            x = np.zeros(0)
        else:
            x = small_lp(c[face.A] @ face.N, face.Aineq, face.bineq)
            if x is None:
                raise _SmallFailed
        self.faces[np.packbits(in_A).tobytes()] = (face, x)
        return face.point(x)

    def descend(self, z: np.ndarray, c: np.ndarray, max_walk: int, scale: float
                ) -> tuple[np.ndarray, float]:
        """Stage 1: descend c'y over faces (module doc); the last point and its c'y."""
        slack = 1e-11 * max(abs(c @ z), scale)
        seen: set[bytes] = set()
        for _ in range(max_walk):
            best, origin = None, None
            for in_A in self.supports(z):  # degenerate pairs: both sides, or the prescribed one
                key = np.packbits(in_A).tobytes()
                if key in seen:  # a face already minimized over
                    continue
                seen.add(key)
                z1 = self.linear(z, in_A, c)
                if z1 is not None and (best is None or c @ z1 < c @ best):
                    best, origin = z1, key
            if best is None or c @ best >= c @ z - slack:
                break
            z, self.origin = best, origin
        return z, float(c @ z)

    def final_face(self, z: np.ndarray) -> tuple[_Face, np.ndarray]:
        """The face of z (its first support) and the coordinates xc of z on it."""
        in_A = self.supports(z)[0]
        if not self.small:
            return _Face(self.M, self.q, z, self.tol, A=np.flatnonzero(in_A), null="svd"), None
        key = np.packbits(in_A).tobytes()
        face, x = self.faces.get(key, (None, None))
        if face is not None and face.z is z:  # built at z
            return face, np.zeros(face.nullity)
        if face is not None and key == self.origin:  # z is this face's LP minimizer
            return face, x
        face = _Face(self.M, self.q, z, self.tol, A=np.flatnonzero(in_A), w=self.w)
        return face, np.zeros(face.nullity)

    def select(self, z0, G, c, eps, max_walk, scale) -> FaceResult:
        M, q = self.M, self.q
        z, bound = z0, None
        if c is not None:  # stage 1, then keep c'y at its minimum
            c = np.asarray(c, dtype=float)
            z, bound = self.descend(z0, c, max_walk, scale)
        face, xc = self.final_face(z)
        if face.nullity == 0:
            moved = float(np.abs(z - z0).max())
            return FaceResult(z, 0, moved, "selected" if moved > 0 else "unique")
        x, status = self.quadratic(face, xc, G, c, bound, eps)
        # Every point returned is checked: an inaccurate one (rounding in a nearly singular
        # face) gives way to the linear stage's point, and that to the solver's own solution.
        limit = max(10.0 * _residual(M, q, z0), 1e-12 * scale)
        for y, label in ((None if x is None else face.point(x), "selected"),
                         (z, "selected (linear stage only)")):
            if y is not None and _residual(M, q, y) <= limit:
                return FaceResult(y, face.nullity, float(np.abs(y - z0).max()), label)
        return FaceResult(z0, face.nullity, 0.0, f"failed: inaccurate face point ({status})")

    def quadratic(self, face: _Face, xc, G, c, bound, eps):
        """Stage 2: min 1/2 |G_A y_A|^2 + eps/2 |y_A - z_A|^2 over the face (y_A = face.z_A +
        N x, z = the point the walk ended at, at x = xc), with c'y = bound after stage 1."""
        q = self.q
        GA = (np.eye(q.size) if G is None else np.asarray(G))[:, face.A]
        GN = GA @ face.N
        P = GN.T @ GN + eps * np.eye(face.nullity)
        f = GN.T @ (GA @ face.z[face.A])
        Aeq = beq = None
        if bound is not None:  # stay on the linear program's optimal set: c'y = its minimum
            Aeq = (c[face.A] @ face.N)[None, :]
            beq = np.array([bound - c @ face.z])
        if not self.small:
            return _qp(P, f, face.Aineq, face.bineq, Aeq, beq)
        x = small_qp(P, f - eps * xc, face.Aineq, face.bineq, Aeq, beq, start=xc)
        if x is None:
            raise _SmallFailed
        return x, "optimal"


@dataclass
class PointCheck:
    point: bool  # proved: the face is {z}, so face_minimum_norm would return z unchanged
    isolated: bool  # proved too: z is an isolated solution of the LCP (strict complementarity)
    A: np.ndarray  # the face's support (as face_minimum_norm takes it)
    sigma_min: float  # least singular value of M_AA (inf when A is empty)
    threshold: float  # what sigma_min had to exceed


def face_is_point(problem: LCP, z: np.ndarray, *, z_side: np.ndarray | None = None,
                  tol: float | None = None, margin: float = 10.0) -> PointCheck:
    """A cheap proof that the face of z is the single point z, i.e. that `face_minimum_norm`
    (same z, z_side, tol) has nothing to select: it would return z itself (status "unique").

    Proof. Take A as face_minimum_norm does: {i : w_i <= tol} with z_side, the indices
    {i : w_i <= tol and (z_i > tol or z_side_i)}. Every y of the face satisfies y_Ac = 0 and
    (M y + q)_A = 0, i.e. M_AA y_A = -q_A. If M_AA is nonsingular, y_A = -M_AA^-1 q_A: the face
    holds at most one point, and z (to tol) is in it, so F(z) = {z}. face_minimum_norm then finds
    no lower c'y on F(z) (its walk stops at once) and its `_Face` has nullity 0: it returns z.
    Nonsingular is decided as `_Face` decides rank -- the singular values of M_AA against
    rank_tol = 1e3 max(|A|) eps max(sigma_max, 1) -- with a margin: sigma_min > margin x
    rank_tol (default 10), so that rounding in the two SVDs cannot make them disagree (the
    singular values are computed to about eps sigma_max, far below rank_tol). Near the
    threshold the answer is "not proved" and the caller runs the selection as before.

    If moreover no pair is degenerate (z_i > tol or w_i > tol for every i: strict
    complementarity), every solution near z has z's pattern, hence lies in F(z) = {z}: z is an
    isolated solution, and so are the quantities linear in z (an event's accelerations and
    forces) -- `isolated`. Without it, other solutions may branch off at the degenerate pairs
    (another face); the face selection does not look there either, so `point` suffices for it.
    """
    M, q = problem.M, problem.q
    z = np.asarray(z, dtype=float)
    w = M @ z + q
    scale = max(np.abs(q).max(initial=0.0), np.abs(z).max(initial=0.0), 1e-300)
    tol = 1e-9 * scale if tol is None else tol
    zero_w = w <= tol
    in_A = zero_w if z_side is None else zero_w & ((z > tol) | np.asarray(z_side, bool))
    A = np.flatnonzero(in_A)
    strict = not np.any(zero_w & (z <= tol))
    if A.size == 0:
        return PointCheck(True, strict, A, np.inf, 0.0)
    sig = np.linalg.svd(M[np.ix_(A, A)], compute_uv=False)
    rank_tol = A.size * np.finfo(float).eps * max(float(sig.max(initial=0.0)), 1.0) * 1e3
    point = bool(sig.min() > margin * rank_tol)
    return PointCheck(point, point and strict, A, float(sig.min()), margin * rank_tol)


def _residual(M: np.ndarray, q: np.ndarray, z: np.ndarray) -> float:
    return float(np.max(np.abs(np.minimum(z, M @ z + q)), initial=0.0))


def global_minimum_norm(
    problem: LCP,
    G: np.ndarray,
    c: np.ndarray,
    z_upper: np.ndarray,
    w_upper: np.ndarray,
    *,
    w_zero: np.ndarray | None = None,
    time_limit: float = 30.0,
    eps: float = 1e-10,
) -> FaceResult:
    """The solution minimizing c'y over every solution of the LCP, then |G y| on its face.

    Mixed-integer program (scipy.optimize.milp, HiGHS): 0 <= y_i <= z_upper_i b_i,
    0 <= w_i <= w_upper_i (1 - b_i), b_i binary; indices in `w_zero` have w_i = 0 imposed and
    no binary. The bounds must hold for the minimizer (the caller derives them, e.g. from a
    known solution with a larger c'y); a minimizer at a bound is reported as "failed". The
    pattern found is then solved exactly: a linear program on its face for c'y, and the
    quadratic program for |G y| as in `face_minimum_norm`.
    """
    from scipy.optimize import Bounds, LinearConstraint, milp

    M, q = problem.M, problem.q
    n = q.size
    zero = np.zeros(n, bool)
    if w_zero is not None:
        zero[np.asarray(w_zero, int)] = True
    free = np.flatnonzero(~zero)
    m = free.size
    # variables [y (n), b (m)]
    rows, lo, hi = [], [], []
    rows.append(np.hstack([M, np.zeros((n, m))]))  # w = M y + q in [0, inf) or {0}
    lo.append(-q)
    hi.append(np.where(zero, -q, np.inf))
    Bz = np.zeros((m, n + m))  # y_i - U b_i <= 0
    Bz[np.arange(m), free] = 1.0
    Bz[np.arange(m), n + np.arange(m)] = -z_upper[free]
    rows.append(Bz)
    lo.append(np.full(m, -np.inf))
    hi.append(np.zeros(m))
    Bw = np.hstack([M[free], np.zeros((m, m))])  # w_i + V b_i <= V - q_i
    Bw[np.arange(m), n + np.arange(m)] = w_upper[free]
    rows.append(Bw)
    lo.append(np.full(m, -np.inf))
    hi.append(w_upper[free] - q[free])
    cons = LinearConstraint(np.vstack(rows), np.concatenate(lo), np.concatenate(hi))
    cost = np.concatenate([c, np.zeros(m)])
    integrality = np.concatenate([np.zeros(n), np.ones(m)])
    bounds = Bounds(np.zeros(n + m), np.concatenate([z_upper, np.ones(m)]))
    res = milp(cost, constraints=cons, integrality=integrality, bounds=bounds,
               options={"time_limit": time_limit, "disp": False})
    if res.status != 0 or res.x is None:
        return FaceResult(np.zeros(n), 0, 0.0, f"failed: milp {res.message}")
    y, b = res.x[:n], res.x[n:] > 0.5
    if np.any(y >= 0.999 * z_upper) or np.any((M @ y + q)[free][~b] >= 0.999 * w_upper[free][~b]):
        return FaceResult(y, 0, 0.0, "failed: a big-M bound is active (bounds too small)")
    A = np.sort(np.concatenate([np.flatnonzero(zero), free[b]]))
    Ac = np.setdiff1d(np.arange(n), A)
    # Exact vertex of the minimizer's face: min c'y, y_A >= 0, (My+q)_A = 0, (My+q)_Ac >= 0.
    from scipy.optimize import linprog

    lp = linprog(c[A], A_eq=M[np.ix_(A, A)], b_eq=-q[A], A_ub=-M[np.ix_(Ac, A)], b_ub=q[Ac],
                 bounds=(0, None), method="highs")
    if lp.status != 0:
        return FaceResult(y, 0, 0.0, f"failed: face LP {lp.message}")
    z = np.zeros(n)
    z[A] = lp.x
    face = _Face(M, q, z, 0.0, A=A)
    if face.nullity == 0:
        return FaceResult(z, 0, 0.0, "selected")
    GA = G[:, face.A]
    GN = GA @ face.N
    P = GN.T @ GN + eps * np.eye(face.nullity)
    Aeq, beq = (c[face.A] @ face.N)[None, :], np.zeros(1)
    x, status = _qp(P, GN.T @ (GA @ z[face.A]), face.Aineq, face.bineq, Aeq, beq)
    if x is None:
        return FaceResult(z, face.nullity, 0.0, f"selected (LP vertex; QP {status})")
    return FaceResult(face.point(x), face.nullity, 0.0, "selected")
