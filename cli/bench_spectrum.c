/* bench_spectrum.c — `pound bench --spectrum`: the paper-scale sweep,
 * 200 Pi2 log-spaced in [0.05, 5] x Pi3 in {0.001, 0.01, 0.1, 1} x sine,
 * cosine pulses x normal, reverse (800 points, 3200 runs with the wall and
 * 800 no-wall twins), eps = 0.5, xi = 0.05, Moreau–Jean at dt = Tp/2000;
 * timed on one thread and on two OpenMP threads (best of two runs each),
 * with the two results compared bit for bit; then the same sweep by the
 * exact event-driven reference on one thread: runs/s by method and the
 * Moreau-Jean umax errors against it (median, worst).  The MPI figure comes from
 * scripts/bench_spectrum_mpi.sh (mpirun -np 2 build-mpi/pound spectrum). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_spectrum.h"

/* The sweep of the benchmark. */
static void paper_sweep(pd_spectrum *s)
{
    static const double pi3[] = {0.001, 0.01, 0.1, 1.0};
    pd_spec_init(s);
    s->pi2_min = 0.05;
    s->pi2_max = 5.0;
    s->npi2 = 200;
    s->npulse = 2;
    s->pulse[0] = PD_PULSE_SINE;
    s->pulse[1] = PD_PULSE_COSINE;
    s->ndir = 2;
    s->dir[0] = 1;
    s->dir[1] = -1;
    s->nsize = 4;
    memcpy(s->size, pi3, sizeof pi3);
    s->eps[0] = 0.5;
    s->xi[0] = 0.05;
    s->dt_per_Tp = 2000.0;
    s->opts.method = PD_METHOD_MOREAU;
}

/* Best wall time of two computations of the sweep on `threads` threads. */
static int timed(const pd_spectrum *s, int threads, pd_spec_result *res, double *best)
{
    long n = pd_spec_tasks(s);
    pd_spec_exec ex = {.threads = threads, .rank = 0, .size = 1};
    pd_err err;
    *best = HUGE_VAL;
    for (int k = 0; k < 2; k++) {
        memset(res, 0, (size_t)n * sizeof *res);
        double t0 = pd_wall_seconds();
        if (pd_spec_compute(s, &ex, res, &err))
            return 1;
        *best = fmin(*best, pd_wall_seconds() - t0);
    }
    return 0;
}

/* The sweep one task at a time by the scalar kernel (pd_spec_run_task),
 * on this thread: its wall time. */
static int timed_scalar(const pd_spectrum *s, pd_spec_result *res, double *sec)
{
    long n = pd_spec_tasks(s);
    pd_err err;
    double t0 = pd_wall_seconds();
    for (long t = 0; t < n; t++) {
        pd_spec_run_task(s, t, &res[t], &err);
        if (res[t].status)
            return 1;
    }
    *sec = pd_wall_seconds() - t0;
    return 0;
}

/* Do two result arrays agree bit for bit (timings aside)? */
static int same_results(const pd_spec_result *a, const pd_spec_result *b, long n)
{
    for (long t = 0; t < n; t++) {
        pd_spec_result x = a[t], y = b[t];
        x.cpu_s = y.cpu_s = 0.0;
        if (memcmp(&x, &y, sizeof x))
            return 0;
    }
    return 1;
}

/* The figures of the benchmark. */
typedef struct bench_fig {
    double serial_s, omp2_s, steps, event_s; /* event_s: the reference, one thread */
    double scalar_s;                         /* Moreau-Jean one task at a time */
    int scalar_identical;                    /* ... giving the batch's numbers */
    double err_median, err_worst;            /* Moreau-Jean umax against it, relative */
    long runs, points;
    int identical;
} bench_fig;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median and worst |umax_mj - umax_ref| / umax_ref over the runs with the
 * wall (the tasks after the twins); err holds n doubles of scratch. */
static void umax_errors(const pd_spectrum *s, const pd_spec_result *mj, const pd_spec_result *ref,
                        double *err, bench_fig *f)
{
    long first = pd_spec_twins(s), n = pd_spec_tasks(s) - first;
    for (long t = 0; t < n; t++)
        err[t] = fabs(mj[first + t].umax - ref[first + t].umax) / ref[first + t].umax;
    qsort(err, (size_t)n, sizeof *err, cmp_double);
    f->err_median = n ? err[n / 2] : 0.0;
    f->err_worst = n ? err[n - 1] : 0.0;
}

