/* structured.c — the structured LCP solver for symmetric positive
 * (semi)definite M, the Delassus matrices of the engine (docs/lcp.md):
 *
 *   block principal pivoting (Judice & Pires 1994)  A guess F of the support:
 *     z_F solves M_FF z_F = -q_F, z = 0 off F, w = M z + q.  The infeasible
 *     indices (z_i < 0 in F, w_i < 0 off F) all change sides while their
 *     number keeps falling; after BPP_PATIENCE rounds without a new low only
 *     the largest does (Murty's rule, finite for every P-matrix).  Warm
 *     started from the last time step's support it ends in one or two solves.
 *   interior point (Mehrotra predictor-corrector, infeasible start)  For a
 *     cold start, or when pivoting does not settle within BPP_WARM_ROUNDS:
 *     (M + W Z^-1) dz = ..., a number of iterations that grows slowly with
 *     n, each one factorisation.  It finds the support of an impact that
 *     runs along a chain in one go, where pivoting would move it one index
 *     per solve.  Once its support guess (z_i M_ii > w_i) holds still, the
 *     pivoting finishes from it; if that fails, the point driven to the
 *     end is the answer when it verifies.
 *
 * Both factor M_FF as L D L^T in the order of the indices.  Tridiagonal
 * blocks (rows of SDOFs) use a twisted factorisation, eliminated from both
 * ends at once; others an envelope (profile) storage, row i of L from its
 * first nonzero column on, fill-in inside that envelope.  The Delassus
 * matrices of a row of structures are (block) banded in the contact order,
 * so a factorisation costs O(n b^2) for bandwidth b: linear in the length
 * of the row.  Every answer is verified (pd_lcp_verify); what does not
 * verify is handed back as numerical or max_iterations for Lemke to take
 * over. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lcp_internal.h"

#define BPP_PATIENCE 3      /* rounds without a new low before Murty's single swaps */
#define BPP_WARM_ROUNDS 4   /* pivoting rounds from a guess before the interior point */
#define BPP_SIGN_TOL 1e-11  /* z_i, w_i below -this * their scale count as infeasible */
#define BPP_PIVOT_TOL 1e-13 /* a Cholesky pivot below this * the diagonal: not positive */
#define IPM_MAX 40          /* interior-point iterations at most */
#define IPM_MU_TOL                                                                                 \
    1e-9 /* complementarity z.w / n to reach, relative to the scales,
                               before the support is handed to the pivoting */
#define IPM_MU_FINAL                                                                               \
    1e-17                 /* the same when the point itself must be the answer
                               (a singular M_FF: redundant contacts) */
#define IPM_STABLE 2      /* iterations the support guess must hold ... */
#define IPM_CROSS_MU 1e-3 /* ... with mu below this * its start, to try the pivoting */
#define IPM_CROSSINGS 3   /* such early tries at most */
#define IPM_STALLED                                                                                \
    -2                 /* interior_point: a factorisation failed on the way; the
                               point reached is valid (z, w > 0) */
#define IPM_STEP 0.995 /* fraction of the step to the boundary */
#define IPM_SHIFT 1e-8 /* regularisation of the least-squares start, times max M_ii */
#define IPM_START 0.1  /* the start's distance from the boundary, times the scales */

/* An interval a .. k of the support in the direct method for tridiagonal
 * Stieltjes matrices (stieltjes_support): its rows condensed on the two
 * ends, S (z_a, z_k) = f with S = [s11 s12; s12 s22] (a single row: s11
 * z_a = f1), when the rows a - 1 and k + 1 next to it have z = 0; zk: the
 * value of z_k then, once the interval is left behind. */
typedef struct tri_port {
    int a, k;
    double s11, s12, s22, f1, f2, zk;
} tri_port;

struct pd_bpp_work {
    int nmax;
    long envmax;
    unsigned char *inF; /* n: in the support guess */
    int *loc;           /* n: local index of a global one in F, or -1 */
    int *glob;          /* n: global index of a local one */
    int *first;         /* n: first column of the envelope of local row i */
    long *rowptr;       /* n + 1: start of row i in env */
    double *env;        /* envmax: the envelope of L, row by row */
    double *diag;       /* n: the diagonal shift of the interior point */
    double *rhs;        /* n: the local right-hand side, then z_F */
    double *rows;       /* n: row sizes of the verification */
    double *dinv;       /* n: 1 / D_ii */
    double *tmpl;       /* envmax: the envelope of the whole M (the interior point) */
    double *mii;        /* n: M_ii */
    double *rz;         /* n: 1 / z_i of the interior point */
    unsigned char *sup; /* n: the interior point's support guess */
    int crossed;        /* the interior point stopped early at a stable support */
    double mu, rmax;    /* its last z.w / n and max |w - (M z + q)| */
    int tridiagonal;    /* the loaded matrix is tridiagonal: ta, tb instead of env */
    double *ta, *tb;    /* n: its diagonal A_ii and subdiagonal A_i,i-1 (tb_0 = 0) */
    double *tl, *tu;    /* n: the twisted factor's multipliers (tri_factor) */
    double *iz, *iw, *dz, *dw, *az, *aw, *r; /* n each: the interior point's */
    tri_port *port; /* n / 2 + 1: the support's intervals (stieltjes_support) */
    int nport;      /* ... how many */
};

void pd_bpp_free(pd_bpp_work *ws)
{
    if (!ws)
        return;
    free(ws->inF);
    free(ws->loc);
    free(ws->glob);
    free(ws->first);
    free(ws->rowptr);
    free(ws->env);
    free(ws->diag);
    free(ws->rhs);
    free(ws->rows);
    free(ws->dinv);
    free(ws->tmpl);
    free(ws->mii);
    free(ws->rz);
    free(ws->sup);
    double *tri[] = {ws->ta, ws->tb, ws->tl, ws->tu};
    for (size_t k = 0; k < sizeof tri / sizeof tri[0]; k++)
        free(tri[k]);
    double *ipm[] = {ws->iz, ws->iw, ws->dz, ws->dw, ws->az, ws->aw, ws->r};
    for (size_t k = 0; k < sizeof ipm / sizeof ipm[0]; k++)
        free(ipm[k]);
    free(ws->port);
    free(ws);
}

