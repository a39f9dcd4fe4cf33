/* test_demand.c — the demand parameters (pd_problems.h, "demand
 * parameters"): the SDOF's peak absolute acceleration against its sampled
 * history and the closed-form response, a building's base shear against
 * the floors' inertia forces from the kinematics, Moreau–Jean's demands
 * converging to the event-driven reference's, the penalty's peak contact
 * force against the impulse and the contact time (oscillator and scene),
 * the other results untouched by measuring the demands, the scene field
 * storey_heights and the flags refused, and the peak of a cubic between two
 * states against closed forms. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "demand.h"
#include "pd_problems.h"
#include "pd_test.h"

/* ---- (a) the SDOF without contact --------------------------------------------- */

/* The largest |2 xi w0 u' + w0^2 u| over the samples (SI). */
typedef struct osc_peak {
    double C, K, peak;
} osc_peak;

/* Per step: the peak of |C v + K u| (the shear per unit mass). */
static int osc_peak_sample(const pd_osc_sample *s, void *ctx)
{
    osc_peak *p = ctx;
    double f = p->C * s->v + p->K * s->u;
    p->peak = fmax(p->peak, fabs(f));
    return 0;
}

/* The closed form's |a_abs(t)| = |2 xi w0 u' + w0^2 u| (pd_osc_free_exact). */
static double exact_abs_acc(const pd_osc *c, double t)
{
    double u, v, w0 = 2.0 * PD_PI / pd_osc_T0(c);
    pd_osc_free_exact(c, t, &u, &v);
    return fabs(2.0 * c->xi * w0 * v + w0 * w0 * u);
}

/* Its largest value on [0, tend]: a grid of 20000 points per period, then a
 * golden-section search around the best one (the closed form to rounding). */
static double exact_peak(const pd_osc *c, double tend)
{
    double T = fmin(pd_osc_T0(c), c->Tp), h = T / 20000.0, best = 0.0, tb = 0.0;
    for (double t = 0.0; t <= tend; t += h) {
        double a = exact_abs_acc(c, t);
        if (a > best) {
            best = a;
            tb = t;
        }
    }
    double lo = fmax(0.0, tb - h), hi = tb + h, g = 0.5 * (sqrt(5.0) - 1.0);
    for (int it = 0; it < 100; it++) {
        double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
        if (exact_abs_acc(c, x1) > exact_abs_acc(c, x2))
            hi = x2;
        else
            lo = x1;
    }
    return fmax(best, exact_abs_acc(c, 0.5 * (lo + hi)));
}

/* Without the wall: every method's acc_max is the peak of its own history
 * (Moreau–Jean: exactly, the same formula on the steps), and close to the
 * closed form: the exact reference's grid and cubic to 1e-8 (the cubic
 * Hermite's error (w h)^4 / 384 at 2000 points per period is 4e-14; the
 * pulse's end is a kink of a_abs' rate), the penalty's rk8pd to 1e-4 (the
 * same cubic between its accepted steps, some T/20 long: (w h)^4 / 384 is
 * 4e-5; 2.7e-5 measured), Newmark's fixed steps dt to 1e-3, Moreau–Jean to its second-order error: the discrete maximum
 * (w dt)^2 / 8 plus the midpoint rule's phase drift 2 pi N (w dt)^2 / 12
 * over N periods, and halving dt divides its error by about 4. */
static void test_demand_sdof_closed_form(pd_test_ctx *ctx)
{
    pd_osc c = pd_osc_default();
    c.ap = 3.0;
    c.Tp = 0.5;
    pd_osc_set_T0(&c, 0.8);
    c.xi = 0.05;
    pd_run_opts o = pd_run_default_opts();
    o.no_wall = 1;
    pd_err e;
    pd_osc_result r;
    double tend = pd_osc_default_tend(&c), want = exact_peak(&c, tend);
    double w0 = 2.0 * PD_PI / pd_osc_T0(&c);
    static const pd_method methods[] = {PD_METHOD_EVENT, PD_METHOD_PENALTY, PD_METHOD_NEWMARK};
    static const double tol[] = {1e-8, 1e-4, 1e-3};
    for (int k = 0; k < 3; k++) {
        o.method = methods[k];
        if (!CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &r, &e) == PD_OK, "%s: %s",
                   pd_method_name(o.method), e.msg))
            return;
        CHECK(ctx, fabs(r.acc_max - want) <= tol[k] * want,
              "%s: acc_max %.12g vs the closed form's %.12g (rel %.3g > %.3g)",
              pd_method_name(o.method), r.acc_max, want, fabs(r.acc_max - want) / want, tol[k]);
    }
    double err[2];
    for (int k = 0; k < 2; k++) {
        osc_peak p = {.C = 2.0 * c.xi * w0, .K = w0 * w0, .peak = 0.0};
        o.method = PD_METHOD_MOREAU;
        o.dt = pd_osc_default_dt(&c) / (1 << k);
        if (!CHECK(ctx, pd_osc_run(&c, &o, osc_peak_sample, &p, &r, &e) == PD_OK, "moreau: %s",
                   e.msg))
            return;
        CHECK(ctx, fabs(r.acc_max - p.peak) <= 1e-12 * p.peak,
              "moreau: acc_max %.17g vs its history's %.17g", r.acc_max, p.peak);
        double w = 2.0 * PD_PI / fmin(c.Tp, pd_osc_T0(&c)), wh2 = (w * o.dt) * (w * o.dt);
        double bound = wh2 / 8.0 + 2.0 * PD_PI * (tend / pd_osc_T0(&c)) * wh2 / 12.0;
        err[k] = fabs(r.acc_max - want) / want;
        CHECK(ctx, err[k] <= bound, "moreau dt %g: acc_max %.12g vs %.12g (rel %.3g > %.3g)", o.dt,
              r.acc_max, want, err[k], bound);
    }
    CHECK(ctx, err[1] < 0.4 * err[0] || err[0] < 1e-9,
          "moreau: halving dt took the error from %.3g to %.3g only", err[0], err[1]);
    /* with the wall the SDOF's shear is the same quantity, the sampled peak;
     * its a_abs, with the wall's held force in it, is the reference's (3.22494
     * m/s^2, its peak free; a held step's P / h gave 4.249) */
    o = pd_run_default_opts();
    o.method = PD_METHOD_MOREAU;
    osc_peak p = {.C = 2.0 * c.xi * w0, .K = w0 * w0, .peak = 0.0};
    pd_osc_result ref;
    pd_run_opts oe = pd_run_default_opts();
    oe.method = PD_METHOD_EVENT;
    if (CHECK(ctx, pd_osc_run(&c, &o, osc_peak_sample, &p, &r, &e) == PD_OK, "%s", e.msg) &&
        CHECK(ctx, pd_osc_run(&c, &oe, NULL, NULL, &ref, &e) == PD_OK, "event: %s", e.msg))
        CHECK(ctx,
              r.impacts > 0 && fabs(r.shear_max - p.peak) <= 1e-12 * p.peak &&
                  fabs(r.acc_max - ref.acc_max) <= 1e-5 * ref.acc_max,
              "moreau with the wall: %ld impacts, shear_max %.17g vs %.17g, acc_max %.12g vs "
              "the reference's %.12g",
              r.impacts, r.shear_max, p.peak, r.acc_max, ref.acc_max);
}

