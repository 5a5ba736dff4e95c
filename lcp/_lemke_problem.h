/* One whole LCP from the user's data, without the GIL (included by lcp/_lemke_c.c): the
 * equilibration of a balanced M (_balanced.h) and the scaled dictionary (fill_scaled and its
 * AVX2 one-pass clone over M), solve_problem (the steps of lemke(), z back in the user's units),
 * the work array (Work, work_init) and the acceptance of an answer (accept_one,
 * solve_and_accept) for solve_eq, solve_accept, solve_batch and solve_fast. The includer
 * includes acceptance/_accuracy_core.h (assess_one, MAX_M) and _lemke_run.h. */
#ifndef RIGIDLCP_LEMKE_PROBLEM_H
#define RIGIDLCP_LEMKE_PROBLEM_H

/* ------------------------------------------------------------------ one whole problem */
#include "_balanced.h" /* balanced_units, pow2_near: shared with solvers/_pivot_c.c */

/* The scales of a filled dictionary (fill_scaled): mu, nu, delta as in `fill`, min q~, max|M|
 * and max|q| of the data given. */
typedef struct {
    double mu, nu, delta, qmin, mmax, qmax;
} Scales;

/* The q~ column of T (unscaled by nu yet): q~ = q r (r NULL: q rs), and nu = max|q~|, qmin =
 * min q~, qmax = max|q| into S. Returns whether every q~ is finite. */
static int q_column(idx n, idx ld, double *T, const double *q, const double *r, double rs,
                    Scales *S)
{
    double nu = 0.0, qmax = 0.0, qmin = DBL_MAX;
    int finite = 1;
    for (idx i = 0; i < n; i++) {
        double v = q[i] * (r ? r[i] : rs), a = fabs(v), aq = fabs(q[i]);
        finite &= a <= DBL_MAX;
        nu = a > nu ? a : nu;
        qmin = v < qmin ? v : qmin;
        qmax = aq > qmax ? aq : qmax;
        T[i + ld * (n + 1)] = v;
    }
    S->nu = nu;
    S->qmin = qmin;
    S->qmax = qmax;
    return finite;
}

/* The covering column d / delta (d NULL: ones; delta = max d) and q~ / nu (S->nu from
 * q_column), and the rest of S: the common end of fill_scaled and fill_units_avx2. */
static void covering_column(idx n, idx ld, double *T, const double *d, double mu, double mmax,
                            Scales *S)
{
    double delta = -1.0 / 0.0, nu = S->nu;
    for (idx i = 0; i < n; i++) {
        double di = d ? d[i] : 1.0;
        if (di > delta) delta = di;
    }
    for (idx i = 0; i < n; i++) {
        T[i + ld * n] = (d ? d[i] : 1.0) / delta;
        T[i + ld * (n + 1)] = T[i + ld * (n + 1)] / nu;
    }
    S->mu = mu;
    S->delta = delta;
    S->mmax = mmax;
}

/* T = [M~ / mu, d / delta, q~ / nu] (as `fill`) for the equilibrated data M~ = (M r) c and
 * q~ = q r, rounded as numpy rounds scaling.py's M * r[:, None] * c[None, :] and q * r; r and c
 * are the arrays r, c or, when NULL, the numbers rs, cs; d NULL means ones. Also max|M| and
 * max|q| of the data given. Returns NOT_FINITE when M~ or q~ is not finite, else 0. */
static int fill_scaled(idx n, idx ld, double *T, const double *M, const double *q,
                       const double *d, const double *r, const double *c, double rs, double cs,
                       Scales *S)
{
    double mu = 0.0, mmax = 0.0;
    int finite = 1; /* branch-free, as in balanced_units */
    for (idx i = 0; i < n; i++) {
        double ri = r ? r[i] : rs;
        const double *Mi = M + i * n;
        for (idx j = 0; j < n; j++) {
            double m = Mi[j], v = (m * ri) * (c ? c[j] : cs);
            double a = fabs(v), am = fabs(m);
            finite &= a <= DBL_MAX;
            mu = a > mu ? a : mu;
            mmax = am > mmax ? am : mmax;
            T[i + ld * j] = v;
        }
    }
    finite &= q_column(n, ld, T, q, r, rs, S);
    if (!finite) return NOT_FINITE;
    if (mu == 0.0) mu = 1.0;
    for (idx j = 0; j < n; j++)
        for (idx i = 0; i < n; i++) T[i + ld * j] = T[i + ld * j] / mu;
    covering_column(n, ld, T, d, mu, mmax, S);
    return 0;
}

