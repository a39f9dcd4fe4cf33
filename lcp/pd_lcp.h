/* pd_lcp.h — linear complementarity problems.
 *
 *   find z >= 0 such that w = M z + q >= 0 and z'w = 0,   M n x n.
 *
 * Three solvers behind one table (pd_lcp_solve, docs/lcp.md):
 *   lemke       Lemke's complementary pivoting with a covering vector and a
 *               lexicographic ratio test, on dense column-major M (M[i + j n]);
 *               the general solver, closed forms for n <= 2;
 *   structured  for symmetric positive (semi)definite M (the Delassus
 *               matrices of the engine): block principal pivoting
 *               (Judice-Pires), warm-started, with a Mehrotra interior
 *               point for cold starts and cascades, on L D L^T factors of
 *               the principal blocks (twisted for tridiagonal ones, an
 *               envelope otherwise) in compressed columns; bounded work,
 *               then a hand-over to Lemke;
 *   pgs         projected Gauss-Seidel, the physics engines' baseline.
 * Every answer is verified (the relative backward residual of
 * pd_lcp_residual) before it is called solved.  Workspaces are sized once;
 * a solve never allocates. */
#ifndef PD_LCP_H
#define PD_LCP_H

/* A verified answer has a relative backward residual at most this. */
#define PD_LCP_VERIFY_TOL 1e-10

#include <stdio.h>

#include "pd_core.h"

/* Outcome of a solve.  The solver returns PD_OK for PD_LCP_SOLVED and the
 * negative status PD_ENOSOLUTION / PD_EMAXPIVOTS / PD_ENUMERICAL otherwise. */
typedef enum {
    PD_LCP_SOLVED = 0,        /* verified solution */
    PD_LCP_NO_SOLUTION = 1,   /* ray termination */
    PD_LCP_MAX_PIVOTS = 2,    /* pivot cap reached */
    PD_LCP_NUMERICAL = 3,     /* pivot too small, or the answer failed verification */
    PD_LCP_MAX_ITERATIONS = 4 /* an iterative solver's budget ran out, unverified */
} pd_lcp_outcome;

/* Name of an outcome as printed by `pound lcp`: "solved", "no_solution",
 * "max_pivots", "numerical", "max_iterations". */
PD_API const char *pd_lcp_outcome_name(pd_lcp_outcome outcome);

/* Options: start from pd_lcp_default_opts() (a NULL opts pointer means the
 * defaults).  Fields hold values, never "use the default" markers; a 0 pivot
 * or iteration budget is derived from n (documented in docs/lcp.md). */
typedef struct pd_lcp_opts {
    const double *cover;        /* Lemke's covering vector d > 0 (n entries), NULL = all ones */
    int max_pivots;             /* Lemke's pivot cap; 0 = max(10000, 100 n) */
    double tol;                 /* relative tolerance for ties and tiny pivots, in (0, 1) */
    int max_iterations;         /* structured: principal solves of the pivoting, 0 = 3 n + 10
                            (its interior point is bounded apart, at 40 iterations
                            a call); pgs: sweeps, 0 = 1000 n (at most 10^6) */
    const unsigned char *guess; /* n flags, a warm start for the structured solver:
                            1 z_i > 0 expected, 0 z_i = 0 expected, 2 no idea (the
                            sign of q_i decides); NULL = 2 everywhere */
} pd_lcp_opts;

/* cover NULL, max_pivots 0 (from n), tol 1e-12, max_iterations 0 (from n),
 * guess NULL. */
PD_API pd_lcp_opts pd_lcp_default_opts(void);

/* What a solve reports. */
typedef struct pd_lcp_info {
    pd_lcp_outcome outcome;
    int pivots;             /* Lemke: pivots performed, counting the one that brings z0 in */
    int iterations;         /* structured: principal solves plus interior-point
                               iterations; pgs: sweeps */
    double complementarity; /* max_i |z_i w_i| */
    double infeasibility;   /* max_i max(-z_i, -w_i, 0) */
    double residual;        /* relative backward residual (pd_lcp_residual): a verified
                               answer has residual <= 1e-10 */
    double scale;           /* max_i r_i, r_i = |q_i| + sum_j |M_ij z_j| (the size of w) */
    const char *solver;     /* the solver that produced the answer (pd_lcp_solve) */
} pd_lcp_info;

typedef struct pd_lcp_work pd_lcp_work;

/* Workspace for problems of size up to nmax; NULL when out of memory. */
PD_API pd_lcp_work *pd_lcp_alloc(int nmax);
PD_API void pd_lcp_free(pd_lcp_work *work);
PD_API int pd_lcp_nmax(const pd_lcp_work *work);

/* Solve the LCP (M, q) of size n <= nmax by Lemke's method.  z and w receive
 * n entries each.  Returns PD_OK only for a verified solution.  Never
 * allocates. info may be NULL. */
PD_API int pd_lcp_lemke(pd_lcp_work *work, int n, const double *M, const double *q,
                        const pd_lcp_opts *opts, double *z, double *w, pd_lcp_info *info);

/* Brute-force enumeration of the 2^n complementary bases, n <= 12: the test
 * oracle.  Returns PD_OK with a solution (the first found, in order of
 * increasing support) or PD_ENOSOLUTION if none exists. */
PD_API int pd_lcp_enumerate(int n, const double *M, const double *q, double *z, double *w);

/* The right-hand side of the benchmark chain of N contacts (D =
 * tridiag(-1, 2, -1)), draw number seed: q uniform in [-1, 1).  `pound
 * bench --lcp` and bench/siconos_lcp draw the same problems from it, so
 * that their timings pair. */
