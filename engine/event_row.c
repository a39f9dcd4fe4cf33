/* event_row.c — the exact event-driven reference for rows (pd_edr).
 *
 * Asynchronous events, as event-driven molecular dynamics schedules them:
 * every structure belongs to a cluster (event_row_cluster.c) that moves by an
 * exact flight from its origin; each open contact holds one prediction of
 * its next closing (from the flights of its two sides), each cluster with
 * persistent contacts one of its next detachment, and a priority queue
 * orders them with the forcing's next piece and the output grid.  A
 * prediction scans one window (EDR_WINDOW0 scan intervals, doubling up to
 * EDR_WINDOW) and, finding nothing, queues its own continuation, so that a
 * prediction that an event will soon replace costs little.  An event re-origins the clusters it
 * touches and predicts again only the contacts next to them.
 *
 * An impact at t (a contact's predicted closing):
 *   1. the group: from the closing contact, every contact of the clusters
 *      reached whose gap is <= close_tol L at t is closed, and its other
 *      side joins (persistent contacts are closed by definition);
 *   2. the extremes of the group's flights are measured up to t;
 *   3. the impact in stages (impact_stages): each an LCP with Newton's law
 *      over the closed contacts Z that are not separating,
 *        U+ = U- + D P,  0 <= U+ + e min(U-, 0) _|_ P >= 0,  D = W_Z^T M^-1 W_Z,
 *      until no closed contact closes; a contact closing a third time at
 *      one instant is plastic (an accumulation at that instant).  On the
 *      clusters' coordinates when it can (impact_reduced_stages), on the dofs
 *      otherwise.  The single law (PD_IMPACT_SINGLE) solves one LCP over
 *      every closed contact, separating ones included, and stops there
 *      (event-general's and Moreau-Jean's law);
 *   4. the contacts left at zero rate decide persistence by the
 *      contact-force LCP (g'' = D lambda + W^T M^-1 (b f - C v - K q));
 *      a contact leaving with a bounce height U+^2 / (2 a) below 1e-10 L
 *      under a closing acceleration a, whose bouncing-ball tail
 *      2 U+ / (a (1 - e)) fits in the forcing piece, has its accumulation
 *      jumped: it joins the held contacts (their velocities projected
 *      M-orthogonally by the cluster's start) if the force LCP and the
 *      force at the tail's middle and end keep it;
 *   5. new clusters from the held contacts, new flights, predictions. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "event_row.h"
#include "pd_alloc.h"
#include "pd_null.h"

/* Bounce heights below this times the length scale are jumped (as the
 * one-wall reference). */
#define EDR_ACC_HEIGHT 1e-10
/* A gap rate is zero below this times the velocity scale of the event. */
#define EDR_RATE_TOL 1e-12
/* Scan intervals a prediction covers before it queues its continuation. */
#define EDR_WINDOW 64
#define EDR_WINDOW0 4
/* A prediction whose safe time (flight bounds) exceeds this many scan
 * steps waits for it instead of scanning. */
#define EDR_SAFE_SCANS 2
/* Closings of one contact at one instant before its impact is plastic
 * (stage_e). */
#define EDR_INSTANT_BOUNCES 2
/* Stages of one impact (a closed contact closing again under the
 * others' impulses) before the run is declared stuck. */
#define EDR_STAGES 10000
/* A tie (zero rate, force and gap acceleration) is broken by the gap's
 * jerk only while the bodies accelerate by more than this times the length
 * scale (per unit time squared): bodies touching under the ground motion,
 * not a structure coming to rest at a wall at its own rest position. */
#define EDR_TIE_ACC 1e-6
/* A hold ends a contact's burst of impacts (max_burst) when it lasts
 * longer than this (units of the run's time). */
#define EDR_HOLD_MIN 1e-6
/* The shift of a singular contact LCP's unit diagonal (scaled_lcp). */
#define EDR_LCP_SHIFT 1e-10
/* Events of one contact or cluster within this span (units of the run's
 * time) before the run is declared stuck in a chatter. */
#define EDR_CHATTER_EVENTS 10000
#define EDR_CHATTER_SPAN 1e-4
/* Events at one instant before the run is declared stuck. */
#define EDR_SAME_INSTANT 1000
/* The clusters' LCPs (contacts between clusters: one or two, a row's
 * cascade more) are dense up to this size, else the dofs' LCP decides. */
#define EDR_REDUCED_MAX 64
/* Impact LCPs of up to this many contacts are assembled densely. */
#define EDR_DENSE_MAX 8
/* A closing must take the gap below -this times the size of its terms
 * (g0 and the displacements it adds): its rounding level. */
#define EDR_GAP_ROUND 1e-14
/* A stage's Newton residual, formed on the clusters, is refined when it
 * exceeds this many roundings of its terms (DBL_EPSILON), in at most
 * EDR_REFINE_MAX steps. */
#define EDR_REFINE_TOL 64.0
#define EDR_REFINE_MAX 8
/* An impact's work may exceed 0 by this many roundings of its terms. */
#define EDR_WORK_TOL 16.0

pd_edr_opts pd_edr_default_opts(void)
{
    return (pd_edr_opts){.close_tol = EDR_ACC_HEIGHT,
                         .length_scale = 1.0,
                         .time_unit = 1.0,
                         .t_measure = 0.0,
                         .h_out = 0.0,
                         .impacts_only = 0,
                         .below = NULL,
                         .no_accumulation = 0,
                         .inactive = 0,
                         .max_events = 10000000L,
                         .max_burst = 100000L,
                         .max_evals = 4e9,
                         .scan_divisions = 64,
                         .lcp_solver = PD_LCP_AUTO,
                         .impact_law = PD_IMPACT_STAGED,
                         .on_event = NULL,
                         .on_event_ctx = NULL,
                         .energy = 0};
}

/* ---- the queue ----------------------------------------------------------------- */

static int q_less(const edr_queue *q, int a, int b)
{
    /* earlier first; at one time the lower slot (contacts, clusters, the piece,
     * the output): simultaneous events in an order fixed by the model */
    return q->key[a] < q->key[b] || (q->key[a] == q->key[b] && a < b);
}

static void q_swap(edr_queue *q, int i, int j)
{
    int a = q->heap[i], b = q->heap[j];
    q->heap[i] = b;
    q->heap[j] = a;
    /* pos stays the inverse of heap: pos[heap[i]] = i */
    q->pos[b] = i;
    q->pos[a] = j;
}

static void q_up(edr_queue *q, int i)
{
    while (i > 0) {
        /* the parent of heap index i is (i - 1) / 2 */
        int p = (i - 1) / 2;
        if (!q_less(q, q->heap[i], q->heap[p]))
            break;
        q_swap(q, i, p);
        i = p;
    }
}

static void q_down(edr_queue *q, int i)
{
    for (;;) {
        /* down past the earlier of the children 2 i + 1, 2 i + 2 */
        int l = 2 * i + 1, rr = l + 1, s = i;
        if (l < q->n && q_less(q, q->heap[l], q->heap[s]))
            s = l;
        if (rr < q->n && q_less(q, q->heap[rr], q->heap[s]))
            s = rr;
        if (s == i)
            return;
        q_swap(q, i, s);
        i = s;
    }
}

/* Queue slot at time t (HUGE_VAL: out of the queue). */
static void q_set(edr_queue *q, int slot, double t)
{
    int i = q->pos[slot];
    /* HUGE_VAL (or NaN): out; the heap's last entry takes its place and
     * moves up or down from there */
    if (!(t < HUGE_VAL)) {
        if (i < 0)
            return;
        q->key[slot] = HUGE_VAL;
        q_swap(q, i, --q->n);
        q->pos[slot] = -1;
        if (i < q->n) {
            q_up(q, i);
            q_down(q, i);
        }
        return;
    }
    /* a new slot goes at the end; a key moved earlier rises, one moved later
     * sinks (only one of the two moves it) */
    q->key[slot] = t;
    if (i < 0) {
        i = q->n++;
        q->heap[i] = slot;
        q->pos[slot] = i;
    }
    q_up(q, i);
    q_down(q, q->pos[slot]);
}

/* ---- helpers -------------------------------------------------------------------- */

static int cl_of_dof(const pd_edr *r, int dof)
{
    return r->rs.blk_cl[r->tp.dof_blk[dof]];
}

/* x(t), v(t), a(t) of a dof. */
static void dof_state(pd_edr *r, int dof, double t, double *x, double *v, double *a)
{
    double dx;
    /* the flight gives x - xo, the increment from its origin's state */
    edr_dof_at(r, cl_of_dof(r, dof), dof, t, &dx, v, a);
    *x = r->rs.xo[dof] + dx;
}

/* The gap of contact a at t from the positions. */
static double gap_now(pd_edr *r, int a, double t, double *U)
{
    const edr_contact *ct = &r->tp.ct[a];
    /* g = g0 + w0 x0 + w1 x1 and U = w0 v0 + w1 v1 (a wall side: dof -1, at rest) */
    double g = ct->g0, u = 0.0;
    for (int s = 0; s < 2; s++)
        if (ct->dof[s] >= 0) {
            double x, v, acc;
            dof_state(r, ct->dof[s], t, &x, &v, &acc);
            g += ct->w[s] * x;
            u += ct->w[s] * v;
        }
    if (U)
        *U = u;
    return g;
}

/* ---- gap and force functions for the scanner ----------------------------------- */

typedef struct gap_ctx {
    pd_edr *r;
    int a;
    double gb;     /* the gap at tb */
    double dxb[2]; /* the sides' increments at tb */
    double thr;    /* the gap's rounding level */
} gap_ctx;

/* f = -g, f' = -U, f'' = -G: positive past the closing. */
static void gap_fn(void *vctx, double t, double out[3])
{
    gap_ctx *g = vctx;
    const edr_contact *ct = &g->r->tp.ct[g->a];
    /* g(t) = g(tb) + sum_s w_s (dx_s(t) - dx_s(tb)): the base gap moved by the
     * flights' increments, so that a gap known exactly (0 after a closing)
     * keeps its value, free of the positions' rounding in g0 + W^T x */
    double gap = g->gb, U = 0.0, G = 0.0;
    for (int s = 0; s < 2; s++)
        if (ct->dof[s] >= 0) {
            double dx, v, acc;
            edr_dof_at(g->r, cl_of_dof(g->r, ct->dof[s]), ct->dof[s], t, &dx, &v, &acc);
            gap += ct->w[s] * (dx - g->dxb[s]);
            U += ct->w[s] * v;
            G += ct->w[s] * acc;
        }
    out[0] = -gap;
    out[1] = -U;
    out[2] = -G;
}

/* The gap's base for contact a: the latest origin of its sides, where its
 * value is known exactly (0 after a closing) or taken from the positions. */
static void gap_base(pd_edr *r, int a, gap_ctx *g)
{
    const edr_contact *ct = &r->tp.ct[a];
    /* tb: the later of its sides' flight origins; the gap is one smooth
     * function of t since */
    double tb = -HUGE_VAL;
    for (int s = 0; s < 2; s++)
        if (ct->dof[s] >= 0)
            tb = fmax(tb, r->rs.cl[cl_of_dof(r, ct->dof[s])].t0);
    g->r = r;
    g->a = a;
    double gap = ct->g0;
    for (int s = 0; s < 2; s++) {
        g->dxb[s] = 0.0;
        if (ct->dof[s] >= 0) {
            double v, acc;
            edr_dof_at(r, cl_of_dof(r, ct->dof[s]), ct->dof[s], tb, &g->dxb[s], &v, &acc);
            gap += ct->w[s] * (r->rs.xo[ct->dof[s]] + g->dxb[s]);
        }
    }
    /* an event that closed the contact set its gap to 0 at base_t: exact while
     * neither side has left its origin since; else g0 + W^T x at tb */
    g->gb = r->rs.base_t[a] == tb ? r->rs.base_g[a] : gap;
    /* the rounding level of the gap: its terms' size */
    double size = fabs(ct->g0);
    for (int s = 0; s < 2; s++)
        if (ct->dof[s] >= 0)
            size += fabs(ct->w[s]) * (fabs(r->rs.xo[ct->dof[s]]) + fabs(g->dxb[s]));
    g->thr = EDR_GAP_ROUND * size;
}

/* Scan step of a contact: the finer of its sides'. */
static double contact_step(const pd_edr *r, int a)
{
    const edr_contact *ct = &r->tp.ct[a];
    double h = HUGE_VAL;
    for (int s = 0; s < 2; s++)
        if (ct->dof[s] >= 0)
            h = fmin(h, r->rs.cl[r->rs.blk_cl[r->tp.dof_blk[ct->dof[s]]]].h);
    return h;
}

/* ---- predictions ----------------------------------------------------------------- */

/* The time a function with value g >= 0, rate U and |second derivative|
 * <= G2 takes at least to reach zero: the positive root of
 * g + U s - G2 s^2 / 2 (HUGE_VAL when it never does). */
static double safe_time(double g, double U, double G2)
{
    /* at zero or past it: no time is safe */
    if (!(g > 0.0))
        return 0.0;
    /* no curvature: the line g + U s reaches 0 at g / -U when U < 0 */
    if (!(G2 > 0.0))
        return U < 0.0 ? g / -U : HUGE_VAL;
    return (U + sqrt(U * U + 2.0 * G2 * g)) / G2;
}

/* A bound on contact a's |g''| over its sides' flights, or -1 when a side
 * has none. */
static double gap_curvature(const pd_edr *r, int a)
{
    const edr_contact *ct = &r->tp.ct[a];
    double G2 = 0.0;
    for (int s = 0; s < 2; s++)
        if (ct->dof[s] >= 0) {
            const edr_cluster *cl = &r->rs.cl[cl_of_dof(r, ct->dof[s])];
            if (!cl->bnd)
                return -1.0;
            /* x_i = s_i y + d_i: |g''| <= sum_s |w_s s_i| max |y''| of its side's flight */
            G2 += fabs(ct->w[s] * r->rs.s[ct->dof[s]]) * cl->Y2;
        }
    return G2;
}

/* End of what a prediction may cover: the piece's end and t1. */
static double horizon(const pd_edr *r)
{
    return fmin(edr_piece_end(r, r->rs.piece), r->rs.t1);
}

/* The end of a prediction's window from ts: win scan steps of h (windows
 * double from EDR_WINDOW0 to EDR_WINDOW as a prediction continues), cut at
 * the horizon. */
static double window_end(pd_edr *r, int slot, int cont, double ts, double h)
{
    int win = cont && r->rs.win[slot] > 0 ? r->rs.win[slot] : EDR_WINDOW0;
    r->rs.win[slot] = win < EDR_WINDOW ? 2 * win : EDR_WINDOW;
    return fmin(horizon(r), ts + win * h);
}

/* Scan (p.t, tw] interval by interval on the grid p.t + k h (the last
 * interval ends at tw exactly): the first crossing found is slot's
 * prediction (EDR_Q_HIT); none, the window's continuation is queued at tw
 * (none at the horizon: a piece change predicts again, t1 ends the run). */
static void scan_window(pd_edr *r, int slot, edr_scan *s, edr_pt p, double h, double tw)
{
    double t0 = p.t, tend = horizon(r);
    long n = (long)ceil((tw - t0) / h);
    if (n < 1)
        n = 1;
    for (long i = 1; i <= n; i++) {
        double tb = i == n ? tw : t0 + (double)i * h, hit;
        if (!(tb > p.t))
            break;
        edr_pt b = edr_scan_point(s, tb);
        if (edr_scan_interval(s, &p, &b, &hit)) {
            r->rs.qkind[slot] = EDR_Q_HIT;
            q_set(&r->rs.q, slot, hit);
            return;
        }
        p = b;
    }
    r->rs.qkind[slot] = EDR_Q_SCAN;
    q_set(&r->rs.q, slot, tw < tend ? tw : HUGE_VAL);
}

/* Contact a's next closing after ts, or the end of its scan window. */
static void predict_contact(pd_edr *r, int a, double ts, int cont)
{
    int slot = a;
    if (r->tp.o.inactive || r->rs.cstate[a] != EDR_OPEN) {
        q_set(&r->rs.q, slot, HUGE_VAL);
        return;
    }
    const edr_contact *ct = &r->tp.ct[a];
    if (ct->dof[0] >= 0 && ct->dof[1] >= 0 &&
        cl_of_dof(r, ct->dof[0]) == cl_of_dof(r, ct->dof[1]) &&
        r->rs.cl[cl_of_dof(r, ct->dof[0])].kind != EDR_MODAL) {
        q_set(&r->rs.q, slot, HUGE_VAL); /* both sides in one rigid tree: the gap is constant */
        return;
    }
    gap_ctx g;
    gap_base(r, a, &g);
    edr_scan s = {
        .fn = gap_fn, .ctx = &g, .hit_mode = 1, .thr = g.thr, .fmax = -HUGE_VAL, .fmin = HUGE_VAL};
    double h = contact_step(r, a), tend = horizon(r), tw = window_end(r, slot, cont, ts, h);
    s.width = 4e-8 * h;
    edr_pt p = edr_scan_point(&s, ts);
    /* a gap at zero (within the closing tolerance) closing at a rate an
     * impact takes as zero (EDR_RATE_TOL of the run's speeds: touching
     * bodies come to rest with rounding in their rates) under an opening
     * acceleration: the gap dips by df^2 / (2 |ddf|), a rounding, and opens.
     * The scan starts where the Taylor quadratic has it back, or at the
     * window's end (else the contact would close at the next double, an
     * impact that does nothing, again and again) */
    if (p.df > 0.0 && p.ddf < 0.0 && p.df <= EDR_RATE_TOL * r->rs.vscale &&
        p.f <= r->tp.o.close_tol * r->rs.L) {
        double back = ts - 2.0 * p.df / p.ddf;
        if (!(back < tw)) {
            r->rs.qkind[slot] = EDR_Q_SCAN;
            q_set(&r->rs.q, slot, tw < tend ? tw : HUGE_VAL);
            return;
        }
        p = edr_scan_point(&s, back);
        if (p.f > 0.0 && p.f <= r->tp.o.close_tol * r->rs.L) {
            g.gb += p.f; /* the dip's rounding: the gap is zero there */
            p.f = 0.0;
        }
    }
    if (p.f > 0.0) { /* past zero at the start: rounding of a gap that is 0 */
        if (p.f > g.thr && p.df > 0.0) {
            r->rs.qkind[slot] = EDR_Q_HIT;
            q_set(&r->rs.q, slot, p.t);
            return;
        }
        g.gb += p.f;
        p.f = 0.0;
    }
    /* a closing the Taylor quadratic puts early in the first interval: a first
     * interval of twice that time brackets it closely */
    double s0 = p.df > 0.0 ? edr_taylor_root(&p) : NAN, t0 = p.t;
    if (s0 < 0.25 * h && t0 + 2.0 * s0 < tw) {
        double hit;
        edr_pt b = edr_scan_point(&s, t0 + 2.0 * s0);
        if (edr_scan_interval(&s, &p, &b, &hit)) {
            r->rs.qkind[slot] = EDR_Q_HIT;
            q_set(&r->rs.q, slot, hit);
            return;
        }
        p = b;
        t0 = b.t;
    }
    /* far from closing by the flights' bounds: no scan before the safe time */
    double G2, sf = safe_time(-p.f, -p.df, G2 = gap_curvature(r, a));
    if (G2 >= 0.0 && sf > EDR_SAFE_SCANS * h) {
        r->rs.qkind[slot] = EDR_Q_SCAN;
        q_set(&r->rs.q, slot, ts + sf < tend ? ts + sf : HUGE_VAL);
        return;
    }
    /* the window on the contact's grid: the first closing is the prediction */
    scan_window(r, slot, &s, p, h, tw);
}

typedef struct force_ctx {
    pd_edr *r;
    int c, a;
} force_ctx;

static void force_fn(void *vctx, double t, double out[3])
{
    force_ctx *f = vctx;
    out[0] = edr_force_at(f->r, f->c, f->a, t);
    /* the force alone: it is only bisected on its sign (edr_bisect_sign) */
    out[1] = out[2] = 0.0;
}

/* lambda linear in t on a linear piece (REST): its zero, polished to the
 * first double where it is negative (the one-wall reference's rule). */
static double detach_linear(pd_edr *r, int c, int a, double ta, double tb)
{
    force_ctx f = {.r = r, .c = c, .a = a};
    double la = edr_force_at(r, c, a, ta), lb = edr_force_at(r, c, a, tb);
    /* negative at ta already: it detaches now */
    if (la < 0.0)
        return ta;
    /* a line positive at both ends stays positive */
    if (!(lb < 0.0))
        return HUGE_VAL;
    /* the line's zero ta + la (tb - ta) / (la - lb), then a bracket of 16
     * roundings about it; the whole interval when rounding puts the sign
     * change outside */
    double tr = fmin(fmax(ta + la * (tb - ta) / (la - lb), ta), tb);
    double pad = 16.0 * 2e-16 * fmax(fabs(tr), 1e-300);
    double lo = fmax(tr - pad, ta), hi = fmin(tr + pad, tb);
    if (!(edr_force_at(r, c, a, lo) >= 0.0 && edr_force_at(r, c, a, hi) < 0.0)) {
        lo = ta;
        hi = tb;
    }
    return edr_bisect_sign(force_fn, &f, 0, -1.0, lo, hi);
}

/* Cluster c's next detachment (a persistent force turning negative) after
 * ts, or the end of its scan window. */
