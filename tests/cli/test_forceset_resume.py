"""`rigidlcp forceset` on large piles: progress on every long phase (stderr only, the JSON on
stdout unchanged; --no-progress honoured) and a resumable --out (DIR/forceset.ends, read back by
--resume: the ends settled before an interruption are not computed again)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rigidlcp.cli import forceset_resume
from rigidlcp.cli.main import main

MU = ["--mu-pp", "0.3", "--mu-plane", "0.3", "--mu-wall", "0.3"]


@pytest.fixture(scope="module")
def pile(tmp_path_factory):
    """docs/packings.md's 100-disk pile: at mu = 0.3 a 100-dimensional set of forces, 200
    contacts (the bars' threshold)."""
    f = tmp_path_factory.mktemp("pile") / "p100.csv"
    assert main(["pack", "--n", "100", "--seed", "2", "--radii", "0.8:1.2", "--out",
                 str(f)]) == 0
    return f


def _json(out: str) -> str:
    """The JSON line of stdout (HiGHS may print its banner once per process before it)."""
    return [line for line in out.splitlines() if line.startswith("{")][-1]


def _ends(d: dict) -> np.ndarray:
    return np.array([[np.inf if v is None else v for v in c["R"] + c["S"]]
                     for c in d["contacts"]], dtype=float)


def test_progress_on_stderr_json_unchanged(pile, tmp_path, capsys):
    """From 1000 disks every phase is named on stderr as it starts; the JSON on stdout is the
    same with or without it; --no-progress shows nothing. (A smaller pile's phases end within
    a second: only the range ends' bar, from 200 contacts.)"""
    big = tmp_path / "p1000.csv"
    assert main(["pack", "--n", "1000", "--seed", "1", "--radii", "0.8:1.2", "--out",
                 str(big)]) == 0
    for f, options in ((big, ["--no-ranges", "--mu-pp", "0.5", "--mu-plane", "0.5",
                              "--mu-wall", "0.5"]), (pile, MU)):
        capsys.readouterr()
        assert main(["forceset", str(f), *options, "--json", "--no-progress"]) == 0
        quiet = capsys.readouterr()
        assert quiet.err == ""
        assert main(["forceset", str(f), *options, "--json"]) == 0
        shown = capsys.readouterr()
        # the JSON, the same; but rank_gap, an ARPACK estimate from a random start, differs in
        # its last bits between two runs of the same command (with or without progress)
        a, b = json.loads(_json(quiet.out)), json.loads(_json(shown.out))
        a.pop("rank_gap", None), b.pop("rank_gap", None)
        assert a == b and a["exists"] is True
        if f == big:
            for phase in ("existence: local certificates in windows",
                          "existence: interior point (analytic centre)",
                          "implicit equalities", "dimension (rank of the balance)"):
                assert phase in shown.err, phase
        else:
            assert "existence" not in shown.err and "force range ends" in shown.err


def test_interrupted_out_resumes(pile, tmp_path, capsys, monkeypatch):
    """Interrupted after 300 ends (a Ctrl-C raised from the journal), the run says how to
    resume and exits 130; --resume reads the 300 ends back, computes only the others (fewer
    LPs) and gives the ranges of an uninterrupted run; the journal is gone after."""
    whole = tmp_path / "whole"
    assert main(["forceset", str(pile), *MU, "--no-progress", "--out", str(whole)]) == 0
    want = json.loads((whole / "forceset.json").read_text())
    assert not (whole / forceset_resume.JOURNAL).exists()
    real = forceset_resume.Journal.__call__

    def interrupt(self, k, side, value):
        real(self, k, side, value)
        if self.count == 300:
            raise KeyboardInterrupt

    monkeypatch.setattr(forceset_resume.Journal, "__call__", interrupt)
    out = tmp_path / "cut"
    capsys.readouterr()
    assert main(["forceset", str(pile), *MU, "--no-progress", "--out", str(out)]) == 130
    err = capsys.readouterr().err
    assert "300 range ends saved" in err and "--resume" in err
    journal = out / forceset_resume.JOURNAL
    lines = journal.read_text().splitlines()
    assert len(lines) == 301 and not (out / "forceset.json").exists()
    saved = {(int(k), s): float(v) for k, s, v in (ln.split() for ln in lines[1:])}
    monkeypatch.setattr(forceset_resume.Journal, "__call__", real)
    # another folder's run, or other coefficients, is refused in one line
    assert main(["forceset", str(pile), "--no-progress", "--out", str(out), "--resume"]) == 2
    assert "not this packing's journal" in capsys.readouterr().err
    assert main(["forceset", str(pile), *MU, "--no-progress", "--out", str(out)]) == 2
    assert "--resume continues it" in capsys.readouterr().err
    assert main(["forceset", str(pile), *MU, "--no-progress", "--out", str(out),
                 "--resume"]) == 0
    got = json.loads((out / "forceset.json").read_text())
    assert not journal.exists()
    assert got["exists"] and got["dimension"] == want["dimension"]
    a, b = _ends(want), _ends(got)
    assert np.array_equal(np.isinf(a), np.isinf(b))
    fin = np.isfinite(a)
    assert np.all(np.abs(a[fin] - b[fin]) <= 1e-7 * max(1.0, np.max(np.abs(a[fin]))))
    c = got["c"]
    for (k, side), v in saved.items():  # the saved ends are the resumed run's, as saved
        entry = got["contacts"][k % c]["R" if k < c else "S"][0 if side == "min" else 1]
        assert (np.inf if entry is None else entry) == abs(v) or entry == v
    assert got["lps"] < want["lps"]
    assert [x["can_slide"] for x in got["contacts"]] == [x["can_slide"]
                                                         for x in want["contacts"]]


def test_resume_refusals(pile, tmp_path, capsys):
    assert main(["forceset", str(pile), "--resume"]) == 2
    assert "give --out" in capsys.readouterr().err
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["forceset", str(pile), "--out", str(empty), "--resume"]) == 2
    assert "nothing to resume" in capsys.readouterr().err
    assert main(["forceset", str(pile), "--out", str(empty), "--resume", "--force"]) == 2
    assert "give one" in capsys.readouterr().err
