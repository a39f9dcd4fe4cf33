/* event_sdof.c — event-driven reference for one oscillator and one wall.
 *
 * Modes: FREE (closed-form flight until the gap closes or the forcing piece
 * ends) and CONTACT (x = delta, v = 0 while lambda = F - w0^2 delta >= 0).
 * Events: impact (Newton), detachment (lambda crosses zero downwards),
 * piece boundary (the forcing changes), accumulation (a geometric tail of
 * impacts replaced by its limit).
 *
 * Flight is scanned on intervals of at most the scan step (the shortest
 * period of the piece over 64), never across a piece boundary (a piece
 * shorter than the step is one interval).  On each
 * interval the velocity is, up to O((w0 h)^2) relative, a quadratic: it has
 * no zero, one (the ends differ in sign: one extremum, bisected), or two
 * (the ends agree, the acceleration changes sign between them and the ends
 * are within reach of zero: the acceleration's zero splits the interval).
 * The gap's interior minima are thus all located; a maximum beyond the wall
 * means the gap closed before it (grazing).
 *
 * A yielding spring (uy > 0, alpha < 1) adds two phases of the same linear
 * form: elastic (stiffness w0^2, the offset's force (1 - alpha) w0^2 up a
 * constant of the piece) and sliding toward sigma (stiffness alpha w0^2,
 * the constant -sigma (1 - alpha) w0^2 uy).  Between the located turns x is
 * monotone, so a level (the wall, or up + sigma uy: a yield onset) is
 * crossed inside a segment exactly when its end is beyond it; a slide ends
 * at its turn (unloading, the velocity's zero to adjacent doubles), where
 * up = x - sigma uy; an impact while sliding unloads it too. */
#include <math.h>
#include <string.h>

#include "pd_root.h"
#include "pd_core.h"
#include "pd_engine.h"
#include "pd_null.h"

/* The velocity may turn twice inside a scan interval only when it is
 * within this many |acceleration| * h of zero at an end (2: twice what a
 * monotone acceleration needs). */
#define TURN_MARGIN 2.0
/* Extrema and the split of a double turn are bisected to this fraction of
 * the scan step only: x is flat there, x(tc) is off by acc w^2 / 2, about
 * 1e-17 of the amplitude for w = 4e-8 T / 64 (w0 w ~ 4e-9). */
#define EXTREMUM_WIDTH 4e-8
/* A closed-form root is polished inside this many relative ulps. */
#define ROOT_POLISH_ULPS 16.0
/* Output times past t_end by this relative amount are still emitted. */
#define OUT_END_REL 1e-15
/* Scan intervals per flight at most (a bound on absurd spans only). */
#define SCAN_MAX_INTERVALS 1e15
/* Accumulation: bounce heights below this times length_scale are jumped. */
#define ACC_HEIGHT 1e-10

typedef struct ed_run {
    const pd_ed_sdof *p;
    const pd_ed_opts *o;
    pd_ed_result *r;
    pd_ed_sampler sampler;
    void *ctx;
    double scan;   /* bracketing grid step */
    long next_out; /* index k of the next output time t_start + k h_out */
    long burst;    /* impacts since the oscillator last rested or left */
    long max_events, max_burst;
    double t_first;
    int stopped; /* the sampler asked to stop */
    /* a yielding spring (yielding 0: elastic, every field below unused) */
    int yielding;
    int phase;         /* 0 elastic, +-1 sliding toward that side */
    double uy;         /* the yield displacement */
    double kbar;       /* (1 - alpha) w0^2 */
    double up;         /* the plastic offset (while sliding: at the slide's start) */
    double shift;      /* the phase's constant force: kbar up, or -phase kbar uy */
    pd_sdof osc;       /* the phase's oscillator (the problem's when elastic) */
    pd_sdof osc_slide; /* stiffness alpha w0^2, the same damping */
    double cdamp;      /* 2 xi w0: the damping of every phase */
    int slide_mass;    /* alpha = 0 with damping: the slide is a damped free mass */
} ed_run;

/* A flight's origin: the piece j and the state there. */
typedef struct ed_origin {
    int j;
    double t, x, v;
    pd_sdof_flow flow; /* of a flight (pd_sdof_flow_init, or _init_mass for an
                          elastic-perfectly-plastic spring's damped slide); unused at rest */
} ed_origin;

/* A point of a flight: x, v, the distance past the wall x - delta (without
 * cancellation) and the free acceleration. */
typedef struct ed_point {
    double t, x, v, past, acc;
} ed_point;

/* What a bisection brackets the sign change of. */
typedef enum {
    ED_YIELD_HI,   /* x - up - uy: a slide toward +1 begins */
    ED_YIELD_LO,   /* up - uy - x: a slide toward -1 begins */
    ED_GAP,        /* x - delta: gap closing */
    ED_NEG_V,      /* -v: a maximum */
    ED_NEG_LAMBDA, /* -lambda: detachment */
    ED_V,          /* v: a minimum */
    ED_ACC,        /* acceleration: v's minimum */
    ED_NEG_ACC     /* -acceleration: v's maximum */
} ed_kind;

