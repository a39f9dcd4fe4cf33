/* event_general.c — event-driven reference for the general system (SPEC §2):
 *
 *   M q'' + C q' + K q = F(t) + W lambda,   g = g0 + W^T q >= 0 ⊥ lambda >= 0.
 *
 * Smooth motion: y = (d, v, z) by GSL rk8pd under step control, q = qref + d
 * with qref re-based at every event (small d keeps gaps near an impact to
 * full relative precision), z' = lambda (the contact impulses, so that the
 * control also resolves the contact forces).  The persistent contacts A are
 * held by their acceleration LCP; while every lambda_a > 0 its solution is
 * the linear system
 *     D_AA lambda_A = -W_A^T M^-1 (F - C v - K q),   D = W^T M^-1 W,
 * factored once per set.  After each accepted step q and v are projected
 * M-orthogonally back onto g_A = 0, U_A = W_A^T v = 0.
 *
 * Events, located on the re-integrated motion (one rk8pd step from the start
 * of the accepted step, never perturbing it):
 *   gap closing   a free gap sampled on the quintic Hermite of the step goes
 *                 below its rounding level (interior minima included: grazing);
 *   detachment    a held contact force lambda_a turns negative;
 *   breakpoint    the integrator stops at each model break and restarts from F(t+);
 *   t1.
 * At an event: one velocity LCP (Newton's law) over every contact at zero
 * gap, then one acceleration LCP over those at zero gap and zero rate
 * decides A (lambda > 0).  Accumulations of impacts are jumped to persistent
 * contact (docs/methods.md, "The event-driven reference for the general system"). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "pd_engine.h"
#include "pd_factor.h"
#include "pd_null.h"

#define EDG_GAP_SAMPLES 16  /* gap samples per accepted step */
#define EDG_FORCE_SAMPLES 8 /* contact-force samples per step */
#define EDG_ZERO 1e-12      /* relative size of a "zero" gap or rate */
#define EDG_NEAR 1e-6       /* relative interpolant minimum checked on the true motion */
#define EDG_BOUNCE 1e-10    /* relative bounce height that ends an accumulation */
#define EDG_STUCK 100       /* events at one instant before giving up */
#define EDG_SET_MAX 512     /* most contacts at zero gap at one instant (dense blocks) */
#define EDG_SINGULAR 1e-14  /* relative pivot floor of a contact set's D block */
/* The integrator's step budget, scaled by time: EDG_STEPS_FLOOR plus
 * EDG_STEPS_PER_RADIAN per radian of the fastest mode's motion (the docs'
 * row of 100: 58k steps where the budget allows 350k).  Past it the motion
 * is stiff under its held contacts or chatters: PD_EBUDGET naming the fixed
 * step scheme, not hours of steps of 1e-8 s. */
#define EDG_STEPS_FLOOR 100000.0
#define EDG_STEPS_PER_RADIAN 10000.0

enum { EV_NONE = 0, EV_GAP = 1, EV_FORCE = 2 };

typedef struct edg {
    const pd_model *md;
    double omega_max; /* fastest_frequency: the step budget's scale */
    pd_edg_opts o;
    pd_edg_result *res;
    pd_observer obs;
    void *obs_ctx;
    int n, m, dim;       /* dim = 2 n + m */
    double t0, t1, t;    /* run interval, current time */
    double seg_a, seg_b; /* current smooth segment (between breakpoints) */
    double ta, tb, h;    /* accepted step [ta, tb], next step size */
    int next_break, stopped, lcp_pivots;
    long next_out;     /* index k of the next output time t0 + k h_out */
    double last_event; /* time of the last event */
    long same_instant; /* consecutive events within rounding of it */
    double last_emit;
    int sample_forces; /* the observer's P: impulses since its last report (z) */
    double *zout;      /* m: z at the observer's last report */
    /* constant data: M factored, M^-1 W and D = W^T M^-1 W (pd_factor.h) */
    pd_factor *fac;
    const pd_matrix *W;
    int kmax; /* most contacts in one set (dense blocks kmax x kmax) */
    /* persistent contacts */
    unsigned char *inA;
    int *idxA, *posA, nA;
    double *Dlu; /* nA x nA LU of D_AA (kmax^2) */
    int *Dperm;
    double *lam;  /* nA: contact forces of the last acceleration */
    double *tmpA; /* nA: projection work */
    /* states: q = qref + d */
    double *qref, *Kqref;  /* n: reference displacement and K qref */
    double *gref, *gscale; /* m: gap at qref, and its rounding scale */
    double *y, *ya, *fa, *fb, *yp, *yev, *yerr, *acc, *qs, *vs;
    double *ga, *Ua, *Ga, *gb, *Ub, *Gb; /* m: gap, rate, acceleration at ta and tb */
    /* contacts at an event */
    double *g, *U, *Um, *vsc, *vpre, *tolg, *tolU, *P, *tail, *Uprev, *rest_from;
    long *burst;
    unsigned char *hit, *flag;
    int *idx;
    double *Dsub, *bsub, *zsub, *wsub;
    pd_lcp_solver *lcp;
    /* GSL */
    gsl_odeiv2_system sys;
    gsl_odeiv2_step *step, *probe;
    gsl_odeiv2_control *ctl;
    gsl_odeiv2_evolve *evo;
    pd_state st;
    char *block;
} edg;

/* ---- workspace ---------------------------------------------------------- */

/* Lay every array out in one block (base NULL: only count the bytes). */
static size_t layout(edg *w, char *base)
{
    size_t off = 0, n = (size_t)w->n, m = w->m > 0 ? (size_t)w->m : 1, d = (size_t)w->dim;
    size_t k = (size_t)w->kmax;
    /* each array 16-byte aligned; base NULL: off only counts (the total) */
#define TAKE(ptr, count, type)                                                                     \
    do {                                                                                           \
        off = (off + 15u) & ~(size_t)15u;                                                          \
        if (base)                                                                                  \
            (ptr) = (type *)(void *)(base + off);                                                  \
        off += (size_t)(count) * sizeof(type);                                                     \
    } while (0)
    /* A: flags, list, places; D_AA's LU (kmax^2) and pivots; lambda_A */
    TAKE(w->inA, m, unsigned char);
    TAKE(w->idxA, m, int);
    TAKE(w->posA, m, int);
    TAKE(w->Dlu, k * k, double);
    TAKE(w->Dperm, m, int);
    TAKE(w->lam, m, double);
    TAKE(w->tmpA, m, double);
    /* q = qref + d: the reference, K qref, its gaps and their rounding scale */
    TAKE(w->qref, n, double);
    TAKE(w->Kqref, n, double);
    TAKE(w->gref, m, double);
    TAKE(w->gscale, m, double);
    /* GSL's states (dim = 2 n + m): y, the step's start ya,
     * rates fa fb, probe yp, event yev, error yerr */
    TAKE(w->y, d, double);
    TAKE(w->ya, d, double);
    TAKE(w->fa, d, double);
    TAKE(w->fb, d, double);
    TAKE(w->yp, d, double);
    TAKE(w->yev, d, double);
    TAKE(w->yerr, d, double);
    TAKE(w->acc, n, double);
    TAKE(w->qs, n, double);
    TAKE(w->vs, n, double);
    /* gap, rate, acceleration at ta, then at tb */
    TAKE(w->ga, m, double);
    TAKE(w->Ua, m, double);
    TAKE(w->Ga, m, double);
    TAKE(w->gb, m, double);
    TAKE(w->Ub, m, double);
    TAKE(w->Gb, m, double);
    /* an event's gaps, rates and tolerances; impacts' bookkeeping */
    TAKE(w->g, m, double);
    TAKE(w->U, m, double);
    TAKE(w->Um, m, double);
    TAKE(w->vsc, m, double);
    TAKE(w->vpre, m, double);
    TAKE(w->tolg, m, double);
    TAKE(w->tolU, m, double);
    TAKE(w->P, m, double);
    TAKE(w->zout, m, double);
    TAKE(w->tail, m, double);
    TAKE(w->Uprev, m, double);
    TAKE(w->rest_from, m, double);
    TAKE(w->burst, m, long);
    TAKE(w->hit, m, unsigned char);
    TAKE(w->flag, m, unsigned char);
    TAKE(w->idx, m, int);
    /* an LCP's block (kmax^2) and vectors */
    TAKE(w->Dsub, k * k, double);
    TAKE(w->bsub, m, double);
    TAKE(w->zsub, m, double);
    TAKE(w->wsub, m, double);
    /* the reported state */
    TAKE(w->st.q, n, double);
    TAKE(w->st.acc, n, double);
    TAKE(w->st.v, n, double);
    TAKE(w->st.P, m, double);
    TAKE(w->st.g, m, double);
    TAKE(w->st.active, m, unsigned char);
#undef TAKE
    return off;
}

