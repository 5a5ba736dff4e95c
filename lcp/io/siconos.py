"""Plain-text LCP files of Siconos's numerics test suite (``numerics/src/LCP/test/data/*.dat``).

A user points the benchmark harness at a folder of such files; nothing of Siconos is shipped.
The layout is the one written by ``linearComplementarity_printInFile`` and read by
``linearComplementarity_newFromFile`` (Siconos numerics, LinearComplementarityProblem.c), i.e.
the problem size followed by a ``NumericsMatrix`` (``NM_write_in_file`` / ``NM_new_from_file``)
and q. Every item is a whitespace-separated number (C ``fscanf``), so line breaks do not matter:

    n                              problem size
    storageType                    0 dense, 1 sparse block (SBM), 2 sparse (not read here)
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
    -- then
    q                              size1 numbers
    anything                       ignored (some test files end with a free-text remark)

The column-major order was checked against Siconos's own reader (python3-siconos 4.4:
``linearComplementarity_newFromFilename`` reads the file ``2 0 2 2 2 2 1 3 2 4 -1 -2`` as
M = [[1, 2], [3, 4]]); tests/verify/test_problem_sets.py repeats that check when the system
interpreter has siconos.numerics.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from rigidlcp.lcp import LCP, InvalidProblem

STORAGE = {0: "dense", 1: "sparse-block", 2: "sparse"}


class _Tokens:
    """The file's whitespace-separated items, consumed in order, with useful errors."""

    def __init__(self, text: str, path: str):
        self.items = text.split()
        self.pos = 0
        self.path = path

    def _next(self, what: str) -> str:
        if self.pos >= len(self.items):
            raise InvalidProblem(f"{self.path}: the file ends where {what} was expected "
                                 f"(after {self.pos} items)")
        item = self.items[self.pos]
        self.pos += 1
        return item

    def integer(self, what: str) -> int:
        item = self._next(what)
        try:
            value = float(item)
        except ValueError:
            raise InvalidProblem(f"{self.path}: item {self.pos} ({item!r}) should be {what}, "
                                 "an integer") from None
        if not value.is_integer():
            raise InvalidProblem(f"{self.path}: item {self.pos} ({item!r}) should be {what}, "
                                 "an integer")
        return int(value)

    def numbers(self, count: int, what: str) -> np.ndarray:
        out = np.empty(count)
        for k in range(count):
            item = self._next(f"{what} (number {k + 1} of {count})")
            try:
                out[k] = float(item)
            except ValueError:
                raise InvalidProblem(f"{self.path}: item {self.pos} ({item!r}) should be "
                                     f"{what} (number {k + 1} of {count})") from None
        return out


def read_siconos_lcp(path: str | os.PathLike) -> LCP:
    """Read an LCP written in Siconos's numerics test-suite format (see the module doc).

    Raises InvalidProblem naming the item that does not fit (sizes that disagree, a truncated
    file, an unsupported storage type), FileNotFoundError when there is no file.
    """
    path = Path(path)
    tok = _Tokens(path.read_text(), str(path))
    n = tok.integer("the problem size n")
    storage = tok.integer("the matrix storage type")
    size0 = tok.integer("size0 (rows of M)")
    size1 = tok.integer("size1 (columns of M)")
    if storage not in STORAGE:
        raise InvalidProblem(f"{path}: unknown matrix storage type {storage} "
                             f"(Siconos knows {STORAGE})")
    if not (n == size0 == size1) or n < 1:
        raise InvalidProblem(f"{path}: an LCP needs a square M of the problem's size; got "
                             f"n = {n}, M {size0} x {size1}")
    if storage == 0:
        rows, cols = tok.integer("size0 again"), tok.integer("size1 again")
        if (rows, cols) != (size0, size1):
            raise InvalidProblem(f"{path}: the dense block says {rows} x {cols}, the header "
                                 f"{size0} x {size1}")
        M = tok.numbers(size0 * size1, "an entry of M").reshape((size0, size1), order="F")
    elif storage == 1:
        M = _read_sparse_block(tok, size0, size1)
    else:
        raise InvalidProblem(f"{path}: storage type 2 (CSparse) is not supported; only dense "
                             "(0) and sparse-block (1) files are read")
    q = tok.numbers(size1, "an entry of q")
    meta = {"source": str(path), "format": "siconos", "storage": STORAGE[storage]}
    return LCP(M, q, name=path.stem, meta=meta)


