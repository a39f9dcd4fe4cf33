/* test_row_rerun.c — the row reference's object run again after a run its
 * event callback stopped (the second run is whole), and its options checked
 * whatever the model. */
#include <string.h>

#include "pd_engine.h"
#include "pd_test.h"

typedef struct stop_ctx {
    int stop; /* 1: stop at the first event */
    long events;
} stop_ctx;

static int stop_at_first(const pd_edr_event *ev, void *vctx)
{
    stop_ctx *s = vctx;
    (void)ev;
    s->events++;
    return s->stop;
}

/* An undamped unit oscillator bouncing elastically on a wall at x = 0.5
 * (from x = 0 at v = 1: an impact every 4 pi / 3), 10 periods: the first
 * run stopped by its callback at the first impact, the second, on the same
 * object, sees all 15. */
static void test_edr_rerun_after_stop(pd_test_ctx *ctx)
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
    stop_ctx sc = {.stop = 1};
    pd_edr_opts eo = pd_edr_default_opts();
    eo.on_event = stop_at_first;
    eo.on_event_ctx = &sc;
    pd_err err;
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    if (!CHECK(ctx, r != NULL, "%s", err.msg))
        return;
    int rc = pd_edr_run(r, 0.0, NULL, v0, 10.0 * PD_TWO_PI, NULL, NULL, &err);
    CHECK(ctx, rc == PD_OK && sc.events == 1 && pd_edr_result_of(r)->impacts == 1,
          "first run: %s, %ld events, %ld impacts", err.msg, sc.events,
          pd_edr_result_of(r)->impacts);
    sc = (stop_ctx){.stop = 0};
    rc = pd_edr_run(r, 0.0, NULL, v0, 10.0 * PD_TWO_PI, NULL, NULL, &err);
    CHECK(ctx, rc == PD_OK && sc.events == 15 && pd_edr_result_of(r)->impacts == 15,
          "second run: %s, %ld events, %ld impacts (15)", err.msg, sc.events,
          pd_edr_result_of(r)->impacts);
    pd_edr_free(r);
}

/* An unknown LCP solver is refused at the allocation, one contact or more
 * (with one it used to pass: its LCPs are closed forms, no solver taken). */
static void test_edr_unknown_solver_refused(pd_test_ctx *ctx)
{
    double one[1] = {1.0}, b[1] = {0.0}, g0[1] = {0.5}, e[1] = {1.0}, wv[1] = {-1.0};
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
    pd_edr_opts eo = pd_edr_default_opts();
    eo.lcp_solver = (pd_lcp_method)99;
    pd_err err = {0};
    pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
    CHECK(ctx, !r && err.status == PD_EINVAL && strstr(err.msg, "lcp_solver"),
          "one contact, solver 99: %s", r ? "accepted" : err.msg);
    pd_edr_free(r);
}

/* The chatter count starts again with each run: a first run of 9999 impacts
 * on one contact (an elastic unit oscillator on a wall at 0.5, an impact
 * every 4 pi / 3 from pi / 6), then a run on the same object whose first
 * impact comes 1e-6 s after its start: one event of that contact, not the
 * 10000th within 1e-4 s (a chatter). */
static void test_edr_rerun_chatter_count_fresh(pd_test_ctx *ctx)
{
    double one[1] = {1.0}, b[1] = {0.0}, g0[1] = {0.5}, e[1] = {1.0}, wv[1] = {-1.0};
    double v0[1] = {1.0}, x1[1] = {0.5 - 1e-6};
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
    /* midway between the 9999th and the 10000th impacts */
    double tend = PD_PI / 6.0 + 9998.0 * (4.0 * PD_PI / 3.0) + 2.0;
    int rc = pd_edr_run(r, 0.0, NULL, v0, tend, NULL, NULL, &err);
    CHECK(ctx, rc == PD_OK && pd_edr_result_of(r)->impacts == 9999, "first run: %s, %ld impacts",
          rc ? err.msg : "ok", pd_edr_result_of(r)->impacts);
    rc = pd_edr_run(r, 0.0, x1, v0, 1.0, NULL, NULL, &err);
    CHECK(ctx, rc == PD_OK && pd_edr_result_of(r)->impacts == 1, "second run: %s, %ld impacts",
          rc ? err.msg : "ok", pd_edr_result_of(r)->impacts);
    pd_edr_free(r);
}

void suite_row_rerun(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_edr_rerun_after_stop);
    PD_RUN(ctx, test_edr_unknown_solver_refused);
    PD_RUN(ctx, test_edr_rerun_chatter_count_fresh);
}
