"""The hot loop of Lemke's method -- ratio test, lexicographic tie-break, pivot -- compiled.

`pivot_loop(T, basic, nonbasic, row_of, slot_of, tol, max_iter)` runs Lemke's pivots on the
dictionary of `lcp.lemke._Lemke` (docs/lemke.md, "The dictionary") in C (lcp/_lemke_c.c,
built by setup.py as an optional extension) and returns (code, pivots, s, entering):
code 0 = z0 left (solved), 1 = a basis repeated (numerical cycling), 2 = pivot limit,
3 = secondary ray (slot s of the unblocked entering variable). The arrays are updated in place.
The C loop applies the same rules in the same order as the numpy loop of `_Lemke.run`
(the fallback when the extension is not built), so both take the same pivots
(tests/lcp/test_lemke_kernel.py compares the sequences).

Set the environment variable RIGIDLCP_NO_KERNEL=1 (or call `use_compiled(False)`) to run the
numpy loop even when the extension is built.
"""

from __future__ import annotations

import os

import numpy as np

try:
    from . import _lemke_c
except ImportError:  # not built (no C compiler at install): the numpy loop runs instead
    _lemke_c = None

#: Is the compiled loop built?
COMPILED = _lemke_c is not None
_use = COMPILED and os.environ.get("RIGIDLCP_NO_KERNEL", "") in ("", "0")

SOLVED, CYCLING, MAX_ITER, RAY = 0, 1, 2, 3
#: Codes of `solve_eq` / `solve_batch(..., equilibrate=True)` besides those of the loop: M is
#: not balanced (run lcp.scaling.ruiz and pass its factors), the equilibrated data are not
#: finite (lemke() refuses them: leave it to the general path).
NEEDS_RUIZ, NOT_FINITE = 4, 5


def enabled() -> bool:
    """Will `lcp.lemke` use the compiled loop?"""
    return _use


def use_compiled(flag: bool) -> bool:
    """Switch the compiled loop on or off (on only when built); returns the previous setting."""
    global _use
    previous, _use = _use, bool(flag) and COMPILED
    return previous


def run(lemke_run, max_iter: int):
    """`_Lemke.run` in C: the pivots on `lemke_run`'s dictionary, then its outcome (solution,
    ray, pivot limit, cycling) built by its own methods. Its bookkeeping becomes int64 arrays,
    updated in place (the outcome methods read them as they read the lists)."""
    L = lemke_run
    n = L.n
    L.row_of, L.nonbasic = np.array(L.row_of), np.arange(n, 2 * n + 1)
    L.basic, L.slot_of = L.basic_np, L.slot_np
    trace = None if L.trace is None else np.full(2 * (max_iter + 1), -1, dtype=np.int64)
    code, pivots, s, entering = pivot_loop(L.T, L.basic_np, L.nonbasic, L.row_of, L.slot_np,
                                           L.tol, max_iter, trace)
    if trace is not None:
        L.trace.extend(map(tuple, trace[: 2 * pivots].reshape(-1, 2).tolist()))
    if code == SOLVED:
        return L.solution(pivots)
    if code == RAY:
        return L.ray(pivots, s, entering)
    sol = L.stopped(pivots)
    if code == CYCLING:
        sol.message = f"numerical cycling: a basis repeated after {pivots} pivots"
        sol.info["cycling"] = True
    return sol


def pivot_loop(T: np.ndarray, basic: np.ndarray, nonbasic: np.ndarray, row_of: np.ndarray,
               slot_of: np.ndarray, tol: float, max_iter: int,
               trace: np.ndarray | None = None) -> tuple[int, int, int, int]:
    """Run the pivots (compiled); `trace` (int64, length 2 k) receives (row, slot) of the first
    k pivots."""
    return _lemke_c.run(T, basic, nonbasic, row_of, slot_of, float(tol), int(max_iter), trace)


def setup(T: np.ndarray, M: np.ndarray, q: np.ndarray, d: np.ndarray) -> tuple[float, float, float]:
    """Fill the dictionary T = [M / mu, d / delta, q / nu] (compiled); returns (mu, nu, delta)."""
    return _lemke_c.setup(T, np.ascontiguousarray(M), q, d)


def plain_finite(M, q) -> tuple[bool, float]:
    """(True, min q) when M (n x n) and q (n) are C-contiguous float64 arrays with finite entries
    (then they need no conversion); (False, nan) otherwise (the caller validates them)."""
    if (_use and type(M) is np.ndarray and type(q) is np.ndarray and M.dtype == np.float64
            and q.dtype == np.float64 and q.ndim == 1 and q.size > 0
            and M.shape == (q.size, q.size) and M.flags.c_contiguous
            and q.flags.c_contiguous):
        return _lemke_c.check(M, q)
    return False, float("nan")


