/* penalty.c — the penalty baseline: a contact element per contact,
 * integrated with GSL's adaptive odeiv2 steppers (SPEC §2, issue 4).
 *
 *   M q'' + C q' + K q = F(t) + W lambda,   y = (q, v),  y' = (v, M^-1 r)
 *   engaged element a:  d = -g_a = -(g0_a + W_a^T q),  d' = -W_a^T v
 *     Kelvin-Voigt:  lambda_a = kc d + c_a d',
 *                    c_a = 2 zeta sqrt(kc m_a),  zeta = -ln e / sqrt(pi^2 + ln^2 e),
 *                    m_a = 1 / (W_a^T M^-1 W_a)                  (not clipped)
 *     Hertz-damp:    lambda_a = kc d^1.5 + c_a d^1.5 d',
 *                    c_a = 3 kc (1 - e^2) / (4 v_a),  v_a = d' when a engaged
 *
 * The right-hand side is frozen to the engaged set (each element keeps its
 * law on both sides of g = 0), so it is smooth within a step.  After every
 * accepted step the gaps are checked; a crossing (a sign change of the gap,
 * or a dip of its cubic Hermite interpolant) is located by Newton's method
 * on the gap with bracketing, each trial state integrated from the step's
 * start by a second "probe" integrator, and the step is cut there: the
 * element switches at the crossing and the stepper restarts.  The
 * integration also stops and restarts at every force breakpoint, the force
 * taken from the right limit at a segment's start and the left limit at its
 * end.  Output states (h_out) come from the probe integrator too, so they
 * do not perturb the trajectory.  See docs/methods.md, "Penalty baseline". */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "pd_alloc.h"
#include "pd_core.h"
#include "pd_engine.h"
#include "pd_factor.h"
#include "penalty_law.h"
#include "pd_null.h"

/* A GSL stepper the baseline offers. */
typedef struct pen_stepper {
    const char *name;
    const gsl_odeiv2_step_type *const *type;
    const gsl_odeiv2_step_type *const *probe; /* one-step type for probes */
    int implicit;                             /* needs the Jacobian */
} pen_stepper;

static const pen_stepper pen_steppers[] = {
    {"rk8pd", &gsl_odeiv2_step_rk8pd, &gsl_odeiv2_step_rk8pd, 0},
    {"rkf45", &gsl_odeiv2_step_rkf45, &gsl_odeiv2_step_rkf45, 0},
    {"rk4imp", &gsl_odeiv2_step_rk4imp, &gsl_odeiv2_step_rk4imp, 1},
    {"msbdf", &gsl_odeiv2_step_msbdf, &gsl_odeiv2_step_rk4imp, 1},
};

/* One run: the model, the engaged set, GSL objects and workspaces. */
#define PEN_MAX_STALL 1000 /* steps in a row that may end (nearly) where they began */
/* A step advancing t by less than this (relative to max(|t|, 1)) does not
 * count as progress: elements switching at one instant cut steps a few
 * doubles long, which would otherwise crawl on for hours. */
#define PEN_STALL_REL 1e-12

typedef struct pen {
    const pd_model *md;
    pd_penalty_opts o;
    const pen_stepper *stp;
    int n, m;
    size_t dim;               /* 2 n */
    pd_factor *fac;           /* M factored (What with h = 0); NULL when minv is used */
    double *minv;             /* n: 1 / M_ii when M is diagonal (factor auto), else NULL */
    double *cd;               /* m: damping constants c_a */
    double *sa;               /* m: W_a^T M^-1 W_a (inverse effective masses) */
    double vfloor;            /* smallest approach speed used by Hertz-damp */
    double vseen;             /* largest approach speed at an engagement so far */
    unsigned char *mode;      /* m: 1 = element engaged (the RHS is frozen to it) */
    double seg_lo, seg_hi;    /* the current force segment */
    double *F, *lam, *col;    /* n, m, n work */
    double *Aq, *Av;          /* n x n: Jacobian blocks before M^-1 (implicit steppers only) */
    double *y, *ya, *yt, *yo; /* dim: state, step start, trial, output */
    double *ys;               /* dim: state before a GSL step (retries) */
    double *ga, *Ua;          /* m: gaps and W^T v at the step start */
    double *fa, *fb;          /* dim: y' at the step start and end under the step's engaged set */
    double *fo;               /* dim: y' at the crossing state of the earliest crossing */
    double *fp;               /* dim: y' at the end of the last probe (valid if probe_f) */
    int probe_f;              /* the last probe ended with a step (fp is y' at its end) */
    double *acc_work;         /* dim: y' for the accelerations of an on_step report */
    gsl_odeiv2_system sys;
    gsl_odeiv2_driver *main_drv, *probe_drv;
    pd_observer observer;
    void *obs_ctx;
    double t_out0; /* t0 (outputs at t0 + k h_out) */
    long next_out; /* k of the next output */
    int stopped;   /* an observer asked to stop */
    long stalled;  /* consecutive steps that did not advance t (PEN_STALL_REL) */
    pd_state st;
    pd_penalty_result res;
} pen;

/* ---- options and setup ------------------------------------------------ */

/* The stepper table entry called name (NULL = rk8pd), or NULL. */
static const pen_stepper *find_stepper(const char *name)
{
    if (!name)
        return &pen_steppers[0];
    for (size_t i = 0; i < sizeof pen_steppers / sizeof pen_steppers[0]; i++)
        if (!strcmp(name, pen_steppers[i].name))
            return &pen_steppers[i];
    return NULL;
}

/* The adaptive integration's own: tolerances and a known stepper. */
static int check_opts(pen *p, double t0, double t1, pd_err *err)
{
    pd_penalty_opts *o = &p->o;
    int rc = pd_penalty_check_opts(o, t0, t1, "penalty", err);
    if (rc)
        return rc;
    /* GSL's tolerances: the adaptive steppers' own */
    if (!(o->rtol > 0.0) || !isfinite(o->rtol) || !(o->atol > 0.0) || !isfinite(o->atol))
        return pd_err_set(err, PD_EINVAL, "penalty: rtol and atol must be > 0 (got %g, %g)",
                          o->rtol, o->atol);
    if (!(p->stp = find_stepper(o->stepper)))
        return pd_err_set(err, PD_EINVAL,
                          "penalty: stepper \"%s\" is unknown (rk8pd, rkf45, rk4imp, msbdf, "
                          "newmark)",
                          o->stepper);
    return PD_OK;
}

