/* case.c — the model, scheme, method and scene flags that simulate,
 * compare, converge and spectrum share, with errors that name the flag. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pd_cli.h"

const char pd_cli_case_help[] =
    "model flags (defaults in brackets):\n"
    "  --pulse sine|cosine|harmonic [sine]    --dir normal|reverse [normal]\n"
    "  --ap A   pulse amplitude, m/s^2 [1]    --Tp T   pulse period, s [1]\n"
    "  --T0 T   oscillator period, s  or  --Pi2 X = Tp/T0 [1]\n"
    "  --gap D  initial gap, m        or  --Pi3 X = gap wp^2/ap [0.05]\n"
    "  --eps E  restitution in [0,1] [0.5]    --xi Z   damping ratio in [0,1) [0.05]\n"
    "  --height H  the oscillator's storey height, m, for its drift ratio [3]\n"
    "  --uy U  yield displacement, m  or  --Piy X = uy wp^2/ap [none: elastic]\n"
    "  --alpha A  post-yield stiffness ratio in [0,1] [0] (a yielding oscillator runs by\n"
    "           event, moreau or newmark; with --chain every SDOF yields: event,\n"
    "           moreau or newmark; docs/methods.md, \"Yielding oscillators\")\n"
    "records (docs/records.md):\n"
    "  --record F    the ground acceleration of a record (PEER .AT2, COSMOS V2, or text\n"
    "                't a'): replaces the pulse; ap and Tp come from its fitted pulse\n"
    "  --scale S [1]  multiplies the record   --dir normal|reverse as for pulses\n"
    "  --units g|m/s2|cm/s2 [g]  of a text record   --record-format auto|at2|v2|text [auto]\n"
    "  --target-pga A | --target-sa A  scale the record to a PGA or to a 5 %-damped Sa(T1)\n"
    "                of A m/s^2 (--T1 T [the oscillator's --T0, a scene's first structure's])\n"
    "scenes (rows of structures, docs/scenes.md):\n"
    "  --scene F.json   run the scene of file F (its excitation replaces the model flags)\n"
    "  --chain N        a row of N SDOFs between two walls built from the model flags: unit\n"
    "                   masses, periods alternating T0 and R T0 (--chain-ratio R [1.5]),\n"
    "                   every gap --gap/--Pi3, every restitution --eps\n"
    "scheme:\n"
    "  --method moreau|event|penalty|newmark|auto|event-general [auto: event for one\n"
    "           oscillator when its scan fits, moreau for scenes; a flag only one method takes\n"
    "           (--dt, --theta, --kc, ...) chooses that method; event-general: the GSL-based\n"
    "           reference for scenes, event-rows' cross-check; newmark: the penalty elements on\n"
    "           fixed implicit Newmark steps (dt, or dt/k for 10 per element period)]\n"
    "  --dt H [min(Tp,T0)/2000]   --theta T [0.5]   --gamma G [0.5]   --tend T [Tp+2 T0;\n"
    "         harmonic: transient + window, see docs/scheme.md]\n"
    "  --rtol R  Moreau-Jean to a tolerance: steps chosen so that every peak is within R of\n"
    "           its value, relative, with an estimate of its error (err_est); --rtol alone\n"
    "           chooses moreau; with --method penalty, its integrator's tolerance\n"
    "  --allow-unstable  accept theta outside [1/2, 1]\n"
    "  --no-wall  without contacts: the oscillator's no-wall twin, a free scene\n"
    "  --no-accumulation  event-driven: do not jump accumulations of impacts\n"
    "  --close-tol X [1e-10]  event-driven rows: contacts within X Le of zero at an impact\n"
    "           take part in it (simultaneous); counted in the output (docs/methods.md)\n"
    "  --impact-law staged|single [staged]  event-driven rows: the law of an impact of\n"
    "           several contacts: LCPs in stages, or one LCP (event-general's); a run with\n"
    "           simultaneous impacts reports law_band, its peaks under the other law\n"
    "  --contact-duration TD [0.005]  s: the equivalent contact force pi I / (2 TD) of an\n"
    "           impact of impulse I (a half-sine pulse; docs/scenes.md, \"Demands\")\n"
    "  --kernel auto|general [auto]  general: no fast path (scalar kernel, exact reference)\n"
    "  --factor auto|scalar|dense|cholmod [auto]  storage of the iteration matrix\n"
    "  --lcp-solver auto|lemke|structured|pgs [auto]  the contact LCP solver (docs/lcp.md)\n"
    "penalty (--method penalty, and newmark: --contact, --kc, --kc-abs):\n"
    "  --contact kelvin|hertz [kelvin]   --kc X stiffness as a multiple of w0^2 (scenes: of\n"
    "         the largest storey stiffness) [max(1e4 w0^2, 1e3 wp^2 / Pi3^2): about 3 %\n"
    "         of the gap's penetration; scenes 1e4]\n"
    "  --kc-abs K  stiffness in N/m per kg (scenes: N/m; N/m^1.5 for hertz)\n"
    "  --rtol R [1e-10] (with --method penalty)  --atol A [1e-12]\n"
    "  --stepper rk8pd|rkf45|rk4imp|msbdf [rk8pd]\n";

void pd_cli_case_init(pd_cli_case *a)
{
    memset(a, 0, sizeof *a);
    a->c = pd_osc_default();
    a->opts = pd_run_default_opts();
    a->chain_ratio = 1.5;
    a->scale = 1.0;
    a->height = PD_STOREY_HEIGHT;
    a->opts.contact_duration = PD_CONTACT_DURATION;
}

static void cli_record_free(pd_cli_record *r)
{
    if (r) {
        pd_record_free(&r->rec);
        free(r);
    }
}

void pd_cli_case_free(pd_cli_case *a)
{
    if (a->recs) { /* record is recs[0] */
        for (int k = 0; k < a->suite->n; k++)
            cli_record_free(a->recs[k]);
        a->record = NULL;
    }
    cli_record_free(a->record);
    a->record = NULL;
    free(a->recs);
    free(a->rec_scale);
    pd_suite_free(a->suite);
    pd_scene_free(a->scene);
    a->scene = NULL;
    a->recs = NULL;
    a->rec_scale = NULL;
    a->suite = NULL;
}

