"""`rigidlcp ranges --clock cpu|wall` (issue 21 point 3): the clock reaches
verify.ranges.steady_ranges (default "cpu", docs/usage.md says why), the answer of a decided
end is the same with either clock, a wrong clock is one line and exit 2."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.cli import main
from rigidlcp.models.runio import save_run
from rigidlcp.verify import ranges as ranges_pkg


@pytest.fixture(scope="module")
def path(tmp_path_factory):
    system = models.System(models.rectangular(3, 1), mu_pp=0.05, mu_plane=0.1, mu_wall=0.0,
                           gamma=0.01)
    run = models.simulate(system, seed=1)
    assert run.status == "steady"
    return save_run(run, tmp_path_factory.mktemp("runs") / "steady")


@pytest.mark.parametrize("argv, want", [([], "cpu"), (["--clock", "cpu"], "cpu"),
                                        (["--clock", "wall"], "wall")])
def test_clock_reaches_steady_ranges(path, argv, want, monkeypatch, capsys):
    seen: list[str] = []
    real = ranges_pkg.steady_ranges

    def recording(*a, **k):
        seen.append(k.get("clock", "wall"))
        return real(*a, **k)

    monkeypatch.setattr(ranges_pkg, "steady_ranges", recording)
    assert main(["ranges", str(path), "--observables", "mu_g", "--json"] + argv) == 0
    assert seen == [want]
    json.loads(capsys.readouterr().out)


def test_same_ends_with_either_clock(path, capsys):
    out = {}
    for name in ("cpu", "wall"):
        assert main(["ranges", str(path), "--json", "--clock", name]) == 0
        out[name] = json.loads(capsys.readouterr().out)["steady"]
    assert out["cpu"]["status"] == out["wall"]["status"]
    st = out["cpu"]["status"]
    assert set(st["mu_g"]) == {"optimal"} and all(set(p) == {"optimal"} for p in st["alpha"])
    a = np.array([out["cpu"]["mu_g"], *out["cpu"]["alpha"]], float)
    b = np.array([out["wall"]["mu_g"], *out["wall"]["alpha"]], float)
    assert np.allclose(a, b, rtol=0.0, atol=1e-12)


def test_wrong_clock_one_line_exit_2(path, capsys):
    with pytest.raises(SystemExit) as stop:  # argparse's refusal (one line: rigidlcp.cli)
        main(["ranges", str(path), "--clock", "gpu"])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "--clock" in err and "\n" not in err
