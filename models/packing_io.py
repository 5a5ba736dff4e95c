"""Packings read and written: plain CSV / .npz (x, y, r [, m, I]) and LAMMPS text dumps.

* CSV: a header line naming at least the columns x, y, r (any order; m and I optional, other
  columns ignored), then one disk per line. Optional columns box_left, box_right give the
  walls, the same on every line (a value "none": no such wall); `write_packing` writes
  x,y,r,m,I,box_left,box_right with the header as the FIRST line, so that csv.DictReader,
  pandas.read_csv and numpy.genfromtxt(names=True) read it as it is (they take a first
  comment line for the header; a sidecar file could be lost when the CSV is copied; a column
  is read, or ignored, by every CSV tool, and survives sorting and filtering rows). Lines
  starting with '#' are comments; files written before used a first line
  `# box: left=L right=R` for the walls, still read.
* .npz: arrays x, y, r [, m, I] and optional scalars left, right (NaN: no such wall).
* LAMMPS dump (text, `dump ... custom`) of one snapshot: its `ITEM: ATOMS` columns x, y and
  radius (or diameter, halved; mass optional); atoms in the file's order. Recognized by its
  first line `ITEM: TIMESTEP`. A trajectory (several snapshots) is refused, naming the line
  where its last snapshot starts: which one is the packing is the user's choice. Its
  `ITEM: BOX BOUNDS` give the walls from the x line and its
  boundary flag (one letter per side: lo, hi): "f" (fixed; also a line without flags) a wall at
  xlo / xhi; "s", "m" (shrink-wrapped: the box follows the atoms' centres) no stated wall (the
  tight box, as without BOX BOUNDS); "p" (periodic) and a tilted box (triclinic, xy != 0) are
  refused unless the caller gives that wall (left= / right=: a position or "none"), since
  neither is a vertical wall and contacts across a periodic boundary are not modelled. The y and
  z lines are not used: the plane is y = 0 and the frame is not moved.

Missing m: m = r^2; missing I: I = m r^2 / 2 (uniform disks; the units of the arrays, where a
disk of radius 1 has mass 1). Walls not given by the file or the caller: the tight box
(left = min(x - r), right = max(x + r)). The plane is y = 0. A bad file is refused naming its
line and field (`InvalidFile`); a file is never read as something else.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rigidlcp.lcp.errors import InvalidFile
from rigidlcp.lcp.io.files import atomic_write, check_new, open_npz

from .lattice import Lattice
from .packing import GAP_TOL, packing

REQUIRED = ("x", "y", "r")
OPTIONAL = ("m", "I")
#: The CSV columns of the walls (module docstring), for the box's "left" and "right".
BOX_COLUMNS = {"box_left": "left", "box_right": "right"}


@dataclass
class Disks:
    """The disks of a file: centres x (p, 2), radii r, masses m, inertias I (p,), and the walls
    the file states (None: not stated, or "none": no wall)."""

    x: np.ndarray
    r: np.ndarray
    m: np.ndarray
    I: np.ndarray  # noqa: E741 (the paper's I)
    left: float | None | str = None
    right: float | None | str = None
    #: {"left" | "right": why the file's bound on that side is not a wall} (a LAMMPS dump's
    #: periodic or tilted box): refused unless the caller gives that wall
    unusable: dict = field(default_factory=dict)

    def box(self, left=None, right=None) -> tuple[float | None, float | None]:
        """The walls: the caller's, else the file's, else the tight box; "none": no wall."""
        def pick(name, given, stated, tight):
            if given is None and name in self.unusable:
                raise InvalidFile(f"{self.unusable[name]}: give the {name} wall ({name}=X or "
                                  f"'none'; `rigidlcp forceset --{name}`), or write the disks "
                                  "as a CSV with columns box_left, box_right")
            v = given if given is not None else stated
            if v is None:
                return tight
            return None if v == "none" else float(v)

        return (pick("left", left, self.left, float(np.min(self.x[:, 0] - self.r))),
                pick("right", right, self.right, float(np.max(self.x[:, 0] + self.r))))


def read_disks(path: str | os.PathLike) -> Disks:
    """The disks of a CSV, .npz or LAMMPS dump file (module docstring)."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(2, "No such packing file", str(path))
    if path.is_dir():
        raise InvalidFile(f"{path} is a directory, not a packing file (.csv, .npz or a "
                          "LAMMPS dump)")
    if path.suffix == ".npz":
        return _read_npz(path)
    try:
        text = path.read_text(encoding="utf-8-sig")  # a spreadsheet's byte-order mark dropped
    except UnicodeDecodeError:
        raise InvalidFile(f"{path} is not a packing file (not text, not .npz)") from None
    lines = text.splitlines()
    if lines and lines[0].strip() == "ITEM: TIMESTEP":
        return _read_lammps(path, lines)
    return _read_csv(path, lines)


