"""--gap-tol accepts rounding-sized overlaps as contacts, never interpenetration (at most
models.packing.MAX_GAP_TOL of the radius): a new user's --gap-tol 0.6 made two disks that
overlap by half a radius an 'equilibrium'."""

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.cli.main import main
from rigidlcp.models.lattice import InvalidSystem
from rigidlcp.models.packing import MAX_GAP_TOL


def _csv(tmp_path, rows: str):
    f = tmp_path / "p.csv"
    f.write_text("x,y,r\n" + rows)
    return str(f)


@pytest.mark.parametrize("rows, hint", [
    ("1,1,1\n2.5,1,1\n", "0.5 of the radius: the disks interpenetrate"),
    ("1,0.5,1\n", "0.5 of the radius: the disks interpenetrate"),  # sunk into the plane
    ("1,1,1\n2.99999,1,1\n", "--gap-tol G accepts overlaps up to G x radius (G <= 0.05)"),
])
def test_overlap_hint(tmp_path, capsys, rows, hint):
    assert main(["forceset", _csv(tmp_path, rows), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert hint in err and err.count("\n") == 1


def test_gap_tol_beyond_the_cap_is_refused(tmp_path, capsys):
    f = _csv(tmp_path, "1,1,1\n2.5,1,1\n")
    assert main(["forceset", f, "--gap-tol", "0.6", "--no-progress"]) == 2
    assert "gap_tol must be in [0, 0.05]" in capsys.readouterr().err


def test_library_cap():
    x = np.array([[1.0, 1.0], [3.0 - 0.5 * MAX_GAP_TOL, 1.0]])  # overlap: half the cap
    lat = models.make_packing(x, np.ones(2), gap_tol=MAX_GAP_TOL)
    assert lat.c == 3  # two plane contacts and the pair
    with pytest.raises(InvalidSystem, match="interpenetration"):
        models.make_packing(x, np.ones(2), gap_tol=2 * MAX_GAP_TOL)
