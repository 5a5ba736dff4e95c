"""Certificates and the paper's claims: residuals, uniqueness, null spaces, Eq. (3.3)/(3.4).

Subpackages by job: `certificates` (certify, uniqueness, laws), `nullspace` (null spaces of the
contact matrix, the paper's formulas, loops, exact ranks), `forces` (force polyhedra, ranges,
particular solutions); `strategies` holds hypothesis strategies for users' property tests.
`rigidlcp.verify.certify` is the function; import the module's other names with
`from rigidlcp.verify.certificates.certify import ...`. The subpackages and `strategies` are
attributes of the package, imported on first use (`verify.strategies.lcps()`).
"""

from .certificates.certify import Certificate as Certificate
from .certificates.certify import certify as certify
from .nullspace.contact import null_space as null_space
from .nullspace.formulas import paper_singularities as paper_singularities


def __getattr__(name: str):
    """Public subpackages and modules are attributes, imported on first use
    (verify.strategies, verify.nullspace, ...); verify.steady_ranges and verify.event_ranges
    are the functions of verify.ranges (issue 21)."""
    if name in ("steady_ranges", "event_ranges"):
        import importlib

        return getattr(importlib.import_module(f"{__name__}.ranges"), name)
    if not name.startswith("_"):
        import importlib
        import importlib.util

        if importlib.util.find_spec(f"{__name__}.{name}") is not None:
            return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
