/* penalty_newmark.c — the penalty baseline the practitioners' way: a fixed-step
 * implicit Newmark scheme (average acceleration, beta = 1/4, gamma = 1/2)
 * with Newton iterations on the contact elements, as OpenSees users run
 * zeroLength impact elements (docs/methods.md, "Penalty baseline").
 *
 *   M a1 + C v1 + K q1 = F(t1-) + W lambda(q1, v1)
 *   q1 = q0 + h v0 + h^2/4 (a0 + a1),   v1 = v0 + h/2 (a0 + a1)
 *
 * Times h^2/4, with v1 = (2/h)(q1 - q0) - v0, the residual in q1 is
 *   r(q1) = b + h^2/4 (F1 + W lambda) - What q1,
 *   What = M + h/2 C + h^2/4 K,  b = M (q0 + h v0 + h^2/4 a0) + C (h/2 q0 + h^2/4 v0),
 * What being Moreau-Jean's iteration matrix at theta = 1/2: factored once
 * (pd_factor: scalar, dense or CHOLMOD).  The elements are penalty.c's
 * (engine/penalty_law.h), engaged where the penetration d = -g is > 0.
 * Newton's matrix adds h^2/4 W_A diag(kt) W_A^T over the engaged set A,
 * kt = dlambda/dd + (2/h) dlambda/dd' (>= 0), solved by Woodbury's identity
 * on What's factor: y = What^-1 r, (I + G D_AA) mu = G W_A^T y, G = h^2/4 kt,
 * D_AA = W_A^T What^-1 W_A, Delta = y - What^-1 W_A mu.  A Kelvin-Voigt
 * element is linear in (d, d'): a step ends when the engaged set stops
 * changing; Hertz-damp iterates until Delta is below tol.  At a force
 * breakpoint landing on a step's end, a1 takes the right limit of F.
 *
 * Yielding springs (pd_model.S, ks, uy) add S diag(ks) up to the force,
 * up by return mapping at each iterate: z = S_j^T q - up_j(t0) beyond
 * +-uy_j slides (up_j = S_j^T q -+ uy_j, tangent ks_j removed), else
 * elastic.  Newton's matrix takes -h^2/4 ks_j S_j S_j^T of each sliding
 * spring (Woodbury over U = [W_A S_Y]); the system is piecewise linear, so
 * a step ends when neither set moves.  Where they cycle (a switch inside the
 * step), Newton has failed: the failure is counted and the step redone with
 * the springs' initial stiffness (the practitioners' fallback, converging
 * linearly), an error only if that fails too. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_mj1.h"
#include "pd_alloc.h"
#include "pd_core.h"
#include "pd_engine.h"
#include "pd_factor.h"
#include "penalty_law.h"
#include "pd_null.h"

#define NM_MAX_ACTIVE 1024  /* elements engaged at once (a dense LU of that size) */
#define NM_MAX_NEWTON 50    /* Newton iterations of one step */
#define NM_TOL 1e-12        /* Newton: |Delta| <= NM_TOL max(|q|, the gaps' scale) */
#define NM_FREEZE 6         /* Newton iterations after which the engaged set is kept */
#define NM_MAX_INITIAL 2000 /* iterations of a failed step redone at initial stiffness */

/* One run: the model, the factors, the state and its workspaces. */
typedef struct nm_run {
    const pd_model *md;
    pd_penalty_opts o;
    int n, m;
    double h, qscale;
    pd_factor *fac;  /* What at theta = 1/2 */
    pd_factor *mass; /* M (the accelerations at t0 and at breakpoints) */
    double *q0, *v0, *a0, *q, *v, *b, *r, *y, *F, *F2, *tmp; /* n */
    double *lam, *kt, *cd;                                   /* m */
    double *mu, *s;   /* m + ns (at most NM_MAX_ACTIVE): Woodbury's unknowns and weights */
    double *col;      /* n: What^-1 S_j */
    int ns, cap;      /* yielding springs; Woodbury's columns at most */
    double *up0, *up; /* ns: plastic offsets at the step's start, at the iterate */
    unsigned char *slides, *slides_prev; /* ns: sliding at the iterate, at the last one */
    int *yidx;                           /* ns: the sliding springs in Newton's matrix */
    int initial; /* this step's iterations keep the springs' initial stiffness */
    unsigned char *eng, *eng_prev, *eng_step; /* m: engaged now, last iterate, at t0 */
    int frozen; /* this step's engaged set no longer follows d (see step) */
    double t1;  /* the step's end (messages) */
    int *idx;   /* m */
    double *D;  /* NM_MAX_ACTIVE^2 */
    int *perm;  /* NM_MAX_ACTIVE */
    double vfloor, vseen;
    pd_state st;
    pd_penalty_result res;
    int stopped;
} nm_run;

