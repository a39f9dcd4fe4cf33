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
 * letting z0 leave whenever it is among the tied rows.  For n <= 4 on a
 * processor with AVX2 the same pivots run with a column of B^-1 a vector of
 * four lanes kept in locals, and no workspace but the stack's (section
 * "n <= LEMKE_SMALL_N"): the same arithmetic, the same answers to the bit. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lcp_internal.h"
#include "pd_lcp.h"

#define LEMKE_TOL_DEFAULT 1e-12            /* relative tolerance for ties and tiny pivots */
#define LEMKE_VERIFY_TOL PD_LCP_VERIFY_TOL /* relative backward residual of a solved answer */
#define LEMKE_CAP_MIN 10000                /* default pivot cap: max(LEMKE_CAP_MIN, ... */
#define LEMKE_CAP_PER_N 100                /* ... LEMKE_CAP_PER_N * n) */
#define LEMKE_REFINE_EVERY 50              /* pivots between two refinements of x_B */
#define LEMKE_FINAL_REFINES 2              /* at most this many refinements of x_B at the end */
#define LEMKE_NMAX_LIMIT 46340             /* n*n must fit an int */
#define LEMKE_SINGULAR_TOL 1e-14           /* relative pivot floor of the final polish */
#define LEMKE_REPAIR_ROUNDS 8              /* principal solves of the final repair at most */
#define LEMKE_SMALL_N 4                    /* up to this n, a column of B^-1 in one vector */
/* GNU C vectors of four lanes for n <= LEMKE_SMALL_N where the pivoting loop
 * has an AVX2 build (LEMKE_KERNEL below), when the processor has AVX2;
 * -DLEMKE_NO_VECTORS leaves every n to the general code. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) &&       \
    !defined(LEMKE_NO_VECTORS)
#define LEMKE_VECTORS 1
#endif

enum { RATIO_RAY = -1, RATIO_NUMERICAL = -2 };

struct pd_lcp_work {
    int nmax;
    double *binv;    /* B^-1, n x n column-major with leading dimension n */
    double *xb;      /* x_B: value of the variable basic in each row */
    double *col;     /* entering column B^-1 a; the answer kept while repairing */
    double *cover;   /* all ones (the default covering vector), set once */
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
    int ld;  /* leading dimension of B^-1: n, or LEMKE_SMALL_N in vectors */
    int vec; /* in vectors (n <= LEMKE_SMALL_N, ws a lemke_small's) */
    const double *M, *q, *d;
    int unit_cover; /* d is all ones (the default) */
    double tol;     /* relative tolerance for ties and tiny pivots */
    double qmax;    /* max|q| */
    pd_lcp_work *ws;
} lemke_state;

/* The workspace of a solve in vectors, on the stack (nothing of the caller's
 * touched, nothing to clear): B^-1 with a leading dimension of
 * LEMKE_SMALL_N, so that each column, x_B and col are aligned vectors. */
typedef struct lemke_small {
    _Alignas(32) double binv[LEMKE_SMALL_N * LEMKE_SMALL_N];
    _Alignas(32) double xb[LEMKE_SMALL_N];
    _Alignas(32) double col[LEMKE_SMALL_N];
    double scratch[LEMKE_SMALL_N], rows[LEMKE_SMALL_N];
    int basis[LEMKE_SMALL_N], row_of[2 * LEMKE_SMALL_N + 1], ties[LEMKE_SMALL_N],
        perm[LEMKE_SMALL_N];
    pd_lcp_work ws;
} lemke_small;

