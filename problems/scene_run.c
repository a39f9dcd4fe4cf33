/* scene_run.c — running a scene: the one-wall oscillator's fast paths, the
 * general engines (Moreau–Jean, event-driven, penalty) on the scene's
 * model, and what a run measures.
 *
 * Measurements, in the reference units of the model (x = u / Le, tau = wp t):
 *   extremes   max |x|, max x, max -x per dof and max |x_k - x_k-1| per storey,
 *              at every step (Moreau–Jean: the discrete maximum); the exact
 *              row reference's own (exact, at its flights' turns); for
 *              event-general and penalty also between their steps, where
 *              the velocity changes sign, on the quintic Hermite of
 *              (x, x', x'') at the step ends;
 *   impacts    an impulse after none (Moreau–Jean: a step with P_a > 0 after a
 *              step without; event-driven: an impulse at an event; penalty: an
 *              element engaging);
 *   impulse    of one impact: the step's P_a, the event's P_a, or the integral
 *              of the element force over one engagement; a sample's impulse
 *              is everything since the previous sample: the contact force
 *              integrated plus the impacts' impulses (both references
 *              integrate their held forces themselves: the row reference in
 *              closed form, event-general by its integrator);
 *   approach   max over t of x_a - x_b (how far the gap closes);
 *   demands    peak |a_abs| per floor and |V| per storey (demand.c): at every
 *              step (Moreau–Jean, the discrete maximum as for umax); at every
 *              accepted step (penalty, newmark) or event (event-general) and
 *              between them on the cubic Hermite of the values and rates
 *              (free steps); the row reference at its impacts (before and
 *              after) and on a grid of whole multiples of dt, at most
 *              DEMAND_GRID per shortest period (or dt when sampling), with the
 *              same cubic between grid points without an impulse; the peak
 *              element force (penalty, newmark) at every accepted step. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_alloc.h"
#include "osc_priv.h"
#include "pd_null.h"
#include "demand.h"
#include "pd_problems.h"
#include "scene_priv.h"

#define DEMAND_GRID 128.0 /* the row reference's demand states per shortest period */

/* What a run tracks, in reference units. */
typedef struct track {
    const pd_scene *sc;
    pd_method method;
    double sample_s; /* wall time in sample(): the samples' assembly and the caller's sampler */
    int n, m;        /* dofs, contacts of the scene (the model may have none) */
    int model_m;     /* contacts of the model */
    double Le, wp, h, tau_measure;
    int *below;                         /* n: the dof of the storey below, -1 for storey 1 */
    int *dof_a, *dof_b;                 /* m: the dofs a contact joins, -1 at a wall */
    double *xmax, *xpos, *xneg, *drift; /* n */
    double *acc, *shear;                /* n: demand peaks [SI] */
    double *da, *dV, *dad, *dVd;        /* n: the instant's a_abs, V and their rates */
    double *qa, *qV, *qad, *qVd;        /* n: the same at the previous demand state */
    double *hacc, *qh;                  /* n: the held contact forces' part M^-1 W lambda of
                                           a_abs [SI] now and at the previous demand state */
    double *hlam;                       /* m: Moreau-Jean: the held force P / h of the last
                                           step without an impact (reference units) */
    double *hsm;                        /* n: Moreau-Jean: the smooth a_abs of the step [SI]
                                           (the holds' structures' entries) */
    int *hJ;                            /* m: Moreau-Jean: the candidate holds */
    double *hG, *hz, *hw, *hD;          /* their LCP: q (MJ_HELD_LCP), z, w, D (^2) */
    pd_lcp_solver *hlcp;
    unsigned char *sheld;    /* nstruct: row reference: a closed contact at an
                                           impact */
    const pd_osc *shape;     /* the excitation's shape: f = F_i / m_i */
    const double *mass;      /* n: the floors' masses [kg] */
    pd_progress_fn progress; /* told every hundredth of tau_end (NULL: not) */
    void *progress_ctx;
    double prog_next, prog_step; /* the next mark and the marks' spacing [tau] */
    double dem_t;                /* its time */
    int dem_prev;                /* 1: it has rates (an interval can be refined) */
    int demands;                 /* 0: not measured (pd_run_opts.no_demands) */
    int *st_of;                  /* n: the structure of each dof */
    double *ex, *ev;             /* n: an impact's positions and velocities */
    double *fpeak;               /* m: largest element force (reference units) */
    long *impacts;               /* m */
    double *first, *maxP, *ctime, *approach, *episode; /* m */
    double *g_prev, *U_prev, *U_prev2;                 /* m: Moreau–Jean first-impact estimate */
    unsigned char *touching;                           /* m: in an impact episode */
    double *px, *pv, *pa, *plam;                       /* the previous on_step report */
    unsigned char *pactive;
    double pt;
    int have_prev;
    long lcp_solves;
    /* sampling */
    pd_scene_sampler fn;
    void *ctx;
    double *sx, *sv, *sg, *sP, *imp; /* SI scratch; impulses since the last sample */
    long *sI, *sampled;              /* m: impacts since the last sample; reported */
    const long *live_impacts;        /* the row reference's counts during its run */
    double imp_t;                    /* penalty: time the impulses were integrated to */
    double *imp_lam;                 /* penalty: forces at imp_t */
    int edr_hit;                     /* row reference: an impulsive impact since the
                                         last sample (its samples' P also hold the
                                         held contacts' force integrals) */
    /* Moreau-Jean to a tolerance: the engine's estimate at each peak's instant */
    const double *err;   /* the state's estimate (NULL: none) */
    double *errx, *errd; /* n: at the umax, drift peaks */
    double *erra, *errv; /* n: the structure's largest at the a_abs, V peaks */
    double *serr;        /* nstruct: the structure's largest estimate now */
    double *wdof;        /* n: each dof's sqrt(K_ii / M_ii) (Pi units) */
    int dem_skipped;     /* a state was left out of the demands since the last */
    /* yielding springs (the model's ns; their dofs, ratios and uy [Le] the model's) */
    int ns;
    const int *spring_dof;
    const double *spring_alpha, *spring_uy;
    double *up, *excursion; /* ns: the offsets at the last report, sum |d up| */
    double *xeff;           /* n: displacements whose storey drifts d - (1 - alpha) up give
                               the springs' forces (the demands' state) */
    const double *xdem;     /* the demands' displacements of the report (q, or xeff) */
    double *sup;            /* n: the storeys' offsets at a sample [m] (0: elastic) */
    double *sF;             /* m: the contact elements' forces at a sample [N] */
    pd_scene_energy *en;    /* a yielding scene by Moreau-Jean: its energy balance */
    long *onsets;           /* ns: a report that slid after one that did not */
    unsigned char *slid;    /* ns: the last report slid */
} track;

/* ---- results ---------------------------------------------------------------- */

int pd_scene_result_alloc(const pd_scene *sc, pd_scene_result *r, pd_err *err)
{
    if (!r)
        return pd_err_set(err, PD_EINVAL, "result: NULL");
    memset(r, 0, sizeof *r);
    if (!sc || !sc->finished)
        return pd_err_set(err, PD_EINVAL, "scene: %s",
                          sc ? "not finished (pd_scene_finish)" : "NULL");
    long n = sc->n, m = sc->ncontact;
    r->n = sc->n;
    r->m = sc->ncontact;
    r->umax = pd_calloc(n, sizeof(double));
    r->u_pos = pd_calloc(n, sizeof(double));
    r->u_neg = pd_calloc(n, sizeof(double));
    r->drift = pd_calloc(n, sizeof(double));
    r->impacts = pd_calloc(m, sizeof(long));
    r->first_impact = pd_calloc(m, sizeof(double));
    r->max_impulse = pd_calloc(m, sizeof(double));
    r->contact_time = pd_calloc(m, sizeof(double));
    r->approach = pd_calloc(m, sizeof(double));
    r->acc_max = pd_calloc(n, sizeof(double));
    r->shear_max = pd_calloc(n, sizeof(double));
    r->drift_ratio = pd_calloc(n, sizeof(double));
    r->force_max = pd_calloc(m, sizeof(double));
    r->force_equiv = pd_calloc(m, sizeof(double));
    r->nstruct = sc->nstruct;
    r->err_est = pd_calloc(sc->nstruct, sizeof(double));
    r->law_band = pd_calloc(sc->nstruct, sizeof(double));
    r->ductility = pd_calloc(n, sizeof(double));
    r->residual = pd_calloc(n, sizeof(double));
    r->plastic_excursion = pd_calloc(n, sizeof(double));
    r->n_yield = pd_calloc(n, sizeof(long));
    if (!r->ductility || !r->residual || !r->plastic_excursion || !r->n_yield || !r->umax ||
        !r->u_pos || !r->u_neg || !r->drift || !r->impacts || !r->first_impact || !r->max_impulse ||
        !r->contact_time || !r->approach || !r->acc_max || !r->shear_max || !r->drift_ratio ||
        !r->force_max || !r->force_equiv || !r->err_est || !r->law_band) {
        pd_scene_result_free(r);
        return pd_err_set(err, PD_ENOMEM, "out of memory for the results of %d dofs", sc->n);
    }
    return PD_OK;
}

int pd_scene_result_fits(const pd_scene *sc, const pd_scene_result *r)
{
    return sc && r && r->n == sc->n && r->m == sc->ncontact && r->umax && r->u_pos && r->u_neg &&
           r->drift && r->impacts && r->first_impact && r->max_impulse && r->contact_time &&
           r->approach && r->acc_max && r->shear_max && r->drift_ratio && r->force_max &&
           r->force_equiv && r->err_est && r->law_band && r->ductility && r->residual &&
           r->plastic_excursion && r->n_yield && r->nstruct == sc->nstruct;
}

void pd_scene_result_free(pd_scene_result *r)
{
    if (!r)
        return;
    free(r->umax);
    free(r->u_pos);
    free(r->u_neg);
    free(r->drift);
    free(r->impacts);
    free(r->first_impact);
    free(r->max_impulse);
    free(r->contact_time);
    free(r->approach);
    free(r->acc_max);
    free(r->shear_max);
    free(r->drift_ratio);
    free(r->force_max);
    free(r->force_equiv);
    free(r->err_est);
    free(r->law_band);
    free(r->ductility);
    free(r->residual);
    free(r->plastic_excursion);
    free(r->n_yield);
    memset(r, 0, sizeof *r);
}

/* A Moreau–Jean contact is a candidate hold when it takes an impulse in
 * this step and the one before and is at rest after both: a gap rate within
 * MJ_HELD_RATE steps' worth of the excitation's acceleration (reference
 * units: ap = 1).  The candidates' forces are those of the contact-force
 * LCP at the step's state, as the references' (up to MJ_HELD_LCP of them;
 * beyond, no held part), not P / h: theta = 1/2 alternates a hold's
 * impulses, and a step that merges an impact's cascade has impulses far
 * beyond any hold. */
#define MJ_HELD_RATE 4.0
#define MJ_HELD_LCP 64

/* ---- the tracker ------------------------------------------------------------ */

