"""Lemke's complementary pivot algorithm with the lexicographic ratio test (method ``lemke``).

The LCP  w = M z + q,  0 <= z perp w >= 0  is embedded in the augmented system

    w = M z + d z0 + q,        z, w, z0 >= 0,   z_i w_i = 0,                         (1)

with a covering vector d > 0 (ones by default). Lemke's method (Lemke 1965; Cottle, Pang &
Stone, *The Linear Complementarity Problem*, 1992, Algorithm 4.4.5) starts from the basis
{w_1..w_n}, lets z0 enter until every w_i >= 0 (the row of min q_i / d_i leaves), and then
alternates: the complement of the variable that just left enters, the minimum ratio test picks
the row that leaves. It stops when z0 leaves (a solution) or when no row blocks the entering
variable (a secondary ray).

Implementation: a dense *dictionary* (compact tableau) x_B = beta + T x_N, stored as one
Fortran-ordered n x (n + 2) array whose columns are the n + 1 nonbasic variables and beta. A
pivot is one in-place rank-one update of that array, O(n^2) with no Python loop over rows,
each entry rounded twice (product, then sum; no fused multiply-add), in C (lcp/_lemke_c.c)
or by numpy, so that both give the same numbers on every CPU. The ratio test needs only the
entering column and beta; the lexicographic tie-break (Cottle-Pang-Stone Sec. 4.9) needs
the rows of B^-1 of the tied rows only, and those are read from the w columns of the
dictionary when (rarely) needed. Details and equations: docs/lemke.md.
"""

from __future__ import annotations

import numpy as np

import rigidlcp.lcp._lemke_kernel as _kernel

from ..acceptance.farkas import numerically_psd
from ..problems.problem import InvalidProblem, as_matrix, as_vector
from ..problems.solution import Solution
from ..registry import register
from .lemke_exact import (
    EXACT_MAX_N,
    EXACT_RAY_MAX_N,
    EXACT_TIES_MAX_N,
    ExactTies,
    ambiguous_tie,
    lemke_exact,
    with_exact_ties,
)
from .lemke_options import DEFAULT_TOL, _check_max_iter, _check_tol, _covering_vector

__all__ = ["lemke", "DEFAULT_TOL", "_check_max_iter", "_check_tol", "_covering_vector"]

_EPS = np.finfo(float).eps


