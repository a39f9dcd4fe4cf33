/* test_reference.c — the event-driven reference: closed forms, accumulation,
 * energy balance, self-consistency, and Moreau–Jean converging to it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_problems.h"
#include "pd_test.h"

#define TWO_PI 6.283185307179586476925286766559

/* Without the wall the reference is the closed form, and its umax is the
 * continuous maximum: above every sample of a fine grid, and within the
 * grid's O(h^2) of the best one. */
typedef struct grid_max {
    const pd_osc *c;
    double worst, umax_grid;
} grid_max;

static int compare_free(const pd_osc_sample *s, void *ctx)
{
    grid_max *g = ctx;
    double u, v;
    pd_osc_free_exact(g->c, s->t, &u, &v);
    g->worst = fmax(g->worst, fabs(s->u - u) + fabs(s->v - v) / pd_osc_wp(g->c));
    g->umax_grid = fmax(g->umax_grid, fabs(u));
    return 0;
}

static void test_ref_no_wall_is_closed_form(pd_test_ctx *ctx)
{
    const pd_pulse pulses[] = {PD_PULSE_SINE, PD_PULSE_COSINE, PD_PULSE_HARMONIC};
    for (int p = 0; p < 3; p++) {
        pd_osc c = {.pulse = pulses[p],
                    .dir = -1,
                    .ap = 3.0,
                    .Tp = 0.7,
                    .Pi2 = 0.8,
                    .Pi3 = 0.0,
                    .eps = 0.5,
                    .xi = 0.05};
        pd_run_opts o = pd_run_default_opts();
        pd_osc_result r;
        pd_err e;
        grid_max g = {&c, 0, 0};
        o.no_wall = 1;
        o.dt = c.Tp / 20000;
        if (pulses[p] == PD_PULSE_HARMONIC)
            o.tend = 10 * c.Tp;
        CHECK(ctx, pd_osc_reference(&c, &o, compare_free, &g, &r, &e) == PD_OK, "%s", e.msg);
        double scale = pd_osc_Le(&c);
        CHECK(ctx, g.worst <= 1e-13 * scale, "%s: samples differ from the closed form by %.3g",
              pd_pulse_name(pulses[p]), g.worst);
        CHECK(ctx, r.umax >= g.umax_grid * (1 - 1e-15) && r.umax - g.umax_grid <= 1e-7 * r.umax,
              "%s: umax %.15g vs grid max %.15g", pd_pulse_name(pulses[p]), r.umax, g.umax_grid);
        CHECK(ctx, r.impacts == 0 && r.steps < 10, "no events beyond breakpoints (%ld)", r.steps);
    }
}

/* Bouncing ball (w0 = 0, constant force a toward the wall from rest at a
 * distance delta): t1 = sqrt(2 delta / a), v1 = a t1, and the impacts
 * accumulate at t_inf = t1 + 2 e v1 / (a (1 - e)); then it rests. */
static void test_ref_bouncing_ball_accumulation(pd_test_ctx *ctx)
{
    const double es[] = {0.3, 0.5, 0.8, 0.9, 0.995}; /* 0.995: chattering, ~2300 impacts */
    for (int k = 0; k < 5; k++) {
        double a = 2.0, delta = 0.5, e = es[k];
        pd_sine_piece piece = {.t_start = 0.0, .A = a, .w = 0.0, .phi = TWO_PI / 4}; /* a */
        pd_ed_sdof prob = {.osc = {.w0 = 0.0, .xi = 0.0},
                           .wall = 1,
                           .delta = delta,
                           .e = e,
                           .npieces = 1,
                           .pieces = &piece};
        double t1 = sqrt(2 * delta / a), v1 = a * t1, t_inf = t1 + 2 * e * v1 / (a * (1 - e));
        pd_ed_opts o;
        o = pd_ed_default_opts();
        o.t_end = 2 * t_inf + 1.0;
        o.max_burst = 5000;
        pd_ed_result r;
        pd_err err;
        CHECK(ctx, pd_ed_sdof_run(&prob, 0.0, 0.0, &o, NULL, NULL, &r, &err) == PD_OK, "%s",
              err.msg);
        CHECK_NEAR(ctx, r.first_impact, t1, 1e-14);
        CHECK_NEAR(ctx, r.first_impact_velocity, v1, 1e-14);
        /* t_inf moves by 2 e dv / (a (1 - e)) for a speed error dv: conditioning 1/(1-e) */
        CHECK_NEAR(ctx, o.t_end - r.contact_time, t_inf, 1e-12 * t_inf / (1 - e));
        CHECK(ctx, r.accumulations == 1, "e %g: accumulations %ld", e, r.accumulations);
        /* bounce heights fall as e^2n: the jump comes after about
         * log(1e-10 / h1) / log(e^2) impacts, h1 = (e v1)^2 / (2 a) */
        double h1 = (e * v1) * (e * v1) / (2 * a), n_expected = log(1e-10 / h1) / log(e * e);
        CHECK(ctx, fabs((double)r.impacts - n_expected) <= 2.0, "e %g: %ld impacts, expected %.1f",
              e, r.impacts, n_expected);
        CHECK_NEAR(ctx, r.xtoward, delta, 0.0);
    }
}

