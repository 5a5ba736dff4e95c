"""The fast path of `lcp.solve` for its most common call: `solve(problem)` or
`solve(problem, "lemke")` on an `lcp.LCP`, default options, the compiled kernel built.

The general path (lcp.api.solve -> lcp.trust.solve_checked) runs, for such a call,

    eq = ruiz(M, q)                    lcp.scaling: Ruiz equilibration (lemke's default)
    sol = lemke(eq.M, eq.q)            the pivots, in C (lcp/_lemke_c.c)
    z = eq.z_back(sol.z)               the user's units
    check(problem, z).accepted         lcp.residual: the one acceptance test

and returns the answer when it is "solved" and accepted. `solve_lemke` does these same steps
with the same roundings, and the check of `lcp.accuracy.judge_lcp`, the verdict
`lcp.trust.Run.judge` gives on an LCP (polish on the basis, backward and forward errors,
`lcp.residual.lcp_measure`). For a balanced M (`ruiz` then makes no sweep and only changes the
unit of q) one C call (`_lemke_c.solve_fast`) does the equilibration, the pivots, z back,
judge_lcp's `assess_lcp` (lcp/acceptance/_accuracy_core.h, the code of the C `assess`), M z by
numpy's own BLAS call (np.dot(M, z, w), called from C) and the rest of lcp.residual's measure;
when the verdict is "accepted" the same call (`_lemke_c.solve_lcp`, lcp/_lemke_solution.h)
also builds the Solution, else it hands its numbers back to the steps below.
Otherwise `ruiz` runs in numpy,
its factors are passed to `_lemke_kernel.solve_eq`, and `judge_lcp` checks the answer. So it
returns the same Solution (z, w, pivots, basis, residuals, message, info) as the general path,
bit for bit
(tests/lcp/test_fast_lemke.py), and None in every other case -- data that are not plain finite
float64 arrays, a ray, a pivot limit, a cycle, an answer that fails the acceptance test, or
numbers large enough for the check to overflow -- where the caller then runs the general path
from the start (which raises the same typed errors, repairs, proves infeasibility).
"""

from __future__ import annotations

import numpy as np

import rigidlcp.lcp._lemke_kernel as _kernel

from .. import registry
from ..acceptance import accuracy as _accuracy
from ..acceptance.accuracy import FERR_TOL, judge_lcp
from ..acceptance.residual import TOL, lcp_measure
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
#: Lemke and `assess_lcp`'s C steps in one call; only with the C acceptance built as well (else
#: judge_lcp measures in numpy, and so must this path)
_solve_accept = (_kernel._lemke_c.solve_accept
                 if _kernel.COMPILED and _accuracy.__dict__.get("_accuracy_c") else None)
_measure = _kernel._lemke_c.lcp_measure if _kernel.COMPILED else None
#: `_solve_accept`, numpy's M z (np.dot(M, z, w): the BLAS call of M.dot(z)) and the measure's C
#: steps in one call (lcp/_lemke_c.c: solve_fast)
_solve_fast = _kernel._lemke_c.solve_fast if _solve_accept is not None else None
_empty, _intp, _dot = np.empty, np.intp, np.dot
#: the longest row whose |M| sum C rounds as numpy (`sums_verified_upto`: probed once, read
#: here once, not at every call)
_UPTO = _kernel.sums_verified_upto() if _kernel.COMPILED else 0
#: `_solve_fast`, the verdict below and `solved_lcp`'s Solution in one call (lcp/_lemke_c.c:
#: solve_lcp, lcp/_lemke_solution.h): the Solution when accepted, else the numbers of
#: `_solve_fast` and its arrays for the steps below
_solve_lcp = _kernel._lemke_c.solve_lcp if _solve_fast is not None else None


def _setup(tol: float = TOL, ferr_tol: float = FERR_TOL) -> None:
    """Give `_solve_lcp` the objects it builds with and the verdict's tolerances (lcp.residual's
    TOL for the scaled residual and the backward error, lcp.accuracy's FERR_TOL for the forward
    bound; tests pass others to check the verdict, then call it again with the defaults)."""
    _kernel._lemke_c.solve_setup(np.dot, np.empty, np.intp, object.__new__, Solution,
                                 _Q_NONNEGATIVE, tol, ferr_tol)


if _solve_lcp is not None:
    _setup()
    _kernel.numpy_gemv()  # M z by numpy's own cblas_dgemv from C, when found and checked


