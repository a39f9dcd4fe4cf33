/* sdof.c — exact motion of one damped linear oscillator under a sinusoid.
 *
 * Everything is computed as increments from the start state, with expm1 and
 * half-angle forms, so that u(t1) - u0 keeps full relative precision for
 * short intervals: the event-driven reference finds gap closings with it. */
#include <math.h>

#include "pd_engine.h"

/* sin(b) - sin(a) and cos(b) - cos(a) without cancellation. */
static void sin_cos_diff(double a, double b, double *ds, double *dc)
{
    double h = sin(0.5 * (b - a)), m = 0.5 * (a + b);
    *ds = 2.0 * cos(m) * h;
    *dc = -2.0 * sin(m) * h;
}

/* Free mass (w0 = 0): du = v0 s + the double integral of A sin(w t + phi). */
static void free_mass(double A, double w, double phi, double t0, double v0, double t1,
                      double *du, double *v1)
{
    double s = t1 - t0;
    if (w == 0.0) { /* constant force A sin(phi) */
        double a = A * sin(phi);
        *du = v0 * s + 0.5 * a * s * s;
        *v1 = v0 + a * s;
        return;
    }
    /* u_p = -A sin(th) / w^2, v_p = -A cos(th) / w, th = w t + phi */
    double ds, dc, th0 = w * t0 + phi;
    sin_cos_diff(th0, w * t1 + phi, &ds, &dc);
    double vp0 = -A * cos(th0) / w;
    *du = -A * ds / (w * w) + (v0 - vp0) * s;
    *v1 = v0 - A * dc / w;
}

/* Particular solution increments of u'' + 2 xi w0 u' + w0^2 u = A sin(w t + phi)
 * from t0 to t1: u_p = Im(A e^{i th} / (w0^2 - w^2 + 2 i xi w0 w)); at xi = 0,
 * w = w0 the secular u_p = -A t cos(th) / (2 w).  Returns u_p(t0), v_p(t0)
 * and the increments dup, dvp. */
static void particular(const pd_sdof *osc, double A, double w, double phi, double t0, double t1,
                       double *up0, double *vp0, double *dup, double *dvp)
{
    double w0 = osc->w0, re = w0 * w0 - w * w, im = 2.0 * osc->xi * w0 * w;
    double den = re * re + im * im, th0 = w * t0 + phi, th1 = w * t1 + phi;
    double s0 = sin(th0), c0 = cos(th0), ds, dc;
    *up0 = *vp0 = *dup = *dvp = 0.0;
    if (A == 0.0)
        return;
    sin_cos_diff(th0, th1, &ds, &dc);
    if (den <= 1e-28 * w0 * w0 * w0 * w0) { /* undamped resonance */
        double s1 = s0 + ds, c1 = c0 + dc;
        *up0 = -A * t0 * c0 / (2.0 * w);
        *vp0 = -A * c0 / (2.0 * w) + A * t0 * s0 / 2.0;
        *dup = -A * (t0 * dc + (t1 - t0) * c1) / (2.0 * w);
        *dvp = -A * dc / (2.0 * w) + A * (t0 * ds + (t1 - t0) * s1) / 2.0;
        return;
    }
    *up0 = A * (re * s0 - im * c0) / den;
    *vp0 = A * w * (re * c0 + im * s0) / den;
    *dup = A * (re * ds - im * dc) / den;
    *dvp = A * w * (re * dc + im * ds) / den;
}

void pd_sdof_increment(const pd_sdof *osc, double A, double w, double phi, double t0, double u0,
                       double v0, double t1, double *du, double *v1)
{
    if (osc->w0 == 0.0) {
        free_mass(A, w, phi, t0, v0, t1, du, v1);
        return;
    }
    double up0, vp0, dup, dvp;
    particular(osc, A, w, phi, t0, t1, &up0, &vp0, &dup, &dvp);
    /* homogeneous part e^{-a s}(c1 cos wd s + c2 sin wd s) minus its start c1 */
    double a = osc->xi * osc->w0, wd = osc->w0 * sqrt(1.0 - osc->xi * osc->xi);
    double c1 = u0 - up0, c2 = (v0 - vp0 + a * c1) / wd;
    double s = t1 - t0, em1 = expm1(-a * s), ex = 1.0 + em1;
    double cs = cos(wd * s), sn = sin(wd * s), half = sin(0.5 * wd * s);
    double cs_m1 = -2.0 * half * half; /* cos - 1 */
    double dh = c1 * (em1 * cs + cs_m1) + c2 * ex * sn;
    *du = dup + dh;
    *v1 = vp0 + dvp + ex * ((c2 * wd - a * c1) * cs - (c1 * wd + a * c2) * sn);
}

/* u(t1) = u0 + (u(t1) - u0). */
void pd_sdof_advance(const pd_sdof *osc, double A, double w, double phi, double t0, double u0,
                     double v0, double t1, double *u1, double *v1)
{
    double du;
    pd_sdof_increment(osc, A, w, phi, t0, u0, v0, t1, &du, v1);
    *u1 = u0 + du;
}
