/* bench_lcp.c — `pound bench --lcp`: the solvers of the table side by side
 * on the Siconos test set (when ../shared/data/lcp/siconos is there) and on
 * the Moreau–Jean Delassus LCPs of a chain of N unit masses pounding each
 * other (D tridiagonal, 2 on the diagonal, -1 beside it, q uniform in
 * [-1, 1) from fixed seeds; compressed columns for the structured solver
 * and PGS, dense for Lemke up to N = 500).  Each solve is repeated in
 * batches of at least BENCH_BATCH_S; the figure is the median over at least
 * BENCH_MIN_RUNS batches and BENCH_MIN_S seconds (3 runs once a solve takes
 * longer than BENCH_LONG_S), divided by the batch size.  Solves are cold
 * (no warm start), and on a chain every timed solve has a new right-hand
 * side, made before its batch (the same q repeated thousands of times lets
 * the processor's branch predictor learn the solver's data-dependent
 * branches for it, which a time step's new q never allows: at N = 1000 the
 * structured solver took 21 ns per contact on one q repeated and 25 on 128
 * in turn, on an AMD EPYC); the pivots, iterations and residual are means
 * over CHAIN_SEEDS seeds (PGS, whose sweeps are fixed: one q for all).
 * The growth exponent is the least-squares slope of log CPU time against
 * log N over N = 10^3 ... 10^5.  One thread; every figure in wall time and
 * in the thread's CPU time (median of each). */
#include <dirent.h>
#include <math.h>
#include <unistd.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pd_bench.h"
#include "pd_lcp.h"

#define BENCH_MIN_RUNS 21
#define BENCH_MAX_RUNS 501
#define BENCH_MIN_S 0.1
#define BENCH_BATCH_S 50e-6
#define BENCH_LONG_S 0.05
#define BENCH_MAX_FILES 256
#define BENCH_PGS_SWEEPS 2000 /* PGS's budget on the chains: its residual is reported */
#define CHAIN_SEEDS 5
#define CHAIN_FRESH_SEED 1000 /* the timed solves' right-hand sides, seeds from here on */
#define GROWTH_ROUNDS 3
#define DENSE_BAND_N 1000    /* the chain given densely (issue 20, goal 4) */
#define GOAL_PER_CONTACT 1.1 /* time per contact at N = 1e5 over that at 1e3, at most */
#define GOAL_DENSE_BAND 2.0  /* a band given densely over the banded path, at most */

/* One measured problem and solver. */
typedef struct bench_row {
    char name[64];
    const char *solver;
    int n, pivots, iterations;
    pd_lcp_outcome outcome;
    double residual;
    double median_us;     /* wall */
    double median_cpu_us; /* the thread's CPU */
} bench_row;

/* The report: rows to print as a table or as JSON. */
typedef struct bench_report {
    bench_row rows[3 * BENCH_MAX_FILES + 64];
    int nrows;
    int failed;
    int siconos_found;
    const char *siconos_dir;
    /* a chain of DENSE_BAND_N given densely (seed 0), CPU µs per solve: in
     * compressed columns, dense in memory (the table's pass over n^2
     * entries each solve), the band's copy from the dense matrix
     * (pd_lcp_band_csc), and the parse of its plain file (one read) */
    double band_csc_us, band_dense_us, band_copy_us, band_parse_us;
    int band_ok;
    /* the structured solver's CPU ns per contact at N = 1e3 and 1e5, a new
     * q each solve and one q (seed 0) repeated (what a branch predictor
     * trained on it gives): the best of GROWTH_ROUNDS (growth_rounds) */
    double fresh_ns3, fresh_ns5, repeated_ns3, repeated_ns5;
} bench_report;

/* Wall and CPU seconds for `batch` solves of M, solve b with the
 * right-hand side at q + b step (step 0: q each time); *failed gets the
 * solves that did not return PD_OK. */
static pd_bench_clock time_batch(pd_lcp_solver *sv, const pd_matrix *M, const double *q,
                                 size_t step, const pd_lcp_opts *o, double *z, double *w, int batch,
                                 pd_lcp_info *info, long *failed)
{
    pd_bench_clock t0 = pd_bench_now();
    for (int b = 0; b < batch; b++)
        *failed += pd_lcp_solve(sv, M, q + (size_t)b * step, o, z, w, info) != PD_OK;
    return pd_bench_since(t0);
}

