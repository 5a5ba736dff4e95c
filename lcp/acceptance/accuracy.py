"""Backward error and forward error bound of an answer, and the one acceptance test.

LAPACK's expert drivers (xGESVX) return with x a backward error BERR and a forward error bound
FERR; every "solved" here carries the same two numbers, computed on the problem passed.

The problem is written as one system in x = [u; v] (an LCP has no u):

    K x + k = [A u + C v + a; D u + B v + b] = [0; w],      0 <= v perp w >= 0.

**Backward error** (Oettli-Prager, row by row). With s = max(|K| |x| + |k|, s_d) (the size of
the terms that make up each row, the scale of the rounding of K x + k, floored by the data's
scale s_d = |k|_inf + ||K||_inf |k|_inf / |K|_max, where x is at the data's own scale):

    berr = max( max_eq |(K x + k)_i| / s_i,  max_comp |min(v_i / v_s, w_i / s_i)| ),

v_s = max(|v|_inf, |b|_inf / |B|_max) as in lcp.residual. Unlike the normwise measure, w_i is
judged against its own row's terms and the data, never against |z|: inflating z cannot hide a
row that z does not touch (M = [[1,-1,0],[-1,1,0],[0,0,1]], q = (-1,1,-100),
z = (1e15,1e15,0): berr = 1/3 on row 3). s <= lcp.residual's w_s, so berr is never below
lcp.residual's scaled residual. (The z side stays normwise: a z_i that is 1e-8 of |z|_inf is
zero to the accuracy the forward error bound speaks of.)

**Forward error bound** of the pattern's system. The pattern P is the basis of the method that
ended on one, else {i : v_i / v_s > w_i / s_i}; the system is K_PP y = -k_P over the rows and
unknowns of u and v_P (v_i = 0 off P). Its solution, refined from the answer with residuals in
extended precision (np.longdouble, "mixed precision" refinement, Higham 2002 Sec. 12.1), is the
*polished* answer (for a method that ended on a basis; another answer is judged as it is).
The bound, at the point y returned (the polished one, its v_P clipped at 0, or the answer as
given, then + its largest v off P / |x|_inf), is LAPACK's (`forward_bound`)

    ferr = || |K_PP^-1| (|r| + gamma (|K_PP| |y| + |k_P|)) ||_inf / ||y||_inf + eps,

r the (extended) residual, gamma = (m + 1) eps_ld: how far y may be from the exact solution of
the pattern's system (y - y* = K_PP^-1 r exactly). |K_PP^-1| is formed column by column from an
LU, never estimated (Hager's estimator, which LAPACK's xGERFS uses, is a lower bound of the norm:
0.46x, and 2e-16x on a rank-deficient pattern, on cases tests/lcp/test_forward_bound.py and
docs/performance.md record); one C function computes it for the C acceptance and for this code,
so lcp.solve and verify.certify report the same number for the same answer and pattern. That
function first bounds |K_PP^-1| g from above in O(m^2) by the LU's comparison matrices,
C(U)^-1 C(L)^-1 P g, and reports that larger bound instead when it is at most 1e-13
(_bound_core.h's CHEAP_FERR; no verdict at FERR_TOL or at bench's accuracies depends on it;
tests/lcp/test_comparison_bound.py); without the C extension |K_PP^-1| is always formed. A
singular K_PP (a continuum of solutions) uses its pseudo-inverse at the numerical rank (y's
distance to the refined point added), and an inconsistent one has ferr = inf. Consistency is
decided exactly (ranks in rationals, up to 200 unknowns; beyond, at the least-norm point),
never only at the answer's own size: a z inflated along a null direction of K_PP keeps its
residual while the rows' terms grow, which had made an inconsistent pattern look consistent
(verify.certify accepted z = 1e13 d on an infeasible LCP with M d = 0;
tests/lcp/test_inflated_null_direction.py).

**Accepted** iff berr <= TOL (lcp.residual.TOL = 1e-8) and ferr <= FERR_TOL. lcp.solve (and its
fast paths, solve_many, the friction and unreduced-MLCP branches) and verify.certify use
`assess`: the same checks and the same polishing on every route.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import rigidlcp.lcp._lemke_kernel as _kernel

from .residual import TOL, lcp_measure

try:
    from . import _accuracy_c
except ImportError:  # not built (no C compiler at install): the numpy code runs
    _accuracy_c = None

_EPS = float(np.finfo(float).eps)
_EPS_LD = float(np.finfo(np.longdouble).eps)
#: Largest forward error bound (relative, inf-norm) of an accepted answer.
FERR_TOL = 1e-6
#: Refinement steps at most (each one LU solve with an extended-precision residual).
STEPS = 5
#: Up to this size the bound runs in C (lcp/acceptance/_bound_core.h: forward_bound).
_EXPLICIT = 400


@dataclass
class Accuracy:
    """The quality of an answer x = [u; v] on the problem passed."""

    berr: float  # componentwise backward error (module doc)
    ferr: float  # forward error bound of the pattern's system, relative
    pattern: np.ndarray  # indices of the basic v's (P)
    refined: bool = False  # the answer returned is the polished one
    u: np.ndarray | None = None  # the (possibly polished) u
    v: np.ndarray | None = None  # the (possibly polished) v

    @property
    def accepted(self) -> bool:
        return bool(self.berr <= TOL and self.ferr <= FERR_TOL)

    def as_info(self) -> dict:
        return {"backward_error": self.berr, "forward_error": self.ferr,
                "polished": self.refined}


def backward_error(K: np.ndarray, k: np.ndarray, x: np.ndarray, nu: int) -> float:
    """berr of the module doc for x = [u; v] (nu the number of free unknowns u)."""
    if x.size == 0:
        return 0.0
    with np.errstate(all="ignore"):
        res = K @ x + k
        s = np.maximum(np.abs(K) @ np.abs(x) + np.abs(k), data_scale(K, k))
        ratio = np.where(s > 0, np.abs(res) / np.where(s > 0, s, 1.0),
                         np.where(res == 0, 0.0, np.inf))
        out = float(np.max(ratio[:nu], initial=0.0))
        v, w, sv = x[nu:], res[nu:], s[nu:]
        if v.size:
            B, b = K[nu:, nu:], k[nu:]
            bmax = float(np.max(np.abs(B))) if B.size else 0.0
            vs = max(float(np.max(np.abs(v))),
                     float(np.max(np.abs(b))) / bmax if bmax > 0 else 0.0)
            vs = vs if vs > 0 else 1.0
            wr = np.where(sv > 0, w / np.where(sv > 0, sv, 1.0),
                          np.where(w == 0, 0.0, np.sign(w) * np.inf))
            out = max(out, float(np.max(np.abs(np.minimum(v / vs, wr)))))
    return out if np.isfinite(out) else np.inf


def data_scale(K: np.ndarray, k: np.ndarray) -> float:
    """|k|_inf + ||K||_inf x_d with x_d = |k|_inf / |K|_max: the size of K x + k at the data's
    own scale of x (not the answer's), the floor of every row's scale in `backward_error`."""
    kmax = float(abs(k).max()) if k.size else 0.0
    kabs = abs(K)
    mmax = float(kabs.max()) if K.size else 0.0
    if not mmax > 0:
        return kmax
    return kmax + float(kabs.sum(axis=1).max()) * (kmax / mmax)


def pattern_of(K: np.ndarray, k: np.ndarray, x: np.ndarray, nu: int) -> np.ndarray:
    """P = {i : v_i / v_s > w_i / s_i, v_i > 0}: the v's that the answer treats as basic."""
    v = x[nu:]
    with np.errstate(all="ignore"):
        w = K[nu:] @ x + k[nu:]
        s = np.abs(K[nu:]) @ np.abs(x) + np.abs(k[nu:])
        vs = max(float(np.max(np.abs(v), initial=0.0)), 1e-300)
        return np.flatnonzero((v > 0) & (v * np.maximum(s, 1e-300) > w * vs))


def _residual_ld(Kp: np.ndarray, kp: np.ndarray, y: np.ndarray) -> np.ndarray:
    """K_PP y + k_P with products and sums in extended precision, rounded to double."""
    ld = np.longdouble
    return (Kp.astype(ld) @ y.astype(ld) + kp.astype(ld)).astype(float)


def forward_bound(Kp: np.ndarray, kp: np.ndarray, y: np.ndarray) -> float | None:
    """LAPACK's forward error bound at y of K_PP y = -k_P (module doc), with |K_PP^-1| formed
    from an LU (not estimated: Hager's estimator is a lower bound of the norm, 20 % below on
    solved problems, issue 23), or the LU's comparison-matrix bound where that is at most 1e-13
    (C only: module doc). None when K_PP is singular to working precision (Skeel's
    || |K^-1| |K| 1 ||_inf beyond 1 / (m eps)). In C when the extension is built (the same
    function the C acceptance calls: lcp.solve and verify.certify compute one number), else
    numpy with the same formula."""
    m = kp.size
    if m == 0:
        return 0.0
    if _accuracy_c is not None and m <= _EXPLICIT:
        code, ferr = _accuracy_c.bound(np.ascontiguousarray(Kp, dtype=float),
                                       np.ascontiguousarray(kp, dtype=float),
                                       np.ascontiguousarray(y, dtype=float))
        return None if code else ferr
    absK = np.abs(Kp)
    with np.errstate(all="ignore"):
        inv = _inverse(Kp, absK, m)
        if inv is None:
            return None
        r = _residual_ld(Kp, kp, y)
        g = np.abs(r) + (m + 1) * _EPS_LD * (absK @ np.abs(y) + np.abs(kp))
        ferr = float(np.max(np.abs(inv) @ g)) / max(float(np.max(np.abs(y))), 1e-300) + _EPS
    return ferr if np.isfinite(ferr) else np.inf


def _inverse(Kp: np.ndarray, absK: np.ndarray, m: int) -> np.ndarray | None:
    """K^-1 (formed: |K^-1| g is computed, not estimated), or None when K is singular to
    working precision (|K^-1| |K| beyond 1 / (m eps), or not finite)."""
    try:
        inv = np.linalg.inv(Kp)
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(inv)) or (
            float(np.max(np.abs(inv) @ absK.sum(axis=1))) * m * _EPS > 1.0):
        return None
    return inv


