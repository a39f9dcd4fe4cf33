/* event_row_cluster.c — clusters of the row reference and their exact flights.
 *
 * SDOF trees.  Blocks of one dof joined by persistent contacts move
 * rigidly: rooted at one dof (the one next to the wall when a wall holds
 * the tree), x_i = s_i y + d_i with s_child = -w_parent s_parent / w_child
 * and d_child = -(g0 + w_parent d_parent) / w_child (every joined gap zero).
 * Virtual work with dx_i = s_i dy gives one oscillator
 *   (sum s^2 m) y'' + (sum s^2 c) y' + (sum s^2 k) y = (sum s b) f - sum s k d,
 * underdamped (the aggregate damping ratio is at most the largest one), so
 * its flight is pd_sdof_flow's closed form.  The force of tree edge e
 * (child c) holds the child's subtree:
 *   lambda_e = sum_sub s (m s y'' + c s y' + k (s y + d) - b f) / (s_c w_c),
 * linear in (y, y', f).  Held by a wall the tree cannot move (REST): y is
 * fixed and every force is linear in f.
 *
 * Modal clusters.  With the persistent contacts' directions W (n_c x r,
 * independent columns kept; a dependent one is LOCKED: its gap is held at
 * zero by the others), q = q* + N y, N an orthonormal basis of W's null
 * space and q* the least-norm point of W^T q = -g0:
 *   Mr y'' + Cr y' + Kr y = br f + kr,   Mr = N^T M N, ..., kr = -N^T K q*.
 * The first-order system z' = S z + (0, Mr^-1 br) f + (0, Mr^-1 kr) is
 * diagonalised, S = V diag(lam) V^-1 (GSL's nonsymmetric eigensolver,
 * balanced); each mode eta = (V^-1 z)_j obeys eta' = lam eta + beta f + kap
 * and has the exact flight, over s from its origin under
 * f = A sin(w t + phi) + c0 + c1 (t - t_start),
 *   eta(s) - eta0 = (e^{lam s} - 1) eta0 + s phi1(lam s) (beta f_lin0 + kap)
 *                 + s^2 phi2(lam s) beta c1
 *                 + beta A / (2i) [e^{i th} s phi1((lam - i w) s) - e^{-i th} s phi1((lam + i w) s)],
 * th the forcing phase at t, phi1(z) = (e^z - 1)/z, phi2(z) = (e^z - 1 - z)/z^2
 * (Taylor series for |z| < 1): resonance and every damping need no special
 * case.  Conjugate modes are kept once with weight 2.  Contact forces:
 * lambda = L (M a + C v + K q - b f), L = (W^T W)^-1 W^T, folded into the
 * modes.  The basis of a configuration (blocks, persistent contacts) is
 * computed once and cached: a row meets few configurations. */
#include <gsl/gsl_complex_math.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "event_row.h"
#include "pd_alloc.h"

/* A constraint direction within this (relative) of the span of the others
 * is dependent: the contact is LOCKED. */
#define DEPENDENT_TOL 1e-10
/* Eigenvector bases worse conditioned than this are refused (a nearly
 * defective cluster: critically damped modes). */
#define MODAL_COND_MAX 1e10
/* The flight's Taylor series: degree, and its reach Omega s (remainder
 * below (Omega s)^8 / 8! ~ 2.5e-21 of the motion's scale). */
#define EDR_TAYLOR_REACH 0.01
/* Buckets of the configuration cache. */
#define BASIS_BUCKETS 1024

/* ---- forcing ------------------------------------------------------------------ */

double edr_force(const pd_edr *r, int j, double t)
{
    return pd_sine_piece_force(&r->tp.pieces[j], t);
}

double edr_piece_end(const pd_edr *r, int j)
{
    return j + 1 < r->tp.npieces ? r->tp.pieces[j + 1].t_start : HUGE_VAL;
}

