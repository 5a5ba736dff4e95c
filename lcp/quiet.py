"""Solver output stays off the user's terminal unless asked for.

Some solver libraries print from C code, on file descriptor 1, where Python's
`contextlib.redirect_stdout` cannot reach: HiGHS prints its copyright banner when the first
`highspy.Highs` of a process is built (before any option such as output_flag can be set).
`quiet_stdout` silences descriptor 1 for a block; `new_highs` builds a silent `highspy.Highs`.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator

_HIGHS_GREETED = False


@contextlib.contextmanager
def quiet_stdout() -> Iterator[None]:
    """Silence C-level prints on file descriptor 1 for the duration of the block."""
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # no real descriptor: nothing to silence
        yield
        return
    sys.stdout.flush()
    saved = os.dup(fd)
    try:
        with open(os.devnull, "w") as devnull:
            os.dup2(devnull.fileno(), fd)
            yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)


def new_highs(**options):
    """A `highspy.Highs` with output_flag off and each of `options` set (HiGHS option names,
    e.g. presolve="off"); the first one of the process is built with descriptor 1 silenced, so
    that HiGHS's banner is not printed."""
    global _HIGHS_GREETED
    import highspy

    if _HIGHS_GREETED:
        h = highspy.Highs()
    else:
        with quiet_stdout():
            h = highspy.Highs()
        _HIGHS_GREETED = True
    h.setOptionValue("output_flag", False)
    for key, value in options.items():
        h.setOptionValue(key, value)
    return h
