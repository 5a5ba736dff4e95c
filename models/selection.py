"""Selection rules: which point of a non-unique solution set an integrator follows.

An event's LCP (Eq. 2.7) or a Moreau-Jean step's LCP can have a continuum of solutions (a row
self-stress, loops of non-sliding contacts: Sec. III). The event engine and the time-stepper
then follow one point, chosen by a *rule*, a parameter of every run (never a hidden constant):

* "face-min-norm": the least total normal force sum R over a walk on the faces of the solver's
  solution, then the least |lambda| (`lcp.face.face_minimum_norm`): the event engine's default.
* "max-sum-R[:F]": the other end: the largest sum R over the same kind of walk (linear programs
  over the face of the current point, contact states of degenerate pairs on the side that keeps
  contacts closed and non-sliding), started from the "face-min-norm" point. Where sum R is
  unbounded on a face (a self-stress that nothing limits at the event), it stops at the cap
  sum R <= F times the "face-min-norm" point's sum R (F = 2 unless given) and says so.
* "random:SEED": a random point of the face of the "face-min-norm" point: a convex combination
  (Dirichlet(1) weights) of that point and the minimizers of 3 random linear functionals over
  the face (capped as above). The functionals and weights are a function of the face: drawn
  from numpy's default_rng([SEED, fingerprint]), the fingerprint a hash of the face's support
  (which pairs have w = 0 and which z may be positive, i.e. the contact states it fixes;
  `Selection.face_rng`). The same face gives the same point, so a time-stepper run whose
  contact states stop changing can settle (its steady test needs forces unchanged over 20
  steps); another SEED draws another point of each face. The event engine passes its own
  generator instead, default_rng(SEED), one per run (`Selection.rng`): an event is solved
  once and a steady event needs no repetition, while the same point on every return to a face
  can lock a run into a Zeno cycle of events (Fig. 9 under random:1 to random:4).
* "global" (events only): the least sum R over the whole solution set by a MILP.
* "none": the solver's own solution: the time-stepper's default.

Every point a rule returns is a solution of the same LCP (a point of a face of the solution set,
which is convex); the caller re-checks it against the laws as it checks the solver's
(`select` returns the rule's point and a status; the engine and the time-stepper measure its
residual with their own acceptance test and keep the solver's point if it fails).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from rigidlcp.lcp import LCP
from rigidlcp.lcp.faces.face import face_minimum_norm

from .lattice import InvalidSystem

RULES = ("face-min-norm", "max-sum-R", "random", "global", "none")
#: Default cap factor of "max-sum-R" and "random" where sum R is unbounded on a face.
CAP = 2.0
#: Random linear functionals per "random" point (their minimizers are the combination's corners).
CORNERS = 3


class InvalidSelection(InvalidSystem):
    """A selection rule that is not one of RULES, or a malformed seed / cap."""


@dataclass(frozen=True)
class Selection:
    """A parsed rule: "face-min-norm", "max-sum-R" (cap), "random" (seed), "global", "none"."""

    rule: str
    seed: int | None = None
    cap: float = CAP

    @classmethod
    def parse(cls, spec: str | Selection) -> Selection:
        """'face-min-norm', 'max-sum-R', 'max-sum-R:3', 'random:7', 'global' or 'none'."""
        if isinstance(spec, Selection):
            return spec
        if not isinstance(spec, str):
            raise InvalidSelection(f"selection must be a string, got {spec!r}")
        rule, _, arg = spec.partition(":")
        if rule not in RULES:
            raise InvalidSelection(f"selection must be one of {', '.join(RULES)} (random:SEED, "
                                   f"max-sum-R[:CAP]), got {spec!r}")
        if rule == "random":
            try:
                seed = int(arg)
            except ValueError:
                raise InvalidSelection(f"selection 'random' needs its seed: random:SEED (an "
                                       f"integer >= 0), got {spec!r}") from None
            if seed < 0:
                raise InvalidSelection(f"the seed of {spec!r} must be >= 0")
            return cls(rule, seed=seed)
        if rule == "max-sum-R" and arg:
            try:
                cap = float(arg)
            except ValueError:
                cap = np.nan
            if not (np.isfinite(cap) and cap > 1.0):
                raise InvalidSelection(f"the cap of {spec!r} must be a number > 1")
            return cls(rule, cap=cap)
        if arg:
            raise InvalidSelection(f"selection {rule!r} takes no argument, got {spec!r}")
        return cls(rule)

    def __str__(self) -> str:
        if self.rule == "random":
            return f"random:{self.seed}"
        if self.rule == "max-sum-R" and self.cap != CAP:
            return f"max-sum-R:{self.cap:g}"
        return self.rule

    def face_rng(self, support: np.ndarray) -> np.random.Generator:
        """The generator of "random:SEED" on the face of this support (a boolean vector):
        default_rng([SEED, fingerprint]), the fingerprint the first 8 bytes of a BLAKE2b hash
        of the support (stable across runs and processes, unlike Python's hash)."""
        mask = np.asarray(support, dtype=bool).reshape(-1)
        digest = hashlib.blake2b(mask.size.to_bytes(8, "little") + np.packbits(mask).tobytes(),
                                 digest_size=8).digest()
        return np.random.default_rng([int(self.seed or 0), int.from_bytes(digest, "little")])

    def rng(self) -> np.random.Generator | None:
        """One generator per run (the event engine's "random:SEED"); None for other rules."""
        return np.random.default_rng(self.seed) if self.rule == "random" else None


def select(problem: LCP, z: np.ndarray, G: np.ndarray, c: int, stick_side: np.ndarray,
           selection: Selection, rng: np.random.Generator | None = None
           ) -> tuple[np.ndarray, str]:
    """The point of `selection` (not "global" / "none") from the accepted solution z of
    `problem`, whose first c unknowns are the normal forces (or impulses) R; G maps z to the
    forces [R; S]; stick_side: the side of degenerate pairs (see lcp.face.face_minimum_norm).
    Returns (point, status): "selected", "capped" (sum R unbounded: the cap was reached),
    "unique" (the face is a point), or "failed: ..." (then the point is z). rng: "random"'s
    generator (the event engine's, one per run); None (the time-stepper): the face's own,
    `Selection.face_rng` (module doc)."""
    least = np.zeros(problem.n)
    least[:c] = 1.0
    base = face_minimum_norm(problem, z, G, c=least, z_side=stick_side)
    if base.status.startswith("failed"):
        return z, base.status
    z0 = base.z
    if selection.rule == "face-min-norm":
        return z0, base.status
    face = _Face(problem, stick_side, selection.cap * max(float(z0[:c].sum()), 1e-300), c)
    if selection.rule == "max-sum-R":
        return face.walk(z0, -least)
    return face.random_point(z0, rng if rng is not None else
                             selection.face_rng(face.support(z0)))


class _Face:
    """Linear programs over the face of a solution (support A: w_A = 0, z_Ac = 0; degenerate
    pairs on the stick side), with the cap sum R <= cap_R."""

    def __init__(self, problem: LCP, stick_side: np.ndarray, cap_R: float, c: int):
        self.M, self.q, self.side, self.cap_R, self.c = problem.M, problem.q, stick_side, cap_R, c

    def support(self, z: np.ndarray) -> np.ndarray:
        scale = max(float(np.abs(self.q).max(initial=0.0)), float(np.abs(z).max(initial=0.0)),
                    1e-300)
        tol = 1e-9 * scale
        w = self.M @ z + self.q
        return (w <= tol) & ((z > tol) | self.side)

    def lp(self, z: np.ndarray, cost: np.ndarray, capped: bool) -> tuple[str, np.ndarray | None]:
        """min cost'y over the face of z (and sum R <= cap_R when capped)."""
        from scipy.optimize import linprog  # not at import: a default run loads no LP stack

        A = np.flatnonzero(self.support(z))
        if A.size == 0:
            return "empty", None
        Ac = np.setdiff1d(np.arange(self.q.size), A)
        A_ub = -self.M[np.ix_(Ac, A)]
        b_ub = self.q[Ac]
        if capped:
            row = (A < self.c).astype(float)[None, :]
            A_ub, b_ub = np.vstack([A_ub, row]), np.r_[b_ub, self.cap_R]
        res = linprog(cost[A], A_ub=A_ub if A_ub.size else None, b_ub=b_ub if b_ub.size else None,
                      A_eq=self.M[np.ix_(A, A)], b_eq=-self.q[A], bounds=(0.0, None),
                      method="highs", options={"primal_feasibility_tolerance": 1e-10,
                                               "dual_feasibility_tolerance": 1e-10})
        if res.status == 3:
            return "unbounded", None
        if res.status != 0 or res.x is None:
            return f"failed: {res.message}", None
        y = np.zeros(self.q.size)
        y[A] = np.maximum(res.x, 0.0)
        return "optimal", y

    def walk(self, z: np.ndarray, cost: np.ndarray, max_walk: int = 20) -> tuple[np.ndarray, str]:
        """Descend cost'y from face to face (as lcp.face's walk); "capped" once a face is
        unbounded in that direction (the walk then stays on the capped program)."""
        status, capped = "unique", False
        for _ in range(max_walk):
            st, y = self.lp(z, cost, capped)
            if st == "unbounded" and not capped:
                capped = True
                st, y = self.lp(z, cost, capped)
            if st != "optimal":
                return z, (status if st == "empty" else f"failed: {st}")
            if cost @ y >= cost @ z - 1e-11 * max(abs(cost @ z), 1.0):
                break
            z, status = y, "selected"
        return z, ("capped" if capped and status == "selected" else status)

    def random_point(self, z0: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, str]:
        """A Dirichlet(1) combination of z0 and the minimizers of CORNERS random functionals
        over z0's face (capped where the face is unbounded)."""
        corners, capped = [z0], False
        for _ in range(CORNERS):
            cost = rng.standard_normal(self.q.size)
            st, y = self.lp(z0, cost, capped)
            if st == "unbounded":
                capped = True
                st, y = self.lp(z0, cost, capped)
            if st == "optimal":
                corners.append(y)
        weights = rng.dirichlet(np.ones(len(corners)))
        point = np.maximum(np.sum([wk * y for wk, y in zip(weights, corners)], axis=0), 0.0)
        if max(float(np.abs(y - z0).max()) for y in corners) == 0.0:
            return z0, "unique"
        return point, "capped" if capped else "selected"


__all__ = ["CAP", "CORNERS", "RULES", "InvalidSelection", "Selection", "select"]