static void predict_detach(pd_edr *r, int c, double ts, int cont)
{
    edr_cluster *cl = &r->rs.cl[c];
    int slot = r->tp.m + c;
    if (r->tp.o.inactive || cl->npers == 0) {
        q_set(&r->rs.q, slot, HUGE_VAL);
        return;
    }
    double tend = horizon(r), best = HUGE_VAL;
    int who = -1;
    const pd_sine_piece *pc = &r->tp.pieces[cl->piece];
    /* a REST tree's forces are lg f + ld: linear in t on a piece without sine */
    if (cl->kind == EDR_REST && pc->A == 0.0) { /* linear forces: closed form */
        for (int a = cl->pers_head; a >= 0; a = r->rs.pers_next[a]) {
            double td = detach_linear(r, c, a, ts, tend);
            if (td < best) {
                best = td;
                who = a;
            }
        }
        cl->det_contact = who;
        r->rs.qkind[slot] = EDR_Q_HIT;
        q_set(&r->rs.q, slot, best);
        return;
    }
    double h = cl->h, tw = window_end(r, slot, cont, ts, h), ta = ts;
    if (cl->bnd && (cl->kind == EDR_SDOF || cl->kind == EDR_REST)) {
        /* lambda = la y + lb y' + lg f + ld: |lambda''| <= |la| Y2 + |lb| Y3 + |lg| F2 */
        const pd_sine_piece *pc2 = &r->tp.pieces[cl->piece];
        double sf = HUGE_VAL, df = pc2->A * pc2->w * cos(pc2->w * ts + pc2->phi) + pc2->c1;
        for (int a = cl->pers_head; a >= 0; a = r->rs.pers_next[a]) {
            /* lambda' = la y' + lb y'' + lg f' at ts; safe_time: no zero of lambda before */
            double lam = edr_force_at(r, c, a, ts);
            double dl = r->rs.la[a] * cl->vy + r->rs.lb[a] * cl->ay + r->rs.lg[a] * df;
            double L2 = fabs(r->rs.la[a]) * cl->Y2 + fabs(r->rs.lb[a]) * cl->Y3 +
                        fabs(r->rs.lg[a]) * cl->F2;
            sf = fmin(sf, safe_time(lam, dl, L2));
        }
        /* every force stays positive that long: no scan before */
        if (sf > EDR_SAFE_SCANS * h) {
            r->rs.qkind[slot] = EDR_Q_SCAN;
            q_set(&r->rs.q, slot, ts + sf < tend ? ts + sf : HUGE_VAL);
            return;
        }
    }
    for (int a = cl->pers_head; a >= 0; a = r->rs.pers_next[a])
        /* a force negative at ts already (at a re-origin, by rounding): detach now */
        if (edr_force_at(r, c, a, ts) < 0.0) {
            cl->det_contact = a;
            r->rs.qkind[slot] = EDR_Q_HIT;
            q_set(&r->rs.q, slot, ts);
            return;
        }
    /* the window on the cluster's grid: a force negative at a grid point is
     * bisected back to its first negative double; the earliest contact wins */
    long n = (long)ceil((tw - ts) / h);
    if (n < 1)
        n = 1;
    for (long i = 1; i <= n && who < 0; i++) {
        double tb = i == n ? tw : ts + (double)i * h;
        if (!(tb > ta))
            break;
        for (int a = cl->pers_head; a >= 0; a = r->rs.pers_next[a])
            if (edr_force_at(r, c, a, tb) < 0.0) {
                force_ctx f = {.r = r, .c = c, .a = a};
                double td = edr_bisect_sign(force_fn, &f, 0, -1.0, ta, tb);
                if (td < best) {
                    best = td;
                    who = a;
                }
            }
        ta = tb;
    }
    if (who >= 0) {
        cl->det_contact = who;
        r->rs.qkind[slot] = EDR_Q_HIT;
        q_set(&r->rs.q, slot, best);
        return;
    }
    /* every force positive over the window: its continuation at tw */
    r->rs.qkind[slot] = EDR_Q_SCAN;
    q_set(&r->rs.q, slot, tw < tend ? tw : HUGE_VAL);
}

/* A yielding spring's event function (spring j, its structure's cluster
 * c): elastic, z^2 - uy^2 with z = d - up, d its drift (positive past
 * either level: an onset); sliding toward ph, -ph d' (positive once the
 * drift turns back: the unloading). */
typedef struct spring_ctx {
    pd_edr *r;
    int c, j;
    double up, uy, ph;
} spring_ctx;

static void spring_fn(void *vctx, double t, double out[3])
{
    spring_ctx *g = vctx;
    double d, dd, ddd;
    edr_spring_at(g->r, g->c, g->j, t, &d, &dd, &ddd);
    if (g->ph == 0.0) {
        double z = d - g->up;
        out[0] = (z - g->uy) * (z + g->uy);
        out[1] = 2.0 * z * dd;
        out[2] = 2.0 * (dd * dd + z * ddd);
        return;
    }
    /* the drift's jerk: its dofs' */
    const pd_edr *r = g->r;
    double jerk = r->tp.sp_sig[g->j] * edr_dof_jerk(g->r, g->c, r->tp.sp_dof[g->j], t);
    if (r->tp.sp_dof2[g->j] >= 0)
        jerk += r->tp.sp_sig2[g->j] * edr_dof_jerk(g->r, g->c, r->tp.sp_dof2[g->j], t);
    out[0] = -g->ph * dd;
    out[1] = -g->ph * ddd;
    out[2] = -g->ph * jerk;
}

/* Spring j's next onset or unloading after ts, or the end of its scan
 * window (as predict_contact's windows). */
static void predict_spring(pd_edr *r, int j, double ts, int cont)
{
    int slot = r->rs.slot_spring0 + j, c = cl_of_dof(r, r->tp.sp_dof[j]);
    const edr_cluster *cl = &r->rs.cl[c];
    if (cl->kind == EDR_REST) { /* held still: no drift changes (its release re-predicts) */
        q_set(&r->rs.q, slot, HUGE_VAL);
        return;
    }
    spring_ctx g = {.r = r,
                    .c = c,
                    .j = j,
                    .up = r->rs.sp_up[j],
                    .uy = r->tp.md->uy[j],
                    .ph = r->rs.sp_phase[j]};
    /* rounding levels: of z^2 - uy^2 (z = d - up rounds with the size of d
     * and up: an offset far beyond uy, a drift of a flight's modal sums), or
     * of the drift's rate */
    double d, dd, ddd;
    edr_spring_at(r, c, j, ts, &d, &dd, &ddd);
    double thr = g.ph == 0.0 ? EDR_GAP_ROUND * g.uy * (g.uy + fabs(d) + fabs(g.up))
                             : EDR_RATE_TOL * fmax(r->rs.vscale, fabs(dd));
    edr_scan s = {
        .fn = spring_fn, .ctx = &g, .hit_mode = 1, .thr = thr, .fmax = -HUGE_VAL, .fmin = HUGE_VAL};
    double h = cl->h, tw = window_end(r, slot, cont, ts, h);
    s.width = 4e-8 * h;
    /* at the start f <= 0 but for rounding below thr: a slide moves toward its
     * side there (the origin's decision), an elastic spring is inside its
     * level or on it (an onset or an unloading put it there) */
    scan_window(r, slot, &s, edr_scan_point(&s, ts), h, tw);
}

/* The springs of cluster c predicted again from ts. */
static void predict_cluster_springs(pd_edr *r, int c, double ts)
{
    for (int b = r->rs.cl[c].head; b >= 0 && r->tp.ns > 0; b = r->rs.blk_next[b])
        for (int k = 0; k < r->tp.blk[b].nsp; k++)
            predict_spring(r, r->tp.blk_sp[r->tp.blk[b].sp0 + k], ts, 0);
}

/* ---- measurements ----------------------------------------------------------------- */

typedef struct meas_ctx {
    pd_edr *r;
    int c, dof, below; /* below >= 0: the drift x_dof - x_below */
} meas_ctx;

static void meas_fn(void *vctx, double t, double out[3])
{
    meas_ctx *m = vctx;
    double dx, v, a;
    /* x = xo + dx, v, a of the dof; of the drift x_dof - x_below, their differences */
    edr_dof_at(m->r, m->c, m->dof, t, &dx, &v, &a);
    out[0] = m->r->rs.xo[m->dof] + dx;
    out[1] = v;
    out[2] = a;
    if (m->below >= 0) {
        edr_dof_at(m->r, m->c, m->below, t, &dx, &v, &a);
        out[0] -= m->r->rs.xo[m->below] + dx;
        out[1] -= v;
        out[2] -= a;
    }
}

/* Note f's extremes into the dof's results (x, or the drift). */
static void note_meas(pd_edr *r, int dof, int drift, double fmax, double fmin)
{
    /* the drift's largest magnitude; x's largest excursions either way,
     * xpos = max x and xneg = max (-x) */
    if (drift) {
        r->rs.drift[dof] = pd_max(r->rs.drift[dof], pd_max(fmax, -fmin));
        return;
    }
    r->rs.xpos[dof] = pd_max(r->rs.xpos[dof], fmax);
    r->rs.xneg[dof] = pd_max(r->rs.xneg[dof], -fmin);
}

/* The below-dof of dof i for the drift, if it lies in the same cluster
 * (storeys of one structure always do); -1 for the ground. */
static int below_of(const pd_edr *r, int i)
{
    return r->tp.o.below ? r->tp.o.below[i] : -1;
}

/* The coordinate y of an SDOF tree (x_i = s_i y + d_i). */
static void tree_y_fn(void *vctx, double t, double out[3])
{
    meas_ctx *m = vctx;
    edr_cluster *cl = &m->r->rs.cl[m->c];
    /* y = y0 + dy: the tree's one coordinate (every x_i = s_i y + d_i) */
    edr_cluster_eval(m->r, m->c, t);
    out[0] = cl->y0 + cl->dy;
    out[1] = cl->vy;
    out[2] = cl->ay;
}

/* Scan the functions mc[0..nf) of cluster c over [ta, tb] on its grid into
 * sc (their extremes). */
static void scan_functions(pd_edr *r, edr_cluster *cl, int nf, meas_ctx *mc, edr_fn fn, double ta,
                           double tb)
{
    edr_scan *sc = r->ev.mscan;
    edr_pt *prev = r->ev.mprev;
    /* each function from ta, its value there noted (the extremes include the start) */
    for (int k = 0; k < nf; k++) {
        sc[k] = (edr_scan){.fn = fn,
                           .ctx = &mc[k],
                           .width = 4e-8 * cl->h,
                           .hit_mode = 0,
                           .fmax = -HUGE_VAL,
                           .fmin = HUGE_VAL};
        prev[k] = edr_scan_point(&sc[k], ta);
        edr_scan_note(&sc[k], prev[k].f);
    }
    /* held still (REST): constant, its value at ta is all */
    if (cl->kind == EDR_REST || !(tb > ta))
        return;
    /* the cluster's grid, every function interval by interval (the last ends
     * at tb); an interval notes its interior extrema and its end */
    long n = (long)ceil((tb - ta) / cl->h);
    if (n < 1)
        n = 1;
    for (long i = 1; i <= n; i++) {
        double t = i == n ? tb : ta + (double)i * cl->h, hit;
        if (!(t > prev[0].t))
            break;
        for (int k = 0; k < nf; k++) {
            edr_pt p = edr_scan_point(&sc[k], t);
            edr_scan_interval(&sc[k], &prev[k], &p, &hit);
            prev[k] = p;
        }
    }
}

/* Extremes of every dof (and drift) of cluster c over [meas_t, tb]: an
 * SDOF tree through its coordinate y (each x_i = s_i y + d_i takes its
 * extremes with y's), a modal cluster dof by dof, the drift of a storey
 * above the first as its own function. */
static void measure_cluster(pd_edr *r, int c, double tb)
{
    edr_cluster *cl = &r->rs.cl[c];
    /* extremes count from t_measure on; meas_t: measured up to there */
    double ta = fmax(cl->meas_t, r->tp.o.t_measure);
    cl->meas_t = fmax(cl->meas_t, tb);
    if (!(tb >= ta))
        return;
    meas_ctx *mc = r->ev.mctx;
    edr_scan *sc = r->ev.mscan;
    if (cl->kind != EDR_MODAL) {
        /* one scan of y: x_i = s_i y + d_i is monotone in y, its extremes
         * s_i y_max + d_i and s_i y_min + d_i (swapped where s_i < 0); each block
         * one dof, its structure's drift over the ground is its x */
        mc[0] = (meas_ctx){.r = r, .c = c, .dof = -1, .below = -1};
        scan_functions(r, cl, 1, mc, tree_y_fn, ta, tb);
        for (int b = cl->head; b >= 0; b = r->rs.blk_next[b]) {
            int i = r->tp.blk_dofs[r->tp.blk[b].first];
            double si = r->rs.s[i], hi = si * (si > 0.0 ? sc[0].fmax : sc[0].fmin) + r->rs.d[i];
            double lo = si * (si > 0.0 ? sc[0].fmin : sc[0].fmax) + r->rs.d[i];
            note_meas(r, i, 0, hi, lo);
            note_meas(r, i, 1, hi, lo);
        }
        return;
    }
    /* modal: each dof's x and, above storey 1, its drift x_i - x_below as a
     * function of its own (a difference's extremes are not the extremes'
     * differences) */
    int nf = 0;
    for (int b = cl->head; b >= 0; b = r->rs.blk_next[b]) {
        const edr_block *bk = &r->tp.blk[b];
        for (int k = 0; k < bk->n; k++) {
            int i = r->tp.blk_dofs[bk->first + k], bl = below_of(r, i);
            mc[nf++] = (meas_ctx){.r = r, .c = c, .dof = i, .below = -1};
            if (bl >= 0)
                mc[nf++] = (meas_ctx){.r = r, .c = c, .dof = i, .below = bl};
        }
    }
    scan_functions(r, cl, nf, mc, meas_fn, ta, tb);
    for (int k = 0; k < nf; k++) {
        note_meas(r, mc[k].dof, mc[k].below >= 0, sc[k].fmax, sc[k].fmin);
        if (mc[k].below < 0 && below_of(r, mc[k].dof) < 0) /* storey 1: the drift is x */
            note_meas(r, mc[k].dof, 1, sc[k].fmax, sc[k].fmin);
    }
}

/* The smallest gap of contact a over [gmeas_t, tb] (contacts that never
 * closed: once closed, the minimum is 0). */
static void measure_contact(pd_edr *r, int a, double tb)
{
    double ta = r->rs.gmeas_t[a];
    r->rs.gmeas_t[a] = fmax(ta, tb);
    /* open contacts that never closed: once closed the minimum is 0 (an
     * inactive contact never closes: its gap is measured throughout) */
    if (!(tb > ta) || (!(r->rs.gmin[a] > 0.0) && !r->tp.o.inactive) || r->rs.cstate[a] != EDR_OPEN)
        return;
    gap_ctx g;
    gap_base(r, a, &g);
    edr_scan s = {.fn = gap_fn, .ctx = &g, .hit_mode = 0, .fmax = -HUGE_VAL, .fmin = HUGE_VAL};
    double h = contact_step(r, a);
    s.width = 4e-8 * h;
    edr_pt p = edr_scan_point(&s, ta);
    edr_scan_note(&s, p.f);
    /* f = -g on the contact's grid: the largest f is the smallest gap */
    long n = (long)ceil((tb - ta) / h);
    for (long i = 1; i <= n; i++) {
        double t = i == n ? tb : ta + (double)i * h, hit;
        if (!(t > p.t))
            break;
        edr_pt b = edr_scan_point(&s, t);
        edr_scan_interval(&s, &p, &b, &hit);
        p = b;
    }
    double gmin = -s.fmax;
    /* an active contact below zero (a closing is located at the first double
     * past zero): its penetration recorded, the minimum taken as 0 */
    if (gmin < 0.0 && !r->tp.o.inactive) {
        r->rs.res.max_penetration = fmax(r->rs.res.max_penetration, -gmin);
        gmin = 0.0;
    }
    r->rs.gmin[a] = fmin(r->rs.gmin[a], gmin);
}

/* ---- the group of an event ---------------------------------------------------------- */

static void group_add_cluster(pd_edr *r, int c)
{
    /* once per event: cl_mark holds the epoch of the event that took it */
    if (r->ev.cl_mark[c] == r->ev.epoch)
        return;
    r->ev.cl_mark[c] = r->ev.epoch;
    r->ev.g_cl[r->ev.ng++] = c;
}

static void group_add_contact(pd_edr *r, int a)
{
    r->ev.ct_mark[a] = r->ev.epoch;
    /* no jumped tail yet: regroup reads one only where decide_persistence set it */
    r->ev.held_tail[r->ev.ngc] = 0.0;
    r->ev.g_ct[r->ev.ngc++] = a;
}

/* The group at t: from the clusters already in it, every contact at zero
 * gap (within the tolerance) and the cluster on its other side.  Seeds
 * (contacts already in g_ct) count as closed. */
static void group_grow(pd_edr *r, double t)
{
    double tol = r->tp.o.close_tol * r->rs.L;
    /* breadth first: ng grows as clusters join, each one searched in turn */
    for (int i = 0; i < r->ev.ng; i++) {
        const edr_cluster *cl = &r->rs.cl[r->ev.g_cl[i]];
        for (int b = cl->head; b >= 0; b = r->rs.blk_next[b]) {
            const edr_block *bk = &r->tp.blk[b];
            for (int k = 0; k < bk->ncont; k++) {
                int a = r->tp.blk_cont[bk->cont0 + k];
                if (r->ev.ct_mark[a] == r->ev.epoch || r->ev.ct_mark2[a] == r->ev.epoch)
                    continue;
                /* each contact looked at once per event (ct_mark2), taken once (ct_mark) */
                r->ev.ct_mark2[a] = r->ev.epoch;
                /* persistent and locked contacts are closed by definition; their
                 * sides lie in this cluster already (or at a wall) */
                if (r->rs.cstate[a] != EDR_OPEN) {
                    group_add_contact(r, a);
                    continue;
                }
                if (r->tp.o.inactive)
                    continue;
                double g = gap_now(r, a, t, NULL);
                if (!(g <= tol))
                    continue;
                group_add_contact(r, a);
                /* tol_closed: closed at a gap that the model's own g0 leaves positive */
                r->rs.res.tol_closed +=
                    g + (r->tp.md->g0[a] - r->tp.ct[a].g0) > 0.0; /* the gap given */
                /* its sides' clusters join: their contacts are searched in turn */
                const edr_contact *ct = &r->tp.ct[a];
                for (int s = 0; s < 2; s++)
                    if (ct->dof[s] >= 0)
                        group_add_cluster(r, cl_of_dof(r, ct->dof[s]));
            }
        }
    }
}

/* A node of flight_quadrature: t and its weight. */
typedef void (*quad_node_fn)(pd_edr *r, int c, double t, double weight, void *ctx);

/* int over [ta, tb] of cluster c's flight: 5-point Gauss-Legendre on n
 * pieces of width w no wider than the scan step (a fraction of the flight's
 * shortest period and of the piece's), on each int f = (w / 2) sum_k wg_k
 * f(mid + (w / 2) xg_k), exact for polynomials of degree up to 9: node(t,
 * weight) at each node.  The cache and the evaluation count are left as
 * they were, so the run is unchanged. */
static void flight_quadrature(pd_edr *r, int c, double ta, double tb, quad_node_fn node, void *ctx)
{
    static const double xg[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                 0.9061798459386640};
    static const double wg[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                 0.4786286704993665, 0.2369268850561891};
    edr_cluster *cl = &r->rs.cl[c];
    long evals = r->rs.evals;
    int cached = cl->cached;
    double tc = cl->tc;
    double h = cl->h > 0.0 ? cl->h : tb - ta;
    long n = (long)ceil((tb - ta) / h);
    if (n < 1)
        n = 1;
    double w = (tb - ta) / (double)n;
    for (long i = 0; i < n; i++) {
        double mid = ta + ((double)i + 0.5) * w;
        for (int k = 0; k < 5; k++)
            node(r, c, mid + 0.5 * w * xg[k], 0.5 * w * wg[k], ctx);
    }
    /* the cache back at tc, where the run left it */
    if (cached)
        edr_cluster_eval(r, c, tc);
    r->rs.evals = evals;
}

/* The held contacts' forces at t into the sampled impulses. */
static void held_node(pd_edr *r, int c, double t, double weight, void *ctx)
{
    (void)ctx;
    for (int a = r->rs.cl[c].pers_head; a >= 0; a = r->rs.pers_next[a])
        r->rs.imp_out[a] += weight * edr_force_at(r, c, a, t);
}

/* The held contacts' forces of cluster c integrated from its imp_t to tb
 * into the sampled impulses (imp_out), exact to rounding for the smooth
 * closed-form force.  Locked contacts (a cycle's redundant edge) have no
 * force of their own and are left out.  Only for a sampler. */
static void integrate_held(pd_edr *r, int c, double tb)
{
    edr_cluster *cl = &r->rs.cl[c];
    double ta = cl->imp_t;
    /* no sampler, no held contact or nothing to integrate: only the mark moves */
    cl->imp_t = fmax(ta, tb);
    if (r->rs.sample_forces && cl->pers_head >= 0 && tb > ta)
        flight_quadrature(r, c, ta, tb, held_node, NULL);
}

/* The input and damping powers at t, (b f) . v and v^T C v, into the
 * balance's integrals. */
static void energy_node(pd_edr *r, int c, double t, double weight, void *ctx)
{
    edr_cluster *cl = &r->rs.cl[c];
    double *v = ctx, pin = 0.0, pd = 0.0; /* v by global dof (the cluster's entries) */
    for (int b = cl->head; b >= 0; b = r->rs.blk_next[b]) {
        const edr_block *bk = &r->tp.blk[b];
        const double *Cb = r->tp.Cb + r->tp.blk_off[b];
        for (int l = 0; l < bk->n; l++) {
            int gi = r->tp.blk_dofs[bk->first + l];
            double dx, a;
            edr_dof_at(r, c, gi, t, &dx, &v[gi], &a);
            pin += r->tp.b[gi] * v[gi];
        }
        for (int l = 0; l < bk->n; l++) /* v^T C_b v, C_b column-major */
            for (int m = 0; m < bk->n; m++)
                pd += v[r->tp.blk_dofs[bk->first + l]] * Cb[l + (long)m * bk->n] *
                      v[r->tp.blk_dofs[bk->first + m]];
    }
    r->rs.e_input += weight * edr_force(r, cl->piece, t) * pin;
    r->rs.e_damping += weight * pd;
}

