"""One exception root for the whole toolkit (in the style of qpsolvers' exceptions module).

Every error that rigidlcp raises on purpose derives from `RigidLCPError`, so that a caller (and
the command line, which turns it into one line and exit status 2) can catch exactly the
toolkit's errors. Each class also derives from ValueError where the error is about a value the
caller passed, so that `except ValueError` keeps working.

A solver that runs and fails is *not* an exception: it returns a `Solution` whose status says
what happened, with its evidence (lcp/problems/solution.py).
"""

from __future__ import annotations


class RigidLCPError(Exception):
    """The root of every error raised on purpose by rigidlcp."""


class InvalidInput(RigidLCPError, ValueError):
    """Bad input: the message names the offending argument (or file) and what was expected."""


class InvalidProblem(InvalidInput):
    """A problem that cannot be built: wrong shape, NaN, negative mu, unknown method, ..."""


class InvalidFile(InvalidInput):
    """A file that is missing, corrupt or of another kind: the message names the file (and the
    line, for text formats) and what was expected. A file is never read as something else."""


class NotApplicable(RigidLCPError, ValueError):
    """A method (or a reduction) refuses a well-formed problem, and says why."""


class NotASolution(RigidLCPError, TypeError):
    """A registered method returned something other than an lcp.Solution (e.g. a forgotten
    `return`): an error of the method's code, named, never reported as the method's failure."""


class OutputExists(RigidLCPError, FileExistsError):
    """An output path that already exists and would be overwritten (pass force=True / --force)."""
