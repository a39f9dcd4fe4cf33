/* osc_penalty.c — the pounding oscillator (SPEC §1) run with the penalty
 * baseline (engine/penalty.c), in the Pi units of oscillator.c:
 *
 *   tau = wp t, x = u / Le:  x'' + 2 xi Pi2 x' + Pi2^2 x = s phi(tau) - lambda,
 *   gap Pi3 - x;  so M = 1, C = 2 xi Pi2, K = Pi2^2, W = -1, g0 = Pi3.
 *
 * Stiffness in Pi units (lambda / ap against d / Le):
 *   Kelvin-Voigt  kc = kc_mult Pi2^2   or  kc_abs / wp^2   (kc_mult 0: max(1e4 Pi2^2, 1e3 / Pi3^2))
 *   Hertz-damp    kc = kc_mult Pi2^2   or  kc_abs sqrt(Le) / wp^2
 * Extremes are measured on every accepted step, refined inside the step by
 * the quintic Hermite interpolant of (x, x', x''); impacts are the located
 * gap closings; samples come every dt from the engine's outputs. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "osc_priv.h"
#include "scene_priv.h"
#include "pd_null.h"
#include "demand.h"
#include "pd_problems.h"

#define OSC_PEN_KC_W0 1e4    /* the default contact stiffness: at least this * w0^2, ... */
#define OSC_PEN_KC_GAP 1e3   /* ... and this * wp^2 / Pi3^2 (penetration ~ 3 % of the gap) */
#define OSC_PEN_MIN_PI3 1e-3 /* the Pi3 of that rule at a zero gap */

/* Measurements in Pi units, updated after every accepted step. */
typedef struct pen_track {
    const pd_osc *c;
    pd_penalty_law law;
    int m; /* 0: no wall */
    double C, K, Pi3, tau_measure;
    double xmax, xtoward, xaway, xpeak;
    pd_demand_osc dem; /* the absolute acceleration's peak */
    double h_out;      /* the output grid's step (a hold's rest rate) */
    double fpeak;      /* the largest element force */
    int no_demands;
    long impacts, sampled; /* sampled: impacts reported to the sampler */
    double first_tau, first_v, vimp_max, contact_tau;
    int have_prev, pactive;
    double pt, px, pv, pP;       /* previous accepted state and its force */
    double imp_t, imp_lam, imp;  /* integral of lambda since the last sample */
    double episode, episode_max; /* integral of lambda over the current contact, its max */
    double Le, vscale, wp;
    pd_osc_sampler sampler;
    void *sampler_ctx;
    /* a yielding spring (newmark): its yielding part kbar = (1 - alpha) K, the
     * offset up (at the previous step), the tallies */
    double kbar, up, excursion;
    long n_yield;
    int slid;            /* the previous step slid */
    pd_scene_energy *en; /* newmark on a yielding spring: the energy balance */
} pen_track;

/* A step of the interpolant: x(s) = sum_k c_k (s/h)^k on [0, h]. */
typedef struct pen_poly {
    double c[8], h;
} pen_poly;

/* The derivatives of x at a step end: x, x', x'', x'''. */
typedef struct pen_jet {
    double x, v, a, j;
} pen_jet;

/* Hermite interpolant through the jets at both ends, matching derivatives
 * up to order (degree - 1) / 2: degree 3 (x, x'), 5 (+ x'') or 7 (+ x''').
 * With r = s/h, the low coefficients are the start's Taylor terms and the
 * high ones solve the end conditions (P, V, A, J: what the low ones miss). */
static pen_poly hermite_step(double h, const pen_jet *s, const pen_jet *e, int degree)
{
    pen_poly p = {{s->x, h * s->v, 0, 0, 0, 0, 0, 0}, h};
    double h2 = h * h;
    if (degree == 3) {
        p.c[2] = 3.0 * (e->x - s->x) - 2.0 * h * s->v - h * e->v;
        p.c[3] = 2.0 * (s->x - e->x) + h * s->v + h * e->v;
        return p;
    }
    p.c[2] = 0.5 * h2 * s->a;
    if (degree == 5) {
        double P = e->x - (p.c[0] + p.c[1] + p.c[2]), V = h * e->v - (p.c[1] + 2.0 * p.c[2]);
        double A = h2 * e->a - 2.0 * p.c[2];
        p.c[3] = 10.0 * P - 4.0 * V + 0.5 * A;
        p.c[4] = -15.0 * P + 7.0 * V - A;
        p.c[5] = 6.0 * P - 3.0 * V + 0.5 * A;
        return p;
    }
    p.c[3] = h2 * h * s->j / 6.0;
    double P = e->x - (p.c[0] + p.c[1] + p.c[2] + p.c[3]);
    double V = h * e->v - (p.c[1] + 2.0 * p.c[2] + 3.0 * p.c[3]);
    double A = h2 * e->a - (2.0 * p.c[2] + 6.0 * p.c[3]), J = h2 * h * e->j - 6.0 * p.c[3];
    p.c[4] = 35.0 * P - 15.0 * V + 2.5 * A - J / 6.0;
    p.c[5] = -84.0 * P + 39.0 * V - 7.0 * A + 0.5 * J;
    p.c[6] = 70.0 * P - 34.0 * V + 6.5 * A - 0.5 * J;
    p.c[7] = -20.0 * P + 10.0 * V - 2.0 * A + J / 6.0;
    return p;
}

