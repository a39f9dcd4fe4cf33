/* test_lcp.c — Lemke's method, the enumeration oracle, residuals and readers. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "pd_lcp.h"
#include "pd_test.h"

#define VERIFY_TOL 1e-10 /* a solved answer: residuals <= this * scale */

/* ---- helpers --------------------------------------------------------------------- */

/* A problem with its own storage (column-major M). */
typedef struct lcp_case {
    int n;
    double *M, *q, *z, *w;
} lcp_case;

/* Zeroed storage for size n; NULL members if out of memory (checked by callers). */
static lcp_case case_new(int n)
{
    lcp_case c = {n, calloc((size_t)n * n, sizeof(double)), calloc((size_t)n, sizeof(double)),
                  calloc((size_t)n, sizeof(double)), calloc((size_t)n, sizeof(double))};
    return c;
}

static void case_free(lcp_case *c)
{
    free(c->M);
    free(c->q);
    free(c->z);
    free(c->w);
}

static int case_ok(const lcp_case *c)
{
    return c->M && c->q && c->z && c->w;
}

/* M = 1 on the diagonal, 2 above it (upper) or below it (lower). */
static void murty_matrix(lcp_case *c, int upper)
{
    int n = c->n;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++)
            c->M[i + j * n] = i == j ? 1.0 : ((upper ? i < j : i > j) ? 2.0 : 0.0);
}

/* Murty's exponential example: upper M, q_i = -sum_{j=i..n} 2^j (1-based). */
static void murty_exponential(lcp_case *c)
{
    murty_matrix(c, 1);
    double tail = 0.0;
    for (int i = c->n - 1; i >= 0; i--) {
        tail += ldexp(1.0, i + 1);
        c->q[i] = -tail;
    }
}

/* Fathi 1979: M = L L^T, L unit lower triangular with 2 below the diagonal; q = -e. */
static void fathi_problem(lcp_case *c)
{
    int n = c->n;
    for (int j = 0; j < n; j++) {
        for (int i = 0; i < n; i++) {
            int lo = i < j ? i : j; /* sum_k L_ik L_jk over k <= min(i, j) */
            c->M[i + j * n] = 4.0 * lo + (i == j ? 1.0 : 2.0);
        }
        c->q[j] = -1.0;
    }
}

/* M = B B^T / r + shift I with B n x r uniform in [-1, 1). */
static void random_gram(lcp_case *c, int r, double shift, uint64_t *rng)
{
    int n = c->n;
    double *B = malloc((size_t)n * r * sizeof(double));
    if (!B)
        return;
    for (int k = 0; k < n * r; k++)
        B[k] = pd_rand_pm1(rng);
    for (int j = 0; j < n; j++)
        for (int i = 0; i <= j; i++) {
            double s = 0.0;
            for (int k = 0; k < r; k++)
                s += B[i + k * n] * B[j + k * n];
            c->M[i + j * n] = c->M[j + i * n] = s / r + (i == j ? shift : 0.0);
        }
    free(B);
}

/* SPD: M = B B^T / r + 0.1 I. */
static void random_spd(lcp_case *c, int r, uint64_t *rng)
{
    random_gram(c, r, 0.1, rng);
}

/* Nonsymmetric P-matrix, row-diagonally dominant with a positive diagonal. */
static void random_diag_dominant(lcp_case *c, uint64_t *rng)
{
    int n = c->n;
    for (int i = 0; i < n; i++) {
        double off = 0.0;
        for (int j = 0; j < n; j++) {
            if (j == i)
                continue;
            c->M[i + j * n] = pd_rand_pm1(rng);
            off += fabs(c->M[i + j * n]);
        }
        c->M[i + i * n] = off + 0.1 + 0.5 * (1.0 + pd_rand_pm1(rng));
    }
}

/* Nonsymmetric positive definite: M = I + (S - S^T) + B B^T / r. */
static void random_pd_skew(lcp_case *c, int r, uint64_t *rng)
{
    int n = c->n;
    random_spd(c, r, rng);
    for (int j = 0; j < n; j++) {
        c->M[j + j * n] += 0.9;
        for (int i = 0; i < j; i++) {
            double s = pd_rand_pm1(rng);
            c->M[i + j * n] += s;
            c->M[j + i * n] -= s;
        }
    }
}

/* q uniform in [-1, 1). */
static void random_q(lcp_case *c, uint64_t *rng)
{
    for (int i = 0; i < c->n; i++)
        c->q[i] = pd_rand_pm1(rng);
}

/* Lemke with a fresh workspace; info out. */
static int solve(lcp_case *c, const pd_lcp_opts *opts, pd_lcp_info *info)
{
    pd_lcp_work *work = pd_lcp_alloc(c->n);
    if (!work)
        return PD_ENOMEM;
    int st = pd_lcp_lemke(work, c->n, c->M, c->q, opts, c->z, c->w, info);
    pd_lcp_free(work);
    return st;
}

/* Independent check of a solved answer: relative backward residual within
 * VERIFY_TOL. */
static void check_verified(pd_test_ctx *ctx, const lcp_case *c, const char *what)
{
    double *w = malloc((size_t)c->n * sizeof(double));
    double comp = NAN, infeas = NAN, residual = NAN;
    if (w)
        pd_lcp_residual(c->n, c->M, c->q, c->z, w, &comp, &infeas, &residual);
    CHECK(ctx, residual <= VERIFY_TOL,
          "%s: relative residual %.3g > %.0e (complementarity %.3g, "
          "infeasibility %.3g)",
          what, residual, VERIFY_TOL, comp, infeas);
    free(w);
}