int pd_cli_record_load(const char *path, pd_record_format format, pd_record_units units,
                       int units_given, pd_cli_record **out)
{
    pd_err err;
    pd_record_format fmt = format;
    *out = NULL;
    if (strchr(path, ',') && access(path, F_OK) != 0) /* a comma list, as spectra take */
        return pd_cli_usage_error("%s: no such file; a suite is --record given once per record, "
                                  "or --records FILE (one record a line)",
                                  path);
    if (units_given && fmt == PD_RECORD_AUTO && pd_record_detect(path, &fmt, &err))
        return pd_cli_usage_error("%s", err.msg);
    if (units_given && fmt != PD_RECORD_TEXT)
        return pd_cli_usage_error(
            "--units: %s is read as %s, whose file states its units "
            "(--units is for two-column text records)",
            path, fmt == PD_RECORD_AT2 ? "a PEER AT2 record (in g)" : "a COSMOS V2 record");
    pd_cli_record *r = calloc(1, sizeof *r);
    if (!r) {
        fprintf(stderr, "pound: out of memory for the record %s\n", path);
        return 1;
    }
    int rc = pd_record_read(path, format, units, &r->rec, &err);
    if (!rc && (rc = pd_record_fit_pulse(&r->rec, &r->pulse, &err)))
        pd_record_free(&r->rec);
    if (rc) {
        free(r);
        if (rc == PD_ENOMEM)
            return fprintf(stderr, "pound: %s\n", err.msg), 1;
        if (format != PD_RECORD_AUTO) /* the user chose how to read it: say so */
            return pd_cli_usage_error("%s (read as --record-format %s)", err.msg,
                                      pd_record_format_name(format));
        return pd_cli_usage_error("%s", err.msg);
    }
    char warn[512];
    if (!pd_record_plausible(&r->rec, units, warn, sizeof warn))
        fprintf(stderr, "pound: warning: %s\n", warn);
    *out = r;
    return 0;
}

/* A numeric flag and where it goes; model flags describe the oscillator. */
typedef struct num_flag {
    const char *flag;
    double *dst;
    int *given;
    int model;
} num_flag;

/* A flag naming one of a set: its parser's verdict, or an error listing the set. */
static int named(const char *flag, const char *val, int bad, const char *set)
{
    if (bad)
        return pd_cli_usage_error("%s: '%s' is not one of %s", flag, val ? val : "", set);
    return 1;
}