pd_bpp_work *pd_bpp_alloc(int nmax, long envmax)
{
    pd_bpp_work *ws = calloc(1, sizeof *ws);
    if (!ws || nmax < 1 || envmax < nmax) {
        free(ws);
        return NULL;
    }
    size_t n = (size_t)nmax;
    ws->nmax = nmax;
    ws->envmax = envmax;
    ws->inF = malloc(n);
    ws->loc = malloc(n * sizeof(int));
    ws->glob = malloc(n * sizeof(int));
    ws->first = malloc(n * sizeof(int));
    ws->rowptr = malloc((n + 1) * sizeof(long));
    ws->env = malloc((size_t)envmax * sizeof(double));
    ws->diag = malloc(n * sizeof(double));
    ws->rhs = malloc(n * sizeof(double));
    ws->rows = malloc(n * sizeof(double));
    ws->dinv = malloc(n * sizeof(double));
    ws->tmpl = malloc((size_t)envmax * sizeof(double));
    ws->mii = malloc(n * sizeof(double));
    ws->rz = malloc(n * sizeof(double));
    ws->sup = malloc(n);
    ws->port = malloc((n / 2 + 1) * sizeof(tri_port));
    double **ipm[] = {&ws->iz, &ws->iw, &ws->dz, &ws->dw, &ws->az, &ws->aw,
                      &ws->r,  &ws->ta, &ws->tb, &ws->tl, &ws->tu};
    int ok = 1;
    for (size_t k = 0; k < sizeof ipm / sizeof ipm[0]; k++)
        ok &= (*ipm[k] = malloc(n * sizeof(double))) != NULL;
    if (!ok || !ws->inF || !ws->loc || !ws->glob || !ws->first || !ws->rowptr || !ws->env ||
        !ws->diag || !ws->rhs || !ws->rows || !ws->dinv || !ws->tmpl || !ws->mii || !ws->rz ||
        !ws->sup || !ws->port) {
        pd_bpp_free(ws);
        return NULL;
    }
    return ws;
}

int pd_bpp_nmax(const pd_bpp_work *ws)
{
    return ws ? ws->nmax : 0;
}

/* Entries of column j of M (the row j of a symmetric M): calls fn(i, Mij). */
#define FOR_COLUMN(M, j, I, X, BODY)                                                               \
    do {                                                                                           \
        if ((M)->kind == PD_MATRIX_CSC) {                                                          \
            for (int k_ = (M)->colptr[j]; k_ < (M)->colptr[(j) + 1]; k_++) {                       \
                int I = (M)->rowind[k_];                                                           \
                double X = (M)->values[k_];                                                        \
                BODY;                                                                              \
            }                                                                                      \
        } else {                                                                                   \
            const double *c_ = (M)->values + (size_t)(j) * (size_t)(M)->rows;                      \
            for (int I = 0; I < (M)->rows; I++) {                                                  \
                double X = c_[I];                                                                  \
                if (X != 0.0) {                                                                    \
                    BODY;                                                                          \
                }                                                                                  \
            }                                                                                      \
        }                                                                                          \
    } while (0)

/* M_FF (k local rows) into the workspace: when every row reaches back at
 * most one column, as ta, tb (ws->tridiagonal); else as an envelope, row i
 * holding columns first[i] .. i.  -1 when the envelope exceeds the
 * workspace. */
static int load_envelope(pd_bpp_work *ws, const pd_matrix *M, int k)
{
    long off = 0;
    int band = 0;
    for (int i = 0; i < k; i++) {
        int g = ws->glob[i], f = i;
        FOR_COLUMN(M, g, r, x, {
            int l = ws->loc[r];
            (void)x;
            if (l >= 0 && l < f)
                f = l;
        });
        ws->first[i] = f;
        ws->rowptr[i] = off;
        off += i - f + 1; /* row i: columns f .. i */
        band = band > i - f ? band : i - f;
    }
    ws->rowptr[k] = off;
    /* no row reaches back more than one column: three diagonals, no envelope */
    if ((ws->tridiagonal = band <= 1)) {
        for (int i = 0; i < k; i++) {
            ws->tb[i] = 0.0;
            FOR_COLUMN(M, ws->glob[i], r, x, {
                int l = ws->loc[r];
                if (l == i)
                    ws->ta[i] = x;
                else if (l >= 0 && l == i - 1)
                    ws->tb[i] = x;
            });
        }
        return 0;
    }
    if (off > ws->envmax)
        return -1;
    memset(ws->env, 0, (size_t)off * sizeof(double));
    for (int i = 0; i < k; i++) {
        double *row = ws->env + ws->rowptr[i] - ws->first[i]; /* row[j] = A_ij */
        FOR_COLUMN(M, ws->glob[i], r, x, {
            int l = ws->loc[r];
            if (l >= 0 && l <= i)
                row[l] = x;
        });
    }
    return 0;
}

/* The twisted factorisation of a tridiagonal A + diag(shift) (shift NULL:
 * none), A = N P N^T: rows above m = k/2 eliminated downwards (pivots d_i,
 * multipliers l_i = A_i,i-1 / d_i-1 in tl), rows below upwards (pivots e_j,
 * u_j = A_j+1,j / e_j+1 in tu), both into row m (pivot g).  The two
 * continued fractions are independent, so they run side by side at half
 * the latency of one.  1 / pivot in dinv; -1 when a pivot is not positive.
 * The rows are off .. off + k - 1 of ta, tb (tb[off], the coupling to the
 * row before, enters multiplied by 0), and of tl, tu, dinv; shift is
 * indexed from 0 (the interior point's, with off = 0). */
