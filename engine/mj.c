/* mj.c — Moreau–Jean theta time-stepping (SPEC §2).
 *
 *   What  = M + h theta C + h^2 theta^2 K                       (factored once)
 *   vfree = v_k + What^-1 h [F_theta - C v_k - K (q_k + h theta v_k)]
 *   I     = { a : g_a(q_k) + h gamma U_a(v_k) <= 0 },  U = W^T v
 *   LCP:  w = D P + W_I^T vfree + e U_k,  D = W_I^T What^-1 W_I,  0 <= w ⊥ P >= 0
 *   v_k+1 = vfree + What^-1 W_I P,   q_k+1 = q_k + h [theta v_k+1 + (1-theta) v_k]
 *
 * Two kernels share these equations: a scalar one for n = 1, m <= 1 (one
 * oscillator, one wall: plain doubles, closed-form scalar LCP) and a general
 * one (the factorisation seam of pd_factor.h, Delassus blocks dense or in
 * compressed columns as the factor kind keeps them, the LCP solver table). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mj.h"
#include "pd_alloc.h"
#include "pd_null.h"

/* A dense active LCP is refined when its D P cancels terms this many times
 * larger than b (half the digits lost), until the Newton residual of its
 * velocities, formed through the factor, is within MJ_REFINE_TOL roundings
 * (DBL_EPSILON) of its terms (1e-12 relative: the basis vectors' rounding
 * times the light dofs' What^-1 leaves tens), in at most MJ_REFINE_MAX
 * steps. */
#define MJ_REFINE_GROWTH 1e8
#define MJ_REFINE_TOL 4096.0
#define MJ_REFINE_MAX 8
#define MJ_REFINE_NMAX 64 /* pushing contacts a refinement takes (2 n of memory each) */

pd_mj_opts pd_mj_default_opts(void)
{
    return (pd_mj_opts){.h = 0.0,     /* no default: check_opts refuses h <= 0 */
                        .theta = 0.5, /* the trapezoidal rule: second order, energy kept */
                        .gamma = 0.5, /* the active set looks half a step ahead */
                        .allow_unstable = 0,
                        .kernel = PD_KERNEL_AUTO,
                        .factor = PD_FACTOR_AUTO,
                        .lcp_solver = PD_LCP_AUTO,
                        .on_lcp = NULL,
                        .on_lcp_ctx = NULL,
                        .rtol = 0.0, /* fixed steps */
                        .atol = 1e-12,
                        .atol_dof = NULL,
                        .max_level = PD_MJ_MAX_LEVEL, /* finest step h 2^-48 */
                        .max_evals = 1e9,
                        .sim_gap = 1e-10,
                        .yield_lcp_max = 0,
                        .pieces = NULL};
}

/* Closed-form scalar LCP  w = D P + b >= 0, P >= 0, wP = 0  (D > 0). */
double pd_contact_impulse_1(double D, double b)
{
    return b < 0.0 ? -b / D : 0.0; /* b >= 0: P = 0, w = b; else w = 0 */
}

/* The pairs' form of the incidence when no contact acts on more than two
 * dofs (mj_inc_dot's two terms). */
static int incidence_pairs(mj_incidence *in, int m)
{
    for (int a = 0; a < m; a++)
        if (in->ptr[a + 1] - in->ptr[a] > 2)
            return PD_OK;
    if (!(in->pair = pd_calloc(2 * (long)m, sizeof(int))) ||
        !(in->pw = pd_calloc(2 * (long)m, sizeof(double))))
        return PD_ENOMEM;
    for (int a = 0; a < m; a++)
        for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++) {
            in->pair[2 * a + j - in->ptr[a]] = in->dof[j];
            in->pw[2 * a + j - in->ptr[a]] = in->w[j];
        }
    return PD_OK;
}

/* W by columns (its nonzeros) and by rows (mj->inc), once for the drivers
 * that read it (the adaptive one, the yielding springs'): PD_OK, or
 * PD_ENOMEM (what was taken is freed with the object). */
int mj_incidence_build(pd_mj *mj)
{
    const pd_model *md = mj->model;
    mj_incidence *in = &mj->inc;
    int n = md->n, m = md->m, nnz = 0;
    double wia;
    if (in->ptr)
        return PD_OK; /* built */
    if (!(in->ptr = calloc((size_t)m + 1, sizeof(int))) ||
        !(in->dptr = calloc((size_t)n + 1, sizeof(int))))
        return PD_ENOMEM;
    for (int a = 0; a < m; a++)
        for (int p = -1, i; mj_col_next(&md->W, a, &p, &i, &wia);)
            if (wia != 0.0) {
                nnz++;
                in->dptr[i + 1]++;
            }
    /* W's nonzeros counted, per dof in dptr[i + 1]: by columns, then by rows */
    if (!(in->dof = pd_malloc(nnz, sizeof(int))) || !(in->w = pd_malloc(nnz, sizeof(double))) ||
        !(in->con = pd_malloc(nnz, sizeof(int))) || !(in->wr = pd_malloc(nnz, sizeof(double))))
        return PD_ENOMEM;
    /* the running sum: dptr[i] is dof i's first contact */
    for (int i = 0; i < n; i++)
        in->dptr[i + 1] += in->dptr[i];
    /* fill[i]: the contacts dof i has so far */
    int *fill = calloc((size_t)n, sizeof(int));
    if (!fill)
        return PD_ENOMEM;
    nnz = 0;
    for (int a = 0; a < m; a++) {
        in->ptr[a] = nnz;
        for (int p = -1, i; mj_col_next(&md->W, a, &p, &i, &wia);) {
            if (wia == 0.0)
                continue;
            in->dof[nnz] = i;
            in->w[nnz++] = wia;
            in->con[in->dptr[i] + fill[i]] = a;
            in->wr[in->dptr[i] + fill[i]++] = wia;
        }
    }
    in->ptr[m] = nnz;
    free(fill);
    return incidence_pairs(in, m);
}

