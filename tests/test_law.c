/* test_law.c — the impact law of the row reference (staged, single) and the
 * law_band a scene run reports when its result rests on simultaneous
 * impacts. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pd_test.h"

/* The velocities at the last output. */
static int law_keep_velocities(const pd_state *s, void *vctx)
{
    memcpy(vctx, s->v, 3 * sizeof(double));
    return 0;
}

/* Three free unit masses, v0 = (1, 0, 1/2), gaps 0.1 and 0, closing
 * tolerance 0.06: at t = 0.1 the first closes (U1 = -1) while the second
 * contact, 0.05 open, separates (U2 = +1/2) within the tolerance.
 *   staged: c1 alone, then c2 (closed by c1's impulse) alone:
 *     v = ((1-e)/2, (1+e)/2 - e(1+e)/4, 1/2 + e(1+e)/4);
 *   single: one LCP, q = (-(1+e), 1/2), D = [2 -1; -1 2]:
 *     P1 = (3 + 4e)/6, P2 = e/3, v = (1 - P1, P1 - P2, 1/2 + P2)
 * (e = 1: (0, 1/2, 1) and (-1/6, 5/6, 5/6); e = 1/2: (1/4, 9/16, 11/16) and
 * (1/6, 2/3, 2/3)). */
static void test_law_closed_forms(pd_test_ctx *ctx)
{
    const double es[2] = {1.0, 0.5};
    for (int ke = 0; ke < 2; ke++)
        for (int law = 0; law < 2; law++) {
            double e = es[ke], g0[2] = {0.1, 0.0}, ev[2] = {e, e}, b[3] = {0, 0, 0};
            double v0[3] = {1.0, 0.0, 0.5}, I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
            double wv[4] = {-1, 1, -1, 1};
            int cp[3] = {0, 2, 4}, ri[4] = {0, 1, 1, 2};
            pd_model md = {.n = 3,
                           .m = 2,
                           .M = pd_matrix_dense(3, 3, I3),
                           .C = pd_matrix_zero(3, 3),
                           .K = pd_matrix_zero(3, 3),
                           .W = pd_matrix_csc(3, 2, cp, ri, wv),
                           .g0 = g0,
                           .e = ev};
            pd_sine_piece pc = {.t_start = 0.0};
            pd_piecewise_force F = {.b = b, .pieces = &pc, .npieces = 1};
            pd_edr_opts eo = pd_edr_default_opts();
            eo.h_out = 1.0;
            eo.close_tol = 0.06;
            eo.impact_law = law ? PD_IMPACT_SINGLE : PD_IMPACT_STAGED;
            pd_err err;
            pd_edr *r = pd_edr_alloc(&md, &F, &eo, &err);
            if (!CHECK(ctx, r != NULL, "%s", err.msg))
                continue;
            double v[3] = {NAN, NAN, NAN}, want[3];
            CHECK(ctx, pd_edr_run(r, 0.0, NULL, v0, 1.0, law_keep_velocities, v, &err) == PD_OK,
                  "%s", err.msg);
            if (law == 0) {
                want[0] = (1.0 - e) / 2.0;
                want[1] = (1.0 + e) / 2.0 - e * (1.0 + e) / 4.0;
                want[2] = 0.5 + e * (1.0 + e) / 4.0;
            } else {
                double P1 = (3.0 + 4.0 * e) / 6.0, P2 = e / 3.0;
                want[0] = 1.0 - P1;
                want[1] = P1 - P2;
                want[2] = 0.5 + P2;
            }
            for (int i = 0; i < 3; i++)
                CHECK(ctx, fabs(v[i] - want[i]) <= 1e-12, "%s, e = %g: v%d = %.17g, want %.17g",
                      law ? "single" : "staged", e, i + 1, v[i], want[i]);
            const pd_edr_result *res = pd_edr_result_of(r);
            CHECK(ctx, res->law_decided == 1 && res->tol_closed == 1,
                  "%s, e = %g: law_decided %ld, tol_closed %ld", law ? "single" : "staged", e,
                  res->law_decided, res->tol_closed);
            pd_edr_free(r);
        }
    pd_edr_opts bad = pd_edr_default_opts();
    bad.impact_law = (pd_impact_law)7;
    double g0 = 1.0, e1 = 0.5, m1 = 1.0, b1 = 0.0, w1 = 1.0;
    int cp1[2] = {0, 1}, ri1[1] = {0};
    pd_model md1 = {.n = 1,
                    .m = 1,
                    .M = pd_matrix_dense(1, 1, &m1),
                    .C = pd_matrix_zero(1, 1),
                    .K = pd_matrix_zero(1, 1),
                    .W = pd_matrix_csc(1, 1, cp1, ri1, &w1),
                    .g0 = &g0,
                    .e = &e1};
    pd_sine_piece pc1 = {.t_start = 0.0};
    pd_piecewise_force F1 = {.b = &b1, .pieces = &pc1, .npieces = 1};
    pd_err err;
    pd_edr *r = pd_edr_alloc(&md1, &F1, &bad, &err);
    CHECK(ctx, r == NULL && err.status == PD_EINVAL && strstr(err.msg, "impact_law"),
          "impact_law 7 refused: %s", r ? "allocated" : err.msg);
    pd_edr_free(r);
    pd_impact_law law;
    CHECK(ctx,
          pd_impact_law_parse("single", &law) == PD_OK && law == PD_IMPACT_SINGLE &&
              pd_impact_law_parse("staged", &law) == PD_OK && law == PD_IMPACT_STAGED &&
              pd_impact_law_parse("newton", &law) == PD_EINVAL &&
              !strcmp(pd_impact_law_name(PD_IMPACT_SINGLE), "single"),
          "impact law names");
}

