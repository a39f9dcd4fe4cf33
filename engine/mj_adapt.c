/* mj_adapt.c — Moreau–Jean to a tolerance: steps chosen from a dyadic ladder,
 * impacts approached or located by halving, an error estimate carried along.
 *
 *   ladder    h_k = h0 2^-k, k = 0..L; times on the grid t_origin + j h_L (integer
 *             ticks), a step never crossing t_end or a forcing piece's start; theta
 *             flights: a step of level k starts on a multiple of its own length
 *   flights   theta: the theta scheme (What(h_k) factored at level k's first use);
 *             exact: the linear structures' exact flow (mj_flight.c), impulses at
 *             mid-step, from any tick.  An exact flight with no contact pushing,
 *             closing or grazing is kept whole: it has no error to control; the rest
 *             of the way to t_end or a piece's start is one span of the ladder's
 *             digits; a flight that shuts a contact predicts the impact's instant
 *             from the gap's Taylor polynomial, flies near it and tries there
 *   a try     from S at t: S1 = one step h_k; Sa, S2 = two steps h_k+1 (kept when
 *             the try passes)
 *   flight    no event: e_i = (|q2 - q1|_i + |v2 - v1|_i / w_i) / (2^p - 1)  (p = 2 at
 *             theta 1/2) against the error per unit step kf rtol s_i h_k / T over the
 *             run's span T; s_i = max(atol_i, the amplitude sqrt(q_i^2 + (v_i/w_i)^2)
 *             seen so far), w_i^2 = K_ii / M_ii; the step doubles below 2^-p of that
 *             (exact flights: as many levels as r h^p allows, not above k_flight)
 *   events    on the dofs an event moves: an impact (a contact pushes while closing,
 *             (1 + e) |U-| above the flight's reach), a gap closed past zero or
 *             grazing inside a free step, a contact let go (its force's zero
 *             extrapolated): e_i = |q2 - q1|_i + |v2 - v1|_i / w_i (first order) + the
 *             events' bounds, against ke rtol s_i; no dof may take two significant
 *             impacts in one step (a cascade: one at a time, down to h |U| <= sim_gap).
 *             A try that fails is halved, keeping its first half when the event lies
 *             in the second
 *   estimate  E_i += e_i over the kept steps: the state's err
 *
 * No allocation once the levels in use are factored (theta flights); the
 * scalar kernel's levels and the exact flights' tables are formed with the
 * object. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mj.h"
#include "pd_alloc.h"
#include "pd_null.h"

#define ADAPT_KF 0.5          /* share of rtol for the flight's errors over the run */
#define ADAPT_KE 0.1          /* share of rtol for one event */
#define ADAPT_GROW 0.9        /* double the step below ADAPT_GROW 2^-p of the tolerance */
#define ADAPT_CLIMB 4         /* levels a kept try may climb at most (exact flights) */
#define ADAPT_START 3         /* the first try's level */
#define ADAPT_BREAK_TOL 1e-12 /* a time within this relative distance of a breakpoint is it */
#define ADAPT_CHATTER 4.0     /* rest speeds: this many steps' worth of the gap's force */
#define ADAPT_DEEP 6          /* the foot of the ladder: its last levels */
#define ADAPT_DEEP_MAX 4096   /* tries in a row there before one is kept as it is */

/* A state of the scheme with the forces at its instant. */
typedef struct snap {
    pd_state st;     /* q, v, P, g, active, t, step, ... */
    double *Fl, *Fr; /* n: F(t-) and F(t+) (theta flights) */
    double *af;      /* n: the free motion's accelerations (exact flights: when af_ok) */
    int af_ok;       /* af is the state's (exact flights; free_acc forms it once) */
    double *accr;    /* n: the accelerations' right limit where the forcing jumps */
    double zl[4];    /* the forcing's state before a piece's start took over */
    int switched;    /* the step to this state ended at a piece's start */
    double z[4];     /* the forcing's state (exact flights) */
    int piece;       /* its piece (exact flights) */
    uint64_t tick;   /* t = t_origin + tick h_L */
    double *mem;     /* the arrays' block */
} snap;

struct mj_adapt {
    int L;                       /* the finest level */
    double h0, htick;            /* h_0 and h_L */
    double t_origin;             /* the grid's origin (the last reset) */
    double span;                 /* T: the run's length (set by the first run after a reset) */
    mj_level *lev;               /* L + 1 levels (theta flights) */
    const pd_piecewise_force *F; /* exact flights' forcing (NULL: theta flights) */
    uint64_t *piece_tick;        /* npieces: each piece's start */
    snap sn[4];
    snap *cur, *one, *half, *two; /* now; one step; the first half; both halves */
    double *E;                    /* n: the flights' estimate kept so far (errors that add up) */
    double *S2;                   /* n: the events' estimates kept so far, squared and summed (the
                              instants of impulses inside their steps: errors of either
                              sign, independent) */
    double *Er;                   /* n: E plus the last step's interpolation bound (state err) */
    double *eps;                  /* n: the try's estimate */
    double *rate;                 /* n: the last smooth pair's error over h^(p+1) */
    double *amp;                  /* n: the amplitudes seen */
    double *w;                    /* n: each dof's frequency */
    double *atol;                 /* n */
    double *minv;                 /* n: 1 / M_ii */
    unsigned *mark;               /* n: the stamp of the last impact on each dof */
    unsigned stamp;
    unsigned *evmark; /* n: try_stamp when an event marked the dof in this try */
    unsigned *timed;  /* n: try_stamp when impulses at other instants moved the dof */
    unsigned try_stamp;
    double *bound;     /* n: the try's events' bound */
    double *hsum;      /* n: the forces P_b / h of the contacts held through a kept step
                          (rest_speeds) */
    long nmarked;      /* dofs marked for events so far */
    double *u_rest;    /* m: closing speeds without restitution (mj->u_rest) */
    double *u_tol, *G; /* m: the tolerance's rest speeds; |free gap acceleration| */
    double *Gs;        /* m: the free gap accelerations at the kept state, W^T a_free */
    double *D0;        /* m: sum_i W_ia^2 / M_ii, a unit impulse's change of gap rate */
    double *lam;       /* m: each held contact's force at the kept state (held_forces) */
    int *push;         /* m: the contacts pushing at the kept state, ad->cur once kept,
                          increasing (keep; none after a reset) */
    int npush;         /* their number */
    double *dmem;      /* the block of the n- and m-arrays of doubles above */
    unsigned *umem;    /* the block of mark, evmark and timed */
    int p;             /* order of the flight's global error */
    double div;        /* 2^p - 1 */
    int k_flight[2];   /* exact flights: the coarsest level whose steps the observers'
                              quintic interpolation keeps within the event tolerance,
                              (w h)^6 / 46080 <= ke rtol: w the highest
                              dof or forcing frequency [0], the highest dof frequency
                              for pieces without a sinusoid [1] */
    int k;             /* the level of the next try */
    int started;       /* the reset state was reported */
    int impact_made;   /* the step that made the state had an impact */
    long deep;         /* tries in a row at the ladder's foot */
    uint64_t target;   /* exact flights: the tick an impact's approach flies to (0: none) */
    pd_mj_stats stats;
};

static void rest_speeds(pd_mj *mj, const snap *w, snap *x);
static void rest_for_step(pd_mj *mj, const snap *x, double h);
static void report_err(pd_mj *mj, double h, double wf);

/* ---- the object ---------------------------------------------------------------- */

static void snap_free(snap *s)
{
    free(s->mem);
    free(s->st.active);
    memset(s, 0, sizeof *s);
}

/* q, v, Fl, Fr, acc, af, accr (n) and g, P (m) in one block; active (m). */
static int snap_alloc(snap *s, int n, int m)
{
    size_t mm = m > 0 ? (size_t)m : 1, nn = (size_t)n;
    /* q v Fl Fr (n each), g P (max(m, 1) each), acc af accr (n each): the offsets below keep mm */
    s->mem = calloc(7 * nn + 2 * mm, sizeof(double));
    s->st.active = pd_calloc(m, 1);
    if (!s->mem || !s->st.active)
        return PD_ENOMEM;
    s->st.q = s->mem;
    s->st.v = s->mem + nn;
    s->Fl = s->mem + 2 * nn;
    s->Fr = s->mem + 3 * nn;
    s->st.g = s->mem + 4 * nn;
    s->st.P = s->mem + 4 * nn + mm;
    s->st.acc = s->mem + 4 * nn + 2 * mm;
    s->af = s->mem + 5 * nn + 2 * mm;
    s->accr = s->mem + 6 * nn + 2 * mm;
    s->st.acc_right = s->st.acc; /* no jump: the right limit is the left */
    return PD_OK;
}

void mj_adapt_free(pd_mj *mj)
{
    mj_adapt *ad = mj ? mj->ad : NULL;
    if (!ad)
        return;
    mj_flight_free(mj);
    if (ad->lev)
        for (int k = 0; k <= ad->L; k++)
            pd_factor_free(ad->lev[k].factor);
    for (int s = 0; s < 4; s++)
        snap_free(&ad->sn[s]);
    free(ad->lev);
    free(ad->piece_tick);
    free(ad->dmem);
    free(ad->umem);
    free(ad->push);
    free(ad);
    mj->ad = NULL;
    mj->u_rest = NULL;   /* the fixed-step kernel: every restitution again */
    mj->st = mj->st_own; /* st pointed into a snapshot */
}

/* h0: opts.h lowered so that the forcing's jumps fall between steps: the
 * first model breakpoint after 0 a whole number of steps from t = 0
 * (theta flights); every piece's start a whole number of steps from the
 * first's when they are evenly spaced (a record's samples: h0 = their
 * spacing / 2^j), else the first start after it (a pulse's end). */
