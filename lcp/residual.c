/* residual.c — residuals of an LCP candidate. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "lcp_internal.h"
#include "pd_lcp.h"

/* max_i |x_i|, in four lanes so that -O2 vectorises it. */
double pd_lcp_max_abs(int n, const double *x)
{
    double m0 = 0.0, m1 = 0.0, m2 = 0.0, m3 = 0.0;
    int i = 0;
    /* four running maxima: independent chains that -O2 vectorises */
    for (; i + 4 <= n; i += 4) {
        double a0 = fabs(x[i]), a1 = fabs(x[i + 1]), a2 = fabs(x[i + 2]), a3 = fabs(x[i + 3]);
        m0 = a0 > m0 ? a0 : m0;
        m1 = a1 > m1 ? a1 : m1;
        m2 = a2 > m2 ? a2 : m2;
        m3 = a3 > m3 ? a3 : m3;
    }
    for (; i < n; i++) {
        double a = fabs(x[i]);
        m0 = a > m0 ? a : m0;
    }
    /* the lanes' maxima combined */
    m0 = m1 > m0 ? m1 : m0;
    m2 = m3 > m2 ? m3 : m2;
    return m2 > m0 ? m2 : m0;
}

/* A row whose terms add up to less than (n + 1) VERIFY_ROW_MIN is not
 * judged: below it the products and sums round to the subnormal spacing
 * (4.9e-324), an absolute error that 1e13 row sizes keep under 1e-13 of the
 * row (the verification's tolerance is 1e-10).  A problem at that scale has
 * no answer this solver can vouch for (stress: subnormal q). */
#define VERIFY_ROW_MIN (1e13 * DBL_TRUE_MIN)
/* Above every (n + 1) VERIFY_ROW_MIN (n < 2^31: below 1.1e-301), and normal:
 * only a row below it pays for the threshold, a subnormal product that
 * costs a microcode assist on x86 (about 100 cycles). */
#define VERIFY_ROW_BOUND 1e-300

/* A row too small to be judged: 0 < r < (n + 1) VERIFY_ROW_MIN. */
static int row_too_small(int n, double r)
{
    return r > 0.0 && r < VERIFY_ROW_BOUND && r < (n + 1.0) * VERIFY_ROW_MIN;
}

/* Ratio a / b with 0 / 0 = 0 (a term that is exactly zero is exact), for
 * a, b >= 0 or NaN.  b > 0 is tested first: a row's size is positive
 * almost always, so that branch is predicted, and a / b is then right for
 * a = 0 too; testing a = 0 first would branch on whether z_i (or w_i) is
 * zero, in an order no branch predictor learns past a few thousand rows. */
static double ratio(double a, double b)
{
    return b > 0.0 ? a / b : a == 0.0 ? 0.0 : HUGE_VAL;
}

/* Up to this n, a dense row i is made at once (w_i and r_i in registers, the
 * support of z gathered first) and judged while it is at hand: one pass, the
 * same sums in the same order as column by column. */
#define VERIFY_ROWWISE_N 32

/* The figures of pd_lcp_verify, row by row. */
typedef struct verify_acc {
    double comp, infeas, rel, scale;
    int nan;
} verify_acc;

/* a > b ? a : b, and x < 0 ? r : 0, without a branch: whether w_i is
 * negative (a rounding of 0 on the support) or z_i is zero follows no
 * order a branch predictor learns past a few thousand rows, and the
 * compiler may branch on a selection of doubles (gcc does here).  A
 * column with z_j = 0 adds -0 (live_term): x + -0 = x, and a NaN of M
 * there is dropped as affine_rows drops the column. */
#if defined(__SSE2__)
static inline double max_nb(double a, double b)
{
    return _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(a), _mm_set_sd(b)));
}
static inline double if_negative(double x, double r)
{
    return _mm_cvtsd_f64(_mm_and_pd(_mm_cmplt_sd(_mm_set_sd(x), _mm_setzero_pd()), _mm_set_sd(r)));
}
/* zj != 0 ? p : -0 */
static inline double live_term(double zj, double p)
{
    __m128d m = _mm_cmpneq_sd(_mm_set_sd(zj), _mm_setzero_pd());
    return _mm_cvtsd_f64(
        _mm_or_pd(_mm_and_pd(m, _mm_set_sd(p)), _mm_andnot_pd(m, _mm_set_sd(-0.0))));
}
#else
static inline double max_nb(double a, double b)
{
    return a > b ? a : b;
}
static inline double live_term(double zj, double p)
{
    return zj != 0.0 ? p : -0.0;
}
static inline double if_negative(double x, double r)
{
    return x < 0.0 ? r : 0.0;
}
#endif

