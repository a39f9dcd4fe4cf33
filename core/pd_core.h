/* pd_core.h — what every pound module shares: status codes and error
 * messages, clocks, constants, and the matrices every layer reads.
 *
 * Status.  Every library function that can fail returns an int status: 0
 * (PD_OK) on success, a negative PD_E* code otherwise, and may fill a pd_err
 * with a one-line message naming what went wrong.  The library never
 * prints, exits or aborts; the caller decides what to show.
 *
 * Matrices.  Read-only views of zero, dense (column-major) or
 * compressed-sparse-column storage, the few products the solvers need, an
 * owned sparse matrix assembled from triplets, and a small dense LU.  A view
 * never owns its arrays.  CSC: colptr has cols + 1 entries, the row indices
 * of a column are strictly increasing, values[k] is the entry at
 * (rowind[k], j) for colptr[j] <= k < colptr[j + 1]. */
#ifndef PD_CORE_H
#define PD_CORE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* PD_API marks the public API: the only symbols libpound.so exports (it is
 * built with -fvisibility=hidden; docs/api.md).  The static library and
 * other compilers see it as nothing. */
#if defined(__GNUC__) || defined(__clang__)
#define PD_API __attribute__((visibility("default")))
#else
#define PD_API
#endif

/* The library's version: MAJOR changes break the public API (pound.h);
 * MINOR adds to it; PATCH fixes.  pd_version() is the string of the
 * library actually linked, PD_VERSION the one compiled against. */
#define PD_VERSION_MAJOR 0
#define PD_VERSION_MINOR 13
#define PD_VERSION_PATCH 0
#define PD_VERSION "0.13.0"
PD_API const char *pd_version(void);

enum {
    PD_OK = 0,
    PD_ENOMEM = -1,      /* an allocation failed */
    PD_EINVAL = -2,      /* an argument is out of range or inconsistent */
    PD_ENOSOLUTION = -3, /* LCP: ray termination, the LCP may have no solution */
    PD_EMAXPIVOTS = -4,  /* LCP: pivot cap reached */
    PD_ENUMERICAL = -5,  /* pivot too small, lost precision, failed verification */
    PD_ENONFINITE = -6,  /* a NaN or infinity appeared in the state */
    PD_EIO = -7,         /* a file could not be opened, read or written */
    PD_EPARSE = -8,      /* a file is malformed */
    PD_ESINGULAR = -9,   /* a matrix to factor is singular */
    PD_EBUDGET = -10,    /* an event or step budget was exhausted */
    PD_ESTOPPED = -11,   /* an observer asked the run to stop (not an error) */
    PD_EMAXITER = -12    /* an iterative solver's budget ran out */
};

/* A one-line error message; status mirrors the code returned. */
typedef struct pd_err {
    int status;
    char msg[256];
} pd_err;

/* Short text for a status code ("out of memory", ...). */
PD_API const char *pd_strerror(int status);

/* Record status and a printf-style message in err (err may be NULL; fmt
 * NULL: the message is pd_strerror(status)); returns status so callers can
 * write `return pd_err_set(err, ...)`. */
