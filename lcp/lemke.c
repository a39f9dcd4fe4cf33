/* lemke.c — Lemke's complementary pivoting method (docs/lcp.md).
 *
 * Tableau  w - M z - d z0 = q  with the covering vector d > 0.  Variables are
 * numbered w_i = i, z_j = n + j, z0 = 2n.  The basis inverse B^-1 (n x n,
 * column-major) is kept explicitly and updated by one Gauss–Jordan (rank-1)
 * step per pivot; the basic values x_B = B^-1 q are updated alongside and
 * refined against the explicit basis B at intervals and at the end.  Column i
 * of B^-1 is exactly the unit vector e_r while w_i is basic in row r, which
 * keeps a pivot at O(n k) work for k basic z's.  Ties in the ratio test are
 * broken by the lexicographic rule (rows of B^-1 scaled by the pivot column),
 * letting z0 leave whenever it is among the tied rows. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lcp_internal.h"
#include "pd_lcp.h"

#define LEMKE_TOL_DEFAULT 1e-12   /* relative tolerance for ties and tiny pivots */
#define LEMKE_VERIFY_TOL PD_LCP_VERIFY_TOL /* relative backward residual of a solved answer */
#define LEMKE_CAP_MIN 10000       /* default pivot cap: max(LEMKE_CAP_MIN, ... */
#define LEMKE_CAP_PER_N 100       /* ... LEMKE_CAP_PER_N * n) */
#define LEMKE_REFINE_EVERY 50     /* pivots between two refinements of x_B */
#define LEMKE_FINAL_REFINES 2     /* at most this many refinements of x_B at the end */
#define LEMKE_NMAX_LIMIT 46340    /* n*n must fit an int */
#define LEMKE_SINGULAR_TOL 1e-14  /* relative pivot floor of the final polish */
#define LEMKE_REPAIR_ROUNDS 8     /* principal solves of the final repair at most */

enum { RATIO_RAY = -1, RATIO_NUMERICAL = -2 };

struct pd_lcp_work {
    int nmax;
    double *binv;    /* B^-1, n x n column-major with leading dimension n */
    double *xb;      /* x_B: value of the variable basic in each row */
    double *col;     /* entering column B^-1 a; the answer kept while repairing */
    double *cover;   /* covering vector d of the current solve */
    double *scratch; /* refinement residual, polish right-hand side */
    double *rows;    /* row sizes of the verification */
    int *basis;      /* variable basic in each row */
    int *row_of;     /* row of each variable (2 nmax + 1 of them), -1 if nonbasic */
    int *ties;       /* rows tied in the ratio test; support of the polish, the repair */
    int *perm;       /* row interchanges of the polish, the repair */
};

/* Everything one solve reads: data, options, workspace. */
typedef struct lemke_state {
    int n;
    const double *M, *q, *d;
    double tol;        /* relative tolerance for ties and tiny pivots */
    double qmax;       /* max|q| */
    pd_lcp_work *ws;
} lemke_state;

/* "solved", "no_solution", "max_pivots", "numerical", "max_iterations". */
const char *pd_lcp_outcome_name(pd_lcp_outcome outcome)
{
    switch (outcome) {
    case PD_LCP_SOLVED: return "solved";
    case PD_LCP_NO_SOLUTION: return "no_solution";
    case PD_LCP_MAX_PIVOTS: return "max_pivots";
    case PD_LCP_NUMERICAL: return "numerical";
    case PD_LCP_MAX_ITERATIONS: return "max_iterations";
    default: return "unknown";
    }
}

/* Release a workspace (NULL allowed). */
void pd_lcp_free(pd_lcp_work *work)
{
    if (!work)
        return;
    free(work->binv);
    free(work->xb);
    free(work->col);
    free(work->cover);
    free(work->scratch);
    free(work->rows);
    free(work->basis);
    free(work->row_of);
    free(work->ties);
    free(work->perm);
    free(work);
}

