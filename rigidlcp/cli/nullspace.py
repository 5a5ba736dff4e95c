"""`rigidlcp nullspace` and `rigidlcp verify-formulas` (over rigidlcp.verify.nullspace).

Each command is a small `add_<name>(sub)` that builds its parser and a `cmd_<name>(args)` that
runs it; `register` lists them. Heavy imports happen inside the commands.

* `rigidlcp nullspace`: the null space of the contact matrix (Eqs. 2.15, 3.1, 3.2) for given
  contact states, with a localized basis (Fig. 5) and optionally a drawing of it.
* `rigidlcp verify-formulas`: the paper's Eqs. (3.3)/(3.4) against SVD counts, as a table.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def register(sub) -> None:
    add_nullspace(sub)
    add_verify_formulas(sub)


# -- rigidlcp nullspace --------------------------------------------------------------------------


#: Default friction of `rigidlcp nullspace`: one coefficient everywhere, so that the friction
#: forces of a row sliding as a whole cancel and the rows of Fig. 5(d) stay local.
NULLSPACE_MU = {"mu_pp": 0.3, "mu_plane": 0.3, "mu_wall": 0.3}


def add_nullspace(sub) -> None:
    from rigidlcp.cli.simulate import GivenArray

    p = sub.add_parser(
        "nullspace", help="null space of the contact matrix (Eqs. 2.15, 3.1, 3.2; Fig. 5)",
        description="SVD of the paper's contact matrix M (Eq. 2.15) for a vector of contact "
        "states: dimension of ker M, the contacts that contribute (Eq. 3.2) and a localized "
        "basis (the structures of Fig. 5).",
        epilog="STATES: 'normal' (every contact transmitting and sliding, Eq. 3.3), "
        "'tangential' (every contact transmitting and non-sliding, frictionless contacts "
        "S = 0, Eq. 3.4), or a file: JSON {\"normal\": [\"T\"|\"NT\", ...], \"tangential\": "
        "[\"NS\"|\"+\"|\"-\", ...]} (one entry per contact, in the lattice's order; also "
        "true/false and 0/+1/-1), or .npz with arrays 'normal' and 'tangential'. The --json "
        "output has this form. See docs/verification.md.")
    p.add_argument("--lattice", choices=("rect", "tri"), default="rect", action=GivenArray,
                   help="rectangular or triangular array (default rect)")
    p.add_argument("--lx", type=int, default=4, action=GivenArray,
                   help="disks in the rows touching both walls (default 4)")
    p.add_argument("--ly", type=int, default=3, action=GivenArray,
                   help="number of rows (default 3)")
    p.add_argument("--packing", metavar="FILE", default=None,
                   help="disks from a packing file (.csv/.npz/LAMMPS dump) or a saved run "
                   "(RUN.npz) instead of --lattice/--lx/--ly (docs/packings.md)")
    from rigidlcp.cli.packing_options import add_packing_options

    add_packing_options(p)  # --left, --right, --gap-tol: read as `rigidlcp forceset` reads
    p.add_argument("--states", default="tangential", metavar="normal|tangential|FILE",
                   help="the paper's states of Eq. (3.3) or (3.4) (default tangential), or a "
                   "JSON file of per-contact states (docs/verification.md)")
    for name, default in NULLSPACE_MU.items():
        p.add_argument("--" + name.replace("_", "-"), type=float, default=default,
                       help=f"friction coefficient (default {default}; 0 = frictionless)")
    p.add_argument("--loops", action="store_true",
                   help="also the kinematic loops of the NS contacts (Fig. 5b/c/e reading)")
    p.add_argument("--no-localize", action="store_true",
                   help="skip the localized basis (one LP per contact)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--plot", metavar="OUT.png", help="draw the localized basis on the lattice "
                   "(with --loops also OUT_loops.png)")
    p.add_argument("--force", action="store_true", help="overwrite existing --plot files")
    p.set_defaults(func=cmd_nullspace)


def cmd_nullspace(args: argparse.Namespace) -> int:
    import numpy as np

    from rigidlcp import models
    from rigidlcp.cli.packing_options import refuse_without_packing
    from rigidlcp.cli.simulate import DENSE_ONLY, refuse_array_options, refuse_too_large_for_dense
    from rigidlcp.models.engine.simulate import check_dense_memory
    from rigidlcp.verify.nullspace.contact import (
        null_space,
        paper_states,
        read_states,
        rotation_loops,
    )

    refuse_without_packing(args)
    if args.packing:
        refuse_array_options(args, ("rect", 4, 3))  # nullspace's own defaults
        lattice = packing_lattice(args.packing, args)
        check_dense_memory(lattice.c, f"the dense contact matrix of {args.packing} "
                           f"({lattice.c} contacts)", instead=DENSE_ONLY)
    else:
        refuse_too_large_for_dense(args, "the dense contact matrix and its SVD", DENSE_ONLY)
        lattice = models.make_lattice(args.lattice, args.lx, args.ly)
    system = models.System(lattice, mu_pp=args.mu_pp, mu_plane=args.mu_plane,
                           mu_wall=args.mu_wall)
    if args.plot:  # checked before the SVD: never overwrite a user's file without --force
        from rigidlcp.lcp.io.files import check_new, output_dir

        if args.no_localize:
            raise ValueError("--plot needs the localized basis (drop --no-localize)")
        plot = Path(args.plot)
        if plot.suffix.lower() not in (".png", ".pdf", ".svg"):
            raise ValueError(f"--plot takes a .png, .pdf or .svg file name, got {args.plot!r}")
        targets = [plot] + ([plot.with_name(plot.stem + "_loops" + plot.suffix)]
                            if args.loops else [])
        check_new(targets, force=args.force)
        output_dir(plot.parent, force=True)
    if args.states in ("normal", "tangential"):
        normal, tangential = paper_states(system, args.states)
    elif not Path(args.states).exists():  # a typo of a name reads as a missing file
        raise ValueError(f"--states {args.states!r}: neither 'normal' nor 'tangential' (the "
                         "paper's states), nor an existing states file (.json or .npz)")
    else:
        normal, tangential = read_states(args.states, system.lattice)
    ns = null_space(system, normal, tangential, localize=not args.no_localize)
    loops = rotation_loops(system.lattice, np.asarray(tangential) == 0) if args.loops else None
    if args.plot:
        from rigidlcp.verify.nullspace.plot import plot_loops, plot_null_space

        if ns.localized is None:
            raise ValueError("--plot needs the localized basis (drop --no-localize)")
        ns_path = plot_null_space(ns, args.plot)
        loop_path = None
        if loops is not None and loops.dim:
            stem = ns_path.with_name(ns_path.stem + "_loops" + ns_path.suffix)
            loop_path = plot_loops(system, loops, stem)
    if args.json:
        out = ns.to_dict()
        out["states"] = args.states
        if loops is not None:
            out["loops"] = [{"contacts": list(loop), "coefficients": list(loop.values())}
                            for loop in loops.loops()]
        print(json.dumps(out, indent=1))
    else:
        _print_null_space(ns, args.states, loops)
    if args.plot and not args.json:
        print(f"plot: {ns_path}" + (f", {loop_path}" if loop_path is not None else ""))
    return 0


def packing_lattice(path: str, args: argparse.Namespace | None = None):
    """The geometry of a packing file (read with the --left, --right, --gap-tol of args), or
    of the system of a run saved by `rigidlcp simulate --out` (RUN.npz with its RUN.json: an
    array or a packing)."""
    from rigidlcp.cli.packing_options import read_packing_args

    return read_packing_args(path, args or argparse.Namespace(), runs=True)


def _print_null_space(ns, states: str, loops) -> None:
    from rigidlcp.cli.packing_options import walls_text
    from rigidlcp.cli.simulate import title

    sysm = ns.system
    lat = sysm.lattice
    n_t = int(ns.normal.sum())
    n_ns = int((ns.tangential == 0).sum())
    print(f"{title(lat)}: {lat.p} disks, {lat.c} contacts{walls_text(lat)}; mu_pp = "
          f"{sysm.mu_pp}, mu_plane = {sysm.mu_plane}, mu_wall = {sysm.mu_wall}")
    print(f"states: {states} ({n_t} T, {lat.c - n_t} NT; {n_ns} NS, {lat.c - n_ns} sliding or "
          "frictionless)")
    kept, dropped = ns.gap
    w = ns.singular_values
    print(f"M: {ns.M.shape[0]} x {ns.M.shape[1]}, rank {ns.rank}; dim ker M = {ns.dim}")
    print(f"singular values: max {w[0]:.4g}, smallest kept {_g(kept)}, largest dropped "
          f"{_g(dropped)}; tol = max(shape) eps w_max = {ns.tol:.3g}; basis error bound "
          f"{ns.basis_error:.2g}")
    print(f"contributing contacts (Eq. 3.2): {len(ns.contributing)} of {lat.c}: "
          + " ".join(f"#{a}" for a in ns.contributing))
    if ns.localized is not None:
        print("localized basis (R, S per contact, largest entry 1):")
        for k, x in enumerate(ns.localized.T):
            d = ns.vector_dict(x)
            print(f"  v{k + 1}: {len(d['contacts'])} contacts")
            for label, R, S in zip(d["labels"], d["R"], d["S"]):
                print(f"      {label}: R = {R:+.4f}, S = {S:+.4f}")
    if loops is not None:
        print(f"kinematic loops of the NS contacts (left ker K, no displacement): {loops.dim}")
        for k, loop in enumerate(loops.loops()):
            terms = " ".join(f"{v:+.3g}*#{a}" for a, v in loop.items())
            print(f"  loop {k + 1}: {len(loop)} contacts: {terms}")


def _g(v) -> str:
    return "-" if v is None else f"{v:.3g}"


# -- rigidlcp verify-formulas --------------------------------------------------------------------


def add_verify_formulas(sub) -> None:
    p = sub.add_parser(
        "verify-formulas", help="the paper's Eqs. (3.3)/(3.4) against SVD counts",
        description="Degree of indeterminacy of rectangular and triangular arrays: the "
        "paper's closed forms (Eq. 3.3 normal, Eq. 3.4 tangential), the count from the SVD of "
        "the contact matrix, and the corrected closed forms (docs/verification.md). A paper "
        "value that differs from the SVD count is starred. Exit status 1 if a corrected closed "
        "form disagrees with the SVD.")
    p.add_argument("--lattice", choices=("rect", "tri", "both"), default="both",
                   help="which arrays (default both)")
    p.add_argument("--lx", type=int, nargs=2, default=(2, 12), metavar=("MIN", "MAX"),
                   help="range of Lx (default 2 12)")
    p.add_argument("--ly", type=int, nargs=2, default=(1, 8), metavar=("MIN", "MAX"),
                   help="range of Ly (default 1 8)")
    p.add_argument("--walls", choices=("rough", "frictionless"), default="rough",
                   help="rough: wall contacts NS in the tangential state (Eq. 3.4's "
                   "convention); frictionless: S = 0 at the walls (the paper's simulations); "
                   "default %(default)s")
    p.add_argument("--json", action="store_true", help="the table as JSON")
    p.add_argument("--markdown", action="store_true", help="the table in Markdown")
    p.add_argument("--grid", action="store_true",
                   help="Markdown grids (Lx down, Ly across): SVD count [paper's, if different]")
    p.set_defaults(func=cmd_verify_formulas)


def cmd_verify_formulas(args: argparse.Namespace) -> int:
    from rigidlcp.verify.nullspace.formulas import format_grid, format_table, formula_table, summary

    for name, (lo, hi) in (("--lx", args.lx), ("--ly", args.ly)):
        if lo > hi or lo < 1:
            raise ValueError(f"{name} needs 1 <= MIN <= MAX, got {lo} {hi}")
    if args.lattice in ("tri", "both") and args.lx[0] < 2:
        raise ValueError("triangular arrays need lx >= 2")
    lattices = ("rect", "tri") if args.lattice == "both" else (args.lattice,)
    rows = formula_table(lattices, range(args.lx[0], args.lx[1] + 1),
                         range(args.ly[0], args.ly[1] + 1), walls=args.walls)
    stats = summary(rows)
    if args.json:
        print(json.dumps({"walls": args.walls, "summary": stats, "rows": rows}, indent=1))
    elif args.grid:
        for name in lattices:
            for kind, eq in (("normal", "3.3"), ("tangential", "3.4")):
                print(f"{name}, Eq. ({eq}), {kind}:\n")
                print(format_grid(rows, name, kind))
                print()
    else:
        print(format_table(rows, markdown=args.markdown))
        print()
        for name, s in stats.items():
            print(f"{name}: {s['cases']} cases; paper agrees with the SVD: Eq. 3.3 "
                  f"{s['Nn_paper_agrees']}, Eq. 3.4 {s['Nt_paper_agrees']}; corrected forms "
                  f"agree: {s['Nn_closed_agrees']}, {s['Nt_closed_agrees']}")
    ok = all(s["Nn_closed_agrees"] == s["Nt_closed_agrees"] == s["cases"]
             for s in stats.values())
    return 0 if ok else 1
