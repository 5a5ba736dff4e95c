"""The set of admissible contact forces of a packing at rest (verify.statics.model's P).

`analyse(system)` answers, each answer checked in code:

* exists: a lambda in P (checked against P), or a Farkas certificate that P is empty (virtual
  velocities under which every contact opens or slides within its cone while gravity does
  work): first a local one, moving a cluster of disks with the others fixed, found in small
  windows and checked in exact rational arithmetic (verify.statics.local), else the global
  one, checked in exact rational arithmetic (verify.statics.farkas; on the disks it moves,
  verify.statics.local.support_certificate, at any size). exists is False only with an exact
  certificate; when none passes, exists is None (undecided, with the reason), never a guess,
  and a floating-point certificate found on the way is kept as evidence (`certificate`,
  `radius`: no equilibrium has sum R below it; "farkas_evidence" in the JSON): a radius
  bounds the size of the equilibria, it does not exclude them.
* dimension: of P itself, i.e. of its affine hull. An inequality of P that holds with equality
  on all of P (an implicit equality: R = 0, S = mu R or S = -mu R on the whole set) is found
  by linear programs maximizing slacks t_k in [0, scale] of the undecided rows (a row whose
  slack can be made positive is not implicit; when no undecided row can, all are: at most one
  LP per row, a few in practice). An interior point of P (the analytic centre of P or of a
  face, verify.statics.centre, or failing those HiGHS's IPM without crossover; checked to lie
  in P) decides most rows first: a clearly positive slack there is a witness; the rows left
  are proved implicit by local virtual motions checked in exact arithmetic
  (verify.statics.implicit) before any slack LP runs.
  Then dim P = (number of unknowns left once the implicit equalities are substituted) - rank
  of the balance equations on them (rows dependent within one disk's rows dropped first,
  exactly: hull.locally_dependent): full row rank is settled by the extreme eigenvalues of
  B B^T (sparse, any size) when sigma_min > 1e-6 sigma_max, else by a dense SVD with the
  standard tolerance max(shape) eps sigma_max (the singular values at the cut are reported).
* ranges: [min, max] of every R and S over P (two LPs each, warm-started; +-inf unbounded),
  every optimum checked to lie in P and its value certified by the LP's duals, every infinite
  end proved by a checked ray (verify.statics.contact_ranges; in `jobs` worker processes when
  jobs > 1); an answer failing its check is retried (verify.statics.ends), and an end that no
  retry settles is unknown: NaN in lo / hi, "unknown" in the JSON, with the failed check and
  its measure in `unknown` ("unknown_ends"), never a number nor +-inf.
* sliding: whether |S| = mu R with R > 0 is attainable at each frictional contact (a checked
  optimum of a range LP at the bound is a witness; else an LP with
  that cone row made an equality), and their count against McNamara & Herrmann's 2M - 3N
  (M contacts, N disks): a packing with s contacts simultaneously at the Coulomb bound has
  dim P >= 0 only if s <= 2M - 3N generically.
* diameter: between the widest range and the diagonal of the box of ranges.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from rigidlcp import models

from .centre import analytic_centre
from .contact_ranges import check_jobs, contact_ranges
from .farkas import Certificate, farkas
from .hull import dimension, implicit_equalities
from .local import START_DIAMETERS, scan, support_certificate
from .model import ForceLP, StaticProblem, interior_point


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
    unchecked: int = 0  # ends and sliding verdicts left unknown (their checks failed)
    unknown: list = field(default_factory=list)  # verify.statics.ends.Unknown, per unknown end
    sliding_unknown: np.ndarray | None = None  # (c,) can_slide unknown (sliding False there)
    retried: int = 0  # LP answers that failed their check and were settled by a retry
    residuals: tuple[float, float] = (0.0, 0.0)  # of `solution`: balance, laws (force units)
    lps: int = 0
    exact: bool = False  # the Farkas certificate is checked in exact rational arithmetic
    undecided: str = ""
    moving: np.ndarray | None = None  # a local certificate's disks (the others held fixed)
    gap: float | None = None  # -b . y of `certificate` (|y|_inf = 1)

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
        """(lower, upper) bounds on the diameter of P from the ranges: the widest known range,
        and the diagonal of the box (inf if a range is unbounded, else NaN, unknown, when an
        end is)."""
        w = np.where(np.isinf(self.lo) | np.isinf(self.hi), np.inf, self.width)
        known = w[~np.isnan(w)]
        hi = np.inf if np.any(np.isinf(known)) else float(np.sqrt(np.sum(w**2)))
        return float(np.max(known, initial=0.0)), hi

    def box(self) -> dict:
        lat = self.system.lattice
        return {"left": lat.left, "right": lat.right, "plane": 0.0}

    def to_dict(self) -> dict:
        """The JSON of `rigidlcp forceset --json` (null for an unbounded end, "unknown" for an
        end whose check failed: its evidence in "unknown_ends")."""
        lat, c = self.system.lattice, self.c
        out = {"exists": self.exists, "dimension": self.dimension, "box": self.box(),
               "p": lat.p, "c": c, "mu": {"pp": self.system.mu_pp,
                                          "plane": self.system.mu_plane,
                                          "wall": self.system.mu_wall}}
        if not self.exists:
            out["farkas_radius"] = None if self.radius == np.inf else self.radius
            out["farkas_exact"] = self.exact
            if self.moving is not None:
                out["farkas_disks"] = [int(k) for k in self.moving]
            if self.exists is None:
                out["undecided"] = self.undecided
                if self.certificate is not None:
                    out["farkas_evidence"] = self.evidence()
            out["contacts"] = [{"i": int(i), "j": int(j), "R": None, "S": None}
                               for i, j in zip(lat.i, lat.j)]
            return out

        def end(v: float):
            if np.isnan(v):
                return UNKNOWN
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
             "implicit": self.implicit[a] or None,
             "can_slide": UNKNOWN if self._slide_unknown(a) else bool(self.sliding[a])}
            for a in range(c)]
        lo, hi = self.diameter()
        out.update(solution_residuals=list(self.residuals),
                   unique=self.dimension == 0, rank_gap=list(self.rank_gap),
                   sliding=int(self.sliding.sum()), sliding_bound_2M_3N=self.sliding_bound,
                   diameter=[end(lo), end(hi)], lps=self.lps,
                   unchecked_optima=self.unchecked,
                   unknown_ends=[u.to_dict(c, lat.i, lat.j) for u in self.unknown],
                   retried=self.retried)
        return out

    def evidence(self) -> dict:
        """An undecided existence's floating-point Farkas certificate (not a proof: its exact
        check failed or was out of reach): "radius" (no equilibrium has sum R below it, force
        units; null when y violates no cone row in floating point, which still proves
        nothing: rounding), "radius_weights" (the same in weights), "gap" (-b . y,
        |y|_inf = 1) and "moving_disks" (the disks y moves, largest first, at most 20) of
        "disks_moved"."""
        y = self.certificate.reshape(3, -1)
        move = np.max(np.abs(y), axis=0)
        order = np.argsort(-move, kind="stable")
        moved = int(np.sum(move > 1e-9 * float(np.max(move, initial=0.0))))
        weight = float(np.sum(self.system.masses)) * self.system.g
        radius = None if not np.isfinite(self.radius) else float(self.radius)
        return {"radius": radius, "radius_weights": None if radius is None else radius / weight,
                "gap": self.gap, "disks_moved": moved,
                "moving_disks": [int(k) for k in order[:min(moved, 20)]]}

    def _slide_unknown(self, a: int) -> bool:
        return self.sliding_unknown is not None and bool(self.sliding_unknown[a])


def analyse(system: models.System, ranges: bool = True,
            progress: Callable[[int, int, str], None] | None = None,
            jobs: int = 1, stage: Callable[[str, str], None] | None = None,
            known: dict | None = None,
            record: Callable[[int, str, float], None] | None = None) -> ForceSet:
    """Existence, dimension, ranges and sliding contacts of P (module docstring).
    progress(done, total, stage): called as the range ends are settled (by an LP, a kept basis
    or a bound: verify.statics.contact_ranges.end_count, the total); jobs: worker
    processes for the range LPs (verify.statics.contact_ranges; 1: in this process).
    stage(name, detail): called as each phase before the ranges starts (name: the phase, e.g.
    "existence: interior point"; detail: "" or how far it is, e.g. windows solved), for
    progress on large packings. known, record: range ends settled by an earlier run of the
    same P, and a callback for each end settled now (contact_ranges; resuming)."""
    check_jobs(jobs)  # before any LP
    say = stage or _silent
    prob = StaticProblem(system)
    weight = float(np.sum(system.masses)) * system.g
    # deposited piles lose their equilibrium locally: small windows first (a few LPs per
    # disk, each exactly checked; 0.3 CPU s on the 10^4-disk pile, docs/packings.md, Scale)
    say(WINDOWS, "")
    local = scan(prob, levels=1, progress=lambda n, side: say(WINDOWS, f"{n} windows"))
    if local is not None:
        return _falls(system, local.y, local.disks, local.windows)
    # the IPM is fast, and its point a relative-interior witness; when it finds no point in
    # its box, a Farkas certificate (wider windows, then one LP, IPM) usually settles
    # existence before any simplex (27 CPU s for the equilibrium LP of a 3000-disk pile
    # without equilibrium)
    status, lam = _interior(prob, weight, say)
    interior = status == "optimal" and prob.admissible(lam)
    lp = cert = None
    if not interior:
        if status != "optimal":  # HiGHS's IPM says "infeasible" or stops undecided
            cert = _certificate(prob, say)
        if cert is None or not cert.proves:
            say("existence: equilibrium LP (simplex)", "")
            lp = ForceLP(prob)
            status, lam = lp.solve(np.zeros(prob.n))
        if cert is not None and cert.proves or status != "optimal" or not prob.admissible(lam):
            cert = cert if cert is not None else _certificate(prob, say)
            if not cert.proves:  # neither a checked solution nor an exact certificate
                return _undecided(system, status, cert, weight)
            if isinstance(cert, _Local):
                return _falls(system, cert.y, cert.disks, cert.windows + 1)
            return ForceSet(system, False, certificate=cert.y, radius=cert.radius, lps=3,
                            exact=cert.exact)
    witness = lam
    if interior and prob.p <= VERTEX_MAX_P and max(prob.residuals(lam)) > 1e-12 * prob.scale:
        # the IPM's point (no crossover) is within its own tolerance, ~1e-8, of P; the
        # reported network is a simplex vertex when that is closer (checked the same way);
        # not on large packings: that simplex had not ended after 14 minutes wall (load
        # 6-14) on a 100 x 100 array written as a packing (docs/packings.md, Scale)
        say("a vertex of the admissible set (simplex)", "")
        lp = ForceLP(prob)
        status, vertex = lp.solve(np.zeros(prob.n))
        if (status == "optimal" and prob.admissible(vertex)
                and max(prob.residuals(vertex)) < max(prob.residuals(lam))):
            witness = vertex
    fs = ForceSet(system, True, solution=witness, lps=1, residuals=prob.residuals(witness))
    say("implicit equalities", "")
    fs.implicit = implicit_equalities(prob, lam if interior else None)
    say("dimension (rank of the balance)", "")
    fs.dimension, fs.rank_gap = dimension(prob, fs.implicit)
    if ranges:
        r = contact_ranges(prob, lp, fs.implicit, witness, progress, jobs, known, record)
        fs.lo, fs.hi, fs.sliding = r.lo, r.hi, r.sliding
        fs.sliding_unknown, fs.unknown, fs.retried = r.sliding_unknown, r.unknown, r.retried
        fs.lps += r.lps
        fs.unchecked += r.unchecked
    return fs


def _silent(name: str, detail: str) -> None:
    """analyse's stage callback when none is given."""


