"""rigidlcp.reproduce.valid_steady: Fig. 11's "linear through 0" judged over every valid
steady state (issue 21, point 3, a start)."""

from __future__ import annotations

import pytest

from rigidlcp.reproduce.valid_steady import BandPoint, linear_through_zero, mu_g_band
from rigidlcp.verify.ranges import End, Range


def _pt(g, lo, hi, selected=None, own=True):
    r = Range("mu_g", End("optimal", lo), End("optimal", hi))
    return BandPoint(g, r, r if own else None, selected)


def test_verdicts_from_ranges():
    assert linear_through_zero([_pt(0, 0, 0), _pt(0.1, 0.2, 0.2), _pt(0.2, 0.4, 0.4)])[0] \
        == "holds for all"
    assert linear_through_zero([_pt(0.1, 0.2, 0.2), _pt(0.2, 0.5, 0.5)])[0] == "holds for none"
    # slopes [2, 3] at 0.1 and [5, 6] at 0.2: no common slope
    assert linear_through_zero([_pt(0.1, 0.2, 0.3), _pt(0.2, 1.0, 1.2)])[0] == "holds for none"
    assert linear_through_zero([_pt(0, 0.1, 0.2)])[0] == "holds for none"  # 0 excluded at 0
    # the lower ends on mu_g = 2 gamma; 0 at gamma = 0 attained by the run's checked state
    pts = [_pt(0, -0.1, 0.1, selected=0.0), _pt(0.1, 0.2, 0.5), _pt(0.2, 0.4, 0.6)]
    assert linear_through_zero(pts)[0] == "holds for some"
    # the same without the run's state at 0: the ends alone do not attain 0 there
    pts[0] = _pt(0, -0.1, 0.1, selected=0.0, own=False)
    assert linear_through_zero(pts)[0] == "unknown"
    tl = Range("mu_g", End("time limit"), End("optimal", 1.0))
    assert linear_through_zero([BandPoint(0.1, tl, None, None)])[0] == "unknown"


def test_small_row_lower_ends_linear():
    """rect 3x1 at Fig. 11's coefficients: the least-mu_g states (the selection's) are linear
    in gamma, the others are not one line: "holds for some"; at gamma = 0 (at rest) static
    friction leaves mu_g anywhere in a symmetric interval."""
    pts = mu_g_band(dict(lattice="rect", lx=3, ly=1, mu_pp=0.05, mu_plane=0.1, mu_wall=0.0),
                    [0.0, 0.01, 0.02], time_limit=20)
    verdict, why = linear_through_zero(pts)
    assert verdict == "holds for some" and "lower ends" in why
    assert pts[0].every.lo.value == pytest.approx(-pts[0].every.hi.value, abs=1e-12)
    for pt in pts:
        assert pt.every.contains(pt.selected, tol=1e-8)
    assert pts[2].every.lo.value == pytest.approx(2 * pts[1].every.lo.value, rel=1e-9)
