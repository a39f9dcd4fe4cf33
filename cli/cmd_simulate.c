/* cmd_simulate.c — `pound simulate`: one run of the pounding oscillator. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_cli.h"
#include "pd_oscillator.h"
#include "pd_output.h"

static const char simulate_usage[] =
    "usage: pound simulate [model flags] [--method moreau] [--dt H] [--theta T] [--tend T]\n"
    "                      [-o FILE.h5|FILE.csv] [--every K] [--json]\n"
    "model flags (defaults in brackets):\n"
    "  --pulse sine|cosine|harmonic [sine]    --dir normal|reverse [normal]\n"
    "  --ap A   pulse amplitude, m/s^2 [1]    --Tp T   pulse period, s [1]\n"
    "  --T0 T   oscillator period, s  or  --Pi2 X = Tp/T0 [1]\n"
    "  --gap D  initial gap, m        or  --Pi3 X = gap wp^2/ap [0.05]\n"
    "  --eps E  restitution in [0,1] [0.5]    --xi Z   damping ratio in [0,1) [0.05]\n"
    "scheme:\n"
    "  --dt H [min(Tp,T0)/2000]   --theta T [0.5]   --gamma G [0.5]   --tend T [Tp+2 T0]\n"
    "  --allow-unstable  accept theta outside [1/2, 1]\n"
    "output:\n"
    "  -o FILE  history t,u,v,impulse,gap (HDF5 or CSV by extension), --every K decimates\n"
    "  --json   one JSON object on stdout\n";

/* Everything the command line sets. */
typedef struct sim_args {
    pd_osc c;
    pd_osc_opts opts;
    double T0, gap;   /* dimensional forms, when given */
    int have_T0, have_Pi2, have_gap, have_Pi3;
    const char *out;
    long every;
    int json;
} sim_args;

/* Value of flag i (argv[i + 1]) or an error. */
static const char *value_of(int argc, char **argv, int i)
{
    return i + 1 < argc ? argv[i + 1] : NULL;
}

/* Parse one flag at argv[*i]; returns 0 or 2. */
static int parse_flag(sim_args *a, int argc, char **argv, int *i)
{
    const char *f = argv[*i], *val = value_of(argc, argv, *i);
    double x;
    int k, rc;
    struct { const char *flag; double *dst; int *have; } nums[] = {
        {"--ap", &a->c.ap, NULL},         {"--Tp", &a->c.Tp, NULL},
        {"--T0", &a->T0, &a->have_T0},    {"--Pi2", &a->c.Pi2, &a->have_Pi2},
        {"--gap", &a->gap, &a->have_gap}, {"--Pi3", &a->c.Pi3, &a->have_Pi3},
        {"--eps", &a->c.eps, NULL},       {"--xi", &a->c.xi, NULL},
        {"--dt", &a->opts.dt, NULL},      {"--theta", &a->opts.theta, NULL},
        {"--gamma", &a->opts.gamma, NULL}, {"--tend", &a->opts.tend, NULL}};
    for (size_t n = 0; n < sizeof nums / sizeof nums[0]; n++)
        if (!strcmp(f, nums[n].flag)) {
            if ((rc = pd_cli_double(f, val, &x)))
                return rc;
            *nums[n].dst = x;
            if (nums[n].have)
                *nums[n].have = 1;
            (*i)++;
            return 0;
        }
    if (!strcmp(f, "--json"))
        a->json = 1;
    else if (!strcmp(f, "--allow-unstable"))
        a->opts.allow_unstable = 1;
    else if (!strcmp(f, "--no-wall"))
        a->opts.no_wall = 1;
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
        if (!val || strcmp(val, "moreau"))
            return pd_cli_usage_error("--method: '%s' is not available (this build has: moreau)",
                                      val ? val : "");
        (*i)++;
    } else if (!strcmp(f, "--kernel")) {
        if (!val || (strcmp(val, "auto") && strcmp(val, "general")))
            return pd_cli_usage_error("--kernel: '%s' is not one of auto, general", val ? val : "");
        a->opts.kernel = strcmp(val, "general") ? PD_KERNEL_AUTO : PD_KERNEL_GENERAL;
        (*i)++;
    } else if (!strcmp(f, "-o")) {
        if (!val)
            return pd_cli_usage_error("-o needs a file name");
        a->out = val;
        (*i)++;
    } else if (!strcmp(f, "--every")) {
        if ((rc = pd_cli_int(f, val, &k)))
            return rc;
        if (k < 1)
            return pd_cli_usage_error("--every: must be >= 1 (got %d)", k);
        a->every = k;
        (*i)++;
    } else
        return pd_cli_usage_error("simulate: unknown flag '%s' (see pound simulate --help)", f);
    return 0;
}

