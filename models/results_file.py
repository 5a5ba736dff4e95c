"""The results file of a sweep: JSON lines, one per finished point, appended durably.

A line is written by a single `write` on a file opened with O_APPEND and fsync'ed; a torn last
line (a kill inside the write) is ignored on reading, and `finalize` rewrites the file in grid
order atomically (models.sweep explains the protocol).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from rigidlcp.lcp.errors import InvalidFile
from rigidlcp.lcp.io.files import atomic_write_text

from .runio import _json_default

#: Sweepable parameters and their types (names as in `rigidlcp.cli.simulate.add_system_arguments`).
PARAMS: dict[str, type] = {
    "lattice": str, "lx": int, "ly": int, "mu_pp": float, "mu_plane": float,
    "mu_wall": float, "gamma": float, "v0": float, "inertia": float, "seed": int,
}
#: Run options, fixed for a sweep and part of every point's identity.
RUN_OPTIONS: dict[str, Any] = {
    "method": "lemke", "select": "face-min-norm", "fallback": "lemke", "max_events": 20_000,
    "t_max": None, "omega_scale": 1.0,
}
#: Result columns written for every point, in this order after the parameters.
RESULT_FIELDS = ("status", "steady", "events", "t", "m_g", "F_g", "mu_g", "dissipation_rate",
                 "dissipation_rate_slope", "paper_regime", "T", "NT", "NS_pp", "NS_plane",
                 "NS_wall", "sliding_pp", "sliding_plane", "sliding_wall", "fallbacks", "message")
RESULTS = "results.jsonl"


def point_key(point: dict) -> str:
    """Identity of a point: canonical JSON of its parameters and run options."""
    sel = {k: point[k] for k in (*PARAMS, *RUN_OPTIONS)}
    return json.dumps(sel, sort_keys=True, separators=(",", ":"))


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
