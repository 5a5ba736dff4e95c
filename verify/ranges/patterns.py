"""Is there a valid steady state whose contact states, forces and angular accelerations satisfy a
pattern P? (issue 21, point 3: the paper's mode claims judged over every valid steady state.)

P is a conjunction of clauses; a clause is a disjunction of terms; a term is a conjunction of
literals; a literal is one linear condition lo <= sum coef * col <= hi on the columns of the
steady-state MILP (verify.ranges.steady): R, S (per contact), ra = r alpha (per disk), and the
tangential state of a frictional contact ("sl" = y+ + y-: 1 sliding, 0 non-sliding; "y+",
"y-"; on a frictionless contact "sl" is the constant 0, the state read off its v_t by
verify.ranges.witness too). A clause may be *guarded* by an indicator (a named binary: the
clause must hold when it is 1; one-way: a 0 says nothing), and `counts` bound linear sums
of indicators (a number of disks in a mode: exact when the indicators of each disk are
exclusive and exhaustive, one per mode with sum 1, as mode_claims writes them). Each term
of a clause of more than one term gets a binary z_t with sum z_t >= 1 (or >= its guard) and
its literals relaxed by big-M where z_t = 0; every M comes
from the MILP's column box (proved bounds: verify.ranges.bounds, the rotation cap, the
velocity box), so it loses no point of the box.

`find_state(system, P)` adds these rows to the MILP (no objective) and solves it with the lazy
kinematic cuts of verify.ranges.milp:

* feasible: its contact states are fixed, the forces and velocities recomputed by one linear
  program (the binaries fixed) and the state checked by verify.ranges.witness.steady_check
  (Newton-Euler and v_t recomputed, residual <= 1e-8) and by P evaluated on the witness
  itself (`Pattern.holds`, strict literals strictly) and by the caller's own predicate;
* infeasible with the cuts exhausted: *no* valid steady state satisfies P (every cut is valid
  for every valid steady state, so the cut MILP contains them all). This is a proof over all
  valid steady states when the force box is proved for P (`proved`): P reads no R of a
  self-stress row (whose bound holds for observables of S only, verify.ranges.bounds);
  otherwise over the states within the box;
* time limit: "time limit", never a verdict.

Strict literals (R > t, |alpha| > t, as in the classifiers of models.modes) are solved closed
(R >= t: a superset, so "infeasible" still proves); when the closed solution fails the strict
test, once more with each strict literal tightened by its `margin`, and if that fails too the
answer is "unknown" (only states at the threshold were found).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp
from scipy.optimize import Bounds, LinearConstraint, milp

from rigidlcp.models.system import System

from .milp import MilpModel
from .milp import clock as milp_clock
from .proportional import exact as proportional_exact
from .result import INFEASIBLE, OPTIMAL, TIME_LIMIT
from .steady import Formulation, formulate, state_velocities, states_of
from .witness import WITNESS_TOL, SteadyWitness, make_witness

FOUND = "feasible"
KINDS = ("R", "S", "ra", "sl", "y+", "y-")


@dataclass(frozen=True)
class Lit:
    """lo <= sum coef * col <= hi over terms ((kind, index, coef), ...); kind in KINDS (index:
    a contact, or a disk for "ra"). strict: the finite sides are strict (< / >), tightened by
    `margin` on the second try (module docstring)."""

    terms: tuple[tuple[str, int, float], ...]
    lo: float = -np.inf
    hi: float = np.inf
    strict: bool = False
    margin: float = 0.0

    def value(self, vals: dict[str, np.ndarray]) -> float:
        return float(sum(coef * vals[k][i] for k, i, coef in self.terms))

    def holds(self, vals: dict[str, np.ndarray], tol: float = 0.0) -> bool:
        v = self.value(vals)
        if self.strict:
            return (self.lo == -np.inf or v > self.lo) and (self.hi == np.inf or v < self.hi)
        return self.lo - tol <= v <= self.hi + tol


def sliding(a: int) -> Lit:
    """Contact a slides (its state indicator sl_a = 1)."""
    return Lit((("sl", int(a), 1.0),), lo=1.0)


def non_sliding(a: int) -> Lit:
    """Contact a does not slide (sl_a = 0)."""
    return Lit((("sl", int(a), 1.0),), hi=0.0)


def at_least(kind: str, idx: int, t: float, strict: bool = False, margin: float = 0.0) -> Lit:
    """The column kind[idx] (KINDS) >= t (> t when strict)."""
    return Lit(((kind, int(idx), 1.0),), lo=float(t), strict=strict, margin=margin)


def at_most(kind: str, idx: int, t: float, strict: bool = False, margin: float = 0.0) -> Lit:
    """The column kind[idx] (KINDS) <= t (< t when strict)."""
    return Lit(((kind, int(idx), 1.0),), hi=float(t), strict=strict, margin=margin)


@dataclass
class Clause:
    """A disjunction of terms (each a conjunction of literals); guard: an indicator's name."""

    terms: list[list[Lit]]
    guard: str | None = None


