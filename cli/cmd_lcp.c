/* cmd_lcp.c — `pound lcp FILE`: solve one LCP with a solver of the table.
 *
 * Exit status 0 when solved, 1 for any other outcome of the solve (the result
 * is still printed), 2 for bad input (flag, unreadable or malformed file). */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_alloc.h"
#include "pd_cli.h"
#include "pd_lcp.h"
#include "pd_lcp_dump.h"

static const char lcp_usage[] =
    "usage: pound lcp FILE [--solver auto|lemke|structured|pgs] [--format plain|siconos|auto]\n"
    "                      [--all | --index K]   (FILE.h5: an LCP dump)\n"
    "                      [--json] [--cover D] [--max-pivots K] [--max-iterations K] [--tol T]\n"
    "\n"
    "Solve the LCP  z >= 0, w = M z + q >= 0, z'w = 0  read from FILE.\n"
    "  --solver S      lemke (general), structured (block principal pivoting for symmetric\n"
    "                  positive definite M), pgs (projected Gauss-Seidel), auto [lemke for\n"
    "                  dense files]; see docs/lcp.md\n"
    "  --max-iterations K  structured: block pivots [3 n + 10]; pgs: sweeps [1000 n]\n"
    "  --format F      plain (n, M row by row, q; '#' comments), siconos (column-major,\n"
    "                  Siconos header), or auto (default: detects the Siconos header)\n"
    "  --json          print one JSON object: status, solver, n, z, w, pivots, iterations,\n"
    "                  complementarity, infeasibility, residual, scale, cpu_s\n"
    "  --cover D       covering vector: one positive value for every entry, or n\n"
    "                  comma-separated positive values (default all ones)\n"
    "  --max-pivots K  pivot cap (default max(10000, 100 n))\n"
    "  --tol T         relative tolerance for ties and tiny pivots (default 1e-12)\n"
    "  FILE.h5         an LCP dump (`simulate --dump-lcp`): --all re-solves every LCP and\n"
    "                  reports agreement with the dumped answers; --index K solves one\n"
    "status: solved, no_solution (ray termination), max_pivots, max_iterations, numerical;\n"
    "solved means verified: relative backward residual <= 1e-10.\n"
    "exit status: 0 solved, 1 another status, 2 bad input.\n";

/* What the command line asks for. */
typedef struct lcp_args {
    const char *path;
    pd_lcp_format format;
    pd_lcp_method solver;
    int json, all;
    long index; /* a dump's LCP, -1: none chosen */
    const char *cover_text;
    int max_pivots, max_iterations;
    double tol;
} lcp_args;

/* --format value. */
static int parse_format(const char *text, pd_lcp_format *format)
{
    if (!text)
        return pd_cli_usage_error("lcp: --format needs a value (plain, siconos or auto)");
    if (!strcmp(text, "plain"))
        *format = PD_LCP_FORMAT_PLAIN;
    else if (!strcmp(text, "siconos"))
        *format = PD_LCP_FORMAT_SICONOS;
    else if (!strcmp(text, "auto"))
        *format = PD_LCP_FORMAT_AUTO;
    else
        return pd_cli_usage_error("lcp: --format: '%s' is not plain, siconos or auto", text);
    return 0;
}