/* F(t) of piece j (and the phase's constant force of a yielding spring). */
static double piece_force(const ed_run *ed, int j, double t)
{
    double F = pd_sine_piece_force(&ed->p->pieces[j], t);
    return ed->shift != 0.0 ? F + ed->shift : F;
}

/* lambda = F - w0^2 delta: the wall's force on the resting oscillator. */
static double lambda_at(const ed_run *ed, int j, double t)
{
    const pd_sdof *osc = &ed->p->osc;
    return piece_force(ed, j, t) - osc->w0 * osc->w0 * ed->p->delta;
}

/* x'' = F - 2 xi w0 v - w0^2 x (free flight, the phase's w0 and xi). */
static double free_accel(const ed_run *ed, int j, double t, double x, double v)
{
    const pd_sdof *osc = &ed->osc;
    return piece_force(ed, j, t) - ed->cdamp * v - osc->w0 * osc->w0 * x;
}

/* Free acceleration toward the wall at x = delta with velocity v. */
static double wall_accel(const ed_run *ed, int j, double t, double v)
{
    return free_accel(ed, j, t, ed->p->delta, v);
}

/* End of piece j (the next start, or +inf). */
static double piece_end(const pd_ed_sdof *p, int j)
{
    return j + 1 < p->npieces ? p->pieces[j + 1].t_start : HUGE_VAL;
}

/* Exact increment dx = x(t) - x_o and velocity at t from the origin. */
static void flow_inc(const ed_origin *o, double t, double *dx, double *v)
{
    if (t == o->t) {
        *dx = 0.0;
        *v = o->v;
        return;
    }
    pd_sdof_flow_at(&o->flow, t, dx, v);
}

/* The flight's point at t: past = (x_o - delta) + dx, and x clipped to the
 * wall when only rounding puts it beyond (past <= 0). */
static ed_point probe(const ed_run *ed, const ed_origin *o, double t)
{
    double dx, v;
    flow_inc(o, t, &dx, &v);
    ed_point q = {.t = t, .x = o->x + dx, .v = v, .past = (o->x - ed->p->delta) + dx};
    /* not past the wall, but x = x_o + dx rounded beyond it: x clipped */
    if (ed->p->wall && q.past <= 0.0 && q.x > ed->p->delta)
        q.x = ed->p->delta;
    return q;
}

/* probe plus the free acceleration (the scan grid's points). */
static ed_point probe_acc(const ed_run *ed, const ed_origin *o, double t)
{
    ed_point q = probe(ed, o, t);
    q.acc = free_accel(ed, o->j, t, q.x, q.v);
    return q;
}

/* Extremes over the measuring window. */
static void note(ed_run *ed, double t, double x)
{
    if (t < ed->o->t_measure)
        return;
    ed->r->xmax = fmax(ed->r->xmax, fabs(x));
    ed->r->xtoward = fmax(ed->r->xtoward, x); /* toward the wall */
    ed->r->xaway = fmax(ed->r->xaway, -x);    /* away from it */
}

/* Output times in (.., tb] of a flight (or resting at x_o when in_contact). */
static void emit(ed_run *ed, const ed_origin *o, double tb, int in_contact)
{
    if (!ed->sampler || ed->o->h_out <= 0.0 || ed->stopped)
        return;
    for (;;) {
        /* t_k = t_first + k h_out up to tb, and to t_end within a relative 1e-15 */
        double t = ed->t_first + (double)ed->next_out * ed->o->h_out;
        if (t > tb || t > ed->o->t_end * (1 + OUT_END_REL))
            return;
        double x = o->x, v = 0.0; /* at rest: held at the wall */
        if (!in_contact) {
            ed_point q = probe(ed, o, t);
            x = q.x;
            v = q.v;
        }
        ed->next_out++;
        if (ed->yielding) /* the offset at t for the sampler (res->up) */
            ed->r->up = ed->phase ? x - ed->phase * ed->uy : ed->up;
        if (ed->sampler(t, x, v, in_contact, ed->ctx) > 0) {
            ed->stopped = 1;
            return;
        }
    }
}

/* The bracketed function of kind at t. */
static double bracket_value(const ed_run *ed, const ed_origin *o, ed_kind kind, double t)
{
    if (kind == ED_NEG_LAMBDA)
        return -lambda_at(ed, o->j, t);
    if (kind == ED_YIELD_HI || kind == ED_YIELD_LO) {
        double x = probe(ed, o, t).x;
        return kind == ED_YIELD_HI ? x - ed->up - ed->uy : ed->up - ed->uy - x;
    }
    if (kind == ED_ACC || kind == ED_NEG_ACC) {
        ed_point q = probe_acc(ed, o, t);
        return kind == ED_ACC ? q.acc : -q.acc;
    }
    ed_point q = probe(ed, o, t);
    /* x - delta, -v or v */
    return kind == ED_GAP ? q.past : kind == ED_NEG_V ? -q.v : q.v;
}

