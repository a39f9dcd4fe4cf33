/* siconos_lcp.c — pound's LCP solvers against Siconos numerics' lexicographic
 * Lemke (lcp_lexicolemke) and projected Gauss–Seidel (lcp_pgs), paired in
 * one run: `make bench` builds it (bench/build.sh) when Siconos is there.
 *   siconos_lcp [--siconos-dir DIR] [--chains] [--json]
 * The Siconos set is every lcp_*.dat of DIR (default
 * ../shared/data/lcp/siconos): n, 0 (dense), rows, cols, "rows cols", M
 * column by column, q, free text.  A chain of N masses has M = tridiag(-1,
 * 2, -1) and q from pd_lcp_chain_q (the draws of `pound bench --lcp`,
 * so the two pair); a chain's figures are means over CHAIN_SEEDS
 * right-hand sides (PGS: the first).
 *
 * Pairing: the machine's speed drifts by tens of percent within seconds,
 * so each problem is timed in alternating batches, Siconos then pound, and
 * the ratio is the median of the batch-by-batch ratios (with the median
 * time of each side beside it).  A batch lasts at least BATCH_S; at least
 * MIN_RUNS pairs and MIN_S seconds (3 pairs when one solve takes over
 * LONG_S).  Solves are cold: z = w = 0 before each, inside the timed loop;
 * problem, options, workspaces and z, w are made once outside it.  Siconos'
 * solvers are called directly (no driver, no filter pass); pound's through
 * its solver table (pd_lcp_solve: the same checks, verification and
 * hand-over a user gets), Lemke on the dense matrix, the structured solver
 * and PGS on compressed columns.
 *
 * pivots: Siconos' iparam[SICONOS_IPARAM_ITER_DONE] (Lemke: after the pivot
 * that brings z0 in, so one fewer than pound counts; PGS: sweeps).  Both
 * answers are checked here by pound's relative backward residual
 * (pd_lcp_residual, docs/lcp.md); verified = status 0 and residual <=
 * VERIFY_TOL (Siconos 4.4's Lemke reports status 0 on ray termination too,
 * so its status alone is not enough).  One thread. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* clock_gettime, strdup */
#endif
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pd_lcp.h"

#include "LCP_Solvers.h"
#include "LinearComplementarityProblem.h"
#include "NumericsMatrix.h"
#include "SolverOptions.h"
#include "lcp_cst.h"

#ifndef SICONOS_NUMERICS_VERSION
#define SICONOS_NUMERICS_VERSION "unknown"
#endif

#define MIN_RUNS 21
#define MAX_RUNS 501
#define MIN_S 0.1
#define BATCH_S 50e-6
#define LONG_S 0.05
#define MAX_FILES 256
#define MAX_ROWS (MAX_FILES + 16)
#define CHAIN_SEEDS 5
#define PGS_SEEDS 1      /* pound times PGS on the first seed only */
#define PGS_SWEEPS 2000  /* PGS's budget on the chains, as pound's */
#define PGS_TOL 1e-10    /* Siconos' relative error at which PGS stops */
#define VERIFY_TOL 1e-10 /* relative residual of a verified answer, as pound's */

/* A Siconos solver and the options it is run with (0: Siconos' default). */
typedef struct solver_kind {
    const char *name;
    int id;
    void (*solve)(LinearComplementarityProblem *, double *, double *, int *, SolverOptions *);
    int max_iter;
    double tol;
} solver_kind;

static const solver_kind LEMKE = {
    .name = "siconos-lexicolemke", .id = SICONOS_LCP_LEMKE, .solve = lcp_lexicolemke};
static const solver_kind PGS = {.name = "siconos-pgs",
                                .id = SICONOS_LCP_PGS,
                                .solve = lcp_pgs,
                                .max_iter = PGS_SWEEPS,
                                .tol = PGS_TOL};

/* A dense LCP: M column-major n x n, q. */
typedef struct lcp_data {
    char name[64];
    int n;
    double *M, *q;
} lcp_data;

/* One problem, a Siconos solver against a pound one. */
typedef struct bench_row {
    char name[64];
    const char *siconos, *pound;
    int n, status, verified, pound_verified;
    double pivots, pound_steps, residual, pound_residual;
    double siconos_us, pound_us, ratio; /* ratio: median of the paired ratios */
} bench_row;

/* The rows to print. */
typedef struct bench_report {
    bench_row rows[MAX_ROWS];
    int nrows, failed;
} bench_report;

/* Siconos' side of a pair, made once outside the timed loop. */
typedef struct siconos_side {
    const solver_kind *kind;
    LinearComplementarityProblem *problem;
    SolverOptions *options;
    double *z, *w;
    int n, info;
} siconos_side;

