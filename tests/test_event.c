/* test_event.c — the general event-driven reference (engine/event_general.c) against
 * the exact one-wall reference, Newton's law, invariants and Moreau–Jean. */
#include <malloc.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_engine.h"
#include "pd_test.h"

#define TWO_PI 6.283185307179586476925286766559

/* ---- the one-wall oscillator as a general model (dimensionless: wp = ap = 1) */

typedef struct osc_case {
    int cosine, dir;
    double Pi2, Pi3, eps, xi;
} osc_case;

typedef struct osc_model {
    osc_case c;
    double M, C, K, W, g0, e, brk;
    pd_model md;
} osc_model;

/* f(t) = dir sin t | dir cos t on [0, 2 pi), 0 after; the right limit at 2 pi is 0. */
static void pulse_force(double t, int side, double *F, void *ctx)
{
    const osc_case *c = ctx;
    if (t > TWO_PI || (t == TWO_PI && side > 0))
        F[0] = 0.0;
    else
        F[0] = c->dir * (c->cosine ? cos(t) : sin(t));
}

static void osc_setup(osc_model *om, const osc_case *c)
{
    om->c = *c;
    om->M = 1.0;
    om->C = 2.0 * c->xi * c->Pi2;
    om->K = c->Pi2 * c->Pi2;
    om->W = -1.0;
    om->g0 = c->Pi3;
    om->e = c->eps;
    om->brk = TWO_PI;
    om->md = (pd_model){.n = 1,
                        .m = 1,
                        .M = pd_matrix_dense(1, 1, &om->M),
                        .C = pd_matrix_dense(1, 1, &om->C),
                        .K = pd_matrix_dense(1, 1, &om->K),
                        .W = pd_matrix_dense(1, 1, &om->W),
                        .g0 = &om->g0,
                        .e = &om->e,
                        .force = pulse_force,
                        .force_ctx = &om->c,
                        .breaks = &om->brk,
                        .nbreaks = 1};
}

/* Every reported state of a one-dof run. */
typedef struct trace {
    long n, cap;
    double *t, *x, *v, *P;
    unsigned char *act;
} trace;

static int record(const pd_state *s, void *ctx)
{
    trace *r = ctx;
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 256;
        r->t = realloc(r->t, (size_t)r->cap * sizeof(double));
        r->x = realloc(r->x, (size_t)r->cap * sizeof(double));
        r->v = realloc(r->v, (size_t)r->cap * sizeof(double));
        r->P = realloc(r->P, (size_t)r->cap * sizeof(double));
        r->act = realloc(r->act, (size_t)r->cap);
    }
    r->t[r->n] = s->t;
    r->x[r->n] = s->q[0];
    r->v[r->n] = s->v[0];
    r->P[r->n] = s->P[0];
    r->act[r->n] = s->active[0];
    r->n++;
    return 0;
}

static void trace_free(trace *r)
{
    free(r->t);
    free(r->x);
    free(r->v);
    free(r->P);
    free(r->act);
}

typedef struct final_state {
    double t, x, v;
} final_state;

static int keep_last(const pd_state *s, void *ctx)
{
    final_state *f = ctx;
    f->t = s->t;
    f->x = s->q[0];
    f->v = s->v[0];
    return 0;
}

/* max |x| over the run: the reported states, and every velocity zero inside
 * a free step refined by Newton (t -= v / x'') on restarts of the run from the
 * step start (the library's exact end time). */
static double continuous_max(const osc_model *om, const trace *r, int *failures)
{
    double xmax = 0.0;
    for (long k = 0; k < r->n; k++)
        xmax = fmax(xmax, fabs(r->x[k]));
    for (long k = 0; k + 1 < r->n; k++) {
        double va = r->v[k], vb = r->v[k + 1] + r->P[k + 1]; /* v- = v+ - W P / M */
        if (r->act[k] || va == 0.0 || vb == 0.0 || (va > 0.0) == (vb > 0.0) ||
            !(r->t[k + 1] > r->t[k]))
            continue;
        double t = r->t[k] + (r->t[k + 1] - r->t[k]) * va / (va - vb);
        final_state f = {0, r->x[k], 0};
        for (int it = 0; it < 8 && t > r->t[k]; it++) {
            pd_err err;
            double q0 = r->x[k], v0 = r->v[k], F;
            if (pd_edg_run(&om->md, r->t[k], &q0, &v0, t, NULL, keep_last, &f, NULL, &err)) {
                (*failures)++;
                break;
            }
            pulse_force(t, -1, &F, (void *)&om->c);
            double dt = -f.v / (F - om->C * f.v - om->K * f.x);
            t += dt;
            if (fabs(dt) <= 1e-15 * fabs(t))
                break;
        }
        xmax = fmax(xmax, fabs(f.x));
    }
    return xmax;
}

