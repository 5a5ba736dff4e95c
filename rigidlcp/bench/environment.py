"""The environment of a ``rigidlcp bench`` run, recorded in its report (as qpbenchmark does):
versions of rigidlcp (with its git commit), Python and the numerical libraries, of every
peer that ran, the CPU and the machine's load."""

from __future__ import annotations

import importlib.metadata
import os
import platform
import subprocess
from pathlib import Path


def cpu_model() -> str:
    """The CPU's model name (/proc/cpuinfo, else platform.processor())."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def git_commit(folder: str | os.PathLike | None = None) -> str:
    """The checkout's commit (with "+ changes" when the tree is not clean), or "-" when
    rigidlcp does not run from a git checkout."""
    folder = Path(folder or Path(__file__).resolve().parents[2])
    try:
        head = subprocess.run(["git", "-C", str(folder), "rev-parse", "--short=12", "HEAD"],
                              capture_output=True, text=True, timeout=30, check=False)
        dirty = subprocess.run(["git", "-C", str(folder), "status", "--porcelain",
                                "--untracked-files=no"], capture_output=True, text=True,
                               timeout=30, check=False)
    except (OSError, subprocess.TimeoutExpired):
        return "-"
    if head.returncode != 0:
        return "-"
    return head.stdout.strip() + (" + uncommitted changes" if dirty.stdout.strip() else "")


def _version(dist: str) -> str:
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return "-"


def environment(peers: dict[str, str] | None = None, started: str = "",
                load: tuple[float, float] | None = None) -> list[tuple[str, str]]:
    """(what, value) rows: date, rigidlcp and its commit, Python, numpy, scipy, the peers'
    versions ({name: version}), the CPU, its cores and the load average at start / end."""
    rows = [("date", started)] if started else []
    rows += [("rigidlcp", f"{_version('rigidlcp')}, commit {git_commit()}"),
             ("Python", f"{platform.python_version()} ({platform.python_implementation()})"),
             ("numpy / scipy", f"{_version('numpy')} / {_version('scipy')}")]
    rows += [(f"peer {name}", version) for name, version in (peers or {}).items()]
    rows += [("CPU", f"{cpu_model()}, {os.cpu_count()} logical cores; one solve at a time, "
              "one BLAS thread"), ("OS", platform.platform())]
    if load is not None:
        rows.append(("load average", f"{load[0]:.2f} at the start, {load[1]:.2f} at the end "
                     "(the machine may be shared: times are indicative)"))
    return rows