static void nm_free(nm_run *w)
{
    pd_factor_free(w->fac);
    pd_factor_free(w->mass);
    double *dbl[] = {w->q0, w->v0,   w->a0,     w->q,   w->v,   w->b,  w->r,  w->y,
                     w->F,  w->F2,   w->tmp,    w->lam, w->kt,  w->cd, w->mu, w->s,
                     w->D,  w->st.g, w->st.acc, w->col, w->up0, w->up};
    for (size_t k = 0; k < sizeof dbl / sizeof dbl[0]; k++)
        free(dbl[k]);
    free(w->eng);
    free(w->eng_prev);
    free(w->eng_step);
    free(w->idx);
    free(w->yidx);
    free(w->slides);
    free(w->slides_prev);
    free(w->perm);
    free(w->st.active);
}

/* Every array, sized once for (n, m). */
static int nm_alloc(nm_run *w)
{
    size_t n = (size_t)w->n;
    int m = w->m, ns = w->ns, na = m + ns < NM_MAX_ACTIVE ? m + ns : NM_MAX_ACTIVE;
    double **dn[] = {&w->q0, &w->v0, &w->a0, &w->q,   &w->v,      &w->b,  &w->r,
                     &w->y,  &w->F,  &w->F2, &w->tmp, &w->st.acc, &w->col};
    double **dm[] = {&w->lam, &w->kt, &w->cd, &w->st.g};
    double **dc[] = {&w->mu, &w->s};
    double **ds[] = {&w->up0, &w->up};
    int ok = 1;
    for (size_t k = 0; k < sizeof dn / sizeof dn[0]; k++)
        ok &= (*dn[k] = calloc(n, sizeof(double))) != NULL;
    for (size_t k = 0; k < sizeof dm / sizeof dm[0]; k++)
        ok &= (*dm[k] = pd_calloc(m, sizeof(double))) != NULL;
    for (size_t k = 0; k < sizeof dc / sizeof dc[0]; k++)
        ok &= (*dc[k] = pd_calloc(na, sizeof(double))) != NULL;
    for (size_t k = 0; k < sizeof ds / sizeof ds[0]; k++)
        ok &= (*ds[k] = pd_calloc(ns, sizeof(double))) != NULL;
    ok &= (w->yidx = pd_calloc(ns, sizeof(int))) != NULL;
    ok &= (w->slides = pd_calloc(ns, 1)) != NULL;
    ok &= (w->slides_prev = pd_calloc(ns, 1)) != NULL;
    w->cap = na;
    ok &= (w->D = pd_calloc((long)na * na, sizeof(double))) != NULL;
    ok &= (w->perm = pd_calloc(na, sizeof(int))) != NULL;
    ok &= (w->idx = pd_calloc(m, sizeof(int))) != NULL;
    ok &= (w->eng = pd_calloc(m, 1)) != NULL;
    ok &= (w->eng_prev = pd_calloc(m, 1)) != NULL;
    ok &= (w->eng_step = pd_calloc(m, 1)) != NULL;
    ok &= (w->st.active = pd_calloc(m, 1)) != NULL;
    return ok ? PD_OK : PD_ENOMEM;
}

/* F(t) from the given side (zero without a force). */
static void force_at(const nm_run *w, double t, int side, double *F)
{
    if (w->md->force)
        w->md->force(t, side, F, w->md->force_ctx);
    else
        memset(F, 0, (size_t)w->n * sizeof(double));
}

/* The elements at (q, v): engaged set, forces lambda and tangents kt.  An
 * element engaging now takes its Hertz-damp constant from the approach
 * speed at the step's start. */
