/* The pivot loop of Lemke's method (lcp/lemke.py) in C: the ratio test with the lexicographic
 * tie-break and the rank-one update of the dictionary, exactly as `_Lemke.run` does them in
 * numpy (same rules, same order of floating-point operations up to BLAS's choice of fused
 * multiply-adds), so that both take the same pivots. Built by setuptools as an optional
 * extension (setup.py); lcp/_lemke_kernel.py falls back to the numpy loop when it is missing.
 *
 * Layout (docs/lemke.md, "The dictionary"): T is the n x (n + 2) dictionary, column-major, slots
 * 0..n hold the nonbasic columns and slot n + 1 holds beta. Variables: w_i = i, z_i = n + i,
 * z0 = 2n. basic[row] -> variable, nonbasic[slot] -> variable, row_of[var] -> row or -1,
 * slot_of[var] -> slot or -1 (int64 arrays, updated in place).
 *
 * run(T, basic, nonbasic, row_of, slot_of, tol, max_iter, trace) -> (code, pivots, s, entering)
 *   code 0: z0 left (a solution); 1: a basis repeated (numerical cycling); 2: max_iter pivots;
 *   3: secondary ray (slot s of the unblocked entering variable). trace: None or an int64
 *   buffer of length 2 k; the (row, slot) of the first k pivots are written there.
 *
 * Also, for lcp.solve's fast path (lcp/fast_lemke.py) and lcp.solve_many: solve_eq / solve_batch
 * run a whole LCP from the user's data -- the equilibration of lcp/scaling.py for a balanced M
 * (or with the factors of `ruiz` given), the dictionary, the pivots, z in the user's units --
 * and lcp_measure / lcp_measure_batch compute lcp/residual.py's acceptance measure after
 * numpy's M z, with numpy's roundings (the same numbers; see the comments there).
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

#include "acceptance/_accuracy_core.h" /* assess_one: the acceptance of solve_accept */

typedef struct {
    idx n;
    idx ld; /* column stride of T: n for a dictionary from Python; in the work array of
             * solve_eq / solve_batch n rounded up to a multiple of 4 from n = 16 on (columns
             * 32-byte aligned) */
    double *T;
    int64_t *basic, *nonbasic, *row_of, *slot_of;
    double tol;
    /* scratch */
    idx *rows, *cand, *wj, *pos;
    double *alpha, *theta, *row, *col, *V;
} Lemke;

/* ------------------------------------------------------------------ basis hash (Zobrist) */
typedef struct {
    int64_t *slot;
    size_t cap, count;
} HashSet;

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

static int hs_init(HashSet *h, size_t cap)
{
    h->cap = cap;
    h->count = 0;
    h->slot = (int64_t *)malloc(cap * sizeof(int64_t));
    if (!h->slot) return -1;
    memset(h->slot, 0xFF, cap * sizeof(int64_t)); /* -1: empty (keys are >= 0) */
    return 0;
}