@register(
    "lemke",
    accepts="any",
    equilibrate=True,
    description="Lemke's complementary pivot method (covering vector d, lexicographic ratio test)",
)
def lemke(
    M: np.ndarray,
    q: np.ndarray,
    *,
    d: np.ndarray | None = None,
    max_iter: int | None = None,
    tol: float | None = None,
) -> Solution:
    """Solve w = M z + q, 0 <= z perp w >= 0 by Lemke's method (Cottle-Pang-Stone Alg. 4.4.5).

    Parameters
    ----------
    M, q : the LCP (n x n, n).
    d : covering vector, all entries > 0 (default ones).
    max_iter : pivot limit (default 1000 + 100 n); status ``max_iter`` when reached.
    tol : zero tolerance on the data normalized to max|M| = max|q| = max(d) = 1 (default
        1e-10): pivot entries, ratio ties and lexicographic ties below it count as zero.

    Returns
    -------
    Solution with status ``solved`` (z, w, basis = indices of the basic z's, iterations =
    pivots including the first one, where z0 enters), ``ray`` (secondary ray; evidence in
    ``info``: "ray" = direction in (z, z0) space, "entering", "point", "z0"), ``infeasible``
    (a ray whose z-part is a verified Farkas certificate y >= 0, M^T y <= 0, q^T y < 0: always
    the case, by Lemke's theorem, when M is copositive-plus, tested as M + M^T PSD) or
    ``max_iter``.
    """
    plain, qmin = _kernel.plain_finite(M, q)  # valid as they are (e.g. from an LCP)?
    if not plain:
        M = as_matrix("M", M, (None, None))
        if M.shape[0] != M.shape[1]:
            raise InvalidProblem(f"M must be square, got shape {M.shape}")
        q = as_vector("q", q, M.shape[0])
        qmin = float(q.min())
    n = M.shape[0]
    d = _covering_vector(d, n)
    max_iter = _check_max_iter(max_iter, n)
    tol = _check_tol(tol)
    if qmin >= 0:
        return Solution(
            z=np.zeros(n), w=q.copy(), status="solved", method="lemke", iterations=0,
            basis=np.zeros(0, dtype=int), message="q >= 0: z = 0 solves the LCP",
        )
    if plain and _kernel.enabled():  # the whole run in C (same pivots, same z)
        fast = _kernel.solve_one(M, q, np.ascontiguousarray(d), tol, max_iter)
        if fast is not None:
            z, basis, pivots = fast
            return Solution(z=z, w=M @ z + q, status="solved", method="lemke",
                            iterations=pivots, basis=basis)
    sol = _Lemke(M, q, d, tol).run(max_iter)  # also reruns what the fast path did not solve
    # Near-ties that floats cannot separate (a repeated basis, a ray proving nothing): rerun
    # with every pivot and tie exact (lcp.lemke_exact: it cannot cycle), and say so.
    if (sol.info.get("cycling") and n <= EXACT_MAX_N) or (sol.status == "ray"
                                                          and n <= EXACT_RAY_MAX_N):
        exact = lemke_exact(M, q, d, max_iter)
        if exact.status == "solved" or sol.info.get("cycling"):
            exact.message = f"{sol.message}; rerun in exact rational arithmetic: " + (
                exact.message or exact.status)
            return exact
        if exact.status == "ray" and sol.status == "ray":  # rounding is not the cause
            sol.info["exact_rerun"] = "ray"
            sol.message += ("; the rerun in exact rational arithmetic ends on a secondary ray "
                            f"too (after {exact.iterations} pivots): the ray is Lemke's on "
                            "these data, not rounding")
    if sol.info.get("cycling") and n <= EXACT_TIES_MAX_N:  # floats, ambiguous ties exact
        sol = with_exact_ties(sol, lambda ties: _Lemke(M, q, d, tol, ties).run(max_iter),
                              M, q, d)
    retry = tol  # larger n: restart with ties decided more coarsely
    while sol.info.get("cycling") and retry < 1e-6:
        retry *= 100.0
        first = sol.message
        sol = _Lemke(M, q, d, retry).run(max_iter)
        sol.message = f"{first}; restarted with tol = {retry:g}: {sol.message}".rstrip(": ")
        sol.info["tol_used"] = retry
    return sol


