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
 *   pieces  blocks of dofs that M, C, K couple, joined by the active
 *           contacts: a spring alone in a piece of one dof and no contact
 *           slides in closed form (G = max(0, -b / L), its 1 x 1 LCP); the
 *           others' pieces, with their contacts, make one dense LCP (the
 *           contacts outside keep the elastic pass's impulses: What is
 *           block diagonal, the pieces do not interact); a piece beyond
 *           MJY_CAP unknowns whose springs are each alone on a dof (a jammed
 *           row of SDOFs) is solved by block Gauss-Seidel: the contacts' LCP
 *           (the kernel's own solver) given the slides, each slide in closed
 *           form given the contacts, until no slide moves (MJY_GS_TOL)
 *   rows    every spring alone on its dof (rows of SDOFs): the slides of a
 *           set A taken as sliding are put into the contacts' LCP (slide_set:
 *           one LCP of the kernel's solver per try, the set corrected until
 *           it holds; Gauss-Seidel when it does not settle).  A starts from
 *           the last step's slides that its push would leave sliding; D_II's
 *           corrections go to places found at the allocation (each pair of
 *           contacts on a spring's dof, its entry of D) through the gather's
 *           map, and are put back from a log for the next try
 *   up     += sigma G
 * When no spring passes uy the step is the elastic one, bit for bit (and
 * with every offset 0 nothing is added to the force).  Memory: the LCP of
 * at most MJY_CAP unknowns, dense, and vectors of n, m, ns, taken with the
 * object. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mj.h"
#include "pd_alloc.h"

#define MJY_CAP 512      /* contacts and sliding springs in one LCP at most */
#define MJY_GS_MAX 200   /* block Gauss-Seidel sweeps of a larger piece at most */
#define MJY_GS_TOL 1e-13 /* ... until no slide moves by more than this share of its uy */
#define MJY_SLACK 1e-10  /* a spring past uy by more than this share of it joins Y */
#define MJY_SET_MAX 32   /* tries of the sliding set before Gauss-Seidel takes the step */

struct mj_yield {
    int ns;
    double *up;            /* ns: the offsets (the state's st.up) */
    double *vfree, *vel;   /* n: the step's free velocity, the elastic pass's */
    double *col;           /* n: What^-1 S_j, or a sum of columns */
    int *ys;               /* ns: Y, in order of joining */
    signed char *sigma;    /* ns: the side of each spring in Y (0: not in Y) */
    double *G;             /* ns: each spring's slide in the last solve */
    double *L, *b, *z, *w; /* the dense LCP: MJY_CAP^2, MJY_CAP each */
    pd_lcp_work *lemke;
    /* the pieces: dofs coupled by M, C, K (block, fixed), joined by contacts */
    int *block;           /* n: the block's first dof */
    double *dM, *dC, *dK; /* n: the diagonals (What of a one-dof block) */
    unsigned char *alone; /* n: the dof is a block of its own */
    int *uf;              /* n: union-find of the step's pieces */
    unsigned char *mark;  /* n, by piece: 1 has a contact, 2 a coupled spring */
    int *cidx;            /* m: the contacts of the coupled pieces */
    double *P0, *dP;      /* m: the elastic pass's impulses, the change */
    int *yc;              /* ns: the coupled springs of Y */
    int all_alone;        /* every spring alone on its dof (rows of SDOFs) */
    int one_per_dof;      /* and no two on one dof (the sliding set's iteration) */
    int ny_prev;          /* Y's springs that slid in the last step (Gauss-Seidel's start) */
    int *sdof;            /* ns: a spring's only dof (-1: its drift takes several) */
    double *sfac;         /* ns: its drift's multiple of that dof */
    long rounds;          /* the LCPs solved with springs (statistics) */
    long set_tries;       /* the sliding set's LCP tries (statistics) */
    long gs_steps;        /* steps block Gauss-Seidel took (statistics) */
    int moved;            /* an offset has moved since the reset */
    /* slide_set: the constants of h theta (hth_set), per spring alone on its
     * dof: its slide's 1 / L; the pairs of contacts on its dof and
     * their entries of D; per step: where D's entries went in D_II, the
     * entries a try changed, W_I P on the sliding dofs, the active rows */
    double hth_set;
    double *Linv;      /* ns: 1 / L of a slide */
    double *inc, *dcs; /* ns: h theta ks s / What_ii, the compliance a slide adds */
    double *bfree;     /* ns: a sliding spring's b from vfree (this try's) */
    int has_D;         /* a factor keeps D (m > 0) */
    int *pptr;         /* ns + 1: spring j's pairs pptr[j] .. pptr[j+1] */
    int *pcol, *prow;  /* the pair's contacts (D's column, row) */
    long *pk;          /* their entry of D (pd_factor_delassus_at; -1: none) */
    double *pw;        /* W_ia W_ib */
    int *map;          /* delassus_nnz: D's entry k at map[k] of D_II (compressed) */
    long *log_at;      /* the entries of D_II a try changed (as many as the pairs), */
    double *log_v;     /* ... their values before */
    int nlog;
    double *wp; /* n: (W_I P)_i */
    int *row;   /* m: a contact's row in the step's active set, -1 when
                             inactive (set and cleared by slide_set) */
    int *snext; /* n: the spring on a dof (-1: none) */
};

void mj_yield_free(pd_mj *mj)
{
    mj_yield *y = mj->yl;
    if (!y)
        return;
    void *arrays[] = {y->sdof,   y->sfac,  y->up,    y->vfree, y->vel, y->col, y->ys,
                      y->sigma,  y->G,     y->block, y->dM,    y->dC,  y->dK,  y->alone,
                      y->uf,     y->mark,  y->cidx,  y->P0,    y->dP,  y->yc,  y->Linv,
                      y->wp,     y->pptr,  y->pcol,  y->prow,  y->pk,  y->pw,  y->map,
                      y->log_at, y->log_v, y->row,   y->snext, y->inc, y->dcs, y->bfree};
    for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
        free(arrays[k]);
    free(y->L);
    free(y->b);
    free(y->z);
    free(y->w);
    pd_lcp_free(y->lemke);
    free(y);
    mj->yl = NULL;
}

/* The root of dof i's piece (path halving). */
static int find(int *uf, int i)
{
    while (uf[i] != i)
        i = uf[i] = uf[uf[i]];
    return i;
}

/* The blocks of dofs M, C, K couple (union-find over their off-diagonal
 * entries), and each dof's diagonal entries. */
static void blocks(mj_yield *y, const pd_model *md)
{
    const pd_matrix *A[3] = {&md->M, &md->C, &md->K};
    double *diag[3] = {y->dM, y->dC, y->dK};
    for (int i = 0; i < md->n; i++) {
        y->uf[i] = i;
        y->alone[i] = 1;
    }
    for (int k = 0; k < 3; k++)
        for (int j = 0; j < md->n; j++) {
            int p = -1, i;
            double v;
            while (mj_col_next(A[k], j, &p, &i, &v)) {
                if (i == j)
                    diag[k][j] += v;
                else if (v != 0.0) {
                    y->alone[i] = y->alone[j] = 0;
                    y->uf[find(y->uf, i)] = find(y->uf, j);
                }
            }
        }
    for (int i = 0; i < md->n; i++)
        y->block[i] = find(y->uf, i);
}

/* Spring j's only dof (its drift a multiple s of one dof: one nonzero in
 * S's column, dense or compressed), or -1. */
static int spring_dof(const pd_model *md, int j, double *s)
{
    int p = -1, i, dof = -1;
    double v;
    while (mj_col_next(&md->S, j, &p, &i, &v)) {
        if (v == 0.0)
            continue;
        if (dof >= 0)
            return -1;
        dof = i;
        *s = v;
    }
    return dof;
}

/* The pairs (a, b) of contacts on each spring's dof i (a one-dof spring's),
 * W_ia W_ib and D_ab's entry in the factor's D: the sliding set's
 * corrections of D_II.  0, or -1 out of memory. */
static int dof_pairs(pd_mj *mj)
{
    const mj_incidence *in = &mj->inc;
    mj_yield *y = mj->yl;
    long np = 0;
    for (int j = 0; j < y->ns; j++) {
        int i = y->sdof[j], deg = i >= 0 ? in->dptr[i + 1] - in->dptr[i] : 0;
        np += (long)deg * deg;
        y->pptr[j + 1] = (int)np;
    }
    y->pcol = pd_calloc(np, sizeof(int));
    y->prow = pd_calloc(np, sizeof(int));
    y->pk = pd_calloc(np, sizeof(long));
    y->pw = pd_calloc(np, sizeof(double));
    y->log_at = pd_calloc(np, sizeof(long));
    y->log_v = pd_calloc(np, sizeof(double));
    if (!y->pcol || !y->prow || !y->pk || !y->pw || !y->log_at || !y->log_v)
        return -1;
    for (int j = 0; j < y->ns; j++) {
        int i = y->sdof[j], p = y->pptr[j];
        for (int q1 = i >= 0 ? in->dptr[i] : 0; i >= 0 && q1 < in->dptr[i + 1]; q1++)
            for (int q2 = in->dptr[i]; q2 < in->dptr[i + 1]; q2++, p++) {
                y->pcol[p] = in->con[q1];
                y->prow[p] = in->con[q2];
                y->pk[p] = pd_factor_delassus_at(mj->factor, in->con[q1], in->con[q2]);
                y->pw[p] = in->wr[q1] * in->wr[q2];
            }
    }
    return 0;
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
    int m = md->m;
    y->up = pd_calloc(ns, sizeof(double));
    y->vfree = pd_calloc(n, sizeof(double));
    y->vel = pd_calloc(n, sizeof(double));
    y->col = pd_calloc(n, sizeof(double));
    y->ys = pd_calloc(ns, sizeof(int));
    y->sigma = pd_calloc(ns, 1);
    y->G = pd_calloc(ns, sizeof(double));
    y->block = pd_calloc(n, sizeof(int));
    y->dM = pd_calloc(n, sizeof(double));
    y->dC = pd_calloc(n, sizeof(double));
    y->dK = pd_calloc(n, sizeof(double));
    y->alone = pd_calloc(n, 1);
    y->uf = pd_calloc(n, sizeof(int));
    y->mark = pd_calloc(n, 1);
    y->cidx = pd_calloc(m, sizeof(int));
    y->P0 = pd_calloc(m, sizeof(double));
    y->dP = pd_calloc(m, sizeof(double));
    y->yc = pd_calloc(ns, sizeof(int));
    y->sdof = pd_calloc(ns, sizeof(int));
    y->sfac = pd_calloc(ns, sizeof(double));
    y->L = pd_malloc((long)MJY_CAP * MJY_CAP, sizeof(double));
    y->b = pd_malloc(MJY_CAP, sizeof(double));
    y->z = pd_malloc(MJY_CAP, sizeof(double));
    y->w = pd_malloc(MJY_CAP, sizeof(double));
    y->lemke = pd_lcp_alloc(MJY_CAP);
    y->Linv = pd_calloc(ns, sizeof(double));
    y->inc = pd_calloc(ns, sizeof(double));
    y->dcs = pd_calloc(ns, sizeof(double));
    y->bfree = pd_calloc(ns, sizeof(double));
    y->has_D = mj->factor && m > 0;
    y->map = pd_calloc(y->has_D && mj->sparse ? mj->factor->delassus_nnz : 0, sizeof(int));
    y->pptr = pd_calloc(ns + 1L, sizeof(int));
    y->wp = pd_calloc(n, sizeof(double));
    y->snext = pd_calloc(n, sizeof(int));
    y->row = pd_malloc(m, sizeof(int));
    y->hth_set = NAN;
    if (!y->up || !y->vfree || !y->vel || !y->col || !y->ys || !y->sigma || !y->G || !y->block ||
        !y->dM || !y->dC || !y->dK || !y->alone || !y->uf || !y->mark || !y->cidx || !y->P0 ||
        !y->sdof || !y->sfac || !y->dP || !y->yc || !y->L || !y->b || !y->z || !y->w || !y->lemke ||
        !y->Linv || !y->map || !y->pptr || !y->wp || !y->snext || !y->row || !y->inc || !y->dcs ||
        !y->bfree)
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for %d yielding springs", ns);
    blocks(y, md);
    if (mj_incidence_build(mj))
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for %d yielding springs", ns);
    y->all_alone = y->one_per_dof = 1;
    for (int i = 0; i < n; i++)
        y->snext[i] = -1;
    for (int a = 0; a < m; a++)
        y->row[a] = -1;
    for (int j = 0; j < ns; j++) {
        y->sdof[j] = spring_dof(md, j, &y->sfac[j]);
        y->all_alone &= y->sdof[j] >= 0 && y->alone[y->sdof[j]];
        if (y->sdof[j] >= 0) { /* two springs on one dof: Gauss-Seidel's rows only */
            y->one_per_dof &= y->snext[y->sdof[j]] < 0;
            y->snext[y->sdof[j]] = j;
        }
    }
    if (y->one_per_dof && y->has_D && dof_pairs(mj))
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for %d yielding springs", ns);
    mj->st.up = y->up;
    return PD_OK;
}

void mj_yield_reset(pd_mj *mj)
{
    if (!mj->yl)
        return;
    memset(mj->yl->up, 0, (size_t)mj->yl->ns * sizeof(double));
    memset(mj->yl->sigma, 0, (size_t)mj->yl->ns);
    mj->yl->ny_prev = mj->yl->moved = 0;
    mj->yl->set_tries = mj->yl->gs_steps = 0;
}

void mj_yield_stats(const pd_mj *mj, long *set_tries, long *gs_steps)
{
    *set_tries = mj->yl ? mj->yl->set_tries : 0;
    *gs_steps = mj->yl ? mj->yl->gs_steps : 0;
}

/* x += s S diag(ks) up (skipped while every offset is 0: an elastic step's
 * bits; then branch-free where every spring is on one dof). */
void mj_yield_force(const pd_mj *mj, double s, double *x)
{
    const pd_model *md = mj->model;
    const mj_yield *y = mj->yl;
    if (!y->moved)
        return;
    if (y->all_alone) { /* one dof each: the column's one entry, as col_axpy adds it */
        for (int j = 0; j < md->ns; j++)
            x[y->sdof[j]] += s * md->ks[j] * y->up[j] * y->sfac[j];
        return;
    }
    for (int j = 0; j < md->ns; j++) {
        if (y->up[j] == 0.0)
            continue;
        double a = s * md->ks[j] * y->up[j];
        if (y->sdof[j] >= 0) /* one dof: the column's one entry, as col_axpy adds it */
            x[y->sdof[j]] += a * y->sfac[j];
        else
            pd_matrix_col_axpy(&md->S, j, a, x);
    }
}

/* z+_j of the step's end state (out->q holds q + h (1 - theta) v). */
static double z_end(const pd_mj *mj, const pd_state *out, double hth, int j)
{
    const pd_model *md = mj->model;
    return pd_matrix_col_dot(&md->S, j, out->q) + hth * pd_matrix_col_dot(&md->S, j, out->v) -
           mj->yl->up[j];
}

/* z+ of spring j alone on one dof with that dof's end velocity vi: s (q1 +
 * h theta vi) - up, q1 = q + h (1 - theta) v. */
static double z_one(const mj_yield *y, int j, double hth, const double *q1, double vi)
{
    return y->sfac[j] * (q1[y->sdof[j]] + hth * vi) - y->up[j];
}

/* The springs past uy after a solve: join Y on their side (a member past
 * the other side turns).  1 when Y changed. */
static int grow(pd_mj *mj, const pd_state *out, double hth, int *ny)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    const int *sdof = y->sdof;
    const double *uy = md->uy, *q1 = out->q, *v = out->v;
    int changed = 0;
    for (int j = 0; j < md->ns; j++) {
        int i = sdof[j]; /* one dof: z+ without a walk of S */
        double zj = i >= 0 ? z_one(y, j, hth, q1, v[i]) : z_end(mj, out, hth, j),
               lim = uy[j] * (1.0 + MJY_SLACK);
        /* a member's z+ is sigma uy at most; beyond -sigma uy it turns
         * (branch-free: the springs in Y sit on their level) */
        int side = (zj > lim) - (zj < -lim);
        if (!(side != 0 && side != y->sigma[j]))
            continue;
        if (y->sigma[j] == 0)
            y->ys[(*ny)++] = j;
        y->sigma[j] = (signed char)side;
        y->G[j] = 0.0;
        changed = 1;
    }
    return changed;
}

