"""The contact-state and mode claims (Figs. 6, 8, 9, 13) as patterns over the valid steady
states (verify.ranges.patterns), for the report's column "over all valid steady states".

Each claim is written twice, as P (the claim) and, where "for all" is asked, as not-P, in the
literals of verify.ranges.patterns, with the thresholds of the classifiers that judge the
run's own state (models.modes: transmitting R > 1e-9 m max(g, |gamma|), |alpha| <= 1e-6
max(g, |gamma|) / r counts as zero, a pair as opposite within the same; claims.py for the
others). Every witness is re-classified by that same code (`check`): a claim "holds for some"
only on a state the report's own criterion accepts.

Modes (Sec. IV A, models.modes): a first-row disk is in mode 1 when its plane contact is
non-sliding and transmitting; otherwise in mode 3 when its alpha is zero, turns against
rolling (alpha gamma > 0) or is the opposite of a row neighbour's non-zero alpha; otherwise in
mode 2. fig9-counts asks for a state whose first row, one wall disk left out, counts 4 / 3 / 2:
one indicator per disk and mode, each guarding its mode's clauses, and counts over them.

Dissipation D = sum over sliding contacts of mu R |v_t| multiplies forces by velocities: it is
not linear at fixed contact states (and its size scales with the velocities where V is free),
so its range is not computed; whether it vanishes is linear at fixed states (D > 0 iff some
frictional contact slides with R > 0), and that is what is judged.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from rigidlcp import models
from rigidlcp.models.lattice import PLANE
from rigidlcp.models.modes import contact_groups, fig5e_loops, row_modes
from rigidlcp.verify.ranges.patterns import (
    WITNESS_TOL,
    Lit,
    Pattern,
    PatternResult,
    at_least,
    at_most,
    find_state,
    non_sliding,
    sliding,
)
from rigidlcp.verify.ranges.steady import (
    Formulation,
    formulate,
    state_extreme,
    state_velocities,
)
from rigidlcp.verify.ranges.valid_steady import seed_states
from rigidlcp.verify.ranges.witness import SteadyWitness, make_witness

from .valid_steady import SEARCH_CLOCK

#: Seconds per question (a pattern, or its negation): full run, --quick.
PATTERN_TIME_LIMIT = {False: 60.0, True: 5.0}
PAPER_FIG9 = (4, 3, 2)


def _record(w) -> SimpleNamespace:
    """A witness as the classifiers read a run's record."""
    return SimpleNamespace(omega_dot=w.alpha, R=w.R, s=w.s)


def _scales(system: models.System) -> tuple[float, float, float]:
    """(R threshold, R margin, r alpha zero/pair tolerance) of the classifiers."""
    F = system.mass * max(system.g, abs(system.gamma), 1e-12)
    z = 1e-6 * max(abs(system.gamma), system.g, 1e-300)  # models.modes._tol, times r
    return 1e-9 * F, 1e-6 * F, z


def _plane(lat, d: int) -> int:
    return int(np.flatnonzero((lat.i == d) & (lat.j == PLANE))[0])


def _first_row(lat) -> np.ndarray:
    d = np.flatnonzero(lat.row == 0)
    return d[np.argsort(lat.x[d, 0])]


def _pair(i: int, j: int, lo: float = -np.inf, hi: float = np.inf, strict=False, margin=0.0):
    return Lit((("ra", int(i), 1.0), ("ra", int(j), 1.0)), lo, hi, strict, margin)


def _mode_clauses(system: models.System, P: Pattern, k: int, disks: np.ndarray) -> None:
    """Indicators m1_k, m2_k, m3_k (one is 1) of disk disks[k], each guarding its mode."""
    lat, gam = system.lattice, system.gamma
    thr, mR, z = _scales(system)
    d, a = int(disks[k]), _plane(lat, int(disks[k]))
    m1, m2, m3 = (P.indicator(f"m{m}_{k}") for m in (1, 2, 3))
    P.count({m1: 1, m2: 1, m3: 1}, 1, 1)
    P.all_of([non_sliding(a), at_least("R", a, thr, True, mR)], guard=m1)
    not_m1 = [[sliding(a)], [at_most("R", a, thr)]]
    P.any_of(not_m1, guard=m3)
    P.any_of(not_m1, guard=m2)
    nbrs = [int(disks[j]) for j in (k - 1, k + 1) if 0 <= j < disks.size]
    terms = [[at_most("ra", d, z), at_least("ra", d, -z)]]
    if gam != 0:  # turning against rolling: alpha gamma > 0
        terms.append([at_least("ra", d, 0.0, True, z) if gam > 0 else
                      at_most("ra", d, 0.0, True, z)])
    for j in nbrs:
        for side in (at_least("ra", j, z, True, z), at_most("ra", j, -z, True, z)):
            terms.append([side, _pair(d, j, -z, z)])
    P.any_of(terms, guard=m3)
    P.any_of([[at_least("ra", d, z, True, z)], [at_most("ra", d, -z, True, z)]], guard=m2)
    if gam != 0:
        P.all_of([at_most("ra", d, 0.0) if gam > 0 else at_least("ra", d, 0.0)], guard=m2)
    for j in nbrs:
        P.any_of([[at_most("ra", j, z), at_least("ra", j, -z)],
                  [_pair(d, j, lo=z, strict=True, margin=z)],
                  [_pair(d, j, hi=-z, strict=True, margin=z)]], guard=m2)


