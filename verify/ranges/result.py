"""Results of range computations: one End per side (min / max), a Range per observable.

An End's status is "optimal" (the value is the exact extreme over the set searched, attained by
its witness), "unbounded" (a ray along which the observable grows without end, checked),
"time limit" (HiGHS stopped before proving optimality: the value, if any, is only the best
point met, *not* a bound), "unproved" (a check failed before the end was proved: the note
says which; the best value met, if any, is not a bound) or "infeasible" (the set is empty).
`scope` says over what the extreme was taken ("all valid steady states", "the face of the
given solution", "every solution of the event", "... with R <= U" when a force bound is not
proved).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from rigidlcp.models.system import System

OPTIMAL, UNBOUNDED, TIME_LIMIT, INFEASIBLE = "optimal", "unbounded", "time limit", "infeasible"
#: An end a check could not prove (the note says why); its best value met is not a bound.
UNPROVED = "unproved"


@dataclass
class End:
    """One end of a range. value: the extreme (None unless status is "optimal"; +-inf when
    "unbounded"); witness: what attains it (a SteadyWitness, or an event's z); ray: the
    direction of unboundedness (checked); best: the best value met when the time limit
    stopped the search (not a bound); residual: the witness's independent residual; bound: for
    an end not decided, a proved bound on it where one is known (a lower bound of a min, an
    upper bound of a max: verify.ranges.cap_split), so the end lies in [bound, best] (min) or
    [best, bound] (max); tol: what the value L . x of the witness is known to
    (`end_tolerance`; NaN when not known), which the table's cells respect (`end_cell`)."""

    status: str
    value: float | None = None
    witness: object | None = None
    ray: np.ndarray | None = None
    residual: float = float("nan")
    best: float | None = None
    seconds: float = 0.0
    note: str = ""
    bound: float | None = None
    tol: float = float("nan")

    def __repr__(self) -> str:
        if self.status == OPTIMAL:
            return f"{self.value:.10g} (residual {self.residual:.1e})"
        if self.status == UNBOUNDED:
            return f"{self.value} (ray checked)"
        if self.status == TIME_LIMIT:
            best = "" if self.best is None else f", best met {self.best:.10g} (not a bound)"
            proved = "" if self.bound is None else f", proved bound {self.bound:.10g}"
            return f"time limit{best}{proved}"
        if self.status == UNPROVED and self.best is not None:
            return f"unproved, best met {self.best:.10g} (not a bound)"
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


#: The unit roundoff of IEEE double precision.
_U = 2.0 ** -53


def end_tolerance(L: np.ndarray, x: np.ndarray, residual: float = 0.0,
                  f_scale: float = 0.0) -> float:
    """What an end's value L . x is known to. First the rounding of the computed dot product
    in any summation order, gamma_k sum_i |L_i x_i| (k the number of pairs with L_i, x_i !=
    0, gamma_k = k u / (1 - k u), u = 2^-53; Higham, Accuracy and Stability of Numerical
    Algorithms, 2nd ed., Sec. 3.1), taken 1.01 times (the sum of |L_i x_i| is itself
    computed), with k 2^-1074 added for products that underflow. Then residual * f_scale *
    sum_i |L_i|: the witness x was accepted as a valid steady state to `residual`, relative
    to the force scale f_scale of verify.steadiness (max(|x|, m g)), i.e. each force only to
    residual * f_scale, and its value only to that much."""
    L, x = np.asarray(L, dtype=float), np.asarray(x, dtype=float)
    terms = np.abs(L * x)
    k = int(np.count_nonzero((L != 0) & (x != 0)))  # a product that underflows counts
    rounding = (1.01 * k * _U / (1 - k * _U) * float(terms.sum()) + k * 2.0 ** -1074
                if k else 0.0)
    law = residual * f_scale * float(np.abs(L).sum()) if residual > 0 else 0.0
    return rounding + law


def witness_tolerance(system: System, L: np.ndarray, x: np.ndarray, residual: float) -> float:
    """end_tolerance of a witness x = [R; S] with its steady_check residual, at the force
    scale of verify.steadiness.from_velocities."""
    f_scale = max(float(np.max(np.abs(x), initial=0.0)),
                  float(system.mass) * max(system.g, abs(system.gamma), 1e-12))
    return end_tolerance(L, x, residual, f_scale)


def value_text(x: float, tol: float = float("nan"), digits: int = 10) -> str:
    """x for the table: at most `digits` significant digits, and none finer than what it is
    known to, `tol` (`end_tolerance`: the rounding of L . x and the witness's residual; NaN:
    not known, then `digits` digits). x is printed as 0 only when |x| <= tol: neither the
    arithmetic that computed it nor the check that accepted its witness tells x from 0 (nor
    its sign), so 0 is as true a reading as x; with no tolerance known, nothing is printed
    as 0 but 0 itself. The JSON (to_dict) keeps every value in full precision."""
    if not np.isfinite(x):
        return f"{x}"
    if np.isfinite(tol) and tol > 0:
        if abs(x) <= tol:
            return "0"
        digits = max(1, min(digits, int(np.floor(np.log10(abs(x) / tol)))))
    elif tol == 0 and x == 0:
        return "0"
    return f"{x:.{digits}g}"


def _outward(x: float, side: int, digits: int = 4) -> str:
    """x to `digits` significant digits rounded outward (down for side < 0, up for side > 0):
    a printed interval then still contains the one it stands for."""
    if not np.isfinite(x) or x == 0:
        return value_text(x, digits=digits)
    text = f"{x:.{digits}g}"
    if (float(text) < x and side > 0) or (float(text) > x and side < 0):
        e = int(np.floor(np.log10(abs(x)))) - digits + 1
        text = f"{float(text) + np.sign(side) * 10.0 ** e:.{digits}g}"
    return text


def end_cell(e: End, side: int) -> str:
    """An end in the table: its value (`value_text`: no digits below its tolerance e.tol, 0
    only when within it); an open end as the interval it is known to lie in (proved
    bound and best value met, each to 4 digits rounded outward, the best value met as 0 when
    within its rounding bound) or its status."""
    if e.status == OPTIMAL:
        return value_text(float(e.value), e.tol)
    if e.status == TIME_LIMIT and e.best is not None and e.bound is not None:
        best = 0.0 if np.isfinite(e.tol) and abs(e.best) <= e.tol else e.best
        lo, hi = (e.bound, best) if side < 0 else (best, e.bound)
        return f"in [{_outward(lo, -1)}, {_outward(hi, +1)}]"
    return e.status


def width_text(r: Range) -> str:
    """hi - lo, "-" while an end is open; a width within the ends' tolerances (lo.tol +
    hi.tol, or, where they are not known, a negative width of 1e-12 of the ends' size: two
    LPs' optima of one point) shows as 0."""
    if not r.decided:
        return "-"
    w = r.width
    slack = r.lo.tol + r.hi.tol
    if np.isfinite(slack) and np.isfinite(w) and abs(w) <= slack:
        w = 0.0
    elif -1e-12 * max(1.0, abs(float(r.lo.value)), abs(float(r.hi.value))) <= w < 0:
        w = 0.0
    return f"{w:.4g}"
