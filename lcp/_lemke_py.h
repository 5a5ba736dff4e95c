/* The Python side of one dictionary (included by lcp/_lemke_c.c): the buffer checks of the
 * arguments (opt_vector, release, problem_data; get_buffer from _buffer.h) and the entry
 * points of lcp/_lemke_kernel.py and lcp.LCP that work on one dictionary or on the data as
 * given: run, setup, check, plain, and lcp.LCP's quick __init__ (lcp_setup, lcp_init). The
 * includer includes <Python.h>, <float.h>, <math.h>, acceptance/_accuracy_core.h
 * (abs_max_finite) and _lemke_run.h. */
#ifndef RIGIDLCP_LEMKE_PY_H
#define RIGIDLCP_LEMKE_PY_H

#ifndef Py_T_OBJECT_EX /* Python < 3.12: structmember.h's names (the slots of a
                        * class: lcp_setup here, solve_setup in _lemke_solution.h) */
#include <structmember.h>
#define SLOT_OBJECT_EX T_OBJECT_EX
#define SLOT_READONLY READONLY
#else
#define SLOT_OBJECT_EX Py_T_OBJECT_EX
#define SLOT_READONLY Py_READONLY
#endif

/* ------------------------------------------------------------------ Python binding */
#include "_buffer.h" /* get_buffer: shared with solvers/_pivot_c.c */

static PyObject *py_run(PyObject *self, PyObject *args)
{
    PyObject *oT, *ob, *onb, *orow, *oslot, *otrace;
    double tol;
    long long max_iter;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOdLO", &oT, &ob, &onb, &orow, &oslot, &tol, &max_iter,
                          &otrace))
        return NULL;
    Py_buffer vb, vnb, vrow, vslot, vT, vtr;
    idx n = PyObject_Length(ob);
    if (n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "basic: empty");
        return NULL;
    }
    if (get_buffer(ob, &vb, "basic", 'q', n, 0) < 0) return NULL;
    if (get_buffer(onb, &vnb, "nonbasic", 'q', n + 1, 0) < 0) goto fail1;
    if (get_buffer(orow, &vrow, "row_of", 'q', 2 * n + 1, 0) < 0) goto fail2;
    if (get_buffer(oslot, &vslot, "slot_of", 'q', 2 * n + 1, 0) < 0) goto fail3;
    if (get_buffer(oT, &vT, "T", 'd', n * (n + 2), 1) < 0) goto fail4;
    idx trace_len = 0;
    int have_trace = otrace != Py_None;
    if (have_trace) {
        if (PyObject_GetBuffer(otrace, &vtr, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS) < 0) goto fail5;
        trace_len = vtr.len / 16;
    }
    Lemke L;
    L.n = n;
    L.ld = n;
    L.T = (double *)vT.buf;
    L.basic = (int64_t *)vb.buf;
    L.nonbasic = (int64_t *)vnb.buf;
    L.row_of = (int64_t *)vrow.buf;
    L.slot_of = (int64_t *)vslot.buf;
    L.tol = tol;
    L.lazy = 0; /* every column updated at every pivot: Python reads the whole dictionary */
    L.rows = (idx *)malloc(4 * n * sizeof(idx));
    L.alpha = (double *)malloc((4 * n + 2) * sizeof(double));
    L.V = (double *)malloc((size_t)n * n * sizeof(double));
    long long pivots = 0;
    idx s = 0;
    int64_t entering = -1;
    int code = -1;
    if (L.rows && L.alpha && L.V) {
        L.cand = L.rows + n;
        L.wj = L.rows + 2 * n;
        L.pos = L.rows + 3 * n;
        L.theta = L.alpha + n;
        L.col = L.alpha + 2 * n;
        L.row = L.alpha + 3 * n;
        Py_BEGIN_ALLOW_THREADS
        code = run(&L, max_iter, have_trace ? (int64_t *)vtr.buf : NULL, trace_len, &pivots,
                   &s, &entering);
        Py_END_ALLOW_THREADS
    }
    free(L.rows);
    free(L.alpha);
    free(L.V);
    if (have_trace) PyBuffer_Release(&vtr);
    PyBuffer_Release(&vT);
    PyBuffer_Release(&vslot);
    PyBuffer_Release(&vrow);
    PyBuffer_Release(&vnb);
    PyBuffer_Release(&vb);
    if (code < 0) return PyErr_NoMemory();
    return Py_BuildValue("iLnL", code, pivots, s, (long long)entering);