/* One flag with its value at argv[*i + 1]; 0, 2 on error. */
static int parse_valued_flag(int argc, char **argv, int *i, lcp_args *a)
{
    const char *flag = argv[*i], *value = *i + 1 < argc ? argv[*i + 1] : NULL;
    int rc;
    if (!strcmp(flag, "--format"))
        rc = parse_format(value, &a->format);
    else if (!strcmp(flag, "--cover")) {
        a->cover_text = value;
        rc = value ? 0 : pd_cli_usage_error("lcp: --cover needs a value");
    } else if (!strcmp(flag, "--max-pivots")) {
        rc = pd_cli_int("--max-pivots", value, &a->max_pivots);
        if (rc == 0 && a->max_pivots <= 0)
            rc = pd_cli_usage_error("--max-pivots: must be a positive integer, got %s", value);
    } else if (!strcmp(flag, "--solver")) {
        rc = pd_lcp_method_parse(value, &a->solver)
                 ? pd_cli_usage_error("lcp: --solver: '%s' is not one of %s", value ? value : "",
                                      pd_lcp_method_list())
                 : 0;
    } else if (!strcmp(flag, "--index")) {
        int k = -1;
        rc = pd_cli_int("--index", value, &k);
        if (rc == 0 && k < 0)
            rc = pd_cli_usage_error("--index: must be >= 0, got %s", value);
        a->index = k;
    } else if (!strcmp(flag, "--max-iterations")) {
        rc = pd_cli_int("--max-iterations", value, &a->max_iterations);
        if (rc == 0 && a->max_iterations <= 0)
            rc = pd_cli_usage_error("--max-iterations: must be a positive integer, got %s", value);
    } else if (!strcmp(flag, "--tol")) {
        rc = pd_cli_double("--tol", value, &a->tol);
        if (rc == 0 && !(a->tol > 0.0 && a->tol < 1e-3))
            rc = pd_cli_usage_error("--tol: must lie in (0, 1e-3), got %s", value);
    } else
        return pd_cli_usage_error("lcp: unknown flag '%s' (try `pound lcp --help`)", flag);
    *i += 1;
    return rc;
}

/* argv into a; 0, 2 on error, -1 when --help was printed. */
static int parse_args(int argc, char **argv, lcp_args *a)
{
    memset(a, 0, sizeof *a);
    a->format = PD_LCP_FORMAT_AUTO;
    a->index = -1;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        int rc = 0;
        if (!strcmp(arg, "--help") || !strcmp(arg, "-h")) {
            fputs(lcp_usage, stdout);
            return -1;
        } else if (!strcmp(arg, "--json") || !strcmp(arg, "--all")) {
            a->json |= !strcmp(arg, "--json");
            a->all |= !strcmp(arg, "--all");
        } else if (arg[0] == '-' && arg[1] != '\0') {
            rc = parse_valued_flag(argc, argv, &i, a);
        } else if (a->path) {
            rc = pd_cli_usage_error("lcp: more than one FILE ('%s' and '%s')", a->path, arg);
        } else {
            a->path = arg;
        }
        if (rc)
            return rc;
    }
    if (!a->path)
        return pd_cli_usage_error("lcp: no FILE given (usage: pound lcp FILE [--json] ...)");
    if (a->all && a->index >= 0)
        return pd_cli_usage_error("--all and --index are alternatives: give one");
    return 0;
}

/* --cover: one value for all entries or n comma-separated values, all > 0. */
static int parse_cover(const char *text, int n, double *cover)
{
    int count = 0;
    const char *p = text;
    for (;;) {
        char *stop = NULL;
        errno = 0;
        double v = strtod(p, &stop);
        if (stop == p || (*stop != ',' && *stop != '\0') || errno == ERANGE || !isfinite(v))
            return pd_cli_usage_error("--cover: '%s' is not a list of numbers", text);
        if (!(v > 0.0))
            return pd_cli_usage_error("--cover: entries must be positive, got %g", v);
        if (count == n)
            return pd_cli_usage_error("--cover: more than n = %d values", n);
        cover[count++] = v;
        if (*stop == '\0')
            break;
        p = stop + 1;
    }
    if (count == 1)
        for (int i = 1; i < n; i++)
            cover[i] = cover[0];
    else if (count != n)
        return pd_cli_usage_error("--cover: expected 1 or n = %d values, got %d", n, count);
    return 0;
}

/* A vector on one line. */
static void print_vector(const char *name, int n, const double *x)
{
    printf("%-16s", name);
    for (int i = 0; i < n; i++)
        printf(" %.12g", x[i]);
    putchar('\n');
}

