/* test_yield.c — the yielding oscillator (SPEC §7) by Moreau–Jean with the
 * slider in the step's LCP (engine/pd_mj1.h, mj1y_step):
 *   - a spring that never yields (uy 1e6 Le) gives the elastic run's
 *     numbers bit for bit, and alpha = 1 is the elastic run;
 *   - a step load on an undamped elastic-plastic (and hardening) spring:
 *     ductility, residual, plastic excursion and hysteretic work against
 *     the closed form, the error falling as dt (order 1);
 *   - the energy balance closes (theta 1/2) to rounding;
 *   - self-similarity in (Pi2, Pi3, Piy, alpha, eps, xi);
 *   - the sampler sees the same run; the methods that do not model
 *     yielding refuse it, and bad uy, alpha are refused;
 *   - one step (mj1y_step) against its equations: balance, slider and
 *     contact complementarity, the elastic answer whenever it is feasible;
 *   - yielding spectra: their points are the single runs, self-similar in
 *     ap, and a stopped sweep resumes to the whole sweep's file;
 *   - the exact reference's phases: the step load's closed form to 1e-12,
 *     the elastic figures when nothing yields, Moreau-Jean converging to
 *     it, an overdamped slide refused. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_core.h"
#include "pd_mj1.h"
#include "pd_problems.h"
#include "pd_test.h"

/* The figures two runs of one case must share, bit for bit. */
static int same_figures(const pd_osc_result *a, const pd_osc_result *b)
{
    const double x[] = {a->umax,         a->u_toward, a->u_away,  a->first_impact, a->max_impulse,
                        a->contact_time, a->min_gap,  a->acc_max, a->shear_max},
                 y[] = {b->umax,         b->u_toward, b->u_away,  b->first_impact, b->max_impulse,
                        b->contact_time, b->min_gap,  b->acc_max, b->shear_max};
    return memcmp(x, y, sizeof x) == 0 && a->impacts == b->impacts && a->steps == b->steps;
}

/* A spring that never reaches uy runs the yielding step and gives the
 * elastic numbers bit for bit (the slider's terms enter only once it
 * slides); alpha = 1 is elastic whatever uy. */
static void test_yield_unreached_is_elastic(pd_test_ctx *ctx)
{
    const double eps[] = {0.0, 0.5, 1.0};
    for (int k = 0; k < 6; k++) {
        pd_osc c = pd_osc_default();
        c.eps = eps[k % 3];
        c.pulse = k % 2 ? PD_PULSE_COSINE : PD_PULSE_SINE;
        c.Pi2 = 0.5 + 0.5 * k;
        pd_run_opts o = pd_run_default_opts();
        o.method = PD_METHOD_MOREAU;
        o.no_wall = k == 5;
        pd_osc_result el, far, hard;
        pd_err e;
        int rc = pd_osc_simulate(&c, &o, NULL, NULL, &el, &e);
        c.Piy = 1e6;
        rc = rc ? rc : pd_osc_simulate(&c, &o, NULL, NULL, &far, &e);
        c.Piy = 0.01;
        c.alpha = 1.0;
        rc = rc ? rc : pd_osc_simulate(&c, &o, NULL, NULL, &hard, &e);
        if (!CHECK(ctx, rc == PD_OK, "case %d: %s", k, e.msg))
            continue;
        CHECK(ctx, same_figures(&el, &far) && same_figures(&el, &hard),
              "case %d: umax %.17g, %.17g (uy 1e6 Le), %.17g (alpha 1)", k, el.umax, far.umax,
              hard.umax);
        CHECK(ctx,
              far.n_yield == 0 && far.residual == 0.0 && far.plastic_excursion == 0.0 &&
                  far.hysteretic_energy == 0.0 && far.ductility == far.umax / (1e6 * pd_osc_Le(&c)),
              "case %d: uy never reached, yet %ld onsets, residual %g", k, far.n_yield,
              far.residual);
        CHECK(ctx, isnan(el.ductility) && isnan(hard.residual) && hard.n_yield == 0,
              "case %d: an elastic run reports ductility %g", k, el.ductility);
    }
}

/* A constant ground acceleration -a0 for 4 s (a record: f = a0 per unit
 * mass, from rest), no wall, undamped, T0 = 1 s: the oscillator c for
 * uy and alpha, with its record rec (the caller frees it). */
static int step_load(pd_osc *c, pd_record *rec, double a0, double uy, double alpha)
{
    double acc[401];
    for (int i = 0; i < 401; i++)
        acc[i] = -a0;
    pd_err e;
    if (pd_record_from_array(rec, "step", acc, 401, 0.01, PD_UNITS_M_S2, &e))
        return 0;
    pd_record_pulse p = {.ap = 1.0, .Tp = 1.0};
    *c = pd_osc_default();
    pd_osc_set_record(c, rec, &p, 1.0);
    c->Pi2 = 1.0; /* T0 = Tp = 1 s */
    c->Pi3 = 1e6; /* no wall within reach */
    c->xi = 0.0;
    c->alpha = alpha;
    pd_osc_set_uy(c, uy);
    return 1;
}

/* The step load's peak by the closed form (w = 2 pi, f = a0 < k uy, f >
 * k uy / 2): elastic to uy, reached at rate v1, v1^2 = w^2 (2 uy f / k -
 * uy^2); then sliding, x'' = f - k (alpha x + (1 - alpha) uy): for alpha =
 * 0 a constant deceleration, umax = uy + v1^2 / (2 (k uy - f)); else an
 * oscillation at w sqrt(alpha) about xc = (f - (1 - alpha) k uy) / (alpha
 * k), umax = xc + sqrt((uy - xc)^2 + v1^2 / (alpha w^2)). */
static double step_load_umax(double f, double uy, double alpha)
{
    double w = 2.0 * PD_PI, k = w * w;
    double v1sq = w * w * (2.0 * uy * f / k - uy * uy);
    if (alpha == 0.0)
        return uy + v1sq / (2.0 * (k * uy - f));
    double xc = (f - (1.0 - alpha) * k * uy) / (alpha * k);
    return xc + sqrt((uy - xc) * (uy - xc) + v1sq / (alpha * w * w));
}

/* The step load's cases (f / Fy, alpha) and the largest relative error of
 * a run's umax, residual, plastic excursion and slider's work against the
 * closed form (up = umax - uy: one slide, never back). */
static const double STEP_UY = 0.01, STEP_RATIO[3] = {0.8, 0.6, 0.7},
                    STEP_ALPHA[3] = {0.0, 0.1, 0.3};