/* One allocation per array; NULL (everything released) if any fails. */
pd_lcp_work *pd_lcp_alloc(int nmax)
{
    if (nmax < 1 || nmax > LEMKE_NMAX_LIMIT)
        return NULL;
    pd_lcp_work *work = calloc(1, sizeof *work);
    if (!work)
        return NULL;
    size_t n = (size_t)nmax;
    work->nmax = nmax;
    work->binv = malloc(n * n * sizeof(double));
    work->xb = malloc(n * sizeof(double));
    work->col = malloc(n * sizeof(double));
    work->cover = malloc(n * sizeof(double));
    work->scratch = malloc(n * sizeof(double));
    work->rows = malloc(n * sizeof(double));
    work->basis = malloc(n * sizeof(int));
    work->row_of = malloc((2 * n + 1) * sizeof(int));
    work->ties = malloc(n * sizeof(int));
    work->perm = malloc(n * sizeof(int));
    if (!work->binv || !work->xb || !work->col || !work->cover || !work->scratch ||
        !work->rows || !work->basis || !work->row_of || !work->ties || !work->perm) {
        pd_lcp_free(work);
        return NULL;
    }
    return work;
}

/* Largest n the workspace takes (0 for NULL). */
int pd_lcp_nmax(const pd_lcp_work *work)
{
    return work ? work->nmax : 0;
}

/* Larger of two numbers (operands known to be finite; cheaper than fmax). */
static double max2(double a, double b)
{
    return a > b ? a : b;
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
/* AVX2 and baseline builds of the pivoting loop (its O(n k) kernels inlined
 * into it), picked once at load time: one indirect call per solve. */
#define LEMKE_KERNEL                                                                      \
    __attribute__((target_clones("avx2", "default"), optimize("no-tree-loop-distribute-patterns")))
/* Short loops stay loops (a call to memset or memcpy costs more for small n). */
#define LEMKE_LOOPS __attribute__((optimize("no-tree-loop-distribute-patterns")))
#else
#define LEMKE_KERNEL
#define LEMKE_LOOPS
#endif
/* The work of a pivot, inlined into the pivoting loop (and so into each build of it). */
#define LEMKE_INLINE static inline __attribute__((always_inline))

/* y <- y - t x; unrolled by four so that -O2 vectorises it. */
static inline __attribute__((always_inline)) void axpy_minus(int n, double t,
                                                             const double *restrict x,
                                                             double *restrict y)
{
    int i = 0;
    for (; i + 4 <= n; i += 4) {
        y[i] -= t * x[i];
        y[i + 1] -= t * x[i + 1];
        y[i + 2] -= t * x[i + 2];
        y[i + 3] -= t * x[i + 3];
    }
    for (; i < n; i++)
        y[i] -= t * x[i];
}

/* out = B^-1 v, taking B^-1[:,i] = e_row(w_i) for every basic w_i. */
LEMKE_INLINE void binv_times(int n, const double *binv, const int *row_of, const double *v,
                       double *restrict out)
{
    for (int r = 0; r < n; r++)
        out[r] = 0.0;
    for (int i = 0; i < n; i++) {
        double vi = v[i];
        if (vi == 0.0)
            continue;
        int r = row_of[i];
        if (r >= 0)
            out[r] += vi;
        else
            axpy_minus(n, -vi, binv + (size_t)i * n, out);
    }
}

/* B^-1 <- E B^-1 for the pivot (r, col): row r divided by col_r, col_i/col_r
 * times row r taken from every other row; columns with B^-1[r,c] = 0 stay. */
LEMKE_INLINE void eta_update(int n, double *binv, const double *restrict col, int r)
{
    double rp = 1.0 / col[r]; /* one division per pivot, not one per column */
    for (int c = 0; c < n; c++) {
        double *restrict bc = binv + (size_t)c * n;
        if (bc[r] == 0.0)
            continue;
        double t = bc[r] * rp;
        axpy_minus(n, t, col, bc);
        bc[r] = t;
    }
}

/* Column a_v of the data for v = z_j (M[:,j]) or z0 (d); the tableau column is -a_v. */
static const double *data_column(const lemke_state *st, int var)
{
    int n = st->n;
    return var == 2 * n ? st->d : st->M + (size_t)(var - n) * (size_t)n;
}

/* Complementary partner: w_i <-> z_i. */
static int complement(int n, int var)
{
    return var < n ? var + n : var - n;
}

/* B = I (all w basic), x_B = q. */
static void start_basis(const lemke_state *st)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    memset(ws->binv, 0, (size_t)n * (size_t)n * sizeof(double));
    for (int i = 0; i < n; i++) {
        ws->binv[i + (size_t)i * n] = 1.0;
        ws->xb[i] = st->q[i];
        ws->basis[i] = i;
        ws->row_of[i] = i;
    }
    for (int v = n; v <= 2 * n; v++)
        ws->row_of[v] = -1;
}