/* pound's side: a solver of the table and the matrix view it reads. */
typedef struct pound_side {
    pd_lcp_solver *solver;
    pd_matrix M;
    const double *q;
    pd_lcp_opts opts;
    double *z, *w;
    int n, status;
    pd_lcp_info info;
} pound_side;

/* Monotonic wall clock in seconds. */
static double wall_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
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

/* Seconds per cold Siconos solve over a batch. */
static double siconos_batch(siconos_side *c, int batch)
{
    size_t bytes = (size_t)c->n * sizeof(double);
    double t0 = wall_seconds();
    for (int b = 0; b < batch; b++) {
        memset(c->z, 0, bytes);
        memset(c->w, 0, bytes);
        c->kind->solve(c->problem, c->z, c->w, &c->info, c->options);
    }
    return (wall_seconds() - t0) / batch;
}

/* Seconds per cold pound solve over a batch. */
static double pound_batch(pound_side *c, int batch)
{
    size_t bytes = (size_t)c->n * sizeof(double);
    double t0 = wall_seconds();
    for (int b = 0; b < batch; b++) {
        memset(c->z, 0, bytes);
        memset(c->w, 0, bytes);
        c->status = pd_lcp_solve(c->solver, &c->M, c->q, &c->opts, c->z, c->w, &c->info);
    }
    return (wall_seconds() - t0) / batch;
}

/* Solves per batch for a solve of `once` seconds. */
static int batch_size(double once)
{
    return once >= BATCH_S ? 1 : (int)(BATCH_S / (once + 1e-9)) + 1;
}

/* Alternating batches, Siconos then pound: the median time of each (µs)
 * and the median of the paired ratios pound / Siconos into row. */
static void time_pairs(siconos_side *sc, pound_side *pc, bench_row *row)
{
    static double ts[MAX_RUNS], tp[MAX_RUNS], tr[MAX_RUNS];
    double once_s = siconos_batch(sc, 1), once_p = pound_batch(pc, 1);
    double once = once_s > once_p ? once_s : once_p, total = 0.0;
    int bs = batch_size(once_s), bp = batch_size(once_p);
    int min_runs = once > LONG_S ? 3 : MIN_RUNS, nruns = 0;
    while (nruns < MAX_RUNS && (nruns < min_runs || (total < MIN_S && once <= LONG_S))) {
        ts[nruns] = siconos_batch(sc, bs);
        tp[nruns] = pound_batch(pc, bp);
        tr[nruns] = tp[nruns] / ts[nruns];
        total += ts[nruns] * bs + tp[nruns] * bp;
        nruns++;
    }
    row->siconos_us = 1e6 * median(ts, nruns);
    row->pound_us = 1e6 * median(tp, nruns);
    row->ratio = median(tr, nruns);
}

/* Options of a solver: Siconos' defaults, then our budget and tolerance. */
static SolverOptions *make_options(const solver_kind *kind)
{
    SolverOptions *o = solver_options_create(kind->id);
    if (o && kind->max_iter > 0)
        o->iparam[SICONOS_IPARAM_MAX_ITER] = kind->max_iter;
    if (o && kind->tol > 0.0)
        o->dparam[SICONOS_DPARAM_TOL] = kind->tol;
    return o;
}

/* pound's relative backward residual of z (w recomputed into w). */
static double rel_residual(const lcp_data *p, const double *z, double *w)
{
    double comp, infeas, res;
    pd_lcp_residual(p->n, p->M, p->q, z, w, &comp, &infeas, &res);
    return res;
}

/* The compressed columns of a dense M (the structured solver and PGS read
 * them), malloc'd into *colptr, *rowind, *values; -1 when out of memory. */
static int to_csc(const lcp_data *p, int **colptr, int **rowind, double **values)
{
    size_t nnz = 0, n = (size_t)p->n;
    for (size_t k = 0; k < n * n; k++)
        nnz += p->M[k] != 0.0;
    *colptr = malloc((n + 1) * sizeof(int));
    *rowind = malloc((nnz ? nnz : 1) * sizeof(int));
    *values = malloc((nnz ? nnz : 1) * sizeof(double));
    if (!*colptr || !*rowind || !*values)
        return -1;
    int k = 0;
    for (size_t j = 0; j < n; j++) {
        (*colptr)[j] = k;
        for (size_t i = 0; i < n; i++)
            if (p->M[i + j * n] != 0.0) {
                (*rowind)[k] = (int)i;
                (*values)[k++] = p->M[i + j * n];
            }
    }
    (*colptr)[n] = k;
    return 0;
}

