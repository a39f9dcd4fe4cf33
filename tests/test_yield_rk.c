/* test_yield_rk.c — the exact yielding reference (engine/event_sdof.c)
 * against an independent integration written here for the purpose.
 *
 * The integration shares nothing with the reference but the forcing
 * pieces (pd_sine_piece_force):
 *   - classical fourth-order Runge–Kutta on x'' = F - c x' - w0^2 (alpha x
 *     + (1 - alpha) z), z = x - up while elastic, z = s uy while sliding
 *     toward s, at a fixed step T/STEPS_PER_PERIOD that never crosses a
 *     piece's start;
 *   - every event found by bisecting the length of one RK4 step from the
 *     step's start to adjacent doubles: the gap's closing (Newton's impact),
 *     a yield onset (|x - up| reaches uy), a slide's end (the velocity's
 *     zero), a turn (the extremes), the wall's force reaching zero at rest;
 *   - a bounce lower than REST_HEIGHT of the length scale, with the net
 *     force pressing on the wall, ends on the wall (accumulations).
 * The integration's own error is measured by running it again at half the
 * step (RK4: about 15x closer), and both must agree with the reference:
 * umax (so the ductility) and the residual to 1e-9, the plastic excursion
 * to 1e-8 (FIG_TOL).  Measured: umax to 1e-12, the residual to 1e-10 of
 * uy, the excursion to 4e-9 of uy (the record with eps 1, as close as the
 * integration's h and h/2 runs are to each other).  The onsets must agree
 * in number: a yield level at the wall is an impact, not an onset.  */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_core.h"
#include "pd_engine.h"
#include "pd_problems.h"
#include "pd_test.h"

#define STEPS_PER_PERIOD 2000.0
#define REST_HEIGHT 1e-14 /* of the length scale: a bounce this low ends on the wall */
#define ENERGY_TOL 1e-9   /* the reference's energy balance, of the input work */

enum { RK_ELASTIC = 0, RK_REST = 2 }; /* +-1: sliding toward that side */

/* One integration: the problem, the phase and the tallies. */
typedef struct rk_run {
    const pd_ed_sdof *p;
    double h, t_end, length;
    double kbar, cdamp; /* (1 - alpha) w0^2, 2 xi w0 */
    int j;              /* the piece of t */
    double t, x, v, up; /* up: the plastic offset (while sliding: at the slide's start) */
    int mode;           /* RK_ELASTIC, RK_REST or +-1 */
    double slide_x0;    /* x where the slide began */
    /* the figures */
    double xtoward, xaway, excursion, contact_time;
    long n_yield, impacts;
} rk_run;

/* The hysteretic displacement z in the phase. */
static double rk_z(const rk_run *r, double x)
{
    return r->mode == 1 || r->mode == -1 ? r->mode * r->p->uy : x - r->up;
}

/* x'' at (t, x, v) in the phase (F of the current piece). */
static double rk_acc(const rk_run *r, double t, double x, double v)
{
    const pd_sdof *o = &r->p->osc;
    double F = pd_sine_piece_force(&r->p->pieces[r->j], t);
    double alpha = r->p->uy > 0.0 ? r->p->alpha : 1.0;
    return F - r->cdamp * v - alpha * o->w0 * o->w0 * x -
           (r->p->uy > 0.0 ? r->kbar * rk_z(r, x) : 0.0);
}

/* One RK4 step of length tau from (t, x, v). */
static void rk4(const rk_run *r, double tau, double *x1, double *v1)
{
    double t = r->t, x = r->x, v = r->v;
    double k1x = v, k1v = rk_acc(r, t, x, v);
    double k2x = v + 0.5 * tau * k1v, k2v = rk_acc(r, t + 0.5 * tau, x + 0.5 * tau * k1x, k2x);
    double k3x = v + 0.5 * tau * k2v, k3v = rk_acc(r, t + 0.5 * tau, x + 0.5 * tau * k2x, k3x);
    double k4x = v + tau * k3v, k4v = rk_acc(r, t + tau, x + tau * k3x, k4x);
    *x1 = x + tau / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    *v1 = v + tau / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
}