/* The same case through the exact one-wall reference. */
static int exact_run(const osc_case *c, double tend, pd_ed_result *er, pd_err *err)
{
    pd_sine_piece pc[2] = {
        {.t_start = 0.0, .A = (double)c->dir, .w = 1.0, .phi = c->cosine ? TWO_PI / 4 : 0.0},
        {.t_start = TWO_PI}};
    pd_ed_sdof prob = {.osc = {.w0 = c->Pi2, .xi = c->xi},
                       .wall = 1,
                       .delta = c->Pi3,
                       .e = c->eps,
                       .npieces = 2,
                       .pieces = pc};
    pd_ed_opts o;
    o = pd_ed_default_opts();
    o.t_end = tend;
    return pd_ed_sdof_run(&prob, 0.0, 0.0, &o, NULL, NULL, er, err);
}

/* The one-wall oscillator posed as a general model matches the closed-form
 * reference: umax to 1e-9, first impact to 1e-10, equal impact counts, and
 * the resting phases (eps = 0) and the accumulation jump agree. */
static void test_edg_oscillator_matches_exact(pd_test_ctx *ctx)
{
    const double triples[][3] = {
        {0.5, 0.05, 0.6}, {1.16, 0.1, 1.0}, {0.2, 0.01, 0.0}, {3.0, 0.001, 0.5}, {0.05, 1.0, 0.9}};
    double worst = 0.0, worst_t = 0.0;
    int cases = 0, resting = 0, accumulating = 0;
    for (int p = 0; p < 2; p++)
        for (int dir = -1; dir <= 1; dir += 2)
            for (size_t k = 0; k < sizeof triples / sizeof triples[0]; k++) {
                osc_case c = {p, dir, triples[k][0], triples[k][1], triples[k][2], 0.05};
                osc_model om;
                osc_setup(&om, &c);
                double tend = TWO_PI * (1.0 + 2.0 / c.Pi2);
                trace tr = {0};
                pd_edg_result r;
                pd_ed_result er;
                pd_err err;
                int failures = 0;
                int rc = pd_edg_run(&om.md, 0.0, NULL, NULL, tend, NULL, record, &tr, &r, &err);
                if (!CHECK(ctx, rc == PD_OK, "%s", err.msg) ||
                    !CHECK(ctx, exact_run(&c, tend, &er, &err) == PD_OK, "%s", err.msg)) {
                    trace_free(&tr);
                    continue;
                }
                double xmax = continuous_max(&om, &tr, &failures);
                double rel = fabs(xmax - er.xmax) / er.xmax;
                CHECK(ctx, failures == 0, "%d restarts failed", failures);
                CHECK(ctx, rel <= 1e-9, "%s %s Pi2 %g Pi3 %g eps %g: umax %.15g vs exact %.15g",
                      p ? "cosine" : "sine", dir > 0 ? "normal" : "reverse", c.Pi2, c.Pi3, c.eps,
                      xmax, er.xmax);
                CHECK(ctx,
                      r.impacts == er.impacts && r.accumulations == er.accumulations &&
                          r.detachments == er.detachments,
                      "Pi2 %g Pi3 %g eps %g: impacts %ld/%ld accumulations %ld/%ld detachments "
                      "%ld/%ld",
                      c.Pi2, c.Pi3, c.eps, r.impacts, er.impacts, r.accumulations, er.accumulations,
                      r.detachments, er.detachments);
                if (er.impacts > 0) {
                    CHECK_NEAR(ctx, r.first_impact, er.first_impact, 1e-10);
                    worst_t = fmax(worst_t, fabs(r.first_impact - er.first_impact));
                }
                CHECK_NEAR(ctx, r.contact_time, er.contact_time, 1e-9 * tend);
                worst = fmax(worst, rel);
                resting += c.eps == 0.0 && r.detachments > 0 && r.contact_time > 0.0;
                accumulating += c.eps > 0.0 && c.eps < 1.0 && r.accumulations > 0;
                cases++;
                trace_free(&tr);
            }
    CHECK(ctx, cases == 20, "%d of 20 cases ran", cases);
    CHECK(ctx, resting >= 2, "eps = 0 must rest and detach (%d cases)", resting);
    CHECK(ctx, accumulating >= 2, "0 < eps < 1 must accumulate (%d cases)", accumulating);
    CHECK(ctx, worst <= 1e-9 && worst_t <= 1e-10, "worst umax %.3g, first impact %.3g", worst,
          worst_t);
}

