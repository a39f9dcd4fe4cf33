/* moreau.c — Moreau–Jean theta time-stepping (SPEC §2).
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
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_engine.h"
#include "pd_factor.h"
#include "pd_null.h"
#include "mj1.h"


struct pd_mj {
    const pd_model *model;
    pd_mj_opts opts;
    int scalar;           /* 1: scalar kernel */
    double t0;            /* time of the last reset */
    int next_break;       /* index of the first model breakpoint after t */
    pd_factor *factor;    /* What, What^-1 W and the Delassus matrix */
    pd_lcp_solver *lcp;   /* the contact LCP solver, sized for lcp_nmax contacts */
    int lcp_nmax;         /* most active contacts one LCP may have */
    unsigned char *guess; /* m: the warm start of the active set's LCP: 1 pushed in the
                             previous step, 0 active without pushing, 2 newly active */
    int sparse;           /* 1: Delassus blocks in compressed columns */
    int stop;             /* the LCP observer asked to stop */
    double *F0, *F1;      /* n: force at t_k and t_k+1 */
    double *work_n;       /* n: right-hand side, then velocity increment */
    double *qtheta;       /* n: q_k + h theta v_k */
    double *U0;           /* m: W^T v_k */
    double *D_active;     /* Delassus block: lcp_nmax^2 (dense) or delassus_nnz (sparse) */
    int *D_colptr, *D_rowind; /* sparse: its compressed columns */
    double *b_active;     /* m: LCP vector of the active set */
    double *P_active;     /* m: impulses of the active set */
    double *w_active;     /* m: post-impact relative velocities of the active set */
    int *idx_active;      /* m: indices of the active contacts */
    mj1_coef s1;          /* scalar kernel constants (no division in a step) */
    pd_state st;
};

pd_mj_opts pd_mj_default_opts(void)
{
    return (pd_mj_opts){.h = 0.0,
                        .theta = 0.5,
                        .gamma = 0.5,
                        .allow_unstable = 0,
                        .kernel = PD_KERNEL_AUTO,
                        .factor = PD_FACTOR_AUTO,
                        .lcp_solver = PD_LCP_AUTO,
                        .on_lcp = NULL,
                        .on_lcp_ctx = NULL};
}

/* Closed-form scalar LCP  w = D P + b >= 0, P >= 0, wP = 0  (D > 0). */
double pd_contact_impulse_1(double D, double b)
{
    return b < 0.0 ? -b / D : 0.0;
}

void pd_mj_free(pd_mj *mj)
{
    if (!mj)
        return;
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
    free(mj->guess);
    free(mj->st.q);
    free(mj->st.v);
    free(mj->st.P);
    free(mj->st.g);
    free(mj->st.active);
    free(mj);
}

/* Options in range: h > 0 finite, theta in [1/2, 1] unless allowed. */
int pd_mj_check_opts(const pd_mj_opts *o, pd_err *err)
{
    if (!(o->h > 0.0) || !isfinite(o->h))
        return pd_err_set(err, PD_EINVAL, "dt must be a finite number > 0 (got %g)", o->h);
    if (!isfinite(o->theta) || o->theta < 0.0 || o->theta > 2.0)
        return pd_err_set(err, PD_EINVAL, "theta must be in [0, 2] (got %g)", o->theta);
    if ((o->theta < 0.5 || o->theta > 1.0) && !o->allow_unstable)
        return pd_err_set(err, PD_EINVAL,
                          "theta = %g is outside [1/2, 1], where the scheme is not unconditionally "
                          "stable (pass --allow-unstable to run it anyway)",
                          o->theta);
    if (!(o->gamma >= 0.0 && o->gamma <= 1.0))
        return pd_err_set(err, PD_EINVAL, "gamma must be in [0, 1] (got %g)", o->gamma);
    return PD_OK;
}

/* Every array, sized once for (n, m). */
static int alloc_arrays(pd_mj *mj, int n, int m)
{
    size_t mm = m > 0 ? (size_t)m : 1;
    mj->F0 = calloc((size_t)n, sizeof(double));
    mj->F1 = calloc((size_t)n, sizeof(double));
    mj->work_n = calloc((size_t)n, sizeof(double));
    mj->qtheta = calloc((size_t)n, sizeof(double));
    mj->U0 = calloc(mm, sizeof(double));
    mj->b_active = calloc(mm, sizeof(double));
    mj->P_active = calloc(mm, sizeof(double));
    mj->w_active = calloc(mm, sizeof(double));
    mj->idx_active = calloc(mm, sizeof(int));
    mj->st.q = calloc((size_t)n, sizeof(double));
    mj->st.v = calloc((size_t)n, sizeof(double));
    mj->st.P = calloc(mm, sizeof(double));
    mj->st.g = calloc(mm, sizeof(double));
    mj->st.active = calloc(mm, 1);
    return mj->F0 && mj->F1 && mj->work_n && mj->qtheta && mj->U0 && mj->b_active && mj->P_active && mj->w_active && mj->idx_active && mj->st.q &&
                   mj->st.v && mj->st.P && mj->st.g && mj->st.active
               ? PD_OK
               : PD_ENOMEM;
}