static double step_load_error(const pd_osc_result *r, int k)
{
    double w2 = 4.0 * PD_PI * PD_PI, alpha = STEP_ALPHA[k], uy = STEP_UY;
    double umax = step_load_umax(STEP_RATIO[k] * w2 * uy, uy, alpha), up = umax - uy;
    double work = (1.0 - alpha) * w2 * uy * up;
    double e1 = fabs(r->umax - umax) / umax, e2 = fabs(r->residual - (1.0 - alpha) * up) / up,
           e3 = fabs(r->plastic_excursion - up) / up, e4 = fabs(r->hysteretic_energy - work) / work;
    return fmax(fmax(e1, e2), fmax(e3, e4));
}

/* Under the step load the spring yields once, to umax; it unloads
 * elastically about f / k + (1 - alpha) up and never yields back (the
 * swing's far end keeps z >= -uy for these loads; its next top touches uy
 * at rest, a grazing the run ends before), so that up = umax - uy:
 * residual (1 - alpha) up, excursion up, the slider's work (1 - alpha) k
 * uy up.  Moreau–Jean's errors against the closed form fall with dt: their
 * envelope over steps near T0 / 4000 at least 2.5 times below the one
 * near T0 / 1000 (first order gives 4; measured 12 to 22), which is below
 * 1e-4 (measured 4e-6 to 9e-6). */
