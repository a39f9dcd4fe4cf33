/* bench_spectrum.c — `pound bench --spectrum`: the paper-scale sweep,
 * 200 Pi2 log-spaced in [0.05, 5] x Pi3 in {0.001, 0.01, 0.1, 1} x sine,
 * cosine pulses x normal, reverse (3200 points: 3200 runs with the wall and
 * 800 no-wall twins), eps = 0.5, xi = 0.05, Moreau–Jean at dt = Tp/2000.
 * First one task at a time by the scalar kernel (pd_spec_run_task; it has
 * no variants); then batched on one thread with each instruction set the
 * processor has (avx512, avx2, baseline up to pd_cpu_level, chosen through
 * POUND_ISA), each compared bit for bit with the scalar kernel: ROUNDS
 * rounds of one scalar computation and BATCH_RUNS of each variant, the best
 * of each kept (a shared host's slow spells last seconds: rounds give each
 * method its share of the quick ones); then at the processor's own level
 * on two OpenMP threads (the best of ROUNDS x BATCH_RUNS, compared with one
 * thread); then the same sweep by the exact event-driven reference on one
 * thread (the best of EVENT_RUNS): runs/s by method and the
 * Moreau-Jean umax errors against it (median, worst).  Times are wall and
 * CPU: the calling thread's on one thread, the sum of the tasks' (each on
 * its thread) on two.  The MPI figure comes from
 * scripts/bench_spectrum_mpi.sh (mpirun -np 2 build-mpi/pound spectrum). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_bench.h"
#include "pd_cpu.h"
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

/* The instruction sets of the batched kernel, widest first. */
static const struct {
    const char *isa; /* POUND_ISA's value */
    int level;       /* pd_cpu_level's */
} variants[] = {{"avx512", 4}, {"avx2", 3}, {"baseline", 0}};
enum { NVARIANTS = sizeof variants / sizeof variants[0] };

/* The sum of the tasks' CPU times (each measured on its thread). */
static double tasks_cpu(const pd_spec_result *res, long n)
{
    double cpu = 0.0;
    for (long t = 0; t < n; t++)
        cpu += res[t].cpu_s;
    return cpu;
}

/* Rounds of the scalar kernel and the variants, and each variant's
 * computations in a round (the batch takes a tenth of the scalar's time). */
enum { ROUNDS = 3, BATCH_RUNS = 2, EVENT_RUNS = 2 };

/* A clock that any measurement beats. */
static void clock_reset(pd_bench_clock *c)
{
    c->wall_s = c->cpu_s = HUGE_VAL;
}

/* `runs` computations of the sweep on `threads` threads, the best (by wall
 * time) kept in *best: its wall time, and its CPU time (one thread: the
 * calling thread's; more: the sum of the tasks'). */
static int timed(const pd_spectrum *s, int threads, int runs, pd_spec_result *res,
                 pd_bench_clock *best)
{
    long n = pd_spec_tasks(s);
    pd_spec_exec ex = {.threads = threads, .rank = 0, .size = 1};
    pd_err err;
    for (int k = 0; k < runs; k++) {
        memset(res, 0, (size_t)n * sizeof *res);
        pd_bench_clock t0 = pd_bench_now();
        if (pd_spec_compute(s, &ex, res, &err)) {
            fprintf(stderr, "pound: bench --spectrum: %s\n", err.msg);
            return 1;
        }
        pd_bench_clock t = pd_bench_since(t0);
        if (threads != 1)
            t.cpu_s = tasks_cpu(res, n);
        if (t.wall_s < best->wall_s)
            *best = t;
    }
    return 0;
}

/* The sweep one task at a time by the scalar kernel (pd_spec_run_task),
 * on this thread, once: its wall and CPU time kept in *best when better. */
