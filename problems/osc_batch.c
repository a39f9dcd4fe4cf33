/* osc_batch.c — the oscillator's runs from a stream of cases, the
 * Moreau–Jean ones many at a time (pd_problems.h).
 *
 * The Moreau–Jean cases run on the lanes of a pd_mjb (engine/mj_batch.c):
 * a lane takes the next case as soon as its run ends, so runs of different
 * lengths keep every lane busy.  A case's figures are pd_osc_simulate's,
 * bit for bit: the same step (engine/pd_mj1.h), the same excitation values
 * (pd_osc_shape, once per step for lanes at the same instant of the same
 * excitation), the same measurements (osc_track.h: the common ones here on
 * whole vectors of lanes, the rare ones -- a gap closing, an impact -- by
 * the very function the single run calls). */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define OSC_BATCH_RUN pd_osc_batch_run_base
#include "osc_batch_lanes.h"

#include "demand.h"
#include "osc_batch.h"
#include "pd_null.h"

/* Cases a and b excite their oscillators by one shape. */
static int same_shape(const pd_osc *a, const pd_osc *b)
{
    if (a->record || b->record)
        return a->record == b->record && a->Tp == b->Tp && a->rec_ap == b->rec_ap;
    return a->pulse == b->pulse;
}

/* Lane l stops reading its excitation table. */
static void table_release(osc_batch *ob, int l)
{
    if (ob->table[l] >= 0)
        ob->tab[ob->table[l]].users--;
    ob->table[l] = -1;
}

/* Lane l reads the table of its excitation at its step h, n steps long
 * (the steps inside it): one kept with the same shape and step, else one
 * no lane reads, filled; none (the lane computes its forces per step) when
 * the excitation is longer than OSC_TABLE_MAX steps or the table's memory
 * was not had at batch_open.
 * The values are the ones the lane would compute: pd_osc_shape at s h. */
static void table_acquire(osc_batch *ob, int l, double h, long n)
{
    int free_slot = -1;
    ob->table[l] = -1;
    if (n < 1 || n > OSC_TABLE_MAX)
        return;
    for (int i = 0; i < OSC_TABLES; i++) {
        osc_table *tb = &ob->tab[i];
        if (tb->n == n && tb->h == h && same_shape(&tb->unit, &ob->unit[l])) {
            tb->users++;
            ob->table[l] = i;
            return;
        }
        if (tb->users == 0 && (free_slot < 0 || tb->n == 0))
            free_slot = i;
    }
    if (free_slot < 0)
        return;
    osc_table *tb = &ob->tab[free_slot];
    if (tb->cap < n) /* its memory was not had at batch_open */
        return;
    tb->unit = ob->unit[l];
    tb->h = h;
    tb->n = n;
    const double th = ob->mjb.theta;
    tb->v[0] = tb->vth[0] = 0.0;
    for (long s = 1; s <= n; s++)
        tb->v[s] = pd_osc_shape(&tb->unit, (double)s * h, -1);
    tb->v[n + 1] = 0.0; /* past the excitation */
    for (long s = 1; s <= n; s++)
        tb->vth[s] = mj1_fth(th, tb->v[s], tb->v[s + 1]);
    tb->users = 1;
    ob->table[l] = free_slot;
}

/* Every lane's force at its own clock (the pd_mjb's force: the right
 * limits at a lane's start and its excitation's end; the steps' left
 * limits come from fill_forces): the case's pd_osc_shape, 0 past the
 * excitation and for idle lanes. */
static void lanes_force(const double *t, int side, double *F, void *ctx)
{
    osc_batch *ob = ctx;
    for (int l = 0; l < NL; l++)
        F[l] = ob->id[l] >= 0 && (side > 0 || ob->mjb.iter < ob->quiet_iter[l])
                   ? pd_osc_shape(&ob->c[l], t[l], side)
                   : 0.0;
}

/* Lane l's force rows 1 .. OSC_BLOCK - 1 cleared: it leaves its
 * excitation (or the batch). */
static void column_clear(osc_batch *ob, int l)
{
    for (int s = 1; s < OSC_BLOCK; s++)
        ob->Fth[s][l] = 0.0;
}