PD_API int pd_err_set(pd_err *err, int status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Replace control bytes in msg by '?' (pd_err_set does it to every message). */
PD_API void pd_err_sanitize(char *msg);

/* Clear err to PD_OK with an empty message. */
PD_API void pd_err_clear(pd_err *err);

/* Monotonic wall-clock time, and the calling thread's CPU time, in seconds. */
PD_API double pd_wall_seconds(void);
PD_API double pd_cpu_seconds(void);

/* ---- constants ------------------------------------------------------------- */

#define PD_PI 3.14159265358979323846264338327950288
#define PD_TWO_PI 6.28318530717958647692528676655900577

/* Standard gravity [m/s^2], for records given in g. */
#define PD_G_STANDARD 9.80665

/* The larger of two numbers known not to be NaN: inlined, where a call to
 * fmax (which must treat NaN) would cost more than the comparison. */
static inline double pd_max(double a, double b)
{
    return a > b ? a : b;
}

/* The smaller, likewise. */
static inline double pd_min(double a, double b)
{
    return a < b ? a : b;
}

/* ---- reproducible random numbers ------------------------------------------ */

/* splitmix64: the next 64 random bits of the stream *state (the same on
 * every platform: tests and benchmarks draw their problems from it). */
PD_API uint64_t pd_rand_next(uint64_t *state);
/* Uniform in [-1, 1): the next 53 bits. */
PD_API double pd_rand_pm1(uint64_t *state);

/* ---- interpolation --------------------------------------------------------- */

/* The quintic Hermite interpolant on a step of length h through (f, f', f'')
 * = p0 at its start and p1 at its end: value *f and time rate *fd at the
 * fraction r in [0, 1] of the step (fd may be NULL: the value alone). */
PD_API void pd_hermite5(const double p0[3], const double p1[3], double h, double r, double *f,
                        double *fd);

/* The cubic Hermite interpolant on a step of length h through (f, f') = p0
 * at its start and p1 at its end: its value at the fraction r in [0, 1]. */
PD_API double pd_hermite3(const double p0[2], const double p1[2], double h, double r);

/* ---- matrices -------------------------------------------------------------- */

typedef enum {
    PD_MATRIX_ZERO = 0,  /* all zeros (no arrays) */
    PD_MATRIX_DENSE = 1, /* column-major values, leading dimension rows */
    PD_MATRIX_CSC = 2    /* compressed sparse column */
} pd_matrix_kind;

/* A rows x cols matrix, read only. */
typedef struct pd_matrix {
    pd_matrix_kind kind;
    int rows, cols;
    const double *values;
    const int *colptr, *rowind; /* CSC only */
} pd_matrix;

PD_API pd_matrix pd_matrix_zero(int rows, int cols);
PD_API pd_matrix pd_matrix_dense(int rows, int cols, const double *values);
PD_API pd_matrix pd_matrix_csc(int rows, int cols, const int *colptr, const int *rowind,
                               const double *values);

/* y = alpha A x + beta y (beta = 0 ignores y's old contents). */
PD_API void pd_matrix_gemv(const pd_matrix *A, double alpha, const double *x, double beta,
                           double *y);

/* y = A^T x (y has cols entries). */
PD_API void pd_matrix_gemv_t(const pd_matrix *A, const double *x, double *y);

/* Entry (i, j). */
PD_API double pd_matrix_get(const pd_matrix *A, int i, int j);

/* A[:, j]^T x;  y += s A[:, j];  sum_i |A_ij| |x_i|. */
PD_API double pd_matrix_col_dot(const pd_matrix *A, int j, const double *x);
PD_API void pd_matrix_col_axpy(const pd_matrix *A, int j, double s, double *y);
PD_API double pd_matrix_col_absdot(const pd_matrix *A, int j, const double *x);

/* Entries stored (rows * cols for dense, 0 for zero). */
PD_API long pd_matrix_nnz(const pd_matrix *A);

/* out (rows x cols, column-major) = A. */
PD_API void pd_matrix_to_dense(const pd_matrix *A, double *out);

/* 1 when every stored off-diagonal entry is zero. */
PD_API int pd_matrix_is_diagonal(const pd_matrix *A);

/* Shape rows x cols, a known kind, a valid CSC structure and finite
 * entries; the message names the matrix. */
PD_API int pd_matrix_check(const pd_matrix *A, int rows, int cols, const char *name, pd_err *err);

/* ---- an owned sparse matrix ---------------------------------------------- */

typedef struct pd_sparse {
    int rows, cols, nnz;
    int *colptr, *rowind;
    double *values;
} pd_sparse;

/* Assemble rows x cols from nt triplets (Ti[k], Tj[k], Tx[k]), summing
 * duplicates and dropping nothing (explicit zeros stay; Ti, Tj, Tx may be
 * NULL when nt = 0).  PD_ENOMEM or PD_EINVAL (an index out of range); on
 * failure sp is empty. */
PD_API int pd_sparse_from_triplets(pd_sparse *sp, int rows, int cols, long nt, const int *Ti,
                                   const int *Tj, const double *Tx, pd_err *err);
PD_API void pd_sparse_free(pd_sparse *sp);
PD_API pd_matrix pd_sparse_view(const pd_sparse *sp);

/* ---- dense LU -------------------------------------------------------------- */

/* P A = L U in place for the n x n column-major A (leading dimension lda),
 * scaled partial pivoting (each row scaled by the power of two nearest its
 * largest entry); PD_ESINGULAR when a pivot is not above rel_tol times its
 * own row's scale, when a row is zero or an entry not finite. */
PD_API int pd_dense_lu(int n, double *A, int lda, int *perm, double rel_tol);

/* Solve A x = b in place from the output of pd_dense_lu. */
PD_API void pd_dense_lu_solve(int n, const double *LU, int lda, const int *perm, double *b);

/* ---- input text files in bounded memory --------------------------------
 * The one reader under the LCP, scene and record readers.
 *
 * A file is read whole (pd_text_read_all) or a line at a time (pd_text_open,
 * pd_text_line), and refused as soon as the offence is read:
 *   - a NUL byte: binary data (/dev/zero, an image, a compressed file);
 *   - more than max_bytes bytes: the reader's size cap (each reader names
 *     its own, generous for real inputs), so that an endless stream costs
 *     at most the cap;
 *   - a line longer than PD_TEXT_LINE_MAX (line by line only).
 * Each refusal is PD_EPARSE with one line naming the file and where, in the
 * style of the reader's other messages (pd_text_at); a file that cannot be
 * opened or read is PD_EIO with the system's reason, a failed allocation
 * PD_ENOMEM. */

/* Longest line of the line reader: 64 MiB.  Text inputs have lines of tens
 * of characters (a record line of 8 numbers is about 120); a line this long
 * is not text, and the cap bounds the line buffer. */
#define PD_TEXT_LINE_MAX (64L << 20)

/* How messages name a place in the file. */
typedef enum {
    PD_TEXT_AT_LINE = 0,     /* "FILE:LINE: " (records) */
    PD_TEXT_AT_LINE_COL = 1, /* "FILE:LINE:COL: " (JSON scenes, as jansson's errors) */
    PD_TEXT_AT_WORD = 2      /* "FILE: line LINE: " (LCP files) */
} pd_text_at;

/* A file read line by line. */
typedef struct pd_text {
    const char *path;
    FILE *f;
    long max_bytes; /* the size cap */
    pd_text_at at;
    char *line;      /* the current line with its '\n' (if any), NUL-terminated */
    size_t len, cap; /* its length and the buffer's size */
    long lineno;     /* of the current line, 1-based; 0 before the first */
    long bytes;      /* read so far */
    pd_err *err;
} pd_text;

/* Open path for reading with a cap of max_bytes > 0 bytes. */
PD_API int pd_text_open(pd_text *t, const char *path, long max_bytes, pd_text_at at, pd_err *err);

/* The next line into t->line: 1, 0 at the end of the file, or an error. */
PD_API int pd_text_line(pd_text *t);

/* Back to the start of the file (PD_EIO if it cannot seek: a pipe). */
PD_API int pd_text_rewind(pd_text *t);

/* Close the file and free the line buffer (t may have failed to open). */
PD_API void pd_text_close(pd_text *t);

/* The whole file into *text (malloc'd, NUL-terminated, *len bytes before the
 * NUL); on error *text is NULL. */
PD_API int pd_text_read_all(const char *path, long max_bytes, pd_text_at at, char **text,
                            size_t *len, pd_err *err);

#endif
