/* Lemke's pivoting run on one dictionary (included by lcp/_lemke_c.c): the Lemke state, the
 * basis hash that detects numerical cycling, the pivot (its updates of the dictionary, eager
 * or lazy, in _lemke_update.h), the ratio test with the lexicographic tie-break, and `run`, the
 * loop of lcp/solvers/lemke.py's `_Lemke.run` (same rules, same order of floating-point
 * operations). Also HAVE_AVX2_CLONE and cpu_avx2() (_lemke_update.h), which the other parts of
 * _lemke_c.c use. The includer
 * defines `idx` (Py_ssize_t) and includes <stdint.h>, <stdlib.h> and <string.h>. */
#ifndef RIGIDLCP_LEMKE_RUN_H
#define RIGIDLCP_LEMKE_RUN_H

typedef struct {
    idx n;
    idx ld; /* column stride of T: n for a dictionary from Python; in the work array of
             * solve_eq / solve_batch n rounded up to a multiple of 4 from n = 8 on (columns
             * 32-byte aligned) */
    double *T;
    int64_t *basic, *nonbasic, *row_of, *slot_of;
    double tol;
    /* scratch */
    idx *rows, *cand, *wj, *pos;
    double *alpha, *theta, *row, *col, *V;
    /* lazy updates (solve_problem's runs; 0 in `run` from Python): each pivot's column (the
     * eta, ld doubles, its pivot row's entry 1), row and multiplier are kept, and a column of
     * T gets the updates it has not had only when it is read (sync_column); beta and the
     * entering column are updated at every pivot. ne etas kept (at most ecap), ver[c] the
     * number column c has had. */
    int lazy;
    idx ne, ecap;
    double *E, *emult, *cur, *rcs; /* cur, rcs, tr: sync_avx2's scratch (ecap each) */
    idx *er, *ver, *tr;
} Lemke;

/* ------------------------------------------------------------------ basis hash (Zobrist) */
typedef struct {
    int64_t *slot;
    size_t cap, count;
    int heap; /* slot malloc'd (freed when the set grows or ends), else the caller's */
} HashSet;

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

/* buf: cap entries of the caller's (NULL: malloc'd here) */
static int hs_init(HashSet *h, size_t cap, int64_t *buf)
{
    h->cap = cap;
    h->count = 0;
    h->heap = buf == NULL;
    h->slot = buf ? buf : (int64_t *)malloc(cap * sizeof(int64_t));
    if (!h->slot) return -1;
    memset(h->slot, 0xFF, cap * sizeof(int64_t)); /* -1: empty (keys are >= 0) */
    return 0;
}

/* 1 if key was present, 0 if inserted, -1 on allocation failure. */
static int hs_add(HashSet *h, int64_t key)
{
    if (2 * (h->count + 1) > h->cap) {
        HashSet g;
        if (hs_init(&g, 2 * h->cap, NULL) < 0) return -1;
        for (size_t i = 0; i < h->cap; i++)
            if (h->slot[i] >= 0) hs_add(&g, h->slot[i]);
        if (h->heap) free(h->slot);
        *h = g;
    }
    size_t mask = h->cap - 1, i = (size_t)((uint64_t)key * 0x9E3779B97F4A7C15ULL >> 7) & mask;
    while (h->slot[i] >= 0) {
        if (h->slot[i] == key) return 1;
        i = (i + 1) & mask;
    }
    h->slot[i] = key;
    h->count++;
    return 0;
}

#include "_lemke_update.h" /* update_plain / update_avx2, sync_column, pivot_lazy */