/* x(s) by Horner. */
static double poly_x(const pen_poly *p, double s)
{
    double r = s / p->h, y = 0.0;
    for (int k = 7; k >= 0; k--)
        y = y * r + p->c[k];
    return y;
}

/* x'(s) = (1/h) sum_k k c_k (s/h)^(k-1). */
static double poly_v(const pen_poly *p, double s)
{
    double r = s / p->h, y = 0.0;
    for (int k = 7; k >= 1; k--)
        y = y * r + k * p->c[k];
    return y / p->h;
}

/* Extremes of x at time tau: |x|, x, -x in the window; x everywhere. */
static void record_x(pen_track *tr, double tau, double x)
{
    if (tau >= tr->tau_measure * (1.0 - 1e-12)) {
        tr->xmax = fmax(tr->xmax, fabs(x));
        tr->xtoward = fmax(tr->xtoward, x);
        tr->xaway = fmax(tr->xaway, -x);
    }
    tr->xpeak = fmax(tr->xpeak, x);
}

/* Turning points x' = 0 inside the step: sign changes of x' on a grid of 16,
 * each refined by bisection. */
static void interior_extremes(pen_track *tr, const pen_poly *p, double t0)
{
    enum { GRID = 16 };
    double s0 = 0.0, v0 = poly_v(p, 0.0);
    for (int k = 1; k <= GRID; k++) {
        double s1 = p->h * k / GRID, v1 = poly_v(p, s1);
        if ((v0 < 0.0) != (v1 < 0.0) && v0 != 0.0 && v1 != 0.0) {
            double lo = s0, hi = s1;
            for (int it = 0; it < 60; it++) {
                double mid = 0.5 * (lo + hi);
                if ((poly_v(p, mid) < 0.0) == (v0 < 0.0))
                    lo = mid;
                else
                    hi = mid;
            }
            record_x(tr, t0 + 0.5 * (lo + hi), poly_x(p, 0.5 * (lo + hi)));
        }
        s0 = s1;
        v0 = v1;
    }
}

/* Trapezoid of lambda from the last point to (tau, lam). */
static void add_impulse(pen_track *tr, double tau, double lam)
{
    double di = 0.5 * (tr->imp_lam + lam) * (tau - tr->imp_t);
    tr->imp += di;
    tr->episode += di;
    tr->episode_max = fmax(tr->episode_max, tr->episode);
    tr->imp_t = tau;
}

/* x, x', x'' and (free flight) x''' = f' - C x'' - Kt x' at tau, side of f;
 * a yielding spring's force K x - kbar up, its tangent Kt = K - kbar while
 * the step slid. */
static pen_jet jet_at(const pen_track *tr, double tau, double x, double v, double lam, double up,
                      int side)
{
    pen_jet q = {x, v, 0.0, 0.0};
    q.a = pd_osc_shape(tr->c, tau, side) - tr->C * v - tr->K * x + tr->kbar * up - lam;
    q.j = pd_osc_shape_rate(tr->c, tau, side) - tr->C * q.a - (tr->K - tr->slid * tr->kbar) * v;
    return q;
}

/* The step from the previous state to (tau, x, v): its turning points, its
 * contact time and impulse.  A free step gets the degree-7 interpolant (the
 * jerk is known there); an engaged one degree 5, with the force at its end
 * from the law it ran with: lambda when still engaged, 0 when released by
 * Hertz-damp (d = 0); a Kelvin-Voigt release leaves it unknown here, so
 * that step gets the cubic. */
