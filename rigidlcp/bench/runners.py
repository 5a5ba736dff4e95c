"""The worker runner of the benchmark harness (rigidlcp.bench.harness): rigidlcp's methods and the
peers (bench.peers) in a worker process (started by "forkserver" or "spawn", never forked from
this possibly multi-threaded process) that is killed on a timeout. Siconos's solvers have their
own runner (rigidlcp.bench.siconos_runner).
A method registered at run time (not built in) is sent to the worker with the problem, by
reference (pickle): it must be a module-level function.

A runner's ``solve(problem, method, time_limit)`` returns a raw answer, a dict with "kind":
"answer" (with z, status, iterations, time, message), "timeout", "not_applicable" or "error";
rigidlcp.bench.harness.judge certifies it.
"""

from __future__ import annotations

import math
import multiprocessing as mp
import time
import warnings

import numpy as np

from rigidlcp import lcp
from rigidlcp.lcp import LCP
from rigidlcp.lcp.errors import RigidLCPError

from .own import OWN_ANSWER
from .peers import PEERS, Peer, solve_peer

#: What LocalRunner._ask returns when the worker gives no reply.
_TIMEOUT, _DIED = object(), object()
#: Seconds a new worker may take to start (imports), outside every time limit.
STARTUP = 300.0
#: Seconds allowed beyond the time limit for passing the problem and the answer around.
GRACE = 2.0
#: Seconds the untimed warm-up solve of a method in a fresh worker may take (imports, numba's
#: compilation), whatever the solves' limit: under that limit, a warm-up killed there left the
#: compilation to the first timed solve (QuantEcon's lcp_lemke, --time-limit 5, loaded machine).
WARM_UP_LIMIT = 120.0


# --------------------------------------------------------------------------------------------

def _worker_main(conn) -> None:
    """The forked worker: solve what it is sent, one problem at a time, on one BLAS thread."""
    try:
        from threadpoolctl import threadpool_limits

        threadpool_limits(1)
    except Exception:  # noqa: BLE001 - no threadpoolctl: leave BLAS alone
        pass
    lcp.methods()  # import every method module before the first (timed) solve
    conn.send("ready")
    while True:
        try:
            problem, method, info = conn.recv()
        except (EOFError, OSError):
            return
        if isinstance(info, Peer):  # another project's solver (bench.peers)
            conn.send(solve_peer(problem, method, info))
            continue
        if info is not None and method not in {m.name for m in lcp.methods()}:
            lcp.register(info.name, accepts=info.accepts, description=info.description,
                         max_n=info.max_n, native=info.native)(info.func)
        if isinstance(problem, list):  # a batch of same-size LCPs (LocalRunner.solve_batch)
            conn.send(_solve_batch_here(problem, method))
        else:
            conn.send(_solve_here(problem, method))


#: A small P-matrix LCP solved once, untimed, by each method in a fresh worker (imports, caches).
WARM_UP = LCP(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0]), name="warm-up")


def _solve_here(problem, method: str) -> dict:
    if method in PEERS:
        return solve_peer(problem, method, PEERS[method])
    t0 = time.perf_counter()
    try:
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if type(problem) is LCP:  # the natural call on M and q, as the peers are given
                problem = LCP(problem.M, problem.q, name=problem.name)
            # OWN_ANSWER: the method's own answer (lcp.solve still checks it: a "solved"
            # that fails becomes "inaccurate", an unproved "infeasible" "failed"), never
            # another method's answer credited to it.
            sol = lcp.solve(problem, method=method, **OWN_ANSWER)
    except lcp.NotApplicable as exc:
        return {"kind": "not_applicable", "message": str(exc), "time": 0.0}
    except Exception as exc:  # noqa: BLE001 - a harness reports, never dies
        return {"kind": "error", "message": f"{type(exc).__name__}: {exc}",
                "time": time.perf_counter() - t0}
    return _answer(sol, time.perf_counter() - t0)


def _answer(sol, seconds: float) -> dict:
    """A solution as the harness's raw answer (judged there, never trusted)."""
    return {"kind": "answer", "z": np.asarray(sol.z, dtype=float), "status": sol.status,
            "iterations": int(sol.iterations), "message": sol.message, "time": seconds,
            "u": None if sol.u is None else np.asarray(sol.u, dtype=float),
            # the method's own final basis: the check bounds the forward error on the method's
            # pattern, as lcp.solve did (without it, another pattern of a degenerate z may give
            # a far looser bound and a correct answer judged "uncertified")
            "basis": None if sol.basis is None else np.asarray(sol.basis, dtype=np.intp),
            "forward_error": getattr(sol, "forward_error",
                                     (sol.info or {}).get("forward_error"))}


def _solve_batch_here(problems: list, method: str) -> list[dict] | dict:
    """`lcp.solve_many(problems, method, repair=False)`, timed as a whole: one raw answer per
    problem, each with the batch's mean time per problem ("batch": its size); or one
    {"kind": "error"} for the whole batch (the harness then solves them one by one)."""
    t0 = time.perf_counter()
    try:
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sols = lcp.solve_many(problems, method, **OWN_ANSWER)
    except Exception as exc:  # noqa: BLE001 - one by one instead
        return {"kind": "error", "message": f"{type(exc).__name__}: {exc}"}
    mean = (time.perf_counter() - t0) / max(len(problems), 1)
    return [{**_answer(sol, mean), "batch": len(problems)} for sol in sols]