class _Lemke:
    """One run of the method on normalized data.

    Variables are numbered w_i = i, z_i = n + i, z0 = 2n. The dictionary is
    x_B = beta + T x_N with T[:, :n+1] the nonbasic columns (slot s holds variable nonbasic[s])
    and T[:, n+1] = beta. Data are scaled so that max|M| = max|q| = max(d) = 1:
    M~ = M / mu, q~ = q / nu, d~ = d / delta, hence z~ = z mu / nu, z0~ = z0 delta / nu,
    w~ = w / nu, and every tolerance is absolute in these units.
    """

    def __init__(self, M: np.ndarray, q: np.ndarray, d: np.ndarray, tol: float,
                 exact: ExactTies | None = None):
        n = q.size
        self.n, self.M, self.q, self.d, self.tol = n, M, q, d, tol
        self.exact, self.entering = exact, 2 * n  # exact ties: the numpy loop decides them
        T = np.empty((n, n + 2), order="F")
        if _kernel.enabled():
            self.mu, self.nu, self.delta = _kernel.setup(T, M, q, d)
        else:
            self.mu = float(np.abs(M).max()) or 1.0
            self.nu = float(np.abs(q).max())
            self.delta = float(d.max())
            np.divide(M, self.mu, out=T[:, :n])
            np.divide(d, self.delta, out=T[:, n])
            np.divide(q, self.nu, out=T[:, n + 1])
        self.T = T
        self.trace: list[tuple[int, int]] | None = None  # (row, slot) of each pivot, if a list
        # Bookkeeping as Python lists (scalar access is several times faster than numpy's).
        self.basic = list(range(n))  # row -> variable
        self.nonbasic = list(range(n, 2 * n + 1))  # slot -> variable
        self.row_of = list(range(n)) + [-1] * (n + 1)  # variable -> row, or -1
        self.slot_of = [-1] * n + list(range(n + 1))  # variable -> slot, or -1
        self.basic_np, self.slot_np = np.array(self.basic), np.array(self.slot_of)  # mirrors

    # -- the pivot -------------------------------------------------------------------------
    def pivot(self, r: int, s: int) -> int:
        """Exchange basic row r with nonbasic slot s; return the variable that left.

        With p = T[r, s]: the new row r is -T[r, :] / p except 1/p in slot s, and every other
        row i gets T[i, c] + T[i, s] * newrow[c] (c != s) and T[i, s] / p in slot s: one
        rank-one update after zeroing row r and column s (with the column's entry at r = 1).
        """
        T = self.T
        if self.trace is not None:
            self.trace.append((r, s))
        colview = T[:, s]
        col = colview.copy()
        p = col[r]
        row = T[r, :] * (-1.0 / p)
        row[s] = 1.0 / p
        T[r, :] = 0.0
        colview.fill(0.0)
        col[r] = 1.0
        # T[:, c] += col row[c] where row[c] != 0 (as the C loop: a zero adds nothing), the
        # product and the sum rounded separately
        nz = np.flatnonzero(row)
        if nz.size == row.size:
            T += np.multiply.outer(col, row)
        else:
            T[:, nz] += np.multiply.outer(col, row[nz])
        entering = self.nonbasic[s]
        leaving = self.basic[r]
        self.basic[r] = entering
        self.nonbasic[s] = leaving
        self.row_of[entering], self.slot_of[entering] = r, -1
        self.row_of[leaving], self.slot_of[leaving] = -1, s
        self.basic_np[r], self.slot_np[entering], self.slot_np[leaving] = entering, -1, s
        return leaving

    # -- the ratio test ------------------------------------------------------------------
    def choose(self, rows: np.ndarray, alpha: np.ndarray, theta: np.ndarray, amax: float) -> int:
        """Minimum ratio row among `rows` (ratios theta, pivots alpha > 0, amax = max alpha),
        ties broken lexicographically.

        Rows whose ratio is within tol / amax of the minimum are tied (the step then leaves
        every basic variable >= -tol). Among tied rows, z0 leaves if it can (the run ends
        with a solution); otherwise the lexicographic minimum of B^-1[i, :] / alpha_i.
        """
        k = theta.argmin()
        tied = theta <= theta[k] + self.tol / amax
        if np.count_nonzero(tied) == 1:
            return int(rows[k])
        rows, alpha = rows[tied], alpha[tied]
        z0_row = self.row_of[2 * self.n]
        if z0_row >= 0 and np.any(rows == z0_row):
            return z0_row
        if self.exact is not None and ambiguous_tie(self, rows, alpha, theta[tied]):
            r = self.exact.choose(self.basic, self.entering, rows)
            if r is not None:
                return r
        return self.lexico_min(rows, alpha)

    def lexico_min(self, rows: np.ndarray, alpha: np.ndarray) -> int:
        """Row i in `rows` with the lexicographically smallest B^-1[i, :] / alpha_i.

        Column j of B^-1 is e_r when w_j is basic in row r, and -T[:, slot(w_j)] when w_j is
        nonbasic (T = -B^-1 N and w_j's column in [I, -M, -d] is e_j). B^-1 is nonsingular,
        so two rows are never equal in exact arithmetic; entries closer than tol (relative
        to the largest compared entry) are treated as equal, since their difference is
        rounding. If all columns are equal to that tolerance, the largest pivot is taken.

        The sweep over the columns j = 0, 1, ... keeps the rows whose entry is minimal. A
        column of a basic w_j has one nonzero, 1/alpha_r > 0 in w_j's row r, so it removes row
        r if r is still a candidate (and not the last one): those columns are handled in bulk
        between the columns of nonbasic w's, and only the latter where the tied rows differ
        are compared one by one.
        """
        n = self.n
        slot_w = self.slot_np[:n]
        wj = np.flatnonzero(slot_w >= 0)  # nonbasic w's, in index order
        V = -self.T[np.ix_(rows, slot_w[wj])] / alpha[:, None]
        bvars = self.basic_np[rows]
        pos = np.where(bvars < n, bvars, n)  # column of each row's unit entry (n: none)
        eps = self.tol * max(float(np.abs(V).max(initial=0.0)), float((1.0 / alpha).max()))
        events = np.flatnonzero(V.max(axis=0, initial=-np.inf) - V.min(axis=0, initial=np.inf)
                                > eps) if wj.size else np.zeros(0, dtype=int)
        cand = np.arange(rows.size)
        for k in [*events.tolist(), None]:
            j = n if k is None else int(wj[k])
            early = pos[cand] < j  # unit entries before column j: their rows go, in order
            if early.all():
                cand = cand[[int(np.argmax(pos[cand]))]]
            elif early.any():
                cand = cand[~early]
            if cand.size == 1 or k is None:
                break
            v = V[cand, k]
            cand = cand[v <= v.min() + eps]
            if cand.size == 1:
                break
        return int(rows[cand[np.argmax(alpha[cand])]])

    # -- the run --------------------------------------------------------------------------
    def run(self, max_iter: int) -> Solution:
        if _kernel.enabled() and self.exact is None:
            return _kernel.run(self, max_iter)  # the same loop in C
        n, tol, T, slot_of = self.n, self.tol, self.T, self.slot_of
        beta = T[:, n + 1]
        z0 = 2 * n
        amin_of, count = np.minimum.reduce, np.count_nonzero
        negative, maximum = np.negative, np.maximum
        # Step 0: z0 enters; every row is "blocking" with pivot d_i and ratio q_i / d_i.
        alpha = T[:, n].copy()
        r = self.choose(np.arange(n), alpha, beta / alpha, float(alpha.max()))
        s = n
        pivots = 0
        pivot = self.pivot
        # Zobrist hash of the basis: exact lexicographic Lemke never revisits a basis, so a
        # repeat proves that rounding defeated the tie-breaking (numerical cycling).
        keys = np.random.default_rng(0).integers(1, 2**63 - 1, size=2 * n + 1, dtype=np.int64)
        keys = [int(k) for k in keys]
        h, seen, ent = 0, set(), z0
        while True:
            leaving = pivot(r, s)
            pivots += 1
            if leaving == z0:
                return self.solution(pivots)
            h ^= keys[leaving] ^ keys[ent]
            if h in seen:
                sol = self.stopped(pivots)
                sol.message = f"numerical cycling: a basis repeated after {pivots} pivots"
                sol.info["cycling"] = True
                return sol
            seen.add(h)
            if pivots >= max_iter:
                return self.stopped(pivots)
            entering = leaving + n if leaving < n else leaving - n
            ent = self.entering = entering
            s = slot_of[entering]
            a = T[:, s]
            amax = -float(amin_of(a))  # the largest pivot candidate alpha_i = -a_i
            thr = tol * amax if amax > 1.0 else tol
            if amax <= thr:
                return self.ray(pivots, s, entering)
            rows = (a < -thr).nonzero()[0]
            if rows.size == 1:
                r = int(rows[0])
                continue
            alpha = a[rows]
            negative(alpha, out=alpha)
            theta = beta[rows]
            maximum(theta, 0.0, out=theta)
            theta /= alpha
            k = theta.argmin()
            tied = theta <= theta[k] + tol / amax
            if count(tied) == 1:
                r = int(rows[k])
            else:
                r = self.choose(rows, alpha, theta, amax)

    # -- outcomes -------------------------------------------------------------------------
    def point(self) -> tuple[np.ndarray, np.ndarray, float]:
        """Current (z, w, z0) in the original units."""
        n = self.n
        x = np.zeros(2 * n + 1)  # every variable: beta in its row if basic, else 0
        x[self.basic_np] = self.T[:, n + 1]
        z0 = float(x[2 * n]) * self.nu / self.delta
        return x[n:2 * n] * (self.nu / self.mu), x[:n] * self.nu, z0

    def basis(self) -> np.ndarray:
        b = self.basic_np
        return np.sort(b[(b >= self.n) & (b < 2 * self.n)] - self.n)

    def solution(self, pivots: int, message: str = "") -> Solution:
        z, w, _ = self.point()
        return Solution(z=z, w=w, status="solved", method="lemke", iterations=pivots,
                        basis=self.basis(), message=message)

    def stopped(self, pivots: int) -> Solution:
        z, w, z0 = self.point()
        return Solution(
            z=z, w=w, status="max_iter", method="lemke", iterations=pivots, basis=self.basis(),
            message=f"pivot limit {pivots} reached with z0 = {z0:.3g} (not a solution)",
            info={"z0": z0},
        )

    def ray(self, pivots: int, s: int, entering: int) -> Solution:
        """Secondary ray: x_B = beta + a t, x_entering = t, t -> infinity (Alg. 4.4.5, step 3)."""
        n, basic, a = self.n, self.basic_np, self.T[:, s]
        z, w, z0 = self.point()
        if z0 <= self.tol * self.nu / self.delta:
            # z0 is basic at 0 (a degenerate step): the current point is complementary.
            return self.solution(pivots, "z0 = 0 on a degenerate basis")
        dz = np.zeros(n)
        zr = np.flatnonzero((basic >= n) & (basic < 2 * n))
        dz[basic[zr] - n] = a[zr]
        if entering >= n:
            dz[entering - n] = 1.0
        dz *= self.nu / self.mu
        dz0 = float(a[self.row_of[2 * n]]) * self.nu / self.delta
        ray = np.append(dz, dz0)
        ray /= np.abs(ray).max()
        name = f"w[{entering}]" if entering < n else f"z[{entering - n}]"
        info = {"ray": ray, "entering": name, "point": z, "z0": z0}
        proved, why = self._infeasibility(ray[:n], info)
        status = "infeasible" if proved else "ray"
        message = f"secondary ray after {pivots} pivots ({name} entering unblocked); {why}"
        return Solution(z=z, w=w, status=status, method="lemke", iterations=pivots,
                        basis=self.basis(), message=message, info=info)

    def _infeasibility(self, dz: np.ndarray, info: dict) -> tuple[bool, str]:
        """Does the ray prove the LCP infeasible?

        Lemke's theorem (Cottle-Pang-Stone Thm 4.4.13): if M is copositive-plus, a secondary
        ray has dz >= 0, dz != 0, M^T dz = -M dz <= 0 and q^T dz = -z0 d^T dz < 0, so y = dz is
        a Farkas certificate that {z >= 0 : M z + q >= 0} is empty. M + M^T positive
        semidefinite is a sufficient test for copositive-plus. The certificate itself is
        checked, to rounding, whatever M is.
        """
        M, q, n = self.M, self.q, self.n
        info["copositive_plus"] = psd = numerically_psd(M + M.T)
        y = np.maximum(dz, 0.0)
        if y.sum() <= 0:
            return False, "the ray has dz = 0 (no certificate)"
        y /= y.sum()
        MTy, qTy = M.T @ y, float(q @ y)
        slack = float(max(MTy.max(), 0.0))
        info["farkas"] = y
        info["farkas_check"] = {"max_MTy": slack, "qTy": qTy}
        ok = (qTy < -100 * n * _EPS * self.nu and slack <= 100 * n * _EPS * self.mu)
        if ok:
            return True, ("the LCP is infeasible: y = info['farkas'] >= 0 has M^T y <= 0 and "
                          f"q^T y = {qTy:.3g} < 0"
                          + (" (M + M^T is PSD, so M is copositive-plus)" if psd else ""))
        if psd:
            return False, ("M + M^T is PSD (copositive-plus), so in exact arithmetic this ray "
                           "proves infeasibility, but its certificate fails numerically "
                           f"(max M^T y = {slack:.3g}, q^T y = {qTy:.3g}): numerical trouble")
        return False, ("ray (Lemke's termination; no proof of infeasibility): M is not known "
                       "to be copositive-plus, and on such M Lemke's method can end on a "
                       "secondary ray of an LCP that has solutions")