static void test_yield_step_load_closed_form(pd_test_ctx *ctx)
{
    for (int k = 0; k < 3; k++) {
        double w2 = 4.0 * PD_PI * PD_PI, f = STEP_RATIO[k] * w2 * STEP_UY;
        pd_osc c;
        pd_record rec = {0};
        if (!CHECK(ctx, step_load(&c, &rec, f, STEP_UY, STEP_ALPHA[k]), "case %d: no record", k))
            continue;
        /* the largest error over five steps near T0 / 1000, then near T0 / 4000
         * (where the onset falls inside its step varies the error: its envelope) */
        double err[2] = {0.0, 0.0};
        pd_osc_result r = {0};
        for (int h = 0; h < 10; h++) {
            pd_run_opts o = pd_run_default_opts();
            o.method = PD_METHOD_MOREAU;
            o.dt = 1.0 / ((h < 5 ? 1000.0 : 4000.0) * (1.0 + 0.023 * (h % 5)));
            o.tend = 1.5; /* before the elastic swing's next top grazes uy (t ~ 1.6 s) */
            pd_err e;
            if (!CHECK(ctx, pd_osc_simulate(&c, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg))
                break;
            err[h / 5] = fmax(err[h / 5], step_load_error(&r, k));
            CHECK(ctx, r.n_yield == 1, "case %d, dt %g: %ld yield onsets, one", k, o.dt, r.n_yield);
        }
        double mu = step_load_umax(f, STEP_UY, STEP_ALPHA[k]) / STEP_UY;
        CHECK(ctx, err[1] <= err[0] / 2.5 && err[0] <= 1e-4,
              "case %d (alpha %g, f / Fy %g): errors up to %.3g near dt = T0/1000, %.3g near "
              "T0/4000 (closed-form ductility %.9g)",
              k, STEP_ALPHA[k], STEP_RATIO[k], err[0], err[1], mu);
        CHECK(ctx, fabs(r.ductility - mu) <= 1e-3 * mu, "case %d: ductility %.9g, closed form %.9g",
              k, r.ductility, mu);
        pd_record_free(&rec);
    }
}

/* Against a wall: a yielding oscillator that pounds (Pi3 0.05, Piy 0.1,
 * alpha 0.05, eps 0.5), Moreau–Jean converging: its figures' distances to
 * the run at dt = T0 / 64000, largest over five steps near T0 / 500 and
 * near T0 / 4000, fall at least 4-fold (first order gives 8; measured
 * 1.9e-3 to 4.4e-7), and the onsets are the fine run's (its bounces, 12,
 * are not: a coarse step merges the last of a burst, 8 or 9 near T0/500). */
static void test_yield_wall_converges(pd_test_ctx *ctx)
{
    pd_osc c = pd_osc_default();
    c.Piy = 0.1;
    c.alpha = 0.05;
    pd_run_opts o = pd_run_default_opts();
    o.method = PD_METHOD_MOREAU;
    o.dt = pd_osc_T0(&c) / 64000.0;
    pd_osc_result fine, r;
    pd_err e;
    if (!CHECK(ctx, pd_osc_simulate(&c, &o, NULL, NULL, &fine, &e) == PD_OK, "%s", e.msg))
        return;
    double dist[2] = {0.0, 0.0};
    for (int h = 0; h < 10; h++) {
        o.dt = pd_osc_T0(&c) / ((h < 5 ? 500.0 : 4000.0) * (1.0 + 0.023 * (h % 5)));
        if (!CHECK(ctx, pd_osc_simulate(&c, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg))
            return;
        double d = fmax(fabs(r.umax - fine.umax) / fine.umax,
                        fabs(r.residual - fine.residual) / fabs(fine.residual));
        d = fmax(d, fabs(r.hysteretic_energy - fine.hysteretic_energy) / fine.hysteretic_energy);
        dist[h / 5] = fmax(dist[h / 5], d);
        CHECK(ctx, r.n_yield == fine.n_yield, "dt %g: %ld onsets; the fine run %ld", o.dt,
              r.n_yield, fine.n_yield);
    }
    CHECK(ctx, dist[1] <= dist[0] / 4.0 && fine.impacts >= 2 && fine.n_yield >= 2,
          "distances to the fine run up to %.3g near T0/500, %.3g near T0/4000 (fine: %ld "
          "impacts, %ld onsets, ductility %.6g, residual %.6g m)",
          dist[0], dist[1], fine.impacts, fine.n_yield, fine.ductility, fine.residual);
}

/* Case k of the energy balances' 24: a pulse (harmonic one in three), Pi2
 * 0.5 to 3, a wall or none (Pi3 1e6), Piy 0.05 to 0.55, alpha 0 to 0.3,
 * eps 0 to 1, xi 0 to 0.1, drawn from rng. */
static pd_osc energy_case(int k, uint64_t *rng)
{
    pd_osc c = pd_osc_default();
    c.pulse = k % 3 == 2 ? PD_PULSE_HARMONIC : k % 2 ? PD_PULSE_COSINE : PD_PULSE_SINE;
    c.Pi2 = 0.5 + 2.5 * pd_test_uniform(rng);
    c.Pi3 = k % 4 == 3 ? 1e6 : 0.5 * pd_test_uniform(rng);
    c.Piy = 0.05 + 0.5 * pd_test_uniform(rng);
    c.alpha = k % 5 == 0 ? 0.0 : 0.3 * pd_test_uniform(rng);
    c.eps = pd_test_uniform(rng);
    c.xi = 0.1 * pd_test_uniform(rng);
    return c;
}

/* The energy balance of yielding runs with theta = 1/2 (the step's
 * energy identity is exact for the midpoint: input = kinetic + strain +
 * damping + slider + impacts per step) closes to rounding, 1e-12 of the
 * input over some 10^4 steps (measured below 4e-14), with every loss >= 0
 * (impacts with e <= 1, the slider's work, damping); theta = 0.7 leaves
 * its numerical damping in the residual, > 0. */
static void test_yield_energy_balance(pd_test_ctx *ctx)
{
    uint64_t rng = 0xe4e6;
    double worst = 0.0, worst_loss = 0.0;
    for (int k = 0; k < 24; k++) {
        pd_osc c = energy_case(k, &rng);
        pd_run_opts o = pd_run_default_opts();
        o.method = PD_METHOD_MOREAU;
        pd_osc_result r;
        pd_err e;
        if (!CHECK(ctx, pd_osc_simulate(&c, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg))
            continue;
        const pd_energy *en = &r.energy;
        worst = fmax(worst, fabs(en->residual));
        double loss = fmin(fmin(en->damping, en->hysteretic), fmin(en->impact, en->strain));
        worst_loss = fmin(worst_loss, fmin(loss, en->kinetic) / en->input);
        if (k == 0) { /* the same case with theta 0.7: numerical damping */
            o.theta = 0.7;
            pd_osc_result r7;
            if (CHECK(ctx, pd_osc_simulate(&c, &o, NULL, NULL, &r7, &e) == PD_OK, "%s", e.msg))
                CHECK(ctx, r7.energy.residual > 1e-6,
                      "theta 0.7: residual %.3g of the input (numerical damping, > 0)",
                      r7.energy.residual);
        }
    }
    CHECK(ctx, worst <= 1e-12 && worst_loss >= -1e-12,
          "theta 1/2: energy balance residual up to %.3g of the input, a loss down to %.3g", worst,
          worst_loss);
}

/* The exact reference's energy balance through pd_osc_run (quadrature of
 * the flights, the impacts' losses, an accumulation's tail): 1e-12 of the
 * input on the cases above (measured 8e-14, harmonic runs of many periods),
 * each term within 2 % of the input from Moreau-Jean's at the default step
 * (the input and the losses; measured 0.8 %) -- and left out (NAN) of a
 * sweep's runs.  Newmark's balance (the step identity with its element's
 * forces by the trapezoid) closes within 1e-9 of the input (its Newton
 * tolerance summed; measured 5.4e-11), its slider's work within 1e-4 of the
 * input from kbar uy times its excursion (the two differ on the onsets'
 * steps; measured 1.7e-6). */
static void test_yield_exact_energy_balance(pd_test_ctx *ctx)
{
    uint64_t rng = 0xe4e6;
    double worst = 0.0, worst_term = 0.0, worst_nm = 0.0, worst_nm_term = 0.0;
    int nm_summed = 1;
    int runs = 0;
    for (int k = 0; k < 24; k++) {
        pd_osc c = energy_case(k, &rng);
        if (!pd_osc_yield_exact(&c))
            continue;
        pd_run_opts o = pd_run_default_opts();
        pd_osc_result ex, mj;
        pd_err e;
        o.method = PD_METHOD_EVENT;
        int ok = CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &ex, &e) == PD_OK, "%s", e.msg);
        o.method = PD_METHOD_MOREAU;
        ok = ok && CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &mj, &e) == PD_OK, "%s", e.msg);
        pd_osc_result nm; /* newmark's: the same step identity, its element's forces */
        o.method = PD_METHOD_NEWMARK;
        ok = ok && CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &nm, &e) == PD_OK, "%s", e.msg);
        if (!ok)
            continue;
        runs++;
        worst_nm = fmax(worst_nm, fabs(nm.energy.residual));
        nm_summed &= isfinite(nm.energy.residual) && isfinite(nm.energy.input);
        /* its slider's work by the identity against kbar uy excursion */
        worst_nm_term = fmax(worst_nm_term,
                             fabs(nm.energy.hysteretic - nm.hysteretic_energy) / nm.energy.input);
        worst = fmax(worst, fabs(ex.energy.residual));
        const double a[] = {ex.energy.input, ex.energy.damping, ex.energy.hysteretic,
                            ex.energy.impact},
                     b[] = {mj.energy.input, mj.energy.damping, mj.energy.hysteretic,
                            mj.energy.impact};
        for (int i = 0; i < 4; i++)
            worst_term = fmax(worst_term, fabs(a[i] - b[i]) / ex.energy.input);
    }
    printf("    %d runs: residual %.2g, a term %.2g of the input from Moreau-Jean's; newmark's "
           "residual %.2g, its slider's work %.2g of the input from kbar uy excursion\n",
           runs, worst, worst_term, worst_nm, worst_nm_term);
    CHECK(ctx, nm_summed && worst_nm <= 1e-9 && worst_nm_term <= 1e-4,
          "newmark: residual %.3g, terms %.3g, every run's balance summed %d", worst_nm,
          worst_nm_term, nm_summed);
    /* an elastic oscillator by newmark sums none (NAN), as Moreau-Jean's */
    pd_osc el = pd_osc_default();
    pd_run_opts on = pd_run_default_opts();
    on.method = PD_METHOD_NEWMARK;
    pd_osc_result re;
    pd_err ee;
    if (CHECK(ctx, pd_osc_run(&el, &on, NULL, NULL, &re, &ee) == PD_OK, "%s", ee.msg))
        CHECK(ctx, isnan(re.energy.input) && isnan(re.energy.residual),
              "an elastic newmark run's energy input %g (NAN)", re.energy.input);
    CHECK(ctx, runs >= 12 && worst <= 1e-12 && worst_term <= 2e-2,
          "%d runs: the exact balance's residual up to %.3g of the input; a term %.3g of the "
          "input from Moreau-Jean's",
          runs, worst, worst_term);
    pd_osc c = pd_osc_default();
    c.Piy = 0.2;
    pd_run_opts o = pd_run_default_opts();
    o.method = PD_METHOD_EVENT;
    o.no_demands = 1;
    pd_osc_result r;
    pd_err e;
    if (CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg))
        CHECK(ctx, isnan(r.energy.input) && isnan(r.energy.residual) && r.n_yield > 0,
              "a sweep's run: energy input %g, residual %g (NAN), %ld onsets", r.energy.input,
              r.energy.residual, r.n_yield);
}

