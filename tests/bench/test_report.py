"""report.md of `rigidlcp bench` (issue 23, point 4): its sections on a tiny set with a lying
method, a refusing method and peers, every peer judged by the harness's own check, refusals
never timed, success at stated accuracies, resumable runs, and bad input (one line, exit 2,
nothing left behind). No timing assertions."""

from __future__ import annotations

import csv
import math
import subprocess
import sys

import numpy as np
import pytest

from rigidlcp import lcp
from rigidlcp.bench import peers
from rigidlcp.bench.harness import Result, read_csv, run_bench
from rigidlcp.bench.peers import PEERS, Peer
from rigidlcp.bench.problem_sets import get_set
from rigidlcp.bench.report import at_accuracy, summarize, summary_table
from rigidlcp.bench.report_md import disagreements, solved_by_nobody, write_report
from rigidlcp.cli.main import main as cli_main
from rigidlcp.lcp.api import _REGISTRY


# Test doubles at module level (the bench's worker receives them by reference).
def lying(M, q):
    """Claims z = 1 solves everything."""
    z = np.ones(q.size)
    return lcp.Solution(z=z, w=M @ z + q, status="solved", method="test-lying")


def refusing(M, q):
    raise lcp.NotApplicable("test-refusing takes no problem")


def fake_peer_false_success(M, q):
    """A peer that says "solved" with z = 1 (as Siconos's direct lcp_lexicolemke does with
    points that are not solutions)."""
    return np.ones(q.size), "solved", 7, "fake: success"


def fake_peer_ray(M, q):
    """A peer that claims no solution exists, whatever the problem."""
    return None, "ray", 1, "fake: secondary ray"


@pytest.fixture
def doubles(monkeypatch):
    lcp.register("test-lying", accepts="any", description="claims z = 1 solves")(lying)
    lcp.register("test-refusing", accepts="any", description="refuses")(refusing)
    monkeypatch.setitem(PEERS, "fake-liar", Peer("numpy", "numpy", fake_peer_false_success,
                                                 "says solved with z = 1"))
    monkeypatch.setitem(PEERS, "fake-ray", Peer("numpy", "numpy", fake_peer_ray,
                                                "says no solution"))
    yield
    for name in ("test-lying", "test-refusing"):
        _REGISTRY.pop(name, None)


def tiny_sets():
    return {"random-p": get_set("random-p", sizes=(3,), per_size=2),
            "infeasible": get_set("infeasible", sizes=(3,), per_size=1)}


def test_the_report_of_a_lying_and_a_refusing_method_and_two_fake_peers(doubles, tmp_path):
    sets = tiny_sets()
    methods = ["lemke", "test-lying", "test-refusing", "fake-liar", "fake-ray"]
    results = run_bench(sets, methods, time_limit=30)
    by = {(r.problem, r.method): r for r in results}
    p_names = [p.name for p in sets["random-p"]]
    inf_name = sets["infeasible"][0].name
    # the lying registered method: its own answer, reported failed (lcp.solve's check)
    assert all(not by[(p, "test-lying")].success for p in p_names)
    # the refusing method: counted apart and never timed
    refused = [r for r in results if r.method == "test-refusing"]
    assert all(r.outcome == "not_applicable" and r.time == 0.0 for r in refused)
    # the fake peer's "solved" is judged by the project's check: a false success
    assert all(by[(p, "fake-liar")].outcome == "uncertified" for p in p_names)
    assert by[(p_names[0], "fake-liar")].status == "solved"
    # a peer's secondary ray: proved infeasible on the infeasible problem; elsewhere a failure
    # that claims nothing (outcome "ray", not "unproved_infeasible")
    assert by[(inf_name, "fake-ray")].outcome == "infeasible"
    assert all(by[(p, "fake-ray")].outcome == "ray" and not by[(p, "fake-ray")].success
               for p in p_names)

    s = {x.method: x for x in summarize(results, time_limit=30)}
    assert s["test-refusing"].refused == 3 and math.isnan(s["test-refusing"].sgm_time)
    row = next(line for line in summary_table(list(s.values()))
               if line.startswith("| test-refusing |"))
    assert row.split("|")[4].strip() == "-"  # refusals are not timed: no "30 s"
    assert s["lemke"].at_accuracy[1e-8][0] == 3 and s["fake-liar"].at_accuracy[1e-8][0] == 0

    rerun = lambda r: f"rigidlcp bench --problems {r.problem} --methods {r.method}"  # noqa: E731
    report = write_report(results, tmp_path, time_limit=30, tol=1e-8, set_info={},
                          environment=[("CPU", "test")], rerun=rerun,
                          warmups={"lemke": [0.001]}).read_text()
    for heading in ("## Environment", "## All sets", "## Solved by nobody",
                    "## Methods disagree", "## False claims", "## Failures by problem",
                    "## Results per problem", "### random-p"):
        assert heading in report
    nobody = report.split("## Solved by nobody")[1].split("##")[0]
    assert "None" in nobody  # lemke solves each
    disagree = report.split("## Methods disagree")[1].split("##")[0]
    assert "fake-ray" not in disagree  # a ray beside lemke's solution: no claim, no dispute
    false = report.split("## False claims")[1].split("##")[0]
    assert f"fake-liar on `{p_names[0]}`: uncertified (claimed solved" in false
    assert "fake-ray" not in false
    failures = report.split("## Failures by problem")[1].split("## Results")[0]
    assert f"rerun: `rigidlcp bench --problems {p_names[0]} --methods test-lying`" in failures
    assert "test-refusing" not in failures  # a refusal is not a failure
    assert "Warm-up" in report and "lemke 1 ms" in report
    assert (tmp_path / "profile_LCP.png").read_bytes()[:4] == b"\x89PNG"
    assert not (tmp_path / "profile_MLCP.png").exists()  # no MLCP in the set


