/* lcp.solve's common call, its Solution built here (lcp/solvers/fast_lemke.py: solve_lemke):
 * `solve_fast`'s work -- the solve, the acceptance of lcp/acceptance/accuracy.py's
 * `assess_lcp`, numpy's M z and lcp.residual's measure -- then the verdict `solve_lemke`
 * gives (scaled <= TOL, berr <= TOL, ferr <= FERR_TOL) and the Solution object
 * lcp.problems.solution.solved_lcp builds (the same fields in the same slots),
 * with no Python between. What the Python did around `solve_fast` (three np.empty, the basis
 * slice, the tuple, the tests, the info dict, solved_lcp's call) was a third of the call at
 * n = 10; the numbers are the same (the same C steps in the same order).
 *
 *   solve_setup(dot, empty, intp, new, Solution, q_nonnegative, TOL, FERR_TOL): the Python
 *     objects these calls use (numpy.dot, numpy.empty, numpy.intp, object.__new__, the class,
 *     lemke()'s message for q >= 0, the tolerances), held for the module's life.
 *   solve_lcp(M, q, tol, max_iter, upto) -> a Solution (solved and accepted), or
 *     (code, pivots, nbasis, acode, berr, ferr, refined, raw, scaled, z, w, basis): the
 *     numbers of `solve_fast` and its arrays (basis of length nbasis) for the Python to
 *     finish (not solved, not assessed here, not measured here, or not accepted).
 *   solve_default(problem) -> a Solution or None: lcp.solve's default call on an lcp.LCP,
 *     `solve_lemke`'s Python steps done here (below); entry_setup gives it its objects.
 * M z is numpy's own cblas_dgemv called directly when lcp/_lemke_kernel.py found and checked it
 * (_blas.h), else numpy.dot called from here. The includer includes _lemke_py.h, _blas.h,
 * _lemke_problem.h and _lemke_measure.h first. */
#ifndef RIGIDLCP_LEMKE_SOLUTION_H
#define RIGIDLCP_LEMKE_SOLUTION_H

static PyObject *s_dot, *s_empty, *s_intp, *s_new, *s_cls, *s_msg, *s_empty_str;
static double s_tol = -1.0, s_ferr_tol = -1.0; /* negative until solve_setup: nothing passes */
/* the Solution's fields, in lcp.problems.solution.Solution's order, and the info keys */
static const char *const s_names[14] = {
    "z", "w", "status", "method", "iterations", "residual", "eq_residual", "scaled_residual",
    "basis", "u", "message", "info", "backward_error", "forward_error"};
static PyObject *s_keys[14], *s_solved, *s_lemke, *s_zero, *s_equilibrated, *s_polished;
/* the byte offsets of the Solution's 14 slots (s_off[0] = -1: not known, set by name) */
static Py_ssize_t s_off[14] = {-1};