/* The run depends on the Pi terms only: ap tripled with Pi2, Pi3, Piy,
 * alpha, eps, xi kept (gap and uy scale with Le) leaves Pi1, ductility,
 * residual / uy and the counts (1e-12). */
static void test_yield_self_similar(pd_test_ctx *ctx)
{
    pd_osc c = pd_osc_default();
    c.Pi2 = 1.5;
    c.Pi3 = 0.3;
    c.Piy = 0.2;
    c.alpha = 0.05;
    c.eps = 0.6;
    pd_run_opts o = pd_run_default_opts();
    o.method = PD_METHOD_MOREAU;
    pd_osc_result a, b;
    pd_err e;
    int rc = pd_osc_simulate(&c, &o, NULL, NULL, &a, &e);
    double Le = pd_osc_Le(&c);
    c.ap *= 3.0;
    rc = rc ? rc : pd_osc_simulate(&c, &o, NULL, NULL, &b, &e);
    if (!CHECK(ctx, rc == PD_OK, "%s", e.msg))
        return;
    double Le3 = pd_osc_Le(&c);
    CHECK(ctx,
          fabs(a.umax / Le - b.umax / Le3) <= 1e-12 * a.umax / Le &&
              fabs(a.ductility - b.ductility) <= 1e-12 * a.ductility &&
              fabs(a.residual / Le - b.residual / Le3) <= 1e-12 * fabs(a.residual / Le) &&
              a.n_yield == b.n_yield && a.impacts == b.impacts && a.n_yield >= 2 && a.impacts >= 1,
          "Pi1 %.17g, %.17g; ductility %.17g, %.17g; residual / Le %.17g, %.17g; onsets %ld, %ld",
          a.umax / Le, b.umax / Le3, a.ductility, b.ductility, a.residual / Le, b.residual / Le3,
          a.n_yield, b.n_yield);
}

/* The samples of a yielding run: one at t = 0 and one per step, the last
 * at the run's end with its umax among them; the figures those of the run
 * without a sampler, bit for bit. */
typedef struct sample_tally {
    long n;
    double umax, t_last;
} sample_tally;

static int tally(const pd_osc_sample *s, void *ctx)
{
    sample_tally *st = ctx;
    st->n++;
    st->umax = fmax(st->umax, fabs(s->u));
    st->t_last = s->t;
    return 0;
}

static void test_yield_sampled(pd_test_ctx *ctx)
{
    pd_osc c = pd_osc_default();
    c.Piy = 0.1;
    c.alpha = 0.02;
    pd_run_opts o = pd_run_default_opts();
    o.method = PD_METHOD_MOREAU;
    pd_osc_result a, b;
    sample_tally st = {0};
    pd_err e;
    int rc = pd_osc_simulate(&c, &o, NULL, NULL, &a, &e);
    rc = rc ? rc : pd_osc_simulate(&c, &o, tally, &st, &b, &e);
    if (CHECK(ctx, rc == PD_OK, "%s", e.msg))
        CHECK(ctx,
              same_figures(&a, &b) && a.residual == b.residual && a.n_yield == b.n_yield &&
                  st.n == a.steps + 1 && st.umax == a.umax &&
                  fabs(st.t_last - a.tend) <= 1e-9 * a.tend,
              "%ld samples for %ld steps, their umax %.17g (run %.17g), last at %g of %g", st.n,
              a.steps, st.umax, a.umax, st.t_last, a.tend);
}

/* One yielding step from random states (K, C, alpha, uy, h, theta, a wall
 * or none, e) against the equations it solves, each to 1e-12 of its terms:
 *   What-free balance  v+ - v = h [F_th - C v_th - K q_th + kbar (up + th G)]
 *                      + W P  (M = 1),  q_th = q + h th v_th, v_th = th v+ +
 *                      (1 - th) v, q+ = q + h v_th;
 *   the slider         |z+| <= uy, z+ = q+ - up+, G = up+ - up, G != 0 only
 *                      with z+ = sign(G) uy;
 *   the contact        P >= 0, U+ + e U >= 0, P (U+ + e U) = 0 when active
 *                      (g + h gamma U <= 0), P = 0 otherwise;
 *   uniqueness         G = 0 exactly when the elastic step (mj1_step with
 *                      the offset's force) keeps |z+| <= uy, and then the
 *                      elastic step's numbers. */
