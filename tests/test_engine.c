/* test_engine.c — the Moreau–Jean engine against closed forms and invariants. */
#include <malloc.h>
#include <stdlib.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "pd_mj1.h"
#include "pd_engine.h"
#include "pd_factor.h"
#include "pd_test.h"

/* pd_sdof_advance satisfies the ODE (central differences), composes over
 * sub-intervals, and matches the textbook free vibration. */
static void test_engine_sdof_closed_form(pd_test_ctx *ctx)
{
    const pd_sdof cases[] = {{2.0, 0.05}, {7.5, 0.0}, {1.3, 0.4}, {3.0, 0.0}};
    for (size_t c = 0; c < 4; c++) {
        const pd_sdof *o = &cases[c];
        double A = 1.7, w = c == 3 ? 3.0 : 2.9, phi = 0.4; /* case 3: undamped resonance */
        double t = 1.234, d = 1e-4, u[3], v[3];
        for (int k = 0; k < 3; k++)
            pd_sdof_advance(o, A, w, phi, 0.2, 0.3, -0.8, t + (k - 1) * d, &u[k], &v[k]);
        double acc = (u[0] - 2 * u[1] + u[2]) / (d * d);
        double res = acc + 2 * o->xi * o->w0 * v[1] + o->w0 * o->w0 * u[1] - A * sin(w * t + phi);
        CHECK(ctx, fabs(res) < 1e-5 * (1 + o->w0 * o->w0), "case %zu: ODE residual %g", c, res);
        CHECK_NEAR(ctx, (u[2] - u[0]) / (2 * d), v[1], 1e-6);
        /* composition: 0.2 -> 0.9 -> t equals 0.2 -> t */
        double um, vm, u2, v2;
        pd_sdof_advance(o, A, w, phi, 0.2, 0.3, -0.8, 0.9, &um, &vm);
        pd_sdof_advance(o, A, w, phi, 0.9, um, vm, t, &u2, &v2);
        CHECK_NEAR(ctx, u2, u[1], 1e-12);
        CHECK_NEAR(ctx, v2, v[1], 1e-11);
        /* initial conditions */
        pd_sdof_advance(o, A, w, phi, 0.2, 0.3, -0.8, 0.2, &um, &vm);
        CHECK_NEAR(ctx, um, 0.3, 1e-14);
        CHECK_NEAR(ctx, vm, -0.8, 1e-14);
    }
    /* free vibration: u = e^{-a t}(u0 cos wd t + (v0 + a u0)/wd sin wd t) */
    pd_sdof o = {2.0, 0.1};
    double a = 0.2, wd = 2.0 * sqrt(0.99), t = 3.7, u, v;
    pd_sdof_advance(&o, 0.0, 1.0, 0.0, 0.0, 0.5, 0.25, t, &u, &v);
    CHECK_NEAR(ctx, u, exp(-a * t) * (0.5 * cos(wd * t) + (0.25 + a * 0.5) / wd * sin(wd * t)),
               1e-14);
}

/* The closed-form scalar LCP gives Lemke's impulse to 1e-15 relative. */
static void test_engine_scalar_lcp_matches_lemke(pd_test_ctx *ctx)
{
    uint64_t seed = 42;
    pd_lcp_work *work = pd_lcp_alloc(1);
    double worst = 0.0;
    int mismatched_sign = 0;
    for (int k = 0; k < 2000; k++) {
        double D = 1e-3 + 10.0 * pd_test_uniform(&seed), b = 4.0 * pd_test_uniform(&seed) - 2.0;
        double z, w;
        int st = pd_lcp_lemke(work, 1, &D, &b, NULL, &z, &w, NULL);
        double P = pd_contact_impulse_1(D, b);
        if (st != PD_OK || (P > 0) != (z > 0))
            mismatched_sign++;
        if (P > 0)
            worst = fmax(worst, fabs(P - z) / P);
    }
    CHECK(ctx, mismatched_sign == 0, "%d scalar LCPs disagree with Lemke on the status",
          mismatched_sign);
    CHECK(ctx, worst <= 1e-15, "closed form vs Lemke: worst relative difference %.3g", worst);
    pd_lcp_free(work);
}

/* Two equal free masses, 1 strikes 2 at speed V: after the step that closes
 * the gap, v1 = (1-e)V/2, v2 = (1+e)V/2 (momentum kept, Newton's law). */
static void test_engine_two_mass_impact(pd_test_ctx *ctx)
{
    const double es[] = {1.0, 0.5, 0.0};
    for (int c = 0; c < 3; c++) {
        double M[4] = {1, 0, 0, 1}, W[2] = {-1, 1}, g0 = 0.01, e = es[c];
        pd_model md = {.n = 2,
                       .m = 1,
                       .M = pd_matrix_dense(2, 2, M),
                       .C = pd_matrix_zero(2, 2),
                       .K = pd_matrix_zero(2, 2),
                       .W = pd_matrix_dense(2, 1, W),
                       .g0 = &g0,
                       .e = &e};
        pd_mj_opts o = pd_mj_default_opts();
        o.h = 1e-3;
        pd_err err;
        pd_mj *mj = pd_mj_alloc(&md, &o, &err);
        if (!CHECK(ctx, mj != NULL, "alloc: %s", err.msg))
            return;
        double v0[2] = {2.0, 0.0};
        pd_mj_reset(mj, 0.0, NULL, v0, &err);
        CHECK(ctx, pd_mj_run(mj, 20, NULL, NULL, &err) == PD_OK, "run: %s", err.msg);
        const pd_state *st = pd_mj_state(mj);
        CHECK_NEAR(ctx, st->v[0], (1 - e) * 1.0, 1e-14);
        CHECK_NEAR(ctx, st->v[1], (1 + e) * 1.0, 1e-14);
        CHECK_NEAR(ctx, st->v[0] + st->v[1], 2.0, 1e-14);
        CHECK(ctx, !strcmp(pd_mj_kernel_name(mj), "general"), "2 dofs run the general kernel");
        pd_mj_free(mj);
    }
}

/* A chain of 3 masses between two walls (4 contacts), springs between
 * neighbours: gaps stay above -C h with C fixed, impulses are complementary,
 * and with theta = 1/2, e = 1, no damping, energy is conserved exactly. */