fail5:
    PyBuffer_Release(&vT);
fail4:
    PyBuffer_Release(&vslot);
fail3:
    PyBuffer_Release(&vrow);
fail2:
    PyBuffer_Release(&vnb);
fail1:
    PyBuffer_Release(&vb);
    return NULL;
}

static void fill(idx n, double *T, const double *M, const double *q, const double *d,
                 double *out_mu, double *out_nu, double *out_delta)
{
    double mu = 0.0, nu = 0.0, delta = -1.0 / 0.0;
    for (idx k = 0; k < n * n; k++) {
        double a = M[k] < 0 ? -M[k] : M[k];
        if (a > mu) mu = a;
    }
    if (mu == 0.0) mu = 1.0;
    for (idx i = 0; i < n; i++) {
        double a = q[i] < 0 ? -q[i] : q[i];
        if (a > nu) nu = a;
        if (d[i] > delta) delta = d[i];
    }
    for (idx i = 0; i < n; i++)
        for (idx j = 0; j < n; j++) T[i + n * j] = M[i * n + j] / mu;
    for (idx i = 0; i < n; i++) {
        T[i + n * n] = d[i] / delta;
        T[i + n * (n + 1)] = q[i] / nu;
    }
    *out_mu = mu;
    *out_nu = nu;
    *out_delta = delta;
}

/* setup(T, M, q, d) -> (mu, nu, delta): T[:, :n] = M / mu, T[:, n] = d / delta,
 * T[:, n + 1] = q / nu with mu = max|M| (1 if M = 0), nu = max|q|, delta = max d; as numpy's
 * true divisions in `_Lemke.__init__`. M is read C-contiguous, T written column-major. */
static PyObject *py_setup(PyObject *self, PyObject *args)
{
    PyObject *oT, *oM, *oq, *od;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOO", &oT, &oM, &oq, &od)) return NULL;
    Py_buffer vq, vd, vM, vT;
    idx n = PyObject_Length(oq);
    if (n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "q: empty");
        return NULL;
    }
    if (get_buffer(oq, &vq, "q", 'd', n, 0) < 0) return NULL;
    if (get_buffer(od, &vd, "d", 'd', n, 0) < 0) goto f1;
    if (get_buffer(oM, &vM, "M", 'd', n * n, 0) < 0) goto f2;
    if (get_buffer(oT, &vT, "T", 'd', n * (n + 2), 1) < 0) goto f3;
    double mu, nu, delta;
    fill(n, (double *)vT.buf, (const double *)vM.buf, (const double *)vq.buf,
         (const double *)vd.buf, &mu, &nu, &delta);
    PyBuffer_Release(&vT);
    PyBuffer_Release(&vM);
    PyBuffer_Release(&vd);
    PyBuffer_Release(&vq);
    return Py_BuildValue("ddd", mu, nu, delta);
f3:
    PyBuffer_Release(&vM);
f2:
    PyBuffer_Release(&vd);
f1:
    PyBuffer_Release(&vq);
    return NULL;
}

