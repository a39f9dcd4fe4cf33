/* test_yield_edr_rk.c — the row reference on yielding structures whose
 * flights are modal (shear buildings with a spring on every storey drift,
 * overdamped oscillators) against an independent integration written here.
 *
 * The integration shares nothing with the reference but the forcing pieces
 * (pd_sine_piece_force) and the model's matrices:
 *   - classical fourth-order Runge–Kutta on M q'' = b f - C q' - K q +
 *     sum_j S_j ks_j up_j, up_j fixed while spring j is elastic and
 *     d_j - ph uy_j while it slides toward ph (d_j = S_j^T q its drift), at
 *     a fixed step (its shortest period / STEPS_PER_PERIOD) that never
 *     crosses a piece's start;
 *   - every event found by bisecting the length of one step from its start
 *     to adjacent doubles: an onset (|d - up| reaches uy), an unloading (a
 *     slide's drift rate turning back), and each drift's turns (its peaks);
 * then run again at half the step: the two runs bound the integration's own
 * error (RK4: about 16x closer), and the reference must agree with both
 * within FIG_TOL; its energy balance (input = kinetic + strain + damping +
 * hysteretic) must close within ENERGY_TOL.  No contact: an impact's
 * exactness is the row reference's own tests' (test_rows.c); here the
 * phases' flights and their constants (the offsets' force in the modes)
 * are checked. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "event_row.h"
#include "pd_core.h"
#include "pd_engine.h"
#include "pd_test.h"

#define YRK_N 6              /* dofs at most */
#define STEPS_PER_PERIOD 1e3 /* RK4 steps in the shortest period */
/* The reference against the integration: peaks relative, offsets and
 * excursions over uy (measured: see the cases' lines). */
#define FIG_TOL 1e-9
/* The reference's energy balance, of the input work (its flights' integrals
 * by Gauss-Legendre; measured below 1e-14). */
#define ENERGY_TOL 1e-12

/* A model of at most YRK_N dofs and springs, dense, M diagonal. */
typedef struct yrk_model {
    int n, ns;
    double M[YRK_N * YRK_N], C[YRK_N * YRK_N], K[YRK_N * YRK_N], S[YRK_N * YRK_N];
    double ks[YRK_N], uy[YRK_N], b[YRK_N];
    const pd_sine_piece *pc;
    int npc;
} yrk_model;

/* One integration's state and tallies. */
typedef struct yrk {
    const yrk_model *m;
    int k; /* the forcing piece of the step */
    double t, q[YRK_N], v[YRK_N];
    int ph[YRK_N];                              /* 0 elastic, +-1 sliding toward that side */
    double up[YRK_N];                           /* fixed while elastic */
    double upx[YRK_N], exc[YRK_N], peak[YRK_N]; /* slide's start, excursion, peak |d| */
    long onsets[YRK_N];
} yrk;

static double drift(const yrk_model *m, int j, const double *y)
{
    double d = 0.0;
    for (int i = 0; i < m->n; i++)
        d += m->S[i + j * m->n] * y[i];
    return d;
}

/* Spring j's offset at q in its phase. */
static double offset(const yrk *r, int j, const double *q)
{
    return r->ph[j] ? drift(r->m, j, q) - r->ph[j] * r->m->uy[j] : r->up[j];
}

/* a = M^-1 (b f - C v - K q + S ks up(q)), f the step's piece's (its
 * left limit at the piece's end). */
static void accel(const yrk *r, double t, const double *q, const double *v, double *a)
{
    const yrk_model *m = r->m;
    double f = pd_sine_piece_force(&m->pc[r->k], t);
    for (int i = 0; i < m->n; i++) {
        double s = m->b[i] * f;
        for (int k = 0; k < m->n; k++)
            s -= m->C[i + k * m->n] * v[k] + m->K[i + k * m->n] * q[k];
        for (int j = 0; j < m->ns; j++)
            s += m->S[i + j * m->n] * m->ks[j] * offset(r, j, q);
        a[i] = s / m->M[i + i * m->n];
    }
}

