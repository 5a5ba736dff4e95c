"""A disk in a V-groove at a generic angle, by hand: statics (the range of its contact forces)
and dynamics (the event engine's forces on a spinning disk), so that the sign conventions of
contacts at angles other than 0, 60 and 90 degrees are checked against a derivation.

The groove: two unit disks on the plane at (1, 1) and (3.4, 1), each against a wall (x = 0,
x = 4.4), not touching each other; a unit disk on top at (2.2, 2.6) touches both along the
normals n1 = (0.6, 0.8), n2 = (-0.6, 0.8) (from the lower disk to the top one: cos phi = 0.8,
sin phi = 0.6, phi the angle from the vertical; a 3-4-5 triangle, so everything is rational).
Tangents t = n rotated by +90 degrees: t1 = (-0.8, 0.6), t2 = (-0.8, -0.6). The force of
contact k on the top disk is R_k n_k + S_k t_k, its torque -S_k (r = 1); weight m g = 1.

Statics (every velocity zero): torque S2 = -S1 = -s; x: 0.6 (R1 - R2) = 0, so R1 = R2 = R;
y: 1.6 R + 1.2 s = 1. Coulomb |s| <= mu R gives s in [-mu / (1.6 - 1.2 mu), mu / (1.6 + 1.2 mu)]
and R in [1 / (1.6 + 1.2 mu), 1 / (1.6 - 1.2 mu)]: the wedge's 1 / (2 (cos phi +- mu sin phi)).
The lower disks add one bound (mu = 1 at the plane and walls). Lower left disk (i of its
three contacts, torque -S each): torque S_p + S_L = -s; x: R_L = 0.6 R - 0.8 s + S_p =
0.6 R - 1.8 s - S_L; its wall cone S_L >= -R_L then needs 0.6 R - 1.8 s >= 0, i.e. s <= R / 3,
i.e. (with 1.6 R + 1.2 s = 1) s <= 1/6 and R >= 1/2 (the lower right disk gives the same, by
mirror symmetry). So max s = min(mu / (1.6 + 1.2 mu), 1/6) and min R = max(1 / (1.6 + 1.2 mu),
1/2): the groove's own bounds up to mu = 1/3, the wall's beyond.

Dynamics: the top disk spins with omega > 0, the others at rest. Both its contacts slide with
v_t = -(r_i omega_i + r_j omega_j) = -omega < 0, so S_k = +mu R_k (Eq. 2.10). Its translation
stays at rest: x: R1 (0.6 - 0.8 mu) = R2 (0.6 + 0.8 mu); y: R1 (0.8 + 0.6 mu) + R2 (0.8 - 0.6
mu) = 1; its angular acceleration is -(S1 + S2) / I = -2 mu (R1 + R2) (I = 1/2).
"""

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.verify.statics.forceset import analyse
from rigidlcp.verify.statics.regime import regime

X = [[1.0, 1.0], [3.4, 1.0], [2.2, 2.6]]


def _groove(mu: float) -> models.System:
    lat = models.make_packing(X, np.ones(3), m=np.ones(3), left=0.0, right=4.4)
    return models.System(lat, mu_pp=mu, mu_plane=1.0, mu_wall=1.0)


def _top_contacts(lat) -> tuple[int, int]:
    a1 = int(np.flatnonzero((lat.i == 0) & (lat.j == 2))[0])
    a2 = int(np.flatnonzero((lat.i == 1) & (lat.j == 2))[0])
    return a1, a2


def test_geometry_is_the_derivations():
    lat = _groove(0.3).lattice
    assert lat.c == 6 and not np.any((lat.i == 0) & (lat.j == 1))  # the lower disks apart
    a1, a2 = _top_contacts(lat)
    assert np.allclose(lat.n[a1], [0.6, 0.8]) and np.allclose(lat.t[a1], [-0.8, 0.6])
    assert np.allclose(lat.n[a2], [-0.6, 0.8]) and np.allclose(lat.t[a2], [-0.8, -0.6])