/* The forces of the next k steps of the block: Fth[s] the force of step
 * s + 1, theta F(s + 1) + (1 - theta) F(s), from the integrator's F0 at
 * the block's start and the left limits F(s) at the steps' ends: dir
 * times its excitation's table (its vth from row 1) or, without one, its
 * shape (computed once for neighbouring lanes at the same instant of the
 * same excitation; pd_osc_shape is odd in dir); 0 past the excitation.
 * Fend: F(k), the next block's F0.  Lanes past their excitation leave the
 * list `live` and their table, their rows cleared.  A table's dir vth is
 * the step's own theta (dir a) + (1 - theta) (dir b) but for the sign of
 * a zero sum, which cannot reach the state: it changes the step's
 * h (Fth - C v - K (q + h theta v)) only when that is zero, and v + 0 is
 * v whatever the zero's sign unless v is -0, which a lane's velocity
 * never is (it starts at +0, and a sum is -0 only of two -0). */
static void fill_forces(osc_batch *ob, int k)
{
    pd_mjb *b = &ob->mjb;
    const double th = b->theta;
    long iter = b->iter;
    int n = 0, own[NL], nown = 0; /* own: the live lanes without a table, in order */
    double F1[NL];                /* F(1) of every lane */
    for (int l = 0; l < NL; l++)
        F1[l] = ob->Fend[l] = 0.0;
    for (int i = 0; i < ob->nlive; i++) {
        int l = ob->live[i];
        if (iter >= ob->quiet_iter[l]) { /* past its excitation from now on */
            table_release(ob, l);
            column_clear(ob, l);
            continue;
        }
        ob->live[n++] = l;
        long left = ob->quiet_iter[l] - iter; /* steps s <= left are inside it */
        int m = left < k ? (int)left : k;
        if (ob->table[l] < 0) {
            own[nown++] = l;
            continue;
        }
        const osc_table *tb = &ob->tab[ob->table[l]];
        long st = (long)b->steps[l];
        double dir = ob->dir[l];
        F1[l] = dir * tb->v[st + 1];
        ob->Fend[l] = k <= m ? dir * tb->v[st + k] : 0.0;
        for (int s = 1; s < k; s++)
            ob->Fth[s][l] = s <= m ? dir * tb->vth[st + s] : 0.0;
    }
    ob->nlive = n;
    for (int s = 1; s <= k && nown > 0; s++) {
        double base = 0.0, tp = 0.0;
        int prev = -1; /* the last lane whose base was computed or reused */
        for (int i = 0; i < nown; i++) {
            int l = own[i];
            if (iter + s - 1 >= ob->quiet_iter[l]) {
                ob->Fraw[s][l] = 0.0;
                continue;
            }
            double t = (b->steps[l] + (double)s) * b->h[l];
            if (!(prev == l - 1 && ob->same_prev[l] && t == tp))
                base = pd_osc_shape(&ob->unit[l], t, -1);
            ob->Fraw[s][l] = ob->dir[l] * base;
            prev = l;
            tp = t;
        }
    }
    for (int i = 0; i < nown; i++) {
        int l = own[i];
        F1[l] = ob->Fraw[1][l];
        ob->Fend[l] = ob->Fraw[k][l];
        for (int s = 1; s < k; s++)
            ob->Fth[s][l] = mj1_fth(th, ob->Fraw[s][l], ob->Fraw[s + 1][l]);
    }
    for (int l = 0; l < NL; l++)
        ob->Fth[0][l] = mj1_fth(th, b->F0[l], F1[l]);
}

/* Recompute lane l's and lane l + 1's neighbour flags. */
static void neighbours(osc_batch *ob, int l)
{
    for (int k = l; k <= l + 1 && k < NL; k++)
        ob->same_prev[k] = k > 0 && ob->id[k] >= 0 && ob->id[k - 1] >= 0 &&
                           same_shape(&ob->unit[k], &ob->unit[k - 1]);
}

