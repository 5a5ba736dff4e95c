"""rigidlcp's pure mathematics: LCP/MLCP problems, solvers, residuals. Knows nothing of disks."""

from . import residual
from .api import MethodInfo, get_method, methods, register, solve
from .batch import solve_many
from .problem import LCP, MLCP, InvalidProblem, NotApplicable, load
from .solution import STATUSES, Solution, complementarity_residual

__all__ = [
    "LCP", "MLCP", "InvalidProblem", "NotApplicable", "load", "Solution", "STATUSES",
    "complementarity_residual", "solve", "solve_many", "methods", "get_method", "register",
    "MethodInfo", "enumerate_solutions", "FrictionContact2D", "natural_residual", "residual",
]


def __getattr__(name: str):
    # Loaded on first use: enumeration needs scipy.optimize, friction scipy.sparse; and the
    # public submodules are attributes (lcp.face, lcp.io, ...).
    if name == "enumerate_solutions":
        from .enumeration import enumerate_solutions

        return enumerate_solutions
    if name in ("FrictionContact2D", "natural_residual"):
        from . import friction

        return getattr(friction, name)
    if not name.startswith("_"):  # a public submodule, as an attribute (issue 14.1)
        import importlib
        from importlib.util import find_spec

        if find_spec(f"{__name__}.{name}") is not None:
            return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