pd_penalty_opts pd_penalty_default_opts(void)
{
    return (pd_penalty_opts){.law = PD_PENALTY_KELVIN,
                             .kc = 0.0, /* no default: refused until set */
                             .rtol = 1e-10,
                             .atol = 1e-12,
                             .stepper = "rk8pd",
                             .h = 0.0,
                             .h_out = 0.0,
                             .max_steps = 100000000L, /* accepted steps */
                             .time_unit = 1.0,
                             .on_step = NULL,
                             .on_step_ctx = NULL,
                             .factor = PD_FACTOR_AUTO,
                             .max_newton = 0};
}

/* Free what the run took (safe on a partly set up run). */
static void pen_free(pen *p)
{
    if (p->main_drv)
        gsl_odeiv2_driver_free(p->main_drv);
    if (p->probe_drv)
        gsl_odeiv2_driver_free(p->probe_drv);
    pd_factor_free(p->fac);
    free(p->minv);
    free(p->cd);
    free(p->sa);
    free(p->fa);
    free(p->fb);
    free(p->fo);
    free(p->fp);
    free(p->mode);
    free(p->F);
    free(p->lam);
    free(p->col);
    free(p->Aq);
    free(p->Av);
    free(p->y);
    free(p->ya);
    free(p->yt);
    free(p->yo);
    free(p->ys);
    free(p->ga);
    free(p->Ua);
    free(p->st.q);
    free(p->st.acc);
    free(p->acc_work);
    free(p->st.v);
    free(p->st.P);
    free(p->st.g);
    free(p->st.active);
}

/* Every array, sized once for (n, m). */
static int alloc_arrays(pen *p)
{
    size_t n = (size_t)p->n, d = p->dim;
    int m = p->m;
    /* the Jacobian's blocks for the implicit steppers only */
    size_t nn = p->stp->implicit ? n * n : 1;
    p->cd = pd_calloc(m, sizeof(double));
    p->sa = pd_calloc(m, sizeof(double));
    p->fa = calloc(d, sizeof(double));
    p->fb = calloc(d, sizeof(double));
    p->fo = calloc(d, sizeof(double));
    p->fp = calloc(d, sizeof(double));
    p->mode = pd_calloc(m, 1);
    p->F = calloc(n, sizeof(double));
    p->lam = pd_calloc(m, sizeof(double));
    p->col = calloc(n, sizeof(double));
    p->Aq = calloc(nn, sizeof(double));
    p->Av = calloc(nn, sizeof(double));
    p->y = calloc(d, sizeof(double));
    p->ya = calloc(d, sizeof(double));
    p->yt = calloc(d, sizeof(double));
    p->yo = calloc(d, sizeof(double));
    p->ys = calloc(d, sizeof(double));
    p->ga = pd_calloc(m, sizeof(double));
    p->Ua = pd_calloc(m, sizeof(double));
    p->st.q = calloc(n, sizeof(double));
    p->st.acc = calloc(n, sizeof(double));
    p->acc_work = calloc(d, sizeof(double));
    p->st.v = calloc(n, sizeof(double));
    p->st.P = pd_calloc(m, sizeof(double));
    p->st.g = pd_calloc(m, sizeof(double));
    p->st.active = pd_calloc(m, 1);
    return p->cd && p->sa && p->fa && p->fb && p->fo && p->fp && p->mode && p->F && p->lam &&
                   p->col && p->Aq && p->Av && p->y && p->ya && p->yt && p->yo && p->ys && p->ga &&
                   p->Ua && p->st.q && p->st.acc && p->acc_work && p->st.v && p->st.P && p->st.g &&
                   p->st.active
               ? PD_OK
               : PD_ENOMEM;
}

/* x = M^-1 x: entrywise for a diagonal M, else by the factor. */
static void mass_solve(const pen *p, double *x)
{
    if (p->minv)
        for (int i = 0; i < p->n; i++)
            x[i] *= p->minv[i]; /* M diagonal: entrywise */
    else
        pd_factor_solve(p->fac, x);
}

/* W_a^T M^-1 W_a, W_a dense in p->col. */
static double inverse_mass(pen *p, int a)
{
    double s = 0.0;
    if (!p->minv) {
        /* D_aa = W_a^T M^-1 W_a from the factor of What(h = 0) = M */
        pd_factor_delassus_dense(p->fac, &a, 1, &s);
        return s;
    }
    memset(p->col, 0, (size_t)p->n * sizeof(double));
    pd_matrix_col_axpy(&p->md->W, a, 1.0, p->col);
    for (int i = 0; i < p->n; i++)
        s += p->col[i] * p->col[i] * p->minv[i];
    return s;
}

/* M^-1 once: a diagonal M (and the automatic storage) is inverted entrywise,
 * any other factored; KV damping c_a = 2 zeta_a sqrt(kc m_a), m_a = 1 / (W_a^T
 * M^-1 W_a). */
static int setup_mass(pen *p, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    const pd_model *md = p->md;
    if (p->o.factor == PD_FACTOR_AUTO && pd_matrix_is_diagonal(&md->M)) {
        if (!(p->minv = malloc((size_t)p->n * sizeof(double))))
            return pd_err_set(err, PD_ENOMEM, "penalty: out of memory for n = %d", p->n);
        for (int i = 0; i < p->n; i++) {
            double Mii = pd_matrix_get(&md->M, i, i);
            /* a mass must be positive */
            if (!(Mii > 0.0))
                return pd_err_set(err, PD_ESINGULAR, "penalty: the mass matrix M is singular");
            p->minv[i] = 1.0 / Mii;
        }
        p->res.diagonal_mass = 1;
    } else if (!(p->fac = pd_factor_alloc(md, 0.0, 1.0, p->o.factor, err)))
        return err && err->status == PD_ESINGULAR
                   ? pd_err_set(err, PD_ESINGULAR, "penalty: the mass matrix M is singular")
                   : err->status;
    for (int a = 0; a < p->m; a++) {
        /* s_a = W_a^T M^-1 W_a = 1 / m_a, the contact's inverse effective mass */
        double s = inverse_mass(p, a);
        p->sa[a] = s;
        if (!(s > 0.0) || !isfinite(s))
            return pd_err_set(err, PD_EINVAL,
                              "penalty: contact %d has no effective mass (W_a^T M^-1 W_a = %g)", a,
                              s);
        /* c_a = 2 zeta(e) sqrt(kc m_a); Hertz-damp's waits for the approach speed */
        if (p->o.law == PD_PENALTY_KELVIN)
            p->cd[a] = pd_kelvin_damping(p->o.kc, md->e[a], 1.0 / s);
    }
    return PD_OK;
}