static int tri_factor(pd_bpp_work *ws, int off, int k, const double *shift)
{
    const double *a = ws->ta + off, *b = ws->tb + off;
    double *tl = ws->tl + off, *tu = ws->tu + off, *dinv = ws->dinv + off, rd = 0.0, re = 0.0;
    int m = k / 2;
    if (k == 0) /* an empty support: nothing to factor */
        return 0;
#define TRI_A(i) (shift ? a[i] + shift[i] : a[i])
    for (int s = 0; s < m; s++) {
        int i = s, j = k - 1 - s;
        /* downward: l_i = A_i,i-1 / d_i-1, d_i = A_ii - l_i A_i,i-1 */
        double l = b[i] * rd, d = TRI_A(i) - l * b[i];
        if (!(d > BPP_PIVOT_TOL * TRI_A(i)) || !(d > 0.0))
            return -1;
        tl[i] = l;
        dinv[i] = rd = 1.0 / d;
        if (j > m) {
            /* upward: u_j = A_j+1,j / e_j+1, e_j = A_jj - u_j A_j+1,j */
            double u = b[j + 1 < k ? j + 1 : 0] * re, e = TRI_A(j) - u * b[j + 1 < k ? j + 1 : 0];
            if (!(e > BPP_PIVOT_TOL * TRI_A(j)) || !(e > 0.0))
                return -1;
            tu[j] = u;
            dinv[j] = re = 1.0 / e;
        }
    }
    /* row m takes both: g = A_mm - l_m A_m,m-1 - u_m A_m+1,m */
    double bm1 = m + 1 < k ? b[m + 1] : 0.0, l = b[m] * rd, u = bm1 * re;
    double g = TRI_A(m) - l * b[m] - u * bm1;
#undef TRI_A
    if (!(g > BPP_PIVOT_TOL * (shift ? a[m] + shift[m] : a[m])) || !(g > 0.0))
        return -1;
    tl[m] = l;
    tu[m] = u;
    dinv[m] = 1.0 / g;
    return 0;
}

/* x = (N P N^T)^-1 x in place, the two halves side by side. */
static void tri_solve(const pd_bpp_work *ws, int off, int k, double *x)
{
    const double *tl = ws->tl + off, *tu = ws->tu + off, *dinv = ws->dinv + off;
    int m = k / 2;
    if (k == 0)
        return;
    double yt = 0.0, yb = 0.0; /* N y = x: down to m from both ends */
    for (int s = 0; s < m; s++) {
        int i = s, j = k - 1 - s;
        x[i] = yt = x[i] - tl[i] * yt;
        if (j > m)
            x[j] = yb = x[j] - tu[j] * yb;
    }
    double xm = (x[m] - tl[m] * yt - tu[m] * yb) * dinv[m];
    x[m] = xm;
    double xt = xm, xb = xm; /* N^T x = P^-1 y: out from m to both ends */
    for (int s = 1; s <= m; s++) {
        int i = m - s, j = m + s;
        x[i] = xt = x[i] * dinv[i] - tl[i + 1] * xt;
        if (j < k)
            x[j] = xb = x[j] * dinv[j] - tu[j - 1] * xb;
    }
}

/* A = L D L^T in place on the envelope (L unit lower triangular, D_ii on
 * the diagonal), 1 / D_ii in dinv; -1 when a pivot is not positive.  No
 * square roots: the factorisation of a chain is a continued fraction whose
 * speed is the latency of one division per row.  Row i first holds
 * u_j = L_ij D_jj, then L_ij. */
static int envelope_ldlt(pd_bpp_work *ws, int k)
{
    double *dinv = ws->dinv, last = 0.0; /* last: 1 / D of the row before */
    for (int i = 0; i < k; i++) {
        int fi = ws->first[i];
        double *ri = ws->env + ws->rowptr[i] - fi, a = ri[i], d = a;
        if (fi == i - 1) { /* one off-diagonal entry: a chain */
            double u = ri[i - 1], l = u * last;
            ri[i - 1] = l;
            d -= u * l;
        } else if (fi < i) {
            for (int j = fi; j < i; j++) { /* u_j = A_ij - sum_c u_c L_jc */
                int fj = ws->first[j], lo = fi > fj ? fi : fj;
                const double *rj = ws->env + ws->rowptr[j] - fj;
                double s = ri[j];
                for (int c = lo; c < j; c++)
                    s -= ri[c] * rj[c];
                ri[j] = s;
            }
            for (int j = fi; j < i; j++) { /* L_ij = u_j / D_jj, D_ii -= u_j L_ij */
                double u = ri[j];
                ri[j] = u * dinv[j];
                d -= u * ri[j];
            }
        }
        /* a pivot below 1e-13 of its diagonal entry: not positive definite to rounding */
        if (!(d > BPP_PIVOT_TOL * a) || !(d > 0.0))
            return -1;
        ri[i] = d;
        dinv[i] = last = 1.0 / d;
    }
    return 0;
}

/* x = (L D L^T)^-1 x in place.  Along a chain the value of the row before
 * stays in a register (y, zi): the sweeps run at the latency of one
 * multiply-add per row. */
static void envelope_solve(const pd_bpp_work *ws, int k, double *x)
{
    const double *dinv = ws->dinv;
    double y = 0.0;
    for (int i = 0; i < k; i++) { /* L y = x, row by row */
        int fi = ws->first[i];
        const double *ri = ws->env + ws->rowptr[i] - fi;
        double s = x[i];
        if (fi == i - 1)
            s -= ri[i - 1] * y;
        else
            for (int c = fi; c < i; c++)
                s -= ri[c] * x[c];
        x[i] = y = s;
    }
    for (int i = 0; i < k; i++) /* D^-1 y */
        x[i] *= dinv[i];
    double zi = k > 0 ? x[k - 1] : 0.0; /* z_i, final */
    for (int i = k - 1; i > 0; i--) {   /* L^T z = D^-1 y: column i of L^T is row i of L */
        int fi = ws->first[i];
        const double *ri = ws->env + ws->rowptr[i] - fi;
        if (fi == i - 1) {
            zi = x[i - 1] - ri[i - 1] * zi;
            x[i - 1] = zi;
        } else {
            for (int c = fi; c < i; c++)
                x[c] -= ri[c] * zi;
            zi = x[i - 1];
        }
    }
}