static PyObject *py_solve_setup(PyObject *self, PyObject *args)
{
    PyObject *dot, *empty, *intp, *new_, *cls, *msg;
    double tol, ferr_tol;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOUdd", &dot, &empty, &intp, &new_, &cls, &msg, &tol,
                          &ferr_tol))
        return NULL;
    if (!s_keys[0]) {
        for (int k = 0; k < 14; k++)
            if (!(s_keys[k] = PyUnicode_InternFromString(s_names[k]))) return NULL;
        if (!(s_solved = PyUnicode_InternFromString("solved")) ||
            !(s_lemke = PyUnicode_InternFromString("lemke")) ||
            !(s_equilibrated = PyUnicode_InternFromString("equilibrated")) ||
            !(s_polished = PyUnicode_InternFromString("polished")) ||
            !(s_empty_str = PyUnicode_FromString("")) || !(s_zero = PyFloat_FromDouble(0.0)))
            return NULL;
    }
    PyObject **slots[6] = {&s_dot, &s_empty, &s_intp, &s_new, &s_cls, &s_msg};
    PyObject *given[6] = {dot, empty, intp, new_, cls, msg};
    for (int k = 0; k < 6; k++) {
        Py_INCREF(given[k]);
        Py_XSETREF(*slots[k], given[k]);
    }
    s_tol = tol;
    s_ferr_tol = ferr_tol;
    /* where each field's slot is in a Solution (its member descriptors): the object is then
     * filled by 14 stores; -1 (the fields set by name instead) when a field is not a plain
     * object slot of the class given */
    s_off[0] = -1;
    if (PyType_Check(cls)) {
        Py_ssize_t off[14];
        int ok = 1;
        for (int k = 0; ok && k < 14; k++) {
            PyObject *dsc = PyDict_GetItemWithError(((PyTypeObject *)cls)->tp_dict, s_keys[k]);
            if (!dsc && PyErr_Occurred()) return NULL;
            ok = dsc && Py_IS_TYPE(dsc, &PyMemberDescr_Type);
            if (ok) {
                PyMemberDef *md = ((PyMemberDescrObject *)dsc)->d_member;
                ok = md->type == SLOT_OBJECT_EX && !(md->flags & SLOT_READONLY) &&
                     md->offset > 0;
                off[k] = md->offset;
            }
        }
        if (ok && ((PyTypeObject *)cls)->tp_dictoffset == 0)
            memcpy(s_off, off, sizeof off);
    }
    Py_RETURN_NONE;
}

/* A new numpy array of n entries: numpy.empty(n) or numpy.empty(n, numpy.intp). */
static PyObject *new_array(idx n, int integer)
{
    PyObject *size = PyLong_FromSsize_t(n);
    if (!size) return NULL;
    PyObject *call[2] = {size, s_intp};
    PyObject *out = PyObject_Vectorcall(s_empty, call, integer ? 2 : 1, NULL);
    Py_DECREF(size);
    return out;
}

/* solved_lcp(z, w, "lemke", pivots, raw, scaled, basis, message, info, berr, ferr), info =
 * {"equilibrated": equilibrated} (and "polished": True when refined): a new Solution
 * (object.__new__, i.e. the type's tp_alloc) whose slots receive the 14 fields, in the
 * dataclass's order; by name (setattr) when the slots are not known. */
static PyObject *solution(PyObject *z, PyObject *w, long long pivots, double raw, double scaled,
                          PyObject *basis, int refined, double berr, double ferr,
                          PyObject *equilibrated)
{
    PyObject *info = PyDict_New(), *sol = NULL;
    PyObject *v[14] = {NULL};
    if (!info) return NULL;
    if (PyDict_SetItem(info, s_equilibrated, equilibrated) < 0 ||
        (refined && PyDict_SetItem(info, s_polished, Py_True) < 0))
        goto fail;
    v[0] = z, v[1] = w, v[2] = s_solved, v[3] = s_lemke;
    v[4] = PyLong_FromLongLong(pivots);
    v[5] = PyFloat_FromDouble(raw);
    v[6] = s_zero;
    v[7] = PyFloat_FromDouble(scaled);
    v[8] = basis, v[9] = Py_None, v[10] = pivots ? s_empty_str : s_msg, v[11] = info;
    v[12] = PyFloat_FromDouble(berr);
    v[13] = PyFloat_FromDouble(ferr);
    if (!(v[4] && v[5] && v[7] && v[12] && v[13])) goto fail;
    if (s_off[0] > 0) {
        PyTypeObject *cls = (PyTypeObject *)s_cls;
        if (!(sol = cls->tp_alloc(cls, 0))) goto fail;
        for (int k = 0; k < 14; k++) {
            Py_INCREF(v[k]);
            *(PyObject **)((char *)sol + s_off[k]) = v[k]; /* the slot is NULL: new object */
        }
    } else if ((sol = PyObject_CallOneArg(s_new, s_cls))) { /* object.__new__(Solution) */
        for (int k = 0; k < 14; k++)
            if (PyObject_SetAttr(sol, s_keys[k], v[k]) < 0) {
                Py_CLEAR(sol);
                break;
            }
    }
fail:
    Py_XDECREF(v[4]);
    Py_XDECREF(v[5]);
    Py_XDECREF(v[7]);
    Py_XDECREF(v[12]);
    Py_XDECREF(v[13]);
    Py_XDECREF(info);
    return sol;
}