/* The energy balance's integrals over cluster c's flight from its en_t to
 * tb: input int (b f) . v dt and damping int v^T C v dt (opts.energy). */
static void integrate_energy(pd_edr *r, int c, double tb)
{
    edr_cluster *cl = &r->rs.cl[c];
    double ta = cl->en_t;
    cl->en_t = fmax(ta, tb);
    if (r->tp.o.energy && tb > ta)
        flight_quadrature(r, c, ta, tb, energy_node, r->ev.wk);
}

/* v^T M v / 2 over the listed dofs of the velocities v (global index). */
static double kinetic_of(const pd_edr *r, const int *dofs, int nd, const double *v)
{
    double ke = 0.0;
    for (int k = 0; k < nd; k++)
        ke += 0.5 * v[dofs[k]] * v[dofs[k]] / r->tp.minv[dofs[k]];
    return ke;
}

/* The state at t of every dof of the group (gx, gv), measured flights. */
static void group_state(pd_edr *r, double t)
{
    r->ev.ngd = 0;
    for (int i = 0; i < r->ev.ng; i++) {
        int c = r->ev.g_cl[i];
        /* held forces integrated and extremes measured up to t, before the
         * flights change at t */
        integrate_held(r, c, t);
        integrate_energy(r, c, t);
        measure_cluster(r, c, t);
        for (int b = r->rs.cl[c].head; b >= 0; b = r->rs.blk_next[b]) {
            const edr_block *bk = &r->tp.blk[b];
            for (int k = 0; k < bk->n; k++) {
                int dof = r->tp.blk_dofs[bk->first + k];
                double acc;
                dof_state(r, dof, t, &r->ev.gx[dof], &r->ev.gv[dof], &acc);
                r->ev.g_dof[r->ev.ngd++] = dof;
            }
            for (int k = 0; k < bk->ncont; k++) /* the gaps about to change flights */
                measure_contact(r, r->tp.blk_cont[bk->cont0 + k], t);
        }
    }
    if (r->tp.o.energy) /* before the event: its losses are what the new flights lack */
        r->rs.ke_group = kinetic_of(r, r->ev.g_dof, r->ev.ngd, r->ev.gv);
}

/* ---- the contact LCPs ----------------------------------------------------------------- */

/* D = W_I^T M^-1 W_I over the contacts idx[0..k): dense (k <= EDR_DENSE_MAX) or CSC. */
static pd_matrix delassus(pd_edr *r, const int *idx, int k)
{
    /* pos_in: each contact's row and column in D */
    for (int j = 0; j < k; j++)
        r->ev.pos_in[idx[j]] = j;
    if (k <= EDR_DENSE_MAX) {
        /* column j: D_aj = sum over the dofs i of contact j of w_ai w_ji / m_i,
         * a running over the contacts of idx at dof i (marked by ct_markD) */
        double *D = r->ev.Dd;
        memset(D, 0, (size_t)k * k * sizeof(double));
        for (int j = 0; j < k; j++) {
            const edr_contact *cj = &r->tp.ct[idx[j]];
            for (int s = 0; s < 2; s++) {
                int dof = cj->dof[s];
                if (dof < 0)
                    continue;
                for (int e = r->tp.dofc_ptr[dof]; e < r->tp.dofc_ptr[dof + 1]; e++) {
                    int a = r->tp.dofc[e];
                    if (r->ev.ct_markD[a] != r->ev.epochD)
                        continue;
                    const edr_contact *ca = &r->tp.ct[a];
                    double wa = ca->dof[0] == dof ? ca->w[0] : ca->w[1];
                    D[r->ev.pos_in[a] + (size_t)j * k] += wa * cj->w[s] * r->tp.minv[dof];
                }
            }
        }
        return pd_matrix_dense(k, k, D);
    }
    /* compressed: the same sums, each column's rows gathered as met (a row
     * met at both of j's dofs summed into one entry) */
    int nz = 0;
    for (int j = 0; j < k; j++) {
        const edr_contact *cj = &r->tp.ct[idx[j]];
        r->ev.Dcol[j] = nz;
        int start = nz;
        for (int s = 0; s < 2; s++) {
            int dof = cj->dof[s];
            if (dof < 0)
                continue;
            for (int e = r->tp.dofc_ptr[dof]; e < r->tp.dofc_ptr[dof + 1]; e++) {
                int a = r->tp.dofc[e];
                if (r->ev.ct_markD[a] != r->ev.epochD)
                    continue;
                const edr_contact *ca = &r->tp.ct[a];
                double wa = ca->dof[0] == dof ? ca->w[0] : ca->w[1];
                int row = r->ev.pos_in[a], f = -1;
                for (int p = start; p < nz && f < 0; p++)
                    if (r->ev.Drow[p] == row)
                        f = p;
                if (f < 0) {
                    r->ev.Drow[nz] = row;
                    r->ev.Dval[nz++] = 0.0;
                    f = nz - 1;
                }
                r->ev.Dval[f] += wa * cj->w[s] * r->tp.minv[dof];
            }
        }
        for (int p = start + 1; p < nz; p++) /* sort the column's rows */
            for (int q = p; q > start && r->ev.Drow[q - 1] > r->ev.Drow[q]; q--) {
                int ti = r->ev.Drow[q];
                double tv = r->ev.Dval[q];
                r->ev.Drow[q] = r->ev.Drow[q - 1];
                r->ev.Dval[q] = r->ev.Dval[q - 1];
                r->ev.Drow[q - 1] = ti;
                r->ev.Dval[q - 1] = tv;
            }
    }
    r->ev.Dcol[k] = nz;
    return pd_matrix_csc(k, k, r->ev.Dcol, r->ev.Drow, r->ev.Dval);
}

/* Solve the LCP D z + q over idx[0..k) into z (w = D z + q). */
/* The LCP (D, q) posed on unit diagonal, when pivoting on D failed (masses
 * of many decades: D's entries span them):  z = S z', w = S^-1 w',
 * (S D S) z' + S q = w', S = diag(D_jj^-1/2) (positive: complementarity
 * kept). */
static int scaled_lcp(pd_edr *r, pd_lcp_solver *solver, pd_matrix *D, int k, const double *q,
                      const pd_lcp_opts *lo, double *z, double *w, pd_lcp_info *info)
{
    double *sc = r->ev.lcp_scale, *qs = r->ev.lcp_q;
    /* S_jj = D_jj^-1/2 (a diagonal not > 0 cannot be scaled: PD_ENUMERICAL) */
    for (int j = 0; j < k; j++) {
        double d = 0.0;
        if (D->kind == PD_MATRIX_DENSE)
            d = D->values[j + (size_t)j * k];
        else
            for (int p = D->colptr[j]; p < D->colptr[j + 1]; p++)
                d = D->rowind[p] == j ? D->values[p] : d;
        if (!(d > 0.0))
            return PD_ENUMERICAL;
        sc[j] = 1.0 / sqrt(d);
        qs[j] = sc[j] * q[j];
    }
    /* D <- S D S in place, entry by entry */
    double *val = (double *)D->values; /* delassus()'s: r->ev.Dd or r->ev.Dval, formed per solve */
    for (int j = 0; j < k; j++) {
        if (D->kind == PD_MATRIX_DENSE)
            for (int i = 0; i < k; i++)
                val[i + (size_t)j * k] *= sc[i] * sc[j];
        else
            for (int p = D->colptr[j]; p < D->colptr[j + 1]; p++)
                val[p] *= sc[D->rowind[p]] * sc[j];
    }
    int rc = pd_lcp_solve(solver, D, qs, lo, z, w, info);
    if (rc) {
        /* a closed loop (a row touching wall to wall, or with a body whose
         * rows D barely tells apart): D singular and q a rounding outside its
         * range; D + EDR_LCP_SHIFT I (on unit diagonal) has one answer, the
         * forces' error of the shift's order */
        for (int j = 0; j < k; j++) {
            if (D->kind == PD_MATRIX_DENSE)
                val[j + (size_t)j * k] += EDR_LCP_SHIFT;
            else
                for (int p = D->colptr[j]; p < D->colptr[j + 1]; p++)
                    val[p] += D->rowind[p] == j ? EDR_LCP_SHIFT : 0.0;
        }
        rc = pd_lcp_solve(solver, D, qs, lo, z, w, info);
        for (int j = 0; j < k && !rc; j++) /* w of D itself */
            w[j] -= EDR_LCP_SHIFT * z[j];
    }
    /* back from the scaled problem: z = S z', w = S^-1 w' */
    for (int j = 0; j < k && !rc; j++) {
        z[j] *= sc[j];
        w[j] /= sc[j];
    }
    return rc;
}

static int solve_lcp(pd_edr *r, const int *idx, int k, const double *q, double *z, double *w,
                     double t, pd_err *err)
{
    if (k == 0)
        return PD_OK;
    /* ct_markD: the contacts of idx, for delassus() to find them at each dof */
    r->ev.epochD++;
    for (int j = 0; j < k; j++)
        r->ev.ct_markD[idx[j]] = r->ev.epochD;
    pd_matrix D = delassus(r, idx, k);
    r->rs.res.lcp_solves++;
    /* one contact: z = -q / D where q < 0, else 0 */
    if (k == 1) {
        z[0] = pd_contact_impulse_1(D.values[0], q[0]);
        w[0] = D.values[0] * z[0] + q[0];
        return PD_OK;
    }
    /* a warm start: every contact pushing (stages move a whole cluster,
     * held forces keep it together), so that pivoting starts near the answer */
    pd_lcp_opts lo = pd_lcp_default_opts();
    memset(r->ev.guess, 1, (size_t)k);
    lo.guess = r->ev.guess;
    pd_lcp_info info;
    int rc = pd_lcp_solve(r->ev.solver, &D, q, &lo, z, w, &info);
    /* pivoting failed (masses of many decades): posed again on unit diagonal */
    if (rc)
        rc = scaled_lcp(r, r->ev.solver, &D, k, q, &lo, z, w, &info);
    if (rc)
        return pd_err_set(err, rc,
                          "row reference: the contact LCP of %d contacts at t = %.9g s "
                          "was not solved (%s)",
                          k, t * r->tp.o.time_unit, pd_lcp_outcome_name(info.outcome));
    return PD_OK;
}

/* Spring j's offset force on dof i, ks s_ji up with up from the dofs'
 * positions x (konst; sliding: up = d(x) - ph uy), or its rate from their
 * velocities x (!konst: a slide's d(x), an elastic spring's 0). */
static double spring_offset_force(const pd_edr *r, int j, int i, const double *x, int konst)
{
    double sij = r->tp.sp_dof[j] == i    ? r->tp.sp_sig[j]
                 : r->tp.sp_dof2[j] == i ? r->tp.sp_sig2[j]
                                         : 0.0;
    int ph = r->rs.sp_phase[j];
    if (sij == 0.0 || (!konst && ph == 0))
        return 0.0;
    double up =
        ph == 0 ? r->rs.sp_up[j] : edr_spring_drift(r, j, x) - (konst ? ph * r->tp.md->uy[j] : 0.0);
    return r->tp.md->ks[j] * sij * up;
}

/* out = M^-1 (b f - C v - K x) over the group's dofs (global index): the
 * free accelerations from (x, v) = (gx, gv) and f(t), the free jerks from
 * (v, a) and f'(t). */
static void group_rhs(pd_edr *r, double f, const double *x, const double *v, int konst, double *out)
{
    for (int k = 0; k < r->ev.ngd; k++) {
        int i = r->ev.g_dof[k], b = r->tp.dof_blk[i];
        const edr_block *bk = &r->tp.blk[b];
        /* an SDOF block: (b f - c v - k_eff x - r0) / m, its spring's phase in
         * k_eff and r0 (k and 0 without one: the same bits), r0 dropped from
         * the jerks */
        if (bk->sdof) {
            double keff, r0;
            edr_block_stiffness(r, b, &keff, &r0);
            out[i] = (bk->b * f - bk->c * v[i] - keff * x[i] - (konst ? r0 : 0.0)) * r->tp.minv[i];
            continue;
        }
        /* a block: row li of b f - C v - K x over its dofs (C, K column-major at
         * blk_off), then 1 / M_ii */
        int li = r->tp.dof_loc[i];
        long off = r->tp.blk_off[b];
        double s = r->tp.b[i] * f;
        for (int jj = 0; jj < bk->n; jj++) {
            int gj = r->tp.blk_dofs[bk->first + jj];
            s -= r->tp.Cb[off + li + (long)jj * bk->n] * v[gj] +
                 r->tp.Kb[off + li + (long)jj * bk->n] * x[gj];
        }
        for (int l = 0; l < bk->nsp; l++) /* its yielding springs' offsets: + S ks up */
            s += spring_offset_force(r, r->tp.blk_sp[bk->sp0 + l], i, x, konst);
        out[i] = s * r->tp.minv[i];
    }
}

/* Free accelerations M^-1 (b f - C v - K x) of the group's dofs at t. */
static void free_accelerations(pd_edr *r, double t)
{
    group_rhs(r, edr_force(r, edr_piece_at(r, t), t), r->ev.gx, r->ev.gv, 1, r->ev.gacc);
}

/* The free jerks of the group's dofs into r->ev.gtmp, from the free
 * accelerations r->ev.gacc:  j = M^-1 (b f'(t) - C a - K v). */
static void free_jerks(pd_edr *r, double t)
{
    const pd_sine_piece *pc = &r->tp.pieces[edr_piece_at(r, t)];
    /* f'(t) = c1 + A w cos(w t + phi) on the piece at t */
    double df = pc->c1 + (pc->A == 0.0 ? 0.0 : pc->A * pc->w * cos(pc->w * t + pc->phi));
    group_rhs(r, df, r->ev.gv, r->ev.gacc, 0, r->ev.gtmp);
}

/* W_a^T y over the group's state array y (walls at rest). */
static double contact_dot(const pd_edr *r, int a, const double *y)
{
    const edr_contact *ct = &r->tp.ct[a];
    double s = 0.0;
    for (int k = 0; k < 2; k++)
        if (ct->dof[k] >= 0)
            s += ct->w[k] * y[ct->dof[k]];
    return s;
}

/* The contact-force LCP over J = idx[0..k): lambda (r->ev.lam), and the gap
 * accelerations of every closed contact of the group (r->ev.wlcp, indexed as
 * g_ct). */
static int reduced_force(pd_edr *r, const int *idx, int k, double t, pd_err *err);

static int force_lcp(pd_edr *r, const int *idx, int k, double t, pd_err *err)
{
    double *q = r->ev.qlcp, *lam = r->ev.lam, *w = r->ev.wtmp;
    /* on the clusters' coordinates when it can (0, or an error); 1: the dofs decide */
    int rr = reduced_force(r, idx, k, t, err);
    if (rr != 1)
        return rr;
    /* q_j = W_j^T a_free: the gap accelerations without contact forces, so that
     * 0 <= g'' = D lambda + q _|_ lambda >= 0 */
    for (int j = 0; j < k; j++)
        q[j] = contact_dot(r, idx[j], r->ev.gacc);
    int rc = solve_lcp(r, idx, k, q, lam, w, t, err);
    if (rc)
        return rc;
    /* gap accelerations of all closed contacts: W^T (a_free + M^-1 W_J lambda) */
    for (int k2 = 0; k2 < r->ev.ngd; k2++)
        r->ev.gtmp[r->ev.g_dof[k2]] = r->ev.gacc[r->ev.g_dof[k2]];
    for (int j = 0; j < k; j++) {
        const edr_contact *ct = &r->tp.ct[idx[j]];
        for (int s = 0; s < 2; s++)
            if (ct->dof[s] >= 0)
                r->ev.gtmp[ct->dof[s]] += ct->w[s] * lam[j] * r->tp.minv[ct->dof[s]];
    }
    for (int j = 0; j < r->ev.ngc; j++)
        r->ev.wlcp[j] = contact_dot(r, r->ev.g_ct[j], r->ev.gtmp);
    return PD_OK;
}

/* ---- clusters from the held contacts ----------------------------------------------------- */

static int uf_find(int *p, int x)
{
    while (p[x] != x) {
        /* path halving: each node on the way to its grandparent */
        p[x] = p[p[x]];
        x = p[x];
    }
    return x;
}

/* Dissolve the group's clusters and make new ones from the contacts
 * flagged held (r->ev.held), every dof starting at (gx, gv) at t. */
static int regroup(pd_edr *r, double t, pd_err *err)
{
    int *uf = r->ev.uf, rc;
    /* the union-find over the group's blocks: each its own root */
    for (int i = 0; i < r->ev.ng; i++) {
        int c = r->ev.g_cl[i];
        for (int b = r->rs.cl[c].head; b >= 0; b = r->rs.blk_next[b])
            uf[b] = b;
    }
    for (int j = 0; j < r->ev.ngc; j++) {
        int a = r->ev.g_ct[j];
        const edr_contact *ct = &r->tp.ct[a];
        /* in contact before: persistent, or locked in a cycle of held contacts */
        int was = r->rs.cstate[a] != EDR_OPEN;
        /* a persistent contact released: its time in contact since it was held */
        if (was && !r->ev.held[j])
            r->rs.ctime[a] += t - r->rs.since[a] > 0.0 ? t - r->rs.since[a] : 0.0;
        /* a contact's burst of impacts ends with a hold that lasted: one
         * released at once (a chatter through held states) bounces on */
        if (was && !r->ev.held[j] && t - r->rs.since[a] > EDR_HOLD_MIN)
            r->rs.burst[a] = 0;
        /* newly held: in contact from t, or from the end of a jumped accumulation's tail */
        if (r->ev.held[j] && !was)
            r->rs.since[a] = t + r->ev.held_tail[j];
        r->rs.cstate[a] = r->ev.held[j] ? EDR_PERSIST : EDR_OPEN;
        r->rs.pers_next[a] = -1;
        /* every closed contact's gap is exactly 0 at t (gap_base) */
        r->rs.base_t[a] = t;
        r->rs.base_g[a] = 0.0;
        /* a held contact between two blocks joins them; a wall joins nothing */
        if (r->ev.held[j] && ct->blk[0] >= 0 && ct->blk[1] >= 0) {
            int x = uf_find(uf, ct->blk[0]), y = uf_find(uf, ct->blk[1]);
            if (x != y)
                uf[x] = y;
        }
    }
    /* the new flights start from the group's state at t */
    for (int k = 0; k < r->ev.ngd; k++) {
        int i = r->ev.g_dof[k];
        r->rs.xo[i] = r->ev.gx[i];
        r->rs.vo[i] = r->ev.gv[i];
    }
    /* release the old clusters, collect the blocks */
    int nblk = 0;
    for (int i = 0; i < r->ev.ng; i++) {
        int c = r->ev.g_cl[i];
        for (int b = r->rs.cl[c].head, nx; b >= 0; b = nx) {
            nx = r->rs.blk_next[b];
            r->ev.gblk[nblk++] = b;
        }
        r->rs.cl[c].live = 0;
        r->rs.cl[c].head = -1;
        r->rs.free_cl[r->rs.nfree++] = c;
        q_set(&r->rs.q, r->tp.m + c, HUGE_VAL);
    }
    /* one cluster per root */
    r->ev.ng = 0;
    for (int k = 0; k < nblk; k++) {
        int b = r->ev.gblk[k];
        if (uf_find(uf, b) != b)
            continue;
        int c = r->rs.free_cl[--r->rs.nfree];
        edr_cluster *cl = &r->rs.cl[c];
        cl->live = 1;
        cl->head = -1;
        cl->nblk = 0;
        cl->pers_head = -1;
        cl->npers = 0;
        cl->meas_t = t;
        r->ev.newcl[b] = c;
        r->ev.g_cl[r->ev.ng++] = c;
    }
    for (int k = 0; k < nblk; k++) {
        /* every block into its root's cluster */
        int b = r->ev.gblk[k], c = r->ev.newcl[uf_find(uf, b)];
        r->rs.blk_cl[b] = c;
        r->rs.blk_next[b] = r->rs.cl[c].head;
        r->rs.cl[c].head = b;
        r->rs.cl[c].nblk++;
    }
    for (int j = 0; j < r->ev.ngc; j++) {
        int a = r->ev.g_ct[j];
        /* every held contact into the persistent list of its cluster */
        if (!r->ev.held[j])
            continue;
        const edr_contact *ct = &r->tp.ct[a];
        int c = r->rs.blk_cl[ct->blk[0] >= 0 ? ct->blk[0] : ct->blk[1]];
        r->rs.pers_next[a] = r->rs.cl[c].pers_head;
        r->rs.cl[c].pers_head = a;
        r->rs.cl[c].npers++;
    }
    for (int i = 0; i < r->ev.ng; i++)
        /* each new cluster's flight: an SDOF tree, a REST tree or modal */
        if ((rc = edr_cluster_start(r, r->ev.g_cl[i], t, err)))
            return rc;
    /* the kinetic energy the event took: the impacts', and what the held
     * contacts' starts projected away (forces are continuous) */
    if (r->tp.o.energy)
        r->rs.e_impact += r->rs.ke_group - kinetic_of(r, r->ev.g_dof, r->ev.ngd, r->rs.vo);
    return PD_OK;
}

/* Predictions of every contact next to the group (once each) and of its
 * clusters. */
static void repredict(pd_edr *r, double t)
{
    r->ev.epochP++;
    for (int i = 0; i < r->ev.ng; i++) {
        int c = r->ev.g_cl[i];
        for (int b = r->rs.cl[c].head; b >= 0; b = r->rs.blk_next[b]) {
            const edr_block *bk = &r->tp.blk[b];
            for (int k = 0; k < bk->ncont; k++) {
                int a = r->tp.blk_cont[bk->cont0 + k];
                /* once each: a contact between two of the group's clusters is met twice */
                if (r->ev.ct_markP[a] == r->ev.epochP)
                    continue;
                r->ev.ct_markP[a] = r->ev.epochP;
                predict_contact(r, a, t, 0);
            }
        }
        predict_detach(r, c, t, 0);
        predict_cluster_springs(r, c, t);
    }
}

