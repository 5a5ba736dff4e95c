/* lcp/acceptance/accuracy.py's `assess` of an LCP answer on its basis, in C: the steps (backward
 * error, LU of the pattern's system, refinement with long double residuals, LAPACK's forward
 * error bound with |K^-1| formed from the LU, the polished point kept when not worse). Included by
 * lcp/acceptance/_accuracy_c.c (the binding `assess`) and by lcp/_lemke_c.c (`solve_accept`:
 * the solve and its acceptance in one call), so that both run the same code. The includer
 * defines `idx` (Py_ssize_t) and includes <float.h>, <math.h>, <stdint.h>, <stdlib.h> and
 * <string.h>. assess_one returns 0 (done) or 1 (not handled here: the numpy code decides).
 * The forward bound and the long double residual are _bound_core.h's (included below). */
#ifndef RIGIDLCP_ACCURACY_CORE_H
#define RIGIDLCP_ACCURACY_CORE_H

/* max / min of numbers that are not NaN (fmax / fmin are library calls unless inlined) */
static inline double dmax(double a, double b) { return a > b ? a : b; }
static inline double dmin(double a, double b) { return a < b ? a : b; }
#define MAX_M 400
#define STEPS 5
/* assess_one's work block on the stack up to this many doubles (32 kB: m up to about 36) */
#define ASSESS_STACK 4096

/* Are all n entries of a finite? Then *mx = max |a_i| (from the value on entry). Four lanes
 * wide where the CPU has AVX2 (the maximum of finite numbers does not depend on the order). */
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && !defined(RIGIDLCP_NO_AVX2)
#include <immintrin.h>
#define ACC_HAVE_AVX2 1
__attribute__((target("avx2"))) static int abs_max_finite_avx2(const double *a, idx n,
                                                               double *mx)
{
    const __m256d sign = _mm256_set1_pd(-0.0), big = _mm256_set1_pd(DBL_MAX);
    __m256d m = _mm256_set1_pd(*mx), bad = _mm256_setzero_pd();
    idx i = 0;
    for (; i + 4 <= n; i += 4) {
        __m256d v = _mm256_andnot_pd(sign, _mm256_loadu_pd(a + i));
        bad = _mm256_or_pd(bad, _mm256_cmp_pd(v, big, _CMP_NLE_UQ)); /* > DBL_MAX or NaN */
        m = _mm256_max_pd(m, v);
    }
    double l[4];
    _mm256_storeu_pd(l, m);
    double top = l[0];
    for (int k = 1; k < 4; k++) top = l[k] > top ? l[k] : top;
    int finite = _mm256_movemask_pd(bad) == 0;
    for (; i < n; i++) {
        double v = fabs(a[i]);
        finite &= v <= DBL_MAX;
        top = v > top ? v : top;
    }
    *mx = top;
    return finite;
}
static int acc_avx2 = -1; /* -1: not decided yet */
#else
#define ACC_HAVE_AVX2 0
#endif

static int abs_max_finite(const double *a, idx n, double *mx)
{
#if ACC_HAVE_AVX2
    if (acc_avx2 < 0) {
        __builtin_cpu_init();
        acc_avx2 = __builtin_cpu_supports("avx2") ? 1 : 0;
    }
    if (acc_avx2) return abs_max_finite_avx2(a, n, mx);
#endif
    double top = *mx;
    int finite = 1;
    for (idx i = 0; i < n; i++) {
        double v = fabs(a[i]);
        finite &= v <= DBL_MAX;
        top = v > top ? v : top;
    }
    *mx = top;
    return finite;
}


#if ACC_HAVE_AVX2
/* The 4 x 4 block of rows M0..M3 at columns j..j+3, transposed: c_k = (M0[j+k], .., M3[j+k]),
 * |.| taken; acc += c_0, += c_1, += c_2, += c_3 in this order. */
