"""Whitespace-separated text items with their line numbers, for Siconos's text formats.

Siconos reads its files with C ``fscanf`` (line breaks do not matter); errors here name the
file, the line and what was expected, and a typed error says which kind of problem it is.
"""

from __future__ import annotations

import re

import numpy as np

from ..problems.problem import InvalidProblem, NotApplicable


class FileFormatError(InvalidProblem):
    """A file that cannot be read as the expected format (names file, line, expectation)."""

    def __init__(self, path: str, line: int | None, message: str):
        where = f"{path}, line {line}" if line is not None else str(path)
        super().__init__(f"{where}: {message}")
        self.path, self.line, self.reason = str(path), line, message


class WrongKind(FileFormatError):
    """The file is in a Siconos format, but of another kind of problem than requested."""


class UnsupportedProblem(NotApplicable):
    """A well-formed file whose problem rigidlcp does not solve (e.g. a rectangular MLCP)."""


_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$|^[+-]?(nan|inf)$", re.I)


def is_number(item: str) -> bool:
    return bool(_NUMBER.match(item))


class Tokens:
    """The file's items, consumed in order; each knows its line (1-based)."""

    def __init__(self, text: str, path: str):
        self.items: list[str] = []
        self.lines: list[int] = []
        for k, line in enumerate(text.splitlines(), start=1):
            parts = line.split()
            self.items += parts
            self.lines += [k] * len(parts)
        self.pos = 0
        self.path = str(path)
        self.nlines = self.lines[-1] if self.lines else 1  # the last line with an item

    @property
    def line(self) -> int:
        """The line of the next item (the last line at the end of the file)."""
        return self.lines[self.pos] if self.pos < len(self.items) else self.nlines

    def error(self, message: str, line: int | None = None) -> FileFormatError:
        return FileFormatError(self.path, self.line if line is None else line, message)

    def _next(self, what: str) -> tuple[str, int]:
        if self.pos >= len(self.items):
            raise FileFormatError(self.path, self.nlines,
                                  f"the file ends where {what} was expected")
        item, line = self.items[self.pos], self.lines[self.pos]
        self.pos += 1
        return item, line

    def word(self, expected: str) -> None:
        """Consume one literal item (e.g. "col"), or fail naming it."""
        item, line = self._next(f"{expected!r}")
        if item.rstrip(",:") != expected.rstrip(",:"):
            raise FileFormatError(self.path, line, f"expected {expected!r}, found {item!r}")

    def integer(self, what: str, low: int | None = None) -> int:
        item, line = self._next(what)
        try:
            value = float(item.rstrip(","))
        except ValueError:
            value = float("nan")
        if not np.isfinite(value) or not value.is_integer():
            raise FileFormatError(self.path, line, f"{item!r} where {what} (an integer) was "
                                  "expected")
        if low is not None and value < low:
            raise FileFormatError(self.path, line, f"{item!r} where {what} (an integer >= "
                                  f"{low}) was expected")
        return int(value)

    def number(self, what: str) -> float:
        item, line = self._next(what)
        try:
            return float(item.rstrip(","))
        except ValueError:
            raise FileFormatError(self.path, line, f"{item!r} where {what} (a number) was "
                                  "expected") from None

    def numbers(self, count: int, what: str) -> np.ndarray:
        end = self.pos + count
        if end > len(self.items):
            got = len(self.items) - self.pos
            raise FileFormatError(self.path, self.nlines, f"the file ends after {got} of the "
                                  f"{count} numbers of {what}")
        chunk = self.items[self.pos:end]
        try:
            out = np.array(chunk, dtype=float)
        except ValueError:
            for k, item in enumerate(chunk):
                try:
                    float(item)
                except ValueError:
                    raise FileFormatError(self.path, self.lines[self.pos + k],
                                          f"{item!r} where {what} (number {k + 1} of {count}, "
                                          "a number) was expected") from None
            raise
        self.pos = end
        return out

    def skip_line(self) -> str:
        """Consume the rest of the current item's line (a free-text header line)."""
        if self.pos >= len(self.items):
            return ""
        line = self.lines[self.pos]
        start = self.pos
        while self.pos < len(self.items) and self.lines[self.pos] == line:
            self.pos += 1
        return " ".join(self.items[start:self.pos])

    def rest(self) -> list[str]:
        return self.items[self.pos:]

    def trailing_numbers(self) -> int:
        """How many numbers follow (up to the first non-number: a free-text remark)."""
        k = self.pos
        while k < len(self.items) and is_number(self.items[k]):
            k += 1
        return k - self.pos


#: Names of the kinds of Siconos problem files.
KIND_NAMES = {"lcp": "LCP", "mlcp": "MLCP", "fc2d": "2D friction-contact",
              "fc3d": "3D friction-contact"}


def header_kinds(tok: Tokens) -> list[str]:
    """The kinds whose header fits the file's first five items: LCP "n st n n ..."; friction
    contact "d nc st d*nc d*nc"; MLCP "0|1 0|1 n m" (then blocksRows from 0 when the first
    flag is 1). Several can fit a tiny problem; none fits a file of another format."""
    h: list[int] = []
    for item in tok.items[:5]:
        try:
            v = float(item)
        except ValueError:
            return []
        if not v.is_integer():
            return []
        h.append(int(v))
    if len(h) < 5:
        return []
    fits = []
    if h[0] >= 1 and h[1] in (0, 1, 2) and h[2] == h[3] == h[0]:
        fits.append("lcp")
    if h[0] in (2, 3) and h[1] >= 1 and h[2] in (0, 1, 2) and h[3] == h[4] == h[0] * h[1]:
        fits.append("fc2d" if h[0] == 2 else "fc3d")
    if h[0] in (0, 1) and h[1] in (0, 1) and (h[0] or h[1]) and h[2] >= 0 and h[3] >= 1 \
            and (h[0] == 0 or h[4] == 0):
        fits.append("mlcp")
    return fits


def check_kind(tok: Tokens, kind: str) -> None:
    """Raise WrongKind when the header fits other kinds of file but not `kind`."""
    fits = header_kinds(tok)
    if fits and kind not in fits:
        names = " or ".join(KIND_NAMES[k] for k in fits)
        raise WrongKind(tok.path, 1, f"this is a Siconos {names} file, not a(n) "
                        f"{KIND_NAMES[kind]} file")


def write_new(path, lines: list[str]):
    """Write the lines to a new file (never over an existing one: FileExistsError)."""
    from pathlib import Path

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "x") as fh:
        fh.write("\n".join(lines) + "\n")
    return path
