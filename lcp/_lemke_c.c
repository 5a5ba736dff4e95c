/* The pivot loop of Lemke's method (lcp/lemke.py) in C: the ratio test with the lexicographic
 * tie-break and the rank-one update of the dictionary, exactly as `_Lemke.run` does them in
 * numpy (same rules, same order of floating-point operations up to BLAS's choice of fused
 * multiply-adds), so that both take the same pivots. Built by setuptools as an optional
 * extension (setup.py); lcp/_lemke_kernel.py falls back to the numpy loop when it is missing.
 *
 * Layout (docs/lemke.md, "The dictionary"): T is the n x (n + 2) dictionary, column-major, slots
 * 0..n hold the nonbasic columns and slot n + 1 holds beta. Variables: w_i = i, z_i = n + i,
 * z0 = 2n. basic[row] -> variable, nonbasic[slot] -> variable, row_of[var] -> row or -1,
 * slot_of[var] -> slot or -1 (int64 arrays, updated in place).
 *
 * run(T, basic, nonbasic, row_of, slot_of, tol, max_iter, trace) -> (code, pivots, s, entering)
 *   code 0: z0 left (a solution); 1: a basis repeated (numerical cycling); 2: max_iter pivots;
 *   3: secondary ray (slot s of the unblocked entering variable). trace: None or an int64
 *   buffer of length 2 k; the (row, slot) of the first k pivots are written there.
 *
 * Also, for lcp.solve's fast path (lcp/fast_lemke.py) and lcp.solve_many: solve_eq / solve_batch
 * run a whole LCP from the user's data -- the equilibration of lcp/scaling.py for a balanced M
 * (or with the factors of `ruiz` given), the dictionary, the pivots, z in the user's units --
 * and lcp_measure / lcp_measure_batch compute lcp/residual.py's acceptance measure after
 * numpy's M z, with numpy's roundings (the same numbers; see the comments there).
 *
 * Only the buffer protocol is used (no numpy headers), so the build needs a C compiler only.
 *
 * One job per file; this one holds the entry points of whole problems (solve_eq, solve_accept,
 * solve_batch, solve_fast) and the module table, and includes, in this order:
 *   acceptance/_accuracy_core.h  the acceptance steps of assess_lcp (shared with _accuracy_c.c)
 *   _lemke_run.h      the Lemke state and the pivoting run on one dictionary (its updates,
 *                     eager or lazy, in _lemke_update.h)
 *   _numpy_abi.h      new arrays by numpy's PyArray_NewFromDescr, found at run time
 *                     (array_setup, array_probe, new_array_of)
 *   _lemke_py.h       the buffer checks and the entry points run, setup, check, plain
 *   _blas.h           numpy's cblas_dgemv, called directly for M z (gemv_setup, gemv)
 *   _lemke_problem.h  one whole problem without the GIL: equilibration (_balanced.h), the
 *                     scaled dictionary (+ AVX2 pass over M), solve_problem, the work array,
 *                     the acceptance of the answer
 *   _lemke_measure.h  the acceptance measure: abs_row_sums, lcp_measure, lcp_measure_batch
 *   _lemke_solution.h solve_lcp: solve_fast's work, the verdict and the Solution in one call;
 *                     solve_default: lcp.solve's default call, from the problem object
 *   _solve_entry.h    Entry: lcp.solve as an object whose default call goes to api._FAST
 *   _batch_solutions.h batch_solutions, stack_lcps: lcp.solve_many's stacks, verdicts and
 *                     Solutions
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef Py_ssize_t idx;

#include "acceptance/_accuracy_core.h" /* assess_one: the acceptance of solve_accept */
#include "_lemke_run.h"
#include "_numpy_abi.h" /* new_array_of: numpy's PyArray_NewFromDescr, found at run time */
#include "_lemke_py.h"
#include "_blas.h" /* gemv_setup, gemv: numpy's own cblas_dgemv for M z */
#include "_lemke_problem.h"
#include "_lemke_measure.h"
#include "_lemke_solution.h" /* solve_setup, solve_lcp: solve_fast and its Solution */
#include "_solve_entry.h"     /* Entry: lcp.solve's default call straight to C */
#include "_batch_solutions.h" /* batch_solutions: lcp.solve_many's Solutions */