static double coarsest_step(const pd_model *md, const pd_piecewise_force *F, double h)
{
    double b = 0.0;
    if (F && F->npieces >= 2) {
        /* d: the first two starts' spacing; even when every
         * start is p d after the first (to 1e-9) */
        double d = F->pieces[1].t_start - F->pieces[0].t_start;
        int even = d > 0.0;
        for (int p = 2; p < F->npieces && even; p++)
            even = fabs(F->pieces[p].t_start - F->pieces[0].t_start - p * d) <= 1e-9 * p * d;
        /* a record: h0 = d 2^-j, the largest such step at most h */
        if (even && F->npieces >= 3)
            return h >= d ? d : ldexp(d, -(int)ceil(log2(d / h) - 1e-12));
        b = d; /* a pulse: its end on a step's end */
    }
    /* theta flights: the first breakpoint after 0 */
    for (int j = 0; !F && j < md->nbreaks && b == 0.0; j++)
        if (md->breaks[j] > 0.0)
            b = md->breaks[j];
    if (b > 0.0) {
        /* the fewest steps of at most h (to 1e-12) ending on b */
        double steps = ceil(b / h * (1.0 - 1e-12));
        return b / (steps > 1.0 ? steps : 1.0);
    }
    return h;
}

/* The largest w h of an exact flight that the observers' quintic
 * interpolation keeps within the event tolerance: (w h)^6 / 46080 <= ke
 * rtol (w the fastest frequency in the step). */
static double flight_room(double rtol)
{
    return pow(46080.0 * ADAPT_KE * rtol, 1.0 / 6.0);
}

/* Each dof's frequency w_i = sqrt(K_ii / M_ii) (floored at 1e-3 of the
 * largest, so that a free dof's velocity error still counts). */
static void dof_frequencies(const pd_model *md, double *w)
{
    double wmax = 0.0;
    for (int i = 0; i < md->n; i++) {
        double k = pd_matrix_get(&md->K, i, i), m = pd_matrix_get(&md->M, i, i);
        /* w_i^2 = K_ii / M_ii (0 without stiffness: floored below) */
        w[i] = k > 0.0 && m > 0.0 ? sqrt(k / m) : 0.0;
        wmax = fmax(wmax, w[i]);
    }
    /* 1 when no dof has a frequency: w_i divides v_i in every error */
    for (int i = 0; i < md->n; i++)
        w[i] = fmax(w[i], wmax > 0.0 ? 1e-3 * wmax : 1.0);
}

/* Each piece's start on the grid of the last reset. */
static void piece_ticks(mj_adapt *ad)
{
    for (int p = 0; ad->F && p < ad->F->npieces; p++) {
        double r = (ad->F->pieces[p].t_start - ad->t_origin) / ad->htick;
        /* a start before the origin at tick 0; beyond 2^63 ticks, never reached */
        ad->piece_tick[p] = r <= 0.0 ? 0 : r >= 0x1p63 ? UINT64_MAX : (uint64_t)llround(r);
    }
}

int mj_adapt_alloc(pd_mj *mj, pd_err *err)
{
    const pd_model *md = mj->model;
    const pd_mj_opts *o = &mj->opts;
    int n = md->n, L = o->max_level, rc;
    mj_adapt *ad = calloc(1, sizeof *ad);
    if (!(mj->ad = ad))
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for its levels");
    ad->F = o->pieces;
    ad->L = L;
    /* the flight's global order p: 2 at theta = 1/2 and for exact flights, else 1 */
    ad->p = o->theta == 0.5 || ad->F ? 2 : 1;
    ad->div = ad->p == 2 ? 3.0 : 1.0; /* 2^p - 1: Richardson's divisor */
    ad->lev = calloc((size_t)L + 1, sizeof *ad->lev);
    /* one element without pieces, so that NULL means out of memory */
    ad->piece_tick = calloc(ad->F ? (size_t)ad->F->npieces : 1, sizeof(uint64_t));
    /* the dofs' and contacts' arrays in two blocks: 11 n + 6 max(m, 1) doubles, 3 n stamps */
    double **nv[] = {&ad->E, &ad->S2,   &ad->Er,   &ad->eps,   &ad->rate, &ad->amp,
                     &ad->w, &ad->atol, &ad->minv, &ad->bound, &ad->hsum};
    double **mv[] = {&ad->u_rest, &ad->D0, &ad->u_tol, &ad->G, &ad->lam, &ad->Gs};
    unsigned **uv[] = {&ad->mark, &ad->evmark, &ad->timed};
    size_t nn = (size_t)n, mm = md->m > 0 ? (size_t)md->m : 1;
    ad->dmem = calloc(11 * nn + 6 * mm, sizeof(double));
    ad->umem = calloc(3 * nn, sizeof(unsigned));
    ad->push = pd_malloc(md->m, sizeof(int));
    int bad = !ad->lev || !ad->piece_tick || !ad->dmem || !ad->umem || !ad->push;
    for (size_t k = 0; !bad && k < 11; k++)
        *nv[k] = ad->dmem + k * nn;
    for (size_t k = 0; !bad && k < 6; k++)
        *mv[k] = ad->dmem + 11 * nn + k * mm;
    for (size_t k = 0; !bad && k < 3; k++)
        *uv[k] = ad->umem + k * nn;
    bad = bad || mj_incidence_build(mj);
    for (int s = 0; s < 4 && !bad; s++)
        bad = snap_alloc(&ad->sn[s], n, md->m) != PD_OK;
    if (bad)
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for its levels (n = %d)", n);
    dof_frequencies(md, ad->w);
    double wdof = 0.0, room = flight_room(o->rtol);
    for (int i = 0; i < n; i++)
        wdof = fmax(wdof, ad->w[i]);
    /* exact flights: h0 no coarser than the observers' interpolation allows
     * where the forcing has no sinusoid, room / w (w the highest dof frequency) */
    ad->h0 = coarsest_step(md, ad->F, ad->F ? fmin(o->h, room / wdof) : o->h);
    ad->htick = ldexp(ad->h0, -L); /* h_L: the tick */
    for (int k = 0; k <= L; k++) {
        /* h_k = h0 2^-k: the scalar kernel's constants now, the
         * general kernel's factors at their first use */
        ad->lev[k].h = ldexp(ad->h0, -k);
        if (mj->scalar && !ad->F) /* theta flights only */
            ad->lev[k].s1 = mj1_coef_make(
                pd_matrix_get(&md->M, 0, 0), pd_matrix_get(&md->C, 0, 0),
                pd_matrix_get(&md->K, 0, 0), md->m > 0, md->m ? pd_matrix_get(&md->W, 0, 0) : 0.0,
                md->m ? md->g0[0] : 0.0, md->m ? md->e[0] : 0.0, ad->lev[k].h, o->theta);
    }
    for (int i = 0; i < n; i++) {
        ad->minv[i] = 1.0 / pd_matrix_get(&md->M, i, i);
        ad->atol[i] = o->atol_dof ? o->atol_dof[i] : o->atol;
        if (!(ad->atol[i] > 0.0) || !isfinite(ad->atol[i]))
            return pd_err_set(err, PD_EINVAL,
                              "atol of dof %d must be a finite number > 0 "
                              "(got %g)",
                              i, ad->atol[i]);
    }
    /* D0_a = sum_i W_ia^2 / M_ii: the gap rate a unit
     * impulse makes (M^-1 by its diagonal) */
    for (int a = 0; a < md->m; a++)
        for (int j = mj->inc.ptr[a]; j < mj->inc.ptr[a + 1]; j++)
            ad->D0[a] += mj->inc.w[j] * mj->inc.w[j] * ad->minv[mj->inc.dof[j]];
    /* the kernels read the driver's rest speeds and M^-1 through mj */
    mj->u_rest = ad->u_rest;
    mj->minv = ad->minv;
    mj->D0 = ad->D0;
    if (ad->F && (rc = mj_flight_alloc(mj, ad->F, ad->h0, L, err)))
        return rc;
    if (ad->F) {
        /* k_flight: the coarsest level with w h <= room, w the highest dof
         * or (pieces with a sinusoid) forcing frequency */
        for (int j = 0; j < 2; j++) {
            double wj = j == 0 ? fmax(wdof, mj_flight_forcing_w(mj)) : wdof;
            while (ad->k_flight[j] < L - 1 && wj * ad->lev[ad->k_flight[j]].h > room)
                ad->k_flight[j]++;
        }
    }
    return PD_OK;
}

/* ---- time and forces ------------------------------------------------------------ */

static double tick_time(const mj_adapt *ad, uint64_t tick)
{
    return ad->t_origin + (double)tick * ad->htick;
}

/* The trailing zero bits of d > 0. */
static int trailing_zeros(uint64_t d)
{
#if defined(__GNUC__) || defined(__clang__)
    return __builtin_ctzll(d);
#else
    int z = 0;
    for (; !(d & 1); d >>= 1)
        z++;
    return z;
#endif
}

static uint64_t level_ticks(const mj_adapt *ad, int k)
{
    return (uint64_t)1 << (ad->L - k); /* 2^(L - k) ticks */
}

/* The forcing's frequency in piece p (exact flights; 0 without a sinusoid). */
static double piece_w(const pd_mj *mj, int p)
{
    return mj->ad->F->pieces[p].A != 0.0 ? mj_flight_forcing_w(mj) : 0.0;
}

/* The coarsest level of an exact flight from x (k_flight of x's piece). */
static int flight_level(const mj_adapt *ad, const snap *x)
{
    return ad->k_flight[ad->F->pieces[x->piece].A != 0.0 ? 0 : 1];
}

/* 1 when t is one of the model's breakpoints (to a relative ADAPT_BREAK_TOL). */
static int at_break(const pd_model *md, double t)
{
    for (int j = 0; j < md->nbreaks; j++)
        if (fabs(md->breaks[j] - t) <= ADAPT_BREAK_TOL * fmax(fabs(t), 1.0))
            return 1;
    return 0;
}

/* F(t-) and F(t+) into s (equal away from breakpoints; theta flights). */
static void forces_at(const pd_mj *mj, double t, snap *s)
{
    const pd_model *md = mj->model;
    size_t bytes = (size_t)md->n * sizeof(double);
    if (mj->fl)
        return;
    if (!md->force) {
        memset(s->Fl, 0, bytes);
        memset(s->Fr, 0, bytes);
        return;
    }
    /* F(t-); F(t+) differs only at a breakpoint (exact flights carry the forcing in z) */
    md->force(t, -1, s->Fl, md->force_ctx);
    if (at_break(md, t))
        md->force(t, +1, s->Fr, md->force_ctx);
    else
        memcpy(s->Fr, s->Fl, bytes);
}

