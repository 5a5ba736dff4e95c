"""Uniqueness of observables of an LCP solution, decided in stages, cheapest first.

`certify_stages(problem, solution)` asks, for each observable L (for an event: the forces
lambda = G z and the accelerations nu' = M^-1 (H^T G z + f), Sec. III A of the paper; for a bare
LCP: z and w), whether L z is the same for every solution. Stages, each verdict checked before
it is returned:

0. residual (lcp.residual.check, verify.certify's test, tol 1e-8): a rejected solution gets
   no verdict; the P-matrix test (verify.certificates.pmatrix.p_matrix_test): P => every
   observable unique.
a. the face (verify.certificates.faces): with the contact states of z* kept (degenerate pairs
   free), the directions N of the affine set A(z*). Where L N != 0, linear programs over the two
   faces F_D, F_0 give the range [min, max] of each moving row of L; a vertex where L differs
   from L z* by more than the margin is a witness: "another solution exists (same contact
   states)".
b. L N = 0 (rank, with a clear spectral gap): L is constant over every solution with these
   contact states: "unique within the face". Not a global verdict: the next stage runs.
c. other contact states: (c1) other solvers (Lemke with random covering vectors, the contact-
   state iteration from random active sets), each answer verified, any that differs in L is a
   witness; (c2) the MILP of verify.uniqueness.milp_search ("values" target) in a box that
   contains every solution seen (at least 1e3 z_s), with a time limit. "none" => "unique"
   (within the box, to the margin; global when verify.certificates.bounds proves that no
   solution has |z|_1 >= the box, which is said in the verdict's scope); a MILP that stopped,
   or that cut bases it could not confirm, => "unknown" with the reason.

Every witness is re-checked by `independent_residual` (w recomputed in extended precision) and
its difference in L measured against the margin delta (relative to s_L = max(|L|_inf z_s,
|L z*|_inf), as in verify.certify).

The states verdict ("is the vector of contact states determined?") is "another solution exists"
when z* is degenerate (a pair with z_i = w_i = 0 admits both states) or a witness changes the
sign pattern; "unique" when the forces and accelerations are unique and z* is nondegenerate
(then R, a_n and a_t, hence every contact state, are fixed); "unknown" otherwise.
"""

from __future__ import annotations

import time

import numpy as np

from rigidlcp.lcp import LCP, Solution, solve
from rigidlcp.lcp.acceptance.residual import check

from .bounds import no_solution_beyond
from .clocked import check_clock
from .clocked import clock as clock_of
from .faces import FaceLP, null_directions
from .uniqueness import BOUND_FACTOR, milp_search, p_matrix_test, scales, sign_pattern
from .verdicts import (  # noqa: F401  (re-exported: the names users import from here)
    OTHER,
    UNIQUE,
    UNKNOWN,
    StagedCertificate,
    Verdict,
    Witness,
)


def independent_residual(M: np.ndarray, q: np.ndarray, z: np.ndarray) -> float:
    """max_i |min(z_i / z_s, w_i / w_s)| with w = M z + q recomputed in extended precision
    (numpy longdouble), independently of any solver's w."""
    zs, ws = scales(M, q, z)
    w = (M.astype(np.longdouble) @ z.astype(np.longdouble) + q.astype(np.longdouble))
    return float(np.max(np.abs(np.minimum(z / zs, w / ws)), initial=0.0))


def observables_of(problem) -> tuple[LCP, dict[str, np.ndarray]]:
    """The LCP and its observables: an EventProblem's forces and accelerations; an LCP's z, w."""
    if hasattr(problem, "lcp") and hasattr(problem, "G") and hasattr(problem, "dyn"):
        G = np.asarray(problem.G, dtype=float)
        acc = problem.dyn.Minv[:, None] * np.asarray(problem.dyn.H.T @ G)
        return problem.lcp, {"accelerations": acc, "forces": G}
    if isinstance(problem, LCP):
        return problem, {"z": np.eye(problem.n), "w": np.asarray(problem.M, dtype=float)}
    raise TypeError(f"problem must be an LCP or an EventProblem, got {type(problem).__name__}")


