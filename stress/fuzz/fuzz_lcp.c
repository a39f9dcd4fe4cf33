/* fuzz_lcp.c — libFuzzer harness of the LCP file reader (pd_lcp_read,
 * lcp/lcp_io.c): every input is read as auto, plain and Siconos.
 *
 * Beyond the sanitizers it checks the reader's contract (docs/lcp.md §8): a
 * successful read gives 1 <= n <= 46340 and finite M and q.  A problem of
 * n <= 12 that reads is also solved by the solver table (auto, structured,
 * pgs); an answer returned as PD_OK must pass an independent check in long
 * double (z >= 0, w >= -tol r, min(|w_i|/r_i, z_i/zs) <= tol): a "solved"
 * that is not a solution is a wrong success, and aborts. */
#include <math.h>

#include "fuzz_common.h"
#include "pd_lcp.h"

#define NSMALL 12
#define TOL 1e-7L

static void verify(int n, const double *M, const double *q, const double *z)
{
    long double zs = 0.0L;
    for (int i = 0; i < n; i++) {
        if (!(z[i] >= 0.0) || !isfinite(z[i]))
            abort(); /* solved with a negative or non-finite z */
        if (z[i] > zs)
            zs = z[i];
    }
    for (int i = 0; i < n; i++) {
        long double w = q[i], r = fabsl((long double)q[i]);
        for (int j = 0; j < n; j++) {
            long double t = (long double)M[i + (long)j * n] * z[j];
            w += t;
            r += fabsl(t);
        }
        if (r == 0.0L)
            continue; /* w_i = 0 exactly */
        if (w < -TOL * r)
            abort(); /* w_i < 0: infeasible */
        long double cw = fabsl(w) / r, cz = zs > 0.0L ? z[i] / zs : 0.0L;
        if ((cw < cz ? cw : cz) > TOL)
            abort(); /* neither z_i nor w_i is zero: not complementary */
    }
}

static void solve(int n, const double *M, const double *q, pd_lcp_method method)
{
    pd_err err;
    pd_lcp_solver *s = pd_lcp_solver_alloc(method, n, 0, &err);
    if (!s)
        return;
    double z[NSMALL], w[NSMALL];
    pd_lcp_info info;
    pd_matrix A = pd_matrix_dense(n, n, M);
    if (pd_lcp_solve(s, &A, q, NULL, z, w, &info) == PD_OK)
        verify(n, M, q, z);
    pd_lcp_solver_free(s);
}

static void check(const char *path, pd_lcp_format format)
{
    int n = 0;
    double *M = NULL, *q = NULL;
    pd_err err;
    if (pd_lcp_read(path, format, &n, &M, &q, &err) != PD_OK)
        return; /* nothing is handed over on error (LeakSanitizer checks) */
    if (n < 1 || n > 46340 || !M || !q)
        abort();
    for (long i = 0; i < (long)n * n; i++)
        if (!isfinite(M[i]))
            abort(); /* non-finite data must be refused (exit 2) */
    for (int i = 0; i < n; i++)
        if (!isfinite(q[i]))
            abort();
    if (n <= NSMALL) {
        solve(n, M, q, PD_LCP_AUTO);
        solve(n, M, q, PD_LCP_STRUCTURED);
        solve(n, M, q, PD_LCP_PGS);
    }
    free(M);
    free(q);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[1024];
    fuzz_write("in.lcp", data, size, path, sizeof path);
    check(path, PD_LCP_FORMAT_AUTO);
    check(path, PD_LCP_FORMAT_PLAIN);
    check(path, PD_LCP_FORMAT_SICONOS);
    return 0;
}
