"""What a new user tripped on with their own packing (session 28): a hand-typed CSV that
forceset accepted with --gap-tol could not be simulated, headers and dumps refused without
saying what differed, forceset --out silent on its files and redrawing its bar per LP, a pile
above the plane, walls and system not stated, a run's geometry refused, doc output drifted."""

from __future__ import annotations

import pytest

from rigidlcp.cli import main


def _one_line_error(capsys, command: str) -> str:
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"rigidlcp {command}: error: ") and "\n" not in err
    return err


@pytest.fixture
def typed(tmp_path):
    """Three unit disks typed by hand: the top one's height 2.732 for 1 + sqrt(3) overlaps its
    supports by 4.4e-5 (docs/packings.md: `forceset --gap-tol 1e-4` accepts them)."""
    path = tmp_path / "typed.csv"
    path.write_text("x,y,r\n1,1,1\n3,1,1\n2,2.732,1\n")
    return path


def _contacts(out: str) -> int:
    """The number of contacts a command's summary states ("N contacts", or timestep's
    transmitting T + not transmitting NT)."""
    import re

    found = re.search(r"(\d+) contacts", out)
    if found:
        return int(found.group(1))
    rows = dict(line.split(None, 1) for line in out.splitlines() if line.strip())
    return int(rows["T"]) + int(rows["NT"])


@pytest.mark.parametrize("command", ["simulate", "timestep", "nullspace"])
def test_packing_commands_read_a_packing_as_forceset_does(command, typed, tmp_path, capsys):
    """`forceset typed.csv --gap-tol 1e-4` worked, but `simulate --packing typed.csv` refused
    the overlap with no way out (no --gap-tol: "unrecognized arguments"), and the walls of a
    packing could not be moved (--left/--right). Every --packing command reads the file with
    the same options, and the overlap's refusal names --gap-tol."""
    extra = {"simulate": ["--no-progress", "--t-max", "1"],
             "timestep": ["--no-progress", "--t-max", "0.1"], "nullspace": []}[command]
    assert main([command, "--packing", str(typed), *extra]) == 2
    assert "--gap-tol G accepts overlaps" in _one_line_error(capsys, command)
    assert main([command, "--packing", str(typed), "--gap-tol", "1e-4", *extra]) == 0
    assert _contacts(capsys.readouterr().out) == 7  # plane 2, walls 2, disks 3
    assert main([command, "--packing", str(typed), "--gap-tol", "1e-4", "--left", "none",
                 "--right", "none", *extra]) in (0, 1)  # 1: simulate's run may detach
    assert _contacts(capsys.readouterr().out) == 5  # no walls


@pytest.mark.parametrize("option", [["--gap-tol", "1e-4"], ["--left", "none"]])
def test_packing_options_without_a_packing_are_refused(option, capsys):
    """--gap-tol or --left on an array would be silently ignored: refused by name."""
    assert main(["simulate", *option, "--no-progress"]) == 2
    assert "give --packing FILE" in _one_line_error(capsys, "simulate")


THREE = "x,y,r\n1,1,1\n3,1,1\n2,2.7320508075688772,1\n"  # docs/packings.md's three disks


