"""rigidlcp.bench.fuzz: the harness runs, judges, refuses bad arguments, and every case it
ever saved (tests/data/fuzz/*.npz: silent-wrong or crashing answers of earlier code) is now
answered honestly by the method that failed on it."""

from __future__ import annotations

from pathlib import Path

import pytest

from rigidlcp import lcp
from rigidlcp.bench.fuzz import judge, main, run_case, run_fuzz
from rigidlcp.bench.fuzz_cases import CLASSES, Case, make_case

DATA = Path(__file__).parent.parent / "data" / "fuzz"
SAVED = sorted(DATA.glob("*.npz"))


def test_a_small_fuzz_run_has_no_silent_wrong_answer_and_no_crash():
    result = run_fuzz(2 * len(CLASSES), seed=0)
    assert {kind for kind, _ in result["table"]} == set(CLASSES)
    for key, cell in result["table"].items():
        assert cell["WRONG"] == 0 and cell["crash"] == 0, key


@pytest.mark.parametrize("path", SAVED, ids=[p.stem for p in SAVED])
def test_saved_fuzz_cases_are_answered_honestly(path):
    P = lcp.load(path)
    meta = P.meta
    case = Case(meta["class"], int(meta["seed"]), P.M, P.q,
                p_matrix=bool(meta["p_matrix"]), solvable=meta["solvable"])
    res = run_case(case, meta["method"])
    assert res["outcome"] not in ("WRONG", "crash"), res


def test_generated_facts_hold():
    """What the judge relies on: planted solutions solve, Farkas vectors certify."""
    import numpy as np

    for seed in range(5):
        c = make_case("infeasible", seed)
        assert float(c.q @ c.farkas) < 0
        assert np.max(c.M.T @ c.farkas) < 0
        for kind in ("PSD", "singular-PSD", "degenerate"):
            c = make_case(kind, seed)
            assert judge(c, "solved", c.planted)[0] == "solved"


def test_the_judge_calls_a_false_infeasible_wrong():
    c = make_case("P", 0)
    assert judge(c, "infeasible", c.q * 0)[0] == "WRONG"