/* Release what edg_alloc took (NULL members are skipped). */
static void edg_free(edg *w)
{
    if (w->evo)
        gsl_odeiv2_evolve_free(w->evo);
    if (w->ctl)
        gsl_odeiv2_control_free(w->ctl);
    if (w->probe)
        gsl_odeiv2_step_free(w->probe);
    if (w->step)
        gsl_odeiv2_step_free(w->step);
    pd_lcp_solver_free(w->lcp);
    pd_factor_free(w->fac);
    free(w->block);
}

static int ode_rhs(double t, const double y[], double dydt[], void *params);

/* Every array, the LCP workspace and the GSL objects, once per run. */
static int edg_alloc(edg *w, pd_err *err)
{
    size_t bytes = layout(w, NULL);
    w->block = calloc(1, bytes);
    if (w->block)
        layout(w, w->block);
    /* two rk8pd steppers: step advances, probe re-integrates from the step's start */
    w->step = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, (size_t)w->dim);
    w->probe = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, (size_t)w->dim);
    w->ctl = gsl_odeiv2_control_y_new(w->o.atol, w->o.rtol); /* per component atol + rtol |y| */
    w->evo = gsl_odeiv2_evolve_alloc((size_t)w->dim);
    w->lcp = pd_lcp_solver_alloc(w->o.lcp_solver, w->kmax, 0, err); /* dense blocks of kmax */
    if (!w->block || !w->step || !w->probe || !w->ctl || !w->evo || !w->lcp)
        return pd_err_set(err, PD_ENOMEM, "event-driven: out of memory for n = %d, m = %d", w->n,
                          w->m);
    w->sys = (gsl_odeiv2_system){ode_rhs, NULL, (size_t)w->dim, w};
    return PD_OK;
}

/* ---- checks ----------------------------------------------------------- */

/* Options in range. */
static int check_opts(const pd_edg_opts *o, pd_err *err)
{
    if (!(o->rtol > 0.0 && o->atol > 0.0 && isfinite(o->rtol) && isfinite(o->atol)))
        return pd_err_set(err, PD_EINVAL, "event-driven: rtol and atol must be finite and > 0");
    if (!(o->h_out >= 0.0) || !isfinite(o->h_out))
        return pd_err_set(err, PD_EINVAL, "event-driven: h_out must be finite and >= 0 (got %g)",
                          o->h_out);
    if (!(o->length_scale > 0.0) || !isfinite(o->length_scale) || !(o->time_unit > 0.0) ||
        !isfinite(o->time_unit))
        return pd_err_set(err, PD_EINVAL,
                          "event-driven: length_scale and time_unit must be "
                          "finite and > 0");
    if (o->max_events < 1 || o->max_burst < 1)
        return pd_err_set(err, PD_EINVAL, "event-driven: budgets must be >= 1");
    return PD_OK;
}

pd_edg_opts pd_edg_default_opts(void)
{
    return (pd_edg_opts){.rtol = 1e-12, /* rk8pd's tolerances */
                         .atol = 1e-14,
                         .h_out = 0.0,
                         .impacts_only = 0,
                         .no_accumulation = 0,
                         .max_events = 1000000L,
                         .max_burst = 100000L, /* impacts of one contact's accumulation */
                         .length_scale = 1.0,
                         .time_unit = 1.0,
                         .on_step = NULL,
                         .on_step_ctx = NULL,
                         .factor = PD_FACTOR_AUTO,
                         .lcp_solver = PD_LCP_AUTO};
}

/* Model, interval and initial state; the message names what is wrong. */
static int check_inputs(const pd_model *md, double t0, const double *q0, const double *v0,
                        double t1, pd_err *err)
{
    int rc = pd_model_check(md, err);
    if (rc || (rc = pd_model_refuse_yield(md, "event-general", err)))
        return rc;
    if (!isfinite(t0) || !isfinite(t1) || !(t1 > t0))
        return pd_err_set(err, PD_EINVAL, "event-driven: t1 = %g must be finite and after t0 = %g",
                          t1, t0);
    for (int i = 0; i < md->n; i++)
        if ((q0 && !isfinite(q0[i])) || (v0 && !isfinite(v0[i])))
            return pd_err_set(err, PD_EINVAL, "event-driven: initial state of dof %d is not finite",
                              i);
    return PD_OK;
}

/* ---- linear algebra ----------------------------------------------------- */

/* W_a^T x. */
static double wdot(const edg *w, int a, const double *x)
{
    return pd_matrix_col_dot(w->W, a, x);
}

/* x += s M^-1 W_a. */
static void add_minv_w(const edg *w, int a, double s, double *x)
{
    pd_factor_add_impulse(w->fac, &a, 1, &s, x);
}

/* M factored once (What with h = 0): M^-1 W and D = W^T M^-1 W with it. */
static int factor_mass(edg *w, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    w->fac = pd_factor_alloc(w->md, 0.0, 1.0, w->o.factor, err); /* What(h = 0) = M */
    if (!w->fac)
        return err && err->status == PD_ESINGULAR
                   ? pd_err_set(err, PD_ESINGULAR, "event-driven: the mass matrix M is singular")
                   : err->status;
    return PD_OK;
}

/* Dsub = D[idx, idx] for k <= kmax contacts. */
static void delassus(const edg *w, const int *idx, int k, double *Dsub)
{
    pd_factor_delassus_dense(w->fac, idx, k, Dsub);
}

/* k contacts at once must fit the dense blocks. */
static int set_fits(const edg *w, int k, double t, pd_err *err)
{
    if (k <= w->kmax)
        return PD_OK;
    return pd_err_set(err, PD_EBUDGET,
                      "event-driven: %d contacts at zero gap at once at t = %.9g s (at most %d)", k,
                      t * w->o.time_unit, w->kmax);
}

/* Index list of A from the flags inA, and the LU of D_AA. */
static int factor_set(edg *w, double t, pd_err *err)
{
    w->nA = 0;
    for (int a = 0; a < w->m; a++) {
        /* idxA: A increasing; posA[a]: a's place in it, or -1 */
        w->posA[a] = -1;
        if (w->inA[a]) {
            w->posA[a] = w->nA;
            w->idxA[w->nA++] = a;
        }
    }
    if (set_fits(w, w->nA, t, err))
        return PD_EBUDGET;
    /* D_AA = W_A^T M^-1 W_A, LU with a relative pivot floor: dependent contacts fail */
    delassus(w, w->idxA, w->nA, w->Dlu);
    if (w->nA && pd_dense_lu(w->nA, w->Dlu, w->nA, w->Dperm, EDG_SINGULAR))
        return pd_err_set(
            err, PD_ESINGULAR,
            "event-driven: the %d contacts in persistent contact at t = %.9g s (first: "
            "contact %d) are redundant (D_AA singular)",
            w->nA, t * w->o.time_unit, w->idxA[0]);
    return PD_OK;
}

/* x -= M^-1 W_A D_AA^-1 r_A, r_a = W_a^T x + shift_a (shift NULL = 0):
 * the M-orthogonal projection onto W_A^T x + shift_A = 0. */
