"""Issue 23: simulate's records credit the method that produced each event's answer.

A test-only method that always says "solved" with z = 1 is never credited: each event is
solved by the fallback ("lemke"), and the record says so (method "lemke", fallback True)."""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import lcp, models
from rigidlcp.lcp import api


@pytest.fixture
def liar():
    @api.register("test-mine", accepts="any", description="z = 1, 'solved' (tests only)")
    def mine(M, q):
        return lcp.Solution(z=np.ones(q.size), w=q, status="solved", method="test-mine")

    yield
    api._REGISTRY.pop("test-mine", None)


def test_simulate_credits_the_method_that_answered(liar):
    system = models.System(models.rectangular(3, 1), mu_pp=0.3, mu_plane=0.5, mu_wall=0.2)
    run = models.simulate(system, seed=3, max_events=4, method="test-mine")
    assert run.records
    assert all(r.method == "lemke" and r.fallback for r in run.records)
    own = models.simulate(system, seed=3, max_events=4, method="lemke")
    assert all(r.method == "lemke" and not r.fallback for r in own.records)
    np.testing.assert_allclose(run.records[-1].R, own.records[-1].R, atol=1e-9)
    stopped = models.simulate(system, seed=3, max_events=4, method="test-mine", fallback=None)
    assert not stopped.records and stopped.status == "solver_failed"


def test_the_summary_counts_the_events_the_fallback_answered(liar):
    """Audit of issue 23.1: run.summary() (run.json's "summary", `simulate --json`) said
    "method": "test-mine" with no count of the events the fallback answered (only the
    command's table had "fallback solves"): a script reading the JSON credited the method."""
    system = models.System(models.rectangular(3, 1), mu_pp=0.3, mu_plane=0.5, mu_wall=0.2)
    run = models.simulate(system, seed=3, max_events=4, method="test-mine")
    assert run.summary()["fallback_solves"] == len(run.records) > 0
    own = models.simulate(system, seed=3, max_events=4, method="lemke")
    assert own.summary()["fallback_solves"] == 0
