/* pd_lcp_dump.h — (cli) LCP dumps: every LCP of a Moreau–Jean run written to
 * HDF5 (lcp_dump.c), and a dump read back to re-solve it. */
#ifndef PD_LCP_DUMP_H
#define PD_LCP_DUMP_H

#include "pd_engine.h"

typedef struct pd_lcp_dump pd_lcp_dump;

/* Create PATH.tmpPID. */
int pd_lcp_dump_open(pd_lcp_dump **d, const char *path, pd_err *err);
/* A pd_lcp_observer (ctx: the dump); stops the run if a write fails. */
int pd_lcp_dump_add(const pd_matrix *D, const double *b, const double *z, const double *w,
                    const pd_lcp_info *info, const int *idx, double t, void *ctx);
/* Write what is buffered, close, rename into place. */
int pd_lcp_dump_finish(pd_lcp_dump *d, pd_err *err);
long pd_lcp_dump_count(const pd_lcp_dump *d);
/* Release; an unfinished file is removed. */
void pd_lcp_dump_free(pd_lcp_dump *d);

/* A dump in memory: LCP k has n[k] unknowns, D by columns at colptr +
 * poff[k] (indices into rowind/values from eoff[k]), b and z at voff[k]. */
typedef struct pd_lcp_set {
    long count;
    int nmax, nnzmax;
    int *n, *solver, *outcome, *iterations, *pivots, *colptr, *rowind;
    double *t, *values, *b, *z;
    long *voff, *poff, *eoff;
} pd_lcp_set;

int pd_lcp_set_read(const char *path, pd_lcp_set *s, pd_err *err);
void pd_lcp_set_free(pd_lcp_set *s);
pd_matrix pd_lcp_set_matrix(const pd_lcp_set *s, long k);
const char *pd_lcp_set_solver_name(int code);

#endif