/* 1 if key was present, 0 if inserted, -1 on allocation failure. */
static int hs_add(HashSet *h, int64_t key)
{
    if (2 * (h->count + 1) > h->cap) {
        HashSet g;
        if (hs_init(&g, 2 * h->cap) < 0) return -1;
        for (size_t i = 0; i < h->cap; i++)
            if (h->slot[i] >= 0) hs_add(&g, h->slot[i]);
        free(h->slot);
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

/* ------------------------------------------------------------------ the pivot */
static int64_t pivot(Lemke *L, idx r, idx s)
{
    const idx n = L->n, ld = L->ld, m = n + 2;
    double *T = L->T, *row = L->row, *col = L->col;
    double *Ts = T + ld * s;
    double p = Ts[r];
    memcpy(col, Ts, n * sizeof(double));
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

/* ------------------------------------------------------------------ the run */
static int run(Lemke *L, long long max_iter, int64_t *trace, idx trace_len,
               long long *out_pivots, idx *out_s, int64_t *out_entering)
{
    const idx n = L->n;
    const idx ld = L->ld;
    double *T = L->T, *beta = T + ld * (n + 1);
    const int64_t z0 = 2 * n;
    uint64_t seed = 0x5EEDULL, *keys = (uint64_t *)malloc((2 * n + 1) * sizeof(uint64_t));
    HashSet seen;
    if (!keys) return -1;
    size_t cap = 64; /* grows as needed: start small, a small problem takes few pivots */
    while (cap < 1024 && cap < (size_t)(8 * n)) cap *= 2;
    if (hs_init(&seen, cap) < 0) {
        free(keys);
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
        for (idx t = 0; t < m; t++) {
            double al = -a[L->rows[t]], b = beta[L->rows[t]];
            L->alpha[t] = al;
            L->theta[t] = (b > 0.0 ? b : 0.0) / al;
        }
        r = choose(L, L->rows, L->alpha, L->theta, m, amax);
    }
    free(keys);
    free(seen.slot);
    *out_pivots = pivots;
    *out_s = s;
    *out_entering = entering;
    return code;
}

/* ------------------------------------------------------------------ Python binding */
static int get_buffer(PyObject *obj, Py_buffer *view, const char *name, char kind, idx size,
                      int fortran)
{
    int flags = PyBUF_WRITABLE | PyBUF_FORMAT | (fortran ? PyBUF_F_CONTIGUOUS : PyBUF_C_CONTIGUOUS);
    if (PyObject_GetBuffer(obj, view, flags) < 0) return -1;
    const char *f = view->format ? view->format : "B";
    if (*f == '<' || *f == '=' || *f == '@') f++;
    int ok = view->itemsize == 8 &&
             (kind == 'd' ? (f[0] == 'd' && f[1] == 0)
                          : ((f[0] == 'l' || f[0] == 'q') && f[1] == 0));
    if (!ok || view->len / 8 != size) {
        PyErr_Format(PyExc_ValueError, "%s: expected %zd %s values", name, size,
                     kind == 'd' ? "float64" : "int64");
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

static PyObject *py_run(PyObject *self, PyObject *args)
{
    PyObject *oT, *ob, *onb, *orow, *oslot, *otrace;
    double tol;
    long long max_iter;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOdLO", &oT, &ob, &onb, &orow, &oslot, &tol, &max_iter,
                          &otrace))
        return NULL;
    Py_buffer vb, vnb, vrow, vslot, vT, vtr;
    idx n = PyObject_Length(ob);
    if (n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "basic: empty");
        return NULL;
    }
    if (get_buffer(ob, &vb, "basic", 'q', n, 0) < 0) return NULL;
    if (get_buffer(onb, &vnb, "nonbasic", 'q', n + 1, 0) < 0) goto fail1;
    if (get_buffer(orow, &vrow, "row_of", 'q', 2 * n + 1, 0) < 0) goto fail2;
    if (get_buffer(oslot, &vslot, "slot_of", 'q', 2 * n + 1, 0) < 0) goto fail3;
    if (get_buffer(oT, &vT, "T", 'd', n * (n + 2), 1) < 0) goto fail4;
    idx trace_len = 0;
    int have_trace = otrace != Py_None;
    if (have_trace) {
        if (PyObject_GetBuffer(otrace, &vtr, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS) < 0) goto fail5;
        trace_len = vtr.len / 16;
    }
    Lemke L;
    L.n = n;
    L.ld = n;
    L.T = (double *)vT.buf;
    L.basic = (int64_t *)vb.buf;
    L.nonbasic = (int64_t *)vnb.buf;
    L.row_of = (int64_t *)vrow.buf;
    L.slot_of = (int64_t *)vslot.buf;
    L.tol = tol;
    L.rows = (idx *)malloc(4 * n * sizeof(idx));
    L.alpha = (double *)malloc((4 * n + 2) * sizeof(double));
    L.V = (double *)malloc((size_t)n * n * sizeof(double));
    long long pivots = 0;
    idx s = 0;
    int64_t entering = -1;
    int code = -1;
    if (L.rows && L.alpha && L.V) {
        L.cand = L.rows + n;
        L.wj = L.rows + 2 * n;
        L.pos = L.rows + 3 * n;
        L.theta = L.alpha + n;
        L.col = L.alpha + 2 * n;
        L.row = L.alpha + 3 * n;
        Py_BEGIN_ALLOW_THREADS
        code = run(&L, max_iter, have_trace ? (int64_t *)vtr.buf : NULL, trace_len, &pivots,
                   &s, &entering);
        Py_END_ALLOW_THREADS
    }
    free(L.rows);
    free(L.alpha);
    free(L.V);
    if (have_trace) PyBuffer_Release(&vtr);
    PyBuffer_Release(&vT);
    PyBuffer_Release(&vslot);
    PyBuffer_Release(&vrow);
    PyBuffer_Release(&vnb);
    PyBuffer_Release(&vb);
    if (code < 0) return PyErr_NoMemory();
    return Py_BuildValue("iLnL", code, pivots, s, (long long)entering);
fail5:
    PyBuffer_Release(&vT);
fail4:
    PyBuffer_Release(&vslot);
fail3:
    PyBuffer_Release(&vrow);
fail2:
    PyBuffer_Release(&vnb);
fail1:
    PyBuffer_Release(&vb);
    return NULL;
}

static void fill(idx n, double *T, const double *M, const double *q, const double *d,
                 double *out_mu, double *out_nu, double *out_delta)
{
    double mu = 0.0, nu = 0.0, delta = -1.0 / 0.0;
    for (idx k = 0; k < n * n; k++) {
        double a = M[k] < 0 ? -M[k] : M[k];
        if (a > mu) mu = a;
    }
    if (mu == 0.0) mu = 1.0;
    for (idx i = 0; i < n; i++) {
        double a = q[i] < 0 ? -q[i] : q[i];
        if (a > nu) nu = a;
        if (d[i] > delta) delta = d[i];
    }
    for (idx i = 0; i < n; i++)
        for (idx j = 0; j < n; j++) T[i + n * j] = M[i * n + j] / mu;
    for (idx i = 0; i < n; i++) {
        T[i + n * n] = d[i] / delta;
        T[i + n * (n + 1)] = q[i] / nu;
    }
    *out_mu = mu;
    *out_nu = nu;
    *out_delta = delta;
}

/* setup(T, M, q, d) -> (mu, nu, delta): T[:, :n] = M / mu, T[:, n] = d / delta,
 * T[:, n + 1] = q / nu with mu = max|M| (1 if M = 0), nu = max|q|, delta = max d; as numpy's
 * true divisions in `_Lemke.__init__`. M is read C-contiguous, T written column-major. */
static PyObject *py_setup(PyObject *self, PyObject *args)
{
    PyObject *oT, *oM, *oq, *od;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOO", &oT, &oM, &oq, &od)) return NULL;
    Py_buffer vq, vd, vM, vT;
    idx n = PyObject_Length(oq);
    if (n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "q: empty");
        return NULL;
    }
    if (get_buffer(oq, &vq, "q", 'd', n, 0) < 0) return NULL;
    if (get_buffer(od, &vd, "d", 'd', n, 0) < 0) goto f1;
    if (get_buffer(oM, &vM, "M", 'd', n * n, 0) < 0) goto f2;
    if (get_buffer(oT, &vT, "T", 'd', n * (n + 2), 1) < 0) goto f3;
    double mu, nu, delta;
    fill(n, (double *)vT.buf, (const double *)vM.buf, (const double *)vq.buf,
         (const double *)vd.buf, &mu, &nu, &delta);
    PyBuffer_Release(&vT);
    PyBuffer_Release(&vM);
    PyBuffer_Release(&vd);
    PyBuffer_Release(&vq);
    return Py_BuildValue("ddd", mu, nu, delta);
f3:
    PyBuffer_Release(&vM);
f2:
    PyBuffer_Release(&vd);
f1:
    PyBuffer_Release(&vq);
    return NULL;
}

/* check(M, q) -> (finite, qmin): are all entries of M and q finite, and min q. */
static PyObject *py_check(PyObject *self, PyObject *args)
{
    PyObject *oM, *oq;
    (void)self;
    if (!PyArg_ParseTuple(args, "OO", &oM, &oq)) return NULL;
    Py_buffer vq, vM;
    idx n = PyObject_Length(oq);
    if (n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "q: empty");
        return NULL;
    }
    if (get_buffer(oq, &vq, "q", 'd', n, 0) < 0) return NULL;
    if (get_buffer(oM, &vM, "M", 'd', n * n, 0) < 0) {
        PyBuffer_Release(&vq);
        return NULL;
    }
    const double *M = (const double *)vM.buf, *q = (const double *)vq.buf;
    double qmin = q[0];
    int finite = 1; /* branch-free and independent per entry (vectorized): |x| <= DBL_MAX is
                     * false for inf and NaN (a sum of x - x was one serial chain of adds) */
    for (idx k = 0; k < n * n; k++) finite &= fabs(M[k]) <= DBL_MAX;
    for (idx i = 0; i < n; i++) {
        finite &= fabs(q[i]) <= DBL_MAX;
        qmin = q[i] < qmin ? q[i] : qmin;
    }
    PyBuffer_Release(&vM);
    PyBuffer_Release(&vq);
    return Py_BuildValue("Od", finite ? Py_True : Py_False, qmin);
}

