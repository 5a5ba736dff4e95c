"""Every answer of `lcp.solve` is checked before it is returned; a method's answer is its own.

The run (called by `lcp.api.solve` with a validated problem):

1. the method runs on the Ruiz-equilibrated LCP (lcp.scaling) when equilibration is on (the
   default of lemke, pivoting and enumerate), and its z is mapped back to the user's units;
2. "solved" is judged by `judge`: polished on the method's final basis (or on the pattern of
   its z) with extended-precision refinement, then its backward error and forward error bound
   (lcp.accuracy) and the scaled residual of `lcp.residual.check` (the measure of
   verify.certify) are computed on the problem the user passed (an MLCP on its full system);
3. a "solved" that fails is rerun by the *same* method with the other equilibration setting
   (``info["repaired_by"]``); only when the caller asked for a fallback (``fallback=``) are
   other methods tried, and then the Solution names the method that produced it
   (``sol.method``; ``info["fallback_for"]`` keeps the first method's outcome). If nothing
   passes, the status is "inaccurate": z is the method's best point, with its errors;
4. "infeasible" is kept only with a Farkas certificate checked in exact rational arithmetic
   (lcp.farkas; a certificate that passes only the floating-point test bounds the size of
   feasible points but proves nothing, and is noted as such in the message); otherwise the
   status becomes "failed" (the claim could not be proved), or a fallback's answer is returned;
5. "ray", "max_iter" and "failed" are retried once with the other equilibration setting. Then,
   if the LP finds an exactly checked Farkas certificate, the status becomes "infeasible"
   (not for a method that raised: its status stays "failed", the exception in
   ``info["exception"]``) (``info["status_of_method"]`` keeps the method's own); else, with a
   fallback asked for and M copositive-plus (M + M^T PSD: solvable when feasible, Lemke's
   theorem), the fallbacks run.
"""

from __future__ import annotations

import traceback
from collections.abc import Callable

import numpy as np

from ..errors import RigidLCPError
from ..problems.problem import LCP, MLCP, InvalidProblem, NotApplicable
from ..problems.solution import Solution
from .accuracy import Accuracy, assess, assess_lcp
from .farkas import find_certificate, numerically_psd
from .residual import Check, check
from .scaling import Equilibration, ruiz

#: The fallback methods of ``fallback=True`` (tried equilibrated, in this order).
FALLBACKS = ("pivoting", "lemke")


def identity(M: np.ndarray, q: np.ndarray) -> Equilibration:
    n = q.size
    return Equilibration(M=M, q=q, r=np.ones(n), c=np.ones(n))


def call_method(func: Callable[..., Solution], name: str, /, *args, **options) -> Solution:
    """func(*args, **options): the method `name` on (M, q) or on a problem object. An
    exception it raises other than bad input or a refusal (RigidLCPError: InvalidProblem,
    NotApplicable) or MemoryError is a bug of the method: it comes back as status "failed",
    credited to it, the exception's type and message in the message and in
    ``info["exception"]`` (`failed_by`), never escapes; KeyboardInterrupt and SystemExit are
    no Exceptions and propagate."""
    try:
        return func(*args, **options)
    except (RigidLCPError, MemoryError):
        raise
    except Exception as exc:  # noqa: BLE001 - a method's bug is its failure
        return failed_by(name, exc, args)


def failed_by(name: str, exc: Exception, args: tuple) -> Solution:
    """Status "failed" for method `name` that raised `exc` when called on `args` ((M, q) or a
    problem object): z = 0 of the problem's size, the exception named in message and info."""
    q = args[1] if len(args) == 2 and isinstance(args[1], np.ndarray) else None
    n = q.size if q is not None else int(getattr(args[0], "n", 0)) if args else 0
    said = f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__
    frames = traceback.extract_tb(exc.__traceback__)
    where = f"{frames[-1].filename}:{frames[-1].lineno} in {frames[-1].name}" if frames else ""
    return Solution(z=np.zeros(n), w=q.copy() if q is not None else np.zeros(n),
                    status="failed", method=name,
                    message=f"the method raised {said}" + (f" ({where})" if where else ""),
                    info={"exception": "".join(traceback.format_exception_only(exc)),
                          "exception_type": type(exc).__name__, "raised_at": where})


def attempt(func: Callable[..., Solution], name: str, eq: Equilibration, options: dict
            ) -> Solution:
    """Run one method on the (equilibrated) data and map its answer back to the user's units.

    An exception other than bad input, a refusal or MemoryError (a bug of the method) comes
    back as status "failed" with the exception in ``info["exception"]`` (`call_method`)."""
    n = eq.q.size
    sol = call_method(func, name, eq.M, eq.q, **options)
    sol.method = name
    z = np.asarray(sol.z, dtype=float)
    if z.shape != (n,) or not np.all(np.isfinite(z)):
        if sol.status == "solved":  # elsewhere z is no claim (infeasible, ray: z may be None)
            sol.status = "failed"
            sol.message = ((sol.message + "; " if sol.message else "")
                           + ("the method's z is not finite" if z.shape == (n,) else
                              f"the method's z is missing or of shape {z.shape}, not ({n},)"))
        z = np.where(np.isfinite(z), z, 0.0) if z.shape == (n,) else np.zeros(n)
    sol.z = eq.z_back(z)
    for key in ("point",):
        if isinstance(sol.info.get(key), np.ndarray) and sol.info[key].shape == (n,):
            sol.info[key] = eq.z_back(sol.info[key])
    if isinstance(sol.info.get("farkas"), np.ndarray) and sol.info["farkas"].shape == (n,):
        y = sol.info["farkas"] * eq.r
        sol.info["farkas"] = y / max(float(y.sum()), 1e-300)
    return sol


