/* demand.c — the demand parameters of a state (pd_problems.h, "demand
 * parameters"), from the structures' own data in SI units.
 *
 * A shear building of floors 1..s (floor 0 the ground), C = alpha M + beta K:
 *   the storey element force  S_k = k_k d_k + beta k_k d_k',  d_k = u_k - u_k-1,
 *   (C u' + K u)_i = S_i - S_i+1 + alpha m_i u_i'   (S_s+1 = 0),
 *   a_abs,i = -(C u' + K u)_i / m_i,
 *   V_k = sum over i >= k of (C u' + K u)_i = S_k + alpha sum over i >= k of m_i u_i'.
 * So V_1 = -sum m_i a_abs,i at every instant (the base shear balances the
 * floors' inertia), and for stiffness-proportional damping (alpha = 0) V_k is
 * the storey's spring plus damper force. */
#include <math.h>
#include <stdio.h>

#include "demand.h"

double pd_equivalent_force(double impulse, double td)
{
    return 0.5 * PD_PI * impulse / td;
}

/* An equivalent force pi I / (2 td) that overflows while I's at the
 * default duration does not: the duration's fault (contact a, or -1 for the
 * oscillator's wall).  An impulse too large for any duration is the
 * excitation's, which the callers name. */
int pd_demand_check_force(double impulse, double force, int a, pd_err *err)
{
    if (isfinite(force) || !isfinite(pd_equivalent_force(impulse, PD_CONTACT_DURATION)))
        return PD_OK;
    char which[32] = "";
    if (a >= 0)
        snprintf(which, sizeof which, " of contact %d", a);
    return pd_err_set(err, PD_EINVAL,
                      "contact-duration: the equivalent force pi I / (2 td)%s "
                      "overflows (impulse I = %g): give a longer duration",
                      which, impulse);
}

/* A drift ratio drift / h that overflows while the drift does not: the
 * storey height's fault. */
int pd_demand_check_drift(double drift, double ratio, const char *name, int storey, pd_err *err)
{
    if (isfinite(ratio) || !isfinite(drift))
        return PD_OK;
    return pd_err_set(err, PD_EINVAL,
                      "storey_heights: the drift ratio of storey %d of %s "
                      "overflows (drift %g m over its height): give a larger height",
                      storey, name, drift);
}

double pd_demand_td(const pd_run_opts *o)
{
    return o && o->contact_duration > 0.0 ? o->contact_duration : PD_CONTACT_DURATION;
}

/* pd_demand_eval_structure's sums, inlined into pd_demand_eval's loop. */
static inline void eval_structure(const pd_structure *st, const double *x, const double *v,
                                  double us, double vs, double *a, double *V)
{
    if (st->storeys == 1) { /* an SDOF: the sums below with one floor */
        int i = st->dof;
        double S = st->stiffness[0] * (us * x[i] + st->beta * (vs * v[i]));
        double mv = st->alpha * st->mass[0] * vs * v[i];
        a[i] = -(S + mv) / st->mass[0];
        V[i] = S + mv;
        return;
    }
    {
        const double *xs = x + st->dof, *vs_ = v + st->dof;
        double S_up = 0.0, mv_up = 0.0; /* S_k+1, alpha sum over floors above of m u' */
        for (int k = st->storeys - 1; k >= 0; k--) {
            double d = us * (xs[k] - (k > 0 ? xs[k - 1] : 0.0));
            double dv = vs * (vs_[k] - (k > 0 ? vs_[k - 1] : 0.0));
            double S = st->stiffness[k] * (d + st->beta * dv);
            double mv = st->alpha * st->mass[k] * vs * vs_[k];
            double f = S - S_up + mv; /* (C u' + K u) of floor k */
            a[st->dof + k] = -f / st->mass[k];
            mv_up += mv;
            V[st->dof + k] = S + mv_up;
            S_up = S;
        }
    }
}

void pd_demand_eval_structure(const pd_structure *st, const double *x, const double *v, double us,
                              double vs, double *a, double *V)
{
    eval_structure(st, x, v, us, vs, a, V);
}

void pd_demand_eval(const pd_scene *sc, const double *x, const double *v, double us, double vs,
                    double *a, double *V)
{
    for (int s = 0; s < sc->nstruct; s++)
        eval_structure(&sc->st[s], x, v, us, vs, a, V);
}

void pd_demand_note(const pd_scene *sc, const double *x, const double *v, double us, double vs,
                    double *a, double *V, double *acc, double *shear)
{
    pd_demand_eval(sc, x, v, us, vs, a, V);
    for (int i = 0; i < sc->n; i++) {
        acc[i] = pd_max(acc[i], fabs(a[i]));
        shear[i] = pd_max(shear[i], fabs(V[i]));
    }
}

