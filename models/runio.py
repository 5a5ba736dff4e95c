"""Save and load a run: one .npz with the per-event arrays and a JSON sidecar with the metadata.

Both files are written to temporary names and renamed into place, so an interrupted write never
leaves a half-written run behind.
"""

from __future__ import annotations

import json
import os
import zipfile
from dataclasses import fields
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rigidlcp.lcp.errors import InvalidFile, RigidLCPError
from rigidlcp.lcp.io.files import atomic_write, open_npz

if TYPE_CHECKING:  # loaded by load_run only: models.sweep needs _json_default, not the engine
    from rigidlcp.models.engine.records import Run

FORMAT = "rigidlcp-run/1"
_SCALARS = ("t", "V", "mu_g", "dissipation", "iterations", "residual", "n_lcp", "fallback")
_ARRAYS = ("omega", "omega_dot", "R", "S", "s", "s_in", "vt", "at")


def run_paths(path: str | os.PathLike) -> tuple[Path, Path]:
    """(data .npz, metadata .json) for a run path given with or without the .npz suffix."""
    path = Path(path)
    if path.suffix != ".npz":
        path = path.with_name(path.name + ".npz")
    return path, path.with_suffix(".json")


def save_run(run: Run, path: str | os.PathLike) -> Path:
    """Write `run` to PATH.npz (+ PATH.json); returns the .npz path."""
    data_path, meta_path = run_paths(path)
    arrays: dict[str, np.ndarray] = {}
    for name in _SCALARS + _ARRAYS:
        arrays[name] = run.array(name) if run.records else np.zeros(0)
    if run.final is not None:
        arrays.update(final_omega=run.final.omega, final_s=run.final.s,
                      final_tV=np.array([run.final.t, run.final.V]))
    if not run.system.lattice.regular:  # a packing: its geometry, per-disk m and I
        arrays.update(_geometry(run.system))
    meta = {
        "format": FORMAT, "system": run.system.describe(), "status": run.status,
        "message": run.message, "contacts": run.contacts, "method": run.method,
        "wall_time": run.wall_time, "events": run.n_events,
        "methods_per_event": [r.method for r in run.records],
        "closed": run.closed,  # the closed-solution search, or None
        "summary": run.summary(),
    }
    text = json.dumps(meta, indent=2, default=_json_default)

    def write_npz(tmp: str) -> None:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, __meta__=np.array(text), **arrays)

    def write_json(tmp: str) -> None:
        Path(tmp).write_text(text + "\n")

    atomic_write(data_path, write_npz)
    atomic_write(meta_path, write_json)
    return data_path


def load_run(path: str | os.PathLike) -> Run:
    """Read a run written by `save_run` (the system is rebuilt from the metadata; run.closed,
    the closed-solution search of the run, is restored, None in files older than it)."""
    data_path, _ = run_paths(path)
    if Path(path).is_file() and not data_path.exists():  # e.g. a text file, not PATH.npz
        npz = Path(path).with_suffix(".npz")
        if Path(path).suffix == ".json" and npz.is_file():  # the run's metadata, beside it
            raise InvalidFile(f"{path} is the metadata of a run: give its data file, {npz}")
        raise InvalidFile(f"{path}: not a run file (a run is the .npz written by "
                          "`rigidlcp simulate`)")
    try:
        return _load_run(data_path)
    except (RigidLCPError, OSError):
        raise
    except (ValueError, EOFError, KeyError, TypeError, AttributeError, IndexError,
            zipfile.BadZipFile) as exc:  # a damaged archive or metadata
        raise InvalidFile(f"{data_path}: damaged run file ({type(exc).__name__}: "
                          f"{' '.join(str(exc).split())[:80]})") from None


