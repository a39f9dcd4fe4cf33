/* oscillator.c — the pounding oscillator as an engine scene (SPEC §1).
 *
 * Dimensionless form (tau = wp t, x = u / Le, Le = ap / wp^2):
 *   x'' + 2 xi Pi2 x' + Pi2^2 x = s phi(tau) - lambda,   gap Pi3 - x >= 0,
 * phi = sin or cos on [0, 2 pi] (zero after), sin for all tau (harmonic).
 * So n = m = 1, M = 1, C = 2 xi Pi2, K = Pi2^2, W = -1, g0 = Pi3. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_mj1.h"
#include "osc_priv.h"
#include "osc_track.h"
#include "pd_null.h"
#include "demand.h"
#include "pd_problems.h"

pd_osc pd_osc_default(void)
{
    return (pd_osc){.pulse = PD_PULSE_SINE,
                    .dir = 1,
                    .ap = 1.0,
                    .Tp = 1.0,
                    .Pi2 = 1.0,
                    .Pi3 = 0.05,
                    .eps = 0.5,
                    .xi = 0.05,
                    .Piy = 0.0,
                    .alpha = 0.0};
}

double pd_osc_wp(const pd_osc *c)
{
    return c ? PD_TWO_PI / c->Tp : NAN;
}
double pd_osc_T0(const pd_osc *c)
{
    return c ? c->Tp / c->Pi2 : NAN;
}
double pd_osc_Le(const pd_osc *c)
{
    return c ? c->ap / (pd_osc_wp(c) * pd_osc_wp(c)) : NAN;
}
double pd_osc_gap(const pd_osc *c)
{
    return c ? c->Pi3 * pd_osc_Le(c) : NAN;
}

void pd_osc_set_T0(pd_osc *c, double T0)
{
    if (c)
        c->Pi2 = c->Tp / T0;
}

void pd_osc_set_gap(pd_osc *c, double gap)
{
    if (c)
        c->Pi3 = gap / pd_osc_Le(c);
}

void pd_osc_set_uy(pd_osc *c, double uy)
{
    if (c)
        c->Piy = uy / pd_osc_Le(c);
}

double pd_osc_uy(const pd_osc *c)
{
    if (!c)
        return NAN;
    return c->Piy > 0.0 ? c->Piy * pd_osc_Le(c) : INFINITY;
}

int pd_osc_yields(const pd_osc *c)
{
    return c && c->Piy > 0.0 && isfinite(c->Piy) && c->alpha < 1.0;
}

int pd_osc_yield_exact(const pd_osc *c)
{
    return pd_osc_yields(c) && (c->xi == 0.0 || c->alpha == 0.0 || c->xi * c->xi < c->alpha);
}

double pd_osc_excitation(const pd_osc *c, double t)
{
    if (!c)
        return NAN;
    return c->ap * pd_osc_shape(c, pd_osc_wp(c) * t, -1);
}

void pd_osc_set_record(pd_osc *c, const pd_record *rec, const pd_record_pulse *p, double scale)
{
    if (!c || !rec || !p)
        return;
    c->record = rec;
    c->rec_ap = p->ap;
    c->scale = scale;
    c->Tp = p->Tp;
    c->ap = scale * p->ap;
}

/* tau past the record's end on the requested side (to a relative 1e-12). */
static int after_record(const pd_osc *c, double tau, int side)
{
    double cut = pd_shape_cut(pd_osc_shape_end(c), side);
    return side < 0 ? tau > cut : tau >= cut;
}

/* -dir ug''(t) / rec_ap: the record's samples are joined linearly. */
double pd_osc_shape(const pd_osc *c, double tau, int side)
{
    if (!c)
        return NAN;
    if (!c->record)
        return pd_pulse_shape(c->pulse, c->dir, tau, side);
    if (tau < 0.0 || after_record(c, tau, side))
        return 0.0;
    return -c->dir *
           pd_record_acc(c->record, fmin(tau / pd_osc_wp(c), pd_record_duration(c->record))) /
           c->rec_ap;
}

/* d/dtau of the shape: the slope of the record's piece at tau. */
double pd_osc_shape_rate(const pd_osc *c, double tau, int side)
{
    if (!c)
        return NAN;
    if (!c->record)
        return pd_pulse_shape_rate(c->pulse, c->dir, tau, side);
    const pd_record *r = c->record;
    if (tau < 0.0 || after_record(c, tau, side))
        return 0.0;
    double t = tau / pd_osc_wp(c);
    long k = (long)floor(t / r->dt);
    if (side < 0 && k > 0 && t <= (double)k * r->dt)
        k--; /* the left limit at a sample: the piece before it */
    k = k < 0 ? 0 : k >= r->npts - 1 ? r->npts - 2 : k;
    double slope = (r->acc[k + 1] - r->acc[k]) / r->dt;
    return -c->dir * slope / (c->rec_ap * pd_osc_wp(c));
}

double pd_osc_shape_end(const pd_osc *c)
{
    if (!c)
        return NAN;
    if (c->record)
        return pd_osc_wp(c) * pd_record_duration(c->record);
    return c->pulse == PD_PULSE_HARMONIC ? HUGE_VAL : PD_TWO_PI;
}

const char *pd_osc_excitation_name(const pd_osc *c)
{
    if (!c)
        return "(none)";
    return c->record ? c->record->name : pd_pulse_name(c->pulse);
}

/* A finite value in [lo, hi] (hi_open: hi excluded). */
static int in_range(double x, double lo, double hi, int hi_open)
{
    return isfinite(x) && x >= lo && (hi_open ? x < hi : x <= hi);
}