/* Constants of the scalar kernel (mj1.h). */
static void scalar_setup(pd_mj *mj)
{
    const pd_model *md = mj->model;
    mj->s1 = mj1_coef_make(pd_matrix_get(&md->M, 0, 0), pd_matrix_get(&md->C, 0, 0),
                           pd_matrix_get(&md->K, 0, 0), md->m > 0,
                           md->m ? pd_matrix_get(&md->W, 0, 0) : 0.0, md->m ? md->g0[0] : 0.0,
                           md->m ? md->e[0] : 0.0, mj->opts.h, mj->opts.theta);
}

/* The LCP solver and the Delassus block: dense m^2 when the factor keeps D
 * dense, compressed columns bounded by the entries of D otherwise. */
static int contact_workspace(pd_mj *mj, pd_err *err)
{
    int m = mj->model->m;
    long nnz = mj->factor->delassus_nnz;
    mj->sparse = mj->factor->type->kind == PD_FACTOR_CHOLMOD;
    mj->lcp_nmax = m;
    if (!(mj->guess = calloc((size_t)m, 1)))
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for %d contacts", m);
    if (!(mj->lcp = pd_lcp_solver_alloc(mj->opts.lcp_solver, mj->lcp_nmax, mj->sparse ? nnz : 0,
                                        err)))
        return err ? err->status : PD_ENOMEM;
    if (mj->sparse) {
        mj->D_active = malloc((size_t)(nnz > 0 ? nnz : 1) * sizeof(double));
        mj->D_colptr = malloc(((size_t)m + 1) * sizeof(int));
        mj->D_rowind = malloc((size_t)(nnz > 0 ? nnz : 1) * sizeof(int));
    } else {
        mj->D_active = malloc((size_t)m * (size_t)m * sizeof(double));
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
    if ((st = pd_model_check(model, err)) || (st = pd_mj_check_opts(&o, err)))
        return NULL;
    mj = calloc(1, sizeof *mj);
    if (!mj || alloc_arrays(mj, model->n, model->m)) {
        pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for n = %d, m = %d", model->n,
                   model->m);
        goto fail;
    }
    mj->model = model;
    mj->opts = o;
    mj->scalar = o.kernel == PD_KERNEL_AUTO && model->n == 1 && model->m <= 1;
    mj->factor = pd_factor_alloc(model, o.h, o.theta, o.factor, err);
    if (!mj->factor)
        goto fail;
    if (mj->scalar)
        scalar_setup(mj);
    else if (model->m > 0 && contact_workspace(mj, err))
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
    const pd_model *md = mj->model;
    int n = md->n;
    for (int i = 0; i < n; i++) {
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
    for (int a = 0; a < md->m; a++) {
        mj->st.P[a] = 0.0;
        mj->st.active[a] = 0;
    }
    gaps(md, mj->st.q, mj->st.g);
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
        md->force(t1, +1, mj->F0, md->force_ctx);
    else
        memcpy(mj->F0, mj->F1, (size_t)md->n * sizeof(double));
}

/* Non-finite state: fail naming time and degree of freedom. */
static int check_finite(const pd_mj *mj, pd_err *err)
{
    for (int i = 0; i < mj->model->n; i++)
        if (!isfinite(mj->st.q[i]) || !isfinite(mj->st.v[i]))
            return pd_err_set(err, PD_ENONFINITE,
                              "Moreau-Jean: non-finite state at t = %.9g (step %ld, dof %d)",
                              mj->st.t, mj->st.step, i);
    return PD_OK;
}

/* One step of the scalar kernel (n = 1, m <= 1): mj1.h's, with the force
 * F1 = F(t_k+1 -). */
static inline int step_scalar_f(pd_mj *mj, double F1, pd_err *err)
{
    const pd_model *md = mj->model;
    pd_state *st = &mj->st;
    double h = mj->opts.h;
    double t1 = mj->t0 + (double)(st->step + 1) * h;
    double g = st->g[0], P;
    int active = mj1_step(h, mj->opts.theta, h * mj->opts.gamma, &mj->s1, mj->F0[0], F1,
                          &st->q[0], &st->v[0], &g, &P);
    if (md->m) {
        st->P[0] = P;
        st->active[0] = (unsigned char)active;
        st->g[0] = g;
    }
    st->nactive = active;
    st->lcp_pivots = 0;
    st->lcp_solver = active ? "closed-form" : NULL;
    mj->F0[0] = F1;
    if (mj->next_break < md->nbreaks) {
        mj->F1[0] = F1;
        advance_force(mj, t1);
    }
    st->t = t1;
    st->step++;
    if (!isfinite(st->q[0]) || !isfinite(st->v[0]))
        return check_finite(mj, err);
    return PD_OK;
}

/* The force's left limit F(t_k+1 -) at the end of step k (0 without one). */
static inline double scalar_force(const pd_mj *mj, long k)
{
    const pd_model *md = mj->model;
    double F1 = 0.0;
    if (md->force)
        md->force(mj->t0 + (double)(k + 1) * mj->opts.h, -1, &F1, md->force_ctx);
    return F1;
}

static int step_scalar(pd_mj *mj, pd_err *err)
{
    return step_scalar_f(mj, scalar_force(mj, mj->st.step), err);
}

/* The scalar kernel's steps with the observer after each.  The forces are
 * asked MJ_FORCE_AHEAD steps ahead (the same values, at the same instants,
 * in the same order), so that the excitation's evaluation of a later step
 * runs beside the step's chain of latencies instead of in it. */
#define MJ_FORCE_AHEAD 8 /* a power of 2 */
static int run_scalar(pd_mj *mj, long nsteps, pd_observer observer, void *ctx, pd_err *err)
{
    double F[MJ_FORCE_AHEAD];
    long step0 = mj->st.step;
    int rc;
    for (long k = 0; k < nsteps && k < MJ_FORCE_AHEAD; k++)
        F[k] = scalar_force(mj, step0 + k);
    for (long k = 0; k < nsteps; k++) {
        double F1 = F[k & (MJ_FORCE_AHEAD - 1)];
        if (k + MJ_FORCE_AHEAD < nsteps)
            F[k & (MJ_FORCE_AHEAD - 1)] = scalar_force(mj, step0 + k + MJ_FORCE_AHEAD);
        if ((rc = step_scalar_f(mj, F1, err)))
            return rc;
        if (observer && observer(&mj->st, ctx) > 0)
            return PD_OK;
    }
    return PD_OK;
}

/* Active set {a : g_a + h gamma U_a <= 0}; returns its size. */
static int predict_active(pd_mj *mj)
{
    const pd_model *md = mj->model;
    double hg = mj->opts.h * mj->opts.gamma;
    int nI = 0;
    pd_matrix_gemv_t(&md->W, mj->st.v, mj->U0);
    for (int a = 0; a < md->m; a++) {
        unsigned char was = mj->st.active[a] ? mj->st.P[a] > 0.0 : 2;
        mj->st.active[a] = 0;
        mj->st.P[a] = 0.0;
        if (mj->st.g[a] + hg * mj->U0[a] <= 0.0) {
            mj->st.active[a] = 1;
            if (mj->guess)
                mj->guess[nI] = was;
            mj->idx_active[nI++] = a;
        }
    }
    return nI;
}

/* Impulses of the active contacts: the LCP (D_II, W_I^T vfree + e U). */
static int solve_contacts(pd_mj *mj, int nI, const double *vfree, pd_err *err)
{
    const pd_model *md = mj->model;
    pd_lcp_info info;
    pd_lcp_opts lo = pd_lcp_default_opts();
    pd_matrix D;
    lo.guess = mj->guess; /* warm start: the contacts that pushed in the last step */
    if (mj->opts.lcp_solver == PD_LCP_LEMKE && nI > PD_LCP_LEMKE_NMAX)
        return pd_err_set(err, PD_EBUDGET,
                          "Moreau-Jean: %d active contacts at t = %.9g: the lemke LCP solver "
                          "takes at most %d (use the structured one)",
                          nI, mj->st.t + mj->opts.h, PD_LCP_LEMKE_NMAX);
    if (mj->sparse)
        pd_factor_delassus_csc(mj->factor, mj->idx_active, nI, mj->D_colptr, mj->D_rowind,
                               mj->D_active);
    else
        pd_factor_delassus_dense(mj->factor, mj->idx_active, nI, mj->D_active);
    for (int r = 0; r < nI; r++) {
        int a = mj->idx_active[r];
        mj->b_active[r] = pd_matrix_col_dot(&md->W, a, vfree) + md->e[a] * mj->U0[a];
    }
    /* one contact, the solver left to choose, nobody watching: the closed
     * form of the scalar kernel (D_11 > 0 as What is positive definite) */
    if (nI == 1 && mj->opts.lcp_solver == PD_LCP_AUTO && !mj->opts.on_lcp &&
        (!mj->sparse || mj->D_colptr[1] == 1) && mj->D_active[0] > 0.0) {
        mj->st.P[mj->idx_active[0]] = mj->P_active[0] =
            pd_contact_impulse_1(mj->D_active[0], mj->b_active[0]);
        mj->st.lcp_solver = "closed-form";
        return PD_OK;
    }
    D = mj->sparse ? pd_matrix_csc(nI, nI, mj->D_colptr, mj->D_rowind, mj->D_active)
                   : pd_matrix_dense(nI, nI, mj->D_active);
    int st = pd_lcp_solve(mj->lcp, &D, mj->b_active, &lo, mj->P_active, mj->w_active, &info);
    mj->st.lcp_pivots = info.pivots + info.iterations;
    mj->st.lcp_solver = info.solver;
    if (mj->opts.on_lcp && mj->opts.on_lcp(&D, mj->b_active, mj->P_active, mj->w_active, &info,
                                           mj->idx_active, mj->st.t + mj->opts.h,
                                           mj->opts.on_lcp_ctx) > 0)
        mj->stop = 1;
    if (st)
        return pd_err_set(err, st,
                          "Moreau-Jean: LCP over %d active contact(s) (first: contact %d) not "
                          "solved at t = %.9g: %s",
                          nI, mj->idx_active[0], mj->st.t + mj->opts.h,
                          pd_lcp_outcome_name(info.outcome));
    for (int r = 0; r < nI; r++)
        mj->st.P[mj->idx_active[r]] = mj->P_active[r];
    return PD_OK;
}

/* One step of the general kernel. */
static int step_general(pd_mj *mj, pd_err *err)
{
    const pd_model *md = mj->model;
    pd_state *st = &mj->st;
    int n = md->n, nI = 0, rc;
    double h = mj->opts.h, th = mj->opts.theta;
    double t1 = mj->t0 + (double)(st->step + 1) * h;
    double *x = mj->work_n;
    /* right-hand side h [F_theta - C v - K (q + h theta v)] */
    if (md->force)
        md->force(t1, -1, mj->F1, md->force_ctx);
    for (int i = 0; i < n; i++) {
        x[i] = th * mj->F1[i] + (1.0 - th) * mj->F0[i];
        mj->qtheta[i] = st->q[i] + h * th * st->v[i];
    }
    pd_matrix_gemv(&md->C, -1.0, st->v, 1.0, x);
    pd_matrix_gemv(&md->K, -1.0, mj->qtheta, 1.0, x);
    for (int i = 0; i < n; i++)
        x[i] *= h;
    /* vfree - v_k = What^-1 rhs */
    pd_factor_solve(mj->factor, x);
    if (md->m)
        nI = predict_active(mj);
    st->lcp_pivots = 0;
    st->lcp_solver = NULL;
    /* q gets the (1 - theta) v_k part before v is overwritten */
    for (int i = 0; i < n; i++) {
        st->q[i] += h * (1.0 - th) * st->v[i];
        st->v[i] += x[i];
    }
    if (nI > 0) {
        if ((rc = solve_contacts(mj, nI, st->v, err)))
            return rc;
        pd_factor_add_impulse(mj->factor, mj->idx_active, nI, mj->P_active, st->v);
    }
    for (int i = 0; i < n; i++)
        st->q[i] += h * th * st->v[i];
    if (md->force)
        advance_force(mj, t1);
    st->nactive = nI;
    st->t = t1;
    st->step++;
    if (md->m)
        gaps(md, st->q, st->g);
    return check_finite(mj, err);
}

static int mj_step(pd_mj *mj, pd_err *err)
{
    return mj->scalar ? step_scalar(mj, err) : step_general(mj, err);
}

int pd_mj_step(pd_mj *mj, pd_err *err)
{
    if (!mj)
        return PD_NULL_ARG(err, "mj");
    return mj_step(mj, err);
}

int pd_mj_run(pd_mj *mj, long nsteps, pd_observer observer, void *ctx, pd_err *err)
{
    int rc;
    if (!mj)
        return PD_NULL_ARG(err, "mj");
    if (observer && observer(&mj->st, ctx) > 0)
        return PD_OK;
    mj->stop = 0;
    if (mj->scalar)
        return run_scalar(mj, nsteps, observer, ctx, err);
    for (long k = 0; k < nsteps && !mj->stop; k++) {
        if ((rc = mj_step(mj, err)))
            return rc;
        if (observer && observer(&mj->st, ctx) > 0)
            break;
    }
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