def _load_run(data_path: Path) -> Run:
    from rigidlcp.models.engine.records import EventRecord, Run
    from rigidlcp.models.event import State
    from rigidlcp.models.system import make_system

    with open_npz(data_path, "a run saved by `rigidlcp simulate` (.npz)") as data:
        if "__meta__" not in data.files:
            kind = (" (it is an LCP/MLCP problem file: see `rigidlcp solve`)"
                    if "__header__" in data.files else "")
            raise InvalidFile(f"{data_path} is not a run saved by `rigidlcp simulate`{kind}")
        meta = json.loads(str(data["__meta__"]))
        if not isinstance(meta, dict) or meta.get("format") != FORMAT:
            fmt = meta.get("format") if isinstance(meta, dict) else None
            raise InvalidFile(f"{data_path} is not a rigidlcp run (format {fmt!r}, expected "
                              f"{FORMAT!r})")
        cols = {k: data[k] for k in _SCALARS + _ARRAYS}
        geometry = {k: data[k] for k in _GEOMETRY if k in data.files}
        final = None
        if "final_omega" in data.files:
            t, V = data["final_tV"]
            final = State(float(t), data["final_omega"], float(V), data["final_s"].astype(int))
    params = dict(meta["system"])
    if params["lattice"] == "packing":
        system = _packing_system(params, geometry, data_path)
    else:
        system = make_system(params.pop("lattice"), params.pop("lx"), params.pop("ly"), **params)
    methods = meta.get("methods_per_event", [])
    names = {f.name for f in fields(EventRecord)}
    records = []
    for k in range(meta["events"]):
        rec = {name: cols[name][k] for name in _SCALARS + _ARRAYS}
        rec.update(method=methods[k] if k < len(methods) else meta["method"])
        for name in ("t", "V", "mu_g", "dissipation", "residual"):
            rec[name] = float(rec[name])
        rec["iterations"], rec["n_lcp"] = int(rec["iterations"]), int(rec["n_lcp"])
        rec["fallback"], rec["s"] = bool(rec["fallback"]), rec["s"].astype(int)
        rec["s_in"] = rec["s_in"].astype(int)
        records.append(EventRecord(**{k: v for k, v in rec.items() if k in names}))
    return Run(system, records, status=meta["status"], message=meta["message"],
               contacts=list(meta.get("contacts", [])), wall_time=float(meta["wall_time"]),
               method=meta["method"], final=final, closed=_closed(meta))


def _closed(meta: dict) -> dict | None:
    """Run.closed as saved; a file written before it was saved keeps it only in its summary
    ("closed_search", since the search exists), an older one not at all (None)."""
    closed = meta.get("closed", (meta.get("summary") or {}).get("closed_search"))
    if closed is None:
        return None
    if not isinstance(closed, dict):
        raise TypeError(f"the closed-solution search's record is a {type(closed).__name__}")
    return dict(closed)


_GEOMETRY = ("packing_x", "packing_r", "packing_m", "packing_I")


def _geometry(system) -> dict[str, np.ndarray]:
    lat = system.lattice
    return {"packing_x": lat.x, "packing_r": lat.radii, "packing_m": system.masses,
            "packing_I": system.inertias}


def _packing_system(params: dict, geometry: dict, data_path: Path):
    """The System of a packing run, rebuilt from the saved geometry (contacts re-detected with
    the saved gap tolerance, so in the same order)."""
    from rigidlcp.models.packing import packing
    from rigidlcp.models.system import System

    missing = [k for k in _GEOMETRY if k not in geometry]
    if missing:
        raise InvalidFile(f"{data_path}: a packing run without its geometry ({missing[0]})")
    lat = packing(geometry["packing_x"], geometry["packing_r"], geometry["packing_m"],
                  geometry["packing_I"], left=params["left"], right=params["right"],
                  gap_tol=params["gap_tol"])
    if lat.c != params["c"]:
        raise InvalidFile(f"{data_path}: the saved packing has {lat.c} contacts, the run "
                          f"{params['c']}")
    keep = ("mu_pp", "mu_plane", "mu_wall", "gamma", "V0", "g")
    return System(lat, **{k: params[k] for k in keep})


def _json_default(obj):
    if isinstance(obj, (np.integer, np.floating, np.bool_)):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"not JSON serializable: {type(obj).__name__}")
