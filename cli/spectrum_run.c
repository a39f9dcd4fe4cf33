/* spectrum_run.c — computing a sweep's tasks.
 *
 * Every task runs in decreasing order of expected cost (a run lasts
 * Tp + 2 T0, so small Pi2 points cost most: starting with them leaves only
 * small tasks for the end).  Distribution is dynamic at both levels: the
 * threads of a rank take one task at a time from a shared cursor; MPI
 * workers ask rank 0 for chunks of the same queue (guided: large chunks of
 * the costly tasks first, small ones at the end) before they run dry, while
 * rank 0 computes from it too.  Every task writes only its own slot of the
 * result array, so the numbers do not depend on who computed what. */
#include <fcntl.h>
#include <gsl/gsl_errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pd_spectrum.h"

#ifdef _OPENMP
#include <omp.h>
#define PD_OMP(x) _Pragma(x)
#else
#define PD_OMP(x)
#endif

/* A task and its expected cost. */
typedef struct costed {
    double cost;
    long task;
} costed;

/* The state of a computation; touched in the critical section only. */
typedef struct run_ctx {
    const pd_spectrum *s;
    const pd_spec_exec *ex;
    pd_spec_result *res;
    double *cost;
    long *order; /* tasks to do, in decreasing cost (rank 0's queue) */
    long norder, cursor;
    int nthreads;
    /* rank 0: progress, failures, workers still running */
    long ntasks, ndone, finished_here;
    double total_cost, done_cost, start_cost, t0, last_draw;
    int bar_shown, workers_left;
    long first_bad; /* lowest failed task, -1 if none */
    char msg[256];  /* its message ("" when a worker computed it) */
    /* a worker: tasks granted, results not yet reported */
    long *queue; /* a ring of qcap = PD_SPEC_CHUNK + nthreads + 1 */
    int qcap, qhead, qlen, asked, no_more;
    pd_spec_report out;
    double last_report;
} run_ctx;

/* Decreasing cost, then increasing task (a total order). */
static int by_cost(const void *a, const void *b)
{
    const costed *x = a, *y = b;
    if (x->cost != y->cost)
        return x->cost < y->cost ? 1 : -1;
    return (x->task > y->task) - (x->task < y->task);
}

/* Redraw the progress bar (at most ten times a second, once the sweep
 * looks longer than a second); final: erase it. */
static void progress(run_ctx *c, int final)
{
    double now = pd_wall_seconds(), el = now - c->t0;
    if (!c->ex->progress || c->ex->rank != 0)
        return;
    if (final) {
        if (c->bar_shown)
            fputs("\r\033[K", stderr);
        return;
    }
    double frac = c->done_cost / c->total_cost, rate = (c->done_cost - c->start_cost) / el;
    double left = rate > 0.0 ? (c->total_cost - c->done_cost) / rate : NAN;
    if (now - c->last_draw < 0.1 || (!c->bar_shown && (el < 0.5 || !(el + left > 1.0))))
        return;
    char bar[31];
    int fill = (int)(30.0 * frac);
    for (int i = 0; i < 30; i++)
        bar[i] = i < fill ? '#' : '-';
    bar[30] = '\0';
    fprintf(stderr, "\rspectrum [%s] %3d%%  %ld/%ld runs  %.1f s, ~%.1f s left \033[K", bar,
            (int)(100.0 * frac), c->ndone, c->ntasks, el, left);
    fflush(stderr);
    c->last_draw = now;
    c->bar_shown = 1;
}

/* Rank 0: a finished task (computed here or reported) is stored, journaled
 * and counted; a failure is remembered if it is the lowest so far. */
static void record(run_ctx *c, long t, const pd_spec_result *r, const char *msg)
{
    c->res[t] = *r;
    c->ndone++;
    c->done_cost += c->cost[t];
    if (r->status == 0 && c->ex->journal)
        pd_spec_journal_append(c->ex->journal, t, r);
    if (r->status != 0 && (c->first_bad < 0 || t < c->first_bad)) {
        c->first_bad = t;
        snprintf(c->msg, sizeof c->msg, "%s", msg);
    }
    progress(c, 0);
}

/* Rank 0: a chunk of the queue for a worker that asked for `want` tasks
 * (guided: a quarter of the remaining tasks per rank, at most a chunk). */
