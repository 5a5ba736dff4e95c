"""Problem types: the LCP and the MLCP in Siconos's layout, with validation and .npz storage.

LCP(M, q):              w = M z + q,          0 <= z  perp  w >= 0.
MLCP(A, C, D, B, a, b): A u + C v + a = 0,    w = D u + B v + b,    0 <= v  perp  w >= 0,
                        with u free (the generalized accelerations of an event).
"""

from __future__ import annotations

import inspect
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import rigidlcp.lcp._lemke_kernel as _kernel

from ..errors import InvalidProblem, NotApplicable
from ..io.files import atomic_write

#: LCP.__init__'s quick route (lcp/_lemke_py.h: lcp_init), set below once the class exists;
#: None when the C extension is not built (and with it LCP.__init__ in C, `_py_init` the Python
#: one it replaces).
_init = _py_init = None


def as_matrix(name: str, value: Any, shape: tuple[int | None, int | None]) -> np.ndarray:
    """Validate and convert a 2-D real finite array; None in `shape` means any size >= 1."""
    arr = _as_float(name, value)
    if arr.ndim != 2:
        raise InvalidProblem(f"{name} must be a 2-D matrix, got an array with {arr.ndim} dims")
    for axis, (got, want) in enumerate(zip(arr.shape, shape)):
        if want is not None and got != want:
            raise InvalidProblem(
                f"{name} must have shape {_fmt(shape)}, got {arr.shape} (axis {axis} differs)"
            )
    return arr


def as_vector(name: str, value: Any, size: int | None) -> np.ndarray:
    """Validate and convert a 1-D real finite array (a column or row matrix is flattened)."""
    arr = _as_float(name, value)
    if arr.ndim == 2 and 1 in arr.shape:
        arr = arr.reshape(-1)
    if arr.ndim != 1:
        raise InvalidProblem(f"{name} must be a vector, got an array of shape {arr.shape}")
    if size is not None and arr.size != size:
        raise InvalidProblem(f"{name} must have length {size}, got {arr.size}")
    return arr


def _as_float(name: str, value: Any) -> np.ndarray:
    if value is None:
        raise InvalidProblem(f"{name} is missing (got None)")
    try:
        if np.iscomplexobj(np.asarray(value)):
            raise InvalidProblem(f"{name} must be real, got complex values")
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        if isinstance(exc, InvalidProblem):
            raise
        raise InvalidProblem(f"{name} must be numeric, got {type(value).__name__}: {exc}") from None
    if arr.size == 0:
        raise InvalidProblem(f"{name} is empty: a problem needs at least one unknown")
    bad = ~np.isfinite(arr)
    if bad.any():
        where = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InvalidProblem(f"{name} contains NaN or Inf (first at index {where})")
    return arr


def _fmt(shape: tuple[int | None, ...]) -> str:
    return "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"


@dataclass(frozen=True, eq=False, slots=True)
class LCP:
    """w = M z + q, 0 <= z perp w >= 0. M is n x n, q has length n (n >= 1).

    Its four fields are slots (no per-object __dict__), set once by __init__: a small solve
    builds one per call (issue 23). Pickled and copied through its constructor (__reduce__).
    """

    M: np.ndarray
    q: np.ndarray
    name: str = ""
    meta: dict = field(default_factory=dict)

    def __init__(self, M: Any, q: Any, name: str = "", meta: dict | None = None) -> None:
        # written out (the dataclass keeps its fields, repr and replace). Plain finite float64
        # numpy arrays, C-contiguous, of the right shapes: one C call tests them (dtype, shape,
        # order, finiteness) and fills the slots with their copies, name and meta -- the copies
        # `as_matrix` and `as_vector` would make (lcp/_lemke_py.h: lcp_init). Anything else,
        # including a NaN, takes the general route below and its error message.
        if _init is not None and _init(self, M, q, name, meta):
            return
        M = as_matrix("M", M, (None, None))
        if M.shape[0] != M.shape[1]:
            raise InvalidProblem(f"M must be square, got shape {M.shape}")
        q = as_vector("q", q, M.shape[0])
        for key, value in (("M", M), ("q", q), ("name", name),
                           ("meta", {} if meta is None else meta)):
            object.__setattr__(self, key, value)  # frozen: set once, here

    def __reduce__(self):
        return type(self), (self.M, self.q, self.name, self.meta)

    @property
    def n(self) -> int:
        return self.q.size

    def w(self, z: np.ndarray) -> np.ndarray:
        return self.M @ z + self.q

    def save(self, path: str | os.PathLike) -> Path:
        """Write the problem to a .npz file (atomically)."""
        return _save_npz(path, "LCP", {"M": self.M, "q": self.q}, self.name, self.meta)

    def __repr__(self) -> str:
        label = f" {self.name!r}" if self.name else ""
        return f"<LCP{label} n={self.n}>"


