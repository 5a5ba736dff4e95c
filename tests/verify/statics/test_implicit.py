"""verify.statics.implicit: exactly checked certificates that a cone row of P vanishes on all
of P (and hull.locally_dependent's rank, through analyse's dimension).

Hand cases (radius-1 disks, m = 1, g as in models):

1. A disk resting on a disk directly below it (contact normal vertical) and touching a
   neighbour beside it (normal horizontal), nothing else: roll it away from the neighbour on
   the disk below (v = (s, 0), w such that the contact point on the lower disk does not slip).
   Gravity does no work (b . y = 0); the lower contact has g = 0 exactly; the side contact
   opens with g_n = s and |g_t| = s (the rolling disk's contact point moves along the
   tangent at r w = s). Its cone rows are -s (1 -+ mu) < 0 when mu < 1: R = 0 on the side
   contact, on all of P. At mu > 1 one of them is > 0: that y is no certificate.
A y that lifts the disk (b . y != 0) or pushes it into its neighbour (a cone row > 0) must be
refused.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.verify.statics import hull
from rigidlcp.verify.statics.forceset import analyse
from rigidlcp.verify.statics.implicit import exact_vanishing, gi_to_cone, proved_rows
from rigidlcp.verify.statics.local import Cone
from rigidlcp.verify.statics.model import StaticProblem


def _block(mu: float) -> models.System:
    """Hand case 1 twice: disks 0 (1, 1) and 1 (3, 1) on the plane, touching; disk 2 (1, 3)
    on disk 0 and disk 3 (3, 3) on disk 1, touching each other; no walls."""
    x = np.array([[1.0, 1.0], [3.0, 1.0], [1.0, 3.0], [3.0, 3.0]])
    lat = models.make_packing(x, np.ones(4), m=np.ones(4))
    return models.System(lat, mu_pp=mu, mu_plane=mu, mu_wall=mu)


def _contact(lat, i: int, j: int) -> int:
    return next(a for a in range(lat.c) if {int(lat.i[a]), int(lat.j[a])} == {i, j})


def _no_slack_lp(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("the slack LP ran")
    monkeypatch.setattr(hull, "linprog", refuse)


@pytest.mark.parametrize("mu", [0.3, 0.5, 0.9])
def test_top_pair_contact_carries_nothing_below_mu_one(mu, monkeypatch):
    """Hand case 1 on the 2 x 2 block: contact 2-3 is R = 0 on all of P,
    proved by certificates alone (the slack LP is not allowed to run)."""
    _no_slack_lp(monkeypatch)
    system = _block(mu)
    fs = analyse(system, ranges=False)
    lat = system.lattice
    a = _contact(lat, 2, 3)
    assert fs.exists and fs.implicit[a] == "R=0"
    # and by hand: the range of R there is {0} (an LP on the rows form)
    prob = StaticProblem(system)
    e = np.zeros(prob.n)
    e[a] = -1.0
    bounds = [(None if not np.isfinite(lo) else lo, None if not np.isfinite(hi) else hi)
              for lo, hi in zip(prob.lb, prob.ub)]
    res = linprog(e, A_ub=prob.G, b_ub=np.zeros(prob.G.shape[0]), A_eq=prob.A, b_eq=prob.b,
                  bounds=bounds, method="highs")
    assert res.status == 0 and -res.fun <= 1e-9



def test_the_hand_certificate_and_wrong_ones():
    """The rolling motion of hand case 1 (disk 2 away from disk 3: v = (-1, 0) and the
    rotation that makes it roll on disk 0) is accepted at mu = 0.5 and proves exactly the
    side contact's rows, and refused at mu = 1.5; lifting the disk (gravity works), pushing it
    into disk 3 or sliding it on disk 0 is refused."""
    system = _block(0.5)
    prob = StaticProblem(system)
    cone = Cone(prob)
    lat = system.lattice
    D = np.array([2])
    a = _contact(lat, 2, 3)
    for w in (1.0, -1.0):  # the rolling sense depends on models' tangent convention
        y = np.array([-1.0, 0.0, w])  # (u, v, w) of disk 2
        got = exact_vanishing(cone, D, y)
        if got.any():
            break
    assert got.any(), "no sense of rotation makes disk 2 roll on disk 0"
    assert set(np.flatnonzero(got)) == set(gi_to_cone(prob, a))
    steep = StaticProblem(_block(1.5))
    assert not exact_vanishing(Cone(steep), D, np.array([-1.0, 0.0, w])).any()
    assert not exact_vanishing(cone, D, np.array([0.0, 1.0, 0.0])).any()  # lifts: b . y != 0
    assert not exact_vanishing(cone, D, np.array([1.0, 0.0, -w])).any()  # into disk 3
    assert not exact_vanishing(cone, D, np.array([-1.0, 0.0, 0.0])).any()  # slides on disk 0


def _slack_lp_rows(prob: StaticProblem, undecided: np.ndarray) -> np.ndarray:
    """The rows among `undecided` with no positive slack anywhere on P: one linprog per row
    (max its slack, capped at the scale) on the rows form, an independent method."""
    c = prob.c
    Gi = sp.vstack([-sp.eye(c, prob.n), prob.G], format="csr").toarray()
    bounds = [(None if not np.isfinite(lo) else lo, None if not np.isfinite(hi) else hi)
              for lo, hi in zip(prob.lb, prob.ub)]
    out = np.zeros(undecided.size, dtype=bool)
    for r in np.flatnonzero(undecided):
        res = linprog(Gi[r], A_ub=np.r_[prob.G.toarray(), -Gi[r][None, :]],
                      b_ub=np.r_[np.zeros(prob.G.shape[0]), prob.scale], A_eq=prob.A,
                      b_eq=prob.b, bounds=bounds, method="highs")
        assert res.status == 0
        out[r] = -res.fun <= 1e-9 * prob.scale
    return out


@settings(max_examples=12)
@given(n=st.integers(2, 25), seed=st.integers(0, 10**5),
       mu=st.sampled_from([0.0, 0.3, 0.5, 0.988, 1.0, 1.5]),
       spread=st.floats(1.0, 1.6), across=st.sampled_from([1, 2, 3, 6]))
def test_proved_rows_are_implicit_by_the_slack_lp(n, seed, mu, spread, across):
    """Every row a certificate proves, sought around every contact, has no positive slack on
    P by linprog (an independent LP per row, on the rows form). (That the certificates find
    the same labels as the slack LPs is tests/verify/statics/test_centre.py's comparison of
    the new path with the old one.)"""
    lat = deposit(n, seed=seed, radii=(1.0, spread), width=2.0 * spread * across)
    system = models.System(lat, mu_pp=mu, mu_plane=mu, mu_wall=0.5 * mu)
    prob = StaticProblem(system)
    m = prob.c + 2 * prob.fric.size
    everything = np.ones(m, dtype=bool)
    if not analyse(system, ranges=False).exists:
        return
    proved = proved_rows(prob, everything)
    if proved.any():
        assert np.all(_slack_lp_rows(prob, proved)[proved])