/* ---- the right-hand side ---------------------------------------------- */

/* g_a = g0_a + W_a^T q. */
static double gap_of(const pen *p, int a, const double *q)
{
    return p->md->g0[a] + pd_matrix_col_dot(&p->md->W, a, q);
}

/* U_a = W_a^T v (the gap rate). */
static double rate_of(const pen *p, int a, const double *v)
{
    return pd_matrix_col_dot(&p->md->W, a, v);
}

/* Element force (penalty_law.h). */
static double element_force(const pen *p, int a, double d, double dd)
{
    return pd_penalty_force(p->o.law, p->o.kc, p->cd[a], d, dd);
}

/* lambda of every contact at (q, v) under the engaged set (0 if released). */
static void contact_forces(const pen *p, const double *q, const double *v, double *lam)
{
    /* d = -g_a, d' = -U_a */
    for (int a = 0; a < p->m; a++)
        lam[a] = p->mode[a] ? element_force(p, a, -gap_of(p, a, q), -rate_of(p, a, v)) : 0.0;
}

/* F(t): right limit in the first half of the segment, left limit in the second. */
static void force_at(const pen *p, double t, double *F)
{
    if (p->md->force)
        p->md->force(t, t < 0.5 * (p->seg_lo + p->seg_hi) ? +1 : -1, F, p->md->force_ctx);
    else
        memset(F, 0, (size_t)p->n * sizeof(double));
}

/* y' = (v, M^-1 [F - C v - K q + W lambda]), uncounted. */
static int rhs_value(pen *p, double t, const double y[], double dydt[])
{
    const pd_model *md = p->md;
    int n = p->n;
    const double *q = y, *v = y + n;
    double *r = dydt + n;
    /* r = F - C v - K q + W lambda, then M^-1 r */
    force_at(p, t, r);
    pd_matrix_gemv(&md->C, -1.0, v, 1.0, r);
    pd_matrix_gemv(&md->K, -1.0, q, 1.0, r);
    if (p->m > 0) {
        contact_forces(p, q, v, p->lam);
        pd_matrix_gemv(&md->W, 1.0, p->lam, 1.0, r);
    }
    mass_solve(p, r);
    memmove(dydt, v, (size_t)n * sizeof(double)); /* q' = v */
    for (size_t i = 0; i < p->dim; i++)
        if (!isfinite(dydt[i]))
            return GSL_ERANGE; /* an overflowing trial step: retried smaller */
    return GSL_SUCCESS;
}

/* The right-hand side GSL calls (counted). */
static int rhs(double t, const double y[], double dydt[], void *params)
{
    pen *p = params;
    p->res.rhs++; /* every evaluation, probes included */
    return rhs_value(p, t, y, dydt);
}

/* d lambda / d d and d lambda / d d' of an engaged element (penalty_law.h). */
static void element_slopes(const pen *p, int a, double d, double dd, double *kd, double *cdd)
{
    pd_penalty_slopes(p->o.law, p->o.kc, p->cd[a], d, dd, kd, cdd);
}

/* Aq = -K - sum_a kd_a W_a W_a^T,  Av = -C - sum_a cdd_a W_a W_a^T. */
static void stiffness_blocks(pen *p, const double *q, const double *v)
{
    const pd_model *md = p->md;
    int n = p->n;
    pd_matrix_to_dense(&md->K, p->Aq);
    pd_matrix_to_dense(&md->C, p->Av);
    /* -K and -C */
    for (size_t k = 0; k < (size_t)n * n; k++) {
        p->Aq[k] = -p->Aq[k];
        p->Av[k] = -p->Av[k];
    }
    for (int a = 0; a < p->m; a++) {
        double kd, cdd;
        if (!p->mode[a])
            continue;
        /* kd = dlambda/dd, cdd = dlambda/dd'; d = -W_a^T q, so d(W_a lambda)/dq = -kd W_a W_a^T */
        element_slopes(p, a, -gap_of(p, a, q), -rate_of(p, a, v), &kd, &cdd);
        memset(p->col, 0, (size_t)n * sizeof(double));
        pd_matrix_col_axpy(&md->W, a, 1.0, p->col); /* W_a, dense */
        /* column j of W_a W_a^T is W_ja W_a */
        for (int j = 0; j < n; j++)
            if (p->col[j] != 0.0) {
                pd_matrix_col_axpy(&md->W, a, -kd * p->col[j], p->Aq + (size_t)j * n);
                pd_matrix_col_axpy(&md->W, a, -cdd * p->col[j], p->Av + (size_t)j * n);
            }
    }
}

/* dF/dt at t by a central difference of step dt kept inside the segment. */
static void force_rate(pen *p, double t, double *dF)
{
    double dt = 1e-6 * fmax(1.0, fabs(t));
    double tc = fmin(fmax(t, p->seg_lo + dt), p->seg_hi - dt);
    /* a segment shorter than 2 dt: dF/dt taken as 0 */
    if (!(p->seg_hi - p->seg_lo > 2.0 * dt)) {
        memset(dF, 0, (size_t)p->n * sizeof(double));
        return;
    }
    force_at(p, tc + dt, dF);
    force_at(p, tc - dt, p->col);
    /* (F(t + dt) - F(t - dt)) / (2 dt) */
    for (int i = 0; i < p->n; i++)
        dF[i] = (dF[i] - p->col[i]) / (2.0 * dt);
}

