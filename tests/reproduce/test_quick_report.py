"""The quick report says, claim by claim, where its sizes differ from the full run's and what it
cannot judge (issue 24.2: it said 10x4 under a table of 6x3 runs, and its fig8 / fig9 / ivb
verdicts contradicted the full run's without a word)."""

from __future__ import annotations

import pytest

from rigidlcp.reproduce.experiments import Claim, Results, plan
from rigidlcp.reproduce.quick import claim_sizes, size_differences
from rigidlcp.reproduce.report import write_report

IDS = ("fig7-steady", "fig8-row1-mode1", "fig8-any-selection", "fig9-counts", "ivb-pp-mu_e",
       "fig13-minimum", "fig6-singular", "eq33-tri")


def _report(tmp_path, quick: bool) -> str:
    claims = [Claim(cid, "", "a claim", "a measurement", "a criterion", True) for cid in IDS]
    write_report(Results(plan(quick=quick)), claims, tmp_path, {}, "rigidlcp reproduce")
    return (tmp_path / "report.md").read_text()


def test_quick_report_names_every_claim_judged_at_other_sizes(tmp_path):
    text = _report(tmp_path, quick=True)
    assert "**Quick run (--quick): not the paper's sizes.**" in text
    assert "Sizes of the full run:" in text  # the prose no longer passes for this run's sizes
    section = text.split("## Quick run")[1]
    assert "fig8: 6x3 (full: 10x4)" in section and "fig9: 6x3 (full: 10x4)" in section
    for cid in IDS:
        assert f"| {cid} |" in text
        row = next(line for line in text.splitlines() if line.startswith(f"| {cid} |"))
        assert "**PASS** (quick run, see below)" in row, row
        assert f"**{cid}: PASS in the quick run**" in section
    fig9 = next(line for line in section.splitlines() if "fig9-counts" in line)
    assert "Cannot judge" in fig9 and "nine of the ten disks" in fig9


def test_full_report_has_no_quick_notes(tmp_path):
    text = _report(tmp_path, quick=False)
    assert "Quick run" not in text and "quick run" not in text


@pytest.mark.parametrize("cid, names", [("fig9-counts", ["fig9"]),
                                        ("ivb-pp-mu_e", ["fig11", "ivb_pp"]),
                                        ("eq34-rect", ["formulas"])])
def test_claim_sizes(cid, names):
    assert claim_sizes(cid, size_differences(plan(quick=True))) == names
    assert size_differences(plan(quick=False)) == {}
