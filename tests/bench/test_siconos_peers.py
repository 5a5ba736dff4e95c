"""Siconos's MLCP and 2D friction-contact solvers as bench peers (rigidlcp.bench.runners), and
the report's common SGM per kind of problem (rigidlcp.bench.report).

Without Siconos the runner is driven by a fake interpreter (a script that answers the helper's
protocol with the z it is told to), so that what the bench does with a Siconos answer (split
an MLCP's z = [u; v], certify an fc2d r, refuse a problem of another kind, survive a crash or
chatter on the pipe) is tested everywhere; with python3-siconos installed the real solvers run
on the small Siconos files of tests/data/siconos. No timing assertions."""

from __future__ import annotations

import json
import math
import stat
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from rigidlcp import lcp
from rigidlcp.bench.harness import (
    Result,
    SiconosRunner,
    available_methods,
    judge,
    read_csv,
    run_bench,
    write_csv,
)
from rigidlcp.bench.report import shifted_geometric_mean, summarize, summary_table

DATA = Path(__file__).resolve().parents[1] / "data" / "siconos"

FAKE = """#!{python}
# A stand-in for /usr/bin/python3 + the Siconos helper: answers every request with the z in
# the file $FAKE_Z (info 0: "solved"), logs the requests to $FAKE_LOG, prints chatter between
# answers (as Siconos's C code would on a shared stdout), exits on a request when the file
# $FAKE_DIE exists.
import json, os, sys
import numpy as np
kinds = os.environ["FAKE_KINDS"].split(",")
print(json.dumps({{"ready": True, "version": "fake", "kinds": kinds}}), flush=True)
for line in sys.stdin:
    req = json.loads(line)
    for key, value in list(req.items()):  # the arrays, as the helper would read them
        if isinstance(value, str) and value.endswith(".npy"):
            req[key + "_data"] = np.load(value).tolist()
    with open(os.environ["FAKE_LOG"], "a") as fh:
        fh.write(json.dumps(req) + "\\n")
    if os.path.exists(os.environ["FAKE_DIE"]):
        sys.exit(3)
    print("[Numerics] some chatter", flush=True)
    print(json.dumps({{"z": json.load(open(os.environ["FAKE_Z"])), "time": 1e-4, "iterations": 7,
                      "info": 0, "error": 0.0}}), flush=True)
"""


@pytest.fixture
def fake(tmp_path, monkeypatch):
    """A fake interpreter; returns (path, log path, setter of the answer z)."""
    path = tmp_path / "fake-python"
    path.write_text(FAKE.format(python=sys.executable))
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    log = tmp_path / "requests.jsonl"
    monkeypatch.setenv("FAKE_LOG", str(log))
    monkeypatch.setenv("FAKE_KINDS", "lcp,mlcp,fc2d")
    monkeypatch.setenv("FAKE_Z", str(tmp_path / "z.json"))
    monkeypatch.setenv("FAKE_DIE", str(tmp_path / "die"))

    def answer(z) -> None:
        (tmp_path / "z.json").write_text(json.dumps([float(x) for x in z]))

    return path, log, answer


def _requests(log: Path) -> list[dict]:
    return [json.loads(line) for line in log.read_text().splitlines()]


# A u + C v + a = 0, w = D u + B v + b: with v = 0, u = 1 and w = 2 > 0 (derived by hand).
MLCP = lcp.MLCP(A=[[2.0]], C=[[1.0]], D=[[1.0]], B=[[1.0]], a=[-2.0], b=[1.0], name="hand")


def test_an_mlcp_answer_is_split_into_u_and_v_and_certified(fake):
    python, log, answer = fake
    runner = SiconosRunner(python=str(python))
    try:
        assert runner.available and runner.offers("siconos-mlcp-fb")
        answer([1.0, 0.0])  # [u; v]: the solution
        raw = runner.solve(MLCP, "siconos-mlcp-fb", 10.0)
        np.testing.assert_array_equal(raw["u"], [1.0])
        np.testing.assert_array_equal(raw["z"], [0.0])
        r = judge(MLCP, "siconos-mlcp-fb", "s", raw, 10.0, 1e-8)
        assert r.outcome == "solved" and r.kind == "MLCP" and r.iterations == 7
        answer([0.0, 0.0])  # claimed "solved" (info 0) but A u + C v + a = -2
        r = judge(MLCP, "siconos-mlcp-fb", "s", runner.solve(MLCP, "siconos-mlcp-fb", 10.0),
                  10.0, 1e-8)
        assert r.outcome == "uncertified" and not r.success
    finally:
        runner.close()
    req = _requests(log)[0]
    assert req["kind"] == "mlcp" and req["solver"] == "fb" and req["nu"] == 1
    np.testing.assert_array_equal(req["q_data"], [-2.0, 1.0])  # Siconos's q = [a; b]
    assert req["M"].endswith(".npy")


