"""`rigidlcp methods` and `rigidlcp solve`, through rigidlcp.cli.main.main."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rigidlcp import lcp
from rigidlcp.cli.main import main


@pytest.fixture
def lcp_file(tmp_path):
    return lcp.LCP(np.eye(2) + 0.5, [-1.0, 1.0], name="small").save(tmp_path / "p.npz")


@pytest.fixture
def mlcp_file(tmp_path):
    problem = lcp.MLCP(np.eye(2), -np.ones((2, 1)), np.ones((1, 2)), np.eye(1), np.zeros(2),
                       [-1.0])
    return problem.save(tmp_path / "m.npz")


def test_methods_lists_every_method_with_what_it_accepts(capsys):
    assert main(["methods"]) == 0
    out = capsys.readouterr().out
    for m in lcp.methods():
        line = next(ln for ln in out.splitlines() if ln.startswith(m.name + " "))
        assert lcp.api.ACCEPTS[m.accepts] in line
    assert "n <= 20" in out


def test_solve_prints_status_residual_iterations(lcp_file, capsys):
    assert main(["solve", str(lcp_file), "--method", "pivoting"]) == 0
    out = capsys.readouterr().out
    assert "status     : solved" in out and "residual" in out and "iterations" in out


def test_solve_json_is_the_whole_solution(lcp_file, capsys):
    assert main(["solve", str(lcp_file), "--method", "enumerate", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["status"] == "solved" and data["method"] == "enumerate"
    z = np.array(data["z"])
    assert np.allclose(z, [2 / 3, 0.0]) and data["residual"] <= 1e-12
    assert data["basis"] == [0]


def test_solve_mlcp_reports_u_and_equality_residual(mlcp_file, capsys):
    assert main(["solve", str(mlcp_file), "--method", "pivoting", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert np.allclose(data["z"], [1 / 3]) and np.allclose(data["u"], [1 / 3, 1 / 3])
    assert data["eq_residual"] <= 1e-12
    assert main(["solve", str(mlcp_file), "--method", "pivoting"]) == 0
    assert "eq_residual" in capsys.readouterr().out


def test_solve_passes_options_parsed_as_json(lcp_file, capsys):
    code = main(["solve", str(lcp_file), "--method", "pivoting", "--option", "active=[0]",
                 "-o", "max_iter=5", "--json"])
    assert code == 0
    assert json.loads(capsys.readouterr().out)["iterations"] == 0  # warm start was the answer


def test_solve_exit_code_1_when_the_method_fails(tmp_path, capsys):
    path = lcp.LCP([[1.0, 0.9], [0.9, 1.0]], [-1.0, -1.0]).save(tmp_path / "slow.npz")
    assert main(["solve", str(path), "--method", "pgs", "-o", "max_iter=1", "--json"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert data["status"] == "not_converged"
    infeasible = lcp.LCP([[1.0, -1.0], [-1.0, 1.0]], [-1.0, -1.0]).save(tmp_path / "inf.npz")
    assert main(["solve", str(infeasible), "--method", "enumerate"]) == 1
    assert "infeasible" in capsys.readouterr().out


@pytest.mark.parametrize("extra, needle", [
    (["--method", "no-such-method"], "unknown method"),
    (["--method", "pgs", "-o", "foo=1"], "does not accept"),
    (["--method", "pgs", "-o", "novalue"], "KEY=VALUE"),
    (["--method", "qp-osqp"], None),  # refused: not symmetric -> NotApplicable, exit 2
])
def test_solve_exit_code_2_on_bad_input(tmp_path, capsys, extra, needle):
    path = lcp.LCP([[1.0, 2.0], [0.0, 1.0]], [-1.0, 1.0]).save(tmp_path / "ns.npz")
    assert main(["solve", str(path), *extra]) == 2
    err = capsys.readouterr().err
    assert "error" in err and (needle is None or needle in err)


def test_solve_exit_code_2_on_missing_or_corrupt_file(tmp_path, capsys):
    assert main(["solve", str(tmp_path / "missing.npz")]) == 2
    assert "no such file" in capsys.readouterr().err.lower()
    bad = tmp_path / "bad.npz"
    bad.write_text("not a zip")
    assert main(["solve", str(bad), "--method", "pivoting"]) == 2
    assert "bad.npz is not" in capsys.readouterr().err
    other = tmp_path / "other.npz"
    np.savez(other, X=np.eye(2))
    assert main(["solve", str(other), "--method", "pivoting"]) == 2
    assert "neither an LCP" in capsys.readouterr().err


def test_solve_without_a_file_is_an_argparse_error():
    with pytest.raises(SystemExit) as exc:
        main(["solve"])
    assert exc.value.code == 2


# -- rigidlcp certify: any problem file, the certificate of the answer --------------------------

DATA = __import__("pathlib").Path(__file__).resolve().parents[1] / "data" / "siconos"


@pytest.mark.parametrize("name,method", [
    ("FC2D_SliderCrankLagrangian00000.dat", "lemke"),   # friction contact (Glocker LCP)
    ("m2n1_mlcp.dat", "lemke"),                          # MLCP
    ("lcp_deudeu_block.dat", "pivoting"),                # LCP, sparse-block storage
])
def test_certify_accepts_answers_to_every_kind_of_file(capsys, name, method):
    assert main(["certify", str(DATA / name), "--method", method, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["accepted"] is True and out["status"] == "solved"
    assert out["scaled_residual"] <= 1e-8


def test_certify_refuses_a_file_it_cannot_solve_with_one_line(capsys):
    assert main(["certify", str(DATA / "Rectangular_mlcp.dat")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Rectangular_mlcp.dat" in err[0] and "line" in err[0]
