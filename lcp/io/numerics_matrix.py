"""Siconos's ``NumericsMatrix`` in text (``NM_write_in_file`` / ``NM_new_from_file``).

    storageType                    0 dense, 1 sparse block (SBM), 2 sparse (CSparse)
    size0                          rows
    size1                          columns
    -- dense (0):
    size0 size1                    repeated
    size0 * size1 numbers          COLUMN-MAJOR (``matrix0[i + j size0]``)
    -- sparse block (1; ``SBM_write_in_file``):
    nbblocks                       stored blocks (0: the zero matrix, nothing else follows)
    blocknumber0 blocknumber1      block rows, block columns
    blocksize0[blocknumber0]       cumulative row counts (the last one is size0)
    blocksize1[blocknumber1]       cumulative column counts
    filled1 filled2                listed block rows + 1, nbblocks
    index1_data[filled1]           CSR-like row pointers into the block list
    index2_data[filled2]           block column of each stored block
    per stored block, by block row: its number, then its entries column-major
    -- sparse (2; ``NSM_write_in_file``: the origin, then CSparse's ``cs_print``):
    origin                         1 triplet, 2 compressed columns (CSC)
    "CSparse Version ..."          one free-text line
    CSC: "R-by-C, nzmax: Z nnz: N, 1-norm: X", then per column j
         "col j : locations p0 to p1" and p1 - p0 + 1 lines "i : x"
    triplet: "triplet: R-by-C, nzmax: Z nnz: N", then N lines "i j : x" (duplicates add up)

Dense and sparse-block matrices are read as numpy arrays, sparse ones as scipy.sparse CSC.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .text import Tokens

STORAGE = {0: "dense", 1: "sparse-block", 2: "sparse"}
NSM_ORIGIN = {1: "triplet", 2: "csc"}


def read_numerics_matrix(tok: Tokens, name: str, expect: tuple[int, int] | None = None
                         ) -> tuple[np.ndarray | sp.csc_matrix, str]:
    """(matrix, storage name) of the NumericsMatrix at the tokens' position; `expect`: the
    shape the problem needs, checked as soon as the header gives it."""
    line = tok.line
    storage = tok.integer(f"the storage type of {name} (0 dense, 1 sparse block, 2 sparse)")
    if storage not in STORAGE:
        raise tok.error(f"unknown storage type {storage} for {name}; expected 0 (dense), "
                        "1 (sparse block) or 2 (sparse)", line)
    size0 = tok.integer(f"the number of rows of {name}", low=1)
    size1 = tok.integer(f"the number of columns of {name}", low=1)
    if expect is not None and (size0, size1) != expect:
        raise tok.error(f"{name} is {size0} x {size1}, the problem's size needs {expect[0]} x "
                        f"{expect[1]}", line)
    if storage == 0:
        line = tok.line
        rows, cols = tok.integer(f"rows of {name} again"), tok.integer(f"columns of {name} again")
        if (rows, cols) != (size0, size1):
            raise tok.error(f"the dense block of {name} says {rows} x {cols}, its header "
                            f"{size0} x {size1}", line)
        values = tok.numbers(size0 * size1, f"the entries of {name} ({size0} x {size1})")
        return values.reshape((size0, size1), order="F"), STORAGE[0]
    if storage == 1:
        return _read_sbm(tok, name, size0, size1), STORAGE[1]
    return _read_nsm(tok, name, size0, size1), STORAGE[2]


def _read_sbm(tok: Tokens, name: str, size0: int, size1: int) -> np.ndarray:
    M = np.zeros((size0, size1))
    nbblocks = tok.integer(f"the number of stored blocks of {name}", low=0)
    if nbblocks == 0:
        return M
    nb0 = tok.integer(f"the number of block rows of {name}", low=1)
    nb1 = tok.integer(f"the number of block columns of {name}", low=1)
    line = tok.line
    bs0 = [tok.integer("a cumulative block row size", low=1) for _ in range(nb0)]
    bs1 = [tok.integer("a cumulative block column size", low=1) for _ in range(nb1)]
    if bs0[-1] != size0 or bs1[-1] != size1 or any(np.diff(bs0) <= 0) or any(np.diff(bs1) <= 0):
        raise tok.error(f"the cumulative block sizes of {name}, {bs0} x {bs1}, must increase "
                        f"to its size {size0} x {size1}", line)
    line = tok.line
    filled1, filled2 = tok.integer("filled1", low=1), tok.integer("filled2", low=0)
    if filled1 > nb0 + 1 or filled2 != nbblocks:
        raise tok.error(f"filled1 = {filled1}, filled2 = {filled2} do not fit {nb0} block rows "
                        f"and {nbblocks} blocks of {name}", line)
    line = tok.line
    index1 = [tok.integer("a block row pointer", low=0) for _ in range(filled1)]
    index2 = [tok.integer("a block column index", low=0) for _ in range(filled2)]
    if index1[0] != 0 or index1[-1] != nbblocks or any(np.diff(index1) < 0):
        raise tok.error(f"the block row pointers of {name} must rise from 0 to {nbblocks}, "
                        f"got {index1}", line)
    if max(index2) >= nb1:
        raise tok.error(f"a block column index of {name} is outside 0..{nb1 - 1}", line)
    row_start, col_start = [0] + bs0, [0] + bs1
    for brow in range(filled1 - 1):
        for num in range(index1[brow], index1[brow + 1]):
            line = tok.line
            got = tok.integer(f"the number of block {num}")
            if got != num:
                raise tok.error(f"block number {got} where {num} was expected", line)
            bcol = index2[num]
            r0, r1 = row_start[brow], row_start[brow + 1]
            c0, c1 = col_start[bcol], col_start[bcol + 1]
            values = tok.numbers((r1 - r0) * (c1 - c0), f"the entries of block {num} of {name}")
            M[r0:r1, c0:c1] = values.reshape((r1 - r0, c1 - c0), order="F")
    return M


def _dims(tok: Tokens, name: str, size0: int, size1: int) -> None:
    line = tok.line
    item = tok.items[tok.pos] if tok.pos < len(tok.items) else ""
    tok.pos += 1
    try:
        r, c = (int(x) for x in item.rstrip(",").split("-by-"))
    except ValueError:
        raise tok.error(f"{item!r} where the size 'R-by-C,' of {name} was expected",
                        line) from None
    if (r, c) != (size0, size1):
        raise tok.error(f"the sparse part of {name} says {r}-by-{c}, its header {size0} x "
                        f"{size1}", line)


def _read_nsm(tok: Tokens, name: str, size0: int, size1: int) -> sp.csc_matrix:
    line = tok.line
    origin = tok.integer(f"the sparse origin of {name} (1 triplet, 2 compressed columns)")
    if origin not in NSM_ORIGIN:
        raise tok.error(f"sparse origin {origin} of {name} is not read (1 triplet and 2 "
                        "compressed columns are)", line)
    line = tok.line
    head = tok.skip_line()
    if not head.startswith("CSparse"):
        raise tok.error(f"{head[:40]!r} where CSparse's version line was expected", line)
    if origin == 1:
        tok.word("triplet:")
    _dims(tok, name, size0, size1)
    tok.word("nzmax:")
    tok.integer("nzmax", low=0)
    tok.word("nnz:")
    nnz = tok.integer("nnz", low=0)
    if origin == 1:
        rows, cols, vals = np.empty(nnz, int), np.empty(nnz, int), np.empty(nnz)
        for k in range(nnz):
            rows[k] = tok.integer(f"the row of entry {k} of {name}", low=0)
            cols[k] = tok.integer(f"the column of entry {k} of {name}", low=0)
            tok.word(":")
            vals[k] = tok.number(f"the value of entry {k} of {name}")
        if nnz and (rows.max() >= size0 or cols.max() >= size1):
            raise tok.error(f"an entry of {name} lies outside {size0} x {size1}")
        return sp.coo_matrix((vals, (rows, cols)), shape=(size0, size1)).tocsc()
    tok.word("1-norm:")
    tok.number("the 1-norm")
    indptr = np.zeros(size1 + 1, dtype=np.int64)
    rows_l: list[np.ndarray] = []
    vals_l: list[np.ndarray] = []
    for j in range(size1):
        line = tok.line
        tok.word("col")
        got = tok.integer(f"the column number {j}")
        if got != j:
            raise tok.error(f"column {got} where column {j} of {name} was expected", line)
        tok.word(":")
        tok.word("locations")
        p0 = tok.integer("the first location", low=0)
        tok.word("to")
        p1 = tok.integer("the last location")
        if p0 != indptr[j] or p1 < p0 - 1:
            raise tok.error(f"column {j} of {name} spans locations {p0} to {p1}, expected "
                            f"to start at {indptr[j]}", line)
        count = p1 - p0 + 1
        r = np.empty(count, dtype=np.int64)
        v = np.empty(count)
        for k in range(count):
            r[k] = tok.integer(f"a row index in column {j} of {name}", low=0)
            tok.word(":")
            v[k] = tok.number(f"a value in column {j} of {name}")
        if count and r.max() >= size0:
            raise tok.error(f"row {int(r.max())} of column {j} lies outside the {size0} rows "
                            f"of {name}")
        indptr[j + 1] = indptr[j] + count
        rows_l.append(r)
        vals_l.append(v)
    if indptr[-1] != nnz:
        raise tok.error(f"{name} holds {indptr[-1]} entries, its header says nnz = {nnz}")
    rows = np.concatenate(rows_l) if rows_l else np.zeros(0, int)
    vals = np.concatenate(vals_l) if vals_l else np.zeros(0)
    M = sp.csc_matrix((vals, rows, indptr), shape=(size0, size1))
    M.sum_duplicates()
    return M


# -- writing ---------------------------------------------------------------------------------

def _num(v: float) -> str:
    return f"{v:32.24e}"


def write_numerics_matrix(M, storage: str = "dense", blocks: list[int] | None = None
                          ) -> list[str]:
    """The lines of M in the given storage ("dense", "sparse-block" with the square block
    sizes `blocks`, or "sparse": CSC). Numbers keep 25 significant digits (round trip)."""
    rows, cols = M.shape
    if storage == "dense":
        A = M.toarray() if sp.issparse(M) else np.asarray(M, dtype=float)
        flat = A.reshape(-1, order="F")
        out = ["0", str(rows), str(cols), f"{rows}\t{cols}"]
        out += [" ".join(_num(v) for v in flat[j * cols:(j + 1) * cols])
                for j in range(rows)]
        return out
    if storage == "sparse":
        C = sp.csc_matrix(M)
        C.sort_indices()
        norm1 = float(abs(C).sum(axis=0).max()) if C.nnz else 0.0
        out = ["2", str(rows), str(cols), "2",
               "CSparse Version 3.1.9, May 4, 2016.  Copyright (c) Timothy A. Davis, 2006-2016",
               f"{rows}-by-{cols}, nzmax: {C.nnz} nnz: {C.nnz}, 1-norm: {norm1:.17g}"]
        for j in range(cols):
            p0, p1 = int(C.indptr[j]), int(C.indptr[j + 1])
            out.append(f"    col {j} : locations {p0} to {p1 - 1}")
            out += [f"      {int(C.indices[p])} : {C.data[p]:.17g}" for p in range(p0, p1)]
        return out
    if storage != "sparse-block":
        raise ValueError(f"storage must be 'dense', 'sparse-block' or 'sparse', got {storage!r}")
    A = M.toarray() if sp.issparse(M) else np.asarray(M, dtype=float)
    if blocks is None or sum(blocks) != rows or rows != cols or min(blocks) < 1:
        raise ValueError(f"block sizes {blocks} must be positive and sum to n = {rows} "
                         "(square M)")
    starts = np.concatenate([[0], np.cumsum(blocks)]).astype(int)
    stored: list[tuple[int, int]] = []
    pointers = [0]
    for br in range(len(blocks)):
        for bc in range(len(blocks)):
            if np.any(A[starts[br]:starts[br + 1], starts[bc]:starts[bc + 1]] != 0):
                stored.append((br, bc))
        pointers.append(len(stored))
    out = ["1", str(rows), str(cols), str(len(stored))]
    if stored:
        cum = " ".join(str(int(s)) for s in starts[1:])
        out += [f"{len(blocks)}", f"{len(blocks)}", cum, cum, f"{len(blocks) + 1}",
                f"{len(stored)}", " ".join(map(str, pointers)),
                " ".join(str(bc) for _, bc in stored)]
        for num, (br, bc) in enumerate(stored):
            blk = A[starts[br]:starts[br + 1], starts[bc]:starts[bc + 1]]
            out.append(str(num))
            out += [_num(v) for v in blk.reshape(-1, order="F")]
    return out
