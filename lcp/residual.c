/* residual.c — residuals of an LCP candidate. */
#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "lcp_internal.h"
#include "pd_lcp.h"

/* max_i |x_i|, in four lanes so that -O2 vectorises it. */
double pd_lcp_max_abs(int n, const double *x)
{
    double m0 = 0.0, m1 = 0.0, m2 = 0.0, m3 = 0.0;
    int i = 0;
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

/* Ratio a / b with 0 / 0 = 0 (a term that is exactly zero is exact). */
static double ratio(double a, double b)
{
    return a == 0.0 ? 0.0 : b > 0.0 ? a / b : HUGE_VAL;
}

/* w = M z + q and the row sizes r_i = |q_i| + sum_j |M_ij| |z_j|, column by
 * column over the support of z. */
static void affine_rows(const pd_matrix *M, const double *q, const double *z, double *w,
                        double *r)
{
    int n = M->rows;
    for (int i = 0; i < n; i++) {
        w[i] = q[i];
        r[i] = fabs(q[i]);
    }
    for (int j = 0; j < M->cols; j++) {
        double zj = z[j];
        if (zj == 0.0)
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

/* The residual figures of a candidate z, with the relative backward residual
 *   max_i max(-z_i / zs, -w_i / r_i, min(|w_i| / r_i, |z_i| / zs)),
 * zs = max|z|, r_i the size of the terms that make w_i: invariant under
 * scaling q and z, or M and 1/z, and exact zeros count as exact.  A z or w
 * with a NaN or an infinity, or whose terms overflow (r_i infinite: a
 * diverged iteration), is no answer: its figures are NaN, which no
 * tolerance accepts (x / inf would otherwise pass as a ratio of 0); so
 * are they when a row is too small to be judged (VERIFY_ROW_MIN). */
void pd_lcp_verify(const pd_matrix *M, const double *q, const double *z, double *w, double *rows,
                   pd_lcp_info *info)
{
    int n = M->rows, nan = 0;
    double zs = pd_lcp_max_abs(n, z), comp = 0.0, infeas = 0.0, rel = 0.0, scale = 0.0;
    double row_min = (n + 1.0) * VERIFY_ROW_MIN;
    affine_rows(M, q, z, w, rows);
    for (int i = 0; i < n; i++) { /* NaN compares false: caught apart, once */
        double za = fabs(z[i]), wa = fabs(w[i]), zi = ratio(za, zs), wi = ratio(wa, rows[i]);
        double v = wi < zi ? wi : zi;
        nan |= !isfinite(z[i]) || !isfinite(w[i]) || !isfinite(rows[i]);
        nan |= rows[i] > 0.0 && rows[i] < row_min;
        comp = pd_max(comp, za * wa);
        infeas = pd_max(infeas, pd_max(-z[i], -w[i]));
        v = z[i] < 0.0 ? pd_max(v, zi) : v;
        v = w[i] < 0.0 ? pd_max(v, wi) : v;
        rel = pd_max(rel, v);
        scale = pd_max(scale, rows[i]);
    }
    info->complementarity = nan ? NAN : comp;
    info->infeasibility = nan ? NAN : infeas;
    info->residual = nan ? NAN : rel;
    info->scale = scale;
}

void pd_lcp_residual(int n, const double *M, const double *q, const double *z, double *w,
                     double *complementarity, double *infeasibility, double *residual)
{
    if (!M || !q || !z || !w)
        return;
    pd_matrix A = pd_matrix_dense(n, n, M);
    pd_lcp_info info = {.complementarity = NAN, .infeasibility = NAN, .residual = NAN};
    double rows[64], *r = n <= 64 ? rows : malloc((size_t)n * sizeof(double));
    if (r)
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
