"""Event-driven evolution: analytic cases, balances, symmetry, the paper's steady states."""

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from rigidlcp import lcp, models
from rigidlcp.models.event import contact_matrix, event_problem
from rigidlcp.models.observables import horizontal_balance, rotational_energy
from rigidlcp.models.runio import load_run, save_run

# --- one disk on the plane (lx = ly = 1, frictionless walls) -------------------------------
#
# Box frame: the plane moves at -V(t), accelerates at -gamma. Plane contact: n = (0, -1),
# t = (1, 0), v_t = -V - r omega, torque -r S on the disk, R = m g. Rolling (a_t = 0) needs
# -gamma + r^2 S / I = 0, i.e. S = I gamma / r^2, admissible while |S| <= mu m g: the
# threshold is |gamma| <= gamma* = mu m g r^2 / I, with omega' = -gamma / r and
# F_g = S = I gamma / r^2. Beyond it the disk slides with sgn(v_t) = -sgn(gamma):
# S = sgn(gamma) mu m g, omega' = -r S / I, mu_g = sgn(gamma) mu.
# From a sliding start with sgn(v_t) = s and |gamma| < gamma*, a_t = -gamma - s mu m g r^2/I
# has the sign of -s, so the disk starts rolling at t* = -v_t(0) / a_t.

@settings(max_examples=30, deadline=None)
@given(mu=st.floats(0.05, 1.0), gamma=st.floats(-2.0, 2.0), inertia=st.floats(0.2, 1.0),
       omega0=st.floats(-3.0, 3.0), V0=st.floats(-1.0, 1.0))
def test_one_disk_rolling_and_sliding(mu, gamma, inertia, omega0, V0):
    m = g = r = 1.0
    gstar = mu * m * g * r**2 / inertia
    assume(abs(abs(gamma) - gstar) > 1e-3)
    vt0 = -V0 - r * omega0
    assume(abs(vt0) > 1e-6)
    system = models.System(models.rectangular(1, 1), mu_plane=mu, gamma=gamma, V0=V0,
                           inertia=inertia)
    run = models.simulate(system, omega=[omega0])
    assert run.status == "steady"
    last = run.last
    # Absolute error 1e-9 g: Lemke decides ties and zeros at 1e-10 of the data's scale (its
    # tol), so a gamma of 1e-11 g can be rounded to rest: correct to that scale, not beyond.
    atol = 1e-9
    if abs(gamma) < gstar:
        s = np.sign(vt0)
        a_t = -gamma - s * mu * m * g * r**2 / inertia
        assert np.isclose(last.omega_dot[0], -gamma / r, rtol=1e-9, atol=atol)
        assert np.isclose(last.mu_g, inertia * gamma / r**2 / (m * g), rtol=1e-9, atol=atol)
        assert last.s[0] == 0  # rolling: non-sliding plane contact
        assert np.isclose(last.t, -vt0 / a_t, rtol=1e-10)
    else:
        S = np.sign(gamma) * mu * m * g
        assert np.isclose(last.omega_dot[0], -r * S / inertia, rtol=1e-9, atol=atol)
        assert np.isclose(last.mu_g, np.sign(gamma) * mu, rtol=1e-9, atol=atol)
        assert last.s[0] == -np.sign(gamma)


# --- the methods agree on a 4x2 run ------------------------------------------------------------

FIG9 = dict(mu_pp=0.1, mu_plane=0.2, mu_wall=0.0, gamma=0.16)


@pytest.fixture(scope="module")
def run_4x2():
    system = models.System(models.rectangular(4, 2), **FIG9)
    return models.simulate(system, seed=1, method="lemke")