/* Output times are re-integrated from the step start: the path (and so the
 * final state and the event count) is the same with and without them. */
static void test_edg_output_grid_leaves_path(pd_test_ctx *ctx)
{
    osc_case c = {0, 1, 0.5, 0.05, 0.6, 0.05};
    osc_model om;
    osc_setup(&om, &c);
    double tend = TWO_PI * 5.0;
    final_state f0 = {0};
    pd_edg_opts o;
    pd_edg_result r0, r1;
    pd_err err;
    trace tr = {0};
    o = pd_edg_default_opts();
    CHECK(ctx, pd_edg_run(&om.md, 0.0, NULL, NULL, tend, &o, keep_last, &f0, &r0, &err) == PD_OK,
          "%s", err.msg);
    o.h_out = 0.01;
    o.impacts_only = 1; /* P > 0 only at the impacts (the held forces are not sampled) */
    CHECK(ctx, pd_edg_run(&om.md, 0.0, NULL, NULL, tend, &o, record, &tr, &r1, &err) == PD_OK, "%s",
          err.msg);
    CHECK(ctx, tr.x[tr.n - 1] == f0.x && tr.v[tr.n - 1] == f0.v && tr.t[tr.n - 1] == tend,
          "final state %.17g %.17g vs %.17g %.17g", tr.x[tr.n - 1], tr.v[tr.n - 1], f0.x, f0.v);
    CHECK(ctx, r0.steps == r1.steps && r0.events == r1.events, "steps %ld/%ld events %ld/%ld",
          r0.steps, r1.steps, r0.events, r1.events);
    long grid = 0, events = 0;
    for (long k = 0; k < tr.n; k++) {
        double kk = tr.t[k] / 0.01;
        grid += fabs(kk - floor(kk + 0.5)) < 1e-9;
        events += tr.P[k] > 0.0;
        CHECK(ctx, om.g0 - tr.x[k] >= -1e-12, "gap %.3g at t = %g", om.g0 - tr.x[k], tr.t[k]);
    }
    CHECK(ctx, grid >= (long)(tend / 0.01) && events == r1.impacts,
          "%ld grid outputs, %ld impact reports of %ld impacts", grid, events, r1.impacts);
    /* sampling the held forces (the default) leaves the path too; every
     * report's P gains the held force's integral (>= 0), nothing else */
    trace ts = {0};
    pd_edg_result r2;
    o.impacts_only = 0;
    CHECK(ctx, pd_edg_run(&om.md, 0.0, NULL, NULL, tend, &o, record, &ts, &r2, &err) == PD_OK, "%s",
          err.msg);
    int same = ts.n == tr.n && r2.steps == r1.steps && r2.events == r1.events, below = 0;
    double held = 0.0;
    for (long k = 0; same && k < tr.n; k++) {
        same = ts.t[k] == tr.t[k] && ts.x[k] == tr.x[k] && ts.v[k] == tr.v[k];
        below += ts.P[k] < tr.P[k];
        held += ts.P[k] - tr.P[k];
    }
    CHECK(ctx, same && below == 0 && held > 0.0 && r1.accumulations > 0,
          "sampled: same path %d, %d reports below the impacts', held impulse %g "
          "(%ld accumulations)",
          same, below, held, r1.accumulations);
    trace_free(&ts);
    trace_free(&tr);
}

/* A grazing impact inside one integrator step is found: the undamped free
 * oscillator x = A sin(w0 t) reaches a wall at A (1 - 1e-8) at
 * asin(1 - 1e-8) / w0 and misses one at A (1 + 1e-8). */
static void test_edg_grazing_is_found(pd_test_ctx *ctx)
{
    for (int pass = 0; pass < 2; pass++) {
        double w0 = 2.0, V = 1.0, A = V / w0, delta = A * (pass ? 1 + 1e-8 : 1 - 1e-8);
        double M = 1, C = 0, K = w0 * w0, W = -1, e = 1.0;
        pd_model md = {.n = 1,
                       .m = 1,
                       .M = pd_matrix_dense(1, 1, &M),
                       .C = pd_matrix_dense(1, 1, &C),
                       .K = pd_matrix_dense(1, 1, &K),
                       .W = pd_matrix_dense(1, 1, &W),
                       .g0 = &delta,
                       .e = &e};
        pd_edg_result r;
        pd_err err;
        CHECK(ctx, pd_edg_run(&md, 0.0, NULL, &V, 3.0, NULL, NULL, NULL, &r, &err) == PD_OK, "%s",
              err.msg);
        if (pass)
            CHECK(ctx, r.impacts == 0, "a wall 1e-8 beyond the amplitude was hit (%ld)", r.impacts);
        else {
            /* the impact speed V sqrt(1 - (delta/A)^2) ~ 1.4e-4 V turns a position error
             * dx into a time error dx / speed: compare the position-equivalent error */
            double t_hit = asin(delta / A) / w0, speed = V * sqrt(1 - (delta / A) * (delta / A));
            CHECK(ctx, r.impacts == 1, "grazing impact: %ld impacts", r.impacts);
            CHECK(ctx, fabs(r.first_impact - t_hit) * speed <= 1e-13 * A,
                  "impact at %.17g, exact %.17g (position-equivalent error %.3g)", r.first_impact,
                  t_hit, fabs(r.first_impact - t_hit) * speed);
        }
    }
}