static void elements(nm_run *w, const double *q, const double *v, const double *vstart)
{
    const pd_model *md = w->md;
    for (int a = 0; a < w->m; a++) {
        double d = -(md->g0[a] + pd_matrix_col_dot(&md->W, a, q)); /* d = -g_a */
        double dd = -pd_matrix_col_dot(&md->W, a, v);              /* d' = -U_a */
        /* engaged where d > 0, unless the set is frozen for the step */
        if (!w->frozen)
            w->eng[a] = d > 0.0;
        if (!w->eng[a]) {
            w->lam[a] = w->kt[a] = 0.0;
            continue;
        }
        /* engaging in this step: Hertz-damp's constant from the approach speed at its start */
        if (!w->eng_step[a] && w->o.law == PD_PENALTY_HERTZDAMP) {
            double vimp = -pd_matrix_col_dot(&md->W, a, vstart);
            w->cd[a] = pd_hertz_damping(w->o.kc, md->e[a], vimp, w->vfloor, w->vseen);
        }
        double kd, cdd;
        w->lam[a] = pd_penalty_force(w->o.law, w->o.kc, w->cd[a], d, dd);
        pd_penalty_slopes(w->o.law, w->o.kc, w->cd[a], d, dd, &kd, &cdd);
        /* kt = dlambda/dd + (2/h) dlambda/dd', as v1 = (2/h)(q1 - q0) - v0 */
        double k = kd + (2.0 / w->h) * cdd;
        w->kt[a] = k > 0.0 ? k : 0.0; /* a modified Newton where the law softens */
    }
}

/* out = What x = M x + h/2 C x + h^2/4 K x. */
static void what_times(const nm_run *w, const double *x, double *out)
{
    const pd_model *md = w->md;
    pd_matrix_gemv(&md->M, 1.0, x, 0.0, out);
    pd_matrix_gemv(&md->C, 0.5 * w->h, x, 1.0, out);
    pd_matrix_gemv(&md->K, 0.25 * w->h * w->h, x, 1.0, out);
}

/* The springs at q by return mapping from the step's start: the offsets
 * up and which slide. */
static void springs(nm_run *w, const double *q)
{
    const pd_model *md = w->md;
    for (int j = 0; j < w->ns; j++) {
        double d = pd_matrix_col_dot(&md->S, j, q), z = d - w->up0[j], uy = md->uy[j];
        w->slides[j] = fabs(z) > uy;
        w->up[j] = z > uy ? d - uy : z < -uy ? d + uy : w->up0[j];
    }
}

/* D from ld nI to ld N >= nI in place (back to front: no entry is
 * overwritten before it moves). */
static void widen(double *D, int nI, int N)
{
    for (int c = nI - 1; c >= 0; c--)
        for (int r = nI - 1; r >= 0; r--)
            D[(size_t)c * N + r] = D[(size_t)c * nI + r];
}

/* The columns of D = U^T What^-1 U of the sliding springs (U = [W_A S_Y],
 * na contacts first), one solve each. */
static void delassus_springs(nm_run *w, int na, int ny)
{
    const pd_model *md = w->md;
    int N = na + ny;
    for (int k = 0; k < ny; k++) {
        memset(w->col, 0, (size_t)w->n * sizeof(double));
        pd_matrix_col_axpy(&md->S, w->yidx[k], 1.0, w->col);
        pd_factor_solve(w->fac, w->col); /* What^-1 S_j */
        for (int i = 0; i < na; i++) {
            double v = pd_matrix_col_dot(&md->W, w->idx[i], w->col);
            w->D[(size_t)(na + k) * N + i] = w->D[(size_t)i * N + na + k] = v;
        }
        for (int k2 = 0; k2 < ny; k2++)
            w->D[(size_t)(na + k) * N + na + k2] = pd_matrix_col_dot(&md->S, w->yidx[k2], w->col);
    }
}

/* Solve (What + h^2/4 (W_A diag(kt) W_A^T - S_Y diag(ks) S_Y^T)) Delta = r
 * into w->y by Woodbury on What's factor: U = [W_A S_Y], G = h^2/4 [kt;
 * -ks], y = What^-1 r, (I + G D) mu = G U^T y, D = U^T What^-1 U, Delta =
 * y - What^-1 U mu.  The springs' part is left out at initial stiffness. */
