/* matrix.c — matrix views, y = A x, dense LU, and model checks. */
#include <math.h>

#include "pd_engine.h"

pd_matrix pd_matrix_dense(int rows, int cols, const double *values)
{
    pd_matrix A = {PD_MATRIX_DENSE, rows, cols, values};
    return A;
}

/* y = alpha A x + beta y, column by column (contiguous axpy). */
void pd_matrix_gemv(const pd_matrix *A, double alpha, const double *x, double beta, double *y)
{
    for (int i = 0; i < A->rows; i++)
        y[i] = beta == 0.0 ? 0.0 : beta * y[i];
    if (A->kind != PD_MATRIX_DENSE || alpha == 0.0)
        return;
    for (int j = 0; j < A->cols; j++) {
        const double *col = A->values + (size_t)j * A->rows;
        double s = alpha * x[j];
        if (s == 0.0)
            continue;
        for (int i = 0; i < A->rows; i++)
            y[i] += s * col[i];
    }
}

/* y_j = sum_i A_ij x_i (a dot product per column). */
void pd_matrix_gemv_t(const pd_matrix *A, const double *x, double *y)
{
    for (int j = 0; j < A->cols; j++) {
        double s = 0.0;
        if (A->kind == PD_MATRIX_DENSE) {
            const double *col = A->values + (size_t)j * A->rows;
            for (int i = 0; i < A->rows; i++)
                s += col[i] * x[i];
        }
        y[j] = s;
    }
}

double pd_matrix_get(const pd_matrix *A, int i, int j)
{
    return A->kind == PD_MATRIX_DENSE ? A->values[i + (size_t)j * A->rows] : 0.0;
}

/* P A = L U by Gaussian elimination with partial pivoting (right-looking). */
int pd_dense_lu(int n, double *A, int *perm)
{
    for (int k = 0; k < n; k++) {
        double *colk = A + (size_t)k * n;
        int p = k;
        double big = fabs(colk[k]), scale = 0.0;
        for (int i = k; i < n; i++) {
            double a = fabs(colk[i]);
            if (a > big) {
                big = a;
                p = i;
            }
        }
        for (int i = 0; i < n; i++)
            scale = fmax(scale, fabs(colk[i]));
        perm[k] = p;
        if (!(big > 1e-14 * scale) || big == 0.0)
            return PD_ESINGULAR;
        if (p != k)
            for (int j = 0; j < n; j++) {
                double *c = A + (size_t)j * n, t = c[k];
                c[k] = c[p];
                c[p] = t;
            }
        for (int i = k + 1; i < n; i++)
            colk[i] /= colk[k];
        for (int j = k + 1; j < n; j++) {
            double *c = A + (size_t)j * n, akj = c[k];
            if (akj != 0.0)
                for (int i = k + 1; i < n; i++)
                    c[i] -= colk[i] * akj;
        }
    }
    return PD_OK;
}

/* x = U^-1 L^-1 P b, in place. */
void pd_dense_lu_solve(int n, const double *LU, const int *perm, double *b)
{
    for (int k = 0; k < n; k++) {
        int p = perm[k];
        if (p != k) {
            double t = b[k];
            b[k] = b[p];
            b[p] = t;
        }
    }
    for (int j = 0; j < n; j++) { /* L y = P b, unit diagonal */
        const double *c = LU + (size_t)j * n;
        double bj = b[j];
        if (bj != 0.0)
            for (int i = j + 1; i < n; i++)
                b[i] -= c[i] * bj;
    }
    for (int j = n - 1; j >= 0; j--) { /* U x = y */
        const double *c = LU + (size_t)j * n;
        b[j] /= c[j];
        double bj = b[j];
        if (bj != 0.0)
            for (int i = 0; i < j; i++)
                b[i] -= c[i] * bj;
    }
}

/* A matrix of the expected shape with finite entries. */
static int check_matrix(const pd_matrix *A, int rows, int cols, const char *name, pd_err *err)
{
    if (A->kind == PD_MATRIX_ZERO)
        return PD_OK;
    if (A->kind != PD_MATRIX_DENSE || !A->values)
        return pd_err_set(err, PD_EINVAL, "model: %s has an unknown storage kind", name);
    if (A->rows != rows || A->cols != cols)
        return pd_err_set(err, PD_EINVAL, "model: %s is %d x %d, expected %d x %d", name, A->rows,
                          A->cols, rows, cols);
    for (size_t k = 0; k < (size_t)rows * cols; k++)
        if (!isfinite(A->values[k]))
            return pd_err_set(err, PD_EINVAL, "model: %s has a non-finite entry", name);
    return PD_OK;
}

int pd_model_check(const pd_model *model, pd_err *err)
{
    int st;
    if (!model || model->n <= 0 || model->m < 0)
        return pd_err_set(err, PD_EINVAL, "model: needs n > 0 degrees of freedom and m >= 0 contacts");
    if (model->M.kind != PD_MATRIX_DENSE)
        return pd_err_set(err, PD_EINVAL, "model: the mass matrix M must be given");
    if ((st = check_matrix(&model->M, model->n, model->n, "M", err)) ||
        (st = check_matrix(&model->C, model->n, model->n, "C", err)) ||
        (st = check_matrix(&model->K, model->n, model->n, "K", err)))
        return st;
    if (model->m == 0)
        return PD_OK;
    if ((st = check_matrix(&model->W, model->n, model->m, "W", err)))
        return st;
    if (!model->g0 || !model->e)
        return pd_err_set(err, PD_EINVAL, "model: gaps g0 and restitution e are required");
    for (int a = 0; a < model->m; a++) {
        if (!(model->g0[a] >= 0.0) || !isfinite(model->g0[a]))
            return pd_err_set(err, PD_EINVAL, "model: gap of contact %d is %g, must be >= 0", a,
                              model->g0[a]);
        if (!(model->e[a] >= 0.0 && model->e[a] <= 1.0))
            return pd_err_set(err, PD_EINVAL,
                              "model: restitution of contact %d is %g, must be in [0, 1]", a,
                              model->e[a]);
    }
    return PD_OK;
}

long pd_steps_for(double tend, double h)
{
    double r = tend / h, k = floor(r + 0.5);
    if (fabs(r - k) <= 1e-9 * fmax(1.0, r))
        return (long)k;
    return (long)ceil(r);
}