@pytest.mark.parametrize("entry", ["module", "cli"])
def test_bad_arguments_exit_2(tmp_path, capsys, entry):
    from rigidlcp.cli.main import main as cli

    run = main if entry == "module" else (lambda argv: cli(["fuzz", *argv]))
    assert run(["--count", "1", "--out", str(tmp_path)]) == 2  # exists: never overwritten
    assert run(["--classes", "nope"]) == 2
    assert run(["--files", str(tmp_path / "missing.dat")]) == 2
    assert run(["--methods", "nope"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 4 and "Traceback" not in err


def test_the_cli_runs_and_saves_nothing_when_all_is_well(tmp_path, capsys):
    from rigidlcp.cli.main import main as cli

    out = tmp_path / "fuzz"
    assert cli(["fuzz", "--count", "3", "--seed", "5", "--methods", "lemke,pivoting",
                "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "| P | lemke | 1 |" in text and "0 silent-wrong" in text
    assert not out.exists() or not any(out.iterdir())


def test_files_of_every_kind_are_judged_and_a_non_square_mlcp_is_refused():
    """rigidlcp fuzz --files: LCP and MLCP files, each answer judged on the problem as given
    (rigidlcp.bench.fuzz_files); the non-square MLCP is a refused row, never a crash."""
    from rigidlcp.bench.fuzz_files import run_files

    siconos = Path(__file__).parent.parent / "data" / "siconos"
    files = [siconos / n for n in ("lcp_CPS_1.dat", "m2n1_mlcp.dat", "diodeBridge_mlcp.dat",
                                   "Rectangular_mlcp.dat")]
    result = run_files(files, methods=("lemke", "pivoting", "newton-min", "enumerate"))
    table = result["table"]
    for key, cell in table.items():
        assert cell["WRONG"] == 0 and cell["crash"] == 0, key
    assert table[("m2n1_mlcp", "lemke")]["solved"] == 1
    assert table[("diodeBridge_mlcp", "newton-min")]["solved"] == 1  # A singular: full system
    assert table[("Rectangular_mlcp", "lemke")]["refused"] == 1
    assert "rectangular" in table[("Rectangular_mlcp", "reader")]["reason"]


def test_a_wrong_mlcp_answer_is_judged_wrong():
    """The MLCP judge does not trust a status: a perturbed answer is SILENT WRONG."""
    import numpy as np

    from rigidlcp.bench.fuzz_files import judge_mlcp

    P = lcp.load(Path(__file__).parent.parent / "data" / "siconos" / "m2n1_mlcp.dat")
    sol = lcp.solve(P, "lemke")
    assert judge_mlcp(P, sol.status, sol.u, sol.z) == ("solved", "")
    outcome, reason = judge_mlcp(P, "solved", sol.u + 0.1, sol.z)
    assert outcome == "WRONG" and "eq" in reason
    assert judge_mlcp(P, "infeasible", None, np.zeros(P.n))[0] == "WRONG"  # it has a solution


def test_batched_lemke_judged_as_one_by_one(monkeypatch):
    """run_fuzz solves lemke's cases CHUNK at a time with lcp.solve_many: the table's outcomes
    are those of one lcp.solve per case."""
    import rigidlcp.bench.fuzz as fuzz

    count = 3 * len(CLASSES)
    monkeypatch.setattr(fuzz, "CHUNK", 5)  # several chunks, one partial
    batched = run_fuzz(count, seed=3, methods=("lemke",))
    monkeypatch.setattr(fuzz, "COMPILED_BATCH", ())
    single = run_fuzz(count, seed=3, methods=("lemke",))
    strip = {k: {o: v for o, v in cell.items() if o != "seconds"}
             for k, cell in batched["table"].items()}
    assert strip == {k: {o: v for o, v in cell.items() if o != "seconds"}
                     for k, cell in single["table"].items()}


def test_progress_by_default_on_stderr_and_none_with_no_progress(monkeypatch, capsys):
    """Without --progress K, a one-line count goes to stderr every PROGRESS_SECONDS (here 0:
    after every problem but the last); --no-progress silences it; stdout is the table."""
    from rigidlcp.bench import fuzz
    from rigidlcp.cli.main import main as cli

    monkeypatch.setattr(fuzz, "PROGRESS_SECONDS", 0.0)
    args = ["fuzz", "--count", "3", "--seed", "5", "--methods", "lemke"]
    assert cli(args) == 0
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert [line.split(",")[0] for line in lines] == ["fuzz: 1 of 3 problems",
                                                     "fuzz: 2 of 3 problems"]
    assert "0 silent-wrong or crashing so far" in lines[0]
    assert "fuzz:" not in captured.out and "| P | lemke |" in captured.out
    assert cli(args + ["--no-progress"]) == 0
    assert capsys.readouterr().err == ""


def test_files_the_reader_refuses_are_named_with_the_reason(tmp_path, capsys):
    """fuzz --files printed only 'refused' for a file no method could be given (a packing
    CSV, a friction-contact file): the reason is now printed below the table."""
    from rigidlcp.cli.main import main as cli

    siconos = Path(__file__).parent.parent / "data" / "siconos"
    csv = tmp_path / "pile.csv"
    csv.write_text("x,y,r\n1,1,1\n")
    assert cli(["fuzz", "--files", str(csv), str(siconos / "FrictionContactProblem00031.dat"),
                str(siconos / "lcp_CPS_1.dat"), "--methods", "lemke"]) == 0
    out = capsys.readouterr().out
    assert f"refused by the reader: {csv}, line 1: no Siconos header fits" in out
    assert "FrictionContactProblem00031.dat: a FrictionContact2D, not an LCP or MLCP" in out
    assert "| lcp_CPS_1 | lemke | 1 |" in out


def test_a_trailing_comma_in_methods_is_ignored_as_in_classes(capsys):
    from rigidlcp.cli.main import main as cli

    assert cli(["fuzz", "--count", "2", "--classes", "P,", "--methods", "lemke,",
                "--no-progress"]) == 0
    assert "| P | lemke | 2 |" in capsys.readouterr().out
