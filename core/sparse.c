/* sparse.c — an owned compressed-column matrix assembled from triplets. */
#include <stdlib.h>
#include <string.h>

#include "pd_alloc.h"
#include "pd_core.h"
#include "pd_null.h"

void pd_sparse_free(pd_sparse *sp)
{
    if (!sp)
        return;
    free(sp->colptr);
    free(sp->rowind);
    free(sp->values);
    memset(sp, 0, sizeof *sp);
}

pd_matrix pd_sparse_view(const pd_sparse *sp)
{
    if (!sp)
        return pd_matrix_zero(0, 0);
    return pd_matrix_csc(sp->rows, sp->cols, sp->colptr, sp->rowind, sp->values);
}

/* Sort the entries of each column by row (insertion sort: columns are short)
 * and sum the duplicates; returns the compressed count. */
static int compress_columns(pd_sparse *sp)
{
    int out = 0;
    for (int j = 0; j < sp->cols; j++) {
        int start = sp->colptr[j], end = sp->colptr[j + 1], first = out;
        for (int k = start + 1; k < end; k++) {
            int r = sp->rowind[k];
            double x = sp->values[k];
            int p = k;
            for (; p > start && sp->rowind[p - 1] > r; p--) {
                sp->rowind[p] = sp->rowind[p - 1];
                sp->values[p] = sp->values[p - 1];
            }
            sp->rowind[p] = r;
            sp->values[p] = x;
        }
        for (int k = start; k < end; k++) {
            if (out > first && sp->rowind[out - 1] == sp->rowind[k]) {
                sp->values[out - 1] += sp->values[k];
                continue;
            }
            sp->rowind[out] = sp->rowind[k];
            sp->values[out++] = sp->values[k];
        }
        sp->colptr[j] = first;
    }
    sp->colptr[sp->cols] = out;
    return out;
}

/* Counting sort of the triplets by column, then each column sorted. */
int pd_sparse_from_triplets(pd_sparse *sp, int rows, int cols, long nt, const int *Ti,
                            const int *Tj, const double *Tx, pd_err *err)
{
    int *next = NULL;
    if (!sp)
        return PD_NULL_ARG(err, "sp");
    memset(sp, 0, sizeof *sp);
    if (nt > 0 && (!Ti || !Tj || !Tx))
        return PD_NULL_ARG(err, !Ti ? "Ti" : !Tj ? "Tj" : "Tx");
    if (rows < 0 || cols < 0 || nt < 0 || nt > 2147483647L)
        return pd_err_set(err, PD_EINVAL, "sparse: bad size %d x %d with %ld entries", rows, cols,
                          nt);
    for (long k = 0; k < nt; k++)
        if (Ti[k] < 0 || Ti[k] >= rows || Tj[k] < 0 || Tj[k] >= cols)
            return pd_err_set(err, PD_EINVAL, "sparse: entry (%d, %d) outside %d x %d", Ti[k],
                              Tj[k], rows, cols);
    sp->rows = rows;
    sp->cols = cols;
    sp->colptr = calloc((size_t)cols + 1, sizeof(int));
    sp->rowind = pd_malloc(nt, sizeof(int));
    sp->values = pd_malloc(nt, sizeof(double));
    next = malloc(((size_t)cols + 1) * sizeof(int));
    if (!sp->colptr || !sp->rowind || !sp->values || !next) {
        free(next);
        pd_sparse_free(sp);
        return pd_err_set(err, PD_ENOMEM, "sparse: out of memory for %ld entries", nt);
    }
    for (long k = 0; k < nt; k++)
        sp->colptr[Tj[k] + 1]++;
    for (int j = 0; j < cols; j++)
        sp->colptr[j + 1] += sp->colptr[j];
    memcpy(next, sp->colptr, ((size_t)cols + 1) * sizeof(int));
    for (long k = 0; k < nt; k++) {
        int p = next[Tj[k]]++;
        sp->rowind[p] = Ti[k];
        sp->values[p] = Tx[k];
    }
    free(next);
    sp->nnz = compress_columns(sp);
    return PD_OK;
}
