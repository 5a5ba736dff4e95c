"""verify.statics: "no equilibrium" (exists False) only with a Farkas certificate checked in
exact rational arithmetic; a floating-point certificate (a radius: no equilibrium has sum R
below it) is evidence, and the existence stays undecided (exists None).

The piles: a 40-disk pile without equilibrium (test_forceset's first near miss: its global
Farkas y passes the float check, radius above 1e9 weights) and a 400-disk pile without
equilibrium, beyond the dense exact check's EXACT_MAX_P disks, whose global Farkas y moves a
few tens of disks: the exact check on its support (verify.statics.local.support_certificate)
proves it. The exact stages are switched off by patching them to find nothing, the way a
certificate out of their reach (or failing them) would.
"""

from __future__ import annotations

import json
from fractions import Fraction

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.verify.statics import farkas, forceset, local
from rigidlcp.verify.statics.forceset import analyse
from rigidlcp.verify.statics.model import StaticProblem


def _pile(n: int, seed: int, radii=(0.8, 1.2), width=None, mu=0.5) -> models.System:
    kw = {} if width is None else {"width": width}
    return models.System(deposit(n, seed=seed, radii=radii, **kw), mu_pp=mu, mu_plane=mu,
                         mu_wall=mu)


def _no_windows(monkeypatch):
    """No local certificate from the window scans: the global Farkas LP decides."""
    monkeypatch.setattr(forceset, "scan", lambda *a, **k: None)


def _no_exact(monkeypatch):
    """Every exact check of the global certificate finds nothing (dense and on the support)."""
    _no_windows(monkeypatch)
    monkeypatch.setattr(farkas, "exact_certificate", lambda *a, **k: None)
    monkeypatch.setattr(forceset, "support_certificate", lambda *a, **k: None)


def _float_violation(prob: StaticProblem, y: np.ndarray) -> float:
    g = prob.A.T @ y
    c = prob.c
    return float(np.max(np.where(prob.mu > 0, prob.mu * np.abs(g[c:]) - g[:c], -g[:c])))


@pytest.mark.parametrize("n, seed, width", [(40, 2, 10.0), (400, 1, None)])
def test_a_float_only_certificate_leaves_existence_undecided(monkeypatch, n, seed, width):
    """With the exact checks finding nothing, the float certificate (which passes the float
    check: radius >= RADIUS_WEIGHTS weights) must not make exists False: exists is None, the
    JSON says why and carries the evidence ("farkas_evidence")."""
    system = _pile(n, seed, width=width)
    assert analyse(system, ranges=False).exists is False  # proved exactly when allowed
    _no_exact(monkeypatch)
    fs = analyse(system, ranges=False)
    weight = float(np.sum(system.masses)) * system.g
    assert fs.exists is None and not fs.exact
    assert fs.certificate is not None and fs.radius >= farkas.RADIUS_WEIGHTS * weight
    prob = StaticProblem(system)
    assert prob.b @ fs.certificate < 0 and _float_violation(prob, fs.certificate) <= 1e-13
    d = json.loads(json.dumps(fs.to_dict(), allow_nan=False))
    assert d["exists"] is None and d["farkas_exact"] is False
    assert "not proved" in d["undecided"]
    ev = d["farkas_evidence"]
    if np.isfinite(fs.radius):
        assert ev["radius"] == pytest.approx(fs.radius) and ev["radius_weights"] >= 1e9
    else:  # no cone row violated in floating point: still no proof
        assert ev["radius"] is None and ev["radius_weights"] is None
    assert ev["gap"] > 0 and 0 < ev["disks_moved"] <= system.p
    assert len(ev["moving_disks"]) == min(ev["disks_moved"], 20)


def test_the_global_certificate_is_proved_on_its_support_beyond_the_dense_limit(monkeypatch):
    """400 disks (> EXACT_MAX_P): without the window scans, the global Farkas y is checked
    exactly on the disks it moves, and exists is False with exact True; each cone row of the
    whole packing holds exactly for the rational y, checked here independently with Python
    Fractions from the stored H, b, mu (g = H y; g_n >= mu |g_t|, g_n >= 0 at mu = 0)."""
    system = _pile(400, 1)
    prob = StaticProblem(system)
    assert prob.p > farkas.EXACT_MAX_P
    _no_windows(monkeypatch)
    fs = analyse(system, ranges=False)
    assert fs.exists is False and fs.exact and fs.moving is not None
    assert 0 < fs.moving.size < prob.p
    C = farkas.cone_rows(prob)
    y = farkas.farkas_lp(prob, C, False)
    cert = local.support_certificate(prob, farkas._polish(C, y))
    assert cert is not None
    _exactly_a_certificate(prob, cert.exact)


def _exactly_a_certificate(prob: StaticProblem, yq: dict) -> None:
    """b . y < 0 and every contact's H y in its dual cone, in Fractions (y zero off yq)."""
    H = sp.csr_matrix(prob.A.T)
    c = prob.c
    work = sum((Fraction(float(prob.b[k])) * v for k, v in yq.items()), Fraction(0))
    assert work < 0

    def g(row: int) -> Fraction:
        lo, hi = H.indptr[row], H.indptr[row + 1]
        return sum((Fraction(float(val)) * yq.get(int(col), Fraction(0))
                    for col, val in zip(H.indices[lo:hi], H.data[lo:hi])), Fraction(0))

    for a in range(c):
        gn, gt, mu = g(a), g(c + a), Fraction(float(prob.mu[a]))
        assert gn >= mu * abs(gt) if mu > 0 else gn >= 0, a


def test_support_clusters_split_a_certificate_into_independent_parts():
    """Two separate piles' worth of motion: a y moving two disks far apart (no contact
    between them) splits into two clusters of one disk each; a y moving nothing has none."""
    system = _pile(40, 2, width=10.0)
    prob = StaticProblem(system)
    lat = system.lattice
    touching = {(int(i), int(j)) for i, j in zip(lat.i, lat.j) if j >= 0}
    a, b = next((a, b) for a in range(prob.p) for b in range(a + 1, prob.p)
                if (a, b) not in touching and (b, a) not in touching)
    y = np.zeros(3 * prob.p)
    y[a], y[prob.p + b] = 1.0, -0.5
    parts = local.clusters(prob, y)
    assert sorted(int(D[0]) for D in parts) == sorted([a, b]) and all(D.size == 1 for D in parts)
    assert local.clusters(prob, np.zeros(3 * prob.p)) == []


@settings(max_examples=15, deadline=None)
@given(n=st.integers(2, 30), seed=st.integers(0, 10**6),
       mu=st.sampled_from([0.0, 0.1, 0.3, 0.5, 1.0]))
def test_no_equilibrium_only_with_an_exact_certificate(n, seed, mu):
    """On any deposited pile: exists False comes with an exactly checked certificate (exact
    True, radius inf), whose float image is a certificate to rounding; exists True with a
    solution in P."""
    system = _pile(n, seed, radii=(0.8, 1.2), width=6.0, mu=mu)
    fs = analyse(system, ranges=False)
    prob = StaticProblem(system)
    if fs.exists is False:
        assert fs.exact and fs.radius == np.inf
        assert prob.b @ fs.certificate < 0 and _float_violation(prob, fs.certificate) <= 1e-12
    elif fs.exists:
        assert prob.admissible(fs.solution)
