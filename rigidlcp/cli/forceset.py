"""`rigidlcp forceset FILE`: whether a packing can rest under gravity, and its admissible forces
(verify.statics). The interface is fixed (issue 22): `rigidlcp forceset FILE.csv [--mu-pp A
--mu-plane B --mu-wall C] --json` prints one JSON object with "exists", "dimension", "box"
and "contacts" (i, j, R: [lo, hi], S: [lo, hi]; j = -1 left wall, -2 right wall, -3 plane;
null for an unbounded end, "unknown" for an end whose check failed, listed with the evidence
in "unknown_ends")."""

from __future__ import annotations

import argparse
import json

import numpy as np


def register(sub) -> None:
    from rigidlcp.cli.packing_options import add_packing_options
    from rigidlcp.models.system import DEFAULT_MU

    p = sub.add_parser(
        "forceset", help="admissible contact forces of a packing at rest (existence, "
        "dimension, ranges)",
        description="The set of contact forces that hold a packing at rest under gravity "
        "with Signorini and Coulomb's laws: whether it is empty (a checked equilibrium, or a "
        "checked Farkas certificate, first sought as one moving a small cluster of disks with "
        "the others fixed, checked exactly: farkas_disks in the JSON), its dimension (of its "
        "affine hull), the range of every R and S (linear programs, HiGHS; each end checked "
        "in the set and certified by the LP's duals, an unbounded end by a checked ray; an "
        "answer failing its check is retried, and an end no retry settles is \"unknown\" in "
        "the JSON, not a number nor null: unknown_ends gives the failed check and its "
        "measure, unchecked_optima their count with the unknown can_slide), the contacts "
        "that can slide against 2M - 3N.")
    p.add_argument("file", help="packing file: .csv / .npz (x, y, r [, m, I]) or LAMMPS dump "
                   "(x, y, radius or diameter [, mass]; its BOX BOUNDS give the walls)")
    for name in ("mu_pp", "mu_plane", "mu_wall"):
        p.add_argument("--" + name.replace("_", "-"), type=float, default=DEFAULT_MU[name],
                       help=f"friction coefficient (default {DEFAULT_MU[name]})")
    add_packing_options(p, with_packing=False)
    p.add_argument("--no-ranges", action="store_true",
                   help="existence and dimension only (no range LPs)")
    p.add_argument("--jobs", type=int, default=1, metavar="N",
                   help="worker processes for the range LPs (default 1: in this process; "
                   "each worker holds its own LP, so N workers use N cores)")
    p.add_argument("--samples", type=int, default=0, metavar="N",
                   help="also draw N uniform samples of the admissible forces (force-network "
                   "ensemble; hopsy if installed, else hit-and-run) and write samples.npz and "
                   "pf.png (P(f), f = R/<R>) into --out")
    p.add_argument("--cap", type=float, default=None, help="bound sum R <= CAP (needed "
                   "to sample an unbounded set of forces, e.g. walls that can pinch the pile)")
    p.add_argument("--seed", type=int, default=0, help="seed of the sampler (default 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object (its keys: "
                   "docs/packings.md, 'The JSON'; a range end is a number, null: unbounded, "
                   "or \"unknown\": its check failed, see unknown_ends)")
    p.add_argument("--out", metavar="DIR", help="write forceset.json and forceset.png here")
    p.add_argument("--force", action="store_true", help="overwrite files in --out")
    p.add_argument("--resume", action="store_true", help="continue an interrupted --out DIR "
                   "run: the range ends it settled (DIR/forceset.ends, written as they are) "
                   "are read back, only the others are computed")
    p.add_argument("--no-progress", action="store_true", help="no progress bars on stderr "
                   "(the phases, from 1000 disks; the range ends, from 200 contacts)")
    p.set_defaults(func=cmd_forceset)


