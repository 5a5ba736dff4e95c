"""The force-network ensemble: uniform samples of the admissible forces P of a packing at rest
(verify.statics.model) and the force distribution P(f), f = R / <R> (Snoeijer et al., PRE 70,
061306, 2004; Unger, Kertesz & Wolf, PRL 94, 178001, 2005).

P is sampled on its affine hull, where it is full-dimensional (a sampler in the 2c unknowns
would see a flat set and stall). `forceset.analyse` gives the implicit equalities (R = 0,
S = +-mu R on the whole of P) and a point of P; substituting them leaves unknowns z with
lambda = E z, the balance B z = b (B = H^T E, `hull.reduced_balance`) and the remaining
inequalities. With an orthonormal basis N of ker B (dense SVD, rank rule of
`hull.dimension`) and a point z0 of P, z = z0 + N y, and P is the polytope
{y : G (z0 + N y) <= 0} in dim P coordinates; uniform samples of y are uniform samples of P
(the map is an isometry onto the affine hull).

The sampler is hopsy's uniform hit-and-run (PyPI `hopsy`, optional extra `[ensemble]`) when it
is installed, else `hit_and_run` below (Smith's hit-and-run: a uniformly random direction, a
uniform point of the chord; its stationary law is uniform on a bounded convex body). Every
sampled network is checked against P (`StaticProblem.residuals`) before it is returned.

P must be bounded to carry a uniform law: `sample` refuses an unbounded P (walls that can
pinch the pile with any force; one LP: sum R unbounded) unless `cap` bounds sum R.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rigidlcp import models
from rigidlcp.lcp.errors import InvalidInput, NotApplicable

from .forceset import ForceSet, analyse
from .hull import reduced_balance
from .model import ForceLP, StaticProblem


class UnboundedForceSet(ValueError):
    """P is unbounded (sum R has no maximum): no uniform law on it without a cap."""


@dataclass
class Ensemble:
    """samples (n, 2c): networks [R; S], each checked against P; residuals: the largest
    (balance, laws) residuals over them in force units; sampler: "hopsy" or "hit-and-run"."""

    forceset: ForceSet
    samples: np.ndarray
    residuals: tuple[float, float]
    sampler: str
    cap: float | None = None

    @property
    def R(self) -> np.ndarray:
        return self.samples[:, : self.forceset.c]

    def f(self) -> np.ndarray:
        """f = R / <R> per network (<R>: the mean normal force of that network over its
        contacts), pooled over the networks."""
        R = self.R
        mean = R.mean(axis=1, keepdims=True)
        return (R / np.where(mean > 0, mean, 1.0)).ravel()

    def fluctuation(self) -> float:
        """The ensemble fluctuation of the forces: the standard deviation of each R_a over
        the ensemble, averaged over contacts, in units of the mean force <R> (0 when the
        forces are unique, dim P = 0)."""
        if self.forceset.dimension == 0:
            return 0.0
        R = self.R
        mean = float(R.mean())
        return float(R.std(axis=0).mean() / mean) if mean > 0 else 0.0


def hopsy_available() -> bool:
    try:
        import hopsy  # noqa: F401
    except ImportError:
        return False
    return True


def _embedding(prob: StaticProblem, implicit: list[str]) -> sp.csc_matrix:
    """E (2c x nz): lambda = E z on the implicit equalities (columns as reduced_balance)."""
    c, mu = prob.c, prob.mu
    rows, cols, vals = [], [], []
    k = 0
    for a in range(c):
        kind = implicit[a]
        if kind == "R=0":
            continue
        if mu[a] == 0:
            rows, cols, vals = rows + [a], cols + [k], vals + [1.0]
            k += 1
        elif kind:
            s = mu[a] if kind == "S=+muR" else -mu[a]
            rows, cols, vals = rows + [a, c + a], cols + [k, k], vals + [1.0, s]
            k += 1
        else:
            rows, cols, vals = rows + [a, c + a], cols + [k, k + 1], vals + [1.0, 1.0]
            k += 2
    return sp.csc_matrix((vals, (rows, cols)), shape=(2 * c, k))


def hull_polytope(fs: ForceSet, cap: float | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(A_y, b_y, lam0, M): P = {lam0 + M y : A_y y <= b_y}, M (2c x dim P) with orthonormal
    columns (module docstring); cap adds sum R <= cap."""
    prob = StaticProblem(fs.system)
    E = _embedding(prob, fs.implicit)
    B = reduced_balance(prob, fs.implicit).toarray()
    if B.shape[1] != E.shape[1]:
        raise AssertionError("embedding and reduced balance disagree")
    lam0 = np.asarray(fs.solution, dtype=float)
    if B.shape[1] == 0:
        return np.zeros((0, 0)), np.zeros(0), lam0, np.zeros((prob.n, 0))
    _, w, vt = np.linalg.svd(B, full_matrices=True)
    tol = max(B.shape) * np.finfo(float).eps * float(w[0] if w.size else 0.0)
    rank = int(np.sum(w > tol))
    N = vt[rank:].T  # orthonormal basis of ker B
    M = E @ N  # E's columns are orthogonal, so M's are too up to the scale 1 or 1+mu^2
    M = np.linalg.qr(M)[0] if M.shape[1] else M
    # z0: the checked solution projected onto the implicit equalities (it satisfies them up
    # to the LP tolerance); the inequalities kept: R >= 0 and |S| <= mu R where not implicit
    z0 = np.linalg.lstsq(E.toarray(), lam0, rcond=None)[0]
    lam0 = E @ z0
    Gi = sp.vstack([-sp.eye(prob.c, prob.n), prob.G], format="csr")
    keep = np.abs(Gi @ M).sum(axis=1) > 1e-12 if M.shape[1] else np.zeros(0, bool)
    A_y = np.asarray(Gi @ M)[keep]
    b_y = np.maximum(-np.asarray(Gi @ lam0)[keep], 0.0)  # lam0 in P up to the LP tolerance
    if cap is not None:  # lam0 itself may exceed the cap: not clamped
        A_y = np.vstack([A_y, M[: prob.c].sum(axis=0)])
        b_y = np.r_[b_y, cap - lam0[: prob.c].sum()]
    return A_y, b_y, lam0, M


