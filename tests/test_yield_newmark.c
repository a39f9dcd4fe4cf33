/* test_yield_newmark.c — the practitioners' baseline on a yielding
 * oscillator: implicit Newmark (average acceleration) with penalty contact
 * elements and Newton iterations on the elements and the spring's return
 * mapping (engine/penalty_newmark.c):
 *   - a spring that never yields gives the elastic run bit for bit;
 *   - it tends to the exact reference as the contact stiffness grows (the
 *     penetration ~ kc^-1/2) and, without a wall, as dt shrinks;
 *   - Newton's failures are counted and the failed steps redone at the
 *     spring's initial stiffness reach the same answer;
 *   - the adaptive penalty refuses yielding springs, naming itself. */
#include <math.h>
#include <string.h>

#include "pd_core.h"
#include "pd_engine.h"
#include "pd_problems.h"
#include "pd_test.h"

/* Run c by method with dt (0: the default) and contact stiffness kc (a
 * multiple of w0^2; 0: the default); 1 when it ran. */
static int run(pd_test_ctx *ctx, const pd_osc *c, pd_method method, double dt, double kc,
               int no_wall, pd_osc_result *r)
{
    pd_run_opts o = pd_run_default_opts();
    o.method = method;
    o.dt = dt;
    o.no_wall = no_wall;
    o.pen.kc_mult = kc;
    pd_err e;
    return CHECK(ctx, pd_osc_run(c, &o, NULL, NULL, r, &e) == PD_OK, "%s: %s",
                 pd_method_name(method), e.msg);
}

/* A spring that never yields (uy 1e6 Le) runs the springs' code with no
 * offset ever: every figure the elastic run's, bit for bit, no onset. */
static void test_yield_newmark_unreached_is_elastic(pd_test_ctx *ctx)
{
    for (int k = 0; k < 3; k++) {
        pd_osc c = pd_osc_default();
        c.Pi2 = 0.6 + 0.9 * k;
        c.Pi3 = k == 2 ? 0.0 : 0.1;
        c.eps = 0.3 * k;
        pd_osc_result el, far;
        if (!run(ctx, &c, PD_METHOD_NEWMARK, 0.0, 0.0, 0, &el))
            continue;
        c.Piy = 1e6;
        c.alpha = 0.1;
        if (!run(ctx, &c, PD_METHOD_NEWMARK, 0.0, 0.0, 0, &far))
            continue;
        const double a[] = {el.umax,         el.u_toward,     el.u_away,
                            el.first_impact, el.contact_time, el.max_impulse,
                            el.acc_max,      el.shear_max,    el.force_max},
                     b[] = {far.umax,         far.u_toward,     far.u_away,
                            far.first_impact, far.contact_time, far.max_impulse,
                            far.acc_max,      far.shear_max,    far.force_max};
        CHECK(ctx,
              !memcmp(a, b, sizeof a) && el.impacts == far.impacts && el.steps == far.steps &&
                  far.n_yield == 0 && far.plastic_excursion == 0.0 && far.newton_failures == 0,
              "case %d: the spring that never yields differs from the elastic run (umax %.17g, "
              "%.17g; %ld onsets)",
              k, el.umax, far.umax, far.n_yield);
    }
}

/* Against a wall (Pi2 1.5, Pi3 0.1, Piy 0.1, alpha 0.05, eps 0.5) at dt =
 * T0/6667: umax and the residual tend to the exact reference as kc grows
 * 1e4, 1e5, 1e6 w0^2 (measured umax 1.6e-3, 4.9e-4, 1.7e-4 of it, the
 * residual 8.7e-3, 2.4e-3, 6.0e-4 of uy: the penetration's share, ~
 * kc^-1/2), each at least twice closer; no Newton failure. */
