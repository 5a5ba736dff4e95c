"""rigidlcp's pure mathematics: LCP/MLCP problems, solvers, residuals. Knows nothing of disks.

Rooms (docs/architecture.md): problems/ (LCP, MLCP, FrictionContact2D, Solution), io/ (files),
acceptance/ (when an answer counts), solvers/ (one module per method), faces/ (the canonical
point of a solution set); registry.py (the table of methods), api.py (`solve`, the facade).
"""

from .acceptance import residual
from .api import MethodInfo, get_method, methods, register, solve
from .batch import solve_many
from .io.load import load
from .problems.problem import LCP, MLCP, InvalidProblem, NotApplicable
from .problems.solution import STATUSES, Solution, complementarity_residual

__all__ = [
    "LCP", "MLCP", "InvalidProblem", "NotApplicable", "load", "Solution", "STATUSES",
    "complementarity_residual", "solve", "solve_many", "methods", "get_method", "register",
    "MethodInfo", "enumerate_solutions", "FrictionContact2D", "natural_residual", "residual",
]


#: The modules of the flat lcp/ (until the rooms), still attributes of the package under their
#: old names: lcp.face is lcp.faces.face (docs/architecture.md, "Where the old imports went").
_MOVED = {
    **{m: f"problems.{m}" for m in ("problem", "solution", "friction")},
    **{m: f"acceptance.{m}" for m in ("trust", "accuracy", "residual", "farkas", "scaling")},
    **{m: f"solvers.{m}" for m in ("lemke", "lemke_exact", "fast_lemke", "enumeration",
                                    "mlcp_full", "newton", "nsgs", "pgs", "pivoting",
                                    "fast_pivoting", "qp", "states", "state_factor",
                                    "state_pivoting")},
    **{m: f"faces.{m}" for m in ("face", "face_coords", "face_reference")},
}


def __getattr__(name: str):
    # Loaded on first use: enumeration needs scipy.optimize, friction scipy.sparse; and the
    # public submodules are attributes (lcp.face, lcp.io, ...).
    if name == "enumerate_solutions":
        from .solvers.enumeration import enumerate_solutions

        return enumerate_solutions
    if name in ("FrictionContact2D", "natural_residual"):
        from .problems import friction

        return getattr(friction, name)
    if name in _MOVED:  # lcp.face, lcp.lemke, ...: the modules by their names before the rooms
        import importlib

        return importlib.import_module(f"{__name__}.{_MOVED[name]}")
    if not name.startswith("_"):  # a public submodule, as an attribute (issue 14.1)
        import importlib
        from importlib.util import find_spec

        if find_spec(f"{__name__}.{name}") is not None:
            return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