static void incidence_free(mj_incidence *in)
{
    free(in->ptr);
    free(in->dof);
    free(in->w);
    free(in->dptr);
    free(in->con);
    free(in->wr);
    free(in->pair);
    free(in->pw);
    memset(in, 0, sizeof *in);
}

void pd_mj_free(pd_mj *mj)
{
    if (!mj)
        return;
    mj_adapt_free(mj);
    mj_yield_free(mj);
    incidence_free(&mj->inc);
    pd_factor_free(mj->factor);
    pd_lcp_solver_free(mj->lcp);
    free(mj->F0);
    free(mj->F1);
    free(mj->work_n);
    free(mj->qtheta);
    free(mj->U0);
    free(mj->D_active);
    free(mj->D_colptr);
    free(mj->D_rowind);
    free(mj->b_active);
    free(mj->P_active);
    free(mj->w_active);
    free(mj->idx_active);
    free(mj->ref_R);
    free(mj->ref_res);
    free(mj->ref_perm);
    free(mj->guess);
    free(mj->st_own.q);
    free(mj->st_own.v);
    free(mj->st_own.P);
    free(mj->st_own.g);
    free(mj->st_own.active);
    free(mj);
}

/* Options in range: h > 0 finite, theta in [1/2, 1] unless allowed. */
int pd_mj_check_opts(const pd_mj_opts *o, pd_err *err)
{
    if (!(o->h > 0.0) || !isfinite(o->h))
        return pd_err_set(err, PD_EINVAL, "dt must be a finite number > 0 (got %g)", o->h);
    if (!isfinite(o->theta) || o->theta < 0.0 || o->theta > 2.0)
        return pd_err_set(err, PD_EINVAL, "theta must be in [0, 2] (got %g)", o->theta);
    /* theta < 1/2: |R|^2 = (1 + (1-theta)^2 Om^2) / (1 + theta^2 Om^2) > 1 at every h */
    if ((o->theta < 0.5 || o->theta > 1.0) && !o->allow_unstable)
        return pd_err_set(err, PD_EINVAL,
                          "theta = %g is outside [1/2, 1], where the scheme is not unconditionally "
                          "stable (pass --allow-unstable to run it anyway)",
                          o->theta);
    if (!(o->gamma >= 0.0 && o->gamma <= 1.0))
        return pd_err_set(err, PD_EINVAL, "gamma must be in [0, 1] (got %g)", o->gamma);
    if (!(o->rtol >= 0.0 && o->rtol < 1.0))
        return pd_err_set(err, PD_EINVAL, "rtol must be in [0, 1) (0: fixed steps; got %g)",
                          o->rtol);
    if (o->yield_lcp_max < -1)
        return pd_err_set(err, PD_EINVAL,
                          "yield_lcp_max must be >= -1 (0: 512, -1: Gauss-Seidel; got %d)",
                          o->yield_lcp_max);
    /* the adaptive driver's options, read only when it runs */
    if (o->rtol > 0.0) {
        if (!(o->atol > 0.0) || !isfinite(o->atol))
            return pd_err_set(err, PD_EINVAL, "atol must be a finite number > 0 (got %g)", o->atol);
        if (o->max_level < 1 || o->max_level > PD_MJ_MAX_LEVEL)
            return pd_err_set(err, PD_EINVAL, "max_level must be in [1, %d] (got %d)",
                              PD_MJ_MAX_LEVEL, o->max_level);
        if (!(o->max_evals >= 1.0))
            return pd_err_set(err, PD_EINVAL, "max_evals must be >= 1 (got %g)", o->max_evals);
        if (!(o->sim_gap >= 0.0) || !isfinite(o->sim_gap))
            return pd_err_set(err, PD_EINVAL, "sim_gap must be a finite number >= 0 (got %g)",
                              o->sim_gap);
    }
    return PD_OK;
}

/* Every array, sized once for (n, m). */
static int alloc_arrays(pd_mj *mj, int n, int m)
{
    mj->F0 = calloc((size_t)n, sizeof(double));
    mj->F1 = calloc((size_t)n, sizeof(double));
    mj->work_n = calloc((size_t)n, sizeof(double));
    mj->qtheta = calloc((size_t)n, sizeof(double));
    /* the contacts' arrays: one element when m = 0, so that NULL means out of memory */
    mj->U0 = pd_calloc(m, sizeof(double));
    mj->b_active = pd_calloc(m, sizeof(double));
    mj->P_active = pd_calloc(m, sizeof(double));
    mj->w_active = pd_calloc(m, sizeof(double));
    mj->idx_active = pd_calloc(m, sizeof(int));
    mj->st.q = calloc((size_t)n, sizeof(double));
    mj->st.v = calloc((size_t)n, sizeof(double));
    mj->st.P = pd_calloc(m, sizeof(double));
    mj->st.g = pd_calloc(m, sizeof(double));
    mj->st.active = pd_calloc(m, 1);
    mj->st_own = mj->st; /* freed through st_own: the adaptive driver repoints st */
    return mj->F0 && mj->F1 && mj->work_n && mj->qtheta && mj->U0 && mj->b_active && mj->P_active &&
                   mj->w_active && mj->idx_active && mj->st.q && mj->st.v && mj->st.P && mj->st.g &&
                   mj->st.active
               ? PD_OK
               : PD_ENOMEM;
}

