"""The options of method ``lemke`` (lcp/solvers/lemke.py), checked: the covering vector d, the
pivot limit and the zero tolerance. Shared by lemke() and lcp.solve_many's compiled batch
(lcp/batch.py), so that both refuse the same options with the same message."""

from __future__ import annotations

import numpy as np

from ..problems.problem import InvalidProblem, as_vector

#: Zero tolerance, relative to data normalized to max|M| = max|q| = max d = 1.
DEFAULT_TOL = 1e-10


def _covering_vector(d, n: int) -> np.ndarray:
    if d is None:
        return np.ones(n)
    d = as_vector("d", d, n)
    if np.any(d <= 0):
        i = int(np.flatnonzero(d <= 0)[0])
        raise InvalidProblem(f"d (covering vector) must be > 0 everywhere, got d[{i}] = {d[i]}")
    return d


def _check_max_iter(max_iter, n: int) -> int:
    if max_iter is None:
        return 1000 + 100 * n
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise InvalidProblem(f"max_iter must be a positive integer, got {max_iter!r}")
    return int(max_iter)


def _check_tol(tol) -> float:
    if tol is None:
        return DEFAULT_TOL
    try:
        tol = float(tol)
    except (TypeError, ValueError):
        raise InvalidProblem(f"tol must be a number, got {tol!r}") from None
    if not (0 < tol < 1):
        raise InvalidProblem(f"tol must be in (0, 1), got {tol}")
    return tol
