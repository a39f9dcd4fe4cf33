/* test_yield_mj.c — Moreau–Jean's general kernel with yielding springs
 * (engine/mj_yield.c: each slider a complementarity in the step's LCP,
 * solved with the contacts by Lemke):
 *   - one dof against a wall: the same steps as the scalar yielding kernel
 *     (engine/pd_mj1.h, the closed-form LCP in (P, G)), an independent
 *     solution of the same equations;
 *   - springs that never yield: the elastic run bit for bit;
 *   - a two-storey shear building with a soft first storey, pounding a
 *     wall: it converges (dt halved) to Newmark's run at a fine step and
 *     stiff contact, and its steps keep the complementarity of every spring;
 *   - Moreau-Jean to a tolerance refuses yielding springs. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "osc_priv.h"
#include "pd_core.h"
#include "pd_engine.h"
#include "pd_problems.h"
#include "pd_test.h"

#define MAXSTEP 200000

/* A trajectory: q (first dof) and up (first spring) per step. */
typedef struct traj {
    long n;
    double *q, *up;
    double scale; /* q's unit (Le for the oscillator) */
} traj;

static int osc_sample(const pd_osc_sample *s, void *ctx)
{
    traj *t = ctx;
    if (t->n < MAXSTEP) {
        t->q[t->n] = s->u;
        t->up[t->n] = s->up;
        t->n++;
    }
    return 0;
}

static int mj_sample(const pd_state *st, void *ctx)
{
    traj *t = ctx;
    if (t->n < MAXSTEP) {
        t->q[t->n] = st->q[0] * t->scale;
        t->up[t->n] = st->up ? st->up[0] * t->scale : 0.0;
        t->n++;
    }
    return 0;
}

/* One dof against a wall: the general kernel's steps (Lemke on the LCP of
 * the contact and the spring) against the scalar kernel's (the closed form)
 * over 15 cases (eps 0, 0.5, 1; alpha 0, 0.1, 0.3; Piy 0.1, 0.4; Pi3 0.05
 * and 0.3): u and up within 1e-9 of umax at every step (measured 1.3e-14). */
static void test_yield_mj_general_equals_scalar(pd_test_ctx *ctx)
{
    traj a = {0}, b = {0};
    a.q = malloc(MAXSTEP * sizeof(double));
    a.up = malloc(MAXSTEP * sizeof(double));
    b.q = malloc(MAXSTEP * sizeof(double));
    b.up = malloc(MAXSTEP * sizeof(double));
    double worst = 0.0;
    for (int k = 0; k < 15 && a.q && a.up && b.q && b.up; k++) {
        pd_osc c = pd_osc_default();
        c.Pi2 = 0.8 + 0.3 * (k % 4);
        c.Pi3 = k % 2 ? 0.05 : 0.3;
        c.eps = 0.5 * (k % 3);
        c.alpha = 0.1 * (k % 4 == 3 ? 3 : k % 3);
        c.Piy = k % 5 < 3 ? 0.1 : 0.4;
        pd_run_opts o = pd_run_default_opts();
        o.method = PD_METHOD_MOREAU;
        pd_osc_result r;
        pd_err e;
        a.n = b.n = 0;
        if (!CHECK(ctx, pd_osc_run(&c, &o, osc_sample, &a, &r, &e) == PD_OK, "%s", e.msg))
            continue;
        /* the same model, the general kernel (pd_osc_run's step and span) */
        double brk = PD_TWO_PI, Le = pd_osc_Le(&c);
        pd_osc_coefs cf;
        pd_model md = pd_osc_model(&c, 0, &cf, &brk, 1);
        double S = 1.0, ks = (1.0 - c.alpha) * cf.K, uy = c.Piy;
        md.ns = 1;
        md.S = pd_matrix_dense(1, 1, &S);
        md.ks = &ks;
        md.uy = &uy;
        pd_mj_opts mo = pd_mj_default_opts();
        mo.h = PD_TWO_PI * r.dt / c.Tp;
        mo.kernel = PD_KERNEL_GENERAL;
        b.scale = Le;
        pd_mj *mj = pd_mj_alloc(&md, &mo, &e);
        if (!CHECK(ctx, mj != NULL, "%s", e.msg))
            continue;
        long steps = pd_steps_for(r.tend, r.dt);
        int rc = pd_mj_run(mj, steps, mj_sample, &b, &e);
        pd_mj_free(mj);
        if (!CHECK(ctx, rc == PD_OK && a.n == b.n, "case %d: %s (%ld and %ld samples)", k,
                   rc ? e.msg : "", a.n, b.n))
            continue;
        double d = 0.0;
        for (long i = 0; i < a.n; i++)
            d = fmax(d, fmax(fabs(a.q[i] - b.q[i]), fabs(a.up[i] - b.up[i])));
        d /= r.umax;
        worst = fmax(worst, d);
        CHECK(ctx, d <= 1e-9 && r.n_yield > 0,
              "case %d: the kernels %.3g of umax apart (%ld onsets)", k, d, r.n_yield);
    }
    printf("    the general kernel against the scalar one: %.2g of umax at most\n", worst);
    free(a.q);
    free(a.up);
    free(b.q);
    free(b.up);
}