static int newton_solve(nm_run *w, pd_err *err)
{
    const pd_model *md = w->md;
    double g4 = 0.25 * w->h * w->h;
    int na = 0, ny = 0;
    memcpy(w->y, w->r, (size_t)w->n * sizeof(double));
    pd_factor_solve(w->fac, w->y); /* y = What^-1 r */
    /* A: the engaged elements with kt > 0; Y: the sliding springs */
    for (int a = 0; a < w->m; a++)
        if (w->eng[a] && w->kt[a] > 0.0)
            w->idx[na++] = a;
    for (int j = 0; j < w->ns && !w->initial; j++)
        if (w->slides[j])
            w->yidx[ny++] = j;
    int N = na + ny;
    if (N > w->cap)
        return pd_err_set(err, PD_EBUDGET,
                          "newmark: more than %d contact elements and sliding springs at once",
                          w->cap);
    if (N == 0) /* What alone */
        return PD_OK;
    /* D, made I + G D in place; mu = G U^T y */
    if (na > 0) {
        pd_factor_delassus_dense(w->fac, w->idx, na, w->D);
        widen(w->D, na, N);
    }
    delassus_springs(w, na, ny);
    for (int j = 0; j < N; j++) {
        double G = j < na ? g4 * w->kt[w->idx[j]] : -g4 * md->ks[w->yidx[j - na]];
        w->mu[j] = G * (j < na ? pd_matrix_col_dot(&md->W, w->idx[j], w->y)
                               : pd_matrix_col_dot(&md->S, w->yidx[j - na], w->y));
        for (int i = 0; i < N; i++) /* row j of I + G D: D is symmetric */
            w->D[(size_t)i * N + j] = (i == j) + G * w->D[(size_t)i * N + j];
    }
    if (pd_dense_lu(N, w->D, N, w->perm, 1e-14))
        return pd_err_set(err, PD_ENUMERICAL, "newmark: the contact update is singular");
    pd_dense_lu_solve(N, w->D, N, w->perm, w->mu);
    for (int j = 0; j < N; j++)
        w->mu[j] = -w->mu[j];
    /* Delta = y - What^-1 U mu: the contacts' part, then the springs' by one solve */
    pd_factor_add_impulse(w->fac, w->idx, na, w->mu, w->y);
    if (ny > 0) {
        memset(w->col, 0, (size_t)w->n * sizeof(double));
        for (int k = 0; k < ny; k++)
            pd_matrix_col_axpy(&md->S, w->yidx[k], w->mu[na + k], w->col);
        pd_factor_solve(w->fac, w->col);
        for (int i = 0; i < w->n; i++)
            w->y[i] += w->col[i];
    }
    return PD_OK;
}

/* The state after step k (or at t0), to the observers. */
static void report(nm_run *w, long k, double t, pd_observer fn, void *ctx)
{
    if (!fn || w->stopped)
        return;
    w->st.step = k;
    w->st.t = t;
    w->st.q = w->q0;
    w->st.v = w->v0;
    w->st.P = w->lam; /* the elements' forces */
    w->st.nactive = 0;
    for (int a = 0; a < w->m; a++) {
        w->st.g[a] = w->md->g0[a] + pd_matrix_col_dot(&w->md->W, a, w->q0);
        w->st.active[a] = w->eng_step[a];
        w->st.nactive += w->eng_step[a];
    }
    memcpy(w->st.acc, w->a0, (size_t)w->n * sizeof(double));
    w->st.has_acc = 1;
    w->st.up = w->ns > 0 ? w->up0 : NULL;
    w->st.lcp_pivots = 0;
    w->st.lcp_solver = NULL;
    if (fn(&w->st, ctx) > 0)
        w->stopped = 1;
}

/* out += s S diag(ks) up: the yielding springs' offsets' force. */
static void spring_force(const nm_run *w, const double *up, double s, double *out)
{
    for (int j = 0; j < w->ns; j++)
        pd_matrix_col_axpy(&w->md->S, j, s * w->md->ks[j] * up[j], out);
}

/* a = M^-1 (F - C v - K q + S ks up + W lambda) at (q0, v0) with F in w->F. */
static void accelerations(nm_run *w)
{
    const pd_model *md = w->md;
    memcpy(w->a0, w->F, (size_t)w->n * sizeof(double));
    pd_matrix_gemv(&md->C, -1.0, w->v0, 1.0, w->a0);
    pd_matrix_gemv(&md->K, -1.0, w->q0, 1.0, w->a0);
    spring_force(w, w->up0, 1.0, w->a0);
    if (w->m > 0)
        pd_matrix_gemv(&md->W, 1.0, w->lam, 1.0, w->a0);
    pd_factor_solve(w->mass, w->a0);
}