/* solve_eq(M, q, r, c, d, tol, max_iter, z, basis) -> (code, pivots, nbasis, bounds): one LCP
 * as lcp.solve gives it to lemke() by default, on its equilibrated data: r = c = None for the
 * balanced case done here (code NEEDS_RUIZ when M is not balanced), or the factors of `ruiz`;
 * d None for ones. M n x n C-contiguous, q, r, c, d, z float64 of length n; basis int64 of
 * length n receives the sorted indices of the basic z's (the first nbasis entries). bounds =
 * (max|M|, max|q|, max|z|) of the data given and the answer (when code 0). */
static PyObject *py_solve_eq(PyObject *self, PyObject *args)
{
    PyObject *oM, *oq, *or_, *oc, *od, *oz, *ob;
    double tol;
    long long max_iter;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOdLOO", &oM, &oq, &or_, &oc, &od, &tol, &max_iter, &oz,
                          &ob))
        return NULL;
    idx n = PyObject_Length(oq);
    if (n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "q: empty");
        return NULL;
    }
    if ((or_ == Py_None) != (oc == Py_None)) {
        PyErr_SetString(PyExc_ValueError, "r and c: both None or both given");
        return NULL;
    }
    Py_buffer vM = {0}, vq = {0}, vr = {0}, vc = {0}, vd = {0}, vz = {0}, vb = {0};
    const double *r, *c, *d;
    PyObject *result = NULL;
    if (get_buffer(oq, &vq, "q", 'd', n, 0) < 0) return NULL;
    if (get_buffer(oM, &vM, "M", 'd', n * n, 0) < 0) goto done;
    if (opt_vector(or_, &vr, "r", n, &r) < 0 || opt_vector(oc, &vc, "c", n, &c) < 0 ||
        opt_vector(od, &vd, "d", n, &d) < 0)
        goto done;
    if (get_buffer(oz, &vz, "z", 'd', n, 0) < 0) goto done;
    if (get_buffer(ob, &vb, "basis", 'q', n, 0) < 0) goto done;
    Work w;
    uint64_t stack[STACK_WORDS] STACK_ALIGNED;
    if (work_init(&w, n, tol, stack) < 0) {
        PyErr_NoMemory();
        goto done;
    }
    long long pivots = 0;
    double bound[3] = {0.0, 0.0, 0.0};
    int code;
    Py_BEGIN_ALLOW_THREADS
    code = solve_problem(&w.L, w.T, (const double *)vM.buf, (const double *)vq.buf, d, r, c,
                         r ? 2 : 1, max_iter, (double *)vz.buf, w.bz, &pivots, bound);
    Py_END_ALLOW_THREADS
    idx nb = 0;
    int64_t *basis = (int64_t *)vb.buf;
    for (idx j = 0; j < n; j++)
        if (w.bz[j]) basis[nb++] = j;
    work_free(&w);
    if (code < 0)
        PyErr_NoMemory();
    else
        result = Py_BuildValue("iLn(ddd)", code, pivots, nb, bound[0], bound[1], bound[2]);
done:
    release(&vb);
    release(&vz);
    release(&vd);
    release(&vc);
    release(&vr);
    release(&vM);
    release(&vq);
    return result;
}

/* solve_accept(M, q, tol, max_iter, z, basis) -> (code, pivots, nbasis, acode, berr, ferr,
 * refined): `solve_eq` with r = c = d = None (lcp.solve's default Lemke) and, on code 0, the
 * acceptance steps of lcp/acceptance/accuracy.py's `assess_lcp` on the answer and its basis
 * (`accept_one`: acode 0 = assessed, z the answer, polished when refined; 1 = not handled
 * here, z the solver's; -1 = numbers too large for the fast check). One crossing from Python
 * for the solve and its acceptance (lcp/solvers/fast_lemke.py); the same numbers as the two
 * calls. */