/* ---- events --------------------------------------------------------------------- */

static int report(pd_edr *r, double t, pd_edr_kind kind, int acc)
{
    if (!r->tp.o.on_event)
        return 0;
    /* v+ and x of the group's dofs in g_dof order (v- was kept before the impact) */
    for (int k = 0; k < r->ev.ngd; k++) {
        r->ev.ev_vplus[k] = r->ev.gv[r->ev.g_dof[k]];
        r->ev.ev_x[k] = r->ev.gx[r->ev.g_dof[k]];
    }
    pd_edr_event ev = {.t = t,
                       .kind = kind,
                       .ncontacts = r->ev.ngc,
                       .contacts = r->ev.g_ct,
                       .P = r->ev.P,
                       .U_minus = r->ev.Uminus,
                       .U_plus = r->ev.Uplus,
                       .ndofs = r->ev.ngd,
                       .dofs = r->ev.g_dof,
                       .v_minus = r->ev.ev_vminus,
                       .v_plus = r->ev.ev_vplus,
                       .x = r->ev.ev_x,
                       .accumulation = acc};
    return r->tp.o.on_event(&ev, r->tp.o.on_event_ctx);
}

/* Count the event of queue slot `slot`; PD_EBUDGET past the budget, or
 * when one slot keeps firing at one instant (time stands still for it;
 * independent events at one instant, identical structures struck
 * together, are no stall). */
static int count_event(pd_edr *r, int slot, double t, pd_err *err)
{
    if (++r->rs.res.events > r->tp.o.max_events)
        return pd_err_set(err, PD_EBUDGET,
                          "row reference: %ld events by t = %.9g s (budget "
                          "exhausted)",
                          r->rs.res.events - 1, t * r->tp.o.time_unit);
    /* the same slot again at the same instant: time does not move for it */
    if (r->rs.slot_t[slot] == t) {
        if (++r->rs.slot_same[slot] > EDR_SAME_INSTANT)
            return pd_err_set(err, PD_EBUDGET,
                              "row reference: %d events at t = %.17g s without "
                              "progress",
                              EDR_SAME_INSTANT, t * r->tp.o.time_unit);
    } else {
        r->rs.slot_t[slot] = t;
        r->rs.slot_same[slot] = 0;
    }
    /* a chatter: EDR_CHATTER_EVENTS events of one slot within EDR_CHATTER_SPAN
     * (a Zeno sequence the accumulation jump did not end) */
    if (++r->rs.slot_run[slot] >= EDR_CHATTER_EVENTS) {
        if (t - r->rs.slot_t0[slot] < EDR_CHATTER_SPAN)
            return pd_err_set(err, PD_EBUDGET,
                              "row reference: %d events of one %s within %.3g "
                              "s at t = %.9g s: a chatter it cannot resolve (Moreau-Jean, "
                              "--method moreau, runs it)",
                              EDR_CHATTER_EVENTS, slot < r->tp.m ? "contact" : "cluster",
                              (t - r->rs.slot_t0[slot]) * r->tp.o.time_unit, t * r->tp.o.time_unit);
        r->rs.slot_run[slot] = 0;
        r->rs.slot_t0[slot] = t;
    }
    return PD_OK;
}

/* After the impact (or at a touch, a detachment, a piece change): which
 * closed contacts hold, accumulations jumped.  idx0 lists the candidates
 * (zero rate), k0 of them. */
static int decide_persistence(pd_edr *r, double t, int *acc_jumped, pd_err *err)
{
    int rc, k0 = 0, *idx = r->ev.lcp_idx;
    double vs = 0.0;
    *acc_jumped = 0;
    for (int k = 0; k < r->ev.ngd; k++)
        vs = fmax(vs, fabs(r->ev.gv[r->ev.g_dof[k]]));
    /* a rate is zero below EDR_RATE_TOL of the event's (and the run's) speeds */
    double tolU = EDR_RATE_TOL * fmax(vs, r->rs.vscale);
    /* the candidates: closed contacts at zero rate after the impact, the
     * detaching one excluded; jpos[j]: a contact's place in idx, or -1 */
    for (int j = 0; j < r->ev.ngc; j++) {
        r->ev.held[j] = 0;
        r->ev.held_tail[j] = 0.0;
        if (fabs(r->ev.Uplus[j]) <= tolU && !r->ev.excluded[j])
            idx[k0++] = r->ev.g_ct[j], r->ev.jpos[j] = k0 - 1;
        else
            r->ev.jpos[j] = -1;
    }
    /* the force LCP, 0 <= g'' = D lambda + W^T a_free _|_ lambda >= 0: a
     * positive force holds the contact */
    free_accelerations(r, t);
    if ((rc = force_lcp(r, idx, k0, t, err)))
        return rc;
    for (int j = 0; j < r->ev.ngc; j++)
        if (r->ev.jpos[j] >= 0)
            r->ev.held[j] = r->ev.lam[r->ev.jpos[j]] > 0.0;
    /* a contact at zero force and zero gap acceleration whose bodies are
     * still but accelerate (touching at rest under one ground motion, as at
     * the start) is held when the free gap's jerk closes it: its force
     * grows from zero.  Left open, its gap would
     * close as t^3 and bounce at ever smaller speeds, never reaching the
     * accumulation jump (no closing acceleration to bound the bounces). */
    int ties = 0;
    for (int j = 0; j < r->ev.ngc; j++) {
        const edr_contact *ct = &r->tp.ct[r->ev.g_ct[j]];
        double as = 0.0; /* its bodies' accelerations */
        for (int k = 0; k < 2; k++)
            if (ct->dof[k] >= 0)
                as = fmax(as, fabs(r->ev.gacc[ct->dof[k]]));
        r->ev.tie[j] = r->ev.jpos[j] >= 0 && !r->ev.held[j] && as > EDR_TIE_ACC * r->rs.L &&
                       !(fabs(r->ev.wlcp[j]) > EDR_RATE_TOL * as);
        ties |= r->ev.tie[j];
    }
    if (ties) {
        /* held when the free gap's jerk W^T j_free < 0 closes it */
        free_jerks(r, t);
        for (int j = 0; j < r->ev.ngc; j++)
            if (r->ev.tie[j])
                r->ev.held[j] = contact_dot(r, r->ev.g_ct[j], r->ev.gtmp) < 0.0;
    }
    if (r->tp.o.no_accumulation)
        return PD_OK;
    /* accumulations: contacts bouncing off with a tiny height under a closing acceleration */
    double tend = fmin(edr_piece_end(r, edr_piece_at(r, t)), r->rs.t1);
    int ns = 0, k1 = k0;
    for (int j = 0; j < r->ev.ngc; j++) {
        int a = r->ev.g_ct[j];
        double U = r->ev.Uplus[j], acl = -r->ev.wlcp[j], e = r->tp.ct[a].e;
        if (r->ev.jpos[j] >= 0 || r->ev.excluded[j] || !(U > 0.0) || !(e < 1.0) || !(acl > 0.0))
            continue;
        /* the next bounce's height U^2 / (2 a), and the time of all the bounces
         * left, sum_k 2 e^k U / a = 2 U / (a (1 - e)): the tail jumped */
        double height = U * U / (2.0 * acl), tail = 2.0 * U / (acl * (1.0 - e));
        if (height > EDR_ACC_HEIGHT * r->rs.L || !(t + tail < tend))
            continue;
        r->ev.held_tail[j] = tail;
        r->ev.jpos[j] = k1;
        idx[k1++] = a;
        ns++;
    }
    if (ns == 0)
        return PD_OK;
    /* the force LCP with the jumped contacts taken as at rest */
    if ((rc = force_lcp(r, idx, k1, t, err)))
        return rc;
    /* every jumped contact must push */
    int ok = 1;
    for (int j = 0; j < r->ev.ngc && ok; j++)
        if (r->ev.held_tail[j] > 0.0)
            ok = r->ev.lam[r->ev.jpos[j]] > 0.0;
    if (ok) {
        for (int j = 0; j < r->ev.ngc; j++)
            r->ev.held[j] = r->ev.jpos[j] >= 0 && r->ev.lam[r->ev.jpos[j]] > 0.0;
        /* the force must hold through the tail: try the clusters */
        *acc_jumped = 1;
        return PD_OK;
    }
    for (int j = 0; j < r->ev.ngc; j++) /* rejected: the force LCP of the resting ones */
        if (r->ev.held_tail[j] > 0.0) {
            r->ev.held_tail[j] = 0.0;
            r->ev.jpos[j] = -1;
        }
    if ((rc = force_lcp(r, idx, k0, t, err)))
        return rc;
    for (int j = 0; j < r->ev.ngc; j++)
        r->ev.held[j] = r->ev.jpos[j] >= 0 && r->ev.lam[r->ev.jpos[j]] > 0.0;
    return PD_OK;
}

/* The jumped contacts' forces at the middle and end of their tails, on
 * the new clusters: 1 when they hold. */
static int tails_hold(pd_edr *r)
{
    for (int j = 0; j < r->ev.ngc; j++) {
        double tail = r->ev.held_tail[j];
        if (!(tail > 0.0) || !r->ev.held[j])
            continue;
        int a = r->ev.g_ct[j],
            c = r->rs.blk_cl[r->tp.ct[a].blk[0] >= 0 ? r->tp.ct[a].blk[0] : r->tp.ct[a].blk[1]];
        /* not held after all (locked in a cycle): nothing to check */
        if (r->rs.cstate[a] != EDR_PERSIST)
            continue;
        /* lambda at the tail's middle and end on the new cluster's flight (from t0) */
        double t0 = r->rs.cl[c].t0;
        if (!(edr_force_at(r, c, a, t0 + 0.5 * tail) > 0.0) ||
            !(edr_force_at(r, c, a, t0 + tail) > 0.0))
            return 0;
    }
    return 1;
}

/* The restitution of closed contact j (g_ct index) in the next stage of
 * an impact: its own, until it has closed EDR_INSTANT_BOUNCES times at
 * this instant; then 0.  A contact that keeps closing again at one
 * instant (a row in an inelastic collapse, touching within the closing
 * tolerance) is in an accumulation at that instant: its bounces shrink
 * geometrically, stage after stage, toward zero relative velocity, which
 * is where a plastic stage takes it at once (as the one-wall reference
 * jumps a bouncing ball to rest).  Counted in r->ev.instant_acc. */
static double stage_e(pd_edr *r, int j)
{
    if (r->ev.nimp[j] < EDR_INSTANT_BOUNCES || r->tp.o.no_accumulation)
        return r->tp.ct[r->ev.g_ct[j]].e;
    r->ev.instant_acc = 1;
    return 0.0;
}

/* The small dense LCP  w = D z + q >= 0 _|_ z >= 0  of the clusters (k <=
 * EDR_REDUCED_MAX): closed forms for k <= 2 and Lemke beyond (a cluster
 * pinned between two held still makes D singular: Lemke takes it; when
 * pivoting fails, posed again on unit diagonal, then shifted: scaled_lcp). */
static int small_lcp(pd_edr *r, int k, const double *D, const double *q, double *z, double *w)
{
    pd_matrix Dm = pd_matrix_dense(k, k, D);
    int rc = pd_lcp_solve(r->ev.dsolver, &Dm, q, NULL, z, w, NULL);
    if (rc) { /* posed again on unit diagonal (then shifted), on a copy: D is refined on */
        memcpy(r->ev.Dlu, D, (size_t)k * k * sizeof(double));
        Dm = pd_matrix_dense(k, k, r->ev.Dlu);
        rc = scaled_lcp(r, r->ev.dsolver, &Dm, k, q, NULL, z, w, NULL);
    }
    return rc;
}

/* Commit an impact's totals: every closed contact's impulse (r->ev.P) and
 * impacts (r->ev.nimp, stages where it was closing). */
static int commit_impacts(pd_edr *r, double t, pd_err *err)
{
    for (int j = 0; j < r->ev.ngc; j++) {
        int a = r->ev.g_ct[j];
        /* imp_out: impulses since the last sample; maxP: the largest impact's impulse */
        r->rs.imp_out[a] += r->ev.P[j];
        r->rs.maxP[a] = pd_max(r->rs.maxP[a], r->ev.P[j]);
        /* pressed, never closing: no impact to count */
        if (!r->ev.nimp[j])
            continue;
        r->rs.impacts[a] += r->ev.nimp[j];
        r->rs.res.impacts += r->ev.nimp[j];
        if (isnan(r->rs.first[a]))
            r->rs.first[a] = t;
        if (isnan(r->rs.res.first_impact))
            r->rs.res.first_impact = t;
        /* burst: impacts since its last lasting hold; past max_burst the run is in
         * an accumulation it does not end */
        if ((r->rs.burst[a] += r->ev.nimp[j]) > r->tp.o.max_burst)
            return pd_err_set(err, PD_EBUDGET,
                              "row reference: accumulation of impacts of "
                              "contact %d at t = %.9g s: %ld impacts without a lasting persistent "
                              "contact%s (Moreau-Jean, --method moreau, runs it)",
                              a, t * r->tp.o.time_unit, r->rs.burst[a] - 1,
                              r->tp.o.no_accumulation ? " (accumulation handling is off)" : "");
    }
    return PD_OK;
}

/* q_x = 0 where |q_x| <= EDR_RATE_TOL max |q|: the single law's rates at
 * the rounding level of the impact (a contact resting in a row that
 * another one strikes) are zero, as event-general zeroes them, so that the
 * LCP does not chase their sign. */
static void single_law_zero(double *q, int k)
{
    double qmax = 0.0;
    for (int x = 0; x < k; x++)
        qmax = fmax(qmax, fabs(q[x]));
    for (int x = 0; x < k; x++)
        if (fabs(q[x]) <= EDR_RATE_TOL * qmax)
            q[x] = 0.0;
}

/* The impact at t, in stages: each takes the closed contacts whose rate
 * is not separating (U <= 0) into one LCP with Newton's law,
 *   w = D P + U + e min(U, 0),  0 <= w _|_ P >= 0,
 * so that every stage dissipates (the kinetic energy changes by
 * 1/2 sum P (U+ + U-) <= 0); a closed contact that was separating takes no
 * impulse, and if the others' impulses make it close it takes part in the
 * next stage at the same instant (as Moreau-Jean's active set leaves a
 * separating contact to the next step).  Stages end when no closed contact
 * closes.  The single law takes every closed contact, separating ones
 * included, into one LCP and ends there.  Totals in r->ev.P, r->ev.nimp. */
static int impact_stages(pd_edr *r, double t, double tolU, pd_err *err)
{
    int rc, *idx = r->ev.lcp_idx, stage = 0, single = r->tp.o.impact_law == PD_IMPACT_SINGLE;
    double *q = r->ev.qlcp, *z = r->ev.lam;
    for (;;) {
        int k = 0, closing = 0, pressing = 0, all = 0;
        for (int j = 0; j < r->ev.ngc; j++) {
            /* U = W_j^T v, zero at the rounding level of the event's speeds */
            double U = contact_dot(r, r->ev.g_ct[j], r->ev.gv);
            if (fabs(U) <= tolU)
                U = 0.0;
            all++;
            /* separating (staged law): no impulse in this stage; the others' impulses
             * may close it for the next */
            if (U > 0.0 && !single) {
                r->ev.jpos[j] = -1;
                continue;
            }
            closing += U < 0.0;
            pressing += U <= 0.0;
            r->ev.jpos[j] = k;
            idx[k] = r->ev.g_ct[j];
            /* Newton's law: w = D P + q = U+ + e min(U-, 0) */
            q[k++] = U + stage_e(r, j) * fmin(U, 0.0);
        }
        /* no closed contact closing: the impact is over */
        if (!closing)
            return PD_OK;
        /* law_multi: its first LCP could take several closed contacts */
        r->ev.law_multi |= stage == 0 && all > 1;
        if (++stage > EDR_STAGES)
            return pd_err_set(err, PD_EBUDGET,
                              "row reference: the impact at t = %.17g s did not "
                              "end in %d stages",
                              t * r->tp.o.time_unit, EDR_STAGES);
        if (single)
            single_law_zero(q, k);
        if ((rc = solve_lcp(r, idx, k, q, z, r->ev.wtmp, t, err)))
            return rc;
        r->rs.res.simultaneous += pressing > 1;
        /* v += M^-1 W_j P_j, the totals P; a stage where it closed is one impact */
        for (int j = 0; j < r->ev.ngc; j++) {
            if (r->ev.jpos[j] < 0)
                continue;
            double P = z[r->ev.jpos[j]];
            const edr_contact *ct = &r->tp.ct[r->ev.g_ct[j]];
            for (int s = 0; s < 2; s++)
                if (ct->dof[s] >= 0)
                    r->ev.gv[ct->dof[s]] += ct->w[s] * P * r->tp.minv[ct->dof[s]];
            r->ev.P[j] += P;
            r->ev.nimp[j] += q[r->ev.jpos[j]] < 0.0;
        }
        /* the single law: one LCP, no further stage */
        if (single)
            return PD_OK;
    }
}

/* sigma of contact a's side s: the rate of its gap per unit rate of the
 * side's cluster coordinate (w s_i for an SDOF tree, 0 held still). */
static double side_sigma(const pd_edr *r, int a, int s)
{
    int dof = r->tp.ct[a].dof[s];
    if (dof < 0)
        return 0.0;
    const edr_cluster *cl = &r->rs.cl[cl_of_dof(r, dof)];
    return cl->kind == EDR_SDOF ? r->tp.ct[a].w[s] * r->rs.s[dof] : 0.0;
}

/* 1 when contact a has a side whose cluster moves (an impulse on it does
 * something). */
static int movable(const pd_edr *r, int a)
{
    return side_sigma(r, a, 0) != 0.0 || side_sigma(r, a, 1) != 0.0;
}

/* r_x = q_x + sum_s sigma_xs G_c / mu_c, G_c = sum_y sigma_yc z_y the
 * stage's impulse on the cluster c of side s (D z without D), and
 * scale_x the sum of the magnitudes of its terms. */
static void reduced_residual(const pd_edr *r, const int *idx, int k, const double *q,
                             const double *z, double *res, double *scale)
{
    for (int x = 0; x < k; x++) {
        int a = r->ev.g_ct[idx[x]];
        /* sum: r_x; sc: its terms' magnitudes, the level of its rounding */
        double sum = q[x], sc = fabs(q[x]);
        for (int s = 0; s < 2; s++) {
            double sa = side_sigma(r, a, s);
            if (sa == 0.0)
                continue;
            int c = cl_of_dof(r, r->tp.ct[a].dof[s]);
            /* G_c = sum_y sigma_yc z_y: the stage's total impulse on cluster c */
            double G = 0.0;
            for (int y = 0; y < k; y++) {
                int b = r->ev.g_ct[idx[y]];
                for (int u = 0; u < 2; u++)
                    if (r->tp.ct[b].dof[u] >= 0 && cl_of_dof(r, r->tp.ct[b].dof[u]) == c)
                        G += side_sigma(r, b, u) * z[y];
            }
            double term = sa * (G / r->ev.cmu[c]);
            sum += term;
            sc += fabs(term);
        }
        res[x] = sum;
        scale[x] = sc;
    }
}

/* z_A -= D_AA^-1 r_A on the pushing contacts A = {z > 0}, r from
 * reduced_residual, while r shrinks: the entries of D lose a heavy
 * cluster's 1/mu under a light one's (D = W^T M^-1 W of condition up to
 * 1e13), and Lemke's z with them, while r keeps it.  Untouched when r_A
 * is at its rounding level; 1 when z was refined. */
static int refine_reduced(pd_edr *r, const int *idx, int k, const double *D, const double *q,
                          double *z)
{
    double *res = r->ev.rtmp, *scale = res + k, *zt = scale + k, *dz = zt + k;
    int *ax = r->ev.lu_perm + k, na = 0, trig = 0;
    /* A = {z > 0}, the pushing contacts (ax); refined only when some r_A
     * exceeds EDR_REFINE_TOL roundings of its terms */
    reduced_residual(r, idx, k, q, z, res, scale);
    for (int x = 0; x < k; x++)
        if (z[x] > 0.0) {
            ax[na++] = x;
            trig |= fabs(res[x]) > EDR_REFINE_TOL * DBL_EPSILON * scale[x];
        }
    if (!trig)
        return 0;
    /* D_AA, LU-factored (singular: Lemke's z stays) */
    for (int i = 0; i < na; i++)
        for (int j = 0; j < na; j++)
            r->ev.Dlu[i + (size_t)j * na] = D[ax[i] + (size_t)ax[j] * k];
    if (pd_dense_lu(na, r->ev.Dlu, na, r->ev.lu_perm, DBL_EPSILON))
        return 0;
    double norm = 0.0;
    for (int i = 0; i < na; i++)
        norm = fmax(norm, fabs(res[ax[i]]));
    int refined = 0;
    /* Newton steps z_A -= D_AA^-1 r_A, each kept while every z_A stays > 0
     * and the residual's largest entry falls */
    for (int it = 0; it < EDR_REFINE_MAX && norm > 0.0; it++) {
        for (int i = 0; i < na; i++)
            dz[i] = -res[ax[i]];
        pd_dense_lu_solve(na, r->ev.Dlu, na, r->ev.lu_perm, dz);
        int ok = 1;
        memcpy(zt, z, (size_t)k * sizeof(double));
        for (int i = 0; i < na; i++)
            ok &= (zt[ax[i]] += dz[i]) > 0.0;
        if (!ok)
            break; /* the pushing set would change: Lemke's */
        reduced_residual(r, idx, k, q, zt, res, scale);
        double nt = 0.0;
        for (int i = 0; i < na; i++)
            nt = fmax(nt, fabs(res[ax[i]]));
        if (!(nt < norm))
            break;
        memcpy(z, zt, (size_t)k * sizeof(double));
        norm = nt;
        refined = 1;
    }
    return refined;
}

/* What one stage's pass over the contacts between clusters found. */
typedef struct stage_set {
    int k;        /* its unknowns: the closed contacts not separating (all, single law) */
    int closing;  /* of them, closing (U < 0) */
    int pressing; /* at U <= 0 */
    int all;      /* closed contacts an impulse moves */
} stage_set;

