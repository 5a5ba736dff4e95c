"""The ranges table's cells (user25's trial: an open end's width printed 'nan', a point range's
width '-5.551e-17')."""

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