def cmd_forceset(args: argparse.Namespace) -> int:
    from rigidlcp.cli.packing_options import read_packing_args, wall
    from rigidlcp.lcp.io.files import output_dir
    from rigidlcp.models.packing_io import read_disks
    from rigidlcp.models.system import System

    if args.jobs < 1:  # the options first: a bad one is named before the file is read
        raise ValueError(f"--jobs must be >= 1, got {args.jobs}")
    left, right = wall(args.left), wall(args.right)
    disks = read_disks(args.file)
    lat = read_packing_args(args.file, args)
    system = System(lat, mu_pp=args.mu_pp, mu_plane=args.mu_plane, mu_wall=args.mu_wall)
    if args.samples < 0:
        raise ValueError(f"--samples must be >= 0, got {args.samples}")
    if args.samples and not args.out:
        raise ValueError("--samples writes samples.npz and pf.png: give --out DIR")
    names = ["forceset.json", "forceset.png"] + (["samples.npz", "pf.png"] if args.samples
                                                  else [])
    known, out = _resumed(args, system, names)
    made = _first_missing(args.out) if args.out and out is None else None
    if args.out and out is None:  # removed again if refused below
        out = output_dir(args.out, force=args.force, names=names)
    journal = None
    if out is not None and not args.no_ranges:
        from rigidlcp.cli.forceset_resume import Journal

        journal = Journal(out, system, resume=args.resume)
    try:
        code = _forceset(args, lat, disks, left, right, system, out, known, journal)
    except BaseException as exc:
        if journal is not None:  # kept for a resume after Ctrl-C, and a resumed run's;
            journal.close()     # else a refusal (e.g. of --samples) leaves nothing
            stopped = isinstance(exc, KeyboardInterrupt)
            if stopped and journal.count + len(known):
                import sys

                print(f"\n{journal.count + len(known)} range ends saved in {journal.path}: "
                      "the same command with --resume continues", file=sys.stderr)
            if not known and not (stopped and journal.count):
                journal.remove()
        _remove_empty(made, out)
        raise
    if journal is not None:
        journal.remove()  # forceset.json holds every end now
    return code


def _resumed(args, system, names) -> tuple[dict, object]:
    """(ends of an interrupted run, its --out folder) for --resume; ({}, None) otherwise, after
    refusing a folder that holds an interrupted run's journal (without --force)."""
    from pathlib import Path

    from rigidlcp.cli.forceset_resume import JOURNAL, read_journal
    from rigidlcp.lcp.errors import InvalidInput
    from rigidlcp.lcp.io.files import OutputExists, output_dir

    if not args.resume:
        if args.out and (Path(args.out) / JOURNAL).is_file() and not args.force:
            raise OutputExists(f"{args.out} holds an interrupted run ({JOURNAL}): --resume "
                               "continues it, --force starts again")
        return {}, None
    if not args.out or args.no_ranges:
        raise InvalidInput("--resume continues the range ends of an --out DIR run: give --out "
                           "(and not --no-ranges)")
    if args.force:
        raise InvalidInput("--resume continues a run, --force starts again: give one")
    if not Path(args.out).is_dir():
        raise InvalidInput(f"--resume: {args.out} is not a folder (nothing to resume)")
    known = read_journal(Path(args.out), system)
    return known, output_dir(args.out, force=True, names=names)


class EndsBar:
    """The progress bar of the range ends (analyse's progress): it counts ends, each once,
    whether an LP, a kept basis or a bound settled it (the total is
    verify.statics.contact_ranges.end_count), so it ends at 100 % exactly; fewer LPs run.
    Opened at the first call (none for an empty set: nothing to count)."""

    LABEL = "force range ends (by LP, kept basis or bound)"

    def __init__(self, before=None) -> None:
        self.bar, self.before = None, before  # before(): called as the bar opens

    def __call__(self, done: int, total: int, stage: str) -> None:
        if self.bar is None:
            from rigidlcp.models.progress import new_bar

            if self.before is not None:
                self.before()
            self.bar = new_bar(total=total, desc=self.LABEL, unit="end")
        self.bar.total = total
        self.bar.update(done - self.bar.n)  # drawn at most every mininterval, not per end

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


