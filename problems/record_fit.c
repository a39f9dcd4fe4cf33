/* record_fit.c — what is measured on a record (SPEC §5, docs/records.md):
 * ground velocity and displacement, peaks, Arias intensity and significant
 * durations, and the Mavroeidis–Papageorgiou (2003) velocity pulse fitted
 * by GSL's nonlinear least squares, with the one-cycle acceleration pulse
 * of the paper (Dimitrakopoulos, Makris & Kappos 2010, Fig. 2) that
 * matches it.
 *
 * Integration is exact for the piecewise-linear acceleration of the
 * record (the excitation every method of pound applies):
 *   v_{k+1} = v_k + dt (a_k + a_{k+1}) / 2,
 *   d_{k+1} = d_k + dt v_k + dt^2 (2 a_k + a_{k+1}) / 6,
 * from rest (v_0 = d_0 = 0), with no baseline correction: processed
 * records (PEER NGA, CDMG V2) are baseline-corrected by their agencies, and
 * any correction here would make the reported velocity and displacement
 * differ from the motion the structures are driven by.  Peaks are exact
 * too: a velocity peak inside a step (where a crosses zero) and a
 * displacement peak inside a step (where v crosses zero) are found from
 * the step's quadratic and cubic.
 *
 * Arias intensity Ia = pi / (2 g) integral a^2 dt, g = PD_G_STANDARD, the
 * integral exact for the piecewise-linear a: dt/3 (a_k^2 + a_k a_{k+1} +
 * a_{k+1}^2) per step.  The Husid curve is that integral from 0 to t; the
 * times at 5, 75 and 95 % of Ia are found inside their step on its cubic
 * (bisection), so durations are not rounded to the sample grid.
 *
 * The pulse fit: the record's velocity over the PGV time -/+ 2 initial
 * periods (twice the time between the zero crossings around the PGV),
 * twelve starts (vp = the velocity at the PGV, t0 its time, nu in {0,
 * +-pi/2, pi}, gamma in {1.5, 2, 3}), GSL's trust region with the analytic
 * Jacobian in the unknowns (vp, ln fp, nu, q, t0), gamma = 1 + 3 / (1 +
 * exp(-q)) in (1, 4); the start with the best r2 is kept.  The one-cycle
 * acceleration pulse is the sine or cosine cycle of amplitude ap and
 * period Tp, of either sign, with the largest correlation with the
 * record's acceleration (the least-squares closest of those templates). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_vector.h>

#include "pd_null.h"
#include "pd_problems.h"

#define FIT_MAXITER 400   /* trust-region iterations per start */
#define FIT_TOL 1e-10     /* xtol, gtol, ftol of the driver */
#define FIT_GAMMA_MIN 1.0 /* gamma = 1 + 3 / (1 + exp(-q)) in (1, 4) */
#define FIT_GAMMA_SPAN 3.0
#define FIT_WINDOW 2.0         /* fit window: PGV time -/+ this many initial periods */
#define FIT_SAMPLES 20000      /* most samples fitted (a stride thins longer windows) */
#define FIT_SHAPE_SAMPLES 1000 /* most samples per cycle in the one-cycle pulse match */
#define FIT_AP_GRID 2000       /* grid over the pulse for the largest |v'| */
#define FIT_BISECT 80          /* bisection steps for Husid times */

/* ---- integration ------------------------------------------------------------ */

/* The record holds at least two samples and a step within the readers' bounds. */
static int record_valid(const pd_record *rec, pd_err *err)
{
    if (!rec || !rec->acc || rec->npts < 2 || !(rec->dt > 0.0) || !isfinite(rec->dt))
        return pd_err_set(err, PD_EINVAL, "record: expected at least 2 samples and dt > 0");
    /* the readers' bounds: beyond them the duration and the sample times
     * overflow or underflow, and indices t / dt are no longer integers */
    if (!(rec->dt >= PD_RECORD_DT_MIN && rec->dt <= PD_RECORD_DT_MAX) ||
        !isfinite(pd_record_duration(rec)))
        return pd_err_set(err, PD_EINVAL,
                          "%s: dt = %g s: expected a sampling interval in "
                          "[%g, %g] s",
                          rec->name, rec->dt, PD_RECORD_DT_MIN, PD_RECORD_DT_MAX);
    return PD_OK;
}

