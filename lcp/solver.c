/* solver.c — the LCP solver table: one object sized once, one solve call,
 * whatever the method and the matrix storage; every answer verified.
 *
 * auto: Lemke for n <= 2 (its closed forms) and for dense matrices; the
 * structured solver for compressed-column ones (the engine's sparse
 * Delassus blocks), handing over to Lemke when it cannot finish and the
 * problem fits Lemke's workspace.  Under auto a solver that ends as
 * numerical (or the structured solver as max_iterations) hands the problem
 * on: Lemke to the structured solver, and what neither finishes to PGS on
 * a bounded budget; a ray of Lemke's (no solution), its pivot cap and bad
 * input end the solve.  Every answer is verified, whoever gives it.  A dense
 * matrix that is mostly zeros (a band) reaches the structured solver as a
 * compressed-column copy made in one pass (dense_copy). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "lcp_internal.h"

#define HANDOVER_PGS_WORK                                                                          \
    1e9                     /* auto's last resort: PGS sweeps of at most this many
                                 multiply-adds in all (about a second) */
#define HANDOVER_PGS_MIN 64 /* ... but at least this many sweeps */
#define SPARSE_COPY_PER_ROW                                                                        \
    17 /* a dense matrix for the structured solver with at most
                                  this many nonzero entries a row on average (a band of
                                  half-width 8), and no more than half of them nonzero,
                                  is copied into compressed columns (dense_copy) */

/* A method of the table. */
typedef struct solver_type {
    pd_lcp_method method;
    const char *name;
    int lemke, structured, pgs; /* the workspaces it needs */
} solver_type;

static const solver_type solver_types[] = {
    {.method = PD_LCP_AUTO, .name = "auto", .lemke = 1, .structured = 1, .pgs = 1},
    {.method = PD_LCP_LEMKE, .name = "lemke", .lemke = 1},
    {.method = PD_LCP_STRUCTURED, .name = "structured", .lemke = 1, .structured = 1},
    {.method = PD_LCP_PGS, .name = "pgs", .pgs = 1},
};

#define NTYPES (int)(sizeof solver_types / sizeof solver_types[0])

struct pd_lcp_solver {
    const solver_type *type;
    int nmax;
    pd_lcp_work *lemke; /* Lemke, for up to lemke_nmax unknowns */
    int lemke_nmax;
    double *dense;    /* lemke_nmax^2: a sparse matrix copied for Lemke */
    pd_bpp_work *bpp; /* the structured solver */
    pd_pgs_work *pgs;
    unsigned char *flag;            /* nmax: scratch of the structured solver */
    long copy_cap;                  /* SPARSE_COPY_PER_ROW nmax: the entries of ... */
    int *copy_colptr, *copy_rowind; /* ... a dense matrix's copy in compressed columns */
    double *copy_values;            /* for the structured solver (dense_copy) */
};

const char *pd_lcp_method_name(pd_lcp_method method)
{
    for (int k = 0; k < NTYPES; k++)
        if (solver_types[k].method == method)
            return solver_types[k].name;
    return "?";
}

int pd_lcp_method_parse(const char *name, pd_lcp_method *method)
{
    if (!name || !method)
        return PD_EINVAL;
    for (int k = 0; k < NTYPES; k++)
        if (!strcmp(name, solver_types[k].name)) {
            *method = solver_types[k].method;
            return PD_OK;
        }
    return PD_EINVAL;
}

const char *pd_lcp_method_list(void)
{
    return "auto, lemke, structured, pgs";
}

void pd_lcp_solver_free(pd_lcp_solver *s)
{
    if (!s)
        return;
    pd_lcp_free(s->lemke);
    free(s->dense);
    pd_bpp_free(s->bpp);
    pd_pgs_free(s->pgs);
    free(s->flag);
    free(s->copy_colptr);
    free(s->copy_rowind);
    free(s->copy_values);
    free(s);
}

