"""`rigidlcp simulate` and `rigidlcp plot` end to end."""

import json

import pytest

from rigidlcp.cli.main import main
from rigidlcp.models.runio import load_run


def test_simulate_then_plot(tmp_path, capsys):
    out = tmp_path / "run.npz"
    code = main(["simulate", "--lattice", "rect", "--lx", "4", "--ly", "2", "--mu-pp", "0.1",
                 "--mu-plane", "0.2", "--mu-wall", "0", "--gamma", "0.16", "--seed", "1",
                 "--out", str(out), "--no-progress"])
    text = capsys.readouterr().out
    assert code == 0 and "steady" in text and "mu_g" in text
    # mu_g is named as one point of the set, with the rule and where its range is
    assert f"one valid steady state, selection face-min-norm; over all of them: rigidlcp " \
        f"ranges {out}" in text
    run = load_run(out)
    assert run.steady and run.n_events > 1
    code = main(["plot", str(out), "--out", str(tmp_path / "fig")])
    files = capsys.readouterr().out.split()
    assert code == 0 and len(files) == 7
    for name in ("angular_acceleration.png", "normal_forces.png", "mu_g.png", "dissipation.png"):
        assert (tmp_path / "fig" / name).stat().st_size > 1000


def test_simulate_json_and_dump(tmp_path, capsys):
    code = main(["simulate", "--lattice", "tri", "--lx", "3", "--ly", "2", "--gamma", "0.1",
                 "--max-events", "3", "--json", "--no-progress",
                 "--dump-problems", str(tmp_path / "dump")])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["events"] == 3 and summary["selection"] == "face-min-norm"
    assert len(list((tmp_path / "dump").glob("event_*.npz"))) == 3


@pytest.mark.parametrize("args, message", [
    (["--lx", "0"], "lx must be >= 1"),
    (["--lattice", "tri", "--lx", "1", "--ly", "3"], "needs lx >= 2"),
    (["--mu-pp", "-1"], "mu_pp must be a finite number >= 0"),
    (["--method", "magic"], "unknown method 'magic'"),
    (["--max-events", "0"], "--max-events must be >= 1"),
])
def test_simulate_bad_input(args, message, capsys):
    assert main(["simulate", "--no-progress", *args]) == 2
    assert message in capsys.readouterr().err


def test_plot_missing_file(tmp_path, capsys):
    assert main(["plot", str(tmp_path / "nope.npz"), "--out", str(tmp_path)]) == 2
    assert "no such file" in capsys.readouterr().err.lower()


def test_simulate_sparse_path_from_the_command_line(capsys):
    code = main(["simulate", "--lx", "4", "--ly", "2", "--gamma", "0.16", "--method",
                 "sparse-pivoting", "--select", "none", "--no-progress", "--json"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["status"] == "steady"
    assert main(["simulate", "--lx", "4", "--ly", "2", "--method", "sparse-pivoting",
                 "--no-progress"]) == 2
    assert "use select='none'" in capsys.readouterr().err


def test_one_default_friction_everywhere():
    """models.System, simulate, sweep and forces share models.system.DEFAULT_MU (issue 14.4)."""
    from rigidlcp import models
    from rigidlcp.cli.main import build_parser
    from rigidlcp.models.sweep import DEFAULTS
    from rigidlcp.models.system import DEFAULT_MU

    system = models.System(models.rectangular(2, 1))
    parser = build_parser()
    for name, value in DEFAULT_MU.items():
        assert getattr(system, name) == value and DEFAULTS[name] == value
        for argv in (["simulate"], ["forces", "--out", "x"]):
            assert getattr(parser.parse_args(argv), name) == value, (argv, name)
