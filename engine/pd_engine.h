/* pd_engine.h — time integration of linear mechanical systems with
 * frictionless unilateral contacts (SPEC §2):
 *
 *     M q'' + C q' + K q = F(t) + W lambda,
 *     g = g0 + W^T q >= 0,  lambda >= 0,  g ⊥ lambda,
 *     Newton impact law  U+ = -e U-  (U = W^T v) for each closing contact.
 *
 * A model (pd_model) is const during a run; an integrator object (pd_mj for
 * Moreau–Jean) owns every workspace, allocated once by its _alloc, and the
 * mutable state (pd_state) that it advances.  Steps never allocate.
 *
 * The matrices are pd_matrix views (zero, dense column-major, or CSC); the
 * iteration matrix is reached through a factorisation table (engine/factor.c)
 * whose kind is chosen from the model, and the contact LCPs through the
 * solver table of lcp/.  Options structs come from their _default_opts()
 * function; their fields hold values, never "use the default" markers. */
#ifndef PD_ENGINE_H
#define PD_ENGINE_H

#include "pd_lcp.h"
#include "pd_core.h"

/* ---- factorisation kinds --------------------------------------------- *
 * How the iteration matrix What = M + h theta C + h^2 theta^2 K (M alone
 * for the event-driven and penalty methods) is stored and factored: a
 * number (one degree of freedom), a dense LU with W^T What^-1 W kept whole,
 * or CHOLMOD's sparse Cholesky (What symmetric positive definite) with
 * What^-1 W and W^T What^-1 W kept sparse -- no dense n x n or m x m matrix. */
typedef enum {
    PD_FACTOR_AUTO = 0, /* scalar for n = 1; dense for n <= PD_FACTOR_DENSE_MAX or
                             dense input; CHOLMOD otherwise */
    PD_FACTOR_SCALAR = 1,
    PD_FACTOR_DENSE = 2,
    PD_FACTOR_CHOLMOD = 3
} pd_factor_kind;

/* The largest n the automatic choice factors densely (docs/scenes.md). */
#define PD_FACTOR_DENSE_MAX 24

/* "auto", "scalar", "dense", "cholmod"; parse: PD_OK or PD_EINVAL. */
PD_API const char *pd_factor_kind_name(pd_factor_kind kind);
PD_API int pd_factor_kind_parse(const char *name, pd_factor_kind *kind);

/* ---- the model -------------------------------------------------------- */

/* Effective force F(t) (n entries) written to F; ctx is the model's.
 * side = -1 asks for the left limit F(t-), +1 for the right limit F(t+);
 * they differ only at the model's breakpoints.  A function of t: the
 * scalar kernel's pd_mj_run asks for the left limits of a few steps ahead
 * (in increasing t), so that their evaluation overlaps the steps. */
typedef void (*pd_force_fn)(double t, int side, double *F, void *ctx);

typedef struct pd_model {
    int n;             /* degrees of freedom */
    int m;             /* contacts (0 = none) */
    pd_matrix M, C, K; /* n x n */
    pd_matrix W;       /* n x m: contact directions, g = g0 + W^T q */
    const double *g0;  /* m initial gaps */
    const double *e;   /* m Newton restitution coefficients in [0, 1] */
    pd_force_fn force; /* F(t); NULL = no external force */
    void *force_ctx;
    const double *breaks; /* increasing times where F may jump (NULL if none) */
    int nbreaks;
    /* yielding springs (SPEC §7; ns = 0: none, every method; ns > 0: newmark only):
     * spring j acts on the drift d_j = S_j^T q; the part ks_j = (1 - alpha_j) k_j of
     * its stiffness (counted in K) acts through the hysteretic displacement z_j =
     * d_j - up_j, |z_j| <= uy_j, so that the restoring force is K q - S diag(ks) up
     * with the plastic offsets up (0 at the start) */
    int ns;
    pd_matrix S;      /* n x ns */
    const double *ks; /* ns, > 0 */
    const double *uy; /* ns, > 0 */
} pd_model;

/* Check sizes, finiteness, gaps, restitution and the yielding springs;
 * message names the field. */
PD_API int pd_model_check(const pd_model *model, pd_err *err);

/* PD_EINVAL naming the method when the model has yielding springs (a method
 * that models none); PD_OK otherwise (PD_EINVAL for a NULL argument). */
PD_API int pd_model_refuse_yield(const pd_model *model, const char *method, pd_err *err);

/* The kind the automatic choice gives this model (never PD_FACTOR_AUTO):
 * requested itself unless it is PD_FACTOR_AUTO.  A NULL model gives
 * PD_FACTOR_AUTO. */
PD_API pd_factor_kind pd_factor_choose(const pd_model *model, pd_factor_kind requested);

/* ---- state and observers ---------------------------------------------- */

