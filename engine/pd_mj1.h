/* pd_mj1.h — the one-degree-of-freedom, at-most-one-contact Moreau–Jean step
 * and its loop: the engine's inline interface (not installed) to the layers
 * that fuse their measurements into the loop.  Its step is the one of the
 * scalar kernel of pd_mj (mj.c), of the batch pd_mjb (mj_batch.c) and of
 * the one-wall oscillator's measured run (problems/oscillator.c), so that
 * all compute the same numbers, bit for bit; its loop is pd_mj_run's and
 * the oscillator's.
 *
 *   What  = M + h theta C + h^2 theta^2 K,   W^ = W / What,  D = W W^
 *   vfree = v + What^-1 h [F_theta - C v - K (q + h theta v)]
 *   active when g + h gamma U <= 0 (U = W v); then
 *   P = max(0, -(W vfree + e U)) / D,  v+ = vfree + W^ P
 *   q+ = q + h [theta v+ + (1 - theta) v],  g+ = g0 + W q+ */
#ifndef PD_MJ1_H
#define PD_MJ1_H

#include <math.h>

#include "pd_cpu.h"
#include "pd_engine.h"

/* The constants of one system: its own and the reciprocals that keep
 * divisions out of a step. */
typedef struct mj1_coef {
    double c, k, w, e, g0; /* C, K, W, restitution, gap offset (0 without a contact) */
    double whatinv;        /* 1 / What, What = M + h theta C + h^2 theta^2 K */
    double winv;           /* W / What */
    double delinv;         /* 1 / (W^2 / What), 0 without a contact */
    int wall;              /* 1: the contact exists */
} mj1_coef;

/* The constants from M, C, K, the contact (wall: it exists; W, g0, e are
 * ignored otherwise), h and theta. */
static inline mj1_coef mj1_coef_make(double M, double C, double K, int wall, double W, double g0,
                                     double e, double h, double th)
{
    double what = M + h * th * C + h * h * th * th * K; /* What */
    mj1_coef s = {.c = C,
                  .k = K,
                  .w = wall ? W : 0.0,
                  .e = wall ? e : 0.0,
                  .g0 = wall ? g0 : 0.0,
                  .wall = wall != 0};
    s.winv = s.w / what;       /* W^ = W / What */
    double del = s.w * s.winv; /* D = W W^ */
    s.whatinv = 1.0 / what;
    s.delinv = del != 0.0 ? 1.0 / del : 0.0; /* 1 / D, 0 without a wall */
    return s;
}

/* theta F1 + (1 - theta) F0: the step's force from F0 at its start and F1
 * at its end (the batch's force tables form it by this too). */
static inline double mj1_fth(double th, double F0, double F1)
{
    return th * F1 + (1.0 - th) * F0;
}

/* One step from (q, v) with the gap g at t_k and the forces F0 (t_k+) and
 * F1 (t_k+1-): q, v and g move to t_k+1, *P gets the impulse; returns 1
 * when the contact was active.  hgamma = h gamma.  The branches are the
 * processor's to predict: one system's step is a chain of latencies. */
static inline int mj1_step(double h, double th, double hgamma, const mj1_coef *s, double F0,
                           double F1, double *q, double *v, double *g, double *P)
{
    double q0 = *q, v0 = *v, imp = 0.0;
    double Fth = mj1_fth(th, F0, F1);
    double rhs = h * (Fth - s->c * v0 - s->k * (q0 + h * th * v0)); /* h (F_th - C v - K q_th) */
    double vnew = v0 + rhs * s->whatinv;                            /* vfree */
    double U0 = s->w * v0;                                          /* U_k = W v_k */
    int active = s->wall && *g + hgamma * U0 <= 0.0;                /* g + h gamma U <= 0 */
    if (active) {
        double b = s->w * vnew + s->e * U0; /* the scalar LCP, closed form */
        imp = b < 0.0 ? -b * s->delinv : 0.0;
        vnew += s->winv * imp; /* v+ = vfree + W^ P */
    }
    double qnew = q0 + h * (th * vnew + (1.0 - th) * v0); /* q+ */
    *q = qnew;
    *v = vnew;
    *g = s->g0 + s->w * qnew; /* g+ = g0 + W q+ */
    *P = imp;
    return active;
}

