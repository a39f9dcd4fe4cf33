/* test_solvers.c — the LCP solver table: the structured solver and PGS
 * against the enumeration oracle and Lemke, the closed forms of n <= 2,
 * warm starts, degenerate Delassus matrices and non-convergence reported
 * with their status, chains of 2 x 10^4 contacts, dumps re-solved by every
 * solver, and the engine's answers independent of the solver. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pd_problems.h"
#include "pd_test.h"

/* A deterministic uniform number in [-1, 1). */
static double rnd(uint64_t *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / (double)(1ULL << 52) - 1.0;
}

/* M = A^T A + n I / 4 (SPD, column-major) and q, from a seed. */
static void random_spd(int n, uint64_t seed, double *M, double *q)
{
    double A[144];
    uint64_t s = seed;
    for (int k = 0; k < n * n; k++)
        A[k] = rnd(&s);
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double x = i == j ? 0.25 * n : 0.0;
            for (int k = 0; k < n; k++)
                x += A[k + i * n] * A[k + j * n];
            M[i + j * n] = x;
        }
    for (int i = 0; i < n; i++)
        q[i] = 2.0 * rnd(&s);
}

/* Solve with a method; the status. */
static int solve_with(pd_lcp_method m, const pd_matrix *M, const double *q,
                      const pd_lcp_opts *o, double *z, double *w, pd_lcp_info *info)
{
    pd_err e;
    long nnz = M->kind == PD_MATRIX_CSC ? M->colptr[M->cols] : 0;
    pd_lcp_solver *s = pd_lcp_solver_alloc(m, M->rows, nnz, &e);
    if (!s)
        return PD_ENOMEM;
    int rc = pd_lcp_solve(s, M, q, o, z, w, info);
    pd_lcp_solver_free(s);
    return rc;
}

/* Random SPD problems, n = 1..10: structured, PGS and auto give the
 * oracle's unique solution (1e-9) and verify. */
static void test_solvers_match_oracle(pd_test_ctx *ctx)
{
    const pd_lcp_method methods[] = {PD_LCP_STRUCTURED, PD_LCP_PGS, PD_LCP_AUTO, PD_LCP_LEMKE};
    int cases = 0;
    for (int n = 1; n <= 10; n++)
        for (uint64_t seed = 1; seed <= 20; seed++) {
            double M[100], q[10], zo[10], wo[10], z[10], w[10];
            random_spd(n, seed * 977 + (uint64_t)n, M, q);
            pd_matrix Mv = pd_matrix_dense(n, n, M);
            if (!CHECK(ctx, pd_lcp_enumerate(n, M, q, zo, wo) == PD_OK, "oracle n %d", n))
                continue;
            cases++;
            for (int k = 0; k < 4; k++) {
                pd_lcp_info info;
                int st = solve_with(methods[k], &Mv, q, NULL, z, w, &info);
                double d = 0.0, s = 0.0;
                for (int i = 0; i < n; i++) {
                    d = fmax(d, fabs(z[i] - zo[i]));
                    s = fmax(s, fabs(zo[i]));
                }
                CHECK(ctx, st == PD_OK && info.residual <= 1e-10 && d <= 1e-9 * fmax(s, 1e-300),
                      "%s, n %d seed %llu: status %d (%s), residual %.3g, |z - z_oracle| %.3g",
                      pd_lcp_method_name(methods[k]), n, (unsigned long long)seed, st,
                      info.solver, info.residual, d);
            }
        }
    CHECK(ctx, cases == 200, "%d cases", cases);
}

/* M = B^T B + I / 4 with B upper triangular of `band` + 1 diagonals (so M
 * has bandwidth `band`, off-diagonal entries of both signs) in compressed
 * columns, and q, from a seed. */
static int banded_spd(int n, int band, uint64_t seed, int *colptr, int *rowind, double *values,
                      double *dense, double *q)
{
    double B[100] = {0};
    uint64_t s = seed;
    for (int j = 0; j < n; j++)
        for (int i = j - band > 0 ? j - band : 0; i <= j; i++)
            B[i + j * n] = rnd(&s);
    int k = 0;
    for (int j = 0; j < n; j++) {
        colptr[j] = k;
        for (int i = 0; i < n; i++) {
            double x = i == j ? 0.25 : 0.0;
            for (int r = 0; r < n; r++)
                x += B[r + i * n] * B[r + j * n];
            dense[i + j * n] = abs(i - j) <= band ? x : 0.0;
            if (abs(i - j) <= band) {
                rowind[k] = i;
                values[k++] = x;
            }
        }
        q[j] = 2.0 * rnd(&s);
    }
    colptr[n] = k;
    return k;
}