/* Without the accumulation jump the same ball exhausts its impact budget
 * with a clear status, and does not hang. */
static void test_ref_accumulation_off_stalls(pd_test_ctx *ctx)
{
    double a = 2.0, delta = 0.5, e = 0.8;
    pd_sine_piece piece = {.t_start = 0.0, .A = a, .w = 0.0, .phi = TWO_PI / 4};
    pd_ed_sdof prob = {.osc = {.w0 = 0.0, .xi = 0.0},
                       .wall = 1,
                       .delta = delta,
                       .e = e,
                       .npieces = 1,
                       .pieces = &piece};
    double t1 = sqrt(2 * delta / a), t_inf = t1 + 2 * e * a * t1 / (a * (1 - e));
    pd_ed_opts o;
    o = pd_ed_default_opts();
    o.t_end = 2 * t_inf;
    o.max_burst = 500;
    o.no_accumulation = 1;
    pd_ed_result r;
    pd_err err;
    int rc = pd_ed_sdof_run(&prob, 0.0, 0.0, &o, NULL, NULL, &r, &err);
    CHECK(ctx, rc == PD_EBUDGET, "status %d, expected PD_EBUDGET", rc);
    CHECK(ctx, strstr(err.msg, "accumulation") && strstr(err.msg, "t = "), "message: %s", err.msg);
    CHECK(ctx, fabs(r.t_reached - t_inf) <= 1e-9 * t_inf,
          "stalled at %.15g, the accumulation point is t_inf = %.15g", r.t_reached, t_inf);
    CHECK(ctx, r.impacts == 501, "impacts %ld (budget 500)", r.impacts);
}

/* Unforced, undamped oscillator launched at V toward a wall at delta:
 * t1 = asin(w0 delta / V) / w0, v1 = V cos(w0 t1); each impact keeps
 * the energy times e^2 in its kinetic part; e = 1 keeps E exactly. */
typedef struct energy_obs {
    double w0, E0, worst;
} energy_obs;

static int track_energy(double t, double x, double v, int in_contact, void *ctx)
{
    energy_obs *eo = ctx;
    (void)t;
    (void)in_contact;
    double E = 0.5 * v * v + 0.5 * eo->w0 * eo->w0 * x * x;
    eo->worst = fmax(eo->worst, fabs(E - eo->E0) / eo->E0);
    return 0;
}

static void test_ref_impact_closed_form(pd_test_ctx *ctx)
{
    double w0 = 2.0, V = 1.0, delta = 0.3;
    pd_sine_piece piece = {.t_start = 0.0};
    pd_ed_sdof prob = {.osc = {.w0 = w0, .xi = 0.0},
                       .wall = 1,
                       .delta = delta,
                       .e = 1.0,
                       .npieces = 1,
                       .pieces = &piece};
    pd_ed_opts o;
    o = pd_ed_default_opts();
    o.t_end = 50.0;
    o.h_out = 1e-3;
    energy_obs eo = {w0, 0.5 * V * V, 0};
    pd_ed_result r;
    pd_err err;
    CHECK(ctx, pd_ed_sdof_run(&prob, 0.0, V, &o, track_energy, &eo, &r, &err) == PD_OK, "%s",
          err.msg);
    double t1 = asin(w0 * delta / V) / w0;
    CHECK_NEAR(ctx, r.first_impact, t1, 1e-14);
    CHECK_NEAR(ctx, r.first_impact_velocity, V * cos(w0 * t1), 1e-14);
    CHECK(ctx, eo.worst <= 1e-13, "e = 1: energy drift %.3g over %ld impacts", eo.worst, r.impacts);
    /* period with the wall: 2 pi/w0 less the clipped arc 2 (pi/2 - w0 t1)/w0 */
    double period = (TWO_PI - 2 * (TWO_PI / 4 - w0 * t1)) / w0;
    CHECK(ctx, labs(r.impacts - (long)floor((50.0 - t1) / period) - 1) <= 1,
          "impacts %ld, expected %ld", r.impacts, (long)floor((50.0 - t1) / period) + 1);
    CHECK_NEAR(ctx, r.xaway, V / w0, 1e-14);
}

