/* mj.h — (engine-private) the Moreau–Jean object, shared by its fixed-step
 * driver (mj.c) and its adaptive one (mj_adapt.c).
 *
 * One step of either driver is the same arithmetic (SPEC §2): the general
 * kernel's mj_general_step, the scalar kernel's mj1_step (pd_mj1.h).  A fixed
 * run steps with h = opts.h in place on mj->st; an adaptive run steps on
 * the ladder h_k = h0 2^-k, each level's iteration matrix factored once,
 * from one snapshot of the state into another (docs/scheme.md, "Moreau–Jean
 * to a tolerance"). */
#ifndef PD_MJ_H
#define PD_MJ_H

#include "pd_mj1.h"
#include "pd_engine.h"
#include "pd_factor.h"

/* One rung of the ladder: its step, and What(h) as the kernel keeps it. */
typedef struct mj_level {
    double h;
    mj1_coef s1;       /* scalar kernel */
    pd_factor *factor; /* general kernel: formed at the level's first use */
} mj_level;

typedef struct mj_adapt mj_adapt;   /* the adaptive driver's own (mj_adapt.c) */
typedef struct mj_yield mj_yield;   /* the yielding springs' (mj_yield.c) */
typedef struct mj_flight mj_flight; /* its exact flights (mj_flight.c) */

/* W by columns and by rows (the adaptive driver's): the dofs each contact
 * acts on, and the contacts acting on each dof. */
typedef struct mj_incidence {
    int *ptr, *dof;  /* contact a: dof[ptr[a] .. ptr[a+1]) */
    double *w;       /* W_ia of each (dof, contact) pair, as dof */
    int *dptr, *con; /* dof i: con[dptr[i] .. dptr[i+1]) */
    double *wr;      /* W_ia of each pair, as con */
    int *pair;       /* 2 m, when no contact acts on more than 2 dofs (rows): each
                        contact's dofs, a missing one dof 0 of weight 0 (else NULL) */
    double *pw;      /* 2 m: their weights */
} mj_incidence;

/* The stored entries of column j of A, one per call into (*i, *v), *p from
 * -1 on; 0 after the last (zero matrices store none; dense ones all rows):
 * the setup's walks over a model's structure, linear in its entries. */
static inline int mj_col_next(const pd_matrix *A, int j, int *p, int *i, double *v)
{
    if (A->kind == PD_MATRIX_CSC) {
        *p = *p < 0 ? A->colptr[j] : *p + 1; /* the first entry, then the next */
        if (*p >= A->colptr[j + 1])
            return 0;
        *i = A->rowind[*p];
        *v = A->values[*p];
        return 1;
    }
    /* a zero matrix stores none; a dense one every row */
    if (A->kind != PD_MATRIX_DENSE || ++*p >= A->rows)
        return 0;
    *i = *p;
    *v = A->values[*p + (size_t)j * (size_t)A->rows];
    return 1;
}

/* W_a^T x. */
static inline double mj_inc_dot(const mj_incidence *in, int a, const double *x)
{
    if (in->pair) { /* rows: two terms, no loop */
        const int *d = in->pair + 2 * a;
        const double *w = in->pw + 2 * a;
        return w[0] * x[d[0]] + w[1] * x[d[1]];
    }
    double sum = 0.0;
    for (int j = in->ptr[a]; j < in->ptr[a + 1]; j++)
        sum += in->w[j] * x[in->dof[j]]; /* over the dofs contact a acts on */
    return sum;
}

struct pd_mj {
    const pd_model *model;
    pd_mj_opts opts;
    int scalar;               /* 1: scalar kernel */
    double t0;                /* time of the last reset */
    int next_break;           /* index of the first model breakpoint after t */
    pd_factor *factor;        /* What, What^-1 W and the Delassus matrix (fixed steps) */
    pd_lcp_solver *lcp;       /* the contact LCP solver, sized for lcp_nmax contacts */
    int lcp_nmax;             /* most active contacts one LCP may have */
    unsigned char *guess;     /* m: the warm start of the active set's LCP: 1 pushed in the
                             previous step, 0 active without pushing, 2 newly active */
    int sparse;               /* 1: Delassus blocks in compressed columns */
    int stop;                 /* the LCP observer asked to stop */
    double *F0, *F1;          /* n: force at t_k and t_k+1 */
    double *work_n;           /* n: right-hand side, then velocity increment */
    double *qtheta;           /* n: q_k + h theta v_k */
    double *U0;               /* m: W^T v_k */
    double *D_active;         /* Delassus block: lcp_nmax^2 (dense) or delassus_nnz (sparse) */
    int *D_colptr, *D_rowind; /* sparse: its compressed columns */
    double *b_active;         /* m: LCP vector of the active set */
    double *P_active;         /* m: impulses of the active set */
    double *w_active;         /* m: post-impact relative velocities of the active set */
    int *idx_active;          /* m: indices of the active contacts */
    /* the refinement of a dense active LCP (dense Delassus only), for up to
     * ref_nmax pushing contacts: */
    int ref_nmax;         /* min(m, MJ_REFINE_NMAX) */
    double *ref_R;        /* ref_nmax^2: R of W_A = Q R; owns ref_C, ref_SC, ref_z */
    double *ref_C;        /* n ref_nmax: Q */
    double *ref_SC;       /* n ref_nmax: What^-1 Q */
    double *ref_z;        /* 2 ref_nmax: a correction's z and R^-1 z */
    double *ref_res;      /* 2 m: residual, trial residual; owns ref_y */
    double *ref_y;        /* 2 n: What^-1 W_I P, its trial */
    int *ref_perm;        /* m + ref_nmax: the pushing contacts, the pivot order */
    int refined;          /* 1: the last LCP was refined (v = vfree + ref_y) */
    mj1_coef s1;          /* scalar kernel constants (no division in a step) */
    pd_state st;          /* the state the caller reads (pd_mj_state) */
    pd_state st_own;      /* the arrays mj->st was allocated with (the adaptive driver
                             points mj->st at its snapshots) */
    mj_adapt *ad;         /* NULL: fixed steps */
    mj_yield *yl;         /* NULL: no yielding spring */
    mj_flight *fl;        /* adaptive with exact flights (linear blocks under piecewise
                             forcing); NULL: theta flights */
    mj_incidence inc;     /* the adaptive driver's view of W */
    const double *minv;   /* the adaptive driver's: n, 1 / M_ii (its projections' M^-1) */
    const double *D0;     /* the adaptive driver's: m, sum_i W_ia^2 / M_ii */
    const double *u_rest; /* NULL, or m: closing speeds |U_k| at or below which a contact
                             takes no restitution (the adaptive driver's: rebounds lower
                             than its tolerance are plastic; an opening contact takes
                             none either) */
};