/* Constants of the scalar kernel (pd_mj1.h). */
static void scalar_setup(pd_mj *mj)
{
    const pd_model *md = mj->model;
    /* without a contact (m = 0) W, g0 and e are passed as 0 and ignored */
    mj->s1 = mj1_coef_make(pd_matrix_get(&md->M, 0, 0), pd_matrix_get(&md->C, 0, 0),
                           pd_matrix_get(&md->K, 0, 0), md->m > 0,
                           md->m ? pd_matrix_get(&md->W, 0, 0) : 0.0, md->m ? md->g0[0] : 0.0,
                           md->m ? md->e[0] : 0.0, mj->opts.h, mj->opts.theta);
}

/* The LCP solver and the Delassus block: dense m^2 when the factor keeps D
 * dense, compressed columns bounded by the entries of D otherwise. */
static int contact_workspace(pd_mj *mj, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    int m = mj->model->m;
    long nnz = mj->factor->delassus_nnz;
    mj->sparse = mj->factor->type->kind == PD_FACTOR_CHOLMOD;
    mj->lcp_nmax = m; /* an active set is at most every contact */
    /* the warm start: 1 pushed, 0 active without pushing, 2 newly active */
    if (!(mj->guess = calloc((size_t)m, 1)))
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for %d contacts", m);
    if (!(mj->lcp =
              pd_lcp_solver_alloc(mj->opts.lcp_solver, mj->lcp_nmax, mj->sparse ? nnz : 0, err)))
        return err->status;
    if (mj->sparse) {
        /* D_II in compressed columns: no more entries than the whole D */
        mj->D_active = pd_malloc(nnz, sizeof(double));
        mj->D_colptr = malloc(((size_t)m + 1) * sizeof(int));
        mj->D_rowind = pd_malloc(nnz, sizeof(int));
    } else {
        /* D_II dense, nI x nI <= m x m; the refinement's R (cap^2), Q and What^-1 Q (n cap each), z
         * and R^-1 z (cap each) in ref_R; r, its trial, y and its trial (2 m + 2 n) in ref_res */
        mj->D_active = malloc((size_t)m * (size_t)m * sizeof(double));
        size_t n = (size_t)mj->model->n, cap = (size_t)(m < MJ_REFINE_NMAX ? m : MJ_REFINE_NMAX);
        mj->ref_nmax = (int)cap;
        mj->ref_R = malloc((cap * cap + 2 * cap * n + 2 * cap) * sizeof(double));
        mj->ref_res = malloc((2 * (size_t)m + 2 * n) * sizeof(double));
        /* the pushing contacts (m), the pivot order (cap) */
        mj->ref_perm = malloc(((size_t)m + cap) * sizeof(int));
        if (!mj->ref_R || !mj->ref_res || !mj->ref_perm)
            return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for the Delassus block");
        mj->ref_C = mj->ref_R + cap * cap;
        mj->ref_SC = mj->ref_C + cap * n;
        mj->ref_z = mj->ref_SC + cap * n;
        mj->ref_y = mj->ref_res + 2 * (size_t)m;
    }
    if (!mj->D_active || (mj->sparse && (!mj->D_colptr || !mj->D_rowind)))
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for the Delassus block");
    return PD_OK;
}

pd_mj *pd_mj_alloc(const pd_model *model, const pd_mj_opts *opts, pd_err *err)
{
    pd_mj *mj = NULL;
    pd_mj_opts o = opts ? *opts : pd_mj_default_opts();
    int st;
    pd_err_clear(err);
    if ((st = pd_model_check(model, err)) ||
        (o.rtol > 0.0 && (st = pd_model_refuse_yield(model, "Moreau-Jean to a tolerance", err))) ||
        (st = pd_mj_check_opts(&o, err)))
        return NULL;
    mj = calloc(1, sizeof *mj);
    if (!mj || alloc_arrays(mj, model->n, model->m)) {
        pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for n = %d, m = %d", model->n,
                   model->m);
        goto fail;
    }
    mj->model = model;
    mj->opts = o;
    /* one dof, at most one wall */
    mj->scalar = o.kernel == PD_KERNEL_AUTO && model->n == 1 && model->m <= 1 && model->ns == 0;
    /* What = M + h theta C + h^2 theta^2 K, factored once for the run */
    mj->factor = pd_factor_alloc(model, o.h, o.theta, o.factor, err);
    if (!mj->factor)
        goto fail;
    if (mj->scalar)
        scalar_setup(mj);
    /* the LCP's workspace: the general kernel's, and exact flights' */
    if ((!mj->scalar || (o.rtol > 0.0 && o.pieces)) && model->m > 0 && contact_workspace(mj, err))
        goto fail;
    if (o.rtol > 0.0 && mj_adapt_alloc(mj, err))
        goto fail;
    if (model->ns > 0 && mj_yield_alloc(mj, err))
        goto fail;
    if (pd_mj_reset(mj, 0.0, NULL, NULL, err))
        goto fail;
    return mj;
fail:
    pd_mj_free(mj);
    return NULL;
}

/* g = g0 + W^T q. */
static void gaps(const pd_model *md, const double *q, double *g)
{
    pd_matrix_gemv_t(&md->W, q, g);
    for (int a = 0; a < md->m; a++)
        g[a] += md->g0[a];
}