/* Work-energy balance with forcing, damping and impacts:
 * E(t) - E(0) = int F v - int 2 xi w0 v^2 - sum (1 - e^2) v_imp^2 / 2,
 * integrals by the trapezoid rule on a fine grid (error O(h^2)). */
typedef struct work_obs {
    const pd_osc *c;
    double prev_t, prev_v, prev_p, prev_d, work, damp, w0;
    double x_last, v_last;
    long n;
} work_obs;

static int track_work(const pd_osc_sample *s, void *ctx)
{
    work_obs *wo = ctx;
    double f = pd_osc_excitation(wo->c, s->t), p = f * s->v;
    double d = 2 * wo->c->xi * wo->w0 * s->v * s->v;
    if (wo->n++ > 0) {
        wo->work += 0.5 * (s->t - wo->prev_t) * (p + wo->prev_p);
        wo->damp += 0.5 * (s->t - wo->prev_t) * (d + wo->prev_d);
    }
    wo->prev_t = s->t;
    wo->prev_p = p;
    wo->prev_d = d;
    wo->x_last = s->u;
    wo->v_last = s->v;
    return 0;
}

static void test_ref_energy_balance(pd_test_ctx *ctx)
{
    const double es[] = {1.0, 0.6};
    for (int k = 0; k < 2; k++) {
        pd_osc c = {.pulse = PD_PULSE_SINE,
                    .dir = 1,
                    .ap = 2.0,
                    .Tp = 0.5,
                    .Pi2 = 0.8,
                    .Pi3 = 0.2,
                    .eps = es[k],
                    .xi = 0.05};
        pd_run_opts o = pd_run_default_opts();
        pd_osc_result r;
        pd_err e;
        double w0 = TWO_PI / pd_osc_T0(&c);
        work_obs wo = {&c, 0, 0, 0, 0, 0, 0, w0, 0, 0, 0};
        o.dt = c.Tp / 200000;
        o.tend = c.Tp; /* during the pulse: the force does work */
        CHECK(ctx, pd_osc_reference(&c, &o, track_work, &wo, &r, &e) == PD_OK, "%s", e.msg);
        double E = 0.5 * wo.v_last * wo.v_last + 0.5 * w0 * w0 * wo.x_last * wo.x_last;
        double loss = E - (wo.work - wo.damp);
        /* the trapezoid rule meets each impact's jump of f v: O(h) per impact */
        if (es[k] == 1.0)
            CHECK(ctx, fabs(loss) <= 1e-5 * wo.work, "e = 1: balance off by %.3g (work %.3g)", loss,
                  wo.work);
        else /* the impact losses are what the balance misses */
            CHECK(ctx, loss < -1e-3 * wo.work && r.impacts > 0,
                  "e = 0.6: impacts must dissipate (%.3g, %ld impacts)", loss, r.impacts);
    }
}

/* Self-consistency over the grid of issue 4: a bracketing grid 8 times
 * finer gives the same umax to 1e-11 (the root finding is to rounding). */