#define ACC_ABS_COLS4(acc, M0, M1, M2, M3, j)                                             \
    do {                                                                                   \
        __m256d r0 = _mm256_loadu_pd((M0) + (j)), r1 = _mm256_loadu_pd((M1) + (j)),       \
                r2 = _mm256_loadu_pd((M2) + (j)), r3 = _mm256_loadu_pd((M3) + (j));       \
        __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1),         \
                t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);         \
        acc = _mm256_add_pd(acc, _mm256_andnot_pd(sign, _mm256_permute2f128_pd(t0, t2, 0x20))); \
        acc = _mm256_add_pd(acc, _mm256_andnot_pd(sign, _mm256_permute2f128_pd(t1, t3, 0x20))); \
        acc = _mm256_add_pd(acc, _mm256_andnot_pd(sign, _mm256_permute2f128_pd(t0, t2, 0x31))); \
        acc = _mm256_add_pd(acc, _mm256_andnot_pd(sign, _mm256_permute2f128_pd(t1, t3, 0x31))); \
    } while (0)

/* max over the rows i < rows4 (a multiple of 4) of 0 + |M_i0| + |M_i1| + ... + |M_i,n-1|,
 * each row summed for j = 0, 1, ..., n - 1 in this order (one lane per row: the same numbers
 * as the scalar loop), eight rows at a time where it can. */
__attribute__((target("avx2"))) static double abs_row_sums_max_avx2(idx n, const double *M,
                                                                   idx rows4, double norm)
{
    const __m256d sign = _mm256_set1_pd(-0.0);
    double l[8];
    idx i = 0;
    for (; i + 8 <= rows4; i += 8) {
        const double *M0 = M + i * n, *M1 = M0 + n, *M2 = M1 + n, *M3 = M2 + n, *M4 = M3 + n,
                     *M5 = M4 + n, *M6 = M5 + n, *M7 = M6 + n;
        __m256d a = _mm256_setzero_pd(), b = _mm256_setzero_pd();
        idx j = 0;
        for (; j + 4 <= n; j += 4) {
            ACC_ABS_COLS4(a, M0, M1, M2, M3, j);
            ACC_ABS_COLS4(b, M4, M5, M6, M7, j);
        }
        _mm256_storeu_pd(l, a);
        _mm256_storeu_pd(l + 4, b);
        for (; j < n; j++) {
            l[0] += fabs(M0[j]), l[1] += fabs(M1[j]), l[2] += fabs(M2[j]), l[3] += fabs(M3[j]);
            l[4] += fabs(M4[j]), l[5] += fabs(M5[j]), l[6] += fabs(M6[j]), l[7] += fabs(M7[j]);
        }
        for (int k = 0; k < 8; k++) norm = dmax(norm, l[k]);
    }
    for (; i + 4 <= rows4; i += 4) {
        const double *M0 = M + i * n, *M1 = M0 + n, *M2 = M1 + n, *M3 = M2 + n;
        __m256d a = _mm256_setzero_pd();
        idx j = 0;
        for (; j + 4 <= n; j += 4) ACC_ABS_COLS4(a, M0, M1, M2, M3, j);
        _mm256_storeu_pd(l, a);
        for (; j < n; j++)
            l[0] += fabs(M0[j]), l[1] += fabs(M1[j]), l[2] += fabs(M2[j]), l[3] += fabs(M3[j]);
        for (int k = 0; k < 4; k++) norm = dmax(norm, l[k]);
    }
    return norm;
}
#endif

/* berr of lcp/accuracy.py (nu = 0). M finite (assess_one returns before otherwise). The row
 * sums run over the columns j with x_j != 0 only (nz: scratch of n), in increasing j as
 * before: a term M_ij x_j with x_j = 0 is a zero, which leaves a sum unchanged but for the sign
 * of a zero sum, and no use of a row's sum sees that sign (|min(v, w)|, and s is a sum of
 * nonnegative terms). An answer on a pattern of m unknowns costs O(n m), not O(n^2). */