enum { EV_NONE, EV_WALL, EV_ONSET, EV_SLIDE_END, EV_TURN };

/* Whether event kind has happened by (x1, v1) after the step's start. */
static int rk_happened(const rk_run *r, int kind, double x1, double v1, double dir)
{
    switch (kind) {
    case EV_WALL:
        return x1 > r->p->delta;
    case EV_ONSET:
        return fabs(x1 - r->up) > r->p->uy;
    case EV_SLIDE_END:
        return r->mode * v1 < 0.0;
    default: /* EV_TURN: the velocity left its direction at the start */
        return dir * v1 < 0.0;
    }
}

/* The step length at which kind happens, bisected to adjacent doubles in
 * (0, tau]. */
static double rk_locate(const rk_run *r, int kind, double tau, double dir)
{
    double lo = 0.0, hi = tau, x1, v1;
    while (lo < hi) {
        double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi)
            break;
        rk4(r, mid, &x1, &v1);
        if (rk_happened(r, kind, x1, v1, dir))
            hi = mid;
        else
            lo = mid;
    }
    return hi;
}

static void rk_note(rk_run *r, double x)
{
    r->xtoward = fmax(r->xtoward, x);
    r->xaway = fmax(r->xaway, -x);
}

/* The force the wall takes at rest (> 0: pressed). */
static double rk_wall_force(const rk_run *r, double t)
{
    return rk_acc(r, t, r->p->delta, 0.0);
}

/* Leave a slide at x: the offset fixed where it ended. */
static void rk_end_slide(rk_run *r, double x)
{
    r->up = x - r->mode * r->p->uy;
    r->excursion += fabs(x - r->slide_x0);
    r->mode = RK_ELASTIC;
}

/* An impact at x = delta with the approach speed v > 0: Newton's law, a
 * slide toward the wall unloaded, and a bounce too low to see ends at rest. */
static void rk_impact(rk_run *r, double v)
{
    r->impacts++;
    r->x = r->p->delta;
    if (r->mode == 1 || r->mode == -1)
        rk_end_slide(r, r->x);
    double vp = -r->p->e * v, a = rk_wall_force(r, r->t);
    if (a > 0.0 && vp * vp <= 2.0 * a * REST_HEIGHT * r->length) {
        r->mode = RK_REST;
        r->v = 0.0;
    } else
        r->v = vp;
}

/* Resting on the wall for at most tau: the release located on the wall's
 * force. */
static void rk_rest(rk_run *r, double tau)
{
    if (rk_wall_force(r, r->t + tau) >= 0.0) {
        r->t += tau;
        r->contact_time += tau;
        return;
    }
    double lo = 0.0, hi = tau;
    while (1) {
        double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi)
            break;
        if (rk_wall_force(r, r->t + mid) >= 0.0)
            lo = mid;
        else
            hi = mid;
    }
    r->t += hi;
    r->contact_time += hi;
    r->mode = RK_ELASTIC;
}

/* One step of at most tau in flight, cut at the earliest event. */
static void rk_flight(rk_run *r, double tau)
{
    const pd_ed_sdof *p = r->p;
    double x1, v1, dir = r->v != 0.0 ? r->v : rk_acc(r, r->t, r->x, 0.0);
    rk4(r, tau, &x1, &v1);
    int kinds[4], nk = 0;
    if (p->wall)
        kinds[nk++] = EV_WALL;
    if (p->uy > 0.0)
        kinds[nk++] = r->mode == RK_ELASTIC ? EV_ONSET : EV_SLIDE_END;
    if (r->mode == RK_ELASTIC)
        kinds[nk++] = EV_TURN;
    int first = EV_NONE;
    double when = tau;
    for (int k = 0; k < nk; k++)
        if (rk_happened(r, kinds[k], x1, v1, dir)) {
            double s = rk_locate(r, kinds[k], tau, dir);
            if (first == EV_NONE || s < when)
                first = kinds[k], when = s;
        }
    if (first != EV_NONE)
        rk4(r, when, &x1, &v1);
    r->t += when;
    r->x = x1;
    r->v = v1;
    rk_note(r, x1);
    if (first == EV_WALL)
        rk_impact(r, v1);
    else if (first == EV_ONSET) {
        r->mode = x1 - r->up > 0.0 ? 1 : -1;
        r->slide_x0 = x1;
        r->n_yield++;
    } else if (first == EV_SLIDE_END) {
        r->v = 0.0;
        rk_end_slide(r, x1);
    }
}