/* The pieces of the step: the blocks joined by the active contacts; mark
 * bit 1: a contact in the piece, 4: a spring of Y on it, 8: two or more. */
static void pieces(const pd_mj *mj, int nI)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    for (int i = 0; i < md->n; i++) {
        y->uf[i] = y->block[i];
        y->mark[i] = 0;
    }
    for (int c = 0; c < nI; c++) {
        int a = mj->idx_active[c], p = -1, i, first = -1;
        double v;
        while (mj_col_next(&md->W, a, &p, &i, &v))
            if (first < 0)
                first = find(y->uf, i);
            else
                y->uf[find(y->uf, i)] = first;
    }
    for (int c = 0; c < nI; c++) {
        int p = -1, i;
        double v;
        if (mj_col_next(&md->W, mj->idx_active[c], &p, &i, &v))
            y->mark[find(y->uf, i)] |= 1;
    }
}

/* Y split: the springs alone on a one-dof piece without a contact (closed
 * form) and the coupled ones (y->yc, *nyc), and the contacts of the coupled
 * springs' pieces (y->cidx, *nc, increasing as idx_active). */
static void classify(pd_mj *mj, int nI, int ny, int *nyc, int *nc)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    double s;
    for (int k = 0; k < ny; k++) { /* how many springs of Y on each piece */
        int j = y->ys[k], i = y->sdof[j], p = -1, r;
        if (i < 0 && !mj_col_next(&md->S, j, &p, &i, &s))
            continue; /* no entry: it cannot slide */
        r = find(y->uf, i);
        y->mark[r] |= y->mark[r] & 4 ? 8 : 4;
    }
    *nyc = *nc = 0;
    for (int k = 0; k < ny; k++) {
        int j = y->ys[k], i = y->sdof[j];
        if (i >= 0 && y->alone[i] && y->mark[find(y->uf, i)] == 4)
            continue; /* alone: the closed form */
        y->yc[(*nyc)++] = j;
        int p = -1;
        double v;
        while (mj_col_next(&md->S, j, &p, &i, &v))
            y->mark[find(y->uf, i)] |= 2;
    }
    for (int c = 0; c < nI; c++) {
        int p = -1, i;
        double v;
        if (mj_col_next(&md->W, mj->idx_active[c], &p, &i, &v) && y->mark[find(y->uf, i)] & 2)
            y->cidx[(*nc)++] = mj->idx_active[c];
    }
}

