"""Progress bars of the long commands (simulate, sweep, reproduce): on stderr, and erased when
they close (leave=False), so that no stale bar stays on the terminal above the results."""

from __future__ import annotations

import sys


def new_bar(**kwargs):
    """A tqdm bar on stderr that is erased when closed (leave=False)."""
    from tqdm import tqdm

    kwargs.setdefault("file", sys.stderr)
    kwargs.setdefault("dynamic_ncols", True)
    kwargs.setdefault("leave", False)
    return tqdm(**kwargs)