def solve_batch(Ms: np.ndarray, qs: np.ndarray, d: np.ndarray, tol: float, max_iter: int,
                Z: np.ndarray, basic: np.ndarray, codes: np.ndarray, pivots: np.ndarray,
                equilibrate: bool = False, acc: np.ndarray | None = None,
                mmax: np.ndarray | None = None) -> None:
    """k LCPs (Ms: k x n x n, qs: k x n, finite, C-contiguous) by Lemke in one compiled loop:
    z into Z, basic z's into basic (int8), status codes and pivots (int64). Only code SOLVED
    leaves a z; the others are to be solved again one by one for their evidence.
    equilibrate: each problem on its equilibrated data, as `solve_eq` with r = c = None (code
    NEEDS_RUIZ for a problem whose M is not balanced); z in the original units.
    acc (k x 4 float64): each solved answer also assessed on (M, q) as `lcp.acceptance.accuracy.
    assess_lcp` does in C, acc[p] = (acode, berr, ferr, refined) -- acode 0: done, Z[p] the
    answer (polished when refined); 1: to be judged in numpy; -1: numbers too large for the
    fast check (solve it alone). mmax (k float64): max|M_p| of each solved problem (its M then
    finite), -1 for the others: `measure_batch` takes it instead of measuring it again."""
    _lemke_c.solve_batch(Ms, qs, d, float(tol), int(max_iter), Z, basic, codes, pivots,
                         int(bool(equilibrate)), acc, mmax)


def solve_eq(M: np.ndarray, q: np.ndarray, r: np.ndarray | None, c: np.ndarray | None,
             tol: float, max_iter: int, z: np.ndarray, basis: np.ndarray
             ) -> tuple[int, int, int, tuple[float, float, float]]:
    """One LCP by Lemke (covering vector ones) on its Ruiz-equilibrated data, as `lcp.solve`
    runs it by default (lcp.scaling.ruiz, then lemke(), then z mapped back), in one C call with
    the same roundings: r = c = None when M is balanced (`ruiz` then only changes the unit of q,
    done in C; code NEEDS_RUIZ otherwise), else the factors of `ruiz` (Eq. 1 of lcp.scaling:
    M~ = diag(r) M diag(c), q~ = r q, z = c z~). M: n x n, q, r, c, z: n, C-contiguous float64;
    basis: int64 of length n. Returns (code, pivots, m, (max|M|, max|q|, max|z|)): on SOLVED,
    z holds the answer (0 when q~ >= 0, with no pivot) and basis[:m] the basic z's, sorted."""
    return _lemke_c.solve_eq(M, q, r, c, None, float(tol), int(max_iter), z, basis)


def measure(M: np.ndarray, q: np.ndarray, z: np.ndarray, Mz: np.ndarray
            ) -> tuple[float, float, float, float] | None:
    """lcp.residual's measure after numpy's Mz = M.dot(z), in C: Mz becomes w = M z + q, and
    (max|min(z, w)|, scaled residual, z_s, w_s) is returned, the row sums of |M| summed in
    numpy's order (checked once on a probe: `sums_verified_upto`). None -- Mz untouched -- when
    not compiled or switched off, when rows are longer than the probe verified, or when an
    input is not a finite float64 C-contiguous array of the right size (numpy measures then)."""
    if not _use or M.shape[-1] > sums_verified_upto():
        return None
    return _lemke_c.lcp_measure(M, q, z, Mz)


def measure_batch(Ms: np.ndarray, qs: np.ndarray, Z: np.ndarray, MZ: np.ndarray,
                  mmax: np.ndarray | None = None) -> np.ndarray | None:
    """`measure` of k problems at once (Ms: k x n x n, qs, Z, MZ: k x n): a k x 4 array of
    (residual, scaled residual, z_s, w_s), NaN in the rows of problems not measured (MZ[p]
    untouched there; the others become w = M z + q); None where `measure` gives None for all.
    mmax: `solve_batch`'s (max|M_p| where >= 0: not measured again; the same numbers)."""
    if not _use or qs.shape[-1] > sums_verified_upto():
        return None
    out = np.empty((qs.shape[0], 4))
    return out if _lemke_c.lcp_measure_batch(Ms, qs, Z, MZ, out, mmax) else None


#: Row lengths the probe tries, in increasing order.
PROBE_SIZES = (*range(1, 20), 31, 64, 100, 127, 128, 129, 200, 255, 300, 1000, 4099, 10007)
_sums_upto: int | None = None


