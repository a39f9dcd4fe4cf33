/* mj_batch.c — Moreau–Jean for a batch of one-DOF systems (pd_engine.h).
 *
 * Each vector of lanes runs mj1_step's operations, lane for lane the scalar kernel's
 * arithmetic, so a lane's numbers equal pd_mj's for its system alone.  The
 * step has no division, no call and no branch.  The lanes' clocks and
 * steps are their own; the breakpoints are met as pd_mj meets them
 * (mj_break_at), at a batch step computed when the lane is set, so that a
 * step checks one counter, not every lane. */
#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "pd_mj1.h"
#include "pd_engine.h"
#include "pd_null.h"

#define MJB_LANES_STEP pd_mjb_lanes_step_base
#include "mj_batch_lanes.h"

#define NVEC (PD_MJB_LANES / MJ1_WIDTH)

/* The constants of group j. */
static mj1_coefv *mjb_coef(pd_mjb *b, int j)
{
    return (mj1_coefv *)(void *)b->coef + j;
}

_Static_assert(offsetof(pd_mjb, brk_iter) % 64 == 0 && offsetof(pd_mjb, t) % 64 == 0 &&
                   offsetof(pd_mjb, coef) % 64 == 0 && sizeof(pd_mjb) % 64 == 0,
               "pd_mjb's lane arrays start on 64-byte lines");

/* The lanes' step for this processor: AVX-512 or AVX2 when it has them
 * (the same text compiled for each, mj_batch_lanes.h), else the baseline. */
static pd_mjb_step_fn lanes_step_for_cpu(void)
{
    switch (pd_cpu_level()) {
#if PD_X86_VARIANTS
    case 4:
        return pd_mjb_lanes_step_x86v4;
    case 3:
        return pd_mjb_lanes_step_x86v3;
#endif
    default:
        return pd_mjb_lanes_step_base;
    }
}

/* The idle lane: a unit mass at rest, no contact, no force breakpoint. */
static const pd_mjb_lane idle_lane = {.M = 1.0, .h = 1.0, .brk = INFINITY};

int pd_mjb_init(pd_mjb *b, const pd_mj_opts *opts, pd_mjb_force force, void *force_ctx, pd_err *err)
{
    pd_mj_opts o = opts ? *opts : pd_mj_default_opts();
    int rc;
    pd_err_clear(err);
    if (!b)
        return PD_NULL_ARG(err, "b");
    o.h = 1.0; /* the lanes have their own */
    if ((rc = pd_mj_check_opts(&o, err)))
        return rc;
    memset(b, 0, sizeof *b);
    b->theta = o.theta;
    b->gamma = o.gamma;
    b->force = force;
    b->force_ctx = force_ctx;
    b->next_event = LONG_MAX;
    b->lanes_step = lanes_step_for_cpu();
    /* every lane idle until set */
    for (int l = 0; l < PD_MJB_LANES; l++)
        if ((rc = pd_mjb_set_lane(b, l, &idle_lane, err)))
            return rc;
    return PD_OK;
}

/* A lane's system and contact in range: PD_OK or PD_EINVAL naming it. */
static int check_lane(const pd_mjb_lane *ln, int l, pd_err *err)
{
    if (l < 0 || l >= PD_MJB_LANES)
        return pd_err_set(err, PD_EINVAL, "batch: lane %d outside [0, %d)", l, PD_MJB_LANES);
    if (!(ln->M > 0.0) || !isfinite(ln->M) || !isfinite(ln->C) || !isfinite(ln->K))
        return pd_err_set(err, PD_EINVAL, "batch: lane %d: M > 0, C and K finite needed", l);
    if (!(ln->h > 0.0) || !isfinite(ln->h) || isnan(ln->brk))
        return pd_err_set(err, PD_EINVAL,
                          "batch: lane %d: h > 0 finite, a breakpoint "
                          "(INFINITY: none) needed",
                          l);
    /* W = 0 would make D = W^2 / What zero: a wall that never acts */
    if (ln->wall && (!isfinite(ln->W) || ln->W == 0.0 || !(ln->g0 >= 0.0) || !isfinite(ln->g0) ||
                     !(ln->e >= 0.0 && ln->e <= 1.0)))
        return pd_err_set(err, PD_EINVAL,
                          "batch: lane %d: W finite and nonzero, g0 >= 0 "
                          "finite, e in [0, 1] needed",
                          l);
    return PD_OK;
}

/* The first step count s >= 1 at which mj_break_at acts on brk for steps h
 * (brk <= s h + tol), or 0 when it never does (no breakpoint, or one
 * before t = 0, which pd_mj skips at reset). */
static long break_step(double brk, double h)
{
    double tol = 1e-9 * h;
    /* no breakpoint, or one before t = 0 */
    if (!isfinite(brk) || brk < -tol)
        return 0;
    /* an estimate, then s corrected both ways by mj_break_at's own test brk <= s h + tol */
    double est = ceil((brk - tol) / h);
    long s = est < 1.0 ? 1 : (long)est;
    while (s > 1 && brk <= (double)(s - 1) * h + tol)
        s--;
    while (!(brk <= (double)s * h + tol))
        s++;
    return s;
}

