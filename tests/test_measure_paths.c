/* test_measure_paths.c — the measurements (problems/demand.c,
 * problems/scene_measure.c) and the scalar Moreau–Jean kernel
 * (engine/pd_mj1.h) on paths the other suites miss, each test killing a
 * mutant of make mutate. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "demand.h"
#include "pd_engine.h"
#include "pd_mj1.h"
#include "pd_problems.h"
#include "pd_test.h"

/* ---- problems/demand.c ---------------------------------------------------- */

/* The window's first state (tau = tau_measure) starts the cubic between
 * states: x = sin(tau - 1) (C = 0, K = 1: f = x, f' = v) noted at tau = 1
 * and 1 + pi has the Hermite pi (t - t^2) between, peak pi / 4 at t = 1/2,
 * far above both states' |f| (0 and 1e-16). */
static void test_demand_osc_window_first_interval(pd_test_ctx *ctx)
{
    pd_demand_osc d = {.C = 0.0, .K = 1.0, .tau_measure = 1.0};
    double a0 = 0.0, a1 = -sin(PD_PI); /* x'' = -x */
    pd_demand_osc_note(&d, 1.0, 0.0, 1.0, &a0, 0.0, 1);
    pd_demand_osc_note(&d, 1.0 + PD_PI, sin(PD_PI), cos(PD_PI), &a1, 0.0, 1);
    /* h = (1 + pi) - 1 is pi to 2 ulps: pi / 4 to 1e-15 */
    CHECK_NEAR(ctx, d.peak, PD_PI / 4.0, 1e-15);
    CHECK_NEAR(ctx, d.shear, PD_PI / 4.0, 1e-15);
}

/* The turn of the quintic Hermite by bisection on the sign of its rate
 * (200 halvings: to the last bit of the step), and the number of sign
 * changes of the rate on a grid of 1000 (1: the turn is unique). */
static double turn_by_bisection(const double p0[3], const double p1[3], double h, int *changes)
{
    double lo = 0.0, hi = 1.0, f, fd, prev = p0[1];
    *changes = 0;
    for (int k = 1; k <= 1000; k++) {
        pd_hermite5(p0, p1, h, k / 1000.0, &f, &fd);
        fd = k == 1000 ? p1[1] : fd;
        *changes += (fd < 0.0) != (prev < 0.0);
        prev = fd;
    }
    for (int k = 0; k < 200; k++) {
        double m = 0.5 * (lo + hi);
        pd_hermite5(p0, p1, h, m, &f, &fd);
        if ((fd < 0.0) == (p0[1] < 0.0))
            lo = m;
        else
            hi = m;
    }
    pd_hermite5(p0, p1, h, 0.5 * (lo + hi), &f, NULL);
    return f;
}

/* The turn inside a step against bisection, to 1e-13 of its value (the
 * Illinois steps stop at 1e-12 of the step, where the rate vanishes: f is
 * off by O(1e-24)), on steps with one turn each: a rate exactly 1 at the
 * first secant point s = 1/2 (no root there); a rate on which regula falsi
 * keeps one end (without Illinois' halving, 100 steps leave f off by 7 %);
 * a lopsided step, rates 600 and -5e-4 (a secant through an end's stale
 * rate creeps: f off by 2e-8). */
static void test_demand_quintic_turn_bisection(pd_test_ctx *ctx)
{
    static const struct {
        double p0[3], p1[3], h;
    } cases[] = {
        {{0.0, 3.0, 0.0}, {0.0, -3.0, 32.0}, 1.0},
        {{0.0, 5.0, -48.0}, {0.0, -0.5, 0.0}, 1.0},
        {{0.0, 600.0, 8.0}, {1.0, -5e-4, 4.0}, 0.25},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        int changes;
        double f = NAN, want = turn_by_bisection(cases[k].p0, cases[k].p1, cases[k].h, &changes);
        int found = pd_demand_quintic_turn(cases[k].p0, cases[k].p1, cases[k].h, &f);
        CHECK(ctx, changes == 1 && found == 1 && fabs(f - want) <= 1e-13 * fabs(want),
              "case %zu: turn %d at %.17g, bisection %.17g (%d sign changes)", k, found, f, want,
              changes);
    }
}