/* Ranges, named by the flag the user gave. */
static int check_args(sim_args *a)
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
    if (!(a->opts.dt > 0.0))
        return pd_cli_usage_error("--dt: the step must be > 0 (got %g)", a->opts.dt);
    if (!(a->opts.tend > 0.0))
        return pd_cli_usage_error("--tend: must be > 0 (got %g)", a->opts.tend);
    if (!(a->opts.gamma >= 0.0 && a->opts.gamma <= 1.0))
        return pd_cli_usage_error("--gamma: must be in [0, 1] (got %g)", a->opts.gamma);
    if (!a->opts.allow_unstable && !(a->opts.theta >= 0.5 && a->opts.theta <= 1.0))
        return pd_cli_usage_error("--theta: %g is outside [1/2, 1], where Moreau-Jean is not "
                                  "unconditionally stable (add --allow-unstable to run it)",
                                  a->opts.theta);
    if (!(a->opts.theta >= 0.0 && a->opts.theta <= 2.0))
        return pd_cli_usage_error("--theta: must be in [0, 2] (got %g)", a->opts.theta);
    if (a->opts.tend / a->opts.dt > 2e9)
        return pd_cli_usage_error("--dt: %g s over %g s is more than 2e9 steps", a->opts.dt,
                                  a->opts.tend);
    if (a->out && pd_output_check_path(a->out, &err))
        return pd_cli_usage_error("%s", err.msg);
    if (pd_osc_check(&a->c, &err))
        return pd_cli_usage_error("%s", err.msg);
    return 0;
}

/* Defaults, then the flags, then derived fields; 0 or 2. */
static int parse_args(sim_args *a, int argc, char **argv)
{
    int rc;
    memset(a, 0, sizeof *a);
    a->c = (pd_osc){PD_PULSE_SINE, 1, 1.0, 1.0, 1.0, 0.05, 0.5, 0.05};
    a->opts = pd_osc_default_opts();
    a->opts.dt = -1.0; /* unset markers: defaults depend on the case */
    a->opts.tend = -1.0;
    a->every = 1;
    for (int i = 1; i < argc; i++)
        if ((rc = parse_flag(a, argc, argv, &i)))
            return rc;
    if (a->have_T0)
        a->c.Pi2 = a->c.Tp / a->T0;
    if (a->have_gap)
        a->c.Pi3 = a->gap / pd_osc_Le(&a->c);
    if (a->have_T0 && !(a->T0 > 0.0))
        a->c.Pi2 = -1.0;
    int dt_unset = a->opts.dt == -1.0, tend_unset = a->opts.tend == -1.0;
    if (dt_unset)
        a->opts.dt = 1.0;
    if (tend_unset)
        a->opts.tend = 1.0;
    if ((rc = check_args(a)))
        return rc;
    if (dt_unset)
        a->opts.dt = pd_osc_default_dt(&a->c);
    if (tend_unset)
        a->opts.tend = pd_osc_default_tend(&a->c);
    return 0;
}

/* The recorded history, allocated once before the run. */
typedef struct history {
    long every, cap, rows;
    double *t, *u, *v, *impulse, *gap;
} history;

static int record(const pd_osc_sample *s, void *ctx)
{
    history *h = ctx;
    if (s->step % h->every || h->rows >= h->cap)
        return 0;
    h->t[h->rows] = s->t;
    h->u[h->rows] = s->u;
    h->v[h->rows] = s->v;
    h->impulse[h->rows] = s->impulse;
    h->gap[h->rows] = s->gap;
    h->rows++;
    return 0;
}

static void history_free(history *h)
{
    free(h->t);
    free(h->u);
    free(h->v);
    free(h->impulse);
    free(h->gap);
}

