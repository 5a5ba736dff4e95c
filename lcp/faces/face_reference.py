"""The reference solvers of lcp.face (the code before issue 13): the face's linear program in
the original unknowns y_A by HiGHS's simplex, and its quadratic program by Clarabel (interior
point) with an active-set polish. face_minimum_norm(..., solvers="reference") and
global_minimum_norm use them; the default path solves the same programs in the face's own
coordinates (lcp.face_coords). Tests compare the two paths."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..quiet import new_highs


def _face_lp(M: np.ndarray, q: np.ndarray, A: np.ndarray, c: np.ndarray) -> np.ndarray | None:
    """A vertex minimizing c'y over the face with support A: y_A >= 0, (M y + q)_A = 0,
    (M y + q)_Ac >= 0, by HiGHS's simplex through its own API (scipy's linprog wrapper costs
    more than the solve on these small sparse LPs), tight tolerances; None if it fails."""
    import highspy

    if A.size == 0:
        return None
    Ac = np.setdiff1d(np.arange(q.size), A)
    K = sp.csc_matrix(np.vstack([M[np.ix_(A, A)], M[np.ix_(Ac, A)]]))
    inf = highspy.kHighsInf
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = A.size, K.shape[0]
    lp.col_cost_ = np.asarray(c[A], dtype=float)
    lp.col_lower_, lp.col_upper_ = np.zeros(A.size), np.full(A.size, inf)
    lp.row_lower_ = np.concatenate([-q[A], -q[Ac]])
    lp.row_upper_ = np.concatenate([-q[A], np.full(Ac.size, inf)])
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = K.indptr, K.indices, K.data
    h = new_highs()
    for key, value in (("presolve", "off"),
                       ("primal_feasibility_tolerance", 1e-10),
                       ("dual_feasibility_tolerance", 1e-10)):
        h.setOptionValue(key, value)
    h.passModel(lp)
    h.run()
    if h.getModelStatus() != highspy.HighsModelStatus.kOptimal:
        return None
    y = np.zeros(q.size)
    y[A] = np.maximum(np.asarray(h.getSolution().col_value), 0.0)
    return y


def _qp(P: np.ndarray, c: np.ndarray, Aineq: np.ndarray, bineq: np.ndarray,
        Aeq: np.ndarray | None = None, beq: np.ndarray | None = None):
    """min 1/2 x'Px + c'x s.t. Aeq x = beq, Aineq x <= bineq, by Clarabel (interior point)."""
    import clarabel

    n = c.size
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = 1e-12
    settings.tol_feas = 1e-12
    Pu = sp.triu(sp.csc_matrix((P + P.T) / 2), format="csc")
    if Aeq is None:
        Aeq, beq = np.zeros((0, n)), np.zeros(0)
    cones = [clarabel.NonnegativeConeT(bineq.size)]
    if beq.size:
        cones.insert(0, clarabel.ZeroConeT(beq.size))
    solver = clarabel.DefaultSolver(
        Pu, c, sp.csc_matrix(np.vstack([Aeq, Aineq])), np.concatenate([beq, bineq]), cones,
        settings,
    )
    sol = solver.solve()
    status = str(sol.status)
    if "Solved" not in status:
        return None, status
    return _polish(P, c, Aineq, bineq, Aeq, beq, np.array(sol.x).reshape(n)), status


def _polish(P, c, Aineq, bineq, Aeq, beq, x):
    """Re-solve the KKT system on the interior point's active constraints, exactly (to rounding),
    and keep the result if it is feasible and not worse: an interior-point answer is accurate
    to ~1e-9 only, which would show in event times."""
    scale = max(np.abs(bineq).max(initial=0.0), 1.0)
    slack = bineq - Aineq @ x
    act = np.flatnonzero(slack <= 1e-7 * scale)
    Aact = np.vstack([Aeq, Aineq[act]])
    n, k = x.size, Aact.shape[0]
    K = np.block([[P, Aact.T], [Aact, np.zeros((k, k))]])
    rhs = np.concatenate([-c, beq, bineq[act]])
    sol = np.linalg.lstsq(K, rhs, rcond=None)[0]
    y = sol[:n]
    if np.all(Aineq @ y <= bineq + 1e-12 * scale) and np.allclose(Aeq @ y, beq, atol=1e-12 * scale):
        f = 0.5 * y @ P @ y + c @ y
        if f <= 0.5 * x @ P @ x + c @ x + 1e-12 * max(abs(f), 1.0):
            return y
    return x
