"""`rigidlcp forces`: several admissible normal-force networks for one state (Fig. 4, Sec. III C).

The state is the paper's Fig. 4 kind: random angular velocities (so every frictional contact
slides, S = -sgn(v_t) mu R, Eq. 2.10), the same for every network; only the normal forces (and
with them the normal states T/NT) differ. The admissible forces are the polyhedron of
verify.forces.particular.state_polyhedron for the normal states of the solver's solution (T where
a_n = 0). The networks drawn: the solver's solution, the minimum-norm one, the paper's choice
(most NT contacts, MILP), and vertices minimizing random positive weightings of R. Each is
checked to be a solution of the event's LCP (verify.certify).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from rigidlcp.cli.main import seed

#: The array of Fig. 4, forces' default (simulate's is ARRAY_DEFAULTS, rect 10 x 4).
FIG4 = ("tri", 5, 4)


def register(sub) -> None:
    p = sub.add_parser(
        "forces", help="admissible normal-force networks of one state (Fig. 4, Sec. III C)",
        description="Draw several different admissible normal-force networks for one state of "
        "the array, as the paper's Fig. 4 does: every frictional contact sliding (random "
        "angular velocities, the same for all networks), normal states varying. Segment "
        "widths are proportional to R, on a scale common to all panels. Prints the force "
        "ranges over the admissible set (linear programs), including the global friction F_g.")
    from rigidlcp.cli.simulate import add_system_arguments

    add_system_arguments(p)  # the system options of `rigidlcp simulate` (and its friction)
    p.set_defaults(lattice=FIG4[0], lx=FIG4[1], ly=FIG4[2], gamma=0.0)  # Fig. 4
    p.add_argument("--seed", type=seed, default=0,
                   help="seed of the angular velocities (default 0)")
    p.add_argument("--omega-scale", type=float, default=1.0,
                   help="angular velocities uniform in [-s, s]")
    p.add_argument("--networks", type=int, default=4, help="how many networks (>= 1; "
                   "default %(default)s)")
    p.add_argument("--method", default="lemke", help="LCP method for the solver's "
                   "solution (default %(default)s)")
    p.add_argument("--time-limit", type=float, default=10.0,
                   help="seconds for the paper's-choice MILP (default %(default)s)")
    p.add_argument("--out", required=True, metavar="DIR", help="directory for the PNGs")
    p.add_argument("--force", action="store_true",
                   help="overwrite forces.json / network PNGs already in --out")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=cmd_forces)


class _Stages:
    """Progress on stderr (models.progress.new_bar, erased at the end): one step per stage of
    the command, named while it runs (the paper's-choice MILP alone may take --time-limit s)."""

    def __init__(self, names: list[str], show: bool):
        self.names, self.k, self.bar = names, 0, None
        if show:
            from rigidlcp.models.progress import new_bar

            self.bar = new_bar(total=len(names), desc=names[0], unit="stage", mininterval=0,
                               miniters=1)  # every stage shown, however short

    def done(self) -> None:
        """The current stage is over: count it and name the next one."""
        self.k += 1
        if self.bar is not None:
            if self.k < len(self.names):
                self.bar.set_description_str(self.names[self.k], refresh=False)
            self.bar.update(1)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


def cmd_forces(args: argparse.Namespace) -> int:
    from rigidlcp import lcp, models
    from rigidlcp.cli.simulate import DENSE_ONLY, refuse_too_large_for_dense, system_from_args
    from rigidlcp.lcp.io.files import output_dir

    if args.networks < 1:
        raise ValueError(f"--networks must be >= 1, got {args.networks}")
    if not args.time_limit > 0:
        raise ValueError(f"--time-limit must be > 0, got {args.time_limit}")
    refuse_too_large_for_dense(args, "the dense event LCP and force polyhedra", DENSE_ONLY)
    system = system_from_args(args, FIG4)  # its own array defaults, beside --packing
    lcp.get_method(args.method)
    names = ["forces.json", "networks.png"] + [f"network_{k + 1}.png"
                                              for k in range(args.networks)]
    state = models.initial_state(system, seed=args.seed, omega_scale=args.omega_scale)
    out = output_dir(args.out, force=args.force, names=names)  # after every input is checked
    stages = _Stages(["event LCP", "force ranges"]
                     + (["minimum-norm network"] if args.networks >= 2 else [])
                     + ([f"paper's choice (MILP, up to {args.time_limit:g} s)"]
                        if args.networks >= 3 else [])
                     + ["other networks", "certify networks", "figures"],
                     show=not args.no_progress)
    try:
        return _forces(args, system, state, out, stages)
    finally:
        stages.close()


def _forces(args: argparse.Namespace, system, state, out: Path, stages: _Stages) -> int:
    from rigidlcp import lcp, models
    from rigidlcp.lcp.io.files import atomic_write_text
    from rigidlcp.models.event import acceleration_tol
    from rigidlcp.verify.certificates.certify import certify
    from rigidlcp.verify.forces.particular import (
        EmptyPolyhedron,
        event_z,
        force_ranges,
        global_friction_vector,
        min_norm_solution,
        paper_solution,
        random_vertex,
        state_polyhedron,
    )

    ep = models.event_problem(system, state)
    sol = lcp.solve(ep.lcp, method=args.method)
    if sol.status != "solved":
        raise ValueError(f"the event LCP was not solved by {args.method!r}: {sol.status} "
                         f"({sol.message})")
    stages.done()
    es = ep.unpack(sol.z)
    tol_a = acceleration_tol(system)
    normal = es.a_n <= tol_a
    poly = state_polyhedron(system, normal, es.s)
    gvec = global_friction_vector(system)
    try:
        ranges = force_ranges(poly, {"F_g": gvec})
    except EmptyPolyhedron as exc:  # cannot happen: the solver's solution lies in it
        raise ValueError(str(exc)) from None
    stages.done()
    c, p = system.c, system.p
    x_solver = ep.forces(sol.z)
    cands: list[tuple[str, np.ndarray]] = [(f"solver ({args.method})", x_solver)]
    if args.networks >= 2:
        cands.append(("minimum norm", min_norm_solution(poly).x))
        stages.done()
    if args.networks >= 3:
        pa = paper_solution(poly, time_limit=args.time_limit, ranges=ranges)
        cands.append(("paper's choice (most NT)", pa.x))
        stages.done()
    fscale = poly.scale
    networks: list[tuple[str, np.ndarray]] = []
    seed = 0
    while len(networks) < args.networks:
        if cands:
            name, x = cands.pop(0)
        else:
            if seed >= 20 * args.networks:
                break
            name, x = f"random vertex (seed {seed})", random_vertex(poly, seed).x
            seed += 1
        if all(np.max(np.abs(x[:c] - y[:c])) > 1e-6 * fscale for _, y in networks):
            networks.append((name, x))
    stages.done()
    rows = []
    for name, x in networks:
        z = event_z(ep, x)
        cert = certify(ep, z, uniqueness="none")
        nu_dot = ep.dyn.accelerations(x)
        R = x[:c]
        rows.append({
            "name": name, "T": int(np.sum(R > 1e-9 * fscale)),
            "NT": int(np.sum(R <= 1e-9 * fscale)), "R_max": float(R.max()),
            "R_norm": float(np.linalg.norm(R)), "F_g": float(gvec @ x),
            "omega_dot": nu_dot[2 * p:].tolist(), "accepted": cert.accepted,
            "scaled_residual": cert.scaled_residual, "R": R.tolist(), "S": x[c:].tolist(),
        })
    stages.done()
    paths = _draw(system, networks, out, args)
    stages.done()
    stages.close()  # before the summary is printed
    indet = ranges.indeterminate(1e-6 * fscale)
    summary = {
        "system": system.describe(), "seed": args.seed, "contacts": c,
        "candidates": int(ep.k), "sliding": int(np.sum((es.s != 0) & (system.mu > 0))),
        "T_states": int(normal.sum()), "NT_states": int((~normal).sum()),
        "indeterminate_R": int(np.sum(indet < c)), "indeterminate_S": int(np.sum(indet >= c)),
        "R_range": {"lo": ranges.lo[:c].tolist(), "hi": ranges.hi[:c].tolist()},
        "F_g_range": list(ranges.observables["F_g"]),
        "networks": rows, "png": [str(q) for q in paths],
    }
    opening = np.flatnonzero(~normal)
    if opening.size:  # a_n > 0: contacts open, particles would move (not the paper's model)
        from rigidlcp.models.observables import EXCLUDED

        summary.update(paper_regime=False, regime_note=(
            f"{opening.size} contact(s) open (a_n > 0 at "
            + ", ".join(f"#{a}" for a in opening) + "): " + EXCLUDED["detachment"]))
        print(f"warning: detachment regime: {summary['regime_note']}", file=sys.stderr)
    else:
        summary["paper_regime"] = True
    if len(networks) < args.networks:
        summary["note"] = (f"only {len(networks)} distinct networks found (the admissible set "
                           f"has few vertices); {args.networks} were asked for")
    atomic_write_text(out / "forces.json", json.dumps(summary, indent=1, default=float) + "\n")
    if args.json:
        print(json.dumps(summary, indent=1, default=float))
    else:
        _print(system, summary)
    return 0 if all(r["accepted"] for r in rows) else 1


def _print(system, s: dict) -> None:
    lat = system.lattice
    print(f"{lat.title() if lat.regular else 'packing'}: {lat.p} disks, {lat.c} contacts; "
          f"mu_pp = {system.mu_pp}, mu_plane = {system.mu_plane}, mu_wall = {system.mu_wall}, "
          f"gamma = {system.gamma}; angular velocities from seed {s['seed']}")
    print(f"state: {s['sliding']} sliding contacts, {s['candidates']} non-sliding candidates; "
          f"normal states of the solver's solution: {s['T_states']} T, {s['NT_states']} NT")
    lo, hi = s["F_g_range"]
    print(f"admissible set: {s['indeterminate_R']} normal and {s['indeterminate_S']} friction "
          f"forces indeterminate; F_g in [{lo:.4g}, {hi:.4g}]")
    print(f"{'network':<28} {'T':>3} {'NT':>3} {'max R':>8} {'|R|':>8} {'F_g':>8} "
          f"{'max|dw/dt|':>10}  LCP")
    for r in s["networks"]:
        ok = "ok" if r["accepted"] else f"REJECTED ({r['scaled_residual']:.2g})"
        print(f"{r['name']:<28} {r['T']:>3} {r['NT']:>3} {r['R_max']:>8.4g} "
              f"{r['R_norm']:>8.4g} {r['F_g']:>8.4g} {max(map(abs, r['omega_dot'])):>10.4g}  {ok}")
    if "note" in s:
        print("note: " + s["note"])
    print("figures: " + ", ".join(s["png"]))


def _draw(system, networks: list[tuple[str, np.ndarray]], out: Path, args) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    from rigidlcp.models.plot import contact_points, draw_lattice

    c = system.c
    a, b = contact_points(system)
    segs = np.stack([a, b], axis=1)
    rmax = max(max(float(x[:c].max()) for _, x in networks), 1e-300)
    lat = system.lattice
    w, h = 0.55 * lat.lx + 1.0, 0.55 * lat.ly * (0.87 if lat.name == "tri" else 1.0) + 1.2

    def panel(ax, name: str, x: np.ndarray) -> None:
        draw_lattice(ax, system)
        ax.add_collection(LineCollection(segs, colors="0.85", linewidths=0.5))
        R = x[:c]
        on = R > 1e-9 * rmax
        if np.any(on):
            ax.add_collection(LineCollection(segs[on], colors="k",
                                             linewidths=np.maximum(7.3 * R[on] / rmax, 0.3)))
        ax.set_title(f"{name}\n{int(on.sum())} T, {int((~on).sum())} NT", fontsize="small")

    paths = []
    for k, (name, x) in enumerate(networks):
        fig, ax = plt.subplots(figsize=(w, h))
        panel(ax, name, x)
        from rigidlcp.models.plot import force_key

        force_key(ax, rmax, 7.3)
        path = out / f"network_{k + 1}.png"
        fig.savefig(path, dpi=120, bbox_inches="tight")
        plt.close(fig)
        paths.append(path)
    ncol = min(len(networks), 2)
    nrow = -(-len(networks) // ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(w * ncol, h * nrow), squeeze=False)
    for ax in axes.flat[len(networks):]:
        ax.axis("off")
    for ax, (name, x) in zip(axes.flat, networks):
        panel(ax, name, x)
    fig.suptitle(f"{lat.title()}, seed {args.seed}: admissible normal forces "
                 "(width ~ R, common scale)", fontsize="small")
    from rigidlcp.models.plot import force_key

    force_key(axes.flat[len(networks) - 1], rmax, 7.3)
    path = out / "networks.png"
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    paths.append(path)
    return paths
