"""`rigidlcp forceset --jobs N`: the range LPs in N worker processes give the ranges of one
process; a bad N is refused in one line, leaving nothing behind."""

import json

import numpy as np

from rigidlcp.cli.main import main


def _ends(d: dict) -> np.ndarray:
    return np.array([[np.inf if v is None else v for v in c["R"] + c["S"]]
                     for c in d["contacts"]], dtype=float)


def test_forceset_jobs_two_gives_the_ranges_of_one(tmp_path, capsys):
    f = tmp_path / "pile.csv"
    assert main(["pack", "--n", "12", "--seed", "1", "--radii", "0.8:1.2", "--out",
                 str(f)]) == 0
    capsys.readouterr()
    runs = []
    for jobs in ("1", "2"):
        assert main(["forceset", str(f), "--mu-pp", "0.5", "--mu-plane", "0.5", "--mu-wall",
                     "0.5", "--jobs", jobs, "--json"]) == 0
        runs.append(json.loads(capsys.readouterr().out))
    one, two = runs
    assert one["exists"] is True and two["exists"] is True
    assert [(c["i"], c["j"]) for c in one["contacts"]] == [(c["i"], c["j"])
                                                           for c in two["contacts"]]
    a, b = _ends(one), _ends(two)
    assert np.array_equal(np.isinf(a), np.isinf(b))
    fin = np.isfinite(a)
    assert np.all(np.abs(a[fin] - b[fin]) <= 1e-7 * max(1.0, np.max(np.abs(a[fin]))))
    assert [c["can_slide"] for c in one["contacts"]] == [c["can_slide"]
                                                         for c in two["contacts"]]
    assert two["unchecked_optima"] == 0


def test_forceset_refuses_jobs_below_one(tmp_path, capsys):
    f = tmp_path / "p.csv"
    f.write_text("# box: left=0.0 right=4.0\nx,y,r\n1,1,1\n3,1,1\n2,2.7320508075688772,1\n")
    out = tmp_path / "o"
    assert main(["forceset", str(f), "--jobs", "0", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--jobs must be >= 1, got 0" in err and err.count("\n") == 1
    assert not out.exists()


def test_forceset_names_bad_jobs_before_reading_the_file(tmp_path, capsys):
    assert main(["forceset", str(tmp_path / "missing.csv"), "--jobs", "-1"]) == 2
    err = capsys.readouterr().err
    assert "--jobs must be >= 1, got -1" in err and err.count("\n") == 1


def test_forceset_names_the_disks_a_local_certificate_moves(tmp_path, capsys):
    """A disk on a frictionless disk at 60 degrees, no walls: both fall (a local certificate
    moving both, checked exactly); the text says so without 'the others held fixed'."""
    f = tmp_path / "fall.csv"
    f.write_text("x,y,r\n1,1,1\n2,2.7320508075688772,1\n")
    base = ["forceset", str(f), "--left", "none", "--right", "none", "--mu-pp", "0",
            "--mu-plane", "0"]
    assert main(base + ["--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["exists"] is False and d["farkas_exact"] is True and d["farkas_disks"] == [0, 1]
    assert main(base) == 0
    out = capsys.readouterr().out
    assert "it moves every disk (2)" in out and "held fixed" not in out