int pd_record_integrate(const pd_record *rec, double *vel, double *disp, pd_err *err)
{
    if (!rec || !vel || !disp)
        return PD_NULL_ARG(err, !rec ? "rec" : !vel ? "vel" : "disp");
    int st = record_valid(rec, err);
    if (st != PD_OK)
        return st;
    const double *a = rec->acc, h = rec->dt;
    vel[0] = disp[0] = 0.0;
    for (long k = 0; k + 1 < rec->npts; k++) {
        vel[k + 1] = vel[k] + 0.5 * h * (a[k] + a[k + 1]);
        disp[k + 1] = disp[k] + h * vel[k] + h * h * (2.0 * a[k] + a[k + 1]) / 6.0;
    }
    return PD_OK;
}

/* ---- peaks -------------------------------------------------------------------- */

/* Keep (x, t) as the peak when |x| is larger. */
static void peak_keep(double x, double t, double *peak, double *t_peak)
{
    if (fabs(x) > *peak) {
        *peak = fabs(x);
        *t_peak = t;
    }
}

/* Largest |a|: at a sample (a is linear between samples). */
static void peak_acc(const pd_record *rec, double *pga, double *t_pga)
{
    *pga = 0.0;
    *t_pga = 0.0;
    for (long k = 0; k < rec->npts; k++)
        peak_keep(rec->acc[k], (double)k * rec->dt, pga, t_pga);
}

/* Largest |v|: at a sample or where a crosses zero inside a step. */
static void peak_vel(const pd_record *rec, const double *v, double *pgv, double *t_pgv)
{
    const double *a = rec->acc, h = rec->dt;
    *pgv = 0.0;
    *t_pgv = 0.0;
    for (long k = 0; k + 1 < rec->npts; k++) {
        if ((a[k] > 0.0 && a[k + 1] < 0.0) || (a[k] < 0.0 && a[k + 1] > 0.0)) {
            double s = h * a[k] / (a[k] - a[k + 1]);
            double vs = v[k] + a[k] * s + 0.5 * (a[k + 1] - a[k]) * s * s / h;
            peak_keep(vs, (double)k * h + s, pgv, t_pgv);
        }
        peak_keep(v[k + 1], (double)(k + 1) * h, pgv, t_pgv);
    }
}

/* Roots in (0, h) of c2 s^2 + c1 s + c0 (at most two, into s[]). */
static int roots_in_step(double c2, double c1, double c0, double h, double s[2])
{
    int n = 0;
    double r[2];
    int nr = 0;
    if (c2 == 0.0) {
        if (c1 != 0.0)
            r[nr++] = -c0 / c1;
    } else {
        double disc = c1 * c1 - 4.0 * c2 * c0;
        if (disc >= 0.0) {
            double q = -0.5 * (c1 + copysign(sqrt(disc), c1));
            r[nr++] = q / c2;
            if (q != 0.0)
                r[nr++] = c0 / q;
        }
    }
    for (int i = 0; i < nr; i++)
        if (r[i] > 0.0 && r[i] < h)
            s[n++] = r[i];
    return n;
}

/* Largest |d|: at a sample or where v crosses zero inside a step. */
static void peak_disp(const pd_record *rec, const double *v, const double *d, double *pgd,
                      double *t_pgd)
{
    const double *a = rec->acc, h = rec->dt;
    *pgd = 0.0;
    *t_pgd = 0.0;
    for (long k = 0; k + 1 < rec->npts; k++) {
        double da = a[k + 1] - a[k], s[2];
        int n = roots_in_step(0.5 * da / h, a[k], v[k], h, s);
        for (int i = 0; i < n; i++) {
            double ds =
                d[k] + v[k] * s[i] + 0.5 * a[k] * s[i] * s[i] + da * s[i] * s[i] * s[i] / (6.0 * h);
            peak_keep(ds, (double)k * h + s[i], pgd, t_pgd);
        }
        peak_keep(d[k + 1], (double)(k + 1) * h, pgd, t_pgd);
    }
}