int pd_osc_check(const pd_osc *c, pd_err *err)
{
    if (!c)
        return PD_NULL_ARG(err, "c");
    if (!c->record && c->pulse != PD_PULSE_SINE && c->pulse != PD_PULSE_COSINE &&
        c->pulse != PD_PULSE_HARMONIC)
        return pd_err_set(err, PD_EINVAL, "pulse must be sine, cosine or harmonic");
    if (c->record && (!(c->rec_ap > 0.0) || !isfinite(c->rec_ap) || !(c->scale > 0.0) ||
                      !isfinite(c->scale) || c->record->npts < 2 || !(c->record->dt > 0.0)))
        return pd_err_set(err, PD_EINVAL,
                          "record %s: scale (got %g) and the fitted pulse's ap "
                          "(got %g) must be > 0",
                          c->record->name, c->scale, c->rec_ap);
    if (c->dir != 1 && c->dir != -1)
        return pd_err_set(err, PD_EINVAL, "dir must be normal (+1) or reverse (-1)");
    if (!(c->ap > 0.0) || !isfinite(c->ap))
        return pd_err_set(err, PD_EINVAL, "ap (pulse amplitude) must be > 0 (got %g)", c->ap);
    if (!(c->Tp > 0.0) || !isfinite(c->Tp))
        return pd_err_set(err, PD_EINVAL, "Tp (pulse period) must be > 0 (got %g)", c->Tp);
    if (!(c->Pi2 > 0.0) || !isfinite(c->Pi2) || !isfinite(pd_osc_T0(c)))
        return pd_err_set(err, PD_EINVAL, "T0 / Pi2 must be finite and > 0 (Pi2 = %g)", c->Pi2);
    if (!in_range(c->Pi3, 0.0, HUGE_VAL, 1))
        return pd_err_set(err, PD_EINVAL, "gap must be >= 0 (Pi3 = %g)", c->Pi3);
    if (!in_range(c->eps, 0.0, 1.0, 0))
        return pd_err_set(err, PD_EINVAL, "eps (restitution) must be in [0, 1] (got %g)", c->eps);
    if (!in_range(c->xi, 0.0, 1.0, 1))
        return pd_err_set(err, PD_EINVAL, "xi (damping ratio) must be in [0, 1) (got %g)", c->xi);
    if (!(c->Piy >= 0.0))
        return pd_err_set(err, PD_EINVAL,
                          "uy (yield displacement) must be > 0 (Piy = %g; 0 or INFINITY: elastic)",
                          c->Piy);
    if (!in_range(c->alpha, 0.0, 1.0, 0))
        return pd_err_set(err, PD_EINVAL,
                          "alpha (post-yield stiffness ratio) must be in [0, 1] (got %g)",
                          c->alpha);
    return PD_OK;
}

int pd_osc_resolve_opts(const pd_osc *c, const pd_run_opts *in, pd_run_opts *out, pd_err *err)
{
    int rc;
    if (!c || !out)
        return PD_NULL_ARG(err, !c ? "c" : "out");
    *out = in ? *in : pd_run_default_opts();
    if ((rc = pd_osc_check(c, err)) || (rc = pd_run_opts_check(out, err)))
        return rc;
    if (out->method == PD_METHOD_EVENT_GENERAL)
        return pd_err_set(err, PD_EINVAL,
                          "method: event-general is the general reference for "
                          "scenes; the oscillator's exact reference is event");
    if (pd_osc_yields(c) &&
        (out->rtol > 0.0 || (out->method != PD_METHOD_AUTO && out->method != PD_METHOD_MOREAU &&
                             out->method != PD_METHOD_NEWMARK &&
                             (out->method != PD_METHOD_EVENT || !pd_osc_yield_exact(c)))))
        return pd_err_set(err, PD_EINVAL,
                          "a yielding oscillator (uy, alpha < 1) runs by Moreau-Jean at a "
                          "fixed step, by newmark, or by the exact reference when its sliding "
                          "phase is underdamped or a free mass, xi < sqrt(alpha) or alpha = 0 "
                          "(method %s%s, xi %g, alpha %g): the adaptive penalty and the "
                          "tolerance do not model yielding yet",
                          pd_method_name(out->method), out->rtol > 0.0 ? " with rtol" : "", c->xi,
                          c->alpha);
    if (out->dt == 0.0 && out->rtol == 0.0)
        out->dt = pd_osc_default_dt(c);
    if (out->tend == 0.0)
        out->tend = pd_osc_default_tend(c);
    if (out->rtol > 0.0) { /* Moreau-Jean to a tolerance: no step of its own */
        out->method = PD_METHOD_MOREAU;
        if (!(out->tend > 0.0) || !isfinite(out->tend))
            return pd_err_set(err, PD_EINVAL, "tend must be a finite number > 0 (got %g)",
                              out->tend);
        return PD_OK;
    }
    if (!(out->dt > 0.0) || !isfinite(out->dt))
        return pd_err_set(err, PD_EINVAL, "dt must be a finite number > 0 (got %g)", out->dt);
    if (!(out->tend > 0.0) || !isfinite(out->tend))
        return pd_err_set(err, PD_EINVAL, "tend must be a finite number > 0 (got %g)", out->tend);
    if (!(out->tend / out->dt <= PD_MAX_STEPS))
        return pd_err_set(err, PD_EINVAL, "dt: tend / dt = %g steps is too many (at most %.0e)",
                          out->tend / out->dt, PD_MAX_STEPS);
    out->method = pd_osc_method(c, out);
    return PD_OK;
}

pd_method pd_osc_method(const pd_osc *c, const pd_run_opts *o)
{
    if (!c || !o)
        return PD_METHOD_AUTO; /* nothing to resolve */
    if (o->method != PD_METHOD_AUTO)
        return o->method;
    /* a tolerance, a yielding spring the exact reference does not model: Moreau-Jean's */
    if (o->rtol > 0.0 || (pd_osc_yields(c) && !pd_osc_yield_exact(c)))
        return PD_METHOD_MOREAU;
    double tend = o->tend > 0.0 ? o->tend : pd_osc_default_tend(c);
    return pd_osc_scan_points(c, tend) <= PD_OSC_MAX_SCAN ? PD_METHOD_EVENT : PD_METHOD_MOREAU;
}