static void track_free(track *tr)
{
    void *arrays[] = {
        tr->below,   tr->dof_a,   tr->dof_b,    tr->xmax,  tr->xpos,     tr->xneg,      tr->drift,
        tr->impacts, tr->first,   tr->maxP,     tr->ctime, tr->approach, tr->episode,   tr->g_prev,
        tr->U_prev,  tr->U_prev2, tr->touching, tr->px,    tr->pv,       tr->pa,        tr->plam,
        tr->pactive, tr->sx,      tr->sv,       tr->sg,    tr->sP,       tr->imp,       tr->imp_lam,
        tr->acc,     tr->shear,   tr->da,       tr->dV,    tr->fpeak,    tr->dad,       tr->dVd,
        tr->qa,      tr->qV,      tr->qad,      tr->qVd,   tr->st_of,    tr->ex,        tr->ev,
        tr->sI,      tr->sampled, tr->errx,     tr->errd,  tr->erra,     tr->errv,      tr->serr,
        tr->wdof,    tr->hacc,    tr->qh,       tr->hlam,  tr->hsm,      tr->hJ,        tr->hG,
        tr->hz,      tr->hw,      tr->hD,       tr->sheld, tr->up,       tr->excursion, tr->onsets,
        tr->slid,    tr->xeff,    tr->sup,      tr->sF};
    for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
        free(arrays[k]);
    pd_lcp_solver_free(tr->hlcp);
}

/* Every array once, the topology of the scene. */
static int track_alloc(track *tr, const pd_scene *sc, pd_err *err)
{
    long n = sc->n, m = sc->ncontact;
    tr->sc = sc;
    tr->n = sc->n;
    tr->m = sc->ncontact;
#define TA(p, cnt) ((p) = pd_calloc((long)(cnt), sizeof *(p)))
    if (!TA(tr->below, n) || !TA(tr->dof_a, m) || !TA(tr->dof_b, m) || !TA(tr->xmax, n) ||
        !TA(tr->xpos, n) || !TA(tr->xneg, n) || !TA(tr->drift, n) || !TA(tr->impacts, m) ||
        !TA(tr->first, m) || !TA(tr->maxP, m) || !TA(tr->ctime, m) || !TA(tr->approach, m) ||
        !TA(tr->episode, m) || !TA(tr->g_prev, m) || !TA(tr->U_prev, m) || !TA(tr->U_prev2, m) ||
        !TA(tr->touching, m) || !TA(tr->px, n) || !TA(tr->pv, n) || !TA(tr->pa, n) ||
        !TA(tr->plam, m) || !TA(tr->pactive, m) || !TA(tr->sx, n) || !TA(tr->sv, n) ||
        !TA(tr->sg, m) || !TA(tr->sP, m) || !TA(tr->imp, m) || !TA(tr->imp_lam, m) ||
        !TA(tr->acc, n) || !TA(tr->shear, n) || !TA(tr->da, n) || !TA(tr->dV, n) ||
        !TA(tr->fpeak, m) || !TA(tr->dad, n) || !TA(tr->dVd, n) || !TA(tr->qa, n) ||
        !TA(tr->qV, n) || !TA(tr->qad, n) || !TA(tr->qVd, n) || !TA(tr->st_of, n) ||
        !TA(tr->ex, n) || !TA(tr->ev, n) || !TA(tr->sI, m) || !TA(tr->sampled, m) ||
        !TA(tr->errx, n) || !TA(tr->errd, n) || !TA(tr->erra, n) || !TA(tr->errv, n) ||
        !TA(tr->serr, sc->nstruct) || !TA(tr->wdof, n) || !TA(tr->hacc, n) || !TA(tr->qh, n) ||
        !TA(tr->hlam, m) || !TA(tr->hsm, n) || !TA(tr->hJ, m) || !TA(tr->hG, MJ_HELD_LCP) ||
        !TA(tr->hz, MJ_HELD_LCP) || !TA(tr->hw, MJ_HELD_LCP) ||
        !TA(tr->hD, MJ_HELD_LCP * MJ_HELD_LCP) || !TA(tr->sheld, sc->nstruct) || !TA(tr->sF, m)) {
#undef TA
        track_free(tr);
        return pd_err_set(err, PD_ENOMEM, "out of memory for tracking %d dofs", sc->n);
    }
    for (int s = 0; s < sc->nstruct; s++)
        for (int k = 0; k < sc->st[s].storeys; k++) {
            tr->below[sc->st[s].dof + k] = k == 0 ? -1 : sc->st[s].dof + k - 1;
            tr->st_of[sc->st[s].dof + k] = s;
        }
    for (int a = 0; a < tr->m; a++) {
        const pd_contact *ct = &sc->ct[a];
        tr->dof_a[a] = ct->a == PD_WALL ? -1 : sc->st[ct->a].dof + ct->level_a - 1;
        tr->dof_b[a] = ct->b == PD_WALL ? -1 : sc->st[ct->b].dof + ct->level_b - 1;
        tr->first[a] = NAN;
        tr->approach[a] = -HUGE_VAL;
    }
    return PD_OK;
}

/* The yielding springs of the model built for sc (sm): their arrays. */
static int track_springs(track *tr, const pd_scene_model *sm, pd_err *err)
{
    int ns = sm->model.ns;
    tr->ns = ns;
    tr->spring_dof = sm->spring_dof;
    tr->spring_alpha = sm->spring_alpha;
    tr->spring_uy = sm->uy;
    tr->up = pd_calloc(ns, sizeof(double));
    tr->excursion = pd_calloc(ns, sizeof(double));
    tr->onsets = pd_calloc(ns, sizeof(long));
    tr->slid = pd_calloc(ns, 1);
    tr->xeff = pd_calloc(tr->n, sizeof(double));
    tr->sup = pd_calloc(tr->n, sizeof(double));
    if (!tr->up || !tr->excursion || !tr->onsets || !tr->slid || !tr->xeff || !tr->sup)
        return pd_err_set(err, PD_ENOMEM, "out of memory for tracking %d yielding springs", ns);
    return PD_OK;
}

/* A report's offsets: a spring that moved slid since the last (an onset
 * when it had not), its excursion summed; the demands' displacements: q,
 * or with springs q less each yielding storey's (1 - alpha) up from its
 * floor up (the storey forces k (d - (1 - alpha) up) as elastic ones). */
static void note_springs(track *tr, const pd_state *st)
{
    tr->xdem = st->q;
    if (!st->up)
        return;
    memcpy(tr->xeff, st->q, (size_t)tr->n * sizeof(double));
    for (int j = 0; j < tr->ns; j++) {
        double d = st->up[j] - tr->up[j];
        tr->onsets[j] += d != 0.0 && !tr->slid[j];
        tr->slid[j] = d != 0.0;
        tr->excursion[j] += fabs(d);
        tr->up[j] = st->up[j];
        int i = tr->spring_dof[j], s = tr->st_of[i];
        int top = tr->sc->st[s].dof + tr->sc->st[s].storeys;
        for (int k = i; k < top; k++)
            tr->xeff[k] -= (1.0 - tr->spring_alpha[j]) * st->up[j];
    }
    tr->xdem = tr->xeff;
}

/* Nothing measured yet (a run to a tolerance repeated): the run's arrays
 * as track_alloc left them. */
static void track_clear(track *tr)
{
    size_t n = (size_t)tr->n * sizeof(double), m = (size_t)tr->m;
    double *dn[] = {tr->xmax,  tr->xpos, tr->xneg, tr->drift, tr->acc,
                    tr->shear, tr->errx, tr->errd, tr->erra,  tr->errv};
    for (size_t k = 0; k < sizeof dn / sizeof dn[0]; k++)
        memset(dn[k], 0, n);
    double *dm[] = {tr->maxP, tr->ctime, tr->episode, tr->imp, tr->fpeak, tr->hlam};
    for (size_t k = 0; k < sizeof dm / sizeof dm[0]; k++)
        memset(dm[k], 0, m * sizeof(double));
    memset(tr->impacts, 0, m * sizeof(long));
    memset(tr->sampled, 0, m * sizeof(long));
    memset(tr->touching, 0, m);
    for (int a = 0; a < tr->m; a++) {
        tr->first[a] = NAN;
        tr->approach[a] = -HUGE_VAL;
    }
    tr->have_prev = tr->dem_prev = tr->dem_skipped = 0;
    tr->lcp_solves = 0;
}

/* The estimate at the instant a displacement (drift: 1) peak of dof i is
 * raised to value p (the engine's, to a tolerance; the drift's adds the
 * storey below). */
static void note_err(track *tr, int i, int drift, double p, double old)
{
    if (!tr->err || !(p > old))
        return;
    if (drift)
        tr->errd[i] = tr->err[i] + (tr->below[i] >= 0 ? tr->err[tr->below[i]] : 0.0);
    else
        tr->errx[i] = tr->err[i];
}

/* Extremes of the displacement and of the storey drift at one point in time. */
static void note_point(track *tr, double t, const double *x)
{
    if (t < tr->tau_measure - 0.5 * tr->h)
        return;
    for (int i = 0; i < tr->n; i++) {
        double d = x[i] - (tr->below[i] >= 0 ? x[tr->below[i]] : 0.0), ax = fabs(x[i]);
        if (ax > tr->xmax[i]) { /* raised: its estimate now (note_err) */
            note_err(tr, i, 0, ax, tr->xmax[i]);
            tr->xmax[i] = ax;
        }
        if (fabs(d) > tr->drift[i]) {
            note_err(tr, i, 1, fabs(d), tr->drift[i]);
            tr->drift[i] = fabs(d);
        }
        tr->xpos[i] = pd_max(tr->xpos[i], x[i]);
        tr->xneg[i] = pd_max(tr->xneg[i], -x[i]);
    }
}

/* The held contact forces' part of a_abs, M^-1 W lambda [SI], into
 * tr->hacc: from forces lam (m, reference units, force unit ap kg; NULL:
 * none held), W's column of contact a being -1 at dof_a and +1 at dof_b. */
static void held_from_forces(track *tr, const double *lam)
{
    double ap = tr->sc->exc.ap;
    memset(tr->hacc, 0, (size_t)tr->n * sizeof(double));
    for (int a = 0; lam && a < tr->model_m; a++) {
        if (lam[a] == 0.0)
            continue;
        if (tr->dof_a[a] >= 0)
            tr->hacc[tr->dof_a[a]] -= ap * lam[a] / tr->mass[tr->dof_a[a]];
        if (tr->dof_b[a] >= 0)
            tr->hacc[tr->dof_b[a]] += ap * lam[a] / tr->mass[tr->dof_b[a]];
    }
}

/* The same from the accelerations acc (reference units, held forces in
 * them) of the state (x, v) at t: a_abs = ap (x'' - f(t)) with f = F_i / m_i
 * the excitation's (side: its limit at a jump), less the smooth part
 * -M^-1 (C u' + K u), evaluated into a (n) and tr->dV: returns 1 then;
 * zero when held is 0 (no contact held: rounding), returns 0. */
static int held_from_acc(track *tr, double t, int side, const double *x, const double *v,
                         const double *acc, int held, double *a)
{
    double us = tr->Le, vs = tr->Le * tr->wp, ap = tr->sc->exc.ap;
    if (!held || !acc || !tr->demands) {
        held_from_forces(tr, NULL);
        return 0;
    }
    double f = pd_osc_shape(tr->shape, t, side);
    pd_demand_eval(tr->sc, x, v, us, vs, a, tr->dV);
    for (int i = 0; i < tr->n; i++)
        tr->hacc[i] = ap * (acc[i] - f) - a[i];
    return 1;
}

/* peak[i] = max(peak[i], p); a peak raised takes, in runs to a tolerance
 * (tr->err), its structure's estimate now into err_at[i]. */
static inline void raise_peak(track *tr, double *peak, double *err_at, int i, double p)
{
    double old = peak[i];
    peak[i] = pd_max(old, p);
    if (tr->err && peak[i] > old)
        err_at[i] = tr->serr[tr->st_of[i]];
}

