/* run.c — the run request shared by the oscillator, scenes and sweeps. */
#include <math.h>
#include <string.h>

#include "pd_null.h"
#include "pd_problems.h"

const char *pd_method_name(pd_method method)
{
    return method == PD_METHOD_EVENT           ? "event"
           : method == PD_METHOD_PENALTY       ? "penalty"
           : method == PD_METHOD_AUTO          ? "auto"
           : method == PD_METHOD_EVENT_GENERAL ? "event-general"
           : method == PD_METHOD_NEWMARK       ? "newmark"
                                               : "moreau";
}

int pd_method_parse(const char *name, pd_method *method)
{
    if (!name || !method)
        return PD_EINVAL;
    if (!strcmp(name, "moreau"))
        *method = PD_METHOD_MOREAU;
    else if (!strcmp(name, "event"))
        *method = PD_METHOD_EVENT;
    else if (!strcmp(name, "penalty"))
        *method = PD_METHOD_PENALTY;
    else if (!strcmp(name, "auto"))
        *method = PD_METHOD_AUTO;
    else if (!strcmp(name, "event-general"))
        *method = PD_METHOD_EVENT_GENERAL;
    else if (!strcmp(name, "newmark"))
        *method = PD_METHOD_NEWMARK;
    else
        return PD_EINVAL;
    return PD_OK;
}

const char *pd_impact_law_name(pd_impact_law law)
{
    return law == PD_IMPACT_SINGLE ? "single" : "staged";
}

int pd_impact_law_parse(const char *name, pd_impact_law *law)
{
    if (!name || !law)
        return PD_EINVAL;
    if (!strcmp(name, "staged"))
        *law = PD_IMPACT_STAGED;
    else if (!strcmp(name, "single"))
        *law = PD_IMPACT_SINGLE;
    else
        return PD_EINVAL;
    return PD_OK;
}

pd_run_opts pd_run_default_opts(void)
{
    return (pd_run_opts){.method = PD_METHOD_AUTO,
                         .dt = 0.0,
                         .tend = 0.0,
                         .theta = 0.5,
                         .gamma = 0.5,
                         .allow_unstable = 0,
                         .kernel = PD_KERNEL_AUTO,
                         .factor = PD_FACTOR_AUTO,
                         .lcp_solver = PD_LCP_AUTO,
                         .no_accumulation = 0,
                         .no_wall = 0,
                         .pen = {.law = PD_PENALTY_KELVIN,
                                 .kc_mult = 0.0, /* derived: pd_osc_penalty, scene runs */
                                 .kc_abs = 0.0,
                                 .rtol = 1e-10,
                                 .atol = 1e-12,
                                 .stepper = "rk8pd"},
                         .on_lcp = NULL,
                         .on_lcp_ctx = NULL,
                         .close_tol = PD_CLOSE_TOL,
                         .impact_law = PD_IMPACT_STAGED,
                         .no_law_band = 0,
                         .contact_duration = 0.0,
                         .no_demands = 0,
                         .rtol = 0.0};
}

int pd_run_opts_check(const pd_run_opts *o, pd_err *err)
{
    if (!o)
        return PD_NULL_ARG(err, "o");
    if (o->method != PD_METHOD_MOREAU && o->method != PD_METHOD_EVENT &&
        o->method != PD_METHOD_PENALTY && o->method != PD_METHOD_AUTO &&
        o->method != PD_METHOD_EVENT_GENERAL && o->method != PD_METHOD_NEWMARK)
        return pd_err_set(err, PD_EINVAL, "method: unknown method %d", (int)o->method);
    if (!(o->dt >= 0.0) || !isfinite(o->dt))
        return pd_err_set(err, PD_EINVAL, "dt: must be a finite number > 0 (got %g)", o->dt);
    if (!(o->tend >= 0.0) || !isfinite(o->tend))
        return pd_err_set(err, PD_EINVAL, "tend: must be a finite number > 0 (got %g)", o->tend);
    if (!(o->theta >= 0.0 && o->theta <= 2.0))
        return pd_err_set(err, PD_EINVAL, "theta: must be in [0, 2] (got %g)", o->theta);
    if (!o->allow_unstable && !(o->theta >= 0.5 && o->theta <= 1.0))
        return pd_err_set(err, PD_EINVAL,
                          "theta: %g is outside [1/2, 1], where Moreau-Jean is not "
                          "unconditionally stable (allow_unstable runs it anyway)",
                          o->theta);
    if (!(o->gamma >= 0.0 && o->gamma <= 1.0))
        return pd_err_set(err, PD_EINVAL, "gamma: must be in [0, 1] (got %g)", o->gamma);
    if (!(o->rtol >= PD_RTOL_MIN && o->rtol < 1.0) && o->rtol != 0.0)
        return pd_err_set(err, PD_EINVAL,
                          "rtol: Moreau-Jean's relative tolerance must be in "
                          "[%g, 1), or 0 for fixed steps (got %g)",
                          PD_RTOL_MIN, o->rtol);
    if (o->rtol > 0.0 && o->method != PD_METHOD_MOREAU && o->method != PD_METHOD_AUTO)
        return pd_err_set(err, PD_EINVAL,
                          "rtol: the tolerance of Moreau-Jean's steps; method %s "
                          "has none (penalty: pen.rtol)",
                          pd_method_name(o->method));
    if (o->rtol > 0.0 && o->dt > 0.0)
        return pd_err_set(err, PD_EINVAL,
                          "rtol with dt: Moreau-Jean takes fixed steps (dt) or "
                          "steps to a tolerance (rtol), not both");
    if (!(o->close_tol >= 0.0 && o->close_tol <= 1.0))
        return pd_err_set(err, PD_EINVAL,
                          "close-tol: the closing tolerance must be in [0, 1] "
                          "(in units of Le; got %g)",
                          o->close_tol);
    if (o->impact_law != PD_IMPACT_STAGED && o->impact_law != PD_IMPACT_SINGLE)
        return pd_err_set(err, PD_EINVAL,
                          "impact-law: must be staged (%d) or single (%d) (got "
                          "%d)",
                          (int)PD_IMPACT_STAGED, (int)PD_IMPACT_SINGLE, (int)o->impact_law);
    if (!(o->contact_duration >= 0.0) || !isfinite(o->contact_duration))
        return pd_err_set(err, PD_EINVAL,
                          "contact-duration: the duration of the equivalent "
                          "contact force must be a finite number > 0 [s], or 0 for the default "
                          "(got %g)",
                          o->contact_duration);
    const pd_penalty_setup *p = &o->pen;
    if (p->law != PD_PENALTY_KELVIN && p->law != PD_PENALTY_HERTZDAMP)
        return pd_err_set(err, PD_EINVAL, "contact: unknown contact law %d", (int)p->law);
    if (!(p->kc_mult >= 0.0) || !isfinite(p->kc_mult))
        return pd_err_set(err, PD_EINVAL,
                          "kc: the contact stiffness multiple must be > 0, or 0 "
                          "for the derived default (got %g)",
                          p->kc_mult);
    if (!(p->kc_abs >= 0.0) || !isfinite(p->kc_abs))
        return pd_err_set(err, PD_EINVAL, "kc-abs: the contact stiffness must be >= 0 (got %g)",
                          p->kc_abs);
    if (!(p->rtol > 0.0 && p->atol > 0.0) || !isfinite(p->rtol) || !isfinite(p->atol))
        return pd_err_set(err, PD_EINVAL, "rtol/atol: tolerances must be > 0 (got %g, %g)", p->rtol,
                          p->atol);
    return PD_OK;
}