double pd_osc_default_dt(const pd_osc *c)
{
    if (!c)
        return NAN;
    return fmin(c->Tp, pd_osc_T0(c)) / 2000.0;
}

/* Measuring window of the harmonic steady state: max(16 Tp, 3 T0). */
static double harmonic_window(const pd_osc *c)
{
    return fmax(16.0 * c->Tp, 3.0 * pd_osc_T0(c));
}

/* Harmonic transient: until exp(-xi w0 t) < 1e-3 (at least 20 Tp), or
 * 20 Tp + 20 T0 without damping (impacts then dissipate when eps < 1).
 * Pulses: Tp + 2 T0; records: their duration + 2 T0. */
double pd_osc_default_tend(const pd_osc *c)
{
    if (!c)
        return NAN;
    double T0 = pd_osc_T0(c);
    if (c->record)
        return pd_record_duration(c->record) + 2.0 * T0;
    if (c->pulse != PD_PULSE_HARMONIC)
        return c->Tp + 2.0 * T0;
    double w0 = PD_TWO_PI / T0;
    double transient =
        c->xi > 0.0 ? fmax(20.0 * c->Tp, log(1e3) / (c->xi * w0)) : 20.0 * c->Tp + 20.0 * T0;
    return transient + harmonic_window(c);
}

double pd_osc_measure_start(const pd_osc *c, double tend)
{
    if (!c)
        return NAN;
    if (c->record || c->pulse != PD_PULSE_HARMONIC)
        return 0.0;
    return fmax(0.0, tend - harmonic_window(c));
}

/* ---- the scene -------------------------------------------------------- */

/* The observer's context: the measurements and the sampler. */
typedef struct tracker {
    pd_osc_track m;
    double Pprev, vprev; /* the previous step's impulse and rate (a held contact) */
    const pd_osc *c;     /* its excitation (the held force) */
    long sampled;        /* impacts reported to the sampler */
    double Le, vscale, wp;
    pd_demand_osc dem; /* the absolute acceleration's peak (Pi units) */
    int demands;       /* 0: not measured (pd_run_opts.no_demands) */
    pd_osc_sampler sampler;
    void *sampler_ctx;
} tracker;

void pd_osc_track_init(pd_osc_track *tr, const pd_osc *c, double h, double tau_measure)
{
    *tr = (pd_osc_track){.h = h,
                         .Pi3 = c->Pi3,
                         .tau_measure = tau_measure,
                         .first_tau = NAN,
                         .first_v = NAN,
                         .min_gap = c->Pi3};
}

/* Time s in [0, h] after the step start at which the gap g0 > 0 closes
 * under x(s) = v s + a s^2 / 2 (velocity v, acceleration a of the step). */
static double closing_time(double g0, double v, double a, double h)
{
    double s = h;
    if (g0 <= 0.0)
        return 0.0;
    if (fabs(a) * h < 1e-12 * fabs(v) || a == 0.0)
        s = v > 0.0 ? g0 / v : h;
    else {
        double disc = v * v + 2.0 * a * g0; /* a s^2/2 + v s - g0 = 0 */
        if (disc >= 0.0)
            s = (v > 0.0) ? 2.0 * g0 / (v + sqrt(disc)) : (-v + sqrt(disc)) / a;
    }
    return fmin(fmax(s, 0.0), h);
}

void pd_osc_track_events(pd_osc_track *tr, long step, double t, double x, double v, double P)
{
    /* the gap closes in this step (or an impulse stops it closing): instant
     * and speed from the step start and the step's free acceleration */
    double gap = tr->Pi3 - x, g_prev = tr->Pi3 - tr->prev_x;
    if (step > 0 && g_prev > 0.0 && (gap <= 0.0 || P > 0.0)) {
        double acc = P == 0.0 ? (v - tr->prev_v) / tr->h
                              : (step > 1 ? (tr->prev_v - tr->prev2_v) / tr->h : 0.0);
        double s = closing_time(g_prev, tr->prev_v, acc, tr->h);
        tr->closing_tau = t - tr->h + s;
        tr->closing_v = tr->prev_v + acc * s;
    }
    if (P > 0.0 && tr->prev_P == 0.0) {
        tr->impacts++;
        tr->vimp_max = pd_max(tr->vimp_max, tr->closing_v);
        if (tr->impacts == 1) {
            tr->first_tau = tr->closing_tau;
            tr->first_v = tr->closing_v;
        }
    }
}

void pd_osc_track_result(const pd_osc_track *tr, const pd_osc *c, double dt, long steps,
                         pd_osc_result *res)
{
    double wp = pd_osc_wp(c), Le = pd_osc_Le(c), vscale = Le * wp;
    memset(res, 0, sizeof *res);
    res->umax = tr->xmax * Le;
    res->u_toward = tr->xtoward * Le;
    res->u_away = tr->xaway * Le;
    res->impacts = tr->impacts;
    res->first_impact = tr->first_tau / wp;
    res->first_impact_velocity = tr->first_v * vscale;
    res->max_impact_velocity = tr->vimp_max * vscale;
    res->max_impulse = tr->Pmax * vscale;
    res->contact_time = (double)tr->contact_steps * dt;
    res->min_gap = tr->min_gap * Le;
    res->steps = steps;
    res->dt = dt;
    pd_osc_result_no_rtol(res, dt);
    pd_osc_result_no_yield(res);
    /* demands: not measured here (the single runs measure and set them) */
    res->acc_max = res->shear_max = res->force_max = res->force_equiv = res->contact_duration = NAN;
}

