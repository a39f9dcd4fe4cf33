/* scene_measure.c — a method's errors against the event-driven reference
 * on a scene, per structure, on the common output grid t_k = k dt:
 *   err_umax_rel  = max over storeys |umax - umax_ref| / max over storeys umax_ref,
 *   err_hist_linf = max_k max over storeys |x(t_k) - x_ref(t_k)| / (the same).
 * The reference history is kept (rows x dofs); the method's run is compared
 * sample by sample as it goes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_problems.h"

#define TRACE_MAX_BYTES (2.0 * 1024 * 1024 * 1024) /* largest reference history kept */

int pd_scene_trace_alloc(pd_scene_trace *tr, const pd_scene *sc, const pd_run_opts *o, pd_err *err)
{
    pd_run_opts r;
    int rc;
    if (!tr)
        return pd_err_set(err, PD_EINVAL, "trace: NULL");
    memset(tr, 0, sizeof *tr);
    if ((rc = pd_scene_resolve_opts(sc, o, &r, err)))
        return rc;
    tr->n = sc->n;
    tr->cap = pd_steps_for(r.tend, r.dt) + 2;
    double bytes = (double)tr->cap * sc->n * sizeof(double);
    if (bytes > TRACE_MAX_BYTES)
        return pd_err_set(err, PD_EINVAL,
                          "dt: the reference history would take %.1f GB (%ld points x %d dofs): "
                          "use a larger dt or a smaller scene",
                          bytes / 1e9, tr->cap, sc->n);
    if (!(tr->x = malloc((size_t)tr->cap * (size_t)sc->n * sizeof(double))))
        return pd_err_set(err, PD_ENOMEM, "out of memory for the reference history");
    return PD_OK;
}

void pd_scene_trace_free(pd_scene_trace *tr)
{
    if (!tr)
        return;
    free(tr->x);
    memset(tr, 0, sizeof *tr);
}

void pd_scene_errors_free(pd_scene_errors *e)
{
    if (!e)
        return;
    free(e->err_umax);
    free(e->err_hist);
    memset(e, 0, sizeof *e);
}

int pd_scene_errors_alloc(const pd_scene *sc, pd_scene_errors *e, pd_err *err)
{
    if (!e)
        return pd_err_set(err, PD_EINVAL, "errors: NULL");
    memset(e, 0, sizeof *e);
    if (!sc || !sc->finished)
        return pd_err_set(err, PD_EINVAL, "scene: %s",
                          sc ? "not finished (pd_scene_finish)" : "NULL");
    e->err_umax = calloc((size_t)sc->nstruct, sizeof(double));
    e->err_hist = calloc((size_t)sc->nstruct, sizeof(double));
    if (!e->err_umax || !e->err_hist) {
        pd_scene_errors_free(e);
        return pd_err_set(err, PD_ENOMEM, "out of memory for the errors");
    }
    e->nstruct = sc->nstruct;
    return PD_OK;
}

/* PD_OK when the trace was allocated for sc's shape (and holds room). */
static int trace_fits(const pd_scene *sc, const pd_scene_trace *tr, pd_err *err)
{
    if (!tr || !tr->x || tr->n != sc->n || tr->cap < 1 || tr->rows < 0 || tr->rows > tr->cap)
        return pd_err_set(err, PD_EINVAL,
                          "the reference trace is not allocated for this scene "
                          "(pd_scene_trace_alloc)");
    return PD_OK;
}

/* Sampler: the reference history on its grid t = k dt, row by row (the
 * states the reference reports at its events, between grid points, are
 * not rows). */
static int keep_row(const pd_scene_sample *s, void *ctx)
{
    pd_scene_trace *tr = ctx;
    if (fabs(s->t - (double)tr->rows * tr->dt) <= 1e-9 * tr->dt && tr->rows < tr->cap)
        memcpy(tr->x + (size_t)tr->rows++ * tr->n, s->x, (size_t)tr->n * sizeof(double));
    return 0;
}