/* x = A^-1 x with the factor in the workspace. */
static void factor_solve(const pd_bpp_work *ws, int k, double *x)
{
    if (ws->tridiagonal)
        tri_solve(ws, 0, k, x);
    else
        envelope_solve(ws, k, x);
}

/* ---- tridiagonal Stieltjes matrices: a direct method ----------------------- *
 * M tridiagonal and symmetric, with a positive diagonal and off-diagonal
 * entries <= 0: once positive definite, a Stieltjes matrix (a symmetric
 * M-matrix), as is the Delassus matrix of a row of bodies with a contact
 * between each two neighbours.  Then M_FF^-1 >= 0 for every F, and the LCP
 * is solved by Chandrasekaran's method: an index with w_i < 0 joins the
 * support F, z_F = -M_FF^-1 q_F, until no w_i < 0 is left.  z only grows
 * (the change solves M_FF dz_F = -w_i e_i >= 0), no index ever leaves, and
 * the end is the LCP's solution (the least element of the feasible set),
 * whatever order the indices join in.
 *
 * stieltjes_support runs it in one sweep from the first row to the last.
 * The support is a stack of intervals (its components), each condensed on
 * its two end rows (tri_port).  Row j joins when w_j = q_j + M_j,j-1 z_j-1
 * < 0; that raises z along its interval, and the only w that can then fall
 * below 0 is that of the row just left of the interval: it joins too,
 * merging with the interval before it when they touch, and so on to the
 * left.  Rows to the right of j are not seen yet (z = 0 there).  Each row
 * joins at most once, and each join is one merge, O(1): the eliminations of
 * the two rows where two intervals meet.  So the sweep is O(n) whatever the
 * data, where pivoting moves an impact along a chain one index per solve
 * and the interior point takes a number of iterations that grows with n.
 * Its tests compare w's numerators with the end values' common denominator
 * (the determinant of the condensed system), so that a row that joins the
 * interval on top costs one division.  The sweep also reads M, column by
 * column, and gives up at the first column that does not fit.
 *
 * Then z is solved on the support by the twisted factorisation, interval by
 * interval, and verified as every other answer.  Condensation is Gaussian
 * elimination in another order, backward stable on a positive definite
 * matrix; a pivot below BPP_PIVOT_TOL times its diagonal entry (a singular
 * M_FF: redundant contacts) ends the method, and the general one takes the
 * problem. */

#define STIELTJES_SYM 1e-12 /* M_i,i-1 and M_i-1,i equal to this, relative */

/* The interval L followed by R (R->a = L->k + 1, beta = M_R->a,L->k) into
 * *out (which may be R): rows c = L->k and d = R->a eliminated from the
 * system of the four ends (a single-row interval has one); -1 when a pivot
 * is not positive. */
static inline int port_merge(const pd_bpp_work *ws, const tri_port *L, const tri_port *R,
                             double beta, tri_port *out)
{
    /* row a: a1 z_a + m z_d = f; row d gains dd on its diagonal, df on its
     * right-hand side, once row c is eliminated */
    double a1 = L->s11, m = beta, f = L->f1, dd = 0.0, df = 0.0;
    if (L->a < L->k) {
        if (!(L->s22 > BPP_PIVOT_TOL * ws->ta[L->k]))
            return -1;
        double r = 1.0 / L->s22, lb = beta * r;
        a1 -= L->s12 * L->s12 * r;
        f -= L->s12 * L->f2 * r;
        m = -L->s12 * lb;
        dd = -beta * lb;
        df = -L->f2 * lb;
    }
    double p = R->s11 + dd, h = R->f1 + df;
    tri_port o = {.a = L->a, .k = R->k};
    if (R->a == R->k) { /* d is the new end */
        o.s11 = a1;
        o.s12 = m;
        o.s22 = p;
        o.f1 = f;
        o.f2 = h;
    } else { /* eliminate row d */
        if (!(p > BPP_PIVOT_TOL * ws->ta[R->a]))
            return -1;
        double r = 1.0 / p, mr = m * r, sr = R->s12 * r;
        o.s11 = a1 - m * mr;
        o.s12 = -R->s12 * mr;
        o.s22 = R->s22 - R->s12 * sr;
        o.f1 = f - h * mr;
        o.f2 = R->f2 - h * sr;
    }
    *out = o;
    return 0;
}

/* The end values of an interval with zero neighbours as z_a = *na / *den,
 * z_k = *nk / *den, *den > 0; -1 when a pivot is not positive. */
static inline int port_ends(const pd_bpp_work *ws, const tri_port *p, double *na, double *nk,
                            double *den)
{
    if (p->a == p->k) { /* s11 = M_aa > 0 */
        *na = *nk = p->f1;
        *den = p->s11;
        return 0;
    }
    /* Cramer on S (z_a, z_k) = (f1, f2): den = det S */
    *den = p->s11 * p->s22 - p->s12 * p->s12;
    *na = p->s22 * p->f1 - p->s12 * p->f2;
    *nk = p->s11 * p->f2 - p->s12 * p->f1;
    return p->s11 > BPP_PIVOT_TOL * ws->ta[p->a] && *den > BPP_PIVOT_TOL * p->s11 * ws->ta[p->k]
               ? 0
               : -1;
}

/* w_g = q_g + M_g,g-1 z_g-1 of a row g with z_g = 0 before the interval
 * on top (z_g-1 from the last interval left behind, if it ends at g - 1);
 * 0 for g < 0. */
static inline double gap_w(const double *q, const double *b, const tri_port *st, int depth, int g)
{
    if (g < 0)
        return 0.0;
    return q[g] + (depth > 0 && st[depth - 1].k == g - 1 ? b[g] * st[depth - 1].zk : 0.0);
}

