"""Every command, on every bad input we could think of, prints ONE line naming the problem and
exits with status 2: no traceback, no usage block, and no file the user had is overwritten
(issue 14.2). Each case runs `python -m rigidlcp.cli` as a subprocess in a folder prepared by
the `workdir` fixture; the cases run concurrently (a few at a time) to keep the test short.
"""

from __future__ import annotations

import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

#: (command line, a word the message must contain). Files: lcp.npz (an LCP), run.npz (a run),
#: corrupt.npz (text), empty.npz (0 bytes), trunc.npz (a cut run), existfile (a plain file),
#: figs/ (a folder holding angular_acceleration.png, sweep outputs and forces.json: a user's),
#: emptydir/ (empty), keep.png (a user's PNG).
CASES: list[tuple[str, str]] = [
    # solve
    ("solve missing.npz", "missing.npz"),
    ("solve empty.npz", "empty"),
    ("solve corrupt.npz", "not a .npz"),
    ("solve trunc.npz", "damaged"),
    ("solve run.npz", "run saved by"),
    ("solve emptydir", "directory"),
    ("solve lcp.npz --method nope", "unknown method"),
    ("solve lcp.npz -o bogus=1", "bogus"),
    ("solve lcp.npz -o tol", "KEY=VALUE"),
    ("solve lcp.npz --bogus", "unrecognized"),
    # plot
    ("plot lcp.npz --out out1", "problem file"),
    ("plot corrupt.npz --out out1", "not a .npz"),
    ("plot empty.npz --out out1", "empty"),
    ("plot trunc.npz --out out1", "damaged"),
    ("plot missing.npz --out out1", "missing.npz"),
    ("plot run.npz --out existfile", "existfile"),
    ("plot run.npz --out existfile/sub", "existfile"),
    ("plot run.npz --out figs", "--force"),
    ("plot run.npz --out out1 --event 99", "--event"),
    ("plot run.npz", "--out"),
    ("plot existfile --out out1", "not a run file"),
    # simulate
    ("simulate --lx 0", "lx"),
    ("simulate --ly -1", "ly"),
    ("simulate --mu-pp -1", "mu_pp"),
    ("simulate --mu-plane nan", "mu_plane"),
    ("simulate --gamma nan", "gamma"),
    ("simulate --inertia -1", "inertia"),
    ("simulate --lattice hex", "hex"),
    ("simulate --lx two", "--lx"),
    ("simulate --method nope", "unknown method"),
    ("simulate --fallback nope", "unknown method"),
    ("simulate --select best", "--select"),
    ("simulate --t-max -1", "--t-max"),
    ("simulate --max-events 0", "--max-events"),
    ("simulate --omega-scale -1", "--omega-scale"),
    ("simulate --lx 3 --ly 2 --out run.npz", "--force"),
    ("simulate --lx 100000000 --ly 100000000 --out big.npz", "disks"),
    ("simulate --seed -1 --out s.npz", "--seed"),
    ("simulate --lx 3 --ly 1 --out emptydir", "directory"),
    ("simulate --lx 3 --ly 2 --out existfile/run.npz", "existfile"),
    ("simulate --lx 3 --ly 2 --dump-problems existfile", "existfile"),
    ("simulate --lx 3 --ly 2 --dump-problems figs", "--force"),
    # the dense backend's memory is estimated before anything is allocated (issue 24.1)
    ("simulate --lx 1000 --ly 1000 --out mid.npz --max-events 1", "sparse"),
    ("simulate --lx 3 --ly 2 --no-progress --out /proc/x.npz", "/proc/x.npz"),
    # sweep (the whole grid is validated before anything runs)
    ("sweep --lattice hex --out sw", "hex"),
    ("sweep --mu-pp -0.1 --out sw", "mu_pp"),
    ("sweep --lx 0 --out sw", "lx"),
    ("sweep --lx 3 --ly 1 --gamma 0:1:3 --mu-pp 0.1,-1 --out sw", "mu_pp"),
    ("sweep --gamma 0:1:x --out sw", "--gamma"),
    ("sweep --gamma 0:1 --out sw", "START:STOP:NUM"),
    ("sweep --lx 2.5 --out sw", "integers"),
    ("sweep --method nope --out sw", "unknown method"),
    ("sweep --max-events 0 --out sw", "max-events"),
    ("sweep --out existfile", "existfile"),
    ("sweep --out figs", "--force"),
    ("sweep --lx 3 --ly 1 --seed -1 --out sw", "seed"),
    ("sweep --lx 3 --ly 1 --gamma 0.1 --jobs 0 --out sw", "--jobs"),
    # effective
    ("effective missing", "missing"),
    ("effective corrupt.npz", "corrupt.npz"),
    ("effective emptydir", "emptydir"),
    # nullspace, verify-formulas
    ("nullspace --lx 0", "lx"),
    ("nullspace --mu-pp -1", "mu_pp"),
    ("nullspace --states missing.json", "missing.json"),
    ("nullspace --states corrupt.npz", "not a .npz"),
    ("nullspace --states lcp.npz", "normal"),
    ("nullspace --states existfile", "existfile"),
    ("nullspace --plot keep.png", "--force"),
    ("nullspace --plot existfile", ".png"),
    ("nullspace --plot existfile/x.png", "existfile"),
    ("nullspace --plot x.png --no-localize", "--no-localize"),
    ("verify-formulas --lx 0 3", "--lx"),
    ("verify-formulas --ly 5 3", "--ly"),
    ("verify-formulas --lattice tri --lx 1 3", "lx >= 2"),
    # forces
    ("forces --lx 0 --out f", "lx"),
    ("forces --mu-pp -1 --out f", "mu_pp"),
    ("forces --networks 0 --out f", "--networks"),
    ("forces --time-limit 0 --out f", "--time-limit"),
    ("forces --method nope --out f", "unknown method"),
    ("forces --out existfile", "existfile"),
    ("forces --out figs", "--force"),
    ("forces --omega-scale -1 --out f", "omega_scale"),
    ("forces --seed -1 --out f", "--seed"),
    # certify, timestep, compare-integrators
    ("certify missing.npz", "missing.npz"),
    ("certify corrupt.npz", "not a .npz"),
    ("certify run.npz", "run saved by"),
    ("certify lcp.npz --method nope", "unknown method"),
    ("certify lcp.npz --time-limit -3", "--time-limit"),
    ("certify lcp.npz --time-limit nan", "--time-limit"),
    ("timestep --lx 0", "lx"),
    ("timestep --mu-pp -1", "mu_pp"),
    ("timestep --lx 3 --ly 2 --out run.npz", "exists"),
    ("timestep --seed -1", "--seed"),
    ("compare-integrators --lx 0", "lx"),
    ("compare-integrators --mu-plane -1", "mu_plane"),
    # certify-run
    ("certify-run missing.npz", "missing.npz"),
    ("certify-run lcp.npz", "problem file"),
    ("certify-run corrupt.npz", "not a .npz"),
    ("certify-run empty.npz", "empty"),
    ("certify-run trunc.npz", "damaged"),
    ("certify-run run.npz --out existfile", "existfile"),
    ("certify-run run.npz --out figs", "--force"),
    ("certify-run run.npz --jobs 0", "--jobs"),
    ("certify-run run.npz --time-limit 0", "--time-limit"),
    # bench
    # (a folder holding unreadable files is a set: they are reported as unreadable rows)
    ("bench --set nope --out b1", "nope"),
    ("bench --set emptydir --out b2", "emptydir"),
    ("bench --set random-p --out b3 --methods nope", "nope"),
    ("bench --set random-p --out existfile", "existfile"),
    ("bench --set random-p --out figs", "--force"),
    ("bench --set random-p --out b4 --time-limit -1", "--time-limit"),
    ("bench --out b5", "--set"),
    ("bench --set random-p --sizes abc --out b6", "--sizes"),
    ("bench --set random-p --sizes 0 --out b7", "--sizes"),
    ("bench --set random-p --per-size 0 --out b8", "--per-size"),
    ("bench --set random-p --seed -1 --out b9", "--seed"),
    ("fuzz --count 3 --seed -1", "--seed"),
    ("fuzz --count 0", "--count"),
    ("fuzz --count 3 --out existfile", "existfile"),
    # reproduce
    ("reproduce --out existfile", "existfile"),
    ("reproduce --out figs", "--force"),
    ("reproduce --out r --jobs 0", "--jobs"),
    # no command / unknown command
    ("", "COMMAND"),
    ("frobnicate", "frobnicate"),
]