@pytest.mark.parametrize("sparse", [False, True])
def test_a_friction_answer_is_certified_by_the_natural_map(fake, sparse):
    python, log, answer = fake
    # q_n = 1 > 0 at the single contact: r = 0 is the solution (the contact opens).
    W = np.array([[2.0, 0.5], [0.5, 1.0]])
    problem = lcp.FrictionContact2D(sp.csr_matrix(W) if sparse else W, [1.0, 0.3], [0.4])
    runner = SiconosRunner(python=str(python))
    try:
        answer([0.0, 0.0])
        ok = judge(problem, "siconos-fc2d-nsgs", "s",
                   runner.solve(problem, "siconos-fc2d-nsgs", 10.0), 10.0, 1e-8)
        answer([1.0, 0.0])  # pushes on an opening contact
        bad = judge(problem, "siconos-fc2d-lemke", "s",
                    runner.solve(problem, "siconos-fc2d-lemke", 10.0), 10.0, 1e-8)
    finally:
        runner.close()
    assert ok.outcome == "solved" and ok.kind == "FC2D"
    assert bad.outcome == "uncertified" and bad.scaled_residual > 1e-8
    first, second = _requests(log)
    assert first["solver"] == "nsgs" and first["tol"] == 1e-12 and first["max_iter"] == 10_000
    assert second["solver"] == "lemke" and second["tol"] is None
    np.testing.assert_array_equal(first["mu_data"], [0.4])
    if sparse:
        rebuilt = sp.coo_matrix((first["vals_data"], (first["rows_data"], first["cols_data"])),
                                shape=first["shape"]).toarray()
        np.testing.assert_array_equal(rebuilt, W)
        assert "W" not in first
    else:
        np.testing.assert_array_equal(first["W_data"], W)


def test_each_method_is_given_only_its_kind_and_size(fake):
    python, log, answer = fake
    runner = SiconosRunner(python=str(python))
    lcp_problem = lcp.LCP(np.eye(2), [-1.0, 1.0], name="p")
    big_fc = lcp.FrictionContact2D(np.eye(12), np.ones(12), 0.5)  # 6 contacts
    big_mlcp = lcp.MLCP(A=np.eye(1), C=np.zeros((1, 17)), D=np.zeros((17, 1)), B=np.eye(17),
                        a=[0.0], b=np.ones(17))
    try:
        cases = [(lcp_problem, "siconos-mlcp-fb", "MLCPs only"),
                 (lcp_problem, "siconos-fc2d-nsgs", "friction-contact problems only"),
                 (MLCP, "siconos-fc2d-lemke", "friction-contact problems only"),
                 (big_fc, "siconos-lemke", "LCPs and Schur-reducible MLCPs only"),
                 (big_fc, "siconos-fc2d-enum", "c (contacts) <= 5"),
                 (big_mlcp, "siconos-mlcp-enum", "m <= 16"),
                 (big_mlcp, "siconos-mlcp-direct-enum", "m <= 16")]
        for problem, method, why in cases:
            raw = runner.solve(problem, method, 10.0)
            assert raw["kind"] == "not_applicable" and why in raw["message"], (method, raw)
        assert not log.exists()  # nothing was sent to the helper
        answer(np.zeros(18))
        assert runner.solve(big_mlcp, "siconos-mlcp-fb", 10.0)["kind"] == "answer"
    finally:
        runner.close()


def test_a_siconos_without_a_kind_of_solvers_is_reported(fake, monkeypatch):
    python, _, _ = fake
    monkeypatch.setenv("FAKE_KINDS", "lcp")
    runner = SiconosRunner(python=str(python))
    try:
        assert runner.available and runner.offers("siconos-lemke")
        assert not runner.offers("siconos-mlcp-enum") and not runner.offers("siconos-fc2d-nsgs")
        names = available_methods(runner)
        assert "siconos-pgs" in names and not any(m.startswith("siconos-fc2d") for m in names)
        with pytest.raises(ValueError, match="mlcp solvers"):
            run_bench({"s": [MLCP]}, ["siconos-mlcp-fb"], siconos=runner)
    finally:
        runner.close()


