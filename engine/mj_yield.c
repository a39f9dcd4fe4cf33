/* mj_yield.c — Moreau–Jean with yielding springs (SPEC §7): the slider of
 * each spring a complementarity in the step's LCP, beside the contacts.
 *
 *   force   F - C v - K q + S ks (up + theta G): the offsets' force, G their
 *           increments over the step (sigma G, G >= 0, toward side sigma)
 *   vfree   the elastic step's, with h S ks up added to its right-hand side
 *   v+      = vfree + What^-1 (W_I P + h theta S_Y ks sigma G)
 *   z+      = S^T q+ - up - sigma G,   q+ = q + h ((1 - theta) v + theta v+)
 *   LCP     contacts: 0 <= P  ⊥  W_I^T v+ + e U >= 0
 *           springs:  0 <= G  ⊥  ks (uy - sigma z+) >= 0
 *           (the spring rows scaled by ks: the coupling blocks are opposite,
 *           M + M^T is positive semidefinite, Lemke solves it)
 *   Y       the springs the step pushes past +-uy: first the contacts alone
 *           (the elastic step), then Y and the contacts together, Y grown
 *           (or a side turned) while a solve leaves a spring past uy
 *   up     += sigma G
 * When no spring passes uy the step is the elastic one, bit for bit (and
 * with every offset 0 nothing is added to the force).  Memory: the LCP of
 * at most MJY_CAP unknowns, dense, and a few vectors, taken with the object. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mj.h"
#include "pd_alloc.h"

#define MJY_CAP 512     /* contacts and sliding springs in one LCP at most */
#define MJY_SLACK 1e-10 /* a spring past uy by more than this share of it joins Y */

struct mj_yield {
    int ns;
    double *up;            /* ns: the offsets (the state's st.up) */
    double *vfree;         /* n: the step's free velocity */
    double *col;           /* n: What^-1 S_j, or a sum of columns */
    int *ys;               /* ns: Y, in order of joining */
    signed char *sigma;    /* ns: the side of each spring in Y (0: not in Y) */
    double *L, *b, *z, *w; /* the LCP: MJY_CAP^2, MJY_CAP each */
    pd_lcp_work *lemke;
    long rounds; /* the LCPs solved with springs (statistics) */
};

void mj_yield_free(pd_mj *mj)
{
    mj_yield *y = mj->yl;
    if (!y)
        return;
    free(y->up);
    free(y->vfree);
    free(y->col);
    free(y->ys);
    free(y->sigma);
    free(y->L);
    free(y->b);
    free(y->z);
    free(y->w);
    pd_lcp_free(y->lemke);
    free(y);
    mj->yl = NULL;
}

int mj_yield_alloc(pd_mj *mj, pd_err *err)
{
    const pd_model *md = mj->model;
    int n = md->n, ns = md->ns;
    mj_yield *y = calloc(1, sizeof *y);
    mj->yl = y;
    if (!y)
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for %d yielding springs", ns);
    y->ns = ns;
    y->up = pd_calloc(ns, sizeof(double));
    y->vfree = pd_calloc(n, sizeof(double));
    y->col = pd_calloc(n, sizeof(double));
    y->ys = pd_calloc(ns, sizeof(int));
    y->sigma = pd_calloc(ns, 1);
    y->L = pd_malloc((long)MJY_CAP * MJY_CAP, sizeof(double));
    y->b = pd_malloc(MJY_CAP, sizeof(double));
    y->z = pd_malloc(MJY_CAP, sizeof(double));
    y->w = pd_malloc(MJY_CAP, sizeof(double));
    y->lemke = pd_lcp_alloc(MJY_CAP);
    if (!y->up || !y->vfree || !y->col || !y->ys || !y->sigma || !y->L || !y->b || !y->z || !y->w ||
        !y->lemke)
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for %d yielding springs", ns);
    mj->st.up = y->up;
    return PD_OK;
}

void mj_yield_reset(pd_mj *mj)
{
    if (mj->yl)
        memset(mj->yl->up, 0, (size_t)mj->yl->ns * sizeof(double));
}

/* x += s S diag(ks) up (skipped for a zero offset: an elastic step's bits). */
void mj_yield_force(const pd_mj *mj, double s, double *x)
{
    const pd_model *md = mj->model;
    for (int j = 0; j < md->ns; j++)
        if (mj->yl->up[j] != 0.0)
            pd_matrix_col_axpy(&md->S, j, s * md->ks[j] * mj->yl->up[j], x);
}

/* z+_j of the step's end state (out->q holds q + h (1 - theta) v). */
static double z_end(const pd_mj *mj, const pd_state *out, double hth, int j)
{
    const pd_model *md = mj->model;
    return pd_matrix_col_dot(&md->S, j, out->q) + hth * pd_matrix_col_dot(&md->S, j, out->v) -
           mj->yl->up[j];
}

/* The springs past uy after a solve: join Y on their side (a member past
 * the other side turns).  1 when Y changed. */
static int grow(pd_mj *mj, const pd_state *out, double hth, int *ny)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    int changed = 0;
    for (int j = 0; j < md->ns; j++) {
        double zj = z_end(mj, out, hth, j), lim = md->uy[j] * (1.0 + MJY_SLACK);
        /* a member's z+ is sigma uy at most; beyond -sigma uy it turns */
        int side = zj > lim ? 1 : zj < -lim ? -1 : 0;
        if (side == 0 || side == y->sigma[j])
            continue;
        if (y->sigma[j] == 0)
            y->ys[(*ny)++] = j;
        y->sigma[j] = (signed char)side;
        changed = 1;
    }
    return changed;
}