def questions(name: str, system: models.System) -> dict[str, tuple]:
    """{claim id: (P, not-P or None, check(witness) -> bool for P)} of an experiment."""
    lat = system.lattice
    thr, mR, z = _scales(system)
    out: dict[str, tuple] = {}
    if name == "fig8":
        first = _first_row(lat)
        pl = [_plane(lat, int(d)) for d in first]
        out["fig8-row1-mode1"] = (
            Pattern().all_of([x for a in pl for x in (non_sliding(a),
                                                      at_least("R", a, thr, True, mR))]),
            Pattern().any_of([t for a in pl for t in ([sliding(a)], [at_most("R", a, thr)])]),
            lambda w: bool(np.all(row_modes(system, _record(w), 0).modes == 1)))
        groups = contact_groups(lat)
        up = groups["lateral"][lat.row[lat.i[groups["lateral"]]] >= 1]
        out["fig8-rows-mode2"] = (Pattern().all_of([sliding(a) for a in up]),
                                  Pattern().any_of([[non_sliding(a)] for a in up]),
                                  lambda w: bool(np.all(w.s[up] != 0)))
        col = groups["column_upper"]
        t = 1e-6 * abs(system.gamma) * lat.radius
        P = Pattern().all_of([x for a in col for x in (
            non_sliding(a), at_least("R", a, thr, True, mR),
            _pair(lat.i[a], lat.j[a], -t, t))])
        notP = Pattern().any_of([tt for a in col for tt in (
            [sliding(a)], [at_most("R", a, thr)],
            [_pair(lat.i[a], lat.j[a], lo=t, strict=True, margin=t)],
            [_pair(lat.i[a], lat.j[a], hi=-t, strict=True, margin=t)])])

        def columns(w) -> bool:
            od = w.alpha
            return bool(np.all((w.s[col] == 0) & (w.R[col] > thr))
                        and np.all(np.abs(od[lat.i[col]] + od[lat.j[col]])
                                   <= 1e-6 * abs(system.gamma)))
        out["fig8-columns-mode3"] = (P, notP, columns)
    elif name == "fig9":
        first = _first_row(lat)
        for side, drop in (("left", 0), ("right", first.size - 1)):
            P = Pattern(name=f"without the {side} wall disk")
            for k in range(first.size):
                _mode_clauses(system, P, k, first)
            keep = [k for k in range(first.size) if k != drop]
            for m, n in zip((1, 2, 3), PAPER_FIG9):
                P.count({f"m{m}_{k}": 1 for k in keep}, n, n)

            def fig9(w, drop=drop) -> bool:
                rm = row_modes(system, _record(w), 0)
                skip = np.zeros(rm.modes.size, bool)
                skip[drop] = True
                return rm.counts(skip) == PAPER_FIG9
            out[f"fig9-counts/{side}"] = (P, None, fig9)
    elif name in ("fig13", "fig13_tri"):
        rough = np.flatnonzero((lat.kind != "wall") & (system.mu > 0))
        fric = np.flatnonzero(system.mu > 0)
        if name == "fig13":
            out["fig13-rect-all-ns"] = (Pattern().all_of([non_sliding(a) for a in rough]),
                                        Pattern().any_of([[sliding(a)] for a in rough]),
                                        lambda w: bool(np.all(w.s[rough] == 0)))
            out["fig13-rect-transmitting-ns"] = (
                _all_terms([[[non_sliding(a)], [at_most("R", a, thr)]] for a in rough]),
                Pattern().any_of([[sliding(a), at_least("R", a, thr, True, mR)]
                                  for a in rough]),
                lambda w: not bool(np.any((w.s[rough] != 0) & (w.R[rough] > thr))))
        # D > 0 iff some frictional contact slides with R > 0 (module docstring)
        out[f"{name}/D>0"] = (Pattern().any_of([[sliding(a), at_least("R", a, thr, True, mR)]
                                                for a in fric]), None,
                              lambda w: bool(np.any((w.s[fric] != 0) & (w.R[fric] > thr))))
        out[f"{name}/D=0"] = (_all_terms([[[non_sliding(a)], [at_most("R", a, thr)]]
                                          for a in fric]), None,
                              lambda w: not bool(np.any((w.s[fric] != 0) & (w.R[fric] > thr))))
    elif name == "fig6":
        first = _first_row(lat)
        loops = []
        for a, b, c in zip(first[:-2], first[1:-1], first[2:]):
            ab = np.flatnonzero(((lat.i == a) & (lat.j == b)) | ((lat.i == b) & (lat.j == a)))
            bc = np.flatnonzero(((lat.i == b) & (lat.j == c)) | ((lat.i == c) & (lat.j == b)))
            if ab.size and bc.size:
                loops.append((_plane(lat, a), int(ab[0]), int(bc[0]), _plane(lat, c)))
        P = Pattern().any_of([[x for a in lp for x in (non_sliding(a),
                                                       at_least("R", a, thr, True, mR))]
                              for lp in loops])
        notP = _all_terms([[[sliding(a)] for a in lp] + [[at_most("R", a, thr)] for a in lp]
                           for lp in loops])
        out["fig6-alternating"] = (P, notP,
                                   lambda w: len(fig5e_loops(system, _record(w))) >= 1)
    return out