/* A table on stdout (js NULL) or the "spectrum" member of js. */
static void print_fig(pd_json *js, const bench_fig *f)
{
    double speedup = f->serial_s / f->omp2_s, eff = speedup / 2.0;
    if (!js) {
        printf("Spectrum sweep: 200 Pi2 in [0.05, 5] x 4 Pi3 x 2 pulses x 2 dirs, "
               "Moreau-Jean dt = Tp/2000\n");
        printf("  %ld points, %ld runs (with the no-wall twins), %.4g oscillator steps\n",
               f->points, f->runs, f->steps);
        printf("  %-22s %8.3f s  %10.4g steps/s  (%.2f ns per oscillator-step)\n",
               "serial (1 thread)", f->serial_s, f->steps / f->serial_s,
               1e9 * f->serial_s / f->steps);
        printf("  %-22s %8.3f s  %10.4g steps/s  (one task at a time: the batch %.1fx faster, "
               "bit-identical: %s)\n", "scalar kernel", f->scalar_s, f->steps / f->scalar_s,
               f->scalar_s / f->serial_s, f->scalar_identical ? "yes" : "NO");
        printf("  %-22s %8.3f s  %10.4g steps/s  speedup %.2f, efficiency %.0f %%\n",
               "OpenMP 2 threads", f->omp2_s, f->steps / f->omp2_s, speedup, 100.0 * eff);
        printf("  results of 1 and 2 threads bit-identical: %s\n", f->identical ? "yes" : "NO");
        printf("  %-22s %8.3f s  runs/s: event %.4g, Moreau-Jean %.4g (event %.2fx faster)\n",
               "event-driven (1 thread)", f->event_s, (double)f->runs / f->event_s,
               (double)f->runs / f->serial_s, f->serial_s / f->event_s);
        printf("  Moreau-Jean umax against the exact reference: median %.2g, worst %.2g\n",
               f->err_median, f->err_worst);
        printf("  targets: under 3 s on 2 cores, efficiency above 85 %%; MPI: "
               "scripts/bench_spectrum_mpi.sh\n");
        return;
    }
    pd_json_begin_object(js, "spectrum");
    pd_json_int(js, "points", f->points);
    pd_json_int(js, "runs", f->runs);
    pd_json_num(js, "steps", f->steps);
    pd_json_num(js, "serial_s", f->serial_s);
    pd_json_num(js, "scalar_serial_s", f->scalar_s);
    pd_json_bool(js, "scalar_identical", f->scalar_identical);
    pd_json_num(js, "omp2_s", f->omp2_s);
    pd_json_num(js, "speedup", speedup);
    pd_json_num(js, "efficiency", eff);
    pd_json_num(js, "steps_per_s_serial", f->steps / f->serial_s);
    pd_json_num(js, "steps_per_s_omp2", f->steps / f->omp2_s);
    pd_json_bool(js, "identical", f->identical);
    pd_json_num(js, "event_serial_s", f->event_s);
    pd_json_num(js, "runs_per_s_event", (double)f->runs / f->event_s);
    pd_json_num(js, "runs_per_s_moreau", (double)f->runs / f->serial_s);
    pd_json_num(js, "moreau_umax_err_median", f->err_median);
    pd_json_num(js, "moreau_umax_err_worst", f->err_worst);
    pd_json_num(js, "target_s", 3.0);
    pd_json_num(js, "target_efficiency", 0.85);
    pd_json_end_object(js);
}

int pd_bench_spectrum(pd_json *js)
{
    pd_spectrum s;
    bench_fig f;
    memset(&f, 0, sizeof f);
    paper_sweep(&s);
    f.runs = pd_spec_tasks(&s);
    f.points = pd_spec_points(&s);
    pd_spec_result *r1 = malloc((size_t)f.runs * sizeof *r1);
    pd_spec_result *r2 = malloc((size_t)f.runs * sizeof *r2);
    double *err = malloc((size_t)f.runs * sizeof *err);
    pd_spectrum se = s; /* the same sweep, exact */
    se.opts.method = PD_METHOD_EVENT;
    int rc = !r1 || !r2 || !err || pd_spec_validate(&s, NULL) ||
             timed(&s, 1, r1, &f.serial_s) || timed(&s, 2, r2, &f.omp2_s);
    if (!rc) {
        for (long t = 0; t < f.runs; t++)
            f.steps += (double)r1[t].steps;
        f.identical = same_results(r1, r2, f.runs);
        rc = timed_scalar(&s, r2, &f.scalar_s);
        f.scalar_identical = !rc && same_results(r1, r2, f.runs);
        rc = rc || timed(&se, 1, r2, &f.event_s);
    }
    if (!rc) {
        umax_errors(&s, r1, r2, err, &f);
        print_fig(js, &f);
    }
    free(r1);
    free(r2);
    free(err);
    return rc || !f.identical || !f.scalar_identical ? 1 : 0;
}
