/* solver.c — the LCP solver table: one object, one solve call, whatever
 * the method and the matrix storage. */
#include <stdlib.h>
#include <string.h>

#include "pd_lcp.h"

/* One method of the table. */
typedef struct solver_type {
    pd_lcp_method method;
    const char *name;
} solver_type;

static const solver_type solver_types[] = {
    {PD_LCP_AUTO, "auto"},
    {PD_LCP_LEMKE, "lemke"},
};

#define NTYPES (int)(sizeof solver_types / sizeof solver_types[0])

struct pd_lcp_solver {
    pd_lcp_method method;
    int nmax;
    pd_lcp_work *lemke; /* Lemke's workspace */
    double *dense;      /* nmax x nmax: a sparse matrix copied for Lemke */
};

const char *pd_lcp_method_name(pd_lcp_method method)
{
    for (int k = 0; k < NTYPES; k++)
        if (solver_types[k].method == method)
            return solver_types[k].name;
    return "?";
}

int pd_lcp_method_parse(const char *name, pd_lcp_method *method)
{
    for (int k = 0; name && k < NTYPES; k++)
        if (!strcmp(name, solver_types[k].name)) {
            *method = solver_types[k].method;
            return PD_OK;
        }
    return PD_EINVAL;
}

const char *pd_lcp_method_list(void)
{
    return "auto, lemke";
}

void pd_lcp_solver_free(pd_lcp_solver *s)
{
    if (!s)
        return;
    pd_lcp_free(s->lemke);
    free(s->dense);
    free(s);
}

pd_lcp_solver *pd_lcp_solver_alloc(pd_lcp_method method, int nmax, long nnzmax, pd_err *err)
{
    pd_lcp_solver *s = NULL;
    if (nmax < 1 || nnzmax < 0 || !strcmp(pd_lcp_method_name(method), "?")) {
        pd_err_set(err, PD_EINVAL, "LCP solver: bad method %d or size %d", (int)method, nmax);
        return NULL;
    }
    s = calloc(1, sizeof *s);
    if (!s)
        goto oom;
    s->method = method;
    s->nmax = nmax;
    if (!(s->lemke = pd_lcp_alloc(nmax)))
        goto oom;
    if (nnzmax > 0 && !(s->dense = malloc((size_t)nmax * (size_t)nmax * sizeof(double))))
        goto oom;
    return s;
oom:
    pd_lcp_solver_free(s);
    pd_err_set(err, PD_ENOMEM, "LCP solver: out of memory for %d unknowns", nmax);
    return NULL;
}

int pd_lcp_solver_nmax(const pd_lcp_solver *s)
{
    return s ? s->nmax : 0;
}

/* Lemke on a dense view, or on a CSC matrix copied into the dense buffer. */
static int solve_lemke(pd_lcp_solver *s, const pd_matrix *M, const double *q,
                       const pd_lcp_opts *opts, double *z, double *w, pd_lcp_info *info)
{
    const double *dense = M->values;
    if (M->kind != PD_MATRIX_DENSE) {
        if (!s->dense)
            return PD_EINVAL;
        pd_matrix_to_dense(M, s->dense);
        dense = s->dense;
    }
    return pd_lcp_lemke(s->lemke, M->rows, dense, q, opts, z, w, info);
}

int pd_lcp_solve(pd_lcp_solver *s, const pd_matrix *M, const double *q, const pd_lcp_opts *opts,
                 double *z, double *w, pd_lcp_info *info)
{
    pd_lcp_info local;
    int rc;
    if (!info)
        info = &local;
    memset(info, 0, sizeof *info);
    info->outcome = PD_LCP_NUMERICAL;
    info->solver = "lemke";
    if (!s || !M || M->rows != M->cols || M->rows < 1 || M->rows > s->nmax ||
        (M->kind != PD_MATRIX_DENSE && M->kind != PD_MATRIX_CSC))
        return PD_EINVAL;
    rc = solve_lemke(s, M, q, opts, z, w, info);
    info->solver = "lemke";
    return rc;
}
