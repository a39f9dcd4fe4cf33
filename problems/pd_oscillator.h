/* pd_oscillator.h — the pounding oscillator of SPEC §1: one damped linear
 * oscillator striking a rigid wall that moves with the ground, under
 * sine, cosine or harmonic acceleration pulses.
 *
 *   u'' + 2 xi w0 u' + w0^2 u = f(t) - lambda,   g = delta - u >= 0,
 *   f(t) = s ap sin(wp t) | s ap cos(wp t),  s = +1 normal, -1 reverse.
 *
 * The scene is integrated in the paper's dimensionless variables
 * (time tau = wp t, displacement u / Le with Le = ap / wp^2), so runs with
 * the same Pi terms and the same dt/Tp are the same discrete computation;
 * results come back in metres and seconds. */
#ifndef PD_OSCILLATOR_H
#define PD_OSCILLATOR_H

#include "pd_engine.h"

typedef enum { PD_PULSE_SINE = 0, PD_PULSE_COSINE = 1, PD_PULSE_HARMONIC = 2 } pd_pulse;

/* The physical case. */
typedef struct pd_osc {
    pd_pulse pulse;
    int dir;    /* +1 normal (wall driven toward the oscillator), -1 reverse */
    double ap;  /* pulse acceleration amplitude [m/s^2] > 0 */
    double Tp;  /* pulse period [s] > 0 */
    double Pi2; /* w0 / wp = Tp / T0 > 0 */
    double Pi3; /* delta wp^2 / ap >= 0 (the dimensionless gap) */
    double eps; /* coefficient of restitution in [0, 1] */
    double xi;  /* damping ratio in [0, 1) */
} pd_osc;

/* Names: "sine", "cosine", "harmonic"; "normal", "reverse".  The parsers
 * return 0 on success, PD_EINVAL for an unknown name. */
const char *pd_pulse_name(pd_pulse pulse);
int pd_pulse_parse(const char *name, pd_pulse *pulse);
const char *pd_dir_name(int dir);
int pd_dir_parse(const char *name, int *dir);

/* Derived quantities. */
double pd_osc_wp(const pd_osc *c);  /* 2 pi / Tp */
double pd_osc_T0(const pd_osc *c);  /* Tp / Pi2 */
double pd_osc_gap(const pd_osc *c); /* delta = Pi3 ap / wp^2 [m] */
double pd_osc_Le(const pd_osc *c);  /* ap / wp^2 [m] */

/* Effective acceleration f(t) [m/s^2] of the case at time t [s]. */
double pd_osc_excitation(const pd_osc *c, double t);

/* The same in Pi units, f / ap at tau = wp t; side -1 / +1 picks the left /
 * right limit at the pulse end tau = 2 pi. */
double pd_osc_shape(const pd_osc *c, double tau, int side);

/* Check every field; the message names the field ("eps", "gap", ...). */
int pd_osc_check(const pd_osc *c, pd_err *err);

/* How a run is made; zero fields take the documented defaults. */
typedef struct pd_osc_opts {
    double dt;          /* step [s]; 0 = min(Tp, T0) / 2000 */
    double tend;        /* end time [s]; 0 = pd_osc_default_tend */
    double theta;       /* 0 = 1/2 */
    double gamma;       /* negative = 1/2; pass 0.5 explicitly or use pd_osc_default_opts */
    int allow_unstable; /* accept theta outside [1/2, 1] */
    int no_wall;        /* run the no-wall twin instead */
    pd_kernel kernel;
    int no_accumulation; /* event-driven: do not jump accumulations of impacts */
} pd_osc_opts;

pd_osc_opts pd_osc_default_opts(void);

/* Check the case and complete opts: dt and tend defaults, their ranges. */
int pd_osc_resolve_opts(const pd_osc *c, const pd_osc_opts *in, pd_osc_opts *out, pd_err *err);
double pd_osc_default_dt(const pd_osc *c);
/* Pulses: Tp + 2 T0.  Harmonic: a transient phase (pd_osc_measure_start)
 * followed by a measuring window of max(16 Tp, 3 T0). */