int pd_mj_reset(pd_mj *mj, double t0, const double *q0, const double *v0, pd_err *err)
{
    if (!mj)
        return PD_NULL_ARG(err, "mj");
    if (mj->ad)
        return mj_adapt_reset(mj, t0, q0, v0, err);
    const pd_model *md = mj->model;
    int n = md->n;
    for (int i = 0; i < n; i++) {
        /* NULL q0 or v0: at rest at q = 0 */
        mj->st.q[i] = q0 ? q0[i] : 0.0;
        mj->st.v[i] = v0 ? v0[i] : 0.0;
        if (!isfinite(mj->st.q[i]) || !isfinite(mj->st.v[i]))
            return pd_err_set(err, PD_EINVAL, "initial state: dof %d is not finite", i);
    }
    mj->t0 = t0;
    mj->st.t = t0;
    mj->st.step = 0;
    mj->st.nactive = 0;
    mj->st.lcp_pivots = 0;
    mj->st.lcp_solver = NULL;
    mj->st.h = mj->opts.h;
    mj->st.err = NULL;
    for (int a = 0; a < md->m; a++) {
        /* no impulse, no active contact before the first step */
        mj->st.P[a] = 0.0;
        mj->st.active[a] = 0;
    }
    gaps(md, mj->st.q, mj->st.g);
    mj_yield_reset(mj); /* the offsets start at 0 */
    /* breakpoints before t0 are passed; F0 = F(t0 +) already takes the right limit of one at t0 */
    mj->next_break = 0;
    while (mj->next_break < md->nbreaks && md->breaks[mj->next_break] < t0 - 1e-9 * mj->opts.h)
        mj->next_break++;
    if (md->force)
        md->force(t0, +1, mj->F0, md->force_ctx);
    else
        memset(mj->F0, 0, (size_t)n * sizeof(double));
    return PD_OK;
}

/* F_k for the next step: F(t_k+1 -) unless t_k+1 is a breakpoint, where the
 * next step starts from the right limit F(t_k+1 +). */
static void advance_force(pd_mj *mj, double t1)
{
    const pd_model *md = mj->model;
    if (mj_break_at(md->breaks, md->nbreaks, &mj->next_break, t1, 1e-9 * mj->opts.h))
        md->force(t1, +1, mj->F0, md->force_ctx); /* a jump at t1: its right limit */
    else
        memcpy(mj->F0, mj->F1, (size_t)md->n * sizeof(double)); /* F continuous at t1 */
}

/* Non-finite state: fail naming time and degree of freedom. */
static int check_state(const pd_model *md, const pd_state *st, pd_err *err)
{
    for (int i = 0; i < md->n; i++)
        if (!isfinite(st->q[i]) || !isfinite(st->v[i]))
            return pd_err_set(err, PD_ENONFINITE,
                              "Moreau-Jean: non-finite state at t = %.9g (step %ld, dof %d)", st->t,
                              st->step, i);
    return PD_OK;
}

/* run_scalar's hooks into pd_mj1.h's loop: the model's force, and the state
 * written back for the observer. */
typedef struct scalar_run {
    pd_mj *mj;
    pd_observer observer;
    void *ctx;
} scalar_run;

static inline double scalar_force_at(void *ctx, double t, int side)
{
    const pd_model *md = ((const scalar_run *)ctx)->mj->model;
    double F = 0.0;
    if (md->force)
        md->force(t, side, &F, md->force_ctx);
    return F;
}

/* pd_state from the loop's state after the step ending at t. */
static inline void scalar_store(pd_mj *mj, const mj1_state *x, double t)
{
    pd_state *st = &mj->st;
    st->q[0] = x->q;
    st->v[0] = x->v;
    if (mj->model->m) {
        st->P[0] = x->P;
        st->active[0] = (unsigned char)x->active;
        st->g[0] = x->g;
    }
    st->nactive = x->active;
    st->lcp_pivots = 0;
    st->lcp_solver = x->active ? "closed-form" : NULL;
    st->t = t;
    st->step = x->step;
}

static inline int scalar_observe(void *ctx, const mj1_state *x, double t)
{
    scalar_run *r = ctx;
    scalar_store(r->mj, x, t);
    return r->observer(&r->mj->st, r->ctx);
}

/* The scalar kernel's steps with the observer after each: pd_mj1.h's loop
 * (the state written back once at the end when nobody observes). */
static int run_scalar(pd_mj *mj, long nsteps, pd_observer observer, void *ctx, pd_err *err)
{
    const pd_model *md = mj->model;
    pd_state *st = &mj->st;
    scalar_run r = {.mj = mj, .observer = observer, .ctx = ctx};
    mj1_state x = {.q = st->q[0],
                   .v = st->v[0],
                   .g = md->m ? st->g[0] : 0.0,
                   .P = md->m ? st->P[0] : 0.0,
                   .F0 = mj->F0[0],
                   .F1 = mj->F1[0],
                   .step = st->step,
                   .next_break = mj->next_break,
                   .active = st->nactive};
    double h = mj->opts.h, th = mj->opts.theta, gamma = mj->opts.gamma;
    /* two calls: without an observer the inlined loop drops its call */
    int rc = observer ? mj1_run(&mj->s1, NULL, h, th, gamma, mj->t0, md->breaks, md->nbreaks,
                                nsteps, &x, scalar_force_at, scalar_observe, &r, err)
                      : mj1_run(&mj->s1, NULL, h, th, gamma, mj->t0, md->breaks, md->nbreaks,
                                nsteps, &x, scalar_force_at, NULL, &r, err);
    /* the state back into mj->st once, after the last step */
    scalar_store(mj, &x, mj->t0 + (double)x.step * h);
    mj->F0[0] = x.F0;
    mj->F1[0] = x.F1;
    mj->next_break = x.next_break;
    return rc;
}

/* Active set {a : g_a + h gamma U_a <= 0} of the state in, into out's
 * flags (out may be in); returns its size. */
static int predict_active(pd_mj *mj, double h, const pd_state *in, pd_state *out)
{
    const pd_model *md = mj->model;
    double hg = h * mj->opts.gamma;
    int nI = 0;
    pd_matrix_gemv_t(&md->W, in->v, mj->U0); /* U_k = W^T v_k */
    for (int a = 0; a < md->m; a++) {
        /* 1 pushed, 0 active without pushing, 2 newly active */
        unsigned char was = in->active[a] ? in->P[a] > 0.0 : 2;
        double ga = in->g[a];
        out->active[a] = 0;
        out->P[a] = 0.0;
        /* the adaptive driver's: an opening contact takes no impulse (an
         * impulse that makes it close leaves the next step its impact) */
        if (ga + hg * mj->U0[a] <= 0.0 && !(mj->u_rest && mj->U0[a] > mj->u_rest[a])) {
            out->active[a] = 1;
            if (mj->guess)
                mj->guess[nI] = was;
            mj->idx_active[nI++] = a;
        }
    }
    return nI;
}

