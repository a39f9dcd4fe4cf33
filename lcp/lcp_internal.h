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
/* The same with zs = max|z| given (a solver that made z knows it). */
void pd_lcp_verify_zs(const pd_matrix *M, const double *q, const double *z, double *w, double *rows,
                      double zs, pd_lcp_info *info);

/* The structured solver (structured.c): block principal pivoting and an
 * interior point on L D L^T factors of M_FF, an envelope of at most envmax
 * entries; flag: n bytes of scratch. */
typedef struct pd_bpp_work pd_bpp_work;
pd_bpp_work *pd_bpp_alloc(int nmax, long envmax);
void pd_bpp_free(pd_bpp_work *ws);
int pd_bpp_nmax(const pd_bpp_work *ws);
int pd_bpp_solve(pd_bpp_work *ws, const pd_matrix *M, const double *q, const pd_lcp_opts *o,
                 double *z, double *w, unsigned char *flag, pd_lcp_info *info);
/* Its direct method for tridiagonal Stieltjes matrices alone (the first
 * thing pd_bpp_solve tries): 1 with z (unverified), 0 when M is not in
 * compressed columns, tridiagonal, symmetric, with a positive diagonal and
 * off-diagonal entries <= 0 (or n > nmax), -1 when a pivot is not positive
 * (a singular principal block).  z is clamped at 0, *zs = max z. */
int pd_bpp_stieltjes(pd_bpp_work *ws, const pd_matrix *M, const double *q, double *z, double *zs);

/* Projected Gauss-Seidel (pgs.c). */
typedef struct pd_pgs_work pd_pgs_work;
pd_pgs_work *pd_pgs_alloc(int nmax);
void pd_pgs_free(pd_pgs_work *ws);
int pd_pgs_solve(pd_pgs_work *ws, const pd_matrix *M, const double *q, const pd_lcp_opts *o,
                 double *z, double *w, pd_lcp_info *info);

#endif