static void close_step(pen_track *tr, double tau, double x, double v, double lam, int active,
                       double up)
{
    double h = tau - tr->pt, lam_end = 0.0;
    int degree = tr->pactive ? 5 : 7;
    if (tr->pactive && active)
        lam_end = lam;
    else if (tr->pactive && tr->law == PD_PENALTY_KELVIN)
        degree = 3;
    pen_jet s = jet_at(tr, tr->pt, tr->px, tr->pv, tr->pactive ? tr->pP : 0.0, tr->up, +1);
    pen_jet e = jet_at(tr, tau, x, v, lam_end, up, -1);
    pen_poly p = hermite_step(h, &s, &e, degree);
    interior_extremes(tr, &p, tr->pt);
    if (tr->pactive)
        tr->contact_tau += h;
    add_impulse(tr, tau, lam_end);
}

/* on_step: per accepted step (and at tau = 0). */
static int track_step(const pd_state *st, void *ctx)
{
    pen_track *tr = ctx;
    double tau = st->t, x = st->q[0], v = st->v[0];
    double lam = tr->m ? st->P[0] : 0.0, up = st->up ? st->up[0] : 0.0;
    int active = tr->m ? st->active[0] : 0;
    if (tr->en) { /* the step's energy identity, the element's force at its start */
        double lam0 = tr->have_prev && tr->pactive ? tr->pP : 0.0;
        pd_scene_energy_note_forces(tr->en, st, &lam0);
    }
    /* a yielding spring: a step that slid after one that did not is an onset */
    int slides = up != tr->up;
    tr->n_yield += slides && !tr->slid;
    tr->excursion += fabs(up - tr->up);
    tr->slid = slides;
    if (tr->have_prev && tau > tr->pt)
        close_step(tr, tau, x, v, lam, active, up);
    tr->up = up;
    record_x(tr, tau, x);
    /* the spring's force K (x - (1 - alpha) up): an elastic spring's at xs */
    double xs = tr->kbar > 0.0 ? x - (tr->kbar / tr->K) * up : x;
    double f = pd_osc_shape(tr->c, tau, -1), a = f - tr->C * v - tr->K * xs - lam;
    /* a_abs: the element's force is an impact's and a hold's at once; a
     * hold (engaged, at rest after this step and the one before) takes the
     * rigid wall's held force, never the element's ringing */
    if (!tr->no_demands)
        pd_demand_osc_note(
            &tr->dem, tau, xs, v, &a,
            pd_demand_osc_held(&tr->dem, tr->h_out, active, tr->pactive, v, tr->pv, x, f),
            !active && !tr->pactive); /* free steps */
    if (active)
        tr->fpeak = fmax(tr->fpeak, lam);
    if (active && !tr->pactive) { /* an element engaged at a located closing */
        tr->episode = 0.0;
        tr->impacts++;
        tr->vimp_max = fmax(tr->vimp_max, v);
        if (tr->impacts == 1) {
            tr->first_tau = tau;
            tr->first_v = v;
        }
    }
    tr->have_prev = 1;
    tr->pt = tau;
    tr->px = x;
    tr->pv = v;
    tr->pP = lam;
    tr->pactive = active;
    tr->imp_lam = lam;
    return 0;
}

/* observer: a sample every dt, in metres, seconds and m/s. */
static int emit_sample(const pd_state *st, void *ctx)
{
    pen_track *tr = ctx;
    double x = st->q[0], lam = tr->m ? st->P[0] : 0.0;
    add_impulse(tr, st->t, lam);
    pd_osc_sample s = {.step = st->step,
                       .t = st->t / tr->wp,
                       .u = x * tr->Le,
                       .v = st->v[0] * tr->vscale,
                       .impulse = tr->imp * tr->vscale,
                       .gap = (tr->Pi3 - x) * tr->Le,
                       .impacts = tr->impacts - tr->sampled};
    tr->sampled = tr->impacts;
    tr->imp = 0.0;
    tr->imp_lam = lam;
    return tr->sampler(&s, tr->sampler_ctx);
}

double pd_newmark_step(double dt, double Tc)
{
    double k = ceil(dt * PD_NEWMARK_STEPS_PER_CONTACT / Tc);
    return k > 1.0 && isfinite(k) ? dt / k : dt;
}