def refine(Kp: np.ndarray, kp: np.ndarray, y0: np.ndarray) -> tuple[np.ndarray, float]:
    """Solve K_PP y = -k_P from the start y0 by refinement with extended-precision residuals;
    return (y, ferr) with LAPACK's bound (module doc). ferr = inf when the system is singular
    and inconsistent, or the refinement diverges."""
    m = kp.size
    if m == 0:
        return y0, 0.0
    y = np.array(y0, dtype=float)
    absK = np.abs(Kp)
    with np.errstate(all="ignore"):
        inv = _inverse(Kp, absK, m)
        singular = inv is None
        if singular:  # singular to working precision: pseudo-inverse at the numerical rank
            U, sv, Vt = np.linalg.svd(Kp)
            keep = sv > max(Kp.shape) * _EPS * (sv[0] if sv.size else 0.0)
            inv = (Vt[keep].T / sv[keep]) @ U[:, keep].T

        def solve(rhs):
            return inv @ rhs
        if not np.all(np.isfinite(y)):
            y = -solve(kp)
        prev = np.inf
        for _ in range(STEPS):
            r = _residual_ld(Kp, kp, y)
            d = solve(r)
            size = float(np.max(np.abs(d)))
            if not np.isfinite(size) or size >= prev:
                break
            y = y - d
            prev = size
            if size <= _EPS * float(np.max(np.abs(y))):
                break
        fb = None if singular else forward_bound(Kp, kp, y)
        if fb is not None:
            return y, fb
        r = _residual_ld(Kp, kp, y)
        g = np.abs(r) + (m + 1) * _EPS_LD * (absK @ np.abs(y) + np.abs(kp))
        if singular:  # consistent to rounding? else no exact point of this pattern
            scale = np.maximum(absK @ np.abs(y) + np.abs(kp), data_scale(Kp, kp))
            if np.any(np.abs(r) > 1e3 * m * _EPS * np.maximum(scale, 1e-300)):
                return y, np.inf
            # ... and not only at y, whose size the answer can inflate: with K_PP d = 0,
            # y + t d keeps y's residual while |K| |y + t d| grows with t, so an inconsistent
            # system looked consistent at a large enough y. Decided exactly where small
            # (rank of K_PP against rank of [K_PP, k_P] in rationals: a K_PP singular only to
            # working precision, with a huge exact solution, stays consistent), else at the
            # least-norm point, whose size the answer cannot change.
            consistent = _exactly_consistent(Kp, kp)
            if consistent is None:
                y_mn = -solve(kp)
                r_mn = _residual_ld(Kp, kp, y_mn)
                scale_mn = np.maximum(absK @ np.abs(y_mn) + np.abs(kp), data_scale(Kp, kp))
                consistent = not np.any(
                    np.abs(r_mn) > 1e3 * m * _EPS * np.maximum(scale_mn, 1e-300))
            if not consistent:
                return y, np.inf
        ynorm = max(float(np.max(np.abs(y))), 1e-300)
        ferr = float(np.max(np.abs(inv) @ g)) / ynorm + _EPS
    return y, (ferr if np.isfinite(ferr) else np.inf)


