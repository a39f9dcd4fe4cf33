/* case.c — the model, scheme and method flags that simulate, compare and
 * converge share, with errors that name the flag. */
#include <math.h>
#include <string.h>

#include "pd_cli.h"

const char pd_cli_case_help[] =
    "model flags (defaults in brackets):\n"
    "  --pulse sine|cosine|harmonic [sine]    --dir normal|reverse [normal]\n"
    "  --ap A   pulse amplitude, m/s^2 [1]    --Tp T   pulse period, s [1]\n"
    "  --T0 T   oscillator period, s  or  --Pi2 X = Tp/T0 [1]\n"
    "  --gap D  initial gap, m        or  --Pi3 X = gap wp^2/ap [0.05]\n"
    "  --eps E  restitution in [0,1] [0.5]    --xi Z   damping ratio in [0,1) [0.05]\n"
    "scheme:\n"
    "  --method moreau|event|penalty [moreau]\n"
    "  --dt H [min(Tp,T0)/2000]   --theta T [0.5]   --gamma G [0.5]   --tend T [Tp+2 T0;\n"
    "         harmonic: transient + window, see docs/scheme.md]\n"
    "  --allow-unstable  accept theta outside [1/2, 1]\n"
    "  --no-accumulation  event-driven: do not jump accumulations of impacts\n"
    "penalty (--method penalty):\n"
    "  --contact kelvin|hertz [kelvin]   --kc X stiffness as a multiple of w0^2 [1e4]\n"
    "  --kc-abs K  stiffness in N/m per kg (N/m^1.5 per kg for hertz)\n"
    "  --rtol R [1e-10]  --atol A [1e-12]  --stepper rk8pd|rkf45|rk4imp|msbdf [rk8pd]\n";

const char *pd_method_name(pd_method m)
{
    return m == PD_METHOD_EVENT ? "event" : m == PD_METHOD_PENALTY ? "penalty" : "moreau";
}

int pd_method_parse(const char *name, pd_method *m)
{
    if (name && !strcmp(name, "moreau"))
        *m = PD_METHOD_MOREAU;
    else if (name && !strcmp(name, "event"))
        *m = PD_METHOD_EVENT;
    else if (name && !strcmp(name, "penalty"))
        *m = PD_METHOD_PENALTY;
    else
        return -1;
    return 0;
}

void pd_cli_case_init(pd_cli_case *a)
{
    memset(a, 0, sizeof *a);
    a->c = (pd_osc){PD_PULSE_SINE, 1, 1.0, 1.0, 1.0, 0.05, 0.5, 0.05};
    a->opts = pd_osc_default_opts();
    a->method = PD_METHOD_MOREAU;
    a->pen.law = PD_PENALTY_KELVIN;
    a->pen.kc_mult = 1e4;
}

/* A numeric flag and where it goes. */
typedef struct num_flag {
    const char *flag;
    double *dst;
    int *given;
} num_flag;

int pd_cli_case_flag(pd_cli_case *a, int argc, char **argv, int *i)
{
    const char *f = argv[*i], *val = *i + 1 < argc ? argv[*i + 1] : NULL;
    double x;
    int rc;
    num_flag nums[] = {
        {"--ap", &a->c.ap, NULL},          {"--Tp", &a->c.Tp, NULL},
        {"--T0", &a->T0, &a->have_T0},     {"--Pi2", &a->c.Pi2, &a->have_Pi2},
        {"--gap", &a->gap, &a->have_gap},  {"--Pi3", &a->c.Pi3, &a->have_Pi3},
        {"--eps", &a->c.eps, NULL},        {"--xi", &a->c.xi, NULL},
        {"--dt", &a->opts.dt, &a->have_dt}, {"--theta", &a->opts.theta, NULL},
        {"--gamma", &a->opts.gamma, NULL}, {"--tend", &a->opts.tend, &a->have_tend},
        {"--kc", &a->pen.kc_mult, NULL},   {"--kc-abs", &a->pen.kc_abs, NULL},
        {"--rtol", &a->pen.rtol, NULL},    {"--atol", &a->pen.atol, NULL}};
    for (size_t n = 0; n < sizeof nums / sizeof nums[0]; n++)
        if (!strcmp(f, nums[n].flag)) {
            if ((rc = pd_cli_double(f, val, &x)))
                return rc;
            *nums[n].dst = x;
            if (nums[n].given)
                *nums[n].given = 1;
            (*i)++;
            return 1;
        }
    if (!strcmp(f, "--allow-unstable"))
        a->opts.allow_unstable = 1;
    else if (!strcmp(f, "--no-wall"))
        a->opts.no_wall = 1;
    else if (!strcmp(f, "--no-accumulation"))
        a->opts.no_accumulation = 1;
    else if (!strcmp(f, "--pulse")) {
        if (pd_pulse_parse(val, &a->c.pulse))
            return pd_cli_usage_error("--pulse: '%s' is not one of sine, cosine, harmonic",
                                      val ? val : "");
        (*i)++;
    } else if (!strcmp(f, "--dir")) {
        if (pd_dir_parse(val, &a->c.dir))
            return pd_cli_usage_error("--dir: '%s' is not one of normal, reverse", val ? val : "");
        (*i)++;
    } else if (!strcmp(f, "--method")) {
        if (pd_method_parse(val, &a->method))
            return pd_cli_usage_error("--method: '%s' is not one of moreau, event, penalty",
                                      val ? val : "");
        (*i)++;
    } else if (!strcmp(f, "--contact")) {
        if (!val || (strcmp(val, "kelvin") && strcmp(val, "hertz")))
            return pd_cli_usage_error("--contact: '%s' is not one of kelvin, hertz", val ? val : "");
        a->pen.law = strcmp(val, "hertz") ? PD_PENALTY_KELVIN : PD_PENALTY_HERTZDAMP;
        (*i)++;
    } else if (!strcmp(f, "--stepper")) {
        static const char *const steppers[] = {"rk8pd", "rkf45", "rk4imp", "msbdf"};
        int ok = 0;
        for (int k = 0; k < 4 && val; k++)
            ok |= !strcmp(val, steppers[k]);
        if (!ok)
            return pd_cli_usage_error("--stepper: '%s' is not one of rk8pd, rkf45, rk4imp, msbdf",
                                      val ? val : "");
        a->pen.stepper = val;
        (*i)++;
    } else if (!strcmp(f, "--kernel")) {
        if (!val || (strcmp(val, "auto") && strcmp(val, "general")))
            return pd_cli_usage_error("--kernel: '%s' is not one of auto, general", val ? val : "");
        a->opts.kernel = strcmp(val, "general") ? PD_KERNEL_AUTO : PD_KERNEL_GENERAL;
        (*i)++;
    } else
        return 0;
    return 1;
}