/* The pair's figures after the timing into row. */
static void record(const lcp_data *p, const siconos_side *sc, pound_side *pc,
                   const SolverOptions *o, bench_row *row)
{
    row->n = p->n;
    row->siconos = sc->kind->name;
    row->pound = pc->info.solver;
    row->status = sc->info;
    row->pivots = o->iparam[SICONOS_IPARAM_ITER_DONE];
    row->pound_steps = pc->info.pivots + pc->info.iterations;
    row->residual = rel_residual(p, sc->z, sc->w);
    row->verified = sc->info == 0 && row->residual <= VERIFY_TOL;
    row->pound_residual = rel_residual(p, pc->z, pc->w);
    row->pound_verified = pc->status == PD_OK && row->pound_residual <= VERIFY_TOL;
}

/* Time Siconos' `kind` against pound's `method` on p into row (name left
 * to the caller); 1 when out of memory.  Everything is made once here. */
static int measure(const solver_kind *kind, pd_lcp_method method, const lcp_data *p, bench_row *row)
{
    NumericsMatrix *M = NM_create(NM_DENSE, p->n, p->n);
    SolverOptions *o = make_options(kind);
    double *zw = malloc(4 * (size_t)p->n * sizeof(double)), *values = NULL;
    int *colptr = NULL, *rowind = NULL, dense = method == PD_LCP_LEMKE;
    pd_lcp_solver *solver = NULL;
    pd_err err;
    int failed = !M || !M->matrix0 || !o || !zw || (!dense && to_csc(p, &colptr, &rowind, &values));
    if (!failed)
        failed = !(solver = pd_lcp_solver_alloc(method, p->n, dense ? 0 : colptr[p->n], &err));
    if (!failed) {
        memcpy(M->matrix0, p->M, (size_t)p->n * (size_t)p->n * sizeof(double));
        LinearComplementarityProblem problem = {.size = p->n, .M = M, .q = p->q};
        siconos_side sc = {
            .kind = kind, .problem = &problem, .options = o, .z = zw, .w = zw + p->n, .n = p->n};
        pound_side pc = {.solver = solver,
                         .q = p->q,
                         .opts = pd_lcp_default_opts(),
                         .z = zw + 2 * p->n,
                         .w = zw + 3 * p->n,
                         .n = p->n};
        pc.M = dense ? pd_matrix_dense(p->n, p->n, p->M)
                     : pd_matrix_csc(p->n, p->n, colptr, rowind, values);
        if (method == PD_LCP_PGS)
            pc.opts.max_iterations = PGS_SWEEPS;
        time_pairs(&sc, &pc, row);
        record(p, &sc, &pc, o, row);
    }
    pd_lcp_solver_free(solver);
    free(colptr);
    free(rowind);
    free(values);
    free(zw);
    if (o)
        solver_options_delete(o); /* Siconos 4.4 clears o but does not free it */
    free(o);
    if (M)
        NM_free(M);
    return failed;
}

/* Free the arrays of an LCP. */
static void lcp_data_free(lcp_data *p)
{
    free(p->M);
    free(p->q);
    p->M = p->q = NULL;
}

/* The chain of N masses with right-hand side number `seed`; -1 when out of memory. */
static int chain_make(lcp_data *p, int N, int seed)
{
    *p = (lcp_data){.n = N};
    snprintf(p->name, sizeof p->name, "chain_%d", N);
    p->M = calloc((size_t)N * (size_t)N, sizeof(double));
    p->q = malloc((size_t)N * sizeof(double));
    if (!p->M || !p->q)
        return -1;
    for (int j = 0; j < N; j++) {
        for (int i = j - 1; i <= j + 1; i++)
            if (i >= 0 && i < N)
                p->M[i + (size_t)j * N] = i == j ? 2.0 : -1.0;
    }
    pd_lcp_chain_q(N, seed, p->q);
    return 0;
}

/* Mean over `seeds` right-hand sides of a chain's per-seed figures into a
 * new row (status: the worst, residual: the largest). */
static void bench_chain(bench_report *rep, const solver_kind *kind, pd_lcp_method method, int N,
                        int seeds)
{
    bench_row *row = &rep->rows[rep->nrows++];
    *row = (bench_row){.n = N, .verified = 1, .pound_verified = 1};
    snprintf(row->name, sizeof row->name, "chain_%d", N);
    for (int s = 0; s < seeds; s++) {
        lcp_data p;
        bench_row one = {.n = N};
        if (chain_make(&p, N, s) || measure(kind, method, &p, &one)) {
            fprintf(stderr, "siconos_lcp: %s: out of memory\n", row->name);
            rep->failed = 1;
        }
        row->siconos = one.siconos;
        row->pound = one.pound;
        row->siconos_us += one.siconos_us / seeds;
        row->pound_us += one.pound_us / seeds;
        row->ratio += one.ratio / seeds;
        row->pivots += one.pivots / seeds;
        row->pound_steps += one.pound_steps / seeds;
        row->residual = fmax(row->residual, one.residual);
        row->pound_residual = fmax(row->pound_residual, one.pound_residual);
        row->status = one.status > row->status ? one.status : row->status;
        row->verified &= one.verified;
        row->pound_verified &= one.pound_verified;
        lcp_data_free(&p);
    }
}