@pytest.mark.parametrize("mu", [0.0, 0.1, 0.3, 0.5, 0.7])
def test_groove_statics_by_hand(mu):
    fs = analyse(_groove(mu))
    assert fs.exists
    c = fs.c
    s_max, R_min = min(mu / (1.6 + 1.2 * mu), 1 / 6), max(1 / (1.6 + 1.2 * mu), 0.5)
    s_min, R_max = -mu / (1.6 - 1.2 * mu), 1 / (1.6 - 1.2 * mu)
    a1, a2 = _top_contacts(fs.system.lattice)
    for a in (a1, a2):
        assert abs(fs.lo[a] - R_min) <= 1e-8 and abs(fs.hi[a] - R_max) <= 1e-8
    assert abs(fs.lo[c + a1] - s_min) <= 1e-8 and abs(fs.hi[c + a1] - s_max) <= 1e-8
    assert abs(fs.lo[c + a2] + s_max) <= 1e-8 and abs(fs.hi[c + a2] + s_min) <= 1e-8  # -S1


@pytest.mark.parametrize("mu", [0.1, 0.2, 0.3])
def test_groove_dynamics_by_hand(mu):
    """(From mu = 0.4 on, the top disk pushes the lower left one hard enough that the event's
    selected solution lets it leave the wall, although forces holding every translation exist:
    the regime check, which leaves out the candidates' tangential laws, cannot call that
    detachment forced; the closed search proves it is: test_groove_closed_search_by_hand.)"""
    system = _groove(mu)
    state = models.initial_state(system, omega=np.array([0.0, 0.0, 1.0]))
    a1, a2 = _top_contacts(system.lattice)
    assert state.s[a1] == state.s[a2] == -1  # v_t = -omega < 0
    assert regime(system, state).exists is True
    run = models.simulate(system, state, max_events=1)
    rec = run.records[0]
    # the two equations of the module docstring, solved by hand
    ratio = (0.6 + 0.8 * mu) / (0.6 - 0.8 * mu)  # R1 / R2
    R2 = 1.0 / (ratio * (0.8 + 0.6 * mu) + 0.8 - 0.6 * mu)
    R1 = ratio * R2
    assert abs(rec.R[a1] - R1) <= 1e-10 and abs(rec.R[a2] - R2) <= 1e-10
    assert abs(rec.S[a1] - mu * R1) <= 1e-10 and abs(rec.S[a2] - mu * R2) <= 1e-10
    assert abs(rec.omega_dot[2] + 2 * mu * (R1 + R2)) <= 1e-10


def test_groove_event_ranges_over_every_solution():
    """verify.ranges.event_ranges on a packing: the spinning top disk's angular acceleration is
    the same, -2 mu (R1 + R2), over every solution of the event (the lower disks' plane and
    wall forces are not: the walls can pinch them, so mu_g is unbounded)."""
    from rigidlcp.verify.ranges.event import event_ranges

    mu = 0.3
    system = _groove(mu)
    state = models.initial_state(system, omega=np.array([0.0, 0.0, 1.0]))
    ratio = (0.6 + 0.8 * mu) / (0.6 - 0.8 * mu)
    R2 = 1.0 / (ratio * (0.8 + 0.6 * mu) + 0.8 - 0.6 * mu)
    want = -2 * mu * (ratio + 1) * R2
    er = event_ranges(models.event_problem(system, state), time_limit=10)
    top = er.every["alpha[2]"]
    assert top.lo.status == top.hi.status == "optimal"
    assert abs(top.lo.value - want) <= 1e-9 and abs(top.hi.value - want) <= 1e-9


