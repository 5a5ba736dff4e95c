"""Problem types: validation (every bad input is an InvalidProblem naming it) and storage."""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import lcp
from rigidlcp.lcp.errors import InvalidFile

GOOD_M, GOOD_Q = np.eye(2), np.array([-1.0, 1.0])


def mlcp_args(**override):
    args = dict(A=np.eye(2), C=np.ones((2, 3)), D=np.ones((3, 2)), B=np.eye(3),
                a=np.zeros(2), b=np.ones(3))
    args.update(override)
    return args


def test_invalid_problem_is_a_value_error():
    assert issubclass(lcp.InvalidProblem, ValueError)
    assert issubclass(lcp.NotApplicable, ValueError)


@pytest.mark.parametrize("M, q, needle", [
    (np.ones((2, 3)), [1.0, 1.0], "M must be square"),
    (np.ones(4), [1.0] * 4, "M must be a 2-D"),
    (np.eye(2), [1.0, 1.0, 1.0], "q must have length 2"),
    (np.eye(2), np.ones((2, 2)), "q must be a vector"),
    ([[1.0, np.nan], [0.0, 1.0]], [1.0, 1.0], "M contains NaN or Inf"),
    (np.eye(2), [np.inf, 1.0], "q contains NaN or Inf"),
    (np.eye(2), [-np.inf, 1.0], "q contains NaN or Inf"),
    ([["a", "b"], ["c", "d"]], [1.0, 1.0], "M must be numeric"),
    (np.eye(2), ["x", 1.0], "q must be numeric"),
    (np.eye(2), {"a": 1}, "q must be numeric"),
    (np.zeros((0, 0)), [], "empty"),
    (np.eye(2) * 1j, [1.0, 1.0], "real"),
    (None, [1.0], "M is missing"),
])
def test_bad_lcp_input_raises_invalid_problem_naming_it(M, q, needle):
    with pytest.raises(lcp.InvalidProblem, match=needle):
        lcp.LCP(M, q)


@pytest.mark.parametrize("override, needle", [
    (dict(A=np.ones((2, 3))), "A must be square"),
    (dict(B=np.ones((3, 2))), "B must be square"),
    (dict(C=np.ones((2, 2))), "C must have shape"),
    (dict(D=np.ones((2, 2))), "D must have shape"),
    (dict(a=np.zeros(3)), "a must have length 2"),
    (dict(b=np.zeros(2)), "b must have length 3"),
    (dict(b=[1.0, np.nan, 1.0]), "b contains NaN"),
    (dict(A=[["x", 1.0], [1.0, 1.0]]), "A must be numeric"),
    (dict(C=np.zeros((2, 0))), "empty"),
])
def test_bad_mlcp_input_raises_invalid_problem_naming_it(override, needle):
    with pytest.raises(lcp.InvalidProblem, match=needle):
        lcp.MLCP(**mlcp_args(**override))


def test_solve_rejects_unknown_method_option_and_non_problems():
    problem = lcp.LCP(GOOD_M, GOOD_Q)
    with pytest.raises(lcp.InvalidProblem, match="unknown method 'simplex'"):
        lcp.solve(problem, "simplex")
    with pytest.raises(lcp.InvalidProblem, match=r"does not accept option\(s\) \['colour'\]"):
        lcp.solve(problem, "pivoting", colour="red")
    with pytest.raises(lcp.InvalidProblem, match="must be an lcp.LCP"):
        lcp.solve((GOOD_M, GOOD_Q), "pivoting")
    with pytest.raises(lcp.InvalidProblem):
        lcp.get_method("nope")


@pytest.mark.parametrize("method, options", [
    ("enumerate", {"tol": 0.0}), ("enumerate", {"tol": float("nan")}),
    ("pivoting", {"max_iter": -1}), ("pivoting", {"tol": 2.0}), ("pivoting", {"block_tries": -1}),
    ("qp-clarabel", {"eps": -1.0}), ("qp-osqp", {"max_iter": 0}),
])
def test_bad_option_values_raise_invalid_problem(method, options):
    with pytest.raises(lcp.InvalidProblem):
        lcp.solve(lcp.LCP(GOOD_M, GOOD_Q), method, **options)


def test_lcp_save_load_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    problem = lcp.LCP(rng.normal(size=(4, 4)), rng.normal(size=4), name="p",
                      meta={"seed": 0, "kind": "test"})
    path = problem.save(tmp_path / "sub" / "p")  # suffix added, folder created
    assert path.suffix == ".npz" and path.exists()
    back = lcp.load(path)
    assert isinstance(back, lcp.LCP)
    assert np.array_equal(back.M, problem.M) and np.array_equal(back.q, problem.q)
    assert back.name == "p" and back.meta == {"seed": 0, "kind": "test"}


def test_mlcp_save_load_round_trip(tmp_path):
    problem = lcp.MLCP(**mlcp_args(), name="m", meta={"event": 3})
    back = lcp.load(problem.save(tmp_path / "m.npz"))
    assert isinstance(back, lcp.MLCP) and back.name == "m" and back.meta == {"event": 3}
    for key in ("A", "C", "D", "B", "a", "b"):
        assert np.array_equal(getattr(back, key), getattr(problem, key))
    # The loaded problem solves to the same answer.
    a = lcp.solve(problem, "pivoting")
    b = lcp.solve(back, "pivoting")
    assert np.array_equal(a.z, b.z) and np.array_equal(a.u, b.u)


def test_load_refuses_foreign_and_missing_files(tmp_path):
    np.savez(tmp_path / "x.npz", X=np.eye(2))
    with pytest.raises(InvalidFile, match="neither an LCP"):
        lcp.load(tmp_path / "x.npz")
    with pytest.raises(FileNotFoundError):
        lcp.load(tmp_path / "missing.npz")
    (tmp_path / "text.npz").write_text("not an archive")
    with pytest.raises(InvalidFile, match="text.npz is not"):
        lcp.load(tmp_path / "text.npz")
    (tmp_path / "empty.npz").write_bytes(b"")
    with pytest.raises(InvalidFile, match="empty"):
        lcp.load(tmp_path / "empty.npz")
    np.savez(tmp_path / "bad.npz", M=np.ones((2, 3)), q=np.ones(2))
    with pytest.raises(lcp.InvalidProblem, match="square"):
        lcp.load(tmp_path / "bad.npz")


def test_mlcp_reduction_and_recovery_by_hand():
    rng = np.random.default_rng(1)
    A = rng.normal(size=(3, 3)) + 3 * np.eye(3)
    C, D = rng.normal(size=(3, 2)), rng.normal(size=(2, 3))
    B, a, b = np.eye(2) * 4, rng.normal(size=3), rng.normal(size=2)
    problem = lcp.MLCP(A, C, D, B, a, b)
    reduced = problem.to_lcp()
    assert np.allclose(reduced.M, B - D @ np.linalg.solve(A, C))
    assert np.allclose(reduced.q, b - D @ np.linalg.solve(A, a))
    v = np.array([0.3, 0.0])
    u = problem.recover_u(v)
    assert np.allclose(A @ u + C @ v + a, 0)


def test_solution_repr_and_dict():
    sol = lcp.solve(lcp.LCP(GOOD_M, GOOD_Q), "pivoting")
    text = repr(sol)
    assert "status='solved'" in text and "residual" in text and "z = " in text
    d = sol.to_dict()
    assert d["status"] == "solved" and d["z"] == [1.0, 0.0] and d["basis"] == [0]
    assert sol.success and sol.residual == 0.0