def certify_stages(
    problem, solution, *, tol: float = 1e-8, delta: float = 1e-4, time_limit: float = 10.0,
    tries: int = 8, bound: float | None = None, milp: bool = True, seed: int = 0,
    ranges: bool = True, observables: dict[str, np.ndarray] | None = None,
    clock: str = "cpu",
) -> StagedCertificate:
    """Decide uniqueness of each observable of `solution` (stages 0, a, b, c above).

    problem: an `lcp.LCP` or a `models.EventProblem`; solution: an `lcp.Solution` or z.
    delta: relative margin for "differs"; time_limit: seconds of MILP per question (c2);
    tries: other-solver attempts (stage c1); bound: the MILP box (default: 1e3 z_s, raised to
    contain every solution seen); milp: False stops after stage c1 ("unknown" if undecided);
    ranges: also the range of every moving row of each observable over the face (two LPs
    per row and face; False: only the witness LPs, the ranges are then NaN where they move);
    observables: replace the default ones by {name: L}. clock: how time_limit is counted,
    "cpu" (this process's CPU seconds, the default: the verdicts do not depend on the
    machine's load) or "wall" (verify.certificates.clocked); a question stopped by it is
    "unknown" with the limit as its reason. Every `seconds` reported is wall time.
    """
    check_clock(clock)  # a wrong clock refused before any work
    t0 = time.perf_counter()
    lcp, obs = observables_of(problem)
    if observables is not None:
        obs = {k: np.atleast_2d(np.asarray(v, dtype=float)) for k, v in observables.items()}
    z = np.asarray(solution.z if isinstance(solution, Solution) else solution, dtype=float)
    base = check(lcp, z, None, tol=tol, lcp_form=lcp)  # verify.certify's acceptance test
    out = StagedCertificate(base.accepted, base.scaled_residual, lcp.n,
                            {k: Verdict(k) for k in obs})
    if not base.accepted:  # every question, the contact states' too, without a verdict
        if observables is None:
            out.verdicts.setdefault("states", Verdict("states"))
        for v in out.verdicts.values():
            v.stage, v.reason = "residual", f"not a solution at tol {tol:g}: no verdict"
        out.seconds = time.perf_counter() - t0
        return out
    run = _Stages(lcp.M, lcp.q, z, obs, out, delta, seed, ranges)
    run.p_matrix()
    run.face()
    run.other_solvers(tries)
    if milp:
        run.milp(time_limit, bound, clock)
    for v in out.verdicts.values():
        if v.verdict == UNKNOWN and not v.reason:
            v.reason = "undecided after the face stage and the other solvers (MILP not run)"
    run.states()
    out.seconds = time.perf_counter() - t0
    return out


