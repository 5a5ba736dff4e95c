"""Observables of the paper: contact states, global friction, dissipation, balances, energy.

Signs (docs/mechanics.md): the force of the plane on a disk is -(R n + S t) with n = (0, -1),
t = (1, 0), so its horizontal part is -S. The global friction F_g = sum over plane contacts of S
is counted positive when it opposes the box's motion relative to the plane, so that Eq. (2.1)
reads N - F_g = m_g gamma; mu_g = F_g / (m_g g). The dissipation rate is D = -sum S v_t >= 0 and
the power the plane gives the disks is F_g V, so between events d(E_rot)/dt = F_g V - D.
"""

from __future__ import annotations

import numpy as np

from .lattice import LEFT_WALL, PLANE, RIGHT_WALL
from .system import System


def global_friction(system: System, S: np.ndarray) -> float:
    """F_g = sum of S over the plane contacts (Eq. 2.1 convention)."""
    return float(np.sum(S[system.lattice.j == PLANE]))


def global_friction_coefficient(system: System, S: np.ndarray) -> float:
    """mu_g = F_g / (m_g g)."""
    return global_friction(system, S) / (system.total_mass * system.g)


#: A reported observable whose magnitude is below ZERO_TOL times its natural scale is rounding
#: noise and reported as 0 (`reported`): mu_g against 1, F_g against the weight m_g g, the
#: dissipation rate against (sum |R| + sum |S|) max |v_t|, its slope with max |a_t|.
ZERO_TOL = 1e-9

#: Stop statuses of a run outside the regime the paper studies (no particle displacement,
#: Sec. II; a finite number of events): its numbers are not the paper's observables.
EXCLUDED = {"detachment": "a contact opens (a_n > 0): particles would move, which the paper's "
                          "model (fixed geometry, Sec. II) excludes",
            "zeno": "events accumulate in finite time (Zeno): the event-driven evolution of "
                    "Sec. II C does not continue past it"}


def dissipation_rate(S: np.ndarray, vt: np.ndarray) -> float:
    """D = -sum_alpha S_alpha v_t,alpha (>= 0 under Coulomb's law), the power dissipated by
    friction: the paper's total dissipation rate W' = sum S theta'^t of Fig. 13 (Sec. IV C),
    with this toolkit's sign of S (docs/mechanics.md). Raw value: see `reported` for the noise."""
    return float(-np.dot(S, vt))


def reported(value: float, scale: float) -> float:
    """`value`, or 0.0 when |value| <= ZERO_TOL * scale (rounding noise such as -9.6e-31)."""
    return 0.0 if abs(value) <= ZERO_TOL * abs(scale) else float(value)


def reported_rate(R: np.ndarray, S: np.ndarray, v: np.ndarray) -> float:
    """-S.v (the dissipation rate D with v = v_t, its slope dD/dt with v = a_t), reported as 0
    within ZERO_TOL of its terms' magnitude (sum |R| + sum |S|) max |v|."""
    force = float(np.sum(np.abs(R)) + np.sum(np.abs(S)))
    return reported(-float(S @ v), force * float(np.max(np.abs(v), initial=0.0)))


def dissipated_energy(records, t_end: float | None = None) -> float:
    """Energy dissipated by friction from the first event to `t_end` (default: the last
    event): the integral of D(t). Between events S is constant and v_t = v_t,k + a_t,k (t -
    t_k), so D is linear there and the integral is exact: sum_k D_k dt_k - (S_k . a_t,k)
    dt_k^2 / 2."""
    recs = list(records)
    if not recs:
        return 0.0
    if any(r.S.size == 0 for r in recs):
        raise ValueError("the run keeps light records (no S, v_t, a_t per event): run it with "
                         "records='full' to integrate the dissipation")
    t_end = recs[-1].t if t_end is None else t_end
    E = 0.0
    for k, rec in enumerate(recs):
        t1 = min(recs[k + 1].t if k + 1 < len(recs) else t_end, t_end)
        dt = max(t1 - rec.t, 0.0)
        E += -float(rec.S @ rec.vt) * dt - 0.5 * float(rec.S @ rec.at) * dt * dt
    return E


