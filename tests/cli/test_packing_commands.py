"""Commands that take a system also take a packing file (--packing, issue 22.4): a run of a
deposited pile, saved with its geometry and reloaded; detachment reported as for the arrays."""

import numpy as np

from rigidlcp.cli.main import main
from rigidlcp.models.deposition import deposit
from rigidlcp.models.packing_io import read_packing, write_packing
from rigidlcp.models.runio import load_run


def test_simulate_and_timestep_take_a_packing(tmp_path, capsys):
    pile = write_packing(tmp_path / "pile.csv", deposit(8, seed=4, radii=(0.8, 1.2), width=5.0))
    out = tmp_path / "run.npz"
    code = main(["simulate", "--packing", str(pile), "--gamma", "0.1", "--max-events", "20",
                 "--out", str(out), "--no-progress"])
    text = capsys.readouterr().out
    assert code in (0, 1) and "8 disks" in text  # 1: the run left the paper's regime
    run = load_run(out)
    lat = read_packing(pile)
    assert np.array_equal(run.system.lattice.x, lat.x)
    assert np.array_equal(run.system.lattice.radii, lat.radii)
    assert np.array_equal(run.system.masses, lat.masses)
    code = main(["timestep", "--packing", str(pile), "--out", str(tmp_path / "ts.npz")])
    assert code in (0, 1) and "saved" in capsys.readouterr().out


def test_packing_with_inertia_option_refused(tmp_path, capsys):
    pile = write_packing(tmp_path / "pile.csv", deposit(3, seed=1, width=4.0))
    code = main(["simulate", "--packing", str(pile), "--inertia", "0.3", "--out",
                 str(tmp_path / "r.npz"), "--no-progress"])
    assert code == 2 and "inertia: the packing gives" in capsys.readouterr().err
    assert not (tmp_path / "r.npz").exists()
