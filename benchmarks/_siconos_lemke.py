"""Helper of benchmarks/lcp_dense.py, run by the system interpreter (/usr/bin/python3) that has
Debian's python3-siconos: Siconos's lexicographic Lemke (``lcp_lexicolemke``, SICONOS_LCP_LEMKE)
on LCPs passed as .npy files.

Protocol (one JSON object per line): the helper first prints {"ready": true, "numpy": ...} or
{"ready": false, "error": ...}; then for every request {"M": path, "q": path, "max_iter": k} it
solves once (or "inner" times in a row, reporting the mean) and prints {"time": wall seconds
of the solve call only, "cpu": its CPU seconds (process time), "iterations": Siconos's pivot
count, "info": return code, "residual": max|min(z, M z + q)|, "z": the answer}. End of input
ends it. The direct lcp_lexicolemke call returns info = 0 on answers that are not solutions
(27 of Fig. 9's 74 event LCPs; Siconos's driver reports those as failures): the callers judge
every "z" with rigidlcp's own check (verify.certify), never by info.

Siconos counts the pivots of its main loop, i.e. every pivot except the first (z0 entering).
"""

from __future__ import annotations

import json
import sys
import time


def main() -> int:
    try:
        import numpy as np
        import siconos.numerics as sn
    except Exception as exc:  # noqa: BLE001 - any import failure means "skip"
        print(json.dumps({"ready": False, "error": f"{type(exc).__name__}: {exc}"}), flush=True)
        return 0
    print(json.dumps({"ready": True, "numpy": np.__version__}), flush=True)
    for line in sys.stdin:
        if not line.strip():
            continue
        req = json.loads(line)
        if "Ms" in req:
            print(json.dumps(_batch(np, sn, req)), flush=True)
            continue
        if "set_Ms" in req:
            print(json.dumps(_timed_set(np, sn, req)), flush=True)
            continue
        M = np.ascontiguousarray(np.load(req["M"]), dtype=float)
        q = np.ascontiguousarray(np.load(req["q"]), dtype=float)
        n = q.size
        problem = sn.LCP(M, q)
        options = sn.SolverOptions(sn.SICONOS_LCP_LEMKE)
        options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = int(req.get("max_iter", 10000))
        z, w = np.zeros(n), np.zeros(n)
        inner = int(req.get("inner", 1))  # consecutive calls timed together (warm caches)
        c0, t0 = time.process_time(), time.perf_counter()
        for _ in range(inner):
            info = sn.lcp_lexicolemke(problem, z, w, options)
        elapsed = (time.perf_counter() - t0) / inner
        cpu = (time.process_time() - c0) / inner
        residual = float(np.max(np.abs(np.minimum(z, M @ z + q))))
        out = {
            "time": elapsed,
            "cpu": cpu,
            "iterations": int(options.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
            "info": int(info) if info is not None else None,
            "residual": residual,
            "z": [float(v) for v in z],
        }
        print(json.dumps(out), flush=True)
    return 0


def _batch(np, sn, req: dict) -> dict:
    """A loop of lcp_lexicolemke over stacked problems {"Ms": path (k, n, n), "qs": path}:
    "loop" = wall seconds of the whole loop (problem objects, options, solve), "calls" = the sum
    of the solver calls only; the pivots, the worst residual and the answers "zs" (to judge)."""
    Ms, qs = np.load(req["Ms"]), np.load(req["qs"])
    k, n = qs.shape
    Ms = [np.ascontiguousarray(Ms[i]) for i in range(k)]
    qs = [np.ascontiguousarray(qs[i]) for i in range(k)]
    Z, W = np.zeros((k, n)), np.zeros((k, n))
    infos, pivots, calls = [], [], 0.0
    max_iter = int(req.get("max_iter", 10000))
    t0 = time.perf_counter()
    for i in range(k):
        problem = sn.LCP(Ms[i], qs[i])
        options = sn.SolverOptions(sn.SICONOS_LCP_LEMKE)
        options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = max_iter
        c0 = time.perf_counter()
        infos.append(sn.lcp_lexicolemke(problem, Z[i], W[i], options))
        calls += time.perf_counter() - c0
        pivots.append(int(options.iparam[sn.SICONOS_IPARAM_ITER_DONE]))
    loop = time.perf_counter() - t0
    res = max(float(np.max(np.abs(np.minimum(Z[i], Ms[i] @ Z[i] + qs[i])))) for i in range(k))
    return {"loop": loop, "calls": calls, "pivots": pivots,
            "failures": sum(1 for x in infos if x), "residual": res, "zs": Z.tolist()}


def _timed_set(np, sn, req: dict) -> dict:
    """benchmarks/peers_small.py: the mean seconds per call over stacked problems {"set_Ms":
    path (k, n, n), "set_qs": path}, each called "inner" times in a row, "how" = "natural"
    (solver options, problem object, linearComplementarity_driver: all timed), "driver"
    (linearComplementarity_driver on a prebuilt problem and options) or "bare"
    (lcp_lexicolemke on a prebuilt problem and options: the solver alone); "zs": the
    answers of the last call, to be judged by the caller. "clock": "cpu" times by the CPU time
    of this thread (time.thread_time) instead of the wall clock."""
    Ms, qs = np.load(req["set_Ms"]), np.load(req["set_qs"])
    k, n = qs.shape
    Ms = [np.ascontiguousarray(Ms[i]) for i in range(k)]
    qs = [np.ascontiguousarray(qs[i]) for i in range(k)]
    inner, max_iter = int(req.get("inner", 1)), int(req.get("max_iter", 10000))
    Z, W = np.zeros((k, n)), np.zeros((k, n))
    clock = time.thread_time if req.get("clock") == "cpu" else time.perf_counter
    total = 0.0
    for i in range(k):
        M, q, z, w = Ms[i], qs[i], Z[i], W[i]
        if req["how"] == "natural":
            t0 = clock()
            for _ in range(inner):
                options = sn.SolverOptions(sn.SICONOS_LCP_LEMKE)
                options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = max_iter
                sn.linearComplementarity_driver(sn.LCP(M, q), z, w, options)
            total += clock() - t0
            continue
        problem = sn.LCP(M, q)
        options = sn.SolverOptions(sn.SICONOS_LCP_LEMKE)
        options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = max_iter
        if req["how"] == "driver":
            t0 = clock()
            for _ in range(inner):
                sn.linearComplementarity_driver(problem, z, w, options)
            total += clock() - t0
        else:
            options = sn.SolverOptions(sn.SICONOS_LCP_LEMKE)
            options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = max_iter
            t0 = clock()
            for _ in range(inner):
                sn.lcp_lexicolemke(problem, z, w, options)
            total += clock() - t0
    return {"per_call": total / (k * inner), "zs": Z.tolist()}


if __name__ == "__main__":
    sys.exit(main())