#: The first phase's name (stage callback).
WINDOWS = "existence: local certificates in windows"


def _interior(prob: StaticProblem, weight: float, say=_silent
              ) -> tuple[str, np.ndarray | None]:
    """A point deep in P: the analytic centre (verify.statics.centre: 1.5-4.2 CPU s at 10^4
    disks; where P has implicit equalities, the centre of the face where the coordinates that
    vanished are 0) when it passes the check against P, else HiGHS's IPM in a box
    (`interior_point`: 67-111 CPU s there)."""
    say("existence: interior point (analytic centre)", "")
    lam = analytic_centre(prob)
    if lam is not None and prob.admissible(lam):
        return "optimal", lam
    say("existence: interior point (HiGHS IPM)", "")
    return interior_point(prob, 1e3 * weight)


#: The JSON's marker of an end (or a can_slide) whose check failed: not a number, and not
#: null (which is a proved unbounded end).
UNKNOWN = "unknown"

#: Largest number of disks for which the IPM's checked point is replaced by a closer vertex.
VERTEX_MAX_P = 3000


class _Local(Certificate):
    """A local certificate (verify.statics.local) as a Certificate, with its disks."""

    def __init__(self, y: np.ndarray, disks: np.ndarray, gap: float, windows: int):
        super().__init__(y, np.inf, gap, exact=True)
        self.disks, self.windows = disks, windows