/* ---- free masses: Newton's law ------------------------------------------ */

typedef struct rows {
    int n, m;
    long calls;
    double t_event, v_after[4], P[4], mom_err, gmin;
    const double *mass;
    double mom0;
} rows;

static int watch(const pd_state *s, void *ctx)
{
    rows *w = ctx;
    double p = 0.0, P = 0.0;
    for (int i = 0; i < w->n; i++)
        p += w->mass[i] * s->v[i];
    if (w->calls++ == 0)
        w->mom0 = p;
    w->mom_err = fmax(w->mom_err, fabs(p - w->mom0));
    for (int a = 0; a < w->m; a++) {
        P += s->P[a];
        w->gmin = fmin(w->gmin, s->g[a]);
    }
    if (P > 0.0 && isnan(w->t_event)) {
        w->t_event = s->t;
        memcpy(w->v_after, s->v, (size_t)w->n * sizeof(double));
        memcpy(w->P, s->P, (size_t)w->m * sizeof(double));
    }
    return 0;
}

/* Mass 1 at V strikes mass 2 at rest across a gap d: t = d / V and
 * v1 = (1 - e) V / 2, v2 = (1 + e) V / 2; momentum kept throughout. */
static void test_edg_two_masses_newton(pd_test_ctx *ctx)
{
    const double es[] = {1.0, 0.5, 0.0};
    for (int k = 0; k < 3; k++) {
        double M[4] = {1, 0, 0, 1}, W[2] = {-1, 1}, g0 = 0.3, e = es[k], V = 1.7;
        double v0[2] = {V, 0.0}, mass[2] = {1, 1};
        pd_model md = {.n = 2,
                       .m = 1,
                       .M = pd_matrix_dense(2, 2, M),
                       .C = pd_matrix_zero(2, 2),
                       .K = pd_matrix_zero(2, 2),
                       .W = pd_matrix_dense(2, 1, W),
                       .g0 = &g0,
                       .e = &e};
        rows w = {2, 1, 0, NAN, {0}, {0}, 0, 0, mass, 0};
        pd_edg_result r;
        pd_err err;
        CHECK(ctx, pd_edg_run(&md, 0.0, NULL, v0, 1.0, NULL, watch, &w, &r, &err) == PD_OK, "%s",
              err.msg);
        CHECK_NEAR(ctx, w.t_event, g0 / V, 1e-15);
        CHECK_NEAR(ctx, w.v_after[0], (1 - e) * V / 2, 1e-12);
        CHECK_NEAR(ctx, w.v_after[1], (1 + e) * V / 2, 1e-12);
        CHECK_NEAR(ctx, w.P[0], (1 + e) * V / 2, 1e-12);
        CHECK(ctx, w.mom_err <= 1e-13 && w.gmin >= -1e-12, "e %g: momentum %.3g, gap %.3g", e,
              w.mom_err, w.gmin);
        CHECK(ctx, r.impacts == 1, "e %g: %ld impacts", e, r.impacts);
    }
}

/* Newton's cradle: mass 0 at V strikes masses 1-2-3, touching at rest.
 * The velocity LCP of Newton's law over the three zero gaps,
 *   w = D P + U- + e min(U-, 0),  D = tridiag(-1, 2, -1),  U- = (-V, 0, 0),
 * has the unique solution P = (1 + e) V / 4 (3, 2, 1) (D is positive
 * definite), every w = 0: the struck row leaves as one body,
 *   v0 = V (1 - 3 e) / 4,  v1 = v2 = v3 = V (1 + e) / 4,
 * i.e. for e = 1 (-V/2, V/2, V/2, V/2) — the answer of a mass striking a
 * rigid body three times heavier, not the sequential cradle (0, 0, 0, V):
 * simultaneous impacts under Newton's law do not propagate through a row. */
