/* event_sdof.c — event-driven reference for one oscillator and one wall.
 *
 * Modes: FREE (closed-form flight until the gap closes or the forcing piece
 * ends) and CONTACT (x = delta, v = 0 while lambda = F - w0^2 delta >= 0).
 * Events: impact (Newton), detachment (lambda crosses zero downwards),
 * piece boundary (the forcing changes), accumulation (a geometric tail of
 * impacts replaced by its limit). */
#include <math.h>
#include <string.h>

#include "pd_core.h"
#include "pd_engine.h"


typedef struct ed_run {
    const pd_ed_sdof *p;
    const pd_ed_opts *o;
    pd_ed_result *r;
    pd_ed_sampler sampler;
    void *ctx;
    double scan;      /* bracketing grid step */
    long next_out;    /* index k of the next output time t_start + k h_out */
    long burst;       /* impacts since the oscillator last rested or left */
    long max_events, max_burst;
    double t_first;
    int stopped;      /* the sampler asked to stop */
} ed_run;

/* Forcing piece j: A sin(w t + phi). */
static double piece_force(const pd_sine_piece *pc, double t)
{
    return pc->A == 0.0 ? 0.0 : pc->A * sin(pc->w * t + pc->phi);
}

/* End of piece j (the next start, or +inf). */
static double piece_end(const pd_ed_sdof *p, int j)
{
    return j + 1 < p->npieces ? p->pieces[j + 1].t_start : HUGE_VAL;
}

/* Exact displacement increment dx = x(t) - xa and velocity at t from
 * (ta, xa, va) under piece j. */
static void flow_inc(const ed_run *ed, int j, double ta, double xa, double va, double t,
                     double *dx, double *v)
{
    const pd_sine_piece *pc = &ed->p->pieces[j];
    if (t == ta) {
        *dx = 0.0;
        *v = va;
        return;
    }
    pd_sdof_increment(&ed->p->osc, pc->A, pc->w, pc->phi, ta, xa, va, t, dx, v);
}

/* Exact state at t from (ta, xa, va) under piece j. */
static void flow(const ed_run *ed, int j, double ta, double xa, double va, double t, double *x,
                 double *v)
{
    double dx;
    flow_inc(ed, j, ta, xa, va, t, &dx, v);
    *x = xa + dx;
}

/* Signed distance past the wall, x(t) - delta, without cancellation. */
static double past_wall(const ed_run *ed, int j, double ta, double xa, double va, double t)
{
    double dx, v;
    flow_inc(ed, j, ta, xa, va, t, &dx, &v);
    return (xa - ed->p->delta) + dx;
}

/* Extremes over the measuring window. */
static void note(ed_run *ed, double t, double x)
{
    if (t < ed->o->t_measure)
        return;
    ed->r->xmax = fmax(ed->r->xmax, fabs(x));
    ed->r->xtoward = fmax(ed->r->xtoward, x);
    ed->r->xaway = fmax(ed->r->xaway, -x);
}

/* Output times in (.., tb] of a free piece (or resting when in_contact). */
static void emit(ed_run *ed, int j, double ta, double xa, double va, double tb, int in_contact)
{
    if (!ed->sampler || ed->o->h_out <= 0.0 || ed->stopped)
        return;
    for (;;) {
        double t = ed->t_first + (double)ed->next_out * ed->o->h_out;
        if (t > tb || t > ed->o->t_end * (1 + 1e-15))
            return;
        double x = xa, v = 0.0;
        if (!in_contact)
            flow(ed, j, ta, xa, va, t, &x, &v);
        ed->next_out++;
        if (ed->sampler(t, x, v, in_contact, ed->ctx) > 0) {
            ed->stopped = 1;
            return;
        }
    }
}

/* Bisection on the sign of f between lo (f <= 0) and hi (f > 0), to
 * adjacent doubles; returns hi.  kind 0: f = x - delta (gap closing),
 * 1: f = -v (a maximum), 2: f = -lambda (detachment), 3: f = v (a minimum). */
static double bisect(const ed_run *ed, int j, double ta, double xa, double va, int kind, double lo,
                     double hi)
{
    const pd_sdof *osc = &ed->p->osc;
    for (int it = 0; it < 200 && hi - lo > 2e-16 * fmax(fabs(hi), 1e-300); it++) {
        double mid = 0.5 * (lo + hi), x, v, f;
        if (mid <= lo || mid >= hi)
            break;
        if (kind == 2)
            f = -(piece_force(&ed->p->pieces[j], mid) - osc->w0 * osc->w0 * ed->p->delta);
        else if (kind == 0)
            f = past_wall(ed, j, ta, xa, va, mid);
        else {
            flow(ed, j, ta, xa, va, mid, &x, &v);
            f = kind == 1 ? -v : v;
        }
        if (f > 0.0)
            hi = mid;
        else
            lo = mid;
    }
    return hi;
}