static void test_yield_step_equations(pd_test_ctx *ctx)
{
    uint64_t rng = 0x1e1d;
    double worst_bal = 0.0, worst_z = 0.0, worst_c = 0.0;
    int yielded = 0, contacts = 0, wrong = 0;
    for (int k = 0; k < 4000; k++) {
        double K = pow(10.0, 2.0 * pd_test_uniform(&rng) - 1.0), C = 0.3 * pd_test_uniform(&rng);
        double h = 0.05 * pd_test_uniform(&rng) + 1e-3, th = 0.5 + 0.5 * pd_test_uniform(&rng);
        double alpha = k % 5 == 0 ? 0.0 : 0.4 * pd_test_uniform(&rng);
        double uy = 0.01 + 0.1 * pd_test_uniform(&rng), e = pd_test_uniform(&rng), hgamma = 0.5 * h;
        int wall = k % 3 != 0;
        double up0 = (pd_test_uniform(&rng) - 0.5) * uy * (k % 2);
        double z0 = (2.0 * pd_test_uniform(&rng) - 1.0) * uy;
        double q0 = up0 + z0, v0 = 4.0 * (pd_test_uniform(&rng) - 0.5);
        double g0 = q0 + 0.05 * (pd_test_uniform(&rng) - 0.3); /* the gap g0 - q0 near 0 */
        if (k % 7 == 0) { /* touching at rest: g + h gamma U = 0, active */
            g0 = q0;
            v0 = 0.0;
        }
        mj1_coef s = mj1_coef_make(1.0, C, K, wall, -1.0, g0, e, h, th);
        mj1_yield y = mj1_yield_make(&s, K, alpha, uy, h, th);
        double F0 = 2.0 * pd_test_uniform(&rng) - 1.0, F1 = 2.0 * pd_test_uniform(&rng) - 1.0;
        double q = q0, v = v0, g = g0 - q0, P, up = up0, G;
        int active = mj1y_step(h, th, hgamma, &s, &y, F0, F1, &q, &v, &g, &P, &up, &G);
        double kbar = (1.0 - alpha) * K, vth = th * v + (1.0 - th) * v0, qth = q0 + h * th * vth;
        double terms = fabs(v) + fabs(v0) +
                       h * (fabs(F0) + fabs(F1) + fabs(C * vth) + fabs(K * qth) +
                            fabs(kbar * (up0 + th * G))) +
                       fabs(P);
        double bal = v - v0 -
                     h * (th * F1 + (1.0 - th) * F0 - C * vth - K * qth + kbar * (up0 + th * G)) -
                     (-1.0) * P;
        worst_bal = fmax(worst_bal, fabs(bal) / terms);
        wrong += fabs(q - (q0 + h * vth)) > 1e-12 * (fabs(q) + h * fabs(vth) + fabs(q0));
        wrong += up != up0 + G || g != (wall ? g0 - q : 0.0); /* g+ = g0 + W q+ */
        double z = q - up;
        worst_z = fmax(worst_z, (fabs(z) - uy) / uy);
        if (G != 0.0) {
            yielded++;
            worst_z = fmax(worst_z, fabs(z - (G > 0.0 ? uy : -uy)) / uy);
        }
        double U0 = -v0, Up = -v, ok_active = g0 - q0 + hgamma * U0 <= 0.0;
        wrong += active != (wall && ok_active);
        if (active) {
            contacts += P > 0.0;
            double sc = fabs(Up) + e * fabs(U0) + fabs(P); /* U+ = W vfree + W^ P: its terms */
            worst_c = fmax(worst_c, fmax(-(Up + e * U0), 0.0) / sc);
            worst_c = fmax(worst_c, P > 0.0 ? fabs(Up + e * U0) / sc : 0.0);
            wrong += P < 0.0;
        } else
            wrong += P != 0.0;
        /* the elastic step with the offset's force: its z+ decides whether G = 0 */
        double qe = q0, ve = v0, ge = g0 - q0, Pe, upe = up0, Ge;
        mj1_yield never = y;
        never.uy = HUGE_VAL;
        mj1y_step(h, th, hgamma, &s, &never, F0, F1, &qe, &ve, &ge, &Pe, &upe, &Ge);
        int feasible = fabs(qe - up0) <= uy;
        wrong += feasible != (G == 0.0) || Ge != 0.0;
        if (feasible)
            wrong += q != qe || v != ve || P != Pe;
        if (up0 == 0.0 && feasible) { /* no offset: mj1_step's numbers, bit for bit */
            double q1 = q0, v1 = v0, g1 = g0 - q0, P1;
            mj1_step(h, th, hgamma, &s, F0, F1, &q1, &v1, &g1, &P1);
            wrong += q1 != q || v1 != v || P1 != P || g1 != g;
        }
    }
    CHECK(ctx, worst_bal <= 1e-12 && worst_z <= 1e-12 && worst_c <= 1e-12 && wrong == 0,
          "balance off by %.3g of its terms, z+ beyond or off uy by %.3g uy, contact law off "
          "by %.3g; %d other failures",
          worst_bal, worst_z, worst_c, wrong);
    CHECK(ctx, yielded >= 600 && contacts >= 400, "%d steps yielded, %d pushed a wall", yielded,
          contacts);
}

/* A yielding spectrum (Piy 0.4, alpha 0.05; two gaps x 5 Pi2, ap 1 and 3):
 * Moreau-Jean chosen, each point's ductility and residual / uy those of
 * the single run of its case bit for bit, ductility_free its no-wall
 * twin's; ap tripled leaves ductility and residual / uy (1e-12). */
static void test_yield_spectrum_points(pd_test_ctx *ctx)
{
    pd_spectrum s;
    pd_spec_init(&s);
    s.base.Piy = 0.4;
    s.base.alpha = 0.05;
    s.pi2_min = 0.5;
    s.pi2_max = 3.0;
    s.npi2 = 5;
    s.nsize = 2;
    s.size[0] = 0.05;
    s.size[1] = 0.3;
    s.nap = 2;
    s.ap[0] = 1.0;
    s.ap[1] = 3.0;
    s.dimensional = 1;
    pd_spec_resolve_method(&s);
    CHECK(ctx, s.opts.method == PD_METHOD_EVENT, "a yielding sweep (xi^2 < alpha) runs by %s",
          pd_method_name(s.opts.method));
    enum { NT = 30, NP = 20 };
    pd_spec_result res[NT];
    pd_spec_row rows[NP];
    pd_err e;
    if (!CHECK(ctx, pd_spec_tasks(&s) == NT && pd_spec_points(&s) == NP, "%ld tasks, %ld points",
               pd_spec_tasks(&s), pd_spec_points(&s)))
        return;
    for (long t = 0; t < NT; t++) {
        pd_spec_run_task(&s, t, &res[t], &e);
        if (!CHECK(ctx, res[t].status == PD_OK, "task %ld: %s", t, e.msg))
            return;
    }
    pd_spec_rows(&s, res, rows);
    int wrong = 0, yielded = 0, paired = 0;
    double worst = 0.0;
    long ntw = pd_spec_twins(&s);
    for (long p = 0; p < NP; p++) {
        pd_osc c;
        pd_run_opts o;
        pd_osc_result one, twin;
        long t = ntw + p;
        if (pd_spec_case(&s, t, &c, &o, &e) || pd_osc_run(&c, &o, NULL, NULL, &one, &e) ||
            pd_spec_case(&s, pd_spec_twin_of(&s, t), &c, &o, &e) ||
            pd_osc_run(&c, &o, NULL, NULL, &twin, &e)) {
            CHECK(ctx, 0, "point %ld: %s", p, e.msg);
            return;
        }
        wrong += rows[p].ductility != one.ductility ||
                 rows[p].residual_uy != one.residual / pd_osc_uy(&rows[p].c) ||
                 rows[p].ductility_free != twin.ductility;
        yielded += rows[p].ductility > 1.0;
        /* the same point at ap 3 */
        for (long q = 0; q < NP && rows[p].c.ap == 1.0; q++)
            if (rows[q].c.ap == 3.0 && rows[q].c.Pi3 == rows[p].c.Pi3 &&
                rows[q].c.Pi2 == rows[p].c.Pi2) {
                worst =
                    fmax(worst, fabs(rows[q].ductility - rows[p].ductility) / rows[p].ductility);
                worst = fmax(worst, fabs(rows[q].residual_uy - rows[p].residual_uy) /
                                        fmax(fabs(rows[p].residual_uy), 1e-300));
                paired++;
            }
    }
    CHECK(ctx, wrong == 0 && yielded >= 10 && paired == NP / 2 && worst <= 1e-12,
          "%d points differ from their single runs; %d of %d yield; ap tripled moves ductility "
          "and residual / uy by %.3g (%d pairs)",
          wrong, yielded, NP, worst, paired);
}