/* The first step count s >= 1 whose end s h lies past cut (the force's
 * left limit is 0 from there on), 0 when none does. */
static long cut_step(double cut, double h)
{
    if (!(cut < (double)LONG_MAX * h * 0.5))
        return 0;
    double est = floor(cut / h);
    long s = est < 1.0 ? 1 : (long)est;
    while (s > 1 && (double)(s - 1) * h > cut)
        s--;
    while (!((double)s * h > cut))
        s++;
    return s;
}

/* Lane l joins the lanes inside their excitation (kept in increasing
 * order, so that neighbours meet). */
static void live_insert(osc_batch *ob, int l)
{
    int i = ob->nlive;
    while (i > 0 && ob->live[i - 1] > l) {
        ob->live[i] = ob->live[i - 1];
        i--;
    }
    ob->live[i] = l;
    ob->nlive++;
}

/* Lane l leaves that list (its force rows cleared). */
static void live_remove(osc_batch *ob, int l)
{
    int n = 0;
    column_clear(ob, l);
    for (int i = 0; i < ob->nlive; i++)
        if (ob->live[i] != l)
            ob->live[n++] = ob->live[i];
    ob->nlive = n;
}

/* Lane l starts case (c, o): its system, its excitation, and the
 * measurements of its state at rest (as the single run's first
 * observation). */
static int lane_start(osc_batch *ob, int l, long id, const pd_osc *c, const pd_run_opts *o,
                      pd_err *err)
{
    double h = PD_TWO_PI * (o->dt / c->Tp), end = pd_osc_shape_end(c);
    pd_mjb_lane ln = {.M = 1.0,
                      .C = 2.0 * c->xi * c->Pi2,
                      .K = c->Pi2 * c->Pi2,
                      .wall = 1, /* without one: a wall at +inf (osc_batch_lanes.h) */
                      .W = -1.0,
                      .g0 = c->Pi3,
                      .e = c->eps,
                      .h = h,
                      .brk = isfinite(end) ? end : INFINITY};
    ob->id[l] = id;
    ob->c[l] = *c;
    ob->unit[l] = *c;
    ob->unit[l].dir = 1;
    ob->o[l] = *o;
    ob->dir[l] = (double)c->dir;
    ob->nsteps[l] = pd_steps_for(o->tend, o->dt);
    long sc = cut_step(pd_shape_cut(end, -1), h), it = ob->mjb.iter;
    ob->quiet_iter[l] = sc > 0 && sc - 1 <= LONG_MAX - it ? it + sc - 1 : LONG_MAX;
    live_insert(ob, l);
    table_acquire(ob, l, h, sc > 0 ? sc - 1 : 0);
    ob->cpu[l] = 0.0;
    neighbours(ob, l);
    int rc = pd_mjb_set_lane(&ob->mjb, l, &ln, err);
    if (rc)
        return rc;
    if (o->no_wall)
        mj1_lanes_far_wall(&ob->mjb, l);
    pd_osc_track *tr = &ob->rare[l];
    pd_osc_track_init(tr, c, h, pd_osc_wp(c) * pd_osc_measure_start(c, o->tend));
    pd_osc_track_step(tr, 0, 0.0, 0.0, 0.0, 0.0);
    rare_store(ob, l);
    ob->Pi3[l] = tr->Pi3;
    ob->meas_from[l] = tr->tau_measure - 0.5 * tr->h;
    return PD_OK;
}

/* Lane l without a case. */
static void lane_idle(osc_batch *ob, int l)
{
    static const pd_mjb_lane idle = {.M = 1.0, .wall = 1, .W = -1.0, .h = 1.0, .brk = INFINITY};
    ob->id[l] = -1;
    live_remove(ob, l);
    table_release(ob, l);
    neighbours(ob, l);
    pd_mjb_set_lane(&ob->mjb, l, &idle, NULL);
    mj1_lanes_far_wall(&ob->mjb, l); /* never closing: its set's steps may skip the impulses */
    ob->Pi3[l] = 1.0;                /* a gap that never closes */
    ob->meas_from[l] = HUGE_VAL;
    ob->prev2_v[l] = 0.0;
}

