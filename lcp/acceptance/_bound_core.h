/* The forward error bound of lcp/acceptance/_accuracy_core.h's `assess_one` (LAPACK's, with
 * |K^-1| formed from the LU, not estimated) and the steps it shares with the refinement there:
 * |K| row sums four rows at once, the long double residual K y + k; bound_one, the bound on
 * its own (the binding `bound` of _accuracy_c.c). The includer defines `idx` and dmax / dmin
 * and includes <float.h>, <math.h>, <stdlib.h> and <string.h> (_accuracy_core.h does). */
#ifndef RIGIDLCP_BOUND_CORE_H
#define RIGIDLCP_BOUND_CORE_H

#include "_lu_core.h" /* lu, lu_solve: the LU of the pattern's system */
#include "_inverse_core.h" /* inverse_columns: K^-1, FB_COLS columns at a time */

/* out_i = init_i + sum_j |K_ij| x_j (x NULL: + |K_ij|; init NULL: from 0), each row summed
 * for j = 0, 1, ..., m - 1 in this order, four rows at once (independent chains: the same
 * numbers as row by row, sooner). out may be init. */
static void abs_row_sums_by4(idx m, const double *K, const double *x, const double *init,
                             double *out)
{
    idx i = 0;
    for (; i + 4 <= m; i += 4) {
        const double *K0 = K + i * m, *K1 = K0 + m, *K2 = K1 + m, *K3 = K2 + m;
        double s0 = init ? init[i] : 0.0, s1 = init ? init[i + 1] : 0.0,
               s2 = init ? init[i + 2] : 0.0, s3 = init ? init[i + 3] : 0.0;
        if (x)
            for (idx j = 0; j < m; j++) {
                double xj = x[j];
                s0 += fabs(K0[j]) * xj;
                s1 += fabs(K1[j]) * xj;
                s2 += fabs(K2[j]) * xj;
                s3 += fabs(K3[j]) * xj;
            }
        else
            for (idx j = 0; j < m; j++) {
                s0 += fabs(K0[j]);
                s1 += fabs(K1[j]);
                s2 += fabs(K2[j]);
                s3 += fabs(K3[j]);
            }
        out[i] = s0, out[i + 1] = s1, out[i + 2] = s2, out[i + 3] = s3;
    }
    for (; i < m; i++) {
        double s = init ? init[i] : 0.0;
        for (idx j = 0; j < m; j++) s += x ? fabs(K[i * m + j]) * x[j] : fabs(K[i * m + j]);
        out[i] = s;
    }
}

/* r = K y + k, accumulated in long double, rounded to double. */
static void residual_ld(idx m, const double *K, const double *k, const double *y, double *r)
{
    idx i0 = 0;
    for (; i0 + 4 <= m; i0 += 4) {  /* four rows at once, each summed in its own order */
        const double *K0 = K + i0 * m, *K1 = K0 + m, *K2 = K1 + m, *K3 = K2 + m;
        long double s0 = (long double)k[i0], s1 = (long double)k[i0 + 1],
                    s2 = (long double)k[i0 + 2], s3 = (long double)k[i0 + 3];
        for (idx j = 0; j < m; j++) {
            long double yj = (long double)y[j];
            s0 += (long double)K0[j] * yj;
            s1 += (long double)K1[j] * yj;
            s2 += (long double)K2[j] * yj;
            s3 += (long double)K3[j] * yj;
        }
        r[i0] = (double)s0, r[i0 + 1] = (double)s1, r[i0 + 2] = (double)s2,
        r[i0 + 3] = (double)s3;
    }
    for (idx i = i0; i < m; i++) {
        long double s = (long double)k[i];
        for (idx j = 0; j < m; j++) s += (long double)K[i * m + j] * (long double)y[j];
        r[i] = (double)s;
    }
}

/* Below this, the comparison-matrix bound (comparison_bound) is the forward bound reported:
 * a tenth of the smallest forward accuracy rigidlcp bench states (1e-12; FERR_TOL is 1e-6), so
 * that no verdict at FERR_TOL or at a stated accuracy depends on which bound was taken. */
#define CHEAP_FERR 1e-13

/* sum_j |a_j| x_j and sum_j |a_j| s_j over j = from .. to - 1, each in four partial sums
 * (j mod 4 from `from`), added as (p0 + p1) + (p2 + p3): nonnegative terms, any order gives an
 * upper bound to the slack of comparison_bound. */