def test_methods_agree_at_every_event_of_a_4x2_run(run_4x2):
    system = run_4x2.system
    assert run_4x2.status == "steady"
    for k, rec in enumerate(run_4x2.records):
        ep = event_problem(system, run_4x2.state_at(k))
        raw = {}
        for method in ("lemke", "pivoting") + (("enumerate",) if ep.lcp.n <= 16 else ()):
            sol = lcp.solve(ep.lcp, method)
            assert sol.success and sol.residual < 1e-9, (k, method, sol)
            raw[method] = ep.unpack(sol.z)
        # Accelerations agree with the run's (lemke + selection) at every event ...
        for method, es in raw.items():
            assert np.allclose(es.omega_dot, rec.omega_dot, atol=1e-8), (k, method)
        # ... and the raw forces differ only by a null vector of the contact matrix (Eq. 2.15).
        ref = raw["lemke"]
        Mc, _ = contact_matrix(system, ref.R > 1e-9, ref.s)
        for es in raw.values():
            d = np.concatenate([es.R - ref.R, es.S - ref.S])
            assert np.abs(Mc @ d).max() < 1e-8


def test_steady_state_agrees_between_lemke_and_warm_pivoting():
    system = models.System(models.rectangular(10, 2), mu_pp=0.1, mu_plane=0.2, gamma=0.3)
    a = models.simulate(system, seed=2, method="lemke")
    b = models.simulate(system, seed=2, method="pivoting")
    assert a.status == b.status == "steady"
    assert np.isclose(a.last.mu_g, b.last.mu_g, atol=1e-9)
    assert np.allclose(a.last.omega_dot, b.last.omega_dot, atol=1e-8)


# --- balances ----------------------------------------------------------------------------------

@pytest.mark.parametrize("lattice, lx, ly, gamma", [("rect", 4, 2, 0.16), ("tri", 4, 3, 0.1),
                                                    ("rect", 3, 3, -0.2)])
def test_force_and_energy_balance(lattice, lx, ly, gamma):
    system = models.System(models.make_lattice(lattice, lx, ly), mu_pp=0.1, mu_plane=0.3,
                           mu_wall=0.05, gamma=gamma, V0=0.3)
    run = models.simulate(system, seed=4, max_events=200)
    assert run.status in ("steady", "event_limit")
    m_g = system.total_mass
    for k, rec in enumerate(run.records):
        # Eq. (2.1) from the box: plane + walls push the disks with m_g gamma horizontally.
        assert abs(horizontal_balance(system, rec.R, rec.S)) < 1e-9 * max(1, m_g)
        if k + 1 == run.n_events:
            break
        # Between events: dE_rot/dt = F_g V - D, with F_g constant and V, D linear in time.
        nxt = run.records[k + 1]
        dt = nxt.t - rec.t
        F_g = rec.mu_g * m_g * system.g
        D_end = -(rec.S @ (rec.vt + rec.at * dt))
        work = dt * (F_g * 0.5 * (rec.V + nxt.V) - 0.5 * (rec.dissipation + D_end))
        dE = rotational_energy(system, nxt.omega) - rotational_energy(system, rec.omega)
        assert np.isclose(dE, work, rtol=1e-8, atol=1e-10)
        assert rec.dissipation >= -1e-10 and D_end >= -1e-10


# --- mirror symmetry ---------------------------------------------------------------------------

def mirror_maps(lat):
    """Disk and contact permutations of the mirror x -> width - x."""
    disks = np.empty(lat.p, int)
    for k in range(lat.p):
        target = np.array([lat.width - lat.x[k, 0], lat.x[k, 1]])
        disks[k] = int(np.argmin(np.linalg.norm(lat.x - target, axis=1)))
    point = lat.x[lat.i] + lat.radius * lat.n
    contacts = np.empty(lat.c, int)
    for a in range(lat.c):
        target = np.array([lat.width - point[a, 0], point[a, 1]])
        contacts[a] = int(np.argmin(np.linalg.norm(point - target, axis=1)))
    return disks, contacts