/* A yielding sweep stopped after 5 runs and resumed from its journal
 * writes the file of an uninterrupted one, its ductility columns too. */
static void test_yield_spectrum_resume(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_yield_resumeXXXXXX", out[256], fresh[256];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(out, sizeof out, "%s/s.csv", dir);
    snprintf(fresh, sizeof fresh, "%s/f.csv", dir);
#define YSWEEP "spectrum", "--Pi2", "0.5:3:6", "--Piy", "0.5", "--alpha", "0.05", "--threads", "1"
    const char *stop[] = {YSWEEP, "-o", out, "--stop-after", "5", NULL};
    const char *resume[] = {YSWEEP, "-o", out, "--resume", NULL};
    const char *whole[] = {YSWEEP, "-o", fresh, NULL};
#undef YSWEEP
    proc_out r;
    pd_test_pound(ctx, stop, &r);
    pd_test_proc_free(&r);
    pd_test_pound(ctx, resume, &r);
    CHECK(ctx, r.status == 0, "--resume: exit %d: %s", r.status, r.err);
    pd_test_proc_free(&r);
    pd_test_pound(ctx, whole, &r);
    CHECK(ctx, r.status == 0, "exit %d: %s", r.status, r.err);
    pd_test_proc_free(&r);
    char *text = pd_test_slurp(out);
    CHECK(ctx, text && strstr(text, ",ductility,ductility_free,residual_uy\n"),
          "the yielding columns in %s", out);
    free(text);
    CHECK(ctx, pd_test_same_file(out, fresh), "the resumed file differs from a whole sweep's");
    pd_test_rm_dir(dir);
}

/* ---- the exact reference (engine/event_sdof.c's phases) ---------------- */

/* The step load's closed form by the event-driven reference: umax,
 * residual, plastic excursion and the slider's work to 1e-12 (the onset
 * and the turn root-found to adjacent doubles), one onset; for alpha = 0
 * the slide is a free mass (xi = 0). */
static void test_yield_exact_step_load(pd_test_ctx *ctx)
{
    for (int k = 0; k < 3; k++) {
        double w2 = 4.0 * PD_PI * PD_PI, f = STEP_RATIO[k] * w2 * STEP_UY;
        pd_osc c;
        pd_record rec = {0};
        if (!CHECK(ctx, step_load(&c, &rec, f, STEP_UY, STEP_ALPHA[k]), "case %d: no record", k))
            continue;
        pd_run_opts o = pd_run_default_opts();
        o.method = PD_METHOD_EVENT;
        o.tend = 1.5;
        pd_osc_result r;
        pd_err e;
        if (CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &r, &e) == PD_OK, "case %d: %s", k, e.msg))
            CHECK(ctx, step_load_error(&r, k) <= 1e-12 && r.n_yield == 1,
                  "case %d: umax, residual, excursion or work off by %.3g; %ld onsets", k,
                  step_load_error(&r, k), r.n_yield);
        pd_record_free(&rec);
    }
}

/* The figures of same_figures within rel of each other (relative). */
static int close_figures(const pd_osc_result *a, const pd_osc_result *b, double rel)
{
    const double x[] = {a->umax,         a->u_toward, a->u_away,  a->first_impact, a->max_impulse,
                        a->contact_time, a->min_gap,  a->acc_max, a->shear_max},
                 y[] = {b->umax,         b->u_toward, b->u_away,  b->first_impact, b->max_impulse,
                        b->contact_time, b->min_gap,  b->acc_max, b->shear_max};
    int ok = a->impacts == b->impacts && a->steps == b->steps;
    for (size_t k = 0; k < sizeof x / sizeof x[0]; k++)
        ok &= fabs(x[k] - y[k]) <= rel * fmax(fabs(x[k]), fabs(y[k])) || x[k] == y[k];
    return ok;
}

/* A spring that never yields (uy 1e6 Le) gives the reference's elastic
 * numbers to 1e-14 (its flights are the elastic ones; an event bracketed
 * on one monotone segment rather than the whole scan interval may land an
 * ulp away: contact time 1.5e-16 apart measured), and alpha = 1 is the
 * elastic run. */
static void test_yield_exact_unreached_is_elastic(pd_test_ctx *ctx)
{
    for (int k = 0; k < 4; k++) {
        pd_osc c = pd_osc_default();
        c.eps = 0.3 * k;
        c.pulse = k % 2 ? PD_PULSE_COSINE : PD_PULSE_SINE;
        c.Pi2 = 0.7 + 0.6 * k;
        pd_run_opts o = pd_run_default_opts();
        o.method = PD_METHOD_EVENT;
        pd_osc_result el, far, hard;
        pd_err e;
        int rc = pd_osc_run(&c, &o, NULL, NULL, &el, &e);
        c.Piy = 1e6;
        c.alpha = 0.1;
        rc = rc ? rc : pd_osc_run(&c, &o, NULL, NULL, &far, &e);
        c.Piy = 0.01;
        c.alpha = 1.0;
        rc = rc ? rc : pd_osc_run(&c, &o, NULL, NULL, &hard, &e);
        if (CHECK(ctx, rc == PD_OK, "case %d: %s", k, e.msg))
            CHECK(ctx,
                  close_figures(&el, &far, 1e-14) && same_figures(&el, &hard) && far.n_yield == 0 &&
                      far.residual == 0.0,
                  "case %d: umax %.17g, %.17g (uy 1e6 Le), %.17g (alpha 1); %ld onsets", k, el.umax,
                  far.umax, hard.umax, far.n_yield);
    }
}

/* Moreau-Jean converges to the exact reference on yielding oscillators
 * that pound (sine and cosine pulses, eps 0 to 1, alpha 0.05 to 0.3, xi <
 * sqrt(alpha)): the distance of umax, residual and the slider's work,
 * largest over five steps near T0/1000, falls at least 4-fold near
 * T0/16000 (first order gives 16, erratic as impacts and onsets fall
 * anywhere in their steps: measured 5.0 to 29) and is below 2e-3 there
 * (measured 1.4e-3 at worst); the onsets agree at the finer steps.  (Case 0 followed further: umax 9.5e-6,
 * 1.4e-6, 2.1e-7 off at T0/8000, /32000, /128000.) */
