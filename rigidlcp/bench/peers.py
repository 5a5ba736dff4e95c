"""Other projects' LCP solvers as bench methods ("peers"), optional: each runs only when its
package imports (`pip install -e ".[peers]"`), and is skipped with a note otherwise.

| bench name | package | the call timed (from Python, on the problem's M and q) |
|---|---|---|
| quantecon-lemke | quantecon (numba) | `quantecon.optimize.lcp_lemke(M, q)` |
| drake-moby | drake | `MobyLcpSolver().Solve(prog)`, prog a MathematicalProgram with M, q |
| drake-unrevised-lemke | drake | `UnrevisedLemkeSolver().Solve(prog)` |
| lemkelcp | lemkelcp | `lemkelcp.lemkelcp(M, q, maxIter)` (0.1: broken on Python 3) |

Every peer is timed the way rigidlcp's methods are (rigidlcp.bench.runners): the whole call
from Python, in the bench's worker process, after one untimed warm-up solve per fresh worker
(numba compiles lcp_lemke there; the warm-up's time is reported apart). Drake's Python
binding exposes Moby's solver only through `Solve` on a MathematicalProgram (its
SolveLcpLemke / SolveLcpFast / SolveLcpFastRegularized paths are C++ only); Solve runs
SolveLcpLemkeRegularized (Lemke on M, then on M + lambda I for lambda = 1e-20, 1e-16, ...,
each answer checked against the matrix it solved, M + lambda I, not M). Building the program
is part of the natural call, so it is timed. A peer's "solved" is only its claim: the
harness certifies the z it returns like any other answer (rigidlcp.bench.harness.judge), so a
false success is reported as `uncertified`. Peers take LCPs only (other kinds are refused).
"""

from __future__ import annotations

import importlib
import importlib.metadata
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np


@dataclass(frozen=True)
class Peer:
    """A peer solver: the package it needs (its distribution name, for the version) and the
    call, M, q -> (z or None, status, iterations, message); status "solved" is the peer's
    claim of a solution, "ray" its Lemke's termination on a secondary ray (no claim: infeasible
    only when the harness proves it), anything else a failure."""

    package: str
    module: str
    call: Callable[[np.ndarray, np.ndarray], tuple]
    description: str


def _quantecon(M: np.ndarray, q: np.ndarray) -> tuple:
    from quantecon.optimize import lcp_lemke

    res = lcp_lemke(M, q, max_iter=1000 + 100 * q.size)
    # status 0: solved, 1: iteration limit, 2: a secondary ray (Lemke's termination, no claim)
    status = {0: "solved", 1: "max_iter", 2: "ray"}.get(int(res.status), "failed")
    return res.z, status, int(res.num_iter), f"quantecon status {res.status}"


def _drake(solver_name: str, M: np.ndarray, q: np.ndarray) -> tuple:
    from pydrake import solvers

    prog = solvers.MathematicalProgram()
    z = prog.NewContinuousVariables(q.size, "z")
    prog.AddLinearComplementarityConstraint(M, q, z)
    result = getattr(solvers, solver_name)().Solve(prog, None, None)
    status = "solved" if result.is_success() else "failed"
    return result.GetSolution(z), status, 0, str(result.get_solution_result())


def _lemkelcp(M: np.ndarray, q: np.ndarray) -> tuple:
    """lemkelcp 0.1 (2016, its only release) is broken on Python 3: its tableau keeps
    `range(n)` for the basis positions and assigns into it at the first pivot, so every call
    on a q with a negative entry raises TypeError ('range' object does not support item
    assignment); q >= 0 returns z = 0 before any pivot. The exception is reported as the
    peer's error on each problem, not hidden: the comparison says the peer is broken."""
    from lemkelcp.lemkelcp import lemkelcp

    z, code, text = lemkelcp(M, q, 1000 + 100 * q.size)
    status = {0: "solved", 1: "ray", 2: "max_iter"}.get(code, "failed")
    return z, status, 0, text


PEERS: dict[str, Peer] = {
    "quantecon-lemke": Peer("quantecon", "quantecon.optimize", _quantecon,
                            "QuantEcon's lcp_lemke (numba, lexicographic Lemke)"),
    "drake-moby": Peer("drake", "pydrake.solvers", partial(_drake, "MobyLcpSolver"),
                       "Drake's MobyLcpSolver via Solve (SolveLcpLemkeRegularized)"),
    "drake-unrevised-lemke": Peer(
        "drake", "pydrake.solvers", partial(_drake, "UnrevisedLemkeSolver"),
        "Drake's UnrevisedLemkeSolver via Solve"),
    "lemkelcp": Peer("lemkelcp", "lemkelcp", _lemkelcp,
                     "PyPI's lemkelcp (pure Python); version 0.1 is broken on Python 3: "
                     "every call with some q_i < 0 raises TypeError ('range' object does not "
                     "support item assignment), only q >= 0 is answered (z = 0)"),
}


def peer_available(name: str) -> tuple[bool, str]:
    """(True, version) when the peer's package imports, else (False, why)."""
    peer = PEERS[name]
    try:
        importlib.import_module(peer.module)
    except Exception as exc:  # noqa: BLE001 - any import failure means "skip"
        return False, (f"{peer.package} not installed ({type(exc).__name__}: {exc}); "
                       "pip install -e \".[peers]\"")
    try:
        return True, importlib.metadata.version(peer.package)
    except importlib.metadata.PackageNotFoundError:
        return True, "?"


def solve_peer(problem, name: str, peer: Peer | None = None) -> dict:
    """The peer's answer as the harness's raw answer (not yet judged) with the time of the
    whole call; {"kind": "not_applicable"} for a problem that is not a plain LCP."""
    import time

    from rigidlcp.lcp import LCP

    if type(problem) is not LCP:
        return {"kind": "not_applicable", "time": 0.0,
                "message": f"{name} is given LCPs only"}
    peer = PEERS[name] if peer is None else peer
    M = problem.M.toarray() if hasattr(problem.M, "toarray") else problem.M
    M = np.array(M, dtype=float)  # a dense copy: the peers take numpy arrays
    q = np.array(problem.q, dtype=float)
    t0 = time.perf_counter()
    try:
        z, status, iterations, message = peer.call(M, q)
    except Exception as exc:  # noqa: BLE001 - a harness reports, never dies
        return {"kind": "error", "message": f"{type(exc).__name__}: {exc}",
                "time": time.perf_counter() - t0}
    seconds = time.perf_counter() - t0
    z = np.full(q.size, np.nan) if z is None else np.asarray(z, dtype=float).reshape(-1)
    return {"kind": "answer", "z": z, "status": status, "iterations": iterations,
            "message": message, "time": seconds, "u": None}
