"""Time limits of the certificates' MILPs on a chosen clock (verify.certificates.clocked;
`clock=` of verify.certify, certify_stages, certify_event, certify_run; `clock_name=` of
milp_search, no_solution_beyond): the clock reaches HiGHS, a limit reached is a time limit
("unknown", never a verdict), and a wrong clock is refused before any work.

No timed assertion: the clocks here are fakes that jump (clocked.CLOCKS is read at every
reading), so what is tested is where a limit is looked at, not how long anything takes.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from rigidlcp import lcp
from rigidlcp.verify import certify
from rigidlcp.verify.certificates import certify_stages, clocked
from rigidlcp.verify.certificates.bounds import no_solution_beyond
from rigidlcp.verify.certificates.stages import UNIQUE, UNKNOWN
from rigidlcp.verify.certificates.uniqueness import milp_search

# M skew-symmetric (not P), q > 0: z = 0 is the only solution (z_1 > 0 would need
# w_1 = 1 + z_2 = 0); the staged path decides it in the MILP stage (test_stages.py).
SKEW = lcp.LCP(np.array([[0.0, 1.0], [-1.0, 0.0]]), np.array([1.0, 1.0]))


def _knapsack():
    """A 0-1 knapsack that HiGHS (presolve off) solves by simplex and branching."""
    rng = np.random.default_rng(0)
    a = rng.integers(3, 20, 30).astype(float)
    return dict(c=-np.ones(30), integrality=np.ones(30), A=a[None, :], row_lo=[-np.inf],
                row_hi=[a.sum() / 2 + 0.5], col_lo=0.0, col_hi=1.0,
                options={"presolve": False})


def _jump_after(k: int):
    """A clock at 0 for its first k readings, then 1e9 s later."""
    calls = itertools.count()
    return lambda: 0.0 if next(calls) < k else 1e9


def _advancing():
    """A clock that moves 1000 s at every reading."""
    calls = itertools.count()
    return lambda: 1000.0 * next(calls)


def test_cpu_clock_reaches_highs_callback(monkeypatch):
    """The deadline is set from the clock's first reading; HiGHS's interrupt callback reads it
    again, sees the limit passed and stops: a time limit (status 1), no point claimed."""
    out = clocked.solve_milp(**_knapsack(), time_limit=60.0, clock_name="cpu")
    assert out.status == 0 and out.x is not None  # the real clock: solved
    monkeypatch.setitem(clocked.CLOCKS, "cpu", _jump_after(1))
    out = clocked.solve_milp(**_knapsack(), time_limit=60.0, clock_name="cpu")
    assert out.status == 1, out
    assert "CPU s" in out.message and "Interrupted" in out.message


def test_wall_clock_is_highs_own_limit(monkeypatch):
    """clock "wall": HiGHS's own time_limit, no callback; a CPU clock that jumps is not read."""
    monkeypatch.setitem(clocked.CLOCKS, "cpu", _jump_after(0))
    out = clocked.solve_milp(**_knapsack(), time_limit=60.0, clock_name="wall")
    assert out.status == 0


@pytest.mark.parametrize("clock_name", ["cpu", "wall"])
def test_milp_stage_stops_on_the_clock_asked(monkeypatch, clock_name):
    """With the asked clock advancing, the MILP stage leaves each question "unknown" with the
    time limit as its reason; the other clock moving changes nothing."""
    cert = certify_stages(SKEW, np.zeros(2), clock=clock_name)
    assert cert.verdicts["z"].verdict == UNIQUE and cert.verdicts["z"].stage == "milp (c2)"
    other = "wall" if clock_name == "cpu" else "cpu"
    monkeypatch.setitem(clocked.CLOCKS, other, _advancing())
    cert = certify_stages(SKEW, np.zeros(2), clock=clock_name)
    assert cert.verdicts["z"].verdict == UNIQUE
    monkeypatch.setitem(clocked.CLOCKS, clock_name, _advancing())
    cert = certify_stages(SKEW, np.zeros(2), clock=clock_name)
    for name in ("z", "w"):
        v = cert.verdicts[name]
        assert v.verdict == UNKNOWN and v.stage == "milp (c2)", v
        assert "time limit" in v.reason, v.reason
    assert cert.verdicts["states"].verdict == UNKNOWN


def test_certify_staged_default_clock_is_cpu(monkeypatch):
    """verify.certify's staged path counts CPU seconds by default: a CPU clock that advances
    leaves z and w undecided (None, the limit in the notes), never a verdict."""
    cert = certify(SKEW, np.zeros(2), uniqueness="staged")
    assert cert.z_unique is True and cert.w_unique is True
    monkeypatch.setitem(clocked.CLOCKS, "cpu", _advancing())
    cert = certify(SKEW, np.zeros(2), uniqueness="staged")
    assert cert.accepted
    assert cert.z_unique is None and cert.w_unique is None
    assert any("time limit" in n for n in cert.notes), cert.notes


def test_milp_search_and_norm_bound_on_an_advancing_clock(monkeypatch):
    """milp_search's "none" and no_solution_beyond's proof each need HiGHS's "infeasible"
    twice: on an advancing CPU clock there is no time for the second run: undecided."""
    M, q = np.eye(2), np.array([-1.0, 1.0])  # P-matrix: one solution, z = (1, 0)
    assert milp_search(M, q, np.array([1.0, 0.0]), "pattern").status == "none"
    assert no_solution_beyond(M, q, 1e3).proved is True
    monkeypatch.setitem(clocked.CLOCKS, "cpu", _advancing())
    res = milp_search(M, q, np.array([1.0, 0.0]), "pattern")
    assert res.status == "unknown" and "CPU s" in res.message, res.message
    nb = no_solution_beyond(M, q, 1e3)
    assert nb.proved is None, nb.message


def test_wrong_clock_refused():
    with pytest.raises(ValueError, match="clock"):
        certify(SKEW, np.zeros(2), clock="gpu")
    with pytest.raises(ValueError, match="clock"):
        certify_stages(SKEW, np.zeros(2), clock="gpu")
    with pytest.raises(ValueError, match="clock"):
        milp_search(SKEW.M, SKEW.q, np.zeros(2), clock_name="gpu")
    with pytest.raises(ValueError, match="clock"):
        no_solution_beyond(SKEW.M, SKEW.q, 1e3, clock_name="gpu")