/* Banded SPD problems in compressed columns, n = 1..10, bandwidth 1
 * (the twisted factorisation of tridiagonal blocks, odd and even sizes)
 * and 2 (the envelope): the structured solver gives the oracle's solution,
 * itself, not through Lemke. */
static void test_solvers_banded_oracle(pd_test_ctx *ctx)
{
    int cases = 0;
    for (int band = 1; band <= 2; band++)
        for (int n = 1; n <= 10; n++)
            for (uint64_t seed = 1; seed <= 20; seed++) {
                int colptr[11], rowind[100];
                double values[100], dense[100], q[10], zo[10], wo[10], z[10], w[10];
                banded_spd(n, band, seed * 131 + (uint64_t)(n + 17 * band), colptr, rowind,
                           values, dense, q);
                pd_matrix M = pd_matrix_csc(n, n, colptr, rowind, values);
                if (!CHECK(ctx, pd_lcp_enumerate(n, dense, q, zo, wo) == PD_OK, "oracle n %d", n))
                    continue;
                cases++;
                pd_lcp_info info;
                int st = solve_with(PD_LCP_STRUCTURED, &M, q, NULL, z, w, &info);
                double d = 0.0, zs = 0.0;
                for (int i = 0; i < n; i++) {
                    d = fmax(d, fabs(z[i] - zo[i]));
                    zs = fmax(zs, fabs(zo[i]));
                }
                CHECK(ctx, st == PD_OK && !strcmp(info.solver, "structured") && d <= 1e-9 * fmax(zs, 1e-300),
                      "band %d, n %d seed %llu: status %d (%s), |z - z_oracle| %.3g", band, n,
                      (unsigned long long)seed, st, info.solver, d);
            }
    CHECK(ctx, cases == 400, "%d cases", cases);
}

/* n <= 2: Lemke answers by the closed forms (no pivot) what its pivoting
 * and the oracle answer, on P-matrices of both signs of the off-diagonal. */
static void test_solvers_closed_forms(pd_test_ctx *ctx)
{
    uint64_t s = 42;
    pd_lcp_work *work = pd_lcp_alloc(2);
    for (int k = 0; k < 400 && work; k++) {
        int n = 1 + k % 2;
        double M[4] = {1.0 + fabs(rnd(&s)), rnd(&s), rnd(&s), 1.0 + fabs(rnd(&s))};
        if (n == 1)
            M[1] = M[2] = M[3] = 0.0;
        double Md[4] = {M[0], M[1], M[2], M[3]}, q[2] = {rnd(&s), rnd(&s)}, z[2], w[2], zo[2],
               wo[2];
        if (n == 1)
            Md[1] = M[3];
        pd_lcp_info info;
        int st = pd_lcp_lemke(work, n, n == 1 ? M : Md, q, NULL, z, w, &info);
        int so = pd_lcp_enumerate(n, n == 1 ? M : Md, q, zo, wo);
        if (so != PD_OK) /* M[1] M[2] >= M[0] M[3] can leave no solution */
            continue;
        CHECK(ctx, st == PD_OK && info.pivots == 0 && fabs(z[0] - zo[0]) <= 1e-14 * (1 + fabs(zo[0])) &&
                       fabs(z[n - 1] - zo[n - 1]) <= 1e-14 * (1 + fabs(zo[n - 1])),
              "n %d case %d: status %d, %d pivots, z (%g, %g) vs (%g, %g)", n, k, st, info.pivots,
              z[0], z[n - 1], zo[0], zo[n - 1]);
    }
    pd_lcp_free(work);
}

/* A tridiagonal Stieltjes chain (2 on the diagonal, -1 beside it) in
 * compressed columns with q in [-1, 1). */
typedef struct chain {
    int n;
    int *colptr, *rowind;
    double *values, *q, *z, *w;
} chain;

static int chain_make(chain *c, int n, uint64_t seed)
{
    c->n = n;
    c->colptr = malloc((size_t)(n + 1) * sizeof(int));
    c->rowind = malloc((size_t)(3 * n) * sizeof(int));
    c->values = malloc((size_t)(3 * n) * sizeof(double));
    c->q = malloc((size_t)n * sizeof(double));
    c->z = malloc((size_t)n * sizeof(double));
    c->w = malloc((size_t)n * sizeof(double));
    if (!c->colptr || !c->rowind || !c->values || !c->q || !c->z || !c->w)
        return -1;
    int k = 0;
    uint64_t s = seed;
    for (int j = 0; j < n; j++) {
        c->colptr[j] = k;
        for (int i = j - 1; i <= j + 1; i++)
            if (i >= 0 && i < n) {
                c->rowind[k] = i;
                c->values[k++] = i == j ? 2.0 : -1.0;
            }
        c->q[j] = rnd(&s);
    }
    c->colptr[n] = k;
    return 0;
}