static void project_on_A(edg *w, double *x, const double *shift)
{
    if (!w->nA)
        return;
    for (int r = 0; r < w->nA; r++) {
        int a = w->idxA[r];
        /* r_A = W_A^T x + shift_A */
        w->tmpA[r] = wdot(w, a, x) + (shift ? shift[a] : 0.0);
    }
    /* mu = D_AA^-1 r_A; x -= M^-1 W_A mu: W_A^T x + shift_A = r_A - D_AA mu = 0 */
    pd_dense_lu_solve(w->nA, w->Dlu, w->nA, w->Dperm, w->tmpA);
    for (int r = 0; r < w->nA; r++)
        add_minv_w(w, w->idxA[r], -w->tmpA[r], x);
}

/* Hold A exactly: g_A(q) = 0 and U_A(v) = 0. */
static void project(edg *w, double *y)
{
    if (!w->nA)
        return;
    project_on_A(w, y, w->gref);     /* g_A = gref_A + W_A^T d = 0 */
    project_on_A(w, y + w->n, NULL); /* U_A = W_A^T v = 0 */
}

/* ---- the smooth motion -------------------------------------------------- */

/* F(t), the limit from inside the current segment [seg_a, seg_b]. */
static void force_at(const edg *w, double t, double *out)
{
    const pd_model *md = w->md;
    if (!md->force) {
        memset(out, 0, (size_t)w->n * sizeof(double));
        return;
    }
    /* t kept in the segment: its first half takes the right limit
     * at seg_a, its second the left one at seg_b */
    double tc = fmin(fmax(t, w->seg_a), w->seg_b);
    md->force(tc, tc - w->seg_a <= w->seg_b - tc ? +1 : -1, out, md->force_ctx);
}

/* acc = M^-1 (F - C v - K q + W_A lambda_A), q = qref + d, with
 * D_AA lambda_A = -W_A^T M^-1 (F - C v - K q)  (lambda_A left in w->lam). */
static void accel(edg *w, double t, const double *d, const double *v, double *acc)
{
    int n = w->n;
    /* acc = F - C v - K (qref + d), K qref kept */
    force_at(w, t, acc);
    pd_matrix_gemv(&w->md->C, -1.0, v, 1.0, acc);
    pd_matrix_gemv(&w->md->K, -1.0, d, 1.0, acc);
    for (int i = 0; i < n; i++)
        acc[i] -= w->Kqref[i];
    pd_factor_solve(w->fac, acc); /* a_free = M^-1 (F - C v - K q) */
    if (!w->nA)
        return;
    /* D_AA lambda_A = -W_A^T a_free: the held gaps do not accelerate */
    for (int r = 0; r < w->nA; r++)
        w->lam[r] = -wdot(w, w->idxA[r], acc);
    pd_dense_lu_solve(w->nA, w->Dlu, w->nA, w->Dperm, w->lam);
    /* acc = a_free + M^-1 W_A lambda_A */
    for (int r = 0; r < w->nA; r++)
        add_minv_w(w, w->idxA[r], w->lam[r], acc);
}

/* y' = (v, q'', lambda) for GSL. */
static int ode_rhs(double t, const double y[], double dydt[], void *params)
{
    edg *w = params;
    int n = w->n;
    memcpy(dydt, y + n, (size_t)n * sizeof(double)); /* d' = v */
    accel(w, t, y, y + n, dydt + n);
    /* z' = lambda: 0 for a free contact */
    for (int a = 0; a < w->m; a++)
        dydt[2 * n + a] = w->posA[a] >= 0 ? w->lam[w->posA[a]] : 0.0;
    /* a non-finite acceleration stops GSL with an error */
    for (int i = n; i < 2 * n; i++)
        if (!isfinite(dydt[i]))
            return GSL_EBADFUNC;
    return GSL_SUCCESS;
}

/* yp = y(t), ta <= t <= tb: one rk8pd step of t - ta from (ta, ya). */
static int probe(edg *w, double t, pd_err *err)
{
    memcpy(w->yp, w->ya, (size_t)w->dim * sizeof(double));
    if (t == w->ta) /* the start itself */
        return PD_OK;
    /* one step of t - ta from (ta, ya) with its rate fa: the accepted path untouched */
    int s = gsl_odeiv2_step_apply(w->probe, w->ta, t - w->ta, w->yp, w->yerr, w->fa, NULL, &w->sys);
    if (s != GSL_SUCCESS)
        return pd_err_set(err, PD_ENUMERICAL,
                          "event-driven: re-integration to t = %.9g s failed: %s",
                          t * w->o.time_unit, gsl_strerror(s));
    return PD_OK;
}

/* Gap of contact a at q = qref + d: gref_a + W_a^T d. */
static double gap_of(const edg *w, int a, const double *d)
{
    return w->gref[a] + wdot(w, a, d);
}

/* Rounding level of a gap computed from the state y = (d, v) over a step
 * of length h: 4 eps (gscale_a + |gref_a| + sum_i |W_ia| (|d_i| + h |v_i|)). */
static double gap_noise(const edg *w, int a, const double *y, double h)
{
    double s = w->gscale[a] + fabs(w->gref[a]) + pd_matrix_col_absdot(w->W, a, y) +
               h * pd_matrix_col_absdot(w->W, a, y + w->n);
    return 4.0 * DBL_EPSILON * s;
}

/* K qref, gref = g0 + W^T qref and its scale |g0| + sum_i |W_ia qref_i|. */
static void set_reference(edg *w)
{
    pd_matrix_gemv(&w->md->K, 1.0, w->qref, 0.0, w->Kqref);
    for (int a = 0; a < w->m; a++) {
        w->gref[a] = w->md->g0[a] + wdot(w, a, w->qref);
        w->gscale[a] = fabs(w->md->g0[a]) + pd_matrix_col_absdot(w->W, a, w->qref);
    }
}

/* New reference at an event: qref += d, d = 0. */
static void rebase(edg *w)
{
    for (int i = 0; i < w->n; i++) {
        w->qref[i] += w->y[i];
        w->y[i] = 0.0;
    }
    set_reference(w);
}

/* Gap, rate and acceleration of every contact at both ends of the step. */
static void step_ends(edg *w)
{
    int n = w->n;
    for (int a = 0; a < w->m; a++) {
        w->ga[a] = gap_of(w, a, w->ya);
        w->Ua[a] = wdot(w, a, w->ya + n);
        w->Ga[a] = wdot(w, a, w->fa + n); /* G = W^T q'': the quintic's data */
        w->gb[a] = gap_of(w, a, w->y);
        w->Ub[a] = wdot(w, a, w->y + n);
        w->Gb[a] = wdot(w, a, w->fb + n);
    }
}

/* One accepted GSL step from t toward the segment end; fa, fb the rates at
 * both ends. */
static int step_once(edg *w, pd_err *err)
{
    w->ta = w->t;
    memcpy(w->ya, w->y, (size_t)w->dim * sizeof(double));
    int s = ode_rhs(w->ta, w->ya, w->fa, w); /* fa: the start rate */
    double h_try = w->h;
    /* GSL keeps the end rate of the last step as the next start rate: y, t or
     * the rates may have changed since (projection, event, breakpoint). */
    gsl_odeiv2_evolve_reset(w->evo);
    /* one accepted step toward seg_b; w->h: the next size */
    if (s == GSL_SUCCESS)
        s = gsl_odeiv2_evolve_apply(w->evo, w->ctl, w->step, &w->sys, &w->t, w->seg_b, &w->h, w->y);
    if (s == GSL_SUCCESS)
        s = ode_rhs(w->t, w->y, w->fb, w);
    if (s != GSL_SUCCESS)
        return pd_err_set(err, PD_ENONFINITE, "event-driven: integration failed at t = %.9g s: %s",
                          w->ta * w->o.time_unit, gsl_strerror(s));
    if (w->t == w->seg_b && w->h < h_try) /* a step cut at the segment end says nothing */
        w->h = h_try;
    w->tb = w->t;
    /* budget: EDG_STEPS_FLOOR + EDG_STEPS_PER_RADIAN w_max (t - t0) steps */
    if (++w->res->steps > EDG_STEPS_FLOOR + EDG_STEPS_PER_RADIAN * w->omega_max * (w->t - w->t0))
        return pd_err_set(err, PD_EBUDGET,
                          "event-driven: %ld integration steps by t = %.9g s (last %.3g s; budget "
                          "%g + %g per radian of the fastest mode exhausted): the motion is stiff "
                          "under its held contacts or chatters; Moreau-Jean (--method moreau) "
                          "runs it",
                          w->res->steps, w->t * w->o.time_unit, (w->tb - w->ta) * w->o.time_unit,
                          EDG_STEPS_FLOOR, EDG_STEPS_PER_RADIAN);
    step_ends(w);
    return PD_OK;
}