/* The format of a buffer of native float64 values ("d", with the native byte order mark or
 * none)? */
static int native_double(const Py_buffer *v)
{
    const char *f = v->format ? v->format : "B";
#if PY_BIG_ENDIAN
    if (*f == '>' || *f == '!' || *f == '=' || *f == '@') f++;
#else
    if (*f == '<' || *f == '=' || *f == '@') f++;
#endif
    return v->itemsize == 8 && f[0] == 'd' && f[1] == 0;
}

/* plain(M, q) -> bool: lcp.LCP's quick route -- is q a C-contiguous native float64 vector of
 * n >= 1 entries and M a C-contiguous native float64 n x n matrix, all entries finite? (Then
 * M and q need no conversion, only the copies.) False for anything else, never an error: the
 * general validation runs and names the problem. One call for the dtype, shape, order and
 * finiteness tests. */
static PyObject *py_plain(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "plain(M, q): two arguments");
        return NULL;
    }
    Py_buffer vq, vM;
    const int flags = PyBUF_FORMAT | PyBUF_C_CONTIGUOUS;
    if (PyObject_GetBuffer(args[1], &vq, flags) < 0) {
        PyErr_Clear();
        Py_RETURN_FALSE;
    }
    if (PyObject_GetBuffer(args[0], &vM, flags) < 0) {
        PyErr_Clear();
        PyBuffer_Release(&vq);
        Py_RETURN_FALSE;
    }
    idx n = vq.ndim == 1 ? vq.shape[0] : 0;
    int ok = n >= 1 && native_double(&vq) && native_double(&vM) && vM.ndim == 2 &&
             vM.shape[0] == n && vM.shape[1] == n;
    if (ok) {
        const double *M = (const double *)vM.buf, *q = (const double *)vq.buf;
        double top = 0.0; /* as `check`: |x| <= DBL_MAX false for inf and NaN; 4 lanes wide */
        int finite = abs_max_finite(M, n * n, &top);
        for (idx i = 0; i < n; i++) finite &= fabs(q[i]) <= DBL_MAX;
        ok = finite;
    }
    PyBuffer_Release(&vM);
    PyBuffer_Release(&vq);
    if (ok) Py_RETURN_TRUE;
    Py_RETURN_FALSE;
}

/* ------------------------------------------------------------------ one whole problem */
#include "_balanced.h" /* balanced_units, pow2_near: shared with solvers/_pivot_c.c */

/* T = [M~ / mu, d / delta, q~ / nu] (as `fill`) for the equilibrated data M~ = (M r) c and
 * q~ = q r, rounded as numpy rounds scaling.py's M * r[:, None] * c[None, :] and q * r; r and c
 * are the arrays r, c or, when NULL, the numbers rs, cs; d NULL means ones. Also max|M| and
 * max|q| of the data given. Returns NOT_FINITE when M~ or q~ is not finite, else 0. */
typedef struct {
    double mu, nu, delta, qmin, mmax, qmax;
} Scales;

