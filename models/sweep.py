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
every point whose line exists: a point is identified by all its parameters and run options,
so changing an option reruns the points. When every point of the grid is done the file is
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
from rigidlcp.lcp.io.files import atomic_write_text

from .executors import default_jobs, iter_map
from .runio import _json_default
from .system import DEFAULT_MU

#: Sweepable parameters and their types (names as in `rigidlcp.cli.simulate.add_system_arguments`).
PARAMS: dict[str, type] = {
    "lattice": str, "lx": int, "ly": int, "mu_pp": float, "mu_plane": float,
    "mu_wall": float, "gamma": float, "v0": float, "inertia": float, "seed": int,
}
#: Defaults of the parameters (those of `rigidlcp simulate`).
DEFAULTS: dict[str, Any] = {
    "lattice": "rect", "lx": 10, "ly": 4, **DEFAULT_MU,
    "gamma": 0.1, "v0": 0.0, "inertia": None, "seed": 1,
}
#: Run options, fixed for a sweep and part of every point's identity.
RUN_OPTIONS: dict[str, Any] = {
    "method": "lemke", "select": "face-min-norm", "fallback": "lemke", "max_events": 20_000,
    "t_max": None, "omega_scale": 1.0,
}
RESULTS = "results.jsonl"
TIMINGS = "timings.jsonl"
SPEC = "sweep.json"
#: Result columns written for every point, in this order after the parameters.
RESULT_FIELDS = ("status", "steady", "events", "t", "m_g", "F_g", "mu_g", "dissipation_rate",
                 "dissipation_rate_slope", "paper_regime", "T", "NT", "NS_pp", "NS_plane",
                 "NS_wall", "sliding_pp", "sliding_plane", "sliding_wall", "fallbacks", "message")


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


def point_key(point: dict) -> str:
    """Identity of a point: canonical JSON of its parameters and run options."""
    sel = {k: point[k] for k in (*PARAMS, *RUN_OPTIONS)}
    return json.dumps(sel, sort_keys=True, separators=(",", ":"))


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


# -- the results file ----------------------------------------------------------------------------


class ResultsFile:
    """JSON lines, appended one whole line per write (O_APPEND) and fsync'ed."""

    def __init__(self, path: str | os.PathLike) -> None:
        self.path = Path(path)
        self.bad_lines = 0

    def read(self) -> list[dict]:
        """Every well-formed line (a torn or corrupt line is counted in `bad_lines`)."""
        self.bad_lines = 0
        if not self.path.exists():
            return []
        rows = []
        for line in self.path.read_text().splitlines():
            if not line.strip():
                continue
            try:
                row = json.loads(line)
                point_key(row)
            except (json.JSONDecodeError, KeyError, TypeError):
                self.bad_lines += 1
                continue
            rows.append(row)
        return rows

    def done(self) -> dict[str, dict]:
        """key -> row of the finished points (the first line of each key)."""
        out: dict[str, dict] = {}
        for row in self.read():
            out.setdefault(point_key(row), row)
        return out

    def append(self, row: dict) -> None:
        data = (json.dumps(row, separators=(", ", ": "), default=_json_default) + "\n").encode()
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            size = os.fstat(fd).st_size
            if size and _last_byte(self.path, size) != b"\n":
                data = b"\n" + data  # a torn line from a killed run stays on its own line
            os.write(fd, data)
            os.fsync(fd)
        finally:
            os.close(fd)

    def finalize(self, order: list[str]) -> list[dict]:
        """Rewrite in grid order (then the lines of other grids, in file order), one line per
        point, torn lines dropped; atomic (temporary file + rename). Returns the rows."""
        done = self.done()
        rank = {k: i for i, k in enumerate(order)}
        rows = sorted(done.values(), key=lambda r: rank.get(point_key(r), len(order)))
        text = "".join(json.dumps(r, separators=(", ", ": "), default=_json_default) + "\n"
                       for r in rows)
        _atomic_write_text(self.path, text)
        return rows


def _last_byte(path: Path, size: int) -> bytes:
    with open(path, "rb") as fh:
        fh.seek(size - 1)
        return fh.read(1)


def _atomic_write_text(path: Path, text: str) -> None:
    atomic_write_text(path, text)


def read_results(out: str | os.PathLike) -> list[dict]:
    """The rows of a sweep directory (or of a results file given directly)."""
    path = Path(out)
    if path.is_dir():
        path = path / RESULTS
    if not path.exists():
        raise FileNotFoundError(2, "No sweep results (results.jsonl)", str(path))
    results = ResultsFile(path)
    try:
        rows = results.read()
    except UnicodeDecodeError:
        raise InvalidFile(f"{path} is not a sweep's results.jsonl (not text)") from None
    if not rows:
        raise InvalidFile(f"{path} holds no sweep result" + (
            f" ({results.bad_lines} unreadable line(s))" if results.bad_lines else " (empty)"))
    return rows


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


def run_sweep(sweep: Sweep, out: str | os.PathLike, *, jobs: int | None = None,
              dask: str | None = None, progress: bool = True, save_runs: bool = False,
              log: Callable[[str], None] | None = None, force: bool = False) -> SweepResult:
    """Run the points of `sweep` not yet in OUT/results.jsonl, appending each as it finishes,
    then rewrite the file in grid order. A KeyboardInterrupt propagates after the finished
    points are safe on disk (rerun to resume). The grid is validated first
    (`Sweep.validate`); OUT must be new, empty or a sweep directory (else `OutputExists`,
    unless `force`)."""
    sweep.validate()  # the whole grid, before anything is written or run
    out = check_out(out, force)
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