@pytest.fixture(scope="module")
def workdir(tmp_path_factory) -> Path:
    from rigidlcp import lcp, models
    from rigidlcp.models.runio import save_run

    d = tmp_path_factory.mktemp("bad_input")
    lcp.LCP(np.eye(2), -np.ones(2)).save(d / "lcp.npz")
    system = models.System(models.rectangular(3, 2), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.1)
    save_run(models.simulate(system, seed=1, progress=None), d / "run.npz")
    (d / "corrupt.npz").write_text("garbage, not an archive\n")
    (d / "empty.npz").write_bytes(b"")
    (d / "trunc.npz").write_bytes((d / "run.npz").read_bytes()[:300])
    (d / "existfile").write_text("a file of the user's\n")
    (d / "keep.png").write_text("a picture of the user's\n")
    (d / "emptydir").mkdir()
    figs = d / "figs"
    figs.mkdir()
    for name in ("angular_acceleration.png", "forces.json", "results.jsonl"):
        (figs / name).write_text("the user's\n")
    return d


def _snapshot(d: Path) -> dict[str, tuple[int, float]]:
    return {str(p.relative_to(d)): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in d.rglob("*") if p.is_file()}


def _run(d: Path, line: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "MPLBACKEND": "Agg", "RIGIDLCP_CACHE": str(d / "cache")}
    return subprocess.run([sys.executable, "-m", "rigidlcp.cli", *line.split()], cwd=d,
                          capture_output=True, text=True, timeout=120, env=env)


