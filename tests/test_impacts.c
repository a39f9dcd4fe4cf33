/* test_impacts.c — simultaneous impacts on chains (docs/methods.md, "Where
 * methods fail on chains"): Newton's cradle of N equal free balls, e = 1,
 * the first one thrown at the others.
 *
 * Touching balls (gaps exactly 0): every contact of the row is closed when
 * the first ball arrives, so Moreau–Jean and the event-driven reference put
 * them all in one LCP with Newton's law at each, U+ = -e U- = (v0, 0, ...,
 * 0).  With momentum that gives the simultaneous-impact answer
 *   v_1 = -(N - 2) v0 / N,  v_k = 2 v0 / N  (k >= 2),
 * energy conserved -- not the cradle on the desk, which sends the last ball
 * off alone.  Any positive gap between the balls makes the impacts
 * sequential, and both methods give the physical answer (0, ..., 0, v0):
 * Moreau–Jean predicts a contact from the velocities at the start of a
 * step, so a chain reaction moves one ball per step whatever the gap is
 * against v0 dt; the event-driven reference locates each impact.  The
 * answer jumps at gap = 0: the impact law, not the integrator, decides.
 * (The impulses of the reference's simultaneous impact: test_event.c.)
 * With restitution eps < 1 and every gap 0, the first one's too, the
 * simultaneous impact has its closed form for any eps, and the bodies
 * that move on together keep every later step's LCP degenerate. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_engine.h"
#include "pd_test.h"

#define CRADLE_MAX 10
#define CRADLE_V0 1.0
#define CRADLE_RUN 0.01 /* the first ball's flight to the others [s] */
#define CRADLE_END 0.1  /* the end of a run: every impact is over (gaps <= 1e-2) */

/* N balls of unit mass, free (K = C = 0), contact a between balls a and
 * a + 1 (g = g0 + q_{a+1} - q_a); the first gap CRADLE_RUN, the others gap. */
typedef struct cradle {
    int N;
    double M[CRADLE_MAX * CRADLE_MAX], W[CRADLE_MAX * CRADLE_MAX];
    double g0[CRADLE_MAX], e[CRADLE_MAX], v0[CRADLE_MAX];
    pd_model model;
} cradle;

/* The cradle with the first gap `run`, the others `gap`, restitution eps
 * at every contact. */
static void cradle_make_eps(cradle *c, int N, double run, double gap, double eps)
{
    memset(c, 0, sizeof *c);
    c->N = N;
    for (int i = 0; i < N; i++)
        c->M[i + i * N] = 1.0;
    for (int a = 0; a < N - 1; a++) {
        c->W[a + a * N] = -1.0;
        c->W[a + 1 + a * N] = 1.0;
        c->g0[a] = a == 0 ? run : gap;
        c->e[a] = eps;
    }
    c->v0[0] = CRADLE_V0;
    c->model = (pd_model){.n = N,
                          .m = N - 1,
                          .M = pd_matrix_dense(N, N, c->M),
                          .C = pd_matrix_zero(N, N),
                          .K = pd_matrix_zero(N, N),
                          .W = pd_matrix_dense(N, N - 1, c->W),
                          .g0 = c->g0,
                          .e = c->e};
}

/* The elastic cradle, first gap CRADLE_RUN, the others gap. */
static void cradle_make(cradle *c, int N, double gap)
{
    cradle_make_eps(c, N, CRADLE_RUN * CRADLE_V0, gap, 1.0);
}

/* Final velocities of Moreau–Jean with step h, run well past the impacts. */
static int cradle_moreau(const cradle *c, double h, double *v, pd_err *err)
{
    pd_mj_opts o = pd_mj_default_opts();
    o.h = h;
    pd_mj *mj = pd_mj_alloc(&c->model, &o, err);
    if (!mj)
        return err->status;
    int rc = pd_mj_reset(mj, 0.0, NULL, c->v0, err);
    long steps = (long)(CRADLE_END / h);
    for (long k = 0; k < steps && !rc; k++)
        rc = pd_mj_step(mj, err);
    memcpy(v, pd_mj_state(mj)->v, (size_t)c->N * sizeof(double));
    pd_mj_free(mj);
    return rc;
}

/* The observer keeping the last state's velocities. */
typedef struct last_v {
    int n;
    double v[CRADLE_MAX];
} last_v;

static int keep_v(const pd_state *st, void *ctx)
{
    last_v *lv = ctx;
    memcpy(lv->v, st->v, (size_t)lv->n * sizeof(double));
    return 0;
}