/* Chandrasekaran's method in one sweep (above), reading M as it goes: its
 * diagonal into ta and subdiagonal into tb (tb[0] = 0), the support's
 * intervals into ws->port.  1 when done; 0 when M is not in compressed
 * columns, tridiagonal, symmetric (to STIELTJES_SYM), with a positive
 * diagonal and off-diagonal entries <= 0; -1 when a pivot is not
 * positive. */
static int stieltjes_support(pd_bpp_work *ws, const pd_matrix *M, const double *q)
{
    int n = M->rows, depth = 0, has = 0;
    const int *cp = M->colptr, *ri = M->rowind;
    const double *v = M->values;
    double *a = ws->ta, *b = ws->tb, na = 0.0, nk = 0.0, den = 1.0, c0 = 0.0;
    tri_port *st = ws->port, t = {.a = -2, .k = -2}; /* t: the interval on top */
    if (M->kind != PD_MATRIX_CSC)
        return 0;
    b[0] = 0.0;
    for (int j = 0; j < n; j++) {
        double d = 0.0, up = 0.0, lo = 0.0; /* column j: M_jj, M_j-1,j, M_j+1,j */
        for (int k = cp[j]; k < cp[j + 1]; k++) {
            int i = ri[k];
            if (i == j)
                d = v[k];
            else if (i == j - 1)
                up = v[k];
            else if (i == j + 1 && i < n)
                lo = v[k];
            else
                return 0;
        }
        /* a Stieltjes column: M_jj > 0, off-diagonal entries <= 0, M_j-1,j = M_j,j-1 */
        if (!(d > 0.0) || !(up <= 0.0) || !(lo <= 0.0) ||
            !(fabs(up - b[j]) <= STIELTJES_SYM * -(up + b[j]))) /* NaN fails */
            return 0;
        a[j] = d;
        if (j + 1 < n)
            b[j + 1] = lo;
        /* row j: w_j = q_j + M_j,j-1 z_j-1 (z_j-1 = nk / den on top) */
        int touch = has && t.k == j - 1;
        if (!(touch ? q[j] * den + b[j] * nk < 0.0 : q[j] < 0.0))
            continue; /* w_j >= 0 with z_j = 0 (or NaN: verification refuses it) */
        /* row j joins, an interval of its own: M_jj z_j = -q_j */
        tri_port one = {.a = j, .k = j, .s11 = d, .f1 = -q[j]};
        if (touch) { /* next to the interval on top: merged */
            if (port_merge(ws, &t, &one, b[j], &t))
                return -1;
        } else {
            if (has) { /* t is left behind: its right end value is final */
                t.zk = nk / den;
                st[depth++] = t;
            }
            t = one;
            has = 1;
            c0 = gap_w(q, b, st, depth, j - 1);
        }
        for (;;) { /* z rose along t: the row g left of it joins when
                      w_g = c0 + M_g,a z_a < 0, c0 = q_g + M_g,g-1 z_g-1 */
            if (port_ends(ws, &t, &na, &nk, &den))
                return -1;
            int g = t.a - 1;
            if (g < 0 || !(c0 * den + b[t.a] * na < 0.0))
                break;
            int left = depth > 0 && st[depth - 1].k == g - 1;
            one = (tri_port){.a = g, .k = g, .s11 = a[g], .f1 = -q[g]};
            if (port_merge(ws, &one, &t, b[t.a], &t) ||
                (left && port_merge(ws, &st[--depth], &t, b[g], &t)))
                return -1;
            c0 = gap_w(q, b, st, depth, t.a - 1);
        }
    }
    if (has)
        st[depth++] = t; /* the last interval */
    ws->nport = depth;
    return 1;
}

/* tri_factor and tri_solve of the interval off .. off + k - 1 with the
 * right-hand side -q, fused: the forward substitution runs beside the
 * factorisation (its y into z) and the back substitution stores z clamped
 * at 0 (as accept does), so that z is made in two passes instead of four.
 * The same operations in the same order as tri_factor, tri_solve and
 * accept, so the same bits; the multipliers are made again on the way
 * back rather than stored and read.  max z of the interval, or -1 when a
 * pivot is not positive. */
static double tri_factor_solve(pd_bpp_work *ws, int off, int k, const double *q, double *z)
{
    const double *a = ws->ta + off, *b = ws->tb + off;
    double *dinv = ws->dinv + off, *x = z + off;
    double rd = 0.0, re = 0.0, yt = 0.0, yb = 0.0, zmax = 0.0;
    int m = k / 2;
    q += off;
    for (int s = 0; s < m; s++) {
        int i = s, j = k - 1 - s;
        double l = b[i] * rd, d = a[i] - l * b[i];
        if (!(d > BPP_PIVOT_TOL * a[i]) || !(d > 0.0))
            return -1.0;
        dinv[i] = rd = 1.0 / d;
        x[i] = yt = -q[i] - l * yt;
        if (j > m) {
            double bj = b[j + 1 < k ? j + 1 : 0], u = bj * re, e = a[j] - u * bj;
            if (!(e > BPP_PIVOT_TOL * a[j]) || !(e > 0.0))
                return -1.0;
            dinv[j] = re = 1.0 / e;
            x[j] = yb = -q[j] - u * yb;
        }
    }
    double bm1 = m + 1 < k ? b[m + 1] : 0.0, l = b[m] * rd, u = bm1 * re;
    double g = a[m] - l * b[m] - u * bm1;
    if (!(g > BPP_PIVOT_TOL * a[m]) || !(g > 0.0))
        return -1.0;
    dinv[m] = 1.0 / g;
    double xm = (-q[m] - l * yt - u * yb) * dinv[m], xt = xm, xb = xm;
    x[m] = xm > 0.0 ? xm : 0.0;
    zmax = x[m];
    /* the multipliers again, not stored: tri_factor's tl_i+1 = b_i+1 / d_i
     * and tu_j-1 = b_j / e_j, the same products */
    for (int s = 1; s <= m; s++) {
        int i = m - s, j = m + s;
        xt = x[i] * dinv[i] - b[i + 1] * dinv[i] * xt;
        x[i] = xt > 0.0 ? xt : 0.0;
        zmax = x[i] > zmax ? x[i] : zmax;
        if (j < k) {
            xb = x[j] * dinv[j] - b[j] * dinv[j] * xb;
            x[j] = xb > 0.0 ? xb : 0.0;
            zmax = x[j] > zmax ? x[j] : zmax;
        }
    }
    return zmax;
}