/* "solved", "no_solution", "max_pivots", "numerical", "max_iterations". */
const char *pd_lcp_outcome_name(pd_lcp_outcome outcome)
{
    switch (outcome) {
    case PD_LCP_SOLVED:
        return "solved";
    case PD_LCP_NO_SOLUTION:
        return "no_solution";
    case PD_LCP_MAX_PIVOTS:
        return "max_pivots";
    case PD_LCP_NUMERICAL:
        return "numerical";
    case PD_LCP_MAX_ITERATIONS:
        return "max_iterations";
    default:
        return "unknown";
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
    /* n^2 must fit an int */
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
    if (!work->binv || !work->xb || !work->col || !work->cover || !work->scratch || !work->rows ||
        !work->basis || !work->row_of || !work->ties || !work->perm) {
        pd_lcp_free(work);
        return NULL;
    }
    /* the default covering vector d = 1, set once */
    for (size_t i = 0; i < n; i++)
        work->cover[i] = 1.0;
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
#define LEMKE_KERNEL                                                                               \
    __attribute__((target_clones("avx2", "default"), optimize("no-tree-loop-distribute-"           \
                                                              "patterns")))
/* Short loops stay loops (a call to memset or memcpy costs more for small n). */
#define LEMKE_LOOPS __attribute__((optimize("no-tree-loop-distribute-patterns")))
#else
#define LEMKE_KERNEL
#define LEMKE_LOOPS
#endif
/* The work of a pivot, inlined into the pivoting loop (and so into each build of it). */
#define LEMKE_INLINE static inline __attribute__((always_inline))

/* y <- y - t x; unrolled by four so that -O2 vectorises it. */
static inline __attribute__((always_inline)) void
axpy_minus(int n, double t, const double *restrict x, double *restrict y)
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
    /* out = sum_i v_i B^-1[:, i] over the nonzero v_i */
    for (int r = 0; r < n; r++)
        out[r] = 0.0;
    for (int i = 0; i < n; i++) {
        double vi = v[i];
        if (vi == 0.0) /* adds nothing */
            continue;
        int r = row_of[i];
        if (r >= 0) /* B^-1[:, i] = e_r: one entry */
            out[r] += vi;
        else
            axpy_minus(n, -vi, binv + (size_t)i * n, out); /* out += v_i B^-1[:, i] */
    }
}

/* B^-1 <- E B^-1 for the pivot (r, col): row r divided by col_r, col_i/col_r
 * times row r taken from every other row; columns with B^-1[r,c] = 0 stay. */
LEMKE_INLINE void eta_update(int n, double *binv, const double *restrict col, int r)
{
    double rp = 1.0 / col[r]; /* one division per pivot, not one per column */
    for (int c = 0; c < n; c++) {
        /* column c: bc -= (bc_r / col_r) col, then bc_r = bc_r / col_r */
        double *restrict bc = binv + (size_t)c * n;
        if (bc[r] == 0.0) /* E leaves it as it is */
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
    return var == 2 * n ? st->d : st->M + (size_t)(var - n) * (size_t)n; /* z0: d; z_j: M[:, j] */
}

/* Complementary partner: w_i <-> z_i. */
static int complement(int n, int var)
{
    return var < n ? var + n : var - n;
}

/* B = I (all w basic), x_B = q, and the column of z0, -d. */
static void start_basis(const lemke_state *st)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    memset(ws->binv, 0, (size_t)n * (size_t)n * sizeof(double));
    for (int i = 0; i < n; i++) {
        /* B^-1 = I, x_B = q, z0's column -d; w_i basic in row i */
        ws->binv[i + (size_t)i * n] = 1.0;
        ws->xb[i] = st->q[i];
        ws->col[i] = -st->d[i];
        ws->basis[i] = i;
        ws->row_of[i] = i;
    }
    /* every z_j and z0 nonbasic */
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
LEMKE_INLINE int first_leaving_row(const lemke_state *st)
{
    int n = st->n, best = 0;
    double tmax = -INFINITY;
    for (int i = 0; i < n; i++) {
        /* t_i = -q_i / d_i; t = the first largest */
        double t = st->unit_cover ? -st->q[i] : -st->q[i] / st->d[i]; /* x / 1 = x */
        if (t > tmax) {
            tmax = t;
            best = i;
        }
    }
    /* from the last row down: the largest index within tol t of t */
    for (int i = n - 1; i > best; i--)
        if ((st->unit_cover ? -st->q[i] : -st->q[i] / st->d[i]) >= tmax - st->tol * tmax)
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
    /* w_e enters: col = B^-1 e_e, column e of B^-1; z_j or z0: B^-1 a_v, negated below */
    if (var < n)
        for (int i = 0; i < n; i++)
            col[i] = ws->binv[i + (size_t)var * n];
    else
        binv_times(n, ws->binv, ws->row_of, data_column(st, var), col);
    for (int i = 0; i < n; i++) {
        /* the tableau's -a_v, max|col| and any NaN in one pass */
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
    const double *bc = ws->binv + (size_t)c * st->ld, *col = ws->col;
    int *ties = ws->ties;
    double *value = ws->scratch, vmin = INFINITY, colmin = INFINITY;
    for (int k = 0; k < nties; k++) {
        /* B^-1[t, c] / col_t over the tied rows t, its minimum, the smallest pivot */
        value[k] = bc[ties[k]] / col[ties[k]];
        vmin = value[k] < vmin ? value[k] : vmin;
        colmin = col[ties[k]] < colmin ? col[ties[k]] : colmin;
    }
    /* the column's roundoff level over the smallest pivot */
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
    /* column by column while more than one row is tied */
    for (int c = 0; c < st->n && nties > 1; c++) {
        int s = ws->row_of[c]; /* w_c basic in row s: a unit column */
        nties = s >= 0 ? lex_drop_row(ties, nties, s) : lex_filter_column(st, c, nties);
    }
    /* still tied after every column: the largest pivot col_r */
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
        if (r < 0) /* w_c nonbasic: its column of B^-1 */
            s += fabs(ws->binv[i + (size_t)c * st->ld] * st->q[c]);
        else if (r == i) /* w_c basic in row i: e_i */
            s += fabs(st->q[c]);
    }
    return s;
}

/* Whether row i ties in the ratio test with theta and slack = tol xscale
 * (blocking_row). */
LEMKE_INLINE int ties_row(const lemke_state *st, int i, double ptol, double theta, double slack)
{
    const double *col = st->ws->col;
    double gap = max2(st->ws->xb[i], 0.0) - theta * col[i]; /* x_i - theta col_i */
    /* a pivot above ptol, and gap <= 0, or within slack and within tol of the row's own terms */
    return col[i] > ptol &&
           (gap <= 0.0 || (gap <= slack && gap <= st->tol * (row_scale(st, i) + theta * col[i])));
}

static int blocking_ties(const lemke_state *st, double ptol, double theta, double slack,
                         int argmin);

/* The blocking row among col_i > ptol: theta = min max(x_i, 0)/col_i; rows whose
 * x_i - theta col_i is zero to within their rounding tie -- within tol*xscale,
 * and within tol times the terms it is made of (row_scale + theta col_i);
 * z0 leaves if it ties, else the lexicographic rule decides.  -1 if no entry
 * exceeds ptol; else theta and the row that attains it (argmin) into
 * *theta_out, *argmin_out.  The second bound keeps a row whose terms are all
 * tiny (a q_i of rounding size next to q_j of order one) from tying at the
 * scale of the others: z0 would leave with that row's x_i - theta_z0 col_i
 * < 0 left behind, all of its own size, a violation the verification
 * counts in full (issue 19). */
LEMKE_INLINE int blocking_row(const lemke_state *st, double ptol, double *theta_out,
                              int *argmin_out)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    const double *col = ws->col, *xb = ws->xb;
    double theta = INFINITY, xscale = st->qmax;
    int argmin = -1;
    for (int i = 0; i < n; i++) {
        /* theta = min max(x_i, 0) / col_i over col_i > ptol, the first row attaining
         * it; xscale = max(max|q|, max x_i) */
        double x = max2(xb[i], 0.0);
        xscale = max2(xscale, x);
        /* x_i < theta col_i: the division only for a new minimum */
        if (col[i] > ptol && x < theta * col[i]) {
            theta = x / col[i];
            argmin = i;
        }
    }
    if (argmin < 0) /* no pivot above ptol */
        return -1;
    *theta_out = theta;
    *argmin_out = argmin;
    /* Whether the blocking row ties itself matters only when another row
     * does, and none can unless col_i > ptol and gap_i <= slack (ties_row):
     * the ties, their row sizes, only then. */
    double slack = st->tol * xscale;
    for (int i = 0; i < n; i++)
        if (i != argmin && col[i] > ptol && max2(xb[i], 0.0) - theta * col[i] <= slack)
            return blocking_ties(st, ptol, theta, slack, argmin);
    return argmin;
}

/* blocking_row once theta, its row argmin and slack = tol xscale are known
 * and another row might tie: the rows that tie, and the one of them that
 * leaves. */
static int blocking_ties(const lemke_state *st, double ptol, double theta, double slack, int argmin)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    int nties = 0, z0row = ws->row_of[2 * n];
    /* the tied rows into ws->ties */
    for (int i = 0; i < n; i++)
        if (ties_row(st, i, ptol, theta, slack))
            ws->ties[nties++] = i;
    if (nties <= 1) /* argmin alone */
        return argmin;
    /* z0 leaves whenever it ties: a solution at once */
    for (int k = 0; k < nties; k++)
        if (ws->ties[k] == z0row)
            return z0row;
    return lex_choice(st, nties); /* else the lexicographic rule */
}