static void chain_free(chain *c)
{
    free(c->colptr);
    free(c->rowind);
    free(c->values);
    free(c->q);
    free(c->z);
    free(c->w);
}

/* Chains of 500 (against Lemke) and 20000 contacts: the structured solver
 * verifies, agrees with Lemke, and a correct warm start ends in one solve. */
static void test_solvers_chains(pd_test_ctx *ctx)
{
    const int sizes[] = {500, 20000};
    for (int k = 0; k < 2; k++) {
        chain c;
        if (!CHECK(ctx, chain_make(&c, sizes[k], 7u + (uint64_t)k) == 0, "memory")) {
            chain_free(&c);
            continue;
        }
        pd_matrix M = pd_matrix_csc(c.n, c.n, c.colptr, c.rowind, c.values);
        pd_lcp_info info;
        int st = solve_with(PD_LCP_STRUCTURED, &M, c.q, NULL, c.z, c.w, &info);
        CHECK(ctx, st == PD_OK && info.residual <= 1e-10 && !strcmp(info.solver, "structured"),
              "n %d: status %d by %s, residual %.3g, %d iterations", c.n, st, info.solver,
              info.residual, info.iterations);
        if (c.n <= 2048) {
            double *zl = malloc((size_t)c.n * sizeof(double)), *wl = malloc((size_t)c.n * sizeof(double));
            pd_lcp_info il;
            int sl = zl && wl ? solve_with(PD_LCP_LEMKE, &M, c.q, NULL, zl, wl, &il) : PD_ENOMEM;
            double d = 0.0, zs = 0.0;
            for (int i = 0; zl && i < c.n; i++) {
                d = fmax(d, fabs(zl[i] - c.z[i]));
                zs = fmax(zs, fabs(c.z[i]));
            }
            CHECK(ctx, sl == PD_OK && d <= 1e-9 * zs,
                  "n %d: Lemke status %d, |z - z_lemke| %.3g", c.n, sl, d);
            free(zl);
            free(wl);
        }
        /* warm start from the answer: one principal solve */
        unsigned char *guess = malloc((size_t)c.n);
        for (int i = 0; guess && i < c.n; i++)
            guess[i] = c.z[i] > 0.0;
        pd_lcp_opts o = pd_lcp_default_opts();
        o.guess = guess;
        st = solve_with(PD_LCP_STRUCTURED, &M, c.q, &o, c.z, c.w, &info);
        CHECK(ctx, st == PD_OK && info.iterations == 1, "n %d warm: status %d, %d iterations",
              c.n, st, info.iterations);
        free(guess);
        chain_free(&c);
    }
}

/* Degenerate Delassus matrices: redundant contacts on one pair (D = [1 1;
 * 1 1], W_I rank deficient): q = (-1, -2) has the one solution (0, 2),
 * q = (-1, -1) a segment of them (z1 + z2 = 1), each solver returns a
 * verified one; an infeasible singular problem (D = [1 -1; -1 1], q = (-1,
 * -1): w1 + w2 = -2) is reported with a failure status by every solver,
 * never as solved.  In compressed columns the structured solver answers a
 * duplicated contact itself -- at the end of a chain of 300, beyond the
 * hand-over to Lemke -- from its interior point, whose factorisation
 * stalls on the singular block exactly when the point is the answer. */
