/* bench_lcp.c — `pound bench --lcp`: median time per Lemke solve.
 *
 * Problems: the Siconos test set (<shared>/data/lcp/siconos, skipped when
 * absent) and the Moreau–Jean Delassus LCPs of a chain of N unit masses
 * pounding each other (D tridiagonal, 2 on the diagonal, -1 beside it, q of
 * mixed signs from a fixed seed).  Each solve is repeated in batches of at
 * least BENCH_BATCH_S; the figure is the median over at least BENCH_MIN_RUNS
 * batches and BENCH_MIN_S seconds, divided by the batch size.  One thread. */
#include <dirent.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pd_cli.h"
#include "pd_lcp.h"

#define BENCH_MIN_RUNS 21
#define BENCH_MAX_RUNS 501
#define BENCH_MIN_S 0.1
#define BENCH_BATCH_S 50e-6
#define BENCH_MAX_FILES 256
#define CHAIN_SEED 20240611u

/* Reference figures (µs) of a widely used lexicographic Lemke on this machine class. */
typedef struct bench_ref {
    const char *name;
    double us;
} bench_ref;

static const bench_ref bench_refs[] = {
    {"mmc", 10.8}, {"tobenna", 137.0}, {"chain_100", 434.0}, {"chain_200", 3200.0}};

/* One measured problem. */
typedef struct bench_row {
    char name[64];
    int n, pivots;
    pd_lcp_outcome outcome;
    double median_us, ref_us; /* ref_us < 0: none */
} bench_row;

/* The report: rows to print as a table or as JSON. */
typedef struct bench_report {
    bench_row rows[BENCH_MAX_FILES + 8];
    int nrows;
    int failed;
    int siconos_found;
    const char *siconos_dir;
} bench_report;

/* Reference time of a problem, -1 if none. */
static double reference_us(const char *name)
{
    for (size_t k = 0; k < sizeof bench_refs / sizeof bench_refs[0]; k++)
        if (!strcmp(bench_refs[k].name, name))
            return bench_refs[k].us;
    return -1.0;
}

/* Ascending order of doubles, for qsort. */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of x[0..n) (sorts x). */
static double median(double *x, int n)
{
    qsort(x, (size_t)n, sizeof *x, cmp_double);
    return n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
}

/* Seconds for `batch` solves of (M, q). */
static double time_batch(pd_lcp_work *work, int n, const double *M, const double *q, double *z,
                         double *w, int batch, pd_lcp_info *info)
{
    double t0 = pd_wall_seconds();
    for (int b = 0; b < batch; b++)
        pd_lcp_lemke(work, n, M, q, NULL, z, w, info);
    return pd_wall_seconds() - t0;
}

/* Median µs per solve over repeated batches; the outcome into row. */
static int measure(int n, const double *M, const double *q, bench_row *row)
{
    pd_lcp_work *work = pd_lcp_alloc(n);
    double *zw = malloc(2 * (size_t)n * sizeof(double));
    double runs[BENCH_MAX_RUNS];
    int rc = 1;
    if (work && zw) {
        pd_lcp_info info;
        double once = time_batch(work, n, M, q, zw, zw + n, 1, &info);
        int batch = once >= BENCH_BATCH_S ? 1 : (int)(BENCH_BATCH_S / (once + 1e-9)) + 1;
        double total = 0.0;
        int nruns = 0;
        while (nruns < BENCH_MAX_RUNS && (nruns < BENCH_MIN_RUNS || total < BENCH_MIN_S)) {
            double t = time_batch(work, n, M, q, zw, zw + n, batch, &info);
            total += t;
            runs[nruns++] = 1e6 * t / batch;
        }
        row->n = n;
        row->pivots = info.pivots;
        row->outcome = info.outcome;
        row->median_us = median(runs, nruns);
        row->ref_us = reference_us(row->name);
        rc = info.outcome == PD_LCP_NUMERICAL || info.outcome == PD_LCP_MAX_PIVOTS;
    }
    free(zw);
    pd_lcp_free(work);
    return rc;
}

/* splitmix64: the next 64 random bits of the stream *state. */
static uint64_t splitmix64(uint64_t *state)
{
    uint64_t x = (*state += 0x9E3779B97F4A7C15ull);
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

/* Uniform in [-1, 1). */
static double uniform_pm1(uint64_t *state)
{
    return 2.0 * ((double)(splitmix64(state) >> 11) * 0x1.0p-53) - 1.0;
}

/* D = tridiag(-1/m, 2/m, -1/m) with m = 1, q uniform in [-1, 1) from a fixed seed. */
static void chain_problem(int N, double *D, double *q)
{
    uint64_t state = CHAIN_SEED + (uint64_t)N;
    memset(D, 0, (size_t)N * (size_t)N * sizeof(double));
    for (int i = 0; i < N; i++) {
        D[i + (size_t)i * N] = 2.0;
        if (i + 1 < N) {
            D[i + 1 + (size_t)i * N] = -1.0;
            D[i + (size_t)(i + 1) * N] = -1.0;
        }
        q[i] = uniform_pm1(&state);
    }
}

/* The chain problems N = 10, 50, 100, 200, 500. */
static void bench_chains(bench_report *rep)
{
    static const int sizes[] = {10, 50, 100, 200, 500};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        int N = sizes[k];
        bench_row *row = &rep->rows[rep->nrows];
        double *D = malloc((size_t)N * (size_t)N * sizeof(double));
        double *q = malloc((size_t)N * sizeof(double));
        snprintf(row->name, sizeof row->name, "chain_%d", N);
        if (D && q) {
            chain_problem(N, D, q);
            int bad = measure(N, D, q, row);
            rep->failed |= bad || row->outcome != PD_LCP_SOLVED;
            rep->nrows++;
        } else {
            rep->failed = 1;
        }
        free(D);
        free(q);
    }
}

