"""Steady-state claims judged over *all* valid steady states (issue 21, point 3; a start).

`mu_g_band` computes, per gamma of a sweep, the range of mu_g over every valid steady state
(verify.ranges.steady_ranges) and over the contact states of the selected run (`own`), and
`linear_through_zero` judges Fig. 11's "mu_g rises linearly with gamma, through 0" over that
set: "holds for all" (every range a point, the points on one line through 0), "holds for
none" (no line through 0 meets every range: the slope intervals [lo/gamma, hi/gamma] do not
intersect, or gamma = 0's range excludes 0), "holds for some" (a line through 0 made of
attained values: the lower ends, or the upper ends, lie on one line through 0, each end a
checked witness; at gamma = 0 the value 0 attained by an end or by the run's own checked
state), or "unknown" (an end not decided, or a line might pass through values
inside the ranges: the values of a union of contact-state sets need not fill the interval,
so the ends alone cannot prove it).

`steady_set` gives the range of mu_g over the valid steady states of an experiment's run (the
report's column "over all valid steady states", overall.py), `end_families` the effective
curves (Eqs. 4.1-4.2) of the band's lower and upper ends: each end is a checked valid steady
state per gamma, so each is one curve of valid steady states beside the selected one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigidlcp import models
from rigidlcp.models.effective import Effective, legendre
from rigidlcp.verify.ranges import Range, SteadyRanges, steady_ranges
from rigidlcp.verify.ranges.result import OPTIMAL, TIME_LIMIT

#: Seconds per end of a band point (Fig. 11's 10x1: ~0.4 s per point) and of an experiment's
#: steady set (the 10x4 and 10x2 arrays decide the upper end of mu_g, mu_plane, in < 1 s, not
#: the lower end: "time limit" with the best value met, e.g. the rolling checkerboard's).
BAND_TIME_LIMIT = 20.0
SET_TIME_LIMIT = {False: 30.0, True: 2.0}
#: The clock of the report's range and pattern searches (verify.ranges.milp.clock): CPU
#: seconds, so that where a search stops, hence a verdict, does not depend on the machine's
#: load. HiGHS checks the limit only between some of its steps, so a search may overrun its
#: CPU limit (measured: a 1 s limit stopped after 1.9 s; docs/benchmarks.md).
SEARCH_CLOCK = "cpu"


@dataclass
class BandPoint:
    """One gamma: the range over all valid steady states, the range over the selected run's
    contact states (None if the run is not steady), and the run's value."""

    gamma: float
    every: Range
    own: Range | None
    selected: float | None


def mu_g_band(params: dict, gammas, *, seed: int = 1, time_limit: float = 10.0,
              clock: str = SEARCH_CLOCK) -> list[BandPoint]:
    """params: a sweep's system parameters (lattice, lx, ly, mu_pp, mu_plane, mu_wall, ...);
    time_limit: seconds per end, on `clock` (verify.ranges.steady_ranges)."""
    p = {k: v for k, v in params.items() if k in ("mu_pp", "mu_plane", "mu_wall", "V0",
                                                   "mass", "inertia", "g")}
    out = []
    for gamma in gammas:
        system = models.make_system(params.get("lattice", "rect"), params["lx"], params["ly"],
                                    gamma=float(gamma), **p)
        run = models.simulate(system, seed=seed)
        target = run if run.status == "steady" else system
        r = steady_ranges(target, time_limit=time_limit, clock=clock)
        out.append(BandPoint(float(gamma), r.mu_g, r.own.get("mu_g"),
                             r.run_values.get("mu_g")))
    return out


def _on_line(values: np.ndarray, gammas: np.ndarray, rel: float, zero_ok: np.ndarray
             ) -> float | None:
    """The slope k if values = k gamma within rel for gamma > 0; at gamma = 0 the value 0
    must be attained (the end is ~0, or zero_ok: the run's own checked state has mu_g ~0)."""
    pos = gammas > 0
    if not np.all((np.abs(values) <= rel) | zero_ok | pos) or not pos.any():
        return None
    k = values[pos] / gammas[pos]
    return float(k.mean()) if np.ptp(k) <= rel * max(1.0, float(np.abs(k).max())) else None


