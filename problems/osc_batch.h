/* osc_batch.h — the oscillator's batch (problems-private): its lanes'
 * cases and measurements (osc_batch.c), and the measurements after each
 * step, a text compiled per instruction set (osc_batch_lanes.h). */
#ifndef PD_OSC_BATCH_H
#define PD_OSC_BATCH_H

#include <math.h>
#include <string.h>

#include "osc_track.h"
#include "pd_cpu.h"
#include "pd_engine.h"
#include "pd_problems.h"

#define NL PD_MJB_LANES

/* The batch: the integrator, each lane's case and measurements (allocated
 * on a 64-byte boundary: the arrays marked so sit on cache lines). */
typedef struct osc_batch {
    pd_mjb mjb;
    /* a lane's case: id, options, length; -1: idle */
    long id[NL], nsteps[NL];
    pd_osc c[NL];     /* the case */
    pd_osc unit[NL];  /* the case with dir = +1: the shape the lane scales */
    pd_run_opts o[NL];
    double dir[NL];   /* +1 or -1 */
    int same_prev[NL]; /* 1: lane l - 1 has the same excitation */
    double cpu[NL];   /* the lane's share of the batch's time so far */
    int busy;         /* lanes running a case */
    long quiet_iter[NL]; /* the batch step from which lane l's force is 0 */
    int live[NL], nlive; /* the lanes still inside their excitation, in order */
    /* the measurements: what every step updates, by vectors of lanes */
    double Pi3[NL] __attribute__((aligned(64))), meas_from[NL]; /* window start - h/2 */
    /* (umax, max |x|, is the larger of xtoward and xaway: not kept apart) */
    double xtoward[NL] __attribute__((aligned(64))), xaway[NL], min_gap[NL], Pmax[NL];
    double contact[NL] __attribute__((aligned(64))); /* contact steps (whole numbers) */
    double prev_x[NL] __attribute__((aligned(64))), prev_v[NL], prev2_v[NL], prev_P[NL];
    /* ... and what the rare events update */
    pd_osc_track rare[NL];
    pd_mjb_observer observe; /* the measurements for this processor */
} osc_batch;

/* The lane's measurements into the struct the rare events use and back. */
static inline void rare_load(osc_batch *ob, int l)
{
    pd_osc_track *tr = &ob->rare[l];
    tr->xmax = ob->xtoward[l] > ob->xaway[l] ? ob->xtoward[l] : ob->xaway[l];
    tr->xmax = tr->xmax > 0.0 ? tr->xmax : 0.0; /* as the fold of |x| from 0 gives */
    tr->xtoward = ob->xtoward[l];
    tr->xaway = ob->xaway[l];
    tr->min_gap = ob->min_gap[l];
    tr->Pmax = ob->Pmax[l];
    tr->contact_steps = (long)ob->contact[l];
    tr->prev_x = ob->prev_x[l];
    tr->prev_v = ob->prev_v[l];
    tr->prev2_v = ob->prev2_v[l];
    tr->prev_P = ob->prev_P[l];
}

static inline void rare_store(osc_batch *ob, int l)
{
    const pd_osc_track *tr = &ob->rare[l];
    ob->xtoward[l] = tr->xtoward;
    ob->xaway[l] = tr->xaway;
    ob->min_gap[l] = tr->min_gap;
    ob->Pmax[l] = tr->Pmax;
    ob->contact[l] = (double)tr->contact_steps;
    ob->prev_x[l] = tr->prev_x;
    ob->prev_v[l] = tr->prev_v;
    ob->prev2_v[l] = tr->prev2_v;
    ob->prev_P[l] = tr->prev_P;
}

/* The measurements after a step, per instruction set (pd_cpu.h). */
int pd_osc_batch_observe_base(const pd_mjb *b, void *ctx);
int pd_osc_batch_observe_x86v3(const pd_mjb *b, void *ctx);
int pd_osc_batch_observe_x86v4(const pd_mjb *b, void *ctx);

#endif