/* The earliest batch step at which a lane meets its breakpoint. */
static void next_event(pd_mjb *b)
{
    b->next_event = LONG_MAX;
    for (int l = 0; l < PD_MJB_LANES; l++)
        if (b->brk_iter[l] < b->next_event)
            b->next_event = b->brk_iter[l];
}

int pd_mjb_set_lane(pd_mjb *b, int l, const pd_mjb_lane *ln, pd_err *err)
{
    int rc;
    if (!b || !ln)
        return PD_NULL_ARG(err, !b ? "b" : "ln");
    if ((rc = check_lane(ln, l, err)))
        return rc;
    mj1_coef one =
        mj1_coef_make(ln->M, ln->C, ln->K, ln->wall, ln->W, ln->g0, ln->e, ln->h, b->theta);
    mj1_coef_setv(mjb_coef(b, l / MJ1_WIDTH), l % MJ1_WIDTH, &one, ln->h, b->theta, b->gamma);
    b->h[l] = ln->h;
    b->brk[l] = ln->brk;
    b->t[l] = b->steps[l] = 0.0; /* the lane's clock restarts at 0 */
    b->q[l] = b->v[l] = b->P[l] = 0.0;
    b->g[l] = one.g0 + one.w * 0.0; /* g0 + W q at q = 0, the step's expression */
    long s = break_step(ln->brk, ln->h);
    /* the batch step at which the lane meets it (LONG_MAX: never) */
    b->brk_iter[l] = s > 0 && s <= LONG_MAX - b->iter ? b->iter + s : LONG_MAX;
    next_event(b);
    /* F(0+) for this lane: the force is asked for every lane at its clock */
    if (b->force) {
        b->force(b->t, +1, b->F1, b->force_ctx);
        b->F0[l] = b->F1[l];
    } else
        b->F0[l] = 0.0;
    return PD_OK;
}

/* The lanes' clocks at the end of the step: (steps + 1) h, as pd_mj's
 * t0 + (step + 1) h with t0 = 0. */
static void step_clocks(pd_mjb *b)
{
    for (int j = 0; j < NVEC; j++) {
        mj1_vec st, h;
        memcpy(&st, &b->steps[j * MJ1_WIDTH], sizeof st);
        memcpy(&h, &b->h[j * MJ1_WIDTH], sizeof h);
        /* t = (steps + 1) h, not t + h: no drift, the clock of pd_mj to the bit */
        st += 1.0;
        mj1_vec t = st * h;
        memcpy(&b->steps[j * MJ1_WIDTH], &st, sizeof st);
        memcpy(&b->t[j * MJ1_WIDTH], &t, sizeof t);
    }
}

/* Lanes meeting their breakpoint at this step: those landing on it start
 * the next step from F(t+), as pd_mj's advance_force. */
void pd_mjb_breakpoints(pd_mjb *b)
{
    unsigned long long any = 0;
    for (int l = 0; l < PD_MJB_LANES; l++) {
        if (b->brk_iter[l] != b->iter)
            continue;
        /* mj_break_at on the lane's one breakpoint decides, as pd_mj's */
        int next = 0;
        b->brk_iter[l] = LONG_MAX; /* met once */
        if (mj_break_at(&b->brk[l], 1, &next, b->t[l], 1e-9 * b->h[l]))
            any |= 1ULL << l;
    }
    /* F(t+) asked once for every lane; the lanes on their breakpoint take it */
    if (any && b->force) {
        double Fr[PD_MJB_LANES];
        b->force(b->t, +1, Fr, b->force_ctx);
        for (int l = 0; l < PD_MJB_LANES; l++)
            if (any & (1ULL << l))
                b->F0[l] = Fr[l];
    }
    next_event(b);
}

void pd_mjb_run(pd_mjb *b, long nsteps, pd_mjb_observer observer, void *ctx)
{
    if (!b)
        return;
    for (long n = 0; n < nsteps; n++) {
        /* the lanes' t_k+1, F(t_k+1 -) for every lane, the step */
        step_clocks(b);
        if (b->force)
            b->force(b->t, -1, b->F1, b->force_ctx);
        else
            memset(b->F1, 0, sizeof b->F1); /* no force */
        b->lanes_step(b);
        b->iter++;
        if (b->iter == b->next_event) /* one counter, not every lane */
            pd_mjb_breakpoints(b);
        if (observer && observer(b, ctx) > 0)
            return;
    }
}

/* A state that stops being finite stays so: q and v feed every later q
 * and v through sums and products, so the state now tells. */
int pd_mjb_finite(const pd_mjb *b, int l)
{
    return b && l >= 0 && l < PD_MJB_LANES && isfinite(b->q[l]) && isfinite(b->v[l]);
}