/* Row i into the figures: z_i, w_i, its size r_i; zs = max|z|.  The
 * relative residual of the row is max(min(wi, zi), zi if z_i < 0, wi if
 * w_i < 0), each term >= 0 (when a term is NaN, acc->nan makes the
 * figures NaN whatever they are). */
static inline void verify_row(verify_acc *acc, int n, double zi_, double wi_, double ri, double zs)
{
    /* |z_i| / zs and |w_i| / r_i, with 0 / 0 = 0 */
    double za = fabs(zi_), wa = fabs(wi_), zi = ratio(za, zs), wi = ratio(wa, ri);
    double v = wi < zi ? wi : zi;
    acc->nan |= !isfinite(zi_) || !isfinite(wi_) || !isfinite(ri); /* NaN compares false */
    acc->nan |= row_too_small(n, ri);
    acc->comp = max_nb(acc->comp, za * wa);                /* max |z_i w_i| */
    acc->infeas = max_nb(acc->infeas, max_nb(-zi_, -wi_)); /* max(-z_i, -w_i) */
    /* min(|w_i| / r_i, |z_i| / zs), and a negative z_i or w_i in full */
    v = max_nb(v, max_nb(if_negative(zi_, zi), if_negative(wi_, wi)));
    acc->rel = max_nb(acc->rel, v);
    acc->scale = max_nb(acc->scale, ri);
}

/* w = M z + q, the row sizes and their figures for a dense M with n <=
 * VERIFY_ROWWISE_N, row by row over the support of z; zs = max|z|. */
static void verify_rowwise(const pd_matrix *M, const double *q, const double *z, double *w,
                           double *rows, double zs, verify_acc *acc)
{
    int n = M->rows, k = 0, supp[VERIFY_ROWWISE_N];
    /* supp: the columns with z_j != 0 */
    for (int j = 0; j < M->cols; j++)
        if (z[j] != 0.0)
            supp[k++] = j;
    for (int i = 0; i < n; i++) {
        double wi = q[i], ri = fabs(q[i]);
        /* w_i = q_i + sum_j M_ij z_j, r_i = |q_i| + sum_j |M_ij z_j| */
        for (int t = 0; t < k; t++) {
            double p = M->values[i + (size_t)supp[t] * (size_t)n] * z[supp[t]];
            wi += p;
            ri += fabs(p);
        }
        w[i] = wi;
        rows[i] = ri;
        verify_row(acc, n, z[i], wi, ri, zs);
    }
}

/* w = M z + q and the row sizes r_i = |q_i| + sum_j |M_ij| |z_j|, column by
 * column over the support of z. */
static void affine_rows(const pd_matrix *M, const double *q, const double *z, double *w, double *r)
{
    int n = M->rows;
    for (int i = 0; i < n; i++) {
        w[i] = q[i];
        r[i] = fabs(q[i]);
    }
    for (int j = 0; j < M->cols; j++) {
        double zj = z[j];
        if (zj == 0.0) /* nothing to add (a NaN of M there is dropped) */
            continue;
        if (M->kind == PD_MATRIX_DENSE) {
            const double *mj = M->values + (size_t)j * (size_t)n;
            for (int i = 0; i < n; i++) {
                w[i] += mj[i] * zj;
                r[i] += fabs(mj[i] * zj);
            }
        } else if (M->kind == PD_MATRIX_CSC) {
            for (int k = M->colptr[j]; k < M->colptr[j + 1]; k++) {
                w[M->rowind[k]] += M->values[k] * zj;
                r[M->rowind[k]] += fabs(M->values[k] * zj);
            }
        }
    }
}

/* w = M z + q, the row sizes and their figures for a tridiagonal M in
 * compressed columns, in one pass over the columns: the three rows column j
 * reaches are kept in registers, and row j - 1, complete once column j is
 * added, is judged at once (while it is in the first-level cache, where
 * affine_rows makes three passes over n-vectors and a fourth to judge).
 * The same sums in the same order as affine_rows (a row's terms by
 * ascending column, a column with z_j = 0 left out), so the same bits.  0,
 * or -1 at the first entry beyond the band of a column with z_j != 0 (w,
 * rows and acc then partial: the caller starts again). */