/* A step ending at rest, f' = 0 of either sign (a quarter sine to its
 * crest: rates 1 and -0.0, or mirrored -1 and +0.0): f' keeps its sign
 * inside, no turn there (the crest is the end state's own). */
static void test_demand_quintic_turn_end_at_rest(pd_test_ctx *ctx)
{
    const double up0[3] = {0.0, 1.0, 0.0}, up1[3] = {1.0, -0.0, -1.0};
    const double dn0[3] = {0.0, -1.0, 0.0}, dn1[3] = {-1.0, 0.0, 1.0};
    double f = NAN;
    CHECK(ctx, pd_demand_quintic_turn(up0, up1, 0.5 * PD_PI, &f) == 0, "rising: a turn at %g", f);
    CHECK(ctx, pd_demand_quintic_turn(dn0, dn1, 0.5 * PD_PI, &f) == 0, "falling: a turn at %g", f);
}

/* ---- problems/scene_measure.c --------------------------------------------- */

/* A building of 2 storeys against a wall at its first floor and an SDOF
 * at its top: 2 structures, 3 dofs (2 + 3 x 3 doubles of the measurement's
 * work are odd: no slack behind them for malloc), both contacts pounding. */
static pd_scene *two_storeys(pd_err *e)
{
    static const double masses[] = {3.0e5, 2.5e5}, stiff[] = {6.0e8, 4.0e8};
    pd_scene_excitation exc = {.pulse = PD_PULSE_SINE, .dir = 1, .ap = 4.0, .Tp = 0.8};
    pd_scene *sc = pd_scene_new(&exc);
    if (!sc || pd_scene_add_building(sc, "low", 2, masses, stiff, 0.05, e) ||
        pd_scene_add_sdof(sc, "flex", 1.0, 0.05, 2.0e5, e) ||
        pd_scene_add_contact(sc, PD_WALL, 0, 0, 1, 0.002, 0.5, 0, e) ||
        pd_scene_add_contact(sc, 0, 2, 1, 1, 0.01, 0.6, 1, e) || pd_scene_finish(sc, e)) {
        pd_scene_free(sc);
        return NULL;
    }
    sc->tend = 3.0;
    return sc;
}

/* A trace with room for 1 s of a 3 s reference (dt 1e-3) holds its first
 * cap = 1000 + 2 rows: full (rows = cap), it is a reference still: measured
 * into again, and a run at dt 2e-3 compared on its rows 0, 2, ..., 1000
 * (501 of them). */
static void test_measure_full_trace(pd_test_ctx *ctx)
{
    pd_err e = {0};
    pd_scene *sc = two_storeys(&e);
    pd_scene_trace tr = {0};
    pd_scene_result rr = {0}, mr = {0};
    pd_scene_errors se = {0};
    pd_run_opts o = pd_run_default_opts(), room = o;
    o.dt = room.dt = 1e-3;
    room.tend = 1.0;
    int rc = sc ? pd_scene_trace_alloc(&tr, sc, &room, &e) : PD_EINVAL;
    if (!rc)
        rc = pd_scene_result_alloc(sc, &rr, &e);
    if (!rc)
        rc = pd_scene_result_alloc(sc, &mr, &e);
    if (!rc)
        rc = pd_scene_errors_alloc(sc, &se, &e);
    for (int k = 0; k < 2 && !rc; k++) {
        rc = pd_scene_measure_reference(sc, &o, &tr, &rr, &e);
        CHECK(ctx, rc == PD_OK && tr.cap == 1002 && tr.rows == tr.cap,
              "reference %d into a trace of %ld rows: %s (%ld rows)", k, tr.cap, e.msg, tr.rows);
    }
    o.method = PD_METHOD_MOREAU;
    o.dt = 2e-3;
    if (!rc) {
        rc = pd_scene_measure_run(sc, &o, &tr, &rr, &mr, &se, &e);
        CHECK(ctx, rc == PD_OK && se.grid_points == 501 && se.err_hist_max > 0.0,
              "run on a full trace: %s (%ld points, err_hist %g)", e.msg, se.grid_points,
              se.err_hist_max);
    }
    CHECK(ctx, sc && !rc, "%s", e.msg);
    pd_scene_errors_free(&se);
    pd_scene_result_free(&mr);
    pd_scene_result_free(&rr);
    pd_scene_trace_free(&tr);
    pd_scene_free(sc);
}

