/* pd_cli.h — the pound command line: subcommands, argument parsing helpers
 * and a small JSON writer.  Only this layer prints or exits. */
#ifndef PD_CLI_H
#define PD_CLI_H

#include <stdio.h>

/* Subcommands: each returns the process exit status (0 ok, 1 run failure,
 * 2 bad input). */
int pd_cmd_lcp(int argc, char **argv);
int pd_cmd_simulate(int argc, char **argv);
int pd_cmd_bench(int argc, char **argv);


/* Print "pound: <message>" on stderr and return 2 (bad input). */
int pd_cli_usage_error(const char *fmt, ...)
    __attribute__((format(printf, 1, 2)));

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
void pd_json_finish(pd_json *js); /* newline after the top-level value */

/* Benchmarks, one per module.  With js NULL they print a readable table on
 * stdout; otherwise they add one member ("lcp", "engine") to the JSON object
 * that js has open.  Return 0, or 1 when a benchmark run failed. */
int pd_bench_lcp(pd_json *js, const char *shared_dir);
int pd_bench_engine(pd_json *js);


/* Benchmarks, one per module.  With js NULL they print a readable table on
 * stdout; otherwise they add one member ("lcp", "engine") to the JSON object
 * that js has open.  Return 0, or 1 when a benchmark run failed. */
int pd_bench_lcp(pd_json *js, const char *shared_dir);
int pd_bench_engine(pd_json *js);

#endif