/* check(M, q) -> (finite, qmin): are all entries of M and q finite, and min q. */
static PyObject *py_check(PyObject *self, PyObject *args)
{
    PyObject *oM, *oq;
    (void)self;
    if (!PyArg_ParseTuple(args, "OO", &oM, &oq)) return NULL;
    Py_buffer vq, vM;
    idx n = PyObject_Length(oq);
    if (n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "q: empty");
        return NULL;
    }
    if (get_buffer(oq, &vq, "q", 'd', n, 0) < 0) return NULL;
    if (get_buffer(oM, &vM, "M", 'd', n * n, 0) < 0) {
        PyBuffer_Release(&vq);
        return NULL;
    }
    const double *M = (const double *)vM.buf, *q = (const double *)vq.buf;
    double qmin = q[0];
    int finite = 1; /* branch-free and independent per entry (vectorized): |x| <= DBL_MAX is
                     * false for inf and NaN (a sum of x - x was one serial chain of adds) */
    for (idx k = 0; k < n * n; k++) finite &= fabs(M[k]) <= DBL_MAX;
    for (idx i = 0; i < n; i++) {
        finite &= fabs(q[i]) <= DBL_MAX;
        qmin = q[i] < qmin ? q[i] : qmin;
    }
    PyBuffer_Release(&vM);
    PyBuffer_Release(&vq);
    return Py_BuildValue("Od", finite ? Py_True : Py_False, qmin);
}

/* The format of a buffer of native float64 values ("d", with the native byte order mark or
 * none)? */
static int native_double(const Py_buffer *v)
{
    const char *f = v->format ? v->format : "B";
#if PY_BIG_ENDIAN
    if (*f == '>' || *f == '!' || *f == '=' || *f == '@') f++;
#else
    if (*f == '<' || *f == '=' || *f == '@') f++;
#endif
    return v->itemsize == 8 && f[0] == 'd' && f[1] == 0;
}

/* numpy.dtype('float64') itself (lcp_setup gives it; NULL before). An array whose dtype is this
 * very object holds native float64 values, so its buffer is asked for without a format string:
 * numpy builds one and compares it by strcmp for every buffer with a format, a tenth of the
 * glue of a small solve. Any other dtype object (a float64 with metadata, an unpickled one,
 * another type) is tested by its format as before. */
static PyObject *s_f64, *s_dtype_key;

static int is_float64(PyObject *obj)
{
    if (!s_f64) return 0;
    PyObject *d = PyObject_GetAttr(obj, s_dtype_key);
    if (!d) {
        PyErr_Clear();
        return 0;
    }
    int ok = d == s_f64;
    Py_DECREF(d);
    return ok;
}

/* get_buffer(obj, view, name, 'd', size, 0): the same buffer and errors, its format string
 * asked for only when the dtype is not numpy's float64 itself. */
static int get_float64(PyObject *obj, Py_buffer *view, const char *name, idx size)
{
    if (!is_float64(obj)) return get_buffer(obj, view, name, 'd', size, 0);
    if (PyObject_GetBuffer(obj, view, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS) < 0) return -1;
    if (view->itemsize != 8 || view->len / 8 != size) {
        PyErr_Format(PyExc_ValueError, "%s: expected %zd float64 values", name, size);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* Are the n x n entries of M and the n of q all finite? */
static int finite_data(const double *M, const double *q, idx n)
{
    double top = 0.0; /* as `check`: |x| <= DBL_MAX false for inf and NaN; 4 lanes wide */
    int all = abs_max_finite(M, n * n, &top);
    for (idx i = 0; i < n; i++) all &= fabs(q[i]) <= DBL_MAX;
    return all;
}

/* Are oq a C-contiguous native float64 vector of n >= 1 entries and oM a C-contiguous native
 * float64 n x n matrix (all entries finite, when `finite`)? Returns n, with both buffers held
 * (the caller releases vM and vq), or 0 with none held, never an error. */
static idx plain_arrays(PyObject *oM, PyObject *oq, Py_buffer *vM, Py_buffer *vq, int finite)
{
    int fq = is_float64(oq), fM = is_float64(oM); /* then no format string is needed */
    if (PyObject_GetBuffer(oq, vq, PyBUF_C_CONTIGUOUS | (fq ? 0 : PyBUF_FORMAT)) < 0) {
        PyErr_Clear();
        return 0;
    }
    if (PyObject_GetBuffer(oM, vM, PyBUF_C_CONTIGUOUS | (fM ? 0 : PyBUF_FORMAT)) < 0) {
        PyErr_Clear();
        PyBuffer_Release(vq);
        return 0;
    }
    idx n = vq->ndim == 1 ? vq->shape[0] : 0;
    int ok = n >= 1 && (fq ? vq->itemsize == 8 : native_double(vq)) &&
             (fM ? vM->itemsize == 8 : native_double(vM)) && vM->ndim == 2 &&
             vM->shape[0] == n && vM->shape[1] == n;
    if (ok && finite) ok = finite_data((const double *)vM->buf, (const double *)vq->buf, n);
    if (ok) return n;
    PyBuffer_Release(vM);
    PyBuffer_Release(vq);
    return 0;
}

/* plain_arrays with the finiteness test. */
static idx plain_buffers(PyObject *oM, PyObject *oq, Py_buffer *vM, Py_buffer *vq)
{
    return plain_arrays(oM, oq, vM, vq, 1);
}

/* The same test, the buffers released (0 or 1). */
static int plain_data(PyObject *oM, PyObject *oq)
{
    Py_buffer vM, vq;
    if (!plain_buffers(oM, oq, &vM, &vq)) return 0;
    PyBuffer_Release(&vM);
    PyBuffer_Release(&vq);
    return 1;
}

/* plain(M, q) -> bool: lcp.LCP's quick route -- is q a C-contiguous native float64 vector of
 * n >= 1 entries and M a C-contiguous native float64 n x n matrix, all entries finite? (Then
 * M and q need no conversion, only the copies.) False for anything else, never an error: the
 * general validation runs and names the problem. One call for the dtype, shape, order and
 * finiteness tests. */
static PyObject *py_plain(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "plain(M, q): two arguments");
        return NULL;
    }
    if (plain_data(args[0], args[1])) Py_RETURN_TRUE;
    Py_RETURN_FALSE;
}