static double backward_error(idx n, const double *M, const double *q, const double *x,
                             double mmax, double qmax, double floor, idx *nz)
{
    double xmax = 0.0;
    idx nnz = 0;
    for (idx i = 0; i < n; i++) {
        xmax = dmax(xmax, fabs(x[i]));
        nz[nnz] = i;
        nnz += x[i] != 0.0; /* a NaN counts: != is true */
    }
    double vs = dmax(xmax, mmax > 0 ? qmax / mmax : 0.0);
    if (!(vs > 0)) vs = 1.0;
    double out = 0.0;
    double rb[4], sb[4];
    for (idx i = 0; i < n; i++) {
        const double *row = M + i * n;
        double res, s;
        if (i % 4 == 0 && i + 4 <= n) {  /* four rows at once: independent sums, each in
                                          * its own order (the same numbers, sooner) */
            const double *r1 = row + n, *r2 = r1 + n, *r3 = r2 + n;
            double a0 = q[i], a1 = q[i + 1], a2 = q[i + 2], a3 = q[i + 3];
            double b0 = fabs(q[i]), b1 = fabs(q[i + 1]), b2 = fabs(q[i + 2]), b3 = fabs(q[i + 3]);
            for (idx t = 0; t < nnz; t++) {
                const idx j = nz[t];
                double xj = x[j], axj = fabs(xj);
                a0 += row[j] * xj;
                b0 += fabs(row[j]) * axj;
                a1 += r1[j] * xj;
                b1 += fabs(r1[j]) * axj;
                a2 += r2[j] * xj;
                b2 += fabs(r2[j]) * axj;
                a3 += r3[j] * xj;
                b3 += fabs(r3[j]) * axj;
            }
            rb[0] = a0, rb[1] = a1, rb[2] = a2, rb[3] = a3;
            sb[0] = b0, sb[1] = b1, sb[2] = b2, sb[3] = b3;
        }
        if (i - i % 4 + 4 <= n) {
            res = rb[i % 4];
            s = sb[i % 4];
        } else {
            res = q[i];
            s = fabs(q[i]);
            for (idx t = 0; t < nnz; t++) {
                const idx j = nz[t];
                res += row[j] * x[j];
                s += fabs(row[j]) * fabs(x[j]);
            }
        }
        s = dmax(s, floor);
        double wr = s > 0 ? res / s : (res == 0 ? 0.0 : copysign(INFINITY, res));
        double v = x[i] / vs, mn = v < wr ? v : wr;
        if (isnan(mn)) return INFINITY;
        out = dmax(out, fabs(mn));
    }
    return out;
}

#include "_bound_core.h" /* forward_bound, residual_ld, abs_row_sums_by4; lu, lu_solve */

/* mmax_in: max |M_ij| when the caller knows it and M is finite (solve_accept: the solve
 * checked and measured M), else negative (measured here). */
