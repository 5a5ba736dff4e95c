"""Certify a whole run: the uniqueness verdicts of every event (verify.certificates.stages).

`certify_run(run, out)` rebuilds the LCP of each event from the run (`Run.state_at(k)`: the
state the event was solved from) and its recorded solution (the forces [R; S], converted to the
LCP's z by verify.polyhedra.event_z), certifies it with `certify_stages` and writes one JSON line
per event to OUT/certificates.jsonl as soon as it is done (appended in one write, fsync'ed, as
`rigidlcp sweep` does), so that an interrupted certification resumes where it stopped
(`resume=True`). Events run in parallel on models.executors.iter_map. At the end the lines are
rewritten in event order, OUT/summary.json gets the totals and OUT/determinacy.png shows, over
time, which events have unique accelerations, forces and contact states.

An existing OUT is never overwritten: `resume=True` continues it (the options must match),
`force=True` starts afresh (only this module's files are removed).
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rigidlcp.lcp.errors import InvalidInput, OutputExists
from rigidlcp.models.engine.records import Run
from rigidlcp.models.event import event_problem
from rigidlcp.models.observables import global_friction
from rigidlcp.models.runio import load_run
from rigidlcp.models.sweep import ResultsFile, _atomic_write_text

from ..forces.polyhedra import event_z
from ..steadiness import KINEMATICS, steadiness
from .clocked import check_clock
from .stages import OTHER, UNIQUE, UNKNOWN, certify_stages

LINES, SUMMARY, FIGURE, OPTIONS = ("certificates.jsonl", "summary.json", "determinacy.png",
                                   "options.json")
QUESTIONS = ("accelerations", "forces", "states")


@dataclass
class RunCertificate:
    """One row per certified event (event order), the totals, the output directory."""

    rows: list[dict]
    totals: dict
    out: Path | None = None
    ran: int = 0
    skipped: int = 0
    notes: list[str] = field(default_factory=list)


def certify_event(run: Run, k: int, *, time_limit: float = 10.0, tries: int = 8,
                  ranges: bool = False, clock: str = "cpu") -> dict:
    """The JSON row of event k: verdicts, stages, times, the full staged certificate and every
    witness (`witness_row`). steady_event: k is the last event of a run that ended steady.
    clock: how time_limit is counted ("cpu" seconds of this process, or "wall"; as
    certify_stages); the row's seconds are wall seconds."""
    t0 = time.perf_counter()
    rec = run.records[k]
    state = run.state_at(k)
    ep = event_problem(run.system, state)
    z = event_z(ep, np.r_[rec.R, rec.S])
    cert = certify_stages(ep, z, time_limit=time_limit, tries=tries, ranges=ranges,
                          clock=clock)
    row: dict = {"event": k, "t": float(rec.t), "n": int(ep.lcp.n), "k": int(ep.k),
                 "accepted": cert.accepted, "scaled_residual": cert.scaled_residual}
    for name in QUESTIONS:
        v = cert.verdicts[name]
        row[name] = v.verdict
        row[name + "_stage"] = v.stage
        row[name + "_seconds"] = round(v.seconds, 4)
    steady_event = bool(run.status == "steady" and k == run.n_events - 1)
    row["steady_event"] = steady_event
    row["witnesses"] = []
    for name in QUESTIONS:
        w = cert.verdicts[name].witness
        if w is None:
            continue
        same = [x for x in row["witnesses"] if np.array_equal(x["z"], w.z)]
        if same:
            same[0]["questions"].append(name)
            continue
        row["witnesses"].append({"questions": [name],
                                 **witness_row(ep, state, z, w.z, w.residual, w.found_by,
                                               steady_event)})
    row["seconds"] = round(time.perf_counter() - t0, 4)
    row["certificate"] = cert.to_dict()
    return row


def witness_row(ep, state, z: np.ndarray, y: np.ndarray, residual: float, found_by: str,
                steady_event: bool) -> dict:
    """A witness y (another solution of the event LCP) beside the run's z: y itself, its
    independent scaled residual, how the observables differ (max |d| of the angular
    accelerations, R, S; d mu_g = mu_g(y) - mu_g(z)) and, at a steady event, whether y is
    itself a steady state (`steady_state`; None elsewhere)."""
    system = ep.system
    a, b = ep.unpack(z), ep.unpack(y)
    weight = system.total_mass * system.g or 1.0
    d_mu_g = (global_friction(system, b.S) - global_friction(system, a.S)) / weight
    ok, why = steady_state(ep, state, b) if steady_event else (None, "not a steady event")
    return {"z": y.tolist(), "residual": float(residual), "found_by": found_by,
            "d_omega_dot": float(np.max(np.abs(b.omega_dot - a.omega_dot), initial=0.0)),
            "d_R": float(np.max(np.abs(b.R - a.R), initial=0.0)),
            "d_S": float(np.max(np.abs(b.S - a.S), initial=0.0)),
            "d_mu_g": float(d_mu_g), "steady": ok, "steady_reason": why}