static inline void abs_dot2(const double *a, const double *x, const double *s, idx from, idx to,
                            double *dx, double *ds)
{
    double x0 = 0.0, x1 = 0.0, x2 = 0.0, x3 = 0.0, s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    idx j = from;
    for (; j + 4 <= to; j += 4) {
        double a0 = fabs(a[j]), a1 = fabs(a[j + 1]), a2 = fabs(a[j + 2]), a3 = fabs(a[j + 3]);
        x0 += a0 * x[j];
        x1 += a1 * x[j + 1];
        x2 += a2 * x[j + 2];
        x3 += a3 * x[j + 3];
        s0 += a0 * s[j];
        s1 += a1 * s[j + 1];
        s2 += a2 * s[j + 2];
        s3 += a3 * s[j + 3];
    }
    for (; j < to; j++) {
        double aj = fabs(a[j]);
        x0 += aj * x[j];
        s0 += aj * s[j];
    }
    *dx = (x0 + x1) + (x2 + x3);
    *ds = (s0 + s1) + (s2 + s3);
}

/* x <- C(U)^-1 C(L)^-1 P x and s likewise (x, s >= 0), C(T) the comparison matrix of the LU's
 * triangle T (|T_ii| on the diagonal, -|T_ij| off it): since K^-1 = U^-1 L^-1 P and
 * |T^-1| <= C(T)^-1 for a triangular T, |K^-1| b <= C(U)^-1 C(L)^-1 P b for b >= 0 (in exact
 * arithmetic; the substitutions here add nonnegative terms only, so their rounding is relative,
 * covered by comparison_bound's slack). Two substitutions for both right-hand sides: O(m^2),
 * where forming K^-1 is O(m^3). */
static void comparison_solve2(idx m, const double *A, const idx *perm, double *x, double *s)
{
    permute(m, perm, x);
    permute(m, perm, s);
    double dx, ds;
    for (idx i = 1; i < m; i++) {  /* C(L): unit diagonal */
        abs_dot2(A + i * m, x, s, 0, i, &dx, &ds);
        x[i] += dx;
        s[i] += ds;
    }
    for (idx i = m - 1; i >= 0; i--) {
        abs_dot2(A + i * m, x, s, i + 1, m, &dx, &ds);
        double d = fabs(A[i * m + i]);
        x[i] = (x[i] + dx) / d;
        s[i] = (s[i] + ds) / d;
    }
}

/* The bound of forward_bound with C(U)^-1 C(L)^-1 P in place of |K^-1| (comparison_solve2),
 * and Skeel's condition likewise: both upper bounds of forward_bound's numbers (g, rows as
 * there; ymax = ||y||_inf). The computed substitutions may fall short of their exact values by
 * a relative 2 m gamma_m each (nonnegative triangular systems; gamma_m = m eps / (1 - m eps)),
 * and forward_bound's formed |K^-1| may exceed the exact |U^-1 L^-1| by as much (its
 * substitutions' backward errors): the slack 1 + 8 (m + 2)^2 eps covers both and the roundings
 * of the last steps (m <= MAX_M = 400: 1 + 2.9e-10). Returns 1 and sets *ferr when the bound
 * certifies: Skeel's bound at most half of 1 / (m eps) (the system is not singular to working
 * precision, as forward_bound would find) and the bound at most CHEAP_FERR; else 0 (x, s
 * scratch of m each). */
static int comparison_bound(idx m, const double *A, const idx *perm, const double *g,
                            const double *rows, double ymax, double *x, double *s, double *ferr)
{
    const double eps = DBL_EPSILON, slack = 1.0 + 8.0 * (double)((m + 2) * (m + 2)) * eps;
    memcpy(x, g, (size_t)m * sizeof(double));
    memcpy(s, rows, (size_t)m * sizeof(double));
    comparison_solve2(m, A, perm, x, s);
    double top = 0.0, skeel = 0.0;
    int finite = 1;
    for (idx i = 0; i < m; i++) {
        finite &= isfinite(x[i]) && isfinite(s[i]);
        top = dmax(top, x[i]);
        skeel = dmax(skeel, s[i]);
    }
    if (!finite || !(skeel * slack * (double)m * eps <= 0.5)) return 0;
    double f = (top * slack) / dmax(ymax, 1e-300) * slack + eps;
    if (!(f <= CHEAP_FERR)) return 0;
    *ferr = f;
    return 1;
}