def dissipation_summary(records) -> dict:
    """The dissipation observables of a run (Sec. IV C, Fig. 13), with units r = m = g = 1:

    * dissipation_rate: D = -sum S v_t right after the last event (a power, m g sqrt(g r));
      in a steady state at constant driving velocity (gamma = 0) it is the steady-state rate;
    * dissipation_rate_slope: dD/dt = -sum S a_t after the last event: 0 when D is stationary;
      under a constant acceleration gamma != 0 the sliding velocities, hence D, grow linearly;
    * dissipated_energy over dissipated_energy_interval = [first event, last event]: the
      integral of D (exact, `dissipated_energy`), in m g r.

    Rates within ZERO_TOL of their terms' magnitude are reported as 0 (`reported`)."""
    recs = list(records)
    if not recs:
        return {}
    last = recs[-1]
    if any(r.S.size == 0 for r in recs):  # light records (sparse engine): the rate only
        return {"dissipation_rate": float(last.dissipation), "dissipation_rate_slope": None,
                "dissipated_energy": None, "dissipated_energy_interval": None}
    return {
        "dissipation_rate": reported_rate(last.R, last.S, last.vt),
        "dissipation_rate_slope": reported_rate(last.R, last.S, last.at),
        "dissipated_energy": dissipated_energy(recs),
        "dissipated_energy_interval": [float(recs[0].t), float(last.t)],
    }


def regime(status: str) -> dict:
    """{"paper_regime": bool, "regime_note": why not} for a run's stop status."""
    if status in EXCLUDED:
        return {"paper_regime": False, "regime_note": EXCLUDED[status]}
    return {"paper_regime": True}


def rotational_energy(system: System, omega: np.ndarray) -> float:
    if system.uniform:
        return 0.5 * system.inertia * float(np.dot(omega, omega))
    return 0.5 * float(np.dot(system.inertias * omega, omega))  # sum of I_i omega_i^2 / 2


def obstacle_force_on_disks(system: System, R: np.ndarray, S: np.ndarray) -> np.ndarray:
    """Total force (x, y) of the plane and the walls on the disks: -(R n + S t) summed."""
    lat = system.lattice
    obst = lat.j < 0
    f = -(R[obst, None] * lat.n[obst] + S[obst, None] * lat.t[obst])
    return f.sum(axis=0)


def horizontal_balance(system: System, R: np.ndarray, S: np.ndarray) -> float:
    """Residual of Eq. (2.1) seen from the box: (plane + walls horizontal force) - m_g gamma."""
    return float(obstacle_force_on_disks(system, R, S)[0] - system.total_mass * system.gamma)


def state_counts(system: System, record) -> dict:
    """Counts of transmitting / non-sliding / sliding contacts of a record, by kind."""
    R, s = record.R, record.s
    tol = 1e-9 * system.mass * max(system.g, abs(system.gamma), 1e-12)
    T = R > tol
    out = {"T": int(T.sum()), "NT": int((~T).sum())}
    for kind in ("pp", "plane", "wall"):
        sel = system.lattice.kind == kind
        out[f"NS_{kind}"] = int(((s == 0) & sel & (system.mu > 0)).sum())
        out[f"sliding_{kind}"] = int(((s != 0) & sel).sum())
    return out


def states_text(system: System, R: np.ndarray, s: np.ndarray) -> list[str]:
    """Per contact: 'T' / 'NT' and 'NS' / 'S+' / 'S-' (frictionless contacts: 'free')."""
    tol = 1e-9 * system.mass * max(system.g, abs(system.gamma), 1e-12)
    out = []
    for a in range(system.c):
        normal = "T" if R[a] > tol else "NT"
        if system.mu[a] == 0:
            tang = "free"
        else:
            tang = {0: "NS", 1: "S+", -1: "S-"}[int(s[a])]
        out.append(f"{normal}/{tang}")
    return out


__all__ = [
    "global_friction", "global_friction_coefficient", "dissipation_rate", "reported",
    "dissipated_energy", "dissipation_summary", "regime", "EXCLUDED", "ZERO_TOL",
    "reported_rate",
    "rotational_energy",
    "obstacle_force_on_disks", "horizontal_balance", "state_counts", "states_text",
    "LEFT_WALL", "RIGHT_WALL", "PLANE",
]
