/* test_row_paths2.c — more of the row reference's (engine/event_row.c) rarely
 * taken paths, each test killing a mutant of make mutate:
 *   - a contact (W's column) of three nonzeros is refused, whichever column
 *     it is, and the message names it;
 *   - two bodies pushed off a wall together (closed form);
 *   - the single impact law stops a separating contact and does exactly
 *     the work 1/2 P U- it allows (no spurious PD_ENUMERICAL);
 *   - impacts of a modal cluster (solved on the dofs) count no accumulation;
 *   - a lever wall (weight -3) closed within close_tol by an impact puts
 *     its body exactly on it;
 *   - a piece boundary where the force does not change leaves a run's
 *     results where they were (rows of SDOFs and of buildings);
 *   - a held pair pushed into a wall rests on it after one impact (the
 *     held contact's force through the wall's push). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_core.h"
#include "pd_engine.h"
#include "pd_problems.h"
#include "pd_test.h"

/* Three free unit masses (three structures); contact 0 joins mass 0 to a
 * wall, contact 1 has three nonzeros (masses 0, 1, 2): no contact of the
 * row reference, refused (PD_EINVAL) naming contact 1. */
static void test_edr_rows_third_nonzero_refused(pd_test_ctx *ctx)
{
    double one[3] = {1.0, 1.0, 1.0}, b[3] = {0.0, 0.0, 0.0};
    double g0[2] = {1.0, 1.0}, e[2] = {0.5, 0.5};
    double wv[4] = {-1.0, 1.0, -1.0, 1.0};
    int cp[3] = {0, 1, 4}, ri[4] = {0, 0, 1, 2};
    int dp[4] = {0, 1, 2, 3}, di[3] = {0, 1, 2};
    pd_model md = {.n = 3,
                   .m = 2,
                   .M = pd_matrix_csc(3, 3, dp, di, one),
                   .C = pd_matrix_zero(3, 3),
                   .K = pd_matrix_zero(3, 3),
                   .W = pd_matrix_csc(3, 2, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pc = {.t_start = 0.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_err err = {0};
    pd_edr *r = pd_edr_alloc(&md, &F, NULL, &err);
    CHECK(ctx, r == NULL && err.status == PD_EINVAL && strstr(err.msg, "contact 1 ") != NULL,
          "a contact of three nonzeros taken (status %d: %s)", err.status, err.msg);
    pd_edr_free(r);
}

/* the last observed state (the observer called at t0 and at t1) */
typedef struct last_ctx {
    int n; /* the model's dofs (at most 4) */
    int calls;
    double q[4], v[4];
} last_ctx;

static int keep_last(const pd_state *s, void *vctx)
{
    last_ctx *c = vctx;
    for (int i = 0; i < c->n; i++) {
        c->q[i] = s->q[i];
        c->v[i] = s->v[i];
    }
    c->calls++;
    return 0;
}

/* Two free unit masses A (x0) and B (x1), A pressed on a wall by b_A = 1
 * (gap -x_A), B by b_B = -3 on A through a contact of weights -1 (A, first
 * row) and +1 (B): gap x_B - x_A, whose force pushes A off the wall.  At rest
 * in contact at t = 0: held together A would pull the wall (1 - 3 < 0), so
 * A and B leave it together, a = (1 - 3) / 2 = -1: x = -t^2 / 2 at t = 1,
 * the B-A contact pressed, the wall's open. */
static void test_edr_rows_pushed_off_wall(pd_test_ctx *ctx)
{
    double one[2] = {1.0, 1.0}, b[2] = {1.0, -3.0}, g0[2] = {0.0, 0.0}, e[2] = {0.0, 0.0};
    double wv[3] = {-1.0, -1.0, 1.0}, x0[2] = {0.0, 0.0}, v0[2] = {0.0, 0.0};
    int cp[3] = {0, 1, 3}, ri[3] = {0, 0, 1}, dp[3] = {0, 1, 2}, di[2] = {0, 1};
    pd_model md = {.n = 2,
                   .m = 2,
                   .M = pd_matrix_csc(2, 2, dp, di, one),
                   .C = pd_matrix_zero(2, 2),
                   .K = pd_matrix_zero(2, 2),
                   .W = pd_matrix_csc(2, 2, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pc = {.t_start = 0.0, .c0 = 1.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_edr_opts eo = pd_edr_default_opts();
    eo.h_out = 1.0;
    pd_err err = {0};
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    last_ctx lc = {.n = md.n};
    int rc = pd_edr_run(r, 0.0, x0, v0, 1.0, keep_last, &lc, &err);
    if (CHECK(ctx, rc == PD_OK && lc.calls == 2, "%s (%d states)", err.msg, lc.calls))
        CHECK(ctx,
              fabs(lc.q[0] + 0.5) <= 1e-12 && fabs(lc.q[1] + 0.5) <= 1e-12 &&
                  fabs(lc.v[0] + 1.0) <= 1e-12 && fabs(lc.v[1] + 1.0) <= 1e-12,
              "x = (%.17g, %.17g), v = (%.17g, %.17g); closed form x = -1/2, v = -1", lc.q[0],
              lc.q[1], lc.v[0], lc.v[1]);
    pd_edr_free(r);
}

/* The single impact law on a closed row A-B-C of free unit masses (gaps
 * 0 at t = 0), v- = (10, 0, 2), e = 1: A hits B while C separates from B
 * (U- = 2).  One LCP: U+(AB) = -e U- = 10, U+(BC) = 0 (the single law
 * stops the separating contact), P = (38/3, 16/3): v+ = (-8/3, 22/3, 22/3),
 * momentum 12 kept, and the kinetic energy grows 52 -> 172/3 by exactly
 * the work 1/2 P_BC U-_BC = 16/3 the law allows (no PD_ENUMERICAL). */
static void test_edr_rows_single_law_stops_separating(pd_test_ctx *ctx)
{
    double one[3] = {1.0, 1.0, 1.0}, b[3] = {0.0, 0.0, 0.0}, g0[2] = {0.0, 0.0}, e[2] = {1.0, 1.0};
    double wv[4] = {-1.0, 1.0, -1.0, 1.0}, x0[3] = {0.0, 0.0, 0.0}, v0[3] = {10.0, 0.0, 2.0};
    int cp[3] = {0, 2, 4}, ri[4] = {0, 1, 1, 2}, dp[4] = {0, 1, 2, 3}, di[3] = {0, 1, 2};
    pd_model md = {.n = 3,
                   .m = 2,
                   .M = pd_matrix_csc(3, 3, dp, di, one),
                   .C = pd_matrix_zero(3, 3),
                   .K = pd_matrix_zero(3, 3),
                   .W = pd_matrix_csc(3, 2, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pc = {.t_start = 0.0, .c0 = 1.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_edr_opts eo = pd_edr_default_opts();
    eo.h_out = 1.0;
    eo.impact_law = PD_IMPACT_SINGLE;
    pd_err err = {0};
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    last_ctx lc = {.n = md.n};
    int rc = pd_edr_run(r, 0.0, x0, v0, 1.0, keep_last, &lc, &err);
    const pd_edr_result *res = pd_edr_result_of(r);
    if (CHECK(ctx, rc == PD_OK && lc.calls == 2, "%s (%d states)", err.msg, lc.calls))
        CHECK(ctx,
              res->impacts == 1 && fabs(lc.v[0] + 8.0 / 3.0) <= 1e-12 &&
                  fabs(lc.v[1] - 22.0 / 3.0) <= 1e-12 && fabs(lc.v[2] - 22.0 / 3.0) <= 1e-12,
              "impacts %ld, v+ = (%.17g, %.17g, %.17g); (-8/3, 22/3, 22/3)", res->impacts, lc.v[0],
              lc.v[1], lc.v[2]);
    pd_edr_free(r);
}

/* A two-dof structure (unit masses, springs k = 1 to ground and between
 * them: a modal cluster), dof 0 thrown at a wall 0.5 away (g = 0.5 - x0),
 * e = 1/2, over 3 s: impacts on the dofs (the clusters' coordinates do not
 * take a modal cluster), none an accumulation (each bounce slower, never
 * the instant's many bounces). */
static void test_edr_rows_modal_impact_no_accumulation(pd_test_ctx *ctx)
{
    double M[4] = {1.0, 0.0, 0.0, 1.0}, K[4] = {2.0, -1.0, -1.0, 2.0}, b[2] = {0.0, 0.0};
    double g0[1] = {0.5}, e[1] = {0.5}, wv[1] = {-1.0}, v0[2] = {2.0, 0.0};
    int cp[2] = {0, 1}, ri[1] = {0};
    pd_model md = {.n = 2,
                   .m = 1,
                   .M = pd_matrix_dense(2, 2, M),
                   .C = pd_matrix_zero(2, 2),
                   .K = pd_matrix_dense(2, 2, K),
                   .W = pd_matrix_csc(2, 1, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pc = {.t_start = 0.0, .c0 = 1.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_err err = {0};
    pd_edr *r = pd_edr_alloc(&md, &F, NULL, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    int rc = pd_edr_run(r, 0.0, NULL, v0, 3.0, NULL, NULL, &err);
    const pd_edr_result *res = pd_edr_result_of(r);
    if (CHECK(ctx, rc == PD_OK, "%s", err.msg))
        CHECK(ctx, res->impacts >= 1 && res->accumulations == 0 && res->modal_bases >= 1,
              "impacts %ld, accumulations %ld (none), modal bases %ld", res->impacts,
              res->accumulations, res->modal_bases);
    pd_edr_free(r);
}

/* A free unit mass A (x0 = 0, v = 1) hits a free unit mass B at rest
 * (gap 0.4 + x_B - x_A, 0.5 at t = 0) which lies 3e-14 short of a lever
 * wall (g = 0.3 - 3 x_B: 9e-14, within close_tol): the wall closes with
 * the impact and B is put on it, x_B = 0.3 / 3; e = 1, A's momentum goes
 * back through B into the wall: A leaves at v = -1 from x = 0.5 at
 * t = 0.5, x_A(2) = -1, and B stays on the wall. */
static void test_edr_rows_lever_wall_closed_on_it(pd_test_ctx *ctx)
{
    double one[2] = {1.0, 1.0}, b[2] = {0.0, 0.0}, g0[2] = {0.4, 0.3}, e[2] = {1.0, 1.0};
    double wv[3] = {-1.0, 1.0, -3.0}, x0[2] = {0.0, 0.1 - 3e-14}, v0[2] = {1.0, 0.0};
    int cp[3] = {0, 2, 3}, ri[3] = {0, 1, 1}, dp[3] = {0, 1, 2}, di[2] = {0, 1};
    pd_model md = {.n = 2,
                   .m = 2,
                   .M = pd_matrix_csc(2, 2, dp, di, one),
                   .C = pd_matrix_zero(2, 2),
                   .K = pd_matrix_zero(2, 2),
                   .W = pd_matrix_csc(2, 2, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pc = {.t_start = 0.0, .c0 = 1.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_edr_opts eo = pd_edr_default_opts();
    eo.h_out = 2.0;
    pd_err err = {0};
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    last_ctx lc = {.n = md.n};
    int rc = pd_edr_run(r, 0.0, x0, v0, 2.0, keep_last, &lc, &err);
    if (CHECK(ctx, rc == PD_OK && lc.calls == 2, "%s (%d states)", err.msg, lc.calls))
        CHECK(ctx,
              fabs(lc.q[0] + 1.0) <= 1e-14 && fabs(lc.q[1] - 0.3 / 3.0) <= 1e-16 &&
                  fabs(lc.v[0] + 1.0) <= 1e-14 && fabs(lc.v[1]) <= 1e-14,
              "x = (%.17g, %.17g), v = (%.17g, %.17g); (-1, 0.1), (-1, 0)", lc.q[0], lc.q[1],
              lc.v[0], lc.v[1]);
    pd_edr_free(r);
}

/* Two free unit masses B (x0) and A (x1) touching (gap x_B - x_A), A
 * pushed toward B by b_A = 1, a wall at 1/2 beyond B (gap 1/2 - x_B,
 * restitution 0; B numbered first, so that the wall's force acts inside
 * the held pair's subtree below the A-B edge).  Held together they accelerate at 1/2 (x = t^2 / 4) and
 * strike the wall at t = sqrt 2 as one block; the impact stops both (e =
 * 0) and the block rests on the wall: one impact, no detachment, the A-B
 * contact held for the whole run, the wall's from sqrt 2 (its force 1, the
 * A-B contact's 1 too: held through the wall's push on B). */
static void test_edr_rows_block_rests_on_wall(pd_test_ctx *ctx)
{
    double one[2] = {1.0, 1.0}, b[2] = {0.0, 1.0}, g0[2] = {0.0, 0.5}, e[2] = {0.5, 0.0};
    double wv[3] = {1.0, -1.0, -1.0}, x0[2] = {0.0, 0.0}, v0[2] = {0.0, 0.0};
    int cp[3] = {0, 2, 3}, ri[3] = {0, 1, 0}, dp[3] = {0, 1, 2}, di[2] = {0, 1};
    pd_model md = {.n = 2,
                   .m = 2,
                   .M = pd_matrix_csc(2, 2, dp, di, one),
                   .C = pd_matrix_zero(2, 2),
                   .K = pd_matrix_zero(2, 2),
                   .W = pd_matrix_csc(2, 2, cp, ri, wv),
                   .g0 = g0,
                   .e = e};
    pd_sine_piece pc = {.t_start = 0.0, .c0 = 1.0};
    pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
    pd_edr_opts eo = pd_edr_default_opts();
    eo.h_out = 1.0;
    pd_err err = {0};
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    last_ctx lc = {.n = md.n};
    int rc = pd_edr_run(r, 0.0, x0, v0, 5.0, keep_last, &lc, &err);
    const pd_edr_result *res = pd_edr_result_of(r);
    if (CHECK(ctx, rc == PD_OK, "%s", err.msg)) {
        CHECK(ctx,
              res->impacts == 1 && res->detachments == 0 &&
                  fabs(res->first_impact - sqrt(2.0)) <= 1e-12,
              "impacts %ld (first at %.17g), detachments %ld; one at t = sqrt 2, none",
              res->impacts, res->first_impact, res->detachments);
        CHECK(ctx,
              fabs(res->contact_time[0] - 5.0) <= 1e-12 &&
                  fabs(res->contact_time[1] - (5.0 - sqrt(2.0))) <= 1e-12,
              "contact times %.17g, %.17g; 5 and 5 - sqrt 2", res->contact_time[0],
              res->contact_time[1]);
        CHECK(ctx,
              fabs(lc.q[0] - 0.5) <= 1e-12 && fabs(lc.q[1] - 0.5) <= 1e-12 &&
                  fabs(lc.v[0]) <= 1e-12 && fabs(lc.v[1]) <= 1e-12,
              "x = (%.17g, %.17g), v = (%.17g, %.17g); at rest on the wall at 1/2", lc.q[0],
              lc.q[1], lc.v[0], lc.v[1]);
    }
    pd_edr_free(r);
}

/* The pieces pc[0..np) with each one cut at the fraction frac of its span
 * (the last one's up to t1) into two pieces of the same force: the linear
 * term's constant moved to the cut.  NULL when out of memory. */
static pd_sine_piece *cut_pieces(const pd_sine_piece *pc, int np, double t1, double frac, int *nout)
{
    pd_sine_piece *out = malloc((size_t)(2 * np) * sizeof *out);
    int k = 0;
    for (int i = 0; i < np && out; i++) {
        double te = i + 1 < np ? pc[i + 1].t_start : t1;
        out[k++] = pc[i];
        if (!(te > pc[i].t_start))
            continue;
        double tc = pc[i].t_start + frac * (te - pc[i].t_start);
        out[k] = pc[i];
        out[k].t_start = tc;
        out[k].c0 = pc[i].c0 + pc[i].c1 * (tc - pc[i].t_start);
        k++;
    }
    *nout = k;
    return out;
}

/* Row k of the cut test: SDOFs between walls (even k) or buildings touching
 * at every common floor, one with a wall (odd k); gaps 1e-6 .. 1e-3 m and
 * restitutions 0 .. 0.3, so that bursts end in accumulations and holds. */
static pd_scene *cut_row(uint64_t *rng, int k, pd_err *e)
{
    pd_scene_excitation exc = {.pulse = k % 4 < 2 ? PD_PULSE_SINE : PD_PULSE_COSINE,
                               .dir = 1,
                               .ap = 2.0 + 4.0 * pd_test_uniform(rng),
                               .Tp = 0.3 + 0.7 * pd_test_uniform(rng)};
    pd_scene *sc = pd_scene_new(&exc);
    int n = 2 + (k / 2) % 3, rc = sc ? 0 : PD_ENOMEM, storeys[4];
    char name[16];
    for (int s = 0; s < n && !rc; s++) {
        double m[3], kk[3];
        storeys[s] = k % 2 ? 1 + (int)(3.0 * pd_test_uniform(rng)) : 1;
        for (int i = 0; i < storeys[s]; i++) {
            m[i] = 1e5 * (1.0 + pd_test_uniform(rng));
            kk[i] = 4e8 * (0.5 + pd_test_uniform(rng));
        }
        snprintf(name, sizeof name, "S%d", s + 1);
        rc = k % 2 ? pd_scene_add_building(sc, name, storeys[s], m, kk, 0.05, e)
                   : pd_scene_add_sdof(sc, name, 0.3 + 1.7 * pd_test_uniform(rng), 0.05,
                                       0.5 + 4.5 * pd_test_uniform(rng), e);
    }
    for (int s = 0; s <= n && !rc; s++) {
        int lv = s == 0 || s == n ? 1 : (storeys[s - 1] < storeys[s] ? storeys[s - 1] : storeys[s]);
        if (k % 2 && s == n) /* buildings: one wall, on the left */
            break;
        for (int l = 1; l <= lv && !rc; l++)
            rc = pd_scene_add_contact(
                sc, s == 0 ? PD_WALL : s - 1, s == 0 ? 0 : l, s == n ? PD_WALL : s, s == n ? 0 : l,
                1e-6 * pow(1e3, pd_test_uniform(rng)), 0.3 * pd_test_uniform(rng), s, e);
    }
    if (!rc)
        rc = pd_scene_finish(sc, e);
    if (rc) {
        pd_scene_free(sc);
        return NULL;
    }
    return sc;
}

/* Cutting every piece of the forcing in two where nothing changes (an
 * event that re-origins every flight at the cut, re-decides every held
 * force and regroups) must leave the answer: each dof's peak within 1e-12
 * of it, each contact's time in contact within 4 sqrt(eps) of the run (a
 * held force that reaches zero tangentially is located only to the square
 * root of its rounding: 1.2e-9 of the run measured on one building row,
 * 3e-13 elsewhere; peaks 1.2e-14), over 24 rows with bursts, accumulations
 * and holds.  A held contact dropped at the cut, or timed again from it,
 * moves a contact time by up to the run. */
static void test_edr_rows_cut_pieces_same(pd_test_ctx *ctx)
{
    uint64_t rng = 0x77aa;
    double worst_ct = 0.0, worst_x = 0.0;
    long holds = 0, accumulations = 0;
    int compared = 0;
    for (int k = 0; k < 24; k++) {
        pd_err e;
        pd_scene *sc = cut_row(&rng, k, &e);
        if (!CHECK(ctx, sc != NULL, "row %d: %s", k, e.msg))
            continue;
        pd_scene_model sm;
        pd_sine_piece *pcs = NULL, *cut = NULL;
        int np = 0, nc = 0, m = 0, n = 0, rc = pd_scene_model_build(sc, 1, &sm, &e);
        if (rc == PD_OK && (rc = pd_osc_pieces(&sm.shape, &pcs, &np, &e)) == PD_OK) {
            double t1 = pd_scene_wp(sc) * pd_scene_default_tend(sc);
            double ct[2][16], xp[2][16];
            m = sm.model.m;
            n = sm.model.n;
            cut = cut_pieces(pcs, np, t1, 0.37, &nc);
            for (int v = 0; v < 2 && rc == PD_OK && cut && m <= 16 && n <= 16; v++) {
                pd_piecewise_force F = {
                    .b = sm.mass, .pieces = v ? cut : pcs, .npieces = v ? nc : np};
                pd_edr *r = pd_edr_alloc(&sm.model, &F, NULL, &e);
                rc = r ? pd_edr_run(r, 0.0, NULL, NULL, t1, NULL, NULL, &e) : e.status;
                if (rc == PD_OK) {
                    const pd_edr_result *res = pd_edr_result_of(r);
                    for (int a = 0; a < m; a++) {
                        ct[v][a] = res->contact_time[a];
                        holds += v == 0 && ct[v][a] > 0.0;
                    }
                    for (int i = 0; i < n; i++)
                        xp[v][i] = fmax(res->xpos[i], res->xneg[i]);
                    accumulations += v == 0 ? res->accumulations : 0;
                }
                pd_edr_free(r);
            }
            if (CHECK(ctx, rc == PD_OK && cut && m <= 16 && n <= 16, "row %d: %s", k, e.msg)) {
                for (int a = 0; a < m; a++)
                    worst_ct = fmax(worst_ct, fabs(ct[0][a] - ct[1][a]) / t1);
                for (int i = 0; i < n; i++)
                    worst_x = fmax(worst_x, fabs(xp[0][i] - xp[1][i]) / xp[0][i]);
                compared++;
            }
        }
        CHECK(ctx, rc == PD_OK, "row %d: %s", k, e.msg);
        free(cut);
        free(pcs);
        if (rc != PD_OK || pcs)
            pd_scene_model_free(&sm);
        pd_scene_free(sc);
    }
    CHECK(ctx, compared == 24 && holds >= 60 && accumulations >= 200,
          "%d rows compared, %ld contacts held, %ld accumulations", compared, holds, accumulations);
    CHECK(ctx, worst_ct <= 4.0 * sqrt(DBL_EPSILON) && worst_x <= 1e-12,
          "cut pieces move contact times by %.3g of the run, peaks by %.3g", worst_ct, worst_x);
}

void suite_row_paths2(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_edr_rows_third_nonzero_refused);
    PD_RUN(ctx, test_edr_rows_pushed_off_wall);
    PD_RUN(ctx, test_edr_rows_single_law_stops_separating);
    PD_RUN(ctx, test_edr_rows_modal_impact_no_accumulation);
    PD_RUN(ctx, test_edr_rows_lever_wall_closed_on_it);
    PD_RUN(ctx, test_edr_rows_cut_pieces_same);
    PD_RUN(ctx, test_edr_rows_block_rests_on_wall);
}