/* The bracketed function of kind, as core/root.c's function (the slope
 * for the gap and the velocity only: value_slope). */
typedef struct bracket_fn {
    const ed_run *ed;
    const ed_origin *o;
    ed_kind kind;
} bracket_fn;

/* f of kind at t and its derivative in closed form: the gap's is v, the
 * velocity's the acceleration (kinds ED_GAP, ED_NEG_V, ED_V only). */
static double value_slope(const ed_run *ed, const ed_origin *o, ed_kind kind, double t, double *df)
{
    ed_point q = probe_acc(ed, o, t);
    double s = kind == ED_NEG_V ? -1.0 : 1.0;
    if (kind == ED_YIELD_HI || kind == ED_YIELD_LO) { /* d(+-(x - up)) / dt = +-v */
        *df = kind == ED_YIELD_HI ? q.v : -q.v;
        return kind == ED_YIELD_HI ? q.x - ed->up - ed->uy : ed->up - ed->uy - q.x;
    }
    if (kind == ED_GAP) {
        *df = q.v; /* d(x - delta) / dt = v */
        return q.past;
    }
    *df = s * q.acc; /* dv / dt = acc */
    return s * q.v;
}

static double bracket_eval(void *ctx, double t, double *slope)
{
    const bracket_fn *c = ctx;
    return slope ? value_slope(c->ed, c->o, c->kind, t, slope)
                 : bracket_value(c->ed, c->o, c->kind, t);
}

/* Bisection on the sign of f between lo (f <= 0) and hi (f > 0), to
 * adjacent doubles (or to the width w > 0); returns hi (core/root.c). */
static double bisect_to(const ed_run *ed, const ed_origin *o, ed_kind kind, double lo, double hi,
                        double w)
{
    bracket_fn c = {.ed = ed, .o = o, .kind = kind};
    pd_root r = {.f = bracket_eval, .ctx = &c};
    return pd_root_bisect(&r, lo, hi, w);
}

/* The sign change of f between lo (f <= 0) and hi (f > 0) to the width w
 * (0: adjacent doubles) by safeguarded Newton on the closed-form slope from
 * the middle (core/root.c): the same hi as bisect_to, in about a fifth of
 * the evaluations. */
static double newton_to(const ed_run *ed, const ed_origin *o, ed_kind kind, double lo, double hi,
                        double w)
{
    bracket_fn c = {.ed = ed, .o = o, .kind = kind};
    pd_root r = {.f = bracket_eval, .ctx = &c};
    return pd_root_newton(&r, lo, hi, w, NAN);
}

/* Event times (gap closing, yield onsets, detachment): to adjacent doubles. */
static double bisect(const ed_run *ed, const ed_origin *o, ed_kind kind, double lo, double hi)
{
    if (kind != ED_NEG_LAMBDA)
        return newton_to(ed, o, kind, lo, hi, 0.0);
    /* the gap's slope v is at hand in closed form (Newton); lambda is bisected */
    return bisect_to(ed, o, kind, lo, hi, 0.0);
}

/* Velocity and acceleration zeros: to EXTREMUM_WIDTH of the scan step. */
static double bisect_turn(const ed_run *ed, const ed_origin *o, ed_kind kind, double lo, double hi)
{
    if (kind == ED_V || kind == ED_NEG_V)
        return newton_to(ed, o, kind, lo, hi, EXTREMUM_WIDTH * ed->scan);
    /* a velocity zero by Newton on the acceleration; the acceleration's zero bisected */
    return bisect_to(ed, o, kind, lo, hi, EXTREMUM_WIDTH * ed->scan);
}

/* Sign of x (0 at 0). */
static int sgn(double x)
{
    return (x > 0.0) - (x < 0.0);
}

/* Direction of motion just after q: v's sign, or the acceleration's at v = 0. */
static int dir_after(const ed_point *q)
{
    return q->v != 0.0 ? sgn(q->v) : sgn(q->acc);
}

/* One velocity zero at most in (a, b]: locate it (an extremum, noted, or
 * beyond the wall: the gap closed before it), then the gap at b.  Returns
 * the impact time or -1. */
static double scan_simple(ed_run *ed, const ed_origin *o, const ed_point *a, const ed_point *b)
{
    int s = dir_after(a), wall = ed->p->wall;
    double hit = -1.0;
    /* v changes sign in (a, b]: one turn, located */
    if (s != 0 && sgn(b->v) != s) {
        double tc = bisect_turn(ed, o, s > 0 ? ED_NEG_V : ED_V, a->t, b->t);
        ed_point c = probe(ed, o, tc);
        /* a maximum beyond the wall: the gap closed before it (grazing), in (a, tc] */
        if (wall && s > 0 && c.past > 0.0)
            hit = bisect(ed, o, ED_GAP, a->t, tc);
        else
            note(ed, tc, c.x);
    }
    /* beyond the wall at b: the gap closed in (a, b] */
    if (hit < 0.0 && wall && b->past > 0.0)
        hit = bisect(ed, o, ED_GAP, a->t, b->t);
    return hit;
}

