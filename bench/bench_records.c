/* bench_records.c — `pound bench --records`: a record study, every record
 * of <shared>/data/records (skipped when absent) x 200 Pi2 log-spaced in
 * [0.05, 5] x Pi3 in {0.01, 0.05, 0.1, 0.5} x eps in {0.2, 0.5, 0.8},
 * normal direction, xi = 0.05, with the exact event-driven reference and
 * with Moreau–Jean at its default dt, on two OpenMP threads: wall time,
 * runs per second, and the accuracy of Moreau–Jean's umax against the
 * reference (median and worst relative difference over the points).  CPU
 * time: the sum of the tasks' (each measured on its thread). */
#include <dirent.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "pd_bench.h"
#include "pd_spectrum.h"

enum { RECORDS_MAX = 32, RECORDS_THREADS = 2 };

/* The figures of one method over every record. */
typedef struct method_fig {
    double wall_s, cpu_s, steps;
    long runs, failed;
} method_fig;

/* The sweep of one record. */
static void record_sweep(pd_spectrum *s, const pd_cli_record *r, pd_method method)
{
    static const double pi3[] = {0.01, 0.05, 0.1, 0.5}, eps[] = {0.2, 0.5, 0.8};
    pd_spec_init(s);
    pd_osc_set_record(&s->base, &r->rec, &r->pulse, 1.0);
    s->ap[0] = s->base.ap;
    s->pi2_min = 0.05;
    s->pi2_max = 5.0;
    s->npi2 = 200;
    s->nsize = 4;
    memcpy(s->size, pi3, sizeof pi3);
    s->neps = 3;
    memcpy(s->eps, eps, sizeof eps);
    s->xi[0] = 0.05;
    s->opts.method = method;
}

/* Compute a record's sweep with a method into res; its wall time added to f. */
static int run_sweep(const pd_cli_record *r, pd_method method, pd_spec_result *res, method_fig *f)
{
    pd_spectrum s;
    pd_err err;
    record_sweep(&s, r, method);
    long n = pd_spec_tasks(&s);
    pd_spec_exec ex = {.threads = RECORDS_THREADS, .rank = 0, .size = 1};
    memset(res, 0, (size_t)n * sizeof *res);
    double t0 = pd_wall_seconds();
    if (pd_spec_compute(&s, &ex, res, &err)) {
        fprintf(stderr, "pound: bench --records: %s: %s\n", r->rec.name, err.msg);
        return 1;
    }
    f->wall_s += pd_wall_seconds() - t0;
    f->runs += n;
    for (long t = 0; t < n; t++) {
        f->steps += (double)res[t].steps;
        f->cpu_s += res[t].cpu_s;
        f->failed += res[t].status != 0;
    }
    return 0;
}

/* Record files (*.AT2, *.at2, *.V2) of dir, sorted; their count. */
static int list_records(const char *dir, char **names, int max)
{
    DIR *d = opendir(dir);
    int n = 0;
    if (!d)
        return 0;
    for (struct dirent *e = readdir(d); e && n < max; e = readdir(d)) {
        size_t len = strlen(e->d_name);
        int at2 = len > 4 && !strcasecmp(e->d_name + len - 4, ".AT2");
        int v2 = len > 3 && !strcasecmp(e->d_name + len - 3, ".V2");
        if ((at2 || v2) && (names[n] = malloc(strlen(dir) + len + 2)))
            sprintf(names[n++], "%s/%s", dir, e->d_name);
    }
    closedir(d);
    qsort(names, (size_t)n, sizeof *names, (int (*)(const void *, const void *))strcmp);
    return n;
}