/* Integrate p from rest at its first piece's start to t_end at step h. */
static void rk_integrate(rk_run *r, const pd_ed_sdof *p, double h, double t_end, double length)
{
    memset(r, 0, sizeof *r);
    r->p = p;
    r->h = h;
    r->t_end = t_end;
    r->length = length;
    r->kbar = (1.0 - p->alpha) * p->osc.w0 * p->osc.w0;
    r->cdamp = 2.0 * p->osc.xi * p->osc.w0;
    r->t = p->pieces[0].t_start;
    while (r->t < t_end) {
        while (r->j + 1 < p->npieces && p->pieces[r->j + 1].t_start <= r->t)
            r->j++;
        double next = r->j + 1 < p->npieces ? p->pieces[r->j + 1].t_start : t_end;
        double tau = fmin(h, fmin(next, t_end) - r->t);
        if (r->mode == RK_REST)
            rk_rest(r, tau);
        else
            rk_flight(r, tau);
    }
    if (r->mode == 1 || r->mode == -1)
        rk_end_slide(r, r->x);
}

/* The figures compared and their bounds: each side's peak against umax
 * (and ductility = umax / uy with it) and the residual (1 - alpha) up
 * against uy to the 1e-9; the plastic excursion (and the
 * hysteretic work, uy times it) against uy to 1e-8: a sum over every slide,
 * where the integration's own error reaches 3e-9 on the record with eps 1
 * (its h and h/2 runs differ by that; the reference differs by as much). */
enum { FIG_TOWARD, FIG_AWAY, FIG_RESIDUAL, FIG_EXCURSION, NFIG };
static const double FIG_TOL[NFIG] = {1e-9, 1e-9, 1e-9, 1e-8};
static const char *const FIG_NAME[NFIG] = {"peak toward the wall", "peak away", "residual",
                                           "plastic excursion"};

/* The figures of one run, scaled as FIG_TOL reads them. */
static void figures(double xtoward, double xaway, double up, double excursion, const pd_ed_sdof *p,
                    double umax, double fig[NFIG])
{
    double uy = p->uy > 0.0 ? p->uy : 1.0, soft = p->uy > 0.0 ? 1.0 - p->alpha : 0.0;
    fig[FIG_TOWARD] = xtoward / umax;
    fig[FIG_AWAY] = xaway / umax;
    fig[FIG_RESIDUAL] = soft * up / uy;
    fig[FIG_EXCURSION] = excursion / uy;
}

/* One case: the reference and the integration at h and h/2 (the
 * integration's own error is about 1/15 of their difference, which must be
 * within the bounds too); the largest differences over the cases, each
 * against its bound, go to worst[0] (the reference against the integration)
 * and worst[1] (the integration against itself), the reference's energy
 * balance residual (of the input work) to worst[2]. */
