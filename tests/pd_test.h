/* pd_test.h — a minimal test harness: named cases made of numeric checks.
 *
 * A case passes when every check inside it holds.  The runner ends with the
 * line "N passed, N failed, N skipped". */
#ifndef PD_TEST_H
#define PD_TEST_H

#include <math.h>
#include <stdio.h>

typedef struct pd_test_ctx {
    int passed, failed, skipped;
    int case_failures; /* failed checks in the running case */
    int case_skipped;
    const char *case_name;
    const char *pound;  /* path to the pound binary (CLI tests) */
    const char *shared; /* path to ../shared, or NULL when absent */
    const char *filter; /* run only cases whose name contains this */
} pd_test_ctx;

void pd_test_run(pd_test_ctx *ctx, const char *name, void (*fn)(pd_test_ctx *));
int pd_test_check(pd_test_ctx *ctx, int ok, const char *file, int line, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
void pd_test_skip(pd_test_ctx *ctx, const char *why);

/* Calls to malloc, calloc and realloc from the library and the tests
 * since the start (the test binary wraps them, test_alloc.c). */
long pd_test_allocations(void);

/* A uniform number in [0, 1) from a seeded stream (splitmix64): reproducible
 * random data for the tests. */
#include <stdint.h>
double pd_test_uniform(uint64_t *state);

#define PD_RUN(ctx, fn) pd_test_run((ctx), #fn, fn)
/* CHECK(ctx, cond, "fmt", ...) — the message says what was measured. */
#define CHECK(ctx, cond, ...) pd_test_check((ctx), (cond) ? 1 : 0, __FILE__, __LINE__, __VA_ARGS__)
/* |a - b| <= tol, printing both values on failure. */
#define CHECK_NEAR(ctx, a, b, tol)                                                                 \
    do {                                                                                           \
        double pd_a_ = (a), pd_b_ = (b), pd_t_ = (tol);                                            \
        pd_test_check((ctx), fabs(pd_a_ - pd_b_) <= pd_t_, __FILE__, __LINE__,                     \
                      "%s = %.17g vs %s = %.17g (|diff| %.3g > tol %.3g)", #a, pd_a_, #b, pd_b_,   \
                      fabs(pd_a_ - pd_b_), pd_t_);                                                 \
    } while (0)

/* ---- helpers for the CLI suites (test_util.c) ---------------------------- */

#include <hdf5.h>

/* What one run printed and returned (out and err malloc'd). */
typedef struct proc_out {
    int status;
    char *out, *err;
} proc_out;

char *pd_test_slurp(const char *path); /* whole file, malloc'd */
void pd_test_proc_free(proc_out *r);
/* Run argv with env ("NAME=value" or NULL) added; capture stdout, stderr. */
int pd_test_spawn(const char *const *argv, const char *env, proc_out *r);

/* The Rinaldi case of the records' tests: the record shipped with the
 * examples (examples/records/README.md), its fitted pulse, T0 0.8 s, gap
 * 1 cm, eps 0.6.  1 when loaded (*rec to free); 0 when the record is
 * absent (the case skipped) or unreadable (the case failed). */
#include "pd_problems.h"
int pd_test_rinaldi_case(pd_test_ctx *ctx, pd_record *rec, pd_osc *c);
/* The Rinaldi record's forcing pieces F = -a_g, linear between samples
 * (its npts pieces, to free); NULL when the record is absent (skipped) or
 * unreadable (failed). */
pd_sine_piece *pd_test_rinaldi_pieces(pd_test_ctx *ctx, long *npieces);
/* The one-wall yielding pulse cases (test_yield_rk.c, test_yield_edr.c),
 * Pi units: one sine or cosine cycle of unit amplitude and frequency (pc,
 * two pieces), w0 = 1/Pi2 (0.7, 1.5), xi 0.05, a wall 0.1 away with eps 0,
 * 0.5, 1 or none, alpha 0, 0.1, 0.3, uy 0.05, 0.3: case c of 96 into *p
 * (pointing at pc) and name; 0 past the last. */
int pd_test_yield_pulse_case(int c, pd_sine_piece pc[2], pd_ed_sdof *p, char *name, size_t cap);
/* A row of n yielding SDOFs between two walls (T0 0.4 to 1.3 s, uy 1 to 2
 * cm, alpha 0 to 0.2, cycling by ten; gaps 3 cm + dgap (k % 7) for contact
 * k, e 0.6) under a sine pulse of 4 m/s^2 and 0.8 s, 3 s; NULL (named) on
 * failure. */
pd_scene *pd_test_yield_row(pd_test_ctx *ctx, int n, double dgap);
/* Run sc by method (dt 0: the default) into r (allocated here); 1 when it
 * ran, else 0 with the failure named. */
/* The scene of a JSON text written to path and loaded (NULL: named). */
pd_scene *pd_test_scene_of_text(pd_test_ctx *ctx, const char *path, const char *text);
int pd_test_scene_run(pd_test_ctx *ctx, const pd_scene *sc, pd_method method, double dt,
                      pd_scene_result *r);
/* Run ctx->pound with args (NULL-terminated). */
int pd_test_pound(const pd_test_ctx *ctx, const char *const *args, proc_out *r);
int pd_test_have_pound(pd_test_ctx *ctx);                          /* else skips the case */
double pd_test_json_num(const char *json, const char *key, int k); /* k-th "key": */
void pd_test_json_str(const char *json, const char *key, int k, char *buf, size_t cap);
int pd_test_dir_entries(const char *dir); /* besides . and .. */
void pd_test_rm_dir(const char *dir);
/* A sparse regular file of `bytes` zero bytes (no disk used) at a fresh
 * /tmp name written into path: 0, or -1 (nothing left). */
int pd_test_zero_file(char *path, size_t cap, long long bytes);
int pd_test_same_file(const char *a, const char *b);
double pd_test_h5_num(hid_t obj, const char *name); /* NAN when missing */

/* Run options base (NULL: the defaults) for the penalty method with the
 * contact elements po, whose zero tolerances and NULL stepper take the
 * defaults (a convenience of the tests). */
#include "pd_problems.h"
pd_run_opts pd_test_pen(const pd_run_opts *base, const pd_penalty_setup *po);

/* Suites, one per test file. */
void suite_lcp(pd_test_ctx *ctx);
void suite_engine(pd_test_ctx *ctx);
void suite_adapt(pd_test_ctx *ctx);
void suite_oscillator(pd_test_ctx *ctx);
void suite_rows(pd_test_ctx *ctx);
void suite_penalty(pd_test_ctx *ctx);
void suite_reference(pd_test_ctx *ctx);
void suite_event(pd_test_ctx *ctx);
void suite_paper(pd_test_ctx *ctx);
void suite_alloc(pd_test_ctx *ctx);
void suite_cli(pd_test_ctx *ctx);
void suite_spectrum(pd_test_ctx *ctx);
void suite_scene(pd_test_ctx *ctx);
void suite_demand(pd_test_ctx *ctx);
void suite_solvers(pd_test_ctx *ctx);
void suite_impacts(pd_test_ctx *ctx);
void suite_record(pd_test_ctx *ctx);
void suite_ed_linear(pd_test_ctx *ctx);
void suite_records_run(pd_test_ctx *ctx);
void suite_plots(pd_test_ctx *ctx);
void suite_outputs(pd_test_ctx *ctx);
void suite_harden(pd_test_ctx *ctx);
void suite_aabs(pd_test_ctx *ctx);
void suite_law(pd_test_ctx *ctx);
void suite_scan(pd_test_ctx *ctx);
void suite_root(pd_test_ctx *ctx);
void suite_measure_paths(pd_test_ctx *ctx);
void suite_row_paths(pd_test_ctx *ctx);
void suite_row_paths2(pd_test_ctx *ctx);
void suite_yield(pd_test_ctx *ctx);
void suite_yield_rk(pd_test_ctx *ctx);
void suite_yield_edr(pd_test_ctx *ctx);
void suite_yield_edr_rk(pd_test_ctx *ctx);
void suite_separation(pd_test_ctx *ctx);
void suite_suite(pd_test_ctx *ctx);
void suite_yield_newmark(pd_test_ctx *ctx);
void suite_yield_mj(pd_test_ctx *ctx);
void suite_yield_scene(pd_test_ctx *ctx);
void suite_row_rerun(pd_test_ctx *ctx);
void suite_lemke_paths(pd_test_ctx *ctx);
void suite_api_null(pd_test_ctx *ctx);

#endif
