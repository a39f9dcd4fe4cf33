/* osc_adapt.c — the pounding oscillator by Moreau–Jean to a tolerance.
 *
 * The oscillator's model in Pi units (oscillator.c) run by pd_mj_run_until
 * with rtol > 0 and exact flights (its excitation as forcing pieces); per
 * kept step the measurements of pd_osc_track, the peaks also inside a
 * step on the quintic Hermite of (x, x', x'') when no impulse acted in it,
 * and at every peak the engine's error estimate of that instant:
 *   err_est = max over the peaks p of err(t_p) / p   (umax, u_toward, u_away;
 *             a_abs = |C x' + K x| with the error (K + C w) err(t_p), w = Pi2)
 * A run whose estimate exceeds rtol (the estimate's bound spread over more
 * events than the controller's share expected) is repeated at the
 * tolerance scaled down by the excess, at most OSC_ADAPT_TRIES runs; the
 * figures are the last run's, the steps and the CPU time all runs'.  A
 * sampler sees the last run, repeated for it (the same numbers). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "demand.h"
#include "osc_priv.h"
#include "osc_track.h"
#include "pd_null.h"
#include "pd_problems.h"

#define OSC_ADAPT_TRIES 3
#define OSC_ADAPT_H0                                                                               \
    2.0                      /* the coarsest step at most max(Tp, T0) / this (the engine
                               lowers it to what the observers allow) */
#define OSC_ADAPT_FLOOR 1e-3 /* errors below this share of the static scale count as none */

/* The observer's measurements in Pi units. */
typedef struct adapt_track {
    pd_osc_track m;     /* extremes, impacts, contact steps, min gap, largest impulse */
    double contact_tau; /* time with an impulse */
    double err_max, err_toward, err_away, err_acc; /* the estimate at each peak */
    double px, pv, pa, pt;                         /* the previous state */
    int pacc;                                      /* 1: it has an acceleration */
    pd_demand_osc dem;
    int demands;
    int dem_skipped; /* a state was left out of the demands since the last */
    double Le, vscale, wp;
    pd_osc_sampler sampler;
    void *sampler_ctx;
    long sampled;
    const pd_osc *c; /* its excitation (a held contact's force) */
} adapt_track;

/* A peak p at err e: raise *peak (and its *perr) when p is above it. */
static void raise_peak(double *peak, double *perr, double p, double e)
{
    if (p > *peak) {
        *peak = p;
        *perr = e;
    }
}

/* The extremes inside a smooth step, on the quintic Hermite of (x, v, a). */
static void interior_extremes(adapt_track *tr, const pd_state *st, double e)
{
    double p0[3] = {tr->px, tr->pv, tr->pa}, p1[3] = {st->q[0], st->v[0], st->acc[0]}, f;
    if (!pd_demand_quintic_turn(p0, p1, st->t - tr->pt, &f))
        return;
    raise_peak(&tr->m.xmax, &tr->err_max, fabs(f), e);
    raise_peak(&tr->m.xtoward, &tr->err_toward, f, e);
    raise_peak(&tr->m.xaway, &tr->err_away, -f, e);
}

static int observe(const pd_state *st, void *ctx)
{
    adapt_track *tr = ctx;
    double x = st->q[0], v = st->v[0], P = st->P[0], e = st->err ? st->err[0] : 0.0;
    double pk = tr->m.xmax, pt = tr->m.xtoward, pw = tr->m.xaway, pd = tr->dem.peak;
    int inside = st->t >= tr->m.tau_measure;
    tr->m.h = st->h > 0.0 ? st->h : tr->m.h;
    pd_osc_track_step(&tr->m, st->step, st->t, x, v, P);
    if (P > 0.0)
        tr->contact_tau += st->h;
    if (tr->m.xmax > pk)
        tr->err_max = e;
    if (tr->m.xtoward > pt)
        tr->err_toward = e;
    if (tr->m.xaway > pw)
        tr->err_away = e;
    /* inside a smooth step (no impact in it, both ends with their
     * accelerations: the right limits, a held contact's force included) */
    if (inside && st->step > 0 && tr->pacc && st->has_acc && !st->impact &&
        tr->pt >= tr->m.tau_measure)
        interior_extremes(tr, st, e);
    /* demands at every state, between them across the smooth steps */
    if (tr->demands && st->has_acc) {
        /* a held contact (an impulse in a step without an impact): its force
         * from x'' = f - C x' - K x - lam, the accelerations' left limit */
        double lam =
            P > 0.0 ? pd_osc_shape(tr->c, st->t, -1) - tr->dem.C * v - tr->dem.K * x - st->acc[0]
                    : 0.0;
        pd_demand_osc_note(&tr->dem, st->t, x, v, st->acc, lam,
                           st->step > 0 && !tr->dem_skipped && !st->impact);
        tr->dem.fd = tr->dem.C * st->acc_right[0] + tr->dem.K * v; /* the next step's start */
        tr->dem_skipped = 0;
        if (tr->dem.peak > pd)
            tr->err_acc = e;
    } else if (tr->demands) {
        tr->dem_skipped = 1;
    }
    tr->px = x;
    tr->pv = v;
    tr->pa = st->has_acc ? st->acc_right[0] : 0.0; /* the next step's start */
    tr->pacc = st->has_acc;
    tr->pt = st->t;
    if (!tr->sampler)
        return 0;
    pd_osc_sample smp = pd_osc_track_sample(&tr->m, &tr->sampled, st->step, st->t, x, v, P, tr->wp,
                                            tr->Le, tr->vscale);
    return tr->sampler(&smp, tr->sampler_ctx);
}