/* Human-readable result. */
static void print_text(int n, const double *z, const double *w, const pd_lcp_info *info,
                       double cpu_s)
{
    printf("%-16s %s\n", "status", pd_lcp_outcome_name(info->outcome));
    printf("%-16s %s\n", "solver", info->solver);
    printf("%-16s %d\n", "n", n);
    printf("%-16s %d\n", "pivots", info->pivots);
    printf("%-16s %d\n", "iterations", info->iterations);
    printf("%-16s %.3g\n", "residual", info->residual);
    printf("%-16s %.3g\n", "complementarity", info->complementarity);
    printf("%-16s %.3g\n", "infeasibility", info->infeasibility);
    printf("%-16s %.3g\n", "scale", info->scale);
    printf("%-16s %.3g\n", "cpu_s", cpu_s);
    print_vector("z", n, z);
    print_vector("w", n, w);
}

/* One JSON object. */
static void print_json(int n, const double *z, const double *w, const pd_lcp_info *info,
                       double cpu_s)
{
    pd_json js;
    pd_json_init(&js, stdout);
    pd_json_begin_object(&js, NULL);
    pd_json_str(&js, "status", pd_lcp_outcome_name(info->outcome));
    pd_json_str(&js, "solver", info->solver);
    pd_json_int(&js, "n", n);
    pd_json_nums(&js, "z", n, z);
    pd_json_nums(&js, "w", n, w);
    pd_json_int(&js, "pivots", info->pivots);
    pd_json_int(&js, "iterations", info->iterations);
    pd_json_num(&js, "residual", info->residual);
    pd_json_num(&js, "complementarity", info->complementarity);
    pd_json_num(&js, "infeasibility", info->infeasibility);
    pd_json_num(&js, "scale", info->scale);
    pd_json_num(&js, "cpu_s", cpu_s);
    pd_json_end_object(&js);
    pd_json_finish(&js);
}

/* The band of a dense M (from pd_lcp_read_band) worth compressed columns
 * for the structured solver: at most BAND_PER_ROW entries a row in
 * the band, and as the solver table's own copy asks, at most that many
 * nonzero entries a row on average and at most half of them nonzero. */
#define BAND_PER_ROW 17

/* M's band (half-width band) into compressed columns (pd_lcp_band_csc),
 * the arrays malloc'd into *colptr, *rowind, *values; -1 when out of
 * memory. */
static int band_to_csc(int n, const double *M, int band, long nnz, int **colptr, int **rowind,
                       double **values)
{
    *colptr = malloc(((size_t)n + 1) * sizeof(int));
    *rowind = pd_malloc(nnz, sizeof(int));
    *values = pd_malloc(nnz, sizeof(double));
    if (!*colptr || !*rowind || !*values)
        return -1;
    return pd_lcp_band_csc(n, M, band, nnz, *colptr, *rowind, *values) < 0 ? -1 : 0;
}

/* One solve of (M, q) with a solver of the table for up to n unknowns and
 * nnzmax stored entries, its CPU time added to *cpu_s (the solver's
 * allocation left out); PD_ENOMEM when it cannot be allocated. */
static int solve_once(const lcp_args *a, const pd_matrix *M, const double *q,
                      const pd_lcp_opts *opts, long nnzmax, double *z, double *w, pd_lcp_info *info,
                      double *cpu_s)
{
    pd_err err;
    pd_lcp_solver *solver = pd_lcp_solver_alloc(a->solver, M->rows, nnzmax, &err);
    if (!solver) {
        fprintf(stderr, "pound: lcp: %s\n", err.msg);
        return PD_ENOMEM;
    }
    double t0 = pd_cpu_seconds();
    int st = pd_lcp_solve(solver, M, q, opts, z, w, info);
    *cpu_s += pd_cpu_seconds() - t0;
    pd_lcp_solver_free(solver);
    return st;
}

