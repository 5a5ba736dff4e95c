"""`rigidlcp fuzz`: the fuzz harness of rigidlcp.bench.fuzz (docs/fuzz.md).

Exit codes: 0 no silent-wrong or crashing answer, 1 some (saved in --out), 2 bad arguments.
"""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `fuzz` sub-command to the `rigidlcp` parser."""
    from rigidlcp.bench.fuzz import add_arguments

    p = subparsers.add_parser(
        "fuzz", help="generated LCPs x every method, judged independently of the solvers",
        description="Generate LCPs of known character (P, ill-conditioned, PSD, degenerate, "
        "scaled, infeasible, event LCPs, ...), run every method, judge each answer without "
        "trusting the solver, print a class x method table (docs/fuzz.md).",
    )
    add_arguments(p)
    p.set_defaults(func=cmd_fuzz)


def cmd_fuzz(args: argparse.Namespace) -> int:
    from rigidlcp.bench.fuzz import run_from_args

    return run_from_args(args)
