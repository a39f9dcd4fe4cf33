/* spectrum.c — a spectrum sweep as a list of tasks: the Pi2 grid, where
 * each task sits, its case (resolved exactly as `pound simulate` resolves
 * one), a task's run, its cost, the canonical key, and the output rows. */
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "pd_null.h"
#include "pd_problems.h"

static int check_lists(const pd_spectrum *s, pd_err *err);

void pd_spec_init(pd_spectrum *s)
{
    if (!s)
        return;
    memset(s, 0, sizeof *s);
    s->base = pd_osc_default();
    s->opts = pd_run_default_opts();
    s->npulse = s->ndir = s->nap = s->nxi = s->nsize = s->neps = 1;
    s->pulse[0] = PD_PULSE_SINE;
    s->dir[0] = 1;
    s->ap[0] = s->base.ap;
    s->xi[0] = s->base.xi;
    s->size[0] = s->base.Pi3;
    s->eps[0] = s->base.eps;
}

long pd_spec_curves(const pd_spectrum *s)
{
    if (!s)
        return 0;
    return (long)s->npulse * s->ndir * s->nap * s->nxi * s->nsize * s->neps;
}

long pd_spec_points(const pd_spectrum *s)
{
    return s ? pd_spec_curves(s) * s->npi2 : 0;
}

long pd_spec_twins(const pd_spectrum *s)
{
    if (!s)
        return 0;
    return (long)s->npulse * s->ndir * s->nap * s->nxi * s->npi2;
}

long pd_spec_tasks(const pd_spectrum *s)
{
    return s ? pd_spec_twins(s) + pd_spec_points(s) : 0;
}

double pd_grid_value(double lo, double hi, int n, int linear, int j)
{
    if (n < 2 || j <= 0)
        return lo;
    if (j >= n - 1)
        return hi;
    double t = (double)j / (n - 1);
    if (linear)
        return lo + (hi - lo) * t;
    return lo * pow(hi / lo, t);
}

double pd_spec_pi2(const pd_spectrum *s, int j)
{
    if (!s)
        return NAN;
    return pd_grid_value(s->pi2_min, s->pi2_max, s->npi2, s->linear, j);
}

/* Split a (pulse, dir, ap, xi) group index into its digits, xi fastest. */
static void group_digits(const pd_spectrum *s, long g, pd_spec_coords *co)
{
    co->xi = (int)(g % s->nxi);
    g /= s->nxi;
    co->ap = (int)(g % s->nap);
    g /= s->nap;
    co->dir = (int)(g % s->ndir);
    co->pulse = (int)(g / s->ndir);
}

void pd_spec_coords_of(const pd_spectrum *s, long task, pd_spec_coords *co)
{
    if (!s || !co)
        return;
    long ntw = pd_spec_twins(s);
    memset(co, 0, sizeof *co);
    if (check_lists(s, NULL))
        return; /* an empty list or grid: nothing to split by */
    if (task < ntw) {
        co->twin = 1;
        co->curve = -1;
        co->j = (int)(task % s->npi2);
        group_digits(s, task / s->npi2, co);
        return;
    }
    long p = task - ntw, c = p / s->npi2;
    co->curve = c;
    co->j = (int)(p % s->npi2);
    co->eps = (int)(c % s->neps);
    c /= s->neps;
    co->size = (int)(c % s->nsize);
    group_digits(s, c / s->nsize, co);
}

long pd_spec_twin_of(const pd_spectrum *s, long task)
{
    if (!s || check_lists(s, NULL))
        return -1;
    long p = task - pd_spec_twins(s);
    long group = (p / s->npi2) / ((long)s->nsize * s->neps);
    return group * s->npi2 + p % s->npi2;
}

int pd_spec_case(const pd_spectrum *s, long task, pd_osc *c, pd_run_opts *o, pd_err *err)
{
    pd_spec_coords co;
    int rc;
    if (!s || !c || !o)
        return PD_NULL_ARG(err, !s ? "s" : !c ? "c" : "o");
    if ((rc = check_lists(s, err)))
        return rc;
    if (task < 0 || task >= pd_spec_tasks(s))
        return pd_err_set(err, PD_EINVAL, "task: %ld is not one of the sweep's %ld", task,
                          pd_spec_tasks(s));
    pd_spec_coords_of(s, task, &co);
    *c = s->base;
    *o = s->opts;
    c->pulse = s->pulse[co.pulse];
    c->dir = s->dir[co.dir];
    c->ap = s->ap[co.ap];
    if (c->record) /* the amplitudes of a record's sweep are its pulse's: scales */
        c->scale = c->ap / c->rec_ap;
    c->xi = s->xi[co.xi];
    c->eps = s->eps[co.eps];
    c->Pi2 = pd_spec_pi2(s, co.j);
    if (s->size_is_gap)
        pd_osc_set_gap(c, s->size[co.size]);
    else
        c->Pi3 = s->size[co.size];
    if (s->dt_per_Tp > 0.0)
        o->dt = c->Tp / s->dt_per_Tp;
    o->no_wall = co.twin;
    o->no_demands = 1; /* a spectrum keeps umax and the impacts */
    return pd_osc_resolve_opts(c, o, o, err);
}