static void test_edg_cradle_simultaneous(pd_test_ctx *ctx)
{
    const double es[] = {1.0, 0.5, 0.0};
    for (int k = 0; k < 3; k++) {
        enum { N = 4, C = 3 };
        double M[N * N] = {0}, W[N * C] = {0}, g0[C] = {0.25, 0.0, 0.0}, e[C], V = 2.0;
        double v0[N] = {V, 0, 0, 0}, mass[N] = {1, 1, 1, 1};
        for (int i = 0; i < N; i++)
            M[i + N * i] = 1.0;
        for (int a = 0; a < C; a++) {
            W[a + N * a] = -1.0;
            W[a + 1 + N * a] = 1.0;
            e[a] = es[k];
        }
        pd_model md = {.n = N,
                       .m = C,
                       .M = pd_matrix_dense(N, N, M),
                       .C = pd_matrix_zero(N, N),
                       .K = pd_matrix_zero(N, N),
                       .W = pd_matrix_dense(N, C, W),
                       .g0 = g0,
                       .e = e};
        rows w = {N, C, 0, NAN, {0}, {0}, 0, 0, mass, 0};
        pd_edg_result r;
        pd_err err;
        CHECK(ctx, pd_edg_run(&md, 0.0, NULL, v0, 2.0, NULL, watch, &w, &r, &err) == PD_OK, "%s",
              err.msg);
        double E0 = 0.5 * V * V, E1 = 0.0;
        for (int i = 0; i < N; i++)
            E1 += 0.5 * w.v_after[i] * w.v_after[i];
        CHECK_NEAR(ctx, w.t_event, g0[0] / V, 1e-15);
        CHECK_NEAR(ctx, w.v_after[0], V * (1 - 3 * es[k]) / 4, 1e-12);
        for (int i = 1; i < N; i++)
            CHECK_NEAR(ctx, w.v_after[i], V * (1 + es[k]) / 4, 1e-12);
        for (int a = 0; a < C; a++)
            CHECK_NEAR(ctx, w.P[a], (1 + es[k]) * V / 4 * (3 - a), 1e-12);
        if (es[k] == 1.0)
            CHECK_NEAR(ctx, E1, E0, 1e-13 * E0);
        CHECK(ctx, w.mom_err <= 1e-13 && w.gmin >= -1e-12, "e %g: momentum %.3g, gap %.3g", es[k],
              w.mom_err, w.gmin);
        CHECK(ctx, r.impacts == 1, "e %g: %ld impacts (the resting contacts are not impacts)",
              es[k], r.impacts);
    }
}

/* ---- a chain between two walls ------------------------------------------ */

enum { CN = 3, CC = 4 };

typedef struct chain {
    double M[CN * CN], K[CN * CN], W[CN * CC], g0[CC], e[CC];
    pd_model md;
} chain;

/* The chain of tests/test_engine.c: springs to the ground and between masses,
 * a wall at each end, gaps 0.02, e = 1, no damping. */
static void chain_setup(chain *ch)
{
    memset(ch, 0, sizeof *ch);
    for (int i = 0; i < CN; i++) {
        ch->M[i + CN * i] = 1.0 + 0.5 * i;
        ch->K[i + CN * i] = 40.0;
    }
    ch->K[0 + CN * 1] = ch->K[1 + CN * 0] = -10.0;
    ch->K[1 + CN * 2] = ch->K[2 + CN * 1] = -10.0;
    ch->W[0 + CN * 0] = 1.0;
    ch->W[0 + CN * 1] = -1.0, ch->W[1 + CN * 1] = 1.0;
    ch->W[1 + CN * 2] = -1.0, ch->W[2 + CN * 2] = 1.0;
    ch->W[2 + CN * 3] = -1.0;
    for (int a = 0; a < CC; a++) {
        ch->g0[a] = 0.02;
        ch->e[a] = 1.0;
    }
    ch->md = (pd_model){.n = CN,
                        .m = CC,
                        .M = pd_matrix_dense(CN, CN, ch->M),
                        .C = pd_matrix_zero(CN, CN),
                        .K = pd_matrix_dense(CN, CN, ch->K),
                        .W = pd_matrix_dense(CN, CC, ch->W),
                        .g0 = ch->g0,
                        .e = ch->e};
}

typedef struct energy_watch {
    const chain *ch;
    long calls, impacts;
    double E0, worst, gmin;
} energy_watch;

static double chain_energy(const chain *ch, const double *q, const double *v)
{
    double E = 0.0;
    for (int i = 0; i < CN; i++) {
        double Kq = 0.0;
        for (int j = 0; j < CN; j++)
            Kq += ch->K[i + CN * j] * q[j];
        E += 0.5 * ch->M[i + CN * i] * v[i] * v[i] + 0.5 * q[i] * Kq;
    }
    return E;
}

