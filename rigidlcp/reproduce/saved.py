"""The finished jobs of `rigidlcp reproduce`, saved in OUT/cells/ as each one finishes, so that
an interrupted run loses nothing and `rigidlcp reproduce --out OUT --resume` runs only the rest.

* OUT/reproduce.json (`MARKER`) makes OUT a reproduce folder: it records the options that the
  results depend on (`--quick`), the plan they give (`experiments.plan`: sizes, seeds, grids)
  and the code that ran. A resume whose options or plan differ is refused (its saved results
  would not be this run's), as is a folder without the record.
* OUT/cells/ holds one file per finished job (a cell): a pickle of {"key": job_key(job),
  "sha256": ..., "result": the pickle of what the job returned}, written to a temporary name
  and renamed (`lcp.io.files.atomic_write`), so a cell on disk is whole. A cell that cannot be
  read, whose result does not match its checksum, or whose key is not its name's, is refused
  naming the file (delete it to compute that job again): it was not written whole by this
  module, so nothing in it is trusted. Pickles run code when loaded: resume only folders that
  rigidlcp reproduce wrote.

The results of a resumed run are those of an uninterrupted one: the jobs are deterministic
(the executor and --jobs do not change them, and are not recorded), and `experiments.run_all`
collects them in job order, whatever order they finished in.
"""

from __future__ import annotations

import hashlib
import json
import os
import pickle
import re
from collections.abc import Callable
from pathlib import Path

from rigidlcp.lcp.errors import InvalidFile, InvalidInput, OutputExists
from rigidlcp.lcp.io.files import atomic_write, atomic_write_text, output_dir
from rigidlcp.models.executors import iter_map
from rigidlcp.models.results_file import point_key

MARKER = "reproduce.json"
CELLS = "cells"
FORMAT = 1
#: "Not saved": a job's result may be None.
MISSING = object()


def job_key(job: tuple) -> tuple:
    """What identifies a job of `experiments.jobs_of` / `check_jobs` within one plan: the job
    itself (its parameters are the plan's), a sweep point by `point_key`, a cross-check by its
    kind and label (its input is the saved run of that label)."""
    kind = job[0]
    if kind == "point":
        return ("point", job[1], point_key(job[2]))
    if kind in ("sim", "band", "formulas"):
        return tuple(job)
    return tuple(job[:2])


def cell_name(key: tuple) -> str:
    """File name of a job's cell: readable kind and experiment, then a digest of the key."""
    digest = hashlib.sha1(repr(key).encode()).hexdigest()[:12]
    readable = re.sub(r"[^A-Za-z0-9_.=-]+", "_", "-".join(str(x) for x in key[:2]))
    return f"{readable}-{digest}.pkl"


def read_cell(path: Path) -> tuple[tuple, object]:
    """(key, result) of a cell written by `Cells.save`; ValueError (or the unpickler's error)
    when the file is not one: its result's checksum, or its key against its name."""
    with open(path, "rb") as fh:
        cell = pickle.load(fh)
    if not isinstance(cell, dict) or set(cell) != {"key", "sha256", "result"}:
        raise ValueError("not a cell")
    key, payload = cell["key"], cell["result"]
    if not isinstance(payload, bytes) or hashlib.sha256(payload).hexdigest() != cell["sha256"]:
        raise ValueError("its result does not match its checksum")
    if not isinstance(key, tuple) or cell_name(key) != path.name:
        raise ValueError(f"it holds the job {key!r}, not the job of its name")
    return key, pickle.loads(payload)


def record_of(options: dict, plan: dict, code: str) -> dict:
    """The contents of OUT/reproduce.json (plan as JSON: tuples become lists)."""
    return {"format": FORMAT, "written by": "rigidlcp reproduce", "options": options,
            "plan": json.loads(json.dumps(plan)), "code": code}


class Cells:
    """The saved jobs of one reproduce folder: `saved` {key: result} (read when resuming),
    `save(job, result)` as each job finishes, `kept` the jobs taken from `saved`."""

    def __init__(self, out: Path, code: str = "") -> None:
        self.dir = Path(out) / CELLS
        self.saved: dict[tuple, object] = {}
        self.kept = 0
        #: the code that computed the saved cells, when it is not this run's
        self.other_code = code

    def path(self, job: tuple) -> Path:
        return self.dir / cell_name(job_key(job))

    def load(self) -> None:
        """Read every cell of the folder; `InvalidFile` naming the first that is not whole."""
        if not self.dir.is_dir():
            return
        for path in sorted(self.dir.glob("*.pkl")):
            try:
                key, result = read_cell(path)
            except Exception as exc:  # noqa: BLE001 - any failure: the file is not a cell
                raise InvalidFile(f"--resume: {path} is not a saved job of rigidlcp reproduce "
                                  f"({type(exc).__name__}: {exc}); delete it to compute that "
                                  "job again") from None
            self.saved[key] = result

    def get(self, job: tuple):
        """The saved result of `job`, or MISSING."""
        out = self.saved.get(job_key(job), MISSING)
        if out is not MISSING:
            self.kept += 1
        return out

    def save(self, job: tuple, result) -> None:
        """Write the cell of `job` (temporary name, fsync, rename)."""
        key = job_key(job)
        payload = pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL)
        cell = pickle.dumps({"key": key, "sha256": hashlib.sha256(payload).hexdigest(),
                             "result": payload}, protocol=pickle.HIGHEST_PROTOCOL)

        def write(tmp: str) -> None:
            with open(tmp, "wb") as fh:
                fh.write(cell)
                fh.flush()
                os.fsync(fh.fileno())

        atomic_write(self.dir / cell_name(key), write)

    def count(self) -> int:
        return len(list(self.dir.glob("*.pkl"))) if self.dir.is_dir() else 0

    def clear(self) -> None:
        """Remove the cells of an earlier run (--force: a fresh run keeps none of them)."""
        for path in self.dir.glob("*.pkl") if self.dir.is_dir() else ():
            path.unlink()