@pytest.mark.slow  # ~100 subprocesses: 40 s on a quiet 2-core machine, minutes on a loaded one
def test_every_bad_input_is_one_line_and_status_2(workdir):
    before = _snapshot(workdir)
    with ThreadPoolExecutor(max_workers=3) as pool:
        results = list(pool.map(lambda case: _run(workdir, case[0]), CASES))
    problems = []
    for (line, word), proc in zip(CASES, results):
        lines = [x for x in proc.stderr.splitlines() if x.strip()]
        why = []
        if proc.returncode != 2:
            why.append(f"exit status {proc.returncode}")
        if "Traceback" in proc.stderr:
            why.append("a traceback")
        if len(lines) != 1:
            why.append(f"{len(lines)} stderr lines")
        elif word.lower() not in lines[0].lower():
            why.append(f"the message does not name {word!r}")
        if why:
            problems.append(f"rigidlcp {line}: {', '.join(why)}: {proc.stderr[-300:]!r}")
    assert not problems, "\n".join(problems)
    after = _snapshot(workdir)
    changed = [k for k, v in before.items() if after.get(k) != v]
    assert not changed, f"a user's file was changed: {changed}"
    left = sorted(set(after) - set(before))
    assert not left, f"a refused command left something behind: {left}"


def test_force_overwrites_and_files_get_ordinary_permissions(workdir, tmp_path):
    """--force is the way to overwrite; what is written has mode 0666 & ~umask (not 0600)."""
    (tmp_path / "run.npz").write_text("old")
    line = f"simulate --lx 3 --ly 2 --no-progress --out {tmp_path / 'run.npz'}"
    assert _run(workdir, line).returncode == 2
    assert (tmp_path / "run.npz").read_text() == "old"
    proc = _run(workdir, line + " --force")
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "run.npz").read_bytes()[:2] == b"PK"
    mask = os.umask(0)
    os.umask(mask)
    for name in ("run.npz", "run.json"):
        assert (tmp_path / name).stat().st_mode & 0o777 == 0o666 & ~mask
    assert "Running HiGHS" not in proc.stdout + proc.stderr  # no solver banner


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0,
                    reason="needs POSIX permissions and a user that is not root")
def test_read_only_folder(workdir, tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        for line in (f"simulate --lx 3 --ly 2 --out {ro / 'run.npz'}",
                     f"plot run.npz --out {ro / 'figs'}",
                     f"forces --out {ro / 'f'}", f"reproduce --out {ro / 'r'}"):
            proc = _run(workdir, line)
            assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1, line
            assert "Traceback" not in proc.stderr
    finally:
        ro.chmod(0o755)
