/* lcp_internal.h — helpers shared by the files of the LCP module only
 * (not part of the public contract in pd_lcp.h). */
#ifndef PD_LCP_INTERNAL_H
#define PD_LCP_INTERNAL_H

/* Largest |x_i| of a vector. */
double pd_lcp_max_abs(int n, const double *x);

/* w = M z + q (columns with z_j == 0 skipped) and the residual figures of
 * pd_lcp_residual, given max|M| already known. */
void pd_lcp_residual_mmax(int n, const double *M, const double *q, const double *z,
                          double mmax, double *w, double *complementarity,
                          double *infeasibility, double *scale);

#endif
