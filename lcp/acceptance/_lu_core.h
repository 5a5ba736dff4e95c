/* Dense LU with partial pivoting and its solves, for lcp/acceptance/_accuracy_core.h (the
 * pattern's system of `assess`): the factorization (AVX2 row updates where the CPU has them,
 * the same roundings: no fused multiply-add, -ffp-contract=off) and K^-1 x, K^-T x. The
 * includer defines `idx` and dmax / dmin and includes <float.h>, <math.h> and <string.h>. */
#ifndef RIGIDLCP_LU_CORE_H
#define RIGIDLCP_LU_CORE_H

/* a_i -= l a_k over len entries: every entry rounded twice (product, difference; no fused
 * multiply-add: -ffp-contract=off), so the AVX2 clone gives the same numbers as the plain
 * loop, four at a time. */
static void row_update_plain(double *ai, const double *ak, double l, idx len)
{
    for (idx j = 0; j < len; j++) ai[j] -= l * ak[j];
}

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && !defined(RIGIDLCP_NO_AVX2)
__attribute__((target("avx2"))) static void row_update_avx2(double *ai, const double *ak,
                                                           double l, idx len)
{
    for (idx j = 0; j < len; j++) ai[j] -= l * ak[j];
}

static void row_update(double *ai, const double *ak, double l, idx len)
{
    static int avx2 = -1;
    if (avx2 < 0) {
        __builtin_cpu_init();
        avx2 = __builtin_cpu_supports("avx2") ? 1 : 0;
    }
    if (avx2)
        row_update_avx2(ai, ak, l, len);
    else
        row_update_plain(ai, ak, l, len);
}
#else
#define row_update row_update_plain
#endif

/* Step k's partial pivoting, shared by both `lu` loops: the row p >= k of largest |A[p, k]|
 * (the first of equals), recorded in perm[k] and swapped with row k; -1 if that column is 0
 * from row k down (U singular). */
static inline int lu_pivot(idx m, double *A, idx *perm, idx k)
{
    idx p = k;
    for (idx i = k + 1; i < m; i++)
        if (fabs(A[i * m + k]) > fabs(A[p * m + k])) p = i;
    perm[k] = p;
    if (A[p * m + k] == 0.0) return -1;
    if (p != k)
        for (idx j = 0; j < m; j++) {
            double t = A[k * m + j];
            A[k * m + j] = A[p * m + j];
            A[p * m + j] = t;
        }
    return 0;
}

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && !defined(RIGIDLCP_NO_AVX2)
#define LU_HAVE_AVX2 1
/* `lu` below where the CPU has AVX2: the same operations on every entry (each multiplier
 * l = A[i, k] / piv one correctly rounded division, each update a product then a difference,
 * no fused multiply-add), four at a time -- the multipliers of a step, then each row's update
 * -- so the same numbers and the same verdict. */
__attribute__((target("avx2"))) static int lu_avx2(idx m, double *A, idx *perm)
{
    double umax = 0.0, umin = INFINITY;
    for (idx k = 0; k < m; k++) {
        if (lu_pivot(m, A, perm, k) != 0) return -1;
        double piv = A[k * m + k];
        const __m256d vp = _mm256_set1_pd(piv);
        idx i = k + 1;
        for (; i + 4 <= m; i += 4) {  /* the multipliers of step k, four divisions at once */
            double *a0 = A + i * m + k, *a1 = a0 + m, *a2 = a1 + m, *a3 = a2 + m;
            double l[4];
            _mm256_storeu_pd(l, _mm256_div_pd(_mm256_set_pd(*a3, *a2, *a1, *a0), vp));
            *a0 = l[0], *a1 = l[1], *a2 = l[2], *a3 = l[3];
        }
        for (; i < m; i++) A[i * m + k] /= piv;
        const double *ak = A + k * m + k + 1;
        const idx len = m - k - 1;
        for (i = k + 1; i < m; i++) {
            const double l = A[i * m + k];
            if (l == 0.0) continue;
            double *ai = A + i * m + k + 1;
            const __m256d vl = _mm256_set1_pd(l);
            idx j = 0;
            for (; j + 4 <= len; j += 4)
                _mm256_storeu_pd(ai + j, _mm256_sub_pd(_mm256_loadu_pd(ai + j),
                                                       _mm256_mul_pd(vl, _mm256_loadu_pd(ak + j))));
            for (; j < len; j++) ai[j] -= l * ak[j];
        }
        umax = dmax(umax, fabs(piv));
        umin = dmin(umin, fabs(piv));
    }
    return (m > 0 && !(umin > (double)m * DBL_EPSILON * umax)) ? -1 : 0;
}
static int lu_avx2_ok = -1; /* -1: not decided yet */
#else
#define LU_HAVE_AVX2 0
#endif