static void test_yield_exact_moreau_converges(pd_test_ctx *ctx)
{
    uint64_t rng = 0x7e1d;
    double worst_ratio = HUGE_VAL, worst_fine = 0.0;
    int onsets_off = 0, cases = 0;
    for (int k = 0; k < 8; k++) {
        pd_osc c = pd_osc_default();
        c.pulse = k % 2 ? PD_PULSE_COSINE : PD_PULSE_SINE;
        c.dir = k % 4 < 2 ? 1 : -1;
        c.Pi2 = 0.5 + 2.0 * pd_test_uniform(&rng);
        c.Pi3 = 0.02 + 0.3 * pd_test_uniform(&rng);
        c.Piy = 0.1 + 0.4 * pd_test_uniform(&rng);
        c.alpha = 0.05 + 0.25 * pd_test_uniform(&rng);
        if (k % 4 == 3) /* elastic-perfectly-plastic, damped: the slide a damped free mass */
            c.alpha = 0.0;
        c.eps = k / 7.0;
        c.xi = 0.05;
        pd_run_opts o = pd_run_default_opts();
        o.method = PD_METHOD_EVENT;
        pd_osc_result ref, r;
        pd_err e;
        if (!CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &ref, &e) == PD_OK, "case %d: %s", k, e.msg))
            continue;
        double dist[2] = {0.0, 0.0};
        o.method = PD_METHOD_MOREAU;
        for (int h = 0; h < 10; h++) {
            o.dt = pd_osc_T0(&c) / ((h < 5 ? 1000.0 : 16000.0) * (1.0 + 0.023 * (h % 5)));
            if (!CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &r, &e) == PD_OK, "%s", e.msg))
                break;
            double d = fmax(fabs(r.umax - ref.umax) / ref.umax,
                            fabs(r.hysteretic_energy - ref.hysteretic_energy) /
                                fmax(ref.hysteretic_energy, 1e-300));
            d = fmax(d, fabs(r.residual - ref.residual) / fmax(ref.plastic_excursion, 1e-300));
            dist[h / 5] = fmax(dist[h / 5], d);
            onsets_off += h >= 5 && r.n_yield != ref.n_yield;
        }
        worst_ratio = fmin(worst_ratio, dist[0] / dist[1]);
        worst_fine = fmax(worst_fine, dist[1]);
        cases += ref.n_yield >= 1;
    }
    CHECK(ctx, worst_ratio >= 4.0 && worst_fine <= 2e-3 && onsets_off == 0 && cases >= 6,
          "Moreau-Jean against the exact reference: the distance falls by at least %.3g from "
          "T0/1000 to T0/16000, %.3g there; %d finer runs count other onsets; %d of 8 cases yield",
          worst_ratio, worst_fine, onsets_off, cases);
}

/* Elastic-perfectly-plastic springs with heavy damping (xi 0.3, Piy 0.05:
 * long slides, c s past 1/2 where the damped free mass's kernels leave
 * their series), with and without a wall: Moreau-Jean at T0/16000 within
 * 1e-3 of the exact reference's umax, residual and slider's work (measured
 * 3.3e-5 at worst).  The onsets may differ: a slide that turns back and
 * reloads within a step (a dip of the velocity through zero) is one slide
 * to Moreau-Jean, two to the reference (6 against 2 on one case here). */
static void test_yield_exact_damped_plastic(pd_test_ctx *ctx)
{
    double worst = 0.0;
    for (int k = 0; k < 4; k++) {
        pd_osc c = pd_osc_default();
        c.Piy = 0.05;
        c.alpha = 0.0;
        c.xi = 0.3;
        c.Pi2 = k < 2 ? 0.8 : 2.0;
        c.Pi3 = k % 2 ? 1e6 : 0.3;
        c.pulse = k < 2 ? PD_PULSE_SINE : PD_PULSE_COSINE;
        pd_run_opts o = pd_run_default_opts();
        o.method = PD_METHOD_EVENT;
        pd_osc_result ref, r;
        pd_err e;
        int rc = pd_osc_run(&c, &o, NULL, NULL, &ref, &e);
        o.method = PD_METHOD_MOREAU;
        o.dt = pd_osc_T0(&c) / 16000.0;
        rc = rc ? rc : pd_osc_run(&c, &o, NULL, NULL, &r, &e);
        if (!CHECK(ctx, rc == PD_OK, "case %d: %s", k, e.msg))
            continue;
        double d = fmax(fabs(r.umax - ref.umax) / ref.umax,
                        fabs(r.hysteretic_energy - ref.hysteretic_energy) / ref.hysteretic_energy);
        d = fmax(d, fabs(r.residual - ref.residual) / ref.plastic_excursion);
        worst = fmax(worst, d);
        CHECK(ctx, ref.n_yield >= r.n_yield && r.n_yield >= 1, "case %d: onsets %ld, %ld", k,
              r.n_yield, ref.n_yield);
    }
    CHECK(ctx, worst <= 1e-3, "Moreau-Jean at T0/16000 %.3g from the reference", worst);
}

/* A constant force written as a sine of no frequency (A sin(phi), w = 0)
 * drives a damped free mass's slide as the same constant written as c0
 * does (to 1e-14): the reference's pd_ed_sdof directly, a yielding spring
 * pushed off its start past uy. */
static void test_yield_exact_constant_sine_piece(pd_test_ctx *ctx)
{
    pd_sine_piece as_sine = {.t_start = 0.0, .A = 2.0, .w = 0.0, .phi = 0.5 * PD_PI};
    pd_sine_piece as_c0 = {.t_start = 0.0, .c0 = 2.0};
    pd_ed_sdof prob = {.osc = {.w0 = 1.0, .xi = 0.3}, .npieces = 1, .uy = 0.5, .alpha = 0.0};
    pd_ed_opts o = pd_ed_default_opts();
    o.t_end = 20.0;
    pd_ed_result a, b;
    pd_err e;
    prob.pieces = &as_sine;
    int rc = pd_ed_sdof_run(&prob, 0.0, 0.0, &o, NULL, NULL, &a, &e);
    prob.pieces = &as_c0;
    rc = rc ? rc : pd_ed_sdof_run(&prob, 0.0, 0.0, &o, NULL, NULL, &b, &e);
    if (CHECK(ctx, rc == PD_OK, "%s", e.msg))
        CHECK(ctx,
              a.n_yield == 1 && b.n_yield == 1 && fabs(a.xmax - b.xmax) <= 1e-14 * b.xmax &&
                  fabs(a.up - b.up) <= 1e-14 * fabs(b.up),
              "onsets %ld, %ld; xmax %.17g, %.17g; up %.17g, %.17g", a.n_yield, b.n_yield, a.xmax,
              b.xmax, a.up, b.up);
}