/* ---- Arias intensity and the Husid curve ----------------------------------------- */

/* integral of a^2 over step k from its start to s (exact: a linear). */
static double step_a2(const double *a, long k, double h, double s)
{
    double da = a[k + 1] - a[k], r = s / h;
    return s * (a[k] * a[k] + a[k] * da * r + da * da * r * r / 3.0);
}

/* The time where the running integral of a^2 reaches target (cum[k]: the
 * integral up to sample k). */
static double husid_time(const pd_record *rec, const double *cum, double target)
{
    long lo = 0, hi = rec->npts - 1;
    while (hi - lo > 1) { /* cum is non-decreasing: the step holding target */
        long mid = lo + (hi - lo) / 2;
        if (cum[mid] < target)
            lo = mid;
        else
            hi = mid;
    }
    double s0 = 0.0, s1 = rec->dt;
    for (int i = 0; i < FIT_BISECT && s1 - s0 > 0.0; i++) {
        double s = 0.5 * (s0 + s1);
        if (cum[lo] + step_a2(rec->acc, lo, rec->dt, s) < target)
            s0 = s;
        else
            s1 = s;
    }
    return (double)lo * rec->dt + 0.5 * (s0 + s1);
}

/* Arias intensity and the 5-75 and 5-95 % durations (cum: npts scratch). */
static void arias(const pd_record *rec, double *cum, pd_record_measures *m)
{
    cum[0] = 0.0;
    for (long k = 0; k + 1 < rec->npts; k++)
        cum[k + 1] = cum[k] + step_a2(rec->acc, k, rec->dt, rec->dt);
    double total = cum[rec->npts - 1];
    m->arias = PD_PI / (2.0 * PD_G_STANDARD) * total;
    m->t5_75 = m->t5_95 = 0.0;
    if (total > 0.0) {
        double t5 = husid_time(rec, cum, 0.05 * total);
        m->t5_75 = husid_time(rec, cum, 0.75 * total) - t5;
        m->t5_95 = husid_time(rec, cum, 0.95 * total) - t5;
    }
}

/* The ground velocity and displacement at the samples, malloc'd into *v and
 * *d (the caller frees both, also on failure). */
static int integrated(const pd_record *rec, double **v, double **d, pd_err *err)
{
    *v = malloc((size_t)rec->npts * sizeof **v);
    *d = malloc((size_t)rec->npts * sizeof **d);
    if (!*v || !*d)
        return pd_err_set(err, PD_ENOMEM, "%s: out of memory for %ld samples", rec->name,
                          rec->npts);
    return pd_record_integrate(rec, *v, *d, err);
}

int pd_record_measure(const pd_record *rec, pd_record_measures *m, pd_err *err)
{
    if (!rec || !m)
        return PD_NULL_ARG(err, !rec ? "rec" : "m");
    int st = record_valid(rec, err);
    if (st != PD_OK)
        return st;
    double *v = NULL, *d = NULL;
    if (st == PD_OK)
        st = integrated(rec, &v, &d, err);
    if (st == PD_OK) {
        *m = (pd_record_measures){.pga = 0.0};
        peak_acc(rec, &m->pga, &m->t_pga);
        peak_vel(rec, v, &m->pgv, &m->t_pgv);
        peak_disp(rec, v, d, &m->pgd, &m->t_pgd);
        arias(rec, v, m); /* v is free scratch now */
    }
    free(v);
    free(d);
    return st;
}

/* ---- the Mavroeidis–Papageorgiou pulse -------------------------------------------- */

/* The model's parameters. */
typedef struct mp_pulse {
    double vp, fp, nu, gamma, t0;
} mp_pulse;