static int watch_energy(const pd_state *s, void *ctx)
{
    energy_watch *ew = ctx;
    double E = chain_energy(ew->ch, s->q, s->v);
    if (ew->calls++ == 0)
        ew->E0 = E;
    ew->worst = fmax(ew->worst, fabs(E - ew->E0) / ew->E0);
    for (int a = 0; a < CC; a++) {
        ew->gmin = fmin(ew->gmin, s->g[a]);
        ew->impacts += s->P[a] > 0.0;
    }
    return 0;
}

/* e = 1 and no damping: the energy is kept to 1e-9 over hundreds of impacts
 * (every step and event reported), and no gap goes below -1e-12. */
static void test_edg_chain_energy(pd_test_ctx *ctx)
{
    chain ch;
    chain_setup(&ch);
    double v0[CN] = {1.0, -0.5, 0.7};
    energy_watch ew = {&ch, 0, 0, 0, 0, 0};
    pd_edg_result r;
    pd_err err;
    CHECK(ctx, pd_edg_run(&ch.md, 0.0, NULL, v0, 5.0, NULL, watch_energy, &ew, &r, &err) == PD_OK,
          "%s", err.msg);
    CHECK(ctx, r.impacts > 100 && ew.impacts == r.impacts, "impacts %ld (reported %ld)", r.impacts,
          ew.impacts);
    CHECK(ctx, ew.worst <= 1e-9, "energy drift %.3g over %ld impacts", ew.worst, r.impacts);
    CHECK(ctx, ew.gmin >= -1e-12, "gap %.3g", ew.gmin);
}

typedef struct grid_rec {
    double *q;
    long n;
    double h;
} grid_rec;

static int keep_grid(const pd_state *s, void *ctx)
{
    grid_rec *g = ctx;
    double k = s->t / g->h;
    long kk = (long)floor(k + 0.5);
    if (fabs(k - (double)kk) < 1e-9 && kk < g->n)
        memcpy(g->q + CN * kk, s->q, sizeof(double) * CN);
    return 0;
}

/* Moreau–Jean (theta = 1/2) converges to the reference at order about 1 on
 * the history: max over the output grid of |q - q_ref| as h halves. */
static void test_edg_moreau_converges(pd_test_ctx *ctx)
{
    chain ch;
    chain_setup(&ch);
    double v0[CN] = {1.0, -0.5, 0.7}, T = 1.0, H = 1e-3, err_prev = 0.0, orders = 0.0;
    grid_rec g = {calloc(CN * 1001, sizeof(double)), 1001, H};
    pd_edg_opts o;
    pd_edg_result r;
    pd_err err;
    o = pd_edg_default_opts();
    o.h_out = H;
    CHECK(ctx, pd_edg_run(&ch.md, 0.0, NULL, v0, T, &o, keep_grid, &g, &r, &err) == PD_OK, "%s",
          err.msg);
    for (int j = 2; j <= 5; j++) {
        pd_mj_opts mo = pd_mj_default_opts();
        mo.h = H / (1 << j);
        pd_mj *mj = pd_mj_alloc(&ch.md, &mo, &err);
        if (!CHECK(ctx, mj && pd_mj_reset(mj, 0.0, NULL, v0, &err) == PD_OK, "%s", err.msg))
            break;
        long steps = pd_steps_for(T, mo.h);
        double emax = 0.0;
        for (long k = 1; k <= steps && !pd_mj_step(mj, &err); k++)
            if (k % (1 << j) == 0)
                for (int i = 0; i < CN; i++)
                    emax = fmax(emax, fabs(pd_mj_state(mj)->q[i] - g.q[CN * (k >> j) + i]));
        if (j > 2) {
            CHECK(ctx, emax < err_prev, "h = %g: error %.3g did not fall from %.3g", mo.h, emax,
                  err_prev);
            orders += log2(err_prev / emax);
        }
        err_prev = emax;
        pd_mj_free(mj);
    }
    CHECK(ctx, orders / 3 > 0.7 && orders / 3 < 1.4, "mean observed order %.2f (expected ~1)",
          orders / 3);
    CHECK(ctx, err_prev < 5e-3, "finest Moreau-Jean error %.3g", err_prev);
    free(g.q);
}

/* ---- accumulation of impacts --------------------------------------------- */

typedef struct ball {
    double M, C, K, W, delta, e, a;
    pd_model md;
} ball;

static void constant_force(double t, int side, double *F, void *ctx)
{
    (void)t;
    (void)side;
    F[0] = *(const double *)ctx;
}