/* A solve's figures (info) into row: its pivots and iterations added to
 * sums, the largest residual, the first outcome that is not solved (else
 * the first solve's). */
static void add_figures(const pd_lcp_info *info, int first, bench_row *row, double *sums)
{
    sums[0] += info->pivots;
    sums[1] += info->iterations;
    row->residual = first ? info->residual : fmax(row->residual, info->residual);
    if (first || info->outcome != PD_LCP_SOLVED)
        row->outcome = info->outcome;
    row->solver = info->solver;
}

/* Median µs per solve with `method` over repeated batches of (M, q) — or,
 * with fresh (M a chain of pd_lcp_chain_q's right-hand sides), of M with a
 * new right-hand side for every solve, made before its batch (seeds
 * CHAIN_FRESH_SEED on); the pivots, iterations and residual as means over
 * the nfig right-hand sides at q (q + s n), and how many timed solves did
 * not return PD_OK into *failed.  1 when the solver could not be set up
 * (Lemke or structured not solving a solvable problem is caught by the
 * callers). */
static int measure(pd_lcp_method method, const pd_matrix *M, const double *q, int nfig, int fresh,
                   int max_iterations, bench_row *row, long *failed)
{
    int n = M->rows, seed = CHAIN_FRESH_SEED;
    long nnz = M->kind == PD_MATRIX_CSC ? M->colptr[n] : 0;
    pd_err err;
    pd_lcp_solver *sv = pd_lcp_solver_alloc(method, n, nnz, &err);
    double *zw = malloc(2 * (size_t)n * sizeof(double)), *bank = NULL, sums[2] = {0.0, 0.0};
    double runs[BENCH_MAX_RUNS], cpu_runs[BENCH_MAX_RUNS];
    pd_lcp_opts o = pd_lcp_default_opts();
    o.max_iterations = max_iterations;
    pd_lcp_info info;
    *failed = 0;
    double once = sv && zw ? time_batch(sv, M, q, 0, &o, zw, zw + n, 1, &info, failed).wall_s : 0;
    int batch = once >= BENCH_BATCH_S ? 1 : (int)(BENCH_BATCH_S / (once + 1e-9)) + 1;
    if (fresh)
        bank = malloc((size_t)batch * (size_t)n * sizeof(double));
    if (!sv || !zw || (fresh && !bank)) {
        pd_lcp_solver_free(sv);
        free(zw);
        free(bank);
        return 1;
    }
    add_figures(&info, 1, row, sums); /* the first q's from the solve just timed */
    for (int s = 1; s < nfig; s++) {
        pd_lcp_solve(sv, M, q + (size_t)s * (size_t)n, &o, zw, zw + n, &info);
        add_figures(&info, 0, row, sums);
    }
    int min_runs = once > BENCH_LONG_S ? 3 : BENCH_MIN_RUNS;
    double total = 0.0;
    int nruns = 0;
    while (nruns < BENCH_MAX_RUNS &&
           (nruns < min_runs || (total < BENCH_MIN_S && once <= BENCH_LONG_S))) {
        for (int b = 0; fresh && b < batch; b++)
            pd_lcp_chain_q(n, seed++, bank + (size_t)b * (size_t)n);
        pd_bench_clock t =
            fresh ? time_batch(sv, M, bank, (size_t)n, &o, zw, zw + n, batch, &info, failed)
                  : time_batch(sv, M, q, 0, &o, zw, zw + n, batch, &info, failed);
        total += t.wall_s;
        cpu_runs[nruns] = 1e6 * t.cpu_s / batch;
        runs[nruns++] = 1e6 * t.wall_s / batch;
    }
    free(bank);
    row->n = n;
    row->pivots = (int)lround(sums[0] / nfig);
    row->iterations = (int)lround(sums[1] / nfig);
    row->median_us = pd_bench_median(runs, nruns);
    row->median_cpu_us = pd_bench_median(cpu_runs, nruns);
    pd_lcp_solver_free(sv);
    free(zw);
    return 0;
}