/* A two-storey shear building (unit masses, storey stiffnesses 40 and 160,
 * the first soft: uy 0.02, alpha 0.05; the second uy 0.05, alpha 0.1;
 * damping 0.01 K) under a ground pulse 0.6 sin(2 t) for t < pi, its roof
 * 0.01 from a wall (e 0.5): the first storey reaches 7 uy, the roof pounds
 * 6 times. */
typedef struct bldg {
    double M[4], C[4], K[4], W[2], S[4], ks[2], uy[2], g0, e;
    double peak[2], up[2], zmax; /* measured: |drift| peaks, offsets at the end, max |z| / uy */
    double zslide;               /* max ||z| / uy - 1| over the steps a spring slid in */
    long slides;
} bldg;

static void bldg_force(double t, int side, double *F, void *ctx)
{
    (void)ctx;
    int on = side < 0 ? t <= PD_PI : t < PD_PI; /* the pulse's end from either side */
    F[0] = F[1] = on ? -0.6 * sin(2.0 * t) : 0.0;
}

static pd_model bldg_model(bldg *b, const double *brk)
{
    const double k1 = 40.0, k2 = 160.0;
    *b = (bldg){.M = {1.0, 0.0, 0.0, 1.0},
                .K = {k1 + k2, -k2, -k2, k2},
                .W = {0.0, -1.0},
                .S = {1.0, 0.0, -1.0, 1.0},
                .ks = {0.95 * k1, 0.9 * k2},
                .uy = {0.02, 0.05},
                .g0 = 0.01,
                .e = 0.5};
    for (int i = 0; i < 4; i++)
        b->C[i] = 0.01 * b->K[i];
    return (pd_model){.n = 2,
                      .m = 1,
                      .M = pd_matrix_dense(2, 2, b->M),
                      .C = pd_matrix_dense(2, 2, b->C),
                      .K = pd_matrix_dense(2, 2, b->K),
                      .W = pd_matrix_dense(2, 1, b->W),
                      .g0 = &b->g0,
                      .e = &b->e,
                      .force = bldg_force,
                      .breaks = brk,
                      .nbreaks = 1,
                      .ns = 2,
                      .S = pd_matrix_dense(2, 2, b->S),
                      .ks = b->ks,
                      .uy = b->uy};
}

/* Per step: the drifts' peaks, the springs' |z| / uy, the offsets. */
static int bldg_note(const pd_state *st, void *ctx)
{
    bldg *b = ctx;
    double d[2] = {st->q[0], st->q[1] - st->q[0]};
    for (int j = 0; j < 2; j++) {
        double up = st->up ? st->up[j] : 0.0, z = fabs(d[j] - up) / b->uy[j];
        if (up != b->up[j]) { /* it slid: its z on the yield level */
            b->zslide = fmax(b->zslide, fabs(z - 1.0));
            b->slides++;
        }
        b->peak[j] = fmax(b->peak[j], fabs(d[j]));
        b->up[j] = up;
        b->zmax = fmax(b->zmax, z);
    }
    return 0;
}

/* The largest distance of the drifts' peaks and the offsets, over uy1. */
static double bldg_dist(const bldg *a, const bldg *b)
{
    double d = 0.0;
    for (int j = 0; j < 2; j++)
        d = fmax(d, fmax(fabs(a->peak[j] - b->peak[j]), fabs(a->up[j] - b->up[j])));
    return d / a->uy[0];
}

