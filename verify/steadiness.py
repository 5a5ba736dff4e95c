"""The valid steady state, one definition (docs/mechanics.md, "Valid steady states and their
ranges"), for every check of steadiness in verify: `verify.integrators.event_check` (a run's
record), `verify.certificates.run.steady_state` (a witness at a steady event) and
`verify.ranges.witness.steady_check` (a witness of the steady-state ranges).

A state (omega, V; R, S) with accelerations a = H nu' + u_obs' of its forces,
nu' = M^-1 (H^T lambda + f), and tangential states s (+1 / -1 sliding with sgn v_t, 0
non-sliding or frictionless) is a valid steady state iff

    kinematics: no translation (nu'_trans = 0) and a_n = 0 on every contact;
                a non-sliding frictional contact keeps a_t = 0;
                a sliding contact never decelerates, s a_t >= 0;
    laws:       R >= 0; |S| <= mu R; S = 0 where mu = 0; sliding: S = -s mu R.

`steadiness` measures each condition per contact (per disk for the translation), relative:
forces to `f_scale`, accelerations to `a_scale`; `Steadiness.failing(tol)` names the contacts
over tol, `.residual` is the largest violation. The callers differ only in where their states
and scales come from (`from_velocities`: states read off v_t, as the ranges' witnesses; an
event's: the states after the event, so that a contact starting to slide counts as sliding).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.system import System

#: The kinematic conditions (what an event's laws leave open) and the contact laws.
KINEMATICS = ("translation", "a_n", "non-sliding a_t", "decelerating")
LAWS = ("R >= 0", "cone", "frictionless S", "sliding law")


@dataclass
class Steadiness:
    """Relative violations of each condition of the definition (module doc)."""

    violations: dict[str, np.ndarray]
    s: np.ndarray  # the tangential states judged

    @property
    def residual(self) -> float:
        return float(max((np.max(v, initial=0.0) for v in self.violations.values()),
                         default=0.0))

    def failing(self, tol: float, conditions: tuple[str, ...] = KINEMATICS + LAWS
                ) -> dict[str, np.ndarray]:
        """{condition: indices over tol} for the conditions asked that fail."""
        out = {}
        for name in conditions:
            v = self.violations.get(name)
            if v is not None and np.any(v > tol):
                out[name] = np.flatnonzero(v > tol)
        return out

    def steady(self, tol: float, conditions: tuple[str, ...] = KINEMATICS + LAWS) -> bool:
        return not self.failing(tol, conditions)

    def reason(self, tol: float, conditions: tuple[str, ...] = KINEMATICS + LAWS) -> str:
        """Why the state is not steady at tol, or what holds."""
        text = {"translation": "disks with a translational acceleration",
                "a_n": "contacts with a_n != 0",
                "non-sliding a_t": "non-sliding transmitting contacts with a_t != 0",
                "decelerating": "sliding contacts decelerate",
                "R >= 0": "contacts with R < 0", "cone": "contacts outside the cone",
                "frictionless S": "frictionless contacts with S != 0",
                "sliding law": "sliding contacts with S != -s mu R"}
        fails = self.failing(tol, conditions)
        why = [f"{idx.size} {text[name]} (e.g. {idx[:5].tolist()})"
               for name, idx in fails.items()]
        return "; ".join(why) or ("steady: a_n = 0, non-sliding a_t = 0, no sliding contact "
                                  "decelerating")


def steadiness(system: System, R, S, s, a_n, a_t, *, f_scale: float, a_scale: float,
               trans: np.ndarray | None = None) -> Steadiness:
    """The relative violations of the definition (module doc) by forces R, S, states s and
    accelerations a_n, a_t (trans: the disks' translational accelerations, when known)."""
    mu = system.mu
    R, S = np.asarray(R, dtype=float), np.asarray(S, dtype=float)
    s = np.where(mu > 0, np.asarray(s, dtype=int), 0)
    a_n, a_t = np.asarray(a_n, dtype=float), np.asarray(a_t, dtype=float)
    v = {"a_n": np.abs(a_n) / a_scale,
         "non-sliding a_t": np.where((s == 0) & (mu > 0), np.abs(a_t), 0.0) / a_scale,
         "decelerating": np.where(s != 0, np.maximum(-s * a_t, 0.0), 0.0) / a_scale,
         "R >= 0": np.maximum(-R, 0.0) / f_scale,
         "cone": np.maximum(np.abs(S) - mu * R, 0.0) / f_scale,
         "frictionless S": np.where(mu == 0, np.abs(S), 0.0) / f_scale,
         "sliding law": np.where(s != 0, np.abs(S + s * mu * R), 0.0) / f_scale}
    if trans is not None:
        v["translation"] = np.abs(np.asarray(trans, dtype=float)) / a_scale
    return Steadiness(v, s)


def from_velocities(system: System, omega, V: float, R, S, dyn: Dynamics | None = None,
                    v_scale: float = 0.0) -> Steadiness:
    """The definition at a state given by its velocities and forces: accelerations recomputed
    from Newton-Euler, each contact's state read off sgn(v_t) (0 where |v_t| <= 1e-9
    max(max|v_t|, v_scale)). Scales: forces max(|lambda|, m g), accelerations max(g, |gamma|)
    (1 + |lambda| / (m g))."""
    dyn = dyn or Dynamics(system)
    c, p, mu = system.c, system.p, system.mu
    R, S = np.asarray(R, dtype=float), np.asarray(S, dtype=float)
    lam = np.concatenate([R, S])
    fs = system.mass * max(system.g, abs(system.gamma), 1e-12)
    fscale = max(float(np.max(np.abs(lam), initial=0.0)), fs)
    ascale = max(system.g, abs(system.gamma), 1e-12) * fscale / fs
    nu_dot = dyn.accelerations(lam)
    a = dyn.H @ nu_dot + dyn.u_obs_dot
    vt = dyn.velocities(np.asarray(omega, dtype=float), V)[c:]
    vscale = max(float(np.max(np.abs(vt), initial=0.0)), v_scale, 1e-300)
    s = np.where(np.abs(vt) <= 1e-9 * vscale, 0, np.sign(vt)).astype(int)
    s[mu == 0] = 0
    return steadiness(system, R, S, s, a[:c], a[c:], f_scale=fscale, a_scale=ascale,
                      trans=nu_dot[:2 * p])


__all__ = ["KINEMATICS", "LAWS", "Steadiness", "from_velocities", "steadiness"]