def solve_lemke(problem) -> Solution | None:
    """`lcp.solve(problem, "lemke")` for an lcp.LCP when its first attempt is accepted (the
    Solution the general path would return), else None (see the module docstring)."""
    M, q = problem.M, problem.q
    info = registry._REGISTRY.get("lemke")  # applies(), written out (the call's glue)
    if not (type(M) is np.ndarray and type(q) is np.ndarray and info is not None
            and info.func is _lemke and info.equilibrate and _kernel._use):
        return None
    n = q.size
    max_iter = 1000 + 100 * n  # lemke()'s default
    if _solve_lcp is None:
        if not (M.dtype is _F64 and q.dtype is _F64 and q.ndim == 1 and M.shape == (n, n)):
            return None
        return _solve_ruiz(M, q, n, max_iter, _empty(n), _empty(n, dtype=_intp),
                           balanced=True)
    try:  # C-contiguous native float64 M (n x n) and q (n), finite (else ValueError or
        # BufferError): the solve, `assess_lcp`'s C steps, M z, the measure and, when the
        # verdict below is "accepted", the Solution, in one call (lcp/_lemke_solution.h)
        out = _solve_lcp(M, q, DEFAULT_TOL, max_iter, _UPTO)
    except (ValueError, BufferError, TypeError):  # e.g. Fortran order, read-only, q 0-d
        return None
    return out if type(out) is not tuple else _finish(M, q, out)


def _finish(M, q, out: tuple) -> Solution | None:
    """`solve_lemke`'s steps after its C call when that call handed its numbers back (`out`,
    a tuple) instead of a Solution; also called by the C entry `solve_default`."""
    code, pivots, m, acode, berr, ferr, refined, raw, scaled, z, w, basis = out
    if code == _kernel.NEEDS_RUIZ:
        n = q.size
        try:
            return _solve_ruiz(M, q, n, 1000 + 100 * n, z, _empty(n, dtype=_intp))
        except (ValueError, BufferError, TypeError):
            return None
    if code != _kernel.SOLVED or acode < 0:  # not solved, or numbers the check could overflow
        return None
    if acode:  # not handled in C (e.g. a singular pattern): judge_lcp's numpy steps
        return _judged(M, q, z, basis, pivots)
    # judge_lcp's verdict after `assess_lcp` (done in C above), when C did not give it: z is
    # the answer (polished when refined), then lcp.residual's measure (w = M z + q and the
    # numbers in C, unless n exceeds the row length whose sums C is known to round as numpy
    # does, or a number overflowed)
    if raw != raw:  # NaN: not measured in C; measured by numpy (lcp_measure recomputes w)
        w, raw, scaled, _, _ = lcp_measure(M, q, z)
    if not (scaled <= TOL and berr <= TOL and ferr <= FERR_TOL):
        return None
    info = {"equilibrated": True, "polished": True} if refined else {"equilibrated": True}
    return solved_lcp(z, w, "lemke", pivots, raw, scaled, basis,
                      "" if pivots else _Q_NONNEGATIVE, info, berr, ferr)


def _solve_ruiz(M, q, n: int, max_iter: int, z, basis, balanced: bool = False
                ) -> Solution | None:
    """The fast path for an M that is not balanced (lcp.scaling.ruiz in numpy, then Lemke on
    its factors in C) or, `balanced`, without `solve_accept`: then `judge_lcp`."""
    try:
        if balanced:
            code, pivots, m, bounds = _solve_eq(M, q, None, None, None, DEFAULT_TOL, max_iter,
                                                z, basis)
        if not balanced or code == _kernel.NEEDS_RUIZ:
            eq = ruiz(M, q)
            code, pivots, m, bounds = _kernel.solve_eq(M, q, eq.r, eq.c, DEFAULT_TOL,
                                                       max_iter, z, basis)
    except (ValueError, BufferError):  # e.g. a Fortran-ordered or read-only M: general path
        return None
    mmax, qmax, zmax = bounds
    if code != _kernel.SOLVED or not n * mmax * (zmax + 1.0) + qmax < _SAFE:
        return None
    return _judged(M, q, z, basis[:m], pivots)


def _judged(M, q, z, basis, pivots: int) -> Solution | None:
    ok, z, w, raw, scaled, acc = judge_lcp(M, q, z, basis)
    if not ok:  # lcp.trust.Run.judge's verdict, with no equality part
        return None
    info = {"equilibrated": True, "polished": True} if acc.refined else {"equilibrated": True}
    return solved_lcp(z, w, "lemke", pivots, raw, scaled, basis,
                      "" if pivots else _Q_NONNEGATIVE, info, acc.berr, acc.ferr)


#: What lcp.solve calls for its default call on an lcp.LCP: `solve_lemke`, or the same steps
#: with no Python frame when the C call is built (`_lemke_c.solve_default`,
#: lcp/_lemke_solution.h: the registry and kernel tests, problem.M and problem.q, `solve_lcp`,
#: then `_finish` when it hands its numbers back): the same Solution or None
#: (tests/lcp/test_solve_fast.py).
entry = solve_lemke
if _solve_lcp is not None:
    _kernel._lemke_c.entry_setup(registry._REGISTRY, vars(_kernel), _lemke, _finish, np.ndarray,
                                 DEFAULT_TOL, _UPTO)
    entry = _kernel._lemke_c.solve_default