static int timed_scalar(const pd_spectrum *s, pd_spec_result *res, pd_bench_clock *best)
{
    long n = pd_spec_tasks(s);
    pd_err err;
    memset(res, 0, (size_t)n * sizeof *res);
    pd_bench_clock t0 = pd_bench_now();
    for (long t = 0; t < n; t++) {
        pd_spec_run_task(s, t, &res[t], &err);
        if (res[t].status) {
            fprintf(stderr, "pound: bench --spectrum: %s\n", err.msg);
            return 1;
        }
    }
    pd_bench_clock t = pd_bench_since(t0);
    if (t.wall_s < best->wall_s)
        *best = t;
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

/* One instruction set's batched serial run. */
typedef struct variant_fig {
    int level;
    pd_bench_clock serial;
    int identical; /* to the scalar kernel's results */
} variant_fig;

/* The figures of the benchmark. */
typedef struct bench_fig {
    variant_fig var[NVARIANTS];
    int nvar;
    int level;                          /* the processor's (POUND_ISA capping it) */
    pd_bench_clock serial, omp2, event; /* at that level; event: the reference, one thread */
    pd_bench_clock scalar;              /* Moreau-Jean one task at a time */
    double steps;
    double err_median, err_worst; /* Moreau-Jean umax against it, relative */
    long runs, points;
    int identical;        /* 1 and 2 threads */
    int scalar_identical; /* the processor's level and the scalar kernel */
} bench_fig;

/* Median and worst |umax_mj - umax_ref| / umax_ref over the runs with the
 * wall (the tasks after the twins); err holds n doubles of scratch. */
static void umax_errors(const pd_spectrum *s, const pd_spec_result *mj, const pd_spec_result *ref,
                        double *err, bench_fig *f)
{
    long first = pd_spec_twins(s), n = pd_spec_tasks(s) - first;
    for (long t = 0; t < n; t++)
        err[t] = fabs(mj[first + t].umax - ref[first + t].umax) / ref[first + t].umax;
    qsort(err, (size_t)n, sizeof *err, pd_bench_cmp_double);
    f->err_median = n ? err[n / 2] : 0.0;
    f->err_worst = n ? err[n - 1] : 0.0;
}

/* "<name>_s" (wall) and "<name>_cpu_s". */
static void json_clock(pd_json *js, const char *name, pd_bench_clock t)
{
    char key[64];
    snprintf(key, sizeof key, "%s_s", name);
    pd_json_num(js, key, t.wall_s);
    snprintf(key, sizeof key, "%s_cpu_s", name);
    pd_json_num(js, key, t.cpu_s);
}

/* A table on stdout (js NULL) or the "spectrum" member of js. */
static void print_fig(pd_json *js, const bench_fig *f)
{
    double speedup = f->serial.wall_s / f->omp2.wall_s, eff = speedup / 2.0;
    if (!js) {
        printf("Spectrum sweep: 200 Pi2 in [0.05, 5] x 4 Pi3 x 2 pulses x 2 dirs, "
               "Moreau-Jean dt = Tp/2000\n");
        printf("  %ld points, %ld runs (with the no-wall twins), %.4g oscillator steps\n",
               f->points, f->runs, f->steps);
        printf("  %-30s %8s %8s %14s\n", "", "wall [s]", "CPU [s]", "steps/s (wall)");
        printf("  %-30s %8.3f %8.3f %14.4g  (one task at a time)\n", "scalar kernel",
               f->scalar.wall_s, f->scalar.cpu_s, f->steps / f->scalar.wall_s);
        for (int k = 0; k < f->nvar; k++) {
            const variant_fig *v = &f->var[k];
            char name[48];
            snprintf(name, sizeof name, "1 thread, %s", pd_cpu_level_name(v->level));
            printf("  %-30s %8.3f %8.3f %14.4g  %.2fx the scalar kernel (CPU; wall %.2fx), "
                   "bit-identical to it: %s\n",
                   name, v->serial.wall_s, v->serial.cpu_s, f->steps / v->serial.wall_s,
                   f->scalar.cpu_s / v->serial.cpu_s, f->scalar.wall_s / v->serial.wall_s,
                   v->identical ? "yes" : "NO");
        }
        printf("  at the processor's level, %s:\n", pd_cpu_level_name(f->level));
        printf("  %-30s %8.3f %8.3f %14.4g  (%.2f ns per oscillator-step)\n", "serial (1 thread)",
               f->serial.wall_s, f->serial.cpu_s, f->steps / f->serial.wall_s,
               1e9 * f->serial.wall_s / f->steps);
        printf("  %-30s %8.3f %8.3f %14.4g  speedup %.2f, efficiency %.0f %%\n", "OpenMP 2 threads",
               f->omp2.wall_s, f->omp2.cpu_s, f->steps / f->omp2.wall_s, speedup, 100.0 * eff);
        printf("  results of 1 and 2 threads bit-identical: %s\n", f->identical ? "yes" : "NO");
        double er = f->serial.wall_s / f->event.wall_s; /* > 1: the exact method faster */
        printf("  %-30s %8.3f %8.3f  runs/s: event %.4g, Moreau-Jean %.4g (%s %.2fx faster)\n",
               "event-driven (1 thread)", f->event.wall_s, f->event.cpu_s,
               (double)f->runs / f->event.wall_s, (double)f->runs / f->serial.wall_s,
               er >= 1.0 ? "event" : "Moreau-Jean batched", er >= 1.0 ? er : 1.0 / er);
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
    pd_json_str(js, "isa", pd_cpu_level_name(f->level));
    json_clock(js, "serial", f->serial);
    json_clock(js, "scalar_serial", f->scalar);
    pd_json_bool(js, "scalar_identical", f->scalar_identical);
    pd_json_begin_array(js, "variants");
    for (int k = 0; k < f->nvar; k++) {
        const variant_fig *v = &f->var[k];
        pd_json_begin_object(js, NULL);
        pd_json_str(js, "isa", pd_cpu_level_name(v->level));
        pd_json_int(js, "level", v->level);
        json_clock(js, "serial", v->serial);
        pd_json_num(js, "scalar_ratio", f->scalar.wall_s / v->serial.wall_s);
        pd_json_num(js, "scalar_ratio_cpu", f->scalar.cpu_s / v->serial.cpu_s);
        pd_json_bool(js, "scalar_identical", v->identical);
        pd_json_end_object(js);
    }
    pd_json_end_array(js);
    json_clock(js, "omp2", f->omp2);
    pd_json_num(js, "speedup", speedup);
    pd_json_num(js, "efficiency", eff);
    pd_json_num(js, "steps_per_s_serial", f->steps / f->serial.wall_s);
    pd_json_num(js, "steps_per_s_omp2", f->steps / f->omp2.wall_s);
    pd_json_bool(js, "identical", f->identical);
    json_clock(js, "event_serial", f->event);
    pd_json_num(js, "runs_per_s_event", (double)f->runs / f->event.wall_s);
    pd_json_num(js, "runs_per_s_moreau", (double)f->runs / f->serial.wall_s);
    pd_json_num(js, "moreau_umax_err_median", f->err_median);
    pd_json_num(js, "moreau_umax_err_worst", f->err_worst);
    pd_json_num(js, "target_s", 3.0);
    pd_json_num(js, "target_efficiency", 0.85);
    pd_json_end_object(js);
}

/* A round of the batched serial runs of each instruction set up to
 * f->level (POUND_ISA set for each, the environment restored after): its
 * figures into f->var (listed in the first round), the results at
 * f->level into own; rs: the scalar kernel's; rv: scratch. */
static int run_variants(const pd_spectrum *s, const pd_spec_result *rs, pd_spec_result *own,
                        pd_spec_result *rv, int round, bench_fig *f)
{
    const char *old = getenv("POUND_ISA");
    char saved[64];
    int rc = 0, nv = 0;
    snprintf(saved, sizeof saved, "%s", old ? old : "");
    for (int k = 0; k < NVARIANTS && !rc; k++) {
        if (variants[k].level > f->level)
            continue;
        variant_fig *v = &f->var[nv++];
        pd_spec_result *r = variants[k].level == f->level ? own : rv;
        setenv("POUND_ISA", variants[k].isa, 1);
        if (round == 0) {
            f->nvar = nv;
            v->level = pd_cpu_level();
            v->identical = 1;
            clock_reset(&v->serial);
        }
        rc = timed(s, 1, BATCH_RUNS, r, &v->serial);
        v->identical &= !rc && v->level == variants[k].level && same_results(rs, r, f->runs);
    }
    if (old)
        setenv("POUND_ISA", saved, 1);
    else
        unsetenv("POUND_ISA");
    return rc;
}

int pd_bench_spectrum(pd_json *js)
{
    pd_spectrum s;
    bench_fig f;
    memset(&f, 0, sizeof f);
    paper_sweep(&s);
    f.level = pd_cpu_level();
    f.runs = pd_spec_tasks(&s);
    f.points = pd_spec_points(&s);
    pd_spec_result *r1 = malloc((size_t)f.runs * sizeof *r1); /* batched, the processor's level */
    pd_spec_result *rs = malloc((size_t)f.runs * sizeof *rs); /* the scalar kernel */
    pd_spec_result *r2 = malloc((size_t)f.runs * sizeof *r2); /* scratch */
    double *err = malloc((size_t)f.runs * sizeof *err);
    pd_spectrum se = s; /* the same sweep, exact */
    se.opts.method = PD_METHOD_EVENT;
    int rc = !r1 || !rs || !r2 || !err || pd_spec_validate(&s, NULL);
    clock_reset(&f.scalar);
    clock_reset(&f.omp2);
    clock_reset(&f.event);
    for (int round = 0; round < ROUNDS && !rc; round++)
        rc = timed_scalar(&s, rs, &f.scalar) || run_variants(&s, rs, r1, r2, round, &f);
    if (!rc) {
        for (int k = 0; k < f.nvar; k++)
            if (f.var[k].level == f.level) {
                f.serial = f.var[k].serial;
                f.scalar_identical = f.var[k].identical;
            }
        for (long t = 0; t < f.runs; t++)
            f.steps += (double)r1[t].steps;
        rc = timed(&s, 2, ROUNDS * BATCH_RUNS, r2, &f.omp2);
        f.identical = !rc && same_results(r1, r2, f.runs);
        rc = rc || timed(&se, 1, EVENT_RUNS, r2, &f.event);
    }
    if (!rc) {
        umax_errors(&s, r1, r2, err, &f);
        print_fig(js, &f);
    }
    int all_identical = f.nvar > 0;
    for (int k = 0; k < f.nvar; k++)
        all_identical &= f.var[k].identical;
    free(r1);
    free(rs);
    free(r2);
    free(err);
    return rc || !f.identical || !all_identical ? 1 : 0;
}
