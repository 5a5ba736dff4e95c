/* numpy's own BLAS call for M z, without going through numpy.dot (included by lcp/_lemke_c.c).
 *
 * lcp.residual's measure takes w = M.dot(z) (numpy: for a C-contiguous float64 n x n M, n >= 2,
 * and a vector z, numpy's cblas_matrixproduct calls cblas_dgemv(CblasRowMajor, CblasNoTrans,
 * n, n, 1.0, M, n, z, 1, 0.0, w, 1) of the BLAS it was built with). The C fast path wants the
 * same numbers; calling numpy.dot from C costs about 0.4 us at n = 10 (argument parsing, the
 * output checks, the floating-point flags), a third of the C work of a small solve. So the
 * Python side (lcp/_lemke_kernel.py: numpy_gemv) finds that very function in the library numpy
 * loaded -- scipy-openblas's scipy_cblas_dgemv64_ (64-bit integers) or scipy_cblas_dgemv
 * (32-bit), by its address from ctypes -- hands it here with gemv_setup, and checks on a probe
 * that gemv gives numpy.dot's numbers bit for bit; anything else (another BLAS, no match)
 * leaves the pointer unset and the callers call numpy.dot as before.
 *
 *   gemv_setup(address, ilp64): the function (0: none).
 *   gemv(M, z, w): w = M z by it (M n x n C-contiguous float64, z and w n float64); False when
 *     no function is set (w untouched). */
#ifndef RIGIDLCP_BLAS_H
#define RIGIDLCP_BLAS_H

#define CBLAS_ROW_MAJOR 101
#define CBLAS_NO_TRANS 111
typedef void (*gemv64_fn)(int, int, int64_t, int64_t, double, const double *, int64_t,
                          const double *, int64_t, double, double *, int64_t);
typedef void (*gemv32_fn)(int, int, int32_t, int32_t, double, const double *, int32_t,
                          const double *, int32_t, double, double *, int32_t);
static void *s_gemv = NULL; /* numpy's cblas_dgemv, when found and checked */
static int s_gemv_ilp64 = 0;

/* w = M z by numpy's cblas_dgemv (the caller checked s_gemv and n >= 2; n <= INT32_MAX for
 * the 32-bit one). */
static void blas_mz(idx n, const double *M, const double *z, double *w)
{
    if (s_gemv_ilp64)
        ((gemv64_fn)s_gemv)(CBLAS_ROW_MAJOR, CBLAS_NO_TRANS, n, n, 1.0, M, n, z, 1, 0.0, w, 1);
    else
        ((gemv32_fn)s_gemv)(CBLAS_ROW_MAJOR, CBLAS_NO_TRANS, (int32_t)n, (int32_t)n, 1.0, M,
                            (int32_t)n, z, 1, 0.0, w, 1);
}

/* May M z be taken by blas_mz? (numpy multiplies 1 x 1 by a scalar product, not by gemv) */
static int blas_ok(idx n) { return s_gemv && n >= 2 && (s_gemv_ilp64 || n <= INT32_MAX); }

static PyObject *py_gemv_setup(PyObject *self, PyObject *args)
{
    unsigned long long address;
    int ilp64;
    (void)self;
    if (!PyArg_ParseTuple(args, "Kp", &address, &ilp64)) return NULL;
    s_gemv = (void *)(uintptr_t)address;
    s_gemv_ilp64 = ilp64;
    Py_RETURN_NONE;
}

static PyObject *py_gemv(PyObject *self, PyObject *args)
{
    PyObject *oM, *oz, *ow;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &oM, &oz, &ow)) return NULL;
    idx n = PyObject_Length(oz);
    if (n < 0) return NULL;
    if (!blas_ok(n)) Py_RETURN_FALSE;
    Py_buffer vM, vz, vw;
    if (get_buffer(oz, &vz, "z", 'd', n, 0) < 0) return NULL;
    if (get_buffer(ow, &vw, "w", 'd', n, 0) < 0) {
        PyBuffer_Release(&vz);
        return NULL;
    }
    if (get_buffer(oM, &vM, "M", 'd', n * n, 0) < 0) {
        PyBuffer_Release(&vw);
        PyBuffer_Release(&vz);
        return NULL;
    }
    blas_mz(n, (const double *)vM.buf, (const double *)vz.buf, (double *)vw.buf);
    PyBuffer_Release(&vM);
    PyBuffer_Release(&vw);
    PyBuffer_Release(&vz);
    Py_RETURN_TRUE;
}

#endif /* RIGIDLCP_BLAS_H */
