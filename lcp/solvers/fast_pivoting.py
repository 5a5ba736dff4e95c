"""The fast path of `lcp.solve(problem, "pivoting")` on an `lcp.LCP` with default options.

The general path (lcp.api.solve -> lcp.acceptance.trust.solve_checked) runs, for such a call,

    eq = ruiz(M, q)                        lcp.scaling: Ruiz equilibration (pivoting's default)
    sol = solve_pivoting(eq.M, eq.q)       lcp.pivoting: block steps, single pivots, ...
    z = eq.z_back(sol.z)                   the user's units
    check(problem, z).accepted             lcp.residual: the one acceptance test

In the common case the pivoting makes block steps only (each failing index flipped at once,
every new basis nonsingular) until no inequality fails. `solve_pivoting` below runs that case
in one C call (lcp/solvers/_pivot_c.c: the equilibration of a balanced M, or `ruiz`'s factors
passed; the block steps with scipy's own LAPACK dgetrf / dgecon / dgetrs and BLAS dgemv, called as
lcp.pivoting's numpy code calls them; z mapped back) and checks the answer with
`lcp.residual.lcp_measure`, as `check` does. So it returns the same Solution as the general
path, bit for bit (tests/lcp/test_fast_pivoting.py), and None in every other case -- data that
are not plain finite float64 arrays, n > MAX_N = 260, a singular starting basis, a single or
exchange pivot, an answer that fails the acceptance test, numbers large enough for the check
to overflow -- where the caller runs the general path from the start.

numpy links its own BLAS, scipy another: the fast path is used only if scipy's dgemv (the C
code's matrix-vector product) rounds as numpy's matmul on a probe of sizes 1..260 with entries
over many binary orders (`_gemv_as_numpy`, run once; it checks the column sums of |M_aa| of
the condition estimate likewise).
"""

from __future__ import annotations

import numpy as np

import rigidlcp.lcp._lemke_kernel as _kernel

from .. import registry as api  # the table of methods (lcp.registry), not the facade
from ..acceptance.accuracy import judge_lcp
from ..acceptance.scaling import ruiz
from ..problems.solution import Solution, solved_lcp
from .pivoting import solve_pivoting as _pivoting

try:
    from . import _pivot_c
except ImportError:  # not built (no C compiler at install): the general path runs
    _pivot_c = None

SOLVED, NEEDS_RUIZ = 0, 4
#: solve_pivoting's defaults (tol, block_tries; max_iter is max(1000, 20 n)).
_TOL, _BLOCK_TRIES = 1e-10, 3
#: As in lcp.fast_lemke: above this bound on |M z + q| and the row sums of |M|, the check
#: could overflow; the general path measures under np.errstate instead.
_SAFE = 1e300
_F64 = np.dtype(np.float64)
#: The largest n the probe checks (and the fast path takes): beyond it the BLAS kernels could
#: block or split work among threads in ways the probe has not seen.
MAX_N = 260
_ready: bool | None = None


def _gemv_as_numpy() -> bool:
    """Does _pivot_c's matrix-vector product (scipy's dgemv, or 0 + ddot at size 1) give
    numpy's A @ x, bit for bit, on C-contiguous A, and its largest column sum of |A| numpy's
    np.max(np.sum(np.abs(A), axis=0))? Checked once on sizes 1..40 and larger ones up to MAX_N
    (blocking and threading of the BLAS kernels), entries over 60 binary orders."""
    for n in (*range(1, 41), 63, 64, 65, 100, 127, 128, 129, 200, MAX_N):
        k = np.arange(n * n + n, dtype=float)
        v = np.exp2((k * 7919 % 61) - 30.0) * (1.0 + (k * 31 % 17) / 17.0)
        v[1::3] *= -1.0
        A, x = v[: n * n].reshape(n, n), v[n * n:]
        y = np.empty(n)
        _pivot_c.matvec(A, x, y)
        if (y.tobytes() != (A @ x).tobytes()
                or _pivot_c.col_abs_max(A) != float(np.max(np.sum(np.abs(A), axis=0)))):
            return False
    return True


def _init() -> bool:
    global _ready
    if _pivot_c is None:
        _ready = False
        return False
    from scipy.linalg import cython_blas, cython_lapack

    lapack, blas = cython_lapack.__pyx_capi__, cython_blas.__pyx_capi__
    _pivot_c.init(lapack["dgetrf"], lapack["dgecon"], lapack["dgetrs"], blas["dgemv"],
                  blas["ddot"])
    _ready = _gemv_as_numpy()
    return _ready


def applies() -> bool:
    """Is "pivoting" the built-in method, equilibrated by default, with the compiled kernels on
    (RIGIDLCP_NO_KERNEL unset) and scipy's BLAS rounding as numpy's?"""
    info = api._REGISTRY.get("pivoting")
    return (info is not None and info.func is _pivoting and info.equilibrate
            and _kernel.enabled() and (_ready if _ready is not None else _init()))


def solve_pivoting(problem) -> Solution | None:
    """`lcp.solve(problem, "pivoting")` for an lcp.LCP when only block steps are needed and the
    answer is accepted (the Solution the general path would return), else None."""
    M, q = problem.M, problem.q
    if not (type(M) is np.ndarray and type(q) is np.ndarray and M.dtype is _F64
            and q.dtype is _F64 and q.ndim == 1 and 0 < q.size <= MAX_N
            and M.shape == (q.size, q.size) and applies()):
        return None
    n = q.size
    z = np.empty(n)
    basis = np.empty(n, dtype=np.intp)
    max_iter = max(1000, 20 * n)
    try:  # C-contiguous finite float64 data only (else ValueError or BufferError)
        code, it, m, flips, bounds = _pivot_c.solve(M, q, None, None, _TOL, _BLOCK_TRIES,
                                                    max_iter, z, basis)
        if code == NEEDS_RUIZ:
            eq = ruiz(M, q)
            code, it, m, flips, bounds = _pivot_c.solve(M, q, eq.r, eq.c, _TOL, _BLOCK_TRIES,
                                                        max_iter, z, basis)
    except (ValueError, BufferError):  # e.g. a Fortran-ordered M: general path
        return None
    mmax, qmax, zmax = bounds
    if code != SOLVED or not n * mmax * (zmax + 1.0) + qmax < _SAFE:
        return None
    ok, z, w, raw, scaled, acc = judge_lcp(M, q, z, basis[:m])
    if not ok:  # lcp.trust.Run.judge's verdict, with no equality part
        return None
    info = {"block_steps": it, "single_pivots": 0, "exchange_pivots": 0, "flips": flips,
            "equilibrated": True}
    if acc.refined:
        info["polished"] = True
    return solved_lcp(z, w, "pivoting", it, raw, scaled, basis[:m], "", info, acc.berr,
                      acc.ferr)
