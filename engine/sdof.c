/* sdof.c — exact motion of one damped linear oscillator under one forcing
 * piece F(t) = A sin(w t + phi) + c0 + c1 (t - t_start).
 *
 * Everything is computed as increments from the start state, with expm1 and
 * half-angle forms, so that u(t1) - u0 keeps full relative precision for
 * short intervals: the event-driven reference finds gap closings with it.
 *
 * The linear part uses the impulse response g(s) = e^{-a s} sin(wd s) / wd
 * (a = xi w0, wd = w0 sqrt(1 - xi^2)) and its integrals G1 = int_0^h g,
 * G2 = int_0^h G1.  By Duhamel, from (u0, v0) under f0 + c1 s:
 *   u(h) - u0 = v0 g + (f0 - w0^2 u0) G1 + c1 G2,
 *   v(h) - v0 = (f0 - 2 a v0 - w0^2 u0) g + (c1 - w0^2 v0) G1,
 * with g ~ h, G1 ~ h^2/2, G2 ~ h^3/6: each term is one of the increment's
 * Taylor terms, so nothing cancels that the motion does not cancel itself. */
#include <math.h>

#include "pd_engine.h"

/* Below this w0 h the kernels are summed as Taylor series (the closed forms
 * lose up to (w0 h)^-3 of their digits for small w0 h). */
#define KERNEL_SERIES_MAX 0.25
/* Series terms: |p_k| <= (w0 h)^k / k!, 1/18! < 1e-16. */
#define KERNEL_MAX_TERMS 40
/* A series stops once two consecutive terms are this small relative to g. */
#define KERNEL_SERIES_TOL 1e-18

/* The impulse response and its first two integrals at h. */
typedef struct kernels {
    double g, G1, G2;
} kernels;

/* sin(a + d) - sin(a) and cos(a + d) - cos(a) without cancellation (the
 * phase step d passed as such: w (t1 - t0), not a difference of phases). */
static void sin_cos_diff(double a, double d, double *ds, double *dc)
{
    double h = sin(0.5 * d), m = a + 0.5 * d;
    /* sin(a + d) - sin a = 2 cos(a + d/2) sin(d/2),
     * cos(a + d) - cos a = -2 sin(a + d/2) sin(d/2) */
    *ds = 2.0 * cos(m) * h;
    *dc = -2.0 * sin(m) * h;
}

/* sin(x / 2) and cos(x / 2). */
static void sincos_half(double x, double *s, double *c)
{
    *s = sin(0.5 * x);
    *c = cos(0.5 * x);
}

/* Taylor series: p_1 = h, p_{k+1} = -(2 a h p_k + (w0 h)^2 p_{k-1} / k) / (k + 1);
 * g = sum p_k, G1 = h sum p_k / (k+1), G2 = h^2 sum p_k / ((k+1)(k+2)). */
static kernels kernels_series(double w0, double a, double h)
{
    double z2 = (w0 * h) * (w0 * h), ah2 = 2.0 * a * h, prev = 0.0, cur = h;
    double g = 0.0, s1 = 0.0, s2 = 0.0;
    for (int k = 1; k <= KERNEL_MAX_TERMS; k++) {
        double next = -(ah2 * cur + z2 * prev / k) / (k + 1);
        g += cur;
        s1 += cur / (k + 1);
        s2 += cur / ((double)(k + 1) * (k + 2));
        /* two terms in a row below 1e-18 of g: the rest is below rounding */
        if (fabs(cur) + fabs(next) <= KERNEL_SERIES_TOL * fabs(g))
            break;
        prev = cur;
        cur = next;
    }
    return (kernels){.g = g, .G1 = h * s1, .G2 = h * h * s2};
}

/* Closed forms: g = e^{-a h} sin(wd h) / wd, G1 = (1 - e^{-a h}(cos + a/wd sin)) / w0^2,
 * G2 = (h - g - 2 a G1) / w0^2 (integrate g' = 1 - 2 a g - w0^2 G1 twice). */