#: Largest pattern decided exactly by `_exactly_consistent` (rational row reduction).
EXACT_CONSISTENCY_MAX_M = 200


def _exactly_consistent(Kp: np.ndarray, kp: np.ndarray) -> bool | None:
    """Whether K_PP y = -k_P has an exact solution, each double read as a rational: rank of
    K_PP equal to the rank of [K_PP, k_P] (python-flint's exact row reduction). None beyond
    EXACT_CONSISTENCY_MAX_M unknowns or on non-finite data."""
    m = kp.size
    if m > EXACT_CONSISTENCY_MAX_M or not (np.all(np.isfinite(Kp)) and np.all(np.isfinite(kp))):
        return None
    from flint import fmpq_mat

    from .farkas import _q  # a double as the exact rational it is

    A = fmpq_mat(m, m, [_q(v) for v in Kp.ravel()])
    Ak = fmpq_mat(m, m + 1, [_q(v) for row in np.c_[Kp, kp] for v in row])
    return A.rref()[1] == Ak.rref()[1]


def assess(K: np.ndarray, k: np.ndarray, x: np.ndarray, nu: int = 0,
           basis: np.ndarray | None = None, polish: bool | None = None) -> Accuracy:
    """berr and ferr of x = [u; v] on K x + k (module doc), after polishing x on its pattern
    when `polish` (default: when the method gave its final basis -- an answer without one is
    judged as it is, its bound then includes its distance to the pattern's exact point): the
    polished point is kept when its backward error is not larger or at rounding level (8 n eps;
    Accuracy.refined, .u, .v)."""
    polish = basis is not None if polish is None else polish
    x = np.asarray(x, dtype=float)
    berr = backward_error(K, k, x, nu) if np.all(np.isfinite(x)) else np.inf
    if basis is not None:
        P = np.sort(np.asarray(basis, dtype=np.intp).reshape(-1))
        if P.size and (P.min() < 0 or P.max() >= x.size - nu
                       or np.unique(P).size < P.size):
            P = pattern_of(K, k, x, nu)
    else:
        P = pattern_of(K, k, x, nu) if np.all(np.isfinite(x)) else np.zeros(0, np.intp)
    idx = np.concatenate([np.arange(nu), nu + P]).astype(np.intp)
    Kp, kp = K[np.ix_(idx, idx)], k[idx]
    y0 = np.where(np.isfinite(x[idx]), x[idx], 0.0)
    y, ferr = refine(Kp, kp, y0)
    refined = False
    if polish and np.all(np.isfinite(y)):
        xp = np.zeros_like(x)
        xp[idx] = y
        xp[nu:] = np.maximum(xp[nu:], 0.0)
        bp = backward_error(K, k, xp, nu)
        if bp <= max(berr, 8 * x.size * _EPS):  # not larger, or at rounding level
            x, berr, refined = xp, bp, True
            if np.any(xp[idx] != y):  # a v_i < 0 clipped: the bound of the point returned
                at_x = forward_bound(Kp, kp, xp[idx])
                with np.errstate(all="ignore"):
                    ferr = at_x if at_x is not None else ferr + float(
                        np.max(np.abs(xp[idx] - y))) / max(float(np.max(np.abs(xp))), 1e-300)
    if not refined:  # the answer as given: the bound at x_P itself (else, on a singular
        # system, |x - y| + the bound of y: triangle inequality), + its v's off the pattern
        with np.errstate(all="ignore"):
            xs = max(float(np.max(np.abs(x), initial=0.0)), 1e-300)
            off = np.setdiff1d(np.arange(x.size - nu), P)
            at_x = (forward_bound(Kp, kp, x[idx]) if np.all(np.isfinite(x)) and np.isfinite(ferr)
                    else None)
            gap = float(np.max(np.abs(x[nu:][off]), initial=0.0))
            if at_x is None:
                gap = max(gap, float(np.max(np.abs(x[idx] - y), initial=0.0)))
                at_x = ferr
            ferr = at_x + gap / xs
        ferr = ferr if np.isfinite(ferr) else np.inf
    return Accuracy(berr=berr, ferr=ferr, pattern=P, refined=refined, u=x[:nu], v=x[nu:])


