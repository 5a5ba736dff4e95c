"""Helper of rigidlcp.bench.siconos_runner, run by the system interpreter (/usr/bin/python3)
that has Debian's python3-siconos: Siconos's LCP, MLCP and 2D friction-contact solvers on problems
passed as .npy files. It imports nothing of rigidlcp (it runs under another interpreter, with
that interpreter's numpy).

Protocol, one JSON object per line on the helper's original standard output (Siconos's C code
prints to file descriptor 1, which is pointed at standard error here so that its messages
never mix with the answers): the helper first prints {"ready": true, "version": ..., "kinds":
[...]} or {"ready": false, "error": ...}. Then for every request

* {"kind": "lcp", "M": path, "q": path, "solver": "lemke" | "enum" | "pgs", ...}:
  ``linearComplementarity_driver`` on 0 <= z perp M z + q >= 0;
* {"kind": "mlcp", "M": path, "q": path, "nu": k, "solver": "enum" | "direct_enum" | "fb"}:
  ``mlcp_driver`` on Siconos's MLCP(nu, M, q), M = [[A, C], [D, B]], q = [a; b] (storage 1),
  z = [u; v];
* {"kind": "fc2d", "W": path (dense) or "rows"/"cols"/"vals"/"shape" (sparse triplets), "q":
  path, "mu": path, "solver": "nsgs" | "lemke" | "enum"}: ``fc2d_driver`` on
  FrictionContactProblem(2, W, q, mu), W dense or sparse-block (2 x 2 blocks), z = r;

with optional "max_iter" and "tol" (SICONOS_IPARAM_MAX_ITER, SICONOS_DPARAM_TOL), it solves
once and prints {"z": [...], "time": wall seconds of the whole call from Python
(solver options, problem object, driver; mlcp: with ``mlcp_driver_init``), "iterations":
SICONOS_IPARAM_ITER_DONE, "info": the return code (0 is
success), "error": Siconos's own residual (SICONOS_DPARAM_RESIDU)}. End of input ends it.
"""

from __future__ import annotations

import json
import os
import sys
import time


def _protocol_stream():
    """A private copy of standard output for the answers; fd 1 (where Siconos's C code
    prints) then goes to standard error."""
    out = os.fdopen(os.dup(1), "w", buffering=1)
    sys.stdout.flush()
    os.dup2(2, 1)
    return out


def _fc2d_matrix(sn, np, req):
    """(W, keep): W as Siconos's fc2d_driver takes it, a dense array or a sparse-block
    NumericsMatrix (2 x 2 blocks) built from the triplets (through scipy's CSC); keep: the
    Python objects that own W's memory (the block matrix is freed with its proxy), to be held
    as long as W is used."""
    if "W" in req:
        return np.ascontiguousarray(np.load(req["W"]), dtype=float), None
    rows, cols = np.load(req["rows"]), np.load(req["cols"])
    vals = np.load(req["vals"])
    shape = tuple(req["shape"])
    try:
        import scipy.sparse as sp
    except Exception:  # noqa: BLE001 - no scipy: a dense W
        W = np.zeros(shape)
        np.add.at(W, (rows, cols), vals)
        return W, None
    W = sp.csc_matrix((vals, (rows, cols)), shape=shape)
    W.indices = W.indices.astype(np.int64)
    W.indptr = W.indptr.astype(np.int64)
    holder = sn.FrictionContactProblem(2, W, np.zeros(shape[0]), np.zeros(shape[0] // 2))
    rc, sbm = sn.SBM_from_csparse(2, holder.M.matrix2.csc)
    if rc != 0:
        raise RuntimeError(f"SBM_from_csparse returned {rc}")
    return sn.NM_new_SBM(shape[0], shape[1], sbm), (holder, sbm)


def main() -> int:
    out = _protocol_stream()
    try:
        import warnings

        import numpy as np
        import siconos.numerics as sn

        warnings.simplefilter("ignore")
    except Exception as exc:  # noqa: BLE001 - any import failure means "not available"
        print(json.dumps({"ready": False, "error": f"{type(exc).__name__}: {exc}"}), file=out)
        return 0
    solvers = {
        "lcp": {"lemke": "SICONOS_LCP_LEMKE", "enum": "SICONOS_LCP_ENUM",
                "pgs": "SICONOS_LCP_PGS"},
        "mlcp": {"enum": "SICONOS_MLCP_ENUM", "direct_enum": "SICONOS_MLCP_DIRECT_ENUM",
                 "fb": "SICONOS_MLCP_FB"},
        "fc2d": {"nsgs": "SICONOS_FRICTION_2D_NSGS", "lemke": "SICONOS_FRICTION_2D_LEMKE",
                 "enum": "SICONOS_FRICTION_2D_ENUM"},
    }
    kinds = [k for k, names in solvers.items() if all(hasattr(sn, v) for v in names.values())]
    version = getattr(sn, "__version__", "") or getattr(sys.modules.get("siconos"),
                                                        "__version__", "?")
    print(json.dumps({"ready": True, "version": str(version), "numpy": np.__version__,
                      "kinds": kinds}), file=out)
    for line in sys.stdin:
        if not line.strip():
            continue
        req = json.loads(line)
        kind = req.get("kind", "lcp")
        q = np.ascontiguousarray(np.load(req["q"]), dtype=float)
        z, w = np.zeros(q.size), np.zeros(q.size)
        if kind == "fc2d":
            mu = np.ascontiguousarray(np.load(req["mu"]), dtype=float)
            W, _keep = _fc2d_matrix(sn, np, req)
        else:
            M = np.ascontiguousarray(np.load(req["M"]), dtype=float)
        # the whole call from Python, as rigidlcp's lcp.solve is timed: options, problem
        # object, driver (the arrays' transport through .npy files is not timed)
        t0 = time.perf_counter()
        options = sn.SolverOptions(getattr(sn, solvers[kind][req["solver"]]))
        if req.get("max_iter") is not None:
            options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = int(req["max_iter"])
        if req.get("tol") is not None:
            options.dparam[sn.SICONOS_DPARAM_TOL] = float(req["tol"])
        if kind == "lcp":
            problem = sn.LCP(M, q)
            info = sn.linearComplementarity_driver(problem, z, w, options)
            elapsed = time.perf_counter() - t0
        elif kind == "mlcp":
            problem = sn.MLCP(int(req["nu"]), M, q)
            sn.mlcp_driver_init(problem, options)
            info = sn.mlcp_driver(problem, z, w, options)
            elapsed = time.perf_counter() - t0
            sn.mlcp_driver_reset(problem, options)
        else:
            problem = sn.FrictionContactProblem(2, W, q, mu)
            info = sn.fc2d_driver(problem, z, w, options)
            elapsed = time.perf_counter() - t0
        answer = {
            "z": [float(v) for v in z],
            "time": elapsed,
            "iterations": int(options.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
            "info": int(info) if info is not None else None,
            "error": float(options.dparam[sn.SICONOS_DPARAM_RESIDU]),
        }
        print(json.dumps(answer), file=out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
