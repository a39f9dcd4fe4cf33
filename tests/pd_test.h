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

#define PD_RUN(ctx, fn) pd_test_run((ctx), #fn, fn)
/* CHECK(ctx, cond, "fmt", ...) — the message says what was measured. */
#define CHECK(ctx, cond, ...) pd_test_check((ctx), (cond) ? 1 : 0, __FILE__, __LINE__, __VA_ARGS__)
/* |a - b| <= tol, printing both values on failure. */
#define CHECK_NEAR(ctx, a, b, tol)                                                          \
    do {                                                                                    \
        double pd_a_ = (a), pd_b_ = (b), pd_t_ = (tol);                                     \
        pd_test_check((ctx), fabs(pd_a_ - pd_b_) <= pd_t_, __FILE__, __LINE__,              \
                      "%s = %.17g vs %s = %.17g (|diff| %.3g > tol %.3g)", #a, pd_a_, #b, pd_b_, \
                      fabs(pd_a_ - pd_b_), pd_t_);                                          \
    } while (0)

/* Suites, one per test file. */
void suite_lcp(pd_test_ctx *ctx);
void suite_engine(pd_test_ctx *ctx);
void suite_oscillator(pd_test_ctx *ctx);
void suite_penalty(pd_test_ctx *ctx);
void suite_reference(pd_test_ctx *ctx);
void suite_event(pd_test_ctx *ctx);
void suite_paper(pd_test_ctx *ctx);
void suite_alloc(pd_test_ctx *ctx);
void suite_cli(pd_test_ctx *ctx);
void suite_spectrum(pd_test_ctx *ctx);

#endif
