"""The sparse event engine's solver: contact-state pivoting, which lives in
rigidlcp.lcp.solvers.state_pivoting (promoted there by issue 12 so that lcp.solve's method
``states`` can use it); re-exported here under its models name."""

from rigidlcp.lcp.solvers.state_pivoting import (  # noqa: F401
    INDEPENDENT,
    EventLCP,
    StateSolution,
    lcp_residual,
    local_rescue,
    solve_states,
    violations,
)