static void test_ref_self_consistent_on_grid(pd_test_ctx *ctx)
{
    const double Pi2s[] = {0.05, 0.2, 0.7, 1.16, 3.0, 10.0}, Pi3s[] = {0.001, 0.05, 1.0, 10.0};
    const double epss[] = {0.0, 0.5, 0.9, 1.0};
    double worst = 0;
    int points = 0, pounding = 0, failures = 0;
    for (int p = 0; p < 2; p++)
        for (int dir = -1; dir <= 1; dir += 2)
            for (int i = 0; i < 6; i++)
                for (int j = 0; j < 4; j++)
                    for (int k = 0; k < 4; k++) {
                        pd_osc c = {.pulse = p ? PD_PULSE_COSINE : PD_PULSE_SINE,
                                    .dir = dir,
                                    .ap = 1.0,
                                    .Tp = 1.0,
                                    .Pi2 = Pi2s[i],
                                    .Pi3 = Pi3s[j],
                                    .eps = epss[k],
                                    .xi = 0.05};
                        pd_osc_result r;
                        pd_err e;
                        pd_ed_result fine;
                        if (pd_osc_reference(&c, NULL, NULL, NULL, &r, &e)) {
                            failures++;
                            continue;
                        }
                        /* the same problem, bracketing grid 8x finer */
                        double phi = p ? TWO_PI / 4 : 0.0;
                        pd_sine_piece pc[2] = {{.t_start = 0, .A = (double)dir, .w = 1, .phi = phi},
                                               {.t_start = TWO_PI}};
                        pd_ed_sdof prob = {.osc = {.w0 = Pi2s[i], .xi = 0.05},
                                           .wall = 1,
                                           .delta = Pi3s[j],
                                           .e = epss[k],
                                           .npieces = 2,
                                           .pieces = pc};
                        pd_ed_opts o;
                        o = pd_ed_default_opts();
                        o.t_end = TWO_PI * pd_osc_default_tend(&c) / c.Tp;
                        o.scan_divisions = 512;
                        if (pd_ed_sdof_run(&prob, 0, 0, &o, NULL, NULL, &fine, &e)) {
                            failures++;
                            continue;
                        }
                        double Pi1 = r.umax / pd_osc_Le(&c);
                        worst = fmax(worst, fabs(fine.xmax - Pi1) / Pi1);
                        points++;
                        pounding += r.impacts > 0;
                    }
    CHECK(ctx, failures == 0, "%d grid points failed", failures);
    CHECK(ctx, worst <= 1e-11, "umax differs by %.3g relative between scan grids", worst);
    CHECK(ctx, pounding > points / 3, "the grid must pound (%d of %d)", pounding, points);
}

/* A chattering burst (cosine pulse, Pi2 = 0.7, Pi3 = 0.001, eps = 0.9: 78
 * shrinking bounces, then rest): each flight lasts down to 1e-5, where the
 * sinusoid's phase step must be w (t1 - t0) itself, not a difference of
 * phases (that cost 1e-11 of each tiny dx and moved the rest time by 2e-9
 * between scan grids).  The contact time agrees to 1e-11 over grids 16..4096. */
static void test_ref_chatter_contact_time_consistent(pd_test_ctx *ctx)
{
    const int divs[] = {16, 64, 65, 512, 4096};
    pd_sine_piece pc[2] = {{.t_start = 0.0, .A = 1.0, .w = 1.0, .phi = TWO_PI / 4},
                           {.t_start = TWO_PI}};
    pd_ed_sdof prob = {.osc = {.w0 = 0.7, .xi = 0.05},
                       .wall = 1,
                       .delta = 0.001,
                       .e = 0.9,
                       .npieces = 2,
                       .pieces = pc};
    double ct[5];
    for (int k = 0; k < 5; k++) {
        pd_ed_opts o = pd_ed_default_opts();
        pd_ed_result r;
        pd_err err;
        o.t_end = 6 * TWO_PI;
        o.scan_divisions = divs[k];
        CHECK(ctx, pd_ed_sdof_run(&prob, 0.0, 0.0, &o, NULL, NULL, &r, &err) == PD_OK, "%s",
              err.msg);
        CHECK(ctx, r.accumulations == 1 && r.impacts > 60,
              "grid %d: %ld accumulations, %ld impacts", divs[k], r.accumulations, r.impacts);
        ct[k] = r.contact_time;
        CHECK(ctx, fabs(ct[k] - ct[0]) <= 1e-11, "grid %d: contact time %.17g vs %.17g", divs[k],
              ct[k], ct[0]);
    }
}

/* Moreau–Jean converges to the reference at order about 1 on the history
 * (max over the step grid of |u - u_ref| / umax_ref). */
typedef struct hist {
    double *u;
    long n, cap;
} hist;

static int record_u(const pd_osc_sample *s, void *ctx)
{
    hist *h = ctx;
    if (h->n < h->cap)
        h->u[h->n++] = s->u;
    return 0;
}

