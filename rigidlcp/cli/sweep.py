"""`rigidlcp sweep` (steady states over a parameter grid) and `rigidlcp effective` (Eqs. 4.1-4.2).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from rigidlcp.cli.simulate import selection_rule

GRID_HELP = "a value, a list A,B,C, or a range START:STOP:NUM (NUM values, ends included)"


def register(sub) -> None:
    add_sweep(sub)
    add_effective(sub)


# -- rigidlcp sweep ------------------------------------------------------------------------------


def add_sweep(sub) -> None:
    from rigidlcp.models.sweep import DEFAULTS, RUN_OPTIONS

    p = sub.add_parser(
        "sweep", help="steady states over a grid of parameters (resumable; local or Dask)",
        description="One run to the steady state per point of the grid (the product of the "
        "values of every option below). Each point's summary is appended to OUT/results.jsonl "
        "as soon as it finishes; rerunning the same command skips the finished points. "
        "When the grid is done the file is rewritten in grid order.",
        epilog="Every system option takes " + GRID_HELP + ", e.g. --gamma 0:1.0:41. "
        "Example (Fig. 11): rigidlcp sweep --lattice rect --lx 10 --ly 1 --mu-pp 0.05 "
        "--mu-plane 0.1 --mu-wall 0 --gamma 0:1.0:41 --out sweep/ ; then "
        "rigidlcp effective sweep/")
    g = p.add_argument_group("system (each a grid)")
    g.add_argument("--lattice", default=DEFAULTS["lattice"], help="rect, tri or rect,tri "
                   "(default %(default)s)")
    for name, text in (("lx", "disks in the rows touching both walls"),
                       ("ly", "number of rows"), ("mu_pp", "particle-particle friction"),
                       ("mu_plane", "particle-plane friction"),
                       ("mu_wall", "particle-wall friction"),
                       ("gamma", "acceleration of the box relative to the plane, in g"),
                       ("v0", "initial velocity of the box relative to the plane"),
                       ("inertia", "moment of inertia ('default': m r^2/2)"),
                       ("seed", "seed of the initial angular velocities")):
        default = DEFAULTS[name]
        g.add_argument("--" + name.replace("_", "-"), default=default,
                       help=f"{text} (default {'default' if default is None else default})")
    r = p.add_argument_group("run (fixed for the sweep)")
    r.add_argument("--method", default=RUN_OPTIONS["method"],
                   help="LCP method (default %(default)s)")
    r.add_argument("--fallback", default=RUN_OPTIONS["fallback"],
                   help="method used where --method fails ('none': stop; default "
                   "%(default)s)")
    r.add_argument("--selection", "--select", dest="select", type=selection_rule,
                   default=RUN_OPTIONS["select"], metavar="RULE",
                   help="the point followed where an event's solution is not unique: "
                   "face-min-norm (default), max-sum-R[:CAP], random:SEED, global, none")
    r.add_argument("--max-events", type=int, default=RUN_OPTIONS["max_events"],
                   help=f"events per run at most (default {RUN_OPTIONS['max_events']})")
    r.add_argument("--t-max", type=float, default=None, help="stop each run at this time")
    r.add_argument("--omega-scale", type=float, default=RUN_OPTIONS["omega_scale"],
                   help="initial angular velocities uniform in [-scale, scale]")
    e = p.add_argument_group("execution")
    e.add_argument("--out", required=True, help="directory of the sweep (results.jsonl)")
    e.add_argument("--jobs", "-j", type=int, default=None,
                   help="worker processes (default: the CPUs available; 1: in this process)")
    e.add_argument("--dask", default=None, metavar="tcp://HOST:PORT|local",
                   help="run the points on a dask.distributed scheduler, or on a LocalCluster "
                   "of --jobs workers on 127.0.0.1 ('local'); needs rigidlcp[dask]")
    e.add_argument("--save-runs", action="store_true",
                   help="also save every run to OUT/runs/<id>.npz (see `rigidlcp plot`)")
    e.add_argument("--force", action="store_true",
                   help="write into an --out directory that is not empty and not a sweep's")
    e.add_argument("--json", action="store_true", help="print the rows as JSON lines")
    e.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=cmd_sweep)


def sweep_from_args(args: argparse.Namespace):
    """A `Sweep` from the parsed options: options with several values are the axes."""
    from rigidlcp.models.sweep import PARAMS, Sweep, parse_grid

    axes, fixed = {}, {}
    for name in PARAMS:
        values = parse_grid(name, getattr(args, name))
        if len(values) > 1:
            axes[name] = values
        else:
            fixed[name] = values[0]
    if args.max_events < 1:
        raise ValueError(f"--max-events must be >= 1, got {args.max_events}")
    if not args.omega_scale >= 0:
        raise ValueError(f"--omega-scale must be >= 0, got {args.omega_scale}")
    options = {"method": args.method, "select": args.select, "max_events": args.max_events,
               "t_max": args.t_max, "omega_scale": args.omega_scale,
               "fallback": None if args.fallback == "none" else args.fallback}
    sweep = Sweep(axes, fixed, options)
    sweep.validate()  # every point of the grid, before anything runs
    return sweep


def cmd_sweep(args: argparse.Namespace) -> int:
    from rigidlcp.models.sweep import check_out, run_sweep, varying

    sweep = sweep_from_args(args)
    if args.jobs is not None and args.jobs < 1:
        raise ValueError(f"--jobs must be >= 1, got {args.jobs}")
    check_out(args.out, force=args.force)
    n = len(sweep.points())
    print(f"sweep: {n} point(s); axes: " + (", ".join(
        f"{k} ({len(v)})" for k, v in sweep.axes.items()) or "none") + f"; out: {args.out}",
        file=sys.stderr)
    try:
        res = run_sweep(sweep, args.out, jobs=args.jobs, dask=args.dask,
                        progress=not args.no_progress, save_runs=args.save_runs,
                        force=args.force)
    except KeyboardInterrupt:
        print(f"\ninterrupted: the finished points are in {Path(args.out) / 'results.jsonl'};"
              " rerun the same command to resume", file=sys.stderr)
        return 130
    if args.json:
        for row in res.rows:
            print(json.dumps(row))
    else:
        cols = varying(res.rows) or list(sweep.axes)
        print_table(res.rows, cols, selection=args.select)
        print(f"{len(res.rows)} points: {res.ran} run now, {res.skipped} found done; "
              f"results: {res.out / 'results.jsonl'}")
    outside = [r for r in res.rows if r.get("paper_regime") is False]
    if outside:
        print(f"warning: {len(outside)} point(s) left the paper's regime (status "
              + ", ".join(sorted({r['status'] for r in outside})) + "): their numbers are not "
              "the paper's observables (paper_regime: false in results.jsonl)", file=sys.stderr)
    bad = [r for r in res.rows if r["status"] not in ("steady",)]
    if bad:
        print(f"{len(bad)} point(s) did not reach a steady state (status: "
              + ", ".join(sorted({r['status'] for r in bad})) + ")", file=sys.stderr)
    return 0


def print_table(rows: list[dict], cols: list[str], selection: str | None = None) -> None:
    """One row per point; D(t) is the dissipation rate right after the last event (at t), dD/dt
    its slope: under gamma != 0 the sliding velocities grow linearly in the steady state, so
    D(t) depends on when the run stopped and dD/dt is the steady observable (Sec. IV C).
    A steady row's mu_g, F_g and D are those of the steady state the `selection` rule reached,
    one valid steady state (there may be others): the last line says so, and where the ranges
    are."""
    head = cols + ["status", "events", "t", "mu_g", "F_g", "D(t)", "dD/dt", "NS", "sliding"]
    table = []
    for r in rows:
        ns = sum(r.get(f"NS_{k}") or 0 for k in ("pp", "plane", "wall"))
        sl = sum(r.get(f"sliding_{k}") or 0 for k in ("pp", "plane", "wall"))
        table.append([_fmt(r.get(c)) for c in cols] + [
            str(r["status"]), str(r["events"]), _fmt(r.get("t")), _fmt(r.get("mu_g")),
            _fmt(r.get("F_g")), _fmt(r.get("dissipation_rate")),
            _fmt(r.get("dissipation_rate_slope")), str(ns), str(sl)])
    widths = [max(len(h), *(len(t[k]) for t in table)) for k, h in enumerate(head)]
    print("  ".join(h.rjust(w) for h, w in zip(head, widths)))
    for t in table:
        print("  ".join(v.rjust(w) for v, w in zip(t, widths)))
    if any(r.get("gamma") for r in rows):
        print("D(t): dissipation rate after the last event, at t (m g sqrt(g r)); under gamma "
              "!= 0 it grows as dD/dt in the steady state: compare dD/dt across points")
    if selection is not None and any(r.get("status") == "steady" for r in rows):
        print(f"mu_g, F_g, D of a steady row: the steady state the selection rule ({selection}) "
              "reached, one valid steady state (there may be others); their range over all: "
              "rigidlcp ranges on that point's run (--save-runs)")


def _fmt(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


# -- rigidlcp effective --------------------------------------------------------------------------


#: The files `rigidlcp effective` writes.
EFFECTIVE_FILES = ("effective.json", "mu_g.png", "effective.png")


def add_effective(sub) -> None:
    p = sub.add_parser(
        "effective", help="effective inertia and friction of a gamma sweep (Eqs. 4.1-4.2)",
        description="Legendre transform of the steady-state F_g(gamma) of a sweep (Sec. IV B): "
        "a = dF_g/dgamma, b = F_g - a gamma, m_e = m_g + a, mu_e = b / (m_g g). The derivative "
        "is a least-residual local polynomial fit that does not straddle the kinks of F_g "
        "(docs/reproduction.md, models/effective.py). One curve per combination of the other "
        "parameters; non-steady points are left out and listed.")
    p.add_argument("sweep", help="a sweep directory (or its results.jsonl)")
    p.add_argument("--out", default=None,
                   help="directory for mu_g.png (Fig. 11), effective.png (Fig. 12) and "
                   "effective.json (default: the sweep directory)")
    p.add_argument("--degree", type=int, default=1, help="degree of the local fits")
    p.add_argument("--window", type=int, default=3, help="points per local fit (default "
                   "%(default)s)")
    p.add_argument("--force", action="store_true",
                   help="overwrite effective.json, mu_g.png, effective.png if present")
    p.add_argument("--json", action="store_true", help="print the table as JSON")
    p.set_defaults(func=cmd_effective)


def cmd_effective(args: argparse.Namespace) -> int:
    from rigidlcp.models.effective import from_rows
    from rigidlcp.models.sweep import read_results

    rows = read_results(args.sweep)
    groups = from_rows(rows, window=args.window, degree=args.degree)
    usable = [(p, e, lo) for p, e, lo in groups if e is not None]
    if not usable:
        raise ValueError(f"{args.sweep}: no group with steady states at two or more gammas")
    out = Path(args.out) if args.out else (Path(args.sweep) if Path(args.sweep).is_dir()
                                           else Path(args.sweep).parent)
    from rigidlcp.models.sweep import PARAMS

    labels = []
    for params, _, _ in usable:
        diff = [k for k in PARAMS if k not in ("gamma", "seed")
                and len({json.dumps(p.get(k)) for p, _, _ in usable}) > 1]
        labels.append(", ".join(f"{k}={params[k]}" for k in diff) or
                      f"{params['lattice']} {params['lx']}x{params['ly']}")
    payload = [{"group": p, "label": lab, "m_g": e.m_g, "rows": e.rows(),
                "left_out": [{"gamma": r["gamma"], "seed": r["seed"], "status": r["status"]}
                             for r in lo]}
               for (p, e, lo), lab in zip(usable, labels)]
    from rigidlcp.lcp.io.files import atomic_write_text, output_dir

    text = json.dumps(payload, indent=1) + "\n"
    if not args.force and _up_to_date(out, text):  # a re-display of the same table
        files = [out / name for name in EFFECTIVE_FILES[1:]]
    else:
        output_dir(out, force=args.force, names=EFFECTIVE_FILES)
        atomic_write_text(out / "effective.json", text)
        files = plot_effective([(lab, e) for (_, e, _), lab in zip(usable, labels)], out,
                               cite=all(is_paper_fig11(p) for p, _, _ in usable))
    if args.json:
        print(json.dumps(payload, indent=1))
        return 0
    for item in payload:
        print(f"{item['label']}: m_g = {item['m_g']:g}")
        print(f"  {'gamma':>8} {'mu_g':>10} {'a':>10} {'m_e':>10} {'mu_e':>10}  fit")
        for r in item["rows"]:
            print(f"  {r['gamma']:8.4g} {r['mu_g']:10.6f} {r['a']:10.5g} {r['m_e']:10.5g} "
                  f"{r['mu_e']:10.6f}  {'exact' if r['exact'] else 'kink'}")
        for r in item["left_out"]:
            print(f"  left out: gamma = {r['gamma']}, seed = {r['seed']}: {r['status']}")
    n_out = sum(len(lo) for _, _, lo in usable)
    if n_out:
        print(f"{n_out} point(s) left out (not steady)", file=sys.stderr)
    print(f"fit: 'exact' = a window of {args.window} points on one linear piece of F_g: a is "
          f"dF_g/dgamma; 'kink' = every window of {args.window} points around gamma straddles "
          "a change of contact states (a kink of F_g, Fig. 11): a is a chord slope, not the "
          "derivative (open markers in effective.png)")
    kinks = sum(not r["exact"] for item in payload for r in item["rows"])
    if kinks:
        total = sum(len(item["rows"]) for item in payload)
        print(f"warning: {kinks} of {total} points are 'kink': their a, m_e and mu_e are chord "
              "estimates, not Eqs. (4.1)-(4.2); refine the gamma grid there (F_g has a kink "
              "wherever a disk changes mode)", file=sys.stderr)
    for f in files:
        print(f)
    return 0


def _up_to_date(out: Path, text: str) -> bool:
    """True when `out` already holds this very effective.json and its figures."""
    try:
        same = (out / "effective.json").read_text(encoding="utf-8") == text
    except (OSError, UnicodeDecodeError):
        return False
    return same and all((out / name).is_file() for name in EFFECTIVE_FILES[1:])


#: The parameters of the paper's Figs. 11-12 (rect 10x1, mu_pp 0.05, mu_plane 0.1, frictionless
#: walls, from rest): only a sweep of this system is titled with their numbers.
PAPER_FIG11 = dict(lattice="rect", lx=10, ly=1, mu_pp=0.05, mu_plane=0.1, mu_wall=0.0, v0=0.0)


def is_paper_fig11(params: dict) -> bool:
    return all(params.get(k) == v for k, v in PAPER_FIG11.items()) and params.get(
        "inertia") is None


def plot_effective(curves: list[tuple[str, object]], out: Path,
                   cite: bool = False) -> list[Path]:
    """mu_g(gamma) and m_e(gamma), mu_e(gamma) for labelled curves; cite: the titles name the
    paper's Figs. 11 and 12 (only when the curves are of the paper's system)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files = []
    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    for label, e in curves:
        ax.plot(e.gamma, e.mu_g, "o-", ms=3, label=label)
    ax.set_xlabel(r"$\gamma$ / g")
    ax.set_ylabel(r"$\mu_g$")
    ax.set_title("global friction coefficient" + (" (Fig. 11)" if cite else ""))
    if len(curves) > 1:
        ax.legend(fontsize="small")
    path = out / "mu_g.png"
    fig.savefig(path, dpi=130, bbox_inches="tight")
    plt.close(fig)
    files.append(path)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11.0, 4.0))
    marked = False
    for label, e in curves:
        for ax, y in ((ax1, e.m_e), (ax2, e.mu_e)):
            line, = ax.plot(e.gamma, y, "-", lw=1, label=label)
            ax.plot(e.gamma[e.exact], y[e.exact], "o", ms=4, color=line.get_color())
            ax.plot(e.gamma[~e.exact], y[~e.exact], "o", ms=6, mfc="none",
                    color=line.get_color())
        marked |= bool((~e.exact).any())
    if marked:  # open markers: chord estimates (every fit window straddles a kink of F_g)
        ax1.plot([], [], "o", mfc="none", color="grey", label="kink: chord, not dF_g/dγ")
    for _, e in curves[:1]:
        ax1.axhline(e.m_g, color="grey", lw=0.8, ls="--", label=r"$m_g$")
    ax1.set_xlabel(r"$\gamma$ / g")
    ax1.set_ylabel(r"$m_e = m_g + \partial F_g/\partial\gamma$")
    ax1.set_title("(a) effective inertia" + (" (Fig. 12)" if cite else ""))
    ax2.set_xlabel(r"$\gamma$ / g")
    ax2.set_ylabel(r"$\mu_e = (F_g - \gamma\,\partial F_g/\partial\gamma) / (m_g g)$")
    ax2.set_title("(b) effective friction coefficient" + (" (Fig. 12)" if cite else ""))
    ax1.legend(fontsize="small")
    if len(curves) > 1:
        ax2.legend(fontsize="small")
    path = out / "effective.png"
    fig.savefig(path, dpi=130, bbox_inches="tight")
    plt.close(fig)
    files.append(path)
    return files