/* Newton's iterations from the predictor q0 + h v0 + h^2/2 a0, at most
 * maxit: 1 when they converged (*rc an error otherwise). */
static int newton(nm_run *w, int maxit, int *rc, pd_err *err)
{
    const pd_model *md = w->md;
    int n = w->n;
    double h = w->h, g4 = 0.25 * h * h;
    for (int i = 0; i < n; i++) /* predictor: a1 = a0 */
        w->q[i] = w->q0[i] + h * w->v0[i] + 2.0 * g4 * w->a0[i];
    int it, done = 0;
    /* the engaged set follows d until NM_FREEZE iterations */
    w->frozen = 0;
    for (int i = 0; i < n; i++)
        w->v[i] = (2.0 / h) * (w->q[i] - w->q0[i]) - w->v0[i];
    elements(w, w->q, w->v, w->v0); /* then after each update, below */
    springs(w, w->q);
    for (it = 0; it < maxit && !done; it++) {
        /* a Kelvin-Voigt element whose force jumps at d = 0 (c d' != 0) can
         * make the engaged set cycle: no set is consistent within the step.
         * Then the set of the last iterate is kept for the step, its
         * elements acting on both sides of d = 0 (as penalty.c's, frozen to
         * their mode within a step); the next step's set follows d again. */
        w->frozen = it >= NM_FREEZE;
        /* r = b + h^2/4 (F1 + S ks up + W lambda) - What q */
        what_times(w, w->q, w->r);
        for (int i = 0; i < n; i++)
            w->r[i] = w->b[i] + g4 * w->F[i] - w->r[i];
        spring_force(w, w->up, g4, w->r);
        if (w->m > 0)
            pd_matrix_gemv(&md->W, g4, w->lam, 1.0, w->r);
        w->res.rhs++;
        w->res.newton_iterations++;
        if ((*rc = newton_solve(w, err)))
            return 0;
        /* q += Delta, |Delta| against the state's scale */
        double dmax = 0.0, qmax = w->qscale;
        for (int i = 0; i < n; i++) {
            w->q[i] += w->y[i];
            dmax = fmax(dmax, fabs(w->y[i]));
            qmax = fmax(qmax, fabs(w->q[i]));
        }
        if (!isfinite(dmax)) {
            *rc = pd_err_set(err, PD_ENONFINITE, "newmark: the state is not finite at t = %.9g s",
                             w->t1 * w->o.time_unit);
            return 0;
        }
        memcpy(w->eng_prev, w->eng, (size_t)w->m);
        memcpy(w->slides_prev, w->slides, (size_t)w->ns);
        for (int i = 0; i < n; i++)
            w->v[i] = (2.0 / h) * (w->q[i] - w->q0[i]) - w->v0[i];
        elements(w, w->q, w->v, w->v0);
        springs(w, w->q);
        int same = w->m == 0 || !memcmp(w->eng_prev, w->eng, (size_t)w->m);
        int same_springs = w->ns == 0 || !memcmp(w->slides_prev, w->slides, (size_t)w->ns);
        /* Kelvin-Voigt (and free flight) is linear on a fixed engaged set,
         * and so are the springs on a fixed sliding set (unless at initial
         * stiffness); Hertz-damp's force is continuous at d = 0: its set
         * may still move */
        done = same_springs &&
               (w->o.law == PD_PENALTY_KELVIN && !w->initial ? same : dmax <= NM_TOL * qmax);
    }
    return done;
}

/* One step from (q0, v0, a0) to t1 = t0 + h: Newton on q1 (a failure
 * counted and the step redone at the springs' initial stiffness), then the
 * state moves to the step's end. */
