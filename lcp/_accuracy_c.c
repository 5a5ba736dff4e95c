/* lcp/accuracy.py's `assess` for an LCP answer with a basis, in C (the common case of
 * lcp.solve, its fast paths and solve_many: a few microseconds at n = 10 instead of a hundred
 * numpy calls). The same steps as the numpy code: the componentwise backward error of z, the
 * pattern's system M_aa y = -q_a refined from z_a with residuals in long double (x86: 64-bit
 * mantissa, numpy's longdouble), LAPACK's forward error bound with the explicit inverse, and
 * the polished point kept when its backward error is not larger.
 *
 * assess(M, q, z, basis, out) -> (code, berr, ferr, refined)
 *   M n x n, q, z, out n (float64, C-contiguous), basis int64 (the basic indices a, m of them,
 *   distinct, in any order: they are sorted here).
 *   code 0: done (out holds the answer: the polished point when refined, else z);
 *   code 1: not handled here (basis out of range or repeated, m > MAX_M, M_aa singular to working
 *   precision by the numpy code's test, a number not finite): the numpy code runs.
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
#define MAX_M 400
#define STEPS 5

/* berr of lcp/accuracy.py (nu = 0). */
static double backward_error(idx n, const double *M, const double *q, const double *x,
                             double mmax, double qmax, double floor)
{
    double xmax = 0.0;
    for (idx i = 0; i < n; i++) xmax = fmax(xmax, fabs(x[i]));
    double vs = fmax(xmax, mmax > 0 ? qmax / mmax : 0.0);
    if (!(vs > 0)) vs = 1.0;
    double out = 0.0;
    for (idx i = 0; i < n; i++) {
        const double *row = M + i * n;
        double res = q[i], s = fabs(q[i]);
        for (idx j = 0; j < n; j++) {
            res += row[j] * x[j];
            s += fabs(row[j]) * fabs(x[j]);
        }
        s = fmax(s, floor);
        double wr = s > 0 ? res / s : (res == 0 ? 0.0 : copysign(INFINITY, res));
        double v = x[i] / vs, mn = v < wr ? v : wr;
        if (isnan(mn)) return INFINITY;
        out = fmax(out, fabs(mn));
    }
    return out;
}

/* inv = K^-1 (m x m, row-major) by LU with partial pivoting; -1 if a pivot is zero. */
static int inverse(idx m, double *A, double *inv, idx *perm)
{
    for (idx i = 0; i < m; i++) perm[i] = i;
    for (idx k = 0; k < m; k++) {
        idx p = k;
        for (idx i = k + 1; i < m; i++)
            if (fabs(A[i * m + k]) > fabs(A[p * m + k])) p = i;
        if (A[p * m + k] == 0.0) return -1;
        if (p != k) {
            for (idx j = 0; j < m; j++) {
                double t = A[k * m + j];
                A[k * m + j] = A[p * m + j];
                A[p * m + j] = t;
            }
            idx t = perm[k];
            perm[k] = perm[p];
            perm[p] = t;
        }
        for (idx i = k + 1; i < m; i++) {
            double l = A[i * m + k] / A[k * m + k];
            A[i * m + k] = l;
            for (idx j = k + 1; j < m; j++) A[i * m + j] -= l * A[k * m + j];
        }
    }
    /* column c of inv solves L U x = P e_c */
    double *x = inv + 0;  /* written column by column below, via a scratch column */
    double *col = (double *)malloc((size_t)m * sizeof(double));
    if (!col) return -1;
    for (idx c = 0; c < m; c++) {
        for (idx i = 0; i < m; i++) col[i] = perm[i] == c ? 1.0 : 0.0;
        for (idx i = 0; i < m; i++)
            for (idx j = 0; j < i; j++) col[i] -= A[i * m + j] * col[j];
        for (idx i = m - 1; i >= 0; i--) {
            for (idx j = i + 1; j < m; j++) col[i] -= A[i * m + j] * col[j];
            col[i] /= A[i * m + i];
        }
        for (idx i = 0; i < m; i++) x[i * m + c] = col[i];
    }
    free(col);
    return 0;
}

/* r = K y + k, accumulated in long double, rounded to double. */
static void residual_ld(idx m, const double *K, const double *k, const double *y, double *r)
{
    for (idx i = 0; i < m; i++) {
        long double s = (long double)k[i];
        for (idx j = 0; j < m; j++) s += (long double)K[i * m + j] * (long double)y[j];
        r[i] = (double)s;
    }
}

