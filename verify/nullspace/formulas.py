"""The paper's closed forms for the degree of indeterminacy, Eqs. (3.3) and (3.4), checked by SVD.

Conventions, established by computation (docs/verification.md has the derivations and tables):

* Eq. (3.3), kind "normal": every contact -- particle-particle, wall and plane -- transmitting
  and sliding. The count is dim ker M = c - 2p (the sliding forces must balance every disk's
  translation; torques are free), independent of the sliding signs and of mu (mu = 0 included)
  except at isolated coefficients where two sliding force directions on one disk become parallel
  (mu = 1, and in triangular arrays also tan 30 deg and tan 60 deg, for some sign patterns).
  Rectangular: c - 2p = Ly, as the paper says. Triangular: c - 2p = p - Lx - Ly + 2, which is
  *not* the paper's Lx Ly - 2 Ly + 2 (they agree only when Lx = ceil(Ly / 2)).
* Eq. (3.4), kind "tangential": every contact transmitting and non-sliding, walls and plane
  included (rough walls, mu_wall > 0). What the paper counts is the part *added* by the NS
  contacts on top of the normal count: dim ker M(NS) - dim ker M(normal) = c - p, the number of
  independent loops of the contact graph with the walls and the plane merged into one ground
  node. The whole null space is 2c - 3p = Eq. (3.3) + Eq. (3.4) for rectangular arrays.
  Rectangular: c - p = Lx Ly + Ly, the paper's. Triangular: c - p = 2 Lx Ly - 2 Ly - Lx + 2 +
  (Ly mod 2): the paper's when Ly is even (as many full rows as rows in the hollows), one more
  when Ly is odd (the bottom row and the top row are both full rows). With frictionless walls
  (the paper's simulations) the wall contacts add nothing: c - p - (number of wall contacts).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from threadpoolctl import threadpool_limits

from rigidlcp import models
from rigidlcp.lcp.errors import InvalidInput, NotApplicable

from .contact import KINDS, paper_states, svd_rank

LATTICES = ("rect", "tri")
#: Friction used for the counts: generic values (the normal count is the same for any generic
#: mu; the tangential count only needs mu > 0 on the contacts that are NS).
DEFAULT_MU = {"mu_pp": 0.3, "mu_plane": 0.4, "mu_wall": 0.2}


class NoClosedForm(NotApplicable):
    """Eqs. (3.3)/(3.4) are closed forms of the paper's regular arrays; a general packing has
    none (count its null spaces with `null_dim`)."""


def _lattice_name(lattice: str | models.Lattice) -> str:
    """'rect' or 'tri' from a name or a Lattice; a general packing is refused by name."""
    key = str(lattice.name if isinstance(lattice, models.Lattice) else lattice).lower()
    if key in ("rect", "rectangular"):
        return "rect"
    if key in ("tri", "triangular"):
        return "tri"
    if key == "packing":
        raise NoClosedForm("Eqs. (3.3)/(3.4) are closed forms of the regular arrays (rect, "
                           "tri); a general packing has none: count its null space by SVD "
                           "(null_dim)")
    raise InvalidInput(f"lattice must be 'rect' or 'tri', got {lattice!r}")


def closed_forms(lattice: models.Lattice) -> dict[str, int]:
    """Eqs. (3.3) and (3.4) of a built array, {"normal": .., "tangential": ..}, as printed in
    the paper; NoClosedForm for a general packing."""
    name = _lattice_name(lattice)
    return {k: paper_formula(name, lattice.lx, lattice.ly, k) for k in ("normal", "tangential")}


def _kind(kind: str) -> str:
    if kind not in KINDS:
        raise InvalidInput(f"kind must be one of {KINDS}, got {kind!r}")
    return kind


def full_rows(lattice: str, ly: int) -> int:
    """Rows touching both walls: all of them (rect); rows 0, 2, 4, ... (tri: ceil(Ly / 2))."""
    return ly if _lattice_name(lattice) == "rect" else (ly + 1) // 2


def sizes(lattice: str, lx: int, ly: int) -> tuple[int, int]:
    """(p, c) in closed form (models.rectangular / models.triangular).

    rect: p = Lx Ly, c = Ly (Lx + 1) [rows, walls included] + Lx (Ly - 1) [columns] + Lx [plane].
    tri, F full rows of Lx disks and H = Ly - F rows of Lx - 1: p = F Lx + H (Lx - 1),
    c = F (Lx + 1) + H (Lx - 2) [rows] + 2 (Lx - 1)(Ly - 1) [between rows] + Lx [plane].
    """
    if _lattice_name(lattice) == "rect":
        return lx * ly, 2 * lx * ly + ly
    F = full_rows("tri", ly)
    H = ly - F
    p = F * lx + H * (lx - 1)
    c = F * (lx + 1) + H * (lx - 2) + 2 * (lx - 1) * (ly - 1) + lx
    return p, c


def paper_formula(lattice: str, lx: int, ly: int, kind: str) -> int:
    """Eq. (3.3) (kind "normal") or Eq. (3.4) (kind "tangential") as printed in the paper."""
    rect = _lattice_name(lattice) == "rect"
    if _kind(kind) == "normal":
        return ly if rect else lx * ly - 2 * ly + 2
    return lx * ly + ly if rect else 2 * lx * ly - 2 * ly - lx + 2


def closed_form(lattice: str, lx: int, ly: int, kind: str, walls: str = "rough") -> int:
    """The count that the computation confirms (see the module docstring).

    normal: c - 2p = Ly (rect), p - Lx - Ly + 2 (tri).
    tangential, increment over the normal count: c - p, less the wall contacts (2 per full row)
    when walls="frictionless".
    """
    if walls not in ("rough", "frictionless"):
        raise InvalidInput(f"walls must be 'rough' or 'frictionless', got {walls!r}")
    p, c = sizes(lattice, lx, ly)
    if _kind(kind) == "normal":
        return c - 2 * p
    return c - p - (2 * full_rows(lattice, ly) if walls == "frictionless" else 0)


def null_dim(system: models.System, kind: str, signs: np.ndarray | None = None,
             dyn: models.Dynamics | None = None) -> int:
    """dim ker M (SVD, Eq. 3.1) for the states of `paper_states(system, kind, signs)`."""
    M, _ = models.contact_matrix(system, *paper_states(system, kind, signs), dyn=dyn)
    with threadpool_limits(1):  # small dense SVDs: one BLAS thread is fastest
        return M.shape[1] - svd_rank(M)[3]


def _system(lattice: str, lx: int, ly: int, walls: str, mu: dict) -> models.System:
    params = {**DEFAULT_MU, **mu}
    if walls == "frictionless":
        params["mu_wall"] = 0.0
    elif walls != "rough":
        raise InvalidInput(f"walls must be 'rough' or 'frictionless', got {walls!r}")
    elif params["mu_wall"] <= 0:
        raise InvalidInput("walls='rough' needs mu_wall > 0")
    return models.System(models.make_lattice(lattice, lx, ly), **params)


@dataclass
class SingularityCount:
    """One line of the comparison: the paper's closed form beside the computed count."""

    lattice: str
    lx: int
    ly: int
    kind: str
    p: int
    c: int
    paper: int  # Eq. (3.3) or (3.4) as printed
    computed: int  # SVD: dim ker M (normal); dim ker M(NS) - dim ker M(normal) (tangential)
    closed_form: int  # the corrected closed form (equal to `paper` where the paper is right)
    whole: int  # dim ker M for the kind's states
    walls: str

    @property
    def paper_agrees(self) -> bool:
        return self.paper == self.computed

    @property
    def closed_form_agrees(self) -> bool:
        return self.closed_form == self.computed

    def to_dict(self) -> dict:
        return {**asdict(self), "paper_agrees": self.paper_agrees,
                "closed_form_agrees": self.closed_form_agrees}