/* Moreau-Jean at h over [0, 6] (the figures into *out); 1 when it ran. */
static int bldg_mj(pd_test_ctx *ctx, double h, double uy_scale, bldg *out)
{
    double brk = PD_PI;
    pd_model md = bldg_model(out, &brk);
    out->uy[0] *= uy_scale;
    out->uy[1] *= uy_scale;
    pd_mj_opts mo = pd_mj_default_opts();
    mo.h = h;
    pd_err e;
    pd_mj *mj = pd_mj_alloc(&md, &mo, &e);
    if (!CHECK(ctx, mj != NULL, "%s", e.msg))
        return 0;
    int rc = pd_mj_run(mj, pd_steps_for(6.0, h), bldg_note, out, &e);
    pd_mj_free(mj);
    return CHECK(ctx, rc == PD_OK, "h %g: %s", h, e.msg);
}

/* Newmark with Newton at kc, h = min(2.5e-5, 0.3 / sqrt(kc)); 1 when it ran. */
static int bldg_newmark(pd_test_ctx *ctx, double kc, bldg *out, long *failures)
{
    double brk = PD_PI;
    pd_model md = bldg_model(out, &brk);
    pd_penalty_opts po = pd_penalty_default_opts();
    po.stepper = "newmark";
    po.kc = kc;
    po.h = fmin(2.5e-5, 0.3 / sqrt(kc));
    po.on_step = bldg_note;
    po.on_step_ctx = out;
    pd_penalty_result pr;
    pd_err e;
    int rc = pd_penalty_run(&md, 0.0, NULL, NULL, 6.0, &po, NULL, NULL, &pr, &e);
    *failures = pr.newton_failures;
    return CHECK(ctx, rc == PD_OK, "newmark kc %g: %s", kc, e.msg);
}

/* The soft storey yields, the roof pounds.  Moreau-Jean converges as h is
 * quartered (h 2e-3, 5e-4, 1.25e-4 against 3.125e-5: measured 1.4e-2,
 * 3.6e-3, 1.1e-3 of uy1 in the drifts' peaks and the offsets; each at
 * least twice closer), every step keeps |z| <= uy (1 + 1e-9); Newmark
 * with Newton comes to it as kc grows 1e5, 1e7, 1e9 (its penetration:
 * measured 4.4e-2, 6.2e-3, 3.9e-3 of uy1; each closer, the last within
 * 1e-2), with no Newton failure. */
static void test_yield_mj_soft_storey(pd_test_ctx *ctx)
{
    bldg fine, run;
    if (!bldg_mj(ctx, 3.125e-5, 1.0, &fine))
        return;
    double prev = HUGE_VAL;
    for (int k = 0; k < 3; k++) {
        double h = 2e-3 / pow(4.0, k);
        if (!bldg_mj(ctx, h, 1.0, &run))
            return;
        double d = bldg_dist(&fine, &run);
        printf("    Moreau-Jean h %.3g: %.3g uy1 from h 3.1e-5 (|z| / uy <= 1 + %.2g; %ld slides "
               "on the level to %.2g)\n",
               h, d, run.zmax - 1.0, run.slides, run.zslide);
        CHECK(ctx,
              d <= 0.5 * prev && run.zmax <= 1.0 + 1e-9 && run.zslide <= 1e-12 && run.slides > 0,
              "h %g: %.3g (was %.3g), |z| / uy %.17g, a slide off its level by %.3g", h, d, prev,
              run.zmax, run.zslide);
        prev = d;
    }
    CHECK(ctx, fine.up[0] > 0.1 * fine.uy[0] && fine.peak[0] > 5.0 * fine.uy[0],
          "the soft storey's offset %g and peak drift %g (uy %g): it must yield", fine.up[0],
          fine.peak[0], fine.uy[0]);
    prev = HUGE_VAL;
    for (int k = 0; k < 3; k++) {
        double kc = 1e5 * pow(100.0, k);
        long failures;
        bldg nm;
        if (!bldg_newmark(ctx, kc, &nm, &failures))
            return;
        double d = bldg_dist(&fine, &nm);
        printf("    Newmark kc %.0e: %.3g uy1 from Moreau-Jean; %ld Newton failures\n", kc, d,
               failures);
        CHECK(ctx, d < prev && failures == 0, "kc %g: %.3g (was %.3g), %ld failures", kc, d, prev,
              failures);
        prev = d;
    }
    CHECK(ctx, prev <= 1e-2, "Newmark at kc 1e9: %.3g uy1 from Moreau-Jean", prev);
}