/* A chain: D = tridiag(-1, 2, -1) in compressed columns (and dense for
 * small N), q uniform in [-1, 1) from a fixed seed. */
typedef struct chain {
    int N;
    int *colptr, *rowind;
    double *values, *dense, *q;
} chain;

static void chain_free(chain *c)
{
    free(c->colptr);
    free(c->rowind);
    free(c->values);
    free(c->dense);
    free(c->q);
}

/* The chain of N (dense too with with_dense) and nq right-hand sides,
 * from the seeds 0 .. nq - 1, at c->q + k N. */
static int chain_make(chain *c, int N, int with_dense, int nq)
{
    memset(c, 0, sizeof *c);
    c->N = N;
    c->colptr = malloc(((size_t)N + 1) * sizeof(int));
    c->rowind = malloc(3 * (size_t)N * sizeof(int));
    c->values = malloc(3 * (size_t)N * sizeof(double));
    c->q = malloc((size_t)nq * (size_t)N * sizeof(double));
    c->dense = with_dense ? calloc((size_t)N * (size_t)N, sizeof(double)) : NULL;
    if (!c->colptr || !c->rowind || !c->values || !c->q || (with_dense && !c->dense))
        return -1;
    int k = 0;
    for (int j = 0; j < N; j++) {
        c->colptr[j] = k;
        for (int i = j - 1; i <= j + 1; i++)
            if (i >= 0 && i < N) {
                double x = i == j ? 2.0 : -1.0;
                c->rowind[k] = i;
                c->values[k++] = x;
                if (c->dense)
                    c->dense[i + (size_t)j * N] = x;
            }
    }
    c->colptr[N] = k;
    for (int seed = 0; seed < nq; seed++)
        pd_lcp_chain_q(N, seed, c->q + (size_t)seed * (size_t)N);
    return 0;
}

/* A solver's figures on the chain of N into row: its time with a new
 * right-hand side for every solve (PGS, whose sweeps are fixed: the q of
 * seed 0 each time), the rest as means over the seeds 0 .. seeds - 1; 1
 * on a failure (Lemke or structured not solving one is one). */
static int measure_chain(pd_lcp_method method, int N, int seeds, bench_row *row)
{
    chain c;
    int its = method == PD_LCP_PGS ? BENCH_PGS_SWEEPS : 0;
    long unsolved = 0;
    if (chain_make(&c, N, method == PD_LCP_LEMKE, seeds)) {
        chain_free(&c);
        return 1;
    }
    pd_matrix dense = pd_matrix_dense(N, N, c.dense);
    pd_matrix csc = pd_matrix_csc(N, N, c.colptr, c.rowind, c.values);
    const pd_matrix *M = method == PD_LCP_LEMKE ? &dense : &csc;
    int failed = measure(method, M, c.q, seeds, method != PD_LCP_PGS, its, row, &unsolved);
    failed |= method != PD_LCP_PGS && (unsolved > 0 || row->outcome != PD_LCP_SOLVED);
    chain_free(&c);
    return failed;
}

/* The structured solver's CPU ns per contact on the chain c, a new q each
 * solve (fresh) or c's first repeated, kept in *best when lower; 1 on a
 * failure. */
static int per_contact_ns(const chain *c, int fresh, double *best)
{
    bench_row row = {0};
    long unsolved = 0;
    pd_matrix csc = pd_matrix_csc(c->N, c->N, c->colptr, c->rowind, c->values);
    if (measure(PD_LCP_STRUCTURED, &csc, c->q, 1, fresh, 0, &row, &unsolved) || unsolved)
        return 1;
    *best = fmin(*best, 1e3 * row.median_cpu_us / c->N);
    return 0;
}

/* The structured solver's cost per contact at N = 1e3 and 1e5, fresh and
 * repeated q, in GROWTH_ROUNDS rounds that alternate them (a shared host's
 * slow spells last seconds: each size gets its share of the quick ones). */
