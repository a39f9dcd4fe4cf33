/* measure.c — a method's errors against the event-driven reference on the
 * same output grid:  err_umax_rel = |umax - umax_ref| / umax_ref,
 * err_hist_linf = max_k |u(t_k) - u_ref(t_k)| / umax_ref. */
#include <math.h>
#include <stdlib.h>

#include "pd_null.h"
#include "pd_problems.h"

/* Sampler filling a preallocated array of u. */
static int record_u(const pd_osc_sample *s, void *ctx)
{
    pd_trace *tr = ctx;
    if (tr->n < tr->cap)
        tr->u[tr->n++] = s->u;
    return 0;
}

int pd_trace_alloc(pd_trace *tr, const pd_run_opts *o)
{
    if (!tr || !o)
        return PD_EINVAL;
    if (!(o->dt > 0.0) || !(o->tend >= 0.0) || !(o->tend / o->dt <= PD_MAX_STEPS))
        return PD_EINVAL; /* no grid: dt and tend not resolved */
    tr->n = 0;
    tr->dt = o->dt;
    tr->cap = pd_steps_for(o->tend, o->dt) + 2;
    tr->u = malloc((size_t)tr->cap * sizeof(double));
    return tr->u ? PD_OK : PD_ENOMEM;
}

void pd_trace_free(pd_trace *tr)
{
    if (!tr)
        return;
    free(tr->u);
    tr->u = NULL;
}

/* A run to a tolerance samples its own steps: u on the grid t_k = k dt of
 * the trace from the cubic through the steps' ends (u and v at both; over
 * a step of w h <= 1 it strays from the motion by at most (w h)^4 / 384 of
 * the amplitude), the line through them across a step with an impulse. */
typedef struct grid_fill {
    pd_trace *tr;
    double t, u, v; /* the last sample */
    int have;
} grid_fill;

static int record_grid(const pd_osc_sample *s, void *ctx)
{
    grid_fill *g = ctx;
    pd_trace *tr = g->tr;
    double h = s->t - g->t;
    for (; tr->n < tr->cap && g->have && (double)tr->n * tr->dt <= s->t; tr->n++) {
        double x = ((double)tr->n * tr->dt - g->t) / h, p[2] = {g->u, g->v}, q[2] = {s->u, s->v};
        tr->u[tr->n] =
            s->impulse > 0.0 || !(h > 0.0) ? g->u + x * (s->u - g->u) : pd_hermite3(p, q, h, x);
    }
    if (!g->have && tr->n < tr->cap && s->t == 0.0)
        tr->u[tr->n++] = s->u; /* t = 0 */
    *g = (grid_fill){.tr = tr, .t = s->t, .u = s->u, .v = s->v, .have = 1};
    return 0;
}

int pd_measure_run(const pd_osc *c, const pd_run_opts *o, const pd_trace *ref, double umax_ref,
                   pd_trace *work, pd_measured *out, pd_err *err)
{
    int rc;
    if (!c || !o || !ref || !work || !out)
        return PD_NULL_ARG(err, !c ? "c" : !o ? "o" : !ref ? "ref" : !work ? "work" : "out");
    work->n = 0;
    grid_fill fill = {.tr = work};
    if (o->rtol > 0.0 && !(work->dt > 0.0))
        return pd_err_set(err, PD_EINVAL,
                          "a run to a tolerance is measured on the grid of its "
                          "trace: dt unset (pd_trace_alloc)");
    if ((rc = o->rtol > 0.0 ? pd_osc_run(c, o, record_grid, &fill, &out->r, err)
                            : pd_osc_run(c, o, record_u, work, &out->r, err)))
        return rc;
    long n = work->n < ref->n ? work->n : ref->n;
    double worst = 0.0;
    for (long i = 0; i < n; i++)
        worst = fmax(worst, fabs(work->u[i] - ref->u[i]));
    out->err_umax_rel = fabs(out->r.umax - umax_ref) / umax_ref;
    out->err_hist_linf = worst / umax_ref;
    out->grid_points = n;
    /* its cost without the sampling (the penalty method integrates to every
     * sample time; the work-precision chart compares bare runs) */
    pd_osc_result timed;
    pd_run_opts bare = *o;
    bare.no_demands = 1;
    if ((rc = pd_osc_run(c, &bare, NULL, NULL, &timed, err)))
        return rc;
    out->r.cpu_s = timed.cpu_s;
    return PD_OK;
}

int pd_measure_reference(const pd_osc *c, const pd_run_opts *o, pd_trace *ref, pd_osc_result *res,
                         pd_err *err)
{
    int rc;
    pd_osc_result timed;
    if (!c || !o || !ref || !res)
        return PD_NULL_ARG(err, !c ? "c" : !o ? "o" : !ref ? "ref" : "res");
    ref->n = 0;
    if ((rc = pd_osc_reference(c, o, record_u, ref, res, err)))
        return rc;
    /* its cost without the sampling (nor the demands) */
    pd_run_opts bare = *o;
    bare.no_demands = 1;
    if ((rc = pd_osc_reference(c, &bare, NULL, NULL, &timed, err)))
        return rc;
    res->cpu_s = timed.cpu_s;
    if (!(res->umax > 0.0))
        return pd_err_set(err, PD_EINVAL, "the reference response is zero: no error to measure");
    return PD_OK;
}