int mj_adapt_reset(pd_mj *mj, double t0, const double *q0, const double *v0, pd_err *err)
{
    const pd_model *md = mj->model;
    mj_adapt *ad = mj->ad;
    snap *s = &ad->sn[0];
    for (int i = 0; i < md->n; i++) {
        s->st.q[i] = q0 ? q0[i] : 0.0;
        s->st.v[i] = v0 ? v0[i] : 0.0;
        if (!isfinite(s->st.q[i]) || !isfinite(s->st.v[i]))
            return pd_err_set(err, PD_EINVAL, "initial state: dof %d is not finite", i);
        ad->E[i] = ad->S2[i] = ad->rate[i] = 0.0;
        ad->amp[i] = hypot(s->st.q[i], s->st.v[i] / ad->w[i]); /* sqrt(q^2 + (v / w)^2) */
    }
    for (int a = 0; a < md->m; a++) {
        s->st.P[a] = 0.0;
        s->st.active[a] = 0;
        s->st.g[a] = md->g0[a] + mj_inc_dot(&mj->inc, a, s->st.q); /* g0 + W^T q */
        ad->lam[a] = 0.0;
    }
    /* the four snapshots: now, one whole step, the first half, both halves */
    ad->cur = &ad->sn[0];
    ad->one = &ad->sn[1];
    ad->half = &ad->sn[2];
    ad->two = &ad->sn[3];
    ad->t_origin = t0;
    ad->span = 0.0; /* T: set by the first run */
    /* the first try at level ADAPT_START (above the foot); exact flights: the
     * coarsest the observers allow (no error to size) */
    ad->k = ADAPT_START < ad->L ? ADAPT_START : ad->L - 1;
    if (ad->F)
        ad->k = ad->k_flight[0];
    ad->started = 0;
    ad->impact_made = 0;
    ad->deep = 0;
    ad->target = 0;
    ad->stats = (pd_mj_stats){.h_min = HUGE_VAL, .h_max = 0.0, .h0 = ad->h0};
    s->tick = 0;
    s->st.t = t0;
    s->st.step = 0;
    s->st.nactive = 0;
    s->st.lcp_pivots = 0;
    s->st.lcp_solver = NULL;
    s->st.h = 0.0;
    s->st.impact = 0;
    forces_at(mj, t0, s);
    s->st.has_acc = 0;
    if (ad->F) { /* the piece in force at t0 */
        piece_ticks(ad);
        s->piece = 0;
        while (s->piece + 1 < ad->F->npieces && ad->F->pieces[s->piece + 1].t_start <= t0)
            s->piece++;
        mj_flight_z(mj, s->piece, t0, s->z);
    }
    if (ad->F) {
        /* the free motion's accelerations, for the observers' interpolation */
        mj_flight_acc(mj, &s->st, s->z, s->af);
        s->af_ok = 1;
        memcpy(s->st.acc, s->af, (size_t)mj->model->n * sizeof(double));
        s->st.has_acc = 1;
        s->st.acc_right = s->st.acc;
        s->switched = 0;
    }
    /* no step made this state (h = 0): no contact pushing, no held force in
     * its rest speeds */
    ad->npush = 0;
    rest_speeds(mj, s, s);
    mj->t0 = t0;
    report_err(mj, 0.0, 0.0);
    mj->st = s->st;
    mj->st.err = ad->Er; /* the estimate: 0 here */
    return PD_OK;
}

/* ---- one step ------------------------------------------------------------------- */

/* Level k's factor of What(h_k), formed at its first use. */
static int level_factor(pd_mj *mj, int k, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    mj_level *lv = &mj->ad->lev[k];
    if (lv->factor)
        return PD_OK;
    lv->factor = pd_factor_alloc(mj->model, lv->h, mj->opts.theta, mj->factor->type->kind, err);
    return lv->factor ? PD_OK : err->status;
}

/* The scalar kernel's step from x to y with level k's constants. */
static int scalar_step(pd_mj *mj, int k, double t1, const snap *x, snap *y, pd_err *err)
{
    const pd_model *md = mj->model;
    const mj_level *lv = &mj->ad->lev[k];
    double q = x->st.q[0], v = x->st.v[0], g = md->m ? x->st.g[0] : 0.0, P;
    mj1_coef s1 = lv->s1;
    if (md->m && -(s1.w * v) <= mj->ad->u_rest[0])
        s1.e = 0.0; /* opening, or closing too slowly for a rebound: the contact holds */
    /* F(t+) at the start, F(t1-) at the end: the fixed-step kernel's arithmetic */
    int active = mj1_step(lv->h, mj->opts.theta, lv->h * mj->opts.gamma, &s1, x->Fr[0], y->Fl[0],
                          &q, &v, &g, &P);
    y->st.q[0] = q;
    y->st.v[0] = v;
    if (md->m) {
        y->st.g[0] = g;
        y->st.P[0] = P;
        y->st.active[0] = (unsigned char)active;
    }
    y->st.nactive = active;
    y->st.lcp_pivots = 0;
    y->st.lcp_solver = active ? "closed-form" : NULL;
    y->st.t = t1;
    y->st.step = x->st.step + 1;
    if (!isfinite(q) || !isfinite(v))
        return pd_err_set(err, PD_ENONFINITE,
                          "Moreau-Jean: non-finite state at t = %.9g (step of %.3g)", t1, lv->h);
    return PD_OK;
}

/* y reached by an exact flight from x: at a piece's start its forcing takes over. */
static void flight_end(const pd_mj *mj, const snap *x, snap *y)
{
    const mj_adapt *ad = mj->ad;
    y->piece = x->piece;
    /* steps never cross a piece's start: one may end on it */
    y->switched = y->piece + 1 < ad->F->npieces && y->tick >= ad->piece_tick[y->piece + 1];
    if (y->switched) {
        memcpy(y->zl, y->z, sizeof y->zl);
        y->piece++;
        mj_flight_z(mj, y->piece, ad->F->pieces[y->piece].t_start, y->z);
    }
}

/* One step of level k from x into y (its forces at the end included). */
static int take_step(pd_mj *mj, int k, const snap *x, snap *y, pd_err *err)
{
    mj_adapt *ad = mj->ad;
    int rc;
    y->tick = x->tick + level_ticks(ad, k); /* t1 = t + h_k on the grid */
    double t1 = tick_time(ad, y->tick);
    ad->stats.evals++;
    rest_for_step(mj, x, ad->lev[k].h); /* mj->u_rest for this step size */
    y->st.h = ad->lev[k].h;
    if (ad->F) { /* exact flight */
        if ((rc = mj_flight_step(mj, k, t1, &x->st, x->z, &y->st, y->z, err)))
            return rc;
        y->af_ok = 0;
        flight_end(mj, x, y);
        return PD_OK;
    }
    /* theta flights: F(t1-) and F(t1+), then the scheme on What(h_k) */
    forces_at(mj, t1, y);
    if (mj->scalar)
        return scalar_step(mj, k, t1, x, y, err);
    if ((rc = level_factor(mj, k, err)))
        return rc;
    return mj_general_step(mj, ad->lev[k].factor, ad->lev[k].h, t1, x->Fr, y->Fl, &x->st, &y->st,
                           err);
}

/* An exact flight of D ticks from x into y (D below h_0's, not a power of
 * two): the free flights of the levels of D's binary digits, the coarsest
 * first, as one step (exp(A~ D h_L) is their product); a contact shut at
 * its end or at x fails it (a contact shut inside and open again at the
 * end is the grazing test's, scan_dips over the whole span).  Returns 1
 * when no contact shut, 0 when one did (y is no step then), < 0 on
 * failure. */
static int span_step(pd_mj *mj, uint64_t D, const snap *x, snap *y, pd_err *err)
{
    mj_adapt *ad = mj->ad;
    int lev[64], nlev = 0, rc;
    for (int k = 0; k <= ad->L; k++)
        if (D & level_ticks(ad, k))
            lev[nlev++] = k;
    y->tick = x->tick + D;
    y->af_ok = 0;
    ad->stats.evals += nlev;
    rest_for_step(mj, x, (double)D * ad->htick);
    rc = mj_flight_span(mj, lev, nlev, tick_time(ad, y->tick), &x->st, x->z, &y->st, y->z, err);
    if (rc <= 0)
        return rc;
    y->st.h = (double)D * ad->htick;
    flight_end(mj, x, y);
    return 1;
}

/* ---- the tests of a try ------------------------------------------------------------ */

/* s_i: the size a dof's error is measured against. */
static double dof_scale(const mj_adapt *ad, int i)
{
    return ad->amp[i] > ad->atol[i] ? ad->amp[i] : ad->atol[i]; /* max(amplitude, atol_i) */
}

/* An impact in the step x -> y: contact a pushes (P > 0) while it was
 * closing (U- = W_a^T v < 0), or starts pushing (its impulse a next stage
 * of an impact nearby): the change of gap rate it makes, the larger of
 * (1 + e) |U-| and its impulse's own P D0_a (D0_a = sum_i W_ia^2 / M_ii);
 * else 0. */
static double impact_jump(const pd_mj *mj, int a, const snap *x, const snap *y)
{
    if (!(y->st.P[a] > 0.0))
        return 0.0;
    const pd_model *md = mj->model;
    double U = mj_inc_dot(&mj->inc, a, x->st.v);
    double jump = U < 0.0 ? (1.0 + md->e[a]) * -U : 0.0; /* (1 + e) |U-| while closing */
    /* starting to push: at least its own impulse's change of gap rate, P D0_a */
    if (!(x->st.P[a] > 0.0))
        jump = pd_max(jump, y->st.P[a] * mj->ad->D0[a]);
    return jump;
}

/* 1 when contact a's impact jump could fail the flight's test at some step
 * on one of its dofs: the first-order error jump h / 2 of a step h against
 * the error per unit step, with room 4 ((2^p - 1) kf rtol s_i / T). */
static int flight_event(const pd_mj *mj, int a, double jump)
{
    const mj_incidence *in = &mj->inc;
    const mj_adapt *ad = mj->ad;
    /* h cancels: the error jump h / 2 and the allowance kf rtol
     * s_i h / T both scale with the step */
    double flight = ad->div * ADAPT_KF * mj->opts.rtol / ad->span;
    for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++)
        if (jump > flight * dof_scale(ad, in->dof[j]))
            return 1;
    return 0;
}

/* Dof i takes part in the try's event with the bound b (units of q). */
static void mark_event(mj_adapt *ad, int i, double b)
{
    ad->evmark[i] = ad->try_stamp;
    ad->bound[i] += b;
    ad->nmarked++;
}