/* What ended a flight's scan interval (a yielding spring's events too). */
typedef enum { EV_NONE = 0, EV_HIT, EV_YIELD_HI, EV_YIELD_LO, EV_UNLOAD } ed_event;

/* The earliest level of a yielding spring's flight crossed on the monotone
 * segment (ta, e] moving toward s: the wall (EV_HIT), or elastic, the yield
 * level up + s uy (EV_YIELD_HI or _LO, the one in front: the other lies
 * behind; already beyond it at ta: at ta).  Its time, or -1. */
static double segment_event(const ed_run *ed, const ed_origin *o, double ta, const ed_point *e,
                            int s, ed_event *kind)
{
    double t = -1.0;
    if (ed->p->wall && s > 0 && e->past > 0.0) { /* beyond the wall at e */
        t = bisect(ed, o, ED_GAP, ta, e->t);
        *kind = EV_HIT;
    }
    if (ed->phase != 0 || s == 0)
        return t;
    /* a yield level at or past the wall: the impact comes first (x is monotone) */
    if (t >= 0.0 && ed->up + ed->uy >= ed->p->delta)
        return t;
    ed_kind yk = s > 0 ? ED_YIELD_HI : ED_YIELD_LO;
    double tend = t >= 0.0 ? t : e->t; /* the yield level before the wall, if crossed */
    if (bracket_value(ed, o, yk, tend) > 0.0) {
        t = bracket_value(ed, o, yk, ta) > 0.0 ? ta : bisect(ed, o, yk, ta, tend);
        *kind = s > 0 ? EV_YIELD_HI : EV_YIELD_LO;
    }
    return t;
}

/* scan_simple for a yielding spring: the turn in (a, b] (if any) splits it
 * into two monotone segments, each searched for its first level; a turn
 * ending a slide (toward the slide's side) unloads it, located to adjacent
 * doubles.  The event's time (*kind), or -1. */
static double scan_simple_yield(ed_run *ed, const ed_origin *o, const ed_point *a,
                                const ed_point *b, ed_event *kind)
{
    int s = dir_after(a);
    if (s != 0 && sgn(b->v) != s) {
        ed_kind vk = s > 0 ? ED_NEG_V : ED_V;
        double tc = ed->phase == s ? newton_to(ed, o, vk, a->t, b->t, 0.0)
                                   : bisect_turn(ed, o, vk, a->t, b->t);
        ed_point c = probe(ed, o, tc);
        double t = segment_event(ed, o, a->t, &c, s, kind);
        if (t >= 0.0)
            return t;
        note(ed, tc, c.x);
        if (ed->phase == s) { /* the slide turns back: unloading */
            *kind = EV_UNLOAD;
            return tc;
        }
        return segment_event(ed, o, tc, b, -s, kind);
    }
    return segment_event(ed, o, a->t, b, s, kind);
}

/* v has the sign s at both ends and may dip through zero between: the
 * acceleration turns v back toward s inside and v is within reach of zero
 * at an end.  With a monotone acceleration, |v(a) - v(t)| <= |acc(a)| h. */
static int may_turn_twice(const ed_point *a, const ed_point *b, int s)
{
    double h = b->t - a->t;
    /* the acceleration drives v toward zero at a and back toward s at b */
    if (!(s * a->acc < 0.0 && s * b->acc > 0.0))
        return 0;
    /* and v within TURN_MARGIN |acc| h of zero at an end */
    return fabs(a->v) <= TURN_MARGIN * fabs(a->acc) * h ||
           fabs(b->v) <= TURN_MARGIN * fabs(b->acc) * h;
}

/* One interval without a double turn: scan_simple (an impact: EV_HIT), or
 * a yielding spring's scan_simple_yield. */
static double scan_once(ed_run *ed, const ed_origin *o, const ed_point *a, const ed_point *b,
                        ed_event *kind)
{
    if (ed->yielding)
        return scan_simple_yield(ed, o, a, b, kind);
    *kind = EV_HIT;
    return scan_simple(ed, o, a, b);
}

/* One scan interval (a, b]: a velocity dip through zero and back is split
 * at the acceleration's zero into two intervals of one turn each. */
static double scan_interval(ed_run *ed, const ed_origin *o, const ed_point *a, const ed_point *b,
                            ed_event *kind)
{
    int s = dir_after(a);
    if (s != 0 && sgn(b->v) == s && may_turn_twice(a, b, s)) {
        /* the acceleration's zero: v's extreme toward zero */
        double tm = bisect_turn(ed, o, s > 0 ? ED_ACC : ED_NEG_ACC, a->t, b->t);
        ed_point m = probe_acc(ed, o, tm);
        if (sgn(m.v) != s) { /* v crossed zero: a turn on each side of tm */
            double hit = scan_once(ed, o, a, &m, kind);
            if (hit >= 0.0)
                return hit;
            note(ed, m.t, m.x);
            return scan_once(ed, o, &m, b, kind);
        }
    }
    return scan_once(ed, o, a, b, kind);
}

