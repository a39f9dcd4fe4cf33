/* event_row.h — private to the exact event-driven reference for rows
 * (engine/event_row.c, event_row_cluster.c, event_row_scan.c); the public interface is
 * pd_edr_* in pd_engine.h.
 *
 * Vocabulary.  A *block* is a structure: the dofs that M, C, K couple (an
 * SDOF, or a shear building).  A *contact* joins one dof of one block to
 * one dof of another, or to a wall.  A *cluster* is a set of blocks held
 * together by persistent contacts (its constraints), moving by one exact
 * closed-form *flight* from its origin (t0, state) until an event touches
 * it.  Kinds of cluster:
 *   SDOF   SDOF blocks only, no wall: one generalised coordinate y,
 *          x_i = s_i y + d_i, an underdamped oscillator (pd_sdof_flow);
 *   REST   SDOF blocks held against a wall: no coordinate left (y fixed);
 *   MODAL  anything else (a building, or SDOFs overdamped together): the
 *          constrained system's complex modes, each a scalar closed form
 *          (exponential-integrator phi functions of the forcing piece). */
#ifndef PD_EDR_H
#define PD_EDR_H

#include <complex.h>

#include "pd_engine.h"

typedef double complex edr_cplx;

enum { EDR_SDOF = 1, EDR_REST = 2, EDR_MODAL = 3 };

/* Degree of a flight's Taylor series near its origin (event_row_cluster.c). */
#define EDR_TAYLOR_N 7

/* ---- scanning a scalar function f (event_row_scan.c) ------------------------- *
 * The one-wall reference's scan carried to any closed-form function with
 * its first two derivatives: on each scan interval f' is nearly quadratic,
 * so it turns at most twice; every turn is located (an extremum, noted)
 * and, in hit mode, the first time f becomes > 0 (a gap closing when
 * f = -gap), grazing maxima included. */
typedef void (*edr_fn)(void *ctx, double t, double out[3]); /* f, f', f'' at t */

typedef struct edr_pt {
    double t, f, df, ddf;
} edr_pt;

typedef struct edr_scan {
    edr_fn fn;
    void *ctx;
    double width;      /* extrema located to this width (root times to adjacent doubles) */
    int hit_mode;      /* 1: stop at the first f > 0 once f exceeds thr somewhere */
    double thr;        /* the rounding level of f: a crossing must reach above it */
    double fmax, fmin; /* extremes noted (initialise to -inf / +inf) */
    long evals;
} edr_scan;

edr_pt edr_scan_point(edr_scan *s, double t);
/* The smallest s > 0 where the Taylor quadratic of f at a vanishes (NAN: none). */
double edr_taylor_root(const edr_pt *a);
void edr_scan_note(edr_scan *s, double f);
/* One interval (a, b]: 1 with *t_hit (the first double where f > 0) in hit
 * mode, else 0 after noting every interior extremum and f(b). */
int edr_scan_interval(edr_scan *s, const edr_pt *a, const edr_pt *b, double *t_hit);
/* The first double in (lo, hi] where g > 0 given g(lo) <= 0 < g(hi), by
 * bisection on the sign of out[k] of fn. */
double edr_bisect_sign(edr_fn fn, void *ctx, int k, double sign, double lo, double hi);

/* ---- model pieces ----------------------------------------------------------- */

typedef struct edr_block {
    int n;            /* dofs */
    int first;        /* its dofs: r->tp.blk_dofs[first .. first + n) */
    int sdof;         /* one dof */
    double m, c, k;   /* SDOF: its scalars */
    double b;         /* SDOF: its load coefficient */
    int cont0, ncont; /* its contacts: r->tp.blk_cont[cont0 .. cont0 + ncont) */
    int spring;       /* SDOF: its yielding spring (-1: none) */
    int sp0, nsp;     /* its yielding springs: r->tp.blk_sp[sp0 .. sp0 + nsp) */
} edr_block;

typedef struct edr_contact {
    int dof[2];  /* side 0, side 1 (-1: wall) */
    double w[2]; /* g = g0 + w[0] x[dof[0]] + w[1] x[dof[1]] */
    int blk[2];  /* their blocks (-1: wall) */
    double g0, e;
} edr_contact;

/* The modes of one cluster configuration (blocks and persistent contacts),
 * computed once and cached. */
