"""Certificates of 2D friction-contact answers (lcp.FrictionContact2D) for verify.certify:
the acceptance lcp.solve applies to them (the relative natural-map residual, and the backward
error and forward error bound of lcp.acceptance.friction_accuracy, on the answer as given), and
the map from the Glocker LCP's z to the forces r, so that certify's uniqueness questions are
asked of r ("forces")."""

from __future__ import annotations

import numpy as np

from rigidlcp import lcp
from rigidlcp.lcp import Solution
from rigidlcp.lcp.acceptance.friction_accuracy import FCAccuracy, assess_fc2d
from rigidlcp.lcp.errors import InvalidInput

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


def fc_accuracy(fc: lcp.FrictionContact2D, r: np.ndarray) -> FCAccuracy:
    """lcp.solve's friction-contact errors of the answer r as given (no polishing): an O(1)
    forward error or an inflated r is not accepted."""
    return assess_fc2d(fc, r, polish=False)


def friction_certificate(fc: lcp.FrictionContact2D, solution, tol: float, uniqueness: str,
                         Certificate):
    """A FrictionContact2D answer r: the relative natural-map residual (lcp.friction) must be
    <= tol, and its backward error and forward error bound (`fc_accuracy`) within lcp.solve's
    limits. Returns the certificate when no uniqueness question is asked (uniqueness "none",
    or more than FC_UNIQUENESS_MAX_C contacts); else None, and certify goes on with the
    Glocker LCP (z = fc.lcp_from_r(r), the forces r = L z as an observable). Certificate:
    certify's result class (passed in: this module is imported by certify)."""
    r = np.asarray(solution.z if isinstance(solution, Solution) else solution, dtype=float)
    r = r.reshape(-1)
    if r.size != fc.n:
        raise InvalidInput(f"the solution has {r.size} entries, the problem {fc.n} unknowns")
    res = lcp.natural_residual(fc, r)
    acc = fc_accuracy(fc, r)
    note = (f"friction contact: relative natural-map residual {res:.3e}, backward error "
            f"{acc.berr:.3g}, forward error bound {acc.ferr:.3g}")
    ok = bool(res <= tol and acc.accepted)
    if uniqueness != "none" and fc.c <= FC_UNIQUENESS_MAX_C and ok:
        return None
    u = fc.u(r)
    cert = Certificate(accepted=ok, tol=tol, residual=res, scaled_residual=res, notes=[note])
    cert.backward_error, cert.forward_error = acc.berr, acc.ferr
    if uniqueness != "none" and fc.c > FC_UNIQUENESS_MAX_C:
        cert.notes.append(f"{fc.c} contacts > {FC_UNIQUENESS_MAX_C}: uniqueness not assessed")
    cert.degenerate = np.flatnonzero((np.abs(r[0::2]) <= 1e-12 * max(np.abs(r).max(
        initial=0.0), 1e-300)) & (np.abs(u[0::2]) <= 1e-12 * max(np.abs(u).max(initial=0.0),
                                                                 1e-300)))
    return cert