/* One RK4 step of length tau from r's state into (q1, v1). */
static void rk4(const yrk *r, double tau, double *q1, double *v1)
{
    int n = r->m->n;
    double k1q[YRK_N], k1v[YRK_N], k2q[YRK_N], k2v[YRK_N], k3q[YRK_N], k3v[YRK_N], k4q[YRK_N],
        k4v[YRK_N], qt[YRK_N] = {0}, vt[YRK_N] = {0};
    memcpy(k1q, r->v, sizeof k1q);
    accel(r, r->t, r->q, r->v, k1v);
    for (int i = 0; i < n; i++) {
        qt[i] = r->q[i] + 0.5 * tau * k1q[i];
        vt[i] = r->v[i] + 0.5 * tau * k1v[i];
    }
    memcpy(k2q, vt, sizeof k2q);
    accel(r, r->t + 0.5 * tau, qt, vt, k2v);
    for (int i = 0; i < n; i++) {
        qt[i] = r->q[i] + 0.5 * tau * k2q[i];
        vt[i] = r->v[i] + 0.5 * tau * k2v[i];
    }
    memcpy(k3q, vt, sizeof k3q);
    accel(r, r->t + 0.5 * tau, qt, vt, k3v);
    for (int i = 0; i < n; i++) {
        qt[i] = r->q[i] + tau * k3q[i];
        vt[i] = r->v[i] + tau * k3v[i];
    }
    memcpy(k4q, vt, sizeof k4q);
    accel(r, r->t + tau, qt, vt, k4v);
    for (int i = 0; i < n; i++) {
        q1[i] = r->q[i] + tau / 6.0 * (k1q[i] + 2.0 * k2q[i] + 2.0 * k3q[i] + k4q[i]);
        v1[i] = r->v[i] + tau / 6.0 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i]);
    }
}

/* Whether a phase event has happened at (q1, v1): an elastic spring past
 * its level, a slide's drift rate turned back. */
static int happened(const yrk *r, int j, const double *q1, const double *v1)
{
    if (r->ph[j] == 0)
        return fabs(drift(r->m, j, q1) - r->up[j]) > r->m->uy[j];
    return r->ph[j] * drift(r->m, j, v1) < 0.0;
}

static int any_event(const yrk *r, const double *q1, const double *v1)
{
    for (int j = 0; j < r->m->ns; j++)
        if (happened(r, j, q1, v1))
            return 1;
    return 0;
}

/* The first double tau in (0, hi] where pred holds at the step's end (it
 * holds at hi, not at 0): bisection on the step's length. */
static double locate(const yrk *r, double hi,
                     int (*pred)(const yrk *, const double *, const double *, int), int j)
{
    double lo = 0.0, q1[YRK_N], v1[YRK_N];
    while (1) {
        double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi)
            return hi;
        rk4(r, mid, q1, v1);
        if (pred(r, q1, v1, j))
            hi = mid;
        else
            lo = mid;
    }
}

static int pred_event(const yrk *r, const double *q1, const double *v1, int j)
{
    (void)j;
    return any_event(r, q1, v1);
}

/* Drift j's rate has changed sign from the step's start. */
static int pred_turn(const yrk *r, const double *q1, const double *v1, int j)
{
    (void)q1;
    return drift(r->m, j, v1) * drift(r->m, j, r->v) <= 0.0;
}

/* The peaks of every drift over the step to tau (its turns inside). */
static void note_peaks(yrk *r, double tau, const double *q1, const double *v1)
{
    for (int j = 0; j < r->m->ns; j++) {
        r->peak[j] = fmax(r->peak[j], fabs(drift(r->m, j, q1)));
        if (drift(r->m, j, v1) * drift(r->m, j, r->v) < 0.0) { /* a turn inside */
            double q2[YRK_N], v2[YRK_N];
            rk4(r, locate(r, tau, pred_turn, j), q2, v2);
            r->peak[j] = fmax(r->peak[j], fabs(drift(r->m, j, q2)));
        }
    }
}

/* The state moves to the step's end tau. */
static void advance(yrk *r, double tau, const double *q1, const double *v1)
{
    note_peaks(r, tau, q1, v1);
    memcpy(r->q, q1, sizeof r->q);
    memcpy(r->v, v1, sizeof r->v);
    r->t += tau;
}