/* The LCP of the active set, its Delassus block in mj->D_active (dense, or
 * compressed columns when mj->sparse) and its vector in mj->b_active: the
 * impulses into P_active and out->P.  t1 is the step's end (messages). */
int mj_impact_active(pd_mj *mj, int nI, double t1, pd_state *out, pd_err *err)
{
    pd_lcp_info info;
    pd_lcp_opts lo = pd_lcp_default_opts();
    pd_matrix D;
    lo.guess = mj->guess; /* warm start: the contacts that pushed in the last step */
    if (mj->opts.lcp_solver == PD_LCP_LEMKE && nI > PD_LCP_LEMKE_NMAX)
        return pd_err_set(err, PD_EBUDGET,
                          "Moreau-Jean: %d active contacts at t = %.9g: the lemke LCP solver "
                          "takes at most %d (use the structured one)",
                          nI, t1, PD_LCP_LEMKE_NMAX);
    /* one contact, the solver left to choose, nobody watching: the closed
     * form of the scalar kernel (D_11 > 0 as What is positive definite) */
    if (nI == 1 && mj->opts.lcp_solver == PD_LCP_AUTO && !mj->opts.on_lcp &&
        (!mj->sparse || mj->D_colptr[1] == 1) && mj->D_active[0] > 0.0) {
        out->P[mj->idx_active[0]] = mj->P_active[0] =
            pd_contact_impulse_1(mj->D_active[0], mj->b_active[0]);
        out->lcp_solver = "closed-form";
        return PD_OK;
    }
    /* w = D_II P + b_I >= 0, P >= 0, w^T P = 0 */
    D = mj->sparse ? pd_matrix_csc(nI, nI, mj->D_colptr, mj->D_rowind, mj->D_active)
                   : pd_matrix_dense(nI, nI, mj->D_active);
    int st = pd_lcp_solve(mj->lcp, &D, mj->b_active, &lo, mj->P_active, mj->w_active, &info);
    out->lcp_pivots = info.pivots + info.iterations;
    out->lcp_solver = info.solver;
    /* the observer sees every LCP, solved or not; > 0 stops the run after this step */
    if (mj->opts.on_lcp && mj->opts.on_lcp(&D, mj->b_active, mj->P_active, mj->w_active, &info,
                                           mj->idx_active, t1, mj->opts.on_lcp_ctx) > 0)
        mj->stop = 1;
    if (st)
        return pd_err_set(err, st,
                          "Moreau-Jean: LCP over %d active contact(s) (first: contact %d) not "
                          "solved at t = %.9g: %s",
                          nI, mj->idx_active[0], t1, pd_lcp_outcome_name(info.outcome));
    /* P_I back to the contacts' indices */
    for (int r = 0; r < nI; r++)
        out->P[mj->idx_active[r]] = mj->P_active[r];
    return PD_OK;
}

/* b_I = W_I^T vfree + e U_k of the active contacts; with the adaptive
 * driver's u_rest, e = 0 for a contact that was opening (U_k > 0: it may
 * not close through the step) or closing slower than u_rest. */
void mj_active_rhs(pd_mj *mj, int nI, const double *vfree)
{
    const pd_model *md = mj->model;
    for (int r = 0; r < nI; r++) {
        int a = mj->idx_active[r];
        /* w_a = (D P + b)_a = U_a(v_k+1) + e U_a(v_k) >= 0: Newton's law
         * U+ = -e U- where P_a > 0 */
        double e = mj->u_rest && (mj->U0[a] > 0.0 || -mj->U0[a] <= mj->u_rest[a]) ? 0.0 : md->e[a];
        mj->b_active[r] = pd_matrix_col_dot(&md->W, a, vfree) + e * mj->U0[a];
    }
}

/* r_I = b_I + W_I^T y, the Newton residual of v = vfree + y, and the worst
 * pushing contact's |r_a| over the rounding of its terms, eps (|W_a|^T
 * (|vfree| + |y|) + |b_a|), returned. */
static double velocity_residual(const pd_mj *mj, int nI, const int *ax, int na, const double *vfree,
                                const double *y, double *res)
{
    const pd_matrix *W = &mj->model->W;
    double worst = 0.0;
    /* r = U_I(vfree + y) + e U_I(v_k): Newton's law on every active contact */
    for (int r = 0; r < nI; r++)
        res[r] = mj->b_active[r] + pd_matrix_col_dot(W, mj->idx_active[r], y);
    for (int i = 0; i < na; i++) {
        int r = ax[i], a = mj->idx_active[r];
        double sc = pd_matrix_col_absdot(W, a, vfree) + pd_matrix_col_absdot(W, a, y) +
                    fabs(mj->b_active[r]);
        /* fmax(sc, DBL_MIN): no 0 / 0 when every term is 0 */
        worst = fmax(worst, fabs(res[r]) / (DBL_EPSILON * fmax(sc, DBL_MIN)));
    }
    return worst;
}

/* x^T y over n entries. */
static double dot_n(int n, const double *x, const double *y)
{
    double s = 0.0;
    for (int i = 0; i < n; i++)
        s += x[i] * y[i];
    return s;
}

