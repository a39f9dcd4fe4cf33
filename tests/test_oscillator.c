/* test_oscillator.c — the pounding oscillator: closed forms, convergence
 * orders, self-similarity, contact physics and energy. */
#include <math.h>
#include <string.h>

#include "pd_problems.h"
#include "pd_test.h"

#define TWO_PI 6.283185307179586476925286766559

/* Largest |u - u_exact| over the steps of a no-wall run, relative to umax. */
typedef struct free_err {
    const pd_osc *c;
    double worst, umax;
} free_err;

static int track_free_error(const pd_osc_sample *s, void *ctx)
{
    free_err *fe = ctx;
    double u, v;
    pd_osc_free_exact(fe->c, s->t, &u, &v);
    fe->worst = fmax(fe->worst, fabs(s->u - u));
    fe->umax = fmax(fe->umax, fabs(u));
    return 0;
}

/* Observed order of the no-wall error as dt halves: 2 for theta = 1/2,
 * 1 for theta = 1 (slopes within 0.2), for sine and cosine pulses. */
static void test_osc_free_flight_order(pd_test_ctx *ctx)
{
    const pd_pulse pulses[] = {PD_PULSE_SINE, PD_PULSE_COSINE};
    const double thetas[] = {0.5, 1.0}, orders[] = {2.0, 1.0};
    for (int p = 0; p < 2; p++)
        for (int th = 0; th < 2; th++) {
            pd_osc c = {.pulse = pulses[p],
                        .dir = 1,
                        .ap = 2.0,
                        .Tp = 0.5,
                        .Pi2 = 0.7,
                        .Pi3 = 0.0,
                        .eps = 0.5,
                        .xi = 0.05};
            double err[4];
            for (int k = 0; k < 4; k++) {
                pd_run_opts o = pd_run_default_opts();
                pd_osc_result r;
                pd_err e;
                free_err fe = {&c, 0, 0};
                o.no_wall = 1;
                o.theta = thetas[th];
                o.dt = c.Tp / (200.0 * (1 << k)); /* theta = 1 is first order from here on */
                int rc = pd_osc_simulate(&c, &o, track_free_error, &fe, &r, &e);
                CHECK(ctx, rc == PD_OK, "run: %s", e.msg);
                err[k] = fe.worst / fe.umax;
            }
            for (int k = 1; k < 4; k++) {
                double slope = log2(err[k - 1] / err[k]);
                CHECK(ctx, fabs(slope - orders[th]) <= 0.2,
                      "%s theta %g: slope %.3f between dt/%d and dt/%d (errors %.3g, %.3g)",
                      pd_pulse_name(pulses[p]), thetas[th], slope, 1 << (k - 1), 1 << k, err[k - 1],
                      err[k]);
            }
            CHECK(ctx, err[3] < (th ? 3e-2 : 1e-4), "finest error %.3g", err[3]);
        }
}

