"""The fast path of `lcp.solve` for its most common call: `solve(problem)` or
`solve(problem, "lemke")` on an `lcp.LCP`, default options, the compiled kernel built.

The general path (lcp.api.solve -> lcp.trust.solve_checked) runs, for such a call,

    eq = ruiz(M, q)                    lcp.scaling: Ruiz equilibration (lemke's default)
    sol = lemke(eq.M, eq.q)            the pivots, in C (lcp/_lemke_c.c)
    z = eq.z_back(sol.z)               the user's units
    check(problem, z).accepted         lcp.residual: the one acceptance test

and returns the answer when it is "solved" and accepted. `solve_lemke` does these same steps
with the same roundings, but the first three in one C call (`_lemke_kernel.solve_eq`: the
equilibration of a balanced M -- `ruiz` then makes no sweep and only changes the unit of q --
is done there; otherwise `ruiz` runs in numpy and its factors are passed), and the check by
`lcp.accuracy.judge_lcp`, the verdict `lcp.trust.Run.judge` gives on an LCP (polish on the
basis, backward and forward errors, `lcp.residual.lcp_measure`). So it returns the same
Solution (z, w, pivots, basis, residuals, message, info) as the general path, bit for bit
(tests/lcp/test_fast_lemke.py), and None in every other case -- data that are not plain finite
float64 arrays, a ray, a pivot limit, a cycle, an answer that fails the acceptance test, or
numbers large enough for the check to overflow -- where the caller then runs the general path
from the start (which raises the same typed errors, repairs, proves infeasibility).
"""

from __future__ import annotations

import numpy as np

import rigidlcp.lcp._lemke_kernel as _kernel

from .. import registry
from ..acceptance.accuracy import judge_lcp
from ..acceptance.scaling import ruiz
from ..problems.solution import Solution, solved_lcp
from .lemke import DEFAULT_TOL
from .lemke import lemke as _lemke

_Q_NONNEGATIVE = "q >= 0: z = 0 solves the LCP"  # lemke()'s message, as it gives it
#: Above this bound on |M z + q| and the row sums of |M|, numpy's part of the check could
#: overflow (and warn): the general path measures under np.errstate instead.
_SAFE = 1e300


def applies() -> bool:
    """Is "lemke" the built-in method, equilibrated by default, with the compiled kernel on?"""
    info = registry._REGISTRY.get("lemke")
    return (info is not None and info.func is _lemke and info.equilibrate
            and _kernel.enabled())


_F64 = np.dtype(np.float64)
_solve_eq = _kernel._lemke_c.solve_eq if _kernel.COMPILED else None


def solve_lemke(problem) -> Solution | None:
    """`lcp.solve(problem, "lemke")` for an lcp.LCP when its first attempt is accepted (the
    Solution the general path would return), else None (see the module docstring)."""
    M, q = problem.M, problem.q
    if not (type(M) is np.ndarray and type(q) is np.ndarray and M.dtype is _F64
            and q.dtype is _F64 and q.ndim == 1 and M.shape == (q.size, q.size)
            and applies()):
        return None
    n = q.size
    z = np.empty(n)
    basis = np.empty(n, dtype=np.intp)
    max_iter = 1000 + 100 * n  # lemke()'s default
    try:  # C-contiguous finite float64 data only (else ValueError or BufferError)
        # _kernel.solve_eq's C function itself (its arguments are already of the right types)
        code, pivots, m, bounds = _solve_eq(M, q, None, None, None, DEFAULT_TOL, max_iter, z,
                                            basis)
        if code == _kernel.NEEDS_RUIZ:
            eq = ruiz(M, q)
            code, pivots, m, bounds = _kernel.solve_eq(M, q, eq.r, eq.c, DEFAULT_TOL,
                                                       max_iter, z, basis)
    except (ValueError, BufferError):  # e.g. a Fortran-ordered or read-only M: general path
        return None
    mmax, qmax, zmax = bounds
    if code != _kernel.SOLVED or not n * mmax * (zmax + 1.0) + qmax < _SAFE:
        return None
    ok, z, w, raw, scaled, acc = judge_lcp(M, q, z, basis[:m])
    if not ok:  # lcp.trust.Run.judge's verdict, with no equality part
        return None
    info = {"equilibrated": True, "polished": True} if acc.refined else {"equilibrated": True}
    return solved_lcp(z, w, "lemke", pivots, raw, scaled, basis[:m],
                      "" if pivots else _Q_NONNEGATIVE, info, acc.berr, acc.ferr)