def paper_singularities(
    lattice: str, lx: int, ly: int, kind: str, walls: str = "rough", **mu: float
) -> SingularityCount:
    """Eq. (3.3) (kind "normal": every contact T and sliding) or Eq. (3.4) (kind "tangential":
    every contact T and NS, zero rotation velocities), with the count computed by SVD.

    walls: "rough" (mu_wall > 0: the wall contacts are NS in the tangential state, the
    convention under which Eq. 3.4 holds) or "frictionless" (mu_wall = 0, as in the paper's
    simulations: S = 0 at the walls). mu: mu_pp, mu_plane, mu_wall overriding DEFAULT_MU.
    """
    return _both(lattice, lx, ly, walls, mu, (_kind(kind),))[0]


def _both(lattice: str, lx: int, ly: int, walls: str, mu: dict,
          kinds=KINDS) -> list[SingularityCount]:
    name = _lattice_name(lattice)
    system = _system(name, lx, ly, walls, mu)
    dyn = models.Dynamics(system)
    normal = null_dim(system, "normal", dyn=dyn)
    tangential = null_dim(system, "tangential", dyn=dyn) if "tangential" in kinds else None
    lat = system.lattice
    out = []
    for kind in kinds:
        whole = normal if kind == "normal" else tangential
        computed = normal if kind == "normal" else tangential - normal  # the NS increment
        out.append(SingularityCount(
            lattice=name, lx=lx, ly=ly, kind=kind, p=lat.p, c=lat.c,
            paper=paper_formula(name, lx, ly, kind), computed=computed,
            closed_form=closed_form(name, lx, ly, kind, walls), whole=whole, walls=walls,
        ))
    return out


