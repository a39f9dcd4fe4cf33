/* api_fixtures.c -- live objects for the generated C API test, and its
 * runner: each case in its own child process (a crash, a sanitizer report
 * or a wrong status fails the case and names the function and argument). */
#include "api_fixtures.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include "pd_test.h"

#define FX_BYTES (1 << 20) /* zeroed arrays: longer than any size the cases pass */

static const char FX_SCENE[] = "examples/scenes/two-sdof.json";
static const char FX_RECORD[] = "stress/corpus/record/synth.V2";
static const char FX_LCP[] = "stress/corpus/lcp/tiny3.dat";

/* Memory or nothing: a child that cannot build its fixtures exits 99. */
static void *fx_zeros(size_t bytes)
{
    void *p = aligned_alloc(64, (bytes + 63) / 64 * 64);
    if (!p)
        _exit(99);
    return memset(p, 0, bytes);
}

void *fx_slot(void)
{
    return fx_zeros(sizeof(void *) * 8);
}

const char *fx_string(const char *fn, const char *name)
{
    if (strstr(name, "path")) {
        if (strstr(fn, "record"))
            return FX_RECORD;
        if (strstr(fn, "lcp"))
            return FX_LCP;
        return FX_SCENE;
    }
    if (!strcmp(name, "fmt"))
        return "a message";
    if (strstr(name, "name") && strstr(fn, "parse"))
        return "auto";
    return "A";
}

/* One degree of freedom (m = k = 1, no damping) 1 from a wall, e = 0.5. */
static const double fx_one = 1.0, fx_half = 0.5;
static pd_model *fx_model(void)
{
    pd_model *m = fx_zeros(sizeof *m);
    *m = (pd_model){.n = 1,
                    .m = 1,
                    .M = pd_matrix_dense(1, 1, &fx_one),
                    .C = pd_matrix_zero(1, 1),
                    .K = pd_matrix_dense(1, 1, &fx_one),
                    .W = pd_matrix_dense(1, 1, &fx_one),
                    .g0 = &fx_one,
                    .e = &fx_half};
    return m;
}

static pd_scene *fx_scene(void)
{
    pd_scene *sc = NULL;
    if (pd_scene_load(FX_SCENE, &sc, NULL) != PD_OK)
        _exit(99);
    return sc;
}

