/* demand.h — (problems-private) the demand parameters both runners measure
 * (pd_problems.h, "demand parameters"): the absolute floor accelerations'
 * smooth part and the storey shears of a scene's state, their peaks. */
#ifndef PD_DEMAND_H
#define PD_DEMAND_H

#include <math.h>

#include "pd_problems.h"

/* The td of o: its contact_duration, or PD_CONTACT_DURATION for 0. */
double pd_demand_td(const pd_run_opts *o);

/* a_abs (a, n) [m/s^2] and the storey shears (V, n) [N], signed, of the
 * state x, v of sc's dofs given in units of us [m] and vs [m/s] (the SI
 * state is us x, vs v). */
void pd_demand_eval(const pd_scene *sc, const double *x, const double *v, double us, double vs,
                    double *a, double *V);

/* The same for structure st alone (its entries of x, v, a, V). */
void pd_demand_eval_structure(const pd_structure *st, const double *x, const double *v, double us,
                              double vs, double *a, double *V);

/* The same into the scratch a, V (n), raising the peaks acc = max |a| and
 * shear = max |V| (n). */
void pd_demand_note(const pd_scene *sc, const double *x, const double *v, double us, double vs,
                    double *a, double *V, double *acc, double *shear);

/* The largest |p| at the turning points inside (0, h) of the cubic Hermite p
 * with values f0, f1 and slopes d0, d1 at the ends of a step h (0 when it
 * has none there): a peak of a demand between two states. */
double pd_demand_cubic_peak(double f0, double d0, double f1, double d1, double h);

/* 1 when the cubic Hermite with values f0, f1 and slopes d0, d1 at the
 * ends of a step h > 0 is monotone, so that no value inside passes its
 * ends: the slopes on the secant m = (f1 - f0) / h's side with d0^2 + d1^2
 * <= 9 m^2 (Fritsch and Carlson's circle, inside the region where it is
 * monotone); 0 otherwise (it may still be).  A demand's peak between two
 * states needs pd_demand_cubic_peak only where this says 0. */
int pd_demand_cubic_monotone(double f0, double d0, double f1, double d1, double h);

/* A turning point of f inside a step of length h: when f' changes sign
 * between its ends, the root of f' on the quintic Hermite of (f, f', f'')
 * = p0 at the start and p1 at the end (Illinois steps to 1e-12 of the step); *f gets the
 * value there and the return is 1; 0 when f' keeps its sign. */
int pd_demand_quintic_turn(const double p0[3], const double p1[3], double h, double *f);

/* The oscillator's absolute acceleration in Pi units, |C x' + K x + lam|
 * (C = 2 xi Pi2, K = Pi2^2, lam the wall's held force, 0 when free: x'' = f
 * - C x' - K x - lam), its peak from tau_measure on: at each state, and
 * between two states with accelerations a (NULL: none) on the cubic
 * Hermite when the interval was smooth and free at both ends. */
typedef struct pd_demand_osc {
    double C, K, tau_measure;
    double peak;
    double shear;    /* peak |C x' + K x|: the base shear per unit mass (Pi units) */
    double f, fd, t; /* the previous state's value, rate and time */
    int prev;        /* 1: it has a rate (free: no held force) */
} pd_demand_osc;

void pd_demand_osc_note(pd_demand_osc *d, double tau, double x, double v, const double *a,
                        double lam, int smooth);

/* The peak at one state (no rate: pd_demand_osc_note with a NULL keeps
 * prev 0 beside it), inline for the scalar kernel's loop. */
static inline void pd_demand_osc_note_state(pd_demand_osc *d, double tau, double x, double v,
                                            double lam)
{
    if (tau >= d->tau_measure) {
        d->peak = pd_max(d->peak, fabs(d->C * v + d->K * x + lam));
        d->shear = pd_max(d->shear, fabs(d->C * v + d->K * x));
    }
}

/* The one-wall oscillator's held force [Pi units] after a Moreau-Jean
 * step of length h ending at (x, v) under the excitation f: a contact with
 * impulses in this step and the one before (P, Pprev), at rest after both
 * (|v|, |vprev| within PD_OSC_HELD_RATE steps' worth of the excitation's
 * unit amplitude), pushes with what holding it takes, max(0, f - C v - K x);
 * 0 otherwise.  Not P / h: theta = 1/2 alternates a hold's impulses (one
 * step's P / h is up to twice the force), and a bounce's impulses are no
 * force at all. */
#define PD_OSC_HELD_RATE 4.0
static inline double pd_demand_osc_held(const pd_demand_osc *d, double h, double P, double Pprev,
                                        double v, double vprev, double x, double f)
{
    if (!(P > 0.0 && Pprev > 0.0) || fabs(v) > PD_OSC_HELD_RATE * h ||
        fabs(vprev) > PD_OSC_HELD_RATE * h)
        return 0.0;
    return pd_max(0.0, f - d->C * v - d->K * x);
}

/* The oscillator's demands into res: acc_max, shear_max and force_max [per unit mass],
 * the td of o and the equivalent force of res->max_impulse. */
/* PD_EINVAL when a derived demand overflows while its source does not: the
 * equivalent force (contact a, -1: the oscillator's wall) or a storey's
 * drift ratio (structure name, storey from 1). */
int pd_demand_check_force(double impulse, double force, int a, pd_err *err);
int pd_demand_check_drift(double drift, double ratio, const char *name, int storey, pd_err *err);
void pd_demand_osc_finish(pd_osc_result *res, const pd_run_opts *o, double acc_max,
                          double shear_max, double force_max);

#endif