static int rk_case(pd_test_ctx *ctx, const pd_ed_sdof *p, double t_end, double tshort,
                   double length, double worst[3], const char *name)
{
    pd_ed_opts o = pd_ed_default_opts();
    o.t_end = t_end;
    o.length_scale = length;
    o.energy = 1;
    pd_ed_result er;
    pd_err err;
    if (!CHECK(ctx, pd_ed_sdof_run(p, 0.0, 0.0, &o, NULL, NULL, &er, &err) == PD_OK, "%s: %s", name,
               err.msg))
        return 0;
    rk_run a, b;
    rk_integrate(&a, p, tshort / STEPS_PER_PERIOD, t_end, length);
    rk_integrate(&b, p, 0.5 * tshort / STEPS_PER_PERIOD, t_end, length);
    double umax = fmax(er.xtoward, er.xaway), ref[NFIG], one[NFIG], two[NFIG];
    figures(er.xtoward, er.xaway, er.up, er.excursion, p, umax, ref);
    figures(a.xtoward, a.xaway, a.up, a.excursion, p, umax, one);
    figures(b.xtoward, b.xaway, b.up, b.excursion, p, umax, two);
    int ok =
        CHECK(ctx, er.n_yield == b.n_yield && er.n_yield == a.n_yield,
              "%s: onsets %ld, integrated %ld and %ld", name, er.n_yield, a.n_yield, b.n_yield);
    /* the reference's energy balance from rest */
    double balance = (er.input_work - er.kinetic - er.strain - er.damping_work - er.hysteretic -
                      er.impact_loss) /
                     er.input_work;
    worst[2] = fmax(worst[2], fabs(balance));
    ok &= CHECK(ctx, fabs(balance) <= ENERGY_TOL,
                "%s: the energy balance's residual %.3g of the input work %.17g", name, balance,
                er.input_work);
    for (int k = 0; k < NFIG; k++) {
        double d_ref = fabs(ref[k] - two[k]), d_self = fabs(one[k] - two[k]);
        worst[0] = fmax(worst[0], d_ref / FIG_TOL[k]);
        worst[1] = fmax(worst[1], d_self / FIG_TOL[k]);
        ok &= CHECK(ctx, d_ref <= FIG_TOL[k] && d_self <= FIG_TOL[k],
                    "%s: %s: the reference %.17g, integrated %.17g (h) and %.17g (h/2): off by "
                    "%.3g, the integration by %.3g (bound %g)",
                    name, FIG_NAME[k], ref[k], one[k], two[k], d_ref, d_self, FIG_TOL[k]);
    }
    return ok;
}

/* Pulses (one sine or cosine cycle of unit amplitude and frequency, then
 * free vibration) on a yielding oscillator against a wall and without one:
 * Pi units, w0 = 1/Pi2, eps 0, 0.5, 1, alpha 0, 0.1, 0.3 (xi 0.05: the
 * slides underdamped or free masses), yields of 0.05 and 0.3 Le. */
static void test_yield_rk_pulses(pd_test_ctx *ctx)
{
    double worst[3] = {0.0, 0.0, 0.0};
    pd_sine_piece pc[2];
    pd_ed_sdof p;
    char name[96];
    int cases = 0, failed = 0;
    for (; pd_test_yield_pulse_case(cases, pc, &p, name, sizeof name); cases++) {
        double tshort = fmin(2.0 * PD_PI, 2.0 * PD_PI / p.osc.w0);
        failed += !rk_case(ctx, &p, 8.0 * PD_PI, tshort, 1.0, worst, name);
    }
    printf("    %d pulse cases, the largest share of a bound: the reference against the "
           "integration %.2g, the integration against itself %.2g; energy balance %.2g\n",
           cases, worst[0], worst[1], worst[2]);
    CHECK(ctx, failed == 0, "%d of %d cases off", failed, cases);
}

/* An elastic-perfectly-plastic oscillator with no wall under a long pulse
 * (five of its periods): the slide is a damped free mass; the ductility
 * and the residual against the integration. */
static void test_yield_rk_long_pulse(pd_test_ctx *ctx)
{
    double worst[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 2; k++) {
        pd_sine_piece pc[2] = {{.t_start = 0.0, .A = -1.0, .w = 0.2, .phi = k ? PD_PI / 2 : 0.0},
                               {.t_start = 10.0 * PD_PI}};
        pd_ed_sdof p = {
            .osc = {.w0 = 1.0, .xi = 0.05}, .npieces = 2, .pieces = pc, .uy = 0.5, .alpha = 0.0};
        rk_case(ctx, &p, 14.0 * PD_PI, 2.0 * PD_PI, 1.0, worst, k ? "long cosine" : "long sine");
    }
    printf("    long pulses, the largest share of a bound: %.2g (the integration against "
           "itself %.2g); energy balance %.2g\n",
           worst[0], worst[1], worst[2]);
}

