/* bench_scene.c — `pound bench --scene`: the cost of a Moreau–Jean step on
 * `--chain N` rows (N SDOFs of unit mass between two walls, periods
 * alternating 1 s and 1.5 s, harmonic ground motion of period 1 s and
 * amplitude 1 m/s^2, every gap Pi3 = 0.01, e = 0, xi = 0.05, dt = Tp / 200):
 * neighbours out of phase keep about half the contacts in the LCP.  After
 * SCENE_WARM_STEPS untimed steps (the contacts start), SCENE_DOF_STEPS / N
 * steps (at least SCENE_MIN_STEPS) are timed: ns per DOF-step, the mean
 * share of contacts in the LCP, and the growth exponent of the per-step
 * time over N = 10^3 ... 10^5.  Beside them the one-wall scene against the
 * oscillator it is (bench --engine's many_impacts case) in the same run:
 * the scene layer must cost the one-wall oscillator nothing.  Then the
 * exact event-driven reference on rows (below).  Every time is the
 * thread's CPU time, with the wall clock's beside it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_bench.h"
#include "pd_problems.h"

#define SCENE_STEPS_PER_TP 200 /* dt = Tp / 200 [s] */
#define SCENE_WARM_STEPS 200   /* one excitation period */
#define SCENE_DOF_STEPS 5e6    /* DOF-steps timed per row */
#define SCENE_MIN_STEPS 100
#define SCENE_PI3 0.01
#define SCENE_TARGET 5e6 /* DOF-steps per second at N = 10^4 */
#define SCENE_ROUNDS 3   /* the yielding rows' rounds, each beside an elastic one */
/* the yielding rows' uy / Le: most springs sliding in a step, few */
static const double SCENE_PIY[2] = {0.5, 2.0};

/* One row's figures. */
typedef struct chain_case {
    int N;
    long steps;
    double ns_per_dof_step, wall_ns_per_dof_step; /* CPU, wall */
    double active_fraction, lcp_iterations;
    double sliding_fraction; /* yielding: the share of springs that slide in a step */
    double lcp_tries;        /* yielding: the sliding set's LCPs a step */
    const char *factor, *lcp_solver;
} chain_case;

/* The share of the springs whose offset moves in each of SCENE_SLIDE_STEPS
 * more steps (untimed). */
#define SCENE_SLIDE_STEPS 200
static int slide_share(pd_mj *mj, int ns, double *share, pd_err *err)
{
    double *prev = malloc((size_t)ns * sizeof(double));
    long moved = 0;
    int rc = prev ? PD_OK : PD_ENOMEM;
    if (prev)
        memcpy(prev, pd_mj_state(mj)->up, (size_t)ns * sizeof(double));
    for (int s = 0; s < SCENE_SLIDE_STEPS && !rc; s++) {
        rc = pd_mj_step(mj, err);
        const double *up = pd_mj_state(mj)->up;
        for (int j = 0; j < ns && !rc; j++) {
            moved += up[j] != prev[j];
            prev[j] = up[j];
        }
    }
    *share = (double)moved / ((double)SCENE_SLIDE_STEPS * (double)ns);
    free(prev);
    return rc;
}

/* Time a chain of N (every SDOF yielding with uy = Piy Le when Piy > 0,
 * alpha 0.05); 1 on failure (message on stderr). */
