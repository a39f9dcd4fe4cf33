/* test_scan.c — the row reference's scan of a closed-form scalar function
 * (engine/event_row_scan.c) on functions whose roots and extrema are known:
 * crossings to adjacent doubles, extrema to their width, grazing maxima,
 * f' dipping through zero and back inside one interval, the Taylor root
 * against the quadratic formula, and the scan's work bounded (evaluations
 * per interval), so that a safeguard or a guess that silently costs more
 * is caught. */
#include <float.h>
#include <math.h>

#include "event_row.h"
#include "pd_test.h"

#define TWO_PI 6.283185307179586476925286766559
#define PI_HALF 1.5707963267948966192313216916398

/* f = A sin(w t + p) + B: (f, f', f''). */
typedef struct sine_fn {
    double A, w, p, B;
} sine_fn;

static void sine_eval(void *ctx, double t, double out[3])
{
    const sine_fn *g = ctx;
    double s = sin(g->w * t + g->p), c = cos(g->w * t + g->p);
    out[0] = g->A * s + g->B;
    out[1] = g->A * g->w * c;
    out[2] = -g->A * g->w * g->w * s;
}

/* f = (t - c)^3 - e (t - c) + B: f' = 3 (t - c)^2 - e turns twice near c. */
typedef struct cubic_fn {
    double c, e, B;
} cubic_fn;

static void cubic_eval(void *ctx, double t, double out[3])
{
    const cubic_fn *g = ctx;
    double u = t - g->c;
    out[0] = (u * u - g->e) * u + g->B;
    out[1] = 3.0 * u * u - g->e;
    out[2] = 6.0 * u;
}

/* f = t - r: a root at r exactly; calls counted. */
typedef struct line_fn {
    double r;
    long calls;
} line_fn;

static void line_eval(void *ctx, double t, double out[3])
{
    line_fn *g = ctx;
    g->calls++;
    out[0] = t - g->r;
    out[1] = 1.0;
    out[2] = 0.0;
}

/* f = u^3 / 3 + b u^4 / 4 + k u^5 / 5 - e u + B, u = t - c:
 * f' = u^2 + b u^3 + k u^4 - e has a minimum near -e at u = 0, where
 * f'' = 2 u + 3 b u^2 + 4 k u^3 is far from linear over a long interval. */
typedef struct quintic_fn {
    double c, b, k, e, B;
} quintic_fn;

static void quintic_eval(void *ctx, double t, double out[3])
{
    const quintic_fn *g = ctx;
    double u = t - g->c, u2 = u * u;
    out[0] = u * (u2 / 3.0 + g->b * u2 * u / 4.0 + g->k * u2 * u2 / 5.0 - g->e) + g->B;
    out[1] = u2 + g->b * u2 * u + g->k * u2 * u2 - g->e;
    out[2] = 2.0 * u + 3.0 * g->b * u2 + 4.0 * g->k * u2 * u;
}

/* The minimum of a quintic_fn: f at the positive zero of f' (Newton from
 * sqrt(e), where f' is convex). */
static double quintic_min(const quintic_fn *g)
{
    double u = sqrt(g->e), o[3];
    for (int i = 0; i < 60; i++) {
        quintic_eval((void *)g, g->c + u, o);
        u -= o[1] / o[2];
    }
    quintic_eval((void *)g, g->c + u, o);
    return o[0];
}

/* Scan [t0, t1] in n intervals; 1 with *t_hit at the first hit (hit mode). */
static int scan_range(edr_scan *s, double t0, double t1, int n, double *t_hit)
{
    edr_pt a = edr_scan_point(s, t0);
    edr_scan_note(s, a.f);
    for (int i = 1; i <= n; i++) {
        double tb = i == n ? t1 : t0 + (t1 - t0) * i / n;
        edr_pt b = edr_scan_point(s, tb);
        if (edr_scan_interval(s, &a, &b, t_hit))
            return 1;
        a = b;
    }
    return 0;
}

static double fval(edr_fn fn, void *ctx, double t)
{
    double o[3];
    fn(ctx, t, o);
    return o[0];
}

/* The root of sin(t) - 1/2 at pi/6, found in the third of 64 intervals a
 * period: the first double with f > 0, f at the double before <= 0.  Work:
 * the Hermite guess is O(h^4) = 1e-5 off, Newton from it doubles the digits
 * (3 steps to 1e-16) and the adjacent doubles are then checked: at most 8
 * evaluations past the 4 interval ends. */
