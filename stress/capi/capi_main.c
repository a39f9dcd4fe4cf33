/* capi_main.c -- the C API misuse category of `make stress`: the generated
 * NULL test (tests/test_api_null.c) and result-shape misuse, linked against
 * the library built under AddressSanitizer and UBSan (scripts/stress.sh).
 * Prints one line per failed check and "capi: N checks, N failed". */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "pd_test.h"

/* The harness's three entry points, as tests/main.c gives them. */
void pd_test_run(pd_test_ctx *ctx, const char *name, void (*fn)(pd_test_ctx *))
{
    ctx->case_name = name;
    ctx->case_failures = 0;
    fn(ctx);
    if (ctx->case_failures)
        ctx->failed++;
    else
        ctx->passed++;
}

int pd_test_check(pd_test_ctx *ctx, int ok, const char *file, int line, const char *fmt, ...)
{
    if (ok)
        return 1;
    va_list ap;
    va_start(ap, fmt);
    printf("FAIL %s (%s:%d): ", ctx->case_name, file, line);
    vprintf(fmt, ap);
    printf("\n");
    va_end(ap);
    ctx->case_failures++;
    return 0;
}

void pd_test_skip(pd_test_ctx *ctx, const char *why)
{
    printf("skip %s: %s\n", ctx->case_name, why);
    ctx->skipped++;
}

/* Results used against scenes of another shape, or before the scene is
 * finished, or zeroed: each refused with PD_EINVAL, never written out of
 * bounds (issue 19, defect 6). */
static void capi_result_shape(pd_test_ctx *ctx)
{
    pd_scene *two = NULL, *three = NULL, *fresh = pd_scene_new(NULL);
    pd_scene_result r2 = {0}, zero = {0}, early = {0};
    int rc = pd_scene_load("examples/scenes/two-sdof.json", &two, NULL) ||
             pd_scene_load("examples/scenes/three-buildings.json", &three, NULL) ||
             pd_scene_result_alloc(two, &r2, NULL);
    CHECK(ctx, rc == 0 && fresh, "fixtures: scenes and a result (%d)", rc);
    if (rc == 0 && fresh) {
        pd_run_opts o = pd_run_default_opts();
        o.tend = 0.05;
        CHECK(ctx, pd_scene_run(three, &o, NULL, NULL, &r2, NULL) == PD_EINVAL,
              "a result of two-sdof run on three-buildings is refused");
        CHECK(ctx, pd_scene_run(two, &o, NULL, NULL, &zero, NULL) == PD_EINVAL,
              "a zeroed result is refused");
        pd_scene_add_sdof(fresh, "A", 0.5, 0.05, 1.0, NULL);
        CHECK(ctx, pd_scene_result_alloc(fresh, &early, NULL) == PD_EINVAL,
              "a result for an unfinished scene is refused");
        CHECK(ctx, pd_scene_run(two, &o, NULL, NULL, &r2, NULL) == PD_OK, "the right shape runs");
    }
    pd_scene_result_free(&r2);
    pd_scene_result_free(&early);
    pd_scene_free(two);
    pd_scene_free(three);
    pd_scene_free(fresh);
}

void suite_api_null(pd_test_ctx *ctx);
#include "api_fixtures.h"

int main(void)
{
    pd_test_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    suite_api_null(&ctx);
    PD_RUN(&ctx, capi_result_shape);
    printf("capi: %d NULL calls over %d functions, 4 result-shape checks\n", api_null_ncases,
           api_null_nfunctions);
    printf("capi: %d cases passed, %d failed\n", ctx.passed, ctx.failed);
    return ctx.failed ? 1 : 0;
}
