/* The updates of Lemke's dictionary T (included by lcp/_lemke_run.h, after the Lemke state):
 * the eager rank-one update of every column at a pivot (and its AVX2 clone), and the lazy
 * updates of the work array's runs, where a column gets the pivots' updates it has not had
 * only when it is read (sync_column), each entry the same operations in the same order: the
 * same numbers, with a third of the column updates at n = 30 (issue 23). Also
 * HAVE_AVX2_CLONE and cpu_avx2(), which the other parts of _lemke_c.c use. */
#ifndef RIGIDLCP_LEMKE_UPDATE_H
#define RIGIDLCP_LEMKE_UPDATE_H

/* ------------------------------------------------------------------ the rank-one update */
/* T[:, c] += col * row[c] for every c with row[c] != 0, each entry rounded twice (the product,
 * then the sum: no fused multiply-add, -ffp-contract=off), as the numpy loop of lemke.py does
 * with np.multiply and np.add. So both loops see the same numbers and take the same pivots on
 * every CPU, whatever BLAS kernel the machine has (OpenBLAS's ?ger kernels fuse some entries
 * and not others: Haswell's fuses blocks of 16 rows and rounds the remainder twice). */
static void update_plain(double *T, const double *col, const double *row, idx n, idx ld,
                         idx m)
{
    for (idx c = 0; c < m; c++) {
        double rc = row[c];
        if (rc == 0.0) continue; /* adds 0 * col: changes nothing but the sign of a zero */
        double *Tc = T + ld * c;
        for (idx i = 0; i < n; i++) Tc[i] += col[i] * rc;
    }
}

/* The AVX2 clones (here, in _balanced.h, acceptance/_accuracy_core.h and _lu_core.h) are
 * chosen at run time where the CPU has AVX2; built with -DRIGIDLCP_NO_AVX2 (or on another
 * architecture) only the plain loops remain, with the same numbers: benchmarks/ab_builds.py
 * --ref on such a build compares the two (docs/performance.md, third pass). */
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && !defined(RIGIDLCP_NO_AVX2)
#define HAVE_AVX2_CLONE 1
#include <immintrin.h>
/* The same loop vectorized 4 wide: each lane rounds the product and the sum as the scalar
 * loop does (AVX2 without FMA), so the numbers are the same, only sooner. */
__attribute__((target("avx2"))) static void update_avx2(double *T, const double *col,
                                                       const double *row, idx n, idx ld,
                                                       idx m)
{
    if (ld % 4 == 0) {
        /* columns of a multiple of 4 doubles (padded by work_init from n = 8 on): the whole
         * column, 8 entries a step, no scalar remainder. col's padding entries are 0 (pivot
         * copies the padded column, whose padding rows work_init zeroed), so the padding rows
         * of T only ever get 0 * rc added: never read, they change nothing. */
        for (idx c = 0; c < m; c++) {
            double rc = row[c];
            if (rc == 0.0) continue;
            double *Tc = T + ld * c;
            const __m256d v = _mm256_set1_pd(rc);
            idx i = 0;
            for (; i + 8 <= ld; i += 8) {
                __m256d a = _mm256_loadu_pd(Tc + i), b = _mm256_loadu_pd(Tc + i + 4);
                a = _mm256_add_pd(a, _mm256_mul_pd(_mm256_loadu_pd(col + i), v));
                b = _mm256_add_pd(b, _mm256_mul_pd(_mm256_loadu_pd(col + i + 4), v));
                _mm256_storeu_pd(Tc + i, a);
                _mm256_storeu_pd(Tc + i + 4, b);
            }
            if (i < ld)
                _mm256_storeu_pd(Tc + i, _mm256_add_pd(_mm256_loadu_pd(Tc + i),
                                                       _mm256_mul_pd(_mm256_loadu_pd(col + i), v)));
        }
        return;
    }
    for (idx c = 0; c < m; c++) {
        double rc = row[c];
        if (rc == 0.0) continue;
        double *Tc = T + ld * c;
        for (idx i = 0; i < n; i++) Tc[i] += col[i] * rc;
    }
}
static int use_avx2 = -1; /* -1: not decided yet */
static int cpu_avx2(void)
{
    if (use_avx2 < 0) {
        __builtin_cpu_init();
        use_avx2 = __builtin_cpu_supports("avx2") ? 1 : 0;
    }
    return use_avx2;
}
#else
#define HAVE_AVX2_CLONE 0
#endif

/* ------------------------------------------------------------------ one column's update */
/* Tc += col * rc, each entry rounded twice as in update_plain / update_avx2 (one column of
 * their loops: the same numbers). */
#if HAVE_AVX2_CLONE
__attribute__((target("avx2"))) static void column_update_avx2(double *Tc, const double *col,
                                                              double rc, idx n, idx ld)
{
    double row1[1] = {rc};
    update_avx2(Tc, col, row1, n, ld, 1);
}
#endif