/* The value x_r / col_r the entering variable takes in row r: theta itself
 * when r is the blocking row and x_r > 0 (theta = max(x_r, 0) / col_r, the
 * same division), else divided here. */
LEMKE_INLINE double leaving_value(const lemke_state *st, int r, int argmin, double theta)
{
    const double *xb = st->ws->xb;
    return r == argmin && xb[r] > 0.0 ? theta : xb[r] / st->ws->col[r];
}

/* Minimum-ratio test on pivots col_i > tol max|col|; when none is that large
 * but some exceed roundoff (8 n eps max|col|), those are used rather than
 * declaring a ray on a column that is merely small.  Returns the row (its
 * leaving_value into *xr), RATIO_RAY (no positive entry above roundoff) or
 * RATIO_NUMERICAL. */
LEMKE_INLINE int ratio_test(const lemke_state *st, double colmax, double *xr)
{
    int n = st->n, argmin = -1;
    double theta = 0.0;
    /* a NaN or an infinity in the column: numerical */
    if (!isfinite(colmax))
        return RATIO_NUMERICAL;
    /* pivots above tol max|col|, else above 8 n eps max|col|
     * (a small column is no ray), else a ray */
    int r = blocking_row(st, st->tol * colmax, &theta, &argmin);
    if (r < 0)
        r = blocking_row(st, 8.0 * n * DBL_EPSILON * colmax, &theta, &argmin);
    if (r < 0)
        return RATIO_RAY;
    *xr = leaving_value(st, r, argmin, theta);
    return r;
}

/* Gauss–Jordan pivot on (r, col), xr = x_r / col_r: x_B <- E x_B, B^-1 <-
 * E B^-1 with the eta matrix E.  Returns -1 (nothing changed) if the new
 * basic value overflows. */
LEMKE_INLINE int pivot(const lemke_state *st, int r, int entering, double xr)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    const double *col = ws->col;
    if (!isfinite(xr)) /* an overflowing basic value: nothing changed */
        return -1;
    /* x_B -= x_r col, then x_r in row r */
    axpy_minus(n, xr, col, ws->xb);
    ws->xb[r] = xr;
    eta_update(n, ws->binv, col, r);
    /* the leaving variable out, the entering one basic in row r */
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
    /* res = q - sum_r x_r B[:, r]: B's column e_v for w_v, -a_v for z_j and z0 */
    for (int i = 0; i < n; i++)
        res[i] = st->q[i];
    for (int r = 0; r < n; r++) {
        int v = ws->basis[r];
        double x = ws->xb[r];
        if (x == 0.0) /* nothing to subtract */
            continue;
        if (v < n) {
            res[v] -= x; /* w_v: e_v x */
        } else {
            axpy_minus(n, -x, data_column(st, v), res); /* -(-a_v) x */
        }
    }
}

/* x_B <- x_B + B^-1 (q - B x_B): one step of iterative refinement. */
LEMKE_INLINE void refine(const lemke_state *st)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    double *res = ws->scratch, *dx = ws->col;
    /* dx = B^-1 res with B^-1 as it is: x_B += dx */
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
        z[j] = r >= 0 ? ws->xb[r] : 0.0; /* basic z_j: its x_B */
    }
    clamp_roundoff(n, z);
}

/* w = M z + q and the residual figures into info; 1 if the relative
 * backward residual is within LEMKE_VERIFY_TOL (pd_lcp_residual). */
static int verify(const lemke_state *st, const double *z, double *w, pd_lcp_info *info)
{
    pd_matrix M = {.kind = PD_MATRIX_DENSE, .rows = st->n, .cols = st->n, .values = st->M};
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
    /* A = M_SS (k x k) over B^-1's storage, rhs = -q_S */
    for (int b = 0; b < k; b++) {
        const double *mcol = st->M + (size_t)ws->ties[b] * n;
        for (int a = 0; a < k; a++)
            A[a + (size_t)b * k] = mcol[ws->ties[a]];
        rhs[b] = -st->q[ws->ties[b]];
    }
    if (pd_dense_lu(k, A, k, ws->perm, LEMKE_SINGULAR_TOL) != PD_OK) /* M_SS singular */
        return -1;
    pd_dense_lu_solve(k, A, k, ws->perm, rhs);
    /* z_S from rhs, 0 off S */
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
    /* S: the basic z_j */
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
        /* infeasible beyond the verification's tolerance: in S
         * with z_j < 0, or off S with w_j < 0 */
        int in = z[j] != 0.0;
        int flip = in ? z[j] < -LEMKE_VERIFY_TOL * zs : w[j] < -LEMKE_VERIFY_TOL * ws->rows[j];
        changed |= flip;
        if (in != flip) /* the new support: kept, or entering */
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
        /* nothing infeasible, or M_SS singular: no repair */
        if (k < 0 || support_solve(st, k, z) != 0)
            return 0;
        if (verify(st, z, w, info))
            return 1;
    }
    return 0;
}

