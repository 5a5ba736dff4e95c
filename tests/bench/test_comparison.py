"""docs/make_comparison.py (issue 23, point 6): one command writes docs/comparison.md with the
stated collection, the tables, the side-by-side on Fig. 9's events, the profiles and what each
method is good for. Run here on its --quick subset, into a temporary folder."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "docs" / "make_comparison.py"


@pytest.mark.slow  # a small bench of every method (~30 s on a shared 2-core machine)
def test_make_comparison_quick_writes_the_page(tmp_path):
    spec = importlib.util.spec_from_file_location("make_comparison", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--quick", "--out", str(tmp_path), "--cache", str(tmp_path / "c"),
                        "--siconos-data", str(tmp_path / "none"),
                        "--time-limit", "5"]) == 0
    page = (tmp_path / "comparison.md").read_text()
    for heading in ("## The collection", "## Successes per set", "## False successes",
                    "## Side by side on Fig. 9's event LCPs", "## All sets",
                    "## What each method is good for"):
        assert heading in page
    assert "Siconos's LCP files skipped" in page  # absent data: a note, not a failure
    assert "| fig9-events |" in page and "| hard-classes |" in page
    assert "- **lemke**" in page
    assert (tmp_path / "comparison" / "profile_LCP.png").read_bytes()[:4] == b"\x89PNG"
    report = (tmp_path / "comparison" / "report.md").read_text()
    assert "## Failures by problem" in report and "## Environment" in report


def _module():
    spec = importlib.util.spec_from_file_location("make_comparison", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _row(set_name, problem, method, outcome, t=0.001, message=""):
    import math

    from rigidlcp.bench.harness import Result

    ok = outcome == "solved"
    return Result(set=set_name, problem=problem, n=2, method=method, outcome=outcome,
                  success=ok, status=outcome, time=t, iterations=1,
                  residual=0.0 if ok else math.nan, scaled_residual=0.0 if ok else math.nan,
                  expected="solution", message=message, kind="LCP")


TYPE_ERROR = "TypeError: 'range' object does not support item assignment"


def test_the_page_says_a_peer_that_raises_is_broken_and_the_common_subset_is_meaningful(
        tmp_path):
    """lemkelcp 0.1 raises on Python 3 on every problem with a negative q_i: the page says it is
    broken (how many calls raised, the message), not "fails some of ... 0/20"; a method that
    solves none without raising says "solves none of"; the Fig. 9 table's common column is not
    shrunk to the one problem pgs takes."""
    module = _module()
    results = []
    for k in range(4):
        p = f"event_{k}"
        results += [
            _row("fig9-events", p, "lemke", "solved"),
            _row("fig9-events", p, "pgs", "solved" if k == 0 else "not_applicable"),
            _row("fig9-events", p, "slow-fail", "max_iter"),
            _row("fig9-events", p, "liar", "solved" if k < 2 else "uncertified"),
            _row("fig9-events", p, "lemkelcp", "solved" if k == 0 else "error",
                 message="" if k == 0 else TYPE_ERROR)]
    page_path = tmp_path / "comparison.md"
    module.write_page(page_path, results, [("fig9-events", "events")], [], "cmd", 10.0)
    page = page_path.read_text()
    lemkelcp = next(line for line in page.splitlines() if line.startswith("- **lemkelcp** ("))
    assert f"broken here: 3 of its 4 calls raised an exception** (`{TYPE_ERROR}`)" in lemkelcp
    assert "broken on Python 3" in lemkelcp  # the peer's own note
    assert "| lemkelcp | 1/4 (3 raised) |" in page
    slow = next(line for line in page.splitlines() if line.startswith("- **slow-fail** ("))
    assert "solves none of fig9-events 0/4" in slow and "fails some" not in slow
    assert "broken" not in slow
    liar = next(line for line in page.splitlines() if line.startswith("- **liar** ("))
    assert "solves part of fig9-events 2/4" in liar and "**2 false successes**" in liar
    # in short: lemke alone certified all four (pgs refused three)
    assert "| fig9-events | lemke | lemke (1 ms) |" in page
    assert "Called solutions that are not (their 'solved' must be checked): liar 2." in page
    assert f"Broken here: lemkelcp (3 of 4 calls raised `{TYPE_ERROR}`)." in page
    assert "SGM time, common LCP (4)" in page and "SGM time, common LCP (1)" not in page
    assert "| pgs | 1/4 (3 refused) |" in page  # pgs certified 1 of 4 and refused 3
    pgs_line = next(line for line in page.splitlines() if line.startswith("- **pgs** ("))
    assert "solves part of fig9-events 1/4 (3 refused)" in pgs_line
    pgs = next(line for line in page.splitlines() if line.startswith("| pgs | 1/4 (25%)"))
    assert pgs.split("|")[5].strip() == "-"  # left out of the common comparison


def test_lemkelcp_raises_on_python_3_and_the_wrapper_reports_it():
    """What the page says of lemkelcp, checked on the installed package (skipped without it)."""
    pytest.importorskip("lemkelcp")
    import numpy as np

    from rigidlcp import lcp
    from rigidlcp.bench.peers import solve_peer

    raw = solve_peer(lcp.LCP(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0])),
                     "lemkelcp")
    assert raw["kind"] == "error" and raw["message"] == TYPE_ERROR
    trivial = solve_peer(lcp.LCP(np.eye(2), np.array([1.0, 2.0])), "lemkelcp")
    assert trivial["kind"] == "answer" and trivial["status"] == "solved"
    assert np.array_equal(trivial["z"], np.zeros(2))