/* The clusters' coordinates before the impact: eta_c = y_c' of an SDOF
 * tree (a REST tree is held still: 0), kept in cvy, and the masses
 * mu_c = sum s^2 m; the contacts between clusters into epos (*ne).  1 when
 * the group holds a modal cluster (no one coordinate). */
static int reduced_begin(pd_edr *r, double t, int *ne)
{
    for (int i = 0; i < r->ev.ng; i++) {
        edr_cluster *cl = &r->rs.cl[r->ev.g_cl[i]];
        if (cl->kind == EDR_MODAL)
            return 1;
        edr_cluster_eval(r, r->ev.g_cl[i], t); /* (the measurements moved the cache) */
        r->ev.ceta[r->ev.g_cl[i]] = cl->kind == EDR_SDOF ? cl->vy : 0.0;
        r->ev.cvy[r->ev.g_cl[i]] = r->ev.ceta[r->ev.g_cl[i]];
        r->ev.cmu[r->ev.g_cl[i]] = cl->mass;
    }
    /* the open ones: a persistent or locked contact lies inside a cluster
     * and moves with it (a tree edge's impulse follows from the balance) */
    *ne = 0;
    for (int j = 0; j < r->ev.ngc; j++)
        if (r->rs.cstate[r->ev.g_ct[j]] == EDR_OPEN)
            r->ev.epos[(*ne)++] = j;
    return 0;
}

/* One stage's unknowns idx[0..k) (g_ct indices) and q = U + e min(U, 0),
 * U = sum_s sigma_s eta_c(s) the contact's rate on the clusters'
 * coordinates; 1 when they exceed EDR_REDUCED_MAX. */
static int reduced_stage_set(pd_edr *r, int ne, double tolU, int single, stage_set *set)
{
    int *idx = r->ev.lcp_idx;
    double *q = r->ev.qlcp;
    *set = (stage_set){.k = 0, .closing = 0, .pressing = 0, .all = 0};
    for (int e = 0; e < ne; e++) {
        int j = r->ev.epos[e], a = r->ev.g_ct[j];
        double U = 0.0;
        for (int s = 0; s < 2; s++)
            if (r->tp.ct[a].dof[s] >= 0)
                U += side_sigma(r, a, s) * r->ev.ceta[cl_of_dof(r, r->tp.ct[a].dof[s])];
        if (fabs(U) <= tolU) /* a rate at the rounding of the event's speeds is zero */
            U = 0.0;
        if (!movable(r, a)) { /* held still on both sides */
            r->ev.jpos[j] = -1;
            continue;
        }
        set->all++;
        if (U > 0.0 && !single) { /* separating (staged) */
            r->ev.jpos[j] = -1;
            continue;
        }
        if (set->k >= EDR_REDUCED_MAX)
            return 1;
        set->closing += U < 0.0;
        set->pressing += U <= 0.0;
        r->ev.jpos[j] = set->k;
        idx[set->k] = j;
        /* Newton's law: w = U+ + e min(U-, 0) = D P + q */
        q[set->k++] = U + stage_e(r, j) * fmin(U, 0.0);
    }
    return 0;
}

/* The stage's Delassus matrix on the clusters' coordinates, D = W^T M^-1 W
 * with each tree rigid: D_xy = sum over the clusters c that x and y share
 * of sigma_xc sigma_yc / mu_c. */
static void reduced_delassus(pd_edr *r, const int *idx, int k, double *D)
{
    for (int x = 0; x < k; x++)
        for (int y = 0; y < k; y++) {
            int a = r->ev.g_ct[idx[x]], b = r->ev.g_ct[idx[y]];
            double dxy = 0.0;
            for (int s = 0; s < 2; s++)
                for (int u = 0; u < 2; u++) {
                    int da = r->tp.ct[a].dof[s], db = r->tp.ct[b].dof[u];
                    if (da < 0 || db < 0 || cl_of_dof(r, da) != cl_of_dof(r, db))
                        continue;
                    /* a REST side (sigma = 0: held still) takes no share */
                    double sa = side_sigma(r, a, s), sb = side_sigma(r, b, u);
                    if (sa != 0.0 && sb != 0.0)
                        dxy += sa * sb / r->ev.cmu[cl_of_dof(r, da)];
                }
            D[x + (size_t)y * k] = dxy;
        }
}

/* The stage's impulses z (r->ev.lam) from w = D z + q >= 0 _|_ z >= 0: the
 * closed form for one contact, else the small dense LCP, refined on the
 * residual formed without D (*refined: 1 when it was). */
static int reduced_solve(pd_edr *r, const int *idx, int k, double t, int *refined, pd_err *err)
{
    double *q = r->ev.qlcp, *z = r->ev.lam, *D = r->ev.Dd;
    *refined = 0;
    r->rs.res.lcp_solves++;
    if (k == 1) {
        z[0] = pd_contact_impulse_1(D[0], q[0]);
        return PD_OK;
    }
    int rc = small_lcp(r, k, D, q, z, r->ev.ztmp);
    if (rc)
        return pd_err_set(err, rc,
                          "row reference: the impact LCP of %d contacts at t = %.9g s "
                          "was not solved",
                          k, t * r->tp.o.time_unit);
    *refined = refine_reduced(r, idx, k, D, q, z);
    return PD_OK;
}

/* The stage's impulses applied: eta_c += sigma_xc z_x / mu_c contact by
 * contact, or, when z was refined, eta_c += G_c / mu_c from each
 * cluster's total G_c = sum_x sigma_xc z_x (the sum the residual was
 * refined on); the totals P and the impacts (stages where it closed). */
static void reduced_apply(pd_edr *r, const int *idx, int k, int refined)
{
    const double *q = r->ev.qlcp, *z = r->ev.lam;
    if (refined)
        for (int x = 0; x < k; x++) {
            int a = r->ev.g_ct[idx[x]];
            for (int s = 0; s < 2; s++)
                if (r->tp.ct[a].dof[s] >= 0)
                    r->ev.cG[cl_of_dof(r, r->tp.ct[a].dof[s])] = 0.0;
        }
    for (int x = 0; x < k; x++) {
        int j = idx[x], a = r->ev.g_ct[j];
        for (int s = 0; s < 2; s++)
            if (r->tp.ct[a].dof[s] >= 0) {
                int c = cl_of_dof(r, r->tp.ct[a].dof[s]);
                if (r->rs.cl[c].kind != EDR_SDOF) /* held still: no coordinate to move */
                    continue;
                if (refined)
                    r->ev.cG[c] += side_sigma(r, a, s) * z[x];
                else
                    r->ev.ceta[c] += side_sigma(r, a, s) * z[x] / r->ev.cmu[c];
            }
        r->ev.P[j] += z[x];
        r->ev.nimp[j] += q[x] < 0.0;
    }
    /* each cluster's G_c added once (cG zeroed after its first visit) */
    for (int x = 0; x < k && refined; x++) {
        int a = r->ev.g_ct[idx[x]];
        for (int s = 0; s < 2; s++)
            if (r->tp.ct[a].dof[s] >= 0) {
                int c = cl_of_dof(r, r->tp.ct[a].dof[s]);
                if (r->rs.cl[c].kind == EDR_SDOF)
                    r->ev.ceta[c] += r->ev.cG[c] / r->ev.cmu[c];
                r->ev.cG[c] = 0.0;
            }
    }
}

/* The held edges' impulses from each tree's momentum balance: with ext_i
 * the impulse of the contacts between clusters on dof i, edge e above
 * child c takes P_e = sum over c's subtree of s (m s deta - ext) /
 * (s_c w_c).  1 when one would pull (P_e < 0 beyond rounding). */
static int held_edge_impulses(pd_edr *r, int ne)
{
    for (int k = 0; k < r->ev.ngd; k++) {
        int i = r->ev.g_dof[k];
        r->ev.ext[i] = 0.0;
    }
    for (int e = 0; e < ne; e++) { /* ext = W_E P_E over the contacts between clusters */
        int j = r->ev.epos[e], a = r->ev.g_ct[j];
        for (int s = 0; s < 2; s++)
            if (r->tp.ct[a].dof[s] >= 0)
                r->ev.ext[r->tp.ct[a].dof[s]] += r->tp.ct[a].w[s] * r->ev.P[j];
    }
    for (int j = 0; j < r->ev.ngc; j++)
        r->ev.jpos[j] = -1;
    for (int j = 0; j < r->ev.ngc; j++)
        r->ev.pos_in[r->ev.g_ct[j]] = j;
    for (int i = 0; i < r->ev.ng; i++) {
        int c = r->ev.g_cl[i];
        edr_cluster *cl = &r->rs.cl[c];
        if (cl->npers == 0)
            continue;
        int nn = 0;
        for (int d = cl->root; d >= 0; d = r->ev.bfs_next[d]) /* the tree breadth first */
            r->ev.stack[nn++] = d;
        double deta = r->ev.ceta[c] - r->ev.cvy[c];
        /* each dof's unbalanced impulse, s_i (m_i dv_i - ext_i), dv_i = s_i deta */
        for (int k = 0; k < nn; k++) {
            int d = r->ev.stack[k];
            r->ev.gtmp[d] = r->rs.s[d] * (r->rs.s[d] * deta / r->tp.minv[d] - r->ev.ext[d]);
        }
        for (int k = nn - 1; k >= 0; k--) { /* children before their parents */
            int d = r->ev.stack[k], e = r->ev.pe[d];
            if (r->ev.pdof[d] >= 0)
                r->ev.gtmp[r->ev.pdof[d]] += r->ev.gtmp[d];
            if (e < 0)
                continue;
            const edr_contact *ct = &r->tp.ct[e];
            double Pe = r->ev.gtmp[d] / (r->rs.s[d] * ct->w[ct->dof[0] == d ? 0 : 1]);
            if (Pe < -EDR_RATE_TOL * (fabs(r->ev.gtmp[d]) + fabs(r->ev.ext[d])) - 1e-300)
                return 1; /* a held contact would pull */
            r->ev.P[r->ev.pos_in[e]] = fmax(Pe, 0.0);
        }
    }
    return 0;
}

/* The same stages on the clusters' coordinates: held trees move rigidly,
 * so only the closed contacts between clusters are unknowns (one or two,
 * not the whole compressed row), U_a = sum sigma eta_c, an impulse P_a
 * adds sigma P_a / mu_c to eta_c (mu_c = sum s^2 m).  The held edges'
 * impulses follow from each tree's momentum balance, subtree by subtree;
 * they must push (a held contact cannot pull): 1 when one would pull, or
 * the group holds a modal cluster, or the stage is larger than the dense
 * solver takes — then the dof-level stages run instead. */
static int impact_reduced_stages(pd_edr *r, double t, double tolU, pd_err *err)
{
    int rc, stage = 0, ne, *idx = r->ev.lcp_idx, single = r->tp.o.impact_law == PD_IMPACT_SINGLE;
    if (reduced_begin(r, t, &ne))
        return 1;
    for (;;) {
        stage_set set;
        if (reduced_stage_set(r, ne, tolU, single, &set))
            return 1;
        if (!set.closing) /* every closed contact at rest or separating: the impact is over */
            break;
        int k = set.k, refined;
        r->ev.law_multi |= stage == 0 && set.all > 1;
        if (single)
            single_law_zero(r->ev.qlcp, k);
        if (++stage > EDR_STAGES)
            return pd_err_set(err, PD_EBUDGET,
                              "row reference: the impact at t = %.17g s did not "
                              "end in %d stages",
                              t * r->tp.o.time_unit, EDR_STAGES);
        reduced_delassus(r, idx, k, r->ev.Dd);
        if ((rc = reduced_solve(r, idx, k, t, &refined, err)))
            return rc;
        r->rs.res.simultaneous += set.pressing > 1;
        reduced_apply(r, idx, k, refined);
        /* the single law: one LCP, no further stage */
        if (single)
            break;
    }
    if (held_edge_impulses(r, ne))
        return 1;
    /* the dofs' rates from their trees: v_i = s_i eta_c (0 held still) */
    for (int k = 0; k < r->ev.ngd; k++) {
        int i = r->ev.g_dof[k], c = cl_of_dof(r, i);
        r->ev.gv[i] = r->rs.cl[c].kind == EDR_SDOF ? r->rs.s[i] * r->ev.ceta[c] : 0.0;
    }
    return PD_OK;
}

/* The clusters' free coordinate accelerations alpha_c = sum s_i F_i / mu_c
 * (F_i = m_i a_i the free force on dof i, a REST tree held still: 0) into
 * ceta, mu_c into cmu.  1 when the group holds a modal cluster. */
static int reduced_free_acc(pd_edr *r)
{
    for (int i = 0; i < r->ev.ng; i++) {
        int c = r->ev.g_cl[i];
        edr_cluster *cl = &r->rs.cl[c];
        if (cl->kind == EDR_MODAL)
            return 1;
        double phi = 0.0;
        for (int b = cl->head; b >= 0 && cl->kind == EDR_SDOF; b = r->rs.blk_next[b]) {
            int d = r->tp.blk_dofs[r->tp.blk[b].first];
            phi += r->rs.s[d] * r->ev.gacc[d] / r->tp.minv[d];
        }
        r->ev.cmu[c] = cl->mass;
        r->ev.ceta[c] = cl->kind == EDR_SDOF ? phi / cl->mass : 0.0; /* alpha_c, free */
    }
    return 0;
}

/* The unknowns of the reduced force LCP among J = idx[0..k): the open
 * contacts between two clusters (or a cluster and a wall) an impulse
 * moves, as their positions x in J (ux); their count, or -1 past
 * EDR_REDUCED_MAX.  lambda starts at 0 over J. */
static int reduced_force_unknowns(pd_edr *r, const int *idx, int k, int *ux)
{
    int ku = 0;
    for (int x = 0; x < k; x++) {
        const edr_contact *ct = &r->tp.ct[idx[x]];
        int internal = ct->dof[0] >= 0 && ct->dof[1] >= 0 &&
                       cl_of_dof(r, ct->dof[0]) == cl_of_dof(r, ct->dof[1]);
        r->ev.lam[x] = 0.0;
        if (r->rs.cstate[idx[x]] == EDR_OPEN && !internal && movable(r, idx[x])) {
            if (ku >= EDR_REDUCED_MAX)
                return -1;
            ux[ku++] = x;
        }
    }
    return ku;
}

/* The reduced force LCP's data: q_x = sum_s sigma_xs alpha_c (the free gap
 * acceleration) and D_xy = sum over the SDOF trees shared of
 * sigma_xc sigma_yc / mu_c. */
static void reduced_force_data(pd_edr *r, const int *idx, const int *ux, int ku, double *q,
                               double *D)
{
    for (int x = 0; x < ku; x++) {
        int a = idx[ux[x]];
        /* q_x = sum_s sigma_xs alpha_c: the gap's acceleration without the
         * unknowns' forces */
        q[x] = 0.0;
        for (int s = 0; s < 2; s++)
            if (r->tp.ct[a].dof[s] >= 0)
                q[x] += side_sigma(r, a, s) * r->ev.ceta[cl_of_dof(r, r->tp.ct[a].dof[s])];
        for (int y = 0; y < ku; y++) {
            int b = idx[ux[y]];
            /* D_xy = sum over the SDOF trees x and y share of sigma_xc sigma_yc / mu_c */
            double dxy = 0.0;
            for (int s = 0; s < 2; s++)
                for (int u = 0; u < 2; u++) {
                    int da = r->tp.ct[a].dof[s], db = r->tp.ct[b].dof[u];
                    if (da >= 0 && db >= 0 && cl_of_dof(r, da) == cl_of_dof(r, db) &&
                        r->rs.cl[cl_of_dof(r, da)].kind == EDR_SDOF)
                        dxy +=
                            side_sigma(r, a, s) * side_sigma(r, b, u) / r->ev.cmu[cl_of_dof(r, da)];
                }
            D[x + (size_t)y * ku] = dxy;
        }
    }
}

/* The held edges' forces from each subtree's balance m a = F + W lambda:
 * with ext_i the unknowns' forces on dof i, edge e above child c carries
 * lambda_e = sum over c's subtree of s (m a - F - ext) / (s_c w_c), into
 * lam where e is in J.  1 when one would pull beyond the rounding of its
 * terms (wk: their magnitudes, summed alike). */
static int held_edge_forces(pd_edr *r, const int *idx, int k, const int *ux, int ku,
                            const double *z)
{
    for (int k2 = 0; k2 < r->ev.ngd; k2++)
        r->ev.ext[r->ev.g_dof[k2]] = 0.0;
    /* ext = W_U lambda_U: the unknowns' forces on the dofs */
    for (int x = 0; x < ku; x++) {
        int a = idx[ux[x]];
        for (int s = 0; s < 2; s++)
            if (r->tp.ct[a].dof[s] >= 0)
                r->ev.ext[r->tp.ct[a].dof[s]] += r->tp.ct[a].w[s] * z[x];
    }
    for (int x = 0; x < k; x++)
        r->ev.pos_in[idx[x]] = x;
    for (int i = 0; i < r->ev.ng; i++) {
        int c = r->ev.g_cl[i];
        edr_cluster *cl = &r->rs.cl[c];
        if (cl->npers == 0)
            continue;
        int nn = 0;
        for (int d = cl->root; d >= 0; d = r->ev.bfs_next[d])
            r->ev.stack[nn++] = d;
        for (int x = 0; x < nn; x++) {
            int d = r->ev.stack[x];
            /* each dof's unbalanced force s_i (m_i a_i - F_i - ext_i) with
             * a_i = s_i alpha_c, F_i = m_i a_free_i; wk its terms' magnitudes */
            double m = 1.0 / r->tp.minv[d], a = r->rs.s[d] * r->ev.ceta[c];
            r->ev.gtmp[d] = r->rs.s[d] * (m * a - m * r->ev.gacc[d] - r->ev.ext[d]);
            r->ev.wk[d] = fabs(m * a) + fabs(m * r->ev.gacc[d]) + fabs(r->ev.ext[d]);
        }
        for (int x = nn - 1; x >= 0; x--) { /* children before their parents */
            int d = r->ev.stack[x], e = r->ev.pe[d];
            if (r->ev.pdof[d] >= 0) {
                r->ev.gtmp[r->ev.pdof[d]] += r->ev.gtmp[d];
                r->ev.wk[r->ev.pdof[d]] += r->ev.wk[d];
            }
            if (e < 0)
                continue;
            const edr_contact *ct = &r->tp.ct[e];
            double le = r->ev.gtmp[d] / (r->rs.s[d] * ct->w[ct->dof[0] == d ? 0 : 1]);
            if (le < -EDR_RATE_TOL * r->ev.wk[d])
                return 1; /* a held contact would pull: it leaves */
            /* the edge's force goes to lam when the edge is one of J */
            if (r->ev.ct_mark[e] == r->ev.epoch && r->ev.pos_in[e] < k && idx[r->ev.pos_in[e]] == e)
                r->ev.lam[r->ev.pos_in[e]] = le;
        }
    }
    return 0;
}

/* The contact-force LCP of force_lcp on the clusters' coordinates: the
 * held contacts of every tree hold (its coordinate's acceleration
 * alpha_c = (sum s_i F_i + sum sigma lambda) / mu_c, F the free forces),
 * the closed contacts between clusters are the unknowns (gap acceleration
 * sum sigma alpha_c), and each held edge's force follows from its
 * subtree's balance, m a = F + W lambda.  1 (the dof-level LCP decides)
 * when a held edge would pull, the group holds a modal cluster, or the
 * LCP is too large for the dense solver. */
static int reduced_force(pd_edr *r, const int *idx, int k, double t, pd_err *err)
{
    int ku, *ux = r->ev.epos;
    double *q = r->ev.qtmp, *z = r->ev.ztmp, *D = r->ev.Dd;
    if (reduced_free_acc(r) || (ku = reduced_force_unknowns(r, idx, k, ux)) < 0)
        return 1;
    reduced_force_data(r, idx, ux, ku, q, D);
    if (ku == 1) {
        /* one unknown: lambda = -q / D where q < 0, else 0; D = 0 (held
         * still on both sides) can answer only a gap not pressed (q >= 0) */
        z[0] = D[0] > 0.0 ? pd_contact_impulse_1(D[0], q[0]) : (q[0] >= 0.0 ? 0.0 : -1.0);
        if (z[0] < 0.0)
            return 1; /* held still on both sides and pressed: let the dofs decide */
        r->rs.res.lcp_solves++;
    } else if (ku > 1) {
        r->rs.res.lcp_solves++;
        if (small_lcp(r, ku, D, q, z, r->ev.wtmp))
            return 1;
    }
    /* alpha_c with the unknowns' forces: += sum_x sigma_xc lambda_x / mu_c */
    for (int x = 0; x < ku; x++) {
        int a = idx[ux[x]];
        r->ev.lam[ux[x]] = z[x];
        for (int s = 0; s < 2; s++)
            if (r->tp.ct[a].dof[s] >= 0) {
                int c = cl_of_dof(r, r->tp.ct[a].dof[s]);
                if (r->rs.cl[c].kind == EDR_SDOF)
                    r->ev.ceta[c] += side_sigma(r, a, s) * z[x] / r->ev.cmu[c];
            }
    }
    if (held_edge_forces(r, idx, k, ux, ku, z))
        return 1;
    for (int j = 0; j < r->ev.ngc; j++) { /* gap accelerations of every closed contact */
        int a = r->ev.g_ct[j];
        double w = 0.0;
        for (int s = 0; s < 2; s++)
            if (r->tp.ct[a].dof[s] >= 0)
                w += side_sigma(r, a, s) * r->ev.ceta[cl_of_dof(r, r->tp.ct[a].dof[s])];
        r->ev.wlcp[j] = w;
    }
    (void)t;
    (void)err;
    return PD_OK;
}

