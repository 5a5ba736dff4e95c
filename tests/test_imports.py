"""A command loads only what it uses: which modules an import pulls in (no timing here; the
times are in docs/benchmarks.md, "Import and start-up")."""

from __future__ import annotations

import subprocess
import sys

HEAVY = ("cvxpy", "matplotlib", "highspy", "scipy.optimize", "clarabel", "osqp")


def loaded_after(code: str) -> set[str]:
    code += "\nimport sys\nprint(' '.join(sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return set(out.stdout.split())


def test_import_lcp_loads_no_solver_stack():
    mods = loaded_after("import rigidlcp.lcp")
    assert not {m for m in mods if m.startswith(HEAVY)}
    assert "scipy.sparse" not in mods and "scipy.linalg" not in mods


def test_lemke_solve_loads_only_lemke():
    mods = loaded_after("import numpy as np\nfrom rigidlcp import lcp\n"
                        "lcp.solve(lcp.LCP(np.eye(2), -np.ones(2)), 'lemke')")
    assert "rigidlcp.lcp.solvers.lemke" in mods
    assert not {m for m in mods if m.startswith(HEAVY)}
    assert not {"rigidlcp.lcp.solvers.qp", "rigidlcp.lcp.solvers.pgs",
                "rigidlcp.lcp.solvers.enumeration", "rigidlcp.lcp.problems.friction"} & mods
    assert "scipy.sparse" not in mods
    assert "scipy.linalg" not in mods  # neither Lemke loop calls BLAS for its update


def test_a_dense_run_loads_no_sparse_lu_and_no_qp_stack():
    """models.simulate on the dense backend (the README's job): no sparse LU, no HiGHS MILP
    machinery, no cvxpy/Clarabel/OSQP, no plotting."""
    mods = loaded_after("from rigidlcp import models\n"
                        "s = models.System(models.make_lattice('rect', 4, 2))\n"
                        "models.simulate(s, seed=1, max_events=5)")
    assert "rigidlcp.models.engine.dense" in mods
    assert not {"rigidlcp.lcp.solvers.state_factor", "rigidlcp.models.engine.sparse"} & mods
    # scipy < 1.16 loads scipy.sparse.linalg with scipy.sparse itself (csgraph's laplacian):
    # only where plain scipy.sparse does not is its presence ours.
    if "scipy.sparse.linalg" not in loaded_after("import scipy.sparse"):
        assert "scipy.sparse.linalg" not in mods
    assert not {m for m in mods if m.startswith(HEAVY)}


def test_cli_parser_loads_no_scipy():
    mods = loaded_after("import importlib\n"
                        "importlib.import_module('rigidlcp.cli.main').build_parser()")
    assert not {m for m in mods if m.startswith("scipy")}
    assert "rigidlcp.models.engine.dense" not in mods


def test_the_lazy_method_table_lists_every_builtin_method_in_order():
    """lcp.solvers.BUILTIN (which module registers which method) names every method the
    modules of lcp/solvers/ register, in the order `lcp.methods()` lists them."""
    out = subprocess.run(
        [sys.executable, "-c", "import importlib, pkgutil\nfrom rigidlcp.lcp import api, solvers\n"
         "for m in pkgutil.iter_modules(solvers.__path__):\n"
         "    importlib.import_module(f'rigidlcp.lcp.solvers.{m.name}')\n"
         "print(sorted(api._REGISTRY) == sorted(solvers.BUILTIN),\n"
         "      [m.name for m in api.methods()] == list(solvers.BUILTIN))"],
        capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "True True"
