"""`rigidlcp ranges RUN.npz [--json]` (issue 21): the JSON layout, the table, bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.cli import main
from rigidlcp.models.runio import save_run
from rigidlcp.verify.ranges.witness import steady_check


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("runs")
    system = models.System(models.rectangular(3, 1), mu_pp=0.05, mu_plane=0.1, mu_wall=0.0,
                           gamma=0.01)
    steady = models.simulate(system, seed=1)
    assert steady.status == "steady"
    short = models.simulate(system, seed=1, t_max=1e-3)
    assert short.status != "steady"
    return system, steady, save_run(steady, d / "steady"), save_run(short, d / "short")


def test_json_is_the_issues_layout(runs, capsys):
    system, run, path, _ = runs
    assert main(["ranges", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert list(out) == ["steady"]
    st = out["steady"]
    lo, hi = st["mu_g"]
    assert lo <= run.records[-1].mu_g <= hi
    assert len(st["alpha"]) == system.p
    for key, W in st["witnesses"].items():
        assert set(W) >= {"mu_g", "omega", "V", "alpha", "R", "S", "pairs"}
        assert len(W["omega"]) == len(W["alpha"]) == system.p
        assert len(W["R"]) == len(W["S"]) == len(W["pairs"]) == system.c
        assert W["mu_g"] == pytest.approx(lo if key == "min" else hi, abs=1e-12)
        pairs = np.array(W["pairs"])
        assert set(pairs[:, 1][pairs[:, 1] < 0]) == {-1, -2, -3}
        res, _ = steady_check(system, W["omega"], W["V"], np.array(W["R"]), np.array(W["S"]))
        assert res <= 1e-8


def test_table(runs, capsys):
    assert main(["ranges", str(runs[2]), "--observables", "mu_g"]) == 0
    out = capsys.readouterr().out
    assert "mu_g" in out and "own states" in out


def test_deep_runs_the_disk_split_on_an_open_end(runs, capsys):
    """--deep S: the minimum of mu_g, left open by a MILP stopped at once (time limit 1e-9 s:
    only the cap split's bound without --deep), is decided by disk_split's case split: the
    value of the MILP given its time."""
    _, _, path, _ = runs
    base = ["ranges", str(path), "--observables", "mu_g", "--json"]
    assert main(base) == 0
    full = json.loads(capsys.readouterr().out)["steady"]
    assert main(base + ["--time-limit", "1e-9"]) == 0
    open_ = json.loads(capsys.readouterr().out)["steady"]
    assert open_["status"]["mu_g"][0] == "time limit" and open_["mu_g"][0] is None
    assert open_["bounds"]["mu_g"][0] < full["mu_g"][0]
    assert main(base + ["--time-limit", "1e-9", "--deep", "5"]) == 0
    deep = json.loads(capsys.readouterr().out)["steady"]
    assert deep["status"]["mu_g"][0] == "optimal"
    assert deep["mu_g"][0] == pytest.approx(full["mu_g"][0], abs=1e-9)
    assert deep["bounds"]["mu_g"][0] == deep["mu_g"][0]


@pytest.mark.parametrize("case", ["missing", "not_steady", "other_kind", "bad_limit",
                                  "deep_zero", "deep_nan"])
def test_bad_input_one_line_exit_2(runs, case, tmp_path, capsys):
    _, _, path, short = runs
    other = tmp_path / "x.npz"
    np.savez(other, M=np.eye(2))
    argv = {"missing": ["ranges", str(tmp_path / "none.npz")],
            "not_steady": ["ranges", str(short)],
            "other_kind": ["ranges", str(other)],
            "bad_limit": ["ranges", str(path), "--time-limit", "0"],
            "deep_zero": ["ranges", str(path), "--deep", "0"],
            "deep_nan": ["ranges", str(path), "--deep", "nan"]}[case]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("rigidlcp ranges: error:") and "\n" not in err


def test_a_run_not_steady_is_told_what_to_rerun(runs, capsys):
    """The refusal named a Python-only way out ("or pass its system"): the command line
    says which run it was, how it ended and what to rerun."""
    _, _, _, short = runs
    assert main(["ranges", str(short)]) == 2
    err = capsys.readouterr().err.strip()
    assert f"{short}: the run ended 'time_limit'" in err
    assert "--t-max or --max-events" in err and "pass its system" not in err


def test_table_prints_no_rounding_noise(runs, capsys):
    """Session 7's closing note: ends that are 0 printed as -4.4e-16, a point range's width as
    3.469e-18 (this 3 x 1 run's alpha[0]). The table prints no digit below what each end is
    known to (verify.ranges.result.value_text); the JSON keeps full precision."""
    import re

    assert main(["ranges", str(runs[2])]) == 0
    out = capsys.readouterr().out
    tiny = [v for v in re.findall(r"-?\d[\d.]*e-\d+", out) if abs(float(v)) < 1e-12]
    assert not tiny, out
    assert main(["ranges", str(runs[2]), "--json"]) == 0
    st = json.loads(capsys.readouterr().out)["steady"]
    assert st["mu_g"][0] == pytest.approx(st["witnesses"]["min"]["mu_g"], abs=1e-15)
