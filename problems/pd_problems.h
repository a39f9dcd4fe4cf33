/* pd_problems.h — the scenes pound models and how they are run: the
 * excitations, the one-wall pounding oscillator of SPEC §1 (the paper's
 * problem, with its exact reference and fast kernels), rows of structures
 * that pound each other and their abutments (SPEC §4), the run request and
 * method dispatch (Moreau–Jean, event-driven, penalty), measurements (maxima
 * per dof, impacts per contact, the Pi terms, gamma and chi), errors against
 * a reference, and spectrum sweeps.
 *
 * Everything here is in metres, seconds and kilograms at the interface;
 * inside, scenes are integrated in the paper's dimensionless variables
 * (time tau = wp t, displacement u / Le, Le = ap / wp^2), so that runs with
 * the same Pi terms are the same discrete computation.
 *
 * Options structs come from their _default_opts() function; their fields
 * hold values, except dt and tend where 0 means "derived from the case". */
#ifndef PD_PROBLEMS_H
#define PD_PROBLEMS_H

#include "pd_engine.h"

/* ==== excitations ========================================================== */

typedef enum { PD_PULSE_SINE = 0, PD_PULSE_COSINE = 1, PD_PULSE_HARMONIC = 2 } pd_pulse;

/* "sine", "cosine", "harmonic"; "normal" (+1), "reverse" (-1).  The parsers
 * return PD_OK, or PD_EINVAL for an unknown name. */
PD_API const char *pd_pulse_name(pd_pulse pulse);
PD_API int pd_pulse_parse(const char *name, pd_pulse *pulse);
PD_API const char *pd_dir_name(int dir);
PD_API int pd_dir_parse(const char *name, int *dir);

/* The effective acceleration in units of ap at tau = wp t: s phi(tau), phi =
 * sin or cos on [0, 2 pi] and zero after (sin for all tau: harmonic), and
 * its tau-derivative.  side -1 / +1 picks the left / right limit at the
 * pulse end tau = 2 pi (recognised to a relative 1e-12, so that tau = k h
 * lands on the same side at every scale). */
PD_API double pd_pulse_shape(pd_pulse pulse, int dir, double tau, int side);
PD_API double pd_pulse_shape_rate(pd_pulse pulse, int dir, double tau, int side);

/* ==== strong-motion records (SPEC §5, docs/records.md) ====================== *
 * A record is the ground acceleration ug''(t) sampled every dt, linear
 * between samples and zero after the last.  Readers: PEER NGA .AT2 (both
 * header spellings, CR CR LF line ends, numbers that touch), COSMOS/CDMG V2
 * (the first channel's acceleration block, units and dt from its header)
 * and two-column text "t a" ('#' comments; t uniform to 1 % of a step,
 * shifted so that the first sample is at t = 0; units given).  Every
 * reader error is PD_EPARSE with "FILE:LINE: what was expected"; an
 * unreadable file PD_EIO.  At most 10^8 samples, files of at most 1 GiB
 * (binary data, a NUL byte, is refused where it is read). */

/* The sampling intervals a record may have [s].  Strong-motion records are
 * sampled every 0.005 to 0.02 s (1e-3 s at the most, 0.05 s for old
 * digitisations); 1e-6 s (1 MHz) and 10 s bound them by far, and keep
 * everything derived finite and exact: the duration (npts - 1) dt is at
 * most 10^9 s, sample times k dt and indices t / dt stay far inside the
 * doubles' exact integers.  A DT outside (1e308, 1e-300, a denormal) is a
 * broken header, refused by the readers with its FILE:LINE. */
#define PD_RECORD_DT_MIN 1e-6
#define PD_RECORD_DT_MAX 10.0

typedef enum {
    PD_RECORD_AUTO = 0, /* by content (an AT2 or V2 header), else two-column text */
    PD_RECORD_AT2 = 1,
    PD_RECORD_V2 = 2,
    PD_RECORD_TEXT = 3
} pd_record_format;

/* Units of a two-column text file's accelerations. */
typedef enum { PD_UNITS_G = 0, PD_UNITS_M_S2 = 1, PD_UNITS_CM_S2 = 2 } pd_record_units;

/* "auto", "at2", "v2", "text"; "g", "m/s2", "cm/s2"; parse: PD_OK or PD_EINVAL. */
PD_API const char *pd_record_format_name(pd_record_format f);
PD_API int pd_record_format_parse(const char *name, pd_record_format *f);
PD_API const char *pd_record_units_name(pd_record_units u);
PD_API int pd_record_units_parse(const char *name, pd_record_units *u);

/* Standard gravity used to convert records given in g (PD_G_STANDARD). */
typedef struct pd_record {
    char name[256]; /* the file's name without its folders */
    long npts;      /* samples >= 2 */
    double dt;      /* sample step [s] > 0 */
    double *acc;    /* npts ground accelerations [m/s^2] at t_k = k dt (malloc'd) */
} pd_record;

/* Read a record; units apply to text files only (AT2 is in g, V2 says).
 * On error rec is left empty (acc NULL, npts 0). */
PD_API int pd_record_read(const char *path, pd_record_format format, pd_record_units units,
                          pd_record *rec, pd_err *err);
PD_API void pd_record_free(pd_record *rec);
/* The format pd_record_read would read path as (PD_RECORD_AUTO's
 * detection: an AT2 or V2 header, else the file name's extension, else
 * text). */
PD_API int pd_record_detect(const char *path, pd_record_format *format, pd_err *err);
/* Whether the record's peak ground acceleration is plausible in the units
 * it was read in (1e-4 g to 5 g): 1 if so; 0 with a warning in msg (up to
 * cap bytes; msg may be NULL) naming the units that would make it
 * plausible; 0 for a NULL or empty record. */
PD_API int pd_record_plausible(const pd_record *rec, pd_record_units units, char *msg, size_t cap);
/* A record from npts >= 2 accelerations acc[k] at t_k = k dt, in units
 * (converted to m/s^2 as the readers do: the same values give the same
 * record bit for bit), named name (NULL: "array").  acc is copied (rec owns
 * it: pd_record_free); every value must be finite, dt in
 * [PD_RECORD_DT_MIN, PD_RECORD_DT_MAX]; on error rec is left empty. */
PD_API int pd_record_from_array(pd_record *rec, const char *name, const double *acc, long npts,
                                double dt, pd_record_units units, pd_err *err);
/* The record's duration (npts - 1) dt [s]. */
PD_API double pd_record_duration(const pd_record *rec);
/* ug''(t) [m/s^2]: linear between samples, 0 before 0 and after the last
 * (whose time is recognised to a relative 1e-12). */
PD_API double pd_record_acc(const pd_record *rec, double t);

/* Ground-motion measures.  Velocity and displacement are the exact
 * integrals of the piecewise-linear acceleration from rest, with no
 * baseline correction (docs/records.md: processed records are corrected
 * by their agencies; the measures describe the motion the structures are
 * driven by); peaks are exact, also inside a step.  Arias intensity
 *   Ia = pi / (2 g) integral a^2 dt   (g = PD_G_STANDARD; the integral exact
 * for the piecewise-linear a), significant durations T5-75 and T5-95 from
 * the normalised Husid curve (times solved inside their step). */
typedef struct pd_record_measures {
    double pga, pgv, pgd;       /* max |a| [m/s^2], |v| [m/s], |d| [m] */
    double t_pga, t_pgv, t_pgd; /* their times [s] */
    double arias;               /* [m/s] */
    double t5_75, t5_95;        /* [s] */
} pd_record_measures;

PD_API int pd_record_measure(const pd_record *rec, pd_record_measures *m, pd_err *err);

/* The record's ground velocity and displacement at the samples (n = npts
 * each, caller's arrays), as the measures use them. */
PD_API int pd_record_integrate(const pd_record *rec, double *vel, double *disp, pd_err *err);

/* The Mavroeidis–Papageorgiou (2003) velocity pulse fitted to the record's
 * velocity by GSL's nonlinear least squares:
 *   v(t) = vp/2 [1 + cos(2 pi fp (t - t0) / gamma)] cos(2 pi fp (t - t0) + nu)
 * for |t - t0| <= gamma / (2 fp), 0 elsewhere; Tp = 1 / fp; ap = the
 * largest |v'| of the fitted pulse; wp = 2 pi / Tp; Le = ap / wp^2.  Also
 * the paper's one-cycle acceleration pulse (Fig. 2): sine or cosine shape,
 * amplitude ap, period Tp, starting at t_start, with the sign polarity, so
 * that ug''(t) ~ ap pd_pulse_shape(shape, polarity, wp (t - t_start), 1)
 * (the one closest in least squares to the record's acceleration).  The
 * fit window is the PGV time -/+ 2 initial periods (twice the time between
 * the velocity's zero crossings around the PGV); of twelve starts (nu in
 * {0, +-pi/2, pi}, gamma in {1.5, 2, 3}; 1 < gamma < 4 enforced) the best
 * r2 is kept.  PD_ENUMERICAL when no pulse is found (r2 <= 0, the pulse
 * centred outside the record or longer than it), PD_EINVAL for a record
 * of fewer than 2 samples. */
