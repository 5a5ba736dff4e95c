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
    # Loaded on first use: enumeration needs scipy.optimize, friction scipy.sparse.
    if name == "enumerate_solutions":
        from .enumeration import enumerate_solutions

        return enumerate_solutions
    if name in ("FrictionContact2D", "natural_residual"):
        from . import friction

        return getattr(friction, name)
    raise AttributeError(f"module 'lcp' has no attribute {name!r}")