/* z0 enters at t = max_i -q_i/d_i; among rows tied within tol the
 * lexicographic rule (B^-1 = I) picks the largest index.  A row ties when
 * its -q_i/d_i is within tol t of t (t > 0: some q_i < 0), not within tol
 * max|q|: z0 is then at least (1 - tol) t, so every w_i = q_i + d_i z0 left
 * basic is >= -tol |q_i|, within the rounding of its own row.  At the scale
 * of max|q| a row with q_i = 0 tied with one with q_i = -2e-16 (a zero
 * relative velocity's rounding, the only term of its row) and left that
 * w_i < 0 behind, a violation the verification counts in full (issue 19). */
static int first_leaving_row(const lemke_state *st)
{
    int n = st->n, best = 0;
    double tmax = -INFINITY;
    for (int i = 0; i < n; i++) {
        double t = -st->q[i] / st->d[i];
        if (t > tmax) {
            tmax = t;
            best = i;
        }
    }
    for (int i = n - 1; i > best; i--)
        if (-st->q[i] / st->d[i] >= tmax - st->tol * tmax)
            return i;
    return best;
}

/* col = B^-1 a_e: column e of B^-1 for w_e, -B^-1 M[:,j] for z_j, -B^-1 d
 * for z0; returns max|col| (NaN when an entry is NaN). */
LEMKE_INLINE double entering_column(const lemke_state *st, int var)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    double *col = ws->col, cmax = 0.0;
    int nan = 0;
    if (var < n)
        for (int i = 0; i < n; i++)
            col[i] = ws->binv[i + (size_t)var * n];
    else
        binv_times(n, ws->binv, ws->row_of, data_column(st, var), col);
    for (int i = 0; i < n; i++) {
        col[i] = var < n ? col[i] : -col[i];
        cmax = max2(cmax, fabs(col[i]));
        nan |= isnan(col[i]);
    }
    return nan ? NAN : cmax;
}

/* Keep the tied rows t with B^-1[t,c]/col_t within eq_c of the smallest, for a
 * column c of B^-1 that is not a unit vector; eq_c = tol max_i|B^-1[i,c]| /
 * min_t col_t is the roundoff level of that column.  Returns the rows kept. */
static int lex_filter_column(const lemke_state *st, int c, int nties)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    const double *bc = ws->binv + (size_t)c * n, *col = ws->col;
    int *ties = ws->ties;
    double *value = ws->scratch, vmin = INFINITY, colmin = INFINITY;
    for (int k = 0; k < nties; k++) {
        value[k] = bc[ties[k]] / col[ties[k]];
        vmin = value[k] < vmin ? value[k] : vmin;
        colmin = col[ties[k]] < colmin ? col[ties[k]] : colmin;
    }
    double eq = st->tol * pd_lcp_max_abs(n, bc) / colmin;
    int kept = 0;
    for (int k = 0; k < nties; k++)
        if (value[k] <= vmin + eq)
            ties[kept++] = ties[k];
    return kept;
}

