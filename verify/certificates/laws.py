"""The contact laws checked from the forces alone, independently of any LCP formulation.

Given the state of an event (models.State: which contacts slide and which way) and contact
forces (R, S), the relative accelerations are recomputed by Newton-Euler (a = H M^-1 (H^T
lambda + f) + u_obs', models.Dynamics) and every law of Sec. II B is measured:

* Signorini at acceleration level, Eq. (2.5): R >= 0, a_n >= 0, R a_n = 0;
* Coulomb's cone: |S| <= mu R, each contact with its own mu (frictionless: S = 0);
* a sliding contact, Eq. (2.10): S = -sgn(v_t) mu R;
* a non-sliding candidate, Eq. (2.7): a_t != 0 only with S = -sgn(a_t) mu R.
"""

from __future__ import annotations

import numpy as np

from rigidlcp.models import Dynamics, State, System


def contact_law_residuals(
    system: System, state: State, R: np.ndarray, S: np.ndarray, zero_acc: float = 1e-7
) -> dict[str, float]:
    """The largest violation of each law (0 when it holds exactly).

    zero_acc: |a_t| below which a candidate counts as non-sliding (a_t = 0).
    """
    dyn = Dynamics(system)
    R, S = np.asarray(R, float), np.asarray(S, float)
    a = dyn.relative_accelerations(np.concatenate([R, S]))
    c, mu, s = system.c, system.mu, np.asarray(state.s)
    an, at = a[:c], a[c:]
    sliding = (s != 0) & (mu > 0)
    started = (s == 0) & (mu > 0) & (np.abs(at) > zero_acc)
    zero = 0.0
    return {
        "R >= 0": float(np.max(-R, initial=zero)),
        "a_n >= 0": float(np.max(-an, initial=zero)),
        "R a_n = 0": float(np.max(np.abs(R * an), initial=zero)),
        "|S| <= mu R": float(np.max(np.abs(S) - mu * R, initial=zero)),
        "sliding: S = -sgn(v_t) mu R (2.10)": float(
            np.max(np.abs(S + s * mu * R)[sliding], initial=zero)),
        "started: S = -sgn(a_t) mu R (2.7)": float(
            np.max(np.abs(S + np.sign(at) * mu * R)[started], initial=zero)),
    }


def check_contact_laws(system: System, state: State, R, S, tol: float = 1e-8) -> None:
    """Raise AssertionError naming the laws violated by more than tol."""
    bad = {k: v for k, v in contact_law_residuals(system, state, R, S).items() if v > tol}
    if bad:
        raise AssertionError(f"contact laws violated (tol {tol:g}): {bad}")