#if HAVE_AVX2_CLONE
/* fill_scaled for mode 1 (r = c = NULL; M and q finite, top = max|M|), in one pass over M:
 * T[i, j] = ((M_ij rs) cs) / mu, the numbers fill_scaled stores and then divides by mu. Its mu
 * is max |(M_ij rs) cs| = (top rs) cs: rounding is monotone and odd, so the maximum of the
 * rounded products is the rounded product of the maximum, known before the pass. Four rows and
 * four columns at a time, transposed in registers (T is column-major). Returns NOT_FINITE when
 * a scaled entry overflows, as fill_scaled. */
__attribute__((target("avx2"))) static int fill_units_avx2(idx n, idx ld, double *T,
                                                           const double *M, const double *q,
                                                           const double *d, double rs,
                                                           double cs, double top, Scales *S)
{
    double mu = (top * rs) * cs;
    if (!(mu <= DBL_MAX)) return NOT_FINITE; /* an entry overflows: fill_scaled's verdict */
    if (mu == 0.0) mu = 1.0;
    const __m256d vr = _mm256_set1_pd(rs), vc = _mm256_set1_pd(cs), vmu = _mm256_set1_pd(mu);
    idx i = 0;
    for (; i + 4 <= n; i += 4) {
        const double *M0 = M + i * n, *M1 = M0 + n, *M2 = M1 + n, *M3 = M2 + n;
        idx j = 0;
        for (; j + 4 <= n; j += 4) {
            __m256d r0 = _mm256_loadu_pd(M0 + j), r1 = _mm256_loadu_pd(M1 + j),
                    r2 = _mm256_loadu_pd(M2 + j), r3 = _mm256_loadu_pd(M3 + j);
            r0 = _mm256_div_pd(_mm256_mul_pd(_mm256_mul_pd(r0, vr), vc), vmu);
            r1 = _mm256_div_pd(_mm256_mul_pd(_mm256_mul_pd(r1, vr), vc), vmu);
            r2 = _mm256_div_pd(_mm256_mul_pd(_mm256_mul_pd(r2, vr), vc), vmu);
            r3 = _mm256_div_pd(_mm256_mul_pd(_mm256_mul_pd(r3, vr), vc), vmu);
            __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1),
                    t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
            _mm256_storeu_pd(T + i + ld * j, _mm256_permute2f128_pd(t0, t2, 0x20));
            _mm256_storeu_pd(T + i + ld * (j + 1), _mm256_permute2f128_pd(t1, t3, 0x20));
            _mm256_storeu_pd(T + i + ld * (j + 2), _mm256_permute2f128_pd(t0, t2, 0x31));
            _mm256_storeu_pd(T + i + ld * (j + 3), _mm256_permute2f128_pd(t1, t3, 0x31));
        }
        for (; j < n; j++)
            for (idx k = 0; k < 4; k++) T[i + k + ld * j] = ((M[(i + k) * n + j] * rs) * cs) / mu;
    }
    for (; i < n; i++)
        for (idx j = 0; j < n; j++) T[i + ld * j] = ((M[i * n + j] * rs) * cs) / mu;
    if (!q_column(n, ld, T, q, NULL, rs, S)) return NOT_FINITE;
    covering_column(n, ld, T, d, mu, top, S);
    return 0;
}
#endif

/* One LCP by the steps of lemke() on the data `solve` gives it (mode 0: as they are; 1: the
 * equilibration of a balanced M done here; 2: the factors r, c of `ruiz` given): q~ >= 0 gives
 * z = 0 and no pivot, else the dictionary and the pivot loop; z in the original units (as
 * `_Lemke.point`, then `Equilibration.z_back`: c_j z~_j) and bz[j] = z_j basic. Returns the
 * code of `run` (0..3), NEEDS_RUIZ, NOT_FINITE or -1 (out of memory); *zmax = max|z| and
 * *mmax, *qmax (of M and q as given) when solved. */