static void test_engine_chain_energy(pd_test_ctx *ctx)
{
    enum { N = 3, C = 4 };
    double M[N * N] = {0}, K[N * N] = {0}, W[N * C] = {0}, g0[C], e[C];
    for (int i = 0; i < N; i++) {
        M[i + N * i] = 1.0 + 0.5 * i;
        K[i + N * i] = 40.0;
    }
    K[0 + N * 1] = K[1 + N * 0] = -10.0;
    K[1 + N * 2] = K[2 + N * 1] = -10.0;
    /* contact 0: left wall and mass 0; 1, 2: between masses; 3: mass 2 and right wall */
    W[0 + N * 0] = 1.0;
    W[0 + N * 1] = -1.0, W[1 + N * 1] = 1.0;
    W[1 + N * 2] = -1.0, W[2 + N * 2] = 1.0;
    W[2 + N * 3] = -1.0;
    for (int a = 0; a < C; a++) {
        g0[a] = 0.02;
        e[a] = 1.0;
    }
    pd_model md = {.n = N,
                   .m = C,
                   .M = pd_matrix_dense(N, N, M),
                   .C = pd_matrix_zero(N, N),
                   .K = pd_matrix_dense(N, N, K),
                   .W = pd_matrix_dense(N, C, W),
                   .g0 = g0,
                   .e = e};
    double v0[N] = {1.0, -0.5, 0.7};
    for (int pass = 0; pass < 2; pass++) {
        double h = pass ? 5e-4 : 1e-3, vmax = 0;
        pd_mj_opts o = pd_mj_default_opts();
        o.h = h;
        pd_err err;
        pd_mj *mj = pd_mj_alloc(&md, &o, &err);
        if (!CHECK(ctx, mj != NULL, "alloc: %s", err.msg))
            return;
        pd_mj_reset(mj, 0.0, NULL, v0, &err);
        const pd_state *st = pd_mj_state(mj);
        double E0 = 0, Emax_dev = 0, gmin = 0, worst_compl = 0, vprev[N];
        memcpy(vprev, v0, sizeof vprev);
        long impacts = 0;
        for (int i = 0; i < N; i++)
            E0 += 0.5 * M[i + N * i] * v0[i] * v0[i];
        for (long k = 0; k < (long)(5.0 / h); k++) {
            if (pd_mj_step(mj, &err)) {
                CHECK(ctx, 0, "step: %s", err.msg);
                break;
            }
            double E = 0;
            for (int i = 0; i < N; i++) {
                double Kq = 0;
                for (int j = 0; j < N; j++)
                    Kq += K[i + N * j] * st->q[j];
                E += 0.5 * M[i + N * i] * st->v[i] * st->v[i] + 0.5 * st->q[i] * Kq;
                vmax = fmax(vmax, fabs(st->v[i]));
            }
            Emax_dev = fmax(Emax_dev, fabs(E - E0) / E0);
            for (int a = 0; a < C; a++) {
                gmin = fmin(gmin, st->g[a]);
                impacts += st->P[a] > 0;
                CHECK(ctx, st->P[a] >= 0.0, "negative impulse %g", st->P[a]);
                /* the step's LCP: w = U_k+1 + e U_k >= 0 and P w = 0 */
                if (st->active[a]) {
                    double U1 = 0, U0 = 0;
                    for (int i = 0; i < N; i++) {
                        U1 += W[i + N * a] * st->v[i];
                        U0 += W[i + N * a] * vprev[i];
                    }
                    double w = U1 + e[a] * U0;
                    worst_compl = fmax(worst_compl, fmax(-w, st->P[a] * fabs(w)));
                }
            }
            memcpy(vprev, st->v, sizeof vprev);
        }
        CHECK(ctx, impacts > 10, "the chain must pound (%ld impacts)", impacts);
        CHECK(ctx, Emax_dev < 1e-10, "h = %g: energy drift %.3g with e = 1, theta = 1/2", h,
              Emax_dev);
        CHECK(ctx, -gmin <= h * 2 * vmax, "h = %g: penetration %.3g > 2 h vmax = %.3g", h, -gmin,
              2 * h * vmax);
        CHECK(ctx, worst_compl <= 1e-12, "step LCPs violated by %.3g", worst_compl);
        pd_mj_free(mj);
    }
}

/* theta < 1/2 is refused unless asked for; asked for, it blows up at a large
 * step while theta = 1/2 and 1 stay bounded (unconditional stability). */
static void test_engine_theta_stability(pd_test_ctx *ctx)
{
    double M = 1, K = 1, zero = 0;
    pd_model md = {.n = 1,
                   .m = 0,
                   .M = pd_matrix_dense(1, 1, &M),
                   .C = pd_matrix_dense(1, 1, &zero),
                   .K = pd_matrix_dense(1, 1, &K),
                   .W = pd_matrix_zero(1, 0)};
    pd_mj_opts o = pd_mj_default_opts();
    pd_err err;
    o.h = 1.0; /* w0 h = 1 */
    o.theta = 0.3;
    CHECK(ctx,
          pd_mj_alloc(&md, &o, &err) == NULL && err.status == PD_EINVAL && strstr(err.msg, "theta"),
          "theta = 0.3 must be refused naming theta: %s", err.msg);
    const double thetas[] = {0.0, 0.3, 0.5, 1.0};
    for (int c = 0; c < 4; c++) {
        o.theta = thetas[c];
        o.allow_unstable = 1;
        /* amplification |R|^2 = (1 + (1-theta)^2 (w0 h)^2) / (1 + theta^2 (w0 h)^2):
         * above 1 for every h when theta < 1/2; 200 steps at w0 h = 2.5 */
        o.h = 2.5;
        pd_mj *mj = pd_mj_alloc(&md, &o, &err);
        if (!CHECK(ctx, mj != NULL, "alloc theta %g: %s", o.theta, err.msg))
            continue;
        double q0 = 1.0;
        pd_mj_reset(mj, 0.0, &q0, NULL, &err);
        int rc = pd_mj_run(mj, 200, NULL, NULL, &err);
        const pd_state *st = pd_mj_state(mj);
        double amp = sqrt(st->q[0] * st->q[0] + st->v[0] * st->v[0]);
        if (thetas[c] < 0.5)
            CHECK(ctx, rc == PD_ENONFINITE || amp > 1e6,
                  "theta %g at w0 h = 2.5 must grow without bound (amp %g)", thetas[c], amp);
        else
            CHECK(ctx, rc == PD_OK && amp <= 1.0 + 1e-12 && amp > 0.0,
                  "theta %g must stay bounded (amp %g)", thetas[c], amp);
        pd_mj_free(mj);
    }
}

