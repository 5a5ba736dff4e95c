"""The `rigidlcp` command line.

Each package registers its own sub-commands as a module with `register(subparsers)` under the
entry-point group `rigidlcp.commands` (see pyproject.toml). The CLI discovers them there, so
that `models` never imports `verify`: the dependency arrow stays lcp <- models <- verify.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from importlib.metadata import entry_points

# Used when the distribution's metadata is missing (running from a source tree without install).
FALLBACK_COMMAND_MODULES = ("lcp.commands", "models.commands", "verify.commands")


def _command_modules() -> list[str]:
    found = [ep.value for ep in entry_points(group="rigidlcp.commands")]
    return found or list(FALLBACK_COMMAND_MODULES)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rigidlcp",
        description="Rigid disks with Signorini's condition and exact Coulomb friction as LCPs "
        "(Radjai, Brendel & Roux, PRE 54, 861, 1996).",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in _command_modules():
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:  # a package not written yet must not break the rest
            if exc.name and name.startswith(exc.name):
                continue
            raise
        module.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except (ValueError, FileNotFoundError) as exc:
        print(f"rigidlcp {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # `rigidlcp ... | head`: the reader left; say nothing more
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    sys.exit(main())
