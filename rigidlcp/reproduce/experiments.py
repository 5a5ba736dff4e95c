"""`rigidlcp reproduce`: the experiments of Sec. IV at the parameters of the figure captions, and
each claim of the paper held against the measured number (PASS / FAIL with the criterion).

Sizes (the captions fix most of them; `plan` says where we chose):

* Fig. 7 (gamma = 0.1 g, mu 0.1 / 0.2 / 0) and Fig. 8 (gamma = 0.2 g, mu 0.05 / 0.2 / 0) give
  no size: 10x4, the size of Fig. 9 (same family of experiments, Lx = 10 as in every sized
  figure), ~5 s per run to the steady state here;
* Fig. 9: 10x4; Fig. 10: 10x2; Fig. 13: 10x3 (captions);
* Figs. 11-12: m_g = 10 (caption of Fig. 12), hence 10x1, gamma from 0 to 0.4 g every 0.005 g:
  both saturations (0.18 g for mu_plane = 0.1, 0.36 g for 0.2) and >= 3 grid points on the
  first linear piece of every curve of Sec. IV B;
* Fig. 6: seven disks on the plane, mu 0.3 / 0.3 (caption); the caption gives no driving. At
  constant velocity (gamma = 0) nothing loads the lateral contacts (frictionless walls) and the
  disks decouple, so an alternating mode needs an acceleration: gamma = 0.05 g, V0 = 0.

Every run is one job on the executor of `models.executors.iter_map` (local processes by
default, or Dask); the claims and figures are computed here from what the jobs return.
`rigidlcp.reproduce.report` writes the figures and report.md.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from rigidlcp import models
from rigidlcp.models.effective import Effective, legendre
from rigidlcp.models.executors import default_jobs
from rigidlcp.models.sweep import Sweep, parse_grid, run_point

BASE = dict(mu_pp=0.1, mu_plane=0.2, mu_wall=0.0)  # Figs. 7, 9, 10 (and 13, see plan)


def plan(quick: bool = False) -> dict[str, dict]:
    """The experiments: system parameters, seeds, grids. quick: small sizes for tests (the
    claims are still all evaluated; sizes differ from the paper's, so some verdicts may too)."""
    r = dict(lattice="rect")
    p = {
        "fig7": dict(r, lx=10, ly=4, gamma=0.1, V0=0.0, **BASE, seeds=(0, 1, 2, 3)),
        "fig8": dict(r, lx=10, ly=4, gamma=0.2, V0=0.0, mu_pp=0.05, mu_plane=0.2, mu_wall=0.0,
                     seeds=(0,), alt_select=("none",)),
        "fig9": dict(r, lx=10, ly=4, gamma=0.16, V0=0.0, **BASE, seeds=(0, 1),
                     scan=(0.04, 0.08, 0.12, 0.2), alt_select=("none", "none/pivoting")),
        "fig10": dict(r, lx=10, ly=2, gamma=0.3, V0=0.0, **BASE, seeds=(0, 1, 2, 3)),
        "fig6": dict(r, lx=7, ly=1, gamma=0.05, V0=0.0, mu_pp=0.3, mu_plane=0.3, mu_wall=0.0,
                     seeds=(0, 1, 2, 3, 4)),
        "fig13": dict(r, lx=10, ly=3, gamma=0.0, V0=1.0, **BASE, seeds=(0, 1, 2)),
        "fig13_tri": dict(lattice="tri", lx=10, ly=3, gamma=0.0, V0=1.0, **BASE,
                          seeds=(0, 1, 2)),
        "fig11": dict(r, lx=10, ly=1, mu_pp=0.05, mu_plane=0.1, mu_wall=0.0,
                      gamma="0:0.4:81", seed=1),
        "formulas": dict(lx=(2, 10), ly=(1, 8)),
    }
    if quick:
        for name in ("fig7", "fig8", "fig9"):
            p[name].update(lx=6, ly=3, seeds=(0, 1) if name == "fig7" else (0,))
        p["fig9"]["scan"] = ()
        p["fig8"]["alt_select"] = p["fig9"]["alt_select"] = ()
        p["fig10"]["seeds"] = (0, 1)
        p["fig6"]["seeds"] = (0, 1)
        p["fig13"].update(lx=6, ly=2, seeds=(0, 1))
        p["fig13_tri"].update(lx=6, ly=2, seeds=(0, 1))
        p["fig11"]["gamma"] = "0:0.4:21"
        p["formulas"] = dict(lx=(2, 5), ly=(1, 4))
    # Sec. IV B: the sweep of Fig. 11 with a rougher plane, and with rougher particles.
    p["ivb_plane"] = dict(p["fig11"], mu_plane=0.2)
    p["ivb_pp"] = dict(p["fig11"], mu_pp=0.1)
    return p


SWEEPS = ("fig11", "ivb_plane", "ivb_pp")
#: The particular-solution rule at non-unique events (models.simulate's default).
SELECT = "face-min-norm"


def system_of(cfg: dict, gamma: float | None = None) -> models.System:
    return models.System(models.make_lattice(cfg["lattice"], cfg["lx"], cfg["ly"]),
                         mu_pp=cfg["mu_pp"], mu_plane=cfg["mu_plane"], mu_wall=cfg["mu_wall"],
                         gamma=cfg["gamma"] if gamma is None else gamma, V0=cfg.get("V0", 0.0))


def jobs_of(p: dict) -> list[tuple]:
    """Every independent computation, longest first (better packing on few workers)."""
    jobs: list[tuple] = []
    for name in ("fig7", "fig8", "fig9", "fig13_tri", "fig13", "fig10", "fig6"):
        cfg = p[name]
        first, gamma = cfg["seeds"][0], cfg["gamma"]
        jobs += [("sim", name, seed, gamma, SELECT) for seed in cfg["seeds"]]
        jobs += [("sim", name, first, g, SELECT) for g in cfg.get("scan", ())]
        jobs += [("sim", name, first, gamma, sel) for sel in cfg.get("alt_select", ())]
    # the raw pivoting selection runs into a zeno accumulation (~75 s on 10x4): start it first
    jobs.sort(key=lambda j: not (j[0] == "sim" and j[4].endswith("/pivoting")))
    for name in ("lx", "ly"):
        lo, hi = p["formulas"][name]
        if not 1 <= lo <= hi:
            raise ValueError(f"formulas: bad {name} range {lo}..{hi}")
    jobs += [("formulas", lat) for lat in ("tri", "rect")]
    for name in SWEEPS:
        cfg = p[name]
        fixed = {k: cfg[k] for k in ("lattice", "lx", "ly", "mu_pp", "mu_plane", "mu_wall",
                                     "seed")}
        for point in Sweep({"gamma": parse_grid("gamma", cfg["gamma"])}, fixed).points():
            jobs.append(("point", name, point))
        # the band: mu_g over every valid steady state at each gamma (valid_steady.py)
        jobs += [("band", name, float(g)) for g in parse_grid("gamma", cfg["gamma"])]
    return jobs


class Job:
    """Picklable job runner (module-level class, for processes and Dask workers)."""

    def __init__(self, p: dict) -> None:
        self.p = p

    def __call__(self, job: tuple):
        kind = job[0]
        if kind == "sim":
            _, name, seed, gamma, select = job
            sel, _, method = select.partition("/")  # "none/pivoting": select none, pivoting
            return models.simulate(system_of(self.p[name], gamma), seed=seed, select=sel,
                                   method=method or "lemke")
        if kind in ("ts", "cert", "sweep-ts"):
            from .crosscheck import check_job

            return check_job(job)
        if kind == "point":
            row = run_point(job[2])
            row.pop("wall_time_s", None)
            return row
        if kind == "band":
            from .valid_steady import BAND_TIME_LIMIT, mu_g_band

            cfg = self.p[job[1]]
            return mu_g_band(cfg, [job[2]], seed=cfg["seed"], time_limit=BAND_TIME_LIMIT)[0]
        if kind == "steady-set":
            from .valid_steady import SET_TIME_LIMIT, steady_set

            return steady_set(job[2], SET_TIME_LIMIT[self.p != plan(quick=False)])
        if kind == "patterns":  # the mode claims over all valid steady states
            from .mode_claims import PATTERN_TIME_LIMIT, judge_patterns

            return judge_patterns(job[1], job[2], PATTERN_TIME_LIMIT[self.p != plan(quick=False)])
        if kind == "formulas":
            from rigidlcp.verify.nullspace.formulas import formula_table

            f = self.p["formulas"]
            return formula_table((job[1],), range(f["lx"][0], f["lx"][1] + 1),
                                 range(f["ly"][0], f["ly"][1] + 1))
        raise ValueError(f"unknown job {job!r}")


@dataclass
class Claim:
    """One claim of the paper against the measurement."""

    id: str
    where: str  # figure / section / equation
    claim: str
    measured: str
    criterion: str
    passed: bool
    note: str = ""
    error: str = ""
    ts_confirmed: bool | None = None  # None: not a steady-state claim (crosscheck.py)
    ts: str = ""  # "kept by the toolkit's time-stepper": the verdict and the drifts
    overall: str = ""  # "over all valid steady states": holds for all / some / none (overall.py)
    determinacy: str = ""  # certified uniqueness at the steady state(s) (crosscheck.py)

    @property
    def verdict(self) -> str:
        return "PASS" if self.passed else "FAIL"


@dataclass
class Results:
    """What the jobs returned, by experiment."""

    plan: dict
    runs: dict[str, dict[tuple[int, float, str], models.Run]] = field(default_factory=dict)
    sweeps: dict[str, list[dict]] = field(default_factory=dict)
    formulas: list[dict] = field(default_factory=list)
    wall_time: float = 0.0
    executor: str = ""
    #: cross-checks of steady states by label (crosscheck.py): experiment name, or
    #: "NAME gamma=G" for sweep points
    ts_checks: dict = field(default_factory=dict)
    certificates: dict = field(default_factory=dict)
    #: per sweep, the mu_g band over every valid steady state at each gamma (valid_steady.py)
    bands: dict[str, list] = field(default_factory=dict)
    #: per STEADY experiment, verify.ranges.SteadyRanges of its first seed's run (or why not)
    steady_sets: dict = field(default_factory=dict)
    #: per experiment, its mode claims over every valid steady state (mode_claims.py)
    patterns: dict = field(default_factory=dict)

    def seeds(self, name: str) -> list[models.Run]:
        cfg = self.plan[name]
        return [self.runs[name][(s, cfg["gamma"], SELECT)] for s in cfg["seeds"]]

    def effective(self, name: str) -> Effective:
        rows = self.sweeps[name]
        gam = np.array([r["gamma"] for r in rows if r["status"] == "steady"])
        F = np.array([r["F_g"] for r in rows if r["status"] == "steady"])
        return legendre(gam, F, float(rows[0]["m_g"]))


def run_all(p: dict, jobs: int | None = None, dask: str | None = None,
            progress: bool = True, cells=None) -> Results:
    """Run every job of plan `p` on the executor and collect the results, in job order.
    cells (saved.Cells): the jobs saved there (an interrupted run) are not run again, and
    every job run is saved there as it finishes (`rigidlcp reproduce --resume`)."""
    from .saved import run_jobs

    todo = jobs_of(p)
    where = f"dask {dask}" if dask else f"{jobs or default_jobs()} local process(es)"
    res = Results(p, executor=where)
    start = time.perf_counter()
    outs = run_jobs(Job(p), todo, jobs=jobs, dask=dask, cells=cells,
                    desc="reproduce" if progress else None)
    for job, out in zip(todo, outs):
        if job[0] == "sim":
            res.runs.setdefault(job[1], {})[job[2:]] = out
        elif job[0] == "point":
            res.sweeps.setdefault(job[1], []).append(out)
        elif job[0] == "band":
            res.bands.setdefault(job[1], []).append(out)
        else:
            res.formulas += out
    for rows in res.sweeps.values():
        rows.sort(key=lambda r: r["gamma"])
    for pts in res.bands.values():
        pts.sort(key=lambda pt: pt.gamma)
    checks = check_jobs(p, res)
    outs = run_jobs(Job(p), checks, jobs=jobs, dask=dask, cells=cells,
                    desc="cross-checks" if progress else None)
    for (kind, label, *_), out in zip(checks, outs):
        {"cert": res.certificates, "steady-set": res.steady_sets,
         "patterns": res.patterns}.get(kind, res.ts_checks)[label] = out
    res.wall_time = time.perf_counter() - start
    if cells is not None and cells.kept:
        code = f", computed by the code at git {cells.other_code}" if cells.other_code else ""
        res.executor += (f" (resumed: {cells.kept} of {len(todo) + len(checks)} jobs taken from "
                         f"the earlier run's {cells.dir}{code}; their time is not counted)")
    return res


#: The experiments whose steady state (first seed, default selection) is cross-checked.
STEADY = ("fig7", "fig8", "fig9", "fig10", "fig6", "fig13", "fig13_tri")
#: The experiments whose mode / contact-state claims are asked of every valid steady state.
PATTERN_EXPERIMENTS = ("fig8", "fig9", "fig6", "fig13", "fig13_tri")
#: Sweep points cross-checked by time-stepping, per sweep (indices into its gamma grid).
SWEEP_POINTS = 5


def sweep_gammas(cfg: dict) -> list[float]:
    """SWEEP_POINTS gammas of a sweep's grid, evenly spread, both ends included."""
    grid = parse_grid("gamma", cfg["gamma"])
    idx = np.unique(np.linspace(0, len(grid) - 1, SWEEP_POINTS).round().astype(int))
    return [float(grid[k]) for k in idx]


def check_jobs(p: dict, res: Results) -> list[tuple]:
    """The cross-check jobs (crosscheck.py) of the runs in `res`: time-stepping and certificate
    of each STEADY experiment's first seed, and its range of mu_g over every valid steady state
    (valid_steady.steady_set); time-stepping at sweep_gammas of each sweep."""
    out: list[tuple] = []
    for name in STEADY:
        cfg = p[name]
        run = res.runs.get(name, {}).get((cfg["seeds"][0], cfg["gamma"], SELECT))
        if run is not None:
            out += [("steady-set", name, run), ("ts", name, run), ("cert", name, run)]
            if name in PATTERN_EXPERIMENTS:
                out.append(("patterns", name, run))
    for name in SWEEPS:
        cfg = p[name]
        for g in sweep_gammas(cfg):
            out.append(("sweep-ts", f"{name} gamma={g:g}", system_of(cfg, g), cfg["seed"]))
    return out


# -- helpers for the claims ----------------------------------------------------------------------


def spread(values: list[np.ndarray]) -> float:
    """Largest difference between any run and the first, over all entries."""
    ref = np.asarray(values[0], float)
    return max((float(np.abs(np.asarray(v, float) - ref).max(initial=0.0)) for v in values),
               default=0.0)


def seed_claim(cid: str, where: str, claim: str, runs: list[models.Run]) -> Claim:
    """Steady state reached, independent of the initial angular velocities (Sec. IV A)."""
    statuses = [r.status for r in runs]
    steady = all(r.steady for r in runs)
    if steady:
        s_mu = spread([[r.last.mu_g] for r in runs])
        s_od = spread([r.last.omega_dot for r in runs])
        s_R = spread([r.last.R for r in runs])
        s_S = spread([r.last.S for r in runs])
        ok = s_mu <= 1e-9 and s_od <= 1e-8 and s_R <= 1e-7 and s_S <= 1e-7
        measured = (f"{len(runs)} seeds, all steady ({', '.join(str(r.n_events) for r in runs)}"
                    f" events); mu_g = {runs[0].last.mu_g:.6f}; spread: mu_g {s_mu:.1e}, "
                    f"omega' {s_od:.1e}, R {s_R:.1e}, S {s_S:.1e}")
    else:
        ok, measured = False, f"statuses {statuses}"
    lat = runs[0].system.lattice
    return Claim(cid, where, claim, f"{lat.name} {lat.lx}x{lat.ly}: " + measured,
                 "every run steady; largest difference between seeds <= 1e-9 (mu_g), "
                 "1e-8 (omega'), 1e-7 (R and S)", ok)


def first_piece(eff: Effective, rel: float = 1e-9) -> int:
    """Number of grid points from gamma_min on the first linear piece: consecutive points whose
    local fit is exact with the same slope as the first point's."""
    n = 0
    scale = max(abs(eff.a[0]), 1.0)
    while n < eff.gamma.size and eff.exact[n] and abs(eff.a[n] - eff.a[0]) <= rel * scale:
        n += 1
    return n


def plateau(eff: Effective, mu_plane: float, tol: float = 1e-9) -> int:
    """Number of grid points, from the end, where mu_g = mu_plane within tol."""
    n = 0
    while n < eff.gamma.size and abs(eff.mu_g[-1 - n] - mu_plane) <= tol:
        n += 1
    return n


def compare(x: np.ndarray, y: np.ndarray, tol: float) -> tuple[int, int, int]:
    """(#x > y, #x == y, #x < y) within tol."""
    d = np.asarray(x) - np.asarray(y)
    return int(np.sum(d > tol)), int(np.sum(np.abs(d) <= tol)), int(np.sum(d < -tol))


def dissipation_profile(run: models.Run) -> dict:
    """D at each event, at the end of each interval, the largest dD/dt within an interval
    (dD/dt = -sum S a_t, constant between events) and the jumps at events (Sec. IV C)."""
    recs = run.records
    D = np.array([r.dissipation for r in recs])
    slope = np.array([-(r.S @ r.at) for r in recs])
    D_end = np.array([-(r.S @ (r.vt + r.at * (recs[k + 1].t - r.t)))
                      for k, r in enumerate(recs[:-1])])
    jumps = D[1:] - D_end
    return {"D": D, "slope": slope, "D_end": D_end, "jumps": jumps}


def ranges(values) -> str:
    """Grid values as contiguous runs of a sorted grid, e.g. "0-0.02, 0.14-0.15" (values given
    as (grid, mask))."""
    grid, mask = values
    out, start = [], None
    for k, on in enumerate(list(mask) + [False]):
        if on and start is None:
            start = k
        if not on and start is not None:
            a, b = grid[start], grid[k - 1]
            out.append(f"{a:g}" if start == k - 1 else f"{a:g}-{b:g}")
            start = None
    return ", ".join(out)


def provenance() -> str:
    """The git commit of the code that ran (+ "dirty" when the tree has changes), if known."""
    import subprocess
    from pathlib import Path

    here = Path(__file__).resolve().parent
    try:
        head = subprocess.run(["git", "-C", str(here), "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True, timeout=10, check=True).stdout
        dirty = subprocess.run(["git", "-C", str(here), "status", "--porcelain",
                                "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10).stdout
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return head.strip() + (" with uncommitted changes" if dirty.strip() else "")


__all__ = ["plan", "jobs_of", "Job", "run_all", "Results", "Claim", "seed_claim", "first_piece",
           "plateau", "compare", "dissipation_profile", "system_of", "spread", "SWEEPS",
           "SELECT", "ranges", "provenance", "STEADY", "sweep_gammas", "check_jobs"]
