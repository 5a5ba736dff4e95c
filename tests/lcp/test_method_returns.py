"""A registered method that returns no Solution (a forgotten `return`) is named in a TypeError;
it failed with "'NoneType' object has no attribute 'method'" inside lcp.acceptance.trust
(session 27, a new user registering a method). Every path of lcp.solve that calls the
method is covered: an LCP, an MLCP (Schur-reduced), a fallback."""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import lcp
from rigidlcp.lcp import registry

M = np.array([[2.0, 1.0], [1.0, 2.0]])
Q = np.array([-1.0, -1.0])


@pytest.fixture
def methods(monkeypatch):
    from rigidlcp.lcp import api

    api._load_builtin_methods()
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))

    @lcp.register("test-forgot-return", accepts="any", description="no return")
    def forgot(M, q):
        lcp.Solution(z=np.zeros(q.size), w=q.copy(), status="solved", method="x")

    @lcp.register("test-returns-z", accepts="any", description="returns the array z")
    def returns_z(M, q):
        return np.zeros(q.size)

    @lcp.register("test-gives-up", accepts="any", description="no answer")
    def gives_up(M, q):
        return lcp.Solution(z=np.zeros(q.size), w=q.copy(), status="max_iter",
                            method="test-gives-up")

    @lcp.register("test-honest", accepts="any", description="lemke's z, as a Solution")
    def honest(M, q):
        z = lcp.solve(lcp.LCP(M, q), method="lemke").z
        return lcp.Solution(z=z, w=M @ z + q, status="solved", method="test-honest")


@pytest.mark.parametrize("name, kind", [("test-forgot-return", "NoneType"),
                                        ("test-returns-z", "ndarray")])
def test_a_method_returning_no_solution_is_named(methods, name, kind):
    said = rf"method '{name}' returned {kind}, not an lcp.Solution"
    with pytest.raises(TypeError, match=said):
        lcp.solve(lcp.LCP(M, Q), method=name)
    # A u + a = 0 (u = 2) beside the LCP of M: an MLCP, Schur-reduced
    mlcp = lcp.MLCP(np.eye(1), np.zeros((1, 2)), np.zeros((2, 1)), M, np.array([-2.0]), Q)
    with pytest.raises(TypeError, match=said):
        lcp.solve(mlcp, method=name)


def test_a_fallback_returning_no_solution_is_named(methods):
    with pytest.raises(TypeError, match="'test-forgot-return' returned NoneType"):
        lcp.solve(lcp.LCP(M, Q), method="test-gives-up", fallback="test-forgot-return")
    sol = lcp.solve(lcp.LCP(M, Q), method="test-gives-up", fallback="test-honest")
    assert sol.success and sol.method == "test-honest"


def test_an_honest_method_is_unchanged(methods):
    sol = lcp.solve(lcp.LCP(M, Q), method="test-honest")
    assert sol.success and sol.method == "test-honest"
    assert np.allclose(sol.z, [1 / 3, 1 / 3])  # (2 1; 1 2) z = (1, 1)


def test_a_claim_without_z_is_judged_on_its_certificate_not_on_z(methods):
    """z is no claim of an 'infeasible' answer: z=None was reported as 'method returned a bad
    z' beside the missing certificate (a new user's method, session 27); a non-finite z of a
    'solved' answer is named as such and the answer fails."""

    @lcp.register("test-says-infeasible", accepts="any", description="claims, no y")
    def says(M, q):
        return lcp.Solution(z=None, w=None, status="infeasible", method="test-says-infeasible")

    @lcp.register("test-nan-z", accepts="any", description="a NaN z, 'solved'")
    def nan_z(M, q):
        return lcp.Solution(z=np.full(q.size, np.nan), w=q.copy(), status="solved",
                            method="test-nan-z")

    sol = lcp.solve(lcp.LCP(M, Q), method="test-says-infeasible")  # solvable: no certificate
    assert sol.status == "failed" and "bad z" not in sol.message and "z is" not in sol.message
    assert "no Farkas certificate" in sol.message
    sol = lcp.solve(lcp.LCP(M, Q), method="test-nan-z")
    assert sol.status == "failed" and "the method's z is not finite" in sol.message
