/* test_row_paths.c — the row reference's (engine/event_row.c,
 * event_row_cluster.c) rarely taken paths, each test killing a mutant of
 * make mutate:
 *   - the observer's states are numbered 0, 1, 2, ... on the output grid,
 *     again from 0 on a second run of the same object;
 *   - a body held on a wall and pulled off by a piece change is released
 *     by the piece change (no detachment event an instant later);
 *   - SDOFs held at rest on a wall through a lever (contact weights -2 and
 *     0.5): the held forces' integrals against the statics;
 *   - an overdamped oscillator far from critical whose unit-norm modal
 *     basis is ill-conditioned by its time scale alone (condition 7e9,
 *     under the bound 1e10) runs and follows its closed form;
 *   - impacts of one contact count one scalar LCP each; close_tol 0 is
 *     taken (a gap of 1e-13 then closes on its own), a negative one refused;
 *   - cutting the load into pieces (the same function) changes no result
 *     and costs a piece change few flight evaluations;
 *   - a critically damped oscillator is refused (nearly defective modes);
 *     a modal configuration met again is taken from the cache;
 *   - a modal flight starts on its constraints (a gap closed within the
 *     tolerance projected away);
 *   - a second wall on a held tree is locked, the other held contacts'
 *     impulses still balance the loads. */
#include <math.h>
#include <string.h>

#include "pd_core.h"
#include "pd_engine.h"
#include "pd_test.h"

/* ---- the observer's step numbers ------------------------------------------------ */

typedef struct steps_ctx {
    int calls;
    long step[16];
    double t[16], q[16];
} steps_ctx;

static int keep_steps(const pd_state *s, void *vctx)
{
    steps_ctx *c = vctx;
    if (c->calls < 16) {
        c->step[c->calls] = s->step;
        c->t[c->calls] = s->t;
        c->q[c->calls] = s->q[0];
    }
    c->calls++;
    return 0;
}

/* An undamped unit oscillator (no contact) from x = 1 at rest, observed
 * every 0.25 over [t0, t0 + 2]: nine states, numbered k = 0..8 at
 * t0 + k/4 (exact in binary), x = cos t (closed-form flight, to 1e-12);
 * a second run of the object (from t0 = 1) numbers its states from 0 again. */