int pd_spec_validate(const pd_spectrum *s, pd_err *err)
{
    pd_osc c;
    pd_run_opts o;
    int rc;
    if (!s)
        return PD_NULL_ARG(err, "s");
    if ((rc = check_lists(s, err)))
        return rc;
    long ntw = pd_spec_twins(s), n = pd_spec_tasks(s);
    for (long t = ntw; t < n; t++)
        if (pd_spec_case(s, t, &c, &o, err))
            return PD_EINVAL;
    return PD_OK;
}

void pd_spec_resolve_method(pd_spectrum *s)
{
    pd_osc c;
    pd_run_opts o;
    if (!s)
        return;
    long n = pd_spec_tasks(s);
    if (s->opts.method != PD_METHOD_AUTO)
        return;
    if (pd_osc_yields(&s->base) && !pd_osc_yield_exact(&s->base)) { /* Moreau-Jean's alone */
        s->opts.method = PD_METHOD_MOREAU;
        return;
    }
    s->opts.method = PD_METHOD_EVENT;
    for (long t = 0; t < n; t++)
        if (!pd_spec_case(s, t, &c, &o, NULL) && o.method != PD_METHOD_EVENT) {
            s->opts.method = PD_METHOD_MOREAU;
            return;
        }
}

double pd_spec_cost(const pd_spectrum *s, long task)
{
    pd_osc c;
    pd_run_opts o;
    if (!s)
        return NAN;
    if (pd_spec_case(s, task, &c, &o, NULL))
        return 1.0;
    return (double)pd_steps_for(o.tend, o.dt);
}

/* A run's figures as a task's result. */
static void result_of(const pd_osc_result *res, pd_spec_result *r)
{
    r->umax = res->umax;
    r->u_toward = res->u_toward;
    r->u_away = res->u_away;
    r->contact_time = res->contact_time;
    r->first_impact = res->first_impact;
    r->cpu_s = res->cpu_s;
    r->impacts = res->impacts;
    r->steps = res->steps;
    r->ductility = res->ductility;
    r->residual = res->residual;
    r->done = 1;
}

/* One task: its case, the chosen method, the figures kept; a failure's
 * message names the point. */
void pd_spec_run_task(const pd_spectrum *s, long t, pd_spec_result *r, pd_err *err)
{
    pd_osc c;
    pd_run_opts o;
    pd_osc_result res;
    if (!s || !r) {
        if (r)
            *r = (pd_spec_result){.status = PD_EINVAL};
        PD_NULL_ARG(err, !s ? "s" : "r");
        return;
    }
    memset(r, 0, sizeof *r);
    pd_err_clear(err);
    if (pd_spec_case(s, t, &c, &o, err)) {
        r->status = PD_EINVAL;
        return;
    }
    if ((r->status = pd_osc_run(&c, &o, NULL, NULL, &res, err))) {
        if (!err)
            return;
        char m[sizeof err->msg];
        snprintf(m, sizeof m, "%s", err->msg);
        pd_err_set(err, r->status, "%s %s pulse, Pi2 = %.6g, Pi3 = %.6g, eps = %g%s: %s",
                   pd_dir_name(c.dir), pd_pulse_name(c.pulse), c.Pi2, c.Pi3, c.eps,
                   o.no_wall ? " (no wall)" : "", m);
        return;
    }
    result_of(&res, r);
}

/* ---- tasks as a stream of runs ------------------------------------------ */

/* The stream's source and sink: the sweep's tasks, the caller's. */
typedef struct task_stream {
    const pd_spectrum *s;
    pd_spec_task_next next;
    pd_spec_task_done done;
    void *ctx;
} task_stream;

static int stream_next(void *ctx, pd_osc *c, pd_run_opts *o, long *id)
{
    task_stream *ts = ctx;
    for (;;) {
        long t = ts->next(ts->ctx);
        if (t < 0)
            return 0;
        if (!pd_spec_case(ts->s, t, c, o, NULL)) {
            *id = t;
            return 1;
        }
        /* a case that does not resolve: reported with its message */
        pd_spec_result r;
        pd_err e;
        pd_spec_run_task(ts->s, t, &r, &e);
        ts->done(ts->ctx, t, &r, &e);
    }
}