/* With damping xi, theta < 1/2 is stable up to about w0 h = 2 xi / (1 - 2 theta)
 * (growth (1 - 2 theta) w0^2 h / 2 per unit time against the decay xi w0):
 * bounded at 0.7 times that step, growing at 1.4 times it. */
static void test_engine_theta_damped_boundary(pd_test_ctx *ctx)
{
    const double thetas[] = {0.3, 0.4, 0.45}, xi = 0.05, w0 = 1.0;
    double M = 1, K = w0 * w0, C = 2 * xi * w0;
    pd_model md = {.n = 1,
                   .m = 0,
                   .M = pd_matrix_dense(1, 1, &M),
                   .C = pd_matrix_dense(1, 1, &C),
                   .K = pd_matrix_dense(1, 1, &K),
                   .W = pd_matrix_zero(1, 0)};
    for (int c = 0; c < 3; c++)
        for (int side = 0; side < 2; side++) {
            double boundary = 2 * xi / (1 - 2 * thetas[c]) / w0;
            pd_mj_opts o = pd_mj_default_opts();
            pd_err err;
            o.theta = thetas[c];
            o.allow_unstable = 1;
            o.h = boundary * (side ? 1.4 : 0.7);
            pd_mj *mj = pd_mj_alloc(&md, &o, &err);
            double q0 = 1.0;
            pd_mj_reset(mj, 0.0, &q0, NULL, &err);
            int rc = pd_mj_run(mj, (long)(400.0 / o.h), NULL, NULL, &err);
            const pd_state *st = pd_mj_state(mj);
            double amp = sqrt(st->q[0] * st->q[0] + st->v[0] * st->v[0] / (w0 * w0));
            if (side)
                CHECK(ctx, rc != PD_OK || amp > 10.0, "theta %g at 1.4x the boundary: amp %g",
                      thetas[c], amp);
            else
                CHECK(ctx, rc == PD_OK && amp < 1.0, "theta %g at 0.7x the boundary: amp %g",
                      thetas[c], amp);
            pd_mj_free(mj);
        }
}

/* A non-finite force stops the run with PD_ENONFINITE naming the time. */
static void nan_after_one(double t, int side, double *F, void *ctx)
{
    (void)side;
    (void)ctx;
    F[0] = t > 1.0 ? NAN : 1.0;
}

static void test_engine_failure_is_reported(pd_test_ctx *ctx)
{
    double M = 1, K = 4;
    pd_model md = {.n = 1,
                   .m = 0,
                   .M = pd_matrix_dense(1, 1, &M),
                   .C = pd_matrix_zero(1, 1),
                   .K = pd_matrix_dense(1, 1, &K),
                   .W = pd_matrix_zero(1, 0),
                   .force = nan_after_one};
    pd_mj_opts o = pd_mj_default_opts();
    o.h = 0.1;
    for (int kernel = 0; kernel < 2; kernel++) {
        o.kernel = kernel ? PD_KERNEL_GENERAL : PD_KERNEL_AUTO;
        pd_err err;
        pd_mj *mj = pd_mj_alloc(&md, &o, &err);
        int rc = pd_mj_run(mj, 100, NULL, NULL, &err);
        CHECK(ctx, rc == PD_ENONFINITE, "status %d, expected PD_ENONFINITE", rc);
        CHECK(ctx, strstr(err.msg, "t = 1.1") != NULL, "message must name t = 1.1: %s", err.msg);
        CHECK(ctx, pd_mj_state(mj)->step == 11, "stopped at step %ld", pd_mj_state(mj)->step);
        pd_mj_free(mj);
    }
}

/* Model checks name the faulty field. */
static void test_engine_model_check(pd_test_ctx *ctx)
{
    double M = 1, K = 1, W = -1, g = -0.1, e = 0.5, Knan = NAN;
    pd_model md = {.n = 1,
                   .m = 1,
                   .M = pd_matrix_dense(1, 1, &M),
                   .C = pd_matrix_zero(1, 1),
                   .K = pd_matrix_dense(1, 1, &K),
                   .W = pd_matrix_dense(1, 1, &W),
                   .g0 = &g,
                   .e = &e};
    pd_err err;
    CHECK(ctx, pd_model_check(&md, &err) == PD_EINVAL && strstr(err.msg, "gap"), "%s", err.msg);
    g = 0.1;
    e = 1.5;
    CHECK(ctx, pd_model_check(&md, &err) == PD_EINVAL && strstr(err.msg, "restitution"), "%s",
          err.msg);
    e = 0.5;
    md.K = pd_matrix_dense(1, 1, &Knan);
    CHECK(ctx, pd_model_check(&md, &err) == PD_EINVAL && strstr(err.msg, "K"), "%s", err.msg);
    md.K = pd_matrix_dense(1, 1, &K);
    CHECK(ctx, pd_model_check(&md, &err) == PD_OK, "valid model refused: %s", err.msg);
    pd_mj_opts o = pd_mj_default_opts();
    o.h = -1;
    CHECK(ctx, pd_mj_alloc(&md, &o, &err) == NULL && strstr(err.msg, "dt"), "%s", err.msg);
}

/* Steps do not allocate: the heap in use is the same before and after a
 * run of many impacting steps (glibc's mallinfo2; skipped where the
 * allocator does not report, e.g. under AddressSanitizer). */
static void osc_force(double t, int side, double *F, void *ctx)
{
    (void)side;
    (void)ctx;
    F[0] = 3.0 * sin(t);
    F[1] = -2.0 * cos(t);
}

static void test_engine_no_allocation_in_steps(pd_test_ctx *ctx)
{
    double M[4] = {1, 0, 0, 2}, K[4] = {4, -1, -1, 3}, C[4] = {0.1, 0, 0, 0.1};
    double W[4] = {-1, 0, 1, -1}, g0[2] = {0.05, 0.02}, e[2] = {0.7, 0.3};
    pd_model md = {.n = 2,
                   .m = 2,
                   .M = pd_matrix_dense(2, 2, M),
                   .C = pd_matrix_dense(2, 2, C),
                   .K = pd_matrix_dense(2, 2, K),
                   .W = pd_matrix_dense(2, 2, W),
                   .g0 = g0,
                   .e = e,
                   .force = osc_force};
    pd_mj_opts o = pd_mj_default_opts();
    o.h = 1e-3;
    pd_err err;
    pd_mj *mj = pd_mj_alloc(&md, &o, &err);
    if (!CHECK(ctx, mj != NULL, "alloc: %s", err.msg))
        return;
    struct mallinfo2 before = mallinfo2();
    if (before.uordblks == 0 && before.arena == 0) {
        pd_test_skip(ctx, "allocator reports no heap statistics");
        pd_mj_free(mj);
        return;
    }
    long pivots = 0, contact_steps = 0;
    for (int k = 0; k < 20000 && !pd_mj_step(mj, &err); k++) {
        pivots += pd_mj_state(mj)->lcp_solver != NULL;
        contact_steps += pd_mj_state(mj)->nactive > 0;
    }
    struct mallinfo2 after = mallinfo2();
    CHECK(ctx, contact_steps > 100 && pivots > 0, "the run must solve LCPs (%ld contact steps)",
          contact_steps);
    CHECK(ctx, after.uordblks == before.uordblks, "heap in use changed by %ld bytes during steps",
          (long)after.uordblks - (long)before.uordblks);
    pd_mj_free(mj);
}