static void test_yield_newmark_tends_to_exact(pd_test_ctx *ctx)
{
    pd_osc c = pd_osc_default();
    c.Pi2 = 1.5;
    c.Pi3 = 0.1;
    c.Piy = 0.1;
    c.alpha = 0.05;
    c.eps = 0.5;
    pd_osc_result ex, nm;
    if (!run(ctx, &c, PD_METHOD_EVENT, 0.0, 0.0, 0, &ex))
        return;
    double prev_u = HUGE_VAL, prev_r = HUGE_VAL, dt = 1e-4;
    for (int k = 0; k < 3; k++) {
        double kc = 1e4 * pow(10.0, k);
        if (!run(ctx, &c, PD_METHOD_NEWMARK, dt, kc, 0, &nm))
            return;
        double du = fabs(nm.umax - ex.umax) / ex.umax;
        double dr = fabs(nm.residual - ex.residual) / pd_osc_uy(&c);
        printf("    kc %.0e w0^2: umax %.3g, residual %.3g of uy off; %ld Newton failures\n", kc,
               du, dr, nm.newton_failures);
        CHECK(ctx, du <= 0.5 * prev_u && dr <= 0.5 * prev_r && nm.newton_failures == 0,
              "kc %g: umax %.3g (was %.3g), residual %.3g (was %.3g) off; %ld failures", kc, du,
              prev_u, dr, prev_r, nm.newton_failures);
        prev_u = du;
        prev_r = dr;
    }
    CHECK(ctx, prev_u <= 3e-4 && prev_r <= 1e-3, "kc 1e6 w0^2: umax %.3g, residual %.3g off",
          prev_u, prev_r);
}

/* No wall, an elastic-perfectly-plastic oscillator under a long cosine
 * pulse (Pi2 4, Piy 0.05, xi 0.05): ductility and residual tend to the
 * exact reference as dt shrinks, at second order (the return mapping is
 * exact at each step's end; measured 6.2e-5, 7.4e-7, 6.4e-9 of the
 * ductility at T0/250, /2500, /25000), each at least 10x closer. */
static void test_yield_newmark_no_wall(pd_test_ctx *ctx)
{
    pd_osc c = pd_osc_default();
    c.pulse = PD_PULSE_COSINE;
    c.Pi2 = 4.0;
    c.Piy = 0.05;
    c.alpha = 0.0;
    pd_osc_result ex, nm;
    if (!run(ctx, &c, PD_METHOD_EVENT, 0.0, 0.0, 1, &ex))
        return;
    double prev = HUGE_VAL, T0 = pd_osc_T0(&c);
    for (int k = 0; k < 3; k++) {
        double dt = T0 / (250.0 * pow(10.0, k));
        if (!run(ctx, &c, PD_METHOD_NEWMARK, dt, 0.0, 1, &nm))
            return;
        double d = fmax(fabs(nm.ductility - ex.ductility) / ex.ductility,
                        fabs(nm.residual - ex.residual) / pd_osc_uy(&c) / ex.ductility);
        printf("    dt T0/%.0f: ductility and residual %.3g off (ductility %.6g)\n", T0 / dt, d,
               ex.ductility);
        CHECK(ctx, d <= 0.1 * prev && nm.n_yield == ex.n_yield,
              "dt %g: %.3g off (was %.3g); %ld onsets against %ld", dt, d, prev, nm.n_yield,
              ex.n_yield);
        prev = d;
    }
}

/* A one-dof yielding model against a wall (engine level): x'' + 0.2 x' +
 * x = 3 sin(t), a spring with ks 0.8, uy 0.5, a Kelvin-Voigt wall at 0.3. */
typedef struct nm_case {
    double M, C, K, W, S, ks, uy, g0, e;
} nm_case;

static void sine_force(double t, int side, double *F, void *ctx)
{
    (void)side;
    F[0] = 3.0 * *(const double *)ctx * sin(t); /* ctx: the length scale */
}

static int final_state(const pd_state *st, void *ctx)
{
    double *qv = ctx;
    qv[0] = st->q[0];
    qv[1] = st->v[0];
    qv[2] = st->up ? st->up[0] : NAN;
    return 0;
}

/* Newton's iterations capped at 1 fail wherever the spring or the element
 * switches inside a step unforeseen by the predictor (a1 = a0): each
 * failure is counted and the step redone at the spring's initial
 * stiffness, which reaches the same answer (1e-9; measured equal) over 400
 * steps with slides and impacts (measured: 4 failures; full Newton none, in
 * 414 iterations: the predictor foresees nearly every switch). */
