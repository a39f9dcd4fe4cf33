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
#define OSC_BLOCK 64        /* batch steps run at a time between the forces' fills */
#define OSC_TABLES 16       /* excitation tables kept */
#define OSC_TABLE_MAX 32768 /* the longest excitation tabulated, in steps */

/* An excitation's left limits at the steps of one h: v[s] = the shape at
 * s h (s = 1 .. n, 0 after), and the steps' forces vth[s] = theta v[s+1]
 * + (1 - theta) v[s] (mj1_step's), shared by the lanes that run this
 * shape with this step (dir scales them: pd_osc_shape is odd in dir, and
 * dir (a + b) is (dir a) + (dir b) to the bit but for the sign of a zero,
 * which a step's velocity never takes: osc_batch.c). */
typedef struct osc_table {
    pd_osc unit; /* the shape (dir = +1) */
    double h;
    long n, cap;
    double *v;   /* cap + 2 values, v[0] unused */
    double *vth; /* cap + 1 values (in v's memory), vth[0] unused */
    int users;   /* lanes reading it */
} osc_table;

typedef struct osc_batch osc_batch;
/* Run k steps of every lane (k <= OSC_BLOCK, no lane ending or meeting its
 * breakpoint before the last), the steps' forces in Fth[0 .. k-1] and the
 * last step's end force in Fend: the lanes' step and measurements, per
 * instruction set (osc_batch_lanes.h). */
typedef void (*osc_batch_run_fn)(osc_batch *ob, int k);

/* The batch: the integrator, each lane's case and measurements (allocated
 * on a 64-byte boundary: the arrays marked so sit on cache lines). */
struct osc_batch {
    pd_mjb mjb;
    /* a lane's case: id, options, length; -1: idle */
    long id[NL], nsteps[NL];
    pd_osc c[NL];    /* the case */
    pd_osc unit[NL]; /* the case with dir = +1: the shape the lane scales */
    pd_run_opts o[NL];
    double dir[NL];      /* +1 or -1 */
    int same_prev[NL];   /* 1: lane l - 1 has the same excitation */
    double cpu[NL];      /* the lane's share of the batch's time so far */
    int busy;            /* lanes running a case */
    long quiet_iter[NL]; /* the batch step from which lane l's force is 0 */
    int live[NL], nlive; /* the lanes still inside their excitation, in order */
    int table[NL];       /* the lane's excitation table (-1: none, computed per step) */
    osc_table tab[OSC_TABLES];
    /* the forces of a block of steps: row s the force of its step s + 1,
     * theta F(end) + (1 - theta) F(start) (rows 1 .. OSC_BLOCK - 1 of a lane
     * outside its excitation are 0); the left limit at the last step's end
     * (the next block's start); the left limits F(s h) of the lanes
     * without a table (rows 1 .. k) */
    double Fth[OSC_BLOCK][NL] __attribute__((aligned(64)));
    double Fend[NL] __attribute__((aligned(64)));
    double Fraw[OSC_BLOCK + 1][NL] __attribute__((aligned(64)));
    /* the measurements: what every step updates, by vectors of lanes (the
     * previous x, v and P are the integrator's q, v and P before the step) */
    double Pi3[NL] __attribute__((aligned(64))), meas_from[NL]; /* window start - h/2 */
    /* (umax, max |x|, is the larger of xtoward and xaway: not kept apart) */
    double xtoward[NL] __attribute__((aligned(64))), xaway[NL], min_gap[NL], Pmax[NL];
    double contact[NL] __attribute__((aligned(64))); /* contact steps (whole numbers) */
    double prev2_v[NL] __attribute__((aligned(64)));
    /* ... and what the rare events update */
    pd_osc_track rare[NL];
    osc_batch_run_fn run; /* the steps for this processor */
};

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
    tr->prev_x = ob->mjb.q[l];
    tr->prev_v = ob->mjb.v[l];
    tr->prev2_v = ob->prev2_v[l];
    tr->prev_P = ob->mjb.P[l];
}

/* (prev_x, prev_v, prev_P are the integrator's state: the lane's q, v, P.) */
static inline void rare_store(osc_batch *ob, int l)
{
    const pd_osc_track *tr = &ob->rare[l];
    ob->xtoward[l] = tr->xtoward;
    ob->xaway[l] = tr->xaway;
    ob->min_gap[l] = tr->min_gap;
    ob->Pmax[l] = tr->Pmax;
    ob->contact[l] = (double)tr->contact_steps;
    ob->prev2_v[l] = tr->prev2_v;
}

/* The steps per instruction set (pd_cpu.h). */
void pd_osc_batch_run_base(osc_batch *ob, int k);
void pd_osc_batch_run_x86v3(osc_batch *ob, int k);
void pd_osc_batch_run_x86v4(osc_batch *ob, int k);

#endif
