/* pd_root.h — (library-internal) the sign change of a scalar function in a
 * bracket, the event locators' one root finder (engine/event_sdof.c, the
 * one-wall reference; engine/event_row_scan.c, the rows'): bisection to
 * adjacent doubles or to a width, and safeguarded Newton on a closed-form
 * slope that bisection finishes. */
#ifndef PD_ROOT_H
#define PD_ROOT_H

/* f(t); with slope != NULL also *slope = f'(t). */
typedef double (*pd_root_fn)(void *ctx, double t, double *slope);

/* A function, its context and a count of its evaluations. */
typedef struct pd_root {
    pd_root_fn f;
    void *ctx;
    long evals;
} pd_root;

/* Bisection stops at adjacent doubles: hi - lo <= this of |hi|. */
#define PD_ROOT_REL 2e-16
/* At most this many halvings (a root at 0 has no relative width). */
#define PD_ROOT_BISECT_MAX 200
/* At most this many safeguarded Newton steps before bisection takes over. */
#define PD_ROOT_NEWTON_MAX 30

/* The width at which a bracket ending at hi is closed: max(w, PD_ROOT_REL |hi|). */
double pd_root_tol(double hi, double w);
/* Bisection between lo (f <= 0) and hi (f > 0) to the width w (0: adjacent
 * doubles); returns hi, the first double where f > 0 (w = 0). */
double pd_root_bisect(pd_root *r, double lo, double hi, double w);
/* The same bracket by safeguarded Newton from t0 (the middle when t0 is not
 * inside): a step leaving the bracket bisects; a converged step is the
 * answer to the width w > 0, or (w = 0) is closed around by probes that
 * double their distance (f's rounding may hold it at zero over many
 * doubles) and bisection finishes: the same hi as bisection. */
double pd_root_newton(pd_root *r, double lo, double hi, double w, double t0);

#endif