def test_a_fake_peer_in_the_worker_process_is_judged_too(doubles):
    """The peer runs in the bench's worker (forkserver/spawn): sent by reference."""
    results = run_bench({"random-p": get_set("random-p", sizes=(3,), per_size=1)},
                        ["fake-liar"], time_limit=30, isolate=True)
    assert [r.outcome for r in results] == ["uncertified"]
    assert results[0].iterations == 7 and results[0].message == "fake: success"


def _r(problem, method, outcome, scaled=1e-14, forward=math.nan, status=None):
    ok = outcome in ("solved", "infeasible")
    return Result(set="s", problem=problem, n=3, method=method, outcome=outcome, success=ok,
                  status=status or outcome, time=0.001, iterations=1, residual=scaled,
                  scaled_residual=scaled, expected="solution", kind="LCP",
                  forward_error=forward)


def test_sections_from_hand_made_results():
    results = [_r("a", "m", "solved"), _r("a", "k", "unproved_infeasible", status="infeasible"),
               _r("b", "m", "timeout", math.nan), _r("b", "k", "max_iter", math.nan),
               _r("c", "m", "solved"), _r("c", "k", "solved"),
               _r("d", "m", "solved"), _r("d", "k", "ray")]
    assert [key for key, _ in solved_by_nobody(results)] == [("s", "b")]
    (key, text), = disagreements(results)  # d: a ray beside a solution claims nothing
    assert key == ("s", "a") and "m" in text and "k (infeasible)" in text
    assert "claimed no solution" in text


def test_success_at_stated_accuracies_backward_and_forward():
    coarse = _r("a", "m", "solved", scaled=1e-10, forward=1e-3)
    fine = _r("b", "m", "solved", scaled=1e-15, forward=1e-13)
    proved = _r("c", "m", "infeasible", scaled=math.nan)
    assert at_accuracy(coarse, 1e-8) and not at_accuracy(coarse, 1e-12)
    assert not at_accuracy(coarse, 1e-8, forward=True)
    assert at_accuracy(fine, 1e-12) and at_accuracy(fine, 1e-12, forward=True)
    assert at_accuracy(proved, 1e-12) and at_accuracy(proved, 1e-12, forward=True)
    s, = summarize([coarse, fine, proved], time_limit=1.0)
    assert s.at_accuracy == {1e-8: (3, 2), 1e-12: (2, 2)}
    s, = summarize([_r("a", "m", "solved")], time_limit=1.0)
    assert s.at_accuracy[1e-8] == (1, None)  # no forward bound reported: "n/a"
    # where the check reports a backward error (one that an inflated z cannot meet), it is
    # the one judged, not the scaled residual
    inflated = _r("d", "m", "solved", scaled=5e-14)
    inflated.backward_error = 1e-2
    assert not at_accuracy(inflated, 1e-8)
    assert "1 / n/a" in summary_table([s])[2]