/* lcp.LCP's __init__, its quick route in one call (lcp/problems/problem.py; lcp_method below
 * makes it the class's __init__):
 *   lcp_setup(LCP, ndarray, empty, float64) -> bool: the class (its four fields M, q, name,
 *     meta plain object slots: their offsets are read from its member descriptors),
 *     numpy.ndarray, numpy.empty and numpy.dtype('float64'); False when the fields are not
 *     such slots (lcp_init then always declines).
 *   lcp_init(self, M, q, name, meta) -> bool: when M and q are numpy arrays (exactly) of plain
 *     finite data (plain_buffers), the four slots receive copies of M and q, name and meta
 *     ({} when None) and True is returned; else False and nothing is set (the Python
 *     validation runs and raises the typed error). A copy is numpy.empty of the shape (float64,
 *     C order, its own data) and the bytes of the data: what M.copy() makes, without numpy's
 *     general copy machinery (casts, iterators, overlap test: half the constructor's time). */
static PyObject *s_lcp_cls, *s_lcp_ndarray, *s_lcp_empty;
static Py_ssize_t s_lcp_off[4] = {-1};

static PyObject *py_lcp_setup(PyObject *self, PyObject *args)
{
    PyObject *cls, *nd, *empty, *f64;
    (void)self;
    if (!PyArg_ParseTuple(args, "O!O!OO", &PyType_Type, &cls, &PyType_Type, &nd, &empty, &f64))
        return NULL;
    if (!s_dtype_key && !(s_dtype_key = PyUnicode_InternFromString("dtype"))) return NULL;
    Py_INCREF(f64);
    Py_XSETREF(s_f64, f64);
    static const char *const names[4] = {"M", "q", "name", "meta"};
    Py_ssize_t off[4];
    int ok = ((PyTypeObject *)cls)->tp_dictoffset == 0;
    for (int k = 0; ok && k < 4; k++) {
        PyObject *dsc = PyDict_GetItemString(((PyTypeObject *)cls)->tp_dict, names[k]);
        ok = dsc && Py_IS_TYPE(dsc, &PyMemberDescr_Type);
        if (ok) {
            PyMemberDef *md = ((PyMemberDescrObject *)dsc)->d_member;
            ok = md->type == SLOT_OBJECT_EX && !(md->flags & SLOT_READONLY) && md->offset > 0;
            off[k] = md->offset;
        }
    }
    s_lcp_off[0] = -1;
    PyObject **slots[3] = {&s_lcp_cls, &s_lcp_ndarray, &s_lcp_empty};
    PyObject *given[3] = {cls, nd, empty};
    for (int k = 0; k < 3; k++) {
        Py_INCREF(given[k]);
        Py_XSETREF(*slots[k], given[k]);
    }
    if (ok) memcpy(s_lcp_off, off, sizeof off);
    return PyBool_FromLong(ok);
}

