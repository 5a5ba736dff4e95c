"""One entry point, `solve(problem, method=...)`, and the registry of methods.

A method is a function `fn(M, q, **options) -> Solution` on a validated dense LCP; it is
registered with `@register(name, accepts=..., description=...)`. `solve` validates the problem,
reduces an MLCP to an LCP (Schur complement), calls the method, recomputes w = M z + q and the
residual itself (a method's own bookkeeping is never trusted), and recovers u for an MLCP.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .problem import LCP, MLCP, InvalidProblem, NotApplicable
from .solution import Solution, complementarity_residual

#: What a method accepts, as shown by `methods()`.
ACCEPTS = {
    "any": "any square M",
    "symmetric-psd": "symmetric positive semidefinite M only",
    "small-n": "any M, but only small n (exhaustive)",
    "friction-2d": "2D friction-contact problems (lcp.FrictionContact2D) only",
}


@dataclass(frozen=True)
class MethodInfo:
    name: str
    accepts: str
    description: str
    options: tuple[str, ...]
    max_n: int | None
    func: Callable[..., Solution]
    #: problem kind ("mlcp", "friction-2d") -> a function taking that problem object itself
    native: dict[str, Callable[..., Solution]] = field(default_factory=dict)

    def __str__(self) -> str:
        limit = f", n <= {self.max_n}" if self.max_n else ""
        opts = ", ".join(self.options) or "-"
        accepts = ACCEPTS[self.accepts]
        return f"{self.name:<12} {accepts}{limit}. {self.description} [options: {opts}]"


_REGISTRY: dict[str, MethodInfo] = {}


def register(name: str, *, accepts: str, description: str, max_n: int | None = None,
             native: dict[str, Callable[..., Solution]] | None = None):
    """Decorator adding a method to the registry. `native` maps a problem kind ("mlcp",
    "friction-2d") to a function `fn(problem, **options)` that solves it without reduction;
    a method that accepts "friction-2d" is itself such a function."""
    if accepts not in ACCEPTS:
        raise ValueError(f"accepts must be one of {sorted(ACCEPTS)}, got {accepts!r}")

    def deco(func: Callable[..., Solution]) -> Callable[..., Solution]:
        params = inspect.signature(func).parameters
        options = tuple(p for p in params if params[p].kind is inspect.Parameter.KEYWORD_ONLY)
        _REGISTRY[name] = MethodInfo(name, accepts, description, options, max_n, func,
                                     dict(native or {}))
        return func

    return deco


#: The built-in methods and the module that registers each (`get_method` imports only that one,
#: so that e.g. lemke never loads the QP solvers).
#: In the order lcp/methods.py registers them (the order `methods()` lists them in).
_BUILTIN = {"enumerate": "enumeration", "lemke": "lemke", "enumerate-mlcp": "mlcp_full",
            "newton-min": "newton", "newton-fb": "newton", "nsgs": "nsgs", "pgs": "pgs",
            "pivoting": "pivoting", "qp-clarabel": "qp", "qp-osqp": "qp", "states": "states"}


def methods() -> list[MethodInfo]:
    """The registered methods, with what each accepts (built-in ones first, in a fixed order,
    whichever were loaded first by `get_method`)."""
    _load_builtin_methods()
    order = {name: i for i, name in enumerate(_BUILTIN)}
    infos = list(_REGISTRY.values())
    return sorted(infos, key=lambda m: order.get(m.name, len(order)))


def get_method(name: str) -> MethodInfo:
    if name not in _REGISTRY:
        if name in _BUILTIN:
            import importlib

            importlib.import_module(f"{__package__}.{_BUILTIN[name]}")
        else:
            _load_builtin_methods()
    try:
        return _REGISTRY[name]
    except KeyError:
        raise InvalidProblem(
            f"unknown method {name!r}; available: {', '.join(sorted(_REGISTRY))}"
        ) from None


def solve(problem: LCP | MLCP, method: str = "lemke", **options) -> Solution:
    """Solve an LCP (w = M z + q, 0 <= z perp w >= 0) or an MLCP by the named method.

    Bad input raises `InvalidProblem`; a method that refuses the problem raises `NotApplicable`;
    a method that fails returns a Solution whose status says how, with its evidence in `info`.
    """
    friction = not isinstance(problem, (LCP, MLCP))
    if friction:  # imported only then: lcp.friction loads scipy.sparse
        from .friction import FrictionContact2D

        if not isinstance(problem, FrictionContact2D):
            raise InvalidProblem(
                f"problem must be an lcp.LCP, lcp.MLCP or lcp.FrictionContact2D, got "
                f"{type(problem).__name__}"
            )
    info = get_method(method)
    unknown = set(options) - set(info.options)
    if unknown:
        raise InvalidProblem(
            f"method {method!r} does not accept option(s) {sorted(unknown)}; "
            f"it accepts {list(info.options) or 'none'}"
        )
    if friction:
        from .friction import solve_friction

        return solve_friction(problem, info, dict(options))
    if info.accepts == "friction-2d":
        raise NotApplicable(f"method {method!r} solves 2D friction-contact problems only")
    if isinstance(problem, MLCP):
        from .mlcp_full import solve_mlcp_unreduced

        sol = solve_mlcp_unreduced(problem, info, options)
        if sol is not None:
            return sol
    lcp = problem.to_lcp() if isinstance(problem, MLCP) else problem
    if info.max_n is not None and lcp.n > info.max_n:
        raise NotApplicable(
            f"method {method!r} is limited to n <= {info.max_n}; this LCP has n = {lcp.n}"
        )
    sol = info.func(lcp.M, lcp.q, **options)
    sol.method = method
    z = np.asarray(sol.z, dtype=float)
    if z.shape != (lcp.n,) or not np.all(np.isfinite(z)):
        sol.status = "failed" if sol.status == "solved" else sol.status
        sol.message = (sol.message + "; " if sol.message else "") + "method returned a bad z"
        z = np.where(np.isfinite(z), z, 0.0) if z.shape == (lcp.n,) else np.zeros(lcp.n)
    sol.z = z
    if isinstance(problem, MLCP):
        sol.u = problem.recover_u(z)
        sol.w, sol.eq_residual = problem.residuals(sol.u, z)
    else:
        sol.w = lcp.M @ z + lcp.q
    sol.residual = complementarity_residual(sol.z, sol.w)
    return sol


_LOADED = False


def _load_builtin_methods() -> None:
    # Importing the method modules registers them (done lazily to keep import cheap).
    # `from . import methods` would find the *function* lcp.methods and import nothing, and
    # importing the submodule rebinds the package attribute `methods` to it: undo that.
    global _LOADED
    if _LOADED:
        return
    import importlib
    import sys

    importlib.import_module(f"{__package__}.methods")
    _LOADED = True
    package = sys.modules[__package__]
    if getattr(package, "methods", None) is not methods:
        package.methods = methods