#: The phases before the ranges (existence, dimension), the samples and the figure are shown
#: from this many disks (about 1 CPU s in all at 1000 disks, minutes at 10^4; a smaller pile's
#: phases end before a bar means anything); the range ends' bar from 200 contacts.
PHASES_FROM = 1000


def _forceset(args, lat, disks, left, right, system, out, known, journal) -> int:
    import sys

    from rigidlcp.cli.forceset_resume import PhaseBar
    from rigidlcp.lcp.io.files import atomic_write_text
    from rigidlcp.models.packing import report
    from rigidlcp.verify.statics.forceset import analyse

    show = not args.no_progress and lat.c >= 200
    phased = not args.no_progress and lat.p >= PHASES_FROM
    phases = PhaseBar()
    bar = EndsBar(before=phases.close)
    try:
        fs = analyse(system, ranges=not args.no_ranges, progress=bar if show else None,
                     jobs=args.jobs, stage=phases if phased else None, known=known,
                     record=journal)
    finally:
        bar.close()
        phases.close()
    ens = None
    if args.samples and fs.exists:  # before any file is written: a refusal leaves nothing
        from rigidlcp.verify.statics.ensemble import sample

        if phased:
            phases(f"{args.samples} uniform samples of the admissible forces")
        try:
            ens = sample(fs, n=args.samples, seed=args.seed, cap=args.cap)
        finally:
            phases.close()
    result = fs.to_dict() if not args.no_ranges or not fs.exists else {
        k: v for k, v in fs.to_dict().items() if k in ("exists", "dimension", "box", "p", "c")}
    result["packing"] = report(lat).to_dict()
    text = json.dumps(result, allow_nan=False)
    if out is not None:
        atomic_write_text(out / "forceset.json", json.dumps(result, indent=1) + "\n")
        if fs.exists and not args.no_ranges:
            from rigidlcp.verify.statics.plot import plot_forceset

            if phased:
                phases("figure forceset.png")
            plot_forceset(fs, out / "forceset.png")
            phases.close()
    if ens is not None:
        result["ensemble"] = _write_ensemble(ens, args, out)
        text = json.dumps(result, allow_nan=False)
        atomic_write_text(out / "forceset.json", json.dumps(result, indent=1) + "\n")
    if args.json:
        print(text)
        return 0
    print(f"{lat.title()}: {lat.c} contacts ({report(lat).text()}); mu_pp = {args.mu_pp:g}, "
          f"mu_plane = {args.mu_plane:g}, mu_wall = {args.mu_wall:g}", file=sys.stdout)
    print(_box_line(lat, disks, left, right))
    if fs.exists is None:
        print(f"existence undecided: {fs.undecided}")
        return _written(out, fs, args)
    if not fs.exists:
        # analyse says "no" only with an exactly checked certificate (verify.statics.farkas)
        print("no equilibrium: Farkas certificate checked in exact rational arithmetic")
        if fs.moving is not None and fs.moving.size < lat.p:
            shown = ", ".join(str(int(k)) for k in fs.moving[:20])
            more = f" and {fs.moving.size - 20} more" if fs.moving.size > 20 else ""
            print(f"it moves only disks {shown}{more} (the others held fixed)")
        elif fs.moving is not None:
            print(f"it moves every disk ({lat.p})")
        return _written(out, fs, args)
    print(f"equilibrium exists (checked: balance residual {fs.residuals[0]:.2e}, laws "
          f"{fs.residuals[1]:.2e}); dimension of the admissible set: {fs.dimension}"
          + (" (unique forces)" if fs.dimension == 0 else ""))
    if not args.no_ranges:
        lo, hi = fs.diameter()
        open_r = int(np.sum(np.isinf(fs.hi[:fs.c])))
        size = (f"diameter in [{lo:.4g}, {hi:.4g}]" if open_r == 0 else
                f"unbounded: {open_r} of {fs.c} R have no upper end (walls and plane can wedge "
                "the pile with any force; null in the JSON)")
        print(f"{int(fs.sliding.sum())} contacts can slide (2M - 3N = {fs.sliding_bound}); "
              f"{size}; {fs.lps} LPs")
        if fs.unchecked:
            print(_unknown_line(fs))
    if "ensemble" in result:
        e = result["ensemble"]
        print(f"{e['samples']} uniform samples ({e['sampler']}), each checked: largest "
              f"residuals {e['residuals'][0]:.2e} (balance), {e['residuals'][1]:.2e} (laws); "
              f"force fluctuation {e['fluctuation']:.4g} <R>; samples.npz, pf.png")
    return _written(out, fs, args)