int pd_cli_case_flag(pd_cli_case *a, int argc, char **argv, int *i)
{
    const char *f = argv[*i], *val = *i + 1 < argc ? argv[*i + 1] : NULL;
    double x;
    int rc;
    num_flag nums[] = {{"--ap", &a->c.ap, NULL, 1},
                       {"--Tp", &a->c.Tp, NULL, 1},
                       {"--T0", &a->T0, &a->have_T0, 1},
                       {"--Pi2", &a->c.Pi2, &a->have_Pi2, 1},
                       {"--gap", &a->gap, &a->have_gap, 1},
                       {"--Pi3", &a->c.Pi3, &a->have_Pi3, 1},
                       {"--eps", &a->c.eps, NULL, 1},
                       {"--xi", &a->c.xi, NULL, 1},
                       {"--dt", &a->opts.dt, &a->have_dt, 0},
                       {"--theta", &a->opts.theta, NULL, 0},
                       {"--gamma", &a->opts.gamma, NULL, 0},
                       {"--tend", &a->opts.tend, &a->have_tend, 0},
                       {"--kc", &a->opts.pen.kc_mult, &a->have_kc, 0},
                       {"--kc-abs", &a->opts.pen.kc_abs, NULL, 0},
                       {"--rtol", &a->rtol, &a->have_rtol, 0},
                       {"--atol", &a->opts.pen.atol, NULL, 0},
                       {"--chain-ratio", &a->chain_ratio, NULL, 1},
                       {"--scale", &a->scale, &a->have_scale, 0},
                       {"--close-tol", &a->opts.close_tol, NULL, 0},
                       {"--height", &a->height, &a->have_height, 1},
                       {"--uy", &a->uy, &a->have_uy, 1},
                       {"--Piy", &a->c.Piy, &a->have_Piy, 1},
                       {"--alpha", &a->c.alpha, &a->have_alpha, 1},
                       {"--contact-duration", &a->opts.contact_duration, NULL, 0}};
    /* flags that only one method takes choose it, unless --method says another */
    static const struct {
        const char *flag;
        pd_method method;
    } only[] = {{"--dt", PD_METHOD_MOREAU},         {"--theta", PD_METHOD_MOREAU},
                {"--gamma", PD_METHOD_MOREAU},      {"--allow-unstable", PD_METHOD_MOREAU},
                {"--kernel", PD_METHOD_MOREAU},     {"--factor", PD_METHOD_MOREAU},
                {"--lcp-solver", PD_METHOD_MOREAU}, {"--no-accumulation", PD_METHOD_EVENT},
                {"--close-tol", PD_METHOD_EVENT},   {"--impact-law", PD_METHOD_EVENT},
                {"--kc", PD_METHOD_PENALTY},        {"--kc-abs", PD_METHOD_PENALTY},
                {"--atol", PD_METHOD_PENALTY},      {"--contact", PD_METHOD_PENALTY},
                {"--stepper", PD_METHOD_PENALTY}};
    for (size_t n = 0; n < sizeof only / sizeof only[0]; n++)
        if (!strcmp(f, only[n].flag)) {
            pd_cli_case_implies(a, f, only[n].method);
            if (a->n_method_flags < (int)(sizeof a->method_flags / sizeof a->method_flags[0]))
                a->method_flags[a->n_method_flags++] = only[n].flag;
        }
    for (size_t n = 0; n < sizeof nums / sizeof nums[0]; n++)
        if (!strcmp(f, nums[n].flag)) {
            if ((rc = pd_cli_double(f, val, &x)))
                return rc;
            *nums[n].dst = x;
            if (nums[n].given)
                *nums[n].given = 1;
            if (nums[n].model && !a->model_flag)
                a->model_flag = nums[n].flag;
            if (!strcmp(f, "--ap") || !strcmp(f, "--Tp"))
                a->pulse_flag = nums[n].flag;
            (*i)++;
            return 1;
        }
    if (!strcmp(f, "--allow-unstable") || !strcmp(f, "--no-wall") ||
        !strcmp(f, "--no-accumulation")) {
        a->opts.allow_unstable |= !strcmp(f, "--allow-unstable");
        a->opts.no_wall |= !strcmp(f, "--no-wall");
        a->opts.no_accumulation |= !strcmp(f, "--no-accumulation");
        return 1;
    }
    if (!strcmp(f, "--pulse"))
        rc = named(f, val, pd_pulse_parse(val, &a->c.pulse) != PD_OK, "sine, cosine, harmonic");
    else if (!strcmp(f, "--dir"))
        rc = named(f, val, pd_dir_parse(val, &a->c.dir) != PD_OK, "normal, reverse");
    else if (!strcmp(f, "--method")) {
        rc = named(f, val, pd_method_parse(val, &a->opts.method) != PD_OK,
                   "moreau, event, penalty, auto, event-general");
        a->method_by = a->opts.method == PD_METHOD_AUTO ? NULL : f;
    } else if (!strcmp(f, "--contact")) {
        rc =
            named(f, val, !val || (strcmp(val, "kelvin") && strcmp(val, "hertz")), "kelvin, hertz");
        if (rc == 1)
            a->opts.pen.law = strcmp(val, "hertz") ? PD_PENALTY_KELVIN : PD_PENALTY_HERTZDAMP;
    } else if (!strcmp(f, "--stepper")) {
        static const char *const steppers[] = {"rk8pd", "rkf45", "rk4imp", "msbdf"};
        int ok = 0;
        for (int k = 0; k < 4 && val; k++)
            if (!strcmp(val, steppers[k])) {
                ok = 1;
                a->opts.pen.stepper = steppers[k];
            }
        rc = named(f, val, !ok, "rk8pd, rkf45, rk4imp, msbdf");
    } else if (!strcmp(f, "--kernel")) {
        rc =
            named(f, val, !val || (strcmp(val, "auto") && strcmp(val, "general")), "auto, general");
        if (rc == 1)
            a->opts.kernel = strcmp(val, "general") ? PD_KERNEL_AUTO : PD_KERNEL_GENERAL;
    } else if (!strcmp(f, "--factor"))
        rc = named(f, val, pd_factor_kind_parse(val, &a->opts.factor) != PD_OK,
                   "auto, scalar, dense, cholmod");
    else if (!strcmp(f, "--impact-law"))
        rc =
            named(f, val, pd_impact_law_parse(val, &a->opts.impact_law) != PD_OK, "staged, single");
    else if (!strcmp(f, "--lcp-solver"))
        rc = named(f, val, pd_lcp_method_parse(val, &a->opts.lcp_solver) != PD_OK,
                   pd_lcp_method_list());
    else if (!strcmp(f, "--units")) {
        a->have_units = 1;
        rc = named(f, val, pd_record_units_parse(val, &a->rec_units) != PD_OK, "g, m/s2, cm/s2");
    } else if (!strcmp(f, "--record-format"))
        rc = named(f, val, pd_record_format_parse(val, &a->rec_format) != PD_OK,
                   "auto, at2, v2, text");
    else if (!strcmp(f, "--record")) {
        if (!val)
            return pd_cli_usage_error("--record needs a file name");
        pd_err err;
        /* a second one makes a suite of both (and of any later) */
        if (a->record_path && !a->suite && !(a->suite = pd_suite_new()))
            return fprintf(stderr, "pound: out of memory for a suite\n"), 2;
        if (a->record_path && a->suite->n == 0 && pd_suite_add(a->suite, a->record_path, 1.0, &err))
            return pd_cli_usage_error("%s", err.msg);
        if (a->suite && pd_suite_add(a->suite, val, 1.0, &err))
            return pd_cli_usage_error("%s", err.msg);
        if (!a->record_path)
            a->record_path = val;
        rc = 1;
    } else if (!strcmp(f, "--records")) {
        if (!val)
            return pd_cli_usage_error("--records needs a suite file (PATH [SCALE] a line)");
        if (a->records_path)
            return pd_cli_usage_error("--records given twice ('%s', then '%s'): give one suite",
                                      a->records_path, val);
        a->records_path = val;
        rc = 1;
    } else if (!strcmp(f, "--target-pga") || !strcmp(f, "--target-sa")) {
        if (a->target_flag)
            return pd_cli_usage_error("%s and %s: a suite is scaled to one target", a->target_flag,
                                      f);
        if ((rc = pd_cli_double(f, val, &a->target_value)))
            return rc;
        if (!(a->target_value > 0.0) || a->target_value > 1e3)
            return pd_cli_usage_error("%s: the target must be in (0, 1000] m/s^2 (got %.10g)", f,
                                      a->target_value);
        a->target = !strcmp(f, "--target-pga") ? PD_SCALE_PGA : PD_SCALE_SA;
        a->target_flag = f;
        rc = 1;
    } else if (!strcmp(f, "--T1")) {
        if ((rc = pd_cli_double(f, val, &a->T1)))
            return rc;
        if (!(a->T1 >= 1e-3 && a->T1 <= 1e3))
            return pd_cli_usage_error("--T1: the period must be in [0.001, 1000] s (got %.10g)",
                                      a->T1);
        a->have_T1 = 1;
        rc = 1;
    } else if (!strcmp(f, "--scene")) {
        if (!val)
            return pd_cli_usage_error("--scene needs a file name");
        a->scene_path = val;
        rc = 1;
    } else if (!strcmp(f, "--chain")) {
        if ((rc = pd_cli_int(f, val, &a->chain)))
            return rc;
        if (a->chain < 1 || a->chain > 10000000)
            return pd_cli_usage_error("--chain: N must be in [1, 1e7] (got %d)", a->chain);
        rc = 1;
    } else
        return 0;
    if (rc == 1)
        (*i)++;
    if (rc == 1 && (!strcmp(f, "--pulse") || !strcmp(f, "--dir")) && !a->model_flag)
        a->model_flag = f;
    if (rc == 1 && !strcmp(f, "--pulse"))
        a->pulse_flag = f;
    return rc;
}