typedef struct pd_state {
    long step;              /* steps taken since reset */
    double t;               /* time */
    double *q, *v;          /* n displacements and velocities */
    double *P;              /* m contact impulses over the last step */
    double *g;              /* m gaps g0 + W^T q at t */
    unsigned char *active;  /* m flags: contact was in the last step's LCP */
    int nactive;            /* number of active contacts in the last step */
    int lcp_pivots;         /* pivots (or iterations) of the last step's LCP (0: none) */
    const char *lcp_solver; /* solver of the last step's LCP ("closed-form" for the
                               scalar kernel, NULL when none was solved) */
    double *acc;            /* n accelerations q'' at t, valid when has_acc (the
                              on_step reports of the event-driven and penalty methods;
                              Moreau-Jean to a tolerance: the right limit at t) */
    int has_acc;
    const double *acc_right; /* Moreau-Jean to a tolerance: n, the accelerations' right
                              limit at t, where the forcing jumps (a piece's start: acc
                              holds the left limit, the end of the step to t); acc
                              itself elsewhere; NULL for the other methods */
    int impact;              /* Moreau-Jean to a tolerance: 1 when the step to t had an
                              impact (its velocities jump inside it: no interpolation
                              across it); 0 otherwise */
    double h;                /* Moreau-Jean: the size of the last step */
    const double *up;        /* newmark with yielding springs: the ns plastic offsets at t
                              (NULL otherwise) */
    const double *err;       /* Moreau-Jean to a tolerance: n, the error estimate of each
                              dof accumulated over the steps so far, in units of q
                              (velocity errors e_v counted as e_v / w_i, w_i^2 = K_ii /
                              M_ii); NULL for fixed steps and the other methods */
} pd_state;

/* Called with the state after reset and after every step: return 0 to go
 * on, a positive value to stop the run early (not an error). */
typedef int (*pd_observer)(const pd_state *state, void *ctx);

/* ---- Moreau–Jean theta scheme (SPEC §2) ------------------------------- */

typedef enum {
    PD_KERNEL_AUTO = 0,   /* scalar kernel when n = 1 and m <= 1, else general */
    PD_KERNEL_GENERAL = 1 /* the general kernel always (tests compare them) */
} pd_kernel;

/* Called after every contact LCP a step solves (solved or not): the
 * Delassus block D (dense or compressed columns), the vector b, the
 * impulses z, w = D z + b, what the solver reported, the active contacts
 * idx (nI = D->rows of them) and the time at the end of the step.  Return
 * > 0 to stop the run. */
typedef int (*pd_lcp_observer)(const pd_matrix *D, const double *b, const double *z,
                               const double *w, const pd_lcp_info *info, const int *idx, double t,
                               void *ctx);

/* The finest level of the adaptive ladder h 2^-k (pd_mj_opts.max_level). */
#define PD_MJ_MAX_LEVEL 48

typedef struct pd_mj_opts {
    double h;           /* step size > 0 (rtol > 0: the coarsest step, h0) */
    double theta;       /* in [1/2, 1] */
    double gamma;       /* active-set look-ahead in [0, 1] */
    int allow_unstable; /* accept theta in [0, 2] outside [1/2, 1] (stability studies) */
    pd_kernel kernel;
    pd_factor_kind factor;    /* storage of What */
    pd_lcp_method lcp_solver; /* the contact LCP solver */
    pd_lcp_observer on_lcp;   /* optional: every LCP solved (dumps, solver studies; with
                                  rtol > 0 also those of steps the controller rejects) */
    void *on_lcp_ctx;
    /* ---- to a tolerance (docs/scheme.md, "Moreau–Jean to a tolerance") ---- */
    double rtol;            /* > 0: steps h 2^-k chosen so that the state's error stays within
                           rtol of each dof's running amplitude (pd_mj_run_until); 0: fixed
                           steps h */
    double atol;            /* > 0: the amplitude below which a dof's error is measured
                           absolutely (units of q) */
    const double *atol_dof; /* optional, n: atol per dof */
    int max_level;          /* finest level k, in [1, PD_MJ_MAX_LEVEL] */
    double max_evals;       /* steps computed (kept or not) before refinement stops, >= 1 */
    double sim_gap;         /* coupled impacts closer than this (a step of h |U| <= sim_gap,
                           units of q) are simultaneous: one LCP, as the exact reference's
                           close_tol; >= 0 */
    int yield_lcp_max;      /* yielding springs (pd_model.ns): 0: springs each alone on a dof
                          (rows of SDOFs) with the sliding set in the contacts' LCP (the
                          contacts' solver; block Gauss-Seidel when it does not settle),
                          the others by the dense LCP (pivoting) of their pieces of at most
                          512 unknowns; -1: such rows by block Gauss-Seidel; > 0: every
                          piece by the dense LCP of at most this many (Gauss-Seidel beyond
                          when its springs are alone on a dof, else PD_EBUDGET) */
    const struct pd_piecewise_force *pieces; /* with rtol > 0: the model's force as
                           pieces (F = b f(t), pd_piecewise_force below; the model's force
                           callback must agree): flights between the contacts' impulses
                           exact for each block of dofs M, C, K couple, impulses at
                           mid-step; NULL: theta flights */
} pd_mj_opts;

/* Defaults: h = 0 (must be set), theta = 1/2, gamma = 1/2, automatic kernel,
 * factor and LCP solver; fixed steps (rtol 0; atol 1e-12, max_level 48, max_evals
 * 1e9, sim_gap 1e-10, theta flights for rtol > 0). */
PD_API pd_mj_opts pd_mj_default_opts(void);

typedef struct pd_mj pd_mj;

/* Allocate every workspace, form What = M + h theta C + h^2 theta^2 K and
 * factor it once, precompute the Delassus data; the state is at rest at
 * t = 0.  The model must outlive the object.  NULL on failure (err says why). */
PD_API pd_mj *pd_mj_alloc(const pd_model *model, const pd_mj_opts *opts, pd_err *err);
PD_API void pd_mj_free(pd_mj *mj);

/* Set t, q, v (NULL = zeros) and clear impulses; recomputes gaps. */
PD_API int pd_mj_reset(pd_mj *mj, double t0, const double *q0, const double *v0, pd_err *err);