class Run:
    """One call of `lcp.solve`: the problem, its LCP form, the checks, the fallbacks asked for."""

    def __init__(self, problem: LCP | MLCP, lcp: LCP, get_method: Callable, tol: float,
                 fallback: tuple[str, ...] = ()):
        self.problem, self.lcp, self.get_method, self.tol = problem, lcp, get_method, tol
        self.fallback = fallback
        self._eq: dict[bool, Equilibration] = {}
        self._K: tuple[np.ndarray, np.ndarray] | None = None

    def eq(self, on: bool) -> Equilibration:
        if on not in self._eq:
            M, q = self.lcp.M, self.lcp.q
            self._eq[on] = ruiz(M, q) if on else identity(M, q)
        return self._eq[on]

    def measure(self, z: np.ndarray, u: np.ndarray | None = None) -> Check:
        if u is None and isinstance(self.problem, MLCP):
            u = self.problem.recover_u(z)
        return check(self.problem, z, u, tol=self.tol,
                     lcp_form=self.lcp if isinstance(self.problem, MLCP) else None)

    #: None: polish on the method's basis when it gives one; False: a method's option
    #: polish=False (e.g. the QP methods' raw answer) is respected
    polish: bool | None = None

    def accuracy(self, z: np.ndarray, basis) -> Accuracy:
        if isinstance(self.problem, MLCP):
            p = self.problem
            if self._K is None:
                self._K = (np.block([[p.A, p.C], [p.D, p.B]]), np.concatenate([p.a, p.b]))
            u = p.recover_u(z) if np.all(np.isfinite(z)) else np.zeros(p.nu)
            return assess(*self._K, np.concatenate([u, z]), p.nu, basis, self.polish)
        return assess_lcp(self.lcp.M, self.lcp.q, z, basis, self.polish)

    def judge(self, sol: Solution) -> tuple[bool, Check, Accuracy]:
        """Polish sol on its basis and measure it (module doc, step 2); sol.z is updated.
        On an LCP this is lcp.accuracy.judge_lcp's verdict (the fast paths call that)."""
        acc = self.accuracy(np.asarray(sol.z, dtype=float), sol.basis)
        z = acc.v if acc.refined else np.asarray(sol.z, dtype=float)
        c = self.measure(z, acc.u if (acc.refined and isinstance(self.problem, MLCP)) else None)
        sol.z = z
        return bool(c.accepted and acc.accepted), c, acc

    def run(self, name: str, equilibrate: bool, options: dict) -> Solution:
        info = self.get_method(name)
        return attempt(info.func, name, self.eq(equilibrate), options)

    def first_fallback(self, name: str) -> tuple[Solution, Check, Accuracy] | None:
        """The first fallback method (other than `name`) whose answer is accepted."""
        for other in self.fallback:
            if other == name:
                continue
            try:
                sol = self.run(other, True, {})
            except (InvalidProblem, NotApplicable):
                continue
            sol.info["equilibrated"] = True
            if sol.status != "solved":
                continue
            ok, c, acc = self.judge(sol)
            if ok:
                return sol, c, acc
        return None


def finish(sol: Solution, c: Check, acc: Accuracy | None = None) -> Solution:
    """Store the check's numbers (on the user's problem) in the solution."""
    sol.w, sol.residual = c.w, c.residual
    sol.eq_residual = c.eq_residual
    sol.u = c.u
    sol.scaled_residual = max(c.scaled_residual, c.scaled_eq_residual)
    if acc is not None:
        sol.backward_error, sol.forward_error = acc.berr, acc.ferr
        if acc.refined:
            sol.info["polished"] = True
    return sol


def _note(sol: Solution, text: str) -> None:
    sol.message = ((sol.message + "; ") if sol.message else "") + text


def _errors(c: Check, acc: Accuracy) -> str:
    return (f"backward error {acc.berr:.3g}, forward error bound {acc.ferr:.3g}, scaled "
            f"residual {max(c.scaled_residual, c.scaled_eq_residual):.3g}")


