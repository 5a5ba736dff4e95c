"""A script may pass --no-progress to every command (user30: solve, certify, plot, nullspace
and effective refused it with exit 2): each sub-command's parser takes it."""

from __future__ import annotations

import argparse

from rigidlcp.cli.main import build_parser, main


def _commands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def test_every_command_takes_no_progress():
    commands = _commands(build_parser())
    assert {"solve", "certify", "plot", "nullspace", "effective", "simulate"} <= set(commands)
    missing = [name for name, p in commands.items()
               if "--no-progress" not in p._option_string_actions]
    assert missing == []


def test_a_command_without_progress_runs_with_it(capsys):
    assert main(["methods", "--no-progress"]) == 0
    assert "lemke" in capsys.readouterr().out
