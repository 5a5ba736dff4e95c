"""`rigidlcp simulate` and `rigidlcp plot`."""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

from rigidlcp.cli.main import seed

#: --lattice, --lx, --ly of the commands that take a system (their defaults).
ARRAY_DEFAULTS = ("rect", 10, 4)


class GivenArray(argparse.Action):
    """Stores --lattice / --lx / --ly and records that it was given (`args.array_given`), so
    that --packing refuses it even at its default value (`--packing F --lattice rect` was
    taken, as rect is the default, and --lattice ignored)."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)
        namespace.array_given = [*getattr(namespace, "array_given", []), option_string]


def add_system_arguments(p: argparse.ArgumentParser) -> None:
    """The options that define a system (shared with other commands)."""
    from rigidlcp.models.system import DEFAULT_MU

    g = p.add_argument_group("system")
    lattice, lx, ly = ARRAY_DEFAULTS
    g.add_argument("--lattice", choices=("rect", "tri"), default=lattice, action=GivenArray,
                   help=f"rectangular or triangular array (default {lattice})")
    g.add_argument("--lx", type=int, default=lx, action=GivenArray,
                   help=f"disks in the rows touching both walls (default {lx})")
    g.add_argument("--ly", type=int, default=ly, action=GivenArray,
                   help=f"number of rows (default {ly})")
    for name, text in (("mu_pp", "particle-particle"), ("mu_plane", "particle-plane"),
                       ("mu_wall", "particle-wall")):
        g.add_argument("--" + name.replace("_", "-"), type=float, default=DEFAULT_MU[name],
                       help=f"{text} friction coefficient (default {DEFAULT_MU[name]})")
    g.add_argument("--gamma", type=float, default=0.1,
                   help="acceleration of the box relative to the plane, in g "
                   "(0: constant velocity; default %(default)s)")
    g.add_argument("--v0", type=float, default=0.0,
                   help="initial velocity of the box relative to the plane (sqrt(g r))")
    g.add_argument("--inertia", type=float, default=None,
                   help="moment of inertia (default m r^2/2)")
    g.add_argument("--packing", metavar="FILE", default=None,
                   help="disks from a packing file (.csv/.npz/LAMMPS dump, docs/packings.md) "
                   "instead of --lattice/--lx/--ly")
    from rigidlcp.cli.packing_options import add_packing_options

    add_packing_options(g)  # --left, --right, --gap-tol: read as `rigidlcp forceset` reads


def system_from_args(args, array_defaults: tuple | None = None):
    """The System of the options; with --packing, refused when --lattice/--lx/--ly differ from
    the command's own `array_defaults` (default ARRAY_DEFAULTS, simulate's 10 x 4 rect)."""
    from rigidlcp.cli.packing_options import refuse_without_packing
    from rigidlcp.models.system import make_system

    refuse_without_packing(args)
    if getattr(args, "packing", None):  # a packing file: its own radii, masses and inertias
        refuse_array_options(args, array_defaults or ARRAY_DEFAULTS)
        if args.inertia is not None:  # the library's refusal speaks Python (inertia=None)
            raise ValueError("--inertia: the packing gives every disk's moment of inertia "
                             "(its file's column I, else m r^2 / 2): leave --inertia out")
        from rigidlcp.models.system import System

        return System(packing_of(args), mu_pp=args.mu_pp, mu_plane=args.mu_plane,
                      mu_wall=args.mu_wall, gamma=args.gamma, V0=args.v0, inertia=args.inertia)
    return make_system(args.lattice, args.lx, args.ly, mu_pp=args.mu_pp, mu_plane=args.mu_plane,
                       mu_wall=args.mu_wall, gamma=args.gamma, V0=args.v0, inertia=args.inertia)


#: The advice of the commands that have no sparse path.
DENSE_ONLY = ("this command is dense only: use a smaller array (the event-driven evolution of "
              "large arrays: rigidlcp simulate --method sparse-pivoting --select none)")


def refuse_array_options(args, defaults: tuple = ARRAY_DEFAULTS) -> None:
    """--packing with --lattice/--lx/--ly changed from their `defaults`: refused (they would
    be silently ignored)."""
    if getattr(args, "array_given", None) or (args.lattice, args.lx, args.ly) != defaults:
        raise ValueError("--packing takes its disks from the file: --lattice, --lx and "
                         "--ly describe an array, give one or the other")


def packing_of(args):
    """The lattice of --packing FILE, read once (kept on args for system_from_args)."""
    lat = getattr(args, "_packing_lattice", None)
    if lat is None:
        from rigidlcp.cli.packing_options import read_packing_args

        lat = args._packing_lattice = read_packing_args(args.packing, args, runs=True)
    return lat


def refuse_too_large_for_dense(args, what: str, instead: str | None = None) -> None:
    """One line and exit 2, in a second and before anything is built or written, when the
    dense matrices of `what` for the --lx x --ly array cannot fit in memory (c >= p = lx ly
    contacts: the lattice itself takes minutes at 10^6 disks). instead: the advice (default:
    the sparse backend of `simulate`)."""
    from rigidlcp.models.engine.simulate import SPARSE_INSTEAD, check_dense_memory
    from rigidlcp.models.lattice import MAX_DISKS

    if getattr(args, "packing", None):  # its disks count, not the array options' defaults
        from rigidlcp.cli.packing_options import is_run
        from rigidlcp.models.packing_io import read_disks

        # cheap first: c >= p before contacts are found (a run's geometry is read whole)
        p = packing_of(args).p if is_run(args.packing) else len(read_disks(args.packing).r)
        check_dense_memory(p, f"{what} of a packing of {p} disks (at least {p} contacts)",
                           instead=instead or SPARSE_INSTEAD)
        lat = packing_of(args)  # then its own contacts
        check_dense_memory(lat.c, f"{what} of a packing of {p} disks ({lat.c} contacts)",
                           instead=instead or SPARSE_INSTEAD)
        return
    p = args.lx * args.ly
    if 0 < p <= MAX_DISKS:  # beyond MAX_DISKS the lattice refuses the size itself
        check_dense_memory(p, f"{what} of a {args.lx} x {args.ly} array (at least {p} "
                           "contacts)", instead=instead or SPARSE_INSTEAD)


def selection_rule(text: str) -> str:
    """argparse type of --selection: a rule of rigidlcp.models.selection (checked, kept as
    text)."""
    from rigidlcp.models.selection import InvalidSelection, Selection

    try:
        return str(Selection.parse(text))
    except InvalidSelection as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def register(sub) -> None:
    p = sub.add_parser("simulate", help="evolve an array event by event to its steady state",
                       description="Exact event-driven evolution of a disk array (Sec. II C, IV).")
    add_system_arguments(p)
    g = p.add_argument_group("run")
    g.add_argument("--seed", type=seed, default=1, help="seed of the initial angular velocities")
    g.add_argument("--omega-scale", type=float, default=1.0,
                   help="initial angular velocities uniform in [-scale, scale]")
    g.add_argument("--method", default="lemke", help="LCP method (see `rigidlcp methods`; "
                   "default %(default)s)")
    g.add_argument("--fallback", default="lemke",
                   help="method used at an event where --method fails ('none': stop; "
                   "default %(default)s)")
    g.add_argument("--selection", "--select", dest="select", type=selection_rule,
                   default="face-min-norm", metavar="RULE",
                   help="the point followed where an event's solution is not unique: "
                   "face-min-norm (default), max-sum-R[:CAP], random:SEED, global, none "
                   "(docs/integrators.md)")
    g.add_argument("--no-closed-search", dest="closed_search", action="store_false",
                   help="stop at the first selected solution that opens a contact, without "
                   "looking for one of the same event that keeps every contact closed "
                   "(docs/packings.md)")
    g.add_argument("--t-max", type=float, default=np.inf,
                   help="stop at this time (> 0; default: no limit)")
    g.add_argument("--max-events", type=int, default=100_000,
                   help="stop after this many events (default 100000)")
    g.add_argument("--out", default=None, help="save the run to OUT (.npz + .json)")
    g.add_argument("--dump-problems", default=None, metavar="DIR",
                   help="write every event's LCP to DIR/event_NNNNNN.npz (DIR new or empty)")
    g.add_argument("--force", action="store_true",
                   help="overwrite an existing --out run / write into a non-empty DIR")
    g.add_argument("--json", action="store_true", help="print the summary as JSON")
    g.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser("plot", help="figures of a saved run (Figs. 7-10, 13)")
    p.add_argument("run", help="a run saved by `rigidlcp simulate --out`")
    p.add_argument("--out", required=True, help="directory for the PNGs")
    p.add_argument("--event", type=int, default=-1, help="event to draw (default: the last)")
    p.add_argument("--force", action="store_true", help="overwrite PNGs already in --out")
    p.set_defaults(func=cmd_plot)


def cmd_simulate(args) -> int:
    from rigidlcp import lcp
    from rigidlcp.lcp.errors import InvalidInput
    from rigidlcp.lcp.io.files import check_new, output_dir
    from rigidlcp.models.engine import simulate
    from rigidlcp.models.event import initial_state
    from rigidlcp.models.observables import state_counts
    from rigidlcp.models.runio import run_paths, save_run

    if args.method != "sparse-pivoting":
        refuse_too_large_for_dense(args, "the dense event LCP")
    system = system_from_args(args)
    if args.omega_scale < 0 or not np.isfinite(args.omega_scale):
        raise ValueError(f"--omega-scale must be a finite number >= 0, got {args.omega_scale}")
    if args.max_events < 1:
        raise ValueError(f"--max-events must be >= 1, got {args.max_events}")
    if not args.t_max > 0:
        raise ValueError(f"--t-max must be > 0, got {args.t_max}")
    for option, name in (("--method", args.method), ("--fallback", args.fallback)):
        if name not in ("none", "sparse-pivoting"):
            try:  # an unknown method fails now, not at the first event
                lcp.get_method(name)
            except lcp.InvalidProblem as exc:
                raise type(exc)(f"{option}: {exc}") from None
    # Outputs are checked before the run, not after it: a user's file is never overwritten
    # (without --force) and a run is never lost to an unwritable folder.
    if args.out:
        if os.path.isdir(args.out):
            raise InvalidInput(f"--out {args.out} is a directory; a run is a file (e.g. "
                               f"{os.path.join(args.out, 'run.npz')})")
        paths = run_paths(args.out)
        check_new(paths, force=args.force)
        try:
            output_dir(paths[0].parent, force=True)
        except OSError as exc:  # name the user's path
            raise OSError(exc.errno, f"--out {args.out}: {exc.strerror}", exc.filename) from None
    if args.dump_problems:
        output_dir(args.dump_problems, force=args.force)
    state = initial_state(system, seed=args.seed, omega_scale=args.omega_scale)
    fallback = None if args.fallback == "none" else args.fallback
    bar = None
    if not args.no_progress:
        from rigidlcp.models.progress import new_bar

        bar = new_bar(desc="events", unit="ev")  # erased at the end: no stale bar on screen
    last_save = [time.monotonic()]

    def progress(run) -> None:
        if bar is not None:
            bar.update(1)
            bar.set_postfix(t=f"{run.last.t:.4g}", mu_g=f"{run.last.mu_g:.4f}", refresh=False)
        if args.out and time.monotonic() - last_save[0] > 30:  # checkpoint long runs
            run.final = None
            save_run(run, args.out)
            last_save[0] = time.monotonic()

    run = simulate(system, state, method=args.method, t_max=args.t_max,
                   max_events=args.max_events, progress=progress, dump_dir=args.dump_problems,
                   select=args.select, fallback=fallback, closed_search=args.closed_search)
    if bar is not None:
        bar.close()
    if args.out:
        path = save_run(run, args.out)
    summary = run.summary()
    if not summary["paper_regime"]:
        print(f"warning: the run left the paper's regime ({run.status}): "
              f"{summary['regime_note']}", file=sys.stderr)
    if run.status == "detachment" and run.final is not None:
        summary["detachment_check"] = detachment_check(system, run.final)
    summary["selection"] = args.select
    if run.closed is not None:
        summary["closed_search"] = closed_summary(run)
    if args.json:
        print(json.dumps(summary, indent=2, default=float))
    else:
        from rigidlcp.cli.packing_options import walls_text

        lat = system.lattice
        print(f"{title(lat)}: {lat.p} disks, {lat.c} contacts{walls_text(lat)}; mu_pp = "
              f"{system.mu_pp}, mu_plane = {system.mu_plane}, mu_wall = {system.mu_wall}, "
              f"gamma = {system.gamma} g, V0 = {system.V0}")
        rows = [("status", run.status), ("message", run.message)]
        if "detachment_check" in summary:
            rows.append(("detachment check", summary["detachment_check"]))
        if "closed_search" in summary:
            rows.append(("closed search", closed_text(summary["closed_search"])))
        rows += [("events", run.n_events),
                ("wall time (s)", f"{run.wall_time:.3f}"), ("method", run.method)]
        if run.records:
            last = run.last
            counts = state_counts(system, last)
            rows += [("t (last event)", f"{last.t:.6g}"), ("mu_g", f"{summary['mu_g']:.6f}"
                      + selection_note(args.select, run.status, args.out)),
                     ("F_g", f"{summary['F_g']:.6f}" + same_state(run.status, "mu_g x "
                                                                  "the weight")),
                     ("dissipation rate D", f"{summary['dissipation_rate']:.6g}"
                      + same_state(run.status, "-sum S v_t")),
                     ("dD/dt", f"{summary['dissipation_rate_slope']:.6g}"),
                     ("dissipated energy", f"{summary['dissipated_energy']:.6g} over t in "
                      "[{:.6g}, {:.6g}]".format(*summary["dissipated_energy_interval"])),
                     ("transmitting / not", f"{counts['T']} / {counts['NT']}"),
                     ("non-sliding pp/plane/wall", f"{counts['NS_pp']} / {counts['NS_plane']}"
                      f" / {counts['NS_wall']}"),
                     ("sliding pp/plane/wall", f"{counts['sliding_pp']} / "
                      f"{counts['sliding_plane']} / {counts['sliding_wall']}"),
                     ("fallback solves", summary["fallback_solves"])]
        if args.out:
            rows.append(("saved", str(path)))
        width = max(len(k) for k, _ in rows)
        for k, v in rows:
            print(f"  {k:<{width}}  {v}")
    return 0 if run.status in ("steady", "time_limit", "event_limit") else 1


def selection_note(rule: str, status: str, out: str | None) -> str:
    """What mu_g is: one point of a set where an event's solution is not unique, picked by the
    selection rule; for a steady run, where its range over all valid steady states is."""
    if status != "steady":
        return f"  (selection {rule})"
    return (f"  (one valid steady state, selection {rule}; over all of them: "
            f"rigidlcp ranges {out or 'RUN.npz'})")


def same_state(status: str, what: str) -> str:
    """F_g and D are read at the state whose mu_g is annotated (`selection_note`): at a
    steady state they vary with it over the valid steady states, so the row says so."""
    return f"  ({what}, at the same selected state)" if status == "steady" else ""


def closed_summary(run) -> dict:
    """The closed-solution search of the run (models/engine/closed.py) for the JSON: on or off,
    at how many events it ran, the events where a closed solution was followed, and its
    verdict at the stop ("proved", "undecided") when the run ends in a detachment (an event's
    or, for `rigidlcp timestep`, a step's: models/step_closed.py)."""
    out = dict(run.closed)
    verdict = None
    if run.status == "detachment" and run.closed.get("search"):
        verdict = ("proved" if ("proved: no solution of the event" in run.message
                               or "proved: no solution of the step" in run.message)
                   else "undecided" if "undecided" in run.message else None)
    out["at_stop"] = verdict
    return out


def closed_text(c: dict, unit: str = "event") -> str:
    """One line of the summary for `closed_summary` (unit: "event", or "step" for a
    time-stepper's run)."""
    if not c["search"]:
        return "off (--no-closed-search)"
    text = f"on: ran at {c['searched']} {unit}(s); a closed solution followed at " + (
        f"{unit}(s) " + ", ".join(str(e) for e in c["followed"][:10]) if c["followed"]
        else f"no {unit}")
    if c["at_stop"]:
        text += f"; at the stop: {c['at_stop']} (message)"
    return text


def title(lat) -> str:
    """"rect 10x4" for an array, "packing" for any other set of disks (whose lx, ly are only a
    box estimate)."""
    return f"{lat.name} {lat.lx}x{lat.ly}" if lat.regular else lat.name


def detachment_check(system, state) -> str:
    """Whether the detachment at `state` is forced (verify.statics.regime): every solution of
    the event opens a contact (a checked Farkas certificate), or forces keeping the disks in
    place exist and the detachment is the selected solution's."""
    from rigidlcp.verify.statics.regime import regime

    r = regime(system, state)
    if r.exists is False:
        return "proved: " + r.text()
    if r.exists:
        return ("not forced for the translations: forces that keep every disk in place exist "
                "at this event (checked witness, without the candidates' tangential laws); "
                "whether a solution of the event's LCP keeps every contact closed is the "
                "closed search's verdict (message)")
    return r.text()


def cmd_plot(args) -> int:
    from rigidlcp.lcp.io.files import output_dir
    from rigidlcp.models.plot import plot_files, plot_run
    from rigidlcp.models.runio import load_run

    run = load_run(args.run)
    if not run.records:
        raise ValueError(f"{args.run} has no event to draw")
    if not -run.n_events <= args.event < run.n_events:
        raise ValueError(f"--event must be in [-{run.n_events}, {run.n_events - 1}]")
    out = output_dir(args.out, force=args.force, names=plot_files(run.system))
    for path in plot_run(run, out, event=args.event):
        print(path)
    return 0