/* The impact's work dK = 1/2 sum m (v+ - v-)(v+ + v-) over the group's
 * dofs: with e <= 1 it is <= 0 under the staged law (<= 1/2 sum P_a U-_a
 * over the contacts separating before it under the single law, whose
 * impulses on them end at U+ = 0), up to its rounding, EDR_WORK_TOL eps
 * sum (|v+| + |v-|) (m |v-| + sum_a |w_a P_a|); PD_ENUMERICAL beyond. */
static int check_work(pd_edr *r, double t, pd_err *err)
{
    double dK = 0.0, tol = 0.0, K = 0.0;
    /* the single law: an impulse that stops a separating contact (U- > 0 to
     * U+ = 0) does the work 1/2 P U-, allowed */
    if (r->tp.o.impact_law == PD_IMPACT_SINGLE)
        for (int j = 0; j < r->ev.ngc; j++)
            if (r->ev.Uminus[j] > 0.0)
                dK -= 0.5 * r->ev.P[j] * r->ev.Uminus[j];
    for (int k = 0; k < r->ev.ngd; k++)
        r->ev.gtmp[r->ev.g_dof[k]] = 0.0;
    /* gtmp_i = sum |w P| over the contacts at dof i: the impulses' size */
    for (int j = 0; j < r->ev.ngc; j++) {
        const edr_contact *ct = &r->tp.ct[r->ev.g_ct[j]];
        for (int s = 0; s < 2; s++)
            if (ct->dof[s] >= 0)
                r->ev.gtmp[ct->dof[s]] += fabs(ct->w[s] * r->ev.P[j]);
    }
    for (int k = 0; k < r->ev.ngd; k++) {
        int i = r->ev.g_dof[k];
        double m = 1.0 / r->tp.minv[i], vm = r->ev.ev_vminus[k], vp = r->ev.gv[i];
        /* 1/2 m (v+^2 - v-^2) factored: no cancellation of two large squares */
        dK += 0.5 * m * (vp - vm) * (vp + vm);
        tol += (fabs(vp) + fabs(vm)) * (m * fabs(vm) + r->ev.gtmp[i]);
        K += 0.5 * m * vm * vm;
    }
    if (dK <= EDR_WORK_TOL * DBL_EPSILON * tol)
        return PD_OK;
    return pd_err_set(err, PD_ENUMERICAL,
                      "row reference: the impact at t = %.17g s adds %.3g of "
                      "its kinetic energy (rounding allows %.3g): the impact LCP lost precision",
                      t * r->tp.o.time_unit, dK / K, EDR_WORK_TOL * DBL_EPSILON * tol / K);
}

/* Resolve the group at t: impact LCP if a contact closes, persistence,
 * accumulations, new clusters, predictions. */
static int impact_group(pd_edr *r, double t, pd_err *err)
{
    int rc, acc = 0;
    /* the group: every contact closed at t with the clusters it joins, and
     * their dofs' states at t */
    group_grow(r, t);
    group_state(r, t);
    double tol = r->tp.o.close_tol * r->rs.L, vs = 0.0;
    for (int j = 0; j < r->ev.ngc; j++) { /* closed walls exactly at their gap */
        const edr_contact *ct = &r->tp.ct[r->ev.g_ct[j]];
        r->ev.excluded[j] = 0;
        if ((ct->dof[0] < 0) != (ct->dof[1] < 0)) {
            int s = ct->dof[0] >= 0 ? 0 : 1;
            /* x = -g0 / w: the wall's gap at zero to a rounding, taken within close_tol */
            double x = -ct->g0 / ct->w[s];
            if (fabs(ct->g0 + ct->w[s] * r->ev.gx[ct->dof[s]]) <= tol + fabs(ct->g0) * 1e-15)
                r->ev.gx[ct->dof[s]] = x;
        }
    }
    /* the event's speed scale; v- kept for the work check and the report */
    for (int k = 0; k < r->ev.ngd; k++) {
        vs = fmax(vs, fabs(r->ev.gv[r->ev.g_dof[k]]));
        r->ev.ev_vminus[k] = r->ev.gv[r->ev.g_dof[k]];
    }
    r->rs.vscale = fmax(r->rs.vscale, vs);
    double tolU = EDR_RATE_TOL * fmax(vs, r->rs.vscale);
    for (int j = 0; j < r->ev.ngc; j++) {
        /* U- = W^T v-, zero at the rounding level of the speeds */
        double U = contact_dot(r, r->ev.g_ct[j], r->ev.gv);
        r->ev.Uminus[j] = fabs(U) <= tolU ? 0.0 : U;
        r->ev.P[j] = 0.0;
    }
    for (int j = 0; j < r->ev.ngc; j++)
        r->ev.nimp[j] = 0;
    r->ev.instant_acc = 0;
    r->ev.law_multi = 0;
    /* the stages on the clusters' coordinates when they can (held trees move
     * rigidly: only the contacts between clusters are unknowns) */
    rc = impact_reduced_stages(r, t, tolU, err);
    if (rc == 1) { /* on the dofs: back to the rates before the impact */
        for (int k = 0; k < r->ev.ngd; k++)
            r->ev.gv[r->ev.g_dof[k]] = r->ev.ev_vminus[k];
        for (int j = 0; j < r->ev.ngc; j++) {
            r->ev.P[j] = 0.0;
            r->ev.nimp[j] = 0;
        }
        r->ev.instant_acc = 0;
        rc = impact_stages(r, t, tolU, err);
    }
    /* an instant's accumulation (stage_e) and a law that decided count once each */
    r->rs.res.accumulations += r->ev.instant_acc;
    r->rs.res.law_decided += r->ev.law_multi;
    if (rc || (rc = check_work(r, t, err)) || (rc = commit_impacts(r, t, err)))
        return rc;
    for (int j = 0; j < r->ev.ngc; j++) {
        /* U+ = W^T v+: a zero rate makes a contact a candidate to persist */
        double U = contact_dot(r, r->ev.g_ct[j], r->ev.gv);
        r->ev.Uplus[j] = fabs(U) <= tolU ? 0.0 : U;
    }
    if ((rc = decide_persistence(r, t, &acc, err)))
        return rc;
    if ((rc = regroup(r, t, err)))
        return rc;
    if (acc && !tails_hold(r)) { /* the tail would not hold: bounce on */
        for (int j = 0; j < r->ev.ngc; j++)
            if (r->ev.held_tail[j] > 0.0) {
                r->ev.held[j] = 0;
                r->ev.held_tail[j] = 0.0;
            }
        acc = 0;
        if ((rc = regroup(r, t, err)))
            return rc;
    }
    if (acc)
        r->rs.res.accumulations++;
    /* v+ as the new flights start: projected onto their held contacts */
    for (int k = 0; k < r->ev.ngd; k++)
        r->ev.gv[r->ev.g_dof[k]] = r->rs.vo[r->ev.g_dof[k]];
    if (report(r, t, PD_EDR_IMPACT, acc) > 0)
        r->rs.stopped = 1;
    repredict(r, t);
    return PD_OK;
}

/* An empty group for the next event. */
static void group_begin(pd_edr *r)
{
    /* a new epoch: every mark of the last group (cl_mark, ct_mark, ct_mark2)
     * is stale at once, with no clearing */
    r->ev.epoch++;
    r->ev.ng = 0;
    r->ev.ngc = 0;
}

/* A new group: cluster c and its closed contacts (persistent or locked). */
static void group_of_cluster(pd_edr *r, int c)
{
    group_begin(r);
    group_add_cluster(r, c);
    for (int b = r->rs.cl[c].head; b >= 0; b = r->rs.blk_next[b]) {
        const edr_block *bk = &r->tp.blk[b];
        for (int k = 0; k < bk->ncont; k++) {
            int x = r->tp.blk_cont[bk->cont0 + k];
            if (r->rs.cstate[x] != EDR_OPEN && r->ev.ct_mark[x] != r->ev.epoch)
                group_add_contact(r, x);
        }
    }
}

/* Every closed contact of the group stays held (no decision at t). */
static void hold_closed(pd_edr *r)
{
    for (int j = 0; j < r->ev.ngc; j++)
        r->ev.held[j] = r->rs.cstate[r->ev.g_ct[j]] != EDR_OPEN;
}

/* Contact a closes at t: the group grows from it. */
static int on_impact(pd_edr *r, int a, double t, pd_err *err)
{
    int rc;
    if ((rc = count_event(r, a, t, err)))
        return rc;
    /* the seed: the closing contact and its sides' clusters */
    group_begin(r);
    group_add_contact(r, a);
    const edr_contact *ct = &r->tp.ct[a];
    for (int s = 0; s < 2; s++)
        if (ct->dof[s] >= 0)
            group_add_cluster(r, cl_of_dof(r, ct->dof[s]));
    return impact_group(r, t, err);
}

/* A persistent force of cluster c reaches zero at t: the force LCP
 * without that contact decides again. */
static int on_detach(pd_edr *r, int c, double t, pd_err *err)
{
    int rc, acc, a = r->rs.cl[c].det_contact;
    if ((rc = count_event(r, r->tp.m + c, t, err)))
        return rc;
    group_of_cluster(r, c);
    group_state(r, t);
    /* no impact: v- is the state's v; U- = U+ = 0, P = 0 */
    for (int k = 0; k < r->ev.ngd; k++)
        r->ev.ev_vminus[k] = r->ev.gv[r->ev.g_dof[k]];
    for (int j = 0; j < r->ev.ngc; j++) {
        r->ev.Uminus[j] = r->ev.Uplus[j] = 0.0;
        r->ev.P[j] = 0.0;
    }
    for (int j = 0; j < r->ev.ngc; j++)
        /* the detaching contact leaves: the force LCP decides the others without it */
        r->ev.excluded[j] = r->ev.g_ct[j] == a;
    if ((rc = decide_persistence(r, t, &acc, err)))
        return rc;
    for (int j = 0; j < r->ev.ngc; j++) {
        r->ev.excluded[j] = 0;
        /* a persistent contact not held any more: one detachment */
        if (r->rs.cstate[r->ev.g_ct[j]] == EDR_PERSIST && !r->ev.held[j])
            r->rs.res.detachments++;
    }
    if ((rc = regroup(r, t, err)))
        return rc;
    /* a jumped accumulation whose tail would not hold: open again */
    if (acc && !tails_hold(r)) {
        for (int j = 0; j < r->ev.ngc; j++)
            if (r->ev.held_tail[j] > 0.0)
                r->ev.held[j] = 0;
        if ((rc = regroup(r, t, err)))
            return rc;
    }
    if (report(r, t, PD_EDR_DETACH, 0) > 0)
        r->rs.stopped = 1;
    repredict(r, t);
    return PD_OK;
}

/* The time of the impact queued for an open contact of dof's structure
 * whose gap is within the closing tolerance at t, closing (HUGE_VAL:
 * none): a yield level there is the contact's (the offset a slide into it
 * left), and its impact comes first. */
static double impact_due(pd_edr *r, int dof, double t)
{
    const edr_block *bk = &r->tp.blk[r->tp.dof_blk[dof]];
    double due = HUGE_VAL;
    for (int k = 0; k < bk->ncont; k++) {
        int a = r->tp.blk_cont[bk->cont0 + k];
        double U;
        if (r->rs.cstate[a] == EDR_OPEN && r->rs.qkind[a] == EDR_Q_HIT &&
            gap_now(r, a, t, &U) <= r->tp.o.close_tol * r->rs.L && U < 0.0)
            due = fmin(due, r->rs.q.key[a]);
    }
    return due;
}

/* Spring j yields or unloads at t: its cluster re-origins in the new phase
 * (the force is continuous, the held contacts stay held).  An onset at a
 * closing contact waits for its impact (which predicts it again). */
static int on_spring(pd_edr *r, int j, double t, pd_err *err)
{
    int rc, dof = r->tp.sp_dof[j], c = cl_of_dof(r, dof), slot = r->rs.slot_spring0 + j;
    if ((rc = count_event(r, slot, t, err)))
        return rc;
    double due = r->rs.sp_phase[j] == 0 ? impact_due(r, dof, t) : HUGE_VAL;
    if (due < HUGE_VAL) {
        r->rs.qkind[slot] = EDR_Q_SCAN;
        q_set(&r->rs.q, slot, fmax(due, t));
        return PD_OK;
    }
    group_of_cluster(r, c);
    group_state(r, t);
    hold_closed(r);
    /* elastic: a slide toward the level passed; sliding: the drift turned back */
    double d = edr_spring_drift(r, j, r->ev.gx), z = d - r->rs.sp_up[j];
    edr_spring_set(r, j, d, r->rs.sp_phase[j] != 0 ? 0 : z > 0.0 ? 1 : -1);
    if ((rc = regroup(r, t, err)))
        return rc;
    repredict(r, t);
    return PD_OK;
}

/* The forcing's next piece starts at t: every cluster re-origins on it;
 * held contacts whose force would be negative decide again. */
static int on_piece(pd_edr *r, double t, pd_err *err)
{
    int rc;
    if ((rc = count_event(r, r->rs.slot_piece, t, err)))
        return rc;
    r->rs.piece = edr_piece_at(r, t);
    /* the live clusters listed first: regroup frees and takes slots as it goes */
    int ncl = 0;
    for (int c = 0; c < r->tp.nb; c++)
        if (r->rs.cl[c].live)
            r->ev.plist[ncl++] = c;
    for (int i = 0; i < ncl; i++) {
        int c = r->ev.plist[i];
        if (!r->rs.cl[c].live || r->rs.cl[c].t0 == t) /* gone, or started at t on the new piece */
            continue;
        group_of_cluster(r, c);
        group_state(r, t);
        for (int k = 0; k < r->ev.ngd; k++)
            r->ev.ev_vminus[k] = r->ev.gv[r->ev.g_dof[k]];
        /* no impact: U- = U+ = P = 0 */
        int negative = 0;
        for (int j = 0; j < r->ev.ngc; j++) {
            r->ev.Uminus[j] = r->ev.Uplus[j] = r->ev.P[j] = 0.0;
            r->ev.excluded[j] = 0;
        }
        if (r->ev.ngc > 0) { /* the held forces under the new piece */
            free_accelerations(r, t);
            int k0 = 0;
            for (int j = 0; j < r->ev.ngc; j++)
                r->ev.lcp_idx[k0++] = r->ev.g_ct[j];
            if ((rc = force_lcp(r, r->ev.lcp_idx, k0, t, err)))
                return rc;
            for (int j = 0; j < r->ev.ngc; j++)
                negative |= r->rs.cstate[r->ev.g_ct[j]] == EDR_PERSIST && !(r->ev.lam[j] > 0.0);
        }
        /* a held force negative under the new piece: persistence decided again */
        if (negative) {
            int acc;
            if ((rc = decide_persistence(r, t, &acc, err)))
                return rc;
            for (int j = 0; j < r->ev.ngc; j++)
                if (r->rs.cstate[r->ev.g_ct[j]] == EDR_PERSIST && !r->ev.held[j])
                    r->rs.res.detachments++;
        } else /* every closed contact stays held: the clusters re-origin on the piece */
            hold_closed(r);
        if ((rc = regroup(r, t, err)))
            return rc;
    }
    /* every contact and cluster predicts again: every flight changed with the piece */
    for (int i = 0; i < r->tp.m; i++)
        predict_contact(r, i, t, 0);
    for (int c = 0; c < r->tp.nb; c++)
        if (r->rs.cl[c].live) {
            predict_detach(r, c, t, 0);
            predict_cluster_springs(r, c, t);
        }
    /* the next piece change, if before t1 */
    double next = edr_piece_end(r, r->rs.piece);
    q_set(&r->rs.q, r->rs.slot_piece, next < r->rs.t1 ? next : HUGE_VAL);
    return PD_OK;
}

/* The springs' offsets into sp_now, with the dofs at q (a slide's from its
 * drift). */
static void spring_offsets(pd_edr *r, const double *q)
{
    for (int j = 0; j < r->tp.ns; j++) /* a slide's offset moves with its drift */
        r->rs.sp_now[j] = edr_spring_up(r, j, r->rs.sp_phase[j] ? edr_spring_drift(r, j, q) : 0.0);
}

/* The observer's state at t. */
static int emit(pd_edr *r, double t, pd_observer obs, void *ctx)
{
    for (int i = 0; i < r->tp.n; i++) {
        double a;
        dof_state(r, i, t, &r->rs.st.q[i], &r->rs.st.v[i], &a);
        r->rs.st.acc[i] = a;
    }
    /* the held forces' impulses up to t (a sampler only) */
    for (int c = 0; r->rs.sample_forces && c < r->tp.nb; c++)
        if (r->rs.cl[c].live)
            integrate_held(r, c, t);
    for (int a = 0; a < r->tp.m; a++) {
        r->rs.st.g[a] = gap_now(r, a, t, NULL);
        /* P: the impulses since the last sample (impacts and held forces), then restarted */
        r->rs.st.P[a] = r->rs.imp_out[a];
        r->rs.imp_out[a] = 0.0;
        r->rs.st.active[a] = r->rs.cstate[a] == EDR_PERSIST;
    }
    if (r->tp.ns > 0) { /* the springs' offsets at t */
        spring_offsets(r, r->rs.st.q);
        r->rs.st.up = r->rs.sp_now;
    }
    r->rs.st.t = t;
    r->rs.st.has_acc = 1;
    return obs(&r->rs.st, ctx);
}

/* ---- allocation ---------------------------------------------------------------------------- */

/* Every array of struct pd_edr, declared once (MuJoCo's X-macro habit):
 * X(field, element type, count), the count written in the sizes of
 * edr_sizes.  A table per stage of pd_edr_alloc, each allocated as soon
 * as its sizes are known (pd_calloc: max(count, 1) zeroed elements);
 * pd_edr_free frees them all (EDR_ARRAYS), and a compile-time check ties
 * each entry's type to its field's, so that the tables, the frees and the
 * struct cannot drift apart. */

/* Sized by the model alone. */
#define EDR_MODEL_ARRAYS(X)                                                                        \
    X(tp.b, double, n)                                                                             \
    X(tp.pieces, pd_sine_piece, npieces)                                                           \
    X(tp.dof_blk, int, n)                                                                          \
    X(tp.dof_loc, int, n)                                                                          \
    X(tp.blk_dofs, int, n)                                                                         \
    X(tp.minv, double, n)                                                                          \
    X(tp.ct, edr_contact, m)                                                                       \
    X(tp.blk_cont, int, 2 * m) /* a contact is listed by each of its (at most two) blocks */       \
    X(tp.dofc_ptr, int, n + 1)                                                                     \
    X(tp.dofc, int, 2 * m)

/* Sized by the blocks, once C and K's couplings have found them. */
#define EDR_BLOCK_ARRAYS(X)                                                                        \
    X(tp.blk, edr_block, nb)                                                                       \
    X(tp.blk_off, long, nb + 1)

/* The yielding springs. */
#define EDR_SPRING_ARRAYS(X)                                                                       \
    X(tp.sp_dof, int, ns)                                                                          \
    X(tp.sp_dof2, int, ns)                                                                         \
    X(tp.sp_sig, double, ns)                                                                       \
    X(tp.sp_sig2, double, ns)                                                                      \
    X(tp.blk_sp, int, ns)                                                                          \
    X(rs.sp_phase, signed char, ns)                                                                \
    X(rs.sp_up, double, ns)                                                                        \
    X(rs.sp_upx, double, ns)                                                                       \
    X(rs.sp_exc, double, ns)                                                                       \
    X(rs.sp_now, double, ns)                                                                       \
    X(rs.sp_onsets, long, ns)

/* The blocks' dense damping and stiffness, sum over the blocks of n_b^2 entries. */
#define EDR_MATRIX_ARRAYS(X)                                                                       \
    X(tp.Cb, double, nentries)                                                                     \
    X(tp.Kb, double, nentries)

