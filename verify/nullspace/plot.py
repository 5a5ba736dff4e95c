"""Drawings of null-space basis vectors on the lattice (matplotlib, Agg backend).

One panel per basis vector: the disks, walls and plane (`models.plot.draw_lattice`), every
contact as a thin grey segment; R as thick segments, width ~ |R|, red where R > 0, blue where
R < 0; S as a green arrow at the contact point along S t (t = n turned by +90 degrees, the
tangential part of the force on body j, docs/mechanics.md), length ~ |S|, so that the sign of
S shows wherever it is nonzero, also where R is. Sizes are relative to the vector's largest
entry, max(|R|, |S|).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rigidlcp import models
from rigidlcp.lcp.errors import InvalidInput

from .contact import LoopBasis, NullSpace


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _draw_vector(ax, system: models.System, R: np.ndarray, S: np.ndarray, title: str) -> None:
    from matplotlib.collections import LineCollection

    from rigidlcp.models.plot import contact_points, draw_lattice

    draw_lattice(ax, system)
    a, b = contact_points(system)
    segs = np.stack([a, b], axis=1)
    ax.add_collection(LineCollection(segs, colors="0.8", linewidths=0.6))
    scale = max(np.abs(R).max(initial=0.0), np.abs(S).max(initial=0.0), 1e-300)
    on = np.abs(R) > 1e-9 * scale
    if np.any(on):
        colors = np.where(R[on] > 0, "tab:red", "tab:blue")
        ax.add_collection(LineCollection(segs[on], colors=list(colors),
                                         linewidths=1.0 + 4.0 * np.abs(R[on]) / scale))
    lat = system.lattice
    tan = np.abs(S) > 1e-9 * scale
    if np.any(tan):  # S t at the contact point: the sign of S, with or without R
        point = lat.x[lat.i[tan]] + lat.radius * lat.n[tan]
        vec = 1.2 * lat.radius * (S[tan] / scale)[:, None] * lat.t[tan]
        ax.quiver(point[:, 0], point[:, 1], vec[:, 0], vec[:, 1], color="tab:green",
                  angles="xy", scale_units="xy", scale=1.0, width=0.014, pivot="middle",
                  zorder=4)
    ax.set_title(title, fontsize="small")


def _key():
    """Legend of the drawing: colours by sign, widths relative to the vector's largest entry
    (a null-space vector has no unit: it is defined up to a factor)."""
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color="tab:red", lw=5), Line2D([], [], color="tab:blue", lw=5),
               Line2D([], [], color="tab:green", marker=">", lw=2),
               Line2D([], [], color="k", lw=5), Line2D([], [], color="k", lw=1)]
    labels = ["R > 0", "R < 0", "S t (arrow: sign and size of S)", "largest |R|",
              "smallest |R| drawn"]
    return handles, labels


def plot_vectors(system: models.System, vectors: list[tuple[np.ndarray, np.ndarray, str]],
                 out: str | Path, suptitle: str = "", max_panels: int = 30) -> Path:
    """Write one figure with a panel per (R, S, title) to `out` (PNG); returns the path."""
    plt = _plt()
    vectors = vectors[:max_panels]
    k = max(len(vectors), 1)
    ncol = min(k, 4)
    nrow = -(-k // ncol)
    lat = system.lattice
    w = max(2.5, 0.45 * lat.lx + 0.8)
    h = max(1.8, 0.45 * lat.ly * (0.87 if lat.name == "tri" else 1.0) + 0.9)
    fig, axes = plt.subplots(nrow, ncol, figsize=(w * ncol, h * nrow), squeeze=False,
                             layout="constrained")
    for ax in axes.flat[len(vectors):]:
        ax.axis("off")
    for ax, (R, S, title) in zip(axes.flat, vectors):
        _draw_vector(ax, system, R, S, title)
    if suptitle:
        fig.suptitle(suptitle)
    fig.legend(*_key(), loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=3,
               fontsize="small", frameon=False)
    path = Path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path


def plot_null_space(ns: NullSpace, out: str | Path, max_panels: int = 30) -> Path:
    """The localized basis of a null space (Fig. 5), one panel per vector."""
    if ns.localized is None:
        raise InvalidInput("compute the localized basis first (null_space(..., localize=True))")
    c = ns.c
    vectors = [(x[:c], x[c:], f"v{k + 1}: {len(ns.contacts_of(x))} contacts")
               for k, x in enumerate(ns.localized.T)]
    lat = ns.system.lattice
    title = f"{lat.name} {lat.lx}x{lat.ly}: ker M, dimension {ns.dim}"
    if ns.dim > max_panels:
        title += f" (first {max_panels} vectors)"
    return plot_vectors(ns.system, vectors, out, title, max_panels)


def plot_loops(system: models.System, loops: LoopBasis, out: str | Path,
               max_panels: int = 30) -> Path:
    """The kinematic loops (left ker K), coefficients drawn as R (Fig. 5b, 5c, 5e)."""
    c = system.c
    vectors = []
    for k, loop in enumerate(loops.loops()):
        R = np.zeros(c)
        for a, v in loop.items():
            R[a] = v
        vectors.append((R, np.zeros(c), f"loop {k + 1}: {len(loop)} NS contacts"))
    lat = system.lattice
    title = f"{lat.name} {lat.lx}x{lat.ly}: loops of NS contacts, {loops.dim}"
    return plot_vectors(system, vectors, out, title, max_panels)