def _certificate(prob: StaticProblem, say=_silent) -> Certificate:
    """Wider windows (verify.statics.local), then the global Farkas LP."""
    name = "existence: Farkas certificate in wider windows"
    say(name, "")
    local = scan(prob, start=2 * START_DIAMETERS,
                 progress=lambda n, side: say(name, f"{n} windows, side {side:.3g}"))
    if local is not None:
        return _Local(local.y, local.disks, local.gap, local.windows)
    say("existence: global Farkas certificate (IPM)", "")
    return farkas(prob, exact=_on_support)


def _on_support(prob: StaticProblem, y: np.ndarray) -> Certificate | None:
    """The global Farkas candidate y checked exactly on the disks it moves
    (verify.statics.local.support_certificate), as a _Local certificate."""
    local = support_certificate(prob, y)
    return None if local is None else _Local(local.y, local.disks, local.gap, 0)


def _undecided(system: models.System, status: str, cert: Certificate,
               weight: float) -> ForceSet:
    """Existence undecided: no checked equilibrium and no exact Farkas certificate; a
    floating-point one, when found, kept as evidence (module docstring)."""
    if cert.y is None:
        why = f"Farkas certificate not proved (best radius {cert.radius:.3g})"
    else:
        why = (f"a floating-point Farkas certificate (radius {cert.radius / weight:.3g} "
               "weights) failed the exact check or was out of its reach: the absence of an "
               "equilibrium is not proved")
    return ForceSet(system, None, certificate=cert.y, radius=cert.radius, lps=3,
                    gap=cert.gap if cert.y is not None else None,
                    undecided=f"equilibrium LP {status}; {why}")


def _falls(system: models.System, y: np.ndarray, disks: np.ndarray, lps: int) -> ForceSet:
    """No equilibrium, by an exactly checked certificate moving only `disks`."""
    return ForceSet(system, False, certificate=y, radius=np.inf, lps=lps, exact=True,
                    moving=disks)

