"""Sweeps: grids, the results file, resume after a real kill -9, local pool vs Dask, the CLI."""

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from rigidlcp.cli.main import main
from rigidlcp.models.sweep import (
    RESULTS,
    ResultsFile,
    Sweep,
    parse_grid,
    point_key,
    read_results,
    run_point,
    run_sweep,
)

# A cheap sweep: a 4x2 rectangular array (Fig. 9's coefficients), ~0.2 s per point.
SMALL = ["--lattice", "rect", "--lx", "4", "--ly", "2", "--mu-pp", "0.1", "--mu-plane", "0.2",
         "--mu-wall", "0"]


def small_sweep(gamma: str = "0.05:0.5:10") -> Sweep:
    return Sweep({"gamma": parse_grid("gamma", gamma)},
                 {"lattice": "rect", "lx": 4, "ly": 2, "mu_pp": 0.1, "mu_plane": 0.2,
                  "mu_wall": 0.0})


# --- grids --------------------------------------------------------------------------------------

def test_parse_grid():
    g = parse_grid("gamma", "0:1.0:41")
    assert len(g) == 41 and g[0] == 0.0 and g[-1] == 1.0 and g[1] == 0.025 and g[12] == 0.3
    assert parse_grid("mu_pp", "0.05,0.1") == [0.05, 0.1]
    assert parse_grid("gamma", "0.3") == [0.3]
    assert parse_grid("lx", "2:8:4") == [2, 4, 6, 8]
    assert parse_grid("seed", "1,2,3") == [1, 2, 3]
    assert parse_grid("lattice", "rect,tri") == ["rect", "tri"]
    assert parse_grid("inertia", "default,0.25") == [None, 0.25]
    assert parse_grid("gamma", 0.2) == [0.2]  # non-strings (defaults) pass through


@pytest.mark.parametrize("name, text, message", [
    ("gamma", "0:1", "START:STOP:NUM"),
    ("gamma", "0:1:0", "NUM must be an integer >= 1"),
    ("gamma", "0:1:2.5", "NUM must be an integer >= 1"),
    ("mu_pp", "a,b", "not a number"),
    ("gamma", "nan", "must be finite"),
    ("lx", "2:5:3", "takes integers"),
    ("gamma", "default", "only for inertia"),
    ("radius", "1", "unknown sweep parameter"),
])
def test_parse_grid_errors(name, text, message):
    with pytest.raises(ValueError, match=message):
        parse_grid(name, text)


def test_points_are_the_product_in_axis_order():
    sweep = Sweep({"mu_pp": [0.05, 0.1], "gamma": [0.1, 0.2, 0.3]}, {"lx": 3})
    pts = sweep.points()
    assert [(p["mu_pp"], p["gamma"]) for p in pts] == [
        (0.05, 0.1), (0.05, 0.2), (0.05, 0.3), (0.1, 0.1), (0.1, 0.2), (0.1, 0.3)]
    assert all(p["lx"] == 3 and p["ly"] == 4 and p["select"] == "face-min-norm" for p in pts)
    assert len({point_key(p) for p in pts}) == 6
    with pytest.raises(ValueError, match="unknown run option"):
        Sweep({}, {}, {"speed": 2})


def test_run_point_summary_and_errors():
    point = small_sweep("0.16").points()[0]
    row = run_point(point)
    assert row["status"] == "steady" and row["steady"] and row["events"] > 1
    assert row["F_g"] == pytest.approx(row["mu_g"] * row["m_g"]) and row["m_g"] == 8.0
    assert row["T"] + row["NT"] == 4 * 2 * 2 + 2  # c = 2 Lx Ly + Ly
    bad = dict(point, lattice="tri", lx=1, ly=3)
    row = run_point(bad)
    assert row["status"] == "error" and "needs lx >= 2" in row["message"]


# --- the results file ---------------------------------------------------------------------------

def test_results_file_ignores_a_torn_line(tmp_path):
    rf = ResultsFile(tmp_path / RESULTS)
    p1, p2 = small_sweep("0.1,0.2").points()
    rf.append({**p1, "status": "steady"})
    with open(rf.path, "a") as fh:
        fh.write('{"lattice": "rect", "lx": 4, "ly')  # a write cut by kill -9
    rf.append({**p2, "status": "steady"})  # starts on a fresh line
    rows = rf.read()
    assert rf.bad_lines == 1 and [r["gamma"] for r in rows] == [0.1, 0.2]
    rows = rf.finalize([point_key(p2), point_key(p1)])
    assert [r["gamma"] for r in rows] == [0.2, 0.1]
    assert len(rf.path.read_text().splitlines()) == 2 and rf.read() and rf.bad_lines == 0


# --- resume after kill -9 -----------------------------------------------------------------------

def _cli(*args: str) -> list[str]:
    return [sys.executable, "-c", "import sys; from rigidlcp.cli.main import main; "
            "sys.exit(main(sys.argv[1:]))", *args]


