/* pd_bench.h — (bench) the drivers of `pound bench`, one per module, and
 * the helpers they share.  Private to bench/: the command line
 * (cli/cmd_bench.c) parses the flags and calls the entry points, nothing
 * else.  bench/siconos_lcp.c is a program of its own (bench/build.sh) and
 * does not use this header. */
#ifndef PD_BENCH_H
#define PD_BENCH_H

#include <stddef.h>

#include "pd_cli.h"

/* ---- the entry points ---------------------------------------------------- *
 * With js NULL each prints a readable table on stdout; otherwise it adds one
 * member ("machine", "lcp", "engine", ...) to the JSON object that js has
 * open.  Each returns 0, or 1 when a benchmark run failed.  Every timed
 * figure is given as the wall clock (pd_wall_seconds) and as CPU time
 * (pd_cpu_seconds: the calling thread's; on several threads the sum of the
 * threads' times their tasks measured). */

/* The machine (bench_util.c): the processor model (/proc/cpuinfo's "model
 * name", else "unknown") and the instruction set the vector kernels run
 * with (pd_cpu_level: the processor's, capped by POUND_ISA); printed once,
 * before the drivers. */
int pd_bench_machine(pd_json *js);
int pd_bench_lcp(pd_json *js, const char *shared_dir);     /* bench_lcp.c */
int pd_bench_engine(pd_json *js);                          /* bench_engine.c */
int pd_bench_scene(pd_json *js);                           /* bench_scene.c */
int pd_bench_spectrum(pd_json *js);                        /* bench_spectrum.c */
int pd_bench_records(pd_json *js, const char *shared_dir); /* bench_records.c */
int pd_bench_startup(pd_json *js);                         /* bench_startup.c */
int pd_bench_adapt(pd_json *js);                           /* bench_adapt.c */

/* ---- shared by the drivers (bench_util.c) -------------------------------- */

/* A point in time, or a duration: the wall clock and the calling thread's
 * CPU time, in seconds. */
typedef struct pd_bench_clock {
    double wall_s, cpu_s;
} pd_bench_clock;

/* Now. */
pd_bench_clock pd_bench_now(void);
/* The time since t0 (from pd_bench_now). */
pd_bench_clock pd_bench_since(pd_bench_clock t0);

/* Ascending order of doubles, for qsort. */
int pd_bench_cmp_double(const void *a, const void *b);
/* The median of x[0..n) (sorts x); NAN when n is 0. */
double pd_bench_median(double *x, int n);

/* The processor's model name into buf ("unknown" when /proc/cpuinfo does
 * not give one); buf. */
const char *pd_bench_cpu_model(char *buf, size_t size);

/* The least-squares slope of log y against log x over the points added
 * (the growth exponents of the benchmarks); NAN with fewer than two. */
typedef struct pd_loglog_fit {
    double sx, sy, sxx, sxy;
    int k;
} pd_loglog_fit;
void pd_loglog_add(pd_loglog_fit *f, double x, double y);
double pd_loglog_slope(const pd_loglog_fit *f);

#endif
