"""What a new user tripped on (session 28): Ctrl-C in a long command printed a traceback (bench,
fuzz, forceset, ranges, simulate), and an interrupted bench's folder was refused without naming
--resume."""

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


def test_a_relative_set_folder_names_the_current_folder(tmp_path, monkeypatch):
    """docs/bench.md's script passes "tests/data/siconos", the repository's folder: run from
    elsewhere it was "not a name ... nor a directory", with no word on where it was looked
    for."""
    from rigidlcp.bench.problem_sets import get_set

    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError, match="read from the current folder") as exc:
        get_set("tests/data/siconos")
    assert str(tmp_path) in str(exc.value)


def test_a_lammps_dump_of_scaled_coordinates_says_so(tmp_path, capsys):
    """LAMMPS's default `dump atom` writes scaled xs ys: refused as "missing x, y" with no word
    on what the file has instead and how to dump x y."""
    f = tmp_path / "scaled.dump"
    f.write_text("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS ff ff pp\n"
                 "0 2\n0 2\n-1 1\nITEM: ATOMS id type xs ys zs radius\n1 1 0.5 0.5 0 1\n")
    assert main(["forceset", str(f)]) == 2
    err = _one_line_error(capsys, "forceset")
    assert "(missing x, y): this dump has xs, ys; write the coordinates x y" in err


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
    monkeypatch.setattr(progress, "new_bar", lambda **kw: real(mininterval=3600, **kw))

    pile = write_packing(tmp_path / "p.csv", deposit(100, seed=2, radii=(0.8, 1.2),
                                                     width=20.0))
    assert main(["forceset", str(pile), "--mu-pp", "0.3", "--mu-plane", "0.3", "--mu-wall",
                 "0.3"]) == 0
    cap = capsys.readouterr()
    assert "200 contacts" in cap.out and "dimension of the admissible set: 100" in cap.out
    assert 1 <= cap.err.count("force ranges:") <= 3


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