def read_packing(path: str | os.PathLike, left: float | None | str = None,
                 right: float | None | str = None, gap_tol: float = GAP_TOL) -> Lattice:
    """The Lattice of a packing file (contacts detected by models.packing)."""
    d = read_disks(path)
    lo, hi = d.box(left, right)
    return packing(d.x, d.r, d.m, d.I, left=lo, right=hi, gap_tol=gap_tol)


def _number(path: Path, line: int | str, field: str, text: str,
            positive: bool = False) -> float:
    """A number of a text file's `line` (an int), or of an .npz array at `line` (a text such
    as "entry 3": an archive has no lines)."""
    where = f"line {line}, field {field!r}" if isinstance(line, int) else f"array {field!r}, {line}"
    try:
        v = float(text)
    except ValueError:
        raise InvalidFile(f"{path} {where}: {text.strip()!r} is not a number") from None
    if not math.isfinite(v):
        raise InvalidFile(f"{path} {where}: {text.strip()!r} is not finite")
    if positive and v <= 0:
        raise InvalidFile(f"{path} {where}: must be > 0, got {v!r}")
    return v


def _finish(path: Path, cols: dict[str, list[float]], left=None, right=None) -> Disks:
    if not cols["x"]:
        raise InvalidFile(f"{path}: no disks")
    x = np.column_stack([cols["x"], cols["y"]])
    r = np.array(cols["r"])
    m = np.array(cols["m"]) if cols.get("m") else r**2
    inertia = np.array(cols["I"]) if cols.get("I") else 0.5 * m * r**2
    return Disks(x, r, m, inertia, left, right)


