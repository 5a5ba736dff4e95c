"""Linear observables of the forces x = [R (c); S (c)]: value = L . x + offset.

`steady_observables(system)` gives mu_g (Eq. 2.2 with F_g of models.observables), the angular
acceleration alpha_i of every disk (Newton-Euler: I alpha_i = -r sum S over its contacts,
models.dynamics), every R_alpha and S_alpha. A user's observable is a vector over x (2c) or a
dict {name: vector}; a wrong length is refused (`BadObservable`).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from rigidlcp.lcp.errors import RigidLCPError
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.lattice import PLANE
from rigidlcp.models.system import System


class BadObservable(RigidLCPError, ValueError):
    """An observable that is not a finite vector of the expected length."""


def mu_g_vector(system: System) -> np.ndarray:
    """mu_g = F_g / (m_g g), F_g = sum of S over the plane contacts."""
    L = np.zeros(2 * system.c)
    L[system.c + np.flatnonzero(system.lattice.j == PLANE)] = 1.0 / (system.total_mass * system.g)
    return L


def alpha_rows(system: System, dyn: Dynamics | None = None) -> np.ndarray:
    """(p, 2c): alpha = rows @ x (the angular part of nu' = M^-1 (H^T x + f); f has no torque)."""
    dyn = dyn or Dynamics(system)
    p = system.p
    return dyn.Minv[2 * p:, None] * dyn.H.T.toarray()[2 * p:]


def steady_observables(system: System, which: str = "all", dyn: Dynamics | None = None
                       ) -> dict[str, np.ndarray]:
    """{name: L}: "mu_g", "alpha[i]" (which = "all" or "alpha"), "R[a]", "S[a]" ("all")."""
    c = system.c
    obs = {"mu_g": mu_g_vector(system)}
    if which in ("all", "alpha"):
        for i, row in enumerate(alpha_rows(system, dyn)):
            obs[f"alpha[{i}]"] = row
    if which == "all":
        for a in range(c):
            e = np.zeros(2 * c)
            e[a] = 1.0
            obs[f"R[{a}]"] = e
            e = np.zeros(2 * c)
            e[c + a] = 1.0
            obs[f"S[{a}]"] = e
    elif which not in ("mu_g", "alpha"):
        raise BadObservable(f"which must be 'all', 'alpha' or 'mu_g', got {which!r}")
    return obs


def check_observable(name: str, L, size: int) -> np.ndarray:
    """L as a float vector of `size` entries, or BadObservable."""
    try:
        v = np.asarray(L, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise BadObservable(f"observable {name!r} is not a numeric vector") from None
    if v.size != size:
        raise BadObservable(f"observable {name!r} has {v.size} entries, expected {size} "
                            "(one per unknown)")
    if not np.all(np.isfinite(v)):
        raise BadObservable(f"observable {name!r} contains NaN or Inf")
    return v


def user_observables(observables, size: int) -> dict[str, np.ndarray]:
    """A user's observables, each checked (check_observable): a dict {name: vector} or a
    matrix whose rows are named "user[k]"; None gives none. A string or any other object is
    BadObservable (the named sets "mu_g", "alpha", "all" are chosen apart, e.g. `which`)."""
    if observables is None:
        return {}
    if isinstance(observables, Mapping):
        items = observables.items()
    elif isinstance(observables, (str, bytes)):
        raise BadObservable(f"observables must be a dict {{name: vector}} or a matrix, got "
                            f"{observables!r}")
    else:
        try:
            rows = np.atleast_2d(np.asarray(observables, dtype=float))
        except (TypeError, ValueError):
            raise BadObservable("observables must be a dict {name: vector} or a numeric "
                                f"matrix, got {type(observables).__name__}") from None
        if rows.ndim != 2:
            raise BadObservable(f"observables must be a matrix (one row per observable), got "
                                f"{rows.ndim} dimensions")
        items = ((f"user[{k}]", row) for k, row in enumerate(rows))
    return {str(name): check_observable(str(name), L, size) for name, L in items}