typedef struct pd_record_pulse {
    double vp, fp, nu, gamma, t0; /* the fitted parameters [m/s, Hz, rad, 1, s] */
    double Tp, ap, wp, Le;        /* [s, m/s^2, rad/s, m] */
    double r2;                    /* 1 - SSE / SST of the fit over its window */
    long iterations;              /* of the solver */
    pd_pulse shape;               /* PD_PULSE_SINE or PD_PULSE_COSINE */
    int polarity;                 /* +1 or -1: the sign of that pulse in ug'' */
    double t_start;               /* start of the one-cycle pulse [s] */
} pd_record_pulse;

PD_API int pd_record_fit_pulse(const pd_record *rec, pd_record_pulse *p, pd_err *err);

/* The fitted pulse as a function of time (record_pulse.c): the
 * Mavroeidis–Papageorgiou velocity v(t) and acceleration a(t) = v'(t), and
 * the paper's one-cycle acceleration pulse of amplitude ap and period Tp
 * from t_start, signed as the record's acceleration there. */
PD_API void pd_record_pulse_eval(const pd_record_pulse *p, double t, double *acc, double *vel);
PD_API double pd_record_one_cycle(const pd_record_pulse *p, double t);

/* ==== how a run is made ====================================================== */

/* PD_METHOD_AUTO, the default, is the exact event-driven reference for
 * the one-wall oscillator (pulses and records) when its scan fits its
 * budget (PD_OSC_MAX_SCAN), Moreau-Jean otherwise and for scenes: the
 * resolution of the options (pd_osc_resolve_opts, pd_scene_resolve_opts,
 * pd_spec_resolve_method) makes it one of the three. */
typedef enum {
    PD_METHOD_MOREAU = 0,
    PD_METHOD_EVENT = 1,
    PD_METHOD_PENALTY = 2,
    PD_METHOD_AUTO = 3,
    PD_METHOD_EVENT_GENERAL = 4, /* scenes: the GSL-based general reference (pd_edg_run) */
    PD_METHOD_NEWMARK = 5        /* the penalty elements on fixed steps dt of the implicit
                             average-acceleration Newmark scheme with Newton iterations
                             (pd_penalty_run's stepper "newmark"): what OpenSees users run */
} pd_method;

/* "moreau", "event", "penalty", "auto", "event-general", "newmark"; parse:
 * PD_OK or PD_EINVAL. */
PD_API const char *pd_method_name(pd_method method);
PD_API int pd_method_parse(const char *name, pd_method *method);

/* The row reference's impact laws (pd_impact_law, pd_engine.h): "staged",
 * "single"; parse: PD_OK or PD_EINVAL. */
PD_API const char *pd_impact_law_name(pd_impact_law law);
PD_API int pd_impact_law_parse(const char *name, pd_impact_law *law);

/* The penalty baseline's contact elements (see pd_penalty_run). */
typedef struct pd_penalty_setup {
    pd_penalty_law law;
    double kc_mult;      /* stiffness as a multiple of the structure's: w0^2 per unit mass for
                            the oscillator, the largest storey stiffness for a scene (> 0) */
    double kc_abs;       /* > 0: the stiffness itself (oscillator: N/m per kg; scene: N/m;
                            N/m^1.5 for Hertz), overriding kc_mult; 0: use kc_mult */
    double rtol, atol;   /* GSL tolerances > 0 */
    const char *stepper; /* "rk8pd", "rkf45", "rk4imp", "msbdf" */
} pd_penalty_setup;

/* The most time steps a run may take (tend / dt): beyond, the run is
 * refused as bad input rather than left to run for hours. */
#define PD_MAX_STEPS 2e9

/* How far a run has come: fraction in [0, 1]. */
typedef void (*pd_progress_fn)(double fraction, void *ctx);

/* The run request of every command and sweep. */
typedef struct pd_run_opts {
    pd_method method;
    double dt;          /* step (Moreau–Jean) or output interval [s]; 0 = derived */
    double tend;        /* end time [s]; 0 = derived */
    double theta;       /* Moreau–Jean theta in [1/2, 1] */
    double gamma;       /* active-set look-ahead in [0, 1] */
    int allow_unstable; /* accept theta outside [1/2, 1] */
    pd_kernel kernel;   /* PD_KERNEL_GENERAL: no fast path (scalar kernel, exact reference) */
    pd_factor_kind factor;
    pd_lcp_method lcp_solver;
    int no_accumulation; /* event-driven: do not jump accumulations of impacts */
    int no_wall;         /* without contacts: the oscillator's no-wall twin, a free scene */
    pd_penalty_setup pen;
    pd_lcp_observer on_lcp; /* Moreau–Jean's general kernel: every contact LCP solved */
    void *on_lcp_ctx;
    double close_tol;         /* event-driven rows: at an impact, contacts whose gap is within
                           close_tol Le are closed too (simultaneous); >= 0 */
    pd_impact_law impact_law; /* event-driven rows: the impact law of several closed
                                 contacts (PD_IMPACT_STAGED, PD_IMPACT_SINGLE) */
    int no_law_band;          /* 1: no second run under the other impact law (law_band NAN):
                           the sweeps and the timed re-runs */
    double contact_duration;  /* td [s] of the equivalent contact force pi I / (2 td) of an
                                impact of impulse I (a half-sine pulse); 0 = PD_CONTACT_DURATION */
    int no_demands;           /* 1: do not measure the peak accelerations and shears (NAN): the
                           sweeps, the contact-free twins and the timed re-runs, whose
                           figures do not use them (the exact references sample a grid
                           for them); nor the exact reference's energy balance of a
                           yielding run (its quadrature: 2.5x the run) */
    double rtol;              /* > 0: Moreau-Jean to this relative tolerance of every reported
                           peak (docs/scheme.md, "Moreau–Jean to a tolerance"; then dt must
                           be 0, the method moreau or auto, which it makes moreau); 0:
                           fixed steps dt */
    /* Told how far a scene's run has come (fraction of tend in [0, 1]) at
     * every hundredth of it, by the methods that visit its steps or events
     * (Moreau-Jean, to a tolerance, the exact row reference); NULL: not
     * told.  The caller's (a command line's progress line); its return is
     * ignored. */
    pd_progress_fn progress;
    void *progress_ctx;
} pd_run_opts;

/* The tightest tolerance a run to a tolerance takes (below, rounding rules). */
#define PD_RTOL_MIN 1e-12

/* ---- demand parameters (docs/scenes.md, "Demands") ------------------------ *
 * What earthquake engineers read off a run, per storey and per contact:
 *   absolute floor acceleration a_abs = u'' + a_g = M^-1 (W lambda - C u' - K u): the
 *     held (persistent) contacts' finite forces lambda in it, the impacts' impulses
 *     (Dirac pulses, reported as such) not; the penalty methods: the smooth part;
 *   storey shear V_k = sum over the floors i >= k of (C u' + K u)_i:
 *     spring plus damping (with Rayleigh's mass-proportional part of the floors above),
 *     so that the base shear V_1 balances the floors' inertia forces; an SDOF: k u + c u';
 *   drift ratio = peak interstorey drift / storey height;
 *   equivalent contact force of an impulse I over a half-sine pulse of duration td:
 *     F = pi I / (2 td); the actual peak contact force where a compliant method ran. */
#define PD_CONTACT_DURATION 0.005 /* default td [s] */
#define PD_STOREY_HEIGHT 3.0      /* default storey height [m] */

/* pi I / (2 td): the peak of a half-sine force pulse of impulse I and duration td. */
PD_API double pd_equivalent_force(double impulse, double td);

/* The default closing tolerance of the event-driven reference for rows
 * [in Le]: gaps within it at an impact take part in it.  The same scale
 * below which the reference already treats a contact as closed when it
 * jumps an accumulation (bounce heights under 1e-10 Le): one "in contact"
 * scale for both decisions (docs/methods.md measures what it moves). */
#define PD_CLOSE_TOL 1e-10

/* The automatic method (PD_METHOD_AUTO: exact for one oscillator,
 * Moreau-Jean for scenes), dt and tend derived, theta = gamma = 1/2 for
 * Moreau-Jean with its automatic kernel,
 * factor and LCP solver, accumulations jumped, Kelvin-Voigt with the
 * derived stiffness (kc_mult = 0: the oscillator's resolves the gap,
 * docs/methods.md; scenes 1e4 w0^2), rtol 1e-10, atol 1e-12, rk8pd. */
PD_API pd_run_opts pd_run_default_opts(void);

/* Ranges of the scheme options, each message naming the option. */
PD_API int pd_run_opts_check(const pd_run_opts *o, pd_err *err);

/* ==== the pounding oscillator (SPEC §1) ===================================== *
 *   u'' + 2 xi w0 u' + w0^2 u = f(t) - lambda,   g = delta - u >= 0,
 *   f(t) = s ap phi(wp t),  s = +1 normal, -1 reverse.                        */