/* The named type's live object (see the header). */
void *fx_object(const char *type, const char *fn, int k)
{
    (void)fn, (void)k;
    if (!strcmp(type, "pd_scene"))
        return fx_scene();
    if (!strcmp(type, "pd_model"))
        return fx_model();
        /* value types with a default: a heap copy of it */
#define FX_DEFAULT(T, value)                                                                       \
    if (!strcmp(type, #T)) {                                                                       \
        T *x = fx_zeros(sizeof *x);                                                                \
        *x = value;                                                                                \
        return x;                                                                                  \
    }
    FX_DEFAULT(pd_osc, pd_osc_default())
    FX_DEFAULT(pd_run_opts, pd_run_default_opts())
    FX_DEFAULT(pd_lcp_opts, pd_lcp_default_opts())
    FX_DEFAULT(pd_mj_opts, pd_mj_default_opts())
    FX_DEFAULT(pd_edr_opts, pd_edr_default_opts())
    FX_DEFAULT(pd_edg_opts, pd_edg_default_opts())
    FX_DEFAULT(pd_penalty_opts, pd_penalty_default_opts())
    FX_DEFAULT(pd_ed_opts, pd_ed_default_opts())
#undef FX_DEFAULT
    if (!strcmp(type, "pd_lcp_work")) {
        pd_lcp_work *w = pd_lcp_alloc(8);
        if (!w)
            _exit(99);
        return w;
    }
    if (!strcmp(type, "pd_lcp_solver")) {
        pd_lcp_solver *s = pd_lcp_solver_alloc(PD_LCP_AUTO, 8, 64, NULL);
        if (!s)
            _exit(99);
        return s;
    }
    if (!strcmp(type, "pd_mj")) {
        pd_mj_opts o = pd_mj_default_opts();
        o.h = 0.01;
        pd_mj *mj = pd_mj_alloc(fx_model(), &o, NULL);
        if (!mj)
            _exit(99);
        return mj;
    }
    if (!strcmp(type, "pd_edr")) {
        static const double b = 0.0; /* F(t) = b f(t): no force */
        static const pd_sine_piece piece = {.t_start = 0.0};
        static const pd_piecewise_force force = {.b = &b, .pieces = &piece, .npieces = 1};
        pd_edr *r = pd_edr_alloc(fx_model(), &force, NULL, NULL);
        if (!r)
            _exit(99);
        return r;
    }
    if (!strcmp(type, "pd_mjb")) {
        pd_mjb *b = fx_zeros(sizeof *b);
        if (pd_mjb_init(b, NULL, NULL, NULL, NULL) != PD_OK)
            _exit(99);
        return b;
    }
    if (!strcmp(type, "pd_record")) {
        pd_record *r = fx_zeros(sizeof *r);
        if (pd_record_read(FX_RECORD, PD_RECORD_AUTO, PD_UNITS_G, r, NULL) != PD_OK)
            _exit(99);
        return r;
    }
    if (!strcmp(type, "pd_spectrum")) {
        pd_spectrum *s = fx_zeros(sizeof *s);
        pd_spec_init(s);
        return s;
    }
    if (!strcmp(type, "pd_scene_result")) {
        pd_scene_result *r = fx_zeros(sizeof *r);
        if (pd_scene_result_alloc(fx_scene(), r, NULL) != PD_OK)
            _exit(99);
        return r;
    }
    if (!strcmp(type, "pd_text")) {
        pd_text *t = fx_zeros(sizeof *t);
        if (pd_text_open(t, FX_SCENE, 1 << 20, PD_TEXT_AT_LINE_COL, NULL) != PD_OK)
            _exit(99);
        return t;
    }
    if (!strcmp(type, "pd_matrix")) {
        pd_matrix *A = fx_zeros(sizeof *A);
        *A = pd_matrix_dense(1, 1, &fx_one);
        return A;
    }
    return fx_zeros(FX_BYTES);
}

/* Run case c in a child: 0 when it met its expectation, else a reason. */
static const char *api_null_run(const api_null_case *c, int *code)
{
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0)
        return "fork failed";
    if (pid == 0) {
        long v = c->call();
        int ok = 1;
        switch (c->expect) {
        case EXPECT_ERROR:
            ok = v < 0;
            break;
        case EXPECT_COUNT:
            ok = v <= 0;
            break;
        case EXPECT_NULL:
            ok = v == 0;
            break;
        case EXPECT_NAME:
        case EXPECT_NOCRASH:
            break;
        }
        _exit(ok ? 0 : 1); /* _exit: no leak report for the fixtures */
    }
    int st = 0;
    if (waitpid(pid, &st, 0) < 0)
        return "waitpid failed";
    if (WIFSIGNALED(st)) {
        *code = WTERMSIG(st);
        return "killed by signal";
    }
    *code = WEXITSTATUS(st);
    if (*code == 0)
        return NULL;
    if (*code == 1)
        return c->expect == EXPECT_NULL ? "returned a pointer" : "returned success";
    if (*code == 99)
        return "fixtures not built";
    return "exited (a sanitizer report?)";
}

static void test_api_null(pd_test_ctx *ctx)
{
    for (int i = 0; i < api_null_ncases; i++) {
        const api_null_case *c = &api_null_cases[i];
        int code = 0;
        const char *why = api_null_run(c, &code);
        CHECK(ctx, why == NULL, "%s(%s = NULL): %s (%d)", c->function, c->argument, why ? why : "",
              code);
    }
    CHECK(ctx, api_null_ncases > 200 && api_null_nfunctions > 150, "%d cases over %d functions",
          api_null_ncases, api_null_nfunctions);
}

void suite_api_null(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_api_null);
}
