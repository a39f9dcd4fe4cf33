/* event_row_scan.c — the scan of a closed-form scalar function f over one
 * interval, as the one-wall reference scans its flight (event_sdof.c):
 * with (f, f', f'') known at every t, f' is nearly quadratic over an
 * interval of a 64th of the shortest period, so it changes sign at most
 * twice.  One sign change: the turn is located (an extremum of f, noted;
 * in hit mode a maximum above zero means f crossed zero before it: a
 * grazing closing).  None at the ends but f'' changing sign with f' within
 * reach of zero: f' may dip through zero and back; the zero of f'' splits
 * the interval into two of one turn each.  A crossing counts once f
 * reaches above thr (its rounding level), so that a gap at zero whose
 * rate and acceleration are rounding noise (a contact just released) does
 * not close again at every next double.  Roots of f are located to
 * adjacent doubles by safeguarded Newton on f' (bisection finishes), turns
 * to a width (f is flat there). */
#include <math.h>

#include "event_row.h"
#include "pd_root.h"

/* f' may turn twice in an interval only within this many |f''| h of zero. */
#define TURN_MARGIN 2.0
/* Past a converged root, this many next doubles are tried one by one. */
#define WALK_DOUBLES 4
/* A turn is not located in hit mode when f stays below -this of the
 * interval's scale. */
#define HERMITE_MARGIN 1e-3
/* In hit mode a maximum is first located to this fraction of its interval. */
#define COARSE_TURN 1e-4
/* A double turn's split is located precisely only when f' at the
 * interpolated extremum is within this of its ends' sizes. */
#define SPLIT_MARGIN 0.05

edr_pt edr_scan_point(edr_scan *s, double t)
{
    double o[3];
    s->fn(s->ctx, t, o);
    s->evals++;
    return (edr_pt){.t = t, .f = o[0], .df = o[1], .ddf = o[2]};
}

void edr_scan_note(edr_scan *s, double f)
{
    s->fmax = fmax(s->fmax, f);
    s->fmin = fmin(s->fmin, f);
}

/* sign * out[k] of the scanned function, as core/root.c's function. */
typedef struct scan_fn {
    edr_scan *s;
    int k;
    double sign;
} scan_fn;

/* sign * out[k] at t, counted in s->evals. */
static double scan_value(void *ctx, double t, double *slope)
{
    const scan_fn *c = ctx;
    double o[3];
    c->s->fn(c->s->ctx, t, o);
    c->s->evals++;
    /* the slope of sign * out[k] is sign * out[k + 1] (none given for f'') */
    if (slope)
        *slope = c->k < 2 ? c->sign * o[c->k + 1] : 0.0;
    return c->sign * o[c->k];
}

static double value(edr_scan *s, int k, double sign, double t, double *slope)
{
    scan_fn c = {.s = s, .k = k, .sign = sign};
    return scan_value(&c, t, slope);
}

/* Bisection between lo (value <= 0) and hi (> 0) to the width w (0:
 * adjacent doubles); returns hi (core/root.c). */
static double bisect_to(edr_scan *s, int k, double sign, double lo, double hi, double w)
{
    scan_fn c = {.s = s, .k = k, .sign = sign};
    pd_root r = {.f = scan_value, .ctx = &c};
    return pd_root_bisect(&r, lo, hi, w);
}

/* The sign change of sign * out[k] between lo and hi by safeguarded Newton
 * on its closed-form slope (k < 2; f'' has none: bisection), from the guess
 * t0 when it lies inside (else the middle): core/root.c's, the same hi as
 * bisection. */
static double locate_from(edr_scan *s, int k, double sign, double lo, double hi, double w,
                          double t0)
{
    if (k == 2)
        return bisect_to(s, k, sign, lo, hi, w);
    scan_fn c = {.s = s, .k = k, .sign = sign};
    pd_root r = {.f = scan_value, .ctx = &c};
    return pd_root_newton(&r, lo, hi, w, t0);
}

static double locate(edr_scan *s, int k, double sign, double lo, double hi, double w)
{
    return locate_from(s, k, sign, lo, hi, w, NAN);
}

/* The first double where f > 0 between lo (f <= 0) and hi (f > 0), to
 * the precision f itself has: Newton on the exact f and f' from the guess
 * t0 until the step is a few ulps or within f's rounding level (thr /
 * f'), then the first iterate or next doubles with f > 0.  A step leaving
 * the bracket hands it to bisection. */