/* Scan intervals for a flight span: equal ones of at most the scan step. */
static long scan_count(const ed_run *ed, double span)
{
    return span > 0.0 ? (long)fmin(fmax(1.0, ceil(span / ed->scan)), SCAN_MAX_INTERVALS) : 0;
}

/* Free flight from the origin up to tb.  Returns the event that ends it
 * first with its time *t_hit and state (an impact exactly at x = delta, a
 * yield onset exactly on its level, an unloading at v = 0), else EV_NONE
 * with the state at tb.  Every velocity zero inside is an extremum (noted). */
static ed_event free_flight(ed_run *ed, const ed_origin *o, double tb, double *t_hit, double *x_end,
                            double *v_end)
{
    ed_point a = {.t = o->t, .x = o->x, .v = o->v, .past = o->x - ed->p->delta};
    a.acc = free_accel(ed, o->j, o->t, o->x, o->v);
    /* n equal intervals of at most the scan step, the last ending exactly at tb */
    long n = scan_count(ed, tb - o->t);
    for (long i = 1; i <= n; i++) {
        double tbi = i == n ? tb : o->t + (tb - o->t) * ((double)i / (double)n);
        ed_point b = probe_acc(ed, o, tbi);
        ed_event kind = EV_NONE;
        double hit = scan_interval(ed, o, &a, &b, &kind);
        if (hit >= 0.0) {
            emit(ed, o, hit, 0);
            ed_point h = probe(ed, o, hit);
            *t_hit = hit;
            *v_end = kind == EV_UNLOAD ? 0.0 : h.v;
            /* the impact exactly at the wall, the onset on its level */
            *x_end = kind == EV_HIT        ? ed->p->delta
                     : kind == EV_YIELD_HI ? ed->up + ed->uy
                     : kind == EV_YIELD_LO ? ed->up - ed->uy
                                           : h.x;
            note(ed, hit, *x_end);
            return kind;
        }
        note(ed, b.t, b.x);
        emit(ed, o, b.t, 0);
        a = b;
    }
    *x_end = a.x;
    *v_end = a.v;
    return EV_NONE;
}

/* Five-point Gauss-Legendre nodes and weights on [-1, 1]. */
static const double GL_NODE[5] = {-0.90617984593866399, -0.53846931010568309, 0.0,
                                  0.53846931010568309, 0.90617984593866399};
static const double GL_WEIGHT[5] = {0.23692688505618909, 0.47862867049936647, 0.56888888888888889,
                                    0.47862867049936647, 0.23692688505618909};

/* int F v dt and int c v^2 dt over the flight from o to tb (F the problem's
 * forcing, without a phase's constant), five Gauss-Legendre points on each
 * scan interval: the integrands are smooth there, the error ~ (w h)^10. */
static void flight_energy(ed_run *ed, const ed_origin *o, double tb)
{
    const pd_sine_piece *pc = &ed->p->pieces[o->j];
    long n = scan_count(ed, tb - o->t);
    double h = (tb - o->t) / (double)n, input = 0.0, damping = 0.0;
    for (long i = 0; i < n; i++) {
        double mid = o->t + ((double)i + 0.5) * h;
        for (int k = 0; k < 5; k++) {
            double t = mid + 0.5 * h * GL_NODE[k], dx, v;
            flow_inc(o, t, &dx, &v);
            input += GL_WEIGHT[k] * pd_sine_piece_force(pc, t) * v;
            damping += GL_WEIGHT[k] * v * v;
        }
    }
    ed->r->input_work += 0.5 * h * input;
    ed->r->damping_work += 0.5 * h * ed->cdamp * damping;
}

/* lambda is linear on a linear piece: its zero ta + lambda(ta) / -c1,
 * polished by bisection to the first double where lambda < 0 (the whole
 * [ta, tb] when rounding puts the root outside its small bracket). */
static double detach_linear(const ed_run *ed, int j, double ta, double tb)
{
    double c1 = ed->p->pieces[j].c1, lam_a = lambda_at(ed, j, ta);
    ed_origin o = {.j = j, .t = ta};
    if (lam_a < 0.0) /* already pulling away */
        return ta;
    /* lambda = lambda(ta) + c1 (t - ta): a zero in [ta, tb] needs c1 < 0 and lambda(tb) < 0 */
    if (!(c1 < 0.0) || !(lambda_at(ed, j, tb) < 0.0))
        return tb;
    double tr = fmin(fmax(ta + lam_a / -c1, ta), tb); /* the line's zero */
    /* a bracket of 16 relative ulps around it, else (rounding) all of [ta, tb] */
    double pad = ROOT_POLISH_ULPS * PD_ROOT_REL * fmax(fabs(tr), 1e-300);
    double lo = fmax(tr - pad, ta), hi = fmin(tr + pad, tb);
    if (!(lambda_at(ed, j, lo) >= 0.0 && lambda_at(ed, j, hi) < 0.0)) {
        lo = ta;
        hi = tb;
    }
    return bisect(ed, &o, ED_NEG_LAMBDA, lo, hi);
}