/* x_r / col_r and 1 / col_r of the pivot that brings z0 in at row r, where
 * x_B = q and col = -d: with d all ones, -q_r and -1 (a division by -1 is
 * exact), without a division to wait for. */
LEMKE_INLINE double first_xr(const lemke_state *st, int r)
{
    return st->unit_cover ? -st->q[r] : st->q[r] / -st->d[r];
}

#ifdef LEMKE_VECTORS /* only the vector path takes the reciprocal */
LEMKE_INLINE double first_rp(const lemke_state *st, int r)
{
    return st->unit_cover ? -1.0 : 1.0 / -st->d[r];
}
#endif

/* The pivoting loop from B = I until z0 leaves, a ray, or the cap. */
LEMKE_INLINE pd_lcp_outcome pivot_loop(const lemke_state *st, int cap, int *pivots)
{
    int n = st->n, z0 = 2 * n;
    pd_lcp_work *ws = st->ws;
    /* B = I; z0 enters at the row of max -q_i / d_i */
    start_basis(st);
    int r = first_leaving_row(st);
    int leaving = ws->basis[r];
    double xr = first_xr(st, r);
    if (pivot(st, r, z0, xr) != 0)
        return PD_LCP_NUMERICAL;
    *pivots = 1; /* the pivot that brings z0 in */
    /* the complement of the variable that left enters */
    for (int entering = complement(n, leaving);; entering = complement(n, leaving)) {
        if (*pivots >= cap)
            return PD_LCP_MAX_PIVOTS;
        if (*pivots % LEMKE_REFINE_EVERY == 0) /* x_B refined every 50 pivots */
            refine(st);
        r = ratio_test(st, entering_column(st, entering), &xr);
        if (r == RATIO_RAY)
            return PD_LCP_NO_SOLUTION;
        if (r == RATIO_NUMERICAL)
            return PD_LCP_NUMERICAL;
        leaving = ws->basis[r];
        if (pivot(st, r, entering, xr) != 0)
            return PD_LCP_NUMERICAL;
        ++*pivots;
        /* z0 left: z0 = 0, the basis complementary, a solution */
        if (leaving == z0)
            return PD_LCP_SOLVED;
    }
}

/* ---- n <= LEMKE_SMALL_N: a column of B^-1 in one vector ---------------------
 * The same pivoting as above and the same arithmetic, lane by lane (no
 * contraction, no reordering: the same answers to the bit), on vectors of
 * four lanes kept in locals (registers, as far as they go): B^-1 by
 * columns, x_B, the entering column;
 * built for AVX2 alone (run_lemke_v4), once for each n = 1..4, the loops
 * over n unrolled.  Lanes past n are zero or whatever the lane arithmetic
 * makes of them, and no decision reads them.  The workspace on the stack
 * (lemke_small) keeps a copy of each vector, stored as it changes, for what
 * reads single entries: the ties and the lexicographic rule, the
 * refinement, the finish, the polish and the repair (the general code, with
 * B^-1's leading dimension 4).  A single entry is never stored alone (a
 * changed entry is blended into its vector): a vector load right after a
 * narrower store into it waits for the store to retire. */
#ifdef LEMKE_VECTORS
typedef double lemke_v4 __attribute__((vector_size(32), may_alias));
typedef long long lemke_m4 __attribute__((vector_size(32), may_alias));
#define LEMKE_UNROLL _Pragma("GCC unroll 4") /* loops over n <= 4: straight code */

/* The lane r, all bits set. */
static const lemke_m4 LEMKE_LANE[4] = {{-1, 0, 0, 0}, {0, -1, 0, 0}, {0, 0, -1, 0}, {0, 0, 0, -1}};
/* All bits set in the lanes below n. */
static const lemke_m4 LEMKE_BELOW[5] = {
    {0, 0, 0, 0}, {-1, 0, 0, 0}, {-1, -1, 0, 0}, {-1, -1, -1, 0}, {-1, -1, -1, -1}};
/* The sign bit cleared in the lanes below n, everything cleared above. */
static const lemke_m4 LEMKE_ABS_BELOW[5] = {
    {0, 0, 0, 0},
    {0x7fffffffffffffff, 0, 0, 0},
    {0x7fffffffffffffff, 0x7fffffffffffffff, 0, 0},
    {0x7fffffffffffffff, 0x7fffffffffffffff, 0x7fffffffffffffff, 0},
    {0x7fffffffffffffff, 0x7fffffffffffffff, 0x7fffffffffffffff, 0x7fffffffffffffff}};
static const lemke_v4 LEMKE_UNIT[4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};

/* Vectors pass through memory or macros, never by value through a function
 * (the ABI of a 32-byte vector differs with and without AVX). */
/* a with its lane r that of b. */
#define V4_BLEND(a, b, r)                                                                          \
    ((lemke_v4)(((lemke_m4)(a) & ~LEMKE_LANE[r]) | ((lemke_m4)(b)&LEMKE_LANE[r])))
/* All four lanes t. */
#define V4_SPLAT(t) ((lemke_v4){(t), (t), (t), (t)})
/* The n <= 4 entries of a, the other lanes 0 (built in registers). */
#define V4_LOAD_N(a, n)                                                                            \
    ((n) >= 4   ? (lemke_v4){(a)[0], (a)[1], (a)[2], (a)[3]}                                       \
     : (n) == 3 ? (lemke_v4){(a)[0], (a)[1], (a)[2], 0.0}                                          \
     : (n) == 2 ? (lemke_v4){(a)[0], (a)[1], 0.0, 0.0}                                             \
                : (lemke_v4){(a)[0], 0.0, 0.0, 0.0})