static double crossing(edr_scan *s, double lo, double hi, double t0)
{
    double t = t0 > lo && t0 < hi ? t0 : 0.5 * (lo + hi);
    for (int it = 0; it < PD_ROOT_NEWTON_MAX; it++) {
        double df, f = value(s, 0, 1.0, t, &df);
        if (f > 0.0)
            hi = t;
        else
            lo = t;
        double tn = t - f / df;
        if (!(df > 0.0) || !(tn >= lo && tn <= hi))
            break; /* outside the bracket: bisection's safety */
        if (fabs(tn - t) > fmax(8.0 * PD_ROOT_REL * fabs(tn), 2.0 * s->thr / df)) {
            if (!(tn > lo && tn < hi))
                break;
            t = tn;
            continue;
        }
        if (f > 0.0) /* converged past the crossing */
            return t;
        /* f <= 0 within its rounding of the root: the next doubles, then
         * steps doubling (f's rounding may hold it at zero over many
         * doubles), then bisection of the last step */
        double c = fmax(tn, nextafter(t, HUGE_VAL));
        for (int j = 0; c < hi && j < PD_ROOT_NEWTON_MAX; j++) {
            if (value(s, 0, 1.0, c, NULL) > 0.0) {
                if (j < WALK_DOUBLES)
                    return c; /* the double after lo */
                hi = c;
                break;
            }
            lo = c;
            c = j + 1 < WALK_DOUBLES ? nextafter(c, HUGE_VAL) : c + 2.0 * (c - t);
        }
        return bisect_to(s, 0, 1.0, lo, hi, 0.0);
    }
    return locate(s, 0, 1.0, lo, hi, 0.0);
}

/* The root of the cubic Hermite of (f, f') through a and b (f(a) <= 0 <
 * f(b)): a guess to O(h^4). */
