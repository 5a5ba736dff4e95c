"""`rigidlcp methods`, `rigidlcp solve` and `rigidlcp certify` (over rigidlcp.lcp and verify).

A problem file is any that `lcp.load` reads: the toolkit's .npz (LCP, MLCP) or Siconos's text
files (LCP, MLCP, 2D friction contact). Exit codes of ``certify``: 0 accepted, 1 rejected (or not
solved), 2 bad input. Exit codes of ``solve``: 0 solved, 1 the method did not solve it (any
other status: infeasible, ray, max_iter, not_converged, failed), 2 bad input (unreadable file,
invalid problem, unknown method or option, a method that refuses the problem).
"""

from __future__ import annotations

import argparse
import json
import math
import shlex
from typing import Any

from rigidlcp.lcp.api import ACCEPTS, methods, solve
from rigidlcp.lcp.errors import InvalidProblem
from rigidlcp.lcp.io.load import load


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `methods` and `solve` sub-commands to the `rigidlcp` parser."""
    p = subparsers.add_parser("methods", help="list the LCP methods and what each accepts")
    p.set_defaults(func=cmd_methods)

    p = subparsers.add_parser(
        "solve", help="solve a problem file (.npz, or Siconos's LCP/MLCP/FC2D text)",
        description="Solve the problem of a file: an LCP or MLCP .npz (LCP.save / MLCP.save) "
        "or a Siconos text file (LCP, MLCP, 2D friction contact), and print one solution "
        "(uniqueness is not checked: `rigidlcp certify`). Exit code 0 when solved, 1 "
        "when the method did not solve it, 2 on bad input.",
    )
    _add_problem_arguments(p)
    p.add_argument("--json", action="store_true", help="print the whole solution as JSON")
    p.set_defaults(func=cmd_solve)

    p = subparsers.add_parser(
        "certify", help="solve a problem file and certify the answer (residual, uniqueness)",
        description="Solve the problem of a file (as `rigidlcp solve`) and certify the answer "
        "independently of the method (verify.certify: the scaled residual, and whether the "
        "solution is unique). Exit code 0 when accepted, 1 when not, 2 on bad input.",
    )
    _add_problem_arguments(p)
    p.add_argument("--uniqueness", default="auto",
                   choices=("auto", "staged", "p-matrix", "enumeration", "milp", "none"),
                   help="how uniqueness is decided (default auto: the P-matrix test, "
                   "enumeration for n <= 10, the staged path beyond; docs/verification.md)")
    p.add_argument("--time-limit", type=float, default=30.0,
                   help="seconds per MILP of the uniqueness search (default 30), on --clock")
    p.add_argument("--clock", choices=("cpu", "wall"), default="cpu",
                   help="how --time-limit is counted: this process's CPU seconds (default; "
                   "a verdict then does not depend on the machine's load) or wall seconds")
    p.add_argument("--json", action="store_true", help="print the certificate as JSON")
    p.set_defaults(func=cmd_certify)


def _add_problem_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("problem", help="the problem file (.npz, or a Siconos .dat/.hdf text file)")
    p.add_argument("--method", default="lemke", help="a method from `rigidlcp methods` "
                   "(default: lemke)")
    p.add_argument("--option", "-o", action="append", default=[], metavar="KEY=VALUE",
                   help="a method option; VALUE is read as JSON when it parses (1e-9, 100, "
                   "true, [0, 2]), else as a string. Repeatable.")


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


def _load(path: str):
    """lcp.load: a missing, corrupt or foreign file raises FileNotFoundError / InvalidFile
    naming it (one line on the command line); a file that reads but holds a bad problem (NaN,
    mismatched sizes) raises InvalidProblem, here prefixed with the file's name."""
    from rigidlcp.lcp.errors import InvalidFile, InvalidProblem

    try:
        return load(path)
    except InvalidProblem as exc:
        if isinstance(exc, InvalidFile) or str(path) in str(exc):
            raise
        raise InvalidProblem(f"{path}: {exc}") from None


def cmd_certify(args: argparse.Namespace) -> int:
    """Solve the problem file, certify the answer, print the certificate (or JSON)."""
    from rigidlcp.verify import certify

    if not args.time_limit > 0:  # checked first: -3 would read as "time limit reached"
        raise ValueError(f"--time-limit must be > 0 seconds, got {args.time_limit}")
    problem = _load(args.problem)
    sol = solve(problem, method=args.method, **parse_options(args.option))
    if sol.z is None or not sol.success:
        print(f"{sol.method}: status {sol.status} ({sol.message or 'no message'}): "
              "nothing to certify")
        return 1
    cert = certify(problem, sol, uniqueness=args.uniqueness, time_limit=args.time_limit,
                   clock=getattr(args, "clock", "cpu"))
    if args.json:
        fields = ("accepted", "tol", "residual", "scaled_residual", "eq_residual",
                  "scaled_eq_residual", "w_unique", "z_unique", "pattern_unique", "observables",
                  "method", "other_reason", "other_distance", "bound", "notes", "seconds")
        out = {"solver": sol.method, "status": sol.status, "z": sol.z, "u": sol.u,
               **{f: getattr(cert, f) for f in fields}}
        print(json.dumps(_jsonable(out), indent=2, allow_nan=False))
    else:
        print(f"solved by {sol.method} ({sol.iterations} iterations)")
        print(cert)
        # the point certified, after the verdicts on whether it is the only one (a friction
        # problem's answer is its forces r, judged as "forces"; its z is the Glocker LCP's)
        from rigidlcp.lcp.problems.problem import LCP, MLCP

        friction = not isinstance(problem, (LCP, MLCP))
        rows = ([("r", sol.z, cert.observables.get("forces"))] if friction
                else [("z", sol.z, cert.z_unique)])
        if sol.u is not None:
            rows.append(("u", sol.u, cert.observables.get("u")))
        for name, x, unique in rows:
            what = {True: f"the solution: {name} is unique", False: f"one of several {name} "
                    "(another above)", None: f"one solution; uniqueness of {name} undecided"}
            print(f"certified {name} = {_vector(x)}  ({what[unique]})")
    return 0 if cert.accepted else 1


def cmd_solve(args: argparse.Namespace) -> int:
    """Solve the problem file; print status, residual, iterations and, when solved, the
    solution (or JSON)."""
    problem = _load(args.problem)
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
        if sol.success:  # the answer itself, and what it is not (yet) known to be
            if sol.u is not None:
                print(f"u          : {_vector(sol.u)}")
            from rigidlcp.lcp.problems.problem import LCP, MLCP

            name = "z" if isinstance(problem, (LCP, MLCP)) else "r"  # friction: the forces
            print(f"{name}          : {_vector(sol.z)}")
            print("note       : one solution, checked; whether it is the only one: "
                  f"rigidlcp certify {shlex.quote(args.problem)}")
    return 0 if sol.success else 1


def _vector(x) -> str:
    """A vector on one line: every entry up to 10, else the first and last 3 (all in --json)."""
    import numpy as np

    return np.array2string(np.asarray(x), precision=6, threshold=10, edgeitems=3,
                           max_line_width=10**6) + ("" if np.size(x) <= 10 else
                                                    f"  ({np.size(x)} entries; all: --json)")