/* One step of the general kernel with the factor f of What(h), from `in` at
 * t to `out` at t1 = t + h (out may be in), with the forces F0 = F(t+) and
 * F1 = F(t1-): q, v, P, g, active, nactive, the LCP's figures, t and step
 * of out.  Fails naming t1 when the LCP is not solved or the state is not
 * finite. */
int mj_general_step(pd_mj *mj, const pd_factor *f, double h, double t1, const double *F0,
                    const double *F1, const pd_state *in, pd_state *out, pd_err *err);

/* The LCP of the active set mj->idx_active (nI contacts): its right-hand
 * side W_I^T vfree + e U_k into mj->b_active (U_k in mj->U0; with
 * mj->u_rest, no restitution for a contact opening or closing slower than
 * it), and its solution with the Delassus
 * block in mj->D_active (dense, or compressed columns when mj->sparse) into
 * mj->P_active and out->P (t1 names the step's end in messages). */
void mj_active_rhs(pd_mj *mj, int nI, const double *vfree);
int mj_incidence_build(pd_mj *mj);
/* The contacts' LCP of the active set from out->v = vfree, and v+ into
 * out->v; reuse_D: the Delassus block of the last call (the same active
 * set and factor) is kept. */
int mj_contacts_apply(pd_mj *mj, const pd_factor *f, int nI, int reuse_D, double t1, pd_state *out,
                      pd_err *err);

/* Yielding springs (mj_yield.c): the object, the offsets back to 0, their
 * force x += s S ks up, and the step's LCP with them from out->v = vfree
 * (out->q = q + h (1 - theta) v): v+ into out->v, the offsets moved. */
int mj_yield_alloc(pd_mj *mj, pd_err *err);
void mj_yield_free(pd_mj *mj);
void mj_yield_reset(pd_mj *mj);
/* Since the reset: the sliding set's LCP tries, the steps Gauss-Seidel took
 * (both 0 without yielding springs). */
void mj_yield_stats(const pd_mj *mj, long *set_tries, long *gs_steps);
void mj_yield_force(const pd_mj *mj, double s, double *x);
int mj_yield_step(pd_mj *mj, const pd_factor *f, double h, int nI, double t1, pd_state *out,
                  pd_err *err);
int mj_impact_active(pd_mj *mj, int nI, double t1, pd_state *out, pd_err *err);

/* The adaptive driver: its workspaces for mj (opts.rtol > 0), their
 * release, the state at rest at t0 (q0, v0 as pd_mj_reset's), and the run
 * to t_end (mj_adapt.c). */
int mj_adapt_alloc(pd_mj *mj, pd_err *err);
void mj_adapt_free(pd_mj *mj);
int mj_adapt_reset(pd_mj *mj, double t0, const double *q0, const double *v0, pd_err *err);
int mj_adapt_run_until(pd_mj *mj, double t_end, pd_observer observer, void *ctx, pd_err *err);
void mj_adapt_stats(const pd_mj *mj, pd_mj_stats *s);

/* Exact flights (mj_flight.c): the tables of every block for the ladder
 * h_k = h0 2^-k, k = 0..L + 1, under the forcing F; their release; the
 * forcing state z (4) of piece p at t; the step of level k from (in, zin)
 * to (out, zout) ending at t1; a span: the free flights of levels lev[0..
 * nlev) in turn, 1 when no contact shut at its end (else 0, out no step;
 * < 0 on failure); the highest frequency of the dof's block (for the
 * grazing test) and of the forcing. */
int mj_flight_alloc(pd_mj *mj, const pd_piecewise_force *F, double h0, int L, pd_err *err);
void mj_flight_free(pd_mj *mj);
void mj_flight_z(const pd_mj *mj, int p, double t, double *z);
int mj_flight_step(pd_mj *mj, int k, double t1, const pd_state *in, const double *zin,
                   pd_state *out, double *zout, pd_err *err);
int mj_flight_span(pd_mj *mj, const int *lev, int nlev, double t1, const pd_state *in,
                   const double *zin, pd_state *out, double *zout, pd_err *err);
double mj_flight_wmax(const pd_mj *mj, int dof);
double mj_flight_forcing_w(const pd_mj *mj);
/* The Delassus block of the active set mj->idx_active (nI contacts) into
 * mj->D_active: W^T Phi_vv(h_k / 2) M^-1 W (minv NULL) or W^T M^-1 W with
 * M^-1 = diag(minv). */
void mj_flight_delassus(pd_mj *mj, int k, const double *minv, int nI);
/* The accelerations of the free motion at st (the forcing's state z). */
void mj_flight_acc(const pd_mj *mj, const pd_state *st, const double *z, double *acc);

#endif
