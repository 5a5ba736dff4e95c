"""The face's programs in its own coordinates (lcp.face_coords: certified pivoted-QR null space,
DAQP for the LP and QP) against the reference path (SVD, HiGHS, Clarabel: lcp.face_reference,
the code before issue 13), on random, rank-deficient and degenerate data."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp.faces import face_coords as fc
from rigidlcp.lcp.faces import face_reference as fr
from rigidlcp.lcp.faces.face import face_minimum_norm


def rank_deficient(rng, n, r, scale=1.0, symmetric=False):
    """An n x n matrix of rank r (r <= n), entries of order `scale`."""
    if symmetric:
        J = rng.standard_normal((n, r))
        return scale * J @ J.T / max(r, 1)
    return scale * rng.standard_normal((n, r)) @ rng.standard_normal((r, n)) / max(r, 1)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10_000), st.integers(1, 40), st.floats(0.0, 1.0),
       st.sampled_from([1e-3, 1.0, 1e4]))
def test_qr_null_space_is_the_svd_null_space(seed, n, frac, scale):
    rng = np.random.default_rng(seed)
    r = int(round(frac * n))
    M = rank_deficient(rng, n, r, scale)
    N, how = fc.null_space(M)
    Ns, _ = fc.null_space(M, method="svd")
    assert N.shape == Ns.shape  # the same rank decision (proved, or the SVD's own)
    assert np.allclose(N.T @ N, np.eye(N.shape[1]), atol=1e-12)
    assert np.abs(M @ N).max(initial=0.0) <= 1e-12 * max(np.abs(M).max(initial=0.0), 1.0) * n
    assert np.linalg.norm(N @ N.T - Ns @ Ns.T) <= 1e-9  # same subspace
    if how == "qr":
        # the certificate: the SVD's singular values straddle its threshold by the margin
        sig = np.linalg.svd(M, compute_uv=False)
        tol = n * np.finfo(float).eps * max(sig.max(initial=0.0), 1.0) * 1e3
        k = n - N.shape[1]
        assert k == 0 or sig[k - 1] > fc.RANK_MARGIN * tol * 0.99
        assert k == n or sig[k] < tol / fc.RANK_MARGIN * 1.01


def test_rank_near_the_threshold_goes_to_the_svd():
    rng = np.random.default_rng(3)
    U, _ = np.linalg.qr(rng.standard_normal((6, 6)))
    V, _ = np.linalg.qr(rng.standard_normal((6, 6)))
    tol = 6 * np.finfo(float).eps * 1e3 * 3.0  # the SVD's threshold, sigma_max = 3
    M = U @ np.diag([3.0, 2.0, 1.0, 1.0, 2.0 * tol, 0.0]) @ V.T  # sigma_5 just above it
    N, how = fc.null_space(M)
    assert how == "svd" and N.shape == (6, 1)


def random_polytope(rng, d, m, zeros):
    """Aineq x <= bineq with x = 0 feasible, `zeros` rows tight at 0 (degenerate), a box."""
    A = np.vstack([rng.standard_normal((m, d)), np.eye(d), -np.eye(d)])
    b = np.concatenate([rng.uniform(0.0, 2.0, m), np.full(2 * d, 3.0)])
    b[rng.choice(m, size=min(zeros, m), replace=False)] = 0.0
    return A, b


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 10_000), st.integers(1, 12), st.integers(0, 40), st.integers(0, 6),
       st.booleans())
def test_small_lp_matches_highs(seed, d, m, zeros, integer_cost):
    from scipy.optimize import linprog

    rng = np.random.default_rng(seed)
    A, b = random_polytope(rng, d, m, zeros)
    g = rng.integers(-2, 3, d).astype(float) if integer_cost else rng.standard_normal(d)
    x = fc.small_lp(g, A, b)
    ref = linprog(g, A_ub=A, b_ub=b, bounds=(None, None), method="highs")
    assert ref.status == 0 and x is not None
    assert np.all(A @ x <= b + 1e-10)
    assert g @ x == pytest.approx(ref.fun, abs=1e-9 * max(1.0, abs(ref.fun)))


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 10_000), st.integers(1, 12), st.integers(0, 40), st.integers(0, 6),
       st.booleans())
def test_small_qp_matches_clarabel(seed, d, m, zeros, with_equality):
    rng = np.random.default_rng(seed)
    A, b = random_polytope(rng, d, m, zeros)
    J = rng.standard_normal((d + 2, d))
    P = J.T @ J + 1e-10 * np.eye(d)
    f = 3.0 * rng.standard_normal(d)
    Aeq = beq = None
    if with_equality:  # through the feasible x = 0, as the engine's c'y = bound
        Aeq, beq = rng.standard_normal((1, d)), np.zeros(1)
    x = fc.small_qp(P, f, A, b, Aeq, beq)
    xr, status = fr._qp(P, f, A, b, Aeq, beq)
    assert x is not None and xr is not None, status
    obj = 0.5 * x @ P @ x + f @ x
    obj_r = 0.5 * xr @ P @ xr + f @ xr
    assert obj <= obj_r + 1e-9 * max(1.0, abs(obj_r))
    assert np.allclose(x, xr, atol=1e-7 * max(1.0, np.abs(xr).max()))  # strictly convex


def lcp_with_a_face(rng, n, r, degenerate, symmetric):
    """An LCP with a known solution z whose face has a null space (M_AA of rank <= r): q is
    built from z; `degenerate` indices get z_i = w_i = 0."""
    M = rank_deficient(rng, n, r, symmetric=symmetric) + np.diag(rng.uniform(0, 0.1, n)) * (
        rng.random(n) < 0.2)
    support = rng.random(n) < 0.7
    z = np.where(support, rng.uniform(0.5, 2.0, n), 0.0)
    w = np.where(support, 0.0, rng.uniform(0.5, 2.0, n))
    deg = rng.choice(n, size=min(degenerate, n), replace=False)
    z[deg], w[deg] = 0.0, 0.0
    q = w - M @ z
    return lcp.LCP(M, q), z


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10_000), st.integers(2, 30), st.floats(0.1, 0.9), st.integers(0, 3),
       st.booleans(), st.booleans(), st.booleans())
def test_face_minimum_norm_paths_agree(seed, n, frac, degenerate, symmetric, use_G, use_side):
    rng = np.random.default_rng(seed)
    problem, z = lcp_with_a_face(rng, n, max(1, int(frac * n)), degenerate, symmetric)
    c = rng.uniform(0.0, 1.0, n) * (rng.random(n) < 0.5)
    G = rng.standard_normal((n + 3, n)) if use_G else None
    side = rng.random(n) < 0.5 if use_side else None
    new = face_minimum_norm(problem, z, G, c=c, z_side=side)
    old = face_minimum_norm(problem, z, G, c=c, z_side=side, solvers="reference")
    M, q = problem.M, problem.q
    scale = max(np.abs(q).max(), np.abs(z).max())
    for res in (new, old):  # every point returned is a solution
        if res.status.startswith("selected"):
            assert lcp.complementarity_residual(res.z, M @ res.z + q) <= 1e-9 * scale
    if not (new.status.startswith("selected") and old.status.startswith("selected")):
        return  # the reference's HiGHS/Clarabel point may fail its accuracy check
    assert c @ new.z == pytest.approx(c @ old.z, abs=1e-8 * scale)  # the same LP minimum
    tol = 1e-9 * scale
    same_face = np.array_equal(new.z > tol, old.z > tol) and np.array_equal(
        M @ new.z + q > tol, M @ old.z + q > tol)
    if same_face:  # the QP stage over the same set: the same (unique) point
        assert np.allclose(new.z, old.z, atol=1e-6 * scale)


def test_small_path_falls_back_to_the_reference(monkeypatch):
    from rigidlcp.lcp.faces import face

    problem = lcp.LCP(np.array([[1.0, 1.0], [1.0, 1.0]]), np.array([-1.0, -1.0]))
    monkeypatch.setattr(face, "small_qp", lambda *a, **k: None)
    res = face_minimum_norm(problem, np.array([0.3, 0.7]))
    assert res.status == "selected" and np.allclose(res.z, [0.5, 0.5], atol=1e-9)


def test_unknown_solvers_is_an_error():
    problem = lcp.LCP(np.eye(2), -np.ones(2))
    with pytest.raises(ValueError, match="solvers"):
        face_minimum_norm(problem, np.ones(2), solvers="daqp")