static void test_ref_moreau_order_one(pd_test_ctx *ctx)
{
    const pd_osc cases[] = {{.pulse = PD_PULSE_SINE,
                             .dir = 1,
                             .ap = 1.0,
                             .Tp = 1.0,
                             .Pi2 = 0.5,
                             .Pi3 = 0.05,
                             .eps = 0.6,
                             .xi = 0.05},
                            {.pulse = PD_PULSE_COSINE,
                             .dir = -1,
                             .ap = 1.0,
                             .Tp = 1.0,
                             .Pi2 = 1.16,
                             .Pi3 = 0.05,
                             .eps = 0.2,
                             .xi = 0.05}};
    for (int c = 0; c < 2; c++) {
        double err[4];
        for (int k = 0; k < 4; k++) {
            pd_run_opts o = pd_run_default_opts();
            pd_osc_result rm, rr;
            pd_err e;
            o.dt = cases[c].Tp / (2000.0 * (1 << k));
            long cap = pd_steps_for(pd_osc_default_tend(&cases[c]), o.dt) + 2;
            hist hm = {malloc(cap * sizeof(double)), 0, cap},
                 hr = {malloc(cap * sizeof(double)), 0, cap};
            CHECK(ctx, pd_osc_simulate(&cases[c], &o, record_u, &hm, &rm, &e) == PD_OK, "%s",
                  e.msg);
            CHECK(ctx, pd_osc_reference(&cases[c], &o, record_u, &hr, &rr, &e) == PD_OK, "%s",
                  e.msg);
            CHECK(ctx, labs(hm.n - hr.n) <= 1, "grids %ld vs %ld", hm.n, hr.n);
            double w = 0;
            for (long i = 0; i < hm.n && i < hr.n; i++)
                w = fmax(w, fabs(hm.u[i] - hr.u[i]));
            err[k] = w / rr.umax;
            free(hm.u);
            free(hr.u);
        }
        double slope = log2(err[0] / err[3]) / 3;
        CHECK(ctx, slope > 0.7 && slope < 1.6, "case %d: history error slope %.3f (%.3g -> %.3g)",
              c, slope, err[0], err[3]);
        CHECK(ctx, err[3] < 1e-2, "case %d: finest history error %.3g", c, err[3]);
    }
}

/* An independent limit: Kelvin–Voigt contact elements (GSL rk8pd) with
 * stiffness kc -> infinity converge to the reference.  With isolated
 * impacts the umax error falls like 1/kc (each impact lasts ~1/sqrt(kc)
 * with an asymmetry of the same order: case 0); with a resting phase the
 * detachment time is off by ~1/sqrt(kc) and so is umax (case 1, eps = 0.2
 * accumulates and rests).  Asserted: at least the sqrt rate, and the
 * isolated-impact case at the 1/kc rate. */
static void test_ref_stiff_penalty_limit(pd_test_ctx *ctx)
{
    const pd_osc cases[] = {{.pulse = PD_PULSE_SINE,
                             .dir = 1,
                             .ap = 1.0,
                             .Tp = 1.0,
                             .Pi2 = 0.5,
                             .Pi3 = 0.05,
                             .eps = 0.6,
                             .xi = 0.05},
                            {.pulse = PD_PULSE_COSINE,
                             .dir = -1,
                             .ap = 1.0,
                             .Tp = 1.0,
                             .Pi2 = 1.16,
                             .Pi3 = 0.3,
                             .eps = 0.2,
                             .xi = 0.05}};
    for (int c = 0; c < 2; c++) {
        pd_osc_result rr, rp;
        pd_err e;
        CHECK(ctx, pd_osc_reference(&cases[c], NULL, NULL, NULL, &rr, &e) == PD_OK, "%s", e.msg);
        double err[3];
        for (int k = 0; k < 3; k++) {
            pd_penalty_setup po = {.law = PD_PENALTY_KELVIN,
                                   .kc_mult = pow(100.0, k + 2),
                                   .kc_abs = 0,
                                   .rtol = 0,
                                   .atol = 0,
                                   .stepper = NULL};
            CHECK(ctx,
                  pd_osc_penalty(&cases[c], (const pd_run_opts[]){pd_test_pen(NULL, &po)}, NULL,
                                 NULL, &rp, &e) == PD_OK,
                  "%s", e.msg);
            err[k] = fabs(rp.umax - rr.umax) / rr.umax;
        }
        double rate = c == 0 ? 0.03 : 0.15; /* 1/kc, or at least 1/sqrt(kc) per 100x */
        CHECK(ctx, err[1] < rate * err[0] && err[2] < rate * err[1],
              "case %d: errors %.3g, %.3g, %.3g at kc = 1e4, 1e6, 1e8 w0^2 must fall", c, err[0],
              err[1], err[2]);
        CHECK(ctx, err[2] < (c == 0 ? 1e-6 : 1e-5), "case %d: kc = 1e8 w0^2 within %.3g", c,
              err[2]);
    }
}

/* Each forcing piece is scanned at its own shortest period: after a short
 * pulse the free vibration at T0 / 64, not Tp / 64.  The same runs with a
 * free phase that carries a sine of 1e-300 (so its scan is the pulse's, as
 * when one step served the whole run) give the same figures to 1e-13:
 * umax, max x and -x, the first impact, the largest impact speed, the
 * contact time; the same impacts and events (only the scan's evaluations
 * fall, 2,624 to 192 per run at Pi2 = 0.05). */