/* Drop row s from the tied rows (its unit-column entry 1/col_s exceeds the 0 of
 * the others).  Returns the rows kept. */
static int lex_drop_row(int *ties, int nties, int s)
{
    int kept = 0;
    for (int k = 0; k < nties; k++)
        if (ties[k] != s)
            ties[kept++] = ties[k];
    return kept;
}

/* Lexicographic minimum of (B^-1[r,:] / col_r) over the tied rows, column by
 * column: a unit column e_s (w_c basic in row s) drops row s exactly, any other
 * column keeps the rows within roundoff of its minimum.  Rows still tied after
 * the last column: the largest pivot. */
static int lex_choice(const lemke_state *st, int nties)
{
    const pd_lcp_work *ws = st->ws;
    int *ties = ws->ties;
    for (int c = 0; c < st->n && nties > 1; c++) {
        int s = ws->row_of[c];
        nties = s >= 0 ? lex_drop_row(ties, nties, s) : lex_filter_column(st, c, nties);
    }
    int best = ties[0];
    for (int k = 1; k < nties; k++)
        if (ws->col[ties[k]] > ws->col[best])
            best = ties[k];
    return best;
}

/* The size of the terms that make x_B[i] = (B^-1 q)_i, sum_c |B^-1[i,c] q_c|
 * (the unit column of a w_c basic in row i gives |q_c|): the scale of
 * x_B[i]'s rounding. */
static double row_scale(const lemke_state *st, int i)
{
    int n = st->n;
    const pd_lcp_work *ws = st->ws;
    double s = 0.0;
    for (int c = 0; c < n; c++) {
        int r = ws->row_of[c];
        if (r < 0)
            s += fabs(ws->binv[i + (size_t)c * n] * st->q[c]);
        else if (r == i)
            s += fabs(st->q[c]);
    }
    return s;
}

/* The blocking row among col_i > ptol: theta = min max(x_i, 0)/col_i; rows whose
 * x_i - theta col_i is zero to within their rounding tie -- within tol*xscale,
 * and within tol times the terms it is made of (row_scale + theta col_i);
 * z0 leaves if it ties, else the lexicographic rule decides.  -1 if no entry
 * exceeds ptol.  The second bound keeps a row whose terms are all tiny (a
 * q_i of rounding size next to q_j of order one) from tying at the scale
 * of the others: z0 would leave with that row's x_i - theta_z0 col_i < 0
 * left behind, all of its own size, a violation the verification counts in
 * full (issue 19). */
LEMKE_INLINE int blocking_row(const lemke_state *st, double ptol)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    const double *col = ws->col, *xb = ws->xb;
    double theta = INFINITY, xscale = st->qmax;
    int argmin = -1;
    for (int i = 0; i < n; i++) {
        double x = max2(xb[i], 0.0);
        xscale = max2(xscale, x);
        if (col[i] > ptol && x < theta * col[i]) {
            theta = x / col[i];
            argmin = i;
        }
    }
    if (argmin < 0)
        return -1;
    double slack = st->tol * xscale;
    int nties = 0, z0row = ws->row_of[2 * n];
    for (int i = 0; i < n; i++) {
        double gap = max2(xb[i], 0.0) - theta * col[i];
        if (col[i] > ptol &&
            (gap <= 0.0 ||
             (gap <= slack && gap <= st->tol * (row_scale(st, i) + theta * col[i]))))
            ws->ties[nties++] = i;
    }
    if (nties <= 1)
        return argmin;
    for (int k = 0; k < nties; k++)
        if (ws->ties[k] == z0row)
            return z0row;
    return lex_choice(st, nties);
}

/* Minimum-ratio test on pivots col_i > tol max|col|; when none is that large
 * but some exceed roundoff (8 n eps max|col|), those are used rather than
 * declaring a ray on a column that is merely small.  Returns the row,
 * RATIO_RAY (no positive entry above roundoff) or RATIO_NUMERICAL. */