/* Held on the wall a_abs is the ground's acceleration (x'' = 0): a flexible
 * SDOF (T0 4 s) 1 mm from the wall, eps 0, under a sine pulse (ap 3, Tp 0.5)
 * rests on the wall through the pulse's peak at Tp / 4, its free shear
 * below 0.7: the peak of a_abs is ap, in every method that has the hold --
 * the reference between its samples (the cubic of (f, f'): 3e-8; its
 * samples alone gave 2.99963), Moreau-Jean from the held force of the
 * step's state (P / h left it 2.5e-6 short at the default dt), the penalty
 * methods from the same rigid held force, their element's left out (0.696,
 * the free shear, without it). */
static void test_demand_sdof_held_peak(pd_test_ctx *ctx)
{
    pd_osc c = pd_osc_default();
    c.ap = 3.0;
    c.Tp = 0.5;
    pd_osc_set_T0(&c, 4.0);
    c.xi = 0.05;
    c.eps = 0.0;
    c.Pi3 = 0.001;
    static const pd_method methods[] = {PD_METHOD_EVENT, PD_METHOD_MOREAU, PD_METHOD_MOREAU,
                                        PD_METHOD_PENALTY, PD_METHOD_NEWMARK};
    static const double dts[] = {0.0, 0.0, 1e-4, 0.0, 0.0};
    for (int k = 0; k < 5; k++) {
        pd_run_opts o = pd_run_default_opts();
        pd_osc_result r;
        pd_err e;
        o.method = methods[k];
        o.dt = dts[k];
        if (CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &r, &e) == PD_OK, "%s: %s",
                  pd_method_name(o.method), e.msg))
            CHECK(ctx,
                  r.contact_time > 0.1 && r.shear_max < 0.25 * c.ap &&
                      fabs(r.acc_max - c.ap) <= 1e-6 * c.ap,
                  "%s (dt %g): acc_max %.12g, want ap = %g (held %.3g s, shear_max %.3g)",
                  pd_method_name(o.method), o.dt, r.acc_max, c.ap, r.contact_time, r.shear_max);
    }
}

/* ---- (b) a building without contact: dynamic equilibrium ---------------------- */

/* The history of a 3-storey building on the output grid. */
typedef struct building_hist {
    int n;
    long rows, cap;
    double *t, *x, *v;
} building_hist;

static int keep_building(const pd_scene_sample *s, void *ctx)
{
    building_hist *h = ctx;
    if (h->rows >= h->cap)
        return 1;
    h->t[h->rows] = s->t;
    memcpy(h->x + h->rows * h->n, s->x, (size_t)h->n * sizeof(double));
    memcpy(h->v + h->rows * h->n, s->v, (size_t)h->n * sizeof(double));
    h->rows++;
    return 0;
}

/* Rayleigh damping (its mass-proportional part too): at every sample of the
 * exact reference, the floors' absolute accelerations from the kinematics,
 * a_i = dv_i/dt (central differences) + a_g, with a_g = -f(t) the ground's
 * (f the effective acceleration, +ap sin(wp t) over the pulse), balance the
 * restoring forces: m_i a_i = -(C v + K x)_i, so the base shear
 * sum_i (C v + K x)_i = -sum_i m_i a_i; and the peaks acc_max, shear_max
 * are those of the history.  Central differences of exact states err by
 * (w h)^2 / 6 of the highest mode (2e-5 here); the grid's peaks by
 * (w h)^2 / 8: 2e-4 of each peak. */