def start_method() -> str:
    """"forkserver" where available (POSIX), else "spawn": a worker is never forked from this
    process, which may run threads (BLAS, HiGHS, the Siconos pump)."""
    methods = mp.get_all_start_methods()
    return "forkserver" if "forkserver" in methods else "spawn"


def _picklable_info(method: str):
    """The method's MethodInfo when it pickles (by reference: a module-level function), so
    that a worker can register a method registered here at run time; else None (the worker
    knows the built-in methods by itself)."""
    import pickle

    from rigidlcp.lcp import api

    if method in PEERS:
        return PEERS[method]
    if method not in _PICKLED:
        info = api.get_method(method)
        try:
            pickle.dumps(info)
        except Exception:  # noqa: BLE001 - a closure or local function
            info = None
        _PICKLED[method] = info
    return _PICKLED[method]


_PICKLED: dict = {}


class LocalRunner:
    """rigidlcp's methods in a worker process (forkserver / spawn), killed and replaced on a
    timeout.
    With isolate=False the solve runs in this process and the limit is checked afterwards."""

    def __init__(self, isolate: bool = True, grace: float = GRACE):
        self.isolate = isolate
        self.grace = grace
        self.proc = None
        self.conn = None
        self.warm: set[str] = set()  # methods already run once by the current worker
        self.cold: set[str] = set()  # methods whose warm-up timed out: not warmed up again
        #: {method: seconds of each warm-up solve} (untimed in the results, reported apart)
        self.warmups: dict[str, list[float]] = {}

    def _start(self) -> None:
        ctx = mp.get_context(start_method())
        if ctx.get_start_method() == "forkserver":
            ctx.set_forkserver_preload(["numpy", "scipy.sparse", "rigidlcp.lcp"])
        parent, child = ctx.Pipe()
        self.proc = ctx.Process(target=_worker_main, args=(child,), daemon=True)
        self.proc.start()
        child.close()
        self.conn = parent
        # the worker's start (imports) is not part of any solve's time limit
        try:
            ready = parent.poll(STARTUP) and parent.recv() == "ready"
        except (EOFError, OSError):  # the worker exited while starting
            self.proc.join(5)
            raise RigidLCPError(
                f"the bench worker exited while starting (exit code {self.proc.exitcode}): "
                "called from a script, run_bench must be under `if __name__ == \"__main__\":` "
                "(each worker process imports the script, Python's spawn / forkserver rule; "
                "its error is printed above)") from None
        if not ready:
            raise RuntimeError(f"the bench worker did not start within {STARTUP:g} s")

    def _warm_up(self, method: str, time_limit: float) -> None:
        """One untimed solve of WARM_UP per method in a fresh worker (imports, numba's
        compilation, caches), up to max(time_limit, WARM_UP_LIMIT) seconds; its wall time is
        kept in `warmups`. A method whose warm-up timed out is not warmed up again."""
        if method not in self.warm and method not in self.cold:
            self.warm.add(method)
            raw = self.solve(WARM_UP, method, max(time_limit, WARM_UP_LIMIT))
            if raw.get("kind") == "timeout":
                self.cold.add(method)
            self.warmups.setdefault(method, []).append(float(raw.get("time", math.nan)))

    def solve(self, problem, method: str, time_limit: float) -> dict:
        self._warm_up(method, time_limit)
        if not self.isolate:
            return _solve_here(problem, method)
        answer = self._ask(problem, method, time_limit + self.grace)
        if answer is _DIED:
            return {"kind": "error", "message": "the worker died", "time": 0.0}
        if answer is _TIMEOUT:
            return {"kind": "timeout", "time": time_limit,
                    "message": f"no answer within {time_limit:g} s: killed"}
        return answer

    def _ask(self, payload, method: str, timeout: float):
        """Send a problem (or a list of them) to the worker and return its reply; _TIMEOUT
        (the worker killed) or _DIED when there is none."""
        if self.proc is None or not self.proc.is_alive():
            self._start()
        self.conn.send((payload, method, _picklable_info(method)))
        if not self.conn.poll(timeout):
            self.close()
            return _TIMEOUT
        try:
            return self.conn.recv()
        except (EOFError, OSError):
            self.close()
            return _DIED

    def solve_batch(self, problems: list, method: str, time_limit: float) -> list[dict] | None:
        """Raw answers for same-size LCPs solved by one `lcp.solve_many` call (time: the mean
        per problem), or None when the batch failed or took longer than time_limit per problem
        on average (the caller then solves them one at a time, each with its own limit)."""
        self._warm_up(method, time_limit)
        raws = (_solve_batch_here(problems, method) if not self.isolate else
                self._ask(list(problems), method, time_limit * len(problems) + self.grace))
        return raws if isinstance(raws, list) else None  # an error, a timeout, a dead worker

    def close(self, wait: float = 0.0) -> None:
        """Stop the worker: killed at once (a timeout), or, with `wait` > 0 (the end of a run),
        asked to exit by closing its pipe and killed only after `wait` seconds, so that its
        exit handlers run (a peer's semaphores, e.g. numba's under QuantEcon, were left to
        the resource tracker, which warned of "leaked semaphore objects" at shutdown)."""
        if self.proc is not None:
            if wait > 0 and self.proc.is_alive():
                self.conn.close()
                self.proc.join(timeout=wait)
            if self.proc.is_alive():
                self.proc.kill()
            self.proc.join(timeout=10)
            self.conn.close()
            self.proc = self.conn = None
            self.warm = set()
