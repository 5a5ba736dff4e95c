"""Parameter sweeps: one steady-state run per point of a grid, resumable, local or on Dask.

A sweep is the Cartesian product of value lists for the system's parameters (`PARAMS`: lattice,
lx, ly, the three friction coefficients, gamma, V0, inertia, seed) with fixed run options
(`RUN_OPTIONS`). Each point is one `models.simulate` run to its steady state (Sec. IV); its
summary -- steady-state F_g and mu_g (Eq. 2.1-2.2), dissipation rate (and its slope),
contact-state counts, number of events, stop status, whether it stayed in the paper's regime --
is one line of `OUT/results.jsonl`.

Durability: a line is written by a single `write` on a file opened with O_APPEND and fsync'ed
as soon as its point finishes, by the one process that owns the file (the workers only compute).
A killed sweep (Ctrl-C, kill -9) therefore loses at most the points that were running; a torn
last line (a kill inside the write) is ignored on reading. Rerunning the same command skips
every point whose line exists: a point is identified by all its parameters and run options.
OUT holding another grid or other options (its sweep.json) is refused unless forced, which
then adds the new points to the same results.jsonl. When every point of the grid is done the file is
rewritten (atomically: temporary file + rename) in grid order, so the finished file does not
depend on the executor, on the order in which points completed, nor on interruptions. Wall
times vary from run to run and go to `OUT/timings.jsonl` instead.

Executors (`models.executors.iter_map`): in-process (jobs = 1), a local process pool (the
default), or Dask (`dask="tcp://HOST:PORT"` for an existing scheduler, `dask="local"` for a
LocalCluster on the loopback interface; `pip install rigidlcp[dask]`). A point's result is a
deterministic function of the point, so every executor returns the same results.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
import sys
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rigidlcp.lcp.errors import InvalidFile, InvalidInput, OutputExists

from .executors import default_jobs, iter_map
from .results_file import (
    PARAMS,
    RESULT_FIELDS,
    RESULTS,
    RUN_OPTIONS,
    ResultsFile,
    _atomic_write_text,
    point_key,
    read_results,
)
from .system import DEFAULT_MU

#: Defaults of the parameters (those of `rigidlcp simulate`).
DEFAULTS: dict[str, Any] = {
    "lattice": "rect", "lx": 10, "ly": 4, **DEFAULT_MU,
    "gamma": 0.1, "v0": 0.0, "inertia": None, "seed": 1,
}
TIMINGS = "timings.jsonl"
SPEC = "sweep.json"


def _round(v: float) -> float:
    """Grid values rounded to 12 significant digits (0.30000000000000004 -> 0.3)."""
    return float(f"{v:.12g}")


def parse_grid(name: str, text: str | float | int | None) -> list:
    """Values of parameter `name` from a grid string.

    "START:STOP:NUM" -> NUM evenly spaced values from START to STOP inclusive (numpy.linspace);
    "A,B,C" -> a list; "A" -> one value. lattice takes names ("rect,tri"); inertia also takes
    "default" (m r^2 / 2); integer parameters need integral values.
    """
    if name not in PARAMS:
        raise ValueError(f"unknown sweep parameter {name!r}; choose from {', '.join(PARAMS)}")
    if text is None or not isinstance(text, str):
        return [text]
    kind = PARAMS[name]
    text = text.strip()
    if not text:
        raise ValueError(f"--{name.replace('_', '-')}: empty value")
    if kind is str:
        return [v.strip() for v in text.split(",") if v.strip()]
    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise ValueError(f"--{name.replace('_', '-')}: a range is START:STOP:NUM, "
                             f"got {text!r}")
        start, stop = (_number(name, p) for p in parts[:2])
        num = _number(name, parts[2])
        if num != int(num) or num < 1:
            raise ValueError(f"--{name.replace('_', '-')}: NUM must be an integer >= 1, "
                             f"got {parts[2]!r}")
        num = int(num)
        values = [start] if num == 1 else [
            start + (stop - start) * k / (num - 1) for k in range(num)]
    else:
        values = [_number(name, p) if p.strip().lower() not in ("default", "none") else None
                  for p in text.split(",")]
    out = []
    for v in values:
        if v is None:
            if name != "inertia":
                raise ValueError(f"--{name.replace('_', '-')}: 'default' only for inertia")
            out.append(None)
        elif kind is int:
            if abs(v - round(v)) > 1e-9:
                raise ValueError(f"--{name.replace('_', '-')} takes integers, got {v:g}")
            out.append(int(round(v)))
        else:
            out.append(_round(v))
    return out


def _number(name: str, text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise ValueError(f"--{name.replace('_', '-')}: not a number: {text!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"--{name.replace('_', '-')}: must be finite, got {text!r}")
    return v


@dataclass
class Sweep:
    """A grid of points: `axes` (parameter -> values, in product order), the other parameters
    from `fixed` (default `DEFAULTS`), and the run options."""

    axes: dict[str, list] = field(default_factory=dict)
    fixed: dict[str, Any] = field(default_factory=dict)
    options: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in list(self.axes) + list(self.fixed):
            if name not in PARAMS:
                raise ValueError(f"unknown sweep parameter {name!r}")
        for name in self.options:
            if name not in RUN_OPTIONS:
                raise ValueError(f"unknown run option {name!r}; choose from "
                                 f"{', '.join(RUN_OPTIONS)}")
        for name, values in self.axes.items():
            if not values:
                raise ValueError(f"sweep axis {name!r} has no value")

    def validate(self) -> None:
        """Check every point of the grid before any runs (raises ValueError / InvalidSystem
        naming the first bad value): each distinct system is built, each run option checked."""
        from rigidlcp import lcp
        from rigidlcp.models.engine.dense import SELECT

        from .system import make_system

        opts = {**RUN_OPTIONS, **self.options}
        for name in (opts["method"], opts["fallback"]):
            if name is not None and name != "sparse-pivoting":
                lcp.get_method(name)
        if opts["select"] not in SELECT:
            raise ValueError(f"select must be one of {', '.join(SELECT)}, got {opts['select']!r}")
        if not (isinstance(opts["max_events"], int) and opts["max_events"] >= 1):
            raise ValueError(f"max_events must be an integer >= 1, got {opts['max_events']!r}")
        if opts["t_max"] is not None and not float(opts["t_max"]) > 0:
            raise ValueError(f"t_max must be > 0, got {opts['t_max']!r}")
        if not (math.isfinite(opts["omega_scale"]) and opts["omega_scale"] >= 0):
            raise ValueError(f"omega_scale must be a finite number >= 0, "
                             f"got {opts['omega_scale']!r}")
        seen = set()
        for point in self.points():
            seed = point["seed"]
            if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
                raise ValueError(f"seed must be an integer >= 0, got {seed!r}")
            sysp = tuple(point[k] for k in PARAMS if k != "seed")
            if sysp in seen:
                continue
            seen.add(sysp)
            where = ", ".join(f"{k}={point[k]}" for k in self.axes) or "the fixed parameters"
            try:
                make_system(point["lattice"], point["lx"], point["ly"], mu_pp=point["mu_pp"],
                            mu_plane=point["mu_plane"], mu_wall=point["mu_wall"],
                            gamma=point["gamma"], V0=point["v0"], inertia=point["inertia"])
            except ValueError as exc:
                raise type(exc)(f"sweep point ({where}): {exc}") from None

    def points(self) -> list[dict]:
        """Every point: all of PARAMS then all of RUN_OPTIONS (a JSON-friendly dict)."""
        base = {**DEFAULTS, **self.fixed}
        opts = {**RUN_OPTIONS, **self.options}
        names = list(self.axes)
        out = []
        for combo in itertools.product(*(self.axes[n] for n in names)):
            point = {name: base[name] for name in PARAMS}
            point.update(zip(names, combo))
            point.update(opts)
            out.append(point)
        return out

    def to_dict(self) -> dict:
        return {"axes": self.axes, "fixed": {**DEFAULTS, **self.fixed},
                "options": {**RUN_OPTIONS, **self.options}}


def point_digest(point: dict) -> str:
    return hashlib.sha1(point_key(point).encode()).hexdigest()[:16]


def run_point(point: dict, runs_dir: str | None = None) -> dict:
    """Run one point to its steady state; returns the point, its result columns and
    `wall_time_s`. Errors in the point's own data (an impossible lattice, a bad option) become
    status "error" with the message: they are results, deterministic like the others."""
    import time

    from rigidlcp.models.engine import simulate

    from .event import initial_state
    from .observables import state_counts
    from .system import make_system

    start = time.perf_counter()
    row = {k: point[k] for k in (*PARAMS, *RUN_OPTIONS)}
    try:
        system = make_system(point["lattice"], point["lx"], point["ly"], mu_pp=point["mu_pp"],
                             mu_plane=point["mu_plane"], mu_wall=point["mu_wall"],
                             gamma=point["gamma"], V0=point["v0"], inertia=point["inertia"])
        state = initial_state(system, seed=point["seed"], omega_scale=point["omega_scale"])
        t_max = math.inf if point["t_max"] is None else float(point["t_max"])
        run = simulate(system, state, method=point["method"], select=point["select"],
                       fallback=point["fallback"], max_events=int(point["max_events"]),
                       t_max=t_max)
    except ValueError as exc:  # InvalidSystem, lcp.InvalidProblem: bad data, not a crash
        row.update({f: None for f in RESULT_FIELDS}, status="error", steady=False, events=0,
                   message=str(exc))
        row["wall_time_s"] = time.perf_counter() - start
        return row
    m_g = system.total_mass
    res: dict[str, Any] = {"status": run.status, "steady": run.steady, "events": run.n_events,
                           "m_g": m_g, "message": run.message,
                           "fallbacks": int(sum(r.fallback for r in run.records))}
    summary = run.summary()
    res["paper_regime"] = summary["paper_regime"]
    if run.records:
        last = run.last
        res.update(t=last.t, mu_g=summary["mu_g"], F_g=summary["F_g"],
                   dissipation_rate=summary["dissipation_rate"],
                   dissipation_rate_slope=summary["dissipation_rate_slope"],
                   **state_counts(system, last))
    row.update({f: res.get(f) for f in RESULT_FIELDS})
    if runs_dir is not None:
        from .runio import save_run

        name = point_digest(point)
        save_run(run, Path(runs_dir) / name)
        row["run_file"] = f"runs/{name}.npz"
    row["wall_time_s"] = time.perf_counter() - start
    return row


# -- the sweep -----------------------------------------------------------------------------------


@dataclass
class SweepResult:
    """Rows in grid order, how many points ran now and how many were found done."""

    rows: list[dict]
    ran: int
    skipped: int
    out: Path
    bad_lines: int = 0

    @property
    def complete(self) -> bool:
        return all(r.get("status") is not None for r in self.rows)


def check_out(out: str | os.PathLike, force: bool = False) -> Path:
    """OUT of a sweep: new, empty, or a sweep directory (resumed); otherwise `OutputExists`
    (unless `force`), or `InvalidInput` for a file."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InvalidInput(f"{out} is a file, not a sweep directory")
    if not force and out.is_dir() and any(out.iterdir()) and not (out / SPEC).exists():
        raise OutputExists(f"{out} is not empty and not a sweep directory (no {SPEC}); "
                           "pass --force (force=True) to write into it")
    return out