static void test_edr_scan_crossing_adjacent_doubles(pd_test_ctx *ctx)
{
    sine_fn g = {.A = 1.0, .w = 1.0, .p = 0.0, .B = -0.5};
    edr_scan s = {.fn = sine_eval,
                  .ctx = &g,
                  .width = 4e-8,
                  .hit_mode = 1,
                  .thr = 1e-16,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    double t = NAN;
    int hit = scan_range(&s, 0.0, TWO_PI, 64, &t);
    CHECK(ctx, hit == 1, "the crossing of sin t = 1/2 is found");
    CHECK_NEAR(ctx, t, (TWO_PI / 12.0), 4e-16);
    CHECK(ctx, fval(sine_eval, &g, t) > 0.0 && fval(sine_eval, &g, nextafter(t, 0.0)) <= 0.0,
          "t = %.17g is the first double with f > 0", t);
    CHECK(ctx, s.evals <= 4 + 8, "%ld evaluations for one crossing (bound 12)", s.evals);
}

/* Extrema noted over a period, not in hit mode: sin(t) + 0.25 has its
 * maximum 1.25 at pi/2 and minimum -0.75 at 3 pi/2, located to the width
 * 1e-9 (the value to width^2); every turn located in a few Newton steps. */
static void test_edr_scan_extrema_to_width(pd_test_ctx *ctx)
{
    sine_fn g = {.A = 1.0, .w = 1.0, .p = 0.3, .B = 0.25};
    edr_scan s = {.fn = sine_eval,
                  .ctx = &g,
                  .width = 1e-9,
                  .hit_mode = 0,
                  .thr = 1e-16,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    double t = NAN;
    int hit = scan_range(&s, 0.0, TWO_PI, 64, &t);
    CHECK(ctx, hit == 0, "no hit outside hit mode");
    CHECK_NEAR(ctx, s.fmax, 1.25, 1e-15);
    CHECK_NEAR(ctx, s.fmin, -0.75, 1e-15);
    /* from the linear zero of f' (O(h^2) off) Newton on f' gains digits
     * quadratically: 1e-3, 1e-6, 1e-12 < width, 3 evaluations a turn */
    CHECK(ctx, s.evals <= 65 + 2 * 3, "%ld evaluations for 64 intervals and 2 turns", s.evals);
}

/* A grazing maximum: sin(t) - 1 + 1e-6 tops 1e-6 above zero at pi/2 and
 * crosses at asin(1 - 1e-6) (f' there only 1.4e-3): hit mode finds that
 * crossing, not the later interval end, to adjacent doubles. */
static void test_edr_scan_grazing_crossing(pd_test_ctx *ctx)
{
    sine_fn g = {.A = 1.0, .w = 1.0, .p = 0.0, .B = -1.0 + 1e-6};
    edr_scan s = {.fn = sine_eval,
                  .ctx = &g,
                  .width = 4e-8,
                  .hit_mode = 1,
                  .thr = 1e-16,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    double t = NAN, exact = asin(1.0 - 1e-6);
    int hit = scan_range(&s, 0.0, TWO_PI, 64, &t);
    CHECK(ctx, hit == 1, "the grazing crossing is found");
    CHECK_NEAR(ctx, t, exact, 1e-11);
    CHECK(ctx, fval(sine_eval, &g, t) > 0.0 && fval(sine_eval, &g, nextafter(t, 0.0)) <= 0.0,
          "t = %.17g is the first double with f > 0", t);
    /* f rises 1.4e-3 t: its rounding (1e-16) spans ~400 doubles; Newton lands
     * on that plateau (3), 4 next doubles are tried, then steps doubling
     * cross the plateau (~7) and bisect the last step (~7): ~21 past the
     * 17 ends (the old walk of 30 doubles then bisection took 64) */
    CHECK(ctx, s.evals <= 17 + 21, "%ld evaluations for one grazing crossing", s.evals);
}

/* f' dips through zero and back inside one interval: f = u^3 - e u + B,
 * u = t - c, e = 3e-4, has a maximum 2e-6 + B at u = -0.01 and a minimum
 * -2e-6 + B at u = +0.01, both inside the interval u in (-0.021, 0.015)
 * with f' > 0 at its ends and f there below both extrema.  Not in hit
 * mode both extrema are noted; in hit mode (B = -1e-6: the maximum 1e-6
 * above zero, f < 0 at both ends) the crossing before the maximum is
 * found. */
static void test_edr_scan_double_turn(pd_test_ctx *ctx)
{
    cubic_fn g = {.c = 0.5, .e = 3e-4, .B = -1e-6};
    edr_scan s = {.fn = cubic_eval,
                  .ctx = &g,
                  .width = 1e-10,
                  .hit_mode = 0,
                  .thr = 1e-18,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    edr_pt a = edr_scan_point(&s, 0.479), b = edr_scan_point(&s, 0.515);
    double t = NAN;
    CHECK(ctx, a.df > 0.0 && b.df > 0.0 && a.f < -3e-6 && b.f < 1e-6, "the ends (%g %g)", a.f, b.f);
    CHECK(ctx, edr_scan_interval(&s, &a, &b, &t) == 0, "no hit outside hit mode");
    CHECK_NEAR(ctx, s.fmax, 1e-6, 1e-17);
    CHECK_NEAR(ctx, s.fmin, -3e-6, 1e-17);
    /* the split at the zero of f'' (1) and two turns from their linear guesses */
    CHECK(ctx, s.evals <= 2 + 14, "%ld evaluations for a double turn", s.evals);

    edr_scan h = {.fn = cubic_eval,
                  .ctx = &g,
                  .width = 1e-10,
                  .hit_mode = 1,
                  .thr = 1e-18,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    int hit = edr_scan_interval(&h, &a, &b, &t);
    CHECK(ctx, hit == 1, "the crossing inside a double turn is found");
    CHECK(ctx, t < g.c - 0.01, "it comes before the maximum (%.17g < 0.49)", t);
    CHECK(ctx, fval(cubic_eval, &g, t) > 0.0 && fval(cubic_eval, &g, nextafter(t, 0.0)) <= 0.0,
          "t = %.17g is the first double with f > 0", t);
}

/* A maximum that stays far below zero is not located in hit mode (the
 * Hermite bound of surely_below): sin(t) - 2 over a period costs the
 * interval ends and nothing more; one just below zero (-1e-3 under) is
 * located and noted. */
static void test_edr_scan_far_maximum_skipped(pd_test_ctx *ctx)
{
    sine_fn g = {.A = 1.0, .w = 1.0, .p = 0.3, .B = -2.0};
    edr_scan s = {.fn = sine_eval,
                  .ctx = &g,
                  .width = 4e-8,
                  .hit_mode = 1,
                  .thr = 1e-16,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    double t = NAN;
    CHECK(ctx, scan_range(&s, 0.0, TWO_PI, 64, &t) == 0, "no hit below zero");
    CHECK(ctx, s.evals <= 65 + 3,
          "%ld evaluations (the maximum far below is skipped, the "
          "minimum located in 3)",
          s.evals);

    sine_fn n = {.A = 1.0, .w = 1.0, .p = 0.3, .B = -1.0 - 1e-9};
    edr_scan m = {.fn = sine_eval,
                  .ctx = &n,
                  .width = 4e-8,
                  .hit_mode = 1,
                  .thr = 1e-16,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    CHECK(ctx, scan_range(&m, 0.0, TWO_PI, 64, &t) == 0, "no hit 1e-9 below zero");
    CHECK_NEAR(ctx, m.fmax, -1e-9, 1e-15);

    /* 64 intervals' ends, the minimum in 3, the maximum coarsely (to 1e-4 h:
     * f within 1e-10 of its top, far from thr) in 2 */
    CHECK(ctx, m.evals <= 65 + 3 + 2, "%ld evaluations", m.evals);
}

/* Crossings at 19 places across one interval (the root at u h from its
 * start, u = 0.05 ... 0.95, h = 0.1): each at the first double with f > 0;
 * from the Hermite guess (O(h^4)) Newton needs two or three steps, then
 * the double below is checked. */
static void test_edr_scan_crossing_sweep(pd_test_ctx *ctx)
{
    long worst = 0;
    for (int i = 1; i <= 19; i++) {
        double r = 0.7, u = 0.05 * i, h = 0.1;
        sine_fn g = {.A = 1.0, .w = 1.0, .p = 0.0, .B = -sin(r)};
        edr_scan s = {.fn = sine_eval,
                      .ctx = &g,
                      .width = 4e-8 * h,
                      .hit_mode = 1,
                      .thr = 1e-16,
                      .fmax = -HUGE_VAL,
                      .fmin = HUGE_VAL};
        edr_pt a = edr_scan_point(&s, r - u * h), b = edr_scan_point(&s, r + (1.0 - u) * h);
        double t = NAN;
        int hit = edr_scan_interval(&s, &a, &b, &t);
        CHECK(ctx,
              hit == 1 && fval(sine_eval, &g, t) > 0.0 &&
                  fval(sine_eval, &g, nextafter(t, 0.0)) <= 0.0,
              "u = %.2f: t = %.17g is the first double with f > 0", u, t);
        worst = s.evals - 2 > worst ? s.evals - 2 : worst;
    }
    CHECK(ctx, worst <= 5, "at most %ld evaluations a crossing", worst);
}

/* A hump inside one interval: sin(t) - 1 + 5e-6 rises 5e-6 above zero
 * only within 3.2e-3 of pi/2, the interval (pi/2 - 0.049, pi/2 + 0.049)
 * holds it whole (f < 0 at both ends, and the ends' slopes make the
 * interval's scale negative): the maximum is located, found above zero,
 * and the crossing before it returned. */
static void test_edr_scan_hump_inside_interval(pd_test_ctx *ctx)
{
    sine_fn g = {.A = 1.0, .w = 1.0, .p = 0.0, .B = -1.0 + 5e-6};
    edr_scan s = {.fn = sine_eval,
                  .ctx = &g,
                  .width = 4e-8 * 0.098,
                  .hit_mode = 1,
                  .thr = 1e-16,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    edr_pt a = edr_scan_point(&s, PI_HALF - 0.049), b = edr_scan_point(&s, PI_HALF + 0.049);
    double t = NAN, exact = asin(1.0 - 5e-6);
    CHECK(ctx, a.f < 0.0 && b.f < 0.0, "f < 0 at both ends");
    int hit = edr_scan_interval(&s, &a, &b, &t);
    CHECK(ctx, hit == 1, "the hump is found");
    CHECK_NEAR(ctx, t, exact, 1e-12);
    CHECK(ctx, fval(sine_eval, &g, t) > 0.0 && fval(sine_eval, &g, nextafter(t, 0.0)) <= 0.0,
          "t = %.17g is the first double with f > 0", t);
    /* the maximum (2), Newton on f from the middle of (a, maximum) (~8),
     * the plateau of f's rounding (~150 doubles) crossed by doubling
     * steps and bisected (~14): was 56 when a Newton step landing on the
     * bracket's end fell back to bisection */
    CHECK(ctx, s.evals <= 2 + 24, "%ld evaluations", s.evals);

    /* a hump 1e-7 high near the start of (pi/2 - 0.005, pi/2 + 0.03): the
     * ends' slopes are far apart, the interval's scale is large, and the
     * Hermite bound must still see the maximum may reach above zero */
    sine_fn k = {.A = 1.0, .w = 1.0, .p = 0.0, .B = -1.0 + 1e-7};
    edr_scan q = {.fn = sine_eval,
                  .ctx = &k,
                  .width = 4e-8 * 0.035,
                  .hit_mode = 1,
                  .thr = 1e-16,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    a = edr_scan_point(&q, PI_HALF - 0.005);
    b = edr_scan_point(&q, PI_HALF + 0.03);
    CHECK(ctx, a.f < 0.0 && b.f < 0.0, "f < 0 at both ends");
    hit = edr_scan_interval(&q, &a, &b, &t);
    CHECK(ctx, hit == 1, "the small hump is found");
    CHECK_NEAR(ctx, t, asin(1.0 - 1e-7), 1e-12);
}

/* A gap already closed by less than its rounding level at the scan's
 * start (f(a) = 1e-13 < thr = 1e-12, f rising): the hit is the first
 * double after a, not a time before the interval. */
static void test_edr_scan_start_just_past_zero(pd_test_ctx *ctx)
{
    line_fn g = {.r = 1.0 - 1e-13};
    edr_scan s = {.fn = line_eval,
                  .ctx = &g,
                  .width = 4e-9,
                  .hit_mode = 1,
                  .thr = 1e-12,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    edr_pt a = edr_scan_point(&s, 1.0), b = edr_scan_point(&s, 1.1);
    double t = NAN;
    int hit = edr_scan_interval(&s, &a, &b, &t);
    CHECK(ctx, hit == 1 && t > 1.0 && t <= nextafter(1.0, 2.0), "hit at %.17g (start 1)", t);
    /* measured: Newton leaves the bracket at once, bisection to adjacent doubles */
    CHECK(ctx, s.evals <= 2 + 49, "%ld evaluations", s.evals);
}

/* f' comes close to zero but stays positive (min 0.2 of its ends' mean
 * over 0.05): not a double turn; the interval costs one more point. */
static void test_edr_scan_near_double_turn(pd_test_ctx *ctx)
{
    cubic_fn g = {.c = 0.5, .e = -2e-4, .B = 0.0};
    edr_scan s = {.fn = cubic_eval,
                  .ctx = &g,
                  .width = 1e-10,
                  .hit_mode = 0,
                  .thr = 1e-18,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    edr_pt a = edr_scan_point(&s, 0.479), b = edr_scan_point(&s, 0.515);
    double t = NAN;
    CHECK(ctx, edr_scan_interval(&s, &a, &b, &t) == 0, "no hit outside hit mode");
    CHECK(ctx, s.fmax == b.f && s.fmin == b.f, "only f(b) noted (%g %g)", s.fmax, s.fmin);
    CHECK(ctx, s.evals == 2 + 1, "%ld evaluations", s.evals);
}

/* A double turn the linear zero of f'' misses: f' = u^2 + 10 u^4 - 1e-3
 * over u in (-0.4, 0.1), f'' far from linear: its interpolated zero
 * (u = 0.067) has f' = 3.6e-3 > 0, its true zero (u = 0) f' = -1e-3.
 * The split is located precisely and both extrema found.  Then
 * f' = u^2 + 2 u^3 - 1e-3 over (-0.115, 0.09): f' at the ends nearly
 * equal (9.2e-3, 8.6e-3), at the interpolated zero of f'' 5.1e-5, within
 * a twentieth of the ends' sum (so located precisely), not of their
 * difference. */
static void test_edr_scan_double_turn_located(pd_test_ctx *ctx)
{
    const quintic_fn cases[2] = {{.c = 1.0, .b = 0.0, .k = 10.0, .e = 1e-3, .B = 0.5},
                                 {.c = 1.0, .b = 2.0, .k = 0.0, .e = 1e-3, .B = 0.5}};
    const double ua[2] = {-0.4, -0.115}, ub[2] = {0.1, 0.09};
    for (int i = 0; i < 2; i++) {
        quintic_fn g = cases[i];
        edr_scan s = {.fn = quintic_eval,
                      .ctx = &g,
                      .width = 1e-12,
                      .hit_mode = 0,
                      .thr = 1e-18,
                      .fmax = -HUGE_VAL,
                      .fmin = HUGE_VAL};
        edr_pt a = edr_scan_point(&s, g.c + ua[i]), b = edr_scan_point(&s, g.c + ub[i]);
        double t = NAN, fmin = quintic_min(&g);
        CHECK(ctx, a.df > 0.0 && b.df > 0.0, "case %d: f' > 0 at both ends", i);
        CHECK(ctx, edr_scan_interval(&s, &a, &b, &t) == 0, "no hit outside hit mode");
        CHECK_NEAR(ctx, s.fmin, fmin, 1e-16);
        CHECK(ctx, s.fmin < b.f - 1e-6, "case %d: the minimum %.17g lies below f(b) %.17g", i,
              s.fmin, b.f);
    }
}

/* Across an inflection with f' far from zero (f' >= 0.05, f'' from -0.12
 * to 0.09 over 0.035): no turn is possible, and none is looked for. */
static void test_edr_scan_inflection_costs_nothing(pd_test_ctx *ctx)
{
    cubic_fn g = {.c = 0.5, .e = -0.05, .B = 0.0};
    edr_scan s = {.fn = cubic_eval,
                  .ctx = &g,
                  .width = 1e-10,
                  .hit_mode = 0,
                  .thr = 1e-18,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    edr_pt a = edr_scan_point(&s, 0.48), b = edr_scan_point(&s, 0.515);
    double t = NAN;
    CHECK(ctx, a.ddf < 0.0 && b.ddf > 0.0, "f'' changes sign");
    CHECK(ctx, edr_scan_interval(&s, &a, &b, &t) == 0 && s.evals == 2,
          "%ld evaluations (no split point)", s.evals);
}

/* A maximum 2e-4 below zero in an interval placed off its centre (so
 * that f'' differs at the ends): the Hermite bound shows it far below,
 * and it costs nothing beyond the ends. */
static void test_edr_scan_below_maximum_costs_nothing(pd_test_ctx *ctx)
{
    sine_fn g = {.A = 1.0, .w = 1.0, .p = 0.0, .B = -1.0 - 2e-4};
    edr_scan s = {.fn = sine_eval,
                  .ctx = &g,
                  .width = 4e-8 * 0.098,
                  .hit_mode = 1,
                  .thr = 1e-16,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    edr_pt a = edr_scan_point(&s, PI_HALF - 0.08), b = edr_scan_point(&s, PI_HALF + 0.018);
    double t = NAN;
    CHECK(ctx, edr_scan_interval(&s, &a, &b, &t) == 0, "no hit");
    CHECK(ctx, s.evals == 2, "%ld evaluations (the maximum is not located)", s.evals);
}

/* The first double where a line crosses zero, by bisection on the sign;
 * a root at exactly 0 has no relative width to stop at: the bisection is
 * capped (BISECT_MAX_IT = 200 halvings of [-1, 1]: 0 then 2^-1 ... 2^-199). */
static void test_edr_scan_bisect_sign(pd_test_ctx *ctx)
{
    line_fn g = {.r = 0.1};
    double t = edr_bisect_sign(line_eval, &g, 0, 1.0, 0.0, 1.0);
    CHECK(ctx, t - g.r > 0.0 && nextafter(t, 0.0) - g.r <= 0.0, "t = %.17g: first double above 0.1",
          t);
    line_fn z = {.r = 0.0};
    double lo = edr_bisect_sign(line_eval, &z, 0, 1.0, -1.0, 1.0);
    CHECK(ctx, lo == ldexp(1.0, -199), "a root at 0 ends after 200 halvings: %.17g", lo);
    CHECK(ctx, z.calls == 200, "%ld evaluations", z.calls);
    /* the bracket (1 + u, 1 + 2 u), u = 2^-52: wider than 2e-16 of 1, yet
     * adjacent; its midpoint rounds to 1 + 2 u (even): the bisection stops */
    line_fn a = {.r = 1.0 + DBL_EPSILON};
    double hi = edr_bisect_sign(line_eval, &a, 0, 1.0, 1.0 + DBL_EPSILON, 1.0 + 2.0 * DBL_EPSILON);
    CHECK(ctx, hi == 1.0 + 2.0 * DBL_EPSILON && a.calls == 0,
          "adjacent doubles: %.17g after %ld "
          "evaluations",
          hi, a.calls);
}

/* The Taylor root: the smallest s > 0 with f + f' s + f''/2 s^2 = 0,
 * against the quadratic's roots written out. */
static void test_edr_scan_taylor_root(pd_test_ctx *ctx)
{
    /* (s - 1)(s - 3) = s^2 - 4 s + 3: f = 3, f' = -4, f'' = 2 -> 1 */
    edr_pt p = {.t = 0.0, .f = 3.0, .df = -4.0, .ddf = 2.0};
    CHECK_NEAR(ctx, edr_taylor_root(&p), 1.0, 1e-15);
    /* (s + 1)(s - 2) / 2: f = -1, f' = -1/2, f'' = 1 -> 2 (the other root negative) */
    p = (edr_pt){.f = -1.0, .df = -0.5, .ddf = 1.0};
    CHECK_NEAR(ctx, edr_taylor_root(&p), 2.0, 1e-15);
    /* -(s + 2)(s - 0.5) = -s^2 - 1.5 s + 1: f = 1, f' = -1.5, f'' = -2 -> 0.5 */
    p = (edr_pt){.f = 1.0, .df = -1.5, .ddf = -2.0};
    CHECK_NEAR(ctx, edr_taylor_root(&p), 0.5, 1e-15);
    /* s^2 + 1: no real root */
    p = (edr_pt){.f = 1.0, .df = 0.0, .ddf = 2.0};
    CHECK(ctx, isnan(edr_taylor_root(&p)), "s^2 + 1 has no root");
    /* (s + 1)(s + 2): both roots negative */
    p = (edr_pt){.f = 2.0, .df = 3.0, .ddf = 2.0};
    CHECK(ctx, isnan(edr_taylor_root(&p)), "no positive root of (s + 1)(s + 2)");
    /* linear: -1 + 4 s -> 0.25; constant -1: none; -1 - s: none */
    p = (edr_pt){.f = -1.0, .df = 4.0, .ddf = 0.0};
    CHECK_NEAR(ctx, edr_taylor_root(&p), 0.25, 1e-16);
    p = (edr_pt){.f = -1.0, .df = 0.0, .ddf = 0.0};
    CHECK(ctx, isnan(edr_taylor_root(&p)), "a constant has no root");
    p = (edr_pt){.f = -1.0, .df = -1.0, .ddf = 0.0};
    CHECK(ctx, isnan(edr_taylor_root(&p)), "-1 - s has no positive root");
    /* q = 1: roots 0.25 = f / q and 0.5 = q / c of 0.25 - 1.5 s + 2 s^2 */
    p = (edr_pt){.f = 0.25, .df = -1.5, .ddf = 4.0};
    CHECK_NEAR(ctx, edr_taylor_root(&p), 0.25, 1e-16);
    /* s^2 alone: its root 0 is not > 0 */
    p = (edr_pt){.f = 0.0, .df = 0.0, .ddf = 2.0};
    CHECK(ctx, isnan(edr_taylor_root(&p)), "s^2 has no root s > 0");
    /* a double root: (s - 2)^2 -> 2 */
    p = (edr_pt){.f = 4.0, .df = -4.0, .ddf = 2.0};
    CHECK_NEAR(ctx, edr_taylor_root(&p), 2.0, 1e-7);
}

/* f = e - u^4, u = t - 1/2: a flat maximum e = 1e-20 above zero (f' = -4 u^3
 * turns at a triple root: Newton on it gains a third a step, so the coarse
 * location stops up to 3e-5 off, where f < 0).  The maximum is refined
 * from there whichever side it fell, and the crossing before it found:
 * u^4 = e at u = -1e-5.  (Refined only on one side, it was missed when the
 * coarse location fell before the maximum.) */
typedef struct quartic_fn {
    double e;
} quartic_fn;

static void quartic_eval(void *ctx, double t, double out[3])
{
    double e = ((const quartic_fn *)ctx)->e, u = t - 0.5;
    out[0] = e - u * u * u * u;
    out[1] = -4.0 * u * u * u;
    out[2] = -12.0 * u * u;
}

static void test_edr_scan_flat_maximum_refined(pd_test_ctx *ctx)
{
    quartic_fn g = {.e = 1e-20};
    edr_scan s = {.fn = quartic_eval,
                  .ctx = &g,
                  .width = 4e-9,
                  .hit_mode = 1,
                  .thr = 1e-26,
                  .fmax = -HUGE_VAL,
                  .fmin = HUGE_VAL};
    edr_pt a = edr_scan_point(&s, 0.48), b = edr_scan_point(&s, 0.58);
    double t = NAN;
    CHECK(ctx, a.f < 0.0 && b.f < 0.0, "f < 0 at both ends");
    int hit = edr_scan_interval(&s, &a, &b, &t);
    CHECK(ctx, hit == 1, "the flat maximum's crossing is found");
    CHECK_NEAR(ctx, t, 0.5 - 1e-5, 1e-15);
}

void suite_scan(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_edr_scan_crossing_adjacent_doubles);
    PD_RUN(ctx, test_edr_scan_extrema_to_width);
    PD_RUN(ctx, test_edr_scan_grazing_crossing);
    PD_RUN(ctx, test_edr_scan_double_turn);
    PD_RUN(ctx, test_edr_scan_far_maximum_skipped);
    PD_RUN(ctx, test_edr_scan_crossing_sweep);
    PD_RUN(ctx, test_edr_scan_hump_inside_interval);
    PD_RUN(ctx, test_edr_scan_start_just_past_zero);
    PD_RUN(ctx, test_edr_scan_near_double_turn);
    PD_RUN(ctx, test_edr_scan_double_turn_located);
    PD_RUN(ctx, test_edr_scan_below_maximum_costs_nothing);
    PD_RUN(ctx, test_edr_scan_inflection_costs_nothing);
    PD_RUN(ctx, test_edr_scan_flat_maximum_refined);
    PD_RUN(ctx, test_edr_scan_bisect_sign);
    PD_RUN(ctx, test_edr_scan_taylor_root);
}