static kernels kernels_closed(double w0, double xi, double h)
{
    double a = xi * w0, wd = w0 * sqrt(1.0 - xi * xi), k = w0 * w0;
    double em1 = expm1(-a * h), ex = 1.0 + em1, half = sin(0.5 * wd * h);
    double cs_m1 = -2.0 * half * half, cs = cos(wd * h); /* cos(wd h) - 1 */
    double g = ex * sin(wd * h) / wd;
    double G1 = -(em1 * cs + cs_m1 + a * g) / k;
    return (kernels){.g = g, .G1 = G1, .G2 = (h - g - 2.0 * a * G1) / k};
}

/* g, G1, G2 of the oscillator at h (w0 = 0: h, h^2/2, h^3/6). */
static kernels kernels_at(const pd_sdof *osc, double h)
{
    double w0 = osc->w0, a = w0 > 0.0 ? osc->xi * w0 : 0.0;
    /* small w0 h: the series, where the closed forms would cancel */
    if (fabs(w0 * h) <= KERNEL_SERIES_MAX)
        return kernels_series(w0, a, h);
    return kernels_closed(w0, osc->xi, h);
}

/* Free mass (w0 = 0): du = v0 s + the double integral of A sin(w t + phi). */
static void free_mass(double A, double w, double phi, double t0, double v0, double t1, double *du,
                      double *v1)
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
    sin_cos_diff(th0, w * s, &ds, &dc);
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
    double den = re * re + im * im, th0 = w * t0 + phi;
    double s0 = sin(th0), c0 = cos(th0), ds, dc;
    *up0 = *vp0 = *dup = *dvp = 0.0;
    if (A == 0.0)
        return;
    sin_cos_diff(th0, w * (t1 - t0), &ds, &dc);
    if (den <= 1e-28 * w0 * w0 * w0 * w0) { /* undamped resonance */
        double s1 = s0 + ds, c1 = c0 + dc;
        *up0 = -A * t0 * c0 / (2.0 * w);
        *vp0 = -A * c0 / (2.0 * w) + A * t0 * s0 / 2.0;
        *dup = -A * (t0 * dc + (t1 - t0) * c1) / (2.0 * w);
        *dvp = -A * dc / (2.0 * w) + A * (t0 * ds + (t1 - t0) * s1) / 2.0;
        return;
    }
    /* u_p = A Im(e^{i th} (re - i im)) / den
     *     = A (re sin th - im cos th) / den, v_p its derivative */
    *up0 = A * (re * s0 - im * c0) / den;
    *vp0 = A * w * (re * c0 + im * s0) / den;
    *dup = A * (re * ds - im * dc) / den;
    *dvp = A * w * (re * dc + im * ds) / den;
}

/* Response to A sin(w t + phi) from (u0, v0): particular solution plus the
 * damped homogeneous part e^{-a s}(c1 cos wd s + c2 sin wd s) minus its start c1. */
static void sine_increment(const pd_sdof *osc, double A, double w, double phi, double t0, double u0,
                           double v0, double t1, double *du, double *v1)
{
    if (osc->w0 == 0.0) {
        free_mass(A, w, phi, t0, v0, t1, du, v1);
        return;
    }
    double up0, vp0, dup, dvp;
    particular(osc, A, w, phi, t0, t1, &up0, &vp0, &dup, &dvp);
    double a = osc->xi * osc->w0, wd = osc->w0 * sqrt(1.0 - osc->xi * osc->xi);
    /* the homogeneous part meets (u0, v0): c1 = u0 - u_p0, wd c2 - a c1 = v0 - v_p0 */
    double c1 = u0 - up0, c2 = (v0 - vp0 + a * c1) / wd;
    double s = t1 - t0, em1 = expm1(-a * s), ex = 1.0 + em1;
    double cs = cos(wd * s), sn = sin(wd * s), half = sin(0.5 * wd * s);
    double cs_m1 = -2.0 * half * half;                  /* cos - 1 */
    double dh = c1 * (em1 * cs + cs_m1) + c2 * ex * sn; /* e^{-a s}(c1 cos + c2 sin) - c1 */
    *du = dup + dh;
    *v1 = vp0 + dvp + ex * ((c2 * wd - a * c1) * cs - (c1 * wd + a * c2) * sn);
}

