/* pd_cli.h — the pound command line: subcommands, argument parsing helpers
 * and a small JSON writer.  Only this layer prints or exits. */
#ifndef PD_CLI_H
#define PD_CLI_H

#include <stdio.h>

#include "pd_problems.h"

/* Subcommands: each returns the process exit status (0 ok, 1 run failure,
 * 2 bad input). */
int pd_cmd_lcp(int argc, char **argv);
int pd_cmd_simulate(int argc, char **argv);
int pd_cmd_bench(int argc, char **argv);
int pd_cmd_compare(int argc, char **argv);
int pd_cmd_converge(int argc, char **argv);
int pd_cmd_spectrum(int argc, char **argv);
int pd_cmd_record(int argc, char **argv);

/* ---- the shared case flags (case.c) ------------------------------------ */

/* What the model, scheme, method and scene flags set, with what was given. */
/* A record read by a case (--record) and its fitted pulse. */
typedef struct pd_cli_record {
    pd_record rec;
    pd_record_pulse pulse;
} pd_cli_record;

typedef struct pd_cli_case {
    pd_osc c;
    pd_run_opts opts;
    double T0, gap; /* dimensional forms when given */
    double height;  /* --height: the oscillator's storey height [m] (drift ratio) */
    int have_height;
    int have_T0, have_Pi2, have_gap, have_Pi3, have_dt, have_tend, have_kc;
    double uy;                         /* --uy: the yield displacement [m] when given */
    int have_uy, have_Piy, have_alpha; /* --uy, --Piy, --alpha given */
    double rtol; /* --rtol: Moreau-Jean's tolerance, or the penalty integrator's */
    int have_rtol;
    const char *model_flag;  /* the first model flag given (refused with --scene) */
    const char *scene_path;  /* --scene F */
    pd_scene *scene;         /* F read once when the case needed it (--target-sa's T1) */
    int chain;               /* --chain N (0: none) */
    double chain_ratio;      /* --chain-ratio R */
    const char *record_path; /* --record F */
    const char *pulse_flag;  /* --pulse, --ap or --Tp when given (refused with --record) */
    const char *dt_flag;     /* the flag that set dt (--dt, or spectrum's --dt-per-Tp) */
    double scale;            /* --scale S */
    int have_scale;
    pd_record_format rec_format; /* --record-format */
    pd_record_units rec_units;   /* --units (text records) */
    int have_units;              /* --units given */
    pd_cli_record *record;       /* read by pd_cli_case_finish; released by pd_cli_case_free */
    /* a suite (--record repeated, or --records FILE): its records, read by
     * pd_cli_case_finish (record above is recs[0]), each one's scale (the
     * suite file's times --scale, or the target's) */
    pd_suite *suite;
    const char *records_path; /* --records FILE */
    pd_cli_record **recs;
    double *rec_scale;
    pd_scale_target target; /* --target-pga or --target-sa */
    double target_value;    /* [m/s^2] */
    const char *target_flag;
    double T1;             /* --T1: Sa's period [s] */
    const char *suites_by; /* the command that runs suites (NULL: it takes one record) */
    int have_T1;
    pd_osc c_base;       /* the oscillator as the flags set it, before a record */
    pd_run_opts opts_in; /* the options as the flags set them, before resolution */
    /* the method: --method's, else the one the flags given belong to (a
     * flag of one method's only: --theta, --kc, ...), else the default;
     * method_by names the flag that chose it (NULL: the default) */
    const char *method_by;
    const char *implies[4];       /* per pd_method: the first flag given that only it takes */
    const char *method_flags[24]; /* the flags given that some methods only take */
    int n_method_flags;
    int methods_listed; /* compare, converge: --methods chooses per run */
} pd_cli_case;

extern const char pd_cli_case_help[];

void pd_cli_case_init(pd_cli_case *a);
/* The quantities derived from a checked case (T0, Le, the gap, tend, the
 * work of the run) finite and bounded: 0, or 2 with one line naming the
 * flag that made them overflow (spectrum checks its sweep's corners). */
int pd_cli_case_check_derived(const pd_cli_case *a);

/* Flag f is one method's only: the method, unless --method says another. */
void pd_cli_case_implies(pd_cli_case *a, const char *flag, pd_method method);
/* The method a run of the checked case takes (scenes: Moreau-Jean by
 * default; the oscillator's is resolved by pd_cli_case_finish). */