/* Ranges, each error naming the flag the user gave. */
static int check_scheme(const pd_cli_case *a)
{
    const pd_run_opts *o = &a->opts;
    if (a->have_dt && !(o->dt > 0.0))
        return pd_cli_usage_error("--dt: the step must be > 0 (got %.10g)", o->dt);
    if (a->have_tend && !(o->tend > 0.0))
        return pd_cli_usage_error("--tend: must be > 0 (got %.10g)", o->tend);
    if (!(o->gamma >= 0.0 && o->gamma <= 1.0))
        return pd_cli_usage_error("--gamma: must be in [0, 1] (got %.10g)", o->gamma);
    if (!o->allow_unstable && !(o->theta >= 0.5 && o->theta <= 1.0))
        return pd_cli_usage_error("--theta: %.10g is outside [1/2, 1], where Moreau-Jean is not "
                                  "unconditionally stable (add --allow-unstable to run it)",
                                  o->theta);
    if (!(o->theta >= 0.0 && o->theta <= 2.0))
        return pd_cli_usage_error("--theta: must be in [0, 2] (got %.10g)", o->theta);
    if (a->have_kc && !(o->pen.kc_mult > 0.0))
        return pd_cli_usage_error("--kc: the contact stiffness multiple must be > 0 (got %.10g)",
                                  o->pen.kc_mult);
    if (o->pen.kc_abs < 0.0)
        return pd_cli_usage_error("--kc-abs: the contact stiffness must be >= 0 (got %.10g)",
                                  o->pen.kc_abs);
    if (!(o->pen.rtol > 0.0 && o->pen.rtol < 1.0))
        return pd_cli_usage_error("--rtol: the relative tolerance must be in (0, 1) (got %.10g)",
                                  o->pen.rtol);
    if (!(o->pen.atol > 0.0))
        return pd_cli_usage_error("--atol: the absolute tolerance must be > 0 (got %.10g)",
                                  o->pen.atol);
    if (!(o->close_tol >= 0.0 && o->close_tol <= 1.0))
        return pd_cli_usage_error("--close-tol: the closing tolerance must be in [0, 1] (in "
                                  "units of Le; got %.10g)",
                                  o->close_tol);
    if (!(o->contact_duration > 0.0) || !isfinite(o->contact_duration))
        return pd_cli_usage_error("--contact-duration: must be a finite number > 0 [s] "
                                  "(got %.10g)",
                                  o->contact_duration);
    if (!(a->height > 0.0) || !isfinite(a->height))
        return pd_cli_usage_error("--height: the storey height must be a finite number > 0 "
                                  "[m] (got %.10g)",
                                  a->height);
    return 0;
}

/* The flag that set the oscillator's period: --T0, --Pi2, else --Tp. */
static const char *period_flag(const pd_cli_case *a)
{
    return a->have_T0 ? "--T0" : a->have_Pi2 ? "--Pi2" : "--Tp";
}

/* The work budgets are the library's: PD_MAX_STEPS Moreau-Jean steps,
 * PD_OSC_MAX_SCAN scan points of the event-driven reference; here they are
 * checked first so that a refusal names the flag the user typed. */
#define CASE_MAX_RATIO 1e4 /* periods of a chain's neighbours, at most this far apart */

/* The flag behind a derived period out of range (T0 = Tp / Pi2, Tp + 2 T0):
 * of Tp and the period flag given (--T0 or --Pi2), the one whose value is
 * further from 1 on a log scale (1 s, or Pi2 = 1). */
static const char *extreme_period_flag(const pd_cli_case *a)
{
    double other = a->have_T0 ? a->T0 : a->have_Pi2 ? a->c.Pi2 : 1.0;
    if (!a->have_T0 && !a->have_Pi2)
        return "--Tp";
    return fabs(log(a->c.Tp)) > fabs(log(other)) ? "--Tp" : period_flag(a);
}

/* The flag behind the step count tend / dt: the ones the user gave, else
 * the period that drives both (tend = Tp + 2 T0, dt = min(Tp, T0) / 2000). */
static const char *steps_flag(const pd_cli_case *a)
{
    const char *dt = a->dt_flag ? a->dt_flag : "--dt";
    if (a->have_dt && a->have_tend)
        return !strcmp(dt, "--dt") ? "--dt/--tend" : "--dt-per-Tp/--tend";
    return a->have_tend ? "--tend" : a->have_dt ? dt : extreme_period_flag(a);
}

/* The flag behind Le = ap (Tp / 2 pi)^2: --scale of a record, else the
 * pulse flag given last (--ap or --Tp). */
static const char *ap_flag(const pd_cli_case *a)
{
    return a->record_path ? "--scale" : a->pulse_flag ? a->pulse_flag : "--ap";
}

