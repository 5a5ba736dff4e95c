"""rigidlcp: rigid disks with Signorini's condition and the exact Coulomb law as LCPs.

Radjai, Brendel & Roux, Phys. Rev. E 54, 861 (1996). The library has three floors, each
importing only the ones below it (docs/architecture.md):

* `rigidlcp.lcp` — pure mathematics: problems, solvers, residuals, file formats (lcp/);
* `rigidlcp.models` — mechanics: lattices, the MLCP of an event, the event engine (models/);
* `rigidlcp.verify` — certificates and the paper's claims (verify/);

and three applications built on them: `rigidlcp.bench` (solver comparison), `rigidlcp.reproduce`
(the paper's Sec. IV) and `rigidlcp.cli` (the `rigidlcp` command). Subpackages load on first use,
so `import rigidlcp` is cheap.
"""

from __future__ import annotations

import importlib
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("rigidlcp")
except PackageNotFoundError:  # a source tree that was not installed
    __version__ = "0+unknown"

SUBPACKAGES = ("lcp", "models", "verify", "bench", "reproduce", "cli")

__all__ = ["__version__", *SUBPACKAGES]


def __getattr__(name: str):
    if name in SUBPACKAGES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