LEMKE_INLINE int ratio_test(const lemke_state *st, double colmax)
{
    int n = st->n;
    if (!isfinite(colmax))
        return RATIO_NUMERICAL;
    int r = blocking_row(st, st->tol * colmax);
    if (r < 0)
        r = blocking_row(st, 8.0 * n * DBL_EPSILON * colmax);
    return r >= 0 ? r : RATIO_RAY;
}

/* Gauss–Jordan pivot on (r, col): x_B <- E x_B, B^-1 <- E B^-1 with the eta
 * matrix E.  Returns -1 (nothing changed) if the new basic value overflows. */
LEMKE_INLINE int pivot(const lemke_state *st, int r, int entering)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    const double *col = ws->col;
    double xr = ws->xb[r] / col[r];
    if (!isfinite(xr))
        return -1;
    axpy_minus(n, xr, col, ws->xb);
    ws->xb[r] = xr;
    eta_update(n, ws->binv, col, r);
    ws->row_of[ws->basis[r]] = -1;
    ws->basis[r] = entering;
    ws->row_of[entering] = r;
    if (entering < n) { /* B^-1 e_i = e_r exactly once w_i is basic in row r */
        double *be = ws->binv + (size_t)entering * n;
        for (int i = 0; i < n; i++)
            be[i] = i == r ? 1.0 : 0.0;
    }
    return 0;
}

/* res = q - B x_B with the explicit basis columns (e_i, -M[:,j], -d). */
LEMKE_INLINE void basis_residual(const lemke_state *st, double *res)
{
    int n = st->n;
    const pd_lcp_work *ws = st->ws;
    for (int i = 0; i < n; i++)
        res[i] = st->q[i];
    for (int r = 0; r < n; r++) {
        int v = ws->basis[r];
        double x = ws->xb[r];
        if (x == 0.0)
            continue;
        if (v < n) {
            res[v] -= x;
        } else {
            axpy_minus(n, -x, data_column(st, v), res);
        }
    }
}

/* x_B <- x_B + B^-1 (q - B x_B): one step of iterative refinement. */
LEMKE_INLINE void refine(const lemke_state *st)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    double *res = ws->scratch, *dx = ws->col;
    basis_residual(st, res);
    binv_times(n, ws->binv, ws->row_of, res, dx);
    for (int r = 0; r < n; r++)
        ws->xb[r] += dx[r];
}

/* Negative entries within roundoff of zero (>= -tol_verify max|z|)
 * become 0; the verification that follows judges the result. */
static void clamp_roundoff(int n, double *z)
{
    double floor_ = -LEMKE_VERIFY_TOL * pd_lcp_max_abs(n, z);
    for (int j = 0; j < n; j++)
        if (z[j] < 0.0 && z[j] >= floor_)
            z[j] = 0.0;
}

/* z_j = x_B of z_j if basic, else 0, roundoff negatives cleared. */
static void extract_z(const lemke_state *st, double *z)
{
    int n = st->n;
    const pd_lcp_work *ws = st->ws;
    for (int j = 0; j < n; j++) {
        int r = ws->row_of[n + j];
        z[j] = r >= 0 ? ws->xb[r] : 0.0;
    }
    clamp_roundoff(n, z);
}

/* w = M z + q and the residual figures into info; 1 if the relative
 * backward residual is within LEMKE_VERIFY_TOL (pd_lcp_residual). */
static int verify(const lemke_state *st, const double *z, double *w, pd_lcp_info *info)
{
    pd_matrix M = pd_matrix_dense(st->n, st->n, st->M);
    pd_lcp_verify(&M, st->q, z, w, st->ws->rows, info);
    return info->residual <= LEMKE_VERIFY_TOL;
}

/* z_S = -M_SS^-1 q_S on the support S of k indices in ws->ties, z = 0 off
 * S, roundoff negatives cleared, by Gaussian elimination (overwrites B^-1);
 * -1 if M_SS is singular. */