/* Final velocities and impacts of the event-driven reference. */
static int cradle_event(const cradle *c, double *v, long *impacts, pd_err *err)
{
    pd_edg_opts o = pd_edg_default_opts();
    pd_edg_result r;
    last_v lv = {.n = c->N};
    int rc = pd_edg_run(&c->model, 0.0, NULL, c->v0, CRADLE_END, &o, keep_v, &lv, &r, err);
    memcpy(v, lv.v, (size_t)c->N * sizeof(double));
    *impacts = r.impacts;
    return rc;
}

/* max_i |v_i - want_i| and the kinetic energy over the initial one. */
static double cradle_error(const double *v, const double *want, int N, double *energy)
{
    double d = 0.0, ke = 0.0;
    for (int i = 0; i < N; i++) {
        d = fmax(d, fabs(v[i] - want[i]));
        ke += v[i] * v[i];
    }
    *energy = ke / (CRADLE_V0 * CRADLE_V0);
    return d;
}

/* Touching balls, N = 3 and 5: both methods give the simultaneous-impact
 * answer to 1e-12 at every step size, energy conserved. */
static void test_impacts_cradle_touching(pd_test_ctx *ctx)
{
    const int sizes[] = {3, 5};
    const double steps[] = {1e-3, 1e-4};
    for (int k = 0; k < 2; k++) {
        cradle c;
        int N = sizes[k];
        double want[CRADLE_MAX], v[CRADLE_MAX], energy;
        long impacts;
        pd_err err;
        cradle_make(&c, N, 0.0);
        for (int i = 0; i < N; i++)
            want[i] = i == 0 ? -(N - 2.0) / N * CRADLE_V0 : 2.0 / N * CRADLE_V0;
        for (int s = 0; s < 2; s++) {
            int rc = cradle_moreau(&c, steps[s], v, &err);
            double d = cradle_error(v, want, N, &energy);
            CHECK(ctx, rc == PD_OK && d <= 1e-12 && fabs(energy - 1.0) <= 1e-12,
                  "Moreau-Jean, N = %d, h = %g: |v - simultaneous| %.3g, energy ratio %.15g (%s)",
                  N, steps[s], d, energy, rc ? err.msg : "ok");
        }
        int rc = cradle_event(&c, v, &impacts, &err);
        double d = cradle_error(v, want, N, &energy);
        CHECK(ctx, rc == PD_OK && d <= 1e-12 && impacts == 1 && fabs(energy - 1.0) <= 1e-12,
              "event-driven, N = %d: |v - simultaneous| %.3g in %ld impacts, energy ratio %.15g", N,
              d, impacts, energy);
    }
}

/* Gaps of 1e-9 ... 1e-2 between the balls (from far below v0 dt to far
 * above): both methods give the sequential answer (0, ..., 0, v0), the
 * reference in N - 1 impacts. */
static void test_impacts_cradle_gapped(pd_test_ctx *ctx)
{
    const double gaps[] = {1e-9, 1e-6, 5e-4, 1e-2};
    for (int k = 0; k < 4; k++) {
        cradle c;
        int N = 5;
        double want[CRADLE_MAX] = {0}, v[CRADLE_MAX], energy;
        long impacts;
        pd_err err;
        cradle_make(&c, N, gaps[k]);
        want[N - 1] = CRADLE_V0;
        int rc = cradle_moreau(&c, 1e-3, v, &err);
        double d = cradle_error(v, want, N, &energy);
        CHECK(ctx, rc == PD_OK && d <= 1e-12,
              "Moreau-Jean, gap %g, h = 1e-3: |v - sequential| %.3g (%s)", gaps[k], d,
              rc ? err.msg : "ok");
        rc = cradle_event(&c, v, &impacts, &err);
        d = cradle_error(v, want, N, &energy);
        CHECK(ctx, rc == PD_OK && d <= 1e-12 && impacts == N - 1,
              "event-driven, gap %g: |v - sequential| %.3g in %ld impacts", gaps[k], d, impacts);
    }
}

/* Touching balls with every gap 0 (the first one too) and restitution eps:
 * one simultaneous impact in the first step, all N - 1 contacts in one LCP
 * (D = tridiag(-1, 2, -1)), whose answer with momentum is
 *   v_1 = ((1 + eps) / N - eps) v0,   v_k = (1 + eps) v0 / N   (k >= 2).
 * After it balls 2..N (1..N when eps = 0) move on together at zero gap and
 * zero relative velocity: every later step solves an LCP over the closed
 * contacts whose b is rounding, which made the default (auto, Lemke)
 * solver stop as "numerical" in the step after the impact (eps = 0.3: N =
 * 6, 8, 9, 10; eps = 0.5: N = 5, 6, 8, 9; issue 19).  Moreau–Jean
 * gives the impact to rounding: the LCP solve errs by about cond(D) n eps
 * (cond(D) <= 0.5 N^2), so the impact is checked to CRADLE_IMPACT_TOL N^3 eps
 * v0; each later step adds impulses at the rounding level of the relative
 * velocities, CRADLE_DRIFT_TOL N eps v0 a step at most. */