/* A new float64 array of nd dimensions dims (_numpy_abi.h) holding the `bytes` bytes at src. */
static PyObject *copy_of(int nd, const Py_ssize_t *dims, const void *src, idx bytes)
{
    void *data;
    PyObject *arr = new_array_of(nd, dims, 0, s_lcp_empty, NULL, &data);
    if (arr) memcpy(data, src, (size_t)bytes);
    return arr;
}

/* The quick route on obj: 1 (the four slots set), 0 (declined: nothing set) or -1 (error). */
static int lcp_quick(PyObject *obj, PyObject *oM, PyObject *oq, PyObject *name, PyObject *meta)
{
    Py_buffer vM = {0}, vq = {0};
    idx n = 0;
    if (s_lcp_off[0] <= 0 || !PyObject_TypeCheck(obj, (PyTypeObject *)s_lcp_cls) ||
        Py_TYPE(oM) != (PyTypeObject *)s_lcp_ndarray || Py_TYPE(oq) != (PyTypeObject *)s_lcp_ndarray)
        return 0;
    /* plain float64 arrays: their data read from their fields (_numpy_abi.h), else buffers */
    const ArrayFields *af = (const ArrayFields *)oq;
    if (s_fields_ok && af->nd == 1) n = af->dimensions[0];
    const double *qd = n >= 1 ? plain_f64(oq, s_f64, 1, n, 0) : NULL,
                 *Md = qd ? plain_f64(oM, s_f64, 2, n, 0) : NULL;
    if (Md) {
        if (!finite_data(Md, qd, n)) return 0;
    } else {
        if (!(n = plain_buffers(oM, oq, &vM, &vq))) return 0;
        Md = (const double *)vM.buf, qd = (const double *)vq.buf;
    }
    PyObject *v[4] = {NULL, NULL, name, meta};
    const Py_ssize_t dims[2] = {n, n};
    v[0] = copy_of(2, dims, Md, n * n * 8);
    v[1] = v[0] ? copy_of(1, dims, qd, n * 8) : NULL;
    if (vM.obj) PyBuffer_Release(&vM);
    if (vq.obj) PyBuffer_Release(&vq);
    if (v[1] && v[3] == Py_None && !(v[3] = PyDict_New())) Py_CLEAR(v[1]);
    else if (v[1] && v[3] != Py_None) Py_INCREF(v[3]);
    if (!v[1]) {
        Py_XDECREF(v[0]);
        return -1;
    }
    Py_INCREF(v[2]);
    for (int k = 0; k < 4; k++) /* the slot may hold a value (__init__ called again) */
        Py_XSETREF(*(PyObject **)((char *)obj + s_lcp_off[k]), v[k]);
    return 1;
}

static PyObject *py_lcp_init(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError, "lcp_init(self, M, q, name, meta): five arguments");
        return NULL;
    }
    int r = lcp_quick(args[0], args[1], args[2], args[3], args[4]);
    if (r < 0) return NULL;
    return PyBool_FromLong(r);
}

/* lcp_method(LCP, init) -> LCP's __init__ as a method of the class written in C: the quick
 * route for LCP(M, q[, name[, meta]]) (positional or by keyword), and init -- the Python
 * __init__, general route and argument errors alike -- for everything else, called with the
 * same arguments. It saves the Python frame of __init__ for the common call. */
static PyObject *s_lcp_py_init, *s_lcp_names[4], *s_lcp_noname;

