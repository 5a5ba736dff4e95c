"""Figures of a run, in the manner of the paper's Figs. 7-10 and 13 (matplotlib, Agg backend)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rigidlcp.models.engine.records import Run

from .lattice import LEFT_WALL, PLANE, RIGHT_WALL
from .system import System

#: The files `plot_run` writes, in order.
PLOT_FILES = ("angular_acceleration.png", "angular_velocity.png",
              "angular_acceleration_rows.png", "normal_forces.png", "friction_forces.png",
              "mu_g.png", "dissipation.png")
#: The files `plot_run` writes for a packing (no rows: the contact states instead).
PACKING_PLOT_FILES = tuple("contact_states.png" if f == "angular_acceleration_rows.png" else f
                           for f in PLOT_FILES)


def plot_files(system: System) -> tuple[str, ...]:
    """The files `plot_run` writes for a run of `system`: PLOT_FILES for an array, else
    PACKING_PLOT_FILES."""
    return PLOT_FILES if system.lattice.regular else PACKING_PLOT_FILES


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


#: Units of the quantities drawn (r = m = g = 1, docs/mechanics.md).
UNITS = {"omega_dot": "g / r", "omega": "sqrt(g / r)", "t": "sqrt(r / g)", "force": "m g",
         "D": "m g sqrt(g r)"}


def draw_lattice(ax, system: System, values: np.ndarray | None = None, label: str = "",
                 cmap: str = "coolwarm") -> None:
    """Disks (coloured by `values`, symmetric colour scale, with a colourbar of this panel's
    own whose label `label` is written horizontally below it), walls and plane."""
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle

    lat = system.lattice
    r = lat.radius
    patches = [Circle(tuple(x), ri) for x, ri in zip(lat.x, lat.radii)]
    coll = PatchCollection(patches, edgecolor="k", linewidth=0.6)
    if values is not None:
        vmax = max(np.abs(values).max(initial=0.0), 1e-12)
        coll.set_array(np.asarray(values))
        coll.set_cmap(cmap)
        coll.set_clim(-vmax, vmax)
    else:
        coll.set_facecolor("whitesmoke")
    ax.add_collection(coll)
    if values is not None:
        cb = ax.figure.colorbar(coll, ax=ax, shrink=0.8, pad=0.02)
        cb.ax.set_xlabel(label, fontsize="small")  # horizontal, below the bar
    top = float(np.max(lat.x[:, 1] + lat.radii))
    lo = lat.left if lat.left is not None else float(np.min(lat.x[:, 0] - lat.radii))
    hi = lo + lat.width
    for wall in (lat.left, lat.right):
        if wall is not None:
            ax.plot([wall, wall], [0, top], "k-", lw=2)
    ax.plot([lo - 0.3 * r, hi + 0.3 * r], [0, 0], "k-", lw=2)
    ax.set_xlim(lo - 0.5 * r, hi + 0.5 * r)
    ax.set_ylim(-0.5 * r, top + 0.5 * r)
    ax.set_aspect("equal")
    ax.axis("off")


def contact_points(system: System) -> tuple[np.ndarray, np.ndarray]:
    """Segment ends of every contact: disk centre to disk centre, or to the obstacle's surface."""
    lat = system.lattice
    a = lat.x[lat.i]
    b = np.where((lat.j >= 0)[:, None], lat.x[np.maximum(lat.j, 0)],
                 a + lat.radii[lat.i][:, None] * lat.n)
    return a, b


def draw_forces(ax, system: System, F: np.ndarray, signed: bool = False,
                max_width: float = 6.0, fmax: float | None = None, key: bool = True,
                name: str = "R") -> float:
    """Contact forces as segments from centre to centre (or to the obstacle) whose width is
    proportional to |F| (Fig. 8b-c, Fig. 4): `max_width` points for `fmax` (default: the
    largest |F|; pass one value to share a scale between panels). signed: colour by sign (red
    +, blue -), for friction forces. key: a width scale below the panel. Returns fmax."""
    from matplotlib.collections import LineCollection

    a, b = contact_points(system)
    fmax = max(np.abs(F).max(initial=0.0), 1e-12) if fmax is None else fmax
    widths = max_width * np.abs(F) / fmax
    colors = ["tab:red" if f > 0 else "tab:blue" for f in F] if signed else "k"
    segs = np.stack([a, b], axis=1)
    keep = widths > 1e-3
    if np.any(keep):
        ax.add_collection(LineCollection(segs[keep], linewidths=widths[keep],
                                         colors=np.array(colors)[keep] if signed else colors))
    if key:
        force_key(ax, fmax, max_width, name=name, signed=signed)
    return fmax