def steady_state(ep, state, es, rtol: float = 1e-8) -> tuple[bool, str]:
    """Is the event solution `es` at `state` a steady state? The definition of
    verify.steadiness (docs/mechanics.md), its kinematic conditions (the event's laws are
    certified apart): every contact closed with a_n = 0; a non-sliding frictional contact keeps
    a_t = 0; a sliding contact never decelerates, sgn(v_t) a_t >= 0. The states are those after
    the event (es.s): sliding where v_t != 0 at the event (state.s) or starting to slide there
    (v_t = 0, a_t != 0, which the event's laws allow only at |S| = mu R). Zero tests: rtol of
    max(g, |gamma|, max|a|) for accelerations, of max R for forces."""
    system = ep.system
    a_scale = max(system.g, abs(system.gamma), float(np.max(np.abs(es.a_n), initial=0.0)),
                  float(np.max(np.abs(es.a_t), initial=0.0)))
    st = steadiness(system, es.R, es.S, es.s, es.a_n, es.a_t, a_scale=a_scale,
                    f_scale=max(float(np.max(es.R, initial=0.0)), 1e-300))
    return st.steady(rtol, KINEMATICS), st.reason(rtol, KINEMATICS)


class _EventTask:
    """Picklable: certify event k of `run` (for models.executors.iter_map)."""

    def __init__(self, run: Run, options: dict) -> None:
        self.run, self.options = run, options

    def __call__(self, k: int) -> dict:
        return strict_json(certify_event(self.run, k, **self.options))


def certify_run(run: Run | str | os.PathLike, out: str | os.PathLike | None = None, *,
                time_limit: float = 10.0, tries: int = 8, ranges: bool = False,
                events: list[int] | None = None, jobs: int | None = 1, resume: bool = False,
                force: bool = False, progress: bool = False, figure: bool = True,
                clock: str = "cpu") -> RunCertificate:
    """Certify every event of `run` (a Run or a saved run's path); see the module docstring.

    out: directory for the JSON lines, totals and figure (None: nothing written, no resume).
    time_limit: seconds per MILP (stage c2, per question); tries: other-solver attempts;
    ranges: the range LPs of each observable over the face (slower); events: which events
    (default all); jobs: worker processes (models.executors.iter_map); clock: how time_limit
    is counted, "cpu" (each worker's CPU seconds: the verdicts do not depend on the load) or
    "wall" (a folder certified on another clock is not resumed: other options).
    """
    from rigidlcp.models.executors import iter_map

    if not isinstance(run, Run):
        run = load_run(run)
    if run.method.startswith("moreau-jean"):  # its records are steps: not event solutions
        raise InvalidInput(f"a time-stepping run ({run.method}): its records are steps, "
                           "whose impulses are not solutions of an event problem; "
                           "certify-run certifies the events of `rigidlcp simulate` (`rigidlcp "
                           "compare-integrators` checks a time-stepper's state in the event "
                           "laws)")
    check_clock(clock)
    options = {"time_limit": float(time_limit), "tries": int(tries), "ranges": bool(ranges),
               "clock": clock}
    todo_all = list(range(run.n_events)) if events is None else sorted(set(int(k) for k in
                                                                         events))
    if events is not None and not todo_all:
        raise InvalidInput("events selects no event")
    bad = [k for k in todo_all if not 0 <= k < run.n_events]
    if bad:
        raise InvalidInput(f"events {bad[:5]} out of range (the run has {run.n_events} events)")
    done: dict[int, dict] = {}
    lines = None
    notes: list[str] = []
    if out is not None:
        out = Path(out)
        lines = ResultsFile(out / LINES)
        done = _prepare(out, options, resume, force, notes)
    todo = [k for k in todo_all if k not in done]
    task = _EventTask(run, options)
    bar = None
    if progress:
        from rigidlcp.models.progress import new_bar  # erased at the end: no stale bar

        bar = new_bar(total=len(todo_all), initial=len(todo_all) - len(todo), unit="event",
                      desc="certify")
    new: dict[int, dict] = {}
    try:
        for _, row in iter_map(task, todo, jobs=jobs):
            new[row["event"]] = row
            if lines is not None:
                lines.append(row)
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    rows = [done.get(k) or new[k] for k in todo_all]
    totals = summarize(rows)
    if out is not None:
        every = {**done, **new}
        text = "".join(json.dumps(strict_json(every[k]), separators=(", ", ": "),
                                  default=_plain, allow_nan=False) + "\n" for k in sorted(every))
        _atomic_write_text(out / LINES, text)
        _atomic_write_text(out / SUMMARY, json.dumps(totals, indent=1) + "\n")
        if figure:
            plot_determinacy([every[k] for k in sorted(every)], out / FIGURE)
    return RunCertificate(rows, totals, out, len(todo), len(todo_all) - len(todo), notes)