static PyObject *lcp_dunder_init(PyObject *self, PyObject *const *args, size_t nargsf,
                                 PyObject *kwnames)
{
    Py_ssize_t nargs = PyVectorcall_NARGS(nargsf), nkw = kwnames ? PyTuple_GET_SIZE(kwnames) : 0;
    PyObject *a[4] = {NULL, NULL, s_lcp_noname, Py_None}; /* the defaults: name "", meta None */
    int given = 0, ok = nargs <= 4;
    for (Py_ssize_t i = 0; ok && i < nargs; i++) a[i] = args[i], given |= 1 << i;
    for (Py_ssize_t k = 0; ok && k < nkw; k++) { /* M, q, name, meta by keyword */
        PyObject *key = PyTuple_GET_ITEM(kwnames, k);
        int j = 0;
        while (j < 4 && key != s_lcp_names[j] &&
               !(PyUnicode_Check(key) && PyUnicode_Compare(key, s_lcp_names[j]) == 0))
            j++;
        ok = j < 4 && !(given & (1 << j));
        if (ok) a[j] = args[nargs + k], given |= 1 << j;
    }
    if (PyErr_Occurred()) return NULL;
    if (ok && a[0] && a[1]) {
        int r = lcp_quick(self, a[0], a[1], a[2], a[3]);
        if (r < 0) return NULL;
        if (r) Py_RETURN_NONE;
    }
    /* anything else (the general route, missing or unknown arguments): the Python __init__ */
    PyObject *small[8], **stack = nargs + nkw < 8 ? small
                                  : (PyObject **)PyMem_Malloc((nargs + nkw + 1) * sizeof(PyObject *));
    if (!stack) return PyErr_NoMemory();
    stack[0] = self;
    memcpy(stack + 1, args, (size_t)(nargs + nkw) * sizeof(PyObject *));
    PyObject *out = PyObject_Vectorcall(s_lcp_py_init, stack, nargs + 1, kwnames);
    if (stack != small) PyMem_Free(stack);
    return out;
}

static PyMethodDef lcp_init_def = {
    "__init__", (PyCFunction)(void (*)(void))lcp_dunder_init, METH_FASTCALL | METH_KEYWORDS,
    "__init__($self, /, M, q, name='', meta=None)\n--\n\n"
    "w = M z + q, 0 <= z perp w >= 0: M n x n, q of length n (validated, copied)."};

static PyObject *py_lcp_method(PyObject *self, PyObject *args)
{
    PyObject *cls, *init;
    (void)self;
    if (!PyArg_ParseTuple(args, "O!O", &PyType_Type, &cls, &init)) return NULL;
    if (!s_lcp_noname) {
        static const char *const names[4] = {"M", "q", "name", "meta"};
        for (int k = 0; k < 4; k++)
            if (!(s_lcp_names[k] = PyUnicode_InternFromString(names[k]))) return NULL;
        if (!(s_lcp_noname = PyUnicode_FromString(""))) return NULL;
    }
    Py_INCREF(init);
    Py_XSETREF(s_lcp_py_init, init);
    return PyDescr_NewMethod((PyTypeObject *)cls, &lcp_init_def);
}

/* An optional float64 vector of length n (None: NULL). */
static int opt_vector(PyObject *obj, Py_buffer *view, const char *name, idx n, const double **out)
{
    *out = NULL;
    view->obj = NULL;
    if (obj == Py_None) return 0;
    if (get_buffer(obj, view, name, 'd', n, 0) < 0) return -1;
    *out = (const double *)view->buf;
    return 0;
}

static void release(Py_buffer *v)
{
    if (v->obj) PyBuffer_Release(v);
}

/* The data of one problem for solve_accept and solve_fast: n = len(q) >= 1, then q (n float64)
 * and M (n x n float64, C-contiguous), in this order. Returns n, or -1 with the error set (vq
 * and vM, zeroed by the caller, are released by it with `release`: one not acquired stays
 * empty). solve_eq checks r and c between the length and the buffers, so it keeps its own. */
static idx problem_data(PyObject *oM, PyObject *oq, Py_buffer *vM, Py_buffer *vq)
{
    idx n = PyObject_Length(oq);
    if (n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "q: empty");
        return -1;
    }
    if (get_float64(oq, vq, "q", n) < 0) return -1;
    if (get_float64(oM, vM, "M", n * n) < 0) return -1;
    return n;
}

#endif /* RIGIDLCP_LEMKE_PY_H */