/* A row of four SDOFs against a wall (the review's restitutions 0.027,
 * 0.003, 0.987, 0.455), pulse, periods, masses and gaps given. */
static pd_scene *law_row(pd_test_ctx *ctx, pd_pulse pulse, const double *T0, const double *mass,
                         const double *gap)
{
    static const double eps[4] = {0.027, 0.003, 0.987, 0.455};
    pd_scene_excitation exc = {.pulse = pulse, .dir = -1, .ap = 4.0, .Tp = 0.5};
    pd_scene *sc = pd_scene_new(&exc);
    pd_err e;
    if (!CHECK(ctx, sc != NULL, "out of memory"))
        return NULL;
    int ok = 1;
    for (int s = 0; s < 4 && ok; s++) {
        char name[16];
        snprintf(name, sizeof name, "S%d", s + 1);
        ok = !pd_scene_add_sdof(sc, name, T0[s], 0.05, mass[s], &e);
    }
    for (int a = 0; a < 4 && ok; a++)
        ok = !pd_scene_add_contact(sc, a ? a - 1 : PD_WALL, a ? 1 : 0, a, 1, gap[a], eps[a], a, &e);
    if (!CHECK(ctx, ok && !pd_scene_finish(sc, &e), "scene: %s", e.msg)) {
        pd_scene_free(sc);
        return NULL;
    }
    return sc;
}

/* Run sc with method m (impact law law) into r; PD_OK or the status. */
static int law_run(pd_test_ctx *ctx, const pd_scene *sc, pd_method m, pd_impact_law law,
                   pd_scene_result *r)
{
    pd_run_opts o = pd_run_default_opts();
    pd_err e;
    o.method = m;
    o.impact_law = law;
    o.tend = 3.0;
    o.no_demands = 1;
    int rc = pd_scene_run(sc, &o, NULL, NULL, r, &e);
    CHECK(ctx, rc == PD_OK, "%s (%s): %s", pd_method_name(m), pd_impact_law_name(law), e.msg);
    return rc;
}

/* law_band: a row whose impacts the law decides (S1 on the wall, S2-S3
 * touching: staged and single differ by 1.3e-3) reports how far each
 * structure's peak moves under the other law, measured from both sides;
 * a row whose simultaneous impacts the laws resolve alike reports 0, the
 * single law there equal to event-general's to 1e-9; a row without
 * simultaneous impacts, and the other methods, NaN. */
