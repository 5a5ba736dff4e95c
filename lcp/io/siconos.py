"""Plain-text LCP files of Siconos's numerics test suite (``numerics/src/LCP/test/data/*.dat``),
and `read_siconos`, which detects the kind of a Siconos text file (LCP, MLCP, 2D friction
contact) and reads it (lcp.io.siconos_mlcp, lcp.io.siconos_fc2d; matrices: lcp.io.numerics_matrix).

A user points the benchmark harness at a folder of such files; nothing of Siconos is shipped.
The layout is the one written by ``linearComplementarity_printInFile`` and read by
``linearComplementarity_newFromFile`` (Siconos numerics, LinearComplementarityProblem.c), i.e.
the problem size followed by a ``NumericsMatrix`` (``NM_write_in_file`` / ``NM_new_from_file``)
and q. Every item is a whitespace-separated number (C ``fscanf``), so line breaks do not matter:

    n                              problem size
    storageType                    0 dense, 1 sparse block (SBM), 2 sparse (CSparse)
    size0                          rows of M
    size1                          columns of M
    -- dense (storageType 0):
    size0 size1                    repeated (tab-separated)
    size0 * size1 numbers          M in COLUMN-MAJOR order (Siconos's ``matrix0[i + j size0]``);
                                   Siconos writes a line break every size1 numbers, so for a
                                   square M each line of the file is a *column* of M
    -- sparse block (storageType 1; ``SBM_write_in_file``):
    nbblocks                       number of stored blocks (0: M = 0, nothing else follows)
    blocknumber0 blocknumber1      number of block rows, block columns
    blocksize0[0..blocknumber0)    cumulative row counts (the last one is size0)
    blocksize1[0..blocknumber1)    cumulative column counts
    filled1 filled2                (listed block rows) + 1, nbblocks
    index1_data[filled1]           CSR-like row pointers into the block list
    index2_data[filled2]           block column of each stored block
    for each stored block, by block row: its number, then rows * cols numbers column-major
    -- sparse (storageType 2): see lcp.io.numerics_matrix
    -- then
    q                              size1 numbers
    a remark                       ignored when it is text (some test files end with one);
                                   more *numbers* after q mean another kind of file (e.g. an
                                   MLCP, which Siconos's LCP reader reads as a 1 x 1 LCP) and
                                   are refused

The column-major order was checked against Siconos's own reader (python3-siconos 4.4:
``linearComplementarity_newFromFilename`` reads the file ``2 0 2 2 2 2 1 3 2 4 -1 -2`` as
M = [[1, 2], [3, 4]]); tests/verify/test_problem_sets.py repeats that check when the system
interpreter has siconos.numerics.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..problems.problem import LCP, MLCP
from .numerics_matrix import STORAGE, read_numerics_matrix, write_numerics_matrix
from .text import (
    KIND_NAMES,
    FileFormatError,
    Tokens,
    UnsupportedProblem,
    WrongKind,
    check_kind,
    header_kinds,
    write_new,
)

__all__ = ["read_siconos_lcp", "write_siconos_lcp", "read_siconos", "siconos_kind", "STORAGE",
           "write_new"]


def read_siconos_lcp(path: str | os.PathLike) -> LCP:
    """Read an LCP written in Siconos's numerics test-suite format (see the module doc).

    Raises FileFormatError (an InvalidProblem) naming the file, the line and what was expected
    (sizes that disagree, a truncated file, an unknown storage type, numbers left over),
    WrongKind when the file is an MLCP or friction-contact file, FileNotFoundError when there
    is no file.
    """
    path = Path(path)
    tok = Tokens(path.read_text(errors="replace"), str(path))
    check_kind(tok, "lcp")
    kind = siconos_kind(tok)  # a tiny MLCP's header is also an LCP's: which reader fits?
    if kind not in ("lcp", None):
        raise WrongKind(str(path), 1, f"this is a Siconos {KIND_NAMES[kind]} file, not an LCP")
    tok.pos = 0
    return _read_lcp(tok, path)


def _read_lcp(tok: Tokens, path: Path) -> LCP:
    n = tok.integer("the problem size n", low=1)
    M, storage = read_numerics_matrix(tok, "M", expect=(n, n))
    q = tok.numbers(n, f"q ({n} numbers)")
    extra = tok.trailing_numbers()
    if extra:
        raise tok.error(f"{extra} more number(s) after q, where the end of the file or a text "
                        "remark was expected: not an LCP file of this size")
    M = M.toarray() if hasattr(M, "toarray") else M
    meta = {"source": str(path), "format": "siconos", "storage": storage}
    return LCP(M, q, name=path.stem, meta=meta)


def siconos_kind(tok: Tokens) -> str | None:
    """The kind of a Siconos text file ("lcp", "mlcp", "fc2d", "fc3d") from its header
    (lcp.io.text.header_kinds); when several headers fit a tiny problem, the kind whose reader
    takes the whole file. None when no header fits."""
    fits = header_kinds(tok)
    if len(fits) <= 1:
        return fits[0] if fits else None
    # several headers fit (tiny problems): the kind whose reader takes the whole file, else
    # the one whose reader got furthest (its error is the telling one)
    furthest, best = -1, fits[0]
    for kind in fits:
        tok.pos = 0
        try:
            _READERS[kind](tok, Path(tok.path))
        except FileFormatError:
            if tok.pos > furthest:
                furthest, best = tok.pos, kind
            continue
        except UnsupportedProblem:
            return kind
        return kind
    return best


def _packing_hint(text: str) -> str:
    """A hint for a packing file of disks given where a problem is expected (a CSV whose
    header names x, y, r, or a LAMMPS dump): `rigidlcp solve pile.csv` said only that no
    Siconos header fits."""
    lines = [s.strip() for s in text.lstrip("\ufeff").splitlines() if s.strip()]
    first = next((s for s in lines if not s.startswith("#")), "")
    names = {f.strip() for f in first.split(",")}
    if {"x", "y", "r"} <= names or (lines and lines[0] == "ITEM: TIMESTEP"):
        return ("; this looks like a packing of disks (docs/packings.md): `rigidlcp forceset FILE` "
                "analyses it at rest, `rigidlcp simulate --packing FILE` runs it")
    return ""


def read_siconos(path: str | os.PathLike) -> LCP | MLCP:
    """Read any Siconos text problem file: LCP, MLCP or 2D friction contact (the kind is
    detected from the header; see `siconos_kind`). Returns an lcp.LCP, lcp.MLCP or
    lcp.FrictionContact2D."""
    path = Path(path)
    text = path.read_text(errors="replace")
    tok = Tokens(text, str(path))
    kind = siconos_kind(tok)
    if kind is None:
        raise FileFormatError(str(path), 1, "no Siconos header fits: expected an LCP "
                              "(n, storage, n, n), an MLCP (0|1, 0|1, n, m, ...) or a friction-"
                              "contact problem (2, contacts, storage, 2 contacts, 2 contacts)"
                              + _packing_hint(text))
    if kind == "fc3d":
        raise WrongKind(str(path), 1, "a 3D friction-contact problem: rigidlcp reads 2D ones")
    tok.pos = 0
    return _READERS[kind](tok, path)


def _mlcp(tok, path):
    from .siconos_mlcp import read_mlcp_tokens

    return read_mlcp_tokens(tok, path)


def _fc2d(tok, path):
    from .siconos_fc2d import read_fc2d_tokens

    return read_fc2d_tokens(tok, path)


_READERS = {"lcp": _read_lcp, "mlcp": _mlcp, "fc2d": _fc2d}


def write_siconos_lcp(
    problem: LCP, path: str | os.PathLike, *, blocks: list[int] | None = None,
    storage: str | None = None,
) -> Path:
    """Write `problem` in Siconos's format: dense storage, sparse-block storage with the
    given block sizes (e.g. [2, 3] for a 5 x 5 M; blocks that are exactly zero are not
    stored), or storage="sparse" (CSparse's compressed columns). Numbers are written with 25
    significant digits (17 in sparse storage), which round-trips every double. An existing
    file is not overwritten (FileExistsError).
    """
    storage = storage or ("dense" if blocks is None else "sparse-block")
    M, q = problem.M, problem.q
    out = [f"{q.size}"] + write_numerics_matrix(M, storage, blocks)
    out.append(" ".join(f"{v:32.24e}" for v in q))
    return write_new(path, out)
