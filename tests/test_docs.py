"""The documentation runs (issue 14.3): a renamed function or option breaks CI, not a user.

* Every ```python block of README.md and docs/*.md is executed; the blocks of one file share a
  namespace (in order) and run in a temporary directory (which links the repository's tests/
  and docs/, for the data files the examples read). A block preceded by the line
  `<!-- not-run: REASON -->` is skipped (the reason is required).
* Every `rigidlcp ...` line of a ```bash block is parsed by the real parser (the command and
  every option must exist, choices must be valid), and the cheap commands (CHEAP) are run.
* A ```bash block preceded by `<!-- run-in-ci: REASON -->` is run whole, line by line, in a
  temporary directory: every `rigidlcp ...` line must exit 0 (docs/usage.md's first steps).
* In the other fenced blocks (listings, transcripts), every `rigidlcp NAME` must name an
  existing command.
* The README lists every command.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
#: Commands cheap enough to run from the docs' bash blocks (seconds).
CHEAP = {"methods", "verify-formulas"}
_NOT_RUN = re.compile(r"<!--\s*not-run:\s*(\S.*?)\s*-->")
_RUN = re.compile(r"<!--\s*run-in-ci:\s*(\S.*?)\s*-->")


def blocks(path: Path) -> list[tuple[str, int, str, str | None]]:
    """(language, first line number, code, not-run reason) of every fenced block."""
    out, lines, k = [], path.read_text().splitlines(), 0
    while k < len(lines):
        m = re.match(r"^(\s*)```(\w*)\s*$", lines[k])
        if not m:
            k += 1
            continue
        indent, lang, start = m.group(1), m.group(2), k + 1
        prev = next((lines[j] for j in range(k - 1, -1, -1) if lines[j].strip()), "")
        reason = _NOT_RUN.search(prev)
        k += 1
        body = []
        while k < len(lines) and lines[k].strip() != "```":
            body.append(lines[k][len(indent):] if lines[k].startswith(indent) else lines[k])
            k += 1
        k += 1
        out.append((lang, start + 1, "\n".join(body), reason.group(1) if reason else None))
    return out


def _commands() -> set[str]:
    from rigidlcp.cli.main import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return set(sub.choices)


def _command_lines(code: str) -> list[str]:
    """The `rigidlcp ...` command lines of a shell block (continuations joined, prompts and
    comments dropped, `.venv/bin/rigidlcp` and `&&` chains understood)."""
    text = re.sub(r"\\\n\s*", " ", code)
    lines = text.splitlines()
    if any(line.startswith("$ ") for line in lines):  # a transcript: the prompts only
        lines = [line for line in lines if line.startswith("$ ")]
    out = []
    for line in lines:
        line = line.strip().removeprefix("$ ")
        for part in line.split("&&"):
            part = part.split(" #")[0].strip()
            m = re.match(r"^(?:\S*/)?rigidlcp(\s.*)?$", part)
            if m:
                out.append("rigidlcp" + (m.group(1) or ""))
    return out


@pytest.mark.parametrize("path", DOCS, ids=[p.name for p in DOCS])
def test_python_blocks_run(path: Path, tmp_path, monkeypatch):
    code = [(line, c, why) for lang, line, c, why in blocks(path) if lang == "python"]
    if not code:
        pytest.skip("no python block")
    for data in ("tests", "docs"):  # blocks may read the repository's data files
        (tmp_path / data).symlink_to(ROOT / data, target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    # Blocks may register methods (docs/bench.md registers "mine", whose body is `...`): they
    # go into a copy of the registry, dropped after the test, so that later tests that run
    # every registered method do not meet them (they did, in pytest 7.1's collection order).
    from rigidlcp.lcp import api, registry
    api._load_builtin_methods()
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))
    namespace: dict = {"__name__": f"docs_{path.stem}"}
    ran = 0
    for line, c, why in code:
        if why is not None:
            continue
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                exec(compile(c, f"{path.name}:{line}", "exec"), namespace)
        except Exception as exc:
            pytest.fail(f"{path.name}, the python block at line {line}: "
                        f"{type(exc).__name__}: {exc}")
        ran += 1
    assert ran or all(why for _, _, why in code)


@pytest.mark.parametrize("path", DOCS, ids=[p.name for p in DOCS])
def test_shell_commands_exist_and_parse(path: Path, tmp_path, monkeypatch, capsys):
    from rigidlcp.cli.main import build_parser, main

    names = _commands()
    problems = []
    for lang, line, code, why in blocks(path):
        if lang in ("python", "json") or why is not None:
            continue
        for cmd in _command_lines(code):
            words = shlex.split(cmd)[1:]
            if not words or words[0].startswith("-"):
                continue
            if words[0] not in names:
                problems.append(f"line {line}: no command {words[0]!r}: {cmd}")
                continue
            if lang != "bash":  # listings: the name is enough ([OPTIONS] are placeholders)
                continue
            try:
                build_parser().parse_args(words)
            except SystemExit:
                problems.append(f"line {line}: does not parse: {cmd}: "
                                f"{capsys.readouterr().err.strip()}")
                continue
            if words[0] in CHEAP:
                monkeypatch.chdir(tmp_path)
                if main(words) != 0:
                    problems.append(f"line {line}: exit status != 0: {cmd}")
    assert not problems, f"{path.name}:\n" + "\n".join(problems)


def _run_in_ci_blocks() -> list[tuple[Path, int, str]]:
    out = []
    for path in DOCS:
        lines = path.read_text().splitlines()
        for lang, line, code, _ in blocks(path):
            prev = next((lines[j] for j in range(line - 3, -1, -1) if lines[j].strip()), "")
            if lang == "bash" and _RUN.search(prev):
                out.append((path, line, code))
    return out


def test_usage_has_run_in_ci_first_steps():
    assert any(p.name == "usage.md" for p, _, _ in _run_in_ci_blocks())


@pytest.mark.parametrize("path, line, code", _run_in_ci_blocks(),
                         ids=[f"{p.name}:{n}" for p, n, _ in _run_in_ci_blocks()])
def test_run_in_ci_blocks_run(path, line, code, tmp_path, monkeypatch, capsys):
    """Each command of the block, in order, in one fresh folder, exits 0 (a second run of a
    command that only displays, such as `effective`, must not need --force: run twice)."""
    from rigidlcp.cli.main import main

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    for cmd in _command_lines(code):
        words = shlex.split(cmd)[1:]
        code_ = main(words)
        err = capsys.readouterr().err
        assert code_ == 0, f"{path.name}:{line}: {cmd}: exit {code_}: {err[-300:]}"
        if words[0] == "effective":
            assert main(words) == 0, f"{path.name}:{line}: {cmd} again: {capsys.readouterr()}"


def test_readme_lists_every_command():
    text = (ROOT / "README.md").read_text()
    missing = [n for n in sorted(_commands()) if not re.search(rf"rigidlcp {n}\b", text)]
    assert not missing, f"README.md does not list: {missing}"


def test_not_run_markers_give_a_reason():
    for path in DOCS:
        for m in re.finditer(r"<!--\s*not-run(.*?)-->", path.read_text()):
            assert m.group(1).strip(": ").strip(), f"{path.name}: not-run without a reason"


if os.environ.get("RIGIDLCP_DOCS_DEBUG"):  # pragma: no cover
    for p in DOCS:
        print(p.name, [(lang, line, why) for lang, line, _, why in blocks(p)])


def test_public_submodules_are_attributes():
    """`from rigidlcp import models; models.runio.save_run` works without importing the
    submodule by hand (checked in a fresh interpreter, where nothing is imported yet)."""
    import subprocess
    import sys

    code = (
        "import pkgutil\n"
        "from rigidlcp import lcp, models, verify\n"
        "missing = []\n"
        "for pkg in (lcp, models, verify):\n"
        "    for m in pkgutil.iter_modules(pkg.__path__):\n"
        "        if not m.name.startswith('_') and not hasattr(pkg, m.name):\n"
        "            missing.append(pkg.__name__ + '.' + m.name)\n"
        "print(' '.join(missing))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "", f"not attributes of their package: {out}"


def test_no_reference_to_a_design_file_the_repository_lacks():
    """Issue 24.6: docs and docstrings sent readers to a DESIGN.md outside the repository; the
    sign conventions live in docs/mechanics.md."""
    files = [*DOCS, *ROOT.glob("models/**/*.py"), *ROOT.glob("lcp/**/*.py"),
             *ROOT.glob("verify/**/*.py"), *ROOT.glob("rigidlcp/**/*.py")]
    bad = [str(p.relative_to(ROOT)) for p in files if "DESIGN.md" in p.read_text()]
    assert not (ROOT / "DESIGN.md").exists() and not bad, bad
    text = (ROOT / "docs" / "mechanics.md").read_text()
    assert "### Sign conventions" in text and "D = -sum_alpha S_alpha v_t,alpha" in text


def test_readme_main_job_writes_only_ignored_files(tmp_path):
    """Issue 24.6: the README's main job left an untracked run.json in the checkout."""
    import shutil
    import subprocess

    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("needs git and a git checkout")
    readme = (ROOT / "README.md").read_text()
    line = next(c for lang, _, code, _ in blocks(ROOT / "README.md") if lang == "bash"
                for c in _command_lines(code) if c.startswith("rigidlcp simulate"))
    words = shlex.split(line)
    out = words[words.index("--out") + 1]
    assert out in readme
    paths = [out, out.removesuffix(".npz") + ".json"]
    proc = subprocess.run(["git", "-C", str(ROOT), "check-ignore", *paths],
                          capture_output=True, text=True)
    assert sorted(proc.stdout.split()) == sorted(paths), f"not ignored: {paths}"