static int time_chain(int N, double Piy, chain_case *cc)
{
    pd_scene_excitation exc = {.pulse = PD_PULSE_HARMONIC, .dir = 1, .ap = 1.0, .Tp = 1.0};
    double wp = 2.0 * PD_PI / exc.Tp, gap = SCENE_PI3 * exc.ap / (wp * wp);
    pd_scene *sc = NULL;
    pd_scene_model sm;
    pd_mj *mj = NULL;
    pd_err err;
    int rc = 1, built = 0;
    memset(cc, 0, sizeof *cc);
    cc->N = N;
    if (pd_scene_chain(N, &exc, 1.0, 1.5, 0.05, gap, 0.0, &sc, &err) ||
        (Piy > 0.0 && pd_scene_yield_every(sc, Piy * exc.ap / (wp * wp), 0.05, &err)) ||
        pd_scene_model_build(sc, 1, &sm, &err))
        goto done;
    built = 1;
    pd_mj_opts mo = pd_mj_default_opts();
    /* the model's time is tau = wp t (pd_scene_model_build, as pd_scene_run
     * steps it: h = wp dt), so dt = Tp / 200 is h = wp Tp / 200 = 2 pi / 200 */
    mo.h = wp * exc.Tp / SCENE_STEPS_PER_TP;
    if (!(mj = pd_mj_alloc(&sm.model, &mo, &err)) || pd_mj_reset(mj, 0.0, NULL, NULL, &err))
        goto done;
    for (int s = 0; s < SCENE_WARM_STEPS; s++)
        if (pd_mj_step(mj, &err))
            goto done;
    long steps = (long)(SCENE_DOF_STEPS / N), active = 0, iterations = 0;
    steps = steps > SCENE_MIN_STEPS ? steps : SCENE_MIN_STEPS;
    pd_bench_clock t0 = pd_bench_now();
    for (long s = 0; s < steps; s++) {
        if (pd_mj_step(mj, &err))
            goto done;
        const pd_state *st = pd_mj_state(mj);
        active += st->nactive;
        iterations += st->lcp_pivots;
    }
    pd_bench_clock t = pd_bench_since(t0);
    cc->steps = steps;
    cc->ns_per_dof_step = 1e9 * t.cpu_s / ((double)steps * (double)sm.model.n);
    cc->wall_ns_per_dof_step = 1e9 * t.wall_s / ((double)steps * (double)sm.model.n);
    cc->active_fraction = (double)active / ((double)steps * (double)sm.model.m);
    cc->lcp_iterations = (double)iterations / (double)steps;
    cc->factor = pd_mj_factor_name(mj);
    pd_mj_stats ms;
    if (pd_mj_get_stats(mj, &ms) == PD_OK && ms.steps > 0)
        cc->lcp_tries = (double)ms.yield_set_tries / (double)ms.steps;
    if (Piy > 0.0 && slide_share(mj, sm.model.ns, &cc->sliding_fraction, &err))
        goto done;
    rc = 0;
done:
    if (rc)
        fprintf(stderr, "pound: bench --scene: chain %d: %s\n", N, err.msg);
    pd_mj_free(mj);
    if (built)
        pd_scene_model_free(&sm);
    pd_scene_free(sc);
    return rc;
}

/* The round whose ratio is the median of SCENE_ROUNDS (3). */
static int median_round(const double *r)
{
    for (int k = 0; k < SCENE_ROUNDS; k++) {
        int below = 0, above = 0;
        for (int l = 0; l < SCENE_ROUNDS; l++)
            if (l != k) {
                below += r[l] < r[k];
                above += r[l] > r[k];
            }
        if (below <= SCENE_ROUNDS / 2 && above <= SCENE_ROUNDS / 2)
            return k;
    }
    return 0;
}

/* Least-squares slope of log(time per step) against log N over [lo, hi]. */
static double growth(const chain_case *cc, int count, int lo, int hi)
{
    pd_loglog_fit fit = {0};
    for (int i = 0; i < count; i++)
        if (cc[i].N >= lo && cc[i].N <= hi)
            pd_loglog_add(&fit, (double)cc[i].N, cc[i].ns_per_dof_step * cc[i].N);
    return pd_loglog_slope(&fit);
}

/* The median of three steps-per-second figures of a run (the scene path
 * when sc is given, else the oscillator's own), per second of CPU time
 * (rate) and of wall time (wall_rate). */