/* The dense LCP of the coupled contacts (nc) and springs (nyc) into y->L
 * (column-major), y->b; q1 = q + h (1 - theta) v. */
static void build(pd_mj *mj, const pd_factor *f, int nc, int nyc, double hth, const double *q1)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    int N = nc + nyc;
    /* contacts: D_CC (written at ld nc, then widened to ld N in place, back
     * to front: no entry is overwritten before it moves) and W_C^T vfree + e U */
    if (nc > 0) {
        pd_factor_delassus_dense(f, y->cidx, nc, y->L);
        for (int c = nc - 1; c >= 0; c--)
            for (int r = nc - 1; r >= 0; r--)
                y->L[(size_t)c * N + r] = y->L[(size_t)c * nc + r];
        for (int c = 0; c < nc; c++) {
            int a = y->cidx[c];
            y->b[c] = pd_matrix_col_dot(&md->W, a, y->vfree) + md->e[a] * mj->U0[a];
        }
    }
    /* each spring k: the column What^-1 S_j gives its couplings */
    for (int k = 0; k < nyc; k++) {
        int j = y->yc[k];
        double sk = y->sigma[j], ks = md->ks[j];
        memset(y->col, 0, (size_t)md->n * sizeof(double));
        pd_matrix_col_axpy(&md->S, j, 1.0, y->col);
        pd_factor_solve(f, y->col);
        for (int c = 0; c < nc; c++) { /* P's velocity on z, G's on the contacts */
            double d = hth * sk * ks * pd_matrix_col_dot(&md->W, y->cidx[c], y->col);
            y->L[(size_t)(nc + k) * N + c] = d;
            y->L[(size_t)c * N + nc + k] = -d;
        }
        for (int l = 0; l < nyc; l++) { /* row l (spring jl) of column k, scaled by ks_jl */
            int jl = y->yc[l];
            double d = pd_matrix_col_dot(&md->S, jl, y->col);
            y->L[(size_t)(nc + k) * N + nc + l] =
                (l == k ? md->ks[jl] : 0.0) - hth * hth * y->sigma[jl] * sk * md->ks[jl] * ks * d;
        }
        /* ks (uy - sigma z_free), z_free the end state with the free velocity */
        y->b[nc + k] =
            ks * (md->uy[j] - sk * (pd_matrix_col_dot(&md->S, j, q1) +
                                    hth * pd_matrix_col_dot(&md->S, j, y->vfree) - y->up[j]));
    }
}