/* The equations of every Newmark step of the building: M a + C v + K q -
 * S ks up - W lambda = F(t) at each step's end (away from the pulse's end,
 * where a takes F's right limit), |S^T q - up| <= uy, an offset that moved
 * sits on its yield level, and the reported gaps are g0 + W^T q. */
typedef struct nm_check {
    bldg *b;
    double up_prev[2], res, comp, gap;
    long steps, slid;
} nm_check;

static int nm_step_check(const pd_state *st, void *ctx)
{
    nm_check *c = ctx;
    bldg *b = c->b;
    double F[2], q[2] = {st->q[0], st->q[1]}, d[2] = {q[0], q[1] - q[0]};
    bldg_force(st->t, -1, F, NULL);
    double kup[2] = {b->ks[0] * st->up[0], b->ks[1] * st->up[1]}; /* S ks up */
    double sku[2] = {kup[0] - kup[1], kup[1]}, lam = st->P[0];
    double scale = 0.0;
    for (int i = 0; i < 2 && fabs(st->t - PD_PI) > 1e-3; i++) {
        double r = b->M[i + 2 * i] * st->acc[i] - F[i] - sku[i] - b->W[i] * lam;
        double t = fabs(F[i]) + fabs(sku[i]) + fabs(b->W[i] * lam);
        for (int j = 0; j < 2; j++) {
            r += b->C[i + 2 * j] * st->v[j] + b->K[i + 2 * j] * q[j];
            t += fabs(b->C[i + 2 * j] * st->v[j]) + fabs(b->K[i + 2 * j] * q[j]);
        }
        scale = fmax(scale, t);
        c->res = fmax(c->res, fabs(r) / fmax(t, 1e-300));
    }
    for (int j = 0; j < 2; j++) {
        double z = d[j] - st->up[j];
        c->comp = fmax(c->comp, fabs(z) / b->uy[j] - 1.0);
        if (st->up[j] != c->up_prev[j]) { /* it slid: on its level */
            c->comp = fmax(c->comp, fabs(fabs(z) / b->uy[j] - 1.0));
            c->slid++;
        }
        c->up_prev[j] = st->up[j];
    }
    c->gap = fmax(c->gap, fabs(st->g[0] - (b->g0 - q[1])));
    c->steps++;
    return 0;
}

static void test_yield_newmark_step_equations(pd_test_ctx *ctx)
{
    double brk = PD_PI;
    bldg b;
    pd_model md = bldg_model(&b, &brk);
    pd_penalty_opts po = pd_penalty_default_opts();
    po.stepper = "newmark";
    po.kc = 1e5;
    po.h = 0.05; /* coarse: the springs' tangent h^2/4 ks is 6 % of What, Newton's matrix
                    matters */
    nm_check c = {.b = &b};
    po.on_step = nm_step_check;
    po.on_step_ctx = &c;
    pd_penalty_result pr;
    pd_err e;
    if (!CHECK(ctx, pd_penalty_run(&md, 0.0, NULL, NULL, 6.0, &po, NULL, NULL, &pr, &e) == PD_OK,
               "%s", e.msg))
        return;
    printf(
        "    %ld steps, %ld slides: balance %.2g of its terms, |z| / uy - 1 <= %.2g, gaps %.2g\n",
        c.steps, c.slid, c.res, c.comp, c.gap);
    CHECK(ctx, c.res <= 1e-10 && c.comp <= 1e-12 && c.gap <= 1e-15 && c.slid > 20,
          "balance %.3g, complementarity %.3g, gaps %.3g, %ld slides", c.res, c.comp, c.gap,
          c.slid);
}

/* Moreau-Jean's equations of every step of the building at a coarse h
 * (0.05: the springs' tangent (h theta)^2 ks is 6 % of What, the storeys'
 * coupling matters):
 *   What (v+ - v) = h (F_theta - C v - K (q + h theta v)) + h S ks up
 *                   + h theta S ks (up+ - up) + W P,
 * What = M + h theta C + (h theta)^2 K, theta 1/2 (away from the pulse's
 * end), to 1e-12 of its terms; every slide on its level. */
typedef struct mj_check {
    bldg *b;
    double h, q[2], v[2], up[2], t, res, zslide;
    long steps, slides;
} mj_check;