/* ---- the batch (pd_mjb) against pd_mj, bit for bit ---------------------- */

/* A lane's system for the comparison: random periods, damping, gaps,
 * restitution, steps, force shapes (a sine pulse ending at brk, or none). */
typedef struct batch_sys {
    double M, C, K, W, g0, e, h, brk, amp, w;
    int wall;
} batch_sys;

static batch_sys batch_sys_draw(uint64_t *rs)
{
    batch_sys b = {.M = 0.5 + pd_test_uniform(rs),
                   .C = 0.3 * pd_test_uniform(rs),
                   .K = 0.2 + 20.0 * pd_test_uniform(rs),
                   .W = pd_test_uniform(rs) < 0.5 ? -1.0 : 1.7,
                   .g0 = 0.02 * pd_test_uniform(rs),
                   .e = pd_test_uniform(rs),
                   .h = 1e-3 * (1.0 + 4.0 * pd_test_uniform(rs)),
                   .amp = pd_test_uniform(rs) < 0.5 ? 1.0 : -1.0,
                   .w = 2.0 + 5.0 * pd_test_uniform(rs),
                   .wall = pd_test_uniform(rs) < 0.8};
    b.brk = pd_test_uniform(rs) < 0.7 ? 0.3 + 0.5 * pd_test_uniform(rs) : INFINITY;
    if (pd_test_uniform(rs) < 0.2) /* a breakpoint on a step: the right limit there */
        b.brk = 97.0 * b.h;
    return b;
}

/* amp sin(w t) until brk (its left limit at brk), 0 after. */
static double batch_sys_force(const batch_sys *b, double t, int side)
{
    int after = side < 0 ? t > b->brk : t >= b->brk;
    return after ? 0.0 : b->amp * sin(b->w * t);
}

static void mj_sys_force(double t, int side, double *F, void *ctx)
{
    F[0] = batch_sys_force(ctx, t, side);
}

typedef struct batch_src {
    batch_sys sys[PD_MJB_LANES];
} batch_src;

static void mjb_sys_force(const double *t, int side, double *F, void *ctx)
{
    batch_src *bs = ctx;
    for (int l = 0; l < PD_MJB_LANES; l++)
        F[l] = batch_sys_force(&bs->sys[l], t[l], side);
}

/* One system alone by pd_mj's scalar kernel: its q, v, g and P after each
 * of nsteps steps into out (4 per step). */
static int mj_alone(const batch_sys *b, double theta, double gamma, long nsteps, double *out,
                    pd_err *err)
{
    pd_model md = {.n = 1,
                   .m = b->wall,
                   .M = pd_matrix_dense(1, 1, (double *)&b->M),
                   .C = pd_matrix_dense(1, 1, (double *)&b->C),
                   .K = pd_matrix_dense(1, 1, (double *)&b->K),
                   .W = pd_matrix_dense(1, 1, (double *)&b->W),
                   .g0 = &b->g0,
                   .e = &b->e,
                   .force = mj_sys_force,
                   .force_ctx = (void *)b,
                   .breaks = &b->brk,
                   .nbreaks = isfinite(b->brk) ? 1 : 0};
    pd_mj_opts o = pd_mj_default_opts();
    o.h = b->h;
    o.theta = theta;
    o.gamma = gamma;
    pd_mj *mj = pd_mj_alloc(&md, &o, err);
    if (!mj)
        return -1;
    for (long k = 0; k < nsteps; k++) {
        if (pd_mj_step(mj, err)) {
            pd_mj_free(mj);
            return -1;
        }
        const pd_state *st = pd_mj_state(mj);
        out[4 * k] = st->q[0];
        out[4 * k + 1] = st->v[0];
        out[4 * k + 2] = b->wall ? st->g[0] : 0.0;
        out[4 * k + 3] = b->wall ? st->P[0] : 0.0;
    }
    pd_mj_free(mj);
    return 0;
}

/* Every lane of the batch, with lanes restarted at different batch steps,
 * gives the numbers of pd_mj for its system alone at every step, bit for
 * bit, with each instruction set's step this processor has. */
