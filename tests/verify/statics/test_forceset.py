"""verify.statics: the admissible forces of a packing at rest, against closed forms derived by
hand and against an independent measure of the dimension.

Conventions (models.lattice, models.dynamics): the force of contact alpha on its disk i is
-(R n + S t), t = n rotated by +90 degrees, and its torque on i is -r_i S. Unit weights
(m = 1 for r = 1: the packing files' m = r^2; g = 1). Every case below is a disk of radius 1.

1. A disk in the corner of the left wall and the plane (centre (1, 1)). Forces on the disk:
   plane (-S_p, R_p), wall (R_w, S_w). Balance: x: R_w = S_p; y: R_p + S_w = 1; torque:
   S_p + S_w = 0. With s = S_p: R_w = s, S_w = -s, R_p = 1 + s. Coulomb at the wall,
   |s| <= mu_w s, needs s >= 0 and, if mu_w < 1, s = 0: the forces are unique, R_p = 1 and
   R_w = 0 on the whole set (an implicit equality). If mu_w >= 1 the plane's cone
   s <= mu_p (1 + s) bounds s <= mu_p / (1 - mu_p): for mu_p = 1/2, s in [0, 1], so
   R_p in [1, 2], R_w = S_p in [0, 1], S_w in [-1, 0]: a segment, dimension 1.
2. A disk on the plane between two walls 2 apart. Forces: plane (-S_p, R_p), left (R_L, S_L),
   right (-R_R, -S_R). x: R_L - R_R = S_p; y: R_p = 1 - S_L + S_R; torque:
   S_p = -(S_L + S_R). R_L, R_R can grow together (the walls pinch), so the only binding law
   is |S_L + S_R| <= mu (1 - S_L + S_R) (one mu < 1 everywhere). Eliminating S_L between its
   two sides gives S_R >= -1/2, and then S_L <= 1/2 (at S_R = -1/2, where R_p = 0); the other
   ends are unbounded. So R_p in [0, inf), R_L, R_R in [0, inf), S_L in (-inf, 1/2],
   S_R in [-1/2, inf), S_p in (-inf, inf); 6 unknowns, 3 independent equations, no implicit
   equality: dimension 3. Frictionless: S = 0, R_p = 1, R_L = R_R in [0, inf): dimension 1.
3. Three disks in a pyramid between walls 4 apart, frictionless: bottom disks at (1, 1) and
   (3, 1) (touching each other, the plane and a wall each), the top one at (2, 1 + sqrt 3).
   Top: its two contacts push along (+-1/2, sqrt(3)/2): R_1 = R_2, sqrt(3) R_1 = 1, so
   R_1 = R_2 = 1/sqrt 3. Bottom left: y: R_p1 = 1 + R_1 sqrt(3)/2 = 3/2; x: R_L = R_b + R_1/2
   (R_b the pair contact); the right one likewise. R_b in [0, inf) is free: dimension 1,
   R_L = R_R in [1/(2 sqrt 3), inf). Without the walls (and without friction) nothing holds
   the bottom disks apart: no equilibrium, and a Farkas certificate must say so.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from rigidlcp import models
from rigidlcp.models.deposition import deposit
from rigidlcp.models.lattice import LEFT_WALL, PLANE, RIGHT_WALL
from rigidlcp.verify.statics.forceset import analyse
from rigidlcp.verify.statics.model import StaticProblem

INF = np.inf
TOL = 1e-8


def _system(x, left=None, right=None, **mu) -> models.System:
    lat = models.make_packing(x, np.ones(len(x)), m=np.ones(len(x)), left=left, right=right)
    return models.System(lat, **mu)


def _range(fs, j_code, i=0, what="R"):
    lat = fs.system.lattice
    a = int(np.flatnonzero((lat.i == i) & (lat.j == j_code))[0])
    k = a if what == "R" else fs.c + a
    return fs.lo[k], fs.hi[k]


def _close(got, want):
    for g, w in zip(got, want):
        assert (g == w) if np.isinf(w) else abs(g - w) <= TOL, (got, want)


def test_corner_unique_below_mu_wall_one():
    fs = analyse(_system([[1.0, 1.0]], left=0.0, mu_plane=0.5, mu_wall=0.9))
    assert fs.exists and fs.dimension == 0
    _close(_range(fs, PLANE), (1, 1))
    _close(_range(fs, LEFT_WALL), (0, 0))
    assert fs.implicit[int(np.flatnonzero(fs.system.lattice.j == LEFT_WALL)[0])] == "R=0"


def test_corner_segment_above_mu_wall_one():
    fs = analyse(_system([[1.0, 1.0]], left=0.0, mu_plane=0.5, mu_wall=1.5))
    assert fs.exists and fs.dimension == 1
    _close(_range(fs, PLANE), (1, 2))
    _close(_range(fs, PLANE, what="S"), (0, 1))
    _close(_range(fs, LEFT_WALL), (0, 1))
    _close(_range(fs, LEFT_WALL, what="S"), (-1, 0))


@pytest.mark.parametrize("mu", [0.1, 0.3, 0.8])
def test_disk_between_two_walls(mu):
    fs = analyse(_system([[1.0, 1.0]], left=0.0, right=2.0, mu_pp=mu, mu_plane=mu,
                         mu_wall=mu))
    assert fs.exists and fs.dimension == 3
    _close(_range(fs, PLANE), (0, INF))
    _close(_range(fs, PLANE, what="S"), (-INF, INF))
    _close(_range(fs, LEFT_WALL), (0, INF))
    _close(_range(fs, LEFT_WALL, what="S"), (-INF, 0.5))
    _close(_range(fs, RIGHT_WALL, what="S"), (-0.5, INF))
    d = fs.to_dict()
    json.dumps(d, allow_nan=False)  # null for unbounded ends, never Infinity
    left = next(c for c in d["contacts"] if c["j"] == -1)
    assert left["R"][1] is None and left["S"][0] is None
    assert abs(left["R"][0]) <= TOL and abs(left["S"][1] - 0.5) <= TOL


def test_disk_between_two_walls_frictionless():
    fs = analyse(_system([[1.0, 1.0]], left=0.0, right=2.0, mu_pp=0, mu_plane=0, mu_wall=0))
    assert fs.exists and fs.dimension == 1
    _close(_range(fs, PLANE), (1, 1))
    _close(_range(fs, LEFT_WALL), (0, INF))


S3 = np.sqrt(3.0)
PYRAMID = [[1.0, 1.0], [3.0, 1.0], [2.0, 1.0 + S3]]


def test_pyramid_between_walls_frictionless():
    fs = analyse(_system(PYRAMID, left=0.0, right=4.0, mu_pp=0, mu_plane=0, mu_wall=0))
    assert fs.exists and fs.dimension == 1
    _close(_range(fs, 2, i=0), (1 / S3, 1 / S3))  # bottom left - top
    _close(_range(fs, 2, i=1), (1 / S3, 1 / S3))
    _close(_range(fs, PLANE, i=0), (1.5, 1.5))
    _close(_range(fs, 1, i=0), (0, INF))  # the bottom pair
    _close(_range(fs, LEFT_WALL, i=0), (1 / (2 * S3), INF))
    _close(_range(fs, RIGHT_WALL, i=1), (1 / (2 * S3), INF))


def test_pyramid_without_walls_has_a_farkas_certificate():
    fs = analyse(_system(PYRAMID, mu_pp=0, mu_plane=0, mu_wall=0))
    assert not fs.exists and fs.radius > 1e9
    prob = StaticProblem(fs.system)
    g = prob.A.T @ fs.certificate  # = H y: relative velocities of the virtual motion
    c = prob.c
    assert np.all(g[:c] >= -1e-12) and prob.b @ fs.certificate < -0.1  # opens, gravity works
    floating = analyse(_system([[1.0, 5.0]], left=0.0, right=3.0))
    assert not floating.exists


def _affine_dimension(prob: StaticProblem, fs, draws: int, rng) -> int:
    """Rank of the differences of LP vertices of P inside a large box, for +-each coordinate
    and `draws` random costs: an independent lower bound on dim P that reaches it for enough
    generic costs."""
    big = 10.0 * (np.abs(fs.solution).max() + prob.scale * prob.p)
    bounds = [(max(lo, -big), min(hi, big)) for lo, hi in zip(prob.lb, prob.ub)]
    pts = []
    # the ends of every coordinate's range (in the box), then random costs
    costs = [s * e for e in np.eye(prob.n) for s in (1.0, -1.0)]
    for cost in costs + [rng.standard_normal(prob.n) for _ in range(draws)]:
        res = linprog(cost, A_ub=prob.G, b_ub=np.zeros(prob.G.shape[0]),
                      A_eq=prob.A, b_eq=prob.b, bounds=bounds, method="highs")
        assert res.status == 0
        pts.append(res.x)
    D = np.array(pts[1:]) - pts[0]
    if D.size == 0:
        return 0
    w = np.linalg.svd(D, compute_uv=False)
    return int(np.sum(w > 1e-7 * max(w[0], 1.0)))


@settings(max_examples=12)
@given(n=st.integers(2, 7), seed=st.integers(0, 10**5), mu=st.floats(0.05, 1.2),
       spread=st.floats(1.0, 1.6))
def test_properties_on_deposited_packings(n, seed, mu, spread):
    """Every checked network satisfies balance and the cones; every range contains it; the
    dimension equals the rank count and the affine rank of many vertices of P."""
    lat = deposit(n, seed=seed, radii=(1.0, spread), width=6.0)
    system = models.System(lat, mu_pp=mu, mu_plane=mu, mu_wall=mu)
    fs = analyse(system)
    if not fs.exists:
        return
    prob = StaticProblem(system)
    eq, viol = prob.residuals(fs.solution)
    assert eq <= 1e-9 * prob.scale * prob.p and viol <= 1e-9 * prob.scale * prob.p
    R, S = fs.solution[: fs.c], fs.solution[fs.c:]
    assert np.all(R >= -1e-9) and np.all(np.abs(S) <= system.mu * R + 1e-9)
    assert np.all(fs.lo - 1e-7 <= fs.solution) and np.all(fs.solution <= fs.hi + 1e-7)
    assert fs.unchecked == 0
    for a, kind in enumerate(fs.implicit):  # R = 0 on all of P iff its range is {0}
        assert (kind == "R=0") == (fs.hi[a] <= 1e-9 * prob.scale), a
    rng = np.random.default_rng(seed)
    # a lower bound: on an unbounded P many random vertices are the box's, and thin directions
    # (widths ~1e-2 against a box of ~1e2) were missed by 3 (dim + 2) random costs alone (the
    # deep profile's 7-disk pile, seed 1737, mu 0.4375: 6 with 27 draws, 7 with 200)
    assert _affine_dimension(prob, fs, 3 * (fs.dimension + 2), rng) == fs.dimension


@pytest.mark.parametrize("seed, mu", [(1, 0.3), (3, 0.5), (5, 1.0), (2, 0.05)])
def test_ranges_and_sliding_against_linprog_on_the_rows_form(seed, mu):
    """ForceLP solves P in cone coordinates (u = mu R - S, v = mu R + S as bounded columns)
    and the sliding contacts are partly settled by range optima already at the bound: an
    independent method, scipy's linprog on P written with its cone rows, must give the same
    range ends (to 1e-7 of the forces) and the same sliding contacts."""
    lat = deposit(6, seed=seed, radii=(0.8, 1.2), width=5.0)
    system = models.System(lat, mu_pp=mu, mu_plane=mu, mu_wall=mu)
    fs = analyse(system)
    if not fs.exists:
        pytest.skip("no equilibrium on this pile")
    prob = StaticProblem(system)
    bounds = [(None if not np.isfinite(lo) else lo, None if not np.isfinite(hi) else hi)
              for lo, hi in zip(prob.lb, prob.ub)]

    def opt(cost, A_eq=prob.A, b_eq=prob.b):
        return linprog(cost, A_ub=prob.G, b_ub=np.zeros(prob.G.shape[0]), A_eq=A_eq,
                       b_eq=b_eq, bounds=bounds, method="highs")

    scale = max(1.0, float(np.max(np.abs(fs.hi[np.isfinite(fs.hi)]))))
    for k in range(prob.n):
        for sgn, end in ((1.0, fs.lo[k]), (-1.0, fs.hi[k])):
            e = np.zeros(prob.n)
            e[k] = sgn
            res = opt(e)
            if res.status == 3:
                assert not np.isfinite(end), k
            else:
                assert res.status == 0 and abs(res.x[k] - end) <= 1e-7 * scale, k
    c, fric = prob.c, list(prob.fric)
    for a in range(c):  # can slide: max R with S = mu R or S = -mu R is positive
        can = False
        if a in fric:
            for s in (1.0, -1.0):
                row = np.zeros(prob.n)
                row[a], row[c + a] = -s * system.mu[a], 1.0
                A_eq = sp.vstack([prob.A, sp.csr_matrix(row)])
                e = np.zeros(prob.n)
                e[a] = -1.0
                res = opt(e, A_eq, np.r_[prob.b, 0.0])
                can |= res.status == 3 or (res.status == 0 and res.x[a] > 1e-9 * prob.scale)
        assert bool(fs.sliding[a]) == can, a


# Piles on which HiGHS found P empty but the Farkas y it returned failed the floating-point
# check (cone rows violated at its tolerance, ~2e-11, capping the radius near 1e10 weights):
# `analyse` raised. Found by a scan of 40-disk piles and by the deep hypothesis profile.
NEAR_MISSES = [(40, 2, (0.8, 1.2), 10.0, 0.3), (7, 1737, (1.0, 1.0894363145159462), 6.0, 0.4)]


@pytest.mark.parametrize("n, seed, radii, width, mu", NEAR_MISSES)
def test_farkas_certificate_where_the_lp_y_fails_the_float_check(n, seed, radii, width, mu):
    """Both the polished float certificate (what `analyse` returns) and the exact rational
    one from the LP's raw y prove P empty; scipy's linprog on the rows form agrees."""
    from rigidlcp.verify.statics.farkas import check, cone_rows, exact_certificate

    system = models.System(deposit(n, seed=seed, radii=radii, width=width), mu_pp=mu,
                           mu_plane=mu, mu_wall=mu)
    fs = analyse(system)
    assert fs.exists is False and fs.radius >= 1e9 * float(np.sum(system.masses))
    prob = StaticProblem(system)
    g = prob.A.T @ fs.certificate  # H y: every contact opens or stays inside its cone
    c = prob.c
    v = np.where(prob.mu > 0, prob.mu * np.abs(g[c:]) - g[:c], -g[:c])
    assert prob.b @ fs.certificate < 0 and np.max(v) <= 1e-13
    C = cone_rows(prob)
    raw = linprog(prob.b, A_ub=C, b_ub=np.zeros(C.shape[0]), bounds=(-1, 1), method="highs")
    assert not check(prob, raw.x).proves  # the raw y alone: the float check says no
    exact = exact_certificate(prob, raw.x)
    assert exact is not None and exact.exact and exact.radius == np.inf and exact.gap > 0
    bounds = [(None if not np.isfinite(lo) else lo, None if not np.isfinite(hi) else hi)
              for lo, hi in zip(prob.lb, prob.ub)]
    rows = linprog(np.zeros(prob.n), A_ub=prob.G, b_ub=np.zeros(prob.G.shape[0]), A_eq=prob.A,
                   b_eq=prob.b, bounds=bounds, method="highs")
    assert rows.status == 2  # infeasible
    assert json.loads(json.dumps(fs.to_dict(), allow_nan=False))["exists"] is False


def test_exact_farkas_check_refuses_a_pile_with_an_equilibrium():
    """On a pile with a checked equilibrium no y passes the exact check (it would prove P
    empty): random virtual velocities and the corner disk's."""
    from rigidlcp.verify.statics.farkas import exact_certificate

    system = models.System(deposit(12, seed=1, radii=(0.8, 1.2), width=6.0), mu_pp=0.5,
                           mu_plane=0.5, mu_wall=0.5)
    assert analyse(system, ranges=False).exists
    prob = StaticProblem(system)
    rng = np.random.default_rng(0)
    for _ in range(5):
        assert exact_certificate(prob, rng.standard_normal(3 * prob.p)) is None