static int solve_problem(Lemke *L, double *T, const double *M, const double *q, const double *d,
                         const double *r, const double *c, int mode, long long max_iter,
                         double *z, int8_t *bz, long long *pivots, double bound[3])
{
    const idx n = L->n;
    double rs = 1.0, cs = 1.0;
    *pivots = 0;
    memset(z, 0, n * sizeof(double));
    memset(bz, 0, n);
    if (mode != 2) r = c = NULL;
    double top = 0.0;
    if (mode == 1) {
        int code = balanced_units(n, M, q, L->theta, &rs, &cs, &top);
        if (code) return code;
    }
    Scales S;
#if HAVE_AVX2_CLONE
    if (mode == 1 && cpu_avx2()) {
        if (fill_units_avx2(n, L->ld, T, M, q, d, rs, cs, top, &S)) return NOT_FINITE;
    } else
#endif
    if (fill_scaled(n, L->ld, T, M, q, d, r, c, rs, cs, &S)) return NOT_FINITE;
    bound[0] = S.mmax;
    bound[1] = S.qmax;
    bound[2] = 0.0;
    if (S.qmin >= 0) return 0; /* z = 0 solves it */
    L->T = T;
    L->ne = 0; /* no eta kept: every column of the new dictionary is up to date */
    for (idx c = 0; c < n + 2; c++) L->ver[c] = 0;
    for (idx i = 0; i < n; i++) {
        L->basic[i] = i;
        L->row_of[i] = i;
        L->slot_of[i] = -1;
    }
    for (idx j = 0; j <= n; j++) {
        L->nonbasic[j] = n + j;
        L->row_of[n + j] = -1;
        L->slot_of[n + j] = j;
    }
    idx s;
    int64_t entering;
    int code = run(L, max_iter, NULL, 0, pivots, &s, &entering);
    if (code != 0) return code;
    const double *beta = T + L->ld * (n + 1);
    double scale = S.nu / S.mu, zmax = 0.0;
    for (idx i = 0; i < n; i++) {
        int64_t b = L->basic[i];
        if (b >= n && b < 2 * n) {
            double cj = c ? c[b - n] : cs, v = cj * (beta[i] * scale);
            z[b - n] = v;
            bz[b - n] = 1;
            if ((v < 0 ? -v : v) > zmax) zmax = v < 0 ? -v : v;
        }
    }
    bound[2] = zmax;
    return 0;
}

/* Scratch of one problem of size n: T, the int64 bookkeeping, the Lemke buffers and the lazy
 * updates' etas (lcp/_lemke_run.h: sync_column; at most ECAP kept), in one
 * block: `stack` (of STACK_WORDS 8-byte words, 64-byte aligned) when it is large enough, else
 * malloc'd and aligned here. From n = 8 on, T's columns are padded to a multiple of 4
 * doubles (ld) and start 32-byte aligned, as do the pivot column `col` and V: the vectorized update then never
 * splits a load across cache lines, and its speed no longer depends on where malloc put the
 * block (a 25-40 % difference between processes at n >= 100 before). The numbers are the
 * same: every entry gets the same operations, only its address changes. */
typedef struct {
    Lemke L;
    double *T;
    int64_t *ints;
    int8_t *bz;
    void *heap;
} Work;

#define STACK_WORDS 4096 /* 32 kB: enough for n <= 32 */
#define ECAP 128         /* lazy updates kept at most (then every column is brought up to date) */
#define ALIGN_WORDS 8    /* 64 bytes */
#if defined(__GNUC__)
#define STACK_ALIGNED __attribute__((aligned(64))) /* of a stack block: uint64_t b[STACK_WORDS] */
#else
#define STACK_ALIGNED
#endif

static void work_free(Work *w) { free(w->heap); }

static size_t round_up(size_t words) { return (words + ALIGN_WORDS - 1) / ALIGN_WORDS * ALIGN_WORDS; }