static int fill_scaled(idx n, idx ld, double *T, const double *M, const double *q,
                       const double *d, const double *r, const double *c, double rs, double cs,
                       Scales *S)
{
    double mu = 0.0, nu = 0.0, mmax = 0.0, qmax = 0.0, qmin = DBL_MAX;
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
    for (idx i = 0; i < n; i++) {
        double v = q[i] * (r ? r[i] : rs), a = fabs(v), aq = fabs(q[i]);
        finite &= a <= DBL_MAX;
        nu = a > nu ? a : nu;
        qmin = v < qmin ? v : qmin;
        qmax = aq > qmax ? aq : qmax;
        T[i + ld * (n + 1)] = v;
    }
    if (!finite) return NOT_FINITE;
    if (mu == 0.0) mu = 1.0;
    double delta = -1.0 / 0.0;
    for (idx i = 0; i < n; i++) {
        double di = d ? d[i] : 1.0;
        if (di > delta) delta = di;
    }
    for (idx j = 0; j < n; j++)
        for (idx i = 0; i < n; i++) T[i + ld * j] = T[i + ld * j] / mu;
    for (idx i = 0; i < n; i++) {
        T[i + ld * n] = (d ? d[i] : 1.0) / delta;
        T[i + ld * (n + 1)] = T[i + ld * (n + 1)] / nu;
    }
    S->mu = mu;
    S->nu = nu;
    S->delta = delta;
    S->qmin = qmin;
    S->mmax = mmax;
    S->qmax = qmax;
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
    double nu = 0.0, qmax = 0.0, qmin = DBL_MAX;
    int finite = 1;
    for (idx i = 0; i < n; i++) {
        double v = q[i] * rs, a = fabs(v), aq = fabs(q[i]);
        finite &= a <= DBL_MAX;
        nu = a > nu ? a : nu;
        qmin = v < qmin ? v : qmin;
        qmax = aq > qmax ? aq : qmax;
        T[i + ld * (n + 1)] = v;
    }
    if (!finite) return NOT_FINITE;
    double delta = -1.0 / 0.0;
    for (idx i = 0; i < n; i++) {
        double di = d ? d[i] : 1.0;
        if (di > delta) delta = di;
    }
    for (idx i = 0; i < n; i++) {
        T[i + ld * n] = (d ? d[i] : 1.0) / delta;
        T[i + ld * (n + 1)] = T[i + ld * (n + 1)] / nu;
    }
    S->mu = mu;
    S->nu = nu;
    S->delta = delta;
    S->qmin = qmin;
    S->mmax = top;
    S->qmax = qmax;
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

/* Scratch of one problem of size n: T, the int64 bookkeeping and the Lemke buffers, in one
 * block: `stack` (of STACK_WORDS 8-byte words, 64-byte aligned) when it is large enough, else
 * malloc'd and aligned here. From n = 16 on, T's columns are padded to a multiple of 4
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

#define STACK_WORDS 2048 /* 16 kB: enough for n <= 28 */
#define ALIGN_WORDS 8    /* 64 bytes */

static void work_free(Work *w) { free(w->heap); }

static size_t round_up(size_t words) { return (words + ALIGN_WORDS - 1) / ALIGN_WORDS * ALIGN_WORDS; }

static int work_init(Work *w, idx n, double tol, uint64_t *stack)
{
    Lemke *L = &w->L;
    const idx ld = n < 16 ? n : (n + 3) / 4 * 4; /* short columns: no padding (no gain) */
    /* T ld(n + 2), V n n, alpha/theta/col ld each and row n + 2, ints 6n + 3, rows 4n, bz n
     * bytes: all 8-byte words, each part starting on a 64-byte boundary */
    size_t nT = round_up((size_t)ld * (n + 2)), nV = round_up((size_t)n * n),
           nA = round_up(3 * (size_t)ld + n + 2), nI = round_up(6 * (size_t)n + 3),
           nR = round_up(4 * (size_t)n);
    size_t words = nT + nV + nA + nI + nR + ((size_t)n + 7) / 8;
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
    w->bz = (int8_t *)(L->rows + nR);
    L->n = n;
    L->ld = ld;
    L->T = w->T;
    L->tol = tol;
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

/* An optional float64 vector of length n (None: NULL). */
static int opt_vector(PyObject *obj, Py_buffer *view, const char *name, idx n, const double **out)
{
    *out = NULL;
    view->obj = NULL;
    if (obj == Py_None) return 0;
    if (get_buffer(obj, view, name, 'd', n, 0) < 0) return -1;
    *out = (const double *)view->buf;
    return 0;
}

static void release(Py_buffer *v)
{
    if (v->obj) PyBuffer_Release(v);
}

/* solve_eq(M, q, r, c, d, tol, max_iter, z, basis) -> (code, pivots, nbasis, bounds): one LCP
 * as lcp.solve gives it to lemke() by default, on its equilibrated data: r = c = None for the
 * balanced case done here (code NEEDS_RUIZ when M is not balanced), or the factors of `ruiz`;
 * d None for ones. M n x n C-contiguous, q, r, c, d, z float64 of length n; basis int64 of
 * length n receives the sorted indices of the basic z's (the first nbasis entries). bounds =
 * (max|M|, max|q|, max|z|) of the data given and the answer (when code 0). */
static PyObject *py_solve_eq(PyObject *self, PyObject *args)
{
    PyObject *oM, *oq, *or_, *oc, *od, *oz, *ob;
    double tol;
    long long max_iter;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOdLOO", &oM, &oq, &or_, &oc, &od, &tol, &max_iter, &oz,
                          &ob))
        return NULL;
    idx n = PyObject_Length(oq);
    if (n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "q: empty");
        return NULL;
    }
    if ((or_ == Py_None) != (oc == Py_None)) {
        PyErr_SetString(PyExc_ValueError, "r and c: both None or both given");
        return NULL;
    }
    Py_buffer vM = {0}, vq = {0}, vr = {0}, vc = {0}, vd = {0}, vz = {0}, vb = {0};
    const double *r, *c, *d;
    PyObject *result = NULL;
    if (get_buffer(oq, &vq, "q", 'd', n, 0) < 0) return NULL;
    if (get_buffer(oM, &vM, "M", 'd', n * n, 0) < 0) goto done;
    if (opt_vector(or_, &vr, "r", n, &r) < 0 || opt_vector(oc, &vc, "c", n, &c) < 0 ||
        opt_vector(od, &vd, "d", n, &d) < 0)
        goto done;
    if (get_buffer(oz, &vz, "z", 'd', n, 0) < 0) goto done;
    if (get_buffer(ob, &vb, "basis", 'q', n, 0) < 0) goto done;
    Work w;
#if defined(__GNUC__)
    uint64_t stack[STACK_WORDS] __attribute__((aligned(64)));
#else
    uint64_t stack[STACK_WORDS];
#endif
    if (work_init(&w, n, tol, stack) < 0) {
        PyErr_NoMemory();
        goto done;
    }
    long long pivots = 0;
    double bound[3] = {0.0, 0.0, 0.0};
    int code;
    Py_BEGIN_ALLOW_THREADS
    code = solve_problem(&w.L, w.T, (const double *)vM.buf, (const double *)vq.buf, d, r, c,
                         r ? 2 : 1, max_iter, (double *)vz.buf, w.bz, &pivots, bound);
    Py_END_ALLOW_THREADS
    idx nb = 0;
    int64_t *basis = (int64_t *)vb.buf;
    for (idx j = 0; j < n; j++)
        if (w.bz[j]) basis[nb++] = j;
    work_free(&w);
    if (code < 0)
        PyErr_NoMemory();
    else
        result = Py_BuildValue("iLn(ddd)", code, pivots, nb, bound[0], bound[1], bound[2]);
done:
    release(&vb);
    release(&vz);
    release(&vd);
    release(&vc);
    release(&vr);
    release(&vM);
    release(&vq);
    return result;
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
        code = m <= MAX_M ? assess_one(n, M, q, zs, basis, m, out, res) : 1;
    if (code) memcpy(out, zs, (size_t)n * sizeof(double));
    return code;
}

/* The work of solve_accept on C-contiguous data (M n x n, q, z: n doubles, basis: n int64),
 * without the GIL: the code of solve_problem (-1: out of memory), *acode that of accept_one
 * (1 when not solved). */
static int solve_and_accept(idx n, const double *M, const double *q, double tol,
                            long long max_iter, double *z, int64_t *basis, long long *pivots,
                            idx *nb, int *acode, double res[3])
{
    Work w;
#if defined(__GNUC__)
    uint64_t stack[STACK_WORDS] __attribute__((aligned(64)));
#else
    uint64_t stack[STACK_WORDS];
#endif
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
    if (zs != zbuf) free(zs);
    work_free(&w);
    return code;
}

/* solve_accept(M, q, tol, max_iter, z, basis) -> (code, pivots, nbasis, acode, berr, ferr,
 * refined): `solve_eq` with r = c = d = None (lcp.solve's default Lemke) and, on code 0, the
 * acceptance steps of lcp/acceptance/accuracy.py's `assess_lcp` on the answer and its basis
 * (`accept_one`: acode 0 = assessed, z the answer, polished when refined; 1 = not handled
 * here, z the solver's; -1 = numbers too large for the fast check). One crossing from Python
 * for the solve and its acceptance (lcp/solvers/fast_lemke.py); the same numbers as the two
 * calls. */