/* The vectors of the pivoting (their copies: ws->binv, ws->xb, ws->col). */
typedef struct v4_regs {
    lemke_v4 binv[LEMKE_SMALL_N]; /* column c of B^-1 */
    lemke_v4 xb, col;
} v4_regs;

/* *out = B^-1 v (binv_times), B^-1 from *reg or from its copy, v the n
 * entries of data or the lanes of *vv. */
LEMKE_INLINE void v4_binv_times(const lemke_state *st, const lemke_v4 *binv, const double *v,
                                const lemke_v4 *vv, lemke_v4 *out)
{
    const pd_lcp_work *ws = st->ws;
    lemke_v4 acc = {0.0, 0.0, 0.0, 0.0};
    LEMKE_UNROLL
    for (int i = 0; i < LEMKE_SMALL_N; i++) {
        if (i >= st->n)
            break;
        double vi = v ? v[i] : (*vv)[i];
        if (vi == 0.0)
            continue;
        int r = ws->row_of[i];
        /* w_i basic in row r: lane r gains v_i; else acc += v_i B^-1[:, i] */
        if (r >= 0)
            acc = V4_BLEND(acc, acc + vi, r);
        else
            acc = acc - (-vi) * binv[i];
    }
    *out = acc;
}

/* start_basis, and the column of z0, -d. */
LEMKE_INLINE void v4_start(const lemke_state *st, v4_regs *reg)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    LEMKE_UNROLL
    for (int c = 0; c < LEMKE_SMALL_N; c++)
        if (c < n)
            ((lemke_v4 *)ws->binv)[c] = reg->binv[c] = LEMKE_UNIT[c];
    *(lemke_v4 *)ws->xb = reg->xb = V4_LOAD_N(st->q, n);
    *(lemke_v4 *)ws->col = reg->col = -V4_LOAD_N(st->d, n);
    LEMKE_UNROLL
    for (int i = 0; i < n; i++) {
        ws->basis[i] = i;
        ws->row_of[i] = i;
    }
    for (int v = n; v <= 2 * n; v++)
        ws->row_of[v] = -1;
}

/* entering_column: max|col| over the lanes below n, NaN if one is NaN (the
 * largest of the same numbers and 0: the same as the loop's). */
LEMKE_INLINE double v4_column(const lemke_state *st, v4_regs *reg, int var)
{
    int n = st->n;
    if (var < n) {
        LEMKE_UNROLL
        for (int c = 0; c < LEMKE_SMALL_N; c++)
            if (c < n && c == var)
                reg->col = reg->binv[c];
    } else {
        v4_binv_times(st, reg->binv, data_column(st, var), NULL, &reg->col);
        reg->col = -reg->col; /* the tableau's -a_v */
    }
    *(lemke_v4 *)st->ws->col = reg->col;
    lemke_v4 a = (lemke_v4)((lemke_m4)reg->col & LEMKE_ABS_BELOW[n]); /* |col|, lanes past n 0 */
    lemke_m4 nan = (lemke_m4)(a != a);
    if (nan[0] | nan[1] | nan[2] | nan[3])
        return NAN;
    return max2(max2(a[0], a[1]), max2(a[2], a[3]));
}

/* blocking_row with ptol, and what the pivot on its row needs: x_r / col_r
 * into *xr (leaving_value) and 1 / col_r into *rp.  The divisions of the
 * minimum are made side by side ahead of it, with 1 / col; the rows that
 * might tie are found in the vectors, blocking_ties called only when one
 * might. */
LEMKE_INLINE int v4_blocking_row(const lemke_state *st, const v4_regs *reg, double ptol, double *xr,
                                 double *rp)
{
    int n = st->n, argmin = -1, positive = 0;
    lemke_v4 col = reg->col, xb = reg->xb, zero = V4_SPLAT(0.0);
    lemke_v4 x = (lemke_v4)((lemke_m4)xb & (lemke_m4)(xb > zero)); /* max(x_B, 0) */
    /* the divisions side by side, ahead of the search for the minimum */
    lemke_v4 ratio = x / col, recip = V4_SPLAT(1.0) / col;
    double theta = INFINITY, rp_min = 0.0;
    LEMKE_UNROLL
    for (int i = 0; i < n; i++) {
        if (col[i] > ptol && x[i] < theta * col[i]) {
            theta = ratio[i];
            argmin = i;
            rp_min = recip[i];
            positive = xb[i] > 0.0;
        }
    }
    if (argmin < 0)
        return -1;
    x = (lemke_v4)((lemke_m4)x & LEMKE_BELOW[n]); /* xscale: the largest of the same numbers */
    double xscale = max2(st->qmax, max2(max2(x[0], x[1]), max2(x[2], x[3])));
    double slack = st->tol * xscale;
    lemke_v4 gap = x - theta * col; /* x_i - theta col_i */
    lemke_m4 other = (lemke_m4)(col > V4_SPLAT(ptol)) & LEMKE_BELOW[n] & ~LEMKE_LANE[argmin];
    lemke_m4 maybe = other & (lemke_m4)(gap <= V4_SPLAT(slack)); /* gap <= 0 among them */
    int r = argmin;
    if (maybe[0] | maybe[1] | maybe[2] | maybe[3])
        r = blocking_ties(st, ptol, theta, slack, argmin);
    const double *xbp = st->ws->xb, *colp = st->ws->col;
    /* x_r / col_r and 1 / col_r: the minimum's own divisions when its row leaves */
    *xr = r == argmin && positive ? theta : xbp[r] / colp[r];
    *rp = r == argmin ? rp_min : 1.0 / colp[r];
    return r;
}

