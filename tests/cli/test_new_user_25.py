"""What a new user tripped on (session 25): `--force (force=True)` on the command line, bench
without --no-progress, `ranges` silent for 14 minutes, a hand-written packing whose walls and
unbounded forces were not explained, and an overlap from rounded centres with no way out named."""

from __future__ import annotations

import argparse
import json

import pytest

from rigidlcp import models
from rigidlcp.cli import main
from rigidlcp.cli.main import build_parser
from rigidlcp.cli.ranges import LONG_RUN_S, _warn_long
from rigidlcp.models.runio import save_run

# Three unit disks: two on the plane touching each other, one on top of them (centre height
# 1 + sqrt(3), written to 16 digits); with the tight box, each bottom disk touches a wall.
THREE = "x,y,r\n1,1,1\n3,1,1\n2,2.7320508075688772,1\n"


def test_refusal_names_the_flag_not_the_python_keyword(tmp_path, capsys):
    out = tmp_path / "p.csv"
    assert main(["pack", "--n", "3", "--out", str(out), "--no-progress"]) == 0
    capsys.readouterr()
    assert main(["pack", "--n", "3", "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert "pass --force to overwrite" in err and "force=True" not in err and "\n" not in err


def test_bench_takes_no_progress_like_the_other_commands():
    args = build_parser().parse_args(["bench", "--no-progress", "--list"])
    assert args.quiet is True


def test_ranges_announces_a_long_run_before_the_work(capsys):
    fig9 = models.System(models.rectangular(10, 4))
    _warn_long(fig9, argparse.Namespace(observables="alpha", time_limit=10.0, clock="cpu"))
    err = capsys.readouterr().err
    # 2 ends of mu_g and of each of the 40 angular accelerations, 10 s each: 820 s
    assert "82 MILP ends" in err and "14 min" in err and "--observables mu_g" in err
    assert "10 CPU s" in err  # --clock cpu, the default
    _warn_long(fig9, argparse.Namespace(observables="mu_g", time_limit=10.0,
                                        clock="cpu"))  # 20 s: quiet
    assert capsys.readouterr().err == ""
    assert 2 * 10.0 < LONG_RUN_S


def test_ranges_note_goes_to_stderr_and_json_stays_clean(tmp_path, capsys):
    system = models.System(models.rectangular(1, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.1)
    run = models.simulate(system, seed=1, progress=False)
    assert run.status == "steady"
    path = save_run(run, tmp_path / "one")
    # mu_g and one alpha, 2 ends each, 30 s each at most: 120 s, announced
    assert main(["ranges", str(path), "--json", "--time-limit", "30"]) == 0
    cap = capsys.readouterr()
    assert "4 MILP ends" in cap.err
    lo, hi = json.loads(cap.out)["steady"]["mu_g"]
    assert lo == pytest.approx(0.05) and hi == pytest.approx(0.05)  # gamma / 2, rolling


def test_hand_written_packing_says_where_its_walls_are(tmp_path, capsys):
    f = tmp_path / "three.csv"
    f.write_text(THREE)
    assert main(["forceset", str(f), "--mu-pp", "0.5", "--mu-plane", "0.5", "--mu-wall",
                 "0.5", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "left wall x = 0 (tight box), right wall x = 4 (tight box), plane y = 0" in out
    # each bottom disk is pinched between a wall and its neighbour: R has no upper end there
    assert "unbounded: 3 of 7 R have no upper end" in out and "inf" not in out
    assert main(["forceset", str(f), "--left", "none", "--right", "none", "--mu-pp", "0.5",
                 "--mu-plane", "0.5", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "no left wall, no right wall" in out and "diameter in [" in out


def test_rounded_centres_name_the_gap_tolerance(tmp_path, capsys):
    f = tmp_path / "rounded.csv"
    f.write_text(THREE.replace("2.7320508075688772", "2.732"))  # overlap 4.4e-5
    assert main(["forceset", str(f), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("rigidlcp forceset: error: disks 0 and 2 overlap")
    assert "--gap-tol" in err and "\n" not in err
    assert main(["forceset", str(f), "--gap-tol", "1e-4", "--no-progress"]) == 0


def test_unknown_option_is_named_by_its_subcommand(capsys):
    """`rigidlcp nullspace --packing F` (an option nullspace lacked then) said `rigidlcp: error:
    ...` and pointed at the top-level --help, which does not list nullspace's options."""
    with pytest.raises(SystemExit) as exc:
        main(["nullspace", "--no-such-option", "three.csv"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err == ("rigidlcp nullspace: error: unrecognized arguments: --no-such-option "
                   "three.csv (see `rigidlcp nullspace --help`)")


def test_a_packing_run_is_not_titled_as_an_array(tmp_path, capsys):
    """`simulate --packing` printed 'packing 2x4: 3 disks' (a lattice's lx x ly, meaningless)."""
    f = tmp_path / "three.csv"
    f.write_text(THREE)
    assert main(["simulate", "--packing", str(f), "--out", str(tmp_path / "run.npz"),
                 "--no-progress"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith("packing: 3 disks, 7 contacts; left wall x = 0, right wall x = 4; "
                            "mu_pp = 0.1")  # the walls: session 28


@pytest.mark.parametrize("command", ["solve", "certify"])
def test_a_bad_problem_names_its_file(tmp_path, capsys, command):
    """A .npz with NaN in M said 'M contains NaN or Inf' without the file's name."""
    import numpy as np

    f = tmp_path / "nan.npz"
    np.savez(f, M=np.array([[1.0, np.nan], [0.0, 1.0]]), q=np.array([1.0, -1.0]))
    assert main([command, str(f)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"rigidlcp {command}: error: {f}: M contains NaN") and "\n" not in err


def test_every_option_of_every_command_has_a_help_text():
    """--help listed --lattice, --max-events, --t-max, --states, ... with no word about them."""
    sub = next(a for a in build_parser()._actions
               if a.__class__.__name__ == "_SubParsersAction")
    bare = [f"{name} {a.option_strings[0]}" for name, p in sub.choices.items()
            for a in p._actions if a.option_strings and a.dest != "help" and not a.help]
    assert not bare


def test_refused_sampling_leaves_no_folder_behind(tmp_path, capsys):
    """`forceset --samples N --out DIR` on an unbounded set (walls that pinch) was refused after
    DIR had been created: an empty folder was left behind. A folder that existed stays."""
    f = tmp_path / "three.csv"
    f.write_text(THREE)
    out = tmp_path / "new" / "deep"
    assert main(["forceset", str(f), "--samples", "5", "--out", str(out)]) == 2
    assert "--cap" in capsys.readouterr().err
    assert not (tmp_path / "new").exists()
    (tmp_path / "mine").mkdir()
    assert main(["forceset", str(f), "--samples", "5", "--out", str(tmp_path / "mine")]) == 2
    assert (tmp_path / "mine").is_dir()


@pytest.mark.parametrize("array", [["--lx", "5"], ["--lattice", "tri"], ["--ly", "2"]])
def test_packing_with_array_options_is_refused(tmp_path, capsys, array):
    """`simulate --packing F --lx 5` ran the packing and ignored --lx without a word."""
    f = tmp_path / "three.csv"
    f.write_text(THREE)
    out = tmp_path / "run.npz"
    assert main(["simulate", "--packing", str(f), *array, "--out", str(out),
                 "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--packing takes its disks from the file" in err and "\n" not in err
    assert list(tmp_path.iterdir()) == [f]


@pytest.mark.parametrize("command", ["forces", "timestep"])
def test_dense_commands_estimate_a_packings_memory_from_its_disks(tmp_path, capsys, command):
    """The up-front memory check of the dense-only commands counted the array defaults
    (10 x 4) for --packing; 10^5 disks on the plane need at least 64 (10^5)^2 bytes."""
    f = tmp_path / "row.csv"
    f.write_text("x,y,r\n" + "".join(f"{2 * k + 1},1,1\n" for k in range(100_000)))
    out = ["--out", str(tmp_path / ("f" if command == "forces" else "ts.npz"))]
    assert main([command, "--packing", str(f), *out]) == 2
    err = capsys.readouterr().err.strip()
    assert "packing of 100000 disks" in err and "GiB" in err and "\n" not in err
    assert list(tmp_path.iterdir()) == [f]


def test_no_progress_bar_when_there_is_nothing_to_range(tmp_path, capsys):
    """The bar 'force ranges: 0LP [00:00, ?LP/s]' was opened before the existence check and
    shown for a pile with no equilibrium (no LP to run); it now opens at the first range LP."""
    from rigidlcp.models.deposition import deposit
    from rigidlcp.models.packing_io import write_packing

    pile = deposit(100, seed=2, radii=(0.8, 1.2))
    assert pile.c >= 200  # large enough for the bar
    f = tmp_path / "pile.csv"
    write_packing(f, pile)
    assert main(["forceset", str(f)]) == 0  # default friction: a Farkas certificate
    cap = capsys.readouterr()
    assert "no equilibrium" in cap.out and cap.err == ""


@pytest.mark.parametrize("array", [["--lx", "5"], ["--ly", "4"]])
def test_nullspace_packing_with_array_options_is_refused(tmp_path, capsys, array):
    """nullspace's own array defaults (rect 4 x 3) differ from simulate's: a changed --lx/--ly
    beside --packing is refused there too, while --packing alone runs."""
    f = tmp_path / "three.csv"
    f.write_text(THREE)
    assert main(["nullspace", "--packing", str(f), *array]) == 2
    err = capsys.readouterr().err.strip()
    assert "--packing takes its disks from the file" in err and "\n" not in err
    assert main(["nullspace", "--packing", str(f)]) == 0