/* Advance one step of size h.  Fails, naming the time and the contact, when
 * the LCP is not solved or the state is not finite.  Fixed steps only
 * (PD_EINVAL for rtol > 0). */
PD_API int pd_mj_step(pd_mj *mj, pd_err *err);

/* Take nsteps steps, calling observer (may be NULL) after reset state and
 * after each step; stops early when the observer asks.  Fixed steps only. */
PD_API int pd_mj_run(pd_mj *mj, long nsteps, pd_observer observer, void *ctx, pd_err *err);

/* Advance to t_end, calling observer after the reset state (the first call
 * after a reset) and after every step kept: fixed steps of h (as pd_mj_run
 * with pd_steps_for's count), or with rtol > 0 the adaptive steps: each
 * step h_k = h 2^-k (k <= max_level) is taken once whole and once as two
 * halves; the halves are kept when they agree with the whole step within
 * the tolerance (rtol times each dof's running amplitude, spread over the
 * run in proportion to the step), else the step is halved.  A step in which
 * a contact starts or stops pushing is halved until the instant is known
 * as well as rtol needs, and coupled impacts closer than a step are taken
 * one at a time (down to sim_gap).  The state's err holds the estimate so
 * far.  The breakpoint model->breaks[0] (when > 0) is a whole number of
 * steps h from t = 0 (h is lowered to make it so), so that the force's jump
 * falls between steps.  t_end is reached to within h 2^-max_level. */
PD_API int pd_mj_run_until(pd_mj *mj, double t_end, pd_observer observer, void *ctx, pd_err *err);

/* What a run to a tolerance did (fixed steps: steps taken, no rejections,
 * h_min = h_max = h, err_max NAN). */
typedef struct pd_mj_stats {
    long steps;          /* steps kept */
    long rejected;       /* steps computed and thrown away (the whole steps of kept pairs
                            not counted) */
    long evals;          /* steps computed in all */
    double h_min, h_max; /* the smallest and largest step kept */
    int floor_hit;       /* a step at the finest level failed its test: rtol not met */
    int budget_hit;      /* max_evals stopped the refinement: rtol not met */
    double err_max;      /* the largest estimate over the dofs, relative to their
                            amplitude, at the end */
    double h0;           /* the coarsest step (h, lowered to the breakpoint) */
    /* yielding springs on rows of SDOFs (0 otherwise): the contacts' LCPs the
     * sliding set tried (about 1.3 a step), and the steps block Gauss-Seidel
     * took (yield_lcp_max -1, or a sliding set that did not settle) */
    long yield_set_tries, yield_gs_steps;
} pd_mj_stats;
PD_API int pd_mj_get_stats(const pd_mj *mj, pd_mj_stats *s);

PD_API const pd_state *pd_mj_state(const pd_mj *mj);

/* Which kernel the object runs: "scalar" or "general"; which factor kind
 * ("scalar", "dense", "cholmod"). */
PD_API const char *pd_mj_kernel_name(const pd_mj *mj);
PD_API const char *pd_mj_factor_name(const pd_mj *mj);

/* Closed-form scalar LCP: the P >= 0 with D P + b >= 0, P (D P + b) = 0,
 * for D > 0 (the one-contact kernel uses it instead of Lemke). */
PD_API double pd_contact_impulse_1(double D, double b);

/* Number of steps to cover [0, tend] with step h (tend/h rounded when
 * within 1e-9 of an integer, else rounded up). */
PD_API long pd_steps_for(double tend, double h);

/* ---- Moreau–Jean for a batch of one-DOF systems (engine/mj_batch.c) ---- *
 * PD_MJB_LANES independent systems  M q'' + C q' + K q = F(t) + W lambda,
 * each with at most one contact (gap g0 + W q) and at most one force
 * breakpoint, advanced together by the arithmetic of pd_mj's scalar kernel:
 * lane l's numbers are the ones pd_mj gives for its system alone, bit for
 * bit (tests/test_engine.c), at a fraction of the cost (the lanes fill the
 * processor's vector units and overlap their dependency chains).  Lanes
 * share theta and gamma; each has its own step h, its own clock, and can be
 * restarted with another system while the others run, so that a queue of
 * systems of different lengths keeps every lane busy.  One force call per
 * step gives every lane its force.  The object holds every number (no
 * allocation, no failure once set up). */
#define PD_MJB_LANES 32

typedef struct pd_mjb_lane {
    double M, C, K;  /* M > 0 */
    int wall;        /* 1: the contact exists */
    double W, g0, e; /* its direction (nonzero), initial gap >= 0, restitution in [0, 1] */
    double h;        /* step > 0 */
    double brk;      /* the force's breakpoint (INFINITY: none) */
} pd_mjb_lane;

/* F[l] = lane l's force at time t[l] (its left limit for side = -1, right
 * limit for +1), for every lane l < PD_MJB_LANES. */
typedef void (*pd_mjb_force)(const double *t, int side, double *F, void *ctx);

typedef struct pd_mjb pd_mjb;
typedef void (*pd_mjb_step_fn)(pd_mjb *b); /* private */

/* Laid out in whole 64-byte lines: an object at a 64-byte boundary
 * (aligned_alloc(64, ...); the compiler's own placement of a declared one
 * is 16) has every lane array on cache-line boundaries, which the wide
 * loads of the step run fastest on. */