/* lambda of a sinusoid: scanned for a negative value, then bisected. */
static double detach_scan(const ed_run *ed, int j, double ta, double tb)
{
    ed_origin o = {.j = j, .t = ta};
    long n = scan_count(ed, tb - ta);
    for (long i = 1; i <= n; i++) {
        double a = ta + (tb - ta) * ((double)(i - 1) / (double)n);
        double b = i == n ? tb : ta + (tb - ta) * ((double)i / (double)n);
        /* the first scan point with lambda < 0 closes the bracket */
        if (lambda_at(ed, j, b) < 0.0)
            return bisect(ed, &o, ED_NEG_LAMBDA, a, b);
    }
    return tb;
}

/* Resting on the wall from ta under piece j: the time lambda turns negative
 * (detachment), or tb if it stays >= 0. */
static double rest(ed_run *ed, int j, double ta, double tb)
{
    /* a linear piece (A = 0): lambda's zero in closed form; a sinusoid: scanned */
    double td =
        ed->p->pieces[j].A == 0.0 ? detach_linear(ed, j, ta, tb) : detach_scan(ed, j, ta, tb);
    ed_origin o = {.j = j, .t = ta, .x = ed->p->delta, .v = 0.0};
    note(ed, ta, ed->p->delta);
    emit(ed, &o, td, 1);
    ed->r->contact_time += td - ta;
    return td;
}

/* Scan step of piece j: the shortest period present in it (the
 * oscillator's; the piece's sine) over divisions (default 64), so that the
 * free vibration after a short pulse is scanned at its own period, not the
 * pulse's; independent of the run's length so that results do not move
 * with t_end; span/4 over divisions only when no period exists (free mass,
 * linear forcing).  Pieces shorter than the step are scanned at their ends. */
static double scan_step(const pd_ed_sdof *p, int j, double span, int divisions)
{
    const pd_sine_piece *pc = &p->pieces[j];
    double T = p->osc.w0 > 0.0 ? PD_TWO_PI / p->osc.w0 : HUGE_VAL; /* the oscillator's period */
    if (pc->A != 0.0 && pc->w > 0.0)
        T = fmin(T, PD_TWO_PI / pc->w);
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

/* Piece starts finite and in order. */
static int check_pieces(const pd_ed_sdof *p, pd_err *err)
{
    for (int j = 0; j < p->npieces; j++) {
        const pd_sine_piece *pc = &p->pieces[j];
        if (!isfinite(pc->t_start) || (j > 0 && pc->t_start < p->pieces[j - 1].t_start))
            return pd_err_set(err, PD_EINVAL,
                              "event-driven: forcing piece %d starts at %g, not finite and "
                              "in order",
                              j, pc->t_start);
        if (!isfinite(pc->A) || !isfinite(pc->w) || !isfinite(pc->phi) || !isfinite(pc->c0) ||
            !isfinite(pc->c1))
            return pd_err_set(err, PD_EINVAL, "event-driven: forcing piece %d is not finite", j);
    }
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
    if (!(p->pieces[0].t_start >= 0.0)) /* event times >= 0: -1 says "none" */
        return pd_err_set(err, PD_EINVAL, "event-driven: the start time must be >= 0 (got %g)",
                          p->pieces[0].t_start);
    if (!(o->t_end > p->pieces[0].t_start) || !isfinite(o->t_end))
        return pd_err_set(err, PD_EINVAL, "event-driven: t_end must follow the start time");
    if (o->max_events < 1 || o->max_burst < 1 || o->scan_divisions < 1 ||
        !(o->length_scale > 0.0) || !isfinite(o->length_scale))
        return pd_err_set(err, PD_EINVAL,
                          "event-driven: budgets and scan divisions must be >= 1 and the length "
                          "scale > 0");
    return check_pieces(p, err);
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
                        .scan_divisions = 64,
                        .on_impact = NULL,
                        .on_impact_ctx = NULL,
                        .energy = 0};
}

/* After an impact at t with post-impact speed vp (<= 0): 1 when the
 * oscillator should rest (lambda > 0 and either vp = 0 or an accumulation
 * is jumped to *t_rest), 0 to fly on.  On a linear piece the acceleration
 * at the wall is linear, so its sign at both ends of the tail holds between. */
