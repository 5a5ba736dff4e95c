"""The closed-solution search on each integrator (docs/packings.md, "The closed search"): how a
run ends and its CPU time on the dense event backend, the sparse event backend and the
time-stepper (a script, not a test; it prints a markdown table).

    python benchmarks/closed_backends.py [--h 0.01] [--max-steps 400]

Cases: the V-groove of tests/verify/statics/test_groove.py spinning at mu = 0.5 (the
detachment is forced: proved); the spun 20-disk pile of docs/packings.md (forced: one LP);
the 12-disk pile at rest, mu = 0.5 (deposit(12, 2, radii=(0.8, 1.2), width=6): a closed
solution exists and is followed). Columns: status, events or steps, where the search ran and
where it was followed, its verdict at the stop, CPU seconds (process time) of the run.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.models.engine.sparse import simulate_sparse
from rigidlcp.models.timestepping import moreau_jean


def cases():
    groove = models.System(models.make_packing([[1.0, 1.0], [3.4, 1.0], [2.2, 2.6]],
                                               np.ones(3), m=np.ones(3), left=0.0, right=4.4),
                           mu_pp=0.5, mu_plane=1.0, mu_wall=1.0)
    yield "V-groove, mu 0.5, top disk spinning", groove, models.initial_state(
        groove, omega=np.array([0.0, 0.0, 1.0]))
    spun = models.System(deposit(20, seed=1, radii=(0.8, 1.2), width=8.0), gamma=0.1)
    yield "20-disk pile, random spins", spun, models.initial_state(spun, seed=1)
    rest = models.System(deposit(12, seed=2, radii=(0.8, 1.2), width=6.0), mu_pp=0.5,
                         mu_plane=0.5, mu_wall=0.5, gamma=0.1)
    yield "12-disk pile at rest, mu 0.5", rest, models.initial_state(
        rest, omega=np.zeros(rest.p))


def verdict(run) -> str:
    if run.status != "detachment":
        return "-"
    return "proved" if "proved: no solution" in run.message else (
        "undecided" if "undecided" in run.message else "?")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h", type=float, default=0.01)
    ap.add_argument("--max-steps", type=int, default=400)
    args = ap.parse_args()
    print("| case | integrator | status | events / steps | searched | followed | at the stop "
          "| CPU s |")
    print("|---|---|---|---|---|---|---|---|")
    for name, system, state in cases():
        runs = (("dense events", models.simulate, {}),
                ("sparse events", simulate_sparse, {}),
                (f"time-stepper h = {args.h:g}", moreau_jean,
                 {"h": args.h, "max_steps": args.max_steps}))
        for label, integrate, options in runs:
            t0 = time.process_time()
            run = integrate(system, state, **options)
            cpu = time.process_time() - t0
            n = run.n_events if "events" in label else int(round((run.last.t - state.t)
                                                                 / args.h))
            print(f"| {name} | {label} | {run.status} | {n} | {run.closed['searched']} | "
                  f"{len(run.closed['followed'])} | {verdict(run)} | {cpu:.2f} |", flush=True)


if __name__ == "__main__":
    main()