@dataclass
class Pattern:
    """A conjunction of clauses, with indicators and counts over them (module docstring)."""

    clauses: list[Clause] = field(default_factory=list)
    indicators: list[str] = field(default_factory=list)
    counts: list[tuple[dict[str, float], float, float]] = field(default_factory=list)
    name: str = ""

    def all_of(self, lits: list[Lit], guard: str | None = None) -> Pattern:
        self.clauses += [Clause([[lit]], guard) for lit in lits]
        return self

    def any_of(self, terms: list[list[Lit]], guard: str | None = None) -> Pattern:
        self.clauses.append(Clause([list(t) for t in terms], guard))
        return self

    def indicator(self, name: str) -> str:
        if name not in self.indicators:
            self.indicators.append(name)
        return name

    def count(self, weights: dict[str, float], lo: float, hi: float) -> Pattern:
        self.counts.append((dict(weights), float(lo), float(hi)))
        return self

    def literals(self):
        for cl in self.clauses:
            for t in cl.terms:
                yield from t

    def holds(self, system: System, wit: SteadyWitness) -> bool:
        """P on a witness: its states (read off v_t), R, S and r alpha; strict literals strictly.
        Indicators: some 0/1 assignment meeting the counts (searched when there are few)."""
        vals = values_of(system, wit)
        tol = 1e-9 * max(1.0, float(np.max(np.abs(wit.R), initial=0.0)))

        def ok(cl: Clause) -> bool:
            return any(all(lit.holds(vals, tol) for lit in t) for t in cl.terms)

        free = [cl for cl in self.clauses if cl.guard is None]
        if not all(ok(cl) for cl in free):
            return False
        if not self.indicators:
            return True
        # an indicator may be 1 only where its guarded clauses hold; the counts then need a
        # 0/1 choice among those (one per group of indicators summing to one: modes)
        can = {n: all(ok(cl) for cl in self.clauses if cl.guard == n) for n in self.indicators}
        return _counts_met(self, can)


def _counts_met(p: Pattern, can: dict[str, bool]) -> bool:
    """Whether 0/1 values x_n <= can[n] meet every count (small exact search by milp)."""
    names = p.indicators
    A = np.array([[w.get(n, 0.0) for n in names] for w, _, _ in p.counts]).reshape(-1, len(names))
    lo = np.array([c[1] for c in p.counts])
    hi = np.array([c[2] for c in p.counts])
    ub = np.array([1.0 if can[n] else 0.0 for n in names])
    res = milp(np.zeros(len(names)), constraints=LinearConstraint(A, lo, hi) if len(lo) else (),
               integrality=np.ones(len(names)), bounds=Bounds(np.zeros(len(names)), ub))
    return res.status == 0


def values_of(system: System, wit: SteadyWitness) -> dict[str, np.ndarray]:
    """The literal kinds' values on a witness (states from its v_t, alpha from Newton-Euler)."""
    s = np.asarray(wit.s)
    return {"R": np.asarray(wit.R), "S": np.asarray(wit.S),
            "ra": system.lattice.radii * np.asarray(wit.alpha),
            "sl": (s != 0).astype(float), "y+": (s > 0).astype(float),
            "y-": (s < 0).astype(float)}


@dataclass
class PatternResult:
    """status: "feasible" (witness: a checked valid steady state with P), "infeasible" (no
    valid steady state has P; over all of them when `proved`, else within the force box),
    "time limit", "failed" or "unknown" (note says why)."""

    status: str
    witness: SteadyWitness | None = None
    proved: bool = False
    cuts: int = 0
    seconds: float = 0.0
    note: str = ""

    def __repr__(self) -> str:
        w = "" if self.witness is None else f", witness {self.witness!r}"
        return f"<PatternResult {self.status}{w}; {self.note}>"


