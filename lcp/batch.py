"""Many LCPs at once: `solve_many(problems, method=..., **options)` (the batch path).

Comparison studies and fuzzing solve thousands of small LCPs; one `lcp.solve` call pays a fixed
Python price (validation, method lookup, building the answer) that is most of its time at
n = 10. `solve_many` pays the lookup and the option check once, validates a stack of same-size
problems with one pass, and -- for ``method="lemke"`` when the compiled kernel is built
(lcp/_lemke_kernel.py) -- runs the whole loop over the problems in C. Every answer is then
checked the way `solve` checks one: w = M z + q is recomputed here (never taken from the
method) and the residual max|min(z, w)| stored; a z that is not finite is a failure. A problem
the batch loop does not solve (ray, pivot limit, numerical cycling) is solved again by
`lcp.solve`, which gives the same status and evidence as a single call.

The answers are the same as those of `[lcp.solve(p, method, **options) for p in problems]`:
the same z, pivots and status (tests/lcp/test_batch.py).
"""

from __future__ import annotations

from collections.abc import Sequence
from types import SimpleNamespace

import numpy as np

import rigidlcp.lcp._lemke_kernel as _kernel

from .acceptance import accuracy as _accuracy
from .acceptance.accuracy import judge_lcp
from .api import check_options, get_method, solve
from .problems.problem import LCP, MLCP, InvalidProblem
from .problems.solution import Solution, solved_lcp

_Q_NONNEGATIVE = "q >= 0: z = 0 solves the LCP"  # lemke()'s message, as it gives it
#: Methods whose batch path runs the whole loop over the problems in compiled code (the others
#: are a loop of their Python function with one lookup and one option check).
COMPILED_BATCH = ("lemke",)
_MODULES: SimpleNamespace | None = None


def _modules() -> SimpleNamespace:
    """The modules solve_many's steps use that this module does not import when it is loaded
    (they import lcp.api, which imports this module, or are not needed by every caller):
    imported on the first call, then kept. A function-level import statement costs ~0.7 us at
    every call even when the module is loaded (the name's resolution); solve_many made eight,
    a quarter of `solve_many([p])`'s time (issue 23). Their names are read from the modules at
    each use, so a module attribute changed later (a test's monkeypatch) is seen."""
    global _MODULES
    if _MODULES is None:
        from .acceptance import residual, scaling
        from .problems import friction
        from .solvers import fast_lemke, lemke  # fast_lemke's: the C calls' objects

        _MODULES = SimpleNamespace(residual=residual, scaling=scaling, friction=friction,
                                   fast_lemke=fast_lemke, lemke=lemke)
    return _MODULES


def solve_many(
    problems: Sequence[LCP | MLCP] | tuple[np.ndarray, np.ndarray],
    method: str = "lemke",
    *,
    repair: bool = True,
    **options,
) -> list[Solution]:
    """Solve a list of LCPs (w = M z + q, 0 <= z perp w >= 0) by one method.

    problems: a sequence of `lcp.LCP` (stacked by size: the fast path), `lcp.MLCP` or
    `lcp.FrictionContact2D` (solved one by one by `lcp.solve`), or a pair (Ms, qs) of stacked
    arrays of shapes (k, n, n) and (k, n). repair: as `lcp.solve`'s, for the problems the
    batch loop hands to `lcp.solve` (with repair=False every answer is the method's own,
    checked). options: the method's options, the same for every problem. Returns one Solution
    per problem, in order, each as `lcp.solve(p, method, repair=repair, **options)` would.
    """
    info = get_method(method)
    check_options(info, options)
    if isinstance(problems, tuple) and len(problems) == 2 and not isinstance(
            problems[0], (LCP, MLCP)):
        Ms, qs = _stacked(*problems)
        return _solve_stack(Ms, qs, method, options, lambda i: LCP(Ms[i], qs[i]), repair)
    FrictionContact2D = _modules().friction.FrictionContact2D

    problems = list(problems)
    stacks = _stack_lcps(problems)
    if stacks is not None:  # every entry an lcp.LCP of plain data, grouped and stacked in C
        out: list[Solution | None] = [None] * len(problems)
        for _n, idx, Ms, qs in stacks:
            sols = _solve_stack(Ms, qs, method, options, lambda j, idx=idx: problems[idx[j]],
                                repair)
            for i, sol in zip(idx, sols):
                out[i] = sol
        return out  # type: ignore[return-value]
    for i, p in enumerate(problems):
        if type(p) is not LCP and not isinstance(p, (LCP, MLCP, FrictionContact2D)):
            raise InvalidProblem(f"problems[{i}] must be an lcp.LCP, lcp.MLCP or "
                                 f"lcp.FrictionContact2D, got {type(p).__name__}")
    out = [None] * len(problems)
    groups: dict[int, list[int]] = {}
    for i, p in enumerate(problems):
        if not (type(p) is LCP or isinstance(p, LCP)) or not p.M.flags.c_contiguous:
            # MLCP (u, reductions), friction problem, or an M in Fortran order (numpy's M z
            # rounds otherwise than on the stacked C-ordered copy): one by one
            out[i] = solve(p, method, repair=repair, **options)
        else:
            groups.setdefault(p.q.size, []).append(i)
    for idx in groups.values():  # LCPs are validated at construction: stack them as they are
        n = problems[idx[0]].q.size
        Ms = np.concatenate([problems[i].M for i in idx]).reshape(len(idx), n, n)
        qs = np.concatenate([problems[i].q for i in idx]).reshape(len(idx), n)
        sols = _solve_stack(Ms, qs, method, options, lambda j, idx=idx: problems[idx[j]],
                            repair)
        for i, sol in zip(idx, sols):
            out[i] = sol
    return out  # type: ignore[return-value]