/* The result of lane l's finished run, as pd_osc_simulate gives it. */
static void lane_result(osc_batch *ob, int l, pd_osc_result *res)
{
    pd_osc_track *tr = &ob->rare[l];
    const pd_run_opts *o = &ob->o[l];
    rare_load(ob, l);
    pd_osc_track_result(tr, &ob->c[l], o->dt, ob->nsteps[l], res);
    res->tend = o->tend;
    res->theta = o->theta;
    res->gamma = o->gamma;
    res->kernel = "batched";
    res->cpu_s = ob->cpu[l];
    /* the equivalent force from the largest impulse, as a single run's;
     * the peak acceleration is not measured on the lanes */
    pd_demand_osc_finish(res, o, NAN, NAN, NAN);
}

int pd_osc_batchable(const pd_osc *c, const pd_run_opts *o)
{
    if (!c || !o)
        return 0;
    return o->method == PD_METHOD_MOREAU && o->kernel == PD_KERNEL_AUTO && !o->on_lcp &&
           !pd_osc_yields(c);
}

/* The steps for this processor (osc_batch_lanes.h, as for the engine's
 * step). */
static osc_batch_run_fn run_for_cpu(void)
{
    switch (pd_cpu_level()) {
#if PD_X86_VARIANTS
    case 4:
        return pd_osc_batch_run_x86v4;
    case 3:
        return pd_osc_batch_run_x86v3;
#endif
    default:
        return pd_osc_batch_run_base;
    }
}

/* k steps of every lane (no lane ends before the last), in blocks that
 * end where a lane meets its breakpoint (pd_mjb_run's order: the step,
 * then the breakpoints). */
static void run_steps(osc_batch *ob, long k)
{
    pd_mjb *b = &ob->mjb;
    while (k > 0) {
        long to_event = b->next_event - b->iter; /* >= 1 */
        int n = (int)(k < OSC_BLOCK ? k : OSC_BLOCK);
        n = to_event < n ? (int)to_event : n;
        fill_forces(ob, n);
        ob->run(ob, n);
        k -= n;
        if (b->iter == b->next_event)
            pd_mjb_breakpoints(b);
    }
}

/* The batch's memory. */
static void batch_free(osc_batch *ob)
{
    if (!ob)
        return;
    for (int i = 0; i < OSC_TABLES; i++)
        free(ob->tab[i].v);
    free(ob);
}

/* The stream's state: the source, the batch (allocated on the first
 * batchable case) and its options. */
typedef struct stream {
    pd_osc_stream_next next;
    pd_osc_stream_done done;
    void *ctx;
    osc_batch *ob;
    pd_run_opts batch_opts; /* theta, gamma, allow_unstable of the batch */
    int exhausted;
} stream;

/* A case run alone, reported. */
static void run_single(stream *s, long id, const pd_osc *c, const pd_run_opts *o)
{
    pd_osc_result res;
    pd_err e;
    int rc = pd_osc_run(c, o, NULL, NULL, &res, &e);
    s->done(s->ctx, id, &res, rc, &e);
}

/* The batch joins runs of the same theta, gamma and stability choice. */
static int fits_batch(const stream *s, const pd_run_opts *o)
{
    const pd_run_opts *b = &s->batch_opts;
    return o->theta == b->theta && o->gamma == b->gamma && o->allow_unstable == b->allow_unstable;
}

/* The batch, allocated and set up for the options of its first case:
 * PD_OK, or a status when out of memory or the options are refused. */
