"""verify.certify refuses bad arguments with the toolkit's typed error (user25's trial)."""

import re

import numpy as np
import pytest

from rigidlcp import lcp, verify
from rigidlcp.lcp.errors import InvalidInput, RigidLCPError


def _solved():
    p = lcp.LCP(np.eye(2), np.array([-1.0, 2.0]))
    return p, lcp.solve(p)


def test_unknown_uniqueness_method_is_a_typed_error():
    p, s = _solved()
    with pytest.raises(InvalidInput, match="uniqueness must be one of") as e:
        verify.certify(p, s, uniqueness="bogus")
    assert isinstance(e.value, RigidLCPError) and isinstance(e.value, ValueError)


def test_solution_of_the_wrong_length_is_a_typed_error():
    p, _ = _solved()
    with pytest.raises(InvalidInput, match="3 entries"):
        verify.certify(p, np.zeros(3))


@pytest.mark.parametrize("kw, says", [
    ({"tol": -1}, "tol must be a number > 0 (finite), got -1"),
    ({"tol": 0.0}, "tol must be a number > 0 (finite), got 0.0"),
    ({"tol": float("nan")}, "tol must be a number > 0 (finite), got nan"),
    ({"tol": "1e-8"}, "tol must be a number > 0 (finite), got '1e-8'"),
    ({"time_limit": 0}, "time_limit must be a number > 0, got 0"),
])
def test_a_bad_tolerance_is_refused_not_a_rejection(kw, says):
    """certify(problem, sol, tol=-1) answered 'REJECTED at tol = -1' for the exact solution
    (session 27): a verdict on the solution from a bad argument. For I z + (-1, 2), z = (1, 0)
    solves it exactly (w = (0, 2))."""
    p, s = _solved()
    assert np.array_equal(s.z, [1.0, 0.0])
    with pytest.raises(InvalidInput, match=re.escape(says)):
        verify.certify(p, s, **kw)
    assert verify.certify(p, s, time_limit=np.inf).accepted  # no limit is a limit
