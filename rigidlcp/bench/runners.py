"""Runners of the benchmark harness (rigidlcp.bench.harness): rigidlcp's methods in a worker process
(started by "forkserver" or "spawn", never forked from this possibly multi-threaded process)
that is killed on a timeout, and Siconos's LCP solvers in a /usr/bin/python3 subprocess.
A method registered at run time (not built in) is sent to the worker with the problem, by
reference (pickle): it must be a module-level function.

A runner's ``solve(problem, method, time_limit)`` returns a raw answer, a dict with "kind":
"answer" (with z, status, iterations, time, message), "timeout", "not_applicable" or "error";
rigidlcp.bench.harness.judge certifies it.
"""

from __future__ import annotations

import json
import multiprocessing as mp
import os
import queue
import subprocess
import tempfile
import threading
import time
import warnings
from pathlib import Path

import numpy as np

from rigidlcp import lcp
from rigidlcp.lcp import LCP

SYSTEM_PYTHON = "/usr/bin/python3"
HELPER = Path(__file__).with_name("_siconos_helper.py")
#: Siconos methods: name -> (helper solver, largest n it is given: None = any).
SICONOS_METHODS = {"siconos-lemke": ("lemke", None), "siconos-enum": ("enum", 20),
                   "siconos-pgs": ("pgs", None)}
#: Seconds a new worker may take to start (imports), outside every time limit.
STARTUP = 300.0
#: Seconds allowed beyond the time limit for passing the problem and the answer around.
GRACE = 2.0


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
        if info is not None and method not in {m.name for m in lcp.methods()}:
            lcp.register(info.name, accepts=info.accepts, description=info.description,
                         max_n=info.max_n, native=info.native)(info.func)
        conn.send(_solve_here(problem, method))


#: A small P-matrix LCP solved once, untimed, by each method in a fresh worker (imports, caches).
WARM_UP = LCP(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0]), name="warm-up")


def _solve_here(problem, method: str) -> dict:
    t0 = time.perf_counter()
    try:
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sol = lcp.solve(problem, method=method)
    except lcp.NotApplicable as exc:
        return {"kind": "not_applicable", "message": str(exc), "time": 0.0}
    except Exception as exc:  # noqa: BLE001 - a harness reports, never dies
        return {"kind": "error", "message": f"{type(exc).__name__}: {exc}",
                "time": time.perf_counter() - t0}
    elapsed = time.perf_counter() - t0
    return {"kind": "answer", "z": np.asarray(sol.z, dtype=float), "status": sol.status,
            "iterations": int(sol.iterations), "message": sol.message, "time": elapsed,
            "u": None if sol.u is None else np.asarray(sol.u, dtype=float)}


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
        if not (parent.poll(STARTUP) and parent.recv() == "ready"):
            raise RuntimeError(f"the bench worker did not start within {STARTUP:g} s")

    def solve(self, problem, method: str, time_limit: float) -> dict:
        if method not in self.warm:
            self.warm.add(method)
            self.solve(WARM_UP, method, time_limit)
        if not self.isolate:
            return _solve_here(problem, method)
        if self.proc is None or not self.proc.is_alive():
            self._start()
        self.conn.send((problem, method, _picklable_info(method)))
        if self.conn.poll(time_limit + self.grace):
            try:
                return self.conn.recv()
            except (EOFError, OSError):
                self.close()
                return {"kind": "error", "message": "the worker died", "time": 0.0}
        self.close()
        return {"kind": "timeout", "time": time_limit,
                "message": f"no answer within {time_limit:g} s: killed"}

    def close(self) -> None:
        if self.proc is not None:
            if self.proc.is_alive():
                self.proc.kill()
            self.proc.join(timeout=10)
            self.conn.close()
            self.proc = self.conn = None
            self.warm = set()


