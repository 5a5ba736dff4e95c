"""The report's column "over all valid steady states" (issue 21, point 3).

Each steady-state claim of the paper is judged over the set of valid steady states of its
system (docs/mechanics.md, "Valid steady states and their ranges"), not only over the state
that this toolkit's selection (face-min-norm) reaches: "holds for all", "holds for some"
(which), "holds for none", or "unknown" (why: an end not decided within its time limit, or a
property the range computation does not constrain), with the ranges of mu_g.

* Figs. 7 and 10 ("the steady state does not depend on the initial state"): read as "every
  valid steady state has the run's mu_g"; it holds for all only when the range is a point.
* Fig. 11: the bands of valid_steady.mu_g_band (one range per gamma of the sweep).
* Fig. 12: mu_e(0) = mu_g(0) on any curve of steady states, so its range at gamma = 0 is the
  band's; m_e is a derivative along a curve, and the curves through the band are many: judged
  on the band's two end curves (valid_steady.end_families) beside the selection's.
* Sec. IV B: the comparisons between systems, on the end curves of like kind.
* The mode and contact-state claims (Figs. 6, 8, 9, 13): asked of the steady-state MILP as
  patterns (mode_claims.py, verify.ranges.patterns): "for all" when not-P is infeasible (the
  lazy kinematic cuts exhausted), "for none" when P is, "for some" with a checked witness of
  each; a time limit is "unknown (time limit)". Dissipation: only its sign (D is not linear
  at fixed contact states).
"""

from __future__ import annotations

import numpy as np

from .experiments import Claim, Results, first_piece, plateau
from .valid_steady import end_families, fmt_range, linear_through_zero, values_met

NA = "n/a (not a steady-state claim)"
#: Width of a range counted as a point (mu_g is O(0.1); steady states are exact to ~1e-12).
POINT = 1e-9


def over_all(res: Results, c: Claim) -> str:
    """The column's text for claim c (the claim's id decides how it is judged)."""
    cid = c.id
    try:
        if cid.startswith(("fig7", "fig10")):
            return _same_value(res, cid.split("-")[0])
        if cid == "fig11-linear":
            return _linear(res)
        if cid == "fig11-plateau":
            return _plateau(res)
        if cid.startswith("fig12"):
            return _fig12(res, cid)
        if cid.startswith("ivb"):
            return _ivb(res, c)
        if cid.startswith(("fig8", "fig9", "fig6", "fig13")):
            return _state_claim(res, c)
    except Exception as exc:  # a broken judgement is reported, never dropped
        return f"unknown (evaluation error: {type(exc).__name__}: {exc})"
    return NA


def _set_of(res: Results, name: str):
    s = res.steady_sets.get(name)
    if s is None:
        return None, "not computed"
    if isinstance(s, str):
        return None, s
    return s, ""


def _same_value(res: Results, name: str) -> str:
    s, why = _set_of(res, name)
    if s is None:
        return f"unknown ({why})"
    r, v = s.mu_g, s.run_values.get("mu_g")
    txt = (f"valid steady mu_g {fmt_range(r)}; run's {v:.7g}; with the run's own contact "
           f"states {fmt_range(s.own.get('mu_g'))}")
    if r.decided and r.width <= POINT:
        return f"holds for all: every valid steady state has mu_g = {r.lo.value:.7g} ({txt})"
    other = [x for x in values_met(r) if v is None or abs(x - v) > POINT] + [
        x for x in (values_met(s.own["mu_g"]) if "mu_g" in s.own else [])
        if v is None or abs(x - v) > POINT]
    if other:
        return ("holds for some: the run's state and those with its mu_g; other valid steady "
                f"states (checked witnesses) have mu_g = {min(other):.7g}"
                + (f"..{max(other):.7g}" if max(other) > min(other) else "")
                + f", so which one is reached is the selection's, not the rigid model's ({txt}; "
                "mu_g only: the accelerations' and forces' ranges are not computed here)")
    return f"unknown (time limit): no other value met ({txt})"