static PyObject *py_solve_accept(PyObject *self, PyObject *args)
{
    PyObject *oM, *oq, *oz, *ob;
    double tol;
    long long max_iter;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOdLOO", &oM, &oq, &tol, &max_iter, &oz, &ob)) return NULL;
    Py_buffer vM = {0}, vq = {0}, vz = {0}, vb = {0};
    PyObject *result = NULL;
    idx n = problem_data(oM, oq, &vM, &vq);
    if (n < 0) goto done;
    if (get_buffer(oz, &vz, "z", 'd', n, 0) < 0) goto done;
    if (get_buffer(ob, &vb, "basis", 'q', n, 0) < 0) goto done;
    long long pivots = 0;
    double res[3];
    idx nb = 0;
    int code, acode = 1;
    Py_BEGIN_ALLOW_THREADS
    code = solve_and_accept(n, (const double *)vM.buf, (const double *)vq.buf, tol, max_iter,
                            (double *)vz.buf, (int64_t *)vb.buf, &pivots, &nb, &acode, res,
                            NULL);
    Py_END_ALLOW_THREADS
    if (code < 0)
        PyErr_NoMemory();
    else
        result = Py_BuildValue("iLniddi", code, pivots, nb, acode, res[0], res[1], (int)res[2]);
done:
    release(&vb);
    release(&vz);
    release(&vM);
    release(&vq);
    return result;
}

/* solve_batch(Ms, qs, d, tol, max_iter, Z, basic_z, codes, pivots, mode): k problems of size n
 * (Ms: k n n C-contiguous, qs: k n; finite) by the steps of lemke() (q >= 0: z = 0 and no
 * pivot; else setup + run), on the data as given (mode 0) or equilibrated here when balanced
 * (mode 1, as `solve_eq` with r = c = None: code NEEDS_RUIZ for the others). Writes z (k n,
 * the original units), basic_z (k n int8: z_j basic), codes and pivots (int64, k). Only code 0
 * (solved) leaves a usable z: the caller solves the others again one by one. acc (optional,
 * k x 4 float64): each solved answer is also assessed as `solve_accept` does (`accept_one`),
 * acc[p] = (acode, berr, ferr, refined) and Z[p] the answer (polished when refined). mmax
 * (optional, k float64): max|M_p| where solved (code 0: M_p finite), else -1 -- for
 * lcp_measure_batch, which then need not measure it again. */
