"""The paper's contact-state iteration as a principal pivoting method (method ``pivoting``).

Radjai, Brendel & Roux (1996), Sec. II C: for a guessed set of contact states, solve the linear
equations of those states (Eq. 2.15), check the inequalities (2.5) and (2.7), and "the choice of
the alternative set of states is guided naturally by the states of those contacts where the
inequalities are not satisfied. This process is iterated until the solution is found."

In LCP terms (w = M z + q, 0 <= z perp w >= 0) a set of states is an index set alpha (z_i is
unknown and w_i = 0 for i in alpha; z_i = 0 for i not in alpha): a complementary basis. The
states are solved from M_aa z_a = -q_a, and the inequalities that fail are

    H = {i in alpha : z_i < 0}  union  {i not in alpha : w_i < 0}.

Flipping all of H at once is *block principal pivoting* (Kostreva 1978; Judice & Pires,
Comput. Oper. Res. 21, 587, 1994). It may cycle, so the scheme of Judice & Pires is used: keep
the least |H| seen so far; a step that does not lower it is allowed ``block_tries`` times, after
which single principal pivots are made on the least index of H (Murty's least-index rule:
K. G. Murty, Opsearch 11, 123, 1974; finite on P-matrices) until |H| drops below its record,
when block steps resume. The record strictly decreases between block phases, so the method
is finite on P-matrices.

Single pivots use the principal pivot transform ("tableau") of M for the current basis,
y = Mbar x + qbar, with y the basic and x the nonbasic member of each pair. When the diagonal
pivot Mbar_rr vanishes (this happens for positive semidefinite and other sufficient matrices,
not for P-matrices), the least-index *criss-cross* rule is used instead (den Hertog, Roos &
Terlaky, Linear Algebra Appl. 187, 1, 1993): take the least s with Mbar_rs > 0 and make an
exchange pivot on the 2 x 2 block {r, s}; if there is none, row r reads
y_r = qbar_r + sum_j Mbar_rj x_j with qbar_r < 0 and every Mbar_rj <= 0, so y_r < 0 for every
x >= 0: the LCP has no solution, and that row is returned as the certificate. The criss-cross
rule is finite on sufficient matrices (including every positive semidefinite M), so the
method solves those too.

Every basis visited has a nonsingular M_aa (checked with LAPACK's condition estimate): a block
step onto a singular basis is refused and replaced by a single pivot, and a singular warm start
falls back to the empty basis. When no criss-cross pivot gives a nonsingular basis (M is not
sufficient, or is singular to rounding) a diagonal pivot on another failing index is tried
(counted in ``info["fallback_pivots"]``); this voids the finiteness argument, so the iteration
limit and an exact cycle test (a repeated state proves an endless loop) report the failure.
Sign tests are relative: z_i < -tol max|z| and w_i < -tol (|q_i| + sum_j |M_ij z_j|), the
latter floored at 1e-4 of its largest value over i (rounding level of the whole problem).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg.lapack import dgecon, dgetrf, dgetrs

from ..problems.problem import InvalidProblem
from ..problems.solution import Solution
from ..registry import register

#: A basis whose estimated reciprocal condition number is below this is treated as singular.
RCOND = 1e-13
#: |Mbar_rr| below PIVOT_TOL times the size of its row counts as a zero pivot.
PIVOT_TOL = 1e-10
#: Sign tests use at least FLOOR times the largest row scale of w (rounding level).
FLOOR = 1e-4


class _Basis:
    """The complementary basis alpha with an LU factorization of M_aa."""

    def __init__(self, M: np.ndarray, alpha: np.ndarray):
        self.alpha = alpha
        self.a = np.flatnonzero(alpha)
        self.b = np.flatnonzero(~alpha)
        self.M = M
        self.lu = None
        self.singular = False
        if self.a.size:
            Maa = M[np.ix_(self.a, self.a)]
            # LAPACK's LU as scipy.linalg.lu_factor(Maa, check_finite=False) calls it (on a
            # copy: Maa is kept), without the wrapper's cost (~20 us a call) and its warning
            # for a zero pivot (the singular test below decides)
            lu, piv, _ = dgetrf(Maa, overwrite_a=False)
            anorm = float(np.max(np.sum(np.abs(Maa), axis=0)))
            rcond, _ = dgecon(lu, anorm, norm="1")
            self.singular = (not np.all(np.diagonal(lu) != 0)) or not (rcond >= RCOND)
            self.lu = (lu, piv)
            self.Maa = Maa

    def solve(self, rhs: np.ndarray, trans: int = 0) -> np.ndarray:
        # as scipy.linalg.lu_solve(self.lu, rhs, trans=trans, check_finite=False) calls it
        return dgetrs(*self.lu, rhs, trans=trans, overwrite_b=False)[0]

    def zw(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """z and w = M z + q of the basis (one step of iterative refinement)."""
        n = q.size
        z = np.zeros(n)
        if self.a.size:
            qa = q[self.a]
            za = -self.solve(qa)
            za -= self.solve(self.Maa @ za + qa)
            z[self.a] = za
        return z, self.M @ z + q

    def row(self, r: int) -> np.ndarray:
        """Row r of the principal pivot transform Mbar (indexed by the pair number).

        y_r = qbar_r + sum_j Mbar_rj x_j, with y_r = z_r if r is in alpha, else w_r.
        For r in alpha: g = e_r' M_aa^{-1}; otherwise g = M_ra M_aa^{-1}. Then
        Mbar_{r,a} = g and Mbar_{r,b} = [r not in alpha] M_{r,b} - g M_{a,b}.
        """
        M, a, b = self.M, self.a, self.b
        out = np.zeros(M.shape[0])
        if a.size:
            if self.alpha[r]:
                e = np.zeros(a.size)
                e[np.searchsorted(a, r)] = 1.0
                g = self.solve(e, trans=1)
            else:
                g = self.solve(M[r, a], trans=1)
            out[a] = g
            out[b] = -g @ M[np.ix_(a, b)]
        if not self.alpha[r]:
            out[b] += M[r, b]
        return out


def _usable(row: np.ndarray, i: int) -> bool:
    """Whether row[i] is a nonzero pivot relative to its row."""
    return abs(row[i]) > PIVOT_TOL * (float(np.max(np.abs(row))) or 1.0)


def _pivot_candidates(basis: _Basis, H: np.ndarray, row: np.ndarray):
    """Single pivots to try, best first, as (indices to flip, kind).

    1. Murty / criss-cross on r = min H: the diagonal pivot if Mbar_rr != 0, else exchange
       pivots {r, s} for s with Mbar_rs > 0 and Mbar_sr != 0, least s first;
    2. fall-backs, tried only when none of those gives a nonsingular basis (M not sufficient,
       or singular to rounding): diagonal pivots on the other failing indices, least first.
       They void the finiteness guarantee; max_iter and the cycle test still hold.
    """
    r = int(H[0])
    if _usable(row, r):
        yield [r], "single_pivots"
    else:
        scale = float(np.max(np.abs(row))) or 1.0
        for s in np.flatnonzero(row > PIVOT_TOL * scale):
            if _usable(basis.row(int(s)), r):
                yield [r, int(s)], "exchange_pivots"
    for c in H[1:]:
        if _usable(basis.row(int(c)), int(c)):
            yield [int(c)], "fallback_pivots"


def _initial_active(active, q: np.ndarray) -> np.ndarray:
    n = q.size
    if active is None:
        return q < 0
    arr = np.asarray(active)
    if arr.dtype == bool:
        if arr.shape != (n,):
            raise InvalidProblem(f"active as a mask must have length {n}, got shape {arr.shape}")
        return arr.copy()
    if arr.size == 0:
        return np.zeros(n, dtype=bool)
    if arr.ndim != 1 or not np.issubdtype(arr.dtype, np.integer):
        raise InvalidProblem(
            f"active must be a boolean mask or a list of indices, got {arr.dtype} {arr.shape}"
        )
    if arr.min() < 0 or arr.max() >= n:
        raise InvalidProblem(f"active indices must lie in [0, {n}), got {arr.tolist()}")
    mask = np.zeros(n, dtype=bool)
    mask[arr] = True
    return mask


def _infeasible(z: np.ndarray, w: np.ndarray, alpha: np.ndarray, M: np.ndarray,
                q: np.ndarray, tol: float) -> np.ndarray:
    """Indices whose inequality fails: z_i < 0 in alpha, w_i < 0 outside (relative tol)."""
    mscale = float(np.max(np.abs(M))) or 1.0
    zscale = max(float(np.max(np.abs(z))), float(np.max(np.abs(q))) / mscale)
    wscale = np.abs(q) + np.abs(M) @ np.abs(z)
    # Row scale (invariant under scaling a row of M and q), with a floor at rounding level of
    # the whole problem, so that a row whose every entry is ~1e-190 does not decide anything.
    wscale = np.maximum(wscale, FLOOR * float(np.max(wscale)))
    bad = np.where(alpha, z < -tol * zscale, w < -tol * wscale)
    return np.flatnonzero(bad)


@register(
    "pivoting", accepts="any", equilibrate=True,
    description="The paper's contact-state iteration: block principal pivoting (Judice-Pires) "
    "with Murty's least-index / criss-cross single pivots; warm start with active=.",
)
def solve_pivoting(
    M: np.ndarray, q: np.ndarray, *, active=None, max_iter: int | None = None,
    tol: float = 1e-10, block_tries: int = 3,
) -> Solution:
    """Solve an LCP by principal pivoting on contact states (paper Sec. II C; see module doc).

    active: the starting index set (z_i basic), as indices or a boolean mask; e.g. the
        previous event's transmitting contacts. Default {i : q_i < 0}.
    max_iter: limit on basis changes (default max(1000, 20 n)).
    tol: relative tolerance of the sign tests (z_i >= -tol |z|, w_i >= -tol |terms of w_i|).
    block_tries: block steps allowed without lowering the number of infeasibilities.

    Status "solved"; "infeasible" with a tableau row proving it (``info["certificate"]``);
    "max_iter"; "failed" when a needed pivot vanishes (M is not sufficient), the basis
    became singular, or a state (basis, record, tries) recurs, which proves an endless cycle
    (``info["cycle_length"]``). iterations counts basis changes; ``info`` has the block
    steps, single and exchange pivots, and the total number of flipped indices.
    """
    n = q.size
    if max_iter is None:
        max_iter = max(1000, 20 * n)
    if not (isinstance(max_iter, (int, np.integer)) and max_iter >= 0):
        raise InvalidProblem(f"max_iter must be a non-negative integer, got {max_iter!r}")
    if not (isinstance(tol, (int, float)) and math.isfinite(tol) and 0 < tol < 1):
        raise InvalidProblem(f"tol must be a number in (0, 1), got {tol!r}")
    if not (isinstance(block_tries, (int, np.integer)) and block_tries >= 0):
        raise InvalidProblem(f"block_tries must be a non-negative integer, got {block_tries!r}")
    alpha = _initial_active(active, q)
    info: dict = {"block_steps": 0, "single_pivots": 0, "exchange_pivots": 0, "flips": 0}
    basis = _Basis(M, alpha)
    if basis.singular:
        info["warm_start_rejected"] = np.flatnonzero(alpha).tolist()
        basis = _Basis(M, np.zeros(n, dtype=bool))
    record, tries, it = n + 1, block_tries, 0
    seen: dict[tuple[bytes, int, int], int] = {}  # the state that fixes every later step

    def result(status: str, z: np.ndarray, message: str = "") -> Solution:
        return Solution(
            z=np.maximum(z, 0.0) if status == "solved" else z, w=M @ z + q, status=status,
            method="pivoting", iterations=it, basis=basis.a.copy(), message=message, info=info,
        )

    while True:
        z, w = basis.zw(q)
        H = _infeasible(z, w, basis.alpha, M, q, tol)
        if H.size == 0:
            return result("solved", z)
        if it >= max_iter:
            info["infeasible_indices"] = H.tolist()
            return result("max_iter", z, f"no solution after {it} basis changes "
                          f"({H.size} inequalities still fail)")
        state = (basis.alpha.tobytes(), record, tries)
        if state in seen:  # deterministic: the same state again means an endless cycle
            info["cycle_length"] = it - seen[state]
            info["infeasible_indices"] = H.tolist()
            return result("failed", z, f"the pivoting cycles (period {it - seen[state]}): M is "
                          "neither a P-matrix nor sufficient, or rounding misled a sign test")
        seen[state] = it
        it += 1
        block = False
        if H.size < record:
            record, tries, block = H.size, block_tries, True
        elif tries > 0:
            tries, block = tries - 1, True
        if block:
            new = basis.alpha.copy()
            new[H] = ~new[H]
            trial = _Basis(M, new)
            if not trial.singular:
                basis = trial
                info["block_steps"] += 1
                info["flips"] += int(H.size)
                continue
            tries = 0  # a singular block basis: fall back to a single pivot
        r = int(H[0])  # Murty's least-index rule
        row = basis.row(r)
        scale = float(np.max(np.abs(row))) or 1.0
        if abs(row[r]) <= PIVOT_TOL * scale and not np.any(row > PIVOT_TOL * scale):
            info["certificate"] = {
                "row": r, "active": basis.a.tolist(),
                "qbar_r": float(z[r] if basis.alpha[r] else w[r]),
                "max_coefficient": float(row.max()),
            }
            return result(
                "infeasible", z,
                f"row {r} of the pivoted system reads y_{r} = qbar_{r} + sum Mbar_rj x_j "
                f"with qbar_{r} < 0 and no positive coefficient: no solution exists",
            )
        for flip, kind in _pivot_candidates(basis, H, row):
            new = basis.alpha.copy()
            new[flip] = ~new[flip]
            trial = _Basis(M, new)
            if not trial.singular:
                info[kind] = info.get(kind, 0) + 1
                break
        else:
            return result("failed", z, f"no pivot on the failing indices {H.tolist()} gives a "
                          "nonsingular basis: M is not sufficient, or it is numerically singular")
        basis = trial
        info["flips"] += len(flip)