/* The dense LCP's answer on out: the coupled contacts' impulses (their
 * change from the elastic pass's through What^-1 W), the coupled springs'
 * slides through What^-1 S ks sigma G. */
static void apply(pd_mj *mj, const pd_factor *f, int nc, int nyc, double hth, pd_state *out)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    for (int c = 0; c < nc; c++) {
        int a = y->cidx[c];
        y->dP[c] = y->z[c] - out->P[a];
        out->P[a] = y->z[c];
    }
    pd_factor_add_impulse(f, y->cidx, nc, y->dP, out->v);
    memset(y->col, 0, (size_t)md->n * sizeof(double));
    for (int k = 0; k < nyc; k++) {
        int j = y->yc[k];
        y->G[j] = y->z[nc + k];
        pd_matrix_col_axpy(&md->S, j, hth * y->sigma[j] * md->ks[j] * y->G[j], y->col);
    }
    pd_factor_solve(f, y->col);
    for (int i = 0; i < md->n; i++)
        out->v[i] += y->col[i];
}

/* The slide's L = ks - (h theta)^2 ks^2 s^2 / What_ii (its 1 / L), its
 * velocity per unit slide and added compliance, of each spring on one dof
 * (read for the springs alone on theirs), at h theta (kept while it holds). */
static void set_constants(mj_yield *y, const pd_model *md, double hth)
{
    if (y->hth_set == hth)
        return;
    for (int j = 0; j < md->ns; j++) {
        int i = y->sdof[j];
        if (i < 0)
            continue;
        double s = y->sfac[j], ks = md->ks[j];
        double what = y->dM[i] + hth * (y->dC[i] + hth * y->dK[i]), r = hth * hth * ks * s * s;
        y->Linv[j] = 1.0 / (ks - hth * hth * ks * ks * s * s / what);
        y->inc[j] = hth * ks * s / what;
        /* 1 / (What_ii - (h theta)^2 ks s^2) - 1 / What_ii: the post-yield What is
         * positive (k - ks s^2 >= 0) */
        y->dcs[j] = r / (what * (what - r));
    }
    y->hth_set = hth;
}