def test_resume_after_kill_gives_the_uninterrupted_file(tmp_path):
    """Really kill -9 a sweep running in a subprocess, rerun the command: the finished file is
    byte for byte the one of an uninterrupted sweep, and the rerun skipped the saved points."""
    args = ["sweep", *SMALL, "--gamma", "0.05:0.5:10", "--jobs", "1", "--no-progress"]
    killed = tmp_path / "killed"
    proc = subprocess.Popen(_cli(*args, "--out", str(killed)), start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    results = killed / RESULTS
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            if results.exists() and len(results.read_text().splitlines()) >= 3:
                break
            time.sleep(0.02)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    assert proc.returncode == -signal.SIGKILL, "the sweep finished before it could be killed"
    saved = len(results.read_text().splitlines())
    assert 3 <= saved < 10
    rerun = subprocess.run(_cli(*args, "--out", str(killed)), capture_output=True, text=True,
                           timeout=300)
    assert rerun.returncode == 0, rerun.stderr
    assert f"resuming: {saved} of 10 points already in" in rerun.stderr
    assert f"{10 - saved} run now, {saved} found done" in rerun.stdout
    whole = tmp_path / "whole"
    res = run_sweep(small_sweep(), whole, jobs=1, progress=False)
    assert res.ran == 10 and res.complete
    assert (whole / RESULTS).read_bytes() == results.read_bytes()
    assert all(r["status"] == "steady" for r in read_results(killed))


# --- executors ----------------------------------------------------------------------------------

@pytest.mark.slow  # starting a LocalCluster takes 3-12 s on this shared machine
def test_local_pool_and_dask_local_cluster_give_identical_files(tmp_path):
    pytest.importorskip("dask.distributed")
    sweep = small_sweep("0.1:0.4:4")
    serial = run_sweep(sweep, tmp_path / "serial", jobs=1, progress=False)
    pool = run_sweep(sweep, tmp_path / "pool", jobs=2, progress=False)
    dask = run_sweep(sweep, tmp_path / "dask", jobs=2, dask="local", progress=False)
    assert serial.ran == pool.ran == dask.ran == 4
    ref = (tmp_path / "serial" / RESULTS).read_bytes()
    assert (tmp_path / "pool" / RESULTS).read_bytes() == ref
    assert (tmp_path / "dask" / RESULTS).read_bytes() == ref
    assert all(r["status"] == "steady" for r in serial.rows)


def test_bad_dask_address(tmp_path):
    with pytest.raises(ValueError, match="--dask takes 'local' or a scheduler address"):
        run_sweep(small_sweep("0.1"), tmp_path / "x", dask="myhost:1", progress=False)


# --- the commands -------------------------------------------------------------------------------

def test_sweep_and_effective_commands(tmp_path, capsys):
    out = tmp_path / "sw"
    code = main(["sweep", "--lattice", "rect", "--lx", "3", "--ly", "1", "--mu-pp", "0.05",
                 "--mu-plane", "0.1", "--mu-wall", "0", "--gamma", "0:0.3:7", "--jobs", "1",
                 "--no-progress", "--out", str(out), "--save-runs"])
    text = capsys.readouterr().out
    assert code == 0 and "7 run now, 0 found done" in text
    rows = read_results(out)
    assert [r["gamma"] for r in rows] == [0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3]
    assert all((out / r["run_file"]).exists() for r in rows)
    assert json.loads((out / "sweep.json").read_text())["axes"] == {"gamma": [
        0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3]}
    code = main(["effective", str(out)])
    text = capsys.readouterr().out
    assert code == 0 and "m_e" in text and "mu_e" in text
    for name in ("mu_g.png", "effective.png"):
        assert (out / name).stat().st_size > 1000
    eff = json.loads((out / "effective.json").read_text())
    assert len(eff) == 1 and eff[0]["m_g"] == 3.0 and len(eff[0]["rows"]) == 7


@pytest.mark.parametrize("args, message", [
    (["--gamma", "0:1"], "START:STOP:NUM"),
    (["--lx", "2.5"], "takes integers"),
    (["--method", "magic"], "unknown method 'magic'"),
    (["--max-events", "0"], "--max-events must be >= 1"),
])
def test_sweep_bad_input(tmp_path, args, message, capsys):
    assert main(["sweep", "--out", str(tmp_path / "x"), "--no-progress", *args]) == 2
    assert message in capsys.readouterr().err


def test_effective_needs_results(tmp_path, capsys):
    assert main(["effective", str(tmp_path)]) == 2
    assert "no sweep results" in capsys.readouterr().err.lower()


def test_a_folder_of_another_sweep_is_refused_not_merged(tmp_path):
    """user25: a 3x1 sweep into a folder of a 10x1 sweep was merged into its results.jsonl."""
    from rigidlcp.lcp.errors import OutputExists
    from rigidlcp.models.sweep import Sweep, run_sweep

    out = tmp_path / "sw"
    first = Sweep({"gamma": [0.05]}, {"lx": 3, "ly": 1})
    run_sweep(first, out, jobs=1, progress=False, log=lambda m: None)
    lines = (out / "results.jsonl").read_text()
    other = Sweep({"gamma": [0.05]}, {"lx": 4, "ly": 1})
    with pytest.raises(OutputExists, match="another sweep.*lx"):
        run_sweep(other, out, jobs=1, progress=False, log=lambda m: None)
    assert (out / "results.jsonl").read_text() == lines
    again = run_sweep(first, out, jobs=1, progress=False, log=lambda m: None)  # resume: same
    assert again.ran == 0 and again.skipped == 1
