"""The certificates' MILPs in HiGHS (highspy) with a time limit on a chosen clock.

A verdict must not depend on the machine's load (issue 21): a MILP stopped by a wall-clock
limit on a loaded machine says "unknown" where a quiet machine finds another solution. With
clock "cpu" the limit counts this process's CPU seconds (time.process_time): HiGHS's MIP and
simplex interrupt callbacks compare the clock with the deadline, and HiGHS's own (wall-clock)
time_limit stays as a backstop at BACKSTOP_FACTOR times the limit plus BACKSTOP_S seconds (a
search that never reaches a callback, e.g. a long presolve, still stops). With clock "wall"
HiGHS's own time_limit is the limit. Either way a search stopped by its limit is reported as a
time limit (status 1), never as a verdict. HiGHS looks at the callback only between some of
its steps, so a CPU limit may be overrun (docs/benchmarks.md: 1 CPU s -> 1.9 CPU s).

The ranges' MILP (verify.ranges.milp) uses the same clocks (`clock`) and backstop.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rigidlcp.lcp.errors import InvalidInput
from rigidlcp.lcp.quiet import new_highs

from .highs import quiet_highs

#: The clocks a time limit may count: this process's CPU seconds or the wall clock.
#: (Looked up at each call, so a test can put a clock of its own here.)
CLOCKS: dict[str, Callable[[], float]] = {"wall": time.perf_counter, "cpu": time.process_time}
#: The unit a limit on each clock is written in (messages).
UNITS = {"wall": "s", "cpu": "CPU s"}
#: clock "cpu": HiGHS's own (wall-clock) limit kept as a backstop at this many times the CPU
#: limit plus BACKSTOP_S seconds.
BACKSTOP_FACTOR, BACKSTOP_S = 20.0, 60.0


def check_clock(name: str) -> str:
    """name if it is a clock ("cpu" or "wall"), else InvalidInput (a ValueError)."""
    if name not in CLOCKS:
        raise InvalidInput(f"clock must be 'wall' or 'cpu', got {name!r}")
    return name


def clock(name: str) -> Callable[[], float]:
    """The clock of a time limit: "wall" (time.perf_counter) or "cpu" (time.process_time,
    this process's CPU seconds: a limit then means the same work whatever the machine's
    load). The clock is looked up in CLOCKS at each reading."""
    check_clock(name)
    return lambda: CLOCKS[name]()


def start_cpu_interrupt(h, highspy, deadline: list[float], now: Callable[[], float] | None
                        = None) -> None:
    """Have HiGHS instance `h` interrupt itself (model status kInterrupt) once now() (default
    time.process_time) reaches deadline[0] (a box the caller may reset between runs), checked
    in its MIP and simplex interrupt callbacks. The flag is set either way at each call:
    HiGHS keeps it from one run to the next."""
    now = time.process_time if now is None else now

    def interrupt(kind, message, data_out, data_in, user_data) -> None:
        data_in.user_interrupt = now() >= deadline[0]

    h.setCallback(interrupt, None)
    h.startCallback(highspy.cb.HighsCallbackType.kCallbackMipInterrupt)
    h.startCallback(highspy.cb.HighsCallbackType.kCallbackSimplexInterrupt)


@dataclass
class MilpAnswer:
    """What `solve_milp` returns, in scipy.optimize.milp's terms: status 0 optimal, 1 a limit
    (time, iterations, interrupt), 2 infeasible, 3 unbounded, 4 other; x a feasible point
    (None if HiGHS has none); message HiGHS's model status."""

    status: int
    x: np.ndarray | None
    message: str


def solve_milp(c: np.ndarray, integrality: np.ndarray, A, row_lo: np.ndarray,
               row_hi: np.ndarray, col_lo: np.ndarray, col_hi: np.ndarray, *,
               time_limit: float, options: dict, clock_name: str = "cpu") -> MilpAnswer:
    """min c.x over row_lo <= A x <= row_hi, col_lo <= x <= col_hi, x_j integer where
    integrality_j, in HiGHS with `options` (HiGHS names; presolve True/False) and time_limit
    seconds on the clock `clock_name` (module docstring)."""
    import highspy

    now = clock(clock_name)
    A = sp.csc_matrix(A)
    n = A.shape[1]
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = n, A.shape[0]
    lp.col_cost_ = np.asarray(c, float)
    lp.col_lower_ = np.broadcast_to(np.asarray(col_lo, float), n).copy()
    lp.col_upper_ = np.broadcast_to(np.asarray(col_hi, float), n).copy()
    lp.row_lower_, lp.row_upper_ = np.asarray(row_lo, float), np.asarray(row_hi, float)
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (A.indptr, A.indices,
                                                                     A.data)
    lp.integrality_ = [highspy.HighsVarType.kInteger if v else highspy.HighsVarType.kContinuous
                       for v in np.asarray(integrality)]
    opts = {k: (("on" if v else "off") if isinstance(v, bool) else v)
            for k, v in options.items()}
    h = new_highs(**opts)
    h.passModel(lp)
    limit = float(time_limit)
    if clock_name == "cpu":
        start_cpu_interrupt(h, highspy, [now() + limit], now)
        h.setOptionValue("time_limit", BACKSTOP_FACTOR * limit + BACKSTOP_S)
    else:
        h.setOptionValue("time_limit", limit)
    with quiet_highs():
        h.run()
    st, hs = h.getModelStatus(), highspy.HighsModelStatus
    limits = (hs.kTimeLimit, hs.kIterationLimit, hs.kSolutionLimit, hs.kInterrupt)
    status = (0 if st == hs.kOptimal else 1 if st in limits else 2 if st == hs.kInfeasible
              else 3 if st in (hs.kUnbounded, hs.kUnboundedOrInfeasible) else 4)
    has_x = status in (0, 1) and h.getInfo().primal_solution_status == 2
    x = np.asarray(h.getSolution().col_value, float) if has_x else None
    message = h.modelStatusToString(st)
    if st == hs.kInterrupt and clock_name == "cpu":
        message = f"time limit {limit:g} CPU s reached (HiGHS: {message})"
    return MilpAnswer(status, x, message)


__all__ = ["BACKSTOP_FACTOR", "BACKSTOP_S", "CLOCKS", "UNITS", "MilpAnswer", "check_clock",
           "clock", "solve_milp", "start_cpu_interrupt"]