static int settle(ed_run *ed, int j, double t, double vp, double tb, double *t_rest)
{
    double a = wall_accel(ed, j, t, vp), e = ed->p->e;
    *t_rest = t;
    /* no rebound (e = 0): rest when the free acceleration pushes into the wall */
    if (vp == 0.0)
        return a > 0.0;
    /* an accumulation needs e < 1 and a push toward the wall */
    if (ed->o->no_accumulation || e >= 1.0 || !(a > 0.0))
        return 0;
    double height = vp * vp / (2.0 * a), scale = ed->o->length_scale; /* v+^2 / (2 a) */
    double tail = 2.0 * fabs(vp) / (a * (1.0 - e)); /* flights 2 |v| / a, v -> e v, summed */
    /* jumped only when the bounce is below ACC_HEIGHT L, the tail ends before tb, and the push
     * holds at its middle and end */
    if (height > ACC_HEIGHT * scale || t + tail >= tb ||
        !(wall_accel(ed, j, t + tail, 0.0) > 0.0) ||
        !(wall_accel(ed, j, t + 0.5 * tail, 0.0) > 0.0))
        return 0;
    *t_rest = t + tail; /* bouncing-ball limit: sum of the geometric flight times */
    ed->r->accumulations++;
    return 1;
}

/* An impact at t_hit with speed vn: Newton's law, then rest (an
 * accumulation jumped or e = 0) or flight.  PD_EBUDGET when the burst of
 * impacts exceeds its budget. */
static int impact(ed_run *ed, int j, double t_hit, double vn, double tb, double *t, double *v,
                  int *resting, pd_err *err)
{
    pd_ed_result *res = ed->r;
    double t_rest;
    res->impacts++;
    if (isnan(res->first_impact)) {
        res->first_impact = t_hit;
        res->first_impact_velocity = vn;
    }
    res->max_impact_velocity = fmax(res->max_impact_velocity, vn);
    res->impulse += (1.0 + ed->p->e) * vn; /* per unit mass */
    *t = t_hit;
    if (++ed->burst > ed->max_burst)
        return pd_err_set(err, PD_EBUDGET,
                          "event-driven: accumulation of impacts at t = %.9g: %ld impacts "
                          "without reaching persistent contact%s",
                          t_hit, ed->burst - 1,
                          ed->o->no_accumulation ? " (accumulation handling is off)" : "");
    *v = -ed->p->e * vn; /* Newton's law v+ = -e v- */
    if (ed->o->on_impact)
        ed->o->on_impact(t_hit, vn, *v, ed->o->on_impact_ctx);
    res->impact_loss += 0.5 * (vn * vn - *v * *v);
    /* at rest from t_rest: now, or the accumulation's limit (its tail loses v+^2 / 2) */
    if (settle(ed, j, t_hit, *v, tb, &t_rest)) {
        res->impact_loss += 0.5 * *v * *v;
        ed_origin o = {.j = j, .t = t_hit, .x = ed->p->delta, .v = 0.0};
        emit(ed, &o, t_rest, 1);
        *t = t_rest;
        *v = 0.0;
        *resting = 1;
        ed->burst = 0;
    }
    return PD_OK;
}

/* A yielding spring's phase: elastic (0) or sliding toward ph, its
 * oscillator and constant force. */
static void set_phase(ed_run *ed, int ph)
{
    ed->phase = ph;
    ed->osc = ph ? ed->osc_slide : ed->p->osc;
    ed->shift = ph ? -ph * ed->kbar * ed->uy : ed->kbar * ed->up;
}

/* A slide ends at x (unloading, or an impact): the offset moves to
 * x - sigma uy; elastic again. */
static void end_slide(ed_run *ed, double x)
{
    double up = x - ed->phase * ed->uy;
    ed->r->excursion += fabs(up - ed->up);
    ed->up = up;
    set_phase(ed, 0);
}

/* A yielding spring's problem: uy >= 0 finite, alpha in [0, 1], the
 * sliding phase underdamped, the start inside the elastic range. */
static int check_yield(const pd_ed_sdof *p, double x0, pd_err *err)
{
    if (!(p->uy >= 0.0) || !isfinite(p->uy) || !(p->alpha >= 0.0 && p->alpha <= 1.0))
        return pd_err_set(err, PD_EINVAL,
                          "event-driven: need uy >= 0 finite and alpha in [0, 1] (uy %g, alpha "
                          "%g)",
                          p->uy, p->alpha);
    if (!(p->uy > 0.0) || p->alpha == 1.0)
        return PD_OK;
    if (!(p->osc.xi * p->osc.xi < p->alpha) && p->osc.xi > 0.0 && p->alpha > 0.0)
        return pd_err_set(err, PD_EINVAL,
                          "event-driven: a yielding spring's sliding phase must be underdamped: "
                          "xi < sqrt(alpha) (xi %g, alpha %g), or xi = 0, or alpha = 0",
                          p->osc.xi, p->alpha);
    if (!(fabs(x0) <= p->uy))
        return pd_err_set(err, PD_EINVAL, "event-driven: the start x0 = %g lies beyond uy = %g", x0,
                          p->uy);
    return PD_OK;
}

