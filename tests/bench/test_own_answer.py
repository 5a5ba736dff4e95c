"""bench and fuzz count each method's OWN outcome (issue 23, point 1): a registered method
that lies is reported failed, never credited with another method's answer."""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import lcp
from rigidlcp.bench.fuzz import run_fuzz
from rigidlcp.bench.harness import run_bench
from rigidlcp.bench.problem_sets import get_set
from rigidlcp.lcp.api import _REGISTRY


def always_one(M, q):
    """Claims z = 1 solves every LCP."""
    z = np.ones(q.size)
    return lcp.Solution(z=z, w=M @ z + q, status="solved", method="test-always-one")


@pytest.fixture
def liar():
    lcp.register("test-always-one", accepts="any", description="claims z = 1")(always_one)
    yield "test-always-one"
    _REGISTRY.pop("test-always-one", None)


def test_fuzz_never_credits_a_lying_method(liar):
    result = run_fuzz(24, seed=3, methods=(liar,))
    cells = [cell for (_, m), cell in result["table"].items() if m == liar]
    assert cells and sum(cell["solved"] for cell in cells) == 0
    assert sum(cell["honest"] + cell["WRONG"] for cell in cells) == 24


def test_bench_never_credits_a_lying_method(liar):
    results = run_bench({"random-psd": get_set("random-psd", sizes=(3, 5), per_size=1)},
                        [liar], time_limit=30, isolate=False)
    assert results and not any(r.success for r in results)
    assert all(r.method == liar for r in results)
