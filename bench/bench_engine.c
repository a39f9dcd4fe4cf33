/* bench_engine.c — `pound bench --engine`: Moreau–Jean steps per second on
 * the one-wall oscillator (no history), in free flight, in persistent
 * contact (an LCP every step) and with many impacts; scalar, batched and
 * general kernels; the median of three timed runs each, beside the bound
 * the step's dependency chain sets (its operations in a row, each at the
 * latency of one dependent multiply or add measured here).  Rates are per
 * second of the thread's CPU time, with the wall clock's beside them (the
 * median of each). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_bench.h"
#include "pd_problems.h"

/* A scene of its own for persistent contact: x'' + k x = 1 pressing the
 * oscillator on a wall at x = 0 (gap 0, e = 0): active, LCP every step. */
static void push_force(double t, int side, double *F, void *ctx)
{
    (void)t;
    (void)side;
    (void)ctx;
    F[0] = 1.0;
}

typedef struct bench_case {
    const char *name;
    const char *what;
    double steps_per_s;      /* per second of CPU time */
    double wall_steps_per_s; /* per second of wall time */
    double lcp_fraction;     /* steps with an active contact */
    long steps;
    double chain_ns; /* the dependency chain's bound per step (NAN: not estimated) */
} bench_case;

/* The scalar kernel's loop-carried chain (engine/pd_mj1.h), in dependent
 * operations per step: q_k -> q_k + h theta v_k (add) -> K (mul) -> the
 * force difference (sub) -> h (mul) -> 1/What (mul) -> + v_k (add) = v_k+1
 * -> theta v (mul) -> + (1 - theta) v_k (add) -> h (mul) -> + q_k (add) =
 * q_k+1: 10.  A step with an impulse adds the closed-form LCP on the way,
 * W vfree + e U (mul, add), -b / D (mul), vfree + W^ P (mul, add): 15. */
#define CHAIN_FREE 10
#define CHAIN_CONTACT 15

/* The latency of one dependent double multiply or add on this machine
 * [ns] in CPU time, and in wall time: a chain of them timed (the median of
 * three). */
static double fp_latency_ns(double *wall_ns)
{
    volatile double seed = 1.0000001, tiny = 1e-300;
    double lat[3], wall[3];
    const long n = 20000000;
    for (int k = 0; k < 3; k++) {
        double x = seed, y = seed, z = tiny;
        pd_bench_clock t0 = pd_bench_now();
        for (long i = 0; i < n; i++) {
            x = x * y; /* each waits for the one before */
            x = x + z;
        }
        pd_bench_clock t = pd_bench_since(t0);
        lat[k] = t.cpu_s / (2.0 * (double)n) * 1e9;
        wall[k] = t.wall_s / (2.0 * (double)n) * 1e9;
        seed = x > 0.0 ? seed : x; /* keep x alive */
    }
    *wall_ns = pd_bench_median(wall, 3);
    return pd_bench_median(lat, 3);
}

/* The batched kernel: 4 x PD_MJB_LANES copies of case c (their Pi2 spread
 * by 1 %) streamed through pd_osc_run_stream; rate per oscillator-step. */
typedef struct batch_src {
    pd_osc c;
    pd_run_opts o;
    long next, n, steps;
    double cpu;
} batch_src;

static int batch_next(void *ctx, pd_osc *c, pd_run_opts *o, long *id)
{
    batch_src *b = ctx;
    if (b->next >= b->n)
        return 0;
    *c = b->c;
    c->Pi2 *= 1.0 + 0.01 * (double)b->next / (double)b->n;
    *o = b->o;
    *id = b->next++;
    return 1;
}

static void batch_done(void *ctx, long id, const pd_osc_result *res, int status, const pd_err *err)
{
    batch_src *b = ctx;
    (void)id;
    (void)err;
    b->steps += status ? 0 : res->steps;
}

