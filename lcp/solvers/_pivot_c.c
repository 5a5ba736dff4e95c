/* The common case of method `pivoting` (lcp/solvers/pivoting.py) in C, for lcp.solve's fast path
 * (lcp/solvers/fast_pivoting.py): the Ruiz equilibration of a balanced M (or the factors of `ruiz`
 * given), then block principal pivoting steps only -- each failing index flipped at once, as
 * long as |H| lowers its record or tries remain, each new basis nonsingular by the same test --
 * until no inequality fails; z in the user's units. Anything else the Python method would do (a
 * singular basis, a single or exchange pivot, the iteration limit, a number that is not finite)
 * returns code DECLINE and the general path runs from the start.
 *
 * The numbers are those of the numpy code, bit for bit: LAPACK's dgetrf / dgecon / dgetrs and
 * BLAS's dgemv / ddot are scipy's own (function pointers from the PyCapsules of
 * scipy.linalg.cython_lapack and cython_blas, passed once by `init`), called as
 * scipy.linalg.lapack's wrappers and numpy's matmul call them (a matrix-vector product of a
 * C-contiguous matrix: gemv 'T' on its rows; an 1 x 1 one: 0 + ddot); the rest -- sums, maxima,
 * the sign tests -- are the numpy operations in numpy's order. lcp/solvers/fast_pivoting.py checks once,
 * on a probe, that scipy's gemv rounds as numpy's matmul (numpy links its own BLAS), and
 * tests/lcp/test_fast_pivoting.py compares whole Solutions.
 *
 * Only the buffer protocol is used (no numpy headers), so the build needs a C compiler only.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef Py_ssize_t idx;

typedef void getrf_t(int *, int *, double *, int *, int *, int *);
typedef void gecon_t(char *, int *, double *, int *, double *, double *, double *, int *, int *);
typedef void getrs_t(char *, int *, int *, double *, int *, int *, double *, int *, int *);
typedef void gemv_t(char *, int *, int *, double *, double *, int *, double *, int *, double *,
                    double *, int *);
typedef double dot_t(int *, double *, int *, double *, int *);

static getrf_t *getrf;
static gecon_t *gecon;
static getrs_t *getrs;
static gemv_t *gemv;
static dot_t *ddot;

#define SOLVED 0
#define DECLINE 1
#define RCOND 1e-13   /* lcp/solvers/pivoting.py */
#define FLOOR 1e-4    /* lcp/solvers/pivoting.py */

/* y = A x as numpy's matmul computes it for A m x m C-contiguous, x of length m: gemv 'T' on
 * the rows (numpy's DOUBLE_gemv: cblas ColMajor Trans), or 0 + ddot when m = 1. */
static void matvec(int m, const double *A, const double *x, double *y)
{
    int one = 1;
    if (m == 1) {
        y[0] = 0.0 + ddot(&one, (double *)A, &one, (double *)x, &one);
        return;
    }
    char t = 'T';
    double alpha = 1.0, beta = 0.0;
    gemv(&t, &m, &m, &alpha, (double *)A, &m, (double *)x, &one, &beta, y, &one);
}

#include "../_balanced.h" /* balanced_units, pow2_near: shared with _lemke_c.c */

/* A complementary basis (pivoting.py's _Basis): a (m indices), Maa row-major, lu column-major. */
typedef struct {
    int m;
    idx *a;
    char *alpha;
    double *Maa, *lu;
    int *ipiv;
} Basis;

typedef struct {
    idx n;
    const double *M, *q; /* the equilibrated data M~ (row-major), q~ */
    double *work, *t;    /* 4n, n */
    int *iwork;
} Ctx;

/* float(np.max(np.sum(np.abs(A), axis=0))) for A m x m C-contiguous (m >= 1): numpy adds the
 * rows in order (a reduction over the outer axis); t: scratch of m. */
static double col_abs_max(int m, const double *A, double *t)
{
    double anorm = 0.0;
    for (int j = 0; j < m; j++) t[j] = 0.0;
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) t[j] += fabs(A[i * m + j]);
    for (int j = 0; j < m; j++) anorm = t[j] > anorm ? t[j] : anorm;
    return anorm;
}

