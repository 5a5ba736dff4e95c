"""Siconos's friction-contact text format (``frictionContact_newFromFile``, Siconos numerics
FrictionContactProblem.c), 2D problems, read and written.

    dimension                      2 (3: a 3D problem, refused)
    numberOfContacts               c
    W                              a NumericsMatrix (lcp.io.numerics_matrix), 2c x 2c
    q                              size1(W) = 2c numbers
    mu                             c numbers
    numbers after that             ignored, as Siconos does (its files often end with "1")

Per contact the unknowns are (normal, tangent): r = [r_n0, r_t0, r_n1, r_t1, ...]; a disk
against a wall has W_tt = 3 W_nn (unit radius and mass, I = m r^2 / 2), which the test
files show (e.g. FrictionContactProblem00031: 0.4436 and 1.3308). Dense and sparse-block W
are read as numpy arrays, sparse (CSparse) W as a scipy.sparse matrix.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..problems.friction import FrictionContact2D
from .numerics_matrix import read_numerics_matrix, write_numerics_matrix
from .text import Tokens, WrongKind, check_kind, write_new


def read_siconos_fc2d(path: str | os.PathLike) -> FrictionContact2D:
    """Read a 2D friction-contact problem (module doc). Raises FileFormatError naming the
    file, the line and what was expected; WrongKind for an LCP, MLCP or 3D file."""
    path = Path(path)
    tok = Tokens(path.read_text(errors="replace"), str(path))
    check_kind(tok, "fc2d")
    return read_fc2d_tokens(tok, path)


def read_fc2d_tokens(tok: Tokens, path: Path) -> FrictionContact2D:
    line = tok.line
    d = tok.integer("the dimension (2)")
    if d != 2:
        if d == 3:
            raise WrongKind(str(path), line, "a 3D friction-contact problem (dimension 3): "
                            "rigidlcp reads 2D ones")
        raise tok.error(f"dimension {d} where 2 was expected", line)
    c = tok.integer("the number of contacts", low=1)
    W, storage = read_numerics_matrix(tok, "W", expect=(2 * c, 2 * c))
    q = tok.numbers(2 * c, f"q ({2 * c} numbers)")
    mu = tok.numbers(c, f"mu ({c} numbers, one per contact)")
    extra = tok.trailing_numbers()  # Siconos's files often end with a "1"; Siconos ignores it
    if np.any(mu < 0):
        raise tok.error(f"a negative friction coefficient (contact {int(np.argmin(mu))}: "
                        f"{mu.min()})")
    meta = {"source": str(path), "format": "siconos-fc2d", "storage": storage,
            "trailing_numbers": extra}
    return FrictionContact2D(W, q, mu, name=path.stem, meta=meta)


def write_siconos_fc2d(problem: FrictionContact2D, path: str | os.PathLike, *,
                       storage: str = "dense", blocks: list[int] | None = None) -> Path:
    """Write `problem` in Siconos's format (W dense, "sparse" or "sparse-block" with 2 x 2
    blocks per contact by default). Never overwrites (FileExistsError)."""
    if storage == "sparse-block" and blocks is None:
        blocks = [2] * problem.c
    out = ["2", str(problem.c)] + write_numerics_matrix(problem.W, storage, blocks)
    out.append(" ".join(f"{v:32.24e}" for v in problem.q))
    out.append(" ".join(f"{v:32.24e}" for v in problem.mu))
    return write_new(path, out)