/* Response to f0 + c1 s from (u0, v0) over h (Duhamel with g, G1, G2). */
static void ramp_increment(const pd_sdof *osc, double f0, double c1, double u0, double v0, double h,
                           double *du, double *v1)
{
    kernels k = kernels_at(osc, h);
    double k0 = osc->w0 * osc->w0, a2 = osc->w0 > 0.0 ? 2.0 * osc->xi * osc->w0 : 0.0;
    double rest = f0 - k0 * u0; /* the acceleration without damping */
    *du = v0 * k.g + rest * k.G1 + c1 * k.G2;
    *v1 = v0 + ((rest - a2 * v0) * k.g + (c1 - k0 * v0) * k.G1);
}

double pd_sine_piece_force(const pd_sine_piece *pc, double t)
{
    if (!pc)
        return NAN;
    double lin = pc->c0 + pc->c1 * (t - pc->t_start);
    return pc->A == 0.0 ? lin : pc->A * sin(pc->w * t + pc->phi) + lin;
}

void pd_sdof_increment_piece(const pd_sdof *osc, const pd_sine_piece *pc, double t0, double u0,
                             double v0, double t1, double *du, double *v1)
{
    if (!osc || !pc || !du || !v1)
        return;
    double f0 = pc->c0 + pc->c1 * (t0 - pc->t_start);
    /* A = 0: the linear force alone */
    if (pc->A == 0.0) {
        ramp_increment(osc, f0, pc->c1, u0, v0, t1 - t0, du, v1);
        return;
    }
    sine_increment(osc, pc->A, pc->w, pc->phi, t0, u0, v0, t1, du, v1);
    if (f0 == 0.0 && pc->c1 == 0.0)
        return;
    /* by linearity: the ramp's response from rest added to the sinusoid's */
    double dul, vl;
    ramp_increment(osc, f0, pc->c1, 0.0, 0.0, t1 - t0, &dul, &vl);
    *du += dul;
    *v1 += vl;
}

/* u(t1) = u0 + (u(t1) - u0). */
void pd_sdof_advance_piece(const pd_sdof *osc, const pd_sine_piece *pc, double t0, double u0,
                           double v0, double t1, double *u1, double *v1)
{
    if (!osc || !pc || !u1 || !v1)
        return;
    double du;
    pd_sdof_increment_piece(osc, pc, t0, u0, v0, t1, &du, v1);
    *u1 = u0 + du;
}

/* phi_k(s) = s^k sum_j (-c s)^j / (j + k)!, k = 1, 2, 3: the damped free
 * mass's kernels (phi1 = (1 - e^{-cs}) / c, phi2 = (s - phi1) / c, phi3 =
 * (s^2 / 2 - phi2) / c), by their series where c s < 1/2 (the closed forms
 * cancel there), else closed. */
static void mass_kernels(double c, double s, double phi[3])
{
    double z = c * s;
    if (z < 0.5) {
        for (int k = 1; k <= 3; k++) {
            double sum = 0.0, fact = 1.0;
            for (int i = 2; i <= k; i++)
                fact *= i;
            double term = 1.0 / fact; /* j = 0: 1 / k! */
            for (int j = 0; j < 24; j++) {
                sum += term;
                term *= -z / (double)(j + k + 1);
            }
            phi[k - 1] = sum * pow(s, k);
        }
        return;
    }
    phi[0] = -expm1(-z) / c;
    phi[1] = (s - phi[0]) / c;
    phi[2] = (0.5 * s * s - phi[1]) / c;
}

/* A damped free mass from (t0, v0) under F = A sin(w t + phi) + c0 + c1 (t
 * - ts): the sine's particular part x_p = B sin + C cos (B = -A / (w^2 +
 * c^2), C = c B / w) plus, for the rest v' + c v = f0 + c1 s with the
 * start's velocity less v_p's, v = v0' e^{-cs} + f0 phi1 + c1 phi2 and dx =
 * v0' phi1 + f0 phi2 + c1 phi3. */
