/* matrix.c — matrix views and their products. */
#include <limits.h>
#include <math.h>
#include <string.h>

#include "pd_core.h"
#include "pd_null.h"

pd_matrix pd_matrix_zero(int rows, int cols)
{
    return (pd_matrix){.kind = PD_MATRIX_ZERO, .rows = rows, .cols = cols};
}

pd_matrix pd_matrix_dense(int rows, int cols, const double *values)
{
    return (pd_matrix){.kind = PD_MATRIX_DENSE, .rows = rows, .cols = cols, .values = values};
}

pd_matrix pd_matrix_csc(int rows, int cols, const int *colptr, const int *rowind,
                        const double *values)
{
    return (pd_matrix){.kind = PD_MATRIX_CSC,
                       .rows = rows,
                       .cols = cols,
                       .values = values,
                       .colptr = colptr,
                       .rowind = rowind};
}

/* y += s A[:, j]. */
static void col_axpy(const pd_matrix *A, int j, double s, double *y)
{
    if (s == 0.0)
        return;
    if (A->kind == PD_MATRIX_DENSE) {
        const double *col = A->values + (size_t)j * A->rows;
        for (int i = 0; i < A->rows; i++)
            y[i] += s * col[i];
    } else if (A->kind == PD_MATRIX_CSC) {
        for (int k = A->colptr[j]; k < A->colptr[j + 1]; k++)
            y[A->rowind[k]] += s * A->values[k];
    }
}

void pd_matrix_col_axpy(const pd_matrix *A, int j, double s, double *y)
{
    if (!A || !y)
        return;
    col_axpy(A, j, s, y);
}

/* A[:, j]^T x. */
static double col_dot(const pd_matrix *A, int j, const double *x)
{
    double s = 0.0;
    if (A->kind == PD_MATRIX_DENSE) {
        const double *col = A->values + (size_t)j * A->rows;
        for (int i = 0; i < A->rows; i++)
            s += col[i] * x[i];
    } else if (A->kind == PD_MATRIX_CSC) {
        for (int k = A->colptr[j]; k < A->colptr[j + 1]; k++)
            s += A->values[k] * x[A->rowind[k]];
    }
    return s;
}

double pd_matrix_col_dot(const pd_matrix *A, int j, const double *x)
{
    if (!A || !x)
        return NAN;
    return col_dot(A, j, x);
}

/* sum_i |A_ij| |x_i|. */
double pd_matrix_col_absdot(const pd_matrix *A, int j, const double *x)
{
    if (!A || !x)
        return NAN;
    double s = 0.0;
    if (A->kind == PD_MATRIX_DENSE) {
        const double *col = A->values + (size_t)j * A->rows;
        for (int i = 0; i < A->rows; i++)
            s += fabs(col[i] * x[i]);
    } else if (A->kind == PD_MATRIX_CSC) {
        for (int k = A->colptr[j]; k < A->colptr[j + 1]; k++)
            s += fabs(A->values[k] * x[A->rowind[k]]);
    }
    return s;
}

/* y = alpha A x + beta y, column by column. */
void pd_matrix_gemv(const pd_matrix *A, double alpha, const double *x, double beta, double *y)
{
    if (!A || !x || !y)
        return;
    for (int i = 0; i < A->rows; i++)
        y[i] = beta == 0.0 ? 0.0 : beta * y[i];
    if (A->kind == PD_MATRIX_ZERO || alpha == 0.0)
        return;
    for (int j = 0; j < A->cols; j++)
        col_axpy(A, j, alpha * x[j], y);
}

/* y_j = A[:, j]^T x. */
void pd_matrix_gemv_t(const pd_matrix *A, const double *x, double *y)
{
    if (!A || !x || !y)
        return;
    for (int j = 0; j < A->cols; j++)
        y[j] = col_dot(A, j, x);
}

double pd_matrix_get(const pd_matrix *A, int i, int j)
{
    if (!A)
        return NAN;
    if (A->kind == PD_MATRIX_DENSE)
        return A->values[i + (size_t)j * A->rows];
    if (A->kind == PD_MATRIX_CSC) /* row indices increase: binary search */
        for (int lo = A->colptr[j], hi = A->colptr[j + 1]; lo < hi;) {
            int mid = lo + (hi - lo) / 2;
            if (A->rowind[mid] == i)
                return A->values[mid];
            if (A->rowind[mid] < i)
                lo = mid + 1;
            else
                hi = mid;
        }
    return 0.0;
}

long pd_matrix_nnz(const pd_matrix *A)
{
    if (!A)
        return 0;
    if (A->kind == PD_MATRIX_DENSE)
        return (long)A->rows * A->cols;
    if (A->kind == PD_MATRIX_CSC)
        return A->colptr[A->cols];
    return 0;
}

void pd_matrix_to_dense(const pd_matrix *A, double *out)
{
    if (!A || !out)
        return;
    memset(out, 0, (size_t)A->rows * (size_t)A->cols * sizeof(double));
    for (int j = 0; j < A->cols; j++)
        col_axpy(A, j, 1.0, out + (size_t)j * A->rows);
}

int pd_matrix_is_diagonal(const pd_matrix *A)
{
    if (!A)
        return 0;
    if (A->kind == PD_MATRIX_DENSE) {
        for (int j = 0; j < A->cols; j++)
            for (int i = 0; i < A->rows; i++)
                if (i != j && A->values[i + (size_t)j * A->rows] != 0.0)
                    return 0;
    } else if (A->kind == PD_MATRIX_CSC) {
        for (int j = 0; j < A->cols; j++)
            for (int k = A->colptr[j]; k < A->colptr[j + 1]; k++)
                if (A->rowind[k] != j && A->values[k] != 0.0)
                    return 0;
    }
    return 1;
}