pd_method pd_cli_case_method(const pd_cli_case *a);
/* How the method was chosen, for the output: "--method", the flag that
 * implied it, or "default". */
const char *pd_cli_method_by(const pd_cli_case *a);

/* Consume the flag at argv[*i] (and its value): 1 if it was a case flag,
 * 0 if not (the caller handles it), 2 after printing an error. */
int pd_cli_case_flag(pd_cli_case *a, int argc, char **argv, int *i);
/* Derive T0/gap forms, check ranges; the oscillator gets its dt and tend
 * defaults (a scene gets them from pd_scene_resolve_opts): 0 or 2. */
int pd_cli_case_finish(pd_cli_case *a);
/* What pd_cli_case_finish took (the record). */
void pd_cli_case_free(pd_cli_case *a);
/* A suite of records was given (--record twice or more, or --records). */
int pd_cli_case_is_suite(const pd_cli_case *a);
/* The oscillator of the suite's record k (the checked case's flags on it:
 * T0, gap and uy in metres kept, Pi forms kept) into *c, its options
 * resolved into *o: 0 or 2 (one line printed).  The single run of that
 * record is made by the same function. */
int pd_cli_case_record(const pd_cli_case *a, int k, pd_osc *c, pd_run_opts *o);
/* The suite's record k on scene sc's excitation (its pulse's ap and Tp,
 * its scale), the scene's duration derived for it unless --tend; the
 * scene finished again (PD_OK, or the excitation's error). */
int pd_cli_scene_record(const pd_cli_case *a, int k, pd_scene *sc, pd_err *err);
/* Read a record and fit its pulse: 0, or 2 after printing the file's error.
 * --units given (units_given) on a format that fixes its units (AT2, V2) is
 * refused; a peak acceleration implausible in its units (pd_record_plausible)
 * gets one warning line on stderr. */
int pd_cli_record_load(const char *path, pd_record_format format, pd_record_units units,
                       int units_given, pd_cli_record **out);
/* The paper's Fig. 2 for up to 6 records (plot_records.c). */
int pd_plot_records(const char *png, const pd_cli_record *const *recs, int n, pd_err *err);
/* 1 when --scene or --chain was given. */
int pd_cli_is_scene(const pd_cli_case *a);
/* The scene of --scene or --chain, its options checked: 0, or 2 (1 when
 * out of memory) after printing why. */
int pd_cli_scene(const pd_cli_case *a, pd_scene **sc);

/* Print "pound: <message>" on stderr and return 2 (bad input). */
int pd_cli_usage_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* When argv holds --help or -h: print usage (and the case flags' help when
 * with_case) on stdout and return 1; else 0. */
int pd_cli_help(int argc, char **argv, const char *usage, int with_case);

/* Parse a finite double / an int from a flag's value; on failure print an
 * error naming the flag and return 2, else 0. */
int pd_cli_double(const char *flag, const char *text, double *out);
int pd_cli_int(const char *flag, const char *text, int *out);

/* A streaming JSON writer: objects, arrays and scalar members. */
typedef struct pd_json {
    FILE *out;
    int depth;
    int need_comma[32];
} pd_json;

void pd_json_init(pd_json *js, FILE *out);
void pd_json_begin_object(pd_json *js, const char *key); /* key NULL at top level or in arrays */
void pd_json_end_object(pd_json *js);
void pd_json_begin_array(pd_json *js, const char *key);
void pd_json_end_array(pd_json *js);
void pd_json_num(pd_json *js, const char *key, double x); /* non-finite -> null */
void pd_json_int(pd_json *js, const char *key, long x);
void pd_json_str(pd_json *js, const char *key, const char *s);
void pd_json_bool(pd_json *js, const char *key, int b);
void pd_json_null(pd_json *js, const char *key);
void pd_json_nums(pd_json *js, const char *key, int n, const double *x);
/* A suite's statistics as one object {n, mean, median, p16, p84, min, max}. */
void pd_json_stats(pd_json *js, const char *key, const pd_stats *st);
void pd_json_finish(pd_json *js); /* newline after the top-level value */

/* The decisions a scene's reference run rests on (docs/methods.md, "The
 * closing tolerance"): JSON keys simultaneous_ref, tol_closed_ref,
 * accumulations_ref, close_tol; or one line of text. */
void pd_cli_ref_decisions_json(pd_json *js, const pd_scene_result *ref);
void pd_cli_ref_decisions_text(FILE *f, const pd_scene_result *ref);

#endif
