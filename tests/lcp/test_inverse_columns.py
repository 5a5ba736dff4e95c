"""The C forward bound (lcp/acceptance/_bound_core.h: forward_bound, through
`_accuracy_c.bound`) against a transcription of its definition in plain Python floats, bit for
bit: the LU with partial pivoting, the long-double residual, g, the comparison-matrix bound
C(U)^-1 C(L)^-1 P g taken when it is at most CHEAP_FERR (and Skeel's likewise certifies), else
|K^-1| formed column by column by the substitutions -- each column on its own, its L solve
begun at its own unit entry (`bound(K, k, y, True)`: always formed). The C code forms the
columns 16 at a time (lcp/acceptance/_inverse_core.h, four AVX2 registers where the CPU has
them); grouping must not change a bit, across the groups' boundaries (m = 15, 16, 17, 31, 32,
33) and on ill-conditioned and singular systems (the same code 1)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rigidlcp.lcp.acceptance import accuracy

EPS = float(np.finfo(float).eps)
EPS_LD = float(np.finfo(np.longdouble).eps)
#: _bound_core.h's CHEAP_FERR: the comparison bound is reported up to this value.
CHEAP_FERR = 1e-13

needs_c = pytest.mark.skipif(accuracy._accuracy_c is None,
                             reason="the accuracy extension is not built")


def lu_ref(K: list[list[float]]):
    """_lu_core.h's `lu`, in Python floats (each product and difference rounded: no fused
    multiply-add), or None when a pivot is 0 or below m eps times the largest."""
    m = len(K)
    A = [row[:] for row in K]
    perm = []
    umax, umin = 0.0, math.inf
    for k in range(m):
        p = k
        for i in range(k + 1, m):
            if abs(A[i][k]) > abs(A[p][k]):
                p = i
        perm.append(p)
        if A[p][k] == 0.0:
            return None
        A[k], A[p] = A[p], A[k]
        piv = A[k][k]
        for i in range(k + 1, m):
            ell = A[i][k] / piv
            A[i][k] = ell
            if ell == 0.0:
                continue
            for j in range(k + 1, m):
                A[i][j] -= ell * A[k][j]
        umax, umin = max(umax, abs(piv)), min(umin, abs(piv))
    if not umin > m * EPS * umax:
        return None
    return A, perm


def abs_dot2(a, x, s, lo, hi):
    """_bound_core.h's abs_dot2: sum_j |a_j| x_j and sum_j |a_j| s_j for lo <= j < hi, each in
    four partial sums (j - lo mod 4; the remainder into the first), then (p0 + p1) + (p2 + p3)."""
    px, ps = [0.0] * 4, [0.0] * 4
    j = lo
    while j + 4 <= hi:
        for t in range(4):
            px[t] += abs(a[j + t]) * x[j + t]
            ps[t] += abs(a[j + t]) * s[j + t]
        j += 4
    while j < hi:
        px[0] += abs(a[j]) * x[j]
        ps[0] += abs(a[j]) * s[j]
        j += 1
    return (px[0] + px[1]) + (px[2] + px[3]), (ps[0] + ps[1]) + (ps[2] + ps[3])


def comparison_ref(A, perm, g, rows, ymax):
    """_bound_core.h's comparison_bound: ferr from C(U)^-1 C(L)^-1 P g (with the slack), or None
    when it does not certify (Skeel's bound above half of 1 / (m eps), or the bound above
    CHEAP_FERR, or not finite)."""
    m = len(g)
    x, s = list(g), list(rows)
    for t in range(m):  # `permute`
        x[t], x[perm[t]] = x[perm[t]], x[t]
        s[t], s[perm[t]] = s[perm[t]], s[t]
    for i in range(1, m):
        dx, ds = abs_dot2(A[i], x, s, 0, i)
        x[i] += dx
        s[i] += ds
    for i in range(m - 1, -1, -1):
        dx, ds = abs_dot2(A[i], x, s, i + 1, m)
        d = abs(A[i][i])
        x[i] = (x[i] + dx) / d
        s[i] = (s[i] + ds) / d
    slack = 1.0 + 8.0 * float((m + 2) * (m + 2)) * EPS
    if not all(map(math.isfinite, x + s)):
        return None
    top, skeel = max([0.0, *x]), max([0.0, *s])
    if not skeel * slack * m * EPS <= 0.5:
        return None
    f = (top * slack) / max(ymax, 1e-300) * slack + EPS
    return f if f <= CHEAP_FERR else None


def bound_ref(K: np.ndarray, k: np.ndarray, y: np.ndarray,
              exact: bool = False) -> tuple[int, float]:
    """(code, ferr) of `_accuracy_c.bound(K, k, y, exact)`: LAPACK's bound
    || |K^-1| g ||_inf / ||y||_inf + eps, g = |r| + (m + 1) eps_ld (|K| |y| + |k|), r = K y + k
    summed in long double; code 1 when K is singular to working precision (Skeel's
    || |K^-1| |K| 1 || beyond 1 / (m eps)). Unless exact, the comparison-matrix bound instead
    when it certifies (comparison_ref)."""
    m = k.size
    Kl = [[float(v) for v in row] for row in K]
    kl, yl = [float(v) for v in k], [float(v) for v in y]
    f = lu_ref(Kl)
    if f is None:
        return 1, math.nan
    A, perm = f
    rows = []
    for i in range(m):
        s = 0.0
        for j in range(m):
            s += abs(Kl[i][j])
        rows.append(s)
    g = []
    for i in range(m):
        r = np.longdouble(kl[i])
        for j in range(m):
            r += np.longdouble(Kl[i][j]) * np.longdouble(yl[j])
        s = abs(kl[i])
        for j in range(m):
            s += abs(Kl[i][j]) * abs(yl[j])
        g.append(abs(float(r)) + (m + 1) * EPS_LD * s)
    ymax = max([0.0, *map(abs, yl)])
    cheap = None if exact else comparison_ref(A, perm, g, rows, ymax)
    if cheap is not None:
        return 0, cheap
    lab = list(range(m))
    for t in range(m):
        lab[t], lab[perm[t]] = lab[perm[t]], lab[t]
    at = [0] * m
    for t in range(m):
        at[lab[t]] = t
    acc, sk = [0.0] * m, [0.0] * m
    for j in range(m):  # column j of K^-1 = U^-1 L^-1 P e_j, on its own
        x = [0.0] * m
        x[at[j]] = 1.0
        for i in range(at[j] + 1, m):
            for ell in range(at[j], i):
                x[i] -= A[i][ell] * x[ell]
        for i in range(m - 1, -1, -1):
            for ell in range(i + 1, m):
                x[i] -= A[i][ell] * x[ell]
            x[i] = x[i] / A[i][i]
        for i in range(m):
            acc[i] += abs(x[i]) * g[j]
            sk[i] += abs(x[i]) * rows[j]
    if not all(map(math.isfinite, acc + sk)):
        return 1, math.nan
    top, skeel = max([0.0, *acc]), max([0.0, *sk])
    if skeel * m * EPS > 1.0:
        return 1, math.nan
    ferr = top / max(ymax, 1e-300) + EPS
    return 0, ferr if math.isfinite(ferr) else math.inf


def system(m: int, kind: str, seed: int):
    """K (psd, general, graded or singular), y over 40 binary decades and k = -K y, off by 1e-12
    for seed 0 (a y off its system: the formed |K^-1|) and at rounding level for seed 1 (the
    comparison bound where it certifies)."""
    rng = np.random.default_rng([m, seed])
    A = rng.standard_normal((m, m))
    if kind == "psd":
        K = A @ A.T + 0.1 * np.eye(m)
    elif kind == "general":
        K = A
    elif kind == "graded":  # singular values over 12 decades
        U, _, Vt = np.linalg.svd(A)
        K = (U * np.logspace(0, -12, m)) @ Vt
    else:  # "singular": rank m - 1
        K = A.copy()
        K[-1] = K[0] + K[1] if m > 2 else 0.0
    y = rng.standard_normal(m) * np.exp2(rng.integers(-20, 20, m))
    k = -(K @ y) + (1e-12 if seed == 0 else 0.0) * rng.standard_normal(m)
    return np.ascontiguousarray(K), k, y


@needs_c
@pytest.mark.parametrize("m", [*range(1, 20), 31, 32, 33, 40])
@pytest.mark.parametrize("kind", ["psd", "general", "graded", "singular"])
def test_c_bound_is_its_definition_bit_for_bit(m, kind):
    """Both routes (comparison bound, |K^-1| formed) bit for bit; test_cheap_route_is_taken
    checks that the comparison route is met here."""
    for seed in range(2):
        K, k, y = system(m, kind, seed)
        for exact in (False, True):
            code, ferr = accuracy._accuracy_c.bound(K, k, y, exact)
            ref_code, ref_ferr = bound_ref(K, k, y, exact)
            assert code == ref_code, (m, kind, seed, exact)
            if code == 0:
                assert np.float64(ferr).tobytes() == np.float64(ref_ferr).tobytes(), (
                    ferr, ref_ferr, exact)


@needs_c
def test_cheap_route_is_taken():
    """The systems above meet both routes of forward_bound: the comparison bound reported (a
    bound larger than the formed one, up to CHEAP_FERR) and |K^-1| formed."""
    routes = set()
    for m in (*range(1, 20), 31, 32, 33, 40):
        for kind in ("psd", "general", "graded"):
            for seed in range(2):
                K, k, y = system(m, kind, seed)
                code, ferr = accuracy._accuracy_c.bound(K, k, y)
                code_x, exact = accuracy._accuracy_c.bound(K, k, y, True)
                if code == 0 and code_x == 0:
                    assert ferr >= exact
                    routes.add("comparison" if ferr > exact else "formed")
    assert routes == {"comparison", "formed"}