static void test_edr_observer_steps_numbered(pd_test_ctx *ctx)
{
    double one[1] = {1.0}, b[1] = {0.0}, x0[1] = {1.0}, v0[1] = {0.0};
    int cp[1] = {0};
    pd_model md = {.n = 1,
                   .m = 0,
                   .M = pd_matrix_dense(1, 1, one),
                   .C = pd_matrix_zero(1, 1),
                   .K = pd_matrix_dense(1, 1, one),
                   .W = pd_matrix_csc(1, 0, cp, NULL, NULL)};
    pd_sine_piece pc = {.t_start = 0.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_edr_opts eo = pd_edr_default_opts();
    eo.h_out = 0.25;
    pd_err err;
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    for (int run = 0; run < 2; run++) {
        double t0 = run ? 1.0 : 0.0;
        x0[0] = cos(t0);
        v0[0] = -sin(t0);
        steps_ctx sc = {0};
        int rc = pd_edr_run(r, t0, x0, v0, t0 + 2.0, keep_steps, &sc, &err);
        if (!CHECK(ctx, rc == PD_OK && sc.calls == 9, "run %d: %s, %d states", run, err.msg,
                   sc.calls))
            continue;
        for (int k = 0; k < 9; k++)
            CHECK(ctx,
                  sc.step[k] == k && sc.t[k] == t0 + 0.25 * k &&
                      fabs(sc.q[k] - cos(sc.t[k])) <= 1e-12,
                  "run %d, state %d: step %ld at t = %.17g, x = %.17g (cos t = %.17g)", run, k,
                  sc.step[k], sc.t[k], sc.q[k], cos(sc.t[k]));
    }
    pd_edr_free(r);
}

/* ---- a release at a piece change -------------------------------------------------- */

static int count_detach_events(const pd_edr_event *ev, void *vctx)
{
    if (ev->kind == PD_EDR_DETACH)
        ++*(int *)vctx;
    return 0;
}

/* A unit oscillator (m = k = 1) touching a wall on its left (g = x) is
 * pressed on it by f = -1 until t = 1 (held at rest, force 1), then pulled
 * off by f = +1: the contact force is -1 from t = 1 on, so the piece change
 * itself releases it (no detachment an instant later), and the body
 * follows x = 1 - cos(t - 1) (maximum 2 at t = 1 + pi) without touching the
 * wall again before t1 = 5 < 1 + 2 pi: one event (the piece change), one
 * detachment, no impact; the extremes to 1e-12 (closed-form flights). */
static void test_edr_piece_change_releases(pd_test_ctx *ctx)
{
    double one[1] = {1.0}, g0[1] = {0.0}, e[1] = {0.5}, wv[1] = {1.0};
    int cp[2] = {0, 1}, ri[1] = {0};
    pd_model md = {.n = 1,
                   .m = 1,
                   .M = pd_matrix_dense(1, 1, one),
                   .C = pd_matrix_zero(1, 1),
                   .K = pd_matrix_dense(1, 1, one),
                   .W = pd_matrix_csc(1, 1, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pcs[2] = {{.t_start = 0.0, .c0 = -1.0}, {.t_start = 1.0, .c0 = 1.0}};
    pd_piecewise_force F = {.b = one, .pieces = pcs, .npieces = 2};
    int detach_events = 0;
    pd_edr_opts eo = pd_edr_default_opts();
    eo.on_event = count_detach_events;
    eo.on_event_ctx = &detach_events;
    pd_err err;
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    int rc = pd_edr_run(r, 0.0, NULL, NULL, 5.0, NULL, NULL, &err);
    const pd_edr_result *res = pd_edr_result_of(r);
    if (CHECK(ctx, rc == PD_OK, "%s", err.msg))
        CHECK(ctx,
              res->events == 1 && res->detachments == 1 && res->impacts == 0 &&
                  detach_events == 0 && fabs(res->xpos[0] - 2.0) <= 1e-12 &&
                  fabs(res->xneg[0]) <= 1e-12 && fabs(res->contact_time[0] - 1.0) <= 1e-12,
              "events %ld, detachments %ld (%d detachment events), impacts %ld; x in "
              "[%.17g, %.17g] (closed form [0, 2]), held %.17g (1)",
              res->events, res->detachments, detach_events, res->impacts, -res->xneg[0],
              res->xpos[0], res->contact_time[0]);
    pd_edr_free(r);
}

/* ---- SDOFs held at rest by a lever ------------------------------------------------ */

typedef struct rest_ctx {
    double h, lam[2]; /* each contact's constant force */
    double worst;
    long samples;
} rest_ctx;

static int check_rest(const pd_state *s, void *vctx)
{
    rest_ctx *c = vctx;
    if (s->t <= 0.0)
        return 0;
    for (int a = 0; a < 2; a++)
        c->worst = fmax(c->worst, fabs(s->P[a] - c->lam[a] * c->h) / (c->lam[a] * c->h));
    c->samples++;
    return 0;
}

/* Two SDOFs (m0 = 1, k0 = 1; m1 = 2, k1 = 8) joined by a lever, contact 0:
 * g = 0.1 - 2 x0 + 0.5 x1 (the tree's scale factor 4, its edge s w = 2),
 * dof 0 against a wall on its right, contact 1: g = -x0; both closed at
 * t = 0 (x = (0, -0.2), at rest) under constant loads b = (10, -3.6).
 * Statics: dof 1, 0 = -3.6 + 8 (0.2) + 0.5 lambda0, so lambda0 = 4;
 * dof 0, 0 = 10 - 2 lambda0 - lambda1, so lambda1 = 2: both press, and
 * the bodies rest (a REST cluster, its edge forces constant).  Over 5 s
 * sampled every 0.5: no event, x fixed, each sample's impulses 4 h and
 * 2 h (constant forces integrated exactly: 1e-12 relative). */
static void test_edr_rest_lever_forces(pd_test_ctx *ctx)
{
    double M[4] = {1.0, 0.0, 0.0, 2.0}, K[4] = {1.0, 0.0, 0.0, 8.0}, b[2] = {10.0, -3.6};
    double g0[2] = {0.1, 0.0}, e[2] = {0.5, 0.5}, wv[3] = {-2.0, 0.5, -1.0}, q0[2] = {0.0, -0.2};
    int cp[3] = {0, 2, 3}, ri[3] = {0, 1, 0};
    pd_model md = {.n = 2,
                   .m = 2,
                   .M = pd_matrix_dense(2, 2, M),
                   .C = pd_matrix_zero(2, 2),
                   .K = pd_matrix_dense(2, 2, K),
                   .W = pd_matrix_csc(2, 2, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pc = {.t_start = 0.0, .c0 = 1.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_edr_opts eo = pd_edr_default_opts();
    eo.h_out = 0.5;
    pd_err err;
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    rest_ctx rest = {.h = 0.5, .lam = {4.0, 2.0}};
    int rc = pd_edr_run(r, 0.0, q0, NULL, 5.0, check_rest, &rest, &err);
    const pd_edr_result *res = pd_edr_result_of(r);
    if (CHECK(ctx, rc == PD_OK, "%s", err.msg)) {
        CHECK(ctx,
              res->events == 0 && res->detachments == 0 && fabs(res->xpos[0]) <= 1e-12 &&
                  fabs(res->xneg[0]) <= 1e-12 && fabs(res->xneg[1] - 0.2) <= 1e-12 &&
                  fabs(res->xpos[1] + 0.2) <= 1e-12,
              "events %ld, detachments %ld; x0 in [%.3g, %.3g] (0), x1 in [%.17g, %.17g] (-0.2)",
              res->events, res->detachments, -res->xneg[0], res->xpos[0], -res->xneg[1],
              res->xpos[1]);
        CHECK(ctx, rest.samples == 10 && rest.worst <= 1e-12,
              "%ld samples, impulses off the statics by %.3g (relative)", rest.samples, rest.worst);
    }
    pd_edr_free(r);
}

/* ---- a modal basis ill-conditioned by its time scale ------------------------------ */

typedef struct decay_ctx {
    double w, worst;
    long samples;
} decay_ctx;

static int check_decay(const pd_state *s, void *vctx)
{
    decay_ctx *c = vctx;
    double wt = c->w * s->t, x = (4.0 * exp(-0.5 * wt) - exp(-2.0 * wt)) / 3.0;
    c->worst = fmax(c->worst, fabs(s->q[0] - x));
    c->samples++;
    return 0;
}

/* An overdamped oscillator, xi = 1.25 (modes -2 w0 and -w0 / 2: far from
 * critical), w0 = 5.25e9, from x = 1 at rest: x = (4 e^{-w0 t / 2} -
 * e^{-2 w0 t}) / 3.  Its modal basis (unit-norm eigenvectors of
 * [0 1; -w0^2 -2 xi w0]: columns (1, lam) / |(1, lam)|) has the 1-norm
 * condition 1.33 w0 = 7.0e9 from its time scale alone, under the bound
 * 1e10 (MODAL_COND_MAX): it runs as a modal cluster and follows the closed
 * form over ten slow time constants, to 1e-12 (the condition comes from
 * scaling y against y', not from close modes: measured 2.7e-16). */
static void test_edr_stiff_overdamped_runs(pd_test_ctx *ctx)
{
    const double w = 5.25e9, xi = 1.25;
    double one[1] = {1.0}, C[1] = {2.0 * xi * w}, K[1] = {w * w}, b[1] = {0.0}, x0[1] = {1.0};
    int cp[1] = {0};
    pd_model md = {.n = 1,
                   .m = 0,
                   .M = pd_matrix_dense(1, 1, one),
                   .C = pd_matrix_dense(1, 1, C),
                   .K = pd_matrix_dense(1, 1, K),
                   .W = pd_matrix_csc(1, 0, cp, NULL, NULL)};
    pd_sine_piece pc = {.t_start = 0.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_edr_opts eo = pd_edr_default_opts();
    eo.h_out = 0.5 / w;
    pd_err err;
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    decay_ctx dc = {.w = w};
    int rc = pd_edr_run(r, 0.0, x0, NULL, 20.0 / w, check_decay, &dc, &err);
    const pd_edr_result *res = pd_edr_result_of(r);
    if (CHECK(ctx, rc == PD_OK, "%s", err.msg))
        CHECK(ctx, res->modal_bases == 1 && dc.samples == 41 && dc.worst <= 1e-12,
              "%ld modal bases, %ld samples off the closed form by %.3g", res->modal_bases,
              dc.samples, dc.worst);
    pd_edr_free(r);
}

/* ---- the LCPs counted; the closing tolerance 0 ------------------------------------- */

/* An undamped unit oscillator bouncing elastically on a wall at x = 0.5
 * (from x = 0 at v = 1: amplitude 1, an impact every 4 pi / 3), free of
 * forcing, over 10 periods 2 pi: 15 impacts, each of one contact, each one
 * scalar LCP (its Newton law), and nothing else is solved (no contact
 * rests): lcp_solves = impacts = 15. */
static void test_edr_single_contact_impacts_counted(pd_test_ctx *ctx)
{
    double one[1] = {1.0}, b[1] = {0.0}, g0[1] = {0.5}, e[1] = {1.0}, wv[1] = {-1.0}, v0[1] = {1.0};
    int cp[2] = {0, 1}, ri[1] = {0};
    pd_model md = {.n = 1,
                   .m = 1,
                   .M = pd_matrix_dense(1, 1, one),
                   .C = pd_matrix_zero(1, 1),
                   .K = pd_matrix_dense(1, 1, one),
                   .W = pd_matrix_csc(1, 1, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pc = {.t_start = 0.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_err err;
    pd_edr *r = pd_edr_alloc(&md, &F, NULL, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    int rc = pd_edr_run(r, 0.0, NULL, v0, 10.0 * PD_TWO_PI, NULL, NULL, &err);
    const pd_edr_result *res = pd_edr_result_of(r);
    if (CHECK(ctx, rc == PD_OK, "%s", err.msg))
        CHECK(ctx, res->impacts == 15 && res->lcp_solves == 15 && res->simultaneous == 0,
              "impacts %ld, LCPs solved %ld (one each), simultaneous %ld", res->impacts,
              res->lcp_solves, res->simultaneous);
    pd_edr_free(r);
}

/* close_tol = 0 is an option value (>= 0): no gap but a zero one closes
 * with another.  Three free unit masses, the first thrown at v = 1 at two
 * at rest 1e-13 apart (gaps 0.1 and 1e-13): with close_tol 0 the cradle
 * is sequential, two impacts (v = (0, 0, 1) to rounding); a negative
 * tolerance is refused. */
static void test_edr_close_tol_zero_taken(pd_test_ctx *ctx)
{
    double g0[2] = {0.1, 1e-13}, e[2] = {1, 1}, b[3] = {0, 0, 0}, v0[3] = {1, 0, 0};
    double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, wv[4] = {-1, 1, -1, 1};
    int cp[3] = {0, 2, 4}, ri[4] = {0, 1, 1, 2};
    pd_model md = {.n = 3,
                   .m = 2,
                   .M = pd_matrix_dense(3, 3, I3),
                   .C = pd_matrix_zero(3, 3),
                   .K = pd_matrix_zero(3, 3),
                   .W = pd_matrix_csc(3, 2, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pc = {.t_start = 0.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_edr_opts eo = pd_edr_default_opts();
    eo.close_tol = -1e-300;
    pd_err err;
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    CHECK(ctx, r == NULL && err.status == PD_EINVAL, "close_tol -1e-300: %s (%s)",
          r ? "taken" : "refused", err.msg);
    pd_edr_free(r);
    eo.close_tol = 0.0;
    r = pd_edr_alloc(&md, &F, &eo, &err);
    if (!CHECK(ctx, r != NULL, "close_tol 0: %s", err.msg))
        return;
    int rc = pd_edr_run(r, 0.0, NULL, v0, 1.0, NULL, NULL, &err);
    const pd_edr_result *res = pd_edr_result_of(r);
    if (CHECK(ctx, rc == PD_OK, "%s", err.msg))
        CHECK(ctx,
              res->impacts == 2 && res->simultaneous == 0 && res->tol_closed == 0 &&
                  res->contact_impacts[0] == 1 && res->contact_impacts[1] == 1,
              "close_tol 0: impacts %ld (%ld, %ld), simultaneous %ld, closed within the "
              "tolerance %ld",
              res->impacts, res->contact_impacts[0], res->contact_impacts[1], res->simultaneous,
              res->tol_closed);
    pd_edr_free(r);
}

/* ---- a piece change's predictions ---------------------------------------------------- */

/* A two-storey shear building (unit masses and springs) pressed by a unit
 * load on both floors against a wall at its first floor (gap 0: held, its
 * force 1 + x2 > 0: a modal cluster, whose detachment is predicted by
 * scanning), its top floor from rest at 0 (x2 = 1 - cos t) bouncing
 * elastically on a second wall at x2 = 1.5: impacts at 2 pi / 3 + k 4 pi / 3
 * (x2 back to 0 at rest in between), 20 over 20 periods 4 pi / 3.  The same
 * load cut into pieces (each piece the same constant: the same motion), a
 * piece starting 0.8 before each impact: the results are the same (the
 * impacts, the extremes 1.5 and 0 to 1e-12: closed-form flights), and a
 * piece change predicts afresh from short windows (4 scan steps of
 * 2 pi / 64, doubling), which the impact 8 steps later replaces: at most 10
 * evaluations a piece change more than the uncut load (measured 4.8 fewer;
 * the window carried over from the last piece, up to 64 steps, costs 24
 * more). */
static void test_edr_piece_changes_cost_little(pd_test_ctx *ctx)
{
    enum { NP = 21 };
    double M[4] = {1.0, 0.0, 0.0, 1.0}, K[4] = {2.0, -1.0, -1.0, 1.0}, b[2] = {1.0, 1.0};
    double g0[2] = {0.0, 1.5}, e[2] = {0.5, 1.0}, wv[2] = {-1.0, -1.0};
    int cp[3] = {0, 1, 2}, ri[2] = {0, 1};
    pd_model md = {.n = 2,
                   .m = 2,
                   .M = pd_matrix_dense(2, 2, M),
                   .C = pd_matrix_zero(2, 2),
                   .K = pd_matrix_dense(2, 2, K),
                   .W = pd_matrix_csc(2, 2, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pcs[NP];
    for (int k = 0; k < NP; k++) /* piece k from 0.8 before impact k (k >= 1) */
        pcs[k] = (pd_sine_piece){.t_start = k ? PD_TWO_PI / 3.0 * (2.0 * k - 1.0) - 0.8 : 0.0,
                                 .c0 = 1.0};
    const double t1 = 20.0 * PD_TWO_PI * 2.0 / 3.0;
    double evals[2] = {0, 0};
    for (int cut = 0; cut < 2; cut++) {
        pd_piecewise_force F = {.b = b, .pieces = pcs, .npieces = cut ? NP : 1};
        pd_err err;
        pd_edr *r = pd_edr_alloc(&md, &F, NULL, &err);
        if (!CHECK(ctx, r != NULL, "%s", err.msg))
            return;
        int rc = pd_edr_run(r, 0.0, NULL, NULL, t1, NULL, NULL, &err);
        const pd_edr_result *res = pd_edr_result_of(r);
        if (CHECK(ctx, rc == PD_OK, "%s", err.msg)) {
            evals[cut] = res->evals;
            CHECK(ctx,
                  res->impacts == 20 && res->detachments == 0 &&
                      fabs(res->xpos[1] - 1.5) <= 1e-12 && fabs(res->xneg[1]) <= 1e-12,
                  "%s load: impacts %ld, detachments %ld, top floor in [%.17g, %.17g]",
                  cut ? "cut" : "uncut", res->impacts, res->detachments, -res->xneg[1],
                  res->xpos[1]);
        }
        pd_edr_free(r);
    }
    CHECK(ctx, evals[1] <= evals[0] + 10.0 * (NP - 1),
          "flight evaluations: %.0f uncut, %.0f cut into %d pieces (%.1f a piece change)", evals[0],
          evals[1], NP, (evals[1] - evals[0]) / (NP - 1));
}

/* ---- the modal cluster's paths ----------------------------------------------------- */

/* A critically damped unit oscillator (C = 2 sqrt(K M), w0 = 1 and 1e3,
 * no contact) has a defective S: its (rounded) eigenvectors are nearly
 * parallel, the modal basis condition |V|_1 |V^-1|_1 far above 1e10, and
 * the row reference refuses it (PD_ENUMERICAL, "nearly defective") rather
 * than follow modes that would cancel. */
static void test_edr_critical_damping_refused(pd_test_ctx *ctx)
{
    const double ws[2] = {1.0, 1e3};
    for (int k = 0; k < 2; k++) {
        double w = ws[k];
        double one[1] = {1.0}, C[1] = {2.0 * w}, K[1] = {w * w}, b[1] = {0.0}, x0[1] = {1.0};
        int cp[1] = {0};
        pd_model md = {.n = 1,
                       .m = 0,
                       .M = pd_matrix_dense(1, 1, one),
                       .C = pd_matrix_dense(1, 1, C),
                       .K = pd_matrix_dense(1, 1, K),
                       .W = pd_matrix_csc(1, 0, cp, NULL, NULL)};
        pd_sine_piece pc = {.t_start = 0.0};
        pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
        pd_err err;
        pd_edr *r = pd_edr_alloc(&md, &F, NULL, &err);
        if (!CHECK(ctx, r != NULL, "%s", err.msg))
            return;
        int rc = pd_edr_run(r, 0.0, x0, NULL, 10.0 / w, NULL, NULL, &err);
        CHECK(ctx, rc == PD_ENUMERICAL && strstr(err.msg, "defective") != NULL,
              "w0 = %g: rc %d (%s)", w, rc, rc ? err.msg : "ran");
        pd_edr_free(r);
    }
}

/* An overdamped unit oscillator (xi = 1.25) driven by f = 3 sin t against
 * a wall at x = -0.5 (e = 0.5): it hits the wall, rests on it and leaves it
 * again and again, each flight the same configuration (the one block, no
 * persistent contact): one modal basis, taken from the cache by every later
 * flight (the key kept whole). */
static void test_edr_modal_basis_cached(pd_test_ctx *ctx)
{
    double one[1] = {1.0}, C[1] = {2.5}, b[1] = {1.0}, g0[1] = {0.5}, e[1] = {0.5}, wv[1] = {1.0};
    int cp[2] = {0, 1}, ri[1] = {0};
    pd_model md = {.n = 1,
                   .m = 1,
                   .M = pd_matrix_dense(1, 1, one),
                   .C = pd_matrix_dense(1, 1, C),
                   .K = pd_matrix_dense(1, 1, one),
                   .W = pd_matrix_csc(1, 1, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pc = {.t_start = 0.0, .A = 3.0, .w = 1.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_err err;
    pd_edr *r = pd_edr_alloc(&md, &F, NULL, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    int rc = pd_edr_run(r, 0.0, NULL, NULL, 10.0 * PD_TWO_PI, NULL, NULL, &err);
    const pd_edr_result *res = pd_edr_result_of(r);
    if (CHECK(ctx, rc == PD_OK, "%s", err.msg))
        CHECK(ctx, res->impacts >= 5 && res->modal_bases == 1,
              "impacts %ld, detachments %ld, modal bases %ld (1)", res->impacts, res->detachments,
              res->modal_bases);
    pd_edr_free(r);
}

typedef struct gap_ctx {
    double worst, x[2];
    long samples;
} gap_ctx;

static int check_gap(const pd_state *s, void *vctx)
{
    gap_ctx *c = vctx;
    c->worst = fmax(c->worst, fabs(s->g[0]));
    c->x[0] = s->q[0];
    c->x[1] = s->q[1];
    c->samples++;
    return 0;
}

/* Two damped free unit masses (c = 1, no spring: a modal cluster) at rest
 * at x = (0, 5e-11), their contact g = x1 - x0 open by 5e-11 (under
 * close_tol 1e-10), pressed together by b = (1, -1): the contact closes at
 * the start within the tolerance, and the flight starts on it, the masses
 * moved onto g = 0 by the M-orthogonal projection (each by 2.5e-11): at
 * rest there, every sampled gap zero to 1e-15 and x = (2.5e-11, 2.5e-11)
 * to 1e-20. */
static void test_edr_modal_origin_projected(pd_test_ctx *ctx)
{
    double I2[4] = {1.0, 0.0, 0.0, 1.0}, b[2] = {1.0, -1.0}, g0[1] = {0.0}, e[1] = {0.0};
    double q0[2] = {0.0, 5e-11};
    double wv[2] = {-1.0, 1.0};
    int cp[2] = {0, 2}, ri[2] = {0, 1};
    pd_model md = {.n = 2,
                   .m = 1,
                   .M = pd_matrix_dense(2, 2, I2),
                   .C = pd_matrix_dense(2, 2, I2),
                   .K = pd_matrix_zero(2, 2),
                   .W = pd_matrix_csc(2, 1, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pc = {.t_start = 0.0, .c0 = 1.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_edr_opts eo = pd_edr_default_opts();
    eo.h_out = 0.5;
    pd_err err;
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    gap_ctx gc = {0};
    int rc = pd_edr_run(r, 0.0, q0, NULL, 5.0, check_gap, &gc, &err);
    if (CHECK(ctx, rc == PD_OK, "%s", err.msg))
        CHECK(ctx,
              gc.samples == 11 && gc.worst <= 1e-15 && fabs(gc.x[0] - 2.5e-11) <= 1e-20 &&
                  fabs(gc.x[1] - 2.5e-11) <= 1e-20,
              "%ld samples, gaps up to %.3g, x = (%.17g, %.17g)", gc.samples, gc.worst, gc.x[0],
              gc.x[1]);
    pd_edr_free(r);
}

typedef struct squeeze_ctx {
    double h, worst, x;
    long samples;
} squeeze_ctx;

static int check_squeeze(const pd_state *s, void *vctx)
{
    squeeze_ctx *c = vctx;
    c->x = fmax(c->x, fmax(fabs(s->q[0]), fabs(s->q[1])));
    if (s->t > 0.0) { /* at rest: each body's impulses balance the load's, int f */
        double load = c->h + 0.5 * (cos(s->t) - cos(s->t - c->h));
        c->worst =
            fmax(c->worst, fmax(fabs(s->P[0] - s->P[1] - load), fabs(s->P[2] - s->P[0] - load)));
        c->samples++;
    }
    return 0;
}

/* Two unit oscillators in a row squeezed between two walls, all at x = 0
 * and touching: contact 0 between them (g = x1 - x0), contact 1 the left
 * wall at body 0 (g = x0), contact 2 the right wall at body 1 (g = -x1),
 * both bodies pushed right by f = 1 - 0.5 sin t > 0.  The right wall and
 * the bodies' contact press (forces 2 f and f); the left wall at zero force
 * is held too (its free jerk f' < 0 at t = 0 closes it): a second wall on
 * the tree, locked (between the list's other two).  Nothing moves, and over
 * each sample h = 0.25 each body's impulses balance its load's:
 * P0 - P1 = P2 - P0 = int f (to 1e-12); each contact, the locked one too,
 * is in contact for the whole run (contact time 10). */
static void test_edr_rows_squeezed_between_walls(pd_test_ctx *ctx)
{
    double I2[4] = {1.0, 0.0, 0.0, 1.0}, b[2] = {1.0, 1.0}, g0[3] = {0.0, 0.0, 0.0};
    double e[3] = {0.5, 0.5, 0.5}, wv[4] = {-1.0, 1.0, 1.0, -1.0};
    int cp[4] = {0, 2, 3, 4}, ri[4] = {0, 1, 0, 1};
    pd_model md = {.n = 2,
                   .m = 3,
                   .M = pd_matrix_dense(2, 2, I2),
                   .C = pd_matrix_zero(2, 2),
                   .K = pd_matrix_dense(2, 2, I2),
                   .W = pd_matrix_csc(2, 3, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pc = {.t_start = 0.0, .A = -0.5, .w = 1.0, .c0 = 1.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_edr_opts eo = pd_edr_default_opts();
    eo.h_out = 0.25;
    pd_err err;
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    squeeze_ctx sc = {.h = 0.25};
    int rc = pd_edr_run(r, 0.0, NULL, NULL, 10.0, check_squeeze, &sc, &err);
    const pd_edr_result *res = pd_edr_result_of(r);
    if (CHECK(ctx, rc == PD_OK, "%s", err.msg)) {
        CHECK(ctx, sc.x <= 1e-12 && sc.samples == 40 && sc.worst <= 1e-12,
              "impacts %ld, events %ld, detachments %ld, |x| up to %.3g, %ld samples, impulses off "
              "by %.3g",
              res->impacts, res->events, res->detachments, sc.x, sc.samples, sc.worst);
        /* every contact, the locked one too, is held over the whole run */
        for (int a = 0; a < 3; a++)
            CHECK(ctx, fabs(res->contact_time[a] - 10.0) <= 1e-12,
                  "contact %d held %.17g of the run's 10", a, res->contact_time[a]);
    }
    pd_edr_free(r);
}

void suite_row_paths(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_edr_observer_steps_numbered);
    PD_RUN(ctx, test_edr_piece_change_releases);
    PD_RUN(ctx, test_edr_rest_lever_forces);
    PD_RUN(ctx, test_edr_stiff_overdamped_runs);
    PD_RUN(ctx, test_edr_single_contact_impacts_counted);
    PD_RUN(ctx, test_edr_close_tol_zero_taken);
    PD_RUN(ctx, test_edr_piece_changes_cost_little);
    PD_RUN(ctx, test_edr_critical_damping_refused);
    PD_RUN(ctx, test_edr_modal_basis_cached);
    PD_RUN(ctx, test_edr_modal_origin_projected);
    PD_RUN(ctx, test_edr_rows_squeezed_between_walls);
}
