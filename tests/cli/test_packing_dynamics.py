"""The paper's dynamics on a deposited packing (issue 22.4): a pile that runs to a steady state,
its figures, `nullspace --packing`, `ranges` on its run, and the detachment check of
`simulate`."""

import json

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.cli.main import main
from rigidlcp.models.deposition import deposit
from rigidlcp.models.packing_io import write_packing
from rigidlcp.models.plot import PACKING_PLOT_FILES, draw_states, plot_files
from rigidlcp.models.runio import save_run


@pytest.fixture(scope="module")
def pile_run(tmp_path_factory):
    """A 12-disk pile (radii 0.8:1.2) with mu = 0.1, driven at gamma = 0.1: steady (16 events,
    tests/verify/statics/test_regime.py checks the regime at its end)."""
    d = tmp_path_factory.mktemp("pile")
    pile = deposit(12, seed=5, radii=(0.8, 1.2), width=6.0)
    system = models.System(pile, mu_pp=0.1, mu_plane=0.1, mu_wall=0.1, gamma=0.1)
    run = models.simulate(system, seed=1)
    assert run.status == "steady"
    return run, save_run(run, d / "run"), write_packing(d / "pile.csv", pile)


def test_plot_of_a_packing_run_draws_its_contacts(pile_run, tmp_path, capsys):
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt

    run, path, _ = pile_run
    assert plot_files(run.system) == PACKING_PLOT_FILES
    assert main(["plot", str(path), "--out", str(tmp_path / "figs")]) == 0
    written = sorted(p.name for p in (tmp_path / "figs").iterdir())
    assert written == sorted(PACKING_PLOT_FILES) and "contact_states.png" in written
    img = mpimg.imread(tmp_path / "figs" / "contact_states.png")[..., :3]
    dark = np.mean(img.sum(axis=-1) < 1.5)  # disks' outlines, walls, contact segments
    green = np.mean((img[..., 1] > 0.5) & (img[..., 0] < 0.3))  # non-sliding contacts
    assert dark > 0.01 and green > 0.001
    fig, ax = plt.subplots()
    last = run.last
    assert draw_states(ax, run.system, last.R, last.s) == run.system.c  # one per contact
    plt.close(fig)


def test_nullspace_takes_a_packing_file_or_run(pile_run, capsys):
    run, path, csv = pile_run
    for target in (csv, path):
        assert main(["nullspace", "--packing", str(target), "--states", "normal",
                     "--no-localize", "--json"]) == 0
        out = json.loads(capsys.readouterr().out)
        assert out["dim"] == 0  # every contact T and sliding on this pile: M has full rank
    assert main(["nullspace", "--packing", str(csv), "--no-localize"]) == 0
    text = capsys.readouterr().out
    assert text.startswith("packing: 12 disks, 24 contacts")