typedef struct pd_osc {
    pd_pulse pulse;
    int dir;    /* +1 normal (wall driven toward the oscillator), -1 reverse */
    double ap;  /* pulse acceleration amplitude [m/s^2] > 0 */
    double Tp;  /* pulse period [s] > 0 */
    double Pi2; /* w0 / wp = Tp / T0 > 0 */
    double Pi3; /* delta wp^2 / ap >= 0 (the dimensionless gap) */
    double eps; /* coefficient of restitution in [0, 1] */
    double xi;  /* damping ratio in [0, 1) */
    /* a record instead of the pulse (pd_osc_set_record; NULL: the pulse):
     * f(t) = -dir scale ug''(t), ap = scale rec_ap and Tp from its fitted pulse */
    const pd_record *record;
    double rec_ap; /* the fitted pulse's ap at scale 1 [m/s^2] */
    double scale;  /* the record's scale S > 0 */
    /* a yielding spring (SPEC §7): restoring force per unit mass w0^2 [alpha u +
     * (1 - alpha) z], |z| <= uy, z' = u' inside and while unloading */
    double Piy;   /* uy wp^2 / ap > 0, the dimensionless yield displacement; 0 (a
                     zeroed struct's) or INFINITY: elastic */
    double alpha; /* the post-yield stiffness ratio in [0, 1] (1: elastic) */
} pd_osc;

/* sine, normal, ap = 1, Tp = 1, Pi2 = 1, Pi3 = 0.05, eps = 0.5, xi = 0.05,
 * elastic (Piy = 0, alpha = 0). */
PD_API pd_osc pd_osc_default(void);

/* Derived quantities. */
PD_API double pd_osc_wp(const pd_osc *c);  /* 2 pi / Tp */
PD_API double pd_osc_T0(const pd_osc *c);  /* Tp / Pi2 */
PD_API double pd_osc_gap(const pd_osc *c); /* delta = Pi3 ap / wp^2 [m] */
PD_API double pd_osc_Le(const pd_osc *c);  /* ap / wp^2 [m] */

/* The dimensional forms: Pi2 = Tp / T0, Pi3 = gap / Le, Piy = uy / Le (ap,
 * Tp set first). */
PD_API void pd_osc_set_T0(pd_osc *c, double T0);
PD_API void pd_osc_set_gap(pd_osc *c, double gap);
PD_API void pd_osc_set_uy(pd_osc *c, double uy);
PD_API double pd_osc_uy(const pd_osc *c); /* Piy Le [m]; INFINITY when elastic */
/* 1 when the spring can yield: Piy > 0 finite and alpha < 1. */
PD_API int pd_osc_yields(const pd_osc *c);
/* 1 when the exact event-driven reference models c's yielding spring: its
 * sliding phase underdamped, xi < sqrt(alpha), or a free mass (alpha = 0,
 * damped or not), or undamped (xi = 0); 0 when it does not yield or only
 * Moreau-Jean can run it (an overdamped slide: 0 < alpha <= xi^2). */
PD_API int pd_osc_yield_exact(const pd_osc *c);

/* Effective acceleration f(t) [m/s^2] at time t [s]. */
PD_API double pd_osc_excitation(const pd_osc *c, double t);

/* Excite c by a record scaled by S (SPEC §5): Tp and ap = S p->ap from its
 * fitted pulse p, so that the Pi terms are the pulse's; dir keeps its
 * meaning (normal: f = -S ug''). */
PD_API void pd_osc_set_record(pd_osc *c, const pd_record *rec, const pd_record_pulse *p,
                              double scale);

/* The effective acceleration in units of ap at tau = wp t (the pulse's
 * s phi(tau) or the record's -dir ug''(t) / rec_ap), with its tau-rate;
 * side -1 / +1: left / right limit at a jump (the pulse's or the record's
 * end).  The end of the excitation in tau (HUGE_VAL: harmonic). */
PD_API double pd_osc_shape(const pd_osc *c, double tau, int side);
PD_API double pd_osc_shape_rate(const pd_osc *c, double tau, int side);
PD_API double pd_osc_shape_end(const pd_osc *c);
/* The excitation ends at `end` to a relative 1e-12: the shape's left limit
 * (side -1) is 0 past end (1 + 1e-12), its right limit (+1) from end
 * (1 - 1e-12) on. */
PD_API double pd_shape_cut(double end, int side);

/* The excitation as forcing pieces in Pi units (f = pd_osc_shape): a
 * pulse's s sin(tau + phi) on [0, 2 pi] then zero (harmonic: one piece for
 * all tau), a record's linear pieces then zero; *pieces malloc'd (free()). */
PD_API int pd_osc_pieces(const pd_osc *c, pd_sine_piece **pieces, int *npieces, pd_err *err);

/* The name of the excitation: the pulse's, or the record's file name. */
PD_API const char *pd_osc_excitation_name(const pd_osc *c);

/* Check every field; the message names the field ("eps", "gap", ...). */
PD_API int pd_osc_check(const pd_osc *c, pd_err *err);

/* Check the case and the options and complete dt and tend (in NULL: the
 * defaults). */
PD_API int pd_osc_resolve_opts(const pd_osc *c, const pd_run_opts *in, pd_run_opts *out,
                               pd_err *err);
PD_API double pd_osc_default_dt(const pd_osc *c); /* min(Tp, T0) / 2000 */
/* Pulses: Tp + 2 T0.  Harmonic: a transient phase followed by a measuring
 * window of max(16 Tp, 3 T0) (docs/scheme.md). */
PD_API double pd_osc_default_tend(const pd_osc *c);
/* Start of the window over which umax is measured (0 for pulses). */
PD_API double pd_osc_measure_start(const pd_osc *c, double tend);

/* One recorded sample, in metres, seconds and m/s. */
typedef struct pd_osc_sample {
    long step;
    double t, u, v;
    double impulse; /* contact impulse per unit mass since the last sample [m/s] */
    double gap;     /* delta - u [m] */
    long impacts;   /* impacts begun since the last sample (over the run they sum to
                       pd_osc_result.impacts; each method's count) */
    double up;      /* a yielding spring's plastic offset [m] (0: elastic); its force per
                       unit mass is w0^2 (u - (1 - alpha) up) */
} pd_osc_sample;

/* Called at t = 0 and after every step (or output); return > 0 to stop. */
typedef int (*pd_osc_sampler)(const pd_osc_sample *s, void *ctx);

/* A run's energy balance per unit mass [J/kg]: the input work equals the
 * kinetic and strain energy at the end plus what damping, the slider and
 * the impacts took; residual is what is left, a fraction of the input
 * (Moreau-Jean with theta = 1/2 closes it to rounding; theta > 1/2 leaves
 * its numerical damping there). */
typedef struct pd_energy {
    double input;      /* int f u' dt */
    double kinetic;    /* u'^2 / 2 at the end */
    double strain;     /* w0^2 (alpha u^2 + (1 - alpha) z^2) / 2 at the end */
    double damping;    /* int c u'^2 dt */
    double hysteretic; /* the slider's work */
    double impact;     /* the impacts' losses */
    double residual;   /* (input - the others) / input */
} pd_energy;

/* What a run measures. */
typedef struct pd_osc_result {
    double umax;                  /* max |u| over the measuring window [m] */
    double u_toward;              /* max u (toward the wall) [m] */
    double u_away;                /* max -u (away from the wall) [m] */
    long impacts;                 /* contact episodes begun */
    double first_impact;          /* time of the first impact [s], NAN when none */
    double first_impact_velocity; /* u' at that instant [m/s], NAN when none */
    double max_impact_velocity;   /* largest approach speed of any impact [m/s] */
    double max_impulse;           /* largest impulse of one impact per unit mass [m/s] */
    double contact_time;          /* time spent in contact [s] */
    double min_gap;               /* smallest gap seen [m] (negative: penetration) */
    long accumulations;           /* event-driven: accumulations jumped to rest */
    long steps;                   /* steps (Moreau–Jean, penalty) or events (event-driven) */
    double dt, tend, theta, gamma;
    double cpu_s;
    const char *kernel; /* "scalar", "general", "event", or the penalty stepper */
    /* demands over the measuring window (pd_run_opts, "demand parameters"), per unit
     * mass; NAN where not measured (the batched runs of pd_osc_run_stream) */
    double acc_max;          /* peak |2 xi w0 u' + w0^2 u + lambda|: the absolute acceleration
                             [m/s^2], the wall's held force lambda (per unit mass) in it,
                             the impacts' impulses not */
    double shear_max;        /* peak |2 xi w0 u' + w0^2 u|: the base shear per unit mass [N/kg]
                             (acc_max where the wall holds no force) */
    double force_max;        /* peak contact force per unit mass [N/kg] (penalty, newmark;
                             NAN for the impulsive methods) */
    double force_equiv;      /* pd_equivalent_force(max_impulse, td) [N/kg] */
    double contact_duration; /* the td used [s] */
    /* Moreau-Jean to a tolerance (rtol > 0; else rtol 0, err_est NAN, rtol_met 1,
     * steps_rejected 0, dt_min = dt_max = dt): */
    double rtol;           /* the tolerance asked */
    double err_est;        /* the estimated relative error of the peaks (umax, u_toward,
                             u_away, drift, acc_max): the largest */
    int rtol_met;          /* 1: err_est <= rtol and no step floor or budget stopped the
                             refinement */
    long steps_rejected;   /* tries thrown away (a step halved) */
    double dt_min, dt_max; /* the smallest and largest step kept [s] */
    /* a yielding oscillator (pd_osc_yields; else NAN and 0), over the whole run: */
    double ductility;         /* umax / uy */
    double residual;          /* (1 - alpha) up at the end [m]: where the oscillator rests */
    double plastic_excursion; /* sum of |d up| [m] */
    double hysteretic_energy; /* the slider's work, per unit mass [J/kg] */
    long n_yield;             /* yield onsets */
    long newton_failures;     /* newmark: steps whose Newton iterations failed (each redone at
                                 the spring's initial stiffness); 0 for the other methods */
    pd_energy energy;         /* the balance (NAN throughout for an elastic run) */
} pd_osc_result;