/* The demands of the state (x, v) at t, inside the window, a_abs with the
 * held contact forces' part held (n, SI; NULL: none); with its
 * accelerations acc (NULL: none), their peaks between it and the previous
 * state on the cubic Hermite of the values and rates, when the interval
 * was smooth (no impulse in it): the held part linear over the interval
 * (its rate the secant's), the rest with its exact rates.  evaluated: the
 * smooth part of (x, v) is in tr->da and tr->dV already (held_from_acc). */
static void note_demand(track *tr, double t, const double *x, const double *v, const double *acc,
                        const double *held, int smooth, int evaluated)
{
    double us = tr->Le, vs = tr->Le * tr->wp, as = vs * tr->wp;
    if (!tr->demands)
        return;
    if (t < tr->tau_measure - 0.5 * tr->h) {
        tr->dem_prev = 0;
        if (evaluated) /* no demands before the window (the samples' a_abs 0) */
            memset(tr->da, 0, (size_t)tr->n * sizeof(double));
        return;
    }
    if (!evaluated)
        pd_demand_eval(tr->sc, x, v, us, vs, tr->da, tr->dV);
    for (int i = 0; i < tr->n; i++) {
        tr->da[i] += held ? held[i] : 0.0;
        raise_peak(tr, tr->acc, tr->erra, i, fabs(tr->da[i]));
        raise_peak(tr, tr->shear, tr->errv, i, fabs(tr->dV[i]));
    }
    if (!acc) {
        tr->dem_prev = 0;
        return;
    }
    pd_demand_eval(tr->sc, v, acc, vs, as, tr->dad, tr->dVd); /* the rates [1/s] */
    double h = (t - tr->dem_t) / tr->wp;
    /* the cubic's turns only where they could raise the peak: inside the step
     * it strays from its ends by at most h (|d0| + |d1|) / 4, and not at all
     * where it is monotone (pd_demand_cubic_monotone) */
    if (tr->dem_prev && smooth && h > 0.0)
        for (int i = 0; i < tr->n; i++) {
            double hs = held ? (held[i] - tr->qh[i]) / h : -tr->qh[i] / h; /* the secant */
            double d0 = tr->qad[i] + hs, d1 = tr->dad[i] + hs;
            if (!pd_demand_cubic_monotone(tr->qa[i], d0, tr->da[i], d1, h) &&
                pd_max(fabs(tr->qa[i]), fabs(tr->da[i])) + 0.25 * h * (fabs(d0) + fabs(d1)) >
                    tr->acc[i])
                raise_peak(tr, tr->acc, tr->erra, i,
                           pd_demand_cubic_peak(tr->qa[i], d0, tr->da[i], d1, h));
            if (!pd_demand_cubic_monotone(tr->qV[i], tr->qVd[i], tr->dV[i], tr->dVd[i], h) &&
                pd_max(fabs(tr->qV[i]), fabs(tr->dV[i])) +
                        0.25 * h * (fabs(tr->qVd[i]) + fabs(tr->dVd[i])) >
                    tr->shear[i])
                raise_peak(tr, tr->shear, tr->errv, i,
                           pd_demand_cubic_peak(tr->qV[i], tr->qVd[i], tr->dV[i], tr->dVd[i], h));
        }
    size_t bytes = (size_t)tr->n * sizeof(double);
    memcpy(tr->qa, tr->da, bytes);
    memcpy(tr->qV, tr->dV, bytes);
    memcpy(tr->qad, tr->dad, bytes);
    memcpy(tr->qVd, tr->dVd, bytes);
    if (held)
        memcpy(tr->qh, held, bytes);
    else
        memset(tr->qh, 0, bytes);
    tr->dem_t = t;
    tr->dem_prev = 1;
}

/* The caller told how far the run has come, at each hundredth of it. */
static void note_progress(track *tr, double t)
{
    if (!tr->progress || t < tr->prog_next)
        return;
    tr->progress(fmin(1.0, t / (100.0 * tr->prog_step)), tr->progress_ctx);
    tr->prog_next = (floor(t / tr->prog_step) + 1.0) * tr->prog_step;
}

/* The row reference's impacts: the demands of the structures involved with
 * the velocities before and after (positions are continuous). */
static int on_edr_event(const pd_edr_event *e, void *ctx)
{
    track *tr = ctx;
    note_progress(tr, e->t);
    double us = tr->Le, vs = tr->Le * tr->wp;
    if (e->kind != PD_EDR_IMPACT)
        return 0;
    for (int j = 0; j < e->ncontacts; j++)
        tr->edr_hit |= e->P[j] > 0.0;
    if (e->t < tr->tau_measure - 0.5 * tr->h)
        return 0;
    /* a structure with a contact closed before or after the impact (held,
     * or coming to rest) carries held forces the event does not give: its
     * a_abs is left to the grid's states (the shears are exact here) */
    double U = 0.0;
    for (int j = 0; j < e->ncontacts; j++)
        U = pd_max(U, fabs(e->U_minus[j]));
    memset(tr->sheld, 0, (size_t)tr->sc->nstruct);
    for (int j = 0; j < e->ncontacts; j++) {
        int a = e->contacts[j];
        if (e->U_minus[j] < -1e-9 * U && e->U_plus[j] > 1e-9 * U)
            continue;
        if (tr->dof_a[a] >= 0)
            tr->sheld[tr->st_of[tr->dof_a[a]]] = 1;
        if (tr->dof_b[a] >= 0)
            tr->sheld[tr->st_of[tr->dof_b[a]]] = 1;
    }
    for (int side = 0; side < 2; side++) {
        for (int k = 0; k < e->ndofs; k++) {
            int d = e->dofs[k];
            tr->ex[d] = e->x[k];
            tr->ev[d] = side ? e->v_plus[k] : e->v_minus[k];
        }
        for (int k = 0; k < e->ndofs; k++) {
            const pd_structure *st = &tr->sc->st[tr->st_of[e->dofs[k]]];
            if (st->dof != e->dofs[k]) /* once per structure, from its first floor */
                continue;
            pd_demand_eval_structure(st, tr->ex, tr->ev, us, vs, tr->da, tr->dV);
            for (int i = st->dof; i < st->dof + st->storeys; i++) {
                if (!tr->sheld[tr->st_of[i]])
                    tr->acc[i] = pd_max(tr->acc[i], fabs(tr->da[i]));
                tr->shear[i] = pd_max(tr->shear[i], fabs(tr->dV[i]));
            }
        }
    }
    return 0;
}

/* 1 when no element is engaged at st nor at the previous report (penalty:
 * the cubic of a free step; an engaged step's rates follow the stiff force). */
static int no_element(const track *tr, const pd_state *st)
{
    for (int a = 0; a < tr->model_m; a++)
        if (st->active[a] || tr->pactive[a])
            return 0;
    return 1;
}

/* 1 when no impulse is reported in st (P holds impulses). */
static int no_impulse(const track *tr, const pd_state *st)
{
    for (int a = 0; a < tr->model_m; a++)
        if (st->P[a] > 0.0)
            return 0;
    return 1;
}

/* How far each gap has closed: x_a - x_b (walls at 0). */
static void note_approach(track *tr, const double *x)
{
    for (int a = 0; a < tr->m; a++) {
        double xa = tr->dof_a[a] >= 0 ? x[tr->dof_a[a]] : 0.0;
        double xb = tr->dof_b[a] >= 0 ? x[tr->dof_b[a]] : 0.0;
        tr->approach[a] = pd_max(tr->approach[a], xa - xb);
    }
}

/* Extremes between the previous report and (t, x, v, a): turning points of
 * every dof and every storey drift. */
static void note_between(track *tr, double t, const double *x, const double *v, const double *acc)
{
    double h = t - tr->pt, f;
    if (!(h > 0.0) || t < tr->tau_measure)
        return;
    for (int i = 0; i < tr->n; i++) {
        int b = tr->below[i];
        /* a turn needs the rate's sign to change (pd_demand_quintic_turn's test) */
        if (b < 0 && !(tr->pv[i] * v[i] < 0.0))
            continue;
        double p0[3] = {tr->px[i], tr->pv[i], tr->pa[i]}, p1[3] = {x[i], v[i], acc[i]};
        if (pd_demand_quintic_turn(p0, p1, h, &f)) {
            note_err(tr, i, 0, fabs(f), tr->xmax[i]);
            tr->xmax[i] = pd_max(tr->xmax[i], fabs(f));
            tr->xpos[i] = pd_max(tr->xpos[i], f);
            tr->xneg[i] = pd_max(tr->xneg[i], -f);
            if (b < 0) { /* storey 1: the drift is the displacement */
                note_err(tr, i, 1, fabs(f), tr->drift[i]);
                tr->drift[i] = pd_max(tr->drift[i], fabs(f));
            }
        }
        if (b < 0)
            continue;
        double d0[3] = {tr->px[i] - tr->px[b], tr->pv[i] - tr->pv[b], tr->pa[i] - tr->pa[b]};
        double d1[3] = {x[i] - x[b], v[i] - v[b], acc[i] - acc[b]};
        if (pd_demand_quintic_turn(d0, d1, h, &f)) {
            note_err(tr, i, 1, fabs(f), tr->drift[i]);
            tr->drift[i] = pd_max(tr->drift[i], fabs(f));
        }
    }
}

/* Remember a report as the start of the next interval. */
static void keep_report(track *tr, const pd_state *st)
{
    memcpy(tr->px, st->q, (size_t)tr->n * sizeof(double));
    memcpy(tr->pv, st->v, (size_t)tr->n * sizeof(double));
    if (st->has_acc)
        memcpy(tr->pa, st->acc, (size_t)tr->n * sizeof(double));
    for (int a = 0; a < tr->model_m; a++) {
        tr->pactive[a] = st->active[a];
        tr->plam[a] = st->P[a];
    }
    tr->pt = st->t;
    tr->have_prev = st->has_acc;
}

/* Time s in [0, h] after a step start at which a gap g0 > 0 closes under
 * g(s) = g0 + U s + G s^2 / 2 (rate U, acceleration G of the step). */
static double closing_time(double g0, double U, double G, double h)
{
    double s = h;
    if (g0 <= 0.0)
        return 0.0;
    if (G == 0.0 || fabs(G) * h < 1e-12 * fabs(U))
        s = U < 0.0 ? -g0 / U : h;
    else {
        double disc = U * U - 2.0 * G * g0;
        if (disc >= 0.0)
            s = U < 0.0 ? 2.0 * g0 / (-U + sqrt(disc)) : (-U - sqrt(disc)) / G;
    }
    return fmin(fmax(s, 0.0), h);
}

/* Sampler: the state in metres, seconds and newton-seconds. */
static int sample(track *tr, const pd_state *st)
{
    double t0 = pd_wall_seconds(), vs = tr->Le * tr->wp, Ps = tr->sc->exc.ap / tr->wp;
    for (int i = 0; i < tr->n; i++) {
        tr->sx[i] = st->q[i] * tr->Le;
        tr->sv[i] = st->v[i] * vs;
    }
    for (int a = 0; a < tr->m; a++) {
        double xa = tr->dof_a[a] >= 0 ? st->q[tr->dof_a[a]] : 0.0;
        double xb = tr->dof_b[a] >= 0 ? st->q[tr->dof_b[a]] : 0.0;
        tr->sg[a] = tr->sc->ct[a].gap + (xb - xa) * tr->Le;
        tr->sP[a] = tr->imp[a] * Ps;
        tr->imp[a] = 0.0;
        tr->sI[a] = tr->impacts[a] - tr->sampled[a];
        tr->sampled[a] = tr->impacts[a];
    }
    for (int j = 0; j < tr->ns; j++) /* the storeys' offsets, in metres */
        tr->sup[tr->spring_dof[j]] = st->up ? st->up[j] * tr->Le : 0.0;
    int penalty = tr->method == PD_METHOD_PENALTY || tr->method == PD_METHOD_NEWMARK;
    for (int a = 0; penalty && a < tr->m; a++) /* the elements' forces [N]: ap kg a unit */
        tr->sF[a] = tr->imp_lam[a] * tr->sc->exc.ap;
    pd_scene_sample s = {.step = st->step,
                         .t = st->t / tr->wp,
                         .x = tr->sx,
                         .v = tr->sv,
                         .gap = tr->sg,
                         .impulse = tr->sP,
                         .impacts = tr->sI,
                         .up = tr->ns > 0 ? tr->sup : NULL,
                         .a_abs = tr->demands ? tr->da : NULL,
                         .force = penalty ? tr->sF : NULL};
    int stop = tr->fn(&s, tr->ctx);
    tr->sample_s += pd_wall_seconds() - t0;
    return stop;
}