def _band_text(pts, k: int) -> str:
    pt = pts[k]
    sel = "" if pt.selected is None else f", selected {pt.selected:.7g}"
    return f"gamma {pt.gamma:g}: {fmt_range(pt.every)}{sel}"


def _first_nonzero(pts) -> int:
    return next((k for k, pt in enumerate(pts) if pt.gamma > 0), 0)


def _linear(res: Results) -> str:
    pts = res.bands.get("fig11")
    if not pts:
        return "unknown (band not computed)"
    eff = res.effective("fig11")
    n1 = first_piece(eff)
    if n1 < 2:
        return "unknown: the selection has no linear piece to judge over"
    top = eff.gamma[n1 - 1]  # the claim is about small gamma: the selection's first piece
    pts = [pt for pt in pts if pt.gamma <= top]
    verdict, why = linear_through_zero(pts)
    return (f"{verdict} over gamma = 0..{top:g} (the selection's linear piece): {why}. Band "
            f"at {_band_text(pts, 0)}; at {_band_text(pts, _first_nonzero(pts))}")


def _plateau(res: Results) -> str:
    pts = res.bands.get("fig11")
    if not pts:
        return "unknown (band not computed)"
    eff = res.effective("fig11")
    mu_p = res.plan["fig11"]["mu_plane"]
    n3 = plateau(eff, mu_p)
    if not n3:
        return "unknown: the selection has no plateau to compare with"
    at = [pt for pt in pts if pt.gamma >= eff.gamma[-n3]]
    if any(not pt.every.decided for pt in at):
        return "unknown (time limit): an end of the band on the plateau is not decided"
    dev = max(max(abs(pt.every.lo.value - mu_p), abs(pt.every.hi.value - mu_p)) for pt in at)
    lo = min(pt.every.lo.value for pt in at)
    if dev <= POINT:
        return (f"holds for all: from gamma = {at[0].gamma:g} every valid steady state has "
                f"mu_g = mu_plane (band within {dev:.1e})")
    return (f"holds for some: from gamma = {at[0].gamma:g} the band reaches mu_plane = {mu_p} "
            f"but extends down to {lo:.7g} (the selection stays on the plateau)")


def _effective_of(res: Results, name: str):
    pts = res.bands.get(name)
    if not pts:
        return None
    rows = res.sweeps[name]
    return end_families(pts, float(rows[0]["m_g"]))


def _fig12(res: Results, cid: str) -> str:
    pts, fam = res.bands.get("fig11"), _effective_of(res, "fig11")
    if not pts or fam is None:
        return "unknown (band not computed)"
    mu_p = res.plan["fig11"]["mu_plane"]
    sel = res.effective("fig11")
    if cid.endswith("friction"):
        r0 = pts[0].every
        if pts[0].gamma != 0 or not r0.decided:
            return f"unknown: the band at gamma = 0 is not decided ({fmt_range(r0)})"
        big = max(abs(r0.lo.value), abs(r0.hi.value))
        where = (f"mu_e(0) = mu_g(0) on any curve of valid steady states: range "
                 f"{fmt_range(r0)}; the selection's {sel.mu_e[0]:.3g}")
        if big <= 0.1 * mu_p:
            return f"holds for all ({where})"
        lo_ok = min(abs(r0.lo.value), abs(r0.hi.value)) <= 0.1 * mu_p or (
            r0.lo.value <= 0 <= r0.hi.value)
        return (("holds for some" if lo_ok else "holds for none")
                + f": |mu_e(0)| <= 0.1 mu_plane only for the states with mu_g(0) in "
                f"[-{0.1 * mu_p:g}, {0.1 * mu_p:g}] ({where})")
    m_g = sel.m_g
    parts, ok = [f"selection m_e({sel.gamma[0]:g}) = {sel.m_e[0]:.4g}"], []
    for key, e in fam.items():
        if e is None:
            parts.append(f"{key} end curve: not decided")
            continue
        parts.append(f"{key} end curve m_e({e.gamma[0]:g}) = {e.m_e[0]:.4g}")
        if e.m_e[0] >= 2 * m_g:
            ok.append(f"the {key} end curve")
    if sel.m_e[0] >= 2 * m_g:  # the selection's curve is one of valid steady states too
        ok.insert(0, "this toolkit's selection")
    head = ("holds for some (" + ", ".join(ok) + ")" if ok else
            "unknown: neither the selection nor an end curve has m_e(0) >= 2 m_g")
    return (f"{head}; m_e is a slope along a curve of valid steady states, and the band "
            f"admits many: {'; '.join(parts)}; band at {_band_text(pts, 0)}")