/* What^-1-orthonormal basis of the pushing contacts' columns, pivoted
 * Gram-Schmidt on the vectors (not on D's entries, which hold the heavy
 * dofs' What^-1 only to eps cond(D)):  W_A Pi = Q R,  Q^T What^-1 Q = I,
 * R upper triangular (ref_R, column j for pivot j), Q and What^-1 Q in
 * ref_C and ref_SC.  Returns the rank reached (< na: dependent columns). */
static int orthogonalise_pushing(pd_mj *mj, const pd_factor *f, const int *ax, int na)
{
    const pd_model *md = mj->model;
    int n = md->n, *piv = mj->ref_perm + md->m;
    double *C = mj->ref_C, *SC = mj->ref_SC, *R = mj->ref_R;
    for (int j = 0; j < na; j++) {
        /* c_j = W_a (a the j-th pushing contact), and What^-1 c_j beside it */
        double *c = C + (size_t)j * n;
        memset(c, 0, (size_t)n * sizeof(double));
        pd_matrix_col_axpy(&md->W, mj->idx_active[ax[j]], 1.0, c);
        memcpy(SC + (size_t)j * n, c, (size_t)n * sizeof(double));
        pd_factor_solve(f, SC + (size_t)j * n);
        piv[j] = j;
    }
    memset(R, 0, (size_t)na * (size_t)na * sizeof(double));
    for (int k = 0; k < na; k++) {
        /* pivot: the remaining column of largest What^-1 norm */
        int best = k;
        double nb = -1.0;
        for (int i = k; i < na; i++) {
            /* |c|^2 = c^T What^-1 c */
            double nrm = dot_n(n, C + (size_t)piv[i] * n, SC + (size_t)piv[i] * n);
            if (nrm > nb) {
                nb = nrm;
                best = i;
            }
        }
        /* no direction left (or a NaN): the columns are dependent, rank k */
        if (!(nb > 0.0))
            return k;
        int p = piv[best];
        piv[best] = piv[k];
        piv[k] = p;
        /* q_k = c_p / |c_p| with |c|^2 = c^T What^-1 c, and R_kk = |c_p| */
        double d = sqrt(nb), *q = C + (size_t)p * n, *sq = SC + (size_t)p * n;
        R[k + (size_t)p * na] = d;
        for (int i = 0; i < n; i++) {
            q[i] /= d;
            sq[i] /= d;
        }
        /* the remaining columns lose their q_k part, twice (the first
         * pass leaves eps |c| along q_k, which the light dofs' What^-1
         * would magnify) */
        for (int i = k + 1; i < na; i++) {
            double *c = C + (size_t)piv[i] * n, *sc = SC + (size_t)piv[i] * n;
            for (int pass = 0; pass < 2; pass++) {
                double rho = dot_n(n, c, sq); /* rho = c^T What^-1 q_k, into R_ki */
                R[k + (size_t)piv[i] * na] += rho;
                for (int l = 0; l < n; l++) {
                    c[l] -= rho * q[l];
                    sc[l] -= rho * sq[l];
                }
            }
        }
    }
    return na;
}

/* One correction of y toward W_A^T (vfree + y) + e U_A = 0 on the pushing
 * contacts:  R^T z = -r_A (forward, pivoted order),  y += What^-1 Q z,
 * the impulses P_A += R^-1 z (backward). */
static void correct_pushing(pd_mj *mj, const int *ax, int na, const double *res, double *y)
{
    int n = mj->model->n, *piv = mj->ref_perm + mj->model->m;
    double *R = mj->ref_R, *z = mj->ref_z, *G = z + na;
    for (int i = 0; i < na; i++) {
        /* R^T z = -r_A forward in the pivot order (R_ki, k < i, sits in column piv[i]) */
        double s = -res[ax[piv[i]]];
        for (int k = 0; k < i; k++)
            s -= R[k + (size_t)piv[i] * na] * z[k];
        z[i] = s / R[i + (size_t)piv[i] * na];
        const double *sq = mj->ref_SC + (size_t)piv[i] * n;
        /* y += z_i What^-1 q_i: W_A^T y moves by Pi R^T z = -r_A */
        for (int l = 0; l < n; l++)
            y[l] += z[i] * sq[l];
    }
    /* R G = z backward: the impulses R^-1 z whose velocity is What^-1 Q z (W_A Pi = Q R) */
    for (int i = na - 1; i >= 0; i--) {
        double s = z[i];
        for (int j = i + 1; j < na; j++)
            s -= R[i + (size_t)piv[j] * na] * G[j];
        G[i] = s / R[i + (size_t)piv[i] * na];
        mj->P_active[ax[piv[i]]] += G[i];
    }
}

/* Refinement of a dense active LCP whose D P cancels terms 1/sqrt(eps)
 * larger than b (a heavy dof's What^-1 lost in D_II's entries under a
 * light one's; D of condition up to 1e13).  The velocity of the impulses,
 * y = What^-1 W_I P, is what the step needs, and it cannot come through P
 * (a light body squeezed between a heavy one and a wall takes two nearly
 * equal impulses whose difference is below their rounding): y is corrected
 * on an orthonormal basis of the pushing contacts A = {P > 0}, each step
 * solving for r_A -> 0 with R of condition sqrt(cond D), while the worst
 * |r_a| shrinks and stays beyond MJ_REFINE_TOL roundings of its terms.
 * Sets mj->refined (y in mj->ref_y); PD_ENUMERICAL when it stays beyond. */
