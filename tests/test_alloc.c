/* test_alloc.c — every allocation of the library's constructors fails in
 * turn (CSparse style): each failure must come back as PD_ENOMEM / NULL,
 * never as a crash, and free what was taken (LeakSanitizer checks that in
 * `make asan`).
 *
 * The test binary is linked with -Wl,--wrap=malloc,--wrap=calloc,
 * --wrap=realloc: the library's calls come here first.  The countdown is
 * test-harness state, not library state. */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pd_problems.h"
#include "pd_test.h"

void *__real_malloc(size_t n);
void *__real_calloc(size_t k, size_t n);
void *__real_realloc(void *p, size_t n);

static long alloc_countdown = -1; /* < 0: never fail; 0: fail this one */
static long alloc_seen = 0;
static long alloc_total = 0; /* every allocation call since the start */

long pd_test_allocations(void)
{
    return alloc_total;
}

/* Decide whether this allocation fails. */
static int alloc_should_fail(void)
{
    alloc_seen++;
    alloc_total++;
    if (alloc_countdown < 0)
        return 0;
    return alloc_countdown-- == 0;
}

void *__wrap_malloc(size_t n)
{
    return alloc_should_fail() ? NULL : __real_malloc(n);
}

void *__wrap_calloc(size_t k, size_t n)
{
    return alloc_should_fail() ? NULL : __real_calloc(k, n);
}

void *__wrap_realloc(void *p, size_t n)
{
    return alloc_should_fail() ? NULL : __real_realloc(p, n);
}

/* A constructor under test: returns a status. */
typedef int (*alloc_case)(void);

/* Fail allocation k = 0, 1, 2, ... until the call succeeds; every failed
 * call must report PD_ENOMEM.  Returns the number of allocations tried. */
static long fail_each(pd_test_ctx *ctx, const char *name, alloc_case fn)
{
    long k = 0;
    for (; k < 10000; k++) {
        alloc_countdown = k;
        alloc_seen = 0;
        int st = fn();
        long seen = alloc_seen;
        alloc_countdown = -1;
        if (seen <= k) { /* fewer allocations than k: it ran clean */
            CHECK(ctx, st == PD_OK, "%s: clean run returned %d", name, st);
            break;
        }
        CHECK(ctx, st == PD_ENOMEM, "%s: allocation %ld failed, status %d (want PD_ENOMEM)", name,
              k, st);
    }
    CHECK(ctx, k > 0, "%s: no allocation seen", name);
    return k;
}

static int case_lcp(void)
{
    pd_lcp_work *w = pd_lcp_alloc(50);
    if (!w)
        return PD_ENOMEM;
    double M[4] = {2, -1, -1, 2}, q[2] = {-1, 1}, z[2], wv[2];
    int st = pd_lcp_lemke(w, 2, M, q, NULL, z, wv, NULL);
    pd_lcp_free(w);
    return st;
}

static int case_moreau_general(void)
{
    double M[4] = {1, 0, 0, 2}, K[4] = {4, -1, -1, 3}, W[4] = {-1, 0, 1, -1};
    double g0[2] = {0.05, 0.02}, e[2] = {0.7, 0.3};
    pd_model md = {.n = 2,
                   .m = 2,
                   .M = pd_matrix_dense(2, 2, M),
                   .C = pd_matrix_zero(2, 2),
                   .K = pd_matrix_dense(2, 2, K),
                   .W = pd_matrix_dense(2, 2, W),
                   .g0 = g0,
                   .e = e};
    pd_mj_opts o = pd_mj_default_opts();
    pd_err err;
    double v0[2] = {1.0, -1.0};
    o.h = 1e-3;
    pd_mj *mj = pd_mj_alloc(&md, &o, &err);
    if (!mj)
        return err.status;
    int st = pd_mj_reset(mj, 0.0, NULL, v0, &err);
    if (!st)
        st = pd_mj_run(mj, 200, NULL, NULL, &err);
    pd_mj_free(mj);
    return st;
}

static int keep_sample(const pd_osc_sample *s, void *ctx)
{
    *(double *)ctx = s->u;
    return 0;
}