int pd_newmark_budget(const pd_penalty_opts *po, double dt, double tau_end, pd_err *err)
{
    double steps = tau_end / po->h;
    if (strcmp(po->stepper, "newmark") || steps <= (double)po->max_steps)
        return PD_OK;
    if (po->h < dt)
        return pd_err_set(err, PD_EINVAL,
                          "kc: newmark's steps resolve the stiffest contact "
                          "element (%d per period): %.3g steps (at most %ld); a softer contact "
                          "(kc, kc-abs) or --method penalty",
                          (int)PD_NEWMARK_STEPS_PER_CONTACT, steps, po->max_steps);
    return pd_err_set(err, PD_EINVAL, "dt: newmark's %.3g steps (at most %ld); a longer step",
                      steps, po->max_steps);
}

/* Contact stiffness in Pi units (see the file comment). */
double pd_osc_penalty_kc(const pd_osc *c, const pd_penalty_setup *po)
{
    double wp = pd_osc_wp(c);
    if (po->kc_abs > 0.0)
        return po->law == PD_PENALTY_HERTZDAMP ? po->kc_abs * sqrt(pd_osc_Le(c)) / (wp * wp)
                                               : po->kc_abs / (wp * wp);
    if (po->kc_mult > 0.0)
        return po->kc_mult * c->Pi2 * c->Pi2;
    /* the default resolves the gap: a pulse's velocity scale ap/wp enters the
     * wall by about 3 % of the gap (1e3 wp^2 / Pi3^2), and never softer than
     * 1e4 w0^2 (docs/methods.md: 200 random cases) */
    double pi3 = fmax(c->Pi3, OSC_PEN_MIN_PI3);
    return fmax(OSC_PEN_KC_W0 * c->Pi2 * c->Pi2, OSC_PEN_KC_GAP / (pi3 * pi3));
}

/* Results back in metres and seconds. */
static void fill_result(const pen_track *tr, const pd_run_opts *o, const pd_penalty_result *pr,
                        pd_osc_result *res)
{
    memset(res, 0, sizeof *res);
    res->umax = tr->xmax * tr->Le;
    res->u_toward = tr->xtoward * tr->Le;
    res->u_away = tr->xaway * tr->Le;
    res->impacts = tr->impacts;
    res->first_impact = tr->first_tau / tr->wp;
    res->first_impact_velocity = tr->first_v * tr->vscale;
    res->max_impact_velocity = tr->vimp_max * tr->vscale;
    res->max_impulse = tr->episode_max * tr->vscale;
    res->contact_time = tr->contact_tau / tr->wp;
    res->min_gap = (tr->Pi3 - tr->xpeak) * tr->Le;
    res->steps = pr->steps;
    res->dt = o->dt;
    res->tend = o->tend;
    res->theta = NAN;
    res->gamma = NAN;
    res->kernel = pr->stepper ? pr->stepper : "penalty";
    pd_osc_result_no_rtol(res, NAN);
    pd_osc_result_no_yield(res);
    res->newton_failures = pr->newton_failures;
    if (tr->kbar > 0.0) /* the slider's work: its force kbar uy over the excursion */
        pd_osc_yield_figures(tr->c, tr->up, tr->excursion, tr->kbar * tr->c->Piy * tr->excursion,
                             tr->n_yield, res);
    pd_demand_osc_finish(res, o, tr->no_demands ? NAN : tr->dem.peak * tr->c->ap,
                         tr->no_demands ? NAN : tr->dem.shear * tr->c->ap,
                         tr->m ? tr->fpeak * tr->c->ap : NAN);
}