def _stack_lcps(problems: list) -> list | None:
    """The grouping below done in C (lcp/_batch_solutions.h: stack_lcps) when every problem is
    an lcp.LCP whose M is C-contiguous native float64 (n x n) and q a float64 vector: for each
    size, in the order of its first problem, (n, indices, Ms, qs) with the stacks
    np.concatenate would make; else None (and when the C calls are not built)."""
    if _modules().fast_lemke._solve_lcp is None:
        return None
    return _kernel._lemke_c.stack_lcps(problems, LCP)


def _stacked(Ms, qs) -> tuple[np.ndarray, np.ndarray]:
    """Validate stacked data once: real finite arrays of shapes (k, n, n) and (k, n)."""
    try:
        Ms = np.ascontiguousarray(Ms, dtype=float)
        qs = np.ascontiguousarray(qs, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidProblem(f"Ms and qs must be numeric arrays: {exc}") from None
    if Ms.ndim != 3 or Ms.shape[1] != Ms.shape[2] or Ms.shape[1] < 1:
        raise InvalidProblem(f"Ms must have shape (k, n, n) with n >= 1, got {Ms.shape}")
    if qs.shape != Ms.shape[:2]:
        raise InvalidProblem(f"qs must have shape {Ms.shape[:2]} (k, n), got {qs.shape}")
    for name, arr in (("Ms", Ms), ("qs", qs)):
        if not np.isfinite(arr).all():
            where = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
            raise InvalidProblem(f"{name} contains NaN or Inf (first at index {where})")
    return Ms, qs


def _solve_stack(Ms: np.ndarray, qs: np.ndarray, method: str, options: dict,
                 problem_of, repair: bool = True) -> list[Solution]:
    """Solve the stacked (validated, finite) problems; problem_of(i) is problem i as an LCP
    (built only when a problem must be solved one by one). As `solve` does (lcp.trust): the
    method runs on the Ruiz-equilibrated data when it is registered so, and each answer is
    checked on the problem passed (lcp.residual); an answer that is not an accepted "solved"
    is redone by `solve` itself (repairs, certificates of infeasibility)."""
    ruiz = _modules().scaling.ruiz
    k, n = qs.shape
    info = get_method(method)
    on = info.equilibrate
    if method == "lemke" and k and _kernel.enabled() and info.func is _builtin_lemke():
        return _lemke_batch(Ms, qs, on, options, problem_of, repair)
    eqs = [ruiz(Ms[i], qs[i]) for i in range(k)] if on else None
    Mr = np.stack([e.M for e in eqs]) if eqs else Ms
    qr = np.stack([e.q for e in eqs]) if eqs else qs
    sols = []
    for i in range(k):
        sol = info.func(Mr[i], qr[i], **options)
        sol.method = method
        sols.append(sol)
    out = []
    for i, sol in enumerate(sols):
        z = np.asarray(sol.z, dtype=float)
        if sol.status == "solved" and z.shape == (n,) and np.isfinite(z).all():
            z = eqs[i].z_back(z) if eqs else z
            ok, z, w, raw, scaled, acc = judge_lcp(Ms[i], qs[i], z, sol.basis)
            if ok:
                sol.z, sol.w, sol.residual, sol.scaled_residual = z, w, raw, scaled
                sol.backward_error, sol.forward_error = acc.berr, acc.ferr
                sol.info["equilibrated"] = on
                if acc.refined:
                    sol.info["polished"] = True
                out.append(sol)
                continue
        out.append(solve(problem_of(i), method, repair=repair, **options))
    return out


def _builtin_lemke():
    return _modules().lemke.lemke


def _lemke_batch(Ms: np.ndarray, qs: np.ndarray, on: bool, options: dict, problem_of,
                 repair: bool = True) -> list[Solution]:
    """`solve`'s first attempt for every problem in C (lcp.fast_lemke's steps: the
    equilibration of a balanced M, Lemke, z back, and judge_lcp's `assess_lcp` of the answer;
    `_kernel.solve_batch` with `acc`), then the rest of its check, lcp.residual's measure, for
    all at once (`_kernel.measure_batch`: M z by numpy, the rest in C, the same numbers as
    `check`): each answer judged once. A problem not solved or not accepted there -- a ray, a
    limit, a cycle, an M that is not balanced, an answer that fails the test -- is solved by
    `solve` itself, which answers it as a single call does."""
    mods = _modules()
    FERR_TOL, _accuracy_c = _accuracy.FERR_TOL, _accuracy._accuracy_c
    TOL, _solve_lcp, lemke = mods.residual.TOL, mods.fast_lemke._solve_lcp, mods.lemke
    k, n = qs.shape
    d = lemke._covering_vector(options.get("d"), n)
    max_iter = lemke._check_max_iter(options.get("max_iter"), n)
    tol = lemke._check_tol(options.get("tol", lemke.DEFAULT_TOL))
    Z = np.empty((k, n))
    basic = np.empty((k, n), dtype=np.int8)
    codes = np.empty(k, dtype=np.int64)
    pivots = np.empty(k, dtype=np.int64)
    # acceptance in C only where judge_lcp would use it (the C `assess` built)
    acc = np.empty((k, 4)) if _accuracy_c is not None else None
    mmax = np.empty(k)  # max|M| of each solved problem, from the solve: not measured again
    _kernel.solve_batch(Ms, qs, np.ascontiguousarray(d), tol, max_iter, Z, basic, codes, pivots,
                        equilibrate=on, acc=acc, mmax=mmax)
    with np.errstate(all="ignore"):  # as `check`: an overflow is measured, never accepted
        W = np.matmul(Ms, Z[:, :, None])[:, :, 0]  # each M.dot(z): the same gemv
    measured = _kernel.measure_batch(Ms, qs, Z, W, mmax)
    if measured is None:  # not compiled as numpy sums: measure one by one
        return [solve(problem_of(i), "lemke", repair=repair, **options) for i in range(k)]
    if acc is None:  # every answer to judge_lcp
        acc = np.ones((k, 4))
    if _solve_lcp is not None:  # the verdicts and the Solutions in C (lcp/_batch_solutions.h)
        sols = _kernel._lemke_c.batch_solutions(Z, W, basic, codes, pivots, acc, measured, TOL,
                                                FERR_TOL, on)
    else:
        sols = [None] * k
    for i in (i for i, sol in enumerate(sols) if sol is None):
        sols[i] = _finish(i, Ms, qs, Z, W, basic, codes, pivots, acc, measured, on, options,
                          problem_of, repair)
    return sols


def _finish(i: int, Ms, qs, Z, W, basic, codes, pivots, acc, measured, on: bool,
            options: dict, problem_of, repair: bool) -> Solution:
    """Problem i of `_lemke_batch` when `batch_solutions` did not accept it (or is not built):
    judge_lcp's verdict on the numbers of the C loop (lcp.residual's TOL, lcp.accuracy's
    FERR_TOL; a NaN fails every test), numpy's judge_lcp where the C acceptance did not handle
    the answer, else `solve` itself, which answers it as a single call does."""
    FERR_TOL, TOL = _accuracy.FERR_TOL, _modules().residual.TOL
    acode, berr, ferr, refined = acc[i].tolist()
    raw, scaled = measured[i, :2].tolist()
    piv = int(pivots[i])
    basis = np.flatnonzero(basic[i])
    solved = codes[i] == _kernel.SOLVED
    if solved and acode == 0 and scaled <= TOL and berr <= TOL and ferr <= FERR_TOL:
        # assessed in C, measured (batch_solutions not built)
        return solved_lcp(Z[i], W[i], "lemke", piv, raw, scaled, basis,
                          "" if piv else _Q_NONNEGATIVE,
                          {"equilibrated": on, "polished": True} if refined else {
                              "equilibrated": on}, berr, ferr)
    if solved and acode == 1:  # to judge_lcp's numpy steps
        ok, z, w, r, sc, a = judge_lcp(Ms[i], qs[i], Z[i], basis)
        if ok:
            info = {"equilibrated": on, "polished": True} if a.refined else {"equilibrated": on}
            return solved_lcp(z, w, "lemke", piv, r, sc, basis, "" if piv else _Q_NONNEGATIVE,
                              info, a.berr, a.ferr)
    # see _lemke_batch's docstring: the single call gives the answer and its evidence
    return solve(problem_of(i), "lemke", repair=repair, **options)
