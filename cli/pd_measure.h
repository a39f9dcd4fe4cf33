/* pd_measure.h — (cli) errors of a method against the event-driven
 * reference on a common output grid (compare, converge). */
#ifndef PD_MEASURE_H
#define PD_MEASURE_H

#include "pd_cli.h"

/* u on the output grid t_k = k dt, preallocated once per run. */
typedef struct pd_trace {
    double *u;
    long n, cap;
} pd_trace;

typedef struct pd_measured {
    pd_osc_result r;
    double err_umax_rel, err_hist_linf;
    long grid_points;
} pd_measured;

int pd_trace_alloc(pd_trace *tr, const pd_osc_opts *o); /* 0 or -1 */
void pd_trace_free(pd_trace *tr);

/* The reference on the grid of o (dt, tend); res->cpu_s is its cost
 * without sampling. */
int pd_measure_reference(const pd_cli_case *k, const pd_osc_opts *o, pd_trace *ref,
                         pd_osc_result *res, pd_err *err);

/* Run a method on the same grid (work sized by pd_trace_alloc for o) and
 * measure its errors against ref; out->r.cpu_s is the cost of a second run
 * without sampling. */
int pd_measure_run(const pd_cli_case *k, pd_method method, const pd_osc_opts *o,
                   const pd_trace *ref, double umax_ref, pd_trace *work, pd_measured *out,
                   pd_err *err);

#endif