def test_nullspace_packing_bad_file_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("x,y,r\n1,1,oops\n")
    assert main(["nullspace", "--packing", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "bad.csv" in err


def test_ranges_of_an_unequal_radii_pile(pile_run, capsys):
    """radii 0.8:1.2 (u_i = r_i omega_i keeps the unit forms): both ends of mu_g decided, the
    run's own mu_g inside, each witness a valid steady state (verify.ranges.steady_check)."""
    from rigidlcp.verify.ranges.witness import steady_check

    run, path, _ = pile_run
    assert main(["ranges", str(path), "--observables", "mu_g", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)["steady"]
    assert out["status"]["mu_g"] == ["optimal", "optimal"]
    lo, hi = out["mu_g"]
    assert lo - 1e-9 <= out["run"]["mu_g"] <= hi + 1e-9 and lo < hi
    for w in out["witnesses"].values():
        res, _ = steady_check(run.system, np.array(w["omega"]), w["V"], np.array(w["R"]),
                              np.array(w["S"]))
        assert res <= 1e-9


def test_simulate_says_the_detachment_is_forced(tmp_path, capsys):
    pile = write_packing(tmp_path / "pile.csv", deposit(20, seed=1, radii=(0.8, 1.2),
                                                         width=8.0))
    assert main(["simulate", "--packing", str(pile), "--no-progress", "--json"]) == 1
    summary = json.loads(capsys.readouterr().out)
    assert summary["status"] == "detachment"
    assert summary["detachment_check"].startswith("proved: ")
    assert summary["closed_search"] == {"search": True, "searched": 1, "followed": [],
                                        "at_stop": "proved"}
    assert main(["simulate", "--packing", str(pile), "--no-progress", "--json",
                 "--no-closed-search"]) == 1
    off = json.loads(capsys.readouterr().out)
    assert off["closed_search"] == {"search": False, "searched": 0, "followed": [],
                                    "at_stop": None}
    assert off["message"] in summary["message"] and "proved: no solution" not in off["message"]


def test_simulate_follows_a_closed_solution(tmp_path, capsys):
    """The 12-disk pile at rest with mu = 0.5 (tests/models/engine/test_closed.py): steady,
    the summary naming the event where a closed solution was followed."""
    pile = write_packing(tmp_path / "pile.csv", deposit(12, seed=2, radii=(0.8, 1.2),
                                                         width=6.0))
    args = ["simulate", "--packing", str(pile), "--no-progress", "--omega-scale", "0",
            "--mu-pp", "0.5", "--mu-plane", "0.5", "--mu-wall", "0.5"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "steady" in out and "a closed solution followed at event(s) 0" in out


def test_ranges_of_an_equal_radii_packing_run_are_the_arrays(tmp_path, capsys):
    """A rectangular array written as a packing file: `ranges` on its run gives the array's."""
    csv = write_packing(tmp_path / "rect.csv", models.rectangular(3, 1))
    out = {}
    for name, system_args in (("lattice", ["--lattice", "rect", "--lx", "3", "--ly", "1"]),
                              ("packing", ["--packing", str(csv)])):
        run = tmp_path / f"{name}.npz"
        assert main(["simulate", *system_args, "--mu-pp", "0.05", "--mu-plane", "0.1",
                     "--gamma", "0.01", "--out", str(run), "--no-progress"]) == 0
        capsys.readouterr()
        assert main(["ranges", str(run), "--observables", "mu_g", "--json"]) == 0
        out[name] = json.loads(capsys.readouterr().out)
    lat, pack = out["lattice"]["steady"], out["packing"]["steady"]
    assert lat["status"]["mu_g"] == pack["status"]["mu_g"] == ["optimal", "optimal"]
    assert np.allclose(lat["mu_g"], pack["mu_g"], rtol=1e-9, atol=1e-12)
    assert lat["mu_g"] == pack["mu_g"]  # bit for bit: per-disk radii all equal r
    assert np.allclose(lat["own_states"]["mu_g"], pack["own_states"]["mu_g"], rtol=1e-9)


@pytest.mark.parametrize("command", ["simulate", "timestep", "compare-integrators"])
def test_dense_memory_check_counts_the_packings_contacts(pile_run, tmp_path, monkeypatch,
                                                          capsys, command):
    """A packing's dense matrices are sized by its own contacts (24 here), not by --lx --ly's
    defaults: with memory for 23 contacts only, refused in one line before any output."""
    import importlib

    engine = importlib.import_module("rigidlcp.models.engine.simulate")  # the module

    _, _, csv = pile_run
    monkeypatch.setattr(engine, "available_bytes", lambda: engine.dense_bytes(23))
    out = tmp_path / "never.npz"
    args = [command, "--packing", str(csv)]
    args += ["--out", str(out)] if command != "compare-integrators" else []
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "(24 contacts)" in err and not out.exists()


def test_timestep_and_the_sparse_backend_say_the_detachment_is_forced(tmp_path, capsys):
    """The same spun pile on the time-stepper and on the sparse backend: each proves that no
    solution of its first step / event keeps every contact closed (models/step_closed.py,
    models/engine/sparse_closed.py), and says so as simulate does; --no-closed-search is the
    old stop."""
    pile = write_packing(tmp_path / "pile.csv", deposit(20, seed=1, radii=(0.8, 1.2),
                                                         width=8.0))
    for cmd in (["timestep", "--h", "0.01"],
                ["simulate", "--method", "sparse-pivoting", "--select", "none"]):
        assert main([*cmd, "--packing", str(pile), "--no-progress", "--json"]) == 1
        summary = json.loads(capsys.readouterr().out)
        assert summary["status"] == "detachment"
        assert summary["closed_search"] == {"search": True, "searched": 1, "followed": [],
                                            "at_stop": "proved"}
        assert main([*cmd, "--packing", str(pile), "--no-progress", "--json",
                     "--no-closed-search"]) == 1
        off = json.loads(capsys.readouterr().out)
        assert off["closed_search"]["search"] is False and off["closed_search"]["at_stop"] is None
    assert main(["timestep", "--h", "0.01", "--packing", str(pile), "--no-progress"]) == 1
    assert "on: ran at 1 step(s); a closed solution followed at no step" in (
        capsys.readouterr().out)