static void growth_rounds(bench_report *rep)
{
    chain c3, c5;
    double *ns[] = {&rep->fresh_ns3, &rep->fresh_ns5, &rep->repeated_ns3, &rep->repeated_ns5};
    for (int k = 0; k < 4; k++)
        *ns[k] = HUGE_VAL;
    int failed = chain_make(&c3, 1000, 0, 1) || chain_make(&c5, 100000, 0, 1);
    for (int r = 0; r < GROWTH_ROUNDS && !failed; r++)
        failed = per_contact_ns(&c3, 1, ns[0]) || per_contact_ns(&c5, 1, ns[1]) ||
                 per_contact_ns(&c3, 0, ns[2]) || per_contact_ns(&c5, 0, ns[3]);
    for (int k = 0; k < 4 && failed; k++)
        *ns[k] = NAN;
    rep->failed |= failed;
    chain_free(&c3);
    chain_free(&c5);
}

/* Lemke (dense, N <= 500), structured and PGS (compressed columns). */
static void bench_chains(bench_report *rep)
{
    static const int sizes[] = {10, 100, 200, 500, 1000, 10000, 100000};
    const pd_lcp_method methods[] = {PD_LCP_LEMKE, PD_LCP_STRUCTURED, PD_LCP_PGS};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++)
        for (int m = 0; m < 3; m++) {
            int N = sizes[k];
            if (methods[m] == PD_LCP_LEMKE && N > 500)
                continue;
            bench_row *row = &rep->rows[rep->nrows++];
            snprintf(row->name, sizeof row->name, "chain_%d", N);
            rep->failed |=
                measure_chain(methods[m], N, methods[m] == PD_LCP_PGS ? 1 : CHAIN_SEEDS, row);
        }
}

/* The median CPU µs of `runs` batches of `batch` copies of M's band. */
static double time_band_copy(const chain *c, int band, long cap, int *colptr, int *rowind,
                             double *values)
{
    double runs[BENCH_MIN_RUNS];
    int batch = 20;
    for (int r = 0; r < BENCH_MIN_RUNS; r++) {
        pd_bench_clock t0 = pd_bench_now();
        for (int b = 0; b < batch; b++)
            pd_lcp_band_csc(c->N, c->dense, band, cap, colptr, rowind, values);
        runs[r] = 1e6 * pd_bench_since(t0).cpu_s / batch;
    }
    return pd_bench_median(runs, BENCH_MIN_RUNS);
}

/* The plain file of a chain into path (mkstemp); 0, or -1. */
static int write_plain(const chain *c, char *path)
{
    int fd = mkstemp(path);
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!f) {
        if (fd >= 0)
            close(fd);
        return -1;
    }
    int N = c->N;
    fprintf(f, "%d\n", N);
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++)
            fprintf(f, "%.17g%c", c->dense[i + (size_t)j * N], j + 1 < N ? ' ' : '\n');
    for (int i = 0; i < N; i++)
        fprintf(f, "%.17g%c", c->q[i], i + 1 < N ? ' ' : '\n');
    return fclose(f) ? -1 : 0;
}

/* The chain of DENSE_BAND_N given densely (seed 0): the structured solver
 * on it in compressed columns and densely in memory; the copy of its band
 * and the parse of its plain file (pd_lcp_read_band, the path of `pound
 * lcp --solver structured FILE`: parse, band noted while reading, band
 * copied, solved in compressed columns). */
