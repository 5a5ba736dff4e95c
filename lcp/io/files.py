"""Writing files the way a user expects: atomically, with ordinary permissions, never over a
file the user already had unless asked (`force=True`, the command line's --force).

Every writer of the toolkit (problems, runs, sweeps, figures, reports) goes through these
helpers, so that the policy is stated once:

* `check_new(paths, force)` refuses outputs that exist (`OutputExists`, naming the first one);
* `output_dir(path, force, names)` makes a directory for outputs, refusing one that is a file or
  already holds any of `names` (or, with `names=None`, anything at all);
* `atomic_write(path, write)` writes through a temporary file in the same folder and renames it
  into place, so an interrupted write never leaves half a file; the file gets the mode a plain
  `open()` would give it (0666 minus the umask), not mkstemp's 0600.
"""

from __future__ import annotations

import os
import tempfile
import zipfile
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from rigidlcp.lcp.errors import InvalidFile, InvalidInput, OutputExists

_ZIP_MAGIC = b"PK\x03\x04"


def open_npz(path: str | os.PathLike, what: str = "a .npz file"):
    """`numpy.load` of a .npz archive (no pickles) that names the file when it is not one.

    Missing file: FileNotFoundError; a directory, an empty file, a file that is not a zip
    archive or a damaged archive: `InvalidFile` ("PATH is not WHAT: ..."). Use as a context
    manager, like `numpy.load`.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(2, f"No such file (expected {what})", str(path))
    if path.is_dir():
        raise InvalidFile(f"{path} is a directory, not {what}")
    with open(path, "rb") as fh:
        head = fh.read(4)
    if not head:
        raise InvalidFile(f"{path} is empty, not {what}")
    if head != _ZIP_MAGIC:
        raise InvalidFile(f"{path} is not {what} (not a .npz archive)")
    try:
        return np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise InvalidFile(f"{path} is not {what} (damaged archive: "
                          f"{' '.join(str(exc).split())[:80]})") from None


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def check_new(paths: Iterable[str | os.PathLike], force: bool = False) -> None:
    """Raise `OutputExists` if any of `paths` exists (unless `force`)."""
    if force:
        return
    for p in paths:
        if os.path.lexists(p):
            raise OutputExists(f"{p} exists; pass --force (force=True) to overwrite it")


def output_dir(path: str | os.PathLike, force: bool = False,
               names: Iterable[str] | None = None) -> Path:
    """Create the output directory `path` (and its parents) and return it.

    Refused (`InvalidInput`) when `path` is an existing file. Unless `force`, refused
    (`OutputExists`) when the directory already holds one of `names`, or, for `names=None`
    (outputs whose names are not known in advance), when it is not empty.
    """
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise InvalidInput(f"{out} is a file, not a directory")
    if out.is_dir() and not force:
        if names is None:
            if any(out.iterdir()):
                raise OutputExists(f"{out} is not empty; pass --force (force=True) to write "
                                   "into it (files of the same name are overwritten)")
        else:
            check_new((out / n for n in names), force=False)
    out.mkdir(parents=True, exist_ok=True)
    if not os.access(out, os.W_OK | os.X_OK):
        raise PermissionError(13, "Permission denied (not writable)", str(out))
    _probe(out)
    return out


def _probe(folder: Path) -> None:
    """Create and remove a file in `folder`: some folders (/proc, a full or read-only file
    system, root's access() answers) refuse files that access() allows. The error names the
    folder, not the probe's hidden name."""
    try:
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=".rigidlcp-probe.", suffix=".tmp")
    except OSError as exc:
        raise OSError(exc.errno, f"{exc.strerror} (no file can be created in this folder)",
                      str(folder)) from None
    os.close(fd)
    os.unlink(tmp)


def atomic_write(path: str | os.PathLike, write: Callable[[str], None],
                 force: bool = True) -> Path:
    """Call `write(tmp)` on a temporary name next to `path`, then rename it to `path`.

    The file's mode is 0666 & ~umask (as `open(path, "w")` would give). With `force=False` an
    existing `path` is refused (`OutputExists`) before anything is written.
    """
    path = Path(path)
    check_new([path], force=force)
    if path.parent.exists() and not path.parent.is_dir():
        raise InvalidInput(f"{path.parent} is a file, not a directory")
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    except OSError as exc:  # name the user's path, not the temporary one
        raise OSError(exc.errno, f"{exc.strerror} (cannot write)", str(path)) from None
    os.close(fd)
    try:
        os.chmod(tmp, 0o666 & ~_umask())
        write(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def atomic_write_text(path: str | os.PathLike, text: str, force: bool = True) -> Path:
    """`atomic_write` of a text file (UTF-8), flushed to disk before the rename."""

    def write(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())

    return atomic_write(path, write, force=force)


__all__ = ["open_npz", "check_new", "output_dir", "atomic_write", "atomic_write_text"]