int pd_cli_case_check_derived(const pd_cli_case *a)
{
    const pd_osc *c = &a->c;
    double T0 = pd_osc_T0(c), wp = pd_osc_wp(c), Le = pd_osc_Le(c), gap = pd_osc_gap(c);
    if (!isfinite(T0) || !(T0 > 0.0) || !isfinite(PD_TWO_PI / T0) || !isfinite(c->Pi2))
        return pd_cli_usage_error("%s: the oscillator's period T0 = Tp / Pi2 = %.3g s / %.3g is "
                                  "out of range",
                                  extreme_period_flag(a), c->Tp, c->Pi2);
    if (!isfinite(wp) || !(Le > 0.0) || !isfinite(Le))
        return pd_cli_usage_error("%s: Le = ap (Tp / 2 pi)^2 = %.3g m is out of range", ap_flag(a),
                                  Le);
    if (!isfinite(gap) || !isfinite(c->Pi3))
        return pd_cli_usage_error("%s: the gap is too large for ap and Tp (Pi3 = gap / Le "
                                  "overflows)",
                                  a->have_gap ? "--gap" : "--Pi3");
    double tend = a->have_tend ? a->opts.tend : pd_osc_default_tend(c);
    double dt = a->have_dt ? a->opts.dt : pd_osc_default_dt(c);
    if (!isfinite(tend))
        return pd_cli_usage_error("%s: tend = Tp + 2 T0 overflows", extreme_period_flag(a));
    if (a->opts.rtol > 0.0) /* to a tolerance: no step count of its own */
        return 0;
    if (a->have_dt && !(dt < tend))
        return pd_cli_usage_error("%s: the step %.3g s is not shorter than the run (tend = "
                                  "%.3g s)",
                                  a->dt_flag ? a->dt_flag : "--dt", dt, tend);
    if (!(tend / dt <= PD_MAX_STEPS))
        return pd_cli_usage_error("%s: %.3g steps of %.3g s over %.3g s (at most %.0e)",
                                  steps_flag(a), tend / dt, dt, tend, PD_MAX_STEPS);
    double scan = pd_osc_scan_points(c, tend);
    if (a->opts.method == PD_METHOD_EVENT && !(scan <= PD_OSC_MAX_SCAN))
        return pd_cli_usage_error("%s: the event-driven reference would scan %.3g points (64 per "
                                  "period T0 = %.3g s over %.3g s; at most %.3g: "
                                  "--method moreau runs it)",
                                  a->have_tend ? "--tend" : period_flag(a), scan, T0, tend,
                                  PD_OSC_MAX_SCAN);
    return 0;
}

/* The yielding spring's flags: ranges, and the runs that model it. */
static int check_yield(const pd_cli_case *a)
{
    const char *yf = a->have_uy ? "--uy" : "--Piy";
    if (a->have_uy && a->have_Piy)
        return pd_cli_usage_error("--uy and --Piy are alternatives: give one");
    if (a->have_uy && !(a->uy > 0.0 && isfinite(a->uy)))
        return pd_cli_usage_error("--uy: the yield displacement must be > 0 m (got %.10g)", a->uy);
    if (a->have_Piy && !(a->c.Piy > 0.0 && isfinite(a->c.Piy)))
        return pd_cli_usage_error("--Piy: the dimensionless yield displacement must be > 0 "
                                  "(got %.10g)",
                                  a->c.Piy);
    if (a->have_alpha && !(a->c.alpha >= 0.0 && a->c.alpha <= 1.0))
        return pd_cli_usage_error("--alpha: the post-yield stiffness ratio must be in [0, 1] "
                                  "(got %.10g)",
                                  a->c.alpha);
    if (!a->have_uy && !a->have_Piy)
        return a->have_alpha ? pd_cli_usage_error("--alpha: needs the yield displacement "
                                                  "(--uy or --Piy)")
                             : 0;
    if (a->opts.method == PD_METHOD_EVENT && !pd_osc_yield_exact(&a->c))
        return pd_cli_usage_error("%s: the exact reference models a yielding spring whose "
                                  "sliding phase is underdamped, --xi < sqrt(--alpha) (or --xi "
                                  "0, or --alpha 0; got xi %g, alpha %g): --method moreau runs "
                                  "it",
                                  yf, a->c.xi, a->c.alpha);
    if (a->opts.method != PD_METHOD_AUTO && a->opts.method != PD_METHOD_MOREAU &&
        a->opts.method != PD_METHOD_EVENT && a->opts.method != PD_METHOD_NEWMARK)
        return pd_cli_usage_error("%s: a yielding oscillator runs by --method event, moreau or "
                                  "newmark (the adaptive penalty does not model yielding yet; "
                                  "got --method %s)",
                                  yf, pd_method_name(a->opts.method));
    if (a->opts.rtol > 0.0)
        return pd_cli_usage_error("%s: a yielding oscillator runs at a fixed step (--dt), not "
                                  "to a tolerance (--rtol)",
                                  yf);
    return 0;
}

/* The oscillator's ranges, each error naming the flag. */
static int check_case(const pd_cli_case *a)
{
    pd_err err;
    int rc;
    if (a->have_T0 && a->have_Pi2)
        return pd_cli_usage_error("--T0 and --Pi2 are alternatives: give one");
    if (a->have_gap && a->have_Pi3)
        return pd_cli_usage_error("--gap and --Pi3 are alternatives: give one");
    if (!(a->c.ap > 0.0))
        return pd_cli_usage_error("--ap: pulse amplitude must be > 0 (got %.10g)", a->c.ap);
    if (!(a->c.Tp > 0.0))
        return pd_cli_usage_error("--Tp: pulse period must be > 0 (got %.10g)", a->c.Tp);
    if (a->have_T0 && !(a->T0 > 0.0))
        return pd_cli_usage_error("--T0: oscillator period must be > 0 (got %.10g)", a->T0);
    if (a->have_Pi2 && !(a->c.Pi2 > 0.0))
        return pd_cli_usage_error("--Pi2: must be > 0 (got %.10g)", a->c.Pi2);
    if (a->have_gap && !(a->gap >= 0.0))
        return pd_cli_usage_error("--gap: the gap must be >= 0 (got %.10g)", a->gap);
    if (a->have_Pi3 && !(a->c.Pi3 >= 0.0))
        return pd_cli_usage_error("--Pi3: the dimensionless gap must be >= 0 (got %.10g)",
                                  a->c.Pi3);
    if (!(a->c.eps >= 0.0 && a->c.eps <= 1.0))
        return pd_cli_usage_error("--eps: restitution must be in [0, 1] (got %.10g)", a->c.eps);
    if (!(a->c.xi >= 0.0 && a->c.xi < 1.0))
        return pd_cli_usage_error("--xi: damping ratio must be in [0, 1) (got %.10g)", a->c.xi);
    if ((rc = check_yield(a)))
        return rc;
    if (a->chain && !(a->chain_ratio > 0.0))
        return pd_cli_usage_error("--chain-ratio: must be > 0 (got %.10g)", a->chain_ratio);
    /* the shorter period sets the step, the longer the run: at most CASE_MAX_RATIO apart */
    if (a->chain > 1 &&
        !(a->chain_ratio <= CASE_MAX_RATIO && a->chain_ratio >= 1.0 / CASE_MAX_RATIO))
        return pd_cli_usage_error("--chain-ratio: must be in [1e-4, 1e4] (got %.10g)",
                                  a->chain_ratio);
    if ((rc = pd_cli_case_check_derived(a)))
        return rc;
    if (pd_osc_check(&a->c, &err))
        return pd_cli_usage_error("%s", err.msg);
    return 0;
}

