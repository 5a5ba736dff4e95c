"""What a new user tripped on (issue 24), on the command line: each bad input is one line naming
the problem, exit status 2, and nothing is left behind (the pattern of test_bad_input.py, for
the few cases that must also run in the default, fast selection)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest


def _run(d: Path, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "MPLBACKEND": "Agg", "RIGIDLCP_CACHE": str(d / ".cache")}
    return subprocess.run([sys.executable, "-m", "rigidlcp.cli", *args], cwd=d,
                          capture_output=True, text=True, timeout=120, env=env)


def _refused(d: Path, word: str, *args: str) -> None:
    before = sorted(p.name for p in d.iterdir())
    proc = _run(d, *args)
    lines = [x for x in proc.stderr.splitlines() if x.strip()]
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and len(lines) == 1, proc.stderr
    assert word in lines[0], lines[0]
    assert sorted(p.name for p in d.iterdir()) == before, "a refused command left a file"


def test_dense_run_too_large_for_memory_names_the_sparse_backend(tmp_path):
    """24.1: 300 x 100 disks asked the dense backend for 53.8 GiB (a numpy traceback); the
    memory is now estimated first (c >= p contacts: 64 c^2 bytes), in about a second."""
    _refused(tmp_path, "--method sparse-pivoting", "simulate", "--lx", "1000", "--ly", "1000",
             "--out", "mid.npz", "--max-events", "1", "--no-progress")
    _refused(tmp_path, "GiB", "simulate", "--lx", "1000", "--ly", "1000", "--out",
             "sub/mid.npz", "--no-progress")


@pytest.mark.parametrize("command", ["timestep", "compare-integrators", "nullspace", "forces"])
def test_dense_only_commands_refuse_arrays_too_large_for_memory(tmp_path, command):
    """24.1 on the other dense commands (they ended in a numpy MemoryError traceback, and
    `forces` left its --out folder behind)."""
    extra = ["--out", "f"] if command == "forces" else []
    _refused(tmp_path, "dense only", command, "--lx", "1000", "--ly", "1000", *extra)


def test_memory_error_is_one_line(monkeypatch, capsys):
    """Past the up-front estimate (a lower bound), an allocation that fails is one line."""
    import importlib

    cli = importlib.import_module("rigidlcp.cli.main")

    def boom(args):
        raise MemoryError("Unable to allocate 99.0 GiB for an array")

    parser = cli.build_parser
    monkeypatch.setattr(cli, "build_parser", lambda: _with_func(parser(), boom))
    assert cli.main(["methods"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "out of memory" in err[0] and "99.0 GiB" in err[0]


def _with_func(parser, func):
    parser.set_defaults(func=func)
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    for p in sub.choices.values():
        p.set_defaults(func=func)
    return parser


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux's /proc")
def test_unwritable_out_names_the_users_path(tmp_path):
    """24.5: --out /proc/x.npz named a hidden temporary file (/proc/.x.npz.XXXX.tmp), and only
    after the whole run."""
    _refused(tmp_path, "/proc/x.npz", "simulate", "--lx", "3", "--ly", "2", "--no-progress",
             "--out", "/proc/x.npz")


def test_certify_refuses_a_negative_time_limit(tmp_path):
    """24.5: --time-limit -3 exited 0 with "time limit -3 s reached"."""
    from rigidlcp import lcp

    lcp.LCP(np.eye(2), -np.ones(2)).save(tmp_path / "problem.npz")
    for value in ("-3", "0", "nan"):
        _refused(tmp_path, "--time-limit", "certify", "problem.npz", "--time-limit", value)


def test_check_dense_memory():
    """The estimate is a lower bound of W (2c x 2c), G (2c x c), B and M (c x c): 64 c^2 bytes."""
    from rigidlcp.lcp.errors import InvalidInput
    from rigidlcp.models.engine.simulate import check_dense_memory, dense_bytes

    assert dense_bytes(1000) == 8 * 8 * 1000**2
    check_dense_memory(1000, "x", available=64 * 1000**2)  # fits exactly
    with pytest.raises(InvalidInput, match="sparse-pivoting"):
        check_dense_memory(1000, "x", available=64 * 1000**2 - 1)