static void grant(run_ctx *c, int to, int want)
{
    pd_spec_grant g;
    long left = c->norder - c->cursor, k = left / (4L * c->ex->size);
    k = k < want ? want : k;
    k = k > PD_SPEC_CHUNK ? PD_SPEC_CHUNK : k;
    k = k > left ? left : k;
    g.n = (int)k;
    for (int i = 0; i < g.n; i++)
        g.task[i] = c->order[c->cursor++];
    pd_spec_mpi_grant(to, &g);
}

/* Rank 0: handle workers' reports (block: wait for one first). */
static void serve(run_ctx *c, int block)
{
    pd_spec_report m;
    int from;
    while (c->workers_left > 0 && pd_spec_mpi_poll_report(block, &m, &from)) {
        for (int k = 0; k < m.n; k++)
            record(c, m.task[k], &m.r[k], "");
        if (m.want > 0)
            grant(c, from, m.want);
        c->workers_left -= m.last;
        block = 0;
    }
}

/* A worker: send the finished tasks not yet reported, asking for `want`
 * more; last marks the worker's final message. */
static void report(run_ctx *c, int want, int last)
{
    c->out.want = want;
    c->out.last = last;
    pd_spec_mpi_report(&c->out);
    c->out.n = 0;
    c->asked |= want > 0;
    c->last_report = pd_wall_seconds();
}

/* A worker: take rank 0's answer when it is there (block: wait for it). */
static void take_grant(run_ctx *c, int block)
{
    pd_spec_grant g;
    if (!c->asked || !pd_spec_mpi_poll_grant(block, &g))
        return;
    c->asked = 0;
    c->no_more = g.n == 0;
    for (int i = 0; i < g.n; i++)
        c->queue[(c->qhead + c->qlen++) % c->qcap] = g.task[i];
}

/* The next task for a thread of this rank, or -1 when none is left. */
static long next_task(run_ctx *c)
{
    if (c->ex->rank == 0) {
        serve(c, 0);
        return c->cursor < c->norder ? c->order[c->cursor++] : -1;
    }
    if (!c->asked && !c->no_more && c->qlen <= c->nthreads)
        report(c, c->nthreads, 0); /* a chunk fits: qlen + PD_SPEC_CHUNK < qcap */
    take_grant(c, c->qlen == 0);
    if (c->qlen == 0)
        return -1;
    long t = c->queue[c->qhead];
    c->qhead = (c->qhead + 1) % c->qcap;
    c->qlen--;
    return t;
}

/* A task finished in this process. */
static void finished(run_ctx *c, long t, const pd_spec_result *r, const char *msg)
{
    if (c->ex->rank == 0) {
        record(c, t, r, msg);
        serve(c, 0);
    } else {
        c->out.task[c->out.n] = t;
        c->out.r[c->out.n++] = *r;
        if (c->out.n == PD_SPEC_BATCH || pd_wall_seconds() - c->last_report > 0.25)
            report(c, 0, 0);
    }
    if (c->ex->stop_after > 0 && ++c->finished_here >= c->ex->stop_after)
        _exit(130); /* the test hook: die like an interrupted sweep */
}

/* The message of the lowest failed task: a worker's failure is run again
 * here (the same deterministic computation fails the same way). */
static void failure_message(run_ctx *c, pd_err *err)
{
    pd_spec_result r;
    if (!c->msg[0])
        pd_spec_run_task(c->s, c->first_bad, &r, err);
    else
        pd_err_set(err, c->res[c->first_bad].status, "%s", c->msg);
    err->status = c->res[c->first_bad].status;
}

/* Costs of every task, the totals, and the queue of tasks to do in
 * decreasing cost: 0 or -1 (out of memory). */
static int plan(run_ctx *c)
{
    costed *all = malloc((size_t)(c->ntasks + 1) * sizeof *all);
    c->cost = malloc((size_t)(c->ntasks + 1) * sizeof *c->cost);
    c->order = malloc((size_t)(c->ntasks + 1) * sizeof *c->order);
    c->qcap = PD_SPEC_CHUNK + c->nthreads + 1;
    c->queue = malloc((size_t)c->qcap * sizeof *c->queue);
    if (!all || !c->cost || !c->order || !c->queue) {
        free(all);
        return -1;
    }
    for (long t = 0; t < c->ntasks; t++) {
        c->cost[t] = pd_spec_cost(c->s, t);
        c->total_cost += c->cost[t];
        if (c->res[t].done) {
            c->done_cost += c->cost[t];
            c->ndone++;
        } else
            all[c->norder++] = (costed){c->cost[t], t};
    }
    c->start_cost = c->done_cost;
    qsort(all, (size_t)c->norder, sizeof *all, by_cost);
    for (long i = 0; i < c->norder; i++)
        c->order[i] = all[i].task;
    free(all);
    return 0;
}