/* ------------------------------------------------------------------ the pivot */
static int64_t pivot(Lemke *L, idx r, idx s)
{
    const idx n = L->n, ld = L->ld, m = n + 2;
    if (L->lazy) {
        pivot_lazy(L, r, s);
        goto swap;
    }
    double *T = L->T, *row = L->row, *col = L->col;
    double *Ts = T + ld * s;
    double p = Ts[r];
    memcpy(col, Ts, ld * sizeof(double)); /* with the padding rows (0) when ld > n */
    double mult = -1.0 / p;
    for (idx c = 0; c < m; c++) row[c] = T[r + ld * c] * mult;
    row[s] = 1.0 / p;
    for (idx c = 0; c < m; c++) T[r + ld * c] = 0.0;
    memset(Ts, 0, n * sizeof(double));
    col[r] = 1.0;
#if HAVE_AVX2_CLONE
    if (use_avx2 < 0) {
        __builtin_cpu_init();
        use_avx2 = __builtin_cpu_supports("avx2") ? 1 : 0;
    }
    if (use_avx2)
        update_avx2(T, col, row, n, ld, m);
    else
#endif
        update_plain(T, col, row, n, ld, m);
swap:;
    int64_t entering = L->nonbasic[s], leaving = L->basic[r];
    L->basic[r] = entering;
    L->nonbasic[s] = leaving;
    L->row_of[entering] = r;
    L->slot_of[entering] = -1;
    L->row_of[leaving] = -1;
    L->slot_of[leaving] = s;
    return leaving;
}

/* ------------------------------------------------------------------ lexicographic minimum */
/* Row in rows[0..m) with the lexicographically smallest B^-1[i, :] / alpha_i (lemke.py's
 * `_Lemke.lexico_min`, same sweep and tolerances). */
static idx lexico_min(Lemke *L, const idx *rows, const double *alpha, idx m)
{
    const idx n = L->n;
    const double *T = L->T;
    idx nw = 0;
    for (idx j = 0; j < n; j++)
        if (L->slot_of[j] >= 0) L->wj[nw++] = j;
    double *V = L->V; /* m x nw, column-major */
    double vmax = 0.0, ainv = -1.0 / 0.0;
    for (idx k = 0; k < nw; k++) {
        if (L->lazy) sync_column(L, L->slot_of[L->wj[k]]);
        const double *Tk = T + L->ld * L->slot_of[L->wj[k]];
        for (idx i = 0; i < m; i++) {
            double v = -Tk[rows[i]] / alpha[i];
            V[i + m * k] = v;
            double av = v < 0 ? -v : v;
            if (av > vmax) vmax = av;
        }
    }
    for (idx i = 0; i < m; i++) {
        double a = 1.0 / alpha[i];
        if (a > ainv) ainv = a;
        int64_t b = L->basic[rows[i]];
        L->pos[i] = b < n ? (idx)b : n;
    }
    double eps = L->tol * (vmax > ainv ? vmax : ainv);
    idx *cand = L->cand, nc = m;
    for (idx i = 0; i < m; i++) cand[i] = i;
    idx k = -1;
    for (;;) {
        /* next column where the tied rows differ (max - min > eps over all m rows) */
        for (k = k + 1; k < nw; k++) {
            double lo = V[m * k], hi = lo;
            for (idx i = 1; i < m; i++) {
                double v = V[i + m * k];
                if (v < lo) lo = v;
                if (v > hi) hi = v;
            }
            if (hi - lo > eps) break;
        }
        int last = k >= nw;
        idx j = last ? n : L->wj[k];
        idx n_early = 0;
        for (idx t = 0; t < nc; t++)
            if (L->pos[cand[t]] < j) n_early++;
        if (n_early == nc) {
            idx best = 0;
            for (idx t = 1; t < nc; t++)
                if (L->pos[cand[t]] > L->pos[cand[best]]) best = t;
            cand[0] = cand[best];
            nc = 1;
        } else if (n_early > 0) {
            idx u = 0;
            for (idx t = 0; t < nc; t++)
                if (!(L->pos[cand[t]] < j)) cand[u++] = cand[t];
            nc = u;
        }
        if (nc == 1 || last) break;
        double vmin = V[cand[0] + m * k];
        for (idx t = 1; t < nc; t++)
            if (V[cand[t] + m * k] < vmin) vmin = V[cand[t] + m * k];
        double lim = vmin + eps;
        idx u = 0;
        for (idx t = 0; t < nc; t++)
            if (V[cand[t] + m * k] <= lim) cand[u++] = cand[t];
        nc = u;
        if (nc == 1) break;
    }
    idx best = 0;
    for (idx t = 1; t < nc; t++)
        if (alpha[cand[t]] > alpha[cand[best]]) best = t;
    return rows[cand[best]];
}