static void test_ref_scan_per_piece_matches_fixed(pd_test_ctx *ctx)
{
    const double Pi2s[] = {0.05, 0.1, 0.3, 0.7, 1.0, 1.6}, Pi3s[] = {0.001, 0.05, 0.5};
    const double epss[] = {0.0, 0.5, 0.9};
    double worst = 0.0;
    int points = 0, pounding = 0, failures = 0, differ = 0;
    for (int p = 0; p < 2; p++)
        for (int dir = -1; dir <= 1; dir += 2)
            for (int i = 0; i < 6; i++)
                for (int j = 0; j < 3; j++)
                    for (int k = 0; k < 3; k++) {
                        pd_osc c = {.pulse = p ? PD_PULSE_COSINE : PD_PULSE_SINE,
                                    .dir = dir,
                                    .ap = 1.0,
                                    .Tp = 1.0,
                                    .Pi2 = Pi2s[i],
                                    .Pi3 = Pi3s[j],
                                    .eps = epss[k],
                                    .xi = 0.05};
                        double phi = p ? TWO_PI / 4 : 0.0;
                        pd_sine_piece adaptive[2] = {
                            {.t_start = 0, .A = (double)dir, .w = 1, .phi = phi},
                            {.t_start = TWO_PI}};
                        pd_sine_piece fixed[2] = {adaptive[0],
                                                  {.t_start = TWO_PI, .A = 1e-300, .w = 1}};
                        pd_ed_sdof pa = {.osc = {.w0 = Pi2s[i], .xi = 0.05},
                                         .wall = 1,
                                         .delta = Pi3s[j],
                                         .e = epss[k],
                                         .npieces = 2,
                                         .pieces = adaptive};
                        pd_ed_sdof pf = pa;
                        pf.pieces = fixed;
                        pd_ed_opts o = pd_ed_default_opts();
                        pd_ed_result ra, rf;
                        pd_err e;
                        o.t_end = TWO_PI * pd_osc_default_tend(&c) / c.Tp;
                        if (pd_ed_sdof_run(&pa, 0, 0, &o, NULL, NULL, &ra, &e) ||
                            pd_ed_sdof_run(&pf, 0, 0, &o, NULL, NULL, &rf, &e)) {
                            failures++;
                            continue;
                        }
                        const double a[] = {ra.xmax, ra.xtoward, ra.xaway, ra.contact_time,
                                            ra.max_impact_velocity},
                                     f[] = {rf.xmax, rf.xtoward, rf.xaway, rf.contact_time,
                                            rf.max_impact_velocity};
                        for (int q = 0; q < 5; q++)
                            worst = fmax(worst, fabs(a[q] - f[q]) / fmax(fabs(f[q]), 1e-300));
                        if (ra.impacts)
                            worst = fmax(worst,
                                         fabs(ra.first_impact - rf.first_impact) / rf.first_impact);
                        differ += ra.impacts != rf.impacts || ra.events != rf.events;
                        points++;
                        pounding += ra.impacts > 0;
                    }
    CHECK(ctx, failures == 0, "%d cases failed", failures);
    CHECK(ctx, differ == 0, "%d cases count other impacts or events", differ);
    CHECK(ctx, worst <= 1e-13, "the figures differ by %.3g relative between the scans", worst);
    CHECK(ctx, pounding > points / 2, "the grid must pound (%d of %d)", pounding, points);
}

/* Samples while resting on the wall: x at the wall, v exactly 0 (the
 * oscillator is held), for the plain and the yielding spring (a sine
 * pulse into a close wall, eps 0: it rests for a while). */
typedef struct rest_tally {
    long resting;
    double vmax;
} rest_tally;

static int rest_sample(const pd_osc_sample *s, void *ctx)
{
    rest_tally *rt = ctx;
    if (s->gap == 0.0) {
        rt->resting++;
        rt->vmax = fmax(rt->vmax, fabs(s->v));
    }
    return 0;
}