@pytest.mark.parametrize("mu_wall", [0.5, 0.9, 0.988, 0.999])
def test_corner_contact_without_force_is_labelled_R_zero(mu_wall):
    """Case 1 below mu_wall = 1: R_w = S_w = 0 on all of P, so S_w = +mu R_w and S_w = -mu R_w
    hold there too; the label must be the strongest, R = 0 (it implies the others), and the
    dimension counts both unknowns as fixed (0 here)."""
    fs = analyse(_system([[1.0, 1.0]], left=0.0, mu_plane=0.5, mu_wall=mu_wall))
    wall = int(np.flatnonzero(fs.system.lattice.j == LEFT_WALL)[0])
    assert fs.implicit[wall] == "R=0" and fs.dimension == 0
    _close(_range(fs, LEFT_WALL), (0, 0))
    _close(_range(fs, LEFT_WALL, what="S"), (0, 0))


def test_one_implicit_cone_row_with_R_zero_is_labelled_R_zero():
    """The slack LPs decide rows from points within the LP's tolerance of P, where R ~ 1e-9 is
    rounding: the deep hypothesis profile's 2-disk pile at mu 0.988 had R = 0 on all of P but
    its R >= 0 row and one cone row decided so, and came out "S=+muR". The labels now ask a
    checked optimum for R > 0 before saying S = +-mu R. Forced here on the corner disk (R_w = 0
    on P): whichever single cone row is left undecided, the label is R = 0; at the plane
    (R_p = 1 on P), an undecided cone row stays S = +-mu R."""
    from rigidlcp.verify.statics.hull import labels

    prob = StaticProblem(_system([[1.0, 1.0]], left=0.0, mu_plane=0.5, mu_wall=0.9))
    lat = prob.system.lattice
    wall = int(np.flatnonzero(lat.j == LEFT_WALL)[0])
    plane = int(np.flatnonzero(lat.j == PLANE)[0])
    c, k = prob.c, prob.fric.size
    for a, want in ((wall, "R=0"), (plane, None)):
        n = int(np.flatnonzero(prob.fric == a)[0])
        for row, kind in ((c + n, "S=+muR"), (c + k + n, "S=-muR")):
            undecided = np.zeros(c + 2 * k, dtype=bool)
            undecided[row] = True
            assert labels(prob, undecided)[a] == (want or kind)


