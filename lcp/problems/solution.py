"""The one result type of every method (in the spirit of scipy's OptimizeResult)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

#: Statuses a method may return. Only "solved" carries a solution; the others carry evidence.
STATUSES = {
    "solved": "a complementary solution, checked: backward error and scaled residual <= "
    "lcp.residual.TOL, forward error bound <= lcp.accuracy.FERR_TOL",
    "ray": "Lemke ended on a secondary ray (no conclusion unless M is copositive-plus)",
    "infeasible": "the LCP has no solution (proved: a checked Farkas certificate in info)",
    "inaccurate": "the method's answer fails the acceptance test even after polishing on its "
    "basis (backward error > lcp.residual.TOL or forward error bound > lcp.accuracy.FERR_TOL); "
    "z is its best point, backward_error / forward_error / scaled_residual the evidence",
    "max_iter": "the iteration / pivot limit was reached",
    "not_converged": "an iterative method stopped above its tolerance",
    "failed": "the method failed (numerical breakdown); see message",
}


def complementarity_residual(z: np.ndarray, w: np.ndarray) -> float:
    """max |min(z, w)|: zero iff z >= 0, w >= 0 and z_i w_i = 0 for every i."""
    if z.size == 0:
        return 0.0
    return float(np.max(np.abs(np.minimum(z, w))))


@dataclass(slots=True)
class Solution:
    """Result of `lcp.solve`.

    z, w: the complementary pair (for an MLCP, z is v and u holds the free unknowns);
    status: one of STATUSES; iterations: pivots (pivoting methods) or sweeps (iterative);
    residual: max|min(z, w)| with w recomputed as M z + q (or D u + B v + b);
    eq_residual: max|A u + C v + a| for an MLCP (0 for an LCP);
    scaled_residual: the acceptance measure of lcp.residual (the larger of the complementarity
    and equality parts), set by `lcp.solve`: "solved" promises it is <= lcp.residual.TOL;
    backward_error, forward_error: lcp.accuracy's componentwise backward error and forward
    error bound (LAPACK's BERR / FERR) of a judged answer;
    basis: indices i with z_i basic (the active set), when the method defines one;
    info: evidence (the ray of Lemke, a cycle, ...), method-specific.

    Its fields are slots (no per-object __dict__): a small solve builds one per call, and a
    slotted object is built and freed in a fraction of the time (issue 23); the C fast path
    (lcp/_lemke_solution.h) writes the slots directly.
    """

    z: np.ndarray
    w: np.ndarray
    status: str
    method: str
    iterations: int = 0
    residual: float = np.inf
    eq_residual: float = 0.0
    scaled_residual: float = np.nan  # lcp.residual's measure (with the MLCP equality part)
    basis: np.ndarray | None = None
    u: np.ndarray | None = None
    message: str = ""
    info: dict[str, Any] = field(default_factory=dict)
    backward_error: float = np.nan  # lcp.accuracy (set by lcp.solve for a judged answer)
    forward_error: float = np.nan

    @property
    def success(self) -> bool:
        return self.status == "solved"

    @property
    def v(self) -> np.ndarray:
        """The complementarity unknowns of an MLCP (an alias of z)."""
        return self.z

    def __repr__(self) -> str:
        n = self.z.size
        fc = self.info.get("contact_states") if isinstance(self.info, dict) else None
        measure = ("relative natural-map residual" if isinstance(self.info, dict)
                   and "natural_residual" in self.info else
                   f"max|min(z, w)|; scaled {self.scaled_residual:.3e}")
        lines = [
            f"Solution(method={self.method!r}, status={self.status!r}, n={n})",
            f"  iterations : {self.iterations}",
            f"  residual   : {self.residual:.3e}  ({measure})",
        ]
        if np.isfinite(self.backward_error) or np.isfinite(self.forward_error):
            lines.append(f"  errors     : backward {self.backward_error:.3e}, forward bound "
                         f"{self.forward_error:.3e}")
        if self.u is not None:
            lines.append(f"  eq_residual: {self.eq_residual:.3e}  (max|A u + C v + a|)")
        if fc is not None:  # a friction answer: z is r, its basis is not over z
            closed = fc["sticking"] + fc["sliding"]
            lines.append(f"  contacts   : {closed} of {closed + fc['open']} closed "
                         f"({fc['sticking']} sticking, {fc['sliding']} sliding)")
        elif self.basis is not None and self.info.get("natural_residual") is None:
            lines.append(f"  active set : {int(np.size(self.basis))} of {n} z basic")
        if self.message:
            lines.append(f"  message    : {self.message}")
        if self.u is not None and self.u.size <= 8:  # an MLCP's free unknowns
            lines.append(f"  u = {np.array2string(self.u, precision=6)}")
        if n <= 8:
            lines.append(f"  z = {np.array2string(self.z, precision=6)}")
            lines.append(f"  w = {np.array2string(self.w, precision=6)}")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly view (arrays as lists)."""
        def conv(x):
            if isinstance(x, np.ndarray):
                return x.tolist()
            if isinstance(x, (np.floating, np.integer)):
                return x.item()
            if isinstance(x, dict):
                return {k: conv(v) for k, v in x.items()}
            return x

        out = {
            "method": self.method, "status": self.status, "iterations": self.iterations,
            "residual": self.residual, "eq_residual": self.eq_residual,
            "scaled_residual": self.scaled_residual,
            "message": self.message, "z": self.z, "w": self.w,
            "basis": self.basis, "u": self.u, "info": self.info,
            "backward_error": self.backward_error, "forward_error": self.forward_error,
        }
        return {k: conv(v) for k, v in out.items()}


_new = object.__new__


def solved_lcp(z: np.ndarray, w: np.ndarray, method: str, iterations: int, residual: float,
               scaled_residual: float, basis: np.ndarray | None, message: str,
               info: dict[str, Any], backward_error: float = np.nan,
               forward_error: float = np.nan) -> Solution:
    """``Solution(z=z, w=w, status="solved", method=method, iterations=iterations,
    residual=residual, eq_residual=0.0, scaled_residual=scaled_residual, basis=basis, u=None,
    message=message, info=info, backward_error=..., forward_error=...)``, its fields set
    directly, in the dataclass's order, without its generated __init__ (the fast paths of
    `lcp.solve` and `lcp.solve_many` build one per small problem).
    tests/lcp/test_fast_lemke.py checks that the objects agree, field for field."""
    sol = _new(Solution)
    sol.z = z
    sol.w = w
    sol.status = "solved"
    sol.method = method
    sol.iterations = iterations
    sol.residual = residual
    sol.eq_residual = 0.0
    sol.scaled_residual = scaled_residual
    sol.basis = basis
    sol.u = None
    sol.message = message
    sol.info = info
    sol.backward_error = backward_error
    sol.forward_error = forward_error
    return sol