/* The method a run of (c, o) takes: o's, or for PD_METHOD_AUTO the exact
 * event-driven reference when its scan of the run fits PD_OSC_MAX_SCAN,
 * else Moreau-Jean. */
PD_API pd_method pd_osc_method(const pd_osc *c, const pd_run_opts *o);

/* Run the case with the method of opts (sampler may be NULL; opts NULL:
 * the defaults). */
PD_API int pd_osc_run(const pd_osc *c, const pd_run_opts *opts, pd_osc_sampler sampler, void *ctx,
                      pd_osc_result *res, pd_err *err);

/* ---- many cases: a stream ---------------------------------------------- *
 * pd_osc_run_stream runs every case a source gives and reports each as it
 * ends.  The Moreau–Jean cases without a sampler or an LCP hook
 * (pd_osc_batchable) run many at a time on the lanes of a pd_mjb
 * (pd_engine.h), a lane taking the next case as soon as its run ends; each
 * result equals pd_osc_run's for the case, bit for bit, but for cpu_s (the
 * lanes share the batch's time), kernel ("batched") and acc_max (NAN: the
 * lanes do not measure it).  The other cases,
 * and any case whose state stops being finite, run alone by pd_osc_run,
 * which gives their failure its message.  One stream per thread. */

/* Fill *c and *o with the next case, *id with the caller's name for it, and
 * return 1; return 0 when no case is left. */
typedef int (*pd_osc_stream_next)(void *ctx, pd_osc *c, pd_run_opts *o, long *id);
/* Case id ended: its result when status is 0, else err's message. */
typedef void (*pd_osc_stream_done)(void *ctx, long id, const pd_osc_result *res, int status,
                                   const pd_err *err);

/* 1 when (c, o) can run in a batch: Moreau-Jean, the automatic kernel, no
 * LCP hook (a sampler is the caller's to avoid). */
PD_API int pd_osc_batchable(const pd_osc *c, const pd_run_opts *o);
/* Run the stream until the source is exhausted: every case is reported,
 * failed or not (without memory for a batch, cases run alone); PD_OK. */
PD_API int pd_osc_run_stream(pd_osc_stream_next next, pd_osc_stream_done done, void *ctx,
                             pd_err *err);

/* The event-driven reference's work: its scan points over tend (64 per
 * shortest period of each forcing piece: of Tp and T0 during a pulse or
 * a harmonic excitation, of T0 after a pulse and under a record's linear
 * pieces), and the most a run may take (about 5 s here: a
 * stiffer oscillator is quasi-static, and Moreau-Jean runs it). */
#define PD_OSC_MAX_SCAN 2.5e7
PD_API double pd_osc_scan_points(const pd_osc *c, double tend);

/* The three methods (pd_osc_run dispatches to them; opts NULL: the
 * defaults):
 * Moreau–Jean, its umax the maximum over the steps; */
PD_API int pd_osc_simulate(const pd_osc *c, const pd_run_opts *opts, pd_osc_sampler sampler,
                           void *ctx, pd_osc_result *res, pd_err *err);
/* the exact event-driven reference (pd_ed_sdof_run): dt is only the
 * sampling interval, res->steps counts events, res->kernel is "event"; */
PD_API int pd_osc_reference(const pd_osc *c, const pd_run_opts *opts, pd_osc_sampler sampler,
                            void *ctx, pd_osc_result *res, pd_err *err);
/* the penalty baseline with opts->pen (Hertz: the force at a penetration of
 * Le equals kc_mult w0^2 Le); samples every dt; res->steps counts accepted
 * steps, res->kernel names the stepper. */
PD_API int pd_osc_penalty(const pd_osc *c, const pd_run_opts *opts, pd_osc_sampler sampler,
                          void *ctx, pd_osc_result *res, pd_err *err);

/* A run and its no-wall twin, with the paper's figures. */
typedef struct pd_osc_summary {
    pd_osc_result r, free;
    double Pi1;     /* umax wp^2 / ap */
    double gamma;   /* umax / umax_free (NAN when umax_free = 0) */
    double chi;     /* gap / umax_free (NAN when umax_free = 0) */
    double cpu_s;   /* both runs */
    double err_est; /* to a tolerance: the larger of the two runs' (NAN: fixed steps) */
    int rtol_met;   /* both runs met their tolerance (1 without one) */
} pd_osc_summary;

/* opts NULL: the defaults. */
PD_API int pd_osc_summarize(const pd_osc *c, const pd_run_opts *opts, pd_osc_sampler sampler,
                            void *ctx, pd_osc_summary *s, pd_err *err);

/* Exact response without the wall from rest (closed form), at t [s]; a
 * pulse only (a record's free response is pd_osc_reference with no wall). */
PD_API void pd_osc_free_exact(const pd_osc *c, double t, double *u, double *v);

/* First time t <= tmax at which that free response reaches the gap, found
 * on a grid of Tp/1000 and bisected to rounding, with the speed there:
 * PD_OK, or PD_EINVAL when it does not reach the gap by tmax (or c is
 * driven by a record). */
PD_API int pd_osc_free_first_contact(const pd_osc *c, double tmax, double *t, double *v);

/* ---- errors against the reference (compare, converge) ------------------- *
 *   err_umax_rel  = |umax - umax_ref| / umax_ref,
 *   err_hist_linf = max_k |u(t_k) - u_ref(t_k)| / umax_ref   on t_k = k dt. */

/* u on the output grid, preallocated once per run. */
typedef struct pd_trace {
    double *u;
    long n, cap;
    double dt; /* the grid's step (pd_trace_alloc) */
} pd_trace;

typedef struct pd_measured {
    pd_osc_result r;
    double err_umax_rel, err_hist_linf;
    long grid_points;
} pd_measured;

/* Room for the grid of o (tend / dt + 2 points): PD_OK, PD_ENOMEM, or
 * PD_EINVAL when o has no grid (dt, tend not resolved). */
PD_API int pd_trace_alloc(pd_trace *tr, const pd_run_opts *o);
PD_API void pd_trace_free(pd_trace *tr);

/* The reference on the grid of o; res->cpu_s is its cost without sampling. */
PD_API int pd_measure_reference(const pd_osc *c, const pd_run_opts *o, pd_trace *ref,
                                pd_osc_result *res, pd_err *err);

/* The method of o on the same grid, its errors against ref; out->r.cpu_s is
 * the cost of a second run without sampling. */
PD_API int pd_measure_run(const pd_osc *c, const pd_run_opts *o, const pd_trace *ref,
                          double umax_ref, pd_trace *work, pd_measured *out, pd_err *err);

/* ==== scenes: rows of structures (SPEC §4) =================================== *
 * Structures stand in a row along x (positive to the right) on a common
 * ground moving with the excitation; displacements are relative to the
 * ground.  A structure is an SDOF or a lumped-mass shear building (storey 1
 * lowest); a contact joins a storey of structure a (left) to a storey of
 * structure b (right), or a structure to a rigid wall at either end, with
 * gap g = gap + x_b - x_a >= 0 and Newton restitution eps.                    */

#define PD_WALL (-1)   /* the structure index of a rigid wall */
#define PD_NAME_MAX 64 /* longest structure name + 1 */

typedef enum {
    PD_DAMPING_RAYLEIGH = 0, /* C = alpha M + beta K: xi at two modes */
    PD_DAMPING_STIFFNESS = 1 /* C = beta K: xi at the first mode */
} pd_damping;

