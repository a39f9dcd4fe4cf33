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
    return pd_sine_piece_force(&r->pieces[j], t);
}

double edr_piece_end(const pd_edr *r, int j)
{
    return j + 1 < r->npieces ? r->pieces[j + 1].t_start : HUGE_VAL;
}

int edr_piece_at(const pd_edr *r, double t)
{
    int lo = 0, hi = r->npieces - 1;
    while (lo < hi) { /* the last piece starting at or before t */
        int mid = (lo + hi + 1) / 2;
        if (r->pieces[mid].t_start <= t)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

/* Shortest period of piece j's sinusoid (HUGE_VAL: none). */
static double piece_period(const pd_edr *r, int j)
{
    const pd_sine_piece *pc = &r->pieces[j];
    return pc->A != 0.0 && pc->w > 0.0 ? PD_TWO_PI / pc->w : HUGE_VAL;
}

/* ---- complex helpers ----------------------------------------------------------- */

/* ---- the SDOF tree -------------------------------------------------------------- */

/* The side of contact a at dof i: 0 or 1. */
static int side_of(const edr_contact *ct, int i) { return ct->dof[0] == i ? 0 : 1; }

/* The cluster's persistent wall contact, or -1. */
static int wall_edge(const pd_edr *r, const edr_cluster *c)
{
    for (int a = c->pers_head; a >= 0; a = r->pers_next[a])
        if (r->ct[a].dof[0] < 0 || r->ct[a].dof[1] < 0)
            return a;
    return -1;
}

/* Unlink contact a from the cluster's persistent list and lock it. */
static void lock_contact(pd_edr *r, edr_cluster *c, int a)
{
    int *p = &c->pers_head;
    while (*p >= 0 && *p != a)
        p = &r->pers_next[*p];
    if (*p == a) {
        *p = r->pers_next[a];
        c->npers--;
    }
    r->pers_next[a] = -1;
    r->cstate[a] = EDR_LOCKED;
}

/* Breadth-first numbering of the tree from the root: s, d, the parent
 * edge and dof of each node; a persistent edge that closes a cycle (or a
 * second wall) is locked.  ord receives the nodes in order; returns their
 * count. */
static int tree_order(pd_edr *r, edr_cluster *c, int root, int wedge, int *ord, int *pe, int *pd)
{
    int nn = 0, head = 0;
    for (int b = c->head; b >= 0; b = r->blk_next[b])
        r->loc[r->blk_dofs[r->blk[b].first]] = -1;
    r->s[root] = 1.0;
    r->d[root] = 0.0;
    r->loc[root] = 0;
    pe[root] = wedge;
    pd[root] = -1;
    ord[nn++] = root;
    while (head < nn) {
        int u = ord[head++];
        const edr_block *bk = &r->blk[r->dof_blk[u]];
        for (int k = 0; k < bk->ncont; k++) {
            int a = r->blk_cont[bk->cont0 + k];
            if (r->cstate[a] != EDR_PERSIST || a == pe[u])
                continue;
            const edr_contact *ct = &r->ct[a];
            int su = side_of(ct, u), v = ct->dof[1 - su];
            if (v < 0 || r->loc[v] >= 0) { /* a second wall, or a cycle */
                lock_contact(r, c, a);
                continue;
            }
            double wu = ct->w[su], wv = ct->w[1 - su];
            r->s[v] = -wu * r->s[u] / wv;
            r->d[v] = -(ct->g0 + wu * r->d[u]) / wv;
            r->loc[v] = nn;
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
    const pd_sine_piece *p = &r->pieces[c->piece], *q = &c->pc;
    double th = p->w * t + p->phi, sn = sin(th), cs = cos(th), w0 = c->osc.w0;
    double cyc[4] = {sn, cs, -sn, -cs}, wk = 1.0, a2 = 2.0 * c->osc.xi * w0, k0 = w0 * w0;
    double *y = c->tay, *f = c->ftay;
    y[0] = c->y0;
    y[1] = c->vy0;
    for (int k = 0; k <= EDR_TAYLOR_N; k++) {
        double Fk = 0.0, fk = 0.0;
        if (p->A != 0.0) {
            Fk = q->A * wk * cyc[k % 4];
            fk = p->A * wk * cyc[k % 4];
        }
        if (k == 0) {
            Fk += q->c0 + q->c1 * (t - q->t_start);
            fk += p->c0 + p->c1 * (t - p->t_start);
        } else if (k == 1) {
            Fk += q->c1;
            fk += p->c1;
        }
        f[k] = fk;
        y[k + 2] = Fk - a2 * y[k + 1] - k0 * y[k];
        wk *= p->w;
    }
    double Om = fmax(w0, p->A != 0.0 ? p->w : 0.0);
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
    const pd_sine_piece *p = &r->pieces[c->piece];
    c->bnd = 0;
    c->F1 = fabs(p->A) * p->w + fabs(p->c1);
    c->F2 = fabs(p->A) * p->w * p->w;
    if (c->kind == EDR_REST) {
        c->bnd = 1;
        c->Y1 = c->Y2 = c->Y3 = 0.0;
        return;
    }
    const pd_sdof_flow *f = &c->flow;
    if (c->kind != EDR_SDOF || !f->fast || !f->constf)
        return;
    double w = c->pc.A != 0.0 ? c->pc.w : 0.0, w0 = c->osc.w0;
    double P = c->pc.A != 0.0 ? hypot(f->pre, f->pim) : 0.0, R = hypot(f->c1, f->c2);
    c->Y1 = w * P + w0 * R;
    c->Y2 = w * w * P + w0 * w0 * R;
    c->Y3 = w * w * w * P + w0 * w0 * w0 * R;
    c->bnd = 1;
}

/* An SDOF tree: aggregates, edge forces, flight.  Returns 0, or 1 when the
 * tree is no underdamped oscillator (it then runs as a modal cluster). */
static int tree_start(pd_edr *r, edr_cluster *c, double t)
{
    int wedge = wall_edge(r, c);
    int root = wedge >= 0 ? r->ct[wedge].dof[r->ct[wedge].dof[0] < 0 ? 1 : 0]
                          : r->blk_dofs[r->blk[c->head].first];
    int *ord = r->stack, *pe = r->pe, *pd = r->pdof;
    int nn = tree_order(r, c, root, wedge, ord, pe, pd);
    for (int k = 0; k < nn; k++) /* the order kept for the impulses of held edges */
        r->bfs_next[ord[k]] = k + 1 < nn ? ord[k + 1] : -1;
    double *Ms = r->wk, *Cs = Ms + r->n, *Ks = Cs + r->n, *KDs = Ks + r->n, *Bs = KDs + r->n;
    for (int k = 0; k < nn; k++) {
        int i = ord[k];
        const edr_block *bk = &r->blk[r->dof_blk[i]];
        double s = r->s[i];
        Ms[i] = s * s * bk->m;
        Cs[i] = s * s * bk->c;
        Ks[i] = s * s * bk->k;
        KDs[i] = s * bk->k * r->d[i];
        Bs[i] = s * bk->b;
    }
    for (int k = nn - 1; k > 0; k--) { /* subtree sums toward the root */
        int i = ord[k], p = pd[i];
        Ms[p] += Ms[i];
        Cs[p] += Cs[i];
        Ks[p] += Ks[i];
        KDs[p] += KDs[i];
        Bs[p] += Bs[i];
    }
    double M = Ms[root], C = Cs[root], K = Ks[root];
    if (wedge < 0 && (K > 0.0 ? C >= 2.0 * sqrt(K * M) : C > 0.0))
        return 1; /* overdamped, or a damped free mass */
    c->mass = M;
    c->root = root;
    c->rho = Bs[root] / M;
    c->kappa = -KDs[root] / M;
    c->kind = wedge >= 0 ? EDR_REST : EDR_SDOF;
    if (c->kind == EDR_REST) {
        const edr_contact *ct = &r->ct[wedge];
        double ww = ct->w[side_of(ct, root)];
        c->y0 = -ct->g0 / ww;
        c->vy0 = 0.0;
        c->osc = (pd_sdof){.w0 = 0.0, .xi = 0.0};
    } else {
        c->osc = (pd_sdof){.w0 = sqrt(K / M), .xi = K > 0.0 ? C / (2.0 * sqrt(K * M)) : 0.0};
        if (nn == 1) {
            c->y0 = r->xo[root];
            c->vy0 = r->vo[root];
        } else { /* the M-orthogonal projection onto the tree's constraints */
            double sy = 0.0, sv = 0.0;
            for (int k = 0; k < nn; k++) {
                int i = ord[k];
                double m = r->blk[r->dof_blk[i]].m;
                sy += r->s[i] * m * (r->xo[i] - r->d[i]);
                sv += r->s[i] * m * r->vo[i];
            }
            c->y0 = sy / M;
            c->vy0 = sv / M;
        }
    }
    for (int k = 0; k < nn; k++) {
        int i = ord[k];
        if (nn > 1 || c->kind == EDR_REST) {
            r->xo[i] = r->s[i] * c->y0 + r->d[i];
            r->vo[i] = r->s[i] * c->vy0;
        }
    }
    /* edge forces: lambda_e = la y + lb y' + lg f + ld */
    double w2 = c->osc.w0 * c->osc.w0, xw = 2.0 * c->osc.xi * c->osc.w0;
    for (int k = 0; k < nn; k++) {
        int i = ord[k], e = pe[i];
        if (e < 0)
            continue;
        double sw = r->s[i] * r->ct[e].w[side_of(&r->ct[e], i)];
        if (c->kind == EDR_REST) { /* y fixed at y0, at rest */
            r->la[e] = r->lb[e] = 0.0;
            r->lg[e] = -Bs[i] / sw;
            r->ld[e] = (Ks[i] * c->y0 + KDs[i]) / sw;
        } else {
            r->la[e] = (Ks[i] - Ms[i] * w2) / sw;
            r->lb[e] = (Cs[i] - Ms[i] * xw) / sw;
            r->lg[e] = (Ms[i] * c->rho - Bs[i]) / sw;
            r->ld[e] = (Ms[i] * c->kappa + KDs[i]) / sw;
        }
    }
    const pd_sine_piece *p = &r->pieces[c->piece];
    c->pc = *p;
    if (c->rho != 1.0 || c->kappa != 0.0) {
        c->pc.A = p->A * c->rho;
        c->pc.c0 = p->c0 * c->rho + c->kappa;
        c->pc.c1 = p->c1 * c->rho;
    }
    if (c->kind == EDR_SDOF) {
        pd_sdof_flow_init(&c->flow, &c->osc, &c->pc, t, c->y0, c->vy0);
        taylor_init(r, c, t);
    }
    flight_bounds(r, c);
    c->T_min = c->kind == EDR_SDOF && c->osc.w0 > 0.0 ? PD_TWO_PI / c->osc.w0 : HUGE_VAL;
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
    free(b->keyv);
    free(b);
}

void edr_basis_cache_free(pd_edr *r)
{
    if (!r->bhash)
        return;
    for (int h = 0; h < r->nbhash; h++) {
        edr_basis *b = r->bhash[h];
        while (b) {
            edr_basis *nx = b->next;
            basis_free(b);
            b = nx;
        }
    }
    free(r->bhash);
    r->bhash = NULL;
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
    c->eta0 = c->deta = c->etad = c->gq = c->bc1 = c->ilp = c->ilm = NULL;
    c->cap = 0;
}

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* The configuration's key: sorted blocks, -1, sorted persistent contacts. */
static int config_key(pd_edr *r, const edr_cluster *c, int *key, unsigned long *hash)
{
    int nk = 0, nb0;
    for (int b = c->head; b >= 0; b = r->blk_next[b])
        key[nk++] = b;
    nb0 = nk;
    qsort(key, (size_t)nb0, sizeof(int), cmp_int);
    key[nk++] = -1;
    int a0 = nk;
    for (int a = c->pers_head; a >= 0; a = r->pers_next[a])
        key[nk++] = a;
    qsort(key + a0, (size_t)(nk - a0), sizeof(int), cmp_int);
    unsigned long h = 1469598103934665603UL;
    for (int k = 0; k < nk; k++)
        h = (h ^ (unsigned long)(unsigned)key[k]) * 1099511628211UL;
    *hash = h;
    return nk;
}

/* Column-major helpers on GSL matrices (row i, column j). */
#define MG(m, i, j) gsl_matrix_get((m), (size_t)(i), (size_t)(j))

/* Build the basis of a configuration (blocks key[0..nb0), contacts after
 * the -1).  Dependent constraint contacts are listed in *dep (count ndep). */
static int basis_build(pd_edr *r, const int *key, int nk, edr_basis **out, int *dep, int *ndep,
                       pd_err *err)
{
    int nb0 = 0, ncon = 0, rc = PD_OK;
    while (key[nb0] >= 0)
        nb0++;
    const int *cons = key + nb0 + 1;
    ncon = nk - nb0 - 1;
    int nc = 0;
    for (int k = 0; k < nb0; k++)
        nc += r->blk[key[k]].n;
    edr_basis *B = calloc(1, sizeof *B);
    gsl_matrix *Wm = NULL, *Q = NULL, *R = NULL, *N = NULL, *Mr = NULL, *Cr = NULL, *Kr = NULL;
    gsl_matrix *Sm = NULL, *T = NULL;
    gsl_vector *tau = NULL;
    gsl_vector_complex *ev = NULL;
    gsl_matrix_complex *V = NULL, *Vi = NULL, *LU = NULL;
    gsl_permutation *perm = NULL;
    gsl_eigen_nonsymmv_workspace *ew = NULL;
    double *Cc = NULL, *Kc = NULL, *bc = NULL, *g0 = NULL, *Wd = NULL, *L = NULL, *tmp = NULL;
    double *af = NULL, *ak = NULL, *Kq = NULL, *mrb = NULL, *mrk = NULL;
    int *indep = NULL;
    *ndep = 0;
    if (!B)
        return pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
    B->nc = nc;
    B->dofs = malloc((size_t)nc * sizeof(int));
    B->keyv = malloc((size_t)nk * sizeof(int));
    Cc = calloc((size_t)nc * nc, sizeof(double));
    Kc = calloc((size_t)nc * nc, sizeof(double));
    bc = calloc((size_t)nc, sizeof(double));
    Wd = calloc((size_t)nc * (ncon > 0 ? ncon : 1), sizeof(double));
    g0 = calloc((size_t)(ncon > 0 ? ncon : 1), sizeof(double));
    indep = malloc((size_t)(ncon > 0 ? ncon : 1) * sizeof(int));
    tmp = malloc((size_t)(4 * nc + 4) * sizeof(double));
    if (!B->dofs || !B->keyv || !Cc || !Kc || !bc || !Wd || !g0 || !indep || !tmp) {
        rc = pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes (%d dofs)", nc);
        goto done;
    }
    memcpy(B->keyv, key, (size_t)nk * sizeof(int));
    B->nkey = nk;
    /* the cluster's dofs, their local index, the blocks' C, K, b */
    int at = 0;
    for (int k = 0; k < nb0; k++) {
        const edr_block *bk = &r->blk[key[k]];
        long off = r->blk_off[key[k]];
        for (int i = 0; i < bk->n; i++) {
            int gi = r->blk_dofs[bk->first + i];
            B->dofs[at + i] = gi;
            r->loc[gi] = at + i;
            bc[at + i] = r->b[gi];
            for (int j = 0; j < bk->n; j++) {
                Cc[(at + i) + (size_t)(at + j) * nc] = r->Cb[off + i + (long)j * bk->n];
                Kc[(at + i) + (size_t)(at + j) * nc] = r->Kb[off + i + (long)j * bk->n];
            }
        }
        at += bk->n;
    }
    /* independent constraint directions by modified Gram-Schmidt */
    int nr = 0;
    for (int k = 0; k < ncon; k++) {
        const edr_contact *ct = &r->ct[cons[k]];
        double *col = Wd + (size_t)nr * nc, nrm0 = 0.0, nrm = 0.0;
        memset(col, 0, (size_t)nc * sizeof(double));
        for (int s = 0; s < 2; s++)
            if (ct->dof[s] >= 0)
                col[r->loc[ct->dof[s]]] += ct->w[s];
        for (int i = 0; i < nc; i++)
            nrm0 += col[i] * col[i];
        /* exact test by projection through a small QR of the kept columns */
        Wm = gsl_matrix_alloc((size_t)nc, (size_t)(nr + 1));
        tau = gsl_vector_alloc((size_t)(nr + 1 < nc ? nr + 1 : nc));
        if (!Wm || !tau) {
            rc = pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
            goto done;
        }
        for (int j = 0; j <= nr; j++)
            for (int i = 0; i < nc; i++)
                gsl_matrix_set(Wm, (size_t)i, (size_t)j, Wd[(size_t)j * nc + i]);
        int full = nr + 1 <= nc;
        if (full) {
            gsl_linalg_QR_decomp(Wm, tau);
            nrm = fabs(MG(Wm, nr, nr));
        }
        gsl_matrix_free(Wm);
        gsl_vector_free(tau);
        Wm = NULL;
        tau = NULL;
        if (full && nrm > DEPENDENT_TOL * sqrt(nrm0)) {
            indep[nr] = cons[k];
            g0[nr] = ct->g0;
            nr++;
        } else
            dep[(*ndep)++] = cons[k];
    }
    int k = nc - nr;
    B->r = nr;
    B->k = k;
    B->cons = malloc((size_t)(nr > 0 ? nr : 1) * sizeof(int));
    B->qstar = calloc((size_t)nc, sizeof(double));
    B->gam = calloc((size_t)(nr > 0 ? nr : 1), sizeof(double));
    B->del = calloc((size_t)(nr > 0 ? nr : 1), sizeof(double));
    Q = gsl_matrix_alloc((size_t)nc, (size_t)nc);
    N = k > 0 ? gsl_matrix_alloc((size_t)nc, (size_t)k) : NULL;
    L = calloc((size_t)(nr > 0 ? nr : 1) * nc, sizeof(double));
    if (!B->cons || !B->qstar || !B->gam || !B->del || !Q || (k > 0 && !N) || !L) {
        rc = pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
        goto done;
    }
    memcpy(B->cons, indep, (size_t)nr * sizeof(int));
    /* W = Q1 R: N = Q2, q* = -Q1 R^-T g0, L = R^-1 Q1^T */
    if (nr > 0) {
        Wm = gsl_matrix_alloc((size_t)nc, (size_t)nr);
        tau = gsl_vector_alloc((size_t)nr);
        R = gsl_matrix_alloc((size_t)nc, (size_t)nr);
        if (!Wm || !tau || !R) {
            rc = pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
            goto done;
        }
        for (int j = 0; j < nr; j++)
            for (int i = 0; i < nc; i++)
                gsl_matrix_set(Wm, (size_t)i, (size_t)j, Wd[(size_t)j * nc + i]);
        gsl_linalg_QR_decomp(Wm, tau);
        gsl_linalg_QR_unpack(Wm, tau, Q, R);
        double *u = tmp; /* R^T u = -g0 (forward), q* = Q1 u */
        for (int i = 0; i < nr; i++) {
            double s = -g0[i];
            for (int j = 0; j < i; j++)
                s -= MG(R, j, i) * u[j];
            u[i] = s / MG(R, i, i);
        }
        for (int i = 0; i < nc; i++) {
            double s = 0.0;
            for (int j = 0; j < nr; j++)
                s += MG(Q, i, j) * u[j];
            B->qstar[i] = s;
        }
        for (int i = 0; i < nc; i++) /* L column i: R^-1 (Q1^T e_i), back substitution */
            for (int a = nr - 1; a >= 0; a--) {
                double s = MG(Q, i, a);
                for (int j = a + 1; j < nr; j++)
                    s -= MG(R, a, j) * L[j + (size_t)i * nr];
                L[a + (size_t)i * nr] = s / MG(R, a, a);
            }
    } else
        gsl_matrix_set_identity(Q);
    for (int j = 0; j < k; j++)
        for (int i = 0; i < nc; i++)
            gsl_matrix_set(N, (size_t)i, (size_t)j, MG(Q, i, nr + j));
    /* the reduced system */
    double *minv = r->minv;
    int nm = 0;
    if (k > 0) {
        Mr = gsl_matrix_alloc((size_t)k, (size_t)k);
        Cr = gsl_matrix_alloc((size_t)k, (size_t)k);
        Kr = gsl_matrix_alloc((size_t)k, (size_t)k);
        Sm = gsl_matrix_calloc((size_t)(2 * k), (size_t)(2 * k));
        T = gsl_matrix_alloc((size_t)k, (size_t)k);
        mrb = calloc((size_t)k, sizeof(double));
        mrk = calloc((size_t)k, sizeof(double));
        Kq = calloc((size_t)nc, sizeof(double));
        af = calloc((size_t)nc, sizeof(double));
        ak = calloc((size_t)nc, sizeof(double));
        ev = gsl_vector_complex_alloc((size_t)(2 * k));
        V = gsl_matrix_complex_alloc((size_t)(2 * k), (size_t)(2 * k));
        Vi = gsl_matrix_complex_alloc((size_t)(2 * k), (size_t)(2 * k));
        LU = gsl_matrix_complex_alloc((size_t)(2 * k), (size_t)(2 * k));
        perm = gsl_permutation_alloc((size_t)(2 * k));
        ew = gsl_eigen_nonsymmv_alloc((size_t)(2 * k));
        B->Y = malloc((size_t)k * nc * sizeof(double));
        if (!Mr || !Cr || !Kr || !Sm || !T || !mrb || !mrk || !Kq || !af || !ak || !ev || !V ||
            !Vi || !LU || !perm || !ew || !B->Y) {
            rc = pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes (%d dofs)", nc);
            goto done;
        }
        for (int i = 0; i < nc; i++) { /* K q* */
            double s = 0.0;
            for (int j = 0; j < nc; j++)
                s += Kc[i + (size_t)j * nc] * B->qstar[j];
            Kq[i] = s;
        }
        for (int a = 0; a < k; a++)
            for (int b2 = 0; b2 < k; b2++) {
                double sm = 0.0, scc = 0.0, sk = 0.0;
                for (int i = 0; i < nc; i++) {
                    double nia = MG(N, i, a);
                    if (nia == 0.0)
                        continue;
                    double cn = 0.0, kn = 0.0;
                    for (int j = 0; j < nc; j++) {
                        double njb = MG(N, j, b2);
                        cn += Cc[i + (size_t)j * nc] * njb;
                        kn += Kc[i + (size_t)j * nc] * njb;
                    }
                    sm += nia * MG(N, i, b2) / minv[B->dofs[i]];
                    scc += nia * cn;
                    sk += nia * kn;
                }
                gsl_matrix_set(Mr, (size_t)a, (size_t)b2, sm);
                gsl_matrix_set(Cr, (size_t)a, (size_t)b2, scc);
                gsl_matrix_set(Kr, (size_t)a, (size_t)b2, sk);
            }
        for (int a = 0; a < k; a++) {
            double sb = 0.0, sq = 0.0;
            for (int i = 0; i < nc; i++) {
                sb += MG(N, i, a) * bc[i];
                sq -= MG(N, i, a) * Kq[i];
            }
            mrb[a] = sb;
            mrk[a] = sq;
        }
        if (gsl_linalg_cholesky_decomp1(Mr) || gsl_linalg_cholesky_invert(Mr)) {
            rc = pd_err_set(err, PD_ESINGULAR, "row reference: a cluster's reduced mass matrix "
                                               "is not positive definite");
            goto done;
        }
        /* Mr^-1 br, Mr^-1 kr; S = [0 I; -Mr^-1 Kr, -Mr^-1 Cr]; Y = Mr^-1 N^T M */
        for (int a = 0; a < k; a++) {
            double s1 = 0.0, s2 = 0.0;
            for (int b2 = 0; b2 < k; b2++) {
                s1 += MG(Mr, a, b2) * mrb[b2];
                s2 += MG(Mr, a, b2) * mrk[b2];
            }
            tmp[a] = s1;
            tmp[k + a] = s2;
        }
        memcpy(mrb, tmp, (size_t)k * sizeof(double));
        memcpy(mrk, tmp + k, (size_t)k * sizeof(double));
        for (int a = 0; a < k; a++) {
            gsl_matrix_set(Sm, (size_t)a, (size_t)(k + a), 1.0);
            for (int b2 = 0; b2 < k; b2++) {
                double sk = 0.0, scc = 0.0;
                for (int c2 = 0; c2 < k; c2++) {
                    sk += MG(Mr, a, c2) * MG(Kr, c2, b2);
                    scc += MG(Mr, a, c2) * MG(Cr, c2, b2);
                }
                gsl_matrix_set(Sm, (size_t)(k + a), (size_t)b2, -sk);
                gsl_matrix_set(Sm, (size_t)(k + a), (size_t)(k + b2), -scc);
            }
            for (int i = 0; i < nc; i++) {
                double s = 0.0;
                for (int b2 = 0; b2 < k; b2++)
                    s += MG(Mr, a, b2) * MG(N, i, b2);
                B->Y[a + (size_t)i * k] = s / minv[B->dofs[i]];
            }
        }
        for (int i = 0; i < nc; i++) { /* accelerations of f and of the constant force */
            double s1 = 0.0, s2 = 0.0;
            for (int a = 0; a < k; a++) {
                s1 += MG(N, i, a) * mrb[a];
                s2 += MG(N, i, a) * mrk[a];
            }
            af[i] = s1;
            ak[i] = s2;
        }
        gsl_eigen_nonsymmv_params(1, ew);
        if (gsl_eigen_nonsymmv(Sm, ev, V, ew)) {
            rc = pd_err_set(err, PD_ENUMERICAL, "row reference: the eigenvalues of a cluster of "
                                                "%d dofs did not converge", nc);
            goto done;
        }
        int sgn;
        gsl_matrix_complex_memcpy(LU, V);
        if (gsl_linalg_complex_LU_decomp(LU, perm, &sgn) || gsl_linalg_complex_LU_invert(LU, perm, Vi)) {
            rc = pd_err_set(err, PD_ENUMERICAL, "row reference: a cluster of %d dofs has a "
                                                "defective modal basis", nc);
            goto done;
        }
        double nv = 0.0, nvi = 0.0; /* 1-norm condition of V */
        for (int j = 0; j < 2 * k; j++) {
            double s1 = 0.0, s2 = 0.0;
            for (int i = 0; i < 2 * k; i++) {
                s1 += gsl_complex_abs(gsl_matrix_complex_get(V, (size_t)i, (size_t)j));
                s2 += gsl_complex_abs(gsl_matrix_complex_get(Vi, (size_t)i, (size_t)j));
            }
            nv = fmax(nv, s1);
            nvi = fmax(nvi, s2);
        }
        if (!(nv * nvi < MODAL_COND_MAX)) {
            rc = pd_err_set(err, PD_ENUMERICAL, "row reference: a cluster of %d dofs is nearly "
                                                "defective (modal basis condition %.3g): a "
                                                "critically damped mode?", nc, nv * nvi);
            goto done;
        }
        for (int j = 0; j < 2 * k; j++)
            nm += GSL_IMAG(gsl_vector_complex_get(ev, (size_t)j)) >= 0.0;
    }
    B->nmodes = nm;
    size_t nmz = (size_t)(nm > 0 ? nm : 1);
    B->lam = malloc(nmz * sizeof(edr_cplx));
    B->ilam = malloc(nmz * sizeof(edr_cplx));
    B->beta = malloc(nmz * sizeof(edr_cplx));
    B->kap = malloc(nmz * sizeof(edr_cplx));
    B->wt = malloc(nmz * sizeof(double));
    B->Px = malloc(nmz * (size_t)nc * sizeof(edr_cplx));
    B->Pv = malloc(nmz * (size_t)nc * sizeof(edr_cplx));
    B->Z = malloc(nmz * (size_t)(2 * (k > 0 ? k : 1)) * sizeof(edr_cplx));
    B->F = malloc(nmz * (size_t)(nr > 0 ? nr : 1) * sizeof(edr_cplx));
    if (!B->lam || !B->ilam || !B->beta || !B->kap || !B->wt || !B->Px || !B->Pv || !B->Z ||
        !B->F) {
        rc = pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
        goto done;
    }
    double lmax = 0.0;
    for (int j = 0, q = 0; j < 2 * k; j++) {
        gsl_complex l = gsl_vector_complex_get(ev, (size_t)j);
        if (GSL_IMAG(l) < 0.0)
            continue;
        edr_cplx lam = GSL_REAL(l) + I * GSL_IMAG(l), bt = 0.0, kp = 0.0;
        for (int a = 0; a < k; a++) {
            gsl_complex z = gsl_matrix_complex_get(Vi, (size_t)j, (size_t)(k + a));
            edr_cplx zz = GSL_REAL(z) + I * GSL_IMAG(z);
            bt += zz * mrb[a];
            kp += zz * mrk[a];
        }
        B->lam[q] = lam;
        B->ilam[q] = 1.0 / lam;
        B->beta[q] = bt;
        B->kap[q] = kp;
        B->wt[q] = GSL_IMAG(l) > 0.0 ? 2.0 : 1.0;
        lmax = fmax(lmax, cabs(lam));
        for (int l2 = 0; l2 < 2 * k; l2++) {
            gsl_complex z = gsl_matrix_complex_get(Vi, (size_t)j, (size_t)l2);
            B->Z[(size_t)q * 2 * k + l2] = GSL_REAL(z) + I * GSL_IMAG(z);
        }
        for (int i = 0; i < nc; i++) {
            edr_cplx px = 0.0, pv = 0.0;
            for (int a = 0; a < k; a++) {
                gsl_complex v1 = gsl_matrix_complex_get(V, (size_t)a, (size_t)j);
                gsl_complex v2 = gsl_matrix_complex_get(V, (size_t)(k + a), (size_t)j);
                px += MG(N, i, a) * (GSL_REAL(v1) + I * GSL_IMAG(v1));
                pv += MG(N, i, a) * (GSL_REAL(v2) + I * GSL_IMAG(v2));
            }
            B->Px[(size_t)i * nm + q] = px;
            B->Pv[(size_t)i * nm + q] = pv;
        }
        q++;
    }
    B->T_min = lmax > 0.0 ? PD_TWO_PI / lmax : HUGE_VAL;
    /* contact forces: lambda = L (M a + C v + K q - b f) */
    for (int c2 = 0; c2 < nr; c2++) {
        double gsum = 0.0, dsum = 0.0;
        for (int i = 0; i < nc; i++) {
            double l = L[c2 + (size_t)i * nr];
            if (l == 0.0)
                continue;
            double mi = 1.0 / minv[B->dofs[i]], kq = 0.0;
            for (int j = 0; j < nc; j++)
                kq += Kc[i + (size_t)j * nc] * B->qstar[j];
            gsum += l * (mi * (k > 0 ? af[i] : 0.0) - bc[i]);
            dsum += l * (mi * (k > 0 ? ak[i] : 0.0) + kq);
        }
        B->gam[c2] = gsum;
        B->del[c2] = dsum;
        for (int q = 0; q < nm; q++) {
            edr_cplx s = 0.0;
            for (int i = 0; i < nc; i++) {
                double l = L[c2 + (size_t)i * nr];
                if (l == 0.0)
                    continue;
                edr_cplx cv = 0.0, kx = 0.0;
                for (int j = 0; j < nc; j++) {
                    cv += Cc[i + (size_t)j * nc] * B->Pv[(size_t)j * nm + q];
                    kx += Kc[i + (size_t)j * nc] * B->Px[(size_t)j * nm + q];
                }
                s += l * (B->Pv[(size_t)i * nm + q] * B->lam[q] / minv[B->dofs[i]] + cv + kx);
            }
            B->F[(size_t)c2 * nm + q] = s;
        }
    }
done:
    gsl_matrix_free(Wm);
    gsl_matrix_free(Q);
    gsl_matrix_free(R);
    gsl_matrix_free(N);
    gsl_matrix_free(Mr);
    gsl_matrix_free(Cr);
    gsl_matrix_free(Kr);
    gsl_matrix_free(Sm);
    gsl_matrix_free(T);
    gsl_vector_free(tau);
    gsl_vector_complex_free(ev);
    gsl_matrix_complex_free(V);
    gsl_matrix_complex_free(Vi);
    gsl_matrix_complex_free(LU);
    gsl_permutation_free(perm);
    if (ew)
        gsl_eigen_nonsymmv_free(ew);
    free(Cc);
    free(Kc);
    free(bc);
    free(g0);
    free(Wd);
    free(L);
    free(tmp);
    free(af);
    free(ak);
    free(Kq);
    free(mrb);
    free(mrk);
    free(indep);
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
    int *key = r->keybuf, *dep = r->keybuf + r->nb + r->m + 1, ndep = 0, rc;
    unsigned long h;
    int nk = config_key(r, c, key, &h);
    if (!r->bhash) {
        r->nbhash = BASIS_BUCKETS;
        if (!(r->bhash = calloc((size_t)r->nbhash, sizeof *r->bhash)))
            return pd_err_set(err, PD_ENOMEM, "out of memory for the modal cache");
    }
    edr_basis **slot = &r->bhash[h % (unsigned long)r->nbhash];
    for (edr_basis *b = *slot; b; b = b->next)
        if (b->key == h && b->nkey == nk && !memcmp(b->keyv, key, (size_t)nk * sizeof(int))) {
            *out = b;
            return PD_OK;
        }
    edr_basis *b = NULL;
    gsl_set_error_handler_off(); /* GSL's default handler aborts (docs/api.md) */
    if ((rc = basis_build(r, key, nk, &b, dep, &ndep, err)))
        return rc;
    b->key = h;
    b->next = *slot;
    *slot = b;
    r->nbasis++;
    *out = b;
    return PD_OK;
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
        nx = r->pers_next[a];
        int in = 0;
        for (int j = 0; j < B->r && !in; j++)
            in = B->cons[j] == a;
        if (!in)
            lock_contact(r, c, a);
    }
    for (int j = 0; j < B->r; j++)
        r->crow_c[B->cons[j]] = j;
    if (c->cap < B->nmodes) {
        edr_cluster_free(c);
        int cap = B->nmodes;
        c->eta0 = malloc((size_t)cap * sizeof(edr_cplx));
        c->deta = malloc((size_t)cap * sizeof(edr_cplx));
        c->etad = malloc((size_t)cap * sizeof(edr_cplx));
        c->gq = malloc((size_t)cap * sizeof(edr_cplx));
        c->bc1 = malloc((size_t)cap * sizeof(edr_cplx));
        c->ilp = malloc((size_t)cap * sizeof(edr_cplx));
        c->ilm = malloc((size_t)cap * sizeof(edr_cplx));
        if (!c->eta0 || !c->deta || !c->etad || !c->gq || !c->bc1 || !c->ilp || !c->ilm) {
            edr_cluster_free(c);
            return pd_err_set(err, PD_ENOMEM, "out of memory for a cluster's modes");
        }
        c->cap = cap;
    }
    c->kind = EDR_MODAL;
    c->basis = B;
    c->bnd = 0;
    int nc = B->nc, k = B->k;
    double *y = r->wk, *yd = y + nc;
    for (int i = 0; i < nc; i++)
        r->crow[B->dofs[i]] = i;
    for (int a = 0; a < k; a++) { /* y0 = Y (x - q*), y0' = Y v */
        double s1 = 0.0, s2 = 0.0;
        for (int i = 0; i < nc; i++) {
            int gi = B->dofs[i];
            s1 += B->Y[a + (size_t)i * k] * (r->xo[gi] - B->qstar[i]);
            s2 += B->Y[a + (size_t)i * k] * r->vo[gi];
        }
        y[a] = s1;
        yd[a] = s2;
    }
    for (int q = 0; q < B->nmodes; q++) {
        edr_cplx e = 0.0;
        const edr_cplx *z = B->Z + (size_t)q * 2 * k;
        for (int a = 0; a < k; a++)
            e += z[a] * y[a] + z[k + a] * yd[a];
        c->eta0[q] = e;
    }
    for (int i = 0; i < nc; i++) { /* the projected origin */
        double x = B->qstar[i], v = 0.0;
        for (int q = 0; q < B->nmodes; q++) {
            x += B->wt[q] * creal(B->Px[(size_t)i * B->nmodes + q] * c->eta0[q]);
            v += B->wt[q] * creal(B->Pv[(size_t)i * B->nmodes + q] * c->eta0[q]);
        }
        r->xo[B->dofs[i]] = x;
        r->vo[B->dofs[i]] = v;
    }
    /* the flight's constants: beta f_lin(t0) + kap, beta c1, A / (2i) e^{i th(t0)},
     * 1 / (lam -+ i w) */
    const pd_sine_piece *pc = &r->pieces[c->piece];
    double fl0 = pc->c0 + pc->c1 * (t - pc->t_start), th = pc->w * t + pc->phi;
    c->ath0 = pc->A != 0.0 ? pc->A / (2.0 * I) * (cos(th) + I * sin(th)) : 0.0;
    for (int q = 0; q < B->nmodes; q++) {
        c->gq[q] = B->beta[q] * fl0 + B->kap[q];
        c->bc1[q] = B->beta[q] * pc->c1;
        if (pc->A != 0.0) {
            edr_cplx lp = B->lam[q] - I * pc->w, lm = B->lam[q] + I * pc->w;
            c->ilp[q] = cabs(lp) > 0.0 ? 1.0 / lp : 0.0; /* (0: the series serves) */
            c->ilm[q] = cabs(lm) > 0.0 ? 1.0 / lm : 0.0;
        }
    }
    c->T_min = B->T_min;
    return PD_OK;
}

int edr_cluster_start(pd_edr *r, int ci, double t, pd_err *err)
{
    edr_cluster *c = &r->cl[ci];
    int all_sdof = 1, rc;
    c->t0 = t;
    c->imp_t = t;
    c->piece = edr_piece_at(r, t);
    c->cached = 0;
    c->ndof = 0;
    for (int b = c->head; b >= 0; b = r->blk_next[b]) {
        all_sdof &= r->blk[b].sdof;
        c->ndof += r->blk[b].n;
    }
    if (!all_sdof || tree_start(r, c, t)) {
        /* a tree may have locked contacts already: the modal start re-reads the list */
        if ((rc = modal_start(r, c, t, err)))
            return rc;
    }
    double T = fmin(c->T_min, piece_period(r, c->piece));
    if (!isfinite(T))
        T = 0.25 * (r->t1 - r->pieces[0].t_start);
    c->h = T / r->o.scan_divisions;
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
    double cm1 = cy > 0.0 ? -sy * sy / (1.0 + cy) : cy - 1.0, ex = 1.0 + em;
    *ez = ex * cy + I * (ex * sy);
    return em * cy + cm1 + I * (ex * sy);
}

/* The modes at t: deta = eta(t) - eta0, etad = eta'(t), by the flight's
 * constants (modal_start): one expm1 and one sin, cos per mode; the phi
 * functions by series below |z| = 1, else from e^z and the precomputed
 * reciprocals of lam and lam -+ i w. */
static void modal_eval(const pd_edr *r, edr_cluster *c, double t)
{
    const edr_basis *B = c->basis;
    const pd_sine_piece *pc = &r->pieces[c->piece];
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
        if (fabs(x) + fabs(y) < 1.0)
            phi12_series(z, phi_terms(fabs(x) + fabs(y)), &p1, &p2);
        else {
            p1 = em1 * B->ilam[q] * is;
            p2 = (p1 - 1.0) * B->ilam[q] * is;
        }
        edr_cplx de = em1 * c->eta0[q] + s * p1 * c->gq[q] + s * s * p2 * c->bc1[q];
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
        c->etad[q] = lam * (c->eta0[q] + de) + B->beta[q] * ft + B->kap[q];
    }
    c->f_tc = ft;
}

void edr_cluster_eval(pd_edr *r, int ci, double t)
{
    edr_cluster *c = &r->cl[ci];
    if (c->cached && c->tc == t)
        return;
    r->evals++;
    c->tc = t;
    c->cached = 1;
    switch (c->kind) {
    case EDR_SDOF: {
        double dy, vy, s = t - c->t0;
        if (s == 0.0) {
            dy = 0.0;
            vy = c->vy0;
        } else if (fabs(s) <= c->s_taylor) { /* the series: y, y', y'', f by Horner */
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
        double w0 = c->osc.w0;
        c->f_tc = edr_force(r, c->piece, t);
        double f = c->rho == 1.0 && c->kappa == 0.0 ? c->f_tc : pd_sine_piece_force(&c->pc, t);
        c->dy = dy;
        c->vy = vy;
        c->ay = f - 2.0 * c->osc.xi * w0 * vy - w0 * w0 * (c->y0 + dy);
        break;
    }
    case EDR_REST:
        c->dy = c->vy = c->ay = 0.0;
        c->f_tc = edr_force(r, c->piece, t);
        break;
    default: modal_eval(r, c, t); break;
    }
}

void edr_dof_at(pd_edr *r, int ci, int dof, double t, double *dx, double *v, double *a)
{
    edr_cluster *c = &r->cl[ci];
    edr_cluster_eval(r, ci, t);
    if (c->kind != EDR_MODAL) {
        double s = r->s[dof];
        *dx = s * c->dy;
        *v = s * c->vy;
        *a = s * c->ay;
        return;
    }
    const edr_basis *B = c->basis;
    const edr_cplx *px = B->Px + (size_t)r->crow[dof] * B->nmodes;
    const edr_cplx *pv = B->Pv + (size_t)r->crow[dof] * B->nmodes;
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

double edr_force_at(pd_edr *r, int ci, int a, double t)
{
    edr_cluster *c = &r->cl[ci];
    edr_cluster_eval(r, ci, t);
    if (c->kind == EDR_REST)
        return r->lg[a] * c->f_tc + r->ld[a];
    if (c->kind == EDR_SDOF)
        return r->la[a] * (c->y0 + c->dy) + r->lb[a] * c->vy + r->lg[a] * c->f_tc + r->ld[a];
    const edr_basis *B = c->basis;
    int row = r->crow_c[a];
    const edr_cplx *F = B->F + (size_t)row * B->nmodes;
    double s = B->gam[row] * c->f_tc + B->del[row];
    for (int q = 0; q < B->nmodes; q++)
        s += B->wt[q] * creal(F[q] * (c->eta0[q] + c->deta[q]));
    return s;
}