/* ratio_test. */
LEMKE_INLINE int v4_ratio_test(const lemke_state *st, const v4_regs *reg, double colmax, double *xr,
                               double *rp)
{
    if (!isfinite(colmax))
        return RATIO_NUMERICAL;
    int r = v4_blocking_row(st, reg, st->tol * colmax, xr, rp);
    if (r < 0)
        r = v4_blocking_row(st, reg, 8.0 * st->n * DBL_EPSILON * colmax, xr, rp);
    return r >= 0 ? r : RATIO_RAY;
}

/* pivot, with x_r / col_r and 1 / col_r given.  B^-1[r, c] is read from the
 * copy. */
LEMKE_INLINE int v4_pivot(const lemke_state *st, v4_regs *reg, int r, int entering, double xr,
                          double rp)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    lemke_v4 *copy = (lemke_v4 *)ws->binv;
    if (!isfinite(xr))
        return -1;
    /* x_B -= x_r col, lane r = x_r */
    *(lemke_v4 *)ws->xb = reg->xb = V4_BLEND(reg->xb - xr * reg->col, V4_SPLAT(xr), r);
    LEMKE_UNROLL
    for (int c = 0; c < LEMKE_SMALL_N; c++) {
        if (c >= n)
            break;
        /* column c: t = B^-1[r, c] / col_r, B^-1[:, c] -= t col, lane r = t */
        double bcr = ws->binv[r + LEMKE_SMALL_N * c];
        if (bcr == 0.0) /* E leaves it as it is */
            continue;
        double t = bcr * rp;
        copy[c] = reg->binv[c] = V4_BLEND(reg->binv[c] - t * reg->col, V4_SPLAT(t), r);
    }
    ws->row_of[ws->basis[r]] = -1;
    ws->basis[r] = entering;
    ws->row_of[entering] = r;
    if (entering < n) {
        LEMKE_UNROLL
        for (int c = 0; c < LEMKE_SMALL_N; c++)
            if (c < n && c == entering)
                copy[c] = reg->binv[c] = LEMKE_UNIT[r];
    }
    return 0;
}

/* refine: res = q - B x_B, then x_B += B^-1 res; on the vectors *reg (their
 * copy of x_B kept), or on the copies when reg is NULL. */
LEMKE_INLINE void v4_refine(const lemke_state *st, v4_regs *reg)
{
    int n = st->n;
    pd_lcp_work *ws = st->ws;
    /* res = q - B x_B as basis_residual, then x_B += B^-1 res */
    lemke_v4 res = V4_LOAD_N(st->q, n), dx, *xb = reg ? &reg->xb : (lemke_v4 *)ws->xb;
    LEMKE_UNROLL
    for (int r = 0; r < LEMKE_SMALL_N; r++) {
        if (r >= n)
            break;
        int v = ws->basis[r];
        double x = (*xb)[r];
        if (x == 0.0)
            continue;
        if (v < n) {
            res = V4_BLEND(res, res - x, v);
        } else {
            const double *a = data_column(st, v);
            res = res - (-x) * V4_LOAD_N(a, n);
        }
    }
    v4_binv_times(st, reg ? reg->binv : (const lemke_v4 *)ws->binv, NULL, &res, &dx);
    *xb += dx;
    if (reg)
        *(lemke_v4 *)ws->xb = reg->xb;
}

/* extract_z, z made in registers (no load of what was just stored). */
LEMKE_INLINE void v4_extract_z(const lemke_state *st, double *z)
{
    int n = st->n;
    const pd_lcp_work *ws = st->ws;
    double zj[LEMKE_SMALL_N], m = 0.0;
    LEMKE_UNROLL
    for (int j = 0; j < LEMKE_SMALL_N; j++) {
        if (j >= n)
            break;
        int r = ws->row_of[n + j];
        zj[j] = r >= 0 ? ws->xb[r] : 0.0;
        double a = fabs(zj[j]);
        m = a > m ? a : m; /* max|z|, as pd_lcp_max_abs */
    }
    /* negatives above -tol_verify max|z| become 0, as clamp_roundoff */
    double floor_ = -LEMKE_VERIFY_TOL * m;
    LEMKE_UNROLL
    for (int j = 0; j < LEMKE_SMALL_N; j++) {
        if (j >= n)
            break;
        z[j] = zj[j] < 0.0 && zj[j] >= floor_ ? 0.0 : zj[j];
    }
}

/* pivot_loop in the vectors. */
LEMKE_INLINE pd_lcp_outcome v4_pivot_loop(const lemke_state *st, int cap, int *pivots)
{
    int n = st->n, z0 = 2 * n;
    pd_lcp_work *ws = st->ws;
    v4_regs reg;
    v4_start(st, &reg);
    int r = first_leaving_row(st);
    int leaving = ws->basis[r];
    double xr = first_xr(st, r), rp = first_rp(st, r);
    if (v4_pivot(st, &reg, r, z0, xr, rp) != 0)
        return PD_LCP_NUMERICAL;
    *pivots = 1; /* the pivot that brings z0 in */
    for (int entering = complement(n, leaving);; entering = complement(n, leaving)) {
        if (*pivots >= cap)
            return PD_LCP_MAX_PIVOTS;
        if (*pivots % LEMKE_REFINE_EVERY == 0)
            v4_refine(st, &reg);
        r = v4_ratio_test(st, &reg, v4_column(st, &reg, entering), &xr, &rp);
        if (r == RATIO_RAY)
            return PD_LCP_NO_SOLUTION;
        if (r == RATIO_NUMERICAL)
            return PD_LCP_NUMERICAL;
        leaving = ws->basis[r];
        if (v4_pivot(st, &reg, r, entering, xr, rp) != 0)
            return PD_LCP_NUMERICAL;
        ++*pivots;
        if (leaving == z0) {
            v4_refine(st, &reg); /* finish_solved's first, on the vectors */
            return PD_LCP_SOLVED;
        }
    }
}
#endif

LEMKE_LOOPS
static pd_lcp_outcome finish_repaired(const lemke_state *st, double *z, double *w,
                                      pd_lcp_info *info);