static PyObject *py_solve_accept(PyObject *self, PyObject *args)
{
    PyObject *oM, *oq, *oz, *ob;
    double tol;
    long long max_iter;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOdLOO", &oM, &oq, &tol, &max_iter, &oz, &ob)) return NULL;
    idx n = PyObject_Length(oq);
    if (n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "q: empty");
        return NULL;
    }
    Py_buffer vM = {0}, vq = {0}, vz = {0}, vb = {0};
    PyObject *result = NULL;
    if (get_buffer(oq, &vq, "q", 'd', n, 0) < 0) return NULL;
    if (get_buffer(oM, &vM, "M", 'd', n * n, 0) < 0) goto done;
    if (get_buffer(oz, &vz, "z", 'd', n, 0) < 0) goto done;
    if (get_buffer(ob, &vb, "basis", 'q', n, 0) < 0) goto done;
    long long pivots = 0;
    double res[3];
    idx nb = 0;
    int code, acode = 1;
    Py_BEGIN_ALLOW_THREADS
    code = solve_and_accept(n, (const double *)vM.buf, (const double *)vq.buf, tol, max_iter,
                            (double *)vz.buf, (int64_t *)vb.buf, &pivots, &nb, &acode, res);
    Py_END_ALLOW_THREADS
    if (code < 0)
        PyErr_NoMemory();
    else
        result = Py_BuildValue("iLniddi", code, pivots, nb, acode, res[0], res[1], (int)res[2]);
done:
    release(&vb);
    release(&vz);
    release(&vM);
    release(&vq);
    return result;
}

/* solve_batch(Ms, qs, d, tol, max_iter, Z, basic_z, codes, pivots, mode): k problems of size n
 * (Ms: k n n C-contiguous, qs: k n; finite) by the steps of lemke() (q >= 0: z = 0 and no
 * pivot; else setup + run), on the data as given (mode 0) or equilibrated here when balanced
 * (mode 1, as `solve_eq` with r = c = None: code NEEDS_RUIZ for the others). Writes z (k n,
 * the original units), basic_z (k n int8: z_j basic), codes and pivots (int64, k). Only code 0
 * (solved) leaves a usable z: the caller solves the others again one by one. acc (optional,
 * k x 4 float64): each solved answer is also assessed as `solve_accept` does (`accept_one`),
 * acc[p] = (acode, berr, ferr, refined) and Z[p] the answer (polished when refined). */
static PyObject *py_solve_batch(PyObject *self, PyObject *args)
{
    PyObject *oM, *oq, *od, *oZ, *oB, *oc, *op, *oacc = Py_None;
    double tol;
    long long max_iter;
    int mode = 0;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOdLOOOO|iO", &oM, &oq, &od, &tol, &max_iter, &oZ, &oB, &oc,
                          &op, &mode, &oacc))
        return NULL;
    if (mode != 0 && mode != 1) {
        PyErr_SetString(PyExc_ValueError, "mode: 0 or 1");
        return NULL;
    }
    Py_buffer vd, vc, vp, vM, vq, vZ, vB, va = {0};
    idx n = PyObject_Length(od), k = PyObject_Length(oc);
    if (n < 1 || k < 0) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "d: empty");
        return NULL;
    }
    if (get_buffer(od, &vd, "d", 'd', n, 0) < 0) return NULL;
    if (get_buffer(oc, &vc, "codes", 'q', k, 0) < 0) goto b1;
    if (get_buffer(op, &vp, "pivots", 'q', k, 0) < 0) goto b2;
    if (get_buffer(oM, &vM, "Ms", 'd', k * n * n, 0) < 0) goto b3;
    if (get_buffer(oq, &vq, "qs", 'd', k * n, 0) < 0) goto b4;
    if (get_buffer(oZ, &vZ, "Z", 'd', k * n, 0) < 0) goto b5;
    if (PyObject_GetBuffer(oB, &vB, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS) < 0) goto b6;
    if (vB.len != k * n || vB.itemsize != 1) {
        PyErr_SetString(PyExc_ValueError, "basic_z: expected k n int8 values");
        goto b7;
    }
    if (oacc != Py_None && get_buffer(oacc, &va, "acc", 'd', 4 * k, 0) < 0) goto b7;
    double *acc = (double *)va.buf, *zs = NULL;
    int64_t *ab = NULL;
    Work w;
    int failed = work_init(&w, n, tol, NULL) < 0;
    if (!failed && acc) {
        zs = (double *)malloc((size_t)n * (sizeof(double) + sizeof(int64_t)));
        ab = (int64_t *)(zs + n);
        if (!zs) {
            work_free(&w);
            failed = 1;
        }
    }
    if (!failed) {
        const double *Ms = (const double *)vM.buf, *qs = (const double *)vq.buf,
                     *d = (const double *)vd.buf;
        double *Z = (double *)vZ.buf;
        int8_t *B = (int8_t *)vB.buf;
        int64_t *codes = (int64_t *)vc.buf, *piv = (int64_t *)vp.buf;
        Py_BEGIN_ALLOW_THREADS
        for (idx p = 0; p < k; p++) {
            long long pivots = 0;
            double bound[3];
            const double *Mp = Ms + p * n * n, *qp = qs + p * n;
            int code = solve_problem(&w.L, w.T, Mp, qp, d, NULL, NULL, mode, max_iter,
                                     acc ? zs : Z + p * n, B + p * n, &pivots, bound);
            if (code < 0) {
                failed = 1;
                break;
            }
            if (acc) {
                double res[3] = {0.0, 0.0, 0.0};
                idx nb;
                acc[4 * p] = code ? 1.0 : (double)accept_one(n, Mp, qp, zs, B + p * n, bound,
                                                               ab, &nb, Z + p * n, res);
                if (code) memcpy(Z + p * n, zs, (size_t)n * sizeof(double));
                acc[4 * p + 1] = res[0], acc[4 * p + 2] = res[1], acc[4 * p + 3] = res[2];
            }
            codes[p] = code;
            piv[p] = pivots;
        }
        Py_END_ALLOW_THREADS
        free(zs);
        work_free(&w);
    }
    release(&va);
    PyBuffer_Release(&vB);
    PyBuffer_Release(&vZ);
    PyBuffer_Release(&vq);
    PyBuffer_Release(&vM);
    PyBuffer_Release(&vp);
    PyBuffer_Release(&vc);
    PyBuffer_Release(&vd);
    if (failed) return PyErr_NoMemory();
    Py_RETURN_NONE;