/* Each spring whose event has happened changes phase. */
static void switch_phases(yrk *r)
{
    for (int j = 0; j < r->m->ns; j++) {
        if (!happened(r, j, r->q, r->v))
            continue;
        double d = drift(r->m, j, r->q);
        if (r->ph[j] == 0) { /* an onset: sliding toward z's side */
            r->ph[j] = d - r->up[j] > 0.0 ? 1 : -1;
            r->upx[j] = r->up[j];
            r->onsets[j]++;
        } else { /* an unloading: the offset stays where the slide left it */
            r->up[j] = d - r->ph[j] * r->m->uy[j];
            r->exc[j] += fabs(r->up[j] - r->upx[j]);
            r->ph[j] = 0;
        }
    }
}

/* Integrate from rest to t_end at step h. */
static void integrate(yrk *r, const yrk_model *m, double h, double t_end)
{
    memset(r, 0, sizeof *r);
    r->m = m;
    int k = 0;
    while (r->t < t_end) {
        while (k + 1 < m->npc && m->pc[k + 1].t_start <= r->t)
            k++;
        r->k = k;
        double stop = k + 1 < m->npc ? fmin(m->pc[k + 1].t_start, t_end) : t_end;
        double tau = fmin(h, stop - r->t), q1[YRK_N], v1[YRK_N];
        rk4(r, tau, q1, v1);
        if (any_event(r, q1, v1)) { /* to the first event, then its phases */
            tau = locate(r, tau, pred_event, 0);
            rk4(r, tau, q1, v1);
            advance(r, tau, q1, v1);
            switch_phases(r);
        } else
            advance(r, tau, q1, v1);
        if (stop - r->t < 1e-12 * h) /* a piece's start, or the end: exactly there */
            r->t = stop;
    }
    for (int j = 0; j < m->ns; j++) /* the offsets at the end; a slide's excursion closed */
        if (r->ph[j]) {
            r->up[j] = offset(r, j, r->q);
            r->exc[j] += fabs(r->up[j] - r->upx[j]);
        }
}

/* A shear building of n storeys (masses m, storey stiffnesses k, Rayleigh
 * damping xi on its first two modes' periods T1, T2 given), a spring on
 * every storey's drift (ks = (1 - alpha) k, uy), loaded by b = m f. */
static void building(yrk_model *y, int n, const double *mass, const double *k, double a0, double a1,
                     const double *uy, double alpha)
{
    memset(y, 0, sizeof *y);
    y->n = y->ns = n;
    for (int i = 0; i < n; i++) {
        y->M[i + i * n] = mass[i];
        y->b[i] = mass[i];
        /* storey i between dof i - 1 (or the ground) and dof i */
        y->K[i + i * n] += k[i];
        if (i > 0) {
            y->K[(i - 1) + (i - 1) * n] += k[i];
            y->K[i + (i - 1) * n] -= k[i];
            y->K[(i - 1) + i * n] -= k[i];
        }
        y->S[i + i * n] = 1.0;
        if (i > 0)
            y->S[(i - 1) + i * n] = -1.0;
        y->ks[i] = (1.0 - alpha) * k[i];
        y->uy[i] = uy[i];
    }
    for (int i = 0; i < n * n; i++)
        y->C[i] = a0 * y->M[i] + a1 * y->K[i];
}

/* The row reference on y's model to t_end: peaks of the drifts, offsets,
 * excursions, onsets into the arrays, its energy balance's residual (of the
 * input work); 0 on failure (named). */
