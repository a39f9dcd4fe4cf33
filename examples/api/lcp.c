/* lcp.c — a small LCP built in code, solved with every solver of the table
 * (auto, lemke, structured, pgs) on dense and compressed-column views of M,
 * and by Lemke's method directly.  Prints z and the status of each.  Exit 0
 * when every solve is verified and they agree.
 *
 *   find z >= 0 with w = M z + q >= 0 and z'w = 0
 *
 *   cc lcp.c $(pkg-config --cflags --libs pound) -lm -o lcp */
#include <math.h>
#include <stdio.h>

#include <pound/pound.h>

#define N 4

/* Solve with one method of the table: 0 when verified and close to zref. */
static int solve(pd_lcp_method method, const pd_matrix *M, const double *q, const double *zref,
                 const char *view)
{
    double z[N], w[N];
    pd_lcp_info info;
    pd_err err;
    pd_lcp_solver *s = pd_lcp_solver_alloc(method, N, M->kind == PD_MATRIX_CSC ? 16 : 0, &err);
    if (!s) {
        fprintf(stderr, "lcp: %s\n", err.msg);
        return 1;
    }
    int rc = pd_lcp_solve(s, M, q, NULL, z, w, &info);
    pd_lcp_solver_free(s);
    double d = 0.0;
    for (int i = 0; i < N; i++) { /* no libm call: the README's link line has no -lm */
        double di = fabs(z[i] - zref[i]);
        d = di > d ? di : d;
    }
    printf("%-10s %-5s z = [%.6f %.6f %.6f %.6f]  %s (%s, residual %.1e)\n",
           pd_lcp_method_name(method), view, z[0], z[1], z[2], z[3],
           pd_lcp_outcome_name(info.outcome), info.solver, info.residual);
    return rc == PD_OK && d < 1e-8 ? 0 : 1;
}

int main(void)
{
    /* A symmetric positive definite tridiagonal M (a row's Delassus matrix),
     * column-major, and q with two contacts closing and two opening. */
    static const double Md[N * N] = {4, -1, 0, 0, -1, 4, -1, 0, 0, -1, 4, -1, 0, 0, -1, 4};
    static const double q[N] = {-1, 2, -3, 0.5};
    static const int colptr[N + 1] = {0, 2, 5, 8, 10}, rowind[10] = {0, 1, 0, 1, 2, 1, 2, 3, 2, 3};
    static const double vals[10] = {4, -1, -1, 4, -1, -1, 4, -1, -1, 4};
    static const pd_lcp_method methods[] = {PD_LCP_AUTO, PD_LCP_LEMKE, PD_LCP_STRUCTURED,
                                            PD_LCP_PGS};
    double z[N], w[N];
    pd_lcp_info info;
    pd_lcp_work *work = pd_lcp_alloc(N);
    int bad = 0;
    if (!work)
        return 1;
    /* Lemke's method on the dense array: the reference answer */
    int rc = pd_lcp_lemke(work, N, Md, q, NULL, z, w, &info);
    pd_lcp_free(work);
    printf("lemke()    dense z = [%.6f %.6f %.6f %.6f]  %s (%d pivots)\n", z[0], z[1], z[2], z[3],
           pd_lcp_outcome_name(info.outcome), info.pivots);
    bad |= rc != PD_OK;
    pd_matrix dense = pd_matrix_dense(N, N, Md), csc = pd_matrix_csc(N, N, colptr, rowind, vals);
    for (size_t k = 0; k < sizeof methods / sizeof methods[0]; k++) {
        bad |= solve(methods[k], &dense, q, z, "dense");
        bad |= solve(methods[k], &csc, q, z, "csc");
    }
    printf("%s\n", bad ? "FAILED" : "every solver verified and agrees");
    return bad;
}