b7:
    PyBuffer_Release(&vB);
b6:
    PyBuffer_Release(&vZ);
b5:
    PyBuffer_Release(&vq);
b4:
    PyBuffer_Release(&vM);
b3:
    PyBuffer_Release(&vp);
b2:
    PyBuffer_Release(&vc);
b1:
    PyBuffer_Release(&vd);
    return NULL;
}

/* ------------------------------------------------------------------ the acceptance measure */
/* sum_j |a_j| in numpy's order: its pairwise summation (numpy's `pairwise_sum`, used by
 * np.add.reduce over a contiguous axis, started from the identity 0): a plain loop below 8
 * terms, eight interleaved partial sums up to 128, halves (at a multiple of 8) above. The
 * Python side checks once, on a probe, that numpy sums so (lcp/_lemke_kernel.py). */
static double pairwise_abs(const double *a, idx n)
{
#define ABS(x) fabs(x)
    if (n < 8) {
        double res = 0.0;
        for (idx i = 0; i < n; i++) res += ABS(a[i]);
        return res;
    }
    if (n <= 128) {
        double r[8];
        for (int j = 0; j < 8; j++) r[j] = ABS(a[j]);
        idx i;
        for (i = 8; i < n - (n % 8); i += 8)
            for (int j = 0; j < 8; j++) r[j] += ABS(a[i + j]);
        double res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        for (; i < n; i++) res += ABS(a[i]);
        return res;
    }
    idx n2 = n / 2;
    n2 -= n2 % 8;
    return pairwise_abs(a, n2) + pairwise_abs(a + n2, n - n2);
#undef ABS
}

#if HAVE_AVX2_CLONE
/* pairwise_abs four lanes wide: the eight partial sums in two registers, each lane adding the
 * same terms in the same order as the scalar r[j] (|x| by clearing the sign bit, as fabs), so
 * the sum is the same number. */
__attribute__((target("avx2"))) static double pairwise_abs_avx2(const double *a, idx n)
{
    if (n < 8) {
        double res = 0.0;
        for (idx i = 0; i < n; i++) res += fabs(a[i]);
        return res;
    }
    if (n <= 128) {
        const __m256d sign = _mm256_set1_pd(-0.0);
        __m256d r0 = _mm256_andnot_pd(sign, _mm256_loadu_pd(a));
        __m256d r1 = _mm256_andnot_pd(sign, _mm256_loadu_pd(a + 4));
        idx i;
        for (i = 8; i < n - (n % 8); i += 8) {
            r0 = _mm256_add_pd(r0, _mm256_andnot_pd(sign, _mm256_loadu_pd(a + i)));
            r1 = _mm256_add_pd(r1, _mm256_andnot_pd(sign, _mm256_loadu_pd(a + i + 4)));
        }
        double r[8];
        _mm256_storeu_pd(r, r0);
        _mm256_storeu_pd(r + 4, r1);
        double res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        for (; i < n; i++) res += fabs(a[i]);
        return res;
    }
    idx n2 = n / 2;
    n2 -= n2 % 8;
    return pairwise_abs_avx2(a, n2) + pairwise_abs_avx2(a + n2, n - n2);
}

/* measure_one's pass over M (finiteness, max|M|, the row sums of |M| in numpy's order), with
 * pairwise_abs_avx2 and _accuracy_core.h's abs_max_finite_avx2. */
__attribute__((target("avx2"))) static int m_pass_avx2(idx n, const double *M, double *mmax,
                                                       double *norm)
{
    int finite = 1;
    for (idx i = 0; i < n; i++) {
        const double *Mi = M + i * n;
        finite &= abs_max_finite_avx2(Mi, n, mmax);
        double row = 0.0 + pairwise_abs_avx2(Mi, n);
        finite &= row <= DBL_MAX;
        *norm = row > *norm ? row : *norm;
    }
    return finite;
}

#endif

/* abs_row_sums(M, out): out[i] = 0 + sum_j |M_ij| summed as numpy's np.add.reduce(np.abs(M),
 * axis=1) (M m x n C-contiguous float64, out m float64): the probe of lcp/_lemke_kernel.py. */
static PyObject *py_abs_row_sums(PyObject *self, PyObject *args)
{
    PyObject *oM, *oout;
    idx n;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOn", &oM, &oout, &n)) return NULL;
    idx m = PyObject_Length(oout);
    if (m < 1 || n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "empty");
        return NULL;
    }
    Py_buffer vM, vo;
    if (get_buffer(oout, &vo, "out", 'd', m, 0) < 0) return NULL;
    if (get_buffer(oM, &vM, "M", 'd', m * n, 0) < 0) {
        PyBuffer_Release(&vo);
        return NULL;
    }
    for (idx i = 0; i < m; i++)
        ((double *)vo.buf)[i] = 0.0 + pairwise_abs((const double *)vM.buf + i * n, n);
    PyBuffer_Release(&vM);
    PyBuffer_Release(&vo);
    Py_RETURN_NONE;
}

/* lcp_measure(M, q, z, Mz) -> (residual, scaled residual, z_s, w_s), or None: lcp/residual.py's
 * `lcp_measure` after numpy's M.dot(z): w = Mz + q (written into Mz), the row sums of |M| in
 * numpy's order, and the rest -- maxima, the scales, the minima -- by the operations the numpy
 * code does, on finite numbers (the same roundings; no fused multiply-add: setup.py builds with
 * -ffp-contract=off). None, with Mz untouched, when an input is not a float64 C-contiguous
 * array of the right length or a number is not finite: the numpy code measures then. */
/* One LCP's measure (see lcp_measure below): 0 and w = Mz + q written, or -1 (nothing written)
 * when a number is not finite. */