static void test_demand_base_shear_equilibrium(pd_test_ctx *ctx)
{
    pd_scene_excitation x = {.pulse = PD_PULSE_SINE, .dir = 1, .ap = 2.0, .Tp = 0.6};
    pd_scene *sc = pd_scene_new(&x);
    double m[3] = {2e5, 1.8e5, 1.5e5}, k[3] = {3e8, 2.5e8, 2e8};
    pd_err e;
    if (!CHECK(ctx,
               sc && !pd_scene_add_building(sc, "B", 3, m, k, 0.05, &e) &&
                   !pd_scene_set_damping(sc, PD_DAMPING_RAYLEIGH, 1, 3, &e) &&
                   !pd_scene_finish(sc, &e),
               "building: %s", sc ? e.msg : "out of memory")) {
        pd_scene_free(sc);
        return;
    }
    const pd_structure *st = &sc->st[0];
    CHECK(ctx, st->alpha > 0.0 && st->beta > 0.0, "Rayleigh: alpha %g, beta %g", st->alpha,
          st->beta);
    pd_run_opts o = pd_run_default_opts();
    o.method = PD_METHOD_EVENT;
    o.dt = st->Tmin / 400.0;
    o.tend = 1.5;
    pd_scene_result r;
    building_hist h = {.n = 3, .cap = (long)(o.tend / o.dt) + 8};
    h.t = malloc((size_t)h.cap * sizeof(double));
    h.x = malloc((size_t)h.cap * 3 * sizeof(double));
    h.v = malloc((size_t)h.cap * 3 * sizeof(double));
    int ok = h.t && h.x && h.v && !pd_scene_result_alloc(sc, &r, &e);
    if (ok && !CHECK(ctx, pd_scene_run(sc, &o, keep_building, &h, &r, &e) == PD_OK, "%s", e.msg))
        pd_scene_result_free(&r), ok = 0;
    if (ok) {
        double worst = 0.0, scale = 0.0, apk[3] = {0, 0, 0}, vpk = 0.0, wp = 2.0 * PD_PI / x.Tp;
        for (long j = 1; j + 1 < h.rows; j++) {
            double hh = h.t[j + 1] - h.t[j - 1], t = h.t[j];
            double f = t <= x.Tp ? x.ap * sin(wp * t) : 0.0, V = 0.0, inertia = 0.0;
            const double *xs = h.x + j * 3, *vs = h.v + j * 3;
            for (int i = 0; i < 3; i++) {
                double a = (h.v[(j + 1) * 3 + i] - h.v[(j - 1) * 3 + i]) / hh - f;
                double kx = k[i] * (xs[i] - (i ? xs[i - 1] : 0.0)) -
                            (i < 2 ? k[i + 1] * (xs[i + 1] - xs[i]) : 0.0);
                double kv = k[i] * (vs[i] - (i ? vs[i - 1] : 0.0)) -
                            (i < 2 ? k[i + 1] * (vs[i + 1] - vs[i]) : 0.0);
                V += st->alpha * m[i] * vs[i] + kx + st->beta * kv; /* (C v + K x)_i */
                inertia += m[i] * a;
                apk[i] = fmax(apk[i], fabs(a));
            }
            worst = fmax(worst, fabs(V + inertia));
            scale = fmax(scale, fabs(V));
            vpk = fmax(vpk, fabs(V));
        }
        CHECK(ctx, h.rows > 1000 && worst <= 1e-4 * scale,
              "base shear vs the inertia forces: worst |V + sum m a| %.4g of peak %.4g "
              "(%ld samples)",
              worst, scale, h.rows);
        CHECK(ctx, fabs(r.shear_max[0] - vpk) <= 2e-4 * vpk,
              "base shear peak %.10g vs the history's %.10g", r.shear_max[0], vpk);
        for (int i = 0; i < 3; i++)
            CHECK(ctx, fabs(r.acc_max[i] - apk[i]) <= 2e-4 * apk[i],
                  "floor %d: acc_max %.10g vs the kinematics' %.10g", i + 1, r.acc_max[i], apk[i]);
        /* every method: the same peaks to its own accuracy */
        static const pd_method others[] = {PD_METHOD_MOREAU, PD_METHOD_EVENT_GENERAL,
                                           PD_METHOD_PENALTY, PD_METHOD_NEWMARK};
        pd_scene_result q;
        for (int k2 = 0; k2 < 4 && !pd_scene_result_alloc(sc, &q, &e); k2++) {
            pd_run_opts oo = o;
            oo.method = others[k2];
            if (CHECK(ctx, pd_scene_run(sc, &oo, NULL, NULL, &q, &e) == PD_OK, "%s: %s",
                      pd_method_name(oo.method), e.msg))
                for (int i = 0; i < 3; i++)
                    CHECK(ctx,
                          fabs(q.acc_max[i] - r.acc_max[i]) <= 1e-4 * r.acc_max[i] &&
                              fabs(q.shear_max[i] - r.shear_max[i]) <= 1e-4 * r.shear_max[i],
                          "%s floor %d: acc %.10g vs %.10g, shear %.10g vs %.10g",
                          pd_method_name(oo.method), i + 1, q.acc_max[i], r.acc_max[i],
                          q.shear_max[i], r.shear_max[i]);
            pd_scene_result_free(&q);
        }
        pd_scene_result_free(&r);
    }
    free(h.t);
    free(h.x);
    free(h.v);
    pd_scene_free(sc);
}

/* ---- (c) Moreau–Jean converging to the reference on a pounding scene ----------- */

