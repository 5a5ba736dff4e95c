/* The acceptance measure of lcp/acceptance/residual.py in C (included by lcp/_lemke_c.c): the
 * row sums of |M| in numpy's pairwise order (and their AVX2 clone with the pass over M),
 * measure_one, and the entry points abs_row_sums, lcp_measure and lcp_measure_batch. The
 * includer includes <Python.h>, acceptance/_accuracy_core.h (abs_max_finite_avx2),
 * _lemke_run.h (HAVE_AVX2_CLONE, cpu_avx2) and _lemke_py.h (get_buffer). */
#ifndef RIGIDLCP_LEMKE_MEASURE_H
#define RIGIDLCP_LEMKE_MEASURE_H

/* ------------------------------------------------------------------ the acceptance measure */
/* sum_j |a_j| in numpy's order: its pairwise summation (numpy's `pairwise_sum`, used by
 * np.add.reduce over a contiguous axis, started from the identity 0): a plain loop below 8
 * terms, eight interleaved partial sums up to 128, halves (at a multiple of 8) above. The
 * Python side checks once, on a probe, that numpy sums so (lcp/_lemke_kernel.py). */
static double pairwise_abs(const double *a, idx n)
{
#define ABS(x) fabs(x)
    if (n < 8) {
        double res = 0.0;
        for (idx i = 0; i < n; i++) res += ABS(a[i]);
        return res;
    }
    if (n <= 128) {
        double r[8];
        for (int j = 0; j < 8; j++) r[j] = ABS(a[j]);
        idx i;
        for (i = 8; i < n - (n % 8); i += 8)
            for (int j = 0; j < 8; j++) r[j] += ABS(a[i + j]);
        double res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        for (; i < n; i++) res += ABS(a[i]);
        return res;
    }
    idx n2 = n / 2;
    n2 -= n2 % 8;
    return pairwise_abs(a, n2) + pairwise_abs(a + n2, n - n2);
#undef ABS
}

#if HAVE_AVX2_CLONE
/* pairwise_abs four lanes wide: the eight partial sums in two registers, each lane adding the
 * same terms in the same order as the scalar r[j] (|x| by clearing the sign bit, as fabs), so
 * the sum is the same number. */
__attribute__((target("avx2"))) static double pairwise_abs_avx2(const double *a, idx n)
{
    if (n < 8) {
        double res = 0.0;
        for (idx i = 0; i < n; i++) res += fabs(a[i]);
        return res;
    }
    if (n <= 128) {
        const __m256d sign = _mm256_set1_pd(-0.0);
        __m256d r0 = _mm256_andnot_pd(sign, _mm256_loadu_pd(a));
        __m256d r1 = _mm256_andnot_pd(sign, _mm256_loadu_pd(a + 4));
        idx i;
        for (i = 8; i < n - (n % 8); i += 8) {
            r0 = _mm256_add_pd(r0, _mm256_andnot_pd(sign, _mm256_loadu_pd(a + i)));
            r1 = _mm256_add_pd(r1, _mm256_andnot_pd(sign, _mm256_loadu_pd(a + i + 4)));
        }
        double r[8];
        _mm256_storeu_pd(r, r0);
        _mm256_storeu_pd(r + 4, r1);
        double res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        for (; i < n; i++) res += fabs(a[i]);
        return res;
    }
    idx n2 = n / 2;
    n2 -= n2 % 8;
    return pairwise_abs_avx2(a, n2) + pairwise_abs_avx2(a + n2, n - n2);
}

/* measure_one's pass over M (finiteness, max|M|, the row sums of |M| in numpy's order), with
 * pairwise_abs_avx2 and _accuracy_core.h's abs_max_finite_avx2; `known`: M is finite and
 * *mmax already max|M| (measure_known), so only the row sums are taken. */
__attribute__((target("avx2"))) static int m_pass_avx2(idx n, const double *M, double *mmax,
                                                       double *norm, int known)
{
    int finite = 1;
    for (idx i = 0; i < n; i++) {
        const double *Mi = M + i * n;
        if (!known) finite &= abs_max_finite_avx2(Mi, n, mmax);
        double row = 0.0 + pairwise_abs_avx2(Mi, n);
        finite &= row <= DBL_MAX;
        *norm = row > *norm ? row : *norm;
    }
    return finite;
}

#endif

/* abs_row_sums(M, out): out[i] = 0 + sum_j |M_ij| summed as numpy's np.add.reduce(np.abs(M),
 * axis=1) (M m x n C-contiguous float64, out m float64): the probe of lcp/_lemke_kernel.py. */