pd_lcp_solver *pd_lcp_solver_alloc(pd_lcp_method method, int nmax, long nnzmax, pd_err *err)
{
    const solver_type *type = NULL;
    pd_lcp_solver *s = NULL;
    for (int k = 0; k < NTYPES; k++)
        if (solver_types[k].method == method)
            type = &solver_types[k];
    if (!type || nmax < 1 || nnzmax < 0) {
        pd_err_set(err, PD_EINVAL, "LCP solver: bad method %d or size %d", (int)method, nmax);
        return NULL;
    }
    if (!(s = calloc(1, sizeof *s)))
        goto oom;
    s->type = type;
    s->nmax = nmax;
    /* Lemke's workspace: a sparse problem handed over to it is copied densely (n^2), so
     * the hand-over's cap, unless Lemke itself was asked for */
    int cap = method != PD_LCP_LEMKE && nnzmax > 0 ? PD_LCP_HANDOVER_NMAX : PD_LCP_LEMKE_NMAX;
    s->lemke_nmax = nmax < cap ? nmax : cap;
    if (type->lemke) {
        size_t ln = (size_t)s->lemke_nmax;
        /* the dense copy only when sparse matrices will come */
        if (!(s->lemke = pd_lcp_alloc(s->lemke_nmax)) ||
            (nnzmax > 0 && !(s->dense = malloc(ln * ln * sizeof(double)))))
            goto oom;
    }
    if (type->structured) {
        /* the envelope of a banded matrix holds about half its entries */
        long env = nnzmax > 0 ? 2 * nnzmax + nmax : (long)nmax * (nmax + 1) / 2;
        if (!(s->bpp = pd_bpp_alloc(nmax, env)) || !(s->flag = malloc((size_t)nmax)))
            goto oom;
        /* dense input: room for a sparse one's copy (dense_copy) */
        s->copy_cap = nnzmax > 0 ? 0 : (long)SPARSE_COPY_PER_ROW * nmax;
        if (s->copy_cap > 0 && (!(s->copy_colptr = malloc(((size_t)nmax + 1) * sizeof(int))) ||
                                !(s->copy_rowind = malloc((size_t)s->copy_cap * sizeof(int))) ||
                                !(s->copy_values = malloc((size_t)s->copy_cap * sizeof(double)))))
            goto oom;
    }
    if (type->pgs && !(s->pgs = pd_pgs_alloc(nmax)))
        goto oom;
    return s;
oom:
    pd_lcp_solver_free(s);
    pd_err_set(err, PD_ENOMEM, "LCP solver %s: out of memory for %d unknowns",
               type ? type->name : "?", nmax);
    return NULL;
}

int pd_lcp_solver_nmax(const pd_lcp_solver *s)
{
    return s ? s->nmax : 0;
}

/* Lemke on a dense view, or on a compressed-column matrix copied densely. */
static int solve_lemke(pd_lcp_solver *s, const pd_matrix *M, const double *q,
                       const pd_lcp_opts *opts, double *z, double *w, pd_lcp_info *info)
{
    const double *dense = M->values;
    info->solver = "lemke";
    if (M->rows > s->lemke_nmax) /* beyond its workspace */
        return PD_EINVAL;
    if (M->kind != PD_MATRIX_DENSE) {
        if (!s->dense)
            return PD_EINVAL;
        /* compressed columns: Lemke works on a dense copy */
        pd_matrix_to_dense(M, s->dense);
        dense = s->dense;
    }
    int rc = pd_lcp_lemke(s->lemke, M->rows, dense, q, opts, z, w, info);
    info->solver = "lemke"; /* the solve clears info */
    return rc;
}

/* 1 when the 8 k doubles at x (k = 1 or 4) are all zeros (of either sign):
 * their bits or'ed, the sign bit shifted off; in two-lane vectors where
 * the compiler has them, so that a column is read at the speed of memory. */
static inline int zeros(const double *x, int k)
{
#if defined(__GNUC__) || defined(__clang__)
    typedef uint64_t u64x2 __attribute__((vector_size(16)));
    u64x2 v0, v1, v2, v3, acc = {0, 0};
    /* or of every bit of the 8 k doubles */
    for (int b = 0; b < k; b++, x += 8) {
        memcpy(&v0, x, sizeof v0);
        memcpy(&v1, x + 2, sizeof v1);
        memcpy(&v2, x + 4, sizeof v2);
        memcpy(&v3, x + 6, sizeof v3);
        acc |= (v0 | v1) | (v2 | v3);
    }
    acc <<= 1; /* the sign bit off: -0 is zero */
    return !(acc[0] | acc[1]);
#else
    uint64_t acc = 0, u;
    for (int i = 0; i < 8 * k; i++) {
        memcpy(&u, x + i, sizeof u);
        acc |= u;
    }
    return !(acc << 1);
#endif
}