/* Per step: the measurements, then the sample. */
static int observe(const pd_state *st, void *ctx)
{
    tracker *tr = ctx;
    double x = st->q[0], v = st->v[0], P = st->P[0];
    pd_osc_track_step(&tr->m, st->step, st->t, x, v, P);
    if (tr->demands) /* the steps' own, as umax, with a held contact's force */
        pd_demand_osc_note(&tr->dem, st->t, x, v, NULL,
                           P > 0.0 && tr->Pprev > 0.0
                               ? pd_demand_osc_held(&tr->dem, st->h, P, tr->Pprev, v, tr->vprev, x,
                                                    pd_osc_shape(tr->c, st->t, -1))
                               : 0.0,
                           0);
    tr->Pprev = P;
    tr->vprev = v;
    if (tr->sampler) {
        pd_osc_sample smp = pd_osc_track_sample(&tr->m, &tr->sampled, st->step, st->t, x, v, P,
                                                tr->wp, tr->Le, tr->vscale);
        return tr->sampler(&smp, tr->sampler_ctx);
    }
    return 0;
}

/* pd_osc_shape, a pulse's inline. */
static inline double osc_force(const pd_osc *c, double tau, int side)
{
    return c->record ? pd_osc_shape(c, tau, side)
                     : pd_pulse_shape_inline(c->pulse, c->dir, tau, side);
}

/* The measured run's hooks into the engine's loop (pd_mj1.h): the
 * excitation, and after each step the tracks and demands. */
typedef struct scalar_osc {
    const pd_osc *c;
    pd_osc_track *tr;
    pd_demand_osc *dem;
    double h, Pprev, vprev; /* the step; the previous step's impulse and velocity */
} scalar_osc;

static inline double scalar_osc_force(void *ctx, double tau, int side)
{
    return osc_force(((const scalar_osc *)ctx)->c, tau, side);
}

/* After a step: the tracks (u itself) and the demands of the spring's
 * force K qs (qs = q for an elastic spring). */
static inline void scalar_osc_note(scalar_osc *so, const mj1_state *x, double tau, double qs)
{
    pd_osc_track_step(so->tr, x->step, tau, x->q, x->v, x->P);
    if (so->dem) /* with a held contact's force */
        pd_demand_osc_note_state(
            so->dem, tau, qs, x->v,
            pd_demand_osc_held(so->dem, so->h, x->P, so->Pprev, x->v, so->vprev, qs, x->F1));
    so->Pprev = x->P;
    so->vprev = x->v;
}

static inline int scalar_osc_observe(void *ctx, const mj1_state *x, double tau)
{
    scalar_osc_note(ctx, x, tau, x->q);
    return 0;
}

/* A yielding run's measures (Pi units), the slider's constants and the
 * sampler its observer feeds. */
typedef struct osc_yield {
    scalar_osc so;    /* the elastic run's measurements */
    double soft;      /* 1 - alpha: the spring's force is K (q - soft up) */
    double th, C;     /* theta; the damping */
    double kbar;      /* (1 - alpha) K */
    double Gprev;     /* the previous step's plastic increment */
    long n_yield;     /* onsets: a step that slides after one that did not */
    double excursion; /* sum |Gamma| */
    double q, up;     /* the state at the step's start (its v: so.vprev) */
    double F0;        /* the step's force at its start */
    /* the balance's sums over the steps, with v_th = th v+ + (1 - th) v and
     * z_th = z + th (z+ - z): the input h sum v_th F_th, the damping h C sum
     * v_th^2, the slider's work kbar sum z_th Gamma, the impacts' losses
     * -sum v_th W P (the sums kept without their constant factors) */
    double input, damping, work, impact;
    tracker *sm; /* the sampler's bridge (sampler NULL: none) */
} osc_yield;

/* After a yielding step: the tracks (u itself), the demands of the
 * spring's force K (q - (1 - alpha) up), the slider's tallies, the step's
 * energies, the sample. */
static inline int scalar_osc_observe_yield(void *ctx, const mj1_state *x, double tau)
{
    osc_yield *oy = ctx;
    scalar_osc *so = &oy->so;
    /* the energies of the step as it was taken (W = -1: -v_th W P = v_th P);
     * the constant factors h, h C, kbar applied at the end (yield_result) */
    double vth = oy->th * x->v + (1.0 - oy->th) * so->vprev;
    /* the spring's force K (q - (1 - alpha) up): an elastic spring's at qs */
    scalar_osc_note(so, x, tau, x->q - oy->soft * x->up);
    oy->input += vth * mj1_fth(oy->th, oy->F0, x->F1);
    oy->damping += vth * vth;
    if (x->P != 0.0)
        oy->impact += vth * x->P;
    if (x->G != 0.0) {
        double z0 = oy->q - oy->up, z1 = x->q - x->up;
        oy->n_yield += oy->Gprev == 0.0;
        oy->excursion += fabs(x->G);
        oy->work += (z0 + oy->th * (z1 - z0)) * x->G;
    }
    oy->Gprev = x->G;
    oy->q = x->q;
    oy->up = x->up;
    oy->F0 = x->F0;
    tracker *sm = oy->sm;
    if (sm && sm->sampler) {
        pd_osc_sample smp = pd_osc_track_sample(so->tr, &sm->sampled, x->step, tau, x->q, x->v,
                                                x->P, sm->wp, sm->Le, sm->vscale);
        smp.up = x->up * sm->Le;
        return sm->sampler(&smp, sm->sampler_ctx);
    }
    return 0;
}

/* pd_mj_run's scalar kernel on the oscillator with the measurements
 * inline: the engine's loop (pd_mj1.h's mj1_run, the same step, forces,
 * breakpoints and failure as pd_mj's) with the tracks as its observer,
 * called directly, so that the state stays in registers.  Its steps taken
 * go to *steps, its last state to *end.  oy (NULL: elastic): the yielding
 * spring's run, its tallies and samples. */