/* The impacts of the step x -> y (of size h; weight 0: detection only).
 * An impact is an event on the dofs it moves when its jump could fail the
 * flight's test at some step (flight_event): the instant of its impulse
 * inside the step is unknown, so they are marked for the event's test with
 * the bound jump h (exact flights: jump h / 2, the impulse at mid-step).  So is a gap closed past zero inside a step where
 * no contact was predicted (theta flights: the impact comes a step late,
 * the penetration is the error).  Returns 1 for a cascade: a dof taking
 * two impacts whose jumps move it by more than the event tolerance,
 * closing more than sim_gap over the step (to be taken one at a time). */
static int scan_impacts(pd_mj *mj, const snap *x, const snap *y, double h, double weight)
{
    const pd_model *md = mj->model;
    const mj_incidence *in = &mj->inc;
    mj_adapt *ad = mj->ad;
    /* reach: how far the impulse's instant may be off, h (theta) or h / 2 (exact: at mid-step) */
    double rtol = mj->opts.rtol, reach = ad->F ? 0.5 * h : h;
    int cascade = 0;
    unsigned stamp = ++ad->stamp; /* this scan's significant impacts, per dof */
    for (int a = 0; a < md->m; a++) {
        /* neither an impulse nor a gap closed past zero: nothing */
        if (!(y->st.P[a] > 0.0) && !(x->st.g[a] > 0.0 && y->st.g[a] < 0.0))
            continue;
        double jump = impact_jump(mj, a, x, y);
        /* open to past zero without an impulse: the penetration is the error */
        double missed =
            x->st.g[a] > 0.0 && y->st.g[a] < 0.0 && !(y->st.P[a] > 0.0) ? -y->st.g[a] : 0.0;
        if (!(jump > 0.0) && !(missed > 0.0))
            continue;
        /* significant: h jump beyond (1 + e) sim_gap and, on every dof it moves, a velocity
         * change beyond ke rtol s_i w_i */
        int big = jump * h > (1.0 + md->e[a]) * mj->opts.sim_gap;
        int marks = missed > 0.0 || flight_event(mj, a, jump);
        for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++) {
            int i = in->dof[j];
            if (marks)
                mark_event(ad, i, weight * pd_max(jump * reach, missed));
            big &= jump > ADAPT_KE * rtol * dof_scale(ad, i) * ad->w[i];
        }
        if (!big)
            continue;
        for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++) {
            int i = in->dof[j];
            cascade |= ad->mark[i] == stamp; /* a second significant impact on dof i */
            ad->mark[i] = stamp;
        }
    }
    return cascade;
}

/* The smallest value of the cubic Hermite through (g0, U0) and (g1, U1)
 * over a step h (its ends excluded: +inf when it turns nowhere inside). */
static double hermite_min(double g0, double U0, double g1, double U1, double h)
{
    /* g(s) = g0 + U0 s + c2 s^2 + c3 s^3 through (g0, U0) at 0 and (g1, U1) at h */
    double c2 = (3.0 * (g1 - g0) / h - 2.0 * U0 - U1) / h;
    double c3 = (2.0 * (g0 - g1) / h + U0 + U1) / (h * h);
    /* its turns: g'(s) = A s^2 + B s + C = 0 */
    double A = 3.0 * c3, B = 2.0 * c2, C = U0, best = HUGE_VAL, s[2];
    int ns = 0;
    if (A == 0.0) {
        if (B != 0.0)
            s[ns++] = -C / B;
    } else {
        double d = B * B - 4.0 * A * C;
        if (d >= 0.0) {
            /* roots q / A and C / q: no cancellation between B and sqrt(d) */
            double q = -0.5 * (B + copysign(sqrt(d), B));
            s[ns++] = q / A;
            if (q != 0.0)
                s[ns++] = C / q;
        }
    }
    /* turns strictly inside the step only */
    for (int j = 0; j < ns; j++)
        if (s[j] > 0.0 && s[j] < h)
            best = fmin(best, g0 + s[j] * (U0 + s[j] * (c2 + s[j] * c3)));
    return best;
}

static inline double gap_acc(const pd_mj *mj, snap *x, int a);
static double first_root(double g, double U, double G);

/* Exact flights: a contact opening at x (U0 >= 0, a rebound) that the free
 * motion presses back (its gap acceleration G < 0) closes again at the
 * first root s of g + U0 s + G s^2 / 2; inside the step h the flight
 * may have passed through the wall and out again (two turns of the gap,
 * which neither its ends nor their cubic show).  Its dofs are marked with
 * the bound of an impact there, (1 + e) |U0 + G s| h on the gap rate.
 * Returns 1 when marked. */
static int scan_return(pd_mj *mj, snap *x, int a, double U0, double h)
{
    const mj_incidence *in = &mj->inc;
    mj_adapt *ad = mj->ad;
    /* a root after an opening start needs G < 0 (g > 0, U0 >= 0), and one
     * before h needs g + G h^2 / 2 < 0 (U0 s >= 0) */
    /* G: at the kept state rest_speeds formed it */
    double G = x == ad->cur ? ad->Gs[a] : gap_acc(mj, x, a), g = x->st.g[a];
    if (!(G < 0.0 && g + 0.5 * G * h * h < 0.0))
        return 0;
    double s = first_root(g, U0, G);
    if (!(s < h) || !(ad->D0[a] > 0.0))
        return 0;
    double jump = (1.0 + mj->model->e[a]) * fabs(U0 + G * s);
    for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++) {
        int i = in->dof[j];
        mark_event(ad, i, jump * h * fabs(in->w[j]) * ad->minv[i] / ad->D0[a]);
    }
    return 1;
}

/* A contact open at both ends of a free step x -> y whose gap may have
 * dipped to zero inside it (a grazing impact the step would miss): the
 * cubic Hermite of the gap, within its error (w h)^4 / 384 of the gap's
 * scale (w: the highest frequency of the blocks it joins, exact flights;
 * of its dofs, theta flights), comes below that margin.  Its dofs are
 * marked with the margin as bound, or, when the cubic goes below zero by
 * more, with a missed impact's (1 + e) |U0| h.  Exact flights: a rebound
 * pressed back inside the step (scan_return). */
static void scan_dips(pd_mj *mj, snap *x, const snap *y, double h)
{
    const pd_model *md = mj->model;
    const mj_incidence *in = &mj->inc;
    mj_adapt *ad = mj->ad;
    for (int a = 0; a < md->m; a++) {
        /* open at both ends, no impulse */
        if (!(x->st.g[a] > 0.0 && y->st.g[a] > 0.0) || y->st.P[a] > 0.0)
            continue;
        double U0 = mj_inc_dot(in, a, x->st.v), U1 = mj_inc_dot(in, a, y->st.v);
        if (mj->fl && U0 >= 0.0 && scan_return(mj, x, a, U0, h))
            continue;
        /* closing at the start and opening at the end: it turned inside */
        if (!(U0 < 0.0 && U1 > 0.0))
            continue;
        /* w: the fastest frequency the gap sees; scale = sum |W_ia| s_i, the gap's */
        double w = 0.0, scale = 0.0;
        for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++) {
            int i = in->dof[j];
            w = fmax(w, mj->fl ? mj_flight_wmax(mj, i) : ad->w[i]);
            scale += fabs(in->w[j]) * dof_scale(ad, i);
        }
        double wh = w * h, margin = wh * wh * wh * wh / 384.0 * scale;
        double gmin = hermite_min(x->st.g[a], U0, y->st.g[a], U1, h);
        if (!(gmin < margin))
            continue;
        /* below zero by more than the cubic's error: the flight went through the
         * wall, an impact missed, whose bound is (1 + e) |U0| h on the gap rate */
        double jump = gmin < -margin && ad->D0[a] > 0.0 ? (1.0 + md->e[a]) * -U0 : 0.0;
        for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++) {
            int i = in->dof[j];
            mark_event(ad, i, fmax(margin, jump * h * fabs(in->w[j]) * ad->minv[i] / ad->D0[a]));
        }
    }
}

/* Contact a's impulse error dP moves dof i by about |W_ia| dP / (M_ii w_i). */
static void mark_impulse(pd_mj *mj, int a, double dP)
{
    mj_adapt *ad = mj->ad;
    const mj_incidence *in = &mj->inc;
    for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++) {
        int i = in->dof[j];
        mark_event(ad, i, fabs(in->w[j]) * ad->minv[i] * dP / ad->w[i]);
    }
}

/* Exact flights: the free motion's accelerations at x, the state's own
 * (formed at their first use); theta flights: NULL. */
static const double *free_accs(const pd_mj *mj, snap *x)
{
    if (!mj->fl)
        return NULL;
    if (!x->af_ok) {
        mj_flight_acc(mj, &x->st, x->z, x->af);
        x->af_ok = 1;
    }
    return x->af;
}

/* The free motion's acceleration of dof i at x: exact flights, free_accs',
 * else M_ii^-1 (F - C v - K q)_i (C, K symmetric: rows are columns). */
static double free_acc(const pd_mj *mj, snap *x, int i)
{
    const pd_model *md = mj->model;
    if (mj->fl)
        return free_accs(mj, x)[i];
    return mj->ad->minv[i] * (x->Fr[i] - pd_matrix_col_dot(&md->C, i, x->st.v) -
                              pd_matrix_col_dot(&md->K, i, x->st.q));
}

/* The free gap acceleration of contact a at x, W_a^T a_free. */
static inline double gap_acc(const pd_mj *mj, snap *x, int a)
{
    const mj_incidence *in = &mj->inc;
    const double *af = free_accs(mj, x);
    double G = 0.0;
    for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++)
        G += in->w[j] * (af ? af[in->dof[j]] : free_acc(mj, x, in->dof[j]));
    return G;
}

/* A contact that pushed in the step that made y and not in the next, of
 * size h: let go at y.  Right when it was not resting on its contact (|U|
 * above the rest speed: an impact's rebound) or when the free motion opens
 * it (its gap's acceleration G >= 0); else the contact would have held,
 * and the step lost up to |G| h of gap rate: its dofs get the bound
 * |G| h / w_i.  Returns 1 when marked. */