def solve_checked(run: Run, name: str, equilibrate: bool, repair: bool, options: dict
                  ) -> Solution:
    """Steps 1-5 of the module docstring."""
    if options.get("polish") is False:
        run.polish = False
    sol = run.run(name, equilibrate, options)
    sol.info["equilibrated"] = equilibrate
    if sol.status == "solved":
        ok, c, acc = run.judge(sol)
        if ok:
            return finish(sol, c, acc)
        best = (sol, c, acc)
        if repair:
            alt = _retry_other_scaling(run, sol, name, equilibrate, options)
            if alt is not None and alt.status == "solved":
                return alt
        got = run.first_fallback(name)
        if got is not None:
            return _adopt(sol, got, f"{name}'s answer failed the acceptance test "
                          f"({_errors(c, acc)})")
        sol, c, acc = best
        sol.status = "inaccurate"
        _note(sol, f"the answer fails the acceptance test: {_errors(c, acc)} (limits "
              f"{run.tol:g} and lcp.accuracy.FERR_TOL), after polishing on its basis")
        return finish(sol, c, acc)
    c = run.measure(sol.z)
    if "copositive_plus" in sol.info:  # a method's test on its (equilibrated) data: redo it
        sol.info["copositive_plus"] = numerically_psd(run.lcp.M + run.lcp.M.T)
    if sol.status == "infeasible":
        cert = find_certificate(run.eq(True), sol.info.get("farkas"))
        if cert is not None and cert.exact:
            sol.info.update(cert.as_info())
            return finish(sol, c)
        got = run.first_fallback(name)
        if got is not None:
            return _adopt(sol, got, f"{name} had claimed 'infeasible' without a valid "
                          "certificate")
        sol.status = "failed"
        sol.info["status_of_method"] = "infeasible"
        sol.message = (f"the method claimed infeasibility ({sol.message or 'no reason given'}), "
                       "but no Farkas certificate (y >= 0, M^T y <= 0, q^T y < 0) passes the "
                       "exact check (lcp.farkas): infeasibility is not proved")
        _note_float_certificate(sol, cert)
        return finish(sol, c)
    if sol.status in ("ray", "max_iter", "failed"):
        if repair:
            alt = _retry_other_scaling(run, sol, name, equilibrate, options)
            if alt is not None:
                return alt
        cert = find_certificate(run.eq(True), sol.info.get("farkas"))
        if cert is None and run.fallback and numerically_psd(run.lcp.M + run.lcp.M.T):
            # M copositive-plus and no certificate: by Lemke's theorem (Cottle-Pang-Stone
            # 4.4.13) a feasible LCP of this kind has a solution: the fallbacks may find it.
            got = run.first_fallback(name)
            if got is not None:
                return _adopt(sol, got, f"{name} had ended with status {sol.status!r} on a "
                              "copositive-plus M with no certificate of infeasibility")
        if cert is not None and cert.exact and "exception" not in sol.info:
            sol.info.update(cert.as_info())  # (a crash stays the method's failure: bench, fuzz)
            sol.info["status_of_method"] = sol.status
            sol.status = "infeasible"
            _note(sol, f"the LCP is infeasible: a Farkas certificate y (info['farkas']) was "
                  f"found by LP and checked ({cert.how})")
        else:
            _note_float_certificate(sol, cert)
    return finish(sol, c)


def _note_float_certificate(sol: Solution, cert) -> None:
    """A certificate that passes only the floating-point test bounds every feasible point's
    size (no feasible z~ with |z~|_1 < its radius) but proves no infeasibility: the data may
    have a solution beyond it (a P-matrix singular to working precision does). Said, and kept
    in info as evidence, never turned into the status "infeasible"."""
    if cert is None or cert.exact:
        return
    sol.info.update(cert.as_info())
    _note(sol, f"no feasible point within |z~|_1 < {cert.radius:.3g} (equilibrated units; a "
          "floating-point Farkas certificate, info['farkas']): infeasibility is not proved, "
          "a solution beyond that size is not excluded")


def _retry_other_scaling(run: Run, first: Solution, name: str, equilibrate: bool,
                         options: dict) -> Solution | None:
    """The same method with the other equilibration setting (still its own answer), kept if
    it solves (judged) or proves infeasibility (certificate checked)."""
    try:
        sol = run.run(name, not equilibrate, options)
    except (InvalidProblem, NotApplicable):
        return None
    how = f"{name} ({'equilibrated' if not equilibrate else 'unscaled data'})"
    if sol.status == "solved":
        ok, c, acc = run.judge(sol)
        if not ok:
            return None
    elif sol.status == "infeasible":
        cert = find_certificate(run.eq(True), sol.info.get("farkas"))
        if cert is None or not cert.exact:
            return None
        sol.info.update(cert.as_info())
        c, acc = run.measure(sol.z), None
    else:
        return None
    sol.info["repaired_by"] = how
    sol.info["equilibrated"] = not equilibrate
    sol.info["first_attempt"] = {"status": first.status, "message": first.message}
    _note(sol, f"answer of {how}: the first run had ended with status {first.status!r}")
    return finish(sol, c, acc)


def _adopt(first: Solution, got: tuple[Solution, Check, Accuracy], why: str) -> Solution:
    """A fallback's answer, named as its own (sol.method) and saying whom it replaces."""
    sol, c, acc = got
    sol.info["fallback_for"] = {"method": first.method, "status": first.status,
                                "message": first.message}
    _note(sol, f"answer of the fallback {sol.method!r}: {why}")
    return finish(sol, c, acc)