/* The largest reference displacement of each structure. */
static double structure_scale(const pd_scene *sc, const pd_scene_result *ref, int s)
{
    double m = 0.0;
    for (int k = 0; k < sc->st[s].storeys; k++)
        m = fmax(m, ref->umax[sc->st[s].dof + k]);
    return m;
}

int pd_scene_measure_reference(const pd_scene *sc, const pd_run_opts *o, pd_scene_trace *ref,
                               pd_scene_result *res, pd_err *err)
{
    pd_run_opts r;
    int rc;
    if ((rc = pd_scene_resolve_opts(sc, o, &r, err)) || /* dt 0: the scene's default */
        (rc = trace_fits(sc, ref, err)))
        return rc;
    if (!pd_scene_result_fits(sc, res))
        return pd_err_set(err, PD_EINVAL,
                          "the result is not allocated for this scene "
                          "(pd_scene_result_alloc)");
    r.method = PD_METHOD_EVENT;
    r.no_law_band = 1; /* the measurements report no law_band: no second run */
    r.no_demands = 1;  /* nor demands: umax and the history */
    ref->rows = 0;
    ref->dt = r.dt;
    if ((rc = pd_scene_run(sc, &r, keep_row, ref, res, err))) /* cpu_s: without sample() */
        return rc;
    for (int s = 0; s < sc->nstruct && !rc; s++)
        if (!(structure_scale(sc, res, s) > 0.0))
            rc = pd_err_set(err, PD_EINVAL,
                            "the reference response of '%s' is zero: no error to measure",
                            sc->st[s].name);
    return rc;
}

/* The comparison as the method runs. */
typedef struct compare_ctx {
    const pd_scene *sc;
    const pd_scene_trace *ref;
    pd_scene_errors *e;
    const double *scale;            /* nstruct */
    long stride, row;               /* the run's step in reference rows; its next row */
    double *x_prev, *v_prev, *x_at; /* to a tolerance: the last sample, a row between (n) */
    double t_prev;
    int have_prev;
    int interp; /* 1: the run's steps interpolated onto the rows */
} compare_ctx;

/* Row at of the reference against x (n displacements) into the errors. */
static void compare_at(compare_ctx *c, long at, const double *x)
{
    const double *xr = c->ref->x + (size_t)at * c->ref->n;
    for (int k = 0; k < c->sc->nstruct; k++) {
        const pd_structure *st = &c->sc->st[k];
        double worst = 0.0;
        for (int i = st->dof; i < st->dof + st->storeys; i++)
            worst = fmax(worst, fabs(x[i] - xr[i]));
        c->e->err_hist[k] = fmax(c->e->err_hist[k], worst / c->scale[k]);
    }
}

/* A run to a tolerance or on another grid: each reference row inside a
 * step compared with the cubic through the step's ends (x and v; the line
 * across a step with an impulse), as measure.c does for the oscillator. */
static void compare_steps(compare_ctx *c, const pd_scene_sample *s)
{
    int n = c->ref->n;
    double h = s->t - c->t_prev;
    int jump = 0;
    for (int a = 0; a < c->sc->ncontact; a++)
        jump |= s->impulse[a] > 0.0;
    /* every row up to this sample's time, within the rows' rounding (a run to
     * a tolerance ends at tend to a few ulps, below or above) */
    for (; c->row < c->ref->rows && (double)c->row * c->ref->dt <= s->t + 1e-9 * c->ref->dt;
         c->row++) {
        if (!c->have_prev) { /* t = 0 */
            compare_at(c, c->row, s->x);
            continue;
        }
        double r = ((double)c->row * c->ref->dt - c->t_prev) / h;
        for (int i = 0; i < n; i++) {
            double p0[2] = {c->x_prev[i], c->v_prev[i]}, p1[2] = {s->x[i], s->v[i]};
            c->x_at[i] =
                jump || !(h > 0.0) ? p0[0] + r * (p1[0] - p0[0]) : pd_hermite3(p0, p1, h, r);
        }
        compare_at(c, c->row, c->x_at);
    }
    memcpy(c->x_prev, s->x, (size_t)n * sizeof(double));
    memcpy(c->v_prev, s->v, (size_t)n * sizeof(double));
    c->t_prev = s->t;
    c->have_prev = 1;
}

