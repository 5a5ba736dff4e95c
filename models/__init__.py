"""Mechanics: lattices and packings of rigid disks, contacts, the MLCP of an event, evolution.

Dependencies point lcp <- models <- verify: this package imports `lcp`, never `verify`.
The names below load on first use (PEP 562), so that a command loads only the modules it uses
(e.g. `rigidlcp sweep --help` reads models.sweep's defaults without scipy.sparse). The public
submodules are attributes too (`models.runio.save_run`, `models.plot`, ...).
"""

from __future__ import annotations

import importlib

#: Public name -> the submodule that defines it.
_WHERE = {
    "Dynamics": "dynamics",
    "Run": "engine", "simulate": "engine",
    "EventProblem": "event", "EventSolution": "event", "State": "event",
    "contact_matrix": "event", "event_problem": "event", "initial_state": "event",
    "LEFT_WALL": "lattice", "PLANE": "lattice", "RIGHT_WALL": "lattice",
    "InvalidSystem": "lattice", "Lattice": "lattice", "make_lattice": "lattice",
    "rectangular": "lattice", "triangular": "lattice",
    "System": "system", "make_system": "system",
    "make_packing": "packing", "Overlap": "packing",
}

__all__ = [
    "Dynamics", "EventProblem", "EventSolution", "State", "contact_matrix", "event_problem",
    "initial_state", "Run", "simulate", "Lattice", "InvalidSystem", "rectangular",
    "triangular", "make_lattice", "System", "make_system", "LEFT_WALL", "RIGHT_WALL", "PLANE",
    "make_packing", "Overlap",
]


def __getattr__(name: str):
    if name in _WHERE:
        value = getattr(importlib.import_module(f"{__name__}.{_WHERE[name]}"), name)
        globals()[name] = value
        return value
    if not name.startswith("_"):  # a public submodule, as an attribute (issue 14.1)
        from importlib.util import find_spec

        if find_spec(f"{__name__}.{name}") is not None:
            return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
