"""A resumable `rigidlcp forceset --out DIR`: the range ends journal, and the phase progress.

The ranges (4 LPs per contact at most) are the long part of a forceset on a large pile (the
1000-disk pile: about 25 CPU minutes, docs/packings.md). Every end settled is appended to
DIR/forceset.ends as it is (one line "k side value", k indexing [R; S], side "min" / "max",
value a float as repr writes it, inf for an end proved unbounded; unknown ends are not
written), after a first line naming the journal's version and a fingerprint of the packing and
its coefficients (the disks, contacts, walls, masses, inertias, every mu). `--resume` reads it
back: the ends written are taken as settled (each was a checked end of the same P) and only the
others are computed; existence, dimension and the sliding verdicts are computed again (seconds
against the ranges' minutes, except existence beyond ~5000 disks). A line cut by an interruption
is ignored. The journal is removed once forceset.json is written.
"""

from __future__ import annotations

import hashlib
import time
from pathlib import Path

import numpy as np

from rigidlcp.lcp.errors import InvalidInput

JOURNAL = "forceset.ends"
VERSION = "rigidlcp forceset ends v1"


def fingerprint(system) -> str:
    """SHA-256 of what fixes P: the disks, contacts, walls, masses, inertias and mu."""
    lat = system.lattice
    h = hashlib.sha256()
    radii = lat.radii if lat.radii is not None else [lat.radius]
    for arr in (lat.x, radii, lat.i, lat.j, system.masses, system.inertias, system.mu,
                [system.g, np.nan if lat.left is None else lat.left,
                 np.nan if lat.right is None else lat.right]):
        h.update(np.ascontiguousarray(np.asarray(arr, dtype=float)).tobytes())
    return h.hexdigest()


def read_journal(out: Path, system) -> dict:
    """The ends of an earlier run in `out` ({(k, side): value}); refused (InvalidInput) when
    there is no journal or it is another packing's (or other coefficients')."""
    path = out / JOURNAL
    if not path.is_file():
        raise InvalidInput(f"--resume: no {JOURNAL} in {out} (nothing to resume: run without "
                           "--resume)")
    lines = path.read_text().split("\n")
    head = f"{VERSION} {fingerprint(system)}"
    if lines[0] != head:
        raise InvalidInput(f"--resume: {path} is not this packing's journal (another packing, "
                           "other coefficients, or another version): run without --resume "
                           "into another folder, or with --force to start again")
    known = {}
    for line in lines[1:]:
        parts = line.split()
        try:
            k, side, value = int(parts[0]), parts[1], float(parts[2])
        except (IndexError, ValueError):
            continue  # the line an interruption cut (the last), or an empty one
        if len(parts) == 3 and side in ("min", "max") and not np.isnan(value):
            known[(k, side)] = value
    return known


class Journal:
    """Appends the ends as they are settled (flushed at most every `every` s and at close)."""

    def __init__(self, out: Path, system, resume: bool, every: float = 2.0):
        self.path = out / JOURNAL
        self.fh = open(self.path, "a" if resume else "w")
        if not resume:
            self.fh.write(f"{VERSION} {fingerprint(system)}\n")
        self.every, self.last, self.count = every, time.monotonic(), 0

    def __call__(self, k: int, side: str, value: float) -> None:
        self.fh.write(f"{k} {side} {value!r}\n")
        self.count += 1
        if time.monotonic() - self.last > self.every:
            self.fh.flush()
            self.last = time.monotonic()

    def close(self) -> None:
        if not self.fh.closed:
            self.fh.close()

    def remove(self) -> None:
        self.close()
        self.path.unlink(missing_ok=True)


class PhaseBar:
    """Progress of the phases before the ranges (analyse's stage callback): one bar on stderr
    (models.progress.new_bar, erased at the end) counting phases, named as each starts, its
    detail (windows solved) as postfix; closed when the range ends' bar opens."""

    def __init__(self) -> None:
        self.bar, self.name = None, None

    def __call__(self, name: str, detail: str = "") -> None:
        if self.bar is None:
            from rigidlcp.models.progress import new_bar

            self.bar = new_bar(desc=name, unit="phase", mininterval=0, miniters=1,
                               bar_format="{desc} [{elapsed}]{postfix}")
        if name != self.name:
            self.name = name
            self.bar.set_description_str(name, refresh=False)
            self.bar.set_postfix_str("", refresh=False)
            self.bar.update(1)
        if detail:
            self.bar.set_postfix_str(detail)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None