/* An upper bound of the fastest mode's frequency: sqrt of Gershgorin's
 * bound on M^-1 K, max_j sum_i |K_ij| / M_jj (K symmetric: its columns'
 * sums are its rows'; O(nnz)); 0 without stiffness. */
static double fastest_frequency(const pd_model *md)
{
    const pd_matrix *K = &md->K;
    double w2 = 0.0;
    for (int j = 0; j < md->n && K->kind != PD_MATRIX_ZERO; j++) {
        double col = 0.0, mj = pd_matrix_get(&md->M, j, j);
        /* col = sum_i |K_ij| over the stored entries */
        if (K->kind == PD_MATRIX_DENSE)
            for (int i = 0; i < md->n; i++)
                col += fabs(K->values[i + (size_t)j * K->rows]);
        else
            for (int p = K->colptr[j]; p < K->colptr[j + 1]; p++)
                col += fabs(K->values[p]);
        if (mj > 0.0) /* a massless dof bounds nothing */
            w2 = fmax(w2, col / mj);
    }
    return sqrt(w2);
}

/* ---- event location ----------------------------------------------------- */

/* The interpolated state (qs, vs) at fraction s of the step. */
static void interp_state(edg *w, double s)
{
    int n = w->n;
    double h = w->tb - w->ta;
    for (int i = 0; i < n; i++) {
        double p0[3] = {w->ya[i], w->ya[n + i], w->fa[n + i]};
        double p1[3] = {w->y[i], w->y[n + i], w->fb[n + i]};
        /* the quintic Hermite of (q, v, a) at both ends */
        pd_hermite5(p0, p1, h, s, &w->qs[i], &w->vs[i]);
    }
}

/* Minimum of the interpolant between s0 (rate < 0) and s1 (rate > 0):
 * bisection on the rate. */
static double min_between(const double p0[3], const double p1[3], double h, double s0, double s1)
{
    /* 60 halvings: below a double's spacing on [0, 1] */
    for (int it = 0; it < 60; it++) {
        double sm = 0.5 * (s0 + s1), f, fd;
        pd_hermite5(p0, p1, h, sm, &f, &fd);
        if (fd < 0.0)
            s0 = sm;
        else
            s1 = sm;
    }
    return 0.5 * (s0 + s1);
}

/* Gap of contact a near a shallow interpolant minimum at tm, on the true
 * motion: two Newton steps t -= U / G toward the true minimum; found when it
 * lies below -thr (a grazing impact), with the bracket [ta, t]. */
static int graze_check(edg *w, int a, double tm, double thr, double *lo, double *hi, int *found,
                       pd_err *err)
{
    int n = w->n, rc = PD_OK;
    for (int it = 0; it < 3 && !rc; it++) {
        if ((rc = probe(w, tm, err)))
            break;
        /* below zero beyond rounding on the true motion: a grazing impact in [ta, tm] */
        if (gap_of(w, a, w->yp) < -thr) {
            *lo = w->ta;
            *hi = tm;
            *found = 1;
            break;
        }
        accel(w, tm, w->yp, w->yp + n, w->acc);
        double U = wdot(w, a, w->yp + n), G = wdot(w, a, w->acc);
        if (it == 2 || !(G > 0.0))
            break;
        /* Newton on the rate toward the minimum: t -= U / G (G > 0) */
        tm = fmin(tm - U / G, w->tb);
        if (!(tm > w->ta))
            break;
    }
    return rc;
}

/* Earliest closing of free contact a in the step on the quintic interpolant
 * of its gap: the first sample below -thr or an interior minimum below it
 * (grazing); a shallow interior minimum is checked on the true motion.
 * found = 1 with the bracket [lo, hi] (gap >= 0 at lo on the interpolant). */
static int scan_gap(edg *w, int a, double *lo, double *hi, int *found, pd_err *err)
{
    double h = w->tb - w->ta, thr = gap_noise(w, a, w->ya, h);
    double p0[3] = {w->ga[a], w->Ua[a], w->Ga[a]}, p1[3] = {w->gb[a], w->Ub[a], w->Gb[a]};
    /* the gap's quintic from (g, U, G) at both ends, sampled at k / EDG_GAP_SAMPLES; slo: the
     * last sample with g >= 0 */
    double slo = 0.0, sprev = 0.0, dprev = p0[1], gmin = HUGE_VAL, smin = 0.0;
    *found = 0;
    for (int k = 1; k <= EDG_GAP_SAMPLES; k++) {
        double s = (double)k / EDG_GAP_SAMPLES, f, fd;
        pd_hermite5(p0, p1, h, s, &f, &fd);
        if (dprev < 0.0 && fd > 0.0) { /* interior minimum in (sprev, s) */
            double sm = min_between(p0, p1, h, sprev, s), fm, fdm;
            pd_hermite5(p0, p1, h, sm, &fm, &fdm);
            /* the minimum below zero: a graze, bracketed by the
             * last sample at g >= 0 and the minimum */
            if (fm < -thr) {
                *lo = w->ta + slo * h;
                *hi = w->ta + sm * h;
                *found = 1;
                return PD_OK;
            }
            if (fm < gmin) {
                gmin = fm;
                smin = sm;
            }
        }
        /* a sample below zero beyond rounding: the gap closed */
        if (f < -thr) {
            *lo = w->ta + slo * h;
            *hi = k == EDG_GAP_SAMPLES ? w->tb : w->ta + s * h;
            *found = 1;
            return PD_OK;
        }
        if (f >= 0.0)
            slo = s;
        sprev = s;
        dprev = fd;
    }
    /* a minimum within EDG_NEAR of the gap's scale: the interpolant's error could hide a graze,
     * so the true motion decides */
    double near = EDG_NEAR * (fabs(p0[0]) + fabs(p1[0]) + h * (fabs(p0[1]) + fabs(p1[1])) +
                              h * h * (fabs(p0[2]) + fabs(p1[2])));
    if (gmin < near)
        return graze_check(w, a, w->ta + smin * h, thr, lo, hi, found, err);
    return PD_OK;
}

/* Earliest sample of the step where a held contact force is negative:
 * found = 1 with the contact *c and the bracket [lo, hi]. */
static void scan_force(edg *w, double *lo, double *hi, int *c, int *found)
{
    double h = w->tb - w->ta, sprev = 0.0;
    *found = 0;
    for (int k = 1; k <= EDG_FORCE_SAMPLES; k++) {
        double s = (double)k / EDG_FORCE_SAMPLES;
        double t = k == EDG_FORCE_SAMPLES ? w->tb : w->ta + s * h;
        interp_state(w, s);
        /* lambda_A at the interpolated state: the first negative one lets go */
        accel(w, t, w->qs, w->vs, w->acc);
        for (int r = 0; r < w->nA; r++)
            if (w->lam[r] < 0.0) {
                *c = w->idxA[r];
                *lo = w->ta + sprev * h;
                *hi = t;
                *found = 1;
                return;
            }
        sprev = s;
    }
}

