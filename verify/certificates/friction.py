"""Certificates of 2D friction-contact answers (lcp.FrictionContact2D) for verify.certify:
the relative natural-map residual (lcp.friction), and the map from the Glocker LCP's z to the
forces r, so that certify's uniqueness questions are asked of r ("forces")."""

from __future__ import annotations

import numpy as np

from rigidlcp import lcp
from rigidlcp.lcp import Solution

#: Friction contact: uniqueness is asked on the dense Glocker LCP up to this many contacts.
FC_UNIQUENESS_MAX_C = 200


def forces_map(fc: lcp.FrictionContact2D) -> np.ndarray:
    """L with r = L z for the Glocker LCP's z = [R, tau, a_minus] (Siconos's layout)."""
    c = fc.c
    L = np.zeros((2 * c, 3 * c))
    idx = np.arange(c)
    L[2 * idx, idx] = 1.0
    L[2 * idx + 1, c + idx] = 1.0
    L[2 * idx + 1, idx] = -fc.mu
    return L


def friction_certificate(fc: lcp.FrictionContact2D, solution, tol: float, uniqueness: str,
                         Certificate):
    """A FrictionContact2D answer r: the relative natural-map residual (lcp.friction) must be
    <= tol. Returns the certificate when no uniqueness question is asked (uniqueness "none",
    or more than FC_UNIQUENESS_MAX_C contacts); else None, and certify goes on with the
    Glocker LCP (z = fc.lcp_from_r(r), the forces r = L z as an observable). Certificate:
    certify's result class (passed in: this module is imported by certify)."""
    r = np.asarray(solution.z if isinstance(solution, Solution) else solution, dtype=float)
    r = r.reshape(-1)
    if r.size != fc.n:
        raise ValueError(f"the solution has {r.size} entries, the problem {fc.n} unknowns")
    res = lcp.natural_residual(fc, r)
    note = f"friction contact: relative natural-map residual {res:.3e}"
    if uniqueness != "none" and fc.c <= FC_UNIQUENESS_MAX_C and res <= tol:
        return None
    u = fc.u(r)
    cert = Certificate(accepted=bool(res <= tol), tol=tol, residual=res, scaled_residual=res,
                       notes=[note])
    if uniqueness != "none" and fc.c > FC_UNIQUENESS_MAX_C:
        cert.notes.append(f"{fc.c} contacts > {FC_UNIQUENESS_MAX_C}: uniqueness not assessed")
    cert.degenerate = np.flatnonzero((np.abs(r[0::2]) <= 1e-12 * max(np.abs(r).max(
        initial=0.0), 1e-300)) & (np.abs(u[0::2]) <= 1e-12 * max(np.abs(u).max(initial=0.0),
                                                                 1e-300)))
    return cert
