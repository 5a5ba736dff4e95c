"""Importing this module registers every built-in method with `lcp.api`."""

from . import enumeration, lemke, mlcp_full, newton, nsgs, pgs, pivoting, qp, states  # noqa: F401