typedef struct edr_basis {
    int nc, k, nmodes, r;       /* dofs, coordinates left, modes kept, constraints */
    int *dofs;                  /* nc global dofs */
    int *cons;                  /* r independent persistent contacts */
    edr_cplx *lam, *beta, *kap; /* nmodes: eta' = lam eta + beta f + kap */
    edr_cplx *ilam;             /* 1 / lam */
    double *wt;                 /* nmodes: 2 for a conjugate pair, 1 for a real mode */
    edr_cplx *Px, *Pv;          /* nc x nmodes, row per dof: x = q* + sum wt Re(Px eta) */
    edr_cplx *Z;                /* nmodes x 2k: eta0 = Z (y0, y0') */
    double *Y;                  /* k x nc: y0 = Y (x - q*), y0' = Y v (M-orthogonal) */
    double *qstar;              /* nc */
    edr_cplx *F;                /* r x nmodes: lambda = sum wt Re(F eta) + gam f + del */
    double *gam, *del;          /* r */
    /* a constant force fc on the dofs (the yielding springs' offsets): the
     * modes' kap + KF fc, the contacts' del + DF fc (NULL: no spring) */
    edr_cplx *KF;      /* nmodes x nc */
    double *DF;        /* r x nc */
    double T_min;      /* shortest period 2 pi / max |lam| */
    unsigned long key; /* hash of (blocks, constraints) */
    int nkey;
    int *keyv;              /* the configuration itself */
    struct edr_basis *next; /* hash chain */
} edr_basis;

typedef struct edr_cluster {
    int kind;
    int head, nblk, ndof; /* blocks linked by r->rs.blk_next */
    int pers_head, npers; /* persistent contacts linked by r->rs.pers_next */
    double t0;            /* flight origin */
    int piece;            /* its forcing piece */
    double h;             /* scan step */
    double T_min;         /* shortest period of the flight (incl. the piece) */
    double meas_t;        /* extremes measured up to here */
    double imp_t;         /* held forces integrated up to here (sampled impulses) */
    double en_t;          /* the energy balance's integrals up to here */
    /* SDOF / REST */
    int root; /* root dof */
    pd_sdof osc;
    double rho, kappa; /* y'' + 2 xi w0 y' + w0^2 y = rho f + kappa */
    double mass;       /* sum s^2 m */
    double a2;         /* damping per unit mass of the flight: 2 xi w0, or the
                          damped free mass's C / M (mass_flight) */
    int mass_flight;   /* every spring of a free tree sliding with no stiffness
                          left: y'' + a2 y' = F, pd_sdof_flow_init_mass */
    pd_sine_piece pc;  /* the piece as the flow sees it */
    pd_sdof_flow flow;
    double y0, vy0;
    double tay[EDR_TAYLOR_N + 3];  /* y^(k)(t0) / 1, k <= N + 2 (Taylor near the origin) */
    double ftay[EDR_TAYLOR_N + 1]; /* the unscaled piece's f^(k)(t0) */
    double s_taylor;               /* the series' reach in s = t - t0 */
    int bnd;                       /* the bounds below hold (flight_bounds) */
    double Y1, Y2, Y3;             /* |y'|, |y''|, |y'''| over the flight */
    double F1, F2;                 /* |f'|, |f''| of the piece */
    /* MODAL */
    edr_basis *basis;
    edr_cplx *eta0, *deta, *etad; /* nmodes each (capacity cap) */
    edr_cplx *gq, *bc1;           /* the flight's beta f_lin(t0) + kap, beta c1 */
    edr_cplx *ilp, *ilm;          /* 1 / (lam - i w), 1 / (lam + i w) */
    edr_cplx ath0;                /* A / (2i) e^{i th(t0)} */
    edr_cplx *kapc;               /* the flight's kap (the basis's, its springs' force added) */
    double *delc;                 /* r: the flight's del */
    int cap, capr;
    /* the state at tc (cache) */
    double tc;
    int cached;
    double dy, vy, ay; /* SDOF */
    double f_tc;       /* f(tc) */
    /* detachment prediction */
    int det_contact; /* the contact whose force turns negative */
    int live;
} edr_cluster;

/* Contact states. */
enum { EDR_OPEN = 0, EDR_PERSIST = 1, EDR_LOCKED = 2 };
/* Queue entries. */
enum { EDR_Q_HIT = 1, EDR_Q_SCAN = 2 };

typedef struct edr_queue {
    int n;
    int *heap;   /* slots */
    int *pos;    /* slot -> heap index, -1 */
    double *key; /* slot -> time */
} edr_queue;

/* What pd_edr_alloc fixed: the model, its forcing, blocks and contacts
 * (a reset sets the contacts' initial gaps). */