static int time_batched(const pd_osc *c, const pd_run_opts *o, bench_case *bc)
{
    double rate[3], wall[3];
    pd_err err;
    for (int k = 0; k < 3; k++) {
        batch_src b = {.c = *c, .o = *o, .n = 4 * PD_MJB_LANES};
        b.o.method = PD_METHOD_MOREAU;
        pd_bench_clock t0 = pd_bench_now();
        pd_osc_run_stream(batch_next, batch_done, &b, &err);
        pd_bench_clock t = pd_bench_since(t0);
        rate[k] = (double)b.steps / fmax(t.cpu_s, 1e-9);
        wall[k] = (double)b.steps / fmax(t.wall_s, 1e-9);
        bc->steps = b.steps;
    }
    bc->steps_per_s = pd_bench_median(rate, 3);
    bc->wall_steps_per_s = pd_bench_median(wall, 3);
    bc->lcp_fraction = NAN;
    return 0;
}

/* Median rate of pd_osc_simulate over three runs. */
static int time_oscillator(const pd_osc *c, const pd_run_opts *o, bench_case *bc)
{
    double rate[3], wall[3];
    pd_osc_result r;
    pd_err err;
    for (int k = 0; k < 3; k++) {
        double t0 = pd_wall_seconds();
        if (pd_osc_simulate(c, o, NULL, NULL, &r, &err))
            return 1;
        rate[k] = (double)r.steps / fmax(r.cpu_s, 1e-9);
        wall[k] = (double)r.steps / fmax(pd_wall_seconds() - t0, 1e-9);
    }
    bc->steps_per_s = pd_bench_median(rate, 3);
    bc->wall_steps_per_s = pd_bench_median(wall, 3);
    bc->steps = r.steps;
    bc->lcp_fraction = r.contact_time / r.tend;
    return 0;
}

/* Median rate of the bare engine (no observer) on the pressing scene. */
static int time_pressing(pd_kernel kernel, pd_lcp_method solver, long nsteps, bench_case *bc)
{
    double M = 1, K = 0.01, W = -1, g0 = 0, e = 0, rate[3], wall[3];
    pd_model md = {.n = 1,
                   .m = 1,
                   .M = pd_matrix_dense(1, 1, &M),
                   .C = pd_matrix_zero(1, 1),
                   .K = pd_matrix_dense(1, 1, &K),
                   .W = pd_matrix_dense(1, 1, &W),
                   .g0 = &g0,
                   .e = &e,
                   .force = push_force};
    pd_mj_opts o = pd_mj_default_opts();
    pd_err err;
    o.h = 1e-3;
    o.kernel = kernel;
    o.lcp_solver = solver;
    pd_mj *mj = pd_mj_alloc(&md, &o, &err);
    if (!mj)
        return 1;
    long active = 0;
    for (int k = 0; k < 3; k++) {
        pd_mj_reset(mj, 0.0, NULL, NULL, &err);
        pd_bench_clock t0 = pd_bench_now();
        active = 0;
        for (long s = 0; s < nsteps; s++) {
            if (pd_mj_step(mj, &err)) {
                pd_mj_free(mj);
                return 1;
            }
            active += pd_mj_state(mj)->nactive;
        }
        pd_bench_clock t = pd_bench_since(t0);
        rate[k] = (double)nsteps / fmax(t.cpu_s, 1e-9);
        wall[k] = (double)nsteps / fmax(t.wall_s, 1e-9);
    }
    pd_mj_free(mj);
    bc->steps_per_s = pd_bench_median(rate, 3);
    bc->wall_steps_per_s = pd_bench_median(wall, 3);
    bc->steps = nsteps;
    bc->lcp_fraction = (double)active / (double)nsteps;
    return 0;
}