/* df/dy = [0 I; M^-1 Aq  M^-1 Av];  df/dt = (0, M^-1 dF/dt). */
static int jacobian(double t, const double y[], double *dfdy, double dfdt[], void *params)
{
    pen *p = params;
    int n = p->n;
    size_t dim = p->dim;
    memset(dfdy, 0, dim * dim * sizeof(double));
    /* GSL's dfdy is row-major: row i, column n + i is dq'/dv = I */
    for (int i = 0; i < n; i++)
        dfdy[(size_t)i * dim + (size_t)(n + i)] = 1.0;
    stiffness_blocks(p, y, y + n);
    /* rows n..2 n - 1: M^-1 Aq, then M^-1 Av, a column at a time */
    for (int blk = 0; blk < 2; blk++)
        for (int j = 0; j < n; j++) {
            const double *A = blk ? p->Av : p->Aq;
            memcpy(p->col, A + (size_t)j * n, (size_t)n * sizeof(double));
            mass_solve(p, p->col);
            for (int i = 0; i < n; i++)
                dfdy[(size_t)(n + i) * dim + (size_t)(blk * n + j)] = p->col[i];
        }
    /* df/dt = (0, M^-1 dF/dt) */
    force_rate(p, t, dfdt + n);
    for (int i = 0; i < n; i++)
        dfdt[i] = 0.0;
    mass_solve(p, dfdt + n);
    return GSL_SUCCESS;
}

/* Main and probe integrators (step, control, evolve), allocated once. */
static int alloc_drivers(pen *p, double span, pd_err *err)
{
    double h0 = span > 0.0 ? 1e-3 * span : 1.0; /* GSL's first try */
    p->sys.function = rhs;
    p->sys.jacobian = jacobian;
    p->sys.dimension = p->dim;
    p->sys.params = p;
    /* error control on y: atol + rtol |y_i| per component */
    p->main_drv = gsl_odeiv2_driver_alloc_y_new(&p->sys, *p->stp->type, h0, p->o.atol, p->o.rtol);
    p->probe_drv = gsl_odeiv2_driver_alloc_y_new(&p->sys, *p->stp->probe, h0, p->o.atol, p->o.rtol);
    if (!p->main_drv || !p->probe_drv)
        return pd_err_set(err, PD_ENOMEM, "penalty: out of memory for the GSL %s integrator",
                          p->stp->name);
    return PD_OK;
}

/* Model time t in seconds, for messages. */
static double seconds(const pen *p, double t)
{
    return t * p->o.time_unit;
}

/* Map a GSL failure at time t to a pd status with a message. */
static int gsl_failure(const pen *p, int status, double t, pd_err *err)
{
    if (status == GSL_ERANGE)
        return pd_err_set(err, PD_ENONFINITE,
                          "penalty: non-finite state or force at t = %.9g s (step size %s cannot "
                          "resolve the contact)",
                          seconds(p, t), p->stp->name);
    if (status == GSL_ENOMEM)
        return pd_err_set(err, PD_ENOMEM, "penalty: GSL ran out of memory at t = %.9g s",
                          seconds(p, t));
    return pd_err_set(err, PD_ENUMERICAL, "penalty: GSL stepper %s failed at t = %.9g s: %s",
                      p->stp->name, seconds(p, t), gsl_strerror(status));
}

/* One GSL evolve step from (*t, y) toward tb.  A trial that overflows (the
 * RHS reports it, or a non-finite state slips through the error control) is
 * undone and retried with h / 10, up to 30 times. */
static int evolve_once(pen *p, gsl_odeiv2_driver *d, double *t, double tb, double *h, double *y,
                       pd_err *err)
{
    double t_in = *t;
    memcpy(p->ys, y, p->dim * sizeof(double));
    for (int tries = 0; tries < 30; tries++) {
        int s = gsl_odeiv2_evolve_apply(d->e, d->c, d->s, &p->sys, t, tb, h, y);
        int finite = 1;
        /* GSL's error control may accept a non-finite state */
        for (size_t i = 0; i < p->dim && !s; i++)
            finite = finite && isfinite(y[i]);
        if (!s && finite)
            return PD_OK;
        if (s && s != GSL_ERANGE) /* a failure of its own */
            return gsl_failure(p, s, t_in, err);
        /* undone: state, time and the stepper's memory; h / 10 */
        memcpy(y, p->ys, p->dim * sizeof(double));
        *t = t_in;
        *h *= 0.1;
        gsl_odeiv2_evolve_reset(d->e);
        gsl_odeiv2_step_reset(d->s);
    }
    return gsl_failure(p, GSL_ERANGE, t_in, err);
}

/* ---- probes: controlled integration from the step start --------------- */

/* yb = y(tb) from (ta, ya) with the probe integrator (same engaged set). */
static int probe(pen *p, double ta, const double *ya, double tb, double *yb, pd_err *err)
{
    gsl_odeiv2_driver *d = p->probe_drv;
    double t = ta, h = tb - ta; /* first try: the whole span */
    memcpy(yb, ya, p->dim * sizeof(double));
    gsl_odeiv2_evolve_reset(d->e);
    gsl_odeiv2_step_reset(d->s);
    int rc = PD_OK;
    p->probe_f = 0;
    while (t < tb && !rc)
        rc = evolve_once(p, d, &t, tb, &h, yb, err);
    /* y' at tb from the stepper, where exact: one evaluation saved */
    if (!rc && t > ta && (*p->stp->probe)->gives_exact_dydt_out) {
        memcpy(p->fp, d->e->dydt_out, p->dim * sizeof(double));
        p->probe_f = 1;
    }
    return rc;
}

/* ---- observers ---------------------------------------------------------- */

/* The pd_state at (t, y) under the engaged set. */
static void fill_state(pen *p, double t, const double *y)
{
    int n = p->n;
    memcpy(p->st.q, y, (size_t)n * sizeof(double));
    memcpy(p->st.v, y + n, (size_t)n * sizeof(double));
    contact_forces(p, y, y + n, p->st.P); /* P holds the forces lambda */
    p->st.nactive = 0;
    for (int a = 0; a < p->m; a++) {
        p->st.g[a] = gap_of(p, a, y);
        p->st.active[a] = p->mode[a];
        p->st.nactive += p->mode[a];
    }
    p->st.t = t;
    p->st.step = p->res.steps;
    p->st.lcp_pivots = 0;
    p->st.has_acc = 0;
}

