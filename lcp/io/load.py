"""`lcp.load`: read a problem file of any kind the toolkit knows (its own .npz of an LCP or an
MLCP, or a Siconos text file of an LCP, an MLCP or a 2D friction-contact problem)."""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path

from ..errors import InvalidFile, RigidLCPError
from ..problems.problem import LCP, MLCP
from .files import open_npz


def load(path: str | os.PathLike):
    """Read a problem file, detecting its kind: an .npz written by `.save` (or any .npz with
    M, q or A, C, D, B, a, b), or a Siconos text file (LCP, MLCP or 2D friction contact:
    lcp.io; returns an LCP, MLCP or FrictionContact2D). A file of no known kind raises
    InvalidProblem (lcp.io.text.FileFormatError) naming the file, the line and what was
    expected."""
    path = Path(path)
    if path.is_file():
        with open(path, "rb") as fh:
            magic = fh.read(4)
        if magic and magic[:2] != b"PK" and path.suffix != ".npz":  # a Siconos text file
            from .siconos import read_siconos

            return read_siconos(path)
    try:
        with open_npz(path, "a problem file (.npz, or a Siconos text file)") as data:
            keys = set(data.files)
            header = json.loads(str(data["__header__"])) if "__header__" in keys else {}
            name, meta = header.get("name", path.stem), header.get("meta", {})
            if {"M", "q"} <= keys:
                return LCP(data["M"], data["q"], name=name, meta=meta)
            mlcp_keys = {"A", "C", "D", "B", "a", "b"}
            if mlcp_keys <= keys:
                return MLCP(*(data[k] for k in ("A", "C", "D", "B", "a", "b")), name=name,
                            meta=meta)
    except (RigidLCPError, OSError):
        raise
    except (ValueError, EOFError, KeyError, AttributeError, zipfile.BadZipFile) as exc:  # damaged
        raise InvalidFile(f"{path}: cannot read the problem "
                          f"({type(exc).__name__}: {' '.join(str(exc).split())[:80]})") from None
    found = sorted(keys - {"__header__"})
    kind = " (it is a run saved by `rigidlcp simulate`)" if "__meta__" in keys else ""
    raise InvalidFile(
        f"{path} holds neither an LCP (arrays M, q) nor an MLCP (arrays A, C, D, B, a, b)"
        f"{kind}; found {', '.join(found[:6])}{', ...' if len(found) > 6 else ''}"
    )