/* Siconos' Lemke against pound's Lemke and structured solver on every
 * chain, then PGS against PGS. */
static void bench_chains(bench_report *rep)
{
    static const int sizes[] = {10, 100, 200, 500};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        bench_chain(rep, &LEMKE, PD_LCP_LEMKE, sizes[k], CHAIN_SEEDS);
        bench_chain(rep, &LEMKE, PD_LCP_STRUCTURED, sizes[k], CHAIN_SEEDS);
    }
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++)
        bench_chain(rep, &PGS, PD_LCP_PGS, sizes[k], PGS_SEEDS);
}

/* The next integer of f into *v; 0 when there is none. */
static int read_int(FILE *f, int *v)
{
    return fscanf(f, "%d", v) == 1;
}

/* count doubles of f into x; 0 when the file ends or has a non-number first. */
static int read_doubles(FILE *f, double *x, size_t count)
{
    for (size_t k = 0; k < count; k++)
        if (fscanf(f, "%lf", &x[k]) != 1)
            return 0;
    return 1;
}

/* Siconos header of f: n, storage 0, rows, cols, "rows cols" with rows = cols = n. */
static int read_header(FILE *f, int *n)
{
    int storage, r1, c1, r2, c2;
    return read_int(f, n) && read_int(f, &storage) && read_int(f, &r1) && read_int(f, &c1) &&
           read_int(f, &r2) && read_int(f, &c2) && *n > 0 && storage == 0 && r1 == *n && c1 == *n &&
           r2 == *n && c2 == *n;
}

/* A dense Siconos LCP file into p; -1 (with a message) on failure. */
static int read_siconos(const char *path, lcp_data *p)
{
    int st = -1, n = 0;
    FILE *f = fopen(path, "r");
    if (!f || !read_header(f, &n)) {
        fprintf(stderr, "siconos_lcp: %s: %s\n", path,
                f ? "not a dense Siconos LCP header" : "cannot open");
        goto out;
    }
    p->n = n;
    p->M = malloc((size_t)n * (size_t)n * sizeof(double));
    p->q = malloc((size_t)n * sizeof(double));
    if (!p->M || !p->q || !read_doubles(f, p->M, (size_t)n * (size_t)n) ||
        !read_doubles(f, p->q, (size_t)n)) {
        fprintf(stderr, "siconos_lcp: %s: cannot read M and q (n = %d)\n", path, n);
        goto out;
    }
    st = 0;
out:
    if (f)
        fclose(f);
    if (st)
        lcp_data_free(p);
    return st;
}

/* Ascending order of strings, for qsort. */
static int cmp_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Whether file is lcp_*.dat. */
static int is_lcp_file(const char *file)
{
    size_t len = strlen(file);
    return len > 8 && !strncmp(file, "lcp_", 4) && !strcmp(file + len - 4, ".dat");
}

/* Sorted lcp_*.dat names of dir; their count, -1 if dir is unreadable. */
static int list_lcp_files(const char *dir, char **names, int max)
{
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    int count = 0;
    for (struct dirent *e = readdir(d); e && count < max; e = readdir(d))
        if (is_lcp_file(e->d_name) && (names[count] = strdup(e->d_name)))
            count++;
    closedir(d);
    qsort(names, (size_t)count, sizeof *names, cmp_name);
    return count;
}

/* Read and time one Siconos file with Lemke. */
static void bench_file(bench_report *rep, const char *dir, const char *file)
{
    char path[4096];
    lcp_data p = {.n = 0};
    bench_row *row = &rep->rows[rep->nrows];
    snprintf(p.name, sizeof p.name, "%.*s", (int)(strlen(file) - 8), file + 4);
    if (snprintf(path, sizeof path, "%s/%s", dir, file) >= (int)sizeof path ||
        read_siconos(path, &p)) {
        rep->failed = 1;
        return;
    }
    *row = (bench_row){.n = p.n};
    memcpy(row->name, p.name, sizeof row->name);
    rep->failed |= measure(&LEMKE, PD_LCP_LEMKE, &p, row);
    rep->nrows++;
    lcp_data_free(&p);
}