static PyObject *py_solve_batch(PyObject *self, PyObject *args)
{
    PyObject *oM, *oq, *od, *oZ, *oB, *oc, *op, *oacc = Py_None, *omx = Py_None;
    double tol;
    long long max_iter;
    int mode = 0;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOdLOOOO|iOO", &oM, &oq, &od, &tol, &max_iter, &oZ, &oB, &oc,
                          &op, &mode, &oacc, &omx))
        return NULL;
    if (mode != 0 && mode != 1) {
        PyErr_SetString(PyExc_ValueError, "mode: 0 or 1");
        return NULL;
    }
    Py_buffer vd, vc, vp, vM, vq, vZ, vB, va = {0};
    idx n = PyObject_Length(od), k = PyObject_Length(oc);
    if (n < 1 || k < 0) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "d: empty");
        return NULL;
    }
    if (get_buffer(od, &vd, "d", 'd', n, 0) < 0) return NULL;
    if (get_buffer(oc, &vc, "codes", 'q', k, 0) < 0) goto b1;
    if (get_buffer(op, &vp, "pivots", 'q', k, 0) < 0) goto b2;
    if (get_buffer(oM, &vM, "Ms", 'd', k * n * n, 0) < 0) goto b3;
    if (get_buffer(oq, &vq, "qs", 'd', k * n, 0) < 0) goto b4;
    if (get_buffer(oZ, &vZ, "Z", 'd', k * n, 0) < 0) goto b5;
    if (PyObject_GetBuffer(oB, &vB, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS) < 0) goto b6;
    if (vB.len != k * n || vB.itemsize != 1) {
        PyErr_SetString(PyExc_ValueError, "basic_z: expected k n int8 values");
        goto b7;
    }
    if (oacc != Py_None && get_buffer(oacc, &va, "acc", 'd', 4 * k, 0) < 0) goto b7;
    Py_buffer vx = {0};
    if (omx != Py_None && get_buffer(omx, &vx, "mmax", 'd', k, 0) < 0) {
        release(&va);
        goto b7;
    }
    double *acc = (double *)va.buf, *zs = NULL, *mx = (double *)vx.buf;
    int64_t *ab = NULL;
    Work w;
    int failed = work_init(&w, n, tol, NULL) < 0;
    if (!failed && acc) {
        zs = (double *)malloc((size_t)n * (sizeof(double) + sizeof(int64_t)));
        ab = (int64_t *)(zs + n);
        if (!zs) {
            work_free(&w);
            failed = 1;
        }
    }
    if (!failed) {
        const double *Ms = (const double *)vM.buf, *qs = (const double *)vq.buf,
                     *d = (const double *)vd.buf;
        double *Z = (double *)vZ.buf;
        int8_t *B = (int8_t *)vB.buf;
        int64_t *codes = (int64_t *)vc.buf, *piv = (int64_t *)vp.buf;
        Py_BEGIN_ALLOW_THREADS
        for (idx p = 0; p < k; p++) {
            long long pivots = 0;
            double bound[3];
            const double *Mp = Ms + p * n * n, *qp = qs + p * n;
            int code = solve_problem(&w.L, w.T, Mp, qp, d, NULL, NULL, mode, max_iter,
                                     acc ? zs : Z + p * n, B + p * n, &pivots, bound);
            if (code < 0) {
                failed = 1;
                break;
            }
            if (acc) {
                double res[3] = {0.0, 0.0, 0.0};
                idx nb;
                acc[4 * p] = code ? 1.0 : (double)accept_one(n, Mp, qp, zs, B + p * n, bound,
                                                               ab, &nb, Z + p * n, res);
                if (code) memcpy(Z + p * n, zs, (size_t)n * sizeof(double));
                acc[4 * p + 1] = res[0], acc[4 * p + 2] = res[1], acc[4 * p + 3] = res[2];
            }
            if (mx) mx[p] = code == 0 ? bound[0] : -1.0; /* max|M|, M finite (fill_*) */
            codes[p] = code;
            piv[p] = pivots;
        }
        Py_END_ALLOW_THREADS
        free(zs);
        work_free(&w);
    }
    release(&vx);
    release(&va);
    PyBuffer_Release(&vB);
    PyBuffer_Release(&vZ);
    PyBuffer_Release(&vq);
    PyBuffer_Release(&vM);
    PyBuffer_Release(&vp);
    PyBuffer_Release(&vc);
    PyBuffer_Release(&vd);
    if (failed) return PyErr_NoMemory();
    Py_RETURN_NONE;
b7:
    PyBuffer_Release(&vB);
b6:
    PyBuffer_Release(&vZ);
b5:
    PyBuffer_Release(&vq);
b4:
    PyBuffer_Release(&vM);
b3:
    PyBuffer_Release(&vp);
b2:
    PyBuffer_Release(&vc);
b1:
    PyBuffer_Release(&vd);
    return NULL;
}
/* solve_fast(M, q, tol, max_iter, z, w, basis, dot, upto) -> (code, pivots, nbasis, acode,
 * berr, ferr, refined, raw, scaled): lcp.solve's common call in one crossing from Python
 * (lcp/solvers/fast_lemke.py): `solve_accept` and then, when the answer was assessed here
 * (code 0, acode 0), lcp.residual's measure as `solve_lemke` took it -- w = dot(M, z, w) by the
 * `dot` given (numpy.dot: the same BLAS call as M.dot(z), written into w) and `lcp_measure`'s C
 * steps when n <= upto (w becomes M z + q) -- with no Python between. raw and scaled are NaN
 * when not measured here (the caller measures in numpy). M: C-contiguous n x n float64, q, z,
 * w float64 of length n (ndim 1), basis int64 of length n; else ValueError. */