/* Pulse from the solver's unknowns x = (vp, ln fp, nu, q, t0). */
static mp_pulse mp_from_x(const double *x)
{
    return (mp_pulse){.vp = x[0],
                      .fp = exp(x[1]),
                      .nu = x[2],
                      .gamma = FIT_GAMMA_MIN + FIT_GAMMA_SPAN / (1.0 + exp(-x[3])),
                      .t0 = x[4]};
}

/* Half the support, gamma / (2 fp). */
static double mp_half(const mp_pulse *p)
{
    return 0.5 * p->gamma / p->fp;
}

/* v(t). */
static double mp_vel(const mp_pulse *p, double t)
{
    double tau = t - p->t0;
    if (fabs(tau) > mp_half(p))
        return 0.0;
    double w = PD_TWO_PI * p->fp;
    return 0.5 * p->vp * (1.0 + cos(w * tau / p->gamma)) * cos(w * tau + p->nu);
}

/* dv/dt. */
static double mp_acc(const mp_pulse *p, double t)
{
    double tau = t - p->t0;
    if (fabs(tau) > mp_half(p))
        return 0.0;
    double w = PD_TWO_PI * p->fp, phi = w * tau / p->gamma, psi = w * tau + p->nu;
    return -0.5 * p->vp * w * (sin(phi) * cos(psi) / p->gamma + (1.0 + cos(phi)) * sin(psi));
}

/* The velocities the pulse is fitted to: samples k0 + i stride, i < n. */
typedef struct mp_data {
    const double *v;
    long k0, stride;
    size_t n;
    double dt;
} mp_data;

/* The record's sample index of data point i. */
static long mp_index(const mp_data *D, size_t i)
{
    return D->k0 + (long)i * D->stride;
}

/* Residuals f_i = model(t_i) - v_i. */
static int mp_f(const gsl_vector *x, void *params, gsl_vector *f)
{
    const mp_data *D = params;
    mp_pulse p = mp_from_x(x->data);
    for (size_t i = 0; i < D->n; i++) {
        long k = mp_index(D, i);
        gsl_vector_set(f, i, mp_vel(&p, (double)k * D->dt) - D->v[k]);
    }
    return GSL_SUCCESS;
}