static int reference_run(pd_test_ctx *ctx, const yrk_model *y, double t_end, double *peak,
                         double *up, double *exc, long *onsets, double *balance, const char *name)
{
    double W = 0.0, g0 = 0.0, e = 0.0;
    pd_model md = {.n = y->n,
                   .m = 0,
                   .M = pd_matrix_dense(y->n, y->n, (double *)y->M),
                   .C = pd_matrix_dense(y->n, y->n, (double *)y->C),
                   .K = pd_matrix_dense(y->n, y->n, (double *)y->K),
                   .W = pd_matrix_dense(y->n, 0, &W),
                   .g0 = &g0,
                   .e = &e,
                   .ns = y->ns,
                   .S = pd_matrix_dense(y->n, y->ns, (double *)y->S),
                   .ks = (double *)y->ks,
                   .uy = (double *)y->uy};
    pd_piecewise_force F = {.b = (double *)y->b, .pieces = y->pc, .npieces = y->npc};
    pd_edr_opts o = pd_edr_default_opts();
    int below[YRK_N]; /* storey i's drift x_i - x_(i-1), the first's x_0 */
    for (int i = 0; i < y->n; i++)
        below[i] = i - 1;
    o.below = below;
    o.energy = 1;
    pd_err err;
    pd_edr *r = pd_edr_alloc(&md, &F, &o, &err);
    int rc = r ? pd_edr_run(r, 0.0, NULL, NULL, t_end, NULL, NULL, &err) : err.status;
    if (!rc) {
        const pd_edr_result *res = pd_edr_result_of(r);
        /* the energy balance: input = kinetic + strain + damping + hysteretic (no impact) */
        *balance = (res->input_work + res->energy0 - res->kinetic - res->strain -
                    res->damping_work - res->hysteretic - res->impact_loss) /
                   res->input_work;
        for (int j = 0; j < y->ns; j++) { /* storey j's drift is measured on dof j (its
                                              * spring's drift a multiple S_jj of it) */
            peak[j] = res->drift[j] * fabs(y->S[j + j * y->n]);
            up[j] = res->up[j];
            exc[j] = res->plastic_excursion[j];
            onsets[j] = res->yield_onsets[j];
        }
    }
    pd_edr_free(r);
    return CHECK(ctx, rc == PD_OK, "%s: %s", name, rc ? err.msg : "");
}

/* One case: the reference against the integration at h and h / 2; the
 * worst distance (relative to the peak, or over uy) kept. */
static int one_case(pd_test_ctx *ctx, const yrk_model *y, double h, double t_end, double *worst,
                    long *onsets_total, const char *name)
{
    double peak[YRK_N], up[YRK_N], exc[YRK_N], balance = NAN;
    long on[YRK_N];
    if (!reference_run(ctx, y, t_end, peak, up, exc, on, &balance, name))
        return 0;
    yrk a, b;
    integrate(&a, y, h, t_end);
    integrate(&b, y, 0.5 * h, t_end);
    double d = 0.0, self = 0.0;
    int ok = 1;
    for (int j = 0; j < y->ns; j++) {
        double dj = fmax(fabs(peak[j] - b.peak[j]) / b.peak[j],
                         fmax(fabs(up[j] - b.up[j]), fabs(exc[j] - b.exc[j])) / y->uy[j]);
        self =
            fmax(self, fmax(fabs(a.peak[j] - b.peak[j]) / b.peak[j],
                            fmax(fabs(a.up[j] - b.up[j]), fabs(a.exc[j] - b.exc[j])) / y->uy[j]));
        d = fmax(d, dj);
        ok &= on[j] == b.onsets[j] && on[j] == a.onsets[j];
        *onsets_total += on[j];
    }
    *worst = fmax(*worst, d);
    long total = 0;
    for (int j = 0; j < y->ns; j++)
        total += on[j];
    printf("    %s: %ld onsets; the reference against the integration %.2g, the integration "
           "against itself %.2g; energy balance %.2g\n",
           name, total, d, self, balance);
    return CHECK(ctx, ok && d <= FIG_TOL && self <= FIG_TOL && fabs(balance) <= ENERGY_TOL,
                 "%s: distance %.3g (itself %.3g)%s, energy balance %.3g", name, d, self,
                 ok ? "" : ", onsets differ", balance);
}

/* Overdamped yielding oscillators (xi 1.5 and 3, alpha 0.1 and 0: a slide
 * whose mode has rate 0; the spring on x and on 2 x): no underdamped
 * flight, so modal ones. */
