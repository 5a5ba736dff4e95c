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
    for (idx i = 0; i < n; i++) {
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