static int support_solve(const lemke_state *st, int k, double *z)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    double *A = ws->binv, *rhs = ws->scratch;
    for (int b = 0; b < k; b++) {
        const double *mcol = st->M + (size_t)ws->ties[b] * n;
        for (int a = 0; a < k; a++)
            A[a + (size_t)b * k] = mcol[ws->ties[a]];
        rhs[b] = -st->q[ws->ties[b]];
    }
    if (pd_dense_lu(k, A, k, ws->perm, LEMKE_SINGULAR_TOL) != PD_OK)
        return -1;
    pd_dense_lu_solve(k, A, k, ws->perm, rhs);
    memset(z, 0, (size_t)n * sizeof(double));
    for (int a = 0; a < k; a++)
        z[ws->ties[a]] = rhs[a];
    clamp_roundoff(n, z);
    return 0;
}

/* Recompute the final basic solution directly: M_SS z_S = -q_S on the
 * support S of the final basis. */
static int polish(const lemke_state *st, double *z)
{
    int n = st->n, k = 0;
    pd_lcp_work *ws = st->ws;
    for (int j = 0; j < n; j++)
        if (ws->row_of[n + j] >= 0)
            ws->ties[k++] = j;
    return support_solve(st, k, z);
}

/* The support of z changed where the answer fails its own rows (w and
 * ws->rows from its verification): an index off the support whose w_i < 0
 * beyond the verification's tolerance of its row enters, one on it with
 * z_i < 0 beyond that of max|z| leaves, all at once (block principal
 * pivoting).  The new support into ws->ties, its size returned; -1 when
 * nothing is infeasible. */
static int repair_support(const lemke_state *st, const double *z, const double *w)
{
    int n = st->n, k = 0, changed = 0;
    pd_lcp_work *ws = st->ws;
    double zs = pd_lcp_max_abs(n, z);
    for (int j = 0; j < n; j++) {
        int in = z[j] != 0.0;
        int flip = in ? z[j] < -LEMKE_VERIFY_TOL * zs : w[j] < -LEMKE_VERIFY_TOL * ws->rows[j];
        changed |= flip;
        if (in != flip)
            ws->ties[k++] = j;
    }
    return changed ? k : -1;
}

/* An answer that does not verify, repaired by at most LEMKE_REPAIR_ROUNDS
 * rounds of principal pivoting from its support; 1 with z, w, info the
 * verified answer, else 0 with z, w, info those of the last round.  Lemke's
 * basic values x_B = B^-1 q carry the q_i that are below their rounding
 * (q_i = -2e-17 where others are of order one: a relative velocity that is
 * zero but for rounding) no further than that rounding, so an index whose
 * w_i = q_i + ... is lost there can end off the support with w_i < 0 at
 * the scale of its own row; one or two principal solves put it right
 * (issue 19). */
static int repair(const lemke_state *st, double *z, double *w, pd_lcp_info *info)
{
    for (int round = 0; round < LEMKE_REPAIR_ROUNDS; round++) {
        int k = repair_support(st, z, w);
        if (k < 0 || support_solve(st, k, z) != 0)
            return 0;
        if (verify(st, z, w, info))
            return 1;
    }
    return 0;
}

/* The pivoting loop from B = I until z0 leaves, a ray, or the cap. */
LEMKE_KERNEL
static pd_lcp_outcome run_pivots(const lemke_state *st, int cap, int *pivots)
{
    int n = st->n, z0 = 2 * n;
    pd_lcp_work *ws = st->ws;
    start_basis(st);
    int r = first_leaving_row(st);
    for (int i = 0; i < n; i++)
        ws->col[i] = -st->d[i];
    int leaving = ws->basis[r];
    if (pivot(st, r, z0) != 0)
        return PD_LCP_NUMERICAL;
    *pivots = 1;
    for (int entering = complement(n, leaving);; entering = complement(n, leaving)) {
        if (*pivots >= cap)
            return PD_LCP_MAX_PIVOTS;
        if (*pivots % LEMKE_REFINE_EVERY == 0)
            refine(st);
        r = ratio_test(st, entering_column(st, entering));
        if (r == RATIO_RAY)
            return PD_LCP_NO_SOLUTION;
        if (r == RATIO_NUMERICAL)
            return PD_LCP_NUMERICAL;
        leaving = ws->basis[r];
        if (pivot(st, r, entering) != 0)
            return PD_LCP_NUMERICAL;
        ++*pivots;
        if (leaving == z0)
            return PD_LCP_SOLVED;
    }
}