/* A 2-storey building and an SDOF pounding at floor 2, a wall at the right:
 * Moreau–Jean's acc_max and shear_max tend to the event-driven
 * reference's as dt shrinks: their largest relative difference over the
 * floors falls with every refinement of dt by 4 (1e-4, 7e-6, 4e-7, 2e-8
 * measured: second order) to below 1e-6 at the finest. */
static void test_demand_moreau_converges(pd_test_ctx *ctx)
{
    pd_scene_excitation x = {.pulse = PD_PULSE_SINE, .dir = 1, .ap = 3.0, .Tp = 0.5};
    pd_scene *sc = pd_scene_new(&x);
    double m[2] = {1e5, 1e5}, k[2] = {8e7, 6e7};
    pd_err e;
    if (!CHECK(ctx,
               sc && !pd_scene_add_building(sc, "B", 2, m, k, 0.05, &e) &&
                   !pd_scene_add_sdof(sc, "S", 0.4, 0.05, 1e5, &e) &&
                   !pd_scene_add_contact(sc, 0, 2, 1, 1, 0.01, 0.6, 0, &e) &&
                   !pd_scene_finish(sc, &e),
               "scene: %s", sc ? e.msg : "out of memory")) {
        pd_scene_free(sc);
        return;
    }
    sc->tend = 2.0;
    pd_run_opts o = pd_run_default_opts();
    pd_scene_result ref, r;
    o.method = PD_METHOD_EVENT;
    o.dt = 1e-4;
    if (pd_scene_result_alloc(sc, &ref, &e) ||
        !CHECK(ctx, pd_scene_run(sc, &o, NULL, NULL, &ref, &e) == PD_OK, "event: %s", e.msg)) {
        pd_scene_result_free(&ref);
        pd_scene_free(sc);
        return;
    }
    CHECK(ctx, ref.impacts[0] > 0, "the reference has no impact");
    enum { NDT = 4 };
    double err[NDT];
    o.method = PD_METHOD_MOREAU;
    for (int j = 0; j < NDT; j++) {
        o.dt = 1.6e-3 / (1 << (2 * j)) * 1.0;
        err[j] = 0.0;
        if (pd_scene_result_alloc(sc, &r, &e) ||
            !CHECK(ctx, pd_scene_run(sc, &o, NULL, NULL, &r, &e) == PD_OK, "moreau: %s", e.msg))
            break;
        for (int i = 0; i < sc->n; i++)
            err[j] = fmax(err[j], fmax(fabs(r.acc_max[i] - ref.acc_max[i]) / ref.acc_max[i],
                                       fabs(r.shear_max[i] - ref.shear_max[i]) / ref.shear_max[i]));
        pd_scene_result_free(&r);
    }
    int falls = 1;
    for (int j = 1; j < NDT; j++)
        falls &= err[j] < 0.25 * err[j - 1];
    CHECK(ctx, falls && err[NDT - 1] < 1e-6,
          "moreau's demands against the reference: rel. error %.3g at dt %g, %.3g at %g", err[0],
          1.6e-3, err[NDT - 1], 1.6e-3 / (1 << (2 * (NDT - 1))));
    pd_scene_result_free(&ref);
    pd_scene_free(sc);
}

/* ---- (d) the penalty's peak force against the impulse ------------------------- */

/* One impact of the oscillator on the wall, Kelvin-Voigt elements: the peak
 * force is at least the mean impulse / contact time (always); for a nearly
 * elastic element (eps 0.95: its force close to the half sine of the
 * undamped spring) within 2 % of the half sine's pi I / (2 td) with td the
 * measured contact time, and for eps 0.5 (the dashpot's force c v at the
 * start skews the pulse: its peak comes earlier and higher) within 15 %
 * (8.6 % measured); the equivalent force is pi I / (2 td) for the td given. */
static void test_demand_penalty_force(pd_test_ctx *ctx)
{
    static const double eps[] = {0.5, 0.95}, tol[] = {0.15, 0.02};
    for (int k = 0; k < 2; k++) {
        pd_osc c = pd_osc_default();
        c.eps = eps[k];
        c.Pi3 = 0.6;
        pd_run_opts o = pd_run_default_opts();
        o.method = PD_METHOD_PENALTY;
        o.tend = 0.9; /* the first impact only */
        o.contact_duration = 0.01;
        pd_osc_result r;
        pd_err e;
        if (!CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg))
            return;
        double td = r.contact_time, mean = r.max_impulse / td;
        double half = pd_equivalent_force(r.max_impulse, td);
        CHECK(ctx, r.impacts == 1 && r.force_max >= mean,
              "eps %g: %ld impacts, peak force %.6g below the mean %.6g", c.eps, r.impacts,
              r.force_max, mean);
        CHECK(ctx, fabs(r.force_max - half) <= tol[k] * half,
              "eps %g: peak force %.6g vs the half sine's %.6g", c.eps, r.force_max, half);
        CHECK_NEAR(ctx, r.force_equiv, 0.5 * PD_PI * r.max_impulse / 0.01, 1e-12 * r.force_equiv);
        CHECK(ctx, r.contact_duration == 0.01, "td %g", r.contact_duration);
    }
}

/* The same on a scene's general path (two SDOFs, eps 0.65, the first impact
 * only): penalty's peak force within 10 % of the half sine of its measured
 * contact time (2.7 % measured), Newmark's at least the mean (its contact
 * time counts whole steps). */