/* max_i |a_i - b_i|. */
static double max_diff(int n, const double *a, const double *b)
{
    double d = 0.0;
    for (int i = 0; i < n; i++)
        d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

/* Lemke solves (verified) and matches the enumeration's solution (unique). */
static void check_against_enumeration(pd_test_ctx *ctx, lcp_case *c, const char *what)
{
    pd_lcp_info info;
    int st = solve(c, NULL, &info);
    CHECK(ctx, st == PD_OK, "%s: Lemke status %d (%s)", what, st,
          pd_lcp_outcome_name(info.outcome));
    check_verified(ctx, c, what);
    double z_enum[12], w_enum[12];
    int se = pd_lcp_enumerate(c->n, c->M, c->q, z_enum, w_enum);
    CHECK(ctx, se == PD_OK, "%s: enumeration status %d", what, se);
    double zmax = fmax(1.0, fabs(z_enum[0]));
    for (int i = 1; i < c->n; i++)
        zmax = fmax(zmax, fabs(z_enum[i]));
    double d = max_diff(c->n, c->z, z_enum);
    CHECK(ctx, d <= 1e-10 * zmax, "%s: |z_lemke - z_enum| = %.3g", what, d);
}

/* Write text to a new temporary file; 0 on success (path filled). */
static int write_temp(char path[64], const char *text)
{
    strcpy(path, "/tmp/pound_lcp_XXXXXX");
    int fd = mkstemp(path);
    if (fd < 0)
        return -1;
    size_t len = strlen(text);
    ssize_t wrote = write(fd, text, len);
    close(fd);
    return wrote == (ssize_t)len ? 0 : -1;
}

/* Read text (written to a temp file) in the given format. */
static int read_text(const char *text, pd_lcp_format format, int *n, double **M, double **q,
                     pd_err *err)
{
    char path[64];
    if (write_temp(path, text) != 0)
        return pd_err_set(err, PD_EIO, "cannot write a temporary file");
    int st = pd_lcp_read(path, format, n, M, q, err);
    remove(path);
    return st;
}

/* The band noted while a file is read (pd_lcp_read_band) and the copy of
 * the band (pd_lcp_band_csc): a tridiagonal chain of 40 has band 1 and
 * 118 nonzero entries, and its band's copy is the matrix; the same chain
 * with one far entry M_0,39 (plain, row-major) or M_39,0 (Siconos,
 * column-major) has band 39, so it is not taken for banded, and the copy
 * of its band 39 is the matrix too; a copy over its capacity is refused. */
static void test_lcp_read_band(pd_test_ctx *ctx)
{
    enum { N = 40 };
    for (int far = 0; far < 2; far++)
        for (int siconos = 0; siconos < 2; siconos++) {
            static char text[16 * N * N + 256];
            size_t at = 0;
            at += (size_t)snprintf(text + at, sizeof text - at,
                                   siconos ? "%d\n0\n%d\n%d\n%d %d\n" : "%d\n", N, N, N, N, N);
            for (int r = 0; r < N; r++) /* row r of the file: M's row (plain), column (siconos) */
                for (int c = 0; c < N; c++) {
                    int i = siconos ? c : r, j = siconos ? r : c;
                    double x = i == j                     ? 2.0
                               : abs(i - j) == 1          ? -1.0
                               : far && i == 39 && j == 0 ? 0.5
                                                          : 0.0;
                    at += (size_t)snprintf(text + at, sizeof text - at, "%g%c", x,
                                           c + 1 < N ? ' ' : '\n');
                }
            for (int i = 0; i < N; i++)
                at += (size_t)snprintf(text + at, sizeof text - at, "%d%c", i % 3 - 1,
                                       i + 1 < N ? ' ' : '\n');
            char path[64];
            int n = 0, band = -2;
            long nnz = -1;
            double *M = NULL, *q = NULL;
            pd_err err;
            if (!CHECK(ctx, write_temp(path, text) == 0, "temp file"))
                return;
            int st = pd_lcp_read_band(path, siconos ? PD_LCP_FORMAT_SICONOS : PD_LCP_FORMAT_PLAIN,
                                      &n, &M, &q, &band, &nnz, &err);
            remove(path);
            if (!CHECK(ctx, st == PD_OK && n == N, "read: %s", err.msg))
                continue;
            CHECK(ctx, band == (far ? 39 : 1) && nnz == 3 * N - 2 + far,
                  "far %d siconos %d: band %d, nnz %ld", far, siconos, band, nnz);
            int colptr[N + 1], rowind[3 * N];
            double values[3 * N], back[N * N];
            long k = pd_lcp_band_csc(n, M, band, 3 * N, colptr, rowind, values);
            CHECK(ctx, k == nnz, "copy: %ld entries", k);
            if (k == nnz) {
                pd_matrix A = pd_matrix_csc(n, n, colptr, rowind, values);
                pd_matrix_to_dense(&A, back);
                CHECK(ctx, !memcmp(back, M, sizeof back), "far %d: the copy is not M", far);
            }
            CHECK(ctx, pd_lcp_band_csc(n, M, band, nnz - 1, colptr, rowind, values) == PD_EINVAL,
                  "over its capacity: not refused");
            free(M);
            free(q);
        }
    int n = 0, band = 7;
    long nnz = 7;
    double *M = NULL, *q = NULL;
    pd_err err;
    char path[64];
    if (CHECK(ctx, write_temp(path, "2\n0 0\n0 0\n1 1\n") == 0, "temp file")) {
        CHECK(ctx,
              pd_lcp_read_band(path, PD_LCP_FORMAT_PLAIN, &n, &M, &q, &band, &nnz, &err) == PD_OK &&
                  band == -1 && nnz == 0,
              "zero M: band %d nnz %ld", band, nnz);
        remove(path);
        free(M);
        free(q);
    }
}

/* ---- Siconos test set --------------------------------------------------------------- */

static const char *const siconos_files[] = {"CPS_1",
                                            "CPS_2",
                                            "CPS_3",
                                            "CPS_4",
                                            "CPS_4bis",
                                            "CPS_5",
                                            "Pang_isolated_sol",
                                            "Pang_isolated_sol_perturbed",
                                            "deudeu",
                                            "enum_fails",
                                            "exp_murty",
                                            "exp_murty2",
                                            "inf_sol_perturbed",
                                            "mmc",
                                            "ortiz",
                                            "tobenna",
                                            "trivial"};

/* README: only these two end on a ray. */
static int siconos_expects_ray(const char *name)
{
    return !strcmp(name, "CPS_3") || !strcmp(name, "Pang_isolated_sol_perturbed");
}

/* Read <shared>/data/lcp/siconos/lcp_NAME.dat. */
static int read_siconos(pd_test_ctx *ctx, const char *name, lcp_case *c)
{
    char path[1024];
    pd_err err;
    snprintf(path, sizeof path, "%s/data/lcp/siconos/lcp_%s.dat", ctx->shared, name);
    memset(c, 0, sizeof *c);
    int st = pd_lcp_read(path, PD_LCP_FORMAT_SICONOS, &c->n, &c->M, &c->q, &err);
    CHECK(ctx, st == PD_OK, "read %s: %s", name, err.msg);
    if (st != PD_OK)
        return -1;
    c->z = calloc((size_t)c->n, sizeof(double));
    c->w = calloc((size_t)c->n, sizeof(double));
    return case_ok(c) ? 0 : -1;
}

static void test_lcp_siconos_outcomes(pd_test_ctx *ctx)
{
    if (!ctx->shared) {
        pd_test_skip(ctx, "no shared folder with data/lcp/siconos");
        return;
    }
    for (size_t k = 0; k < sizeof siconos_files / sizeof siconos_files[0]; k++) {
        lcp_case c;
        if (read_siconos(ctx, siconos_files[k], &c) != 0) {
            case_free(&c);
            continue;
        }
        pd_lcp_info info;
        int st = solve(&c, NULL, &info);
        if (siconos_expects_ray(siconos_files[k])) {
            CHECK(ctx, st == PD_ENOSOLUTION && info.outcome == PD_LCP_NO_SOLUTION,
                  "%s: status %d (%s), expected no_solution", siconos_files[k], st,
                  pd_lcp_outcome_name(info.outcome));
        } else {
            CHECK(ctx, st == PD_OK && info.outcome == PD_LCP_SOLVED, "%s: status %d (%s)",
                  siconos_files[k], st, pd_lcp_outcome_name(info.outcome));
            check_verified(ctx, &c, siconos_files[k]);
        }
        case_free(&c);
    }
}

static void test_lcp_siconos_murty2_pivots(pd_test_ctx *ctx)
{
    if (!ctx->shared) {
        pd_test_skip(ctx, "no shared folder with data/lcp/siconos");
        return;
    }
    lcp_case c;
    if (read_siconos(ctx, "exp_murty2", &c) == 0) {
        pd_lcp_info info;
        CHECK(ctx, solve(&c, NULL, &info) == PD_OK, "exp_murty2 solved");
        CHECK(ctx, info.pivots == 64, "exp_murty2: %d pivots, expected 2^6 = 64", info.pivots);
        CHECK_NEAR(ctx, c.z[5], 64.0, 0.0);
        /* the file holds the n = 6 member of the generated family */
        lcp_case g = case_new(6);
        if (case_ok(&g)) {
            murty_exponential(&g);
            CHECK(ctx, max_diff(36, g.M, c.M) == 0.0 && max_diff(6, g.q, c.q) == 0.0,
                  "exp_murty2 equals the generated Murty family member n = 6");
        }
        case_free(&g);
    }
    case_free(&c);
}

/* ---- classics defined by formulas ----------------------------------------------------- */

static void test_lcp_murty_exponential_pivots(pd_test_ctx *ctx)
{
    for (int n = 6; n <= 12; n++) {
        lcp_case c = case_new(n);
        if (!case_ok(&c)) {
            CHECK(ctx, 0, "out of memory");
            case_free(&c);
            return;
        }
        murty_exponential(&c);
        pd_lcp_opts opts = pd_lcp_default_opts();
        opts.max_pivots = 1 << 14;
        pd_lcp_info info;
        int st = solve(&c, &opts, &info);
        CHECK(ctx, st == PD_OK, "n = %d: status %d", n, st);
        CHECK(ctx, info.pivots == 1 << n, "n = %d: %d pivots, expected 2^n = %d", n, info.pivots,
              1 << n);
        /* unique solution z = 2^n e_n, w_i = 2^i (1-based i < n) */
        for (int i = 0; i < n - 1; i++) {
            CHECK_NEAR(ctx, c.z[i], 0.0, 0.0);
            CHECK_NEAR(ctx, c.w[i], ldexp(1.0, i + 1), 1e-12 * ldexp(1.0, n));
        }
        CHECK_NEAR(ctx, c.z[n - 1], ldexp(1.0, n), 1e-12 * ldexp(1.0, n));
        case_free(&c);
    }
}

/* Murty's 1978 test problem, q = -e: M lower (1 diagonal, 2 below; solution e_1)
 * or upper (the Siconos exp_murty orientation; solution e_n).  With the
 * lexicographic rule the tie of the first step is resolved towards the last
 * row, which makes the lower orientation the exponential instance (2^n
 * pivots) and the upper one a two-pivot solve. */
static void check_murty_1978(pd_test_ctx *ctx, int n, int upper)
{
    lcp_case c = case_new(n);
    if (!case_ok(&c)) {
        CHECK(ctx, 0, "out of memory");
        case_free(&c);
        return;
    }
    murty_matrix(&c, upper);
    for (int i = 0; i < n; i++)
        c.q[i] = -1.0;
    pd_lcp_info info;
    CHECK(ctx, solve(&c, NULL, &info) == PD_OK, "Murty %s n = %d solved", upper ? "upper" : "lower",
          n);
    int want = n <= 2 ? 0 : upper ? 2 : 1 << n; /* n <= 2: the closed forms, no pivots */
    CHECK(ctx, info.pivots == want, "Murty %s n = %d: %d pivots, expected %d",
          upper ? "upper" : "lower", n, info.pivots, want);
    int one = upper ? n - 1 : 0;
    for (int i = 0; i < n; i++)
        CHECK_NEAR(ctx, c.z[i], i == one ? 1.0 : 0.0, 1e-14);
    if (n <= 10)
        check_against_enumeration(ctx, &c, upper ? "Murty upper" : "Murty lower");
    case_free(&c);
}

static void test_lcp_murty_1978(pd_test_ctx *ctx)
{
    int lower[] = {1, 2, 5, 10, 12}, upper[] = {1, 2, 5, 10, 40, 200};
    for (size_t k = 0; k < sizeof lower / sizeof lower[0]; k++)
        check_murty_1978(ctx, lower[k], 0);
    for (size_t k = 0; k < sizeof upper / sizeof upper[0]; k++)
        check_murty_1978(ctx, upper[k], 1);
}

static void test_lcp_fathi_1979(pd_test_ctx *ctx)
{
    int sizes[] = {1, 3, 8, 10, 32, 100};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        int n = sizes[k];
        lcp_case c = case_new(n);
        if (!case_ok(&c)) {
            CHECK(ctx, 0, "out of memory");
            case_free(&c);
            return;
        }
        fathi_problem(&c);
        pd_lcp_info info;
        CHECK(ctx, solve(&c, NULL, &info) == PD_OK, "Fathi n = %d solved", n);
        for (int i = 0; i < n; i++) /* known solution z = e_1 */
            CHECK_NEAR(ctx, c.z[i], i == 0 ? 1.0 : 0.0, 1e-12);
        if (n <= 10)
            check_against_enumeration(ctx, &c, "Fathi");
        case_free(&c);
    }
}

static void test_lcp_q_nonnegative(pd_test_ctx *ctx)
{
    lcp_case c = case_new(4);
    if (!case_ok(&c)) {
        CHECK(ctx, 0, "out of memory");
        case_free(&c);
        return;
    }
    double q[4] = {0.0, 3.0, -0.0, 1e-300};
    memcpy(c.q, q, sizeof q);
    for (int k = 0; k < 16; k++)
        c.M[k] = k % 3 - 1.0; /* arbitrary, even indefinite */
    pd_lcp_info info;
    CHECK(ctx, solve(&c, NULL, &info) == PD_OK, "q >= 0 solved");
    CHECK(ctx, info.pivots == 0, "q >= 0: %d pivots, expected 0", info.pivots);
    for (int i = 0; i < 4; i++) {
        CHECK_NEAR(ctx, c.z[i], 0.0, 0.0);
        CHECK_NEAR(ctx, c.w[i], q[i], 0.0);
    }
    CHECK_NEAR(ctx, info.complementarity, 0.0, 0.0);
    case_free(&c);
}