/* Jacobian of the residuals in x = (vp, ln fp, nu, q, t0). */
static int mp_df(const gsl_vector *x, void *params, gsl_matrix *J)
{
    const mp_data *D = params;
    mp_pulse p = mp_from_x(x->data);
    double w = PD_TWO_PI * p.fp, g = p.gamma, half = mp_half(&p);
    double s = (g - FIT_GAMMA_MIN) / FIT_GAMMA_SPAN, dg_dq = FIT_GAMMA_SPAN * s * (1.0 - s);
    for (size_t i = 0; i < D->n; i++) {
        double tau = (double)mp_index(D, i) * D->dt - p.t0;
        double row[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
        if (fabs(tau) <= half) {
            double phi = w * tau / g, psi = w * tau + p.nu;
            double env = 1.0 + cos(phi), sp = sin(phi), cs = cos(psi), sn = sin(psi);
            double A = 0.5 * p.vp;
            row[0] = 0.5 * env * cs;
            /* d/dfp times fp: phi and psi scale with fp */
            row[1] = -A * (sp * cs * phi + env * sn * w * tau);
            row[2] = -A * env * sn;
            row[3] = A * sp * cs * phi / g * dg_dq;
            row[4] = A * (sp * cs * w / g + env * sn * w);
        }
        for (size_t j = 0; j < 5; j++)
            gsl_matrix_set(J, i, j, row[j]);
    }
    return GSL_SUCCESS;
}

/* 1 - SSE / SST of pulse p over the data. */
static double mp_r2(const mp_data *D, const mp_pulse *p)
{
    double mean = 0.0, sse = 0.0, sst = 0.0;
    for (size_t i = 0; i < D->n; i++)
        mean += D->v[mp_index(D, i)];
    mean /= (double)D->n;
    for (size_t i = 0; i < D->n; i++) {
        long k = mp_index(D, i);
        double vi = D->v[k], e = mp_vel(p, (double)k * D->dt) - vi;
        sse += e * e;
        sst += (vi - mean) * (vi - mean);
    }
    return sst > 0.0 ? 1.0 - sse / sst : -INFINITY;
}

/* Where v crosses zero next from sample k in direction step (+1 / -1),
 * interpolated; the record's end when it does not. */
static double zero_crossing(const double *v, long n, long k, int step, double dt)
{
    for (long j = k; j + step >= 0 && j + step < n; j += step) {
        double a = v[j], b = v[j + step];
        if ((a > 0.0 && b <= 0.0) || (a < 0.0 && b >= 0.0))
            return ((double)j + (double)step * a / (a - b)) * dt;
    }
    return step > 0 ? (double)(n - 1) * dt : 0.0;
}

/* Starting pulse and fit window from the record's velocity: vp and t0
 * at the PGV sample, the period twice the time between the zero crossings
 * around it (a half cycle); the window PGV time -/+ FIT_WINDOW periods, so
 * that it holds the whole support gamma / fp <= 4 / fp of pulses near the
 * start (the residual then weighs all of the model), thinned to at most
 * about FIT_SAMPLES samples. */
static void fit_start(const pd_record *rec, const double *v, mp_pulse *p0, mp_data *D)
{
    long kp = 0;
    for (long k = 1; k < rec->npts; k++)
        if (fabs(v[k]) > fabs(v[kp]))
            kp = k;
    double dt = rec->dt, T = pd_record_duration(rec);
    double ta = zero_crossing(v, rec->npts, kp, -1, dt);
    double tb = zero_crossing(v, rec->npts, kp, +1, dt);
    double Tp = fmin(fmax(2.0 * (tb - ta), 8.0 * dt), T);
    *p0 = (mp_pulse){.vp = v[kp], .fp = 1.0 / Tp, .nu = 0.0, .gamma = 2.0, .t0 = kp * dt};
    double lo = fmax(0.0, p0->t0 - FIT_WINDOW * Tp), hi = fmin(T, p0->t0 + FIT_WINDOW * Tp);
    D->k0 = (long)floor(lo / dt);
    long k1 = (long)ceil(hi / dt);
    if (k1 > rec->npts - 1)
        k1 = rec->npts - 1;
    D->stride = (k1 - D->k0) / FIT_SAMPLES + 1;
    D->n = (size_t)((k1 - D->k0) / D->stride + 1);
}

/* One trust-region solve from x (5 unknowns, updated); its r2 and iterations. */
static int fit_once(gsl_multifit_nlinear_workspace *w, gsl_multifit_nlinear_fdf *fdf, double *x,
                    double *r2, long *iters)
{
    gsl_vector_view xv = gsl_vector_view_array(x, 5);
    int info = 0;
    if (gsl_multifit_nlinear_init(&xv.vector, fdf, w) != GSL_SUCCESS)
        return PD_ENUMERICAL;
    /* the driver's status is not needed: a start that ends on its budget or
     * without progress still offers its point, judged by its r2 */
    gsl_multifit_nlinear_driver(FIT_MAXITER, FIT_TOL, FIT_TOL, FIT_TOL, NULL, NULL, &info, w);
    const gsl_vector *xs = gsl_multifit_nlinear_position(w);
    for (int j = 0; j < 5; j++)
        x[j] = gsl_vector_get(xs, (size_t)j);
    mp_pulse p = mp_from_x(x);
    *r2 = mp_r2(fdf->params, &p);
    *iters = (long)gsl_multifit_nlinear_niter(w);
    return isfinite(*r2) && isfinite(p.fp) && isfinite(p.t0) && isfinite(p.vp) ? PD_OK
                                                                               : PD_ENUMERICAL;
}

/* The best of the starts nu in {0, +-pi/2, pi} x gamma in {1.5, 2, 3}. */
static int fit_best(const mp_data *D, const mp_pulse *p0, mp_pulse *best, double *r2_best,
                    long *iters_best)
{
    static const double nus[] = {0.0, 0.5 * PD_PI, -0.5 * PD_PI, PD_PI};
    static const double gammas[] = {1.5, 2.0, 3.0};
    gsl_multifit_nlinear_parameters par = gsl_multifit_nlinear_default_parameters();
    gsl_multifit_nlinear_workspace *w =
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &par, D->n, 5);
    if (!w)
        return PD_ENOMEM;
    gsl_multifit_nlinear_fdf fdf = {
        .f = mp_f, .df = mp_df, .fvv = NULL, .n = D->n, .p = 5, .params = (void *)D};
    *r2_best = -INFINITY;
    for (size_t i = 0; i < sizeof nus / sizeof nus[0]; i++)
        for (size_t j = 0; j < sizeof gammas / sizeof gammas[0]; j++) {
            double g = gammas[j], r2 = 0.0;
            double x[5] = {p0->vp, log(p0->fp), nus[i],
                           log((g - FIT_GAMMA_MIN) / (FIT_GAMMA_MIN + FIT_GAMMA_SPAN - g)), p0->t0};
            long it = 0;
            if (fit_once(w, &fdf, x, &r2, &it) == PD_OK && r2 > *r2_best) {
                *r2_best = r2;
                *best = mp_from_x(x);
                *iters_best = it;
            }
        }
    gsl_multifit_nlinear_free(w);
    return isfinite(*r2_best) ? PD_OK : PD_ENUMERICAL;
}

