/* mj1.h — the one-degree-of-freedom, at-most-one-contact Moreau–Jean step
 * (engine-private), shared by the scalar kernel of pd_mj (moreau.c) and the
 * batch pd_mjb (mj_batch.c), so that both compute the same numbers, bit for
 * bit.
 *
 *   What  = M + h theta C + h^2 theta^2 K,   W^ = W / What,  D = W W^
 *   vfree = v + What^-1 h [F_theta - C v - K (q + h theta v)]
 *   active when g + h gamma U <= 0 (U = W v); then
 *   P = max(0, -(W vfree + e U)) / D,  v+ = vfree + W^ P
 *   q+ = q + h [theta v+ + (1 - theta) v],  g+ = g0 + W q+ */
#ifndef PD_MJ1_H
#define PD_MJ1_H

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
    double what = M + h * th * C + h * h * th * th * K;
    mj1_coef s = {.c = C, .k = K, .w = wall ? W : 0.0, .e = wall ? e : 0.0,
                  .g0 = wall ? g0 : 0.0, .wall = wall != 0};
    s.winv = s.w / what;
    double del = s.w * s.winv;
    s.whatinv = 1.0 / what;
    s.delinv = del != 0.0 ? 1.0 / del : 0.0;
    return s;
}

/* One step from (q, v) with the gap g at t_k and the forces F0 (t_k+) and
 * F1 (t_k+1-): q, v and g move to t_k+1, *P gets the impulse; returns 1
 * when the contact was active.  hgamma = h gamma.  The branches are the
 * processor's to predict: one system's step is a chain of latencies. */
static inline int mj1_step(double h, double th, double hgamma, const mj1_coef *s, double F0,
                           double F1, double *q, double *v, double *g, double *P)
{
    double q0 = *q, v0 = *v, imp = 0.0;
    double Fth = th * F1 + (1.0 - th) * F0;
    double rhs = h * (Fth - s->c * v0 - s->k * (q0 + h * th * v0));
    double vnew = v0 + rhs * s->whatinv;
    double U0 = s->w * v0;
    int active = s->wall && *g + hgamma * U0 <= 0.0;
    if (active) {
        double b = s->w * vnew + s->e * U0; /* the scalar LCP, closed form */
        imp = b < 0.0 ? -b * s->delinv : 0.0;
        vnew += s->winv * imp;
    }
    double qnew = q0 + h * (th * vnew + (1.0 - th) * v0);
    *q = qnew;
    *v = vnew;
    *g = s->g0 + s->w * qnew;
    *P = imp;
    return active;
}

/* ---- the same step on a vector of systems ---------------------------- *
 * MJ1_WIDTH lanes of doubles (one AVX-512 register; two AVX2 or four SSE2
 * registers otherwise), each lane plain IEEE double arithmetic: lane i of
 * mj1_stepv computes mj1_step's numbers for system i, the same operations
 * in the same order (tests/test_engine.c compares them bit for bit; the
 * build keeps the compiler from fusing multiplications and additions).  The
 * choices are selections, not branches: many systems side by side are a
 * question of throughput, not latency. */
#define MJ1_WIDTH 8
typedef double mj1_vec __attribute__((vector_size(8 * MJ1_WIDTH)));
typedef long long mj1_mask __attribute__((vector_size(8 * MJ1_WIDTH))); /* all ones or zero */

/* a where the mask m is set, else b. */
#define MJ1_SELECT(m, a, b) ((mj1_vec)(((m) & (mj1_mask)(a)) | (~(m) & (mj1_mask)(b))))

/* The same vectors at any address of a double (the batch object may sit
 * where malloc puts it): loads and stores that do not assume alignment. */
typedef double mj1_uvec __attribute__((vector_size(8 * MJ1_WIDTH), aligned(8)));
typedef long long mj1_umask __attribute__((vector_size(8 * MJ1_WIDTH), aligned(8)));

/* mj1_coef's constants per lane, with the lane's h theta and h gamma,
 * stored in pd_mjb's coef array (may_alias: read and written as this
 * type only, over storage declared as doubles). */
typedef struct __attribute__((may_alias)) mj1_coefv {
    mj1_uvec c, k, w, e, g0, whatinv, winv, delinv, hth, hgamma;
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
    s->delinv[i] = one->delinv;
    s->hth[i] = h * th;
    s->hgamma[i] = h * gamma;
    s->wall[i] = one->wall ? -1 : 0;
}

/* mj1_step on a vector of lanes (steps h): P is 0 where the contact was
 * not active. */
static inline void mj1_stepv(double th, const mj1_vec *hp, const mj1_coefv *s,
                             const mj1_vec *F0, const mj1_vec *F1, mj1_vec *q, mj1_vec *v,
                             mj1_vec *g, mj1_vec *P)
{
    const mj1_vec zero = {0.0};
    mj1_vec q0 = *q, v0 = *v, h = *hp;
    mj1_vec Fth = th * *F1 + (1.0 - th) * *F0;
    mj1_vec rhs = h * (Fth - s->c * v0 - s->k * (q0 + s->hth * v0));
    mj1_vec vfree = v0 + rhs * s->whatinv;
    mj1_vec U0 = s->w * v0;
    mj1_mask active = s->wall & (*g + s->hgamma * U0 <= zero);
    mj1_vec b = s->w * vfree + s->e * U0;
    mj1_vec imp = MJ1_SELECT(active & (b < zero), -b * s->delinv, zero);
    mj1_vec vnew = MJ1_SELECT(active, vfree + s->winv * imp, vfree);
    mj1_vec qnew = q0 + h * (th * vnew + (1.0 - th) * v0);
    *q = qnew;
    *v = vnew;
    *g = s->g0 + s->w * qnew;
    *P = imp;
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

/* h > 0 finite, theta in [1/2, 1] (in [0, 2] when allowed), gamma in
 * [0, 1]: PD_OK or PD_EINVAL naming the option. */
int pd_mj_check_opts(const pd_mj_opts *o, pd_err *err);

#endif