/* Free flight from (ta, xa, va) under piece j up to tb.  Returns 1 with
 * *t_hit when the gap closes first (exactly x = delta), else 0 with the
 * state at tb.  Every velocity zero inside is an extremum (noted); a
 * maximum beyond the wall means the gap closed before it (grazing). */
static int free_flight(ed_run *ed, int j, double ta, double xa, double va, double tb,
                       double *t_hit, double *x_end, double *v_end)
{
    double a = ta, x_a = xa, v_a = va;
    const double delta = ed->p->delta;
    while (a < tb) {
        double b = fmin(a + ed->scan, tb), xb, vb, hit = -1.0;
        flow(ed, j, ta, xa, va, b, &xb, &vb);
        if (v_a != 0.0 && (v_a > 0.0) != (vb > 0.0)) { /* extremum inside (a, b] */
            double tc = bisect(ed, j, ta, xa, va, v_a > 0.0 ? 1 : 3, a, b), xc, vc;
            flow(ed, j, ta, xa, va, tc, &xc, &vc);
            if (ed->p->wall && v_a > 0.0 && past_wall(ed, j, ta, xa, va, tc) > 0.0)
                hit = bisect(ed, j, ta, xa, va, 0, a, tc);
            else
                note(ed, tc, xc);
        }
        if (hit < 0.0 && ed->p->wall && past_wall(ed, j, ta, xa, va, b) > 0.0)
            hit = bisect(ed, j, ta, xa, va, 0, a, b);
        if (hit >= 0.0) {
            emit(ed, j, ta, xa, va, hit, 0);
            *t_hit = hit;
            flow(ed, j, ta, xa, va, hit, x_end, v_end);
            *x_end = delta;
            note(ed, hit, delta);
            return 1;
        }
        note(ed, b, xb);
        emit(ed, j, ta, xa, va, b, 0);
        a = b;
        x_a = xb;
        v_a = vb;
    }
    *x_end = x_a;
    *v_end = v_a;
    return 0;
}

/* Resting on the wall from ta under piece j: the time lambda turns negative
 * (detachment), or tb if it stays >= 0. */
static double rest(ed_run *ed, int j, double ta, double tb)
{
    const pd_sdof *osc = &ed->p->osc;
    double k_delta = osc->w0 * osc->w0 * ed->p->delta, a = ta, td = tb;
    while (a < tb) {
        double b = fmin(a + ed->scan, tb);
        if (piece_force(&ed->p->pieces[j], b) - k_delta < 0.0) {
            td = bisect(ed, j, ta, 0, 0, 2, a, b);
            break;
        }
        a = b;
    }
    note(ed, ta, ed->p->delta);
    emit(ed, j, ta, ed->p->delta, 0.0, td, 1);
    ed->r->contact_time += td - ta;
    return td;
}

/* Free acceleration toward the wall at x = delta with velocity v. */
static double wall_accel(const ed_run *ed, int j, double t, double v)
{
    const pd_sdof *osc = &ed->p->osc;
    return piece_force(&ed->p->pieces[j], t) - 2.0 * osc->xi * osc->w0 * v -
           osc->w0 * osc->w0 * ed->p->delta;
}

/* Scan step: the shortest period present over divisions (default 64),
 * independent of the run's length so that results do not move with t_end;
 * span/4 over divisions only when no period exists (free mass, constant force). */
static double scan_step(const pd_ed_sdof *p, double span, int divisions)
{
    double T = HUGE_VAL;
    if (p->osc.w0 > 0.0)
        T = PD_TWO_PI / p->osc.w0;
    for (int j = 0; j < p->npieces; j++)
        if (p->pieces[j].A != 0.0 && p->pieces[j].w > 0.0)
            T = fmin(T, PD_TWO_PI / p->pieces[j].w);
    if (!isfinite(T))
        T = span / 4.0;
    return T / divisions;
}

/* Count an event; PD_EBUDGET past the budget. */
static int count_event(ed_run *ed, double t, pd_err *err)
{
    if (++ed->r->events > ed->max_events)
        return pd_err_set(err, PD_EBUDGET,
                          "event-driven: %ld events by t = %.9g (budget exhausted)",
                          ed->r->events - 1, t);
    return PD_OK;
}

static int check_problem(const pd_ed_sdof *p, const pd_ed_opts *o, pd_err *err)
{
    if (!p || p->npieces < 1 || !p->pieces)
        return pd_err_set(err, PD_EINVAL, "event-driven: no forcing pieces");
    if (!(p->osc.w0 >= 0.0) || !(p->osc.xi >= 0.0 && p->osc.xi < 1.0))
        return pd_err_set(err, PD_EINVAL, "event-driven: need w0 >= 0 and xi in [0, 1)");
    if (p->wall && (!(p->delta >= 0.0) || !(p->e >= 0.0 && p->e <= 1.0)))
        return pd_err_set(err, PD_EINVAL, "event-driven: need gap >= 0 and e in [0, 1]");
    if (!(o->t_end > p->pieces[0].t_start) || !isfinite(o->t_end))
        return pd_err_set(err, PD_EINVAL, "event-driven: t_end must follow the start time");
    if (o->max_events < 1 || o->max_burst < 1 || o->scan_divisions < 1 ||
        !(o->length_scale > 0.0) || !isfinite(o->length_scale))
        return pd_err_set(err, PD_EINVAL,
                          "event-driven: budgets and scan divisions must be >= 1 and the length "
                          "scale > 0");
    return PD_OK;
}