static int assess_one(idx n, const double *M, const double *q, const double *z,
                      const int64_t *a, idx m, double mmax_in, double *out, double *res)
{
    const double eps = DBL_EPSILON;
    double mmax = 0.0, qmax = 0.0, norm = 0.0;
    for (idx i = 0; i < n; i++) qmax = dmax(qmax, fabs(q[i]));
    for (idx i = 0; i < n; i++)
        if (!isfinite(z[i]) || !isfinite(q[i])) return 1;
    /* |M|_max and ||M||_inf, for the data's scale (lcp/accuracy.py's data_scale):
     * |q| + ||M||_inf |q| / |M|_max */
    if (mmax_in >= 0 ? (mmax = mmax_in, 1) : abs_max_finite(M, n * n, &mmax)) {
        /* all finite: the maxima do not depend on the order, and each row sum is taken in its
         * own order, four rows at once (independent chains: the same numbers, sooner); with
         * AVX2, one row per lane, eight rows at once (abs_row_sums_max_avx2, issue 23: 0.08
         * us of the acceptance's 2.8 at n = 30), the rows beyond a multiple of 4 below */
        idx i = 0;
#if ACC_HAVE_AVX2
        if (acc_avx2 < 0) {
            __builtin_cpu_init();
            acc_avx2 = __builtin_cpu_supports("avx2") ? 1 : 0;
        }
        if (acc_avx2) {
            i = n - n % 4;
            norm = abs_row_sums_max_avx2(n, M, i, norm);
        }
#endif
        for (; i + 4 <= n; i += 4) {
            const double *M0 = M + i * n, *M1 = M0 + n, *M2 = M1 + n, *M3 = M2 + n;
            double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
            for (idx j = 0; j < n; j++) {
                s0 += fabs(M0[j]);
                s1 += fabs(M1[j]);
                s2 += fabs(M2[j]);
                s3 += fabs(M3[j]);
            }
            norm = dmax(dmax(dmax(dmax(norm, s0), s1), s2), s3);
        }
        for (; i < n; i++) {
            double s = 0.0;
            for (idx j = 0; j < n; j++) s += fabs(M[i * n + j]);
            norm = dmax(norm, s);
        }
    } else {  /* a NaN or an infinity: the order of the maxima matters; the plain pass */
        mmax = 0.0;
        for (idx i = 0; i < n; i++) {
            double s = 0.0;
            for (idx j = 0; j < n; j++) {
                double v = fabs(M[i * n + j]);
                s += v;
                mmax = dmax(mmax, v);
            }
            norm = dmax(norm, s);
        }
    }
    if (!isfinite(norm)) return 1;
    double floor = mmax > 0 ? qmax + norm * (qmax / mmax) : qmax;
    /* one block for the work below: 2 m^2 + (FB_COLS + 10) m + 1 doubles (K, its LU, the
     * vectors, the bound's scratch), perm and the sorted pattern (m + 1 entries of 8 bytes
     * each) and the marks (n bytes); on the stack when it fits (no allocation for small
     * problems) */
    size_t nd = (size_t)2 * m * m + (FB_COLS + 10) * (size_t)m + 1,
           words = nd + 2 * ((size_t)m + 1) + (size_t)n + ((size_t)n + 7) / 8;
    double stackbuf[ASSESS_STACK];
    double *buf = words <= ASSESS_STACK ? stackbuf : (double *)malloc(words * sizeof(double));
    if (!buf) return 1;
    idx *perm = (idx *)(buf + nd);  /* each in its own words (8 bytes, 8-aligned) */
    int64_t *sorted = (int64_t *)(buf + nd + m + 1);
    idx *nz = (idx *)(buf + nd + 2 * (m + 1));  /* backward_error's scratch */
    char *mark = (char *)(nz + n);
    memset(mark, 0, (size_t)n);
    for (idx i = 0; i < m; i++) {
        if (a[i] < 0 || a[i] >= n || mark[a[i]]) {
            if (buf != stackbuf) free(buf);
            return 1;
        }
        mark[a[i]] = 1;
    }
    for (idx i = 0, k = 0; i < n; i++)
        if (mark[i]) sorted[k++] = i;
    a = sorted;  /* the pattern in increasing order, whatever order the basis came in */
    double berr = -1.0;  /* of z as given: computed only when needed (below) */
    double ferr = 0.0;
    int refined = 0;
    double *K = buf, *A = K + m * m, *kp = A + m * m, *y = kp + m, *r = y + m, *d = r + m,
           *g = d + m, *rows = g + m, *col = rows + m, *acc = col + (FB_COLS + 2) * m;
    for (idx i = 0; i < m; i++) {
        kp[i] = q[a[i]];
        y[i] = z[a[i]];
        const double *Mi = M + a[i] * n;
        double *Ki = K + i * m;
        for (idx j = 0; j < m; j++) Ki[j] = Mi[a[j]];
    }
    abs_row_sums_by4(m, K, NULL, NULL, rows);
    memcpy(A, K, (size_t)m * m * sizeof(double));
    int code = 0;
    if (m > 0) {
        if (lu(m, A, perm) < 0) code = 1;  /* singular: numpy's SVD path */
        if (!code) {
            double prev = INFINITY;
            for (int step = 0; step < STEPS; step++) {
                residual_ld(m, K, kp, y, r);
                memcpy(d, r, (size_t)m * sizeof(double));
                lu_solve(m, A, perm, d, 0);
                double size = 0.0, ymax = 0.0;
                for (idx i = 0; i < m; i++) size = dmax(size, fabs(d[i]));
                if (!isfinite(size) || size >= prev) break;
                for (idx i = 0; i < m; i++) {
                    y[i] -= d[i];
                    ymax = dmax(ymax, fabs(y[i]));
                }
                prev = size;
                if (size <= eps * ymax) break;
            }
            /* the bound at the refined y (exact norm of |K^-1| g; Skeel's singularity test) */
            if (forward_bound(m, K, A, perm, kp, y, rows, r, g, col, acc, 0, &ferr)) code = 1;
        }
    }
    if (!code) {
        for (idx i = 0; i < n; i++) out[i] = 0.0;
        int finite = 1;
        for (idx i = 0; i < m; i++) {
            if (!isfinite(y[i])) finite = 0;
            out[a[i]] = y[i] > 0.0 ? y[i] : 0.0;
        }
        double bp = finite ? backward_error(n, M, q, out, mmax, qmax, floor, nz) : INFINITY;
        /* kept when its backward error is at rounding level or not larger than z's */
        if (!(finite && bp <= 8.0 * (double)n * eps))
            berr = backward_error(n, M, q, z, mmax, qmax, floor, nz);
        if (finite && (bp <= 8.0 * (double)n * eps || bp <= berr)) {
            berr = bp;
            refined = 1;
            /* a y_i < 0 clipped to 0: the bound of the point returned, not of y (the one
             * verify.certify computes on it) */
            int clipped = 0;
            for (idx i = 0; i < m; i++)
                if (y[i] < 0.0) {
                    y[i] = 0.0;
                    clipped = 1;
                }
            if (clipped && forward_bound(m, K, A, perm, kp, y, rows, r, g, col, acc, 0, &ferr))
                ferr = INFINITY;  /* not finite (the same K passed the test above) */
        } else {
            /* z as given: the bound at z_a itself (lcp/acceptance/accuracy.py's `assess`),
             * + its entries off the pattern */
            double xs = 0.0, gap = 0.0, at_z = ferr;
            for (idx i = 0; i < n; i++) xs = dmax(xs, fabs(z[i]));
            xs = dmax(xs, 1e-300);
            memcpy(d, y, (size_t)m * sizeof(double));  /* the refined y */
            for (idx i = 0; i < m; i++) y[i] = z[a[i]];
            if (!isfinite(ferr) || forward_bound(m, K, A, perm, kp, y, rows, r, g, col, acc,
                                                 0, &at_z)) {
                at_z = ferr;  /* not finite: |z_a - y| + the bound of y, as numpy */
                for (idx i = 0; i < m; i++) gap = dmax(gap, fabs(z[a[i]] - d[i]));
            }
            for (idx i = 0; i < n; i++)
                if (!mark[i]) gap = dmax(gap, fabs(z[i]));
            ferr = at_z + gap / xs;
            if (!isfinite(ferr)) ferr = INFINITY;
            memcpy(out, z, (size_t)n * sizeof(double));
        }
    }
    if (buf != stackbuf) free(buf);
    res[0] = berr;
    res[1] = ferr;
    res[2] = refined;
    return code;
}

#endif /* RIGIDLCP_ACCURACY_CORE_H */
