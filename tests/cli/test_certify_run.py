"""Certifying a whole run (verify.certificates.run and `rigidlcp certify-run`): rows, totals,
resume, never overwriting, parallel events."""

from __future__ import annotations

import json

import pytest

from rigidlcp import models
from rigidlcp.cli import main
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
    with pytest.raises(ValueError, match="--resume"):
        certify_run(path, out, events=[0])
    with pytest.raises(ValueError, match="other options"):
        certify_run(path, out, resume=True, time_limit=3.0)
    res = certify_run(path, out, events=[0, 1], force=True)
    assert res.skipped == 0 and res.ran == 2
    with pytest.raises(ValueError, match="out of range"):
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