static void test_law_band(pd_test_ctx *ctx)
{
    const double T_a[4] = {0.741, 0.528, 0.211, 1.342}, m_a[4] = {1e5, 3e5, 3e5, 3e5};
    const double g_a[4] = {0.0, 0.02, 0.0, 0.02};
    const double T_b[4] = {0.524, 0.342, 1.012, 0.648}, m_b[4] = {3e5, 2e5, 3e5, 3e5};
    const double g_b[4] = {0.0, 0.0, 0.0, 0.005};
    const double T_c[4] = {0.375, 1.302, 1.193, 0.532}, m_c[4] = {1e5, 2e5, 1e5, 2e5};
    const double g_c[4] = {0.01, 0.01, 0.01, 0.01};
    pd_scene_result st, si, eg;
    pd_err e;
    pd_scene *sc = law_row(ctx, PD_PULSE_COSINE, T_a, m_a, g_a);
    if (!sc)
        return;
    if (!CHECK(ctx,
               !pd_scene_result_alloc(sc, &st, &e) && !pd_scene_result_alloc(sc, &si, &e) &&
                   !pd_scene_result_alloc(sc, &eg, &e),
               "%s", e.msg)) {
        pd_scene_free(sc);
        return;
    }
    if (!law_run(ctx, sc, PD_METHOD_EVENT, PD_IMPACT_STAGED, &st) &&
        !law_run(ctx, sc, PD_METHOD_EVENT, PD_IMPACT_SINGLE, &si)) {
        CHECK(ctx,
              st.law_decided > 0 && !strcmp(st.impact_law, "staged") &&
                  !strcmp(si.impact_law, "single"),
              "law_decided %ld, laws %s, %s", st.law_decided, st.impact_law, si.impact_law);
        double worst = 0.0;
        for (int s = 0; s < 4; s++) {
            double want = fabs(si.umax[s] - st.umax[s]) / st.umax[s];
            CHECK(ctx,
                  fabs(st.law_band[s] - want) <= 1e-15 &&
                      fabs(si.law_band[s] - want * st.umax[s] / si.umax[s]) <= 1e-15,
                  "S%d: law_band %.6g (single's %.6g), want %.6g", s + 1, st.law_band[s],
                  si.law_band[s], want);
            worst = fmax(worst, st.law_band[s]);
        }
        CHECK(ctx, worst > 1e-3 && st.law_band_max == worst,
              "the laws differ on this row: law_band_max %.3g (largest %.3g)", st.law_band_max,
              worst);
    }
    pd_scene_result_free(&st);
    pd_scene_result_free(&si);
    pd_scene_result_free(&eg);
    pd_scene_free(sc);

    sc = law_row(ctx, PD_PULSE_SINE, T_b, m_b, g_b);
    if (!sc)
        return;
    if (!CHECK(ctx, !pd_scene_result_alloc(sc, &si, &e) && !pd_scene_result_alloc(sc, &eg, &e),
               "%s", e.msg)) {
        pd_scene_free(sc);
        return;
    }
    if (!law_run(ctx, sc, PD_METHOD_EVENT, PD_IMPACT_SINGLE, &si) &&
        !law_run(ctx, sc, PD_METHOD_EVENT_GENERAL, PD_IMPACT_STAGED, &eg)) {
        CHECK(ctx, si.simultaneous > 0 && si.law_band_max == 0.0, "simultaneous %ld, law_band %.3g",
              si.simultaneous, si.law_band_max);
        for (int s = 0; s < 4; s++)
            CHECK(ctx, fabs(si.umax[s] - eg.umax[s]) <= 1e-9 * eg.umax[s],
                  "S%d: single %.12g, event-general %.12g", s + 1, si.umax[s], eg.umax[s]);
        CHECK(ctx, isnan(eg.law_band_max) && isnan(eg.law_band[0]) && !eg.impact_law,
              "event-general: law_band %g", eg.law_band_max);
    }
    pd_scene_result_free(&si);
    pd_scene_result_free(&eg);
    pd_scene_free(sc);

    sc = law_row(ctx, PD_PULSE_SINE, T_c, m_c, g_c);
    if (!sc)
        return;
    if (!CHECK(ctx, !pd_scene_result_alloc(sc, &st, &e), "%s", e.msg)) {
        pd_scene_free(sc);
        return;
    }
    if (!law_run(ctx, sc, PD_METHOD_EVENT, PD_IMPACT_STAGED, &st))
        CHECK(ctx, st.law_decided == 0 && isnan(st.law_band_max) && isnan(st.law_band[0]),
              "no simultaneous impact: law_decided %ld, law_band %g", st.law_decided,
              st.law_band_max);
    pd_scene_result_free(&st);
    pd_scene_free(sc);
}

void suite_law(pd_test_ctx *ctx)
{
    pd_test_run(ctx, "law_closed_forms", test_law_closed_forms);
    pd_test_run(ctx, "law_band", test_law_band);
}