static int mj_step_check(const pd_state *st, void *ctx)
{
    mj_check *c = ctx;
    bldg *b = c->b;
    double h = c->h, th = 0.5, F0[2], F1[2];
    if (st->step > 0 && fabs(st->t - PD_PI) > 2.0 * h && fabs(c->t - PD_PI) > 2.0 * h) {
        bldg_force(c->t, +1, F0, NULL);
        bldg_force(st->t, -1, F1, NULL);
        double dup[2] = {st->up[0] - c->up[0], st->up[1] - c->up[1]};
        for (int i = 0; i < 2; i++) {
            double lhs = 0.0, rhs = h * (th * F1[i] + (1.0 - th) * F0[i]), scale = fabs(rhs);
            for (int j = 0; j < 2; j++) {
                double What =
                    b->M[i + 2 * j] + h * th * b->C[i + 2 * j] + h * th * h * th * b->K[i + 2 * j];
                lhs += What * (st->v[j] - c->v[j]);
                double f = -h * (b->C[i + 2 * j] * c->v[j] +
                                 b->K[i + 2 * j] * (c->q[j] + h * th * c->v[j])) +
                           b->S[i + 2 * j] * b->ks[j] * (h * c->up[j] + h * th * dup[j]);
                rhs += f;
                scale += fabs(What * st->v[j]) + fabs(f);
            }
            rhs += b->W[i] * st->P[0];
            c->res = fmax(c->res, fabs(lhs - rhs) / scale);
        }
        for (int j = 0; j < 2; j++) {
            double d = j ? st->q[1] - st->q[0] : st->q[0];
            if (dup[j] != 0.0) {
                c->zslide = fmax(c->zslide, fabs(fabs(d - st->up[j]) / b->uy[j] - 1.0));
                c->slides++;
            }
        }
        c->steps++;
    }
    c->t = st->t;
    for (int j = 0; j < 2; j++) {
        c->q[j] = st->q[j];
        c->v[j] = st->v[j];
        c->up[j] = st->up[j];
    }
    return 0;
}

static void test_yield_mj_step_equations(pd_test_ctx *ctx)
{
    for (int wall = 1; wall >= 0; wall--) { /* without it a storey slides with no contact */
        double brk = PD_PI;
        bldg b;
        pd_model md = bldg_model(&b, &brk);
        md.m = wall;
        pd_mj_opts mo = pd_mj_default_opts();
        mo.h = 0.05;
        mj_check c = {.b = &b, .h = mo.h};
        pd_err e;
        pd_mj *mj = pd_mj_alloc(&md, &mo, &e);
        if (!CHECK(ctx, mj != NULL, "%s", e.msg))
            return;
        int rc = pd_mj_run(mj, 120, mj_step_check, &c, &e);
        pd_mj_free(mj);
        printf("    %s: %ld steps, %ld slides: the step's balance to %.2g of its terms, slides "
               "on their level to %.2g\n",
               wall ? "the wall" : "no wall", c.steps, c.slides, c.res, c.zslide);
        CHECK(ctx, rc == PD_OK && c.res <= 1e-12 && c.zslide <= 1e-12 && c.slides > 10,
              "%s: balance %.3g, slides off their level %.3g, %ld slides: %s",
              wall ? "wall" : "no wall", c.res, c.zslide, c.slides, rc ? e.msg : "");
    }
}

/* Springs that never yield (uy 1e6 times): the run of the model without
 * them, bit for bit; Moreau-Jean to a tolerance refuses them. */