/* A claimed solution: x_B refined until it verifies (at most LEMKE_FINAL_REFINES
 * times), else recomputed from the support (polish), else the better of the
 * two repaired (repair); solved if one verifies, else the better of the two
 * is returned as numerical.  The first refinement is never skipped: it buys
 * forward accuracy on ill-conditioned bases that the backward residual
 * alone would accept. */
LEMKE_LOOPS
static pd_lcp_outcome finish_solved(const lemke_state *st, double *z, double *w,
                                    pd_lcp_info *info)
{
    for (int k = 0; k < LEMKE_FINAL_REFINES; k++) {
        refine(st);
        extract_z(st, z);
        if (verify(st, z, w, info))
            return PD_LCP_SOLVED;
    }
    double pivoting = info->residual;
    int polished = polish(st, z) == 0;
    if (polished) {
        if (verify(st, z, w, info))
            return PD_LCP_SOLVED;
        polished = info->residual < pivoting;
    }
    if (!polished) { /* the pivoting answer is the better one */
        extract_z(st, z);
        verify(st, z, w, info);
    }
    double *best = st->ws->col; /* free once the pivots are over */
    memcpy(best, z, (size_t)st->n * sizeof(double));
    if (repair(st, z, w, info))
        return PD_LCP_SOLVED;
    memcpy(z, best, (size_t)st->n * sizeof(double));
    verify(st, z, w, info);
    return PD_LCP_NUMERICAL;
}

/* max|x_k| over count entries; *finite cleared if one is NaN or infinite
 * (0 * x_k is NaN exactly then; four lanes so that -O2 vectorises it). */
static double scan_max_abs(int count, const double *x, int *finite)
{
    double p0 = 0.0, p1 = 0.0, p2 = 0.0, p3 = 0.0;
    int k = 0;
    for (; k + 4 <= count; k += 4) {
        p0 += 0.0 * x[k];
        p1 += 0.0 * x[k + 1];
        p2 += 0.0 * x[k + 2];
        p3 += 0.0 * x[k + 3];
    }
    for (; k < count; k++)
        p0 += 0.0 * x[k];
    if (isnan(p0 + p1 + p2 + p3))
        *finite = 0;
    return pd_lcp_max_abs(count, x);
}

/* max|q|; 0 if every entry of q and M is finite. */
static int scan_data(lemke_state *st)
{
    int finite = 1;
    st->qmax = scan_max_abs(st->n, st->q, &finite);
    scan_max_abs(st->n * st->n, st->M, &finite);
    return finite ? 0 : -1;
}

/* Covering vector: the user's (all entries finite and > 0) or all ones. */
static int set_cover(lemke_state *st, const double *cover)
{
    double *d = st->ws->cover;
    for (int i = 0; i < st->n; i++) {
        d[i] = cover ? cover[i] : 1.0;
        if (!(d[i] > 0.0) || !isfinite(d[i]))
            return -1;
    }
    st->d = d;
    return 0;
}

/* All entries of q >= 0. */
static int q_nonnegative(int n, const double *q)
{
    for (int i = 0; i < n; i++)
        if (q[i] < 0.0)
            return 0;
    return 1;
}

/* Status code of an outcome. */
static int outcome_status(pd_lcp_outcome outcome)
{
    switch (outcome) {
    case PD_LCP_SOLVED: return PD_OK;
    case PD_LCP_NO_SOLUTION: return PD_ENOSOLUTION;
    case PD_LCP_MAX_PIVOTS: return PD_EMAXPIVOTS;
    default: return PD_ENUMERICAL;
    }
}