def test_undecided_existence_is_reported_as_null_with_its_reason():
    """When neither a checked point nor a checked certificate is found, the JSON says
    "exists": null and why (no case of it is known; the contract is checked directly)."""
    from rigidlcp.verify.statics.forceset import ForceSet

    system = _system([[1.0, 1.0]], left=0.0)
    fs = ForceSet(system, None, radius=12.5, undecided="equilibrium LP failed; Farkas "
                  "certificate not proved (radius 12.5 weights' units)")
    d = json.loads(json.dumps(fs.to_dict(), allow_nan=False))
    assert d["exists"] is None and "not proved" in d["undecided"]
    assert d["farkas_radius"] == 12.5 and d["contacts"][0]["R"] is None


@pytest.mark.parametrize("n, seed, radii, width, mu, empty",
                         [case + (True,) for case in NEAR_MISSES]
                         + [(12, 1, (0.8, 1.2), 6.0, 0.5, False)])
def test_farkas_lp_without_crossover_gives_the_verdict_with_crossover(n, seed, radii, width,
                                                                      mu, empty):
    """The Farkas LP's interior optimum (IPM, no crossover: the path taken first, and the only
    one on large piles) proves P empty exactly where the vertex (with crossover) does: on the
    near-miss piles (no equilibrium, see above) both settle to a checked certificate; on a
    pile with a checked equilibrium neither gives a y with b . y < 0 that passes."""
    from rigidlcp.verify.statics.farkas import _settle, cone_rows, farkas_lp

    system = models.System(deposit(n, seed=seed, radii=radii, width=width), mu_pp=mu,
                           mu_plane=mu, mu_wall=mu)
    assert analyse(system, ranges=False).exists is (not empty)
    prob = StaticProblem(system)
    C = cone_rows(prob)
    verdicts = []
    for crossover in (False, True):
        y = farkas_lp(prob, C, crossover)
        cert = None if y is None else _settle(prob, C, y)
        verdicts.append(cert is not None and cert.proves)
        if cert is not None and cert.proves:
            g = prob.A.T @ cert.y
            v = np.where(prob.mu > 0, prob.mu * np.abs(g[prob.c:]) - g[:prob.c], -g[:prob.c])
            assert prob.b @ cert.y < 0 and (cert.exact or np.max(v) <= 1e-13)
    assert verdicts == [empty, empty]
