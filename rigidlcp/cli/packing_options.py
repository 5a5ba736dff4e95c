"""The options that read a packing file: `--gap-tol` (contact detection, models.packing) and
`--left`, `--right` (the walls, models.packing_io), shared by `rigidlcp forceset` and by every
command that takes `--packing FILE` (simulate, timestep, compare-integrators, forces,
nullspace), so that a packing `forceset` reads is read the same way by the others."""

from __future__ import annotations

import argparse


def add_packing_options(g, with_packing: bool = True) -> None:
    """--gap-tol, --left, --right on the parser or group g; with_packing: their help says they
    need --packing."""
    need = " (with --packing)" if with_packing else ""
    g.add_argument("--left", default=None, help="left wall abscissa, or 'none' (default: the "
                   f"file's box, else the tight box){need}")
    g.add_argument("--right", default=None, help=f"right wall abscissa, or 'none'{need}")
    g.add_argument("--gap-tol", type=float, default=None,
                   help="relative gap tolerance of contact detection (default 1e-9, at most "
                   f"0.05: overlaps up to G x the smaller radius are contacts){need}")


def wall(text: str | None) -> float | str | None:
    """A --left / --right value: a number, 'none' (no wall), or None (the file's box)."""
    if text is None or text == "none":
        return text
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"a wall must be a number or 'none', got {text!r}") from None


def refuse_without_packing(args: argparse.Namespace) -> None:
    """--left, --right or --gap-tol without --packing: refused (an array has its own box and
    exact contacts; the options would be silently ignored)."""
    given = [f"--{n.replace('_', '-')}" for n in ("left", "right", "gap_tol")
             if getattr(args, n, None) is not None]
    if given and not getattr(args, "packing", None):
        raise ValueError(f"{', '.join(given)} read a packing file: give --packing FILE (an "
                         "array has its own walls and exact contacts)")


def is_run(path) -> bool:
    """Whether `path` is a run saved by `rigidlcp simulate --out` (RUN.npz beside RUN.json)."""
    from pathlib import Path

    return Path(path).suffix.lower() == ".npz" and Path(path).with_suffix(".json").is_file()


def read_packing_args(path, args: argparse.Namespace, runs: bool = False):
    """The Lattice of the packing file `path` with the options of `args` (missing ones at
    their defaults); an overlap beyond --gap-tol is refused with what accepts it, or with why
    nothing does (interpenetration beyond models.packing.MAX_GAP_TOL). runs: a run saved by
    `rigidlcp simulate --out` (RUN.npz beside its RUN.json) gives its own geometry (the
    options, which would change it, are then refused)."""
    from rigidlcp.models.packing import GAP_TOL, MAX_GAP_TOL, Overlap
    from rigidlcp.models.packing_io import read_disks, read_packing

    if runs and is_run(path):
        from rigidlcp.models.runio import load_run

        given = [f"--{n.replace('_', '-')}" for n in ("left", "right", "gap_tol")
                 if getattr(args, n, None) is not None]
        if given:
            raise ValueError(f"{', '.join(given)}: {path} is a run, whose geometry (walls, "
                             "contacts) was fixed when it was simulated")
        return load_run(path).system.lattice

    gap_tol = getattr(args, "gap_tol", None)
    gap_tol = GAP_TOL if gap_tol is None else gap_tol
    left, right = wall(getattr(args, "left", None)), wall(getattr(args, "right", None))
    try:
        lat = read_packing(path, left=left, right=right, gap_tol=gap_tol)
    except Overlap as exc:  # a hand-written file rounds its centres: say what accepts it
        r = read_disks(path).r
        s = min(r[exc.i], r[exc.j]) if exc.j >= 0 else r[exc.i]
        hint = (f"--gap-tol G accepts overlaps up to G x radius (G <= {MAX_GAP_TOL:g})"
                if exc.overlap <= MAX_GAP_TOL * s else
                f"{exc.overlap / s:.3g} of the radius: the disks interpenetrate, beyond what "
                f"any --gap-tol accepts (at most {MAX_GAP_TOL:g}): not rigid disks in contact")
        raise Overlap(f"{exc}; {hint}", exc.i, exc.j, exc.overlap) from None
    warn_if_off_the_plane(lat)
    return lat


def warn_if_off_the_plane(lat) -> None:
    """On stderr, when no disk touches the plane y = 0: a DEM frame whose bottom is elsewhere
    (the frame is not moved) reads as a pile floating above the plane, with no equilibrium."""
    import sys

    import numpy as np

    from rigidlcp.models.lattice import PLANE

    if lat.p and not np.any(lat.j == PLANE):
        low = float(np.min(lat.x[:, 1] - lat.radii))
        print(f"warning: no disk touches the plane y = 0 (the lowest disk's bottom is at y = "
              f"{low:.6g}): the file's frame is not moved; shift y so that the bottom is 0",
              file=sys.stderr, flush=True)


def walls_text(lat) -> str:
    """"; left wall x = 0, right wall x = 4" for a packing (its walls come from options, the
    file or the tight box: worth saying), "" for an array (walls at its ends)."""
    if lat.regular:
        return ""

    def side(name: str, at) -> str:
        return f"no {name} wall" if at is None else f"{name} wall x = {at:g}"

    return f"; {side('left', lat.left)}, {side('right', lat.right)}"
