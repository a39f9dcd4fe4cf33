/* sdof.c — exact motion of one damped linear oscillator under a sinusoid. */
#include <math.h>

#include "pd_engine.h"

/* Particular solution of u'' + 2 xi w0 u' + w0^2 u = A sin(w t + phi) at t:
 * u_p = Im(A e^{i(wt+phi)} / (w0^2 - w^2 + 2 i xi w0 w)); for xi = 0 and
 * w = w0 the secular u_p = -A t cos(w t + phi) / (2 w). */
static void particular(const pd_sdof *osc, double A, double w, double phi, double t, double *u,
                       double *v)
{
    double w0 = osc->w0, re = w0 * w0 - w * w, im = 2.0 * osc->xi * w0 * w;
    double den = re * re + im * im, th = w * t + phi, s = sin(th), c = cos(th);
    if (A == 0.0) {
        *u = *v = 0.0;
        return;
    }
    if (den <= 1e-28 * w0 * w0 * w0 * w0) { /* undamped resonance */
        *u = -A * t * c / (2.0 * w);
        *v = -A * c / (2.0 * w) + A * t * s / 2.0;
        return;
    }
    /* A e^{i th} (re - i im) / den: imaginary part and its derivative */
    *u = A * (re * s - im * c) / den;
    *v = A * w * (re * c + im * s) / den;
}

/* u(t1) = u_p(t1) + e^{-xi w0 s}(c1 cos wd s + c2 sin wd s), s = t1 - t0. */
void pd_sdof_advance(const pd_sdof *osc, double A, double w, double phi, double t0, double u0,
                     double v0, double t1, double *u1, double *v1)
{
    double up0, vp0, up1, vp1;
    particular(osc, A, w, phi, t0, &up0, &vp0);
    particular(osc, A, w, phi, t1, &up1, &vp1);
    double a = osc->xi * osc->w0, wd = osc->w0 * sqrt(1.0 - osc->xi * osc->xi);
    double c1 = u0 - up0, c2 = (v0 - vp0 + a * c1) / wd;
    double s = t1 - t0, ex = exp(-a * s), cs = cos(wd * s), sn = sin(wd * s);
    *u1 = up1 + ex * (c1 * cs + c2 * sn);
    *v1 = vp1 + ex * ((c2 * wd - a * c1) * cs - (c1 * wd + a * c2) * sn);
}
