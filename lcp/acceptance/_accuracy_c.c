/* lcp/accuracy.py's `assess` for an LCP answer with a basis, in C (the common case of
 * lcp.solve, its fast paths and solve_many: a few microseconds at n = 10 instead of a hundred
 * numpy calls). The same steps as the numpy code: the componentwise backward error of z, the
 * pattern's system M_aa y = -q_a refined from z_a with residuals in long double (x86: 64-bit
 * mantissa, numpy's longdouble) on one LU factorization, LAPACK's forward error bound with
 * || |K^-1| g || computed from K^-1's columns (m solves on the LU: O(m^3), not Hager's
 * estimate, which is a lower bound of it), and
 * the polished point kept when its backward error is not larger.
 *
 * assess(M, q, z, basis, out) -> (code, berr, ferr, refined)
 *   M n x n, q, z, out n (float64, C-contiguous), basis int64 (the basic indices a, m of them,
 *   distinct, in any order: they are sorted here).
 *   code 0: done (out holds the answer: the polished point when refined, else z);
 *   code 1: not handled here (basis out of range or repeated, m > MAX_M, a pivot of M_aa's LU
 *   below m eps times the largest, a number not finite): the numpy code runs.
 * Only the buffer protocol is used (no numpy headers).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef Py_ssize_t idx;

#include "_accuracy_core.h" /* assess_one and its steps (also in ../_lemke_c.c) */

static PyObject *py_assess(PyObject *self, PyObject *args)
{
    PyObject *oM, *oq, *oz, *oa, *oout;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOO", &oM, &oq, &oz, &oa, &oout)) return NULL;
    Py_buffer vM, vq, vz, va, vo;
    int got = 0;
    if (PyObject_GetBuffer(oM, &vM, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) == 0) got = 1;
    if (got == 1 && PyObject_GetBuffer(oq, &vq, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) == 0) got = 2;
    if (got == 2 && PyObject_GetBuffer(oz, &vz, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) == 0) got = 3;
    if (got == 3 && PyObject_GetBuffer(oa, &va, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) == 0) got = 4;
    if (got == 4 &&
        PyObject_GetBuffer(oout, &vo, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS | PyBUF_WRITABLE) == 0)
        got = 5;
    PyErr_Clear();
    int code = 1;
    double res[3] = {0.0, 0.0, 0.0};
    if (got == 5) {
        idx n = vq.len / 8, m = va.len / 8;
        int ok = vM.itemsize == 8 && vq.itemsize == 8 && vz.itemsize == 8 && va.itemsize == 8 &&
                 vo.itemsize == 8 && vM.len == n * n * 8 && vz.len == n * 8 &&
                 vo.len == n * 8 && m <= MAX_M && m <= n;
        const char *fa = va.format ? va.format : "B";
        if (*fa == '<' || *fa == '=' || *fa == '@') fa++;
        ok = ok && (fa[0] == 'q' || fa[0] == 'l') && fa[1] == 0;
        const char *fs[4] = {vM.format, vq.format, vz.format, vo.format};
        for (int i = 0; i < 4 && ok; i++) {
            const char *f = fs[i] ? fs[i] : "B";
            if (*f == '<' || *f == '=' || *f == '@') f++;
            ok = f[0] == 'd' && f[1] == 0;
        }
        if (ok && n >= 1)
            code = assess_one(n, (const double *)vM.buf, (const double *)vq.buf,
                              (const double *)vz.buf, (const int64_t *)va.buf, m, -1.0,
                              (double *)vo.buf, res);
    }
    if (got >= 5) PyBuffer_Release(&vo);
    if (got >= 4) PyBuffer_Release(&va);
    if (got >= 3) PyBuffer_Release(&vz);
    if (got >= 2) PyBuffer_Release(&vq);
    if (got >= 1) PyBuffer_Release(&vM);
    return Py_BuildValue("iddi", code, res[0], res[1], (int)res[2]);
}

/* bound(K, k, y, exact=0) -> (code, ferr): accuracy.py's forward_bound (K m x m, k, y m;
 * float64, C-contiguous); code 1: singular to working precision or bad buffers (numpy
 * decides). exact = 1: |K^-1| formed whatever the comparison bound says (for tests). */
static PyObject *py_bound(PyObject *self, PyObject *args)
{
    PyObject *oK, *ok, *oy;
    int exact = 0;
    if (!PyArg_ParseTuple(args, "OOO|p", &oK, &ok, &oy, &exact)) return NULL;
    Py_buffer b[3];
    PyObject *o[3] = {oK, ok, oy};
    int got = 0;
    while (got < 3 && PyObject_GetBuffer(o[got], &b[got], PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) == 0)
        got++;
    PyErr_Clear();
    int code = 1;
    double ferr = 0.0;
    if (got == 3) {
        idx m = b[1].len / 8;
        int fine = b[0].len == m * m * 8 && b[2].len == m * 8 && m <= MAX_M;
        for (int i = 0; i < 3 && fine; i++) {
            const char *f = b[i].format ? b[i].format : "B";
            if (*f == '<' || *f == '=' || *f == '@') f++;
            fine = b[i].itemsize == 8 && f[0] == 'd' && f[1] == 0;
        }
        if (fine)
            code = bound_one(m, (const double *)b[0].buf, (const double *)b[1].buf,
                             (const double *)b[2].buf, exact, &ferr);
    }
    for (int i = 0; i < got; i++) PyBuffer_Release(&b[i]);
    return Py_BuildValue("id", code, ferr);
}

static PyMethodDef methods[] = {
    {"bound", py_bound, METH_VARARGS,
     "bound(K, k, y, exact=False) -> (code, ferr): lcp/acceptance/accuracy.py's forward_bound "
     "at y (code 1: singular to working precision or not handled, run the numpy code); exact: "
     "|K^-1| formed even where the comparison-matrix bound certifies."},
    {"assess", py_assess, METH_VARARGS,
     "assess(M, q, z, basis, out) -> (code, berr, ferr, refined): lcp/accuracy.py's assess "
     "of an LCP answer on its basis (code 1: not handled, run the numpy code)."},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_accuracy_c",
                                    "lcp/accuracy.py's assess in C.", -1, methods};

PyMODINIT_FUNC PyInit__accuracy_c(void) { return PyModule_Create(&module); }