static int work_init(Work *w, idx n, double tol, uint64_t *stack)
{
    Lemke *L = &w->L;
    const idx ld = n < 8 ? n : (n + 3) / 4 * 4; /* below 8: no padding (no gain) */
    /* T ld(n + 2), V n n, alpha/theta/col ld each and row n + 2, ints 6n + 3, rows 4n, the
     * lazy updates' etas ecap ld, their rows and multipliers ecap each, the versions n + 2 and
     * sync_avx2's scratch 3 ecap,
     * bz n bytes: all 8-byte words, each part starting on a 64-byte boundary */
    const idx ecap = n + 2 < ECAP ? n + 2 : ECAP;
    size_t nT = round_up((size_t)ld * (n + 2)), nV = round_up((size_t)n * n),
           nA = round_up(3 * (size_t)ld + n + 2), nI = round_up(6 * (size_t)n + 3),
           nR = round_up(4 * (size_t)n), nE = round_up((size_t)ecap * ld),
           nL = round_up(5 * (size_t)ecap + n + 2);
    size_t words = nT + nV + nA + nI + nR + nE + nL + ((size_t)n + 7) / 8;
    uint64_t *block = stack;
    w->heap = NULL;
    if (!stack || words > STACK_WORDS) {
        w->heap = malloc((words + ALIGN_WORDS) * 8);
        if (!w->heap) return -1;
        uintptr_t at = (uintptr_t)w->heap, mask = ALIGN_WORDS * 8 - 1;
        block = (uint64_t *)((at + mask) & ~mask);
    }
    w->T = (double *)block;
    L->V = w->T + nT;
    L->alpha = L->V + nV;
    w->ints = (int64_t *)(L->alpha + nA);
    L->rows = (idx *)(w->ints + nI);
    L->E = (double *)(L->rows + nR);
    L->emult = L->E + nE;
    L->er = (idx *)(L->emult + ecap);
    L->ver = L->er + ecap;
    L->cur = (double *)(L->ver + n + 2);
    L->rcs = L->cur + ecap;
    L->tr = (idx *)(L->rcs + ecap);
    w->bz = (int8_t *)(L->emult + nL);
    L->n = n;
    L->ld = ld;
    L->T = w->T;
    L->tol = tol;
    L->lazy = 1;
    L->ne = 0;
    L->ecap = ecap;
    L->basic = w->ints;
    L->nonbasic = w->ints + n;
    L->row_of = w->ints + 2 * n + 1;
    L->slot_of = w->ints + 4 * n + 2;
    L->cand = L->rows + n;
    L->wj = L->rows + 2 * n;
    L->pos = L->rows + 3 * n;
    L->theta = L->alpha + ld;
    L->col = L->alpha + 2 * ld;
    L->row = L->alpha + 3 * ld;
    /* the padding rows of T are never read; zero them anyway (no uninitialized memory) */
    for (idx c = 0; c < n + 2; c++)
        for (idx i = n; i < ld; i++) w->T[i + ld * c] = 0.0;
    return 0;
}

/* ------------------------------------------------------------------ solve and accept */
/* Above this bound on n max|M| (max|z| + 1) + max|q|, numpy's part of the check could overflow
 * (lcp/solvers/fast_lemke.py's _SAFE): the caller runs the general path. */
#define SAFE 1e300

/* After solve_problem's code 0: the basic z's into basis (sorted; returns their number) and,
 * when the numbers are safe, assess_one of z (zs: the solver's z, out: the answer, polished or
 * as given); res = (berr, ferr, refined). Returns the acceptance code: 0 done, 1 not handled
 * (the numpy code decides), -1 unsafe (nothing assessed); out = zs unless 0. */
static int accept_one(idx n, const double *M, const double *q, const double *zs,
                      const int8_t *bz, const double bound[3], int64_t *basis, idx *nb,
                      double *out, double res[3])
{
    idx m = 0;
    for (idx j = 0; j < n; j++)
        if (bz[j]) basis[m++] = j;
    *nb = m;
    res[0] = res[1] = res[2] = 0.0;
    int code = -1;
    if ((double)n * bound[0] * (bound[2] + 1.0) + bound[1] < SAFE)
        code = m <= MAX_M ? assess_one(n, M, q, zs, basis, m, bound[0], out, res) : 1;
    if (code) memcpy(out, zs, (size_t)n * sizeof(double));
    return code;
}

/* The work of solve_accept on C-contiguous data (M n x n, q, z: n doubles, basis: n int64),
 * without the GIL: the code of solve_problem (-1: out of memory), *acode that of accept_one
 * (1 when not solved); *mmax (unless NULL) = max|M| when the code is 0 (M then finite: the
 * solve refuses other data with NOT_FINITE), else -1. */
static int solve_and_accept(idx n, const double *M, const double *q, double tol,
                            long long max_iter, double *z, int64_t *basis, long long *pivots,
                            idx *nb, int *acode, double res[3], double *mmax)
{
    Work w;
    uint64_t stack[STACK_WORDS] STACK_ALIGNED;
    double bound[3] = {0.0, 0.0, 0.0};
    *pivots = 0;
    *nb = 0;
    *acode = 1;
    res[0] = res[1] = res[2] = 0.0;
    if (work_init(&w, n, tol, stack) < 0) return -1;
    double zbuf[64], *zs = n <= 64 ? zbuf : (double *)malloc((size_t)n * sizeof(double));
    if (!zs) {
        work_free(&w);
        return -1;
    }
    int code = solve_problem(&w.L, w.T, M, q, NULL, NULL, NULL, 1, max_iter, zs, w.bz, pivots,
                             bound);
    if (code == 0) *acode = accept_one(n, M, q, zs, w.bz, bound, basis, nb, z, res);
    if (mmax) *mmax = code == 0 ? bound[0] : -1.0;
    if (zs != zbuf) free(zs);
    work_free(&w);
    return code;
}

#endif /* RIGIDLCP_LEMKE_PROBLEM_H */