/* err_hist of a run on another grid recomputed from its samples: each
 * reference row inside a step against the cubic Hermite of the step's ends
 * (the line across a step with an impulse), as compare_steps does. */
typedef struct interp_hist {
    const pd_scene *sc;
    const pd_scene_trace *ref;
    const double *scale; /* nstruct */
    double err[2];       /* nstruct */
    double x[3], v[3], t;
    long row, jumps;
    int have;
} interp_hist;

static int interp_hist_sample(const pd_scene_sample *s, void *vctx)
{
    interp_hist *g = vctx;
    const pd_scene *sc = g->sc;
    int jump = 0;
    for (int a = 0; a < sc->ncontact; a++)
        jump |= s->impulse[a] > 0.0;
    g->jumps += jump;
    for (; g->row < g->ref->rows && (double)g->row * g->ref->dt <= s->t; g->row++) {
        const double *xr = g->ref->x + (size_t)g->row * (size_t)sc->n;
        double h = s->t - g->t, r = ((double)g->row * g->ref->dt - g->t) / h;
        for (int st = 0; st < sc->nstruct; st++)
            for (int i = sc->st[st].dof; i < sc->st[st].dof + sc->st[st].storeys; i++) {
                double p0[2] = {g->x[i], g->v[i]}, p1[2] = {s->x[i], s->v[i]};
                double x = !g->have ? s->x[i]
                           : jump   ? p0[0] + r * (p1[0] - p0[0])
                                    : pd_hermite3(p0, p1, h, r);
                g->err[st] = fmax(g->err[st], fabs(x - xr[i]) / g->scale[st]);
            }
    }
    memcpy(g->x, s->x, sizeof g->x);
    memcpy(g->v, s->v, sizeof g->v);
    g->t = s->t;
    g->have = 1;
    return 0;
}

/* Moreau–Jean at dt 4.64e-4 against the reference on the grid 1e-3 (no
 * whole multiple: its steps interpolated onto every one of the 3001 rows):
 * err_hist is the recomputation's to the bit (the same operations on the
 * same doubles), above zero (first-order steps across impacts), the run's
 * steps crossing impulses (the line) and not (the cubic). */