/* vp > 0 (its sign moved into nu), nu in (-pi, pi]. */
static void mp_normalise(mp_pulse *p)
{
    if (p->vp < 0.0) {
        p->vp = -p->vp;
        p->nu += PD_PI;
    }
    p->nu = remainder(p->nu, PD_TWO_PI);
    if (p->nu <= -PD_PI)
        p->nu += PD_TWO_PI;
}

/* Largest |dv/dt| of the pulse: a grid over its support, refined by golden
 * section around the best grid point. */
static double mp_peak_acc(const mp_pulse *p)
{
    double half = mp_half(p), h = 2.0 * half / FIT_AP_GRID, best = 0.0, tb = p->t0;
    for (int i = 0; i <= FIT_AP_GRID; i++) {
        double t = p->t0 - half + i * h, a = fabs(mp_acc(p, t));
        if (a > best) {
            best = a;
            tb = t;
        }
    }
    const double r = 0.5 * (sqrt(5.0) - 1.0);
    double lo = tb - h, hi = tb + h;
    for (int i = 0; i < 60; i++) {
        double x1 = hi - r * (hi - lo), x2 = lo + r * (hi - lo);
        if (fabs(mp_acc(p, x1)) > fabs(mp_acc(p, x2)))
            hi = x2;
        else
            lo = x1;
    }
    return fmax(best, fabs(mp_acc(p, 0.5 * (lo + hi))));
}

/* sum of a_k phi(wp (t_k - ts)) over one cycle from ts = k0 dt, every
 * stride-th sample (times the step: the correlation of record and pulse). */
static double pulse_score(const pd_record *rec, pd_pulse shape, double Tp, long k0, long stride)
{
    double wp = PD_TWO_PI / Tp, sum = 0.0, dt = rec->dt;
    long m = (long)floor(Tp / dt);
    for (long j = 0; j <= m && k0 + j < rec->npts; j += stride) {
        double tau = wp * (double)j * dt;
        sum += rec->acc[k0 + j] * (shape == PD_PULSE_COSINE ? cos(tau) : sin(tau));
    }
    return sum * dt * (double)stride;
}

/* The one-cycle pulse (sine or cosine, sign, start) of amplitude ap and
 * period Tp closest in least squares to the record's acceleration: the
 * largest |correlation| over starts around the velocity pulse. */
