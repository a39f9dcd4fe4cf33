/* root.c — the sign change of f in a bracket (pd_root.h).  Both methods
 * keep f(lo) <= 0 < f(hi) and return hi, so that an event is never located
 * before the function crossed. */
#include <math.h>
#include <stddef.h>

#include "pd_root.h"

/* f at t (and f' into *slope when wanted), counted. */
static double value(pd_root *r, double t, double *slope)
{
    r->evals++;
    return r->f(r->ctx, t, slope);
}

double pd_root_tol(double hi, double w)
{
    return fmax(w, PD_ROOT_REL * fmax(fabs(hi), 1e-300));
}

double pd_root_bisect(pd_root *r, double lo, double hi, double w)
{
    for (int it = 0; it < PD_ROOT_BISECT_MAX && hi - lo > pd_root_tol(hi, w); it++) {
        double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi) /* adjacent doubles */
            break;
        if (value(r, mid, NULL) > 0.0)
            hi = mid;
        else
            lo = mid;
    }
    return hi;
}

/* Around a converged root tn of a bracket (lo, hi): lo moved up to tn - tol
 * when f <= 0 there (else hi down to it), then probes above, each twice as
 * far as the last, until f > 0; the bracket left to bisection. */
static void close_around(pd_root *r, double tn, double tol, double *lo, double *hi)
{
    double a = fmax(tn - tol, *lo);
    if (a > *lo) {
        if (value(r, a, NULL) <= 0.0)
            *lo = a;
        else
            *hi = a;
    }
    for (double step = tol; fmax(tn, *lo) + step < *hi; step *= 2.0) {
        double b = fmax(tn, *lo) + step;
        if (value(r, b, NULL) > 0.0) {
            *hi = b;
            return;
        }
        *lo = b;
    }
}

double pd_root_newton(pd_root *r, double lo, double hi, double w, double t0)
{
    double t = t0 > lo && t0 < hi ? t0 : 0.5 * (lo + hi);
    for (int it = 0; it < PD_ROOT_NEWTON_MAX; it++) {
        double tol = pd_root_tol(hi, w);
        if (hi - lo <= tol)
            return hi;
        double df, f = value(r, t, &df);
        if (f > 0.0)
            hi = t;
        else
            lo = t;
        double tn = t - f / df;                            /* Newton: f + f' (tn - t) = 0 */
        if (tn >= lo && tn <= hi && fabs(tn - t) <= tol) { /* converged, on a bracket end too */
            if (w > 0.0)
                return tn; /* wanted to a width: Newton is there */
            close_around(r, tn, tol, &lo, &hi);
            break;
        }
        if (!(tn > lo && tn < hi)) { /* outside the bracket (or f' = 0): bisect */
            t = 0.5 * (lo + hi);
            continue;
        }
        t = tn;
    }
    return pd_root_bisect(r, lo, hi, w);
}