typedef struct edr_topo {
    const pd_model *md;
    pd_edr_opts o;
    int n, m, nb;
    /* forcing */
    double *b; /* n */
    pd_sine_piece *pieces;
    int npieces;
    /* blocks and contacts */
    edr_block *blk;
    int *blk_dofs, *dof_blk, *dof_loc; /* dof lists, dof -> block, dof -> local index */
    double *Cb, *Kb;                   /* dense n_b x n_b per block, at blk_off[b] */
    long *blk_off;
    int *blk_cont;        /* contacts of each block */
    int *dofc_ptr, *dofc; /* contacts of each dof */
    edr_contact *ct;
    double *minv; /* n: 1 / M_ii */
    /* yielding springs: spring j's drift d = sp_sig[j] x[sp_dof[j]] (+
     * sp_sig2[j] x[sp_dof2[j]] for a storey above the first; sp_dof2 -1
     * otherwise), the model's S column; ks and uy the model's; each block's
     * springs in blk_sp */
    int ns;
    int *sp_dof, *sp_dof2;
    double *sp_sig, *sp_sig2;
    int *blk_sp;
} edr_topo;

/* The run: clusters, the contacts' states, results, the event queue, the
 * clock, the modal cache and the observer's state. */
typedef struct edr_run {
    /* clusters */
    edr_cluster *cl;        /* nb slots */
    int *blk_cl, *blk_next; /* block -> cluster, next block in its cluster */
    int *free_cl, nfree;
    double *s, *d;   /* n: SDOF trees x = s y + d */
    double *xo, *vo; /* n: state at the flight origin of its cluster */
    int *crow;       /* n: row of a dof in its modal cluster's basis */
    int *crow_c;     /* m: row of a persistent contact in its basis */
    /* contacts */
    unsigned char *cstate; /* EDR_OPEN / PERSIST / LOCKED */
    int *pers_next;
    double *la, *lb, *lg, *ld; /* SDOF/REST force: lambda = la y + lb y' + lg f + ld */
    double *base_t, *base_g;   /* gap known exactly at base_t (0 after closing) */
    unsigned char *qkind;      /* what the queued time of a slot means */
    int *win;                  /* a prediction's next window (scan intervals) */
    double *gmeas_t;           /* contacts: gap minimum measured up to */
    double *since;             /* persistent since */
    long *burst;
    /* results */
    pd_edr_result res;
    double *xpos, *xneg, *drift, *gmin;
    long *impacts;
    double *first, *maxP, *ctime, *imp_out; /* imp_out: impulses since the last sample */
    int sample_forces; /* the held forces' integrals go into imp_out (a sampler) */
    /* queue: contacts 0..m-1, clusters m..m+nb-1, piece m+nb, output m+nb+1,
     * springs m+nb+2.. */
    edr_queue q;
    int slot_piece, slot_out;
    long next_out;
    double t_out0;
    /* the run */
    double t, t1, L;
    int piece;      /* the current piece */
    double *slot_t; /* per queue slot: time of its last event */
    int *slot_same; /* and how many it had there */
    int *slot_run;  /* events of the slot since slot_t0 (count_event's chatter) */
    double *slot_t0;
    int stopped;
    double vscale; /* largest velocity met at an event */
    /* the energy balance (opts.energy): the flights' integrals, the impacts'
     * losses; the group's kinetic energy before an event */
    double e_input, e_damping, e_impact, ke_group;
    long evals;
    /* yielding springs: phase (0 elastic, +-1 sliding toward that side), the
     * offset up (sliding: up = sig x - phase uy, sp_up its value at the
     * slide's last origin), the excursion summed up to sp_upx, onsets */
    signed char *sp_phase;
    double *sp_up, *sp_upx, *sp_exc, *sp_now;
    long *sp_onsets;
    int slot_spring0; /* the springs' queue slots: slot_spring0 + j */
    /* modal cache */
    edr_basis **bhash;
    int nbhash;
    long nbasis;
    /* observer state */
    pd_state st;
} edr_run;

/* One event's scratch: its group (clusters, contacts, dofs), the LCPs'
 * data and the work arrays. */
