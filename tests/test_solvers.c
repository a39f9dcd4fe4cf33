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

#include "lcp_internal.h"
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
static int solve_with(pd_lcp_method m, const pd_matrix *M, const double *q, const pd_lcp_opts *o,
                      double *z, double *w, pd_lcp_info *info)
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
                      pd_lcp_method_name(methods[k]), n, (unsigned long long)seed, st, info.solver,
                      info.residual, d);
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
                banded_spd(n, band, seed * 131 + (uint64_t)(n + 17 * band), colptr, rowind, values,
                           dense, q);
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
                CHECK(ctx,
                      st == PD_OK && !strcmp(info.solver, "structured") &&
                          d <= 1e-9 * fmax(zs, 1e-300),
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
        CHECK(ctx,
              st == PD_OK && info.pivots == 0 && fabs(z[0] - zo[0]) <= 1e-14 * (1 + fabs(zo[0])) &&
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
            double *zl = malloc((size_t)c.n * sizeof(double)),
                   *wl = malloc((size_t)c.n * sizeof(double));
            pd_lcp_info il;
            int sl = zl && wl ? solve_with(PD_LCP_LEMKE, &M, c.q, NULL, zl, wl, &il) : PD_ENOMEM;
            double d = 0.0, zs = 0.0;
            for (int i = 0; zl && i < c.n; i++) {
                d = fmax(d, fabs(zl[i] - c.z[i]));
                zs = fmax(zs, fabs(c.z[i]));
            }
            CHECK(ctx, sl == PD_OK && d <= 1e-9 * zs, "n %d: Lemke status %d, |z - z_lemke| %.3g",
                  c.n, sl, d);
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
        CHECK(ctx, st == PD_OK && info.iterations == 1, "n %d warm: status %d, %d iterations", c.n,
              st, info.iterations);
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
        CHECK(
            ctx,
            st == PD_OK && info.residual <= 1e-10 && fabs(z[0]) <= 1e-9 && fabs(z[1] - 2.0) <= 1e-9,
            "%s redundant: status %d, z (%g, %g)", pd_lcp_method_name(methods[k]), st, z[0], z[1]);
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
          "chain of %d with a doubled contact: status %d by %s, residual %.3g", NC, st, info.solver,
          info.residual);
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
        CHECK(ctx,
              st == PD_EMAXITER && info.outcome == PD_LCP_MAX_ITERATIONS && info.iterations == 20 &&
                  info.residual > 1e-10,
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
        CHECK(ctx,
              pd_scene_result_alloc(sc, &r[k], &e) == PD_OK &&
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
    const char *sim[] = {"simulate", "--chain", "30",   "--pulse",    "sine",  "--Tp", "0.5",
                         "--T0",     "1",       "--ap", "3",          "--Pi3", "0.01", "--eps",
                         "0.5",      "--tend",  "1",    "--dump-lcp", dump,    NULL};
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
            CHECK(ctx, count > 100 && solved >= 0.9 * count && (r.status == 0) == (solved == count),
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
    const pd_matrix views[2] = {pd_matrix_dense(3, 3, M),
                                pd_matrix_csc(3, 3, colptr, rowind, vals)};
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
          "-1e+300 -2e+300 3e+300\n",
          f);
    fclose(f);
    const char *solvers[] = {"structured", "auto", "lemke", "pgs"};
    for (int k = 0; k < 4; k++) {
        const char *a[] = {"lcp", path, "--json", "--solver", solvers[k], NULL};
        proc_out r;
        pd_test_pound(ctx, a, &r);
        CHECK(ctx,
              r.status == 1 && r.out && strstr(r.out, "\"status\":\"") &&
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
        CHECK(ctx,
              st == PD_OK && info.residual <= 1e-10 && fabs(z[1] + q[1] / 2.0) <= 1e-30 &&
                  z[0] == 0.0 && z[2] == 0.0,
              "%s: status %d (%s) by %s, residual %.3g, z (%g, %g, %g)",
              pd_lcp_method_name(methods[k]), st, pd_lcp_outcome_name(info.outcome), info.solver,
              info.residual, z[0], z[1], z[2]);
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
    static const double q9[9] = {-0.92206794791839819,
                                 -0.063183171803975036,
                                 0,
                                 0,
                                 0.34313256311911433,
                                 -8.1089502575916512e-18,
                                 -3.6568136374579563e-17,
                                 0,
                                 0.13650529119144461};
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
    static const double D4[16] = {
        417386.51306114433,     -417386.51306114433,     0, 0, -417386.51306114433,
        417386.51306179556,     -6.5121435460566592e-07, 0, 0, -6.5121435460566592e-07,
        1.6457142655450299e-06, -9.9449991093936384e-07, 0, 0, -9.9449991093936384e-07,
        9.9456886771884702e-07};
    static const double q4[4] = {-3.1180842755874724e-17, -0.97636601327127071,
                                 4.119965808919095e-17, -0.19371545894983699};
    static const double D5[25] = {
        25842.610253135914,     -1099.3041189440878,     0, 0, 0, -1099.3041189440878,
        1099.3041189440908,     -3.0132670230515511e-12, 0, 0, 0, -3.0132670230515511e-12,
        0.00026760355590129645, -0.00026760355288802941, 0, 0, 0, -0.00026760355288802941,
        0.0045322791061028558,  -0.0042646755532148263,  0, 0, 0, -0.0042646755532148263,
        589938.42350120074};
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
        CHECK(ctx,
              st == PD_OK && r <= 1e-10 && info.residual <= 1e-10 &&
                  !strcmp(info.solver, cases[k].solver),
              "n = %d: auto: status %d by %s, residual %.3g (%.3g), expected %s", cases[k].n, st,
              info.solver, r, info.residual, cases[k].solver);
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

/* ---- the direct method for tridiagonal Stieltjes matrices ------------------ */

/* A tridiagonal Stieltjes matrix in compressed columns (and dense): its
 * diagonal a, its subdiagonal b (b[0] unused, entries <= 0). */
static void tri_csc(int n, const double *a, const double *b, int *colptr, int *rowind,
                    double *values, double *dense)
{
    int k = 0;
    for (int j = 0; j < n; j++) {
        colptr[j] = k;
        if (j > 0) {
            rowind[k] = j - 1;
            values[k++] = b[j];
        }
        rowind[k] = j;
        values[k++] = a[j];
        if (j + 1 < n) {
            rowind[k] = j + 1;
            values[k++] = b[j + 1];
        }
    }
    colptr[n] = k;
    if (dense) {
        memset(dense, 0, (size_t)n * (size_t)n * sizeof(double));
        pd_matrix M = pd_matrix_csc(n, n, colptr, rowind, values);
        pd_matrix_to_dense(&M, dense);
    }
}

/* Problem `kind` of size n from a seed, into a, b, q (z*: its solution, when
 * kind 2 builds it):
 *   0  diagonally dominant: b_i in (-1, 0] (some exactly 0: the chain cut),
 *      a_i = |b_i| + |b_i+1| + s_i, s_i in [1e-3, 1); q in [-1, 1) with
 *      exact zeros and entries of 1e-17;
 *   1  S A S of kind 0 with s_i in [0.1, 10]: not diagonally dominant;
 *   2  the chain tridiag(-1, 2, -1) with q = w* - M z*, z* in {0, 1, 2}, w*
 *      in {0, 1} off the support of z*, and a third of the indices with
 *      z* = w* = 0 (degenerate: zero gaps that neither push nor open), all
 *      in integers, exact;
 *   3  the chain with q = -e_1 (an impact that runs along touching bodies:
 *      every other q_i = 0). */
static void stieltjes_problem(int kind, int n, uint64_t seed, double *a, double *b, double *q,
                              double *zstar)
{
    uint64_t s = seed;
    for (int i = 0; i < n; i++) {
        double u = rnd(&s);
        b[i] = kind >= 2 ? -1.0 : i == 0 || u > 0.8 ? 0.0 : -0.5 * (u + 1.0);
    }
    b[0] = 0.0;
    for (int i = 0; i < n; i++)
        a[i] =
            kind >= 2 ? 2.0 : -b[i] - (i + 1 < n ? b[i + 1] : 0.0) + 1e-3 + 0.5 * (rnd(&s) + 1.0);
    if (kind == 1) {
        double sc[16];
        for (int i = 0; i < n; i++)
            sc[i] = pow(10.0, rnd(&s));
        for (int i = 0; i < n; i++) {
            a[i] *= sc[i] * sc[i];
            b[i] *= i > 0 ? sc[i] * sc[i - 1] : 0.0;
        }
    }
    for (int i = 0; i < n; i++) {
        double u = rnd(&s);
        q[i] = u < -0.8 ? 0.0 : u > 0.85 ? (u > 0.92 ? 1e-17 : -1e-17) : rnd(&s);
        zstar[i] = 0.0;
    }
    if (kind == 2) {
        double wstar[16];
        for (int i = 0; i < n; i++) {
            double u = rnd(&s);
            zstar[i] = u < -1.0 / 3 ? 0.0 : u < 1.0 / 3 ? 1.0 : 2.0;
            wstar[i] = zstar[i] > 0.0 || rnd(&s) < 0.0 ? 0.0 : 1.0;
        }
        for (int i = 0; i < n; i++)
            q[i] = wstar[i] - 2.0 * zstar[i] + (i > 0 ? zstar[i - 1] : 0.0) +
                   (i + 1 < n ? zstar[i + 1] : 0.0);
    }
    if (kind == 3)
        for (int i = 0; i < n; i++)
            q[i] = i == 0 ? -1.0 : 0.0;
}

/* max_i |x_i - y_i| over max(max_i |y_i|, tiny). */
static double rel_diff(int n, const double *x, const double *y)
{
    double d = 0.0, s = 0.0;
    for (int i = 0; i < n; i++) {
        d = fmax(d, fabs(x[i] - y[i]));
        s = fmax(s, fabs(y[i]));
    }
    return d / fmax(s, 1e-300);
}

/* Chandrasekaran's method with dense LU, the reference for Stieltjes
 * matrices (M-matrices: z only grows, every index with w_i < 0 joins, no
 * index leaves): F grows by the indices whose w_i is below -1e-13 of its
 * row's terms until none is; z into z.  -1 when a solve fails. */
static int chandrasekaran_dense(int n, const double *M, const double *q, double *z)
{
    static double A[128 * 128], rhs[128];
    static int perm[128], idx[128];
    unsigned char in[128] = {0};
    memset(z, 0, (size_t)n * sizeof(double));
    for (int round = 0; round <= n; round++) {
        int added = 0, k = 0;
        for (int i = 0; i < n; i++) {
            double wi = q[i], ri = fabs(q[i]);
            for (int j = 0; j < n; j++) {
                wi += M[i + (size_t)j * n] * z[j];
                ri += fabs(M[i + (size_t)j * n] * z[j]);
            }
            if (!in[i] && wi < -1e-13 * ri)
                in[i] = 1, added = 1;
        }
        if (!added)
            return 0;
        for (int i = 0; i < n; i++)
            if (in[i])
                idx[k++] = i;
        for (int b = 0; b < k; b++) {
            for (int a = 0; a < k; a++)
                A[a + b * k] = M[idx[a] + (size_t)idx[b] * n];
            rhs[b] = -q[idx[b]];
        }
        if (pd_dense_lu(k, A, k, perm, 1e-14) != PD_OK)
            return -1;
        pd_dense_lu_solve(k, A, k, perm, rhs);
        for (int b = 0; b < k; b++)
            z[idx[b]] = rhs[b];
    }
    return 0;
}

/* Block-tridiagonal Stieltjes matrices (blocks of 2 and 3, 1 to 40 of
 * them, n up to 120): off-diagonal entries in [-1, 0] (a fifth exactly 0)
 * within neighbouring blocks, symmetric, the diagonal dominant by [1e-3,
 * 1); q random with exact zeros and entries of 1e-17, or an impact (-e_1,
 * every other q_i = 0: degenerate), or an impact with q_i = 1e-4.  The
 * structured solver (the envelope, not the tridiagonal direct method)
 * answers itself, verified, with the z of Chandrasekaran's method to 1e-9
 * of max z. */
static void test_solvers_block_mmatrix(pd_test_ctx *ctx)
{
    static const int nblocks[] = {1, 2, 5, 13, 40};
    static double dense[120 * 120], values[120 * 120];
    static int rowind[120 * 120];
    int colptr[121], cases = 0;
    double q[120], z[120], w[120], zr[120];
    uint64_t s = 4242;
    for (int bs = 2; bs <= 3; bs++)
        for (size_t kb = 0; kb < sizeof nblocks / sizeof nblocks[0]; kb++)
            for (int form = 0; form < 3; form++)
                for (int rep = 0; rep < 4; rep++) {
                    int n = bs * nblocks[kb];
                    memset(dense, 0, (size_t)n * n * sizeof(double));
                    for (int j = 0; j < n; j++)
                        for (int i = j + 1; i < n && i / bs <= j / bs + 1; i++) {
                            double u = rnd(&s);
                            dense[i + j * n] = dense[j + i * n] = u < -0.6 ? 0.0 : -0.5 * (u + 1.0);
                        }
                    for (int i = 0; i < n; i++) {
                        double d = 0.0;
                        for (int j = 0; j < n; j++)
                            d += fabs(dense[i + j * n]);
                        dense[i + i * n] = d + 1e-3 + 0.5 * (rnd(&s) + 1.0);
                        double u = rnd(&s);
                        q[i] = form == 0   ? (u < -0.7  ? 0.0
                                              : u > 0.9 ? 1e-17
                                                        : rnd(&s))
                               : i == 0    ? -1.0
                               : form == 1 ? 0.0
                                           : 1e-4;
                    }
                    int k = 0;
                    for (int j = 0; j < n; j++) {
                        colptr[j] = k;
                        for (int i = 0; i < n; i++)
                            if (dense[i + j * n] != 0.0 || i == j) {
                                rowind[k] = i;
                                values[k++] = dense[i + j * n];
                            }
                    }
                    colptr[n] = k;
                    pd_matrix M = pd_matrix_csc(n, n, colptr, rowind, values);
                    if (!CHECK(ctx, chandrasekaran_dense(n, dense, q, zr) == 0, "reference n %d",
                               n))
                        continue;
                    pd_lcp_info info;
                    int st = solve_with(PD_LCP_STRUCTURED, &M, q, NULL, z, w, &info);
                    double d = rel_diff(n, z, zr);
                    cases++;
                    CHECK(ctx, st == PD_OK && !strcmp(info.solver, "structured") && d <= 1e-9,
                          "blocks of %d, n %d form %d: status %d by %s, |z - z_ref| %.3g", bs, n,
                          form, st, info.solver, d);
                }
    CHECK(ctx, cases == 120, "%d cases", cases);
}

/* The direct method itself (pd_bpp_stieltjes), then the structured solver
 * through the table, against the enumeration oracle on the four kinds of
 * stieltjes_problem, n = 1..10 (800 cases): the direct method takes each
 * one, and the table's answer is the structured solver's own, verified,
 * in one iteration. */
static void test_solvers_stieltjes_oracle(pd_test_ctx *ctx)
{
    int cases = 0;
    pd_bpp_work *ws = pd_bpp_alloc(10, 100);
    if (!CHECK(ctx, ws != NULL, "memory"))
        return;
    for (int kind = 0; kind < 4; kind++)
        for (int n = 1; n <= 10; n++)
            for (uint64_t seed = 1; seed <= 20; seed++) {
                int colptr[11], rowind[30];
                double a[10], b[10], q[10], zs[10], values[30], dense[100], zo[10], wo[10];
                double z[10], w[10], zmax = 0.0;
                stieltjes_problem(kind, n, seed * 7919 + (uint64_t)(n + 13 * kind), a, b, q, zs);
                tri_csc(n, a, b, colptr, rowind, values, dense);
                pd_matrix M = pd_matrix_csc(n, n, colptr, rowind, values);
                if (!CHECK(ctx, pd_lcp_enumerate(n, dense, q, zo, wo) == PD_OK, "oracle n %d", n))
                    continue;
                cases++;
                int rc = pd_bpp_stieltjes(ws, &M, q, z, &zmax);
                double d = rel_diff(n, z, zo), res = 1.0;
                pd_lcp_residual(n, dense, q, z, w, NULL, NULL, &res);
                CHECK(ctx, rc == 1 && d <= 1e-12 && res <= 1e-10,
                      "direct, kind %d n %d seed %llu: %d, |z - z_oracle| %.3g, residual %.3g",
                      kind, n, (unsigned long long)seed, rc, d, res);
                if (kind == 2)
                    CHECK(ctx, rel_diff(n, z, zs) <= 1e-15, "kind 2 n %d: not z*", n);
                pd_lcp_info info;
                int st = solve_with(PD_LCP_STRUCTURED, &M, q, NULL, z, w, &info);
                d = rel_diff(n, z, zo);
                CHECK(ctx,
                      st == PD_OK && !strcmp(info.solver, "structured") && info.iterations == 1 &&
                          d <= 1e-12,
                      "structured, kind %d n %d seed %llu: status %d by %s, %d iterations, "
                      "|z - z_oracle| %.3g",
                      kind, n, (unsigned long long)seed, st, info.solver, info.iterations, d);
            }
    CHECK(ctx, cases == 800, "%d cases", cases);
    pd_bpp_free(ws);
}

/* Where the direct method does not apply it says so (0) and the structured
 * solver answers as before: a positive off-diagonal entry, a nonsymmetric
 * pair, an entry beyond the tridiagonal band (even an explicit 0), a dense
 * view; where a principal block is singular (the Laplacian of two free
 * bodies, q = (-1, -1): infeasible) it stops at the pivot (-1), and no
 * solver calls the problem solved. */
static void test_solvers_stieltjes_not_taken(pd_test_ctx *ctx)
{
    pd_bpp_work *ws = pd_bpp_alloc(4, 64);
    if (!CHECK(ctx, ws != NULL, "memory"))
        return;
    int colptr[5] = {0, 2, 5, 8, 10}, rowind[10] = {0, 1, 0, 1, 2, 1, 2, 3, 2, 3};
    double z[4], w[4], zo[4], wo[4], q[4] = {-1.0, 0.5, -0.25, 0.1}, zmax = 0.0;
    const double base[10] = {2, -1, -1, 2, -1, -1, 2, -1, -1, 2};
    for (int c = 0; c < 3; c++) {
        double v[10], dense[16];
        memcpy(v, base, sizeof v);
        if (c == 0) /* M_12 = M_21 > 0 */
            v[3] = v[5] = 0.5;
        else if (c == 1) /* M_12 != M_21 */
            v[5] = -0.5;
        pd_matrix M = pd_matrix_csc(4, 4, colptr, rowind, v);
        if (c == 2) { /* the dense view of the chain */
            pd_matrix_to_dense(&M, dense);
            M = pd_matrix_dense(4, 4, dense);
        }
        CHECK(ctx, pd_bpp_stieltjes(ws, &M, q, z, &zmax) == 0, "case %d taken", c);
        pd_lcp_info info;
        int st = solve_with(PD_LCP_STRUCTURED, &M, q, NULL, z, w, &info);
        if (c == 1) { /* nonsymmetric: the table still answers, verified */
            CHECK(ctx, st == PD_OK && info.residual <= 1e-10, "case 1: status %d", st);
            continue;
        }
        if (c == 0)
            pd_matrix_to_dense(&M, dense);
        pd_lcp_enumerate(4, dense, q, zo, wo);
        CHECK(ctx, st == PD_OK && rel_diff(4, z, zo) <= 1e-12, "case %d: status %d by %s", c, st,
              info.solver);
    }
    { /* pentadiagonal pattern with an explicit zero at (0, 2) */
        int cp[5] = {0, 3, 6, 10, 12}, ri[12] = {0, 1, 2, 0, 1, 2, 0, 1, 2, 3, 2, 3};
        double v[12] = {2, -1, 0, -1, 2, -1, 0, -1, 2, -1, -1, 2};
        pd_matrix M = pd_matrix_csc(4, 4, cp, ri, v);
        CHECK(ctx, pd_bpp_stieltjes(ws, &M, q, z, &zmax) == 0, "pentadiagonal pattern taken");
    }
    { /* singular: D = [1 -1; -1 1], q = (-1, -1) */
        int cp[3] = {0, 2, 4}, ri[4] = {0, 1, 0, 1};
        double v[4] = {1, -1, -1, 1}, q2[2] = {-1.0, -1.0};
        pd_matrix M = pd_matrix_csc(2, 2, cp, ri, v);
        CHECK(ctx, pd_bpp_stieltjes(ws, &M, q2, z, &zmax) == -1, "singular block: not -1");
        pd_lcp_info info;
        int st = solve_with(PD_LCP_STRUCTURED, &M, q2, NULL, z, w, &info);
        CHECK(ctx, st != PD_OK && info.outcome != PD_LCP_SOLVED, "singular: status %d", st);
    }
    pd_bpp_free(ws);
}

/* The direct method against the solver it bypasses, at sizes the oracle
 * cannot reach: chains of 3000 and 20000 bodies of random masses in [0.5,
 * 2] (D_ii = 1/m_i + 1/m_i+1, D_i,i+1 = -1/m_i+1), q random (with zeros) or
 * an impact at the first contact, every other q_i = 0 or 1e-4 (a support
 * that grows along the whole chain); the same matrix with one explicit zero
 * outside the band (so not taken: pivoting and the interior point) gives
 * the same z to 1e-8.  The direct answer takes one iteration, the other at
 * least two on the impacts.  At 400, Lemke on the dense matrix agrees. */
static void test_solvers_stieltjes_large(pd_test_ctx *ctx)
{
    const int sizes[] = {400, 3000, 20000};
    for (int k = 0; k < 3; k++)
        for (int form = 0; form < 3; form++) {
            int n = sizes[k];
            size_t un = (size_t)n;
            double *a = malloc(un * sizeof(double)), *b = malloc(un * sizeof(double));
            double *q = malloc(un * sizeof(double)), *z = malloc(un * sizeof(double));
            double *w = malloc(un * sizeof(double)), *z2 = malloc(un * sizeof(double));
            double *m = malloc((un + 1) * sizeof(double));
            double *values = malloc(3 * un * sizeof(double));
            int *colptr = malloc((un + 1) * sizeof(int)), *rowind = malloc(3 * un * sizeof(int));
            int *cp2 = malloc((un + 1) * sizeof(int)), *ri2 = malloc((3 * un + 2) * sizeof(int));
            double *v2 = malloc((3 * un + 2) * sizeof(double));
            if (!CHECK(ctx,
                       a && b && q && z && w && z2 && m && values && colptr && rowind && cp2 &&
                           ri2 && v2,
                       "memory"))
                goto next;
            uint64_t s = 1234u + (uint64_t)(31 * k + form);
            for (int i = 0; i <= n; i++)
                m[i] = pow(2.0, rnd(&s));
            for (int i = 0; i < n; i++) {
                a[i] = 1.0 / m[i] + 1.0 / m[i + 1];
                b[i] = i > 0 ? -1.0 / m[i] : 0.0;
                double u = rnd(&s);
                q[i] = form == 0   ? (u < -0.9 ? 0.0 : rnd(&s))
                       : i == 0    ? -1.0
                       : form == 1 ? 0.0
                                   : 1e-4;
            }
            tri_csc(n, a, b, colptr, rowind, values, NULL);
            pd_matrix M = pd_matrix_csc(n, n, colptr, rowind, values);
            pd_lcp_info info, i2;
            int st = solve_with(PD_LCP_STRUCTURED, &M, q, NULL, z, w, &info);
            CHECK(ctx, st == PD_OK && info.iterations == 1 && !strcmp(info.solver, "structured"),
                  "n %d form %d: status %d by %s, %d iterations", n, form, st, info.solver,
                  info.iterations);
            /* the same matrix with an explicit zero at (2, 0) and (0, 2) */
            int t = 0;
            for (int j = 0; j < n; j++) {
                cp2[j] = t;
                for (int r = colptr[j]; r < colptr[j + 1]; r++) {
                    if (j == 2 && rowind[r] == 1) {
                        ri2[t] = 0;
                        v2[t++] = 0.0;
                    }
                    ri2[t] = rowind[r];
                    v2[t++] = values[r];
                    if (j == 0 && rowind[r] == 1) {
                        ri2[t] = 2;
                        v2[t++] = 0.0;
                    }
                }
            }
            cp2[n] = t;
            pd_matrix M2 = pd_matrix_csc(n, n, cp2, ri2, v2);
            int st2 = solve_with(PD_LCP_STRUCTURED, &M2, q, NULL, z2, w, &i2);
            double d = rel_diff(n, z, z2);
            CHECK(ctx, st2 == PD_OK && d <= 1e-8 && (form == 0 || i2.iterations >= 2),
                  "n %d form %d: pivoting / interior point status %d (%d iterations), |dz| %.3g", n,
                  form, st2, i2.iterations, d);
            if (n <= 500) {
                double *dense = malloc(un * un * sizeof(double));
                if (dense) {
                    pd_matrix_to_dense(&M, dense);
                    pd_matrix Md = pd_matrix_dense(n, n, dense);
                    st2 = solve_with(PD_LCP_LEMKE, &Md, q, NULL, z2, w, &i2);
                    d = rel_diff(n, z, z2);
                    CHECK(ctx, st2 == PD_OK && d <= 1e-8,
                          "n %d form %d: lemke status %d, |dz| %.3g", n, form, st2, d);
                }
                free(dense);
            }
        next:
            free(a);
            free(b);
            free(q);
            free(z);
            free(w);
            free(z2);
            free(m);
            free(values);
            free(colptr);
            free(rowind);
            free(cp2);
            free(ri2);
            free(v2);
        }
}

/* Warm starts on a Stieltjes chain (2000 contacts): the direct method does
 * not need one, and any guess -- right, wrong everywhere, no idea, random
 * -- gives the cold answer, bit for bit, in one iteration. */
static void test_solvers_stieltjes_warm(pd_test_ctx *ctx)
{
    chain c;
    int n = 2000;
    double *zc = malloc((size_t)n * sizeof(double));
    unsigned char *guess = malloc((size_t)n);
    if (!CHECK(ctx, chain_make(&c, n, 99u) == 0 && zc && guess, "memory"))
        goto done;
    pd_matrix M = pd_matrix_csc(n, n, c.colptr, c.rowind, c.values);
    pd_lcp_info info;
    int st = solve_with(PD_LCP_STRUCTURED, &M, c.q, NULL, zc, c.w, &info);
    CHECK(ctx, st == PD_OK && info.iterations == 1, "cold: status %d, %d iterations", st,
          info.iterations);
    uint64_t s = 5u;
    for (int g = 0; g < 4; g++) {
        for (int i = 0; i < n; i++)
            guess[i] = g == 0 ? zc[i] > 0.0 : g == 1 ? !(zc[i] > 0.0) : g == 2 ? 2 : rnd(&s) < 0.0;
        pd_lcp_opts o = pd_lcp_default_opts();
        o.guess = guess;
        st = solve_with(PD_LCP_STRUCTURED, &M, c.q, &o, c.z, c.w, &info);
        CHECK(ctx,
              st == PD_OK && info.iterations == 1 && !memcmp(c.z, zc, (size_t)n * sizeof(double)),
              "guess %d: status %d, %d iterations, |dz| %.3g", g, st, info.iterations,
              rel_diff(n, c.z, zc));
    }
done:
    chain_free(&c);
    free(zc);
    free(guess);
}

/* The verification's one pass for tridiagonal compressed columns against
 * its general path (the same matrix densely, n > 32: column by column)
 * and against itself with an entry beyond the band (the general path
 * again): w, the row sizes and every figure the same to the bit, on random
 * tridiagonals, n = 1..120, z with zeros, negatives and NaN, q with -0
 * (w alike as numbers: a stored 0 adds +0 to a -0);
 * a NaN of M in a column whose z_j = 0 is left out by both. */
static void test_solvers_verify_tridiagonal(pd_test_ctx *ctx)
{
    enum { NMAX = 120 };
    static double dense[NMAX * NMAX];
    int colptr[NMAX + 1], rowind[3 * NMAX + 1], cp2[NMAX + 1], ri2[3 * NMAX + 1], mism = 0,
                                                                                  cases = 0;
    double a[NMAX], b[NMAX], values[3 * NMAX + 1], v2[3 * NMAX + 1], q[NMAX], z[NMAX];
    double w1[NMAX], w2[NMAX], w3[NMAX], r1[NMAX], r2[NMAX], r3[NMAX];
    uint64_t s = 99;
    for (int n = 1; n <= NMAX; n += n < 10 ? 1 : 7)
        for (int rep = 0; rep < 20; rep++) {
            for (int i = 0; i < n; i++) {
                a[i] = 2.0 + rnd(&s);
                b[i] = i > 0 ? rnd(&s) : 0.0;
                double u = rnd(&s);
                q[i] = u < -0.8 ? -0.0 : u < -0.6 ? 0.0 : rnd(&s);
                u = rnd(&s);
                z[i] = u < 0.0 ? 0.0 : u < 0.1 ? -u : rep == 3 && i == n / 2 ? NAN : u;
            }
            tri_csc(n, a, b, colptr, rowind, values, NULL);
            if (rep == 5) /* a NaN in M where z_j = 0: dropped by both */
                for (int j = 0; j < n; j++)
                    if (z[j] == 0.0) {
                        values[colptr[j]] = NAN;
                        break;
                    }
            pd_matrix M = pd_matrix_csc(n, n, colptr, rowind, values);
            memset(dense, 0, sizeof dense);
            pd_matrix_to_dense(&M, dense);
            /* the same with an explicit 0 at (n - 1, 0): beyond the band for n > 2 */
            int t = 0;
            for (int j = 0; j < n; j++) {
                cp2[j] = t;
                for (int k = colptr[j]; k < colptr[j + 1]; k++) {
                    ri2[t] = rowind[k];
                    v2[t++] = values[k];
                }
                if (j == 0 && n > 2) {
                    ri2[t] = n - 1;
                    v2[t++] = 0.0;
                }
            }
            cp2[n] = t;
            z[0] = n > 2 && z[0] == 0.0 ? 0.5 : z[0]; /* column 0 is used */
            pd_matrix D = pd_matrix_dense(n, n, dense), M2 = pd_matrix_csc(n, n, cp2, ri2, v2);
            pd_lcp_info i1, i2, i3;
            pd_lcp_verify(&M, q, z, w1, r1, &i1);
            pd_lcp_verify(&M2, q, z, w3, r3, &i3);
            pd_lcp_verify(&D, q, z, w2, r2, &i2);
            /* w alike as numbers: an explicit 0 adds a +0 that the band
             * does not (-0 + 0 = +0); a NaN of z spreads further densely */
            int same = 1;
            for (int i = 0; i < n; i++)
                same &= (w1[i] == w3[i] || (isnan(w1[i]) && isnan(w3[i]))) &&
                        (n <= 32 || rep == 3 || w1[i] == w2[i] || (isnan(w1[i]) && isnan(w2[i])));
            same = same && !memcmp(r1, r3, (size_t)n * sizeof(double)) &&
                   !memcmp(&i1.residual, &i3.residual, sizeof(double)) &&
                   !memcmp(&i1.complementarity, &i3.complementarity, sizeof(double)) &&
                   !memcmp(&i1.infeasibility, &i3.infeasibility, sizeof(double)) &&
                   !memcmp(&i1.scale, &i3.scale, sizeof(double));
            if (n > 32 && rep != 3) /* the dense general path (n <= 32 is made row by row;
                                       a NaN of z spreads over the dense rows) */
                same &= !memcmp(&i1.residual, &i2.residual, sizeof(double)) &&
                        !memcmp(&i1.scale, &i2.scale, sizeof(double));
            mism += !same;
            cases++;
        }
    CHECK(ctx, mism == 0, "%d of %d cases differ from the general path", mism, cases);
}

/* A banded matrix given densely (a plain LCP file) is copied once into
 * compressed columns for the structured solver: a tridiagonal Stieltjes one
 * of 300 rows with an impact at its first row is answered by the direct
 * method (one iteration, where pivoting and the interior point take more),
 * bit for bit as in compressed columns; the same with one more pair of
 * entries far from the band (-1e-3 at (0, 299)) is answered on the copy by
 * the general method and agrees with Lemke; a dense SPD matrix with more
 * entries than the copy holds (17 a row) is solved as it is. */
static void test_solvers_dense_banded(pd_test_ctx *ctx)
{
    enum { N = 300 };
    double *dense = malloc((size_t)N * N * sizeof(double)), a[N], b[N], q[N], z[N], w[N];
    double zc[N], zl[N];
    int colptr[N + 1], rowind[3 * N];
    double values[3 * N];
    if (!CHECK(ctx, dense != NULL, "memory"))
        return;
    for (int i = 0; i < N; i++) {
        a[i] = 2.0;
        b[i] = i > 0 ? -1.0 : 0.0;
        q[i] = i == 0 ? -1.0 : 1e-3;
    }
    tri_csc(N, a, b, colptr, rowind, values, dense);
    pd_matrix Mc = pd_matrix_csc(N, N, colptr, rowind, values), Md = pd_matrix_dense(N, N, dense);
    pd_lcp_info ic, id;
    int sc = solve_with(PD_LCP_STRUCTURED, &Mc, q, NULL, zc, w, &ic);
    int sd = solve_with(PD_LCP_STRUCTURED, &Md, q, NULL, z, w, &id);
    CHECK(ctx,
          sc == PD_OK && sd == PD_OK && ic.iterations == 1 && id.iterations == 1 &&
              !strcmp(id.solver, "structured") && !memcmp(z, zc, sizeof z),
          "tridiagonal: compressed status %d (%d iterations), dense status %d by %s (%d "
          "iterations), |dz| %.3g",
          sc, ic.iterations, sd, id.solver, id.iterations, rel_diff(N, z, zc));
    dense[0 + (size_t)(N - 1) * N] = dense[N - 1] = -1e-3;
    sd = solve_with(PD_LCP_STRUCTURED, &Md, q, NULL, z, w, &id);
    int sl = solve_with(PD_LCP_LEMKE, &Md, q, NULL, zl, w, &ic);
    CHECK(ctx,
          sd == PD_OK && !strcmp(id.solver, "structured") && sl == PD_OK &&
              rel_diff(N, z, zl) <= 1e-9,
          "one entry off the band: status %d by %s, lemke %d, |dz| %.3g", sd, id.solver, sl,
          rel_diff(N, z, zl));
    { /* 30 x 30 SPD, full: 900 entries, more than 17 * 30 */
        double M[900], qq[30], z1[30], w1[30], z2[30];
        uint64_t s = 77u;
        double B[900];
        for (int k = 0; k < 900; k++)
            B[k] = rnd(&s);
        for (int j = 0; j < 30; j++)
            for (int i = 0; i < 30; i++) {
                double x = i == j ? 7.5 : 0.0;
                for (int r = 0; r < 30; r++)
                    x += B[r + i * 30] * B[r + j * 30];
                M[i + j * 30] = x;
            }
        for (int i = 0; i < 30; i++)
            qq[i] = 2.0 * rnd(&s);
        pd_matrix A = pd_matrix_dense(30, 30, M);
        sd = solve_with(PD_LCP_STRUCTURED, &A, qq, NULL, z1, w1, &id);
        sl = solve_with(PD_LCP_LEMKE, &A, qq, NULL, z2, w1, &ic);
        CHECK(ctx, sd == PD_OK && sl == PD_OK && rel_diff(30, z1, z2) <= 1e-9,
              "full 30 x 30: status %d by %s, lemke %d", sd, id.solver, sl);
    }
    free(dense);
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
    PD_RUN(ctx, test_solvers_stieltjes_oracle);
    PD_RUN(ctx, test_solvers_stieltjes_not_taken);
    PD_RUN(ctx, test_solvers_stieltjes_large);
    PD_RUN(ctx, test_solvers_stieltjes_warm);
    PD_RUN(ctx, test_solvers_dense_banded);
    PD_RUN(ctx, test_solvers_verify_tridiagonal);
    PD_RUN(ctx, test_solvers_block_mmatrix);
}
