/* test_separation.c — how wide a gap must be (problems/separation.c):
 *   - the exact required separation of each contact: with every gap set to
 *     it (plus 1e-9 of it) a scene has no impact, with one 1 % short that
 *     contact strikes, on random pairs of SDOFs, of buildings (every common
 *     floor) and SDOFs against a wall, by the exact reference;
 *   - the DDC rule's correlation against its closed form for equal damping
 *     (written apart here), its symmetry, its range, and the rules from the
 *     twin's peaks (ABS, SRSS, DDC: wall contacts take the side's peak). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pd_core.h"
#include "pd_problems.h"
#include "pd_test.h"

/* Der Kiureghian's coefficient for equal damping xi (the form the DDC
 * papers print): 8 xi^2 (1 + r) r^(3/2) / ((1 - r^2)^2 + 4 xi^2 r (1 + r)^2). */
static double rho_equal(double r, double xi)
{
    return 8.0 * xi * xi * (1.0 + r) * pow(r, 1.5) /
           ((1.0 - r * r) * (1.0 - r * r) + 4.0 * xi * xi * r * (1.0 + r) * (1.0 + r));
}

/* The correlation: the equal-damping closed form (1e-14), symmetric in its
 * two oscillators (1e-15), 1 for one oscillator twice, in (0, 1], falling
 * as the periods part; NAN for nonsense. */
static void test_separation_ddc_correlation(pd_test_ctx *ctx)
{
    double worst = 0.0, sym = 0.0;
    int in_range = 1, falls = 1;
    const double xis[3] = {0.02, 0.05, 0.2};
    for (int k = 0; k < 3; k++) {
        double prev = 2.0;
        for (double r = 1.0; r <= 4.0; r += 0.125) {
            double rho = pd_ddc_correlation(r, 1.0, xis[k], xis[k]);
            worst = fmax(worst, fabs(rho - rho_equal(r, xis[k])));
            in_range &= rho > 0.0 && rho <= 1.0;
            falls &= rho < prev;
            prev = rho;
            for (int l = 0; l < 3; l++) /* the pair swapped: r to 1 / r, the dampings */
                sym = fmax(sym, fabs(pd_ddc_correlation(r, 1.0, xis[k], xis[l]) -
                                     pd_ddc_correlation(1.0, r, xis[l], xis[k])));
        }
    }
    printf("    rho against the equal-damping closed form within %.2g, symmetric within %.2g\n",
           worst, sym);
    CHECK(ctx, worst <= 1e-14 && sym <= 1e-15 && in_range && falls,
          "closed form %.3g, symmetry %.3g, in (0, 1] %d, falling %d", worst, sym, in_range, falls);
    CHECK(ctx,
          pd_ddc_correlation(0.7, 0.7, 0.05, 0.05) == 1.0 &&
              pd_ddc_correlation(0.7, 0.7, 0.0, 0.0) == 1.0 &&
              pd_ddc_correlation(0.7, 1.4, 0.0, 0.05) == 0.0 &&
              isnan(pd_ddc_correlation(0.0, 1.0, 0.05, 0.05)) &&
              isnan(pd_ddc_correlation(1.0, 0.0, 0.05, 0.05)) &&
              isnan(pd_ddc_correlation(1.0, 1.0, 0.05, -0.1)) &&
              isnan(pd_ddc_correlation(1.0, INFINITY, 0.05, 0.05)) &&
              isnan(pd_ddc_correlation(1.0, 1.0, -0.1, 0.05)) &&
              isnan(pd_ddc_correlation(NAN, 1.0, 0.05, 0.05)),
          "special values");
}

/* A random pair (kind 0: two SDOFs, 1: two buildings touching at every
 * common floor, 2: an SDOF and a wall) under a random sine or cosine pulse,
 * as a scene's JSON text. */
static void random_pair(int kind, uint64_t *rng, char *text, size_t cap)
{
    double Tp = 0.3 + 1.2 * pd_test_uniform(rng), ap = 2.0 + 6.0 * pd_test_uniform(rng);
    const char *pulse = pd_test_uniform(rng) < 0.5 ? "sine" : "cosine";
    char st[2][512];
    int storeys[2] = {1, 1};
    for (int s = 0; s < 2; s++) {
        double xi = 0.02 + 0.08 * pd_test_uniform(rng);
        if (kind == 1) { /* 2 or 3 storeys of random masses and stiffnesses */
            storeys[s] = 2 + (pd_test_uniform(rng) < 0.5);
            char m[96] = "", k[96] = "";
            for (int i = 0; i < storeys[s]; i++) {
                snprintf(m + strlen(m), sizeof m - strlen(m), "%s%.4g", i ? ", " : "",
                         (2.0 + 2.0 * pd_test_uniform(rng)) * 1e5);
                snprintf(k + strlen(k), sizeof k - strlen(k), "%s%.4g", i ? ", " : "",
                         (1.0 + 4.0 * pd_test_uniform(rng)) * 1e8);
            }
            snprintf(st[s], sizeof st[s],
                     "{\"name\": \"s%d\", \"masses\": [%s], \"stiffnesses\": [%s], \"xi\": %.4g}",
                     s, m, k, xi);
        } else
            snprintf(st[s], sizeof st[s], "{\"name\": \"s%d\", \"T0\": %.4g, \"xi\": %.4g}", s,
                     0.3 + 1.7 * pd_test_uniform(rng), xi);
    }
    int common = storeys[0] < storeys[1] ? storeys[0] : storeys[1];
    char levels[32] = "";
    for (int i = 1; i <= common; i++)
        snprintf(levels + strlen(levels), sizeof levels - strlen(levels), "%s%d", i > 1 ? ", " : "",
                 i);
    if (kind == 2)
        snprintf(
            text, cap,
            "{\"excitation\": {\"pulse\": \"%s\", \"ap\": %.4g, \"Tp\": %.4g},\n"
            " \"structures\": [%s],\n"
            " \"contacts\": [{\"a\": \"s0\", \"b\": \"wall\", \"gap\": 0.01, \"eps\": 0.5}]}\n",
            pulse, ap, Tp, st[0]);
    else
        snprintf(text, cap,
                 "{\"excitation\": {\"pulse\": \"%s\", \"ap\": %.4g, \"Tp\": %.4g},\n"
                 " \"structures\": [%s, %s],\n"
                 " \"contacts\": [{\"a\": \"s0\", \"b\": \"s1\", \"levels\": [%s], \"gap\": 0.01, "
                 "\"eps\": 0.5}]}\n",
                 pulse, ap, Tp, st[0], st[1], levels);
}