/* With a sampler: through pd_mj (without one the run allocates nothing:
 * test_alloc_every_failure_reported). */
static int case_oscillator(void)
{
    pd_osc c = {.pulse = PD_PULSE_SINE,
                .dir = 1,
                .ap = 1.0,
                .Tp = 1.0,
                .Pi2 = 0.5,
                .Pi3 = 0.05,
                .eps = 0.5,
                .xi = 0.05};
    pd_run_opts o = pd_run_default_opts();
    pd_osc_result r;
    pd_err err;
    double u = 0.0;
    o.dt = 0.01;
    return pd_osc_simulate(&c, &o, keep_sample, &u, &r, &err);
}

static int case_oscillator_plain(void)
{
    pd_osc c = {.pulse = PD_PULSE_SINE,
                .dir = 1,
                .ap = 1.0,
                .Tp = 1.0,
                .Pi2 = 0.5,
                .Pi3 = 0.05,
                .eps = 0.5,
                .xi = 0.05};
    pd_run_opts o = pd_run_default_opts();
    pd_osc_result r;
    pd_err err;
    o.dt = 0.01;
    return pd_osc_simulate(&c, &o, NULL, NULL, &r, &err);
}

static int case_penalty(void)
{
    pd_osc c = {.pulse = PD_PULSE_SINE,
                .dir = 1,
                .ap = 1.0,
                .Tp = 1.0,
                .Pi2 = 0.5,
                .Pi3 = 0.05,
                .eps = 0.5,
                .xi = 0.05};
    pd_run_opts o = pd_run_default_opts();
    pd_osc_result r;
    pd_err err;
    o.dt = 0.01;
    return pd_osc_penalty(&c, &o, NULL, NULL, &r, &err);
}

static int case_lcp_read(void)
{
    char path[] = "/tmp/pd_alloc_lcpXXXXXX";
    int fd = mkstemp(path);
    if (fd < 0)
        return PD_EIO;
    const char text[] = "2\n2 -1\n-1 2\n-1 1\n";
    int ok = write(fd, text, sizeof text - 1) == (ssize_t)(sizeof text - 1);
    close(fd);
    int n;
    double *M = NULL, *q = NULL;
    pd_err err;
    int st = ok ? pd_lcp_read(path, PD_LCP_FORMAT_PLAIN, &n, &M, &q, &err) : PD_EIO;
    free(M);
    free(q);
    unlink(path);
    return st;
}

/* The row reference on two shear buildings touching at two floors (modal
 * clusters: their bases are allocated during the run) and an SDOF against
 * a wall: the constructor and the run. */
static int case_rows(void)
{
    pd_scene_excitation exc = {.pulse = PD_PULSE_SINE, .dir = 1, .ap = 4.0, .Tp = 0.5};
    double m[2] = {2e5, 2e5}, k[2] = {3e8, 2e8};
    pd_scene *sc = pd_scene_new(&exc);
    pd_scene_model sm;
    pd_sine_piece *pc = NULL;
    int np = 0, built = 0, st;
    pd_err err;
    if (!sc)
        return PD_ENOMEM;
    st = pd_scene_add_building(sc, "A", 2, m, k, 0.05, &err);
    if (!st)
        st = pd_scene_add_building(sc, "B", 2, m, k, 0.05, &err);
    if (!st)
        st = pd_scene_add_sdof(sc, "C", 0.5, 0.05, 1e5, &err);
    if (!st)
        st = pd_scene_add_contact(sc, 0, 1, 1, 1, 0.002, 0.3, 0, &err);
    if (!st)
        st = pd_scene_add_contact(sc, 0, 2, 1, 2, 0.002, 0.3, 0, &err);
    if (!st)
        st = pd_scene_add_contact(sc, 2, 1, PD_WALL, 0, 0.001, 0.5, 1, &err);
    if (!st)
        st = pd_scene_finish(sc, &err);
    if (!st && !(st = pd_scene_model_build(sc, 1, &sm, &err)))
        built = 1;
    if (!st)
        st = pd_osc_pieces(&sm.shape, &pc, &np, &err);
    if (!st) {
        pd_piecewise_force F = {.b = sm.mass, .pieces = pc, .npieces = np};
        pd_edr *r = pd_edr_alloc(&sm.model, &F, NULL, &err);
        st = r ? pd_edr_run(r, 0.0, NULL, NULL, 2.0 * PD_TWO_PI, NULL, NULL, &err) : err.status;
        pd_edr_free(r);
    }
    free(pc);
    if (built)
        pd_scene_model_free(&sm);
    pd_scene_free(sc);
    return st;
}

