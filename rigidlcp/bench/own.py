"""The keyword arguments that make `lcp.solve` / `lcp.solve_many` return the named method's own
answer, never another method's substituted for it (issue 23, point 1): ``repair=False`` where
lcp.solve has that switch; where it has not, its own answer is the default. bench and fuzz
count each method's own outcome with these."""

from __future__ import annotations

import inspect

from rigidlcp import lcp

OWN_ANSWER: dict = ({"repair": False} if "repair" in inspect.signature(lcp.solve).parameters
                    else {})
