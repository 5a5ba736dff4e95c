"""Legendre transform of F_g(gamma), Eqs. (4.1)-(4.2): exact on analytic curves, kinks kept."""

import numpy as np
import pytest

from rigidlcp.models.effective import derivative, from_rows, legendre

M_G = 10.0


def piecewise_linear(gamma, kinks=(0.0437, 0.1121, 0.1873), slopes=(14.5, 6.0, 1.3, 0.0)):
    """A concave piecewise-linear F_g through the origin (the shape of Fig. 11): returns F_g
    and the exact slope of the piece each gamma lies on."""
    gamma = np.asarray(gamma, float)
    F, slope = np.zeros_like(gamma), np.zeros_like(gamma)
    edges = (0.0, *kinks, np.inf)
    for k, s in enumerate(slopes):
        lo, hi = edges[k], edges[k + 1]
        F += s * np.clip(gamma - lo, 0.0, hi - lo)
        slope[(gamma >= lo) & (gamma < hi)] = s
    return F, slope


def test_piecewise_linear_is_exact_at_every_point_kinks_included():
    gamma = np.linspace(0.0, 0.3, 31)  # kinks fall between grid points
    F, slope = piecewise_linear(gamma)
    eff = legendre(gamma, F, M_G)
    b = F - slope * gamma
    assert np.allclose(eff.a, slope, rtol=0, atol=1e-9)
    assert np.allclose(eff.m_e, M_G + slope, rtol=0, atol=1e-9)
    assert np.allclose(eff.mu_e, b / M_G, rtol=0, atol=1e-10)
    assert np.allclose(eff.F_e, b, rtol=0, atol=1e-9) and eff.exact.all()
    # the first piece goes through the origin: mu_e = 0 exactly there; the last is flat
    assert np.allclose(eff.mu_e[gamma < 0.04], 0.0, atol=1e-12)
    assert np.allclose(eff.m_e[gamma > 0.19], M_G, atol=1e-9)
    # A centred difference straddles the kinks and is wrong beside each of them.
    assert np.abs(np.gradient(F, gamma) - slope).max() > 1.0


def test_piecewise_linear_on_an_uneven_grid():
    rng = np.random.default_rng(3)
    gamma = np.sort(np.concatenate([np.linspace(0, 0.3, 25), rng.uniform(0.0, 0.3, 15)]))
    F, slope = piecewise_linear(gamma)
    eff = legendre(gamma[::-1], F[::-1], M_G)  # any order: sorted inside
    assert np.array_equal(eff.gamma, gamma)
    # a point whose three windows all cross a kink cannot be exact; every other point is
    ok = eff.exact
    assert ok.sum() >= len(gamma) - 2
    assert np.allclose(eff.a[ok], slope[ok], atol=1e-9)


def test_kink_at_a_grid_point_gives_a_subgradient():
    gamma = np.linspace(0.0, 1.0, 11)
    F = np.minimum(3.0 * gamma, 1.5 + 0.5 * (gamma - 0.5))  # kink at gamma = 0.5 exactly
    eff = legendre(gamma, F, M_G)
    k = 5
    assert 0.5 <= eff.a[k] <= 3.0 and eff.a[k] == pytest.approx(1.75)  # mean of both sides
    assert np.allclose(np.delete(eff.a, k), np.where(gamma < 0.5, 3.0, 0.5)[np.arange(11) != k])


