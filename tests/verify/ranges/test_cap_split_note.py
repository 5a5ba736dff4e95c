"""verify.ranges.cap_split's note on an end left open prints its best value met as the ranges
table does (result.value_text with the end's tolerance End.tol): no digit below what it is
known to, 0 only within it (it printed 'best met -6.661338148e-16')."""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp.verify.ranges import cap_split
from rigidlcp.verify.ranges.result import TIME_LIMIT, End, Range, value_text


def _note(monkeypatch, best: float, tol: float, bound: float = -0.25) -> str:
    """bound_open_ends on one open min end, the case split's proved bound stubbed (this test
    is about the note's text, not the bound)."""
    monkeypatch.setattr(cap_split, "cap_split_bound", lambda form, L: cap_split.CapSplitBound(
        bound, (), 3, 1, 0.0))
    lo = End(TIME_LIMIT, best=best, bound=None, tol=tol)
    ranges = {"mu_g": Range("mu_g", lo, End("optimal", 1.0))}
    cap_split.bound_open_ends(None, ranges, {"mu_g": np.ones(2)})
    assert lo.status == TIME_LIMIT and lo.bound == bound
    return lo.note


def test_rounding_noise_is_printed_as_zero(monkeypatch):
    note = _note(monkeypatch, -6.661338148e-16, 1e-15)
    assert note.endswith("; best met 0"), note


# digits = min(10, floor(log10(|best| / tol))) (value_text): 0.105... / 1e-13 ~ 1.05e12 -> 10
# (the cap), / 1e-6 ~ 1.05e5 -> 5; 3e-9 / 1e-15 = 3e6 -> 6; no tolerance known -> 10
@pytest.mark.parametrize("best, tol, text", [
    (0.1050919108123456, 1e-13, "0.1050919108"), (0.1050919108123456, 1e-6, "0.10509"),
    (-3.0e-9, 1e-15, "-3e-09"), (0.5, float("nan"), "0.5")])
def test_best_met_as_the_table_prints_it(monkeypatch, best, tol, text):
    note = _note(monkeypatch, best, tol)
    assert note.rsplit("; best met ", 1)[1] == text == value_text(best, tol)


def test_a_deep_witness_brings_its_own_tolerance(monkeypatch):
    """The disk split's witness replaces the best met: its value is printed to that witness's
    tolerance (result.witness_tolerance of its residual), not the one of the point it
    replaced."""
    from types import SimpleNamespace

    from rigidlcp.verify.ranges.result import end_tolerance

    R, S = np.array([1.0]), np.array([-1.0 + 2.0 ** -52])  # L . x = 2^-52: rounding noise
    wit = SimpleNamespace(R=R, S=S, residual=1e-12)
    monkeypatch.setattr(cap_split, "disk_split_bound", lambda *a, **kw: SimpleNamespace(
        candidate=object(), bound=-0.5, seconds=0.0, cases=2, empty=0, open=1))
    monkeypatch.setattr(cap_split, "witness_of", lambda form, cand: wit)
    monkeypatch.setattr(cap_split, "cap_split_bound", lambda form, L: cap_split.CapSplitBound(
        -0.25, (), 3, 1, 0.0))
    system = SimpleNamespace(mass=1.0, g=1.0, gamma=0.0)
    lo = End(TIME_LIMIT, best=0.3, tol=1e-16)
    ranges = {"mu_g": Range("mu_g", lo, End("optimal", 1.0))}
    cap_split.bound_open_ends(SimpleNamespace(system=system), ranges, {"mu_g": np.ones(2)},
                              deep=1.0)
    # the force scale is max(|x|, m g) = 1: the residual alone makes the value known to 2e-12
    assert lo.best == 2.0 ** -52 and lo.witness is wit
    assert lo.tol == end_tolerance(np.ones(2), np.r_[R, S], 1e-12, 1.0) >= 2e-12
    assert lo.note.endswith("; best met 0"), lo.note