/* An upper bound on the estimate of ||A^-1||_1 that dgecon('1') computes from the LU factors
 * lu (column order, m x m, nonzero diagonal), or +inf.
 *
 * dgecon estimates ||U^-1 L^-1||_1 (the row permutation does not change a 1-norm) by dlacn2:
 * each estimate is ||y||_1 / ||x||_1 for a computed y = U^-1 (L^-1 x) (dlatrs: triangular
 * solves), x = e/n, e_j or dlacn2's alternating vector. A computed triangular solve is exact
 * for T + dT with |dT| <= gamma |T| (Higham, Accuracy and Stability, Thm 8.5), and for
 * triangular T |T^-1| <= M(T)^-1, M(T) the comparison matrix (|t_ii| on the diagonal,
 * -|t_ij| off it), which grows entrywise as |T| shrinks. So |y| <= M'(U)^-1 M'(L)^-1 |x| with
 * M' the comparison matrices of |T| (1 -/+ gamma), and every estimate is at most
 * ||M'(U)^-1 M'(L)^-1||_1 = max(M'(L)^-T M'(U)^-T e): two substitutions of nonnegative terms.
 * r, s: scratch of m. */
static double inv_norm_bound(int m, const double *lu, double *r, double *s)
{
    double gam = 4.0 * (m + 2) * DBL_EPSILON, up = 1.0 + gam, dn = 1.0 - gam, B = 0.0;
    for (int i = 0; i < m; i++) { /* M'(U)^T r = e: lower triangular */
        double acc = 1.0;
        for (int j = 0; j < i; j++) acc += up * fabs(lu[j + i * m]) * r[j];
        r[i] = acc / (dn * fabs(lu[i + i * m]));
    }
    for (int i = m - 1; i >= 0; i--) { /* M'(L)^T s = r: upper triangular, unit diagonal */
        double acc = r[i];
        for (int j = i + 1; j < m; j++) acc += up * fabs(lu[j + i * m]) * s[j];
        s[i] = acc / dn;
        if (!(s[i] <= DBL_MAX)) return INFINITY; /* overflow or NaN: let dgecon decide */
        B = s[i] > B ? s[i] : B;
    }
    return B;
}

/* dgecon's rcond = (1 / ainvnm) / anorm is >= RCOND whenever anorm * ainvnm <= 0.1 / RCOND
 * (a factor 10 of margin for the roundings of the bound and of the two divisions; dlatrs
 * scales only near overflow, far from these numbers): then the basis is nonsingular by pivoting.py's test and
 * dgecon (about 17 000 instructions at m = 6, most of the basis's cost) need not run. */
#define RCOND_BOUND (0.1 / RCOND)

/* _Basis.__init__ for the index set B->alpha: 1 when M_aa is singular by pivoting.py's test. */
static int factor(const Ctx *C, Basis *B)
{
    idx n = C->n;
    int m = 0;
    for (idx i = 0; i < n; i++)
        if (B->alpha[i]) B->a[m++] = i;
    B->m = m;
    if (!m) return 0;
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            double v = C->M[B->a[i] * n + B->a[j]];
            B->Maa[i * m + j] = v;
            B->lu[i + j * m] = v;
        }
    double anorm = col_abs_max(m, B->Maa, C->t);
    int info = 0;
    getrf(&m, &m, B->lu, &m, B->ipiv, &info);
    for (int i = 0; i < m; i++)
        if (B->lu[i + i * m] == 0.0) return 1;
    if (anorm > 0.0 && anorm * inv_norm_bound(m, B->lu, C->work, C->work + m) <= RCOND_BOUND)
        return 0; /* dgecon would find rcond >= RCOND (see inv_norm_bound) */
    double rcond = 0.0;
    char norm = '1';
    gecon(&norm, &m, B->lu, &m, &anorm, &rcond, C->work, C->iwork, &info);
    return !(rcond >= RCOND);
}

/* x <- M_aa^{-1} x (dgetrs 'N', as scipy's lu_solve). */
static void lu_solve(const Basis *B, double *x)
{
    char tr = 'N';
    int one = 1, info = 0, m = B->m;
    getrs(&tr, &m, &one, B->lu, &m, B->ipiv, x, &m, &info);
}

