"""rigidlcp.reproduce.overall: the report's column "over all valid steady states" (issue 21.3),
on systems small enough to know the answer."""

from __future__ import annotations

import pytest

from rigidlcp import models
from rigidlcp.reproduce.experiments import Claim, Job, Results, first_piece, plan
from rigidlcp.reproduce.overall import NA, over_all
from rigidlcp.reproduce.valid_steady import end_families, steady_set


def _fig11_results(grid: str) -> Results:
    """The Fig. 11 sweep (rect 10x1, mu 0.05 / 0.1 / 0) on a small grid, with its band, as
    run_all collects them (the same jobs)."""
    p = plan(quick=True)
    p["fig11"]["gamma"] = grid
    res = Results(p)
    from rigidlcp.reproduce.experiments import jobs_of

    job = Job(p)
    for j in jobs_of(p):
        if j[1] == "fig11" and j[0] in ("point", "band"):
            out = job(j)
            (res.sweeps if j[0] == "point" else res.bands).setdefault("fig11", []).append(out)
    res.sweeps["fig11"].sort(key=lambda r: r["gamma"])
    res.bands["fig11"].sort(key=lambda pt: pt.gamma)
    return res


@pytest.fixture(scope="module")
def fig11_small():
    return _fig11_results("0:0.03:4")


def test_linear_through_zero_holds_for_the_selection_not_for_every_steady_state(fig11_small):
    """rect 10x1 at Fig. 11's coefficients: the selection's mu_g is one line through 0 (the
    claim's criterion), but at gamma = 0.01 the valid steady states span a wide interval
    (measured from outside the project: [0.0145179, 0.0976197]) whose lower end is the
    selection's: "holds for some" (the lower ends), not "for all"."""
    res = fig11_small
    eff = res.effective("fig11")
    assert first_piece(eff) == 4 and abs(eff.mu_g[0]) <= 1e-9  # the selection: linear
    pts = res.bands["fig11"]
    at = next(pt for pt in pts if pt.gamma == pytest.approx(0.01))
    assert at.every.decided and at.every.width > 0.05
    assert at.every.lo.value == pytest.approx(at.selected, abs=1e-9)
    assert at.every.lo.value == pytest.approx(0.0145179, abs=1e-6)
    text = over_all(res, Claim("fig11-linear", "", "", "", "", True))
    assert text.startswith("holds for some") and "lower ends" in text, text


def test_band_contains_the_selected_curve(fig11_small):
    pts = fig11_small.bands["fig11"]
    for pt in pts:
        assert pt.every.decided and pt.every.contains(pt.selected, tol=1e-8), pt
        assert pt.own is not None and pt.own.contains(pt.selected, tol=1e-8)
        assert pt.every.lo.value <= pt.own.lo.value + 1e-9
        assert pt.own.hi.value <= pt.every.hi.value + 1e-9
    fam = end_families(pts, 10.0)
    lo, hi = fam["lower"], fam["upper"]
    sel = fig11_small.effective("fig11")
    # at gamma = 0, mu_e = mu_g on any curve: the selection's lies between the end curves'
    assert lo.mu_e[0] - 1e-12 <= sel.mu_e[0] <= hi.mu_e[0] + 1e-12


def test_fig12_friction_judged_on_the_band_at_rest(fig11_small):
    """At gamma = 0 (at rest) static friction leaves mu_g in a symmetric interval wider than
    0.1 mu_plane: mu_e(0) = 0 holds for some valid steady states (the selection's), not all."""
    text = over_all(fig11_small, Claim("fig12-friction", "", "", "", "", True))
    assert text.startswith("holds for some"), text


def test_a_single_disk_has_one_steady_state():
    """One disk on the plane between frictionless walls: the steady state is unique, so "the
    steady state does not depend on the initial state" holds for all."""
    system = models.make_system("rect", 1, 1, gamma=0.05, mu_pp=0.1, mu_plane=0.2,
                                mu_wall=0.0)
    run = models.simulate(system, seed=0)
    res = Results(plan(quick=True))
    res.steady_sets["fig10"] = steady_set(run, time_limit=20.0)
    text = over_all(res, Claim("fig10-steady", "", "", "", "", True))
    assert text.startswith("holds for all"), text
    assert over_all(res, Claim("eq33-rect", "", "", "", "", True)) == NA