static int history_alloc(history *h, long nsteps, long every)
{
    memset(h, 0, sizeof *h);
    h->every = every;
    h->cap = nsteps / every + 1;
    h->t = malloc((size_t)h->cap * sizeof(double));
    h->u = malloc((size_t)h->cap * sizeof(double));
    h->v = malloc((size_t)h->cap * sizeof(double));
    h->impulse = malloc((size_t)h->cap * sizeof(double));
    h->gap = malloc((size_t)h->cap * sizeof(double));
    return h->t && h->u && h->v && h->impulse && h->gap ? 0 : -1;
}

/* Summary figures of a run and its no-wall twin. */
typedef struct summary {
    pd_osc_result r, free;
    double Pi1, gamma, chi, cpu_s;
} summary;

static void print_json(const sim_args *a, const summary *s)
{
    pd_json js;
    const pd_osc *c = &a->c;
    pd_json_init(&js, stdout);
    pd_json_begin_object(&js, NULL);
    pd_json_str(&js, "method", "moreau");
    pd_json_num(&js, "umax", s->r.umax);
    pd_json_num(&js, "Pi1", s->Pi1);
    pd_json_num(&js, "u_toward", s->r.u_toward);
    pd_json_num(&js, "u_away", s->r.u_away);
    pd_json_int(&js, "impacts", s->r.impacts);
    pd_json_num(&js, "first_impact", s->r.first_impact); /* NaN -> null */
    pd_json_num(&js, "first_impact_velocity", s->r.first_impact_velocity);
    pd_json_num(&js, "max_impact_velocity", s->r.max_impact_velocity);
    pd_json_num(&js, "contact_time", s->r.contact_time);
    pd_json_num(&js, "min_gap", s->r.min_gap);
    pd_json_num(&js, "umax_free", s->free.umax);
    pd_json_num(&js, "gamma", s->gamma);
    pd_json_num(&js, "chi", s->chi);
    pd_json_int(&js, "steps", s->r.steps);
    pd_json_num(&js, "cpu_s", s->cpu_s);
    pd_json_num(&js, "Pi2", c->Pi2);
    pd_json_num(&js, "Pi3", c->Pi3);
    pd_json_num(&js, "eps", c->eps);
    pd_json_num(&js, "xi", c->xi);
    pd_json_num(&js, "ap", c->ap);
    pd_json_num(&js, "Tp", c->Tp);
    pd_json_num(&js, "T0", pd_osc_T0(c));
    pd_json_num(&js, "gap", pd_osc_gap(c));
    pd_json_str(&js, "pulse", pd_pulse_name(c->pulse));
    pd_json_str(&js, "dir", pd_dir_name(c->dir));
    pd_json_num(&js, "dt", s->r.dt);
    pd_json_num(&js, "theta", s->r.theta);
    pd_json_num(&js, "gamma_active", s->r.gamma);
    pd_json_num(&js, "tend", s->r.tend);
    pd_json_str(&js, "kernel", s->r.kernel);
    pd_json_end_object(&js);
    pd_json_finish(&js);
}

static void print_text(const sim_args *a, const summary *s)
{
    const pd_osc *c = &a->c;
    printf("pounding oscillator, %s %s pulse: ap = %g m/s^2, Tp = %g s, T0 = %g s, "
           "gap = %g m, eps = %g, xi = %g\n",
           pd_dir_name(c->dir), pd_pulse_name(c->pulse), c->ap, c->Tp, pd_osc_T0(c),
           pd_osc_gap(c), c->eps, c->xi);
    printf("  Pi2 = %.6g  Pi3 = %.6g   Moreau-Jean theta = %g, dt = %.6g s, %ld steps to %g s\n",
           c->Pi2, c->Pi3, s->r.theta, s->r.dt, s->r.steps, s->r.tend);
    printf("  umax      = %.6g m   (Pi1 = %.6g)\n", s->r.umax, s->Pi1);
    printf("  toward    = %.6g m,  away = %.6g m\n", s->r.u_toward, s->r.u_away);
    printf("  umax_free = %.6g m   gamma = umax/umax_free = %.4g,  chi = gap/umax_free = %.4g\n",
           s->free.umax, s->gamma, s->chi);
    if (s->r.impacts)
        printf("  impacts   = %ld, first at t = %.6g s (velocity %.4g m/s), contact time %.4g s\n",
               s->r.impacts, s->r.first_impact, s->r.first_impact_velocity, s->r.contact_time);
    else
        printf("  impacts   = 0 (the oscillator never reaches the wall)\n");
    printf("  cpu       = %.3g s\n", s->cpu_s);
}

