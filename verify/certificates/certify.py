"""Certificates for LCP / MLCP solutions: residuals, acceptance, and a uniqueness verdict.

`certify(problem, solution)` recomputes w from the problem (a solver's own w is never trusted),
measures the residuals relative to the data, and answers three separate uniqueness questions:

* w_unique: is w = M z + q the same for every solution? (relative accelerations)
* z_unique: is z the same for every solution? (forces, for the event LCP)
* pattern_unique: is the complementary pattern unique, i.e. is there exactly one basis alpha
  (z_b = 0, w_a = 0) that admits a solution? This is the paper's vector of contact states, the
  choice of one alternative of Eq. (2.5) / (2.7) per pair. It is z_unique *and* nondegenerate:
  a pair with z_i = w_i = 0 admits both alternatives, so a degenerate solution never has a
  unique pattern, even when z is unique (even for a P-matrix).

pattern_unique => z_unique => w_unique. Each is True, False (with another solution when one was
found) or None (unknown). For an `models.EventProblem` the certificate adds two *observables*:
"forces" lambda = [R; S] = G z and "accelerations" nu' = M^-1 (H^T G z + f). They matter: the
event LCP's w holds, besides a_n and a_plus, the slack 2 mu R - tau, a force; two solutions can
have the same accelerations and different w. For an MLCP the observable "u" (the free unknowns,
the generalized accelerations of an event MLCP) is added.

Acceptance (lcp.residual.check, the same test lcp.solve applies to every "solved"): with
z_s = max(|z|_inf, |q|_inf / |M|_max) and w_s = |q|_inf + ||M||_inf z_s, the scaled residual is
max_i |min(z_i / z_s, w_i / w_s)|; for an MLCP the equality residual max|A u + C v + a| is divided
by |a|_inf + ||A||_inf |u|_inf + ||C||_inf |v|_inf. Accepted iff both are <= tol.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from rigidlcp import lcp
from rigidlcp.lcp import LCP, MLCP, NotApplicable, Solution, enumerate_solutions
from rigidlcp.lcp.acceptance.accuracy import assess_problem
from rigidlcp.lcp.acceptance.residual import check
from rigidlcp.lcp.errors import InvalidInput

from .clocked import check_clock
from .friction import fc_accuracy, forces_map, friction_certificate
from .stages import OTHER, UNIQUE, certify_stages
from .uniqueness import Search, milp_search, p_matrix_test, sign_pattern

#: "auto" enumerates the complementary bases up to this n (2^n bases; singular ones need LPs),
#: and takes the staged path (verify.certificates.stages) beyond it.
ENUM_AUTO_MAX_N = 10
UNIQUENESS_METHODS = ("auto", "p-matrix", "enumeration", "milp", "staged", "none")


@dataclass
class Certificate:
    """What `certify` established about one solution. See the module docstring."""

    accepted: bool
    tol: float
    residual: float  # max|min(z, w)|, unscaled
    scaled_residual: float
    eq_residual: float = 0.0  # MLCP: max|A u + C v + a|
    scaled_eq_residual: float = 0.0
    z_scale: float = 1.0
    w_scale: float = 1.0
    w_unique: bool | None = None
    z_unique: bool | None = None
    pattern_unique: bool | None = None
    observables: dict[str, bool | None] = field(default_factory=dict)
    method: str = "none"
    other: np.ndarray | None = None  # z of another solution, when one was found
    other_reason: str = ""  # what the other solution differs in
    other_distance: float = 0.0  # |z' - z|_inf / z_s
    others: list[np.ndarray] = field(default_factory=list)
    degenerate: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    delta: float = 1e-4
    bound: float | None = None  # the MILP's box 0 <= z <= bound (verdicts relative to it)
    notes: list[str] = field(default_factory=list)
    seconds: float = 0.0
    staged: object | None = None  # uniqueness="staged": the verify.certificates StagedCertificate
    backward_error: float = np.nan  # lcp.accuracy's, of the solution as given (lcp.solve's)
    forward_error: float = np.nan  # lcp.accuracy's bound; accepted needs <= FERR_TOL

    @staticmethod
    def verdict(flag: bool | None) -> str:
        return {True: "unique", False: "another solution exists", None: "unknown"}[flag]

    def __repr__(self) -> str:
        ok = "ACCEPTED" if self.accepted else "REJECTED"
        lines = [
            f"Certificate: {ok} at tol = {self.tol:g}",
            f"  residual        : {self.residual:.3e}  (max|min(z, w)|; scaled "
            f"{self.scaled_residual:.3e}, z_s = {self.z_scale:.3g}, w_s = {self.w_scale:.3g})",
        ]
        if self.eq_residual or self.scaled_eq_residual:
            lines.append(f"  eq_residual     : {self.eq_residual:.3e}  (scaled "
                         f"{self.scaled_eq_residual:.3e})")
        lines.append(f"  errors          : backward {self.backward_error:.3e}, forward bound "
                     f"{self.forward_error:.3e}  (lcp.accuracy)")
        lines.append(f"  uniqueness by   : {self.method}")
        lines.append(f"  w = M z + q     : {self.verdict(self.w_unique)}")
        lines.append(f"  z               : {self.verdict(self.z_unique)}")
        lines.append(f"  pattern (basis) : {self.verdict(self.pattern_unique)}"
                     + (f"  [degenerate pairs: {self.degenerate.tolist()}]"
                        if self.degenerate.size else ""))
        for name, flag in self.observables.items():
            lines.append(f"  {name:<16}: {self.verdict(flag)}")
        if self.other is not None:
            lines.append(f"  other solution  : differs in {self.other_reason}; "
                         f"|z' - z|_inf / z_s = {self.other_distance:.3g}"
                         + (f" ({len(self.others)} found)" if len(self.others) > 1 else ""))
            if self.other.size <= 8:
                lines.append(f"    z' = {np.array2string(self.other, precision=6)}")
        if self.bound is not None:
            lines.append(f"  MILP box        : 0 <= z <= {self.bound:.3g}, margin delta = "
                         f"{self.delta:g} (relative)")
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)


def certify(
    problem, solution, tol: float = 1e-8, uniqueness: str = "auto", *,
    delta: float = 1e-4, bound: float | None = None, time_limit: float = 30.0,
    objective: str = "none", observables: dict[str, np.ndarray] | None = None,
    clock: str = "cpu",
) -> Certificate:
    """Certify `solution` (an `lcp.Solution` or a vector z) of `problem`.

    problem: an `lcp.LCP`, an `lcp.MLCP` (reduced by the Schur complement for the uniqueness
    questions), or a `models.EventProblem` (its LCP, with the observables "forces" and
    "accelerations"). uniqueness: "auto" (P-matrix test; then enumeration for n <= 10, else
    the stages of verify.certificates.stages: the face, other solvers, a MILP per open
    question, as uniqueness="staged"; the MILP instead when objective="min-sum" asks for its
    least-sum witness), "p-matrix", "enumeration", "milp", "staged" or "none". delta: the
    relative margin by which another solution must differ to count (see
    uniqueness.milp_search; the MILP raises it to its rounding floor, 1e-4 with the default
    box; the margin used is reported); bound: the MILP's box (default 1e3 z_s); time_limit:
    seconds per MILP; objective: "none" (the first other solution HiGHS meets) or "min-sum"
    (the other solution of least sum z, e.g. the small-force one; slower: optimality must be
    proved). observables: extra linear maps L (quantity = L z + const) whose uniqueness is
    asked too. clock: how time_limit is counted, "cpu" (this process's CPU seconds, the
    default: a verdict does not depend on the machine's load) or "wall"
    (verify.certificates.clocked); a MILP stopped by it leaves its question undecided (None,
    with the limit in the notes), never a verdict. `seconds`: wall time.
    """
    if uniqueness not in UNIQUENESS_METHODS:
        raise InvalidInput(f"uniqueness must be one of {UNIQUENESS_METHODS}, got {uniqueness!r}")
    for name, value, most in (("tol", tol, np.finfo(float).max),  # -1 read as "REJECTED"
                              ("time_limit", time_limit, np.inf)):
        if not (isinstance(value, (int, float, np.number)) and 0 < value <= most):
            raise InvalidInput(f"{name} must be a number > 0{' (finite)' if name == 'tol' else ''}"
                               f", got {value!r}")
    if solution is None:  # np.asarray(None) has one entry: "the solution has 1 entries"
        raise InvalidInput("certify needs a solution: an lcp.Solution or a vector z "
                           "(lcp.solve(problem) gives one), got None")
    check_clock(clock)
    t0 = time.perf_counter()
    obs: dict[str, np.ndarray] = {}
    fc_residual, fc = None, None
    if isinstance(problem, lcp.FrictionContact2D):
        fc_cert = friction_certificate(problem, solution, tol, uniqueness, Certificate)
        if fc_cert is not None:
            fc_cert.seconds = time.perf_counter() - t0
            return fc_cert
        fc = problem
        problem = fc.to_lcp()
        r = np.asarray(solution.z if isinstance(solution, Solution) else solution, dtype=float)
        solution = fc.lcp_from_r(r)
        obs["forces"] = forces_map(fc)
        fc_residual = lcp.natural_residual(fc, r)
    if hasattr(problem, "lcp") and hasattr(problem, "G") and hasattr(problem, "dyn"):
        ep = problem
        problem = ep.lcp
        obs["forces"] = np.asarray(ep.G, dtype=float)
        obs["accelerations"] = ep.dyn.Minv[:, None] * np.asarray(ep.dyn.H.T @ ep.G)
    if not isinstance(problem, (LCP, MLCP)):
        raise TypeError(f"problem must be an LCP, MLCP or EventProblem, got "
                        f"{type(problem).__name__}")
    z = np.asarray(solution.z if isinstance(solution, Solution) else solution, dtype=float)
    z = z.reshape(-1)
    if z.size != problem.n:
        raise InvalidInput(f"the solution has {z.size} entries, the problem {problem.n} pairs")
    notes: list[str] = []
    lcp_form: LCP | None
    if isinstance(problem, MLCP):
        try:
            lcp_form = problem.to_lcp()
        except NotApplicable as exc:
            lcp_form = None
            notes.append(f"no Schur reduction ({exc}): uniqueness not assessed")
        u = getattr(solution, "u", None) if isinstance(solution, Solution) else None
        if lcp_form is not None:
            Ainv_C = np.linalg.solve(problem.A, problem.C)
            obs["u"] = -Ainv_C
    else:
        lcp_form, u = problem, None
    # The acceptance test is lcp.residual's: the one lcp.solve applies to every "solved".
    chk = check(problem, z, u, tol=tol, lcp_form=lcp_form)
    w, zs, ws = chk.w, chk.z_scale, chk.w_scale
    cert = Certificate(
        accepted=chk.accepted, tol=tol, residual=chk.residual,
        scaled_residual=chk.scaled_residual, eq_residual=chk.eq_residual,
        scaled_eq_residual=chk.scaled_eq_residual, z_scale=zs, w_scale=ws, delta=delta,
        notes=notes,
    )
    # lcp.accuracy's backward error and forward error bound, as lcp.solve reports them: an
    # inflated z or an O(1) forward error is not accepted (issue 23)
    # (a friction-contact answer: on the friction-contact conditions, as lcp.solve judges it)
    acc = (fc_accuracy(fc, r) if fc is not None else
           assess_problem(problem, z, chk.u if isinstance(problem, MLCP) else None,
                          getattr(solution, "basis", None)))
    cert.backward_error, cert.forward_error = acc.berr, acc.ferr
    cert.accepted = cert.accepted and acc.accepted
    if fc_residual is not None:
        notes.append(f"friction contact: relative natural-map residual {fc_residual:.3e}; "
                     "z is its Glocker LCP's, 'forces' its r")
        cert.accepted = cert.accepted and fc_residual <= tol
    for name, L in (observables or {}).items():
        obs[name] = np.atleast_2d(np.asarray(L, dtype=float))
    cert.observables = {name: None for name in obs}
    # Degenerate pairs: z_i and w_i both zero to 100 tol (relative), i.e. beyond doubt at
    # the accuracy the solution was accepted with.
    cert.degenerate = np.flatnonzero(sign_pattern(z, w, zs, ws, 100 * tol) == 0)
    if cert.degenerate.size:
        cert.pattern_unique = False
    if uniqueness == "none" or lcp_form is None:
        cert.seconds = time.perf_counter() - t0
        return cert
    if not cert.accepted:
        notes.append("not a solution at this tolerance: uniqueness not assessed")
        cert.seconds = time.perf_counter() - t0
        return cert
    M, q = lcp_form.M, lcp_form.q
    n = q.size
    if uniqueness == "staged":
        _staged(cert, lcp_form, z, obs, delta, bound, time_limit, clock)
        cert.seconds = time.perf_counter() - t0
        return cert
    method = uniqueness
    if uniqueness in ("auto", "p-matrix"):
        pt = p_matrix_test(M)
        if pt.is_p:
            cert.method = f"P-matrix ({pt.how})"
            cert.w_unique = cert.z_unique = True
            cert.observables = {name: True for name in obs}
            cert.pattern_unique = not cert.degenerate.size
            if cert.degenerate.size:
                notes.append("P-matrix: z and w are unique, but the solution is degenerate "
                             f"at {cert.degenerate.tolist()}: more than one basis admits it")
            cert.seconds = time.perf_counter() - t0
            return cert
        notes.append(f"P-matrix test: {pt.message}")
        if uniqueness == "p-matrix":
            cert.method = "P-matrix (inconclusive)"
            cert.seconds = time.perf_counter() - t0
            return cert
        if n > ENUM_AUTO_MAX_N and objective == "none":  # the stages, cheapest first
            _staged(cert, lcp_form, z, obs, delta, bound, time_limit, clock)
            cert.method = f"staged (auto, n = {n} > {ENUM_AUTO_MAX_N})"
            cert.seconds = time.perf_counter() - t0
            return cert
        method = "enumeration" if n <= ENUM_AUTO_MAX_N else "milp"
    ctx = _Context(cert, M, q, z, w, zs, ws, obs, delta, bound, time_limit, objective, clock)
    if method == "enumeration":
        ctx.by_enumeration(lcp_form)
    else:
        ctx.by_milp()
    cert.seconds = time.perf_counter() - t0
    return cert


def _staged(cert: Certificate, problem: LCP, z: np.ndarray, obs: dict, delta: float,
            bound: float | None, time_limit: float, clock: str) -> None:
    """uniqueness="staged": the verdicts of verify.certificates.stages.certify_stages."""
    staged = certify_stages(problem, z, delta=delta, bound=bound, time_limit=time_limit,
                            clock=clock,
                            observables={"z": np.eye(problem.n), "w": problem.M, **obs})
    flag = {UNIQUE: True, OTHER: False}
    v = staged.verdicts
    cert.method, cert.staged = "staged", staged
    cert.z_unique, cert.w_unique = flag.get(v["z"].verdict), flag.get(v["w"].verdict)
    cert.observables = {name: flag.get(v[name].verdict) for name in obs}
    cert.pattern_unique = flag.get(v["states"].verdict)
    for name, verdict in v.items():
        if verdict.witness is not None:
            cert.others.append(verdict.witness.z)
            if cert.other is None:
                cert.other, cert.other_reason = verdict.witness.z, f"{name} ({verdict.stage})"
                cert.other_distance = verdict.witness.distance
        if verdict.verdict != UNIQUE or verdict.scope:
            cert.notes.append(f"{name}: {verdict.verdict} [{verdict.stage}] {verdict.reason}"
                              + (f" (scope: {verdict.scope})" if verdict.scope else ""))


class _Context:
    """The uniqueness questions for one accepted solution (shared by the two methods)."""

    def __init__(self, cert, M, q, z, w, zs, ws, obs, delta, bound, time_limit, objective,
                 clock="cpu"):
        self.cert, self.M, self.q, self.z, self.w = cert, M, q, z, w
        self.zs, self.ws, self.obs = zs, ws, obs
        self.delta, self.bound, self.time_limit = delta, bound, time_limit
        self.objective, self.clock = objective, clock

    # -- helpers ---------------------------------------------------------------------------
    def differs(self, other: np.ndarray, L: np.ndarray | None) -> bool:
        """Does `other` differ from z by more than delta in the quantity L z (None: z)?"""
        if L is None:
            return bool(np.max(np.abs(other - self.z)) > self.delta * self.zs)
        v = L @ self.z
        sL = max(float(np.max(np.sum(np.abs(L), axis=1))) * self.zs,
                 float(np.max(np.abs(v))), 1e-300)
        return bool(np.max(np.abs(L @ (other - self.z))) > self.delta * sL)

    def record(self, other: np.ndarray, reason: str) -> None:
        cert = self.cert
        if not any(np.array_equal(other, o) for o in cert.others):
            cert.others.append(other)
        if cert.other is None:
            cert.other, cert.other_reason = other, reason
            cert.other_distance = float(np.max(np.abs(other - self.z))) / self.zs

    def search(self, target: str, L: np.ndarray | None) -> Search:
        """One MILP; a 'found' whose difference is tiny is retried once with delta = 1e-2
        (to report a clearly different solution when there is one)."""
        kw = dict(bound=self.bound, time_limit=self.time_limit, objective=self.objective,
                  clock_name=self.clock)
        s = milp_search(self.M, self.q, self.z, target, L, delta=self.delta, **kw)
        self.cert.bound = s.bound
        self.cert.delta = max(self.cert.delta, s.delta)
        if s.status == "found" and s.deviation < 1e-3 and self.delta < 1e-2:
            s2 = milp_search(self.M, self.q, self.z, target, L, delta=1e-2, **kw)
            if s2.status == "found":
                return s2
        return s

    def value_question(self, name: str, L: np.ndarray, implied: bool | None) -> bool | None:
        """Unique value of L z? Implied by z_unique; else any known other solution; else MILP."""
        if implied:
            return True
        for other in self.cert.others:
            if self.differs(other, L):
                return False
        s = self.search("values", L)
        if s.status == "found":
            self.record(s.other, name)
            return False
        if s.status == "none":
            return True
        self.cert.notes.append(f"{name}: {s.message}")
        return None

    def finish(self) -> None:
        cert = self.cert
        cert.w_unique = self.value_question("w", self.M, cert.z_unique)
        for name, L in self.obs.items():
            cert.observables[name] = self.value_question(name, L, cert.z_unique)
        if cert.z_unique is False:
            cert.pattern_unique = False
        elif cert.z_unique is True and not cert.degenerate.size:
            cert.pattern_unique = True
        if cert.bound is not None:
            cert.notes.append(f"MILP verdicts are relative to the box 0 <= z <= {cert.bound:.3g}"
                              " and to the margin delta")

    # -- the two methods -------------------------------------------------------------------
    def by_milp(self) -> None:
        cert = self.cert
        cert.method = "milp"
        s = self.search("pattern", None)
        if s.status == "found":
            cert.z_unique = False
            self.record(s.other, "z (another complementary pattern)")
        elif s.status == "none":
            cert.z_unique = True
        else:
            cert.notes.append(f"z: {s.message}")
        self.finish()

    def by_enumeration(self, problem: LCP) -> None:
        cert = self.cert
        cert.method = "enumeration"
        sols = enumerate_solutions(problem)
        continuum = any(s.info.get("continuum") for s in sols)
        found_self = False
        for s in sols:
            if self.differs(s.z, None):
                self.record(s.z, "z")
            else:
                found_self = True
        if not found_self:
            cert.notes.append("the enumeration did not reproduce this solution (tolerances)")
        if cert.others:
            cert.z_unique = False
        elif continuum:
            cert.notes.append("enumeration: this solution lies in a continuum of solutions")
            cert.z_unique = False
            s = self.search("pattern", None)
            if s.status == "found":
                self.record(s.other, "z (continuum)")
        else:
            cert.z_unique = True
        if cert.z_unique is False and not continuum:
            # finitely many solutions, all listed: the value questions are decided by them
            cert.w_unique = not any(self.differs(o, self.M) for o in cert.others)
            for name, L in self.obs.items():
                cert.observables[name] = not any(self.differs(o, L) for o in cert.others)
            cert.pattern_unique = False
            return
        if continuum:
            cert.method = "enumeration + milp (continuum)"
        self.finish()
