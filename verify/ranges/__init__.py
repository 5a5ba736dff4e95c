"""Certified ranges of observables over whole solution sets (issue 21).

* `steady_ranges(system or run)`: over every valid steady state (docs/mechanics.md).
* `event_ranges(event, solution, observables)`: over every solution of an event's LCP, and
  over the face of the given solution (verify.ranges.event).

Each end of a range carries a witness checked independently, a ray when unbounded, or the
status "time limit" (never a bound).
"""

from .event import EventRanges as EventRanges
from .event import event_ranges as event_ranges
from .result import End as End
from .result import Range as Range
from .valid_steady import SteadyRanges as SteadyRanges
from .valid_steady import steady_ranges as steady_ranges