/* A dense M with at most SPARSE_COPY_PER_ROW nonzero entries a row on
 * average, and at most half of its entries nonzero, is copied into
 * compressed columns in one pass over it: *out is then the copy (the same
 * matrix, its zeros left out), and the structured solver works on its band
 * (a chain's three diagonals: the tridiagonal direct method) instead of
 * scanning whole columns in every product and factorisation.  Else *out is
 * M, after at most the pass.  A column is read in blocks of 8 entries, a
 * block of zeros (of either sign) skipped after one test; a NaN counts as
 * nonzero, so it is kept. */
static void dense_copy(pd_lcp_solver *s, const pd_matrix *M, pd_matrix *out)
{
    int n = M->rows;
    long nz = 0, cap = (long)SPARSE_COPY_PER_ROW * n, half = (long)n * n / 2;
    int *colptr = s->copy_colptr, *rowind = s->copy_rowind;
    double *values = s->copy_values;
    *out = *M;
    cap = cap < half ? cap : half; /* at most half the entries */
    /* not dense, or no room for the copy: M as it is */
    if (M->kind != PD_MATRIX_DENSE || !colptr || cap > s->copy_cap)
        return;
    for (int j = 0; j < n; j++) {
        const double *c = M->values + (size_t)j * (size_t)n;
        colptr[j] = (int)nz;
        for (int i0 = 0; i0 < n; i0 += 8) {
            int i1 = n - i0 >= 8 ? i0 + 8 : n;      /* the block's end */
            if (n - i0 >= 32 && zeros(c + i0, 4)) { /* four cache lines at once */
                i0 += 24;
                continue;
            }
            if (i1 - i0 == 8 && zeros(c + i0, 1))
                continue;
            for (int i = i0; i < i1; i++)
                if (c[i] != 0.0) { /* true for a NaN */
                    if (nz == cap)
                        return; /* too many: M as it is */
                    rowind[nz] = i;
                    values[nz++] = c[i];
                }
        }
    }
    /* every column copied: the same matrix in compressed columns */
    colptr[n] = (int)nz;
    *out = pd_matrix_csc(n, n, colptr, rowind, values);
}

/* The structured solver on M, or on its sparse copy (dense_copy). */
static int solve_bpp(pd_lcp_solver *s, const pd_matrix *M, const double *q, const pd_lcp_opts *opts,
                     double *z, double *w, pd_lcp_info *info)
{
    pd_matrix A;
    dense_copy(s, M, &A);
    return pd_bpp_solve(s->bpp, &A, q, opts, z, w, s->flag, info);
}

/* The structured solver; Lemke takes over a problem it cannot finish when
 * the problem fits Lemke's workspace. */
static int solve_structured(pd_lcp_solver *s, const pd_matrix *M, const double *q,
                            const pd_lcp_opts *opts, double *z, double *w, pd_lcp_info *info)
{
    info->solver = "structured";
    int rc = solve_bpp(s, M, q, opts, z, w, info);
    /* solved, too large for Lemke, or sparse with no room for its dense copy: the answer stands */
    if (rc == PD_OK || M->rows > s->lemke_nmax || (M->kind == PD_MATRIX_CSC && !s->dense))
        return rc;
    /* Lemke's figures replace the structured solver's; its iteration count is kept */
    int iterations = info->iterations;
    rc = solve_lemke(s, M, q, opts, z, w, info);
    info->iterations = iterations;
    info->solver = "lemke (after structured)";
    return rc;
}

/* A failure another solver may overcome: lost precision, or the structured
 * solver's iterations spent (max_iterations bounds PGS's sweeps as well).
 * A ray of Lemke's proves a positive semidefinite problem infeasible, its
 * pivot cap is the caller's, bad input stays bad. */
static int hands_over(int rc)
{
    return rc == PD_ENUMERICAL || rc == PD_EMAXITER;
}