struct pd_mjb {
    double theta, gamma;
    pd_mjb_step_fn lanes_step; /* private: the step for this processor */
    pd_mjb_force force;
    void *force_ctx;
    long iter;                   /* batch steps taken */
    long next_event;             /* iter at which a lane meets its breakpoint */
    long reserved;               /* (the first line's last word) */
    long brk_iter[PD_MJB_LANES]; /* iter at which lane l does (LONG_MAX: never) */
    double t[PD_MJB_LANES];      /* lane clocks */
    double steps[PD_MJB_LANES];  /* lane step counts (whole numbers) */
    double q[PD_MJB_LANES];      /* displacements at t */
    double v[PD_MJB_LANES];      /* velocities at t */
    double g[PD_MJB_LANES];      /* gaps at t */
    double P[PD_MJB_LANES];      /* impulses of the last step */
    double F0[PD_MJB_LANES];     /* forces at t+ */
    double F1[PD_MJB_LANES];     /* forces at the step's end (scratch) */
    double h[PD_MJB_LANES], brk[PD_MJB_LANES];
    double coef[11 * PD_MJB_LANES]; /* private: the lanes' constants */
};

/* Set theta, gamma (opts as pd_mj's: theta, gamma, allow_unstable; h and
 * the kernel, factor and LCP fields are not used; opts NULL: the defaults)
 * and the force (NULL: none); every lane idle (a unit mass at rest, no
 * contact, h = 1). */
PD_API int pd_mjb_init(pd_mjb *b, const pd_mj_opts *opts, pd_mjb_force force, void *force_ctx,
                       pd_err *err);

/* Start lane l afresh with the system ln, at rest at its time 0 (the
 * force is asked for every lane's F(t+); only lane l's is kept). */
PD_API int pd_mjb_set_lane(pd_mjb *b, int l, const pd_mjb_lane *ln, pd_err *err);

/* Take nsteps steps of every lane, calling observer (may be NULL) after
 * each; stops early when it returns > 0. */
typedef int (*pd_mjb_observer)(const pd_mjb *b, void *ctx);
PD_API void pd_mjb_run(pd_mjb *b, long nsteps, pd_mjb_observer observer, void *ctx);

/* 1 when lane l's state is finite (a state that stops being finite stays
 * so): otherwise its run is repeated alone by pd_mj to name the step where
 * it failed. */
PD_API int pd_mjb_finite(const pd_mjb *b, int l);

/* ---- event-driven reference for the general system (engine/event_general.c) --- *
 * Smooth motion between events integrated by GSL (rk8pd, tight tolerances)
 * with the persistent contacts held by the acceleration-level LCP
 * (paper Eqs. 2, 7); every gap closing located by root finding; impacts of
 * all contacts at zero gap in one velocity-level LCP with Newton's law
 * (Eqs. 3, 4, 8, 9); detachment when a contact force reaches zero; force
 * breakpoints as events; accumulations of impacts jumped to persistent
 * contact (criterion in docs/methods.md). */
typedef struct pd_edg_opts {
    double rtol, atol;   /* GSL tolerances > 0 */
    double h_out;        /* > 0: observer every h_out (and at t1) and at every event;
                               its P: each contact's impulse since its last report, the
                               held force integrated plus the impacts'; 0: every
                               event/step, P the impacts at that instant */
    int impacts_only;    /* 1: with h_out > 0 the observer's P holds the impacts only */
    int no_accumulation; /* 1: never jump an accumulation */
    long max_events;     /* event budget >= 1 */
    long max_burst;      /* impacts of one accumulation before giving up, >= 1 */
    double length_scale; /* accumulation jumped once the bounce height is below
                               1e-10 * length_scale (> 0), as in pd_ed_opts */
    double time_unit;    /* > 0: the model's unit of time in seconds, for messages */
    pd_observer on_step; /* optional: the state with its accelerations at t0, at the
                               end of every accepted step, just before every event and
                               just after it (same t), whatever h_out */
    void *on_step_ctx;
    pd_factor_kind factor;    /* storage of M */
    pd_lcp_method lcp_solver; /* the impact and contact-force LCPs */
} pd_edg_opts;

/* rtol 1e-12, atol 1e-14, h_out 0 (with an output grid: P with the held
 * forces), accumulations jumped, 10^6 events,
 * bursts of 10^5, length scale 1, automatic factor and solver. */
PD_API pd_edg_opts pd_edg_default_opts(void);

typedef struct pd_edg_result {
    long impacts, accumulations, detachments, events, steps;
    double first_impact; /* NAN when none */
    double contact_time; /* summed over contacts: time spent in persistent contact */
} pd_edg_result;

/* Run the model from (t0, q0, v0) (NULL = zeros) to t1 (opts NULL: the
 * defaults).  The observer gets pd_state: P holds the impulses of an impact
 * at that instant (zero otherwise; with h_out > 0 and not impacts_only,
 * each contact's impulse since the observer's previous report: its held
 * force integrated by the integrator, to its tolerances, plus the impacts'),
 * active flags the contacts in persistent contact.  on_step's P holds the
 * impacts at that instant only. */
PD_API int pd_edg_run(const pd_model *model, double t0, const double *q0, const double *v0,
                      double t1, const pd_edg_opts *opts, pd_observer observer, void *ctx,
                      pd_edg_result *res, pd_err *err);

/* ---- penalty baseline (engine/penalty.c) -------------------------------- */