@pytest.mark.parametrize("extra, files, why", [
    ([], ["forceset.json", "forceset.png"], ""),
    (["--no-ranges"], ["forceset.json"], "(no forceset.png: --no-ranges)"),
    (["--mu-pp", "0", "--mu-plane", "0", "--mu-wall", "0", "--left", "none", "--right",
      "none"], ["forceset.json"], "(no forceset.png: no equilibrium to draw)"),
])
def test_forceset_out_says_what_it_wrote(extra, files, why, tmp_path, capsys):
    """`forceset FILE --out DIR` printed the analysis and nothing about DIR: the figure was
    there to find, or silently absent (no equilibrium: nothing to draw). The last line names
    the files, and the reason when forceset.png is not among them."""
    (tmp_path / "three.csv").write_text(THREE)
    out = tmp_path / "fs"
    assert main(["forceset", str(tmp_path / "three.csv"), "--out", str(out), *extra]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last == f"written: {', '.join(str(out / f) for f in files)}" + (
        f" {why}" if why else "")
    assert sorted(p.name for p in out.iterdir()) == sorted(files)


def test_packings_md_three_disks_output_is_what_forceset_prints(tmp_path, capsys):
    """docs/packings.md shows `rigidlcp forceset three.csv ...`'s output; it had drifted (a
    balance residual of 3.46e-14 where the code prints 2.22e-16). The block is compared line
    by line, the residual's digits left out (rounding, platform-dependent) but bounded."""
    import re
    from pathlib import Path

    doc = (Path(__file__).parents[2] / "docs" / "packings.md").read_text()
    start = doc.index("`rigidlcp forceset three.csv --mu-pp 0.5")
    block = doc[doc.index("```\n", start) + 4:]
    block = block[:block.index("```")].strip().splitlines()
    (tmp_path / "three.csv").write_text(THREE)
    assert main(["forceset", str(tmp_path / "three.csv"), "--mu-pp", "0.5", "--mu-plane",
                 "0.5", "--mu-wall", "0.5"]) == 0
    got = capsys.readouterr().out.strip().splitlines()
    residual = re.compile(r"balance residual ([0-9.e+-]+)")

    def masked(lines):
        return [residual.sub("balance residual R", line) for line in lines]

    assert masked(got) == masked(block)
    assert float(residual.search("\n".join(got)).group(1)) <= 1e-13
    assert float(residual.search("\n".join(block)).group(1)) <= 1e-13


def test_forceset_json_diameter_of_an_unbounded_set_is_null_null(tmp_path, capsys):
    """docs/packings.md said the diameter's upper end is null for an unbounded set; its lower
    end is null too (the widest range is infinite, so is the diameter): the doc now says so."""
    import json

    (tmp_path / "three.csv").write_text(THREE)
    assert main(["forceset", str(tmp_path / "three.csv"), "--mu-pp", "0.5", "--mu-plane",
                 "0.5", "--mu-wall", "0.5", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert any(c["R"][1] is None for c in d["contacts"]) and d["diameter"] == [None, None]


@pytest.mark.parametrize("header, says", [
    ("x y r", "fields are separated by commas, this line by spaces or tabs"),
    ("x\ty\tr", "fields are separated by commas, this line by spaces or tabs"),
    ("X,Y,R", "names are case-sensitive, got 'X', 'Y', 'R'"),
    ("x,y,radius", "name the radius column r"),
    ("x,y,diameter", "give the radius as a column r (half the diameter)"),
])
def test_a_csv_header_says_what_is_wrong(header, says, tmp_path, capsys):
    """A researcher's own file, whitespace-separated or with 'radius' or 'X,Y,R': refused as
    "missing x, y, r" while the line visibly had them. The refusal now says what differs."""
    f = tmp_path / "mine.csv"
    sep = "\t" if "\t" in header else " " if " " in header else ","
    f.write_text(header + "\n" + sep.join(["1", "1", "1"]) + "\n")
    assert main(["forceset", str(f)]) == 2
    assert _one_line_error(capsys, "forceset").endswith(": " + says)


def test_a_lammps_dump_of_scaled_coordinates_says_so(tmp_path, capsys):
    """LAMMPS's default `dump atom` writes scaled xs ys: refused as "missing x, y" with no word
    on what the file has instead and how to dump x y."""
    f = tmp_path / "scaled.dump"
    f.write_text("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS ff ff pp\n"
                 "0 2\n0 2\n-1 1\nITEM: ATOMS id type xs ys zs radius\n1 1 0.5 0.5 0 1\n")
    assert main(["forceset", str(f)]) == 2
    err = _one_line_error(capsys, "forceset")
    assert "(missing x, y): this dump has xs, ys; write the coordinates x y" in err


@pytest.mark.parametrize("extra", [["--h", "0.01"], ["--ensemble", "face-min-norm,none"]])
def test_compare_integrators_titles_a_packing_as_a_packing(extra, tmp_path, capsys):
    """`compare-integrators --packing` printed "packing 3x5" (a lattice's lx x ly, meaningless
    for a packing) and "first-row modes " with nothing after it."""
    (tmp_path / "three.csv").write_text(THREE)
    assert main(["compare-integrators", "--packing", str(tmp_path / "three.csv"),
                 "--t-max", "3", "--no-progress", *extra]) in (0, 1)
    out = capsys.readouterr().out
    assert out.startswith("packing of 3 disks, mu_pp 0.1")
    assert "first-row modes" not in out


def test_an_npz_of_centres_as_one_array_says_x_must_be_1d(tmp_path, capsys):
    """A packing .npz whose 'x' held the centres as an (N, 2) array was refused as "array 'x'
    must be 4 numbers (like x)": x compared with itself."""
    import numpy as np

    f = tmp_path / "centres.npz"
    np.savez(f, x=[[1.0, 1.0], [3.0, 1.0]], y=[1.0, 1.0], r=[1.0, 1.0])
    assert main(["forceset", str(f)]) == 2
    err = _one_line_error(capsys, "forceset")
    assert err.endswith("array 'x' must be 1-D, one abscissa per disk (the ordinates in array "
                        "'y'), got shape (2, 2)")


def test_inertia_with_a_packing_is_refused_in_command_line_words(typed, capsys):
    """`simulate --packing F --inertia 0.3` answered "pass inertia=None" (Python's words)."""
    assert main(["simulate", "--packing", str(typed), "--gap-tol", "1e-4", "--inertia", "0.3",
                 "--no-progress"]) == 2
    err = _one_line_error(capsys, "simulate")
    assert "leave --inertia out" in err and "inertia=None" not in err


def test_every_packing_command_takes_a_runs_geometry(tmp_path, capsys):
    """`nullspace --packing RUN.npz` read a run's geometry, while `forces --packing RUN.npz`
    and `simulate --packing RUN.npz` refused it ("a run ..., not a packing"). All take it now;
    the same run again from it gives the same steady mu_g, and the options that would change
    its geometry are refused."""
    import json

    from rigidlcp.models.deposition import deposit
    from rigidlcp.models.packing_io import write_packing

    pile = write_packing(tmp_path / "p5.csv", deposit(12, seed=5, radii=(0.8, 1.2), width=6.0))
    mu = ["--mu-pp", "0.1", "--mu-plane", "0.1", "--mu-wall", "0.1", "--seed", "1"]
    assert main(["simulate", "--packing", str(pile), *mu, "--out", str(tmp_path / "run5"),
                 "--no-progress", "--json"]) == 0
    first = json.loads(capsys.readouterr().out)
    run = str(tmp_path / "run5.npz")
    assert main(["simulate", "--packing", run, *mu, "--no-progress", "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["status"] == first["status"] == "steady"
    assert again["mu_g"] == first["mu_g"]
    assert main(["forces", "--packing", run, "--out", str(tmp_path / "f")]) == 0
    capsys.readouterr()
    assert main(["simulate", "--packing", run, "--gap-tol", "1e-3", "--no-progress"]) == 2
    assert "is a run, whose geometry" in _one_line_error(capsys, "simulate")


def test_forceset_progress_is_not_redrawn_at_every_lp(tmp_path, capsys, monkeypatch):
    """The range bar was redrawn after every LP (an explicit refresh): 800 LPs of a 100-disk
    pile wrote about 200 bars into a log (stderr redirected) in 5 s. Now tqdm's rate limit
    applies (mininterval, 0.1 s by default; an hour here, so that only the first and last
    draws remain, whatever the machine's speed)."""
    import rigidlcp.models.progress as progress
    from rigidlcp.models.deposition import deposit
    from rigidlcp.models.packing_io import write_packing

    real = progress.new_bar
    # (the phase bar passes its own mininterval=0: every phase shown; this one wins here)
    monkeypatch.setattr(progress, "new_bar", lambda **kw: real(**{**kw, "mininterval": 3600}))

    pile = write_packing(tmp_path / "p.csv", deposit(100, seed=2, radii=(0.8, 1.2),
                                                     width=20.0))
    assert main(["forceset", str(pile), "--mu-pp", "0.3", "--mu-plane", "0.3", "--mu-wall",
                 "0.3"]) == 0
    cap = capsys.readouterr()
    assert "200 contacts" in cap.out and "dimension of the admissible set: 100" in cap.out
    assert 1 <= cap.err.count("force range ends") <= 3  # the bar's label (EndsBar)


@pytest.mark.parametrize("command", [["forceset"], ["simulate", "--no-progress", "--packing"]])
def test_a_pile_above_the_plane_is_named(command, tmp_path, capsys):
    """A DEM frame whose bottom is not y = 0 (the frame is not moved): forceset said "no
    equilibrium" (a checked Farkas certificate: the pile floats) with no word on why; a
    warning now says that no disk touches the plane, and where the lowest bottom is."""
    f = tmp_path / "lifted.csv"
    f.write_text(THREE.replace(",1,1\n", ",6,1\n").replace("2.7320508075688772",
                                                          "7.7320508075688772"))
    main([*command, str(f)])
    err = capsys.readouterr().err
    assert ("warning: no disk touches the plane y = 0 (the lowest disk's bottom is at y = 5)"
            in err)
    (tmp_path / "three.csv").write_text(THREE)
    main([*command, str(tmp_path / "three.csv")])
    assert "no disk touches the plane" not in capsys.readouterr().err


@pytest.mark.parametrize("command", [["simulate", "--no-progress"], ["nullspace"]])
def test_a_packings_walls_are_in_the_summary(command, tmp_path, capsys):
    """`simulate --packing` did not say where the walls were (the file's box, the options, or
    the tight box around the disks, which makes the outermost disks touch them); forceset
    did. The first line now names them."""
    (tmp_path / "three.csv").write_text(THREE)
    main([*command, "--packing", str(tmp_path / "three.csv"), "--left", "none"])
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith("packing: 3 disks, 6 contacts; no left wall, right wall x = 4; ")


def test_timestep_says_what_it_ran(tmp_path, capsys):
    """`rigidlcp timestep` printed its summary with no line on the system (simulate's first
    line: the array or packing, its contacts, walls, friction and driving)."""
    (tmp_path / "three.csv").write_text(THREE)
    assert main(["timestep", "--packing", str(tmp_path / "three.csv"), "--t-max", "0.05",
                 "--mu-pp", "0.3", "--no-progress"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first == ("packing: 3 disks, 7 contacts; left wall x = 0, right wall x = 4; "
                     "mu_pp = 0.3, mu_plane = 0.2, mu_wall = 0.0, gamma = 0.1 g, V0 = 0.0")
    assert main(["timestep", "--lx", "2", "--ly", "1", "--t-max", "0.05",
                 "--no-progress"]) == 0
    assert capsys.readouterr().out.startswith("rect 2x1: 2 disks, 5 contacts; mu_pp = 0.1")