static void test_demand_penalty_force_scene(pd_test_ctx *ctx)
{
    pd_scene *sc = NULL;
    pd_err e;
    if (!CHECK(ctx, pd_scene_load("examples/scenes/two-sdof.json", &sc, &e) == PD_OK, "%s", e.msg))
        return;
    static const pd_method methods[] = {PD_METHOD_PENALTY, PD_METHOD_NEWMARK};
    for (int k = 0; k < 2; k++) {
        pd_run_opts o = pd_run_default_opts();
        pd_scene_result r;
        o.method = methods[k];
        o.tend = 0.6;
        if (pd_scene_result_alloc(sc, &r, &e) ||
            !CHECK(ctx, pd_scene_run(sc, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg)) {
            pd_scene_result_free(&r);
            break;
        }
        double mean = r.max_impulse[0] / r.contact_time[0];
        double half = pd_equivalent_force(r.max_impulse[0], r.contact_time[0]);
        CHECK(ctx,
              r.impacts[0] == 1 && r.force_max[0] >= mean &&
                  (k || fabs(r.force_max[0] - half) <= 0.1 * half),
              "%s: %ld impacts, peak %.6g, mean %.6g, half sine %.6g", pd_method_name(o.method),
              r.impacts[0], r.force_max[0], mean, half);
        pd_scene_result_free(&r);
    }
    pd_scene_free(sc);
}

/* Measuring the demands changes nothing else: every method on a scene and on
 * the oscillator gives, with and without them (pd_run_opts.no_demands: the
 * reference's output grid and impact reports off), the same extremes,
 * impacts, impulses and steps to the bit; without them the peaks are NaN. */
static void test_demand_leaves_results_alone(pd_test_ctx *ctx)
{
    pd_scene *sc = NULL;
    pd_err e;
    if (!CHECK(ctx, pd_scene_load("examples/scenes/three-sdof.json", &sc, &e) == PD_OK, "%s",
               e.msg))
        return;
    static const pd_method methods[] = {PD_METHOD_MOREAU, PD_METHOD_EVENT, PD_METHOD_PENALTY,
                                        PD_METHOD_NEWMARK, PD_METHOD_EVENT_GENERAL};
    for (int k = 0; k < 5; k++) {
        pd_scene_result r[2];
        int ok = 1;
        for (int off = 0; off < 2; off++) {
            pd_run_opts o = pd_run_default_opts();
            o.method = methods[k];
            o.no_demands = off;
            ok &= !pd_scene_result_alloc(sc, &r[off], &e) &&
                  CHECK(ctx, pd_scene_run(sc, &o, NULL, NULL, &r[off], &e) == PD_OK, "%s", e.msg);
        }
        size_t n = (size_t)sc->n * sizeof(double), m = (size_t)sc->ncontact * sizeof(double);
        if (ok)
            CHECK(ctx,
                  !memcmp(r[0].umax, r[1].umax, n) && !memcmp(r[0].drift, r[1].drift, n) &&
                      !memcmp(r[0].max_impulse, r[1].max_impulse, m) &&
                      !memcmp(r[0].approach, r[1].approach, m) &&
                      !memcmp(r[0].impacts, r[1].impacts, (size_t)sc->ncontact * sizeof(long)) &&
                      r[0].steps == r[1].steps && isnan(r[1].acc_max[0]) &&
                      isnan(r[1].shear_max[0]) && r[0].acc_max[0] > 0.0,
                  "%s: the results differ with and without the demands",
                  pd_method_name(methods[k]));
        pd_scene_result_free(&r[0]);
        pd_scene_result_free(&r[1]);
    }
    pd_scene_free(sc);
    pd_osc c = pd_osc_default();
    for (int k = 0; k < 4; k++) {
        pd_osc_result r[2];
        for (int off = 0; off < 2; off++) {
            pd_run_opts o = pd_run_default_opts();
            o.method = methods[k];
            o.no_demands = off;
            CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &r[off], &e) == PD_OK, "%s", e.msg);
        }
        CHECK(ctx,
              r[0].umax == r[1].umax && r[0].impacts == r[1].impacts &&
                  r[0].max_impulse == r[1].max_impulse && r[0].steps == r[1].steps &&
                  r[0].contact_time == r[1].contact_time && isnan(r[1].acc_max) &&
                  r[0].acc_max > 0.0,
              "oscillator %s: the results differ with and without the demands",
              pd_method_name(methods[k]));
    }
}

/* ---- (e) storey heights and drift ratios; bad input refused -------------------- */

