/* The equilibration check shared by lcp/_lemke_c.c and lcp/solvers/_pivot_c.c (included by
 * both): lcp/acceptance/scaling.py's `ruiz` for a balanced M, where it makes no sweep and only
 * changes the unit of q. The includer defines `idx` (Py_ssize_t) and includes <float.h>,
 * <math.h>, <stdint.h> and <string.h>. */
#ifndef RIGIDLCP_BALANCED_H
#define RIGIDLCP_BALANCED_H

/* The equilibration of lcp/scaling.py's `ruiz`, done here for a balanced M (every row and
 * column maximum of |M| at least 1/BALANCED of the largest entry: `ruiz` then makes no sweep
 * and only changes the unit of q: r = 1/s, c = s, s the power of 2 nearest |q|_inf). */
#define BALANCED 16.0
#define NEEDS_RUIZ 4 /* mode 1 and M not balanced (or s not decided here): equilibrate in numpy */
#define NOT_FINITE 5 /* the equilibrated data are not finite: lemke() would refuse them */

/* The power of 2 nearest x > 0 in the log sense, numpy's exp2(round(log2(x))) in
 * lcp/scaling.py's `_pow2`, read from the bits of x = (1 + f) 2^e: 2^e if 1 + f < sqrt 2, else
 * 2^(e + 1). Returns 0 (the caller then leaves it to numpy) when x is not a positive normal
 * number, when 1 + f is within 1e-9 of sqrt 2 (where the last bit of a computed log2 could
 * decide the rounding) or when 2^-e would not be a normal number. */
static double pow2_near(double x)
{
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    int be = (int)((u >> 52) & 0x7FF);
    if (be == 0 || be == 0x7FF || (u >> 63)) return 0.0;
    double f = (double)(u & 0xFFFFFFFFFFFFFULL) / 4503599627370496.0; /* 2^52: exact */
    double gap = f - 0.41421356237309504880;                           /* sqrt 2 - 1 */
    if (gap < 1e-9 && gap > -1e-9) return 0.0;
    int k = be - 1023 + (gap > 0);
    if (k < -1000 || k > 1000) return 0.0;
    uint64_t v = (uint64_t)(k + 1023) << 52;
    double s;
    memcpy(&s, &v, sizeof s);
    return s;
}

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && !defined(RIGIDLCP_NO_AVX2)
#include <immintrin.h>
#define BALANCED_AVX2 1
static int balanced_avx2 = -1; /* -1: not decided yet */
/* balanced_units's pass over M four lanes wide: the column maxima (colmax, zeroed by the
 * caller), the largest entry (*top) and the smallest row maximum (*rmin), and whether every
 * entry is finite. Maxima and minima of finite numbers do not depend on the order in which they
 * are taken; with a NaN or an infinity only the finiteness is used. */
__attribute__((target("avx2"))) static int row_col_max_avx2(idx n, const double *M,
                                                            double *colmax, double *top,
                                                            double *rmin)
{
    const __m256d sign = _mm256_set1_pd(-0.0), big = _mm256_set1_pd(DBL_MAX);
    __m256d bad = _mm256_setzero_pd();
    int finite = 1;
    for (idx i = 0; i < n; i++) {
        const double *Mi = M + i * n;
        __m256d rv = _mm256_setzero_pd();
        idx j = 0;
        for (; j + 4 <= n; j += 4) {
            __m256d a = _mm256_andnot_pd(sign, _mm256_loadu_pd(Mi + j));
            bad = _mm256_or_pd(bad, _mm256_cmp_pd(a, big, _CMP_NLE_UQ));
            rv = _mm256_max_pd(rv, a);
            _mm256_storeu_pd(colmax + j, _mm256_max_pd(_mm256_loadu_pd(colmax + j), a));
        }
        double l[4];
        _mm256_storeu_pd(l, rv);
        double rm = l[0];
        for (int k = 1; k < 4; k++) rm = l[k] > rm ? l[k] : rm;
        for (; j < n; j++) {
            double a = fabs(Mi[j]), cm = colmax[j];
            finite &= a <= DBL_MAX;
            rm = a > rm ? a : rm;
            colmax[j] = a > cm ? a : cm;
        }
        *top = rm > *top ? rm : *top;
        *rmin = rm < *rmin ? rm : *rmin;
    }
    return finite && _mm256_movemask_pd(bad) == 0;
}
#else
#define BALANCED_AVX2 0
#endif

/* Mode 1: is M (finite) balanced? Then *rs = 1/s, *cs = s (or 1, 1 when q = 0) and 0 is
 * returned; NEEDS_RUIZ otherwise, NOT_FINITE if M or q has a NaN or an infinity. colmax:
 * scratch of n doubles; *top_out (unless NULL) = max|M| when M and q are finite. */
static int balanced_units(idx n, const double *M, const double *q, double *colmax, double *rs,
                          double *cs, double *top_out)
{
    /* Branch-free maxima (x > m ? x : m) and finiteness test (|x| <= DBL_MAX is false for
     * inf and NaN): random data would defeat the branch predictor. */
    double top = 0.0, rmin = DBL_MAX;
    int finite = 1;
    for (idx j = 0; j < n; j++) colmax[j] = 0.0;
#if BALANCED_AVX2
    if (balanced_avx2 < 0) {
        __builtin_cpu_init();
        balanced_avx2 = __builtin_cpu_supports("avx2") ? 1 : 0;
    }
    if (balanced_avx2) finite = row_col_max_avx2(n, M, colmax, &top, &rmin);
    for (idx i = 0; i < n && !balanced_avx2; i++) {
#else
    for (idx i = 0; i < n; i++) {
#endif
        const double *Mi = M + i * n;
        double rm = 0.0;
        for (idx j = 0; j < n; j++) {
            double a = fabs(Mi[j]), cm = colmax[j];
            finite &= a <= DBL_MAX;
            rm = a > rm ? a : rm;
            colmax[j] = a > cm ? a : cm;
        }
        top = rm > top ? rm : top;
        rmin = rm < rmin ? rm : rmin;
    }
    double qmax = 0.0;
    for (idx i = 0; i < n; i++) {
        double a = fabs(q[i]);
        finite &= a <= DBL_MAX;
        qmax = a > qmax ? a : qmax;
    }
    if (!finite) return NOT_FINITE;
    if (top_out) *top_out = top;
    double cmin = DBL_MAX;
    for (idx j = 0; j < n; j++) cmin = colmax[j] < cmin ? colmax[j] : cmin;
    if (!(top > 0 && rmin >= top / BALANCED && cmin >= top / BALANCED)) return NEEDS_RUIZ;
    *rs = *cs = 1.0;
    if (qmax > 0) {
        double s = pow2_near(qmax);
        if (s == 0.0) return NEEDS_RUIZ;
        *rs = 1.0 / s;
        *cs = 1.0 * s;
    }
    return 0;
}

#endif /* RIGIDLCP_BALANCED_H */
