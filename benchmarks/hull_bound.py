"""The Lagrangian (convex-hull) relaxation of the contacts whose order is open, measured on
Fig. 9's two open ends (issue 21): its root bound, alone and inside the disk split's cases.

    python benchmarks/hull_bound.py [--system fig9|row1|row2|row3] [--cases N] [--no-cap-cases]

Setting as in verify.ranges.disk_split: no translation, a_t = T_u ra + b on the frictional
contacts, |ra_i| <= M* (the rotation cap), and on every valid steady state (*): a_t > 0 =>
S = -mu R, a_t < 0 => S = +mu R. The two-disk contacts 2-colour the disks (sigma_i = +-1):
w_i = sigma_i ra_i makes a two-disk contact's a_t = kappa (w_i - w_j) (kappa = eps sigma_i),
a one-disk contact's (the plane's) a_t = eps sigma_i w_i + b with |b| = M*.

The set. Keep the force balances and torque balances aside; what is left is
X = {(w, x): w in [-M*, M*]^p, x = [R; S] in the proved force box, each frictional contact's
(R, S) in the polytope of its state read off sgn a_t(w)} (state a_t = 0: the cone
|S| <= mu R; a_t > 0: S = -mu R; a_t < 0: S = +mu R). Every valid steady state is a point of
X that satisfies the balances.

(1) conv X = conv X_bin, X_bin = X with w in {-M*, M*}^p. Threshold decomposition: for t in
(-M*, M*), w^t_i = M* if w_i > t else -M*; w = average over t of w^t, and (w^t, x) is in X:
where w_i > w_j, w^t_i >= w^t_j (a tie, whose state polytope is the cone, contains every
state's, or the same strict order: the same state); where w_i = w_j, a tie; a one-disk
contact's a_t is affine in w_i with a_t = 0 at one end (|b| = M*): at that end the cone, at
the other the strict state, which is the true one when w_i is not that end. x is the same
for every t.

(2) Dualizing the balances with multipliers y, min over X of the Lagrangian is min over
X_bin: per contact the best point of its state's polytope for y's cost (g_tie <= g_>, g_<, as
the cone contains both), a pairwise energy in the binary xi_i = [w_i = M*] that is
submodular (g_tie + g_tie <= g_> + g_<), so its local-polytope LP is exact. Hence the
Lagrangian dual (the best bound of ANY relaxation that keeps the balances as multipliers and
the contacts exact) is the LP below: the balances on x, xi_i = (w_i + M*) / (2 M*) (affine
in x through the torque balance), per two-disk contact the marginals mu00, mu01, mu10, mu11
>= 0 (mu10 + mu11 = xi_i, mu01 + mu11 = xi_j, sum 1), and Balas copies (R, S) = sum over
its three states of (R^s, S^s), each in its state's polytope scaled by its weight
(tie: mu00 + mu11; >: mu10; <: mu01), R^s in [R_lo, R_hi] times the weight; a one-disk
contact likewise with the weights xi_i, 1 - xi_i. On a valid steady state the weights are
mu10 = (w_i - w_j)^+ / (2 M*), ..., and each copy is its weight times (R, S): the LP
contains every valid steady state.

(3) The power cut, exact in the copies: S . a_t = sum over copies of S^s a_t(s) (a_t is
affine in w, and the copies are the weights times S), so sum_i z_i <= -u_obs' . lambda +
sum_copies S^s a_t(s), z_i >= the tangents of ra_i^2 / D_i (as in the disk split).

Each LP's optimum is bounded by the certified Lagrangian bound
(verify.ranges.milp.certified_result): the numbers printed are proved.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
import scipy.sparse as sp

from rigidlcp.lcp.quiet import new_highs
from rigidlcp.verify.certificates.uniqueness import quiet_highs
from rigidlcp.verify.ranges.bounds import rotation_cap
from rigidlcp.verify.ranges.disk_split import DOWN, NOTDOWN, NOTUP, OPEN, UP, _Cases, _load
from rigidlcp.verify.ranges.milp import certified_result
from rigidlcp.verify.ranges.observables import alpha_rows
from rigidlcp.verify.ranges.seeds import two_colouring
from rigidlcp.verify.ranges.steady import Formulation, _equalities, velocity_box


class Hull:
    """The LP of the module docstring. Columns: x = [R; S] (2c) | xi (p) | z (p) | per
    two-disk frictional contact mu00, mu01, mu10, mu11 and three copies (R, S) (tie, >, <) |
    per one-disk frictional contact two copies (R, S) (xi = 0, xi = 1)."""

    def __init__(self, form: Formulation, cost: np.ndarray, power: bool = True,
                 rlt: bool = False):
        import highspy

        system, dyn = form.system, form.dyn
        c, p, mu, r = system.c, system.p, system.mu, system.lattice.radii
        M = rotation_cap(system, dyn)
        if M is None or M <= 0 or form.R_hi is None or not form.proved_for(cost):
            raise ValueError("no rotation cap or no proved force box")
        self.hs, self.c, self.p, self.M = highspy, c, p, M
        fr = np.flatnonzero(mu > 0)
        T_u, _, _ = velocity_box(dyn)
        b = np.asarray(dyn.u_obs_dot, float)[c:]
        ra = r[:, None] * alpha_rows(system, dyn)  # ra = ra_map @ x
        D = r * r * dyn.Minv[2 * p:]
        sigma = self._colours(T_u[fr], p)
        self.sigma, self.ra, self.D = sigma, ra, D
        self.layout: list = []  # per frictional contact: (beta, disks, first copy, weights)
        E, e = _equalities(dyn)
        lbx, ubx = form.lb[:2 * c].copy(), form.ub[:2 * c].copy()
        lbx[c + np.flatnonzero(mu == 0)] = ubx[c + np.flatnonzero(mu == 0)] = 0.0
        cols_lb, cols_ub = [lbx, np.zeros(p), np.zeros(p)], [ubx, np.ones(p), M * M / D]
        n = 2 * c + 2 * p
        rows: list[dict[int, float]] = []
        rlo: list[float] = []
        rhi: list[float] = []

        def row(d, lo, hi):
            rows.append(d)
            rlo.append(lo)
            rhi.append(hi)

        def new(k, lo, hi):
            nonlocal n
            cols_lb.append(np.full(k, lo, float))
            cols_ub.append(np.full(k, hi, float))
            n += k
            return n - k

        for i in range(E.shape[0]):
            row({j: E[i, j] for j in np.flatnonzero(E[i])}, e[i], e[i])
        ixi, iz = 2 * c, 2 * c + p
        # xi_i = (sigma_i ra_i + M) / (2 M)  <=>  2 M xi_i - sigma_i ra_i = M
        for i in range(p):
            d = {j: -sigma[i] * ra[i, j] for j in np.flatnonzero(ra[i])}
            d[ixi + i] = 2 * M
            row(d, M, M)
        pw: dict[int, float] = {iz + i: -1.0 for i in range(p)}
        for j in range(2 * c):  # -u_obs' . lambda
            u = -float(np.asarray(dyn.u_obs_dot, float)[j])
            if u != 0:
                pw[j] = pw.get(j, 0.0) + u
        ts = M * np.array([-1.0, -0.75, -0.5, -0.25, 0.25, 0.5, 0.75, 1.0])
        for i in range(p if power or rlt else 0):  # z_i >= (2 t ra_i - t^2) / D_i
            for t in ts:
                d = {j: -2 * t / D[i] * ra[i, j] for j in np.flatnonzero(ra[i])}
                d[iz + i] = 1.0
                row(d, -t * t / D[i], np.inf)
        self.ixi, self.iz = ixi, iz
        one = self.one = new(1, 1.0, 1.0)  # a column fixed at 1 (weights 1 - xi)
        up: list[dict[int, float]] = [{} for _ in range(p)]  # per disk: xi_i S copies, T
        for beta in fr:
            nz = np.flatnonzero(T_u[beta])
            eps = float(T_u[beta, nz[0]])
            m_ = float(mu[beta])
            Rl, Rh, Sl, Sh = lbx[beta], ubx[beta], lbx[c + beta], ubx[c + beta]
            if nz.size == 2:
                i, j = nz
                kap = eps * sigma[i]  # a_t = kap (w_i - w_j) = kap 2M (xi_i - xi_j)
                im = new(4, 0.0, 1.0)  # mu00, mu01, mu10, mu11
                row({im + 2: 1, im + 3: 1, ixi + i: -1}, 0, 0)
                row({im + 1: 1, im + 3: 1, ixi + j: -1}, 0, 0)
                row({im: 1, im + 1: 1, im + 2: 1, im + 3: 1}, 1, 1)
                # (weight, a_t at the vertex, disks with xi = 1 there)
                states = [({im: 1.0}, 0.0, ()), ({im + 3: 1.0}, 0.0, (i, j)),
                          ({im + 2: 1.0}, 2 * M * kap, (i,)),
                          ({im + 1: 1.0}, -2 * M * kap, (j,))]
                if not rlt:  # the two ties as one copy
                    states = [({im: 1.0, im + 3: 1.0}, 0.0, ())] + states[2:]
            else:
                i = nz[0]
                if abs(abs(b[beta]) - M) > 1e-12 * M:
                    raise ValueError("a one-disk frictional contact with |b| != M*")
                # vertex xi = 1: w = M, ra = sigma M; xi = 0: ra = -sigma M
                a1 = eps * sigma[i] * M + b[beta]
                a0 = -eps * sigma[i] * M + b[beta]
                states = [({ixi + i: 1.0}, a1, (i,)), ({one: 1.0, ixi + i: -1.0}, a0, ())]
            cp = new(2 * len(states), 0.0, 0.0)  # bounds: weight * (R, S), weight in [0, 1]
            self.layout.append((int(beta), nz, cp, [st[0] for st in states]))
            for s in range(len(states)):
                cols_lb[-1][2 * s:2 * s + 2] = [min(0.0, Rl), min(0.0, Sl)]
                cols_ub[-1][2 * s:2 * s + 2] = [max(0.0, Rh), max(0.0, Sh)]
            sumR, sumS = {beta: -1.0}, {c + beta: -1.0}
            for s, (wt, a, ups) in enumerate(states):
                R_, S_ = cp + 2 * s, cp + 2 * s + 1
                sumR[R_], sumS[S_] = 1.0, 1.0
                for d_ in ups:
                    up[d_][S_] = float(T_u[beta, d_])  # ra_i / D_i = sum T_u[beta, i] S_beta
                for var, lo_, hi_ in ((R_, Rl, Rh), (S_, Sl, Sh)):
                    d = {var: 1.0}
                    for kk, v in wt.items():
                        d[kk] = d.get(kk, 0.0) - lo_ * v
                    row(d, 0.0, np.inf)  # var >= lo * weight
                    d = {var: 1.0}
                    for kk, v in wt.items():
                        d[kk] = d.get(kk, 0.0) - hi_ * v
                    row(d, -np.inf, 0.0)  # var <= hi * weight
                if abs(a) <= 1e-12 * M:  # cone
                    row({R_: m_, S_: 1.0}, 0.0, np.inf)
                    row({R_: m_, S_: -1.0}, 0.0, np.inf)
                else:  # S = -sgn(a) mu R
                    row({S_: 1.0, R_: np.sign(a) * m_}, 0.0, 0.0)
                    pw[S_] = pw.get(S_, 0.0) + a  # the term S^s a(s) <= 0 of the power cut
            row(sumR, 0.0, 0.0)
            row(sumS, 0.0, 0.0)
        # the torque balance of disk i times xi_i (self-RLT): ra_i xi_i / D_i = sum_beta
        # T[beta, i] (xi_i S_beta); ra_i xi_i = sigma_i (w_i^2 + M w_i) / (2 M), w_i^2 = D_i z_i
        # (the power cut's column, z_i >= tangents, z_i <= M^2 / D_i), w_i = sigma_i ra_i
        self.check_torque(ra, D, T_u, fr, c)
        if rlt:
            for i in range(p):
                d = {S_: -v for S_, v in up[i].items()}
                d[iz + i] = d.get(iz + i, 0.0) + sigma[i] * D[i] / (2 * M * D[i])
                for j in np.flatnonzero(ra[i]):  # + sigma_i M w_i / (2 M D_i) = ra_i / (2 D_i)
                    d[j] = d.get(j, 0.0) + ra[i, j] / (2 * D[i])
                row(d, 0.0, 0.0)
        if power:
            row(pw, 0.0, np.inf)
        lb, ub = np.concatenate(cols_lb), np.concatenate(cols_ub)
        ri = [i for i, d in enumerate(rows) for _ in d]
        ci = [j for d in rows for j in d]
        vv = [v for d in rows for v in d.values()]
        A = sp.csr_matrix((vv, (ri, ci)), shape=(len(rows), n))
        self.A, self.lo, self.hi, self.lb, self.ub = A, np.array(rlo), np.array(rhi), lb, ub
        self.cost = np.r_[np.asarray(cost, float), np.zeros(n - 2 * c)]
        self.h = new_highs(primal_feasibility_tolerance=1e-10,
                           dual_feasibility_tolerance=1e-10, presolve="off")
        _load(self.h, highspy, self.cost, A, self.lo, self.hi, lb, ub)

    def lift(self, x: np.ndarray) -> np.ndarray:
        """The LP's columns at a valid steady state x = [R; S] (module docstring, (2)): xi_i
        = (w_i + M*) / (2 M*), z_i = ra_i^2 / D_i, mu10 = (w_i - w_j)^+ / (2 M*), mu01 =
        (w_j - w_i)^+ / (2 M*), mu11 = xi_i - mu10, mu00 the rest, each copy its weight times
        the contact's (R, S)."""
        c, p, M = self.c, self.p, self.M
        v = np.zeros(self.A.shape[1])
        v[:2 * c] = x
        ra = self.ra @ x
        w = self.sigma * ra
        v[self.ixi:self.ixi + p] = (w + M) / (2 * M)
        v[self.iz:self.iz + p] = ra * ra / self.D
        v[self.one] = 1.0
        for beta, nz, cp, weights in self.layout:
            if nz.size == 2:
                i, j = nz
                im = min(weights[0])
                m10 = max(w[i] - w[j], 0.0) / (2 * M)
                m01 = max(w[j] - w[i], 0.0) / (2 * M)
                m11 = v[self.ixi + i] - m10
                v[im:im + 4] = [1.0 - m10 - m01 - m11, m01, m10, m11]
            for s, wt in enumerate(weights):
                k = sum(coef * v[col] for col, coef in wt.items())
                v[cp + 2 * s], v[cp + 2 * s + 1] = k * x[beta], k * x[c + beta]
        return v

    @staticmethod
    def check_torque(ra: np.ndarray, D: np.ndarray, T_u: np.ndarray, fr: np.ndarray, c: int
                     ) -> None:
        """ra = D T_u^T S on the frictional contacts' S, no R (the frictionless contacts'
        S = 0 are ignored), else ValueError: the self-RLT rows rely on it."""
        want = np.zeros_like(ra)
        want[:, c + fr] = D[:, None] * T_u[fr].T
        keep = np.r_[np.arange(c), c + fr]
        if not np.allclose(ra[:, keep], want[:, keep], rtol=1e-12,
                           atol=1e-12 * np.abs(ra).max()):
            raise ValueError("the torque balance is not ra = D T_u^T S here")

    @staticmethod
    def _colours(Tf: np.ndarray, p: int) -> np.ndarray:
        """sigma = +-1 with sigma_j = -sigma_i on every two-disk row (a 2-colouring), else
        ValueError."""
        adj: list[list[int]] = [[] for _ in range(p)]
        for rr in Tf:
            nz = np.flatnonzero(rr)
            if nz.size == 2:
                adj[nz[0]].append(nz[1])
                adj[nz[1]].append(nz[0])
        sigma = two_colouring(adj)
        if sigma is None:
            raise ValueError("the two-disk contacts do not 2-colour the disks")
        return sigma.astype(int)

    def solve(self, col_lb: np.ndarray | None = None, col_ub: np.ndarray | None = None
              ) -> tuple[float, np.ndarray | None]:
        """(certified lower bound, LP point) with the column bounds given (default: the
        model's)."""
        lb = self.lb if col_lb is None else col_lb
        ub = self.ub if col_ub is None else col_ub
        h = self.h
        h.changeColsBounds(len(lb), np.arange(len(lb), dtype=np.int32), lb, ub)
        with quiet_highs():
            h.run()
        return certified_result(h, self.hs, self.cost, self.A, self.lo, self.hi, lb, ub)