def _written(out, fs, args) -> int:
    """Say what --out holds (the text output only: --json prints one object), and why
    forceset.png is missing when it is: there is no equilibrium to draw, or no ranges."""
    if out is not None:
        names = ["forceset.json"]
        if fs.exists and not args.no_ranges:
            names.append("forceset.png")
        if fs.exists and args.samples:
            names += ["samples.npz", "pf.png"]
        why = ("" if len(names) > 1 else " (no forceset.png: no equilibrium to draw)"
               if fs.exists is False else " (no forceset.png: existence undecided)"
               if fs.exists is None else " (no forceset.png: --no-ranges)")
        print(f"written: {', '.join(str(out / n) for n in names)}{why}")
    return 0


def _unknown_line(fs) -> str:
    """How many ends and sliding verdicts are unknown (their checks failed after the retries),
    and the first one's evidence."""
    slide = int(np.sum(fs.sliding_unknown)) if fs.sliding_unknown is not None else 0
    text = (f"unknown: {len(fs.unknown)} range ends and {slide} can_slide verdicts (their "
            "checks failed after the retries; \"unknown\" in the JSON, see unknown_ends)")
    if fs.unknown:
        u, c = fs.unknown[0], fs.c
        text += (f"; first: {u.side} {'R' if u.k < c else 'S'} of contact {u.k % c}, "
                 f"{u.evidence.text()}")
    return text


def _first_missing(path):
    """The outermost folder of `path` that does not exist yet (None: it exists)."""
    from pathlib import Path

    p, top = Path(path).absolute(), None
    while not p.exists():
        p, top = p.parent, p
    return top


def _remove_empty(top, out) -> None:
    """A refused command leaves nothing behind: remove the folders it created, when empty."""
    if top is None or out is None:
        return
    p = out.absolute()
    while True:
        try:
            p.rmdir()  # only an empty folder
        except OSError:
            return
        if p == top:
            return
        p = p.parent


def _box_line(lat, disks, left, right) -> str:
    """Where the obstacles are and where each wall comes from (the option, the file's
    box_left / box_right columns or old '# box:' comment, or the tight box around the
    disks); the plane is y = 0."""
    def side(name: str, at, given, stated) -> str:
        if at is None:
            return f"no {name} wall"
        src = ("--" + name if given is not None else "the file's box" if stated is not None
               else "tight box")
        return f"{name} wall x = {at:g} ({src})"

    return (f"box: {side('left', lat.left, left, disks.left)}, "
            f"{side('right', lat.right, right, disks.right)}, plane y = 0")


def _write_ensemble(ens, args: argparse.Namespace, out) -> dict:
    """Write samples.npz and pf.png of the force-network ensemble; return its summary."""
    import numpy as np

    from rigidlcp.lcp.io.files import atomic_write
    from rigidlcp.verify.statics.plot import plot_pf

    fs = ens.forceset
    c = fs.c

    def write(tmp: str) -> None:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, R=ens.samples[:, :c], S=ens.samples[:, c:],
                                i=fs.system.lattice.i, j=fs.system.lattice.j)

    atomic_write(out / "samples.npz", write)
    plot_pf(ens.f(), out / "pf.png")
    return {"samples": args.samples, "sampler": ens.sampler, "seed": args.seed, "cap": ens.cap,
            "residuals": list(ens.residuals), "fluctuation": ens.fluctuation()}