#define CRADLE_AFTER 2000     /* steps after the impact, h = 1e-3 */
#define CRADLE_IMPACT_TOL 1.0 /* the impact step: this * N^3 eps v0 */
#define CRADLE_DRIFT_TOL 1.0  /* each later step: this * N eps v0 more */
static void test_impacts_cradle_inelastic_touching(pd_test_ctx *ctx)
{
    const double eps_list[] = {0.0, 0.3, 0.5, 0.8};
    for (int k = 0; k < 4; k++)
        for (int N = 2; N <= CRADLE_MAX; N++) {
            double eps = eps_list[k], h = 1e-3, want[CRADLE_MAX], energy;
            double tol = CRADLE_IMPACT_TOL * N * N * N * DBL_EPSILON * CRADLE_V0;
            double drift = CRADLE_DRIFT_TOL * N * DBL_EPSILON * CRADLE_V0 * CRADLE_AFTER;
            cradle c;
            pd_err err;
            cradle_make_eps(&c, N, 0.0, 0.0, eps);
            for (int i = 0; i < N; i++)
                want[i] = (i == 0 ? (1.0 + eps) / N - eps : (1.0 + eps) / N) * CRADLE_V0;
            pd_mj_opts o = pd_mj_default_opts();
            o.h = h;
            pd_mj *mj = pd_mj_alloc(&c.model, &o, &err);
            int rc = mj ? pd_mj_reset(mj, 0.0, NULL, c.v0, &err) : err.status;
            if (!rc)
                rc = pd_mj_step(mj, &err);
            double d = rc ? INFINITY : cradle_error(pd_mj_state(mj)->v, want, N, &energy);
            int nactive = rc ? 0 : pd_mj_state(mj)->nactive;
            CHECK(ctx, rc == PD_OK && nactive == N - 1 && d <= tol,
                  "eps = %g, N = %d: the impact step: %d contacts, |v - closed form| %.3g > %.3g "
                  "(%s)",
                  eps, N, nactive, d, tol, rc ? err.msg : "ok");
            long steps = 0;
            for (; steps < CRADLE_AFTER && !rc; steps++)
                rc = pd_mj_step(mj, &err);
            d = rc ? INFINITY : cradle_error(pd_mj_state(mj)->v, want, N, &energy);
            CHECK(ctx, rc == PD_OK && d <= tol + drift,
                  "eps = %g, N = %d: %ld steps after the impact, |v - closed form| %.3g > %.3g "
                  "(%s)",
                  eps, N, steps, d, tol + drift, rc ? err.msg : "ok");
            pd_mj_free(mj);
        }
}

/* ---- the samples' impact counts ---------------------------------------- */

/* What a sampler adds up: impacts and the largest impulse of one sample. */
typedef struct sample_sum {
    long impacts, m, per[3];
    double max_impulse;
} sample_sum;

static int osc_sum(const pd_osc_sample *s, void *ctx)
{
    sample_sum *q = ctx;
    q->impacts += s->impacts;
    q->max_impulse = fmax(q->max_impulse, s->impulse);
    return 0;
}

static int scene_sum(const pd_scene_sample *s, void *ctx)
{
    sample_sum *q = ctx;
    for (long a = 0; a < q->m && s->impacts; a++)
        q->per[a] += s->impacts[a];
    return 0;
}

/* Every method's samples report the impacts begun since the previous
 * sample, and over the run they add up to the result's count: the
 * oscillator of the paper's Fig. 9 (5 impacts, far apart), and two SDOFs
 * beside a wall (per contact, the exact references and penalty on their
 * output grid too), and one SDOF beside a wall (the oscillator's paths).  The event-driven oscillator's samples carry its
 * impulses: its impacts fall in different samples, so the largest sample
 * is the largest impact's (1 + eps) v, to rounding of the unit change. */