def _extend(form: Formulation, p: Pattern, tighten: bool) -> tuple[Formulation, bool]:
    """The MILP of `form` with P's rows and binaries appended; and whether the force box is
    proved for P (no literal on the R of a self-stress row)."""
    c, pd, F = form.system.c, form.system.p, form.fric.size
    n0 = form.A.shape[1]
    fpos = {int(a): k for k, a in enumerate(form.fric)}
    base = 2 * c + 2 * pd + 1

    def cols(kind: str, i: int) -> list[int]:
        if kind == "R":
            return [i]
        if kind == "S":
            return [c + i]
        if kind == "ra":
            return [2 * c + i]
        if i not in fpos:  # a frictionless contact: never sliding
            return []
        k = fpos[i]
        return {"sl": [base + k, base + F + k], "y+": [base + k], "y-": [base + F + k]}[kind]

    extra = list(p.indicators)
    ind = {n: n0 + k for k, n in enumerate(extra)}
    rows: list[tuple[dict[int, float], float, float]] = []
    lb, ub = np.asarray(form.lb, float), np.asarray(form.ub, float)

    def lit_row(lit: Lit) -> tuple[dict[int, float], float, float, float, float]:
        g: dict[int, float] = {}
        for kind, i, coef in lit.terms:
            if kind not in KINDS:
                raise ValueError(f"literal kind must be one of {KINDS}, got {kind!r}")
            for j in cols(kind, i):
                g[j] = g.get(j, 0.0) + coef
        lo, hi = lit.lo, lit.hi
        if lit.strict and tighten:
            lo, hi = lo + lit.margin, hi - lit.margin
        idx = np.array(list(g), dtype=int)
        w = np.array(list(g.values()))
        gmin = float(np.sum(np.minimum(w * lb[idx], w * ub[idx]))) if idx.size else 0.0
        gmax = float(np.sum(np.maximum(w * lb[idx], w * ub[idx]))) if idx.size else 0.0
        return g, lo, hi, gmin, gmax

    n = n0 + len(extra)
    for cl in p.clauses:
        guard = None if cl.guard is None else ind[cl.guard]
        if len(cl.terms) == 1 and guard is None:
            for lit in cl.terms[0]:
                g, lo, hi, _, _ = lit_row(lit)
                rows.append((g, lo, hi))
            continue
        zs = list(range(n, n + len(cl.terms)))
        n += len(cl.terms)
        extra += [f"z{k}" for k in zs]
        cover = {z: 1.0 for z in zs}
        if guard is not None:  # sum z >= guard
            cover[guard] = -1.0
            rows.append((cover, 0.0, np.inf))
        else:
            rows.append((cover, 1.0, np.inf))
        for z, term in zip(zs, cl.terms):
            for lit in term:  # lo - (lo - gmin)(1 - z) <= g.x <= hi + (gmax - hi)(1 - z)
                g, lo, hi, gmin, gmax = lit_row(lit)
                if np.isfinite(lo):
                    if lo > gmax:
                        rows.append(({z: 1.0}, -np.inf, 0.0))
                    elif lo > gmin:
                        rows.append(({**g, z: -(lo - gmin)}, gmin, np.inf))
                if np.isfinite(hi):
                    if hi < gmin:
                        rows.append(({z: 1.0}, -np.inf, 0.0))
                    elif hi < gmax:
                        rows.append(({**g, z: gmax - hi}, -np.inf, gmax))
    for w, lo, hi in p.counts:
        rows.append(({ind[k]: v for k, v in w.items()}, lo, hi))
    k = n - n0
    A = sp.lil_matrix((len(rows), n))
    for r, (g, _, _) in enumerate(rows):
        for j, v in g.items():
            A[r, j] = v
    A0 = sp.hstack([form.A, sp.csr_matrix((form.A.shape[0], k))])
    ext = replace(form, A=sp.vstack([A0, A.tocsr()]).tocsr(),
                  lo=np.r_[form.lo, [r[1] for r in rows]], hi=np.r_[form.hi, [r[2] for r in rows]],
                  lb=np.r_[form.lb, np.zeros(k)], ub=np.r_[form.ub, np.ones(k)],
                  integrality=np.r_[form.integrality, np.ones(k)])
    free = form.free_R if form.free_R is not None else np.zeros(c, bool)
    reads_free = any(kind == "R" and free[i] for lit in p.literals() for kind, i, _ in lit.terms)
    return ext, bool(form.box_proved and not reads_free)


def _polish(ext: Formulation, x: np.ndarray) -> np.ndarray | None:
    """The MILP's point made exact: one LP over every column with the binaries fixed (the
    velocity rows in, which the lazy MILP dropped), or None."""
    fix = ext.integrality > 0
    lb, ub = np.array(ext.lb, float), np.array(ext.ub, float)
    lb[fix] = ub[fix] = np.round(x[fix])
    res = milp(np.zeros(lb.size), constraints=LinearConstraint(ext.A, ext.lo, ext.hi),
               bounds=Bounds(lb, ub), options={"presolve": True})
    return res.x if res.status == 0 else None


def _witness(ext: Formulation, x: np.ndarray) -> SteadyWitness | None:
    system, c, pd = ext.system, ext.system.c, ext.system.p
    r = system.lattice.radii
    y = _polish(ext, x)
    if y is not None:
        u, V = y[2 * c + pd:2 * c + 2 * pd], float(y[2 * c + 2 * pd])
        omega = u / r
        if ext.V_mode in ("positive", "negative"):  # the cone's point scaled to V = V0
            k = system.V0 / V
            omega, V = omega * k, system.V0
    else:
        vel = state_velocities(ext, states_of(ext, x))
        if vel is None:
            return None
        (omega, V), y = vel, x
    return make_witness(system, omega, V, y[:c], y[c:2 * c], ext.dyn)


