/* osc_track.h — the oscillator's measurements step by step (problems-
 * private), shared by its single Moreau–Jean run (oscillator.c) and its
 * batched runs (osc_batch.c), in Pi units: extremes over the measuring
 * window, contact steps, the largest impulse, the smallest gap, and the
 * impacts with their instant and approach speed estimated inside the step
 * where the gap closed. */
#ifndef PD_OSC_TRACK_H
#define PD_OSC_TRACK_H

#include "pd_problems.h"

typedef struct pd_osc_track {
    double h;           /* dimensionless step */
    double Pi3;         /* gap */
    double tau_measure; /* window start (dimensionless) */
    double xmax, xtoward, xaway;
    long impacts, contact_steps;
    double first_tau, first_v, vimp_max, Pmax;
    double closing_tau, closing_v; /* last gap closing seen */
    double prev_x, prev_v, prev2_v, prev_P, min_gap;
} pd_osc_track;

/* Nothing seen yet, for steps h of case c measured from tau_measure. */
void pd_osc_track_init(pd_osc_track *tr, const pd_osc *c, double h, double tau_measure);

/* The state (x, v, P) after step `step` ending at t: extremes inside the
 * window, contact steps, largest impulse, smallest gap. */
static inline void pd_osc_track_common(pd_osc_track *tr, double t, double x, double P)
{
    double gap = tr->Pi3 - x;
    if (t >= tr->tau_measure - 0.5 * tr->h) {
        tr->xmax = pd_max(tr->xmax, fabs(x)); /* inlined: fmax is a library call */
        tr->xtoward = pd_max(tr->xtoward, x);
        tr->xaway = pd_max(tr->xaway, -x);
    }
    if (P > 0.0) {
        tr->contact_steps++;
        tr->Pmax = pd_max(tr->Pmax, P);
    }
    tr->min_gap = tr->min_gap < gap ? tr->min_gap : gap;
}

/* 1 when the step needs pd_osc_track_events: the gap closed in it (or an
 * impulse stopped it closing), or an impact began. */
static inline int pd_osc_track_events_due(const pd_osc_track *tr, long step, double x, double P)
{
    double gap = tr->Pi3 - x, g_prev = tr->Pi3 - tr->prev_x;
    return (step > 0 && g_prev > 0.0 && (gap <= 0.0 || P > 0.0)) || (P > 0.0 && tr->prev_P == 0.0);
}

/* The gap closing's instant and speed, and the impact begun (counted, its
 * speed, the first one's instant). */
void pd_osc_track_events(pd_osc_track *tr, long step, double t, double x, double v, double P);

/* The state becomes the previous one. */
static inline void pd_osc_track_shift(pd_osc_track *tr, double x, double v, double P)
{
    tr->prev2_v = tr->prev_v;
    tr->prev_x = x;
    tr->prev_v = v;
    tr->prev_P = P;
}

/* One step's measurements. */
static inline void pd_osc_track_step(pd_osc_track *tr, long step, double t, double x, double v,
                                     double P)
{
    pd_osc_track_common(tr, t, x, P);
    if (pd_osc_track_events_due(tr, step, x, P))
        pd_osc_track_events(tr, step, t, x, v, P);
    pd_osc_track_shift(tr, x, v, P);
}

/* The results in metres and seconds of case c run with steps dt over
 * `steps` steps (the method's fields left to the caller). */
void pd_osc_track_result(const pd_osc_track *tr, const pd_osc *c, double dt, long steps,
                         pd_osc_result *res);

/* The sampler's view of the state (x, v, P) after step `step` at t, in
 * Pi units: back to seconds and metres (wp, Le, vscale = Le wp), with the
 * impacts begun since the one sampled before (*sampled, moved on). */
static inline pd_osc_sample pd_osc_track_sample(const pd_osc_track *tr, long *sampled, long step,
                                                double t, double x, double v, double P, double wp,
                                                double Le, double vscale)
{
    pd_osc_sample smp = {.step = step,
                         .t = t / wp,
                         .u = x * Le,
                         .v = v * vscale,
                         .impulse = P * vscale,
                         .gap = (tr->Pi3 - x) * Le,
                         .impacts = tr->impacts - *sampled};
    *sampled = tr->impacts;
    return smp;
}

#endif