def _prepare(out: Path, options: dict, resume: bool, force: bool, notes: list[str]
             ) -> dict[int, dict]:
    """Check / create OUT; return the rows already done (resume)."""
    ours = [out / name for name in (LINES, SUMMARY, FIGURE, OPTIONS)]
    exists = out.exists() and any(out.iterdir()) if out.is_dir() else out.exists()
    if out.exists() and not out.is_dir():
        raise InvalidInput(f"{out} exists and is not a directory")
    if exists and not (resume or force):
        raise OutputExists(f"{out} exists: pass --resume to continue it or --force to start "
                         "afresh")
    if exists and force:
        for path in ours:
            path.unlink(missing_ok=True)
    out.mkdir(parents=True, exist_ok=True)
    done: dict[int, dict] = {}
    saved = out / OPTIONS
    if resume and saved.exists():
        previous = json.loads(saved.read_text())
        if isinstance(previous, dict):  # written before the clock was an option: wall
            previous.setdefault("clock", "wall")
        if previous != options:
            raise InvalidInput(f"{out} was certified with other options {previous}; pass "
                             "--force to start afresh")
        lines = ResultsFile(out / LINES)
        for line in (lines.path.read_text().splitlines() if lines.path.exists() else []):
            try:
                row = json.loads(line)
                done.setdefault(int(row["event"]), row)
            except (json.JSONDecodeError, KeyError, TypeError, ValueError):
                notes.append("ignored a torn or corrupt line")
    _atomic_write_text(saved, json.dumps(options) + "\n")
    return done


def strict_json(obj):
    """obj with every non-finite float (NaN, +-inf) replaced by None, numpy scalars and arrays
    by plain Python: what json.dumps(..., allow_nan=False) accepts (strict JSON has no NaN)."""
    if isinstance(obj, dict):
        return {k: strict_json(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [strict_json(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return strict_json(obj.tolist())
    if isinstance(obj, (np.integer, np.bool_)):
        return obj.item()
    if isinstance(obj, (float, np.floating)):
        return float(obj) if np.isfinite(obj) else None
    return obj


def _plain(obj):
    if isinstance(obj, (np.integer, np.floating, np.bool_)):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"not JSON serializable: {type(obj).__name__}")


def summarize(rows: list[dict]) -> dict:
    """Counts of each verdict per question, by stage; median and max seconds per event."""
    secs = np.array([r["seconds"] for r in rows]) if rows else np.zeros(0)
    out: dict = {"events": len(rows), "rejected": sum(not r["accepted"] for r in rows),
                 "median_seconds": float(np.median(secs)) if secs.size else 0.0,
                 "max_seconds": float(np.max(secs, initial=0.0)),
                 "over_30s": int(np.sum(secs > 30.0))}
    for q in QUESTIONS:
        counts = {v: sum(r[q] == v for r in rows) for v in (UNIQUE, OTHER, UNKNOWN)}
        stages: dict[str, int] = {}
        for r in rows:
            stages[r[q + "_stage"]] = stages.get(r[q + "_stage"], 0) + 1
        out[q] = {**counts, "stages": stages}
    return out


def format_totals(totals: dict) -> str:
    """The totals as a small table (the CLI prints it)."""
    lines = [f"events: {totals['events']} (rejected solutions: {totals['rejected']}); "
             f"seconds per event: median {totals['median_seconds']:.3f}, max "
             f"{totals['max_seconds']:.3f}, over 30 s: {totals['over_30s']}",
             f"{'question':<14}{'unique':>8}{'other':>8}{'unknown':>9}  decided by"]
    for q in QUESTIONS:
        c = totals[q]
        stages = ", ".join(f"{s} {n}" for s, n in sorted(c["stages"].items()))
        lines.append(f"{q:<14}{c[UNIQUE]:>8}{c[OTHER]:>8}{c[UNKNOWN]:>9}  {stages}")
    return "\n".join(lines)


def plot_determinacy(rows: list[dict], path: Path) -> None:
    """Markers over time, one line per question: green unique, red another solution exists,
    grey unknown."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colors = {UNIQUE: "tab:green", OTHER: "tab:red", UNKNOWN: "0.6"}
    fig, ax = plt.subplots(figsize=(8, 2.4))
    t = np.array([r["t"] for r in rows])
    for y, q in enumerate(QUESTIONS):
        for verdict, color in colors.items():
            sel = np.array([r[q] == verdict for r in rows], dtype=bool)
            if sel.any():
                ax.scatter(t[sel], np.full(sel.sum(), y), c=color, s=14, marker="|" if
                           verdict == UNKNOWN else "o", label=verdict if y == 0 else None)
    ax.set_yticks(range(len(QUESTIONS)), QUESTIONS)
    ax.set_ylim(-0.6, len(QUESTIONS) - 0.4)
    ax.set_xlabel("t (events)")
    ax.set_title("determinacy at each event (green: unique, red: another solution exists)",
                 fontsize=9)
    handles, labels = [], []
    for verdict, color in colors.items():
        handles.append(plt.Line2D([], [], color=color, marker="o", ls=""))
        labels.append(verdict)
    ax.legend(handles, labels, fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.savefig(path, dpi=130, bbox_inches="tight")
    plt.close(fig)