/* ---- a yielding spring: the slider beside the contact ----------------- *
 * The spring K [alpha q + (1 - alpha) z], |z| <= uy (docs/methods.md,
 * "Yielding"), with up = q - z the plastic offset and Gamma its increment
 * over the step (0 <= Gamma _|_ uy - z+ >= 0, and the mirror at -uy): the
 * step's spring force is K q_theta - kbar (up + theta Gamma), kbar =
 * (1 - alpha) K, so that
 *   v+ = vfree + (h kbar / What) up + a Gamma + W^ P,   a = h theta kbar / What
 *   z+ = ztrial - s Gamma + h theta W^ P,               s = 1 - h theta a > 0
 * with ztrial the step's z+ at Gamma = P = 0.  The LCP in (P, Gamma) has the
 * matrix [D, W a; -h theta W^, s], a P-matrix (positive diagonal, positive
 * determinant): one answer.  The elastic step's (Gamma = 0) is it when its
 * |z+| <= uy; else Gamma has the sign sigma of the side passed, z+ = sigma
 * uy, and the contact's scalar LCP with Gamma eliminated is
 *   b' = b + W a (ztrial - sigma uy) / s,   D' = D + h theta a W W^ / s. */
typedef struct mj1_yield {
    double uy;     /* the yield displacement > 0 */
    double hkw;    /* h kbar / What: v's response to the offset */
    double a;      /* h theta kbar / What: v's response to Gamma */
    double sinv;   /* 1 / s */
    double hthw;   /* h theta W / What: z's response to P */
    double delinv; /* 1 / D', 0 without a wall */
} mj1_yield;

/* The slider's constants for the system s (stiffness K) stepped by h, theta. */
static inline mj1_yield mj1_yield_make(const mj1_coef *s, double K, double alpha, double uy,
                                       double h, double th)
{
    double kbar = (1.0 - alpha) * K;
    mj1_yield y = {.uy = uy,
                   .hkw = h * kbar * s->whatinv,
                   .a = h * th * kbar * s->whatinv,
                   .hthw = h * th * s->winv};
    y.sinv = 1.0 / (1.0 - h * th * y.a);
    double del = s->w * s->winv + y.a * y.hthw * s->w * y.sinv; /* D' */
    y.delinv = del != 0.0 ? 1.0 / del : 0.0;
    return y;
}

/* mj1_step with the slider: also up (the plastic offset) moves, and *G
 * gets the step's Gamma.  While nothing yields (up = 0, Gamma = 0) its
 * numbers are mj1_step's, bit for bit. */
static inline int mj1y_step(double h, double th, double hgamma, const mj1_coef *s,
                            const mj1_yield *y, double F0, double F1, double *q, double *v,
                            double *g, double *P, double *up, double *G)
{
    double q0 = *q, v0 = *v, imp = 0.0, gam = 0.0;
    double Fth = mj1_fth(th, F0, F1);
    double rhs = h * (Fth - s->c * v0 - s->k * (q0 + h * th * v0));
    double vfree = v0 + rhs * s->whatinv;
    if (*up != 0.0) /* the offset's force kbar up */
        vfree += y->hkw * *up;
    double U0 = s->w * v0, b = 0.0;
    int active = s->wall && *g + hgamma * U0 <= 0.0;
    double vnew = vfree;
    if (active) { /* the elastic step's contact */
        b = s->w * vfree + s->e * U0;
        imp = b < 0.0 ? -b * s->delinv : 0.0;
        vnew += s->winv * imp;
    }
    double qnew = q0 + h * (th * vnew + (1.0 - th) * v0);
    double z = qnew - *up;
    if (!(fabs(z) <= y->uy)) {
        /* it yields toward sigma: Gamma from z+ = sigma uy, P from (b', D') */
        double sig = z > 0.0 ? 1.0 : -1.0;
        double ztr = q0 + h * (th * vfree + (1.0 - th) * v0) - *up;
        if (active) {
            double bb = b + s->w * y->a * (ztr - sig * y->uy) * y->sinv;
            imp = bb < 0.0 ? -bb * y->delinv : 0.0;
        }
        gam = (ztr + y->hthw * imp - sig * y->uy) * y->sinv;
        vnew = vfree + y->a * gam + s->winv * imp;
        qnew = q0 + h * (th * vnew + (1.0 - th) * v0);
    }
    *q = qnew;
    *v = vnew;
    *g = s->g0 + s->w * qnew;
    *P = imp;
    *up += gam;
    *G = gam;
    return active;
}