int pd_osc_penalty(const pd_osc *c, const pd_run_opts *opts, pd_osc_sampler sampler, void *ctx,
                   pd_osc_result *res, pd_err *err)
{
    pd_run_opts o;
    pd_penalty_result pr;
    int rc;
    if (!c || !res)
        return PD_NULL_ARG(err, !c ? "c" : "res");
    pd_err_clear(err);
    if ((rc = pd_osc_resolve_opts(c, opts, &o, err)) ||
        (o.method != PD_METHOD_NEWMARK &&
         (rc = pd_osc_refuse_yield(c, "the adaptive penalty method", err))))
        return rc;

    /* the scene in Pi units; outputs on the grid tau_k = k 2 pi dt / Tp */
    double M = 1.0, C = 2.0 * c->xi * c->Pi2, K = c->Pi2 * c->Pi2, W = -1.0;
    double g0 = c->Pi3, e = c->eps, wp = pd_osc_wp(c);
    double h_out = PD_TWO_PI * (o.dt / c->Tp);
    double tau_end = (double)pd_steps_for(o.tend, o.dt) * h_out;
    double tau_measure = wp * pd_osc_measure_start(c, o.tend);
    double brk = isfinite(pd_osc_shape_end(c)) ? pd_osc_shape_end(c) : tau_measure;
    /* a record: every sample is a kink of the force, a breakpoint for the stepper */
    double *brks = NULL;
    if (c->record) {
        long nb = c->record->npts;
        if (!(brks = malloc((size_t)nb * sizeof(double))))
            return pd_err_set(err, PD_ENOMEM, "out of memory for %ld breakpoints", nb);
        for (long k = 0; k < nb; k++)
            brks[k] = wp * (double)k * c->record->dt;
        brks[nb - 1] = brk;
    }
    pd_model model = {.n = 1,
                      .m = o.no_wall ? 0 : 1,
                      .M = pd_matrix_dense(1, 1, &M),
                      .C = pd_matrix_dense(1, 1, &C),
                      .K = pd_matrix_dense(1, 1, &K),
                      .W = pd_matrix_dense(1, 1, &W),
                      .g0 = &g0,
                      .e = &e,
                      .force = pd_osc_model_force,
                      .force_ctx = (void *)c,
                      .breaks = brks ? brks + 1 : &brk,
                      .nbreaks = brks        ? (int)(c->record->npts - 1)
                                 : brk > 0.0 ? 1
                                             : 0};
    /* a yielding spring (newmark): S = 1, ks = (1 - alpha) K, uy = Piy */
    double S = 1.0, ks = (1.0 - c->alpha) * K, uy = c->Piy;
    if (pd_osc_yields(c)) {
        model.ns = 1;
        model.S = pd_matrix_dense(1, 1, &S);
        model.ks = &ks;
        model.uy = &uy;
    }
    pen_track tr;
    memset(&tr, 0, sizeof tr);
    tr.c = c;
    tr.law = o.pen.law;
    tr.m = model.m;
    tr.C = C;
    tr.K = K;
    tr.Pi3 = c->Pi3;
    tr.tau_measure = tau_measure;
    tr.dem = (pd_demand_osc){.C = C, .K = K, .tau_measure = tau_measure};
    tr.h_out = h_out;
    tr.no_demands = o.no_demands;
    tr.first_tau = tr.first_v = NAN;
    tr.Le = pd_osc_Le(c);
    tr.wp = wp;
    tr.vscale = tr.Le * wp;
    tr.sampler = sampler;
    tr.sampler_ctx = ctx;
    tr.kbar = model.ns ? ks : 0.0;
    pd_penalty_opts eo = pd_penalty_default_opts();
    eo.law = o.pen.law;
    eo.kc = pd_osc_penalty_kc(c, &o.pen);
    eo.rtol = o.pen.rtol;
    eo.atol = o.pen.atol;
    eo.stepper = o.method == PD_METHOD_NEWMARK ? "newmark" : o.pen.stepper;
    /* stepper newmark: dt, or dt / k for PD_NEWMARK_STEPS_PER_CONTACT steps per
     * period of the element on the unit mass (2 pi / sqrt(kc) in tau) */
    eo.h = model.m ? pd_newmark_step(h_out, PD_TWO_PI / sqrt(eo.kc)) : h_out;
    eo.h_out = sampler ? h_out : 0.0;
    eo.on_step = track_step;
    eo.on_step_ctx = &tr;
    eo.factor = o.factor;
    eo.time_unit = 1.0 / wp; /* tau = wp t */

    double cpu0 = pd_cpu_seconds();
    if ((rc = pd_newmark_budget(&eo, h_out, tau_end, err))) {
        free(brks);
        return rc;
    }
    /* newmark on a yielding spring: its energy balance (the scene's identity;
     * a sweep's runs go without, as the exact reference's) */
    if (model.ns > 0 && o.method == PD_METHOD_NEWMARK && !o.no_demands &&
        !(tr.en = pd_scene_energy_alloc(&model, eo.h, 0.5))) {
        free(brks);
        return pd_err_set(err, PD_ENOMEM, "out of memory for the energy balance");
    }
    rc = pd_penalty_run(&model, 0.0, NULL, NULL, tau_end, &eo, sampler ? emit_sample : NULL, &tr,
                        &pr, err);
    free(brks);
    fill_result(&tr, &o, &pr, res);
    if (tr.en) /* per unit mass: (Le wp)^2 */
        pd_scene_energy_finish(tr.en, tr.vscale * tr.vscale, &res->energy);
    pd_scene_energy_free(tr.en);
    res->cpu_s = pd_cpu_seconds() - cpu0;
    return rc;
}