static PyObject *py_abs_row_sums(PyObject *self, PyObject *args)
{
    PyObject *oM, *oout;
    idx n;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOn", &oM, &oout, &n)) return NULL;
    idx m = PyObject_Length(oout);
    if (m < 1 || n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "empty");
        return NULL;
    }
    Py_buffer vM, vo;
    if (get_buffer(oout, &vo, "out", 'd', m, 0) < 0) return NULL;
    if (get_buffer(oM, &vM, "M", 'd', m * n, 0) < 0) {
        PyBuffer_Release(&vo);
        return NULL;
    }
    for (idx i = 0; i < m; i++)
        ((double *)vo.buf)[i] = 0.0 + pairwise_abs((const double *)vM.buf + i * n, n);
    PyBuffer_Release(&vM);
    PyBuffer_Release(&vo);
    Py_RETURN_NONE;
}

/* One LCP's measure (see lcp_measure below): 0 and w = Mz + q written, or -1 (nothing written)
 * when a number is not finite. mmax_in >= 0: M is known finite and max|M| = mmax_in (the
 * solve measured it: solve_and_accept's *mmax), so the pass over M takes only the row sums
 * (max|M| is the same number in any order); negative: measured here. */
static int measure_known(idx n, const double *M, const double *q, const double *z, double *w,
                         double out[4], double mmax_in)
{
    const int known = mmax_in >= 0;
    double mmax = known ? mmax_in : 0.0, qmax = 0.0, zmax = 0.0, norm = 0.0;
    int finite = 1; /* branch-free maxima and finiteness test, as in balanced_units */
#if HAVE_AVX2_CLONE
    int wide = cpu_avx2(); /* M's pass four lanes wide: the same numbers (see m_pass_avx2) */
    if (wide) finite = m_pass_avx2(n, M, &mmax, &norm, known);
#else
    const int wide = 0;
#endif
    for (idx i = 0; i < n; i++) {
        if (!wide) {
            const double *Mi = M + i * n;
            for (idx j = 0; !known && j < n; j++) {
                double a = fabs(Mi[j]);
                finite &= a <= DBL_MAX;
                mmax = a > mmax ? a : mmax;
            }
            double row = 0.0 + pairwise_abs(Mi, n);
            norm = row > norm ? row : norm;
            finite &= row <= DBL_MAX;
        }
        double aq = fabs(q[i]), az = fabs(z[i]), wi = fabs(w[i] + q[i]);
        finite &= (aq <= DBL_MAX) & (az <= DBL_MAX) & (wi <= DBL_MAX);
        qmax = aq > qmax ? aq : qmax;
        zmax = az > zmax ? az : zmax;
    }
    /* residual.py: zs = max(zmax, qmax / mmax if mmax > 0 else 0.0), 1 if 0;
     * ws = qmax + norm_inf(M) * zs, 1 if not > 0 */
    double ratio = mmax > 0 ? qmax / mmax : 0.0;
    double zs = ratio > zmax ? ratio : zmax;
    if (zs == 0.0) zs = 1.0;
    double prod = norm * zs;
    double ws = qmax + prod;
    if (!(ws > 0)) ws = 1.0;
    if (!(finite && zs <= DBL_MAX && ws <= DBL_MAX)) return -1;
    double scaled = 0.0, raw = 0.0;
    for (idx i = 0; i < n; i++) {
        double wi = w[i] + q[i];
        w[i] = wi;
        double a = z[i] / zs, b = wi / ws, m = fabs(a < b ? a : b);
        scaled = m > scaled ? m : scaled;
        double m2 = fabs(z[i] < wi ? z[i] : wi);
        raw = m2 > raw ? m2 : raw;
    }
    out[0] = raw;
    out[1] = scaled;
    out[2] = zs;
    out[3] = ws;
    return 0;
}

/* measure_known with max|M| measured here. */
static int measure_one(idx n, const double *M, const double *q, const double *z, double *w,
                       double out[4])
{
    return measure_known(n, M, q, z, w, out, -1.0);
}

/* float64 C-contiguous buffers of the given sizes (objs[i], writable where asked), all or none:
 * the number acquired (< count: some failed, those released, no error set). */
