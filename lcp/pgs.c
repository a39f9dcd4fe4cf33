/* pgs.c — projected Gauss–Seidel, the baseline of Siconos and most
 * physics engines (docs/lcp.md):
 *   for i = 1..n:  z_i <- max(0, z_i - w_i / M_ii),  w <- w + (change) M[:, i],
 * with w = M z + q kept up to date column by column (so the matrix may be
 * dense or compressed-column, symmetric or not).  It converges for
 * symmetric positive semidefinite M with a positive diagonal; it stops when
 * the relative backward residual is verified (every PGS_CHECK sweeps) or
 * the sweep budget runs out, reported honestly as max_iterations. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lcp_internal.h"

#define PGS_CHECK 8 /* sweeps between two verifications */

struct pd_pgs_work {
    int nmax;
    double *diag, *rows;
};

void pd_pgs_free(pd_pgs_work *ws)
{
    if (!ws)
        return;
    free(ws->diag);
    free(ws->rows);
    free(ws);
}

pd_pgs_work *pd_pgs_alloc(int nmax)
{
    pd_pgs_work *ws = calloc(1, sizeof *ws);
    if (!ws || nmax < 1) {
        free(ws);
        return NULL;
    }
    ws->nmax = nmax;
    ws->diag = malloc((size_t)nmax * sizeof(double));
    ws->rows = malloc((size_t)nmax * sizeof(double));
    if (!ws->diag || !ws->rows) {
        pd_pgs_free(ws);
        return NULL;
    }
    return ws;
}

/* w += s M[:, j]. */
static void column_axpy(const pd_matrix *M, int j, double s, double *w)
{
    pd_matrix_col_axpy(M, j, s, w);
}

int pd_pgs_solve(pd_pgs_work *ws, const pd_matrix *M, const double *q, const pd_lcp_opts *o,
                 double *z, double *w, pd_lcp_info *info)
{
    int n = M->rows;
    /* the budget: max_iterations sweeps, else 1000 n, at most 10^6 */
    long maxit = o->max_iterations > 0 ? o->max_iterations : 1000L * n;
    maxit = maxit > 1000000L ? 1000000L : maxit;
    info->iterations = 0;
    for (int i = 0; i < n; i++) {
        /* the start z = 0, w = q; every M_ii must be positive */
        ws->diag[i] = pd_matrix_get(M, i, i);
        if (!(ws->diag[i] > 0.0)) {
            info->outcome = PD_LCP_NUMERICAL; /* a zero or negative pivot: PGS cannot move */
            memset(z, 0, (size_t)n * sizeof(double));
            pd_lcp_verify(M, q, z, w, ws->rows, info);
            return PD_ENUMERICAL;
        }
        z[i] = 0.0;
        w[i] = q[i];
    }
    for (long it = 1; it <= maxit; it++) {
        for (int i = 0; i < n; i++) {
            /* z_i <- max(0, z_i - w_i / M_ii): the new w_i is 0 where z_i stays positive */
            double zi = z[i] - w[i] / ws->diag[i];
            zi = zi > 0.0 ? zi : 0.0;
            if (zi != z[i]) { /* w += (z_i new - z_i) M[:, i] */
                column_axpy(M, i, zi - z[i], w);
                z[i] = zi;
            }
        }
        info->iterations = (int)it;
        if (it % PGS_CHECK == 0 || it == maxit) {
            pd_lcp_verify(M, q, z, w, ws->rows, info); /* w recomputed, drift removed */
            if (info->residual <= PD_LCP_VERIFY_TOL) {
                info->outcome = PD_LCP_SOLVED;
                return PD_OK;
            }
            if (!isfinite(info->residual)) /* diverged: no sweep brings it back */
                break;
        }
    }
    /* the budget spent, or a residual that diverged: numerical */
    info->outcome = isfinite(info->residual) ? PD_LCP_MAX_ITERATIONS : PD_LCP_NUMERICAL;
    return isfinite(info->residual) ? PD_EMAXITER : PD_ENUMERICAL;
}