static PyObject *py_solve_fast(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 9) {
        PyErr_SetString(PyExc_TypeError, "solve_fast: nine arguments");
        return NULL;
    }
    double tol = PyFloat_AsDouble(args[2]);
    long long max_iter = PyLong_AsLongLong(args[3]);
    idx upto = PyLong_AsSsize_t(args[8]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer vq = {0}, vM = {0}, vz = {0}, vw = {0}, vb = {0};
    PyObject *result = NULL;
    idx n = problem_data(args[0], args[1], &vM, &vq);
    if (n < 0) goto done;
    if (get_buffer(args[4], &vz, "z", 'd', n, 0) < 0) goto done;
    if (get_buffer(args[5], &vw, "w", 'd', n, 0) < 0) goto done;
    if (get_buffer(args[6], &vb, "basis", 'q', n, 0) < 0) goto done;
    if (vq.ndim != 1 || vM.ndim != 2 || vM.shape[0] != n || vM.shape[1] != n) {
        PyErr_SetString(PyExc_ValueError, "M must be n x n and q of length n");
        goto done;
    }
    const double *M = (const double *)vM.buf, *q = (const double *)vq.buf;
    double *z = (double *)vz.buf, *w = (double *)vw.buf;
    long long pivots = 0;
    double res[3], got[4] = {NAN, NAN, 0.0, 0.0};
    idx nb = 0;
    int code, acode = 1;
    int direct = blas_ok(n), measured = 0;
    double mmax = -1.0; /* max|M| from the solve (measure_known) */
    Py_BEGIN_ALLOW_THREADS
    code = solve_and_accept(n, M, q, tol, max_iter, z, (int64_t *)vb.buf, &pivots, &nb, &acode,
                            res, &mmax);
    if (code == 0 && acode == 0 && direct) { /* numpy's own gemv (_blas.h), then the measure */
        blas_mz(n, M, z, w);
        measured = 1;
        if (n <= upto && measure_known(n, M, q, z, w, got, mmax) < 0) got[0] = got[1] = NAN;
    }
    Py_END_ALLOW_THREADS
    if (code < 0) {
        PyErr_NoMemory();
        goto done;
    }
    if (code == 0 && acode == 0 && !measured) {
        PyObject *call[3] = {args[0], args[4], args[5]};
        PyObject *out = PyObject_Vectorcall(args[7], call, 3, NULL); /* dot(M, z, w) */
        if (!out) goto done;
        Py_DECREF(out);
        if (n <= upto && measure_known(n, M, q, z, w, got, mmax) < 0) got[0] = got[1] = NAN;
    }
    result = Py_BuildValue("iLniddidd", code, pivots, nb, acode, res[0], res[1], (int)res[2],
                           got[0], got[1]);
done:
    release(&vb);
    release(&vw);
    release(&vz);
    release(&vM);
    release(&vq);
    return result;
}