/* What practitioners use today: a contact element per contact, active while
 * the gap is negative (penetration d = -g > 0), integrated with GSL's
 * adaptive odeiv2 steppers.
 *   Kelvin-Voigt (Anagnostopoulos):  lambda = kc d + c d'        (c from e)
 *   Hertz-damp (Muthukumar–DesRoches): lambda = kc d^1.5 + c d^1.5 d'
 * Damping constants follow from the restitution e of each contact and, for
 * Hertz-damp, from the approach speed at the start of each contact; see
 * docs/methods.md. */
typedef enum { PD_PENALTY_KELVIN = 0, PD_PENALTY_HERTZDAMP = 1 } pd_penalty_law;

typedef struct pd_penalty_opts {
    pd_penalty_law law;
    double kc;           /* contact stiffness (force per unit penetration[^1.5]) > 0 */
    double rtol, atol;   /* adaptive tolerances > 0 */
    const char *stepper; /* GSL stepper: "rk8pd", "rkf45", "rk4imp", "msbdf"; or "newmark":
                            fixed steps h of the implicit average-acceleration Newmark
                            scheme with Newton iterations (rtol, atol unused) */
    double h;            /* newmark: the step > 0 (the others ignore it) */
    double h_out;        /* > 0: the observer is called every h_out (and at t1) */
    long max_steps;      /* budget of accepted steps >= 1 */
    double time_unit;    /* > 0: the model's unit of time in seconds, for messages */
    pd_observer on_step; /* optional: called at t0 and after every accepted step
                            whatever h_out (measurements next to the outputs); where
                            elements switch, twice: the step's end under the engaged
                            set it ran with (acc its left limits), then the same
                            instant after the switch (right limits) */
    void *on_step_ctx;
    pd_factor_kind factor; /* storage of M */
    int max_newton;        /* newmark: Newton iterations of a step before it has failed (0:
                              50); a failed step with yielding springs is redone at their
                              initial stiffness and counted, without them an error */
} pd_penalty_opts;

/* Kelvin-Voigt, kc = 0 (must be set), rtol 1e-10, atol 1e-12, rk8pd,
 * h_out 0, 10^8 steps, time unit 1 s, no on_step, automatic factor, newmark's
 * 50 Newton iterations a step.  A run
 * whose steps stop advancing (elements switching at one instant: 1000
 * steps in a row advancing t by less than 1e-12 of it) ends PD_ENUMERICAL. */
PD_API pd_penalty_opts pd_penalty_default_opts(void);

typedef struct pd_penalty_result {
    long steps; /* accepted steps */
    long rhs;   /* right-hand-side evaluations (probes included) */
    double min_gap;
    double max_penetration_velocity; /* largest -W_a^T v while contact a is engaged */
    long switches;                   /* contact elements engaged or released (located crossings) */
    const char *stepper;             /* canonical GSL stepper name (static string) */
    long newton_failures;   /* newmark: steps whose Newton iterations did not converge (each
                             then converged with the yielding springs' initial stiffness) */
    long newton_iterations; /* newmark: Newton iterations over the run */
    int diagonal_mass;      /* 1: M was diagonal and inverted entrywise (no factor) */
} pd_penalty_result;

/* Integrate the model from (t0, q0, v0) to t1 (NULL = zeros; opts NULL: the
 * defaults).  The observer
 * gets a pd_state at t0, at every t0 + k h_out and at t1; in it P holds the
 * contact forces lambda at that instant (not impulses) and active the
 * engaged elements.  Output states are integrated (to the tolerances) from
 * the last accepted step, so h_out never changes the trajectory.  Extremes
 * that fall between outputs are the caller's to track through on_step, or
 * an observer with h_out = 0: then it is called after every accepted step.
 * Steps end exactly at every breakpoint and at every located gap crossing
 * (the state there is reported with the element already switched).
 * Turns GSL's aborting error handler off for the whole process. */
PD_API int pd_penalty_run(const pd_model *model, double t0, const double *q0, const double *v0,
                          double t1, const pd_penalty_opts *opts, pd_observer observer, void *ctx,
                          pd_penalty_result *res, pd_err *err);

/* ---- closed forms for one linear oscillator --------------------------- */

/* u'' + 2 xi w0 u' + w0^2 u = F(t),  0 <= xi < 1, w0 >= 0 (w0 = 0: a free
 * mass, xi ignored). */
typedef struct pd_sdof {
    double w0, xi;
} pd_sdof;

/* One piece of forcing, from t_start until the next piece's t_start:
 *   F(t) = A sin(w t + phi) + c0 + c1 (t - t_start).
 * c0 = c1 = 0 (what designated or positional initialisers leave out) is the
 * pure sinusoid; A = 0 with c0, c1 is one linear segment of a sampled record
 * (w = 0 with A is the constant A sin(phi)). */
typedef struct pd_sine_piece {
    double t_start, A, w, phi;
    double c0, c1;
} pd_sine_piece;

/* F(t) of one piece (t need not lie inside it). */
PD_API double pd_sine_piece_force(const pd_sine_piece *pc, double t);

/* Advance the exact solution under the piece pc from (u0, v0) at t0 to t1:
 * the sinusoid's particular solution plus the damped free vibration
 * (undamped resonance handled), and by linearity the response to the linear
 * term from rest, u(h) = f0 G1(h) + c1 G2(h) with f0 = F_lin(t0) and G1, G2
 * the first two integrals of the impulse response (Taylor series for
 * w0 |t1 - t0| <= 1, closed forms beyond).  The increment form returns
 * du = u(t1) - u0 computed without cancellation (full relative precision
 * for short intervals). */
