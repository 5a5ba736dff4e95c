"""What a quick run (`rigidlcp reproduce --quick`) changes against the full run, claim by claim
(issue 24.2): the experiments that ran at other sizes, seeds or grids, and what the quick
verdicts therefore cannot judge. The full run's sizes are the paper's where it gives them.
"""

from __future__ import annotations

import numpy as np

from .columns import experiments_of
from .experiments import Claim, plan


def size_differences(used: dict) -> dict[str, str]:
    """{experiment: "what differs from the full run"} for the experiments of `used` whose
    size, seeds or grid are not the full run's (the paper's where it gives them)."""
    full = plan(quick=False)
    out = {}
    for name, cfg in used.items():
        ref = full.get(name)
        if ref is None:
            continue
        diff = []
        if name == "formulas":
            if cfg != ref:
                diff.append(f"Lx {cfg['lx'][0]}-{cfg['lx'][1]}, Ly {cfg['ly'][0]}-{cfg['ly'][1]}"
                            f" (full: Lx {ref['lx'][0]}-{ref['lx'][1]}, "
                            f"Ly {ref['ly'][0]}-{ref['ly'][1]})")
        else:
            if (cfg["lx"], cfg["ly"]) != (ref["lx"], ref["ly"]):
                diff.append(f"{cfg['lx']}x{cfg['ly']} (full: {ref['lx']}x{ref['ly']})")
            for key, what in (("seeds", "seeds"), ("scan", "other gammas"),
                              ("alt_select", "other selections"), ("gamma", "gamma grid")):
                if key in ref and tuple(np.atleast_1d(cfg.get(key, ()))) != tuple(
                        np.atleast_1d(ref[key])):
                    diff.append(f"{what} {_fmt(cfg.get(key))} (full: {_fmt(ref[key])})")
        if diff:
            out[name] = "; ".join(diff)
    return out


def _fmt(v) -> str:
    if isinstance(v, (tuple, list)):
        return ", ".join(repr(x) if isinstance(x, str) else str(x) for x in v) if v else "none"
    return str(v)


#: What a claim cannot judge at smaller sizes, beyond "the verdict is this size's".
_CANNOT = {
    "fig8": "the modes of Fig. 8 are those of a 10x4 array: rows and columns of another size "
            "may settle in other modes",
    "fig9": "Fig. 9 counts nine of the ten disks of a 10-disk first row (4/3/2): a shorter row "
            "cannot show those counts, so this verdict says nothing about the paper's",
    "fig13": "the paper's rates are those of 10x3 arrays; which contacts end sliding depends on "
             "the size",
    "fig11": "a coarser gamma grid resolves fewer of F_g's kinks",
    "fig12": "a coarser gamma grid resolves fewer of F_g's kinks (see `rigidlcp effective`)",
    "ivb": "a coarser gamma grid resolves fewer of F_g's kinks: the effective values come from "
           "chords across more of them",
    "eq": "fewer (Lx, Ly) cases are compared",
    "fig7": "fewer seeds: the independence of the steady state from the initial one is tried "
            "on fewer initial states (and the array is smaller)",
    "fig10": "fewer seeds: the independence of mu_g from the initial state is tried on fewer "
             "initial states",
    "fig6": "fewer seeds: fewer initial states are followed to the alternating mode",
}


def claim_sizes(cid: str, smaller: dict[str, str]) -> list[str]:
    """The experiments of claim `cid` run at other sizes than the full run's."""
    exps, sweeps = experiments_of(cid)
    names = ["formulas"] if cid.startswith("eq") else [*exps, *sweeps]
    return [n for n in names if n in smaller]


def quick_section(claims: list[Claim], smaller: dict[str, str]) -> list[str]:
    """Claim by claim, where the sizes differ from the full run and what that leaves unjudged
    (nothing when every experiment ran at the full run's sizes)."""
    if not smaller:
        return []
    out = ["## Quick run: sizes, seeds and grids that are not the full run's", "",
           "This report comes from a quick run (`--quick`): the experiments below ran smaller, "
           "with fewer seeds or on coarser grids than the full run (`rigidlcp reproduce` "
           "without --quick), whose sizes are the paper's where it gives them. The table of "
           "sizes above lists what ran. Every claim is still evaluated, but a verdict marked "
           "\"quick run\" is the verdict at these settings: it may differ from the full "
           "run's, and does not judge the paper's claim.", ""]
    out += [f"* {name}: {what}" for name, what in smaller.items()]
    out.append("")
    for c in claims:
        names = claim_sizes(c.id, smaller)
        if not names:
            continue
        key = next((k for k in _CANNOT if c.id.startswith(k)), None)
        why = f" Cannot judge: {_CANNOT[key]}." if key else ""
        out.append(f"* **{c.id}: {c.verdict} in the quick run** ({', '.join(names)}).{why}")
    unaffected = [c.id for c in claims if not claim_sizes(c.id, smaller)]
    if unaffected:
        out.append(f"* At the full run's sizes (verdicts comparable): {', '.join(unaffected)}.")
    return out + [""]


__all__ = ["size_differences", "claim_sizes", "quick_section"]
