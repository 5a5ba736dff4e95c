"""Dolan-More performance profiles of a ``rigidlcp bench`` run (Math. Program. 91, 201, 2002),
one figure per kind of problem (LCP, MLCP, FC2D), drawn with matplotlib (Agg).

With t_ps the time of method s on problem p (infinite when it failed or refused),
r_ps = t_ps / min_s t_ps and rho_s(tau) = |{p : r_ps <= tau}| / |P|, against log2(tau):
rho_s(1) is the fraction of problems on which s was fastest, the right end its success rate.
Only the methods that accept at least one problem of the kind are drawn, each with its own
(colour, line style, marker), so that no two curves look alike.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .harness import Result
from .report import profile_data

STYLES = ("-", "--", "-.", ":")
MARKERS = ("o", "s", "^", "v", "D", "x", "+", "*", "<", ">")


def style(k: int) -> dict:
    """The k-th curve's matplotlib style: 10 colours x 4 line styles x 10 markers, distinct
    for k < 40 (colour and line style change together, never only one of them repeats)."""
    return {"color": f"C{k % 10}", "linestyle": STYLES[(k // 10 + k) % 4],
            "marker": MARKERS[(k + 3 * (k // 10)) % 10], "markevery": 0.1, "markersize": 4}


def plot_profile(results: Sequence[Result], path: str | os.PathLike, title: str,
                 kind: str | None = None, set_name: str | None = None) -> Path | None:
    """The profile of the problems of `kind` (None: all) as a PNG; None when there is
    nothing to plot (no problem of the kind, or no method accepts any)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    methods, ratios = profile_data(results, set_name, kind)
    if ratios.size == 0:
        return None
    finite = ratios[np.isfinite(ratios)]
    tau_max = max(2.0, float(finite.max()) * 2 if finite.size else 2.0)
    taus = np.logspace(0, np.log2(tau_max), 400, base=2.0)
    fig, ax = plt.subplots(figsize=(7.0, 3.8))
    for k, method in enumerate(methods):
        rho = (ratios[:, k][None, :] <= taus[:, None]).mean(axis=1)
        ax.step(np.log2(taus), rho, where="post", label=method, **style(k))
    ax.set_xlabel(r"$\log_2 \tau$  (time within a factor $\tau$ of the fastest)")
    ax.set_ylabel(r"$\rho_s(\tau)$: fraction of problems")
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlim(0, np.log2(tau_max))
    ax.grid(alpha=0.3)
    ax.set_title(f"{title} ({ratios.shape[0]} problems)", fontsize=10)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path