/* Mass under a constant force a toward a wall at distance delta, no spring. */
static void ball_setup(ball *b, double e)
{
    *b = (ball){1.0, 0.0, 0.0, -1.0, 0.5, e, 2.0, {0}};
    b->md = (pd_model){.n = 1,
                       .m = 1,
                       .M = pd_matrix_dense(1, 1, &b->M),
                       .C = pd_matrix_dense(1, 1, &b->C),
                       .K = pd_matrix_dense(1, 1, &b->K),
                       .W = pd_matrix_dense(1, 1, &b->W),
                       .g0 = &b->delta,
                       .e = &b->e,
                       .force = constant_force,
                       .force_ctx = &b->a};
}

/* Bouncing ball: t1 = sqrt(2 delta / a), v1 = a t1, and the impacts
 * accumulate at t_inf = t1 + 2 e v1 / (a (1 - e)); then it rests on the wall.
 * The jump comes at the same impact as in the exact reference. */
static void test_edg_zeno_accumulation(pd_test_ctx *ctx)
{
    const double es[] = {0.3, 0.5, 0.8, 0.9};
    for (int k = 0; k < 4; k++) {
        ball b;
        ball_setup(&b, es[k]);
        double e = es[k], t1 = sqrt(2 * b.delta / b.a), v1 = b.a * t1;
        double t_inf = t1 + 2 * e * v1 / (b.a * (1 - e)), T = 2 * t_inf + 1.0;
        pd_sine_piece piece = {.t_start = 0.0, .A = b.a, .w = 0.0, .phi = TWO_PI / 4};
        pd_ed_sdof prob = {.osc = {.w0 = 0.0, .xi = 0.0},
                           .wall = 1,
                           .delta = b.delta,
                           .e = e,
                           .npieces = 1,
                           .pieces = &piece};
        pd_ed_opts eo;
        pd_ed_result er;
        pd_edg_result r;
        final_state f = {0};
        pd_err err;
        eo = pd_ed_default_opts();
        eo.t_end = T;
        CHECK(ctx, pd_ed_sdof_run(&prob, 0.0, 0.0, &eo, NULL, NULL, &er, &err) == PD_OK, "%s",
              err.msg);
        CHECK(ctx, pd_edg_run(&b.md, 0.0, NULL, NULL, T, NULL, keep_last, &f, &r, &err) == PD_OK,
              "%s", err.msg);
        CHECK_NEAR(ctx, r.first_impact, t1, 1e-14);
        CHECK(ctx, r.accumulations == 1 && r.impacts == er.impacts,
              "e %g: accumulations %ld, impacts %ld (exact reference %ld)", e, r.accumulations,
              r.impacts, er.impacts);
        /* t_inf moves by 2 e dv / (a (1 - e)) for a speed error dv */
        CHECK_NEAR(ctx, T - r.contact_time, t_inf, 1e-12 * t_inf / (1 - e));
        CHECK(ctx, fabs(f.x - b.delta) <= 1e-15 && f.v == 0.0 && f.t == T,
              "e %g: final state x %.17g v %.3g (resting on the wall at %g)", e, f.x, f.v, b.delta);
    }
}

/* Without the jump the same ball exhausts its burst budget quickly, near
 * t_inf, with a message naming the time and the contact. */
static void test_edg_zeno_without_jump_stalls(pd_test_ctx *ctx)
{
    ball b;
    ball_setup(&b, 0.8);
    double t1 = sqrt(2 * b.delta / b.a), t_inf = t1 + 2 * 0.8 * b.a * t1 / (b.a * 0.2);
    pd_edg_opts o;
    pd_edg_result r;
    final_state f = {0};
    pd_err err;
    o = pd_edg_default_opts();
    o.no_accumulation = 1;
    o.max_burst = 60;
    double c0 = pd_cpu_seconds();
    int rc = pd_edg_run(&b.md, 0.0, NULL, NULL, 2 * t_inf, &o, keep_last, &f, &r, &err);
    double cpu = pd_cpu_seconds() - c0;
    CHECK(ctx, rc == PD_EBUDGET, "status %d, expected PD_EBUDGET", rc);
    CHECK(ctx,
          strstr(err.msg, "accumulation") && strstr(err.msg, "contact 0") &&
              strstr(err.msg, "t = ") && strstr(err.msg, "off"),
          "message: %s", err.msg);
    CHECK(ctx, r.impacts == 61 && r.accumulations == 0, "impacts %ld (burst budget 60)", r.impacts);
    CHECK(ctx, f.t < t_inf && t_inf - f.t < 1e-4, "stalled at %.15g, t_inf = %.15g", f.t, t_inf);
    CHECK(ctx, cpu < 1.0, "the stall took %.3g s", cpu);
    /* the total event budget stops it too */
    o.max_burst = 100000;
    o.max_events = 40;
    rc = pd_edg_run(&b.md, 0.0, NULL, NULL, 2 * t_inf, &o, NULL, NULL, &r, &err);
    CHECK(ctx,
          rc == PD_EBUDGET && strstr(err.msg, "events by t = ") && strstr(err.msg, "contact 0"),
          "status %d: %s", rc, err.msg);
}