/* err_est of the peaks measured: the largest of their relative estimates. */
static double peaks_error(const adapt_track *tr, const pd_osc *c)
{
    double w = c->Pi2, e = 0.0;
    if (tr->m.xmax > 0.0)
        e = fmax(e, tr->err_max / tr->m.xmax);
    if (tr->m.xtoward > 0.0)
        e = fmax(e, tr->err_toward / tr->m.xtoward);
    if (tr->m.xaway > 0.0)
        e = fmax(e, tr->err_away / tr->m.xaway);
    if (tr->demands && tr->dem.peak > 0.0)
        e = fmax(e, (tr->dem.K + tr->dem.C * w) * tr->err_acc / tr->dem.peak);
    return e;
}

/* One run at the tolerance rtol into res (its figures in metres and seconds). */
static int run_once(const pd_osc *c, const pd_run_opts *o, double rtol, pd_osc_sampler sampler,
                    void *ctx, pd_osc_result *res, pd_mj_stats *stats, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    double pulse_end = pd_osc_shape_end(c);
    double b = 1.0;
    pd_osc_coefs k;
    pd_model model = pd_osc_model(c, o->no_wall, &k, &pulse_end, isfinite(pulse_end) ? 1 : 0);
    pd_sine_piece *pieces;
    int npieces, rc;
    if ((rc = pd_osc_pieces(c, &pieces, &npieces, err)))
        return rc;
    pd_piecewise_force F = {.b = &b, .pieces = pieces, .npieces = npieces};
    double wp = pd_osc_wp(c), Le = pd_osc_Le(c);
    pd_mj_opts mo = pd_run_mj_opts(o, PD_TWO_PI * fmax(1.0, 1.0 / c->Pi2) / OSC_ADAPT_H0);
    mo.rtol = rtol;
    /* below a thousandth of the static deflection under ap (1 / Pi2^2 in Pi
     * units) or of Le, an error is measured absolutely */
    mo.atol = OSC_ADAPT_FLOOR * fmin(1.0, 1.0 / (c->Pi2 * c->Pi2));
    mo.pieces = &F;
    adapt_track tr = {.Le = Le,
                      .vscale = Le * wp,
                      .wp = wp,
                      .demands = !o->no_demands,
                      .sampler = sampler,
                      .sampler_ctx = ctx,
                      .c = c};
    pd_osc_track_init(&tr.m, c, mo.h, wp * pd_osc_measure_start(c, o->tend));
    tr.dem = (pd_demand_osc){.C = k.C, .K = k.K, .tau_measure = tr.m.tau_measure};
    pd_mj *mj = pd_mj_alloc(&model, &mo, err);
    if (!mj) {
        free(pieces);
        return err->status;
    }
    rc = pd_mj_run_until(mj, wp * o->tend, observe, &tr, err);
    pd_mj_get_stats(mj, stats);
    pd_osc_track_result(&tr.m, c, o->dt, stats->steps, res);
    res->contact_time = tr.contact_tau / wp;
    res->dt = stats->h0 / wp;
    res->dt_min = stats->h_min / wp;
    res->dt_max = stats->h_max / wp;
    res->steps_rejected = stats->rejected;
    res->err_est = peaks_error(&tr, c);
    res->kernel = "exact-flight"; /* the scenes' name for it (scene_run.c) */
    pd_demand_osc_finish(res, o, tr.demands ? tr.dem.peak * c->ap : NAN,
                         tr.demands ? tr.dem.shear * c->ap : NAN, NAN);
    pd_mj_free(mj);
    free(pieces);
    return rc;
}

int pd_osc_adapt(const pd_osc *c, const pd_run_opts *o, pd_osc_sampler sampler, void *ctx,
                 pd_osc_result *res, pd_err *err)
{
    double cpu0 = pd_cpu_seconds(), rtol = o->rtol;
    long rejected = 0, steps = 0;
    pd_mj_stats st;
    int rc = PD_OK, runs = 0;
    /* a sampler sees one run: the one kept, repeated for it (the same numbers) */
    for (;;) {
        rc = run_once(c, o, rtol, NULL, ctx, res, &st, err);
        runs++;
        rejected += res->steps_rejected;
        steps += res->steps;
        if (rc || st.budget_hit || res->err_est <= o->rtol || runs >= OSC_ADAPT_TRIES ||
            rtol * 0.5 < PD_RTOL_MIN)
            break;
        rtol *= fmin(0.5, 0.5 * o->rtol / res->err_est);
        rtol = fmax(rtol, PD_RTOL_MIN);
    }
    if (!rc && sampler) {
        rc = run_once(c, o, rtol, sampler, ctx, res, &st, err);
        rejected += res->steps_rejected;
        steps += res->steps;
    }
    res->rtol = o->rtol;
    res->rtol_met = !rc && !st.floor_hit && !st.budget_hit && res->err_est <= o->rtol;
    res->steps = steps;
    res->steps_rejected = rejected;
    res->tend = o->tend;
    res->theta = o->theta;
    res->gamma = o->gamma;
    res->cpu_s = pd_cpu_seconds() - cpu0;
    return rc;
}