/* The data pointer of an array made here by numpy.empty (its dtype known): a writable
 * C-contiguous buffer of `bytes` bytes, asked for without PyBUF_FORMAT (numpy then builds no
 * format string: that and its check were a tenth of the C call's overhead at n = 10). */
static int own_buffer(PyObject *obj, Py_buffer *view, idx bytes)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS) < 0) return -1;
    if (view->len != bytes) {
        PyErr_SetString(PyExc_ValueError, "solve_lcp: an output array of the wrong size");
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* solve_lcp's work on M and q (max_iter < 0: lemke()'s default 1000 + 100 n): the Solution, or
 * the tuple of numbers and arrays; NULL with an error (ValueError, BufferError or TypeError for
 * data the C call does not take: the caller's general path). */
static PyObject *lcp_answer(PyObject *oM, PyObject *oq, double tol, long long max_iter, idx upto)
{
    Py_buffer vq = {0}, vM = {0};
    PyObject *result = NULL, *z = NULL, *w = NULL, *basis = NULL;
    void *zp, *wp, *bp;
    int64_t bbuf[64], *b = NULL;
    /* plain float64 arrays: their data read from their fields (_numpy_abi.h), else buffers */
    const ArrayFields *af = (const ArrayFields *)oq;
    idx n = s_fields_ok && Py_TYPE(oq) == s_arr_type && af->nd == 1 ? af->dimensions[0] : 0;
    const double *qf = n >= 1 ? plain_f64(oq, s_f64, 1, n, 1) : NULL,
                 *Mf = qf ? plain_f64(oM, s_f64, 2, n, 1) : NULL;
    if (!Mf) {
        n = problem_data(oM, oq, &vM, &vq);
        if (n < 0) goto done;
        if (vq.ndim != 1 || vM.ndim != 2 || vM.shape[0] != n || vM.shape[1] != n) {
            PyErr_SetString(PyExc_ValueError, "M must be n x n and q of length n");
            goto done;
        }
        Mf = (const double *)vM.buf, qf = (const double *)vq.buf;
    }
    if (max_iter < 0) max_iter = 1000 + 100 * (long long)n;
    if (!(z = new_array_of(1, &n, 0, s_empty, s_intp, &zp)) ||
        !(w = new_array_of(1, &n, 0, s_empty, s_intp, &wp)))
        goto done;
    b = n <= 64 ? bbuf : (int64_t *)malloc((size_t)n * sizeof(int64_t));
    if (!b) {
        PyErr_NoMemory();
        goto done;
    }
    const double *M = Mf, *q = qf;
    double *zd = (double *)zp, *wd = (double *)wp;
    long long pivots = 0;
    double res[3], got[4] = {NAN, NAN, 0.0, 0.0};
    idx nb = 0;
    int code, acode = 1;
    int direct = blas_ok(n), measured = 0;
    double mmax = -1.0; /* max|M|, which the solve measured: the measure does not again */
    Py_BEGIN_ALLOW_THREADS
    code = solve_and_accept(n, M, q, tol, max_iter, zd, b, &pivots, &nb, &acode, res, &mmax);
    if (code == 0 && acode == 0 && direct) { /* numpy's own gemv (_blas.h), then the measure */
        blas_mz(n, M, zd, wd);
        measured = 1;
        if (n <= upto && measure_known(n, M, q, zd, wd, got, mmax) < 0) got[0] = got[1] = NAN;
    }
    Py_END_ALLOW_THREADS
    if (code < 0) {
        PyErr_NoMemory();
        goto done;
    }
    if (code == 0 && acode == 0 && !measured) {
        PyObject *call[3] = {oM, z, w};
        PyObject *out = PyObject_Vectorcall(s_dot, call, 3, NULL); /* dot(M, z, w) */
        if (!out) goto done;
        Py_DECREF(out);
        if (n <= upto && measure_known(n, M, q, zd, wd, got, mmax) < 0) got[0] = got[1] = NAN;
    }
    if (!(basis = new_array_of(1, &nb, 1, s_empty, s_intp, &bp))) goto done;
    if (nb) memcpy(bp, b, (size_t)nb * sizeof(int64_t)); /* intp: 8 bytes (numpy_arrays) */
    int refined = (int)res[2];
    /* solve_lemke's verdict (NaN fails every test: then the Python measures or refuses) */
    if (code == 0 && acode == 0 && got[1] <= s_tol && res[0] <= s_tol && res[1] <= s_ferr_tol)
        result = solution(z, w, pivots, got[0], got[1], basis, refined, res[0], res[1],
                          Py_True);
    else
        result = Py_BuildValue("iLniddiddOOO", code, pivots, nb, acode, res[0], res[1], refined,
                               got[0], got[1], z, w, basis);
done:
    if (b && b != bbuf) free(b);
    release(&vM);
    release(&vq);
    Py_XDECREF(z);
    Py_XDECREF(w);
    Py_XDECREF(basis);
    return result;
}

static PyObject *py_solve_lcp(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError, "solve_lcp: five arguments");
        return NULL;
    }
    if (!s_cls) {
        PyErr_SetString(PyExc_RuntimeError, "solve_lcp: solve_setup was not called");
        return NULL;
    }
    double tol = PyFloat_AsDouble(args[2]);
    long long max_iter = PyLong_AsLongLong(args[3]);
    idx upto = PyLong_AsSsize_t(args[4]);
    if (PyErr_Occurred()) return NULL;
    return lcp_answer(args[0], args[1], tol, max_iter, upto);
}

