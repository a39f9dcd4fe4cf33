/* pd_journal.h — (cli) an append-only journal of finished work (a spectrum
 * sweep's points, a suite's records), so that an interrupted run resumes
 * where it stopped (journal.c).
 *
 *   <magic line>
 *   key <the canonical key of the run>
 *   <body> #<fnv1a of body>          one line per finished item
 *
 * Each line is one write(2) on an O_APPEND descriptor: a killed process
 * leaves whole lines and at worst one torn last line, which the checksum
 * exposes and the reader drops. */
#ifndef PD_JOURNAL_H
#define PD_JOURNAL_H

#include <stddef.h>

#include "pd_problems.h"

typedef struct pd_journal {
    int fd;
    char path[4096];
    double last_sync;
    int failed; /* an append failed: warned once, the run goes on */
} pd_journal;

/* What a journal is for, in its messages: its first line, the flag that
 * names it, the kind of run ("sweep", "suite"). */
typedef struct pd_journal_kind {
    const char *magic; /* with its newline */
    const char *flag;  /* "-o", "--journal" */
    const char *what;  /* "spectrum", "suite" (in "not a pound spectrum journal") */
    const char *run;   /* "sweep", "suite" */
} pd_journal_kind;

/* A line read back (its checksum checked and cut off, no newline): 0, or
 * -1 to skip it as malformed. */
typedef int (*pd_journal_reader)(const char *body, size_t len, void *ctx);

/* Open path: with resume, read back the lines of a journal whose header
 * matches key (each through read, a torn last line cut off; none there: a
 * new one); without resume, create it (an existing one is an error:
 * PD_EINVAL, as is a header that does not match or a journal locked by a
 * running process). */
int pd_journal_open(pd_journal *j, const pd_journal_kind *kind, const char *path, const char *key,
                    int resume, pd_journal_reader read, void *ctx, pd_err *err);
/* Append body (no newline) as one checksummed line, written at once,
 * fdatasync'd at most once a second: 0 or -1. */
int pd_journal_append(pd_journal *j, const char *body, size_t len);
/* Close; remove the file when remove is set. */
void pd_journal_close(pd_journal *j, int remove);

/* ---- a suite's finished records (suite_journal.c) ------------------------ *
 * simulate --records ... --journal F [--resume]: each finished record's
 * summary as one line, every figure to the bit (C99 hexadecimal, or the
 * struct's bytes), so that a resumed suite prints what an uninterrupted
 * one prints; MPI ranks send rank 0 the same lines. */

/* The names (kernel, factor, ...) read back: they outlive the summaries
 * that point at them. */
typedef struct pd_suite_names {
    char **s;
    int n, cap;
} pd_suite_names;

void pd_suite_names_free(pd_suite_names *p);

/* Open the suite's journal at path (as pd_journal_open; its magic line and
 * messages a suite's). */
int pd_suite_journal_open(pd_journal *j, const char *path, const char *key, int resume,
                          pd_journal_reader read, void *ctx, pd_err *err);

/* Record k's summary as a line's body (malloc'd, its length in *len; NULL
 * when out of memory or a name cannot be written). */
char *pd_suite_osc_body(int k, const pd_osc_summary *s, size_t *len);
char *pd_suite_scene_body(int k, const pd_scene_summary *s, size_t *len);
/* A body read back: the record k in [0, n) and its summary (a scene's
 * allocated for sc: pd_scene_summary_free frees it), the names kept in
 * names: 0, or -1 when malformed (nothing left allocated in s). */
int pd_suite_osc_parse(const char *body, size_t len, int n, int *k, pd_osc_summary *s,
                       pd_suite_names *names);
int pd_suite_scene_parse(const char *body, size_t len, const pd_scene *sc, int n, int *k,
                         pd_scene_summary *s, pd_suite_names *names);

#endif
