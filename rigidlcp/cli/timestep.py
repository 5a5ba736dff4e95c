"""`rigidlcp timestep`: Moreau-Jean time-stepping of an array (rigidlcp.models.timestepping),
printed and saved like `rigidlcp simulate` (the same run format: `rigidlcp plot` reads it)."""

from __future__ import annotations

import json

import numpy as np

from rigidlcp.cli.main import seed
from rigidlcp.cli.simulate import selection_rule


def register(sub) -> None:
    from .simulate import add_system_arguments

    p = sub.add_parser("timestep", help="Moreau-Jean time-stepping of an array to its steady "
                       "state (the second integrator)",
                       description="Moreau-Jean (theta-method) time-stepping: each step a "
                       "velocity-level Signorini-Coulomb LCP solved by the toolkit's solvers and "
                       "checked (docs/integrators.md).")
    add_system_arguments(p)
    g = p.add_argument_group("run")
    g.add_argument("--seed", type=seed, default=1, help="seed of the initial angular velocities")
    g.add_argument("--h", type=float, default=1e-3, help="time step (default %(default)s)")
    g.add_argument("--theta", type=float, default=1.0, help="theta in [0.5, 1]")
    g.add_argument("--method", default="lemke", help="LCP method of a step (default %(default)s)")
    g.add_argument("--selection", type=selection_rule, default="none", metavar="RULE",
                   help="the point followed where a step's solution is not unique: none "
                   "(default: the solver's), face-min-norm, max-sum-R[:CAP], random:SEED")
    g.add_argument("--no-closed-search", dest="closed_search", action="store_false",
                   help="stop at a step whose solution opens a contact without looking for "
                   "one of the same step that keeps every contact closed (default: look, "
                   "and follow it or prove there is none)")
    g.add_argument("--t-max", type=float, default=np.inf, help="stop at this time (> 0; default: "
                   "no limit)")
    g.add_argument("--max-steps", type=int, default=2_000_000,
                   help="stop after this many steps (default 2000000)")
    g.add_argument("--record-every", type=int, default=100,
                   help="also record every N steps (besides state changes; 0: only those; "
                   "default %(default)s)")
    g.add_argument("--out", default=None, help="save the run to OUT (.npz + .json); an "
                   "existing run is not overwritten without --force")
    g.add_argument("--force", action="store_true", help="overwrite an existing --out")
    g.add_argument("--json", action="store_true", help="print the summary as JSON")
    g.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=cmd_timestep)


def cmd_timestep(args) -> int:
    from rigidlcp.lcp.io.files import check_new
    from rigidlcp.models.runio import run_paths, save_run
    from rigidlcp.models.timestepping import StepOptions, moreau_jean

    from .simulate import DENSE_ONLY, refuse_too_large_for_dense, system_from_args

    refuse_too_large_for_dense(args, "the time-stepper's dense step LCP", DENSE_ONLY)
    system = system_from_args(args)
    # a bad --h, --theta, --t-max, ... is refused before the progress bar is drawn
    StepOptions(h=args.h, theta=args.theta, method=args.method, t_max=args.t_max,
                max_steps=args.max_steps, record_every=args.record_every,
                selection=args.selection)
    if args.out:
        check_new(run_paths(args.out), force=args.force)
    bar = None
    if not args.no_progress:  # steps and t on stderr, erased at the end (as simulate's)
        from rigidlcp.models.progress import new_bar

        bar = new_bar(desc="steps", unit="step", mininterval=0.5)

    def progress(run, t: float, omega) -> None:
        bar.update(1)
        if bar.n % 1000 == 0:
            bar.set_postfix_str(f"t={t:.4g}", refresh=False)

    try:
        run = moreau_jean(system, seed=args.seed, h=args.h, theta=args.theta,
                          method=args.method, t_max=args.t_max, max_steps=args.max_steps,
                          record_every=args.record_every, selection=args.selection,
                          closed_search=args.closed_search,
                          progress=progress if bar is not None else None)
    finally:
        if bar is not None:
            bar.close()
    summary = run.summary()
    if run.closed is not None:
        from .simulate import closed_summary

        summary["closed_search"] = closed_summary(run)
    if args.out:
        summary["saved"] = str(save_run(run, args.out))
    if args.json:
        print(json.dumps(summary, indent=2, default=float))
    else:
        from .packing_options import walls_text
        from .simulate import title

        lat = system.lattice  # what was run, as simulate's first line says it
        print(f"{title(lat)}: {lat.p} disks, {lat.c} contacts{walls_text(lat)}; mu_pp = "
              f"{system.mu_pp}, mu_plane = {system.mu_plane}, mu_wall = {system.mu_wall}, "
              f"gamma = {system.gamma} g, V0 = {system.V0}")
        width = max(len(k) for k in summary)
        for k, v in summary.items():
            if k == "closed_search":
                from .simulate import closed_text

                v = closed_text(v, "step")
            elif isinstance(v, float):
                v = f"{v:.6g}"
            elif isinstance(v, (list, tuple)) and all(isinstance(x, float) for x in v):
                v = "[" + ", ".join(f"{x:.6g}" for x in v) + "]"
            print(f"  {k:<{width}}  {v}")
    return 0 if run.status in ("steady", "time_limit", "event_limit") else 1