int pd_spec_threads(int requested)
{
#ifdef _OPENMP
    return requested > 0 ? requested : omp_get_max_threads();
#else
    (void)requested;
    return 1;
#endif
}

/* A thread's source: the next task of the shared queue. */
static long stream_next(void *ctx)
{
    run_ctx *c = ctx;
    long t;
    PD_OMP("omp critical(pd_spectrum)")
    t = next_task(c);
    return t;
}

/* A thread's sink: the finished task stored (rank 0) or reported. */
static void stream_done(void *ctx, long t, const pd_spec_result *r, const pd_err *err)
{
    run_ctx *c = ctx;
    PD_OMP("omp critical(pd_spectrum)")
    finished(c, t, r, err->msg);
}

/* The threads of this rank take tasks until none is left, each thread a
 * stream of them (the Moreau-Jean ones run many at a time). */
static void compute_here(run_ctx *c)
{
    PD_OMP("omp parallel num_threads(c->nthreads)")
    pd_spec_stream(c->s, stream_next, stream_done, c, NULL);
}

/* Every task's case resolves, the no-wall twins' too (pd_spec_validate
 * checks the points only): PD_OK, or PD_EINVAL with the first bad task's
 * message, before anything is computed. */
static int validate_all(const run_ctx *c, pd_err *err)
{
    pd_osc oc;
    pd_run_opts o;
    for (long t = 0; t < c->ntasks; t++)
        if (pd_spec_case(c->s, t, &oc, &o, err))
            return PD_EINVAL;
    return PD_OK;
}

/* Rank 0, a sweep ending as bad input (exit 2): a journal this run created
 * holds nothing worth resuming (the same flags fail the same way), and left
 * behind it would make the next run refuse to start ("an interrupted
 * sweep"), so it goes.  The journal tells by its descriptor: one created by
 * this run is open write-only, one resumed read-write (spectrum_journal.c);
 * that one is kept. */
static void drop_own_journal(const pd_spec_exec *ex)
{
    pd_spec_journal *j = ex->journal;
    if (ex->rank == 0 && j && j->fd >= 0 && (fcntl(j->fd, F_GETFL) & O_ACCMODE) == O_WRONLY)
        pd_spec_journal_close(j, 1);
}

int pd_spec_compute(const pd_spectrum *s, const pd_spec_exec *ex, pd_spec_result *res, pd_err *err)
{
    run_ctx *c = calloc(1, sizeof *c);
    int rc = PD_OK;
    if (!c)
        return pd_err_set(err, PD_ENOMEM, "out of memory");
    c->s = s;
    c->ex = ex;
    c->res = res;
    c->ntasks = pd_spec_tasks(s);
    c->nthreads = pd_spec_threads(ex->threads);
    c->t0 = c->last_report = pd_wall_seconds();
    c->first_bad = -1;
    c->workers_left = ex->rank == 0 ? ex->size - 1 : 0;
    if ((rc = validate_all(c, err)))
        goto done;
    if (plan(c)) {
        rc = pd_err_set(err, PD_ENOMEM, "out of memory for %ld tasks", c->ntasks);
        if (ex->size > 1) { /* the other ranks would wait for this one */
            fprintf(stderr, "pound: spectrum: rank %d: %s\n", ex->rank, err->msg);
            pd_spec_mpi_abort(1);
        }
        goto done;
    }
    /* GSL's error handler is process-wide: the penalty runs turn it off
     * (the same store from every thread); do it once before the threads. */
    if (s->opts.method == PD_METHOD_PENALTY)
        gsl_set_error_handler_off();
    compute_here(c);
    if (ex->rank != 0)
        report(c, 0, 1);
    while (c->workers_left > 0)
        serve(c, 1);
    progress(c, 1);
    if (ex->rank == 0 && c->first_bad >= 0) {
        failure_message(c, err);
        rc = err->status;
    } else if (ex->rank == 0 && c->ndone != c->ntasks)
        rc = pd_err_set(err, PD_EIO, "%ld of %ld runs were not reported", c->ntasks - c->ndone,
                        c->ntasks);
done:
    if (rc == PD_EINVAL)
        drop_own_journal(ex);
    free(c->cost);
    free(c->order);
    free(c->queue);
    free(c);
    return rc;
}