/* Gap rate of contact a: x_b' - x_a' (walls at rest). */
static double gap_rate(const track *tr, int a, const double *v)
{
    return (tr->dof_b[a] >= 0 ? v[tr->dof_b[a]] : 0.0) -
           (tr->dof_a[a] >= 0 ? v[tr->dof_a[a]] : 0.0);
}

/* The free relative acceleration of dof i (reference units; -1: a wall, at
 * rest with the ground) from the smooth a_abs (SI) and the forcing f. */
static double free_rel_acc(const track *tr, int i, double f)
{
    return i < 0 ? 0.0 : tr->hsm[i] / tr->sc->exc.ap + f;
}

/* The holds' forces at the state st into tr->hlam and tr->hacc: the
 * contact-force LCP over the candidate holds J[0..k) (none beyond
 * MJ_HELD_LCP of them),
 *   g'' = D lambda + G >= 0 _|_ lambda >= 0,  D_ab = sum_i W_ia W_ib / m_i,
 *   G_a = W_a^T u''_free  (u''_free from the smooth a_abs and f(t)). */
static void held_lcp(track *tr, const pd_state *st, int k)
{
    int *J = tr->hJ;
    if (k == 0 || k > MJ_HELD_LCP || !tr->hlcp) {
        held_from_forces(tr, NULL);
        return;
    }
    double f = pd_osc_shape(tr->shape, st->t, -1);
    /* the smooth a_abs of the holds' structures only (note_demand takes the
     * whole scene's): O(their storeys) per step with holds */
    for (int r = 0; r < k; r++)
        for (int side = 0; side < 2; side++) {
            int i = side ? tr->dof_b[J[r]] : tr->dof_a[J[r]];
            if (i >= 0)
                pd_demand_eval_structure(&tr->sc->st[tr->st_of[i]], tr->xdem ? tr->xdem : st->q,
                                         st->v, tr->Le, tr->Le * tr->wp, tr->hsm, tr->dV);
        }
    for (int r = 0; r < k; r++) {
        int a = J[r], ia = tr->dof_a[a], ib = tr->dof_b[a];
        tr->hG[r] = free_rel_acc(tr, ib, f) - free_rel_acc(tr, ia, f);
        for (int c = 0; c < k; c++) { /* W_a = -e_ia + e_ib */
            int b = J[c], ja = tr->dof_a[b], jb = tr->dof_b[b];
            double d = 0.0;
            if (ia >= 0)
                d += ((ia == ja) - (ia == jb)) / tr->mass[ia];
            if (ib >= 0)
                d += ((ib == jb) - (ib == ja)) / tr->mass[ib];
            tr->hD[r + (size_t)c * k] = d;
        }
    }
    pd_matrix D = pd_matrix_dense(k, k, tr->hD);
    if (pd_lcp_solve(tr->hlcp, &D, tr->hG, NULL, tr->hz, tr->hw, NULL) == PD_OK)
        for (int r = 0; r < k; r++)
            tr->hlam[J[r]] = tr->hz[r];
    held_from_forces(tr, tr->hlam);
}

/* Moreau–Jean's holds (held_lcp): contacts with an impulse in this step and
 * the one before, at rest after both. */
static void moreau_held(track *tr, const pd_state *st)
{
    double rest = MJ_HELD_RATE * tr->h;
    int k = 0, *J = tr->hJ;
    for (int a = 0; a < tr->model_m; a++) {
        tr->hlam[a] = 0.0;
        if (st->P[a] > 0.0 && tr->touching[a] && fabs(tr->U_prev[a]) <= rest &&
            fabs(gap_rate(tr, a, st->v)) <= rest)
            J[k++] = a;
    }
    held_lcp(tr, st, k);
}

/* The penalty methods' holds: an element engaged after this step and the
 * one before, at rest after both (a gap rate within MJ_HELD_RATE grid
 * steps' worth of ap), takes the rigid contact-force LCP's force, not the
 * element's (an impact's and a hold's at once: its ringing is no floor
 * acceleration); the gap rates kept in U_prev. */
static void penalty_held(track *tr, const pd_state *st)
{
    double rest = MJ_HELD_RATE * tr->h;
    int k = 0, *J = tr->hJ;
    for (int a = 0; a < tr->model_m; a++) {
        double U = gap_rate(tr, a, st->v);
        tr->hlam[a] = 0.0;
        if (st->active[a] && tr->pactive[a] && fabs(tr->U_prev[a]) <= rest && fabs(U) <= rest)
            J[k++] = a;
        tr->U_prev[a] = U;
    }
    held_lcp(tr, st, k);
}

/* Moreau–Jean, every step: extremes at the step, impacts (an impulse after a
 * step without) with the first one's instant estimated inside its step from
 * the step start and the previous step's gap acceleration, the sample. */
static int observe_moreau(const pd_state *st, void *ctx)
{
    track *tr = ctx;
    note_progress(tr, st->t);
    note_springs(tr, st);
    if (tr->en)
        pd_scene_energy_note(tr->en, st);
    note_point(tr, st->t, st->q);
    note_approach(tr, st->q);
    if (tr->demands)
        moreau_held(tr, st);
    note_demand(tr, st->t, tr->xdem, st->v, NULL, tr->hacc, 0, 0); /* the steps' own: as umax */
    tr->lcp_solves += st->nactive > 0;
    for (int a = 0; a < tr->model_m; a++) {
        double P = st->P[a], U = gap_rate(tr, a, st->v);
        if (P > 0.0) {
            if (!tr->touching[a] && isnan(tr->first[a])) {
                double G = st->step > 1 ? (tr->U_prev[a] - tr->U_prev2[a]) / tr->h : 0.0;
                tr->first[a] = st->t - tr->h + closing_time(tr->g_prev[a], tr->U_prev[a], G, tr->h);
            }
            tr->impacts[a] += !tr->touching[a];
            tr->ctime[a] += tr->h;
            tr->maxP[a] = pd_max(tr->maxP[a], P);
        }
        tr->touching[a] = P > 0.0;
        tr->imp[a] += P;
        tr->U_prev2[a] = tr->U_prev[a];
        tr->U_prev[a] = U;
        tr->g_prev[a] = st->g[a];
    }
    return tr->fn ? sample(tr, st) : 0;
}

/* Moreau-Jean to a tolerance, every kept step (its size st->h): extremes at
 * the step and inside it (smooth steps: no impact, on the quintic Hermite
 * of the exact flights' accelerations), each raised peak with the engine's
 * estimate at its instant (demands: the structure's largest), impacts (an
 * impulse after a step without; the first at the middle of its step, a
 * step the controller made short), contact time, the sample. */
static int observe_adapt(const pd_state *st, void *ctx)
{
    track *tr = ctx;
    note_progress(tr, st->t);
    /* a smooth step: no impact in it, the accelerations at both ends (the
     * start's right limit, kept below, and the end's left one; held
     * contacts' forces included) */
    int smooth = st->has_acc && st->step > 0 && !st->impact;
    tr->err = st->err;
    for (int s = 0; s < tr->sc->nstruct; s++) {
        const pd_structure *ps = &tr->sc->st[s];
        double e = 0.0;
        for (int k = 0; k < ps->storeys; k++)
            e = pd_max(e, st->err[ps->dof + k]);
        tr->serr[s] = e;
    }
    if (tr->have_prev && st->has_acc && smooth)
        note_between(tr, st->t, st->q, st->v, st->acc);
    note_point(tr, st->t, st->q);
    note_approach(tr, st->q);
    /* demands at the states after smooth steps only: right after an impact
     * the velocities may be a stage's, which the next step's impulse
     * completes (the impact's outcome is the next state's, a step the
     * controller made short) */
    if (tr->demands && st->has_acc && !st->impact) {
        int ev = held_from_acc(tr, st->t, -1, st->q, st->v, st->acc, !no_impulse(tr, st), tr->da);
        note_demand(tr, st->t, st->q, st->v, st->acc, tr->hacc, smooth && !tr->dem_skipped, ev);
        tr->dem_skipped = 0;
    } else if (tr->demands) {
        tr->dem_skipped = 1;
    }
    tr->lcp_solves += st->nactive > 0;
    for (int a = 0; a < tr->model_m; a++) {
        double P = st->P[a];
        if (P > 0.0) {
            if (!tr->touching[a] && isnan(tr->first[a]))
                tr->first[a] = st->t - 0.5 * st->h;
            tr->impacts[a] += !tr->touching[a];
            tr->ctime[a] += st->h;
            tr->maxP[a] = pd_max(tr->maxP[a], P);
        }
        tr->touching[a] = P > 0.0;
        tr->imp[a] += P;
    }
    keep_report(tr, st);
    if (st->has_acc && st->acc_right != st->acc) { /* a forcing jump at t: the next step's start */
        double vs = tr->Le * tr->wp, as = vs * tr->wp;
        memcpy(tr->pa, st->acc_right, (size_t)tr->n * sizeof(double));
        if (tr->demands && tr->dem_prev) {
            pd_demand_eval(tr->sc, st->v, st->acc_right, vs, as, tr->qad, tr->qVd);
            /* a_abs's right limit: the next interval's start, and a value it takes */
            held_from_acc(tr, st->t, +1, st->q, st->v, st->acc_right, !no_impulse(tr, st),
                          tr->hacc);
            for (int i = 0; i < tr->n; i++) {
                tr->qa[i] += tr->hacc[i] - tr->qh[i];
                tr->qh[i] = tr->hacc[i];
                tr->acc[i] = pd_max(tr->acc[i], fabs(tr->qa[i]));
            }
        }
    }
    return tr->fn ? sample(tr, st) : 0;
}

/* Event-driven, on_step: extremes between reports, impulses at events,
 * persistent-contact time. */
static int step_event(const pd_state *st, void *ctx)
{
    track *tr = ctx;
    if (tr->have_prev && st->has_acc)
        note_between(tr, st->t, st->q, st->v, st->acc);
    note_point(tr, st->t, st->q);
    note_approach(tr, st->q);
    int ev = held_from_acc(tr, st->t, -1, st->q, st->v, st->has_acc ? st->acc : NULL,
                           st->nactive > 0, tr->da);
    note_demand(tr, st->t, st->q, st->v, st->has_acc ? st->acc : NULL, tr->hacc, no_impulse(tr, st),
                ev);
    for (int a = 0; a < tr->model_m; a++) {
        double P = st->P[a];
        if (tr->pactive[a] && tr->have_prev)
            tr->ctime[a] += st->t - tr->pt;
        if (P > 0.0) {
            tr->impacts[a]++;
            tr->maxP[a] = pd_max(tr->maxP[a], P);
            if (isnan(tr->first[a]))
                tr->first[a] = st->t;
        }
    }
    keep_report(tr, st);
    return 0;
}

