"""verify.certify refuses bad arguments with the toolkit's typed error (user25's trial)."""

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