typedef struct edr_event {
    /* the group of an event */
    int epoch, epochD;
    int *g_cl, ng; /* its clusters */
    int *cl_mark;
    int *g_ct, ngc; /* its closed contacts */
    int *ct_mark, *ct_mark2, *ct_markD, *ct_markP, epochP;
    int *g_dof, ngd;               /* its dofs */
    double *gx, *gv, *gacc, *gtmp; /* n: state of the group's dofs (global index) */
    double *Uminus, *Uplus, *P;    /* per closed contact (g_ct order) */
    double *lam, *wlcp, *qlcp, *wtmp;
    int *lcp_idx, *jpos, *excluded;
    unsigned char *held;
    unsigned char *tie; /* at zero rate, force and gap acceleration (decide_persistence) */
    double *held_tail;
    int *pos_in;
    unsigned char *guess;      /* the LCP's warm start */
    double *lcp_scale, *lcp_q; /* m: scaled_lcp's S and S q */
    double *Dd;                /* dense Delassus */
    double *Dlu, *rtmp;        /* the clusters' refinement: D_AA's LU, 4 dm */
    int *lu_perm;              /* 2 dm: its rows, the pushing contacts */
    double *cG;                /* per cluster slot: a refined stage's impulse on it */
    double *Dval;              /* compressed Delassus */
    int *Dcol, *Drow;
    long Dcap;
    pd_lcp_solver *solver;  /* dof-level LCPs */
    pd_lcp_solver *dsolver; /* the clusters' small dense LCPs */
    int *epos;              /* an event's contacts between clusters (g_ct indices) */
    double *qtmp, *ztmp;    /* the clusters' LCP data */
    double *ev_vminus, *ev_vplus, *ev_x;
    /* scratch */
    int *stack, *pe, *pdof;   /* trees: scratch; per dof its parent edge and dof */
    int *bfs_next;            /* per dof: the next in its tree's breadth-first order */
    double *ceta, *cmu, *cvy; /* per cluster slot: its coordinate's rate, mass, rate before */
    double *ext;              /* per dof: impulse from the contacts between clusters */
    long *nimp;               /* per closed contact of an event: its impacts */
    int instant_acc;          /* the event's stages met an accumulation at one instant */
    int law_multi;            /* the event's first LCP could take several closed contacts */
    int *keybuf;              /* configuration keys */
    int *uf, *gblk, *newcl, *plist;
    int *loc;              /* n: local index */
    double *wk;            /* 8 n */
    struct meas_ctx *mctx; /* measurement functions (2 n) */
    edr_scan *mscan;
    edr_pt *mprev;
} edr_event;

struct pd_edr {
    edr_topo tp;  /* fixed at the allocation */
    edr_run rs;   /* the run's state */
    edr_event ev; /* one event's scratch */
};

/* ---- clusters (event_row_cluster.c) ------------------------------------------- */

/* f(t) of piece j. */
double edr_force(const pd_edr *r, int j, double t);
/* The piece containing t (right limit at a start). */
int edr_piece_at(const pd_edr *r, double t);
double edr_piece_end(const pd_edr *r, int j);

/* Make the blocks linked from head (nblk of them) one cluster held by the
 * persistent contacts linked from pers_head, starting at t from the
 * states xo, vo of its dofs (projected onto its constraints).  Contacts of
 * the cluster that close a cycle become LOCKED.  PD_ENOMEM / PD_EINVAL /
 * PD_ESINGULAR with a message. */
int edr_cluster_start(pd_edr *r, int c, double t, pd_err *err);
/* State of the cluster at t (cached). */
void edr_cluster_eval(pd_edr *r, int c, double t);
/* x(t) - xo, v, a of one dof of cluster c (evaluated at t). */
void edr_dof_at(pd_edr *r, int c, int dof, double t, double *dx, double *v, double *a);
/* The jerk x^(3) of one dof (0 for a REST tree, held still). */
double edr_dof_jerk(pd_edr *r, int c, int dof, double t);
/* Spring j's drift from the dofs' values y (positions, rates or
 * accelerations: d, d', d''), y indexed by global dof. */
double edr_spring_drift(const pd_edr *r, int j, const double *y);
/* Spring j's drift, its rate and acceleration on cluster c's flight at t. */
void edr_spring_at(pd_edr *r, int c, int j, double t, double *d, double *dd, double *ddd);
/* Spring j's plastic offset at drift d, in its phase. */
double edr_spring_up(const pd_edr *r, int j, double d);
/* Spring j into phase (0 elastic, +-1 sliding) at drift d: the offset, the
 * excursion and the onsets kept. */
void edr_spring_set(pd_edr *r, int j, double d, int phase);
/* lambda of persistent contact a of cluster c at t. */
double edr_force_at(pd_edr *r, int c, int a, double t);
/* A block's restoring force k x - sig ks up(x) as k_eff x + r0 (its spring's
 * phase; k, 0 without a spring). */
void edr_block_stiffness(const pd_edr *r, int b, double *keff, double *r0);
/* Release a cluster's modal storage and the cache. */
void edr_basis_cache_free(pd_edr *r);
void edr_cluster_free(edr_cluster *c);

#endif