/* The element forces integrated since the last sample, by the trapezoid
 * rule over every point reported (accepted steps and samples, in time
 * order): samples alone would alias the elements' vibration. */
static void integrate_forces(track *tr, const pd_state *st)
{
    for (int a = 0; a < tr->model_m; a++) {
        double lam = st->active[a] ? st->P[a] : 0.0;
        tr->imp[a] += 0.5 * (tr->imp_lam[a] + lam) * (st->t - tr->imp_t);
        tr->imp_lam[a] = lam;
    }
    tr->imp_t = st->t;
}

/* Penalty, on_step: extremes between reports, engagements, the element
 * impulses by the trapezoid rule over the accepted steps. */
static int step_penalty(const pd_state *st, void *ctx)
{
    track *tr = ctx;
    if (tr->en) /* newmark's energy balance: the step from the last report */
        pd_scene_energy_note_forces(tr->en, st, tr->plam);
    integrate_forces(tr, st);
    note_springs(tr, st);
    if (tr->have_prev && st->has_acc)
        note_between(tr, st->t, st->q, st->v, st->acc);
    note_point(tr, st->t, st->q);
    note_approach(tr, st->q);
    /* the elements' forces are left out of a_abs (an element's force is its
     * impact's and its hold's at once); holds take the rigid held force */
    if (tr->demands)
        penalty_held(tr, st);
    note_demand(tr, st->t, tr->xdem, st->v, st->has_acc ? st->acc : NULL,
                tr->demands ? tr->hacc : NULL, no_element(tr, st), 0);
    for (int a = 0; a < tr->model_m; a++) {
        double dt = tr->have_prev ? st->t - tr->pt : 0.0;
        if (st->active[a])
            tr->fpeak[a] = pd_max(tr->fpeak[a], st->P[a]);
        double di = 0.5 * (tr->plam[a] + (st->active[a] ? st->P[a] : 0.0)) * dt;
        if (tr->pactive[a])
            tr->ctime[a] += dt;
        tr->episode[a] += tr->pactive[a] ? di : 0.0;
        tr->maxP[a] = pd_max(tr->maxP[a], tr->episode[a]);
        if (st->active[a] && !tr->pactive[a]) {
            tr->impacts[a]++;
            tr->episode[a] = 0.0;
            if (isnan(tr->first[a]))
                tr->first[a] = st->t;
        }
    }
    keep_report(tr, st);
    return 0;
}

/* The output grid (event-driven, penalty): impulses since the last sample
 * (event-general: the engine's P, its impacts plus its held forces
 * integrated; penalty: the element forces integrated here and by
 * step_penalty). */
static int observe_grid(const pd_state *st, void *ctx)
{
    track *tr = ctx;
    if (tr->method == PD_METHOD_PENALTY || tr->method == PD_METHOD_NEWMARK)
        integrate_forces(tr, st);
    else /* event-general: the engine's own, held forces included */
        memcpy(tr->imp, st->P, (size_t)tr->model_m * sizeof(double));
    tr->imp_t = st->t;
    return sample(tr, st);
}

/* Results in metres, seconds and newton-seconds. */
static void fill_result(const track *tr, pd_scene_result *r)
{
    double Ps = tr->sc->exc.ap / tr->wp;
    for (int i = 0; i < tr->n; i++) {
        r->umax[i] = tr->xmax[i] * tr->Le;
        r->u_pos[i] = tr->xpos[i] * tr->Le;
        r->u_neg[i] = tr->xneg[i] * tr->Le;
        r->drift[i] = tr->drift[i] * tr->Le;
        r->acc_max[i] = tr->demands ? tr->acc[i] : NAN;
        r->shear_max[i] = tr->demands ? tr->shear[i] : NAN;
    }
    for (int a = 0; a < tr->m; a++) {
        r->impacts[a] = tr->impacts[a];
        r->first_impact[a] = tr->first[a] / tr->wp;
        r->max_impulse[a] = tr->maxP[a] * Ps;
        r->contact_time[a] = tr->ctime[a] / tr->wp;
        r->approach[a] = tr->approach[a] * tr->Le;
        r->force_max[a] = tr->method == PD_METHOD_PENALTY || tr->method == PD_METHOD_NEWMARK
                              ? tr->fpeak[a] * tr->sc->exc.ap /* force unit: ap kg */
                              : NAN;
    }
    r->lcp_solves = tr->lcp_solves;
    for (int j = 0; j < tr->ns; j++) { /* the yielding storeys */
        int i = tr->spring_dof[j];
        r->ductility[i] = tr->drift[i] / tr->spring_uy[j];
        r->residual[i] = (1.0 - tr->spring_alpha[j]) * tr->up[j] * tr->Le;
        r->plastic_excursion[i] = tr->excursion[j] * tr->Le;
        r->n_yield[i] = tr->onsets[j];
    }
}

/* ---- the one-wall oscillator: its fast paths ------------------------------- */

/* The oscillator's samples as scene samples (x = -u when mirrored). */
typedef struct osc_bridge {
    pd_scene_sampler fn;
    void *ctx;
    double sign, mass;
    int m;
} osc_bridge;

static int osc_sample(const pd_osc_sample *s, void *ctx)
{
    osc_bridge *b = ctx;
    double x = b->sign * s->u, v = b->sign * s->v, imp = s->impulse * b->mass;
    pd_scene_sample ss = {.step = s->step,
                          .t = s->t,
                          .x = &x,
                          .v = &v,
                          .gap = b->m ? &s->gap : NULL,
                          .impulse = b->m ? &imp : NULL,
                          .impacts = b->m ? &s->impacts : NULL};
    return b->fn(&ss, b->ctx);
}

/* Run the one-wall scene as the oscillator c. */
static int run_oscillator(const pd_scene *sc, const pd_osc *c, int mirrored, const pd_run_opts *o,
                          pd_scene_sampler fn, void *ctx, pd_scene_result *res, pd_err *err)
{
    pd_run_opts oo = *o;
    pd_osc_result r;
    double mass = sc->st[0].mass[0];
    int has_wall = sc->ncontact > 0 && !o->no_wall, rc;
    osc_bridge b = {
        .fn = fn, .ctx = ctx, .sign = mirrored ? -1.0 : 1.0, .mass = mass, .m = sc->ncontact};
    oo.no_wall = !has_wall;
    oo.pen.kc_abs = o->pen.kc_abs / mass; /* N/m -> N/m per kg */
    if ((rc = pd_osc_run(c, &oo, fn ? osc_sample : NULL, &b, &r, err)))
        return rc;
    res->umax[0] = res->drift[0] = r.umax;
    res->acc_max[0] = r.acc_max;
    res->shear_max[0] = r.shear_max * mass;
    res->u_pos[0] = mirrored ? r.u_away : r.u_toward;
    res->u_neg[0] = mirrored ? r.u_toward : r.u_away;
    if (sc->ncontact > 0) {
        res->impacts[0] = r.impacts;
        res->first_impact[0] = r.first_impact;
        res->max_impulse[0] = r.max_impulse * mass;
        res->contact_time[0] = r.contact_time;
        res->approach[0] = r.u_toward;
        res->force_max[0] = r.force_max * mass;
    }
    res->steps = r.steps;
    res->accumulations = r.accumulations;
    res->close_tol = NAN; /* one contact: nothing is simultaneous */
    res->lcp_solves = 0;
    res->kernel = r.kernel;
    res->factor = o->method == PD_METHOD_MOREAU ? "scalar" : "none";
    res->lcp_solver = o->method == PD_METHOD_MOREAU && has_wall ? "closed-form" : "none";
    if (o->rtol > 0.0) { /* to a tolerance: the oscillator's figures */
        res->err_est[0] = res->err_est_max = r.err_est;
        res->rtol_met = r.rtol_met;
        res->steps_rejected = r.steps_rejected;
        res->dt = r.dt;
        res->dt_min = r.dt_min;
        res->dt_max = r.dt_max;
        res->factor = "blocks"; /* as the scenes' runs to a tolerance */
    }
    return PD_OK;
}

/* ---- the general engines -------------------------------------------------- */

/* The holds' contact-force LCP solver (demands measured, contacts in the
 * model), once per run. */
static int held_solver(track *tr, const pd_model *md, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    if (tr->demands && md->m > 0 && !tr->hlcp &&
        !(tr->hlcp =
              pd_lcp_solver_alloc(PD_LCP_LEMKE, md->m < MJ_HELD_LCP ? md->m : MJ_HELD_LCP, 0, err)))
        return err->status;
    return PD_OK;
}

/* Moreau–Jean on the scene's model. */
static int run_moreau(const pd_model *md, const pd_run_opts *o, long nsteps, track *tr,
                      pd_scene_result *res, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    pd_mj_opts mo = pd_run_mj_opts(o, tr->h);
    int rc0 = held_solver(tr, md, err);
    if (rc0)
        return rc0;
    pd_mj *mj = pd_mj_alloc(md, &mo, err);
    if (!mj)
        return err->status;
    /* a yielding scene's energy balance, summed step by step */
    if (md->ns > 0 && !(tr->en = pd_scene_energy_alloc(md, tr->h, o->theta))) {
        pd_mj_free(mj);
        return pd_err_set(err, PD_ENOMEM, "out of memory for the energy balance");
    }
    int rc = pd_mj_run(mj, nsteps, observe_moreau, tr, err);
    res->steps = pd_mj_state(mj)->step;
    res->kernel = pd_mj_kernel_name(mj);
    res->factor = pd_mj_factor_name(mj);
    res->lcp_solver = pd_lcp_method_name(o->lcp_solver);
    if (tr->en) /* in joules: kg (Le wp)^2 */
        pd_scene_energy_finish(tr->en, (tr->Le * tr->wp) * (tr->Le * tr->wp), &res->energy);
    pd_scene_energy_free(tr->en);
    tr->en = NULL;
    pd_mj_free(mj);
    return rc;
}

/* The largest change of a_abs (shear: 0) or V (shear: 1) of floor k of
 * structure st [SI] for state errors |dx| <= E, |dv| <= w E on its floors
 * (Pi units; us, vs their SI scales): the storey forces S = k (d + beta d')
 * and the mass-proportional damping (demand.c's formulas, in bounds). */
static double demand_bound(const pd_structure *st, int k, double E, double w, double us, double vs,
                           int shear)
{
    double dd = 2.0 * E * us, ddv = 2.0 * w * E * vs, mv = st->alpha * w * E * vs;
    double Sk = st->stiffness[k] * (dd + st->beta * ddv);
    if (shear) {
        double damp = 0.0;
        for (int i = k; i < st->storeys; i++)
            damp += st->mass[i] * mv;
        return Sk + damp;
    }
    double Sup = k + 1 < st->storeys ? st->stiffness[k + 1] * (dd + st->beta * ddv) : 0.0;
    return (Sk + Sup + st->mass[k] * mv) / st->mass[k];
}

/* Each structure's estimate into err_est (nstruct): its peaks' (umax,
 * drift and, with demands, a_abs and V per storey) largest relative error;
 * returns the largest over the structures. */