static void test_solvers_degenerate(pd_test_ctx *ctx)
{
    const pd_lcp_method methods[] = {PD_LCP_LEMKE, PD_LCP_STRUCTURED, PD_LCP_PGS, PD_LCP_AUTO};
    double R[4] = {1, 1, 1, 1}, qr[2] = {-1, -2}, qt[2] = {-1, -1}, S[4] = {1, -1, -1, 1},
           qs[2] = {-1, -1};
    for (int k = 0; k < 4; k++) {
        double z[2], w[2];
        pd_lcp_info info;
        pd_matrix Rm = pd_matrix_dense(2, 2, R), Sm = pd_matrix_dense(2, 2, S);
        int st = solve_with(methods[k], &Rm, qr, NULL, z, w, &info);
        CHECK(ctx, st == PD_OK && info.residual <= 1e-10 && fabs(z[0]) <= 1e-9 &&
                       fabs(z[1] - 2.0) <= 1e-9,
              "%s redundant: status %d, z (%g, %g)", pd_lcp_method_name(methods[k]), st, z[0],
              z[1]);
        st = solve_with(methods[k], &Rm, qt, NULL, z, w, &info);
        CHECK(ctx, st == PD_OK && info.residual <= 1e-10 && fabs(z[0] + z[1] - 1.0) <= 1e-9,
              "%s redundant, a segment of answers: status %d, z (%g, %g)",
              pd_lcp_method_name(methods[k]), st, z[0], z[1]);
        st = solve_with(methods[k], &Sm, qs, NULL, z, w, &info);
        CHECK(ctx, st != PD_OK && info.outcome != PD_LCP_SOLVED,
              "%s infeasible: status %d, outcome %s", pd_lcp_method_name(methods[k]), st,
              pd_lcp_outcome_name(info.outcome));
    }
    /* a chain of 300 contacts whose last one is doubled, in compressed columns */
    enum { NC = 300, ND = NC + 1 };
    static int cp[ND + 1], ri[3 * ND + 2];
    static double vx[3 * ND + 2], q[ND], z[ND], w[ND];
    uint64_t seed = 11;
    int k = 0;
    for (int j = 0; j < ND; j++) {
        int c = j < NC ? j : NC - 1; /* the contact column j repeats */
        cp[j] = k;
        for (int i = 0; i < ND; i++) {
            int r = i < NC ? i : NC - 1;
            double x = r == c ? 2.0 : abs(r - c) == 1 ? -1.0 : 0.0;
            if (x != 0.0) {
                ri[k] = i;
                vx[k++] = x;
            }
        }
        q[j] = j < NC ? rnd(&seed) : q[NC - 1];
    }
    cp[ND] = k;
    pd_matrix C = pd_matrix_csc(ND, ND, cp, ri, vx);
    pd_lcp_info info;
    int st = solve_with(PD_LCP_STRUCTURED, &C, q, NULL, z, w, &info);
    CHECK(ctx, st == PD_OK && info.residual <= 1e-10 && !strcmp(info.solver, "structured"),
          "chain of %d with a doubled contact: status %d by %s, residual %.3g", NC, st,
          info.solver, info.residual);
}

/* PGS reports what it did: a zero pivot is numerical; a budget too small
 * for its linear convergence is max_iterations with the residual left. */
static void test_solvers_pgs_honest(pd_test_ctx *ctx)
{
    double Z[4] = {0, 1, 1, 2}, q[2] = {-1, -1}, z[2], w[2];
    pd_matrix Zm = pd_matrix_dense(2, 2, Z);
    pd_lcp_info info;
    int st = solve_with(PD_LCP_PGS, &Zm, q, NULL, z, w, &info);
    CHECK(ctx, st == PD_ENUMERICAL && info.outcome == PD_LCP_NUMERICAL,
          "zero diagonal: status %d (%s)", st, pd_lcp_outcome_name(info.outcome));
    chain c;
    if (chain_make(&c, 400, 3u) == 0) {
        pd_matrix M = pd_matrix_csc(c.n, c.n, c.colptr, c.rowind, c.values);
        pd_lcp_opts o = pd_lcp_default_opts();
        o.max_iterations = 20;
        st = solve_with(PD_LCP_PGS, &M, c.q, &o, c.z, c.w, &info);
        CHECK(ctx, st == PD_EMAXITER && info.outcome == PD_LCP_MAX_ITERATIONS &&
                       info.iterations == 20 && info.residual > 1e-10,
              "budget 20: status %d (%s), %d sweeps, residual %.3g", st,
              pd_lcp_outcome_name(info.outcome), info.iterations, info.residual);
    }
    chain_free(&c);
}

/* The engine's answer does not depend on the solver: a row of 40 SDOFs
 * with Lemke, the structured solver and PGS (umax to 1e-8). */
static void test_solvers_engine_independent(pd_test_ctx *ctx)
{
    pd_scene_excitation x = {.pulse = PD_PULSE_SINE, .dir = 1, .ap = 3.0, .Tp = 0.5};
    pd_scene *sc = NULL;
    pd_err e;
    if (!CHECK(ctx, pd_scene_chain(40, &x, 1.0, 1.5, 0.05, 0.0005, 0.5, &sc, &e) == PD_OK, "%s",
               e.msg))
        return;
    const pd_lcp_method methods[] = {PD_LCP_LEMKE, PD_LCP_STRUCTURED, PD_LCP_PGS};
    pd_scene_result r[3];
    memset(r, 0, sizeof r);
    for (int k = 0; k < 3; k++) {
        pd_run_opts o = pd_run_default_opts();
        o.lcp_solver = methods[k];
        o.factor = PD_FACTOR_CHOLMOD;
        o.tend = 1.5;
        CHECK(ctx, pd_scene_result_alloc(sc, &r[k], &e) == PD_OK &&
                       pd_scene_run(sc, &o, NULL, NULL, &r[k], &e) == PD_OK,
              "%s: %s", pd_lcp_method_name(methods[k]), e.msg);
    }
    long impacts = 0;
    for (int a = 0; a < sc->ncontact; a++)
        impacts += r[0].impacts[a];
    for (int k = 1; k < 3; k++) {
        double d = 0.0, s = 0.0;
        for (int i = 0; i < sc->n; i++) {
            d = fmax(d, fabs(r[k].umax[i] - r[0].umax[i]));
            s = fmax(s, r[0].umax[i]);
        }
        CHECK(ctx, d <= 1e-8 * s && impacts > 100, "%s vs lemke: umax differ by %.3g (%ld impacts)",
              pd_lcp_method_name(methods[k]), d / s, impacts);
    }
    for (int k = 0; k < 3; k++)
        pd_scene_result_free(&r[k]);
    pd_scene_free(sc);
}