/* A claimed solution: x_B refined until it verifies (at most LEMKE_FINAL_REFINES
 * times), else recomputed from the support (polish), else the better of the
 * two repaired (repair); solved if one verifies, else the better of the two
 * is returned as numerical.  The first refinement is never skipped: it buys
 * forward accuracy on ill-conditioned bases that the backward residual
 * alone would accept (in vectors, v4_pivot_loop makes it on its own). */
LEMKE_INLINE pd_lcp_outcome finish_solved(const lemke_state *st, int vec, double *z, double *w,
                                          pd_lcp_info *info)
{
    (void)vec; /* without LEMKE_VECTORS */
    /* refine x_B, extract z, verify: at most LEMKE_FINAL_REFINES times */
    for (int k = 0; k < LEMKE_FINAL_REFINES; k++) {
#ifdef LEMKE_VECTORS
        if (vec) {
            if (k > 0) /* the first made by v4_pivot_loop */
                v4_refine(st, NULL);
            v4_extract_z(st, z);
        } else
#endif
        {
            refine(st);
            extract_z(st, z);
        }
        if (verify(st, z, w, info))
            return PD_LCP_SOLVED;
    }
    return finish_repaired(st, z, w, info);
}

/* finish_solved once the refinements failed: the polish, the repair (cold
 * code, in no vector build). */
static pd_lcp_outcome finish_repaired(const lemke_state *st, double *z, double *w,
                                      pd_lcp_info *info)
{
    double pivoting = info->residual; /* the pivoting answer's */
    int polished = polish(st, z) == 0;
    if (polished) {
        if (verify(st, z, w, info))
            return PD_LCP_SOLVED;
        polished = info->residual < pivoting; /* kept only if better */
    }
    if (!polished) { /* the pivoting answer is the better one */
        extract_z(st, z);
        verify(st, z, w, info);
    }
    /* the better answer kept while repair overwrites z */
    double *best = st->ws->col; /* free once the pivots are over */
    memcpy(best, z, (size_t)st->n * sizeof(double));
    if (repair(st, z, w, info))
        return PD_LCP_SOLVED;
    /* no repair verified: the better answer again, with its figures */
    memcpy(z, best, (size_t)st->n * sizeof(double));
    verify(st, z, w, info);
    return PD_LCP_NUMERICAL;
}

/* The pivots from B = I and the answer they give, verified; vec and nn (=
 * st0->n) constants where they can be. */
LEMKE_INLINE pd_lcp_outcome pivot_and_finish(const lemke_state *st0, int vec, int nn, int cap,
                                             double *z, double *w, pd_lcp_info *info)
{
    lemke_state local = *st0;
    local.n = nn;
    const lemke_state *st = &local;
#ifdef LEMKE_VECTORS
    pd_lcp_outcome outcome =
        vec ? v4_pivot_loop(st, cap, &info->pivots) : pivot_loop(st, cap, &info->pivots);
#else
    pd_lcp_outcome outcome = pivot_loop(st, cap, &info->pivots);
#endif
    if (outcome == PD_LCP_SOLVED)
        return finish_solved(st, vec, z, w, info);
    /* a ray, the cap, a numerical end: the last basis's z and its figures */
    extract_z(st, z);
    verify(st, z, w, info);
    return outcome;
}

/* pivot_and_finish on the caller's workspace. */
LEMKE_KERNEL
static pd_lcp_outcome run_lemke(const lemke_state *st, int cap, double *z, double *w,
                                pd_lcp_info *info)
{
    return pivot_and_finish(st, 0, st->n, cap, z, w, info);
}

#ifdef LEMKE_VECTORS
/* pivot_and_finish in vectors on the stack, n a constant in each case; built
 * for AVX2 alone, called only where the processor has it. */
__attribute__((target("avx2"), optimize("no-tree-loop-distribute-patterns"))) static pd_lcp_outcome
run_lemke_v4(const lemke_state *st, int cap, double *z, double *w, pd_lcp_info *info)
{
    switch (st->n) {
    case 1:
        return pivot_and_finish(st, 1, 1, cap, z, w, info);
    case 2:
        return pivot_and_finish(st, 1, 2, cap, z, w, info);
    case 3:
        return pivot_and_finish(st, 1, 3, cap, z, w, info);
    default:
        return pivot_and_finish(st, 1, 4, cap, z, w, info);
    }
}
#endif

/* 0 if every one of count entries is finite, else -1: |x_k| <= DBL_MAX,
 * in pairs (GNU C vectors of two lanes, native wherever there are SIMD
 * registers) or four scalar lanes, no chain of operations to wait for. */
static int scan_finite(int count, const double *x)
{
    int k = 0, bad = 0;
#ifdef __GNUC__
    typedef double v2 __attribute__((vector_size(16), may_alias, aligned(8)));
    typedef long long m2 __attribute__((vector_size(16)));
    const v2 big = {DBL_MAX, DBL_MAX};
    const m2 sign = {0x7fffffffffffffffLL, 0x7fffffffffffffffLL};
    m2 ok = {-1, -1};
    /* |x| <= DBL_MAX with the sign bit cleared: false for an infinity or a NaN */
    for (; k + 2 <= count; k += 2) {
        v2 v = *(const v2 *)(x + k);
        ok &= (m2)((v2)((m2)v & sign) <= big);
    }
    bad = !(ok[0] & ok[1]);
#else
    int b1 = 0, b2 = 0, b3 = 0;
    for (; k + 4 <= count; k += 4) {
        bad |= !(fabs(x[k]) <= DBL_MAX);
        b1 |= !(fabs(x[k + 1]) <= DBL_MAX);
        b2 |= !(fabs(x[k + 2]) <= DBL_MAX);
        b3 |= !(fabs(x[k + 3]) <= DBL_MAX);
    }
    bad |= b1 | b2 | b3;
#endif
    /* the entries left over */
    for (; k < count; k++)
        bad |= !(fabs(x[k]) <= DBL_MAX);
    return bad ? -1 : 0;
}