static void mass_increment(const pd_sdof_flow *f, double t, double *dx, double *v)
{
    const pd_sine_piece *pc = &f->pc;
    double c = f->mass_c, s = t - f->t0, phi[3], f0 = pc->c0 + pc->c1 * (f->t0 - pc->t_start);
    double dxp = 0.0, vp0 = 0.0, vp1 = 0.0;
    if (pc->A != 0.0 && pc->w == 0.0) /* the constant A sin(phi) */
        f0 += pc->A * sin(pc->phi);
    else if (pc->A != 0.0) {
        double w = pc->w, B = -pc->A / (w * w + c * c), C = c * B / w;
        double th0 = w * f->t0 + pc->phi, d = w * s, h = sin(0.5 * d), m = th0 + 0.5 * d;
        /* x_p(t) - x_p(t0) by half angles: no cancellation for short s */
        dxp = B * 2.0 * cos(m) * h - C * 2.0 * sin(m) * h;
        vp0 = w * (B * cos(th0) - C * sin(th0));
        vp1 = w * (B * cos(th0 + d) - C * sin(th0 + d));
    }
    mass_kernels(c, s, phi);
    double v0 = f->v0 - vp0;
    *dx = dxp + v0 * phi[0] + f0 * phi[1] + pc->c1 * phi[2];
    *v = vp1 + v0 * (1.0 - c * phi[0]) + f0 * phi[0] + pc->c1 * phi[1];
}

void pd_sdof_flow_init(pd_sdof_flow *f, const pd_sdof *osc, const pd_sine_piece *pc, double t0,
                       double u0, double v0)
{
    if (!f || !osc || !pc)
        return;
    const pd_sine_piece *p = pc;
    double w0 = osc->w0, w = p->w, re = w0 * w0 - w * w, im = 2.0 * osc->xi * w0 * w;
    double den = re * re + im * im;
    *f = (pd_sdof_flow){.osc = *osc, .pc = *pc, .t0 = t0, .u0 = u0, .v0 = v0};
    /* the general path keeps the free mass and undamped resonance */
    f->fast = w0 > 0.0 && (p->A == 0.0 || den > 1e-28 * w0 * w0 * w0 * w0);
    if (!f->fast)
        return;
    f->a = osc->xi * w0;
    f->wd = w0 * sqrt(1.0 - osc->xi * osc->xi);
    f->k0 = w0 * w0;
    f->f0 = p->c0 + p->c1 * (t0 - p->t_start); /* F's linear part at t0 */
    double up0 = 0.0;
    if (p->A != 0.0) {
        double th0 = w * t0 + p->phi;
        f->s0 = sin(th0);
        f->c0 = cos(th0);
        f->pre = p->A * re / den;
        f->pim = p->A * im / den;
        up0 = f->pre * f->s0 - f->pim * f->c0;
        f->vp0 = w * (f->pre * f->c0 + f->pim * f->s0);
    }
    /* no ramp: a constant force's particular solution is the constant f0 / w0^2,
     * folded into the particular one (the motion is then homogeneous about it) */
    f->constf = p->c1 == 0.0;
    if (f->constf)
        up0 += f->f0 / f->k0;
    f->c1 = u0 - up0;
    f->c2 = (v0 - f->vp0 + f->a * f->c1) / f->wd;
    /* the linear term by linearity from rest beside a sinusoid, else from (u0, v0) */
    f->ur = p->A != 0.0 ? 0.0 : u0;
    f->vr = p->A != 0.0 ? 0.0 : v0;
}

void pd_sdof_flow_init_mass(pd_sdof_flow *f, double c, const pd_sine_piece *pc, double t0,
                            double u0, double v0)
{
    if (!f || !pc)
        return;
    *f = (pd_sdof_flow){.pc = *pc, .t0 = t0, .u0 = u0, .v0 = v0, .mass_c = c};
}