static double structure_errors(const track *tr, int demands, double *err_est)
{
    const pd_scene *sc = tr->sc;
    double us = tr->Le, vs = tr->Le * tr->wp, most = 0.0;
    for (int s = 0; s < sc->nstruct; s++) {
        const pd_structure *st = &sc->st[s];
        double e = 0.0, w = 0.0;
        for (int k = 0; k < st->storeys; k++)
            w = pd_max(w, tr->wdof[st->dof + k]);
        for (int k = 0; k < st->storeys; k++) {
            int i = st->dof + k;
            if (tr->xmax[i] > 0.0)
                e = pd_max(e, tr->errx[i] / tr->xmax[i]);
            if (tr->drift[i] > 0.0)
                e = pd_max(e, tr->errd[i] / tr->drift[i]);
            if (demands && tr->acc[i] > 0.0)
                e = pd_max(e, demand_bound(st, k, tr->erra[i], w, us, vs, 0) / tr->acc[i]);
            if (demands && tr->shear[i] > 0.0)
                e = pd_max(e, demand_bound(st, k, tr->errv[i], w, us, vs, 1) / tr->shear[i]);
        }
        err_est[s] = e;
        most = pd_max(most, e);
    }
    return most;
}

/* The coarsest step of a run to a tolerance [tau]: the shortest of the
 * pulse's and the structures' fundamental periods over 16. */
#define SCENE_ADAPT_H0 16.0
#define SCENE_ADAPT_TRIES 3
#define SCENE_ADAPT_LOOSE 4.0  /* the second pass: a tolerance this many times looser */
#define SCENE_ADAPT_FLOOR 1e-3 /* errors below this share of a dof's static scale count as none */
/* a tighter run whose displacements are within rtol must bring the
 * estimate below this share of the last one's, or no other is tried */
#define SCENE_ADAPT_STALL 0.5

/* One run to the tolerance rtol, measured into tr; stats of the engine. */
static int adapt_once(const pd_scene_model *sm, const pd_run_opts *o, double rtol,
                      const pd_piecewise_force *F, const double *atol, double tau_end, track *tr,
                      pd_scene_result *res, pd_mj_stats *stats, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    const pd_scene *sc = tr->sc;
    double T = sc->exc.Tp;
    for (int k = 0; k < sc->nstruct; k++)
        T = fmin(T, sc->st[k].T0);
    pd_mj_opts mo = pd_run_mj_opts(o, tr->wp * T / SCENE_ADAPT_H0);
    mo.rtol = rtol;
    mo.atol_dof = atol;
    mo.sim_gap = o->close_tol;              /* the reference's scale of simultaneity, in Le */
    mo.pieces = o->theta == 0.5 ? F : NULL; /* exact flights; theta flights for another theta */
    track_clear(tr);
    pd_mj *mj = pd_mj_alloc(&sm->model, &mo, err);
    if (!mj)
        return err->status;
    int rc = pd_mj_run_until(mj, tau_end, observe_adapt, tr, err);
    pd_mj_get_stats(mj, stats);
    res->steps = stats->steps;
    res->steps_rejected = stats->rejected;
    res->dt = stats->h0 / tr->wp;
    res->dt_min = stats->h_min / tr->wp;
    res->dt_max = stats->h_max / tr->wp;
    res->kernel = mo.pieces ? "exact-flight" : pd_mj_kernel_name(mj);
    res->factor = mo.pieces ? "blocks" : pd_mj_factor_name(mj);
    res->lcp_solver = pd_lcp_method_name(o->lcp_solver);
    pd_mj_free(mj);
    res->err_est_max = structure_errors(tr, tr->demands, res->err_est);
    return rc;
}

/* The peaks of a run (umax, drift, a_abs, V per dof) into buf (4 n). */
static void keep_peaks(const track *tr, double *buf)
{
    size_t n = (size_t)tr->n * sizeof(double);
    memcpy(buf, tr->xmax, n);
    memcpy(buf + tr->n, tr->drift, n);
    memcpy(buf + 2 * tr->n, tr->acc, n);
    memcpy(buf + 3 * tr->n, tr->shear, n);
}

/* The second pass's estimate: the run's peaks p against those of a run
 * SCENE_ADAPT_LOOSE = c times looser, p_c: the errors scale with the
 * tolerance (p_c - p* ~ c (p - p*)), so p - p* ~ |p - p_c| / (c - 1); it
 * sees what the local estimates cannot, errors carried and amplified from
 * structure to structure (docs/scheme.md).  Each structure's estimate in
 * err_est (its local one there) becomes the larger of the two (peaks
 * umax, drift and, with demands, a_abs and V); returns the largest. */
static double second_pass(const track *tr, const double *loose, int demands, double *err_est)
{
    const pd_scene *sc = tr->sc;
    const double *cur[4] = {tr->xmax, tr->drift, tr->acc, tr->shear};
    int kinds = demands ? 4 : 2;
    double most = 0.0;
    for (int s = 0; s < sc->nstruct; s++) {
        double e = err_est[s];
        for (int k = 0; k < sc->st[s].storeys; k++) {
            int i = sc->st[s].dof + k;
            for (int q = 0; q < kinds; q++)
                if (cur[q][i] > 0.0)
                    e = pd_max(e, fabs(cur[q][i] - loose[q * tr->n + i]) /
                                      ((SCENE_ADAPT_LOOSE - 1.0) * cur[q][i]));
        }
        err_est[s] = e;
        most = pd_max(most, e);
    }
    return most;
}

/* Moreau–Jean to a tolerance on the scene's model: with two contacts or
 * more a second pass first, SCENE_ADAPT_LOOSE times looser; then runs at
 * rtol, repeated SCENE_ADAPT_LOOSE times tighter while the estimate exceeds
 * rtol (the run before is the next one's second pass; at most
 * SCENE_ADAPT_TRIES) and falls with the tolerance (a tighter run that
 * leaves the displacements' part within rtol and the estimate above
 * SCENE_ADAPT_STALL of the last: the demands' peaks do not converge with
 * the tolerance, and no other run is tried); the figures
 * the last run's, the steps all runs'; a sampler sees the last run,
 * repeated for it (the same numbers). */
static int run_moreau_adapt(const pd_scene_model *sm, const pd_run_opts *o, double tau_end,
                            track *tr, pd_scene_result *res, pd_err *err)
{
    const pd_scene *sc = tr->sc;
    pd_sine_piece *pieces;
    int npieces, rc, runs = 0, n = tr->n;
    if ((rc = pd_osc_pieces(&sm->shape, &pieces, &npieces, err)))
        return rc;
    /* atol (n), the last run's peaks (4 n), the displacements' estimates (nstruct) */
    double *atol = malloc(((size_t)n * 5 + (size_t)sc->nstruct) * sizeof(double)),
           *loose = atol + n, *sest = loose + 4 * (size_t)n;
    if (!atol) {
        free(pieces);
        return pd_err_set(err, PD_ENOMEM, "out of memory for the tolerances of %d dofs", n);
    }
    /* a dof's error is measured absolutely below a thousandth of its static
     * scale, the deflection under ap: (T0 / Tp)^2 Le, or Le */
    for (int k = 0; k < sc->nstruct; k++)
        for (int j = 0; j < sc->st[k].storeys; j++) {
            double r = sc->st[k].T0 / sc->exc.Tp;
            atol[sc->st[k].dof + j] = SCENE_ADAPT_FLOOR * fmin(1.0, r * r);
        }
    for (int i = 0; i < n; i++) {
        double kk = pd_matrix_get(&sm->model.K, i, i), mm = pd_matrix_get(&sm->model.M, i, i);
        tr->wdof[i] = kk > 0.0 && mm > 0.0 ? sqrt(kk / mm) : 0.0;
    }
    pd_piecewise_force F = {.b = sm->mass, .pieces = pieces, .npieces = npieces};
    pd_scene_sampler fn = tr->fn;
    pd_mj_stats st;
    double rtol = o->rtol, est_last = HUGE_VAL;
    long steps = 0, rejected = 0;
    /* contacts that share structures carry errors into each other and can
     * amplify them: the second pass, a run SCENE_ADAPT_LOOSE times looser */
    int second = sc->ncontact >= 2;
    tr->fn = NULL;
    if (second) {
        rc = adapt_once(sm, o, fmin(SCENE_ADAPT_LOOSE * rtol, 0.5), &F, atol, tau_end, tr, res, &st,
                        err);
        steps += res->steps;
        rejected += res->steps_rejected;
        keep_peaks(tr, loose);
    }
    while (!rc) {
        rc = adapt_once(sm, o, rtol, &F, atol, tau_end, tr, res, &st, err);
        runs++;
        steps += res->steps;
        rejected += res->steps_rejected;
        /* the displacements' part of the estimate (umax, drift) */
        double disp = structure_errors(tr, 0, sest);
        if (second && !rc) {
            res->err_est_max = second_pass(tr, loose, tr->demands, res->err_est);
            disp = second_pass(tr, loose, 0, sest);
        }
        /* a tighter run that leaves the displacements within rtol and the
         * estimate above SCENE_ADAPT_STALL of the last: the demands' peaks
         * do not follow the tolerance, and no other run is tried */
        int stall = disp <= o->rtol && res->err_est_max > SCENE_ADAPT_STALL * est_last;
        if (rc || st.budget_hit || res->err_est_max <= o->rtol || runs >= SCENE_ADAPT_TRIES ||
            rtol / SCENE_ADAPT_LOOSE < PD_RTOL_MIN || stall)
            break;
        est_last = res->err_est_max;
        /* again at a tighter tolerance: this run is the next one's looser pass */
        keep_peaks(tr, loose);
        rtol /= SCENE_ADAPT_LOOSE;
    }
    if (!rc && fn) { /* the run kept, again for the sampler (the same numbers) */
        double est_max = res->err_est_max;
        tr->fn = fn;
        for (int k = 0; k < sc->nstruct; k++)
            loose[k] = res->err_est[k];
        rc = adapt_once(sm, o, rtol, &F, atol, tau_end, tr, res, &st, err);
        for (int k = 0; k < sc->nstruct; k++) /* the estimates the second pass gave */
            res->err_est[k] = pd_max(res->err_est[k], loose[k]);
        res->err_est_max = pd_max(res->err_est_max, est_max);
        steps += res->steps;
        rejected += res->steps_rejected;
    }
    tr->fn = fn;
    res->steps = steps;
    res->steps_rejected = rejected;
    res->rtol = o->rtol;
    res->rtol_met = !rc && !st.floor_hit && !st.budget_hit && res->err_est_max <= o->rtol;
    free(atol);
    free(pieces);
    return rc;
}

/* The row reference's samples: impulses since the last sample come with
 * the state (the impacts' and the held contacts' force integrals, so P > 0
 * does not mean an impact: the demands' cubic is kept to grid intervals
 * without an impact, which on_edr_event flags). */
static int observe_edr(const pd_state *st, void *ctx)
{
    track *tr = ctx;
    int smooth = !tr->edr_hit;
    tr->edr_hit = 0;
    int held = 0;
    for (int a = 0; a < tr->model_m; a++)
        held |= st->active[a];
    int ev = held_from_acc(tr, st->t, -1, st->q, st->v, st->has_acc ? st->acc : NULL, held, tr->da);
    note_demand(tr, st->t, st->q, st->v, st->has_acc ? st->acc : NULL, tr->hacc, smooth, ev);
    if (!tr->fn)
        return 0;
    for (int a = 0; a < tr->model_m; a++) {
        tr->imp[a] += st->P[a];
        tr->impacts[a] = tr->live_impacts[a];
    }
    return sample(tr, st);
}

/* The row reference's demand grid: the largest whole multiple of the step
 * with DEMAND_GRID points per shortest period (of the structures' highest
 * modes and the pulse), in tau. */
static double demand_grid(const track *tr)
{
    double T = tr->sc->exc.Tp;
    for (int s = 0; s < tr->sc->nstruct; s++)
        T = fmin(T, tr->sc->st[s].Tmin);
    double k = floor(tr->wp * T / (DEMAND_GRID * tr->h));
    return k > 1.0 ? k * tr->h : tr->h;
}