def force_key(ax, fmax: float, max_width: float, name: str = "R", signed: bool = False) -> None:
    """A legend below the panel: segment widths for |F| = fmax, fmax/2, fmax/4 (in m g)."""
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color="k", lw=max_width * f) for f in (1.0, 0.5, 0.25)]
    labels = [f"|{name}| = {fmax * f:.3g} m g" for f in (1.0, 0.5, 0.25)]
    if signed:
        handles += [Line2D([], [], color=c, lw=3) for c in ("tab:red", "tab:blue")]
        labels += [f"{name} > 0", f"{name} < 0"]
    # at most three entries a row: five in one row ran past a narrow figure and were clipped
    ax.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0),
              ncol=min(len(labels), 3), fontsize="x-small", frameon=False, handlelength=2.5)


#: The colours of the contact states (draw_states): state -> (colour, legend).
STATE_STYLE = {"NT": ("0.6", "not transmitting (R = 0)"), "NS": ("tab:green", "non-sliding"),
               "+": ("tab:red", "sliding, v_t > 0"), "-": ("tab:blue", "sliding, v_t < 0")}


def contact_states(R: np.ndarray, s: np.ndarray, tol: float = 0.0) -> list[str]:
    """Each contact's state after an event: NT (R <= tol), else NS, + or - (its s)."""
    return ["NT" if Ra <= tol else {0: "NS", 1: "+", -1: "-"}[int(sa)] for Ra, sa in zip(R, s)]


def draw_states(ax, system: System, R: np.ndarray, s: np.ndarray, max_width: float = 6.0
                ) -> int:
    """Every contact as a segment (centre to centre, or to the obstacle) coloured by its state
    (STATE_STYLE), width proportional to R (NT contacts thin and dashed); returns the number of
    segments drawn (one per contact)."""
    from matplotlib.collections import LineCollection
    from matplotlib.lines import Line2D

    a, b = contact_points(system)
    tol = 1e-12 * max(float(np.max(np.abs(R), initial=0.0)), 1e-300)
    states = contact_states(R, s, tol)
    rmax = max(float(np.max(R, initial=0.0)), 1e-12)
    widths = [0.6 if st == "NT" else 0.8 + max_width * Ra / rmax for st, Ra in zip(states, R)]
    coll = LineCollection(np.stack([a, b], axis=1), linewidths=widths,
                          colors=[STATE_STYLE[st][0] for st in states],
                          linestyles=["--" if st == "NT" else "-" for st in states])
    ax.add_collection(coll)
    seen = [k for k in STATE_STYLE if k in states]
    ax.legend([Line2D([], [], color=STATE_STYLE[k][0], lw=3) for k in seen],
              [f"{STATE_STYLE[k][1]}: {states.count(k)}" for k in seen], loc="upper center",
              bbox_to_anchor=(0.5, 0.0), ncol=2, fontsize="x-small", frameon=False)
    return len(states)


def plot_rows(fig, system: System, omega_dot: np.ndarray, title: str = "") -> None:
    """Fig. 9: the angular accelerations against the position along each row, one panel per
    row (top row at the top, shared axes), so that rows with equal values do not hide each
    other."""
    lat = system.lattice
    axes = fig.subplots(lat.ly, 1, sharex=True, sharey=True, squeeze=False)[:, 0]
    lim = max(float(np.abs(omega_dot).max(initial=0.0)), 1e-12) * 1.15
    for k, ax in enumerate(axes):
        row = lat.ly - 1 - k
        sel = np.flatnonzero(lat.row == row)
        sel = sel[np.argsort(lat.x[sel, 0])]
        ax.plot(lat.x[sel, 0], omega_dot[sel], "o-", ms=4, color=f"C{row % 10}")
        ax.axhline(0, color="grey", lw=0.5)
        ax.set_ylim(-lim, lim)
        ax.text(1.01, 0.5, f"row {row + 1}", transform=ax.transAxes, va="center",
                fontsize="small")
    axes[-1].set_xlabel("x / r (position along the row)")
    fig.supylabel(r"$\dot\omega$ (" + UNITS["omega_dot"] + ")")
    if title:
        axes[0].set_title(title, fontsize="medium")


#: The one linear threshold of every symmetric-log time axis (in sqrt(r / g)): times below it
#: are drawn linearly (t = 0 included), above it logarithmically.
TIME_LINTHRESH = 1e-3


def time_axis(ax, t: np.ndarray) -> None:
    """A time axis that shows the transient: symmetric-log (linear below TIME_LINTHRESH,
    logarithmic above; on a linear scale the early events are squeezed against the axis) when
    the times span more than two decades above the threshold, else linear. The label says
    which."""
    t = np.asarray(t)
    if t.size and t.max() > 100 * TIME_LINTHRESH:
        ax.set_xscale("symlog", linthresh=TIME_LINTHRESH, linscale=1.0)
        ax.set_xlabel(f"t ({UNITS['t']}); symlog: linear below {TIME_LINTHRESH:g}, "
                      "logarithmic above")
    else:
        ax.set_xlabel(f"t ({UNITS['t']})")