/* Ranges, each error naming the flag the user gave. */
static int check_case(const pd_cli_case *a)
{
    pd_err err;
    if (a->have_T0 && a->have_Pi2)
        return pd_cli_usage_error("--T0 and --Pi2 are alternatives: give one");
    if (a->have_gap && a->have_Pi3)
        return pd_cli_usage_error("--gap and --Pi3 are alternatives: give one");
    if (!(a->c.ap > 0.0))
        return pd_cli_usage_error("--ap: pulse amplitude must be > 0 (got %g)", a->c.ap);
    if (!(a->c.Tp > 0.0))
        return pd_cli_usage_error("--Tp: pulse period must be > 0 (got %g)", a->c.Tp);
    if (a->have_T0 && !(a->T0 > 0.0))
        return pd_cli_usage_error("--T0: oscillator period must be > 0 (got %g)", a->T0);
    if (a->have_Pi2 && !(a->c.Pi2 > 0.0))
        return pd_cli_usage_error("--Pi2: must be > 0 (got %g)", a->c.Pi2);
    if (a->have_gap && !(a->gap >= 0.0))
        return pd_cli_usage_error("--gap: the gap must be >= 0 (got %g)", a->gap);
    if (a->have_Pi3 && !(a->c.Pi3 >= 0.0))
        return pd_cli_usage_error("--Pi3: the dimensionless gap must be >= 0 (got %g)", a->c.Pi3);
    if (!(a->c.eps >= 0.0 && a->c.eps <= 1.0))
        return pd_cli_usage_error("--eps: restitution must be in [0, 1] (got %g)", a->c.eps);
    if (!(a->c.xi >= 0.0 && a->c.xi < 1.0))
        return pd_cli_usage_error("--xi: damping ratio must be in [0, 1) (got %g)", a->c.xi);
    if (a->have_dt && !(a->opts.dt > 0.0))
        return pd_cli_usage_error("--dt: the step must be > 0 (got %g)", a->opts.dt);
    if (a->have_tend && !(a->opts.tend > 0.0))
        return pd_cli_usage_error("--tend: must be > 0 (got %g)", a->opts.tend);
    if (!(a->opts.gamma >= 0.0 && a->opts.gamma <= 1.0))
        return pd_cli_usage_error("--gamma: must be in [0, 1] (got %g)", a->opts.gamma);
    if (!a->opts.allow_unstable && !(a->opts.theta >= 0.5 && a->opts.theta <= 1.0))
        return pd_cli_usage_error("--theta: %g is outside [1/2, 1], where Moreau-Jean is not "
                                  "unconditionally stable (add --allow-unstable to run it)",
                                  a->opts.theta);
    if (!(a->opts.theta >= 0.0 && a->opts.theta <= 2.0))
        return pd_cli_usage_error("--theta: must be in [0, 2] (got %g)", a->opts.theta);
    if (!(a->pen.kc_mult > 0.0) || a->pen.kc_abs < 0.0)
        return pd_cli_usage_error("--kc: the contact stiffness must be > 0");
    if (a->pen.rtol < 0.0 || a->pen.atol < 0.0)
        return pd_cli_usage_error("--rtol/--atol: tolerances must be >= 0");
    if (pd_osc_check(&a->c, &err))
        return pd_cli_usage_error("%s", err.msg);
    return 0;
}

int pd_cli_case_finish(pd_cli_case *a)
{
    int rc;
    if (a->have_T0)
        a->c.Pi2 = a->T0 > 0.0 ? a->c.Tp / a->T0 : -1.0;
    if (a->have_gap && a->c.ap > 0.0 && a->c.Tp > 0.0)
        a->c.Pi3 = a->gap / pd_osc_Le(&a->c);
    if ((rc = check_case(a)))
        return rc;
    if (!a->have_dt)
        a->opts.dt = pd_osc_default_dt(&a->c);
    if (!a->have_tend)
        a->opts.tend = pd_osc_default_tend(&a->c);
    if (a->opts.tend / a->opts.dt > 2e9)
        return pd_cli_usage_error("--dt: %g s over %g s is more than 2e9 steps", a->opts.dt,
                                  a->opts.tend);
    return 0;
}

int pd_cli_run(const pd_cli_case *a, pd_method method, const pd_osc_opts *opts,
               pd_osc_sampler sampler, void *ctx, pd_osc_result *res, pd_err *err)
{
    switch (method) {
    case PD_METHOD_EVENT: return pd_osc_reference(&a->c, opts, sampler, ctx, res, err);
    case PD_METHOD_PENALTY: return pd_osc_penalty(&a->c, opts, &a->pen, sampler, ctx, res, err);
    default: return pd_osc_simulate(&a->c, opts, sampler, ctx, res, err);
    }
}
