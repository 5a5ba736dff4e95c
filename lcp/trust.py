"""Every answer of `lcp.solve` is checked before it is returned, and repaired when it can be.

The run (called by `lcp.api.solve` with a validated problem):

1. the method runs on the Ruiz-equilibrated LCP (lcp.scaling) when equilibration is on (the
   default of lemke, pivoting and enumerate), and its z is mapped back to the user's units;
2. "solved" is checked with `lcp.residual.check` on the problem the user passed (for an MLCP,
   with its equality residual): the same measure and tolerance as `verify.certify`;
3. a "solved" that fails is repaired, in order: z recomputed on the method's final basis with a
   fresh LU factorization and one step of iterative refinement; the method again with the
   other equilibration setting; `pivoting`, then `lemke` (equilibrated). The first answer that
   passes is returned (``info["repaired_by"]`` says how); if none does, the status is
   "inaccurate" and z is the best point found, with its scaled residual as the evidence;
4. "infeasible" is kept only with a checked Farkas certificate (lcp.farkas), found by HiGHS on
   the equilibrated problem; otherwise the same alternatives as in 3 are tried, and if none
   solves the problem the status becomes "failed" (the claim could not be proved);
5. "ray", "max_iter" and "failed" are retried once with the other equilibration setting; a
   solution found that way (and checked) is returned. Otherwise, if the LP finds a Farkas
   certificate the status becomes "infeasible"; if it finds none and M is copositive-plus
   (M + M^T PSD), the LCP has a solution (Lemke's theorem) and the fall-back methods of 3 are
   tried; else the method's status stays.
"""

from __future__ import annotations

import traceback
from collections.abc import Callable

import numpy as np

from .farkas import find_certificate, numerically_psd
from .problem import LCP, MLCP, InvalidProblem, NotApplicable
from .residual import Check, check
from .scaling import Equilibration, ruiz
from .solution import Solution

#: Methods tried, equilibrated, when an answer cannot be trusted (for any M).
FALLBACKS = ("pivoting", "lemke")


def identity(M: np.ndarray, q: np.ndarray) -> Equilibration:
    n = q.size
    return Equilibration(M=M, q=q, r=np.ones(n), c=np.ones(n))


def attempt(func: Callable[..., Solution], name: str, eq: Equilibration, options: dict
            ) -> Solution:
    """Run one method on the (equilibrated) data and map its answer back to the user's units.

    An exception other than bad input or a refusal is a bug of the method; it is reported as
    status "failed" with the exception in ``info["exception"]`` instead of escaping."""
    n = eq.q.size
    try:
        sol = func(eq.M, eq.q, **options)
    except (InvalidProblem, NotApplicable):
        raise
    except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
        return Solution(z=np.zeros(n), w=eq.q.copy(), status="failed", method=name,
                        message=f"the method raised {type(exc).__name__}: {exc}",
                        info={"exception": "".join(traceback.format_exception_only(exc))})
    sol.method = name
    z = np.asarray(sol.z, dtype=float)
    if z.shape != (n,) or not np.all(np.isfinite(z)):
        if sol.status == "solved":
            sol.status = "failed"
        sol.message = (sol.message + "; " if sol.message else "") + "method returned a bad z"
        z = np.where(np.isfinite(z), z, 0.0) if z.shape == (n,) else np.zeros(n)
    sol.z = eq.z_back(z)
    for key in ("point",):
        if isinstance(sol.info.get(key), np.ndarray) and sol.info[key].shape == (n,):
            sol.info[key] = eq.z_back(sol.info[key])
    if isinstance(sol.info.get("farkas"), np.ndarray) and sol.info["farkas"].shape == (n,):
        y = sol.info["farkas"] * eq.r
        sol.info["farkas"] = y / max(float(y.sum()), 1e-300)
    return sol