static int simulate_scalar(const pd_osc *c, const pd_model *md, const pd_mj_opts *mo, long nsteps,
                           pd_osc_track *tr, pd_demand_osc *dem, osc_yield *oy, mj1_state *end,
                           pd_err *err)
{
    const double h = mo->h, t0 = 0.0, K = pd_matrix_get(&md->K, 0, 0);
    mj1_coef s1 = mj1_coef_make(1.0, pd_matrix_get(&md->C, 0, 0), K, md->m > 0, md->m ? -1.0 : 0.0,
                                md->m ? md->g0[0] : 0.0, md->m ? md->e[0] : 0.0, h, mo->theta);
    scalar_osc so = {.c = c, .tr = tr, .dem = dem, .h = h};
    mj1_state x = {.g = s1.g0, .F0 = osc_force(c, t0, +1)};
    while (x.next_break < md->nbreaks && md->breaks[x.next_break] < t0 - 1e-9 * h)
        x.next_break++;
    pd_osc_track_step(tr, 0, t0, x.q, x.v, x.P);
    if (dem)
        pd_demand_osc_note_state(dem, t0, x.q, x.v, 0.0);
    int rc = PD_OK;
    if (!oy)
        rc = mj1_run(&s1, NULL, h, mo->theta, mo->gamma, t0, md->breaks, md->nbreaks, nsteps, &x,
                     scalar_osc_force, scalar_osc_observe, &so, err);
    else {
        mj1_yield yl = mj1_yield_make(&s1, K, c->alpha, c->Piy, h, mo->theta);
        oy->so = so;
        oy->soft = 1.0 - c->alpha;
        oy->th = mo->theta;
        oy->C = pd_matrix_get(&md->C, 0, 0);
        oy->kbar = (1.0 - c->alpha) * K;
        oy->F0 = x.F0;
        tracker *sm = oy->sm;
        if (sm && sm->sampler) { /* the sample at t0 */
            pd_osc_sample smp = pd_osc_track_sample(tr, &sm->sampled, 0, t0, x.q, x.v, x.P, sm->wp,
                                                    sm->Le, sm->vscale);
            if (sm->sampler(&smp, sm->sampler_ctx) > 0)
                nsteps = 0;
        }
        rc = mj1_run(&s1, &yl, h, mo->theta, mo->gamma, t0, md->breaks, md->nbreaks, nsteps, &x,
                     scalar_osc_force, scalar_osc_observe_yield, oy, err);
    }
    *end = x;
    return rc;
}

/* A yielding run's figures from its offset at the end, its excursion and
 * the slider's work (Pi units: lengths times Le, energies per unit mass
 * times (Le wp)^2), every method's. */
void pd_osc_yield_figures(const pd_osc *c, double up, double excursion, double work, long n_yield,
                          pd_osc_result *res)
{
    double Le = pd_osc_Le(c), wp = pd_osc_wp(c);
    res->ductility = res->umax / pd_osc_uy(c);
    res->residual = (1.0 - c->alpha) * up * Le;
    res->plastic_excursion = excursion * Le;
    res->hysteretic_energy = work * ((Le * wp) * (Le * wp));
    res->n_yield = n_yield;
}

/* A yielding run's results from its tallies and its end (q, v, up; Pi
 * units to metres, energies per unit mass in (Le wp)^2). */
static void yield_result(const pd_osc *c, const osc_yield *oy, const mj1_state *end,
                         pd_osc_result *res)
{
    double Le = pd_osc_Le(c), wp = pd_osc_wp(c), E = (Le * wp) * (Le * wp);
    double K = c->Pi2 * c->Pi2, z = end->q - end->up;
    pd_osc_yield_figures(c, end->up, oy->excursion, oy->kbar * oy->work, oy->n_yield, res);
    pd_energy *en = &res->energy;
    en->input = oy->so.h * oy->input * E;
    en->kinetic = 0.5 * end->v * end->v * E;
    en->strain = 0.5 * (c->alpha * K * end->q * end->q + oy->kbar * z * z) * E;
    en->damping = oy->so.h * oy->C * oy->damping * E;
    en->hysteretic = res->hysteretic_energy;
    en->impact = oy->impact * E;
    pd_energy_close(en, 0.0); /* from rest */
}

/* The exact reference's energy balance (per unit mass, Pi units times
 * vscale^2), from rest. */
static void ref_energy(const pd_ed_result *er, double vscale, pd_osc_result *res)
{
    double E = vscale * vscale;
    pd_energy *en = &res->energy;
    en->input = er->input_work * E;
    en->kinetic = er->kinetic * E;
    en->strain = er->strain * E;
    en->damping = er->damping_work * E;
    en->hysteretic = res->hysteretic_energy;
    en->impact = er->impact_loss * E;
    pd_energy_close(en, 0.0); /* from rest */
}