static int verify_tridiagonal(const pd_matrix *M, const double *q, const double *z, double *w,
                              double *rows, double zs, verify_acc *acc)
{
    int n = M->rows;
    const int *cp = M->colptr, *ri = M->rowind;
    const double *v = M->values;
    /* rows j - 1, j, j + 1 while column j is added */
    double wa = 0.0, ra = 0.0, wb = q[0], rb = fabs(q[0]), wc, rc;
    for (int j = 0; j < n; j++) {
        /* row j + 1 starts from q_j+1 */
        wc = j + 1 < n ? q[j + 1] : 0.0;
        rc = fabs(wc);
        /* a column with z_j = 0 adds -0 (live_term): no branch on z_j */
        double zj = z[j];
        int live = zj != 0.0;
        int k0 = cp[j];
        if (cp[j + 1] - k0 == 3 && ri[k0] == j - 1 && ri[k0 + 1] == j && ri[k0 + 2] == j + 1) {
            /* a chain's column, in order: no switch */
            double p0 = live_term(zj, v[k0] * zj), p1 = live_term(zj, v[k0 + 1] * zj);
            double p2 = live_term(zj, v[k0 + 2] * zj);
            wa += p0;
            ra += fabs(p0);
            wb += p1;
            rb += fabs(p1);
            wc += p2;
            rc += fabs(p2);
        } else
            for (int k = cp[j]; k < cp[j + 1]; k++) {
                double p = live_term(zj, v[k] * zj), pa = fabs(p);
                switch (ri[k] - j) {
                case -1:
                    wa += p;
                    ra += pa;
                    break;
                case 0:
                    wb += p;
                    rb += pa;
                    break;
                case 1:
                    wc += p;
                    rc += pa;
                    break;
                default:
                    if (live)
                        return -1; /* beyond the band: the general path */
                }
            }
        /* row j - 1 is complete: stored and judged */
        if (j > 0) {
            w[j - 1] = wa;
            rows[j - 1] = ra;
            verify_row(acc, n, z[j - 1], wa, ra, zs);
        }
        /* the window moves down a row */
        wa = wb;
        ra = rb;
        wb = wc;
        rb = rc;
    }
    /* the last row */
    w[n - 1] = wa;
    rows[n - 1] = ra;
    verify_row(acc, n, z[n - 1], wa, ra, zs);
    return 0;
}

/* The residual figures of a candidate z, with the relative backward residual
 *   max_i max(-z_i / zs, -w_i / r_i, min(|w_i| / r_i, |z_i| / zs)),
 * zs = max|z|, r_i the size of the terms that make w_i: invariant under
 * scaling q and z, or M and 1/z, and exact zeros count as exact.  A z or w
 * with a NaN or an infinity, or whose terms overflow (r_i infinite: a
 * diverged iteration), is no answer: its figures are NaN, which no
 * tolerance accepts (x / inf would otherwise pass as a ratio of 0); so
 * are they when a row is too small to be judged (VERIFY_ROW_MIN). */
void pd_lcp_verify_zs(const pd_matrix *M, const double *q, const double *z, double *w, double *rows,
                      double zs, pd_lcp_info *info)
{
    int n = M->rows;
    const verify_acc zero = {.comp = 0.0, .infeas = 0.0, .rel = 0.0, .scale = 0.0, .nan = 0};
    verify_acc acc = zero;
    if (M->kind == PD_MATRIX_DENSE && M->cols == n && n <= VERIFY_ROWWISE_N) {
        verify_rowwise(M, q, z, w, rows, zs, &acc);
    } else if (M->kind == PD_MATRIX_CSC && M->cols == n &&
               verify_tridiagonal(M, q, z, w, rows, zs, &acc) == 0) {
        /* done in one pass */
    } else {
        /* a tridiagonal pass cut short left partial figures */
        acc = zero;
        affine_rows(M, q, z, w, rows);
        for (int i = 0; i < n; i++)
            verify_row(&acc, n, z[i], w[i], rows[i], zs);
    }
    /* a NaN anywhere, or a row too small to judge: NaN figures, which no tolerance accepts */
    info->complementarity = acc.nan ? NAN : acc.comp;
    info->infeasibility = acc.nan ? NAN : acc.infeas;
    info->residual = acc.nan ? NAN : acc.rel;
    info->scale = acc.scale;
}

void pd_lcp_verify(const pd_matrix *M, const double *q, const double *z, double *w, double *rows,
                   pd_lcp_info *info)
{
    pd_lcp_verify_zs(M, q, z, w, rows, pd_lcp_max_abs(M->rows, z), info);
}

void pd_lcp_residual(int n, const double *M, const double *q, const double *z, double *w,
                     double *complementarity, double *infeasibility, double *residual)
{
    if (!M || !q || !z || !w)
        return;
    pd_matrix A = pd_matrix_dense(n, n, M);
    pd_lcp_info info = {.complementarity = NAN, .infeasibility = NAN, .residual = NAN};
    /* the row sizes on the stack up to n = 64 */
    double rows[64], *r = n <= 64 ? rows : malloc((size_t)n * sizeof(double));
    if (r) /* out of memory: the figures stay NaN */
        pd_lcp_verify(&A, q, z, w, r, &info);
    if (complementarity)
        *complementarity = info.complementarity;
    if (infeasibility)
        *infeasibility = info.infeasibility;
    if (residual)
        *residual = info.residual;
    if (r != rows)
        free(r);
}
