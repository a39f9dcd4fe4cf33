/* osc_priv.h — (problems-private) what the oscillator's runs (oscillator.c, osc_penalty.c,
 * osc_adapt.c) share, and the engine options the scenes' runs take too. */
#ifndef PD_OSC_PRIV_H
#define PD_OSC_PRIV_H

#include <math.h>

#include "pd_problems.h"

/* pd_shape_cut's and pd_pulse_shape's texts (excitation.c), inline for the loop of the single
 * Moreau-Jean run (oscillator.c): s phi(tau), 0 past the pulse's end on
 * the requested side. */
static inline double pd_shape_cut_inline(double end, int side)
{
    return end * (1.0 + (side < 0 ? 1e-12 : -1e-12));
}

static inline double pd_pulse_shape_inline(pd_pulse pulse, int dir, double tau, int side)
{
    if (pulse != PD_PULSE_HARMONIC) {
        double cut = pd_shape_cut_inline(PD_TWO_PI, side);
        if (side < 0 ? tau > cut : tau >= cut)
            return 0.0;
    }
    return dir * (pulse == PD_PULSE_COSINE ? cos(tau) : sin(tau));
}

/* The fields of a run to a tolerance, for a run without one: rtol 0,
 * err_est NAN, rtol_met 1, no rejections, dt_min = dt_max = step (NAN
 * for the methods without steps of their own to report). */
static inline void pd_osc_result_no_rtol(pd_osc_result *res, double step)
{
    res->rtol = 0.0;
    res->err_est = NAN;
    res->rtol_met = 1;
    res->steps_rejected = 0;
    res->dt_min = res->dt_max = step;
}

/* The balance's residual: (input + the energies at the start - every
 * other term) / input. */
static inline void pd_energy_close(pd_energy *en, double start)
{
    en->residual =
        (en->input + start - en->kinetic - en->strain - en->damping - en->hysteretic - en->impact) /
        en->input;
}

/* An energy balance not measured: NAN throughout. */
static inline pd_energy pd_energy_none(void)
{
    return (pd_energy){.input = NAN,
                       .kinetic = NAN,
                       .strain = NAN,
                       .damping = NAN,
                       .hysteretic = NAN,
                       .impact = NAN,
                       .residual = NAN};
}

/* The yielding fields of an elastic run: NAN, no onsets. */
static inline void pd_osc_result_no_yield(pd_osc_result *res)
{
    res->ductility = res->residual = res->plastic_excursion = res->hysteretic_energy = NAN;
    res->n_yield = 0;
    res->energy = pd_energy_none();
}

/* A yielding run's figures from its offset at the end, its excursion and
 * the slider's work (Pi units: lengths times Le, energies per unit mass
 * times (Le wp)^2), every method's (oscillator.c). */
void pd_osc_yield_figures(const pd_osc *c, double up, double excursion, double work, long n_yield,
                          pd_osc_result *res);

/* PD_EINVAL for a yielding oscillator in a run that does not model
 * yielding (what: its name), else PD_OK. */
static inline int pd_osc_refuse_yield(const pd_osc *c, const char *what, pd_err *err)
{
    if (!pd_osc_yields(c))
        return PD_OK;
    return pd_err_set(err, PD_EINVAL,
                      "%s does not model yielding yet (uy, alpha < 1): a yielding oscillator "
                      "runs by Moreau-Jean (method moreau), newmark or the exact reference",
                      what);
}

/* F = s phi(tau) (or the record's): the oscillator model's force callback. */
static inline void pd_osc_model_force(double tau, int side, double *F, void *ctx)
{
    F[0] = pd_osc_shape(ctx, tau, side);
}

/* The coefficients a pd_osc_model points at (they outlive the model). */
typedef struct pd_osc_coefs {
    double M, C, K, W, g0, e;
} pd_osc_coefs;

/* The oscillator's model in Pi units: M = 1, C = 2 xi Pi2, K = Pi2^2, one
 * wall at gap Pi3 (W = -1; none with no_wall), the force pd_osc_shape with
 * the breakpoints given; its coefficients in k. */
static inline pd_model pd_osc_model(const pd_osc *c, int no_wall, pd_osc_coefs *k,
                                    const double *breaks, int nbreaks)
{
    *k = (pd_osc_coefs){.M = 1.0,
                        .C = 2.0 * c->xi * c->Pi2,
                        .K = c->Pi2 * c->Pi2,
                        .W = -1.0,
                        .g0 = c->Pi3,
                        .e = c->eps};
    return (pd_model){.n = 1,
                      .m = no_wall ? 0 : 1,
                      .M = pd_matrix_dense(1, 1, &k->M),
                      .C = pd_matrix_dense(1, 1, &k->C),
                      .K = pd_matrix_dense(1, 1, &k->K),
                      .W = pd_matrix_dense(1, 1, &k->W),
                      .g0 = &k->g0,
                      .e = &k->e,
                      .force = pd_osc_model_force,
                      .force_ctx = (void *)c,
                      .breaks = breaks,
                      .nbreaks = nbreaks};
}

/* The engine's options of a run's (Moreau-Jean): the step h, the scheme's
 * and the solvers' settings of o. */
static inline pd_mj_opts pd_run_mj_opts(const pd_run_opts *o, double h)
{
    pd_mj_opts mo = pd_mj_default_opts();
    mo.h = h;
    mo.theta = o->theta;
    mo.gamma = o->gamma;
    mo.allow_unstable = o->allow_unstable;
    mo.kernel = o->kernel;
    mo.factor = o->factor;
    mo.lcp_solver = o->lcp_solver;
    mo.on_lcp = o->on_lcp;
    mo.on_lcp_ctx = o->on_lcp_ctx;
    return mo;
}

/* Moreau-Jean to a tolerance (osc_adapt.c): o resolved, rtol > 0. */
int pd_osc_adapt(const pd_osc *c, const pd_run_opts *o, pd_osc_sampler sampler, void *ctx,
                 pd_osc_result *res, pd_err *err);

/* Steps of the Newmark penalty method per period of its stiffest contact
 * element, at least: its step is the output step dt, or dt / k for the
 * smallest whole k that gives this many (coarser steps pump energy into the
 * elements: docs/methods.md, "Penalty baseline": a chain of 3 at kc 1e8
 * blows up at 0.7 steps per period and agrees with the adaptive penalty at
 * 3.5). */
#define PD_NEWMARK_STEPS_PER_CONTACT 10.0

/* dt / k, the Newmark step for the output step dt and the element period Tc. */
double pd_newmark_step(double dt, double Tc);
/* Newmark's steps of h over tau_end within po's budget, up front: PD_OK, or
 * PD_EINVAL naming the flag that made them too many (kc when h is a
 * fraction of the grid's step dt, else dt). */
int pd_newmark_budget(const pd_penalty_opts *po, double dt, double tau_end, pd_err *err);

/* The contact element's stiffness in Pi units (osc_penalty.c's file comment). */
double pd_osc_penalty_kc(const pd_osc *c, const pd_penalty_setup *po);

#endif