/* Sa(T1)'s period: --T1, else the oscillator's --T0, else the scene's
 * first structure's fundamental period (the scene kept for pd_cli_scene);
 * 0 or 2. */
static int case_T1(pd_cli_case *a, double *T1)
{
    pd_err err;
    *T1 = a->have_T1 ? a->T1 : a->have_T0 ? a->T0 : 0.0;
    if (*T1 > 0.0 || a->target != PD_SCALE_SA)
        return 0;
    if (!a->scene_path)
        return pd_cli_usage_error("--target-sa: give the period of Sa(T1) with --T1 (or the "
                                  "oscillator's --T0)");
    if (pd_scene_load(a->scene_path, &a->scene, &err))
        return pd_cli_usage_error("%s", err.msg);
    *T1 = a->scene->st[0].T0;
    return 0;
}

/* --record (once or more) or --records: the flags checked, every record
 * read and its pulse fitted, each one's scale (--scale times the suite
 * file's, or the target's: PGA, or the 5 %-damped Sa(T1)); record is the
 * first: 0 or 2. */
static int case_records(pd_cli_case *a)
{
    pd_err err;
    double T1;
    int rc;
    if (a->records_path && a->record_path)
        return pd_cli_usage_error("--records and --record: give the suite one way (%s, %s)",
                                  a->records_path, a->record_path);
    if (a->target_flag && !a->record_path && !a->records_path)
        return pd_cli_usage_error("%s: scales records (--record or --records)", a->target_flag);
    if (a->have_T1 && a->target != PD_SCALE_SA)
        return pd_cli_usage_error("--T1: the period of --target-sa");
    if (!a->record_path && !a->records_path)
        return a->have_scale ? pd_cli_usage_error("--scale: goes with --record") : 0;
    if (pd_cli_case_is_suite(a) && !a->suites_by)
        return pd_cli_usage_error("%s: a suite of records runs through `pound simulate`; this "
                                  "command takes one record",
                                  a->records_path ? "--records" : "--record given twice");
    if (a->chain)
        return pd_cli_usage_error("--record: rows of structures take a record through a scene "
                                  "(--scene F.json --record R, or the scene file's excitation)");
    if (a->pulse_flag)
        return pd_cli_usage_error("%s: the record replaces the pulse (its fitted pulse gives ap "
                                  "and Tp; --scale scales it)",
                                  a->pulse_flag);
    if (!(a->scale > 0.0) || !isfinite(a->scale))
        return pd_cli_usage_error("--scale: must be > 0 (got %.10g)", a->scale);
    if (a->target_flag && a->have_scale)
        return pd_cli_usage_error("--scale and %s: the target sets each record's scale",
                                  a->target_flag);
    if (a->records_path && pd_suite_read(a->records_path, &a->suite, &err))
        return pd_cli_usage_error("--records: %s", err.msg);
    if (!a->suite &&
        (!(a->suite = pd_suite_new()) || pd_suite_add(a->suite, a->record_path, 1.0, &err))) {
        fprintf(stderr, "pound: out of memory for the record %s\n", a->record_path);
        return 1;
    }
    int n = a->suite->n;
    for (int k = 0; k < n && a->target_flag; k++)
        if (a->suite->scale[k] != 1.0)
            return pd_cli_usage_error("%s: %s gives %s a scale (%g); with a target the target "
                                      "scales every record",
                                      a->target_flag, a->records_path, a->suite->path[k],
                                      a->suite->scale[k]);
    if ((rc = case_T1(a, &T1)))
        return rc;
    a->recs = calloc((size_t)n, sizeof *a->recs);
    a->rec_scale = calloc((size_t)n, sizeof *a->rec_scale);
    if (!a->recs || !a->rec_scale) {
        fprintf(stderr, "pound: out of memory for a suite of %d records\n", n);
        return 1;
    }
    for (int k = 0; k < n; k++) {
        if ((rc = pd_cli_record_load(a->suite->path[k], a->rec_format, a->rec_units, a->have_units,
                                     &a->recs[k])))
            return rc;
        a->rec_scale[k] = a->scale * a->suite->scale[k];
        if (a->target_flag && pd_record_scale_to(&a->recs[k]->rec, &a->recs[k]->pulse, a->target,
                                                 a->target_value, T1, 0.05, &a->rec_scale[k], &err))
            return pd_cli_usage_error("%s: %s", a->target_flag, err.msg);
    }
    a->record = a->recs[0];
    a->record_path = a->suite->path[0];
    return 0;
}

int pd_cli_case_is_suite(const pd_cli_case *a)
{
    return a->records_path != NULL || (a->suite && a->suite->n > 1);
}

