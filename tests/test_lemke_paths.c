/* test_lemke_paths.c — lcp/lemke.c's rarely taken paths (ties, fallbacks, the small-n vector path, the polish), each test killing a mutant of make mutate. */
#include <math.h>
#include <string.h>

#include "pd_lcp.h"
#include "pd_test.h"

#define PATHS_TOL 0x1p-40 /* tol ~ 9.1e-13 (the default's scale), a power of 2: tol x is exact */

/* Lemke on (M, q) of size n <= 10, tol given (0: the default); the status. */
static int paths_solve(int n, const double *M, const double *q, double tol, double *z, double *w,
                       pd_lcp_info *info)
{
    pd_lcp_work *work = pd_lcp_alloc(n);
    pd_lcp_opts opts = pd_lcp_default_opts();
    if (tol > 0.0)
        opts.tol = tol;
    int st = work ? pd_lcp_lemke(work, n, M, q, &opts, z, w, info) : PD_EINVAL;
    pd_lcp_free(work);
    return st;
}

/* The n = 3 problem (the vector path where the processor has AVX2) against
 * the general code on it embedded at n = 5: rows and columns 3, 4 of M are
 * e_3, e_4 and q_3 = q_4 = 0, so that w_3 = w_4 = z0 (a copy of z0's row:
 * the same max|col|, max x_B, ties; they never leave): the same status,
 * pivots and z to the bit.  Returns n = 3's pivots (-1 if a solve failed). */
static int paths_same_as_general(pd_test_ctx *ctx, const double *M, const double *q, double tol,
                                 double *z)
{
    double M5[25] = {0}, q5[5] = {q[0], q[1], q[2], 0.0, 0.0}, w[3], z5[5], w5[5];
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            M5[i + 5 * j] = M[i + 3 * j];
    M5[3 + 5 * 3] = M5[4 + 5 * 4] = 1.0;
    pd_lcp_info a, b;
    int sa = paths_solve(3, M, q, tol, z, w, &a), sb = paths_solve(5, M5, q5, tol, z5, w5, &b);
    CHECK(ctx,
          sa == PD_OK && sb == PD_OK && a.pivots == b.pivots && z5[3] == 0.0 && z5[4] == 0.0 &&
              !memcmp(z, z5, 3 * sizeof(double)),
          "n = 3 vs n = 5: status %d / %d, pivots %d / %d, z0 %.17g / %.17g", sa, sb, a.pivots,
          b.pivots, z[0], z5[0]);
    return sa == PD_OK ? a.pivots : -1;
}

/* The roundoff-level ratio test (pivots > 8 n eps max|col|) runs only when
 * the first (pivots > tol max|col|) finds none, also when that one found
 * row 0.  n = 5, M = 2 I but column 4 = (1, 2 - 2^-44, 3, 3, 2), q = (-3/4,
 * -1, 1, 1, -1): z0 enters in row 4 (q_1 = q_4 ties, the larger index),
 * then z_4 with col = (1, 2^-44, -1, -1, 2) on x_B = (1/4, 0, 2, 2, 1):
 * row 0 blocks (ratio 1/4 < 1/2), row 1's 2^-44 (ratio 0) is no pivot;
 * z0 leaves next: 3 pivots, z = (1/8, 0, 0, 0, 1/2) (w_0 = w_4 = 0), as
 * the enumeration has it (to 1e-12: w_1 = -2^-45 beside |q_1| = 1). */
