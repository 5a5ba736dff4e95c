"""The ranges table's cells (user25's trial: an open end's width printed 'nan', a point range's
width '-5.551e-17')."""

import pytest

from rigidlcp.verify.ranges.result import OPTIMAL, TIME_LIMIT, End, Range, end_cell, width_text


def test_open_end_shows_where_it_lies_and_no_width():
    lo = End(TIME_LIMIT, best=0.1050919, bound=0.012)
    r = Range("mu_g", lo, End(OPTIMAL, 0.2))
    assert end_cell(lo, -1) == "in [0.012, 0.1051]" and width_text(r) == "-"
    assert end_cell(End(TIME_LIMIT), 1) == "time limit"
    assert end_cell(End(TIME_LIMIT, best=0.15, bound=0.16), 1) == "in [0.15, 0.16]"


def test_rounding_level_negative_width_is_zero_but_a_real_one_is_kept():
    point = Range("x", End(OPTIMAL, -0.1), End(OPTIMAL, -0.1 - 5.551e-17))
    assert width_text(point) == "0"
    bad = Range("x", End(OPTIMAL, 1.0), End(OPTIMAL, 0.5))
    assert width_text(bad) == "-0.5"


# Rounding noise (session 7's closing note): an end that is 0 was printed -4.4e-16; a point
# range's width 3.469e-18. The cells print no digit below what the end is known to (End.tol,
# result.end_tolerance) and 0 only within it; the JSON keeps the values in full.

from fractions import Fraction  # noqa: E402

import numpy as np  # noqa: E402
from hypothesis import given  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from rigidlcp.verify.ranges.result import _outward, end_tolerance, value_text  # noqa: E402

U = 2.0 ** -53


def test_a_value_within_its_tolerance_is_0_and_only_then():
    assert value_text(-4.4e-16, 1e-14) == "0" and value_text(4.4e-16, 4.4e-16) == "0"
    assert value_text(3e-14, 1e-14) == "3e-14"  # outside: its one meaningful digit, not 0
    assert value_text(-4.4e-16) == "-4.4e-16"  # no tolerance known: no value becomes 0
    assert value_text(0.1267138048123, 1e-15) == "0.1267138048"  # at most 10 digits
    assert value_text(0.1267138048123, 1e-6) == "0.12671"  # none below the tolerance
    assert value_text(0.0, 0.0) == "0" and value_text(float("inf"), 1.0) == "inf"


def test_end_tolerance_by_hand():
    # two nonzero products of size 1: 1.01 gamma_2 (1 + 1) + 2 * 2^-1074
    assert end_tolerance(np.array([1.0, -1.0, 5.0]), np.array([1.0, 1.0, 0.0])) == \
        pytest.approx(1.01 * 2 * U / (1 - 2 * U) * 2, rel=1e-15)
    # the witness's residual 1e-12 at force scale 3: each force to 3e-12, |L|_1 = 7
    assert end_tolerance(np.array([2.0, -5.0]), np.zeros(2), 1e-12, 3.0) == \
        pytest.approx(1e-12 * 3.0 * 7.0, rel=1e-15)
    assert end_tolerance(np.zeros(3), np.ones(3)) == 0.0


finite = st.floats(-1e6, 1e6, allow_nan=False, allow_subnormal=False)


@given(st.lists(st.tuples(finite, finite), min_size=1, max_size=40))
def test_end_tolerance_bounds_the_rounding_of_the_dot_product(pairs):
    """The computed L . x is within end_tolerance(L, x) of the exact one (rationals)."""
    L, x = (np.array(v) for v in zip(*pairs))
    exact = sum(Fraction(a) * Fraction(b) for a, b in pairs)
    assert abs(Fraction(float(L @ x)) - exact) <= Fraction(end_tolerance(L, x))


@given(st.floats(-1e9, 1e9, allow_nan=False).filter(lambda v: abs(v) > 1e-300),
       st.integers(1, 8))
def test_open_end_cells_are_rounded_outward(x, digits):
    assert float(_outward(x, -1, digits)) <= x <= float(_outward(x, +1, digits))


def test_cells_of_noise_ends():
    lo = End(TIME_LIMIT, best=-6.661338148e-16, bound=-0.1, tol=1e-14)
    assert end_cell(lo, -1) == "in [-0.1, 0]"
    lo = End(TIME_LIMIT, best=0.1050919, bound=0.0117647058)
    assert end_cell(lo, -1) == "in [0.01176, 0.1051]"  # the bound down, the best met up
    hi = End(TIME_LIMIT, best=0.0403557, bound=0.100004)
    assert end_cell(hi, 1) == "in [0.04035, 0.1001]"
    point = Range("alpha[0]", End(OPTIMAL, -0.01, tol=4e-15),
                  End(OPTIMAL, -0.01 + 3.469e-18, tol=4e-15))
    assert width_text(point) == "0" and end_cell(point.hi, 1) == "-0.01"
    real = Range("x", End(OPTIMAL, 0.0, tol=1e-15), End(OPTIMAL, 1e-13, tol=1e-15))
    assert width_text(real) == "1e-13" and end_cell(real.hi, 1) == "1e-13"