/* _Basis.zw: z (zero off a) and w = M z + q; za, t: scratch of n. */
static void zw(const Ctx *C, const Basis *B, double *z, double *w, double *za)
{
    idx n = C->n;
    int m = B->m;
    for (idx i = 0; i < n; i++) z[i] = 0.0;
    if (m) {
        double *t = C->t;
        for (int i = 0; i < m; i++) za[i] = C->q[B->a[i]];
        lu_solve(B, za);
        for (int i = 0; i < m; i++) za[i] = -za[i];
        matvec(m, B->Maa, za, t);
        for (int i = 0; i < m; i++) t[i] = t[i] + C->q[B->a[i]];
        lu_solve(B, t);
        for (int i = 0; i < m; i++) z[B->a[i]] = za[i] - t[i];
    }
    matvec((int)n, C->M, z, w);
    for (idx i = 0; i < n; i++) w[i] = w[i] + C->q[i];
}

/* The pivoting loop on M~, q~ while only block steps are needed. SOLVED: z~ in z, the final
 * basis in *B, *it block steps, *flips; DECLINE otherwise. */
static int block_loop(const Ctx *C, Basis *B, Basis *trial, const double *absM, double mscale,
                      double qmax, double tol, long long block_tries, long long max_iter,
                      double *z, double *w, double *ws, double *za, long long *it,
                      long long *flips)
{
    idx n = C->n;
    long long record = n + 1, tries = block_tries;
    *it = *flips = 0;
    if (factor(C, B)) return DECLINE; /* a rejected warm start: the Python path reports it */
    for (;;) {
        zw(C, B, z, w, za);
        double zmax = 0.0;
        for (idx i = 0; i < n; i++) {
            if (!(fabs(z[i]) <= DBL_MAX && fabs(w[i]) <= DBL_MAX)) return DECLINE;
            zmax = fabs(z[i]) > zmax ? fabs(z[i]) : zmax;
        }
        double ratio = qmax / mscale, zscale = ratio > zmax ? ratio : zmax;
        for (idx i = 0; i < n; i++) za[i] = fabs(z[i]);
        matvec((int)n, absM, za, ws);
        double wmax = 0.0;
        for (idx i = 0; i < n; i++) {
            ws[i] = fabs(C->q[i]) + ws[i];
            if (!(ws[i] <= DBL_MAX)) return DECLINE;
            wmax = ws[i] > wmax ? ws[i] : wmax;
        }
        double floor_ = FLOOR * wmax, zt = -tol * zscale, mt = -tol;
        long long h = 0;
        for (idx i = 0; i < n; i++) {
            double wsi = ws[i] > floor_ ? ws[i] : floor_;
            char bad = B->alpha[i] ? z[i] < zt : w[i] < mt * wsi;
            trial->alpha[i] = B->alpha[i] ^ bad;
            h += bad;
        }
        if (h == 0) return SOLVED;
        if (*it >= max_iter) return DECLINE;
        *it += 1;
        if (h < record) {
            record = h;
            tries = block_tries;
        } else if (tries > 0) {
            tries -= 1;
        } else {
            return DECLINE; /* a single pivot */
        }
        if (factor(C, trial)) return DECLINE;
        Basis s = *B;
        *B = *trial;
        *trial = s;
        *flips += h;
    }
}

#include "../_buffer.h" /* get_buffer: shared with _lemke_c.c */