double pd_osc_default_tend(const pd_osc *c);
/* Start of the window over which umax is measured: 0 for pulses; for the
 * harmonic excitation tend minus the measuring window, where the transient
 * has decayed (see docs/scheme.md). */
double pd_osc_measure_start(const pd_osc *c, double tend);

/* One recorded sample, in metres, seconds and m/s. */
typedef struct pd_osc_sample {
    long step;
    double t, u, v;
    double impulse; /* contact impulse per unit mass over the last step [m/s] */
    double gap;     /* delta - u [m] */
} pd_osc_sample;

/* Called at t = 0 and after every step; return > 0 to stop early. */
typedef int (*pd_osc_sampler)(const pd_osc_sample *s, void *ctx);

/* What a run measures. */
typedef struct pd_osc_result {
    double umax;          /* max |u| over the measuring window [m] */
    double u_toward;      /* max u (toward the wall) [m] */
    double u_away;        /* max -u (away from the wall) [m] */
    long impacts;         /* contact episodes begun (an impulse after a step without) */
    double first_impact;  /* time of the first impact [s], NAN when none; the
                             instant and speed are estimated inside the step
                             from the step's start state and acceleration */
    double first_impact_velocity; /* u' at that instant [m/s], NAN when none */
    double max_impact_velocity;   /* largest approach speed of any impact [m/s] */
    double contact_time;  /* time spent with a nonzero impulse [s] */
    double min_gap;       /* smallest gap seen [m] (negative: penetration) */
    long accumulations;   /* event-driven: accumulations jumped to rest */
    long steps;           /* steps (Moreau–Jean, penalty) or events (event-driven) */
    double dt, tend, theta, gamma;
    double cpu_s;
    const char *kernel;   /* "scalar" or "general" */
} pd_osc_result;

/* Run the case with Moreau–Jean; sampler may be NULL. */
int pd_osc_simulate(const pd_osc *c, const pd_osc_opts *opts, pd_osc_sampler sampler,
                    void *ctx, pd_osc_result *res, pd_err *err);

/* ---- other methods on the same case ------------------------------------ */

/* Event-driven reference (pd_ed_sdof_run): exact between events, so its
 * umax is the continuous maximum to rounding.  opts->dt is only the
 * sampling interval of sampler; theta/gamma/kernel are ignored; res->steps
 * counts events, res->min_gap is 0, res->kernel is "event". */
int pd_osc_reference(const pd_osc *c, const pd_osc_opts *opts, pd_osc_sampler sampler, void *ctx,
                     pd_osc_result *res, pd_err *err);

/* Penalty baseline (problems/osc_penalty.c): the same case with a contact
 * element (see pd_penalty_run).  kc_mult > 0 sets the stiffness as a
 * multiple of w0^2 (Hertz: the force at a penetration of Le equals
 * kc_mult w0^2 Le); kc_abs > 0 instead gives it in N/m per kg (N/m^1.5 per
 * kg for Hertz).
 * Steps, extremes and impacts are measured on the accepted steps; the
 * sampler (if any) is called every opts->dt.  res->steps counts accepted
 * steps, res->kernel names the stepper. */
typedef struct pd_osc_penalty_opts {
    pd_penalty_law law;
    double kc_mult;      /* stiffness as a multiple of w0^2 (default 1e4) */
    double kc_abs;       /* or absolute, N/m per kg (overrides kc_mult when > 0) */
    double rtol, atol;   /* 0 = defaults */
    const char *stepper; /* NULL = "rk8pd" */
} pd_osc_penalty_opts;

int pd_osc_penalty(const pd_osc *c, const pd_osc_opts *opts, const pd_osc_penalty_opts *popts,
                   pd_osc_sampler sampler, void *ctx, pd_osc_result *res, pd_err *err);

/* Exact response without the wall from rest (closed form), at t [s]. */
void pd_osc_free_exact(const pd_osc *c, double t, double *u, double *v);

/* First time t <= tmax at which that free response reaches the gap, found
 * on a grid of Tp/1000 and bisected to rounding, with the speed there:
 * PD_OK, or PD_EINVAL when it does not reach the gap by tmax. */
int pd_osc_free_first_contact(const pd_osc *c, double tmax, double *t, double *v);

#endif