static void match_shape(const pd_record *rec, pd_record_pulse *out, const mp_pulse *p)
{
    double T = pd_record_duration(rec), half = mp_half(p);
    double lo = fmax(0.0, p->t0 - half - out->Tp), hi = fmin(T - out->Tp, p->t0 + half);
    if (hi < lo)
        hi = lo;
    long k_lo = (long)floor(lo / rec->dt), k_hi = (long)ceil(hi / rec->dt);
    long stride = (long)(out->Tp / rec->dt) / FIT_SHAPE_SAMPLES + 1;
    double best = -1.0;
    static const pd_pulse shapes[] = {PD_PULSE_SINE, PD_PULSE_COSINE};
    for (int s = 0; s < 2; s++)
        for (long k = k_lo; k <= k_hi && k < rec->npts; k += stride) {
            double c = pulse_score(rec, shapes[s], out->Tp, k, stride);
            if (fabs(c) > best) {
                best = fabs(c);
                out->shape = shapes[s];
                out->polarity = c >= 0.0 ? 1 : -1;
                out->t_start = (double)k * rec->dt;
            }
        }
}

/* Fill the report from the fitted pulse. */
static void pulse_report(const pd_record *rec, const mp_pulse *p, double r2, long iters,
                         pd_record_pulse *out)
{
    *out = (pd_record_pulse){.vp = p->vp,
                             .fp = p->fp,
                             .nu = p->nu,
                             .gamma = p->gamma,
                             .t0 = p->t0,
                             .Tp = 1.0 / p->fp,
                             .ap = mp_peak_acc(p),
                             .wp = PD_TWO_PI * p->fp,
                             .r2 = r2,
                             .iterations = iters,
                             .shape = PD_PULSE_SINE,
                             .polarity = 1,
                             .t_start = 0.0};
    out->Le = out->ap / (out->wp * out->wp);
    match_shape(rec, out, p);
}

/* A fit that explains none of the velocity (r2 <= 0), is centred outside
 * the record or is longer than it has found no pulse. */
static int fit_check(const pd_record *rec, const mp_pulse *p, double r2, pd_err *err)
{
    double T = pd_record_duration(rec);
    if (r2 > 0.0 && p->t0 >= 0.0 && p->t0 <= T && 1.0 / p->fp <= T)
        return PD_OK;
    return pd_err_set(err, PD_ENUMERICAL,
                      "%s: no velocity pulse found: the best fit has r2 = %.3g, Tp = %.4g s "
                      "at t0 = %.4g s (record %.4g s)",
                      rec->name, r2, 1.0 / p->fp, p->t0, T);
}

int pd_record_fit_pulse(const pd_record *rec, pd_record_pulse *out, pd_err *err)
{
    if (!rec || !out)
        return PD_NULL_ARG(err, !rec ? "rec" : "out");
    int st = record_valid(rec, err);
    if (st != PD_OK)
        return st;
    *out = (pd_record_pulse){.shape = PD_PULSE_SINE, .polarity = 1};
    double *v = NULL, *d = NULL;
    if (st == PD_OK)
        st = integrated(rec, &v, &d, err);
    mp_pulse p0, best;
    mp_data D = {.v = v, .dt = rec->dt, .stride = 1};
    double r2 = 0.0;
    long iters = 0;
    if (st == PD_OK) {
        gsl_set_error_handler_off(); /* process-wide: GSL reports, never aborts */
        fit_start(rec, v, &p0, &D);
        if (p0.vp == 0.0 || D.n < 6)
            st = pd_err_set(err, PD_ENUMERICAL,
                            "%s: no velocity pulse to fit (zero velocity or too few samples)",
                            rec->name);
    }
    if (st == PD_OK) {
        st = fit_best(&D, &p0, &best, &r2, &iters);
        if (st == PD_ENOMEM)
            pd_err_set(err, st, "%s: out of memory for the pulse fit", rec->name);
        else if (st != PD_OK)
            pd_err_set(err, st, "%s: the pulse fit failed from every start", rec->name);
    }
    if (st == PD_OK)
        st = fit_check(rec, &best, r2, err);
    if (st == PD_OK) {
        mp_normalise(&best);
        pulse_report(rec, &best, r2, iters, out);
    }
    free(v);
    free(d);
    return st;
}
