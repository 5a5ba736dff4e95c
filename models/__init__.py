"""Mechanics: lattices of rigid disks, contacts, the MLCP of an event, event-driven evolution.

Dependencies point lcp <- models <- verify: this package imports `lcp`, never `verify`.
"""

from .dynamics import Dynamics
from .engine import Run, simulate
from .event import (
    EventProblem,
    EventSolution,
    State,
    contact_matrix,
    event_problem,
    initial_state,
)
from .lattice import (
    LEFT_WALL,
    PLANE,
    RIGHT_WALL,
    InvalidSystem,
    Lattice,
    make_lattice,
    rectangular,
    triangular,
)
from .system import System, make_system

__all__ = [
    "Dynamics", "EventProblem", "EventSolution", "State", "contact_matrix", "event_problem",
    "initial_state", "Run", "simulate", "Lattice", "InvalidSystem", "rectangular",
    "triangular", "make_lattice", "System", "make_system", "LEFT_WALL", "RIGHT_WALL", "PLANE",
]
