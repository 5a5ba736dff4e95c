"""Runners of the benchmark harness (rigidlcp.bench.harness): rigidlcp's methods in a worker process
(started by "forkserver" or "spawn", never forked from this possibly multi-threaded process)
that is killed on a timeout, and Siconos's LCP, MLCP and 2D friction-contact solvers
(SICONOS_METHODS) in a /usr/bin/python3 subprocess (_siconos_helper.py).
A method registered at run time (not built in) is sent to the worker with the problem, by
reference (pickle): it must be a module-level function.

A runner's ``solve(problem, method, time_limit)`` returns a raw answer, a dict with "kind":
"answer" (with z, status, iterations, time, message), "timeout", "not_applicable" or "error";
rigidlcp.bench.harness.judge certifies it.
"""

from __future__ import annotations

import json
import math
import multiprocessing as mp
import os
import queue
import subprocess
import tempfile
import threading
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from rigidlcp import lcp
from rigidlcp.lcp import LCP

from .own import OWN_ANSWER
from .peers import PEERS, Peer, solve_peer

SYSTEM_PYTHON = "/usr/bin/python3"
HELPER = Path(__file__).with_name("_siconos_helper.py")


@dataclass(frozen=True)
class SiconosMethod:
    """A Siconos solver as a bench method: the kind of problem it is given ("lcp": LCPs and
    Schur-reducible MLCPs; "mlcp": MLCPs; "fc2d": 2D friction contact), the helper's solver
    name, the largest size it is given (n for an LCP, m for an MLCP, contacts c for fc2d; None:
    any; exhaustive methods are capped) and its iteration limit and tolerance (None: Siconos's
    default)."""

    kind: str
    solver: str
    max_size: int | None = None
    max_iter: int | None = None
    tol: float | None = None


#: Siconos methods by bench name. siconos-lemke gets rigidlcp's lemke pivot limit (1000 + 100 n,
#: set per problem), the PGS and NSGS methods rigidlcp's pgs / nsgs tolerance and sweep limit.
SICONOS_METHODS: dict[str, SiconosMethod] = {
    "siconos-lemke": SiconosMethod("lcp", "lemke"),
    "siconos-enum": SiconosMethod("lcp", "enum", max_size=20),
    "siconos-pgs": SiconosMethod("lcp", "pgs", max_iter=10_000, tol=1e-10),
    "siconos-mlcp-enum": SiconosMethod("mlcp", "enum", max_size=16),
    "siconos-mlcp-direct-enum": SiconosMethod("mlcp", "direct_enum", max_size=16),
    "siconos-mlcp-fb": SiconosMethod("mlcp", "fb"),
    "siconos-fc2d-nsgs": SiconosMethod("fc2d", "nsgs", max_iter=10_000, tol=1e-12),
    "siconos-fc2d-lemke": SiconosMethod("fc2d", "lemke"),
    "siconos-fc2d-enum": SiconosMethod("fc2d", "enum", max_size=5),
}
#: What LocalRunner._ask returns when the worker gives no reply.
_TIMEOUT, _DIED = object(), object()
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
        if not (parent.poll(STARTUP) and parent.recv() == "ready"):
            raise RuntimeError(f"the bench worker did not start within {STARTUP:g} s")

    def _warm_up(self, method: str, time_limit: float) -> None:
        """One untimed solve of WARM_UP per method in a fresh worker (imports, numba's
        compilation, caches); its wall time is kept in `warmups`."""
        if method not in self.warm:
            self.warm.add(method)
            raw = self.solve(WARM_UP, method, time_limit)
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

    def close(self) -> None:
        if self.proc is not None:
            if self.proc.is_alive():
                self.proc.kill()
            self.proc.join(timeout=10)
            self.conn.close()
            self.proc = self.conn = None
            self.warm = set()