static int get_input(PyObject *obj, Py_buffer *view, const char *name, idx size)
{
    view->obj = NULL;
    if (obj == Py_None) return 0;
    if (PyObject_GetBuffer(obj, view, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) return -1;
    const char *f = view->format ? view->format : "B";
    if (*f == '<' || *f == '=' || *f == '@') f++;
    if (view->itemsize != 8 || f[0] != 'd' || f[1] != 0 || view->len / 8 != size) {
        PyErr_Format(PyExc_ValueError, "%s: expected %zd float64 values", name, size);
        PyBuffer_Release(view);
        view->obj = NULL;
        return -1;
    }
    return 0;
}

static void release(Py_buffer *v)
{
    if (v->obj) PyBuffer_Release(v);
}

/* The whole problem: equilibration, block loop, z = c max(z~, 0). */
static int solve_problem(idx n, const double *M, const double *q, const double *r,
                         const double *c, double tol, long long block_tries, long long max_iter,
                         double *zout, int64_t *basis, idx *nb, long long *it, long long *flips,
                         double bound[3])
{
    size_t nd = (size_t)n;
    double *mem = malloc(sizeof(double) * (7 * nd * nd + 12 * nd + 8));
    idx *ia = malloc(sizeof(idx) * 2 * nd + sizeof(int) * 3 * nd + 2 * nd + 16);
    if (!mem || !ia) {
        free(mem);
        free(ia);
        return -1;
    }
    double *Mt = mem, *absM = Mt + nd * nd, *qt = absM + nd * nd, *z = qt + nd, *w = z + nd,
           *ws = w + nd, *za = ws + nd, *t = za + nd, *work = t + nd, *dbl = work + 4 * nd;
    Basis B[2];
    B[0].a = ia;
    B[1].a = ia + nd;
    int *ints = (int *)(ia + 2 * nd);
    B[0].ipiv = ints;
    B[1].ipiv = ints + nd;
    char *chars = (char *)(ints + 3 * nd);
    B[0].alpha = chars;
    B[1].alpha = chars + nd;
    for (int k = 0; k < 2; k++) {
        B[k].Maa = dbl + 2 * k * nd * nd;
        B[k].lu = B[k].Maa + nd * nd;
    }
    Ctx C = {n, Mt, qt, work, t, ints + 2 * nd};
    double rs = 1.0, cs = 1.0;
    int code = 0;
    if (!r) code = balanced_units(n, M, q, t, &rs, &cs, NULL);
    if (code) goto out;
    /* lcp/acceptance/scaling.py: M * r[:, None] * c[None, :] and q * r; max|M|, max|q| of the data */
    double mmax = 0.0, qmax = 0.0, mscale = 0.0, qtmax = 0.0;
    int finite = 1;
    for (idx i = 0; i < n; i++) {
        double ri = r ? r[i] : rs;
        for (idx j = 0; j < n; j++) {
            double m = M[i * n + j], v = (m * ri) * (c ? c[j] : cs);
            finite &= (fabs(m) <= DBL_MAX) & (fabs(v) <= DBL_MAX);
            Mt[i * n + j] = v;
            absM[i * n + j] = fabs(v);
            mmax = fabs(m) > mmax ? fabs(m) : mmax;
            mscale = fabs(v) > mscale ? fabs(v) : mscale;
        }
        double v = q[i] * ri;
        finite &= (fabs(q[i]) <= DBL_MAX) & (fabs(v) <= DBL_MAX);
        qt[i] = v;
        qmax = fabs(q[i]) > qmax ? fabs(q[i]) : qmax;
        qtmax = fabs(v) > qtmax ? fabs(v) : qtmax;
        B[0].alpha[i] = v < 0;
    }
    if (!finite) {
        code = NOT_FINITE;
        goto out;
    }
    if (mscale == 0.0) mscale = 1.0; /* float(np.max(np.abs(M))) or 1.0 */
    bound[0] = mmax;
    bound[1] = qmax;
    Basis *cur = &B[0], *trial = &B[1];
    code = block_loop(&C, cur, trial, absM, mscale, qtmax, tol, block_tries, max_iter, z, w, ws,
                      za, it, flips);
    if (code != SOLVED) goto out;
    double zmax = 0.0;
    for (idx j = 0; j < n; j++) {
        double v = (c ? c[j] : cs) * (z[j] > 0.0 ? z[j] : 0.0); /* np.maximum(z, 0.0) */
        zout[j] = v;
        zmax = fabs(v) > zmax ? fabs(v) : zmax;
    }
    bound[2] = zmax;
    for (int i = 0; i < cur->m; i++) basis[i] = cur->a[i];
    *nb = cur->m;
out:
    free(mem);
    free(ia);
    return code;
}

/* solve(M, q, r, c, tol, block_tries, max_iter, z, basis) -> (code, it, nbasis, flips,
 * (max|M|, max|q|, max|z|)): see the top of this file and lcp/solvers/fast_pivoting.py. */
static PyObject *py_solve(PyObject *self, PyObject *args)
{
    PyObject *oM, *oq, *or_, *oc, *oz, *ob;
    double tol;
    long long block_tries, max_iter;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOdLLOO", &oM, &oq, &or_, &oc, &tol, &block_tries,
                          &max_iter, &oz, &ob))
        return NULL;
    if (!getrf) {
        PyErr_SetString(PyExc_RuntimeError, "init() was not called");
        return NULL;
    }
    idx n = PyObject_Length(oq);
    if (n < 1 || n > 46000) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "q: size");
        return NULL;
    }
    if ((or_ == Py_None) != (oc == Py_None)) {
        PyErr_SetString(PyExc_ValueError, "r and c: both None or both given");
        return NULL;
    }
    Py_buffer vM = {0}, vq = {0}, vr = {0}, vc = {0}, vz = {0}, vb = {0};
    PyObject *result = NULL;
    if (get_input(oq, &vq, "q", n) < 0 || get_input(oM, &vM, "M", n * n) < 0 ||
        get_input(or_, &vr, "r", n) < 0 || get_input(oc, &vc, "c", n) < 0)
        goto done;
    if (oq == Py_None || oM == Py_None) {
        PyErr_SetString(PyExc_ValueError, "M, q: arrays");
        goto done;
    }
    if (get_buffer(oz, &vz, "z", 'd', n, 0) < 0) goto done;
    if (get_buffer(ob, &vb, "basis", 'q', n, 0) < 0) goto done;
    long long it = 0, flips = 0;
    idx nb = 0;
    double bound[3] = {0.0, 0.0, 0.0};
    int code = solve_problem(n, vM.buf, vq.buf, vr.obj ? vr.buf : NULL, vc.obj ? vc.buf : NULL,
                             tol, block_tries, max_iter, vz.buf, vb.buf, &nb, &it, &flips,
                             bound);
    if (code < 0)
        PyErr_NoMemory();
    else
        result = Py_BuildValue("iLnL(ddd)", code, it, nb, flips, bound[0], bound[1], bound[2]);