/* The earliest candidate event of the accepted step (kind EV_NONE: none). */
static int scan(edg *w, int *kind, int *c, double *lo, double *hi, pd_err *err)
{
    int rc = PD_OK, found;
    double l, u;
    *kind = EV_NONE;
    for (int a = 0; a < w->m && !rc; a++) {
        if (w->inA[a])
            continue;
        /* a held contact's force is watched instead (scan_force);
         * the earliest bracket's end wins */
        rc = scan_gap(w, a, &l, &u, &found, err);
        if (!rc && found && (*kind == EV_NONE || u < *hi)) {
            *kind = EV_GAP;
            *c = a;
            *lo = l;
            *hi = u;
        }
    }
    if (rc || !w->nA)
        return rc;
    int cf;
    scan_force(w, &l, &u, &cf, &found);
    if (found && (*kind == EV_NONE || u < *hi)) {
        *kind = EV_FORCE;
        *c = cf;
        *lo = l;
        *hi = u;
    }
    return PD_OK;
}

/* Event function on the true motion at t (state left in yp): the gap of c
 * (EV_GAP) or its held contact force (EV_FORCE). */
static int value(edg *w, int kind, int c, double t, double *f, pd_err *err)
{
    int rc = probe(w, t, err);
    if (rc)
        return rc;
    if (kind == EV_GAP) {
        *f = gap_of(w, c, w->yp); /* g_c */
    } else {
        accel(w, t, w->yp, w->yp + w->n, w->acc);
        *f = w->lam[w->posA[c]]; /* lambda_c */
    }
    return PD_OK;
}

/* Illinois regula falsi on f(lo) >= 0 > f(hi) to adjacent doubles, bisecting
 * when the bracket fails to halve in three iterations; *t_ev = hi side
 * (f <= 0 there), its state in yp. */
static int illinois(edg *w, int kind, int c, double lo, double flo, double hi, double fhi,
                    double *t_ev, pd_err *err)
{
    int side = 0, rc = PD_OK;
    double wref = hi - lo, last = NAN;
    for (int it = 0; it < 200 && !rc; it++) {
        /* adjacent doubles (4 ulps): done */
        if (!(hi - lo > 4.0 * DBL_EPSILON * fmax(fabs(lo), fabs(hi))))
            break;
        /* regula falsi: the secant's zero */
        double tc = (flo * hi - fhi * lo) / (flo - fhi), f;
        /* every third iteration: a bisection unless the bracket halved since */
        if (it % 3 == 0 && it > 0) {
            if (hi - lo > 0.5 * wref)
                tc = 0.5 * (lo + hi);
            wref = hi - lo;
        }
        /* a secant point outside (rounding): bisect */
        if (!(tc > lo && tc < hi))
            tc = 0.5 * (lo + hi);
        if (tc <= lo || tc >= hi)
            break;
        if ((rc = value(w, kind, c, tc, &f, err)))
            break;
        last = tc;
        if (f < 0.0) {
            hi = tc;
            fhi = f;
            /* Illinois: the same side twice halves the kept end's f, so the secant leaves it */
            if (side == -1)
                flo *= 0.5;
            side = -1;
        } else {
            lo = tc;
            flo = f;
            if (side == 1)
                fhi *= 0.5;
            side = 1;
        }
    }
    /* f <= 0 at hi: the event, its state in yp */
    *t_ev = hi;
    if (!rc && last != hi)
        rc = probe(w, hi, err);
    return rc;
}

/* A contact that crossed before t (state in yp): a free gap below its zero
 * tolerance, or a held force below zero.  Returns 1 with its kind and index. */
static int earlier_event(edg *w, double t, int c, int *kind, int *a_out)
{
    int n = w->n;
    for (int a = 0; a < w->m; a++) {
        if (w->inA[a] || a == c)
            continue;
        double g = gap_of(w, a, w->yp), U = wdot(w, a, w->yp + n);
        /* zero: EDG_ZERO of the rounding scale, plus 64 ulps of t at its rate */
        double tol = EDG_ZERO * gap_noise(w, a, w->yp, 0.0) / (4.0 * DBL_EPSILON) +
                     64.0 * DBL_EPSILON * fabs(t) * fabs(U);
        if (g < -tol) {
            *kind = EV_GAP;
            *a_out = a;
            return 1;
        }
    }
    if (!w->nA)
        return 0;
    /* a held force already negative at t */
    accel(w, t, w->yp, w->yp + n, w->acc);
    for (int r = 0; r < w->nA; r++)
        if (w->lam[r] < 0.0 && w->idxA[r] != c) {
            *kind = EV_FORCE;
            *a_out = w->idxA[r];
            return 1;
        }
    return 0;
}

/* Locate the candidate (kind, c) bracketed by [lo, hi] on the true motion.
 * On return w->yev holds the state at *t_ev; *kind = EV_NONE when the true
 * motion has no event at hi (then the step is cut there). */
static int locate(edg *w, int *kind, int *c, double lo, double hi, double *t_ev, pd_err *err)
{
    int rc = PD_OK;
    if (!(hi > w->ta)) { /* a dip at the very start is rounding: no event */
        *kind = EV_NONE;
        memcpy(w->yev, w->y, (size_t)w->dim * sizeof(double));
        *t_ev = w->tb;
        return PD_OK;
    }
    /* each round locates a crossing; another contact's crossing before it starts the
     * next (m + 2 rounds at most) */
    for (int round = 0; round <= w->m + 1 && !rc; round++) {
        double fhi, flo, thr = *kind == EV_GAP ? gap_noise(w, *c, w->ya, w->tb - w->ta) : 0.0;
        if ((rc = value(w, *kind, *c, hi, &fhi, err)))
            break;
        if (!(fhi < -thr)) { /* the interpolant was wrong: no event, cut the step at hi */
            if (round == 0)
                *kind = EV_NONE;
            *t_ev = hi;
            break;
        }
        /* f(lo) >= 0 kept: lo falls back to ta (the step starts at g >= 0, lambda >= 0) */
        flo = 0.0;
        if (lo > w->ta && (rc = value(w, *kind, *c, lo, &flo, err)))
            break;
        if (lo <= w->ta || flo < 0.0) {
            lo = w->ta;
            flo = 0.0;
        }
        if ((rc = illinois(w, *kind, *c, lo, flo, hi, fhi, t_ev, err)))
            break;
        if (!earlier_event(w, *t_ev, *c, kind, c))
            break;
        lo = w->ta;
        hi = *t_ev;
    }
    memcpy(w->yev, w->yp, (size_t)w->dim * sizeof(double));
    return rc;
}

/* ---- observer ----------------------------------------------------------- */

/* Report state y at t (with the event's impulses when with_P). */
static void fill_state(edg *w, double t, const double *y, int with_P)
{
    pd_state *st = &w->st;
    st->step = w->res->steps;
    st->t = t;
    for (int i = 0; i < w->n; i++)
        st->q[i] = w->qref[i] + y[i]; /* q = qref + d */
    memcpy(st->v, y + w->n, (size_t)w->n * sizeof(double));
    for (int a = 0; a < w->m; a++) {
        st->g[a] = gap_of(w, a, y);
        st->P[a] = with_P ? w->P[a] : 0.0;
        st->active[a] = w->inA[a];
    }
    st->nactive = w->nA;
    st->lcp_pivots = with_P ? w->lcp_pivots : 0;
    st->lcp_solver = with_P && w->lcp_pivots ? "lemke" : NULL;
}

enum { TO_OBSERVER = 1, TO_ON_STEP = 2 };

/* Report state y at t (with the event's impulses when with_P) to the
 * observer and/or on_step (with the accelerations). */