def refactorize(eq: Equilibration, basis) -> np.ndarray | None:
    """z on the complementary basis alpha (z_b = 0, M_aa z_a = -q_a) from a fresh LU of the
    equilibrated M~_aa with one step of iterative refinement, in the user's units."""
    if basis is None:
        return None
    from scipy.linalg import lu_factor, lu_solve  # loaded on first use (cheap import)

    a = np.unique(np.asarray(basis, dtype=np.intp).reshape(-1))
    n = eq.q.size
    if a.size and (a.min() < 0 or a.max() >= n):
        return None
    zt = np.zeros(n)
    if a.size:
        Maa, qa = eq.M[np.ix_(a, a)], eq.q[a]
        try:
            lu = lu_factor(Maa, check_finite=True)
        except (np.linalg.LinAlgError, ValueError):
            return None
        za = -lu_solve(lu, qa)
        za -= lu_solve(lu, Maa @ za + qa)
        if not np.all(np.isfinite(za)):
            return None
        zt[a] = np.maximum(za, 0.0)
    return eq.z_back(zt)


class Run:
    """One call of `lcp.solve`: the problem, its LCP form, and the checks."""

    def __init__(self, problem: LCP | MLCP, lcp: LCP, get_method: Callable, tol: float):
        self.problem, self.lcp, self.get_method, self.tol = problem, lcp, get_method, tol
        self._eq: dict[bool, Equilibration] = {}
        self.best: tuple[float, np.ndarray, Check] | None = None

    def eq(self, on: bool) -> Equilibration:
        if on not in self._eq:
            M, q = self.lcp.M, self.lcp.q
            self._eq[on] = ruiz(M, q) if on else identity(M, q)
        return self._eq[on]

    def measure(self, z: np.ndarray) -> Check:
        u = self.problem.recover_u(z) if isinstance(self.problem, MLCP) else None
        c = check(self.problem, z, u, tol=self.tol,
                  lcp_form=self.lcp if isinstance(self.problem, MLCP) else None)
        worst = max(c.scaled_residual, c.scaled_eq_residual)
        if np.isfinite(worst) and (self.best is None or worst < self.best[0]):
            self.best = (worst, z, c)
        return c

    def run(self, name: str, equilibrate: bool, options: dict) -> Solution:
        info = self.get_method(name)
        return attempt(info.func, name, self.eq(equilibrate), options)

    def alternatives(self, name: str, equilibrate: bool):
        """(method, equilibrate) pairs to try after (name, equilibrate) gave no trusted answer."""
        seen = {(name, equilibrate)}
        yield name, not equilibrate
        seen.add((name, not equilibrate))
        for other in FALLBACKS:
            if (other, True) not in seen:
                seen.add((other, True))
                yield other, True

    def first_accepted(self, name: str, equilibrate: bool, options: dict, same_only: bool
                       ) -> tuple[Solution, Check, str] | None:
        for other, eq_on in self.alternatives(name, equilibrate):
            if same_only and other != name:
                break
            try:
                sol = self.run(other, eq_on, options if other == name else {})
            except (InvalidProblem, NotApplicable):
                continue
            if sol.status != "solved":
                continue
            c = self.measure(sol.z)
            if not c.accepted:
                z = refactorize(self.eq(eq_on), sol.basis)
                if z is None:
                    continue
                c = self.measure(z)
                if not c.accepted:
                    continue
                sol.z = z
            how = f"{other} ({'equilibrated' if eq_on else 'unscaled data'})"
            return sol, c, how
        return None


def finish(sol: Solution, c: Check) -> Solution:
    """Store the check's numbers (on the user's problem) in the solution."""
    sol.w, sol.residual = c.w, c.residual
    sol.eq_residual = c.eq_residual
    sol.u = c.u
    sol.scaled_residual = max(c.scaled_residual, c.scaled_eq_residual)
    return sol