static int impact_refine(pd_mj *mj, const pd_factor *f, int nI, const double *vfree, double t1,
                         pd_err *err)
{
    int n = mj->model->n, na = 0, *ax = mj->ref_perm;
    double *P = mj->P_active, *D = mj->D_active, grow = 0.0;
    double *res = mj->ref_res, *rt = res + mj->model->m, *y = mj->ref_y, *yt = y + n;
    mj->refined = 0;
    for (int r = 0; r < nI; r++) {
        double s = 0.0;
        /* grow = max_r sum_c |D_rc P_c| / |b_r|, and A = {r : P_r > 0} */
        for (int c = 0; c < nI; c++)
            s += fabs(D[r + (size_t)c * nI] * P[c]);
        if (P[r] > 0.0)
            ax[na++] = r;
        grow = fmax(grow, s / fmax(fabs(mj->b_active[r]), DBL_MIN));
    }
    /* one pushing contact, more than the basis holds, or D P's terms at most 1e8 b: P stands */
    if (na < 2 || na > mj->ref_nmax || !(grow > MJ_REFINE_GROWTH))
        return PD_OK;
    /* y = What^-1 W_I P, the impulses' velocity, through the factor */
    memset(yt, 0, (size_t)n * sizeof(double));
    for (int r = 0; r < nI; r++)
        pd_matrix_col_axpy(&mj->model->W, mj->idx_active[r], P[r], yt);
    memcpy(y, yt, (size_t)n * sizeof(double));
    pd_factor_solve(f, y);
    double worst = velocity_residual(mj, nI, ax, na, vfree, y, res);
    if (worst <= MJ_REFINE_TOL)
        return PD_OK;
    mj->refined = 1;                           /* y is kept even when no correction improves it */
    memcpy(yt, y, (size_t)n * sizeof(double)); /* the iterate; y the best */
    int full = orthogonalise_pushing(mj, f, ax, na) == na;
    /* not monotone: a first correction can carry the basis vectors'
     * rounding times a large z into a light dof; the next removes it */
    double wt = worst;
    for (int it = 0; it < MJ_REFINE_MAX && full && worst > MJ_REFINE_TOL; it++) {
        correct_pushing(mj, ax, na, it ? rt : res, yt);
        wt = velocity_residual(mj, nI, ax, na, vfree, yt, rt);
        /* y, r and worst: the best iterate so far */
        if (wt < worst) {
            memcpy(y, yt, (size_t)n * sizeof(double));
            memcpy(res, rt, (size_t)nI * sizeof(double));
            worst = wt;
        }
    }
    for (int i = 0; i < na; i++)
        P[ax[i]] = fmax(P[ax[i]], 0.0); /* P is reported; y carries the step */
    if (worst > MJ_REFINE_TOL)
        return pd_err_set(err, PD_ENUMERICAL,
                          "Moreau-Jean: the LCP of %d active contacts at t = "
                          "%.9g lost precision: its velocities miss Newton's law by %.3g roundings "
                          "of their terms (at most %g)",
                          nI, t1, worst, MJ_REFINE_TOL);
    return PD_OK;
}

/* Impulses of the active contacts into out->P: the LCP (D_II, W_I^T vfree
 * + e U) with D_II from the factor f, refined when it lost precision; t1
 * is the step's end (messages). */
static int impact_contacts(pd_mj *mj, const pd_factor *f, int nI, int reuse_D, const double *vfree,
                           double t1, pd_state *out, pd_err *err)
{
    int rc;
    mj->refined = 0;
    /* D_II = W_I^T What^-1 W_I from the factor, as it keeps D (kept from the
     * last call on the same active set when reuse_D) */
    if (reuse_D)
        ;
    else if (mj->sparse)
        pd_factor_delassus_csc(f, mj->idx_active, nI, mj->D_colptr, mj->D_rowind, mj->D_active,
                               NULL);
    else
        pd_factor_delassus_dense(f, mj->idx_active, nI, mj->D_active);
    mj_active_rhs(mj, nI, vfree);
    /* refined only dense (the ref_ arrays exist only then), with two contacts or more */
    if ((rc = mj_impact_active(mj, nI, t1, out, err)) || mj->sparse || nI < 2)
        return rc;
    if ((rc = impact_refine(mj, f, nI, vfree, t1, err)))
        return rc;
    /* the refinement may have moved P_A (P_A += R^-1 z, clipped at 0) */
    for (int r = 0; r < nI; r++)
        out->P[mj->idx_active[r]] = mj->P_active[r];
    return PD_OK;
}

int mj_contacts_apply(pd_mj *mj, const pd_factor *f, int nI, int reuse_D, double t1, pd_state *out,
                      pd_err *err)
{
    int rc = impact_contacts(mj, f, nI, reuse_D, out->v, t1, out, err);
    if (rc)
        return rc;
    if (mj->refined) /* the impulses' velocity corrected on the pushing contacts */
        for (int i = 0; i < mj->model->n; i++)
            out->v[i] += mj->ref_y[i];
    else
        pd_factor_add_impulse(f, mj->idx_active, nI, mj->P_active, out->v);
    return PD_OK;
}