/* The exact event-driven reference for rows (pd_edr) on the scene's model:
 * its exact extremes, impacts and gaps replace the tracker's. */
static int run_event(const pd_scene_model *sm, const pd_run_opts *o, double tau_end, track *tr,
                     pd_scene_result *res, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    pd_edr_opts eo = pd_edr_default_opts();
    pd_sine_piece *pieces;
    int npieces, rc;
    if ((rc = pd_osc_pieces(&sm->shape, &pieces, &npieces, err)))
        return rc;
    pd_piecewise_force F = {.b = sm->mass, .pieces = pieces, .npieces = npieces};
    eo.close_tol = o->close_tol;
    eo.time_unit = 1.0 / tr->wp;
    eo.t_measure = tr->tau_measure;
    /* the grid: samples every dt; else the demands' states */
    eo.h_out = tr->fn ? tr->h : tr->demands ? demand_grid(tr) : 0.0;
    eo.impacts_only = !tr->fn; /* the demands' grid needs no impulses */
    eo.on_event = tr->demands ? on_edr_event : NULL;
    eo.on_event_ctx = tr;
    eo.below = tr->below;
    eo.no_accumulation = o->no_accumulation;
    eo.inactive = o->no_wall;
    eo.lcp_solver = o->lcp_solver;
    eo.impact_law = o->impact_law;
    /* a yielding scene's energy balance, as Moreau-Jean's (not a twin's or a sweep's) */
    eo.energy = sm->model.ns > 0 && !o->no_demands;
    pd_edr *edr = pd_edr_alloc(&sm->model, &F, &eo, err);
    if (!edr) {
        free(pieces);
        return err->status;
    }
    tr->live_impacts = pd_edr_result_of(edr)->contact_impacts;
    rc = pd_edr_run(edr, 0.0, NULL, NULL, tau_end, eo.h_out > 0.0 ? observe_edr : NULL, tr, err);
    if (err && (rc == PD_ENUMERICAL || rc == PD_ESINGULAR)) { /* a cluster without modes */
        char why[sizeof err->msg];
        snprintf(why, sizeof why, "%s", err->msg);
        pd_err_set(err, rc, "%s; --method event-general integrates such clusters numerically", why);
    }
    const pd_edr_result *er = pd_edr_result_of(edr);
    for (int i = 0; i < tr->n; i++) {
        tr->xpos[i] = er->xpos[i];
        tr->xneg[i] = er->xneg[i];
        tr->xmax[i] = pd_max(er->xpos[i], er->xneg[i]);
        tr->drift[i] = er->drift[i];
    }
    for (int a = 0; a < tr->m; a++) {
        tr->impacts[a] = er->contact_impacts[a];
        tr->first[a] = er->first[a];
        tr->maxP[a] = er->max_impulse[a];
        tr->ctime[a] = er->contact_time[a];
        tr->approach[a] = sm->g0[a] - er->min_gap[a];
    }
    for (int j = 0; j < tr->ns && j < er->ns; j++) { /* the springs' exact offsets and slides */
        tr->up[j] = er->up[j];
        tr->excursion[j] = er->plastic_excursion[j];
        tr->onsets[j] = er->yield_onsets[j];
    }
    if (eo.energy) /* in joules: kg (Le wp)^2 */
        pd_scene_energy_of_edr(er, (tr->Le * tr->wp) * (tr->Le * tr->wp), &res->energy);
    tr->lcp_solves = er->lcp_solves;
    res->steps = er->events;
    res->simultaneous = er->simultaneous;
    res->tol_closed = er->tol_closed;
    res->accumulations = er->accumulations;
    res->close_tol = o->close_tol;
    res->impact_law = pd_impact_law_name(o->impact_law);
    res->law_decided = er->law_decided;
    res->kernel = "event-rows";
    res->factor = "none";
    res->lcp_solver = pd_lcp_method_name(o->lcp_solver);
    pd_edr_free(edr);
    free(pieces);
    return rc;
}

/* The general event-driven reference (pd_edg_run, GSL between events) on
 * the scene's model. */
static int run_event_general(const pd_model *md, const pd_run_opts *o, double tau_end, track *tr,
                             pd_scene_result *res, pd_err *err)
{
    pd_edg_opts eo = pd_edg_default_opts();
    pd_edg_result er;
    eo.h_out = tr->fn ? tr->h : 0.0;
    eo.no_accumulation = o->no_accumulation;
    eo.on_step = step_event;
    eo.time_unit = 1.0 / tr->wp;
    eo.on_step_ctx = tr;
    eo.factor = o->factor;
    eo.lcp_solver = o->lcp_solver;
    int rc =
        pd_edg_run(md, 0.0, NULL, NULL, tau_end, &eo, tr->fn ? observe_grid : NULL, tr, &er, err);
    res->steps = er.events;
    res->accumulations = er.accumulations;
    res->kernel = "event-general";
    res->factor = pd_factor_kind_name(pd_factor_choose(md, o->factor));
    res->lcp_solver = pd_lcp_method_name(o->lcp_solver);
    return rc;
}

/* The penalty baseline on the scene's model: kc in reference units is
 * kc_abs / wp^2 (Kelvin) or kc_abs sqrt(Le) / wp^2 (Hertz), or kc_mult times
 * the largest storey stiffness / wp^2 for both laws. */
static int run_penalty(const pd_model *md, const pd_run_opts *o, double tau_end, track *tr,
                       pd_scene_result *res, pd_err *err)
{
    pd_penalty_opts po = pd_penalty_default_opts();
    pd_penalty_result pr;
    double wp2 = tr->wp * tr->wp;
    po.law = o->pen.law;
    if (o->pen.kc_abs > 0.0)
        po.kc = o->pen.kc_abs * (o->pen.law == PD_PENALTY_HERTZDAMP ? sqrt(tr->Le) : 1.0) / wp2;
    else
        po.kc = pd_scene_penalty_kc(tr->sc, o) / wp2;
    po.rtol = o->pen.rtol;
    po.atol = o->pen.atol;
    po.stepper = o->method == PD_METHOD_NEWMARK ? "newmark" : o->pen.stepper;
    /* stepper newmark: the grid's step, or a whole fraction of it for
     * PD_NEWMARK_STEPS_PER_CONTACT steps per period of the stiffest element */
    po.h = md->m ? pd_newmark_step(tr->h, tr->wp * pd_scene_contact_period_min(tr->sc, o)) : tr->h;
    po.h_out = tr->fn ? tr->h : 0.0;
    po.time_unit = 1.0 / tr->wp;
    po.on_step = step_penalty;
    po.on_step_ctx = tr;
    po.factor = o->factor;
    int rc = pd_newmark_budget(&po, tr->h, tau_end, err);
    if (!rc)
        rc = held_solver(tr, md, err);
    if (rc)
        return rc;
    /* a yielding scene by newmark: its energy balance, step by step (the
     * adaptive penalty's steppers have no such identity) */
    if (md->ns > 0 && o->method == PD_METHOD_NEWMARK &&
        !(tr->en = pd_scene_energy_alloc(md, po.h, 0.5)))
        return pd_err_set(err, PD_ENOMEM, "out of memory for the energy balance");
    rc = pd_penalty_run(md, 0.0, NULL, NULL, tau_end, &po, tr->fn ? observe_grid : NULL, tr, &pr,
                        err);
    if (tr->en) /* in joules: kg (Le wp)^2 */
        pd_scene_energy_finish(tr->en, (tr->Le * tr->wp) * (tr->Le * tr->wp), &res->energy);
    pd_scene_energy_free(tr->en);
    tr->en = NULL;
    res->steps = pr.steps;
    res->kernel = pr.stepper ? pr.stepper : "penalty";
    res->factor =
        pr.diagonal_mass ? "diagonal" : pd_factor_kind_name(pd_factor_choose(md, o->factor));
    res->lcp_solver = "none";
    return rc;
}

/* Build the model, track, run the method, convert. */
/* The run of o through the general model; *sample_s gets the time spent in
 * sample() (the run's cost leaves it out). */
static int run_general(const pd_scene *sc, const pd_run_opts *o, pd_scene_sampler fn, void *ctx,
                       pd_scene_result *res, double *sample_s, pd_err *err)
{
    pd_scene_model sm;
    track tr;
    int rc;
    memset(&tr, 0, sizeof tr);
    /* the row reference measures the gaps of a free twin's contacts itself */
    if ((rc = pd_scene_model_build(sc, !o->no_wall || o->method == PD_METHOD_EVENT, &sm, err)))
        return rc;
    if ((rc = track_alloc(&tr, sc, err))) { /* it freed what it took */
        pd_scene_model_free(&sm);
        return rc;
    }
    if ((rc = track_springs(&tr, &sm, err))) {
        track_free(&tr);
        pd_scene_model_free(&sm);
        return rc;
    }
    tr.method = o->method;
    tr.model_m = sm.model.m;
    tr.Le = pd_scene_Le(sc);
    tr.wp = pd_scene_wp(sc);
    tr.h = tr.wp * o->dt;
    tr.tau_measure = tr.wp * pd_scene_measure_start(sc, o->tend);
    tr.fn = fn;
    tr.ctx = ctx;
    tr.demands = !o->no_demands;
    tr.shape = &sm.shape;
    tr.mass = sm.mass;
    long nsteps = o->rtol > 0.0 ? 0 : pd_steps_for(o->tend, o->dt);
    double tau_end = o->rtol > 0.0 ? tr.wp * o->tend : (double)nsteps * tr.h;
    tr.progress = o->progress;
    tr.progress_ctx = o->progress_ctx;
    tr.prog_step = tau_end / 100.0;
    tr.prog_next = tr.prog_step;
    switch (o->method) {
    case PD_METHOD_EVENT:
        rc = run_event(&sm, o, tau_end, &tr, res, err);
        break;
    case PD_METHOD_EVENT_GENERAL:
        rc = run_event_general(&sm.model, o, tau_end, &tr, res, err);
        break;
    case PD_METHOD_PENALTY:
    case PD_METHOD_NEWMARK:
        rc = run_penalty(&sm.model, o, tau_end, &tr, res, err);
        break;
    case PD_METHOD_MOREAU:
        rc = o->rtol > 0.0 ? run_moreau_adapt(&sm, o, tau_end, &tr, res, err)
                           : run_moreau(&sm.model, o, nsteps, &tr, res, err);
        break;
    default: /* resolved opts name one of the above: never silently another */
        rc = pd_err_set(err, PD_EINVAL, "method: %d is no method", (int)o->method);
        break;
    }
    fill_result(&tr, res);
    *sample_s = tr.sample_s;
    track_free(&tr);
    pd_scene_model_free(&sm);
    return rc;
}

/* The event-driven references' impact LCPs resolve two bodies that touch
 * while their masses differ by less than this: beyond, 1/m_light + 1/m_heavy
 * rounds to 1/m_light and the Delassus matrix of a light body squeezed
 * between a heavy one and a wall is singular in double precision. */
#define SCENE_EVENT_MASS_RATIO 1e15

/* Contacts between masses beyond SCENE_EVENT_MASS_RATIO, refused up front
 * for the event-driven references (Moreau-Jean runs them). */
