"""HiGHS as verify calls it: its tolerances for the MILPs and LPs of the uniqueness search, and
a context that silences its prints (split out of verify.certificates.uniqueness: one job per
module; re-exported there)."""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator

from rigidlcp.lcp.quiet import quiet_stdout

#: HiGHS tolerances for the MILP and the polishing LP (its defaults are 1e-6 / 1e-7). Options
#: other than scipy's own five are passed to HiGHS verbatim (scipy warns; the warning is muted).
HIGHS_MILP = {"mip_feasibility_tolerance": 1e-9, "primal_feasibility_tolerance": 1e-9}
HIGHS_LP = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


@contextlib.contextmanager
def quiet_highs() -> Iterator[None]:
    """Silence HiGHS's C++ debug prints (e.g. "HighsMipSolverData::transformNewInteger...") that
    go to file descriptor 1 whatever log_to_console says (lcp.quiet.quiet_stdout), and scipy's
    warning about passing HiGHS options verbatim."""
    with warnings.catch_warnings(), quiet_stdout():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


__all__ = ["HIGHS_LP", "HIGHS_MILP", "quiet_highs"]
