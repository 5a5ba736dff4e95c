"""The figure of `rigidlcp forceset --out`: the packing with every contact force drawn as a
segment (centre to centre, or to the obstacle) of width proportional to R, coloured by its
indeterminacy, the width hi - lo of R's range over the admissible set."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .forceset import ForceSet


def plot_forceset(fs: ForceSet, out: str | Path, max_width: float = 5.0) -> Path:
    """PNG of the packing and its forces: width ~ R of the checked solution, colour ~ R's
    range width (unbounded ranges drawn at the top of the scale, dotted; a range with an
    unknown end dotted, grey)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    from rigidlcp.models.plot import contact_points, draw_lattice

    system, c = fs.system, fs.c
    lat = system.lattice
    height = float(np.max(lat.x[:, 1] + lat.radii))
    w = 8.0
    h = max(3.0, min(14.0, w * height / max(lat.width, 1e-12)))
    fig, ax = plt.subplots(figsize=(w, h + 0.8), layout="constrained")
    draw_lattice(ax, system)
    a, b = contact_points(system)
    R = np.maximum(fs.solution[:c], 0.0)
    spread = np.where(np.isinf(fs.hi[:c]), np.inf, fs.hi[:c] - fs.lo[:c])
    finite = np.isfinite(spread)
    top = float(np.max(spread[finite], initial=0.0)) or 1.0
    colour = np.where(np.isinf(spread), top, spread)  # NaN (an unknown end): grey
    widths = max_width * R / max(float(R.max(initial=0.0)), 1e-300)
    segs = LineCollection(np.stack([a, b], axis=1), linewidths=np.maximum(widths, 0.2),
                          cmap=matplotlib.colormaps["viridis"].with_extremes(bad="0.6"),
                          linestyles=[":" if not f else "-" for f in finite])
    segs.set_array(np.ma.masked_invalid(colour))
    segs.set_clim(0.0, top)
    ax.add_collection(segs)
    cb = fig.colorbar(segs, ax=ax, shrink=0.7, pad=0.02)
    cb.set_label("indeterminacy of R: max R - min R over the admissible set (m g)")
    ax.set_title(f"{lat.title()}: admissible forces, dimension {fs.dimension}; width ~ R of "
                 "one checked equilibrium", fontsize="small")
    return _save_png(fig, out)


def plot_pf(f: np.ndarray | dict, out: str | Path, bins: int = 40) -> Path:
    """PNG of the force distribution P(f), f = R / <R> (verify.statics.ensemble): a histogram
    density on linear and logarithmic axes. f: one array, or {label: array} for several."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt


    series = f if isinstance(f, dict) else {"": f}
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6), layout="constrained")
    top = max(float(np.max(v, initial=0.0)) for v in series.values()) or 1.0
    edges = np.linspace(0.0, top, bins + 1)
    for label, v in series.items():
        dens, _ = np.histogram(v, bins=edges, density=True)
        mid = 0.5 * (edges[1:] + edges[:-1])
        for ax in axes:
            ax.plot(mid, dens, drawstyle="steps-mid", label=label or None)
    axes[1].set_yscale("log")
    for ax in axes:
        ax.set_xlabel("f = R / <R>")
        ax.set_ylabel("P(f)")
    if len(series) > 1:
        axes[0].legend(fontsize="small")
    return _save_png(fig, out)


def _save_png(fig, out: str | Path) -> Path:
    """Write `fig` to `out` as a PNG, atomically (a failed write leaves no partial file), and
    close it."""
    import matplotlib.pyplot as plt

    from rigidlcp.lcp.io.files import atomic_write

    out = Path(out)

    def write(tmp: str) -> None:
        fig.savefig(tmp, format="png", dpi=110)

    atomic_write(out, write)
    plt.close(fig)
    return out
