"""Staged uniqueness certificates over whole runs (issue 17): verdicts and seconds per event.

    python benchmarks/certify_runs.py [--quick] [--enumerate] [--defaults [K]]

Simulates the runs of the paper's figures (Fig. 9: rect 10x4, gamma 0.16 g, seed 1; Fig. 10:
rect 10x2, gamma 0.3 g; Fig. 11: rect 10x1, mu 0.05/0.1, gamma 0.1 g; Fig. 13: tri 10x3 at
constant velocity), certifies every event with verify.certificates.certify_run (default
settings, one process) and prints one table row per run: events, pairs, the verdict counts for
accelerations / forces / states, the deciding stages, median and max seconds per event.
`--enumerate`: on small runs (events with n <= 20), every "unique" verdict is compared with
lcp.enumerate_solutions (slow: 2^n bases). `--defaults K`: `verify.certify(event, solution)`
at its defaults (uniqueness="auto") on K events of Fig. 9's run spread evenly over it (the
first and the last included): one row per event with its verdicts and seconds, then the median,
the max and the number of "unknown" verdicts (issue 21.5: none, median < 1 s, max < 30 s).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from rigidlcp import lcp, models, verify
from rigidlcp.verify.certificates.run import certify_run
from rigidlcp.verify.certificates.stages import UNIQUE, certify_stages, observables_of
from rigidlcp.verify.forces.polyhedra import event_z

RUNS = {  # name: (lattice, lx, ly, mu_pp, mu_plane, mu_wall, gamma, V0, seed)
    "fig9 rect 10x4": ("rect", 10, 4, 0.1, 0.2, 0.0, 0.16, 0.0, 1),
    "fig10 rect 10x2": ("rect", 10, 2, 0.1, 0.2, 0.0, 0.3, 0.0, 0),
    "fig11 rect 10x1": ("rect", 10, 1, 0.05, 0.1, 0.0, 0.1, 0.0, 1),
    "fig13 tri 10x3": ("tri", 10, 3, 0.1, 0.2, 0.0, 0.0, 1.0, 0),
}
SMALL = {  # runs with events of n <= 20 for the enumeration cross-check
    "rect 2x1, mu_pp 0": ("rect", 2, 1, 0.0, 0.2, 0.0, 0.16, 0.0, 1),
    "rect 3x1, mu 0.3": ("rect", 3, 1, 0.3, 0.3, 0.3, 0.16, 0.0, 1),
    "tri 3x2, mu_pp 0": ("tri", 3, 2, 0.0, 0.3, 0.0, 0.16, 0.0, 1),
}


def simulate(spec, max_events: int = 100_000) -> models.Run:
    kind, lx, ly, mpp, mpl, mw, gamma, v0, seed = spec
    system = models.System(models.make_lattice(kind, lx, ly), mu_pp=mpp, mu_plane=mpl,
                           mu_wall=mw, gamma=gamma, V0=v0)
    return models.simulate(system, models.initial_state(system, seed=seed),
                           max_events=max_events)


def table(quick: bool) -> None:
    print("| run | events | n | accelerations u/o/? | forces u/o/? | states u/o/? | stages "
          "(accelerations) | median s | max s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, spec in RUNS.items():
        run = simulate(spec, 10 if quick else 100_000)
        res = certify_run(run, None)
        t = res.totals
        ns = [r["n"] for r in res.rows]
        cnt = {q: f"{t[q]['unique']}/{t[q]['another solution exists']}/{t[q]['unknown']}"
               for q in ("accelerations", "forces", "states")}
        stages = ", ".join(f"{s} {k}" for s, k in t["accelerations"]["stages"].items())
        print(f"| {name} | {t['events']} | {min(ns)}-{max(ns)} | {cnt['accelerations']} | "
              f"{cnt['forces']} | {cnt['states']} | {stages} | {t['median_seconds']:.3f} | "
              f"{t['max_seconds']:.3f} |", flush=True)


def enumerate_check(max_n: int = 20) -> None:
    print("\n| run | events n <= 20 | unique verdicts | agree with enumeration | seconds |")
    print("|---|---|---|---|---|")
    for name, spec in SMALL.items():
        run = simulate(spec, 12)
        t0 = time.perf_counter()
        events = unique = agree = 0
        for k in range(run.n_events):
            ep = models.event_problem(run.system, run.state_at(k))
            if ep.lcp.n > max_n:
                continue
            rec = run.records[k]
            z = event_z(ep, np.r_[rec.R, rec.S])
            cert = certify_stages(ep, z)
            events += 1
            _, obs = observables_of(ep)
            sols = None
            for q, L in obs.items():
                if cert.verdicts[q].verdict != UNIQUE:
                    continue
                unique += 1
                sols = sols if sols is not None else lcp.enumerate_solutions(ep.lcp)
                zs = max(np.abs(z).max(), 1e-300)
                sL = max(np.abs(L).sum(axis=1).max() * zs, np.abs(L @ z).max())
                agree += all(np.max(np.abs(L @ (s.z - z))) <= 1e-3 * sL for s in sols)
        print(f"| {name} | {events} | {unique} | {agree} | {time.perf_counter() - t0:.1f} |",
              flush=True)


def defaults_table(k: int) -> None:
    run = simulate(RUNS["fig9 rect 10x4"])
    events = sorted(set(np.linspace(0, run.n_events - 1, k).round().astype(int).tolist()))
    print(f"\nFig. 9's run: {run.n_events} events, {run.status}; verify.certify at its defaults "
          f"on events {events}\n")
    print("| event | t | n | method | w | z | accelerations | forces | pattern | seconds |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    secs, unknown = [], 0
    short = {True: "unique", False: "other", None: "UNKNOWN"}
    for e in events:
        ep = models.event_problem(run.system, run.state_at(e))
        rec = run.records[e]
        z = event_z(ep, np.r_[rec.R, rec.S])
        t0 = time.perf_counter()
        cert = verify.certify(ep, z)
        secs.append(time.perf_counter() - t0)
        flags = [cert.w_unique, cert.z_unique, cert.observables["accelerations"],
                 cert.observables["forces"], cert.pattern_unique]
        unknown += sum(f is None for f in flags)
        print(f"| {e} | {rec.t:.4f} | {ep.lcp.n} | {cert.method} | "
              + " | ".join(short[f] for f in flags) + f" | {secs[-1]:.2f} |", flush=True)
    print(f"\nmedian {np.median(secs):.2f} s, max {max(secs):.2f} s, unknown verdicts: "
          f"{unknown} of {5 * len(events)}")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="first 10 events of each run only")
    p.add_argument("--enumerate", action="store_true", help="the enumeration cross-check")
    p.add_argument("--defaults", type=int, nargs="?", const=9, default=0, metavar="K",
                   help="only verify.certify at its defaults on K events of Fig. 9 (default 9)")
    args = p.parse_args()
    if args.defaults:
        defaults_table(args.defaults)
        return
    table(args.quick)
    if args.enumerate:
        enumerate_check()


if __name__ == "__main__":
    main()
