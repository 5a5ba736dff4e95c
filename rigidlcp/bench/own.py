"""The keyword arguments that make `lcp.solve` / `lcp.solve_many` return the named method's own
answer, never another method's substituted for it (issue 23, point 1). Where lcp.solve has a
``fallback=`` switch, other methods are tried only when asked, so its defaults (the natural
call) already give the method's own answer, with its own retries; where it has only
``repair=``, whose repairs may substitute pivoting's or lemke's answer, ``repair=False``.
bench and fuzz count each method's own outcome with these."""

from __future__ import annotations

import inspect

from rigidlcp import lcp

_PARAMETERS = inspect.signature(lcp.solve).parameters
OWN_ANSWER: dict = ({} if "fallback" in _PARAMETERS else
                    {"repair": False} if "repair" in _PARAMETERS else {})