static void column_update(double *Tc, const double *col, double rc, idx n, idx ld)
{
#if HAVE_AVX2_CLONE
    if (cpu_avx2()) {
        column_update_avx2(Tc, col, rc, n, ld);
        return;
    }
#endif
    for (idx i = 0; i < n; i++) Tc[i] += col[i] * rc;
}

/* Column c of T brought up to date (lazy mode): the updates of the pivots it has not had, in
 * their order, each as the eager pivot does it -- rc = T[r, c] * mult, T[r, c] = 0, then
 * T[:, c] += eta * rc unless rc is 0 -- so the column holds the same numbers as if every
 * pivot had updated it. */
#if HAVE_AVX2_CLONE
/* sync_column's etas e = from .. ne - 1 on Tc (ld a multiple of 4, Tc 32-byte aligned: T and
 * its padded columns are, see work_init). The zeroing of T[r_e, c] is done in the register of
 * its aligned four-entry block, loaded whole, not by a scalar store (the vector load of that
 * block which followed a scalar store waited for the store to retire: that first version was
 * 1.06-1.14x slower than the eager update at n <= 30). Each entry gets the eager update's
 * operations (rc = T[r, c] * mult, T[r, c] = 0, then += eta * rc unless rc = 0) in its
 * order, so the same numbers. */
__attribute__((target("avx2"))) static void sync_avx2(Lemke *L, double *Tc, idx from, idx ne)
{
    const idx ld = L->ld;
    const __m256d zero = _mm256_setzero_pd();
    for (idx e = from; e < ne; e++) {
        const idx r = L->er[e], rb = r & ~(idx)3;
        const __m256i lane = _mm256_set1_epi64x((long long)(r & 3));
        const __m256d blk = _mm256_load_pd(Tc + rb);
        const __m256d here = _mm256_castsi256_pd(
            _mm256_cmpeq_epi64(_mm256_set_epi64x(3, 2, 1, 0), lane));
        double rc = Tc[r] * L->emult[e];
        const double *col = L->E + ld * e;
        const __m256d v = _mm256_set1_pd(rc);
        if (rc == 0.0) { /* T[r, c] = 0 only */
            _mm256_store_pd(Tc + rb, _mm256_blendv_pd(blk, zero, here));
            continue;
        }
        for (idx i = 0; i < ld; i += 4) {
            __m256d a = i == rb ? _mm256_blendv_pd(blk, zero, here) : _mm256_load_pd(Tc + i);
            _mm256_store_pd(Tc + i, _mm256_add_pd(a, _mm256_mul_pd(_mm256_loadu_pd(col + i), v)));
        }
    }
}
#endif

static void sync_column(Lemke *L, idx c)
{
    const idx ne = L->ne, n = L->n, ld = L->ld;
    double *Tc = L->T + ld * c;
#if HAVE_AVX2_CLONE
    if (ld % 4 == 0 && cpu_avx2()) {
        if (L->ver[c] < ne) sync_avx2(L, Tc, L->ver[c], ne);
        L->ver[c] = ne;
        return;
    }
#endif
    for (idx e = L->ver[c]; e < ne; e++) {
        const idx r = L->er[e];
        double rc = Tc[r] * L->emult[e];
        Tc[r] = 0.0;
        if (rc == 0.0) continue;
        column_update(Tc, L->E + ld * e, rc, n, ld);
    }
    L->ver[c] = ne;
}

/* The pivot on (r, s) in lazy mode (pivot's numbers; T[:, s] up to date): the eta kept, beta
 * (slot n + 1) updated, the entering column replaced by eta / p; the other columns wait.
 * With ecap etas kept, every column is brought up to date first and the etas dropped. */
static void pivot_lazy(Lemke *L, idx r, idx s)
{
    const idx n = L->n, ld = L->ld;
    if (L->ne == L->ecap) {
        for (idx c = 0; c < n + 2; c++) sync_column(L, c);
        for (idx c = 0; c < n + 2; c++) L->ver[c] = 0;
        L->ne = 0;
    }
    const idx e = L->ne;
    double *Ts = L->T + ld * s, *col = L->E + ld * e;
    double p = Ts[r];
    memcpy(col, Ts, ld * sizeof(double)); /* with the padding rows (0) when ld > n */
    double mult = -1.0 / p, rs = 1.0 / p;
    col[r] = 1.0;
    L->er[e] = r;
    L->emult[e] = mult;
    L->ne = e + 1;
    sync_column(L, n + 1); /* beta */
    memset(Ts, 0, n * sizeof(double));
    if (rs != 0.0) column_update(Ts, col, rs, n, ld);
    L->ver[s] = e + 1;
}

#endif /* RIGIDLCP_LEMKE_UPDATE_H */