/* Solve (M, q) and print; the exit status.  A banded M (band >= 0, nnz
 * entries, from the reader) goes to the structured solver as compressed
 * columns built from its band; when that does not solve it, M
 * goes again densely, as it would without its band (the hand-over to
 * Lemke is larger for dense input).  cpu_s counts the copy of the band
 * and the solves, not the solvers' allocation. */
static int solve_and_print(const lcp_args *a, int n, const double *M, const double *q, int band,
                           long nnz, const double *cover, double *z, double *w)
{
    pd_lcp_opts opts = pd_lcp_default_opts();
    opts.cover = cover;
    opts.max_pivots = a->max_pivots;
    opts.max_iterations = a->max_iterations;
    if (a->tol > 0.0)
        opts.tol = a->tol;
    pd_lcp_info info;
    pd_matrix Mv = pd_matrix_dense(n, n, M);
    long cap = (long)BAND_PER_ROW * n < (long)n * n / 2 ? (long)BAND_PER_ROW * n : (long)n * n / 2;
    int banded =
        a->solver == PD_LCP_STRUCTURED && band >= 0 && 2 * band + 1 <= BAND_PER_ROW && nnz <= cap;
    int *colptr = NULL, *rowind = NULL, st = PD_ENUMERICAL;
    double *values = NULL;
    double t0 = pd_cpu_seconds(), cpu_s = 0.0;
    if (banded && band_to_csc(n, M, band, nnz, &colptr, &rowind, &values) == 0) {
        cpu_s = pd_cpu_seconds() - t0;
        pd_matrix Mc = pd_matrix_csc(n, n, colptr, rowind, values);
        st = solve_once(a, &Mc, q, &opts, nnz > 0 ? nnz : 1, z, w, &info, &cpu_s);
    } else {
        banded = 0;
    }
    if (!banded || (st != PD_OK && st != PD_ENOMEM))
        st = solve_once(a, &Mv, q, &opts, 0, z, w, &info, &cpu_s);
    free(colptr);
    free(rowind);
    free(values);
    if (st == PD_ENOMEM)
        return 1;
    if (st == PD_EINVAL) /* the reader refuses non-finite data: the size is what is left */
        return pd_cli_usage_error("lcp: %s: n = %d is more than the %s solver takes (Lemke: at "
                                  "most %d unknowns)",
                                  a->path, n, pd_lcp_method_name(a->solver), PD_LCP_LEMKE_NMAX);
    if (a->json)
        print_json(n, z, w, &info, cpu_s);
    else
        print_text(n, z, w, &info, cpu_s);
    return st == PD_OK ? 0 : 1;
}

/* Does path end with suffix? */
static int ends_with(const char *path, const char *suffix)
{
    size_t n = strlen(path), k = strlen(suffix);
    return n > k && !strcmp(path + n - k, suffix);
}

/* Every LCP of a dump (or the one of --index) re-solved: the agreement with
 * the dumped answers.  Exit 0 when every one is solved. */