/* Every contact's required separation by the exact reference: each gap at
 * it plus 1e-9 of it leaves the scene without an impact; one 1 % short
 * strikes there.  And the rules from the twin's peaks. */
static void test_separation_required_gap(pd_test_ctx *ctx)
{
    uint64_t rng = 0x5e9a;
    int cases = 0, contacts = 0, clear = 0, strike = 0, rules_ok = 1;
    double ddc_worst = 0.0;
    pd_run_opts o = pd_run_default_opts();
    o.method = PD_METHOD_EVENT;
    for (int c = 0; c < 18; c++) {
        char text[4096];
        random_pair(c % 3, &rng, text, sizeof text);
        pd_scene *sc = pd_test_scene_of_text(ctx, "/tmp/pd_separation.json", text);
        if (!sc)
            continue;
        pd_scene_summary s;
        pd_err e;
        if (!CHECK(ctx, pd_scene_summarize(sc, &o, NULL, NULL, &s, &e) == PD_OK, "%s", e.msg)) {
            pd_scene_free(sc);
            continue;
        }
        cases++;
        /* the rules from the twin's peaks at the contact's levels */
        for (int a = 0; a < sc->ncontact; a++) {
            const pd_contact *ct = &sc->ct[a];
            double ua = s.free.umax[sc->st[ct->a].dof + ct->level_a - 1];
            double ub = ct->b == PD_WALL ? 0.0 : s.free.umax[sc->st[ct->b].dof + ct->level_b - 1];
            double rho = ct->b == PD_WALL ? 0.0
                                          : pd_ddc_correlation(sc->st[ct->a].T0, sc->st[ct->b].T0,
                                                               sc->st[ct->a].xi, sc->st[ct->b].xi);
            double ddc = sqrt(fmax(ua * ua + ub * ub - 2.0 * rho * ua * ub, 0.0));
            rules_ok &= s.rule_abs[a] == ua + ub && fabs(s.rule_srss[a] - hypot(ua, ub)) <= 0.0 &&
                        rho >= 0.0 && rho <= 1.0;
            ddc_worst = fmax(ddc_worst, fabs(s.rule_ddc[a] - ddc) / fmax(ua + ub, 1e-300));
            rules_ok &= s.rule_ddc[a] <= s.rule_srss[a] + 1e-15 * (ua + ub) &&
                        s.rule_srss[a] <= s.rule_abs[a];
        }
        double req[8];
        int m = sc->ncontact < 8 ? sc->ncontact : 8;
        for (int a = 0; a < m; a++)
            req[a] = s.required_gap[a];
        pd_scene_summary_free(&s);
        /* every gap at its requirement: no impact */
        for (int a = 0; a < m; a++)
            if (req[a] > 0.0)
                sc->ct[a].gap = req[a] * (1.0 + 1e-9);
        pd_scene_result r;
        if (pd_test_scene_run(ctx, sc, PD_METHOD_EVENT, 0.0, &r)) {
            long n = 0;
            for (int a = 0; a < m; a++)
                n += r.impacts[a];
            clear += n == 0;
            CHECK(ctx, n == 0, "case %d: %ld impacts with every gap at its requirement", c, n);
            pd_scene_result_free(&r);
        }
        /* each closing contact 1 % short in turn: it strikes */
        for (int a = 0; a < m; a++) {
            if (!(req[a] > 0.0))
                continue;
            contacts++;
            sc->ct[a].gap = 0.99 * req[a];
            if (pd_test_scene_run(ctx, sc, PD_METHOD_EVENT, 0.0, &r)) {
                strike += r.impacts[a] > 0;
                CHECK(ctx, r.impacts[a] > 0, "case %d, contact %d: no impact 1 %% short of %g m", c,
                      a, req[a]);
                pd_scene_result_free(&r);
            }
            sc->ct[a].gap = req[a] * (1.0 + 1e-9);
        }
        pd_scene_free(sc);
    }
    remove("/tmp/pd_separation.json");
    printf("    %d scenes, %d closing contacts: clear at the requirement in %d, struck 1 %% short "
           "in %d; DDC against its formula within %.2g\n",
           cases, contacts, clear, strike, ddc_worst);
    CHECK(ctx, cases == 18 && contacts >= 18 && rules_ok && ddc_worst <= 1e-15,
          "%d cases, %d contacts, rules %d, DDC %.3g", cases, contacts, rules_ok, ddc_worst);
}

void suite_separation(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_separation_ddc_correlation);
    PD_RUN(ctx, test_separation_required_gap);
}