/* Every lcp_*.dat of dir; -1 if there is none. */
static int bench_siconos(bench_report *rep, const char *dir)
{
    char *names[MAX_FILES];
    int count = list_lcp_files(dir, names, MAX_FILES);
    for (int k = 0; k < count; k++) {
        bench_file(rep, dir, names[k]);
        free(names[k]);
    }
    return count > 0 ? 0 : -1;
}

/* The aligned table. */
static void print_table(const bench_report *rep)
{
    printf("pound against Siconos numerics %s: median us per cold solve, paired batches "
           "(>= %d pairs; 3 for solves over %g s), one thread\n",
           SICONOS_NUMERICS_VERSION, MIN_RUNS, LONG_S);
    printf("%-28s %4s %-20s %4s %7s %9s %11s %-26s %4s %7s %9s %11s %7s\n", "problem", "n",
           "siconos", "ok", "pivots", "residual", "us", "pound", "ok", "steps", "residual", "us",
           "ratio");
    for (int k = 0; k < rep->nrows; k++) {
        const bench_row *r = &rep->rows[k];
        printf("%-28s %4d %-20s %4s %7.1f %9.2g %11.3f %-26s %4s %7.1f %9.2g %11.3f %7.3f\n",
               r->name, r->n, r->siconos, r->verified ? "yes" : "no", r->pivots, r->residual,
               r->siconos_us, r->pound, r->pound_verified ? "yes" : "no", r->pound_steps,
               r->pound_residual, r->pound_us, r->ratio);
    }
    printf("ok: verified (status 0 and pound's relative backward residual <= %g); pivots: "
           "Siconos' (Lemke: after the z0 pivot); steps: pound's pivots + iterations; ratio: "
           "median of the paired batch ratios pound / Siconos; chains: means over %d "
           "right-hand sides (PGS: one, %d sweeps)\n",
           VERIFY_TOL, CHAIN_SEEDS, PGS_SWEEPS);
}

/* One JSON object with every row. */
static void print_json(const bench_report *rep)
{
    printf("{\"siconos_version\": \"%s\", \"problems\": [", SICONOS_NUMERICS_VERSION);
    for (int k = 0; k < rep->nrows; k++) {
        const bench_row *r = &rep->rows[k];
        printf("%s\n  {\"name\": \"%s\", \"n\": %d, \"siconos\": \"%s\", \"status\": %d, "
               "\"verified\": %s, \"pivots\": %.17g, \"residual\": %.17g, \"siconos_us\": %.17g, "
               "\"pound\": \"%s\", \"pound_verified\": %s, \"pound_steps\": %.17g, "
               "\"pound_residual\": %.17g, \"pound_us\": %.17g, \"ratio\": %.17g}",
               k ? "," : "", r->name, r->n, r->siconos, r->status, r->verified ? "true" : "false",
               r->pivots, r->residual, r->siconos_us, r->pound,
               r->pound_verified ? "true" : "false", r->pound_steps, r->pound_residual, r->pound_us,
               r->ratio);
    }
    printf("\n]}\n");
}

/* Command line: [--siconos-dir DIR] [--chains] [--json]. */
typedef struct cli_args {
    const char *dir;
    int chains, json;
} cli_args;

/* Parse argv into a; -1 (with usage) on an unknown argument. */
static int parse_args(int argc, char **argv, cli_args *a)
{
    *a = (cli_args){.dir = "../shared/data/lcp/siconos"};
    for (int k = 1; k < argc; k++) {
        if (!strcmp(argv[k], "--siconos-dir") && k + 1 < argc)
            a->dir = argv[++k];
        else if (!strcmp(argv[k], "--chains"))
            a->chains = 1;
        else if (!strcmp(argv[k], "--json"))
            a->json = 1;
        else {
            fprintf(stderr, "usage: siconos_lcp [--siconos-dir DIR] [--chains] [--json]\n");
            return -1;
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    cli_args a;
    if (parse_args(argc, argv, &a))
        return 2;
    bench_report *rep = calloc(1, sizeof *rep);
    if (!rep) {
        fprintf(stderr, "siconos_lcp: out of memory\n");
        return 1;
    }
    if (bench_siconos(rep, a.dir))
        fprintf(stderr, "siconos_lcp: no lcp_*.dat files in %s: Siconos set skipped\n", a.dir);
    if (a.chains)
        bench_chains(rep);
    if (a.json)
        print_json(rep);
    else
        print_table(rep);
    int failed = rep->failed;
    free(rep);
    return failed ? 1 : 0;
}