/* b = ks (uy - sigma z) of spring j, z of the end state with its dof's
 * velocity vi (its own slide left out); q1 = q + h (1 - theta) v. */
static inline double slide_b(const pd_model *md, const mj_yield *y, int j, double hth,
                             const double *q1, double vi)
{
    return md->ks[j] * (md->uy[j] - y->sigma[j] * z_one(y, j, hth, q1, vi));
}

/* The springs alone on their dof (classify's others): the 1 x 1 LCP
 * G = max(0, -b / L), L = ks (1 - (h theta)^2 ks s^2 / What_ii), in closed
 * form, on out->v[i] (= vfree: no contact in its piece). */
static void slide_alone(pd_mj *mj, int ny, double hth, pd_state *out)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    for (int k = 0; k < ny; k++) {
        int j = y->ys[k], i = y->sdof[j];
        if (i < 0 || !y->alone[i] || y->mark[find(y->uf, i)] != 4)
            continue;
        double b = slide_b(md, y, j, hth, out->q, y->vfree[i]);
        y->G[j] = b < 0.0 ? -b * y->Linv[j] : 0.0;
        out->v[i] = y->vfree[i] + y->sigma[j] * y->inc[j] * y->G[j];
    }
}

/* 1 when every spring of Y is alone on its dof (block Gauss-Seidel's case). */
static int all_alone(const mj_yield *y, int ny)
{
    for (int k = 0; k < ny; k++) {
        int i = y->sdof[y->ys[k]];
        if (i < 0 || !y->alone[i])
            return 0;
    }
    return 1;
}

/* Block Gauss-Seidel over the springs (each alone on its dof) and the
 * active contacts, from out->v = vfree with the slides G of Y: the
 * contacts' LCP given the slides' velocity, then each slide in closed form
 * given the contacts' and the others' velocity; a spring left past uy joins
 * Y (G = 0); until no slide moves by MJY_GS_TOL of its uy and none joins.
 * With Y empty the first sweep is the elastic step, bit for bit. */
static int slide_gs(pd_mj *mj, const pd_factor *f, int nI, int *ny, double hth, double t1,
                    pd_state *out, pd_err *err)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    int rc;
    for (int it = 0; it < MJY_GS_MAX; it++) {
        if (it > 0 || *ny > 0) { /* the slides' velocity on vfree */
            memcpy(out->v, y->vfree, (size_t)md->n * sizeof(double));
            for (int k = 0; k < *ny; k++) {
                int j = y->ys[k];
                out->v[y->sdof[j]] += y->sigma[j] * y->inc[j] * y->G[j];
            }
        }
        if (nI > 0 && (rc = mj_contacts_apply(mj, f, nI, it > 0, t1, out, err)))
            return rc;
        double moved = 0.0;
        for (int k = 0; k < *ny; k++) { /* each slide given the rest */
            int j = y->ys[k], i = y->sdof[j];
            double inc = y->sigma[j] * y->inc[j];
            double vi = out->v[i] - inc * y->G[j]; /* without its own slide */
            double b = slide_b(md, y, j, hth, out->q, vi);
            double G = b < 0.0 ? -b * y->Linv[j] : 0.0;
            moved = fmax(moved, fabs(G - y->G[j]) / md->uy[j]);
            y->G[j] = G;
            out->v[i] = vi + inc * G;
        }
        if (!grow(mj, out, hth, ny) && moved <= MJY_GS_TOL)
            return PD_OK;
    }
    return pd_err_set(err, PD_ENUMERICAL,
                      "Moreau-Jean: the slides of %d springs and %d contacts did not settle in "
                      "%d sweeps at t = %.9g",
                      *ny, nI, MJY_GS_MAX, t1);
}