static int get_doubles(PyObject **objs, Py_buffer *v, const idx *sizes, const int *writable,
                       int count)
{
    for (int i = 0; i < count; i++) {
        int flags = PyBUF_FORMAT | PyBUF_C_CONTIGUOUS | (writable[i] ? PyBUF_WRITABLE : 0);
        int ok = PyObject_GetBuffer(objs[i], &v[i], flags) == 0;
        if (ok) {
            const char *f = v[i].format ? v[i].format : "B";
            if (*f == '<' || *f == '=' || *f == '@') f++;
            ok = v[i].itemsize == 8 && f[0] == 'd' && f[1] == 0 && v[i].len / 8 == sizes[i];
            if (!ok) PyBuffer_Release(&v[i]);
        }
        if (!ok) {
            for (int j = 0; j < i; j++) PyBuffer_Release(&v[j]);
            PyErr_Clear();
            return i;
        }
    }
    return count;
}

/* lcp_measure(M, q, z, Mz) -> (residual, scaled residual, z_s, w_s), or None: lcp/residual.py's
 * `lcp_measure` after numpy's M.dot(z): w = Mz + q (written into Mz), the row sums of |M| in
 * numpy's order, and the rest -- maxima, the scales, the minima -- by the operations the numpy
 * code does, on finite numbers (the same roundings; no fused multiply-add: setup.py builds with
 * -ffp-contract=off). None, with Mz untouched, when an input is not a float64 C-contiguous
 * array of the right length or a number is not finite: the numpy code measures then. */
static PyObject *py_lcp_measure(PyObject *self, PyObject *args)
{
    PyObject *objs[4];
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOO", &objs[0], &objs[1], &objs[2], &objs[3])) return NULL;
    idx n = PyObject_Length(objs[1]);
    if (n < 1) {
        PyErr_Clear();
        Py_RETURN_NONE;
    }
    Py_buffer v[4];
    idx sizes[4] = {n * n, n, n, n};
    int writable[4] = {0, 0, 0, 1};
    if (get_doubles(objs, v, sizes, writable, 4) < 4) Py_RETURN_NONE;
    double out[4];
    int ok = measure_one(n, (const double *)v[0].buf, (const double *)v[1].buf,
                         (const double *)v[2].buf, (double *)v[3].buf, out) == 0;
    for (int i = 0; i < 4; i++) PyBuffer_Release(&v[i]);
    if (!ok) Py_RETURN_NONE;
    return Py_BuildValue("dddd", out[0], out[1], out[2], out[3]);
}

/* lcp_measure_batch(Ms, qs, Z, MZ, out, mmax=None) -> bool: `lcp_measure` of k problems (Ms k n
 * n, qs, Z, MZ k n, out k 4 float64, C-contiguous): row p of out receives (residual, scaled,
 * z_s, w_s) and MZ[p] becomes w = M z + q, or out[p] is NaN (MZ[p] untouched) when a number is
 * not finite. False when the arrays are not as described. mmax (k float64, solve_batch's):
 * where mmax[p] >= 0, M_p is finite and max|M_p| = mmax[p] (measure_known: the row sums
 * only; the maximum of finite numbers is the same in any order); else measured here. */
static PyObject *py_lcp_measure_batch(PyObject *self, PyObject *args)
{
    PyObject *objs[6] = {NULL, NULL, NULL, NULL, NULL, Py_None};
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOO|O", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4],
                          &objs[5]))
        return NULL;
    idx k = PyObject_Length(objs[1]), n = 0;
    Py_buffer vz;
    if (k >= 1 && PyObject_GetBuffer(objs[2], &vz, PyBUF_ND) == 0) {
        if (vz.ndim == 2) n = vz.shape[1];
        PyBuffer_Release(&vz);
    }
    PyErr_Clear();
    Py_buffer v[6];
    idx sizes[6] = {k * n * n, k * n, k * n, k * n, 4 * k, k};
    int writable[6] = {0, 0, 0, 1, 1, 0}, count = objs[5] == Py_None ? 5 : 6;
    if (n < 1 || get_doubles(objs, v, sizes, writable, count) < count) Py_RETURN_FALSE;
    const double *Ms = (const double *)v[0].buf, *qs = (const double *)v[1].buf,
                 *Z = (const double *)v[2].buf, *mx = count == 6 ? (const double *)v[5].buf : NULL;
    double *W = (double *)v[3].buf, *out = (double *)v[4].buf;
    for (idx p = 0; p < k; p++)
        if (measure_known(n, Ms + p * n * n, qs + p * n, Z + p * n, W + p * n, out + 4 * p,
                          mx ? mx[p] : -1.0) < 0)
            for (int j = 0; j < 4; j++) out[4 * p + j] = 0.0 / 0.0;
    for (int i = 0; i < count; i++) PyBuffer_Release(&v[i]);
    Py_RETURN_TRUE;
}

#endif /* RIGIDLCP_LEMKE_MEASURE_H */