/* ---- the constants of a vector of systems -------------------------- *
 * The batch (engine/mj_batch.c) keeps its systems' constants in groups of
 * MJ1_WIDTH lanes; its step (mj_batch_lanes.h) computes, lane by lane,
 * mj1_step's numbers: the same operations in the same order, plain IEEE
 * double arithmetic (tests/test_engine.c compares them bit for bit; the
 * build keeps the compiler from fusing multiplications and additions), the
 * choices as selections, not branches. */
#define MJ1_WIDTH 8
typedef double mj1_vec __attribute__((vector_size(8 * MJ1_WIDTH)));

/* The same vectors at any address of a double (the batch object may sit
 * where malloc puts it): loads and stores that do not assume alignment. */
typedef double mj1_uvec __attribute__((vector_size(8 * MJ1_WIDTH), aligned(8)));
typedef long long mj1_umask __attribute__((vector_size(8 * MJ1_WIDTH), aligned(8)));

/* mj1_coef's constants per lane (-1/D for 1/D), with the lane's h theta and h gamma,
 * stored in pd_mjb's coef array (may_alias: read and written as this
 * type only, over storage declared as doubles). */
typedef struct __attribute__((may_alias)) mj1_coefv {
    mj1_uvec c, k, w, e, g0, whatinv, winv, ndelinv, hth, hgamma;
    mj1_umask wall;
} mj1_coefv;

/* Lane i of s from one system's constants, its step h, theta and gamma. */
static inline void mj1_coef_setv(mj1_coefv *s, int i, const mj1_coef *one, double h, double th,
                                 double gamma)
{
    s->c[i] = one->c;
    s->k[i] = one->k;
    s->w[i] = one->w;
    s->e[i] = one->e;
    s->g0[i] = one->g0;
    s->whatinv[i] = one->whatinv;
    s->winv[i] = one->winv;
    s->ndelinv[i] = -one->delinv; /* -1/D: the impulse as a product */
    s->hth[i] = h * th;
    s->hgamma[i] = h * gamma;
    s->wall[i] = one->wall ? -1 : 0;
}

/* The batch's step over every lane, per instruction set (mj_batch_lanes.h):
 * x86-64 variants with GCC; the baseline everywhere. */
void pd_mjb_lanes_step_base(pd_mjb *b);
void pd_mjb_lanes_step_x86v3(pd_mjb *b);
void pd_mjb_lanes_step_x86v4(pd_mjb *b);

/* Past force breakpoints: moves *next beyond those before t1 and returns 1
 * when t1 lands on one (within tol): the next step starts from F(t1+). */
static inline int mj_break_at(const double *breaks, int nbreaks, int *next, double t1, double tol)
{
    while (*next < nbreaks && breaks[*next] < t1 - tol)
        (*next)++;
    if (*next < nbreaks && breaks[*next] <= t1 + tol) {
        (*next)++;
        return 1;
    }
    return 0;
}