static int batch_open(stream *s, const pd_run_opts *o, pd_err *err)
{
    pd_mj_opts mo = pd_mj_default_opts();
    s->ob = aligned_alloc(64, (sizeof *s->ob + 63) / 64 * 64);
    if (!s->ob)
        return pd_err_set(err, PD_ENOMEM, "out of memory for a batch of %d runs", NL);
    memset(s->ob, 0, sizeof *s->ob);
    mo.theta = o->theta;
    mo.gamma = o->gamma;
    mo.allow_unstable = o->allow_unstable;
    s->ob->run = run_for_cpu();
    for (int l = 0; l < NL; l++)
        s->ob->table[l] = -1;
    /* the tables' memory once, here (touched only as far as filled): no
     * allocation while lanes start runs inside the batch's steps; a table
     * not had stays empty, its lanes compute their forces per step */
    for (int i = 0; i < OSC_TABLES; i++) {
        osc_table *tb = &s->ob->tab[i];
        if ((tb->v = malloc((size_t)(2 * OSC_TABLE_MAX + 3) * sizeof *tb->v))) {
            tb->vth = tb->v + OSC_TABLE_MAX + 2;
            tb->cap = OSC_TABLE_MAX;
        }
    }
    int rc = pd_mjb_init(&s->ob->mjb, &mo, lanes_force, s->ob, err);
    if (rc) {
        batch_free(s->ob);
        s->ob = NULL;
        return rc;
    }
    s->batch_opts = *o;
    for (int l = 0; l < NL; l++)
        lane_idle(s->ob, l);
    return PD_OK;
}

/* Lane l takes the next case the batch can run; the others run alone as
 * they come.  Leaves it idle when the source is exhausted. */
static void refill(stream *s, int l)
{
    pd_osc c;
    pd_run_opts o;
    long id;
    pd_err e;
    while (!s->exhausted) {
        if (!s->next(s->ctx, &c, &o, &id)) {
            s->exhausted = 1;
            break;
        }
        pd_run_opts ro;
        if (!pd_osc_batchable(&c, &o) || pd_osc_resolve_opts(&c, &o, &ro, NULL) ||
            (!s->ob && batch_open(s, &ro, &e)) || !fits_batch(s, &ro) ||
            lane_start(s->ob, l, id, &c, &ro, &e)) {
            if (s->ob && s->ob->id[l] >= 0)
                lane_idle(s->ob, l);
            run_single(s, id, &c, &o);
            continue;
        }
        s->ob->busy++;
        return;
    }
    if (s->ob)
        lane_idle(s->ob, l);
}

/* Lane l's run ended: reported (a run that stopped being finite is run
 * again alone, which names the step), and the lane refilled. */
static void finish(stream *s, int l)
{
    osc_batch *ob = s->ob;
    long id = ob->id[l];
    ob->busy--;
    if (!pd_mjb_finite(&ob->mjb, l)) {
        pd_osc c = ob->c[l];
        pd_run_opts o = ob->o[l];
        lane_idle(ob, l);
        run_single(s, id, &c, &o);
    } else {
        pd_osc_result res;
        pd_err e;
        lane_result(ob, l, &res);
        pd_err_clear(&e);
        lane_idle(ob, l);
        s->done(s->ctx, id, &res, PD_OK, &e);
    }
    refill(s, l);
}

int pd_osc_run_stream(pd_osc_stream_next next, pd_osc_stream_done done, void *ctx, pd_err *err)
{
    if (!next || !done)
        return PD_NULL_ARG(err, !next ? "next" : "done");
    stream s = {.next = next, .done = done, .ctx = ctx};
    pd_err_clear(err);
    /* fill the lanes (the batch opens with its first case) */
    for (int l = 0; l < NL && !s.exhausted; l++)
        refill(&s, l);
    while (s.ob && s.ob->busy > 0) {
        osc_batch *ob = s.ob;
        long k = -1; /* steps until the first lane ends */
        for (int l = 0; l < NL; l++)
            if (ob->id[l] >= 0) {
                long left = ob->nsteps[l] - (long)ob->mjb.steps[l];
                k = k < 0 || left < k ? left : k;
            }
        double cpu0 = pd_cpu_seconds();
        run_steps(ob, k);
        double share = (pd_cpu_seconds() - cpu0) / ob->busy;
        for (int l = 0; l < NL; l++)
            if (ob->id[l] >= 0)
                ob->cpu[l] += share;
        for (int l = 0; l < NL; l++)
            if (ob->id[l] >= 0 && (long)ob->mjb.steps[l] >= ob->nsteps[l])
                finish(&s, l);
    }
    batch_free(s.ob);
    return PD_OK;
}
