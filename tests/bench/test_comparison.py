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
