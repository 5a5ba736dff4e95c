"""Columns and rows of the report that cross-check the claims (issues 16.5, 17.4).

`cross_check(res, claim)` fills a claim's "kept by the toolkit's time-stepper" and "determinacy"
columns from the checks of crosscheck.py; `fig8_any` / `fig9_any` are the rows saying whether
the paper's Fig. 8-9 modes are reached by any valid particular-solution selection we ran.
"""

from __future__ import annotations

import numpy as np

from rigidlcp.models.modes import row_modes

from .crosscheck import TS_H
from .experiments import Claim, Results, sweep_gammas

#: Fig. 9's first-row counts in modes 1 / 2 / 3 (nine disks counted of ten).
PAPER_FIG9 = (4, 3, 2)


def experiments_of(cid: str) -> tuple[list[str], list[str]]:
    """(experiments, sweeps) whose steady states a claim is about (none: not a steady-state
    claim, e.g. Eqs. (3.3)-(3.4))."""
    for prefix, exps, sweeps in (("fig7", ["fig7"], []), ("fig10", ["fig10"], []),
                                 ("fig8", ["fig8"], []), ("fig9", ["fig9"], []),
                                 ("fig11", [], ["fig11"]), ("fig12", [], ["fig11"]),
                                 ("ivb-plane", [], ["fig11", "ivb_plane"]),
                                 ("ivb-pp", [], ["fig11", "ivb_pp"]),
                                 ("fig13", ["fig13", "fig13_tri"], []), ("fig6", ["fig6"], [])):
        if cid.startswith(prefix):
            return exps, sweeps
    return [], []


def cross_check(res: Results, c: Claim) -> None:
    """Fill the columns "kept by the toolkit's time-stepper" and "determinacy" of claim c from the
    cross-checks in res (crosscheck.py). A missing or broken check is a FAIL in the column."""
    exps, sweeps = experiments_of(c.id)
    if not exps and not sweeps:
        c.ts, c.determinacy = "n/a (not a steady-state claim)", "n/a"
        return
    labels = list(exps)
    for name in sweeps:
        labels += [f"{name} gamma={g:g}" for g in sweep_gammas(res.plan[name])]
    checks = [res.ts_checks.get(label) for label in labels]
    missing = [lab for lab, x in zip(labels, checks) if x is None]
    broken = [x for x in checks if x is not None and x.error]
    if missing or broken:
        c.ts_confirmed = False
        c.ts = "FAIL (evaluation error: " + "; ".join(
            [f"{lab}: not run" for lab in missing] + [x.text() for x in broken]) + ")"
    else:
        bad = [x for x in checks if not x.confirmed]
        c.ts_confirmed = not bad
        c.ts = (f"kept ({len(checks)} steady state(s): {', '.join(labels)})" if not bad
                else "NOT kept: " + "; ".join(x.text() for x in bad)
                + (f" ({len(checks) - len(bad)} other(s) kept)" if len(bad) < len(checks)
                   else ""))
    if not exps:
        c.determinacy = "not certified (sweep points)"
        return
    certs = [res.certificates.get(name) for name in exps]
    c.determinacy = "; ".join(
        f"{name}: FAIL (evaluation error: not run)" if x is None else x.short()
        for name, x in zip(exps, certs))


def _selections(res: Results, name: str) -> list[tuple[str, bool, object, str]]:
    """Every particular-solution selection we ran on `name`'s system (first seed, the
    caption's gamma): (label, valid steady state, first-row modes, status). The
    time-stepper's state comes from the confirmation run (crosscheck.py): valid when that run
    ended steady and its last step satisfies the exact event problem."""
    cfg = res.plan[name]
    out = []
    for (seed, gamma, sel), run in sorted(res.runs[name].items()):
        if seed == cfg["seeds"][0] and gamma == cfg["gamma"]:
            sel_, _, method = sel.partition("/")
            label = f"select='{sel_}', {method or 'lemke'}"
            out.append((label, bool(run.steady), row_modes(run.system, run.last),
                        f"{run.status}, {run.n_events} events, mu_g {run.last.mu_g:.6f}"))
    ts = res.ts_checks.get(name)
    if ts is not None and not ts.error:
        out.append((f"Moreau-Jean h={TS_H:g} from the ED steady state",
                    ts.status == "steady" and bool(ts.ts_valid_event), ts.row_ts,
                    f"{ts.status}, mu_g {ts.mu_g_ts:.6f}"))
    return out


def _any_selection(res: Results, name: str, paper: str, reached) -> Claim:
    """Is the paper's mode pattern reached by any valid selection we ran? reached(rm) -> bool."""
    rows = _selections(res, name)
    parts, hit = [], []
    for label, valid, rm, status in rows:
        ok = valid and bool(reached(rm))
        c = rm.counts()
        parts.append(f"{label}: {rm.text()} ({c[0]}/{c[1]}/{c[2]}; {status}"
                     f"{'' if valid else '; not a valid steady state'})")
        if ok:
            hit.append(label)
    lat = res.runs[name][next(iter(res.runs[name]))].system.lattice
    return Claim(f"{name}-any-selection", "", f"(Issue 16.5) {paper} is reached by some valid "
                 "particular-solution selection at non-unique events",
                 f"{lat.name} {lat.lx}x{lat.ly}, first row under {len(rows)} selection(s): "
                 + "; ".join(parts) + ". Reached by: " + (", ".join(hit) or "none"),
                 "some selection whose run ends in a steady state (every event's solution "
                 "checked; for the time-stepper: ended steady and exact in the event problem) "
                 "gives the paper's pattern (same classifier and reading as the row above)",
                 bool(hit))


def fig8_any(res: Results) -> Claim:
    lx = res.plan["fig8"]["lx"]
    return _any_selection(res, "fig8", "Fig. 8's first row all in mode 1",
                          lambda rm: int(np.sum(rm.modes == 1)) == lx)


def fig9_any(res: Results) -> Claim:
    def reached(rm) -> bool:
        drops = []
        for k in np.flatnonzero(rm.wall):
            d = np.zeros(rm.modes.size, bool)
            d[k] = True
            drops.append(rm.counts(d))
        return PAPER_FIG9 in drops

    return _any_selection(res, "fig9", "Fig. 9's first-row counts 4/3/2 (one wall disk left "
                          "out)", reached)


__all__ = ["PAPER_FIG9", "experiments_of", "cross_check", "fig8_any", "fig9_any"]