/* z on the support of stieltjes_support (0 elsewhere), clamped at 0, by
 * the twisted factorisation of each interval: max z, or -1 when a pivot
 * is not positive. */
static double stieltjes_solve(pd_bpp_work *ws, int n, const double *q, double *z)
{
    int done = 0; /* z is set below this */
    double zs = 0.0;
    for (int p = 0; p < ws->nport; p++) {
        int s = ws->port[p].a, k = ws->port[p].k - s + 1;
        memset(z + done, 0, (size_t)(s - done) * sizeof(double)); /* z = 0 between intervals */
        double zk = tri_factor_solve(ws, s, k, q, z);
        if (zk < 0.0)
            return -1.0;
        zs = zk > zs ? zk : zs;
        done = s + k;
    }
    memset(z + done, 0, (size_t)(n - done) * sizeof(double));
    return zs;
}

int pd_bpp_stieltjes(pd_bpp_work *ws, const pd_matrix *M, const double *q, double *z, double *zs)
{
    int rc = M->rows <= ws->nmax ? stieltjes_support(ws, M, q) : 0;
    if (rc <= 0)
        return rc;
    return (*zs = stieltjes_solve(ws, M->rows, q, z)) < 0.0 ? -1 : 1;
}

/* z on F from the principal system, w = M z + q with the row sizes; the
 * number of unknowns in F, or -1 (envelope too large), -2 (not positive). */
static int principal_solve(pd_bpp_work *ws, const pd_matrix *M, const double *q, double *z,
                           double *w)
{
    int n = M->rows, k = 0;
    for (int i = 0; i < n; i++) {
        ws->loc[i] = -1; /* i's place in F, or -1; glob: the inverse */
        if (ws->inF[i]) {
            ws->loc[i] = k;
            ws->glob[k++] = i;
        }
    }
    if (load_envelope(ws, M, k))
        return -1;
    if (ws->tridiagonal ? tri_factor(ws, 0, k, NULL) : envelope_ldlt(ws, k))
        return -2;
    /* M_FF z_F = -q_F */
    for (int l = 0; l < k; l++)
        ws->rhs[l] = -q[ws->glob[l]];
    factor_solve(ws, k, ws->rhs);
    memset(z, 0, (size_t)n * sizeof(double));
    for (int l = 0; l < k; l++)
        z[ws->glob[l]] = ws->rhs[l];
    for (int i = 0; i < n; i++) {
        /* w = M z + q and the row sizes, over F's columns */
        w[i] = q[i];
        ws->rows[i] = fabs(q[i]);
    }
    for (int l = 0; l < k; l++) {
        int j = ws->glob[l];
        double zj = z[j];
        FOR_COLUMN(M, j, r, x, {
            w[r] += x * zj;
            ws->rows[r] += fabs(x * zj);
        });
    }
    return k;
}

/* Mark the infeasible indices (in F: z_i < 0; off F: w_i < 0, each below
 * its rounding level); their number, the largest in *last. */
static int infeasible(const pd_bpp_work *ws, int n, const double *z, const double *w,
                      unsigned char *flag, int *last)
{
    double zs = pd_lcp_max_abs(n, z);
    int count = 0;
    *last = -1;
    for (int i = 0; i < n; i++) {
        /* below -1e-11 of the scale (max |z|, or the row size
         * r_i): a rounding of 0 is not infeasible */
        flag[i] = ws->inF[i] ? z[i] < -BPP_SIGN_TOL * zs : w[i] < -BPP_SIGN_TOL * ws->rows[i];
        if (flag[i]) {
            count++;
            *last = i;
        }
    }
    return count;
}

/* Pivoting rounds from the support in ws->inF: 0 with z, w the answer
 * (not yet verified), -1 (M_FF not positive, or the envelope too large),
 * or 1 when `rounds` rounds did not settle.  *iterations counts the solves. */
static int pivot_rounds(pd_bpp_work *ws, const pd_matrix *M, const double *q, int rounds, double *z,
                        double *w, unsigned char *flag, int *iterations)
{
    int n = M->rows, best = n + 1, patience = BPP_PATIENCE;
    for (int round = 0; round < rounds; round++) {
        int last, k = principal_solve(ws, M, q, z, w);
        ++*iterations;
        if (k < 0)
            return -1;
        int count = infeasible(ws, n, z, w, flag, &last);
        if (count == 0)
            return 0;
        if (count < best) { /* a new low: every infeasible index changes sides */
            best = count;
            patience = BPP_PATIENCE;
        } else if (patience > 0) {
            patience--;
        } else { /* Murty: only the largest */
            memset(flag, 0, (size_t)n);
            flag[last] = 1;
        }
        /* the flagged indices change sides */
        for (int i = 0; i < n; i++)
            ws->inF[i] ^= flag[i];
    }
    return 1;
}

/* y = M x. */
static void matvec(const pd_matrix *M, const double *x, double *y)
{
    memset(y, 0, (size_t)M->rows * sizeof(double));
    for (int j = 0; j < M->cols; j++)
        if (x[j] != 0.0)
            FOR_COLUMN(M, j, r, v, y[r] += v * x[j]);
}

/* y = M x for the interior point, whose M is loaded whole (ipm_pattern):
 * three diagonals when tridiagonal. */
static void ipm_matvec(const pd_bpp_work *ws, const pd_matrix *M, const double *x, double *y)
{
    int n = M->rows;
    if (!ws->tridiagonal) {
        matvec(M, x, y);
        return;
    }
    const double *a = ws->ta, *b = ws->tb;
    y[0] = a[0] * x[0];
    for (int i = 1; i < n; i++) {
        /* M symmetric: row i takes M_i,i-1 x_i-1, row i - 1 takes M_i-1,i x_i */
        y[i] = a[i] * x[i] + b[i] * x[i - 1];
        y[i - 1] += b[i] * x[i];
    }
}

