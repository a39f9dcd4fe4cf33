/* scene_energy.c — the energy balance of a yielding scene run by
 * Moreau–Jean (fixed steps) or by Newmark (average acceleration: the same
 * identity at theta = 1/2, its elements' forces by the trapezoid as the
 * impulses), from rest.  Each step's identity, exact at theta = 1/2 (the
 * midpoint; Newmark's q+ - q = h (v + v+) / 2), with v_th = theta v+ + (1 -
 * theta) v,
 * q_mid = q + h theta v_th, D = up+ - up:
 *   input      h F_theta . v_th,  F_theta = theta F(t1-) + (1 - theta) F(t0+)
 *   damping    h v_th^T C v_th
 *   impacts    -(W P) . v_th                  (P the step's impulses)
 *   hysteretic sum_j ks_j D_j (S_j^T q_mid - up_j - theta D_j)
 * and at the end kinetic v^T M v / 2, strain q^T K q / 2 - up^T ks S^T q +
 * ks up^2 / 2.  theta > 1/2 leaves its numerical damping in the residual. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_alloc.h"
#include "osc_priv.h"
#include "scene_priv.h"

struct pd_scene_energy {
    const pd_model *md;
    double h, theta;
    double *q, *v, *up, *F0, *F1, *vth, *tmp; /* the last state, scratch */
    double *imp;                              /* m: a Newmark step's impulses */
    double t;
    double input, damping, impact, hysteretic, kinetic, strain;
};

void pd_scene_energy_free(pd_scene_energy *e)
{
    if (!e)
        return;
    double *arrays[] = {e->q, e->v, e->up, e->F0, e->F1, e->vth, e->tmp, e->imp};
    for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
        free(arrays[k]);
    free(e);
}

pd_scene_energy *pd_scene_energy_alloc(const pd_model *md, double h, double theta)
{
    pd_scene_energy *e = calloc(1, sizeof *e);
    if (!e)
        return NULL;
    e->md = md;
    e->h = h;
    e->theta = theta;
    double **arrays[] = {&e->q, &e->v, &e->F0, &e->F1, &e->vth, &e->tmp};
    int ok = 1;
    for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
        ok &= (*arrays[k] = pd_calloc(md->n, sizeof(double))) != NULL;
    ok &= (e->up = pd_calloc(md->ns, sizeof(double))) != NULL;
    ok &= (e->imp = pd_calloc(md->m, sizeof(double))) != NULL;
    if (!ok) {
        pd_scene_energy_free(e);
        return NULL;
    }
    return e;
}

/* F(t) from the given side (zero without a force). */
static void force_at(const pd_model *md, double t, int side, double *F)
{
    if (md->force)
        md->force(t, side, F, md->force_ctx);
    else
        memset(F, 0, (size_t)md->n * sizeof(double));
}

/* x^T A y. */
static double quad(const pd_matrix *A, const double *x, const double *y, double *tmp, int n)
{
    pd_matrix_gemv(A, 1.0, y, 0.0, tmp);
    double s = 0.0;
    for (int i = 0; i < n; i++)
        s += x[i] * tmp[i];
    return s;
}

/* The step from the kept state to st (of length h, the contacts' impulses
 * P over it): its terms summed; st kept. */
static void note_step(pd_scene_energy *e, const pd_state *st, double h, const double *P)
{
    const pd_model *md = e->md;
    int n = md->n;
    double th = e->theta;
    if (st->step > 0) {
        force_at(md, e->t, +1, e->F0);
        force_at(md, st->t, -1, e->F1);
        double input = 0.0;
        for (int i = 0; i < n; i++) {
            e->vth[i] = th * st->v[i] + (1.0 - th) * e->v[i];
            input += (th * e->F1[i] + (1.0 - th) * e->F0[i]) * e->vth[i];
        }
        e->input += h * input;
        e->damping += h * quad(&md->C, e->vth, e->vth, e->tmp, n);
        for (int a = 0; a < md->m; a++) /* an impulse's work on the contact's mid-step rate */
            e->impact -= P[a] * pd_matrix_col_dot(&md->W, a, e->vth);
        for (int i = 0; i < n; i++) /* q_mid */
            e->tmp[i] = e->q[i] + h * th * e->vth[i];
        for (int j = 0; j < md->ns; j++) {
            double D = st->up[j] - e->up[j];
            if (D != 0.0)
                e->hysteretic +=
                    md->ks[j] * D * (pd_matrix_col_dot(&md->S, j, e->tmp) - e->up[j] - th * D);
        }
    }
    e->t = st->t;
    memcpy(e->q, st->q, (size_t)n * sizeof(double));
    memcpy(e->v, st->v, (size_t)n * sizeof(double));
    memcpy(e->up, st->up, (size_t)md->ns * sizeof(double));
}

void pd_scene_energy_note(pd_scene_energy *e, const pd_state *st)
{
    note_step(e, st, e->h, st->P);
}

void pd_scene_energy_note_forces(pd_scene_energy *e, const pd_state *st, const double *lam0)
{
    const pd_model *md = e->md;
    double h = st->step > 0 ? st->t - e->t : 0.0;
    for (int a = 0; a < md->m; a++) /* the trapezoid's impulse of the elements' forces */
        e->imp[a] = 0.5 * h * (lam0[a] + (st->active[a] ? st->P[a] : 0.0));
    note_step(e, st, h, e->imp);
}

void pd_scene_energy_finish(const pd_scene_energy *e, double E, pd_energy *out)
{
    const pd_model *md = e->md;
    int n = md->n;
    double strain = 0.5 * quad(&md->K, e->q, e->q, e->tmp, n);
    for (int j = 0; j < md->ns; j++) {
        double d = pd_matrix_col_dot(&md->S, j, e->q);
        strain += md->ks[j] * e->up[j] * (0.5 * e->up[j] - d);
    }
    out->input = e->input * E;
    out->kinetic = 0.5 * quad(&md->M, e->v, e->v, e->tmp, n) * E;
    out->strain = strain * E;
    out->damping = e->damping * E;
    out->hysteretic = e->hysteretic * E;
    out->impact = e->impact * E;
    pd_energy_close(out, 0.0); /* from rest */
}

void pd_scene_energy_of_edr(const pd_edr_result *er, double E, pd_energy *out)
{
    out->input = er->input_work * E;
    out->kinetic = er->kinetic * E;
    out->strain = er->strain * E;
    out->damping = er->damping_work * E;
    out->hysteretic = er->hysteretic * E;
    out->impact = er->impact_loss * E;
    pd_energy_close(out, er->energy0 * E);
}