/* A dump of a row's LCPs re-solved by every solver: every one solved and
 * agreeing with the dump (PGS: solved or honestly out of sweeps). */
static void test_solvers_dump_resolved(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_dumpXXXXXX", dump[256];
    if (!mkdtemp(dir))
        return;
    snprintf(dump, sizeof dump, "%s/lcps.h5", dir);
    proc_out r;
    const char *sim[] = {"simulate", "--chain", "30", "--pulse", "sine", "--Tp", "0.5", "--T0",
                         "1", "--ap", "3", "--Pi3", "0.01", "--eps", "0.5", "--tend", "1",
                         "--dump-lcp", dump, NULL};
    pd_test_pound(ctx, sim, &r);
    CHECK(ctx, r.status == 0, "simulate: %s", r.err);
    pd_test_proc_free(&r);
    const char *solvers[] = {"lemke", "structured", "auto", "pgs"};
    for (int k = 0; k < 4; k++) {
        const char *a[] = {"lcp", dump, "--all", "--solver", solvers[k], "--json", NULL};
        pd_test_pound(ctx, a, &r);
        double count = pd_test_json_num(r.out ? r.out : "", "count", 0);
        double solved = pd_test_json_num(r.out ? r.out : "", "solved", 0);
        double agree = pd_test_json_num(r.out ? r.out : "", "agree", 0);
        double res = pd_test_json_num(r.out ? r.out : "", "worst_residual", 0);
        if (k < 3)
            CHECK(ctx, r.status == 0 && count > 100 && solved == count && agree == count,
                  "%s: exit %d, %g of %g solved, %g agree", solvers[k], r.status, solved, count,
                  agree);
        else
            CHECK(ctx, count > 100 && solved >= 0.9 * count &&
                           (r.status == 0) == (solved == count),
                  "pgs: exit %d, %g of %g solved (worst residual %.3g)", r.status, solved, count,
                  res);
        pd_test_proc_free(&r);
    }
    pd_test_rm_dir(dir);
}

/* q huge and M tiny (stress corpus extreme-q-huge-M-tiny): M = 1e-300
 * tridiag(1, 4, 1), q = (-1e300, -2e300, 3e300), whose solution z ~ 1e600
 * has no double.  The structured solver reported it solved with z_2 = inf
 * (inf / inf passed the residual as 0): no solver may call it solved, dense
 * or sparse, and whatever is called solved anywhere must be finite. */
static void test_solvers_nonfinite_never_solved(pd_test_ctx *ctx)
{
    double M[9] = {4e-300, 1e-300, 0.0, 1e-300, 4e-300, 1e-300, 0.0, 1e-300, 4e-300};
    double q[3] = {-1e300, -2e300, 3e300}, z[3], w[3];
    int colptr[4] = {0, 2, 5, 7}, rowind[7] = {0, 1, 0, 1, 2, 1, 2};
    double vals[7] = {4e-300, 1e-300, 1e-300, 4e-300, 1e-300, 1e-300, 4e-300};
    const pd_matrix views[2] = {pd_matrix_dense(3, 3, M), pd_matrix_csc(3, 3, colptr, rowind, vals)};
    const pd_lcp_method methods[] = {PD_LCP_AUTO, PD_LCP_LEMKE, PD_LCP_STRUCTURED, PD_LCP_PGS};
    for (int v = 0; v < 2; v++)
        for (int k = 0; k < 4; k++) {
            pd_lcp_info info;
            int rc = solve_with(methods[k], &views[v], q, NULL, z, w, &info);
            int finite = 1;
            for (int i = 0; i < 3; i++)
                finite &= isfinite(z[i]) && isfinite(w[i]);
            CHECK(ctx, rc != PD_OK && info.outcome != PD_LCP_SOLVED,
                  "%s (%s): status %d, outcome %s, z = (%g, %g, %g), residual %g",
                  pd_lcp_method_name(methods[k]), v ? "csc" : "dense", rc,
                  pd_lcp_outcome_name(info.outcome), z[0], z[1], z[2], info.residual);
            CHECK(ctx, info.outcome != PD_LCP_SOLVED || finite, "%s: solved with a non-finite z",
                  pd_lcp_method_name(methods[k]));
        }
}

