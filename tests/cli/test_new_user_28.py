"""What a new user tripped on (session 28): Ctrl-C in a long command printed a traceback (bench,
fuzz, forceset, ranges, simulate), and an interrupted bench's folder was refused without naming
--resume."""

from __future__ import annotations

import pytest

from rigidlcp.cli import main


def _one_line_error(capsys, command: str) -> str:
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"rigidlcp {command}: error: ") and "\n" not in err
    return err


@pytest.mark.parametrize("command", ["fuzz", "ranges", "forceset", "simulate"])
def test_ctrl_c_is_one_line_and_exit_130(command, monkeypatch, capsys):
    """Ctrl-C is a user's choice, not a defect: one line naming the command, exit status 130
    (128 + SIGINT), no traceback."""
    import importlib

    from rigidlcp.cli.main import COMMAND_MODULES

    def interrupted(args):
        raise KeyboardInterrupt

    name = command.replace("-", "_")
    module = next(m for m in COMMAND_MODULES if m.endswith("." + name))
    monkeypatch.setattr(importlib.import_module(module), "cmd_" + name, interrupted)
    argv = {"fuzz": ["fuzz"], "ranges": ["ranges", "run.npz"],
            "forceset": ["forceset", "pile.csv"], "simulate": ["simulate"]}[command]
    assert main(argv) == 130
    err = capsys.readouterr().err.strip()
    assert err == f"rigidlcp {command}: interrupted"


def test_an_interrupted_bench_says_how_to_resume(tmp_path, monkeypatch, capsys):
    """Ctrl-C in `rigidlcp bench` after some solves: the rows written so far stay, and the
    line says to rerun with --resume; the same folder without --resume is refused naming
    --resume (it said only --force, which starts over)."""
    import rigidlcp.bench.harness as harness

    real = harness.run_bench

    def stop_after_first(sets, methods, **kw):
        progress = kw["progress"]

        def once(r):
            progress(r)
            raise KeyboardInterrupt

        return real(sets, methods, **{**kw, "progress": once})

    monkeypatch.setattr(harness, "run_bench", stop_after_first)
    out = tmp_path / "b"
    base = ["bench", "--set", "random-p", "--sizes", "4", "--per-size", "1", "--methods",
            "lemke,pivoting", "--out", str(out), "--no-progress", "--no-siconos"]
    assert main(base) == 130
    err = capsys.readouterr().err
    assert "interrupted" in err and "--resume" in err and "Traceback" not in err
    assert len((out / "results.csv").read_text().splitlines()) == 2  # header + one row
    monkeypatch.setattr(harness, "run_bench", real)
    assert main(base) == 2
    assert "--resume finishes it" in _one_line_error(capsys, "bench")
    assert main([*base, "--resume"]) == 0
    assert len((out / "results.csv").read_text().splitlines()) == 3