static PyMethodDef methods[] = {
    {"solve_batch", py_solve_batch, METH_VARARGS,
     "solve_batch(Ms, qs, d, tol, max_iter, Z, basic_z, codes, pivots, mode=0, acc=None, "
     "mmax=None): k "
     "LCPs by Lemke (and the acceptance of each answer into acc)."},
    {"solve_accept", py_solve_accept, METH_VARARGS,
     "solve_accept(M, q, tol, max_iter, z, basis) -> (code, pivots, nbasis, acode, berr, ferr, "
     "refined): solve_eq's default Lemke and the acceptance of its answer in one call."},
    {"solve_fast", (PyCFunction)(void (*)(void))py_solve_fast, METH_FASTCALL,
     "solve_fast(M, q, tol, max_iter, z, w, basis, dot, upto) -> (code, pivots, nbasis, acode, "
     "berr, ferr, refined, raw, scaled): solve_accept, then w = dot(M, z, w) and the measure."},
    {"solve_lcp", (PyCFunction)(void (*)(void))py_solve_lcp, METH_FASTCALL,
     "solve_lcp(M, q, tol, max_iter, upto) -> Solution, or solve_fast's numbers and (z, w, "
     "basis): see lcp/_lemke_solution.h."},
    {"batch_solutions", py_batch_solutions, METH_VARARGS,
     "batch_solutions(Z, W, basic, codes, pivots, acc, measured, tol, ferr_tol, equilibrated) -> "
     "list of Solution or None (see lcp/_batch_solutions.h)."},
    {"stack_lcps", py_stack_lcps, METH_VARARGS,
     "stack_lcps(problems, LCP) -> [(n, indices, Ms, qs), ...] or None: solve_many's stacks."},
    {"solve_default", py_solve_default, METH_O,
     "solve_default(problem) -> Solution or None: lcp.solve's default call on an lcp.LCP (see "
     "lcp/_lemke_solution.h)."},
    {"entry_setup", py_entry_setup, METH_VARARGS,
     "entry_setup(registry, kernel_dict, lemke, finish, ndarray, tol, upto): solve_default's "
     "objects."},
    {"array_setup", py_array_setup, METH_VARARGS,
     "array_setup(capsule, float64, intp, ndarray) -> bool: new arrays by numpy's "
     "PyArray_NewFromDescr (see lcp/_numpy_abi.h)."},
    {"array_probe", py_array_probe, METH_VARARGS,
     "array_probe(shape, integer) -> an array made by that route, entries 0, 1, 2, ..."},
    {"array_fields", py_array_fields, METH_O,
     "array_fields(arr) -> (address, nd, shape, strides, dtype, C-contiguous, writeable)."},
    {"array_fields_use", py_array_fields_use, METH_O,
     "array_fields_use(flag) -> bool: read plain float64 arrays' data from their fields."},
    {"gemv_setup", py_gemv_setup, METH_VARARGS,
     "gemv_setup(address, ilp64): numpy's cblas_dgemv for M z (0: none; see lcp/_blas.h)."},
    {"gemv", py_gemv, METH_VARARGS,
     "gemv(M, z, w) -> bool: w = M z by the cblas_dgemv of gemv_setup (False: none set)."},
    {"solve_setup", py_solve_setup, METH_VARARGS,
     "solve_setup(dot, empty, intp, new, Solution, q_nonnegative, TOL, FERR_TOL): solve_lcp's "
     "Python objects."},
    {"solve_eq", py_solve_eq, METH_VARARGS,
     "solve_eq(M, q, r, c, d, tol, max_iter, z, basis) -> (code, pivots, nbasis, bounds): one "
     "LCP by Lemke on its equilibrated data."},
    {"lcp_measure", py_lcp_measure, METH_VARARGS,
     "lcp_measure(M, q, z, Mz) -> (residual, scaled, z_s, w_s) or None; Mz becomes M z + q."},
    {"lcp_measure_batch", py_lcp_measure_batch, METH_VARARGS,
     "lcp_measure_batch(Ms, qs, Z, MZ, out, mmax=None) -> bool: lcp_measure of k problems."},
    {"abs_row_sums", py_abs_row_sums, METH_VARARGS,
     "abs_row_sums(M, out, n): out = the row sums of |M| (m x n), in numpy's order."},
    {"check", py_check, METH_VARARGS, "check(M, q) -> (all finite, min q)."},
    {"plain", (PyCFunction)(void (*)(void))py_plain, METH_FASTCALL,
     "plain(M, q) -> bool: C-contiguous native float64 q (n >= 1) and M (n x n), all finite."},
    {"lcp_setup", py_lcp_setup, METH_VARARGS,
     "lcp_setup(LCP, ndarray, empty, float64) -> bool: lcp_init's class (False: its fields are not plain "
     "slots, lcp_init always declines)."},
    {"lcp_init", (PyCFunction)(void (*)(void))py_lcp_init, METH_FASTCALL,
     "lcp_init(self, M, q, name, meta) -> bool: lcp.LCP's quick route (see lcp/_lemke_py.h)."},
    {"lcp_method", py_lcp_method, METH_VARARGS,
     "lcp_method(LCP, init) -> LCP's __init__ in C (the quick route; init for the rest)."},
    {"setup", py_setup, METH_VARARGS,
     "setup(T, M, q, d) -> (mu, nu, delta): the normalized dictionary (see lcp/lemke.py)."},
    {"run", py_run, METH_VARARGS,
     "run(T, basic, nonbasic, row_of, slot_of, tol, max_iter, trace) -> (code, pivots, s, "
     "entering): Lemke's pivot loop on the dictionary T (see lcp/_lemke_kernel.py)."},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_lemke_c",
                                    "Lemke's pivot loop in C (see lcp/_lemke_kernel.py).", -1,
                                    methods};

PyMODINIT_FUNC PyInit__lemke_c(void)
{
    if (PyType_Ready(&EntryType) < 0) return NULL;
    PyObject *m = PyModule_Create(&module);
    if (m && PyModule_AddObjectRef(m, "Entry", (PyObject *)&EntryType) < 0) Py_CLEAR(m);
    return m;
}