/* One 1 x 1 problem: the expected status and z. */
static void check_scalar(pd_test_ctx *ctx, double m, double q, int want_status, double want_z)
{
    pd_lcp_work *work = pd_lcp_alloc(1);
    double z = -7.0, w = -7.0;
    pd_lcp_info info;
    int st = pd_lcp_lemke(work, 1, &m, &q, NULL, &z, &w, &info);
    CHECK(ctx, st == want_status, "m = %g, q = %g: status %d, expected %d", m, q, st, want_status);
    CHECK(ctx, z >= 0.0, "m = %g, q = %g: z = %g is negative", m, q, z);
    if (want_status == PD_OK) {
        CHECK_NEAR(ctx, z, want_z, 1e-15 * fmax(1.0, want_z));
        CHECK_NEAR(ctx, w, m * z + q, 1e-15 * fmax(1.0, fabs(q)));
    }
    /* solved: the closed form (no pivot); a ray: Lemke's one pivot */
    CHECK(ctx, info.pivots == (q < 0.0 && want_status != PD_OK ? 1 : 0),
          "m = %g, q = %g: %d pivots", m, q, info.pivots);
    pd_lcp_free(work);
}

static void test_lcp_scalar_signs(pd_test_ctx *ctx)
{
    check_scalar(ctx, 2.0, -3.0, PD_OK, 1.5);
    check_scalar(ctx, 2.0, 3.0, PD_OK, 0.0);
    check_scalar(ctx, 2.0, 0.0, PD_OK, 0.0);
    check_scalar(ctx, 0.0, 1.0, PD_OK, 0.0);
    check_scalar(ctx, 0.0, 0.0, PD_OK, 0.0);
    check_scalar(ctx, -2.0, 3.0, PD_OK, 0.0);
    check_scalar(ctx, 1e-8, -1e8, PD_OK, 1e16);
    check_scalar(ctx, 0.0, -1.0, PD_ENOSOLUTION, 0.0);
    check_scalar(ctx, -2.0, -3.0, PD_ENOSOLUTION, 0.0);
}

/* ---- random problems -------------------------------------------------------------- */

/* n x n random P-matrix problems of one kind against the enumeration. */
static void random_small_vs_enumeration(pd_test_ctx *ctx, int kind, const char *what)
{
    uint64_t rng = 0x5eed0000u + (uint64_t)kind;
    for (int n = 1; n <= 10; n++) {
        for (int rep = 0; rep < 20; rep++) {
            lcp_case c = case_new(n);
            if (!case_ok(&c)) {
                CHECK(ctx, 0, "out of memory");
                case_free(&c);
                return;
            }
            if (kind == 0)
                random_spd(&c, n + 2, &rng);
            else if (kind == 1)
                random_diag_dominant(&c, &rng);
            else
                random_pd_skew(&c, 2, &rng);
            random_q(&c, &rng);
            check_against_enumeration(ctx, &c, what);
            case_free(&c);
        }
    }
}

/* Large random problems of one kind: solved and verified. */
static void random_large_verified(pd_test_ctx *ctx, int kind, const int *sizes, int count)
{
    uint64_t rng = 0xb16b00b5u + (uint64_t)kind;
    for (int k = 0; k < count; k++) {
        lcp_case c = case_new(sizes[k]);
        if (!case_ok(&c)) {
            CHECK(ctx, 0, "out of memory");
            case_free(&c);
            return;
        }
        if (kind == 0)
            random_spd(&c, 32, &rng);
        else if (kind == 1)
            random_diag_dominant(&c, &rng);
        else
            random_pd_skew(&c, 16, &rng);
        random_q(&c, &rng);
        pd_lcp_info info;
        int st = solve(&c, NULL, &info);
        CHECK(ctx, st == PD_OK, "kind %d, n = %d: status %d (%s)", kind, sizes[k], st,
              pd_lcp_outcome_name(info.outcome));
        CHECK(ctx, info.pivots >= 1 && info.pivots <= 4 * sizes[k], "n = %d: %d pivots", sizes[k],
              info.pivots);
        check_verified(ctx, &c, "large random");
        case_free(&c);
    }
}

static void test_lcp_random_spd_vs_enumeration(pd_test_ctx *ctx)
{
    random_small_vs_enumeration(ctx, 0, "random SPD");
}

static void test_lcp_random_diag_dominant_vs_enumeration(pd_test_ctx *ctx)
{
    random_small_vs_enumeration(ctx, 1, "random diagonally dominant");
}

static void test_lcp_random_pd_skew_vs_enumeration(pd_test_ctx *ctx)
{
    random_small_vs_enumeration(ctx, 2, "random I + skew + SPD");
}

static void test_lcp_random_large_spd(pd_test_ctx *ctx)
{
    int sizes[] = {50, 200, 500};
    random_large_verified(ctx, 0, sizes, 3);
}

static void test_lcp_random_large_nonsymmetric(pd_test_ctx *ctx)
{
    int sizes[] = {100, 500};
    random_large_verified(ctx, 1, sizes, 2);
    random_large_verified(ctx, 2, sizes, 2);
}

/* Random PSD (rank-deficient, copositive-plus) problems: Lemke solves exactly when
 * the enumeration finds a solution, and ray-terminates otherwise. */
static void test_lcp_random_psd_solvable_iff_enumeration(pd_test_ctx *ctx)
{
    uint64_t rng = 0xfeedu;
    int solved = 0, rays = 0;
    for (int rep = 0; rep < 400; rep++) {
        int n = 2 + rep % 7;
        lcp_case c = case_new(n);
        if (!case_ok(&c)) {
            CHECK(ctx, 0, "out of memory");
            case_free(&c);
            return;
        }
        random_gram(&c, 1 + rep % 2, 0.0, &rng); /* positive semidefinite, singular */
        random_q(&c, &rng);
        double ze[12], we[12];
        int se = pd_lcp_enumerate(n, c.M, c.q, ze, we);
        pd_lcp_info info;
        int st = solve(&c, NULL, &info);
        CHECK(ctx, (st == PD_OK) == (se == PD_OK) && (st == PD_OK || st == PD_ENOSOLUTION),
              "rep %d (n = %d): Lemke %d, enumeration %d", rep, n, st, se);
        if (st == PD_OK)
            check_verified(ctx, &c, "random PSD");
        solved += st == PD_OK;
        rays += st == PD_ENOSOLUTION;
        case_free(&c);
    }
    CHECK(ctx, solved > 40 && rays > 40, "both outcomes exercised: %d solved, %d rays", solved,
          rays);
}

/* ---- degeneracy, rays, caps ------------------------------------------------------- */

static void test_lcp_degenerate_cyclic(pd_test_ctx *ctx)
{
    /* M = [1 2 0; 0 1 2; 2 0 1], q = -e: every ratio test ties; z = e/3 */
    lcp_case c = case_new(3);
    if (!case_ok(&c)) {
        CHECK(ctx, 0, "out of memory");
        case_free(&c);
        return;
    }
    double M[9] = {1, 0, 2, 2, 1, 0, 0, 2, 1};
    memcpy(c.M, M, sizeof M);
    for (int i = 0; i < 3; i++)
        c.q[i] = -1.0;
    pd_lcp_info info;
    CHECK(ctx, solve(&c, NULL, &info) == PD_OK, "cyclic 3 x 3 solved");
    for (int i = 0; i < 3; i++)
        CHECK_NEAR(ctx, c.z[i], 1.0 / 3.0, 1e-15);
    CHECK(ctx, info.pivots <= 10, "cyclic: %d pivots", info.pivots);
    check_against_enumeration(ctx, &c, "cyclic");
    case_free(&c);
}

static void test_lcp_degenerate_repeated_q(pd_test_ctx *ctx)
{
    uint64_t rng = 0xdec0de;
    int sizes[] = {2, 4, 7, 10, 60};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        int n = sizes[k];
        for (int kind = 0; kind < 3; kind++) {
            lcp_case c = case_new(n);
            if (!case_ok(&c)) {
                CHECK(ctx, 0, "out of memory");
                case_free(&c);
                return;
            }
            if (kind == 0)
                random_spd(&c, n + 1, &rng);
            else if (kind == 1)
                random_diag_dominant(&c, &rng);
            else
                for (int i = 0; i < n; i++)
                    c.M[i + i * n] = 1.0; /* identity: every row ties */
            for (int i = 0; i < n; i++)   /* repeated equal negatives and zeros */
                c.q[i] = i % 3 == 2 ? 0.0 : -1.0;
            pd_lcp_info info;
            int st = solve(&c, NULL, &info);
            CHECK(ctx, st == PD_OK, "n = %d kind %d: status %d", n, kind, st);
            check_verified(ctx, &c, "repeated q");
            if (n <= 10)
                check_against_enumeration(ctx, &c, "repeated q");
            case_free(&c);
        }
    }
}

/* Integer data, heavy degeneracy: M = I + G G^T with G in {-2..1}^(n x 3) (a
 * P-matrix), q in {-2..2} (many zeros and repeats): every ratio test is full of
 * exact ties.  Solved, verified, equal to the enumeration for n <= 10. */
static void test_lcp_degenerate_integer_random(pd_test_ctx *ctx)
{
    uint64_t rng = 0x1e9;
    int sizes[] = {3, 5, 8, 10, 40, 150};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        for (int rep = 0; rep < (sizes[k] <= 10 ? 40 : 4); rep++) {
            int n = sizes[k];
            lcp_case c = case_new(n);
            int G[150 * 3];
            if (!case_ok(&c)) {
                CHECK(ctx, 0, "out of memory");
                case_free(&c);
                return;
            }
            for (int e = 0; e < 3 * n; e++)
                G[e] = (int)(pd_rand_next(&rng) % 4) - 2;
            for (int j = 0; j < n; j++) {
                for (int i = 0; i < n; i++) {
                    int dot = G[3 * i] * G[3 * j] + G[3 * i + 1] * G[3 * j + 1] +
                              G[3 * i + 2] * G[3 * j + 2];
                    c.M[i + j * n] = dot + (i == j);
                }
                c.q[j] = (double)((int)(pd_rand_next(&rng) % 5) - 2);
            }
            pd_lcp_info info;
            int st = solve(&c, NULL, &info);
            CHECK(ctx, st == PD_OK, "n = %d rep %d: status %d (%s)", n, rep, st,
                  pd_lcp_outcome_name(info.outcome));
            check_verified(ctx, &c, "integer degenerate");
            if (n <= 10)
                check_against_enumeration(ctx, &c, "integer degenerate");
            case_free(&c);
        }
    }
}