static void test_yield_edr_rk_overdamped(pd_test_ctx *ctx)
{
    pd_sine_piece pc[2] = {{.t_start = 0.0, .A = -1.0, .w = 1.0}, {.t_start = 2.0 * PD_PI}};
    double worst = 0.0;
    long onsets = 0;
    for (int k = 0; k < 6; k++) {
        /* the spring on x, and for the last two on the drift 2 x (ks / 4, 2 uy: the
         * same oscillator) */
        double xi = k % 2 ? 3.0 : 1.5, alpha = k / 2 == 1 ? 0.0 : 0.1, sig = k < 4 ? 1.0 : 2.0;
        yrk_model y = {.n = 1, .ns = 1, .pc = pc, .npc = 2};
        y.M[0] = y.b[0] = 1.0;
        y.S[0] = sig;
        y.K[0] = 1.0;
        y.C[0] = 2.0 * xi;
        y.ks[0] = (1.0 - alpha) / (sig * sig);
        y.uy[0] = 0.05 * sig;
        char name[96];
        snprintf(name, sizeof name, "overdamped xi %g alpha %g, the spring on %g x", xi, alpha,
                 sig);
        one_case(ctx, &y, 2.0 * PD_PI / STEPS_PER_PERIOD, 20.0, &worst, &onsets, name);
    }
    CHECK(ctx, onsets >= 6, "%ld onsets", onsets);
}

/* Shear buildings of 2 and 3 storeys (a soft first storey), every storey
 * yielding, alpha 0, 0.05, 0.2, under a sine and a cosine pulse and three
 * sine cycles, strong enough that storeys yield and unload several times. */
static void test_yield_edr_rk_buildings(pd_test_ctx *ctx)
{
    const double mass[3] = {3.0e5, 3.0e5, 2.5e5}, k[3] = {1.5e8, 4.0e8, 3.0e8},
                 uy[3] = {0.03, 0.02, 0.02};
    double worst = 0.0;
    long onsets = 0;
    int cases = 0;
    for (int n = 2; n <= 3; n++)
        for (int c = 0; c < 9; c++) {
            /* a sine cycle, a cosine cycle, three sine cycles of 0.5 s */
            double alpha = c % 3 == 0 ? 0.0 : c % 3 == 1 ? 0.05 : 0.2, Tp = c < 6 ? 0.8 : 0.5;
            pd_sine_piece pc[2] = {{.t_start = 0.0,
                                    .A = c < 6 ? -6.0 : -4.0,
                                    .w = PD_TWO_PI / Tp,
                                    .phi = c < 3 || c >= 6 ? 0.0 : 0.5 * PD_PI},
                                   {.t_start = c < 6 ? Tp : 3.0 * Tp}};
            yrk_model y;
            /* Rayleigh: 5 % at 2 pi / 0.6 and 2 pi / 0.2 rad/s */
            double w1 = PD_TWO_PI / 0.6, w2 = PD_TWO_PI / 0.2, xi = 0.05;
            building(&y, n, mass, k, 2.0 * xi * w1 * w2 / (w1 + w2), 2.0 * xi / (w1 + w2), uy,
                     alpha);
            y.pc = pc;
            y.npc = 2;
            char name[80];
            snprintf(name, sizeof name, "%d storeys, alpha %g, %s", n, alpha,
                     c < 3   ? "sine pulse"
                     : c < 6 ? "cosine pulse"
                             : "three sine cycles");
            one_case(ctx, &y, 0.1 / STEPS_PER_PERIOD, 4.0, &worst, &onsets, name);
            cases++;
        }
    printf("    %d buildings: the reference against the integration within %.2g, %ld onsets\n",
           cases, worst, onsets);
    CHECK(ctx, onsets >= 2 * cases, "%ld onsets over %d cases", onsets, cases);
}

/* A modal flight's derivatives against their differences (central, 1e-5):
 * each dof's jerk (edr_dof_jerk: the unloading scan's curvature) and each
 * spring's drift, its rate and acceleration (edr_spring_at), sampled
 * through a run, the free vibration after the pulse included. */
typedef struct modal_track {
    pd_edr *r;
    double worst, scale;
    long checked;
} modal_track;