static void emit(edg *w, double t, const double *y, int with_P, int to)
{
    if (w->stopped)
        return;
    if ((to & TO_ON_STEP) && w->o.on_step) {
        fill_state(w, t, y, with_P);
        /* on_step gets the accelerations too */
        accel(w, t, y, y + w->n, w->st.acc);
        w->st.has_acc = 1;
        if (w->o.on_step(&w->st, w->o.on_step_ctx) > 0)
            w->stopped = 1;
    }
    if (!(to & TO_OBSERVER) || !w->obs || w->stopped)
        return;
    fill_state(w, t, y, with_P);
    /* a sampler's P: the held forces' integral since the last report (z
     * holds int lambda dt and is constant while a contact is free, so a
     * free contact's P is its impacts' bit for bit) */
    for (int a = 0; w->sample_forces && a < w->m; a++) {
        double z = y[2 * w->n + a];
        w->st.P[a] += z - w->zout[a];
        w->zout[a] = z;
    }
    w->st.has_acc = 0;
    w->last_emit = t;
    if (w->obs(&w->st, w->obs_ctx) > 0)
        w->stopped = 1;
}

/* Output times t0 + k h_out in (ta, t_end], re-integrated from the step
 * start (the accepted path is untouched). */
static int emit_grid(edg *w, double t_end, pd_err *err)
{
    int rc = PD_OK;
    if (!(w->o.h_out > 0.0) || !w->obs)
        return PD_OK;
    for (;;) {
        double tk = w->t0 + (double)w->next_out * w->o.h_out;
        if (tk > t_end || tk > w->t1 || w->stopped)
            break;
        /* the output time re-integrated from ta, then put on A */
        if ((rc = probe(w, fmax(tk, w->ta), err)))
            break;
        project(w, w->yp);
        emit(w, tk, w->yp, 0, TO_OBSERVER);
        w->next_out++;
    }
    return rc;
}

/* ---- contacts at an event ---------------------------------------------- */

/* Gaps, rates and their zero tolerances for every contact at t: a gap is
 * zero below 1e-12 of its rounding scale (plus 64 ulp of t at its rate), a
 * rate below 1e-12 of sum_i |W_ia v_i| plus vpre (the velocity scale before
 * an impact and that of its LCP). */
static void measure(edg *w, double t)
{
    int n = w->n;
    const double *d = w->y, *v = w->y + n;
    for (int a = 0; a < w->m; a++) {
        double vs = pd_matrix_col_absdot(w->W, a, v);
        w->g[a] = gap_of(w, a, d);
        w->U[a] = wdot(w, a, v);
        w->vsc[a] = vs;
        /* gap_noise / (4 eps) is the rounding scale itself */
        w->tolg[a] = EDG_ZERO * gap_noise(w, a, w->y, 0.0) / (4.0 * DBL_EPSILON) +
                     64.0 * DBL_EPSILON * fabs(t) * fabs(w->U[a]);
        w->tolU[a] = EDG_ZERO * (vs + w->vpre[a]);
    }
}

/* Count an event; PD_EBUDGET past the budget, or after EDG_STUCK events
 * at one instant (within 64 ulp): the run would make no progress. */
static int count_event(edg *w, double t, const char *what, int c, pd_err *err)
{
    /* events within 64 ulps of the last: one instant */
    w->same_instant = t - w->last_event <= 64.0 * DBL_EPSILON * fabs(t) ? w->same_instant + 1 : 0;
    w->last_event = t;
    if (w->same_instant > EDG_STUCK)
        return pd_err_set(err, PD_EBUDGET,
                          "event-driven: no progress at t = %.9g s: %ld events at one instant "
                          "(last: %s of contact %d)",
                          t * w->o.time_unit, w->same_instant, what, c);
    if (++w->res->events > w->o.max_events)
        return pd_err_set(err, PD_EBUDGET,
                          "event-driven: %ld events by t = %.9g s (budget exhausted; last: %s of "
                          "contact %d)",
                          w->res->events - 1, t * w->o.time_unit, what, c);
    return PD_OK;
}

/* The rates after an impact carry the rounding of its LCP: vpre_a +=
 * max|b| + max|D_II| max P (velocity scale of the LCP data). */
static void lcp_rounding(edg *w, int nI)
{
    double bmax = 0.0, Dmax = 0.0, Pmax = 0.0;
    for (int r = 0; r < nI; r++) {
        bmax = fmax(bmax, fabs(w->bsub[r]));
        Pmax = fmax(Pmax, w->zsub[r]);
    }
    for (int k = 0; k < nI * nI; k++)
        Dmax = fmax(Dmax, fabs(w->Dsub[k]));
    for (int a = 0; a < w->m; a++)
        w->vpre[a] += bmax + Dmax * Pmax;
}

/* Newton's law over the nI contacts idx at zero gap, one LCP:
 *   U+ = U- + D_II P,  0 <= U+ + e min(U-, 0) ⊥ P >= 0,  v += M^-1 W_I P. */
static int impact(edg *w, double t, int nI, pd_err *err)
{
    pd_lcp_info info;
    pd_matrix D = pd_matrix_dense(nI, nI, w->Dsub);
    if (set_fits(w, nI, t, err))
        return PD_EBUDGET;
    delassus(w, w->idx, nI, w->Dsub);
    double bmax = 0.0;
    for (int r = 0; r < nI; r++) {
        int a = w->idx[r];
        /* b = U- + e min(U-, 0): w = U+ + e U- closing, U+ opening; a rate within tolU is 0 */
        double U = fabs(w->U[a]) <= w->tolU[a] ? 0.0 : w->U[a];
        w->bsub[r] = U + w->md->e[a] * fmin(U, 0.0);
        bmax = fmax(bmax, fabs(w->bsub[r]));
    }
    /* a rate at the rounding level of the impact (a contact resting in a row
     * that another one strikes) is zero: the LCP must not chase its sign */
    for (int r = 0; r < nI; r++)
        w->bsub[r] = fabs(w->bsub[r]) <= EDG_ZERO * bmax ? 0.0 : w->bsub[r];
    int rc = pd_lcp_solve(w->lcp, &D, w->bsub, NULL, w->zsub, w->wsub, &info);
    w->lcp_pivots = info.pivots;
    if (rc)
        return pd_err_set(err, rc,
                          "event-driven: impact LCP over %d contact(s) (first: contact %d) not "
                          "solved at t = %.9g s: %s",
                          nI, w->idx[0], t * w->o.time_unit, pd_lcp_outcome_name(info.outcome));
    for (int r = 0; r < nI; r++) {
        w->P[w->idx[r]] = w->zsub[r];
        /* v += M^-1 W_I P */
        add_minv_w(w, w->idx[r], w->zsub[r], w->y + w->n);
    }
    lcp_rounding(w, nI);
    return PD_OK;
}

/* Impact statistics of the closing contacts, and the burst budget: a burst
 * is a run of impacts of one contact with shrinking speeds. */
static int count_impacts(edg *w, double t, int nI, pd_err *err)
{
    for (int r = 0; r < nI; r++) {
        int a = w->idx[r];
        double speed = -w->Um[a];
        if (!(w->Um[a] < -w->tolU[a])) /* not closing: no impact */
            continue;
        w->hit[a] = 1;
        w->res->impacts++;
        if (isnan(w->res->first_impact))
            w->res->first_impact = t;
        /* a burst goes on while each impact is slower than the last */
        w->burst[a] = speed < w->Uprev[a] * (1.0 - 1e-12) ? w->burst[a] + 1 : 1;
        w->Uprev[a] = speed;
        if (w->burst[a] > w->o.max_burst)
            return pd_err_set(err, PD_EBUDGET,
                              "event-driven: accumulation of impacts of contact %d at t = %.9g s: "
                              "%ld impacts without reaching persistent contact%s",
                              a, t * w->o.time_unit, w->burst[a] - 1,
                              w->o.no_accumulation ? " (accumulation handling is off)" : "");
    }
    return PD_OK;
}

/* Bookkeeping of contacts entering (rest starts) and leaving A (detachment,
 * contact time), then the new flags. */
static void commit(edg *w, double t)
{
    for (int a = 0; a < w->m; a++) {
        if (w->inA[a] && !w->flag[a]) { /* detaches */
            w->res->detachments++;
            w->res->contact_time += fmax(0.0, t - w->rest_from[a]);
            w->burst[a] = 0;
            w->Uprev[a] = 0.0;
        } else if (!w->inA[a] && w->flag[a]) { /* comes to rest */
            w->rest_from[a] = t;
            w->burst[a] = 0;
            w->Uprev[a] = 0.0;
        }
        w->inA[a] = w->flag[a];
    }
}