static int released(pd_mj *mj, int a, snap *y, double h)
{
    const mj_incidence *in = &mj->inc;
    mj_adapt *ad = mj->ad;
    if (fabs(mj_inc_dot(in, a, y->st.v)) > ad->u_rest[a]) /* moving: an impact's rebound */
        return 0;
    double G = gap_acc(mj, y, a); /* the gap's free acceleration */
    if (!(G < 0.0))               /* the free motion opens it */
        return 0;
    /* it would have held: |G| h of gap rate lost, |G| h / w_i on each dof */
    for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++)
        mark_event(ad, in->dof[j], -G * h / ad->w[in->dof[j]]);
    return 1;
}

/* The overrun of a held contact whose force falls: lambda0 at time t0 and
 * lambda1 at t1 > t0 (the means P / h of two held steps at their
 * middles), their line's zero z; when z falls before the end `until` of
 * the later held step, the force was applied d = until - z too long, an
 * impulse error |lambda'| d^2 / 2 on the contact's dofs.  Returns the zero
 * (+inf when the force does not fall or its zero is later). */
static double overrun(pd_mj *mj, int a, double lambda0, double t0, double lambda1, double t1,
                      double until)
{
    double rate = (lambda1 - lambda0) / (t1 - t0); /* lambda' */
    if (!(rate < 0.0))
        return HUGE_VAL;
    double zero = t1 + lambda1 / -rate; /* lambda1 + rate (z - t1) = 0 */
    if (!(zero < until))
        return HUGE_VAL;
    /* the force held d = until - z too long: |lambda'| d^2 / 2 of impulse */
    mark_impulse(mj, a, -rate * (until - zero) * (until - zero) / 2.0);
    return zero;
}

/* Contact a held through a step x -> y of size h (exact flights): its
 * force at an instant is about -G / D0_a (G the free gap acceleration),
 * pressing (G < 0) at x and, when G > 0 at y (the free motion there opens
 * it), negative at y: the force crossed zero at z (G's line) and was held
 * d = h - z too long, an impulse error |lambda'| d^2 / 2 on the contact's
 * dofs.  The means' line of overrun() is a curved force's secant, which
 * puts the zero too late.  Returns 1 when marked. */
static int force_zero(pd_mj *mj, int a, snap *x, snap *y, double h)
{
    mj_adapt *ad = mj->ad;
    double G0 = gap_acc(mj, x, a), G1 = gap_acc(mj, y, a);
    if (!(G0 < 0.0 && G1 > 0.0) || !(ad->D0[a] > 0.0))
        return 0;
    double d = h * G1 / (G1 - G0);           /* h - z, z = h (-G0) / (G1 - G0) */
    double rate = (G1 - G0) / h / ad->D0[a]; /* |lambda'| */
    mark_impulse(mj, a, rate * d * d / 2.0);
    return 1;
}

/* Contacts that stop pushing in the try (its halves of size h, times from
 * its start): the scheme lets go at the end of the step where the contact
 * force's mean turns negative, so a held step may overrun the force's
 * zero.  Held in the step before (size hc; no impact in it) and in the
 * first half: the line through their forces (released() when the first
 * half let go);
 * held in both halves (no impact in the first): the line through theirs
 * (released() when the second let go).  Returns 1 when an event may lie
 * in the first half. */
static int scan_releases(pd_mj *mj, double h)
{
    const pd_model *md = mj->model;
    const mj_adapt *ad = mj->ad;
    double hc = ad->cur->st.h; /* the step before the try (0 after a reset) */
    int first = 0;
    for (int a = 0; a < md->m; a++) {
        double P0 = ad->cur->st.P[a], Pa = ad->half->st.P[a], P2 = ad->two->st.P[a];
        /* pushed before the try, not in its first half: let go at the try's start */
        if (P0 > 0.0 && !(Pa > 0.0))
            first |= released(mj, a, ad->cur, h);
        if (!(Pa > 0.0))
            continue;
        /* exact flights: the force's zero in the first half from its instants' */
        if (ad->F && !flight_event(mj, a, impact_jump(mj, a, ad->cur, ad->half)))
            first |= force_zero(mj, a, ad->cur, ad->half, h);
        /* held before and in the first half: their means' line, times from the try's start */
        if (P0 > 0.0 && hc > 0.0 && !ad->impact_made &&
            overrun(mj, a, P0 / hc, -0.5 * hc, Pa / h, 0.5 * h, h) < h)
            first = 1;
        /* let go at the half */
        if (!(P2 > 0.0)) {
            released(mj, a, ad->half, h);
            continue;
        }
        /* an impact in the first half: its impulse is no held force */
        if (flight_event(mj, a, impact_jump(mj, a, ad->cur, ad->half)))
            continue;
        /* held in both halves: a zero before h lies in the first */
        first |= overrun(mj, a, Pa / h, 0.5 * h, P2 / h, 1.5 * h, 2.0 * h) < h;
        /* exact flights: the force's zero in the second half from its instants' */
        if (ad->F)
            force_zero(mj, a, ad->half, ad->two, h);
    }
    return first;
}

/* Contacts that push in any of the try's three steps: an impulse taken at
 * another instant of the whole step than of the halves (a next stage of an
 * impact, a held force that turns) leaves their velocities apart at any
 * step size, which moves the dofs by the difference over the step, not
 * over 1 / w: their dofs are timed (try_error; a held contact's smooth
 * velocity errors are measured a little more loosely so, by w H).  When
 * such a contact pushes in some steps and not in others with an impulse
 * that changes a velocity by more than the event tolerance's (ke rtol s_i
 * w_i; its jump P D0), its dofs take the event's test with the bound
 * jump h. */
static void scan_patterns(pd_mj *mj, double h)
{
    const pd_model *md = mj->model;
    const mj_incidence *in = &mj->inc;
    mj_adapt *ad = mj->ad;
    double tol = ADAPT_KE * mj->opts.rtol;
    for (int a = 0; a < md->m; a++) {
        double P1 = ad->one->st.P[a], Pa = ad->half->st.P[a], P2 = ad->two->st.P[a];
        int p1 = P1 > 0.0, pa = Pa > 0.0, p2 = P2 > 0.0;
        if (!p1 && !pa && !p2)
            continue;
        int mixed = !(p1 == pa && pa == p2);                  /* pushes in some steps only */
        double jump = pd_max(P1, pd_max(Pa, P2)) * ad->D0[a]; /* the largest change of gap rate */
        for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++) {
            int i = in->dof[j];
            ad->timed[i] = ad->try_stamp; /* its velocity errors move it by dv H */
            if (mixed && jump > tol * dof_scale(ad, i) * ad->w[i])
                mark_event(ad, i, jump * h);
        }
    }
}

/* The try's events: impacts and dips of each half (with their bounds), of
 * the whole step (detection), contacts let go, contacts whose pushing
 * differs among the steps; *first: one lies in the first half, *event: one
 * lies in the try.  Returns 1 for a cascade. */
static int scan_try(pd_mj *mj, double h, int *first, int *event)
{
    mj_adapt *ad = mj->ad;
    long before = ad->nmarked;
    int cascade = scan_impacts(mj, ad->cur, ad->half, h, 1.0);
    scan_dips(mj, ad->cur, ad->half, h);
    /* marks so far are the first half's: an event there */
    *first = ad->nmarked > before || scan_releases(mj, h);
    cascade |= scan_impacts(mj, ad->half, ad->two, h, 1.0);
    scan_dips(mj, ad->half, ad->two, h);
    /* the whole step: detection only, weight 0 adds no bound */
    scan_impacts(mj, ad->cur, ad->one, 2.0 * h, 0.0);
    scan_patterns(mj, h);
    *event = ad->nmarked > before;
    return cascade;
}

/* The try's error against its tolerance (> 1: fails), its estimate into
 * eps: on the dofs an event marked, the first-order difference |q2 - q1| +
 * |v2 - v1| H plus the events' bounds against ke rtol s_i; on the others the
 * doubling estimate (|q2 - q1| + |v2 - v1| / w) / (2^p - 1) against the
 * error per unit step kf rtol s_i H / T.
 * Differences within rounding of the state (64 ulps) count as none. */
static double try_error(pd_mj *mj, double H)
{
    const mj_adapt *ad = mj->ad;
    const snap *s1 = ad->one, *s2 = ad->two;
    double rtol = mj->opts.rtol, div = ad->div, r = 0.0;
    double tol_event = ADAPT_KE * rtol, tol_flight = ADAPT_KF * rtol * H / ad->span;
    for (int i = 0; i < mj->model->n; i++) {
        double dq = fabs(s2->st.q[i] - s1->st.q[i]), dv = fabs(s2->st.v[i] - s1->st.v[i]);
        /* differences within 64 ulps of the state are rounding, not error */
        double noise = 64.0 * 2.2e-16 * (fabs(s2->st.q[i]) + fabs(s2->st.v[i]) / ad->w[i]);
        int event = ad->evmark[i] == ad->try_stamp;
        /* an event's velocities, or a timed dof's, differ by impulses taken at
         * other instants of the step (a next stage of an impact in the halves,
         * the whole step's in its next step): that moves the dof by dv over
         * the step, not dv / w */
        int timed = event || ad->timed[i] == ad->try_stamp;
        double d = pd_max(dq + dv * (timed ? H : 1.0 / ad->w[i]) - noise, 0.0);
        /* an event's error: first order plus its bounds; a flight's: Richardson's d / (2^p - 1) */
        double e = event ? d + ad->bound[i] : d / div;
        ad->eps[i] = e;
        /* r > 1: some dof fails its tolerance */
        r = pd_max(r, e / (dof_scale(ad, i) * (event ? tol_event : tol_flight)));
    }
    return r;
}

/* A new try: no dof marked, no bound. */
static void try_begin(mj_adapt *ad, int n)
{
    if (++ad->try_stamp == 0) { /* the stamps wrapped: clear the marks */
        memset(ad->evmark, 0, (size_t)n * sizeof *ad->evmark);
        memset(ad->timed, 0, (size_t)n * sizeof *ad->timed);
        ad->try_stamp = 1;
    }
    memset(ad->bound, 0, (size_t)n * sizeof *ad->bound);
}

/* ---- keeping steps ------------------------------------------------------------------ */