/* A PGS iteration that diverges to 1e307 (found by the LCP fuzzer): M =
 * [[2, -12], [-1.222, 2]] has no P-property, and the row sums of |M z|
 * overflow, so r_i = inf made every ratio 0 and the answer passed as
 * solved with w_1 = -1.2e308.  An answer whose terms overflow is
 * unverifiable: never solved, whatever the solver. */
/* Every solver (auto, Lemke, structured, PGS) declines the problem: a
 * status other than PD_OK and an outcome other than solved. */
static void check_never_solved(pd_test_ctx *ctx, const pd_matrix *A, const double *q,
                               const char *what)
{
    const pd_lcp_method methods[] = {PD_LCP_AUTO, PD_LCP_LEMKE, PD_LCP_STRUCTURED, PD_LCP_PGS};
    double z[8], w[8];
    for (int k = 0; k < 4; k++) {
        pd_lcp_info info;
        int rc = solve_with(methods[k], A, q, NULL, z, w, &info);
        CHECK(ctx, rc != PD_OK && info.outcome != PD_LCP_SOLVED,
              "%s, %s: status %d, outcome %s, z0 = %g, w0 = %g", what,
              pd_lcp_method_name(methods[k]), rc, pd_lcp_outcome_name(info.outcome), z[0], w[0]);
    }
}

static void test_solvers_overflowing_terms_never_solved(pd_test_ctx *ctx)
{
    double M[4] = {2.0, -1.222, -12.0, 2.0}, q[2] = {-5.0, -6.0};
    const pd_matrix A = pd_matrix_dense(2, 2, M);
    check_never_solved(ctx, &A, q, "overflowing terms");
}

/* A q of subnormal numbers (stress: extreme-subnormal-q-underflow): its
 * answer rounds to the subnormal spacing, 33 % off in exact arithmetic, and
 * was called solved by every solver.  Now none vouches for it; the same
 * problem scaled by 2^1000 (exact) is solved, and its z scaled back is the
 * answer the tiny one would have. */
static void test_solvers_subnormal_never_solved(pd_test_ctx *ctx)
{
    double M[9] = {400.0, 1.0, 0.0, 0.1, 4.0, 1.0, 0.0, 1.0, 4.0};
    double q[3] = {-5e-324, -1e-322, 1.5e-323}, big[3], z[3], w[3];
    const pd_matrix A = pd_matrix_dense(3, 3, M);
    check_never_solved(ctx, &A, q, "subnormal q");
    for (int i = 0; i < 3; i++)
        big[i] = ldexp(q[i], 1000);
    pd_lcp_info info;
    int rc = solve_with(PD_LCP_AUTO, &A, big, NULL, z, w, &info);
    CHECK(ctx, rc == PD_OK && info.residual <= 1e-12, "scaled: status %d, residual %g", rc,
          info.residual);
}

/* The same problem from a file through `pound lcp --solver structured`: a
 * status other than solved on stdout, exit 1 (it was "solved", exit 0). */
static void test_solvers_nonfinite_cli(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_lcpXXXXXX", path[256];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(path, sizeof path, "%s/extreme.lcp", dir);
    FILE *f = fopen(path, "w");
    if (!CHECK(ctx, f != NULL, "write %s", path))
        return;
    fputs("3\n4e-300 1e-300 0.0\n1e-300 4e-300 1e-300\n0.0 1e-300 4e-300\n"
          "-1e+300 -2e+300 3e+300\n", f);
    fclose(f);
    const char *solvers[] = {"structured", "auto", "lemke", "pgs"};
    for (int k = 0; k < 4; k++) {
        const char *a[] = {"lcp", path, "--json", "--solver", solvers[k], NULL};
        proc_out r;
        pd_test_pound(ctx, a, &r);
        CHECK(ctx, r.status == 1 && r.out && strstr(r.out, "\"status\":\"") &&
                   !strstr(r.out, "\"status\":\"solved\"") && !strstr(r.out, "null"),
              "%s: exit %d: %s", solvers[k], r.status, r.out ? r.out : "");
        pd_test_proc_free(&r);
    }
    pd_test_rm_dir(dir);
}

/* Issue 19: the LCP of the step after a cradle's impact (five balls, eps =
 * 0.5): contacts 0, 1 and 3 active, the bodies behind the first moving
 * together at zero gap, D positive definite, q_2 = -1.7e-16 the rounding
 * of a zero relative velocity and the only term of its row.  Lemke ended
 * it as numerical: its first pivot tied row 3 (q = 0) with row 2 at the
 * scale of max|q| and left w_2 = q_2 < 0 behind, which the verification
 * measures against that row's own terms.  Every solver, auto and Lemke
 * alone, solve it: z_2 = -q_2 / 2. */