void pd_demand_osc_finish(pd_osc_result *res, const pd_run_opts *o, double acc_max,
                          double shear_max, double force_max)
{
    res->acc_max = acc_max;
    res->shear_max = shear_max;
    res->force_max = force_max;
    res->contact_duration = pd_demand_td(o);
    res->force_equiv = pd_equivalent_force(res->max_impulse, res->contact_duration);
}

/* The cubic p(t) = ((a t + b) t + c) t + d at t. */
static double cubic_at(double a, double b, double c, double d, double t)
{
    return ((a * t + b) * t + c) * t + d;
}

double pd_demand_cubic_peak(double f0, double d0, double f1, double d1, double h)
{
    /* the cubic Hermite in t = s / h in [0, 1] */
    double c = h * d0, b = 3.0 * (f1 - f0) - h * (2.0 * d0 + d1);
    double a = 2.0 * (f0 - f1) + h * (d0 + d1), peak = 0.0;
    double A = 3.0 * a, B = 2.0 * b, t[2];
    int nt = 0;
    if (fabs(A) <= 1e-14 * (fabs(B) + fabs(c))) { /* p' linear */
        if (B != 0.0)
            t[nt++] = -c / B;
    } else {
        double disc = B * B - 4.0 * A * c;
        if (disc >= 0.0) {
            double q = -0.5 * (B + copysign(sqrt(disc), B));
            t[nt++] = q / A;
            if (q != 0.0)
                t[nt++] = c / q;
        }
    }
    for (int k = 0; k < nt; k++)
        if (t[k] > 0.0 && t[k] < 1.0)
            peak = pd_max(peak, fabs(cubic_at(a, b, c, f0, t[k])));
    return peak;
}

/* alpha = d0 / m, beta = d1 / m >= 0 and alpha^2 + beta^2 <= 9, times m^2 h^2. */
int pd_demand_cubic_monotone(double f0, double d0, double f1, double d1, double h)
{
    double df = f1 - f0;
    return d0 * df >= 0.0 && d1 * df >= 0.0 && (d0 * d0 + d1 * d1) * (h * h) <= 9.0 * df * df;
}

void pd_demand_osc_note(pd_demand_osc *d, double tau, double x, double v, const double *a,
                        double lam, int smooth)
{
    pd_demand_osc_note_state(d, tau, x, v, lam);
    if (tau < d->tau_measure || !a || lam != 0.0) {
        d->prev = 0;
        return;
    }
    double f = d->C * v + d->K * x;
    double fd = d->C * *a + d->K * v, h = tau - d->t;
    if (d->prev && smooth && h > 0.0) { /* free at both ends: a_abs is the shear */
        double p = pd_demand_cubic_peak(d->f, d->fd, f, fd, h);
        d->peak = pd_max(d->peak, p);
        d->shear = pd_max(d->shear, p);
    }
    d->f = f;
    d->fd = fd;
    d->t = tau;
    d->prev = 1;
}

#define DEMAND_TURN_TOL 1e-12 /* the turn's place, in fractions of the step */
#define DEMAND_TURN_ITERS 100

int pd_demand_quintic_turn(const double p0[3], const double p1[3], double h, double *f)
{
    /* the rate's sign change bracketed in [lo, hi]: Illinois steps (the
     * secant through the bracket, the kept end's value halved when it is
     * kept twice) to DEMAND_TURN_TOL; the value there is off by
     * O(tol^2) of the step's curvature */
    double lo = 0.0, hi = 1.0, flo = p0[1], fhi = p1[1], s = 0.5, fd;
    int side = 0;
    if (!(p0[1] * p1[1] < 0.0))
        return 0;
    for (int it = 0; it < DEMAND_TURN_ITERS && hi - lo > DEMAND_TURN_TOL; it++) {
        s = (lo * fhi - hi * flo) / (fhi - flo);
        if (!(s > lo && s < hi))
            s = 0.5 * (lo + hi);
        pd_hermite5(p0, p1, h, s, f, &fd);
        if (fd == 0.0)
            return 1;
        if ((fd < 0.0) == (flo < 0.0)) {
            lo = s;
            flo = fd;
            if (side == -1)
                fhi *= 0.5;
            side = -1;
        } else {
            hi = s;
            fhi = fd;
            if (side == 1)
                flo *= 0.5;
            side = 1;
        }
    }
    pd_hermite5(p0, p1, h, s, f, NULL);
    return 1;
}
