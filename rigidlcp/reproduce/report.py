"""Figures and report.md of `rigidlcp reproduce` (from `experiments.Results` and the claims)."""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import numpy as np

from rigidlcp.models.modes import fig5e_loops, row_modes
from rigidlcp.models.plot import (
    UNITS,
    dissipation_curve,
    draw_forces,
    draw_lattice,
    plot_rows,
    step_series,
    time_axis,
)

from .crosscheck import TS_DEFINITION
from .experiments import SELECT, SWEEP_POINTS, Claim, Results, provenance
from .quick import claim_sizes, quick_section, size_differences
from .valid_steady import SEARCH_CLOCK

#: How the report names the clock of its searches' time limits.
CLOCK_WORDS = {"cpu": "CPU seconds of the process", "wall": "wall-clock seconds"}


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: Path) -> Path:
    plt = _plt()
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path


def _size(system) -> tuple[float, float]:
    lat = system.lattice
    return max(5.0, 0.5 * lat.lx + 1.5), max(2.2, 0.5 * lat.ly + 1.2)


def figures(res: Results, out: Path) -> dict[str, Path]:
    """Every figure of the report; returns {name: path}."""
    from rigidlcp.cli.sweep import plot_effective

    plt = _plt()
    files: dict[str, Path] = {}
    smaller = size_differences(res.plan)  # a title cites the paper's figure only at its sizes
    # Fig. 7: angular accelerations at three stages of one run.
    run = res.seeds("fig7")[0]
    w, h = _size(run.system)
    fig, axes = plt.subplots(1, 3, figsize=(3 * w, h))
    for ax, k in zip(axes, (0, run.n_events // 2, run.n_events - 1)):
        rec = run.records[k]
        draw_lattice(ax, run.system, rec.omega_dot,
                     label=r"$\dot\omega$ (" + UNITS["omega_dot"] + ")")
        ax.set_title(f"event {k}, t = {rec.t:.3g}" + (" (steady)" if k == run.n_events - 1
                                                      else ""))
    files["fig7"] = _save(fig, out / "fig7_stages.png")
    # Fig. 8: angular accelerations, normal and friction forces of the steady state.
    files["fig8"] = fig8_steady_state(res.seeds("fig8")[0], out / "fig8_steady_state.png")
    # Fig. 9: steady angular accelerations against position, one panel per row.
    run = res.seeds("fig9")[0]
    fig = plt.figure(figsize=(6.5, 1.0 + 1.1 * run.system.lattice.ly), layout="constrained")
    plot_rows(fig, run.system, run.last.omega_dot,
              title=f"steady state; first-row modes {row_modes(run.system, run.last).text()}")
    files["fig9"] = _save(fig, out / "fig9_rows.png")
    # Fig. 10: mu_g(t) from several initial states.
    fig, ax = plt.subplots(figsize=(6.5, 4))
    for seed, run in zip(res.plan["fig10"]["seeds"], res.seeds("fig10")):
        t, mu = step_series(run, "mu_g")
        ax.step(t, mu, where="post", label=f"seed {seed}")
    time_axis(ax, t)
    ax.set_ylabel(r"$\mu_g = F_g / (m_g\, g)$")
    ax.set_title("global friction coefficient from several initial states"
                 + (" (Fig. 10)" if "fig10" not in smaller else " (quick run)"))
    ax.legend(fontsize="small", title="initial angular velocities")
    files["fig10"] = _save(fig, out / "fig10_mu_g.png")
    # Figs. 11-12 (base system) and Sec. IV B (three systems).
    d = out / "fig11_12"
    d.mkdir(exist_ok=True)
    base = res.effective("fig11")
    mu_g_png, eff_png = plot_effective([("10x1, mu 0.05 / 0.1 / 0", base)], d,
                                       cite="fig11" not in smaller)
    if res.bands.get("fig11"):  # the same figures with the bands over all valid steady states
        mu_g_png, eff_png = band_figures(res, "fig11", d, cite="fig11" not in smaller)
    files["fig11"], files["fig12"] = mu_g_png, eff_png
    d = out / "ivb"
    d.mkdir(exist_ok=True)
    curves = [(f"mu_pp {res.plan[n]['mu_pp']}, mu_plane {res.plan[n]['mu_plane']}",
               res.effective(n)) for n in ("fig11", "ivb_plane", "ivb_pp")]
    files["ivb_mu_g"], files["ivb"] = plot_effective(curves, d)
    # Fig. 13: dissipation rate at constant velocity, rectangular and triangular.
    fig, axes = plt.subplots(1, 2, figsize=(12, 4))
    for ax, name in zip(axes, ("fig13", "fig13_tri")):
        for seed, run in zip(res.plan[name]["seeds"], res.seeds(name)):
            t, D = dissipation_curve(run)
            ax.plot(t, D, lw=1, label=f"seed {seed}")
        lat = run.system.lattice
        ax.set_title(f"{lat.name} {lat.lx}x{lat.ly}, constant velocity")
        time_axis(ax, t)
        ax.set_ylabel(r"$D = -\sum S\,v_t$ (" + UNITS["D"] + ")")
        ax.legend(fontsize="small")
    files["fig13"] = _save(fig, out / "fig13_dissipation.png")
    # Fig. 6: initial and final angular velocities, and the loops of Fig. 5(e).
    run = res.seeds("fig6")[0]
    lat = run.system.lattice
    fig, axes = plt.subplots(1, 2, figsize=(12, 3.2))
    k = np.arange(lat.p)
    axes[0].bar(k - 0.2, run.records[0].omega, 0.4, label="t = 0")
    axes[0].bar(k + 0.2, run.last.omega, 0.4, label=f"steady, t = {run.last.t:.3g}")
    axes[0].set_xlabel("disk (left to right)")
    axes[0].set_ylabel(r"$\omega$ (" + UNITS["omega"] + ")")
    axes[0].legend(fontsize="small")
    draw_lattice(axes[1], run.system, run.last.omega,
                 label=r"$\omega$ (" + UNITS["omega"] + ")")
    pts = lat.x[lat.i] + lat.radius * lat.n
    for loop in fig5e_loops(run.system, run.last):
        axes[1].plot(pts[list(loop), 0], pts[list(loop), 1], "k*", ms=10)
    axes[1].set_title("steady state; stars: Fig. 5(e) loop contacts")
    files["fig6"] = _save(fig, out / "fig6_omega.png")
    return files


def band_figures(res: Results, name: str, out: Path, cite: bool) -> tuple[Path, Path]:
    """Figs. 11-12 as bands: mu_g over every valid steady state at each gamma (the band), and
    m_e, mu_e of the band's two end curves (each a curve of valid steady states), with the
    selection's curve inside; gammas whose band has an undecided end are marked."""
    from .valid_steady import end_families

    plt = _plt()
    pts, eff = res.bands[name], res.effective(name)
    fam = end_families(pts, eff.m_g, eff.g)
    ok = [pt for pt in pts if pt.every.decided]
    bad = [pt.gamma for pt in pts if not pt.every.decided]
    sel = f"this toolkit's selection ({SELECT})"
    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    g = np.array([pt.gamma for pt in ok])
    # `where` given: matplotlib 3.6.0 (our lowest) with newer numpy fails without it
    # (IndexError in cbook.contiguous_regions on a 0-d mask)
    ax.fill_between(g, [pt.every.lo.value for pt in ok], [pt.every.hi.value for pt in ok],
                    where=np.ones(len(g), dtype=bool), color="C0", alpha=0.25, lw=0,
                    label="all valid steady states (band)")
    ax.plot(eff.gamma, eff.mu_g, "o-", ms=3, color="C1", label=sel)
    for x in bad:
        ax.axvline(x, color="red", lw=0.6, ls=":")
    if bad:
        ax.plot([], [], color="red", lw=0.6, ls=":", label="band end not decided (time limit)")
    ax.set_xlabel(r"$\gamma$ / g")
    ax.set_ylabel(r"$\mu_g$")
    ax.set_title("global friction coefficient" + (" (Fig. 11)" if cite else ""))
    ax.legend(fontsize="small")
    mu_png = _save(fig, out / "mu_g.png")
    fig, axes = plt.subplots(1, 2, figsize=(12.0, 4.0), gridspec_kw={"wspace": 0.3})
    for ax, q, ylab, title in (
            (axes[0], "m_e", r"$m_e = m_g + \partial F_g/\partial\gamma$",
             "(a) effective inertia"),
            (axes[1], "mu_e", r"$\mu_e$", "(b) effective friction coefficient")):
        curves = [getattr(e, q) for e in fam.values() if e is not None
                  and np.array_equal(e.gamma, eff.gamma)]
        if curves:
            stack = np.vstack(curves + [getattr(eff, q)])
            ax.fill_between(eff.gamma, stack.min(axis=0), stack.max(axis=0), color="C0",
                            where=np.ones(stack.shape[1], dtype=bool), alpha=0.2, lw=0,
                            label="between the band's end curves")
        for (key, e), style in zip(fam.items(), ("--", ":")):
            if e is not None:
                ax.plot(e.gamma, getattr(e, q), style, color="C0", lw=1.2,
                        label=f"{key} end of the band")
        ax.plot(eff.gamma, getattr(eff, q), "o-", ms=3, color="C1", label=sel)
        ax.set_xlabel(r"$\gamma$ / g")
        ax.set_ylabel(ylab)
        ax.set_title(title + (" (Fig. 12)" if cite else ""))
    axes[0].axhline(eff.m_g, color="grey", lw=0.8, ls="--", label=r"$m_g$")
    axes[0].legend(fontsize="small")
    return mu_png, _save(fig, out / "effective.png")


def fig8_steady_state(run, path: Path) -> Path:
    """Fig. 8: angular accelerations, normal and friction forces of a run's last state."""
    plt = _plt()
    w, h = _size(run.system)
    fig, axes = plt.subplots(3, 1, figsize=(w, 3.3 * h), gridspec_kw={"hspace": 0.55})
    draw_lattice(axes[0], run.system, run.last.omega_dot,
                 label=r"$\dot\omega$ (" + UNITS["omega_dot"] + ")")
    # two lines, left-aligned: on one line the title ran into the colour bar
    axes[0].set_title("(a) angular accelerations\nfirst-row modes "
                      + row_modes(run.system, run.last).text(), loc="left")
    for ax, F, signed, title, sym in (
            (axes[1], run.last.R, False, "(b) normal forces R, width ~ R", "R"),
            (axes[2], run.last.S, True, "(c) friction forces S, width ~ |S|", "S")):
        draw_lattice(ax, run.system)
        draw_forces(ax, run.system, F, signed=signed, name=sym)
        ax.set_title(title)
    return _save(fig, path)


SECTIONS = [
    ("Fig. 7 / Fig. 10: steady state", ("fig7", "fig10"), ("fig7", "fig10")),
    ("Figs. 8-9: collective modes", ("fig8", "fig9"), ("fig8", "fig9")),
    ("Figs. 11-12: global friction, effective inertia and friction", ("fig11", "fig12"),
     ("fig11", "fig12")),
    ("Sec. IV B: dependence on the coefficients", ("ivb",), ("ivb_mu_g", "ivb")),
    ("Fig. 13 / Sec. IV C: dissipation at constant velocity", ("fig13",), ("fig13",)),
    ("Fig. 6 / Fig. 5(e): the alternating indeterminate mode", ("fig6",), ("fig6",)),
    ("Eqs. (3.3)-(3.4)", ("eq",), ()),
]


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def write_report(res: Results, claims: list[Claim], out: Path, files: dict[str, Path],
                 command: str) -> Path:
    """report.md (claims table, sizes, figures, notes) and claims.json."""
    n_pass = sum(c.passed for c in claims)
    code = provenance()
    lines = [
        "# Reproduction of Radjai, Brendel & Roux, PRE 54, 861 (1996)",
        "",
        f"Generated by `{command}` on {res.executor}; {len(claims)} claims, "
        f"**{n_pass} PASS, {len(claims) - n_pass} FAIL**; computing time {res.wall_time:.0f} s; "
        f"code: git {code}.",
        "Conventions: gamma > 0 accelerates the box to +x relative to the plane (the paper's "
        "figures accelerate to the left: mirror image, same physics); r = m = g = 1, "
        "I = m r^2 / 2; steady states by exact event-driven evolution with Lemke's method and "
        f"the particular-solution rule select='{SELECT}' at non-unique events (docs/theory.md).",
        "",
        "**Kept by the toolkit's time-stepper** (rigidlcp/reproduce/crosscheck.py), a "
        "self-consistency check, not an independent confirmation: the time-stepper shares "
        "this toolkit's solvers and follows their points where a step's solution is not "
        "unique; other selection rules reach other valid steady states (rigidlcp "
        f"compare-integrators --ensemble, docs/integrators.md). {TS_DEFINITION}. "
        "Checked at the steady state of the first seed of each experiment and, for the sweeps, "
        f"at {SWEEP_POINTS} gammas of the grid. \"NOT kept\" gives the drift; it does "
        "not change the claim's PASS / FAIL (the claim is the paper against the event-driven "
        "measurement).",
        "",
        "**Determinacy** (certified): the staged certificate "
        "(rigidlcp.verify.certificates.stages, via certify_event) of the last event of that "
        "run: are the angular accelerations and the forces unique, with the stage that decided "
        "([face (a)]: another solution with the same contact states, found by LPs on the face "
        "of the recorded solution); witnesses' sizes in the sections below.",
        "",
        "**Over all valid steady states** (rigidlcp/reproduce/overall.py, issue 21): the "
        "steady states of the rigid model are not unique (docs/mechanics.md, \"Valid steady "
        "states and their ranges\"), so each steady-state claim is also judged over every "
        "valid steady state of its system: holds for all, for some (which), for none, or "
        "unknown (why), with the range of mu_g (verify.ranges.steady_ranges; each end a "
        "checked witness, an end not decided in its time limit is \"unknown (time limit)\" "
        "with the best value met, never a bound). The range and pattern searches count their "
        f"time limits in {CLOCK_WORDS[SEARCH_CLOCK]} (rigidlcp/reproduce/valid_steady.py, "
        "SEARCH_CLOCK), so where a search stops does not depend on the machine's load. "
        "The column \"this toolkit's selection "
        f"(face-min-norm)\" is the verdict on the one state the select='{SELECT}' rule "
        "reaches.",
        "",
        "## Claims",
        "",
        "| id | where | claim | measured | criterion | this toolkit's selection "
        f"({SELECT}) | over all valid steady states | kept by the toolkit's time-stepper "
        "| determinacy (certified) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    smaller = size_differences(res.plan)
    if smaller:
        at = lines.index("## Claims")
        lines[at:at] = ["**Quick run (--quick): not the paper's sizes.** Some experiments ran "
                        "smaller, with fewer seeds or on coarser grids than the full run; their "
                        "verdicts are marked \"quick run\" and may differ from the full run's. "
                        "Claim by claim, what differs and what this run cannot judge: section "
                        "\"Quick run\" below the sizes.", ""]
    for c in claims:
        size = " (quick run, see below)" if claim_sizes(c.id, smaller) else ""
        lines.append(f"| {c.id} | {c.where} | {_cell(c.claim)} | {_cell(c.measured)} | "
                     f"{_cell(c.criterion)} | **{c.verdict}**{size} | "
                     f"{_cell(c.overall or 'n/a')}{size and ' (quick run)'} | {_cell(c.ts)} | "
                     f"{_cell(c.determinacy)} |")
    lines += ["", "## Sizes and parameters", "",
              "| experiment | lattice | size | gamma (g) | V0 | mu_pp / mu_plane / mu_wall | "
              "seeds |", "|---|---|---|---|---|---|---|"]
    for name, cfg in res.plan.items():
        if name == "formulas":
            lines.append(f"| {name} | rect, tri | Lx {cfg['lx'][0]}-{cfg['lx'][1]}, Ly "
                         f"{cfg['ly'][0]}-{cfg['ly'][1]} | - | - | SVD counts | - |")
            continue
        seeds = cfg.get("seeds", (cfg.get("seed"),))
        extra = f"; also gamma = {', '.join(map(str, cfg['scan']))}" if cfg.get("scan") else ""
        lines.append(f"| {name} | {cfg['lattice']} | {cfg['lx']}x{cfg['ly']} | "
                     f"{cfg['gamma']}{extra} | {cfg.get('V0', 0.0)} | {cfg['mu_pp']} / "
                     f"{cfg['mu_plane']} / {cfg['mu_wall']} | {', '.join(map(str, seeds))} |")
    lines += ["", "Sizes of the full run: the captions' where given (Fig. 9 10x4, Fig. 10 "
              "10x2, Fig. 13 10x3, Fig. 12 m_g = 10 hence 10x1); Figs. 7-8 give none: 10x4 like "
              "Fig. 9. Fig. 13 gives no coefficients: those of Figs. 7, 9, 10 (0.1 / 0.2 / 0). "
              "Fig. 6 gives no driving: gamma = 0.05 g (at constant velocity the seven disks "
              "decouple). See docs/reproduction.md.", ""]
    lines += quick_section(claims, smaller)
    by_prefix = {}
    for c in claims:
        by_prefix.setdefault(c.id.split("-")[0], []).append(c)
    for title, prefixes, figs in SECTIONS:
        lines += [f"## {title}", ""]
        for name in figs:
            if name in files:
                rel = files[name].relative_to(out)
                lines += [f"![{name}]({rel.as_posix()})", ""]
        for p in prefixes:
            for c in [c for k, v in by_prefix.items() if k.startswith(p) for c in v]:
                lines.append(f"* **{c.id}: {c.verdict}** (this toolkit's selection). "
                             f"{c.measured}")
                if c.overall and not c.overall.startswith("n/a"):
                    lines.append(f"  Over all valid steady states: {c.overall}.")
                if c.note and (not c.passed or c.id.startswith(("fig12", "fig13-min", "fig9"))):
                    lines.append(f"  {c.note}")
                if c.error:
                    lines.append(f"  Evaluation error: `{_cell(c.error.splitlines()[0])}`")
        lines += _cross_checks(res, claims, prefixes)
        lines.append("")
        if "eq" in prefixes and res.formulas:
            lines += _formula_grids(res)
    path = out / "report.md"
    path.write_text("\n".join(lines) + "\n")
    (out / "claims.json").write_text(json.dumps(
        {"command": command, "wall_time_s": res.wall_time, "executor": res.executor,
         "code": code, "select": SELECT, "timestepping_definition": TS_DEFINITION,
         "timestepping": {k: _check_dict(v) for k, v in res.ts_checks.items()},
         "certificates": {k: _check_dict(v) for k, v in res.certificates.items()},
         "plan": res.plan, "claims": [dict(asdict(c), verdict=c.verdict) for c in claims]},
        indent=1, default=_json) + "\n")
    return path


def _cross_checks(res: Results, claims: list[Claim], prefixes: tuple) -> list[str]:
    """The time-stepping checks and certificates of a section's steady states, in full."""
    from .columns import experiments_of

    labels: list[str] = []
    for c in claims:
        if c.id.startswith(prefixes):
            exps, sweeps = experiments_of(c.id)
            labels += [x for x in exps if x not in labels]
            labels += [k for k in res.ts_checks if k.split(" ")[0] in sweeps and k not in labels]
    out = []
    for label in labels:
        if label in res.ts_checks:
            x = res.ts_checks[label]
            extra = (f" Time-stepper's first row {x.modes_ts} (event-driven {x.modes_ed}), "
                     f"mu_g {x.mu_g_ts:.6f}, max|d force| {x.d_force:.1e}; the event-driven "
                     f"state in the step laws: residual {x.ed_in_step:.1e}; "
                     f"{x.seconds:.1f} s." if not x.error else "")
            out.append(f"* Time-stepping check, {x.text()}.{extra}")
        if label in res.certificates:
            out.append(f"* Certified at the steady state, {res.certificates[label].text()}.")
    return out


def _formula_grids(res: Results) -> list[str]:
    """The SVD counts of Eqs. (3.3)/(3.4), Lx down and Ly across; "n [p]" where the paper's
    closed form p differs from the count n (rigidlcp.verify.nullspace.formulas.format_grid)."""
    from rigidlcp.verify.nullspace.formulas import format_grid

    out = []
    for lat in ("rect", "tri"):
        for kind, eq in (("normal", "3.3"), ("tangential", "3.4")):
            out += [f"{lat}, Eq. ({eq}), {kind} (SVD count [paper's value where it differs]):",
                    "", format_grid(res.formulas, lat, kind), ""]
    return out


def _check_dict(x) -> dict:
    d = {k: v for k, v in vars(x).items() if k != "row_ts"}
    return dict(d, text=x.text())


def _json(obj):
    if isinstance(obj, (np.integer, np.floating, np.bool_)):
        return obj.item()
    if isinstance(obj, tuple):
        return list(obj)
    raise TypeError(type(obj).__name__)


__all__ = ["figures", "write_report"]