static int measure_one(idx n, const double *M, const double *q, const double *z, double *w,
                       double out[4])
{
    double mmax = 0.0, qmax = 0.0, zmax = 0.0, norm = 0.0;
    int finite = 1; /* branch-free maxima and finiteness test, as in balanced_units */
#if HAVE_AVX2_CLONE
    int wide = cpu_avx2(); /* M's pass four lanes wide: the same numbers (see m_pass_avx2) */
    if (wide) finite = m_pass_avx2(n, M, &mmax, &norm);
#else
    const int wide = 0;
#endif
    for (idx i = 0; i < n; i++) {
        if (!wide) {
            const double *Mi = M + i * n;
            for (idx j = 0; j < n; j++) {
                double a = fabs(Mi[j]);
                finite &= a <= DBL_MAX;
                mmax = a > mmax ? a : mmax;
            }
            double row = 0.0 + pairwise_abs(Mi, n);
            norm = row > norm ? row : norm;
            finite &= row <= DBL_MAX;
        }
        double aq = fabs(q[i]), az = fabs(z[i]), wi = fabs(w[i] + q[i]);
        finite &= (aq <= DBL_MAX) & (az <= DBL_MAX) & (wi <= DBL_MAX);
        qmax = aq > qmax ? aq : qmax;
        zmax = az > zmax ? az : zmax;
    }
    /* residual.py: zs = max(zmax, qmax / mmax if mmax > 0 else 0.0), 1 if 0;
     * ws = qmax + norm_inf(M) * zs, 1 if not > 0 */
    double ratio = mmax > 0 ? qmax / mmax : 0.0;
    double zs = ratio > zmax ? ratio : zmax;
    if (zs == 0.0) zs = 1.0;
    double prod = norm * zs;
    double ws = qmax + prod;
    if (!(ws > 0)) ws = 1.0;
    if (!(finite && zs <= DBL_MAX && ws <= DBL_MAX)) return -1;
    double scaled = 0.0, raw = 0.0;
    for (idx i = 0; i < n; i++) {
        double wi = w[i] + q[i];
        w[i] = wi;
        double a = z[i] / zs, b = wi / ws, m = fabs(a < b ? a : b);
        scaled = m > scaled ? m : scaled;
        double m2 = fabs(z[i] < wi ? z[i] : wi);
        raw = m2 > raw ? m2 : raw;
    }
    out[0] = raw;
    out[1] = scaled;
    out[2] = zs;
    out[3] = ws;
    return 0;
}

/* float64 C-contiguous buffers of the given sizes (objs[i], writable where asked), all or none:
 * the number acquired (< count: some failed, those released, no error set). */
static int get_doubles(PyObject **objs, Py_buffer *v, const idx *sizes, const int *writable,
                       int count)
{
    for (int i = 0; i < count; i++) {
        int flags = PyBUF_FORMAT | PyBUF_C_CONTIGUOUS | (writable[i] ? PyBUF_WRITABLE : 0);
        int ok = PyObject_GetBuffer(objs[i], &v[i], flags) == 0;
        if (ok) {
            const char *f = v[i].format ? v[i].format : "B";
            if (*f == '<' || *f == '=' || *f == '@') f++;
            ok = v[i].itemsize == 8 && f[0] == 'd' && f[1] == 0 && v[i].len / 8 == sizes[i];
            if (!ok) PyBuffer_Release(&v[i]);
        }
        if (!ok) {
            for (int j = 0; j < i; j++) PyBuffer_Release(&v[j]);
            PyErr_Clear();
            return i;
        }
    }
    return count;
}

/* lcp_measure(M, q, z, Mz) -> (residual, scaled residual, z_s, w_s), or None: lcp/residual.py's
 * `lcp_measure` after numpy's M.dot(z): w = Mz + q (written into Mz), the row sums of |M| in
 * numpy's order, and the rest -- maxima, the scales, the minima -- by the operations the numpy
 * code does, on finite numbers (the same roundings; no fused multiply-add: setup.py builds with
 * -ffp-contract=off). None, with Mz untouched, when an input is not a float64 C-contiguous
 * array of the right length or a number is not finite: the numpy code measures then. */
static PyObject *py_lcp_measure(PyObject *self, PyObject *args)
{
    PyObject *objs[4];
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOO", &objs[0], &objs[1], &objs[2], &objs[3])) return NULL;
    idx n = PyObject_Length(objs[1]);
    if (n < 1) {
        PyErr_Clear();
        Py_RETURN_NONE;
    }
    Py_buffer v[4];
    idx sizes[4] = {n * n, n, n, n};
    int writable[4] = {0, 0, 0, 1};
    if (get_doubles(objs, v, sizes, writable, 4) < 4) Py_RETURN_NONE;
    double out[4];
    int ok = measure_one(n, (const double *)v[0].buf, (const double *)v[1].buf,
                         (const double *)v[2].buf, (double *)v[3].buf, out) == 0;
    for (int i = 0; i < 4; i++) PyBuffer_Release(&v[i]);
    if (!ok) Py_RETURN_NONE;
    return Py_BuildValue("dddd", out[0], out[1], out[2], out[3]);
}

/* lcp_measure_batch(Ms, qs, Z, MZ, out) -> bool: `lcp_measure` of k problems (Ms k n n, qs, Z,
 * MZ k n, out k 4 float64, C-contiguous): row p of out receives (residual, scaled, z_s, w_s)
 * and MZ[p] becomes w = M z + q, or out[p] is NaN (MZ[p] untouched) when a number is not
 * finite. False when the arrays are not as described. */
static PyObject *py_lcp_measure_batch(PyObject *self, PyObject *args)
{
    PyObject *objs[5];
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOO", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4]))
        return NULL;
    idx k = PyObject_Length(objs[1]), n = 0;
    Py_buffer vz;
    if (k >= 1 && PyObject_GetBuffer(objs[2], &vz, PyBUF_ND) == 0) {
        if (vz.ndim == 2) n = vz.shape[1];
        PyBuffer_Release(&vz);
    }
    PyErr_Clear();
    Py_buffer v[5];
    idx sizes[5] = {k * n * n, k * n, k * n, k * n, 4 * k};
    int writable[5] = {0, 0, 0, 1, 1};
    if (n < 1 || get_doubles(objs, v, sizes, writable, 5) < 5) Py_RETURN_FALSE;
    const double *Ms = (const double *)v[0].buf, *qs = (const double *)v[1].buf,
                 *Z = (const double *)v[2].buf;
    double *W = (double *)v[3].buf, *out = (double *)v[4].buf;
    for (idx p = 0; p < k; p++)
        if (measure_one(n, Ms + p * n * n, qs + p * n, Z + p * n, W + p * n, out + 4 * p) < 0)
            for (int j = 0; j < 4; j++) out[4 * p + j] = 0.0 / 0.0;
    for (int i = 0; i < 5; i++) PyBuffer_Release(&v[i]);
    Py_RETURN_TRUE;
}