/* ---- rows of SDOFs: the sliding set in the contacts' LCP ---------------- */

/* This step's active rows of the contacts (row), or -1 for all again (clear). */
static void set_rows(pd_mj *mj, int nI, int clear)
{
    mj_yield *y = mj->yl;
    for (int r = 0; r < nI; r++)
        y->row[mj->idx_active[r]] = clear ? -1 : r;
}

/* Contact a's active row this step, or -1. */
static int active_row(const pd_mj *mj, int a)
{
    return mj->yl->row[a];
}

/* Whether an active contact pushes on dof i. */
static int pushed(const pd_mj *mj, const pd_state *out, int i)
{
    for (int q = mj->inc.dptr[i]; q < mj->inc.dptr[i + 1]; q++)
        if (out->P[mj->inc.con[q]] > 0.0) /* (an inactive contact's is 0) */
            return 1;
    return 0;
}

/* Whether every active contact on dof i keeps w = W^T v+ + e U >= 0. */
static int contacts_hold(const pd_mj *mj, int i, const double *v)
{
    const pd_model *md = mj->model;
    for (int q = mj->inc.dptr[i]; q < mj->inc.dptr[i + 1]; q++) {
        int a = mj->inc.con[q];
        if (active_row(mj, a) >= 0 && mj_inc_dot(&mj->inc, a, v) + md->e[a] * mj->U0[a] < 0.0)
            return 0;
    }
    return 1;
}

/* Pair p of a spring's dof (contacts in D_II's column col and row row, both
 * active) corrected by dc: D_ab += W_ia W_ib dc at its place (dense, or
 * through the map), the entry as it was logged for the next try.  0, or 1
 * when the entry falls outside D's pattern. */
static inline int correct_pair(pd_mj *mj, mj_yield *y, int p, int col, int row, int nI, double dc)
{
    long at = !mj->sparse ? row + (long)col * nI : y->pk[p] < 0 ? -1 : y->map[y->pk[p]];
    if (at < 0)
        return 1;
    y->log_at[y->nlog] = at;
    y->log_v[y->nlog++] = mj->D_active[at];
    mj->D_active[at] += y->pw[p] * dc;
    return 0;
}

/* D_II corrected on the sliding dofs: D_ab += W_ia W_ib dc_j over the
 * pairs of active contacts on spring j's dof i (pairs in the order of the
 * dof's contacts, pptr[j] + u deg + v): a dof of two contacts (a row's)
 * reads their two rows once.  0, or 1 when an entry falls outside D's
 * pattern (Gauss-Seidel then). */
static int set_delassus(pd_mj *mj, int nI, int ny)
{
    mj_yield *y = mj->yl;
    const mj_incidence *in = &mj->inc;
    for (int k = 0; k < ny; k++) {
        int j = y->ys[k], i = y->sdof[j], p0 = y->pptr[j], q0 = in->dptr[i];
        int deg = in->dptr[i + 1] - q0, bad = 0;
        double dc = y->dcs[j];
        if (deg == 2) { /* (a, a), (a, b), (b, a), (b, b) of the rows ra, rb */
            int ra = y->row[in->con[q0]], rb = y->row[in->con[q0 + 1]];
            if (ra >= 0)
                bad |= correct_pair(mj, y, p0, ra, ra, nI, dc);
            if (ra >= 0 && rb >= 0)
                bad |= correct_pair(mj, y, p0 + 1, ra, rb, nI, dc) |
                       correct_pair(mj, y, p0 + 2, rb, ra, nI, dc);
            if (rb >= 0)
                bad |= correct_pair(mj, y, p0 + 3, rb, rb, nI, dc);
        } else
            for (int p = p0; p < y->pptr[j + 1]; p++) {
                int col = y->row[y->pcol[p]], row = y->row[y->prow[p]];
                if (col >= 0 && row >= 0)
                    bad |= correct_pair(mj, y, p, col, row, nI, dc);
            }
        if (bad)
            return 1;
    }
    return 0;
}

/* A sliding spring j's constant part on its dof i's v (from vfree):
 * -sigma inc b / L; no push yet. */
static inline void slide_free(mj_yield *y, int j, int i, double *v)
{
    v[i] -= y->sigma[j] * y->inc[j] * y->bfree[j] * y->Linv[j];
    y->wp[i] = 0.0;
}

/* The sliding set's start, from the springs that slid in the last step
 * (ys, *ny; out->v = vfree): each stays in Y where the last step's push on
 * its dof would leave it sliding (b = bfree - sigma inc (W_I P)_i <= 0),
 * its constant part on out->v; the others leave. */
static void slide_start(pd_mj *mj, int *ny, double hth, pd_state *out)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    int kept = 0;
    for (int k = 0; k < *ny; k++) {
        int j = y->ys[k], i = y->sdof[j];
        y->bfree[j] = slide_b(md, y, j, hth, out->q, y->vfree[i]);
        if (y->bfree[j] - y->sigma[j] * y->inc[j] * y->wp[i] <= 0.0) {
            y->ys[kept++] = j;
            slide_free(y, j, i, out->v);
        } else
            y->sigma[j] = 0;
    }
    *ny = kept;
}

