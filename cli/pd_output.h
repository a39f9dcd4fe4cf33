/* pd_output.h — (cli) output files: every file pound writes goes to a
 * temporary name beside it and is renamed into place once complete, so a
 * failed, refused or interrupted run leaves no partial file behind; tables
 * of columns plus attributes streamed to HDF5 or CSV; checks made before a
 * run starts (the name, the folder writable, the room for the file). */
#ifndef PD_OUTPUT_H
#define PD_OUTPUT_H

#include <stdio.h>
#include <sys/types.h>

#include "pd_core.h"

enum {
    PD_PATH_MAX = 4096,       /* the longest output path */
    PD_OUTPUT_NOTICE_MB = 100 /* larger outputs are announced on stderr */
};

/* ---- checks before a run ------------------------------------------------ */

/* PD_OK when path has a supported extension (.h5, .hdf5, .csv) and the
 * file can be written (pd_output_check_writable); else PD_EINVAL with a
 * message naming -o and the reason. */
int pd_output_check_path(const char *path, pd_err *err);

/* Can `flag path` be written?  Symlinks followed; a directory refused;
 * a temporary file is created beside it and removed.  PD_OK, or PD_EINVAL
 * with "FLAG PATH: <the system's reason>". */
int pd_output_check_writable(const char *flag, const char *path, pd_err *err);

/* Is there room for about `bytes` on path's file system?  PD_OK, or
 * PD_EINVAL naming the sizes (the estimate is refused when it exceeds the
 * space free there). */
int pd_output_check_room(const char *flag, const char *path, double bytes, pd_err *err);

/* Do the n outputs name n different files?  flags[k] and paths[k] as given
 * (paths[k] NULL: that output is not written).  Two paths are the same file
 * when, symlinks followed, their folders resolve to one folder and their
 * names agree, or when they are one existing file (hard links too).  PD_OK,
 * or PD_EINVAL with "FLAG1 PATH1 and FLAG2 PATH2 name the same file". */
int pd_output_check_distinct(int n, const char *const *flags, const char *const *paths,
                             pd_err *err);

/* ---- interrupted runs --------------------------------------------------- */

/* SIGINT, SIGTERM and SIGHUP (unless ignored) remove every temporary file
 * still registered, then end the process by the signal's default action.
 * Called once by main. */
void pd_output_signals(void);

/* ---- an output file replaced atomically --------------------------------- */

typedef struct pd_outfile {
    const char *flag, *given;   /* "-o" and the path as given, for messages */
    char path[PD_PATH_MAX];     /* the file replaced (symlinks followed) */
    char tmp[PD_PATH_MAX + 32]; /* path.tmpPID, renamed onto path */
    int slot;                   /* its signal-cleanup slot (-1: none) */
    int keep_mode;              /* path exists: its mode goes to the new file */
    mode_t mode;
} pd_outfile;

/* Before writing o->tmp: follow symlinks, refuse a directory, note the mode
 * of a file being replaced, remove stale path.tmp<PID> files of processes
 * that are gone, register o->tmp for removal on a signal.  PD_OK or PD_EIO. */
int pd_outfile_begin(pd_outfile *o, const char *flag, const char *given, pd_err *err);
/* o->tmp is complete: give it the old mode, sync it, rename it onto
 * o->path.  PD_OK, or PD_EIO with the reason (the temporary removed). */
int pd_outfile_commit(pd_outfile *o, pd_err *err);
/* Remove the temporary file (if any) and unregister it; idempotent. */
void pd_outfile_abort(pd_outfile *o);
/* "FLAG GIVEN: <strerror(e)>" into err as PD_EIO. */
int pd_outfile_error(const pd_outfile *o, int e, pd_err *err);

/* ---- text files whose every write is checked --------------------------- */

typedef struct pd_csv {
    FILE *f;
    int failure; /* errno of the first failed write, 0 if none */
} pd_csv;