static void test_engine_batch_matches_scalar(pd_test_ctx *ctx)
{
    enum { NSTEP = 700, RESTART = 250 };
    static const struct {
        const char *name;
        pd_mjb_step_fn fn;
        int level; /* pd_cpu_level() it needs */
    } variants[] = {
        {"baseline", pd_mjb_lanes_step_base, 0},
#if PD_X86_VARIANTS
        {"x86-64-v3", pd_mjb_lanes_step_x86v3, 3},
        {"x86-64-v4", pd_mjb_lanes_step_x86v4, 4},
#endif
    };
    static double alone[PD_MJB_LANES][2][4 * NSTEP];
    batch_src src;
    uint64_t rs = 20261123;
    const double theta = 0.55, gamma = 0.5;
    pd_err err;
    /* lanes 0..L-1 run system A from step 0; odd lanes switch to system B
     * at batch step RESTART (its own clock from 0 again) */
    batch_sys A[PD_MJB_LANES], B[PD_MJB_LANES];
    for (int l = 0; l < PD_MJB_LANES; l++) {
        A[l] = batch_sys_draw(&rs);
        B[l] = batch_sys_draw(&rs);
        if (mj_alone(&A[l], theta, gamma, NSTEP, alone[l][0], &err) ||
            mj_alone(&B[l], theta, gamma, NSTEP, alone[l][1], &err)) {
            CHECK(ctx, 0, "pd_mj: %s", err.msg);
            return;
        }
    }
    long compared = 0, contacts = 0, breaks = 0;
    for (size_t vi = 0; vi < sizeof variants / sizeof variants[0]; vi++) {
        if (pd_cpu_level() < variants[vi].level)
            continue;
        pd_mjb *b = aligned_alloc(64, sizeof *b);
        pd_mj_opts o = pd_mj_default_opts();
        o.theta = theta;
        o.gamma = gamma;
        if (!CHECK(ctx, b && !pd_mjb_init(b, &o, mjb_sys_force, &src, &err), "init: %s", err.msg)) {
            free(b);
            return;
        }
        b->lanes_step = variants[vi].fn;
        for (int l = 0; l < PD_MJB_LANES; l++) {
            src.sys[l] = A[l];
            pd_mjb_lane ln = {.M = A[l].M,
                              .C = A[l].C,
                              .K = A[l].K,
                              .wall = A[l].wall,
                              .W = A[l].W,
                              .g0 = A[l].g0,
                              .e = A[l].e,
                              .h = A[l].h,
                              .brk = A[l].brk};
            CHECK(ctx, !pd_mjb_set_lane(b, l, &ln, &err), "lane %d: %s", l, err.msg);
        }
        long bad = 0;
        for (long k = 0; k < NSTEP + RESTART; k++) {
            if (k == RESTART)
                for (int l = 1; l < PD_MJB_LANES; l += 2) {
                    src.sys[l] = B[l];
                    pd_mjb_lane ln = {.M = B[l].M,
                                      .C = B[l].C,
                                      .K = B[l].K,
                                      .wall = B[l].wall,
                                      .W = B[l].W,
                                      .g0 = B[l].g0,
                                      .e = B[l].e,
                                      .h = B[l].h,
                                      .brk = B[l].brk};
                    pd_mjb_set_lane(b, l, &ln, &err);
                }
            pd_mjb_run(b, 1, NULL, NULL);
            for (int l = 0; l < PD_MJB_LANES; l++) {
                int restarted = l % 2 && k >= RESTART;
                long s = restarted ? k - RESTART : k;
                if (s >= NSTEP)
                    continue;
                const double *ref = &alone[l][restarted][4 * s];
                double got[4] = {b->q[l], b->v[l], src.sys[l].wall ? b->g[l] : 0.0, b->P[l]};
                bad += memcmp(got, ref, sizeof got) != 0;
                contacts += got[3] > 0.0;
                breaks +=
                    isfinite(src.sys[l].brk) && fabs(b->t[l] - src.sys[l].brk) < 0.5 * src.sys[l].h;
                compared++;
            }
        }
        CHECK(ctx, bad == 0, "%s: %ld of the lanes' steps differ from pd_mj's", variants[vi].name,
              bad);
        for (int l = 0; l < PD_MJB_LANES; l++)
            CHECK(ctx, pd_mjb_finite(b, l), "%s: lane %d flagged not finite", variants[vi].name, l);
        free(b);
    }
    CHECK(ctx, compared > 0 && contacts > 100 && breaks > 10,
          "the comparison must cover impacts and breakpoints (%ld steps, %ld impulses, %ld "
          "breakpoints)",
          compared, contacts, breaks);
}

/* A lane that blows up is flagged, the others are not disturbed. */
static void test_engine_batch_flags_nonfinite(pd_test_ctx *ctx)
{
    pd_mjb *b = aligned_alloc(64, sizeof *b);
    pd_mj_opts o = pd_mj_default_opts();
    pd_err err;
    o.theta = 0.0; /* explicit, unstable for h w0 > 2 */
    o.allow_unstable = 1;
    if (!CHECK(ctx, b && !pd_mjb_init(b, &o, NULL, NULL, &err), "init: %s", err.msg)) {
        free(b);
        return;
    }
    pd_mjb_lane calm = {.M = 1.0, .K = 1.0, .h = 0.01, .brk = INFINITY};
    pd_mjb_lane wild = {.M = 1.0, .K = 1e6, .h = 0.01, .brk = INFINITY};
    for (int l = 0; l < PD_MJB_LANES; l++)
        pd_mjb_set_lane(b, l, l == 3 ? &wild : &calm, &err);
    b->q[3] = 1e-3; /* a disturbance that grows (the state is the caller's to set) */
    pd_mjb_run(b, 2000, NULL, NULL);
    for (int l = 0; l < PD_MJB_LANES; l++)
        CHECK(ctx, pd_mjb_finite(b, l) == (l != 3), "lane %d: finite %d", l, pd_mjb_finite(b, l));
    pd_mjb_lane bad = calm;
    bad.h = -1.0;
    CHECK(ctx, pd_mjb_set_lane(b, 0, &bad, &err) == PD_EINVAL && strstr(err.msg, "h > 0"),
          "a negative step is refused: %s", err.msg);
    o.theta = 0.3;
    o.allow_unstable = 0;
    CHECK(ctx, pd_mjb_init(b, &o, NULL, NULL, &err) == PD_EINVAL && strstr(err.msg, "theta"),
          "theta outside [1/2, 1] is refused: %s", err.msg);
    free(b);
}

/* ---- the dense factor on badly scaled matrices (issue 19) ---------------- */

#define SCALED_N 6
#define SCALED_SOLVE_TOL                                                                           \
    1e-12 /* relative error of a solve of a well-conditioned-
                                  after-scaling system: about cond(B) n eps */

/* A row-diagonally-dominant B: off-diagonal entries in [-0.1, 0.1), unit
 * diagonal (cond(B) <= 1.5 / 0.5 = 3 in the infinity norm). */
static void scaled_base(uint64_t *seed, double *B)
{
    for (int j = 0; j < SCALED_N; j++)
        for (int i = 0; i < SCALED_N; i++)
            B[i + j * SCALED_N] = i == j ? 1.0 : 0.2 * pd_test_uniform(seed) - 0.1;
}

/* x from the factors of A (n x n, in LU, perm) for b = A x: max_i |dx_i| w_i
 * over max_i |x_i| w_i (w = NULL: ones). */
static double scaled_solve_error(int n, const double *A, const double *LU, const int *perm,
                                 const double *x, const double *w)
{
    double b[SCALED_N], num = 0.0, den = 0.0;
    for (int i = 0; i < n; i++) {
        b[i] = 0.0;
        for (int j = 0; j < n; j++)
            b[i] += A[i + j * n] * x[j];
    }
    pd_dense_lu_solve(n, LU, n, perm, b);
    for (int i = 0; i < n; i++) {
        num = fmax(num, fabs(b[i] - x[i]) * (w ? w[i] : 1.0));
        den = fmax(den, fabs(x[i]) * (w ? w[i] : 1.0));
    }
    return num / den;
}