/* Call fn (if any) on the current pd_state; remember a stop request. */
static void notify(pen *p, pd_observer fn, void *ctx)
{
    if (fn && !p->stopped && fn(&p->st, ctx) > 0)
        p->stopped = 1;
}

/* on_step: the state at t (end of a step, or t0) with its accelerations:
 * from f = y' there under the engaged set when the caller has it (a step's
 * end without a switch: GSL's own evaluation), else evaluated (counted). */
static void notify_step(pen *p, double t, const double *f)
{
    if (!p->o.on_step || p->stopped)
        return;
    fill_state(p, t, p->y);
    /* acc: the v part of y', the caller's f or one evaluation */
    p->st.has_acc = f || rhs(t, p->y, p->acc_work, p) == GSL_SUCCESS;
    if (p->st.has_acc)
        memcpy(p->st.acc, (f ? f : p->acc_work) + p->n, (size_t)p->n * sizeof(double));
    notify(p, p->o.on_step, p->o.on_step_ctx);
}

/* Time of output k. */
static double out_time(const pen *p, long k)
{
    return p->t_out0 + (double)k * p->o.h_out;
}

/* Outputs t_k in (ta, tb), integrated from the step start (ta, ya). */
static int outputs_inside(pen *p, double ta, double tb, pd_err *err)
{
    double tprev = ta, tol = 1e-12 * fmax(1.0, fabs(tb));
    int rc;
    if (!p->observer || !(p->o.h_out > 0.0))
        return PD_OK;
    memcpy(p->yo, p->ya, p->dim * sizeof(double));
    while (!p->stopped && out_time(p, p->next_out) < tb - tol) {
        double tk = out_time(p, p->next_out++);
        if (tk <= tprev) /* at the start: already given */
            continue;
        /* from the last output: the probes chain, the step untouched */
        memcpy(p->yt, p->yo, p->dim * sizeof(double));
        if ((rc = probe(p, tprev, p->yt, tk, p->yo, err)))
            return rc;
        tprev = tk;
        fill_state(p, tk, p->yo);
        notify(p, p->observer, p->obs_ctx);
    }
    return PD_OK;
}

/* An output that falls on tb (within rounding) gets the end state. */
static void output_at_end(pen *p, double tb)
{
    double tol = 1e-12 * fmax(1.0, fabs(tb));
    if (!p->observer || !(p->o.h_out > 0.0))
        return;
    while (!p->stopped && out_time(p, p->next_out) <= tb + tol) {
        fill_state(p, out_time(p, p->next_out++), p->y);
        notify(p, p->observer, p->obs_ctx);
    }
}

/* ---- crossings ---------------------------------------------------------- */

/* Cubic Hermite on [0, h] through (f0, d0) and (f1, d1), at s. */
static double hermite(double f0, double d0, double f1, double d1, double h, double s)
{
    double x = s / h, x2 = x * x, x3 = x2 * x;
    /* h00 f0 + h10 h d0 + h01 f1 + h11 h d1 */
    return (2 * x3 - 3 * x2 + 1) * f0 + (x3 - 2 * x2 + x) * h * d0 + (-2 * x3 + 3 * x2) * f1 +
           (x3 - x2) * h * d1;
}

/* Interior critical points of that cubic (its derivative is a quadratic);
 * returns how many lie in (0, h). */
static int hermite_critical(double f0, double d0, double f1, double d1, double h, double s[2])
{
    /* H'(x)/h in x = s/h: A x^2 + B x + C */
    double D = (f1 - f0) / h;
    double A = 3.0 * (d0 + d1 - 2.0 * D), B = 2.0 * (3.0 * D - 2.0 * d0 - d1), C = d0;
    double r[2];
    int nr = 0, k = 0;
    /* A = 0 to rounding: a linear slope */
    if (fabs(A) <= 1e-14 * (fabs(B) + fabs(C))) {
        if (B != 0.0)
            r[nr++] = -C / B;
    } else {
        double disc = B * B - 4.0 * A * C;
        if (disc >= 0.0) {
            /* roots qq / A and C / qq: no cancellation */
            double sq = sqrt(disc), qq = -0.5 * (B + (B >= 0.0 ? sq : -sq));
            if (qq != 0.0) {
                r[nr++] = qq / A;
                r[nr++] = C / qq;
            }
        }
    }
    /* interior points only */
    for (int i = 0; i < nr; i++)
        if (r[i] > 0.0 && r[i] < 1.0)
            s[k++] = r[i] * h;
    return k;
}

/* The quintic Hermite of (f, f', f'') on [0, h] at time s: value, and slope in *df. */
static double quintic(const double e0[3], const double e1[3], double h, double s, double *df)
{
    double f;
    pd_hermite5(e0, e1, h, s / h, &f, df);
    return f;
}

/* Smallest value of that quintic over (0, h): sign changes of its slope on a
 * grid of 16, refined by bisection. */
static double quintic_min(const double e0[3], const double e1[3], double h)
{
    double best = fmin(e0[0], e1[0]), s0 = 0.0, d0 = e0[1], d1, d;
    for (int k = 1; k <= 16; k++) {
        double s1 = h * k / 16.0;
        quintic(e0, e1, h, s1, &d1);
        /* the slope turns upward: a minimum, bisected on the slope */
        if (d0 < 0.0 && d1 >= 0.0) {
            double lo = s0, hi = s1;
            for (int it = 0; it < 60; it++) {
                double mid = 0.5 * (lo + hi);
                quintic(e0, e1, h, mid, &d);
                *(d < 0.0 ? &lo : &hi) = mid;
            }
            best = fmin(best, quintic(e0, e1, h, 0.5 * (lo + hi), &d));
        }
        s0 = s1;
        d0 = d1;
    }
    return best;
}

/* y' at the step's ends under its engaged set: GSL's evolve evaluates both
 * (dydt_in, dydt_out) for every stepper offered; one that did not would get
 * them here, counted. */
