"""lcp.io: Siconos's LCP, MLCP and 2D friction-contact text formats, against hand-derived files,
round trips, malformed files, and Siconos's own readers when /usr/bin/python3 has them."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from rigidlcp import lcp
from rigidlcp.lcp.io.siconos import read_siconos, read_siconos_lcp, write_siconos_lcp
from rigidlcp.lcp.io.siconos_fc2d import read_siconos_fc2d, write_siconos_fc2d
from rigidlcp.lcp.io.siconos_mlcp import read_siconos_mlcp, write_siconos_mlcp
from rigidlcp.lcp.io.text import FileFormatError, UnsupportedProblem, WrongKind

DATA = Path(__file__).resolve().parents[1] / "data" / "siconos"
SYSTEM_PYTHON = "/usr/bin/python3"
DUMP = Path(__file__).with_name("siconos_dump.py")


def test_m2n1_is_read_as_derived_by_hand():
    # The file: flags 1 1, n = 1, m = 2, blocksRows 0 1 3, blocksIsComp 0 1, M dense 3 x 3
    # by columns (1 0 0 | 2 1 0 | 0 1.3333 1), q = (-1, 1, -3); then A..b by rows.
    p = lcp.load(DATA / "m2n1_mlcp.dat")
    assert isinstance(p, lcp.MLCP) and (p.nu, p.n) == (1, 2)
    assert p.A.tolist() == [[1.0]] and p.C.tolist() == [[2.0, 0.0]]
    assert p.D.tolist() == [[0.0], [0.0]] and p.B.tolist() == [[1.0, 1.3333], [0.0, 1.0]]
    assert p.a.tolist() == [-1.0] and p.b.tolist() == [1.0, -3.0]
    assert p.meta["abcd_agrees"] and p.meta["trailing_numbers"] == 4


def test_fc2d_layout_normal_then_tangent_per_contact():
    p = lcp.load(DATA / "FrictionContactProblem00031.dat")
    assert isinstance(p, lcp.FrictionContact2D) and p.c == 11
    W = p.dense_W()
    # a disk on the ground: W_tt = 3 W_nn (I = m r^2 / 2), normal first
    assert W[1, 1] == pytest.approx(3 * W[0, 0], rel=1e-5)
    assert p.mu.tolist() == [0.9] * 11


def test_hand_written_sparse_and_sparse_block_files(tmp_path):
    csc = ("2\n1\n2\n2\n2\n2\nCSparse Version 3.1.9, May 4, 2016.  Copyright (c) T. Davis\n"
           "2-by-2, nzmax: 3 nnz: 3, 1-norm: 5\n    col 0 : locations 0 to 1\n      0 : 2\n"
           "      1 : -1\n    col 1 : locations 2 to 2\n      1 : 3\n-1 0\n0.5\n")
    (tmp_path / "s.dat").write_text(csc)
    p = read_siconos_fc2d(tmp_path / "s.dat")
    assert sp.issparse(p.W) and p.W.toarray().tolist() == [[2, 0], [-1, 3]]
    assert p.q.tolist() == [-1, 0] and p.mu.tolist() == [0.5]
    # sparse block, 2 contacts, only the diagonal blocks, each by columns
    sbm = ("2\n2\n1\n4\n4\n2\n2\n2\n2 4\n2 4\n3\n2\n0 1 2\n0 1\n0\n1 2 3 4\n1\n5 6 7 8\n"
           "-1 0 -2 0\n0.1 0.2\n")
    (tmp_path / "b.dat").write_text(sbm)
    b = read_siconos_fc2d(tmp_path / "b.dat")
    assert b.W.tolist() == [[1, 3, 0, 0], [2, 4, 0, 0], [0, 0, 5, 7], [0, 0, 6, 8]]


@pytest.mark.parametrize("storage", ["dense", "sparse", "sparse-block"])
def test_fc2d_round_trip_bit_for_bit(tmp_path, storage):
    rng = np.random.default_rng(5)
    W = rng.standard_normal((6, 6)) * 10.0 ** rng.integers(-8, 8, (6, 6))
    W[0:2, 4:6] = 0.0
    p = lcp.FrictionContact2D(W, rng.standard_normal(6), [0.1, 0.0, 2.5])
    back = lcp.load(write_siconos_fc2d(p, tmp_path / "p.dat", storage=storage))
    assert np.array_equal(back.dense_W(), W) and np.array_equal(back.q, p.q)
    assert np.array_equal(back.mu, p.mu) and back.meta["storage"] == storage


@pytest.mark.parametrize("storage", ["dense", "sparse"])
def test_mlcp_round_trip_and_no_overwrite(tmp_path, storage):
    rng = np.random.default_rng(2)
    p = lcp.MLCP(rng.standard_normal((2, 2)), rng.standard_normal((2, 3)),
                 rng.standard_normal((3, 2)), rng.standard_normal((3, 3)),
                 rng.standard_normal(2), rng.standard_normal(3))
    path = write_siconos_mlcp(p, tmp_path / "m.dat", storage=storage)
    back = read_siconos_mlcp(path)
    for k in "ACDBab":
        assert np.array_equal(getattr(back, k), getattr(p, k)), k
    with pytest.raises(FileExistsError):
        write_siconos_mlcp(p, path)
    with pytest.raises(FileExistsError):
        write_siconos_lcp(lcp.LCP(np.eye(2), np.ones(2)), path)


@pytest.mark.parametrize("reader, name, kind, match", [
    (read_siconos_lcp, "deudeu_mlcp.dat", WrongKind, "line 1: this is a Siconos MLCP file"),
    (read_siconos_lcp, "FrictionContactProblem00031.dat", WrongKind, "2D friction-contact"),
    (read_siconos_mlcp, "lcp_CPS_1.dat", WrongKind, "LCP file, not a"),
    (read_siconos_fc2d, "m2n1_mlcp.dat", WrongKind, "MLCP file"),
    (read_siconos, "Rectangular_mlcp.dat", UnsupportedProblem, "line 7: a rectangular MLCP"),
    (read_siconos, "README.md", FileFormatError, "line 1: no Siconos header fits"),
])
def test_wrong_kind_is_refused_naming_file_and_line(reader, name, kind, match):
    with pytest.raises(kind, match=match) as info:
        reader(DATA / name)
    assert name in str(info.value)


@pytest.mark.parametrize("text, match", [
    ("2\n2\n0\n4\n4\n4\t4\n" + "1 " * 16 + "\n-1 0 -1\n", "line 8: the file ends after"),
    ("2\n2\n0\n4\n4\n4\t4\n" + "1 " * 15 + "oops\n", "line 7: 'oops' where the entries of W"),
    ("2\n1\n2\n2\n2\n2\nCSparse\n2-by-3, nzmax: 1 nnz: 1, 1-norm: 1\n", "line 8: the sparse"),
    ("2\n1\n2\n2\n2\n2\nCSparse\n2-by-2, nzmax: 1 nnz: 1, 1-norm: 1\n    col 1 :",
     "line 9: column 1 where column 0"),
    ("1\n1\n2\n1\n0 5\n", "line 5: blocksRows \\[0, 5\\] must increase to n \\+ m = 3"),
])
def test_malformed_files_name_the_line(tmp_path, text, match):
    (tmp_path / "bad.dat").write_text(text)
    with pytest.raises(FileFormatError, match=match):
        lcp.load(tmp_path / "bad.dat")


def _siconos_missing() -> str | None:
    """Why the cross-checks with Siconos's own reader cannot run (None: they can). They need
    siconos.numerics AND scipy in the system interpreter; name the one that is missing (a
    system Python with Siconos but without scipy is common)."""
    if not Path(SYSTEM_PYTHON).exists():
        return f"{SYSTEM_PYTHON} does not exist"
    missing = [m for m in ("siconos.numerics", "scipy.sparse")
               if subprocess.run([SYSTEM_PYTHON, "-c", f"import {m}"], capture_output=True,
                                 check=False).returncode != 0]
    return f"{SYSTEM_PYTHON} has no {' and no '.join(missing)}" if missing else None


_MISSING = _siconos_missing()


def _siconos_available() -> bool:
    return _MISSING is None


_SKIP_REASON = _MISSING or ""


KINDS = {"lcp_CPS_1.dat": "lcp", "lcp_deudeu_block.dat": "lcp", "deudeu_mlcp.dat": "mlcp",
         "m2n1_mlcp.dat": "mlcp", "diodeBridge_mlcp.dat": "mlcp",
         "FC2D_SliderCrankLagrangian00000.dat": "fc2d",
         "FrictionContactProblem00031.dat": "fc2d"}


@pytest.mark.skipif(not _siconos_available(), reason=_SKIP_REASON)
@pytest.mark.parametrize("name", sorted(KINDS))
def test_same_arrays_as_siconos_own_reader(tmp_path, name):
    kind = KINDS[name]
    out = tmp_path / "ref.npz"
    subprocess.run([SYSTEM_PYTHON, str(DUMP), kind, str(DATA / name), str(out)], check=True,
                   capture_output=True)
    ref = np.load(out)
    p = lcp.load(DATA / name)
    if kind == "lcp":
        assert np.array_equal(p.M, ref["M"]) and np.array_equal(p.q, ref["q"])
    elif kind == "mlcp":
        assert np.array_equal(np.block([[p.A, p.C], [p.D, p.B]]), ref["M"])
        assert np.array_equal(np.concatenate([p.a, p.b]), ref["q"])
    else:
        assert np.array_equal(p.dense_W(), ref["W"]) and np.array_equal(p.q, ref["q"])
        assert np.array_equal(p.mu, ref["mu"])


@pytest.mark.skipif(not _siconos_available(), reason=_SKIP_REASON)
@pytest.mark.parametrize("storage", ["dense", "sparse", "sparse-block"])
def test_siconos_reads_what_we_write(tmp_path, storage):
    rng = np.random.default_rng(11)
    W = rng.standard_normal((4, 4))
    W[0:2, 2:4] = 0.0
    p = lcp.FrictionContact2D(W, rng.standard_normal(4), [0.3, 0.7])
    path = write_siconos_fc2d(p, tmp_path / "p.dat", storage=storage)
    out = tmp_path / "ref.npz"
    subprocess.run([SYSTEM_PYTHON, str(DUMP), "fc2d", str(path), str(out)], check=True,
                   capture_output=True)
    ref = np.load(out)
    assert np.array_equal(ref["W"], W) and np.array_equal(ref["q"], p.q)
    assert np.array_equal(ref["mu"], p.mu)