def _closed_by_hand(mu: float) -> dict:
    """The closed solution of least sum R of the spinning groove's event, by hand (mu <= 1/3).

    The top disk's R1, R2 are fixed by its translation (module doc), S_k = mu R_k, and
    omega'_top = -2 mu (R1 + R2). Lower left disk (plane p, left wall L; a = R1 (0.6 - 0.8 mu),
    s1 = mu R1, b = 1 + R1 (0.8 + 0.6 mu)), at rest with every contact closed: x: R_L = S_p + a;
    y: R_p + S_L = b; torque (I omega'): -S_p - S_L - s1. Its plane and wall contacts are
    candidates with a_t = -omega' (mu = 1). Sticking (omega' = 0): S_L = -s1 - S_p and
    |S_L| <= R_L needs s1 <= a, i.e. mu <= 1/3, and S_p >= -(s1 + a) / 2; sum R = R_p + R_L =
    b + s1 + a + 2 S_p is least at S_p = -(s1 + a) / 2: R_L = S_L = (a - s1) / 2,
    R_p = b - R_L. Rolling with omega' < 0 (S = -R at both: a_t > 0): x gives R_p + R_L = a,
    y gives R_p - R_L = b > a, so R_L < 0; with omega' > 0 (S = +R at both) the torque is
    -R_p - R_L - s1 < 0: neither exists, so for mu > 1/3 no closed solution does.
    Lower right disk (plane p', right wall W, a' = 0.6 R2 + 0.8 s2, s2 = mu R2): x: R_W =
    a' - S_p'; y: R_p' = 1 + 0.8 R2 - 0.6 s2 + S_W; sticking, S_W = -s2 - S_p', and sum R =
    const - 2 S_p' is least at the largest S_p' that |S_W| <= R_W (S_p' <= (a' - s2) / 2) and
    |S_p'| <= R_p' (S_p' <= (1 + 0.8 R2 - 1.6 s2) / 2) allow."""
    ratio = (0.6 + 0.8 * mu) / (0.6 - 0.8 * mu)
    R2 = 1.0 / (ratio * (0.8 + 0.6 * mu) + 0.8 - 0.6 * mu)
    R1 = ratio * R2
    s1, s2 = mu * R1, mu * R2
    a, b = R1 * (0.6 - 0.8 * mu), 1.0 + R1 * (0.8 + 0.6 * mu)
    R_L = (a - s1) / 2
    a2 = 0.6 * R2 + 0.8 * s2
    S_p2 = min((a2 - s2) / 2, (1 + 0.8 * R2 - 1.6 * s2) / 2)
    S_W = -s2 - S_p2
    return {"R1": R1, "R2": R2, "S1": s1, "S2": s2, "R_L": R_L, "S_L": R_L, "R_p": b - R_L,
            "S_p": -(s1 + a) / 2, "R_W": a2 - S_p2, "S_W": S_W,
            "R_p2": 1 + 0.8 * R2 - 0.6 * s2 + S_W, "S_p2": S_p2,
            "omega_dot": [0.0, 0.0, -2 * mu * (R1 + R2)]}


@pytest.mark.parametrize("mu", [0.2, 0.3])
def test_groove_closed_solution_followed_by_hand(mu, monkeypatch):
    """Up to mu = 1/3 a closed solution exists; with the engine told that its selected solution
    leaves the regime, the run follows the closed solution of least sum R: by hand."""
    import rigidlcp.models.engine.dense as dense

    calls, real = [], dense.leaves_regime

    def selected_leaves(*args):  # the selected solution "leaves"; the closed one is checked
        calls.append(1)
        return len(calls) == 1 or real(*args)

    monkeypatch.setattr(dense, "leaves_regime", selected_leaves)
    system = _groove(mu)
    lat = system.lattice
    state = models.initial_state(system, omega=np.array([0.0, 0.0, 1.0]))
    run = models.simulate(system, state, max_events=1)
    assert run.closed["followed"] == [0]
    rec, want = run.records[0], _closed_by_hand(mu)

    def at(i, j):
        return int(np.flatnonzero((lat.i == i) & (lat.j == j))[0])

    for key, alpha in (("1", at(0, 2)), ("2", at(1, 2)), ("_L", at(0, -1)), ("_p", at(0, -3)),
                       ("_W", at(1, -2)), ("_p2", at(1, -3))):
        assert abs(rec.R[alpha] - want["R" + key]) <= 1e-10, key
        assert abs(rec.S[alpha] - want["S" + key]) <= 1e-10, key
    np.testing.assert_allclose(rec.omega_dot, want["omega_dot"], rtol=0, atol=1e-10)


@pytest.mark.parametrize("mu", [0.4, 0.5])
def test_groove_closed_search_by_hand(mu):
    """From mu > 1/3 no solution of the event keeps the lower left disk at the wall (the
    sticking one needs mu <= 1/3, neither rolling one exists: _closed_by_hand): the detachment
    the selected solution shows is forced by the LCP itself, and the search proves it."""
    system = _groove(mu)
    state = models.initial_state(system, omega=np.array([0.0, 0.0, 1.0]))
    run = models.simulate(system, state, max_events=1)
    assert run.status == "detachment" and run.closed["followed"] == []
    assert "proved: no solution of the event keeps every contact closed" in run.message
