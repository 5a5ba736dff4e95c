"""`rigidlcp compare-integrators`: event-driven against Moreau-Jean time-stepping on one system
(rigidlcp.verify.integrators), for h halving over at least three values."""

from __future__ import annotations

import math
import sys
import time

from rigidlcp.cli.main import seed

#: The default ensemble (rigidlcp.verify.ensemble.RULES, repeated here so that registering the
#: command imports nothing heavy).
ENSEMBLE_RULES = ("face-min-norm", "max-sum-R", "random:1", "random:2", "none")


def register(sub) -> None:
    from .simulate import add_system_arguments

    p = sub.add_parser(
        "compare-integrators",
        help="event-driven vs Moreau-Jean time-stepping on one system, h halving",
        description="Runs the exact event-driven evolution and Moreau-Jean time-stepping from "
        "the same initial angular velocities, for h, h/2, h/4, ...: steady mu_g, contact "
        "states, first-row modes, max |delta alpha|, the angular velocities at a common time, "
        "each steady state checked against the other integrator's exact laws, and the observed "
        "orders of convergence (docs/integrators.md).")
    add_system_arguments(p)
    g = p.add_argument_group("comparison")
    g.add_argument("--seed", type=seed, default=1, help="seed of the initial angular velocities")
    g.add_argument("--h", type=float, default=2e-3, help="largest time step (default %(default)s)")
    g.add_argument("--levels", type=int, default=3, help="number of step sizes (h halving; "
                   "default %(default)s)")
    g.add_argument("--theta", type=float, default=1.0, help="theta of the Moreau-Jean scheme")
    g.add_argument("--t-max", type=float, default=40.0, help="bound on both runs' time (default "
                   "%(default)s)")
    g.add_argument("--T", type=float, default=None,
                   help="time at which the angular velocities are compared (default: half "
                   "the event-driven run's last event time)")
    g.add_argument("--phases", type=int, default=1,
                   help="average the sup error over N grids shifted by j h / N (shows the "
                   "order cleanly; N times the cost)")
    g.add_argument("--selection", default="face-min-norm", metavar="RULE",
                   help="the event engine's selection rule (face-min-norm, max-sum-R[:CAP], "
                   "random:SEED, global, none; default face-min-norm)")
    g.add_argument("--step-selection", default="none", metavar="RULE",
                   help="the time-stepper's selection rule (default none: the solver's point)")
    g.add_argument("--no-progress", action="store_true",
                   help="no line on stderr as each step size is done")
    e = p.add_argument_group("ensemble over selection rules (instead of the h halving)")
    e.add_argument("--ensemble", nargs="?", const=",".join(ENSEMBLE_RULES), default=None,
                   metavar="RULES", help="run the event engine once per rule from the same start "
                   "and print the spread of the valid steady states reached (mu_g, contact "
                   f"states); default rules {','.join(ENSEMBLE_RULES)}")
    e.add_argument("--step-rules", default=None, metavar="RULES",
                   help="with --ensemble: also the time-stepper (step --h) over these rules")
    p.set_defaults(func=cmd_compare_integrators)


def cmd_compare_integrators(args) -> int:
    from rigidlcp.models.selection import Selection
    from rigidlcp.models.timestepping import StepOptions
    from rigidlcp.verify.integrators import compare_integrators, format_comparison

    from .simulate import DENSE_ONLY, refuse_too_large_for_dense, system_from_args

    refuse_too_large_for_dense(args, "the dense event and step LCPs", DENSE_ONLY)
    system = system_from_args(args)
    if args.levels < 3:
        raise ValueError(f"--levels must be >= 3 (an order needs three step sizes), "
                         f"got {args.levels}")
    if not (math.isfinite(args.t_max) and args.t_max > 0):
        raise ValueError(f"--t-max must be a finite number > 0, got {args.t_max}")
    # bad h / theta / rules: one line, exit status 2
    StepOptions(h=args.h, theta=args.theta, selection=args.step_selection)
    Selection.parse(args.selection)
    if args.ensemble is not None:
        return _ensemble(system, args)
    if args.step_rules is not None:
        raise ValueError("--step-rules goes with --ensemble")
    hs = tuple(args.h / 2**k for k in range(args.levels))
    t0 = time.perf_counter()

    def progress(row) -> None:  # each level takes twice the last: say where it is
        print(f"compare-integrators: h = {row.h:g} done ({hs.index(row.h) + 1} of {len(hs)}, "
              f"{time.perf_counter() - t0:.0f} s)", file=sys.stderr, flush=True)

    cmp = compare_integrators(system, seed=args.seed, hs=hs, T=args.T, t_max=args.t_max,
                              event_options={"selection": args.selection},
                              step_options={"theta": args.theta,
                                            "selection": args.step_selection},
                              phases=args.phases,
                              progress=None if args.no_progress else progress)
    print(format_comparison(cmp))
    bad = [r.h for r in cmp.rows if r.run.status not in ("steady", "time_limit")]
    return 1 if bad else 0


def _ensemble(system, args) -> int:
    from rigidlcp.models.selection import Selection
    from rigidlcp.verify.ensemble import format_ensemble, selection_ensemble

    rules = tuple(r.strip() for r in args.ensemble.split(",") if r.strip())
    steps = (tuple(r.strip() for r in args.step_rules.split(",") if r.strip())
             if args.step_rules else None)
    if not rules:
        raise ValueError("--ensemble needs at least one rule")
    for r in rules + (steps or ()):
        Selection.parse(r)  # every rule checked before anything runs
    ens = selection_ensemble(system, seed=args.seed, rules=rules,
                             h=args.h if steps else None, t_max=args.t_max, step_rules=steps)
    print(format_ensemble(ens))
    return 0