def assess_lcp(M: np.ndarray, q: np.ndarray, z: np.ndarray, basis=None,
               polish: bool | None = None) -> Accuracy:
    """`assess` for an LCP (no u). With a basis, in C when the extension is built and the
    kernels are on (lcp/acceptance/_accuracy_c.c: the same steps; RIGIDLCP_NO_KERNEL=1 runs
    numpy)."""
    if basis is not None and polish is not False and _accuracy_c is not None and _kernel.enabled():
        a = basis if (type(basis) is np.ndarray and basis.dtype == _I64
                      and basis.flags.c_contiguous) else np.ascontiguousarray(
            basis, dtype=np.int64).reshape(-1)  # C: 1 (numpy runs) on a repeated index
        out = np.empty(q.size)
        code, berr, ferr, refined = _accuracy_c.assess(M, q, z, a, out)
        if code == 0:  # Accuracy(berr=..., ...) without its generated __init__ (hot path)
            acc = _new(Accuracy)
            acc.__dict__ = {"berr": berr, "ferr": ferr, "pattern": a,
                            "refined": refined == 1, "u": _NO_U, "v": out if refined else z}
            return acc
    return assess(M, q, z, 0, basis, polish)


_new = object.__new__


_NO_U = np.zeros(0)
_I64 = np.dtype(np.int64)