static int step(nm_run *w, double t1, int at_break, pd_err *err)
{
    const pd_model *md = w->md;
    int n = w->n, rc = PD_OK;
    double h = w->h, g4 = 0.25 * h * h;
    w->t1 = t1;
    /* b = M (q0 + h v0 + h^2/4 a0) + C (h/2 q0 + h^2/4 v0) */
    for (int i = 0; i < n; i++)
        w->tmp[i] = w->q0[i] + h * w->v0[i] + g4 * w->a0[i];
    pd_matrix_gemv(&md->M, 1.0, w->tmp, 0.0, w->b);
    for (int i = 0; i < n; i++)
        w->tmp[i] = 0.5 * h * w->q0[i] + g4 * w->v0[i];
    pd_matrix_gemv(&md->C, 1.0, w->tmp, 1.0, w->b);
    force_at(w, t1, -1, w->F); /* F1 = F(t1-) */
    w->initial = 0;
    int done = newton(w, w->o.max_newton > 0 ? w->o.max_newton : NM_MAX_NEWTON, &rc, err);
    if (!done && !rc && w->ns > 0) { /* Newton failed: counted, redone at initial stiffness */
        w->res.newton_failures++;
        w->initial = 1;
        done = newton(w, NM_MAX_INITIAL, &rc, err);
    }
    if (rc)
        return rc;
    if (!done)
        return pd_err_set(err, PD_ENUMERICAL,
                          "newmark: Newton did not converge in %d iterations at t = %.9g s "
                          "(elements switching within the step: a smaller dt)",
                          w->initial            ? NM_MAX_INITIAL
                          : w->o.max_newton > 0 ? w->o.max_newton
                                                : NM_MAX_NEWTON,
                          t1 * w->o.time_unit);
    memcpy(w->up0, w->up, (size_t)w->ns * sizeof(double)); /* the offsets committed */
    /* the step's end: a1 = 4/h^2 (q1 - q0) - 4/h v0 - a0, v1 */
    for (int i = 0; i < n; i++) {
        double a1 = (4.0 / (h * h)) * (w->q[i] - w->q0[i]) - (4.0 / h) * w->v0[i] - w->a0[i];
        w->a0[i] = a1;
        w->q0[i] = w->q[i];
        w->v0[i] = w->v[i];
    }
    for (int a = 0; a < w->m; a++) {
        /* the step's end: gaps, switches, the engaged elements' penetration rates */
        double g = md->g0[a] + pd_matrix_col_dot(&md->W, a, w->q0);
        w->res.min_gap = fmin(w->res.min_gap, g);
        if (w->eng[a] != w->eng_step[a]) {
            w->res.switches++;
            if (w->eng[a] && w->o.law == PD_PENALTY_HERTZDAMP)
                w->vseen = fmax(w->vseen, -pd_matrix_col_dot(&md->W, a, w->v0));
        }
        if (w->eng[a])
            w->res.max_penetration_velocity =
                fmax(w->res.max_penetration_velocity, -pd_matrix_col_dot(&md->W, a, w->v0));
        w->eng_step[a] = w->eng[a];
    }
    if (at_break) { /* F jumps at t1: a1 from its right limit */
        force_at(w, t1, +1, w->F2);
        for (int i = 0; i < n; i++)
            w->F2[i] -= w->F[i];
        pd_factor_solve(w->mass, w->F2); /* a1 += M^-1 (F(t1+) - F(t1-)) */
        for (int i = 0; i < n; i++)
            w->a0[i] += w->F2[i];
    }
    w->res.steps++;
    return PD_OK;
}

/* The options newmark needs: the shared ones and the step h > 0. */
static int nm_check(const nm_run *w, double t0, double t1, pd_err *err)
{
    const pd_penalty_opts *o = &w->o;
    int rc = pd_penalty_check_opts(o, t0, t1, "newmark", err);
    if (rc)
        return rc;
    if (!(o->h > 0.0) || !isfinite(o->h))
        return pd_err_set(err, PD_EINVAL, "newmark: the step h must be > 0 (got %g)", o->h);
    /* the run's steps within the budget */
    double steps = (t1 - t0) / o->h;
    if (!(steps <= (double)o->max_steps))
        return pd_err_set(err, PD_EBUDGET, "newmark: %.3g steps of %g s (at most %ld)", steps,
                          o->h * o->time_unit, o->max_steps);
    return PD_OK;
}

