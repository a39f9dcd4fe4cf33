/* residual.c — residuals of an LCP candidate. */
#include <math.h>

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

/* w = M z + q, column by column (column-major, zero z_j skipped). */
static void lcp_affine(int n, const double *restrict M, const double *q, const double *z,
                       double *restrict w)
{
    for (int i = 0; i < n; i++)
        w[i] = q[i];
    for (int j = 0; j < n; j++) {
        double zj = z[j];
        if (zj == 0.0)
            continue;
        const double *mj = M + (size_t)j * (size_t)n;
        int i = 0;
        for (; i + 4 <= n; i += 4) { /* unrolled so that -O2 vectorises it */
            w[i] += mj[i] * zj;
            w[i + 1] += mj[i + 1] * zj;
            w[i + 2] += mj[i + 2] * zj;
            w[i + 3] += mj[i + 3] * zj;
        }
        for (; i < n; i++)
            w[i] += mj[i] * zj;
    }
}

/* comp = max|z_i w_i|, infeas = max(-z_i, -w_i, 0), scale = max(1, |q|, |M| max(1, |z|)) */
void pd_lcp_residual_mmax(int n, const double *M, const double *q, const double *z,
                          double mmax, double *w, double *complementarity,
                          double *infeasibility, double *scale)
{
    lcp_affine(n, M, q, z, w);
    double comp = 0.0, infeas = 0.0;
    for (int i = 0; i < n; i++) {
        double c = fabs(z[i] * w[i]);
        if (c > comp || isnan(c))
            comp = c;
        if (-z[i] > infeas || isnan(z[i]))
            infeas = -z[i];
        if (-w[i] > infeas || isnan(w[i]))
            infeas = -w[i];
    }
    double zmax = pd_lcp_max_abs(n, z);
    double data = fmax(pd_lcp_max_abs(n, q), mmax * fmax(1.0, zmax));
    *complementarity = comp;
    *infeasibility = isnan(infeas) ? NAN : fmax(infeas, 0.0);
    *scale = fmax(1.0, data);
}

/* The public form: max|M| measured here. */
void pd_lcp_residual(int n, const double *M, const double *q, const double *z,
                     double *w, double *complementarity, double *infeasibility,
                     double *scale)
{
    double mmax = pd_lcp_max_abs(n * n, M);
    pd_lcp_residual_mmax(n, M, q, z, mmax, w, complementarity, infeasibility, scale);
}