/* PGS as auto's last resort, its sweeps bounded by HANDOVER_PGS_WORK (and
 * by the caller's max_iterations); info keeps the pivots and adds the
 * iterations of the solvers before it. */
static int solve_pgs_last(pd_lcp_solver *s, const pd_matrix *M, const double *q,
                          const pd_lcp_opts *opts, double *z, double *w, pd_lcp_info *info,
                          const char *name)
{
    pd_lcp_opts o = *opts;
    int pivots = info->pivots, iterations = info->iterations;
    long nnz = pd_matrix_nnz(M), n = M->rows;
    /* a sweep costs about nnz multiply-adds (n at least): the sweeps within HANDOVER_PGS_WORK,
     * at least HANDOVER_PGS_MIN */
    long sweeps = (long)(HANDOVER_PGS_WORK / (double)(nnz > n ? nnz : n));
    sweeps = sweeps > HANDOVER_PGS_MIN ? sweeps : HANDOVER_PGS_MIN;
    if (o.max_iterations <= 0 || o.max_iterations > sweeps)
        o.max_iterations = sweeps < 1000L * n ? (int)sweeps : 0; /* 0: PGS's own default */
    int rc = pd_pgs_solve(s->pgs, M, q, &o, z, w, info);
    info->pivots = pivots;
    info->iterations += iterations; /* the solvers before it */
    info->solver = name;
    return rc;
}

/* auto: Lemke first on small dense input, else the structured solver (with
 * its hand-over to Lemke); a failure that hands_over goes on to the other
 * one, then to PGS. */
static int solve_auto(pd_lcp_solver *s, const pd_matrix *M, const double *q, const pd_lcp_opts *o,
                      double *z, double *w, pd_lcp_info *info)
{
    int rc;
    /* n <= 2 (its closed forms), or dense within Lemke's workspace: Lemke first */
    if (M->rows <= 2 || (M->kind == PD_MATRIX_DENSE && M->rows <= s->lemke_nmax)) {
        rc = solve_lemke(s, M, q, o, z, w, info);
        if (!hands_over(rc))
            return rc;
        int pivots = info->pivots; /* Lemke's, kept */
        rc = solve_bpp(s, M, q, o, z, w, info);
        info->pivots = pivots;
        info->solver = "structured (after lemke)";
        if (!hands_over(rc))
            return rc;
        return solve_pgs_last(s, M, q, o, z, w, info, "pgs (after lemke, structured)");
    }
    /* the structured solver (with its hand-over to Lemke), then PGS */
    rc = solve_structured(s, M, q, o, z, w, info);
    if (!hands_over(rc))
        return rc;
    return solve_pgs_last(s, M, q, o, z, w, info,
                          strcmp(info->solver, "structured") ? "pgs (after structured, lemke)"
                                                             : "pgs (after structured)");
}

int pd_lcp_solve(pd_lcp_solver *s, const pd_matrix *M, const double *q, const pd_lcp_opts *opts,
                 double *z, double *w, pd_lcp_info *info)
{
    pd_lcp_info local;
    pd_lcp_opts o = opts ? *opts : pd_lcp_default_opts();
    if (!info)
        info = &local;
    /* info cleared; a bad call returns PD_EINVAL with the outcome numerical */
    memset(info, 0, sizeof *info);
    info->outcome = PD_LCP_NUMERICAL;
    info->solver = s ? s->type->name : "?";
    /* square, 1 <= n <= nmax, dense or compressed columns */
    if (!s || !M || !q || !z || !w || M->rows != M->cols || M->rows < 1 || M->rows > s->nmax ||
        (M->kind != PD_MATRIX_DENSE && M->kind != PD_MATRIX_CSC))
        return PD_EINVAL;
    switch (s->type->method) {
    case PD_LCP_LEMKE:
        return solve_lemke(s, M, q, &o, z, w, info);
    case PD_LCP_STRUCTURED:
        return solve_structured(s, M, q, &o, z, w, info);
    case PD_LCP_PGS:
        info->solver = "pgs";
        return pd_pgs_solve(s->pgs, M, q, &o, z, w, info);
    default:
        return solve_auto(s, M, q, &o, z, w, info);
    }
}