PD_API void pd_sdof_increment_piece(const pd_sdof *osc, const pd_sine_piece *pc, double t0,
                                    double u0, double v0, double t1, double *du, double *v1);
PD_API void pd_sdof_advance_piece(const pd_sdof *osc, const pd_sine_piece *pc, double t0, double u0,
                                  double v0, double t1, double *u1, double *v1);

/* A flight from (t0, u0, v0) under one piece with what does not depend on
 * t1 computed once (the particular solution's phase at t0, the homogeneous
 * constants), so that each later time costs two sincos and one expm1 (the
 * half angles give sin, cos and cos - 1 alike).  Equal to
 * pd_sdof_increment_piece to rounding; cases without that form (a free
 * mass, undamped resonance) fall back to it. */
typedef struct pd_sdof_flow {
    pd_sdof osc;
    pd_sine_piece pc;
    double t0, u0, v0;
    int fast;           /* 1: the cached form applies */
    int constf;         /* 1: no ramp (c1 = 0): the constant's particular solution
                                folded into the sinusoid's, no series */
    double a, wd, k0;   /* xi w0, the damped frequency, w0^2 */
    double s0, c0;      /* sin, cos of the forcing phase at t0 */
    double pre, pim;    /* A re / den, A im / den: the particular's amplitudes */
    double vp0, c1, c2; /* v_p(t0) and the homogeneous constants */
    double f0, ur, vr;  /* the linear force at t0, its response's start state */
    double mass_c;      /* > 0: a damped free mass u'' + mass_c u' = F instead
                           (pd_sdof_flow_init_mass); 0: the oscillator */
} pd_sdof_flow;
PD_API void pd_sdof_flow_init(pd_sdof_flow *f, const pd_sdof *osc, const pd_sine_piece *pc,
                              double t0, double u0, double v0);
/* A damped free mass's flight, u'' + c u' = F (c > 0: an elastic-perfectly-
 * plastic spring's slide), from (t0, u0, v0) under one piece. */
PD_API void pd_sdof_flow_init_mass(pd_sdof_flow *f, double c, const pd_sine_piece *pc, double t0,
                                   double u0, double v0);
/* du = u(t1) - u0 and v(t1) of the flight. */
PD_API void pd_sdof_flow_at(const pd_sdof_flow *f, double t1, double *du, double *v1);

/* The sinusoid alone, F = A sin(w t + phi) (A = 0: free vibration; w = 0
 * with w0 = 0: the constant force A sin(phi)): the piece {t0, A, w, phi}. */
PD_API void pd_sdof_advance(const pd_sdof *osc, double A, double w, double phi, double t0,
                            double u0, double v0, double t1, double *u1, double *v1);
PD_API void pd_sdof_increment(const pd_sdof *osc, double A, double w, double phi, double t0,
                              double u0, double v0, double t1, double *du, double *v1);

/* ---- exact event-driven reference for rows (engine/event_row.c) -------- *
 * For models whose structures are linear between events under a force
 * F(t) = b f(t), f a sequence of pd_sine_piece (pulses, harmonics, the
 * linear pieces of a record): each structure (block of dofs that M, C, K
 * couple; M diagonal) or cluster of structures held by persistent contacts
 * moves by an exact closed-form flight (an underdamped oscillator for SDOFs
 * and rigid trees of them, complex modes otherwise), so the reference is
 * exact to rounding.  Events are asynchronous: each contact's next closing
 * is predicted from the flights of its two sides (a scan at 1/64 of the
 * shortest period of the pair that cannot miss a grazing dip, roots to
 * adjacent doubles), a priority queue orders them, and an event changes
 * only the cluster it touches, so its cost does not grow with the row.
 * At an impact the contacts closed within close_tol take impulses in
 * stages, each an LCP with Newton's law over the closed contacts that are
 * not separating (paper Eqs. 3, 4, 8, 9), persistence is decided by the
 * contact-force LCP (Eqs. 2, 7), detachment root-found on the closed-form
 * contact forces, accumulations of impacts jumped to their limit
 * (docs/methods.md). */
typedef struct pd_piecewise_force {
    const double *b;             /* n: F(t) = b f(t) */
    const pd_sine_piece *pieces; /* f: piece k from pieces[k].t_start to the next start */
    int npieces;                 /* >= 1 */
} pd_piecewise_force;

/* What an event did, for observers (momentum and energy tests). */
typedef enum { PD_EDR_IMPACT = 0, PD_EDR_DETACH = 1, PD_EDR_PIECE = 2 } pd_edr_kind;

typedef struct pd_edr_event {
    double t;
    pd_edr_kind kind;
    int ncontacts; /* the contacts taken as closed (impact) or re-decided */
    const int *contacts;
    const double *P;                /* their impulses (impact) */
    const double *U_minus, *U_plus; /* their gap rates before and after */
    int ndofs;                      /* the dofs of the clusters involved */
    const int *dofs;
    const double *v_minus, *v_plus; /* their velocities before and after */
    const double *x;                /* their positions at t */
    int accumulation;               /* an accumulation of impacts was jumped here */
} pd_edr_event;

typedef int (*pd_edr_event_fn)(const pd_edr_event *ev, void *ctx);

/* The impact law at an impact of several closed contacts (docs/methods.md,
 * "The impact law"):
 *   STAGED  LCPs with Newton's law over the closed contacts that are not
 *           separating, stage after stage until none closes (dissipative);
 *   SINGLE  one LCP over every closed contact, Newton's law on each one's
 *           rate before the impact: U+ = U- + D P, 0 <= U+ + e min(U-, 0)
 *           _|_ P >= 0 (as event-general and Moreau-Jean pose it).
 * They agree wherever an impact ends in one stage. */