/* Open path for writing: 0, or the errno. */
int pd_csv_open(pd_csv *c, const char *path);
/* Formatted output; after a failure nothing more is written.  0 or -1. */
int pd_csv_printf(pd_csv *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Flush and close (c->f NULL after): 0, or the errno of the first failure. */
int pd_csv_close(pd_csv *c);

/* ---- provenance (docs/formats.md) --------------------------------------- */

/* What every file pound writes records about its making, before anything
 * else: root attributes of an HDF5 file, the first '#' lines of a CSV file.
 *   format         the layout's name and version, "pound simulate oscillator 1"
 *   command        the command line: "pound", then the arguments, each quoted
 *                  for a POSIX shell when it needs it (Python's shlex.quote
 *                  rule, so shlex.split(command) gives the arguments back)
 *   pound_version  pd_version()
 *   created        the UTC time the file was begun, "2025-01-31T12:00:00Z";
 *                  absent from reproducible files (spectra), which hold the
 *                  same bytes whenever and however they are computed */
enum { PD_COMMAND_MAX = 16384 };

/* The formats (a layout's name and version). */
#define PD_FORMAT_OSCILLATOR "pound simulate oscillator 1"
#define PD_FORMAT_SCENE "pound simulate scene 1"
#define PD_FORMAT_LCP_DUMP "pound LCP dump 1"
#define PD_FORMAT_CONVERGE "pound converge 1"
#define PD_FORMAT_SPECTRUM "pound spectrum 1"
#define PD_FORMAT_SPECTRUM_SCENE "pound spectrum scene 1"

typedef struct pd_provenance {
    const char *format, *command, *pound_version;
    char created[32]; /* "" in reproducible files */
} pd_provenance;

/* This process's command line (argv as a command receives it, argv[0] its
 * name: "simulate"), the format of the tables it writes (pd_table_open,
 * pd_output_write) and whether its files are reproducible.  Each command
 * that writes files calls it once, before writing; until then the command
 * is "pound" and the format "pound table 1".  A command line longer than
 * PD_COMMAND_MAX is cut and ends in "...". */
void pd_provenance_set(int argc, char *const *argv, const char *table_format, int reproducible);

/* The provenance of a file of `format` (NULL: the tables' format) begun now. */
void pd_provenance_now(pd_provenance *p, const char *format);

/* Is `format` the format of this process's tables?  (An LCP dump of the
 * oscillator is in its dimensionless units, a scene's in SI.) */
int pd_provenance_tables_are(const char *format);

/* p as '#' lines ("# format = ..."): 0 or -1. */
int pd_provenance_csv(pd_csv *c, const pd_provenance *p);

/* A "# name = text" line, control bytes in text written as '?' (a CSV
 * comment is one line): 0 or -1. */
int pd_csv_comment(pd_csv *c, const char *name, const char *text);

/* ---- tables ------------------------------------------------------------- */

typedef struct pd_attr {
    const char *name;
    const char *units; /* NULL or "" = dimensionless / none */
    int is_text;
    double num;
    const char *text;
} pd_attr;

typedef struct pd_column {
    const char *name;
    const char *units;    /* NULL or "": "1" (dimensionless, or a code) */
    const double *values; /* pd_output_write only */
    /* A coded column (labels non-NULL): its values are codes 0..nlabels-1;
     * the CSV writes labels[code] as text, the HDF5 file the code with a
     * "codes" attribute naming them ("0 = moreau, 1 = event, ..."); a code
     * outside the labels is written as a number. */
    const char *const *labels;
    int nlabels;
} pd_column;

typedef struct pd_table {
    long rows;
    int ncols;
    const pd_column *cols;
    int nattrs;
    const pd_attr *attrs;
    const char *dim; /* the rows' dimension (pd_table_open); NULL: "row" */
} pd_table;

/* Write the table to path: HDF5 when it ends in .h5/.hdf5 (the provenance
 * and the attributes on the root, one 1-D dataset per column with a "units"
 * attribute, all along the dimension table->dim), CSV when it ends in .csv ('#' lines with the provenance and
 * the attributes, "# units = U1,U2,..." with one unit per column, the
 * header row, the rows); anything else is PD_EINVAL. */
int pd_output_write(const char *path, const pd_table *table, pd_err *err);

/* The same files streamed: rows are written in blocks as they come (memory
 * stays bounded whatever their number), the attributes at the end. */
typedef struct pd_table_writer pd_table_writer;

/* Open path.tmpPID for ncols columns (names and units kept until finish);
 * expected_rows sizes the HDF5 chunks.  The HDF5 columns are along the
 * dimension dim (NULL: "row"): a column of that name is its coordinate
 * ("t"), else the file gets a dimension of that name without values
 * (pd_h5_dimension).  PD_OK, PD_EINVAL or PD_EIO. */
int pd_table_open(pd_table_writer **w, const char *path, int ncols, const pd_column *cols,
                  const char *dim, long expected_rows, pd_err *err);
/* One row of ncols values: 0, or -1 once a write has failed (stop). */
int pd_table_row(pd_table_writer *w, const double *row);
/* The rows buffered, the attributes; close, rename into place. */
int pd_table_finish(pd_table_writer *w, int nattrs, const pd_attr *attrs, pd_err *err);
/* Release; an unfinished file is removed. */
void pd_table_free(pd_table_writer *w);

#endif
