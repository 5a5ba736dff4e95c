"""Helper of bench.harness, run by the system interpreter (/usr/bin/python3) that has Debian's
python3-siconos: Siconos's LCP solvers on problems passed as .npy files. It imports nothing of
rigidlcp (it runs under another interpreter, with that interpreter's numpy).

Protocol, one JSON object per line: the helper first prints {"ready": true, "version": ...} or
{"ready": false, "error": ...}. Then for every request
{"M": path, "q": path, "solver": "lemke" | "enum" | "pgs", "max_iter": k, "tol": t} it solves
once through ``linearComplementarity_driver`` and prints {"z": [...], "time": wall seconds of
the driver call only, "iterations": SICONOS_IPARAM_ITER_DONE, "info": the return code (0 is
success), "error": Siconos's own residual (SICONOS_DPARAM_RESIDU)}. End of input ends it.
"""

from __future__ import annotations

import json
import sys
import time


def main() -> int:
    try:
        import numpy as np
        import siconos.numerics as sn
    except Exception as exc:  # noqa: BLE001 - any import failure means "not available"
        print(json.dumps({"ready": False, "error": f"{type(exc).__name__}: {exc}"}), flush=True)
        return 0
    solvers = {"lemke": sn.SICONOS_LCP_LEMKE, "enum": sn.SICONOS_LCP_ENUM,
               "pgs": sn.SICONOS_LCP_PGS}
    version = getattr(sn, "__version__", "") or getattr(sys.modules.get("siconos"),
                                                        "__version__", "?")
    print(json.dumps({"ready": True, "version": str(version), "numpy": np.__version__}),
          flush=True)
    for line in sys.stdin:
        if not line.strip():
            continue
        req = json.loads(line)
        M = np.ascontiguousarray(np.load(req["M"]), dtype=float)
        q = np.ascontiguousarray(np.load(req["q"]), dtype=float)
        n = q.size
        options = sn.SolverOptions(solvers[req["solver"]])
        if req.get("max_iter") is not None:
            options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = int(req["max_iter"])
        if req.get("tol") is not None:
            options.dparam[sn.SICONOS_DPARAM_TOL] = float(req["tol"])
        z, w = np.zeros(n), np.zeros(n)
        problem = sn.LCP(M, q)
        t0 = time.perf_counter()
        info = sn.linearComplementarity_driver(problem, z, w, options)
        elapsed = time.perf_counter() - t0
        out = {
            "z": [float(v) for v in z],
            "time": elapsed,
            "iterations": int(options.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
            "info": int(info) if info is not None else None,
            "error": float(options.dparam[sn.SICONOS_DPARAM_RESIDU]),
        }
        print(json.dumps(out), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