/* The Rinaldi record (examples/records) on T0 0.8 s, xi 0.05, uy 2 cm,
 * with a wall 1 cm away (eps 0, 0.6, 1) and without; alpha 0, 0.1, 0.3:
 * 4180 linear pieces. */
static void test_yield_rk_record(pd_test_ctx *ctx)
{
    long np;
    pd_sine_piece *pc = pd_test_rinaldi_pieces(ctx, &np);
    if (!pc)
        return;
    const double eps[] = {0.0, 0.6, 1.0}, alphas[] = {0.0, 0.1, 0.3};
    double worst[3] = {0.0, 0.0, 0.0}, T0 = 0.8;
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < 4; k++) {
            pd_ed_sdof p = {.osc = {.w0 = 2.0 * PD_PI / T0, .xi = 0.05},
                            .wall = k < 3,
                            .delta = 0.01,
                            .e = eps[k < 3 ? k : 0],
                            .npieces = (int)np,
                            .pieces = pc,
                            .uy = 0.02,
                            .alpha = alphas[a]};
            char name[64];
            snprintf(name, sizeof name, "record alpha %g %s %g", alphas[a],
                     k < 3 ? "eps" : "no wall", k < 3 ? eps[k] : 0.0);
            rk_case(ctx, &p, pc[np - 1].t_start + 2.0, T0, 0.01, worst, name);
        }
    printf("    record, the largest share of a bound: %.2g against the integration, %.2g the "
           "integration against itself; energy balance %.2g\n",
           worst[0], worst[1], worst[2]);
    free(pc);
}

/* The energy balance of elastic runs (uy 0: the strain w0^2 x^2 / 2) over
 * the pulses against a wall, eps 0 to 1 (accumulations jumped): 1e-12 of
 * the input (measured 4e-15); a missing result is named. */
static void test_yield_rk_elastic_energy(pd_test_ctx *ctx)
{
    double worst = 0.0;
    for (int k = 0; k < 12; k++) {
        pd_sine_piece pc[2] = {
            {.t_start = 0.0, .A = -1.0, .w = 1.0, .phi = k % 2 ? PD_PI / 2 : 0.0},
            {.t_start = 2.0 * PD_PI}};
        pd_ed_sdof p = {.osc = {.w0 = 0.5 + 0.4 * (k / 4), .xi = 0.05 * (k % 3)},
                        .wall = 1,
                        .delta = 0.05,
                        .e = (double)(k % 4) / 3.0,
                        .npieces = 2,
                        .pieces = pc};
        pd_ed_opts o = pd_ed_default_opts();
        o.t_end = 8.0 * PD_PI;
        o.energy = 1;
        pd_ed_result er;
        pd_err err;
        if (!CHECK(ctx, pd_ed_sdof_run(&p, 0.0, 0.0, &o, NULL, NULL, &er, &err) == PD_OK, "%s",
                   err.msg))
            continue;
        double b = (er.input_work - er.kinetic - er.strain - er.damping_work - er.impact_loss) /
                   er.input_work;
        worst = fmax(worst, fabs(b));
        CHECK(ctx, fabs(b) <= 1e-12 && er.impacts > 0 && er.hysteretic == 0.0,
              "case %d: the balance's residual %.3g, %ld impacts", k, b, er.impacts);
    }
    printf("    elastic: the energy balance within %.2g of the input\n", worst);
    pd_ed_sdof p = {.osc = {.w0 = 1.0}, .npieces = 0};
    pd_err err;
    CHECK(ctx,
          pd_ed_sdof_run(&p, 0.0, 0.0, NULL, NULL, NULL, NULL, &err) == PD_EINVAL &&
              strstr(err.msg, "res is NULL"),
          "no result: %s", err.msg);
}

void suite_yield_rk(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_yield_rk_pulses);
    PD_RUN(ctx, test_yield_rk_long_pulse);
    PD_RUN(ctx, test_yield_rk_record);
    PD_RUN(ctx, test_yield_rk_elastic_energy);
}