def test_absent_peers_are_skipped_with_a_note(monkeypatch, tmp_path, capsys):
    monkeypatch.setitem(PEERS, "absent-peer", Peer("no-such-dist", "no_such_module_xyz",
                                                   fake_peer_ray, "not installed"))
    ok, why = peers.peer_available("absent-peer")
    assert not ok and "not installed" in why
    out = tmp_path / "o"
    code = cli_main(["bench", "--set", "random-p", "--sizes", "3", "--per-size", "1",
                     "--methods", "lemke,absent-peer", "--out", str(out), "--no-siconos",
                     "--quiet", "--no-isolation"])
    assert code == 0
    assert "skipped absent-peer" in (out / "report.md").read_text()
    assert {r.method for r in read_csv(out / "results.csv")} == {"lemke"}


def test_installed_peers_run_and_are_judged():
    """Each real peer that is installed (pip install -e ".[peers]") runs on small P-matrix
    LCPs; its answers are judged by the same check (skipped when none is installed)."""
    available = [m for m in ("quantecon-lemke", "drake-moby", "drake-unrevised-lemke")
                 if peers.peer_available(m)[0]]
    if not available:
        pytest.skip("no peer installed (pip install -e \".[peers]\")")
    results = run_bench({"random-p": get_set("random-p", sizes=(4,), per_size=2)},
                        available, time_limit=60)
    for r in results:  # a P-matrix LCP has a solution: these Lemke codes find it
        assert r.outcome == "solved", (r.method, r.outcome, r.message)


def test_resume_keeps_the_rows_done_and_runs_the_rest(tmp_path, capsys):
    out = tmp_path / "o"
    args = ["bench", "--set", "random-p", "--sizes", "3", "--per-size", "2", "--methods",
            "lemke,pivoting", "--out", str(out), "--no-siconos", "--no-isolation"]
    assert cli_main(args + ["--quiet"]) == 0
    path = out / "results.csv"
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 4
    with open(path, "w", newline="") as fh:  # as if interrupted after the first row
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerow(rows[0])
    capsys.readouterr()
    assert cli_main(args + ["--resume"]) == 0
    captured = capsys.readouterr()
    printed = [line for line in captured.err.splitlines() if line.startswith("[")]
    assert len(printed) == 3  # only the three missing pairs ran (progress: on stderr)
    assert not [line for line in captured.out.splitlines() if line.startswith("[")]
    table = captured.out.splitlines()  # stdout is the result: one row per method
    assert table[0].split()[:2] == ["method", "certified"]
    assert [line.split()[:2] for line in table[1:3]] == [["lemke", "2/2"], ["pivoting", "2/2"]]
    back = read_csv(path)
    assert sorted((r.problem, r.method) for r in back) == \
        sorted((r["problem"], r["method"]) for r in rows)
    assert "Resumed: 1 rows kept" in (out / "report.md").read_text()


def test_the_set_header_counts_unreadable_files_apart(tmp_path):
    folder = tmp_path / "f"
    folder.mkdir()
    get_set("random-p", sizes=(3,), per_size=1)[0].save(folder / "good.npz")
    for k in range(5):
        (folder / f"bad{k}.dat").write_text("not a problem\n")
    out = tmp_path / "o"
    assert cli_main(["bench", "--set", str(folder), "--methods", "lemke", "--out", str(out),
                     "--no-siconos", "--quiet", "--no-isolation"]) == 0
    report = (out / "report.md").read_text()
    assert "1 problem (5 more unreadable)" in report and "6 problems" not in report


@pytest.mark.parametrize("extra, words", [
    (["--methods", "lemke,nosuch"], "unknown method 'nosuch'"),
    (["--methods", "lemke", "--resume"], "--resume"),
    (["--methods", "lemke", "--problems", "nosuch"], "no problem named nosuch"),
])
def test_a_refused_bench_command_says_one_line_and_leaves_nothing(tmp_path, extra, words):
    out = tmp_path / "b3"
    proc = subprocess.run(
        [sys.executable, "-m", "rigidlcp.cli", "bench", "--set", "random-p", "--sizes",
         "3", "--per-size", "1", "--out", str(out), "--no-siconos", *extra],
        capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0] and "Traceback" not in proc.stderr
    assert not out.exists()