/* The contacts' LCP with the slides of Y taken as sliding (each G solved
 * for and put in): a sliding dof starts from vfree_i - sigma inc b / L and
 * answers an impulse with the post-yield compliance; then v+ on out->v and
 * (W_I P)_i of each sliding dof in y->wp.  The Delassus block is built at
 * the first call of a step (*built), its entries that a try changes put
 * back at the next (the log); with Y empty the
 * step's contacts are the elastic step's, bit for bit.  0, 1 (Gauss-Seidel
 * takes the step), or an error. */
static int set_contacts(pd_mj *mj, const pd_factor *f, int nI, int ny, double hth, double t1,
                        int first, int *built, pd_state *out, pd_err *err)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    /* the step's first try: out->v and bfree as slide_start left them */
    int rc;
    if (!first)
        memcpy(out->v, y->vfree, (size_t)md->n * sizeof(double));
    for (int k = 0; k < ny && !first; k++) { /* the slides' constant parts (slide_start's) */
        int j = y->ys[k], i = y->sdof[j];
        y->bfree[j] = slide_b(md, y, j, hth, out->q, y->vfree[i]);
        slide_free(y, j, i, out->v);
    }
    if (nI == 0)
        return PD_OK;
    if (!*built) { /* D_II as the factor gives it (and where D's entries went) */
        if (mj->sparse)
            pd_factor_delassus_csc(f, mj->idx_active, nI, mj->D_colptr, mj->D_rowind, mj->D_active,
                                   y->map);
        else
            pd_factor_delassus_dense(f, mj->idx_active, nI, mj->D_active);
        y->nlog = 0;
        *built = 1;
    }
    while (y->nlog > 0) { /* a later try: the entries the last one changed, back */
        y->nlog--;
        mj->D_active[y->log_at[y->nlog]] = y->log_v[y->nlog];
    }
    if (ny == 0) /* no slide: the elastic step's contacts */
        return mj_contacts_apply(mj, f, nI, 1, t1, out, err);
    if (set_delassus(mj, nI, ny))
        return 1;
    mj_active_rhs(mj, nI, out->v);
    if ((rc = mj_impact_active(mj, nI, t1, out, err)))
        return rc;
    pd_factor_add_impulse(f, mj->idx_active, nI, mj->P_active, out->v);
    for (int k = 0; k < ny; k++) { /* the sliding dofs' extra compliance */
        int j = y->ys[k], i = y->sdof[j];
        double s = 0.0; /* out->P: the active contacts' impulses, the others' 0 */
        for (int q = mj->inc.dptr[i]; q < mj->inc.dptr[i + 1]; q++)
            s += mj->inc.wr[q] * out->P[mj->inc.con[q]];
        y->wp[i] = s;
        out->v[i] += y->dcs[j] * s;
    }
    return PD_OK;
}

/* Spring j's slide where no contact pushes on its dof: G in closed form
 * from vfree (the contacts give nothing there), its dof's v+ with it (G =
 * 0 and out of Y when it would be negative).  1 when the active contacts
 * on the dof still hold (else the contacts' LCP must take the change). */
static int slide_unpushed(pd_mj *mj, int j, double hth, pd_state *out)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    int i = y->sdof[j];
    double G = y->sigma[j] ? -slide_b(md, y, j, hth, out->q, y->vfree[i]) * y->Linv[j] : 0.0;
    y->G[j] = G > 0.0 ? G : 0.0;
    if (!(G > 0.0))
        y->sigma[j] = 0;
    out->v[i] = y->vfree[i] + y->sigma[j] * y->inc[j] * y->G[j];
    y->wp[i] = 0.0; /* no contact pushes on the dof */
    return contacts_hold(mj, i, out->v);
}

/* The sliding set's iteration (every spring alone on its dof, one a dof):
 * from Y (the last step's slides), the contacts' LCP with Y sliding
 * (set_contacts), then each G = -(b - beta (W_I P)_i) / L: a negative one
 * leaves Y, a spring past uy joins it (grow).  A change on a dof where no
 * contact pushes is made there (slide_unpushed: the others' impulses stay
 * a solution while that dof's contacts hold); any other takes the LCP
 * again, until nothing changes.  0, 1 when MJY_SET_MAX tries do not settle
 * it (Gauss-Seidel then), or an error.  The active rows are set (set_rows). */
static int slide_tries(pd_mj *mj, const pd_factor *f, int nI, int *ny, double hth, double t1,
                       pd_state *out, pd_err *err)
{
    mj_yield *y = mj->yl;
    int built = 0, rc;
    for (int it = 0; it < MJY_SET_MAX; it++) {
        y->set_tries++;
        if ((rc = set_contacts(mj, f, nI, *ny, hth, t1, it == 0, &built, out, err)))
            return rc;
        int kept = 0, again = 0;
        for (int k = 0; k < *ny; k++) {
            int j = y->ys[k], i = y->sdof[j];
            double b = y->bfree[j] - y->sigma[j] * y->inc[j] * y->wp[i];
            y->G[j] = -b * y->Linv[j];
            if (y->G[j] >= 0.0) {
                y->ys[kept++] = j;
                continue;
            }
            y->sigma[j] = 0; /* it does not slide: out of Y (G read for Y only) */
            if (pushed(mj, out, i))
                again = 1;
            else
                again |= !slide_unpushed(mj, j, hth, out);
        }
        int ny0 = *ny = kept;
        if (!again && grow(mj, out, hth, ny)) {
            kept = 0; /* the joined (G = 0 from grow) and the turned */
            for (int k = 0; k < *ny; k++) {
                int j = y->ys[k], i = y->sdof[j];
                if ((k >= ny0 || y->G[j] == 0.0) && !again) {
                    if (pushed(mj, out, i))
                        again = 1;
                    else
                        again |= !slide_unpushed(mj, j, hth, out);
                }
                if (y->sigma[j])
                    y->ys[kept++] = j;
            }
            *ny = kept;
        }
        if (!again)
            return PD_OK;
    }
    return 1;
}