/* ------------------------------------------------------------ lcp.solve's default call
 * solve_default(problem) -> Solution or None: lcp/solvers/fast_lemke.py's `solve_lemke`, its
 * Python steps done here (lcp.solve calls it for `solve(P)` / `solve(P, "lemke")` on an
 * lcp.LCP with default options): the registry's "lemke" must be the built-in lemke,
 * equilibrated by default, and the compiled kernel on (lcp._lemke_kernel._use), read at every
 * call; M and q numpy arrays; then `solve_lcp(M, q, DEFAULT_TOL, 1000 + 100 n, upto)`. Its
 * Solution is returned; its tuple goes to `finish(M, q, out)` (solve_lemke's own steps after
 * the call); data the C call refuses (ValueError, BufferError, TypeError) give None, as
 * solve_lemke's `except` does. entry_setup(registry, kernel_dict, lemke, finish, ndarray,
 * DEFAULT_TOL, upto) gives it those objects. */
static PyObject *s_registry, *s_kernel_dict, *s_lemke_fn, *s_finish, *s_ndarray, *s_info;
static PyObject *s_use_key, *s_func_key, *s_equilibrate_key, *s_M_key, *s_q_key;
static double s_default_tol;
static idx s_upto;

static PyObject *py_entry_setup(PyObject *self, PyObject *args)
{
    PyObject *registry, *kernel_dict, *lemke, *finish, *ndarray;
    double tol;
    Py_ssize_t upto;
    (void)self;
    if (!PyArg_ParseTuple(args, "O!O!OOO!dn", &PyDict_Type, &registry, &PyDict_Type,
                          &kernel_dict, &lemke, &finish, &PyType_Type, &ndarray, &tol, &upto))
        return NULL;
    if (!s_use_key) {
        if (!(s_use_key = PyUnicode_InternFromString("_use")) ||
            !(s_func_key = PyUnicode_InternFromString("func")) ||
            !(s_equilibrate_key = PyUnicode_InternFromString("equilibrate")) ||
            !(s_M_key = PyUnicode_InternFromString("M")) ||
            !(s_q_key = PyUnicode_InternFromString("q")))
            return NULL;
    }
    PyObject **slots[5] = {&s_registry, &s_kernel_dict, &s_lemke_fn, &s_finish, &s_ndarray};
    PyObject *given[5] = {registry, kernel_dict, lemke, finish, ndarray};
    for (int k = 0; k < 5; k++) {
        Py_INCREF(given[k]);
        Py_XSETREF(*slots[k], given[k]);
    }
    Py_CLEAR(s_info);
    s_default_tol = tol;
    s_upto = upto;
    Py_RETURN_NONE;
}