done:
    release(&vb);
    release(&vz);
    release(&vc);
    release(&vr);
    release(&vM);
    release(&vq);
    return result;
}

/* matvec(A, x, y): y = A x by `matvec` (for the probe of lcp/solvers/fast_pivoting.py). */
static PyObject *py_matvec(PyObject *self, PyObject *args)
{
    PyObject *oA, *ox, *oy;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &oA, &ox, &oy)) return NULL;
    if (!gemv) {
        PyErr_SetString(PyExc_RuntimeError, "init() was not called");
        return NULL;
    }
    idx n = PyObject_Length(ox);
    if (n < 1 || n > 46000) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "x: size");
        return NULL;
    }
    Py_buffer vA, vx, vy;
    if (get_input(oA, &vA, "A", n * n) < 0) return NULL;
    if (get_input(ox, &vx, "x", n) < 0) {
        release(&vA);
        return NULL;
    }
    if (get_buffer(oy, &vy, "y", 'd', n, 0) < 0) {
        release(&vx);
        release(&vA);
        return NULL;
    }
    matvec((int)n, vA.buf, vx.buf, vy.buf);
    release(&vy);
    release(&vx);
    release(&vA);
    Py_RETURN_NONE;
}

/* The buffer of a square float64 C-contiguous matrix of order 1..max_m, or -1 (an error set). */
static int square_matrix(PyObject *arg, Py_buffer *v, idx max_m)
{
    if (PyObject_GetBuffer(arg, v, PyBUF_FORMAT | PyBUF_ND | PyBUF_C_CONTIGUOUS) < 0) return -1;
    const char *f = v->format ? v->format : "B";
    if (*f == '<' || *f == '=' || *f == '@') f++;
    if (v->ndim != 2 || v->shape[0] != v->shape[1] || v->shape[0] < 1 || v->shape[0] > max_m ||
        v->itemsize != 8 || f[0] != 'd' || f[1] != 0) {
        PyBuffer_Release(v);
        PyErr_SetString(PyExc_ValueError, "A: a square float64 C-contiguous matrix");
        return -1;
    }
    return 0;
}