pd_ed_opts pd_ed_default_opts(void)
{
    return (pd_ed_opts){.t_end = 0.0,
                        .t_measure = 0.0,
                        .h_out = 0.0,
                        .no_accumulation = 0,
                        .max_events = 10000000L,
                        .max_burst = 100000L,
                        .length_scale = 1.0,
                        .scan_divisions = 64};
}

/* After an impact at t with post-impact speed vp (<= 0): 1 when the
 * oscillator should rest (lambda > 0 and either vp = 0 or an accumulation
 * is jumped to *t_rest), 0 to fly on. */
static int settle(ed_run *ed, int j, double t, double vp, double tb, double *t_rest)
{
    double a = wall_accel(ed, j, t, vp), e = ed->p->e;
    *t_rest = t;
    if (vp == 0.0)
        return a > 0.0;
    if (ed->o->no_accumulation || e >= 1.0 || !(a > 0.0))
        return 0;
    double height = vp * vp / (2.0 * a), scale = ed->o->length_scale;
    double tail = 2.0 * fabs(vp) / (a * (1.0 - e));
    if (height > 1e-10 * scale || t + tail >= tb || !(wall_accel(ed, j, t + tail, 0.0) > 0.0) ||
        !(wall_accel(ed, j, t + 0.5 * tail, 0.0) > 0.0))
        return 0;
    *t_rest = t + tail; /* bouncing-ball limit: sum of the geometric flight times */
    ed->r->accumulations++;
    return 1;
}

int pd_ed_sdof_run(const pd_ed_sdof *prob, double x0, double v0, const pd_ed_opts *opts,
                   pd_ed_sampler sampler, void *ctx, pd_ed_result *res, pd_err *err)
{
    ed_run ed;
    int rc, j = 0, resting = 0;
    pd_err_clear(err);
    memset(res, 0, sizeof *res);
    res->first_impact = res->first_impact_velocity = NAN;
    res->max_impact_velocity = 0.0;
    if ((rc = check_problem(prob, opts, err)))
        return rc;
    double t = prob->pieces[0].t_start, x = x0, v = v0;
    ed = (ed_run){.p = prob,
                  .o = opts,
                  .r = res,
                  .sampler = sampler,
                  .ctx = ctx,
                  .scan = scan_step(prob, opts->t_end - t, opts->scan_divisions),
                  .max_events = opts->max_events,
                  .max_burst = opts->max_burst,
                  .t_first = t};
    note(&ed, t, x);
    if (prob->wall && x >= prob->delta && v >= 0.0) { /* starting on the wall */
        x = prob->delta;
        resting = v == 0.0 && wall_accel(&ed, j, t, 0.0) > 0.0;
    }
    while (t < opts->t_end && !ed.stopped) {
        double tb = fmin(piece_end(prob, j), opts->t_end), t_hit, xn, vn, t_rest;
        if ((rc = count_event(&ed, t, err)))
            break;
        if (resting) {
            double td = rest(&ed, j, t, tb);
            if (td < tb) { /* detachment */
                resting = 0;
                res->detachments++;
                ed.burst = 0;
            }
            t = td;
            x = prob->delta;
            v = 0.0;
        } else if (free_flight(&ed, j, t, x, v, tb, &t_hit, &xn, &vn)) {
            /* impact: Newton's law, then rest, jump an accumulation, or fly */
            res->impacts++;
            if (isnan(res->first_impact)) {
                res->first_impact = t_hit;
                res->first_impact_velocity = vn;
            }
            res->max_impact_velocity = fmax(res->max_impact_velocity, vn);
            if (++ed.burst > ed.max_burst) {
                rc = pd_err_set(err, PD_EBUDGET,
                                "event-driven: accumulation of impacts at t = %.9g: %ld impacts "
                                "without reaching persistent contact%s",
                                t_hit, ed.burst - 1,
                                opts->no_accumulation ? " (accumulation handling is off)" : "");
                t = t_hit;
                break;
            }
            t = t_hit;
            x = prob->delta;
            v = -prob->e * vn;
            if (settle(&ed, j, t, v, tb, &t_rest)) {
                emit(&ed, j, t, x, 0.0, t_rest, 1);
                t = t_rest;
                v = 0.0;
                resting = 1;
                ed.burst = 0;
            }
            continue;
        } else {
            t = tb;
            x = xn;
            v = vn;
        }
        if (t >= piece_end(prob, j) && j + 1 < prob->npieces) {
            j++; /* forcing breakpoint: re-decide rest or flight */
            if (resting && !(wall_accel(&ed, j, t, 0.0) > 0.0)) {
                resting = 0;
                res->detachments++;
            }
        }
    }
    res->t_reached = t;
    return rc;
}