typedef struct pd_structure {
    char name[PD_NAME_MAX];
    int storeys;       /* 1 for an SDOF */
    double *mass;      /* storeys entries [kg] */
    double *stiffness; /* storeys entries [N/m]: k_i joins storey i - 1 (ground for i = 1) to i */
    double xi;         /* damping ratio in [0, 1) */
    pd_damping damping;
    int modes[2]; /* Rayleigh: the two modes (1-based) given xi; an SDOF uses mode 1 */
    /* derived by pd_scene_finish */
    double T0;          /* fundamental period [s] */
    double period[2];   /* periods of the damping modes [s] */
    double Tmin;        /* shortest natural period (the highest mode) [s] */
    double alpha, beta; /* C = alpha M + beta K */
    int dof;            /* first dof of the structure in the scene's model */
    double *height;     /* storeys entries: storey heights [m] (PD_STOREY_HEIGHT unless set) */
    /* yielding storeys (SPEC §7; pd_scene_set_yield; NULL: elastic): storey i's
     * restoring force k_i [a d + (1 - a) z], |z| <= uy[i], a = yield_alpha[i] */
    double *uy;          /* storeys entries: yield drifts [m] (INFINITY: that storey elastic) */
    double *yield_alpha; /* storeys entries: post-yield stiffness ratios in [0, 1] */
} pd_structure;

typedef struct pd_contact {
    int a, b;             /* structure indices (file order), PD_WALL for a wall */
    int level_a, level_b; /* storeys, 1-based (0 at a wall) */
    double gap;           /* [m] >= 0 */
    double eps;           /* Newton restitution in [0, 1] */
    int entry;            /* the contacts[] entry of the scene file it came from */
} pd_contact;

/* The excitation of a scene: a pulse along +x (dir +1) or -x, or a record
 * whose axis is +x (dir -1 flips it): effective forces -m dir S ug''(t). */
typedef struct pd_scene_excitation {
    pd_pulse pulse;
    int dir;                 /* +1: first effective inertial force -m ug'' along +x */
    double ap, Tp;           /* [m/s^2], [s]; a record: S times its fitted pulse's, and its */
    const pd_record *record; /* NULL: the pulse */
    double rec_ap, scale;    /* the record's fitted ap at scale 1, and S */
} pd_scene_excitation;

typedef struct pd_scene {
    int nstruct, ncontact;
    pd_structure *st;
    pd_contact *ct;
    pd_scene_excitation exc;
    double tend; /* [s]; 0 = derived */
    int n;       /* degrees of freedom (after pd_scene_finish) */
    int finished;
    int cap_struct, cap_contact; /* allocated entries */
    int *names;                  /* name_cap slots: structure index + 1 by name hash, 0 empty */
    int name_cap;
    pd_record *own_record; /* the record a scene file named (freed with the scene) */
} pd_scene;

/* An empty scene excited by exc (NULL: none yet, sc->exc to be set before
 * pd_scene_finish); NULL when out of memory. */
PD_API pd_scene *pd_scene_new(const pd_scene_excitation *exc);
PD_API void pd_scene_free(pd_scene *sc);

/* Add structures and contacts (file order is row order, left to right).
 * Each returns PD_OK or an error whose message starts with the field it
 * concerns ("T0: must be > 0 (got -1)"). */
PD_API int pd_scene_add_sdof(pd_scene *sc, const char *name, double T0, double xi, double mass,
                             pd_err *err);
PD_API int pd_scene_add_building(pd_scene *sc, const char *name, int storeys, const double *masses,
                                 const double *stiffnesses, double xi, pd_err *err);
/* Uniform storeys of mass `mass` with the stiffness that gives the
 * fundamental period T0. */
PD_API int pd_scene_add_uniform(pd_scene *sc, const char *name, int storeys, double mass, double T0,
                                double xi, pd_err *err);
/* Damping of the last structure added: the model and (Rayleigh) its modes. */
PD_API int pd_scene_set_damping(pd_scene *sc, pd_damping damping, int mode1, int mode2,
                                pd_err *err);
/* Storey heights of the last structure added (storeys entries, each finite
 * and > 0 [m]; the message names "storey_heights"). */
PD_API int pd_scene_set_heights(pd_scene *sc, const double *heights, pd_err *err);
/* The last structure's yielding storeys: uy one per storey, each > 0 [m]
 * (INFINITY: that storey stays elastic); alpha one per storey in [0, 1]
 * (NULL: 0, elastic-perfectly plastic).  Runs by Moreau-Jean at fixed steps
 * and by newmark (the others refuse a yielding scene). */
PD_API int pd_scene_set_yield(pd_scene *sc, const double *uy, const double *alpha, pd_err *err);
/* Every storey of every structure yielding with uy [m] > 0 and alpha in
 * [0, 1] (a generated row's, `--chain N --uy`). */
PD_API int pd_scene_yield_every(pd_scene *sc, double uy, double alpha, pd_err *err);
/* The yielding springs of a scene: storeys with finite uy and alpha < 1. */
PD_API int pd_scene_springs(const pd_scene *sc);
/* A contact; a or b PD_WALL for a wall (level 0 there). */
PD_API int pd_scene_add_contact(pd_scene *sc, int a, int level_a, int b, int level_b, double gap,
                                double eps, int entry, pd_err *err);
/* A deep copy, not finished (NULL when out of memory); a record it names
 * is shared, not copied: the original must outlive the copy. */
PD_API pd_scene *pd_scene_copy(const pd_scene *sc);
/* The structure called name, or -1 (PD_WALL for "wall"); -2 when unknown
 * (or sc or name NULL). */
PD_API int pd_scene_find(const pd_scene *sc, const char *name);

/* Check the row (contacts left to right, levels that exist, a non-empty
 * row), number the dofs, derive periods and damping.  PD_OK or PD_EINVAL. */
PD_API int pd_scene_finish(pd_scene *sc, pd_err *err);

/* Read a scene file (JSON, docs/scenes.md).  Errors: PD_EIO (unreadable),
 * PD_EPARSE with "FILE:LINE:COL: field.path: what is wrong". */
PD_API int pd_scene_load(const char *path, pd_scene **out, pd_err *err);

/* A generated row of N SDOFs of unit mass between two walls, periods
 * alternating T0 and ratio T0, every gap `gap` and restitution eps: the
 * scale-study scene of `--chain N`. */
PD_API int pd_scene_chain(int N, const pd_scene_excitation *exc, double T0, double ratio, double xi,
                          double gap, double eps, pd_scene **out, pd_err *err);

/* Reference scales: wp = 2 pi / Tp, Le = ap / wp^2. */
PD_API double pd_scene_wp(const pd_scene *sc);
PD_API double pd_scene_Le(const pd_scene *sc);
/* min(Tp, shortest fundamental period) / 2000, and the tend of a pulse:
 * Tp + 2 (longest fundamental period); harmonic: as for the oscillator with
 * the longest period and the smallest damping. */
PD_API double pd_scene_default_dt(const pd_scene *sc);
PD_API double pd_scene_default_tend(const pd_scene *sc);
PD_API double pd_scene_measure_start(const pd_scene *sc, double tend);
/* Check the options (in NULL: pd_run_default_opts()) and complete dt and tend. */
PD_API int pd_scene_resolve_opts(const pd_scene *sc, const pd_run_opts *in, pd_run_opts *out,
                                 pd_err *err);
/* 1 when the scene is the one-wall oscillator (one SDOF, at most one contact,
 * with a wall): it then runs on the oscillator's fast paths, with *c the
 * equivalent case (mirrored when the wall is on the left); 0 otherwise, and
 * when a pointer is NULL. */
PD_API int pd_scene_as_oscillator(const pd_scene *sc, pd_osc *c, int *mirrored);

/* The scene as an engine model in the reference units (tau = wp t, x =
 * u / Le, masses in kg): M, C, K, W compressed-column, F = M 1 phi(tau). */
typedef struct pd_scene_model {
    pd_model model;
    pd_sparse M, C, K, W;
    double *g0, *e, *mass;
    /* the yielding springs (model.ns of them; pd_scene_springs): */
    pd_sparse S;          /* n x ns: +1 at the storey's dof, -1 at the one below */
    double *ks, *uy;      /* ns: (1 - alpha) k [reference units], uy [in Le] */
    int *spring_dof;      /* ns: the storey's dof */
    double *spring_alpha; /* ns: its post-yield stiffness ratio */
    double breaks[1];
    pd_osc shape; /* the excitation's shape in Pi units (pd_osc_shape) */
} pd_scene_model;

PD_API int pd_scene_model_build(const pd_scene *sc, int with_contacts, pd_scene_model *sm,
                                pd_err *err);
PD_API void pd_scene_model_free(pd_scene_model *sm);