static void test_solvers_cradle_after_impact(pd_test_ctx *ctx)
{
    const pd_lcp_method methods[] = {PD_LCP_AUTO, PD_LCP_LEMKE, PD_LCP_STRUCTURED, PD_LCP_PGS};
    double D[9] = {2, -1, 0, -1, 2, 0, 0, 0, 2}, q[3] = {0.75, -1.6653345369377348e-16, 0.0};
    pd_matrix Dm = pd_matrix_dense(3, 3, D);
    for (int k = 0; k < 4; k++) {
        double z[3], w[3];
        pd_lcp_info info;
        int st = solve_with(methods[k], &Dm, q, NULL, z, w, &info);
        CHECK(ctx, st == PD_OK && info.residual <= 1e-10 && fabs(z[1] + q[1] / 2.0) <= 1e-30 &&
                       z[0] == 0.0 && z[2] == 0.0,
              "%s: status %d (%s) by %s, residual %.3g, z (%g, %g, %g)",
              pd_lcp_method_name(methods[k]), st, pd_lcp_outcome_name(info.outcome),
              info.solver, info.residual, z[0], z[1], z[2]);
    }
}

/* Rows in persistent contact: chains of five and nine contacts (masses
 * of order one), q with entries of rounding size (1e-17: relative
 * velocities that are zero but for rounding) next to ones of order one.
 * Lemke's basic values carry such a q_i no further than their rounding, so
 * its last basis left w_i = q_i < 0 off the support, a violation at the
 * scale of that row; its final repair (principal solves from that support)
 * puts it right.  Every solver, and Lemke alone, agree with the oracle. */
static void test_solvers_rounding_size_q(pd_test_ctx *ctx)
{
    static const double d5[5] = {1.7148812556851616, 2.302481199504391, 2.1074597900058123,
                                 1.7676700091545996, 1.8918536715523984};
    static const double o5[4] = {-1.1629686585902015, -1.1395125409141893, -0.967947249091623,
                                 -0.79972276006297649};
    static const double q5[5] = {0, -1.5736185683543978e-17, 1.5559924651822565e-17,
                                 0.10829623838829594, -0.11178781438072138};
    static const double d9[9] = {2.7827906822824353, 2.4548209892288089, 2.4392412496057956,
                                 2.2553665127581271, 1.8683054462329767, 2.0522631389978248,
                                 1.6462809857827096, 1.9589978697960273, 2.3622935591810865};
    static const double o9[8] = {-1.410037783941168,   -1.0447832052876409, -1.3944580443181545,
                                 -0.86090846843997249, -1.0073969777930041, -1.0448661612048209,
                                 -0.60141482457788864, -1.3575830452181386};
    static const double q9[9] = {-0.92206794791839819, -0.063183171803975036, 0, 0,
                                 0.34313256311911433,  -8.1089502575916512e-18,
                                 -3.6568136374579563e-17, 0, 0.13650529119144461};
    const pd_lcp_method methods[] = {PD_LCP_LEMKE, PD_LCP_AUTO, PD_LCP_STRUCTURED, PD_LCP_PGS};
    struct {
        int n;
        const double *d, *o, *q;
    } cases[] = {{5, d5, o5, q5}, {9, d9, o9, q9}};
    for (int c = 0; c < 2; c++) {
        int n = cases[c].n;
        double D[81] = {0}, zo[9], wo[9], z[9], w[9];
        for (int i = 0; i < n; i++) {
            D[i + i * n] = cases[c].d[i];
            if (i + 1 < n)
                D[i + 1 + i * n] = D[i + (i + 1) * n] = cases[c].o[i];
        }
        pd_matrix Dm = pd_matrix_dense(n, n, D);
        CHECK(ctx, pd_lcp_enumerate(n, D, cases[c].q, zo, wo) == PD_OK, "n = %d: oracle", n);
        double zs = 0.0;
        for (int i = 0; i < n; i++)
            zs = fmax(zs, fabs(zo[i]));
        for (int k = 0; k < 4; k++) {
            pd_lcp_info info;
            int st = solve_with(methods[k], &Dm, cases[c].q, NULL, z, w, &info);
            double d = 0.0;
            for (int i = 0; i < n; i++)
                d = fmax(d, fabs(z[i] - zo[i]));
            CHECK(ctx, st == PD_OK && info.residual <= 1e-10 && d <= 1e-9 * zs,
                  "n = %d, %s: status %d (%s) by %s, residual %.3g, |z - oracle| %.3g", n,
                  pd_lcp_method_name(methods[k]), st, pd_lcp_outcome_name(info.outcome),
                  info.solver, info.residual, d);
        }
    }
}