/* slide_start and slide_tries with this step's active rows (cleared
 * after). */
static int slide_set(pd_mj *mj, const pd_factor *f, int nI, int *ny, double hth, double t1,
                     pd_state *out, pd_err *err)
{
    set_rows(mj, nI, 0);
    slide_start(mj, ny, hth, out);
    int rc = slide_tries(mj, f, nI, ny, hth, t1, out, err);
    set_rows(mj, nI, 1);
    return rc;
}

int mj_yield_step(pd_mj *mj, const pd_factor *f, double h, int nI, double t1, pd_state *out,
                  pd_err *err)
{
    const pd_model *md = mj->model;
    mj_yield *y = mj->yl;
    double hth = h * mj->opts.theta;
    int rc, ny = 0;
    memcpy(y->vfree, out->v, (size_t)md->n * sizeof(double));
    set_constants(y, md, hth);
    if (y->all_alone && mj->opts.yield_lcp_max <= 0) { /* rows of SDOFs */
        /* its start: the springs that slid in the last step, with their slides */
        ny = y->ny_prev;
        rc = mj->opts.yield_lcp_max == 0 && y->one_per_dof && (y->has_D || md->m == 0)
                 ? slide_set(mj, f, nI, &ny, hth, t1, out, err)
                 : 1;
        if (rc > 0) { /* not settled: Gauss-Seidel from vfree and the slides found */
            y->gs_steps++;
            memcpy(out->v, y->vfree, (size_t)md->n * sizeof(double));
            rc = slide_gs(mj, f, nI, &ny, hth, t1, out, err);
        }
        if (rc)
            return rc;
        int slid = 0;
        for (int k = 0; k < ny; k++) {
            int j = y->ys[k];
            y->up[j] += y->sigma[j] * y->G[j];
            y->moved |= y->G[j] > 0.0;
            if (y->G[j] > 0.0) /* kept for the next step's start, in order */
                y->ys[slid++] = j;
            else
                y->sigma[j] = 0;
        }
        y->ny_prev = slid;
        return PD_OK;
    }
    memset(y->sigma, 0, (size_t)md->ns);
    /* the elastic step first: the contacts alone */
    if (nI > 0 && (rc = mj_contacts_apply(mj, f, nI, 0, t1, out, err)))
        return rc;
    for (int round = 0; grow(mj, out, hth, &ny); round++) {
        int nyc, nc;
        if (round == 0) { /* the elastic pass, each round's start */
            memcpy(y->vel, out->v, (size_t)md->n * sizeof(double));
            for (int c = 0; c < nI; c++)
                y->P0[c] = out->P[mj->idx_active[c]];
        } else {
            memcpy(out->v, y->vel, (size_t)md->n * sizeof(double));
            for (int c = 0; c < nI; c++)
                out->P[mj->idx_active[c]] = y->P0[c];
        }
        pieces(mj, nI);
        classify(mj, nI, ny, &nyc, &nc);
        int N = nc + nyc, cap = mj->opts.yield_lcp_max > 0 && mj->opts.yield_lcp_max < MJY_CAP
                                    ? mj->opts.yield_lcp_max
                                    : MJY_CAP;
        if (N > cap && round <= md->ns && all_alone(y, ny)) {
            memcpy(out->v, y->vfree, (size_t)md->n * sizeof(double));
            for (int k = 0; k < ny; k++)
                y->G[y->ys[k]] = 0.0;
            if ((rc = slide_gs(mj, f, nI, &ny, hth, t1, out, err)))
                return rc;
            break; /* settled: no spring past uy */
        }
        if (N > cap || round > md->ns)
            return pd_err_set(err, PD_EBUDGET,
                              "Moreau-Jean: %d contacts and %d sliding springs coupled at t = "
                              "%.9g (at most %d in one LCP, %d rounds; newmark runs it)",
                              nc, nyc, t1, cap, md->ns + 1);
        if (N > 0 && nyc > 0) {
            build(mj, f, nc, nyc, hth, out->q); /* out->q: q + h (1 - theta) v */
            pd_lcp_opts lo = pd_lcp_default_opts();
            pd_lcp_info info;
            if ((rc = pd_lcp_lemke(y->lemke, N, y->L, y->b, &lo, y->z, y->w, &info)))
                return pd_err_set(err, rc,
                                  "Moreau-Jean: the LCP of %d contacts and %d sliding springs "
                                  "not solved at t = %.9g: %s",
                                  nc, nyc, t1, pd_lcp_outcome_name(info.outcome));
            y->rounds++;
            out->lcp_pivots += info.pivots;
            out->lcp_solver = "lemke";
            apply(mj, f, nc, nyc, hth, out);
        }
        slide_alone(mj, ny, hth, out);
    }
    /* the offsets move by sigma G */
    for (int k = 0; k < ny; k++) {
        y->up[y->ys[k]] += y->sigma[y->ys[k]] * y->G[y->ys[k]];
        y->moved |= y->G[y->ys[k]] > 0.0;
    }
    return PD_OK;
}