/* Options into the state; -1 if one is out of range. */
static int set_options(lemke_state *st, const pd_lcp_opts *opts, int *cap)
{
    pd_lcp_opts o = opts ? *opts : pd_lcp_default_opts();
    if (!(o.tol > 0.0 && o.tol < 1.0) || o.max_pivots < 0)
        return -1;
    st->tol = o.tol;
    int by_size = LEMKE_CAP_PER_N * st->n; /* n <= 46340: no overflow */
    *cap = o.max_pivots > 0 ? o.max_pivots : (by_size > LEMKE_CAP_MIN ? by_size : LEMKE_CAP_MIN);
    return set_cover(st, o.cover);
}

pd_lcp_opts pd_lcp_default_opts(void)
{
    return (pd_lcp_opts){.cover = NULL,
                         .max_pivots = 0,
                         .tol = LEMKE_TOL_DEFAULT,
                         .max_iterations = 0,
                         .guess = NULL};
}

/* n <= 2: the supports {1}, {2}, {1, 2} by their closed forms (z_S =
 * -M_SS^-1 q_S, Cramer's rule), the first that verifies; 0 if none does
 * (Lemke's pivots then decide the outcome). */
static int small_closed_form(const lemke_state *st, double *z, double *w, pd_lcp_info *info)
{
    const double *M = st->M, *q = st->q;
    int n = st->n;
    for (int s = 0; s < (n == 1 ? 1 : 3); s++) {
        z[0] = z[n - 1] = 0.0;
        if (s < 2) {
            double d = M[s + (size_t)s * n];
            if (d == 0.0)
                continue;
            z[s] = -q[s] / d;
        } else {
            double det = M[0] * M[3] - M[2] * M[1];
            if (det == 0.0)
                continue;
            z[0] = (-q[0] * M[3] + q[1] * M[2]) / det;
            z[1] = (-q[1] * M[0] + q[0] * M[1]) / det;
        }
        if (z[0] >= 0.0 && z[n - 1] >= 0.0 && verify(st, z, w, info))
            return 1;
    }
    return 0;
}

/* Lemke's method on (M, q): check the input, z = 0 if q >= 0, the closed
 * forms for n <= 2, else pivot from B = I and verify the answer.  Invalid
 * input: PD_EINVAL, outcome numerical. */
int pd_lcp_lemke(pd_lcp_work *work, int n, const double *M, const double *q,
                 const pd_lcp_opts *opts, double *z, double *w, pd_lcp_info *info)
{
    pd_lcp_info local;
    if (!info)
        info = &local;
    memset(info, 0, sizeof *info);
    info->outcome = PD_LCP_NUMERICAL;
    if (!work || !M || !q || !z || !w || n < 1 || n > work->nmax)
        return PD_EINVAL;
    lemke_state st = {.n = n, .M = M, .q = q, .ws = work};
    int cap = 0;
    if (set_options(&st, opts, &cap) != 0 || scan_data(&st) != 0)
        return PD_EINVAL;
    if (q_nonnegative(n, q)) {
        memset(z, 0, (size_t)n * sizeof(double));
        info->outcome = verify(&st, z, w, info) ? PD_LCP_SOLVED : PD_LCP_NUMERICAL;
        return outcome_status(info->outcome);
    }
    if (n <= 2 && small_closed_form(&st, z, w, info)) {
        info->outcome = PD_LCP_SOLVED;
        return PD_OK;
    }
    pd_lcp_outcome outcome = run_pivots(&st, cap, &info->pivots);
    if (outcome == PD_LCP_SOLVED) {
        outcome = finish_solved(&st, z, w, info);
    } else {
        extract_z(&st, z);
        verify(&st, z, w, info);
    }
    info->outcome = outcome;
    return outcome_status(outcome);
}