/* A CSC structure: colptr from 0, nondecreasing, rows in range and increasing. */
static int csc_valid(const pd_matrix *A)
{
    if (!A->colptr || A->colptr[0] != 0 || (A->colptr[A->cols] > 0 && (!A->rowind || !A->values)))
        return 0;
    for (int j = 0; j < A->cols; j++) {
        if (A->colptr[j + 1] < A->colptr[j])
            return 0;
        for (int k = A->colptr[j]; k < A->colptr[j + 1]; k++)
            if (A->rowind[k] < 0 || A->rowind[k] >= A->rows ||
                (k > A->colptr[j] && A->rowind[k] <= A->rowind[k - 1]))
                return 0;
    }
    return 1;
}

int pd_matrix_check(const pd_matrix *A, int rows, int cols, const char *name, pd_err *err)
{
    if (!A || !name)
        return PD_NULL_ARG(err, !A ? "A" : "name");
    if (A->kind == PD_MATRIX_ZERO)
        return A->rows == rows && A->cols == cols
                   ? PD_OK
                   : pd_err_set(err, PD_EINVAL, "model: %s is %d x %d, expected %d x %d", name,
                                A->rows, A->cols, rows, cols);
    if ((A->kind != PD_MATRIX_DENSE && A->kind != PD_MATRIX_CSC) || !A->values)
        return pd_err_set(err, PD_EINVAL, "model: %s has an unknown storage kind", name);
    if (A->rows != rows || A->cols != cols)
        return pd_err_set(err, PD_EINVAL, "model: %s is %d x %d, expected %d x %d", name, A->rows,
                          A->cols, rows, cols);
    if (A->kind == PD_MATRIX_CSC && !csc_valid(A))
        return pd_err_set(err, PD_EINVAL, "model: %s is not a valid compressed-column matrix",
                          name);
    long nnz = pd_matrix_nnz(A);
    for (long k = 0; k < nnz; k++)
        if (!isfinite(A->values[k]))
            return pd_err_set(err, PD_EINVAL, "model: %s has a non-finite entry", name);
    return PD_OK;
}

/* P A = L U by right-looking elimination with scaled partial pivoting.
 * Each row has a scale 2^e, e the binary exponent of its largest entry in
 * A (so the scale is that entry to within a factor 2, and exact to divide
 * by).  The pivot of column k is the entry largest relative to the scale
 * of its row, and A is singular (PD_ESINGULAR) when that pivot is not above
 * rel_tol times the scale of its own row -- not of the largest entry of
 * A: the iteration matrix of two structures of 1e12 and 1e-6 kg is
 * regular, and scaling rows by powers of two changes nothing.  A zero row
 * or a non-finite entry is singular.  The exponents of the rows not yet
 * pivoted live in perm[k..n-1] (no workspace): step k moves the pivot
 * row's out before it writes perm[k]. */
int pd_dense_lu(int n, double *A, int lda, int *perm, double rel_tol)
{
    if (!A || !perm)
        return PD_EINVAL;
    for (int i = 0; i < n; i++)
        perm[i] = INT_MIN;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double a = A[i + (size_t)j * lda];
            if (!isfinite(a))
                return PD_ESINGULAR;
            if (a != 0.0 && ilogb(a) > perm[i])
                perm[i] = ilogb(a);
        }
    for (int i = 0; i < n; i++)
        if (perm[i] == INT_MIN)
            return PD_ESINGULAR;
    for (int k = 0; k < n; k++) {
        double *colk = A + (size_t)k * lda, best = -1.0;
        int p = k;
        for (int i = k; i < n; i++) {
            double scaled = scalbn(fabs(colk[i]), -perm[i]);
            if (scaled > best) {
                best = scaled;
                p = i;
            }
        }
        int e = perm[p];
        perm[p] = perm[k];
        perm[k] = p;
        if (!(fabs(colk[p]) > scalbn(rel_tol, e)) || !isfinite(colk[p]))
            return PD_ESINGULAR;
        if (p != k)
            for (int j = 0; j < n; j++) {
                double *c = A + (size_t)j * lda, t = c[k];
                c[k] = c[p];
                c[p] = t;
            }
        for (int i = k + 1; i < n; i++)
            colk[i] /= colk[k];
        for (int j = k + 1; j < n; j++) {
            double *c = A + (size_t)j * lda, akj = c[k];
            if (akj != 0.0)
                for (int i = k + 1; i < n; i++)
                    c[i] -= colk[i] * akj;
        }
    }
    return PD_OK;
}

/* x = U^-1 L^-1 P b, in place. */
void pd_dense_lu_solve(int n, const double *LU, int lda, const int *perm, double *b)
{
    if (!LU || !perm || !b)
        return;
    for (int k = 0; k < n; k++) {
        int p = perm[k];
        if (p != k) {
            double t = b[k];
            b[k] = b[p];
            b[p] = t;
        }
    }
    for (int j = 0; j < n; j++) { /* L y = P b, unit diagonal */
        const double *c = LU + (size_t)j * lda;
        double bj = b[j];
        if (bj != 0.0)
            for (int i = j + 1; i < n; i++)
                b[i] -= c[i] * bj;
    }
    for (int j = n - 1; j >= 0; j--) { /* U x = y */
        const double *c = LU + (size_t)j * lda;
        b[j] /= c[j];
        double bj = b[j];
        if (bj != 0.0)
            for (int i = 0; i < j; i++)
                b[i] -= c[i] * bj;
    }
}