/* The run's state, results and scratch. */
#define EDR_RUN_ARRAYS(X)                                                                          \
    /* clusters */                                                                                 \
    X(rs.cl, edr_cluster, nb)                                                                      \
    X(rs.blk_cl, int, nb)                                                                          \
    X(rs.blk_next, int, nb)                                                                        \
    X(rs.free_cl, int, nb)                                                                         \
    X(rs.s, double, n)                                                                             \
    X(rs.d, double, n)                                                                             \
    X(rs.xo, double, n)                                                                            \
    X(rs.vo, double, n)                                                                            \
    X(rs.crow, int, n)                                                                             \
    X(rs.crow_c, int, m)                                                                           \
    /* contacts */                                                                                 \
    X(rs.cstate, unsigned char, m)                                                                 \
    X(rs.pers_next, int, m)                                                                        \
    X(rs.la, double, m)                                                                            \
    X(rs.lb, double, m)                                                                            \
    X(rs.lg, double, m)                                                                            \
    X(rs.ld, double, m)                                                                            \
    X(rs.base_t, double, m)                                                                        \
    X(rs.base_g, double, m)                                                                        \
    X(rs.gmeas_t, double, m)                                                                       \
    X(rs.since, double, m)                                                                         \
    X(rs.burst, long, m)                                                                           \
    /* results */                                                                                  \
    X(rs.xpos, double, n)                                                                          \
    X(rs.xneg, double, n)                                                                          \
    X(rs.drift, double, n)                                                                         \
    X(rs.gmin, double, m)                                                                          \
    X(rs.impacts, long, m)                                                                         \
    X(rs.first, double, m)                                                                         \
    X(rs.maxP, double, m)                                                                          \
    X(rs.ctime, double, m)                                                                         \
    X(rs.imp_out, double, m)                                                                       \
    /* the queue and its slots */                                                                  \
    X(rs.q.heap, int, nslot)                                                                       \
    X(rs.q.pos, int, nslot)                                                                        \
    X(rs.q.key, double, nslot)                                                                     \
    X(rs.qkind, unsigned char, nslot)                                                              \
    X(rs.win, int, nslot)                                                                          \
    X(rs.slot_t, double, nslot)                                                                    \
    X(rs.slot_same, int, nslot)                                                                    \
    X(rs.slot_run, int, nslot)                                                                     \
    X(rs.slot_t0, double, nslot)                                                                   \
    /* the group of an event */                                                                    \
    X(ev.g_cl, int, nb)                                                                            \
    X(ev.cl_mark, int, nb)                                                                         \
    X(ev.g_ct, int, m)                                                                             \
    X(ev.ct_mark, int, m)                                                                          \
    X(ev.ct_mark2, int, m)                                                                         \
    X(ev.ct_markD, int, m)                                                                         \
    X(ev.ct_markP, int, m)                                                                         \
    X(ev.g_dof, int, n)                                                                            \
    X(ev.gx, double, n)                                                                            \
    X(ev.gv, double, n)                                                                            \
    X(ev.gacc, double, n)                                                                          \
    X(ev.gtmp, double, n)                                                                          \
    X(ev.Uminus, double, m)                                                                        \
    X(ev.Uplus, double, m)                                                                         \
    X(ev.P, double, m)                                                                             \
    X(ev.lam, double, m)                                                                           \
    X(ev.wlcp, double, m)                                                                          \
    X(ev.qlcp, double, m)                                                                          \
    X(ev.wtmp, double, m)                                                                          \
    X(ev.lcp_idx, int, m)                                                                          \
    X(ev.jpos, int, m)                                                                             \
    X(ev.excluded, int, m)                                                                         \
    X(ev.held, unsigned char, m)                                                                   \
    X(ev.tie, unsigned char, m)                                                                    \
    X(ev.held_tail, double, m)                                                                     \
    X(ev.pos_in, int, m)                                                                           \
    X(ev.guess, unsigned char, m)                                                                  \
    X(ev.lcp_scale, double, m)                                                                     \
    X(ev.lcp_q, double, m)                                                                         \
    X(ev.Dd, double, dm *dm)                                                                       \
    X(ev.Dlu, double, dm *dm)                                                                      \
    X(ev.rtmp, double, 4 * dm)                                                                     \
    X(ev.lu_perm, int, 2 * dm)                                                                     \
    X(ev.cG, double, nb)                                                                           \
    X(ev.Dval, double, dcap)                                                                       \
    X(ev.Dcol, int, m + 1)                                                                         \
    X(ev.Drow, int, dcap)                                                                          \
    X(ev.epos, int, m)                                                                             \
    X(ev.qtmp, double, m)                                                                          \
    X(ev.ztmp, double, m)                                                                          \
    X(ev.ev_vminus, double, n)                                                                     \
    X(ev.ev_vplus, double, n)                                                                      \
    X(ev.ev_x, double, n)                                                                          \
    /* scratch */                                                                                  \
    X(ev.stack, int, n)                                                                            \
    X(ev.pe, int, n)                                                                               \
    X(ev.pdof, int, n)                                                                             \
    X(ev.bfs_next, int, n)                                                                         \
    X(ev.ceta, double, nb)                                                                         \
    X(ev.cmu, double, nb)                                                                          \
    X(ev.cvy, double, nb)                                                                          \
    X(ev.ext, double, n)                                                                           \
    X(ev.nimp, long, m)                                                                            \
    X(ev.keybuf, int, 2 * (nb + m + ns + 2))                                                       \
    X(ev.uf, int, nb)                                                                              \
    X(ev.gblk, int, nb)                                                                            \
    X(ev.newcl, int, nb)                                                                           \
    X(ev.plist, int, nb)                                                                           \
    X(ev.loc, int, n)                                                                              \
    X(ev.wk, double, 8 * n)                                                                        \
    X(ev.mctx, struct meas_ctx, nmeas)                                                             \
    X(ev.mscan, edr_scan, nmeas)                                                                   \
    X(ev.mprev, edr_pt, nmeas)                                                                     \
    /* the observer's state */                                                                     \
    X(rs.st.q, double, n)                                                                          \
    X(rs.st.v, double, n)                                                                          \
    X(rs.st.P, double, m)                                                                          \
    X(rs.st.g, double, m)                                                                          \
    X(rs.st.active, unsigned char, m)                                                              \
    X(rs.st.acc, double, n)

#define EDR_ARRAYS(X)                                                                              \
    EDR_MODEL_ARRAYS(X)                                                                            \
    EDR_BLOCK_ARRAYS(X) EDR_SPRING_ARRAYS(X) EDR_MATRIX_ARRAYS(X) EDR_RUN_ARRAYS(X)