/* solve_fast(M, q, tol, max_iter, z, w, basis, dot, upto) -> (code, pivots, nbasis, acode,
 * berr, ferr, refined, raw, scaled): lcp.solve's common call in one crossing from Python
 * (lcp/solvers/fast_lemke.py): `solve_accept` and then, when the answer was assessed here
 * (code 0, acode 0), lcp.residual's measure as `solve_lemke` took it -- w = dot(M, z, w) by the
 * `dot` given (numpy.dot: the same BLAS call as M.dot(z), written into w) and `lcp_measure`'s C
 * steps when n <= upto (w becomes M z + q) -- with no Python between. raw and scaled are NaN
 * when not measured here (the caller measures in numpy). M: C-contiguous n x n float64, q, z,
 * w float64 of length n (ndim 1), basis int64 of length n; else ValueError. */
static PyObject *py_solve_fast(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 9) {
        PyErr_SetString(PyExc_TypeError, "solve_fast: nine arguments");
        return NULL;
    }
    double tol = PyFloat_AsDouble(args[2]);
    long long max_iter = PyLong_AsLongLong(args[3]);
    idx upto = PyLong_AsSsize_t(args[8]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer vq = {0}, vM = {0}, vz = {0}, vw = {0}, vb = {0};
    PyObject *result = NULL;
    idx n = PyObject_Length(args[1]);
    if (n < 1) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "q: empty");
        return NULL;
    }
    if (get_buffer(args[1], &vq, "q", 'd', n, 0) < 0) return NULL;
    if (get_buffer(args[0], &vM, "M", 'd', n * n, 0) < 0) goto done;
    if (get_buffer(args[4], &vz, "z", 'd', n, 0) < 0) goto done;
    if (get_buffer(args[5], &vw, "w", 'd', n, 0) < 0) goto done;
    if (get_buffer(args[6], &vb, "basis", 'q', n, 0) < 0) goto done;
    if (vq.ndim != 1 || vM.ndim != 2 || vM.shape[0] != n || vM.shape[1] != n) {
        PyErr_SetString(PyExc_ValueError, "M must be n x n and q of length n");
        goto done;
    }
    const double *M = (const double *)vM.buf, *q = (const double *)vq.buf;
    double *z = (double *)vz.buf, *w = (double *)vw.buf;
    long long pivots = 0;
    double res[3], got[4] = {NAN, NAN, 0.0, 0.0};
    idx nb = 0;
    int code, acode = 1;
    Py_BEGIN_ALLOW_THREADS
    code = solve_and_accept(n, M, q, tol, max_iter, z, (int64_t *)vb.buf, &pivots, &nb, &acode,
                            res);
    Py_END_ALLOW_THREADS
    if (code < 0) {
        PyErr_NoMemory();
        goto done;
    }
    if (code == 0 && acode == 0) {
        PyObject *call[3] = {args[0], args[4], args[5]};
        PyObject *out = PyObject_Vectorcall(args[7], call, 3, NULL); /* dot(M, z, w) */
        if (!out) goto done;
        Py_DECREF(out);
        if (n <= upto && measure_one(n, M, q, z, w, got) < 0) got[0] = got[1] = NAN;
    }
    result = Py_BuildValue("iLniddidd", code, pivots, nb, acode, res[0], res[1], (int)res[2],
                           got[0], got[1]);
done:
    release(&vb);
    release(&vw);
    release(&vz);
    release(&vM);
    release(&vq);
    return result;
}

static PyMethodDef methods[] = {
    {"solve_batch", py_solve_batch, METH_VARARGS,
     "solve_batch(Ms, qs, d, tol, max_iter, Z, basic_z, codes, pivots, mode=0, acc=None): k "
     "LCPs by Lemke (and the acceptance of each answer into acc)."},
    {"solve_accept", py_solve_accept, METH_VARARGS,
     "solve_accept(M, q, tol, max_iter, z, basis) -> (code, pivots, nbasis, acode, berr, ferr, "
     "refined): solve_eq's default Lemke and the acceptance of its answer in one call."},
    {"solve_fast", (PyCFunction)(void (*)(void))py_solve_fast, METH_FASTCALL,
     "solve_fast(M, q, tol, max_iter, z, w, basis, dot, upto) -> (code, pivots, nbasis, acode, "
     "berr, ferr, refined, raw, scaled): solve_accept, then w = dot(M, z, w) and the measure."},
    {"solve_eq", py_solve_eq, METH_VARARGS,
     "solve_eq(M, q, r, c, d, tol, max_iter, z, basis) -> (code, pivots, nbasis, bounds): one "
     "LCP by Lemke on its equilibrated data."},
    {"lcp_measure", py_lcp_measure, METH_VARARGS,
     "lcp_measure(M, q, z, Mz) -> (residual, scaled, z_s, w_s) or None; Mz becomes M z + q."},
    {"lcp_measure_batch", py_lcp_measure_batch, METH_VARARGS,
     "lcp_measure_batch(Ms, qs, Z, MZ, out) -> bool: lcp_measure of k problems."},
    {"abs_row_sums", py_abs_row_sums, METH_VARARGS,
     "abs_row_sums(M, out, n): out = the row sums of |M| (m x n), in numpy's order."},
    {"check", py_check, METH_VARARGS, "check(M, q) -> (all finite, min q)."},
    {"plain", (PyCFunction)(void (*)(void))py_plain, METH_FASTCALL,
     "plain(M, q) -> bool: C-contiguous native float64 q (n >= 1) and M (n x n), all finite."},
    {"setup", py_setup, METH_VARARGS,
     "setup(T, M, q, d) -> (mu, nu, delta): the normalized dictionary (see lcp/lemke.py)."},
    {"run", py_run, METH_VARARGS,
     "run(T, basic, nonbasic, row_of, slot_of, tol, max_iter, trace) -> (code, pivots, s, "
     "entering): Lemke's pivot loop on the dictionary T (see lcp/_lemke_kernel.py)."},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_lemke_c",
                                    "Lemke's pivot loop in C (see lcp/_lemke_kernel.py).", -1,
                                    methods};

PyMODINIT_FUNC PyInit__lemke_c(void) { return PyModule_Create(&module); }