/* ------------------------------------------------------------------ the ratio test */
/* Minimum ratio among rows[0..m) (ratios theta, pivots alpha > 0, amax = max alpha); ties
 * within tol / amax: z0 leaves if it can, else the lexicographic minimum. Overwrites the
 * leading entries of rows and alpha with the tied ones. */
static idx choose(Lemke *L, idx *rows, double *alpha, const double *theta, idx m, double amax)
{
    idx k = 0;
    for (idx i = 1; i < m; i++)
        if (theta[i] < theta[k]) k = i;
    double lim = theta[k] + L->tol / amax;
    idx mt = 0;
    for (idx i = 0; i < m; i++)
        if (theta[i] <= lim) {
            rows[mt] = rows[i];
            alpha[mt] = alpha[i];
            mt++;
        }
    if (mt == 1) return rows[0];
    int64_t z0_row = L->row_of[2 * L->n];
    if (z0_row >= 0)
        for (idx i = 0; i < mt; i++)
            if (rows[i] == z0_row) return (idx)z0_row;
    return lexico_min(L, rows, alpha, mt);
}

/* ------------------------------------------------------------------ the column minimum */
/* min over a[0..n) as the loop amin = a[i] < amin ? a[i] : amin from amin = a[0] (a NaN
 * skipped, unless a[0] is one: then NaN). Four lanes wide where the CPU has AVX2: each lane
 * keeps the same rule (vminpd returns its second operand unless the first is smaller), and the
 * minimum of numbers does not depend on the order (of two zeros the sign may differ, which no
 * use of it sees: only amax = -amin compared with thresholds and 1 follows). */
#if HAVE_AVX2_CLONE
__attribute__((target("avx2"))) static double column_min_avx2(const double *a, idx n)
{
    __m256d m = _mm256_set1_pd(a[0]);
    idx i = 1;
    for (; i + 4 <= n; i += 4) m = _mm256_min_pd(_mm256_loadu_pd(a + i), m);
    double l[4];
    _mm256_storeu_pd(l, m);
    double amin = l[0];
    for (int k = 1; k < 4; k++) amin = l[k] < amin ? l[k] : amin;
    for (; i < n; i++) amin = a[i] < amin ? a[i] : amin;
    return amin;
}
#endif

static double column_min(const double *a, idx n)
{
#if HAVE_AVX2_CLONE
    if (n >= 16 && cpu_avx2()) return column_min_avx2(a, n);
#endif
    double amin = a[0];
    for (idx i = 1; i < n; i++) amin = a[i] < amin ? a[i] : amin; /* minsd: no branch */
    return amin;
}

/* ------------------------------------------------------------------ the ratios */
/* alpha_t = -a_i and theta_t = max(beta_i, 0) / alpha_t for the blocking rows i = rows[t]
 * (b > 0 ? b : 0: a NaN or -0 gives 0). Four at a time where the CPU has AVX2: the divisions
 * were the ratio test's bottleneck, and a division, a negation (the sign bit flipped) and
 * vmaxpd(b, 0) (b when b > 0, else 0, NaN included) give each lane the scalar loop's number. */
static void ratios_plain(const double *a, const double *beta, const idx *rows, idx m,
                         double *alpha, double *theta)
{
    for (idx t = 0; t < m; t++) {
        double al = -a[rows[t]], b = beta[rows[t]];
        alpha[t] = al;
        theta[t] = (b > 0.0 ? b : 0.0) / al;
    }
}

#if HAVE_AVX2_CLONE
__attribute__((target("avx2"))) static void ratios_avx2(const double *a, const double *beta,
                                                       const idx *rows, idx m, double *alpha,
                                                       double *theta)
{
    const __m256d sign = _mm256_set1_pd(-0.0), zero = _mm256_setzero_pd();
    idx t = 0;
    for (; t + 4 <= m; t += 4) {
        const idx i0 = rows[t], i1 = rows[t + 1], i2 = rows[t + 2], i3 = rows[t + 3];
        __m256d al = _mm256_xor_pd(_mm256_set_pd(a[i3], a[i2], a[i1], a[i0]), sign);
        __m256d b = _mm256_max_pd(_mm256_set_pd(beta[i3], beta[i2], beta[i1], beta[i0]), zero);
        _mm256_storeu_pd(alpha + t, al);
        _mm256_storeu_pd(theta + t, _mm256_div_pd(b, al));
    }
    ratios_plain(a, beta, rows + t, m - t, alpha + t, theta + t);
}
#endif