static void test_lcp_ray_copositive_plus(pd_test_ctx *ctx)
{
    /* M skew (copositive-plus), w1 = z2 - 1, w2 = -z1 - 1 < 0: infeasible */
    double M[4] = {0.0, -1.0, 1.0, 0.0}, q[2] = {-1.0, -1.0}, z[2], w[2];
    pd_lcp_work *work = pd_lcp_alloc(2);
    pd_lcp_info info;
    int st = pd_lcp_lemke(work, 2, M, q, NULL, z, w, &info);
    CHECK(ctx, st == PD_ENOSOLUTION, "skew: status %d, expected PD_ENOSOLUTION", st);
    CHECK(ctx, info.outcome == PD_LCP_NO_SOLUTION, "skew: outcome %s",
          pd_lcp_outcome_name(info.outcome));
    CHECK(ctx, pd_lcp_enumerate(2, M, q, z, w) == PD_ENOSOLUTION, "enumeration agrees");
    /* M = 0 (copositive-plus) with a negative q */
    double Z[9] = {0}, q3[3] = {1.0, -2.0, 0.5}, z3[3], w3[3];
    st = pd_lcp_lemke(work, 2, Z, q3, NULL, z3, w3, &info); /* n = 2 of a bigger array */
    CHECK(ctx, st == PD_ENOSOLUTION, "M = 0: status %d", st);
    CHECK(ctx, z3[0] >= 0.0 && z3[1] >= 0.0, "M = 0: z stays >= 0");
    pd_lcp_free(work);
}

static void test_lcp_small_pivot_is_not_a_ray(pd_test_ctx *ctx)
{
    /* M = [1 -1; -1 1 + 1e-12] (SPD: a P-matrix, so never a ray) beside a
     * third, uncoupled unknown (n = 3: pivoting, not the closed forms of
     * n <= 2), q = (0.5, -1, -1): the last entering column has an entry ~1e-12
     * of its largest, below the pivot tolerance but far above roundoff;
     * unique solution z2 = 0.5 / 1e-12, z1 = z2 - 0.5, z3 = 1 */
    double M[9] = {1.0, -1.0, 0.0, -1.0, 1.0 + 1e-12, 0.0, 0.0, 0.0, 1.0};
    double q[3] = {0.5, -1.0, -1.0}, z[3], w[3];
    pd_lcp_work *work = pd_lcp_alloc(3);
    pd_lcp_info info;
    int st = pd_lcp_lemke(work, 3, M, q, NULL, z, w, &info);
    CHECK(ctx, st == PD_OK && info.pivots >= 3,
          "status %d (%s), %d pivots, expected solved by "
          "pivoting",
          st, pd_lcp_outcome_name(info.outcome), info.pivots);
    double z2 = 0.5 / (M[4] - 1.0); /* exact for this double data */
    CHECK_NEAR(ctx, z[1], z2, 1e-6 * z2);
    CHECK_NEAR(ctx, z[0], z2 - 0.5, 1e-6 * z2);
    CHECK_NEAR(ctx, z[2], 1.0, 1e-12);
    pd_lcp_free(work);
}

static void test_lcp_numerical_outcome(pd_test_ctx *ctx)
{
    /* M = [1.1 -1.3; -1.3 1.3^2/1.1 + 1e-11] (SPD, cond ~ 1e11), q = (0.3, -1): the
     * unique solution has |z| ~ 1e11; |w| ~ eps |M| |z| in doubles is rounding
     * of the terms that make w, so the answer is backward stable (solved, relative
     * residual <= 1e-10) and its forward error is what the condition allows */
    double m22 = 1.3 * 1.3 / 1.1 + 1e-11;
    double M[4] = {1.1, -1.3, -1.3, m22}, q[2] = {0.3, -1.0}, z[2], w[2];
    pd_lcp_work *work = pd_lcp_alloc(2);
    pd_lcp_info info;
    int st = pd_lcp_lemke(work, 2, M, q, NULL, z, w, &info);
    CHECK(ctx, st == PD_OK && info.residual <= 1e-10, "status %d, residual %.3g", st,
          info.residual);
    long double det = (long double)M[0] * M[3] - (long double)M[1] * M[2]; /* z = -M^-1 q */
    long double z1 = -((long double)M[3] * q[0] - (long double)M[2] * q[1]) / det;
    long double z2 = -(-(long double)M[1] * q[0] + (long double)M[0] * q[1]) / det;
    CHECK(ctx, fabsl(z[0] - z1) <= 1e-3L * z1 && fabsl(z[1] - z2) <= 1e-3L * z2,
          "z = (%.6g, %.6g) vs (%.6Lg, %.6Lg)", z[0], z[1], z1, z2);
    /* no solution with extreme scales (w2 = -1e13 z1 - z2 + 1 < 0 whenever
     * w1 = 2 z1 + z2 - 2 >= 0): a scale that hides w2 = -1 behind 1e13 must not
     * make it "solved" (the enumeration oracle agrees there is none) */
    double M2[4] = {2, -1e13, 1, -1}, q2[2] = {-2, 1};
    st = pd_lcp_lemke(work, 2, M2, q2, NULL, z, w, &info);
    CHECK(ctx, st != PD_OK && info.outcome != PD_LCP_SOLVED,
          "extreme scales: status %d (%s), z = (%g, %g), w = (%g, %g)", st,
          pd_lcp_outcome_name(info.outcome), z[0], z[1], w[0], w[1]);
    CHECK(ctx, pd_lcp_enumerate(2, M2, q2, z, w) == PD_ENOSOLUTION, "the oracle finds none");
    pd_lcp_free(work);
}

static void test_lcp_max_pivots(pd_test_ctx *ctx)
{
    lcp_case c = case_new(12);
    if (!case_ok(&c)) {
        CHECK(ctx, 0, "out of memory");
        case_free(&c);
        return;
    }
    murty_exponential(&c);
    pd_lcp_opts opts = pd_lcp_default_opts();
    opts.max_pivots = 100;
    pd_lcp_info info;
    int st = solve(&c, &opts, &info);
    CHECK(ctx, st == PD_EMAXPIVOTS, "status %d, expected PD_EMAXPIVOTS", st);
    CHECK(ctx, info.outcome == PD_LCP_MAX_PIVOTS, "outcome %s", pd_lcp_outcome_name(info.outcome));
    CHECK(ctx, info.pivots == 100, "%d pivots at a cap of 100", info.pivots);
    CHECK(ctx, PD_EMAXPIVOTS != PD_ENOSOLUTION, "cap and ray have distinct codes");
    /* the cap is exact: 2^6 pivots are enough for n = 6, 2^6 - 1 are not */
    lcp_case s = case_new(6);
    if (case_ok(&s)) {
        murty_exponential(&s);
        opts.max_pivots = 64;
        CHECK(ctx, solve(&s, &opts, &info) == PD_OK, "cap 64 suffices for n = 6");
        opts.max_pivots = 63;
        CHECK(ctx, solve(&s, &opts, &info) == PD_EMAXPIVOTS, "cap 63 does not");
        /* the default cap (max(10000, 100 n)) lets n = 12 finish */
        CHECK(ctx, solve(&c, NULL, &info) == PD_OK && info.pivots == 4096, "default cap: %d pivots",
              info.pivots);
    }
    case_free(&s);
    case_free(&c);
}

static void test_lcp_cover_vector(pd_test_ctx *ctx)
{
    uint64_t rng = 0xc0e7;
    for (int rep = 0; rep < 20; rep++) {
        int n = 1 + rep % 10;
        lcp_case c = case_new(n);
        double d[10];
        if (!case_ok(&c)) {
            CHECK(ctx, 0, "out of memory");
            case_free(&c);
            return;
        }
        random_diag_dominant(&c, &rng);
        random_q(&c, &rng);
        for (int i = 0; i < n; i++)
            d[i] = 0.5 + 1.5 * (1.0 + pd_rand_pm1(&rng));
        pd_lcp_opts opts = pd_lcp_default_opts();
        opts.cover = d;
        pd_lcp_info info;
        CHECK(ctx, solve(&c, &opts, &info) == PD_OK, "cover: solved");
        check_verified(ctx, &c, "cover");
        double ze[10], we[10];
        pd_lcp_enumerate(n, c.M, c.q, ze, we);
        CHECK(ctx, max_diff(n, ze, c.z) <= 1e-10, "cover: same unique solution");
        case_free(&c);
    }
}

/* ---- the small problems' path and the fixed costs ----------------------------------- */

/* Both answers, to the bit: status, outcome, pivots, figures, z and w. */
static int same_answer(int n, int sa, const pd_lcp_info *a, const double *za, const double *wa,
                       int sb, const pd_lcp_info *b, const double *zb, const double *wb)
{
    return sa == sb && a->outcome == b->outcome && a->pivots == b->pivots &&
           !memcmp(&a->residual, &b->residual, sizeof(double)) &&
           !memcmp(&a->complementarity, &b->complementarity, sizeof(double)) &&
           !memcmp(&a->infeasibility, &b->infeasibility, sizeof(double)) &&
           !memcmp(&a->scale, &b->scale, sizeof(double)) &&
           !memcmp(za, zb, (size_t)n * sizeof(double)) &&
           !memcmp(wa, wb, (size_t)n * sizeof(double));
}

/* A covering vector given as all ones and the default (NULL, all ones without a
 * division by them: -q_i / 1 = -q_i, q_r / -1 = -q_r exactly) give the same
 * answers to the bit, on the vector path (n <= 4) and the general one, for
 * solved problems, rays and degenerate ones. */
static void test_lcp_unit_cover_same_bits(pd_test_ctx *ctx)
{
    uint64_t rng = 0xc07e;
    double ones[9] = {1, 1, 1, 1, 1, 1, 1, 1, 1};
    for (int rep = 0; rep < 400; rep++) {
        int n = 1 + rep % 9;
        lcp_case c = case_new(n);
        double *z2 = calloc((size_t)n, sizeof(double)), *w2 = calloc((size_t)n, sizeof(double));
        if (!case_ok(&c) || !z2 || !w2) {
            CHECK(ctx, 0, "out of memory");
            free(z2);
            free(w2);
            case_free(&c);
            return;
        }
        for (int k = 0; k < n * n; k++) /* integers: ties, singular blocks, rays */
            c.M[k] = rep % 2 ? (double)((int)(pd_rand_next(&rng) % 5) - 2) : pd_rand_pm1(&rng);
        for (int i = 0; i < n; i++)
            c.q[i] = rep % 3 ? pd_rand_pm1(&rng) : (double)((int)(pd_rand_next(&rng) % 3) - 1);
        pd_lcp_opts opts = pd_lcp_default_opts();
        opts.cover = ones;
        pd_lcp_info a, b;
        int sa = solve(&c, NULL, &a);
        int sb = solve(&(lcp_case){n, c.M, c.q, z2, w2}, &opts, &b);
        CHECK(ctx, same_answer(n, sa, &a, c.z, c.w, sb, &b, z2, w2),
              "rep %d, n = %d: cover NULL (status %d, %s, %d pivots) and ones (status %d, %s, %d "
              "pivots) differ",
              rep, n, sa, pd_lcp_outcome_name(a.outcome), a.pivots, sb,
              pd_lcp_outcome_name(b.outcome), b.pivots);
        free(z2);
        free(w2);
        case_free(&c);
    }
}