typedef enum { PD_IMPACT_STAGED = 0, PD_IMPACT_SINGLE = 1 } pd_impact_law;

typedef struct pd_edr_opts {
    double close_tol;         /* at an impact, contacts with gap <= close_tol * length_scale
                              are closed too (one LCP); >= 0 */
    double length_scale;      /* > 0: the scene's length (1 in the reference units) */
    double time_unit;         /* > 0: the model's unit of time in seconds (1 / wp for a
                              scene), for the times the messages give */
    double t_measure;         /* extremes count from here */
    double h_out;             /* > 0: the observer every h_out from t0 (and at t1); its
                              state's P: each contact's impulse since the last
                              output, the impacts' plus its held force integrated */
    int impacts_only;         /* 1: the outputs' P hold the impacts only (cheaper) */
    const int *below;         /* NULL, or n: the dof whose displacement is subtracted for the
                              drift of dof i (-1: the ground) */
    int no_accumulation;      /* 1: never jump an accumulation */
    int inactive;             /* 1: contacts are measured (gaps) but never act (free twins) */
    long max_events;          /* impacts, detachments and piece changes >= 1 */
    long max_burst;           /* impacts of one contact before it rests or leaves, >= 1 */
    double max_evals;         /* flight evaluations (the cost) before PD_EBUDGET, >= 1 */
    int scan_divisions;       /* scan step: shortest period / this, >= 1 */
    pd_lcp_method lcp_solver; /* the LCPs on the dofs (a modal cluster takes part, or more
                                 than 64 contacts between clusters); the clusters' own
                                 LCPs are Lemke's */
    pd_impact_law impact_law; /* PD_IMPACT_STAGED (the default) or PD_IMPACT_SINGLE */
    pd_edr_event_fn on_event; /* optional: every impact, detachment, piece change */
    void *on_event_ctx;
    int energy; /* 1: the energy balance's terms (pd_edr_result; Gauss-Legendre on
                   every scan interval of the flights) */
} pd_edr_opts;

/* close_tol 1e-10 (the accumulation's bounce height: one "in contact"
 * scale), length scale 1, time unit 1 s, t_measure 0, no output grid (its P
 * with the held forces when there is one), drift of
 * each dof against the ground, accumulations jumped, active contacts, 10^7
 * events, bursts of 10^5, 4e9 evaluations, 64 scan divisions, automatic
 * LCP solver, the staged impact law, no energy balance. */
PD_API pd_edr_opts pd_edr_default_opts(void);

typedef struct pd_edr_result {
    long events, impacts, simultaneous, tol_closed, accumulations, detachments;
    long lcp_solves;
    long modal_bases;    /* cluster configurations diagonalised */
    double evals;        /* flight evaluations */
    double first_impact; /* NAN: none */
    double t_reached;
    double max_penetration; /* deepest gap below zero the measurement found (rounding) */
    /* per dof (n), over [t_measure, t1]: */
    const double *xpos, *xneg; /* max x, max -x */
    const double *drift;       /* max |x_i - x_below(i)| */
    /* per contact (m): */
    const long *contact_impacts;
    const double *first;        /* NAN: none */
    const double *max_impulse;  /* largest impulse of one event */
    const double *contact_time; /* time held (persistent, or locked in a cycle) */
    const double *min_gap;      /* smallest gap (0 once closed) */
    long law_decided;           /* impacts whose LCP could take several closed contacts, one
                              closing (separating ones included): where the staged and
                              single impact laws may differ */
    /* per yielding spring (ns): */
    int ns;
    const double *up;                /* the plastic offset at t_reached */
    const double *plastic_excursion; /* sum of |d up| */
    const long *yield_onsets;        /* slides begun */
    /* opts.energy (0 otherwise), from t0 to t_reached:
       input_work = (kinetic + strain) - energy0 + damping_work + hysteretic + impact_loss */
    double input_work;   /* int (b f) . v dt */
    double damping_work; /* int v^T C v dt */
    double impact_loss;  /* the kinetic energy the impacts (and held contacts' starts) took */
    double hysteretic;   /* the sliders' work, sum ks uy excursion */
    double kinetic;      /* v^T M v / 2 at t_reached */
    double strain;       /* q^T K q / 2 - sum ks up d + sum ks up^2 / 2 at t_reached */
    double energy0;      /* kinetic + strain at t0 */
} pd_edr_result;

typedef struct pd_edr pd_edr;

/* Check the model (M diagonal and positive, every contact joining at most
 * two structures), find its structures and allocate every workspace.  The
 * model and force (both required) must outlive the object; opts NULL: the
 * defaults.  NULL on failure (err says why). */
PD_API pd_edr *pd_edr_alloc(const pd_model *model, const pd_piecewise_force *force,
                            const pd_edr_opts *opts, pd_err *err);
PD_API void pd_edr_free(pd_edr *r);

/* Run from (t0, q0, v0) (NULL = zeros) to t1.  The observer gets pd_state
 * at t0 and every h_out (P: the impulses since the previous call; active:
 * the persistent contacts).  PD_EBUDGET when a budget runs out, with the
 * time in the message. */
PD_API int pd_edr_run(pd_edr *r, double t0, const double *q0, const double *v0, double t1,
                      pd_observer observer, void *ctx, pd_err *err);

/* The last run's results (valid until the next run or pd_edr_free).  During
 * a run (from its observer) contact_impacts holds the impacts so far. */