int mj_general_step(pd_mj *mj, const pd_factor *f, double h, double t1, const double *F0,
                    const double *F1, const pd_state *in, pd_state *out, pd_err *err)
{
    const pd_model *md = mj->model;
    int n = md->n, nI = 0, rc;
    double th = mj->opts.theta;
    double *x = mj->work_n;
    /* right-hand side h [F_theta - C v - K (q + h theta v)] */
    for (int i = 0; i < n; i++) {
        x[i] = th * F1[i] + (1.0 - th) * F0[i];       /* F_theta */
        mj->qtheta[i] = in->q[i] + h * th * in->v[i]; /* q_k + h theta v_k */
    }
    pd_matrix_gemv(&md->C, -1.0, in->v, 1.0, x);
    pd_matrix_gemv(&md->K, -1.0, mj->qtheta, 1.0, x);
    for (int i = 0; i < n; i++)
        x[i] *= h;
    if (mj->yl) /* the yielding springs' offsets: h S ks up */
        mj_yield_force(mj, h, x);
    /* vfree - v_k = What^-1 rhs */
    pd_factor_solve(f, x);
    /* I = {a : g_a + h gamma U_a <= 0} at the step's start */
    if (md->m)
        nI = predict_active(mj, h, in, out);
    out->lcp_pivots = 0;
    out->lcp_solver = NULL;
    /* q gets the (1 - theta) v_k part before v is overwritten */
    for (int i = 0; i < n; i++) {
        out->q[i] = in->q[i] + h * (1.0 - th) * in->v[i];
        out->v[i] = in->v[i] + x[i];
    }
    out->t = t1;
    out->step = in->step + 1;
    /* out->v = vfree; v_k+1 = vfree + What^-1 (W_I P [+ the springs' slides]) */
    if (mj->yl)
        rc = mj_yield_step(mj, f, h, nI, t1, out, err);
    else
        rc = nI > 0 ? mj_contacts_apply(mj, f, nI, 0, t1, out, err) : PD_OK;
    if (rc)
        return rc;
    /* q_k+1 = q_k + h [(1 - theta) v_k + theta v_k+1] */
    for (int i = 0; i < n; i++)
        out->q[i] += h * th * out->v[i];
    out->nactive = nI;
    /* g_k+1 = g0 + W^T q_k+1: the next step's prediction */
    if (md->m)
        gaps(md, out->q, out->g);
    return check_state(md, out, err);
}

/* One step of the general kernel: F1 = F(t_k+1 -), then the step in place,
 * then F_k of the next step. */
static int step_general(pd_mj *mj, pd_err *err)
{
    const pd_model *md = mj->model;
    double t1 = mj->t0 + (double)(mj->st.step + 1) * mj->opts.h;
    int rc;
    if (md->force)
        md->force(t1, -1, mj->F1, md->force_ctx); /* F(t_k+1 -) */
    /* in place: out = in = mj->st */
    rc = mj_general_step(mj, mj->factor, mj->opts.h, t1, mj->F0, mj->F1, &mj->st, &mj->st, err);
    if (md->force)
        advance_force(mj, t1);
    return rc;
}

static int mj_step(pd_mj *mj, pd_err *err)
{
    return mj->scalar ? run_scalar(mj, 1, NULL, NULL, err) : step_general(mj, err);
}

/* The adaptive driver chooses its own steps: the fixed-step calls refuse it. */
static int refuse_adaptive(const pd_mj *mj, const char *call, pd_err *err)
{
    if (!mj->ad)
        return PD_OK;
    return pd_err_set(err, PD_EINVAL,
                      "%s: this Moreau-Jean object chooses its steps (rtol = "
                      "%g): run it with pd_mj_run_until",
                      call, mj->opts.rtol);
}

int pd_mj_step(pd_mj *mj, pd_err *err)
{
    int rc;
    if (!mj)
        return PD_NULL_ARG(err, "mj");
    if ((rc = refuse_adaptive(mj, "pd_mj_step", err)))
        return rc;
    return mj_step(mj, err);
}

int pd_mj_run(pd_mj *mj, long nsteps, pd_observer observer, void *ctx, pd_err *err)
{
    int rc;
    if (!mj)
        return PD_NULL_ARG(err, "mj");
    if ((rc = refuse_adaptive(mj, "pd_mj_run", err)))
        return rc;
    if (observer && observer(&mj->st, ctx) > 0)
        return PD_OK;
    /* the observer saw the start state first: > 0 stopped before any step */
    mj->stop = 0;
    if (mj->scalar)
        return run_scalar(mj, nsteps, observer, ctx, err);
    /* mj->stop: the LCP observer asked to stop */
    for (long k = 0; k < nsteps && !mj->stop; k++) {
        if ((rc = mj_step(mj, err)))
            return rc;
        if (observer && observer(&mj->st, ctx) > 0)
            break;
    }
    return PD_OK;
}

int pd_mj_run_until(pd_mj *mj, double t_end, pd_observer observer, void *ctx, pd_err *err)
{
    if (!mj)
        return PD_NULL_ARG(err, "mj");
    if (!isfinite(t_end))
        return pd_err_set(err, PD_EINVAL, "pd_mj_run_until: t_end must be finite (got %g)", t_end);
    if (mj->ad)
        return mj_adapt_run_until(mj, t_end, observer, ctx, err);
    /* the steps of h that reach t_end: the whole number within 1e-9 of the ratio, else one more */
    long nsteps = t_end > mj->st.t ? pd_steps_for(t_end - mj->st.t, mj->opts.h) : 0;
    return pd_mj_run(mj, nsteps, observer, ctx, err);
}

int pd_mj_get_stats(const pd_mj *mj, pd_mj_stats *s)
{
    if (!mj || !s)
        return PD_EINVAL;
    if (mj->ad) {
        mj_adapt_stats(mj, s);
        return PD_OK;
    }
    /* fixed steps: each taken once and kept, no error estimate */
    *s = (pd_mj_stats){.steps = mj->st.step,
                       .rejected = 0,
                       .evals = mj->st.step,
                       .h_min = mj->opts.h,
                       .h_max = mj->opts.h,
                       .floor_hit = 0,
                       .budget_hit = 0,
                       .err_max = NAN,
                       .h0 = mj->opts.h};
    mj_yield_stats(mj, &s->yield_set_tries, &s->yield_gs_steps);
    return PD_OK;
}

const pd_state *pd_mj_state(const pd_mj *mj)
{
    return mj ? &mj->st : NULL;
}

const char *pd_mj_kernel_name(const pd_mj *mj)
{
    if (!mj)
        return "(none)";
    return mj->scalar ? "scalar" : "general";
}

const char *pd_mj_factor_name(const pd_mj *mj)
{
    if (!mj)
        return "(none)";
    return mj->factor->type->name;
}
