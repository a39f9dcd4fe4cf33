/* structured.c — the structured LCP solver for symmetric positive
 * (semi)definite M, the Delassus matrices of the engine (docs/lcp.md):
 *
 *   block principal pivoting (Judice & Pires 1994)  A guess F of the support:
 *     z_F solves M_FF z_F = -q_F, z = 0 off F, w = M z + q.  The infeasible
 *     indices (z_i < 0 in F, w_i < 0 off F) all change sides while their
 *     number keeps falling; after BPP_PATIENCE rounds without a new low only
 *     the largest does (Murty's rule, finite for every P-matrix).  Warm
 *     started from the last time step's support it ends in one or two solves.
 *   interior point (Mehrotra predictor-corrector, infeasible start)  For a
 *     cold start, or when pivoting does not settle within BPP_WARM_ROUNDS:
 *     (M + W Z^-1) dz = ..., a fixed number of iterations whatever n, each
 *     one envelope factorisation.  It finds the support of an impact that
 *     runs along a chain in one go, where pivoting would move it one index
 *     per solve.  Its point, if it verifies, is the answer; else its support
 *     (z_i > w_i) warm-starts the pivoting again.
 *
 * Both factor by an envelope (profile) Cholesky in the order of the
 * indices: row i of L is stored from its first nonzero column on, and
 * fill-in stays inside that envelope.  The Delassus matrices of a row of
 * structures are (block) banded in the contact order, so a factorisation
 * costs O(n b^2) for bandwidth b: linear in the length of the row.  Every
 * answer is verified (pd_lcp_verify); what does not verify is handed back
 * as numerical or max_iterations for Lemke to take over. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lcp_internal.h"

#define BPP_PATIENCE 3      /* rounds without a new low before Murty's single swaps */
#define BPP_WARM_ROUNDS 4   /* pivoting rounds from a guess before the interior point */
#define BPP_SIGN_TOL 1e-11  /* z_i, w_i below -this * their scale count as infeasible */
#define BPP_PIVOT_TOL 1e-13 /* a Cholesky pivot below this * the diagonal: not positive */
#define IPM_MAX 40          /* interior-point iterations at most */
#define IPM_MU_TOL 1e-9     /* complementarity z.w / n to reach, relative to the scales,
                               before the support is handed to the pivoting */
#define IPM_MU_FINAL 1e-17  /* the same when the point itself must be the answer
                               (a singular M_FF: redundant contacts) */
#define IPM_STEP 0.995      /* fraction of the step to the boundary */
#define IPM_SHIFT 1e-8      /* regularisation of the least-squares start, times max M_ii */
#define IPM_START 0.1       /* the start's distance from the boundary, times the scales */

struct pd_bpp_work {
    int nmax;
    long envmax;
    unsigned char *inF; /* n: in the support guess */
    int *loc;           /* n: local index of a global one in F, or -1 */
    int *glob;          /* n: global index of a local one */
    int *first;         /* n: first column of the envelope of local row i */
    long *rowptr;       /* n + 1: start of row i in env */
    double *env;        /* envmax: the envelope of L, row by row */
    double *diag;       /* n: M_ii */
    double *rhs;        /* n: the local right-hand side, then z_F */
    double *rows;       /* n: row sizes of the verification */
    double *iz, *iw, *dz, *dw, *az, *aw, *r; /* n each: the interior point's */
};

void pd_bpp_free(pd_bpp_work *ws)
{
    if (!ws)
        return;
    free(ws->inF);
    free(ws->loc);
    free(ws->glob);
    free(ws->first);
    free(ws->rowptr);
    free(ws->env);
    free(ws->diag);
    free(ws->rhs);
    free(ws->rows);
    double *ipm[] = {ws->iz, ws->iw, ws->dz, ws->dw, ws->az, ws->aw, ws->r};
    for (size_t k = 0; k < sizeof ipm / sizeof ipm[0]; k++)
        free(ipm[k]);
    free(ws);
}

