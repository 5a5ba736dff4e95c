"""Siconos's LCP, MLCP and 2D friction-contact solvers (SICONOS_METHODS) as bench methods, in a
long-lived /usr/bin/python3 subprocess (_siconos_helper.py) that has Debian's python3-siconos;
its answers are raw answers for rigidlcp.bench.harness.judge, like LocalRunner's
(rigidlcp.bench.runners). (Not named siconos.py: the helper runs as a script from this folder,
where such a file would shadow the siconos package.)"""

from __future__ import annotations

import json
import math
import os
import queue
import subprocess
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from rigidlcp import lcp
from rigidlcp.lcp import LCP

from .runners import GRACE, WARM_UP

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