static int event_mass_ratio(const pd_scene *sc, const pd_run_opts *o, pd_err *err)
{
    if ((o->method != PD_METHOD_EVENT && o->method != PD_METHOD_EVENT_GENERAL) || o->no_wall)
        return PD_OK;
    for (int a = 0; a < sc->ncontact; a++) {
        const pd_contact *ct = &sc->ct[a];
        if (ct->a == PD_WALL || ct->b == PD_WALL)
            continue;
        double ma = sc->st[ct->a].mass[ct->level_a - 1], mb = sc->st[ct->b].mass[ct->level_b - 1];
        double ratio = fmax(ma, mb) / fmin(ma, mb);
        if (!(ratio <= SCENE_EVENT_MASS_RATIO))
            return pd_err_set(err, PD_EINVAL,
                              "mass: %s and %s touch with masses %g and %g kg, "
                              "a ratio of %.3g: beyond %g the event-driven references' impact "
                              "LCPs are singular in double precision (--method moreau runs it)",
                              sc->st[ct->a].name, sc->st[ct->b].name, ma, mb, ratio,
                              SCENE_EVENT_MASS_RATIO);
    }
    return PD_OK;
}

/* law_band_s = max_k |umax'_k - umax_k| / max_k umax_k over structure s's
 * storeys, umax' the peaks of the run again under the other impact law
 * (o resolved, res the run's); inf when that run fails (a budget: the run
 * itself stands), PD_ENOMEM returned. */
static int scene_law_band(const pd_scene *sc, const pd_run_opts *o, pd_scene_result *res,
                          pd_err *err)
{
    pd_run_opts other = *o;
    pd_scene_result alt;
    int rc;
    other.impact_law = o->impact_law == PD_IMPACT_SINGLE ? PD_IMPACT_STAGED : PD_IMPACT_SINGLE;
    other.no_law_band = 1;
    other.no_demands = 1; /* its figure is umax */
    other.on_lcp = NULL;
    if ((rc = pd_scene_result_alloc(sc, &alt, err)))
        return rc;
    if ((rc = pd_scene_run(sc, &other, NULL, NULL, &alt, err))) {
        pd_scene_result_free(&alt);
        if (rc == PD_ENOMEM)
            return rc;
        pd_err_clear(err);
        res->law_band_max = INFINITY;
        for (int s = 0; s < sc->nstruct; s++)
            res->law_band[s] = INFINITY;
        return PD_OK;
    }
    res->law_band_max = 0.0;
    for (int s = 0; s < sc->nstruct; s++) {
        double top = 0.0, moved = 0.0;
        for (int k = 0; k < sc->st[s].storeys; k++) {
            int i = sc->st[s].dof + k;
            top = fmax(top, res->umax[i]);
            moved = fmax(moved, fabs(alt.umax[i] - res->umax[i]));
        }
        res->law_band[s] = top > 0.0 ? moved / top : moved > 0.0 ? INFINITY : 0.0;
        res->law_band_max = fmax(res->law_band_max, res->law_band[s]);
    }
    pd_scene_result_free(&alt);
    return PD_OK;
}

int pd_scene_run(const pd_scene *sc, const pd_run_opts *opts, pd_scene_sampler sampler, void *ctx,
                 pd_scene_result *res, pd_err *err)
{
    pd_run_opts o;
    pd_osc c;
    int mirrored, rc;
    pd_err_clear(err);
    if (!sc || !res)
        return PD_NULL_ARG(err, !sc ? "sc" : "res");
    if (!sc->finished)
        return pd_err_set(err, PD_EINVAL, "scene: not finished (pd_scene_finish)");
    if (!pd_scene_result_fits(sc, res))
        return pd_err_set(err, PD_EINVAL,
                          "the result is not allocated for this scene "
                          "(pd_scene_result_alloc)");
    if ((rc = pd_scene_resolve_opts(sc, opts, &o, err)) || (rc = event_mass_ratio(sc, &o, err)))
        return rc;
    int springs = pd_scene_springs(sc);
    if (springs > 0 && !(o.method == PD_METHOD_MOREAU && o.rtol == 0.0) &&
        o.method != PD_METHOD_NEWMARK && o.method != PD_METHOD_EVENT)
        return pd_err_set(err, PD_EINVAL,
                          "uy: a yielding scene (%d yielding storeys) runs by Moreau-Jean at "
                          "fixed steps (method moreau, dt), by newmark, or (SDOF structures) "
                          "by event; %s%s models no yielding storey yet",
                          springs, pd_method_name(o.method), o.rtol > 0.0 ? " to a tolerance" : "");
    for (int i = 0; i < res->n; i++) {
        res->umax[i] = res->u_pos[i] = res->u_neg[i] = res->drift[i] = res->acc_max[i] =
            res->shear_max[i] = res->drift_ratio[i] = 0.0;
        res->ductility[i] = res->residual[i] = res->plastic_excursion[i] = NAN;
        res->n_yield[i] = 0;
    }
    for (int a = 0; a < res->m; a++) {
        res->impacts[a] = 0;
        res->first_impact[a] = res->force_max[a] = NAN;
        res->max_impulse[a] = res->contact_time[a] = res->approach[a] = res->force_equiv[a] = 0.0;
    }
    res->dt = o.dt;
    res->tend = o.tend;
    res->theta = o.method == PD_METHOD_MOREAU ? o.theta : NAN;
    res->rtol = o.rtol;
    res->err_est_max = NAN;
    for (int s = 0; s < res->nstruct; s++)
        res->err_est[s] = NAN;
    res->rtol_met = 1;
    res->steps_rejected = 0;
    res->dt_min = res->dt_max = o.method == PD_METHOD_MOREAU ? o.dt : NAN;
    res->method = pd_method_name(o.method);
    res->simultaneous = res->tol_closed = res->accumulations = 0;
    res->close_tol = o.method == PD_METHOD_EVENT ? o.close_tol : NAN;
    res->impact_law = NULL;
    res->law_decided = 0;
    res->law_band_max = NAN;
    for (int s = 0; s < res->nstruct; s++)
        res->law_band[s] = NAN;
    res->energy = pd_energy_none();
    double cpu0 = pd_cpu_seconds(), wall0 = pd_wall_seconds(), sample_s = 0.0;
    if (o.kernel == PD_KERNEL_AUTO && o.method != PD_METHOD_EVENT_GENERAL && springs == 0 &&
        pd_scene_as_oscillator(sc, &c, &mirrored))
        rc = run_oscillator(sc, &c, mirrored, &o, sampler, ctx, res, err);
    else
        rc = run_general(sc, &o, sampler, ctx, res, &sample_s, err);
    /* the sampler's share of the run's wall time left out of its CPU time
     * (a CPU clock read costs 0.7 us, a wall clock's 20 ns; under load the
     * share, not the wall seconds, carries over) */
    double cpu = pd_cpu_seconds() - cpu0, wall = pd_wall_seconds() - wall0;
    res->cpu_s = wall > 0.0 ? cpu * (1.0 - fmin(sample_s / wall, 1.0)) : cpu;
    res->contact_duration = pd_demand_td(&o);
    for (int s = 0; s < sc->nstruct; s++)
        for (int k = 0; k < sc->st[s].storeys; k++)
            res->drift_ratio[sc->st[s].dof + k] =
                res->drift[sc->st[s].dof + k] / sc->st[s].height[k];
    for (int a = 0; a < res->m; a++)
        res->force_equiv[a] = pd_equivalent_force(res->max_impulse[a], res->contact_duration);
    for (int s = 0; s < sc->nstruct && !rc; s++)
        for (int k = 0; k < sc->st[s].storeys && !rc; k++)
            rc = pd_demand_check_drift(res->drift[sc->st[s].dof + k],
                                       res->drift_ratio[sc->st[s].dof + k], sc->st[s].name, k + 1,
                                       err);
    for (int a = 0; a < res->m && !rc; a++)
        rc = pd_demand_check_force(res->max_impulse[a], res->force_equiv[a], a, err);
    if (!rc && o.method == PD_METHOD_EVENT && res->law_decided > 0 && !o.no_law_band)
        rc = scene_law_band(sc, &o, res, err);
    return rc;
}

/* ---- the run, its contact-free twin, and the Pi terms --------------------- */

void pd_scene_summary_free(pd_scene_summary *s)
{
    if (!s)
        return;
    pd_scene_result_free(&s->r);
    pd_scene_result_free(&s->free);
    free(s->Pi1);
    free(s->gamma);
    free(s->Pi2);
    free(s->Pi3);
    free(s->chi);
    free(s->err_est_structure);
    free(s->required_gap);
    free(s->rule_abs);
    free(s->rule_srss);
    free(s->rule_ddc);
    memset(s, 0, sizeof *s);
}

int pd_scene_summarize(const pd_scene *sc, const pd_run_opts *opts, pd_scene_sampler sampler,
                       void *ctx, pd_scene_summary *s, pd_err *err)
{
    pd_run_opts twin = opts ? *opts : pd_run_default_opts();
    if (!sc || !s)
        return PD_NULL_ARG(err, !sc ? "sc" : "s");
    if (!sc->finished)
        return pd_err_set(err, PD_EINVAL, "scene: not finished (pd_scene_finish)");
    int rc;
    memset(s, 0, sizeof *s);
    twin.no_wall = 1;
    twin.no_demands = 1; /* the twin's figures are umax and the approach */
    s->Pi1 = pd_malloc(sc->n, sizeof(double));
    s->gamma = pd_malloc(sc->n, sizeof(double));
    s->Pi2 = pd_malloc(sc->nstruct, sizeof(double));
    s->Pi3 = pd_malloc(sc->ncontact, sizeof(double));
    s->chi = pd_malloc(sc->ncontact, sizeof(double));
    s->err_est_structure = pd_malloc(sc->nstruct, sizeof(double));
    s->required_gap = pd_malloc(sc->ncontact, sizeof(double));
    s->rule_abs = pd_malloc(sc->ncontact, sizeof(double));
    s->rule_srss = pd_malloc(sc->ncontact, sizeof(double));
    s->rule_ddc = pd_malloc(sc->ncontact, sizeof(double));
    if (!s->Pi1 || !s->gamma || !s->Pi2 || !s->Pi3 || !s->chi || !s->err_est_structure ||
        !s->required_gap || !s->rule_abs || !s->rule_srss || !s->rule_ddc) {
        pd_scene_summary_free(s);
        return pd_err_set(err, PD_ENOMEM, "out of memory for the summary of %d dofs", sc->n);
    }
    double cpu0 = pd_cpu_seconds();
    if ((rc = pd_scene_result_alloc(sc, &s->r, err)) ||
        (rc = pd_scene_result_alloc(sc, &s->free, err)) ||
        (rc = pd_scene_run(sc, opts, sampler, ctx, &s->r, err)) ||
        (rc = pd_scene_run(sc, &twin, NULL, NULL, &s->free, err))) {
        pd_scene_summary_free(s);
        return rc;
    }
    s->cpu_s = pd_cpu_seconds() - cpu0;
    s->err_est = s->r.rtol > 0.0 ? fmax(s->r.err_est_max, s->free.err_est_max) : NAN;
    s->rtol_met = s->r.rtol_met && s->free.rtol_met;
    double Le = pd_scene_Le(sc);
    for (int i = 0; i < sc->n; i++) {
        s->Pi1[i] = s->r.umax[i] / Le;
        s->gamma[i] = s->free.umax[i] > 0.0 ? s->r.umax[i] / s->free.umax[i] : NAN;
    }
    for (int k = 0; k < sc->nstruct; k++) {
        s->Pi2[k] = sc->exc.Tp / sc->st[k].T0;
        s->err_est_structure[k] = s->r.rtol > 0.0 ? fmax(s->r.err_est[k], s->free.err_est[k]) : NAN;
    }
    for (int a = 0; a < sc->ncontact; a++) {
        s->Pi3[a] = sc->ct[a].gap / Le;
        s->chi[a] = s->free.approach[a] > 0.0 ? sc->ct[a].gap / s->free.approach[a] : NAN;
    }
    pd_scene_separation(sc, s);
    return PD_OK;
}
