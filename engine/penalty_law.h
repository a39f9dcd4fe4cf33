/* penalty_law.h — (internal) the penalty baseline's contact elements, shared
 * by the adaptive integrator (penalty.c) and the fixed-step Newmark scheme
 * (penalty_newmark.c); penetration d = -g > 0, its rate d' = -W^T v:
 *   Kelvin-Voigt (Anagnostopoulos):   lambda = kc d + c d',
 *       c = 2 zeta sqrt(kc m),  zeta = -ln e / sqrt(pi^2 + ln^2 e),  m = 1 / (W^T M^-1 W)
 *   Hertz-damp (Muthukumar-DesRoches): lambda = d^1.5 (kc + c d'),
 *       c = 3 kc (1 - e^2) / (4 v),  v the approach speed when the element engages. */
#ifndef PD_PENALTY_LAW_H
#define PD_PENALTY_LAW_H

#include <math.h>

#include "pd_engine.h"

/* Anagnostopoulos: zeta = -ln e / sqrt(pi^2 + ln^2 e); zeta(0) = 1 (the limit). */
static inline double pd_kelvin_zeta(double e)
{
    if (e <= 0.0)
        return 1.0; /* -ln e -> inf: critical damping */
    double l = log(e);
    return -l / sqrt(PD_PI * PD_PI + l * l);
}

/* The Kelvin-Voigt damping constant of a contact of effective mass m_eff. */
static inline double pd_kelvin_damping(double kc, double e, double m_eff)
{
    return 2.0 * pd_kelvin_zeta(e) * sqrt(kc * m_eff); /* c = 2 zeta sqrt(kc m) */
}

/* The Hertz-damp damping constant for the approach speed vimp, floored at
 * vfloor and at 1e-3 of the largest approach speed seen (a grazing contact
 * must not get an unbounded constant). */
static inline double pd_hertz_damping(double kc, double e, double vimp, double vfloor, double vseen)
{
    /* 3 kc (1 - e^2) / (4 v) */
    return 0.75 * kc * (1.0 - e * e) / fmax(vimp, fmax(vfloor, 1e-3 * vseen));
}

/* The element force: KV kc d + c d'; Hertz-damp d^1.5 (kc + c d'), 0 for d <= 0. */
static inline double pd_penalty_force(pd_penalty_law law, double kc, double c, double d, double dd)
{
    /* Kelvin-Voigt acts on both sides of d = 0 (the engaged set decides where);
     * Hertz-damp's d^1.5 is 0 for d <= 0 */
    if (law == PD_PENALTY_KELVIN)
        return kc * d + c * dd;
    if (d <= 0.0)
        return 0.0;
    return d * sqrt(d) * (kc + c * dd);
}

/* d lambda / d d and d lambda / d d' of an engaged element. */
static inline void pd_penalty_slopes(pd_penalty_law law, double kc, double c, double d, double dd,
                                     double *kd, double *cdd)
{
    if (law == PD_PENALTY_KELVIN) {
        *kd = kc;
        *cdd = c;
        return;
    }
    /* d/dd [d^1.5 (kc + c d')] = 1.5 d^0.5 (kc + c d'), d/dd' = c d^1.5 */
    double sd = d > 0.0 ? sqrt(d) : 0.0;
    *kd = 1.5 * sd * (kc + c * dd);
    *cdd = c * d * sd;
}

/* The options both integrations take, in range (the law, kc, h_out,
 * max_steps, time_unit, t0 <= t1); messages start with who (penalty.c). */
int pd_penalty_check_opts(const pd_penalty_opts *o, double t0, double t1, const char *who,
                          pd_err *err);

/* The fixed-step Newmark integration of the elements (penalty_newmark.c):
 * pd_penalty_run with stepper "newmark" (opts->h the step). */
int pd_penalty_newmark(const pd_model *model, double t0, const double *q0, const double *v0,
                       double t1, const pd_penalty_opts *opts, pd_observer observer, void *ctx,
                       pd_penalty_result *res, pd_err *err);

#endif