static void bench_dense_band(bench_report *rep)
{
    chain c;
    bench_row csc_row = {0}, dense_row = {0};
    char path[] = "/tmp/pound_bench_bandXXXXXX";
    int n = 0, band = -1, *colptr = NULL, *rowind = NULL;
    long nnz = 0;
    double *M = NULL, *q = NULL, *values = NULL;
    pd_err err;
    rep->band_ok = 0;
    if (chain_make(&c, DENSE_BAND_N, 1, 1) || write_plain(&c, path)) {
        chain_free(&c);
        rep->failed = 1;
        return;
    }
    pd_matrix csc = pd_matrix_csc(c.N, c.N, c.colptr, c.rowind, c.values);
    pd_matrix dense = pd_matrix_dense(c.N, c.N, c.dense);
    long unsolved = 0, dense_unsolved = 0;
    int failed = measure(PD_LCP_STRUCTURED, &csc, c.q, 1, 0, 0, &csc_row, &unsolved) ||
                 measure(PD_LCP_STRUCTURED, &dense, c.q, 1, 0, 0, &dense_row, &dense_unsolved) ||
                 unsolved || dense_unsolved;
    pd_bench_clock t0 = pd_bench_now();
    int rd = pd_lcp_read_band(path, PD_LCP_FORMAT_PLAIN, &n, &M, &q, &band, &nnz, &err);
    rep->band_parse_us = 1e6 * pd_bench_since(t0).cpu_s;
    remove(path);
    colptr = malloc(((size_t)c.N + 1) * sizeof(int));
    rowind = malloc(((size_t)nnz + 1) * sizeof(int));
    values = malloc(((size_t)nnz + 1) * sizeof(double));
    failed |= rd != PD_OK || band != 1 || nnz != c.colptr[c.N] || !colptr || !rowind || !values;
    if (!failed) {
        rep->band_copy_us = time_band_copy(&c, band, nnz, colptr, rowind, values);
        failed |= pd_lcp_band_csc(c.N, M, band, nnz, colptr, rowind, values) != nnz ||
                  memcmp(colptr, c.colptr, ((size_t)c.N + 1) * sizeof(int)) ||
                  memcmp(values, c.values, (size_t)nnz * sizeof(double));
    }
    rep->band_csc_us = csc_row.median_cpu_us;
    rep->band_dense_us = dense_row.median_cpu_us;
    rep->band_ok = !failed;
    rep->failed |= failed;
    free(colptr);
    free(rowind);
    free(values);
    free(M);
    free(q);
    chain_free(&c);
}

/* The structured solver's CPU time per contact at N = 1e5 over that at
 * 1e3, a new q each solve (growth_rounds'). */
static double per_contact_growth(const bench_report *rep)
{
    return rep->fresh_ns5 / rep->fresh_ns3;
}

/* Least-squares slope of log(CPU us) against log(n) of a solver's chains
 * with n in [lo, hi] (CPU time: the wall clock of a shared machine doubles
 * with its load); NAN with fewer than two. */