class _Stages:
    """The stages for one accepted solution (shared state: the pattern, scales, witnesses)."""

    def __init__(self, M, q, z, obs, out: StagedCertificate, delta: float, seed: int,
                 ranges: bool):
        self.M, self.q, self.z, self.obs, self.out = M, q, z, obs, out
        self.ranges = ranges
        self.delta, self.rng = delta, np.random.default_rng(seed)
        self.zs, self.ws = scales(M, q, z)
        self.pat = sign_pattern(z, M @ z + q, self.zs, self.ws, 1e-6)
        out.degenerate = np.flatnonzero(self.pat == 0).tolist()
        self.seen: list[np.ndarray] = []  # verified other solutions

    def open(self) -> list[Verdict]:
        return [v for v in self.out.verdicts.values() if v.verdict == UNKNOWN]

    def s_L(self, L: np.ndarray) -> float:
        return max(float(np.max(np.sum(np.abs(L), axis=1))) * self.zs,
                   float(np.max(np.abs(L @ self.z))), 1e-300)

    def witness(self, y: np.ndarray, L: np.ndarray, found_by: str) -> Witness | None:
        """y as a witness for L, if it is a solution (independent residual <= 1e-8) and
        differs in L by more than delta s_L."""
        res = independent_residual(self.M, self.q, y)
        diff = float(np.max(np.abs(L @ (y - self.z)))) / self.s_L(L)
        if res > 1e-8 or diff <= 0.99 * self.delta:  # (the MILP polishes to 0.999 delta)
            return None
        pat = sign_pattern(y, self.M @ y + self.q, self.zs, self.ws, 1e-6)
        # a pair changes state when it flips (z_i > 0 <-> w_i > 0); reaching a degenerate
        # 0 (a vertex of the face) is not a change
        changed = np.flatnonzero(pat * self.pat == -1).tolist()
        left = np.flatnonzero((self.pat == 0) & (pat != 0)).tolist()
        return Witness(y, res, float(np.max(np.abs(y - self.z))) / self.zs, diff, changed,
                       not changed, found_by, left)

    def decide(self, v: Verdict, verdict: str, stage: str, reason: str, t: float,
               witness: Witness | None = None, scope: str = "") -> None:
        v.verdict, v.stage, v.reason, v.witness, v.scope = verdict, stage, reason, witness, scope
        v.seconds += time.perf_counter() - t

    # -- stage 0 -----------------------------------------------------------------------------
    def p_matrix(self) -> None:
        t = time.perf_counter()
        pt = p_matrix_test(self.M)
        self.out.log.append(f"p-matrix: {pt.message} [{time.perf_counter() - t:.3f} s]")
        if pt.is_p:
            for v in self.open():
                self.decide(v, UNIQUE, "p-matrix", pt.message, t, scope="global")

    # -- stages a and b ----------------------------------------------------------------------
    def face(self) -> None:
        t = time.perf_counter()
        M, q, z = self.M, self.q, self.z
        P, D = self.pat == 1, self.pat == 0
        nd = null_directions(M, P, D)
        self.out.face_dim = nd.dim
        lps = {side: None for side in ("z", "w")} if D.any() else {"z": None}
        n_lp = 0
        for v in self.open():
            tv = time.perf_counter()
            L = self.obs[v.name]
            val = L @ z
            v.lo, v.hi = val.copy(), val.copy()
            moving = np.flatnonzero(nd.moves(L, self.zs) > 1e-9) if nd.dim else np.zeros(0, int)
            if moving.size == 0:
                if nd.gap_ok:
                    self.decide(v, UNKNOWN, "face (b)",
                                f"unique within the face: {v.name} constant on the "
                                f"{nd.dim}-dim. directions of the contact states (rank, gap "
                                f"{nd.kept_min:.1e} / {nd.rank_tol:.1e})", tv)
                else:
                    v.reason = "face (b): rank gap unclear, no proof within the face"
                continue
            if not self.ranges:
                v.lo[moving] = v.hi[moving] = np.nan
            best: tuple[float, np.ndarray | None] = (0.0, None)
            # one LP along a random combination of the moving rows first (the witness), then,
            # when asked, the range of every moving row (two LPs each, on each face)
            mix = self.rng.choice((-1.0, 1.0), moving.size) @ L[moving]
            jobs = [(None, 1.0, mix), (None, -1.0, -mix)]
            if self.ranges:
                jobs += [(j, sgn, sgn * L[j]) for j in moving for sgn in (1.0, -1.0)]
            for side in lps:
                if lps[side] is None:
                    lps[side] = FaceLP(M, q, P, D, side)
                for j, sgn, cost in jobs:
                    st, y = lps[side].solve(cost)
                    n_lp += 1
                    if st == "optimal":
                        dev = float(np.max(np.abs(L[moving] @ y - val[moving])))
                        if dev > best[0]:
                            best = (dev, y)
                    if j is None:
                        continue
                    if st == "unbounded":  # min of sgn L_j is -inf
                        (v.lo if sgn > 0 else v.hi)[j] = -sgn * np.inf
                    elif st == "optimal":
                        lj = float(L[j] @ y)
                        v.lo[j], v.hi[j] = min(v.lo[j], lj), max(v.hi[j], lj)
            if best[0] <= self.delta * self.s_L(L):  # rays (or nothing): points in a box
                for side in lps:
                    boxed = FaceLP(M, q, P, D, side, BOUND_FACTOR * self.zs)
                    for cost in (mix, -mix):
                        st, y = boxed.solve(cost)
                        n_lp += 1
                        dev = (float(np.max(np.abs(L[moving] @ y - val[moving])))
                               if st == "optimal" else 0.0)
                        if dev > best[0]:
                            best = (dev, y)
            w = None if best[1] is None else self.witness(best[1], L, "face LP")
            if w is not None:
                self.seen.append(w.z)
                width = (f"by {v.face_width:.3g} (range LPs)" if self.ranges
                         else "(ranges not computed)")
                self.decide(v, OTHER, "face (a)", f"{v.name} varies over the face {width}, "
                            f"{moving.size} rows move", tv, w, scope="same contact states")
            else:
                v.reason = (f"face (a): {moving.size} rows of {v.name} move along A(z*) but no "
                            "vertex of F_D / F_0 differs by the margin")
                v.seconds += time.perf_counter() - tv
        self.out.log.append(f"face: dim {nd.dim}, {len(lps)} face(s), {n_lp} LPs "
                            f"[{time.perf_counter() - t:.3f} s]")

    # -- stage c1 ----------------------------------------------------------------------------
    def other_solvers(self, tries: int) -> None:
        t = time.perf_counter()
        lcp = LCP(self.M, self.q)
        n, found = self.q.size, 0
        for k in range(tries):
            if not self.open():
                break
            try:
                if k % 2 == 0:
                    d = None if k == 0 else self.rng.uniform(0.01, 1.0, n)
                    sol, how = solve(lcp, method="lemke", d=d), "lemke" + (" (random d)" if k
                                                                          else "")
                else:
                    act = self.rng.random(n) < 0.5
                    sol, how = solve(lcp, method="pivoting", active=act), "pivoting (random)"
            except Exception as exc:  # noqa: BLE001 - a solver refusing is just no witness
                self.out.log.append(f"other solvers: {type(exc).__name__}: {exc}")
                continue
            if sol.z is None:
                continue
            y = np.asarray(sol.z, dtype=float)
            for v in self.open():
                w = self.witness(y, self.obs[v.name], how)
                if w is not None:
                    found += 1
                    self.seen.append(y)
                    tv = time.perf_counter()
                    self.decide(v, OTHER, "other solvers (c1)",
                                f"{how} returned a solution with other {v.name}", tv, w,
                                scope="other contact states" if w.changed else "same states")
        self.out.log.append(f"other solvers: {min(k + 1, tries) if tries else 0} tries, "
                            f"{found} witnesses [{time.perf_counter() - t:.3f} s]")

    # -- stage c2 ----------------------------------------------------------------------------
    def milp(self, time_limit: float, bound: float | None, clock_name: str = "cpu") -> None:
        now = clock_of(clock_name)
        sizes = [float(np.max(y)) for y in self.seen]
        U = bound if bound is not None else max(BOUND_FACTOR * self.zs, 10.0 * max(sizes,
                                                                                   default=0.0))
        for v in self.open():
            t, tc = time.perf_counter(), now()
            L = self.obs[v.name]
            s = milp_search(self.M, self.q, self.z, "values", L, delta=self.delta, bound=U,
                            time_limit=time_limit, clock_name=clock_name)
            left = time_limit - (now() - tc)  # one budget per question
            if s.status == "found" and s.deviation < 1e-3 and self.delta < 1e-2 and left > 0.1:
                s2 = milp_search(self.M, self.q, self.z, "values", L, delta=1e-2, bound=U,
                                 time_limit=left, clock_name=clock_name)  # a clearly other one
                s = s2 if s2.status == "found" else s
            unproved = int(s.info.get("unproved_cuts", 0))  # cuts proved empty by LP are sound
            self.out.log.append(f"milp {v.name}: {s.status}, {s.message}")
            scope = f"0 <= z <= {U:.3g} (box), margin {s.delta:g}"
            w = None if s.other is None else self.witness(s.other, L, "milp")
            if s.status == "found" and w is not None:
                self.decide(v, OTHER, "milp (c2)", f"MILP: {s.message}", t, w, scope=scope)
            elif s.status == "none" and unproved == 0:
                prior = f"; {v.reason}" if v.reason else ""
                left = max(time_limit - (now() - tc), 0.5)
                nb = no_solution_beyond(self.M, self.q, U, time_limit=left,
                                        clock_name=clock_name)
                self.out.log.append(f"norm bound: {nb.message}")
                scope = ("global: " + nb.message if nb.proved else
                         f"{scope}; not global: {nb.message}")
                self.decide(v, UNIQUE, "milp (c2)", f"MILP infeasible: {s.message}{prior}", t,
                            scope=scope)
            else:
                why = (f"MILP cut {unproved} unconfirmed bases (a 'none' after cuts is not a "
                       "proof)" if s.status == "none" else s.message)
                self.decide(v, UNKNOWN, "milp (c2)",
                            f"tried: face LPs, {len(self.seen)} other solutions seen, MILP: "
                            f"{why}", t, scope=scope)

    # -- the contact states ------------------------------------------------------------------
    def states(self) -> None:
        t = time.perf_counter()
        v = self.out.verdicts.setdefault("states", Verdict("states"))
        others = [x.witness for x in self.out.verdicts.values()
                  if x.witness is not None and x.witness.changed]
        if self.out.degenerate:
            self.decide(v, OTHER, "pattern", f"degenerate pairs {self.out.degenerate}: both "
                        "states admissible there", t)
        elif others:
            self.decide(v, OTHER, others[0].found_by, f"a witness changes the states of pairs "
                        f"{others[0].changed[:10]}", t, others[0])
        elif all(x.verdict == UNIQUE for k, x in self.out.verdicts.items() if k != "states"):
            self.decide(v, UNIQUE, "implied", "forces and accelerations unique, z* "
                        "nondegenerate", t, scope="as the forces")
        else:
            self.decide(v, UNKNOWN, "implied", "forces or accelerations undecided", t)