def _read_csv(path: Path, lines: list[str]) -> Disks:
    header, cols, box = None, {}, {}
    for k, raw in enumerate(lines, start=1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("#"):
            if line[1:].strip().startswith("box:"):
                box = _box_comment(path, k, line[1:].strip()[4:])
            continue
        fields = [f.strip() for f in line.split(",")]
        if header is None:
            header = fields
            missing = [c for c in REQUIRED if c not in header]
            if missing:
                raise InvalidFile(f"{path} line {k}: the header must name the columns x, y, r "
                                  f"(missing {', '.join(missing)}; got {line[:60]!r})"
                                  + _header_hint(line, header, missing, lines[:k - 1]))
            dup = [c for c in set(header) if header.count(c) > 1 and c]
            if dup:
                raise InvalidFile(f"{path} line {k}: column {dup[0]!r} named twice")
            cols = {c: [] for c in REQUIRED + OPTIONAL if c in header}
            continue
        if len(fields) != len(header):
            raise InvalidFile(f"{path} line {k}: {len(fields)} fields, the header has "
                              f"{len(header)}")
        for c in cols:
            cols[c].append(_number(path, k, c, fields[header.index(c)],
                                   positive=c in ("r", "m", "I")))
        for c, side in BOX_COLUMNS.items():
            if c in header:
                _box_column(path, k, c, side, fields[header.index(c)], box)
    if header is None:
        raise InvalidFile(f"{path}: no header line naming the columns x, y, r")
    return _finish(path, cols, **box)


def _box_column(path: Path, k: int, column: str, side: str, text: str, box: dict) -> None:
    """A wall from a box_left / box_right field (module docstring): "none" or a number, the
    same on every line (and as an old `# box:` comment, when the file has both)."""
    value = "none" if text == "none" else _number(path, k, column, text)
    if box.setdefault(side, value) != value:
        raise InvalidFile(f"{path} line {k}, field {column!r}: {text!r}, but the {side} wall "
                          f"is {box[side]!r} above (one box per file)")


def _header_hint(line: str, header: list[str], missing: list[str],
                 before: list[str] = ()) -> str:
    """What is most likely wrong with a CSV header that lacks `missing`: the header written as
    a comment (numpy.savetxt's `header=` is written after '# ' unless `comments=''`), whitespace
    instead of commas, names in another case, or a radius column named otherwise."""
    for k, raw in enumerate(before, start=1):
        names = [f.strip() for f in raw.strip().lstrip("#").split(",")]
        if raw.strip().startswith("#") and all(c in names for c in REQUIRED):
            return (f": line {k} names them but is a comment (it starts with '#'): remove the "
                    "'#' (numpy.savetxt writes its header= so unless given comments='')")
    if len(header) == 1 and len(line.split()) > 1:
        return ": fields are separated by commas, this line by spaces or tabs"
    lower = {h.lower(): h for h in header}
    if all(c in lower for c in missing):
        return (": names are case-sensitive, got " + ", ".join(repr(lower[c]) for c in missing))
    if "r" in missing and ("radius" in lower or "diameter" in lower or "d" in lower):
        return (": name the radius column r" if "radius" in lower else
                ": give the radius as a column r (half the diameter)")
    return ""


def _box_comment(path: Path, k: int, text: str) -> dict:
    out = {}
    for item in text.split():
        key, _, value = item.partition("=")
        if key not in ("left", "right"):
            raise InvalidFile(f"{path} line {k}: box comment field {key!r} (expected left=, "
                              "right=)")
        out[key] = "none" if value == "none" else _number(path, k, key, value)
    return out


def _read_npz(path: Path) -> Disks:
    with open_npz(path, "a packing (.npz with arrays x, y, r)") as data:
        files = set(data.files)
        if "__meta__" in files:  # models.runio's marker
            raise InvalidFile(f"{path} is a run saved by `rigidlcp simulate`, not a packing "
                              "(.npz with arrays x, y, r)")
        missing = [c for c in REQUIRED if c not in files]
        if missing:
            raise InvalidFile(f"{path}: array {missing[0]!r} missing (a packing .npz holds x, "
                              "y, r [, m, I])")
        arrays = {c: np.asarray(data[c]) for c in REQUIRED + OPTIONAL if c in files}
        walls = {k: float(data[k]) for k in ("left", "right") if k in files}
    if arrays["x"].ndim != 1:  # e.g. centres as one (N, 2) array: "like x" would not help
        raise InvalidFile(f"{path}: array 'x' must be 1-D, one abscissa per disk (the "
                          f"ordinates in array 'y'), got shape {arrays['x'].shape}")
    p = arrays["x"].size
    cols = {}
    for c, a in arrays.items():
        if a.ndim != 1 or a.size != p or a.dtype.kind not in "fiu":
            raise InvalidFile(f"{path}: array {c!r} must be {p} numbers (like x), got shape "
                              f"{a.shape} of {a.dtype}")
        for k, v in enumerate(a.astype(float)):
            _number(path, f"entry {k}", c, repr(float(v)), positive=c in ("r", "m", "I"))
        cols[c] = a.astype(float).tolist()
    box = {k: ("none" if math.isnan(v) else v) for k, v in walls.items()}
    return _finish(path, cols, **box)


def _read_lammps(path: Path, lines: list[str]) -> Disks:
    start = next((k for k, line in enumerate(lines) if line.startswith("ITEM: ATOMS")), None)
    count = next((k for k, line in enumerate(lines) if line.startswith("ITEM: NUMBER OF")), None)
    if start is None or count is None or count + 1 >= len(lines):
        raise InvalidFile(f"{path}: a LAMMPS dump needs 'ITEM: NUMBER OF ATOMS' and "
                          "'ITEM: ATOMS ...' lines")
    n = _number(path, count + 2, "number of atoms", lines[count + 1])
    if n != int(n) or n < 1:
        raise InvalidFile(f"{path} line {count + 2}: the number of atoms must be an integer "
                          f">= 1, got {lines[count + 1].strip()!r}")
    n = int(n)
    names = lines[start].split()[2:]
    # the radius column, else LAMMPS's per-atom diameter (halved below)
    need = {"x": "x", "y": "y", "r": "radius" if "radius" in names or "diameter" not in names
            else "diameter"}
    missing = [v for v in need.values() if v not in names]
    if missing:
        other = [n for n in ("xs", "ys", "xu", "yu", "xsu", "ysu") if n in names]
        hint = (f": this dump has {', '.join(other)}; write the coordinates x y (e.g. "
                "`dump 1 all custom N file id x y z radius`)" if other else "")
        raise InvalidFile(f"{path} line {start + 1}: the ATOMS columns must include x, y and "
                          f"radius or diameter (missing {', '.join(missing)}){hint}")
    if "mass" in names:
        need["m"] = "mass"
    cols = {c: [] for c in need}
    body = lines[start + 1: start + 1 + n]
    if len(body) < n:
        raise InvalidFile(f"{path}: {n} atoms announced, {len(body)} lines follow")
    _one_snapshot(path, lines, start + 1 + n, n)
    for k, raw in enumerate(body, start=start + 2):
        fields = raw.split()
        if len(fields) != len(names):
            raise InvalidFile(f"{path} line {k}: {len(fields)} fields, the ATOMS header has "
                              f"{len(names)}")
        for c, name in need.items():
            cols[c].append(_number(path, k, name, fields[names.index(name)],
                                   positive=c in ("r", "m")))
    if need["r"] == "diameter":
        cols["r"] = [d / 2 for d in cols["r"]]
    disks = _finish(path, cols)
    _lammps_box(path, lines[:start], disks)
    return disks


def _one_snapshot(path: Path, lines: list[str], end: int, n: int) -> None:
    """InvalidFile when anything but blank lines follows the first snapshot's n atoms (which
    end at line index `end`): more snapshots (a trajectory), or more atoms than announced."""
    more = next((k for k in range(end, len(lines)) if lines[k].strip()), None)
    if more is None:
        return
    if lines[more].strip() != "ITEM: TIMESTEP":
        raise InvalidFile(f"{path} line {more + 1}: more lines than the {n} atoms announced "
                          "by ITEM: NUMBER OF ATOMS")
    starts = [k for k, line in enumerate(lines) if line.strip() == "ITEM: TIMESTEP"]
    steps = [lines[k + 1].strip() if k + 1 < len(lines) else "?" for k in starts]
    raise InvalidFile(f"{path} holds {len(starts)} snapshots (timesteps {steps[0]} to "
                      f"{steps[-1]}), a packing is one: write the one you want to its own "
                      f"file, e.g. the last: tail -n +{starts[-1] + 1} {path} > "
                      f"{path.with_name(path.stem + '_last' + path.suffix)}")


def _lammps_box(path: Path, head: list[str], disks: Disks) -> None:
    """The walls of a dump's `ITEM: BOX BOUNDS` (module docstring) into disks."""
    at = next((k for k, line in enumerate(head) if line.startswith("ITEM: BOX BOUNDS")), None)
    if at is None:
        return  # no box: the tight box
    words = head[at].split()[3:]
    tilted = words[:3] == ["xy", "xz", "yz"]
    flags = words[3:] if tilted else words
    flag = flags[0] if flags else "ff"  # old dumps state no flags: the box is fixed
    if len(flag) != 2 or any(f not in "fsmp" for f in flag):
        raise InvalidFile(f"{path} line {at + 1}: x boundary flag {flag!r} (expected two of "
                          "f, s, m, p)")
    if at + 1 >= len(head):
        raise InvalidFile(f"{path} line {at + 2}: the x bounds are missing")
    fields = head[at + 1].split()
    if len(fields) != (3 if tilted else 2):
        raise InvalidFile(f"{path} line {at + 2}: {len(fields)} fields, the x bounds need "
                          f"{3 if tilted else 2}")
    lo, hi = (_number(path, at + 2, name, v) for name, v in zip(("xlo", "xhi"), fields))
    tilt = _number(path, at + 2, "xy", fields[2]) if tilted else 0.0
    for name, f, x in (("left", flag[0], lo), ("right", flag[1], hi)):
        if tilt != 0.0:
            disks.unusable[name] = (f"{path} line {at + 2}: the box is tilted (xy = {tilt:g}), "
                                    "its x faces are not vertical walls")
        elif f == "p":
            disks.unusable[name] = (f"{path} line {at + 1}: the x boundary is periodic; "
                                    "contacts across it are not modelled")
        elif f == "f":
            setattr(disks, name, x)


def write_packing(path: str | os.PathLike, lattice: Lattice, m: np.ndarray | None = None,
                  inertia: np.ndarray | None = None, force: bool = False) -> Path:
    """Write a lattice's disks as CSV (or .npz by suffix) with its walls (the CSV's columns
    box_left, box_right, header first: module docstring); m, I default to the lattice's own,
    else r^2 and m r^2 / 2. Refuses an existing file unless force."""
    path = Path(path)
    check_new([path], force=force)
    r = lattice.radii
    m = np.asarray(m if m is not None else (lattice.masses if lattice.masses is not None
                                            else r**2), dtype=float)
    inertia = np.asarray(inertia if inertia is not None else (
        lattice.inertias if lattice.inertias is not None else 0.5 * m * r**2), dtype=float)
    walls = {"left": lattice.left, "right": lattice.right}
    if path.suffix == ".npz":
        def write(tmp: str) -> None:
            with open(tmp, "wb") as fh:
                np.savez(fh, x=lattice.x[:, 0], y=lattice.x[:, 1], r=r, m=m, I=inertia,
                         **{k: np.nan if v is None else v for k, v in walls.items()})
    else:
        box = ",".join("none" if v is None else repr(float(v)) for v in walls.values())
        rows = ["x,y,r,m,I," + ",".join(BOX_COLUMNS)]  # the header first (module docstring)
        rows += [f"{a!r},{b!r},{c!r},{d!r},{e!r},{box}" for a, b, c, d, e in
                 zip(*(v.tolist() for v in (lattice.x[:, 0], lattice.x[:, 1], r, m, inertia)))]

        def write(tmp: str) -> None:
            Path(tmp).write_text("\n".join(rows) + "\n")
    atomic_write(path, write)
    return path