int pd_bench_engine(pd_json *js)
{
    bench_case cases[12];
    int n = 0, rc = 0;
    pd_run_opts o = pd_run_default_opts();
    /* free flight: harmonic excitation, the wall out of reach */
    pd_osc free_c = {.pulse = PD_PULSE_HARMONIC,
                     .dir = 1,
                     .ap = 1.0,
                     .Tp = 1.0,
                     .Pi2 = 0.5,
                     .Pi3 = 1e9,
                     .eps = 0.5,
                     .xi = 0.05};
    o.dt = 1e-4;
    o.tend = 1000.0;
    cases[n] =
        (bench_case){.name = "free_flight", .what = "harmonic, no contact, oscillator observer"};
    rc |= time_oscillator(&free_c, &o, &cases[n++]);
    /* many impacts: harmonic, small gap, eps = 0.8 */
    pd_osc imp_c = {.pulse = PD_PULSE_HARMONIC,
                    .dir = 1,
                    .ap = 1.0,
                    .Tp = 1.0,
                    .Pi2 = 0.5,
                    .Pi3 = 0.01,
                    .eps = 0.8,
                    .xi = 0.05};
    cases[n] = (bench_case){.name = "many_impacts", .what = "harmonic, Pi3 = 0.01, eps = 0.8"};
    rc |= time_oscillator(&imp_c, &o, &cases[n++]);
    /* persistent contact: a normal sine pulse, eps = 0, long resting phases */
    pd_osc rest_c = {.pulse = PD_PULSE_HARMONIC,
                     .dir = 1,
                     .ap = 1.0,
                     .Tp = 1.0,
                     .Pi2 = 0.3,
                     .Pi3 = 0.0,
                     .eps = 0.0,
                     .xi = 0.05};
    cases[n] = (bench_case){.name = "contact_phases",
                            .what = "harmonic, Pi3 = 0, eps = 0 (rests half the time)"};
    rc |= time_oscillator(&rest_c, &o, &cases[n++]);
    cases[n] = (bench_case){.name = "persistent_scalar",
                            .what = "pressed on the wall, LCP every step, scalar kernel"};
    rc |= time_pressing(PD_KERNEL_AUTO, PD_LCP_AUTO, 10000000, &cases[n++]);
    cases[n] = (bench_case){.name = "persistent_general",
                            .what = "the same, general kernel (one contact: the closed form)"};
    rc |= time_pressing(PD_KERNEL_GENERAL, PD_LCP_AUTO, 4000000, &cases[n++]);
    cases[n] = (bench_case){.name = "persistent_lemke",
                            .what = "the same, general kernel, --lcp-solver lemke"};
    rc |= time_pressing(PD_KERNEL_GENERAL, PD_LCP_LEMKE, 2000000, &cases[n++]);
    /* the yielding step (issue 30): the same runs with a spring that yields
     * (Piy 0.3, alpha 0.05: it slides in about a tenth of the steps) */
    pd_osc yfree_c = free_c, yimp_c = imp_c;
    yfree_c.Piy = yimp_c.Piy = 0.3;
    yfree_c.alpha = yimp_c.alpha = 0.05;
    cases[n] = (bench_case){.name = "yielding_free",
                            .what = "free_flight with a yielding spring (Piy 0.3, alpha 0.05)"};
    rc |= time_oscillator(&yfree_c, &o, &cases[n++]);
    cases[n] =
        (bench_case){.name = "yielding_impacts",
                     .what = "many_impacts with the yielding spring (it drifts off the wall)"};
    rc |= time_oscillator(&yimp_c, &o, &cases[n++]);
    /* the batched kernel on the free flight and the impacts (shorter runs) */
    pd_run_opts ob = o;
    ob.tend = 100.0;
    cases[n] = (bench_case){.name = "batched_free_flight",
                            .what = "free_flight, 128 oscillators on the batch's lanes"};
    rc |= time_batched(&free_c, &ob, &cases[n++]);
    cases[n] = (bench_case){.name = "batched_impacts",
                            .what = "many_impacts, 128 oscillators on the batch's lanes"};
    rc |= time_batched(&imp_c, &ob, &cases[n++]);
    /* the chains' bounds: the scalar kernel's per step, the batch's per
     * oscillator-step (its lanes' chains overlap) */
    double lat_wall, lat = fp_latency_ns(&lat_wall);
    for (int k = 0; k < n; k++) {
        const char *nm = cases[k].name;
        int batched = !strncmp(nm, "batched", 7),
            general = strstr(nm, "general") || strstr(nm, "lemke") || strstr(nm, "yielding");
        double ops = !strcmp(nm, "persistent_scalar") ? CHAIN_CONTACT : CHAIN_FREE;
        cases[k].chain_ns = general ? NAN : ops * lat / (batched ? PD_MJB_LANES : 1);
    }

    if (js) {
        pd_json_begin_object(js, "engine");
        pd_json_num(js, "target_free_steps_per_s", 20e6);
        pd_json_num(js, "target_lcp_steps_per_s", 5e6);
        pd_json_num(js, "fp_latency_ns", lat);
        pd_json_num(js, "fp_latency_wall_ns", lat_wall);
        pd_json_int(js, "batch_lanes", PD_MJB_LANES);
        pd_json_begin_array(js, "cases");
        for (int k = 0; k < n; k++) {
            pd_json_begin_object(js, NULL);
            pd_json_str(js, "name", cases[k].name);
            pd_json_str(js, "what", cases[k].what);
            pd_json_num(js, "steps_per_s", cases[k].steps_per_s);
            pd_json_num(js, "ns_per_step", 1e9 / cases[k].steps_per_s);
            pd_json_num(js, "wall_steps_per_s", cases[k].wall_steps_per_s);
            pd_json_num(js, "wall_ns_per_step", 1e9 / cases[k].wall_steps_per_s);
            pd_json_num(js, "chain_ns_per_step", cases[k].chain_ns);
            pd_json_num(js, "active_fraction", cases[k].lcp_fraction);
            pd_json_int(js, "steps", cases[k].steps);
            pd_json_end_object(js);
        }
        pd_json_end_array(js);
        pd_json_end_object(js);
    } else {
        printf("Moreau-Jean engine, one-wall oscillator (median of 3 runs, one core; steps/s and "
               "ns/step in CPU time, wall: ns/step of the wall clock)\n");
        printf("  %-20s %14s %10s %10s %10s %8s  %s\n", "case", "steps/s", "ns/step", "wall ns",
               "chain", "active", "what");
        for (int k = 0; k < n; k++) {
            char chain[16] = "-", active[16] = "-";
            if (isfinite(cases[k].chain_ns))
                snprintf(chain, sizeof chain, "%.2f", cases[k].chain_ns);
            if (isfinite(cases[k].lcp_fraction))
                snprintf(active, sizeof active, "%.1f%%", 100 * cases[k].lcp_fraction);
            printf("  %-20s %14.4g %10.2f %10.2f %10s %8s  %s\n", cases[k].name,
                   cases[k].steps_per_s, 1e9 / cases[k].steps_per_s,
                   1e9 / cases[k].wall_steps_per_s, chain, active, cases[k].what);
        }
        printf("  chain: the bound of the step's dependency chain (%d dependent operations, %d "
               "with an impulse, at %.2f ns each, measured (wall %.2f ns); batched: per "
               "oscillator, the %d lanes' chains overlapping)\n",
               CHAIN_FREE, CHAIN_CONTACT, lat, lat_wall, PD_MJB_LANES);
        printf("  yielding: %.2fx the elastic step's time in free flight, %.2fx with impacts (the "
               "measured run's energy sums included)\n",
               cases[0].steps_per_s / cases[6].steps_per_s,
               cases[1].steps_per_s / cases[7].steps_per_s);
        printf("  targets: 20e6 steps/s in free flight, 5e6 steps/s with an LCP every step\n");
    }
    return rc ? 1 : 0;
}