static void test_samples_count_impacts(pd_test_ctx *ctx)
{
    static const pd_method osc_methods[] = {PD_METHOD_MOREAU, PD_METHOD_EVENT, PD_METHOD_PENALTY,
                                            PD_METHOD_NEWMARK};
    pd_osc c = pd_osc_default();
    c.pulse = PD_PULSE_SINE;
    c.ap = 4.0;
    c.Tp = 0.3;
    c.eps = 0.6;
    pd_osc_set_T0(&c, 3.0);
    pd_osc_set_gap(&c, 0.004);
    for (int k = 0; k < 4; k++) {
        pd_run_opts o = pd_run_default_opts();
        pd_osc_result r;
        pd_err e;
        sample_sum q = {0};
        o.method = osc_methods[k];
        int rc = pd_osc_run(&c, &o, osc_sum, &q, &r, &e);
        if (!CHECK(ctx, rc == PD_OK, "%s: %s", pd_method_name(o.method), e.msg))
            continue;
        CHECK(ctx, r.impacts == 5 && q.impacts == r.impacts,
              "%s: samples report %ld impacts, "
              "the result %ld (5 expected)",
              pd_method_name(o.method), q.impacts, r.impacts);
        if (o.method == PD_METHOD_EVENT)
            CHECK_NEAR(ctx, q.max_impulse, r.max_impulse, 1e-14 * r.max_impulse);
    }
    static const pd_method scene_methods[] = {PD_METHOD_MOREAU, PD_METHOD_EVENT,
                                              PD_METHOD_EVENT_GENERAL, PD_METHOD_PENALTY,
                                              PD_METHOD_NEWMARK};
    pd_scene_excitation x = {.pulse = PD_PULSE_SINE, .dir = 1, .ap = 4.0, .Tp = 0.5};
    pd_scene *sc = pd_scene_new(&x);
    pd_err e;
    int ok = sc && !pd_scene_add_sdof(sc, "A", 0.4, 0.05, 1e5, &e) &&
             !pd_scene_add_sdof(sc, "B", 1.2, 0.05, 1e5, &e) &&
             !pd_scene_add_contact(sc, PD_WALL, 1, 0, 1, 0.01, 0.5, 0, &e) &&
             !pd_scene_add_contact(sc, 0, 1, 1, 1, 0.01, 0.5, 0, &e) &&
             !pd_scene_add_contact(sc, 1, 1, PD_WALL, 1, 0.02, 0.5, 0, &e) &&
             !pd_scene_finish(sc, &e);
    CHECK(ctx, ok, "building the scene: %s", ok ? "" : e.msg);
    for (int k = 0; ok && k < 5; k++) {
        pd_run_opts o = pd_run_default_opts();
        pd_scene_result r;
        sample_sum q = {.m = 3};
        long all = 0;
        o.method = scene_methods[k];
        o.tend = 3.0;
        if (!CHECK(ctx, pd_scene_result_alloc(sc, &r, &e) == PD_OK, "%s", e.msg))
            break;
        int rc = pd_scene_run(sc, &o, scene_sum, &q, &r, &e);
        if (CHECK(ctx, rc == PD_OK, "%s: %s", pd_method_name(o.method), e.msg))
            for (int a = 0; a < 3; a++) {
                all += r.impacts[a];
                CHECK(ctx, q.per[a] == r.impacts[a],
                      "%s, contact %d: samples report %ld "
                      "impacts, the result %ld",
                      pd_method_name(o.method), a, q.per[a], r.impacts[a]);
            }
        CHECK(ctx, all > 0, "%s: no impact to count", pd_method_name(o.method));
        pd_scene_result_free(&r);
    }
    pd_scene_free(sc);
    /* one SDOF and a wall: the oscillator's fast paths */
    sc = pd_scene_new(&x);
    ok = sc && !pd_scene_add_sdof(sc, "A", 0.4, 0.05, 1e5, &e) &&
         !pd_scene_add_contact(sc, 0, 1, PD_WALL, 1, 0.01, 0.5, 0, &e) && !pd_scene_finish(sc, &e);
    CHECK(ctx, ok, "building the one-wall scene: %s", ok ? "" : e.msg);
    for (int k = 0; ok && k < 4; k++) {
        pd_run_opts o = pd_run_default_opts();
        pd_scene_result r;
        sample_sum q = {.m = 1};
        o.method = osc_methods[k];
        o.tend = 3.0;
        if (!CHECK(ctx, pd_scene_result_alloc(sc, &r, &e) == PD_OK, "%s", e.msg))
            break;
        int rc = pd_scene_run(sc, &o, scene_sum, &q, &r, &e);
        CHECK(ctx, rc == PD_OK && r.impacts[0] > 0 && q.per[0] == r.impacts[0],
              "one wall, %s: samples report %ld impacts, the result %ld (%s)",
              pd_method_name(o.method), q.per[0], r.impacts[0], rc ? e.msg : "");
        pd_scene_result_free(&r);
    }
    pd_scene_free(sc);
}

void suite_impacts(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_impacts_cradle_touching);
    PD_RUN(ctx, test_impacts_cradle_gapped);
    PD_RUN(ctx, test_impacts_cradle_inelastic_touching);
    PD_RUN(ctx, test_samples_count_impacts);
}