/* n = 1..4 (the vector path where the processor has AVX2), degenerate: M = I +
 * G G^T with G in {-2..1}^(n x 2) (a P-matrix), q with zeros, repeats and
 * entries of 1e-17 beside entries of order one: every answer solved,
 * verified and the enumeration's (unique); the same again from a workspace
 * sized for 40 that just solved a larger problem. */
static void test_lcp_small_degenerate_vs_enumeration(pd_test_ctx *ctx)
{
    uint64_t rng = 0x5a11;
    pd_lcp_work *big = pd_lcp_alloc(40);
    CHECK(ctx, big != NULL, "out of memory");
    for (int rep = 0; big && rep < 800; rep++) {
        int n = 1 + rep % 4, G[8];
        lcp_case c = case_new(n);
        double z2[4], w2[4], qs[5] = {-2.0, -1.0, 0.0, 1e-17, -1e-17};
        if (!case_ok(&c)) {
            CHECK(ctx, 0, "out of memory");
            case_free(&c);
            break;
        }
        for (int e = 0; e < 2 * n; e++)
            G[e] = (int)(pd_rand_next(&rng) % 4) - 2;
        for (int j = 0; j < n; j++) {
            for (int i = 0; i < n; i++)
                c.M[i + j * n] = G[2 * i] * G[2 * j] + G[2 * i + 1] * G[2 * j + 1] + (i == j);
            c.q[j] = qs[pd_rand_next(&rng) % 5];
        }
        pd_lcp_info a, b;
        check_against_enumeration(ctx, &c, "small degenerate");
        int sa = solve(&c, NULL, &a);
        lcp_case large = case_new(40);
        if (case_ok(&large)) {
            random_spd(&large, 3, &rng);
            random_q(&large, &rng);
            pd_lcp_lemke(big, 40, large.M, large.q, NULL, large.z, large.w, NULL);
        }
        case_free(&large);
        int sb = pd_lcp_lemke(big, n, c.M, c.q, NULL, z2, w2, &b);
        CHECK(ctx, same_answer(n, sa, &a, c.z, c.w, sb, &b, z2, w2),
              "rep %d, n = %d: a used workspace of 40 gives another answer", rep, n);
        case_free(&c);
    }
    pd_lcp_free(big);
}

/* n = 3, 4 (the vector path where the processor has AVX2) against the
 * general code on the same problem with one more row, decoupled (M = 1 on
 * its diagonal, 0 elsewhere; q = 1: its w = 1 + z0 stays basic, its z = 0):
 * the same pivots on the first n rows, the same operations in the same
 * order (the extra row adds only zero terms to them), so the same status,
 * pivots, z and w to the bit, on 400 random P-matrix problems (a wrong z
 * from the vector path that the polish or the repair would put right to
 * within the verification's tolerance is still another z). */
static void test_lcp_vector_path_same_bits(pd_test_ctx *ctx)
{
    uint64_t rng = 0x5ec70;
    int differ = 0;
    for (int rep = 0; rep < 400; rep++) {
        int n = 3 + rep % 2, n1 = n + 1;
        lcp_case c = case_new(n), e = case_new(n1);
        if (!case_ok(&c) || !case_ok(&e)) {
            CHECK(ctx, 0, "out of memory");
            case_free(&c);
            case_free(&e);
            return;
        }
        if (rep % 4 < 2)
            random_pd_skew(&c, 2, &rng);
        else
            random_diag_dominant(&c, &rng);
        random_q(&c, &rng);
        for (int j = 0; j < n; j++) {
            for (int i = 0; i < n; i++)
                e.M[i + j * n1] = c.M[i + j * n];
            e.q[j] = c.q[j];
        }
        e.M[n + n * n1] = 1.0;
        e.q[n] = 1.0;
        pd_lcp_info a, b;
        int sa = solve(&c, NULL, &a), sb = solve(&e, NULL, &b);
        int same = sa == PD_OK && sb == PD_OK && a.pivots == b.pivots && e.z[n] == 0.0 &&
                   !memcmp(c.z, e.z, (size_t)n * sizeof(double)) &&
                   !memcmp(c.w, e.w, (size_t)n * sizeof(double));
        if (!same && differ++ < 3)
            CHECK(ctx, 0, "rep %d, n = %d: status %d / %d, pivots %d / %d, z differs by %.3g", rep,
                  n, sa, sb, a.pivots, b.pivots, max_diff(n, c.z, e.z));
        case_free(&c);
        case_free(&e);
    }
    CHECK(ctx, differ == 0, "%d of 400 problems differ between the two paths", differ);
}

/* The last tie-break of the ratio test: rows still tied after every column
 * of the lexicographic rule leave by the largest pivot.  With tol 0.5 (the
 * ties and the rule's roundoff level half of their scale; any tol in
 * (0, 1) is allowed) rows of this degenerate n = 6 problem (integer M, q
 * with zeros, found among random ones) stay tied through every column, and
 * taking the first of them instead makes the pivots cycle to the cap
 * (10000).  Lemke answers in 17 pivots, verified independently (relative
 * residual <= 1e-10, pd_lcp_residual). */
static void test_lcp_final_tie_break(pd_test_ctx *ctx)
{
    static const double M[36] = {3, -1, -1, 0, 1, -1, -2, 2, 1, 2,  -1, 0,  -2, -1, 2, 1,  2, 1,
                                 1, -1, 2,  2, 1, -2, 0,  0, 1, -2, 2,  -2, -2, -2, 2, -1, 1, 3};
    static const double q[6] = {1, 0, -1, -1, 0, 1};
    double z[6], w[6], wr[6], comp = NAN, infeas = NAN, residual = NAN;
    pd_lcp_work *work = pd_lcp_alloc(6);
    pd_lcp_opts opts = pd_lcp_default_opts();
    pd_lcp_info info;
    opts.tol = 0.5;
    if (!CHECK(ctx, work != NULL, "out of memory"))
        return;
    int st = pd_lcp_lemke(work, 6, M, q, &opts, z, w, &info);
    pd_lcp_residual(6, M, q, z, wr, &comp, &infeas, &residual);
    CHECK(ctx,
          st == PD_OK && info.outcome == PD_LCP_SOLVED && info.pivots < 100 &&
              residual <= VERIFY_TOL,
          "status %d (%s) after %d pivots, relative residual %.3g", st,
          pd_lcp_outcome_name(info.outcome), info.pivots, residual);
    pd_lcp_free(work);
}

/* A NaN or an infinity anywhere in M or q is invalid input, whatever its
 * place (the scan of M runs in pairs with a tail): PD_EINVAL, outcome
 * numerical, z and w untouched. */
static void test_lcp_nonfinite_anywhere(pd_test_ctx *ctx)
{
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    pd_lcp_work *work = pd_lcp_alloc(7);
    double M[49], q[7], z[7], w[7];
    for (int n = 1; work && n <= 7; n++) {
        for (int k = 0; k < n * n + n; k++) {
            for (int b = 0; b < 3; b++) {
                for (int j = 0; j < n; j++) {
                    for (int i = 0; i < n; i++)
                        M[i + j * n] = i == j ? 2.0 : -0.5;
                    q[j] = -1.0;
                    z[j] = w[j] = 7.0;
                }
                if (k < n * n)
                    M[k] = bad[b];
                else
                    q[k - n * n] = bad[b];
                pd_lcp_info info;
                int st = pd_lcp_lemke(work, n, M, q, NULL, z, w, &info);
                int untouched = 1;
                for (int i = 0; i < n; i++)
                    untouched &= z[i] == 7.0 && w[i] == 7.0;
                CHECK(ctx, st == PD_EINVAL && info.outcome == PD_LCP_NUMERICAL && untouched,
                      "n = %d, entry %d = %g: status %d, outcome %s, z and w %s", n, k, bad[b], st,
                      pd_lcp_outcome_name(info.outcome), untouched ? "kept" : "written");
            }
        }
    }
    pd_lcp_free(work);
}

/* A solve allocates nothing: n = 1..6 and 40, solved, rays, a covering
 * vector, the closed forms, q >= 0. */
static void test_lcp_solve_allocates_nothing(pd_test_ctx *ctx)
{
    uint64_t rng = 0xa110c;
    pd_lcp_work *work = pd_lcp_alloc(40);
    lcp_case c = case_new(40);
    double d[40];
    if (!work || !case_ok(&c)) {
        CHECK(ctx, 0, "out of memory");
        pd_lcp_free(work);
        case_free(&c);
        return;
    }
    for (int i = 0; i < 40; i++)
        d[i] = 0.5 + i % 3;
    int sizes[] = {1, 2, 3, 4, 5, 6, 40};
    long before = pd_test_allocations();
    int solved = 0, rays = 0;
    for (int rep = 0; rep < 70; rep++) {
        int n = sizes[rep % 7];
        c.n = n;
        for (int k = 0; k < n * n; k++)
            c.M[k] = rep % 2 ? pd_rand_pm1(&rng) : (double)(k % (n + 1) == 0) + 0.1;
        random_q(&c, &rng);
        pd_lcp_opts opts = pd_lcp_default_opts();
        opts.cover = rep % 5 == 0 ? d : NULL;
        pd_lcp_info info;
        int st = pd_lcp_lemke(work, n, c.M, c.q, &opts, c.z, c.w, &info);
        solved += st == PD_OK;
        rays += st == PD_ENOSOLUTION;
    }
    long used = pd_test_allocations() - before;
    CHECK(ctx, used == 0, "%ld allocations in 70 solves (%d solved, %d rays)", used, solved, rays);
    CHECK(ctx, solved > 0 && rays > 0, "both outcomes met: %d solved, %d rays", solved, rays);
    pd_lcp_free(work);
    c.n = 40;
    case_free(&c);
}

