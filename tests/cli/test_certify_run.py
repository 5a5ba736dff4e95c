"""Certifying a whole run (verify.certificates.run and `rigidlcp certify-run`): rows, totals,
resume, never overwriting, parallel events."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.cli import main
from rigidlcp.lcp.errors import InvalidInput, OutputExists
from rigidlcp.models.runio import save_run
from rigidlcp.verify.certificates.run import FIGURE, LINES, SUMMARY, certify_run

VERDICTS = ("accelerations", "forces", "states")


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    system = models.System(models.rectangular(2, 1), mu_pp=0.0, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.16)
    run = models.simulate(system, models.initial_state(system, seed=1), max_events=6)
    return save_run(run, tmp_path_factory.mktemp("run") / "short"), run.n_events


def _verdicts(rows):
    return [(r["event"], *(r[q] for q in VERDICTS)) for r in rows]


def test_every_event_gets_verdicts_and_files(run_file, tmp_path):
    path, n = run_file
    res = certify_run(path, tmp_path / "cert")
    assert [r["event"] for r in res.rows] == list(range(n))
    for r in res.rows:
        assert r["accepted"] and all(r[q] for q in VERDICTS)
        assert r["certificate"]["verdicts"]["forces"]["stage"]
    lines = (tmp_path / "cert" / LINES).read_text().splitlines()
    assert [json.loads(x)["event"] for x in lines] == list(range(n))
    totals = json.loads((tmp_path / "cert" / SUMMARY).read_text())
    for q in VERDICTS:
        c = totals[q]
        assert c["unique"] + c["another solution exists"] + c["unknown"] == n
    assert (tmp_path / "cert" / FIGURE).stat().st_size > 0
    # this frictionless row: forces not unique (free compression), accelerations unique
    assert totals["forces"]["another solution exists"] == n
    assert totals["accelerations"]["unique"] == n


def test_resume_runs_only_the_missing_events(run_file, tmp_path):
    path, n = run_file
    out = tmp_path / "cert"
    first = certify_run(path, out, events=[0, 1])
    assert first.ran == 2
    with open(out / LINES, "a") as fh:  # a torn line from a killed run
        fh.write('{"event": 4, "t": ')
    res = certify_run(path, out, resume=True)
    assert res.skipped == 2 and res.ran == n - 2
    fresh = certify_run(path, None)
    assert _verdicts(res.rows) == _verdicts(fresh.rows)
    assert len((out / LINES).read_text().splitlines()) == n


def test_never_overwrites_and_checks_options(run_file, tmp_path):
    path, _ = run_file
    out = tmp_path / "cert"
    certify_run(path, out, events=[0])
    with pytest.raises(OutputExists, match="--resume"):
        certify_run(path, out, events=[0])
    with pytest.raises(InvalidInput, match="other options"):
        certify_run(path, out, resume=True, time_limit=3.0)
    res = certify_run(path, out, events=[0, 1], force=True)
    assert res.skipped == 0 and res.ran == 2
    with pytest.raises(InvalidInput, match="out of range"):
        certify_run(path, tmp_path / "other", events=[99])


def test_parallel_events_give_the_same_verdicts(run_file, tmp_path):
    path, _ = run_file
    a = certify_run(path, None, events=[0, 1, 2])
    b = certify_run(path, tmp_path / "par", events=[0, 1, 2], jobs=2)
    assert _verdicts(a.rows) == _verdicts(b.rows)


def test_command(run_file, tmp_path, capsys):
    path, n = run_file
    out = tmp_path / "cert"
    assert main(["certify-run", str(path), "--out", str(out), "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert f"events: {n}" in text and "accelerations" in text
    assert main(["certify-run", str(path), "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "exists" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert main(["certify-run", str(path), "--out", str(out), "--resume", "--json",
                 "--no-progress"]) == 0
    assert json.loads(capsys.readouterr().out)["events"] == n
    assert main(["certify-run", str(tmp_path / "missing.npz"), "--no-progress"]) == 2
    assert main(["certify-run", str(path), "--events", "x", "--out", str(tmp_path / "o"),
                 "--no-progress"]) == 2


def _no_nan(name):
    raise ValueError(f"not strict JSON: {name}")


def test_lines_are_strict_json_with_witnesses(run_file, tmp_path):
    """No NaN / Infinity in certificates.jsonl (issue 24.5: face_width was NaN on every line),
    and every witness is written with its z, which re-checks as a solution of the event."""
    from rigidlcp.models.event import event_problem
    from rigidlcp.models.runio import load_run
    from rigidlcp.verify.certificates.stages import independent_residual

    path, n = run_file
    certify_run(path, tmp_path / "cert")
    rows = [json.loads(x, parse_constant=_no_nan)
            for x in (tmp_path / "cert" / LINES).read_text().splitlines()]
    run = load_run(path)
    assert len(rows) == n
    for r in rows:
        assert r["certificate"]["verdicts"]["forces"]["face_width"] is None  # ranges not asked
        # forces are not unique on this row: each row carries its witness
        assert r["witnesses"] and "forces" in sum((w["questions"] for w in r["witnesses"]), [])
        ep = event_problem(run.system, run.state_at(r["event"]))
        for w in r["witnesses"]:
            z = np.array(w["z"])
            assert independent_residual(ep.lcp.M, ep.lcp.q, z) <= 1e-8
            assert w["residual"] <= 1e-8 and max(w["d_R"], w["d_S"]) > 0


def test_witness_at_a_steady_event_says_whether_it_is_steady():
    """A 3x1 row (0.1/0.2/0, gamma 0.16, seed 1) ends steady; at its last event one witness
    (other accelerations) opens a contact (a_n != 0): not a steady state; another (other
    forces, same accelerations) is one. Each verdict is checked here from the witness's own
    accelerations."""
    from rigidlcp.models.event import event_problem

    system = models.System(models.rectangular(3, 1), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.16)
    run = models.simulate(system, seed=1)
    assert run.status == "steady"
    k = run.n_events - 1
    row = certify_run(run, None, events=[k]).rows[0]
    assert row["steady_event"] is True
    flags = sorted(w["steady"] for w in row["witnesses"])
    assert flags == [False, True]
    ep = event_problem(system, run.state_at(k))
    s_in = run.state_at(k).s
    for w in row["witnesses"]:
        es = ep.unpack(np.array(w["z"]))
        tol = 1e-6 * system.g  # the verdicts are clear-cut here: far above rounding
        closed = np.all(np.abs(es.a_n) <= tol)
        # es.s: the states after the event (a contact starting to slide there is sliding)
        kept = np.all(np.abs(es.a_t[(es.s == 0) & (system.mu > 0) & (es.R > 1e-9)]) <= tol)
        no_slowing = np.all(s_in * es.a_t >= -tol)
        assert w["steady"] == bool(closed and kept and no_slowing)
    # at a non-steady event the question is not asked
    early = certify_run(run, None, events=[0]).rows[0]
    assert early["steady_event"] is False
    assert all(w["steady"] is None for w in early["witnesses"])


def test_a_file_that_is_not_a_run_is_named(tmp_path, capsys):
    """`certify-run pile.csv` said 'No such file ...: pile.csv.npz' of a file that exists;
    now, as `ranges` and `plot` do, that it is not a run file; nothing is written."""
    csv = tmp_path / "pile.csv"
    csv.write_text("x,y,r\n1,1,1\n")
    assert main(["certify-run", str(csv)]) == 2
    err = capsys.readouterr().err
    assert f"{csv}: not a run file" in err and err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pile.csv"]


def test_an_empty_events_range_is_refused_and_writes_nothing(run_file, tmp_path, capsys):
    """--events 5:2 certified no event, exited 0 and left an output folder behind."""
    path, _ = run_file
    out = tmp_path / "c"
    assert main(["certify-run", str(path), "--events", "5:2", "--out", str(out)]) == 2
    assert "selects no event" in capsys.readouterr().err and not out.exists()
    with pytest.raises(InvalidInput, match="selects no event"):
        certify_run(path, out, events=[])
    assert not out.exists()


def test_clock_is_an_option_of_the_folder(run_file, tmp_path, capsys):
    """--clock (cpu by default) is stored with the options: a folder certified on one clock is
    not resumed on the other, one written before the option existed counts as wall; a wrong
    clock is refused (Python: ValueError; command line: exit 2)."""
    from rigidlcp.verify.certificates.run import OPTIONS

    path, _ = run_file
    out = tmp_path / "cert"
    certify_run(path, out, events=[0], clock="wall")
    assert json.loads((out / OPTIONS).read_text())["clock"] == "wall"
    with pytest.raises(InvalidInput, match="other options"):
        certify_run(path, out, events=[0, 1], resume=True)  # cpu, the default
    res = certify_run(path, out, events=[0, 1], resume=True, clock="wall")
    assert res.skipped == 1 and res.ran == 1
    old = json.loads((out / OPTIONS).read_text())
    del old["clock"]
    (out / OPTIONS).write_text(json.dumps(old))
    assert certify_run(path, out, events=[0, 1], resume=True, clock="wall").skipped == 2
    with pytest.raises(ValueError, match="clock"):
        certify_run(path, tmp_path / "o2", events=[0], clock="gpu")
    with pytest.raises(SystemExit) as exc:  # argparse: usage line and the error, exit 2
        main(["certify-run", str(path), "--out", str(tmp_path / "o3"), "--clock", "gpu"])
    assert exc.value.code == 2
    assert "--clock" in capsys.readouterr().err
    assert not (tmp_path / "o2").exists() and not (tmp_path / "o3").exists()