def assess_mlcp(problem, v: np.ndarray, u: np.ndarray, basis=None,
                polish: bool = True) -> Accuracy:
    """`assess` for an lcp.MLCP on its full system [A C; D B] (no Schur reduction: the bound
    covers u too)."""
    K = np.block([[problem.A, problem.C], [problem.D, problem.B]])
    k = np.concatenate([problem.a, problem.b])
    return assess(K, k, np.concatenate([u, v]), problem.nu, basis, polish)


def judge_lcp(M: np.ndarray, q: np.ndarray, z: np.ndarray, basis=None
              ) -> tuple[bool, np.ndarray, np.ndarray, float, float, Accuracy]:
    """The verdict on an LCP answer, as lcp.trust gives it (the fast paths and solve_many call
    this same function): (accepted, z (polished when that helped), w, max|min(z, w)|, scaled
    residual of lcp.residual, Accuracy)."""
    acc = assess_lcp(M, q, z, basis)
    if acc.refined:
        z = acc.v
    w, raw, scaled, _, _ = lcp_measure(M, q, z)
    return bool(scaled <= TOL and acc.accepted), z, w, raw, scaled, acc


def assess_problem(problem, z: np.ndarray, u: np.ndarray | None = None, basis=None,
                   polish: bool = False) -> Accuracy:
    """`assess` of an answer to an lcp.LCP or lcp.MLCP as given (no polishing by default):
    verify.certify reports these bounds and accepts only with them."""
    z = np.asarray(z, dtype=float).reshape(-1)
    if hasattr(problem, "M"):
        return assess_lcp(problem.M, problem.q, z, basis, polish)
    if u is None:
        u = problem.recover_u(z)
    return assess_mlcp(problem, z, np.asarray(u, dtype=float).reshape(-1), basis, polish)