def test_mirror_symmetry_of_a_run():
    lat = models.make_lattice("rect", 5, 3)
    params = dict(mu_pp=0.15, mu_plane=0.25, mu_wall=0.05)
    a_sys = models.System(lat, gamma=0.2, V0=0.1, **params)
    b_sys = models.System(lat, gamma=-0.2, V0=-0.1, **params)
    disks, contacts = mirror_maps(lat)
    omega = np.random.default_rng(7).uniform(-1, 1, lat.p)
    omega_b = np.empty_like(omega)
    omega_b[disks] = -omega
    a = models.simulate(a_sys, omega=omega)
    b = models.simulate(b_sys, omega=omega_b)
    assert a.status == b.status and a.n_events == b.n_events
    # Mirror images agree to rounding (1e-13) until the first event whose solution is not
    # unique; from there the canonical selection (a linear then a quadratic program on the
    # solution's face) amplifies the 1e-13 differences of the states about 1e3-fold, and an
    # event time t_k = |v_t| / |a_t| amplifies them again by 1/|a_t|. Hence the tolerances.
    for ra, rb in zip(a.records, b.records):
        assert np.isclose(ra.t, rb.t, rtol=1e-6, atol=1e-12)
        assert np.allclose(rb.omega_dot[disks], -ra.omega_dot, atol=1e-7)
        assert np.allclose(rb.R[contacts], ra.R, atol=1e-6)
        assert np.allclose(np.abs(rb.S[contacts]), np.abs(ra.S), atol=1e-6)
        assert np.isclose(rb.mu_g, -ra.mu_g, atol=1e-7)
        assert np.isclose(rb.dissipation, ra.dissipation, atol=1e-6)


@pytest.mark.parametrize("lattice", ["rect", "tri"])
def test_mirror_image_of_a_solution_is_a_solution(lattice):
    """Event by event, in both lattices: the mirror image of a solution (R kept, S reversed on
    the mirrored contacts, omega' reversed on the mirrored disks) solves the mirrored event.
    Whole triangular runs are not mirror images of each other: their events have several
    solutions and a method may pick either (docs/theory.md, "Non-unique events")."""
    from rigidlcp.verify.certificates.laws import check_contact_laws

    lat = models.make_lattice(lattice, 5, 3)
    params = dict(mu_pp=0.15, mu_plane=0.25, mu_wall=0.05)
    a_sys = models.System(lat, gamma=0.2, V0=0.1, **params)
    b_sys = models.System(lat, gamma=-0.2, V0=-0.1, **params)
    disks, contacts = mirror_maps(lat)
    run = models.simulate(a_sys, seed=7, max_events=15)
    for k, rec in enumerate(run.records):
        st = run.state_at(k)
        omega_b = np.empty_like(st.omega)
        omega_b[disks] = -st.omega
        s_b = np.empty_like(st.s)
        s_b[contacts] = -st.s
        state_b = models.State(st.t, omega_b, -st.V, s_b)
        R_b, S_b = np.empty_like(rec.R), np.empty_like(rec.S)
        R_b[contacts], S_b[contacts] = rec.R, -rec.S
        check_contact_laws(b_sys, state_b, R_b, S_b)
        acc = models.Dynamics(b_sys).accelerations(np.concatenate([R_b, S_b]))
        assert np.allclose(acc[2 * lat.p:][disks], -rec.omega_dot, atol=1e-9)


# --- the paper's steady states (Sec. IV) -------------------------------------------------------

FIG10 = dict(mu_pp=0.1, mu_plane=0.2, mu_wall=0.0, gamma=0.3)


@pytest.fixture(scope="module")
def fig10_reference():
    system = models.System(models.rectangular(10, 2), **FIG10)
    return models.simulate(system, seed=0)


@settings(max_examples=5, deadline=None)
@given(seed=st.integers(1, 10**6), scale=st.floats(0.2, 3.0))
def test_steady_state_independent_of_initial_velocities(fig10_reference, seed, scale):
    """Fig. 10: the steady state (mu_g, angular accelerations, forces) does not depend on the
    initial angular velocities."""
    system = fig10_reference.system
    state = models.initial_state(system, seed=seed, omega_scale=scale)
    run = models.simulate(system, state)
    ref = fig10_reference.last
    assert run.status == fig10_reference.status == "steady"
    assert np.isclose(run.last.mu_g, ref.mu_g, atol=1e-9)
    assert np.allclose(run.last.omega_dot, ref.omega_dot, atol=1e-8)
    assert np.allclose(run.last.R, ref.R, atol=1e-7)