/* ---- the scalar kernel's loop ------------------------------------------ *
 * nsteps steps of mj1_step (mj1y_step with the slider yl, when not NULL)
 * from the state x at step x->step (its time t0 +
 * step h): the force's left limits F(t_k+1 -) asked MJ1_FORCE_AHEAD steps
 * ahead (the same values at the same instants, so that the excitation's
 * evaluation runs beside the step's chain of latencies instead of in it),
 * its right limit F(t+) after a breakpoint, observe after each step (> 0:
 * stop).  force and observe are the caller's static functions: the loop
 * is inlined where it is called and they in it, so that the state stays in
 * registers (pd_mj_run's scalar kernel, engine/mj.c; the one-wall
 * oscillator's measured run, problems/oscillator.c). */
#define MJ1_FORCE_AHEAD 8 /* a power of 2 */

typedef struct mj1_state {
    double q, v, g; /* the state at step */
    double P;       /* the impulse of the last step */
    double F0;      /* F(t_step +): the next step's force at its start */
    double F1;      /* F(t_step -): the last step's force at its end */
    long step;      /* steps taken */
    int next_break; /* the first force breakpoint not passed */
    int active;     /* the last step's contact was active */
    double up, G;   /* a yielding spring's plastic offset, and its last step's increment */
} mj1_state;

/* F(t) from the left (side -1) or the right (+1). */
typedef double (*mj1_force_fn)(void *ctx, double t, int side);
/* After a step ending at t; > 0 stops the run. */
typedef int (*mj1_observe_fn)(void *ctx, const mj1_state *x, double t);

static inline __attribute__((always_inline)) int
mj1_run(const mj1_coef *s, const mj1_yield *yl, double h, double th, double gamma, double t0,
        const double *breaks, int nbreaks, long nsteps, mj1_state *x, mj1_force_fn force,
        mj1_observe_fn observe, void *ctx, pd_err *err)
{
    const double hgamma = h * gamma, tol = 1e-9 * h; /* tol: a breakpoint this near t1 is on it */
    const long k0 = x->step;
    mj1_state y = *x; /* in registers */
    double F[MJ1_FORCE_AHEAD];
    for (long k = 0; k < nsteps && k < MJ1_FORCE_AHEAD; k++)
        F[k] = force(ctx, t0 + (double)(k0 + k + 1) * h, -1);
    for (long k = 0; k < nsteps; k++) {
        /* F(t_k+1 -) from the ring; the slot refilled MJ1_FORCE_AHEAD ahead */
        double t1 = t0 + (double)(k0 + k + 1) * h;
        y.F1 = F[k & (MJ1_FORCE_AHEAD - 1)];
        if (k + MJ1_FORCE_AHEAD < nsteps)
            F[k & (MJ1_FORCE_AHEAD - 1)] =
                force(ctx, t0 + (double)(k0 + k + MJ1_FORCE_AHEAD + 1) * h, -1);
        if (yl) /* a constant where the loop is inlined: one of the two steps is compiled */
            y.active =
                mj1y_step(h, th, hgamma, s, yl, y.F0, y.F1, &y.q, &y.v, &y.g, &y.P, &y.up, &y.G);
        else
            y.active = mj1_step(h, th, hgamma, s, y.F0, y.F1, &y.q, &y.v, &y.g, &y.P);
        y.step++;
        /* the next step starts from F(t1 +): F1, or the right limit at a breakpoint */
        y.F0 = y.F1;
        if (y.next_break < nbreaks && mj_break_at(breaks, nbreaks, &y.next_break, t1, tol))
            y.F0 = force(ctx, t1, +1);
        if (!isfinite(y.q) || !isfinite(y.v)) {
            *x = y;
            return pd_err_set(err, PD_ENONFINITE,
                              "Moreau-Jean: non-finite state at t = %.9g (step %ld, dof %d)", t1,
                              y.step, 0);
        }
        if (observe && observe(ctx, &y, t1) > 0)
            break;
    }
    *x = y;
    return PD_OK;
}

/* h > 0 finite, theta in [1/2, 1] (in [0, 2] when allowed), gamma in
 * [0, 1]: PD_OK or PD_EINVAL naming the option. */
int pd_mj_check_opts(const pd_mj_opts *o, pd_err *err);

#endif