def test_a_crashed_helper_is_an_error_and_is_restarted(fake, tmp_path):
    python, log, answer = fake
    runner = SiconosRunner(python=str(python))
    try:
        (tmp_path / "die").write_text("")
        raw = runner.solve(MLCP, "siconos-mlcp-enum", 10.0)
        assert raw["kind"] == "error" and "died" in raw["message"]
        (tmp_path / "die").unlink()
        answer([1.0, 0.0])
        assert runner.solve(MLCP, "siconos-mlcp-enum", 10.0)["status"] == "solved"
    finally:
        runner.close()


def test_siconos_absent_offers_nothing():
    runner = SiconosRunner(python="/nonexistent/python3")
    try:
        assert not runner.available and not runner.offers("siconos-mlcp-fb")
        assert not any(m.startswith("siconos") for m in available_methods(runner))
        with pytest.raises(ValueError, match="needs Siconos"):
            run_bench({"s": [MLCP]}, ["siconos-mlcp-fb"], siconos=runner)
    finally:
        runner.close()


def test_siconos_mlcp_and_friction_solvers_when_available():
    runner = SiconosRunner()
    if not (runner.available and runner.offers("siconos-mlcp-enum")
            and runner.offers("siconos-fc2d-lemke")):
        runner.close()
        pytest.skip(f"Siconos's MLCP / fc2d solvers unavailable: {runner.reason}")
    problems = [lcp.load(DATA / name) for name in
                ("diodeBridge_mlcp.dat", "m2n1_mlcp.dat", "FrictionContactProblem00031.dat",
                 "FC2D_SliderCrankLagrangian00000.dat")]
    methods = ["siconos-mlcp-enum", "siconos-mlcp-direct-enum", "siconos-mlcp-fb",
               "siconos-fc2d-lemke", "siconos-fc2d-enum"]
    try:
        results = run_bench({"s": problems}, methods, siconos=runner, time_limit=30)
    finally:
        runner.close()
    got = {(r.problem.split("/")[-1], r.method): r for r in results}
    for name in ("diodeBridge_mlcp", "m2n1_mlcp"):  # diodeBridge: A singular
        for m in methods[:3]:
            assert got[(name, m)].outcome == "solved", got[(name, m)]
        assert got[(name, "siconos-fc2d-lemke")].outcome == "not_applicable"
    for name in ("FrictionContactProblem00031", "FC2D_SliderCrankLagrangian00000"):
        r = got[(name, "siconos-fc2d-lemke")]
        assert r.outcome == "solved", r
        assert got[(name, "siconos-mlcp-fb")].outcome == "not_applicable"
    assert got[("FC2D_SliderCrankLagrangian00000", "siconos-fc2d-enum")].outcome == "solved"
    assert got[("FrictionContactProblem00031", "siconos-fc2d-enum")].outcome == "not_applicable"
    # every claimed success passed the harness's own check
    assert all(r.scaled_residual <= 1e-8 for r in results if r.outcome == "solved")


# --- the common SGM per kind ----------------------------------------------------------------

def _r(problem, method, kind, t, outcome="solved"):
    ok = outcome == "solved"
    return Result(set="s", problem=problem, n=2, method=method, outcome=outcome, success=ok,
                  status=outcome, time=t if ok else 0.0, iterations=1, residual=0.0,
                  scaled_residual=0.0 if ok else math.nan, expected="solution", kind=kind)


