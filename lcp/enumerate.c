/* enumerate.c — brute-force LCP solver for n <= 12, the test oracle.
 *
 * Every complementary basis is a support S: z_S solves M_SS z_S = -q_S,
 * z = 0 off S, w = M z + q.  Supports are tried by increasing size, and in
 * increasing bit-mask order within one size; the first with z >= 0 and
 * w >= 0 (within ENUM_TOL of the data scale) is returned. */
#include <string.h>

#include "lcp_internal.h"
#include "pd_lcp.h"

#define ENUM_NMAX 12
#define ENUM_TOL 1e-9           /* relative backward residual of an accepted support */
#define ENUM_SINGULAR_TOL 1e-13 /* M_SS with a relative pivot below this is skipped */

/* Number of set bits of mask. */
static int popcount(unsigned mask)
{
    int count = 0;
    for (; mask; mask &= mask - 1) /* clears the lowest set bit */
        count++;
    return count;
}

/* z for the support in mask (z_S = -M_SS^-1 q_S); 0 if M_SS is nonsingular. */
static int support_solution(int n, const double *M, const double *q, unsigned mask, double *z)
{
    double A[ENUM_NMAX * ENUM_NMAX], b[ENUM_NMAX];
    int idx[ENUM_NMAX], perm[ENUM_NMAX], k = 0;
    /* idx: S in increasing order; A = M_SS, b = -q_S */
    for (int j = 0; j < n; j++)
        if (mask & (1u << j))
            idx[k++] = j;
    for (int c = 0; c < k; c++) {
        for (int r = 0; r < k; r++)
            A[r + c * k] = M[idx[r] + idx[c] * n];
        b[c] = -q[idx[c]];
    }
    if (k > 0 && pd_dense_lu(k, A, k, perm, ENUM_SINGULAR_TOL) != PD_OK) /* M_SS singular */
        return -1;
    if (k > 0)
        pd_dense_lu_solve(k, A, k, perm, b);
    memset(z, 0, (size_t)n * sizeof(double));
    /* a negative z_i of rounding size (above -ENUM_TOL) is 0 */
    for (int c = 0; c < k; c++)
        z[idx[c]] = b[c] < 0.0 && b[c] > -ENUM_TOL ? 0.0 : b[c];
    return 0;
}

/* 1 if z (with w = M z + q) satisfies the LCP within ENUM_TOL * scale. */
static int is_solution(int n, const double *M, const double *q, const double *z, double *w)
{
    double comp, infeas, residual;
    pd_lcp_residual(n, M, q, z, w, &comp, &infeas, &residual);
    return residual <= ENUM_TOL;
}

int pd_lcp_enumerate(int n, const double *M, const double *q, double *z, double *w)
{
    if (n < 1 || n > ENUM_NMAX || !M || !q || !z || !w)
        return PD_EINVAL;
    unsigned count = 1u << n;
    /* supports by size, then by mask: the first that verifies */
    for (int size = 0; size <= n; size++) {
        for (unsigned mask = 0; mask < count; mask++) {
            if (popcount(mask) != size)
                continue;
            if (support_solution(n, M, q, mask, z) == 0 && is_solution(n, M, q, z, w))
                return PD_OK;
        }
    }
    double comp, infeas, residual;
    /* none: z = 0 and its w = q reported */
    memset(z, 0, (size_t)n * sizeof(double));
    pd_lcp_residual(n, M, q, z, w, &comp, &infeas, &residual);
    return PD_ENOSOLUTION;
}
