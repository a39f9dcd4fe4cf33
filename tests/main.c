/* main.c — test runner: runs every suite, ends with "N passed, N failed". 
 *
 * usage: pound_tests [--pound PATH] [--shared DIR] [FILTER]
 *
 * Each case runs under a wall-clock limit, POUND_TEST_TIMEOUT seconds
 * (default TEST_TIMEOUT): a case still running then (a loop that never
 * ends, as a mutant's) fails the run with its name, exit status 1, instead
 * of hanging it.  POUND_TEST_FAILFAST set: the run stops at the first
 * failed case (make mutate). */
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pd_test.h"

#define TEST_TIMEOUT 300 /* s: the slowest case takes about 10 s, 40 s under ASan */

static const char *running_case; /* for the alarm's message */

/* SIGALRM: the running case is over its limit; async-signal-safe writes. */
static void over_time(int sig)
{
    static const char head[] = "FAIL  ", tail[] = ": over the per-case time limit "
                                                  "(POUND_TEST_TIMEOUT)\n";
    (void)sig;
    if (write(STDOUT_FILENO, head, sizeof head - 1) < 0 ||
        (running_case && write(STDOUT_FILENO, running_case, strlen(running_case)) < 0) ||
        write(STDOUT_FILENO, tail, sizeof tail - 1) < 0)
        _exit(1);
    _exit(1);
}

/* The limit in seconds: POUND_TEST_TIMEOUT (0: none), else TEST_TIMEOUT. */
static unsigned case_limit(void)
{
    const char *s = getenv("POUND_TEST_TIMEOUT");
    long v = s ? strtol(s, NULL, 10) : TEST_TIMEOUT;
    return v > 0 && v < 86400 ? (unsigned)v : 0;
}

void pd_test_run(pd_test_ctx *ctx, const char *name, void (*fn)(pd_test_ctx *))
{
    if (ctx->filter && !strstr(name, ctx->filter))
        return;
    ctx->case_failures = 0;
    ctx->case_skipped = 0;
    ctx->case_name = name;
    /* the handler again before each case: a case may install its own */
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = over_time;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGALRM, &sa, NULL);
    running_case = name;
    fflush(stdout);
    alarm(case_limit());
    fn(ctx);
    alarm(0);
    if (ctx->case_failures) {
        ctx->failed++;
        printf("FAIL  %s\n", name);
        if (getenv("POUND_TEST_FAILFAST")) { /* make mutate: the first failure kills */
            printf("%d passed, %d failed, %d skipped (stopped at the first failure)\n", ctx->passed,
                   ctx->failed, ctx->skipped);
            fflush(stdout);
            exit(1);
        }
    } else if (ctx->case_skipped) {
        ctx->skipped++;
    } else {
        ctx->passed++;
        printf("ok    %s\n", name);
    }
    fflush(stdout);
}

int pd_test_check(pd_test_ctx *ctx, int ok, const char *file, int line, const char *fmt, ...)
{
    if (!ok) {
        va_list ap;
        printf("  %s:%d: %s: ", file, line, ctx->case_name);
        va_start(ap, fmt);
        vprintf(fmt, ap);
        va_end(ap);
        printf("\n");
        ctx->case_failures++;
    }
    return ok;
}

void pd_test_skip(pd_test_ctx *ctx, const char *why)
{
    printf("skip  %s: skipped (%s)\n", ctx->case_name, why);
    ctx->case_skipped = 1;
}

static int is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

int main(int argc, char **argv)
{
    pd_test_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.pound = "build/pound";
    ctx.shared = getenv("POUND_SHARED") ? getenv("POUND_SHARED") : "../shared";
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--pound") && i + 1 < argc)
            ctx.pound = argv[++i];
        else if (!strcmp(argv[i], "--shared") && i + 1 < argc)
            ctx.shared = argv[++i];
        else
            ctx.filter = argv[i];
    }
    if (!is_dir(ctx.shared))
        ctx.shared = NULL;

    suite_lcp(&ctx);
    suite_engine(&ctx);
    suite_adapt(&ctx);
    suite_oscillator(&ctx);
    suite_penalty(&ctx);
    suite_reference(&ctx);
    suite_event(&ctx);
    suite_root(&ctx);
    suite_scan(&ctx);
    suite_rows(&ctx);
    suite_paper(&ctx);
    suite_alloc(&ctx);
    suite_cli(&ctx);
    suite_spectrum(&ctx);
    suite_scene(&ctx);
    suite_demand(&ctx);
    suite_solvers(&ctx);
    suite_impacts(&ctx);
    suite_record(&ctx);
    suite_ed_linear(&ctx);
    suite_records_run(&ctx);
    suite_plots(&ctx);
    suite_outputs(&ctx);
    suite_harden(&ctx);
    suite_aabs(&ctx);
    suite_law(&ctx);
    suite_lemke_paths(&ctx);
    suite_row_paths(&ctx);
    suite_row_paths2(&ctx);
    suite_yield(&ctx);
    suite_yield_rk(&ctx);
    suite_yield_edr(&ctx);
    suite_yield_edr_rk(&ctx);
    suite_separation(&ctx);
    suite_suite(&ctx);
    suite_yield_newmark(&ctx);
    suite_yield_mj(&ctx);
    suite_yield_scene(&ctx);
    suite_row_rerun(&ctx);
    suite_measure_paths(&ctx);
    suite_api_null(&ctx);

    printf("%d passed, %d failed, %d skipped\n", ctx.passed, ctx.failed, ctx.skipped);
    return ctx.failed ? 1 : 0;
}