def open_out(out: str | os.PathLike, options: dict, plan: dict, code: str, *, force: bool,
             resume: bool) -> Cells:
    """Check OUT and return its `Cells`. Without `resume`, OUT must be new or empty (else
    `OutputExists`, unless `force`, which also drops an earlier reproduce run's cells); with it,
    OUT must be a reproduce folder whose record has the same options and plan (else a
    ValueError naming the option), and its cells are read (`Cells.load`)."""
    out = Path(out)
    path = out / MARKER
    record = record_of(options, plan, code)
    if not resume:
        try:
            output_dir(out, force=force)
        except OutputExists:
            if path.is_file():
                raise OutputExists(f"{out} holds an earlier rigidlcp reproduce run: --resume "
                                   "finishes it (same options), --force starts it afresh"
                                   ) from None
            raise OutputExists(f"{out} is not empty; pass --force to write into it (files of "
                               "the same name are overwritten), or --resume to finish an "
                               "interrupted rigidlcp reproduce run there") from None
        cells = Cells(out)
        if path.is_file():  # --force over an earlier reproduce run: none of its jobs kept
            cells.clear()  # (in any other folder, OUT/cells/*.pkl would be the user's files)
        atomic_write_text(path, json.dumps(record, indent=1) + "\n")
        return cells
    if out.exists() and not out.is_dir():
        raise InvalidInput(f"--resume: {out} is a file, not a reproduce folder")
    if not path.is_file():
        raise InvalidInput(f"--resume: {out} is not a rigidlcp reproduce folder (no {MARKER})")
    try:
        before = json.loads(path.read_text(encoding="utf-8"))
        if not isinstance(before, dict) or before.get("format") != FORMAT:
            raise ValueError(f"not format {FORMAT}")
        saved_options, saved_plan = before["options"], before["plan"]
    except (OSError, UnicodeDecodeError, ValueError, KeyError) as exc:
        raise InvalidFile(f"--resume: {path} is not a rigidlcp reproduce record ({exc})"
                          ) from None
    differ = [f"{k} {_word(saved_options.get(k))} there, {_word(v)} here"
              for k, v in options.items() if saved_options.get(k) != v]
    if differ:
        raise ValueError(f"--resume: {out} was run with other options ({'; '.join(differ)}): "
                         "its saved jobs would not be this run's; give the same options, or a "
                         "new --out")
    if saved_plan != record["plan"]:
        names = [n for n in sorted(set(saved_plan) | set(record["plan"]))
                 if saved_plan.get(n) != record["plan"].get(n)]
        raise ValueError(f"--resume: {out} was planned with other experiments "
                         f"({', '.join(names)} differ: the code has changed since); its saved "
                         "jobs would not be this run's; use a new --out")
    output_dir(out, force=True)  # still writable
    cells = Cells(out, "" if before.get("code") == code else str(before.get("code")))
    cells.load()
    return cells


def _word(value) -> str:
    if isinstance(value, bool):
        return "given" if value else "not given"
    return str(value)


def run_jobs(func: Callable, todo: list, *, jobs: int | None, dask: str | None,
             desc: str | None, cells: Cells | None) -> list:
    """func(job) for every job of `todo`, in todo's order: those saved in `cells` taken from
    it, the others run on the executor (models.executors.iter_map) and each saved as it
    finishes. desc: the progress bar's name (None: no bar)."""
    outs = [cells.get(job) if cells is not None else MISSING for job in todo]
    left = [k for k, out in enumerate(outs) if out is MISSING]
    bar = None
    if desc is not None:
        from rigidlcp.models.progress import new_bar  # erased at the end: no stale bar

        bar = new_bar(total=len(todo), unit="job", desc=desc, initial=len(todo) - len(left))
    try:
        for i, out in iter_map(func, [todo[k] for k in left], jobs=jobs, dask=dask):
            outs[left[i]] = out
            if cells is not None:
                cells.save(todo[left[i]], out)
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return outs


__all__ = ["MARKER", "CELLS", "Cells", "job_key", "cell_name", "read_cell", "open_out",
           "run_jobs"]