if _kernel.COMPILED and _kernel._lemke_c.lcp_setup(LCP, np.ndarray, np.empty,
                                                      np.dtype(np.float64)):
    _init = _kernel._lemke_c.lcp_init
    # the common call LCP(M, q) without the Python frame of __init__: a method written in C
    # takes the quick route and calls the __init__ above for anything else (lcp/_lemke_py.h)
    _py_init = LCP.__init__  # the Python __init__ (benchmarks and tests switch back to it)
    LCP.__init__ = _kernel._lemke_c.lcp_method(LCP, _py_init)
    # the class's signature stays the Python __init__'s (inspect reads a C __init__ from its
    # text signature, and Python 3.13's inspect cannot bind a method descriptor to the class)
    _signature = inspect.signature(_py_init)
    LCP.__signature__ = _signature.replace(parameters=list(_signature.parameters.values())[1:])


@dataclass(frozen=True, eq=False)
class MLCP:
    """A u + C v + a = 0, w = D u + B v + b, 0 <= v perp w >= 0 (Siconos's layout).

    u has length nu (free), v and w length m. A: nu x nu, C: nu x m, D: m x nu, B: m x m.
    """

    A: np.ndarray
    C: np.ndarray
    D: np.ndarray
    B: np.ndarray
    a: np.ndarray
    b: np.ndarray
    name: str = ""
    meta: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        A = as_matrix("A", self.A, (None, None))
        if A.shape[0] != A.shape[1]:
            raise InvalidProblem(f"A must be square, got shape {A.shape}")
        nu = A.shape[0]
        B = as_matrix("B", self.B, (None, None))
        if B.shape[0] != B.shape[1]:
            raise InvalidProblem(f"B must be square, got shape {B.shape}")
        m = B.shape[0]
        C = as_matrix("C", self.C, (nu, m))
        D = as_matrix("D", self.D, (m, nu))
        a = as_vector("a", self.a, nu)
        b = as_vector("b", self.b, m)
        for key, val in dict(A=A, B=B, C=C, D=D, a=a, b=b).items():
            object.__setattr__(self, key, val)

    @property
    def nu(self) -> int:
        return self.a.size

    @property
    def n(self) -> int:
        """Number of complementarity pairs."""
        return self.b.size

    def to_lcp(self, rcond: float = 1e-12) -> LCP:
        """Schur-complement reduction: u = -A^{-1}(C v + a), hence
        w = (B - D A^{-1} C) v + b - D A^{-1} a.

        Raises NotApplicable when A is singular (to the relative tolerance `rcond` on its
        condition number), naming why.
        """
        Ainv_C, Ainv_a = self._solve_A(np.column_stack([self.C, self.a]), rcond)
        M = self.B - self.D @ Ainv_C
        q = self.b - self.D @ Ainv_a
        return LCP(M, q, name=self.name, meta={**self.meta, "reduced_from": "MLCP"})

    def recover_u(self, v: np.ndarray) -> np.ndarray:
        """The free unknowns of a complementarity solution v: u = -A^{-1}(C v + a)."""
        _, Ainv_rhs = self._solve_A(np.column_stack([self.C @ v + self.a]), 0.0)
        return -Ainv_rhs

    def residuals(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, float]:
        """(w, equality residual max|A u + C v + a|)."""
        w = self.D @ u + self.B @ v + self.b
        eq = float(np.max(np.abs(self.A @ u + self.C @ v + self.a))) if self.nu else 0.0
        return w, eq

    def _solve_A(self, rhs: np.ndarray, rcond: float) -> tuple[np.ndarray, np.ndarray]:
        A = self.A
        if np.count_nonzero(A - np.diag(np.diagonal(A))) == 0:  # diagonal: the mass matrix
            d = np.diagonal(A)
            if np.any(np.abs(d) <= rcond * max(np.abs(d).max(), 1e-300)):
                raise NotApplicable("A is singular (a zero on its diagonal): no Schur reduction")
            sol = rhs / d[:, None]
        else:
            cond = np.linalg.cond(A)
            if not np.isfinite(cond) or cond * rcond > 1:
                raise NotApplicable(
                    f"A is singular or ill-conditioned (cond = {cond:.3g}): the MLCP cannot be "
                    "reduced to an LCP by the Schur complement"
                )
            sol = np.linalg.solve(A, rhs)
        return sol[:, :-1], sol[:, -1]

    def save(self, path: str | os.PathLike) -> Path:
        """Write the problem to a .npz file (atomically)."""
        arrays = {k: getattr(self, k) for k in ("A", "C", "D", "B", "a", "b")}
        return _save_npz(path, "MLCP", arrays, self.name, self.meta)

    def __repr__(self) -> str:
        label = f" {self.name!r}" if self.name else ""
        return f"<MLCP{label} nu={self.nu} m={self.n}>"


Problem = LCP | MLCP


def _save_npz(path, kind: str, arrays: dict, name: str, meta: dict) -> Path:
    path = Path(path)
    if path.suffix != ".npz":
        path = path.with_suffix(path.suffix + ".npz") if path.suffix else path.with_suffix(".npz")
    header = json.dumps({"kind": kind, "name": name, "meta": meta}, default=str)

    def write(tmp: str) -> None:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, __header__=np.array(header), **arrays)

    atomic_write(path, write)
    return path
