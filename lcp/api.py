"""The facade: one entry point, `solve(problem, method=...)`, over the table of methods.

A method is a function `fn(M, q, **options) -> Solution` on a validated dense LCP; it is
registered with `@register(name, accepts=..., description=..., equilibrate=False)` in
lcp.registry (which imports no method and not this module; the built-in methods live in
lcp/solvers/ and are loaded here on first use). Nothing in lcp/ below this module imports it.
`solve` validates the problem, reduces an MLCP to an LCP (Schur complement), calls the
method (on the Ruiz-equilibrated data when `equilibrate`), and checks the answer on the user's
problem with the acceptance test of lcp.acceptance (a method's own bookkeeping is never
trusted): see lcp.acceptance.trust.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import rigidlcp.lcp._lemke_kernel as _kernel
import rigidlcp.lcp.registry as registry

from .acceptance.residual import TOL
from .acceptance.trust import Run, call_method, solve_checked
from .errors import InvalidInput, NotASolution
from .problems.problem import LCP, MLCP, InvalidProblem, NotApplicable
from .problems.solution import Solution
from .registry import ACCEPTS, MethodInfo, check_options, did_you_mean, lookup
from .solvers import BUILTIN as _BUILTIN

__all__ = ["solve", "get_method", "methods", "register", "MethodInfo", "ACCEPTS",
           "check_options"]


def register(name: str, *, accepts: str, description: str, replace: bool = False, **kw):
    """Decorator adding a method of one's own to the table (`lcp.registry.register`: `max_n`,
    `native`, `equilibrate` as there). A built-in method's name is refused (InvalidInput)
    unless `replace=True`: such a registration used to replace the built-in silently when it
    was loaded, and to be replaced by it silently when it was not (the built-ins load on first
    use), so that "my lemke" was either rigidlcp's or everyone's. With `replace=True` the
    built-in is loaded first, so the replacement stays. Registering one's own name again
    replaces the earlier registration (a notebook cell run twice)."""
    if name in _BUILTIN:
        if not replace:
            raise InvalidInput(f"{name!r} is one of rigidlcp's methods: register yours under "
                               f"another name (e.g. 'my-{name}'), or pass replace=True to "
                               "replace rigidlcp's in this process")
        get_method(name)
    return registry.register(name, accepts=accepts, description=description, **kw)


def methods() -> list[MethodInfo]:
    """The registered methods, with what each accepts (built-in ones first, in a fixed order,
    whichever were loaded first by `get_method`)."""
    _load_builtin_methods()
    order = {name: i for i, name in enumerate(_BUILTIN)}
    infos = list(registry._REGISTRY.values())
    return sorted(infos, key=lambda m: order.get(m.name, len(order)))


def get_method(name: str) -> MethodInfo:
    """The registered method `name`, importing its built-in module (lcp/solvers/) on first use;
    InvalidProblem naming the available methods when there is none."""
    info = lookup(name)
    if info is None:
        if name in _BUILTIN:
            import importlib

            importlib.import_module(f"{__package__}.solvers.{_BUILTIN[name]}")
        else:
            _load_builtin_methods()
        info = lookup(name)
    if info is None:
        raise InvalidProblem(
            f"unknown method {name!r}{did_you_mean(name, registry._REGISTRY)}; available: "
            f"{', '.join(sorted(registry._REGISTRY))}"
        )
    return info


def solve(problem: LCP | MLCP, method: str = "lemke", *, equilibrate: bool | None = None,
          repair: bool = True, fallback: bool | str | tuple[str, ...] = False,
          **options) -> Solution:
    """Solve an LCP (w = M z + q, 0 <= z perp w >= 0) or an MLCP by the named method.

    The answer is the method's own: polished on its final basis (extended-precision
    refinement), then judged on the problem passed by its backward error and forward error
    bound (lcp.accuracy; tolerances lcp.residual.TOL = 1e-8 and lcp.accuracy.FERR_TOL) and the
    scaled residual of `lcp.residual.check` (verify.certify's measure). A "solved" that fails
    is rerun with the other equilibration or becomes "inaccurate"; an "infeasible" needs a
    checked Farkas certificate (lcp.farkas). See lcp.trust for the steps.

    equilibrate: run the method on the Ruiz-equilibrated problem (lcp.scaling); default: the
    method's registered setting (on for lemke, pivoting and enumerate). repair: allow the
    rerun of the method with the other equilibration setting; a false "solved" is never
    returned either way. fallback: methods to try when this one gives no accepted answer
    (True: lcp.trust.FALLBACKS, "pivoting" then "lemke"; a name or a tuple of names); their
    answer is returned under their own name (sol.method) with info["fallback_for"] holding
    the first method's outcome. Other keyword arguments are the method's options.
    Bad input raises `InvalidProblem`; a method that refuses the problem raises `NotApplicable`;
    a method that fails returns a Solution whose status says how, with its evidence in `info`.
    """
    if (type(problem) is LCP and not options and fallback is False
            and (equilibrate is None or equilibrate is True)):
        fast = _FAST if method == "lemke" and _FAST is not None else (
            _fast(method) if method in _FAST_METHODS else None)
        if fast is not None:
            sol = fast(problem)  # the same answer, when the first attempt is accepted
            if sol is not None:
                return sol
    return _general(problem, method, equilibrate, repair, fallback, options)


def _general(problem, method: str, equilibrate: bool | None, repair: bool,
             fallback: bool | str | tuple[str, ...], options: dict) -> Solution:
    """`solve` after its fast path (which declined or does not apply): the general path."""
    friction = not isinstance(problem, (LCP, MLCP))
    if friction:  # imported only then: lcp.friction loads scipy.sparse
        from .problems.friction import FrictionContact2D

        if not isinstance(problem, FrictionContact2D):
            raise InvalidProblem(
                f"problem must be an lcp.LCP, lcp.MLCP or lcp.FrictionContact2D, got "
                f"{type(problem).__name__}"
            )
    info = _returning_solutions(get_method(method))
    check_options(info, options)
    if friction:
        from .acceptance.friction import solve_friction

        return solve_friction(problem, info, dict(options))
    if info.accepts == "friction-2d":
        raise NotApplicable(f"method {method!r} solves 2D friction-contact problems only")
    if isinstance(problem, MLCP):
        from .solvers.mlcp_full import solve_mlcp_unreduced

        sol = solve_mlcp_unreduced(problem, info, options)
        if sol is not None:
            return sol
    lcp = problem.to_lcp() if isinstance(problem, MLCP) else problem
    if info.max_n is not None and lcp.n > info.max_n:
        raise NotApplicable(
            f"method {method!r} is limited to n <= {info.max_n}; this LCP has n = {lcp.n}"
        )
    on = info.equilibrate if equilibrate is None else bool(equilibrate)
    run = Run(problem, lcp, lambda name: _returning_solutions(get_method(name)), TOL,
              _fallbacks(fallback))
    return solve_checked(run, method, on, bool(repair), options)


if _kernel.COMPILED:
    #: `solve` as an object whose default call -- solve(P) or solve(P, "lemke") on an lcp.LCP,
    #: no keywords -- goes to _FAST and then _general from C, without the Python frame of
    #: `solve` (lcp/_solve_entry.h); every other call is `solve` itself. It passes for the
    #: function (doc, name, signature through __wrapped__, repr, pickling by name).
    solve = _kernel._lemke_c.Entry(solve, LCP, globals())


def _returning_solutions(info: MethodInfo) -> MethodInfo:
    """`info` whose functions (the method and its native forms) answer with an lcp.Solution.

    A method that raises (RuntimeError, IndexError, ...: a bug of the method) gives status
    "failed", credited to it (lcp.acceptance.trust.call_method): lcp.solve's docstring
    promises a status, and a registered method's RuntimeError escaped as a traceback
    (session 28). A method that returns anything but an lcp.Solution raises NotASolution (a
    TypeError) naming it: one that forgot its `return` failed with "'NoneType' object has no
    attribute 'method'" deep in lcp.acceptance.trust."""
    name = info.name

    def guarded(func: Callable[..., Solution]) -> Callable[..., Solution]:
        def checked(*args, **kwargs) -> Solution:
            sol = call_method(func, name, *args, **kwargs)
            if not isinstance(sol, Solution):
                raise NotASolution(f"method {name!r} returned {type(sol).__name__}, not an "
                                "lcp.Solution (a registered method returns lcp.Solution(z=..., "
                                "w=..., status=..., method=...))")
            return sol

        return checked

    return replace(info, func=guarded(info.func),
                   native={kind: guarded(fn) for kind, fn in info.native.items()})


def _fallbacks(fallback) -> tuple[str, ...]:
    """The fallback= argument of `solve` as a tuple of registered method names."""
    if fallback is False or fallback is None:
        return ()
    if fallback is True:
        from .acceptance.trust import FALLBACKS

        return FALLBACKS
    names = (fallback,) if isinstance(fallback, str) else fallback
    try:
        names = tuple(names)
    except TypeError:
        raise InvalidProblem(f"fallback must be a bool, a method name or a tuple of names, "
                             f"got {fallback!r}") from None
    for name in names:
        if not isinstance(name, str):
            raise InvalidProblem(f"fallback names must be strings, got {name!r}")
        get_method(name)  # InvalidProblem naming the available methods
    return names


_FAST = None
_FAST_PIVOTING = None
#: Methods with a fast path for a plain LCP and default options (lcp.fast_lemke,
#: lcp.fast_pivoting): the same Solution as the general path, or None to run it.
_FAST_METHODS = ("lemke", "pivoting")


def _fast(method: str):
    """lcp.solvers.fast_lemke.entry (solve_lemke, in C when built) or
    lcp.solvers.fast_pivoting.solve_pivoting (imported on first use: they load the method's
    module, hence numpy's LAPACK paths)."""
    global _FAST, _FAST_PIVOTING
    if method == "lemke":
        if _FAST is None:
            from .solvers.fast_lemke import entry

            _FAST = entry
        return _FAST
    if _FAST_PIVOTING is None:
        from .solvers.fast_pivoting import solve_pivoting

        _FAST_PIVOTING = solve_pivoting
    return _FAST_PIVOTING


_LOADED = False


def _load_builtin_methods() -> None:
    # Importing the method modules registers them (done lazily to keep import cheap).
    global _LOADED
    if _LOADED:
        return
    import importlib

    for module in dict.fromkeys(_BUILTIN.values()):
        importlib.import_module(f"{__package__}.solvers.{module}")
    _LOADED = True


def __getattr__(name: str):
    # api._REGISTRY: the table itself (lcp.registry._REGISTRY, read where it is now)
    if name == "_REGISTRY":
        return registry._REGISTRY
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