def solve_checked(run: Run, name: str, equilibrate: bool, repair: bool, options: dict
                  ) -> Solution:
    """Steps 1-5 of the module docstring."""
    sol = run.run(name, equilibrate, options)
    sol.info["equilibrated"] = equilibrate
    c = run.measure(sol.z)
    if sol.status == "solved":
        if c.accepted:
            return finish(sol, c)
        first = c
        z = refactorize(run.eq(equilibrate), sol.basis)
        if z is not None:
            c2 = run.measure(z)
            if c2.accepted:
                sol.z = z
                sol.info["repaired_by"] = "basis refactorized (fresh LU + refinement)"
                return finish(sol, c2)
        got = run.first_accepted(name, equilibrate, options, same_only=False) if repair else None
        if got is not None:
            return _adopt(sol, got, f"the answer had scaled residual {first.scaled_residual:.3g}")
        best_z, best_c = (run.best[1], run.best[2]) if run.best else (sol.z, first)
        sol.status = "inaccurate"
        sol.z = best_z
        sol.message = ((sol.message + "; ") if sol.message else "") + (
            f"the answer fails the acceptance test: scaled residual "
            f"{max(best_c.scaled_residual, best_c.scaled_eq_residual):.3g} > {run.tol:g} "
            "(lcp.residual), and no repair passed it")
        return finish(sol, best_c)
    if "copositive_plus" in sol.info:  # a method's test on its (equilibrated) data: redo it
        sol.info["copositive_plus"] = numerically_psd(run.lcp.M + run.lcp.M.T)
    if sol.status == "infeasible":
        cert = find_certificate(run.eq(True), sol.info.get("farkas"))
        if cert is not None:
            sol.info.update(cert.as_info())
            return finish(sol, c)
        got = (run.first_accepted(name, equilibrate, options, same_only=False) if repair
               else None)
        if got is not None:
            return _adopt(sol, got, "it had claimed 'infeasible' without a valid certificate")
        sol.status = "failed"
        sol.info["status_of_method"] = "infeasible"
        sol.message = (f"the method claimed infeasibility ({sol.message or 'no reason given'}), "
                       "but no Farkas certificate (y >= 0, M^T y <= 0, q^T y < 0) passes the "
                       "check (lcp.farkas): infeasibility is not proved, and no other method "
                       "solved the problem")
        return finish(sol, c)
    if sol.status in ("ray", "max_iter", "failed"):
        if repair:
            alt = _retry_other_scaling(run, sol, name, equilibrate, options)
            if alt is not None:
                return alt
        cert = find_certificate(run.eq(True), sol.info.get("farkas"))
        if cert is None and repair and numerically_psd(run.lcp.M + run.lcp.M.T):
            # M copositive-plus and no certificate: by Lemke's theorem (Cottle-Pang-Stone
            # 4.4.13) a feasible LCP of this kind has a solution, so the method's stop is
            # numerical trouble: let the other methods find it.
            got = run.first_accepted(name, equilibrate, options, same_only=False)
            if got is not None:
                return _adopt(sol, got, f"it had ended with status {sol.status!r} on a "
                              "copositive-plus M with no certificate of infeasibility")
        if cert is not None:
            sol.info.update(cert.as_info())
            sol.info["status_of_method"] = sol.status
            sol.status = "infeasible"
            sol.message = ((sol.message + "; ") if sol.message else "") + (
                f"the LCP is infeasible: a Farkas certificate y (info['farkas']) was found by LP "
                f"and checked (gap {cert.gap:.3g}, no feasible point within radius "
                f"{cert.radius:.3g})")
    return finish(sol, c)


def _retry_other_scaling(run: Run, first: Solution, name: str, equilibrate: bool,
                         options: dict) -> Solution | None:
    """The same method with the other equilibration setting, kept if it solves (checked) or
    proves infeasibility (certificate checked)."""
    try:
        sol = run.run(name, not equilibrate, options)
    except (InvalidProblem, NotApplicable):
        return None
    how = f"{name} ({'equilibrated' if not equilibrate else 'unscaled data'})"
    if sol.status == "solved":
        c = run.measure(sol.z)
        if not c.accepted:
            z = refactorize(run.eq(not equilibrate), sol.basis)
            c = run.measure(z) if z is not None else c
            if not c.accepted:
                return None
            sol.z = z
        return _adopt(first, (sol, c, how), f"it had ended with status {first.status!r}")
    if sol.status == "infeasible":
        cert = find_certificate(run.eq(True), sol.info.get("farkas"))
        if cert is None:
            return None
        sol.info.update(cert.as_info())
        return _adopt(first, (sol, run.measure(sol.z), how),
                      f"it had ended with status {first.status!r}")
    return None


def _adopt(first: Solution, got: tuple[Solution, Check, str], why: str) -> Solution:
    sol, c, how = got
    sol.method = first.method
    sol.info["repaired_by"] = how
    sol.info["first_attempt"] = {"status": first.status, "message": first.message}
    sol.info["equilibrated"] = first.info.get("equilibrated")
    if "copositive_plus" in first.info:
        sol.info["copositive_plus"] = first.info["copositive_plus"]
    sol.message = ((sol.message + "; ") if sol.message else "") + f"answer by {how}: {why}"
    return finish(sol, c)