/* pd_dense_lu judges a pivot against the scale of its own row: matrices
 * with entries from 1e-6 to 1e12 that are diagonally dominant once scaled
 * factor and solve to 1e-12 (the global floor 1e-14 max|A| = 1e-2 refused
 * every pivot of the small rows); singular ones are still refused. */
static void test_engine_dense_lu_scaled(pd_test_ctx *ctx)
{
    const double s2[SCALED_N] = {1e12, 1e-6, 1e3, 1.0, 1e9, 1e-3}; /* the diagonal's scales */
    uint64_t seed = 19;
    double B[SCALED_N * SCALED_N], A[SCALED_N * SCALED_N], LU[SCALED_N * SCALED_N];
    double x[SCALED_N], s[SCALED_N];
    int perm[SCALED_N], n = SCALED_N;
    for (int i = 0; i < n; i++)
        s[i] = sqrt(s2[i]);
    for (int trial = 0; trial < 20; trial++) {
        scaled_base(&seed, B);
        for (int i = 0; i < n; i++)
            x[i] = 2.0 * pd_test_uniform(&seed) - 1.0;
        /* rows scaled: A = diag(s2) B, entries 1e-7 .. 1e12; x itself to 1e-12 */
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++)
                A[i + j * n] = s2[i] * B[i + j * n];
        memcpy(LU, A, sizeof A);
        int rc = pd_dense_lu(n, LU, n, perm, 1e-14);
        double err = rc ? INFINITY : scaled_solve_error(n, A, LU, perm, x, NULL);
        CHECK(ctx, rc == PD_OK && err <= SCALED_SOLVE_TOL,
              "trial %d, rows scaled 1e-6 .. 1e12: status %d, relative error %.3g", trial, rc, err);
        /* symmetric scaling, as What = M + ... of a scene: A = S B S, the
         * diagonal 1e-6 .. 1e12; the answer to 1e-12 in the scaled norm
         * max |s_i dx_i| / max |s_i x_i| (x_i = y_i / s_i, y of order one) */
        double y[SCALED_N];
        for (int j = 0; j < n; j++) {
            y[j] = x[j] / s[j];
            for (int i = 0; i < n; i++)
                A[i + j * n] = s[i] * B[i + j * n] * s[j];
        }
        memcpy(LU, A, sizeof A);
        rc = pd_dense_lu(n, LU, n, perm, 1e-14);
        err = rc ? INFINITY : scaled_solve_error(n, A, LU, perm, y, s);
        CHECK(ctx, rc == PD_OK && err <= SCALED_SOLVE_TOL,
              "trial %d, S B S with S^2 1e-6 .. 1e12: status %d, scaled relative error %.3g", trial,
              rc, err);
    }
    /* singular: S G G^T S with G 6 x 5 (rank 5), a zero row, equal rows */
    for (int trial = 0; trial < 20; trial++) {
        double G[SCALED_N * (SCALED_N - 1)];
        for (int k = 0; k < n * (n - 1); k++)
            G[k] = 2.0 * pd_test_uniform(&seed) - 1.0;
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                double g = 0.0;
                for (int k = 0; k < n - 1; k++)
                    g += G[i + k * n] * G[j + k * n];
                A[i + j * n] = s[i] * g * s[j];
            }
        int rc = pd_dense_lu(n, A, n, perm, 1e-14);
        CHECK(ctx, rc == PD_ESINGULAR, "trial %d: S G G^T S of rank 5 factored (status %d)", trial,
              rc);
    }
    scaled_base(&seed, B);
    memcpy(A, B, sizeof A);
    for (int j = 0; j < n; j++)
        A[3 + j * n] = 0.0;
    CHECK(ctx, pd_dense_lu(n, A, n, perm, 1e-14) == PD_ESINGULAR, "a zero row factored");
    double E[4] = {1e12, 1e12, 1e-6, 1e-6}; /* columns (1e12, 1e12), (1e-6, 1e-6) */
    CHECK(ctx, pd_dense_lu(2, E, 2, perm, 1e-14) == PD_ESINGULAR, "equal rows factored");
    double Z[4] = {0.0, 0.0, 0.0, 0.0};
    CHECK(ctx, pd_dense_lu(2, Z, 2, perm, 1e-14) == PD_ESINGULAR, "the zero matrix factored");
}

/* Where D's entries land in a gathered D_II (pd_factor_delassus_at and the
 * map of pd_factor_delassus_csc), by the dense and the CHOLMOD factors, on
 * a row of 5 dofs and 6 contacts (a wall each end): for every pair of the
 * chosen contacts (1, 2, 3, 5), D_ab's place through the map holds the dense
 * gather's D_ab; the pairs that share no dof have no place in CHOLMOD's D
 * (-1), and the dense D's exact zeros none either. */
static void test_engine_delassus_map(pd_test_ctx *ctx)
{
    enum { N = 5, MC = 6, NI = 4 };
    double M[N * N] = {0}, K[N * N] = {0}, W[N * MC] = {0}, g0[MC], e[MC];
    for (int i = 0; i < N; i++) {
        M[i * (N + 1)] = 1.0 + 0.3 * i;
        K[i * (N + 1)] = 4.0 + i;
    }
    for (int a = 0; a < MC; a++) { /* contact a between dof a - 1 and dof a (walls at the ends) */
        if (a > 0)
            W[(a - 1) + a * N] = 1.0;
        if (a < N)
            W[a + a * N] = -1.0;
        g0[a] = 0.01;
        e[a] = 0.5;
    }
    pd_model md = {.n = N,
                   .m = MC,
                   .M = pd_matrix_dense(N, N, M),
                   .C = pd_matrix_zero(N, N),
                   .K = pd_matrix_dense(N, N, K),
                   .W = pd_matrix_dense(N, MC, W),
                   .g0 = g0,
                   .e = e};
    const int idx[NI] = {1, 2, 3, 5};
    const pd_factor_kind kinds[2] = {PD_FACTOR_DENSE, PD_FACTOR_CHOLMOD};
    for (int k = 0; k < 2; k++) {
        pd_err err;
        pd_factor *f = pd_factor_alloc(&md, 0.01, 0.5, kinds[k], &err);
        if (!CHECK(ctx, f != NULL, "%s", err.msg))
            continue;
        double Dd[NI * NI], val[MC * MC];
        int colptr[NI + 1], rowind[MC * MC], map[MC * MC];
        pd_factor_delassus_dense(f, idx, NI, Dd);
        pd_factor_delassus_csc(f, idx, NI, colptr, rowind, val, map);
        int ok = 1, absent = 0;
        for (int c = 0; c < NI; c++)
            for (int r = 0; r < NI; r++) {
                long at = pd_factor_delassus_at(f, idx[c], idx[r]);
                int share = abs(idx[c] - idx[r]) <= 1; /* neighbours share a dof */
                if (!share) {
                    absent += at < 0;
                    ok &= at < 0 || Dd[r + c * NI] == 0.0;
                    continue;
                }
                ok &= at >= 0 && val[map[at]] == Dd[r + c * NI] && rowind[map[at]] == r &&
                      map[at] >= colptr[c] && map[at] < colptr[c + 1];
            }
        CHECK(ctx, ok && absent == 8, "%s factor: places %s, %d absent pairs (8)",
              k ? "cholmod" : "dense", ok ? "right" : "wrong", absent);
        pd_factor_free(f);
    }
}