static int one_wall_rate(const pd_scene *sc, const pd_osc *c, const pd_run_opts *o, double *rate,
                         double *wall_rate)
{
    double r[3], w[3];
    pd_err err;
    for (int k = 0; k < 3; k++) {
        double t0 = pd_wall_seconds();
        long steps = 0;
        if (sc) {
            pd_scene_result res;
            if (pd_scene_result_alloc(sc, &res, &err))
                return 1;
            int rc = pd_scene_run(sc, o, NULL, NULL, &res, &err);
            r[k] = (double)res.steps / fmax(res.cpu_s, 1e-9);
            steps = res.steps;
            pd_scene_result_free(&res);
            if (rc)
                return 1;
        } else {
            pd_osc_result res;
            if (pd_osc_simulate(c, o, NULL, NULL, &res, &err))
                return 1;
            r[k] = (double)res.steps / fmax(res.cpu_s, 1e-9);
            steps = res.steps;
        }
        w[k] = (double)steps / fmax(pd_wall_seconds() - t0, 1e-9);
    }
    *rate = pd_bench_median(r, 3);
    *wall_rate = pd_bench_median(w, 3);
    return 0;
}

/* The one-wall scene against the oscillator (harmonic, Pi2 = 0.5, Pi3 =
 * 0.01, e = 0.8, dt = 1e-4 s over 1000 s): steps per second of CPU time
 * (rate[0] the scene's, rate[1] the oscillator's) and of wall time
 * (rate[2], rate[3]). */
static int one_wall(double rate[4])
{
    pd_osc c = {.pulse = PD_PULSE_HARMONIC,
                .dir = 1,
                .ap = 1.0,
                .Tp = 1.0,
                .Pi2 = 0.5,
                .Pi3 = 0.01,
                .eps = 0.8,
                .xi = 0.05};
    pd_scene_excitation exc = {.pulse = c.pulse, .dir = c.dir, .ap = c.ap, .Tp = c.Tp};
    double wp = 2.0 * PD_PI / c.Tp;
    pd_run_opts o = pd_run_default_opts();
    o.method = PD_METHOD_MOREAU; /* both by the scalar kernel */
    pd_err err;
    o.dt = 1e-4;
    o.tend = 1000.0;
    pd_scene *sc = pd_scene_new(&exc);
    int rc = !sc || pd_scene_add_sdof(sc, "oscillator", c.Tp / c.Pi2, c.xi, 1.0, &err) ||
             pd_scene_add_contact(sc, 0, 1, PD_WALL, 0, c.Pi3 * c.ap / (wp * wp), c.eps, 0, &err) ||
             pd_scene_finish(sc, &err) || one_wall_rate(sc, NULL, &o, &rate[0], &rate[2]) ||
             one_wall_rate(NULL, &c, &o, &rate[1], &rate[3]);
    pd_scene_free(sc);
    return rc;
}

/* ---- the exact event-driven reference on rows --------------------------- *
 * The work-precision row of docs/methods.md at N = 10 ... 10^4 (--chain N:
 * periods 1 s and 1.5 s, sine pulse Tp = 1 s, ap = 1 m/s^2, Pi3 = 0.05,
 * e = 0.6, xi = 0.05, 4 s), one run each: CPU, events and the cost per
 * event (goal: flat within 2x); the GSL-based general reference on the row
 * of 10 in the same run (the ratio); the 200-point spectrum of a
 * three-structure row (examples/scenes/three-sdof.json) by the reference. */
enum { ROW_SIZES = 4 };

typedef struct row_case {
    int N;
    long events, impacts;
    double cpu_s, wall_s, us_per_event; /* us_per_event: CPU */
} row_case;

/* The row of N under the event method m: PD_OK or the failure (stderr). */
static int time_row(int N, pd_method m, row_case *rc_out)
{
    pd_scene_excitation exc = {.pulse = PD_PULSE_SINE, .dir = 1, .ap = 1.0, .Tp = 1.0};
    double wp = 2.0 * PD_PI / exc.Tp, gap = 0.05 * exc.ap / (wp * wp);
    pd_scene *sc = NULL;
    pd_scene_result r = {0};
    pd_run_opts o = pd_run_default_opts();
    pd_err err;
    int rc;
    memset(rc_out, 0, sizeof *rc_out);
    rc_out->N = N;
    o.method = m;
    if ((rc = pd_scene_chain(N, &exc, 1.0, 1.5, 0.05, gap, 0.6, &sc, &err)) == PD_OK) {
        sc->tend = 4.0;
        double t0 = pd_wall_seconds();
        if (!(rc = pd_scene_result_alloc(sc, &r, &err)))
            rc = pd_scene_run(sc, &o, NULL, NULL, &r, &err);
        rc_out->wall_s = pd_wall_seconds() - t0;
    }
    if (rc)
        fprintf(stderr, "pound: bench --scene: row of %d (%s): %s\n", N, pd_method_name(m),
                err.msg);
    else {
        rc_out->events = r.steps;
        rc_out->cpu_s = r.cpu_s;
        for (int c = 0; c < sc->ncontact; c++)
            rc_out->impacts += r.impacts[c];
        rc_out->us_per_event = 1e6 * r.cpu_s / (double)(r.steps > 0 ? r.steps : 1);
    }
    pd_scene_result_free(&r);
    pd_scene_free(sc);
    return rc;
}