class HullCases(_Cases):
    """disk_split._Cases with the hull LP's rows and columns appended (the x columns shared):
    each case LP of the disk split, with rows that hold on every valid steady state (so on
    every one of the case). For disk_split_bound(..., cases_class=HullCases)."""

    def __init__(self, form: Formulation, cost: np.ndarray, M: float):
        super().__init__(form, cost, M)
        hull = Hull(form, cost, rlt=True)
        c2, nb = 2 * self.c, self.A.shape[1]
        self.nb, self.mb = nb, self.A.shape[0]
        Hx = sp.hstack([hull.A[:, :c2], sp.csr_matrix((hull.A.shape[0], nb - c2))])
        self.A = sp.bmat([[sp.csr_matrix(self.A), None], [Hx, hull.A[:, c2:]]]).tocsr()
        self.Ad = None  # not kept dense (solve_with below updates A itself)
        self.lb = np.r_[self.lb, hull.lb[c2:]]
        self.ub = np.r_[self.ub, hull.ub[c2:]]
        self.lo0, self.hi0 = np.r_[self.lo0, hull.lo], np.r_[self.hi0, hull.hi]
        self.cost = np.r_[self.cost, np.zeros(hull.A.shape[1] - c2)]
        self.h = new_highs(primal_feasibility_tolerance=1e-10,
                           dual_feasibility_tolerance=1e-10, presolve="off")
        _load(self.h, self.hs, self.cost, self.A, self.lo0, self.hi0, self.lb, self.ub)
        self.cur_lo, self.cur_hi = self.lo0.copy(), self.hi0.copy()
        self.pw_row = np.asarray(self.A[self.r_pw].todense()).ravel()
        # the power row's entries stored for every column it may use (x and z: explicit
        # zeros kept), so that a case changes them in place
        A = self.A.tolil()
        A[self.r_pw, :nb] = 1.0
        A = A.tocsr()
        lo_, hi_ = A.indptr[self.r_pw], A.indptr[self.r_pw + 1]
        self.pw_cols = A.indices[lo_:hi_]
        A.data[lo_:hi_] = self.pw_row[self.pw_cols]
        self.A, self.pw_slice = A, slice(lo_, hi_)

    def solve_with(self, disks: np.ndarray, lo: np.ndarray, hi: np.ndarray
                   ) -> tuple[float, np.ndarray | None]:
        """As _Cases.solve_with, on the larger LP (its sparse matrix updated in place)."""
        h = self.h
        row = np.r_[self.power_row(disks), np.zeros(self.A.shape[1] - self.nb)]
        changed = np.flatnonzero(row != self.pw_row)
        if changed.size:
            for j in changed:
                h.changeCoeff(self.r_pw, int(j), float(row[j]))
            if not np.all(np.isin(changed, self.pw_cols)):
                raise AssertionError("the power row left its stored pattern")
            self.A.data[self.pw_slice] = row[self.pw_cols]
            self.pw_row = row
        for i in np.flatnonzero((lo != self.cur_lo) | (hi != self.cur_hi)):
            h.changeRowBounds(int(i), float(lo[i]), float(hi[i]))
        self.cur_lo, self.cur_hi = lo, hi
        with quiet_highs():
            h.run()
        if h.getModelStatus() not in (self.hs.HighsModelStatus.kOptimal,
                                      self.hs.HighsModelStatus.kInfeasible):
            h.clearSolver()
            with quiet_highs():
                h.run()
        b, x = certified_result(h, self.hs, self.cost, self.A, lo, hi, self.lb, self.ub)
        return b, (None if x is None else x[:2 * self.c])


