"""The table of methods: `register` adds one, `lookup` finds a registered one.

It imports only data types and errors (lcp.problems, lcp.errors), never a method and never the
facade: a method's module imports it to register (`@register(...)`, lcp/solvers/), and
`lcp.solve` (lcp/api.py) imports it to find the method it is asked for. Loading the built-in
methods on first use is the facade's job (`lcp.api.get_method`), as in qpsolvers, where the
solvers fill a table the facade reads (docs/architecture.md, "Adding a method").
"""

from __future__ import annotations

import difflib
import inspect
from collections.abc import Callable
from dataclasses import dataclass, field

from .errors import InvalidProblem
from .problems.solution import Solution

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
    equilibrate: bool = False  # solve() runs it on Ruiz-equilibrated data by default

    def __str__(self) -> str:
        limit = f", n <= {self.max_n}" if self.max_n else ""
        opts = ", ".join(self.options) or "-"
        accepts = ACCEPTS[self.accepts]
        return f"{self.name:<12} {accepts}{limit}. {self.description} [options: {opts}]"


_REGISTRY: dict[str, MethodInfo] = {}


def register(name: str, *, accepts: str, description: str, max_n: int | None = None,
             native: dict[str, Callable[..., Solution]] | None = None,
             equilibrate: bool = False):
    """Decorator adding a method to the registry. `native` maps a problem kind ("mlcp",
    "friction-2d") to a function `fn(problem, **options)` that solves it without reduction;
    a method that accepts "friction-2d" is itself such a function. `equilibrate`: whether
    `solve` runs it on the Ruiz-equilibrated problem by default (for methods whose answer
    depends on the units)."""
    if accepts not in ACCEPTS:
        raise ValueError(f"accepts must be one of {sorted(ACCEPTS)}, got {accepts!r}")

    def deco(func: Callable[..., Solution]) -> Callable[..., Solution]:
        params = inspect.signature(func).parameters
        options = tuple(p for p in params if params[p].kind is inspect.Parameter.KEYWORD_ONLY)
        _REGISTRY[name] = MethodInfo(name, accepts, description, options, max_n, func,
                                     dict(native or {}), equilibrate)
        return func

    return deco


def lookup(name: str) -> MethodInfo | None:
    """The registered method `name`, or None (nothing is loaded here: see lcp.api.get_method)."""
    return _REGISTRY.get(name)


def did_you_mean(name: str, names) -> str:
    """" (did you mean 'lemke'?)" for the closest of `names` to a mistyped `name` (difflib's
    ratio >= 0.6), else "": the tail of an "unknown method / set" message."""
    close = difflib.get_close_matches(str(name), list(names), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def check_options(info: MethodInfo, options: dict) -> None:
    """Raise InvalidProblem naming the options `info`'s method does not accept."""
    unknown = set(options) - set(info.options)
    if unknown:
        raise InvalidProblem(
            f"method {info.name!r} does not accept option(s) {sorted(unknown)}; "
            f"it accepts {list(info.options) or 'none'}"
        )