static int resolve_dump(const lcp_args *a)
{
    pd_lcp_set set;
    pd_err err;
    if (pd_lcp_set_read(a->path, &set, &err))
        return pd_cli_usage_error("lcp: %s", err.msg);
    if (!a->all && (a->index < 0 || a->index >= set.count)) {
        long count = set.count;
        pd_lcp_set_free(&set);
        return pd_cli_usage_error("lcp: %s holds %ld LCPs: give --all or --index K (0 <= K < %ld)",
                                  a->path, count, count);
    }
    long lo = a->all ? 0 : a->index, hi = a->all ? set.count : a->index + 1;
    long solved = 0, agree = 0, iterations = 0, pivots = 0;
    double worst = 0.0, worst_res = 0.0, cpu = 0.0;
    int rc = 0, nmax = set.nmax > 0 ? set.nmax : 1;
    pd_lcp_solver *solver = pd_lcp_solver_alloc(a->solver, nmax, set.nnzmax + 1, &err);
    double *z = malloc((size_t)nmax * sizeof(double)), *w = malloc((size_t)nmax * sizeof(double));
    pd_lcp_opts opts = pd_lcp_default_opts();
    opts.max_pivots = a->max_pivots;
    opts.max_iterations = a->max_iterations;
    if (!solver || !z || !w) {
        fprintf(stderr, "pound: lcp: %s\n", solver ? "out of memory" : err.msg);
        rc = 1;
    }
    for (long k = lo; k < hi && !rc; k++) {
        pd_matrix D = pd_lcp_set_matrix(&set, k);
        const double *b = set.b + set.voff[k], *z0 = set.z + set.voff[k];
        pd_lcp_info info;
        double t0 = pd_cpu_seconds();
        int st = pd_lcp_solve(solver, &D, b, &opts, z, w, &info);
        cpu += pd_cpu_seconds() - t0;
        double d = 0.0, s = 0.0;
        for (int i = 0; i < set.n[k]; i++) {
            d = fmax(d, fabs(z[i] - z0[i]));
            s = fmax(s, fabs(z0[i]));
        }
        d = s > 0.0 ? d / s : d;
        solved += st == PD_OK;
        agree += st == PD_OK && d <= 1e-8;
        worst = fmax(worst, d);
        worst_res = fmax(worst_res, info.residual);
        iterations += info.iterations;
        pivots += info.pivots;
    }
    long count = hi - lo;
    if (!rc && a->json) {
        pd_json js;
        pd_json_init(&js, stdout);
        pd_json_begin_object(&js, NULL);
        pd_json_str(&js, "dump", a->path);
        pd_json_str(&js, "solver", pd_lcp_method_name(a->solver));
        pd_json_int(&js, "count", count);
        pd_json_int(&js, "solved", solved);
        pd_json_int(&js, "agree", agree);
        pd_json_num(&js, "worst_difference", worst);
        pd_json_num(&js, "worst_residual", worst_res);
        pd_json_int(&js, "pivots", pivots);
        pd_json_int(&js, "iterations", iterations);
        pd_json_num(&js, "cpu_s", cpu);
        pd_json_int(&js, "nmax", set.nmax);
        pd_json_end_object(&js);
        pd_json_finish(&js);
    } else if (!rc) {
        printf("%s: %ld LCPs (n up to %d) re-solved by %s in %.3g s\n", a->path, count, set.nmax,
               pd_lcp_method_name(a->solver), cpu);
        printf("  solved %ld, agreeing with the dump (1e-8) %ld, worst difference %.3g, worst "
               "residual %.3g\n",
               solved, agree, worst, worst_res);
        printf("  pivots %ld, iterations %ld\n", pivots, iterations);
    }
    pd_lcp_solver_free(solver);
    free(z);
    free(w);
    pd_lcp_set_free(&set);
    return rc ? rc : solved == count ? 0 : 1;
}

int pd_cmd_lcp(int argc, char **argv)
{
    lcp_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc)
        return rc < 0 ? 0 : rc;
    if (ends_with(a.path, ".h5") || ends_with(a.path, ".hdf5"))
        return resolve_dump(&a);
    if (a.all || a.index >= 0)
        return pd_cli_usage_error("lcp: --all and --index go with an LCP dump (FILE.h5)");
    int n = 0, band = -1;
    long nnz = 0;
    double *M = NULL, *q = NULL, *buf = NULL;
    pd_err err;
    if (pd_lcp_read_band(a.path, a.format, &n, &M, &q, &band, &nnz, &err) != PD_OK)
        return pd_cli_usage_error("lcp: %s", err.msg);
    buf = malloc(3 * (size_t)n * sizeof(double));
    if (!buf) {
        fprintf(stderr, "pound: lcp: out of memory for n = %d\n", n);
        rc = 1;
    } else if (!a.cover_text || (rc = parse_cover(a.cover_text, n, buf + 2 * n)) == 0) {
        rc = solve_and_print(&a, n, M, q, band, nnz, a.cover_text ? buf + 2 * n : NULL, buf,
                             buf + n);
    }
    free(buf);
    free(M);
    free(q);
    return rc;
}