def cap_cases(form: Formulation, cost: np.ndarray) -> dict[str, np.ndarray]:
    """The certified bound of every cap-split case (each first-row disk at its rolling cap
    point, or not) as disk-split case LPs, without and with the hull rows: 2^n values each
    (+inf: the case proved empty)."""
    from rigidlcp.verify.ranges.cap_split import cap_contacts

    system = form.system
    M = rotation_cap(system, form.dyn)
    beta, disk, eps, _ = cap_contacts(form)
    b = np.asarray(form.dyn.u_obs_dot, float)[system.c + beta]
    down = np.round(-b / eps / M) < 0  # the rolling point is -M* (else +M*)
    out = {}
    for label, cls in (("disk-split LP", _Cases), ("with the hull rows", HullCases)):
        cases, vals = cls(form, cost, M), []
        for g in range(2 ** beta.size):
            disks = np.full(system.p, OPEN)
            for k in range(beta.size):
                at = (g >> k) & 1
                disks[disk[k]] = ((DOWN if down[k] else UP) if at
                                  else (NOTDOWN if down[k] else NOTUP))
            vals.append(cases.solve(disks, {})[0])
        out[label] = np.array(vals)
    return out


SYSTEMS = {"fig9": ((10, 4), 0.1, 0.2, 0.16), "row1": ((10, 1), 0.05, 0.1, 0.01),
           "row2": ((10, 1), 0.05, 0.1, 0.02), "row3": ((10, 1), 0.1, 0.2, 0.02)}