def test_missing_inputs_are_unknown_not_a_verdict():
    res = Results(plan(quick=True))
    for cid in ("fig7-steady", "fig11-linear", "fig12-inertia", "ivb-pp-m_e"):
        text = over_all(res, Claim(cid, "", "", "", "", True))
        assert text.startswith("unknown"), (cid, text)


def test_fig12_inertia_names_the_curves_where_it_holds(fig11_small):
    """m_e(0) >= 2 m_g on the selection's curve (24.5 = 2.45 m_g): "holds for some", naming it;
    m_e is a slope along a curve, so "for all" is never claimed."""
    text = over_all(fig11_small, Claim("fig12-inertia", "", "", "", "", True))
    assert text.startswith("holds for some (this toolkit's selection"), text


# -- the mode and contact-state claims, asked as patterns (mode_claims.py) ----------------------


def _patterns(name: str, system: models.System, seed: int = 0) -> Results:
    from rigidlcp.reproduce.mode_claims import judge_patterns

    res = Results(plan(quick=True))
    res.patterns[name] = judge_patterns(name, models.simulate(system, seed=seed), 20.0)
    return res


def test_every_disk_of_a_frictionless_row_rolls_holds_for_all():
    """rect 3x1, mu_pp = mu_wall = 0, gamma 0.1: each disk is the single disk, which rolls
    (S_P = gamma / 2 <= mu_P; tests/verify/ranges/test_steady_closed_forms.py), so "every
    first-row disk in mode 1" holds for every valid steady state: not-P is infeasible."""
    s = models.System(models.rectangular(3, 1), mu_pp=0.0, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.1)
    res = _patterns("fig8", s)
    text = over_all(res, Claim("fig8-row1-mode1", "", "", "", "", True))
    assert text.startswith("holds for all:"), text
    assert "infeasible" in text


def test_all_non_wall_contacts_non_sliding_holds_for_none_by_kinematics():
    """rect 2x2 at constant velocity (gamma 0, V0 = 1): non-sliding plane contacts give
    r omega = -V0 to both first-row disks, a non-sliding lateral contact r omega_0 = -r
    omega_1: no velocities do both, so no valid steady state has every non-wall contact
    non-sliding (a kinematic cut proves it); the run's state is a witness of the negation."""
    s = models.System(models.rectangular(2, 2), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.0, V0=1.0)
    res = _patterns("fig13", s)
    text = over_all(res, Claim("fig13-rect-all-ns", "", "", "", "", False))
    assert text.startswith("holds for none:"), text
    q = res.patterns["fig13"]["fig13-rect-all-ns"]["P"]
    assert q.proved and q.cuts >= 1


def test_fig9_counts_need_nine_disks():
    """4 / 3 / 2 counts nine first-row disks besides the wall disk left out: a 4x2 array has
    three, so the claim holds for no valid steady state (proved: the counts are infeasible)."""
    s = models.System(models.rectangular(4, 2), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=0.16)
    text = over_all(_patterns("fig9", s), Claim("fig9-counts", "", "", "", "", False))
    assert text.startswith("holds for none:"), text


@pytest.mark.parametrize("name, lx, ly, gamma", [("fig8", 4, 2, 0.2), ("fig8", 3, 3, 0.05),
                                                 ("fig6", 4, 1, 0.05)])
def test_every_pattern_witness_is_valid_and_has_what_it_claims(name, lx, ly, gamma):
    """Each witness of a pattern question: a valid steady state (steady_check, called here) on
    which the claim's own classifier (models.modes, as the report's criterion) gives the
    answer claimed (P for the claim's witness, not-P for the negation's)."""
    from rigidlcp.reproduce.mode_claims import questions
    from rigidlcp.verify.ranges.witness import steady_check

    s = models.System(models.rectangular(lx, ly), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                      gamma=gamma)
    res = _patterns(name, s)
    checks = {cid: q[2] for cid, q in questions(name, s).items()}
    seen = 0
    for cid, q in res.patterns[name].items():
        for side in ("P", "not"):
            r = q[side]
            if r is None or r.witness is None:
                assert r is None or r.status != "feasible"
                continue
            w, seen = r.witness, seen + 1
            assert steady_check(s, w.omega, w.V, w.R, w.S)[0] <= 1e-8, (cid, side)
            assert checks[cid](w) == (side == "P"), (cid, side, r.note)
    assert seen >= 1
