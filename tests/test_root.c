/* test_root.c — core/root.c, the event locators' root finder, on functions
 * whose roots are known: the first double where f > 0, to a width, with
 * f's rounding holding it at zero over many doubles, and its work. */
#include <float.h>
#include <math.h>

#include "pd_root.h"
#include "pd_test.h"

/* f = sin(t) - s0: a root at asin(s0). */
static double sine_minus(void *ctx, double t, double *slope)
{
    if (slope)
        *slope = cos(t);
    return sin(t) - *(const double *)ctx;
}

/* f = t - r. */
static double line_minus(void *ctx, double t, double *slope)
{
    if (slope)
        *slope = 1.0;
    return t - *(const double *)ctx;
}

/* The first double with f > 0, by both methods, on sin t - 1/2 (root pi/6)
 * and on t - 0.1; Newton from the middle of (0, 1) in a handful of
 * evaluations (quadratic: 1e-1, 1e-2, 1e-5, 1e-10, 1e-16, then the
 * closing probes), bisection in about 53. */
static void test_root_first_double(pd_test_ctx *ctx)
{
    double s0 = 0.5, r0 = 0.1;
    pd_root a = {.f = sine_minus, .ctx = &s0}, b = {.f = sine_minus, .ctx = &s0};
    double tb = pd_root_bisect(&a, 0.0, 1.0, 0.0), tn = pd_root_newton(&b, 0.0, 1.0, 0.0, NAN);
    CHECK(ctx, tb == tn, "bisection %.17g and Newton %.17g agree", tb, tn);
    CHECK(ctx, sin(tn) - s0 > 0.0 && sin(nextafter(tn, 0.0)) - s0 <= 0.0,
          "%.17g is the first double with f > 0", tn);
    CHECK_NEAR(ctx, tn, asin(0.5), 2.3e-16);
    CHECK(ctx, b.evals <= 8 && a.evals >= 50, "Newton %ld, bisection %ld evaluations", b.evals,
          a.evals);
    pd_root l = {.f = line_minus, .ctx = &r0};
    double t = pd_root_newton(&l, 0.0, 1.0, 0.0, 0.3);
    CHECK(ctx, t - r0 > 0.0 && nextafter(t, 0.0) - r0 <= 0.0, "line: %.17g", t);
    /* the guess, the root itself (f = 0 on the bracket's end), probes above */
    CHECK(ctx, l.evals <= 5, "a line from a guess: %ld evaluations", l.evals);
}

/* To a width: Newton's converged step is returned within w of the root. */
static void test_root_width(pd_test_ctx *ctx)
{
    double s0 = 0.5;
    pd_root r = {.f = sine_minus, .ctx = &s0};
    double t = pd_root_newton(&r, 0.0, 1.0, 1e-6, NAN);
    CHECK(ctx, fabs(t - asin(0.5)) <= 1e-6, "within 1e-6: %.17g", t);
    pd_root b = {.f = sine_minus, .ctx = &s0};
    t = pd_root_bisect(&b, 0.0, 1.0, 1e-6);
    CHECK(ctx, t - asin(0.5) >= 0.0 && t - asin(0.5) <= 1e-6, "bisection above, within 1e-6");
    CHECK(ctx, b.evals <= 20, "%ld halvings for 1e-6 (2^-20)", b.evals);
}

/* sin t - (1 - 1e-6) near pi/2: f rises 1.4e-3 per unit of t, its rounding
 * (1.1e-16) spans ~80 doubles of zeros; Newton lands on them, the probes
 * double their distance until f > 0 and bisection finds the first double:
 * the same as bisection's, in at most half its evaluations. */
static void test_root_rounding_plateau(pd_test_ctx *ctx)
{
    double s0 = 1.0 - 1e-6, lo = 1.5, hi = 1.5707963267948966;
    pd_root a = {.f = sine_minus, .ctx = &s0}, b = {.f = sine_minus, .ctx = &s0};
    double tb = pd_root_bisect(&a, lo, hi, 0.0), tn = pd_root_newton(&b, lo, hi, 0.0, NAN);
    CHECK(ctx, tb == tn, "bisection %.17g and Newton %.17g agree", tb, tn);
    CHECK(ctx, sin(tn) - s0 > 0.0 && sin(nextafter(tn, 0.0)) - s0 <= 0.0,
          "%.17g is the first double with f > 0", tn);
    CHECK(ctx, 2 * b.evals <= a.evals, "Newton %ld, bisection %ld evaluations", b.evals, a.evals);
}

