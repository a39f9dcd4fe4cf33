/* factor_dense.c — dense LU of the iteration matrix and the Delassus data. */
#include <stdlib.h>
#include <string.h>

#include "pd_factor.h"

typedef struct dense_data {
    double *lu;    /* n x n LU factors of What */
    int *perm;     /* n row interchanges */
    double *winv;  /* n x m: What^-1 W */
    double *del;   /* m x m: W^T What^-1 W */
} dense_data;

/* A += s B for n x n views (zero kind adds nothing). */
static void add_scaled(const pd_matrix *B, double s, double *A, int n)
{
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++)
            A[i + (size_t)j * n] += s * pd_matrix_get(B, i, j);
}

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

/* What = M + h theta C + (h theta)^2 K, LU, then What^-1 W and W^T What^-1 W. */
static int dense_setup(pd_factor *f, pd_err *err)
{
    const pd_model *md = f->model;
    int n = md->n, m = md->m;
    double ht = f->h * f->theta;
    dense_data *d = calloc(1, sizeof *d);
    f->data = d;
    if (!d || !(d->lu = calloc((size_t)n * n, sizeof(double))) ||
        !(d->perm = calloc((size_t)n, sizeof(int))) ||
        !(d->winv = calloc((size_t)n * (m ? m : 1), sizeof(double))) ||
        !(d->del = calloc((size_t)(m ? m : 1) * (m ? m : 1), sizeof(double))))
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for the iteration matrix");
    add_scaled(&md->M, 1.0, d->lu, n);
    add_scaled(&md->C, ht, d->lu, n);
    add_scaled(&md->K, ht * ht, d->lu, n);
    if (pd_dense_lu(n, d->lu, d->perm))
        return pd_err_set(err, PD_ESINGULAR,
                          "Moreau-Jean: the iteration matrix M + h theta C + h^2 theta^2 K is "
                          "singular");
    for (int a = 0; a < m; a++) {
        double *col = d->winv + (size_t)a * n;
        for (int i = 0; i < n; i++)
            col[i] = pd_matrix_get(&md->W, i, a);
        pd_dense_lu_solve(n, d->lu, d->perm, col);
    }
    for (int b = 0; b < m; b++)
        for (int a = 0; a < m; a++) {
            double s = 0.0;
            for (int i = 0; i < n; i++)
                s += pd_matrix_get(&md->W, i, a) * d->winv[i + (size_t)b * n];
            d->del[a + (size_t)b * m] = s;
        }
    return PD_OK;
}

static void dense_solve(const pd_factor *f, double *x)
{
    const dense_data *d = f->data;
    pd_dense_lu_solve(f->model->n, d->lu, d->perm, x);
}

/* D_rs = del[idx_r, idx_s]. */
static void dense_delassus(const pd_factor *f, const int *idx, int nI, double *D)
{
    const dense_data *d = f->data;
    int m = f->model->m;
    for (int s = 0; s < nI; s++)
        for (int r = 0; r < nI; r++)
            D[r + (size_t)s * nI] = d->del[idx[r] + (size_t)idx[s] * m];
}

/* v += sum_r What^-1 W[:, idx_r] P_r. */
static void dense_add_impulse(const pd_factor *f, const int *idx, int nI, const double *P,
                              double *v)
{
    const dense_data *d = f->data;
    int n = f->model->n;
    for (int r = 0; r < nI; r++) {
        const double *col = d->winv + (size_t)idx[r] * n;
        if (P[r] != 0.0)
            for (int i = 0; i < n; i++)
                v[i] += col[i] * P[r];
    }
}

const pd_factor_type pd_factor_dense_type = {"dense-lu", dense_setup, dense_solve,
                                             dense_delassus, dense_add_impulse, dense_release};

pd_factor *pd_factor_alloc(const pd_model *model, double h, double theta, pd_err *err)
{
    pd_factor *f = calloc(1, sizeof *f);
    if (!f) {
        pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory");
        return NULL;
    }
    f->type = &pd_factor_dense_type;
    f->model = model;
    f->h = h;
    f->theta = theta;
    if (f->type->setup(f, err)) {
        pd_factor_free(f);
        return NULL;
    }
    return f;
}

void pd_factor_free(pd_factor *f)
{
    if (!f)
        return;
    f->type->release(f);
    free(f);
}