static int assess_one(idx n, const double *M, const double *q, const double *z,
                      const int64_t *a, idx m, double *out, double *res)
{
    const double eps = DBL_EPSILON, eps_ld = LDBL_EPSILON;
    double mmax = 0.0, qmax = 0.0;
    for (idx i = 0; i < n * n; i++) mmax = fmax(mmax, fabs(M[i]));
    for (idx i = 0; i < n; i++) qmax = fmax(qmax, fabs(q[i]));
    for (idx i = 0; i < n; i++)
        if (!isfinite(z[i]) || !isfinite(q[i])) return 1;
    if (!isfinite(mmax)) return 1;
    /* the data's scale (lcp/accuracy.py's data_scale): |q| + ||M||_inf |q| / |M|_max */
    double norm = 0.0;
    for (idx i = 0; i < n; i++) {
        double s = 0.0;
        for (idx j = 0; j < n; j++) s += fabs(M[i * n + j]);
        norm = fmax(norm, s);
    }
    double floor = mmax > 0 ? qmax + norm * (qmax / mmax) : qmax;
    char *mark = (char *)calloc((size_t)n, 1);
    if (!mark) return 1;
    for (idx i = 0; i < m; i++) {
        if (a[i] < 0 || a[i] >= n || mark[a[i]]) {
            free(mark);
            return 1;
        }
        mark[a[i]] = 1;
    }
    int64_t *sorted = (int64_t *)malloc(((size_t)m + 1) * sizeof(int64_t));
    if (!sorted) {
        free(mark);
        return 1;
    }
    for (idx i = 0, k = 0; i < n; i++)
        if (mark[i]) sorted[k++] = i;
    a = sorted;  /* the pattern in increasing order, whatever order the basis came in */
    double berr = backward_error(n, M, q, z, mmax, qmax, floor);
    double ferr = 0.0;
    int refined = 0;
    double *buf = (double *)malloc(((size_t)3 * m * m + 6 * (size_t)m + 1) * sizeof(double));
    idx *perm = (idx *)malloc(((size_t)m + 1) * sizeof(idx));
    if (!buf || !perm) {
        free(buf);
        free(perm);
        free(mark);
        free(sorted);
        return 1;
    }
    double *K = buf, *A = K + m * m, *inv = A + m * m, *kp = inv + m * m, *y = kp + m,
           *r = y + m, *d = r + m, *g = d + m, *rows = g + m;
    for (idx i = 0; i < m; i++) {
        kp[i] = q[a[i]];
        y[i] = z[a[i]];
        rows[i] = 0.0;
        for (idx j = 0; j < m; j++) {
            K[i * m + j] = M[a[i] * n + a[j]];
            rows[i] += fabs(K[i * m + j]);
        }
    }
    memcpy(A, K, (size_t)m * m * sizeof(double));
    int code = 0;
    if (m > 0) {
        if (inverse(m, A, inv, perm) < 0) code = 1;
        double cond = 0.0;
        for (idx i = 0; i < m && !code; i++) {
            double s = 0.0;
            for (idx j = 0; j < m; j++) s += fabs(inv[i * m + j]) * rows[j];
            if (!isfinite(s)) code = 1;
            cond = fmax(cond, s);
        }
        if (!code && cond * (double)m * eps > 1.0) code = 1;  /* singular: numpy's SVD path */
        if (!code) {
            double prev = INFINITY;
            for (int step = 0; step < STEPS; step++) {
                residual_ld(m, K, kp, y, r);
                double size = 0.0, ymax = 0.0;
                for (idx i = 0; i < m; i++) {
                    double s = 0.0;
                    for (idx j = 0; j < m; j++) s += inv[i * m + j] * r[j];
                    d[i] = s;
                    size = fmax(size, fabs(s));
                }
                if (!isfinite(size) || size >= prev) break;
                for (idx i = 0; i < m; i++) {
                    y[i] -= d[i];
                    ymax = fmax(ymax, fabs(y[i]));
                }
                prev = size;
                if (size <= eps * ymax) break;
            }
            residual_ld(m, K, kp, y, r);
            double ymax = 0.0;
            for (idx i = 0; i < m; i++) {
                double s = fabs(kp[i]);
                for (idx j = 0; j < m; j++) s += fabs(K[i * m + j]) * fabs(y[j]);
                g[i] = fabs(r[i]) + (double)(m + 1) * eps_ld * s;
                ymax = fmax(ymax, fabs(y[i]));
            }
            double bound = 0.0;
            for (idx i = 0; i < m; i++) {
                double s = 0.0;
                for (idx j = 0; j < m; j++) s += fabs(inv[i * m + j]) * g[j];
                bound = fmax(bound, s);
            }
            ferr = bound / fmax(ymax, 1e-300) + eps;
            if (!isfinite(ferr)) ferr = INFINITY;
        }
    }
    if (!code) {
        for (idx i = 0; i < n; i++) out[i] = 0.0;
        int finite = 1;
        for (idx i = 0; i < m; i++) {
            if (!isfinite(y[i])) finite = 0;
            out[a[i]] = y[i] > 0.0 ? y[i] : 0.0;
        }
        double bp = finite ? backward_error(n, M, q, out, mmax, qmax, floor) : INFINITY;
        if (finite && bp <= berr) {
            berr = bp;
            refined = 1;
        } else {
            double xs = 0.0, gap = 0.0;
            for (idx i = 0; i < n; i++) xs = fmax(xs, fabs(z[i]));
            xs = fmax(xs, 1e-300);
            for (idx i = 0; i < m; i++) gap = fmax(gap, fabs(z[a[i]] - y[i]));
            for (idx i = 0; i < n; i++)
                if (!mark[i]) gap = fmax(gap, fabs(z[i]));
            ferr = ferr + gap / xs;
            if (!isfinite(ferr)) ferr = INFINITY;
            memcpy(out, z, (size_t)n * sizeof(double));
        }
    }
    free(buf);
    free(perm);
    free(mark);
    free(sorted);
    res[0] = berr;
    res[1] = ferr;
    res[2] = refined;
    return code;
}

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
                              (const double *)vz.buf, (const int64_t *)va.buf, m,
                              (double *)vo.buf, res);
    }
    if (got >= 5) PyBuffer_Release(&vo);
    if (got >= 4) PyBuffer_Release(&va);
    if (got >= 3) PyBuffer_Release(&vz);
    if (got >= 2) PyBuffer_Release(&vq);
    if (got >= 1) PyBuffer_Release(&vM);
    return Py_BuildValue("iddi", code, res[0], res[1], (int)res[2]);
}

static PyMethodDef methods[] = {
    {"assess", py_assess, METH_VARARGS,
     "assess(M, q, z, basis, out) -> (code, berr, ferr, refined): lcp/accuracy.py's assess "
     "of an LCP answer on its basis (code 1: not handled, run the numpy code)."},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_accuracy_c",
                                    "lcp/accuracy.py's assess in C.", -1, methods};

PyMODINIT_FUNC PyInit__accuracy_c(void) { return PyModule_Create(&module); }