/* max|q| into st->qmax and whether q >= 0 into *q_nonneg; 0 if every entry of
 * q and M is finite, else -1. */
static int scan_data(lemke_state *st, int *q_nonneg)
{
    const double *q = st->q;
    double qmax = 0.0;
    int neg = 0, bad = 0;
    for (int i = 0; i < st->n; i++) {
        double a = fabs(q[i]);
        qmax = a > qmax ? a : qmax;
        bad |= !(a <= DBL_MAX); /* an infinity or a NaN */
        neg |= q[i] < 0.0;
    }
    st->qmax = qmax;
    *q_nonneg = !neg;
    return bad ? -1 : scan_finite(st->n * st->n, st->M);
}

/* Covering vector: the user's (all entries finite and > 0), read in place, or
 * the workspace's all ones. */
static int set_cover(lemke_state *st, const double *cover)
{
    st->unit_cover = !cover; /* d = 1: the first pivot divides by nothing */
    st->d = cover ? cover : st->ws->cover;
    for (int i = 0; cover && i < st->n; i++)
        if (!(cover[i] > 0.0) || !isfinite(cover[i]))
            return -1;
    return 0;
}

/* Status code of an outcome. */
static int outcome_status(pd_lcp_outcome outcome)
{
    switch (outcome) {
    case PD_LCP_SOLVED:
        return PD_OK;
    case PD_LCP_NO_SOLUTION:
        return PD_ENOSOLUTION;
    case PD_LCP_MAX_PIVOTS:
        return PD_EMAXPIVOTS;
    default:
        return PD_ENUMERICAL;
    }
}

/* Options into the state; -1 if one is out of range. */
static int set_options(lemke_state *st, const pd_lcp_opts *opts, int *cap)
{
    pd_lcp_opts o = opts ? *opts : pd_lcp_default_opts();
    if (!(o.tol > 0.0 && o.tol < 1.0) || o.max_pivots < 0) /* tol in (0, 1), max_pivots >= 0 */
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

/* n = 2, support {s}: whether w of the other row, made as the verification
 * makes it (q_o + M_os z_s, its size |q_o| + |M_os z_s|), is below 0 beyond
 * the verification's tolerance, which would then fail. */
static int other_row_fails(const lemke_state *st, int s, double zs)
{
    int o = 1 - s;
    double p = st->M[o + 2 * s] * zs, wo = st->q[o] + p; /* w_o = q_o + M_os z_s */
    return wo < 0.0 && -wo / (fabs(st->q[o]) + fabs(p)) > LEMKE_VERIFY_TOL;
}

/* n <= 2: the supports {1}, {2}, {1, 2} by their closed forms (z_S =
 * -M_SS^-1 q_S, Cramer's rule), the first that verifies; 0 if none does
 * (Lemke's pivots then decide the outcome). */
static int small_closed_form(const lemke_state *st, double *z, double *w, pd_lcp_info *info)
{
    const double *M = st->M, *q = st->q;
    int n = st->n;
    /* s = 0: {1}, 1: {2}, 2: {1, 2} */
    for (int s = 0; s < (n == 1 ? 1 : 3); s++) {
        z[0] = z[n - 1] = 0.0;
        if (s < 2) {
            double d = M[s + (size_t)s * n];
            if (d == 0.0) /* no pivot: the next support */
                continue;
            z[s] = -q[s] / d; /* M_ss z_s = -q_s */
            if (n == 2 && other_row_fails(st, s, z[s]))
                continue;
        } else {
            double det = M[0] * M[3] - M[2] * M[1];
            if (det == 0.0)
                continue;
            /* Cramer: z = -M^-1 q */
            z[0] = (-q[0] * M[3] + q[1] * M[2]) / det;
            z[1] = (-q[1] * M[0] + q[0] * M[1]) / det;
        }
        /* z >= 0 and verified */
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
    lemke_state st = {.n = n, .ld = n, .M = M, .q = q, .ws = work};
#ifdef LEMKE_VECTORS
    lemke_small small;
    /* n <= 4 with AVX2: the workspace on the stack, B^-1 of leading dimension 4 */
    if (n <= LEMKE_SMALL_N && __builtin_cpu_supports("avx2")) {
        small.ws = (pd_lcp_work){.nmax = LEMKE_SMALL_N,
                                 .binv = small.binv,
                                 .xb = small.xb,
                                 .col = small.col,
                                 .cover = work->cover,
                                 .scratch = small.scratch,
                                 .rows = small.rows,
                                 .basis = small.basis,
                                 .row_of = small.row_of,
                                 .ties = small.ties,
                                 .perm = small.perm};
        st.ws = &small.ws;
        st.ld = LEMKE_SMALL_N;
        st.vec = 1;
    }
#endif
    int cap = 0, q_nonneg = 0;
    if (set_options(&st, opts, &cap) != 0 || scan_data(&st, &q_nonneg) != 0)
        return PD_EINVAL;
    /* q >= 0: z = 0, w = q, no pivot */
    if (q_nonneg) {
        memset(z, 0, (size_t)n * sizeof(double));
        info->outcome = verify(&st, z, w, info) ? PD_LCP_SOLVED : PD_LCP_NUMERICAL;
        return outcome_status(info->outcome);
    }
    /* n <= 2: the closed forms first, no pivot */
    if (n <= 2 && small_closed_form(&st, z, w, info)) {
        info->outcome = PD_LCP_SOLVED;
        return PD_OK;
    }
#ifdef LEMKE_VECTORS
    pd_lcp_outcome outcome =
        st.vec ? run_lemke_v4(&st, cap, z, w, info) : run_lemke(&st, cap, z, w, info);
#else
    pd_lcp_outcome outcome = run_lemke(&st, cap, z, w, info);
#endif
    info->outcome = outcome;
    return outcome_status(outcome);
}
