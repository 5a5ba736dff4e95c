"""`rigidlcp forceset FILE`: whether a packing can rest under gravity, and its admissible forces
(verify.statics). The interface is fixed (issue 22): `rigidlcp forceset FILE.csv [--mu-pp A
--mu-plane B --mu-wall C] --json` prints one JSON object with "exists", "dimension", "box"
and "contacts" (i, j, R: [lo, hi], S: [lo, hi]; j = -1 left wall, -2 right wall, -3 plane;
null for an unbounded end)."""

from __future__ import annotations

import argparse
import json


def register(sub) -> None:
    from rigidlcp.models.system import DEFAULT_MU

    p = sub.add_parser(
        "forceset", help="admissible contact forces of a packing at rest (existence, "
        "dimension, ranges)",
        description="The set of contact forces that hold a packing at rest under gravity "
        "with Signorini and Coulomb's laws: whether it is empty (a checked equilibrium, or a "
        "checked Farkas certificate), its dimension (of its affine hull), the range of every "
        "R and S (linear programs, HiGHS), the contacts that can slide against 2M - 3N.")
    p.add_argument("file", help="packing file: .csv / .npz (x, y, r [, m, I]) or LAMMPS dump")
    for name in ("mu_pp", "mu_plane", "mu_wall"):
        p.add_argument("--" + name.replace("_", "-"), type=float, default=DEFAULT_MU[name],
                       help=f"friction coefficient (default {DEFAULT_MU[name]})")
    p.add_argument("--left", default=None, help="left wall abscissa, or 'none' (default: the "
                   "file's '# box:', else the tight box)")
    p.add_argument("--right", default=None, help="right wall abscissa, or 'none'")
    p.add_argument("--gap-tol", type=float, default=None,
                   help="relative gap tolerance of contact detection (default 1e-9)")
    p.add_argument("--no-ranges", action="store_true",
                   help="existence and dimension only (no range LPs)")
    p.add_argument("--samples", type=int, default=0, metavar="N",
                   help="also draw N uniform samples of the admissible forces (force-network "
                   "ensemble; hopsy if installed, else hit-and-run) and write samples.npz and "
                   "pf.png (P(f), f = R/<R>) into --out")
    p.add_argument("--cap", type=float, default=None, help="bound sum R <= CAP (needed "
                   "to sample an unbounded set of forces, e.g. walls that can pinch the pile)")
    p.add_argument("--seed", type=int, default=0, help="seed of the sampler (default 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", metavar="DIR", help="write forceset.json and forceset.png here")
    p.add_argument("--force", action="store_true", help="overwrite files in --out")
    p.add_argument("--no-progress", action="store_true")
    p.set_defaults(func=cmd_forceset)


def _wall(text: str | None):
    if text is None or text == "none":
        return text
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"a wall must be a number or 'none', got {text!r}") from None


def cmd_forceset(args: argparse.Namespace) -> int:
    import sys

    from rigidlcp.lcp.io.files import atomic_write_text, output_dir
    from rigidlcp.models.packing import GAP_TOL, report
    from rigidlcp.models.packing_io import read_packing
    from rigidlcp.models.system import System
    from rigidlcp.verify.statics.forceset import analyse

    lat = read_packing(args.file, left=_wall(args.left), right=_wall(args.right),
                       gap_tol=GAP_TOL if args.gap_tol is None else args.gap_tol)
    system = System(lat, mu_pp=args.mu_pp, mu_plane=args.mu_plane, mu_wall=args.mu_wall)
    if args.samples < 0:
        raise ValueError(f"--samples must be >= 0, got {args.samples}")
    if args.samples and not args.out:
        raise ValueError("--samples writes samples.npz and pf.png: give --out DIR")
    names = ["forceset.json", "forceset.png"] + (["samples.npz", "pf.png"] if args.samples
                                                  else [])
    out = output_dir(args.out, force=args.force, names=names) if args.out else None
    bar = None
    if not args.no_progress and not args.no_ranges and lat.c >= 200:
        from rigidlcp.models.progress import new_bar

        bar = new_bar(desc="force ranges", unit="LP")

    def progress(done: int, total: int, stage: str) -> None:
        bar.total = total
        bar.n = done
        bar.refresh()

    fs = analyse(system, ranges=not args.no_ranges, progress=progress if bar is not None else None)
    if bar is not None:
        bar.close()
    ens = None
    if args.samples and fs.exists:  # before any file is written: a refusal leaves nothing
        from rigidlcp.verify.statics.ensemble import sample

        ens = sample(fs, n=args.samples, seed=args.seed, cap=args.cap)
    result = fs.to_dict() if not args.no_ranges or not fs.exists else {
        k: v for k, v in fs.to_dict().items() if k in ("exists", "dimension", "box", "p", "c")}
    result["packing"] = report(lat).to_dict()
    text = json.dumps(result, allow_nan=False)
    if out is not None:
        atomic_write_text(out / "forceset.json", json.dumps(result, indent=1) + "\n")
        if fs.exists and not args.no_ranges:
            from rigidlcp.verify.statics.plot import plot_forceset

            plot_forceset(fs, out / "forceset.png")
    if ens is not None:
        result["ensemble"] = _write_ensemble(ens, args, out)
        text = json.dumps(result, allow_nan=False)
        atomic_write_text(out / "forceset.json", json.dumps(result, indent=1) + "\n")
    if args.json:
        print(text)
        return 0
    print(f"{lat.title()}: {lat.c} contacts ({report(lat).text()}); mu_pp = {args.mu_pp:g}, "
          f"mu_plane = {args.mu_plane:g}, mu_wall = {args.mu_wall:g}", file=sys.stdout)
    if fs.exists is None:
        print(f"existence undecided: {fs.undecided}")
        return 0
    if not fs.exists:
        print("no equilibrium: Farkas certificate checked " + (
            "in exact rational arithmetic" if fs.exact else
            f"(no admissible forces with sum R < {fs.radius:.3g})"))
        return 0
    print(f"equilibrium exists (checked: balance residual {fs.residuals[0]:.2e}, laws "
          f"{fs.residuals[1]:.2e}); dimension of the admissible set: {fs.dimension}"
          + (" (unique forces)" if fs.dimension == 0 else ""))
    if not args.no_ranges:
        lo, hi = fs.diameter()
        print(f"{int(fs.sliding.sum())} contacts can slide (2M - 3N = {fs.sliding_bound}); "
              f"diameter in [{lo:.4g}, {hi:.4g}]; {fs.lps} LPs")
    if "ensemble" in result:
        e = result["ensemble"]
        print(f"{e['samples']} uniform samples ({e['sampler']}), each checked: largest "
              f"residuals {e['residuals'][0]:.2e} (balance), {e['residuals'][1]:.2e} (laws); "
              f"force fluctuation {e['fluctuation']:.4g} <R>; samples.npz, pf.png")
    return 0


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