/* One sample of a scene run, in metres, seconds and newton-seconds. */
typedef struct pd_scene_sample {
    long step;
    double t;
    const double *x;       /* n displacements (structure s, storey k: st[s].dof + k - 1) */
    const double *v;       /* n velocities [m/s] */
    const double *gap;     /* m gaps [m] */
    const double *impulse; /* m contact impulses since the last sample [N s] */
    const long *impacts;   /* m impacts begun since the last sample (over the run they sum
                              to pd_scene_result.impacts) */
    const double *up;      /* n: each storey's plastic offset up at t [m] (0 for an
                              elastic storey); NULL when no storey of the scene yields */
    const double *a_abs;   /* n: each floor's absolute acceleration [m/s^2] as the demands
                              measure it (the held contacts' forces in it, an impact's
                              impulse not: at a sample that ends an impact step, the finite
                              part); NULL when the demands are not measured */
    const double *force;   /* m: each contact element's force at t [N] (penalty, newmark);
                              NULL for the rigid methods, whose history is the impulse */
} pd_scene_sample;

typedef int (*pd_scene_sampler)(const pd_scene_sample *s, void *ctx);

/* What a scene run measures.  Arrays are allocated by pd_scene_result_alloc. */
typedef struct pd_scene_result {
    int n, m;
    double *umax;          /* n: max |x| per dof over the measuring window [m] */
    double *u_pos, *u_neg; /* n: max x and max -x [m] */
    double *drift;         /* n: max |x_k - x_k-1| per storey (x_0 = ground) [m] */
    long *impacts;         /* m: contact episodes begun */
    double *first_impact;  /* m: time of the first impact [s], NAN when none */
    double *max_impulse;   /* m: largest impulse of one impact [N s] */
    double *contact_time;  /* m: time in contact [s] */
    double *approach;      /* m: max over t of -(g - gap), the closing [m] */
    long steps;            /* steps, accepted steps or events */
    long lcp_solves;       /* LCPs solved (Moreau–Jean general kernel, event-driven) */
    /* the model decisions of the event-driven reference (0 for the other methods):
     * impacts whose LCP took several contacts at zero gap, contacts taken as closed
     * within the closing tolerance (gap in (0, close_tol Le]), accumulations of
     * impacts jumped to their limit */
    long simultaneous, tol_closed, accumulations;
    double close_tol; /* the closing tolerance used [in Le] (NAN: not event-driven) */
    double dt, tend, theta;
    double cpu_s; /* the run's CPU time, its sampler's (sample() and the caller's) left out */
    const char *method, *kernel, *factor, *lcp_solver;
    /* demands over the measuring window (pd_run_opts, "demand parameters"): */
    double *acc_max;         /* n: peak |a_abs| per floor [m/s^2] */
    double *shear_max;       /* n: peak |V_k| per storey [N] (storey 1: the base shear) */
    double *drift_ratio;     /* n: drift / storey height [-] */
    double *force_max;       /* m: peak contact force [N] (penalty, newmark; NAN otherwise) */
    double *force_equiv;     /* m: pd_equivalent_force(max_impulse, td) [N] */
    double contact_duration; /* the td used [s] */
    /* Moreau-Jean to a tolerance (rtol > 0; else rtol 0, err_est NAN, rtol_met 1,
     * steps_rejected 0, dt_min = dt_max = dt): */
    double rtol;           /* the tolerance asked */
    double *err_est;       /* nstruct: the estimated relative error of each structure's
                              peaks (umax, drift and demands per storey): the largest */
    double err_est_max;    /* the largest over the structures */
    int rtol_met;          /* 1: err_est_max <= rtol and no step floor or budget stopped
                              the refinement */
    long steps_rejected;   /* tries thrown away (a step halved) */
    double dt_min, dt_max; /* the smallest and largest step kept [s] */
    int nstruct;           /* err_est's and law_band's entries */
    /* the event-driven reference for rows (method event): its impact law, and when
     * its result rests on simultaneous impacts (law_decided > 0: impacts whose LCP
     * could take several closed contacts, one closing, separating ones included:
     * where the staged and single laws may differ) how far each structure's peak
     * moves under the other law (a second run):
     *   law_band = max over storeys |umax_other - umax| / max over storeys umax,
     * NAN without simultaneous impacts, for the other methods, and with
     * pd_run_opts.no_law_band. */
    const char *impact_law; /* "staged", "single" (NULL: not the row reference) */
    double *law_band;       /* nstruct */
    double law_band_max;    /* the largest over the structures (NAN: none measured) */
    long law_decided;
    /* yielding storeys (pd_scene_set_yield; NAN, 0 for an elastic storey): */
    double *ductility;         /* n: drift / uy */
    double *residual;          /* n: (1 - alpha) up at the end [m] */
    double *plastic_excursion; /* n: sum |d up| [m] */
    long *n_yield;             /* n: yield onsets */
    pd_energy energy;          /* a yielding scene by Moreau-Jean: the balance over the scene [J]
                         (from rest; NAN throughout otherwise) */
} pd_scene_result;

/* Arrays for the finished scene sc (PD_EINVAL before pd_scene_finish). */
PD_API int pd_scene_result_alloc(const pd_scene *sc, pd_scene_result *r, pd_err *err);
/* 1 when r holds the arrays of sc's shape (as pd_scene_result_alloc made
 * them); 0 otherwise, and when sc or r is NULL. */
PD_API int pd_scene_result_fits(const pd_scene *sc, const pd_scene_result *r);
PD_API void pd_scene_result_free(pd_scene_result *r);

/* Run the scene with the method of opts (NULL: pd_run_default_opts()) into res (from
 * pd_scene_result_alloc for this scene: PD_EINVAL otherwise); sampler (may
 * be NULL) gets the state every step (Moreau–Jean) or every dt (the others;
 * event-general also at each of its events, between grid points), and at
 * t = 0. */
PD_API int pd_scene_run(const pd_scene *sc, const pd_run_opts *opts, pd_scene_sampler sampler,
                        void *ctx, pd_scene_result *res, pd_err *err);

/* A run and its contact-free twin with the Pi terms:
 *   Pi1 = umax wp^2 / ap per dof,  Pi2 = Tp / T0 per structure,
 *   Pi3 = gap wp^2 / ap per contact,
 *   gamma = umax / umax_free per dof,  chi = gap / approach_free per contact;
 * and the separation of each contact (docs/scenes.md, "Separation"): the
 * gap it needs, the largest closing of its sides' free motions (the twin's
 * approach: exact by the event method), beside the codes' rules from each
 * side's own peak u (the twin's umax at its level; a wall's 0):
 *   ABS u_a + u_b,  SRSS sqrt(u_a^2 + u_b^2),
 *   DDC sqrt(u_a^2 + u_b^2 - 2 rho u_a u_b), rho pd_ddc_correlation of the
 *   structures' fundamental periods and damping ratios. */
typedef struct pd_scene_summary {
    pd_scene_result r, free;
    double *Pi1, *gamma; /* n */
    double *Pi2;         /* nstruct */
    double *Pi3, *chi;   /* m */
    double cpu_s;
    double err_est;            /* to a tolerance: the largest of both runs' (NAN: fixed steps) */
    int rtol_met;              /* both runs met their tolerance (1 without one) */
    double *err_est_structure; /* nstruct: each structure's, the larger of both runs' (NAN:
                                  fixed steps) */
    double *required_gap;      /* m: [m] */
    double *rule_abs, *rule_srss, *rule_ddc; /* m: [m] */
} pd_scene_summary;

/* The correlation coefficient of two oscillators' responses to one white
 * noise (Der Kiureghian's, the DDC rule's rho): r = Ta / Tb,
 *   rho = 8 sqrt(xa xb) (xa + r xb) r^(3/2) / ((1 - r^2)^2
 *         + 4 xa xb r (1 + r^2) + 4 (xa^2 + xb^2) r^2),
 * symmetric in the two, 1 for equal periods and damping; NAN for a period
 * <= 0 or a damping ratio < 0 (0 when either damping is 0 and r != 1). */
PD_API double pd_ddc_correlation(double Ta, double Tb, double xia, double xib);

/* opts NULL: pd_run_default_opts(). */
PD_API int pd_scene_summarize(const pd_scene *sc, const pd_run_opts *opts, pd_scene_sampler sampler,
                              void *ctx, pd_scene_summary *s, pd_err *err);
PD_API void pd_scene_summary_free(pd_scene_summary *s);

/* ---- errors against the reference on a scene (compare, converge) -------- *
 * Per structure, on the output grid t_k = k dt:
 *   err_umax_rel  = max over storeys |umax - umax_ref| / max over storeys umax_ref,
 *   err_hist_linf = max_k max over storeys |x(t_k) - x_ref(t_k)| / (the same). */

/* The reference history: rows of n displacements at t = k dt.  A run on a
 * grid whose step is a whole multiple of dt is compared on its own points. */
typedef struct pd_scene_trace {
    double *x;
    long rows, cap;
    int n;
    double dt;
} pd_scene_trace;

typedef struct pd_scene_errors {
    double *err_umax, *err_hist;       /* nstruct */
    double err_umax_max, err_hist_max; /* the worst structure */
    long impacts;                      /* over every contact */
    long grid_points;
    double cpu_s; /* the run's, the sampling and comparison left out */
    int nstruct;  /* the shape: set by pd_scene_errors_alloc */
} pd_scene_errors;