static int modal_note(const pd_state *st, void *ctx)
{
    modal_track *m = ctx;
    pd_edr *r = m->r;
    int c = r->rs.blk_cl[r->tp.dof_blk[0]];
    if (r->rs.cl[c].kind != EDR_MODAL || st->t < 1e-3)
        return 0;
    double h = 1e-5, t = st->t;
    for (int i = 0; i < r->tp.n; i++) { /* the jerk against a's difference */
        double dx, v, ap, am;
        edr_dof_at(r, c, i, t + h, &dx, &v, &ap);
        edr_dof_at(r, c, i, t - h, &dx, &v, &am);
        double fd = (ap - am) / (2.0 * h);
        m->scale = fmax(m->scale, fabs(fd));
        m->worst = fmax(m->worst, fabs(edr_dof_jerk(r, c, i, t) - fd));
    }
    for (int j = 0; j < r->tp.ns; j++) { /* d' and d'' against d's and d''s differences */
        double dp, dm, vp, vm, ap, am, d, dd, ddd;
        edr_spring_at(r, c, j, t + h, &dp, &vp, &ap);
        edr_spring_at(r, c, j, t - h, &dm, &vm, &am);
        edr_spring_at(r, c, j, t, &d, &dd, &ddd);
        m->worst = fmax(m->worst, fmax(fabs(dd - (dp - dm) / (2.0 * h)) / fmax(fabs(dd), 1.0),
                                       fabs(ddd - (vp - vm) / (2.0 * h)) / fmax(fabs(ddd), 1.0)) *
                                      m->scale);
    }
    m->checked++;
    return 0;
}

static void test_yield_edr_rk_modal_derivatives(pd_test_ctx *ctx)
{
    const double mass[2] = {3.0e5, 2.5e5}, k[2] = {1.5e8, 3.0e8}, uy[2] = {0.03, 0.01};
    double w1 = PD_TWO_PI / 0.6, w2 = PD_TWO_PI / 0.2, xi = 0.05;
    pd_sine_piece pc[2] = {{.t_start = 0.0, .A = -6.0, .w = PD_TWO_PI / 0.8, .phi = 0.3},
                           {.t_start = 0.8}};
    yrk_model y;
    building(&y, 2, mass, k, 2.0 * xi * w1 * w2 / (w1 + w2), 2.0 * xi / (w1 + w2), uy, 0.05);
    double W = 0.0, g0 = 0.0, e = 0.0;
    pd_model md = {.n = 2,
                   .m = 0,
                   .M = pd_matrix_dense(2, 2, y.M),
                   .C = pd_matrix_dense(2, 2, y.C),
                   .K = pd_matrix_dense(2, 2, y.K),
                   .W = pd_matrix_dense(2, 0, &W),
                   .g0 = &g0,
                   .e = &e,
                   .ns = 2,
                   .S = pd_matrix_dense(2, 2, y.S),
                   .ks = y.ks,
                   .uy = y.uy};
    pd_piecewise_force F = {.b = y.b, .pieces = pc, .npieces = 2};
    pd_edr_opts o = pd_edr_default_opts();
    o.h_out = 0.005;
    pd_err err;
    modal_track m = {.r = pd_edr_alloc(&md, &F, &o, &err)};
    if (!CHECK(ctx, m.r != NULL, "%s", err.msg))
        return;
    int rc = pd_edr_run(m.r, 0.0, NULL, NULL, 3.0, modal_note, &m, &err);
    long onsets = 0;
    for (int j = 0; j < 2 && !rc; j++)
        onsets += pd_edr_result_of(m.r)->yield_onsets[j];
    printf("    modal flights: jerks and drifts' derivatives against their differences within "
           "%.2g of the jerks' scale over %ld samples (%ld onsets)\n",
           m.worst / m.scale, m.checked, onsets);
    CHECK(ctx, rc == PD_OK && m.checked > 500 && onsets >= 2 && m.worst <= 1e-6 * m.scale,
          "%s; off by %.3g of %.3g", rc ? err.msg : "ok", m.worst, m.scale);
    pd_edr_free(m.r);
}

void suite_yield_edr_rk(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_yield_edr_rk_overdamped);
    PD_RUN(ctx, test_yield_edr_rk_buildings);
    PD_RUN(ctx, test_yield_edr_rk_modal_derivatives);
}