/* auto hands a problem its first solver ends as numerical to the next one,
 * and the answer is verified.  The problems: Delassus matrices of free rows
 * of four and five bodies whose masses span 1e-6 .. 1e12 kg (blocks of
 * condition up to 1e12), q with entries of rounding size.  On the first
 * Lemke ends numerical and the structured solver answers; on the second
 * both end numerical and PGS answers.  A budget is the caller's: Lemke
 * capped at one pivot ends as max_pivots under auto too (and a ray of
 * Lemke's is final, test_solvers_degenerate). */
static void test_solvers_auto_hands_over(pd_test_ctx *ctx)
{
    static const double D4[16] = {417386.51306114433, -417386.51306114433, 0, 0,
                                  -417386.51306114433, 417386.51306179556,
                                  -6.5121435460566592e-07, 0, 0, -6.5121435460566592e-07,
                                  1.6457142655450299e-06, -9.9449991093936384e-07, 0, 0,
                                  -9.9449991093936384e-07, 9.9456886771884702e-07};
    static const double q4[4] = {-3.1180842755874724e-17, -0.97636601327127071,
                                 4.119965808919095e-17, -0.19371545894983699};
    static const double D5[25] = {
        25842.610253135914, -1099.3041189440878, 0, 0, 0,
        -1099.3041189440878, 1099.3041189440908, -3.0132670230515511e-12, 0, 0,
        0, -3.0132670230515511e-12, 0.00026760355590129645, -0.00026760355288802941, 0,
        0, 0, -0.00026760355288802941, 0.0045322791061028558, -0.0042646755532148263,
        0, 0, 0, -0.0042646755532148263, 589938.42350120074};
    static const double q5[5] = {4.8812983381857435e-17, 0, 0, 1.6896876525163484e-17,
                                 -0.57626793738914239};
    struct {
        int n;
        const double *D, *q;
        const char *solver;
    } cases[] = {{4, D4, q4, "structured (after lemke)"},
                 {5, D5, q5, "pgs (after lemke, structured)"}};
    for (int k = 0; k < 2; k++) {
        double z[5], w[5];
        pd_lcp_info info;
        pd_matrix Dm = pd_matrix_dense(cases[k].n, cases[k].n, cases[k].D);
        int st = solve_with(PD_LCP_LEMKE, &Dm, cases[k].q, NULL, z, w, &info);
        CHECK(ctx, st == PD_ENUMERICAL, "n = %d: lemke alone: status %d (%s)", cases[k].n, st,
              pd_lcp_outcome_name(info.outcome));
        st = solve_with(PD_LCP_AUTO, &Dm, cases[k].q, NULL, z, w, &info);
        double r = info.residual;
        pd_lcp_residual(cases[k].n, cases[k].D, cases[k].q, z, w, &info.complementarity,
                        &info.infeasibility, &info.residual);
        CHECK(ctx, st == PD_OK && r <= 1e-10 && info.residual <= 1e-10 &&
                       !strcmp(info.solver, cases[k].solver),
              "n = %d: auto: status %d by %s, residual %.3g (%.3g), expected %s", cases[k].n,
              st, info.solver, r, info.residual, cases[k].solver);
    }
    enum { N = 6 };
    double M[N * N], q[N], z[N], w[N];
    pd_lcp_info info;
    pd_lcp_opts o = pd_lcp_default_opts();
    o.max_pivots = 1;
    random_spd(N, 19, M, q);
    pd_matrix Mm = pd_matrix_dense(N, N, M);
    int st = solve_with(PD_LCP_AUTO, &Mm, q, &o, z, w, &info);
    CHECK(ctx, st == PD_EMAXPIVOTS && !strcmp(info.solver, "lemke") && info.pivots == 1,
          "auto, lemke capped at one pivot: status %d by %s (%d pivots)", st, info.solver,
          info.pivots);
}

void suite_solvers(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_solvers_match_oracle);
    PD_RUN(ctx, test_solvers_banded_oracle);
    PD_RUN(ctx, test_solvers_closed_forms);
    PD_RUN(ctx, test_solvers_chains);
    PD_RUN(ctx, test_solvers_degenerate);
    PD_RUN(ctx, test_solvers_pgs_honest);
    PD_RUN(ctx, test_solvers_engine_independent);
    PD_RUN(ctx, test_solvers_dump_resolved);
    PD_RUN(ctx, test_solvers_nonfinite_never_solved);
    PD_RUN(ctx, test_solvers_overflowing_terms_never_solved);
    PD_RUN(ctx, test_solvers_nonfinite_cli);
    PD_RUN(ctx, test_solvers_cradle_after_impact);
    PD_RUN(ctx, test_solvers_rounding_size_q);
    PD_RUN(ctx, test_solvers_auto_hands_over);
    PD_RUN(ctx, test_solvers_subnormal_never_solved);
}
