/* penalty_law.c — what the penalty baseline's two integrators share
 * (penalty.c: GSL's adaptive steppers; penalty_newmark.c: fixed Newmark
 * steps): the options' common checks.  The contact elements' laws are
 * inline in penalty_law.h. */
#include <math.h>

#include "pd_core.h"
#include "pd_engine.h"
#include "penalty_law.h"

/* Options in range; zero tolerances and budget take their defaults. */
int pd_penalty_check_opts(const pd_penalty_opts *o, double t0, double t1, const char *who,
                          pd_err *err)
{
    if (o->law != PD_PENALTY_KELVIN && o->law != PD_PENALTY_HERTZDAMP)
        return pd_err_set(err, PD_EINVAL, "%s: law must be Kelvin-Voigt or Hertz-damp", who);
    /* kc > 0: the elements' stiffness; their damping follows from it and e */
    if (!(o->kc > 0.0) || !isfinite(o->kc))
        return pd_err_set(err, PD_EINVAL,
                          "%s: kc (contact stiffness) must be a finite number > 0 (got %g)", who,
                          o->kc);
    /* h_out = 0: the observer after every step */
    if (!(o->h_out >= 0.0) || !isfinite(o->h_out))
        return pd_err_set(err, PD_EINVAL, "%s: h_out must be >= 0 (got %g)", who, o->h_out);
    if (o->max_steps < 1)
        return pd_err_set(err, PD_EINVAL, "%s: max_steps must be >= 1", who);
    if (o->max_newton < 0)
        return pd_err_set(err, PD_EINVAL, "%s: max_newton must be >= 0 (got %d)", who,
                          o->max_newton);
    if (!(o->time_unit > 0.0) || !isfinite(o->time_unit))
        return pd_err_set(err, PD_EINVAL, "%s: time_unit must be > 0 (got %g)", who, o->time_unit);
    /* a run of no length (t1 = t0) is allowed */
    if (!isfinite(t0) || !isfinite(t1) || t1 < t0)
        return pd_err_set(err, PD_EINVAL, "%s: need finite t0 <= t1 (got %g, %g)", who, t0, t1);
    return PD_OK;
}