/* The closing speeds below which a contact takes no restitution, from the
 * tolerance: a rebound e |U| <= ke rtol s_i w_i moves its dofs within the
 * event tolerance; and the gap accelerations that press each contact shut
 * at the state x (made by a step from w): its free motion's, G, and the
 * held forces of the contacts it shares a dof with (their impulses in both
 * steps, over the step), for the steps' own part (rest_for_step). */
static void rest_speeds(pd_mj *mj, const snap *w, snap *x)
{
    const pd_model *md = mj->model;
    const mj_incidence *in = &mj->inc;
    mj_adapt *ad = mj->ad;
    /* the contacts pushing through both steps (else no held force to add):
     * their mean forces P_b / h summed on each of their dofs */
    int both = 0;
    for (int r = 0; r < ad->npush && x->st.h > 0.0; r++) {
        int b = ad->push[r]; /* pushing at x (keep) */
        if (!(w->st.P[b] > 0.0))
            continue;
        if (!both)
            memset(ad->hsum, 0, (size_t)md->n * sizeof *ad->hsum);
        both = 1;
        for (int j = in->ptr[b]; j < in->ptr[b + 1]; j++)
            ad->hsum[in->dof[j]] += x->st.P[b] / x->st.h;
    }
    const double *af = free_accs(mj, x);
    double ku = ADAPT_KE * mj->opts.rtol;
    for (int a = 0; a < md->m; a++) {
        double u = HUGE_VAL, G = 0.0, held = 0.0;
        int self = both && w->st.P[a] > 0.0 && x->st.P[a] > 0.0;
        for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++) {
            int i = in->dof[j];
            /* u: the smallest ke rtol s_i w_i of its dofs */
            u = pd_min(u, ku * dof_scale(ad, i) * ad->w[i]);
            G += in->w[j] * (af ? af[i] : free_acc(mj, x, i)); /* W_a^T a_free */
            /* the other contacts on dof i held through both steps */
            if (both)
                held += fabs(in->w[j]) * ad->minv[i] *
                        (self ? ad->hsum[i] - x->st.P[a] / x->st.h : ad->hsum[i]);
        }
        ad->u_tol[a] = isfinite(u) ? u : 0.0; /* no dof: none */
        ad->Gs[a] = G;
        ad->G[a] = fabs(G) + held;
    }
}

/* The rest speeds of a step of size h from x (mj->u_rest): the
 * tolerance's, and for a contact shut at x (its gap within sim_gap: in
 * contact, not arriving) ADAPT_CHATTER G h, the speed it reaches in a few
 * steps of the accelerations pressing it: a contact in contact closing
 * that slowly is resting on it (the scheme's chatter at O(h) speeds,
 * else).  A contact arriving across an open gap rebounds at any speed
 * above the tolerance's. */
static void rest_for_step(pd_mj *mj, const snap *x, double h)
{
    mj_adapt *ad = mj->ad;
    for (int a = 0; a < mj->model->m; a++)
        ad->u_rest[a] = x->st.g[a] <= mj->opts.sim_gap
                            ? pd_max(ad->u_tol[a], ADAPT_CHATTER * ad->G[a] * h)
                            : ad->u_tol[a];
}

/* The state's err: the estimate so far and, for exact flights, the bound
 * of the observers' quintic interpolation inside the last step h, (w h)^6
 * / 46080 s_i (w: the dof's frequency or the forcing's in the step, wf, the
 * larger). */
static void report_err(pd_mj *mj, double h, double wf)
{
    mj_adapt *ad = mj->ad;
    for (int i = 0; i < mj->model->n; i++) {
        double wh = pd_max(ad->w[i], wf) * h, wh3 = wh * wh * wh;
        /* flights' errors add up (E), events' in quadrature (S2) */
        ad->Er[i] = ad->E[i] + (ad->S2[i] > 0.0 ? sqrt(ad->S2[i]) : 0.0) +
                    (ad->F ? wh3 * wh3 / 46080.0 * dof_scale(ad, i) : 0.0);
    }
}

/* Contact a held at x: it pushed in the step to x and rests there (|U| <=
 * u_rest: the impulses held its gap rate at zero). */
static int is_held(const pd_mj *mj, const snap *x, int a)
{
    return x->st.P[a] > 0.0 && fabs(mj_inc_dot(&mj->inc, a, x->st.v)) <= mj->u_rest[a];
}

/* The contacts held at x (the kept state: among ad->push) into
 * mj->idx_active and their block D_HH = W_H^T M^-1 W_H (M diagonal) into
 * mj->D_active: their number. */
static int held_set(pd_mj *mj, const snap *x)
{
    int nH = 0;
    for (int r = 0; r < mj->ad->npush; r++)
        if (is_held(mj, x, mj->ad->push[r]))
            mj->idx_active[nH++] = mj->ad->push[r];
    mj_flight_delassus(mj, 0, mj->ad->minv, nH);
    return nH;
}

/* The held contacts' forces at x under the free motion's accelerations af
 * into ad->lam: the acceleration LCP over the held set of held_set (nH),
 * lam_H >= 0, W_H^T (af + M^-1 W_H lam_H) >= 0, complementary, every other
 * contact's 0.  The forces at the state's instant, as the exact reference
 * has them: a step's mean P / h moves with the step's length and with the
 * impulses of its neighbours' impacts.  Where the LCP is not solved the
 * held contacts take P / h. */
static void held_forces(pd_mj *mj, const snap *x, int nH, const double *af)
{
    const mj_incidence *in = &mj->inc;
    mj_adapt *ad = mj->ad;
    for (int a = 0; a < mj->model->m; a++)
        ad->lam[a] = 0.0;
    if (nH == 0)
        return;
    /* b = W_H^T af: the free gap accelerations */
    for (int r = 0; r < nH; r++)
        mj->b_active[r] = mj_inc_dot(in, mj->idx_active[r], af);
    if (nH == 1 && mj->D_active[0] > 0.0) { /* one contact: the closed form */
        ad->lam[mj->idx_active[0]] = pd_contact_impulse_1(mj->D_active[0], mj->b_active[0]);
        return;
    }
    pd_lcp_opts lo = pd_lcp_default_opts();
    pd_lcp_info info;
    pd_matrix D = mj->sparse ? pd_matrix_csc(nH, nH, mj->D_colptr, mj->D_rowind, mj->D_active)
                             : pd_matrix_dense(nH, nH, mj->D_active);
    /* beyond Lemke's workspace (PD_LCP_LEMKE_NMAX) the solver refuses: not solved */
    int solved =
        pd_lcp_solve(mj->lcp, &D, mj->b_active, &lo, mj->P_active, mj->w_active, &info) == PD_OK;
    for (int r = 0; r < nH; r++) {
        int a = mj->idx_active[r];
        ad->lam[a] = solved ? mj->P_active[r] : x->st.h > 0.0 ? x->st.P[a] / x->st.h : 0.0;
    }
}

/* The held contacts' forces ad->lam (pushing ones only) into acc: a_i +=
 * W_ia lam_a / M_ii. */
static void add_held(const pd_mj *mj, double *acc)
{
    const mj_incidence *in = &mj->inc;
    for (int r = 0; r < mj->ad->npush; r++) {
        int a = mj->ad->push[r];
        if (mj->ad->lam[a] > 0.0)
            for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++)
                acc[in->dof[j]] += mj->ad->minv[in->dof[j]] * in->w[j] * mj->ad->lam[a];
    }
}

/* The accelerations at x for the observers' quintic interpolation of the
 * step to it and of the next: the free motion's plus the held contacts'
 * forces (held_forces); where a piece's start ended the step, the left
 * limit (the old piece's forcing) in acc, the right one in acc_right. */
static void step_accelerations(pd_mj *mj, snap *x)
{
    size_t bytes = (size_t)mj->model->n * sizeof(double);
    x->st.has_acc = 1;
    mj_flight_acc(mj, &x->st, x->z, x->af); /* anew: the held gaps may have moved q */
    x->af_ok = 1;
    x->st.acc_right = x->switched ? x->accr : x->st.acc;
    memcpy((double *)x->st.acc_right, x->af, bytes);
    /* one held set and block for both limits (none when no contact pushed) */
    int nH = mj->ad->npush == 0 ? 0 : held_set(mj, x);
    held_forces(mj, x, nH, x->af);
    if (nH > 0)
        add_held(mj, (double *)x->st.acc_right);
    if (!x->switched)
        return;
    /* the left limit, under the old piece's forcing zl */
    mj_flight_acc(mj, &x->st, x->zl, x->st.acc);
    held_forces(mj, x, nH, x->st.acc);
    if (nH > 0)
        add_held(mj, x->st.acc);
}

/* Errors cross contacts: a contact that pushed in the step to the kept
 * state (ad->push) moves each of its dofs by the others' motion (an
 * impact exchanges their momentum, a held contact makes them one body),
 * so each takes the largest estimate among them. */
static void share_errors(pd_mj *mj)
{
    const mj_incidence *in = &mj->inc;
    mj_adapt *ad = mj->ad;
    for (int r = 0; r < ad->npush; r++) {
        int a = ad->push[r];
        /* the largest E and S2 of the contact's dofs, to each */
        double E = 0.0, S2 = 0.0;
        for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++) {
            E = pd_max(E, ad->E[in->dof[j]]);
            S2 = pd_max(S2, ad->S2[in->dof[j]]);
        }
        for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++) {
            ad->E[in->dof[j]] = E;
            ad->S2[in->dof[j]] = S2;
        }
    }
}

/* Keep x, made by a step from w, as the new state with the error eps
 * scaled by f (0: none; events: the dofs the try's events marked count it
 * among the events'): the estimate, the amplitudes, the statistics; report
 * it.  Returns the observer's verdict (> 0: stop). */
/* Held contacts (pushing, their gap rate at rest: |U| <= u_rest) sit at
 * gap min(g(w), 0) in the kept state x: the impulses hold the gap rate at
 * zero, the gap itself drifts by O(h^3) per step (the force varies inside
 * the step), and a contact brought to rest by an impulse at mid-step
 * stops short of zero where the exact motion stops at zero.  q moves along
 * M^-1 W_a to put it there (Gauss-Seidel sweeps over the held contacts,
 * M^-1 by its diagonal), in the kept state only: the tries compare the
 * steps as the scheme made them.  A held gap left above sim_gap would
 * leave the contact out of the next impact's LCP, an impact of one body
 * where the pair strikes. */
