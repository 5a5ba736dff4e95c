"""`rigidlcp forceset ... --samples N --out DIR`: the force-network ensemble on the command
line (samples.npz, pf.png, a summary in forceset.json); refusals leave nothing behind."""

from __future__ import annotations

import json

import numpy as np

from rigidlcp.cli.main import main
from rigidlcp.models.deposition import deposit
from rigidlcp.models.packing_io import write_packing

MU = ["--mu-pp", "0.5", "--mu-plane", "0.5", "--mu-wall", "0.5", "--no-progress"]


def test_samples_written_and_checked(tmp_path, capsys):
    pile = tmp_path / "pile.csv"
    write_packing(pile, deposit(8, seed=4, radii=(0.8, 1.2), width=6.0))
    out = tmp_path / "o"
    assert main(["forceset", str(pile), *MU, "--samples", "50", "--out", str(out)]) == 0
    assert "uniform samples" in capsys.readouterr().out
    data = np.load(out / "samples.npz")
    assert data["R"].shape == (50, data["i"].size) and data["S"].shape == data["R"].shape
    summary = json.loads((out / "forceset.json").read_text())["ensemble"]
    assert summary["samples"] == 50 and max(summary["residuals"]) < 1e-8
    assert (out / "pf.png").stat().st_size > 0


def test_samples_need_out_and_a_bounded_set(tmp_path, capsys):
    pile = tmp_path / "pile.csv"
    write_packing(pile, deposit(8, seed=4, radii=(0.8, 1.2), width=6.0))
    assert main(["forceset", str(pile), *MU, "--samples", "5"]) == 2
    assert "give --out" in capsys.readouterr().err
    # a disk pinched between two walls: unbounded forces, refused without --cap
    one = tmp_path / "one.csv"
    one.write_text("# box: left=0 right=2\nx,y,r\n1,1,1\n")
    out = tmp_path / "o"
    assert main(["forceset", str(one), *MU, "--samples", "5", "--out", str(out)]) == 2
    assert "--cap" in capsys.readouterr().err
    assert not any(out.iterdir()) if out.exists() else True
    assert main(["forceset", str(one), *MU, "--samples", "5", "--cap", "10", "--out",
                 str(out)]) == 0