static double growth(const bench_report *rep, const char *solver, int lo, int hi)
{
    pd_loglog_fit fit = {0};
    for (int r = 0; r < rep->nrows; r++) {
        const bench_row *row = &rep->rows[r];
        if (!strncmp(row->name, "chain_", 6) && row->n >= lo && row->n <= hi &&
            !strcmp(row->solver, solver))
            pd_loglog_add(&fit, (double)row->n, row->median_cpu_us);
    }
    return pd_loglog_slope(&fit);
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
    memset(row, 0, sizeof *row);
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
    pd_matrix Mv = pd_matrix_dense(n, n, M);
    const pd_lcp_method methods[] = {PD_LCP_LEMKE, PD_LCP_STRUCTURED, PD_LCP_PGS};
    for (int m = 0; m < 3; m++) {
        bench_row *r = &rep->rows[rep->nrows++];
        if (m)
            *r = rep->rows[rep->nrows - 2];
        long unsolved;
        rep->failed |= measure(methods[m], &Mv, q, 1, 0, 0, r, &unsolved);
        rep->failed |=
            m == 0 && (r->outcome == PD_LCP_NUMERICAL || r->outcome == PD_LCP_MAX_PIVOTS);
    }
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

/* The table. */
static void print_table(const bench_report *rep)
{
    printf("LCP solvers, median us per cold solve over >= %d timed batches (3 for solves over "
           "%g s), one thread; wall clock (median_us) and CPU time (cpu_us)\n",
           BENCH_MIN_RUNS, BENCH_LONG_S);
    if (!rep->siconos_found)
        printf("Siconos set: skipped (no .dat files in %s)\n", rep->siconos_dir);
    printf("%-28s %6s %-26s %-14s %7s %6s %9s %12s %12s\n", "problem", "n", "solver", "status",
           "pivots", "iters", "residual", "median_us", "cpu_us");
    for (int k = 0; k < rep->nrows; k++) {
        const bench_row *r = &rep->rows[k];
        printf("%-28s %6d %-26s %-14s %7d %6d %9.2g %12.3f %12.3f\n", r->name, r->n, r->solver,
               pd_lcp_outcome_name(r->outcome), r->pivots, r->iterations, r->residual, r->median_us,
               r->median_cpu_us);
    }
    printf("chains: a new right-hand side q for every timed solve (pgs: one q), pivots and "
           "iterations means over %d; against Siconos numerics, paired in one run: make bench "
           "(bench/siconos_lcp)\n",
           CHAIN_SEEDS);
    printf("growth exponent of the CPU time on chains, N = 1e3 ... 1e5: structured %.3f, pgs (%d "
           "sweeps) %.3f\n",
           growth(rep, "structured", 1000, 100000), BENCH_PGS_SWEEPS,
           growth(rep, "pgs", 1000, 100000));
    double g = per_contact_growth(rep);
    printf("structured, CPU time per contact at N = 1e5 over N = 1e3, a new q each solve (the "
           "best of %d alternating rounds): %.1f / %.1f ns = %.3f (goal <= %.1f: %s)\n",
           GROWTH_ROUNDS, rep->fresh_ns5, rep->fresh_ns3, g, GOAL_PER_CONTACT,
           g <= GOAL_PER_CONTACT ? "met" : "not met");
    printf("  one q repeated instead (the branch predictor trained on it): %.1f / %.1f ns = "
           "%.3f\n",
           rep->repeated_ns5, rep->repeated_ns3, rep->repeated_ns5 / rep->repeated_ns3);
    if (!rep->band_ok) {
        printf("band given densely: FAILED\n");
        return;
    }
    double copy_solve = rep->band_copy_us + rep->band_csc_us;
    printf("chain of %d given densely, structured, CPU us per solve: compressed columns %.3f; "
           "dense in memory %.3f (%.2fx: each solve reads all n^2 entries);\n"
           "  plain file as `pound lcp --solver structured` takes it: parse %.0f (once; the band "
           "noted while reading), then band copy %.3f + solve %.3f = %.3f: %.2fx the banded "
           "path (goal <= %.0f: %s)\n",
           DENSE_BAND_N, rep->band_csc_us, rep->band_dense_us,
           rep->band_dense_us / rep->band_csc_us, rep->band_parse_us, rep->band_copy_us,
           rep->band_csc_us, copy_solve, copy_solve / rep->band_csc_us, GOAL_DENSE_BAND,
           copy_solve <= GOAL_DENSE_BAND * rep->band_csc_us ? "met" : "not met");
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
        pd_json_str(js, "solver", r->solver);
        pd_json_int(js, "pivots", r->pivots);
        pd_json_int(js, "iterations", r->iterations);
        pd_json_str(js, "status", pd_lcp_outcome_name(r->outcome));
        pd_json_num(js, "residual", r->residual);
        pd_json_num(js, "median_us", r->median_us);
        pd_json_num(js, "median_cpu_us", r->median_cpu_us);
        pd_json_end_object(js);
    }
    pd_json_end_array(js);
    pd_json_num(js, "growth_structured", growth(rep, "structured", 1000, 100000));
    pd_json_num(js, "growth_pgs", growth(rep, "pgs", 1000, 100000));
    pd_json_num(js, "per_contact_growth_structured", per_contact_growth(rep));
    pd_json_num(js, "per_contact_growth_structured_repeated_q",
                rep->repeated_ns5 / rep->repeated_ns3);
    pd_json_begin_object(js, "dense_band");
    pd_json_int(js, "n", DENSE_BAND_N);
    pd_json_bool(js, "ok", rep->band_ok);
    pd_json_num(js, "csc_cpu_us", rep->band_csc_us);
    pd_json_num(js, "dense_cpu_us", rep->band_dense_us);
    pd_json_num(js, "band_copy_cpu_us", rep->band_copy_us);
    pd_json_num(js, "parse_cpu_us", rep->band_parse_us);
    pd_json_num(js, "ratio", (rep->band_copy_us + rep->band_csc_us) / rep->band_csc_us);
    pd_json_end_object(js);
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
    growth_rounds(rep);
    bench_dense_band(rep);
    if (js)
        print_json(js, rep);
    else
        print_table(rep);
    int failed = rep->failed;
    free(rep);
    return failed ? 1 : 0;
}