def _check_same_sweep(out: Path, sweep: Sweep) -> None:
    """Refuse (`OutputExists`) to resume into OUT when its sweep.json holds another grid or
    other options: the new points would be merged silently into the other sweep's
    results.jsonl. `InvalidFile` for an unreadable sweep.json."""
    spec = out / SPEC
    if not spec.exists():
        return
    try:
        old = json.loads(spec.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InvalidFile(f"{spec} is not a sweep's {SPEC} ({exc})") from None
    new = json.loads(json.dumps(sweep.to_dict()))
    if old == new:
        return
    if not isinstance(old, dict):
        raise InvalidFile(f"{spec} is not a sweep's {SPEC} (not a JSON object)")
    diff = []
    for part in ("axes", "fixed", "options"):
        a, b = old.get(part) or {}, new.get(part) or {}
        diff += [f"{k}: {a.get(k)!r} there, {b.get(k)!r} here"
                 for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k)]
    raise OutputExists(f"{out} holds another sweep ({'; '.join(diff[:3])}); use another --out, "
                       "or pass --force (force=True) to add these points to it")


def run_sweep(sweep: Sweep, out: str | os.PathLike, *, jobs: int | None = None,
              dask: str | None = None, progress: bool = True, save_runs: bool = False,
              log: Callable[[str], None] | None = None, force: bool = False) -> SweepResult:
    """Run the points of `sweep` not yet in OUT/results.jsonl, appending each as it finishes,
    then rewrite the file in grid order. A KeyboardInterrupt propagates after the finished
    points are safe on disk (rerun to resume). The grid is validated first
    (`Sweep.validate`); OUT must be new, empty or a sweep directory (else `OutputExists`,
    unless `force`)."""
    sweep.validate()  # the whole grid, before anything is written or run
    if jobs is not None and (isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1):
        raise ValueError(f"jobs must be an integer >= 1, got {jobs!r}")
    out = check_out(out, force)
    if not force:
        _check_same_sweep(out, sweep)
    out.mkdir(parents=True, exist_ok=True)
    log = log or (lambda msg: print(msg, file=sys.stderr))
    _atomic_write_text(out / SPEC, json.dumps(sweep.to_dict(), indent=1) + "\n")
    results = ResultsFile(out / RESULTS)
    points = sweep.points()
    keys = [point_key(p) for p in points]
    if len(set(keys)) != len(keys):
        raise ValueError("the sweep grid repeats a point (a value listed twice?)")
    done = results.done()
    if results.bad_lines:
        log(f"{results.path}: ignoring {results.bad_lines} torn or corrupt line(s)")
    todo = [k for k, key in enumerate(keys) if key not in done]
    skipped = len(points) - len(todo)
    if skipped:
        log(f"resuming: {skipped} of {len(points)} points already in {results.path}, "
            f"{len(todo)} to run")
    bar = None
    if progress:
        from .progress import new_bar as tqdm  # erased at the end: no stale bar on screen

        bar = tqdm(total=len(points), initial=skipped, unit="pt", desc="sweep",
                   file=sys.stderr, dynamic_ncols=True)
    timings = ResultsFile(out / TIMINGS)
    runs_dir = str(out / "runs") if save_runs else None
    task = _Task(runs_dir)
    ran = 0
    try:
        for _, row in iter_map(task, [points[k] for k in todo], jobs=jobs, dask=dask):
            wall = row.pop("wall_time_s", None)
            results.append(row)
            timings.append({"key": point_digest(row), "wall_time_s": wall})
            ran += 1
            if bar is not None:
                bar.update(1)
                bar.set_postfix(last=f"{row['status']}", refresh=False)
    finally:
        if bar is not None:
            bar.close()
    rows = results.finalize(keys)
    rank = {point_key(r): r for r in rows}
    return SweepResult([rank[key] for key in keys], ran, skipped, out, results.bad_lines)


class _Task:
    """Picklable callable for the executors: run_point with the runs directory bound."""

    def __init__(self, runs_dir: str | None) -> None:
        self.runs_dir = runs_dir

    def __call__(self, point: dict) -> dict:
        return run_point(point, self.runs_dir)


def varying(rows: Iterable[dict]) -> list[str]:
    """Parameters that take more than one value among `rows` (for tables and grouping)."""
    rows = list(rows)
    return [p for p in PARAMS if len({json.dumps(r.get(p)) for r in rows}) > 1]


__all__ = ["PARAMS", "DEFAULTS", "RUN_OPTIONS", "RESULT_FIELDS", "parse_grid", "Sweep",
           "point_key", "run_point", "ResultsFile", "read_results", "iter_map", "run_sweep",
           "SweepResult", "varying", "default_jobs"]