static void stream_done(void *ctx, long id, const pd_osc_result *res, int status, const pd_err *err)
{
    task_stream *ts = ctx;
    pd_spec_result r;
    pd_err e;
    (void)err;
    if (status) /* the failure worded as a task's (the same run fails the same way) */
        pd_spec_run_task(ts->s, id, &r, &e);
    else {
        memset(&r, 0, sizeof r);
        pd_err_clear(&e);
        result_of(res, &r);
    }
    ts->done(ts->ctx, id, &r, &e);
}

int pd_spec_stream(const pd_spectrum *s, pd_spec_task_next next, pd_spec_task_done done, void *ctx,
                   pd_err *err)
{
    if (!s || !next || !done)
        return PD_NULL_ARG(err, !s ? "s" : !next ? "next" : "done");
    task_stream ts = {.s = s, .next = next, .done = done, .ctx = ctx};
    return pd_osc_run_stream(stream_next, stream_done, &ts, err);
}

/* ---- the canonical key -------------------------------------------------- */

/* A growing text buffer. */
typedef struct textbuf {
    char *p;
    size_t n, cap;
    int oom;
} textbuf;

/* Append printf-style text. */
static void tb_add(textbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void tb_add(textbuf *b, const char *fmt, ...)
{
    va_list ap;
    if (b->oom)
        return;
    for (;;) {
        va_start(ap, fmt);
        int len = vsnprintf(b->p + b->n, b->cap - b->n, fmt, ap);
        va_end(ap);
        if (len < 0) {
            b->oom = 1;
            return;
        }
        if ((size_t)len < b->cap - b->n) {
            b->n += (size_t)len;
            return;
        }
        size_t cap = 2 * b->cap + (size_t)len + 64;
        char *q = realloc(b->p, cap);
        if (!q) {
            b->oom = 1;
            return;
        }
        b->p = q;
        b->cap = cap;
    }
}

/* " name=x1,x2,..." with every value in hexadecimal floating point. */
static void tb_list(textbuf *b, const char *name, const double *x, int n)
{
    tb_add(b, " %s=", name);
    for (int i = 0; i < n; i++)
        tb_add(b, "%s%a", i ? "," : "", x[i]);
}

/* A checksum of a record's samples (a sum weighted by position). */
static double record_checksum(const pd_record *r)
{
    double sum = 0.0;
    for (long k = 0; k < r->npts; k++)
        sum += r->acc[k] * (double)((k % 1000) + 1);
    return sum;
}

char *pd_spec_key(const pd_spectrum *s)
{
    if (!s)
        return NULL;
    const pd_run_opts *o = &s->opts;
    textbuf b = {malloc(256), 0, 256, 0};
    if (!b.p)
        return NULL;
    b.p[0] = '\0';
    tb_add(&b, "v=1 method=%s pulse=", pd_method_name(o->method));
    for (int i = 0; i < s->npulse; i++)
        tb_add(&b, "%s%s", i ? "," : "",
               s->base.record ? s->base.record->name : pd_pulse_name(s->pulse[i]));
    tb_add(&b, " dir=");
    for (int i = 0; i < s->ndir; i++)
        tb_add(&b, "%s%s", i ? "," : "", pd_dir_name(s->dir[i]));
    tb_list(&b, "ap", s->ap, s->nap);
    tb_add(&b, " Tp=%a", s->base.Tp);
    if (s->base.record) /* a record's sweep: its samples matter, summed into the key */
        tb_add(&b, " record=%s npts=%ld rdt=%a rec_ap=%a sum=%a", s->base.record->name,
               s->base.record->npts, s->base.record->dt, s->base.rec_ap,
               record_checksum(s->base.record));
    tb_list(&b, "xi", s->xi, s->nxi);
    if (pd_osc_yields(&s->base)) /* a yielding sweep's spring (elastic keys unchanged) */
        tb_add(&b, " Piy=%a alpha=%a", s->base.Piy, s->base.alpha);
    tb_list(&b, s->size_is_gap ? "gap" : "Pi3", s->size, s->nsize);
    tb_list(&b, "eps", s->eps, s->neps);
    tb_add(&b, " Pi2=%a:%a:%d spacing=%s", s->pi2_min, s->pi2_max, s->npi2,
           s->linear ? "linear" : "log");
    tb_add(&b, " dt=%a dt_per_Tp=%a theta=%a gamma=%a tend=%a", o->dt, s->dt_per_Tp, o->theta,
           o->gamma, o->tend);
    tb_add(&b, " unstable=%d accumulation=%d kernel=%d factor=%d lcp=%d", o->allow_unstable,
           !o->no_accumulation, (int)o->kernel, (int)o->factor, (int)o->lcp_solver);
    tb_add(&b, " contact=%d kc=%a kc_abs=%a rtol=%a atol=%a stepper=%s", (int)o->pen.law,
           o->pen.kc_mult, o->pen.kc_abs, o->pen.rtol, o->pen.atol,
           o->pen.stepper ? o->pen.stepper : "(none)");
    tb_add(&b, " tasks=%ld", pd_spec_tasks(s));
    if (b.oom) {
        free(b.p);
        return NULL;
    }
    return b.p;
}

/* ---- rows --------------------------------------------------------------- */

/* One point from its run and its twin, as `pound simulate` computes them. */
static void fill_row(const pd_osc *c, const pd_run_opts *o, long curve, const pd_spec_result *r,
                     const pd_spec_result *f, pd_spec_row *row)
{
    memset(row, 0, sizeof *row);
    row->c = *c;
    row->curve = curve;
    row->T0 = pd_osc_T0(c);
    row->gap = pd_osc_gap(c);
    row->dt = o->dt;
    row->tend = o->tend;
    row->umax = r->umax;
    row->Pi1 = r->umax / pd_osc_Le(c);
    row->umax_free = f->umax;
    row->gamma = f->umax > 0.0 ? r->umax / f->umax : NAN;
    row->chi = f->umax > 0.0 ? pd_osc_gap(c) / f->umax : NAN;
    row->u_toward = r->u_toward;
    row->u_away = r->u_away;
    row->contact_time = r->contact_time;
    row->first_impact = r->first_impact;
    row->cpu_s = r->cpu_s;
    row->impacts = r->impacts;
    row->steps = r->steps;
    row->ductility = r->ductility;
    row->ductility_free = f->ductility;
    row->residual_uy = r->residual / pd_osc_uy(c);
}

void pd_spec_rows(const pd_spectrum *s, const pd_spec_result *res, pd_spec_row *rows)
{
    if (!s || !res || !rows || check_lists(s, NULL))
        return;
    long ntw = pd_spec_twins(s), np = pd_spec_points(s);
    pd_osc c;
    pd_run_opts o;
    for (long p = 0; p < np; p++) {
        long t = ntw + p;
        pd_spec_case(s, t, &c, &o, NULL);
        fill_row(&c, &o, p / s->npi2, &res[t], &res[pd_spec_twin_of(s, t)], &rows[p]);
    }
}

void pd_spec_curve_label(const pd_spectrum *s, long curve, char *buf, size_t cap)
{
    pd_spec_coords co;
    size_t n = 0;
    if (!s || !buf || cap == 0)
        return;
    buf[0] = '\0';
    if (check_lists(s, NULL) || curve < 0 || curve >= pd_spec_curves(s))
        return; /* no such curve: an empty label */
    pd_spec_coords_of(s, pd_spec_twins(s) + curve * s->npi2, &co);
#define ADD(...) (n += (size_t)snprintf(buf + n, n < cap ? cap - n : 0, __VA_ARGS__))
    if (s->npulse > 1)
        ADD("%s ", pd_pulse_name(s->pulse[co.pulse]));
    if (s->ndir > 1)
        ADD("%s ", pd_dir_name(s->dir[co.dir]));
    if (s->nap > 1 || s->dimensional)
        ADD("ap=%g ", s->ap[co.ap]);
    if (s->nxi > 1)
        ADD("xi=%g ", s->xi[co.xi]);
    if (s->nsize > 1 || n == 0)
        ADD("%s=%g ", s->size_is_gap ? "gap" : "Pi3", s->size[co.size]);
    if (s->neps > 1)
        ADD("eps=%g ", s->eps[co.eps]);
#undef ADD
    if (n > 0 && n <= cap)
        buf[n - 1] = '\0';
}

/* ---- a serial sweep with a callback per point -------------------------- */

/* The lists and the grid within their arrays' bounds: PD_OK or PD_EINVAL. */
static int check_lists(const pd_spectrum *s, pd_err *err)
{
    const struct {
        const char *name;
        int n, max;
    } lists[] = {{"pulse", s->npulse, 3},
                 {"dir", s->ndir, 2},
                 {"ap", s->nap, PD_SPEC_MAX_LIST},
                 {"xi", s->nxi, PD_SPEC_MAX_LIST},
                 {s->size_is_gap ? "gap" : "Pi3", s->nsize, PD_SPEC_MAX_LIST},
                 {"eps", s->neps, PD_SPEC_MAX_LIST},
                 {"Pi2", s->npi2, 1 << 24}};
    for (size_t k = 0; k < sizeof lists / sizeof lists[0]; k++)
        if (lists[k].n < 1 || lists[k].n > lists[k].max)
            return pd_err_set(err, PD_EINVAL, "%s: %d values (1 to %d)", lists[k].name, lists[k].n,
                              lists[k].max);
    return PD_OK;
}

/* The lists and the grid, and at most PD_SPEC_MAX_TASKS tasks. */
static int check_shape(const pd_spectrum *s, pd_err *err)
{
    int rc = check_lists(s, err);
    if (rc)
        return rc;
    if (pd_spec_tasks(s) > PD_SPEC_MAX_TASKS)
        return pd_err_set(err, PD_EINVAL, "sweep: %ld runs (at most %ld)", pd_spec_tasks(s),
                          PD_SPEC_MAX_TASKS);
    return PD_OK;
}

/* The sweep's stream state: results arrive in any order (a batch ends its
 * runs as they end), points go to the caller in task order. */
typedef struct sweep_ctx {
    const pd_spectrum *s;
    pd_spec_point_fn fn;
    void *ctx;
    pd_spec_result *res;                      /* every task's, as it ends */
    long first_bad;                           /* the lowest failed task so far (-1: none) */
    char bad_msg[sizeof(((pd_err *)0)->msg)]; /* its message */
    long ntasks, ntw, next, emitted;
    int rc;
    pd_err *err;
} sweep_ctx;

static long sweep_next(void *ctx)
{
    sweep_ctx *w = ctx;
    return !w->rc && w->next < w->ntasks ? w->next++ : -1;
}

/* Emit the points whose task and twin have ended, in order; stop at the
 * first failure or when the caller asks. */
static void sweep_emit(sweep_ctx *w)
{
    pd_osc c;
    pd_run_opts o;
    pd_spec_coords co;
    pd_spec_row row;
    while (!w->rc && w->emitted < w->ntasks && w->res[w->emitted].done) {
        long t = w->emitted;
        const pd_spec_result *r = &w->res[t];
        if (r->status) { /* the lowest failure: every task before it ended */
            w->rc = pd_err_set(w->err, r->status, "%s", w->bad_msg);
            return;
        }
        w->emitted++;
        if (t < w->ntw)
            continue;
        pd_spec_case(w->s, t, &c, &o, NULL);
        pd_spec_coords_of(w->s, t, &co);
        fill_row(&c, &o, co.curve, r, &w->res[pd_spec_twin_of(w->s, t)], &row);
        if (w->fn && w->fn(&co, &row, w->ctx))
            w->rc = pd_err_set(w->err, PD_ESTOPPED,
                               "spectrum: stopped by the caller after point %ld", t - w->ntw);
    }
}

static void sweep_done(void *ctx, long t, const pd_spec_result *r, const pd_err *e)
{
    sweep_ctx *w = ctx;
    w->res[t] = *r;
    w->res[t].done = 1;
    if (r->status && (w->first_bad < 0 || t < w->first_bad)) {
        w->first_bad = t;
        snprintf(w->bad_msg, sizeof w->bad_msg, "%s", e->msg);
    }
    sweep_emit(w);
}

int pd_spec_sweep(const pd_spectrum *s, pd_spec_point_fn fn, void *ctx, pd_err *err)
{
    if (!s)
        return PD_NULL_ARG(err, "s");
    long n = pd_spec_tasks(s);
    int rc = check_shape(s, err); /* then every point checked before any run */
    if (rc || (rc = pd_spec_validate(s, err)))
        return rc;
    pd_spectrum one = *s; /* one method for every run */
    pd_spec_resolve_method(&one);
    sweep_ctx w = {.s = &one,
                   .fn = fn,
                   .ctx = ctx,
                   .ntasks = n,
                   .ntw = pd_spec_twins(s),
                   .first_bad = -1,
                   .err = err};
    w.res = calloc((size_t)n, sizeof *w.res);
    if (!w.res)
        return pd_err_set(err, PD_ENOMEM, "out of memory for %ld runs", n);
    pd_spec_stream(&one, sweep_next, sweep_done, &w, NULL);
    free(w.res);
    if (!w.rc)
        pd_err_clear(err);
    return w.rc;
}
