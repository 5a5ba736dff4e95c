"""Run by /usr/bin/python3 (Debian's python3-siconos): read a Siconos problem file with
Siconos's own reader and save its arrays to an .npz (tests compare them with lcp.io's).
Usage: siconos_dump.py KIND FILE OUT.npz   (KIND: lcp, mlcp, fc2d). Imports nothing of rigidlcp.
"""

import sys

import numpy as np
import scipy.sparse  # noqa: F401  (siconos converts sparse matrices through scipy)
import scipy.sparse.coo  # noqa: F401
import scipy.sparse.csc  # noqa: F401
import siconos.numerics as sn


def dense(M, shape=None):
    if isinstance(M, np.ndarray):
        return M
    if hasattr(M, "toarray"):
        return M.toarray()
    if type(M).__name__ == "SparseBlockStructuredMatrix":
        return np.array([[sn.SBM_get_value(M, i, j) for j in range(shape[1])]
                         for i in range(shape[0])])
    if getattr(M, "storageType", None) == sn.NM_DENSE:  # NM_csc would drop tiny entries
        return np.array([[M.get_matrix0(i, j) for j in range(M.size1)] for i in range(M.size0)])
    if getattr(M, "storageType", None) == sn.NM_SPARSE_BLOCK:
        return dense(M.matrix1, (M.size0, M.size1))
    for conv in (sn.NM_csc, sn.NM_triplet):
        try:
            return conv(M).toarray()
        except Exception:  # noqa: BLE001
            continue
    d = sn.NM_create(sn.NM_DENSE, M.size0, M.size1)
    sn.NM_to_dense(M, d)
    return np.array([[d.get_matrix0(i, j) for j in range(M.size1)] for i in range(M.size0)])


def main() -> None:
    kind, path, out = sys.argv[1:4]
    if kind == "lcp":
        with open(path) as fh:
            n = int(fh.read().split()[0])
        p = sn.LCP(np.eye(n), np.zeros(n))
        sn.linearComplementarity_newFromFilename(p, path)
        np.savez(out, M=dense(p.M, (n, n)), q=np.array(p.q))
    elif kind == "mlcp":
        p = sn.MLCP()
        sn.mixedLinearComplementarity_newFromFilename(p, path)
        np.savez(out, M=dense(p.M), q=np.array(p.q), n=p.n, m=p.m)
    else:
        p = sn.frictionContact_new_from_filename(path)
        np.savez(out, W=dense(p.M), q=np.array(p.q), mu=np.array(p.mu), d=p.dimension)


main()