static void test_measure_other_grid_recomputed(pd_test_ctx *ctx)
{
    pd_err e = {0};
    pd_scene *sc = two_storeys(&e);
    pd_scene_trace tr = {0};
    pd_scene_result rr = {0}, mr = {0}, own = {0};
    pd_scene_errors se = {0};
    pd_run_opts o = pd_run_default_opts();
    o.dt = 1e-3;
    int rc = sc ? pd_scene_trace_alloc(&tr, sc, &o, &e) : PD_EINVAL;
    if (!rc)
        rc = pd_scene_result_alloc(sc, &rr, &e);
    if (!rc)
        rc = pd_scene_result_alloc(sc, &mr, &e);
    if (!rc)
        rc = pd_scene_result_alloc(sc, &own, &e);
    if (!rc)
        rc = pd_scene_errors_alloc(sc, &se, &e);
    if (!rc)
        rc = pd_scene_measure_reference(sc, &o, &tr, &rr, &e);
    o.method = PD_METHOD_MOREAU;
    o.dt = 4.641588833612779e-4;
    if (!rc)
        rc = pd_scene_measure_run(sc, &o, &tr, &rr, &mr, &se, &e);
    double scale[2] = {0.0, 0.0};
    interp_hist g = {.sc = sc, .ref = &tr, .scale = scale};
    if (!rc) {
        for (int st = 0; st < 2; st++)
            for (int i = sc->st[st].dof; i < sc->st[st].dof + sc->st[st].storeys; i++)
                scale[st] = fmax(scale[st], rr.umax[i]);
        o.no_demands = o.no_law_band = 1; /* as the measurement runs it */
        rc = pd_scene_run(sc, &o, interp_hist_sample, &g, &own, &e);
    }
    if (CHECK(ctx, sc && !rc && sc->n == 3 && sc->nstruct == 2, "%s", e.msg)) {
        CHECK(ctx, se.grid_points == 3001 && g.row == 3001 && g.jumps > 0,
              "%ld rows compared, recomputed %ld (3001); %ld steps with an impulse", se.grid_points,
              g.row, g.jumps);
        for (int st = 0; st < 2; st++)
            CHECK(ctx, se.err_hist[st] > 0.0 && se.err_hist[st] == g.err[st],
                  "%s: err_hist %.17g, recomputed %.17g", sc->st[st].name, se.err_hist[st],
                  g.err[st]);
        /* without the walls no step has an impulse: every row from the cubic
         * (the largest error no longer at a step across an impact, where the
         * line would hide which interpolation ran) */
        interp_hist f = {.sc = sc, .ref = &tr, .scale = scale};
        o.no_wall = 1;
        o.no_demands = o.no_law_band = 0;
        rc = pd_scene_measure_run(sc, &o, &tr, &rr, &mr, &se, &e);
        o.no_demands = o.no_law_band = 1;
        if (!rc)
            rc = pd_scene_run(sc, &o, interp_hist_sample, &f, &own, &e);
        if (CHECK(ctx, !rc, "no walls: %s", e.msg)) {
            CHECK(ctx, f.jumps == 0 && f.row == 3001, "no walls: %ld jumps, %ld rows", f.jumps,
                  f.row);
            for (int st = 0; st < 2; st++)
                CHECK(ctx, se.err_hist[st] > 0.0 && se.err_hist[st] == f.err[st],
                      "no walls, %s: err_hist %.17g, recomputed %.17g", sc->st[st].name,
                      se.err_hist[st], f.err[st]);
        }
    }
    pd_scene_errors_free(&se);
    pd_scene_result_free(&own);
    pd_scene_result_free(&mr);
    pd_scene_result_free(&rr);
    pd_scene_trace_free(&tr);
    pd_scene_free(sc);
}

/* Moreau–Jean to a tolerance (rtol 1e-3: steps of its own) against the
 * reference on the grid 1e-3: its steps interpolated onto the rows (all but
 * the last, at 3 s: the run's last state is reported at 3 - 4e-16 s, and
 * the rows are taken up to it); its run is pd_scene_run's without demands
 * (their peaks NAN, umax the same to the bit). */
static void test_measure_rtol_run(pd_test_ctx *ctx)
{
    pd_err e = {0};
    pd_scene *sc = two_storeys(&e);
    pd_scene_trace tr = {0};
    pd_scene_result rr = {0}, mr = {0}, own = {0};
    pd_scene_errors se = {0};
    pd_run_opts o = pd_run_default_opts();
    o.dt = 1e-3;
    int rc = sc ? pd_scene_trace_alloc(&tr, sc, &o, &e) : PD_EINVAL;
    if (!rc)
        rc = pd_scene_result_alloc(sc, &rr, &e);
    if (!rc)
        rc = pd_scene_result_alloc(sc, &mr, &e);
    if (!rc)
        rc = pd_scene_result_alloc(sc, &own, &e);
    if (!rc)
        rc = pd_scene_errors_alloc(sc, &se, &e);
    if (!rc)
        rc = pd_scene_measure_reference(sc, &o, &tr, &rr, &e);
    o.method = PD_METHOD_MOREAU;
    o.dt = 0.0;
    o.rtol = 1e-3;
    if (!rc)
        rc = pd_scene_measure_run(sc, &o, &tr, &rr, &mr, &se, &e);
    o.no_demands = o.no_law_band = 1;
    if (!rc)
        rc = pd_scene_run(sc, &o, NULL, NULL, &own, &e);
    if (CHECK(ctx, sc && !rc, "%s", e.msg)) {
        /* every row of [0, 3 s] at 1e-3, the last one too (the run ends at 3 s
         * to an ulp, below it) */
        CHECK(ctx, se.grid_points == 3001 && se.err_hist_max > 0.0 && se.err_hist_max < 0.1,
              "%ld rows compared (3001), err_hist %g", se.grid_points, se.err_hist_max);
        CHECK(ctx, !memcmp(mr.umax, own.umax, 3 * sizeof(double)),
              "the measured run's umax %.17g, without demands %.17g", mr.umax[0], own.umax[0]);
        for (int i = 0; i < 3; i++)
            CHECK(ctx, isnan(mr.acc_max[i]) && isnan(mr.shear_max[i]),
                  "dof %d: demands %g %g measured", i, mr.acc_max[i], mr.shear_max[i]);
    }
    pd_scene_errors_free(&se);
    pd_scene_result_free(&own);
    pd_scene_result_free(&mr);
    pd_scene_result_free(&rr);
    pd_scene_trace_free(&tr);
    pd_scene_free(sc);
}

