"""`rigidlcp pack`: a packing deposited under gravity (models.deposition), written as CSV/.npz.

The interface is fixed (issue 22): `rigidlcp pack --n N --seed S [--radii MIN:MAX] --out FILE`;
the CSV's first line is its header x,y,r,m,I,box_left,box_right (m = r^2, I = m r^2 / 2; the
walls repeated on every line: models.packing_io).
"""

from __future__ import annotations

import argparse
import json

from rigidlcp.cli.main import seed


def radii(text: str) -> tuple[float, float]:
    """argparse type of --radii: MIN:MAX (or one value: monodisperse)."""
    parts = text.split(":")
    try:
        a, b = (float(parts[0]), float(parts[-1])) if len(parts) <= 2 else (None, None)
    except ValueError:
        a = b = None
    if a is None or not (0 < a <= b < float("inf")):
        raise argparse.ArgumentTypeError(f"expected MIN:MAX with 0 < MIN <= MAX, got {text!r}")
    return a, b


def register(sub) -> None:
    p = sub.add_parser(
        "pack", help="deposit disks under gravity in the box (a packing file)",
        description="Sequential deposition under gravity: each disk dropped at a random "
        "abscissa rolls down the pile to a resting position on two supports (disk, wall or "
        "plane), so its contacts are exact. Writes x, y, r, m, I (m = r^2, I = m r^2 / 2) as "
        "CSV (or .npz by suffix), the walls in columns box_left, box_right (header first).")
    p.add_argument("--n", type=int, default=None,
                   help="number of disks to deposit (required unless --array)")
    p.add_argument("--seed", type=seed, default=0,
                   help="seed of the radii and drop points (default 0)")
    p.add_argument("--radii", type=radii, default=(1.0, 1.0), metavar="MIN:MAX",
                   help="radii uniform in [MIN, MAX] (default 1:1, monodisperse; within "
                   "[1e-76, 1e76], where the inertia r^4 / 2 is a normal float)")
    p.add_argument("--width", type=float, default=None,
                   help="box width (default 2 mean(r) round(sqrt(N)))")
    p.add_argument("--vacancies", type=float, default=0.0, metavar="F",
                   help="remove a fraction F of the deposited disks at random (the rest keep "
                   "their contacts; rattlers and floating clusters are reported)")
    g = p.add_argument_group("a regular array instead of a deposit (models.disorder)")
    g.add_argument("--array", choices=("rect", "tri"), default=None,
                   help="the paper's array (--lx, --ly) instead of a deposition")
    g.add_argument("--lx", type=int, default=10, help="disks in the rows touching both walls")
    g.add_argument("--ly", type=int, default=4, help="number of rows")
    g.add_argument("--size-disorder", type=float, default=0.0, metavar="SPREAD",
                   help="radii uniform in [1 - SPREAD, 1 + SPREAD] (0 <= SPREAD < 0.5; seeded "
                   "by --seed), the array rebuilt with exact contacts (docs/packings.md)")
    p.add_argument("--out", required=True, metavar="FILE", help="output .csv or .npz")
    p.add_argument("--force", action="store_true", help="overwrite FILE")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=cmd_pack)


def cmd_pack(args: argparse.Namespace) -> int:
    from rigidlcp.lcp.io.files import check_new
    from rigidlcp.models.deposition import deposit, with_vacancies
    from rigidlcp.models.packing import report
    from rigidlcp.models.packing_io import write_packing

    if args.array is None and args.n is None:
        raise ValueError("--n N (a deposition) or --array rect|tri (an array) is required")
    if args.array is not None and args.n is not None:
        raise ValueError("--n deposits disks and --array builds an array: give one of them")
    if args.array is None and args.size_disorder:
        raise ValueError("--size-disorder applies to --array (a deposition's radii: --radii)")
    if args.n is not None and args.n < 1:
        raise ValueError(f"--n must be >= 1, got {args.n}")
    if not 0 <= args.vacancies < 1:
        raise ValueError(f"--vacancies must be in [0, 1), got {args.vacancies}")
    if not str(args.out).endswith((".csv", ".npz")):
        raise ValueError(f"--out must end in .csv or .npz, got {args.out!r}")
    check_new([args.out], force=args.force)  # before the work, so nothing is lost
    if args.array is not None:
        return _array(args)
    bar = None
    if not args.no_progress and args.n >= 2000:
        from rigidlcp.models.progress import new_bar

        bar = new_bar(total=args.n, desc="deposition", unit="disk")
    lat = deposit(args.n, seed=args.seed, radii=args.radii, width=args.width,
                  progress=(lambda k, n: bar.update(1)) if bar else None)
    if bar:
        bar.close()
    if args.vacancies:
        lat = with_vacancies(lat, args.vacancies, seed=args.seed)
    write_packing(args.out, lat, force=args.force)
    rep = report(lat)
    summary = {"out": str(args.out), "p": lat.p, "c": lat.c, "width": lat.width,
               "radii": list(args.radii), "seed": args.seed, **rep.to_dict()}
    if args.json:
        summary.pop("floating_clusters")
        print(json.dumps(summary))
    else:
        print(f"{lat.p} disks (radii {args.radii[0]:g}:{args.radii[1]:g}, seed {args.seed}) in "
              f"a box of width {lat.width:g}: {lat.c} contacts, {rep.text()} -> {args.out}")
    return 0


def _array(args: argparse.Namespace) -> int:
    """`pack --array`: a regular array, with size disorder (models.disorder) and vacancies."""
    from rigidlcp.models.deposition import with_vacancies
    from rigidlcp.models.disorder import with_size_disorder
    from rigidlcp.models.lattice import make_lattice
    from rigidlcp.models.packing import report
    from rigidlcp.models.packing_io import write_packing

    lat = make_lattice(args.array, args.lx, args.ly)
    if args.size_disorder:
        lat = with_size_disorder(lat, args.size_disorder, seed=args.seed)
    if args.vacancies:
        lat = with_vacancies(lat, args.vacancies, seed=args.seed)
    write_packing(args.out, lat, force=args.force)
    rep = report(lat)
    what = f"{args.array} {args.lx}x{args.ly} array, size disorder {args.size_disorder:g}"
    if args.json:
        summary = {"out": str(args.out), "p": lat.p, "c": lat.c, "width": lat.width,
                   "array": args.array, "lx": args.lx, "ly": args.ly,
                   "size_disorder": args.size_disorder, "seed": args.seed, **rep.to_dict()}
        summary.pop("floating_clusters")
        print(json.dumps(summary))
    else:
        print(f"{lat.p} disks ({what}, seed {args.seed}) in a box of width {lat.width:g}: "
              f"{lat.c} contacts, {rep.text()} -> {args.out}")
    return 0