/* Rates of the nJ contacts idx set exactly to zero (M-orthogonal projection)
 * when D_JJ is regular; they are zero to EDG_ZERO already. */
static void zero_rates(edg *w, int nJ)
{
    int n = w->n;
    if (!nJ)
        return;
    delassus(w, w->idx, nJ, w->Dsub);
    /* D_JJ singular (dependent contacts): the rates stay as they are */
    if (pd_dense_lu(nJ, w->Dsub, nJ, w->Dperm, EDG_SINGULAR))
        return;
    /* v -= M^-1 W_J D_JJ^-1 W_J^T v: U_J = 0 */
    for (int r = 0; r < nJ; r++)
        w->bsub[r] = wdot(w, w->idx[r], w->y + n);
    pd_dense_lu_solve(nJ, w->Dsub, nJ, w->Dperm, w->bsub);
    for (int r = 0; r < nJ; r++)
        add_minv_w(w, w->idx[r], -w->bsub[r], w->y + n);
}

/* Acceleration LCP over the nJ contacts idx at zero gap and rate:
 *   g''_J = D_JJ lambda + W_J^T M^-1 (F(t+) - C v - K q) >= 0 ⊥ lambda >= 0,
 * A = { lambda > 0 }; then A is factored and held. */
static int decide(edg *w, double t, int nJ, pd_err *err)
{
    pd_lcp_info info;
    int n = w->n, rc;
    if ((rc = set_fits(w, nJ, t, err)))
        return rc;
    zero_rates(w, nJ);
    memset(w->flag, 0, (size_t)w->m);
    w->nA = 0;
    if (nJ) {
        pd_matrix D = pd_matrix_dense(nJ, nJ, w->Dsub);
        /* nA = 0: acc is the free motion, b_J = W_J^T M^-1 (F(t+) - C v - K q) */
        accel(w, t, w->y, w->y + n, w->acc);
        delassus(w, w->idx, nJ, w->Dsub);
        for (int r = 0; r < nJ; r++)
            w->bsub[r] = wdot(w, w->idx[r], w->acc);
        rc = pd_lcp_solve(w->lcp, &D, w->bsub, NULL, w->zsub, w->wsub, &info);
        if (rc)
            return pd_err_set(err, rc,
                              "event-driven: contact-force LCP over %d contact(s) (first: contact "
                              "%d) not solved at t = %.9g s: %s",
                              nJ, w->idx[0], t * w->o.time_unit, pd_lcp_outcome_name(info.outcome));
        /* A = {lambda > 0} */
        for (int r = 0; r < nJ; r++)
            w->flag[w->idx[r]] = w->zsub[r] > 0.0;
    }
    commit(w, t);
    if ((rc = factor_set(w, t, err)))
        return rc;
    project(w, w->y); /* on A: g_A = 0, U_A = 0 */
    return PD_OK;
}

/* The contacts at zero gap and zero rate (except drop) into idx; count. */
static int zero_set(edg *w, double t, int drop)
{
    int nJ = 0;
    measure(w, t);
    /* in contact (gap within tolg, or held) and at rest (rate within tolU) */
    for (int a = 0; a < w->m; a++)
        if (a != drop && (w->g[a] <= w->tolg[a] || w->inA[a]) && fabs(w->U[a]) <= w->tolU[a])
            w->idx[nJ++] = a;
    return nJ;
}

/* Accumulation test for contact a bouncing off at U+ > 0 after an impact at t:
 * closing acceleration acl = -W_a^T q'' > 0, bounce height U+^2 / (2 acl)
 * below 1e-10 L, tail 2 U+ / (acl (1 - e)) inside the segment, and a held
 * contact force positive half-way through and at the end of the tail (frozen
 * state).  On success v has U_a = 0 and tail[a] is set. */
static int try_jump(edg *w, double t, int a, int *jumped, pd_err *err)
{
    int n = w->n, rc, ok = 1;
    double e = w->md->e[a], Up = w->U[a];
    *jumped = 0;
    /* e = 1 never accumulates; only a contact leaving at U+ > 0 can */
    if (!(e < 1.0) || !(Up > w->tolU[a]))
        return PD_OK;
    accel(w, t, w->y, w->y + n, w->acc);
    double acl = -wdot(w, a, w->acc); /* closing acceleration */
    /* on only when pushed back (acl > 0) with a bounce height U+^2 / (2 acl) <= 1e-10 L */
    if (!(acl > 0.0) || Up * Up / (2.0 * acl) > EDG_BOUNCE * w->o.length_scale)
        return PD_OK;
    /* the flights 2 U / acl with U -> e U sum to 2 U+ / (acl (1 - e)) */
    double tail = 2.0 * Up / (acl * (1.0 - e));
    if (!(t + tail < w->seg_b)) /* no breakpoint inside the tail */
        return PD_OK;
    w->inA[a] = 1; /* held tentatively, on a copy of the state */
    if (factor_set(w, t, NULL) == PD_OK) {
        memcpy(w->yp, w->y, (size_t)w->dim * sizeof(double));
        project_on_A(w, w->yp + n, NULL);
        /* the held force at mid-tail and at its end, the state frozen */
        for (int k = 1; k <= 2 && ok; k++) {
            accel(w, t + 0.5 * k * tail, w->yp, w->yp + n, w->acc);
            ok = w->lam[w->posA[a]] > 0.0;
        }
    } else {
        ok = 0;
    }
    w->inA[a] = 0;
    if ((rc = factor_set(w, t, err)))
        return rc;
    if (ok) {
        memcpy(w->y + n, w->yp + n, (size_t)n * sizeof(double)); /* U_a = 0 */
        w->tail[a] = tail;
        *jumped = 1;
    }
    return PD_OK;
}

/* Accumulations among the contacts that just bounced: jump them to
 * persistent contact and decide A again. */
static int jump_accumulations(edg *w, double t, int drop, pd_err *err)
{
    int rc = PD_OK, any = 0, jumped;
    if (w->o.no_accumulation)
        return PD_OK;
    memset(w->flag, 0, (size_t)w->m);
    for (int a = 0; a < w->m && !rc; a++) {
        if (!w->hit[a] || w->inA[a])
            continue;
        measure(w, t);
        if (!(rc = try_jump(w, t, a, &jumped, err)) && jumped) {
            w->flag[a] = 2; /* jumped */
            any = 1;
        }
    }
    if (rc || !any)
        return rc;
    for (int a = 0; a < w->m; a++)
        w->hit[a] = w->flag[a] == 2;
    /* hit: the jumped contacts only; A decided again with them at rest */
    if ((rc = decide(w, t, zero_set(w, t, drop), err)))
        return rc;
    for (int a = 0; a < w->m; a++)
        if (w->hit[a] && w->inA[a]) {
            w->res->accumulations++;
            w->rest_from[a] = t + w->tail[a]; /* rest from the accumulation point */
            w->burst[a] = 0;
        }
    return PD_OK;
}

/* The nI contacts idx at zero gap put exactly on it: qref projected
 * M-orthogonally onto g_I = 0 (when D_II is regular), then gref_I = 0. */
static void snap(edg *w, int nI)
{
    if (!nI)
        return;
    delassus(w, w->idx, nI, w->Dsub);
    if (pd_dense_lu(nI, w->Dsub, nI, w->Dperm, EDG_SINGULAR))
        return;
    /* qref -= M^-1 W_I D_II^-1 gref_I: g_I = 0 to rounding, then set exactly */
    for (int r = 0; r < nI; r++)
        w->bsub[r] = w->gref[w->idx[r]];
    pd_dense_lu_solve(nI, w->Dsub, nI, w->Dperm, w->bsub);
    for (int r = 0; r < nI; r++)
        add_minv_w(w, w->idx[r], -w->bsub[r], w->qref);
    set_reference(w);
    for (int r = 0; r < nI; r++)
        w->gref[w->idx[r]] = w->gscale[w->idx[r]] = 0.0;
}

