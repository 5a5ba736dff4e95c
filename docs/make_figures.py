"""Regenerate every figure of docs/figures.md (and the reproduction report) with one command:

    python docs/make_figures.py            # everything: ~2-5 minutes on 2 cores
    python docs/make_figures.py --quick    # reproduction at --quick sizes (for a look only)

It runs the `rigidlcp` commands in this process, writes docs/reproduction/ (the report of
`rigidlcp reproduce`, unless --quick) and copies each figure to docs/figures/ under the name
docs/figures.md shows. Existing files there are replaced (this script owns that folder).
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
from pathlib import Path

DOCS = Path(__file__).resolve().parent
FIGURES = DOCS / "figures"

#: docs/figures/NAME <- (command output folder key, file inside it)
COPIES = {
    "fig4_networks.png": ("forces", "networks.png"),
    "fig5_nullspace.png": ("nullspace", "nullspace.png"),
    "fig6_omega.png": ("reproduce", "fig6_omega.png"),
    "fig7_stages.png": ("reproduce", "fig7_stages.png"),
    "fig8_steady_state.png": ("reproduce", "fig8_steady_state.png"),
    "fig9_rows.png": ("reproduce", "fig9_rows.png"),
    "fig10_mu_g.png": ("reproduce", "fig10_mu_g.png"),
    "fig11_mu_g.png": ("reproduce", "fig11_12/mu_g.png"),
    "fig12_effective.png": ("reproduce", "fig11_12/effective.png"),
    "fig13_dissipation.png": ("reproduce", "fig13_dissipation.png"),
    "run_angular_acceleration.png": ("plot", "angular_acceleration.png"),
    "run_normal_forces.png": ("plot", "normal_forces.png"),
    "run_friction_forces.png": ("plot", "friction_forces.png"),
    "run_mu_g.png": ("plot", "mu_g.png"),
    "run_dissipation.png": ("plot", "dissipation.png"),
    "bench_profile.png": ("bench", "profile_LCP.png"),
}


def _run(argv: list[str]) -> None:
    from rigidlcp.cli.main import main

    print("rigidlcp " + " ".join(argv), flush=True)
    code = main(argv)
    if code not in (0, 1):  # 1: reproduce / forces report a verdict, not a crash
        sys.exit(f"rigidlcp {argv[0]} failed with status {code}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true",
                   help="reproduction at small sizes in a temporary folder (not the report)")
    args = p.parse_args(argv)
    os.chdir(DOCS.parent)  # the report names its command with the relative docs/reproduction
    with tempfile.TemporaryDirectory() as tmp:
        t = Path(tmp)
        out = {"forces": t / "forces", "nullspace": t / "ns", "plot": t / "plot",
               "bench": t / "bench",
               "reproduce": t / "reproduce" if args.quick else Path("docs/reproduction")}
        _run(["forces", "--out", str(out["forces"])])
        _run(["nullspace", "--lattice", "rect", "--lx", "4", "--ly", "3", "--states",
              "tangential", "--plot", str(out["nullspace"] / "nullspace.png")])
        _run(["simulate", "--lattice", "rect", "--lx", "10", "--ly", "4", "--gamma", "0.16",
              "--no-progress", "--out", str(t / "run.npz")])
        _run(["plot", str(t / "run.npz"), "--out", str(out["plot"])])
        _run(["bench", "--set", "random-p", "--sizes", "10,20", "--per-size", "5",
              "--methods", "lemke,pivoting,pgs,enumerate", "--no-siconos", "--quiet",
              "--out", str(out["bench"])])
        _run(["reproduce", "--out", str(out["reproduce"]), "--no-progress", "--force"]
             + (["--quick"] if args.quick else []))
        FIGURES.mkdir(exist_ok=True)
        for name, (key, rel) in COPIES.items():
            shutil.copyfile(out[key] / rel, FIGURES / name)
            print(f"docs/figures/{name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