/* Is `info` (registry["lemke"]) the built-in lemke, equilibrated by default? 1, 0 or -1
 * (error). The last one that was is remembered: a MethodInfo is frozen, and registering a
 * method makes a new one. */
static int builtin_lemke(PyObject *info)
{
    if (info == s_info) return 1;
    PyObject *func = PyObject_GetAttr(info, s_func_key);
    if (!func) return -1;
    int ok = func == s_lemke_fn;
    Py_DECREF(func);
    if (ok) {
        PyObject *eq = PyObject_GetAttr(info, s_equilibrate_key);
        if (!eq) return -1;
        ok = PyObject_IsTrue(eq);
        Py_DECREF(eq);
        if (ok < 0) return -1;
    }
    if (ok) {
        Py_INCREF(info);
        Py_XSETREF(s_info, info);
    }
    return ok;
}

static PyObject *py_solve_default(PyObject *self, PyObject *problem)
{
    (void)self;
    if (!s_finish || !s_cls) {
        PyErr_SetString(PyExc_RuntimeError, "solve_default: entry_setup was not called");
        return NULL;
    }
    PyObject *M = NULL, *q = NULL, *result = NULL;
    if (!(M = PyObject_GetAttr(problem, s_M_key)) || !(q = PyObject_GetAttr(problem, s_q_key)))
        goto done;
    PyObject *info = PyDict_GetItemWithError(s_registry, s_lemke); /* borrowed */
    PyObject *use = info ? PyDict_GetItemWithError(s_kernel_dict, s_use_key) : NULL;
    if (PyErr_Occurred()) goto done;
    int ok = Py_TYPE(M) == (PyTypeObject *)s_ndarray && Py_TYPE(q) == (PyTypeObject *)s_ndarray
             && info && use;
    if (ok && (ok = builtin_lemke(info)) > 0) ok = PyObject_IsTrue(use);
    if (ok < 0) goto done;
    if (!ok) { /* not the built-in lemke, or the kernel off, or not arrays: the general path */
        result = Py_NewRef(Py_None);
        goto done;
    }
    PyObject *out = lcp_answer(M, q, s_default_tol, -1, s_upto);
    if (!out) {
        if (PyErr_ExceptionMatches(PyExc_ValueError) || PyErr_ExceptionMatches(PyExc_BufferError)
            || PyErr_ExceptionMatches(PyExc_TypeError)) {
            PyErr_Clear(); /* e.g. Fortran order, read-only, q 0-d: the general path */
            result = Py_NewRef(Py_None);
        }
    } else if (PyTuple_CheckExact(out)) {
        PyObject *call[3] = {M, q, out};
        result = PyObject_Vectorcall(s_finish, call, 3, NULL);
        Py_DECREF(out);
    } else {
        result = out;
    }
done:
    Py_XDECREF(M);
    Py_XDECREF(q);
    return result;
}

#endif /* RIGIDLCP_LEMKE_SOLUTION_H */