def _accepts(system: System, pattern: Pattern, wit: SteadyWitness, check) -> str:
    """"" if the witness is a valid steady state (residual) with P (Pattern.holds and the
    caller's check), else why not."""
    if wit.residual > WITNESS_TOL:
        return f"witness residual {wit.residual:.1e} > {WITNESS_TOL:g}"
    if not pattern.holds(system, wit):
        return "P fails on the witness"
    if check is not None and not check(wit):
        return "the caller's predicate fails on the witness"
    return ""


def find_state(target: System | Formulation, pattern: Pattern, *, time_limit: float = 60.0,
               check: Callable[[SteadyWitness], bool] | None = None,
               known: list[SteadyWitness] = (), kinematics: str = "auto",
               clock: str = "cpu") -> PatternResult:
    """A valid steady state of `target` (a System, or its Formulation) satisfying `pattern`, or
    a proof that none does (module docstring). check(witness) -> bool: the caller's own test
    of the property on the witness (e.g. the classifier of models.modes); a witness must pass
    it, steady_check and Pattern.holds. known: valid steady states met before (a run's own, the
    seeds', earlier witnesses), tried first: one that passes is the answer, no MILP.
    kinematics: MilpModel's; "auto" is "lazy-a_t" (states checked on the contacts with a_t =
    0 only) where that is exact (gamma != 0, V = gamma t admitted), else "lazy". clock:
    time_limit counted as this process's CPU seconds ("cpu", the default: the same work
    whatever the machine's load; verify.ranges.milp.MilpModel) or on the wall clock
    ("wall"); the result's `seconds` are wall seconds either way."""
    now = milp_clock(clock)  # a wrong clock refused before any work (ValueError)
    t0, c0 = time.perf_counter(), now()
    form = target if isinstance(target, Formulation) else formulate(target)
    for k, wit in enumerate(known):
        if not _accepts(form.system, pattern, wit, check):
            return PatternResult(FOUND, wit, True, 0, time.perf_counter() - t0,
                                 f"a known valid steady state (#{k} of those given; residual "
                                 f"{wit.residual:.1e}), no MILP")
    notes: list[str] = []
    if kinematics == "auto":
        kinematics = ("lazy-a_t" if form.system.gamma != 0 and proportional_exact(form)
                      else "lazy")
    elif kinematics == "proportional":  # its binaries are a_t's signs, not contact states
        raise ValueError("find_state asks contact states: kinematics 'lazy-a_t', 'lazy' or "
                         "'big-M', not 'proportional'")
    for tighten in (False, True):
        if tighten and not any(lit.strict and lit.margin > 0 for lit in pattern.literals()):
            break
        ext, proved = _extend(form, pattern, tighten)
        model = MilpModel(ext, kinematics, clock)
        left = time_limit - (now() - c0)
        st, x = model.solve(np.zeros(model.n), left) if left > 0 else (TIME_LIMIT, None)
        took = time.perf_counter() - t0
        if st == INFEASIBLE and not tighten:
            scope = ("" if proved else f" within the force box R <= {form.U:.4g} (not "
                     "proved for the R that P reads)")
            return PatternResult(INFEASIBLE, None, proved, model.cuts, took,
                                 f"MILP infeasible after {model.cuts} lazy kinematic cut(s): "
                                 f"no valid steady state{scope} has it")
        if st == INFEASIBLE:
            notes.append("infeasible with the strict literals tightened by their margins")
            break
        if x is None or st not in (OPTIMAL, TIME_LIMIT):  # with no objective, an incumbent
            # at the time limit whose states the kinematics admit is a point: checked below
            return PatternResult(TIME_LIMIT if st == TIME_LIMIT else "failed", None, proved,
                                 model.cuts, took, f"HiGHS: {st} ({model.cuts} cuts)")
        wit = _witness(ext, x)
        if wit is None:
            notes.append("the MILP's point gave no witness (velocity LP failed)")
            continue
        why = _accepts(form.system, pattern, wit, check)
        if not why:
            return PatternResult(FOUND, wit, True, model.cuts, time.perf_counter() - t0,
                                 f"checked witness (residual {wit.residual:.1e}, "
                                 f"{model.cuts} cuts" + (", strict literals tightened"
                                                         if tighten else "") + ")")
        notes.append(why)
    return PatternResult("unknown", None, False, 0, time.perf_counter() - t0,
                         "no checked witness: " + "; ".join(notes))


__all__ = ["Lit", "Clause", "Pattern", "PatternResult", "find_state", "sliding",
           "non_sliding", "at_least", "at_most", "values_of", "FOUND"]