static double hermite_root(const edr_pt *a, const edr_pt *b)
{
    double h = b->t - a->t, u = 0.5;
    double p0 = a->f, p1 = b->f, m0 = a->df * h, m1 = b->df * h;
    for (int it = 0; it < 8; it++) { /* Newton on the cubic in u in [0, 1] */
        double u2 = u * u, u3 = u2 * u;
        /* p(u) = h00 p0 + h10 m0 + h01 p1 + h11 m1 (the cubic Hermite basis on
         * [0, 1]) and d = p'(u) */
        double f = (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 + (-2 * u3 + 3 * u2) * p1 +
                   (u3 - u2) * m1;
        double d = (6 * u2 - 6 * u) * p0 + (3 * u2 - 4 * u + 1) * m0 + (-6 * u2 + 6 * u) * p1 +
                   (3 * u2 - 2 * u) * m1;
        if (!(d > 0.0))
            break;
        double un = u - f / d;
        if (!(un > 0.0 && un < 1.0))
            break;
        u = un;
    }
    return a->t + u * h;
}

double edr_taylor_root(const edr_pt *a)
{
    /* f + f' s + f'' s^2 / 2 = 0: the smallest s > 0 (NAN: none) */
    double f = a->f, d = a->df, c = 0.5 * a->ddf;
    if (c == 0.0)
        return d != 0.0 && -f / d > 0.0 ? -f / d : NAN;
    double disc = d * d - 4.0 * c * f;
    if (disc < 0.0)
        return NAN;
    double q = -0.5 * (d + copysign(sqrt(disc), d)), r1 = q / c, r2 = q != 0.0 ? f / q : NAN;
    double best = NAN;
    if (r1 > 0.0)
        best = r1;
    if (r2 > 0.0 && !(r2 >= best))
        best = r2;
    return best;
}

double edr_bisect_sign(edr_fn fn, void *ctx, int k, double sign, double lo, double hi)
{
    edr_scan s = {.fn = fn, .ctx = ctx};
    return bisect_to(&s, k, sign, lo, hi, 0.0);
}

static int sgn(double x)
{
    return (x > 0.0) - (x < 0.0);
}

/* Direction of f just after p: f' 's sign, or f'' 's where f' = 0. */
static int dir_after(const edr_pt *p)
{
    return p->df != 0.0 ? sgn(p->df) : sgn(p->ddf);
}

/* In hit mode, a maximum of f inside (a, b) that stays far below zero
 * need not be located.  With f' linear from p = f'(a) > 0 to q = f'(b) < 0
 * the maximum is f(a) + p^2 h / (2 (p - q)); f' departs from the line by
 * at most |f''(b) - f''(a)| h / 4, which adds h^2 / 4 of it.  Far below:
 * under -HERMITE_MARGIN of the interval's scale. */
static int surely_below(const edr_scan *s, const edr_pt *a, const edr_pt *b)
{
    double h = b->t - a->t, p = a->df, q = b->df;
    if (!s->hit_mode || !(p > 0.0 && q < 0.0))
        return 0;
    double top = a->f + p * p * h / (2.0 * (p - q)) + 0.25 * fabs(b->ddf - a->ddf) * h * h;
    double scale = fabs(a->f) + fabs(b->f) + h * (fabs(p) + fabs(q));
    return top < -HERMITE_MARGIN * scale;
}

/* At most one turn of f in (a, b]: locate it (noted, or in hit mode a
 * maximum above zero: the crossing before it), then f(b). */
static int scan_simple(edr_scan *s, const edr_pt *a, const edr_pt *b, double *t_hit)
{
    int dir = dir_after(a);
    if (dir != 0 && sgn(b->df) != dir && !surely_below(s, a, b)) {
        double tc;
        edr_pt c;
        if (s->hit_mode && dir > 0) {
            /* a maximum: located coarsely first; refined only when f could
             * reach thr within the coarse location's uncertainty */
            double w = fmax(s->width, COARSE_TURN * (b->t - a->t));
            double t0 = a->t + (b->t - a->t) * (a->df / (a->df - b->df));
            tc = locate_from(s, 1, -1.0, a->t, b->t, w, t0);
            c = edr_scan_point(s, tc);
            double top = c.f + fabs(c.df) * w + fabs(c.ddf) * w * w;
            if (!(c.f > s->thr) && top > s->thr && w > s->width) {
                /* Newton from the coarse tc over the whole (a, b), where f'
                 * changes sign: tc may lie on either side of the maximum */
                tc = locate_from(s, 1, -1.0, a->t, b->t, s->width, tc);
                c = edr_scan_point(s, tc);
            }
        } else {
            /* from the zero of f' interpolated linearly */
            double t0 = a->t + (b->t - a->t) * (a->df / (a->df - b->df));
            tc = locate_from(s, 1, dir > 0 ? -1.0 : 1.0, a->t, b->t, s->width, t0);
            c = edr_scan_point(s, tc);
        }
        if (s->hit_mode && dir > 0 && c.f > s->thr) {
            *t_hit = locate(s, 0, 1.0, a->t, tc, 0.0);
            return 1;
        }
        edr_scan_note(s, c.f);
    }
    if (s->hit_mode && b->f > s->thr) {
        *t_hit =
            crossing(s, a->t, b->t, a->f <= 0.0 ? hermite_root(a, b) : a->t + edr_taylor_root(a));
        return 1;
    }
    return 0;
}

/* f' has the sign dir at both ends and may dip through zero between. */
static int may_turn_twice(const edr_pt *a, const edr_pt *b, int dir)
{
    double h = b->t - a->t;
    /* f' heads toward zero at a and away at b: |f'| has a minimum inside,
     * a dip through zero possible only if f' at an end is within
     * TURN_MARGIN |f''| h of zero */
    if (!(dir * a->ddf < 0.0 && dir * b->ddf > 0.0))
        return 0;
    return fabs(a->df) <= TURN_MARGIN * fabs(a->ddf) * h ||
           fabs(b->df) <= TURN_MARGIN * fabs(b->ddf) * h;
}

int edr_scan_interval(edr_scan *s, const edr_pt *a, const edr_pt *b, double *t_hit)
{
    int dir = dir_after(a);
    if (dir != 0 && sgn(b->df) == dir && may_turn_twice(a, b, dir)) {
        /* f'' is nearly linear over the interval: its interpolated zero is
         * f' 's extremum to O(h^2); located precisely only when f' there is
         * too close to zero to tell whether it dips through.  (f'' changes
         * sign, so the zero lies in [a, b]; rounded onto an end, f' has
         * its extremum there, of the sign dir: no dip.) */
        double tm = a->t + (b->t - a->t) * (a->ddf / (a->ddf - b->ddf));
        int inside = tm > a->t && tm < b->t;
        edr_pt mid = inside ? edr_scan_point(s, tm) : *a;
        if (inside && sgn(mid.df) == dir &&
            fabs(mid.df) <= SPLIT_MARGIN * (fabs(a->df) + fabs(b->df))) {
            tm = locate(s, 2, dir > 0 ? 1.0 : -1.0, a->t, b->t, s->width);
            mid = edr_scan_point(s, tm);
        }
        if (sgn(mid.df) != dir) {
            if (scan_simple(s, a, &mid, t_hit))
                return 1;
            edr_scan_note(s, mid.f);
            if (scan_simple(s, &mid, b, t_hit))
                return 1;
            edr_scan_note(s, b->f);
            return 0;
        }
    }
    if (scan_simple(s, a, b, t_hit))
        return 1;
    edr_scan_note(s, b->f);
    return 0;
}