def _all_terms(clauses: list[list[list[Lit]]]) -> Pattern:
    P = Pattern()
    for terms in clauses:
        P.any_of(terms)
    return P


def judge_patterns(name: str, run: models.Run, time_limit: float,
                   clock: str = SEARCH_CLOCK) -> dict[str, dict]:
    """{claim id: {"P": PatternResult, "not": PatternResult | None}} for the system of `run`
    (a report job: one per experiment; time_limit seconds per question, on `clock`:
    verify.ranges.patterns.find_state); a string value when the MILP cannot be formed."""
    system = run.system
    try:
        form = formulate(system)
    except Exception as exc:  # NotSteady, NoVelocityBound: the column says why
        return {"error": f"{type(exc).__name__}: {exc}"}
    known, labels = known_states(form, run)
    out: dict[str, dict] = {}
    for cid, (P, notP, check) in questions(name, system).items():
        out[cid] = {"P": _ask(form, P, time_limit, check, known, labels, clock),
                    "not": None if notP is None else _ask(form, notP, time_limit,
                                                          lambda w, c=check: not c(w), known,
                                                          labels, clock)}
    return out


def describe(system: models.System, w: SteadyWitness) -> str:
    """A witness in a few words: mu_g, sliding contacts, first-row modes, residual."""
    fr = system.mu > 0
    modes = row_modes(system, _record(w), 0).text()
    return (f"mu_g {w.mu_g:.7g}, {int(np.sum(w.s[fr] != 0))} of {int(fr.sum())} frictional "
            f"contacts sliding, first-row modes {modes}, residual {w.residual:.0e}")


def known_states(form: Formulation, run: models.Run | None
                 ) -> tuple[list[SteadyWitness], list[str]]:
    """Checked valid steady states to try before any MILP, and a label of each: the run's own
    (one time unit after its last event, as verify.ranges.steady_ranges takes it) and the
    seeds' (the locked array, the rolling checkerboards: valid_steady.seed_states)."""
    system, out, labels = form.system, [], []
    if run is not None and run.status == "steady":
        last, fin = run.records[-1], run.final
        alpha = make_witness(system, fin.omega, fin.V, last.R, last.S, form.dyn).alpha
        V = fin.V + system.gamma
        v_scale = max(float(np.sqrt(system.g * system.lattice.radius)), abs(V))
        out.append(make_witness(system, fin.omega + alpha, V, np.asarray(last.R, float),
                                np.asarray(last.S, float), form.dyn, v_scale))
        labels.append("the run's own steady state")
    for s in seed_states(form):
        status, x, _ = state_extreme(form, s, np.zeros(2 * system.c), 1)
        vel = state_velocities(form, s)
        if status == "optimal" and vel is not None:
            out.append(make_witness(system, vel[0], vel[1], x[:system.c], x[system.c:],
                                    form.dyn))
            slid = s[(system.lattice.j == PLANE) & (system.mu > 0)]
            labels.append("the locked array's contact states (a seed: every plane contact "
                          "sliding, every disk-disk one not)" if np.all(slid != 0)
                          else "a rolling checkerboard's contact states (a seed)")
    keep = [k for k, w in enumerate(out) if w.residual <= WITNESS_TOL]
    return [out[k] for k in keep], [labels[k] for k in keep]


def _ask(form, P: Pattern, time_limit: float, check, known: list, labels: list,
         clock: str = SEARCH_CLOCK) -> PatternResult:
    try:
        res = find_state(form, P, time_limit=time_limit, check=check, known=known,
                         clock=clock)
    except Exception as exc:  # a failed question is "unknown", never a verdict
        return PatternResult("failed", note=f"{type(exc).__name__}: {exc}")
    w = res.witness
    if w is not None:
        k = next((k for k, x in enumerate(known) if x is w), None)
        if k is None:
            known.append(w)
            labels.append(f"the witness of an earlier question ({res.cuts} cuts)")
            k = len(known) - 1
            src = f"a MILP witness ({res.cuts} lazy cuts, {res.seconds:.1f} s)"
        else:
            src = labels[k]
        res.note = f"{src}: {describe(form.system, w)}"
    return res


__all__ = ["questions", "judge_patterns", "PATTERN_TIME_LIMIT"]