def _ivb(res: Results, c: Claim) -> str:
    cid = c.id
    other = "ivb_plane" if cid.startswith("ivb-plane") else "ivb_pp"
    base, fam = _effective_of(res, "fig11"), _effective_of(res, other)
    if base is None or fam is None:
        return "unknown (band not computed)"
    q = "m_e" if cid.endswith("m_e") else "mu_e"
    grow = (q == "m_e") == cid.startswith("ivb-plane")
    n = res.effective("fig11").gamma.size - plateau(res.effective("fig11"),
                                                     res.plan["fig11"]["mu_plane"])
    held, failed = [], []
    for key in ("lower", "upper"):
        x, y = fam[key], base[key]
        if x is None or y is None or not np.array_equal(x.gamma, y.gamma):
            failed.append(f"{key} end curves: not comparable (an end not decided)")
            continue
        k = min(n, x.gamma.size)  # below the selection's saturation, as the claim's row
        d = getattr(x, q)[:k] - getattr(y, q)[:k]
        tol = 1e-9 * (y.m_g if q == "m_e" else 1.0)
        good = bool(np.all(d >= -tol) and np.any(d > tol)) if grow else bool(
            np.all(d <= tol) and np.any(d < -tol))
        (held if good else failed).append(f"{key} end curves ({q}(0) {getattr(x, q)[0]:.4g} "
                                          f"vs {getattr(y, q)[0]:.4g})")
    if c.passed:  # the selections' curves are curves of valid steady states too
        held.insert(0, "this toolkit's selections (the claim's row)")
    if held:
        return ("holds for some: " + "; ".join(held) + (f"; not for: {'; '.join(failed)}"
                                                        if failed else "")
                + ". Other curves through the bands not compared")
    return "unknown: fails for " + "; ".join(failed) + "; other curves through the bands not tried"


def _state_claim(res: Results, c: Claim) -> str:
    """Mode / contact-state claims, asked of the steady-state MILP as patterns
    (mode_claims.py, verify.ranges.patterns): P and not-P, each a checked witness, a proof
    that there is none, or "unknown (time limit)"."""
    name = c.id.split("-")[0]
    s, why = _set_of(res, name)
    rng = f"valid steady mu_g {fmt_range(s.mu_g)}" if s is not None else why
    if c.id.endswith("any-selection"):
        return f"not judged over the set: a claim about the runs' paths ({rng})"
    if c.id in ("fig13-minimum", "fig13-tri-higher"):
        return _dissipation(res, c)
    qs = res.patterns.get(name)
    if qs is None or "error" in qs:
        return f"unknown (patterns not asked: {'not computed' if qs is None else qs['error']})"
    if c.id == "fig9-counts":
        return _fig9(qs, s) + f" ({rng})"
    q = qs.get(c.id)
    if q is None:  # fig6-singular: dim ker M is not a pattern of states and forces
        own_ok = s is not None and "mu_g" in s.own
        return ("holds for some (at least the run's steady state, checked valid); for all: "
                "not judged (not a pattern of contact states and forces)" if c.passed and own_ok
                else "unknown (not a pattern of contact states and forces)")
    return _pattern_verdict(q["P"], q["not"]) + f" ({rng})"


def _found(r) -> bool:
    return r is not None and r.status == "feasible"


def _none(r) -> bool:
    return r is not None and r.status == "infeasible"


def _scope(r) -> str:
    return "" if r.proved else " within the force box (its bound is not proved for this R)"