/* n = 2, support {1}: the closed form's answer stands when w_2 < 0 is within
 * the verification's tolerance of its row (|w_2| / (|q_2| + |M_21 z_1|) <=
 * 1e-10), and gives way to the next support beyond it; 0 pivots either way. */
static void test_lcp_closed_form_within_tolerance(pd_test_ctx *ctx)
{
    double M[4] = {1.0, 1.0, 1.0, 1.0}, z[2], w[2];
    pd_lcp_work *work = pd_lcp_alloc(2);
    pd_lcp_info info;
    double q_in[2] = {-1.0, -1.0 - 1e-13}; /* w_2 = -1e-13, row size 2 */
    int st = pd_lcp_lemke(work, 2, M, q_in, NULL, z, w, &info);
    CHECK(ctx, st == PD_OK && info.pivots == 0 && z[0] == 1.0 && z[1] == 0.0 && w[1] < 0.0,
          "within: status %d, %d pivots, z = (%g, %g), w_2 = %g", st, info.pivots, z[0], z[1],
          w[1]);
    double q_out[2] = {-1.0, -1.0 - 1e-9}; /* w_2 = -1e-9: support {2} */
    st = pd_lcp_lemke(work, 2, M, q_out, NULL, z, w, &info);
    CHECK(ctx, st == PD_OK && info.pivots == 0 && z[0] == 0.0 && z[1] == 1.0 + 1e-9,
          "beyond: status %d, %d pivots, z = (%g, %.17g)", st, info.pivots, z[0], z[1]);
    pd_lcp_free(work);
}

/* ---- workspace, arguments ----------------------------------------------------------- */

static void test_lcp_workspace_reuse(pd_test_ctx *ctx)
{
    int sizes[] = {40, 3, 17, 1, 40, 25};
    uint64_t rng = 0x7e57;
    pd_lcp_work *shared = pd_lcp_alloc(40);
    CHECK(ctx, shared && pd_lcp_nmax(shared) == 40, "nmax = 40");
    for (size_t k = 0; shared && k < sizeof sizes / sizeof sizes[0]; k++) {
        int n = sizes[k];
        lcp_case c = case_new(n);
        double *z2 = calloc((size_t)n, sizeof(double)), *w2 = calloc((size_t)n, sizeof(double));
        if (case_ok(&c) && z2 && w2) {
            random_pd_skew(&c, 4, &rng);
            random_q(&c, &rng);
            pd_lcp_info a, b;
            int sa = pd_lcp_lemke(shared, n, c.M, c.q, NULL, z2, w2, &a);
            int sb = solve(&c, NULL, &b);
            CHECK(ctx, sa == PD_OK && sb == PD_OK, "n = %d: %d, %d", n, sa, sb);
            CHECK(ctx, a.pivots == b.pivots, "n = %d: pivots %d vs %d", n, a.pivots, b.pivots);
            CHECK(ctx, max_diff(n, z2, c.z) == 0.0, "n = %d: shared workspace gives the same z", n);
        } else {
            CHECK(ctx, 0, "out of memory");
        }
        free(z2);
        free(w2);
        case_free(&c);
    }
    pd_lcp_free(shared);
}

static void test_lcp_invalid_arguments(pd_test_ctx *ctx)
{
    double M[9] = {2, 0, 0, 0, 2, 0, 0, 0, 2}, q[3] = {-1, -1, -1}, z[3], w[3];
    pd_lcp_work *work = pd_lcp_alloc(2);
    pd_lcp_info info;
    CHECK(ctx, pd_lcp_alloc(0) == NULL && pd_lcp_alloc(-3) == NULL, "alloc(n <= 0) is NULL");
    CHECK(ctx, pd_lcp_nmax(work) == 2 && pd_lcp_nmax(NULL) == 0, "nmax");
    CHECK(ctx, pd_lcp_lemke(work, 3, M, q, NULL, z, w, &info) == PD_EINVAL, "n > nmax");
    CHECK(ctx, pd_lcp_lemke(work, 0, M, q, NULL, z, w, &info) == PD_EINVAL, "n = 0");
    CHECK(ctx, pd_lcp_lemke(NULL, 1, M, q, NULL, z, w, &info) == PD_EINVAL, "NULL workspace");
    CHECK(ctx, pd_lcp_lemke(work, 1, M, NULL, NULL, z, w, NULL) == PD_EINVAL, "NULL q");
    double bad_cover[2] = {1.0, 0.0};
    pd_lcp_opts opts = pd_lcp_default_opts();
    opts.cover = bad_cover;
    CHECK(ctx, pd_lcp_lemke(work, 2, M, q, &opts, z, w, &info) == PD_EINVAL, "cover with a 0");
    opts = pd_lcp_default_opts();
    opts.tol = 2.0;
    CHECK(ctx, pd_lcp_lemke(work, 2, M, q, &opts, z, w, &info) == PD_EINVAL, "tol >= 1");
    double Mnan[4] = {1.0, NAN, 0.0, 1.0}, qinf[2] = {-1.0, -INFINITY};
    CHECK(ctx, pd_lcp_lemke(work, 2, Mnan, q, NULL, z, w, &info) == PD_EINVAL, "NaN in M");
    CHECK(ctx, pd_lcp_lemke(work, 2, M, qinf, NULL, z, w, &info) == PD_EINVAL, "inf in q");
    CHECK(ctx, pd_lcp_enumerate(13, M, q, z, w) == PD_EINVAL, "enumerate n = 13");
    pd_lcp_free(work);
    pd_lcp_free(NULL);
}

static void test_lcp_outcome_names(pd_test_ctx *ctx)
{
    CHECK(ctx, !strcmp(pd_lcp_outcome_name(PD_LCP_SOLVED), "solved"), "solved");
    CHECK(ctx, !strcmp(pd_lcp_outcome_name(PD_LCP_NO_SOLUTION), "no_solution"), "no_solution");
    CHECK(ctx, !strcmp(pd_lcp_outcome_name(PD_LCP_MAX_PIVOTS), "max_pivots"), "max_pivots");
    CHECK(ctx, !strcmp(pd_lcp_outcome_name(PD_LCP_NUMERICAL), "numerical"), "numerical");
}

static void test_lcp_residual_figures(pd_test_ctx *ctx)
{
    /* M = [2 -1; 0 3] (column-major {2, 0, -1, 3}), q = (1, -4), z = (0.5, 1):
     * w = (1, -1), row sizes r = (1 + 1 + 1, 4 + 0 + 3) = (3, 7), zs = 1 */
    double M[4] = {2, 0, -1, 3}, q[2] = {1, -4}, z[2] = {0.5, 1}, w[2];
    double comp, infeas, residual;
    pd_lcp_residual(2, M, q, z, w, &comp, &infeas, &residual);
    CHECK_NEAR(ctx, w[0], 1.0, 0.0);   /* 2 * 0.5 - 1 + 1 */
    CHECK_NEAR(ctx, w[1], -1.0, 0.0);  /* 3 - 4 */
    CHECK_NEAR(ctx, comp, 1.0, 0.0);   /* max(0.5 * 1, 1 * 1) */
    CHECK_NEAR(ctx, infeas, 1.0, 0.0); /* -w2 */
    /* max(min(1/3, 0.5/1), min(1/7, 1), -w2/r2 = 1/7) = 1/3 */
    CHECK_NEAR(ctx, residual, 1.0 / 3.0, 1e-16);
    /* invariant: q and z scaled by 1e9, or M by 1e-7 with z by 1e7 */
    double q9[2] = {1e9, -4e9}, z9[2] = {0.5e9, 1e9}, M7[4] = {2e-7, 0, -1e-7, 3e-7};
    double z7[2] = {0.5e7, 1e7}, r9, r7;
    pd_lcp_residual(2, M, q9, z9, w, &comp, &infeas, &r9);
    pd_lcp_residual(2, M7, q, z7, w, &comp, &infeas, &r7);
    CHECK(ctx, fabs(r9 - residual) <= 1e-15 && fabs(r7 - residual) <= 1e-15,
          "scaled residuals %.17g, %.17g vs %.17g", r9, r7, residual);
}

/* A candidate with an infinity or a NaN is no answer: its residual is NaN,
 * above every tolerance (z = (0, inf, 0) on the extreme problem of
 * test_solvers_nonfinite_never_solved had residual 0: inf / inf). */
static void test_lcp_residual_nonfinite(pd_test_ctx *ctx)
{
    double M[9] = {4e-300, 1e-300, 0.0, 1e-300, 4e-300, 1e-300, 0.0, 1e-300, 4e-300};
    double q[3] = {-1e300, -2e300, 3e300}, w[3], comp, infeas, residual;
    double zs[3][3] = {{0.0, INFINITY, 0.0}, {0.0, NAN, 0.0}, {-INFINITY, 0.0, 0.0}};
    for (int k = 0; k < 3; k++) {
        pd_lcp_residual(3, M, q, zs[k], w, &comp, &infeas, &residual);
        CHECK(ctx, isnan(residual) && !(residual <= VERIFY_TOL),
              "z = (%g, %g, %g): residual %g must be NaN", zs[k][0], zs[k][1], zs[k][2], residual);
    }
    /* a finite candidate keeps a finite residual */
    double z0[3] = {0.0, 0.0, 0.0};
    pd_lcp_residual(3, M, q, z0, w, &comp, &infeas, &residual);
    CHECK(ctx, residual == 1.0, "z = 0: residual %g (w_1 = -1e300 < 0)", residual);
}

/* Binary input: 3 GB of zeros (a sparse file) refused at its first byte
 * (/dev/zero took 2 GB before; it is not a regular file now, refused
 * unread), a NUL byte named by its line; the size n followed by a mere
 * stream of tokens is refused by the count, naming the end of the file. */