def formula_table(
    lattices=LATTICES, lx=range(2, 13), ly=range(1, 9), walls: str = "rough"
) -> list[dict]:
    """One row per (lattice, Lx, Ly): Eqs. (3.3) and (3.4), paper vs SVD vs closed form."""
    rows = []
    for name in lattices:
        for a in lx:
            for b in ly:
                n, t = _both(name, a, b, walls, {})
                rows.append({
                    "lattice": n.lattice, "lx": a, "ly": b, "p": n.p, "c": n.c,
                    "Nn_paper": n.paper, "Nn_svd": n.computed, "Nn_closed": n.closed_form,
                    "Nt_paper": t.paper, "Nt_svd": t.computed, "Nt_closed": t.closed_form,
                    "whole_svd": t.whole, "walls": walls,
                })
    return rows


COLUMNS = ("lattice", "lx", "ly", "p", "c", "Nn_paper", "Nn_svd", "Nn_closed", "Nt_paper",
           "Nt_svd", "Nt_closed", "whole_svd")


def format_table(rows: list[dict], markdown: bool = False) -> str:
    """Text (or Markdown) table; a paper value that differs from the SVD count is starred."""

    def cell(row: dict, col: str) -> str:
        v = str(row[col])
        for kind in ("Nn", "Nt"):
            if col == f"{kind}_paper" and row[col] != row[f"{kind}_svd"]:
                v += "*"
        return v

    table = [[cell(r, col) for col in COLUMNS] for r in rows]
    if markdown:
        lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
        lines += ["| " + " | ".join(t) + " |" for t in table]
        return "\n".join(lines)
    widths = [max(len(col), *(len(t[k]) for t in table)) for k, col in enumerate(COLUMNS)]
    fmt = "  ".join(f"{{:>{w}}}" for w in widths)
    return "\n".join([fmt.format(*COLUMNS)] + [fmt.format(*t) for t in table])


def format_grid(rows: list[dict], lattice: str, kind: str) -> str:
    """Markdown grid, Lx down and Ly across, of the SVD count for one lattice and kind; where
    the paper's value differs it follows in brackets, e.g. "8 [10]"."""
    key = {"normal": "Nn", "tangential": "Nt"}[_kind(kind)]
    sel = [r for r in rows if r["lattice"] == _lattice_name(lattice)]
    lys = sorted({r["ly"] for r in sel})
    cell = {(r["lx"], r["ly"]): r for r in sel}
    lines = ["| Lx \\ Ly | " + " | ".join(map(str, lys)) + " |", "|---" * (len(lys) + 1) + "|"]
    for lx in sorted({r["lx"] for r in sel}):
        out = []
        for ly in lys:
            r = cell[lx, ly]
            v = str(r[f"{key}_svd"])
            if r[f"{key}_paper"] != r[f"{key}_svd"]:
                v += f" [{r[f'{key}_paper']}]"
            out.append(v)
        lines.append(f"| {lx} | " + " | ".join(out) + " |")
    return "\n".join(lines)


def summary(rows: list[dict]) -> dict:
    """How often each closed form agrees with the SVD count, per lattice."""
    out = {}
    for name in sorted({r["lattice"] for r in rows}):
        sel = [r for r in rows if r["lattice"] == name]
        out[name] = {
            "cases": len(sel),
            "Nn_paper_agrees": sum(r["Nn_paper"] == r["Nn_svd"] for r in sel),
            "Nt_paper_agrees": sum(r["Nt_paper"] == r["Nt_svd"] for r in sel),
            "Nn_closed_agrees": sum(r["Nn_closed"] == r["Nn_svd"] for r in sel),
            "Nt_closed_agrees": sum(r["Nt_closed"] == r["Nt_svd"] for r in sel),
            "whole_is_Nn_plus_Nt": sum(r["whole_svd"] == r["Nn_closed"] + r["Nt_closed"]
                                       for r in sel),
        }
    return out