#define ADAPT_HOLD_SWEEPS 3
static void hold_gaps(pd_mj *mj, const snap *w, snap *x)
{
    const pd_model *md = mj->model;
    const mj_incidence *in = &mj->inc;
    const mj_adapt *ad = mj->ad;
    int moved = 0;
    for (int sweep = 0; sweep < ADAPT_HOLD_SWEEPS; sweep++)
        for (int r = 0; r < ad->npush; r++) {
            int a = ad->push[r];
            if (!is_held(mj, x, a))
                continue;
            /* d: the gap's move to min(g(w), 0) */
            double d = fmin(w->st.g[a], 0.0) - (md->g0[a] + mj_inc_dot(in, a, x->st.q));
            double D0 = ad->D0[a];
            if (d == 0.0 || !(D0 > 0.0))
                continue;
            /* q += M^-1 W_a d / D0_a moves the gap by W_a^T M^-1 W_a d / D0_a = d */
            for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++)
                x->st.q[in->dof[j]] += ad->minv[in->dof[j]] * in->w[j] * d / D0;
            moved = 1;
        }
    /* the moved state's gaps */
    for (int a = 0; moved && a < md->m; a++)
        x->st.g[a] = md->g0[a] + mj_inc_dot(in, a, x->st.q);
}

static int keep(pd_mj *mj, const snap *w, snap *x, double f, int events, pd_observer observer,
                void *ctx)
{
    const pd_model *md = mj->model;
    mj_adapt *ad = mj->ad;
    ad->npush = 0; /* the contacts pushing at x */
    for (int a = 0; a < md->m; a++)
        if (x->st.P[a] > 0.0)
            ad->push[ad->npush++] = a;
    hold_gaps(mj, w, x);
    ad->impact_made = 0; /* an impact in the step w -> x (its impulses are no held force) */
    for (int r = 0; r < ad->npush && !ad->impact_made; r++)
        ad->impact_made = flight_event(mj, ad->push[r], impact_jump(mj, ad->push[r], w, x));
    x->st.impact = ad->impact_made;
    for (int i = 0; i < md->n; i++) {
        /* the estimate: an event's dofs in quadrature (S2), the others added (E) */
        if (f > 0.0 && events && ad->evmark[i] == ad->try_stamp)
            ad->S2[i] += f * ad->eps[i] * f * ad->eps[i];
        else if (f > 0.0)
            ad->E[i] += f * ad->eps[i];
        double vw = x->st.v[i] / ad->w[i];
        /* sqrt(q^2 + (v/w)^2) */
        ad->amp[i] = pd_max(ad->amp[i], sqrt(x->st.q[i] * x->st.q[i] + vw * vw));
    }
    share_errors(mj);
    if (ad->F) /* the accelerations, for the observers' interpolation */
        step_accelerations(mj, x);
    /* the statistics, the reported err, the observer */
    ad->stats.steps++;
    ad->stats.h_min = fmin(ad->stats.h_min, x->st.h);
    ad->stats.h_max = fmax(ad->stats.h_max, x->st.h);
    /* the step's piece: the one before x's when x is that piece's end */
    report_err(mj, x->st.h, ad->F ? piece_w(mj, x->switched ? x->piece - 1 : x->piece) : 0.0);
    mj->st = x->st;
    mj->st.err = ad->Er;
    return observer ? observer(&mj->st, ctx) : 0;
}

/* keep, then the rest speeds at x for the steps from it (rest_speeds). */
static int keep_from(pd_mj *mj, const snap *w, snap *x, double f, int events, pd_observer observer,
                     void *ctx)
{
    int stop = keep(mj, w, x, f, events, observer, ctx);
    rest_speeds(mj, w, x);
    return stop;
}

static void swap(snap **a, snap **b)
{
    snap *t = *a;
    *a = *b;
    *b = t;
}

/* Keep the pair of halves: half then two become the state, each with half
 * of the try's estimate (the rest speeds of the last kept only).  An
 * observer that stops the run at the half leaves the state there. */
static int keep_pair(pd_mj *mj, pd_observer observer, void *ctx)
{
    mj_adapt *ad = mj->ad;
    int stop = keep(mj, ad->cur, ad->half, 0.5, 1, observer, ctx);
    if (stop) {
        rest_speeds(mj, ad->cur, ad->half);
        swap(&ad->cur, &ad->half);
        return stop;
    }
    stop = keep_from(mj, ad->half, ad->two, 0.5, 1, observer, ctx);
    swap(&ad->cur, &ad->two);
    return stop;
}

/* A smooth pair's error per h^(p+1), for steps kept without a try of their own. */
static void note_rate(mj_adapt *ad, int n, double H)
{
    /* C of the local error C h^(p+1): the pair made 2 C (H/2)^(p+1) = C H^(p+1) / 2^p */
    double scale = (ad->div + 1.0) / (ad->p == 2 ? H * H * H : H * H);
    for (int i = 0; i < n; i++)
        ad->rate[i] = ad->eps[i] * scale;
}

/* The estimate of one smooth step of size h from the last smooth pair. */
static void rate_estimate(mj_adapt *ad, int n, double h)
{
    double hp = ad->p == 2 ? h * h * h : h * h;
    for (int i = 0; i < n; i++)
        ad->eps[i] = ad->rate[i] * hp; /* C h^(p+1) */
}

/* ---- the run ---------------------------------------------------------------------------- */

/* The last tick at or before t_end (t_end itself when within 1e-9 of a tick). */
static int end_tick(const mj_adapt *ad, double t_end, uint64_t *tick, pd_err *err)
{
    double r = (t_end - ad->t_origin) / ad->htick, k = floor(r + 0.5);
    /* ticks count in 64 bits; 2^62 leaves room for a step beyond */
    if (!(r < 0x1p62))
        return pd_err_set(err, PD_EINVAL,
                          "Moreau-Jean: the run to t = %g spans %.3g coarsest steps of %g, more "
                          "than the ladder of %d levels can count (a larger h)",
                          t_end, (t_end - ad->t_origin) / ad->h0, ad->h0, ad->L);
    *tick = r <= 0.0 ? 0 : fabs(r - k) <= 1e-9 * fmax(1.0, r) ? (uint64_t)k : (uint64_t)floor(r);
    return PD_OK;
}

/* The tick no step may cross from x: t_end, or the next piece's start. */
static uint64_t step_limit(const mj_adapt *ad, const snap *x, uint64_t tick_end)
{
    if (ad->F && x->piece + 1 < ad->F->npieces && ad->piece_tick[x->piece + 1] < tick_end)
        return ad->piece_tick[x->piece + 1];
    return tick_end;
}

/* The finest level: one step, no try (the estimate from the last smooth
 * pair, the events' bound); rtol is not met when an event needed more. */
static int finest_step(pd_mj *mj, pd_observer observer, void *ctx, pd_err *err)
{
    mj_adapt *ad = mj->ad;
    int n = mj->model->n, rc;
    double h = ad->lev[ad->L].h;
    /* one step at the foot, no halves to compare */
    if ((rc = take_step(mj, ad->L, ad->cur, ad->two, err)))
        return rc;
    try_begin(ad, n);
    rate_estimate(ad, n, h);
    scan_impacts(mj, ad->cur, ad->two, h, 1.0);
    for (int i = 0; i < n; i++)
        if (ad->evmark[i] == ad->try_stamp) {
            /* its events' bounds; beyond the event tolerance rtol is not met */
            ad->eps[i] += ad->bound[i];
            if (ad->eps[i] > ADAPT_KE * mj->opts.rtol * dof_scale(ad, i))
                ad->stats.floor_hit = 1;
        }
    int stop = keep_from(mj, ad->cur, ad->two, 1.0, 1, observer, ctx);
    swap(&ad->cur, &ad->two);
    return stop;
}

/* The first positive root of g + U s + G s^2 / 2 (+inf when none). */
static double first_root(double g, double U, double G)
{
    double r = HUGE_VAL, d = U * U - 2.0 * G * g;
    if (G == 0.0)
        return U < 0.0 ? -g / U : HUGE_VAL;
    if (d < 0.0)
        return HUGE_VAL;
    /* roots q / (G / 2) and g / q, q = -(U + sign(U) sqrt(d)) / 2 * 2: no cancellation */
    double q = -(U + copysign(sqrt(d), U));
    double s1 = q / G, s2 = q != 0.0 ? 2.0 * g / q : HUGE_VAL;
    if (s1 > 0.0)
        r = s1;
    if (s2 > 0.0 && s2 < r)
        r = s2;
    return r;
}

/* An impact's approach (exact flights): the flight of level k from x = cur
 * into ad->one shut a contact that was open at x.  Its instant s* from x
 * by the gap's Taylor polynomial g + U s + G s^2 / 2 (G the free motion's
 * gap acceleration; relative error about (w s)^2 / 6, w the fastest
 * frequency it sees), the earliest of the shut contacts'; the level of the
 * try that takes it, k_try: the coarsest whose halves h keep the impact's
 * bound, the dof's velocity jump times h, within half the event tolerance
 * ke rtol s_i.  The approach flies to the tick ad->target, at least (w s*)^2
 * / 2 s* and half a try's step before s*, on the grid of quarter steps of
 * k_try, and predicts again there.  Returns 1 with a target; 2 when the
 * impact lies within that lead: the try from x at level *k_try; 0 when
 * the halving is as good (k_try the next level, a contact shut at x, no
 * root).  by_flight: the contacts the flight shut (else every open one
 * whose polynomial closes within 2 h_k: at a target, no flight to find
 * them). */
