/* test_row_paths2.c — more of the row reference's (engine/event_row.c) rarely
 * taken paths, each test killing a mutant of make mutate:
 *   - a contact (W's column) of three nonzeros is refused, whichever column
 *     it is, and the message names it;
 *   - two bodies pushed off a wall together (closed form);
 *   - the single impact law stops a separating contact and does exactly
 *     the work 1/2 P U- it allows (no spurious PD_ENUMERICAL);
 *   - impacts of a modal cluster (solved on the dofs) count no accumulation;
 *   - a lever wall (weight -3) closed within close_tol by an impact puts
 *     its body exactly on it. */
#include <math.h>
#include <string.h>

#include "pd_core.h"
#include "pd_engine.h"
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

void suite_row_paths2(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_edr_rows_third_nonzero_refused);
    PD_RUN(ctx, test_edr_rows_pushed_off_wall);
    PD_RUN(ctx, test_edr_rows_single_law_stops_separating);
    PD_RUN(ctx, test_edr_rows_modal_impact_no_accumulation);
    PD_RUN(ctx, test_edr_rows_lever_wall_closed_on_it);
}