def sums_verified_upto() -> int:
    """The longest row for which the C row sum of |M| is known to round as numpy's
    np.add.reduce(np.abs(M), axis=1): rows of the lengths PROBE_SIZES, whose terms span 120
    binary orders of magnitude with varied mantissas and signs (any other order of summation
    shows), are summed both ways in increasing length until one differs; the last length that
    agreed is remembered (0: none). numpy's pairwise order for very long rows differs between
    its versions (numpy 1.24-2.2 differ from 2.3+ at 10007), so `measure` uses C only up to
    this length. (No numpy.random: importing it would cost more than the probe.)"""
    global _sums_upto
    if _sums_upto is None:
        upto = 0
        for n in PROBE_SIZES:
            k = np.arange(2 * n).reshape(2, n)
            P = np.exp2((k * 7919 % 241 - 120).astype(float)) * (1.0 + (k * 31 % 17) / 17.0)
            P[:, 1::3] *= -1.0
            out = np.empty(2)
            _lemke_c.abs_row_sums(P, out, n)
            if not np.array_equal(out, np.add.reduce(np.abs(P), axis=1)):
                break
            upto = n
        _sums_upto = upto
    return _sums_upto


def sums_as_numpy() -> bool:
    """Whether the C row sums round as numpy's at every probed length (`sums_verified_upto`)."""
    return sums_verified_upto() >= PROBE_SIZES[-1]


def solve_one(M: np.ndarray, q: np.ndarray, d: np.ndarray, tol: float, max_iter: int):
    """One LCP by the compiled loop, start to end: (z, basis, pivots) when it is solved, None
    otherwise (the caller reruns `_Lemke` for the evidence of a ray, a limit or a cycle).
    M, q: C-contiguous float64 and finite (see `plain_finite`); q not >= 0."""
    n = q.size
    Z = np.empty((1, n))
    basic = np.empty((1, n), dtype=np.int8)
    codes = np.empty(1, dtype=np.int64)
    pivots = np.empty(1, dtype=np.int64)
    _lemke_c.solve_batch(M, q, d, float(tol), int(max_iter), Z, basic, codes, pivots)
    if codes[0] != SOLVED:
        return None
    return Z[0], basic[0].nonzero()[0], int(pivots[0])


#: numpy's BLAS whose cblas_dgemv `numpy_gemv` looks for: (BLAS name in numpy's build
#: configuration, library file pattern in numpy.libs, symbol of 64-bit or 32-bit integers)
_GEMV_LIBS = (("scipy-openblas", "libscipy_openblas*", "scipy_cblas_dgemv64_",
               "scipy_cblas_dgemv"),)
_GEMV_PROBE = (2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 15, 16, 17, 31, 32, 33, 63, 64, 65, 100,
               127, 128, 129, 200, 301)
_gemv_found: bool | None = None


def _gemv_address() -> tuple[int, bool] | None:
    """(address, 64-bit integers) of the cblas_dgemv in the BLAS library numpy loaded, or None
    (another BLAS, numpy without a build configuration, the library not loaded)."""
    try:
        import ctypes  # numpy has imported it already

        blas = np.__config__.CONFIG["Build Dependencies"]["blas"]
        name, config = blas.get("name"), str(blas.get("openblas configuration", ""))
    except Exception:  # noqa: BLE001 - numpy < 1.26 or another layout: no direct call
        return None
    from pathlib import Path

    for lib_name, pattern, sym64, sym32 in _GEMV_LIBS:
        if name != lib_name:
            continue
        ilp64 = "USE64BITINT" in config
        for path in sorted((Path(np.__file__).parent.parent / "numpy.libs").glob(pattern)):
            try:  # the copy numpy loaded, never a second one
                lib = ctypes.CDLL(str(path), mode=os.RTLD_NOLOAD | ctypes.RTLD_LOCAL)
                address = ctypes.cast(getattr(lib, sym64 if ilp64 else sym32),
                                      ctypes.c_void_p).value
            except (OSError, AttributeError):
                continue
            if address:
                return address, ilp64
    return None


