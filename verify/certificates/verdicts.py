"""What the staged uniqueness certificate (verify.certificates.stages) establishes: one
`Verdict` per question (UNIQUE, OTHER: "another solution exists", UNKNOWN), the `Witness` of
another solution when one is found, and the `StagedCertificate` that holds them, with their
JSON (to_dict) and text forms. Split from stages.py by job (session 8); re-exported there.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

UNIQUE, OTHER, UNKNOWN = "unique", "another solution exists", "unknown"


@dataclass
class Witness:
    """Another solution z: its independent scaled residual, |z - z*|_inf / z_s (distance), the
    relative difference in the observable, the pairs whose sign pattern flips (changed), the
    degenerate pairs of z* it leaves (z_i > 0 or w_i > 0 where z*_i = w*_i = 0: e.g. R > 0 at
    a contact where z* had R = a_n = 0), and how it was found."""

    z: np.ndarray
    residual: float
    distance: float
    difference: float
    changed: list[int]
    same_states: bool
    found_by: str
    degenerate_left: list[int] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"residual": self.residual, "distance": self.distance,
                "difference": self.difference, "changed": self.changed,
                "same_states": self.same_states, "found_by": self.found_by,
                "degenerate_left": self.degenerate_left}


@dataclass
class Verdict:
    """One question. verdict: UNIQUE / OTHER / UNKNOWN; stage: which stage decided (or the
    last tried); reason: in words; ranges: [min, max] over the face of each row of L (rows
    constant on A(z*) have min = max = L z*; +-inf: unbounded); scope: what "unique" is
    relative to."""

    name: str
    verdict: str = UNKNOWN
    stage: str = ""
    reason: str = ""
    seconds: float = 0.0
    witness: Witness | None = None
    lo: np.ndarray | None = None
    hi: np.ndarray | None = None
    scope: str = ""

    @property
    def face_width(self) -> float:
        if self.lo is None:
            return float("nan")
        return float(np.max(self.hi - self.lo, initial=0.0))

    def to_dict(self) -> dict:
        """Strict JSON: face_width is null when the ranges were not computed (NaN) and
        "unbounded" is true when a range is infinite (JSON has neither NaN nor Infinity)."""
        width = self.face_width
        return {"verdict": self.verdict, "stage": self.stage, "reason": self.reason,
                "seconds": round(self.seconds, 4), "scope": self.scope,
                "face_width": width if np.isfinite(width) else None,
                "face_unbounded": bool(np.isinf(width)),
                "witness": None if self.witness is None else self.witness.to_dict()}


@dataclass
class StagedCertificate:
    """What `certify_stages` established; see the module docstring."""

    accepted: bool
    scaled_residual: float
    n: int
    verdicts: dict[str, Verdict] = field(default_factory=dict)
    degenerate: list[int] = field(default_factory=list)
    face_dim: int = 0
    log: list[str] = field(default_factory=list)  # every stage tried, with its time
    seconds: float = 0.0

    def to_dict(self) -> dict:
        return {"accepted": self.accepted, "scaled_residual": self.scaled_residual,
                "n": self.n, "degenerate": self.degenerate, "face_dim": self.face_dim,
                "seconds": round(self.seconds, 4), "log": self.log,
                "verdicts": {k: v.to_dict() for k, v in self.verdicts.items()}}

    def __repr__(self) -> str:
        lines = [f"StagedCertificate: {'ACCEPTED' if self.accepted else 'REJECTED'} "
                 f"(scaled residual {self.scaled_residual:.2e}), n = {self.n}, face dim "
                 f"{self.face_dim}, degenerate pairs {self.degenerate}, {self.seconds:.2f} s"]
        for v in self.verdicts.values():
            lines.append(f"  {v.name:<14}: {v.verdict:<24} [{v.stage}] {v.reason}")
            if v.witness is not None:
                w = v.witness
                lines.append(f"  {'':<14}  witness ({w.found_by}): residual {w.residual:.1e}, "
                             f"|dz|/z_s = {w.distance:.3g}, d{v.name} = {w.difference:.3g}, "
                             f"{len(w.changed)} pairs change state, leaves "
                             f"{len(w.degenerate_left)} degenerate pairs")
        lines += [f"  stage: {s}" for s in self.log]
        return "\n".join(lines)