class SiconosRunner:
    """Siconos's LCP solvers in a long-lived /usr/bin/python3 subprocess (restarted after a
    timeout). `available` is False, with `reason`, when that interpreter has no siconos."""

    def __init__(self, python: str = SYSTEM_PYTHON):
        self.python = python
        self.proc: subprocess.Popen | None = None
        self.lines: queue.Queue = queue.Queue()
        self.reason = ""
        self.version = ""
        self.tmp = tempfile.TemporaryDirectory(prefix="rigidlcp_bench_")
        self.available = self._start()

    def _start(self) -> bool:
        if not os.path.exists(self.python):
            self.reason = f"{self.python} not found"
            return False
        self.proc = subprocess.Popen([self.python, str(HELPER)], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                     text=True, bufsize=1)
        self.lines = queue.Queue()
        proc, lines = self.proc, self.lines

        def pump() -> None:
            for line in proc.stdout:
                lines.put(line)
            lines.put(None)

        threading.Thread(target=pump, daemon=True).start()
        try:
            hello = self.lines.get(timeout=120)
        except queue.Empty:
            hello = None
        ready = json.loads(hello) if hello else {"ready": False, "error": "no answer"}
        if not ready.get("ready"):
            self.reason = f"{self.python} cannot import siconos.numerics ({ready.get('error')})"
            self._kill()
            return False
        self.version = _debian_version("python3-siconos") or ready.get("version", "?")
        return True

    def solve(self, problem, method: str, time_limit: float) -> dict:
        solver, max_n = SICONOS_METHODS[method]
        if isinstance(problem, lcp.MLCP):
            try:
                problem = problem.to_lcp()
            except lcp.NotApplicable as exc:
                return {"kind": "not_applicable", "time": 0.0,
                        "message": f"{method} is given LCPs (an MLCP after its Schur "
                        f"reduction): {exc}"}
        if not isinstance(problem, LCP):
            return {"kind": "not_applicable", "time": 0.0,
                    "message": f"{method} is given LCPs and MLCPs only"}
        if max_n is not None and problem.n > max_n:
            return {"kind": "not_applicable", "time": 0.0,
                    "message": f"{method} is given n <= {max_n} only (exhaustive)"}
        if self.proc is None or self.proc.poll() is not None:
            if not self._start():
                return {"kind": "error", "message": self.reason, "time": 0.0}
        M_path, q_path = Path(self.tmp.name, "M.npy"), Path(self.tmp.name, "q.npy")
        np.save(M_path, problem.M)
        np.save(q_path, problem.q)
        n = problem.n
        req = {"M": str(M_path), "q": str(q_path), "solver": solver,
               "max_iter": 1000 + 100 * n if solver == "lemke" else 10_000,
               "tol": 1e-10 if solver == "pgs" else None}
        self.proc.stdin.write(json.dumps(req) + "\n")
        self.proc.stdin.flush()
        try:
            line = self.lines.get(timeout=time_limit + GRACE)
        except queue.Empty:
            self._kill()
            return {"kind": "timeout", "time": time_limit,
                    "message": f"no answer within {time_limit:g} s: killed"}
        if line is None:
            self._kill()
            return {"kind": "error", "message": "the Siconos helper died", "time": 0.0}
        out = json.loads(line)
        ok = out["info"] == 0
        status = "solved" if ok else ("max_iter" if out["iterations"] >= req["max_iter"]
                                      else "failed")
        return {"kind": "answer", "z": np.array(out["z"], dtype=float), "status": status,
                "iterations": out["iterations"], "time": out["time"],
                "message": "" if ok else f"Siconos info = {out['info']} "
                f"(its error {out['error']:.3g})"}

    def _kill(self) -> None:
        if self.proc is not None:
            if self.proc.poll() is None:
                self.proc.kill()
            self.proc.wait(timeout=10)
            self.proc = None

    def close(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.stdin.close()
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
        self.proc = None
        self.tmp.cleanup()


def _debian_version(package: str) -> str:
    try:
        out = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", package],
                             capture_output=True, text=True, check=False, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return ""
    return out.stdout.strip()