static void step_rates(pen *p, double ta, double tb)
{
    const gsl_odeiv2_evolve *e = p->main_drv->e;
    const gsl_odeiv2_step_type *T = *p->stp->type;
    /* GSL's own evaluations when the stepper keeps them */
    if (T->can_use_dydt_in)
        memcpy(p->fa, e->dydt_in, p->dim * sizeof(double));
    else
        rhs(ta, p->ya, p->fa, p);
    if (T->gives_exact_dydt_out)
        memcpy(p->fb, e->dydt_out, p->dim * sizeof(double));
    else
        rhs(tb, p->y, p->fb, p);
}

/* phi = sigma g with sigma = +1 released, -1 engaged: a crossing makes phi < 0. */
static double phi_sign(const pen *p, int a)
{
    return p->mode[a] ? -1.0 : 1.0;
}

/* (phi, phi', phi'') of contact a at the step's start (e0) and end (e1). */
static void phi_jets(const pen *p, int a, double e0[3], double e1[3])
{
    double sg = phi_sign(p, a);
    int n = p->n;
    /* phi = sigma g, phi' = sigma U, phi'' = sigma W^T a */
    e0[0] = sg * p->ga[a];
    e0[1] = sg * p->Ua[a];
    e0[2] = sg * rate_of(p, a, p->fa + n);
    e1[0] = sg * gap_of(p, a, p->y);
    e1[1] = sg * rate_of(p, a, p->y + n);
    e1[2] = sg * rate_of(p, a, p->fb + n);
}

/* Whether element a may stay on the wrong side of g = 0 by the depth dep
 * (gap rate r) for up to h without the crossing being located: the element's
 * force there, for the time it takes to get that deep (dep / |r|, at most h),
 * changes the velocities by W_a^T M^-1 W_a |lambda| min(h, dep / |r|); with
 * that and dep itself within atol, locating the crossing would change the
 * state by less than GSL's error control allows a step.  (Hertz-damp's
 * force at depth dep is at most 1.75 kc dep^1.5.) */
static int tolerable(const pen *p, int a, double dep, double r, double h)
{
    double kc = p->o.kc, ar = fabs(r);
    dep = fabs(dep);
    if (!(dep <= p->o.atol)) /* deeper than atol: located */
        return 0;
    double lam =
        p->o.law == PD_PENALTY_KELVIN ? kc * dep + p->cd[a] * ar : 1.75 * kc * dep * sqrt(dep);
    double tw = ar > 0.0 ? fmin(h, dep / ar) : h; /* the time that deep */
    /* its velocity change s_a |lambda| tw within atol */
    return p->sa[a] * lam * tw <= p->o.atol;
}

/* Smallest s in (0, h] where the cubic of phi (ends a: start, b: end) may turn
 * negative: h if phi_b < 0, the dip's bottom if the cubic dips below zero,
 * else 0 (no crossing). */
static double crossing_bound(double fa, double da, double fb, double db, double h)
{
    double s[2];
    if (fb < 0.0) /* across at the end */
        return h;
    /* a dip: positive at the start, falling there, rising at the end */
    if (!(fa > 0.0 && da < 0.0 && db > 0.0))
        return 0.0;
    int k = hermite_critical(fa, da, fb, db, h, s);
    for (int i = 0; i < k; i++)
        if (hermite(fa, da, fb, db, h, s[i]) < 0.0)
            return s[i];
    return 0.0;
}

/* phi_a and its rate at ta + s (probe state left in p->yt). */
static int phi_at(pen *p, int a, double ta, double s, double *f, double *df, pd_err *err)
{
    int rc = probe(p, ta, p->ya, ta + s, p->yt, err);
    double sg = phi_sign(p, a);
    *f = sg * gap_of(p, a, p->yt);
    *df = sg * rate_of(p, a, p->yt + p->n);
    return rc;
}

/* Root of phi_a in (0, hi] with phi_a(hi) < 0: the quintic Hermite's root
 * (the cubic's where the quintic stays positive), then safeguarded Newton on
 * probes until the state is within the tolerance of the crossing (tolerable)
 * or converged; *s gets the crossing, p->yt the state there (the last trial
 * is the answer). */
static int locate_root(pen *p, int a, double ta, double hi, const double e0[3], const double e1[3],
                       double h, double *s, pd_err *err)
{
    double lo = 0.0, x = hi, f, df, d;
    int use5 = quintic(e0, e1, h, hi, &d) < 0.0; /* else the cubic */
    int rc;
    for (int it = 0; it < 60; it++) { /* the interpolant's root in [lo, x] by bisection */
        double mid = 0.5 * (lo + x);
        double v = use5 ? quintic(e0, e1, h, mid, &d) : hermite(e0[0], e0[1], e1[0], e1[1], h, mid);
        *(v < 0.0 ? &x : &lo) = mid;
    }
    lo = 0.0;
    /* Newton on probes, kept inside the bracket [lo, hi] with phi(hi) < 0 */
    for (int it = 0;; it++) {
        if ((rc = phi_at(p, a, ta, x, &f, &df, err)))
            return rc;
        *(f < 0.0 ? &hi : &lo) = x;
        double tol = 4.0 * DBL_EPSILON * (fabs(ta) + hi);
        double nx = df != 0.0 ? x - f / df : 0.5 * (lo + hi); /* Newton's step */
        /* exact, within the tolerance, converged, or 100 probes */
        if (f == 0.0 || tolerable(p, a, f, df, h) || fabs(nx - x) <= tol || hi - lo <= tol ||
            it == 100)
            break;
        x = nx > lo && nx < hi ? nx : 0.5 * (lo + hi);
    }
    *s = x;
    return PD_OK;
}

/* Engage or release element a at the current state p->y; Hertz-damp takes
 * c_a = 3 kc (1 - e^2) / (4 v_a) from the approach speed v_a = -W_a^T v. */
static void switch_element(pen *p, int a)
{
    p->mode[a] = (unsigned char)!p->mode[a];
    p->res.switches++;
    if (p->mode[a] && p->o.law == PD_PENALTY_HERTZDAMP) {
        double e = p->md->e[a], vimp = -rate_of(p, a, p->y + p->n); /* approach speed -U */
        /* the floor's 1e-3 of the largest so far */
        p->vseen = fmax(p->vseen, vimp);
        p->cd[a] = pd_hertz_damping(p->o.kc, e, vimp, p->vfloor, p->vseen);
    }
}