/* The three-structure row's 200-point spectrum (Pi2 0.1 ... 5 of S1) on one
 * thread: its CPU and wall time. */
static int time_row_spectrum(pd_bench_clock *time)
{
    pd_scene_excitation exc = {.pulse = PD_PULSE_SINE, .dir = -1, .ap = 4.0, .Tp = 0.5};
    pd_scene *sc = pd_scene_new(&exc);
    pd_err err;
    int rc = !sc || pd_scene_add_sdof(sc, "S1", 0.234, 0.05, 3e5, &err) ||
             pd_scene_add_sdof(sc, "S2", 1.1, 0.05, 2e5, &err) ||
             pd_scene_add_sdof(sc, "S3", 0.6, 0.05, 2.5e5, &err) ||
             pd_scene_add_contact(sc, PD_WALL, 0, 0, 1, 0.01, 0.08, 0, &err) ||
             pd_scene_add_contact(sc, 0, 1, 1, 1, 0.02, 0.08, 1, &err) ||
             pd_scene_add_contact(sc, 1, 1, 2, 1, 0.015, 0.71, 2, &err) ||
             pd_scene_finish(sc, &err);
    if (!rc) {
        sc->tend = 3.0;
        pd_scene_sweep w = {.sc = sc,
                            .opts = pd_run_default_opts(),
                            .ref = 0,
                            .ref_contact = 0,
                            .pi2_min = 0.1,
                            .pi2_max = 5.0,
                            .npi2 = 200};
        w.opts.method = PD_METHOD_EVENT;
        long n = pd_scene_sweep_twins(&w) + pd_scene_sweep_points(&w);
        pd_scene_point *pts = calloc((size_t)n, sizeof *pts);
        double *umax = calloc((size_t)n * 3, sizeof *umax);
        pd_bench_clock t0 = pd_bench_now();
        rc = !pts || !umax || pd_scene_sweep_run(&w, 1, pts, umax, &err);
        *time = pd_bench_since(t0);
        free(pts);
        free(umax);
    }
    if (rc)
        fprintf(stderr, "pound: bench --scene: the row's spectrum failed\n");
    pd_scene_free(sc);
    return rc;
}

