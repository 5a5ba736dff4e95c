"""Results of range computations: one End per side (min / max), a Range per observable.

An End's status is "optimal" (the value is the exact extreme over the set searched, attained by
its witness), "unbounded" (a ray along which the observable grows without end, checked),
"time limit" (HiGHS stopped before proving optimality: the value, if any, is only the best
point met, *not* a bound) or "infeasible" (the set is empty). `scope` says over what the
extreme was taken ("all valid steady states", "the face of the given solution", "every
solution of the event", "... with R <= U" when a force bound is not proved).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

OPTIMAL, UNBOUNDED, TIME_LIMIT, INFEASIBLE = "optimal", "unbounded", "time limit", "infeasible"


@dataclass
class End:
    """One end of a range. value: the extreme (None unless status is "optimal"; +-inf when
    "unbounded"); witness: what attains it (a SteadyWitness, or an event's z); ray: the
    direction of unboundedness (checked); best: the best value met when the time limit
    stopped the search (not a bound); residual: the witness's independent residual; bound: for
    an end not decided, a proved bound on it where one is known (a lower bound of a min, an
    upper bound of a max: verify.ranges.cap_split), so the end lies in [bound, best] (min) or
    [best, bound] (max)."""

    status: str
    value: float | None = None
    witness: object | None = None
    ray: np.ndarray | None = None
    residual: float = float("nan")
    best: float | None = None
    seconds: float = 0.0
    note: str = ""
    bound: float | None = None

    def __repr__(self) -> str:
        if self.status == OPTIMAL:
            return f"{self.value:.10g} (residual {self.residual:.1e})"
        if self.status == UNBOUNDED:
            return f"{self.value} (ray checked)"
        if self.status == TIME_LIMIT:
            best = "" if self.best is None else f", best met {self.best:.10g} (not a bound)"
            proved = "" if self.bound is None else f", proved bound {self.bound:.10g}"
            return f"time limit{best}{proved}"
        return self.status


@dataclass
class Range:
    """[lo, hi] of one observable; `selected`: the value of a given solution (a run's state,
    the engine's event solution), which must lie in the range; `scope`: see the module
    docstring."""

    name: str
    lo: End
    hi: End
    scope: str = ""
    selected: float | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def interval(self) -> tuple[float | None, float | None]:
        return self.lo.value, self.hi.value

    @property
    def decided(self) -> bool:
        return self.lo.status in (OPTIMAL, UNBOUNDED) and self.hi.status in (OPTIMAL, UNBOUNDED)

    @property
    def width(self) -> float:
        if not self.decided:
            return float("nan")
        return float(self.hi.value) - float(self.lo.value)

    def contains(self, value: float, tol: float = 1e-9) -> bool:
        """value in [lo, hi] (to tol relative to the range's magnitude); False when undecided."""
        if not self.decided:
            return False
        lo, hi = float(self.lo.value), float(self.hi.value)
        slack = tol * max(1.0, abs(lo) if np.isfinite(lo) else 1.0,
                          abs(hi) if np.isfinite(hi) else 1.0)
        return lo - slack <= value <= hi + slack

    def __repr__(self) -> str:
        sel = "" if self.selected is None else f", selected {self.selected:.10g}"
        return f"{self.name}: [{self.lo!r}, {self.hi!r}]{sel}"


def end_cell(e: End, side: int) -> str:
    """An end in the table: its value; an open end as the interval it is known to lie in
    (proved bound and best value met) or its status."""
    if e.status == OPTIMAL:
        return f"{e.value:.10g}"
    if e.status == TIME_LIMIT and e.best is not None and e.bound is not None:
        lo, hi = (e.bound, e.best) if side < 0 else (e.best, e.bound)
        return f"in [{lo:.4g}, {hi:.4g}]"
    return e.status


def width_text(r: Range) -> str:
    """hi - lo, "-" while an end is open; a rounding-level negative width (lo above hi by
    1e-12 of their size, two LPs' optima of one point) shows as 0."""
    if not r.decided:
        return "-"
    w = r.width
    if -1e-12 * max(1.0, abs(float(r.lo.value)), abs(float(r.hi.value))) <= w < 0:
        w = 0.0
    return f"{w:.4g}"