/* dw = c - w - (w / z) dz, with c NULL: 0, then the largest step in
 * (0, 1] keeping z + a dz and w + a dw positive. */
static double step_to_boundary(int n, const double *z, const double *dz, const double *w,
                               const double *ratio, const double *c, double *dw)
{
    double a = 1.0;
    for (int i = 0; i < n; i++) { /* z + a dz < 0 only when dz < 0 (z > 0) */
        dw[i] = (c ? c[i] : 0.0) - w[i] - ratio[i] * dz[i];
        if (z[i] + a * dz[i] < 0.0)
            a = -z[i] / dz[i];
        if (w[i] + a * dw[i] < 0.0)
            a = -w[i] / dw[i];
    }
    return a;
}

/* The whole M loaded once for the interior point, whose factorisations
 * change only the diagonal: an envelope is kept in tmpl.  -1 when it is
 * too large. */
static int ipm_pattern(pd_bpp_work *ws, const pd_matrix *M)
{
    int n = M->rows;
    for (int i = 0; i < n; i++)
        ws->loc[i] = ws->glob[i] = i;
    if (load_envelope(ws, M, n))
        return -1;
    if (!ws->tridiagonal)
        memcpy(ws->tmpl, ws->env, (size_t)ws->rowptr[n] * sizeof(double));
    return 0;
}

/* The factor of M + diag(shift) on the pattern of ipm_pattern; -1 when a
 * pivot is not positive. */
static int ipm_factor(pd_bpp_work *ws, int n, const double *shift)
{
    if (ws->tridiagonal)
        return tri_factor(ws, 0, n, shift);
    memcpy(ws->env, ws->tmpl, (size_t)ws->rowptr[n] * sizeof(double));
    /* the shift on the diagonal, the last entry of row i's envelope */
    for (int i = 0; i < n; i++)
        ws->env[ws->rowptr[i] + i - ws->first[i]] += shift[i];
    return envelope_ldlt(ws, n);
}

/* The start: the (regularised) least-squares solution of M z = -q moved
 * inside the positive orthant, w = M z + q likewise; -1 if the factor fails. */
static int ipm_start(pd_bpp_work *ws, const pd_matrix *M, const double *q, double qs, double ds)
{
    int n = M->rows;
    double *z = ws->iz, *w = ws->iw;
    for (int i = 0; i < n; i++) {
        ws->diag[i] = IPM_SHIFT * ds;
        z[i] = -q[i];
    }
    if (ipm_factor(ws, n, ws->diag))
        return -1;
    factor_solve(ws, n, z);
    double zs = fmax(pd_lcp_max_abs(n, z), qs / ds);
    /* inside the orthant: z_i = max(z_i, 0) + IPM_START zs, w likewise */
    for (int i = 0; i < n; i++)
        z[i] = fmax(z[i], 0.0) + IPM_START * zs;
    ipm_matvec(ws, M, z, w);
    for (int i = 0; i < n; i++)
        w[i] = fmax(w[i] + q[i], 0.0) + IPM_START * qs;
    return 0;
}

/* The support guess of the interior point, z_i M_ii > w_i (in the units
 * of w), into sup; the number of indices that changed sides. */
static int ipm_support(pd_bpp_work *ws, int n)
{
    int changed = 0;
    for (int i = 0; i < n; i++) {
        unsigned char s = ws->iz[i] * ws->mii[i] > ws->iw[i];
        changed += s != ws->sup[i];
        ws->sup[i] = s;
    }
    return changed;
}

/* Mehrotra's predictor-corrector for the monotone LCP, infeasible start:
 *   (M + W Z^-1) dz = -(M z + q) + (sigma mu - dz_a dw_a) / z,
 *   dw = (sigma mu - dz_a dw_a) / z - w - (w / z) dz,
 * sigma = (mu_affine / mu)^3, until mu = z.w / n is small relative to the
 * scales -- or, with `cross`, until the support guess has held for
 * IPM_STABLE iterations while mu fell by IPM_CROSS_MU (ws->crossed): the
 * pivoting finishes from there in one solve, where the last iterations
 * would only sharpen a point whose support is known.  The point in ws->iz,
 * ws->iw; -1 when a factorisation fails, else the iterations made. */
static int interior_point(pd_bpp_work *ws, const pd_matrix *M, const double *q, double qs,
                          double ds, double tol, int from_start, int cross)
{
    int n = M->rows, it, stable = 0;
    double *z = ws->iz, *w = ws->iw, *dz = ws->dz, *dw = ws->dw, *az = ws->az, *aw = ws->aw;
    double *rz = ws->rz, mu0 = -1.0;
    if (ipm_pattern(ws, M) || (from_start && ipm_start(ws, M, q, qs, ds)))
        return -1;
    ws->crossed = 0;
    ipm_support(ws, n);
    for (it = 0; it < IPM_MAX; it++) {
        double mu = 0.0, rmax = 0.0;
        ipm_matvec(ws, M, z, ws->r);
        for (int i = 0; i < n; i++) {
            mu += z[i] * w[i] / n; /* mu = z.w / n */
            ws->r[i] += q[i];      /* M z + q */
            double gap = fabs(w[i] - ws->r[i]);
            rmax = gap > rmax ? gap : rmax;
            rz[i] = 1.0 / z[i];
            ws->diag[i] = w[i] * rz[i]; /* W Z^-1 */
        }
        ws->mu = mu;
        ws->rmax = rmax;
        /* mu and the residual small against the scales qs^2 / ds and qs */
        if (mu <= tol * qs * qs / ds && rmax <= tol * qs)
            break;
        mu0 = mu0 < 0.0 ? mu : mu0;
        if (cross && it > 0) {
            stable = ipm_support(ws, n) ? 0 : stable + 1;
            if (stable >= IPM_STABLE && mu <= IPM_CROSS_MU * mu0) {
                ws->crossed = 1;
                break;
            }
        }
        if (ipm_factor(ws, n, ws->diag)) /* M_FF singular at this point: w / z -> 0 */
            return IPM_STALLED;
        for (int i = 0; i < n; i++) /* predictor */
            az[i] = -ws->r[i];
        factor_solve(ws, n, az);
        double a = step_to_boundary(n, z, az, w, ws->diag, NULL, aw), mua = 0.0;
        for (int i = 0; i < n; i++)
            mua += (z[i] + a * az[i]) * (w[i] + a * aw[i]) / n;
        double sigma = pow(mua / mu, 3.0); /* Mehrotra's centring */
        for (int i = 0; i < n; i++) {      /* corrector */
            double c = (sigma * mu - az[i] * aw[i]) * rz[i];
            dz[i] = -ws->r[i] + c;
            ws->rows[i] = c;
        }
        factor_solve(ws, n, dz);
        /* 0.995 of the way to the boundary */
        a = IPM_STEP * step_to_boundary(n, z, dz, w, ws->diag, ws->rows, dw);
        for (int i = 0; i < n; i++) {
            z[i] += a * dz[i];
            w[i] += a * dw[i];
        }
    }
    return it;
}