class SiconosRunner:
    """Siconos's solvers (SICONOS_METHODS) in a long-lived /usr/bin/python3 subprocess
    (restarted after a timeout or a crash). `available` is False, with `reason`, when that
    interpreter has no siconos. A method is given only its kind of problem (others are
    refused, not_applicable); an MLCP's answer comes back as z = v with u, a friction-contact
    answer as z = r, for the harness to certify like any other."""

    def __init__(self, python: str = SYSTEM_PYTHON):
        self.python = python
        self.proc: subprocess.Popen | None = None
        self.lines: queue.Queue = queue.Queue()
        self.reason = ""
        self.version = ""
        self.kinds: set[str] = set()
        self.warm: set[str] = set()  # methods already run once by the current helper
        self.warmups: dict[str, list[float]] = {}  # {method: seconds of each warm-up solve}
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
        self.kinds = set(ready.get("kinds", ["lcp"]))
        return True

    def offers(self, method: str) -> bool:
        """Whether `method` (a SICONOS_METHODS name) can run: Siconos is available and its
        version has the solvers of the method's kind."""
        spec = SICONOS_METHODS.get(method)
        return self.available and spec is not None and spec.kind in self.kinds

    def solve(self, problem, method: str, time_limit: float) -> dict:
        spec = SICONOS_METHODS[method]
        prepared = self._prepare(problem, method, spec)
        if isinstance(prepared, dict) and "kind" in prepared:  # a refusal
            return prepared
        if method not in self.warm and spec.kind == "lcp" and problem is not WARM_UP:
            self.warm.add(method)  # one untimed solve per helper (as LocalRunner's methods)
            raw = self.solve(WARM_UP, method, time_limit)
            self.warmups.setdefault(method, []).append(float(raw.get("time", math.nan)))
            prepared = self._prepare(problem, method, spec)  # the warm-up's files replaced
        req, nu = prepared
        if self.proc is None or self.proc.poll() is not None:
            if not self._start():
                return {"kind": "error", "message": self.reason, "time": 0.0}
        self.proc.stdin.write(json.dumps(req) + "\n")
        self.proc.stdin.flush()
        deadline = time.monotonic() + time_limit + GRACE
        while True:  # skip any line that is not an answer (the helper prints only answers)
            try:
                line = self.lines.get(timeout=max(deadline - time.monotonic(), 0.0))
            except queue.Empty:
                self._kill()
                return {"kind": "timeout", "time": time_limit,
                        "message": f"no answer within {time_limit:g} s: killed"}
            if line is None:
                self._kill()
                return {"kind": "error", "message": "the Siconos helper died", "time": 0.0}
            try:
                out = json.loads(line)
            except ValueError:
                continue
            if isinstance(out, dict) and "info" in out:
                break
        ok = out["info"] == 0
        limit = req.get("max_iter")
        status = "solved" if ok else ("max_iter" if limit and out["iterations"] >= limit
                                      else "failed")
        z = np.array(out["z"], dtype=float)
        answer = {"kind": "answer", "z": z, "status": status, "iterations": out["iterations"],
                  "time": out["time"], "message": "" if ok else f"Siconos info = {out['info']} "
                  f"(its error {out['error']:.3g})"}
        if spec.kind == "mlcp":  # Siconos's z = [u; v]
            answer["u"], answer["z"] = z[:nu], z[nu:]
        return answer

    def _prepare(self, problem, method: str, spec: SiconosMethod):
        """(the helper's request, nu) with the problem's arrays written to .npy files, or a
        not_applicable answer when `method` is not given this problem."""
        def refuse(why: str) -> dict:
            return {"kind": "not_applicable", "time": 0.0, "message": f"{method} {why}"}

        tmp = Path(self.tmp.name)
        req: dict = {"kind": spec.kind, "solver": spec.solver, "max_iter": spec.max_iter,
                     "tol": spec.tol}
        nu = 0
        if spec.kind == "lcp":
            if isinstance(problem, lcp.MLCP):
                try:
                    problem = problem.to_lcp()
                except lcp.NotApplicable as exc:
                    return refuse(f"is given LCPs (an MLCP after its Schur reduction): {exc}")
            if not isinstance(problem, LCP):
                return refuse("is given LCPs and Schur-reducible MLCPs only")
            size, M, q = problem.n, problem.M, problem.q
            if spec.solver == "lemke":
                req["max_iter"] = 1000 + 100 * problem.n
        elif spec.kind == "mlcp":
            if not isinstance(problem, lcp.MLCP):
                return refuse("is given MLCPs only")
            size, nu = problem.n, problem.nu
            M = np.block([[problem.A, problem.C], [problem.D, problem.B]])
            q = np.concatenate([problem.a, problem.b])
            req["nu"] = nu
        else:
            if not isinstance(problem, lcp.FrictionContact2D):
                return refuse("is given 2D friction-contact problems only")
            size, q, M = problem.c, problem.q, None
            np.save(tmp / "mu.npy", problem.mu)
            req["mu"] = str(tmp / "mu.npy")
            if sp.issparse(problem.W):
                W = sp.coo_matrix(problem.W)
                for key, arr in (("rows", W.row), ("cols", W.col), ("vals", W.data)):
                    np.save(tmp / f"{key}.npy", np.asarray(arr))
                    req[key] = str(tmp / f"{key}.npy")
                req["shape"] = list(W.shape)
            else:
                np.save(tmp / "W.npy", problem.W)
                req["W"] = str(tmp / "W.npy")
        if spec.max_size is not None and size > spec.max_size:
            what = {"lcp": "n", "mlcp": "m", "fc2d": "c (contacts)"}[spec.kind]
            return refuse(f"is given {what} <= {spec.max_size} only (exhaustive)")
        if M is not None:
            np.save(tmp / "M.npy", M)
            req["M"] = str(tmp / "M.npy")
        np.save(tmp / "q.npy", q)
        req["q"] = str(tmp / "q.npy")
        return req, nu

    def _kill(self) -> None:
        if self.proc is not None:
            if self.proc.poll() is None:
                self.proc.kill()
            self.proc.wait(timeout=10)
            self.proc = None
            self.warm = set()

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