static void test_lemke_small_pivot_only_without_pivot(pd_test_ctx *ctx)
{
    double M[25] = {0}, q[5] = {-0.75, -1, 1, 1, -1}, z[5], w[5], ze[5], we[5], res = NAN;
    for (int i = 0; i < 5; i++)
        M[i + 5 * i] = 2.0;
    M[0 + 5 * 4] = 1.0;
    M[1 + 5 * 4] = 2.0 - 0x1p-44;
    M[2 + 5 * 4] = M[3 + 5 * 4] = 3.0;
    pd_lcp_info info;
    int st = paths_solve(5, M, q, 0.0, z, w, &info);
    pd_lcp_residual(5, M, q, z, w, NULL, NULL, &res);
    CHECK(ctx, st == PD_OK && info.pivots == 3 && res <= 1e-10,
          "status %d, %d pivots (3 expected), residual %.3g", st, info.pivots, res);
    CHECK(ctx, pd_lcp_enumerate(5, M, q, ze, we) == PD_OK, "the enumeration finds a solution");
    for (int i = 0; i < 5; i++)
        CHECK_NEAR(ctx, z[i], ze[i], 1e-12);
    CHECK_NEAR(ctx, z[0], 0.125, 1e-12);
    CHECK_NEAR(ctx, z[4], 0.5, 1e-12);
}

/* The polish solves M_SS z_S = -q_S on the whole support of the final
 * basis, z_j basic in row 0 included.  Hilbert n = 10 (H_ij = 1/(i+j+1),
 * cond ~ 1.6e13), q = -H 1: z = 1, all 10 in the support.  The pivots'
 * x_B stays above the verification after 2 refinements; the polish's LU is
 * backward stable: residual ~ n eps (<= 1e-14; one index left out of S
 * gives ~2e-13), forward error <= cond x residual ~ 2e-3 (checked at 1e-2). */
static void test_lemke_polish_full_support_hilbert(pd_test_ctx *ctx)
{
    enum { N = 10 };
    double M[N * N], q[N], z[N], w[N], res = NAN, err = 0.0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            M[i + N * j] = 1.0 / (i + j + 1);
    for (int i = 0; i < N; i++) {
        q[i] = 0.0;
        for (int j = 0; j < N; j++)
            q[i] -= M[i + N * j];
    }
    pd_lcp_info info;
    int st = paths_solve(N, M, q, 0.0, z, w, &info);
    pd_lcp_residual(N, M, q, z, w, NULL, NULL, &res);
    for (int i = 0; i < N; i++)
        err = fmax(err, fabs(z[i] - 1.0));
    CHECK(ctx, st == PD_OK && res <= 1e-14 && err <= 1e-2,
          "status %d after %d pivots, residual %.3g, max|z - 1| %.3g", st, info.pivots, res, err);
}

/* An entry exactly tol max|col| is no pivot in the vector path either
 * (col_i > ptol, strict, as the general code's).  n = 3, tol = 2^-40, M =
 * [2 0 2-2^-39; 0 2 3; 0 0 2], q = (-1, 0, -1): z0 enters in row 2, z_2
 * with col = (2^-39, -1, 2) on x_B = (0, 1, 1): row 0's 2^-39 = tol 2 (ratio
 * 0) is skipped, z0 leaves at 1/2: 2 pivots, z = (0, 0, 1/2), residual
 * 2^-40 / 2 (w_0 = -2^-40 beside its terms |q_0| + M_02 z_2 ~ 2). */
static void test_lemke_vector_pivot_at_ptol(pd_test_ctx *ctx)
{
    static const double M[9] = {2, 0, 0, 0, 2, 0, 2 - 0x1p-39, 3, 2}, q[3] = {-1, 0, -1};
    double z[3];
    int pivots = paths_same_as_general(ctx, M, q, PATHS_TOL, z);
    CHECK(ctx, pivots == 2 && z[0] == 0.0 && z[1] == 0.0 && z[2] == 0.5,
          "%d pivots (2 expected), z = (%.17g, %.17g, %.17g)", pivots, z[0], z[1], z[2]);
}

/* A gap exactly slack = tol max(max|q|, max x_B) ties in the vector path
 * (gap <= slack, as the general code's).  n = 3, tol = 2^-40, M = [2 0 1;
 * 0 2 2; 1 0 2], q = (-1/2 - 2^-41, 0, -1): z0 enters in row 2, z_2 with
 * col = (1, 0, 2) on x_B = (1/2 - 2^-41, 1, 1): row 0 blocks at theta =
 * 1/2 - 2^-41, z0's row has gap 1 - 2 theta = 2^-40 = slack (and <= tol
 * (row size 1 + 2 theta)): it ties, z0 leaves: 2 pivots, z = (0, 0, 1/2). */