/* Write the history and every input and summary figure. */
static int write_output(const sim_args *a, const summary *s, const history *h, pd_err *err)
{
    const pd_osc *c = &a->c;
    pd_column cols[] = {{"t", "s", h->t},
                        {"u", "m", h->u},
                        {"v", "m/s", h->v},
                        {"impulse", "m/s", h->impulse},
                        {"gap", "m", h->gap}};
    pd_attr attrs[] = {
        {"method", NULL, 1, 0, "moreau"},
        {"pulse", NULL, 1, 0, pd_pulse_name(c->pulse)},
        {"dir", NULL, 1, 0, pd_dir_name(c->dir)},
        {"ap", "m/s^2", 0, c->ap, NULL},
        {"Tp", "s", 0, c->Tp, NULL},
        {"T0", "s", 0, pd_osc_T0(c), NULL},
        {"gap", "m", 0, pd_osc_gap(c), NULL},
        {"eps", "1", 0, c->eps, NULL},
        {"xi", "1", 0, c->xi, NULL},
        {"Pi2", "1", 0, c->Pi2, NULL},
        {"Pi3", "1", 0, c->Pi3, NULL},
        {"dt", "s", 0, s->r.dt, NULL},
        {"theta", "1", 0, s->r.theta, NULL},
        {"tend", "s", 0, s->r.tend, NULL},
        {"every", "steps", 0, (double)a->every, NULL},
        {"umax", "m", 0, s->r.umax, NULL},
        {"Pi1", "1", 0, s->Pi1, NULL},
        {"u_toward", "m", 0, s->r.u_toward, NULL},
        {"u_away", "m", 0, s->r.u_away, NULL},
        {"impacts", "1", 0, (double)s->r.impacts, NULL},
        {"first_impact", "s", 0, s->r.first_impact, NULL},
        {"contact_time", "s", 0, s->r.contact_time, NULL},
        {"umax_free", "m", 0, s->free.umax, NULL},
        {"gamma", "1", 0, s->gamma, NULL},
        {"steps", "1", 0, (double)s->r.steps, NULL},
        {"cpu_s", "s", 0, s->cpu_s, NULL}};
    pd_table t = {h->rows, 5, cols, (int)(sizeof attrs / sizeof attrs[0]), attrs};
    return pd_output_write(a->out, &t, err);
}

int pd_cmd_simulate(int argc, char **argv)
{
    sim_args a;
    summary s;
    history hist;
    pd_err err;
    int rc, status = 0;
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs(simulate_usage, stdout);
            return 0;
        }
    if ((rc = parse_args(&a, argc, argv)))
        return rc;
    memset(&hist, 0, sizeof hist);
    if (a.out && history_alloc(&hist, pd_steps_for(a.opts.tend, a.opts.dt), a.every)) {
        history_free(&hist);
        fprintf(stderr, "pound: simulate: out of memory for the history (use --every)\n");
        return 1;
    }
    memset(&s, 0, sizeof s);
    double cpu0 = pd_cpu_seconds();
    pd_osc_opts free_opts = a.opts;
    free_opts.no_wall = 1;
    if ((rc = pd_osc_simulate(&a.c, &a.opts, a.out ? record : NULL, &hist, &s.r, &err)) ||
        (rc = pd_osc_simulate(&a.c, &free_opts, NULL, NULL, &s.free, &err))) {
        fprintf(stderr, "pound: simulate: %s\n", err.msg);
        status = rc == PD_EINVAL ? 2 : 1;
        goto done;
    }
    s.cpu_s = pd_cpu_seconds() - cpu0;
    s.Pi1 = s.r.umax / pd_osc_Le(&a.c);
    s.gamma = s.free.umax > 0.0 ? s.r.umax / s.free.umax : NAN;
    s.chi = s.free.umax > 0.0 ? pd_osc_gap(&a.c) / s.free.umax : NAN;
    if (a.out && write_output(&a, &s, &hist, &err)) {
        fprintf(stderr, "pound: simulate: %s\n", err.msg);
        status = 1;
        goto done;
    }
    if (a.json)
        print_json(&a, &s);
    else
        print_text(&a, &s);
done:
    history_free(&hist);
    return status;
}