static int approach(pd_mj *mj, int k, int *k_try, int by_flight)
{
    const pd_model *md = mj->model;
    const mj_incidence *in = &mj->inc;
    mj_adapt *ad = mj->ad;
    snap *x = ad->cur;
    double smin = HUGE_VAL, h_need = HUGE_VAL, w = 0.0;
    for (int a = 0; a < md->m; a++) {
        if (by_flight && !ad->one->st.active[a])
            continue;
        if (x->st.g[a] <= mj->opts.sim_gap) {
            if (by_flight)
                return 0; /* shut at x: a held contact's step, not an arrival */
            continue;
        }
        double U = mj_inc_dot(in, a, x->st.v), G = gap_acc(mj, x, a);
        double s = first_root(x->st.g[a], U, G);
        if (!(s < 2.0 * ad->lev[k].h)) {
            if (by_flight)
                return 0; /* no root near the step: the try's halving */
            continue;
        }
        /* the closing speed there, (1 + e) |U(s)| of gap rate; on dof i
         * |W_ia| M_ii^-1 / D0_a of it */
        double jump = (1.0 + md->e[a]) * fabs(U + G * s);
        for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++) {
            int i = in->dof[j];
            /* measured against the dof's scale and the contact's gap in its
             * units (the peak toward the wall is the gap) */
            double dv = jump * fabs(in->w[j]) * ad->minv[i] / ad->D0[a];
            double gap = md->g0[a] > 0.0 ? md->g0[a] / fabs(in->w[j]) : HUGE_VAL;
            if (dv > 0.0)
                h_need =
                    fmin(h_need, 0.5 * ADAPT_KE * mj->opts.rtol * fmin(dof_scale(ad, i), gap) / dv);
            w = fmax(w, mj_flight_wmax(mj, i)); /* its block's or the forcing's */
        }
        smin = fmin(smin, s);
    }
    if (!isfinite(smin))
        return 0;
    /* the try's level: its halves h_k_try+1 <= h_need */
    int kt = k + 1;
    while (kt + 1 < ad->L && ad->lev[kt + 1].h > h_need)
        kt++;
    if (kt <= k + 1 || kt + 2 > ad->L)
        return 0;
    *k_try = kt;
    double H = ad->lev[kt].h, margin = fmin(0.5, 0.5 * (w * smin) * (w * smin));
    double lead = fmax(margin * smin, 0.5 * H); /* how far before s* to stop */
    /* the target on the grid of quarter steps of k_try */
    uint64_t D = smin - lead <= H ? 0 : (uint64_t)((smin - lead) / ad->lev[kt + 2].h);
    if (D == 0)
        return 2;
    ad->target = x->tick + D * level_ticks(ad, kt + 2);
    return 1;
}

/* An exact flight of D ticks from a state where no contact pushes (one
 * level's step, or a span of several: span_step): kept whole when no
 * contact shuts, grazes or closes in it (then it has no error).  Returns 1
 * when kept, 0 when the step needs a try (a level's: in ad->one), < 0 on
 * failure. */
static int exact_flight(pd_mj *mj, uint64_t D, pd_observer observer, void *ctx, int *stop,
                        pd_err *err)
{
    mj_adapt *ad = mj->ad;
    int k = ad->L, rc;
    /* D = 2^(L - k): one level (D nonzero, at most h_0's 2^L ticks) */
    k -= trailing_zeros(D);
    if (level_ticks(ad, k) == D) { /* one level */
        if ((rc = take_step(mj, k, ad->cur, ad->one, err)))
            return rc;
    } else if ((rc = span_step(mj, D, ad->cur, ad->one, err)) <= 0) {
        return rc;
    }
    /* a contact predicted active: a try */
    if (ad->one->st.nactive > 0)
        return 0;
    try_begin(ad, mj->model->n);
    long before = ad->nmarked;
    /* a grazing dip inside: a try */
    scan_dips(mj, ad->cur, ad->one, ad->one->st.h);
    if (ad->nmarked > before)
        return 0;
    *stop = keep_from(mj, ad->cur, ad->one, 0.0, 0, observer, ctx); /* no error: f = 0 */
    swap(&ad->cur, &ad->one);
    return 1;
}

int mj_adapt_run_until(pd_mj *mj, double t_end, pd_observer observer, void *ctx, pd_err *err)
{
    const pd_model *md = mj->model;
    mj_adapt *ad = mj->ad;
    uint64_t tick_end = 0;
    int n = md->n, rc, have_one = 0, stop = 0;
    if ((rc = end_tick(ad, t_end, &tick_end, err)))
        return rc;
    if (!ad->started) {
        ad->started = 1;
        /* T: the first run's span, at least h0 */
        if (ad->span == 0.0)
            ad->span = fmax(t_end - ad->t_origin, ad->h0);
        /* the reset state, reported once */
        if (observer && observer(&mj->st, ctx) > 0)
            return PD_OK;
    }
    mj->stop = 0;
    int k = ad->k;
    uint64_t no_span = UINT64_MAX; /* a tick whose span to the limit found a contact */
    while (ad->cur->tick < tick_end && !stop && !mj->stop) {
        uint64_t limit = step_limit(ad, ad->cur, tick_end), tick = ad->cur->tick;
        /* an impact's approach: its target a limit; there, predicted again */
        if (ad->target && tick >= ad->target) {
            int k_try, how;
            ad->target = 0;
            k = flight_level(ad, ad->cur);
            have_one = 0;
            if ((how = approach(mj, k, &k_try, 0)) == 2)
                k = k_try;
            if (how)
                continue;
        }
        if (ad->target && ad->target < limit)
            limit = ad->target;
        /* exact flights: the rest of the way to t_end or a piece's start in one span
         * when a step of level k would cross it (the ladder's digits, not a walk) */
        if (ad->F && !have_one && k < ad->L && tick + level_ticks(ad, k) > limit &&
            tick != no_span && ad->npush == 0) {
            if ((rc = exact_flight(mj, limit - tick, observer, ctx, &stop, err)) < 0)
                return rc;
            if (rc == 1) {
                k = flight_level(ad, ad->cur);
                continue;
            }
            no_span = tick;
            ad->target = 0; /* the approach came too close: the tries from here */
        }
        /* the coarsest level from k on that ends in time and (theta flights)
         * starts on a multiple of its step; exact flights start anywhere */
        while (k < ad->L && ((!ad->F && (tick & (level_ticks(ad, k) - 1)) != 0) ||
                             tick + level_ticks(ad, k) > limit)) {
            k++;
            have_one = 0;
        }
        /* at the foot: one step, no try */
        if (k >= ad->L) {
            if ((rc = finest_step(mj, observer, ctx, err)) < 0)
                return rc;
            stop = rc;
            k = ad->L - 1;
            have_one = 0;
            continue;
        }
        /* tries in a row at the ladder's foot (rounding's scale: no finer step
         * tells the states apart): after ADAPT_DEEP_MAX, one is kept as it is
         * and the steps climb out; rtol is not met */
        ad->deep = k + ADAPT_DEEP >= ad->L ? ad->deep + 1 : 0;
        int stuck = ad->deep > ADAPT_DEEP_MAX;
        ad->stats.floor_hit |= stuck;
        /* max_evals spent: every try from here on is kept as it is */
        int budget = (double)ad->stats.evals >= mj->opts.max_evals;
        ad->stats.budget_hit |= budget;
        double H = ad->lev[k].h, h = ad->lev[k + 1].h;
        if (ad->F && !have_one && ad->npush == 0) {
            /* an exact flight: no error to control, so back to the coarsest step */
            if ((rc = exact_flight(mj, level_ticks(ad, k), observer, ctx, &stop, err)) < 0)
                return rc;
            if (rc == 1) {
                k = flight_level(ad, ad->cur);
                continue;
            }
            /* an impact ahead: fly to it, or try at its level, when the halving
             * would take longer */
            int k_try, how = ad->target ? 0 : approach(mj, k, &k_try, 1);
            if (how) {
                k = how == 2 ? k_try : k;
                have_one = 0;
                continue;
            }
            have_one = 1;
        }
        /* S1 = one step H (unless the last try left it), Sa and S2 = two steps h = H / 2 */
        if ((!have_one && (rc = take_step(mj, k, ad->cur, ad->one, err))) ||
            (rc = take_step(mj, k + 1, ad->cur, ad->half, err)) ||
            (rc = take_step(mj, k + 1, ad->half, ad->two, err)))
            return rc;
        /* the try: events mark their dofs for the event's test */
        try_begin(ad, n);
        int ev_half, event, cascade = scan_try(mj, h, &ev_half, &event);
        double r = try_error(mj, H);
        have_one = 0;
        /* kept: within the tolerance without a cascade, or nothing finer to try */
        if ((r <= 1.0 && !cascade) || budget || stuck || k + 1 >= ad->L) {
            ad->stats.floor_hit |= (r > 1.0 || cascade) && !budget;
            if (!event)
                note_rate(ad, n, H); /* a smooth pair: its error constant */
            stop = keep_pair(mj, observer, ctx);
            /* well within 2^-p of the tolerance: the step doubles; exact flights
             * climb as many levels as r h^p keeps within ADAPT_GROW (at most
             * ADAPT_CLIMB a try while a contact pushes, 4 ADAPT_CLIMB else), never
             * above the observers' level k_flight */
            int top = ad->F ? flight_level(ad, ad->cur) : 0;
            int climb = !ad->F ? 1 : ad->npush == 0 ? 4 * ADAPT_CLIMB : ADAPT_CLIMB;
            for (int up = 0; !event && k > top && up < climb && r * (ad->div + 1.0) <= ADAPT_GROW;
                 up++) {
                k--;
                r *= ad->div + 1.0;
            }
            if (stuck) {
                ad->deep = 0;
                k = ad->L - ADAPT_DEEP - 1;
            }
            continue;
        }
        /* rejected: halve */
        ad->stats.rejected++;
        if (event && !ev_half) {
            /* the event lies in the second half: keep the first, try the second */
            rate_estimate(ad, n, h);
            stop = keep_from(mj, ad->cur, ad->half, 1.0, 0, observer, ctx);
            swap(&ad->cur, &ad->half);
            swap(&ad->one, &ad->two); /* the second half's whole step */
        } else {
            swap(&ad->one, &ad->half); /* the first half is the next try's whole step */
        }
        have_one = 1;
        k++;
    }
    ad->k = k;
    mj->st = ad->cur->st;
    mj->st.err = ad->Er;
    return PD_OK;
}

void mj_adapt_stats(const pd_mj *mj, pd_mj_stats *s)
{
    const mj_adapt *ad = mj->ad;
    *s = ad->stats;
    s->err_max = 0.0;
    /* err_max = max_i (E_i + sqrt(S2_i)) / s_i */
    for (int i = 0; i < mj->model->n; i++)
        s->err_max = pd_max(s->err_max, (ad->E[i] + sqrt(ad->S2[i])) / dof_scale(ad, i));
    if (s->steps == 0)
        s->h_min = s->h_max = NAN; /* no step, no sizes */
}