def _read_sparse_block(tok: _Tokens, size0: int, size1: int) -> np.ndarray:
    M = np.zeros((size0, size1))
    nbblocks = tok.integer("nbblocks")
    if nbblocks == 0:
        return M
    nb0, nb1 = tok.integer("blocknumber0"), tok.integer("blocknumber1")
    bs0 = [tok.integer("a block row size") for _ in range(nb0)]
    bs1 = [tok.integer("a block column size") for _ in range(nb1)]
    if not bs0 or not bs1 or bs0[-1] != size0 or bs1[-1] != size1:
        raise InvalidProblem(f"{tok.path}: block sizes {bs0} x {bs1} do not end at the "
                             f"matrix size {size0} x {size1}")
    filled1, filled2 = tok.integer("filled1"), tok.integer("filled2")
    # filled1 - 1 block rows are listed (trailing empty block rows may be left out).
    if not 1 <= filled1 <= nb0 + 1 or filled2 != nbblocks:
        raise InvalidProblem(f"{tok.path}: filled1 = {filled1}, filled2 = {filled2} do not fit "
                             f"{nb0} block rows and {nbblocks} blocks")
    index1 = [tok.integer("a block row pointer") for _ in range(filled1)]
    index2 = [tok.integer("a block column index") for _ in range(filled2)]
    row_start = [0] + bs0
    col_start = [0] + bs1
    for brow in range(filled1 - 1):
        for num in range(index1[brow], index1[brow + 1]):
            got = tok.integer("a block number")
            if got != num:
                raise InvalidProblem(f"{tok.path}: block number {got} where {num} was expected")
            bcol = index2[num]
            if not 0 <= bcol < nb1:
                raise InvalidProblem(f"{tok.path}: block {num} is in column {bcol}, outside "
                                     f"0..{nb1 - 1}")
            r0, r1 = row_start[brow], row_start[brow + 1]
            c0, c1 = col_start[bcol], col_start[bcol + 1]
            values = tok.numbers((r1 - r0) * (c1 - c0), f"an entry of block {num}")
            M[r0:r1, c0:c1] = values.reshape((r1 - r0, c1 - c0), order="F")
    return M


def write_siconos_lcp(
    problem: LCP, path: str | os.PathLike, *, blocks: list[int] | None = None
) -> Path:
    """Write `problem` in Siconos's format: dense storage, or sparse-block storage with the
    given block sizes (e.g. [2, 3] for a 5 x 5 M; blocks that are exactly zero are not
    stored). Numbers are written with 25 significant digits, which round-trips every double.
    """
    M, q = problem.M, problem.q
    n = q.size
    out = [f"{n}"]
    if blocks is None:
        out += ["0", f"{n}", f"{n}", f"{n}\t{n}"]
        cols = M.reshape(-1, order="F")
        out += [" ".join(f"{v:32.24e}" for v in cols[j * n:(j + 1) * n]) for j in range(n)]
    else:
        if sum(blocks) != n or min(blocks) < 1:
            raise ValueError(f"block sizes {blocks} must be positive and sum to n = {n}")
        starts = np.concatenate([[0], np.cumsum(blocks)]).astype(int)
        stored: list[tuple[int, int]] = []
        pointers = [0]
        for br in range(len(blocks)):
            for bc in range(len(blocks)):
                blk = M[starts[br]:starts[br + 1], starts[bc]:starts[bc + 1]]
                if np.any(blk != 0):
                    stored.append((br, bc))
            pointers.append(len(stored))
        out += ["1", f"{n}", f"{n}", f"{len(stored)}"]
        if stored:
            cum = " ".join(str(int(s)) for s in starts[1:])
            out += [f"{len(blocks)}", f"{len(blocks)}", cum, cum,
                    f"{len(blocks) + 1}", f"{len(stored)}",
                    " ".join(map(str, pointers)), " ".join(str(bc) for _, bc in stored)]
            for num, (br, bc) in enumerate(stored):
                blk = M[starts[br]:starts[br + 1], starts[bc]:starts[bc + 1]]
                out.append(str(num))
                out += [f"{v:32.24e}" for v in blk.reshape(-1, order="F")]
    out.append(" ".join(f"{v:32.24e}" for v in q))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(out) + "\n")
    return path