int pd_ed_sdof_run(const pd_ed_sdof *prob, double x0, double v0, const pd_ed_opts *opts,
                   pd_ed_sampler sampler, void *ctx, pd_ed_result *res, pd_err *err)
{
    ed_run ed;
    int rc, j = 0, resting = 0;
    pd_ed_opts defaults = pd_ed_default_opts();
    pd_err_clear(err);
    if (!prob || !res)
        return PD_NULL_ARG(err, !prob ? "prob" : "res");
    if (!opts)
        opts = &defaults;
    memset(res, 0, sizeof *res);
    res->first_impact = res->first_impact_velocity = NAN;
    res->max_impact_velocity = 0.0;
    if ((rc = check_problem(prob, opts, err)) || (rc = check_yield(prob, x0, err)))
        return rc;
    double t = prob->pieces[0].t_start, x = x0, v = v0;
    ed = (ed_run){.p = prob,
                  .o = opts,
                  .r = res,
                  .sampler = sampler,
                  .ctx = ctx,
                  .scan = scan_step(prob, 0, opts->t_end - t, opts->scan_divisions),
                  .max_events = opts->max_events,
                  .max_burst = opts->max_burst,
                  .t_first = t,
                  .yielding = prob->uy > 0.0 && prob->alpha < 1.0,
                  .uy = prob->uy,
                  .kbar = (1.0 - prob->alpha) * prob->osc.w0 * prob->osc.w0,
                  .osc = prob->osc,
                  .cdamp = 2.0 * prob->osc.xi * prob->osc.w0,
                  .slide_mass = prob->alpha == 0.0 && prob->osc.xi > 0.0};
    /* the sliding phase: stiffness alpha w0^2, the damping 2 xi w0 kept */
    double sa = sqrt(prob->alpha);
    ed.osc_slide = (pd_sdof){.w0 = prob->osc.w0 * sa, .xi = sa > 0.0 ? prob->osc.xi / sa : 0.0};
    note(&ed, t, x);
    if (prob->wall && x >= prob->delta && v >= 0.0) { /* starting on the wall */
        x = prob->delta;
        /* resting only at v = 0 with a push into the wall */
        resting = v == 0.0 && wall_accel(&ed, j, t, 0.0) > 0.0;
    }
    while (t < opts->t_end && !ed.stopped) {
        /* rest or flight up to the piece's end or t_end */
        double tb = fmin(piece_end(prob, j), opts->t_end), t_hit = tb, xn, vn;
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
        } else {
            ed_origin o = {.j = j, .t = t, .x = x, .v = v};
            /* the flight's constants once: each later time is two
             * sincos of half angles and one expm1 (the piece with the
             * phase's constant force, a yielding spring's) */
            pd_sine_piece pc = prob->pieces[j];
            if (ed.shift != 0.0)
                pc.c0 += ed.shift;
            if (ed.phase && ed.slide_mass) /* a damped free mass slides */
                pd_sdof_flow_init_mass(&o.flow, ed.cdamp, &pc, t, x, v);
            else
                pd_sdof_flow_init(&o.flow, &ed.osc, &pc, t, x, v);
            ed_event ev = free_flight(&ed, &o, tb, &t_hit, &xn, &vn);
            if (opts->energy)
                flight_energy(&ed, &o, ev != EV_NONE ? t_hit : tb);
            if (ev == EV_HIT) {
                x = prob->delta;
                if (ed.phase) /* an impact unloads a slide */
                    end_slide(&ed, x);
                if ((rc = impact(&ed, j, t_hit, vn, tb, &t, &v, &resting, err)))
                    break;
                continue;
            }
            if (ev != EV_NONE) { /* a slide begins (on its level) or ends (v = 0) */
                t = t_hit;
                x = xn;
                v = vn;
                if (ev == EV_UNLOAD)
                    end_slide(&ed, x);
                else {
                    res->n_yield++;
                    set_phase(&ed, ev == EV_YIELD_HI ? 1 : -1);
                }
                continue;
            }
            t = tb;
            x = xn;
            v = vn;
        }
        if (t >= piece_end(prob, j) && j + 1 < prob->npieces) {
            j++; /* forcing breakpoint: re-decide rest or flight */
            ed.scan =
                scan_step(prob, j, opts->t_end - prob->pieces[0].t_start, opts->scan_divisions);
            /* the new piece pulls away: detachment at its start */
            if (resting && !(wall_accel(&ed, j, t, 0.0) > 0.0)) {
                resting = 0;
                res->detachments++;
            }
        }
    }
    if (ed.phase) /* sliding at the end: the offset it has reached */
        end_slide(&ed, x);
    res->up = ed.up;
    res->hysteretic = ed.kbar * ed.uy * res->excursion;
    if (opts->energy) { /* the state's energies at the end */
        double w2 = prob->osc.w0 * prob->osc.w0, z = x - ed.up;
        res->kinetic = 0.5 * v * v;
        res->strain =
            ed.yielding ? 0.5 * (prob->alpha * w2 * x * x + ed.kbar * z * z) : 0.5 * w2 * x * x;
    }
    res->t_reached = t;
    return rc;
}