int pd_bench_scene(pd_json *js)
{
    static const int sizes[] = {10, 100, 1000, 10000, 100000};
    enum { NSIZES = sizeof sizes / sizeof sizes[0] };
    chain_case cc[NSIZES];
    int rc = 0;
    for (int k = 0; k < NSIZES; k++)
        rc |= time_chain(sizes[k], 0.0, &cc[k]);
    /* yielding (every SDOF, Piy SCENE_PIY): the cost per DOF-step against the
     * elastic row's of 10^4 (goal: at most 1.5x), each timed beside an
     * elastic run in SCENE_ROUNDS rounds (the machine's drift between two
     * timings cancels): the median round's ratio */
    chain_case yc[2], yr[SCENE_ROUNDS][2], el;
    double yratio[2], ratios[2][SCENE_ROUNDS];
    for (int r = 0; r < SCENE_ROUNDS; r++)
        for (int k = 0; k < 2; k++) {
            rc |= time_chain(10000, 0.0, &el);
            rc |= time_chain(10000, SCENE_PIY[k], &yr[r][k]);
            ratios[k][r] = yr[r][k].ns_per_dof_step / el.ns_per_dof_step;
        }
    for (int k = 0; k < 2; k++) {
        int med = median_round(ratios[k]);
        yc[k] = yr[med][k];
        yratio[k] = ratios[k][med];
    }
    double ow[4] = {0.0, 0.0, 0.0, 0.0}; /* one wall: scene, oscillator; CPU, wall */
    rc |= one_wall(ow);
    double expo = growth(cc, NSIZES, 1000, 100000);
    static const int rsizes[ROW_SIZES] = {10, 100, 1000, 10000};
    row_case rows[ROW_SIZES], general;
    double lo = HUGE_VAL, hi = 0.0;
    pd_bench_clock spec = {0.0, 0.0};
    for (int k = 0; k < ROW_SIZES; k++) {
        rc |= time_row(rsizes[k], PD_METHOD_EVENT, &rows[k]);
        lo = fmin(lo, rows[k].us_per_event);
        hi = fmax(hi, rows[k].us_per_event);
    }
    rc |= time_row(10, PD_METHOD_EVENT_GENERAL, &general);
    rc |= time_row_spectrum(&spec);
    if (js) {
        pd_json_begin_object(js, "scene");
        pd_json_begin_array(js, "chains");
        for (int k = 0; k < NSIZES; k++) {
            pd_json_begin_object(js, NULL);
            pd_json_int(js, "N", cc[k].N);
            pd_json_int(js, "steps", cc[k].steps);
            pd_json_num(js, "ns_per_dof_step", cc[k].ns_per_dof_step);
            pd_json_num(js, "dof_steps_per_s", 1e9 / cc[k].ns_per_dof_step);
            pd_json_num(js, "wall_ns_per_dof_step", cc[k].wall_ns_per_dof_step);
            pd_json_num(js, "active_fraction", cc[k].active_fraction);
            pd_json_num(js, "lcp_iterations_per_step", cc[k].lcp_iterations);
            pd_json_str(js, "factor", cc[k].factor ? cc[k].factor : "?");
            pd_json_end_object(js);
        }
        pd_json_end_array(js);
        pd_json_begin_array(js, "yielding_chains");
        for (int k = 0; k < 2; k++) {
            pd_json_begin_object(js, NULL);
            pd_json_int(js, "N", yc[k].N);
            pd_json_num(js, "Piy", SCENE_PIY[k]);
            pd_json_num(js, "ns_per_dof_step", yc[k].ns_per_dof_step);
            pd_json_num(js, "wall_ns_per_dof_step", yc[k].wall_ns_per_dof_step);
            pd_json_num(js, "sliding_fraction", yc[k].sliding_fraction);
            pd_json_num(js, "active_fraction", yc[k].active_fraction);
            pd_json_num(js, "ratio_to_elastic", yratio[k]);
            pd_json_num(js, "lcps_per_step", yc[k].lcp_tries);
            pd_json_end_object(js);
        }
        pd_json_end_array(js);
        pd_json_num(js, "growth_exponent", expo);
        pd_json_num(js, "target_dof_steps_per_s", SCENE_TARGET);
        pd_json_int(js, "chains_steps_per_Tp", SCENE_STEPS_PER_TP);
        pd_json_num(js, "one_wall_scene_steps_per_s", ow[0]);
        pd_json_num(js, "one_wall_oscillator_steps_per_s", ow[1]);
        pd_json_num(js, "one_wall_ratio", ow[0] / ow[1]);
        pd_json_num(js, "one_wall_scene_wall_steps_per_s", ow[2]);
        pd_json_num(js, "one_wall_oscillator_wall_steps_per_s", ow[3]);
        pd_json_begin_array(js, "event_rows");
        for (int k = 0; k < ROW_SIZES; k++) {
            pd_json_begin_object(js, NULL);
            pd_json_int(js, "N", rows[k].N);
            pd_json_num(js, "cpu_s", rows[k].cpu_s);
            pd_json_num(js, "wall_s", rows[k].wall_s);
            pd_json_int(js, "events", rows[k].events);
            pd_json_int(js, "impacts", rows[k].impacts);
            pd_json_num(js, "us_per_event", rows[k].us_per_event);
            pd_json_end_object(js);
        }
        pd_json_end_array(js);
        pd_json_num(js, "event_rows_cost_spread", hi / lo);
        pd_json_num(js, "event_general_row10_cpu_s", general.cpu_s);
        pd_json_num(js, "event_general_row10_wall_s", general.wall_s);
        pd_json_num(js, "event_general_row10_ratio", general.cpu_s / rows[0].cpu_s);
        pd_json_num(js, "row_spectrum_200_cpu_s", spec.cpu_s);
        pd_json_num(js, "row_spectrum_200_wall_s", spec.wall_s);
        pd_json_end_object(js);
    } else {
        printf("Moreau-Jean on --chain N rows (harmonic, Pi3 = %g, e = 0, dt = Tp/%d; one core)\n",
               SCENE_PI3, SCENE_STEPS_PER_TP);
        printf("  %8s %8s %12s %14s %8s %8s %10s  %s\n", "N", "steps", "ns/DOF-step", "DOF-steps/s",
               "wall ns", "active", "LCP its", "factor");
        for (int k = 0; k < NSIZES; k++)
            printf("  %8d %8ld %12.1f %14.4g %8.1f %7.1f%% %10.1f  %s\n", cc[k].N, cc[k].steps,
                   cc[k].ns_per_dof_step, 1e9 / cc[k].ns_per_dof_step, cc[k].wall_ns_per_dof_step,
                   100 * cc[k].active_fraction, cc[k].lcp_iterations,
                   cc[k].factor ? cc[k].factor : "?");
        printf("  (ns/DOF-step and DOF-steps/s in CPU time; wall ns: per DOF-step of the wall "
               "clock)\n");
        printf("  growth exponent of the time per step, N = 1e3 ... 1e5: %.3f (goal <= 1.2); "
               "goal %.0e DOF-steps/s at N = 1e4\n",
               expo, SCENE_TARGET);
        for (int k = 0; k < 2; k++)
            printf("  yielding (every SDOF, Piy %g, alpha 0.05), N = %d: %.1f ns/DOF-step, %.2fx "
                   "the elastic row's (goal <= 1.5x; the median of %d rounds); %.1f%% of the "
                   "springs slide in a step, %.1f%% of the contacts in the LCP, %.2f LCPs a step\n",
                   SCENE_PIY[k], yc[k].N, yc[k].ns_per_dof_step, yratio[k], SCENE_ROUNDS,
                   100.0 * yc[k].sliding_fraction, 100.0 * yc[k].active_fraction, yc[k].lcp_tries);
        printf("  one-wall scene %.4g steps/s, the oscillator %.4g steps/s: ratio %.3f (CPU; wall "
               "%.4g and %.4g)\n",
               ow[0], ow[1], ow[0] / ow[1], ow[2], ow[3]);
        printf("the exact event-driven reference on --chain N rows (sine Tp = 1 s, Pi3 = 0.05, "
               "e = 0.6, 4 s; one core)\n");
        printf("  %8s %10s %10s %10s %10s %12s\n", "N", "cpu [s]", "wall [s]", "events", "impacts",
               "us/event");
        for (int k = 0; k < ROW_SIZES; k++)
            printf("  %8d %10.4g %10.4g %10ld %10ld %12.3g\n", rows[k].N, rows[k].cpu_s,
                   rows[k].wall_s, rows[k].events, rows[k].impacts, rows[k].us_per_event);
        printf(
            "  cost per event (CPU) from N = 10 to 1e4 within %.2fx (goal 2x); the row of 100 in "
            "%.3g s CPU, %.3g s wall (goal 0.2 s)\n",
            hi / lo, rows[1].cpu_s, rows[1].wall_s);
        printf("  the GSL-based general reference (event-general) on the row of 10: %.3g s CPU, "
               "%.3g s wall, %.3gx the exact one\n",
               general.cpu_s, general.wall_s, general.cpu_s / rows[0].cpu_s);
        printf("  200-point spectrum of a three-structure row (event): %.3g s CPU, %.3g s wall "
               "(goal 1 s)\n",
               spec.cpu_s, spec.wall_s);
    }
    return rc ? 1 : 0;
}