/* col_abs_max(A) -> float(np.max(np.sum(np.abs(A), axis=0))) by `col_abs_max` (the probe). */
static PyObject *py_col_abs_max(PyObject *self, PyObject *arg)
{
    (void)self;
    Py_buffer v;
    if (square_matrix(arg, &v, 46000) < 0) return NULL;
    int m = (int)v.shape[0];
    double *t = malloc(sizeof(double) * m);
    if (!t) {
        PyBuffer_Release(&v);
        return PyErr_NoMemory();
    }
    double r = col_abs_max(m, v.buf, t);
    free(t);
    PyBuffer_Release(&v);
    return PyFloat_FromDouble(r);
}

/* rcond_shortcut(A) -> (bound, lu): `inv_norm_bound` of A's LU (dgetrf) times the column
 * norm anorm, and the factors (column order) for a test that compares with dgecon. */
static PyObject *py_rcond_shortcut(PyObject *self, PyObject *arg)
{
    (void)self;
    Py_buffer v;
    if (!getrf) {
        PyErr_SetString(PyExc_RuntimeError, "call init first");
        return NULL;
    }
    if (square_matrix(arg, &v, 4000) < 0) return NULL;
    int m = (int)v.shape[0], info = 0;
    const double *A = v.buf;
    double *buf = malloc(sizeof(double) * ((size_t)m * m + 3 * (size_t)m));
    int *ipiv = malloc(sizeof(int) * m);
    if (!buf || !ipiv) {
        free(buf);
        free(ipiv);
        PyBuffer_Release(&v);
        return PyErr_NoMemory();
    }
    double *lu = buf + 3 * m;
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) lu[i + j * m] = A[i * m + j];
    double anorm = col_abs_max(m, A, buf);
    getrf(&m, &m, lu, &m, ipiv, &info);
    double bound = INFINITY;
    int zero = 0;
    for (int i = 0; i < m; i++) zero |= lu[i + i * m] == 0.0;
    if (!zero) bound = anorm * inv_norm_bound(m, lu, buf + m, buf + 2 * m);
    PyObject *out = PyList_New((Py_ssize_t)m * m);
    for (idx k = 0; out && k < (idx)m * m; k++) PyList_SET_ITEM(out, k, PyFloat_FromDouble(lu[k]));
    free(buf);
    free(ipiv);
    PyBuffer_Release(&v);
    if (!out) return NULL;
    return Py_BuildValue("dN", bound, out);
}

static void *pointer(PyObject *cap)
{
    if (!PyCapsule_CheckExact(cap)) {
        PyErr_SetString(PyExc_TypeError, "expected a PyCapsule");
        return NULL;
    }
    return PyCapsule_GetPointer(cap, PyCapsule_GetName(cap));
}

/* init(getrf, gecon, getrs, gemv, ddot): the capsules of scipy.linalg.cython_lapack / _blas. */
static PyObject *py_init(PyObject *self, PyObject *args)
{
    PyObject *o[5];
    void *p[5];
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOO", &o[0], &o[1], &o[2], &o[3], &o[4])) return NULL;
    for (int k = 0; k < 5; k++)
        if (!(p[k] = pointer(o[k]))) return NULL;
    getrf = (getrf_t *)p[0];
    gecon = (gecon_t *)p[1];
    getrs = (getrs_t *)p[2];
    gemv = (gemv_t *)p[3];
    ddot = (dot_t *)p[4];
    Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
    {"init", py_init, METH_VARARGS,
     "init(getrf, gecon, getrs, gemv, ddot): scipy's LAPACK / BLAS capsules."},
    {"solve", py_solve, METH_VARARGS,
     "solve(M, q, r, c, tol, block_tries, max_iter, z, basis) -> (code, it, nbasis, flips, "
     "bounds): pivoting's block steps on the equilibrated data."},
    {"matvec", py_matvec, METH_VARARGS, "matvec(A, x, y): y = A x as numpy's matmul."},
    {"rcond_shortcut", py_rcond_shortcut, METH_O,
     "rcond_shortcut(A) -> (anorm * bound on dgecon's inverse-norm estimate, LU factors)."},
    {"col_abs_max", py_col_abs_max, METH_O,
     "col_abs_max(A) -> the largest column sum of |A|, as numpy sums it."},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_pivot_c",
                                    "pivoting's block steps in C (see lcp/solvers/fast_pivoting.py).",
                                    -1, methods};

PyMODINIT_FUNC PyInit__pivot_c(void) { return PyModule_Create(&module); }