int pd_osc_simulate(const pd_osc *c, const pd_run_opts *opts, pd_osc_sampler sampler, void *ctx,
                    pd_osc_result *res, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    pd_run_opts o;
    int rc;
    if (!c || !res)
        return PD_NULL_ARG(err, !c ? "c" : "res");
    pd_err_clear(err);
    if ((rc = pd_osc_resolve_opts(c, opts, &o, err)))
        return rc;
    if (o.rtol > 0.0)
        return pd_osc_adapt(c, &o, sampler, ctx, res, err);

    /* model in Pi units; the step is 2 pi (dt / Tp) so equal dt/Tp gives equal h */
    double pulse_end = pd_osc_shape_end(c); /* the only breakpoint: the pulse's or record's end */
    pd_osc_coefs k;
    pd_model model = pd_osc_model(c, o.no_wall, &k, &pulse_end, isfinite(pulse_end) ? 1 : 0);
    pd_mj_opts mo = pd_run_mj_opts(&o, PD_TWO_PI * (o.dt / c->Tp));
    long nsteps = pd_steps_for(o.tend, o.dt);

    double cpu0 = pd_cpu_seconds();
    double wp = pd_osc_wp(c), Le = pd_osc_Le(c);
    tracker tr = {.Le = Le,
                  .vscale = Le * wp,
                  .wp = wp,
                  .demands = !o.no_demands,
                  .c = c,
                  .sampler = sampler,
                  .sampler_ctx = ctx};
    pd_osc_track_init(&tr.m, c, mo.h, wp * pd_osc_measure_start(c, o.tend));
    tr.dem = (pd_demand_osc){.C = k.C, .K = k.K, .tau_measure = tr.m.tau_measure - 0.5 * mo.h};
    int yields = pd_osc_yields(c);
    if (yields && (mo.kernel != PD_KERNEL_AUTO || mo.factor != PD_FACTOR_AUTO))
        return pd_err_set(err, PD_EINVAL,
                          "a yielding oscillator runs on Moreau-Jean's scalar kernel only: "
                          "kernel and factor must be auto");
    if ((!sampler || yields) && mo.kernel == PD_KERNEL_AUTO && mo.factor == PD_FACTOR_AUTO) {
        /* the scalar kernel, which pd_mj would choose (n = 1, m <= 1) */
        mj1_state end = {0};
        osc_yield oy = {.sm = &tr};
        if ((rc = pd_model_check(&model, err)) || (rc = pd_mj_check_opts(&mo, err)))
            return rc;
        rc = simulate_scalar(c, &model, &mo, nsteps, &tr.m, tr.demands ? &tr.dem : NULL,
                             yields ? &oy : NULL, &end, err);
        pd_osc_track_result(&tr.m, c, o.dt, end.step, res);
        if (yields)
            yield_result(c, &oy, &end, res);
        res->tend = o.tend;
        res->theta = mo.theta;
        res->gamma = mo.gamma;
        res->kernel = "scalar";
        pd_demand_osc_finish(res, &o, tr.demands ? tr.dem.peak * c->ap : NAN,
                             tr.demands ? tr.dem.shear * c->ap : NAN, NAN);
        res->cpu_s = pd_cpu_seconds() - cpu0;
        return rc;
    }
    pd_mj *mj = pd_mj_alloc(&model, &mo, err);
    if (!mj)
        return err->status;
    rc = pd_mj_run(mj, nsteps, observe, &tr, err);
    pd_osc_track_result(&tr.m, c, o.dt, pd_mj_state(mj)->step, res);
    res->tend = o.tend;
    res->theta = mo.theta;
    res->gamma = mo.gamma;
    res->kernel = pd_mj_kernel_name(mj);
    pd_mj_free(mj);
    pd_demand_osc_finish(res, &o, tr.demands ? tr.dem.peak * c->ap : NAN,
                         tr.demands ? tr.dem.shear * c->ap : NAN, NAN);
    res->cpu_s = pd_cpu_seconds() - cpu0;
    return rc;
}

/* Sampler bridge: Pi units to metres and seconds. */
typedef struct ref_bridge {
    double wp, Le, vscale, Pi3;
    const pd_osc *c;
    pd_demand_osc dem;           /* the absolute acceleration's peak (Pi units) */
    long impacts, impacts_prev;  /* impacts seen, and by the previous sample */
    int rest_prev;               /* the previous sample was resting on the wall */
    double tprev, fprev, fdprev; /* its time, excitation and excitation's rate */
    long step;
    const pd_ed_result *er; /* the run's impacts and impulse so far (and the offset) */
    double up_prev;         /* a yielding spring's offset at the previous sample */
    long reported;          /* impacts and impulse reported to the sampler */
    double impulse_reported;
    pd_osc_sampler sampler;
    void *ctx;
} ref_bridge;

static int ref_sample(double tau, double x, double v, int in_contact, void *ctx)
{
    ref_bridge *b = ctx;
    /* free flight: x'' = f - C x' - K x; at rest on the wall x'' = 0 and the
     * held force is f - C x' - K x (a_abs = a_g); the interval since the
     * previous sample is smooth when it held no impact and no rest */
    double f = pd_osc_shape(b->c, tau, -1), fd = pd_osc_shape_rate(b->c, tau, -1);
    /* a yielding spring's force K (x - (1 - alpha) up): an elastic one's at xs;
     * smooth since the previous sample only if the offset stayed */
    double xs = x, up = b->er->up;
    if (up != 0.0 || b->up_prev != 0.0)
        xs = x - (1.0 - b->c->alpha) * up;
    double a = f - b->dem.C * v - b->dem.K * xs;
    int smooth = !in_contact && !b->rest_prev && b->impacts == b->impacts_prev && up == b->up_prev;
    b->up_prev = up;
    pd_demand_osc_note(&b->dem, tau, xs, v, in_contact ? NULL : &a, in_contact ? a : 0.0, smooth);
    /* at rest from the previous sample on, a_abs = |f|: its peak between
     * them on the cubic Hermite of (f, f') */
    if (in_contact && b->rest_prev && tau > b->tprev && b->tprev >= b->dem.tau_measure)
        b->dem.peak =
            pd_max(b->dem.peak, pd_demand_cubic_peak(b->fprev, b->fdprev, f, fd, tau - b->tprev));
    b->tprev = tau;
    b->fprev = f;
    b->fdprev = fd;
    b->impacts_prev = b->impacts;
    b->rest_prev = in_contact;
    if (!b->sampler) {
        b->step++;
        return 0;
    }
    pd_osc_sample s = {.step = b->step++,
                       .t = tau / b->wp,
                       .u = x * b->Le,
                       .v = v * b->vscale,
                       .impulse = (b->er->impulse - b->impulse_reported) * b->vscale,
                       .gap = (b->Pi3 - x) * b->Le,
                       .impacts = b->er->impacts - b->reported,
                       .up = b->er->up * b->Le}; /* the offset at the sample (0: elastic) */
    b->reported = b->er->impacts;
    b->impulse_reported = b->er->impulse;
    return b->sampler(&s, b->ctx);
}

/* An impact: the demand at the wall with the velocities before and after it. */
static void ref_impact(double tau, double vn, double v_plus, void *ctx)
{
    ref_bridge *b = ctx;
    pd_demand_osc *d = &b->dem;
    b->impacts++;
    if (tau >= d->tau_measure) {
        double p = pd_max(fabs(d->C * vn + d->K * b->Pi3), fabs(d->C * v_plus + d->K * b->Pi3));
        d->peak = pd_max(d->peak, p);
        d->shear = pd_max(d->shear, p);
    }
}