#: The best checked values met (docs/mechanics.md): the targets of the case searches.
MET = {"fig9": (0.1050919108, 0.1534752959), "row1": (0.0145179, 0.01),
       "row2": (0.0290357, 0.02), "row3": (0.0669235, 0.02)}
PROVED = 0.0610279  # Fig. 9's min mu_g >= this (the disk split, 1800 s: docs/mechanics.md)


def main() -> int:
    from rigidlcp import models
    from rigidlcp.verify.ranges.cap_split import cap_split_bound
    from rigidlcp.verify.ranges.disk_split import disk_split_bound
    from rigidlcp.verify.ranges.observables import mu_g_vector
    from rigidlcp.verify.ranges.steady import formulate

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--system", default="fig9", choices=sorted(SYSTEMS))
    ap.add_argument("--cases", type=int, default=1500, help="LPs per disk-split search")
    ap.add_argument("--no-cap-cases", action="store_true", help="skip the 2^n cap cases")
    args = ap.parse_args()
    (nx, ny), mpp, mpl, g = SYSTEMS[args.system]
    system = models.System(models.rectangular(nx, ny), mu_pp=mpp, mu_plane=mpl, mu_wall=0.0,
                           gamma=g)
    form = formulate(system)
    last = nx - 1
    print(f"{args.system}; load {os.getloadavg()[0]:.2f}; CPU s (time.process_time)")
    print("| end | relaxation | proved bound | LP size | CPU s |")
    print("|---|---|---|---|---|")
    ends = (("min mu_g", mu_g_vector(system), 1.0, MET[args.system][0]),
            (f"max alpha_{last}", -alpha_rows(system, form.dyn)[last], -1.0,
             -MET[args.system][1]))
    for name, L, sense, _ in ends:
        for power, rlt in ((False, False), (True, False), (True, True)):
            c0 = time.process_time()
            hull = Hull(form, L, power=power, rlt=rlt)
            bnd, _ = hull.solve()
            label = "hull" + (" + power" if power else "") + (" + self-RLT" if rlt else "")
            print(f"| {name} | {label} (root) | {sense * bnd:.7f} | {hull.A.shape[0]} x "
                  f"{hull.A.shape[1]} | {time.process_time() - c0:.2f} |")
        c0 = time.process_time()
        cs = cap_split_bound(form, L)
        print(f"| {name} | cap split ({cs.cases} LPs) | {sense * cs.bound:.7f} | | "
              f"{time.process_time() - c0:.2f} |")
    L, target = ends[0][1], ends[0][3]
    if not args.no_cap_cases:
        c0 = time.process_time()
        vals = cap_cases(form, L)
        print(f"\nmin mu_g, the {len(vals['disk-split LP'])} cap cases as disk-split case LPs "
              f"({time.process_time() - c0:.1f} CPU s, both columns):")
        print(f"| case LP | least bound | below {PROVED:.7f} (Fig. 9's proved bound) | "
              f"below the met {target:.7f} | empty |")
        print("|---|---|---|---|---|")
        for label, v in vals.items():
            print(f"| {label} | {v.min():.7f} | {(v < PROVED).sum()} | "
                  f"{(v < target).sum()} | {(v == np.inf).sum()} |")
    print(f"\nmin mu_g, the disk split at {args.cases} cases:")
    print("| case LP | proved bound | open | empty | CPU s |")
    print("|---|---|---|---|---|")
    for label, cls in (("disk-split LP", None), ("with the hull rows", HullCases)):
        c0 = time.process_time()
        res = disk_split_bound(form, L, target, 1e9, max_cases=args.cases, cases_class=cls)
        print(f"| {label} | {res.bound:.7f} | {res.open} | {res.empty} | "
              f"{time.process_time() - c0:.1f} |")
    print(f"load {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
