/* factor.c — choosing the storage kind of the iteration matrix, and the
 * object's lifecycle. */
#include <stdlib.h>
#include <string.h>

#include "pd_factor.h"

static const pd_factor_type *const factor_types[] = {&pd_factor_scalar_type, &pd_factor_dense_type,
                                                     &pd_factor_cholmod_type};

const char *pd_factor_kind_name(pd_factor_kind kind)
{
    if (kind == PD_FACTOR_AUTO)
        return "auto";
    for (size_t k = 0; k < sizeof factor_types / sizeof factor_types[0]; k++)
        if (factor_types[k]->kind == kind)
            return factor_types[k]->name;
    return "?";
}

int pd_factor_kind_parse(const char *name, pd_factor_kind *kind)
{
    if (!name || !kind)
        return PD_EINVAL;
    if (!strcmp(name, "auto")) {
        *kind = PD_FACTOR_AUTO;
        return PD_OK;
    }
    for (size_t k = 0; k < sizeof factor_types / sizeof factor_types[0]; k++)
        if (!strcmp(name, factor_types[k]->name)) {
            *kind = factor_types[k]->kind;
            return PD_OK;
        }
    return PD_EINVAL;
}

/* Model no more than the scene needs: a number for one degree of freedom,
 * dense for small or dense models, sparse Cholesky for the rest. */
pd_factor_kind pd_factor_choose(const pd_model *model, pd_factor_kind requested)
{
    if (!model)
        return PD_FACTOR_AUTO;
    if (requested != PD_FACTOR_AUTO)
        return requested; /* the caller's choice stands */
    if (model->n == 1)
        return PD_FACTOR_SCALAR; /* What is a number */
    /* small, or any matrix stored dense: the dense LU */
    if (model->n <= PD_FACTOR_DENSE_MAX || model->M.kind == PD_MATRIX_DENSE ||
        model->C.kind == PD_MATRIX_DENSE || model->K.kind == PD_MATRIX_DENSE ||
        (model->m > 0 && model->W.kind == PD_MATRIX_DENSE))
        return PD_FACTOR_DENSE;
    return PD_FACTOR_CHOLMOD; /* large and sparse */
}

pd_factor *pd_factor_alloc(const pd_model *model, double h, double theta, pd_factor_kind kind,
                           pd_err *err)
{
    pd_factor_kind chosen = pd_factor_choose(model, kind);
    const pd_factor_type *type = NULL;
    for (size_t k = 0; k < sizeof factor_types / sizeof factor_types[0]; k++)
        if (factor_types[k]->kind == chosen)
            type = factor_types[k];
    if (!type) {
        pd_err_set(err, PD_EINVAL, "factor: unknown storage kind %d", (int)kind);
        return NULL;
    }
    /* the scalar kind asked for by name */
    if (chosen == PD_FACTOR_SCALAR && model->n != 1) {
        pd_err_set(err, PD_EINVAL, "factor: the scalar kind needs one degree of freedom (n = %d)",
                   model->n);
        return NULL;
    }
    pd_factor *f = calloc(1, sizeof *f);
    if (!f) {
        pd_err_set(err, PD_ENOMEM, "factor: out of memory");
        return NULL;
    }
    *f = (pd_factor){.type = type, .model = model, .h = h, .theta = theta};
    /* the kind forms and factors What = M + h theta C + h^2 theta^2 K, What^-1 W and D */
    if (type->setup(f, err)) {
        pd_factor_free(f);
        return NULL;
    }
    return f;
}

void pd_factor_free(pd_factor *f)
{
    if (!f)
        return;
    f->type->release(f); /* the kind's own data */
    free(f);
}

/* The place of D_ab (column a, row b) in a dense m x m D, or -1 for an exact
 * zero (left out of the compressed D_II). */
long pd_factor_dense_at(const double *D, int m, int a, int b)
{
    long k = b + (long)a * m;
    return D[k] != 0.0 ? k : -1;
}

void pd_factor_gather_dense(const double *D, int m, const int *idx, int nI, double *out)
{
    for (int s = 0; s < nI; s++) {
        const double *col = D + (size_t)idx[s] * m; /* out_rs = D_idx[r],idx[s] */
        for (int r = 0; r < nI; r++)
            out[r + (size_t)s * nI] = col[idx[r]];
    }
}

int pd_factor_gather_dense_csc(const double *D, int m, const int *idx, int nI, int *colptr,
                               int *rowind, double *values, int *map)
{
    int nz = 0;
    for (int s = 0; s < nI; s++) {
        const double *col = D + (size_t)idx[s] * m;
        colptr[s] = nz;
        /* exact zeros of D left out */
        for (int r = 0; r < nI; r++)
            if (col[idx[r]] != 0.0) {
                if (map) /* D_(idx_s, idx_r) is D's entry idx_r + idx_s m */
                    map[idx[r] + (size_t)idx[s] * m] = nz;
                rowind[nz] = r;
                values[nz++] = col[idx[r]];
            }
    }
    colptr[nI] = nz; /* the entries of D_II */
    return nz;
}