@pytest.fixture(scope="module")
def constant_velocity_run():
    """Fig. 13's setting: a rectangular 10x3 array driven at constant velocity."""
    system = models.System(models.rectangular(10, 3), mu_pp=0.1, mu_plane=0.2, gamma=0.0,
                           V0=1.0)
    return models.simulate(system, seed=0)


def test_constant_velocity_dissipation(constant_velocity_run):
    run = constant_velocity_run
    assert run.status == "steady"
    D = run.array("dissipation")
    # Within every interval between events D decreases (dD/dt = -sum S a_t <= 0) ...
    for rec in run.records[:-1]:
        assert -(rec.S @ rec.at) <= 1e-9
    # ... and the steady state has the least dissipation of the run, essentially zero.
    assert D[-1] <= D.min() + 1e-9 and D[-1] < 1e-8 * D[0]
    # Not monotone from event to event, though: D jumps up at some events (docs/theory.md).
    assert np.any(np.diff(D) > 1e-3)


def test_constant_velocity_steady_contact_states(constant_velocity_run):
    """Sec. IV C: every transmitting contact except those with the walls ends non-sliding;
    the lateral contacts transmit nothing (no horizontal load at constant velocity) and may
    slide freely (rows in mode 1: neighbours turn the same way)."""
    run = constant_velocity_run
    system, last = run.system, run.last
    lat = system.lattice
    T = last.R > 1e-8
    assert not np.any(T & (lat.kind != "wall") & (last.s != 0))
    lateral = (lat.kind == "pp") & (np.abs(lat.n[:, 1]) < 1e-12)
    assert np.all(last.R[lateral] < 1e-8)
    # rows in mode 1 (equal angular velocities), columns in mode 3 (alternating)
    omega = last.omega.reshape(lat.ly, lat.lx)
    assert np.allclose(omega, omega[:, :1], atol=1e-9)
    assert np.allclose(omega[1:], -omega[:-1], atol=1e-9)


# --- stops -------------------------------------------------------------------------------------

def test_detachment_is_reported_with_the_contact():
    """No gravity, box accelerating: wall friction on a spinning upper disk lifts it."""
    system = models.System(models.rectangular(1, 2), mu_wall=0.5, mu_pp=0.2, mu_plane=0.2,
                           gamma=1.0, g=0.0)
    run = models.simulate(system, omega=[0.0, 3.0])
    assert run.status == "detachment"
    assert run.contacts == [3] and "disk 0 (row 0, col 0) - disk 1" in run.message
    assert run.last.R[1] == pytest.approx(1.0)  # left wall holds the upper disk: m gamma


def test_limits_and_bad_options():
    system = models.System(models.rectangular(4, 2), **FIG9)
    run = models.simulate(system, seed=1, max_events=3)
    assert run.status == "event_limit" and run.n_events == 3
    run = models.simulate(system, seed=1, t_max=0.05)
    assert run.status == "time_limit" and run.final.t == pytest.approx(0.05)
    with pytest.raises(lcp.InvalidProblem, match="unknown method 'nope'"):
        models.simulate(system, seed=1, method="nope")
    with pytest.raises(ValueError, match="selection must be one of"):
        models.simulate(system, seed=1, select="best")


def test_save_load_roundtrip(tmp_path, run_4x2):
    path = save_run(run_4x2, tmp_path / "run")
    assert path.name == "run.npz" and (tmp_path / "run.json").exists()
    back = load_run(path)
    assert back.status == run_4x2.status and back.n_events == run_4x2.n_events
    assert back.system.describe() == run_4x2.system.describe()
    for a, b in zip(run_4x2.records, back.records):
        assert a.t == b.t and np.array_equal(a.omega_dot, b.omega_dot)
        assert np.array_equal(a.s, b.s) and np.array_equal(a.s_in, b.s_in)
    with pytest.raises(FileNotFoundError):
        load_run(tmp_path / "missing.npz")