void pd_sdof_flow_at(const pd_sdof_flow *f, double t1, double *du, double *v1)
{
    if (!f || !du || !v1)
        return;
    if (f->mass_c > 0.0) {
        mass_increment(f, t1, du, v1);
        return;
    }
    if (!f->fast) {
        pd_sdof_increment_piece(&f->osc, &f->pc, f->t0, f->u0, f->v0, t1, du, v1);
        return;
    }
    const pd_sine_piece *p = &f->pc;
    double s = t1 - f->t0, a = f->a, wd = f->wd, k0 = f->k0;
    /* e^{-a s} - 1, sin wd s, cos wd s - 1 from the half angle */
    double em1 = expm1(-a * s), ex = 1.0 + em1, hs, hc;
    sincos_half(wd * s, &hs, &hc);
    double sn = 2.0 * hs * hc, cs_m1 = -2.0 * hs * hs, cs = 1.0 + cs_m1;
    *du = 0.0;
    *v1 = 0.0;
    if (f->constf && p->A == 0.0) { /* e^{-a s}(c1 cos + c2 sin) about the equilibrium */
        *du = f->c1 * (em1 * cs + cs_m1) + f->c2 * ex * sn;
        *v1 = ex * ((f->c2 * wd - a * f->c1) * cs - (f->c1 * wd + a * f->c2) * sn);
        return;
    }
    if (p->A != 0.0) { /* particular increments by angle addition, then the homogeneous part */
        double ps, pc2;
        sincos_half(p->w * s, &ps, &pc2);
        /* sin and cos of th0 + w s / 2 by angle addition, then
         * the differences as in sin_cos_diff */
        double sm = f->s0 * pc2 + f->c0 * ps, cm = f->c0 * pc2 - f->s0 * ps;
        double ds = 2.0 * cm * ps, dc = -2.0 * sm * ps;
        *du = f->pre * ds - f->pim * dc + f->c1 * (em1 * cs + cs_m1) + f->c2 * ex * sn;
        *v1 = f->vp0 + p->w * (f->pre * dc + f->pim * ds) +
              ex * ((f->c2 * wd - a * f->c1) * cs - (f->c1 * wd + a * f->c2) * sn);
    }
    if (f->constf) /* the constant is in the particular solution */
        return;
    kernels k;
    if (fabs(f->osc.w0 * s) <= KERNEL_SERIES_MAX)
        k = kernels_series(f->osc.w0, a, s);
    else {
        double g = ex * sn / wd, G1 = -(em1 * cs + cs_m1 + a * g) / k0;
        k = (kernels){.g = g, .G1 = G1, .G2 = (s - g - 2.0 * a * G1) / k0};
    }
    /* Duhamel: du = v g + (f0 - w0^2 u) G1 + c1 G2 */
    double rest = f->f0 - k0 * f->ur;
    *du += f->vr * k.g + rest * k.G1 + p->c1 * k.G2;
    *v1 += f->vr + ((rest - 2.0 * a * f->vr) * k.g + (p->c1 - k0 * f->vr) * k.G1);
}

/* The sinusoid alone: a piece without linear terms. */
void pd_sdof_increment(const pd_sdof *osc, double A, double w, double phi, double t0, double u0,
                       double v0, double t1, double *du, double *v1)
{
    if (!osc || !du || !v1)
        return;
    pd_sine_piece pc = {.t_start = t0, .A = A, .w = w, .phi = phi};
    pd_sdof_increment_piece(osc, &pc, t0, u0, v0, t1, du, v1);
}

/* u(t1) = u0 + (u(t1) - u0). */
void pd_sdof_advance(const pd_sdof *osc, double A, double w, double phi, double t0, double u0,
                     double v0, double t1, double *u1, double *v1)
{
    if (!osc || !u1 || !v1)
        return;
    double du;
    pd_sdof_increment(osc, A, w, phi, t0, u0, v0, t1, &du, v1);
    *u1 = u0 + du;
}