/* Each entry's element type is its field's (checked, not evaluated). */
#define EDR_ARRAY_TYPE(field, type, count)                                                         \
    _Static_assert(_Generic(((pd_edr *)0)->field, type * : 1, default : 0),                        \
                   "pd_edr." #field ": " #type);
EDR_ARRAYS(EDR_ARRAY_TYPE)
#undef EDR_ARRAY_TYPE

/* The counts the tables are written in. */
typedef struct edr_sizes {
    long n, m, npieces; /* dofs, contacts, forcing pieces */
    long nb;            /* blocks (and cluster slots: a cluster holds at least one) */
    long ns;            /* yielding springs */
    long nentries;      /* the blocks' dense matrices: sum of n_b^2 */
    long nslot;         /* queue slots: the contacts, the clusters, the piece, the output,
                           the springs */
    long dm;            /* the clusters' dense LCPs: min(m, EDR_REDUCED_MAX) contacts */
    long dcap;          /* entries of a compressed Delassus matrix */
    long nmeas;         /* functions measured on one cluster: each dof's x and drift */
} edr_sizes;

/* One entry: PD_ENOMEM (the arrays taken so far are pd_edr_free's). */
#define EDR_ALLOC_ARRAY(field, type, count)                                                        \
    if (!(r->field = pd_calloc((count), sizeof(type))))                                            \
        return PD_ENOMEM;

static int alloc_model_arrays(pd_edr *r, const edr_sizes *sizes)
{
    long n = sizes->n, m = sizes->m, npieces = sizes->npieces;
    EDR_MODEL_ARRAYS(EDR_ALLOC_ARRAY)
    return PD_OK;
}

static int alloc_block_arrays(pd_edr *r, const edr_sizes *sizes)
{
    long nb = sizes->nb;
    EDR_BLOCK_ARRAYS(EDR_ALLOC_ARRAY)
    return PD_OK;
}

static int alloc_spring_arrays(pd_edr *r, const edr_sizes *sizes)
{
    long ns = sizes->ns;
    EDR_SPRING_ARRAYS(EDR_ALLOC_ARRAY)
    return PD_OK;
}

static int alloc_matrix_arrays(pd_edr *r, const edr_sizes *sizes)
{
    long nentries = sizes->nentries;
    EDR_MATRIX_ARRAYS(EDR_ALLOC_ARRAY)
    return PD_OK;
}

static int alloc_run_arrays(pd_edr *r, const edr_sizes *sizes)
{
    long n = sizes->n, m = sizes->m, nb = sizes->nb, nslot = sizes->nslot, ns = sizes->ns;
    long dm = sizes->dm, dcap = sizes->dcap, nmeas = sizes->nmeas;
    EDR_RUN_ARRAYS(EDR_ALLOC_ARRAY)
    return PD_OK;
}
#undef EDR_ALLOC_ARRAY

void pd_edr_free(pd_edr *r)
{
    if (!r)
        return;
    /* the clusters' modal storage, the basis cache and the solvers, then the tables */
    if (r->rs.cl)
        for (int c = 0; c < r->tp.nb; c++)
            edr_cluster_free(&r->rs.cl[c]);
    edr_basis_cache_free(r);
    pd_lcp_solver_free(r->ev.solver);
    pd_lcp_solver_free(r->ev.dsolver);
#define EDR_FREE_ARRAY(field, type, count) free(r->field);
    EDR_ARRAYS(EDR_FREE_ARRAY)
#undef EDR_FREE_ARRAY
    free(r);
}

/* Entries of column j of A: rows and values through the callback. */
typedef void (*entry_fn)(void *ctx, int i, int j, double x);
static void for_each_entry(const pd_matrix *A, entry_fn fn, void *ctx)
{
    if (A->kind == PD_MATRIX_DENSE) {
        for (int j = 0; j < A->cols; j++)
            for (int i = 0; i < A->rows; i++)
                fn(ctx, i, j, A->values[i + (size_t)j * A->rows]);
    } else if (A->kind == PD_MATRIX_CSC) {
        for (int j = 0; j < A->cols; j++)
            for (int p = A->colptr[j]; p < A->colptr[j + 1]; p++)
                fn(ctx, A->rowind[p], j, A->values[p]);
    }
}

static void join_entry(void *ctx, int i, int j, double x)
{
    int *uf = ctx;
    if (x != 0.0 && i != j) {
        int a = uf_find(uf, i), b = uf_find(uf, j);
        if (a != b)
            uf[a] = b;
    }
}

typedef struct fill_ctx {
    pd_edr *r;
    double *dst;
} fill_ctx;

static void fill_entry(void *ctx, int i, int j, double x)
{
    fill_ctx *f = ctx;
    pd_edr *r = f->r;
    int b = r->tp.dof_blk[i];
    if (x == 0.0 || r->tp.dof_blk[j] != b)
        return;
    f->dst[r->tp.blk_off[b] + r->tp.dof_loc[i] + (long)r->tp.dof_loc[j] * r->tp.blk[b].n] += x;
}

typedef struct wcol_ctx {
    pd_edr *r;
    int bad;
} wcol_ctx;

static void wcol_entry(void *ctx, int i, int j, double x)
{
    wcol_ctx *w = ctx;
    edr_contact *ct = &w->r->tp.ct[j];
    if (x == 0.0)
        return;
    if (ct->dof[0] < 0) {
        ct->dof[0] = i;
        ct->w[0] = x;
        /* a third nonzero: no contact of the row reference (bad: its index + 1) */
    } else if (ct->dof[1] < 0) {
        ct->dof[1] = i;
        ct->w[1] = x;
    } else
        w->bad = j + 1;
}

static int check_opts(const pd_edr_opts *o, pd_err *err)
{
    if (!(o->close_tol >= 0.0) || !isfinite(o->close_tol))
        return pd_err_set(err, PD_EINVAL, "close_tol: must be >= 0 (got %g)", o->close_tol);
    if (!(o->length_scale > 0.0) || !isfinite(o->length_scale) || !(o->time_unit > 0.0) ||
        !isfinite(o->time_unit))
        return pd_err_set(err, PD_EINVAL,
                          "row reference: the length scale and time unit must "
                          "be > 0");
    if (o->max_events < 1 || o->max_burst < 1 || o->scan_divisions < 1 || !(o->max_evals >= 1.0))
        return pd_err_set(err, PD_EINVAL,
                          "row reference: budgets and scan divisions must be "
                          ">= 1");
    if (o->impact_law != PD_IMPACT_STAGED && o->impact_law != PD_IMPACT_SINGLE)
        return pd_err_set(err, PD_EINVAL,
                          "row reference: impact_law must be staged (0) or "
                          "single (1) (got %d)",
                          (int)o->impact_law);
    if (!(o->h_out >= 0.0) || !isfinite(o->h_out) || !isfinite(o->t_measure))
        return pd_err_set(err, PD_EINVAL, "row reference: h_out and t_measure must be finite");
    /* refused here whatever the contacts (the solvers are taken for m > 1 only) */
    if (o->lcp_solver < PD_LCP_AUTO || o->lcp_solver > PD_LCP_PGS)
        return pd_err_set(err, PD_EINVAL,
                          "row reference: lcp_solver must be auto (0), lemke (1), structured (2) "
                          "or pgs (3) (got %d)",
                          (int)o->lcp_solver);
    return PD_OK;
}

/* The model, the force and the options as the row reference takes them. */
static int check_inputs(const pd_model *md, const pd_piecewise_force *F, const pd_edr_opts *o,
                        pd_err *err)
{
    int rc;
    if (!F->b || !F->pieces || F->npieces < 1)
        return pd_err_set(err, PD_EINVAL,
                          "row reference: a model and a piecewise force are "
                          "needed");
    if ((rc = pd_model_check(md, err)) || (rc = check_opts(o, err)))
        return rc;
    if (!pd_matrix_is_diagonal(&md->M))
        return pd_err_set(err, PD_EINVAL,
                          "M: the row reference needs a diagonal (lumped) mass "
                          "matrix");
    /* finite pieces, their starts strictly increasing (edr_piece_at bisects on them) */
    for (int k = 0; k < F->npieces; k++) {
        const pd_sine_piece *pc = &F->pieces[k];
        if (!isfinite(pc->t_start) || (k > 0 && !(pc->t_start > F->pieces[k - 1].t_start)) ||
            !isfinite(pc->A) || !isfinite(pc->w) || !isfinite(pc->phi) || !isfinite(pc->c0) ||
            !isfinite(pc->c1))
            return pd_err_set(err, PD_EINVAL,
                              "row reference: forcing piece %d is not finite or "
                              "not in order",
                              k);
    }
    for (int i = 0; i < md->n; i++)
        if (!isfinite(F->b[i]))
            return pd_err_set(err, PD_EINVAL,
                              "row reference: load coefficient %d is not "
                              "finite",
                              i);
    return PD_OK;
}

static int out_of_memory(const pd_edr *r, pd_err *err)
{
    return pd_err_set(err, PD_ENOMEM,
                      "out of memory for the row reference (%d dofs, %d "
                      "contacts)",
                      r->tp.n, r->tp.m);
}

/* 1 / M_ii of the lumped masses, each > 0. */
static int set_masses(pd_edr *r, pd_err *err)
{
    for (int i = 0; i < r->tp.n; i++) {
        double mi = pd_matrix_get(&r->tp.md->M, i, i);
        if (!(mi > 0.0))
            return pd_err_set(err, PD_EINVAL, "M: mass %d must be > 0 (got %g)", i, mi);
        r->tp.minv[i] = 1.0 / mi;
    }
    return PD_OK;
}

/* The blocks: the components of C and K's couplings (union-find in uf),
 * each numbered at its root (dof_blk of the root); returns their count. */
static int find_blocks(pd_edr *r, int *uf)
{
    for (int i = 0; i < r->tp.n; i++)
        uf[i] = i;
    /* C_ij != 0 or K_ij != 0 (i != j) puts dofs i and j in one structure */
    for_each_entry(&r->tp.md->C, join_entry, uf);
    for_each_entry(&r->tp.md->K, join_entry, uf);
    int nb = 0;
    for (int i = 0; i < r->tp.n; i++)
        if (uf_find(uf, i) == i)
            r->tp.dof_blk[i] = nb++;
    return nb;
}

/* Each dof's block and local index, each block's dofs (blk_dofs[first ..
 * first + n)) and the offset of its dense n_b x n_b matrices; returns
 * their total size, sum n_b^2. */
static long lay_out_blocks(pd_edr *r, int *uf)
{
    /* a root's dof_blk holds its block's number: every dof takes its root's */
    for (int i = 0; i < r->tp.n; i++) {
        int b = r->tp.dof_blk[uf_find(uf, i)];
        r->tp.dof_blk[i] = b;
        r->tp.dof_loc[i] = r->tp.blk[b].n++;
    }
    /* the blocks' dofs contiguous in blk_dofs, in block order; their matrices
     * n_b x n_b column-major from blk_off[b] */
    long off = 0;
    int at = 0;
    for (int b = 0; b < r->tp.nb; b++) {
        r->tp.blk[b].first = at;
        at += r->tp.blk[b].n;
        r->tp.blk_off[b] = off;
        off += (long)r->tp.blk[b].n * r->tp.blk[b].n;
        r->tp.blk[b].sdof = r->tp.blk[b].n == 1;
    }
    r->tp.blk_off[r->tp.nb] = off;
    for (int i = 0; i < r->tp.n; i++)
        r->tp.blk_dofs[r->tp.blk[r->tp.dof_blk[i]].first + r->tp.dof_loc[i]] = i;
    return off;
}

/* C and K block by block, and an SDOF block's scalars m, c, k, b. */
static int fill_blocks(pd_edr *r, pd_err *err)
{
    fill_ctx fc = {.r = r, .dst = r->tp.Cb};
    for_each_entry(&r->tp.md->C, fill_entry, &fc);
    fc.dst = r->tp.Kb;
    for_each_entry(&r->tp.md->K, fill_entry, &fc);
    for (int b = 0; b < r->tp.nb; b++) {
        edr_block *bk = &r->tp.blk[b];
        if (!bk->sdof)
            continue;
        /* an SDOF block's scalars: its 1 x 1 M, C, K and load coefficient */
        int i = r->tp.blk_dofs[bk->first];
        bk->m = 1.0 / r->tp.minv[i];
        bk->c = r->tp.Cb[r->tp.blk_off[b]];
        bk->k = r->tp.Kb[r->tp.blk_off[b]];
        bk->b = r->tp.b[i];
        if (bk->k < 0.0 || bk->c < 0.0)
            return pd_err_set(err, PD_EINVAL, "K, C: dof %d has a negative stiffness or damping",
                              i);
    }
    return PD_OK;
}

/* Spring j's entries of S: their count and the last one's dof and value. */
typedef struct spring_col_ctx {
    int *count, *dof, *dof2;
    double *val, *val2;
} spring_col_ctx;

/* S's entries: a column's first into (dof, val), its second into (dof2, val2). */
static void spring_entry(void *ctx, int i, int j, double x)
{
    spring_col_ctx *c = ctx;
    if (x == 0.0)
        return;
    if (c->count[j]++ == 0) {
        c->dof[j] = i;
        c->val[j] = x;
    } else {
        c->dof2[j] = i;
        c->val2[j] = x;
    }
}

/* The yielding springs: each a drift of one structure (its S column one
 * entry, an SDOF's or a first storey's, or two, a storey's above the
 * first); on an SDOF one a structure, its post-yield stiffness k - sig^2
 * ks >= 0; each block's springs listed (blk_sp). */
static int set_springs(pd_edr *r, pd_err *err)
{
    const pd_model *md = r->tp.md;
    for (int b = 0; b < r->tp.nb; b++) {
        r->tp.blk[b].spring = -1;
        r->tp.blk[b].nsp = 0;
    }
    if (r->tp.ns == 0)
        return PD_OK;
    int *cnt = pd_calloc(r->tp.ns, sizeof(int));
    if (!cnt)
        return out_of_memory(r, err);
    for (int j = 0; j < r->tp.ns; j++)
        r->tp.sp_dof2[j] = -1;
    spring_col_ctx c = {.count = cnt,
                        .dof = r->tp.sp_dof,
                        .dof2 = r->tp.sp_dof2,
                        .val = r->tp.sp_sig,
                        .val2 = r->tp.sp_sig2};
    for_each_entry(&md->S, spring_entry, &c);
    int rc = PD_OK;
    for (int j = 0; j < r->tp.ns && !rc; j++) {
        int i = r->tp.sp_dof[j], i2 = r->tp.sp_dof2[j];
        int b = cnt[j] >= 1 && cnt[j] <= 2 ? r->tp.dof_blk[i] : -1;
        edr_block *bk = b >= 0 ? &r->tp.blk[b] : NULL;
        double sg = r->tp.sp_sig[j];
        if (!bk || (i2 >= 0 && r->tp.dof_blk[i2] != b))
            rc = pd_err_set(err, PD_EINVAL,
                            "uy: row reference: yielding spring %d's drift takes %d dofs%s (a "
                            "storey's drift: one structure's, one or two dofs)",
                            j, cnt[j], bk ? " of two structures" : "");
        else if (bk->sdof && bk->spring >= 0)
            rc = pd_err_set(err, PD_EINVAL,
                            "uy: row reference: dof %d has two yielding springs (%d and %d)", i,
                            bk->spring, j);
        else if (bk->sdof && bk->k - sg * sg * md->ks[j] < -1e-12 * bk->k)
            rc = pd_err_set(err, PD_EINVAL,
                            "uy: row reference: yielding spring %d leaves dof %d a negative "
                            "post-yield stiffness (k %g < sig^2 ks %g)",
                            j, i, bk->k, sg * sg * md->ks[j]);
        else {
            bk->spring = bk->sdof ? j : -1;
            bk->nsp++;
        }
    }
    /* each block's springs, in order: sp0 the running sum of the counts */
    for (int b = 0, at = 0; b < r->tp.nb && !rc; b++) {
        r->tp.blk[b].sp0 = at;
        at += r->tp.blk[b].nsp;
        r->tp.blk[b].nsp = 0;
    }
    for (int j = 0; j < r->tp.ns && !rc; j++) {
        edr_block *bk = &r->tp.blk[r->tp.dof_blk[r->tp.sp_dof[j]]];
        r->tp.blk_sp[bk->sp0 + bk->nsp++] = j;
    }
    free(cnt);
    return rc;
}

/* The contacts from W's columns: one or two dofs each, in different
 * structures (g = g0 + w0 x_dof0 + w1 x_dof1). */
static int set_contacts(pd_edr *r, pd_err *err)
{
    for (int a = 0; a < r->tp.m; a++)
        r->tp.ct[a] = (edr_contact){
            .dof = {-1, -1}, .blk = {-1, -1}, .g0 = r->tp.md->g0[a], .e = r->tp.md->e[a]};
    wcol_ctx wc = {.r = r, .bad = 0};
    for_each_entry(&r->tp.md->W, wcol_entry, &wc);
    /* a first side always, a second (if any) in another structure */
    for (int a = 0; a < r->tp.m && !wc.bad; a++) {
        edr_contact *ct = &r->tp.ct[a];
        if (ct->dof[0] < 0)
            wc.bad = a + 1;
        for (int s = 0; s < 2; s++)
            ct->blk[s] = ct->dof[s] >= 0 ? r->tp.dof_blk[ct->dof[s]] : -1;
        if (ct->dof[1] >= 0 && ct->blk[0] == ct->blk[1])
            wc.bad = a + 1;
    }
    if (wc.bad)
        return pd_err_set(err, PD_EINVAL,
                          "W: contact %d must join one dof of one structure to "
                          "one of another, or to a wall (the row reference)",
                          wc.bad - 1);
    return PD_OK;
}

/* The contacts of each block (blk_cont[cont0 .. cont0 + ncont)) and of
 * each dof (dofc[dofc_ptr[i] .. dofc_ptr[i + 1]), uf counting each dof's
 * filled); returns the Delassus matrix's largest pattern, sum over the
 * dofs of (contacts at the dof)^2. */
static long link_contacts(pd_edr *r, int *uf)
{
    int n = r->tp.n, m = r->tp.m;
    /* count: contacts per block (ncont) and per dof (dofc_ptr[i + 1]) */
    for (int a = 0; a < m; a++)
        for (int s = 0; s < 2; s++)
            if (r->tp.ct[a].dof[s] >= 0) {
                r->tp.blk[r->tp.ct[a].blk[s]].ncont++;
                r->tp.dofc_ptr[r->tp.ct[a].dof[s] + 1]++;
            }
    /* each block's list starts at cont0; its count restarts for the filling */
    for (int b = 0, c0 = 0; b < r->tp.nb; b++) {
        r->tp.blk[b].cont0 = c0;
        c0 += r->tp.blk[b].ncont;
        r->tp.blk[b].ncont = 0;
    }
    /* prefix sums: dof i's contacts from dofc_ptr[i] */
    for (int i = 0; i < n; i++)
        r->tp.dofc_ptr[i + 1] += r->tp.dofc_ptr[i];
    long dnnz = 0;
    for (int a = 0; a < m; a++)
        for (int s = 0; s < 2; s++) {
            int dof = r->tp.ct[a].dof[s];
            if (dof < 0)
                continue;
            edr_block *bk = &r->tp.blk[r->tp.ct[a].blk[s]];
            r->tp.blk_cont[bk->cont0 + bk->ncont++] = a;
        }
    /* uf[i]: the contacts filled so far into dof i's list */
    for (int i = 0; i < n; i++)
        uf[i] = 0;
    for (int a = 0; a < m; a++)
        for (int s = 0; s < 2; s++) {
            int dof = r->tp.ct[a].dof[s];
            if (dof >= 0)
                r->tp.dofc[r->tp.dofc_ptr[dof] + uf[dof]++] = a;
        }
    for (int i = 0; i < n; i++) {
        /* a dof with dg contacts couples each pair of them in D: dg^2 entries at most */
        long dg = r->tp.dofc_ptr[i + 1] - r->tp.dofc_ptr[i];
        dnnz += dg * dg;
    }
    return dnnz;
}

/* The dof-level LCPs' solver (m contacts, Dcap entries) and the clusters'
 * dense Lemke (dm contacts); none for one contact (closed forms). */
static int alloc_solvers(pd_edr *r, int dm, pd_err *err)
{
    if (r->tp.m > 1 &&
        (!(r->ev.solver = pd_lcp_solver_alloc(r->tp.o.lcp_solver, r->tp.m, r->ev.Dcap, err)) ||
         !(r->ev.dsolver = pd_lcp_solver_alloc(PD_LCP_LEMKE, dm, 0, err))))
        return err && err->status ? err->status : PD_ENOMEM;
    return PD_OK;
}

/* The model's blocks and contacts, then the run's arrays and solvers,
 * each stage's arrays allocated once its sizes are known; uf: n ints of
 * scratch.  A failure's status (err set). */
static int build(pd_edr *r, const pd_piecewise_force *F, int *uf, pd_err *err)
{
    edr_sizes sizes = {.n = r->tp.n, .m = r->tp.m, .npieces = F->npieces};
    int rc;
    if (alloc_model_arrays(r, &sizes))
        return out_of_memory(r, err);
    memcpy(r->tp.b, F->b, (size_t)r->tp.n * sizeof(double));
    memcpy(r->tp.pieces, F->pieces, (size_t)F->npieces * sizeof(pd_sine_piece));
    r->tp.npieces = F->npieces;
    if ((rc = set_masses(r, err)))
        return rc;
    sizes.nb = r->tp.nb = find_blocks(r, uf);
    if (alloc_block_arrays(r, &sizes))
        return out_of_memory(r, err);
    sizes.nentries = lay_out_blocks(r, uf);
    if (alloc_matrix_arrays(r, &sizes))
        return out_of_memory(r, err);
    if ((rc = fill_blocks(r, err)) || (rc = set_contacts(r, err)))
        return rc;
    sizes.ns = r->tp.ns = r->tp.md->ns;
    if (alloc_spring_arrays(r, &sizes))
        return out_of_memory(r, err);
    if ((rc = set_springs(r, err)))
        return rc;
    /* D's entries: at most sum over the dofs of dg^2; m more to spare */
    r->ev.Dcap = link_contacts(r, uf) + r->tp.m;
    int dm = r->tp.m < EDR_REDUCED_MAX ? r->tp.m : EDR_REDUCED_MAX;
    sizes.nslot = r->tp.m + r->tp.nb + 2 + r->tp.ns;
    sizes.dm = dm;
    sizes.dcap = r->ev.Dcap;
    sizes.nmeas = 2L * r->tp.n;
    if (alloc_run_arrays(r, &sizes))
        return out_of_memory(r, err);
    return alloc_solvers(r, dm, err);
}

pd_edr *pd_edr_alloc(const pd_model *md, const pd_piecewise_force *F, const pd_edr_opts *opts,
                     pd_err *err)
{
    pd_edr_opts o = opts ? *opts : pd_edr_default_opts();
    pd_err_clear(err);
    if (!md || !F) {
        PD_NULL_ARG(err, !md ? "model" : "force");
        return NULL;
    }
    if (check_inputs(md, F, &o, err))
        return NULL;
    pd_edr *r = calloc(1, sizeof *r);
    if (!r) {
        pd_err_set(err, PD_ENOMEM, "out of memory for the row reference");
        return NULL;
    }
    r->tp.md = md;
    r->tp.o = o;
    r->tp.n = md->n;
    r->tp.m = md->m;
    /* uf: the blocks' union-find, then link_contacts' fill counts */
    int *uf = pd_malloc(r->tp.n, sizeof *uf);
    int rc = uf ? build(r, F, uf, err) : out_of_memory(r, err);
    free(uf);
    if (rc) {
        pd_edr_free(r);
        return NULL;
    }
    /* the queue's last two slots: the piece change and the output */
    r->rs.slot_piece = r->tp.m + r->tp.nb;
    r->rs.slot_out = r->tp.m + r->tp.nb + 1;
    r->rs.slot_spring0 = r->tp.m + r->tp.nb + 2;
    return r;
}

/* ---- the run -------------------------------------------------------------------------------- */

static void reset(pd_edr *r, double t0, const double *q0, const double *v0, double t1)
{
    int n = r->tp.n, m = r->tp.m;
    memset(&r->rs.res, 0, sizeof r->rs.res);
    r->rs.res.first_impact = NAN;
    r->rs.e_input = r->rs.e_damping = r->rs.e_impact = r->rs.ke_group = 0.0;
    r->rs.t = t0;
    r->rs.t1 = t1;
    r->rs.L = r->tp.o.length_scale;
    r->rs.piece = edr_piece_at(r, t0);
    /* the queue empty: every slot out of it (pos -1, key +inf) */
    r->rs.q.n = 0;
    for (int k = 0; k < m + r->tp.nb + 2 + r->tp.ns; k++) {
        r->rs.q.pos[k] = -1;
        r->rs.q.key[k] = HUGE_VAL;
    }
    for (int i = 0; i < n; i++) {
        r->rs.xo[i] = q0 ? q0[i] : 0.0;
        r->rs.vo[i] = v0 ? v0[i] : 0.0;
        /* extremes from -inf: finish zeroes those never measured */
        r->rs.xpos[i] = r->rs.xneg[i] = r->rs.drift[i] = -HUGE_VAL;
        r->ev.loc[i] = -1;
    }
    /* a gap within the closing tolerance is closed: a row touching at gaps
     * of 1e-300 runs as the row touching at 0, not as a cascade of bounces
     * across gaps no event could tell apart */
    for (int a = 0; a < m; a++) {
        double g0 = r->tp.md->g0[a];
        r->tp.ct[a].g0 = g0 > 0.0 && g0 <= r->tp.o.close_tol * r->rs.L ? 0.0 : g0;
    }
    for (int a = 0; a < m; a++) {
        /* every contact open with no exact gap (base_t -inf), minimum +inf, counts 0 */
        r->rs.cstate[a] = EDR_OPEN;
        r->rs.pers_next[a] = -1;
        r->rs.base_t[a] = -HUGE_VAL;
        r->rs.gmeas_t[a] = t0;
        r->rs.gmin[a] = HUGE_VAL;
        r->rs.impacts[a] = 0;
        r->rs.first[a] = NAN;
        r->rs.maxP[a] = r->rs.ctime[a] = r->rs.imp_out[a] = 0.0;
        r->rs.burst[a] = 0;
        r->rs.since[a] = t0;
    }
    /* every cluster slot free, stacked so that start gives block b slot b */
    r->rs.nfree = 0;
    for (int c = r->tp.nb - 1; c >= 0; c--) {
        r->rs.cl[c].live = 0;
        r->rs.free_cl[r->rs.nfree++] = c;
    }
    /* marks zeroed and epochs restarted: the first group's epoch, 1, matches none */
    r->ev.epoch = r->ev.epochD = 0;
    memset(r->ev.cl_mark, 0, (size_t)r->tp.nb * sizeof *r->ev.cl_mark);
    memset(r->ev.ct_mark, 0, (size_t)m * sizeof *r->ev.ct_mark);
    memset(r->ev.ct_mark2, 0, (size_t)m * sizeof *r->ev.ct_mark2);
    memset(r->ev.ct_markD, 0, (size_t)m * sizeof *r->ev.ct_markD);
    memset(r->ev.ct_markP, 0, (size_t)m * sizeof *r->ev.ct_markP);
    r->ev.epochP = 0;
    for (int k = 0; k < m + r->tp.nb + 2 + r->tp.ns; k++) {
        /* NaN: no event yet (it equals no t) */
        r->rs.slot_t[k] = NAN;
        r->rs.slot_same[k] = 0;
        r->rs.slot_run[k] = 0;
        r->rs.slot_t0[k] = t0;
    }
    for (int j = 0; j < r->tp.ns; j++) { /* every spring elastic, unmoved */
        r->rs.sp_phase[j] = 0;
        r->rs.sp_up[j] = r->rs.sp_upx[j] = r->rs.sp_exc[j] = r->rs.sp_now[j] = 0.0;
        r->rs.sp_onsets[j] = 0;
    }
    r->rs.stopped = 0;
    r->rs.vscale = 0.0;
    r->rs.evals = 0;
}

/* Every structure alone at t0; contacts closed at t0 resolved. */
static int start(pd_edr *r, double t0, pd_err *err)
{
    int rc;
    /* every structure a cluster of its own, its flight from (q0, v0) */
    for (int b = 0; b < r->tp.nb; b++) {
        int c = r->rs.free_cl[--r->rs.nfree];
        edr_cluster *cl = &r->rs.cl[c];
        cl->live = 1;
        cl->head = b;
        cl->nblk = 1;
        cl->pers_head = -1;
        cl->npers = 0;
        cl->meas_t = t0;
        r->rs.blk_cl[b] = c;
        r->rs.blk_next[b] = -1;
        if ((rc = edr_cluster_start(r, c, t0, err)))
            return rc;
    }
    /* a gap below -tol at t0: the structures start overlapping */
    double tol = r->tp.o.close_tol * r->rs.L;
    for (int a = 0; a < r->tp.m; a++) {
        double g = gap_now(r, a, t0, NULL);
        if (g < -tol && !r->tp.o.inactive)
            return pd_err_set(err, PD_EINVAL, "q0: contact %d starts with a negative gap (%g)", a,
                              g);
    }
    /* contacts closed at t0 resolve at t0 (an impact, or persistence) */
    if (!r->tp.o.inactive)
        for (int a = 0; a < r->tp.m; a++) {
            if (r->rs.cstate[a] != EDR_OPEN || !(gap_now(r, a, t0, NULL) <= tol))
                continue;
            group_begin(r);
            group_add_contact(r, a);
            const edr_contact *ct = &r->tp.ct[a];
            for (int s = 0; s < 2; s++)
                if (ct->dof[s] >= 0)
                    group_add_cluster(r, cl_of_dof(r, ct->dof[s]));
            if ((rc = impact_group(r, t0, err)))
                return rc;
        }
    /* every prediction, and the first piece change */
    for (int a = 0; a < r->tp.m; a++)
        predict_contact(r, a, t0, 0);
    for (int c = 0; c < r->tp.nb; c++)
        if (r->rs.cl[c].live) {
            predict_detach(r, c, t0, 0);
            predict_cluster_springs(r, c, t0);
        }
    double next = edr_piece_end(r, r->rs.piece);
    q_set(&r->rs.q, r->rs.slot_piece, next < r->rs.t1 ? next : HUGE_VAL);
    return PD_OK;
}

/* The kinetic and strain energies of the state (q, v) (global index) with
 * the springs' offsets up: v^T M v / 2, q^T K q / 2 - sum ks up d + sum
 * ks up^2 / 2 (the storeys' alpha k d^2 / 2 and the springs' ks z^2 / 2). */
static void state_energy(const pd_edr *r, const double *q, const double *v, const double *up,
                         double *kinetic, double *strain)
{
    double ke = 0.0, se = 0.0;
    for (int b = 0; b < r->tp.nb; b++) {
        const edr_block *bk = &r->tp.blk[b];
        const double *Kb = r->tp.Kb + r->tp.blk_off[b];
        ke += kinetic_of(r, r->tp.blk_dofs + bk->first, bk->n, v);
        for (int l = 0; l < bk->n; l++) {
            int gi = r->tp.blk_dofs[bk->first + l];
            for (int k = 0; k < bk->n; k++) /* K_b column-major */
                se += 0.5 * q[gi] * Kb[l + (long)k * bk->n] * q[r->tp.blk_dofs[bk->first + k]];
        }
    }
    for (int j = 0; j < r->tp.ns; j++)
        se += r->tp.md->ks[j] * up[j] * (0.5 * up[j] - edr_spring_drift(r, j, q));
    *kinetic = ke;
    *strain = se;
}

/* The energy balance's terms at t (opts.energy): the flights' integrals to
 * t, the end state's (q, v) energies, the sliders' work. */
static void finish_energy(pd_edr *r, double t, const double *q, const double *v)
{
    pd_edr_result *res = &r->rs.res;
    for (int c = 0; c < r->tp.nb; c++)
        if (r->rs.cl[c].live)
            integrate_energy(r, c, t);
    state_energy(r, q, v, r->rs.sp_now, &res->kinetic, &res->strain);
    res->hysteretic = 0.0;
    for (int j = 0; j < r->tp.ns; j++) /* a slide's work: ks z dup = ks uy |dup| */
        res->hysteretic += r->tp.md->ks[j] * r->tp.md->uy[j] * r->rs.sp_exc[j];
    res->input_work = r->rs.e_input;
    res->damping_work = r->rs.e_damping;
    res->impact_loss = r->rs.e_impact;
}

/* Close the run at t: extremes and gaps to t, contact times. */
static void finish(pd_edr *r, double t)
{
    for (int c = 0; c < r->tp.nb; c++)
        if (r->rs.cl[c].live)
            measure_cluster(r, c, t);
    for (int a = 0; a < r->tp.m; a++) {
        measure_contact(r, a, t);
        /* a contact held at the end (persistent or locked): its time in contact up to t */
        if (r->rs.cstate[a] != EDR_OPEN && t > r->rs.since[a])
            r->rs.ctime[a] += t - r->rs.since[a];
        /* never measured (never open, or no time to measure): its gap at t */
        if (!(r->rs.gmin[a] < HUGE_VAL))
            r->rs.gmin[a] = gap_now(r, a, t, NULL);
    }
    for (int i = 0; i < r->tp.n; i++) {
        /* NaN becomes -inf; -inf: never measured (t_measure at or past t), extremes 0 */
        r->rs.xpos[i] = pd_max(r->rs.xpos[i], -HUGE_VAL);
        if (!(r->rs.xpos[i] > -HUGE_VAL))
            r->rs.xpos[i] = r->rs.xneg[i] = r->rs.drift[i] = 0.0;
    }
    double *q = r->ev.wk + r->tp.n, *v = r->ev.wk + 2 * r->tp.n; /* the state at t */
    for (int i = 0; i < r->tp.n; i++) {
        double a;
        dof_state(r, i, t, &q[i], &v[i], &a);
    }
    spring_offsets(r, q);
    for (int j = 0; j < r->tp.ns; j++) /* a slide under way: its excursion up to t */
        if (r->rs.sp_phase[j] != 0) {
            r->rs.sp_exc[j] += fabs(r->rs.sp_now[j] - r->rs.sp_upx[j]);
            r->rs.sp_upx[j] = r->rs.sp_now[j];
        }
    if (r->tp.o.energy)
        finish_energy(r, t, q, v);
    r->rs.res.t_reached = t;
    r->rs.res.evals = (double)r->rs.evals;
}

int pd_edr_run(pd_edr *r, double t0, const double *q0, const double *v0, double t1, pd_observer obs,
               void *ctx, pd_err *err)
{
    int rc;
    pd_err_clear(err);
    if (!r)
        return PD_NULL_ARG(err, "r");
    if (!isfinite(t0) || !(t1 > t0) || !isfinite(t1))
        return pd_err_set(err, PD_EINVAL, "row reference: need t0 < t1, both finite");
    for (int i = 0; q0 && i < r->tp.n; i++)
        if (!isfinite(q0[i]) || (v0 && !isfinite(v0[i])))
            return pd_err_set(err, PD_EINVAL, "row reference: the initial state is not finite");
    /* a sampler reports impulses over each output interval: held forces integrated */
    r->rs.sample_forces = obs && r->tp.o.h_out > 0.0 && !r->tp.o.impacts_only;
    reset(r, t0, q0, v0, t1);
    if (r->tp.o.energy) /* the energies at the start (offsets 0) */
        state_energy(r, r->rs.xo, r->rs.vo, r->rs.sp_up, &r->rs.res.kinetic, &r->rs.res.strain);
    r->rs.res.energy0 = r->rs.res.kinetic + r->rs.res.strain;
    if ((rc = start(r, t0, err)))
        goto out;
    r->rs.t_out0 = t0;
    r->rs.next_out = 0;
    /* the observer's first state at t0, then the output grid */
    if (obs) {
        r->rs.st.step = 0;
        if (emit(r, t0, obs, ctx) > 0)
            goto out;
        r->rs.next_out = 1;
        if (r->tp.o.h_out > 0.0)
            q_set(&r->rs.q, r->rs.slot_out, fmin(t0 + r->tp.o.h_out, t1));
    }
    double t = t0;
    while (!r->rs.stopped) {
        /* the earliest queued time; past t1 the run is done */
        int slot = r->rs.q.n > 0 ? r->rs.q.heap[0] : -1;
        double te = slot >= 0 ? r->rs.q.key[slot] : HUGE_VAL;
        if (!(te <= t1))
            break;
        t = te;
        if (r->rs.evals > r->tp.o.max_evals) {
            rc = pd_err_set(err, PD_EBUDGET,
                            "row reference: %.3g flight evaluations by t = %.9g "
                            "s (budget exhausted)",
                            (double)r->rs.evals, t * r->tp.o.time_unit);
            break;
        }
        if (slot == r->rs.slot_out) {
            r->rs.st.step = r->rs.next_out;
            if (emit(r, t, obs, ctx) > 0)
                break;
            r->rs.next_out++;
            /* the grid t0 + k h_out, not accumulated (no drift); a point past t1
             * becomes t1 unless the last one was t1 already (to rounding) */
            double tn = r->rs.t_out0 + (double)r->rs.next_out * r->tp.o.h_out;
            if (tn > t1 && t < t1 * (1.0 - 1e-15))
                tn = t1;
            q_set(&r->rs.q, r->rs.slot_out, tn <= t1 * (1.0 + 1e-15) && tn > t ? tn : HUGE_VAL);
            continue;
        }
        if (slot == r->rs.slot_piece) {
            rc = on_piece(r, t, err);
            /* a contact's slot: a scan's continuation or an impact; a cluster's: a
         * scan's continuation or a detachment */
        } else if (slot < r->tp.m) {
            if (r->rs.qkind[slot] == EDR_Q_SCAN)
                predict_contact(r, slot, t, 1);
            else
                rc = on_impact(r, slot, t, err);
        } else if (slot >= r->rs.slot_spring0) { /* a spring's onset or unloading */
            int j = slot - r->rs.slot_spring0;
            if (r->rs.qkind[slot] == EDR_Q_SCAN)
                predict_spring(r, j, t, 1);
            else
                rc = on_spring(r, j, t, err);
        } else {
            int c = slot - r->tp.m;
            if (r->rs.qkind[slot] == EDR_Q_SCAN)
                predict_detach(r, c, t, 1);
            else
                rc = on_detach(r, c, t, err);
        }
        if (rc)
            break;
    }
    /* no error: measured up to t1, or to the event's t when its report stopped the run */
    if (!rc) {
        t = r->rs.stopped ? t : t1;
        finish(r, t);
    } else
        finish(r, t);
out:
    r->rs.res.t_reached = t1;
    if (rc)
        r->rs.res.t_reached = r->rs.t;
    return rc;
}

const pd_edr_result *pd_edr_result_of(const pd_edr *r)
{
    if (!r)
        return NULL;
    /* the arrays point into r: valid until its next run or its free */
    pd_edr_result *res = (pd_edr_result *)&r->rs.res;
    res->xpos = r->rs.xpos;
    res->xneg = r->rs.xneg;
    res->drift = r->rs.drift;
    res->contact_impacts = r->rs.impacts;
    res->first = r->rs.first;
    res->max_impulse = r->rs.maxP;
    res->contact_time = r->rs.ctime;
    res->min_gap = r->rs.gmin;
    res->modal_bases = r->rs.nbasis;
    res->ns = r->tp.ns;
    res->up = r->rs.sp_now;
    res->plastic_excursion = r->rs.sp_exc;
    res->yield_onsets = r->rs.sp_onsets;
    return res;
}