/* The reference's demand grid without a sampler: the largest whole multiple
 * of dt with OSC_DEMAND_GRID points per shortest period (of T0 and Tp). */
#define OSC_DEMAND_GRID 128.0
static double ref_demand_grid(const pd_osc *c, double dt)
{
    double k = floor(fmin(c->Tp, pd_osc_T0(c)) / (OSC_DEMAND_GRID * dt));
    return (k > 1.0 ? k : 1.0) * dt;
}

int pd_osc_pieces(const pd_osc *c, pd_sine_piece **pieces, int *npieces, pd_err *err)
{
    if (!c || !pieces || !npieces)
        return PD_NULL_ARG(err, !c ? "c" : !pieces ? "pieces" : "npieces");
    const pd_record *r = c->record;
    int n = r ? (int)r->npts : c->pulse == PD_PULSE_HARMONIC ? 1 : 2;
    pd_sine_piece *p = malloc((size_t)n * sizeof *p);
    *pieces = NULL;
    *npieces = 0;
    if (!p)
        return pd_err_set(err, PD_ENOMEM, "out of memory for the forcing pieces of %s",
                          pd_osc_excitation_name(c));
    if (r) { /* piece k = [tau_k, tau_k+1): linear from F(tau_k) with the piece's slope */
        double wp = pd_osc_wp(c), g = -(double)c->dir / c->rec_ap;
        for (long k = 0; k + 1 < r->npts; k++)
            p[k] = (pd_sine_piece){.t_start = wp * (double)k * r->dt,
                                   .c0 = g * r->acc[k],
                                   .c1 = g * (r->acc[k + 1] - r->acc[k]) / (wp * r->dt)};
        p[n - 1] = (pd_sine_piece){.t_start = pd_osc_shape_end(c)};
    } else { /* s sin(tau + phi) (cos = sin(+pi/2)), then zero after 2 pi */
        double phi = c->pulse == PD_PULSE_COSINE ? PD_TWO_PI / 4.0 : 0.0;
        p[0] = (pd_sine_piece){.t_start = 0.0, .A = (double)c->dir, .w = 1.0, .phi = phi};
        if (n > 1)
            p[1] = (pd_sine_piece){.t_start = PD_TWO_PI};
    }
    *pieces = p;
    *npieces = n;
    return PD_OK;
}

double pd_osc_scan_points(const pd_osc *c, double tend)
{
    if (!c)
        return NAN;
    double T0 = pd_osc_T0(c);
    double sine = c->record                       ? 0.0 /* linear pieces: T0 alone */
                  : c->pulse == PD_PULSE_HARMONIC ? tend
                                                  : fmin(tend, c->Tp);
    return 64.0 * (sine / fmin(c->Tp, T0) + (tend - sine) / T0);
}

int pd_osc_reference(const pd_osc *c, const pd_run_opts *opts, pd_osc_sampler sampler, void *ctx,
                     pd_osc_result *res, pd_err *err)
{
    pd_run_opts o;
    pd_ed_result er;
    int rc;
    if (!c || !res)
        return PD_NULL_ARG(err, !c ? "c" : "res");
    pd_err_clear(err);
    if ((rc = pd_osc_resolve_opts(c, opts, &o, err)))
        return rc;
    if (pd_osc_yields(c) && !pd_osc_yield_exact(c))
        return pd_osc_refuse_yield(c,
                                   "the event-driven reference (a sliding phase not underdamped: "
                                   "0 < alpha <= xi^2)",
                                   err);
    double scan = pd_osc_scan_points(c, o.tend); /* its scan grid: the cost */
    if (!(scan <= PD_OSC_MAX_SCAN))
        return pd_err_set(err, PD_EINVAL,
                          "Pi2: the event-driven reference would scan %.3g "
                          "points over tend (T0 = %.3g s; at most %.0e)",
                          scan, pd_osc_T0(c), PD_OSC_MAX_SCAN);
    pd_sine_piece *pieces;
    int npieces;
    if ((rc = pd_osc_pieces(c, &pieces, &npieces, err)))
        return rc;
    pd_ed_sdof prob = {.osc = {.w0 = c->Pi2, .xi = c->xi},
                       .wall = !o.no_wall,
                       .delta = c->Pi3,
                       .e = c->eps,
                       .npieces = npieces,
                       .pieces = pieces,
                       .uy = pd_osc_yields(c) ? c->Piy : 0.0,
                       .alpha = c->alpha};
    double wp = pd_osc_wp(c), Le = pd_osc_Le(c);
    pd_ed_opts eo = pd_ed_default_opts();
    eo.t_end = wp * o.tend;
    eo.t_measure = wp * pd_osc_measure_start(c, o.tend);
    /* the grid: samples every dt; else the demand's states (with its impacts) */
    eo.h_out = sampler        ? PD_TWO_PI * (o.dt / c->Tp)
               : o.no_demands ? 0.0
                              : PD_TWO_PI * (ref_demand_grid(c, o.dt) / c->Tp);
    eo.on_impact = o.no_demands ? NULL : ref_impact;
    eo.no_accumulation = o.no_accumulation;
    eo.energy = pd_osc_yields(c) && !o.no_demands; /* a yielding run's balance, as Moreau-Jean's */
    ref_bridge bridge = {
        .wp = wp,
        .Le = Le,
        .vscale = Le * wp,
        .Pi3 = c->Pi3,
        .c = c,
        .dem = {.C = 2.0 * c->xi * c->Pi2, .K = c->Pi2 * c->Pi2, .tau_measure = eo.t_measure},
        .step = 0,
        .er = &er,
        .sampler = sampler,
        .ctx = ctx};
    eo.on_impact_ctx = &bridge;
    double cpu0 = pd_cpu_seconds();
    rc =
        pd_ed_sdof_run(&prob, 0.0, 0.0, &eo, eo.h_out > 0.0 ? ref_sample : NULL, &bridge, &er, err);
    free(pieces);
    memset(res, 0, sizeof *res);
    res->umax = er.xmax * Le;
    res->u_toward = er.xtoward * Le;
    res->u_away = er.xaway * Le;
    res->impacts = er.impacts;
    res->accumulations = er.accumulations;
    res->first_impact = er.first_impact / wp;
    res->first_impact_velocity = er.first_impact_velocity * Le * wp;
    res->max_impact_velocity = er.max_impact_velocity * Le * wp;
    res->max_impulse = (1.0 + c->eps) * res->max_impact_velocity;
    res->contact_time = er.contact_time / wp;
    res->min_gap = o.no_wall ? NAN : 0.0;
    res->steps = er.events;
    res->dt = o.dt;
    res->tend = o.tend;
    res->theta = NAN;
    res->gamma = NAN;
    res->kernel = "event";
    pd_osc_result_no_rtol(res, NAN);
    pd_osc_result_no_yield(res);
    /* a yielding spring's figures */
    if (pd_osc_yields(c)) {
        pd_osc_yield_figures(c, er.up, er.excursion, er.hysteretic, er.n_yield, res);
        if (eo.energy)
            ref_energy(&er, Le * wp, res);
    }
    pd_demand_osc_finish(res, &o, o.no_demands ? NAN : bridge.dem.peak * c->ap,
                         o.no_demands ? NAN : bridge.dem.shear * c->ap, NAN);
    res->cpu_s = pd_cpu_seconds() - cpu0;
    return rc;
}

