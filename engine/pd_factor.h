/* pd_factor.h — (internal) the factorisation seam of the engine.
 *
 * The stepping code needs four things of the iteration matrix
 * What = M + h theta C + h^2 theta^2 K: factor it once, solve with it, form
 * the Delassus block W_I^T What^-1 W_I of an active set, and add
 * What^-1 W_I P to a velocity.  A storage kind implements them in one
 * table; the dense one precomputes What^-1 W and W^T What^-1 W once. */
#ifndef PD_FACTOR_H
#define PD_FACTOR_H

#include "pd_engine.h"

typedef struct pd_factor pd_factor;

typedef struct pd_factor_type {
    const char *name;
    int (*setup)(pd_factor *f, pd_err *err);                           /* form and factor */
    void (*solve)(const pd_factor *f, double *x);                      /* x = What^-1 x */
    void (*delassus)(const pd_factor *f, const int *idx, int nI, double *D); /* nI x nI */
    void (*add_impulse)(const pd_factor *f, const int *idx, int nI, const double *P, double *v);
    void (*release)(pd_factor *f);
} pd_factor_type;

struct pd_factor {
    const pd_factor_type *type;
    const pd_model *model;
    double h, theta;
    void *data; /* the storage kind's own */
};

extern const pd_factor_type pd_factor_dense_type;

pd_factor *pd_factor_alloc(const pd_model *model, double h, double theta, pd_err *err);
void pd_factor_free(pd_factor *f);

static inline void pd_factor_solve(const pd_factor *f, double *x) { f->type->solve(f, x); }
static inline void pd_factor_delassus(const pd_factor *f, const int *idx, int nI, double *D)
{
    f->type->delassus(f, idx, nI, D);
}
static inline void pd_factor_add_impulse(const pd_factor *f, const int *idx, int nI,
                                         const double *P, double *v)
{
    f->type->add_impulse(f, idx, nI, P, v);
}

#endif