static void test_lcp_read_bounded(pd_test_ctx *ctx)
{
    int n = 5;
    double *M = NULL, *q = NULL;
    pd_err err;
    char zero[64], want[128];
    int st = pd_lcp_read("/dev/zero", PD_LCP_FORMAT_AUTO, &n, &M, &q, &err);
    CHECK(ctx,
          st == PD_EINVAL && strstr(err.msg, "/dev/zero: not a regular file") && n == 0 && !M && !q,
          "/dev/zero: %d %s", st, err.msg);
    if (CHECK(ctx, pd_test_zero_file(zero, sizeof zero, 3LL << 30) == 0, "a sparse file")) {
        n = 5;
        st = pd_lcp_read(zero, PD_LCP_FORMAT_AUTO, &n, &M, &q, &err);
        snprintf(want, sizeof want, "%s: line 1: not a text file (a NUL", zero);
        CHECK(ctx, st == PD_EPARSE && strstr(err.msg, want) && n == 0 && !M && !q,
              "3 GB of zeros: %d %s", st, err.msg);
        unlink(zero);
    }
    char path[64];
    strcpy(path, "/tmp/pound_lcp_XXXXXX");
    int fd = mkstemp(path);
    static const char nul[] = "2\n1 0\n0 1\0\n-1 -1\n";
    if (!CHECK(ctx, fd >= 0 && write(fd, nul, sizeof nul - 1) == (ssize_t)(sizeof nul - 1),
               "temporary file"))
        return;
    close(fd);
    st = pd_lcp_read(path, PD_LCP_FORMAT_AUTO, &n, &M, &q, &err);
    CHECK(ctx,
          st == PD_EPARSE && strstr(err.msg, path) &&
              strstr(err.msg, ": line 3: not a text file (a NUL byte)"),
          "NUL: %d %s", st, err.msg);
    remove(path);
    /* n = 46340, then 10^5 ones on 1000 lines */
    size_t cap = 10 + 200000 + 1000;
    char *text = malloc(cap), *p = text;
    if (!CHECK(ctx, text != NULL, "malloc"))
        return;
    p += sprintf(p, "46340\n");
    for (int line = 0; line < 1000; line++) {
        for (int k = 0; k < 100; k++)
            p += sprintf(p, k ? " 1" : "1");
        *p++ = '\n';
    }
    *p = '\0';
    st = read_text(text, PD_LCP_FORMAT_AUTO, &n, &M, &q, &err);
    CHECK(ctx,
          st == PD_EPARSE && strstr(err.msg, "line 1001: too few values: the file ends "
                                             "after 100000 of the 2147441940 numbers"),
          "stream: %d %s", st, err.msg);
    free(text);
}

static void test_lcp_enumerate_oracle(pd_test_ctx *ctx)
{
    /* deudeu: M = [2 1; 1 2], q = (-5, -6): z = (4/3, 7/3) */
    double M[4] = {2, 1, 1, 2}, q[2] = {-5, -6}, z[2], w[2];
    CHECK(ctx, pd_lcp_enumerate(2, M, q, z, w) == PD_OK, "deudeu solved");
    CHECK_NEAR(ctx, z[0], 4.0 / 3.0, 1e-15);
    CHECK_NEAR(ctx, z[1], 7.0 / 3.0, 1e-15);
    /* M = [1 -1; -1 1] (CPS_5), q = (1, -1): smallest support first, z = (0, 1) */
    double M5[4] = {1, -1, -1, 1}, q5[2] = {1, -1};
    CHECK(ctx, pd_lcp_enumerate(2, M5, q5, z, w) == PD_OK, "CPS_5 solved");
    CHECK_NEAR(ctx, z[0], 0.0, 0.0);
    CHECK_NEAR(ctx, z[1], 1.0, 1e-15);
}

/* ---- readers ------------------------------------------------------------------------- */

static void test_lcp_read_plain(pd_test_ctx *ctx)
{
    const char *text = "# a 2 x 2 LCP\r\n"
                       "2   # size\r\n"
                       "\r\n"
                       "1 2\t# row 1\r\n"
                       "3 4e0\r\n"
                       "-5 6.5#q\r\n";
    int n = 0;
    double *M = NULL, *q = NULL;
    pd_err err;
    int st = read_text(text, PD_LCP_FORMAT_PLAIN, &n, &M, &q, &err);
    CHECK(ctx, st == PD_OK, "plain: %s", err.msg);
    if (st == PD_OK) {
        CHECK(ctx, n == 2, "n = %d", n);
        CHECK_NEAR(ctx, M[0], 1.0, 0.0); /* row by row in the file, column-major in memory */
        CHECK_NEAR(ctx, M[1], 3.0, 0.0);
        CHECK_NEAR(ctx, M[2], 2.0, 0.0);
        CHECK_NEAR(ctx, M[3], 4.0, 0.0);
        CHECK_NEAR(ctx, q[0], -5.0, 0.0);
        CHECK_NEAR(ctx, q[1], 6.5, 0.0);
    }
    free(M);
    free(q);
    /* auto-detection keeps it plain */
    st = read_text(text, PD_LCP_FORMAT_AUTO, &n, &M, &q, &err);
    CHECK(ctx, st == PD_OK && n == 2 && M[2] == 2.0, "auto: plain (%s)", err.msg);
    free(M);
    free(q);
}

static void test_lcp_read_siconos(pd_test_ctx *ctx)
{
    const char *text = "2\r\n0\r\n2\r\n2\r\n2\t2\r\n"
                       "1 3\r\n" /* column 1 */
                       "2 4\r\n" /* column 2 */
                       "-5 6.5\r\n"
                       "\r\nExample 4.4.16 CPS 2009: 12 words of free text, 3.5 numbers\r\n";
    for (int fmt = 0; fmt < 2; fmt++) {
        int n = 0;
        double *M = NULL, *q = NULL;
        pd_err err;
        pd_lcp_format format = fmt ? PD_LCP_FORMAT_SICONOS : PD_LCP_FORMAT_AUTO;
        int st = read_text(text, format, &n, &M, &q, &err);
        CHECK(ctx, st == PD_OK, "siconos (%s): %s", fmt ? "explicit" : "auto", err.msg);
        if (st == PD_OK) {
            CHECK(ctx, n == 2, "n = %d", n);
            CHECK_NEAR(ctx, M[0], 1.0, 0.0);
            CHECK_NEAR(ctx, M[1], 3.0, 0.0);
            CHECK_NEAR(ctx, M[2], 2.0, 0.0);
            CHECK_NEAR(ctx, M[3], 4.0, 0.0);
            CHECK_NEAR(ctx, q[1], 6.5, 0.0);
        }
        free(M);
        free(q);
    }
    /* n = 1, no newline at the end */
    int n = 0;
    double *M = NULL, *q = NULL;
    pd_err err;
    int st = read_text("1\n0\n1\n1\n1 1\n2\n-3", PD_LCP_FORMAT_AUTO, &n, &M, &q, &err);
    CHECK(ctx, st == PD_OK && n == 1 && M[0] == 2.0 && q[0] == -3.0, "siconos n = 1: %s", err.msg);
    free(M);
    free(q);
}

/* A malformed text: PD_EPARSE and a message that holds `needle`. */
static void check_malformed(pd_test_ctx *ctx, const char *text, pd_lcp_format format,
                            const char *needle)
{
    int n = 5;
    double *M = NULL, *q = NULL;
    pd_err err;
    int st = read_text(text, format, &n, &M, &q, &err);
    CHECK(ctx, st == PD_EPARSE, "status %d for %.30s...", st, text);
    CHECK(ctx, strstr(err.msg, needle) != NULL, "message '%s' lacks '%s'", err.msg, needle);
    CHECK(ctx, M == NULL && q == NULL && n == 0, "nothing returned on error");
}

static void test_lcp_read_malformed(pd_test_ctx *ctx)
{
    check_malformed(ctx, "2\n1 2\n3 x\n-1 -1\n", PD_LCP_FORMAT_PLAIN, "line 3: matrix entry: 'x'");
    check_malformed(ctx, "2\n1 2\n3 4\n-1\n", PD_LCP_FORMAT_PLAIN, "line 4: too few values");
    check_malformed(ctx, "# size\n0\n", PD_LCP_FORMAT_PLAIN, "line 2: the size n must be");
    check_malformed(ctx, "-3\n", PD_LCP_FORMAT_AUTO, "line 1: the size n must be");
    check_malformed(ctx, "2.5\n1\n", PD_LCP_FORMAT_PLAIN, "line 1");
    check_malformed(ctx, "1\n\n\nnan\n-1\n", PD_LCP_FORMAT_PLAIN,
                    "line 4: matrix entry: 'nan' is not a finite");
    check_malformed(ctx, "1\n2\ninf\n", PD_LCP_FORMAT_PLAIN, "line 3: entry of q");
    check_malformed(ctx, "1\n2\n-1\n7\n", PD_LCP_FORMAT_PLAIN, "line 4: unexpected value '7'");
    check_malformed(ctx, "", PD_LCP_FORMAT_AUTO, "line 1: empty file");
    check_malformed(ctx, "# nothing\n\n", PD_LCP_FORMAT_PLAIN, "line 2: empty file");
    check_malformed(ctx, "2\n1\n2\n2\n2 2\n1 0 0 1 -1 -1\n", PD_LCP_FORMAT_SICONOS,
                    "line 2: storage '1' is not supported");
    check_malformed(ctx, "2\n0\n2\n3\n2 3\n1 0 0 1 -1 -1\n", PD_LCP_FORMAT_SICONOS,
                    "line 4: matrix dimension '3'");
    check_malformed(ctx, "2\n0\n2\n2\n2 2\n1 0 0 1\n-1\n", PD_LCP_FORMAT_SICONOS,
                    "line 7: too few values");
    check_malformed(ctx, "3\n0\n3\n3\n3 3\n1 0 0\n0 1 0\n0 0 1e999\n-1 -1 -1\n", PD_LCP_FORMAT_AUTO,
                    "line 8: matrix entry: '1e999' is not a finite");
    int n = 0;
    double *M = NULL, *q = NULL;
    pd_err err;
    int st = pd_lcp_read("/nonexistent/pound.lcp", PD_LCP_FORMAT_AUTO, &n, &M, &q, &err);
    CHECK(ctx, st == PD_EIO, "missing file: status %d, expected PD_EIO", st);
    CHECK(ctx, strstr(err.msg, "/nonexistent/pound.lcp") != NULL, "message names the file: %s",
          err.msg);
}