/* The scene of issue 19 -- two oscillators of 1e12 kg (T0 = 0.4 s) and
 * 1e-6 kg (T0 = 1.2 s), one contact between them -- factors densely
 * (What = diag(1e12, 1e-6) (1 + ...), refused as singular before): What^-1
 * and D = W^T What^-1 W to 1e-12 relative, and Moreau–Jean runs it.  A
 * singular What (M of rank 1, K = C = 0) is still refused. */
static void test_engine_dense_factor_scaled(pd_test_ctx *ctx)
{
    const double mass[2] = {1e12, 1e-6}, T0[2] = {0.4, 1.2}, xi = 0.05, h = 2e-4, theta = 0.5;
    double M[4] = {0}, K[4] = {0}, C[4] = {0}, W[2] = {-1.0, 1.0}, g0 = 0.02, e = 0.5;
    double what[2];
    for (int i = 0; i < 2; i++) {
        double w0 = 2.0 * PD_PI / T0[i];
        M[i * 3] = mass[i];
        K[i * 3] = mass[i] * w0 * w0;
        C[i * 3] = 2.0 * xi * w0 * mass[i];
        what[i] = M[i * 3] + h * theta * C[i * 3] + h * theta * h * theta * K[i * 3];
    }
    pd_model md = {.n = 2,
                   .m = 1,
                   .M = pd_matrix_dense(2, 2, M),
                   .C = pd_matrix_dense(2, 2, C),
                   .K = pd_matrix_dense(2, 2, K),
                   .W = pd_matrix_dense(2, 1, W),
                   .g0 = &g0,
                   .e = &e};
    pd_err err;
    pd_factor *f = pd_factor_alloc(&md, h, theta, PD_FACTOR_DENSE, &err);
    CHECK(ctx, f != NULL, "the dense factor refused the scene: %s", f ? "" : err.msg);
    if (f) {
        double x[2] = {3.0, -2.0}, D, Dwant = 1.0 / what[0] + 1.0 / what[1];
        int idx = 0;
        pd_factor_solve(f, x);
        for (int i = 0; i < 2; i++)
            CHECK(ctx, fabs(x[i] * what[i] - (i ? -2.0 : 3.0)) <= 1e-12 * fabs(x[i] * what[i]),
                  "What^-1 b, row %d: %.17g, want %.17g", i, x[i], (i ? -2.0 : 3.0) / what[i]);
        pd_factor_delassus_dense(f, &idx, 1, &D);
        CHECK(ctx, fabs(D - Dwant) <= 1e-12 * Dwant, "D = %.17g, want %.17g", D, Dwant);
        pd_factor_free(f);
    }
    pd_mj_opts o = pd_mj_default_opts();
    o.h = h;
    pd_mj *mj = pd_mj_alloc(&md, &o, &err);
    double v0[2] = {1.0, -1.0};
    int rc = mj ? pd_mj_reset(mj, 0.0, NULL, v0, &err) : err.status;
    if (!rc)
        rc = pd_mj_run(mj, 1000, NULL, NULL, &err);
    CHECK(ctx, rc == PD_OK && !strcmp(pd_mj_factor_name(mj), "dense"),
          "Moreau-Jean on the scene: %s", rc ? err.msg : pd_mj_factor_name(mj));
    pd_mj_free(mj);
    double Ms[4] = {1e12, 1e12, 1e12, 1e12};
    md.M = pd_matrix_dense(2, 2, Ms);
    md.C = pd_matrix_zero(2, 2);
    md.K = pd_matrix_zero(2, 2);
    f = pd_factor_alloc(&md, h, theta, PD_FACTOR_DENSE, &err);
    CHECK(ctx, f == NULL && err.status == PD_ESINGULAR && strstr(err.msg, "singular"),
          "a singular What factored (%s)", f ? "no error" : err.msg);
    pd_factor_free(f);
}

/* ---- breakpoints closer than a step ---------------------------------------------- */

/* F(t) = F_k on [b_k, b_k+1): a load jumping at every breakpoint; side -1
 * the left limit, +1 the right one (they differ only at the b_k). */
typedef struct jumpy_force {
    const double *b, *F; /* nb breakpoints, nb values */
    int nb;
    long right_calls; /* right limits asked */
} jumpy_force;

static void jumpy_at(double t, int side, double *F, void *vctx)
{
    jumpy_force *j = vctx;
    int k = -1;
    while (k + 1 < j->nb && (side > 0 ? j->b[k + 1] <= t : j->b[k + 1] < t))
        k++;
    F[0] = k < 0 ? 0.0 : j->F[k];
    j->right_calls += side > 0;
}

/* The states of a run, step by step. */
typedef struct step_log {
    double q[400], v[400], P[400];
    int n;
} step_log;

static int log_step(const pd_state *s, void *vctx)
{
    step_log *l = vctx;
    if (l->n < 400) {
        l->q[l->n] = s->q[0];
        l->v[l->n] = s->v[0];
        l->P[l->n++] = s->P[0];
    }
    return 0;
}