/* The reference refuses a slide it cannot write in closed form (an
 * overdamped one: 0 < alpha <= xi^2), naming xi and alpha; the method auto
 * runs it by Moreau-Jean.  A damped free mass (alpha = 0) and an
 * underdamped slide are the reference's. */
static void test_yield_exact_refuses_overdamped_slide(pd_test_ctx *ctx)
{
    pd_osc c = pd_osc_default(); /* xi 0.05: xi^2 = 0.0025 */
    c.Piy = 0.3;
    c.alpha = 0.002;
    pd_run_opts o = pd_run_default_opts();
    o.method = PD_METHOD_EVENT;
    pd_osc_result r;
    pd_err e;
    CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &r, &e) == PD_EINVAL && strstr(e.msg, "alpha"),
          "an overdamped slide taken: %s", e.msg);
    o = pd_run_default_opts();
    CHECK(ctx, pd_osc_method(&c, &o) == PD_METHOD_MOREAU && !pd_osc_yield_exact(&c),
          "auto chose %s", pd_method_name(pd_osc_method(&c, &o)));
    const double exact[] = {0.01, 0.0}; /* xi^2 < alpha; a damped free mass */
    for (int k = 0; k < 2; k++) {
        c.alpha = exact[k];
        CHECK(ctx, pd_osc_method(&c, &o) == PD_METHOD_EVENT && pd_osc_yield_exact(&c),
              "auto chose %s for alpha %g", pd_method_name(pd_osc_method(&c, &o)), c.alpha);
    }
}

/* `pound converge` on a yielding oscillator: Moreau-Jean's rows only (the
 * default), measured against the exact reference; the history's error
 * falls over two decades of dt by more than 100 (measured 4.4e-3, 5.2e-4,
 * 1.5e-5 of umax: order 0.9 then 1.5); the rows it cannot run are
 * refused naming --methods. */
static void test_yield_converge(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    const char *args[] = {"converge", "--Piy",         "0.5",    "--alpha", "0.05",
                          "--dt",     "0.01:0.0001:3", "--json", NULL};
    proc_out r;
    pd_test_pound(ctx, args, &r);
    double e0 = pd_test_json_num(r.out, "err_hist_linf", 0),
           e2 = pd_test_json_num(r.out, "err_hist_linf", 2);
    CHECK(ctx,
          r.status == 0 && !strstr(r.out, "moreau-rtol") &&
              !isnan(pd_test_json_num(r.out, "dt", 2)) && isnan(pd_test_json_num(r.out, "dt", 3)) &&
              e2 * 100.0 < e0,
          "exit %d: history errors %.3g to %.3g over three rows (%s)", r.status, e0, e2, r.err);
    pd_test_proc_free(&r);
    const char *bad[] = {"converge",  "--Piy",          "0.5", "--dt", "0.01:0.001:2",
                         "--methods", "moreau,penalty", NULL};
    pd_test_pound(ctx, bad, &r);
    CHECK(ctx, r.status == 2 && strstr(r.err, "--methods"), "exit %d: %s", r.status, r.err);
    pd_test_proc_free(&r);
}

/* What does not model yielding says so; bad uy and alpha are refused. */
static void test_yield_refused(pd_test_ctx *ctx)
{
    pd_osc c = pd_osc_default();
    c.Piy = 0.5;
    c.alpha = 0.002; /* an overdamped slide (xi^2 = 0.0025): not the reference's */
    pd_osc_result r;
    pd_err e;
    pd_run_opts o = pd_run_default_opts();
    CHECK(ctx,
          pd_osc_reference(&c, &o, NULL, NULL, &r, &e) == PD_EINVAL &&
              strstr(e.msg, "yielding") != NULL,
          "the event-driven reference took a yielding oscillator: %s", e.msg);
    o.method = PD_METHOD_PENALTY;
    CHECK(ctx, pd_osc_penalty(&c, &o, NULL, NULL, &r, &e) == PD_EINVAL, "penalty: %s", e.msg);
    o = pd_run_default_opts();
    o.rtol = 1e-3;
    CHECK(ctx, pd_osc_run(&c, &o, NULL, NULL, &r, &e) == PD_EINVAL && strstr(e.msg, "rtol"),
          "to a tolerance: %s", e.msg);
    o = pd_run_default_opts();
    CHECK(ctx, pd_osc_method(&c, &o) == PD_METHOD_MOREAU, "auto chose %s for a yielding spring",
          pd_method_name(pd_osc_method(&c, &o)));
    const double bad_piy[] = {-1.0, NAN}, bad_alpha[] = {-0.1, 1.5, NAN};
    for (int k = 0; k < 2; k++) {
        c.Piy = bad_piy[k];
        CHECK(ctx, pd_osc_check(&c, &e) == PD_EINVAL && strstr(e.msg, "uy"), "Piy %g: %s",
              bad_piy[k], e.msg);
    }
    c.Piy = 0.5;
    for (int k = 0; k < 3; k++) { /* with alpha out of range */
        c.alpha = bad_alpha[k];
        CHECK(ctx, pd_osc_check(&c, &e) == PD_EINVAL && strstr(e.msg, "alpha"), "alpha %g: %s",
              bad_alpha[k], e.msg);
    }
}

void suite_yield(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_yield_unreached_is_elastic);
    PD_RUN(ctx, test_yield_step_load_closed_form);
    PD_RUN(ctx, test_yield_wall_converges);
    PD_RUN(ctx, test_yield_energy_balance);
    PD_RUN(ctx, test_yield_exact_energy_balance);
    PD_RUN(ctx, test_yield_self_similar);
    PD_RUN(ctx, test_yield_sampled);
    PD_RUN(ctx, test_yield_refused);
    PD_RUN(ctx, test_yield_step_equations);
    PD_RUN(ctx, test_yield_exact_step_load);
    PD_RUN(ctx, test_yield_exact_unreached_is_elastic);
    PD_RUN(ctx, test_yield_exact_moreau_converges);
    PD_RUN(ctx, test_yield_exact_damped_plastic);
    PD_RUN(ctx, test_yield_exact_constant_sine_piece);
    PD_RUN(ctx, test_yield_exact_refuses_overdamped_slide);
    PD_RUN(ctx, test_yield_spectrum_points);
    PD_RUN(ctx, test_yield_spectrum_resume);
    PD_RUN(ctx, test_yield_converge);
}