/* Room for the grid of o (NULL: pd_run_default_opts(); PD_EINVAL when it
 * would exceed 2 GB).  The
 * trace, the errors and the results carry the shape of the finished scene
 * they were allocated for; a measurement with another shape is refused
 * (PD_EINVAL), never written out of bounds. */
PD_API int pd_scene_trace_alloc(pd_scene_trace *tr, const pd_scene *sc, const pd_run_opts *o,
                                pd_err *err);
PD_API void pd_scene_trace_free(pd_scene_trace *tr);
PD_API int pd_scene_errors_alloc(const pd_scene *sc, pd_scene_errors *e, pd_err *err);
PD_API void pd_scene_errors_free(pd_scene_errors *e);

/* The event-driven reference of o's scene on its grid (res allocated by
 * pd_scene_result_alloc; res->cpu_s is its cost, the sampler's time left out:
 * its states on the grid stay in it). */
PD_API int pd_scene_measure_reference(const pd_scene *sc, const pd_run_opts *o, pd_scene_trace *ref,
                                      pd_scene_result *res, pd_err *err);
/* The method of o and its errors against ref, on ref's rows: the run's own
 * states when its dt is a whole multiple of ref's, else its steps
 * interpolated (the cubic through a step's ends, the line across a step
 * with an impulse; to a tolerance, or any other grid). */
PD_API int pd_scene_measure_run(const pd_scene *sc, const pd_run_opts *o, const pd_scene_trace *ref,
                                const pd_scene_result *ref_res, pd_scene_result *res,
                                pd_scene_errors *e, pd_err *err);

/* ==== spectrum sweeps ============================================================ *
 * A Pi2 grid crossed with lists of pulse, directivity, amplitude, damping,
 * gap and restitution.
 *
 * Tasks.  A sweep is a list of independent, deterministic runs ("tasks"):
 * first the no-wall twins, one per (pulse, dir, ap, xi, Pi2) — they do not
 * depend on the gap or on eps — then the runs with the wall, one per point.
 * Task results go into a preallocated array indexed by task, so the order in
 * which threads or processes finish never changes a number: any split of
 * the tasks gives output bit-identical to the serial run.
 *
 * Curves and points.  A curve is one (pulse, dir, ap, xi, Pi3 or gap, eps);
 * curve indices run with eps fastest, then the gap, xi, ap, dir, pulse.
 * Point p = curve * npi2 + j is the curve's j-th Pi2 value. */

enum { PD_SPEC_MAX_LIST = 64 };

/* Most tasks a sweep may have (memory for results and journal). */
#define PD_SPEC_MAX_TASKS 2000000L

/* The sweep as the command line defines it. */
typedef struct pd_spectrum {
    pd_osc base;      /* Tp and the defaults (the lists override) */
    pd_run_opts opts; /* scheme, method and penalty; dt, tend 0: per point */
    double pi2_min, pi2_max;
    int npi2, linear; /* linear: equal steps; else log-spaced */
    int npulse, ndir, nap, nxi, nsize, neps;
    pd_pulse pulse[3];
    int dir[2];
    double ap[PD_SPEC_MAX_LIST], xi[PD_SPEC_MAX_LIST];
    double size[PD_SPEC_MAX_LIST], eps[PD_SPEC_MAX_LIST];
    int size_is_gap;  /* size[] holds gaps in metres (--gap), else Pi3 values */
    int dimensional;  /* --ap given: add the dimensional view (umax vs T0) */
    double dt_per_Tp; /* > 0: dt = Tp / dt_per_Tp for every point */
} pd_spectrum;

/* Where a task sits in the sweep. */
typedef struct pd_spec_coords {
    int twin; /* 1: the no-wall twin of a (pulse, dir, ap, xi, Pi2) */
    int pulse, dir, ap, xi, size, eps, j;
    long curve; /* -1 for a twin */
} pd_spec_coords;

/* What one task measured (in metres and seconds). */
typedef struct pd_spec_result {
    double umax, u_toward, u_away, contact_time, first_impact, cpu_s;
    long impacts, steps;
    double ductility, residual; /* a yielding sweep's (pd_osc_result's); NAN if elastic */
    int status;                 /* 0 ok, else the run's PD_E* status */
    int done;                   /* 1 once computed (or read back from the journal) */
} pd_spec_result;

/* One point of the spectrum, ready for output. */
typedef struct pd_spec_row {
    pd_osc c;
    long curve;
    double T0, gap, dt, tend;
    double umax, Pi1, umax_free, gamma, chi, u_toward, u_away, contact_time, first_impact;
    double cpu_s;
    long impacts, steps;
    /* a yielding sweep (base.Piy, base.alpha; NAN if elastic): umax / uy, the
     * no-wall twin's, and (1 - alpha) up at the end over uy */
    double ductility, ductility_free, residual_uy;
} pd_spec_row;

/* ---- the sweep (spectrum_sweep.c) ---------------------------------------- */

/* Defaults: one sine pulse, normal, ap = 1, Tp = 1, xi = 0.05, Pi3 = 0.05,
 * eps = 0.5; no Pi2 grid yet (npi2 = 0). */
PD_API void pd_spec_init(pd_spectrum *s);
PD_API long pd_spec_curves(const pd_spectrum *s);
PD_API long pd_spec_points(const pd_spectrum *s);
PD_API long pd_spec_twins(const pd_spectrum *s);
PD_API long pd_spec_tasks(const pd_spectrum *s);
/* The j-th of n values from lo to hi, equal steps (linear) or log-spaced,
 * the end points exact. */
PD_API double pd_grid_value(double lo, double hi, int n, int linear, int j);
/* The j-th Pi2 of the grid (end points exact). */
PD_API double pd_spec_pi2(const pd_spectrum *s, int j);
PD_API void pd_spec_coords_of(const pd_spectrum *s, long task, pd_spec_coords *co);
/* The twin task of a point task. */
PD_API long pd_spec_twin_of(const pd_spectrum *s, long task);
/* The case and options of a task, resolved as `pound simulate` resolves
 * them (dt, tend derived per point): PD_OK or PD_EINVAL naming the field. */
PD_API int pd_spec_case(const pd_spectrum *s, long task, pd_osc *c, pd_run_opts *o, pd_err *err);
/* Check every point's case: PD_OK or PD_EINVAL with the first bad one. */
PD_API int pd_spec_validate(const pd_spectrum *s, pd_err *err);
/* One method for the whole sweep: PD_METHOD_AUTO becomes the exact
 * event-driven reference when every run's scan fits its budget
 * (pd_osc_method), else Moreau-Jean for every run. */
PD_API void pd_spec_resolve_method(pd_spectrum *s);
/* Run one task into r (r->status and err say why it failed). */
PD_API void pd_spec_run_task(const pd_spectrum *s, long task, pd_spec_result *r, pd_err *err);

/* Tasks as a stream (pd_osc_run_stream): next returns the next task to run
 * (-1: none left), done receives each task's result as pd_spec_run_task
 * gives it (cpu_s aside) with its message when r->status != 0.  The
 * Moreau-Jean tasks run many at a time.  One stream per thread. */
typedef long (*pd_spec_task_next)(void *ctx);
typedef void (*pd_spec_task_done)(void *ctx, long task, const pd_spec_result *r, const pd_err *err);
PD_API int pd_spec_stream(const pd_spectrum *s, pd_spec_task_next next, pd_spec_task_done done,
                          void *ctx, pd_err *err);
/* Expected cost of a task: its number of steps. */
PD_API double pd_spec_cost(const pd_spectrum *s, long task);
/* A canonical text of every parameter that shapes the results (the
 * journal header); malloc'd, NULL when out of memory. */
PD_API char *pd_spec_key(const pd_spectrum *s);
/* Points from task results (twins give umax_free, gamma, chi). */
PD_API void pd_spec_rows(const pd_spectrum *s, const pd_spec_result *res, pd_spec_row *rows);
/* A short label of a curve naming the parameters that vary. */
PD_API void pd_spec_curve_label(const pd_spectrum *s, long curve, char *buf, size_t cap);

/* Called by pd_spec_sweep for each point, in order (p = curve * npi2 + j):
 * co its place in the lists (co->curve, co->j; co->twin = 0), row its
 * numbers (row->c holds Pi2, Pi3, eps, xi, ap, pulse, dir; umax, Pi1,
 * umax_free of the no-wall twin, gamma, chi, impacts, ...).  Both are valid
 * during the call only.  Return 0 to go on, nonzero to stop the sweep. */
typedef int (*pd_spec_point_fn)(const pd_spec_coords *co, const pd_spec_row *row, void *ctx);

