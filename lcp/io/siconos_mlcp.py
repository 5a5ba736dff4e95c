"""Siconos's MLCP text format (``mixedLinearComplementarity_newFromFile``, Siconos numerics
MixedLinearComplementarityProblem.c), read and written.

    isStorageType1                 1: the (M, q) form follows
    isStorageType2                 1: the (A, B, C, D, a, b) form follows
    n                              free unknowns u (equality rows)
    m                              complementarity pairs (v, w)
    -- when isStorageType1:
    blocksRows                     0 = r_0 < r_1 < ... < r_K = n + m (read until n + m)
    blocksIsComp[K]                1: rows r_k .. r_{k+1} - 1 are complementarity rows
    M                              a NumericsMatrix (lcp.io.numerics_matrix), (n+m) x (n+m)
    q                              size1(M) numbers (Siconos reads the *column* count)
    -- when isStorageType2, every matrix ROW-MAJOR (``A[i + j n]`` read with j fastest):
    A (n x n), B (m x m), C (n x m), D (m x n), a (n), b (m)
    numbers after that             ignored (Siconos's test files often end with a solution)

In the (M, q) form, unknown j goes with row j: the equality rows' unknowns are u, the others v,
and M, q permuted to put u first are [[A, C], [D, B]], [a, b] (lcp.MLCP's layout). The (M, q)
form is used when both are present; `meta["abcd_agrees"]` says whether the other form is the
same problem. A rectangular M (size0 != size1) is read and refused (UnsupportedProblem).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..problems.problem import MLCP
from .numerics_matrix import read_numerics_matrix, write_numerics_matrix
from .text import Tokens, UnsupportedProblem, check_kind, write_new


def read_siconos_mlcp(path: str | os.PathLike) -> MLCP:
    """Read an MLCP in Siconos's text format (see the module doc). Raises FileFormatError
    (naming the file, the line and what was expected), WrongKind for another kind of Siconos
    file, UnsupportedProblem for a rectangular M, FileNotFoundError."""
    path = Path(path)
    tok = Tokens(path.read_text(errors="replace"), str(path))
    check_kind(tok, "mlcp")
    return read_mlcp_tokens(tok, path)


def read_mlcp_tokens(tok: Tokens, path: Path) -> MLCP:
    line = tok.line
    st1 = tok.integer("isStorageType1 (0 or 1)")
    st2 = tok.integer("isStorageType2 (0 or 1)")
    if st1 not in (0, 1) or st2 not in (0, 1) or not (st1 or st2):
        raise tok.error(f"storage flags {st1} {st2}: expected 0 or 1 each, one of them 1", line)
    n = tok.integer("n, the number of free unknowns", low=0)
    m = tok.integer("m, the number of complementarity pairs", low=1)
    meta: dict = {"source": str(path), "format": "siconos-mlcp", "n": n, "m": m}
    mq = abcd = None
    if st1:
        line = tok.line
        rows = [tok.integer("blocksRows[0] = 0")]
        if rows[0] != 0:
            raise tok.error(f"blocksRows must start at 0, got {rows[0]}", line)
        while rows[-1] != n + m:
            r = tok.integer(f"the next of blocksRows (ending at n + m = {n + m})")
            if r <= rows[-1] or r > n + m:
                raise tok.error(f"blocksRows {rows + [r]} must increase to n + m = {n + m}")
            rows.append(r)
        comp = [tok.integer("blocksIsComp (0 or 1)") for _ in range(len(rows) - 1)]
        if any(c not in (0, 1) for c in comp):
            raise tok.error(f"blocksIsComp {comp}: expected 0 or 1 each")
        is_comp = np.zeros(n + m, dtype=bool)
        for k, c in enumerate(comp):
            is_comp[rows[k]:rows[k + 1]] = bool(c)
        if int(is_comp.sum()) != m:
            raise tok.error(f"blocksIsComp marks {int(is_comp.sum())} complementarity rows, "
                            f"m = {m}")
        line = tok.line
        M, storage = read_numerics_matrix(tok, "M")
        M = M.toarray() if hasattr(M, "toarray") else M
        q = tok.numbers(M.shape[1], f"q ({M.shape[1]} numbers, the columns of M)")
        meta.update(storage=storage, blocks_rows=rows, blocks_is_comp=comp,
                    M_shape=list(M.shape))
        mq = (M, q, is_comp, line)
    if st2:
        A = tok.numbers(n * n, f"A ({n} x {n}, by rows)").reshape(n, n)
        B = tok.numbers(m * m, f"B ({m} x {m}, by rows)").reshape(m, m)
        C = tok.numbers(n * m, f"C ({n} x {m}, by rows)").reshape(n, m)
        D = tok.numbers(m * n, f"D ({m} x {n}, by rows)").reshape(m, n)
        a = tok.numbers(n, f"a ({n} numbers)")
        b = tok.numbers(m, f"b ({m} numbers)")
        abcd = (A, C, D, B, a, b)
    meta["trailing_numbers"] = tok.trailing_numbers()
    if mq is not None:
        M, q, is_comp, line = mq
        if M.shape[0] != M.shape[1]:
            raise UnsupportedProblem(
                f"{path}, line {line}: a rectangular MLCP (M is {M.shape[0]} x {M.shape[1]}, "
                f"q has {q.size} entries, n = {n}, m = {m}): rigidlcp solves square MLCPs "
                "(A u + C v + a = 0 with as many equations as free unknowns) only")
        if M.shape[0] != n + m:
            raise tok.error(f"M is {M.shape[0]} x {M.shape[1]}, expected n + m = {n + m}",
                            line)
        eq, cp = np.flatnonzero(~is_comp), np.flatnonzero(is_comp)
        parts = (M[np.ix_(eq, eq)], M[np.ix_(eq, cp)], M[np.ix_(cp, eq)], M[np.ix_(cp, cp)],
                 q[eq], q[cp])
        if abcd is not None:
            meta["abcd_agrees"] = all(np.array_equal(x, y) for x, y in zip(parts, abcd))
        A, C, D, B, a, b = parts
    else:
        A, C, D, B, a, b = abcd
    if n == 0:
        raise UnsupportedProblem(f"{path}: an MLCP without free unknowns (n = 0) is an LCP; "
                                 "rigidlcp's MLCP needs n >= 1 (read it as lcp.LCP(B, b))")
    return MLCP(A, C, D, B, a, b, name=path.stem, meta=meta)


def write_siconos_mlcp(problem: MLCP, path: str | os.PathLike, *,
                       storage: str = "dense") -> Path:
    """Write `problem` in Siconos's MLCP format, both forms (M, q with u first; A, B, C, D, a,
    b), M in the given storage ("dense" or "sparse"). Never overwrites (FileExistsError)."""
    n, m = problem.nu, problem.n
    M = np.block([[problem.A, problem.C], [problem.D, problem.B]])
    q = np.concatenate([problem.a, problem.b])

    def num(v):
        return " ".join(f"{x:32.24e}" for x in np.ravel(v))

    out = ["1", "1", str(n), str(m), f"0 {n} {n + m}", "0 1"]
    out += write_numerics_matrix(M, storage)
    out += [num(q), num(problem.A), num(problem.B), num(problem.C), num(problem.D),
            num(problem.a), num(problem.b)]
    return write_new(path, out)
