"""`rigidlcp compare-integrators`: event-driven against Moreau-Jean time-stepping on one system
(rigidlcp.verify.integrators), for h halving over at least three values."""

from __future__ import annotations

import math

from rigidlcp.cli.main import seed


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
    g.add_argument("--h", type=float, default=2e-3, help="largest time step")
    g.add_argument("--levels", type=int, default=3, help="number of step sizes (h halving)")
    g.add_argument("--theta", type=float, default=1.0, help="theta of the Moreau-Jean scheme")
    g.add_argument("--t-max", type=float, default=40.0, help="bound on both runs' time")
    g.add_argument("--T", type=float, default=None,
                   help="time at which the angular velocities are compared (default: half "
                   "the event-driven run's last event time)")
    g.add_argument("--phases", type=int, default=1,
                   help="average the sup error over N grids shifted by j h / N (shows the "
                   "order cleanly; N times the cost)")
    p.set_defaults(func=cmd_compare_integrators)


def cmd_compare_integrators(args) -> int:
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
    StepOptions(h=args.h, theta=args.theta)  # bad h / theta: one line, exit status 2
    hs = tuple(args.h / 2**k for k in range(args.levels))
    cmp = compare_integrators(system, seed=args.seed, hs=hs, T=args.T, t_max=args.t_max,
                              step_options={"theta": args.theta}, phases=args.phases)
    print(format_comparison(cmp))
    bad = [r.h for r in cmp.rows if r.run.status not in ("steady", "time_limit")]
    return 1 if bad else 0
