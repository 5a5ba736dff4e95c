"""The `rigidlcp` command line: the parser, and the one place that turns errors into messages.

Each module in `COMMAND_MODULES` adds its sub-commands with `register(subparsers)` and keeps
its heavy imports inside the commands, so that `rigidlcp --help` stays fast. An error raised on
purpose by the toolkit (`rigidlcp.lcp.errors.RigidLCPError`), a bad value, a file that is
missing, exists already or cannot be written, or an allocation that fails (MemoryError, past
the commands' up-front memory estimates), is printed as one line naming the problem, with exit
status 2: never a traceback. Ctrl-C (KeyboardInterrupt) is one line too, with exit status 130
(128 + SIGINT, as a shell reports it); a command with resumable output says how to resume.
"""

from __future__ import annotations

import argparse
import importlib
import re
import sys

from rigidlcp.lcp.errors import RigidLCPError

#: The command modules, in the order of `rigidlcp --help`.
COMMAND_MODULES = (
    "rigidlcp.cli.solve",  # methods, solve
    "rigidlcp.cli.simulate",  # simulate, plot
    "rigidlcp.cli.timestep",  # timestep (Moreau-Jean)
    "rigidlcp.cli.compare_integrators",  # compare-integrators
    "rigidlcp.cli.sweep",  # sweep, effective
    "rigidlcp.cli.nullspace",  # nullspace, verify-formulas
    "rigidlcp.cli.forces",  # forces
    "rigidlcp.cli.pack",  # pack (deposition)
    "rigidlcp.cli.forceset",  # forceset (statics of a packing)
    "rigidlcp.cli.certify_run",  # certify-run
    "rigidlcp.cli.ranges",  # ranges
    "rigidlcp.cli.bench",  # bench
    "rigidlcp.cli.fuzz",  # fuzz
    "rigidlcp.cli.reproduce",  # reproduce
)


#: A word that starts like a negative number ("-1:1", "-1e-3", "-.5"): a value, never an
#: option (argparse takes only "-1" and "-1.5" as numbers; no option of ours starts "-<digit>").
_NEGATIVE = re.compile(r"^-\.?\d")


class OneLineParser(argparse.ArgumentParser):
    """An ArgumentParser whose usage errors are one line (not the usage block), exit status 2,
    and that reads a word starting like a negative number as a value (`--radii -1:1` reaches
    the option's own check instead of "expected one argument")."""

    def error(self, message: str) -> None:  # type: ignore[override]
        text = " ".join(message.split())
        self.exit(2, f"{self.prog}: error: {text} (see `{self.prog} --help`)\n")

    def _parse_optional(self, arg_string):  # argparse's hook: None means "a value"
        if _NEGATIVE.match(arg_string):
            return None
        return super()._parse_optional(arg_string)


def seed(text: str) -> int:
    """argparse type of every --seed: an integer >= 0 (numpy's generators refuse others)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {value}")
    return value


def build_parser() -> argparse.ArgumentParser:
    from rigidlcp import __version__

    parser = OneLineParser(
        prog="rigidlcp",
        description="Rigid disks with Signorini's condition and exact Coulomb friction as LCPs "
        "(Radjai, Brendel & Roux, PRE 54, 861, 1996).",
    )
    parser.add_argument("--version", action="version", version=f"rigidlcp {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    for command in sub.choices.values():  # a script may pass --no-progress to every command
        if "--no-progress" not in command._option_string_actions:
            command.add_argument("--no-progress", action="store_true",
                                 help="accepted for scripts; this command shows no progress")
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args, extra = parser.parse_known_args(argv)
    if extra:  # named by the sub-command, whose --help lists what it takes
        parser.exit(2, f"rigidlcp {args.command}: error: unrecognized arguments: "
                    f"{' '.join(extra)} (see `rigidlcp {args.command} --help`)\n")
    try:
        return int(args.func(args) or 0)
    except BrokenPipeError:  # `rigidlcp ... | head`: the reader left; say nothing more
        _silence_stdout()
        return 0
    except KeyboardInterrupt:  # Ctrl-C: the user knows why; one line, not a traceback
        print(f"\nrigidlcp {args.command}: interrupted", file=sys.stderr)
        return 130
    except (RigidLCPError, ValueError, OSError) as exc:
        print(f"rigidlcp {args.command}: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except MemoryError as exc:  # past the up-front estimates (lower bounds): still one line
        print(f"rigidlcp {args.command}: error: out of memory ({_one_line(exc)}); use a "
              "smaller array (large arrays: rigidlcp simulate --method sparse-pivoting "
              "--select none)", file=sys.stderr)
        return 2


def _silence_stdout() -> None:
    """Point stdout at /dev/null so that the interpreter's final flush does not fail again."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def _one_line(exc: BaseException) -> str:
    """The message of an error on one line (OSError: 'strerror: filename')."""
    if isinstance(exc, OSError) and exc.filename and not isinstance(exc, RigidLCPError):
        text = f"{exc.strerror or type(exc).__name__}: {exc.filename}"
    else:
        text = str(exc) or type(exc).__name__
    # The toolkit's messages name both spellings, "--force (force=True)"; here only the flag.
    return " ".join(text.replace("--force (force=True)", "--force").split())


if __name__ == "__main__":
    sys.exit(main())