int pd_bench_records(pd_json *js, const char *shared_dir)
{
    char dir[4096], *names[RECORDS_MAX];
    snprintf(dir, sizeof dir, "%s/data/records", shared_dir ? shared_dir : "../shared");
    int nrec = list_records(dir, names, RECORDS_MAX), rc = 0;
    method_fig ev = {0}, mj = {0};
    double *rel = NULL, worst_rel = -1.0;
    long nrel = 0;
    char worst_at[512] = "";
    for (int k = 0; k < nrec && !rc; k++) {
        pd_cli_record *r = NULL;
        pd_spectrum s;
        if ((rc = pd_cli_record_load(names[k], PD_RECORD_AUTO, PD_UNITS_G, 0, &r)))
            break;
        record_sweep(&s, r, PD_METHOD_EVENT);
        long n = pd_spec_tasks(&s);
        pd_spec_result *a = malloc((size_t)n * sizeof *a), *b = malloc((size_t)n * sizeof *b);
        double *grown = realloc(rel, (size_t)(nrel + n) * sizeof *rel);
        rel = grown ? grown : rel;
        rc = !a || !b || !grown || run_sweep(r, PD_METHOD_EVENT, a, &ev) ||
             run_sweep(r, PD_METHOD_MOREAU, b, &mj);
        for (long t = 0; !rc && t < n; t++)
            if (a[t].status == 0 && b[t].status == 0 && a[t].umax > 0.0) {
                double e = fabs(b[t].umax - a[t].umax) / a[t].umax;
                rel[nrel++] = e;
                if (e > worst_rel) { /* where Moreau-Jean is furthest from the exact */
                    pd_spec_coords co;
                    pd_spec_coords_of(&s, t, &co);
                    worst_rel = e;
                    snprintf(worst_at, sizeof worst_at, "%s, Pi2 = %.4g, Pi3 = %g, eps = %g%s",
                             r->rec.name, pd_spec_pi2(&s, co.j), co.twin ? 0.0 : s.size[co.size],
                             co.twin ? 0.0 : s.eps[co.eps], co.twin ? " (no wall)" : "");
                }
            }
        free(a);
        free(b);
        pd_record_free(&r->rec);
        free(r);
    }
    for (int k = 0; k < nrec; k++)
        free(names[k]);
    qsort(rel, (size_t)nrel, sizeof *rel, pd_bench_cmp_double);
    double med = nrel ? rel[nrel / 2] : NAN, worst = nrel ? rel[nrel - 1] : NAN;
    double p95 = nrel ? rel[(long)(0.95 * (double)(nrel - 1))] : NAN;
    free(rel);
    if (js) {
        pd_json_begin_object(js, "records");
        pd_json_str(js, "dir", dir);
        pd_json_int(js, "records", nrec);
        pd_json_int(js, "threads", RECORDS_THREADS);
        pd_json_num(js, "event_wall_s", ev.wall_s);
        pd_json_num(js, "event_cpu_s", ev.cpu_s);
        pd_json_num(js, "event_runs_per_s", (double)ev.runs / ev.wall_s);
        pd_json_num(js, "moreau_wall_s", mj.wall_s);
        pd_json_num(js, "moreau_cpu_s", mj.cpu_s);
        pd_json_num(js, "moreau_runs_per_s", (double)mj.runs / mj.wall_s);
        pd_json_int(js, "runs_per_method", ev.runs);
        pd_json_int(js, "failed", ev.failed + mj.failed);
        pd_json_num(js, "moreau_umax_rel_median", med);
        pd_json_num(js, "moreau_umax_rel_p95", p95);
        pd_json_num(js, "moreau_umax_rel_max", worst);
        pd_json_str(js, "moreau_worst_at", worst_at);
        pd_json_end_object(js);
    } else if (!nrec) {
        printf("Record study: skipped (no records in %s)\n", dir);
    } else {
        printf("Record study: %d records x 200 Pi2 x 4 Pi3 x 3 eps (+ no-wall twins), xi = 0.05, "
               "normal, %d OpenMP threads\n",
               nrec, RECORDS_THREADS);
        printf("  %-26s %9s %9s %9s %12s %14s\n", "method", "runs", "wall [s]", "CPU [s]", "runs/s",
               "steps or events");
        printf("  %-26s %9ld %9.3f %9.3f %12.4g %14.4g\n", "event-driven (exact)", ev.runs,
               ev.wall_s, ev.cpu_s, (double)ev.runs / ev.wall_s, ev.steps);
        printf("  %-26s %9ld %9.3f %9.3f %12.4g %14.4g\n", "Moreau-Jean (default dt)", mj.runs,
               mj.wall_s, mj.cpu_s, (double)mj.runs / mj.wall_s, mj.steps);
        printf("  (runs/s per second of wall time; CPU: both threads' sum)\n");
        printf("  Moreau-Jean umax against the exact: median %.3g, 95th percentile %.3g, worst "
               "%.3g (relative, %ld points); %ld failed runs\n",
               med, p95, worst, nrel, ev.failed + mj.failed);
        printf("  worst at %s\n", worst_at);
    }
    return rc || ev.failed + mj.failed ? 1 : 0;
}
