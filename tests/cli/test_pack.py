"""`rigidlcp pack` end to end: the fixed interface, the file it writes, refusals."""

import json
from contextlib import nullcontext

import numpy as np
import pytest

from rigidlcp.cli.main import main
from rigidlcp.models.packing_io import read_disks, read_packing


def test_pack_writes_a_packing(tmp_path, capsys):
    out = tmp_path / "p.csv"
    code = main(["pack", "--n", "40", "--seed", "3", "--radii", "0.8:1.2", "--out", str(out),
                 "--json"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["p"] == 40 and summary["rattlers"] == []
    header = [line for line in out.read_text().splitlines() if not line.startswith("#")][0]
    assert header.split(",")[:3] == ["x", "y", "r"]
    d = read_disks(out)
    assert np.allclose(d.m, d.r**2) and np.allclose(d.I, d.m * d.r**2 / 2)
    assert read_packing(out).c == summary["c"]
    assert main(["pack", "--n", "40", "--seed", "3", "--radii", "0.8:1.2", "--out",
                 str(tmp_path / "q.csv"), "--json"]) == 0
    capsys.readouterr()
    assert (tmp_path / "q.csv").read_text() == out.read_text()  # seeded


@pytest.mark.parametrize("args, message", [
    (["--n", "0"], "--n must be >= 1"),
    (["--n", "5", "--radii", "1:x"], "expected MIN:MAX"),
    (["--n", "5", "--width", "1"], "width must be >= the largest diameter"),
    (["--n", "5", "--vacancies", "1.5"], "--vacancies must be in"),
    (["--n", "5", "--radii", "1:1e300"], "radii must lie in"),  # r^4 / 2 overflows
    (["--n", "5", "--radii", "1e-100:1e-100"], "radii must lie in"),  # r^4 / 2 is 0
])
def test_pack_refusals_leave_nothing(tmp_path, capsys, args, message):
    out = tmp_path / "p.csv"
    with pytest.raises(SystemExit) if "MIN:MAX" in message else nullcontext():
        code = main(["pack", *args, "--out", str(out)])
        assert code == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not out.exists()


def test_pack_never_overwrites(tmp_path, capsys):
    out = tmp_path / "p.csv"
    out.write_text("mine")
    assert main(["pack", "--n", "3", "--out", str(out)]) == 2
    assert "exists" in capsys.readouterr().err and out.read_text() == "mine"



@pytest.mark.parametrize("value", ["-1:1", "-1e-3", "-.5:2"])
def test_pack_negative_radii_reach_the_radii_check(tmp_path, capsys, value):
    """`--radii -1:1` (no '='): argparse took a word starting with '-' for an option ("expected
    one argument"); it now reaches --radii's own check: one line, exit status 2."""
    out = tmp_path / "p.csv"
    with pytest.raises(SystemExit) as stop:
        main(["pack", "--n", "5", "--radii", value, "--out", str(out)])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and err.count("\n") == 1
    assert f"argument --radii: expected MIN:MAX with 0 < MIN <= MAX, got {value!r}" in err
    assert not out.exists()