/* LAPACK's forward error bound at y of the pattern's system K y + k = 0 (A, perm: K's LU;
 * rows_i = sum_j |K_ij|), lcp/acceptance/accuracy.py's `forward_bound`:
 *
 *     ferr = || |K^-1| (|r| + (m + 1) eps_ld (|K| |y| + |k|)) ||_inf / ||y||_inf + eps,
 *
 * r = K y + k in long double. First the O(m^2) comparison-matrix bound (comparison_bound, an
 * upper bound of this one): when it is at most CHEAP_FERR it is the ferr returned (issue 23:
 * forming |K^-1| was half of the acceptance at n = 30). Else |K^-1| is formed column by column
 * from the LU (column j = K^-1 e_j; m solves, O(m^3)), so the norm is computed, not estimated:
 * Hager's estimator (xGERFS's) is a lower bound of it and came out 20 % below on solved
 * problems (issue 23). Skeel's condition || |K^-1| |K| 1 || comes from the same columns:
 * beyond 1 / (m eps) the system is singular to working precision and 1 is returned (the numpy
 * code's SVD path decides), else 0 with *ferr set. exact: skip the comparison bound (the
 * binding `bound(K, k, y, 1)`, for tests). r, g: scratch of m doubles, col of (FB_COLS + 2) m,
 * acc of 2 m. */
static int forward_bound(idx m, const double *K, const double *A, const idx *perm,
                         const double *kp, const double *y, const double *rows, double *r,
                         double *g, double *col, double *acc, int exact, double *ferr)
{
    const double eps = DBL_EPSILON, eps_ld = LDBL_EPSILON;
    residual_ld(m, K, kp, y, r);
    double ymax = 0.0;
    for (idx i = 0; i < m; i++) {
        col[i] = fabs(y[i]);
        ymax = dmax(ymax, col[i]);
    }
    for (idx i = 0; i < m; i++) g[i] = fabs(kp[i]);
    abs_row_sums_by4(m, K, col, g, g);  /* g_i = |k_i| + sum_j |K_ij| |y_j| */
    for (idx i = 0; i < m; i++) g[i] = fabs(r[i]) + (double)(m + 1) * eps_ld * g[i];
    double *sk = acc + m;
    if (!exact && comparison_bound(m, A, perm, g, rows, ymax, acc, sk, ferr)) return 0;
    memset(acc, 0, 2 * (size_t)m * sizeof(double));
    /* acc += |K^-1 e_j| g_j, sk += |K^-1 e_j| rows_j for j = 0, 1, ..., m - 1 in this order;
     * the columns FB_COLS at a time (_inverse_core.h: X[FB_COLS i + b] = column j0 + b, by
     * lu_solve's substitutions: the same numbers however grouped) */
    idx *lab = (idx *)col, *at = lab + m;  /* idx and double: both 8 bytes */
    double *X = col + 2 * m;
    unit_rows(m, perm, lab, at);
    for (idx j0 = 0; j0 < m; j0 += FB_COLS) {
        idx nb = m - j0 < FB_COLS ? m - j0 : FB_COLS;
        inverse_columns(m, A, at, j0, nb, X);
        const double *gj = g + j0, *rj = rows + j0;
        for (idx i = 0; i < m; i++) {
            const double *Xi = X + FB_COLS * i;
            double a = acc[i], s = sk[i];
            for (idx b = 0; b < nb; b++) {
                double c = fabs(Xi[b]);
                a += c * gj[b];
                s += c * rj[b];
            }
            acc[i] = a, sk[i] = s;
        }
    }
    double top = 0.0, skeel = 0.0;
    int finite = 1;
    for (idx i = 0; i < m; i++) {
        finite &= isfinite(acc[i]) && isfinite(sk[i]);
        top = dmax(top, acc[i]);
        skeel = dmax(skeel, sk[i]);
    }
    if (!finite || skeel * (double)m * eps > 1.0) return 1;
    *ferr = top / dmax(ymax, 1e-300) + eps;
    if (!isfinite(*ferr)) *ferr = INFINITY;
    return 0;
}

/* forward_bound of K y + k = 0 at y, K m x m row-major: the LU here (the same `lu` as
 * assess_one's, so the same number for the same K and y). Returns 0 (*ferr set) or 1
 * (singular to working precision, a zero pivot, or no memory: the numpy code decides). */
static int bound_one(idx m, const double *K, const double *kp, const double *y, int exact,
                     double *ferr)
{
    if (m == 0) {
        *ferr = 0.0;
        return 0;
    }
    size_t nd = (size_t)m * m + (FB_COLS + 7) * (size_t)m;
    double *buf = (double *)malloc((nd + (size_t)m + 1) * sizeof(double));
    if (!buf) return 1;
    double *A = buf, *rows = A + m * m, *r = rows + m, *g = r + m, *col = g + m,
           *acc = col + (FB_COLS + 2) * m;
    idx *perm = (idx *)(buf + nd);
    memcpy(A, K, (size_t)m * m * sizeof(double));
    abs_row_sums_by4(m, K, NULL, NULL, rows);
    int code = lu(m, A, perm) < 0 ? 1 : forward_bound(m, K, A, perm, kp, y, rows, r, g, col,
                                                      acc, exact, ferr);
    free(buf);
    return code;
}

#endif /* RIGIDLCP_BOUND_CORE_H */