int edr_piece_at(const pd_edr *r, double t)
{
    int lo = 0, hi = r->tp.npieces - 1;
    while (lo < hi) { /* the last piece starting at or before t */
        int mid = (lo + hi + 1) / 2;
        if (r->tp.pieces[mid].t_start <= t)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

/* Shortest period of piece j's sinusoid (HUGE_VAL: none). */
static double piece_period(const pd_edr *r, int j)
{
    const pd_sine_piece *pc = &r->tp.pieces[j];
    return pc->A != 0.0 && pc->w > 0.0 ? PD_TWO_PI / pc->w : HUGE_VAL;
}

/* ---- complex helpers ----------------------------------------------------------- */

/* GSL's complex number as C's: re + i im. */
static edr_cplx cplx_of(gsl_complex z)
{
    return GSL_REAL(z) + I * GSL_IMAG(z);
}

/* ---- the SDOF tree -------------------------------------------------------------- */

/* The side of contact a at dof i: 0 or 1. */
static int side_of(const edr_contact *ct, int i)
{
    return ct->dof[0] == i ? 0 : 1;
}

/* The cluster's persistent wall contact, or -1. */
static int wall_edge(const pd_edr *r, const edr_cluster *c)
{
    for (int a = c->pers_head; a >= 0; a = r->rs.pers_next[a])
        if (r->tp.ct[a].dof[0] < 0 || r->tp.ct[a].dof[1] < 0) /* a wall's side has no dof */
            return a;
    return -1;
}

/* Unlink contact a from the cluster's persistent list and lock it. */
static void lock_contact(pd_edr *r, edr_cluster *c, int a)
{
    int *p = &c->pers_head; /* the link that points at a (singly linked list) */
    while (*p >= 0 && *p != a)
        p = &r->rs.pers_next[*p];
    if (*p == a) {
        *p = r->rs.pers_next[a];
        c->npers--;
    }
    r->rs.pers_next[a] = -1;
    r->rs.cstate[a] = EDR_LOCKED;
}

/* Breadth-first numbering of the tree from the root: s, d, the parent
 * edge and dof of each node; a persistent edge that closes a cycle (or a
 * second wall) is locked.  ord receives the nodes in order; returns their
 * count. */
static int tree_order(pd_edr *r, edr_cluster *c, int root, int wedge, int *ord, int *pe, int *pd)
{
    int nn = 0, head = 0; /* ord[head..nn) is the queue: reached, edges not yet followed */
    for (int b = c->head; b >= 0; b = r->rs.blk_next[b]) /* loc < 0: not reached yet */
        r->ev.loc[r->tp.blk_dofs[r->tp.blk[b].first]] = -1;
    /* the root carries the coordinate itself: x_root = y */
    r->rs.s[root] = 1.0;
    r->rs.d[root] = 0.0;
    r->ev.loc[root] = 0;
    pe[root] = wedge;
    pd[root] = -1;
    ord[nn++] = root;
    while (head < nn) {
        int u = ord[head++];
        const edr_block *bk = &r->tp.blk[r->tp.dof_blk[u]];
        for (int k = 0; k < bk->ncont; k++) {
            int a = r->tp.blk_cont[bk->cont0 + k];
            if (r->rs.cstate[a] != EDR_PERSIST || a == pe[u]) /* not back up the parent edge */
                continue;
            const edr_contact *ct = &r->tp.ct[a];
            int su = side_of(ct, u), v = ct->dof[1 - su];
            if (v < 0 || r->ev.loc[v] >= 0) { /* a second wall, or a cycle */
                lock_contact(r, c, a);
                continue;
            }
            /* the gap g0 + wu x_u + wv x_v stays zero: x_v = -(g0 + wu x_u) / wv */
            double wu = ct->w[su], wv = ct->w[1 - su];
            r->rs.s[v] = -wu * r->rs.s[u] / wv;
            r->rs.d[v] = -(ct->g0 + wu * r->rs.d[u]) / wv;
            r->ev.loc[v] = nn;
            pe[v] = a;
            pd[v] = u;
            ord[nn++] = v;
        }
    }
    return nn;
}

/* The flight's Taylor coefficients at its origin, y_k = y^(k)(t0) for
 * k <= EDR_TAYLOR_N + 2 by y'' = F - 2 xi w0 y' - w0^2 y differentiated
 * (F the scaled piece), and the unscaled piece's f_k: near the origin
 * (Omega s <= EDR_TAYLOR_REACH) the series is the flight to rounding. */
static void taylor_init(pd_edr *r, edr_cluster *c, double t)
{
    const pd_sine_piece *p = &r->tp.pieces[c->piece], *q = &c->pc;
    double th = p->w * t + p->phi, sn = sin(th), cs = cos(th), w0 = c->osc.w0;
    /* d^k/dt^k sin(th) = sin(th + k pi / 2), one of cyc[k % 4]; wk = w^k */
    double cyc[4] = {sn, cs, -sn, -cs}, wk = 1.0, a2 = c->a2, k0 = w0 * w0;
    double *y = c->tay, *f = c->ftay;
    y[0] = c->y0;
    y[1] = c->vy0;
    for (int k = 0; k <= EDR_TAYLOR_N; k++) {
        double Fk = 0.0, fk = 0.0;
        if (p->A != 0.0) {
            Fk = q->A * wk * cyc[k % 4];
            fk = p->A * wk * cyc[k % 4];
        }
        if (k == 0) { /* the ramp c0 + c1 (t - t_start): its value, then its slope */
            Fk += q->c0 + q->c1 * (t - q->t_start);
            fk += p->c0 + p->c1 * (t - p->t_start);
        } else if (k == 1) {
            Fk += q->c1;
            fk += p->c1;
        }
        f[k] = fk;
        /* y^(k+2) = F^(k) - 2 xi w0 y^(k+1) - w0^2 y^(k) */
        y[k + 2] = Fk - a2 * y[k + 1] - k0 * y[k];
        wk *= p->w;
    }
    /* Omega, the flight's fastest rate: the series serves for |s| <= REACH / Omega */
    double Om = fmax(w0, p->A != 0.0 ? p->w : 0.0);
    if (c->mass_flight) /* the damped mass's rate */
        Om = fmax(Om, a2);
    c->s_taylor = Om > 0.0 ? EDR_TAYLOR_REACH / Om : 0.0;
}

/* Bounds on |y^(k)|, k = 1..3, over an SDOF tree's flight (until its
 * piece ends), and on the piece's |f'|, |f''|: without a ramp the flight
 * is a constant plus the sinusoid's particular solution (amplitude P) plus
 * e^{-a s} (c1 cos + c2 sin) (amplitude R, each derivative a factor w0 at
 * most), so |y^(k)| <= w^k P + w0^k R.  Held still (REST): zero.  Other
 * flights (a ramp, a free mass, resonance, modal clusters) have none:
 * their predictions scan. */
static void flight_bounds(pd_edr *r, edr_cluster *c)
{
    const pd_sine_piece *p = &r->tp.pieces[c->piece];
    c->bnd = 0;
    /* f = A sin(w t + phi) + c0 + c1 (t - t_start): |f'| <= |A| w + |c1|, |f''| <= |A| w^2 */
    c->F1 = fabs(p->A) * p->w + fabs(p->c1);
    c->F2 = fabs(p->A) * p->w * p->w;
    if (c->kind == EDR_REST) {
        c->bnd = 1;
        c->Y1 = c->Y2 = c->Y3 = 0.0;
        return;
    }
    const pd_sdof_flow *f = &c->flow;
    if (c->kind != EDR_SDOF || !f->fast || !f->constf) /* no closed bound: scans */
        return;
    double w = c->pc.A != 0.0 ? c->pc.w : 0.0, w0 = c->osc.w0;
    double P = c->pc.A != 0.0 ? hypot(f->pre, f->pim) : 0.0, R = hypot(f->c1, f->c2);
    /* |y^(k)| <= w^k P + w0^k R: a derivative multiplies the particular part's
     * amplitude by w, the free part's by |-a + i w_d| = w0 */
    c->Y1 = w * P + w0 * R;
    c->Y2 = w * w * P + w0 * w0 * R;
    c->Y3 = w * w * w * P + w0 * w0 * w0 * R;
    c->bnd = 1;
}

/* A post-yield stiffness below this share of the initial one is none (an
 * elastic-perfectly-plastic spring's k - sig^2 ks, zero up to rounding). */
#define EDR_KEFF_ZERO 1e-12

void edr_block_stiffness(const pd_edr *r, int b, double *keff, double *r0)
{
    const edr_block *bk = &r->tp.blk[b];
    int j = bk->spring;
    *keff = bk->k;
    *r0 = 0.0;
    if (j < 0)
        return;
    double sg = r->tp.sp_sig[j], ks = r->tp.md->ks[j], ph = r->rs.sp_phase[j];
    if (ph == 0.0) { /* elastic: up fixed */
        *r0 = -sg * ks * r->rs.sp_up[j];
        return;
    }
    /* sliding: up = sg x - ph uy, so k x - sg ks up = (k - sg^2 ks) x + sg ks ph uy */
    double k = bk->k - sg * sg * ks;
    *keff = k > EDR_KEFF_ZERO * bk->k ? k : 0.0;
    *r0 = sg * ks * ph * r->tp.md->uy[j];
}

/* The tree's per-node terms summed over each node's subtree (in r->ev.wk). */
typedef struct tree_sums {
    double *Ms, *Cs, *Ks; /* sum s^2 m, sum s^2 c, sum s^2 k */
    double *KDs, *Bs;     /* sum s k d, sum s b */
} tree_sums;

/* Subtree sums of s^2 m, s^2 c, s^2 k, s k d, s b: at the root, the
 * oscillator's M, C, K and its load terms. */
static tree_sums subtree_sums(pd_edr *r, const int *ord, const int *pd, int nn)
{
    double *wk = r->ev.wk; /* 5 n of its 8 n */
    tree_sums S = {.Ms = wk,
                   .Cs = wk + r->tp.n,
                   .Ks = wk + 2 * r->tp.n,
                   .KDs = wk + 3 * r->tp.n,
                   .Bs = wk + 4 * r->tp.n};
    for (int k = 0; k < nn; k++) { /* each node's own terms */
        int i = ord[k];
        const edr_block *bk = &r->tp.blk[r->tp.dof_blk[i]];
        double s = r->rs.s[i];
        S.Ms[i] = s * s * bk->m;
        S.Cs[i] = s * s * bk->c;
        if (bk->spring < 0) {
            S.Ks[i] = s * s * bk->k;
            S.KDs[i] = s * bk->k * r->rs.d[i];
        } else { /* a yielding spring: its phase's k_eff x + r0 */
            double keff, r0;
            edr_block_stiffness(r, r->tp.dof_blk[i], &keff, &r0);
            S.Ks[i] = s * s * keff;
            S.KDs[i] = s * (keff * r->rs.d[i] + r0);
        }
        S.Bs[i] = s * bk->b;
    }
    /* toward the root: in reverse breadth-first order every child is
     * complete before it is added to its parent */
    for (int k = nn - 1; k > 0; k--) {
        int i = ord[k], p = pd[i];
        S.Ms[p] += S.Ms[i];
        S.Cs[p] += S.Cs[i];
        S.Ks[p] += S.Ks[i];
        S.KDs[p] += S.KDs[i];
        S.Bs[p] += S.Bs[i];
    }
    return S;
}

/* The oscillator w0 = sqrt(K / M), xi = C / (2 sqrt(K M)) and the flight's
 * origin (y0, y0'), the dofs' origin put on x = s y + d; held by the wall
 * (wedge >= 0), y0 closes its gap and nothing moves. */
static void tree_origin(pd_edr *r, edr_cluster *c, const int *ord, int nn, int wedge, double C,
                        double K)
{
    int root = c->root;
    double M = c->mass;
    if (c->kind == EDR_REST) {
        const edr_contact *ct = &r->tp.ct[wedge];
        double ww = ct->w[side_of(ct, root)];
        /* the wall's gap g0 + ww x_root is closed, and x_root = y */
        c->y0 = -ct->g0 / ww;
        c->vy0 = 0.0;
        c->osc = (pd_sdof){.w0 = 0.0, .xi = 0.0};
        c->a2 = 0.0;
    } else {
        c->osc = (pd_sdof){.w0 = sqrt(K / M), .xi = K > 0.0 ? C / (2.0 * sqrt(K * M)) : 0.0};
        c->a2 = c->mass_flight ? C / M : 2.0 * c->osc.xi * c->osc.w0;
        if (nn == 1) { /* one dof, no constraint: y = x */
            c->y0 = r->rs.xo[root];
            c->vy0 = r->rs.vo[root];
        } else {
            /* the M-orthogonal projection onto x = s y + d, the least of
             * sum m (x - s y - d)^2: y0 = sum s m (x - d) / M, y0' = sum s m v / M */
            double sy = 0.0, sv = 0.0;
            for (int k = 0; k < nn; k++) {
                int i = ord[k];
                double m = r->tp.blk[r->tp.dof_blk[i]].m;
                sy += r->rs.s[i] * m * (r->rs.xo[i] - r->rs.d[i]);
                sv += r->rs.s[i] * m * r->rs.vo[i];
            }
            c->y0 = sy / M;
            c->vy0 = sv / M;
        }
    }
    /* the origin onto the constraints (a lone free dof is already there) */
    for (int k = 0; k < nn; k++) {
        int i = ord[k];
        if (nn > 1 || c->kind == EDR_REST) {
            r->rs.xo[i] = r->rs.s[i] * c->y0 + r->rs.d[i];
            r->rs.vo[i] = r->rs.s[i] * c->vy0;
        }
    }
}

/* The tree edges' forces lambda_e = la y + lb y' + lg f + ld: the subtree
 * below edge e (child i) balanced,
 *   lambda_e = (Ms y'' + Cs y' + Ks y + KDs - Bs f) / (s_i w_i),
 * with y'' = rho f + kappa - 2 xi w0 y' - w0^2 y substituted. */
static void tree_edge_forces(pd_edr *r, const edr_cluster *c, const int *ord, const int *pe, int nn,
                             const tree_sums *S)
{
    double w2 = c->osc.w0 * c->osc.w0, xw = c->a2;
    for (int k = 0; k < nn; k++) {
        int i = ord[k], e = pe[i];
        if (e < 0) /* a free tree's root; held, the root's edge is the wall's (the whole tree) */
            continue;
        double sw = r->rs.s[i] * r->tp.ct[e].w[side_of(&r->tp.ct[e], i)];
        if (c->kind == EDR_REST) { /* y fixed at y0, at rest: y' = y'' = 0 */
            r->rs.la[e] = r->rs.lb[e] = 0.0;
            r->rs.lg[e] = -S->Bs[i] / sw;
            r->rs.ld[e] = (S->Ks[i] * c->y0 + S->KDs[i]) / sw;
        } else {
            r->rs.la[e] = (S->Ks[i] - S->Ms[i] * w2) / sw;
            r->rs.lb[e] = (S->Cs[i] - S->Ms[i] * xw) / sw;
            r->rs.lg[e] = (S->Ms[i] * c->rho - S->Bs[i]) / sw;
            r->rs.ld[e] = (S->Ms[i] * c->kappa + S->KDs[i]) / sw;
        }
    }
}

/* Whether a spring of the tree's nodes ord[0..nn) slides. */
static int tree_sliding(const pd_edr *r, const int *ord, int nn)
{
    for (int k = 0; k < nn; k++) {
        int j = r->tp.blk[r->tp.dof_blk[ord[k]]].spring;
        if (j >= 0 && r->rs.sp_phase[j] != 0)
            return 1;
    }
    return 0;
}

/* An SDOF tree: aggregates, edge forces, flight.  Returns 0, or 1 when the
 * tree is no underdamped oscillator (it then runs as a modal cluster). */
static int tree_start(pd_edr *r, edr_cluster *c, double t)
{
    int wedge = wall_edge(r, c);
    /* rooted at the wall's dof (then x_root = y is the one the wall holds) */
    int root = wedge >= 0 ? r->tp.ct[wedge].dof[r->tp.ct[wedge].dof[0] < 0 ? 1 : 0]
                          : r->tp.blk_dofs[r->tp.blk[c->head].first];
    int *ord = r->ev.stack, *pe = r->ev.pe, *pd = r->ev.pdof;
    int nn = tree_order(r, c, root, wedge, ord, pe, pd);
    for (int k = 0; k < nn; k++) /* the order kept for the impulses of held edges */
        r->ev.bfs_next[ord[k]] = k + 1 < nn ? ord[k + 1] : -1;
    tree_sums S = subtree_sums(r, ord, pd, nn);
    /* the aggregates M = sum s^2 m, C = sum s^2 c, K = sum s^2 k; critical C = 2 sqrt(K M) */
    double M = S.Ms[root], C = S.Cs[root], K = S.Ks[root];
    /* a damped free mass whose stiffness its sliding springs took: its own flight */
    c->mass_flight = wedge < 0 && !(K > 0.0) && C > 0.0 && tree_sliding(r, ord, nn);
    if (wedge < 0 && !c->mass_flight && (K > 0.0 ? C >= 2.0 * sqrt(K * M) : C > 0.0))
        return 1; /* overdamped, or a damped free mass */
    c->mass = M;
    c->root = root;
    /* y'' + 2 xi w0 y' + w0^2 y = rho f + kappa: rho = sum s b / M, kappa = -sum s k d / M */
    c->rho = S.Bs[root] / M;
    c->kappa = -S.KDs[root] / M;
    c->kind = wedge >= 0 ? EDR_REST : EDR_SDOF;
    tree_origin(r, c, ord, nn, wedge, C, K);
    tree_edge_forces(r, c, ord, pe, nn, &S);
    /* the flow's forcing F = rho f + kappa, the piece scaled (the piece itself when
     * rho = 1, kappa = 0) */
    const pd_sine_piece *p = &r->tp.pieces[c->piece];
    c->pc = *p;
    if (c->rho != 1.0 || c->kappa != 0.0) {
        c->pc.A = p->A * c->rho;
        c->pc.c0 = p->c0 * c->rho + c->kappa;
        c->pc.c1 = p->c1 * c->rho;
    }
    if (c->kind == EDR_SDOF) {
        if (c->mass_flight)
            pd_sdof_flow_init_mass(&c->flow, c->a2, &c->pc, t, c->y0, c->vy0);
        else
            pd_sdof_flow_init(&c->flow, &c->osc, &c->pc, t, c->y0, c->vy0);
        taylor_init(r, c, t);
    }
    flight_bounds(r, c);
    /* the flight's shortest period 2 pi / w0 (none at rest or for a free
     * mass; a damped one's 2 pi / a2, its decay's time scale) */
    c->T_min = c->kind == EDR_SDOF && c->osc.w0 > 0.0 ? PD_TWO_PI / c->osc.w0
               : c->mass_flight                       ? PD_TWO_PI / c->a2
                                                      : HUGE_VAL;
    return 0;
}

/* ---- modal bases ------------------------------------------------------------- */

static void basis_free(edr_basis *b)
{
    if (!b)
        return;
    free(b->dofs);
    free(b->cons);
    free(b->lam);
    free(b->ilam);
    free(b->beta);
    free(b->kap);
    free(b->wt);
    free(b->Px);
    free(b->Pv);
    free(b->Z);
    free(b->Y);
    free(b->qstar);
    free(b->F);
    free(b->gam);
    free(b->del);
    free(b->KF);
    free(b->DF);
    free(b->keyv);
    free(b);
}

void edr_basis_cache_free(pd_edr *r)
{
    if (!r->rs.bhash)
        return;
    for (int h = 0; h < r->rs.nbhash; h++) {
        edr_basis *b = r->rs.bhash[h];
        while (b) {
            edr_basis *nx = b->next;
            basis_free(b);
            b = nx;
        }
    }
    free(r->rs.bhash);
    r->rs.bhash = NULL;
}

void edr_cluster_free(edr_cluster *c)
{
    free(c->eta0);
    free(c->deta);
    free(c->etad);
    free(c->gq);
    free(c->bc1);
    free(c->ilp);
    free(c->ilm);
    free(c->kapc);
    free(c->delc);
    c->eta0 = c->deta = c->etad = c->gq = c->bc1 = c->ilp = c->ilm = c->kapc = NULL;
    c->delc = NULL;
    c->cap = c->capr = 0;
}

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* The configuration's key: sorted blocks, -1, sorted persistent contacts,
 * and when a yielding spring of the blocks slides, -2 and the sorted
 * sliding springs (their stiffness is the cluster's). */
static int config_key(pd_edr *r, const edr_cluster *c, int *key, unsigned long *hash)
{
    int nk = 0, nb0;
    for (int b = c->head; b >= 0; b = r->rs.blk_next[b])
        key[nk++] = b;
    nb0 = nk;
    qsort(key, (size_t)nb0, sizeof(int), cmp_int);
    key[nk++] = -1; /* the separator: a block and a contact may share a number */
    int a0 = nk;
    for (int a = c->pers_head; a >= 0; a = r->rs.pers_next[a])
        key[nk++] = a;
    qsort(key + a0, (size_t)(nk - a0), sizeof(int), cmp_int);
    int nsl = 0; /* the sliding springs, listed after the -2 at key[nk] */
    for (int k = 0; k < nb0; k++) {
        const edr_block *bk = &r->tp.blk[key[k]];
        for (int l = 0; l < bk->nsp; l++) {
            int j = r->tp.blk_sp[bk->sp0 + l];
            if (r->rs.sp_phase[j] != 0)
                key[nk + 1 + nsl++] = j;
        }
    }
    if (nsl > 0) {
        key[nk] = -2;
        qsort(key + nk + 1, (size_t)nsl, sizeof(int), cmp_int);
        nk += 1 + nsl;
    }
    /* sorted, the key names the configuration whatever the lists' order;
     * its 64-bit FNV-1a hash: h = (h ^ key_k) * FNV prime */
    unsigned long h = 1469598103934665603UL;
    for (int k = 0; k < nk; k++)
        h = (h ^ (unsigned long)(unsigned)key[k]) * 1099511628211UL;
    *hash = h;
    return nk;
}

/* Entry (i, j) of a GSL matrix. */
#define MG(m, i, j) gsl_matrix_get((m), (size_t)(i), (size_t)(j))

/* ---- modal bases: the build ------------------------------------------------------ */

/* What the phases of basis_build share: the configuration's sizes, its
 * dense blocks and what each phase hands the next.  Dense arrays are
 * column-major; every pointer is NULL until its phase allocates it and
 * scratch_free releases them all (the basis itself, B, is the caller's). */
typedef struct basis_scratch {
    int nb0, ncon;    /* blocks key[0..nb0), persistent contacts cons[0..ncon) */
    const int *cons;  /* the key after its -1 */
    const int *slide; /* the sliding springs (the key after its -2), nslide */
    int nslide;
    int springs;              /* a block has yielding springs: the basis takes KF, DF */
    int nc, nr, k;            /* dofs, independent constraints, coordinates left k = nc - nr */
    double *Cc, *Kc;          /* nc x nc: the cluster's C, K (block diagonal) */
    double *bc;               /* nc: the load coefficients b */
    double *Wd;               /* nc x ncon: constraint directions, the kept ones first */
    double *g0;               /* ncon, nr used: the kept contacts' gaps at q = 0 */
    int *indep;               /* ncon, nr used: the kept contacts */
    double *tmp;              /* 4 nc + 4: triangular solves, products before a copy */
    gsl_matrix *Wm;           /* a QR's input and packed factors */
    gsl_vector *tau;          /* its Householder coefficients */
    gsl_matrix *Q, *R, *N;    /* W = Q1 R with Q = (Q1 Q2) nc x nc, R nc x nr; N = Q2, nc x k */
    double *L;                /* nr x nc: L = R^-1 Q1^T = (W^T W)^-1 W^T */
    gsl_matrix *Mr, *Cr, *Kr; /* k x k: N^T M N (inverted in place), N^T C N, N^T K N */
    gsl_matrix *Sm;           /* 2k x 2k: S = [0 I; -Mr^-1 Kr, -Mr^-1 Cr] */
    double *Kq;               /* nc: K q* */
    double *mrb, *mrk;        /* k: br = N^T b, kr = -N^T K q*, then Mr^-1 br, Mr^-1 kr */
    double *af, *ak;          /* nc: N Mr^-1 br, N Mr^-1 kr (accelerations of f, of the constant) */
    gsl_vector_complex *ev;   /* 2k: the eigenvalues of S */
    gsl_matrix_complex *V, *Vi, *LU; /* 2k x 2k: S's eigenvectors, V^-1, V's LU */
    gsl_permutation *perm;           /* the LU's rows */
    gsl_eigen_nonsymmv_workspace *ew;
} basis_scratch;

/* Release everything the phases allocated (one exit, CSparse's cs_done). */
static void scratch_free(basis_scratch *w)
{
    gsl_matrix_free(w->Wm);
    gsl_matrix_free(w->Q);
    gsl_matrix_free(w->R);
    gsl_matrix_free(w->N);
    gsl_matrix_free(w->Mr);
    gsl_matrix_free(w->Cr);
    gsl_matrix_free(w->Kr);
    gsl_matrix_free(w->Sm);
    gsl_vector_free(w->tau);
    gsl_vector_complex_free(w->ev);
    gsl_matrix_complex_free(w->V);
    gsl_matrix_complex_free(w->Vi);
    gsl_matrix_complex_free(w->LU);
    gsl_permutation_free(w->perm);
    if (w->ew)
        gsl_eigen_nonsymmv_free(w->ew);
    free(w->Cc);
    free(w->Kc);
    free(w->bc);
    free(w->g0);
    free(w->Wd);
    free(w->L);
    free(w->tmp);
    free(w->af);
    free(w->ak);
    free(w->Kq);
    free(w->mrb);
    free(w->mrk);
    free(w->indep);
}

/* The cluster's dofs in key order, loc(dof) their local index, and
 * C = diag(C_b), K = diag(K_b), b of its blocks. */
static int gather_blocks(pd_edr *r, const int *key, int nk, edr_basis *B, basis_scratch *w,
                         pd_err *err)
{
    int nc = w->nc;
    B->dofs = pd_malloc(nc, sizeof(int));
    B->keyv = pd_malloc(nk, sizeof(int));
    w->Cc = pd_calloc((long)nc * nc, sizeof(double));
    w->Kc = pd_calloc((long)nc * nc, sizeof(double));
    w->bc = pd_calloc(nc, sizeof(double));
    w->Wd = pd_calloc((long)nc * w->ncon, sizeof(double));
    w->g0 = pd_calloc(w->ncon, sizeof(double));
    w->indep = pd_malloc(w->ncon, sizeof(int));
    w->tmp = pd_malloc(4L * nc + 4, sizeof(double));
    if (!B->dofs || !B->keyv || !w->Cc || !w->Kc || !w->bc || !w->Wd || !w->g0 || !w->indep ||
        !w->tmp)
        return pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes (%d dofs)", nc);
    /* the key kept whole: a cache hit compares it, not only its hash */
    memcpy(B->keyv, key, (size_t)nk * sizeof(int));
    B->nkey = nk;
    int at = 0; /* the block's first local index */
    for (int k = 0; k < w->nb0; k++) {
        const edr_block *bk = &r->tp.blk[key[k]];
        long off = r->tp.blk_off[key[k]];
        for (int i = 0; i < bk->n; i++) {
            int gi = r->tp.blk_dofs[bk->first + i];
            B->dofs[at + i] = gi;
            r->ev.loc[gi] = at + i;
            w->bc[at + i] = r->tp.b[gi];
            /* C[at + i, at + j] = C_b[i, j] (C nc x nc, C_b n_b x n_b, column-major) */
            for (int j = 0; j < bk->n; j++) {
                w->Cc[(at + i) + (size_t)(at + j) * nc] = r->tp.Cb[off + i + (long)j * bk->n];
                w->Kc[(at + i) + (size_t)(at + j) * nc] = r->tp.Kb[off + i + (long)j * bk->n];
            }
        }
        at += bk->n;
        w->springs |= bk->nsp > 0;
    }
    /* a sliding spring j's stiffness leaves K: K - ks_j s_j s_j^T, s_j its drift's
     * column (sig at its dof, sig2 at the dof below) */
    for (int l = 0; l < w->nslide; l++) {
        int j = w->slide[l], li[2] = {r->ev.loc[r->tp.sp_dof[j]], -1};
        double sg[2] = {r->tp.sp_sig[j], r->tp.sp_sig2[j]}, ks = r->tp.md->ks[j];
        if (r->tp.sp_dof2[j] >= 0)
            li[1] = r->ev.loc[r->tp.sp_dof2[j]];
        for (int a = 0; a < 2; a++)
            for (int b = 0; b < 2; b++)
                if (li[a] >= 0 && li[b] >= 0)
                    w->Kc[li[a] + (size_t)li[b] * nc] -= ks * sg[a] * sg[b];
    }
    return PD_OK;
}

/* The independent constraint directions, in key order: contact a's column
 * w_a (g = g0 + w_a^T q) is kept when |R_jj| of QR(W_kept, w_a), its
 * distance to the kept columns' span, exceeds DEPENDENT_TOL |w_a|;
 * otherwise it joins dep (LOCKED).  Sets nr, k = nc - nr. */
static int keep_independent(pd_edr *r, basis_scratch *w, int *dep, int *ndep, pd_err *err)
{
    int nc = w->nc, nr = 0;
    for (int k = 0; k < w->ncon; k++) {
        const edr_contact *ct = &r->tp.ct[w->cons[k]];
        /* the candidate goes in the column after the kept ones (overwritten if dependent) */
        double *col = w->Wd + (size_t)nr * nc, nrm0 = 0.0, nrm = 0.0;
        memset(col, 0, (size_t)nc * sizeof(double));
        for (int s = 0; s < 2; s++)
            if (ct->dof[s] >= 0) /* a wall side has no dof */
                col[r->ev.loc[ct->dof[s]]] += ct->w[s];
        for (int i = 0; i < nc; i++) /* |w_a|^2 */
            nrm0 += col[i] * col[i];
        /* the exact test: Householder QR of the kept columns and w_a */
        w->Wm = gsl_matrix_alloc((size_t)nc, (size_t)(nr + 1));
        w->tau = gsl_vector_alloc((size_t)(nr + 1 < nc ? nr + 1 : nc));
        if (!w->Wm || !w->tau)
            return pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
        for (int j = 0; j <= nr; j++)
            for (int i = 0; i < nc; i++)
                gsl_matrix_set(w->Wm, (size_t)i, (size_t)j, w->Wd[(size_t)j * nc + i]);
        int full = nr + 1 <= nc; /* else nr = nc kept columns span R^nc: w_a depends */
        if (full) {
            gsl_linalg_QR_decomp(w->Wm, w->tau);
            nrm = fabs(MG(w->Wm, nr, nr)); /* |w_a - P_kept w_a| */
        }
        gsl_matrix_free(w->Wm);
        gsl_vector_free(w->tau);
        w->Wm = NULL;
        w->tau = NULL;
        if (full && nrm > DEPENDENT_TOL * sqrt(nrm0)) {
            w->indep[nr] = w->cons[k];
            w->g0[nr] = ct->g0;
            nr++;
        } else
            dep[(*ndep)++] = w->cons[k];
    }
    w->nr = nr;
    w->k = nc - nr;
    return PD_OK;
}

/* q*, the least-norm point of W^T q = -g0, and L = R^-1 Q1^T from
 * W = Q1 R: q* = Q1 u with R^T u = -g0 (then W^T q* = R^T u). */
static void qstar_and_L(edr_basis *B, basis_scratch *w)
{
    int nc = w->nc, nr = w->nr;
    double *u = w->tmp;
    /* forward substitution, (R^T)_ij = R_ji: u_i = (-g0_i - sum_{j<i} R_ji u_j) / R_ii */
    for (int i = 0; i < nr; i++) {
        double s = -w->g0[i];
        for (int j = 0; j < i; j++)
            s -= MG(w->R, j, i) * u[j];
        u[i] = s / MG(w->R, i, i);
    }
    for (int i = 0; i < nc; i++) { /* q*_i = sum_j Q_ij u_j over Q1's columns */
        double s = 0.0;
        for (int j = 0; j < nr; j++)
            s += MG(w->Q, i, j) * u[j];
        B->qstar[i] = s;
    }
    /* L's column i solves R l = Q1^T e_i by back substitution:
     * l_a = (Q_ia - sum_{j>a} R_aj l_j) / R_aa */
    for (int i = 0; i < nc; i++)
        for (int a = nr - 1; a >= 0; a--) {
            double s = MG(w->Q, i, a);
            for (int j = a + 1; j < nr; j++)
                s -= MG(w->R, a, j) * w->L[j + (size_t)i * nr];
            w->L[a + (size_t)i * nr] = s / MG(w->R, a, a);
        }
}

/* The constraints' factors: W = Q1 R (nc x nr), N = Q2 an orthonormal
 * basis of W^T q = 0 (q = q* + N y keeps every kept gap closed), q* and L. */
static int constraint_basis(edr_basis *B, basis_scratch *w, pd_err *err)
{
    int nc = w->nc, nr = w->nr, k = w->k;
    B->r = nr;
    B->k = k;
    B->cons = pd_malloc(nr, sizeof(int));
    B->qstar = pd_calloc(nc, sizeof(double));
    B->gam = pd_calloc(nr, sizeof(double));
    B->del = pd_calloc(nr, sizeof(double));
    w->Q = gsl_matrix_alloc((size_t)nc, (size_t)nc);
    w->N = k > 0 ? gsl_matrix_alloc((size_t)nc, (size_t)k) : NULL;
    w->L = pd_calloc((long)nr * nc, sizeof(double));
    if (!B->cons || !B->qstar || !B->gam || !B->del || !w->Q || (k > 0 && !w->N) || !w->L)
        return pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
    memcpy(B->cons, w->indep, (size_t)nr * sizeof(int));
    if (nr > 0) { /* W: Wd's first nr columns, the kept directions (keep_independent) */
        w->Wm = gsl_matrix_alloc((size_t)nc, (size_t)nr);
        w->tau = gsl_vector_alloc((size_t)nr);
        w->R = gsl_matrix_alloc((size_t)nc, (size_t)nr);
        if (!w->Wm || !w->tau || !w->R)
            return pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
        for (int j = 0; j < nr; j++)
            for (int i = 0; i < nc; i++)
                gsl_matrix_set(w->Wm, (size_t)i, (size_t)j, w->Wd[(size_t)j * nc + i]);
        /* Householder QR; unpacked, Q's first nr columns Q1 span W's */
        gsl_linalg_QR_decomp(w->Wm, w->tau);
        gsl_linalg_QR_unpack(w->Wm, w->tau, w->Q, w->R);
        qstar_and_L(B, w);
    } else /* no constraint: q* = 0, N = I */
        gsl_matrix_set_identity(w->Q);
    for (int j = 0; j < k; j++) /* N = Q's last k columns */
        for (int i = 0; i < nc; i++)
            gsl_matrix_set(w->N, (size_t)i, (size_t)j, MG(w->Q, i, nr + j));
    return PD_OK;
}

/* The reduced system's storage (k > 0): Mr, Cr, Kr, S, the eigensolver's,
 * and the basis's Y. */
static int reduced_alloc(edr_basis *B, basis_scratch *w, pd_err *err)
{
    size_t k = (size_t)w->k;
    /* z = (y, y') has 2k components: S, V, V^-1 are 2k x 2k */
    w->Mr = gsl_matrix_alloc(k, k);
    w->Cr = gsl_matrix_alloc(k, k);
    w->Kr = gsl_matrix_alloc(k, k);
    w->Sm = gsl_matrix_calloc(2 * k, 2 * k);
    w->mrb = pd_calloc(w->k, sizeof(double));
    w->mrk = pd_calloc(w->k, sizeof(double));
    w->Kq = pd_calloc(w->nc, sizeof(double));
    w->af = pd_calloc(w->nc, sizeof(double));
    w->ak = pd_calloc(w->nc, sizeof(double));
    w->ev = gsl_vector_complex_alloc(2 * k);
    w->V = gsl_matrix_complex_alloc(2 * k, 2 * k);
    w->Vi = gsl_matrix_complex_alloc(2 * k, 2 * k);
    w->LU = gsl_matrix_complex_alloc(2 * k, 2 * k);
    w->perm = gsl_permutation_alloc(2 * k);
    w->ew = gsl_eigen_nonsymmv_alloc(2 * k);
    B->Y = pd_malloc((long)w->k * w->nc, sizeof(double));
    if (!w->Mr || !w->Cr || !w->Kr || !w->Sm || !w->mrb || !w->mrk || !w->Kq || !w->af || !w->ak ||
        !w->ev || !w->V || !w->Vi || !w->LU || !w->perm || !w->ew || !B->Y)
        return pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes (%d dofs)", w->nc);
    return PD_OK;
}

/* The reduced system Mr y'' + Cr y' + Kr y = br f + kr on q = q* + N y:
 * Mr = N^T M N (M = diag(1 / minv)), Cr = N^T C N, Kr = N^T K N,
 * br = N^T b, kr = -N^T K q*. */
static void reduced_project(const pd_edr *r, const edr_basis *B, basis_scratch *w)
{
    int nc = w->nc, k = w->k;
    const double *minv = r->tp.minv, *Cc = w->Cc, *Kc = w->Kc;
    const gsl_matrix *N = w->N;
    for (int i = 0; i < nc; i++) { /* (K q*)_i = sum_j K_ij q*_j */
        double s = 0.0;
        for (int j = 0; j < nc; j++)
            s += Kc[i + (size_t)j * nc] * B->qstar[j];
        w->Kq[i] = s;
    }
    /* (Mr, Cr, Kr)_ab = sum_i N_ia ((M, C, K) N)_ib */
    for (int a = 0; a < k; a++)
        for (int b2 = 0; b2 < k; b2++) {
            double sm = 0.0, scc = 0.0, sk = 0.0;
            for (int i = 0; i < nc; i++) {
                double nia = MG(N, i, a);
                if (nia == 0.0) /* the row adds nothing: skip its C N, K N */
                    continue;
                double cn = 0.0, kn = 0.0; /* (C N)_ib, (K N)_ib */
                for (int j = 0; j < nc; j++) {
                    double njb = MG(N, j, b2);
                    cn += Cc[i + (size_t)j * nc] * njb;
                    kn += Kc[i + (size_t)j * nc] * njb;
                }
                sm += nia * MG(N, i, b2) / minv[B->dofs[i]]; /* M diagonal: M_ii N_ib */
                scc += nia * cn;
                sk += nia * kn;
            }
            gsl_matrix_set(w->Mr, (size_t)a, (size_t)b2, sm);
            gsl_matrix_set(w->Cr, (size_t)a, (size_t)b2, scc);
            gsl_matrix_set(w->Kr, (size_t)a, (size_t)b2, sk);
        }
    for (int a = 0; a < k; a++) { /* br_a = sum_i N_ia b_i, kr_a = -sum_i N_ia (K q*)_i */
        double sb = 0.0, sq = 0.0;
        for (int i = 0; i < nc; i++) {
            sb += MG(N, i, a) * w->bc[i];
            sq -= MG(N, i, a) * w->Kq[i];
        }
        w->mrb[a] = sb;
        w->mrk[a] = sq;
    }
}

/* The first-order system z' = S z + (0, Mr^-1 br) f + (0, Mr^-1 kr) of
 * z = (y, y'): S = [0 I; -Mr^-1 Kr, -Mr^-1 Cr]; and Y = Mr^-1 N^T M (the
 * M-orthogonal projection y = Y (x - q*)), af = N Mr^-1 br, ak = N Mr^-1 kr. */
static int first_order_system(const pd_edr *r, edr_basis *B, basis_scratch *w, pd_err *err)
{
    int nc = w->nc, k = w->k;
    const gsl_matrix *Mr = w->Mr, *N = w->N;
    double *tmp = w->tmp;
    /* Mr = G G^T (Cholesky), then Mr^-1 in place: refused unless positive definite */
    if (gsl_linalg_cholesky_decomp1(w->Mr) || gsl_linalg_cholesky_invert(w->Mr))
        return pd_err_set(err, PD_ESINGULAR,
                          "row reference: a cluster's reduced mass matrix "
                          "is not positive definite");
    for (int a = 0; a < k; a++) { /* Mr^-1 br, Mr^-1 kr into tmp: the products read mrb, mrk */
        double s1 = 0.0, s2 = 0.0;
        for (int b2 = 0; b2 < k; b2++) {
            s1 += MG(Mr, a, b2) * w->mrb[b2];
            s2 += MG(Mr, a, b2) * w->mrk[b2];
        }
        tmp[a] = s1;
        tmp[k + a] = s2;
    }
    memcpy(w->mrb, tmp, (size_t)k * sizeof(double));
    memcpy(w->mrk, tmp + k, (size_t)k * sizeof(double));
    for (int a = 0; a < k; a++) {
        /* row a: (y)' = y', the identity block (Sm came zeroed) */
        gsl_matrix_set(w->Sm, (size_t)a, (size_t)(k + a), 1.0);
        for (int b2 = 0; b2 < k; b2++) { /* row k + a: -(Mr^-1 Kr)_ab, -(Mr^-1 Cr)_ab */
            double sk = 0.0, scc = 0.0;
            for (int c2 = 0; c2 < k; c2++) {
                sk += MG(Mr, a, c2) * MG(w->Kr, c2, b2);
                scc += MG(Mr, a, c2) * MG(w->Cr, c2, b2);
            }
            gsl_matrix_set(w->Sm, (size_t)(k + a), (size_t)b2, -sk);
            gsl_matrix_set(w->Sm, (size_t)(k + a), (size_t)(k + b2), -scc);
        }
        for (int i = 0; i < nc; i++) { /* Y_ai = (Mr^-1 N^T)_ai M_ii */
            double s = 0.0;
            for (int b2 = 0; b2 < k; b2++)
                s += MG(Mr, a, b2) * MG(N, i, b2);
            B->Y[a + (size_t)i * k] = s / r->tp.minv[B->dofs[i]];
        }
    }
    /* the dofs' accelerations per unit f (af) and from the constant force (ak) */
    for (int i = 0; i < nc; i++) {
        double s1 = 0.0, s2 = 0.0;
        for (int a = 0; a < k; a++) {
            s1 += MG(N, i, a) * w->mrb[a];
            s2 += MG(N, i, a) * w->mrk[a];
        }
        w->af[i] = s1;
        w->ak[i] = s2;
    }
    return PD_OK;
}

/* S = V diag(lam) V^-1 (balanced nonsymmetric eigensolver, V^-1 by LU),
 * refused when V is singular or its 1-norm condition
 * |V|_1 |V^-1|_1 reaches MODAL_COND_MAX; *nm the modes kept (Im lam >= 0). */
static int modal_decomposition(basis_scratch *w, int *nm, pd_err *err)
{
    int nc = w->nc, k = w->k, sgn;
    gsl_eigen_nonsymmv_params(1, w->ew);
    if (gsl_eigen_nonsymmv(w->Sm, w->ev, w->V, w->ew))
        return pd_err_set(err, PD_ENUMERICAL,
                          "row reference: the eigenvalues of a cluster of "
                          "%d dofs did not converge",
                          nc);
    /* V^-1 by LU: a singular V (S defective) has no modal basis */
    gsl_matrix_complex_memcpy(w->LU, w->V);
    if (gsl_linalg_complex_LU_decomp(w->LU, w->perm, &sgn) ||
        gsl_linalg_complex_LU_invert(w->LU, w->perm, w->Vi))
        return pd_err_set(err, PD_ENUMERICAL,
                          "row reference: a cluster of %d dofs has a "
                          "defective modal basis",
                          nc);
    double nv = 0.0, nvi = 0.0; /* |V|_1, |V^-1|_1: the largest column sums of |entries| */
    for (int j = 0; j < 2 * k; j++) {
        double s1 = 0.0, s2 = 0.0;
        for (int i = 0; i < 2 * k; i++) {
            s1 += gsl_complex_abs(gsl_matrix_complex_get(w->V, (size_t)i, (size_t)j));
            s2 += gsl_complex_abs(gsl_matrix_complex_get(w->Vi, (size_t)i, (size_t)j));
        }
        nv = fmax(nv, s1);
        nvi = fmax(nvi, s2);
    }
    if (!(nv * nvi < MODAL_COND_MAX)) /* (a NaN condition is refused too) */
        return pd_err_set(err, PD_ENUMERICAL,
                          "row reference: a cluster of %d dofs is nearly "
                          "defective (modal basis condition %.3g): a "
                          "critically damped mode?",
                          nc, nv * nvi);
    /* S is real: its complex modes come in conjugate pairs, each kept once */
    for (int j = 0; j < 2 * k; j++)
        *nm += GSL_IMAG(gsl_vector_complex_get(w->ev, (size_t)j)) >= 0.0;
    return PD_OK;
}

/* The cluster's modes (k > 0): the reduced system, its first-order form
 * and S's eigendecomposition. */
static int reduced_modes(const pd_edr *r, edr_basis *B, basis_scratch *w, int *nm, pd_err *err)
{
    int rc = reduced_alloc(B, w, err);
    if (rc)
        return rc;
    reduced_project(r, B, w);
    if ((rc = first_order_system(r, B, w, err)))
        return rc;
    return modal_decomposition(w, nm, err);
}

/* The basis's per-mode arrays for nm modes. */
static int modes_alloc(edr_basis *B, const basis_scratch *w, int nm, pd_err *err)
{
    long nc = w->nc, k = w->k, nr = w->nr;
    /* a product of 0 (k = 0: no mode) still takes one element: NULL means out of memory */
    B->nmodes = nm;
    B->lam = pd_malloc(nm, sizeof(edr_cplx));
    B->ilam = pd_malloc(nm, sizeof(edr_cplx));
    B->beta = pd_malloc(nm, sizeof(edr_cplx));
    B->kap = pd_malloc(nm, sizeof(edr_cplx));
    B->wt = pd_malloc(nm, sizeof(double));
    B->Px = pd_malloc(nm * nc, sizeof(edr_cplx));
    B->Pv = pd_malloc(nm * nc, sizeof(edr_cplx));
    B->Z = pd_malloc(nm * 2 * k, sizeof(edr_cplx));
    B->F = pd_malloc(nm * nr, sizeof(edr_cplx));
    if (!B->lam || !B->ilam || !B->beta || !B->kap || !B->wt || !B->Px || !B->Pv || !B->Z || !B->F)
        return pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
    return PD_OK;
}

/* Mode q (eigenvalue j of S, Im lam_j >= 0): eta_q = (V^-1 z)_j obeys
 * eta' = lam eta + beta f + kap with (beta, kap) = V^-1 (0, Mr^-1 br),
 * V^-1 (0, Mr^-1 kr) at row j; Z = V^-1's row j, and x - q* = N y,
 * v = N y' give Px = N V[0..k, j], Pv = N V[k..2k, j].  T_min = 2 pi / max |lam|. */
static void modes_store(edr_basis *B, const basis_scratch *w)
{
    int nc = w->nc, k = w->k, nm = B->nmodes;
    double lmax = 0.0;
    for (int j = 0, q = 0; j < 2 * k; j++) {
        gsl_complex l = gsl_vector_complex_get(w->ev, (size_t)j);
        if (GSL_IMAG(l) < 0.0) /* the conjugate of a kept mode */
            continue;
        edr_cplx lam = cplx_of(l), bt = 0.0, kp = 0.0;
        for (int a = 0; a < k; a++) { /* only z's lower half is forced */
            edr_cplx zz = cplx_of(gsl_matrix_complex_get(w->Vi, (size_t)j, (size_t)(k + a)));
            bt += zz * w->mrb[a];
            kp += zz * w->mrk[a];
        }
        B->lam[q] = lam;
        B->ilam[q] = 1.0 / lam; /* (lam = 0: read only where |lam s| >= 1, never) */
        B->beta[q] = bt;
        B->kap[q] = kp;
        /* z = sum over all modes V_j eta_j = sum over the kept wt Re(V_j eta_j) */
        B->wt[q] = GSL_IMAG(l) > 0.0 ? 2.0 : 1.0;
        lmax = fmax(lmax, cabs(lam));
        for (int l2 = 0; l2 < 2 * k; l2++) /* Z's row q: V^-1's row j */
            B->Z[(size_t)q * 2 * k + l2] =
                cplx_of(gsl_matrix_complex_get(w->Vi, (size_t)j, (size_t)l2));
        for (int i = 0; i < nc; i++) { /* Px_iq = sum_a N_ia V_aj, Pv_iq = sum_a N_ia V_(k+a)j */
            edr_cplx px = 0.0, pv = 0.0;
            for (int a = 0; a < k; a++) {
                gsl_complex v1 = gsl_matrix_complex_get(w->V, (size_t)a, (size_t)j);
                gsl_complex v2 = gsl_matrix_complex_get(w->V, (size_t)(k + a), (size_t)j);
                px += MG(w->N, i, a) * cplx_of(v1);
                pv += MG(w->N, i, a) * cplx_of(v2);
            }
            B->Px[(size_t)i * nm + q] = px;
            B->Pv[(size_t)i * nm + q] = pv;
        }
        q++;
    }
    B->T_min = lmax > 0.0 ? PD_TWO_PI / lmax : HUGE_VAL;
}

/* The contact forces lambda = L (M a + C v + K q - b f) folded into the
 * modes, with q = q* + sum wt Re(Px eta), v = sum wt Re(Pv eta),
 * a = af f + ak + sum wt Re(Pv lam eta):
 *   lambda = gam f + del + sum wt Re(F eta),  gam = L (M af - b),
 *   del = L (M ak + K q*),  F = L (M Pv diag(lam) + C Pv + K Px). */
static void contact_force_modes(const pd_edr *r, edr_basis *B, const basis_scratch *w)
{
    int nc = w->nc, k = w->k, nr = w->nr, nm = B->nmodes;
    const double *minv = r->tp.minv, *Cc = w->Cc, *Kc = w->Kc, *L = w->L;
    for (int c2 = 0; c2 < nr; c2++) {
        double gsum = 0.0, dsum = 0.0;
        for (int i = 0; i < nc; i++) {
            double l = L[c2 + (size_t)i * nr];
            if (l == 0.0) /* the dof adds nothing to this contact's force */
                continue;
            double mi = 1.0 / minv[B->dofs[i]], kq = 0.0; /* M_ii */
            for (int j = 0; j < nc; j++)                  /* (K q*)_i */
                kq += Kc[i + (size_t)j * nc] * B->qstar[j];
            /* no coordinate left (k = 0): the cluster is held still, a = 0 */
            gsum += l * (mi * (k > 0 ? w->af[i] : 0.0) - w->bc[i]);
            dsum += l * (mi * (k > 0 ? w->ak[i] : 0.0) + kq);
        }
        B->gam[c2] = gsum;
        B->del[c2] = dsum;
        for (int q = 0; q < nm; q++) {
            edr_cplx s = 0.0;
            for (int i = 0; i < nc; i++) {
                double l = L[c2 + (size_t)i * nr];
                if (l == 0.0)
                    continue;
                edr_cplx cv = 0.0, kx = 0.0; /* (C Pv)_iq, (K Px)_iq */
                for (int j = 0; j < nc; j++) {
                    cv += Cc[i + (size_t)j * nc] * B->Pv[(size_t)j * nm + q];
                    kx += Kc[i + (size_t)j * nc] * B->Px[(size_t)j * nm + q];
                }
                /* M_ii Pv_iq lam_q + (C Pv)_iq + (K Px)_iq */
                s += l * (B->Pv[(size_t)i * nm + q] * B->lam[q] / minv[B->dofs[i]] + cv + kx);
            }
            B->F[(size_t)c2 * nm + q] = s;
        }
    }
}

/* A constant force fc on the dofs in the modes and the contacts' forces
 * (the yielding springs' offsets, set per flight): Mr y'' + ... = ... +
 * N^T fc gives kap += KF fc, KF = Z_(., k..2k) Mr^-1 N^T, and lambda =
 * L (M a + C v + K q - b f - fc) gives del += DF fc, DF = L (M N Mr^-1 N^T
 * - I) (no coordinate left: -L). */
static int constant_force_modes(const pd_edr *r, edr_basis *B, const basis_scratch *w, pd_err *err)
{
    int nc = w->nc, k = w->k, nr = w->nr, nm = B->nmodes;
    B->KF = pd_calloc((long)nm * nc, sizeof(edr_cplx));
    B->DF = pd_calloc((long)nr * nc, sizeof(double));
    if (!B->KF || !B->DF)
        return pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
    double *ak = w->tmp; /* N Mr^-1 N^T e_i: the accelerations of a unit force on dof i */
    for (int i = 0; i < nc; i++) {
        double mi = r->tp.minv[B->dofs[i]]; /* (Mr^-1 N^T)_ai = Y_ai / M_ii */
        for (int q = 0; q < nm; q++) {
            edr_cplx s = 0.0;
            for (int a = 0; a < k; a++)
                s += B->Z[(size_t)q * 2 * k + k + a] * (B->Y[a + (size_t)i * k] * mi);
            B->KF[(size_t)q * nc + i] = s;
        }
        for (int l = 0; l < nc; l++) {
            double s = 0.0;
            for (int a = 0; a < k; a++)
                s += MG(w->N, l, a) * (B->Y[a + (size_t)i * k] * mi);
            ak[l] = s;
        }
        for (int c2 = 0; c2 < nr; c2++) {
            double s = -w->L[c2 + (size_t)i * nr];
            for (int l = 0; l < nc; l++)
                s += w->L[c2 + (size_t)l * nr] * ak[l] / r->tp.minv[B->dofs[l]];
            B->DF[(size_t)c2 * nc + i] = s;
        }
    }
    return PD_OK;
}

/* Build the basis of a configuration (blocks key[0..nb0), contacts after
 * the -1): its dofs, independent constraints, modes and contact forces.
 * Dependent constraint contacts are listed in *dep (count ndep). */
static int basis_build(pd_edr *r, const int *key, int nk, edr_basis **out, int *dep, int *ndep,
                       pd_err *err)
{
    basis_scratch w = {.nb0 = 0};
    /* key: the sorted blocks, -1, the sorted persistent contacts, and -2 and
     * the sliding springs when there are (config_key) */
    while (key[w.nb0] >= 0)
        w.nb0++;
    w.cons = key + w.nb0 + 1;
    while (w.nb0 + 1 + w.ncon < nk && w.cons[w.ncon] >= 0)
        w.ncon++;
    if (w.nb0 + 1 + w.ncon < nk) { /* after the -2 */
        w.slide = w.cons + w.ncon + 1;
        w.nslide = nk - (w.nb0 + 1 + w.ncon + 1);
    }
    for (int k = 0; k < w.nb0; k++)
        w.nc += r->tp.blk[key[k]].n;
    edr_basis *B = pd_calloc(1, sizeof *B);
    *ndep = 0;
    if (!B)
        return pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
    B->nc = w.nc;
    int nm = 0; /* no coordinate left: no mode */
    /* the phases in order: a failure skips the rest, and what they took is
     * freed once below (the basis too when it failed) */
    int rc = gather_blocks(r, key, nk, B, &w, err);
    if (!rc)
        rc = keep_independent(r, &w, dep, ndep, err);
    if (!rc)
        rc = constraint_basis(B, &w, err);
    if (!rc && w.k > 0)
        rc = reduced_modes(r, B, &w, &nm, err);
    if (!rc)
        rc = modes_alloc(B, &w, nm, err);
    if (!rc) {
        modes_store(B, &w);
        contact_force_modes(r, B, &w);
        if (w.springs)
            rc = constant_force_modes(r, B, &w, err);
    }
    scratch_free(&w);
    if (rc) {
        basis_free(B);
        return rc;
    }
    *out = B;
    return PD_OK;
}

/* The cached basis of the cluster's configuration (built when first met). */
static int basis_of(pd_edr *r, edr_cluster *c, edr_basis **out, pd_err *err)
{
    int *key = r->ev.keybuf, *dep = r->ev.keybuf + r->tp.nb + r->tp.m + r->tp.ns + 2, ndep = 0, rc;
    unsigned long h;
    int nk = config_key(r, c, key, &h);
    if (!r->rs.bhash) { /* the buckets, taken when the first modal cluster starts */
        r->rs.nbhash = BASIS_BUCKETS;
        if (!(r->rs.bhash = pd_calloc(r->rs.nbhash, sizeof *r->rs.bhash)))
            return pd_err_set(err, PD_ENOMEM, "out of memory for the modal cache");
    }
    edr_basis **slot = &r->rs.bhash[h % (unsigned long)r->rs.nbhash];
    /* a hit needs the whole key equal: two configurations may share a hash */
    for (edr_basis *b = *slot; b; b = b->next)
        if (b->key == h && b->nkey == nk && !memcmp(b->keyv, key, (size_t)nk * sizeof(int))) {
            *out = b;
            return PD_OK;
        }
    edr_basis *b = NULL;
    gsl_set_error_handler_off(); /* GSL's default handler aborts (docs/api.md) */
    if ((rc = basis_build(r, key, nk, &b, dep, &ndep, err)))
        return rc;
    b->key = h; /* pushed at the chain's head */
    b->next = *slot;
    *slot = b;
    r->rs.nbasis++;
    *out = b;
    return PD_OK;
}

/* The flight's origin on the constraints: y0 = Y (x - q*), y0' = Y v, the
 * modes eta0 = Z (y0, y0') and the dofs' origin x = q* + sum wt Re(Px eta0),
 * v = sum wt Re(Pv eta0). */
static void modal_origin(pd_edr *r, edr_cluster *c, const edr_basis *B)
{
    int nc = B->nc, k = B->k;
    double *y = r->ev.wk, *yd = y + nc; /* y0, y0' (k <= nc each) */
    for (int i = 0; i < nc; i++)        /* dof -> its row of Px, Pv */
        r->rs.crow[B->dofs[i]] = i;
    /* y0 = Y (x - q*), y0' = Y v: the M-orthogonal projection onto q = q* + N y */
    for (int a = 0; a < k; a++) {
        double s1 = 0.0, s2 = 0.0;
        for (int i = 0; i < nc; i++) {
            int gi = B->dofs[i];
            s1 += B->Y[a + (size_t)i * k] * (r->rs.xo[gi] - B->qstar[i]);
            s2 += B->Y[a + (size_t)i * k] * r->rs.vo[gi];
        }
        y[a] = s1;
        yd[a] = s2;
    }
    for (int q = 0; q < B->nmodes; q++) { /* eta0_q = Z_q (y0, y0') = (V^-1 z0)_q */
        edr_cplx e = 0.0;
        const edr_cplx *z = B->Z + (size_t)q * 2 * k;
        for (int a = 0; a < k; a++)
            e += z[a] * y[a] + z[k + a] * yd[a];
        c->eta0[q] = e;
    }
    /* the projected origin: x = q* + sum wt Re(Px eta0), v = sum wt Re(Pv eta0) */
    for (int i = 0; i < nc; i++) {
        double x = B->qstar[i], v = 0.0;
        for (int q = 0; q < B->nmodes; q++) {
            x += B->wt[q] * creal(B->Px[(size_t)i * B->nmodes + q] * c->eta0[q]);
            v += B->wt[q] * creal(B->Pv[(size_t)i * B->nmodes + q] * c->eta0[q]);
        }
        r->rs.xo[B->dofs[i]] = x;
        r->rs.vo[B->dofs[i]] = v;
    }
}

/* The flight's kap and del: the basis's, with its yielding springs'
 * constant force fc added (KF, DF): an elastic spring's ks up s, a sliding
 * one's -ks ph uy s (its stiffness left K: K x - ks s up = (K - ks s s^T) x
 * + ks ph uy s), s its drift's column.  Rows of Px, Pv: modal_origin's. */
static void spring_constants(pd_edr *r, edr_cluster *c, const edr_basis *B)
{
    int nc = B->nc;
    memcpy(c->kapc, B->kap, (size_t)B->nmodes * sizeof(edr_cplx));
    memcpy(c->delc, B->del, (size_t)B->r * sizeof(double));
    if (!B->KF)
        return;
    double *fc = r->ev.wk; /* nc (modal_origin is done with it) */
    memset(fc, 0, (size_t)nc * sizeof(double));
    for (int b = c->head; b >= 0; b = r->rs.blk_next[b]) {
        const edr_block *bk = &r->tp.blk[b];
        for (int l = 0; l < bk->nsp; l++) {
            int j = r->tp.blk_sp[bk->sp0 + l], ph = r->rs.sp_phase[j];
            double f = ph != 0 ? -r->tp.md->ks[j] * ph * r->tp.md->uy[j]
                               : r->tp.md->ks[j] * r->rs.sp_up[j];
            fc[r->rs.crow[r->tp.sp_dof[j]]] += f * r->tp.sp_sig[j];
            if (r->tp.sp_dof2[j] >= 0)
                fc[r->rs.crow[r->tp.sp_dof2[j]]] += f * r->tp.sp_sig2[j];
        }
    }
    for (int i = 0; i < nc; i++) {
        if (fc[i] == 0.0) /* (no offset yet: the basis's constants, bit for bit) */
            continue;
        for (int q = 0; q < B->nmodes; q++)
            c->kapc[q] += B->KF[(size_t)q * nc + i] * fc[i];
        for (int c2 = 0; c2 < B->r; c2++)
            c->delc[c2] += B->DF[(size_t)c2 * nc + i] * fc[i];
    }
}

/* The flight's constants at its origin t0 (modal_eval): beta f_lin(t0) + kap,
 * beta c1, A / (2i) e^{i th(t0)} and 1 / (lam -+ i w). */
static void modal_flight_constants(const pd_edr *r, edr_cluster *c, const edr_basis *B, double t)
{
    const pd_sine_piece *pc = &r->tp.pieces[c->piece];
    /* f_lin(t0) = c0 + c1 (t0 - t_start), th(t0) = w t0 + phi */
    double fl0 = pc->c0 + pc->c1 * (t - pc->t_start), th = pc->w * t + pc->phi;
    c->ath0 = pc->A != 0.0 ? pc->A / (2.0 * I) * (cos(th) + I * sin(th)) : 0.0;
    for (int q = 0; q < B->nmodes; q++) {
        c->gq[q] = B->beta[q] * fl0 + c->kapc[q];
        c->bc1[q] = B->beta[q] * pc->c1;
        if (pc->A != 0.0) { /* (without a sinusoid modal_eval reads neither) */
            edr_cplx lp = B->lam[q] - I * pc->w, lm = B->lam[q] + I * pc->w;
            c->ilp[q] = cabs(lp) > 0.0 ? 1.0 / lp : 0.0; /* (0: the series serves) */
            c->ilm[q] = cabs(lm) > 0.0 ? 1.0 / lm : 0.0;
        }
    }
}

/* A modal cluster: its basis, the locked contacts, the origin projected. */
static int modal_start(pd_edr *r, edr_cluster *c, double t, pd_err *err)
{
    edr_basis *B = NULL;
    int rc;
    if ((rc = basis_of(r, c, &B, err)))
        return rc;
    /* persistent contacts the basis found dependent are locked */
    for (int a = c->pers_head, nx; a >= 0; a = nx) {
        nx = r->rs.pers_next[a];
        int in = 0;
        for (int j = 0; j < B->r && !in; j++)
            in = B->cons[j] == a;
        if (!in)
            lock_contact(r, c, a);
    }
    for (int j = 0; j < B->r; j++) /* contact -> its row of F, gam, del */
        r->rs.crow_c[B->cons[j]] = j;
    if (c->cap < B->nmodes) { /* the per-mode state grows to the largest basis met */
        edr_cluster_free(c);
        int cap = B->nmodes;
        c->eta0 = pd_malloc(cap, sizeof(edr_cplx));
        c->deta = pd_malloc(cap, sizeof(edr_cplx));
        c->etad = pd_malloc(cap, sizeof(edr_cplx));
        c->gq = pd_malloc(cap, sizeof(edr_cplx));
        c->bc1 = pd_malloc(cap, sizeof(edr_cplx));
        c->ilp = pd_malloc(cap, sizeof(edr_cplx));
        c->ilm = pd_malloc(cap, sizeof(edr_cplx));
        c->kapc = pd_malloc(cap, sizeof(edr_cplx));
        if (!c->eta0 || !c->deta || !c->etad || !c->gq || !c->bc1 || !c->ilp || !c->ilm ||
            !c->kapc) {
            edr_cluster_free(c);
            return pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
        }
        c->cap = cap;
    }
    if (!c->delc || c->capr < B->r) { /* the contacts' constants, as large as the most met */
        free(c->delc);
        if (!(c->delc = pd_malloc(B->r, sizeof(double)))) {
            edr_cluster_free(c);
            return pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
        }
        c->capr = B->r;
    }
    c->kind = EDR_MODAL;
    c->basis = B;
    c->bnd = 0; /* no closed bounds on a modal flight: its predictions scan */
    modal_origin(r, c, B);
    spring_constants(r, c, B);
    modal_flight_constants(r, c, B, t);
    c->T_min = B->T_min;
    return PD_OK;
}

/* The phase a sliding spring j takes at a flight's origin (dd, ddd its
 * drift's rate and acceleration): the slide goes on while its drift moves
 * toward its side (or, at rest, accelerates there), else unloads.  An
 * elastic spring stays so: one on its level moving past it is an onset
 * its prediction finds at once (past the level by its rounding threshold),
 * an event of its own. */
static int spring_phase_at(const pd_edr *r, int j, double dd, double ddd)
{
    double ph = r->rs.sp_phase[j];
    if (ph == 0.0)
        return 0;
    return ph * dd > 0.0 || (dd == 0.0 && ph * ddd > 0.0) ? (int)ph : 0;
}

double edr_spring_drift(const pd_edr *r, int j, const double *y)
{
    double d = r->tp.sp_sig[j] * y[r->tp.sp_dof[j]];
    return r->tp.sp_dof2[j] >= 0 ? d + r->tp.sp_sig2[j] * y[r->tp.sp_dof2[j]] : d;
}

void edr_spring_at(pd_edr *r, int c, int j, double t, double *d, double *dd, double *ddd)
{
    int i = r->tp.sp_dof[j], i2 = r->tp.sp_dof2[j];
    double sg = r->tp.sp_sig[j], dx, v, a;
    edr_dof_at(r, c, i, t, &dx, &v, &a);
    *d = sg * (r->rs.xo[i] + dx);
    *dd = sg * v;
    *ddd = sg * a;
    if (i2 < 0)
        return;
    sg = r->tp.sp_sig2[j]; /* a storey above the first: its drift takes the dof below */
    edr_dof_at(r, c, i2, t, &dx, &v, &a);
    *d += sg * (r->rs.xo[i2] + dx);
    *dd += sg * v;
    *ddd += sg * a;
}

double edr_spring_up(const pd_edr *r, int j, double d)
{
    int ph = r->rs.sp_phase[j];
    /* sliding toward ph: z = ph uy, so up = d - ph uy; elastic: up fixed */
    return ph != 0 ? d - ph * r->tp.md->uy[j] : r->rs.sp_up[j];
}

void edr_spring_set(pd_edr *r, int j, double d, int phase)
{
    int old = r->rs.sp_phase[j];
    if (phase == old)
        return;
    double up = edr_spring_up(r, j, d); /* at d, in the old phase */
    if (old != 0) {                     /* a slide ends: its excursion (monotone within a slide) */
        r->rs.sp_exc[j] += fabs(up - r->rs.sp_upx[j]);
        r->rs.sp_upx[j] = up;
    } else
        r->rs.sp_onsets[j]++;
    r->rs.sp_phase[j] = (signed char)phase;
    r->rs.sp_up[j] = up;
    if (phase != 0) /* sliding: z exactly on the level at d */
        r->rs.sp_up[j] = edr_spring_up(r, j, d);
}

/* Each spring of cluster ci at its flight's origin: the phase its motion
 * there asks for; 1 when one changed (the flight is built again: the force
 * is continuous across a change, so the state is unchanged). */
static int spring_phases(pd_edr *r, int ci, double t)
{
    edr_cluster *c = &r->rs.cl[ci];
    int changed = 0;
    for (int b = c->head; b >= 0; b = r->rs.blk_next[b]) {
        const edr_block *bk = &r->tp.blk[b];
        for (int k = 0; k < bk->nsp; k++) {
            int j = r->tp.blk_sp[bk->sp0 + k];
            double d, dd, ddd;
            edr_spring_at(r, ci, j, t, &d, &dd, &ddd);
            int ph = spring_phase_at(r, j, dd, ddd);
            if (ph != r->rs.sp_phase[j]) {
                edr_spring_set(r, j, d, ph);
                changed = 1;
            }
        }
    }
    return changed;
}

int edr_cluster_start(pd_edr *r, int ci, double t, pd_err *err)
{
    edr_cluster *c = &r->rs.cl[ci];
    int all_sdof = 1, rc;
    c->t0 = t;
    c->imp_t = t;
    c->en_t = t;
    c->piece = edr_piece_at(r, t);
    c->cached = 0; /* a new flight: the state cached at tc belongs to the old one */
    c->ndof = 0;
    for (int b = c->head; b >= 0; b = r->rs.blk_next[b]) { /* a tree needs SDOF blocks only */
        all_sdof &= r->tp.blk[b].sdof;
        c->ndof += r->tp.blk[b].n;
    }
    int tree = all_sdof && !tree_start(r, c, t);
    /* a tree may have locked contacts already: the modal start re-reads the list */
    if (!tree && (rc = modal_start(r, c, t, err)))
        return rc;
    /* a yielding spring's phase decided at the origin; a change builds the
     * flight again (at most twice: the decision reads the state, which a
     * change leaves as it was); a tree whose new phase has no underdamped
     * flight goes modal */
    for (int pass = 0; r->tp.ns > 0 && pass < 2 && spring_phases(r, ci, t); pass++) {
        if (tree)
            tree = !tree_start(r, c, t);
        if (!tree && (rc = modal_start(r, c, t, err)))
            return rc;
    }
    /* the scan step h = T / divisions, T the shortest of the flight's and the
     * forcing's periods; with neither, a quarter of the run */
    double T = fmin(c->T_min, piece_period(r, c->piece));
    if (!isfinite(T))
        T = 0.25 * (r->rs.t1 - r->tp.pieces[0].t_start);
    c->h = T / r->tp.o.scan_divisions;
    return PD_OK;
}

/* ---- evaluation -------------------------------------------------------------- */

/* Terms of the phi series for |z| (|Re| + |Im|) below 1: the first k with
 * |z|^k / k! under 1e-17 of the sum's 1. */
static int phi_terms(double az)
{
    return az < 1e-4 ? 5 : az < 1e-2 ? 8 : az < 0.1 ? 12 : az < 0.5 ? 17 : 21;
}

/* phi1(z) and phi2(z) by Horner on their series (|z| < 1). */
static void phi12_series(edr_cplx z, int n, edr_cplx *p1, edr_cplx *p2)
{
    edr_cplx s1 = 1.0, s2 = 1.0;
    for (int k = n; k >= 1; k--) { /* phi1 = sum z^k/(k+1)!, phi2 = sum z^k/(k+2)! */
        s1 = 1.0 + s1 * z / (double)(k + 1);
        s2 = 1.0 + s2 * z / (double)(k + 2);
    }
    *p1 = s1;
    *p2 = 0.5 * s2;
}

/* e^z - 1 from expm1 of the real part and sin, cos of the imaginary one
 * (cos - 1 without cancellation), and e^z. */
static edr_cplx expm1_parts(double x, double y, edr_cplx *ez)
{
    double em = expm1(x), sy, cy;
    sy = sin(y);
    cy = cos(y);
    /* cos y - 1 = -sin^2 y / (1 + cos y), exact where cos y - 1 would cancel */
    double cm1 = cy > 0.0 ? -sy * sy / (1.0 + cy) : cy - 1.0, ex = 1.0 + em;
    *ez = ex * cy + I * (ex * sy);
    /* e^z - 1 = (e^x - 1) cos y + (cos y - 1) + i e^x sin y */
    return em * cy + cm1 + I * (ex * sy);
}

/* The modes at t: deta = eta(t) - eta0, etad = eta'(t), by the flight's
 * constants (modal_start): one expm1 and one sin, cos per mode; the phi
 * functions by series below |z| = 1, else from e^z and the precomputed
 * reciprocals of lam and lam -+ i w. */
static void modal_eval(const pd_edr *r, edr_cluster *c, double t)
{
    const edr_basis *B = c->basis;
    const pd_sine_piece *pc = &r->tp.pieces[c->piece];
    /* is = 1 / s is read only where |lam s| >= 1, so never at s = 0 */
    double s = t - c->t0, ft = pd_sine_piece_force(pc, t), is = 1.0 / s;
    edr_cplx ews = 1.0, Aep = 0.0, Aem = 0.0;
    if (pc->A != 0.0) { /* e^{i w s}; beta A / (2i) e^{+-i th} s at t folded below */
        double ws = pc->w * s;
        ews = cos(ws) + I * sin(ws);
        Aep = c->ath0 * ews * s;
        Aem = -conj(c->ath0 * ews) * s; /* conj(1 / (2i)) = -1 / (2i) */
    }
    for (int q = 0; q < B->nmodes; q++) {
        edr_cplx lam = B->lam[q], z = lam * s, ez, p1, p2;
        double x = creal(z), y = cimag(z);
        edr_cplx em1 = expm1_parts(x, y, &ez);
        if (fabs(x) + fabs(y) < 1.0) /* the closed forms would cancel (and lam may be 0) */
            phi12_series(z, phi_terms(fabs(x) + fabs(y)), &p1, &p2);
        else { /* phi1 = (e^z - 1) / z, phi2 = (phi1 - 1) / z with 1 / z = ilam / s */
            p1 = em1 * B->ilam[q] * is;
            p2 = (p1 - 1.0) * B->ilam[q] * is;
        }
        /* eta - eta0 = (e^z - 1) eta0 + s phi1(z) (beta f_lin0 + kap) + s^2 phi2(z) beta c1 */
        edr_cplx de = em1 * c->eta0[q] + s * p1 * c->gq[q] + s * s * p2 * c->bc1[q];
        /* the sinusoid: beta A / (2i) [e^{i th} s phi1(zp) - e^{-i th} s phi1(zm)],
         * zp, zm = (lam -+ i w) s and e^{zp}, e^{zm} = e^z e^{-+i w s} */
        if (pc->A != 0.0) {
            edr_cplx zp = (lam - I * pc->w) * s, zm = (lam + I * pc->w) * s, u1, u2, dummy;
            double ap = fabs(creal(zp)) + fabs(cimag(zp)), am = fabs(creal(zm)) + fabs(cimag(zm));
            if (ap < 1.0)
                phi12_series(zp, phi_terms(ap), &u1, &dummy);
            else
                u1 = (ez * conj(ews) - 1.0) * c->ilp[q] * is;
            if (am < 1.0)
                phi12_series(zm, phi_terms(am), &u2, &dummy);
            else
                u2 = (ez * ews - 1.0) * c->ilm[q] * is;
            de += B->beta[q] * (Aep * u1 - Aem * u2);
        }
        c->deta[q] = de;
        /* the mode's equation: eta' = lam eta + beta f + kap */
        c->etad[q] = lam * (c->eta0[q] + de) + B->beta[q] * ft + c->kapc[q];
    }
    c->f_tc = ft;
}

void edr_cluster_eval(pd_edr *r, int ci, double t)
{
    edr_cluster *c = &r->rs.cl[ci];
    if (c->cached && c->tc == t) /* the scans ask the same t of several dofs and contacts */
        return;
    r->rs.evals++;
    c->tc = t;
    c->cached = 1;
    switch (c->kind) {
    case EDR_SDOF: {
        double dy, vy, s = t - c->t0;
        if (s == 0.0) { /* the origin itself */
            dy = 0.0;
            vy = c->vy0;
        } else if (fabs(s) <= c->s_taylor) {
            /* the series by Horner: y - y0 = sum_{k<=N} y^(k+1) s^(k+1) / (k+1)!,
             * y' = sum y^(k+1) s^k / k!, y'' = sum y^(k+2) s^k / k!, f = sum f^(k) s^k / k! */
            const double *y = c->tay, *f = c->ftay;
            double sy = 0.0, sv = 0.0, sa = 0.0, sf = 0.0;
            for (int k = EDR_TAYLOR_N; k >= 0; k--) {
                double ik = 1.0 / (k + 1);
                sy = (sy + y[k + 1]) * s * ik;
                sv = sv * s * ik + y[k + 1];
                sa = sa * s * ik + y[k + 2];
                sf = sf * s * ik + f[k];
            }
            c->dy = sy;
            c->vy = sv;
            c->ay = sa;
            c->f_tc = sf;
            break;
        } else
            pd_sdof_flow_at(&c->flow, t, &dy, &vy);
        /* y'' = F - 2 xi w0 y' - w0^2 y with F = rho f + kappa (the scaled piece) */
        double w0 = c->osc.w0;
        c->f_tc = edr_force(r, c->piece, t);
        double f = c->rho == 1.0 && c->kappa == 0.0 ? c->f_tc : pd_sine_piece_force(&c->pc, t);
        c->dy = dy;
        c->vy = vy;
        c->ay = f - c->a2 * vy - w0 * w0 * (c->y0 + dy);
        break;
    }
    case EDR_REST: /* held by the wall: y stays y0 */
        c->dy = c->vy = c->ay = 0.0;
        c->f_tc = edr_force(r, c->piece, t);
        break;
    default:
        modal_eval(r, c, t);
        break;
    }
}

void edr_dof_at(pd_edr *r, int ci, int dof, double t, double *dx, double *v, double *a)
{
    edr_cluster *c = &r->rs.cl[ci];
    edr_cluster_eval(r, ci, t);
    if (c->kind != EDR_MODAL) { /* x = s y + d: dx = s dy, v = s y', a = s y'' */
        double s = r->rs.s[dof];
        *dx = s * c->dy;
        *v = s * c->vy;
        *a = s * c->ay;
        return;
    }
    const edr_basis *B = c->basis;
    const edr_cplx *px = B->Px + (size_t)r->rs.crow[dof] * B->nmodes;
    const edr_cplx *pv = B->Pv + (size_t)r->rs.crow[dof] * B->nmodes;
    /* dx = sum wt Re(Px deta), v = sum wt Re(Pv eta), a = sum wt Re(Pv eta'):
     * N times the upper and lower halves of z = V eta, z' = V eta' */
    double sx = 0.0, sv = 0.0, sa = 0.0;
    for (int q = 0; q < B->nmodes; q++) {
        double w = B->wt[q];
        sx += w * creal(px[q] * c->deta[q]);
        sv += w * creal(pv[q] * (c->eta0[q] + c->deta[q]));
        sa += w * creal(pv[q] * c->etad[q]);
    }
    *dx = sx;
    *v = sv;
    *a = sa;
}

/* A modal cluster's dof's jerk: sum wt Re(Pv eta''), eta'' = lam eta' +
 * beta f'(t). */
static double modal_jerk(pd_edr *r, int ci, int dof, double t)
{
    edr_cluster *c = &r->rs.cl[ci];
    edr_cluster_eval(r, ci, t);
    const edr_basis *B = c->basis;
    const pd_sine_piece *p = &r->tp.pieces[c->piece];
    double df = p->c1 + (p->A == 0.0 ? 0.0 : p->A * p->w * cos(p->w * t + p->phi)), s = 0.0;
    const edr_cplx *pv = B->Pv + (size_t)r->rs.crow[dof] * B->nmodes;
    for (int q = 0; q < B->nmodes; q++)
        s += B->wt[q] * creal(pv[q] * (B->lam[q] * c->etad[q] + B->beta[q] * df));
    return s;
}

double edr_dof_jerk(pd_edr *r, int ci, int dof, double t)
{
    edr_cluster *c = &r->rs.cl[ci];
    if (c->kind == EDR_MODAL)
        return modal_jerk(r, ci, dof, t);
    if (c->kind != EDR_SDOF)
        return 0.0;
    edr_cluster_eval(r, ci, t);
    /* y^(3) = F' - a2 y'' - w0^2 y', F' = A w cos(w t + phi) + c1 of the scaled piece */
    const pd_sine_piece *p = &c->pc;
    double dF = p->c1 + (p->A == 0.0 ? 0.0 : p->A * p->w * cos(p->w * t + p->phi));
    return r->rs.s[dof] * (dF - c->a2 * c->ay - c->osc.w0 * c->osc.w0 * c->vy);
}

double edr_force_at(pd_edr *r, int ci, int a, double t)
{
    edr_cluster *c = &r->rs.cl[ci];
    edr_cluster_eval(r, ci, t);
    if (c->kind == EDR_REST) /* lambda = lg f + ld (y held) */
        return r->rs.lg[a] * c->f_tc + r->rs.ld[a];
    if (c->kind == EDR_SDOF)
        return r->rs.la[a] * (c->y0 + c->dy) + r->rs.lb[a] * c->vy + r->rs.lg[a] * c->f_tc +
               r->rs.ld[a];
    /* lambda = gam f + del + sum wt Re(F eta) (contact_force_modes) */
    const edr_basis *B = c->basis;
    int row = r->rs.crow_c[a];
    const edr_cplx *F = B->F + (size_t)row * B->nmodes;
    double s = B->gam[row] * c->f_tc + c->delc[row];
    for (int q = 0; q < B->nmodes; q++)
        s += B->wt[q] * creal(F[q] * (c->eta0[q] + c->deta[q]));
    return s;
}