pd_bpp_work *pd_bpp_alloc(int nmax, long envmax)
{
    pd_bpp_work *ws = calloc(1, sizeof *ws);
    if (!ws || nmax < 1 || envmax < nmax) {
        free(ws);
        return NULL;
    }
    size_t n = (size_t)nmax;
    ws->nmax = nmax;
    ws->envmax = envmax;
    ws->inF = malloc(n);
    ws->loc = malloc(n * sizeof(int));
    ws->glob = malloc(n * sizeof(int));
    ws->first = malloc(n * sizeof(int));
    ws->rowptr = malloc((n + 1) * sizeof(long));
    ws->env = malloc((size_t)envmax * sizeof(double));
    ws->diag = malloc(n * sizeof(double));
    ws->rhs = malloc(n * sizeof(double));
    ws->rows = malloc(n * sizeof(double));
    double **ipm[] = {&ws->iz, &ws->iw, &ws->dz, &ws->dw, &ws->az, &ws->aw, &ws->r};
    int ok = 1;
    for (size_t k = 0; k < sizeof ipm / sizeof ipm[0]; k++)
        ok &= (*ipm[k] = malloc(n * sizeof(double))) != NULL;
    if (!ok || !ws->inF || !ws->loc || !ws->glob || !ws->first || !ws->rowptr || !ws->env ||
        !ws->diag || !ws->rhs || !ws->rows) {
        pd_bpp_free(ws);
        return NULL;
    }
    return ws;
}

int pd_bpp_nmax(const pd_bpp_work *ws)
{
    return ws ? ws->nmax : 0;
}

/* Entries of column j of M (the row j of a symmetric M): calls fn(i, Mij). */
#define FOR_COLUMN(M, j, I, X, BODY)                                                          \
    do {                                                                                      \
        if ((M)->kind == PD_MATRIX_CSC) {                                                     \
            for (int k_ = (M)->colptr[j]; k_ < (M)->colptr[(j) + 1]; k_++) {                  \
                int I = (M)->rowind[k_];                                                      \
                double X = (M)->values[k_];                                                   \
                BODY;                                                                         \
            }                                                                                 \
        } else {                                                                              \
            const double *c_ = (M)->values + (size_t)(j) * (size_t)(M)->rows;                 \
            for (int I = 0; I < (M)->rows; I++) {                                             \
                double X = c_[I];                                                             \
                if (X != 0.0) {                                                               \
                    BODY;                                                                     \
                }                                                                             \
            }                                                                                 \
        }                                                                                     \
    } while (0)

/* The envelope of M_FF (k local rows) and its entries, plus shift_i on the
 * diagonal (shift NULL: none): row i of A holds columns first[i] .. i.  -1
 * when the envelope exceeds the workspace. */
static int load_envelope(pd_bpp_work *ws, const pd_matrix *M, int k, const double *shift)
{
    long off = 0;
    for (int i = 0; i < k; i++) {
        int g = ws->glob[i], f = i;
        FOR_COLUMN(M, g, r, x, {
            int l = ws->loc[r];
            (void)x;
            if (l >= 0 && l < f)
                f = l;
        });
        ws->first[i] = f;
        ws->rowptr[i] = off;
        off += i - f + 1;
        if (off > ws->envmax)
            return -1;
    }
    ws->rowptr[k] = off;
    memset(ws->env, 0, (size_t)off * sizeof(double));
    for (int i = 0; i < k; i++) {
        double *row = ws->env + ws->rowptr[i] - ws->first[i]; /* row[j] = A_ij */
        FOR_COLUMN(M, ws->glob[i], r, x, {
            int l = ws->loc[r];
            if (l >= 0 && l <= i)
                row[l] = x;
        });
        if (shift)
            row[i] += shift[i];
    }
    return 0;
}

/* A = L L^T in place on the envelope; -1 when a pivot is not positive. */
static int envelope_cholesky(pd_bpp_work *ws, int k)
{
    for (int i = 0; i < k; i++) {
        int fi = ws->first[i];
        double *ri = ws->env + ws->rowptr[i] - fi;
        for (int j = fi; j < i; j++) {
            int fj = ws->first[j], lo = fi > fj ? fi : fj;
            const double *rj = ws->env + ws->rowptr[j] - fj;
            double s = ri[j];
            for (int c = lo; c < j; c++)
                s -= ri[c] * rj[c];
            ri[j] = s / rj[j];
        }
        double d = ri[i];
        for (int c = fi; c < i; c++)
            d -= ri[c] * ri[c];
        if (!(d > BPP_PIVOT_TOL * ri[i]) || !(d > 0.0))
            return -1;
        ri[i] = sqrt(d);
    }
    return 0;
}

