/* model.c — checking a model (its yielding springs too), and the step count of a run. */
#include <math.h>

#include "pd_engine.h"
#include "pd_null.h"

/* The yielding springs: S sized n x ns, ks and uy > 0 finite. */
static int check_springs(const pd_model *model, pd_err *err)
{
    int st;
    if (model->ns < 0)
        return pd_err_set(err, PD_EINVAL, "model: %d yielding springs", model->ns);
    if (model->ns == 0)
        return PD_OK;
    if ((st = pd_matrix_check(&model->S, model->n, model->ns, "S", err)))
        return st;
    if (!model->ks || !model->uy)
        return pd_err_set(err, PD_EINVAL, "model: yielding springs need ks and uy");
    for (int j = 0; j < model->ns; j++)
        if (!(model->ks[j] > 0.0) || !isfinite(model->ks[j]) || !(model->uy[j] > 0.0) ||
            !isfinite(model->uy[j]))
            return pd_err_set(err, PD_EINVAL,
                              "model: yielding spring %d needs ks > 0 and uy > 0 finite (ks %g, "
                              "uy %g)",
                              j, model->ks[j], model->uy[j]);
    return PD_OK;
}

int pd_model_refuse_yield(const pd_model *model, const char *method, pd_err *err)
{
    if (!model || !method)
        return PD_NULL_ARG(err, !model ? "model" : "method");
    if (model->ns > 0)
        return pd_err_set(err, PD_EINVAL,
                          "%s: models no yielding springs (%d given; the newmark method does)",
                          method, model->ns);
    return PD_OK;
}

int pd_model_check(const pd_model *model, pd_err *err)
{
    int st;
    if (!model || model->n <= 0 || model->m < 0)
        return pd_err_set(err, PD_EINVAL,
                          "model: needs n > 0 degrees of freedom and m >= 0 contacts");
    /* every method inverts or factors M */
    if (model->M.kind == PD_MATRIX_ZERO)
        return pd_err_set(err, PD_EINVAL, "model: the mass matrix M must be given");
    if ((st = pd_matrix_check(&model->M, model->n, model->n, "M", err)) ||
        (st = pd_matrix_check(&model->C, model->n, model->n, "C", err)) ||
        (st = pd_matrix_check(&model->K, model->n, model->n, "K", err)))
        return st;
    if (model->nbreaks < 0 || (model->nbreaks > 0 && !model->breaks))
        return pd_err_set(err, PD_EINVAL, "model: %d breakpoints without their times",
                          model->nbreaks);
    /* strictly increasing: each breakpoint is passed once */
    for (int k = 0; k < model->nbreaks; k++)
        if (!isfinite(model->breaks[k]) || (k > 0 && !(model->breaks[k] > model->breaks[k - 1])))
            return pd_err_set(err, PD_EINVAL, "model: breakpoints must be finite and increasing");
    if ((st = check_springs(model, err)))
        return st;
    if (model->m == 0) /* no contact: W, g0 and e unused */
        return PD_OK;
    if ((st = pd_matrix_check(&model->W, model->n, model->m, "W", err)))
        return st;
    if (!model->g0 || !model->e)
        return pd_err_set(err, PD_EINVAL, "model: gaps g0 and restitution e are required");
    for (int a = 0; a < model->m; a++) {
        /* no contact starts penetrated; e in [0, 1]: Newton's law never creates energy */
        if (!(model->g0[a] >= 0.0) || !isfinite(model->g0[a]))
            return pd_err_set(err, PD_EINVAL, "model: gap of contact %d is %g, must be >= 0", a,
                              model->g0[a]);
        if (!(model->e[a] >= 0.0 && model->e[a] <= 1.0))
            return pd_err_set(err, PD_EINVAL,
                              "model: restitution of contact %d is %g, must be in [0, 1]", a,
                              model->e[a]);
    }
    return PD_OK;
}

long pd_steps_for(double tend, double h)
{
    double r = tend / h, k = floor(r + 0.5);
    /* tend / h within 1e-9 of a whole k: k steps; else the steps that pass tend */
    if (fabs(r - k) <= 1e-9 * fmax(1.0, r))
        return (long)k;
    return (long)ceil(r);
}