/* ---- inputs and allocation ------------------------------------------------ */

/* Bad inputs are refused with PD_EINVAL and a message naming them. */
static void test_edg_bad_input(pd_test_ctx *ctx)
{
    ball b;
    ball_setup(&b, 0.5);
    pd_err err;
    pd_edg_result r;
    double bad_gap = -0.1, bad_e = 1.5, q_in = 0.6, q_nan = NAN;
    b.md.g0 = &bad_gap;
    CHECK(ctx,
          pd_edg_run(&b.md, 0, NULL, NULL, 1, NULL, NULL, NULL, &r, &err) == PD_EINVAL &&
              strstr(err.msg, "gap"),
          "negative gap: %s", err.msg);
    b.md.g0 = &b.delta;
    b.md.e = &bad_e;
    CHECK(ctx,
          pd_edg_run(&b.md, 0, NULL, NULL, 1, NULL, NULL, NULL, &r, &err) == PD_EINVAL &&
              strstr(err.msg, "restitution"),
          "e > 1: %s", err.msg);
    b.md.e = &b.e;
    CHECK(ctx,
          pd_edg_run(&b.md, 1, NULL, NULL, 1, NULL, NULL, NULL, &r, &err) == PD_EINVAL &&
              strstr(err.msg, "t1"),
          "t1 <= t0: %s", err.msg);
    CHECK(ctx,
          pd_edg_run(&b.md, 0, &q_in, NULL, 1, NULL, NULL, NULL, &r, &err) == PD_EINVAL &&
              strstr(err.msg, "initial gap of contact 0"),
          "penetrating q0: %s", err.msg);
    CHECK(ctx,
          pd_edg_run(&b.md, 0, &q_nan, NULL, 1, NULL, NULL, NULL, &r, &err) == PD_EINVAL &&
              strstr(err.msg, "dof 0"),
          "NaN q0: %s", err.msg);
}

typedef struct heap_watch {
    long calls;
    size_t first;
    long changed;
} heap_watch;

static int watch_heap(const pd_state *s, void *ctx)
{
    heap_watch *hw = ctx;
    struct mallinfo2 mi = mallinfo2();
    (void)s;
    if (hw->calls++ == 0)
        hw->first = mi.uordblks;
    else
        hw->changed += mi.uordblks != hw->first;
    return 0;
}

/* Everything is allocated before the first report: the heap in use does not
 * change over the steps, events and LCPs of a run. */
static void test_edg_no_allocation_per_step(pd_test_ctx *ctx)
{
    chain ch;
    chain_setup(&ch);
    double v0[CN] = {1.0, -0.5, 0.7};
    heap_watch hw = {0, 0, 0};
    pd_edg_result r;
    pd_err err;
    struct mallinfo2 mi = mallinfo2();
    if (mi.uordblks == 0 && mi.arena == 0) {
        pd_test_skip(ctx, "allocator reports no heap statistics");
        return;
    }
    CHECK(ctx, pd_edg_run(&ch.md, 0.0, NULL, v0, 1.0, NULL, watch_heap, &hw, &r, &err) == PD_OK,
          "%s", err.msg);
    CHECK(ctx, hw.calls > 50 && r.impacts > 10, "%ld reports, %ld impacts", hw.calls, r.impacts);
    CHECK(ctx, hw.changed == 0, "heap in use changed at %ld of %ld reports", hw.changed, hw.calls);
}

void suite_event(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_edg_oscillator_matches_exact);
    PD_RUN(ctx, test_edg_output_grid_leaves_path);
    PD_RUN(ctx, test_edg_grazing_is_found);
    PD_RUN(ctx, test_edg_two_masses_newton);
    PD_RUN(ctx, test_edg_cradle_simultaneous);
    PD_RUN(ctx, test_edg_chain_energy);
    PD_RUN(ctx, test_edg_moreau_converges);
    PD_RUN(ctx, test_edg_zeno_accumulation);
    PD_RUN(ctx, test_edg_zeno_without_jump_stalls);
    PD_RUN(ctx, test_edg_bad_input);
    PD_RUN(ctx, test_edg_no_allocation_per_step);
}
