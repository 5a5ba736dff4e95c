"""Importing this module registers every built-in method with `lcp.api`."""

from . import enumeration, lemke, pgs, pivoting, qp  # noqa: F401