PD_API const pd_edr_result *pd_edr_result_of(const pd_edr *r);

/* ---- event-driven reference: one oscillator, one wall (event_sdof.c) --

 *   x'' + 2 xi w0 x' + w0^2 x = F(t) - lambda,  g = delta - x >= 0,
 * F piecewise: sinusoids plus linear terms (pd_sine_piece; a strong-motion
 * record is one linear piece per sample interval).  Exact closed-form
 * flight between events; gap closings (and grazing) located by bracketing
 * on a scan grid (the shortest period / scan_divisions, never wider than a
 * piece) plus bisection to machine precision, a turn of the velocity and
 * back inside one scan interval included; Newton impacts; persistent
 * contact while lambda = F - w0^2 delta >= 0 (the acceleration-level LCP of
 * one contact; on a linear piece its zero is closed-form); accumulations of
 * impacts jumped with the bouncing-ball tail t_inf = t_i + 2 v+ / (a (1 - e)).
 * Extremes are the exact continuous ones.  Each piece boundary is one cheap
 * event (one closed-form evaluation per scan interval). */

typedef struct pd_ed_sdof {
    pd_sdof osc;
    int wall;     /* 0: no wall (the free twin) */
    double delta; /* wall at x = delta >= 0 */
    double e;     /* Newton restitution in [0, 1] */
    int npieces;  /* >= 1; pieces[0].t_start is the start time, starts
                       non-decreasing and finite (PD_EINVAL otherwise) */
    const pd_sine_piece *pieces;
    /* a yielding spring (SPEC §7; uy 0, or alpha 1: elastic): w0^2 [alpha x +
     * (1 - alpha) z], |z| <= uy, the motion in phases of closed-form flights
     * (elastic, or sliding with stiffness alpha w0^2); the sliding phase must be
     * underdamped (xi < sqrt(alpha)), or a free mass (alpha = 0), or undamped
     * (xi = 0), the start inside |x| <= uy */
    double uy, alpha;
} pd_ed_sdof;

typedef struct pd_ed_opts {
    double t_end;
    double t_measure;    /* extremes count from here on */
    double h_out;        /* > 0: sampler at t_start + k h_out */
    int no_accumulation; /* 1: never jump an accumulation (shows the stall) */
    long max_events;     /* event budget >= 1 */
    long max_burst;      /* impacts in one accumulation before giving up, >= 1 */
    double length_scale; /* an accumulation is jumped once its bounce height
                             v+^2 / (2 a) is below 1e-10 * length_scale (> 0):
                             the motion left out stays that close to the wall */
    int scan_divisions;  /* bracketing grid: shortest period / this, >= 1 */
    /* optional: every impact at t with the approach speed vn and the rebound
     * -e vn (before an accumulation jumped or a rest begins) */
    void (*on_impact)(double t, double vn, double v_plus, void *ctx);
    void *on_impact_ctx;
    int energy; /* 1: the energy balance's terms (pd_ed_result; Gauss-Legendre on
                   every scan interval of the flights: about 3x the cost) */
} pd_ed_opts;

/* t_end 0 (must be set), t_measure 0, h_out 0, accumulations jumped, 10^7
 * events, bursts of 10^5, length scale 1, 64 scan divisions, no on_impact,
 * no energy balance. */
PD_API pd_ed_opts pd_ed_default_opts(void);

typedef struct pd_ed_result {
    double xmax, xtoward, xaway; /* max |x|, max x, max -x over the window */
    long impacts, accumulations, detachments, events;
    double first_impact, first_impact_velocity, max_impact_velocity; /* NAN: none */
    double contact_time; /* time spent resting on the wall */
    double t_reached;    /* where the run stopped (t_end unless it failed) */
    double impulse;      /* sum of the impacts' impulses (1 + e) vn per unit mass */
    /* a yielding spring's (0 when elastic): */
    double up;         /* the plastic offset x - z at the end (during the run: at the
                          sampler's t) */
    long n_yield;      /* slides begun (yield onsets) */
    double excursion;  /* sum of |d up| */
    double hysteretic; /* the slider's work (1 - alpha) w0^2 uy excursion */
    /* opts->energy (0 otherwise), per unit mass from the start to where the run
       stopped: input = (kinetic + strain) - (their values at the start) + damping
       + hysteretic + impact_loss */
    double input_work;   /* int F x' dt */
    double damping_work; /* int 2 xi w0 x'^2 dt */
    double impact_loss;  /* (1 - e^2) vn^2 / 2 per impact; an accumulation's tail v+^2 / 2 */
    double kinetic;      /* x'^2 / 2 at the end */
    double strain;       /* w0^2 (alpha x^2 + (1 - alpha) z^2) / 2 at the end (z = x elastic) */
} pd_ed_result;

/* Called on the output grid with the exact state; return > 0 to stop. */
typedef int (*pd_ed_sampler)(double t, double x, double v, int in_contact, void *ctx);

/* Run from (x0, v0) at pieces[0].t_start to opts->t_end (opts NULL: the
 * defaults, t_end 0).  res is kept up to date as the run goes: the sampler
 * may read the impacts and their impulse so far.  PD_EBUDGET when an event budget is exhausted (message
 * names the time and the count). */
PD_API int pd_ed_sdof_run(const pd_ed_sdof *prob, double x0, double v0, const pd_ed_opts *opts,
                          pd_ed_sampler sampler, void *ctx, pd_ed_result *res, pd_err *err);

#endif