int pd_cli_case_record(const pd_cli_case *a, int k, pd_osc *c, pd_run_opts *o)
{
    pd_cli_case t = *a; /* the flags, on the record's oscillator */
    pd_err err;
    int rc;
    t.c = a->c_base;
    pd_osc_set_record(&t.c, &a->recs[k]->rec, &a->recs[k]->pulse, a->rec_scale[k]);
    /* the dimensional forms given keep their metres and seconds */
    if (t.have_T0 && t.T0 > 0.0)
        pd_osc_set_T0(&t.c, t.T0);
    if (t.have_gap && t.c.ap > 0.0 && t.c.Tp > 0.0)
        pd_osc_set_gap(&t.c, t.gap);
    if (t.have_uy && t.uy > 0.0 && t.c.ap > 0.0 && t.c.Tp > 0.0)
        pd_osc_set_uy(&t.c, t.uy);
    if ((rc = check_case(&t)))
        return rc;
    if (pd_osc_resolve_opts(&t.c, &a->opts_in, o, &err))
        return pd_cli_usage_error("%s", err.msg);
    *c = t.c;
    return 0;
}

int pd_cli_scene_record(const pd_cli_case *a, int k, pd_scene *sc, pd_err *err)
{
    pd_scene_excite_record(&sc->exc, &a->recs[k]->rec, &a->recs[k]->pulse, a->rec_scale[k]);
    sc->tend = 0.0; /* derived from the record (--tend: the options') */
    return pd_scene_finish(sc, err);
}

void pd_cli_case_implies(pd_cli_case *a, const char *flag, pd_method method)
{
    if (!a->implies[method])
        a->implies[method] = flag;
}

/* --rtol to the method that takes it: Moreau-Jean's tolerance (which
 * --rtol alone chooses), or the penalty integrator's; refused with --dt
 * and with the methods that have none; 0 or 2. */
static int case_rtol(pd_cli_case *a)
{
    pd_method m = a->opts.method;
    if (!a->have_rtol)
        return 0;
    if (!(a->rtol >= PD_RTOL_MIN && a->rtol < 1.0))
        return pd_cli_usage_error("--rtol: the relative tolerance must be in [%g, 1) (got "
                                  "%.10g)",
                                  PD_RTOL_MIN, a->rtol);
    if (m == PD_METHOD_PENALTY) {
        a->opts.pen.rtol = a->rtol;
        return 0;
    }
    if (a->methods_listed) { /* compare, converge: the penalty rows' (the commands refuse it
                                without them; converge's rows to a tolerance take --rtols) */
        a->opts.pen.rtol = a->rtol;
        return 0;
    }
    if (m != PD_METHOD_MOREAU && m != PD_METHOD_AUTO)
        return pd_cli_usage_error("--rtol: the tolerance of moreau's steps or of penalty's "
                                  "integrator; --method %s has none",
                                  pd_method_name(m));
    if (a->have_dt)
        return pd_cli_usage_error("--rtol and %s: Moreau-Jean takes fixed steps (--dt) or "
                                  "steps to a tolerance (--rtol), not both",
                                  a->dt_flag ? a->dt_flag : "--dt");
    a->opts.method = PD_METHOD_MOREAU;
    a->opts.rtol = a->rtol;
    return 0;
}

/* The method when --method was not given: the one that the flags given
 * belong to (two methods' flags together need --method; --rtol alone
 * chooses moreau), else the default, left PD_METHOD_AUTO for the library
 * to resolve; 0 or 2. */
static int case_method(pd_cli_case *a)
{
    const char *by = NULL;
    if (a->method_by || a->methods_listed)
        return 0;
    if (a->have_rtol && !a->implies[PD_METHOD_MOREAU] && !a->implies[PD_METHOD_PENALTY] &&
        !a->implies[PD_METHOD_EVENT])
        pd_cli_case_implies(a, "--rtol", PD_METHOD_MOREAU);
    for (int m = 0; m < 3; m++) {
        if (!a->implies[m])
            continue;
        if (by)
            return pd_cli_usage_error("%s and %s belong to different methods (%s, %s): give "
                                      "--method",
                                      by, a->implies[m], pd_method_name(a->opts.method),
                                      pd_method_name((pd_method)m));
        by = a->implies[m];
        a->opts.method = (pd_method)m;
    }
    a->method_by = by;
    return 0;
}

pd_method pd_cli_case_method(const pd_cli_case *a)
{
    if (a->opts.method == PD_METHOD_AUTO && pd_cli_is_scene(a))
        return PD_METHOD_MOREAU; /* as pd_scene_resolve_opts */
    return a->opts.method;
}

const char *pd_cli_method_by(const pd_cli_case *a)
{
    return a->method_by ? a->method_by : "default";
}

#define M_(m) (1u << (m))

/* The methods that read each flag of one method's (or a few): a flag given
 * with --method naming another is refused, not ignored. */
static const struct {
    const char *flag;
    unsigned methods; /* M_(pd_method) bits */
} method_flag_readers[] = {
    {"--theta", M_(PD_METHOD_MOREAU)},
    {"--gamma", M_(PD_METHOD_MOREAU)},
    {"--allow-unstable", M_(PD_METHOD_MOREAU)},
    {"--close-tol", M_(PD_METHOD_EVENT)}, /* and moreau's steps to a tolerance in scenes */
    {"--impact-law", M_(PD_METHOD_EVENT)},
    {"--no-accumulation", M_(PD_METHOD_EVENT) | M_(PD_METHOD_EVENT_GENERAL)},
    {"--kc", M_(PD_METHOD_PENALTY) | M_(PD_METHOD_NEWMARK)},
    {"--kc-abs", M_(PD_METHOD_PENALTY) | M_(PD_METHOD_NEWMARK)},
    {"--contact", M_(PD_METHOD_PENALTY) | M_(PD_METHOD_NEWMARK)},
    {"--atol", M_(PD_METHOD_PENALTY) | M_(PD_METHOD_NEWMARK)},
    {"--stepper", M_(PD_METHOD_PENALTY)}};

/* The names of the methods in bits, "a or b". */
static void method_names(unsigned bits, char *buf, size_t cap)
{
    buf[0] = '\0';
    for (int m = 0; m <= PD_METHOD_NEWMARK; m++)
        if (bits & M_(m))
            snprintf(buf + strlen(buf), cap - strlen(buf), "%s%s", buf[0] ? " or " : "",
                     pd_method_name((pd_method)m));
}

/* Every method-specific flag given is read by the method chosen (one
 * method per run; compare and converge choose per row): 0 or 2. */