PD_API void pd_lcp_chain_q(int N, int seed, double *q);

/* Residuals of a candidate z: fills w = M z + q and returns, through the
 * pointers, max|z_i w_i|, the largest sign violation, and the relative
 * backward residual
 *     max_i max(-z_i / zs, -w_i / r_i, min(|w_i| / r_i, |z_i| / zs)),
 * zs = max|z|, r_i = |q_i| + sum_j |M_ij| |z_j| the size of the terms that
 * make w_i (0/0 = 0).  It is invariant under scaling (q, z) or (M, 1/z), and
 * an answer is verified when it is at most 1e-10 (docs/lcp.md).
 * complementarity, infeasibility and residual may each be NULL (not wanted). */
PD_API void pd_lcp_residual(int n, const double *M, const double *q, const double *z, double *w,
                            double *complementarity, double *infeasibility, double *residual);

/* ---- the solver table ------------------------------------------------------ *
 * One entry point for every solver: a solver object sized once (no
 * allocation in a solve) takes the matrix as a pd_matrix view, dense or
 * compressed-sparse-column; a solver that works on dense data copies a sparse
 * matrix into its own buffer.  info->solver names who answered. */
typedef enum {
    PD_LCP_AUTO = 0,       /* Lemke for n <= 2 and dense M (n <= PD_LCP_LEMKE_NMAX),
                              structured for compressed columns and larger dense M */
    PD_LCP_LEMKE = 1,      /* Lemke's method (dense), always available */
    PD_LCP_STRUCTURED = 2, /* block principal pivoting for symmetric positive definite M */
    PD_LCP_PGS = 3         /* projected Gauss-Seidel (positive diagonal) */
} pd_lcp_method;

typedef struct pd_lcp_solver pd_lcp_solver;

/* "auto", "lemke", "structured", "pgs"; parse: PD_OK or PD_EINVAL. */
PD_API const char *pd_lcp_method_name(pd_lcp_method method);
PD_API int pd_lcp_method_parse(const char *name, pd_lcp_method *method);
/* The names the parser takes, comma-separated (for messages). */
PD_API const char *pd_lcp_method_list(void);

/* A solver for problems of up to nmax unknowns whose sparse matrices store
 * up to nnzmax entries (0: the caller passes dense matrices only).  Lemke
 * takes a dense workspace of min(nmax, PD_LCP_LEMKE_NMAX)^2; the hand-over
 * of the structured solver on sparse matrices (auto, structured with
 * nnzmax > 0) one of min(nmax, PD_LCP_HANDOVER_NMAX)^2, so that a long row
 * never pays the square of its length.  NULL on failure, with the reason
 * in err. */
PD_API pd_lcp_solver *pd_lcp_solver_alloc(pd_lcp_method method, int nmax, long nnzmax, pd_err *err);
PD_API void pd_lcp_solver_free(pd_lcp_solver *s);
PD_API int pd_lcp_solver_nmax(const pd_lcp_solver *s);

/* Most unknowns Lemke takes inside the solver table (its workspace grows as
 * the square): larger problems go to the structured solver or PGS. */
#define PD_LCP_LEMKE_NMAX 2048
/* Most unknowns the structured solver hands over to Lemke on sparse input. */
#define PD_LCP_HANDOVER_NMAX 256

/* Solve (M, q), M square (dense or CSC) with n <= nmax: PD_OK only for a
 * verified solution; PD_ENOSOLUTION, PD_EMAXPIVOTS, PD_EMAXITER,
 * PD_ENUMERICAL otherwise (info->outcome), PD_EINVAL for bad input.
 * info->solver names the solver that answered (auto, or a hand-over).
 * opts NULL: the defaults; info may be NULL. */
PD_API int pd_lcp_solve(pd_lcp_solver *s, const pd_matrix *M, const double *q,
                        const pd_lcp_opts *opts, double *z, double *w, pd_lcp_info *info);

/* File formats: plain (SPEC §3, row-major, '#' comments) and Siconos
 * (column-major).  PD_LCP_FORMAT_AUTO detects which. */
typedef enum { PD_LCP_FORMAT_AUTO, PD_LCP_FORMAT_PLAIN, PD_LCP_FORMAT_SICONOS } pd_lcp_format;

/* Read an LCP from a file; on success *M (column-major n x n) and *q are
 * malloc'd and owned by the caller.  A malformed file returns PD_EPARSE with
 * a message naming the line. */
PD_API int pd_lcp_read(const char *path, pd_lcp_format format, int *n, double **M, double **q,
                       pd_err *err);
/* pd_lcp_read, and the band of M noted while its entries are read (no
 * pass of its own): *band = max |i - j| over the nonzero entries M_ij (-1
 * when M is zero), *nnz their number; band and nnz may each be NULL. A
 * caller with a banded M may hand the structured solver compressed
 * columns built from the band alone (`pound lcp` does, docs/lcp.md). */
PD_API int pd_lcp_read_band(const char *path, pd_lcp_format format, int *n, double **M, double **q,
                            int *band, long *nnz, pd_err *err);
/* The nonzero entries of the band |i - j| <= band of the dense n x n M
 * (column-major) into compressed columns colptr (n + 1), rowind, values
 * (cap entries each), reading the band alone; the number of entries, or
 * PD_EINVAL when there are more than cap (or an argument is bad).  With
 * the band of pd_lcp_read_band, the matrix itself. */
PD_API long pd_lcp_band_csc(int n, const double *M, int band, long cap, int *colptr, int *rowind,
                            double *values);

#endif