/* All contacts at an event at t: the reference re-based, impacts of those at
 * zero gap (forced: the located one), then the new set A (drop: a detaching
 * contact, kept out). */
static int impact_event(edg *w, double t, int forced, int drop, pd_err *err)
{
    int nI = 0, closing = 0, rc;
    rebase(w);
    /* vpre: the rates' scale before the impact (measured with vpre = 0) */
    memset(w->vpre, 0, (size_t)w->m * sizeof(double));
    measure(w, t);
    memcpy(w->vpre, w->vsc, (size_t)w->m * sizeof(double));
    for (int a = 0; a < w->m; a++) {
        w->P[a] = 0.0;
        w->hit[a] = 0;
        /* at zero gap, the located one, or held: in the impact LCP */
        if (w->g[a] <= w->tolg[a] || a == forced || w->inA[a]) {
            w->idx[nI++] = a;
            closing |= w->U[a] < -w->tolU[a]; /* an impact only when one closes */
        }
    }
    if ((rc = set_fits(w, nI, t, err)))
        return rc;
    snap(w, nI);
    w->lcp_pivots = 0;
    if (closing) {
        memcpy(w->Um, w->U, (size_t)w->m * sizeof(double)); /* U- for the statistics */
        if ((rc = impact(w, t, nI, err)) || (rc = count_impacts(w, t, nI, err)))
            return rc;
    }
    if ((rc = decide(w, t, zero_set(w, t, drop), err)))
        return rc;
    /* accumulations only after an impact */
    return closing ? jump_accumulations(w, t, drop, err) : PD_OK;
}

/* ---- the run -------------------------------------------------------------- */

/* The smooth segment from t: up to the next breakpoint after t, or t1. */
static void next_segment(edg *w)
{
    const pd_model *md = w->md;
    /* past the breakpoints at or before t */
    while (w->next_break < md->nbreaks && md->breaks[w->next_break] <= w->t)
        w->next_break++;
    w->seg_a = w->t;
    w->seg_b = w->next_break < md->nbreaks ? fmin(md->breaks[w->next_break], w->t1) : w->t1;
}

/* A breakpoint reached: F(t+) from now on, persistent contacts re-decided. */
static int on_break(edg *w, pd_err *err)
{
    int rc = count_event(w, w->t, "breakpoint", -1, err);
    next_segment(w);
    if (!rc)
        rc = impact_event(w, w->t, -1, -1, err);
    if (!rc)
        emit(w, w->t, w->y, 1, TO_OBSERVER | TO_ON_STEP);
    return rc;
}

/* An impact (EV_GAP) or a detachment (EV_FORCE) of contact c at t. */
static int on_event(edg *w, int kind, int c, pd_err *err)
{
    int rc = count_event(w, w->t, kind == EV_GAP ? "impact" : "detachment", c, err);
    if (!rc)
        rc = impact_event(w, w->t, kind == EV_GAP ? c : -1, kind == EV_FORCE ? c : -1, err);
    if (rc)
        return rc;
    emit(w, w->t, w->y, 1, TO_OBSERVER | TO_ON_STEP);
    return PD_OK;
}

/* One accepted step, cut at its first event, which is then resolved. */
static int advance(edg *w, pd_err *err)
{
    int kind, c = -1, rc;
    double lo = 0.0, hi = 0.0, t_end;
    if ((rc = step_once(w, err)) || (rc = scan(w, &kind, &c, &lo, &hi, err)))
        return rc;
    t_end = w->tb;
    /* the candidate on the true motion: t_end <= tb */
    if (kind != EV_NONE && (rc = locate(w, &kind, &c, lo, hi, &t_end, err)))
        return rc;
    if ((rc = emit_grid(w, t_end, err)))
        return rc;
    /* the step cut at the event: the event's state */
    if (t_end < w->tb) {
        memcpy(w->y, w->yev, (size_t)w->dim * sizeof(double));
        w->t = t_end;
    }
    if (kind != EV_NONE) {
        emit(w, w->t, w->y, 0, TO_ON_STEP); /* the smooth motion up to the event */
        rc = on_event(w, kind, c, err);
    } else {
        project(w, w->y); /* back on A after the smooth step */
        emit(w, w->t, w->y, 0, TO_ON_STEP | (w->o.h_out > 0.0 ? 0 : TO_OBSERVER));
    }
    if (!rc && w->t >= w->seg_b && w->t < w->t1)
        rc = on_break(w, err);
    return rc;
}

/* Initial state, contacts at t0 resolved, the first report. */
static int start(edg *w, const double *q0, const double *v0, pd_err *err)
{
    int n = w->n, rc;
    for (int i = 0; i < n; i++) {
        w->qref[i] = q0 ? q0[i] : 0.0;
        w->y[n + i] = v0 ? v0[i] : 0.0;
    }
    set_reference(w);
    w->t = w->t0;
    next_segment(w);
    measure(w, w->t0);
    /* a penetrating start is refused */
    for (int a = 0; a < w->m; a++)
        if (w->g[a] < -w->tolg[a])
            return pd_err_set(err, PD_EINVAL,
                              "event-driven: initial gap of contact %d is %g < 0 (q0 penetrates)",
                              a, w->g[a]);
    w->h = 1e-4 * (w->t1 - w->t0); /* GSL's first try */
    if ((rc = impact_event(w, w->t0, -1, -1, err)))
        return rc;
    emit(w, w->t0, w->y, 1, TO_OBSERVER | TO_ON_STEP);
    w->next_out = 1;
    return PD_OK;
}

/* The run: checks, one allocation, the initial contacts, then accepted
 * steps and events up to t1; one exit path frees the workspace. */
int pd_edg_run(const pd_model *model, double t0, const double *q0, const double *v0, double t1,
               const pd_edg_opts *opts, pd_observer observer, void *ctx, pd_edg_result *res,
               pd_err *err)
{
    edg w;
    pd_edg_result local;
    int rc;
    pd_err_clear(err);
    memset(&w, 0, sizeof w);
    w.res = res ? res : &local;
    memset(w.res, 0, sizeof *w.res);
    w.res->first_impact = NAN;
    w.o = opts ? *opts : pd_edg_default_opts();
    if ((rc = check_opts(&w.o, err)) || (rc = check_inputs(model, t0, q0, v0, t1, err)))
        return rc;
    gsl_set_error_handler_off(); /* process-wide: GSL reports, never aborts */
    w.md = model;
    w.n = model->n;
    w.m = model->m;
    w.dim = 2 * w.n + w.m;
    w.W = &model->W;
    w.kmax = w.m < EDG_SET_MAX ? (w.m > 0 ? w.m : 1) : EDG_SET_MAX;
    w.t0 = t0;
    w.t1 = t1;
    w.obs = observer;
    w.obs_ctx = ctx;
    w.last_emit = NAN;
    w.last_event = -HUGE_VAL;
    /* the observer's P on a grid: the held forces' integral with the impacts */
    w.sample_forces = observer && w.o.h_out > 0.0 && !w.o.impacts_only;
    w.omega_max = fmax(fastest_frequency(model), PD_TWO_PI / (t1 - t0)); /* free bodies: a turn */
    if (!(rc = edg_alloc(&w, err)) && !(rc = factor_mass(&w, err)))
        rc = start(&w, q0, v0, err);
    while (!rc && !w.stopped && w.t < t1)
        rc = advance(&w, err);
    if (!rc) {
        /* the contacts still held at the end */
        for (int a = 0; a < w.m; a++)
            if (w.inA[a])
                w.res->contact_time += fmax(0.0, w.t - w.rest_from[a]);
        if (w.last_emit != w.t) /* the last state, once */
            emit(&w, w.t, w.y, 0, TO_OBSERVER);
    }
    edg_free(&w);
    return rc;
}