/* A root at 0 has no relative width: bisection of [-1, 1] stops after
 * PD_ROOT_BISECT_MAX halvings, at 2^-199; adjacent doubles whose middle
 * rounds to hi stop at once. */
static void test_root_bisect_limits(pd_test_ctx *ctx)
{
    double z = 0.0, r1 = 1.0 + DBL_EPSILON;
    pd_root r = {.f = line_minus, .ctx = &z};
    double t = pd_root_bisect(&r, -1.0, 1.0, 0.0);
    CHECK(ctx, t == ldexp(1.0, -199) && r.evals == PD_ROOT_BISECT_MAX, "%.17g after %ld", t,
          r.evals);
    pd_root a = {.f = line_minus, .ctx = &r1};
    t = pd_root_bisect(&a, 1.0 + DBL_EPSILON, 1.0 + 2.0 * DBL_EPSILON, 0.0);
    CHECK(ctx, t == 1.0 + 2.0 * DBL_EPSILON && a.evals == 0, "adjacent: %.17g after %ld", t,
          a.evals);
}

/* f = t - r with a slope that lies (1e20): Newton's first step barely moves
 * and looks converged half a unit above the root; the probe below it finds
 * f > 0 there, so the bracket is cut to it and bisection still returns the
 * first double above r: the slope guides, the signs decide. */
static double line_lying_slope(void *ctx, double t, double *slope)
{
    if (slope)
        *slope = 1e20;
    return t - *(const double *)ctx;
}

static void test_root_lying_slope(pd_test_ctx *ctx)
{
    double r0 = 0.25;
    pd_root r = {.f = line_lying_slope, .ctx = &r0};
    double t = pd_root_newton(&r, 0.0, 1.0, 0.0, 0.75);
    CHECK(ctx, t - r0 > 0.0 && nextafter(t, 0.0) - r0 <= 0.0, "%.17g: the first double above 0.25",
          t);
}

/* A bracket already as narrow as the width asked is returned as it is (hi,
 * no evaluation), by bisection and by Newton; one wider by a factor 2 takes
 * one halving. */
static void test_root_bisect_width(pd_test_ctx *ctx)
{
    double r0 = 0.3;
    pd_root a = {.f = line_minus, .ctx = &r0}, b = {.f = line_minus, .ctx = &r0};
    double t = pd_root_bisect(&a, 0.0, 1.0, 1.0);
    CHECK(ctx, t == 1.0 && a.evals == 0, "width 1 on (0, 1): %.17g after %ld", t, a.evals);
    t = pd_root_bisect(&b, 0.0, 1.0, 0.5);
    CHECK(ctx, t == 0.5 && b.evals == 1, "width 0.5 on (0, 1): %.17g after %ld", t, b.evals);
    /* Newton the same: (0, 1) at width 1, (0.5, 1) at width 0.6 */
    pd_root c = {.f = line_minus, .ctx = &r0}, d = {.f = line_minus, .ctx = &r0};
    t = pd_root_newton(&c, 0.0, 1.0, 1.0, NAN);
    CHECK(ctx, t == 1.0 && c.evals == 0, "Newton, width 1 on (0, 1): %.17g after %ld", t, c.evals);
    t = pd_root_newton(&d, 0.5, 1.0, 0.6, NAN);
    CHECK(ctx, t == 1.0 && d.evals == 0, "Newton, width 0.6 on (0.5, 1): %.17g after %ld", t,
          d.evals);
}

void suite_root(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_root_first_double);
    PD_RUN(ctx, test_root_width);
    PD_RUN(ctx, test_root_rounding_plateau);
    PD_RUN(ctx, test_root_bisect_limits);
    PD_RUN(ctx, test_root_lying_slope);
    PD_RUN(ctx, test_root_bisect_width);
}
