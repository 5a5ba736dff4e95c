/* Columns of K^-1 from K's LU (lcp/acceptance/_lu_core.h), FB_COLS at a time, for the forward
 * bound of _bound_core.h (|K^-1| formed, not estimated). Each column is lu_solve's
 * substitutions on P e_j -- the L one begun at the first nonzero of P e_j (the entries above it
 * stay +0, as they would there), then U's from the last row up, each row's subtractions in the
 * order j = i + 1, ..., m - 1 and the division last -- so every entry is the same number
 * whichever way the columns are grouped; only independent chains are interleaved. The
 * substitutions are latency-bound (each row is one chain of subtractions), so the more columns
 * at once the sooner: 16 (four AVX2 registers, no fused multiply-add: the same roundings) where
 * the CPU has AVX2, else the plain loop over the same layout. The includer includes
 * _lu_core.h (permute) and defines `idx`. */
#ifndef RIGIDLCP_INVERSE_CORE_H
#define RIGIDLCP_INVERSE_CORE_H

#define FB_COLS 16 /* columns per group: X[FB_COLS i + b] is row i of column j0 + b */

/* at[j]: the row of the one nonzero (1) of P e_j, for the interchanges `perm` of `lu` (as
 * `permute` moves it). lab: scratch of m. */
static void unit_rows(idx m, const idx *perm, idx *lab, idx *at)
{
    for (idx k = 0; k < m; k++) lab[k] = k;
    for (idx k = 0; k < m; k++)
        if (perm[k] != k) {
            idx t = lab[k];
            lab[k] = lab[perm[k]];
            lab[perm[k]] = t;
        }
    for (idx k = 0; k < m; k++) at[lab[k]] = k;
}

/* The unit entries of columns j0 .. j0 + nb - 1 into X (zeroed), and the first row any of them
 * has: the L substitution starts below it. */
static idx inverse_start(idx m, const idx *at, idx j0, idx nb, double *X)
{
    idx p = m;
    memset(X, 0, (size_t)FB_COLS * m * sizeof(double));
    for (idx b = 0; b < nb; b++) {
        idx pb = at[j0 + b];
        X[FB_COLS * pb + b] = 1.0;
        p = pb < p ? pb : p;
    }
    return p;
}

static void inverse_columns_plain(idx m, const double *A, const idx *at, idx j0, idx nb,
                                  double *X)
{
    const idx lanes = (nb + 3) / 4 * 4; /* the columns beyond nb are 0 and stay so */
    idx p = inverse_start(m, at, j0, nb, X);
    for (idx i = p + 1; i < m; i++) {
        const double *Ai = A + i * m;
        double *Xi = X + FB_COLS * i;
        for (idx l = p; l < i; l++) {
            const double al = Ai[l], *Xl = X + FB_COLS * l;
            for (idx b = 0; b < lanes; b++) Xi[b] -= al * Xl[b];
        }
    }
    for (idx i = m - 1; i >= 0; i--) {
        const double *Ai = A + i * m;
        double *Xi = X + FB_COLS * i;
        for (idx l = i + 1; l < m; l++) {
            const double al = Ai[l], *Xl = X + FB_COLS * l;
            for (idx b = 0; b < lanes; b++) Xi[b] -= al * Xl[b];
        }
        const double d = Ai[i];
        for (idx b = 0; b < lanes; b++) Xi[b] = Xi[b] / d;
    }
}

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && !defined(RIGIDLCP_NO_AVX2)
#define INV_HAVE_AVX2 1
/* Row i of the group, Xi, minus sum_{l = from}^{to - 1} Ai[l] X row l, in that order: the
 * subtractions of both substitutions (one chain per column, four registers of four). */
__attribute__((target("avx2"))) static inline void sub_rows_avx2(double *Xi, const double *Ai,
                                                                const double *X, idx from,
                                                                idx to)
{
    __m256d x0 = _mm256_loadu_pd(Xi), x1 = _mm256_loadu_pd(Xi + 4),
            x2 = _mm256_loadu_pd(Xi + 8), x3 = _mm256_loadu_pd(Xi + 12);
    for (idx l = from; l < to; l++) {
        const __m256d al = _mm256_set1_pd(Ai[l]);
        const double *Xl = X + FB_COLS * l;
        x0 = _mm256_sub_pd(x0, _mm256_mul_pd(al, _mm256_loadu_pd(Xl)));
        x1 = _mm256_sub_pd(x1, _mm256_mul_pd(al, _mm256_loadu_pd(Xl + 4)));
        x2 = _mm256_sub_pd(x2, _mm256_mul_pd(al, _mm256_loadu_pd(Xl + 8)));
        x3 = _mm256_sub_pd(x3, _mm256_mul_pd(al, _mm256_loadu_pd(Xl + 12)));
    }
    _mm256_storeu_pd(Xi, x0), _mm256_storeu_pd(Xi + 4, x1);
    _mm256_storeu_pd(Xi + 8, x2), _mm256_storeu_pd(Xi + 12, x3);
}

__attribute__((target("avx2"))) static void inverse_columns_avx2(idx m, const double *A,
                                                                const idx *at, idx j0, idx nb,
                                                                double *X)
{
    idx p = inverse_start(m, at, j0, nb, X);
    for (idx i = p + 1; i < m; i++) sub_rows_avx2(X + FB_COLS * i, A + i * m, X, p, i);
    for (idx i = m - 1; i >= 0; i--) {
        double *Xi = X + FB_COLS * i;
        sub_rows_avx2(Xi, A + i * m, X, i + 1, m);
        const __m256d d = _mm256_set1_pd(A[i * m + i]);
        for (int k = 0; k < FB_COLS; k += 4)
            _mm256_storeu_pd(Xi + k, _mm256_div_pd(_mm256_loadu_pd(Xi + k), d));
    }
}
static int inv_avx2 = -1; /* -1: not decided yet */
#endif

/* Columns j0 .. j0 + nb - 1 (nb <= FB_COLS) of K^-1 into X (FB_COLS m doubles). */
static void inverse_columns(idx m, const double *A, const idx *at, idx j0, idx nb, double *X)
{
#ifdef INV_HAVE_AVX2
    if (inv_avx2 < 0) {
        __builtin_cpu_init();
        inv_avx2 = __builtin_cpu_supports("avx2") ? 1 : 0;
    }
    if (inv_avx2) {
        inverse_columns_avx2(m, A, at, j0, nb, X);
        return;
    }
#endif
    inverse_columns_plain(m, A, at, j0, nb, X);
}

#endif /* RIGIDLCP_INVERSE_CORE_H */