/* Ascending order of strings, for qsort. */
static int cmp_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Sorted names of the *.dat files of dir; their count, -1 if dir is unreadable. */
static int list_dat_files(const char *dir, char **names, int max)
{
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    int count = 0;
    for (struct dirent *e = readdir(d); e && count < max; e = readdir(d)) {
        size_t len = strlen(e->d_name);
        if (len > 4 && !strcmp(e->d_name + len - 4, ".dat") && (names[count] = strdup(e->d_name)))
            count++;
    }
    closedir(d);
    qsort(names, (size_t)count, sizeof *names, cmp_name);
    return count;
}

/* "lcp_mmc.dat" -> "mmc". */
static void problem_name(const char *file, char *name, size_t size)
{
    const char *stem = strncmp(file, "lcp_", 4) ? file : file + 4;
    size_t len = strlen(stem) - 4;
    snprintf(name, size, "%.*s", (int)(len < size ? len : size - 1), stem);
}

/* Read and time one Siconos file. */
static void bench_siconos_file(bench_report *rep, const char *dir, const char *file)
{
    char path[4096];
    bench_row *row = &rep->rows[rep->nrows];
    int n = 0;
    double *M = NULL, *q = NULL;
    pd_err err;
    problem_name(file, row->name, sizeof row->name);
    if (snprintf(path, sizeof path, "%s/%s", dir, file) >= (int)sizeof path) {
        fprintf(stderr, "pound: bench: path too long: %s/%s\n", dir, file);
        rep->failed = 1;
        return;
    }
    if (pd_lcp_read(path, PD_LCP_FORMAT_SICONOS, &n, &M, &q, &err) != PD_OK) {
        fprintf(stderr, "pound: bench: %s\n", err.msg);
        rep->failed = 1;
        return;
    }
    rep->failed |= measure(n, M, q, row);
    rep->nrows++;
    free(M);
    free(q);
}

/* Every Siconos file of <shared>/data/lcp/siconos. */
static void bench_siconos(bench_report *rep, const char *shared_dir, char *dir, size_t size)
{
    char *names[BENCH_MAX_FILES];
    snprintf(dir, size, "%s/data/lcp/siconos", shared_dir ? shared_dir : "../shared");
    rep->siconos_dir = dir;
    int count = list_dat_files(dir, names, BENCH_MAX_FILES);
    rep->siconos_found = count > 0;
    for (int k = 0; k < count; k++) {
        bench_siconos_file(rep, dir, names[k]);
        free(names[k]);
    }
}

/* The table with reference figures and ratios. */
static void print_table(const bench_report *rep)
{
    printf("LCP: Lemke (lexicographic, basis-inverse updates), median us per solve over >= %d "
           "timed batches, one thread\n", BENCH_MIN_RUNS);
    if (!rep->siconos_found)
        printf("Siconos set: skipped (no .dat files in %s)\n", rep->siconos_dir);
    printf("%-28s %5s %7s %-12s %12s %10s %7s\n", "problem", "n", "pivots", "status",
           "median_us", "ref_us", "ratio");
    for (int k = 0; k < rep->nrows; k++) {
        const bench_row *r = &rep->rows[k];
        printf("%-28s %5d %7d %-12s %12.3f", r->name, r->n, r->pivots,
               pd_lcp_outcome_name(r->outcome), r->median_us);
        if (r->ref_us > 0.0)
            printf(" %10.1f %7.3f\n", r->ref_us, r->median_us / r->ref_us);
        else
            printf(" %10s %7s\n", "-", "-");
    }
    printf("ratio = ours / reference (below 1: faster)\n");
}

/* The member "lcp": {...} of the open JSON object. */
static void print_json(pd_json *js, const bench_report *rep)
{
    pd_json_begin_object(js, "lcp");
    pd_json_str(js, "siconos_dir", rep->siconos_dir);
    pd_json_bool(js, "siconos_skipped", !rep->siconos_found);
    pd_json_int(js, "min_runs", BENCH_MIN_RUNS);
    pd_json_begin_array(js, "problems");
    for (int k = 0; k < rep->nrows; k++) {
        const bench_row *r = &rep->rows[k];
        pd_json_begin_object(js, NULL);
        pd_json_str(js, "name", r->name);
        pd_json_int(js, "n", r->n);
        pd_json_int(js, "pivots", r->pivots);
        pd_json_str(js, "status", pd_lcp_outcome_name(r->outcome));
        pd_json_num(js, "median_us", r->median_us);
        if (r->ref_us > 0.0)
            pd_json_num(js, "ref_us", r->ref_us);
        else
            pd_json_null(js, "ref_us");
        pd_json_end_object(js);
    }
    pd_json_end_array(js);
    pd_json_bool(js, "failed", rep->failed);
    pd_json_end_object(js);
}

int pd_bench_lcp(pd_json *js, const char *shared_dir)
{
    char dir[4096];
    bench_report *rep = calloc(1, sizeof *rep);
    if (!rep) {
        fprintf(stderr, "pound: bench: out of memory\n");
        return 1;
    }
    bench_siconos(rep, shared_dir, dir, sizeof dir);
    bench_chains(rep);
    if (js)
        print_json(js, rep);
    else
        print_table(rep);
    int failed = rep->failed;
    free(rep);
    return failed ? 1 : 0;
}