/* The LCP of the contacts idx_active (nI) and the springs Y (ny), dense
 * into y->L (column-major), y->b; q1 = q + h (1 - theta) v. */
static void build(pd_mj *mj, const pd_factor *f, int nI, int ny, double hth, const double *q1)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    int N = nI + ny;
    /* contacts: D_II (written at ld nI, then widened to ld N in place, back
     * to front: no entry is overwritten before it moves) and W_I^T vfree + e U */
    if (nI > 0) {
        pd_factor_delassus_dense(f, mj->idx_active, nI, y->L);
        for (int c = nI - 1; c >= 0; c--)
            for (int r = nI - 1; r >= 0; r--)
                y->L[(size_t)c * N + r] = y->L[(size_t)c * nI + r];
        mj_active_rhs(mj, nI, y->vfree);
        memcpy(y->b, mj->b_active, (size_t)nI * sizeof(double));
    }
    /* each spring k: the column What^-1 S_j gives its couplings */
    for (int k = 0; k < ny; k++) {
        int j = y->ys[k];
        double sk = y->sigma[j], ks = md->ks[j];
        memset(y->col, 0, (size_t)md->n * sizeof(double));
        pd_matrix_col_axpy(&md->S, j, 1.0, y->col);
        pd_factor_solve(f, y->col);
        for (int c = 0; c < nI; c++) { /* P's velocity on z, G's on the contacts */
            double d = hth * sk * ks * pd_matrix_col_dot(&md->W, mj->idx_active[c], y->col);
            y->L[(size_t)(nI + k) * N + c] = d;
            y->L[(size_t)c * N + nI + k] = -d;
        }
        for (int l = 0; l < ny; l++) { /* row l (spring jl) of column k, scaled by ks_jl */
            int jl = y->ys[l];
            double d = pd_matrix_col_dot(&md->S, jl, y->col);
            y->L[(size_t)(nI + k) * N + nI + l] =
                (l == k ? md->ks[jl] : 0.0) - hth * hth * y->sigma[jl] * sk * md->ks[jl] * ks * d;
        }
        /* ks (uy - sigma z_free), z_free the end state with the free velocity */
        y->b[nI + k] =
            ks * (md->uy[j] - sk * (pd_matrix_col_dot(&md->S, j, q1) +
                                    hth * pd_matrix_col_dot(&md->S, j, y->vfree) - y->up[j]));
    }
}

/* v+ = vfree + What^-1 (W_I P + h theta S_Y ks sigma G); out->P the
 * contacts' impulses. */
static void apply(pd_mj *mj, const pd_factor *f, int nI, int ny, double hth, pd_state *out)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    memcpy(out->v, y->vfree, (size_t)md->n * sizeof(double));
    for (int c = 0; c < nI; c++)
        out->P[mj->idx_active[c]] = mj->P_active[c] = y->z[c];
    pd_factor_add_impulse(f, mj->idx_active, nI, mj->P_active, out->v);
    memset(y->col, 0, (size_t)md->n * sizeof(double));
    for (int k = 0; k < ny; k++) {
        int j = y->ys[k];
        pd_matrix_col_axpy(&md->S, j, hth * y->sigma[j] * md->ks[j] * y->z[nI + k], y->col);
    }
    pd_factor_solve(f, y->col);
    for (int i = 0; i < md->n; i++)
        out->v[i] += y->col[i];
}

int mj_yield_step(pd_mj *mj, const pd_factor *f, double h, int nI, double t1, pd_state *out,
                  pd_err *err)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    double hth = h * mj->opts.theta;
    int rc, ny = 0;
    memcpy(y->vfree, out->v, (size_t)md->n * sizeof(double));
    memset(y->sigma, 0, (size_t)md->ns);
    /* the elastic step first: the contacts alone */
    if (nI > 0 && (rc = mj_contacts_apply(mj, f, nI, t1, out, err)))
        return rc;
    for (int round = 0; grow(mj, out, hth, &ny); round++) {
        int N = nI + ny;
        if (N > MJY_CAP || round > md->ns)
            return pd_err_set(err, PD_EBUDGET,
                              "Moreau-Jean: %d contacts and %d sliding springs at t = %.9g (at "
                              "most %d in one LCP, %d rounds)",
                              nI, ny, t1, MJY_CAP, md->ns + 1);
        build(mj, f, nI, ny, hth, out->q); /* out->q: q + h (1 - theta) v until the step ends */
        pd_lcp_opts lo = pd_lcp_default_opts();
        pd_lcp_info info;
        if ((rc = pd_lcp_lemke(y->lemke, N, y->L, y->b, &lo, y->z, y->w, &info)))
            return pd_err_set(err, rc,
                              "Moreau-Jean: the LCP of %d contacts and %d sliding springs not "
                              "solved at t = %.9g: %s",
                              nI, ny, t1, pd_lcp_outcome_name(info.outcome));
        y->rounds++;
        out->lcp_pivots += info.pivots;
        out->lcp_solver = "lemke";
        apply(mj, f, nI, ny, hth, out);
    }
    /* the offsets move by sigma G */
    for (int k = 0; k < ny; k++)
        y->up[y->ys[k]] += y->sigma[y->ys[k]] * y->z[nI + k];
    return PD_OK;
}