def _pattern_verdict(P, N) -> str:
    """The column's text from the answers for P and for not-P (verify.ranges.patterns)."""
    if _none(P):
        return f"holds for none{_scope(P)}: {P.note}"
    if _found(P) and _none(N):
        return f"holds for all{_scope(N)}: {N.note}; e.g. {P.note}"
    if _found(P) and _found(N):
        return f"holds for some: e.g. {P.note}; not for {N.note}"
    if _found(P):
        return (f"holds for some: e.g. {P.note}; for all: unknown ("
                + (N.status if N is not None else "not asked") + ")")
    head = f"unknown ({P.status}: whether some valid steady state has it)"
    if _found(N):
        return f"{head}; not for all: {N.note}"
    if _none(N):
        return f"holds for all{_scope(N)}: {N.note} (yet no witness of it met: {P.status})"
    return head


def _fig9(qs: dict, s) -> str:
    """fig9-counts: some valid steady state with 4 / 3 / 2, one wall disk left out (either)."""
    P = [qs.get("fig9-counts/left", {}).get("P"), qs.get("fig9-counts/right", {}).get("P")]
    hit = next((r for r in P if _found(r)), None)
    own = ("not for all: the run's own state (checked valid) has other counts"
           if s is not None and "mu_g" in s.own else "for all: not asked")
    if hit is not None:
        return f"holds for some: e.g. {hit.note}; {own}"
    if all(_none(r) for r in P):
        return f"holds for none{_scope(P[0]) or _scope(P[1])}: {P[0].note} (either wall disk)"
    return ("unknown (" + ", ".join(r.status if r is not None else "not asked" for r in P)
            + f"): no valid steady state with 4 / 3 / 2 met, none ruled out; {own}")


def _dissipation(res: Results, c: Claim) -> str:
    """D = sum mu R |v_t| over sliding contacts is not linear at fixed states (forces times
    velocities; mode_claims.py): only whether it vanishes is asked."""
    why = ("D multiplies forces by velocities (not linear at fixed contact states), so its "
           "range is not computed; judged by its sign (D > 0 iff a frictional contact slides "
           "with R > 0)")
    qs = {k: res.patterns.get(k) or {} for k in ("fig13", "fig13_tri")}
    zero = {k: q.get(f"{k}/D=0", {}).get("P") for k, q in qs.items()}
    pos = {k: q.get(f"{k}/D>0", {}).get("P") for k, q in qs.items()}
    if c.id == "fig13-minimum":
        z = zero["fig13"]
        tail = (f"a valid steady state with D = 0 exists ({z.note}), so the least steady D "
                "is 0" if _found(z) else
                f"D = 0 on some valid steady state: {getattr(z, 'status', 'not asked')}")
        return f"not judged over the set: a claim about a run's path; {tail}; {why}"
    # fig13-tri-higher: D_tri > D_rect for some pair iff tri has D > 0 somewhere and rect a
    # state with less (D = 0); for none iff tri has no D > 0; for all iff rect is always 0
    # and tri always > 0 (both negations infeasible)
    if _none(pos["fig13_tri"]):
        return f"holds for none{_scope(pos['fig13_tri'])}: tri {pos['fig13_tri'].note}; {why}"
    if _found(pos["fig13_tri"]) and _none(pos["fig13"]) and _none(zero["fig13_tri"]):
        return (f"holds for all: every tri state dissipates ({zero['fig13_tri'].note}), no "
                f"rect state does ({pos['fig13'].note}); {why}")
    if _found(pos["fig13_tri"]) and _found(zero["fig13"]):
        return (f"holds for some: tri with D > 0, {pos['fig13_tri'].note}; rect with D = 0, "
                f"{zero['fig13'].note}; {why}")
    return ("unknown (" + ", ".join(f"{k} {q}: {getattr(r, 'status', 'not asked')}"
                                    for q, d in (("D>0", pos), ("D=0", zero))
                                    for k, r in d.items()) + f"); {why}")


__all__ = ["over_all", "NA"]