static void test_ref_rest_samples_still(pd_test_ctx *ctx)
{
    for (int k = 0; k < 2; k++) {
        pd_osc c = pd_osc_default();
        c.eps = 0.0;
        c.Pi3 = 0.02;
        c.alpha = 0.2;
        c.Piy = k ? 0.5 : 0.0;
        pd_run_opts o = pd_run_default_opts();
        o.method = PD_METHOD_EVENT;
        rest_tally rt = {0};
        pd_osc_result r;
        pd_err e;
        if (CHECK(ctx, pd_osc_run(&c, &o, rest_sample, &rt, &r, &e) == PD_OK, "%s", e.msg))
            CHECK(ctx, rt.resting >= 10 && rt.vmax == 0.0,
                  "%s: %ld samples at the wall, |v| up to %g there", k ? "yielding" : "elastic",
                  rt.resting, rt.vmax);
    }
}

/* The reference refuses options it cannot run with, naming them: an end
 * time not after the start or not finite, a length scale not > 0 (0
 * included), a start before 0 (its value named), a yielding spring's
 * alpha out of [0, 1] or a start beyond uy. */
static void test_ref_refuses_bad_options(pd_test_ctx *ctx)
{
    pd_sine_piece piece = {.t_start = 0.0, .A = 1.0, .w = 1.0};
    pd_ed_sdof prob = {.osc = {.w0 = 1.0, .xi = 0.05},
                       .wall = 1,
                       .delta = 0.1,
                       .e = 0.5,
                       .npieces = 1,
                       .pieces = &piece};
    pd_ed_result r;
    pd_err e;
    const double t_ends[] = {INFINITY, 0.0, NAN}, scales[] = {0.0, -1.0, INFINITY};
    for (int k = 0; k < 3; k++) {
        pd_ed_opts o = pd_ed_default_opts();
        o.t_end = t_ends[k];
        CHECK(ctx, pd_ed_sdof_run(&prob, 0.0, 0.0, &o, NULL, NULL, &r, &e) == PD_EINVAL,
              "t_end %g taken", t_ends[k]);
        o.t_end = 10.0;
        o.length_scale = scales[k];
        CHECK(ctx,
              pd_ed_sdof_run(&prob, 0.0, 0.0, &o, NULL, NULL, &r, &e) == PD_EINVAL &&
                  strstr(e.msg, "length scale"),
              "length scale %g taken: %s", scales[k], e.msg);
    }
    pd_ed_opts o = pd_ed_default_opts();
    o.t_end = 10.0;
    piece.t_start = -1.5; /* event times are >= 0 */
    CHECK(ctx,
          pd_ed_sdof_run(&prob, 0.0, 0.0, &o, NULL, NULL, &r, &e) == PD_EINVAL &&
              strstr(e.msg, "(got -1.5)"),
          "a start before 0 taken: %s", e.msg);
    piece.t_start = 0.0;
    prob.uy = 0.5;
    prob.alpha = 1.5;
    CHECK(ctx, pd_ed_sdof_run(&prob, 0.0, 0.0, &o, NULL, NULL, &r, &e) == PD_EINVAL,
          "alpha 1.5 taken");
    prob.alpha = 0.1;
    CHECK(ctx,
          pd_ed_sdof_run(&prob, 0.6, 0.0, &o, NULL, NULL, &r, &e) == PD_EINVAL &&
              strstr(e.msg, "beyond uy"),
          "a start beyond uy taken: %s", e.msg);
    CHECK(ctx, pd_ed_sdof_run(&prob, 0.4, 0.0, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg);
}

/* Closed-form rests and tails of a free mass (w0 = 0) at a wall (delta 0):
 *   - held by F = sin(t + pi - 0.01) from t = 0 (starting on the wall at
 *     rest: held, no impact): it detaches exactly where F turns negative,
 *     t = 0.01, within the scan's first interval;
 *   - pushed by F = 1 from x = -1/2 at rest: it strikes at t = 1 (v = 1,
 *     to the adjacent double), and with e = 1/2 its bounces accumulate at
 *     t = 1 + 2 (v / 2) / (a (1 - e)) = 3: with t_end 6 the accumulation
 *     is jumped (at rest from 3), with t_end 3 - 1e-5 it is not (every
 *     bounce's tail ends at 3, after the run: the run ends bouncing); the
 *     first impact's speed is the largest, none gives 0;
 *   - a damped oscillator starting at rest on the wall, pushed into it,
 *     stays held without an impact;
 *   - a budget of 5 events names 5 in its message. */
static void test_ref_free_mass_rests(pd_test_ctx *ctx)
{
    pd_sine_piece hold = {.t_start = 0.0, .A = 1.0, .w = 1.0, .phi = PD_PI - 0.01};
    pd_ed_sdof prob = {.osc = {.w0 = 0.0, .xi = 0.0},
                       .wall = 1,
                       .delta = 0.0,
                       .e = 0.5,
                       .npieces = 1,
                       .pieces = &hold};
    pd_ed_opts o = pd_ed_default_opts();
    o.t_end = 1.0;
    pd_ed_result r;
    pd_err e;
    if (CHECK(ctx, pd_ed_sdof_run(&prob, 0.0, 0.0, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg))
        CHECK(ctx, fabs(r.contact_time - 0.01) <= 1e-15 && r.detachments == 1 && r.impacts == 0,
              "held until %.17g (0.01), %ld detachments, %ld impacts (none: it starts held)",
              r.contact_time, r.detachments, r.impacts);
    pd_sine_piece push = {.t_start = 0.0, .c0 = 1.0};
    prob.pieces = &push;
    const double t_ends[] = {6.0, 3.0 - 1e-5};
    for (int k = 0; k < 2; k++) {
        o.t_end = t_ends[k];
        if (!CHECK(ctx, pd_ed_sdof_run(&prob, -0.5, 0.0, &o, NULL, NULL, &r, &e) == PD_OK, "%s",
                   e.msg))
            continue;
        CHECK(ctx,
              fabs(r.first_impact - 1.0) <= 4e-16 && fabs(r.max_impact_velocity - 1.0) <= 4e-16 &&
                  r.t_reached == t_ends[k],
              "t_end %.17g: first impact at %.17g, largest speed %.17g, reached %.17g", t_ends[k],
              r.first_impact, r.max_impact_velocity, r.t_reached);
        if (k == 0)
            CHECK(ctx, r.accumulations == 1 && fabs(r.contact_time - 3.0) <= 1e-12,
                  "t_end 6: %ld accumulations, at rest %.17g (3, from t = 3)", r.accumulations,
                  r.contact_time);
        else
            CHECK(ctx, r.accumulations == 0 && r.contact_time == 0.0,
                  "t_end 3 - 1e-5: %ld accumulations, at rest %.17g (none: the tail ends at 3)",
                  r.accumulations, r.contact_time);
    }
    /* a damped oscillator at rest on the wall, pushed into it by F = 1/2 > 0
     * (its acceleration at rest; 2 xi w0 = 1 would make it -1/2 at v = 1):
     * held the whole run, no impact */
    pd_sine_piece half = {.t_start = 0.0, .c0 = 0.5};
    pd_ed_sdof pressed = {.osc = {.w0 = 1.0, .xi = 0.5},
                          .wall = 1,
                          .delta = 0.0,
                          .e = 0.5,
                          .npieces = 1,
                          .pieces = &half};
    o.t_end = 2.0;
    if (CHECK(ctx, pd_ed_sdof_run(&pressed, 0.0, 0.0, &o, NULL, NULL, &r, &e) == PD_OK, "%s",
              e.msg))
        CHECK(ctx, r.impacts == 0 && r.contact_time == 2.0,
              "pressed at rest: %ld impacts, held %.17g of 2", r.impacts, r.contact_time);
    prob.wall = 0;
    o.t_end = 6.0;
    if (CHECK(ctx, pd_ed_sdof_run(&prob, -0.5, 0.0, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg))
        CHECK(ctx, r.impacts == 0 && r.max_impact_velocity == 0.0,
              "no wall: %ld impacts, largest speed %g", r.impacts, r.max_impact_velocity);
    prob.wall = 1;
    o.max_events = 5;
    o.no_accumulation = 1;
    CHECK(ctx,
          pd_ed_sdof_run(&prob, -0.5, 0.0, &o, NULL, NULL, &r, &e) == PD_EBUDGET &&
              strstr(e.msg, ": 5 events by") != NULL,
          "the budget's message: %s", e.msg);
}

void suite_reference(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_ref_no_wall_is_closed_form);
    PD_RUN(ctx, test_ref_bouncing_ball_accumulation);
    PD_RUN(ctx, test_ref_accumulation_off_stalls);
    PD_RUN(ctx, test_ref_impact_closed_form);
    PD_RUN(ctx, test_ref_energy_balance);
    PD_RUN(ctx, test_ref_self_consistent_on_grid);
    PD_RUN(ctx, test_ref_scan_per_piece_matches_fixed);
    PD_RUN(ctx, test_ref_chatter_contact_time_consistent);
    PD_RUN(ctx, test_ref_rest_samples_still);
    PD_RUN(ctx, test_ref_refuses_bad_options);
    PD_RUN(ctx, test_ref_free_mass_rests);
    PD_RUN(ctx, test_ref_moreau_order_one);
    PD_RUN(ctx, test_ref_stiff_penalty_limit);
}