/* A breakpoint inside a step changes nothing (the step's end sees the load
 * past it as the left limit there), one on a step's end starts the next
 * step from the right limit.  An SDOF on a wall (the scalar kernel) under a
 * load jumping every 0.3 h (h = 0.01 s, 300 steps, 1000 breakpoints, one in
 * ten on a step's end): the run told every breakpoint equals, to the bit at
 * every step (the same operations on the same loads), the run told only
 * the 100 on its grid; the right limit is asked at the start (t = 0, one of
 * them) and at the other 99 only, not at the ends of steps that merely
 * contain one. */
static void test_engine_breaks_inside_steps(pd_test_ctx *ctx)
{
    enum { NB = 1000, NSTEPS = 300 };
    static double b[NB], F[NB], grid_b[NB];
    static step_log all, grid;
    const double h = 0.01;
    int ng = 0;
    for (int k = 0; k < NB; k++) {
        b[k] = (double)k * 0.3 * h;
        F[k] = 50.0 * sin(1.7 * k);
        double j = round(b[k] / h); /* on the grid as pd_mj sees it: within 1e-9 h */
        if (fabs(b[k] - j * h) <= 1e-9 * h)
            grid_b[ng++] = b[k];
    }
    double M = 1.0, K = 4.0 * PD_PI * PD_PI, C = 0.1, W = -1.0, g0 = 0.05, e = 0.5;
    int cp[2] = {0, 1}, ri[1] = {0};
    jumpy_force fine = {.b = b, .F = F, .nb = NB};
    pd_model md = {.n = 1,
                   .m = 1,
                   .M = pd_matrix_dense(1, 1, &M),
                   .C = pd_matrix_dense(1, 1, &C),
                   .K = pd_matrix_dense(1, 1, &K),
                   .W = pd_matrix_csc(1, 1, cp, ri, &W),
                   .g0 = &g0,
                   .e = &e,
                   .force = jumpy_at,
                   .force_ctx = &fine,
                   .breaks = b,
                   .nbreaks = NB};
    pd_mj_opts o = pd_mj_default_opts();
    o.h = h;
    for (int run = 0; run < 2; run++) {
        step_log *l = run ? &grid : &all;
        pd_model m2 = md;
        if (run) { /* the same load, told only the breakpoints on the grid */
            m2.breaks = grid_b;
            m2.nbreaks = ng;
        }
        pd_err err;
        fine.right_calls = 0;
        l->n = 0;
        pd_mj *mj = pd_mj_alloc(&m2, &o, &err);
        int rc = mj ? pd_mj_run(mj, NSTEPS, log_step, l, &err) : -1;
        CHECK(ctx,
              mj && rc == PD_OK && l->n == NSTEPS + 1 && !strcmp(pd_mj_kernel_name(mj), "scalar"),
              "run %d: %s (%d states)", run, mj ? err.msg : "alloc", l->n);
        CHECK(ctx, fine.right_calls == 1 + (ng - 1),
              "run %d: the right limit asked %ld times: at t = 0 and the %d breakpoints on the "
              "grid after it",
              run, fine.right_calls, ng - 1);
        pd_mj_free(mj);
    }
    CHECK(ctx,
          ng == 100 && !memcmp(all.q, grid.q, sizeof all.q) &&
              !memcmp(all.v, grid.v, sizeof all.v) && !memcmp(all.P, grid.P, sizeof all.P),
          "every breakpoint (%d) or only the %d on the grid: the same steps to the bit", NB, ng);
    double worst = 0.0;
    for (int k = 0; k < NSTEPS; k++)
        worst = fmax(worst, fabs(all.P[k]));
    CHECK(ctx, worst > 0.0, "the wall takes impulses (largest %g)", worst);
}

/* A free unit mass (no stiffness, no damping: What = M = 1, so the
 * Delassus number W^2 / What is exactly 1) thrown at a wall, in the scalar
 * kernel and the general one: it leaves at -e times its speed, Newton's
 * law, with the same impulse (1 + e) v. */
static void test_engine_free_unit_mass_rebounds(pd_test_ctx *ctx)
{
    double M = 1.0, K = 0.0, W = -1.0, g0 = 0.01, e = 0.5, v0 = 1.0;
    pd_model md = {.n = 1,
                   .m = 1,
                   .M = pd_matrix_dense(1, 1, &M),
                   .C = pd_matrix_zero(1, 1),
                   .K = pd_matrix_dense(1, 1, &K),
                   .W = pd_matrix_dense(1, 1, &W),
                   .g0 = &g0,
                   .e = &e};
    for (int general = 0; general < 2; general++) {
        pd_err err;
        pd_mj_opts o = pd_mj_default_opts();
        o.h = 1e-3;
        o.kernel = general ? PD_KERNEL_GENERAL : PD_KERNEL_AUTO;
        pd_mj *mj = pd_mj_alloc(&md, &o, &err);
        if (!CHECK(ctx, mj && !pd_mj_reset(mj, 0.0, NULL, &v0, &err), "%s", err.msg)) {
            pd_mj_free(mj);
            continue;
        }
        double P = 0.0;
        for (int k = 0; k < 30 && !pd_mj_step(mj, &err); k++)
            P += pd_mj_state(mj)->P[0];
        const pd_state *st = pd_mj_state(mj);
        CHECK(ctx, fabs(st->v[0] + e * v0) <= 1e-12 && fabs(P - (1.0 + e) * v0) <= 1e-12,
              "%s kernel: v after %.17g (want %g), impulse %.17g (want %g)",
              general ? "general" : "scalar", st->v[0], -e * v0, P, (1.0 + e) * v0);
        pd_mj_free(mj);
    }
}

void suite_engine(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_engine_sdof_closed_form);
    PD_RUN(ctx, test_engine_free_unit_mass_rebounds);
    PD_RUN(ctx, test_engine_scalar_lcp_matches_lemke);
    PD_RUN(ctx, test_engine_two_mass_impact);
    PD_RUN(ctx, test_engine_chain_energy);
    PD_RUN(ctx, test_engine_theta_stability);
    PD_RUN(ctx, test_engine_theta_damped_boundary);
    PD_RUN(ctx, test_engine_failure_is_reported);
    PD_RUN(ctx, test_engine_model_check);
    PD_RUN(ctx, test_engine_no_allocation_in_steps);
    PD_RUN(ctx, test_engine_batch_matches_scalar);
    PD_RUN(ctx, test_engine_batch_flags_nonfinite);
    PD_RUN(ctx, test_engine_dense_lu_scaled);
    PD_RUN(ctx, test_engine_dense_factor_scaled);
    PD_RUN(ctx, test_engine_delassus_map);
    PD_RUN(ctx, test_engine_breaks_inside_steps);
}