/* Same Pi terms and dt/Tp at three scales: the same Pi1 to 1e-12. */
static void test_osc_self_similarity(pd_test_ctx *ctx)
{
    const double scales[3][2] = {{1.0, 1.0}, {3.7, 0.4}, {0.2, 2.5}};
    const pd_pulse pulses[] = {PD_PULSE_SINE, PD_PULSE_COSINE};
    for (int p = 0; p < 2; p++)
        for (int dir = -1; dir <= 1; dir += 2) {
            double Pi1[3];
            long impacts[3];
            for (int k = 0; k < 3; k++) {
                pd_osc c = {.pulse = pulses[p],
                            .dir = dir,
                            .ap = scales[k][0],
                            .Tp = scales[k][1],
                            .Pi2 = 0.7,
                            .Pi3 = 0.05,
                            .eps = 0.6,
                            .xi = 0.05};
                pd_run_opts o = pd_run_default_opts();
                pd_osc_result r;
                pd_err e;
                o.dt = c.Tp / 4000;
                CHECK(ctx, pd_osc_simulate(&c, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg);
                Pi1[k] = r.umax / pd_osc_Le(&c);
                impacts[k] = r.impacts;
            }
            double spread =
                (fmax(Pi1[0], fmax(Pi1[1], Pi1[2])) - fmin(Pi1[0], fmin(Pi1[1], Pi1[2]))) / Pi1[0];
            CHECK(ctx, spread <= 1e-12, "%s %s: Pi1 spread %.3g (%.17g %.17g %.17g)",
                  pd_pulse_name(pulses[p]), pd_dir_name(dir), spread, Pi1[0], Pi1[1], Pi1[2]);
            CHECK(ctx, impacts[0] == impacts[1] && impacts[1] == impacts[2] && impacts[0] > 0,
                  "impacts %ld %ld %ld", impacts[0], impacts[1], impacts[2]);
        }
}

/* Penetration is O(dt): -min g <= C dt.  The look-ahead g + h/2 U misses a
 * gap that closes late in a step, and the impact step moves q by
 * h (U_k + U_k+1)/2, so C <= (1 - gamma + (1 - e)/2) max|U| <= max|U|.
 * Measured C = max(-min g / dt) over dt = Tp/500 ... Tp/4000. */
static void test_osc_penetration_is_order_dt(pd_test_ctx *ctx)
{
    pd_osc c = {.pulse = PD_PULSE_COSINE,
                .dir = 1,
                .ap = 1.0,
                .Tp = 1.0,
                .Pi2 = 0.5,
                .Pi3 = 0.02,
                .eps = 0.7,
                .xi = 0.05};
    double C = 0, vmax = 0;
    for (int k = 0; k < 4; k++) {
        pd_run_opts o = pd_run_default_opts();
        pd_osc_result r;
        pd_err e;
        o.dt = c.Tp / (500.0 * (1 << k));
        CHECK(ctx, pd_osc_simulate(&c, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg);
        CHECK(ctx, r.impacts >= 2, "impacts %ld", r.impacts);
        double pen = -r.min_gap;
        C = fmax(C, pen / o.dt);
        vmax = fmax(vmax, r.max_impact_velocity);
        CHECK(ctx, pen > 0, "Moreau-Jean penetrates a little (%.3g)", pen);
        CHECK(ctx, pen <= (1 - 0.5 + (1 - c.eps) / 2) * r.max_impact_velocity * o.dt * 1.05,
              "dt %g: penetration %.3g beyond the bound %.3g", o.dt, pen,
              (0.5 + (1 - c.eps) / 2) * r.max_impact_velocity * o.dt);
    }
    CHECK(ctx, C > 0.01 * vmax && C <= vmax, "measured C = %.4g m/s, impact speeds up to %.4g m/s",
          C, vmax);
}

/* Persistent contact: eps = 0, normal sine pulse, Pi2 = 0.3, Pi3 = 0.05.
 * On the wall (u' = 0, u = delta) the contact force per unit mass is
 * lambda = f(t) - w0^2 delta - 2 xi w0 * 0 >= 0; the oscillator leaves when
 * it turns negative: sin(wp t) = Pi2^2 Pi3 on the falling side. */
typedef struct rest_track {
    const pd_osc *c;
    double dt, worst_lambda_err, lambda_scale;
    long longest, run;
    double run_start, run_end, best_start, best_end;
} rest_track;

static int track_rest(const pd_osc_sample *s, void *ctx)
{
    rest_track *rt = ctx;
    if (s->impulse > 0) {
        if (rt->run == 0)
            rt->run_start = s->t;
        rt->run++;
        rt->run_end = s->t;
        if (rt->run > 2) { /* inside the episode: compare P/dt with lambda at mid-step */
            double w0 = TWO_PI / pd_osc_T0(rt->c);
            double tm = s->t - 0.5 * rt->dt;
            double lambda = pd_osc_excitation(rt->c, tm) - w0 * w0 * pd_osc_gap(rt->c);
            rt->worst_lambda_err = fmax(rt->worst_lambda_err, fabs(s->impulse / rt->dt - lambda));
        }
        if (rt->run > rt->longest) {
            rt->longest = rt->run;
            rt->best_start = rt->run_start;
            rt->best_end = rt->run_end;
        }
    } else
        rt->run = 0;
    return 0;
}

static void test_osc_persistent_contact(pd_test_ctx *ctx)
{
    pd_osc c = {.pulse = PD_PULSE_SINE,
                .dir = 1,
                .ap = 3.0,
                .Tp = 0.8,
                .Pi2 = 0.3,
                .Pi3 = 0.05,
                .eps = 0.0,
                .xi = 0.05};
    pd_run_opts o = pd_run_default_opts();
    pd_osc_result r;
    pd_err e;
    o.dt = c.Tp / 4000;
    rest_track rt = {&c, o.dt, 0, c.ap, 0, 0, 0, 0, 0, 0};
    CHECK(ctx, pd_osc_simulate(&c, &o, track_rest, &rt, &r, &e) == PD_OK, "%s", e.msg);
    double wp = pd_osc_wp(&c);
    double t_detach = (TWO_PI / 2 - asin(c.Pi2 * c.Pi2 * c.Pi3)) / wp;
    CHECK(ctx, rt.longest > 1000, "a long resting episode (%ld steps)", rt.longest);
    CHECK(ctx, rt.worst_lambda_err <= 1e-3 * c.ap,
          "contact force P/dt vs f - w0^2 delta: worst error %.3g (ap %g)", rt.worst_lambda_err,
          c.ap);
    CHECK(ctx, fabs(rt.best_end - t_detach) <= 3 * o.dt,
          "detachment at %.6f s, lambda changes sign at %.6f s (dt %.2g)", rt.best_end, t_detach,
          o.dt);
    CHECK(ctx, rt.best_start < 0.4 * c.Tp, "rests from %.4f s", rt.best_start);
}

/* Energy E = v^2/2 + w0^2 u^2/2 with xi = 0 after the pulse: never rises
 * across an impact for any eps, falls for eps < 1 (theta = 1/2 keeps it
 * exactly in free flight). */
typedef struct energy_track {
    double w0, Tp, prev_E, worst_rise, total_drop, E_scale;
    long impacts_seen;
} energy_track;

static int track_energy(const pd_osc_sample *s, void *ctx)
{
    energy_track *et = ctx;
    double E = 0.5 * s->v * s->v + 0.5 * et->w0 * et->w0 * s->u * s->u;
    if (s->t > et->Tp * (1 + 1e-9) && et->prev_E >= 0) {
        et->worst_rise = fmax(et->worst_rise, (E - et->prev_E) / et->E_scale);
        if (s->impulse > 0) {
            et->total_drop += et->prev_E - E;
            et->impacts_seen++;
        }
    }
    if (s->t > et->Tp * (1 + 1e-9) && et->E_scale == 0)
        et->E_scale = E;
    et->prev_E = s->t > et->Tp * (1 + 1e-9) ? E : -1;
    return 0;
}

static void test_osc_energy_across_impacts(pd_test_ctx *ctx)
{
    const double eps[] = {0.0, 0.3, 0.7, 1.0};
    for (int k = 0; k < 4; k++) {
        pd_osc c = {.pulse = PD_PULSE_SINE,
                    .dir = 1,
                    .ap = 1.0,
                    .Tp = 1.0,
                    .Pi2 = 0.6,
                    .Pi3 = 0.02,
                    .eps = eps[k],
                    .xi = 0.0};
        pd_run_opts o = pd_run_default_opts();
        pd_osc_result r;
        pd_err e;
        o.dt = c.Tp / 2000;
        o.tend = c.Tp + (eps[k] == 1.0 ? 200 : 12) * pd_osc_T0(&c); /* eps = 1: a long run */
        energy_track et = {TWO_PI / pd_osc_T0(&c), c.Tp, -1, 0, 0, 0, 0};
        CHECK(ctx, pd_osc_simulate(&c, &o, track_energy, &et, &r, &e) == PD_OK, "%s", e.msg);
        CHECK(ctx, et.impacts_seen > 0, "eps %g: impacts after the pulse", eps[k]);
        CHECK(ctx, et.worst_rise <= 1e-12, "eps %g: energy rose by %.3g (relative)", eps[k],
              et.worst_rise);
        if (eps[k] < 1)
            CHECK(ctx, et.total_drop > 1e-3 * et.E_scale, "eps %g: energy must fall (drop %.3g)",
                  eps[k], et.total_drop / et.E_scale);
        else
            CHECK(ctx, fabs(et.total_drop) <= 1e-12 * et.E_scale,
                  "eps 1: energy kept across impacts (change %.3g)", et.total_drop / et.E_scale);
    }
}

/* First impact: time and speed against the closed-form free flight,
 * error O(dt) and falling with dt. */
static void test_osc_first_impact(pd_test_ctx *ctx)
{
    pd_osc c = {.pulse = PD_PULSE_SINE,
                .dir = 1,
                .ap = 2.0,
                .Tp = 0.5,
                .Pi2 = 0.8,
                .Pi3 = 0.3,
                .eps = 0.5,
                .xi = 0.05};
    double t_star, v_star;
    CHECK(ctx, pd_osc_free_first_contact(&c, 2 * c.Tp, &t_star, &v_star) == PD_OK,
          "the free response must reach the gap");
    double et[3], ev[3];
    for (int k = 0; k < 3; k++) {
        pd_run_opts o = pd_run_default_opts();
        pd_osc_result r;
        pd_err e;
        o.dt = c.Tp / (200.0 * (1 << k));
        CHECK(ctx, pd_osc_simulate(&c, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg);
        et[k] = fabs(r.first_impact - t_star);
        ev[k] = fabs(r.first_impact_velocity - v_star);
        CHECK(ctx, et[k] <= 0.1 * o.dt, "dt %g: first impact %.9f vs exact %.9f", o.dt,
              r.first_impact, t_star);
        CHECK(ctx, ev[k] <= 0.1 * c.ap * o.dt, "dt %g: impact speed %.9f vs exact %.9f", o.dt,
              r.first_impact_velocity, v_star);
    }
    CHECK(ctx, et[2] < 0.5 * et[0] && ev[2] < 0.5 * ev[0],
          "errors must fall with dt: time %.3g -> %.3g, speed %.3g -> %.3g", et[0], et[2], ev[0],
          ev[2]);
}

/* The scalar kernel and the general one (Lemke, dense LU) agree. */
typedef struct pair_track {
    double *u;
    long n, cap;
} pair_track;

static int record_u(const pd_osc_sample *s, void *ctx)
{
    pair_track *pt = ctx;
    if (pt->n < pt->cap)
        pt->u[pt->n++] = s->u;
    return 0;
}

static void test_osc_scalar_vs_general_kernel(pd_test_ctx *ctx)
{
    enum { CAP = 8000 };
    static double ua[CAP], ub[CAP];
    pd_osc c = {.pulse = PD_PULSE_COSINE,
                .dir = -1,
                .ap = 1.0,
                .Tp = 1.0,
                .Pi2 = 1.16,
                .Pi3 = 0.02,
                .eps = 0.2,
                .xi = 0.05};
    pd_run_opts o = pd_run_default_opts();
    pd_osc_result ra, rb;
    pd_err e;
    o.dt = c.Tp / 1000;
    pair_track a = {ua, 0, CAP}, b = {ub, 0, CAP};
    CHECK(ctx, pd_osc_simulate(&c, &o, record_u, &a, &ra, &e) == PD_OK, "%s", e.msg);
    o.kernel = PD_KERNEL_GENERAL;
    CHECK(ctx, pd_osc_simulate(&c, &o, record_u, &b, &rb, &e) == PD_OK, "%s", e.msg);
    CHECK(ctx, !strcmp(ra.kernel, "scalar") && !strcmp(rb.kernel, "general"), "kernels %s %s",
          ra.kernel, rb.kernel);
    CHECK(ctx, ra.impacts == rb.impacts && ra.impacts > 0, "impacts %ld vs %ld", ra.impacts,
          rb.impacts);
    double worst = 0;
    for (long k = 0; k < a.n && k < b.n; k++)
        worst = fmax(worst, fabs(ua[k] - ub[k]));
    CHECK(ctx, a.n == b.n && worst <= 1e-13 * ra.umax, "histories differ by %.3g (umax %.3g)",
          worst, ra.umax);
}

static int count_sample(const pd_osc_sample *s, void *ctx)
{
    (void)s;
    ++*(long *)ctx;
    return 0;
}

/* The single Moreau-Jean run without a sampler (its own loop: the scalar
 * kernel's step with the measurements inline, the forces asked ahead) gives
 * the figures of the run through pd_mj_run (with a sampler) bit for bit:
 * pulses with their end's breakpoint, the harmonic excitation, the no-wall
 * twin, theta, gamma, restitution 0 and 1, and a run that blows up (theta
 * outside the stable range) with the same status, message and steps. */
static void test_osc_inline_run_matches_pd_mj(pd_test_ctx *ctx)
{
    static const struct {
        pd_pulse pulse;
        int dir, no_wall;
        double Pi2, Pi3, eps, theta, gamma;
    } cases[] = {
        {PD_PULSE_SINE, 1, 0, 0.7, 0.05, 0.5, 0.5, 0.5},
        {PD_PULSE_COSINE, -1, 0, 2.3, 0.01, 0.0, 0.5, 0.5},
        {PD_PULSE_SINE, -1, 1, 1.3, 0.05, 0.5, 0.5, 0.5},
        {PD_PULSE_HARMONIC, 1, 0, 0.5, 0.01, 1.0, 0.6, 0.0},
        {PD_PULSE_COSINE, 1, 0, 3.1, 0.0, 0.8, 1.0, 1.0},
        {PD_PULSE_SINE, 1, 0, 5.0, 1e9, 0.5, 0.0, 0.5}, /* unstable: blows up */
    };
    int failed = 0;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        pd_osc c = {.pulse = cases[k].pulse,
                    .dir = cases[k].dir,
                    .ap = 1.0,
                    .Tp = 1.0,
                    .Pi2 = cases[k].Pi2,
                    .Pi3 = cases[k].Pi3,
                    .eps = cases[k].eps,
                    .xi = 0.05};
        pd_run_opts o = pd_run_default_opts();
        pd_osc_result ra, rb;
        pd_err ea, eb;
        long samples = 0;
        o.method = PD_METHOD_MOREAU;
        o.no_wall = cases[k].no_wall;
        o.theta = cases[k].theta;
        o.gamma = cases[k].gamma;
        o.allow_unstable = 1;
        o.tend = cases[k].pulse == PD_PULSE_HARMONIC ? 30.0 : 0.0;
        if (cases[k].theta == 0.0) /* h w = 6.3: the state grows ~6x a step */
            o.dt = 0.2, o.tend = 400.0;
        int sa = pd_osc_simulate(&c, &o, NULL, NULL, &ra, &ea);
        int sb = pd_osc_simulate(&c, &o, count_sample, &samples, &rb, &eb);
        failed += sa != PD_OK;
        ra.cpu_s = rb.cpu_s = 0.0;
        CHECK(ctx, sa == sb && !strcmp(ra.kernel, "scalar") && !strcmp(rb.kernel, "scalar"),
              "case %zu: status %d vs %d, kernels %s %s", k, sa, sb, ra.kernel, rb.kernel);
        ra.kernel = rb.kernel;
        CHECK(ctx, !memcmp(&ra, &rb, sizeof ra),
              "case %zu: figures differ (umax %.17g vs "
              "%.17g, impacts %ld vs %ld, steps %ld vs %ld)",
              k, ra.umax, rb.umax, ra.impacts, rb.impacts, ra.steps, rb.steps);
        CHECK(ctx, sa == PD_OK ? samples == ra.steps + 1 : !strcmp(ea.msg, eb.msg),
              "case %zu: %ld samples for %ld steps; messages '%s' '%s'", k, samples, ra.steps,
              sa ? ea.msg : "", sa ? eb.msg : "");
    }
    CHECK(ctx, failed == 1, "%d runs failed (the unstable one expected)", failed);
}

/* Defaults a user expects: dt = min(Tp, T0)/2000, tend = Tp + 2 T0. */
static void test_osc_defaults_and_checks(pd_test_ctx *ctx)
{
    pd_osc c = {.pulse = PD_PULSE_SINE,
                .dir = 1,
                .ap = 1.0,
                .Tp = 0.3,
                .Pi2 = 0.1,
                .Pi3 = 0.4,
                .eps = 0.6,
                .xi = 0.05};
    pd_osc_result r;
    pd_err e;
    CHECK_NEAR(ctx, pd_osc_default_dt(&c), 0.3 / 2000, 1e-18);
    CHECK_NEAR(ctx, pd_osc_default_tend(&c), 0.3 + 2 * 3.0, 1e-12);
    CHECK(ctx, pd_osc_simulate(&c, NULL, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg);
    CHECK(ctx, r.steps == 42000, "steps %ld", r.steps);
    pd_osc bad = c;
    bad.eps = 1.5;
    CHECK(ctx, pd_osc_simulate(&bad, NULL, NULL, NULL, &r, &e) == PD_EINVAL && strstr(e.msg, "eps"),
          "%s", e.msg);
    bad = c;
    bad.Pi3 = -0.1;
    CHECK(ctx, pd_osc_check(&bad, &e) == PD_EINVAL && strstr(e.msg, "gap"), "%s", e.msg);
    bad = c;
    bad.xi = 1.0;
    CHECK(ctx, pd_osc_check(&bad, &e) == PD_EINVAL && strstr(e.msg, "xi"), "%s", e.msg);
    pd_osc h = c;
    h.pulse = PD_PULSE_HARMONIC;
    double tend = pd_osc_default_tend(&h);
    CHECK(ctx, tend > 20 * h.Tp && pd_osc_measure_start(&h, tend) > 0.0,
          "harmonic: transient then window (tend %g)", tend);
}

void suite_oscillator(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_osc_free_flight_order);
    PD_RUN(ctx, test_osc_self_similarity);
    PD_RUN(ctx, test_osc_penetration_is_order_dt);
    PD_RUN(ctx, test_osc_persistent_contact);
    PD_RUN(ctx, test_osc_energy_across_impacts);
    PD_RUN(ctx, test_osc_first_impact);
    PD_RUN(ctx, test_osc_scalar_vs_general_kernel);
    PD_RUN(ctx, test_osc_inline_run_matches_pd_mj);
    PD_RUN(ctx, test_osc_defaults_and_checks);
}