/* x = (L L^T)^-1 x in place. */
static void envelope_solve(const pd_bpp_work *ws, int k, double *x)
{
    for (int i = 0; i < k; i++) { /* L y = x, row by row */
        const double *ri = ws->env + ws->rowptr[i] - ws->first[i];
        double s = x[i];
        for (int c = ws->first[i]; c < i; c++)
            s -= ri[c] * x[c];
        x[i] = s / ri[i];
    }
    for (int i = k - 1; i >= 0; i--) { /* L^T z = y, column i of L^T is row i of L */
        const double *ri = ws->env + ws->rowptr[i] - ws->first[i];
        x[i] /= ri[i];
        for (int c = ws->first[i]; c < i; c++)
            x[c] -= ri[c] * x[i];
    }
}

/* z on F from the principal system, w = M z + q with the row sizes; the
 * number of unknowns in F, or -1 (envelope too large), -2 (not positive). */
static int principal_solve(pd_bpp_work *ws, const pd_matrix *M, const double *q, double *z,
                           double *w)
{
    int n = M->rows, k = 0;
    for (int i = 0; i < n; i++) {
        ws->loc[i] = -1;
        if (ws->inF[i]) {
            ws->loc[i] = k;
            ws->glob[k++] = i;
        }
    }
    if (load_envelope(ws, M, k, NULL))
        return -1;
    if (envelope_cholesky(ws, k))
        return -2;
    for (int l = 0; l < k; l++)
        ws->rhs[l] = -q[ws->glob[l]];
    envelope_solve(ws, k, ws->rhs);
    memset(z, 0, (size_t)n * sizeof(double));
    for (int l = 0; l < k; l++)
        z[ws->glob[l]] = ws->rhs[l];
    for (int i = 0; i < n; i++) {
        w[i] = q[i];
        ws->rows[i] = fabs(q[i]);
    }
    for (int l = 0; l < k; l++) {
        int j = ws->glob[l];
        double zj = z[j];
        FOR_COLUMN(M, j, r, x, {
            w[r] += x * zj;
            ws->rows[r] += fabs(x * zj);
        });
    }
    return k;
}

/* Mark the infeasible indices (in F: z_i < 0; off F: w_i < 0, each below
 * its rounding level); their number, the largest in *last. */
static int infeasible(const pd_bpp_work *ws, int n, const double *z, const double *w,
                      unsigned char *flag, int *last)
{
    double zs = pd_lcp_max_abs(n, z);
    int count = 0;
    *last = -1;
    for (int i = 0; i < n; i++) {
        flag[i] = ws->inF[i] ? z[i] < -BPP_SIGN_TOL * zs : w[i] < -BPP_SIGN_TOL * ws->rows[i];
        if (flag[i]) {
            count++;
            *last = i;
        }
    }
    return count;
}

/* Pivoting rounds from the support in ws->inF: 0 with z, w the answer
 * (not yet verified), -1 (M_FF not positive, or the envelope too large),
 * or 1 when `rounds` rounds did not settle.  *iterations counts the solves. */
static int pivot_rounds(pd_bpp_work *ws, const pd_matrix *M, const double *q, int rounds,
                        double *z, double *w, unsigned char *flag, int *iterations)
{
    int n = M->rows, best = n + 1, patience = BPP_PATIENCE;
    for (int round = 0; round < rounds; round++) {
        int last, k = principal_solve(ws, M, q, z, w);
        ++*iterations;
        if (k < 0)
            return -1;
        int count = infeasible(ws, n, z, w, flag, &last);
        if (count == 0)
            return 0;
        if (count < best) { /* a new low: every infeasible index changes sides */
            best = count;
            patience = BPP_PATIENCE;
        } else if (patience > 0) {
            patience--;
        } else { /* Murty: only the largest */
            memset(flag, 0, (size_t)n);
            flag[last] = 1;
        }
        for (int i = 0; i < n; i++)
            ws->inF[i] ^= flag[i];
    }
    return 1;
}