def step_series(run: Run, name: str) -> tuple[np.ndarray, np.ndarray]:
    """A per-event quantity as a piecewise-constant curve up to the end of the run."""
    t = run.array("t")
    v = run.array(name)
    t_end = run.final.t if run.final is not None else t[-1]
    t_end = max(t_end, t[-1] + 0.1 * max(t[-1], 1.0)) if run.steady else t_end
    return np.append(t, t_end), np.append(v, v[-1])


def dissipation_curve(run: Run, samples: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """D(t) = -sum S (v_t + a_t (t - t_k)): linear within each inter-event interval."""
    ts, ds = [], []
    times, t_end = step_series(run, "t")
    for k, rec in enumerate(run.records):
        t1 = times[k + 1] if k + 1 < len(run.records) else t_end[-1]
        tt = np.linspace(rec.t, t1, samples)
        ts.append(tt)
        ds.append(-(rec.S @ (rec.vt[:, None] + rec.at[:, None] * (tt - rec.t))))
    return np.concatenate(ts), np.concatenate(ds)


def plot_run(run: Run, outdir: str | Path, event: int = -1) -> list[Path]:
    """Write the figures of a run to `outdir`; returns the files written."""
    plt = _plt()
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    system = run.system
    rec = run.records[event]
    files = []

    def save(fig, name: str) -> None:
        path = out / name
        fig.savefig(path, dpi=130, bbox_inches="tight")
        plt.close(fig)
        files.append(path)

    lat = system.lattice
    size = (max(6.0, 0.6 * lat.lx + 2), max(3.0, 0.6 * lat.ly * (0.87 if lat.name == "tri" else 1)
                                            + 1.8))
    when = f"t = {rec.t:.4g} ({run.status}, event {event % run.n_events})"
    for name, values, label, unit in (
            ("angular_acceleration", rec.omega_dot, r"$\dot\omega$", UNITS["omega_dot"]),
            ("angular_velocity", rec.omega, r"$\omega$", UNITS["omega"])):
        fig, ax = plt.subplots(figsize=size)
        draw_lattice(ax, system, values, label=f"{label} ({unit})")
        ax.set_title(f"{label} at {when}")
        save(fig, f"{name}.png")
    if lat.regular:  # Fig. 9: angular accelerations against the position in each row.
        fig = plt.figure(figsize=(6.5, 1.0 + 1.1 * lat.ly), layout="constrained")
        plot_rows(fig, system, rec.omega_dot, title=f"angular accelerations by row, {when}")
        save(fig, "angular_acceleration_rows.png")
    else:  # a packing has no rows: its contact states and normal forces
        fig, ax = plt.subplots(figsize=size)
        draw_lattice(ax, system)
        draw_states(ax, system, rec.R, rec.s)
        ax.set_title(f"contact states at {when}; width ~ R")
        save(fig, "contact_states.png")
    for name, F, signed, title, sym in (
            ("normal_forces", rec.R, False, "normal forces R", "R"),
            ("friction_forces", rec.S, True, "friction forces S", "S")):
        fig, ax = plt.subplots(figsize=size)
        draw_lattice(ax, system)
        draw_forces(ax, system, F, signed=signed, name=sym)
        ax.set_title(f"{title} at {when}; width ~ |{sym}|")
        save(fig, f"{name}.png")
    # Fig. 10: mu_g(t); Fig. 13: dissipation rate.
    fig, ax = plt.subplots(figsize=(6.5, 4))
    t, mu = step_series(run, "mu_g")
    ax.step(t, mu, where="post")
    time_axis(ax, t)
    ax.set_ylabel(r"$\mu_g = F_g / (m_g\, g)$")
    ax.set_title("global friction coefficient")
    save(fig, "mu_g.png")
    fig, ax = plt.subplots(figsize=(6.5, 4))
    t, D = dissipation_curve(run)
    ax.plot(t, D)
    time_axis(ax, t)
    ax.set_ylabel(f"dissipation rate D ({UNITS['D']})")
    ax.set_title(r"dissipation rate $D = -\sum S\, v_t$")
    save(fig, "dissipation.png")
    return files


__all__ = ["PLOT_FILES", "PACKING_PLOT_FILES", "plot_files", "draw_states", "contact_states",
           "UNITS", "plot_run", "draw_lattice", "draw_forces", "force_key",
           "plot_rows", "time_axis", "TIME_LINTHRESH", "dissipation_curve", "step_series",
           "LEFT_WALL", "RIGHT_WALL", "PLANE"]