/* After a step (ta, ya) -> (*t, p->y): find the earliest crossing that must
 * be located; if any, cut the step there (p->y, *t, its rates in p->fb) and
 * return its contact in *which (else -1).  A crossing the tolerance lets
 * pass (tolerable: the end across by no more, a dip no deeper) is not
 * located: *across says an element ended the step across, to be switched
 * there. */
static int earliest_crossing(pen *p, double ta, double *t, int *which, int *across, pd_err *err)
{
    double h = *t - ta, best = h;
    int rc;
    *which = -1;
    *across = 0;
    for (int a = 0; a < p->m; a++) {
        double e0[3], e1[3], s;
        phi_jets(p, a, e0, e1);
        /* where the cubic of phi may first go negative (0: nowhere) */
        double bound = crossing_bound(e0[0], e0[1], e1[0], e1[1], h);
        if (!(bound > 0.0))
            continue;
        if (bound < h) { /* a dip: is the true phi negative at its bottom? */
            double f, df;
            if (tolerable(p, a, hermite(e0[0], e0[1], e1[0], e1[1], h, bound), 0.0, h))
                continue;
            if ((rc = phi_at(p, a, ta, bound, &f, &df, err)))
                return rc;
            if (f >= 0.0)
                continue;
        } else if (tolerable(p, a, e1[0], e1[1], h)) {
            *across = 1; /* switched at the end, not located */
            continue;
        }
        if ((rc = locate_root(p, a, ta, bound, e0, e1, h, &s, err)))
            return rc;
        /* the earliest crossing wins: its state and rates kept */
        if (s <= best) {
            best = s;
            *which = a;
            memcpy(p->yo, p->yt, p->dim * sizeof(double));
            if (p->probe_f)
                memcpy(p->fo, p->fp, p->dim * sizeof(double));
            else
                rhs(ta + s, p->yo, p->fo, p);
        }
    }
    /* the step cut at the crossing */
    if (*which >= 0) {
        memcpy(p->y, p->yo, p->dim * sizeof(double));
        memcpy(p->fb, p->fo, p->dim * sizeof(double));
        *t = ta + best;
    }
    return PD_OK;
}

/* Switch the located crossing's contact (which >= 0), and every other one
 * across at this state and still moving across (phi < 0, phi' <= 0): one
 * across by rounding but already coming back is left alone, else it would
 * switch back and forth at one instant.  Returns how many switched. */
static int apply_switches(pen *p, int which)
{
    int k = 0;
    for (int a = 0; a < p->m; a++) {
        double sg = phi_sign(p, a), phi = sg * gap_of(p, a, p->y);
        double dphi = sg * rate_of(p, a, p->y + p->n);
        /* the located one, and any other across and still moving across */
        if (a == which || (phi < 0.0 && dphi <= 0.0)) {
            switch_element(p, a);
            k++;
        }
    }
    return k;
}

/* Smallest gap a over the step (ta, ya) -> (ta + h, p->y): the cubic of
 * (g, U) tells whether it dips inside; then the quintic with g'' = W^T a at
 * both ends (GSL's own evaluations, p->fa and p->fb) gives its bottom. */
static double step_min_gap(pen *p, int a, double h)
{
    double g1 = gap_of(p, a, p->y), U1 = rate_of(p, a, p->y + p->n), s[2];
    double gmin = fmin(p->ga[a], g1), cub = gmin;
    int k = h > 0.0 ? hermite_critical(p->ga[a], p->Ua[a], g1, U1, h, s) : 0;
    for (int i = 0; i < k; i++)
        cub = fmin(cub, hermite(p->ga[a], p->Ua[a], g1, U1, h, s[i]));
    /* the cubic does not dip below the ends' minimum */
    if (!(cub < gmin))
        return cub;
    /* a dip: the quintic with g'' = W^T a at both ends finds its bottom */
    double e0[3] = {p->ga[a], p->Ua[a], rate_of(p, a, p->fa + p->n)};
    double e1[3] = {g1, U1, rate_of(p, a, p->fb + p->n)};
    return quintic_min(e0, e1, h);
}

/* min gap over the step and the largest engaged penetration rate at its end. */
static void track_extremes(pen *p, double h)
{
    for (int a = 0; a < p->m; a++) {
        p->res.min_gap = fmin(p->res.min_gap, step_min_gap(p, a, h));
        /* penetration rate -U */
        if (p->mode[a])
            p->res.max_penetration_velocity =
                fmax(p->res.max_penetration_velocity, -rate_of(p, a, p->y + p->n));
    }
}

/* ---- the run ------------------------------------------------------------ */

/* Remember the step start: state, gaps, gap rates. */
static void mark_start(pen *p)
{
    memcpy(p->ya, p->y, p->dim * sizeof(double));
    for (int a = 0; a < p->m; a++) {
        p->ga[a] = gap_of(p, a, p->y);
        p->Ua[a] = rate_of(p, a, p->y + p->n);
    }
}

