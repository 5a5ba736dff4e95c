"""`rigidlcp methods` and `rigidlcp solve` (over rigidlcp.lcp).

Exit codes of ``solve``: 0 solved, 1 the method did not solve it (any other status: infeasible,
ray, max_iter, not_converged, failed), 2 bad input (unreadable file, invalid problem, unknown
method or option, a method that refuses the problem).
"""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

from rigidlcp.lcp.api import ACCEPTS, methods, solve
from rigidlcp.lcp.problem import InvalidProblem, load


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `methods` and `solve` sub-commands to the `rigidlcp` parser."""
    p = subparsers.add_parser("methods", help="list the LCP methods and what each accepts")
    p.set_defaults(func=cmd_methods)

    p = subparsers.add_parser(
        "solve", help="solve an LCP or MLCP stored in a .npz file",
        description="Solve the LCP (arrays M, q) or MLCP (arrays A, C, D, B, a, b) of a .npz "
        "file. Exit code 0 when solved, 1 when the method did not solve it, 2 on bad input.",
    )
    p.add_argument("problem", help="the .npz file (written by LCP.save / MLCP.save)")
    p.add_argument("--method", default="lemke", help="a method from `rigidlcp methods` "
                   "(default: lemke)")
    p.add_argument("--option", "-o", action="append", default=[], metavar="KEY=VALUE",
                   help="a method option; VALUE is read as JSON when it parses (1e-9, 100, "
                   "true, [0, 2]), else as a string. Repeatable.")
    p.add_argument("--json", action="store_true", help="print the whole solution as JSON")
    p.set_defaults(func=cmd_solve)


def cmd_methods(args: argparse.Namespace) -> int:
    """Print a table of the registered methods."""
    rows = [("method", "accepts", "options", "description")]
    for m in methods():
        accepts = ACCEPTS[m.accepts] + (f" (n <= {m.max_n})" if m.max_n else "")
        rows.append((m.name, accepts, ", ".join(m.options) or "-", m.description))
    widths = [max(len(r[i]) for r in rows) for i in range(3)]
    for r in rows:
        print("  ".join(c.ljust(w) for c, w in zip(r[:3], widths, strict=True)) + "  " + r[3])
    return 0


def parse_options(pairs: list[str]) -> dict[str, Any]:
    """KEY=VALUE strings to a dict; VALUE as JSON when it parses, else as a string."""
    options: dict[str, Any] = {}
    for pair in pairs:
        key, sep, raw = pair.partition("=")
        key = key.strip()
        if not sep or not key:
            raise InvalidProblem(f"--option must be KEY=VALUE, got {pair!r}")
        try:
            options[key] = json.loads(raw)
        except json.JSONDecodeError:
            options[key] = raw
    return options


def _jsonable(x: Any) -> Any:
    """Plain JSON: numpy to lists/numbers, non-finite floats to strings ("inf", "nan")."""
    if hasattr(x, "tolist"):
        x = x.tolist()
    if isinstance(x, float) and not math.isfinite(x):
        return str(x)
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    return x


def cmd_solve(args: argparse.Namespace) -> int:
    """Solve the problem file; print status, residual, iterations (or JSON)."""
    try:
        problem = load(args.problem)
    except (FileNotFoundError, InvalidProblem):
        raise
    except Exception as exc:  # a corrupt or foreign file: numpy/zipfile say why
        raise InvalidProblem(f"cannot read {args.problem} as a problem file: {exc}") from None
    sol = solve(problem, method=args.method, **parse_options(args.option))
    if args.json:
        print(json.dumps(_jsonable(sol.to_dict()), indent=2, allow_nan=False))
    else:
        print(f"method     : {sol.method}")
        print(f"status     : {sol.status}")
        print(f"residual   : {sol.residual:.3e}")
        if sol.u is not None:
            print(f"eq_residual: {sol.eq_residual:.3e}")
        print(f"iterations : {sol.iterations}")
        if sol.message:
            print(f"message    : {sol.message}")
    return 0 if sol.success else 1
