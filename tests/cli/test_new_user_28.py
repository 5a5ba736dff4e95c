"""What a new user tripped on (session 28), outside packings: Ctrl-C in a long command printed
a traceback (bench, fuzz, forceset, ranges, simulate) and an interrupted bench's folder was
refused without naming --resume; ranges ran minutes without progress; a run's .json, a
relative set folder, a method of one's own in bench / fuzz, and a time-stepping run given to
certify-run were met with unhelpful messages or a traceback. Packings:
test_new_user_28_packings.py."""

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


def test_ranges_counts_its_ends(tmp_path, capsys):
    """`rigidlcp ranges` ran its MILPs (up to 14 min on a 10 x 4 run) with no progress at all
    after the first line: steady_ranges now reports each end, and the command draws a bar
    (`--no-progress`: none); the result is the same either way."""
    import json

    from rigidlcp import models
    from rigidlcp.models.runio import save_run
    from rigidlcp.verify.ranges import steady_ranges

    system = models.System(models.rectangular(2, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.1)
    run = models.simulate(system, seed=1, progress=False)
    assert run.status == "steady"
    calls: list = []
    steady_ranges(run, which="alpha", time_limit=30,
                  progress=lambda done, total, name: calls.append((done, total, name)))
    # mu_g and alpha of each of the 2 disks, two ends each, in order
    assert [c[:2] for c in calls] == [(k, 6) for k in range(1, 7)]
    assert [c[2] for c in calls[::2]] == ["mu_g", "alpha[0]", "alpha[1]"]
    path = save_run(run, tmp_path / "two")
    assert main(["ranges", str(path), "--json", "--time-limit", "30"]) == 0
    cap = capsys.readouterr()
    assert "range ends" in cap.err
    with_bar = json.loads(cap.out)["steady"]
    assert main(["ranges", str(path), "--json", "--time-limit", "30", "--no-progress"]) == 0
    cap = capsys.readouterr()
    assert "range ends" not in cap.err
    assert json.loads(cap.out)["steady"]["mu_g"] == with_bar["mu_g"]


def test_a_runs_json_names_its_npz(tmp_path, capsys):
    """`simulate --out run5` writes run5.npz and run5.json; `ranges run5.json` (the file a
    user opens to read) said only "not a run file"."""
    from rigidlcp import models
    from rigidlcp.models.runio import save_run

    system = models.System(models.rectangular(1, 1), gamma=0.1)
    save_run(models.simulate(system, seed=1, progress=False), tmp_path / "run5")
    for command in (["ranges"], ["plot", "--out", str(tmp_path / "figs")], ["certify-run"]):
        assert main([command[0], str(tmp_path / "run5.json"), *command[1:]]) == 2
        err = _one_line_error(capsys, command[0])
        assert err.endswith(f"is the metadata of a run: give its data file, "
                            f"{tmp_path / 'run5.npz'}")


def test_a_relative_set_folder_names_the_current_folder(tmp_path, monkeypatch):
    """docs/bench.md's script passes "tests/data/siconos", the repository's folder: run from
    elsewhere it was "not a name ... nor a directory", with no word on where it was looked
    for."""
    from rigidlcp.bench.problem_sets import get_set

    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError, match="read from the current folder") as exc:
        get_set("tests/data/siconos")
    assert str(tmp_path) in str(exc.value)


def test_bench_says_how_to_compare_a_method_of_ones_own(tmp_path, capsys):
    """`rigidlcp bench --methods mine` (a method registered in the user's own module) listed
    the built-in methods and nothing on how to bench one's own: the command line cannot
    import it; the message points to the script of docs/bench.md."""
    from pathlib import Path

    assert main(["bench", "--set", "random-p", "--methods", "mine", "--out",
                 str(tmp_path / "b"), "--no-siconos"]) == 2
    err = _one_line_error(capsys, "bench")
    assert "a method of your own: register it in a script that calls run_bench" in err
    doc = (Path(__file__).parents[2] / "docs" / "bench.md").read_text()
    assert "## A test double" in doc and "from rigidlcp.bench.harness import run_bench" in doc
    assert not (tmp_path / "b").exists()


def test_certify_run_of_a_time_stepping_run_is_refused_in_one_line(tmp_path, capsys):
    """`rigidlcp certify-run` on a run of `rigidlcp timestep` ended in a traceback (KeyError
    'states'): its step impulses are no event solution, every certificate was rejected, and a
    rejected certificate had no "states" question. Refused by name now, nothing written."""
    out = tmp_path / "ts_cert"
    assert main(["timestep", "--lx", "2", "--ly", "1", "--t-max", "0.05", "--out",
                 str(tmp_path / "ts"), "--no-progress"]) in (0, 1)
    capsys.readouterr()
    assert main(["certify-run", str(tmp_path / "ts.npz"), "--out", str(out),
                 "--no-progress"]) == 2
    assert "a time-stepping run (moreau-jean" in _one_line_error(capsys, "certify-run")
    assert not out.exists()


def test_a_rejected_staged_certificate_asks_every_question():
    """A solution that fails the residual check gets "no verdict" on each question, the
    contact states' included (certify_event read verdicts["states"] and crashed)."""
    import numpy as np

    from rigidlcp import models
    from rigidlcp.verify.certificates import certify_stages
    from rigidlcp.verify.certificates.run import QUESTIONS

    system = models.System(models.rectangular(2, 1), gamma=0.1)
    ep = models.event_problem(system, models.initial_state(system, seed=1))
    cert = certify_stages(ep, np.full(ep.lcp.n, 7.0))
    assert not cert.accepted
    for name in QUESTIONS:
        v = cert.verdicts[name]
        assert v.verdict == "unknown" and v.stage == "residual"


def test_fuzz_says_how_to_fuzz_a_method_of_ones_own(capsys):
    """`rigidlcp fuzz --methods mine` listed the built-in methods only."""
    assert main(["fuzz", "--count", "1", "--methods", "mine"]) == 2
    assert "a method of your own: register it in your script and call " \
        "rigidlcp.bench.fuzz.run_fuzz" in _one_line_error(capsys, "fuzz")


def test_run_fuzz_judges_a_method_registered_by_the_caller(monkeypatch):
    """What the hint says works: a registered method is fuzzed by run_fuzz."""
    from rigidlcp import lcp
    from rigidlcp.bench.fuzz import run_fuzz
    from rigidlcp.lcp import api, registry

    api._load_builtin_methods()
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))

    @lcp.register("mine-28", accepts="any", description="test: pivoting")
    def mine(M, q):
        z = lcp.solve(lcp.LCP(M, q), method="pivoting").z
        return lcp.Solution(z=z, w=M @ z + q, status="solved", method="mine-28")

    result = run_fuzz(4, seed=3, classes=("P",), methods=("mine-28",))
    assert {m for (_, m) in result["table"]} == {"mine-28"}