/* One accepted step from *t toward tb, cut at the earliest crossing. */
static int one_step(pen *p, double *t, double tb, double *h, pd_err *err)
{
    gsl_odeiv2_driver *d = p->main_drv;
    double ta = *t;
    int which, across, rc;
    if (p->res.steps >= p->o.max_steps)
        return pd_err_set(err, PD_EBUDGET,
                          "penalty: budget of %ld accepted steps exhausted at t = %.9g s",
                          p->o.max_steps, seconds(p, ta));
    mark_start(p);
    /* one GSL step, the engaged set frozen: a smooth right-hand side */
    if ((rc = evolve_once(p, d, t, tb, h, p->y, err)))
        return rc;
    p->res.steps++;
    step_rates(p, ta, *t);
    if ((rc = earliest_crossing(p, ta, t, &which, &across, err)) ||
        (rc = outputs_inside(p, ta, *t, err)))
        return rc;
    /* progress: more than 1e-12 of t */
    p->stalled = *t - ta > PEN_STALL_REL * fmax(fabs(ta), 1.0) ? 0 : p->stalled + 1;
    if (p->stalled > PEN_MAX_STALL) /* switching back and forth at one instant */
        return pd_err_set(err, PD_ENUMERICAL,
                          "penalty: no progress at t = %.9g s (%d steps in a row advanced t by "
                          "less than %g of it: elements switching at one instant; rtol = %g, "
                          "atol = %g); --method newmark or moreau run the scene",
                          seconds(p, ta), PEN_MAX_STALL, PEN_STALL_REL, p->o.rtol, p->o.atol);
    track_extremes(p, *t - ta);
    /* elements switch at this instant: the located one, or one across */
    int switching = which >= 0 || across, switched = 0;
    if (switching) { /* the step's end under the set it ran with (left limits) */
        notify_step(p, *t, p->fb);
        switched = apply_switches(p, which);
    }
    if (switched)
        track_extremes(p, 0.0); /* after the switch */
    if (which >= 0) {           /* the step was cut: its stepper restarts from the crossing */
        gsl_odeiv2_evolve_reset(d->e);
        gsl_odeiv2_step_reset(d->s);
    }
    output_at_end(p, *t);
    if (switched) /* the same instant after the switch (right limits) */
        notify_step(p, *t, NULL);
    else if (!switching)
        notify_step(p, *t, p->fb);
    /* without an output grid the observer sees every step */
    fill_state(p, *t, p->y);
    if (p->o.h_out == 0.0)
        notify(p, p->observer, p->obs_ctx);
    return PD_OK;
}

/* Integrate [*t, tb] within one force segment. */
static int run_segment(pen *p, double *t, double tb, double *h, pd_err *err)
{
    gsl_odeiv2_driver *d = p->main_drv;
    int rc;
    p->seg_lo = *t;
    p->seg_hi = tb;
    gsl_odeiv2_evolve_reset(d->e);
    gsl_odeiv2_step_reset(d->s);
    *h = fmin(*h, tb - *t); /* no try beyond the segment */
    while (*t < tb && !p->stopped)
        if ((rc = one_step(p, t, tb, h, err)))
            return rc;
    return PD_OK;
}

/* Segments between the model's breakpoints inside (t0, t1). */
static int run_segments(pen *p, double t0, double t1, pd_err *err)
{
    const pd_model *md = p->md;
    double t = t0, h = 1e-3 * (t1 - t0), tol = 1e-12 * fmax(1.0, fmax(fabs(t0), fabs(t1)));
    int k = 0, rc;
    /* breakpoints at or before t0 (within tol) passed */
    while (k < md->nbreaks && md->breaks[k] <= t0 + tol)
        k++;
    while (t < t1 && !p->stopped) {
        double tb = t1;
        /* the segment ends at the next breakpoint before t1 */
        if (k < md->nbreaks && md->breaks[k] < t1 - tol)
            tb = md->breaks[k++];
        if ((rc = run_segment(p, &t, tb, &h, err)))
            return rc;
    }
    /* the grid's last point at t1 when it fell short */
    if (p->observer && p->o.h_out > 0.0 && !p->stopped && out_time(p, p->next_out - 1) < t1 - tol) {
        fill_state(p, t1, p->y);
        notify(p, p->observer, p->obs_ctx);
    }
    return PD_OK;
}

/* Initial state, engaged set from the initial gaps, first observer calls. */
static int start(pen *p, double t0, const double *q0, const double *v0, pd_err *err)
{
    int n = p->n;
    for (int i = 0; i < n; i++) {
        p->y[i] = q0 ? q0[i] : 0.0;
        p->y[n + i] = v0 ? v0[i] : 0.0;
        if (!isfinite(p->y[i]) || !isfinite(p->y[n + i]))
            return pd_err_set(err, PD_EINVAL, "penalty: initial state: dof %d is not finite", i);
    }
    p->vfloor = 1e3 * p->o.atol; /* Hertz-damp's smallest approach speed */
    p->res.min_gap = HUGE_VAL;
    for (int a = 0; a < p->m; a++) {
        p->res.min_gap = fmin(p->res.min_gap, gap_of(p, a, p->y));
        /* engaged from the start where the gap is negative */
        if (gap_of(p, a, p->y) < 0.0)
            switch_element(p, a);
    }
    p->res.switches = 0; /* the initial engagements are no switches */
    p->t_out0 = t0;
    p->next_out = 1;
    notify_step(p, t0, NULL);
    fill_state(p, t0, p->y);
    notify(p, p->observer, p->obs_ctx);
    return PD_OK;
}

int pd_penalty_run(const pd_model *model, double t0, const double *q0, const double *v0, double t1,
                   const pd_penalty_opts *opts, pd_observer observer, void *ctx,
                   pd_penalty_result *res, pd_err *err)
{
    pen p;
    int rc;
    memset(&p, 0, sizeof p);
    pd_err_clear(err);
    gsl_set_error_handler_off(); /* process-wide: GSL reports, never aborts */
    p.md = model;
    p.observer = observer;
    p.obs_ctx = ctx;
    p.o = opts ? *opts : pd_penalty_default_opts();
    /* the fixed-step scheme, penalty_newmark.c */
    if (p.o.stepper && !strcmp(p.o.stepper, "newmark"))
        return (rc = pd_model_check(model, err))
                   ? rc
                   : pd_penalty_newmark(model, t0, q0, v0, t1, &p.o, observer, ctx, res, err);
    if (!(rc = pd_model_check(model, err)) &&
        !(rc = pd_model_refuse_yield(model, "the adaptive penalty (GSL)", err)) &&
        !(rc = check_opts(&p, t0, t1, err))) {
        p.n = model->n;
        p.m = model->m;
        p.dim = 2 * (size_t)model->n; /* y = (q, v) */
        p.res.stepper = p.stp->name;
        if (alloc_arrays(&p))
            rc = pd_err_set(err, PD_ENOMEM, "penalty: out of memory for n = %d, m = %d", p.n, p.m);
        if (!rc && !(rc = setup_mass(&p, err)) && !(rc = alloc_drivers(&p, t1 - t0, err)) &&
            !(rc = start(&p, t0, q0, v0, err)))
            rc = run_segments(&p, t0, t1, err);
    }
    /* also on failure: what was reached */
    if (res)
        *res = p.res;
    pen_free(&p);
    return rc;
}