/* The run's own state on a reference row. */
static void compare_row(compare_ctx *c, const pd_scene_sample *s)
{
    long at = c->row * c->stride;
    if (at >= c->ref->rows || fabs(s->t - (double)at * c->ref->dt) > 1e-9 * c->ref->dt)
        return; /* past the reference, or an event's state between grid points */
    c->row++;
    compare_at(c, at, s->x);
}

/* Sampler: the comparison (pd_scene_run's cpu_s leaves its time out). */
static int compare_sample(const pd_scene_sample *s, void *ctx)
{
    compare_ctx *c = ctx;
    if (c->interp)
        compare_steps(c, s);
    else
        compare_row(c, s);
    return 0;
}

int pd_scene_measure_run(const pd_scene *sc, const pd_run_opts *o, const pd_scene_trace *ref,
                         const pd_scene_result *ref_res, pd_scene_result *res, pd_scene_errors *e,
                         pd_err *err)
{
    pd_run_opts r;
    int rc;
    if ((rc = pd_scene_resolve_opts(sc, o, &r, err)) || (rc = trace_fits(sc, ref, err)))
        return rc;
    if (!pd_scene_result_fits(sc, ref_res) || !pd_scene_result_fits(sc, res) || !e ||
        e->nstruct != sc->nstruct || !e->err_umax || !e->err_hist)
        return pd_err_set(err, PD_EINVAL,
                          "the results or errors are not allocated for this "
                          "scene (pd_scene_result_alloc, pd_scene_errors_alloc)");
    /* on the reference's rows: the run's own states where its grid holds
     * them (a whole multiple), else its steps interpolated (to a tolerance,
     * or another grid) */
    double ratio = r.rtol > 0.0 ? 0.5 : r.dt / ref->dt;
    long stride = lround(ratio);
    int interp = stride < 1 || fabs(ratio - (double)stride) > 1e-9 * ratio;
    /* nstruct scales, then (interpolated) x_prev, v_prev, x_at */
    double *work =
        malloc(((size_t)sc->nstruct + (interp ? 3 * (size_t)sc->n : 0)) * sizeof(double));
    double *scale = work;
    if (!work)
        return pd_err_set(err, PD_ENOMEM, "out of memory");
    for (int s = 0; s < sc->nstruct; s++) {
        scale[s] = structure_scale(sc, ref_res, s);
        e->err_hist[s] = e->err_umax[s] = 0.0;
    }
    compare_ctx c = {
        .sc = sc, .ref = ref, .e = e, .scale = scale, .stride = stride, .row = 0, .interp = interp};
    if (interp) {
        c.x_prev = work + sc->nstruct;
        c.v_prev = c.x_prev + sc->n;
        c.x_at = c.v_prev + sc->n;
    }
    pd_run_opts measured = o ? *o : pd_run_default_opts();
    measured.no_demands = 1; /* umax and the history are measured, not the demands */
    measured.no_law_band = 1;
    if ((rc = pd_scene_run(sc, &measured, compare_sample, &c, res, err))) {
        free(work);
        return rc;
    }
    e->cpu_s = res->cpu_s; /* sample() and the comparison left out */
    e->err_umax_max = e->err_hist_max = 0.0;
    e->impacts = 0;
    for (int s = 0; s < sc->nstruct; s++) {
        for (int i = sc->st[s].dof; i < sc->st[s].dof + sc->st[s].storeys; i++)
            e->err_umax[s] = fmax(e->err_umax[s], fabs(res->umax[i] - ref_res->umax[i]) / scale[s]);
        e->err_umax_max = fmax(e->err_umax_max, e->err_umax[s]);
        e->err_hist_max = fmax(e->err_hist_max, e->err_hist[s]);
    }
    for (int a = 0; a < sc->ncontact; a++)
        e->impacts += res->impacts[a];
    e->grid_points = c.row;
    free(work);
    return rc;
}
