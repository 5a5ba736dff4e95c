"""The house rules (docs/architecture.md): one namespace, floors that import only downwards,
no import cycles, every package installed, modules of a readable size."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10 (tomllib is 3.11+): the pyproject checks skip
    tomllib = None

ROOT = Path(__file__).resolve().parents[1]
#: Folder of each installed package's root (pyproject's package-dir).
FOLDERS = {"rigidlcp.lcp": "lcp", "rigidlcp.models": "models", "rigidlcp.verify": "verify",
           "rigidlcp": "rigidlcp"}
#: What each floor may import (lcp <- models <- verify <- applications).
ALLOWED = {
    "rigidlcp.lcp": {"rigidlcp.lcp"},
    "rigidlcp.models": {"rigidlcp.lcp", "rigidlcp.models"},
    "rigidlcp.verify": {"rigidlcp.lcp", "rigidlcp.models", "rigidlcp.verify"},
}


def _modules() -> dict[str, Path]:
    """Every module of the distribution, by its import name."""
    out = {}
    for pkg, folder in FOLDERS.items():
        for path in (ROOT / folder).rglob("*.py"):
            rel = path.relative_to(ROOT / folder).with_suffix("")
            parts = [p for p in rel.parts if p != "__init__"]
            name = ".".join([pkg, *parts])
            if pkg == "rigidlcp" and parts and f"rigidlcp.{parts[0]}" in FOLDERS:
                continue
            out[name] = path
    return out


def _imports(name: str, path: Path) -> set[str]:
    """The rigidlcp modules a module imports (at any depth in the file), resolved."""
    tree = ast.parse(path.read_text())
    is_pkg = path.name == "__init__.py"
    base = name.split(".") if is_pkg else name.split(".")[:-1]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.startswith("rigidlcp")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                mod = ".".join(base[: len(base) - node.level + 1] + ([node.module] if node.module
                                                                      else []))
            else:
                mod = node.module or ""
            if mod.startswith("rigidlcp"):
                found.add(mod)
                found |= {f"{mod}.{a.name}" for a in node.names}
    return found


def _floor(name: str) -> str:
    for pkg in ("rigidlcp.lcp", "rigidlcp.models", "rigidlcp.verify"):
        if name == pkg or name.startswith(pkg + "."):
            return pkg
    return "rigidlcp"


def test_every_package_is_installed():
    """pyproject's explicit package list names every folder with an __init__.py."""
    if tomllib is None:
        pytest.skip("tomllib needs Python >= 3.11")
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert config["package-dir"] == {k: v for k, v in FOLDERS.items()}
    packages = {n for n, p in _modules().items() if p.name == "__init__.py"}
    assert packages == set(config["packages"])


def test_floors_import_only_downwards():
    modules = _modules()
    for name, path in modules.items():
        floor = _floor(name)
        if floor not in ALLOWED:
            continue
        for target in _imports(name, path):
            if target == "rigidlcp":  # the namespace itself: lazy, imports nothing
                continue
            if target in modules or target.rsplit(".", 1)[0] in modules:
                assert _floor(target) in ALLOWED[floor], f"{name} imports {target}"