/* ---- engine/mj1.h ----------------------------------------------------------- */

/* mj_break_at lands on a breakpoint within tol of the step's end t1, both
 * ends of [t1 - tol, t1 + tol] in (the next step starts from F(t1+)); one
 * an ulp outside is passed (before t1) or kept for later (after). */
static void test_mj_break_window(pd_test_ctx *ctx)
{
    const double h = 0.01, t1 = 0.37, tol = 1e-9 * h, lo = t1 - tol, hi = t1 + tol;
    const struct {
        double b[3];
        int landed, next; /* the return and *next after it */
    } cases[] = {
        {{0.1, lo, 0.5}, 1, 2},  {{0.1, nextafter(lo, 0.0), 0.5}, 0, 2},
        {{0.1, hi, 0.5}, 1, 2},  {{0.1, nextafter(hi, 1.0), 0.5}, 0, 1},
        {{0.1, 0.2, 0.3}, 0, 3},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        int next = 0, landed = mj_break_at(cases[k].b, 3, &next, t1, tol);
        CHECK(ctx, landed == cases[k].landed && next == cases[k].next,
              "case %zu: landed %d, next %d (want %d, %d)", k, landed, next, cases[k].landed,
              cases[k].next);
    }
}

/* Lane 0 without a contact (a unit mass under F = 1): no contact, no gap
 * to move, g stays where pd_mjb_set_lane puts it (0: g0 + W q with g0 and W
 * 0) while q follows F = 1. */
static void unit_force(const double *t, int side, double *F, void *ctx)
{
    (void)t, (void)side, (void)ctx;
    for (int l = 0; l < PD_MJB_LANES; l++)
        F[l] = 1.0;
}

static void test_mj_batch_no_contact_gap(pd_test_ctx *ctx)
{
    pd_err e;
    pd_mjb *b = aligned_alloc(64, sizeof *b);
    pd_mjb_lane ln = {.M = 1.0, .K = 1.0, .h = 1e-2, .brk = INFINITY};
    if (!CHECK(ctx,
               b && !pd_mjb_init(b, NULL, unit_force, NULL, &e) && !pd_mjb_set_lane(b, 0, &ln, &e),
               "batch: %s", b ? e.msg : "out of memory")) {
        free(b);
        return;
    }
    pd_mjb_run(b, 100, NULL, NULL);
    /* q'' = 1 - q from rest: q(1) = 1 - cos 1, to O(h^2) at theta 1/2 (7e-6) */
    CHECK(ctx, b->g[0] == 0.0 && fabs(b->q[0] - (1.0 - cos(1.0))) < 1e-4,
          "g %g, q %g (1 - cos 1 = %g)", b->g[0], b->q[0], 1.0 - cos(1.0));
    free(b);
}

void suite_measure_paths(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_demand_osc_window_first_interval);
    PD_RUN(ctx, test_demand_quintic_turn_bisection);
    PD_RUN(ctx, test_demand_quintic_turn_end_at_rest);
    PD_RUN(ctx, test_measure_full_trace);
    PD_RUN(ctx, test_measure_other_grid_recomputed);
    PD_RUN(ctx, test_measure_rtol_run);
    PD_RUN(ctx, test_mj_break_window);
    PD_RUN(ctx, test_mj_batch_no_contact_gap);
}
