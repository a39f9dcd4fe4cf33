/* pd_spectrum.h — (cli) computing a spectrum sweep (pd_problems.h defines
 * the sweep and its tasks): the journal that makes it resumable, MPI ranks
 * and OpenMP threads taking tasks dynamically, and the output files. */
#ifndef PD_SPECTRUM_H
#define PD_SPECTRUM_H

#include "pd_cli.h"
#include "pd_journal.h"

/* `pound spectrum` (cmd_spectrum.c): the exit status. */
int pd_cmd_spectrum(int argc, char **argv);

/* `pound spectrum --scene` (spectrum_scene.c): the Pi spectra of a scene. */
typedef struct pd_scene_sweep_args {
    const pd_cli_case *k;
    const char *ref_name;
    int ref_contact;
    double pi2_min, pi2_max;
    int npi2, linear;
    int npi3, neps;
    const double *pi3, *eps;
    const char *out, *plot;
    int json, threads;
} pd_scene_sweep_args;

int pd_cmd_spectrum_scene(const pd_scene_sweep_args *a, double wall0);

/* ---- the journal of finished tasks (spectrum_journal.c) ------------------ */

typedef pd_journal pd_spec_journal;

/* Open OUT.partial: with resume, read back the finished tasks (res[t].done)
 * whose header matches key, dropping a torn last line; without resume,
 * create it (an existing one is an error: PD_EINVAL, as is a header that
 * does not match or a journal locked by a running sweep). */
int pd_spec_journal_open(pd_spec_journal *j, const char *out, const char *key, long ntasks,
                         int resume, pd_spec_result *res, long *loaded, pd_err *err);
/* Append one finished task as one checksummed line (written at once,
 * fdatasync'd at most once a second): 0 or -1. */
int pd_spec_journal_append(pd_spec_journal *j, long task, const pd_spec_result *r);
/* Close; remove the file when remove is set. */
void pd_spec_journal_close(pd_spec_journal *j, int remove);

/* ---- MPI (spectrum_mpi.c; stubs without -DPD_MPI) ------------------------ */

/* Start MPI (the MPI build) or refuse to run as one of several copies
 * under mpirun (the plain build): 0, or 2 after printing why. */
int pd_spec_mpi_init(const char *cmd, int *rank, int *size, int *threaded);
void pd_spec_mpi_finalize(void);
/* End every rank at once (a rank that cannot go on would leave the others
 * waiting); no-op in the plain build. */
void pd_spec_mpi_abort(int status);
/* The largest status of any rank, on every rank. */
void pd_spec_mpi_agree(int *status);
/* Rank 0's n bytes at p on every rank (no-op in the plain build). */
void pd_mpi_bcast_bytes(void *p, long n);
/* A text of len bytes to rank 0 (a suite's finished record): 0, or -1
 * when it is too long (and always in the plain build). */
int pd_mpi_send_text(const char *text, size_t len);
/* Rank 0: the next text a rank sent (block: wait for one), malloc'd and
 * NUL-terminated, its length in *len; NULL when none is there (out of
 * memory ends every rank: the others would wait for this one). */
char *pd_mpi_recv_text(int block, size_t *len);
/* Rank 0's done flags on every rank. */
int pd_spec_mpi_bcast_done(pd_spec_result *res, long ntasks);
/* Dynamic distribution: rank 0 holds the queue of tasks (in decreasing
 * cost) and computes from it too; a worker asks for a chunk of tasks before
 * it runs dry and reports finished tasks in batches (messages under 4 kB,
 * sent eagerly). */
enum { PD_SPEC_BATCH = 40, PD_SPEC_CHUNK = 64 };

/* A worker's message to rank 0: finished tasks, a request for `want` more
 * tasks (0: none), and whether it is the worker's last message. */
typedef struct pd_spec_report {
    int n, want, last;
    long task[PD_SPEC_BATCH];
    pd_spec_result r[PD_SPEC_BATCH];
} pd_spec_report;

/* Rank 0's answer to a request: tasks to compute (n = 0: none are left). */
typedef struct pd_spec_grant {
    int n;
    long task[PD_SPEC_CHUNK];
} pd_spec_grant;

void pd_spec_mpi_report(const pd_spec_report *m);
/* Rank 0: a worker's report, if any (block: wait for one): 1 and its
 * sender in *from, else 0. */
int pd_spec_mpi_poll_report(int block, pd_spec_report *m, int *from);
void pd_spec_mpi_grant(int to, const pd_spec_grant *g);
/* A worker: rank 0's answer, if any (block: wait for it): 1 or 0. */
int pd_spec_mpi_poll_grant(int block, pd_spec_grant *g);

/* ---- computing (spectrum_run.c) ------------------------------------------ */

/* How to compute. */
typedef struct pd_spec_exec {
    int threads;              /* OpenMP threads per rank; 0 = the OpenMP default */
    int progress;             /* a progress bar on stderr (rank 0) */
    long stop_after;          /* test hook: exit(130) after this many tasks; 0 = never */
    pd_spec_journal *journal; /* rank 0's journal, or NULL */
    int rank, size;           /* MPI; size 1: this process computes every task */
} pd_spec_exec;

/* The threads a rank uses for `requested` (0: the OpenMP default; 1
 * without OpenMP). */
int pd_spec_threads(int requested);

/* Compute every task not yet done.  On rank 0 all results are in res at
 * the end; the status of the lowest failed task (0 if none) is returned
 * there, with its message in err. */
int pd_spec_compute(const pd_spectrum *s, const pd_spec_exec *ex, pd_spec_result *res, pd_err *err);

/* ---- output (spectrum_out.c) --------------------------------------------- */

/* HDF5 (one group per curve) or CSV (one row per point) by extension,
 * through a temporary file renamed on success. */
int pd_spec_write(const char *path, const pd_spectrum *s, const pd_spec_row *rows, pd_err *err);
/* PNG.png: Pi1 vs Pi2 (log-log); PNG-gamma.png: gamma vs Pi2; with the
 * dimensional view PNG-dim.png: umax [cm] vs T0 [s]. */
int pd_spec_plot(const char *png, const pd_spectrum *s, const pd_spec_row *rows, pd_err *err);
/* A suite's charts (png, png-gamma.png, png-dim.png: Pi1, gamma, umax [cm]
 * against T0 or Pi2): each of the nrec records' curves (rows: nrec x the
 * points of s) faint, and their mean (mean: the points of s). */
int pd_spec_plot_suite(const char *png, const pd_spectrum *s, int nrec, const pd_spec_row *rows,
                       const pd_spec_row *mean, int use_T0, pd_err *err);
/* Totals printed beside the points. */
typedef struct pd_spec_totals {
    double cpu_s, wall_s, steps; /* steps: of every run, twins included */
    long runs, resumed;
    int threads, ranks;
    const char *method_by; /* how the method was chosen: "default", or the flag */
} pd_spec_totals;
void pd_spec_print_json(const pd_spectrum *s, const pd_spec_row *rows, const pd_spec_totals *t);
/* One point as a JSON object (the "points" entries of --json). */
void pd_spec_json_point(pd_json *js, const pd_spectrum *s, const pd_spec_row *r);
void pd_spec_print_text(const pd_spectrum *s, const pd_spec_row *rows, const pd_spec_totals *t);

#endif