static void test_yield_mj_unreached_is_elastic(pd_test_ctx *ctx)
{
    bldg far, el;
    if (!bldg_mj(ctx, 1e-3, 1e6, &far))
        return;
    double brk = PD_PI;
    pd_model md = bldg_model(&el, &brk);
    md.ns = 0;
    pd_mj_opts mo = pd_mj_default_opts();
    mo.h = 1e-3;
    pd_err e;
    pd_mj *mj = pd_mj_alloc(&md, &mo, &e);
    if (!CHECK(ctx, mj != NULL, "%s", e.msg))
        return;
    int rc = pd_mj_run(mj, pd_steps_for(6.0, 1e-3), bldg_note, &el, &e);
    pd_mj_free(mj);
    CHECK(ctx,
          rc == PD_OK && !memcmp(far.peak, el.peak, sizeof far.peak) && far.up[0] == 0.0 &&
              far.up[1] == 0.0,
          "peaks %.17g, %.17g against %.17g, %.17g", far.peak[0], far.peak[1], el.peak[0],
          el.peak[1]);
    /* the dense LCP capped at 1 unknown: the building's springs share a dof,
     * no Gauss-Seidel for them: refused, naming the cap, the rounds (ns + 1)
     * and newmark */
    md = bldg_model(&el, &brk);
    mo.yield_lcp_max = 1;
    mj = pd_mj_alloc(&md, &mo, &e);
    if (CHECK(ctx, mj != NULL, "%s", e.msg)) {
        rc = pd_mj_run(mj, pd_steps_for(6.0, 1e-3), NULL, NULL, &e);
        CHECK(ctx,
              rc == PD_EBUDGET && strstr(e.msg, "at most 1 in one LCP, 3 rounds") &&
                  strstr(e.msg, "newmark"),
              "a capped LCP: %d, %s", rc, e.msg);
        pd_mj_free(mj);
    }
    mo.yield_lcp_max = 0;
    mo.rtol = 1e-3;
    mj = pd_mj_alloc(&md, &mo, &e);
    CHECK(ctx, mj == NULL && e.status == PD_EINVAL && strstr(e.msg, "tolerance"),
          "rtol with yielding springs: %s", mj ? "accepted" : e.msg);
    pd_mj_free(mj);
}

/* A spring on the drift 2 q with uy 2 uy0 and ks ks0 / 4 is the spring on q
 * with uy0 and ks0 (its offset twice): the general kernel's steps of both
 * on the one-dof oscillator against a wall, in and out of contact, within
 * 1e-12 of umax (measured 1e-15), the offsets in ratio 2. */
static void test_yield_mj_spring_scale(pd_test_ctx *ctx)
{
    pd_osc c = pd_osc_default();
    c.Pi2 = 1.3;
    c.Pi3 = 0.1;
    c.Piy = 0.2;
    c.alpha = 0.1;
    double brk = PD_TWO_PI;
    traj t[2] = {{0}, {0}};
    for (int k = 0; k < 2; k++) {
        t[k].q = malloc(MAXSTEP * sizeof(double));
        t[k].up = malloc(MAXSTEP * sizeof(double));
        t[k].scale = 1.0;
    }
    for (int k = 0; k < 2 && t[k].q && t[k].up; k++) {
        pd_osc_coefs cf;
        pd_model md = pd_osc_model(&c, 0, &cf, &brk, 1);
        double S = k ? 2.0 : 1.0, ks = (1.0 - c.alpha) * cf.K / (S * S), uy = c.Piy * S;
        md.ns = 1;
        md.S = pd_matrix_dense(1, 1, &S);
        md.ks = &ks;
        md.uy = &uy;
        pd_mj_opts mo = pd_mj_default_opts();
        mo.h = 2e-3;
        pd_err e;
        pd_mj *mj = pd_mj_alloc(&md, &mo, &e);
        if (!CHECK(ctx, mj != NULL, "%s", e.msg))
            break;
        CHECK(ctx, pd_mj_run(mj, 8000, mj_sample, &t[k], &e) == PD_OK, "%s", e.msg);
        pd_mj_free(mj);
    }
    double d = 0.0, umax = 0.0, upmax = 0.0;
    for (long i = 0; i < t[0].n && i < t[1].n; i++) {
        umax = fmax(umax, fabs(t[0].q[i]));
        upmax = fmax(upmax, fabs(t[0].up[i]));
        d = fmax(d, fmax(fabs(t[0].q[i] - t[1].q[i]), fabs(2.0 * t[0].up[i] - t[1].up[i])));
    }
    printf("    the spring on 2 q against the one on q: %.2g of umax (offsets up to %.3g)\n",
           d / umax, upmax);
    CHECK(ctx, t[0].n == t[1].n && t[0].n > 1000 && d <= 1e-12 * umax && upmax > 0.0,
          "%.3g of umax apart over %ld and %ld steps", d / umax, t[0].n, t[1].n);
    for (int k = 0; k < 2; k++) {
        free(t[k].q);
        free(t[k].up);
    }
}

void suite_yield_mj(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_yield_mj_spring_scale);
    PD_RUN(ctx, test_yield_mj_general_equals_scalar);
    PD_RUN(ctx, test_yield_mj_soft_storey);
    PD_RUN(ctx, test_yield_newmark_step_equations);
    PD_RUN(ctx, test_yield_mj_step_equations);
    PD_RUN(ctx, test_yield_mj_unreached_is_elastic);
}