def test_no_import_cycles():
    """Module-level imports (not those inside functions, which run later) form no cycle."""
    modules = _modules()
    graph = {}
    for name, path in modules.items():
        tree = ast.parse(path.read_text())
        top = ast.Module(body=[n for n in tree.body if isinstance(n, (ast.Import,
                                                                      ast.ImportFrom))],
                         type_ignores=[])
        tmp = set()
        is_pkg = path.name == "__init__.py"
        base = name.split(".") if is_pkg else name.split(".")[:-1]
        for node in top.body:
            if isinstance(node, ast.Import):
                tmp |= {a.name for a in node.names}
            elif node.level:
                mod = ".".join(base[: len(base) - node.level + 1]
                               + ([node.module] if node.module else []))
                tmp |= {mod} | {f"{mod}.{a.name}" for a in node.names}
            elif node.module:
                tmp |= {node.module} | {f"{node.module}.{a.name}" for a in node.names}
        # importing a.b.c imports the packages a.b and a first; a package is not its children
        graph[name] = {t for t in tmp if t in modules and t != name}
    state: dict[str, int] = {}

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for nxt in graph[node]:
            if state.get(nxt) == 1:
                cycle = stack[stack.index(nxt):] + [nxt] if nxt in stack else [node, nxt]
                raise AssertionError("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt, stack + [nxt])
        state[node] = 2

    for name in graph:
        if name not in state:
            visit(name, [name])


def test_no_generic_top_level_names():
    """Everything installs under `rigidlcp`: no top-level lcp/models/verify in site-packages."""
    if tomllib is None:
        pytest.skip("tomllib needs Python >= 3.11")
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert all(p == "rigidlcp" or p.startswith("rigidlcp.") for p in config["packages"])


def test_modules_stay_readable():
    """One job per module: none grows far past ~400 lines (a file that does is asking to be
    split; the margin is for docstrings)."""
    long = {n: len(p.read_text().splitlines()) for n, p in _modules().items()}
    assert {n: k for n, k in long.items() if k > 450} == {}


def test_import_rigidlcp_is_cheap_and_complete():
    import rigidlcp

    assert rigidlcp.__version__
    assert rigidlcp.lcp.solve and rigidlcp.models.simulate and rigidlcp.verify.certify


def test_engine_functions_are_short():
    """The event engine (the loop, its backends, records, simulate) reads as steps: no function
    over ~60 lines. (The sparse backend's solver, contact-state pivoting, is an algorithm of its
    own in lcp/solvers/state_pivoting.py, re-exported by models/engine/sparse_pivoting.py.)"""
    long = []
    for path in (ROOT / "models" / "engine").glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > 60:
                    long.append(f"{path.name}:{node.name} ({n} lines)")
    assert long == []


def test_no_two_models_modules_import_each_other():
    """Not even inside functions (issue 24.8: models/engine/simulate.py <-> sparse.py through
    blas_limit, now in loop.py below both): a piece two modules share lives below both.
    (lcp/ is checked room by room: test_lcp_rooms_import_downwards.)"""
    modules = {n: p for n, p in _modules().items() if _floor(n) == "rigidlcp.models"}
    deps = {name: {t for t in _imports(name, path) if t in modules and t != name}
            for name, path in modules.items()}
    mutual = sorted(f"{a} <-> {b}" for a in deps for b in deps[a]
                    if a < b and a in deps.get(b, ()) and not b.startswith(a + ".")
                    and not a.startswith(b + "."))
    assert not mutual, "modules importing each other: " + "; ".join(mutual)


#: Import cycles through imports inside functions, known when this test was written (issue 24.8
#: names the engine's; lcp/'s 14-module one through lcp/api.py went with its rooms, issue 23.5,
#: and bench.fuzz <-> fuzz_files with bench/fuzz_judge.py below both). The test fails on any
#: other: a new cycle, or a known one that grows. Remove an entry once its cycle is gone.
KNOWN_FUNCTION_LEVEL_CYCLES: list[set[str]] = []


def _cycles(graph: dict[str, set[str]]) -> list[set[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[set[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = set()
            while True:
                w = stack.pop()
                on.discard(w)
                comp.add(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(comp)

    for v in graph:
        if v not in index:
            visit(v)
    return out


def test_no_new_import_cycles_inside_functions():
    """Imports at any depth (inside functions too) between modules (a package's __init__ is
    left out: importing a.b imports a first, which is not a cycle of code): no cycle beyond
    the known ones above (e.g. verify/certificates/certify.py <-> stages.py, issue 24.8)."""
    modules = _modules()
    graph = {name: {t for t in _imports(name, path)
                    if t in modules and t != name and modules[t].name != "__init__.py"}
             for name, path in modules.items()}
    new = [sorted(c) for c in _cycles(graph)
           if not any(c <= known for known in KNOWN_FUNCTION_LEVEL_CYCLES)]
    assert new == []


#: The rooms of lcp/ (docs/architecture.md, "The rooms of lcp/"), lowest first: a module imports
#: only from its own room or a lower level; rooms on one level (solvers, faces) do not import
#: each other. errors.py, quiet.py, _lemke_kernel.py and io/files.py are leaves every room uses.
LCP_LEVELS = {
    "errors": 0, "quiet": 1, "_lemke_kernel": 1, "io.files": 1,
    "problems": 2, "io": 3, "acceptance": 4, "registry": 5, "solvers": 6, "faces": 6,
    "api": 7, "batch": 8,
}


def _room(name: str) -> str | None:
    """The room of an lcp module (None for the package rigidlcp.lcp itself)."""
    parts = name.split(".")[2:]
    if not parts:
        return None
    return "io.files" if parts[:2] == ["io", "files"] else parts[0]


def test_lcp_rooms_import_downwards():
    """The registry imports only data types, the methods import the registry, `solve` (api)
    imports them all, and nothing below the facade imports it (issue 23.5): at any depth,
    imports inside functions included."""
    modules = _modules()
    wrong = []
    for name, path in modules.items():
        if _floor(name) != "rigidlcp.lcp" or _room(name) is None:
            continue
        src = _room(name)
        for target in _imports(name, path):
            if target not in modules:
                target = target.rsplit(".", 1)[0]
            dst = _room(target) if target in modules else None
            if dst is None or dst == src:
                continue
            if not LCP_LEVELS[dst] < LCP_LEVELS[src]:
                wrong.append(f"{name} -> {target}")
    assert wrong == []