/* y = M x. */
static void matvec(const pd_matrix *M, const double *x, double *y)
{
    memset(y, 0, (size_t)M->rows * sizeof(double));
    for (int j = 0; j < M->cols; j++)
        if (x[j] != 0.0)
            FOR_COLUMN(M, j, r, v, y[r] += v * x[j]);
}

/* The largest step in (0, 1] keeping z + a dz and w + a dw positive. */
static double step_to_boundary(int n, const double *z, const double *dz, const double *w,
                               const double *dw)
{
    double a = 1.0;
    for (int i = 0; i < n; i++) {
        if (dz[i] < 0.0 && -z[i] / dz[i] < a)
            a = -z[i] / dz[i];
        if (dw[i] < 0.0 && -w[i] / dw[i] < a)
            a = -w[i] / dw[i];
    }
    return a;
}

/* The start: the (regularised) least-squares solution of M z = -q moved
 * inside the positive orthant, w = M z + q likewise; -1 if the factor fails. */
static int ipm_start(pd_bpp_work *ws, const pd_matrix *M, const double *q, double qs, double ds)
{
    int n = M->rows;
    double *z = ws->iz, *w = ws->iw;
    for (int i = 0; i < n; i++) {
        ws->loc[i] = ws->glob[i] = i;
        ws->diag[i] = IPM_SHIFT * ds;
        z[i] = -q[i];
    }
    if (load_envelope(ws, M, n, ws->diag) || envelope_cholesky(ws, n))
        return -1;
    envelope_solve(ws, n, z);
    double zs = fmax(pd_lcp_max_abs(n, z), qs / ds);
    for (int i = 0; i < n; i++)
        z[i] = fmax(z[i], 0.0) + IPM_START * zs;
    matvec(M, z, w);
    for (int i = 0; i < n; i++)
        w[i] = fmax(w[i] + q[i], 0.0) + IPM_START * qs;
    return 0;
}

/* Mehrotra's predictor-corrector for the monotone LCP, infeasible start:
 *   (M + W Z^-1) dz = -(M z + q) + (sigma mu - dz_a dw_a) / z,
 *   dw = (sigma mu - dz_a dw_a) / z - w - (w / z) dz,
 * sigma = (mu_affine / mu)^3, until mu = z.w / n is small relative to the
 * scales.  The point in ws->iz, ws->iw; -1 when a factorisation fails, else
 * the iterations made. */
static int interior_point(pd_bpp_work *ws, const pd_matrix *M, const double *q, double qs,
                          double ds, double tol, int from_start)
{
    int n = M->rows, it;
    double *z = ws->iz, *w = ws->iw, *dz = ws->dz, *dw = ws->dw, *az = ws->az, *aw = ws->aw;
    if (from_start && ipm_start(ws, M, q, qs, ds))
        return -1;
    for (int i = 0; i < n; i++)
        ws->loc[i] = ws->glob[i] = i;
    for (it = 0; it < IPM_MAX; it++) {
        double mu = 0.0, rmax = 0.0;
        matvec(M, z, ws->r);
        for (int i = 0; i < n; i++) {
            mu += z[i] * w[i] / n;
            ws->r[i] += q[i]; /* M z + q */
            rmax = fmax(rmax, fabs(w[i] - ws->r[i]));
            ws->diag[i] = w[i] / z[i];
        }
        if (mu <= tol * qs * qs / ds && rmax <= tol * qs)
            break;
        if (load_envelope(ws, M, n, ws->diag) || envelope_cholesky(ws, n))
            return -1;
        for (int i = 0; i < n; i++) /* predictor */
            az[i] = -ws->r[i];
        envelope_solve(ws, n, az);
        for (int i = 0; i < n; i++)
            aw[i] = -w[i] - ws->diag[i] * az[i];
        double a = step_to_boundary(n, z, az, w, aw), mua = 0.0;
        for (int i = 0; i < n; i++)
            mua += (z[i] + a * az[i]) * (w[i] + a * aw[i]) / n;
        double sigma = pow(mua / mu, 3.0);
        for (int i = 0; i < n; i++) { /* corrector */
            double c = (sigma * mu - az[i] * aw[i]) / z[i];
            dz[i] = -ws->r[i] + c;
            ws->rows[i] = c;
        }
        envelope_solve(ws, n, dz);
        for (int i = 0; i < n; i++)
            dw[i] = ws->rows[i] - w[i] - ws->diag[i] * dz[i];
        a = IPM_STEP * step_to_boundary(n, z, dz, w, dw);
        for (int i = 0; i < n; i++) {
            z[i] += a * dz[i];
            w[i] += a * dw[i];
        }
    }
    return it;
}

