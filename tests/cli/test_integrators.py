"""`rigidlcp timestep` and `rigidlcp compare-integrators`: bad input, the table, the run file."""

from rigidlcp.cli.main import main


def test_cli_bad_input(capsys):
    assert main(["compare-integrators", "--lx", "2", "--ly", "1", "--h", "0"]) == 2
    assert "h must be" in capsys.readouterr().err
    assert main(["compare-integrators", "--lx", "2", "--ly", "1", "--levels", "2"]) == 2
    assert main(["timestep", "--lx", "1", "--ly", "1", "--theta", "2"]) == 2


def test_cli_compare_prints_the_table(capsys):
    code = main(["compare-integrators", "--lx", "3", "--ly", "1", "--gamma", "0.05",
                 "--h", "8e-3", "--t-max", "1.0"])
    captured = capsys.readouterr()
    out = captured.out
    assert code == 0
    assert "observed order of sup|domega|" in out and out.count(" time_lim ") == 3
    # a line on stderr per step size (the run was silent for its whole length)
    lines = captured.err.splitlines()
    assert [line.split(" (")[0] for line in lines] == [
        "compare-integrators: h = 0.008 done", "compare-integrators: h = 0.004 done",
        "compare-integrators: h = 0.002 done"]
    assert lines[0].split(" (")[1].startswith("1 of 3, ")


def test_cli_timestep_saves_a_run_and_refuses_to_overwrite(tmp_path, capsys):
    out = tmp_path / "disk"
    args = ["timestep", "--lx", "1", "--ly", "1", "--mu-plane", "0.3", "--gamma", "0.16",
            "--h", "1e-3", "--out", str(out)]
    assert main(args) == 0
    assert "steady" in capsys.readouterr().out
    assert main(["plot", str(out) + ".npz", "--out", str(tmp_path / "png")]) == 0
    assert main(args) == 2
    assert "exists" in capsys.readouterr().err


def test_cli_compare_no_progress_is_silent_on_stderr(capsys):
    assert main(["compare-integrators", "--lx", "2", "--ly", "1", "--gamma", "0.05",
                 "--h", "8e-3", "--t-max", "0.5", "--no-progress"]) == 0
    assert capsys.readouterr().err == ""


def test_cli_timestep_shows_progress_on_stderr_unless_told_not_to(capsys):
    """timestep ran silent (a 4 x 2 run: 26 s under load); a bar of steps and t on stderr,
    erased at the end as simulate's is; --no-progress silences it; stdout is the summary."""
    args = ["timestep", "--lx", "1", "--ly", "1", "--mu-plane", "0.3", "--gamma", "0.16",
            "--h", "1e-3"]
    assert main(args) == 0
    captured = capsys.readouterr()
    assert "steps" in captured.err and "steps" not in captured.out
    assert "steady" in captured.out
    assert main(args + ["--no-progress"]) == 0
    assert capsys.readouterr().err == ""