def linear_through_zero(points: list[BandPoint], rel: float = 1e-9,
                        which: str = "every") -> tuple[str, str]:
    """(verdict, reason) of "mu_g = k gamma for one k" over the ranges (`which`: "every" or
    "own"); see the module docstring."""
    ranges = [getattr(pt, which) for pt in points]
    if any(r is None or r.lo.status != OPTIMAL or r.hi.status != OPTIMAL for r in ranges):
        return "unknown", "an end is not decided (time limit, unbounded or no run)"
    g = np.array([pt.gamma for pt in points])
    lo = np.array([r.lo.value for r in ranges])
    hi = np.array([r.hi.value for r in ranges])
    if np.any((g == 0) & ((lo > rel) | (hi < -rel))):
        return "holds for none", "at gamma = 0 no valid steady state has mu_g = 0"
    pos = g > 0
    k_lo = float(np.max(lo[pos] / g[pos])) if pos.any() else -np.inf
    k_hi = float(np.min(hi[pos] / g[pos])) if pos.any() else np.inf
    if k_lo > k_hi * (1 + rel) + rel:
        return "holds for none", (f"no slope fits every range: lo/gamma up to {k_lo:.6g} > "
                                  f"hi/gamma down to {k_hi:.6g}")
    if np.all(hi - lo <= rel * np.maximum(1.0, np.abs(hi))):
        k = _on_line(lo, g, rel, np.zeros(g.size, bool))
        return (("holds for all", f"every range a point, slope {k:.6g}") if k is not None
                else ("holds for none", "every range a point, not on one line through 0"))
    zero_ok = np.array([pt.gamma == 0 and pt.own is not None and pt.selected is not None
                        and abs(pt.selected) <= rel for pt in points])
    for name, ends in (("lower", lo), ("upper", hi)):
        k = _on_line(ends, g, rel, zero_ok)
        if k is not None:
            return "holds for some", (f"the {name} ends (checked witnesses) lie on mu_g = "
                                      f"{k:.6g} gamma; slopes {k_lo:.6g}..{k_hi:.6g} fit "
                                      "every range")
    return "unknown", (f"slopes {k_lo:.6g}..{k_hi:.6g} fit every range, but neither end "
                       "lies on one line (intermediate values not checked)")


def steady_set(run: models.Run, time_limit: float, clock: str = SEARCH_CLOCK
               ) -> SteadyRanges | str:
    """The range of mu_g over every valid steady state of a run's system, with the run's own
    contact states (time_limit seconds per end, on `clock`); a string (the reason) when there
    is none to compute."""
    try:
        return steady_ranges(run, time_limit=time_limit, clock=clock)
    except Exception as exc:  # NotSteady, a solver failure: the column says why
        return f"{type(exc).__name__}: {exc}"


def end_families(points: list[BandPoint], m_g: float, g: float = 1.0
                 ) -> dict[str, Effective | None]:
    """{"lower": Effective, "upper": Effective} of the band's end curves F_g = m_g g mu_g over
    the gammas where that end is decided (None with fewer than 3 such gammas)."""
    out: dict[str, Effective | None] = {}
    for key in ("lower", "upper"):
        ends = [(pt.gamma, (pt.every.lo if key == "lower" else pt.every.hi)) for pt in points]
        ok = [(gam, e.value) for gam, e in ends if e.status == OPTIMAL]
        if len(ok) < 3:
            out[key] = None
            continue
        gam, mu = np.array(ok).T
        out[key] = legendre(gam, m_g * g * mu, m_g, g)
    return out


def fmt_range(r: Range | None) -> str:
    """"[lo, hi]" with an undecided end as "time limit (best met x, not a bound)" and its
    proved bound where one is known (End.bound, verify.ranges.cap_split)."""
    if r is None:
        return "not computed"

    def end(e) -> str:
        if e.status == OPTIMAL:
            return f"{e.value:.7g}"
        proved = ("" if e.bound is None else
                  f"; proved {'>=' if e is r.lo else '<='} {e.bound:.7g}")
        if e.status == TIME_LIMIT and e.best is not None:
            return f"unknown (time limit; best met {e.best:.7g}, not a bound{proved})"
        if e.status == TIME_LIMIT:
            return f"unknown (time limit; no value met{proved})"
        return e.status
    return f"[{end(r.lo)}, {end(r.hi)}]"


def values_met(r: Range) -> list[float]:
    """The values of r's checked witnesses (decided ends and best values met at a time limit)."""
    out = []
    for e in (r.lo, r.hi):
        if e.status == OPTIMAL:
            out.append(float(e.value))
        elif e.status == TIME_LIMIT and e.best is not None:
            out.append(float(e.best))
    return out