def test_quadratic_is_exact():
    """Smooth F_g = c0 + c1 gamma + c2 gamma^2: a = c1 + 2 c2 gamma, b = c0 - c2 gamma^2.
    Default fits (lines through 3 points, centred when the residuals tie): exact at interior
    points of a uniform grid. degree=2, window=4: exact everywhere, ends included."""
    c0, c1, c2 = 0.02, 9.0, -11.0
    gamma = np.linspace(0.0, 0.4, 21)
    F = c0 + c1 * gamma + c2 * gamma**2
    a, b = c1 + 2 * c2 * gamma, c0 - c2 * gamma**2
    eff = legendre(gamma, F, M_G)
    assert np.allclose(eff.a[1:-1], a[1:-1], rtol=0, atol=1e-10)
    assert np.allclose(eff.mu_e[1:-1], b[1:-1] / M_G, rtol=0, atol=1e-11)
    assert abs(eff.a[0] - a[0]) > 0.1  # a one-sided line is not exact at the end
    eff = legendre(gamma, F, M_G, degree=2, window=4)
    assert np.allclose(eff.a, a, rtol=0, atol=1e-10)
    assert np.allclose(eff.m_e, M_G + a, rtol=0, atol=1e-10)
    assert np.allclose(eff.mu_e, b / M_G, rtol=0, atol=1e-11)


def test_smooth_curve_converges_at_second_order():
    """F_g = A tanh(gamma / g0) (smooth, not polynomial): the interior error of a falls ~4x
    each time the spacing halves (centred windows win the ties)."""
    errors = []
    for n in (21, 41, 81):
        gamma = np.linspace(0.0, 1.0, n)
        eff = legendre(gamma, 2.0 * np.tanh(gamma / 0.3), M_G)
        exact = 2.0 / 0.3 / np.cosh(gamma / 0.3) ** 2
        errors.append(np.abs(eff.a - exact)[1:-1].max())
    assert errors[0] / errors[1] > 3.5 and errors[1] / errors[2] > 3.5


def test_input_checks():
    with pytest.raises(ValueError, match="strictly increasing"):
        derivative([0.0, 0.1, 0.1], [0.0, 1.0, 2.0])
    with pytest.raises(ValueError, match="at least two points"):
        derivative([0.0], [1.0])
    with pytest.raises(ValueError, match="window"):
        derivative([0, 1, 2, 3], [0, 1, 2, 3], window=2, degree=2)
    with pytest.raises(ValueError, match="differ in length"):
        legendre([0.0, 0.1], [1.0], M_G)
    with pytest.raises(ValueError, match="m_g and g must be > 0"):
        legendre([0.0, 0.1], [0.0, 1.0], 0.0)
    # two points: a single secant, still a line
    d, _, _ = derivative([0.0, 2.0], [1.0, 5.0])
    assert np.allclose(d, 2.0)


def _row(gamma, F, seed=1, status="steady", mu_pp=0.05):
    return {"lattice": "rect", "lx": 10, "ly": 1, "mu_pp": mu_pp, "mu_plane": 0.1,
            "mu_wall": 0.0, "gamma": gamma, "v0": 0.0, "inertia": None, "seed": seed,
            "method": "lemke", "select": "face-min-norm", "fallback": "lemke",
            "max_events": 20000, "t_max": None, "omega_scale": 1.0, "status": status,
            "F_g": F, "m_g": M_G}


def test_from_rows_groups_seeds_and_leaves_out_unsteady_points():
    gamma = np.linspace(0.0, 0.3, 31)
    F, slope = piecewise_linear(gamma)
    rows = [_row(g, f, seed=s) for g, f in zip(gamma, F) for s in (1, 2)]
    rows += [_row(g, 2 * f, mu_pp=0.1) for g, f in zip(gamma, F)]
    rows.append(_row(0.35, 99.0, status="event_limit"))
    groups = from_rows(rows)
    assert len(groups) == 2
    (p1, e1, out1), (p2, e2, out2) = groups
    assert p1["mu_pp"] == 0.05 and p2["mu_pp"] == 0.1
    assert [r["status"] for r in out1] == ["event_limit"] and out2 == []
    assert np.allclose(e1.a, slope, atol=1e-9) and np.allclose(e2.a, 2 * slope, atol=1e-9)
    rows[1]["F_g"] += 1e-3  # seed 2 disagrees at gamma = 0
    with pytest.raises(ValueError, match="seeds disagree"):
        from_rows(rows)
