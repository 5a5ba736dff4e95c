"""The `rigidlcp` command line: one thin module per command group over the library.

`main.py` builds the parser from the modules listed in `main.COMMAND_MODULES` and turns every
error the toolkit raises on purpose into one line and exit status 2.
"""

from .main import build_parser, main

__all__ = ["build_parser", "main"]