void pd_osc_free_exact(const pd_osc *c, double t, double *u, double *v)
{
    if (!c || !u || !v)
        return;
    pd_sdof osc = {.w0 = PD_TWO_PI / pd_osc_T0(c), .xi = c->xi};
    double wp = pd_osc_wp(c), A = c->dir * c->ap;
    double phi = c->pulse == PD_PULSE_COSINE ? PD_TWO_PI / 4.0 : 0.0; /* cos = sin(+pi/2) */
    if (c->pulse == PD_PULSE_HARMONIC || t <= c->Tp) {
        pd_sdof_advance(&osc, A, wp, phi, 0.0, 0.0, 0.0, t, u, v);
        return;
    }
    double uT, vT;
    pd_sdof_advance(&osc, A, wp, phi, 0.0, 0.0, 0.0, c->Tp, &uT, &vT);
    pd_sdof_advance(&osc, 0.0, wp, 0.0, c->Tp, uT, vT, t, u, v);
}

int pd_osc_free_first_contact(const pd_osc *c, double tmax, double *t, double *v)
{
    if (!c || !t || !v)
        return PD_EINVAL;
    double delta = pd_osc_gap(c), step = c->Tp / 1000.0, lo = 0.0, hi = -1.0, u;
    if (c->record || !(step > 0.0) || !isfinite(step)) /* a record, or no grid (Tp) */
        return PD_EINVAL;
    for (double s = step; s <= tmax + 0.5 * step; s += step) {
        pd_osc_free_exact(c, s, &u, v);
        if (u >= delta) {
            hi = s;
            break;
        }
        lo = s;
    }
    if (hi < 0.0)
        return PD_EINVAL;
    for (int it = 0; it < 200 && hi - lo > 1e-16 * hi; it++) {
        double mid = 0.5 * (lo + hi);
        pd_osc_free_exact(c, mid, &u, v);
        *(u < delta ? &lo : &hi) = mid;
    }
    *t = 0.5 * (lo + hi);
    pd_osc_free_exact(c, *t, &u, v);
    return PD_OK;
}

int pd_osc_run(const pd_osc *c, const pd_run_opts *opts, pd_osc_sampler sampler, void *ctx,
               pd_osc_result *res, pd_err *err)
{
    if (!c || !res)
        return PD_NULL_ARG(err, !c ? "c" : "res");
    pd_run_opts o = opts ? *opts : pd_run_default_opts();
    int rc;
    switch (pd_osc_method(c, &o)) {
    case PD_METHOD_EVENT:
        rc = pd_osc_reference(c, &o, sampler, ctx, res, err);
        break;
    case PD_METHOD_PENALTY:
    case PD_METHOD_NEWMARK:
        rc = pd_osc_penalty(c, &o, sampler, ctx, res, err);
        break;
    default:
        rc = pd_osc_simulate(c, &o, sampler, ctx, res, err);
        break;
    }
    return rc ? rc : pd_demand_check_force(res->max_impulse, res->force_equiv, -1, err);
}

/* The run, its no-wall twin, Pi1 = umax / Le, gamma and chi. */
int pd_osc_summarize(const pd_osc *c, const pd_run_opts *opts, pd_osc_sampler sampler, void *ctx,
                     pd_osc_summary *s, pd_err *err)
{
    if (!c || !s)
        return PD_NULL_ARG(err, !c ? "c" : "s");
    pd_run_opts twin = opts ? *opts : pd_run_default_opts();
    int rc;
    memset(s, 0, sizeof *s);
    double cpu0 = pd_cpu_seconds();
    twin.no_wall = 1;
    twin.no_demands = 1; /* the twin's figure is umax */
    if ((rc = pd_osc_run(c, opts, sampler, ctx, &s->r, err)) ||
        (rc = pd_osc_run(c, &twin, NULL, NULL, &s->free, err)))
        return rc;
    s->cpu_s = pd_cpu_seconds() - cpu0;
    s->err_est = s->r.rtol > 0.0 ? fmax(s->r.err_est, s->free.err_est) : NAN;
    s->rtol_met = s->r.rtol_met && s->free.rtol_met;
    s->Pi1 = s->r.umax / pd_osc_Le(c);
    s->gamma = s->free.umax > 0.0 ? s->r.umax / s->free.umax : NAN;
    s->chi = s->free.umax > 0.0 ? pd_osc_gap(c) / s->free.umax : NAN;
    return PD_OK;
}