/* A scene suite's statistics of two runs prepared beforehand (test state:
 * only pd_scene_suite_stats' own allocations fail in turn). */
static const pd_scene *stats_scene;
static const pd_scene_summary *stats_runs;

static int case_suite_stats(void)
{
    pd_scene_suite st;
    pd_err err;
    int rc = pd_scene_suite_stats(stats_scene, stats_runs, 2, &st, &err);
    pd_scene_suite_free(&st);
    return rc;
}

/* Two runs of a two-building scene for case_suite_stats: 0 or a status. */
static int suite_prepare(pd_scene **sc, pd_scene_summary runs[2])
{
    pd_scene_excitation exc = {.pulse = PD_PULSE_SINE, .dir = 1, .ap = 4.0, .Tp = 0.5};
    double m[2] = {2e5, 2e5}, k[2] = {3e8, 2e8};
    pd_err err;
    pd_run_opts o = pd_run_default_opts();
    o.method = PD_METHOD_EVENT;
    int st = (*sc = pd_scene_new(&exc)) ? PD_OK : PD_ENOMEM;
    if (!st)
        st = pd_scene_add_building(*sc, "A", 2, m, k, 0.05, &err);
    if (!st)
        st = pd_scene_add_sdof(*sc, "B", 0.5, 0.05, 1e5, &err);
    if (!st)
        st = pd_scene_add_contact(*sc, 0, 1, 1, 1, 0.002, 0.3, 0, &err);
    if (!st)
        st = pd_scene_finish(*sc, &err);
    for (int r = 0; r < 2 && !st; r++) {
        (*sc)->exc.ap = 2.0 + 4.0 * r;
        st = pd_scene_summarize(*sc, &o, NULL, NULL, &runs[r], &err);
    }
    return st;
}

static void test_alloc_every_failure_reported(pd_test_ctx *ctx)
{
    long n[7];
    pd_scene *sc = NULL;
    pd_scene_summary runs[2] = {{.cpu_s = 0}};
    alloc_countdown = -1;
    int st = suite_prepare(&sc, runs);
    CHECK(ctx, st == PD_OK, "a suite's two runs: %d", st);
    stats_scene = sc;
    stats_runs = runs;
    n[6] = st ? 0 : fail_each(ctx, "pd_scene_suite_stats", case_suite_stats);
    CHECK(ctx, n[6] >= 4, "the suite's statistics take several allocations (%ld)", n[6]);
    for (int r = 0; r < 2; r++)
        pd_scene_summary_free(&runs[r]);
    pd_scene_free(sc);
    n[0] = fail_each(ctx, "pd_lcp_alloc", case_lcp);
    n[1] = fail_each(ctx, "pd_mj_alloc (general)", case_moreau_general);
    n[2] = fail_each(ctx, "pd_osc_simulate", case_oscillator);
    n[3] = fail_each(ctx, "pd_osc_penalty", case_penalty);
    n[4] = fail_each(ctx, "pd_lcp_read", case_lcp_read);
    n[5] = fail_each(ctx, "pd_edr_alloc, pd_edr_run (modal clusters)", case_rows);
    CHECK(ctx, n[5] >= 50, "the row reference takes many allocations (%ld)", n[5]);
    CHECK(ctx, n[1] >= 10, "the general kernel takes many allocations (%ld)", n[1]);
    /* the single Moreau-Jean run without a sampler: no allocation at all */
    alloc_countdown = -1;
    alloc_seen = 0;
    st = case_oscillator_plain();
    CHECK(ctx, st == PD_OK && alloc_seen == 0,
          "pd_osc_simulate without a sampler: status %d, "
          "%ld allocations",
          st, alloc_seen);
}

void suite_alloc(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_alloc_every_failure_reported);
}
