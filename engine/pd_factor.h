/* pd_factor.h — (internal) the factorisation seam of the engine.
 *
 * The integrators need five things of the iteration matrix
 * What = M + h theta C + h^2 theta^2 K (What = M when h = 0):
 *   solve        x = What^-1 x
 *   impulse      v += What^-1 W_I P            (the velocity jump of impulses P)
 *   delassus     D_II = W_I^T What^-1 W_I      (dense, or compressed columns)
 * for an index set I of contacts (indices increasing).  The object keeps
 * scratch of its own: one factor serves one integrator at a time.  A storage kind implements them in one
 * table; every kind precomputes What^-1 W and D = W^T What^-1 W once, dense
 * for the scalar and dense kinds, sparse for CHOLMOD (whose D holds only the
 * pairs of contacts that share a coupled block of What). */
#ifndef PD_FACTOR_H
#define PD_FACTOR_H

#include "pd_engine.h"

typedef struct pd_factor pd_factor;

typedef struct pd_factor_type {
    const char *name;
    pd_factor_kind kind;
    int (*setup)(pd_factor *f, pd_err *err);      /* form and factor, precompute */
    void (*solve)(const pd_factor *f, double *x); /* x = What^-1 x */
    void (*add_impulse)(const pd_factor *f, const int *idx, int nI, const double *P, double *v);
    /* D_II into a dense nI x nI column-major array */
    void (*delassus_dense)(const pd_factor *f, const int *idx, int nI, double *D);
    /* D_II in compressed columns (row indices increasing, idx increasing);
     * returns the entries (at most delassus_nnz).  map (or NULL): for each
     * entry of D gathered, map[k] = its place in values, k as delassus_at */
    int (*delassus_csc)(const pd_factor *f, const int *idx, int nI, int *colptr, int *rowind,
                        double *values, int *map);
    /* the index k < delassus_nnz of D's stored entry (a, b) (the contacts'),
     * or -1 where D keeps none */
    long (*delassus_at)(const pd_factor *f, int a, int b);
    void (*release)(pd_factor *f);
} pd_factor_type;

struct pd_factor {
    const pd_factor_type *type;
    const pd_model *model;
    double h, theta;
    long delassus_nnz; /* entries of D stored: bounds the entries of any D_II */
    void *data;        /* the storage kind's own */
};

extern const pd_factor_type pd_factor_scalar_type;
extern const pd_factor_type pd_factor_dense_type;
extern const pd_factor_type pd_factor_cholmod_type;

/* Form and factor What for the model, h and theta, in the kind chosen by
 * pd_factor_choose.  NULL on failure (err says why). */
pd_factor *pd_factor_alloc(const pd_model *model, double h, double theta, pd_factor_kind kind,
                           pd_err *err);
void pd_factor_free(pd_factor *f);

static inline void pd_factor_solve(const pd_factor *f, double *x)
{
    f->type->solve(f, x);
}
static inline void pd_factor_add_impulse(const pd_factor *f, const int *idx, int nI,
                                         const double *P, double *v)
{
    f->type->add_impulse(f, idx, nI, P, v); /* v += What^-1 W_I P */
}
static inline void pd_factor_delassus_dense(const pd_factor *f, const int *idx, int nI, double *D)
{
    f->type->delassus_dense(f, idx, nI, D); /* D_II = W_I^T What^-1 W_I */
}
static inline int pd_factor_delassus_csc(const pd_factor *f, const int *idx, int nI, int *colptr,
                                         int *rowind, double *values, int *map)
{
    return f->type->delassus_csc(f, idx, nI, colptr, rowind, values, map); /* its entries */
}
static inline long pd_factor_delassus_at(const pd_factor *f, int a, int b)
{
    return f->type->delassus_at(f, a, b); /* D_ab's place, or -1 */
}

/* ---- helpers the dense kinds share (factor.c) ------------------------------ */

/* The place of D_ab (column a, row b) in a dense m x m D, or -1 for an exact zero. */
long pd_factor_dense_at(const double *D, int m, int a, int b);
/* D_II from a dense m x m D. */
void pd_factor_gather_dense(const double *D, int m, const int *idx, int nI, double *out);
/* D_II from a dense m x m D into compressed columns (entries that are 0 dropped). */
int pd_factor_gather_dense_csc(const double *D, int m, const int *idx, int nI, int *colptr,
                               int *rowind, double *values, int *map);

#endif
