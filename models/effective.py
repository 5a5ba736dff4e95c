"""Effective inertia and effective friction by the Legendre transform of F_g(gamma) (Sec. IV B).

Eq. (2.1), N - F_g = m_g gamma, with the steady-state global friction F_g(gamma) of a sweep.
Eqs. (4.1)-(4.2):

    a = dF_g / dgamma,   b = F_g - a gamma,   N - F_e = m_e gamma,
    F_e = b,   m_e = m_g + a,   mu_e = F_e / (m_g g).

The derivative estimate (`derivative`). F_g(gamma) is piecewise linear: the steady state of a
given pattern of contact states is the solution of a linear system whose right-hand side is
linear in gamma, and the pattern changes at isolated accelerations (the kinks of Fig. 11, one
per disk that leaves mode 1). A centred difference across a kink averages two slopes and
gives a wrong a (hence a wrong b) at both neighbours of the kink. Instead, at each gamma_i we
fit a polynomial of degree `degree` (default 1: the pieces are lines) by least squares to every
window of `window` (default 3, the fewest points that can reveal a kink of a line) consecutive
points that contains gamma_i, and keep the window with the smallest RMS residual: a window that
does not straddle a kink fits exactly (residual at rounding level), so on a piecewise-linear
curve whose pieces span >= `window` grid points the estimate is the exact slope of the piece
the point lies on -- one-sided next to a kink. a is the fitted polynomial's derivative *at
gamma_i* (not at the window's centre).

Ties: windows whose residual is within `tol` of the best, or within a factor `ratio` (2) of it,
are ties, and the most centred of them wins. On a smooth curve neighbouring windows have
residuals within a factor 1 + O(h) of each other, so the centred window is used: with the
defaults, the centred difference, exact for a quadratic F_g on a uniform grid and O(h^2) on a
smooth one (O(h) at the two ends, where only one-sided windows exist; `degree=2, window=4`
differentiates a quadratic exactly everywhere, ends included). Next to a kink the exact window
has a rounding-level residual and the straddling ones a residual ~ (slope jump) x (spacing), so
no tie. Two equally centred tied windows (a kink exactly at a grid point, where the left and
right pieces both fit exactly) are averaged: a value inside the subdifferential
[right slope, left slope]. `Effective.exact` flags the points whose chosen window fitted
within `tol`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def derivative(x, y, window: int = 3, degree: int = 1, tol: float | None = None,
               ratio: float = 2.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """dy/dx at every x by least-residual local polynomial fits (see the module docstring).

    Returns (dydx, residual, start): the RMS residual of the chosen window and its first index
    (for an averaged tie, the left window's). x must be strictly increasing. tol: residuals
    within tol are equal, default 1e-9 * max(|y|, 1) -- far above rounding (1e-15 relative)
    and far below the residual of a window across a kink (~ slope jump x spacing).
    """
    x = np.asarray(x, dtype=float).reshape(-1)
    y = np.asarray(y, dtype=float).reshape(-1)
    n = x.size
    if y.size != n:
        raise ValueError(f"x and y differ in length ({n} and {y.size})")
    if n < 2:
        raise ValueError("a derivative needs at least two points")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise ValueError("x and y must be finite")
    if np.any(np.diff(x) <= 0):
        raise ValueError("x must be strictly increasing (one value of F_g per gamma)")
    if degree < 1:
        raise ValueError(f"degree must be >= 1, got {degree}")
    if ratio < 1:
        raise ValueError(f"ratio must be >= 1, got {ratio}")
    if window < degree + 1:
        raise ValueError(f"window ({window}) must be >= degree + 1 ({degree + 1})")
    w = min(window, n)
    d = min(degree, w - 1)
    if tol is None:
        tol = 1e-9 * max(float(np.abs(y).max()), 1.0)
    # Fit every window once: coefficients in the window's centred, scaled coordinate.
    starts = np.arange(n - w + 1)
    coef, res = [], np.empty(starts.size)
    for s in starts:
        xs, ys = x[s:s + w], y[s:s + w]
        c0, h = 0.5 * (xs[0] + xs[-1]), 0.5 * (xs[-1] - xs[0])
        V = np.vander((xs - c0) / h, d + 1, increasing=True)
        c, *_ = np.linalg.lstsq(V, ys, rcond=None)
        coef.append((c, c0, h))
        res[s] = np.sqrt(np.mean((V @ c - ys) ** 2))
    dydx, resid, start = np.empty(n), np.empty(n), np.empty(n, dtype=int)
    for i in range(n):
        cand = np.arange(max(0, i - w + 1), min(i, n - w) + 1)
        best = res[cand].min()
        tied = cand[(res[cand] <= best + tol) | (res[cand] <= ratio * best)]
        offset = np.abs(tied + 0.5 * (w - 1) - i)
        chosen = tied[offset <= offset.min() + 1e-12]
        slopes = [_slope_at(*coef[s], x[i]) for s in chosen]
        dydx[i] = float(np.mean(slopes))
        resid[i] = float(res[chosen].max())
        start[i] = int(chosen[0])
    return dydx, resid, start


def _slope_at(c: np.ndarray, c0: float, h: float, x: float) -> float:
    u = (x - c0) / h
    k = np.arange(1, c.size)
    return float(np.sum(k * c[1:] * u ** (k - 1)) / h)


@dataclass
class Effective:
    """Eqs. (4.1)-(4.2) at each gamma of a sweep."""

    gamma: np.ndarray
    F_g: np.ndarray
    a: np.ndarray  # dF_g / dgamma (Eq. 4.1)
    b: np.ndarray  # F_g - a gamma = F_e
    m_g: float
    g: float
    residual: np.ndarray  # RMS residual of the fit each a comes from
    exact: np.ndarray  # the fit matched the data within tol (no kink inside its window)

    @property
    def m_e(self) -> np.ndarray:
        """Effective inertia m_e = m_g + a (Eq. 4.2)."""
        return self.m_g + self.a

    @property
    def F_e(self) -> np.ndarray:
        """Effective friction force F_e = b (Eq. 4.2)."""
        return self.b

    @property
    def mu_e(self) -> np.ndarray:
        """Effective coefficient of friction mu_e = F_e / (m_g g)."""
        return self.b / (self.m_g * self.g)

    @property
    def mu_g(self) -> np.ndarray:
        """Global coefficient of friction mu_g = F_g / (m_g g) (Eq. 2.2)."""
        return self.F_g / (self.m_g * self.g)

    def rows(self) -> list[dict]:
        return [{"gamma": float(self.gamma[k]), "F_g": float(self.F_g[k]),
                 "mu_g": float(self.mu_g[k]), "a": float(self.a[k]), "b": float(self.b[k]),
                 "m_e": float(self.m_e[k]), "mu_e": float(self.mu_e[k]),
                 "exact": bool(self.exact[k])} for k in range(self.gamma.size)]


def legendre(gamma, F_g, m_g: float, g: float = 1.0, window: int = 3, degree: int = 1,
             tol: float | None = None) -> Effective:
    """The Legendre transform of F_g(gamma), Eqs. (4.1)-(4.2), with `derivative`'s estimate
    of a = dF_g/dgamma. gamma is sorted here (F_g follows)."""
    gamma = np.asarray(gamma, dtype=float).reshape(-1)
    F_g = np.asarray(F_g, dtype=float).reshape(-1)
    if gamma.size != F_g.size:
        raise ValueError(f"gamma and F_g differ in length ({gamma.size} and {F_g.size})")
    if not m_g > 0 or not g > 0:
        raise ValueError(f"m_g and g must be > 0, got {m_g} and {g}")
    order = np.argsort(gamma, kind="stable")
    gamma, F_g = gamma[order], F_g[order]
    if tol is None:
        tol = 1e-9 * max(float(np.abs(F_g).max(initial=0.0)), m_g * g)
    a, residual, _ = derivative(gamma, F_g, window=window, degree=degree, tol=tol)
    b = F_g - a * gamma
    return Effective(gamma, F_g, a, b, float(m_g), float(g), residual, residual <= tol)


def from_rows(rows: list[dict], window: int = 3, degree: int = 1,
              g: float = 1.0) -> list[tuple[dict, Effective, list[dict]]]:
    """Group sweep rows by every parameter except gamma and seed, keep the steady points, and
    transform each group: [(group parameters, Effective, rows left out)]. Several seeds at one
    gamma must agree on F_g (within 1e-9 relative, the steady state does not depend on them,
    Sec. IV B); their mean is used, and a disagreement raises ValueError."""
    from .sweep import PARAMS, RUN_OPTIONS

    keys = [k for k in (*PARAMS, *RUN_OPTIONS) if k not in ("gamma", "seed")]
    groups: dict[str, tuple[dict, list[dict]]] = {}
    import json

    for row in rows:
        params = {k: row.get(k) for k in keys}
        groups.setdefault(json.dumps(params, sort_keys=True), (params, []))[1].append(row)
    out = []
    for params, members in groups.values():
        steady = [r for r in members if r.get("status") == "steady" and r.get("F_g") is not None]
        left_out = [r for r in members if r not in steady]
        by_gamma: dict[float, list[float]] = {}
        for r in steady:
            by_gamma.setdefault(float(r["gamma"]), []).append(float(r["F_g"]))
        if len(by_gamma) < 2:
            out.append((params, None, left_out))
            continue
        gam = np.array(sorted(by_gamma))
        F = []
        for gm in gam:
            vals = np.array(by_gamma[gm])
            if np.ptp(vals) > 1e-9 * max(np.abs(vals).max(), 1.0):
                raise ValueError(f"seeds disagree on the steady F_g at gamma = {gm:g}: "
                                 f"{vals.min():.12g} .. {vals.max():.12g}")
            F.append(vals.mean())
        m_g = float(steady[0]["m_g"])
        out.append((params, legendre(gam, np.array(F), m_g, g=g, window=window, degree=degree),
                    left_out))
    return out


__all__ = ["derivative", "legendre", "Effective", "from_rows"]
