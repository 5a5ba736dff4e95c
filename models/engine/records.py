"""What an event-driven run keeps: one `EventRecord` per event and the `Run` that holds them."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rigidlcp.models.event import State
from rigidlcp.models.observables import reported, reported_rate
from rigidlcp.models.system import System

#: Why a run stops (models/engine/loop.py's module doc says when).
STOP_REASONS = ("steady", "time_limit", "event_limit", "detachment", "no_solution", "zeno",
                "solver_failed")


@dataclass
class EventRecord:
    """What is recorded at each event (values right after the event's LCP is solved)."""

    t: float
    V: float
    omega: np.ndarray
    omega_dot: np.ndarray
    R: np.ndarray
    S: np.ndarray
    s: np.ndarray  # tangential states after the event: +1/-1 sliding, 0 non-sliding
    s_in: np.ndarray  # the states the event started from (0: candidates), see Run.state_at
    vt: np.ndarray
    at: np.ndarray
    mu_g: float
    dissipation: float
    iterations: int
    residual: float
    n_lcp: int
    method: str
    fallback: bool = False

    def __repr__(self) -> str:
        # rounding noise as 0, as in the run's summary (light records keep no S, v_t)
        D = reported_rate(self.R, self.S, self.vt) if self.S.size else self.dissipation
        return (f"<EventRecord t = {self.t:.6g}: mu_g = {reported(self.mu_g, 1.0):.6g}, D = "
                f"{D:.3g}, {int((self.s != 0).sum())} of {self.s.size} contacts "
                f"sliding, {self.method}{' (fallback)' if self.fallback else ''}>")


@dataclass
class Run:
    """A simulation: the system, one record per event, and why it stopped.

    sparse_info: on the sparse path, the seconds and iterations of every event and the
    pivoting's counters summed over the run (models/engine/sparse.py); None on the dense path.
    """

    system: System
    records: list[EventRecord] = field(default_factory=list)
    status: str = "running"
    message: str = ""
    contacts: list[int] = field(default_factory=list)  # contacts named by the stop report
    wall_time: float = 0.0
    method: str = "lemke"
    final: State | None = None
    sparse_info: dict | None = None
    #: the closed-solution search (models/engine/closed.py; both backends and the time-stepper,
    #: whose "followed" are steps): {"search":
    #: on/off, "followed": the events where a closed solution replaced the selected one}
    closed: dict | None = None

    @property
    def steady(self) -> bool:
        return self.status == "steady"

    @property
    def n_events(self) -> int:
        return len(self.records)

    def array(self, name: str) -> np.ndarray:
        """Stack a record field over events, e.g. run.array('mu_g') or run.array('omega')."""
        return np.array([getattr(r, name) for r in self.records])

    def state_at(self, k: int) -> State:
        """The state from which event k was solved (to re-solve it with another method)."""
        rec = self.records[k]
        return State(rec.t, rec.omega.copy(), rec.V, rec.s_in.copy())

    @property
    def last(self) -> EventRecord:
        if not self.records:
            raise ValueError("the run has no event")
        return self.records[-1]

    def summary(self) -> dict:
        """Status, the last event's observables (dissipation: models.observables.
        dissipation_summary) and whether the run stayed in the paper's regime."""
        from rigidlcp.models.observables import (
            dissipation_summary,
            regime,
            reported,
            state_counts,
        )

        out = {"status": self.status, "message": self.message, "events": self.n_events,
               "wall_time_s": round(self.wall_time, 4), "method": self.method,
               # events answered by the fallback, not by `method` (issue 23.1)
               "fallback_solves": sum(1 for r in self.records if r.fallback),
               **regime(self.status)}
        if self.closed is not None:  # the closed-solution search
            out["closed_search"] = dict(self.closed)
        if self.records:
            last = self.last
            weight = self.system.total_mass * self.system.g
            out.update(t=last.t, mu_g=reported(last.mu_g, 1.0),
                       F_g=reported(last.mu_g * weight, weight),
                       **dissipation_summary(self.records),
                       **state_counts(self.system, last))
        return out

    def __repr__(self) -> str:
        lat = self.system.lattice
        last = (f", t = {self.records[-1].t:.6g}, "
                f"mu_g = {reported(self.records[-1].mu_g, 1.0):.6g}"
                if self.records else "")
        return (f"<Run {lat.title()}: {self.status}, {self.n_events} events"
                f"{last}, method {self.method!r}>")