/* z, w from the point (z clamped at 0, w = M z + q) and its verification. */
static int accept(pd_bpp_work *ws, const pd_matrix *M, const double *q, double *z, double *w,
                  pd_lcp_info *info)
{
    for (int i = 0; i < M->rows; i++)
        z[i] = z[i] > 0.0 ? z[i] : 0.0;
    pd_lcp_verify(M, q, z, w, ws->rows, info);
    return info->residual <= PD_LCP_VERIFY_TOL;
}

int pd_bpp_solve(pd_bpp_work *ws, const pd_matrix *M, const double *q, const pd_lcp_opts *o,
                 double *z, double *w, unsigned char *flag, pd_lcp_info *info)
{
    int n = M->rows, its = 0, rc;
    int maxit = o->max_iterations > 0 ? o->max_iterations : 3 * n + 10; /* principal solves */
    double qs = pd_lcp_max_abs(n, q), ds = 0.0;
    info->iterations = 0;
    info->outcome = PD_LCP_NUMERICAL;
    /* a tridiagonal Stieltjes matrix: the direct method, one sweep and one
     * principal solve, warm or cold */
    double zs = 0.0;
    if ((rc = pd_bpp_stieltjes(ws, M, q, z, &zs)) != 0) {
        its = 1; /* z is clamped already: verified as accept would */
        if (rc > 0 &&
            (pd_lcp_verify_zs(M, q, z, w, ws->rows, zs, info), info->residual <= PD_LCP_VERIFY_TOL))
            goto solved;
    }
    for (int i = 0; i < n; i++) {
        ws->mii[i] = pd_matrix_get(M, i, i);
        ds = fmax(ds, ws->mii[i]);
        if (!(ws->mii[i] > 0.0))
            return PD_ENUMERICAL; /* not positive definite: not this solver's problem */
    }
    /* from the guess (a warm start), or from the signs of q */
    for (int i = 0; i < n; i++)
        ws->inF[i] = o->guess && o->guess[i] < 2 ? o->guess[i] : q[i] < 0.0;
    int rounds = o->guess ? BPP_WARM_ROUNDS : 1; /* cold: one try from the signs of q */
    rc = pivot_rounds(ws, M, q, maxit < rounds ? maxit : rounds, z, w, flag, &its);
    if (rc == 0 && accept(ws, M, q, z, w, info))
        goto solved;
    /* the interior point: its support, once stable, hands over to the
     * pivoting (IPM_CROSSINGS tries, then to convergence); if that fails (a
     * singular M_FF: redundant contacts), the point itself, driven further,
     * is the answer when it verifies */
    int ipm = -1;
    for (int t = 0; qs > 0.0 && t <= IPM_CROSSINGS; t++) {
        int more = interior_point(ws, M, q, qs, ds, IPM_MU_TOL, t == 0, t < IPM_CROSSINGS);
        if ((ipm = more) < 0)
            break;
        its += more;
        if (!ws->crossed)
            ipm_support(ws, n);
        memcpy(ws->inF, ws->sup, (size_t)n);
        int left = maxit > its ? maxit - its : 1;
        rc = pivot_rounds(ws, M, q, ws->crossed && left > 2 ? 2 : left, z, w, flag, &its);
        if (rc == 0 && accept(ws, M, q, z, w, info))
            goto solved;
        if (!ws->crossed)
            break;
    }
    /* a singular M_FF stalls the factorisation as w / z -> 0 on the
     * redundant contacts: the point reached then is the answer if it is
     * feasible and complementary to the interior point's own tolerance (an
     * infeasible problem stalls too, with z running away and w far from
     * M z + q) and verifies */
    if (ipm >= 0) {
        int more = interior_point(ws, M, q, qs, ds, IPM_MU_FINAL, 0, 0);
        its += more > 0 ? more : 0;
        ipm = more == IPM_STALLED ? IPM_STALLED : ipm;
    }
    /* the point itself only when converged to IPM_MU_TOL */
    int converged = ws->rmax <= IPM_MU_TOL * qs && ws->mu <= IPM_MU_TOL * qs * qs / ds;
    if ((ipm >= 0 || ipm == IPM_STALLED) && converged) {
        memcpy(z, ws->iz, (size_t)n * sizeof(double));
        if (accept(ws, M, q, z, w, info))
            goto solved;
    }
    info->iterations = its;
    /* pivoting out of rounds: max_iterations; anything else: numerical */
    info->outcome = rc > 0 ? PD_LCP_MAX_ITERATIONS : PD_LCP_NUMERICAL;
    return rc > 0 ? PD_EMAXITER : PD_ENUMERICAL;
solved:
    info->iterations = its;
    info->outcome = PD_LCP_SOLVED;
    return PD_OK;
}