static void ratios(const double *a, const double *beta, const idx *rows, idx m, double *alpha,
                   double *theta)
{
#if HAVE_AVX2_CLONE
    if (m >= 8 && cpu_avx2()) {
        ratios_avx2(a, beta, rows, m, alpha, theta);
        return;
    }
#endif
    ratios_plain(a, beta, rows, m, alpha, theta);
}

/* ------------------------------------------------------------------ the run */
#define RUN_STACK_N 256 /* run's keys on the stack up to this n */
static int run(Lemke *L, long long max_iter, int64_t *trace, idx trace_len,
               long long *out_pivots, idx *out_s, int64_t *out_entering)
{
    const idx n = L->n;
    const idx ld = L->ld;
    double *T = L->T, *beta = T + ld * (n + 1);
    const int64_t z0 = 2 * n;
    /* the keys and the first hash table on the stack up to n = RUN_STACK_N (no allocation
     * for small problems; the table moves to the heap when it grows) */
    uint64_t kbuf[2 * RUN_STACK_N + 1];
    int64_t hbuf[1024];
    uint64_t seed = 0x5EEDULL,
             *keys = n <= RUN_STACK_N ? kbuf : (uint64_t *)malloc((2 * n + 1) * sizeof(uint64_t));
    HashSet seen;
    if (!keys) return -1;
    size_t cap = 64; /* grows as needed: start small, a small problem takes few pivots */
    while (cap < 1024 && cap < (size_t)(8 * n)) cap *= 2;
    if (hs_init(&seen, cap, hbuf) < 0) {
        if (keys != kbuf) free(keys);
        return -1;
    }
    for (idx i = 0; i < 2 * n + 1; i++) keys[i] = splitmix64(&seed) >> 1; /* >= 0 as int64 */
    int code = -1;
    /* step 0: z0 enters; every row blocks with pivot d_i and ratio q_i / d_i */
    double amax = -1.0 / 0.0;
    for (idx i = 0; i < n; i++) {
        L->rows[i] = i;
        L->alpha[i] = T[i + ld * n];
        L->theta[i] = beta[i] / L->alpha[i];
        if (L->alpha[i] > amax) amax = L->alpha[i];
    }
    idx r = choose(L, L->rows, L->alpha, L->theta, n, amax), s = n;
    long long pivots = 0;
    int64_t h = 0, ent = z0, entering = -1;
    for (;;) {
        int64_t leaving = pivot(L, r, s);
        if (pivots < trace_len) {
            trace[2 * pivots] = r;
            trace[2 * pivots + 1] = s;
        }
        pivots++;
        if (leaving == z0) {
            code = 0;
            break;
        }
        h ^= (int64_t)(keys[leaving] ^ keys[ent]);
        int added = hs_add(&seen, h);
        if (added < 0) {
            code = -1;
            break;
        }
        if (added == 1) {
            code = 1;
            break;
        }
        if (pivots >= max_iter) {
            code = 2;
            break;
        }
        entering = leaving < n ? leaving + n : leaving - n;
        ent = entering;
        s = (idx)L->slot_of[entering];
        if (L->lazy) sync_column(L, s);
        const double *a = T + ld * s;
        double amin = column_min(a, n);
        amax = -amin;
        double thr = amax > 1.0 ? L->tol * amax : L->tol;
        if (amax <= thr) {
            code = 3;
            break;
        }
        idx m = 0;
        for (idx i = 0; i < n; i++) { /* branch-free: random signs defeat the predictor */
            L->rows[m] = i;
            m += a[i] < -thr;
        }
        if (m == 1) {
            r = L->rows[0];
            continue;
        }
        ratios(a, beta, L->rows, m, L->alpha, L->theta);
        r = choose(L, L->rows, L->alpha, L->theta, m, amax);
    }
    if (keys != kbuf) free(keys);
    if (seen.heap) free(seen.slot);
    *out_pivots = pivots;
    *out_s = s;
    *out_entering = entering;
    return code;
}

#endif /* RIGIDLCP_LEMKE_RUN_H */
