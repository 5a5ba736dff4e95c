"""A registered method that raises (a bug of the method) gives status "failed", credited to it,
with the exception's type and message in its message and `info`: lcp.solve's docstring
promises a status, and a RuntimeError escaped as a traceback (session 7's closing note,
"Left for the next session"). bench and fuzz count it as that method's failure; the command
line prints the status, never a traceback. Bad input, refusals, MemoryError and
KeyboardInterrupt still propagate."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from rigidlcp import lcp
from rigidlcp.bench.fuzz import run_fuzz
from rigidlcp.cli.main import main
from rigidlcp.lcp import registry

M = np.array([[2.0, 1.0], [1.0, 2.0]])
Q = np.array([-1.0, -1.0])


def _raise(exc: BaseException):
    def method(M, q):
        raise exc

    return method


@pytest.fixture
def raising(monkeypatch):
    """Registers test-raises-<kind> for several exceptions, in a copy of the table."""
    from rigidlcp.lcp import api

    api._load_builtin_methods()
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))
    kinds = {"runtime": RuntimeError("boom"), "index": IndexError("index 7 is out of bounds"),
             "memory": MemoryError("no room"), "interrupt": KeyboardInterrupt(),
             "invalid": lcp.InvalidProblem("my bad input"),
             "refuses": lcp.NotApplicable("not for this M")}
    for kind, exc in kinds.items():
        lcp.register(f"test-raises-{kind}", accepts="any", description=kind)(_raise(exc))

    @lcp.register("test-raises-fc", accepts="friction-2d", description="friction, raises")
    def fc(problem):
        raise RuntimeError("fc boom")

    def native(problem):
        raise ZeroDivisionError("native boom")

    lcp.register("test-raises-native", accepts="any", description="MLCP natively, raises",
                 native={"mlcp": native})(_raise(RuntimeError("unused")))


def _is_failure_of(sol: lcp.Solution, method: str, kind: str, text: str) -> None:
    assert sol.status == "failed" and sol.method == method and not sol.success
    assert f"the method raised {kind}: {text}" in sol.message
    assert sol.info["exception"].strip() == f"{kind}: {text}"
    assert sol.info["exception_type"] == kind
    assert "test_method_raises.py" in sol.info["raised_at"]


@pytest.mark.parametrize("name, kind, text", [("test-raises-runtime", "RuntimeError", "boom"),
                                              ("test-raises-index", "IndexError",
                                               "index 7 is out of bounds")])
def test_a_method_that_raises_fails_with_its_exception_named(raising, name, kind, text):
    _is_failure_of(lcp.solve(lcp.LCP(M, Q), method=name), name, kind, text)
    # A u + a = 0 (u = 2) beside the LCP of M: an MLCP, Schur-reduced
    mlcp = lcp.MLCP(np.eye(1), np.zeros((1, 2)), np.zeros((2, 1)), M, np.array([-2.0]), Q)
    sol = lcp.solve(mlcp, method=name)
    _is_failure_of(sol, name, kind, text)
    assert sol.z.shape == (2,) and sol.u.shape == (1,)


def test_native_and_friction_methods_that_raise_fail_too(raising):
    mlcp = lcp.MLCP(np.eye(1), np.zeros((1, 2)), np.zeros((2, 1)), M, np.array([-2.0]), Q)
    _is_failure_of(lcp.solve(mlcp, method="test-raises-native"), "test-raises-native",
                   "ZeroDivisionError", "native boom")
    fc = lcp.FrictionContact2D(np.eye(2), np.array([-1.0, 0.5]), 0.3)
    sol = lcp.solve(fc, method="test-raises-fc")
    _is_failure_of(sol, "test-raises-fc", "RuntimeError", "fc boom")
    assert sol.z.shape == (2,)


def test_a_crash_is_not_turned_into_infeasible(raising):
    """On an infeasible LCP (w = -z - 1 < 0) lcp.solve's LP finds a Farkas certificate for a
    method that ends "failed"; a method that raised proved nothing: it stays "failed"."""
    sol = lcp.solve(lcp.LCP(-np.eye(2), Q), method="test-raises-runtime")
    _is_failure_of(sol, "test-raises-runtime", "RuntimeError", "boom")
    assert "farkas" not in sol.info


def test_a_fallback_asked_for_still_answers(raising):
    sol = lcp.solve(lcp.LCP(M, Q), method="test-raises-runtime", fallback="lemke")
    assert sol.success and sol.method == "lemke"
    assert sol.info["fallback_for"]["method"] == "test-raises-runtime"
    assert "RuntimeError: boom" in sol.info["fallback_for"]["message"]


@pytest.mark.parametrize("kind, exc", [("memory", MemoryError), ("interrupt", KeyboardInterrupt),
                                       ("invalid", lcp.InvalidProblem),
                                       ("refuses", lcp.NotApplicable)])
def test_memory_interrupts_bad_input_and_refusals_propagate(raising, kind, exc):
    with pytest.raises(exc):
        lcp.solve(lcp.LCP(M, Q), method=f"test-raises-{kind}")


def test_solve_on_the_command_line_prints_the_failure_not_a_traceback(raising, tmp_path,
                                                                      capsys):
    path = lcp.LCP(M, Q).save(tmp_path / "p.npz")
    assert main(["solve", str(path), "--method", "test-raises-runtime"]) == 1
    out, err = capsys.readouterr()
    assert err == "" and "Traceback" not in out
    assert "status     : failed" in out
    lines = [line for line in out.splitlines() if "RuntimeError: boom" in line]
    assert len(lines) == 1 and lines[0].startswith("message    : the method raised")


def test_bench_counts_it_as_the_methods_failure(raising, tmp_path, capsys):
    out = tmp_path / "b"
    assert main(["bench", "--set", "random-p", "--sizes", "3", "--per-size", "2", "--methods",
                 "test-raises-runtime", "--out", str(out), "--no-siconos", "--no-peers",
                 "--no-isolation"]) == 0
    printed, err = capsys.readouterr()
    assert "Traceback" not in printed + err
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert len(rows) == 2
    for row in rows:
        assert row["method"] == "test-raises-runtime" and row["success"] == "False"
        assert row["status"] == "failed" and "RuntimeError: boom" in row["message"]
    progress = [line for line in (printed + err).splitlines()
                if "test-raises-runtime" in line and "random-p/n3" in line]
    assert len(progress) == 2 and all(" failed " in line for line in progress)


def test_fuzz_counts_it_as_the_methods_crash(raising):
    result = run_fuzz(6, seed=1, methods=("test-raises-runtime",))
    cells = [cell for (_, m), cell in result["table"].items() if m == "test-raises-runtime"]
    assert cells and sum(cell["crash"] for cell in cells) == 6
    assert sum(cell["solved"] + cell["WRONG"] for cell in cells) == 0


def test_callers_of_the_table_without_the_facade_get_failed_too(raising):
    """lcp.acceptance.trust's Run is also driven with the raw table (lcp.registry.lookup: the
    local rescue of lcp.solvers.state_pivoting, below the facade): a raising method still
    comes back "failed" there (trust.call_method), and a method returning no Solution still
    raises the named TypeError through the facade."""
    from rigidlcp.lcp.acceptance.residual import TOL
    from rigidlcp.lcp.acceptance.trust import Run, solve_checked

    problem = lcp.LCP(M, Q)
    sol = solve_checked(Run(problem, problem, registry.lookup, TOL), "test-raises-runtime",
                        True, True, {})
    _is_failure_of(sol, "test-raises-runtime", "RuntimeError", "boom")
    assert issubclass(lcp.errors.NotASolution, TypeError)