static void scratch_file(const char *dir, const char *name, const char *text, char *path,
                         size_t cap)
{
    snprintf(path, cap, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

#define EXC "\"excitation\": {\"pulse\": \"sine\", \"ap\": 4, \"Tp\": 0.3},\n"
#define BLD(h)                                                                                     \
    "\"structures\": [{\"name\": \"A\", \"T0\": 1}, {\"name\": \"B\", \"storeys\": 3, "            \
    "\"mass\": 1e5, \"T0\": 0.5, \"storey_heights\": " h "}]\n"

/* The heights of a file: drift_ratio = drift / height; a number for every
 * storey; without the field PD_STOREY_HEIGHT. */
static void test_demand_storey_heights(pd_test_ctx *ctx)
{
    char dir[] = "/tmp/pd_demandXXXXXX", path[256];
    if (!mkdtemp(dir))
        return;
    static const char *const given[] = {"[4.5, 3.2, 3.0]", "3.5"};
    static const double h[2][3] = {{4.5, 3.2, 3.0}, {3.5, 3.5, 3.5}};
    for (int k = 0; k < 2; k++) {
        char text[512];
        snprintf(text, sizeof text, "{\n" EXC BLD("%s") "}\n", given[k]);
        scratch_file(dir, "h.json", text, path, sizeof path);
        pd_scene *sc = NULL;
        pd_scene_result r;
        pd_err e;
        if (!CHECK(ctx, pd_scene_load(path, &sc, &e) == PD_OK, "%s", e.msg))
            continue;
        if (!pd_scene_result_alloc(sc, &r, &e) &&
            CHECK(ctx, pd_scene_run(sc, NULL, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg)) {
            CHECK(ctx, r.drift_ratio[0] == r.drift[0] / PD_STOREY_HEIGHT,
                  "the SDOF's drift ratio %g: not drift / %g", r.drift_ratio[0], PD_STOREY_HEIGHT);
            for (int i = 0; i < 3; i++)
                CHECK(ctx,
                      sc->st[1].height[i] == h[k][i] &&
                          r.drift_ratio[1 + i] == r.drift[1 + i] / h[k][i],
                      "%s: storey %d height %g, drift ratio %g", given[k], i + 1,
                      sc->st[1].height[i], r.drift_ratio[1 + i]);
        }
        pd_scene_result_free(&r);
        /* a copy keeps them */
        pd_scene *cp = pd_scene_copy(sc);
        CHECK(ctx, cp && cp->st[1].height[2] == h[k][2], "the copy lost the heights");
        pd_scene_free(cp);
        pd_scene_free(sc);
    }
    pd_test_rm_dir(dir);
}

/* The CLI refuses bad heights naming the field, bad --contact-duration and
 * --height, with exit 2, one line and no output file. */
static void test_demand_cli_refusals(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_demandXXXXXX";
    if (!mkdtemp(dir))
        return;
    static const struct {
        const char *name, *heights, *want;
    } bad[] = {
        {"negative", "[3, -1, 3]", "structures[1].storey_heights[1]: the storey height must be"},
        {"zero", "0", "structures[1].storey_heights: the storey height must be"},
        {"length", "[3, 3]", "structures[1].storey_heights: 2 heights for 3 storeys"},
        {"type", "\"tall\"", "structures[1].storey_heights: expected a non-empty array"},
        {"element", "[3, \"x\", 3]", "structures[1].storey_heights[1]: expected a number"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char text[512], path[256], out[256], fname[64];
        proc_out r;
        snprintf(text, sizeof text, "{\n" EXC BLD("%s") "}\n", bad[k].heights);
        snprintf(fname, sizeof fname, "%s.json", bad[k].name);
        scratch_file(dir, fname, text, path, sizeof path);
        snprintf(out, sizeof out, "%s/out-%s.h5", dir, bad[k].name);
        const char *args[] = {"simulate", "--scene", path, "-o", out, NULL};
        pd_test_pound(ctx, args, &r);
        int lines = 0;
        for (const char *p = r.err; p && *p; p++)
            lines += *p == '\n';
        CHECK(ctx,
              r.status == 2 && lines == 1 && r.err && strstr(r.err, bad[k].want) &&
                  access(out, F_OK) != 0,
              "%s: exit %d, %d lines: %s", bad[k].name, r.status, lines, r.err ? r.err : "");
        pd_test_proc_free(&r);
    }
    static const struct {
        const char *flag, *value, *want;
    } flags[] = {{"--contact-duration", "-1", "--contact-duration: must be a finite number > 0"},
                 {"--contact-duration", "0", "--contact-duration: must be a finite number > 0"},
                 {"--height", "0", "--height: the storey height must be"},
                 {"--height", "inf", "--height"}};
    for (size_t k = 0; k < sizeof flags / sizeof flags[0]; k++) {
        char out[256];
        proc_out r;
        snprintf(out, sizeof out, "%s/out-flag%zu.csv", dir, k);
        const char *args[] = {"simulate", flags[k].flag, flags[k].value, "-o", out, NULL};
        pd_test_pound(ctx, args, &r);
        CHECK(ctx, r.status == 2 && r.err && strstr(r.err, flags[k].want) && access(out, F_OK) != 0,
              "%s %s: exit %d: %s", flags[k].flag, flags[k].value, r.status, r.err ? r.err : "");
        pd_test_proc_free(&r);
    }
    pd_test_rm_dir(dir);
}

/* ---- the peak between two states ------------------------------------------------ */

/* pd_demand_cubic_peak against cubics whose turning points are known: p
 * given by its values and slopes at the ends of [0, h] is the cubic itself,
 * so the peak is max |p| at the roots of p' inside (0, h), in closed form.
 * The function forms the Hermite coefficients from the four data (a few
 * roundings each, their sizes those of p) and the roots from them by the
 * stable quadratic formula: 1e-12 relative leaves the roundings room and
 * no wrong root (a wrong root's value differs here by percents).
 *   - p' = 3 (s - 0.5)(s - 1.5) on h = 2: both turns inside, p(0.5) =
 *     -0.3, p(1.5) = -0.8: the peak 0.8 is the second root's;
 *   - the same reflected (p -> -p, the roots' order swapped by s -> h - s);
 *   - p = 3 + 2 (s - 1/4)^2 on h = 1 (A = 0 exactly: p' linear, the
 *     degenerate branch): the peak 3 at s = 1/4; with the turn at s = 1.5
 *     past h = 1: none inside, 0;
 *   - p' = (s - 1)^2 + 1 > 0 (no real turn): 0. */
static double cubic_p(double p0, double alpha, double r1, double r2, double s)
{
    return p0 + alpha * (s * s * s / 3.0 - 0.5 * (r1 + r2) * s * s + r1 * r2 * s);
}

static double cubic_dp(double alpha, double r1, double r2, double s)
{
    return alpha * (s - r1) * (s - r2);
}

static void test_demand_cubic_peak(pd_test_ctx *ctx)
{
    const double tol = 1e-12;
    /* two turns inside */
    double h = 2.0, p0 = -0.8, al = 3.0, r1 = 0.5, r2 = 1.5;
    double want = fmax(fabs(cubic_p(p0, al, r1, r2, r1)), fabs(cubic_p(p0, al, r1, r2, r2)));
    double got = pd_demand_cubic_peak(cubic_p(p0, al, r1, r2, 0.0), cubic_dp(al, r1, r2, 0.0),
                                      cubic_p(p0, al, r1, r2, h), cubic_dp(al, r1, r2, h), h);
    CHECK(ctx, fabs(want - 0.8) <= 1e-15 && fabs(got - want) <= tol * want,
          "cubic, turns at 0.5 and 1.5: peak %.17g, closed form %.17g", got, want);
    /* reflected: q(s) = -p(h - s), its slopes q'(s) = p'(h - s) */
    got = pd_demand_cubic_peak(-cubic_p(p0, al, r1, r2, h), cubic_dp(al, r1, r2, h),
                               -cubic_p(p0, al, r1, r2, 0.0), cubic_dp(al, r1, r2, 0.0), h);
    CHECK(ctx, fabs(got - want) <= tol * want, "reflected cubic: peak %.17g, closed form %.17g",
          got, want);
    /* p' linear: p = 3 + 2 (s - r)^2 on h = 1 */
    for (int k = 0; k < 2; k++) {
        double r = k ? 1.5 : 0.25, b = 2.0, c0 = 3.0, h1 = 1.0;
        double f0 = c0 + b * r * r, f1 = c0 + b * (h1 - r) * (h1 - r);
        double d0 = -2.0 * b * r, d1 = 2.0 * b * (h1 - r);
        got = pd_demand_cubic_peak(f0, d0, f1, d1, h1);
        want = k ? 0.0 : c0;
        CHECK(ctx, fabs(got - want) <= tol * c0,
              "quadratic, turn at s = %g on [0, 1]: peak %.17g, expected %.17g", r, got, want);
    }
    /* no real turn: p' = (s - 1)^2 + 1 = s^2 - 2 s + 2, p = s^3 / 3 - s^2 + 2 s - 1 */
    got = pd_demand_cubic_peak(-1.0, 2.0, 8.0 / 3.0 - 4.0 + 4.0 - 1.0, 2.0, 2.0);
    CHECK(ctx, got == 0.0, "monotone cubic: peak %.17g, expected 0", got);
}

/* An SDOF's base shear is its inertia: V = k u + c u' = -m a_abs at every
 * instant (Rayleigh damping, its mass part included), so its peaks are
 * shear_max = m acc_max to rounding whatever the method, the steps or the
 * cubic interpolation between them (the rates obey the same identity).  Two
 * SDOFs (different masses, periods, damping) in a scene whose contacts
 * never close (gaps of a metre): Moreau–Jean at fixed steps, to rtol 1e-4,
 * and the exact reference, 1e-12 relative. */
static void test_demand_sdof_scene_shear(pd_test_ctx *ctx)
{
    pd_scene_excitation x = {.pulse = PD_PULSE_SINE, .dir = 1, .ap = 3.0, .Tp = 0.7};
    pd_scene *sc = pd_scene_new(&x);
    const double mass[2] = {1.2e5, 3e5};
    pd_scene_result r = {0};
    pd_err e;
    int rc = !sc || pd_scene_add_sdof(sc, "S1", 0.45, 0.05, mass[0], &e) ||
             pd_scene_add_sdof(sc, "S2", 0.8, 0.02, mass[1], &e) ||
             pd_scene_add_contact(sc, PD_WALL, 0, 0, 1, 1.0, 0.5, 0, &e) ||
             pd_scene_add_contact(sc, 0, 1, 1, 1, 1.0, 0.5, 1, &e) || pd_scene_finish(sc, &e) ||
             pd_scene_result_alloc(sc, &r, &e);
    if (CHECK(ctx, !rc, "scene: %s", sc ? e.msg : "out of memory")) {
        const pd_method methods[3] = {PD_METHOD_MOREAU, PD_METHOD_MOREAU, PD_METHOD_EVENT};
        for (int k = 0; k < 3; k++) {
            pd_run_opts o = pd_run_default_opts();
            o.method = methods[k];
            o.rtol = k == 1 ? 1e-4 : 0.0;
            o.tend = 2.0;
            if (!CHECK(ctx, pd_scene_run(sc, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg))
                continue;
            for (int s = 0; s < 2; s++) {
                double want = mass[s] * r.acc_max[s];
                CHECK(ctx, want > 0.0 && fabs(r.shear_max[s] - want) <= 1e-12 * want,
                      "run %d, S%d: shear_max %.17g, m acc_max %.17g", k, s + 1, r.shear_max[s],
                      want);
            }
        }
    }
    pd_scene_result_free(&r);
    pd_scene_free(sc);
}

/* The cubic Hermite with values f0, f1 and slopes d0, d1 on [0, h] at s. */
static double hermite3(double f0, double d0, double f1, double d1, double h, double s)
{
    double t = s / h, t2 = t * t, t3 = t2 * t;
    return (2.0 * t3 - 3.0 * t2 + 1.0) * f0 + (t3 - 2.0 * t2 + t) * h * d0 +
           (-2.0 * t3 + 3.0 * t2) * f1 + (t3 - t2) * h * d1;
}

/* pd_demand_cubic_monotone (Fritsch and Carlson's circle) against the
 * cubic sampled densely and against pd_demand_cubic_peak:
 *   - 2000 seeded cubics with alpha = d0 / m, beta = d1 / m drawn in the
 *     circle's quarter (m the secant, of either sign): it says monotone,
 *     and no sample of 400 inside passes the ends by more than rounding
 *     (1e-12 of |f0| + |f1| + |h m|), nor does pd_demand_cubic_peak find a
 *     turn above them — what lets the observers skip the peak there;
 *   - 2000 cubics with slopes anywhere in [-6 m, 6 m]: whenever a sample
 *     passes the ends by more than rounding it said not monotone (no peak
 *     skipped);
 *   - exact edges: alpha = 3, beta = 0 and alpha = 0, beta = 3 (on the
 *     circle, monotone: yes), alpha = beta = 2.2 (outside: no, though
 *     monotone), a slope against the secant (no), a constant (yes). */
static void test_demand_cubic_monotone(pd_test_ctx *ctx)
{
    uint64_t seed = 20261130;
    int said_no = 0, passed = 0, peak_above = 0, skipped = 0, overshoots = 0;
    for (int k = 0; k < 4000; k++) {
        int inside = k < 2000;
        double h = 0.01 + pd_test_uniform(&seed), f0 = 4.0 * pd_test_uniform(&seed) - 2.0;
        double m = (pd_test_uniform(&seed) < 0.5 ? -1.0 : 1.0) * (0.1 + pd_test_uniform(&seed));
        double al, be;
        if (inside) { /* in the quarter circle of radius 3 */
            double r = 3.0 * sqrt(pd_test_uniform(&seed)), th = 1.5707963 * pd_test_uniform(&seed);
            al = r * cos(th);
            be = r * sin(th);
        } else {
            al = 12.0 * pd_test_uniform(&seed) - 6.0;
            be = 12.0 * pd_test_uniform(&seed) - 6.0;
        }
        double f1 = f0 + m * h, d0 = al * m, d1 = be * m;
        int mono = pd_demand_cubic_monotone(f0, d0, f1, d1, h);
        double hi = fmax(f0, f1), lo = fmin(f0, f1),
               room = 1e-12 * (fabs(f0) + fabs(f1) + fabs(h * m));
        int passes = 0;
        for (int j = 1; j < 400; j++) {
            double p = hermite3(f0, d0, f1, d1, h, h * j / 400.0);
            passes |= p > hi + room || p < lo - room;
        }
        if (inside) {
            said_no += !mono;
            passed += passes;
            peak_above += pd_demand_cubic_peak(f0, d0, f1, d1, h) > fmax(fabs(f0), fabs(f1)) + room;
        } else {
            overshoots += passes;
            skipped += passes && mono;
        }
    }
    CHECK(ctx, said_no == 0 && passed == 0 && peak_above == 0,
          "inside the circle: %d said not monotone, %d passed their ends, %d with a peak "
          "above them (of 2000)",
          said_no, passed, peak_above);
    CHECK(ctx, overshoots > 100 && skipped == 0,
          "slopes anywhere: %d of 2000 pass their ends, %d of them said monotone", overshoots,
          skipped);
    /* the edges, exact in doubles: f 0 -> 1 on h = 1, m = 1 */
    CHECK(ctx,
          pd_demand_cubic_monotone(0.0, 3.0, 1.0, 0.0, 1.0) == 1 &&
              pd_demand_cubic_monotone(0.0, 0.0, 1.0, 3.0, 1.0) == 1 &&
              pd_demand_cubic_monotone(2.0, 0.0, 2.0, 0.0, 0.5) == 1,
          "on the circle and constant: monotone");
    CHECK(ctx,
          pd_demand_cubic_monotone(0.0, 2.2, 1.0, 2.2, 1.0) == 0 &&
              pd_demand_cubic_monotone(0.0, -0.5, 1.0, 1.0, 1.0) == 0 &&
              pd_demand_cubic_monotone(1.0, 0.5, 0.0, -1.0, 1.0) == 0,
          "outside the circle, or a slope against the secant: not said monotone");
}

void suite_demand(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_demand_sdof_closed_form);
    PD_RUN(ctx, test_demand_sdof_held_peak);
    PD_RUN(ctx, test_demand_base_shear_equilibrium);
    PD_RUN(ctx, test_demand_moreau_converges);
    PD_RUN(ctx, test_demand_penalty_force);
    PD_RUN(ctx, test_demand_penalty_force_scene);
    PD_RUN(ctx, test_demand_leaves_results_alone);
    PD_RUN(ctx, test_demand_storey_heights);
    PD_RUN(ctx, test_demand_cli_refusals);
    PD_RUN(ctx, test_demand_cubic_peak);
    PD_RUN(ctx, test_demand_cubic_monotone);
    PD_RUN(ctx, test_demand_sdof_scene_shear);
}