/* The factors, damping constants and the state at t0. */
static int nm_start(nm_run *w, double t0, const double *q0, const double *v0, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    const pd_model *md = w->md;
    /* What(h, theta = 1/2) = M + h/2 C + h^2/4 K; M itself for the accelerations */
    if (!(w->fac = pd_factor_alloc(md, w->h, 0.5, w->o.factor, err)) ||
        !(w->mass = pd_factor_alloc(md, 0.0, 1.0, w->o.factor, err)))
        return err->status;
    w->qscale = 0.0;
    for (int a = 0; a < w->m; a++) {
        double s;
        pd_factor_delassus_dense(w->mass, &a, 1, &s);
        if (!(s > 0.0) || !isfinite(s))
            return pd_err_set(err, PD_EINVAL,
                              "newmark: contact %d has no effective mass (W_a^T M^-1 W_a = %g)", a,
                              s);
        if (w->o.law == PD_PENALTY_KELVIN)
            w->cd[a] = pd_kelvin_damping(w->o.kc, md->e[a], 1.0 / s);
        w->qscale = fmax(w->qscale, fabs(md->g0[a])); /* Newton's scale: gaps and q */
    }
    for (int i = 0; i < w->n; i++) {
        w->q0[i] = q0 ? q0[i] : 0.0;
        w->v0[i] = v0 ? v0[i] : 0.0;
        if (!isfinite(w->q0[i]) || !isfinite(w->v0[i]))
            return pd_err_set(err, PD_EINVAL, "newmark: initial state: dof %d is not finite", i);
        w->qscale = fmax(w->qscale, fabs(w->q0[i]));
    }
    for (int j = 0; j < w->ns; j++) /* the springs' offsets start at 0 */
        w->qscale = fmax(w->qscale, md->uy[j]);
    if (!(w->qscale > 0.0))
        w->qscale = 1e-300; /* all zero */
    w->vfloor = 1e3 * w->o.atol;
    w->res.min_gap = HUGE_VAL;
    /* the engaged set at t0 and its forces, for a0 */
    elements(w, w->q0, w->v0, w->v0);
    memcpy(w->eng_step, w->eng, (size_t)w->m);
    for (int a = 0; a < w->m; a++)
        w->res.min_gap = fmin(w->res.min_gap, md->g0[a] + pd_matrix_col_dot(&md->W, a, w->q0));
    force_at(w, t0, +1, w->F);
    accelerations(w);
    return PD_OK;
}

int pd_penalty_newmark(const pd_model *model, double t0, const double *q0, const double *v0,
                       double t1, const pd_penalty_opts *opts, pd_observer observer, void *ctx,
                       pd_penalty_result *res, pd_err *err)
{
    nm_run w;
    int rc;
    memset(&w, 0, sizeof w);
    w.md = model;
    w.o = *opts;
    w.res.stepper = "newmark";
    if (!(rc = nm_check(&w, t0, t1, err))) {
        w.n = model->n;
        w.m = model->m;
        w.ns = model->ns;
        w.h = w.o.h;
        if (nm_alloc(&w))
            rc = pd_err_set(err, PD_ENOMEM, "newmark: out of memory for n = %d, m = %d, ns = %d",
                            w.n, w.m, w.ns);
    }
    if (!rc && !(rc = nm_start(&w, t0, q0, v0, err))) {
        long nsteps = pd_steps_for(t1 - t0, w.h), every = 1, k;
        int next_break = 0;
        /* the observer every h_out (a whole number of steps) and at the end */
        if (w.o.h_out > w.h)
            every = lround(w.o.h_out / w.h);
        report(&w, 0, t0, w.o.on_step, w.o.on_step_ctx);
        report(&w, 0, t0, observer, ctx);
        for (k = 1; k <= nsteps && !rc && !w.stopped; k++) {
            /* fixed steps (What holds h): step k ends at t0 + k h, the last at t1 */
            double tb = k == nsteps ? t1 : t0 + (double)k * w.h;
            int at_break = mj_break_at(model->breaks, model->nbreaks, &next_break, tb, 1e-9 * w.h);
            if (!(rc = step(&w, tb, at_break, err))) {
                report(&w, k, tb, w.o.on_step, w.o.on_step_ctx);
                if (k % every == 0 || k == nsteps)
                    report(&w, k, tb, observer, ctx);
            }
        }
    }
    if (res)
        *res = w.res;
    nm_free(&w);
    return rc;
}