static int case_method_flags(const pd_cli_case *a)
{
    pd_method m = a->opts.method;
    if (a->methods_listed || m == PD_METHOD_AUTO)
        return 0;
    for (int k = 0; k < a->n_method_flags; k++)
        for (size_t n = 0; n < sizeof method_flag_readers / sizeof method_flag_readers[0]; n++) {
            unsigned bits = method_flag_readers[n].methods;
            if (strcmp(a->method_flags[k], method_flag_readers[n].flag))
                continue;
            if (!strcmp(a->method_flags[k], "--close-tol") && pd_cli_is_scene(a))
                bits |= M_(PD_METHOD_MOREAU) * (a->have_rtol != 0);
            if (bits & M_(m))
                continue;
            char names[64];
            method_names(bits, names, sizeof names);
            return pd_cli_usage_error(
                "%s: a flag of %s%s; --method %s does not take it", a->method_flags[k], names,
                !strcmp(a->method_flags[k], "--close-tol") ? " (and of "
                                                             "moreau --rtol on scenes)"
                                                           : "",
                pd_method_name(m));
        }
    return 0;
}

static int case_finish(pd_cli_case *a)
{
    int rc;
    pd_err err;
    if ((rc = case_method(a)) || (rc = case_rtol(a)) || (rc = case_method_flags(a)))
        return rc;
    a->opts.method = pd_cli_case_method(a); /* the oscillator's resolves below */
    if (a->scene_path && a->chain)
        return pd_cli_usage_error("--scene and --chain are alternatives: give one");
    if (a->scene_path && a->model_flag)
        return pd_cli_usage_error("%s: the scene file gives the structures and the excitation "
                                  "(model flags go with --chain or the oscillator)",
                                  a->model_flag);
    if ((rc = check_scheme(a)))
        return rc;
    if (a->chain && a->have_height)
        return pd_cli_usage_error("--height: the oscillator's; a --chain's SDOFs have the "
                                  "default storey height (%g m)",
                                  PD_STOREY_HEIGHT);
    if ((rc = case_records(a)))
        return rc;
    a->c_base = a->c;
    a->opts_in = a->opts;
    if (a->scene_path || a->recs) /* a scene resolves its own; a record's: below */
        return a->recs && !a->scene_path ? pd_cli_case_record(a, 0, &a->c, &a->opts) : 0;
    if (a->have_T0 && a->T0 > 0.0)
        pd_osc_set_T0(&a->c, a->T0);
    if (a->have_gap && a->c.ap > 0.0 && a->c.Tp > 0.0)
        pd_osc_set_gap(&a->c, a->gap);
    if (a->have_uy && a->uy > 0.0 && a->c.ap > 0.0 && a->c.Tp > 0.0)
        pd_osc_set_uy(&a->c, a->uy);
    if ((rc = check_case(a)))
        return rc;
    if (a->chain)
        return 0; /* the chain's dt and tend come from its periods */
    if (pd_osc_resolve_opts(&a->c, &a->opts, &a->opts, &err))
        return pd_cli_usage_error("%s", err.msg);
    return 0;
}

int pd_cli_case_finish(pd_cli_case *a)
{
    int rc = case_finish(a);
    if (rc) /* bad input: nothing left behind */
        pd_cli_case_free(a);
    return rc;
}

int pd_cli_is_scene(const pd_cli_case *a)
{
    return a->scene_path != NULL || a->chain > 0;
}

void pd_cli_ref_decisions_json(pd_json *js, const pd_scene_result *ref)
{
    pd_json_int(js, "simultaneous_ref", ref->simultaneous);
    pd_json_int(js, "tol_closed_ref", ref->tol_closed);
    pd_json_int(js, "accumulations_ref", ref->accumulations);
    pd_json_num(js, "close_tol", ref->close_tol);
}

void pd_cli_ref_decisions_text(FILE *f, const pd_scene_result *ref)
{
    if (isnan(ref->close_tol)) /* the one-wall fast path */
        fprintf(f, "  reference decisions: %ld accumulations jumped (one contact)\n",
                ref->accumulations);
    else
        fprintf(f,
                "  reference decisions: %ld LCPs of several contacts, %ld contacts closed "
                "within --close-tol %g Le, %ld accumulations jumped\n",
                ref->simultaneous, ref->tol_closed, ref->close_tol, ref->accumulations);
}

int pd_cli_scene(const pd_cli_case *a, pd_scene **sc)
{
    pd_err err;
    int rc;
    *sc = NULL;
    if (a->scene) /* read already */
        rc = (*sc = pd_scene_copy(a->scene)) ? PD_OK : pd_err_set(&err, PD_ENOMEM, "out of memory");
    else if (a->scene_path)
        rc = pd_scene_load(a->scene_path, sc, &err);
    else {
        pd_scene_excitation x = {
            .pulse = a->c.pulse, .dir = a->c.dir, .ap = a->c.ap, .Tp = a->c.Tp};
        rc = pd_scene_chain(a->chain, &x, pd_osc_T0(&a->c), a->chain_ratio, a->c.xi,
                            pd_osc_gap(&a->c), a->c.eps, sc, &err);
        if (!rc && pd_osc_yields(&a->c)) /* --uy or --Piy: every SDOF yields */
            rc = pd_scene_yield_every(*sc, pd_osc_uy(&a->c), a->c.alpha, &err);
    }
    if (!rc && a->recs && (rc = pd_cli_scene_record(a, 0, *sc, &err))) /* --record replaces */
        pd_scene_free(*sc), *sc = NULL;                                /* the excitation */
    if (rc == PD_ENOMEM) {
        fprintf(stderr, "pound: %s\n", err.msg);
        return 1;
    }
    if (rc)
        return pd_cli_usage_error("%s", err.msg);
    pd_run_opts o;
    if (pd_scene_resolve_opts(*sc, &a->opts, &o, &err)) {
        pd_scene_free(*sc);
        *sc = NULL;
        return pd_cli_usage_error("%s", err.msg);
    }
    return 0;
}