static void test_yield_newmark_failures_redone(pd_test_ctx *ctx)
{
    double L = 1.0;
    nm_case k = {.M = 1.0,
                 .C = 0.2,
                 .K = 1.0,
                 .W = -1.0,
                 .S = 1.0,
                 .ks = 0.8,
                 .uy = 0.5,
                 .g0 = 0.3,
                 .e = 0.5};
    pd_model md = {.n = 1,
                   .m = 1,
                   .M = pd_matrix_dense(1, 1, &k.M),
                   .C = pd_matrix_dense(1, 1, &k.C),
                   .K = pd_matrix_dense(1, 1, &k.K),
                   .W = pd_matrix_dense(1, 1, &k.W),
                   .g0 = &k.g0,
                   .e = &k.e,
                   .force = sine_force,
                   .force_ctx = &L,
                   .ns = 1,
                   .S = pd_matrix_dense(1, 1, &k.S),
                   .ks = &k.ks,
                   .uy = &k.uy};
    pd_penalty_opts o = pd_penalty_default_opts();
    o.stepper = "newmark";
    o.kc = 1e4;
    o.h = 0.05;
    double full[3], capped[3];
    pd_penalty_result r1, r2;
    pd_err e;
    if (!CHECK(ctx,
               pd_penalty_run(&md, 0.0, NULL, NULL, 20.0, &o, final_state, full, &r1, &e) == PD_OK,
               "%s", e.msg))
        return;
    o.max_newton = 1;
    if (!CHECK(ctx,
               pd_penalty_run(&md, 0.0, NULL, NULL, 20.0, &o, final_state, capped, &r2, &e) ==
                   PD_OK,
               "%s", e.msg))
        return;
    double d =
        fmax(fabs(full[0] - capped[0]), fmax(fabs(full[1] - capped[1]), fabs(full[2] - capped[2])));
    printf("    capped at one iteration: %ld of %ld steps failed, the state %.3g apart "
           "(full Newton: %ld failures, %ld iterations)\n",
           r2.newton_failures, r2.steps, d, r1.newton_failures, r1.newton_iterations);
    CHECK(ctx, r1.newton_failures == 0 && r2.newton_failures >= 3 && d <= 1e-9 && full[2] != 0.0,
          "failures %ld and %ld, the states %.3g apart, the offset %g", r1.newton_failures,
          r2.newton_failures, d, full[2]);
    /* lengths scaled by 2^-20 (the force, uy, the gap: exactly, in binary;
     * kc as before: a linear element): the capped run scales with them, its
     * iterations converging to the state's own scale (1e-9 of it; measured
     * equal) */
    double small[3];
    L = ldexp(1.0, -20);
    k.uy *= L;
    k.g0 *= L;
    if (CHECK(ctx,
              pd_penalty_run(&md, 0.0, NULL, NULL, 20.0, &o, final_state, small, &r2, &e) == PD_OK,
              "%s", e.msg)) {
        double ds = 0.0;
        for (int i = 0; i < 3; i++)
            ds = fmax(ds, fabs(small[i] / L - capped[i]));
        CHECK(ctx, ds <= 1e-9 * fabs(capped[2]) && r2.newton_failures >= 3,
              "lengths scaled by 2^-20: %.3g apart (scaled back), %ld failures", ds,
              r2.newton_failures);
    }
    k.uy /= L;
    k.g0 /= L;
    L = 1.0;
    /* a state that is not finite, the adaptive penalty with springs, a bad
     * spring: refused, each named */
    double q0 = NAN, v0 = 0.0;
    CHECK(ctx,
          pd_penalty_run(&md, 0.0, &q0, &v0, 1.0, &o, NULL, NULL, NULL, &e) == PD_EINVAL &&
              strstr(e.msg, "not finite"),
          "a NaN start: %s", e.msg);
    o.stepper = "rk8pd";
    CHECK(ctx,
          pd_penalty_run(&md, 0.0, NULL, NULL, 1.0, &o, NULL, NULL, NULL, &e) == PD_EINVAL &&
              strstr(e.msg, "adaptive penalty") && strstr(e.msg, "newmark"),
          "rk8pd with yielding springs: %s", e.msg);
    k.uy = -1.0;
    o.stepper = "newmark";
    CHECK(ctx,
          pd_penalty_run(&md, 0.0, NULL, NULL, 1.0, &o, NULL, NULL, NULL, &e) == PD_EINVAL &&
              strstr(e.msg, "uy"),
          "a negative uy: %s", e.msg);
}

void suite_yield_newmark(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_yield_newmark_unreached_is_elastic);
    PD_RUN(ctx, test_yield_newmark_tends_to_exact);
    PD_RUN(ctx, test_yield_newmark_no_wall);
    PD_RUN(ctx, test_yield_newmark_failures_redone);
}