/* z, w from the point (z clamped at 0, w = M z + q) and its verification. */
static int accept(pd_bpp_work *ws, const pd_matrix *M, const double *q, double *z, double *w,
                  pd_lcp_info *info)
{
    for (int i = 0; i < M->rows; i++)
        z[i] = z[i] > 0.0 ? z[i] : 0.0;
    pd_lcp_verify(M, q, z, w, ws->rows, info);
    return info->residual <= PD_LCP_VERIFY_TOL;
}

int pd_bpp_solve(pd_bpp_work *ws, const pd_matrix *M, const double *q, const pd_lcp_opts *o,
                 double *z, double *w, unsigned char *flag, pd_lcp_info *info)
{
    int n = M->rows, its = 0, rc;
    int maxit = o->max_iterations > 0 ? o->max_iterations : 3 * n + 10;
    double qs = pd_lcp_max_abs(n, q), ds = 0.0;
    info->iterations = 0;
    info->outcome = PD_LCP_NUMERICAL;
    for (int i = 0; i < n; i++) {
        ws->diag[i] = pd_matrix_get(M, i, i);
        ds = fmax(ds, ws->diag[i]);
        if (!(ws->diag[i] > 0.0))
            return PD_ENUMERICAL; /* not positive definite: not this solver's problem */
    }
    /* from the guess (a warm start), or from the signs of q */
    for (int i = 0; i < n; i++)
        ws->inF[i] = o->guess && o->guess[i] < 2 ? o->guess[i] : q[i] < 0.0;
    rc = pivot_rounds(ws, M, q, maxit < BPP_WARM_ROUNDS ? maxit : BPP_WARM_ROUNDS, z, w, flag,
                      &its);
    if (rc == 0 && accept(ws, M, q, z, w, info))
        goto solved;
    /* the interior point: its support hands over to the pivoting; if that
     * fails (a singular M_FF: redundant contacts), the point itself, driven
     * further, is the answer when it verifies */
    int ipm = qs > 0.0 ? interior_point(ws, M, q, qs, ds, IPM_MU_TOL, 1) : -1;
    if (ipm >= 0) {
        its += ipm;
        for (int i = 0; i < n; i++) /* the support: z_i M_ii > w_i, in the units of w */
            ws->inF[i] = ws->iz[i] * pd_matrix_get(M, i, i) > ws->iw[i];
        rc = pivot_rounds(ws, M, q, maxit > its ? maxit - its : 1, z, w, flag, &its);
        if (rc == 0 && accept(ws, M, q, z, w, info))
            goto solved;
        int more = interior_point(ws, M, q, qs, ds, IPM_MU_FINAL, 0);
        its += more > 0 ? more : 0;
        memcpy(z, ws->iz, (size_t)n * sizeof(double));
        if (more >= 0 && accept(ws, M, q, z, w, info))
            goto solved;
    }
    info->iterations = its;
    info->outcome = rc > 0 ? PD_LCP_MAX_ITERATIONS : PD_LCP_NUMERICAL;
    return rc > 0 ? PD_EMAXITER : PD_ENUMERICAL;
solved:
    info->iterations = its;
    info->outcome = PD_LCP_SOLVED;
    return PD_OK;
}