def _bounded(fs: ForceSet) -> bool:
    """P is bounded iff sum R is (a recession direction has R >= 0, and |S| <= mu R)."""
    prob = StaticProblem(fs.system)
    status, _ = ForceLP(prob).solve(-np.r_[np.ones(prob.c), np.zeros(prob.c)])
    return status == "optimal"


def _start(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The Chebyshev centre of {A y <= b} (an LP), a point deep inside for the chain."""
    from scipy.optimize import linprog

    d = A.shape[1]
    norms = np.linalg.norm(A, axis=1)
    res = linprog(np.r_[np.zeros(d), -1.0], A_ub=np.c_[A, norms], b_ub=b,
                  bounds=[(None, None)] * d + [(0, None)], method="highs")
    if res.status != 0 or res.x[-1] <= 0:
        raise NotApplicable("the admissible forces have no interior point on their hull (a cap "
                         f"on sum R below its minimum?): {res.message}")
    return res.x[:d]


def hit_and_run(A: np.ndarray, b: np.ndarray, y0: np.ndarray, n: int, thinning: int,
                rng: np.random.Generator) -> np.ndarray:
    """n samples of Smith's hit-and-run on the bounded polytope {A y <= b} from an interior
    y0, keeping every `thinning`-th step: the stationary law is uniform."""
    d = y0.size
    y = y0.copy()
    out = np.empty((n, d))
    for s in range(n * thinning):
        u = rng.standard_normal(d)
        u /= np.linalg.norm(u)
        au, slack = A @ u, b - A @ y
        with np.errstate(divide="ignore", invalid="ignore"):
            t = slack / au
        hi = np.min(t[au > 0], initial=np.inf)
        lo = np.max(t[au < 0], initial=-np.inf)
        if not (np.isfinite(lo) and np.isfinite(hi)):
            raise UnboundedForceSet("hit-and-run met an unbounded chord")
        y = y + rng.uniform(lo, hi) * u
        if (s + 1) % thinning == 0:
            out[(s + 1) // thinning - 1] = y
    return out


def rounding(A: np.ndarray, b: np.ndarray, y0: np.ndarray, rng: np.random.Generator,
             rounds: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """(c, L): an affine map y = c + L u making {A y <= b} roughly isotropic in u, from the
    covariance of short hit-and-run runs (a chain in a thin, elongated polytope barely moves
    along its long axes). A linear map carries a uniform law to a uniform law, so sampling u
    uniformly and mapping back is exact; the map only speeds mixing."""
    d = y0.size
    c, L = y0.copy(), np.eye(d)
    for _ in range(rounds):
        Au, bu = A @ L, b - A @ c
        us = hit_and_run(Au, bu, np.zeros(d), 20 * d, 1, rng)
        ys = c + us @ L.T
        cov = np.atleast_2d(np.cov(ys.T))
        cov = cov + 1e-12 * max(float(np.trace(cov)), 1e-300) * np.eye(d)
        try:
            L = np.linalg.cholesky(cov)
        except np.linalg.LinAlgError:
            break
        c = _start(A @ L, b - A @ ys.mean(axis=0)) @ L.T + ys.mean(axis=0)
    return c, L


def _hopsy(A: np.ndarray, b: np.ndarray, y0: np.ndarray, n: int, thinning: int,
           seed: int) -> np.ndarray:
    import hopsy

    problem = hopsy.Problem(A, b)
    chain = hopsy.MarkovChain(problem, proposal=hopsy.UniformHitAndRunProposal,
                              starting_point=y0)
    _, s = hopsy.sample(chain, hopsy.RandomNumberGenerator(seed), n_samples=n,
                        thinning=thinning)
    return np.asarray(s, dtype=float).reshape(n, -1)


def sample(system_or_fs: models.System | ForceSet, n: int = 1000, seed: int = 0,
           thinning: int | None = None, sampler: str = "auto", cap: float | None = None,
           tol: float = 1e-8) -> Ensemble:
    """n uniform samples of P (module docstring). thinning: steps per kept sample (default
    the dimension, at least 10); sampler "auto" (hopsy if installed), "hopsy" or
    "hit-and-run"; tol: every sample must lie in P to tol (`StaticProblem.admissible`)."""
    fs = (system_or_fs if isinstance(system_or_fs, ForceSet)
          else analyse(system_or_fs, ranges=False))
    if not fs.exists:
        raise NotApplicable("no equilibrium: the admissible set is empty (Farkas certificate)")
    if fs.dimension is None:
        raise NotApplicable("the dimension of the admissible set is not settled at this size")
    if cap is None and not _bounded(fs):
        raise UnboundedForceSet("the admissible forces are unbounded (walls can pinch the "
                                "pile with any force): give a cap on sum R (--cap)")
    if sampler == "auto":
        sampler = "hopsy" if hopsy_available() else "hit-and-run"
    A, b, lam0, M = hull_polytope(fs, cap)
    if M.shape[1] != fs.dimension:
        raise RuntimeError(f"hull basis of size {M.shape[1]} against dimension "
                           f"{fs.dimension} (please report)")
    if M.shape[1] == 0:
        lams = np.repeat(lam0[None], n, axis=0)
    else:
        rng = np.random.default_rng(seed)
        y0, L = rounding(A, b, _start(A, b), rng)
        Au, bu = A @ L, b - A @ y0
        u0 = np.zeros(M.shape[1])
        thin = thinning or max(10, M.shape[1])
        if sampler == "hopsy":
            us = _hopsy(Au, bu, u0, n, thin, seed)
        elif sampler == "hit-and-run":
            us = hit_and_run(Au, bu, u0, n, thin, rng)
        else:
            raise InvalidInput(f"unknown sampler {sampler!r}")
        lams = lam0[None] + (y0 + us @ L.T) @ M.T
    prob = StaticProblem(fs.system)
    res = np.array([prob.residuals(lam) for lam in lams])
    bad = [k for k, lam in enumerate(lams) if not prob.admissible(lam, tol)]
    if bad:
        raise RuntimeError(f"{len(bad)} sampled networks fail the check against P "
                           f"(first: {bad[0]}; please report)")
    return Ensemble(fs, lams, (float(res[:, 0].max()), float(res[:, 1].max())), sampler, cap)