static void test_lcp_example_file(pd_test_ctx *ctx)
{
    int n = 0;
    double *M = NULL, *q = NULL;
    pd_err err;
    if (access("examples/murty1978.lcp", R_OK) != 0) {
        pd_test_skip(ctx, "examples/murty1978.lcp not found (run from the project root)");
        return;
    }
    int st = pd_lcp_read("examples/murty1978.lcp", PD_LCP_FORMAT_AUTO, &n, &M, &q, &err);
    CHECK(ctx, st == PD_OK && n == 4, "example: %s", err.msg);
    if (st == PD_OK && n == 4) {
        lcp_case c = {n, M, q, calloc(4, sizeof(double)), calloc(4, sizeof(double))};
        pd_lcp_info info;
        CHECK(ctx, case_ok(&c) && solve(&c, NULL, &info) == PD_OK, "example solved");
        for (int i = 0; case_ok(&c) && i < n; i++)
            CHECK_NEAR(ctx, c.z[i], i == 0 ? 1.0 : 0.0, 1e-15);
        free(c.z);
        free(c.w);
    }
    free(M);
    free(q);
}

/* ---- the command line ----------------------------------------------------------------- */

/* Run a shell command; its exit status, its stdout in out. */
static int run_capture(const char *cmd, char *out, size_t size)
{
    FILE *p = popen(cmd, "r");
    if (!p)
        return -1;
    size_t len = fread(out, 1, size - 1, p);
    out[len] = '\0';
    int status = pclose(p);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static void test_lcp_cli(pd_test_ctx *ctx)
{
    if (access(ctx->pound, X_OK) != 0) {
        pd_test_skip(ctx, "no pound binary");
        return;
    }
    char solvable[64], three[64], ray[64], bad[64], cmd[512], out[4096];
    if (write_temp(solvable, "2\n2 1\n1 2\n-5 -6\n") || write_temp(ray, "1\n-1\n-2\n") ||
        write_temp(bad, "2\n1 2\n3 oops\n-1 -1\n") ||
        write_temp(three, "3\n2 1 0\n1 2 1\n0 1 2\n-5 -6 -4\n")) {
        CHECK(ctx, 0, "temporary files");
        return;
    }
    snprintf(cmd, sizeof cmd, "%s lcp --json %s", ctx->pound, solvable);
    CHECK(ctx, run_capture(cmd, out, sizeof out) == 0, "solved: exit 0");
    CHECK(ctx, strstr(out, "\"status\":\"solved\"") && strstr(out, "\"z\":[1.3333333333333333,"),
          "solved JSON: %s", out);
    CHECK(ctx,
          strstr(out, "\"pivots\":0") && strstr(out, "\"cpu_s\":") &&
              strstr(out, "\"complementarity\":") && strstr(out, "\"w\":["),
          "JSON keys: %s", out);
    snprintf(cmd, sizeof cmd, "%s lcp %s --json", ctx->pound, ray);
    CHECK(ctx, run_capture(cmd, out, sizeof out) == 1, "ray: exit 1");
    CHECK(ctx, strstr(out, "\"status\":\"no_solution\"") != NULL, "ray JSON: %s", out);
    snprintf(cmd, sizeof cmd, "%s lcp %s --json 2>&1", ctx->pound, bad);
    CHECK(ctx, run_capture(cmd, out, sizeof out) == 2, "malformed: exit 2");
    int lines = 0;
    for (const char *c = out; *c; c++)
        lines += *c == '\n';
    CHECK(ctx, strstr(out, "line 3") && strstr(out, bad) && lines == 1,
          "one line naming file and line: %s", out);
    snprintf(cmd, sizeof cmd, "%s lcp %s --max-pivots 1 --json", ctx->pound, three);
    CHECK(ctx, run_capture(cmd, out, sizeof out) == 1 && strstr(out, "\"status\":\"max_pivots\""),
          "cap: %s", out);
    snprintf(cmd, sizeof cmd, "%s lcp %s --frobnicate 2>/dev/null", ctx->pound, solvable);
    CHECK(ctx, run_capture(cmd, out, sizeof out) == 2, "bad flag: exit 2");
    snprintf(cmd, sizeof cmd, "%s lcp %s --cover 1,2 --format plain", ctx->pound, solvable);
    CHECK(ctx, run_capture(cmd, out, sizeof out) == 0 && strstr(out, "solved"), "cover: %s", out);
    remove(solvable);
    remove(three);
    remove(ray);
    remove(bad);
}

/* The plain file of the n x n tridiagonal (lo, 2, up) with q = -e_1, and
 * with far != 0 the entries M_0,n-1 = M_n-1,0 = far, into path. */
static int write_tridiagonal(char *path, int n, double lo, double up, double far)
{
    static char text[4 * 300 * 300 + 4096];
    size_t at = (size_t)snprintf(text, sizeof text, "%d\n", n);
    for (int i = 0; i < n && at < sizeof text; i++)
        for (int j = 0; j < n && at < sizeof text; j++) {
            double x = i == j                                             ? 2.0
                       : j == i - 1                                       ? lo
                       : j == i + 1                                       ? up
                       : (i == 0 && j == n - 1) || (i == n - 1 && j == 0) ? far
                                                                          : 0.0;
            at += (size_t)snprintf(text + at, sizeof text - at, "%g%c", x, j + 1 < n ? ' ' : '\n');
        }
    for (int i = 0; i < n && at < sizeof text; i++)
        at += (size_t)snprintf(text + at, sizeof text - at, "%d%c", i == 0 ? -1 : 0,
                               i + 1 < n ? ' ' : '\n');
    return at < sizeof text ? write_temp(path, text) : -1;
}

/* `pound lcp --solver structured` on a band given densely (a chain of 300,
 * an impact q = -e_1): the band noted while reading, solved in compressed
 * columns by the direct method (1 iteration, verified); with one pair of
 * far entries not taken for banded (the general method, more iterations,
 * solved); a nonsymmetric band that the structured solver cannot finish
 * solved again densely, where the hand-over to Lemke takes it (n = 300 is
 * above the sparse hand-over's 256). */
static void test_lcp_cli_band(pd_test_ctx *ctx)
{
    if (access(ctx->pound, X_OK) != 0) {
        pd_test_skip(ctx, "no pound binary");
        return;
    }
    char chain[64], far[64], skew[64], cmd[512];
    static char out[1 << 16];
    if (write_tridiagonal(chain, 300, -1.0, -1.0, 0.0) ||
        write_tridiagonal(far, 300, -1.0, -1.0, -1e-3) ||
        write_tridiagonal(skew, 300, -1.5, -0.25, 0.0)) {
        CHECK(ctx, 0, "temporary files");
        return;
    }
    snprintf(cmd, sizeof cmd, "%s lcp %s --solver structured --json", ctx->pound, chain);
    CHECK(ctx,
          run_capture(cmd, out, sizeof out) == 0 && strstr(out, "\"status\":\"solved\"") &&
              strstr(out, "\"solver\":\"structured\"") && strstr(out, "\"iterations\":1,"),
          "chain: %.200s", out);
    snprintf(cmd, sizeof cmd, "%s lcp %s --solver structured --json", ctx->pound, far);
    CHECK(ctx,
          run_capture(cmd, out, sizeof out) == 0 && strstr(out, "\"status\":\"solved\"") &&
              strstr(out, "\"solver\":\"structured\"") && !strstr(out, "\"iterations\":1,"),
          "far entry: %.200s", out);
    snprintf(cmd, sizeof cmd, "%s lcp %s --solver structured --json", ctx->pound, skew);
    CHECK(ctx,
          run_capture(cmd, out, sizeof out) == 0 && strstr(out, "\"status\":\"solved\"") &&
              strstr(out, "\"solver\":\"lemke (after structured)\""),
          "nonsymmetric band: %.200s", out);
    remove(chain);
    remove(far);
    remove(skew);
}

void suite_lcp(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_lcp_siconos_outcomes);
    PD_RUN(ctx, test_lcp_siconos_murty2_pivots);
    PD_RUN(ctx, test_lcp_murty_exponential_pivots);
    PD_RUN(ctx, test_lcp_murty_1978);
    PD_RUN(ctx, test_lcp_fathi_1979);
    PD_RUN(ctx, test_lcp_q_nonnegative);
    PD_RUN(ctx, test_lcp_scalar_signs);
    PD_RUN(ctx, test_lcp_random_spd_vs_enumeration);
    PD_RUN(ctx, test_lcp_random_diag_dominant_vs_enumeration);
    PD_RUN(ctx, test_lcp_random_pd_skew_vs_enumeration);
    PD_RUN(ctx, test_lcp_random_large_spd);
    PD_RUN(ctx, test_lcp_random_large_nonsymmetric);
    PD_RUN(ctx, test_lcp_random_psd_solvable_iff_enumeration);
    PD_RUN(ctx, test_lcp_degenerate_cyclic);
    PD_RUN(ctx, test_lcp_degenerate_repeated_q);
    PD_RUN(ctx, test_lcp_degenerate_integer_random);
    PD_RUN(ctx, test_lcp_ray_copositive_plus);
    PD_RUN(ctx, test_lcp_small_pivot_is_not_a_ray);
    PD_RUN(ctx, test_lcp_numerical_outcome);
    PD_RUN(ctx, test_lcp_max_pivots);
    PD_RUN(ctx, test_lcp_cover_vector);
    PD_RUN(ctx, test_lcp_unit_cover_same_bits);
    PD_RUN(ctx, test_lcp_small_degenerate_vs_enumeration);
    PD_RUN(ctx, test_lcp_vector_path_same_bits);
    PD_RUN(ctx, test_lcp_final_tie_break);
    PD_RUN(ctx, test_lcp_nonfinite_anywhere);
    PD_RUN(ctx, test_lcp_solve_allocates_nothing);
    PD_RUN(ctx, test_lcp_closed_form_within_tolerance);
    PD_RUN(ctx, test_lcp_workspace_reuse);
    PD_RUN(ctx, test_lcp_invalid_arguments);
    PD_RUN(ctx, test_lcp_outcome_names);
    PD_RUN(ctx, test_lcp_residual_figures);
    PD_RUN(ctx, test_lcp_residual_nonfinite);
    PD_RUN(ctx, test_lcp_read_bounded);
    PD_RUN(ctx, test_lcp_enumerate_oracle);
    PD_RUN(ctx, test_lcp_read_plain);
    PD_RUN(ctx, test_lcp_read_siconos);
    PD_RUN(ctx, test_lcp_read_malformed);
    PD_RUN(ctx, test_lcp_read_band);
    PD_RUN(ctx, test_lcp_example_file);
    PD_RUN(ctx, test_lcp_cli);
    PD_RUN(ctx, test_lcp_cli_band);
}