def test_the_common_sgm_is_taken_per_kind_over_the_problems_all_its_methods_accept():
    NA = "not_applicable"
    results = [
        # LCPs: "a" and "b" accept both, "c" refuses p2, "f" (friction only) refuses both.
        _r("p1", "a", "LCP", 0.001), _r("p2", "a", "LCP", 0.004),
        _r("p1", "b", "LCP", 0.002), _r("p2", "b", "LCP", 0.0, "max_iter"),
        _r("p1", "c", "LCP", 0.003), _r("p2", "c", "LCP", 0.0, NA),
        _r("p1", "f", "LCP", 0.0, NA), _r("p2", "f", "LCP", 0.0, NA),
        # friction problems: "a" and "f" accept both, "b" and "c" refuse both.
        _r("g1", "a", "FC2D", 0.010), _r("g2", "a", "FC2D", 0.020),
        _r("g1", "f", "FC2D", 0.030), _r("g2", "f", "FC2D", 0.040),
        _r("g1", "b", "FC2D", 0.0, NA), _r("g2", "b", "FC2D", 0.0, NA),
        _r("g1", "c", "FC2D", 0.0, NA), _r("g2", "c", "FC2D", 0.0, NA),
    ]
    by = {s.method: s for s in summarize(results, time_limit=5.0)}
    assert by["a"].common == {"LCP": 1, "FC2D": 2}  # LCP: p1 only (c refused p2)
    sgm = shifted_geometric_mean
    assert by["a"].sgm_common["LCP"] == pytest.approx(sgm([0.001]))
    assert by["b"].sgm_common["LCP"] == pytest.approx(sgm([0.002]))  # its failure is on p2
    assert by["c"].sgm_common["LCP"] == pytest.approx(sgm([0.003]))
    assert "LCP" not in by["f"].sgm_common  # refuses every LCP: not compared on them
    assert by["a"].sgm_common["FC2D"] == pytest.approx(sgm([0.010, 0.020]))
    assert by["f"].sgm_common["FC2D"] == pytest.approx(sgm([0.030, 0.040]))
    assert "FC2D" not in by["b"].sgm_common and "FC2D" not in by["c"].sgm_common
    table = summary_table(list(by.values()))
    assert "SGM time, common LCP (1)" in table[0] and "SGM time, common FC2D (2)" in table[0]
    assert table[0].index("common LCP") < table[0].index("common FC2D")
    row_f = next(line for line in table if line.startswith("| f |"))
    assert row_f.split("|")[5].strip() == "-"  # f's LCP cell
    # a failure on a common problem counts at the time limit
    results.append(_r("p3", "a", "LCP", 0.0, "timeout"))
    results += [_r("p3", m, "LCP", 0.001) for m in "bc"] + [_r("p3", "f", "LCP", 0.0, NA)]
    by = {s.method: s for s in summarize(results, time_limit=5.0)}
    assert by["a"].sgm_common["LCP"] == pytest.approx(sgm([0.001, 5.0]))


def test_a_method_taking_few_problems_of_a_kind_does_not_decide_the_common_subset():
    """Fig. 9's event LCPs: pgs takes 1 of the 74 and the common subset was that one problem.
    A method that accepts fewer than half of a kind's problems is left out of the comparison
    ('-' in the column) instead; a method that accepts exactly half is compared."""
    NA = "not_applicable"
    results = []
    for k in range(4):
        results += [_r(f"p{k}", "a", "LCP", 0.001 * (k + 1)),
                    _r(f"p{k}", "b", "LCP", 0.002 * (k + 1)),
                    _r(f"p{k}", "narrow", "LCP", 0.5 if k == 0 else 0.0,
                       "solved" if k == 0 else NA),
                    _r(f"p{k}", "half", "LCP", 0.003 if k < 2 else 0.0,
                       "solved" if k < 2 else NA)]
    by = {s.method: s for s in summarize(results, time_limit=5.0)}
    # narrow (1 of 4) is out; half (2 of 4) is in, so the common problems are p0 and p1
    assert by["a"].common == {"LCP": 2}
    assert "LCP" not in by["narrow"].sgm_common
    sgm = shifted_geometric_mean
    assert by["a"].sgm_common["LCP"] == pytest.approx(sgm([0.001, 0.002]))
    assert by["half"].sgm_common["LCP"] == pytest.approx(sgm([0.003, 0.003]))
    table = summary_table(list(by.values()))
    assert "SGM time, common LCP (2)" in table[0]
    row = next(line for line in table if line.startswith("| narrow |"))
    assert row.split("|")[5].strip() == "-" and row.split("|")[4].strip() == "500 ms"
    # without "half", the common subset is every problem a and b take
    by = {s.method: s for s in summarize([r for r in results if r.method != "half"], 5.0)}
    assert by["b"].common == {"LCP": 4}
    assert by["b"].sgm_common["LCP"] == pytest.approx(sgm([0.002, 0.004, 0.006, 0.008]))


def test_the_kind_survives_the_csv(tmp_path):
    rows = [_r("p1", "a", "MLCP", 0.001), _r("g1", "a", "FC2D", 0.002)]
    back = read_csv(write_csv(rows, tmp_path / "r.csv"))
    assert [r.kind for r in back] == ["MLCP", "FC2D"]
    # a results.csv of an older run, without the column, still reads (kind unknown)
    text = (tmp_path / "r.csv").read_text().splitlines()
    at = text[0].split(",").index("kind")
    old = [",".join(c for k, c in enumerate(line.split(",")) if k != at) for line in text]
    (tmp_path / "old.csv").write_text("\n".join(old) + "\n")
    assert [r.kind for r in read_csv(tmp_path / "old.csv")] == ["", ""]