/* Run every task of the sweep on the calling thread (the no-wall twins
 * first, then the points; Moreau-Jean's many at a time, pd_spec_stream)
 * and hand each point to fn, in order, once it and its twin have ended:
 * the numbers pd_spec_run_task and pd_spec_rows give (`pound spectrum`
 * runs the same tasks on threads and ranks).  Every case is checked before
 * anything runs: PD_EINVAL naming the first bad one (or a list or grid out
 * of range).  A failed run stops the sweep with its status and a message
 * naming the point (the first failure in order, after every point before
 * it); fn's nonzero return stops it with PD_ESTOPPED.  Memory: one result
 * per task.  Re-entrant: sweeps may run on several threads (docs/api.md:
 * threads, and GSL's process-wide error handler). */
PD_API int pd_spec_sweep(const pd_spectrum *s, pd_spec_point_fn fn, void *ctx, pd_err *err);

/* ---- scene sweeps ------------------------------------------------------------ *
 * The Pi presentation carried to N structures: the pulse period swept over
 * Pi2 = Tp / T0 of a reference structure (the others keep their period
 * ratios), every gap scaled so that the reference contact's Pi3 = gap wp^2 /
 * ap takes each listed value (the others keep their ratios to it), every
 * restitution set to each listed eps.  Tasks: first the contact-free twins,
 * one per Pi2, then the points, Pi2 fastest, then Pi3, then eps. */
typedef struct pd_scene_sweep {
    const pd_scene *sc;
    pd_run_opts opts; /* dt 0: the scene's default at each point */
    int ref;          /* reference structure */
    int ref_contact;  /* reference contact (its gap must be > 0 with Pi3 values) */
    double pi2_min, pi2_max;
    int npi2, linear;
    int npi3, neps; /* 0: the scene's own gaps, restitutions */
    const double *pi3, *eps;
} pd_scene_sweep;

/* Per task: what the table of a sweep needs. */
typedef struct pd_scene_point {
    double Pi2, Pi3, eps, Tp, Le; /* Pi3 of the reference contact */
    long steps, impacts;
    double cpu_s;
    int status;
} pd_scene_point;

PD_API long pd_scene_sweep_twins(const pd_scene_sweep *w);
PD_API long pd_scene_sweep_points(const pd_scene_sweep *w);
/* Check the sweep (the reference contact, the lists): PD_OK or PD_EINVAL
 * naming the field. */
PD_API int pd_scene_sweep_check(const pd_scene_sweep *w, pd_err *err);
/* The scene of a task (a finished copy, freed by the caller) and its point. */
PD_API int pd_scene_sweep_scene(const pd_scene_sweep *w, long task, pd_scene **out,
                                pd_scene_point *pt, pd_err *err);
/* Run every task on `threads` OpenMP threads (0: the default): pts[task]
 * and umax[task * nstruct + s] (the largest storey displacement of
 * structure s [m]).  The status of the lowest failed task, its message. */
PD_API int pd_scene_sweep_run(const pd_scene_sweep *w, int threads, pd_scene_point *pts,
                              double *umax, pd_err *err);

/* ==== suites of ground motions (suite.c) ====================================== */

/* The records of a suite, each with its scale factor. */
typedef struct pd_suite {
    int n, cap;
    char **path;   /* n record files */
    double *scale; /* n factors > 0 */
} pd_suite;

/* An empty suite (NULL: out of memory); pd_suite_free frees it and its paths. */
PD_API pd_suite *pd_suite_new(void);
PD_API void pd_suite_free(pd_suite *s);
/* Append a record path (copied) with its scale (> 0). */
PD_API int pd_suite_add(pd_suite *s, const char *path, double scale, pd_err *err);
/* A suite file: one record a line, PATH [SCALE], '#' comments, blank lines
 * skipped; a relative PATH is read from the suite file's folder.
 * PD_EINVAL naming the file and line; *out NULL on error. */
PD_API int pd_suite_read(const char *file, pd_suite **out, pd_err *err);

/* The statistics of a suite's values: of the n finite ones (NaN left out),
 * mean, median, 16th and 84th percentiles (linear between order
 * statistics, NumPy's default), min and max; all NaN (n 0) when none is
 * finite, and when the call fails (out of memory, NULL x). */
typedef struct pd_stats {
    int n;
    double mean, median, p16, p84, min, max;
} pd_stats;

PD_API int pd_stats_of(const double *x, int n, pd_stats *st, pd_err *err);

/* A scene's statistics over a suite: n runs of one scene (its structures
 * and contacts), each under one record (docs/records.md, "Suites").
 * Peaks of a storey (dof), or of a structure: its largest storey's (NaN
 * passed over; the base shear: storey 1's); ductility NaN when elastic. */
typedef struct pd_suite_peaks {
    pd_stats umax, drift_ratio, acc_max, shear_max, gamma, ductility;
    pd_stats umax_free; /* the contact-free twin's umax */
} pd_suite_peaks;

/* A rule's gap is taken as closed when the required gap exceeds it by more
 * than this fraction of it (rounding: at a wall ABS is the gap itself). */
#define PD_SUITE_RULE_TOL 1e-9

/* A contact over the suite: how often it closed, its required gap, the
 * codes' rules (ABS, SRSS, DDC) and how often each rule's gap would have
 * been closed (the required gap above it). */
typedef struct pd_suite_contact {
    double closed; /* the share of runs with an impact */
    pd_stats required_gap, impacts, max_impulse;
    pd_stats contact_time, force_equiv, force_max; /* force_max: penalty, newmark (n 0 else) */
    pd_stats rule_abs, rule_srss, rule_ddc;
    double abs_closed, srss_closed, ddc_closed; /* the shares of runs */
} pd_suite_contact;

typedef struct pd_scene_suite {
    int n;                       /* runs */
    int nstruct, ndof, ncontact; /* the scene's */
    pd_suite_peaks *structure;   /* nstruct */
    pd_suite_peaks *storey;      /* ndof, in the scene's dof order */
    pd_suite_contact *contact;   /* ncontact */
    double *structure_umax;      /* nstruct x n: run k's umax of structure s (its largest
                                    storey's) at [s n + k] */
} pd_scene_suite;

/* The statistics of the n summaries runs[0..n) of the finished scene sc
 * (each a pd_scene_summarize of sc under one record) into *out, which
 * pd_scene_suite_free releases (also after a failure). */
PD_API int pd_scene_suite_stats(const pd_scene *sc, const pd_scene_summary *runs, int n,
                                pd_scene_suite *out, pd_err *err);
PD_API void pd_scene_suite_free(pd_scene_suite *s);

/* The 5 %- (xi-) damped pseudo-spectral acceleration Sa(T) = w^2 max |u| of
 * the record at scale 1 [m/s^2]: the elastic oscillator's exact response
 * (the event reference with no wall: exact flights of the piecewise-linear
 * record, its peaks inside a sample step included). */
PD_API int pd_record_sa(const pd_record *rec, const pd_record_pulse *pulse, double T, double xi,
                        double *Sa, pd_err *err);

/* Scaling a record to a target: its PGA, or Sa(T1) at damping xi. */
typedef enum { PD_SCALE_NONE = 0, PD_SCALE_PGA = 1, PD_SCALE_SA = 2 } pd_scale_target;

/* The factor that takes the record to the target value [m/s^2] (1 for
 * PD_SCALE_NONE): value / PGA or value / Sa(T1). */
PD_API int pd_record_scale_to(const pd_record *rec, const pd_record_pulse *pulse,
                              pd_scale_target kind, double value, double T1, double xi,
                              double *scale, pd_err *err);

/* A stochastic near-fault ground motion: the Mavroeidis-Papageorgiou
 * (2003) velocity pulse's acceleration (vp, Tp = 1 / fp, gamma, nu, t0)
 * plus white noise of spectral density S0 [m^2/s^3] through the
 * Clough-Penzien filters (ground wg, zg; high-pass wf, zf) under the
 * Jennings-Housner-Tsai envelope ((t / t1)^2, 1 to t2, then exp(-c (t -
 * t2))), sampled at dt for duration seconds; the noise from splitmix64
 * seeded by seed, held over each sample step (four RK4 steps a sample):
 * the same record bit for bit on every platform. */
typedef struct pd_synth {
    double duration, dt;          /* [s] */
    double vp, Tp, gamma, nu, t0; /* the pulse [m/s, s, 1, rad, s] */
    double S0, wg, zg, wf, zf;    /* the noise [m^2/s^3, rad/s, 1, rad/s, 1] */
    double t1, t2, c;             /* the envelope [s, s, 1/s] */
    unsigned long long seed;      /* the noise's stream */
} pd_synth;

PD_API int pd_record_synth(const pd_synth *p, const char *name, pd_record *rec, pd_err *err);
/* The parameters of the suite pound ships (examples/records/suite/): k in
 * [0, pd_synth_shipped_count()), NULL outside. */
PD_API int pd_synth_shipped_count(void);
PD_API const pd_synth *pd_synth_shipped(int k);

/* A scene's excitation by a record at scale (its fitted pulse gives ap and
 * Tp, as a scene file's "record"): pulse and direction kept. */
PD_API void pd_scene_excite_record(pd_scene_excitation *x, const pd_record *rec,
                                   const pd_record_pulse *pulse, double scale);

#endif