static void test_lemke_vector_tie_at_slack(pd_test_ctx *ctx)
{
    static const double M[9] = {2, 0, 1, 0, 2, 0, 1, 2, 2}, q[3] = {-0.5 - 0x1p-41, 0, -1};
    double z[3];
    int pivots = paths_same_as_general(ctx, M, q, PATHS_TOL, z);
    CHECK(ctx, pivots == 2 && z[0] == 0.0 && z[1] == 0.0 && z[2] == 0.5,
          "%d pivots (2 expected), z = (%.17g, %.17g, %.17g)", pivots, z[0], z[1], z[2]);
}

/* n = 3 reads B^-1 by its own leading dimension in the row sizes of the
 * ties (row_scale).  tol = 2^-40, M = [2 -3/2 6; 0 1/2 0; 0 -1/2 2], q =
 * (1 - 3 2^-40, -1, 0): z0 enters in row 1, z_1 with col = (2, 1/2, 1) on
 * x_B = (2 - 3 2^-40, 1, 1): row 0 blocks at theta = 1 - 3 2^-41; row 2's
 * gap 1 - theta = 1.5 tol is within slack ~ 2 tol and within tol (row size
 * |B^-1[2,1] q_1| = 1, + theta) ~ 2 tol: rows 0, 2 tie, the lexicographic
 * rule drops row 0 (w_0's unit column), w_2 leaves; then z_2 in, z0 out:
 * 3 pivots, z = (0, 2, 1/2) exactly (w = (1 - 3 2^-40, 0, 0)).  A row size
 * of 0 there makes w_0 leave: 5 pivots. */
static void test_lemke_vector_tie_row_size(pd_test_ctx *ctx)
{
    static const double M[9] = {2, 0, 0, -1.5, 0.5, -0.5, 6, 0, 2}, q[3] = {1 - 3 * 0x1p-40, -1, 0};
    double z[3];
    int pivots = paths_same_as_general(ctx, M, q, PATHS_TOL, z);
    CHECK(ctx, pivots == 3 && z[0] == 0.0 && z[1] == 2.0 && z[2] == 0.5,
          "%d pivots (3 expected), z = (%.17g, %.17g, %.17g)", pivots, z[0], z[1], z[2]);
}

/* n = 2, support {1, 2} by Cramer's rule for any det M != 0, det = 1
 * included: M = [2 1; 1 1], q = (-3, -2): z = M^-1 (3, 2) = (1, 1) exactly
 * (supports {1}: w_2 = -1/2, {2}: w_1 = -1, rejected), 0 pivots. */
static void test_lemke_closed_form_det_one(pd_test_ctx *ctx)
{
    static const double M[4] = {2, 1, 1, 1}, q[2] = {-3, -2};
    double z[2], w[2];
    pd_lcp_info info;
    int st = paths_solve(2, M, q, 0.0, z, w, &info);
    CHECK(ctx,
          st == PD_OK && info.pivots == 0 && z[0] == 1.0 && z[1] == 1.0 && w[0] == 0.0 &&
              w[1] == 0.0,
          "status %d, %d pivots (0 expected), z = (%.17g, %.17g)", st, info.pivots, z[0], z[1]);
}

void suite_lemke_paths(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_lemke_small_pivot_only_without_pivot);
    PD_RUN(ctx, test_lemke_polish_full_support_hilbert);
    PD_RUN(ctx, test_lemke_vector_pivot_at_ptol);
    PD_RUN(ctx, test_lemke_vector_tie_at_slack);
    PD_RUN(ctx, test_lemke_vector_tie_row_size);
    PD_RUN(ctx, test_lemke_closed_form_det_one);
}
