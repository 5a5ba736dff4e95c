"""`rigidlcp reproduce` printed one line per claim with the selection's PASS / FAIL and ended
with "15 PASS, 11 FAIL": the terminal gave one state's verdicts as the answer, where report.md
judges each steady-state claim over all valid steady states too (session 27). Each line now
carries that verdict as well, and the last line counts both."""

from __future__ import annotations

import pytest

from rigidlcp.cli.reproduce import overall_word, print_claims
from rigidlcp.reproduce.experiments import Claim

# The beginnings of rigidlcp.reproduce.overall's verdicts, as a quick run wrote them.
SEEN = [
    ("holds for some: the run's state and those with its mu_g", "some"),
    ("holds for some over gamma = 0..0.04 (the selection's linear piece)", "some"),
    ("holds for some (this toolkit's selection, the lower end curve)", "some"),
    ("holds for all: from gamma = 0.18 every valid steady state", "all"),
    ("holds for none: MILP infeasible after 0 lazy kinematic cut(s)", "none"),
    ("unknown (time limit: whether some valid steady state has it)", "unknown"),
    ("unknown: fails for lower end curves", "unknown"),
    ("not judged over the set: a claim about the runs' paths", "not judged"),
    ("n/a (not a steady-state claim)", "n/a"),
    ("", "-"),
]


@pytest.mark.parametrize("text, word", SEEN)
def test_overall_word(text, word):
    assert overall_word(text) == word


def _claim(cid: str, passed: bool, overall: str) -> Claim:
    return Claim(id=cid, where="Fig. 7", claim="...", measured=f"measured {cid}",
                 criterion="...", passed=passed, overall=overall)


def test_each_line_has_both_verdicts_and_the_last_counts_both(capsys):
    claims = [_claim("fig7-steady", True, SEEN[0][0]), _claim("fig9-counts", False, SEEN[4][0]),
              _claim("fig11-plateau", True, SEEN[3][0]), _claim("eq33-tri", False, SEEN[8][0])]
    print_claims(claims, "out/report.md (3 s on 1 local process(es))", "face-min-norm")
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("the selection (face-min-norm): PASS / FAIL; over all valid")
    assert lines[1] == "PASS  some  fig7-steady    measured fig7-steady"
    assert lines[2] == "FAIL  none  fig9-counts    measured fig9-counts"
    assert lines[3] == "PASS  all   fig11-plateau  measured fig11-plateau"
    assert lines[4] == "FAIL  n/a   eq33-tri       measured eq33-tri"
    assert lines[5] == ("2 PASS, 2 FAIL for this toolkit's selection; over all valid steady "
                        "states: 1 some, 1 none, 1 all, 1 n/a; report: out/report.md (3 s on "
                        "1 local process(es))")
