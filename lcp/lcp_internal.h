/* lcp_internal.h — helpers shared by the files of the LCP module only
 * (not part of the public contract in pd_lcp.h). */
#ifndef PD_LCP_INTERNAL_H
#define PD_LCP_INTERNAL_H

#include "pd_lcp.h"

/* Largest |x_i| of a vector. */
double pd_lcp_max_abs(int n, const double *x);

/* w = M z + q and the residual figures into info (complementarity,
 * infeasibility, residual, scale); rows: n doubles of scratch. */
void pd_lcp_verify(const pd_matrix *M, const double *q, const double *z, double *w, double *rows,
                   pd_lcp_info *info);

#endif
