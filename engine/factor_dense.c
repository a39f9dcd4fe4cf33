/* factor_dense.c — the scalar and dense storage kinds: What as a number or
 * a dense LU, What^-1 W (n x m) and D = W^T What^-1 W (m x m) kept whole. */
#include <stdlib.h>
#include <string.h>

#include "pd_alloc.h"
#include "pd_factor.h"

#define DENSE_SINGULAR_TOL 1e-14 /* relative pivot floor of What's LU */

typedef struct dense_data {
    double what;  /* scalar kind: the 1 x 1 What */
    double *lu;   /* dense kind: n x n LU factors of What */
    int *perm;    /* dense kind: n row interchanges */
    double *winv; /* n x m: What^-1 W */
    double *del;  /* m x m: W^T What^-1 W */
} dense_data;

static void dense_release(pd_factor *f)
{
    dense_data *d = f->data;
    if (!d)
        return;
    free(d->lu);
    free(d->perm);
    free(d->winv);
    free(d->del);
    free(d);
    f->data = NULL;
}

/* What = M + ht C + ht^2 K into the n x n column-major A. */
static void form_what(const pd_model *md, double ht, double *A)
{
    int n = md->n;
    pd_matrix_to_dense(&md->M, A);
    for (int j = 0; j < n; j++) {
        /* column j: M_j + ht C_j + ht^2 K_j */
        double *col = A + (size_t)j * n;
        pd_matrix_col_axpy(&md->C, j, ht, col);
        pd_matrix_col_axpy(&md->K, j, ht * ht, col);
    }
}

/* The arrays both kinds keep: What^-1 W and D. */
static int alloc_contact_data(dense_data *d, int n, int m)
{
    /* zeroed: form_winv adds W into it; one element when m = 0 */
    d->winv = pd_calloc((long)n * m, sizeof(double));
    d->del = pd_calloc((long)m * m, sizeof(double));
    return d->winv && d->del ? PD_OK : PD_ENOMEM;
}

/* del = W^T winv once winv = What^-1 W. */
static void form_delassus(const pd_factor *f, dense_data *d)
{
    const pd_model *md = f->model;
    int n = md->n, m = md->m;
    /* D_ab = W_a^T (What^-1 W)_b */
    for (int b = 0; b < m; b++)
        for (int a = 0; a < m; a++)
            d->del[a + (size_t)b * m] = pd_matrix_col_dot(&md->W, a, d->winv + (size_t)b * n);
}

/* winv = What^-1 W column by column through the kind's solve. */
static void form_winv(const pd_factor *f, dense_data *d)
{
    const pd_model *md = f->model;
    for (int a = 0; a < md->m; a++) {
        double *col = d->winv + (size_t)a * md->n;
        /* W_a into the zeroed column, then What^-1 W_a in place */
        pd_matrix_col_axpy(&md->W, a, 1.0, col);
        f->type->solve(f, col);
    }
}

/* The scalar kind: What = M + ht C + ht^2 K as one number. */
static int scalar_setup(pd_factor *f, pd_err *err)
{
    const pd_model *md = f->model;
    double ht = f->h * f->theta; /* h theta */
    dense_data *d = calloc(1, sizeof *d);
    f->data = d;
    if (!d || alloc_contact_data(d, 1, md->m))
        return pd_err_set(err, PD_ENOMEM, "factor: out of memory for m = %d contacts", md->m);
    d->what = pd_matrix_get(&md->M, 0, 0) + ht * pd_matrix_get(&md->C, 0, 0) +
              ht * ht * pd_matrix_get(&md->K, 0, 0);
    /* What > 0: a NaN is refused too */
    if (!(d->what > 0.0))
        return pd_err_set(err, PD_ESINGULAR,
                          "the iteration matrix M + h theta C + h^2 theta^2 K = %g is not positive",
                          d->what);
    form_winv(f, d);
    form_delassus(f, d);
    f->delassus_nnz = (long)md->m * md->m; /* D kept whole */
    return PD_OK;
}

static void scalar_solve(const pd_factor *f, double *x)
{
    const dense_data *d = f->data;
    x[0] /= d->what; /* x = x / What */
}

/* The dense kind: LU with partial pivoting of What. */
static int dense_setup(pd_factor *f, pd_err *err)
{
    const pd_model *md = f->model;
    int n = md->n;
    dense_data *d = calloc(1, sizeof *d);
    f->data = d;
    if (!d || !(d->lu = calloc((size_t)n * n, sizeof(double))) ||
        !(d->perm = calloc((size_t)n, sizeof(int))) || alloc_contact_data(d, n, md->m))
        return pd_err_set(err, PD_ENOMEM, "factor: out of memory for a dense %d x %d matrix", n, n);
    form_what(md, f->h * f->theta, d->lu);
    /* LU with partial pivoting; a pivot below 1e-14 (relative) is singular */
    if (pd_dense_lu(n, d->lu, n, d->perm, DENSE_SINGULAR_TOL))
        return pd_err_set(err, PD_ESINGULAR,
                          "the iteration matrix M + h theta C + h^2 theta^2 K is singular");
    form_winv(f, d);
    form_delassus(f, d);
    f->delassus_nnz = (long)md->m * md->m; /* D kept whole */
    return PD_OK;
}

static void dense_solve(const pd_factor *f, double *x)
{
    const dense_data *d = f->data;
    pd_dense_lu_solve(f->model->n, d->lu, f->model->n, d->perm, x);
}

/* v += sum_r What^-1 W[:, idx_r] P_r. */
static void dense_add_impulse(const pd_factor *f, const int *idx, int nI, const double *P,
                              double *v)
{
    const dense_data *d = f->data;
    int n = f->model->n;
    for (int r = 0; r < nI; r++) {
        const double *col = d->winv + (size_t)idx[r] * n;
        if (P[r] != 0.0) /* a zero impulse adds nothing */
            for (int i = 0; i < n; i++)
                v[i] += col[i] * P[r];
    }
}

static void dense_delassus(const pd_factor *f, const int *idx, int nI, double *D)
{
    const dense_data *d = f->data;
    pd_factor_gather_dense(d->del, f->model->m, idx, nI, D); /* D_II out of the whole D */
}

static int dense_delassus_csc(const pd_factor *f, const int *idx, int nI, int *colptr, int *rowind,
                              double *values, int *map)
{
    const dense_data *d = f->data;
    return pd_factor_gather_dense_csc(d->del, f->model->m, idx, nI, colptr, rowind, values, map);
}

static long dense_delassus_at(const pd_factor *f, int a, int b)
{
    const dense_data *d = f->data;
    return pd_factor_dense_at(d->del, f->model->m, a, b);
}

const pd_factor_type pd_factor_scalar_type = {
    .name = "scalar",
    .kind = PD_FACTOR_SCALAR,
    .setup = scalar_setup,
    .solve = scalar_solve,
    .add_impulse = dense_add_impulse,
    .delassus_dense = dense_delassus,
    .delassus_csc = dense_delassus_csc,
    .delassus_at = dense_delassus_at,
    .release = dense_release,
};

const pd_factor_type pd_factor_dense_type = {
    .name = "dense",
    .kind = PD_FACTOR_DENSE,
    .setup = dense_setup,
    .solve = dense_solve,
    .add_impulse = dense_add_impulse,
    .delassus_dense = dense_delassus,
    .delassus_csc = dense_delassus_csc,
    .delassus_at = dense_delassus_at,
    .release = dense_release,
};