def numpy_gemv() -> bool:
    """Does the C fast path take M z by numpy's own cblas_dgemv (lcp/_blas.h)? Found once: the
    function numpy's dot calls for a C-contiguous float64 matrix times a vector, in the BLAS
    library numpy loaded, then checked against np.dot on matrices of the sizes _GEMV_PROBE
    (entries over 120 binary orders of magnitude, varied mantissas and signs: any other order
    of summation or fused multiply-add shows; then within 4 orders, where every term counts),
    bit for bit; any difference and it is not used
    (M z then comes from np.dot, called from C)."""
    global _gemv_found
    if _gemv_found is None:
        _gemv_found = False
        found = _gemv_address() if COMPILED else None
        if COMPILED:
            _lemke_c.gemv_setup(*(found or (0, False)))
        if found is not None:
            ok = True
            for n in _GEMV_PROBE:
                k = np.arange(n * (n + 1)).reshape(n + 1, n)
                for e in (k * 7919 % 241 - 120, k * 7 % 9 - 4):  # wide, then close scales
                    P = np.exp2(e.astype(float)) * (1.0 + (k * 31 % 17) / 17.0)
                    P[:, 1::3] *= -1.0
                    M, z, w = P[:n], P[n], np.empty(n)
                    ok = ok and bool(_lemke_c.gemv(M, z, w)) and (
                        w.tobytes() == np.dot(M, z).tobytes())
                if not ok:
                    break
            if not ok:
                _lemke_c.gemv_setup(0, False)
            _gemv_found = ok
    return _gemv_found


_arrays_found: bool | None = None


def _array_capsule():
    """numpy's table of C functions for extensions (the capsule `_ARRAY_API`), or None."""
    import importlib

    for name in ("numpy._core._multiarray_umath", "numpy.core._multiarray_umath"):
        try:
            return importlib.import_module(name)._ARRAY_API
        except (ImportError, AttributeError):
            continue
    return None


def _flags(a: np.ndarray) -> tuple[bool, ...]:
    return tuple(a.flags[f] for f in ("C_CONTIGUOUS", "F_CONTIGUOUS", "OWNDATA", "WRITEABLE",
                                      "ALIGNED", "WRITEBACKIFCOPY"))


def numpy_arrays() -> bool:
    """Do the C calls make their new arrays (lcp.LCP's copies of M and q, a Solution's z, w and
    basis) by numpy's own PyArray_NewFromDescr (lcp/_numpy_abi.h) rather than by calling
    numpy.empty? Found once: the function is taken from numpy's C-API table when its ABI
    version and ndarray type are the known ones, then arrays made by it (1-D and 2-D, float64
    and intp, empty included) are checked against numpy.empty's -- type, dtype, shape,
    strides, flags, no base -- and their entries, written through the data pointer read in C,
    against 0, 1, 2, ...; any difference and numpy.empty is called as before."""
    global _arrays_found
    if _arrays_found is None:
        _arrays_found = False
        if COMPILED and hasattr(_lemke_c, "array_setup"):  # (an older build has not)
            intp = np.dtype(np.intp)
            ok = intp.itemsize == 8 and bool(_lemke_c.array_setup(
                _array_capsule(), np.dtype(np.float64), intp, np.ndarray))
            for shape in ((0,), (1,), (10,), (3, 3), (30, 30), (0, 0)) if ok else ():
                for integer in (False, True):
                    got = _lemke_c.array_probe(shape, integer)
                    ref = np.empty(shape, np.intp if integer else np.float64)
                    ok = ok and (type(got) is np.ndarray and got.dtype is ref.dtype
                                 and got.shape == ref.shape and got.strides == ref.strides
                                 and _flags(got) == _flags(ref) and got.base is None
                                 and np.array_equal(got.ravel(), np.arange(got.size)))
            if not ok:
                _lemke_c.array_setup(None, np.dtype(np.float64), np.dtype(np.intp),
                                     np.ndarray)
            _arrays_found = ok
            _lemke_c.array_fields_use(ok and _fields_read_as_numpy())
    return _arrays_found


def _fields_read_as_numpy() -> bool:
    """Does lcp/_numpy_abi.h read an array's data pointer, dimensions, strides, dtype and its
    C-contiguous and writeable flags as numpy itself gives them? Checked on probes -- C and
    Fortran order, a strided view, a view at an offset, read-only, 0-d to 2-d, float64 and
    other dtypes -- before the C calls read plain float64 arrays' data from their fields
    instead of asking for a buffer (`plain_f64`)."""
    if not hasattr(_lemke_c, "array_fields"):
        return False
    base = np.arange(60.0).reshape(6, 10)
    ro = np.ones((3, 3))
    ro.flags.writeable = False
    probes = [np.empty((30, 30)), np.empty(7), np.zeros(()), base, base[1:4, 2:5], base[:, ::2],
              base.T, base[2], ro, np.asfortranarray(np.ones((4, 4))), np.ones(5, np.float32),
              np.ones((2, 2), np.intp), np.empty((0, 3))]
    for a in probes:
        address, nd, shape, strides, dtype, c_contiguous, writeable = _lemke_c.array_fields(a)
        if (address != a.__array_interface__["data"][0] or nd != a.ndim or shape != a.shape
                or strides != a.strides or dtype is not a.dtype
                or c_contiguous != a.flags["C_CONTIGUOUS"] or writeable != a.flags["WRITEABLE"]):
            return False
    return True


numpy_arrays()