/* LU with partial pivoting of A (m x m, row-major, in place: L below the diagonal, U on and
 * above; perm[k] the row swapped with k at step k). -1 if U is singular to working precision:
 * a pivot below m eps times the largest (the numpy code then decides, by its SVD path). */
static int lu(idx m, double *A, idx *perm)
{
#if LU_HAVE_AVX2
    if (lu_avx2_ok < 0) {
        __builtin_cpu_init();
        lu_avx2_ok = __builtin_cpu_supports("avx2") ? 1 : 0;
    }
    if (lu_avx2_ok) return lu_avx2(m, A, perm);
#endif
    double umax = 0.0, umin = INFINITY;
    for (idx k = 0; k < m; k++) {
        if (lu_pivot(m, A, perm, k) != 0) return -1;
        double piv = A[k * m + k];
        for (idx i = k + 1; i < m; i++) {
            double l = A[i * m + k] / piv;
            A[i * m + k] = l;
            if (l == 0.0) continue;
            if (m - k - 1 >= 16)  /* long rows: the AVX2 clone where the CPU has it */
                row_update(A + i * m + k + 1, A + k * m + k + 1, l, m - k - 1);
            else
                for (idx j = k + 1; j < m; j++) A[i * m + j] -= l * A[k * m + j];
        }
        umax = dmax(umax, fabs(piv));
        umin = dmin(umin, fabs(piv));
    }
    return (m > 0 && !(umin > (double)m * DBL_EPSILON * umax)) ? -1 : 0;
}

/* x <- P x for the row interchanges `perm` of `lu` (x[k] and x[perm[k]] swapped for k = 0, 1,
 * ..., m - 1 in this order): the first step of a solve with the factors. */
static void permute(idx m, const idx *perm, double *x)
{
    for (idx k = 0; k < m; k++)
        if (perm[k] != k) {
            double t = x[k];
            x[k] = x[perm[k]];
            x[perm[k]] = t;
        }
}

/* x <- K^-1 x (trans = 0) or K^-T x (trans = 1) from the LU of `lu`. */
static void lu_solve(idx m, const double *A, const idx *perm, double *x, int trans)
{
    if (!trans) {
        permute(m, perm, x);
        /* L (unit): x[i] -= A[i, j] x[j] for j = 0, 1, ..., i - 1 in this order; four rows
         * at once, each row's subtractions in that same order (the same numbers, sooner) */
        idx i = 0;
        for (; i + 4 <= m; i += 4) {
            const double *A0 = A + i * m, *A1 = A0 + m, *A2 = A1 + m, *A3 = A2 + m;
            double x0 = x[i], x1 = x[i + 1], x2 = x[i + 2], x3 = x[i + 3];
            for (idx j = 0; j < i; j++) {
                double xj = x[j];
                x0 -= A0[j] * xj;
                x1 -= A1[j] * xj;
                x2 -= A2[j] * xj;
                x3 -= A3[j] * xj;
            }
            x1 -= A1[i] * x0;
            x2 -= A2[i] * x0;
            x3 -= A3[i] * x0;
            x2 -= A2[i + 1] * x1;
            x3 -= A3[i + 1] * x1;
            x3 -= A3[i + 2] * x2;
            x[i] = x0, x[i + 1] = x1, x[i + 2] = x2, x[i + 3] = x3;
        }
        for (; i < m; i++)
            for (idx j = 0; j < i; j++) x[i] -= A[i * m + j] * x[j];
        for (idx i = m - 1; i >= 0; i--) {
            for (idx j = i + 1; j < m; j++) x[i] -= A[i * m + j] * x[j];
            x[i] /= A[i * m + i];
        }
    } else {  /* K = P^T L U: K^T x = b  <=>  U^T L^T (P x) = b */
        /* U^T: x[i] -= A[j, i] x[j] for j = 0, ..., i - 1 in this order, then x[i] /= A[i, i];
         * done column by column (row j of A, contiguous): each x[i] gets the same
         * subtractions in the same order */
        for (idx j = 0; j < m; j++) {
            x[j] /= A[j * m + j];
            const double xj = x[j], *Aj = A + j * m;
            for (idx i = j + 1; i < m; i++) x[i] -= Aj[i] * xj;
        }
        for (idx i = m - 1; i >= 0; i--)
            for (idx j = i + 1; j < m; j++) x[i] -= A[j * m + i] * x[j];
        for (idx k = m - 1; k >= 0; k--)
            if (perm[k] != k) {
                double t = x[k];
                x[k] = x[perm[k]];
                x[perm[k]] = t;
            }
    }
}

#endif /* RIGIDLCP_LU_CORE_H */
